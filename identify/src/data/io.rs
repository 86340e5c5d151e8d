//! Reading and writing the CSV schema of the module docs. The reader checks the
//! header against the schema first, then every field of every row, collecting errors
//! (up to [`MAX_ERRORS`]) so that one run shows what is wrong with a file.

use std::fs::{File, OpenOptions};
use std::io::{self, Read};
use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use super::error::{DataError, Location};
use super::lines::{skip_bom, LineIndex};
use super::recipe::Delimiter;
use super::trajectory::Trajectory;
use dyngen::Wrench;

/// The reader stops after this many errors and reports them together.
pub const MAX_ERRORS: usize = 20;

/// The joint wrench components, in the order of [`Wrench`]'s `force` then `torque`.
pub(super) const WRENCH_PREFIXES: [&str; 6] = ["fx", "fy", "fz", "mx", "my", "mz"];

/// What a header column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    T,
    Q,
    V,
    A,
    Tau,
    /// Component `0..6` of a joint wrench: `fx, fy, fz, mx, my, mz`.
    Wrench(usize),
}

/// One parsed header column: its kind and 1-based joint (0 for `t`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Column {
    pub(super) kind: Kind,
    pub(super) joint: usize,
}

impl Column {
    /// `t`, or a known prefix followed by a joint number written without leading zeros.
    fn parse(name: &str) -> Option<Column> {
        if name == "t" {
            return Some(Column {
                kind: Kind::T,
                joint: 0,
            });
        }
        let digits = name.find(|c: char| c.is_ascii_digit())?;
        let (prefix, number) = name.split_at(digits);
        if number.starts_with('0') || !number.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let joint: usize = number.parse().ok()?;
        let kind = match prefix {
            "q" => Kind::Q,
            "v" => Kind::V,
            "a" => Kind::A,
            "tau" => Kind::Tau,
            _ => Kind::Wrench(WRENCH_PREFIXES.iter().position(|p| *p == prefix)?),
        };
        Some(Column { kind, joint })
    }

    pub(super) fn name(self) -> String {
        let j = self.joint;
        match self.kind {
            Kind::T => "t".into(),
            Kind::Q => format!("q{j}"),
            Kind::V => format!("v{j}"),
            Kind::A => format!("a{j}"),
            Kind::Tau => format!("tau{j}"),
            Kind::Wrench(c) => format!("{}{j}", WRENCH_PREFIXES[c]),
        }
    }
}

/// The schema for `n` joints, in words, for error messages.
fn valid_columns(n: usize) -> String {
    if n == 0 {
        return "`t`, `q1`..`qn` and `tau1`..`taun` for n ≥ 1 joints, optionally `v1`..`vn`, `a1`..`an` and \
                `fx1, fy1, fz1, mx1, my1, mz1`, …, `mzn`"
            .into();
    }
    let range = |p: &str| {
        if n == 1 {
            format!("`{p}1`")
        } else {
            format!("`{p}1`..`{p}{n}`")
        }
    };
    format!(
        "`t`, {}, {} (required) and {}, {}, `fx1, fy1, fz1, mx1, my1, mz1`, …, `mz{n}` (optional) for {n} joint{}",
        range("q"),
        range("tau"),
        range("v"),
        range("a"),
        if n == 1 { "" } else { "s" }
    )
}

/// Collects errors up to [`MAX_ERRORS`].
pub(super) struct Errors {
    list: Vec<DataError>,
    pub(super) truncated: bool,
}

impl Errors {
    pub(super) fn new() -> Self {
        Errors {
            list: Vec::new(),
            truncated: false,
        }
    }

    /// Records `e`; `false` when the list is full and reading should stop.
    pub(super) fn push(&mut self, e: DataError) -> bool {
        if self.list.len() < MAX_ERRORS {
            self.list.push(e);
            true
        } else {
            self.truncated = true;
            false
        }
    }

    pub(super) fn full(&self) -> bool {
        self.list.len() >= MAX_ERRORS
    }

    pub(super) fn into_result(mut self) -> Result<(), DataError> {
        match self.list.len() {
            0 => Ok(()),
            1 if !self.truncated => Err(self.list.pop().expect("one error")),
            _ => Err(DataError::Multiple {
                errors: self.list,
                truncated: self.truncated,
            }),
        }
    }
}

/// The checked header: each field's column, the number of joints, which optional
/// groups are present.
pub(super) struct Header {
    pub(super) columns: Vec<Column>,
    pub(super) dof: usize,
    pub(super) has_v: bool,
    pub(super) has_a: bool,
    pub(super) has_wrenches: bool,
}

