//! Hostile input: sizes that would abort the process on allocation, outputs that
//! cannot be written, unbounded lines, parameters that overflow or belong to another
//! robot, absurd flag values, a byte order mark. Each is a clear error with its exit
//! code (or, for the byte order mark, accepted), never a crash or a silent result.

use crate::common;
use crate::common::{assert_exit, assert_ok, pendulum, run, simulate_ur5, stderr, stdout, temp_dir, ur5};
use std::process::{Command, Stdio};

/// Rows of a pendulum recording `t, q1, tau1` (header included).
fn pendulum_rows() -> String {
    let rows: String = (0..40)
        .map(|k| {
            let t = 0.01 * k as f64;
            format!("{t},{},{}\n", (0.3 * t).sin(), 0.1 + 0.01 * (2.0 * t).cos())
        })
        .collect();
    format!("t,q1,tau1\n{rows}")
}

#[test]
fn a_recipe_column_range_beyond_any_line_is_refused_not_allocated() {
    let dir = temp_dir("dyngen-hostile", "recipe-range");
    let urdf = pendulum(&dir, "pendulum.urdf", "1");
    let csv = dir.join("p.csv");
    std::fs::write(&csv, pendulum_rows()).unwrap();
    let recipe = dir.join("huge.recipe");
    std::fs::write(&recipe, "q = 2-4000000000\ntau = 3\n").unwrap();
    assert_exit(
        &run!("identify", urdf, csv, "--recipe", recipe),
        3,
        "line 1: `q = 2-4000000000`: expected column numbers (from 1 to 524288",
    );
}

#[test]
fn simulate_steps_beyond_the_limit_are_refused_not_allocated() {
    let dir = temp_dir("dyngen-hostile", "steps");
    let o = run!("simulate", ur5(), "-o", dir.join("x.csv"), "--steps", "100000000000");
    assert_exit(
        &o,
        2,
        "--steps 100000000000: out of range; expected a whole number from 1 to 1000000",
    );
    assert!(!dir.join("x.csv").exists());
    // A logger over a long duration at a short period: too many samples.
    let o = run!(
        "simulate",
        ur5(),
        "-o",
        dir.join("x.csv"),
        "--duration",
        "1000",
        "--logger-period",
        "1e-6"
    );
    assert_exit(
        &o,
        2,
        "--logger-period 0.000001 over 1000 s gives 1.000e9 samples; at most 1000000",
    );
}

#[test]
fn a_nim_layer_size_beyond_the_file_is_refused_not_allocated() {
    let dir = temp_dir("dyngen-hostile", "nim-size");
    let urdf = pendulum(&dir, "pendulum.urdf", "1");
    let mlp = |sizes: &str, weights: &str| {
        format!(
            r#"{{"schema":"dyngen-mlp/1","sizes":{sizes},"layers":[{{"weights":{weights},"bias":[0]}}],
               "input":{{"mean":[0],"std":[1]}},"output":{{"mean":[0],"std":[1]}}}}"#
        )
    };
    let nim = format!(
        r#"{{"schema":"dyngen-nim/1","robot":"pendulum","body_names":["arm"],"window":4,"spread":0.3,
             "nominal":[1,0.1,0.1,0.01],"bodies":[{{"outputs":[0],"net":{{"schema":"dyngen-window-net/1",
             "encoder":{},"decoder":{}}}}}]}}"#,
        mlp("[1000000000000, 1]", "[[1, 2, 3]]"),
        mlp("[1, 1]", "[[1]]")
    );
    let weights = dir.join("weights.json");
    std::fs::write(&weights, nim).unwrap();
    assert_exit(
        &run!("nim", "predict", urdf, weights, dir.join("data.csv")),
        3,
        "row 0 of length 3, expected 1 × 1000000000000",
    );
}

#[test]
fn stdout_on_a_full_disk_is_an_output_error() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // not Linux
    };
    let o = Command::new(env!("CARGO_BIN_EXE_dyngen"))
        .args(["info".as_ref(), ur5().as_os_str(), "--no-ops".as_ref()])
        .stdout(full)
        .output()
        .unwrap();
    assert_exit(&o, 5, "cannot write to stdout: No space left on device");
}

#[test]
fn generate_with_stdout_closed_is_an_output_error() {
    if !std::path::Path::new("/proc/self/fd").is_dir() {
        return;
    }
    let dir = temp_dir("dyngen-hostile", "closed-stdout");
    let urdf = pendulum(&dir, "pendulum.urdf", "1");
    let o = Command::new("sh")
        .arg("-c")
        .arg(r#"exec "$0" "$@" >&-"#)
        .arg(env!("CARGO_BIN_EXE_dyngen"))
        .args(["generate".as_ref(), urdf.as_os_str(), "--name".as_ref(), "P".as_ref()])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert_exit(&o, 5, "cannot write to stdout: it is closed");
    // Redirected to /dev/null on purpose: written, and nothing to complain about.
    let o = Command::new(env!("CARGO_BIN_EXE_dyngen"))
        .args(["generate".as_ref(), urdf.as_os_str(), "--name".as_ref(), "P".as_ref()])
        .stdout(Stdio::null())
        .output()
        .unwrap();
    assert_ok(&o);
}

#[test]
fn a_line_longer_than_the_limit_is_refused_before_it_is_read_whole() {
    let dir = temp_dir("dyngen-hostile", "long-line");
    let urdf = pendulum(&dir, "pendulum.urdf", "1");
    let csv = dir.join("long.csv");
    let mut text = b"t,q1,tau1\n0,0,0\n".to_vec();
    text.extend(std::iter::repeat_n(b'1', 2 << 20));
    std::fs::write(&csv, text).unwrap();
    let o = run!("identify", urdf, csv);
    assert_exit(
        &o,
        3,
        "long.csv: line 3 is longer than 1048576 bytes (1 MiB) without a line break",
    );
    // A recipe that is no recipe: bounded too.
    let o = run!("identify", urdf, dir.join("long.csv"), "--recipe", dir.join("long.csv"));
    assert_exit(
        &o,
        3,
        "longer than 1048576 bytes; a recipe is a few `key = value` lines",
    );
}

/// A UR5 parameters JSON (standard regressor) with `solution` and `channels`.
fn ur5_params(solution: &str, channels: &str) -> String {
    format!(
        r#"{{"schema":"dyngen-parameters/1","robot":"ur5","parameterisation":"standard","method":"OLS","rank":60,
           "condition_number":null,"residual_rms":[],"channels":{channels},"parameters":[],"combinations":[],
           "prediction":{{"regressor":"standard","solution":{solution}}}}}"#
    )
}

