//! The one error type of the neural-network identifier: every failure names what
//! failed and where, and says what would have been valid.

use std::fmt;
use std::path::PathBuf;

/// Which half of a [`Dataset`](super::Dataset) an element belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// The network inputs (features).
    Inputs,
    /// The training targets.
    Targets,
}

impl fmt::Display for Part {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Part::Inputs => "input",
            Part::Targets => "target",
        })
    }
}

/// Why building, training, saving or loading a network failed. Nothing in
/// [`nim`](super) panics on user data except the allocation-free inference calls,
/// which document their panics.
#[derive(Clone, Debug, PartialEq)]
pub enum NimError {
    /// The layer sizes do not describe a network.
    InvalidSizes { sizes: Vec<usize>, reason: String },
    /// A length or count does not match (`what` names the argument).
    DimensionMismatch {
        what: &'static str,
        expected: usize,
        found: usize,
    },
    /// Row `row` of a dataset part is not as long as its first row.
    RowLength {
        part: Part,
        row: usize,
        expected: usize,
        found: usize,
    },
    /// A dataset, or one part of a split, has no samples.
    Empty { what: &'static str },
    /// A NaN or infinity in a dataset, at sample `row` and feature `column` (both
    /// 0-based).
    NonFinite {
        part: Part,
        row: usize,
        column: usize,
        value: f64,
    },
    /// A training option or split argument is outside its domain.
    InvalidOption { field: &'static str, reason: String },
    /// The training MSE became NaN or infinite (learning rate too large).
    Diverged { step: usize, mse: f64 },
    /// The JSON does not name the schema this version reads (`None`: no `schema`
    /// field).
    Schema {
        found: Option<String>,
        expected: &'static str,
    },
    /// A stored array has the wrong shape: `layer` (0-based) is `None` for the
    /// top-level fields (`sizes`, the standardisers).
    Shape {
        layer: Option<usize>,
        field: String,
        expected: String,
        found: String,
    },
    /// A stored number is invalid (non-finite weight, non-positive standard
    /// deviation, …).
    InvalidValue { field: String, reason: String },
    /// The text is not JSON of the expected structure (serde's message, with line
    /// and column).
    Json { message: String },
    /// [`Mlp::save`](super::Mlp::save) with `overwrite = false` found a file there.
    AlreadyExists { path: PathBuf },
    /// Reading or writing a file failed.
    Io { path: PathBuf, message: String },
    /// An error inside a part of a larger file or model (`context` names it, e.g.
    /// `encoder` or `bodies[2].net`).
    In { context: String, error: Box<NimError> },
}

impl NimError {
    /// This error as part of `context`.
    pub(crate) fn within(self, context: impl Into<String>) -> NimError {
        NimError::In {
            context: context.into(),
            error: Box::new(self),
        }
    }

    pub(crate) fn io(path: &std::path::Path, e: std::io::Error) -> NimError {
        NimError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }
}

impl fmt::Display for NimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidSizes { sizes, reason } => write!(
                f,
                "invalid layer sizes {sizes:?}: {reason} (expected [inputs, hidden…, outputs], at least two \
                 sizes, all positive)"
            ),
            Self::DimensionMismatch { what, expected, found } => {
                write!(f, "dimension mismatch in {what}: expected {expected}, found {found}")
            }
            Self::RowLength {
                part,
                row,
                expected,
                found,
            } => write!(
                f,
                "{part} row {row} has {found} values, expected {expected} (the length of {part} row 0)"
            ),
            Self::Empty { what } => write!(f, "{what} has no samples; at least one is needed"),
            Self::NonFinite {
                part,
                row,
                column,
                value,
            } => write!(
                f,
                "non-finite {part} value {value} at row {row}, {part} column {column} (0-based); every value \
                 must be finite"
            ),
            Self::InvalidOption { field, reason } => write!(f, "invalid {field}: {reason}"),
            Self::Diverged { step, mse } => write!(
                f,
                "training diverged: the training MSE is {mse} after {step} steps; lower the learning rate"
            ),
            Self::Schema {
                found: Some(found),
                expected,
            } => write!(f, "unsupported schema {found:?}: this version reads \"{expected}\""),
            Self::Schema { found: None, expected } => {
                write!(f, "missing `schema` field: expected \"schema\": \"{expected}\"")
            }
            Self::Shape {
                layer,
                field,
                expected,
                found,
            } => match layer {
                Some(l) => write!(f, "layer {l}: `{field}` has shape {found}, expected {expected}"),
                None => write!(f, "`{field}` has shape {found}, expected {expected}"),
            },
            Self::InvalidValue { field, reason } => write!(f, "invalid value in `{field}`: {reason}"),
            Self::Json { message } => write!(f, "invalid network JSON: {message}"),
            Self::AlreadyExists { path } => write!(
                f,
                "refusing to overwrite existing file {}; pass overwrite = true to replace it",
                path.display()
            ),
            Self::Io { path, message, .. } => write!(f, "{}: {message}", path.display()),
            Self::In { context, error } => write!(f, "{context}: {error}"),
        }
    }
}

impl std::error::Error for NimError {}