/// Checks the header row (on `line`) against the schema, collecting every problem.
pub(super) fn parse_header(names: &csv::StringRecord, line: u64, dof: Option<usize>) -> Result<Header, DataError> {
    if names.iter().all(|f| f.is_empty() || f.parse::<f64>().is_ok()) {
        return Err(DataError::MissingHeader {
            line,
            found: names.iter().collect::<Vec<_>>().join(","),
        });
    }
    if dof == Some(0) {
        return Err(DataError::InvalidArgument {
            name: "dof",
            value: 0.0,
            expected: "at least 1 joint (or `None` to take it from the `q` columns)".into(),
        });
    }
    let parsed: Vec<Option<Column>> = names.iter().map(Column::parse).collect();
    let max_q = parsed
        .iter()
        .flatten()
        .filter(|c| c.kind == Kind::Q)
        .map(|c| c.joint)
        .max();
    let mut errors = Errors::new();
    let n = match (dof, max_q) {
        (Some(n), Some(found)) if found > n => {
            errors.push(DataError::DofMismatch {
                line,
                expected: n,
                found,
            });
            n
        }
        (Some(n), _) => n,
        (None, Some(found)) => found,
        (None, None) => 0,
    };
    let valid = valid_columns(n);

    let mut columns = Vec::with_capacity(parsed.len());
    let mut seen: Vec<(Column, usize)> = Vec::new();
    for (i, (name, column)) in names.iter().zip(&parsed).enumerate() {
        let position = i + 1;
        match column {
            Some(c) if c.joint <= n => {
                if let Some(&(_, first)) = seen.iter().find(|(s, _)| s == c) {
                    errors.push(DataError::DuplicateColumn {
                        line,
                        column: name.into(),
                        first,
                        second: position,
                    });
                } else {
                    seen.push((*c, position));
                }
                columns.push(*c);
            }
            // Already reported as a mismatch of the number of joints.
            Some(c) if c.kind == Kind::Q && dof.is_some() => {}
            // No `q` column: the number of joints is unknown, and the missing `q1`
            // is the error to report, not every joint column.
            Some(_) if n == 0 => {}
            _ => {
                errors.push(DataError::UnknownColumn {
                    line,
                    column: name.into(),
                    position,
                    valid: valid.clone(),
                });
            }
        }
    }

    let has = |kind: Kind, joint: usize| seen.iter().any(|(c, _)| c.kind == kind && c.joint == joint);
    let mut required = vec![Column {
        kind: Kind::T,
        joint: 0,
    }];
    if n == 0 {
        required.push(Column {
            kind: Kind::Q,
            joint: 1,
        });
    }
    for kind in [Kind::Q, Kind::Tau] {
        required.extend((1..=n).map(|joint| Column { kind, joint }));
    }
    for c in required {
        if !has(c.kind, c.joint) {
            errors.push(DataError::MissingColumn {
                line,
                column: c.name(),
                valid: valid.clone(),
            });
        }
    }

    let mut group = |name: &'static str, kinds: &[Kind]| -> bool {
        let all: Vec<Column> = (1..=n)
            .flat_map(|joint| kinds.iter().map(move |&kind| Column { kind, joint }))
            .collect();
        let missing: Vec<String> = all.iter().filter(|c| !has(c.kind, c.joint)).map(|c| c.name()).collect();
        let present = all.len() - missing.len();
        if present > 0 && !missing.is_empty() {
            errors.push(DataError::IncompleteGroup {
                line,
                group: name,
                present,
                missing,
            });
        }
        present > 0
    };
    let has_v = group("velocity (`v`)", &[Kind::V]);
    let has_a = group("acceleration (`a`)", &[Kind::A]);
    let wrench_kinds: Vec<Kind> = (0..6).map(Kind::Wrench).collect();
    let has_wrenches = group("joint wrench (`fx`..`mz`)", &wrench_kinds);

    errors.into_result()?;
    Ok(Header {
        columns,
        dof: n,
        has_v,
        has_a,
        has_wrenches,
    })
}

/// The error of a first line that does not fit, replaced by a hint about the
/// separator when another one would have split that line: its many column errors
/// would only say the same thing less clearly.
pub(super) fn separator_hint(e: DataError, line: u64, used: Delimiter, other: Option<(Delimiter, usize)>) -> DataError {
    match other {
        Some((found, fields)) => DataError::Separator {
            line,
            used,
            found,
            fields,
        },
        None => e,
    }
}

/// Converts a csv-layer failure; `line` maps a byte offset to its file line.
fn csv_error(e: csv::Error, path: Option<&Path>, line: impl FnOnce(u64) -> u64) -> DataError {
    let line = e.position().map(|p| line(p.byte()));
    match e.into_kind() {
        csv::ErrorKind::Io(source) => {
            super::lines::line_error(&source).unwrap_or_else(|| DataError::io(path.map(Path::to_path_buf), source))
        }
        csv::ErrorKind::Utf8 { err, .. } => DataError::Malformed {
            line,
            message: format!("invalid UTF-8 in field {}", err.field() + 1),
        },
        other => DataError::Malformed {
            line,
            message: format!("{other:?}"),
        },
    }
}

