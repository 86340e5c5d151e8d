//! The one error type of identification: every failure names what failed and where.

use std::fmt;

/// Which input holds a non-finite number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    /// The regressor `A` (row, column).
    Regressor,
    /// The observation vector `y`.
    Observation,
    /// A prior or start vector supplied by the caller.
    Prior,
}

/// Why an identification call failed. Estimators never panic on user data; they
/// return one of these.
#[derive(Clone, Debug, PartialEq)]
pub enum IdentifyError {
    /// A length or column count does not match (`what` names the argument).
    DimensionMismatch {
        what: &'static str,
        expected: usize,
        found: usize,
    },
    /// No rows were given.
    Empty,
    /// A NaN or infinity at global data row `row` (0-based, counted over all rows
    /// pushed so far) and, for the regressor, column `column`.
    NonFinite { input: Input, row: usize, column: usize },
    /// A non-zero regressor entry at global data row `row`, column `column`,
    /// outside the columns declared for the row's channel
    /// ([`crate::Accumulator::with_column_support`]).
    OutsideSupport { row: usize, column: usize, channel: usize },
    /// Every singular value of the regressor is below the rank tolerance: the data
    /// determine nothing.
    RankZero { tolerance: f64 },
    /// Too few rows for the requested statistic (e.g. residual variance needs
    /// more rows than the rank).
    TooFewRows { needed: usize, found: usize },
    /// An iterative solver stopped before meeting its tolerance.
    NotConverged { algorithm: &'static str, iterations: usize },
    /// A dense decomposition (SVD) failed to converge inside faer.
    DecompositionFailed { what: &'static str },
    /// The total-least-squares problem has no solution: the smallest singular
    /// direction of `[A y]` has no `y` component (the nongeneric case).
    TlsNongeneric,
    /// A scalar argument is outside its domain (`what` names it, `reason` says why).
    InvalidArgument { what: &'static str, reason: String },
}

impl fmt::Display for IdentifyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::DimensionMismatch { what, expected, found } => {
                write!(f, "dimension mismatch in {what}: expected {expected}, found {found}")
            }
            Self::Empty => write!(f, "no data rows"),
            Self::NonFinite { input, row, column } => match input {
                Input::Regressor => write!(f, "non-finite regressor entry at row {row}, column {column}"),
                Input::Observation => write!(f, "non-finite observation at row {row}"),
                Input::Prior => write!(f, "non-finite entry {column} in the prior/start vector"),
            },
            Self::OutsideSupport { row, column, channel } => write!(
                f,
                "regressor row {row} (channel {channel}) is non-zero in column {column}, outside the columns \
                 declared for its channel"
            ),
            Self::RankZero { tolerance } => {
                write!(
                    f,
                    "the regressor has rank zero (every singular value ≤ {tolerance:.3e})"
                )
            }
            Self::TooFewRows { needed, found } => write!(f, "too few rows: need at least {needed}, have {found}"),
            Self::NotConverged { algorithm, iterations } => {
                write!(f, "{algorithm} did not converge in {iterations} iterations")
            }
            Self::DecompositionFailed { what } => write!(f, "{what} failed to converge"),
            Self::TlsNongeneric => write!(
                f,
                "total least squares has no solution: the smallest singular vector of [A y] has no y component"
            ),
            Self::InvalidArgument { what, reason } => write!(f, "invalid {what}: {reason}"),
        }
    }
}

impl std::error::Error for IdentifyError {}

/// Checks that every entry of a caller-supplied vector is finite.
pub(crate) fn check_finite_vector(v: &[f64], input: Input) -> Result<(), IdentifyError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(IdentifyError::NonFinite {
            input,
            row: 0,
            column: i,
        }),
        None => Ok(()),
    }
}

/// Checks a caller-supplied vector's length.
pub(crate) fn check_len(v: &[f64], expected: usize, what: &'static str) -> Result<(), IdentifyError> {
    if v.len() == expected {
        Ok(())
    } else {
        Err(IdentifyError::DimensionMismatch {
            what,
            expected,
            found: v.len(),
        })
    }
}
