//! `dyngen identify --drive-gains`: torque constants identified from two logs of
//! motor currents, the second with a known payload; then `dyngen validate` reads a
//! third current log with them.

use crate::common::{self, assert_exit, assert_ok, overall, run, stdout, temp_dir, ur5};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Output;

const GAINS: [f64; 6] = [0.125, 0.125, 0.125, 0.092, 0.092, 0.092];

/// The UR5 with a 5 kg cylinder (radius 5 cm, length 10 cm) fixed to `tool0`, its
/// centre of mass 10 cm off the flange's axis and 5 cm beyond it.
fn loaded_ur5(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(ur5()).unwrap();
    let payload = r#"  <joint name="payload_joint" type="fixed"><parent link="tool0"/><child link="payload"/></joint>
  <link name="payload"><inertial><mass value="5"/><origin xyz="0.1 0 0.05"/>
    <inertia ixx="0.0072917" iyy="0.0072917" izz="0.00625" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>"#;
    let path = dir.join("ur5-loaded.urdf");
    std::fs::write(&path, text.replace("</robot>", payload)).unwrap();
    path
}

/// A logger's recording of motor currents (60 s at 100 Hz, jittered stamps, stale
/// and duplicate rows, 0.5 % noise) with rotor inertia and friction.
fn currents(robot: &Path, out: &Path, seed: &str) {
    let gains: Vec<String> = GAINS.iter().map(f64::to_string).collect();
    assert_ok(&run!(
        "simulate",
        robot,
        "-o",
        out,
        "--experiment",
        "fourier",
        "--evaluations",
        "0",
        "--duration",
        "60",
        "--seed",
        seed,
        "--noise",
        "0.005",
        "--logger-period",
        "0.01",
        "--current-gains",
        gains.join(","),
        "--armature",
        "0.5,0.5,0.3,0.05,0.05,0.05",
        "--damping",
        "2,2,1,0.3,0.3,0.3",
        "--coulomb",
        "3,3,2,0.5,0.5,0.5"
    ));
}

/// `dyngen identify ur5.urdf DATA` with `flags`.
fn identify(data: &Path, flags: &[&str]) -> Output {
    let mut args: Vec<OsString> = vec!["identify".into(), ur5().into(), data.into()];
    args.extend(flags.iter().map(OsString::from));
    common::dyngen(&args.iter().map(OsString::as_os_str).collect::<Vec<_>>())
}

/// The loaded log and the payload of [`loaded_ur5`], as flags.
fn drive_gains(loaded: &Path) -> Vec<String> {
    let payload = [
        "--payload-frame",
        "tool0",
        "--payload-mass",
        "5",
        "--payload-com",
        "0.1,0,0.05",
        "--payload-inertia",
        "0.0072917,0.0072917,0.00625",
    ];
    ["--drive-gains".to_string(), loaded.display().to_string()]
        .into_iter()
        .chain(payload.map(String::from))
        .collect()
}

#[test]
fn drive_gains_are_identified_and_validate_reads_currents_with_them() {
    let dir = temp_dir("dyngen-cli-drive-gains", "identify");
    let (unloaded, loaded, check) = (dir.join("unloaded.csv"), dir.join("loaded.csv"), dir.join("check.csv"));
    currents(&ur5(), &unloaded, "1");
    currents(&loaded_ur5(&dir), &loaded, "2");
    currents(&ur5(), &check, "3");
    // The logger's columns: t, q, v, then the currents.
    let recipe = dir.join("log.recipe");
    std::fs::write(&recipe, "q = 2-7\nv = 8-13\ntau = 14-19\nstale = drop\n").unwrap();
    let params = dir.join("ur5.json");
    let mut flags: Vec<String> = ["--friction", "sign", "--recipe"].map(String::from).into();
    flags.extend([
        recipe.display().to_string(),
        "--params-json".into(),
        params.display().to_string(),
    ]);
    flags.extend(drive_gains(&loaded));
    let o = identify(&unloaded, &flags.iter().map(String::as_str).collect::<Vec<_>>());
    assert_ok(&o);
    let out = stdout(&o);
    assert!(out.contains("drive gains (τ = k·i"), "{out}");
    for (j, truth) in GAINS.iter().enumerate() {
        let line = out
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("k{} (", j + 1)))
            .unwrap_or_else(|| panic!("no k{}:\n{out}", j + 1));
        let (k, sigma) = line.split_once(" = ").unwrap().1.split_once(" ± ").unwrap();
        let (k, sigma): (f64, f64) = (k.parse().unwrap(), sigma.parse().unwrap());
        assert!((k / truth - 1.0).abs() < 0.02, "k{}: {k} against {truth}\n{out}", j + 1);
        assert!(sigma > 0.0 && sigma < 0.02 * k, "{line}");
    }
    assert!(out.contains("torque: motor currents × gains"), "{out}");
    // `validate` reads another current log through the recorded gains.
    let o = run!("validate", ur5(), &params, &check);
    assert_ok(&o);
    let text = stdout(&o);
    assert!(text.contains("torque: motor currents × gains"), "{text}");
    assert!(overall(&text) < 0.05, "{text}");
}

#[test]
fn drive_gain_errors_name_the_flag() {
    let dir = temp_dir("dyngen-cli-drive-gains", "errors");
    let csv = dir.join("currents.csv");
    std::fs::write(&csv, "t,q1\n").unwrap();
    let full = drive_gains(&csv);
    let full: Vec<&str> = full.iter().map(String::as_str).collect();
    // `full` with the value of `flag` replaced.
    fn with<'a>(full: &[&'a str], flag: &str, value: &'a str) -> Vec<&'a str> {
        let mut v = full.to_vec();
        let at = v.iter().position(|f| *f == flag).unwrap();
        v[at + 1] = value;
        v
    }
    let csv_text = csv.display().to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--drive-gains", &csv_text], "--payload-mass"),
        (vec!["--payload-mass", "5"], "--drive-gains"),
        ([full.as_slice(), &["--gains", "0.1"]].concat(), "cannot be used with"),
        (
            [full.as_slice(), &["--friction", "none"]].concat(),
            "give --friction sign or smooth",
        ),
        (
            [full.as_slice(), &["--friction", "sign", "--rotor-inertia", "no"]].concat(),
            "drop --rotor-inertia no",
        ),
        (
            [with(&full, "--payload-frame", "nowhere"), vec!["--friction", "sign"]].concat(),
            "no link or frame `nowhere`",
        ),
        (
            [with(&full, "--payload-frame", "base_link"), vec!["--friction", "sign"]].concat(),
            "fixed to the base",
        ),
        (
            [with(&full, "--payload-mass", "-1"), vec!["--friction", "sign"]].concat(),
            "--payload-mass: -1 is not a mass",
        ),
        (
            [with(&full, "--payload-com", "0,1"), vec!["--friction", "sign"]].concat(),
            "--payload-com: `0,1` is not 3",
        ),
        (
            [with(&full, "--payload-inertia", "1,2"), vec!["--friction", "sign"]].concat(),
            "is not 3 or 6",
        ),
        (
            [with(&full, "--payload-inertia", "1,1,5"), vec!["--friction", "sign"]].concat(),
            "triangle inequality",
        ),
    ];
    for (flags, needle) in cases {
        assert_exit(&identify(&csv, &flags), 2, needle);
    }
}
