//! What `identify` records and applies about how the recordings were read: the
//! training window is not applied to the validation recording, the parameters JSON
//! records every preprocessing choice and `validate` applies them, non-physical
//! joint parameters are flagged, and `--friction auto` says which ε it chose.

use crate::common::{assert_exit, assert_ok, run, simulate_ur5, stderr, stdout, temp_dir, ur5};
use dyngen_identify::report::{CoulombReport, ParameterReport};
use std::path::{Path, PathBuf};

/// Two noisy UR5 recordings of different motions (no friction in them), 601 and
/// 401 samples over 10 s.
fn recordings(dir: &Path) -> (PathBuf, PathBuf) {
    let one = simulate_ur5(dir, 600, &["--noise", "0.01", "--seed", "1"]);
    let first = dir.join("run1.csv");
    std::fs::rename(&one, &first).unwrap();
    let two = simulate_ur5(dir, 400, &["--noise", "0.01", "--seed", "2"]);
    let second = dir.join("run2.csv");
    std::fs::rename(&two, &second).unwrap();
    (first, second)
}

/// The line of `out` that starts with `prefix`.
fn line<'a>(out: &'a str, prefix: &str) -> &'a str {
    out.lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line `{prefix}…` in:\n{out}"))
}

/// The full-precision overall relative error both commands print.
fn exact(out: &str) -> f64 {
    line(out, "(as a fraction, full precision: ")
        .trim_start_matches("(as a fraction, full precision: ")
        .trim_end_matches(')')
        .parse()
        .unwrap_or_else(|_| panic!("no exact error in:\n{out}"))
}

#[test]
fn the_training_window_is_not_applied_to_the_validation_recording() {
    let dir = temp_dir("dyngen-preprocessing", "window");
    let (run1, run2) = recordings(&dir);
    let o = run!("identify", ur5(), &run1, "--window", "2:8", "--validate", &run2);
    assert_ok(&o);
    let out = stdout(&o);
    // Training: the samples of run1 within 2 s … 8 s (60 Hz: lines 122 to 482).
    let training = line(&out, "training: ");
    assert!(
        training.contains("361 samples of") && training.contains("run1.csv, line 122 to line 482"),
        "{out}"
    );
    // Validation: all of run2, and it says that the window was not applied.
    let validation = line(&out, "validation: ");
    assert!(
        validation.contains("401 samples of") && validation.contains("run2.csv, line 2 to line 402"),
        "{out}"
    );
    assert!(
        validation.contains("the training window (window = 2:8) is not applied"),
        "{out}"
    );
    assert!(
        out.contains("overall relative error") && out.contains("over 401 samples"),
        "{out}"
    );

    // Its own window: 1 s … 3 s of run2 (40 Hz: lines 42 to 122).
    let o = run!(
        "identify",
        ur5(),
        &run1,
        "--window",
        "2:8",
        "--validate",
        &run2,
        "--validate-window",
        "1:3"
    );
    assert_ok(&o);
    let out = stdout(&o);
    let validation = line(&out, "validation: ");
    assert!(
        validation.contains("81 samples of") && validation.contains("line 42 to line 122"),
        "{out}"
    );
    assert!(validation.contains("--validate-window 1:3"), "{out}");
    assert!(out.contains("over 81 samples"), "{out}");

    // Its own recipe: the training recipe's rows are not applied either.
    let train_recipe = dir.join("train.recipe");
    std::fs::write(&train_recipe, "rows = 1:300\n").unwrap();
    let validate_recipe = dir.join("validate.recipe");
    std::fs::write(&validate_recipe, "rows = 1:100\n").unwrap();
    let o = run!("identify", ur5(), &run1, "--recipe", &train_recipe, "--validate", &run2);
    assert_ok(&o);
    assert!(
        line(&stdout(&o), "validation: ").contains("401 samples of"),
        "{}",
        stdout(&o)
    );
    let o = run!(
        "identify",
        ur5(),
        &run1,
        "--recipe",
        &train_recipe,
        "--validate",
        &run2,
        "--validate-recipe",
        &validate_recipe
    );
    assert_ok(&o);
    let out = stdout(&o);
    assert!(line(&out, "training: ").contains("300 samples of"), "{out}");
    let validation = line(&out, "validation: ");
    assert!(
        validation.contains("100 samples of") && validation.contains("--validate-recipe"),
        "{out}"
    );

    // Without --validate they mean nothing.
    assert_exit(
        &run!("identify", ur5(), &run1, "--validate-window", "1:3"),
        2,
        "--validate",
    );
    let o = run!(
        "identify",
        ur5(),
        &run1,
        "--validate",
        &run2,
        "--validate-window",
        "3:1"
    );
    assert_exit(&o, 2, "--validate-window");
}

