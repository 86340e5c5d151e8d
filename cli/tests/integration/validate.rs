//! Identify on one recording, predict another: `identify --friction --validate` and
//! `dyngen validate` on the MuJoCo fixture (data dyngen did not simulate), against
//! the Pinocchio + numpy/scipy pipeline with per-joint friction (3.58 % overall on the
//! same files, `scripts/identify_pinocchio_scipy.py`).

use crate::common;
use crate::common::{assert_exit, assert_ok, overall, run, stdout, temp_dir, ur5};
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/mujoco")
        .join(name)
}

#[test]
fn friction_identification_predicts_the_mujoco_recording_better_than_the_baseline() {
    let dir = temp_dir("dyngen-validate", "mujoco");
    let params = dir.join("ur5.json");
    let urdf_out = dir.join("ur5-identified.urdf");
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "auto",
        "--cutoff",
        "5",
        "--urdf-out",
        &urdf_out,
        "--params-json",
        &params,
        "--validate",
        fixture("ur5_validate.csv"),
        "--force"
    );
    assert_ok(&o);
    let with_friction = overall(&stdout(&o));
    assert!(with_friction < 0.0358, "{}", stdout(&o));
    assert!(
        stdout(&o).contains("positions and measured velocities low-passed at 5 Hz (zero phase)"),
        "{}",
        stdout(&o)
    );
    // The measured positions and velocities as read: their noise enters every
    // regressor column, and the prediction is worse (2.54 % against 2.06 %).
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "auto",
        "--cutoff",
        "5",
        "--raw-states",
        "--validate",
        fixture("ur5_validate.csv")
    );
    assert_ok(&o);
    assert!(!stdout(&o).contains("low-passed"), "{}", stdout(&o));
    let raw = overall(&stdout(&o));
    assert!(with_friction < 0.9 * raw, "low-passed {with_friction}, raw {raw}");
    // The identified friction is written to the joints' <dynamics>: MuJoCo's
    // damping 3, 3, 2, 0.6, 0.6, 0.6 and frictionloss 6, 6, 4, 1.5, 1.5, 1.5.
    let model = dyngen_model::load_urdf(&urdf_out).unwrap();
    for (j, (fv, fc)) in [(3.0, 6.0), (3.0, 6.0), (2.0, 4.0), (0.6, 1.5), (0.6, 1.5), (0.6, 1.5)]
        .iter()
        .enumerate()
    {
        let d = model.joints[j].dynamics;
        assert!(
            (d.damping - fv).abs() < 0.3 * fv && (d.friction - fc).abs() < 0.1 * fc,
            "joint {}: {d:?}",
            j + 1
        );
    }

    // The same through the JSON, with the SVG.
    let svg = dir.join("validate.svg");
    let o = run!(
        "validate",
        ur5(),
        &params,
        fixture("ur5_validate.csv"),
        "--cutoff",
        "5",
        "--svg",
        &svg,
        "--force"
    );
    assert_ok(&o);
    assert_eq!(overall(&stdout(&o)), with_friction);
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));

    // Without friction the wrists are worse than predicting zero.
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "none",
        "--validate",
        fixture("ur5_validate.csv")
    );
    assert_ok(&o);
    let rigid = overall(&stdout(&o));
    assert!(rigid > 5.0 * with_friction, "{rigid} vs {with_friction}");
    assert!(stdout(&o).contains("(no better than zero)"), "{}", stdout(&o));
    // ...and `identify` says what to do about it.
    assert!(stdout(&o).contains("try --friction best"), "{}", stdout(&o));
}

#[test]
fn the_raw_logger_file_reads_through_flags() {
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify_raw.csv"),
        "--no-header",
        "--degrees",
        "--gains",
        "14,13,12,9,8.5,8",
        "--friction",
        "sign"
    );
    assert_ok(&o);
    let out = stdout(&o);
    assert!(
        out.contains("1975 rows read, 1972 samples of 6 joints kept; dropped 3 repeated rows"),
        "{out}"
    );
    assert!(out.contains("58 of 84 parameter directions identifiable"), "{out}");
}

