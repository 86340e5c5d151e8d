//! One error type for everything the data module reads, checks, filters and writes.
//! Each variant says where (file line, or sample index for data built in memory) and
//! what would have been valid.

use std::fmt;
use std::path::PathBuf;

/// Where a value sits: a line of a CSV file (1-based, as an editor shows it), or a
/// sample index (0-based) of a trajectory built in memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    Line(u64),
    Sample(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(line) => write!(f, "line {line}"),
            Location::Sample(k) => write!(f, "sample {k} (0-based)"),
        }
    }
}

/// A column of a log read through a [`Recipe`](super::Recipe), as errors name it:
/// its 1-based position, its header name when the file has one, and what the
/// recipe reads from it (`t`, `q3`, `tau2`, `current2`, …).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    pub index: usize,
    pub name: Option<String>,
    pub role: String,
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.name {
            // The schema's own names: the name says it all, as the plain reader does.
            Some(name) if *name == self.role => write!(f, "column `{name}`"),
            Some(name) => write!(f, "column {} `{name}` ({})", self.index, self.role),
            None => write!(f, "column {} ({})", self.index, self.role),
        }
    }
}

/// Largest magnitude a value may have in SI units, after the recipe's scaling: a
/// larger one is a unit or column mistake (or a sensor fault), not a measurement.
pub const MAX_ABS_VALUE: f64 = 1e6;

/// Longest line a recording may have, in bytes (1 MiB, terminator excluded): tens
/// of thousands of numbers. A longer line is refused before it is read whole (a
/// binary file, `/dev/zero`, a file whose line breaks were lost).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Largest column number a recipe may name: no line within [`MAX_LINE_BYTES`] has
/// more fields than this (each needs at least one byte and a separator).
pub const MAX_COLUMNS: usize = MAX_LINE_BYTES / 2;

