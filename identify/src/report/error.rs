//! The one error type of the report outputs: each names the file, link or line.

use std::fmt;

/// Why writing or reading a report failed.
#[derive(Clone, Debug, PartialEq)]
pub enum ReportError {
    /// The file exists and overwriting was not asked for.
    Exists {
        path: String,
    },
    Io {
        path: String,
        message: String,
    },
    /// The JSON does not follow the schema (1-based line and column).
    Json {
        message: String,
        line: usize,
        column: usize,
    },
    /// The URDF text is not well-formed enough to edit (1-based line).
    Xml {
        line: usize,
        message: String,
    },
    /// No `<link>` of that name in the URDF.
    LinkNotFound {
        link: String,
    },
    /// No `<joint>` of that name in the URDF, or several (lines of each).
    JointNotFound {
        joint: String,
        lines: Vec<usize>,
    },
    /// Friction to write that is negative or not finite.
    InvalidDynamics {
        joint: String,
        damping: f64,
        friction: f64,
    },
    /// Two `<link>` elements share the name (lines of both).
    DuplicateLink {
        link: String,
        lines: Vec<usize>,
    },
    /// The same link appears twice in the updates.
    DuplicateUpdate {
        link: String,
    },
    /// The link is not a moving body of its own: it hangs on `body` through fixed
    /// joints (`body` is `None` when that is the fixed base), so identification has
    /// no inertial for it alone.
    NotABody {
        link: String,
        line: usize,
        body: Option<String>,
    },
    /// The body's inertial lumps links attached through fixed joints; writing it to
    /// the body's link alone would count their mass twice. See [`super::MergedLinks`].
    MergedLinks {
        link: String,
        line: usize,
        merged: Vec<String>,
    },
    /// The inertial is not physical ([`dyngen_model::check_physical`]): a number is
    /// not finite, the mass is negative, or the inertia is not positive
    /// semi-definite or breaks the triangle inequality.
    InvalidInertial {
        link: String,
        reason: String,
    },
    /// Array lengths do not agree (`what` names the argument).
    DimensionMismatch {
        what: String,
        expected: usize,
        found: usize,
    },
    /// A number to plot is NaN or infinite.
    NonFinite {
        what: String,
        index: usize,
    },
    /// The plotting library failed.
    Plot {
        message: String,
    },
}

impl fmt::Display for ReportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Exists { path } => write!(f, "{path}: file exists (pass overwrite to replace it)"),
            Self::Io { path, message } => write!(f, "{path}: {message}"),
            Self::Json { message, line, column } => write!(f, "JSON line {line}, column {column}: {message}"),
            Self::Xml { line, message } => write!(f, "URDF line {line}: {message}"),
            Self::LinkNotFound { link } => write!(f, "no <link name=\"{link}\"> in the URDF"),
            Self::JointNotFound { joint, lines } if lines.is_empty() => {
                write!(f, "no <joint name=\"{joint}\"> in the URDF")
            }
            Self::JointNotFound { joint, lines } => {
                let lines: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
                write!(
                    f,
                    "<joint name=\"{joint}\"> appears on lines {}; joint names must be unique",
                    lines.join(", ")
                )
            }
            Self::InvalidDynamics {
                joint,
                damping,
                friction,
            } => write!(
                f,
                "joint `{joint}`: <dynamics damping=\"{damping}\" friction=\"{friction}\"> is not a physical friction \
                 (both must be finite and ≥ 0)"
            ),
            Self::DuplicateLink { link, lines } => {
                let lines: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
                write!(
                    f,
                    "link `{link}` is defined more than once (lines {})",
                    lines.join(", ")
                )
            }
            Self::DuplicateUpdate { link } => write!(f, "link `{link}` is given two inertials"),
            Self::NotABody { link, line, body } => match body {
                Some(b) => write!(
                    f,
                    "URDF line {line}: link `{link}` is attached to `{b}` by fixed joints and identified as part of \
                     it; give the inertial of `{b}` instead"
                ),
                None => write!(
                    f,
                    "URDF line {line}: link `{link}` belongs to the fixed base, whose inertia has no effect and is \
                     not identified"
                ),
            },
            Self::MergedLinks { link, line, merged } => write!(
                f,
                "URDF line {line}: the identified inertial of `{link}` includes the fixed-joint links [{}]; \
                 pass MergedLinks::Lump to write it to `{link}` and remove their <inertial> elements",
                merged.join(", ")
            ),
            Self::InvalidInertial { link, reason } => write!(f, "inertial of `{link}`: {reason}"),
            Self::DimensionMismatch { what, expected, found } => {
                write!(f, "dimension mismatch in {what}: expected {expected}, found {found}")
            }
            Self::NonFinite { what, index } => write!(f, "non-finite value in {what} at index {index}"),
            Self::Plot { message } => write!(f, "plotting failed: {message}"),
        }
    }
}

impl std::error::Error for ReportError {}