#[test]
fn validate_errors_name_the_file() {
    let dir = temp_dir("dyngen-validate", "errors");
    let params = dir.join("bad.json");
    // A JSON from MIM holds no regressor model.
    std::fs::write(
        &params,
        r#"{"schema":"dyngen-parameters/1","robot":"ur5","parameterisation":"principal","method":"MIM","rank":0,
           "condition_number":null,"residual_rms":[],"parameters":[],"combinations":[]}"#,
    )
    .unwrap();
    let o = run!("validate", ur5(), &params, fixture("ur5_validate.csv"));
    assert_exit(&o, 3, "holds no prediction model");
    // A solution of the wrong length: another robot's parameters.
    std::fs::write(
        &params,
        r#"{"schema":"dyngen-parameters/1","robot":"ur5","parameterisation":"standard","method":"OLS","rank":0,
           "condition_number":null,"residual_rms":[],"parameters":[],"combinations":[],
           "prediction":{"regressor":"standard","solution":[1.0,2.0]}}"#,
    )
    .unwrap();
    let o = run!("validate", ur5(), &params, fixture("ur5_validate.csv"));
    assert_exit(
        &o,
        3,
        "the solution has 2 entries; this robot's Standard regressor has 60 columns",
    );
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "smooth",
        "--epsilon",
        "-1"
    );
    assert_exit(&o, 2, "--epsilon -1: out of range; expected a number with 0 < x ≤ 1000");
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "auto",
        "--mode",
        "principal"
    );
    assert_exit(&o, 2, "applies to the standard mode");
}

/// `simulate` writes what a robot's logger writes (jittered stamps, duplicate and
/// stale rows, motor currents), with friction and rotor inertia in the torques;
/// `identify` reads it back through a recipe and finds the friction.
#[test]
fn simulated_logger_files_identify_their_friction() {
    let dir = temp_dir("dyngen-validate", "logger");
    let log = dir.join("ur5.log");
    let o = run!(
        "simulate",
        ur5(),
        "-o",
        &log,
        "--experiment",
        "fourier",
        "--duration",
        "60",
        "--evaluations",
        "20",
        "--armature",
        "0.4,0.4,0.2,0.08,0.08,0.08",
        "--damping",
        "3,3,2,0.6,0.6,0.6",
        "--coulomb",
        "6,6,4,1.5,1.5,1.5",
        "--logger-period",
        "0.01",
        "--current-gains",
        "14,13,12,9,8.5,8",
        "--force"
    );
    assert_ok(&o);
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(text.starts_with("t,q1,"), "{}", &text[..80]);
    assert!(text.lines().next().unwrap().contains(",i6"));
    let recipe = dir.join("log.recipe");
    std::fs::write(
        &recipe,
        "q = 2-7\nv = 8-13\ntau = 14-19\ngains = 14,13,12,9,8.5,8\nstale = drop\n",
    )
    .unwrap();
    let o = run!("identify", ur5(), &log, "--recipe", &recipe, "--friction", "sign");
    assert_ok(&o);
    let out = stdout(&o);
    assert!(out.contains("repeated rows") && out.contains("stale rows"), "{out}");
    // Noise-free: the viscous friction of joint 2 to a fraction of a percent.
    let fv2: f64 = out
        .lines()
        .find_map(|l| l.strip_prefix("Fv2 "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("no Fv2 in\n{out}"));
    assert!((fv2 - 3.0).abs() < 0.03, "Fv2 = {fv2}\n{out}");

    let o = run!(
        "simulate",
        ur5(),
        "-o",
        dir.join("x.csv"),
        "--damping",
        "1,2",
        "--force"
    );
    assert_exit(&o, 2, "--damping: 2 values for 6 joints");
    let o = run!(
        "simulate",
        ur5(),
        "-o",
        dir.join("x.csv"),
        "--logger-period",
        "0.01",
        "--jitter",
        "1.5",
        "--force"
    );
    assert_exit(&o, 2, "--jitter 1.5: out of range; expected a number with 0 ≤ x < 1");
}

/// Total least squares without column scaling on real-looking data: the fit is
/// far worse than ordinary least squares (25×), and `identify` says so instead of
/// printing its numbers silently. With the columns scaled (the default) it is not,
/// and it predicts the other recording (4.8 % against OLS's 3.5 % and the unscaled
/// fit's 270 %).
#[test]
fn tls_far_worse_than_ols_is_a_warning() {
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "sign",
        "--method",
        "tls-unscaled"
    );
    assert_ok(&o);
    let err = common::stderr(&o);
    assert!(
        err.contains("warning: total least squares fits the torques")
            && err.contains("equal noise in every regressor column")
            && err.contains("prefer ols or wls"),
        "{err}"
    );
    // (Other warnings may come: this recording's OLS fit has a negative rotor
    // inertia, flagged as non-physical.)
    let o = run!("identify", ur5(), fixture("ur5_identify.csv"), "--friction", "sign");
    assert!(
        !common::stderr(&o).contains("warning: total least squares"),
        "{}",
        common::stderr(&o)
    );
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "sign",
        "--method",
        "tls",
        "--cutoff",
        "5",
        "--validate",
        fixture("ur5_validate.csv")
    );
    assert_ok(&o);
    assert!(
        !common::stderr(&o).contains("warning: total least squares"),
        "{}",
        common::stderr(&o)
    );
    assert!(
        stdout(&o).contains("total least squares (columns scaled)"),
        "{}",
        stdout(&o)
    );
    assert!(overall(&stdout(&o)) < 0.06, "{}", stdout(&o));
}

