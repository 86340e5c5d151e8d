//! `dyngen nim train` and `dyngen nim predict` on robots/ur5/ur5.urdf (a small
//! training budget: these test the command, the accuracy is tested in the tests
//! crate).

use crate::common::{assert_error, assert_ok, run, simulate_ur5, stdout, temp_dir, ur5, without_wrenches};
use dyngen_identify::report::{ParamStatus, ParameterReport};
use std::path::{Path, PathBuf};

/// Noise-free UR5 data along a 2 s Fourier motion designed for the body model.
fn simulate(dir: &Path) -> PathBuf {
    simulate_ur5(dir, 60, &["--criterion", "body-model", "--base-frequency", "0.5"])
}

fn train(dir: &Path, csv: &Path) -> PathBuf {
    let nim = dir.join("ur5-nim.json");
    let svg = dir.join("loss.svg");
    let o = run!(
        "nim",
        "train",
        ur5(),
        csv,
        "-o",
        nim,
        "--draws",
        "40",
        "--steps",
        "100",
        "--window",
        "10",
        "--test-draws",
        "2",
        "--loss-svg",
        svg
    );
    assert_ok(&o);
    let out = stdout(&o);
    assert!(out.contains("shoulder_link: predicts m, J3;"), "{out}");
    assert!(out.contains("wrist_3_link: predicts m, J1, J2, J3;"), "{out}");
    assert!(out.contains("on 2 unseen draws"), "{out}");
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
    nim
}

#[test]
fn nim_trains_predicts_and_writes_parameters() {
    let dir = temp_dir("dyngen-cli-nim", "train-predict");
    let csv = simulate(&dir);
    let nim = train(&dir, &csv);

    // The identifier is kept unless --force, and nothing is trained first.
    let o = run!("nim", "train", ur5(), csv, "-o", nim, "--steps", "1");
    assert_error(&o, "--force");

    let json = dir.join("params.json");
    let o = run!(
        "nim",
        "predict",
        ur5(),
        nim,
        csv,
        "--truth-from-urdf",
        "--params-json",
        json
    );
    assert_ok(&o);
    let out = stdout(&o);
    assert!(
        out.contains("(cf. the paper's Table 4)") && out.contains("(cf. the paper's Table 5)"),
        "{out}"
    );
    let shoulder = out.lines().find(|l| l.starts_with("shoulder_link")).unwrap();
    assert_eq!(shoulder.matches("n/i").count(), 2, "{shoulder}");

    let report = ParameterReport::read(&json).unwrap();
    assert_eq!(report.parameters.len(), 24);
    assert_eq!(report.parameters[1].status, ParamStatus::NoEffect);
    assert_eq!(report.parameters[1].value, None);
    assert!(report.method.starts_with("NIM"), "{}", report.method);
    // A tiny budget, but the masses already come out within 30 % (the draws' spread).
    let truth = dyngen_model::principal_params(&dyngen_model::load_urdf(&ur5()).unwrap());
    for j in (0..24).step_by(4) {
        let p = &report.parameters[j];
        if let Some(v) = p.value {
            assert!(
                dyngen_identify::relative_error(v, truth[j]) < 0.3,
                "{p:?} vs {}",
                truth[j]
            );
        }
    }
}

#[test]
fn nim_predict_explains_bad_input() {
    let dir = temp_dir("dyngen-cli-nim", "errors");
    let csv = simulate(&dir);
    let nim = train(&dir, &csv);

    // Another robot.
    let paper6 = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/paper6.urdf");
    let o = run!("nim", "predict", paper6, nim, csv);
    assert_error(&o, "was trained for ur5 with bodies [shoulder_link");

    // Data without the joint wrench columns.
    let o = run!("nim", "predict", ur5(), nim, without_wrenches(&csv, &dir));
    assert_error(&o, "joint wrench columns fx1, fy1, fz1, mx1, my1, mz1");

    // A damaged identifier file: the error names the file and the field.
    let broken = dir.join("broken.json");
    let text = std::fs::read_to_string(&nim)
        .unwrap()
        .replacen("\"window\": 10", "\"window\": 0", 1);
    std::fs::write(&broken, text).unwrap();
    let o = run!("nim", "predict", ur5(), broken, csv);
    assert_error(&o, "broken.json: `window` has shape 0, expected at least 1");
    let o = run!("nim", "predict", ur5(), dir.join("missing.json"), csv);
    assert_error(&o, "missing.json");

    // Training options out of range.
    let o = run!("nim", "train", ur5(), csv, "-o", dir.join("x.json"), "--spread", "1.5");
    assert_error(&o, "--spread 1.5: out of range; expected a number with 0 ≤ x < 1");
    let o = run!("nim", "train", ur5(), csv, "-o", dir.join("x.json"), "--window", "500");
    assert_error(
        &o,
        "invalid window: 500 samples per window along a motion of 61 samples",
    );
    assert!(!dir.join("x.json").exists());
}
