//! Helpers shared by the `dyngen` binary's tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn ur5() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../robots/ur5/ur5.urdf")
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

/// Exit code 1, one `error: ` message containing `needle`, no panic.
#[track_caller]
pub fn assert_error(o: &Output, needle: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(1), "stdout:\n{}\nstderr:\n{err}", stdout(o));
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains(needle), "expected `{needle}` in:\n{err}");
    assert!(!err.contains("panicked") && !err.contains("internal error"), "{err}");
}