/// The overall validation error of `identify` on the MuJoCo pair with `flags`.
fn validated(flags: &[&str]) -> (f64, String) {
    let mut args: Vec<std::ffi::OsString> = vec![
        "identify".into(),
        ur5().into(),
        fixture("ur5_identify.csv").into(),
        "--cutoff".into(),
        "5".into(),
        "--validate".into(),
        fixture("ur5_validate.csv").into(),
    ];
    args.extend(flags.iter().map(Into::into));
    let refs: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let o = common::dyngen(&refs);
    assert_ok(&o);
    let out = stdout(&o);
    (overall(&out), out)
}

/// Physically consistent estimation with friction and rotor inertia from the
/// command line: every body physical, Ia, Fv, Fc ≥ 0, and the other recording
/// predicted at least as well as by OLS (3.33 % against 3.52 % on these files).
#[test]
fn consistent_estimation_with_friction_predicts_as_well_as_ols() {
    let (ols, _) = validated(&["--friction", "sign"]);
    let (consistent, out) = validated(&["--friction", "sign", "--method", "consistent"]);
    assert!(out.contains("physically consistent, pseudo-inertia barrier"), "{out}");
    assert!(consistent <= 1.01 * ols, "consistent {consistent}, OLS {ols}");
    // Fv and Fc of every joint, as printed: never negative.
    for line in out
        .lines()
        .filter(|l| l.starts_with("Fv") || l.starts_with("Fc") || l.starts_with("Ia"))
    {
        let value = line.split_whitespace().nth(1).unwrap();
        assert!(value == "—" || value.parse::<f64>().unwrap() >= 0.0, "{line}");
    }
    let (smooth, out) = validated(&["--friction", "smooth", "--epsilon", "0.02", "--method", "consistent"]);
    assert!(out.contains("physically consistent"), "{out}");
    assert!(smooth < 0.05, "{smooth}");
    // The principal form has no joint terms.
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--mode",
        "principal",
        "--method",
        "consistent",
        "--friction",
        "sign"
    );
    assert_exit(&o, 2, "--friction applies to the standard mode");
}

/// Rows near zero velocity left out of the Coulomb fit: counted, printed, and the
/// other recording is predicted better (3.27 % against 3.52 % at 0.05 rad/s).
#[test]
fn rows_below_a_speed_are_left_out() {
    let (all, _) = validated(&["--friction", "sign"]);
    let (some, out) = validated(&["--friction", "sign", "--exclude-below", "0.05"]);
    assert!(
        out.contains("--exclude-below 0.05: left out 859 of 11832 torque rows"),
        "{out}"
    );
    assert!(some < all, "{some} vs {all}");
    for bad in ["-1", "0", "nan"] {
        let o = run!(
            "identify",
            ur5(),
            fixture("ur5_identify.csv"),
            "--friction",
            "sign",
            "--exclude-below",
            bad
        );
        assert_exit(
            &o,
            2,
            &format!("--exclude-below {bad}: out of range; expected a number with 0 < x ≤ 1000"),
        );
    }
    let o = run!("identify", ur5(), fixture("ur5_identify.csv"), "--exclude-below", "100");
    assert_exit(&o, 2, "--exclude-below 100 leaves no torque row");
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--mode",
        "mim",
        "--exclude-below",
        "0.1"
    );
    assert_exit(&o, 2, "--exclude-below applies to the standard and principal modes");
}