/// Bad data or a failed read/write. Messages name the line (1-based file line) and
/// the column, and say what would be valid.
///
/// The CSV reader collects up to [`MAX_ERRORS`](super::MAX_ERRORS) errors in one pass
/// and returns a single one as itself, several as [`DataError::Multiple`]; use
/// [`DataError::errors`] to go through them either way.
#[derive(Debug)]
#[non_exhaustive]
pub enum DataError {
    /// The file could not be opened, read or written.
    Io {
        path: Option<PathBuf>,
        source: std::io::Error,
    },
    /// [`write_csv`](super::write_csv) refuses to replace an existing file.
    FileExists { path: PathBuf },
    /// The input has no lines at all (or only blank ones).
    Empty,
    /// The first line holds numbers (or nothing), not column names.
    MissingHeader { line: u64, found: String },
    /// A header name that is not in the schema for this number of joints.
    UnknownColumn {
        line: u64,
        column: String,
        position: usize,
        valid: String,
    },
    /// The same column name twice in the header (`first`, `second`: 1-based positions).
    DuplicateColumn {
        line: u64,
        column: String,
        first: usize,
        second: usize,
    },
    /// A column the schema requires (`t`, every `q`, every `tau`) is absent.
    MissingColumn { line: u64, column: String, valid: String },
    /// Part of an optional group (`v`, `a`, joint wrenches) is present, part is not.
    IncompleteGroup {
        line: u64,
        group: &'static str,
        present: usize,
        missing: Vec<String>,
    },
    /// The number of joints asked for differs from the file's `q` columns.
    DofMismatch { line: u64, expected: usize, found: usize },
    /// A row with too few or too many fields.
    FieldCount { line: u64, expected: usize, found: usize },
    /// A field that does not parse as a number.
    NotANumber { line: u64, column: String, text: String },
    /// NaN or ±infinity.
    NonFinite { at: Location, column: String, value: f64 },
    /// `t` not strictly increasing.
    NonMonotonicTime { at: Location, t: f64, previous: f64 },
    /// Too few samples: a trajectory needs 2, a second difference 3.
    TooFewSamples { found: usize, needed: usize },
    /// A time step that differs from the mean step by more than 1 %.
    NonUniformSampling { at: Location, step: f64, nominal: f64 },
    /// An in-memory array whose length does not fit the trajectory.
    LengthMismatch {
        what: &'static str,
        expected: usize,
        found: usize,
    },
    /// An argument out of its valid range (`dof`, `dt`, `cutoff_hz`).
    InvalidArgument {
        name: &'static str,
        value: f64,
        expected: String,
    },
    /// A whole optional group (`v`, `a`, joint wrenches) that a computation needs is
    /// absent; `columns` names it, `needed_for` says what needs it.
    MissingGroup {
        group: &'static str,
        columns: String,
        needed_for: &'static str,
    },
    /// The CSV layer itself failed (for example invalid UTF-8).
    Malformed { line: Option<u64>, message: String },
    /// A recipe that cannot be applied to this input (see [`RecipeError`](super::RecipeError)).
    Recipe(super::RecipeError),
    /// A recipe column given by name that the header does not have.
    ColumnNotInHeader {
        line: u64,
        key: &'static str,
        name: String,
        header: Vec<String>,
    },
    /// A recipe column given by position beyond the fields of the line.
    ColumnOutOfRange {
        line: u64,
        key: &'static str,
        index: usize,
        width: usize,
    },
    /// One column given for two roles.
    ColumnTwice {
        index: usize,
        first: String,
        second: String,
    },
    /// A recipe list (`gains`, `units`, `sign`) whose length fits neither all joints
    /// at once (1) nor one per joint (`dof`).
    RecipeLength {
        key: &'static str,
        found: usize,
        dof: usize,
    },
    /// A recipe column list (`q`, `v`, `a`, `tau`) with other than one column per joint.
    RecipeColumns {
        key: &'static str,
        found: usize,
        dof: usize,
    },
    /// Without a header or column settings, a row whose field count matches no
    /// layout of the writer's column order.
    NoLayout {
        line: u64,
        found: usize,
        dof: Option<usize>,
    },
    /// A row with a different field count from the row that set the width.
    RowWidth {
        line: u64,
        expected: usize,
        found: usize,
        reference: u64,
    },
    /// A field of a log read through a recipe that does not parse as a number.
    NotANumberIn { line: u64, field: Field, text: String },
    /// A NaN or infinite field of a log read through a recipe.
    NonFiniteIn { line: u64, field: Field, value: f64 },
    /// A finite field whose magnitude in SI units, after scaling, exceeds
    /// [`MAX_ABS_VALUE`].
    OutOfRange { line: u64, field: Field, value: f64 },
    /// A time stamp below the previous one (an equal one is a duplicate, dropped).
    TimeNotIncreasing {
        line: u64,
        field: Field,
        t: f64,
        previous: f64,
        previous_line: u64,
    },
    /// Too few samples left after windows, duplicates and decimation for `purpose`.
    TooFewSamplesLeft {
        found: usize,
        needed: usize,
        purpose: &'static str,
        rows: usize,
        dropped: usize,
    },
    /// The first line does not split at the delimiter in use but does at another:
    /// the file is, say, semicolon-separated and read as comma-separated.
    Separator {
        line: u64,
        used: super::Delimiter,
        found: super::Delimiter,
        fields: usize,
    },
    /// A line longer than [`MAX_LINE_BYTES`] (`limit`), refused before reading it whole.
    LineTooLong { line: u64, limit: usize },
    /// Several errors found in one pass (at most [`MAX_ERRORS`](super::MAX_ERRORS));
    /// `truncated` when reading stopped there.
    Multiple { errors: Vec<DataError>, truncated: bool },
}

impl DataError {
    /// The individual errors: the errors of a [`DataError::Multiple`], or `self`.
    pub fn errors(&self) -> &[DataError] {
        match self {
            DataError::Multiple { errors, .. } => errors,
            other => std::slice::from_ref(other),
        }
    }

    /// The 1-based file line this error is about, when it is about one line.
    pub fn line(&self) -> Option<u64> {
        match self {
            DataError::MissingHeader { line, .. }
            | DataError::UnknownColumn { line, .. }
            | DataError::DuplicateColumn { line, .. }
            | DataError::MissingColumn { line, .. }
            | DataError::IncompleteGroup { line, .. }
            | DataError::DofMismatch { line, .. }
            | DataError::FieldCount { line, .. }
            | DataError::NotANumber { line, .. }
            | DataError::ColumnNotInHeader { line, .. }
            | DataError::ColumnOutOfRange { line, .. }
            | DataError::NoLayout { line, .. }
            | DataError::RowWidth { line, .. }
            | DataError::NotANumberIn { line, .. }
            | DataError::NonFiniteIn { line, .. }
            | DataError::OutOfRange { line, .. }
            | DataError::TimeNotIncreasing { line, .. }
            | DataError::Separator { line, .. }
            | DataError::LineTooLong { line, .. } => Some(*line),
            DataError::Recipe(e) => e.line(),
            DataError::NonFinite { at, .. }
            | DataError::NonMonotonicTime { at, .. }
            | DataError::NonUniformSampling { at, .. } => match at {
                Location::Line(line) => Some(*line),
                Location::Sample(_) => None,
            },
            DataError::Malformed { line, .. } => *line,
            DataError::Multiple { errors, .. } => errors.first().and_then(DataError::line),
            _ => None,
        }
    }

