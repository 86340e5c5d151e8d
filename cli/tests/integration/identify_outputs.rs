//! `dyngen identify` with --params-json, --svg and --urdf-out on robots/ur5/ur5.urdf.

use dyngen_identify::report::{ParamStatus, ParameterReport};

use crate::common::{assert_error, assert_ok, run, simulate_ur5, stdout, temp_dir, ur5, without_wrenches};
use std::path::{Path, PathBuf};

const JOINTS: [&str; 6] = [
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
];

/// Noise-free fourier data for the UR5 in `dir`.
fn simulate(dir: &Path) -> PathBuf {
    simulate_ur5(dir, 120, &[])
}

#[test]
fn identify_writes_json_svg_and_urdf() {
    let dir = temp_dir("dyngen-cli-identify-outputs", "all");
    let csv = simulate(&dir);
    let json = dir.join("ur5.json");
    let svg = dir.join("ur5.svg");
    let urdf = dir.join("ur5-identified.urdf");

    let o = run!(
        "identify",
        ur5(),
        csv,
        "--params-json",
        json,
        "--svg",
        svg,
        "--truth-from-urdf",
        "--urdf-out",
        urdf
    );
    assert_ok(&o);
    let out = stdout(&o);

    // JSON: the 60 standard parameters, unidentifiable ones in combinations.
    let report = ParameterReport::read(&json).unwrap();
    assert_eq!(report.parameters.len(), 60);
    assert_eq!(report.rank, 36);
    assert_eq!(report.channels, JOINTS);
    assert!(
        report
            .parameters
            .iter()
            .any(|p| p.status == ParamStatus::InCombination && p.value.is_none()),
        "{report:?}"
    );
    assert!(!report.combinations.is_empty());
    assert!(report
        .parameters
        .iter()
        .all(|p| p.value.is_some() == matches!(p.status, ParamStatus::Identified | ParamStatus::NotSignificant)));

    // SVG: one plot per joint.
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"), "{}", &text[..text.len().min(200)]);
    for joint in JOINTS {
        assert!(text.contains(joint), "{joint} missing from the SVG");
    }

    // URDF: parses; with joint torques only no UR5 body is fully identifiable, so
    // the file is the input and the output says why.
    let model = dyngen_model::load_urdf(&urdf).unwrap();
    assert_eq!(model.dof(), 6);
    let fully_identified = (0..6).any(|b| {
        report.parameters[10 * b..10 * b + 10]
            .iter()
            .all(|p| p.status == ParamStatus::Identified)
    });
    if fully_identified {
        assert!(out.contains("with the identified inertials of"), "{out}");
    } else {
        assert_eq!(std::fs::read(&urdf).unwrap(), std::fs::read(ur5()).unwrap());
        assert!(out.contains("unchanged"), "{out}");
        assert!(out.contains("no body has all its parameters identified"), "{out}");
        assert!(out.contains("expected"), "{out}");
    }
    assert!(out.contains("kept the URDF inertials of"), "{out}");

    // Not replaced without --force: the error names the file, nothing changes.
    let before = std::fs::read(&json).unwrap();
    std::fs::write(&svg, "keep me").unwrap();
    let o = run!("identify", ur5(), csv, "--svg", svg);
    assert_error(&o, &svg.display().to_string());
    assert_error(&o, "--force");
    assert_eq!(std::fs::read_to_string(&svg).unwrap(), "keep me");
    let o = run!("identify", ur5(), csv, "--params-json", json, "--urdf-out", urdf);
    assert_error(&o, &json.display().to_string());
    let o = run!("identify", ur5(), csv, "--urdf-out", urdf);
    assert_error(&o, &urdf.display().to_string());
    assert_eq!(std::fs::read(&json).unwrap(), before);

    // With --force all three are replaced.
    let o = run!(
        "identify",
        ur5(),
        csv,
        "--params-json",
        json,
        "--svg",
        svg,
        "--urdf-out",
        urdf,
        "--force"
    );
    assert_ok(&o);
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
    assert_eq!(ParameterReport::read(&json).unwrap().parameters.len(), 60);
}