/// `--friction stribeck` on the MuJoCo fixture: MuJoCo's joint friction vanishes at
/// rest, which a static friction below the Coulomb friction describes; the fit
/// predicts the second recording better than sign friction, and `validate`
/// predicts the same from the JSON, which holds Fs and vs.
#[test]
fn stribeck_friction_predicts_the_mujoco_recording_better_than_sign_friction() {
    let dir = temp_dir("dyngen-validate", "stribeck");
    let params = dir.join("ur5.json");
    let identify = |friction: &str, json: Option<&PathBuf>| {
        let mut args: Vec<std::ffi::OsString> = vec![
            "identify".into(),
            ur5().into(),
            fixture("ur5_identify.csv").into(),
            "--friction".into(),
            friction.into(),
            "--cutoff".into(),
            "5".into(),
            "--validate".into(),
            fixture("ur5_validate.csv").into(),
        ];
        if let Some(json) = json {
            args.extend(["--params-json".into(), json.into(), "--force".into()]);
        }
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let o = common::dyngen(&args);
        assert_ok(&o);
        stdout(&o)
    };
    let sign = overall(&identify("sign", None));
    let out = identify("stribeck", Some(&params));
    let stribeck = overall(&out);
    assert!(stribeck < 0.7 * sign, "sign {sign}, stribeck {stribeck}\n{out}");
    assert!(
        out.contains("Stribeck friction (Fs at rest falling to Fc above vs)"),
        "{out}"
    );
    let json = std::fs::read_to_string(&params).unwrap();
    assert!(json.contains("\"stribeck\"") && json.contains("\"Fs1\"") && json.contains("\"vs6\""));
    let o = run!("validate", ur5(), &params, fixture("ur5_validate.csv"), "--cutoff", "5");
    assert_ok(&o);
    assert_eq!(overall(&stdout(&o)), stribeck);
}

#[test]
fn simulated_stribeck_friction_needs_a_positive_velocity() {
    let dir = temp_dir("dyngen-validate", "stribeck-simulate");
    let csv = dir.join("s.csv");
    let simulate = |extra: &[&str]| {
        let mut args: Vec<std::ffi::OsString> = vec!["simulate".into(), ur5().into(), "-o".into(), csv.clone().into()];
        args.extend(extra.iter().map(|a| a.into()));
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        common::dyngen(&args)
    };
    let o = simulate(&[
        "--static-friction",
        "2",
        "--stribeck-velocity",
        "0.05,0.05,0,0.05,0.05,0.05",
    ]);
    assert_exit(
        &o,
        2,
        "joint 3: the Stribeck velocity must be positive and finite, got 0",
    );
    assert_exit(&simulate(&["--static-friction", "2"]), 2, "--stribeck-velocity");
    assert_exit(
        &simulate(&["--static-friction", "2,3", "--stribeck-velocity", "0.05"]),
        2,
        "--static-friction: 2 values for 6 joints",
    );
    let o = simulate(&[
        "--coulomb",
        "1",
        "--static-friction",
        "2",
        "--stribeck-velocity",
        "0.05",
    ]);
    assert_ok(&o);
    assert!(csv.exists());
}

/// `--friction best` on the MuJoCo recording: every candidate's held-out error is
/// printed, the choice is one of the nonlinear Coulomb models (which predict the
/// other recording best, table in the README), it is recorded for `validate`, and
/// the prediction is at least as good as sign friction's.
#[test]
fn the_best_joint_model_is_chosen_on_held_out_blocks() {
    let dir = temp_dir("dyngen-validate", "best");
    let params = dir.join("ur5.json");
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "best",
        "--cutoff",
        "5",
        "--validate",
        fixture("ur5_validate.csv"),
        "--params-json",
        &params
    );
    assert_ok(&o);
    let out = stdout(&o);
    let table: Vec<&str> = out
        .lines()
        .skip_while(|l| !l.starts_with("joint model chosen by the error on held-out data"))
        .skip(1)
        .take(5)
        .collect();
    let names: Vec<&str> = table.iter().filter_map(|l| l.split_whitespace().next()).collect();
    assert_eq!(
        names,
        ["none", "sign-no-rotor-inertia", "sign", "auto", "stribeck"],
        "{out}"
    );
    let errors: Vec<f64> = table
        .iter()
        .map(|l| l.split_whitespace().nth(1).and_then(|x| x.parse().ok()).unwrap())
        .collect();
    let chosen = table.iter().position(|l| l.ends_with("<- chosen")).expect("a choice");
    // A more complex model is chosen where it lowers the error by 1 %.
    assert!(errors.iter().all(|&e| e >= 0.99 * errors[chosen]), "{out}");
    assert!(["auto", "stribeck"].contains(&names[chosen]), "{out}");
    // Sign friction predicts this recording at 3.52 % (README).
    let best = overall(&out);
    assert!(best < 0.0352, "{out}");
    let o = run!("validate", ur5(), &params, fixture("ur5_validate.csv"), "--cutoff", "5");
    assert_ok(&o);
    assert_eq!(overall(&stdout(&o)), best);
    // What it cannot combine with.
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "best",
        "--rotor-inertia",
        "yes"
    );
    assert_exit(&o, 2, "--friction best chooses the rotor inertia too");
    let part = dir.join("run.part");
    let o = run!(
        "identify",
        ur5(),
        fixture("ur5_identify.csv"),
        "--friction",
        "best",
        "--partial",
        &part
    );
    assert_exit(
        &o,
        2,
        "--friction best cannot be written as or solved from partial factors",
    );
}