#[test]
fn validate_applies_the_preprocessing_the_parameters_record() {
    let dir = temp_dir("dyngen-preprocessing", "validate");
    let (run1, run2) = recordings(&dir);
    let recipe = dir.join("train.recipe");
    std::fs::write(&recipe, "decimate = 2\nwindow = 1:9\n").unwrap();
    let params = dir.join("p.json");
    let o = run!(
        "identify",
        ur5(),
        &run1,
        "--cutoff",
        "6",
        "--recipe",
        &recipe,
        "--friction",
        "sign",
        "--params-json",
        &params,
        "--validate",
        &run2
    );
    assert_ok(&o);
    let identified = exact(&stdout(&o));
    let json = ParameterReport::read(&params).unwrap();
    let pre = json.prediction.as_ref().unwrap().preprocessing.clone().unwrap();
    assert_eq!(pre.cutoff_hz, Some(6.0), "{pre:?}");
    assert_eq!(pre.low_pass_states, Some(true), "{pre:?}");
    assert_eq!(pre.recipe.as_deref(), Some("decimate = 2\n"), "{pre:?}");
    assert_eq!(pre.window.as_deref(), Some("window = 1:9"), "{pre:?}");
    assert_eq!(pre.friction.as_deref(), Some("sign"), "{pre:?}");
    assert_eq!(pre.data.as_ref().map(|d| d.samples), Some(241), "{pre:?}");

    let o = run!("validate", ur5(), &params, &run2);
    assert_ok(&o);
    let out = stdout(&o);
    let said = line(&out, "preprocessing from ");
    assert!(
        said.contains("cutoff 6 Hz") && said.contains("decimate = 2") && said.contains("window = 1:9"),
        "{out}"
    );
    let validated = exact(&out);
    assert!(identified > 1e-4, "{identified}");
    assert!(
        (validated - identified).abs() <= 1e-12,
        "{validated} against {identified}"
    );

    // A flag overrides the recorded choice, and says so.
    let o = run!("validate", ur5(), &params, &run2, "--cutoff", "3");
    assert_ok(&o);
    let out = stdout(&o);
    assert!(
        line(&out, "overriding ").contains("--cutoff 3 Hz instead of its 6 Hz"),
        "{out}"
    );
    assert!(out.contains("low-passed at 3 Hz"), "{out}");
    assert!(exact(&out) != identified, "{out}");

    // An older file without the record: the defaults, with a note.
    let mut old = json.clone();
    old.prediction.as_mut().unwrap().preprocessing = None;
    let old_path = dir.join("old.json");
    let text = old.to_json().unwrap();
    assert!(!text.contains("preprocessing"), "{text}");
    std::fs::write(&old_path, text).unwrap();
    let o = run!("validate", ur5(), &old_path, &run2);
    assert_ok(&o);
    let out = stdout(&o);
    assert!(line(&out, "note: ").contains("records no preprocessing"), "{out}");
    assert!(out.contains("low-passed at 10 Hz"), "{out}");
}

/// Data without friction: the friction estimates scatter around zero, the negative
/// ones are flagged in the output and the JSON, with the remedy; `--friction auto`
/// prints and records the ε it chose.
#[test]
fn non_physical_joint_parameters_and_the_chosen_epsilon_are_reported() {
    let dir = temp_dir("dyngen-preprocessing", "nonphysical");
    let (run1, _) = recordings(&dir);
    let params = dir.join("p.json");
    let o = run!("identify", ur5(), &run1, "--friction", "auto", "--params-json", &params);
    assert_ok(&o);
    let (out, err) = (stdout(&o), stderr(&o));
    let json = ParameterReport::read(&params).unwrap();
    let prediction = json.prediction.as_ref().unwrap();
    let flagged = &prediction.nonphysical;
    assert!(!flagged.is_empty(), "{json:?}");
    for p in flagged {
        let name = p.parameter.as_str();
        assert!(p.value < 0.0, "{p:?}");
        assert!(["Ia", "Fv", "Fc"].iter().any(|k| name.starts_with(k)), "{p:?}");
        assert!(out.contains(&format!("non-physical: {name} = ")), "{out}");
        assert!(err.contains(&format!("{name} = ")), "{err}");
    }
    assert!(
        err.contains("--method consistent keeps every joint's Ia, Fv, Fc and Fcl >= 0"),
        "{err}"
    );

    // One ε per joint, chosen on held-out blocks, in the JSON (the prediction's and the
    // preprocessing's) and printed.
    let Some(CoulombReport::Tanh { epsilon }) = prediction.coulomb else {
        panic!("{:?}", prediction.coulomb)
    };
    let epsilons = prediction.epsilons.as_ref().unwrap();
    assert_eq!(epsilons.len(), 6);
    assert_eq!(epsilon, epsilons[0]);
    let pre = prediction.preprocessing.as_ref().unwrap();
    assert_eq!(pre.coulomb_epsilons.as_ref(), Some(epsilons));
    assert_eq!(pre.coulomb_epsilon, None);
    assert_eq!(pre.epsilon_auto, Some(true));
    let said = line(&out, "--friction auto: ");
    let list: Vec<String> = epsilons.iter().map(|e| format!("{e:.4e}")).collect();
    assert!(
        said.contains(&format!("ε per joint {} rad/s", list.join(", "))),
        "{out}"
    );
}
