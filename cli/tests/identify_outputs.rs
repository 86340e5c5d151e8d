//! `dyngen identify` with --params-json, --svg and --urdf-out on robots/ur5/ur5.urdf.

use dyngen::report::{ParamStatus, ParameterReport};
mod common;

use common::{assert_error, assert_ok, run, stderr, stdout, temp_dir, ur5};
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
    let csv = dir.join("ur5.csv");
    let o = run!(
        "simulate",
        ur5(),
        "-o",
        csv,
        "--experiment",
        "fourier",
        "--evaluations",
        "0",
        "--steps",
        "120"
    );
    assert_ok(&o);
    csv
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
        .all(|p| p.value.is_some() == (p.status == ParamStatus::Identified)));

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
        assert!(
            out.contains("no body has all 10 standard parameters identified"),
            "{out}"
        );
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

    // --truth-from-urdf needs --svg (a usage error from clap: exit code 1 too).
    let o = run!("identify", ur5(), csv, "--truth-from-urdf");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--svg"), "{}", stderr(&o));
}