#[test]
fn parameters_that_overflow_the_prediction_are_an_error() {
    let dir = temp_dir("dyngen-hostile", "overflow");
    let csv = simulate_ur5(&dir, 30, &[]);
    let params = dir.join("huge.json");
    let solution = format!("[{}]", vec!["1e308"; 60].join(","));
    std::fs::write(&params, ur5_params(&solution, "[]")).unwrap();
    let o = run!("validate", ur5(), &params, &csv);
    assert_exit(&o, 3, "huge.json: the predicted torque");
    assert!(stderr(&o).contains("too large"), "{}", stderr(&o));
    assert!(!stdout(&o).contains("inf"), "{}", stdout(&o));
    // Large enough to predict finite torques whose squared errors overflow.
    let solution = format!("[{}]", vec!["1e160"; 60].join(","));
    std::fs::write(&params, ur5_params(&solution, "[]")).unwrap();
    let o = run!("validate", ur5(), &params, &csv);
    assert_exit(&o, 3, "huge.json: ");
    assert!(!stdout(&o).contains("inf"), "{}", stdout(&o));
}

#[test]
fn parameters_of_another_robot_are_refused_with_the_differences() {
    let dir = temp_dir("dyngen-hostile", "other-robot");
    let csv = simulate_ur5(&dir, 30, &[]);
    let params = dir.join("other.json");
    let solution = format!("[{}]", vec!["0.1"; 60].join(","));
    std::fs::write(&params, ur5_params(&solution, r#"["hinge", "shoulder_pan_joint"]"#)).unwrap();
    let o = run!("validate", ur5(), &params, &csv);
    assert_exit(
        &o,
        3,
        "other.json: the parameters were identified for `ur5` with joints [hinge, shoulder_pan_joint]",
    );
    let err = stderr(&o);
    assert!(
        err.contains("2 joints instead of 6")
            && err.contains("joints the robot does not have: hinge")
            && err.contains("robot joints it lacks: shoulder_lift_joint"),
        "{err}"
    );
}

#[test]
fn absurd_flag_values_name_the_flag_the_value_and_the_range() {
    let dir = temp_dir("dyngen-hostile", "flags");
    let out = dir.join("x.csv");
    let cases: [(Vec<&str>, &str); 7] = [
        (
            vec!["--duration", "1e300"],
            "--duration 1e300: out of range; expected a number with 0 < x ≤ 1000000 (s)",
        ),
        (
            vec!["--noise", "1e300"],
            "--noise 1e300: out of range; expected a number with 0 ≤ x ≤ 1",
        ),
        (vec!["--noise", "-0.5"], "--noise -0.5: out of range"),
        (
            vec!["--gravity", "0", "0", "-1e300"],
            "--gravity -1e300: out of range; expected a number with -1000 ≤ x ≤ 1000",
        ),
        (
            vec!["--jitter", "1"],
            "--jitter 1: out of range; expected a number with 0 ≤ x < 1",
        ),
        (vec!["--time-budget", "-1"], "--time-budget -1: out of range"),
        (
            vec!["--base-frequency", "1e-300"],
            "--base-frequency 1e-300: out of range; expected a number with 0.000001 ≤ x ≤ 1000 (Hz)",
        ),
    ];
    let urdf = ur5();
    for (flags, message) in cases {
        let mut args: Vec<&std::ffi::OsStr> =
            vec!["simulate".as_ref(), urdf.as_os_str(), "-o".as_ref(), out.as_os_str()];
        args.extend(flags.iter().map(|f| std::ffi::OsStr::new(*f)));
        let o = common::dyngen(&args);
        assert_exit(&o, 2, message);
    }
    assert!(!out.exists());
    assert_exit(
        &run!("generate", ur5(), "--name", "Ur5", "--max-statements", "0"),
        2,
        "--max-statements 0: out of range; expected a whole number from 100 to 10000000",
    );
    // The ranges are in the help.
    let help = stdout(&run!("simulate", "--help"));
    assert!(help.contains("0 < s ≤ 1e6") && help.contains("1 to 1000000"), "{help}");
}

#[test]
fn a_recording_with_a_byte_order_mark_is_read() {
    let dir = temp_dir("dyngen-hostile", "bom");
    let urdf = pendulum(&dir, "pendulum.urdf", "1");
    let csv = dir.join("bom.csv");
    std::fs::write(&csv, format!("\u{feff}{}", pendulum_rows())).unwrap();
    let o = run!("identify", urdf, csv);
    assert_ok(&o);
    assert!(stdout(&o).contains("40 samples of 1 joints"), "{}", stdout(&o));
}
