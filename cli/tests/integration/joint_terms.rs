//! The joint terms of `dyngen identify` on the MuJoCo fixture (a UR5 with rotor
//! inertia, damping and dry friction from an independent simulator): Stribeck
//! friction with the consistent estimator, the rotor inertia on its own, and
//! `--urdf-out` writing every identified joint term (in the URDF's `<dynamics>`
//! what it can hold, the rest in a JSON file beside it).

use crate::common;
use crate::common::{assert_error, assert_exit, assert_ok, run, stdout, temp_dir, ur5};
use dyngen_identify::report::{JointParamsFile, ParamReport, ParamStatus, ParameterReport, JOINT_PARAMS_SCHEMA};
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/mujoco")
        .join(name)
}

fn value(p: &ParamReport) -> f64 {
    p.value.unwrap_or_else(|| panic!("{p:?} has no value"))
}

/// `--friction stribeck --method consistent`: the consistent linear fit, then the
/// Stribeck refinement within the same bounds (rounds run, every joint keeps its
/// term, Ia, Fv, Fc ≥ 0); `--urdf-out` writes Fv and Fc to the `<dynamics>` and
/// every term to `<name>.joint-params.json`, never over an existing file without
/// --force.
#[test]
fn consistent_stribeck_fit_and_every_joint_term_beside_the_urdf() {
    let dir = temp_dir("dyngen-cli-joint-terms", "stribeck");
    let (urdf, params) = (dir.join("ur5-id.urdf"), dir.join("ur5.json"));
    let beside = dir.join("ur5-id.joint-params.json");
    let identify = |force: bool| {
        let mut args: Vec<std::ffi::OsString> = vec![
            "identify".into(),
            ur5().into(),
            fixture("ur5_identify.csv").into(),
            "--friction".into(),
            "stribeck".into(),
            "--method".into(),
            "consistent".into(),
            "--cutoff".into(),
            "5".into(),
            "--urdf-out".into(),
            urdf.clone().into(),
            "--params-json".into(),
            params.clone().into(),
        ];
        if force {
            args.push("--force".into());
        }
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        common::dyngen(&args)
    };
    let o = identify(false);
    assert_ok(&o);
    let out = stdout(&o);
    assert!(!out.contains(": 0 rounds"), "{out}");
    for j in 1..=6 {
        assert!(out.contains(&format!("joint {j}: Stribeck kept: ")), "{out}");
    }
    assert!(
        out.contains(&format!(
            "Fs, vs, the Coulomb model), including those a URDF cannot hold, to {}",
            beside.display()
        )),
        "{out}"
    );
    let report = ParameterReport::read(&params).unwrap();
    for p in &report.parameters[60..84] {
        if !p.name.starts_with("F0") {
            assert!(p.value.is_none_or(|v| v >= 0.0), "{p:?}");
        }
    }

    // The companion file: Ia, Fv, Fc, F0, Fs, vs per joint, as the report has them;
    // the URDF's <dynamics> hold the same Fv and Fc.
    let file = JointParamsFile::from_json(&std::fs::read_to_string(&beside).unwrap()).unwrap();
    assert_eq!(file.schema, JOINT_PARAMS_SCHEMA);
    assert_eq!(file.urdf.as_deref(), Some("ur5-id.urdf"));
    let model = dyngen_model::load_urdf(&urdf).unwrap();
    assert_eq!(file.joints.len(), 6);
    for (j, joint) in file.joints.iter().enumerate() {
        let names: Vec<&str> = joint.parameters.iter().map(|p| p.name.as_str()).collect();
        let k = j + 1;
        assert_eq!(
            names,
            [
                format!("Ia{k}"),
                format!("Fv{k}"),
                format!("Fc{k}"),
                format!("F0_{k}"),
                format!("Fs{k}"),
                format!("vs{k}")
            ]
        );
        assert_eq!(joint.name, model.joints[j].name);
        assert!(joint.in_urdf, "{joint:?}");
        let d = model.joints[j].dynamics;
        assert_eq!(
            (d.damping, d.friction),
            (value(&joint.parameters[1]), value(&joint.parameters[2]))
        );
        assert!(value(&joint.parameters[4]) >= 0.0 && value(&joint.parameters[5]) > 0.0);
        assert_eq!(joint.parameters[..4], report.parameters[60 + 4 * j..64 + 4 * j]);
    }

    // An existing companion file is not replaced without --force, and the error
    // comes before any work.
    std::fs::remove_file(&urdf).unwrap();
    std::fs::remove_file(&params).unwrap();
    std::fs::write(&beside, "keep me").unwrap();
    let o = identify(false);
    assert_error(&o, &beside.display().to_string());
    assert_error(&o, "--force");
    assert!(!urdf.exists() && !params.exists());
    assert_eq!(std::fs::read_to_string(&beside).unwrap(), "keep me");
    assert_ok(&identify(true));
    assert!(JointParamsFile::from_json(&std::fs::read_to_string(&beside).unwrap()).is_ok());
}

/// `--rotor-inertia no` fits friction without Ia, `--rotor-inertia yes` Ia without
/// friction; the terms left out are `excluded`; bad uses are refused by name.
#[test]
fn rotor_inertia_on_its_own() {
    let dir = temp_dir("dyngen-cli-joint-terms", "rotor");
    let params = dir.join("p.json");
    let csv = fixture("ur5_identify.csv");
    let o = run!(
        "identify",
        ur5(),
        &csv,
        "--friction",
        "sign",
        "--rotor-inertia",
        "no",
        "--params-json",
        &params,
        "--force"
    );
    assert_ok(&o);
    assert!(
        stdout(&o).contains("left out of the model (held at 0)"),
        "{}",
        stdout(&o)
    );
    let report = ParameterReport::read(&params).unwrap();
    for (i, p) in report.parameters[60..84].iter().enumerate() {
        assert_eq!(p.status == ParamStatus::Excluded, i % 4 == 0, "{p:?}");
    }
    let pre = report.prediction.as_ref().unwrap().preprocessing.as_ref().unwrap();
    assert_eq!(pre.rotor_inertia, Some(false));

    let o = run!(
        "identify",
        ur5(),
        &csv,
        "--rotor-inertia",
        "yes",
        "--params-json",
        &params,
        "--force"
    );
    assert_ok(&o);
    let report = ParameterReport::read(&params).unwrap();
    assert_eq!(report.parameters.len(), 84);
    for (i, p) in report.parameters[60..84].iter().enumerate() {
        assert_eq!(p.status == ParamStatus::Excluded, i % 4 != 0, "{p:?}");
    }
    assert!(report.parameters[60 + 4 * 5].value.is_some());

    assert_exit(
        &run!("identify", ur5(), &csv, "--rotor-inertia", "no"),
        2,
        "--rotor-inertia no has nothing to leave the rotor inertia out of without friction terms",
    );
    assert_exit(
        &run!("identify", ur5(), &csv, "--rotor-inertia", "yes", "--mode", "principal"),
        2,
        "--rotor-inertia applies to the standard mode",
    );
    let o = run!("identify", ur5(), &csv, "--rotor-inertia", "maybe");
    assert_exit(&o, 2, "--rotor-inertia");
    assert_error(&o, "[possible values: yes, no]");
}
