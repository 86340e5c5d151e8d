//! What several test files of the model crate share.

use dyngen_model::load_mjcf;
use std::path::{Path, PathBuf};

/// A fresh folder under the temporary directory, named for the test and the process,
/// removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("dyngen-test-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    /// Writes `contents` to `name` (folders made as needed) and returns its path.
    pub fn write(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let path = self.0.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, contents).unwrap();
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The refusal of `load_mjcf(top)`: its only error, on `line` of the top-level file
/// (`top.xml`), saying `says`. Returns the whole message.
pub fn load_error(top: &Path, line: usize, says: &str) -> String {
    let e = load_mjcf(top).expect_err("should be refused");
    assert_eq!(e.errors.len(), 1, "{e}");
    assert_eq!(e.errors[0].line, Some(line), "{e}");
    let message = e.to_string();
    assert!(message.contains(&format!("top.xml:{line}: ")), "{message}");
    assert!(message.contains(says), "{message}");
    message
}