#[test]
fn identify_output_flags_are_checked() {
    let dir = temp_dir("dyngen-cli-identify-outputs", "flags");
    let csv = simulate(&dir);
    let same = dir.join("out");
    let o = run!("identify", ur5(), csv, "--params-json", same, "--svg", same);
    assert_error(&o, "--params-json and --svg both name");
    assert!(!same.exists());

    let o = run!("identify", ur5(), csv, "--lump-merged");
    assert_error(&o, "--urdf-out");

    // --truth-from-urdf alone prints each parameter's error against the URDF.
    let o = run!("identify", ur5(), csv, "--truth-from-urdf");
    assert_ok(&o);
    assert!(stdout(&o).contains("against the URDF: "), "{}", stdout(&o));

    // MIM has its own estimator.
    let o = run!("identify", ur5(), csv, "--mode", "mim", "--method", "ols");
    assert_error(&o, "--method applies to --mode standard and principal");

    // MIM needs the joint wrench columns: the same data without them is refused
    // with a message naming them.
    let bare_csv = without_wrenches(&csv, &dir);
    let o = run!("identify", ur5(), bare_csv, "--mode", "mim");
    assert_error(
        &o,
        "--mode mim needs the joint wrench columns fx1, fy1, fz1, mx1, my1, mz1",
    );
    assert_ok(&run!("identify", ur5(), bare_csv, "--mode", "principal"));
}

/// The paper's MIM on the simulated joint wrenches: every θ that enters a body's
/// equations is identified to rounding; the shoulder link only turns about its own
/// axis, so its J1 and J2 are reported as not identifiable; the URDF gets the
/// identified inertials of the other five bodies.
#[test]
fn identify_by_mim_rewrites_the_identified_bodies() {
    let dir = temp_dir("dyngen-cli-identify-outputs", "mim");
    let csv = simulate(&dir);
    let json = dir.join("mim.json");
    let urdf = dir.join("ur5-mim.urdf");
    let o = run!(
        "identify",
        ur5(),
        csv,
        "--mode",
        "mim",
        "--truth-from-urdf",
        "--params-json",
        json,
        "--urdf-out",
        urdf
    );
    // wrist_3_link carries the fixed tool links: refused without --lump-merged,
    // and the URDF is not written.
    assert_error(&o, "pass --lump-merged");
    assert!(!urdf.exists());
    let o = run!(
        "identify",
        ur5(),
        csv,
        "--mode",
        "mim",
        "--params-json",
        json,
        "--urdf-out",
        urdf,
        "--lump-merged",
        "--force"
    );
    assert_ok(&o);
    let out = stdout(&o);
    assert!(
        out.contains("identified inertials of upper_arm_link, forearm_link, wrist_1_link, wrist_2_link, wrist_3_link"),
        "{out}"
    );
    assert!(
        out.contains("shoulder_link (2 of its 4 parameters not identified)"),
        "{out}"
    );

    let report = ParameterReport::read(&json).unwrap();
    assert_eq!(report.parameters.len(), 24);
    let truth = dyngen_model::principal_params(&dyngen_model::load_urdf(&ur5()).unwrap());
    for (j, (p, t)) in report.parameters.iter().zip(&truth).enumerate() {
        if j == 1 || j == 2 {
            assert_eq!(p.status, ParamStatus::NoEffect, "{p:?}");
            assert!(p.value.is_none());
        } else {
            assert_eq!(p.status, ParamStatus::Identified, "{p:?}");
            let rel = (p.value.unwrap() - t).abs() / t;
            assert!(rel < 1e-9, "{}: {rel:e}", p.name);
        }
    }
    // The rewritten file: the same robot, the identified masses (wrist_3 lumps its
    // fixed tool links), the shoulder's inertial untouched.
    let rewritten = dyngen_model::load_urdf(&urdf).unwrap();
    let original = dyngen_model::load_urdf(&ur5()).unwrap();
    assert_eq!(rewritten.dof(), 6);
    for (a, b) in rewritten.bodies.iter().zip(&original.bodies) {
        assert!(
            (a.inertial.mass - b.inertial.mass).abs() < 1e-12 * b.inertial.mass,
            "{}",
            a.name
        );
    }
}