    /// The error of a failed `io` operation on `path`.
    pub(crate) fn io(path: Option<PathBuf>, source: std::io::Error) -> Self {
        DataError::Io { path, source }
    }
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DataError::Io { path: Some(path), source } => write!(f, "cannot access `{}`: {source}", path.display()),
            DataError::Io { path: None, source } => write!(f, "input/output error: {source}"),
            DataError::FileExists { path } => write!(
                f,
                "`{}` already exists; refusing to overwrite it (use `overwrite_csv` to replace it)",
                path.display()
            ),
            DataError::Empty => write!(
                f,
                "the input is empty; expected a header line `t, q1, …, tau1, …` followed by at least 2 rows"
            ),
            DataError::MissingHeader { line, found } => write!(
                f,
                "line {line}: expected a header of column names (`t, q1, …, tau1, …`), found `{found}`"
            ),
            DataError::UnknownColumn { line, column, position, valid } => {
                write!(f, "line {line}, column {position}: unknown column `{column}`; valid columns: {valid}")
            }
            DataError::DuplicateColumn { line, column, first, second } => {
                write!(f, "line {line}: column `{column}` appears twice (columns {first} and {second})")
            }
            DataError::MissingColumn { line, column, valid } => {
                write!(f, "line {line}: missing required column `{column}`; a file needs {valid}")
            }
            DataError::IncompleteGroup { line, group, present, missing } => write!(
                f,
                "line {line}: incomplete {group} columns: {present} present but {} missing ({}); give all of them or none",
                missing.len(),
                missing.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", ")
            ),
            DataError::DofMismatch { line, expected, found } => write!(
                f,
                "line {line}: the header has `q1`..`q{found}` ({found} joints) but {expected} joints were expected \
                 (`q1`..`q{expected}`)"
            ),
            DataError::FieldCount { line, expected, found } => {
                let what = if found < expected { "too few" } else { "too many" };
                write!(f, "line {line}: {what} fields: {found}, expected {expected} (one per header column)")
            }
            DataError::NotANumber { line, column, text } if text.is_empty() => {
                write!(f, "line {line}, column `{column}`: empty field; expected a number")
            }
            DataError::NotANumber { line, column, text } => {
                write!(f, "line {line}, column `{column}`: `{text}` is not a number")
            }
            DataError::NonFinite { at, column, value } => {
                write!(f, "{at}, column `{column}`: {value} is not a finite number")
            }
            DataError::NonMonotonicTime { at, t, previous } => write!(
                f,
                "{at}: time t = {t} s does not increase (previous t = {previous} s); t must be strictly increasing"
            ),
            DataError::TooFewSamples { found, needed } => {
                write!(f, "{found} sample(s); at least {needed} are needed")
            }
            DataError::NonUniformSampling { at, step, nominal } => write!(
                f,
                "{at}: time step {step} s differs from the mean step {nominal} s by {:.3} %; \
                 filtering and differentiation need uniform sampling (within 1 %)",
                100.0 * (step - nominal).abs() / nominal
            ),
            DataError::LengthMismatch { what, expected, found } => {
                write!(f, "`{what}` has {found} values, expected {expected}")
            }
            DataError::InvalidArgument { name, value, expected } => {
                write!(f, "invalid `{name}` = {value}: expected {expected}")
            }
            DataError::MissingGroup { group, columns, needed_for } => {
                write!(f, "the data have no {group} columns ({columns}); {needed_for} needs them")
            }
            DataError::Malformed { line: Some(line), message } => write!(f, "line {line}: malformed CSV: {message}"),
            DataError::Malformed { line: None, message } => write!(f, "malformed CSV: {message}"),
            DataError::Recipe(e) => write!(f, "recipe: {e}"),
            DataError::ColumnNotInHeader { line, key, name, header } => write!(
                f,
                "line {line}: recipe `{key}` names column `{name}`, which the header does not have; its columns are {}",
                header.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", ")
            ),
            DataError::ColumnOutOfRange { line, key, index, width } => write!(
                f,
                "line {line}: recipe `{key}` names column {index}, but the line has {width} field(s); \
                 columns are numbered 1 to {width}"
            ),
            DataError::ColumnTwice { index, first, second } => write!(
                f,
                "column {index} is given both as {first} and as {second}; each column holds one quantity"
            ),
            DataError::RecipeLength { key, found, dof } => write!(
                f,
                "recipe `{key}` has {found} value(s); give 1 (for every joint) or {dof} (one per joint)"
            ),
            DataError::RecipeColumns { key, found, dof } => write!(
                f,
                "recipe `{key}` names {found} column(s); give one per joint ({dof}, the number of `q` columns or \
                 of the robot's joints)"
            ),
            DataError::NoLayout { line, found, dof } => {
                write!(f, "line {line}: {found} fields and no header or column settings; ")?;
                match dof {
                    Some(n) => write!(
                        f,
                        "for {n} joints the columns must be t, q1..q{n}, tau1..tau{n} ({} fields), with v1..v{n} \
                         before tau ({}), or v and a ({}), optionally followed by the 6·{n} joint wrench columns; \
                         otherwise name the columns in a recipe (`time`, `q`, `tau`, …)",
                        1 + 2 * n,
                        1 + 3 * n,
                        1 + 4 * n
                    ),
                    None => write!(
                        f,
                        "without the number of joints the columns must be t, q1..qn, tau1..taun (an odd number \
                         of fields); otherwise name the columns in a recipe (`time`, `q`, `tau`, …)"
                    ),
                }
            }
            DataError::RowWidth { line, expected, found, reference } => write!(
                f,
                "line {line}: {found} fields, expected {expected} like line {reference}; every row needs the same \
                 columns"
            ),
            DataError::NotANumberIn { line, field, text } if text.is_empty() => {
                write!(f, "line {line}, {field}: empty field; expected a number")
            }
            DataError::NotANumberIn { line, field, text } => {
                write!(f, "line {line}, {field}: `{text}` is not a number")
            }
            DataError::NonFiniteIn { line, field, value } => {
                write!(f, "line {line}, {field}: {value} is not a finite number")
            }
            DataError::OutOfRange { line, field, value } => {
                write!(
                    f,
                    "line {line}, {field}: {value:e} after scaling to SI units; values must lie within ±{MAX_ABS_VALUE:e}"
                )?;
                if field.role == "t" {
                    write!(f, " (check `time_unit`; for clock time stamps set `time_origin = first`)")
                } else {
                    write!(f, " (check the column and its unit, gain or scale)")
                }
            }
            DataError::TimeNotIncreasing { line, field, t, previous, previous_line } => write!(
                f,
                "line {line}, {field}: time t = {t} s is before t = {previous} s on line {previous_line}; \
                 time must increase (rows with an equal time stamp are dropped as duplicates)"
            ),
            DataError::TooFewSamplesLeft { found, needed, purpose, rows, dropped } => write!(
                f,
                "{found} sample(s) left of {rows} row(s) read ({dropped} dropped as duplicates, outside the \
                 windows or by decimation); {purpose} needs at least {needed}"
            ),
            DataError::Separator { line, used, found, fields } => {
                let mark = |d: super::Delimiter| match d {
                    super::Delimiter::Comma => "`,`",
                    super::Delimiter::Semicolon => "`;`",
                    super::Delimiter::Tab => "tab",
                    super::Delimiter::Whitespace => "space",
                };
                let name = found.name();
                write!(
                    f,
                    "line {line}: no {} separates the fields, but a {} splits the line into {fields}: the file looks \
                     {name}-separated; read it with `delimiter = {name}` in a recipe (`--delimiter {name}` on the \
                     command line)",
                    mark(*used),
                    mark(*found),
                )
            }
            DataError::LineTooLong { line, limit } => write!(
                f,
                "line {line} is longer than {limit} bytes ({} MiB) without a line break; a recording holds one \
                 sample per line, so this is not a text recording (a binary file?) or its line breaks are lost",
                limit >> 20
            ),
            DataError::Multiple { errors, truncated } => {
                write!(f, "{} errors", errors.len())?;
                if *truncated {
                    write!(f, " (stopped reading there)")?;
                }
                write!(f, ":")?;
                for e in errors {
                    write!(f, "\n  {e}")?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for DataError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            DataError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
