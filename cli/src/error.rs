//! The command line's one error type, and the exit code of each kind of failure.

use std::fmt;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The exit codes, as `dyngen --help` and the README list them.
pub const EXIT_CODES: &str = "\
Exit codes:
  0  success
  1  the computation failed (identification, training, an internal error)
  2  usage: unknown flag, missing argument, invalid or conflicting option values
  3  bad input: a URDF, recording, recipe or weights file that cannot be read or is
     invalid (the message names the file, line and column)
  4  an output file exists (pass --force to replace it)
  5  an output file could not be written";

/// Why a command failed; [`CliError::exit_code`] says how `dyngen` exits.
#[derive(Debug)]
pub enum CliError {
    /// An option value or combination that cannot work.
    Usage(String),
    /// An input file that cannot be read, or whose content is invalid: the message
    /// names the file (and line and column where there is one).
    Input(String),
    /// The computation failed on valid input.
    Failed(String),
    /// The output file exists and --force was not given.
    OutputExists(PathBuf),
    /// Writing an output failed.
    Output(String),
}

impl CliError {
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Failed(_) => 1,
            CliError::Usage(_) => 2,
            CliError::Input(_) => 3,
            CliError::OutputExists(_) => 4,
            CliError::Output(_) => 5,
        }
    }

    pub fn usage(message: impl Into<String>) -> CliError {
        CliError::Usage(message.into())
    }

    /// An input error about `path`.
    pub fn input(path: &Path, error: impl fmt::Display) -> CliError {
        CliError::Input(format!("{}: {error}", path.display()))
    }

    /// An output error about `path`.
    pub fn output(path: &Path, error: impl fmt::Display) -> CliError {
        CliError::Output(format!("{}: {error}", path.display()))
    }

    pub fn failed(error: impl fmt::Display) -> CliError {
        CliError::Failed(error.to_string())
    }

    /// A report error about `path`: an existing file is [`CliError::OutputExists`].
    pub fn report(path: &Path, e: dyngen_identify::report::ReportError) -> CliError {
        use dyngen_identify::report::ReportError;
        match e {
            ReportError::Exists { .. } => CliError::OutputExists(path.to_path_buf()),
            ReportError::Io { .. } => CliError::output(path, e),
            e => CliError::failed(format!("{}: {e}", path.display())),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Usage(m) | CliError::Input(m) | CliError::Failed(m) | CliError::Output(m) => f.write_str(m),
            CliError::OutputExists(path) => {
                write!(f, "{} already exists; pass --force to overwrite it", path.display())
            }
        }
    }
}

impl std::error::Error for CliError {}

impl From<CliError> for ExitCode {
    fn from(e: CliError) -> ExitCode {
        ExitCode::from(e.exit_code())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_has_its_own_code_and_the_codes_are_documented() {
        let errors = [
            CliError::Failed(String::new()),
            CliError::Usage(String::new()),
            CliError::Input(String::new()),
            CliError::OutputExists(PathBuf::new()),
            CliError::Output(String::new()),
        ];
        for (e, code) in errors.iter().zip(1..) {
            assert_eq!(e.exit_code(), code);
            assert!(EXIT_CODES.contains(&format!("\n  {code}  ")), "{code}");
        }
    }

    #[test]
    fn an_existing_report_file_is_output_exists() {
        let e = CliError::report(
            Path::new("x.json"),
            dyngen_identify::report::ReportError::Exists { path: "x.json".into() },
        );
        assert_eq!(e.exit_code(), 4);
        assert_eq!(e.to_string(), "x.json already exists; pass --force to overwrite it");
    }
}