/// Reads a trajectory from the CSV file at `path` (schema in the [module docs](super)).
///
/// `dof`: the number of joints the file must have, or `None` to take it from the
/// highest `q` column. Errors (see [`DataError`]) name the file line and column;
/// up to [`MAX_ERRORS`] are collected in one pass.
pub fn read_csv(path: impl AsRef<Path>, dof: Option<usize>) -> Result<Trajectory, DataError> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| DataError::io(Some(path.to_path_buf()), e))?;
    read(file, dof, Some(path))
}

/// [`read_csv`] from any reader (a file, a string's bytes, a network stream).
pub fn from_reader(reader: impl Read, dof: Option<usize>) -> Result<Trajectory, DataError> {
    read(reader, dof, None)
}

fn read(reader: impl Read, dof: Option<usize>, path: Option<&Path>) -> Result<Trajectory, DataError> {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(LineIndex::new(
            skip_bom(reader).map_err(|e| DataError::io(path.map(Path::to_path_buf), e))?,
        ));
    let mut record = csv::StringRecord::new();
    // The csv crate's line numbers skip blank lines; count them ourselves.
    let line_of = |rdr: &mut csv::Reader<LineIndex<_>>, record: &csv::StringRecord| {
        let byte = record.position().map_or(0, |p| p.byte());
        rdr.get_mut().line_of(byte)
    };

    let header_line = loop {
        match rdr.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => return Err(DataError::Empty),
            Err(e) => return Err(csv_error(e, path, |byte| rdr.get_mut().line_of(byte))),
        }
        let line = line_of(&mut rdr, &record);
        // Lines holding only spaces are blank too: skip them like empty ones, but
        // only before the header.
        if record.iter().any(|f| !f.is_empty()) {
            break line;
        }
    };
    let header = parse_header(&record, header_line, dof).map_err(|e| {
        // One field that a semicolon or tab would split: the wrong separator.
        let other = match record.iter().collect::<Vec<_>>()[..] {
            [only] => Delimiter::guess_other(only.as_bytes(), Delimiter::Comma),
            _ => None,
        };
        separator_hint(e, header_line, Delimiter::Comma, other)
    })?;
    let n = header.dof;
    let width = header.columns.len();

    let mut t = Vec::new();
    let mut q = Vec::new();
    let mut v = Vec::new();
    let mut a = Vec::new();
    let mut tau = Vec::new();
    let mut wrenches: Vec<Wrench<f64>> = Vec::new();
    let mut lines = Vec::new();
    let mut errors = Errors::new();
    // The last time stamp read, for the monotonicity check.
    let mut previous_t: Option<f64> = None;

    // One row's values, by kind, reused.
    let mut row_q = vec![0.0; n];
    let mut row_v = vec![0.0; n];
    let mut row_a = vec![0.0; n];
    let mut row_tau = vec![0.0; n];
    let mut row_w = vec![[0.0; 6]; n];

    loop {
        match rdr.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => {
                errors.push(csv_error(e, path, |byte| rdr.get_mut().line_of(byte)));
                break;
            }
        }
        let line = line_of(&mut rdr, &record);
        if record.len() != width {
            if !errors.push(DataError::FieldCount {
                line,
                expected: width,
                found: record.len(),
            }) {
                break;
            }
            continue;
        }
        let mut row_t = 0.0;
        let mut ok = true;
        for (text, column) in record.iter().zip(&header.columns) {
            let value = match text.parse::<f64>() {
                Ok(x) if x.is_finite() => x,
                Ok(x) => {
                    ok = false;
                    errors.push(DataError::NonFinite {
                        at: Location::Line(line),
                        column: column.name(),
                        value: x,
                    });
                    continue;
                }
                Err(_) => {
                    ok = false;
                    errors.push(DataError::NotANumber {
                        line,
                        column: column.name(),
                        text: text.into(),
                    });
                    continue;
                }
            };
            let j = column.joint.wrapping_sub(1);
            match column.kind {
                Kind::T => {
                    row_t = value;
                    if let Some(previous) = previous_t {
                        if value <= previous {
                            ok = false;
                            errors.push(DataError::NonMonotonicTime {
                                at: Location::Line(line),
                                t: value,
                                previous,
                            });
                        }
                    }
                    previous_t = Some(value);
                }
                Kind::Q => row_q[j] = value,
                Kind::V => row_v[j] = value,
                Kind::A => row_a[j] = value,
                Kind::Tau => row_tau[j] = value,
                Kind::Wrench(c) => row_w[j][c] = value,
            }
        }
        if errors.full() {
            // Stop, and say so if there was more to read.
            errors.truncated = matches!(rdr.read_record(&mut record), Ok(true));
            break;
        }
        if ok {
            t.push(row_t);
            q.extend_from_slice(&row_q);
            tau.extend_from_slice(&row_tau);
            if header.has_v {
                v.extend_from_slice(&row_v);
            }
            if header.has_a {
                a.extend_from_slice(&row_a);
            }
            if header.has_wrenches {
                wrenches.extend(row_w.iter().map(|w| Wrench {
                    force: Vector3::new(w[0], w[1], w[2]),
                    torque: Vector3::new(w[3], w[4], w[5]),
                }));
            }
            lines.push(line);
        }
    }
    errors.into_result()?;
    if t.len() < 2 {
        return Err(DataError::TooFewSamples {
            found: t.len(),
            needed: 2,
        });
    }
    Trajectory::from_checked_parts(
        n,
        t,
        q,
        header.has_v.then_some(v),
        header.has_a.then_some(a),
        tau,
        header.has_wrenches.then_some(wrenches),
        Some(lines),
    )
}

