//! `dyngen identify` on recordings in other layouts: recipes and their flags.

use crate::common;
use crate::common::{assert_error, assert_ok, run, simulate_ur5, stdout, temp_dir, ur5};
use std::fmt::Write;
use std::path::Path;

/// The torque residual RMS `identify` prints.
fn residual(out: &str) -> f64 {
    out.lines()
        .find_map(|l| l.strip_prefix("torque residual RMS "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("no residual line in:\n{out}"))
}

/// The simulated UR5 recording rewritten as a controller would log it: no header,
/// semicolons, degrees, motor currents (gain 2 N·m/A), joint 2 counting the other
/// way, every 10th row logged twice.
fn raw_log(csv: &Path, out: &Path) {
    let traj = dyngen_identify::data::read_csv(csv, None).unwrap();
    let deg = 180.0 / std::f64::consts::PI;
    let sign = |j: usize| if j == 1 { -1.0 } else { 1.0 };
    let mut text = String::new();
    for k in 0..traj.len() {
        let mut row = vec![traj.t()[k]];
        row.extend(traj.q(k).iter().enumerate().map(|(j, x)| sign(j) * x * deg));
        row.extend(traj.v(k).unwrap().iter().enumerate().map(|(j, x)| sign(j) * x * deg));
        row.extend(traj.a(k).unwrap().iter().enumerate().map(|(j, x)| sign(j) * x * deg));
        row.extend(traj.tau(k).iter().enumerate().map(|(j, x)| sign(j) * x / 2.0));
        let line = row.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(";");
        for _ in 0..if k % 10 == 5 { 2 } else { 1 } {
            writeln!(text, "{line}").unwrap();
        }
    }
    std::fs::write(out, text).unwrap();
}

#[test]
fn identify_reads_a_raw_log_through_flags_or_a_recipe() {
    let dir = temp_dir("dyngen-logs", "raw");
    let csv = simulate_ur5(&dir, 120, &[]);
    let log = dir.join("robot.log");
    raw_log(&csv, &log);

    let o = run!(
        "identify",
        ur5(),
        log,
        "--no-header",
        "--delimiter",
        "semicolon",
        "--degrees",
        "--gains",
        "2",
        "--recipe",
        {
            let recipe = dir.join("sign.recipe");
            std::fs::write(&recipe, "sign = 1, -1, 1, 1, 1, 1\n").unwrap();
            recipe
        }
    );
    assert_ok(&o);
    let out = stdout(&o);
    assert!(
        out.contains("133 rows read, 121 samples of 6 joints kept; dropped 12 repeated rows"),
        "{out}"
    );
    assert!(out.contains("(uniform)"), "{out}");
    assert!(out.contains("torque: motor currents × gains (columns 20–25)"), "{out}");
    assert!(
        out.contains("velocity: measured (columns 8–13); acceleration: measured (columns 14–19)"),
        "{out}"
    );
    assert!(out.contains("36 of 60 parameter directions identifiable"), "{out}");
    assert!(residual(&out) < 1e-8, "{out}");

    // The same through a recipe file naming the columns (no accelerations: they
    // are estimated), a window and decimation.
    let recipe = dir.join("log.recipe");
    std::fs::write(
        &recipe,
        "delimiter = semicolon\nheader = false\nq = 2-7\nv = 8-13\ntau = 20-25\nunits = deg\ngains = 2\n\
         sign = 1,-1,1,1,1,1\nwindow = 0.2:\ndecimate = 2\n",
    )
    .unwrap();
    let o = run!("identify", ur5(), log, "--recipe", recipe, "--cutoff", "1");
    assert_ok(&o);
    let out = stdout(&o);
    assert!(
        out.contains("acceleration: estimated by zero-phase differentiation (low-pass 1 Hz"),
        "{out}"
    );
    assert!(out.contains("rows by decimation"), "{out}");
    assert!(out.contains("rows outside the time window"), "{out}");
}

#[test]
fn log_errors_name_the_line_column_or_flag() {
    let dir = temp_dir("dyngen-logs", "errors");
    let pendulum = common::pendulum(&dir, "pendulum.urdf", "1");
    let log = dir.join("p.log");
    std::fs::write(&log, "0;0;0\n0.01;inf;0\n0.02;0;0\n").unwrap();
    assert_error(
        &run!("identify", pendulum, log, "--no-header", "--delimiter", "semicolon"),
        "p.log: line 2, column 2 (q1): inf is not a finite number",
    );
    assert_error(
        &run!("identify", pendulum, log, "--decimate", "0"),
        "--decimate: `decimate = 0`: expected a whole number ≥ 1",
    );
    assert_error(
        &run!("identify", pendulum, log, "--window", "-1"),
        "--window: `window = -1`: expected `t0:t1` in seconds",
    );
    let recipe = dir.join("bad.recipe");
    std::fs::write(&recipe, "header = false\ndelimiter = pipe\n").unwrap();
    assert_error(
        &run!("identify", pendulum, log, "--recipe", recipe),
        "bad.recipe: line 2: `delimiter = pipe`: expected `comma`, `semicolon`, `tab` or `whitespace`",
    );
    // Time that goes back is not a duplicate.
    std::fs::write(&log, "t,q1,tau1\n0,0,0\n0.02,0,0\n0.01,0,0\n").unwrap();
    assert_error(
        &run!("identify", pendulum, log),
        "line 4, column `t`: time t = 0.01 s is before",
    );
}

#[test]
fn the_example_recipe_parses() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/example.recipe");
    let recipe = dyngen_identify::data::Recipe::from_file(&path).unwrap();
    assert_eq!(recipe.gains.as_ref().map(Vec::len), Some(6));
    assert_eq!(recipe.signs, vec![1.0, -1.0, 1.0, 1.0, 1.0, 1.0]);
}
