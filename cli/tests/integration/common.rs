//! Helpers shared by the `dyngen` binary's tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn ur5() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../robots/ur5/ur5.urdf")
}

/// A one-link pendulum URDF of the given mass (`"1"`; `"-1"` for a broken one)
/// written to `dir/name`; its `<link name="arm">` is on line 3.
pub fn pendulum(dir: &Path, name: &str, mass: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            r#"<robot name="{}">
  <link name="base"/>
  <link name="arm"><inertial>
    <mass value="{mass}"/><origin xyz="0 0 -0.5"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/></joint>
</robot>
"#,
            name.trim_end_matches(".urdf")
        ),
    )
    .unwrap();
    path
}

/// A fresh directory for one test, under `group`.
pub fn temp_dir(group: &str, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(group).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn dyngen(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dyngen"))
        .args(args)
        .output()
        .expect("run dyngen")
}

/// Runs `dyngen` with the given arguments (anything `AsRef<OsStr>`).
macro_rules! run {
    ($($arg:expr),* $(,)?) => {
        $crate::common::dyngen(&[$(std::ffi::OsStr::new(&$arg)),*])
    };
}
pub(crate) use run;

/// The overall relative error `validate` prints, as a fraction.
pub fn overall(out: &str) -> f64 {
    out.lines()
        .find_map(|l| l.strip_prefix("overall relative error "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|x| x.parse::<f64>().ok())
        .map(|p| p / 100.0)
        .unwrap_or_else(|| panic!("no overall error in:\n{out}"))
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[track_caller]
pub fn assert_ok(o: &Output) {
    assert!(
        o.status.success(),
        "dyngen failed ({:?}):\n{}\n{}",
        o.status,
        stdout(o),
        stderr(o)
    );
}

/// A failure (exit codes 1–5), one `error: ` message containing `needle`, no panic.
#[track_caller]
pub fn assert_error(o: &Output, needle: &str) {
    let err = stderr(o);
    assert!(
        matches!(o.status.code(), Some(1..=5)),
        "{:?}\nstdout:\n{}\nstderr:\n{err}",
        o.status,
        stdout(o)
    );
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains(needle), "expected `{needle}` in:\n{err}");
    assert!(!err.contains("panicked") && !err.contains("internal error"), "{err}");
}

/// Noise-free UR5 data from `dyngen simulate` along a Fourier motion with the random
/// feasible start (`--evaluations 0`: excitation enough for exact data, and fast in a
/// debug build), `steps` + 1 samples, in `dir/ur5.csv`; `extra` arguments are
/// passed on.
pub fn simulate_ur5(dir: &Path, steps: usize, extra: &[&str]) -> PathBuf {
    let csv = dir.join("ur5.csv");
    let steps = steps.to_string();
    let mut args: Vec<std::ffi::OsString> = vec!["simulate".into(), ur5().into(), "-o".into(), csv.clone().into()];
    for a in ["--experiment", "fourier", "--evaluations", "0", "--steps", &steps]
        .into_iter()
        .chain(extra.iter().copied())
    {
        args.push(a.into());
    }
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    assert_ok(&dyngen(&args));
    csv
}

/// `csv` without its joint wrench columns (keeps t, q, v, a, tau: the first
/// 1 + 4·6 columns of a 6-joint file), as `dir/bare.csv`.
pub fn without_wrenches(csv: &Path, dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(csv).unwrap();
    let bare: String = text
        .lines()
        .map(|l| l.split(',').take(25).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    let path = dir.join("bare.csv");
    std::fs::write(&path, bare).unwrap();
    path
}

/// Exit code `code` and an error message containing `needle`.
#[track_caller]
pub fn assert_exit(o: &Output, code: i32, needle: &str) {
    assert_error(o, needle);
    assert_eq!(o.status.code(), Some(code), "{}", stderr(o));
}