/// A number in the shortest form that reads back to the same bits: plain decimal
/// for moderate magnitudes, scientific otherwise (never 300 zeros).
fn format_f64(x: f64) -> String {
    let m = x.abs();
    if m == 0.0 || (1e-4..1e16).contains(&m) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// The header row [`to_writer`] writes for `traj`.
pub fn csv_header(traj: &Trajectory) -> Vec<String> {
    let n = traj.dof();
    let mut names = vec!["t".to_string()];
    let mut group = |prefix: &str| names.extend((1..=n).map(|j| format!("{prefix}{j}")));
    group("q");
    if traj.velocities().is_some() {
        group("v");
    }
    if traj.accelerations().is_some() {
        group("a");
    }
    group("tau");
    if traj.joint_wrenches().is_some() {
        for j in 1..=n {
            names.extend(WRENCH_PREFIXES.iter().map(|p| format!("{p}{j}")));
        }
    }
    names
}

/// Writes `traj` as CSV to `writer`: header `t, q…, [v…, a…,] tau…, [fx1, …, mzn]`,
/// one row per sample, numbers in their shortest exact form (reading them back
/// gives the same bits).
pub fn to_writer(writer: impl io::Write, traj: &Trajectory) -> Result<(), DataError> {
    let mut wtr = csv::WriterBuilder::new().has_headers(false).from_writer(writer);
    let fail = |e: csv::Error| csv_error(e, None, |_| 0);
    wtr.write_record(csv_header(traj)).map_err(fail)?;
    let mut row: Vec<String> = Vec::new();
    for s in traj.samples() {
        row.clear();
        row.push(format_f64(s.t));
        let groups = [Some(s.q), s.v, s.a, Some(s.tau)];
        row.extend(groups.into_iter().flatten().flatten().map(|&x| format_f64(x)));
        if let Some(w) = s.wrenches {
            for w in w {
                row.extend(w.force.iter().chain(w.torque.iter()).map(|&x| format_f64(x)));
            }
        }
        wtr.write_record(&row).map_err(fail)?;
    }
    wtr.flush().map_err(|e| DataError::io(None, e))
}

/// Writes `traj` to a new file at `path`; fails with [`DataError::FileExists`] if
/// the file exists (use [`overwrite_csv`] to replace it). A file left half-written
/// by a failed write is removed.
pub fn write_csv(path: impl AsRef<Path>, traj: &Trajectory) -> Result<(), DataError> {
    let path = path.as_ref();
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(|e| {
            if e.kind() == io::ErrorKind::AlreadyExists {
                DataError::FileExists {
                    path: path.to_path_buf(),
                }
            } else {
                DataError::io(Some(path.to_path_buf()), e)
            }
        })?;
    write_file(file, path, traj).inspect_err(|_| {
        // Best effort: the file is ours (create_new), and a partial one misleads.
        let _ = std::fs::remove_file(path);
    })
}

/// Writes `traj` to `path`, replacing the file if it exists.
pub fn overwrite_csv(path: impl AsRef<Path>, traj: &Trajectory) -> Result<(), DataError> {
    let path = path.as_ref();
    let file = File::create(path).map_err(|e| DataError::io(Some(path.to_path_buf()), e))?;
    write_file(file, path, traj)
}

fn write_file(file: File, path: &Path, traj: &Trajectory) -> Result<(), DataError> {
    let with_path = |e: DataError| match e {
        DataError::Io { path: None, source } => DataError::Io {
            path: Some(PathBuf::from(path)),
            source,
        },
        other => other,
    };
    to_writer(file, traj).map_err(with_path)
}
