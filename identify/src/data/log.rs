//! Reading a log through a [`Recipe`]: one pass over the lines, fields split in
//! place and parsed straight into the trajectory's arrays; duplicates, windows and
//! decimation applied on the way; then optional resampling, and derivatives on the
//! grid the samples are on.

use std::fmt;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

use nalgebra::Vector3;

use super::derivatives::{hermite, intervals, SAMPLING_TOLERANCE};
use super::error::{DataError, Field, MAX_ABS_VALUE, MAX_LINE_BYTES};
use super::io::{parse_header, separator_hint, Errors, Kind, WRENCH_PREFIXES};
use super::lines::{line_error, skip_bom, TooLong};
use super::recipe::{ColumnRef, Delimiter, Recipe, RecipeError, Sampling, Stale, TimeOrigin};
use super::trajectory::{column, set_column, Trajectory};
use dyngen::Wrench;

/// A resampled log may have at most this many times the samples it was read with: a
/// step far below the logger's only invents data (and memory).
pub const MAX_RESAMPLE_FACTOR: usize = 100;

/// A trajectory read through a recipe, and what was done to get it.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub trajectory: Trajectory,
    pub report: LoadReport,
}

/// Smallest, median and largest time step of the samples kept (before resampling), s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeSteps {
    pub min: f64,
    pub median: f64,
    pub max: f64,
}

/// Where a group of values (velocities, accelerations) comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Provenance {
    /// Read from these 1-based columns of the file.
    Measured { columns: Vec<usize> },
    /// Estimated by zero-phase low-pass filtering at `cutoff_hz` and finite
    /// differences, on a `uniform` grid or on the log's own time stamps.
    Estimated { cutoff_hz: f64, uniform: bool },
    /// Neither in the file nor estimated (yet: see [`Loaded::with_derivatives`]).
    Missing,
}

/// What reading a log did: rows read and dropped, the time grid, where each
/// quantity comes from. Its `Display` is the summary `dyngen identify` prints.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadReport {
    /// Data rows looked at (inside the `rows` window).
    pub rows: usize,
    /// Samples in the trajectory (after resampling, if any).
    pub samples: usize,
    pub dof: usize,
    /// Rows identical to the previous one, time stamp included: dropped.
    pub repeated: usize,
    /// Rows with the previous row's time stamp but other values: dropped (the first
    /// row of a time stamp is kept).
    pub same_time: usize,
    /// Rows repeating the previous values under a new time stamp, dropped with
    /// `stale = drop`.
    pub stale: usize,
    /// Rows outside the time window.
    pub outside_window: usize,
    /// Rows left out by decimation.
    pub decimated: usize,
    /// Of the samples kept, before resampling.
    pub steps: TimeSteps,
    /// Every step within [`SAMPLING_TOLERANCE`] of the mean (before resampling).
    pub uniform: bool,
    /// The uniform step the samples were interpolated to.
    pub resampled: Option<f64>,
    pub q_columns: Vec<usize>,
    pub tau_columns: Vec<usize>,
    /// The torque columns held motor currents, converted with the recipe's gains.
    pub currents: bool,
    pub velocity: Provenance,
    pub acceleration: Provenance,
    /// The cutoff (Hz) the positions and measured velocities were low-passed at
    /// ([`Loaded::with_states_low_passed`]); `None`: used as read.
    pub states_low_passed: Option<f64>,
    /// The states were to be low-passed, but the cutoff is at or above this Nyquist
    /// frequency (Hz) of the mean step: there is nothing above the cutoff to remove,
    /// and they are used as read.
    pub states_above_nyquist: Option<f64>,
}

impl LoadReport {
    /// Rows read but not in the trajectory, for whatever reason.
    pub fn dropped(&self) -> usize {
        self.repeated + self.same_time + self.stale + self.outside_window + self.decimated
    }
}

/// `columns 8–13`, or `columns 2, 4, 6` when they are not consecutive.
fn columns_text(columns: &[usize]) -> String {
    let consecutive = columns.windows(2).all(|w| w[1] == w[0] + 1);
    match columns {
        [] => "no columns".into(),
        [c] => format!("column {c}"),
        [first, .., last] if consecutive => format!("columns {first}–{last}"),
        _ => format!(
            "columns {}",
            columns.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(", ")
        ),
    }
}

fn seconds_text(s: f64) -> String {
    if s.abs() < 1.0 {
        format!("{:.3} ms", s * 1e3)
    } else {
        format!("{s:.4} s")
    }
}

impl fmt::Display for Provenance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Provenance::Measured { columns } => write!(f, "measured ({})", columns_text(columns)),
            Provenance::Estimated { cutoff_hz, uniform } => write!(
                f,
                "estimated by zero-phase differentiation (low-pass {cutoff_hz} Hz, {})",
                if *uniform { "uniform grid" } else { "non-uniform grid" }
            ),
            Provenance::Missing => write!(f, "not in the file"),
        }
    }
}

impl fmt::Display for LoadReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} rows read, {} samples of {} joints kept",
            self.rows, self.samples, self.dof
        )?;
        let drops = [
            (self.repeated, "repeated rows"),
            (self.same_time, "rows repeating a time stamp"),
            (self.stale, "stale rows"),
            (self.outside_window, "rows outside the time window"),
            (self.decimated, "rows by decimation"),
        ];
        let drops: Vec<String> = drops
            .iter()
            .filter(|(n, _)| *n > 0)
            .map(|(n, what)| format!("{n} {what}"))
            .collect();
        if !drops.is_empty() {
            write!(f, "; dropped {}", drops.join(", "))?;
        }
        let s = &self.steps;
        write!(
            f,
            "\ntime step: min {}, median {}, max {}",
            seconds_text(s.min),
            seconds_text(s.median),
            seconds_text(s.max)
        )?;
        match (self.resampled, self.uniform) {
            (Some(dt), _) => write!(f, " (resampled to a uniform {} grid)", seconds_text(dt))?,
            (None, true) => write!(f, " (uniform)")?,
            (None, false) => write!(f, " (irregular: used as they are)")?,
        }
        write!(f, "\nposition: measured ({})", columns_text(&self.q_columns))?;
        if self.currents {
            write!(
                f,
                "; torque: motor currents × gains ({})",
                columns_text(&self.tau_columns)
            )?;
        } else {
            write!(f, "; torque: measured ({})", columns_text(&self.tau_columns))?;
        }
        write!(f, "\nvelocity: {}; acceleration: {}", self.velocity, self.acceleration)?;
        if let Some(hz) = self.states_low_passed {
            let what = match self.velocity {
                Provenance::Measured { .. } => "positions and measured velocities",
                _ => "positions",
            };
            write!(f, "\n{what} low-passed at {hz} Hz (zero phase)")?;
        }
        if let Some(nyquist) = self.states_above_nyquist {
            write!(
                f,
                "\npositions used as read: the cutoff is at or above the Nyquist frequency ({nyquist} Hz) of the samples"
            )?;
        }
        Ok(())
    }
}

impl Recipe {
    /// Reads the log at `path` through this recipe. `dof`: the number of joints the
    /// log must have (`None`: from the columns). Errors name the line and column.
    pub fn read(&self, path: impl AsRef<Path>, dof: Option<usize>) -> Result<Loaded, DataError> {
        let path = path.as_ref();
        let file = File::open(path).map_err(|e| DataError::io(Some(path.to_path_buf()), e))?;
        read(file, self, dof, Some(path))
    }

    /// [`Recipe::read`] from any reader.
    pub fn read_from(&self, reader: impl Read, dof: Option<usize>) -> Result<Loaded, DataError> {
        read(reader, self, dof, None)
    }
}

impl Loaded {
    /// Estimates the velocities and accelerations the log does not have, at
    /// `cutoff_hz`: on a uniform grid by [`Trajectory::with_derivatives`], otherwise
    /// by [`Trajectory::with_derivatives_nonuniform`] on the time stamps as they are.
    /// Measured values are kept.
    ///
    /// Errors: fewer than 3 samples when accelerations come from positions (2 when
    /// they come from measured velocities), `cutoff_hz` at or above the Nyquist
    /// frequency of the mean step.
    pub fn with_derivatives(mut self, cutoff_hz: f64) -> Result<Loaded, DataError> {
        let traj = &self.trajectory;
        let (has_v, has_a) = (traj.velocities().is_some(), traj.accelerations().is_some());
        if has_v && has_a {
            return Ok(self);
        }
        let needed = if has_v { 2 } else { 3 };
        if traj.len() < needed {
            return Err(DataError::TooFewSamplesLeft {
                found: traj.len(),
                needed,
                purpose: "estimating velocities and accelerations",
                rows: self.report.rows,
                dropped: self.report.dropped(),
            });
        }
        let uniform = traj.uniform_time_step().is_ok();
        self.trajectory = if uniform {
            traj.with_derivatives(cutoff_hz)?
        } else {
            traj.with_derivatives_nonuniform(cutoff_hz)?
        };
        let estimated = Provenance::Estimated { cutoff_hz, uniform };
        if !has_v {
            self.report.velocity = estimated.clone();
        }
        if !has_a {
            self.report.acceleration = estimated;
        }
        Ok(self)
    }

    /// Low-passes the positions, and the velocities where they were measured, at
    /// `cutoff_hz` ([`Trajectory::with_states_low_passed`]); velocities estimated by
    /// [`Loaded::with_derivatives`] are already filtered and are kept. Call it after
    /// that. The report records the cutoff.
    ///
    /// A finite `cutoff_hz` at or above the Nyquist frequency of the mean step leaves
    /// the states as read (the samples hold nothing above it) and records that in
    /// [`LoadReport::states_above_nyquist`].
    ///
    /// Errors: `cutoff_hz` not finite and positive, a non-finite filtered value.
    pub fn with_states_low_passed(mut self, cutoff_hz: f64) -> Result<Loaded, DataError> {
        let t = self.trajectory.t();
        if t.len() >= 2 && cutoff_hz.is_finite() {
            let nyquist = 0.5 * (t.len() - 1) as f64 / (t[t.len() - 1] - t[0]);
            if cutoff_hz >= nyquist {
                self.report.states_above_nyquist = Some(nyquist);
                return Ok(self);
            }
        }
        let measured = matches!(self.report.velocity, Provenance::Measured { .. });
        self.trajectory = self.trajectory.with_states_low_passed(cutoff_hz, measured)?;
        self.report.states_low_passed = Some(cutoff_hz);
        Ok(self)
    }
}

/// The lines of the input, without terminators: `\n`, `\r\n` and a lone `\r` end a
/// line, as for the plain reader. The buffer is reused, so reading allocates only
/// when a line is longer than every line before; a line longer than
/// [`MAX_LINE_BYTES`] is an error ([`TooLong`]) raised before more of it is read.
struct Lines<R> {
    inner: BufReader<R>,
    buf: Vec<u8>,
    /// The last line ended with `\r`: a `\n` right after it belongs to that break.
    after_cr: bool,
    number: u64,
}

impl<R: Read> Lines<R> {
    fn new(inner: R) -> Self {
        Lines {
            inner: BufReader::with_capacity(1 << 16, inner),
            buf: Vec::new(),
            after_cr: false,
            number: 0,
        }
    }

    fn next_line(&mut self) -> io::Result<Option<(u64, &[u8])>> {
        self.buf.clear();
        let mut any = false;
        loop {
            let available = match self.inner.fill_buf() {
                Ok(bytes) => bytes,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if available.is_empty() {
                if !any {
                    return Ok(None);
                }
                break;
            }
            if std::mem::take(&mut self.after_cr) && available[0] == b'\n' {
                self.inner.consume(1);
                continue;
            }
            any = true;
            let stop = available.iter().position(|&b| b == b'\n' || b == b'\r');
            let take = stop.unwrap_or(available.len());
            if self.buf.len() + take > MAX_LINE_BYTES {
                return Err(TooLong { line: self.number + 1 }.into_io());
            }
            self.buf.extend_from_slice(&available[..take]);
            match stop {
                Some(i) => {
                    self.after_cr = available[i] == b'\r';
                    self.inner.consume(i + 1);
                    break;
                }
                None => self.inner.consume(take),
            }
        }
        self.number += 1;
        Ok(Some((self.number, &self.buf)))
    }
}

/// The fields of one line, trimmed of ASCII spaces and of one pair of double quotes.
struct Fields<'a> {
    rest: Option<&'a [u8]>,
    separator: Option<u8>,
}

impl<'a> Fields<'a> {
    fn new(line: &'a [u8], delimiter: Delimiter) -> Self {
        Fields {
            rest: Some(line),
            separator: delimiter.byte(),
        }
    }
}

fn clean(field: &[u8]) -> &[u8] {
    let field = field.trim_ascii();
    match field {
        [b'"', inner @ .., b'"'] => inner.trim_ascii(),
        _ => field,
    }
}

impl<'a> Iterator for Fields<'a> {
    type Item = &'a [u8];

    fn next(&mut self) -> Option<&'a [u8]> {
        let rest = self.rest?;
        match self.separator {
            Some(sep) => match rest.iter().position(|&b| b == sep) {
                Some(i) => {
                    self.rest = Some(&rest[i + 1..]);
                    Some(clean(&rest[..i]))
                }
                None => {
                    self.rest = None;
                    Some(clean(rest))
                }
            },
            None => {
                let start = rest.iter().position(|b| !b.is_ascii_whitespace());
                let Some(start) = start else {
                    self.rest = None;
                    return None;
                };
                let rest = &rest[start..];
                let stop = rest.iter().position(u8::is_ascii_whitespace).unwrap_or(rest.len());
                self.rest = Some(&rest[stop..]);
                Some(clean(&rest[..stop]))
            }
        }
    }
}

fn is_blank(line: &[u8]) -> bool {
    line.iter().all(u8::is_ascii_whitespace)
}

/// What the value of one field becomes.
#[derive(Clone, Copy, Debug)]
enum Target {
    Skip,
    Time,
    /// Position in the row buffer, and the factor to SI units.
    Value {
        pos: usize,
        scale: f64,
    },
}

/// How to read the rows of this file: what each field is, and the shape of a sample.
struct Plan {
    width: usize,
    /// The line that set `width`: the header, or the first data row.
    reference: u64,
    targets: Vec<Target>,
    fields: Vec<Option<Field>>,
    time_field: usize,
    dof: usize,
    has_v: bool,
    has_a: bool,
    has_wrenches: bool,
    q_columns: Vec<usize>,
    v_columns: Vec<usize>,
    a_columns: Vec<usize>,
    tau_columns: Vec<usize>,
}

/// One joint quantity a field may hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    Q,
    V,
    A,
    Tau,
    Wrench(usize),
}

impl Plan {
    /// Offsets of the groups in a row buffer: q, v, a, tau, wrenches.
    fn offset(&self, role: Role, joint: usize) -> usize {
        let n = self.dof;
        let v = if self.has_v { n } else { 0 };
        let a = if self.has_a { n } else { 0 };
        match role {
            Role::Q => joint,
            Role::V => n + joint,
            Role::A => n + v + joint,
            Role::Tau => n + v + a + joint,
            Role::Wrench(c) => 2 * n + v + a + 6 * joint + c,
        }
    }

    fn row_len(&self) -> usize {
        self.offset(Role::Wrench(0), self.dof) - if self.has_wrenches { 0 } else { 6 * self.dof }
    }

    /// Builds the plan from `(field index, role, joint)` assignments.
    #[allow(clippy::too_many_arguments)]
    fn build(
        recipe: &Recipe,
        width: usize,
        reference: u64,
        names: Option<&[String]>,
        time_field: usize,
        assign: &[(usize, Role, usize)],
        dof: usize,
        flags: (bool, bool, bool),
    ) -> Result<Plan, DataError> {
        let (has_v, has_a, has_wrenches) = flags;
        let per_joint = |key: &'static str, len: usize| -> Result<(), DataError> {
            if len == 0 || len == 1 || len == dof {
                Ok(())
            } else {
                Err(DataError::RecipeLength { key, found: len, dof })
            }
        };
        per_joint("units", recipe.units.len())?;
        per_joint("sign", recipe.signs.len())?;
        if let Some(g) = &recipe.gains {
            per_joint("gains", g.len())?;
        }
        let pick = |values: &[f64], j: usize| match values.len() {
            0 => 1.0,
            1 => values[0],
            _ => values[j],
        };
        let units: Vec<f64> = recipe.units.iter().map(|u| u.scale()).collect();
        let gains = recipe.gains.clone().unwrap_or_default();
        let role_name = |role: Role, j: usize| match role {
            Role::Q => format!("q{}", j + 1),
            Role::V => format!("v{}", j + 1),
            Role::A => format!("a{}", j + 1),
            Role::Tau if recipe.gains.is_some() => format!("current{}", j + 1),
            Role::Tau => format!("tau{}", j + 1),
            Role::Wrench(c) => format!("{}{}", WRENCH_PREFIXES[c], j + 1),
        };
        let field = |index: usize, role: String| Field {
            index: index + 1,
            name: names.and_then(|n| n.get(index).cloned()),
            role,
        };
        let mut plan = Plan {
            width,
            reference,
            targets: vec![Target::Skip; width],
            fields: vec![None; width],
            time_field,
            dof,
            has_v,
            has_a,
            has_wrenches,
            q_columns: vec![0; dof],
            v_columns: vec![0; if has_v { dof } else { 0 }],
            a_columns: vec![0; if has_a { dof } else { 0 }],
            tau_columns: vec![0; dof],
        };
        plan.targets[time_field] = Target::Time;
        plan.fields[time_field] = Some(field(time_field, "t".into()));
        for &(index, role, j) in assign {
            if let Some(first) = &plan.fields[index] {
                return Err(DataError::ColumnTwice {
                    index: index + 1,
                    first: format!("`{}`", first.role),
                    second: format!("`{}`", role_name(role, j)),
                });
            }
            let sign = pick(&recipe.signs, j);
            let scale = match role {
                Role::Q | Role::V | Role::A => sign * pick(&units, j),
                Role::Tau => sign * pick(&gains, j),
                // Wrenches are in their body's frame, which a joint's sign
                // convention does not flip: read as they are.
                Role::Wrench(_) => 1.0,
            };
            plan.targets[index] = Target::Value {
                pos: plan.offset(role, j),
                scale,
            };
            plan.fields[index] = Some(field(index, role_name(role, j)));
            match role {
                Role::Q => plan.q_columns[j] = index + 1,
                Role::V => plan.v_columns[j] = index + 1,
                Role::A => plan.a_columns[j] = index + 1,
                Role::Tau => plan.tau_columns[j] = index + 1,
                Role::Wrench(_) => {}
            }
        }
        Ok(plan)
    }

    /// The named schema of [`read_csv`](super::read_csv), from the header.
    fn named(recipe: &Recipe, names: &[String], line: u64, dof: Option<usize>) -> Result<Plan, DataError> {
        let record = csv::StringRecord::from(names.to_vec());
        let header = parse_header(&record, line, dof)?;
        let mut time_field = 0;
        let mut assign = Vec::new();
        for (i, c) in header.columns.iter().enumerate() {
            let j = c.joint.wrapping_sub(1);
            let role = match c.kind {
                Kind::T => {
                    time_field = i;
                    continue;
                }
                Kind::Q => Role::Q,
                Kind::V => Role::V,
                Kind::A => Role::A,
                Kind::Tau => Role::Tau,
                Kind::Wrench(k) => Role::Wrench(k),
            };
            assign.push((i, role, j));
        }
        Plan::build(
            recipe,
            names.len(),
            line,
            Some(names),
            time_field,
            &assign,
            header.dof,
            (header.has_v, header.has_a, header.has_wrenches),
        )
    }

    /// The recipe's `time`, `q`, `v`, `a`, `tau` settings.
    fn explicit(
        recipe: &Recipe,
        names: Option<&[String]>,
        width: usize,
        line: u64,
        dof: Option<usize>,
    ) -> Result<Plan, DataError> {
        let c = &recipe.columns;
        let resolve = |key: &'static str, r: &ColumnRef| -> Result<usize, DataError> {
            match (r, names) {
                (ColumnRef::Index(i), _) if *i <= width => Ok(i - 1),
                (ColumnRef::Index(i), _) => Err(DataError::ColumnOutOfRange {
                    line,
                    key,
                    index: *i,
                    width,
                }),
                (ColumnRef::Name(n), Some(names)) => {
                    names
                        .iter()
                        .position(|h| h == n)
                        .ok_or_else(|| DataError::ColumnNotInHeader {
                            line,
                            key,
                            name: n.clone(),
                            header: names.to_vec(),
                        })
                }
                (ColumnRef::Name(n), None) => Err(DataError::Recipe(RecipeError::BadValue {
                    line: None,
                    key,
                    value: n.clone(),
                    expected: "column numbers: a log without a header (`header = false`) has no names",
                })),
            }
        };
        let q = c.q.as_deref().unwrap_or_default();
        let n = q.len();
        let mut groups: Vec<(&'static str, Role, &[ColumnRef])> = vec![("q", Role::Q, q)];
        if let Some(v) = &c.v {
            groups.push(("v", Role::V, v));
        }
        if let Some(a) = &c.a {
            groups.push(("a", Role::A, a));
        }
        groups.push(("tau", Role::Tau, c.tau.as_deref().unwrap_or_default()));
        for &(key, _, refs) in &groups {
            let expected = dof.unwrap_or(n);
            if refs.len() != expected {
                return Err(DataError::RecipeColumns {
                    key,
                    found: refs.len(),
                    dof: expected,
                });
            }
        }
        let time_field = resolve("time", c.time.as_ref().unwrap_or(&ColumnRef::Index(1)))?;
        let mut assign = Vec::new();
        for (key, role, refs) in groups {
            for (j, r) in refs.iter().enumerate() {
                let index = resolve(key, r)?;
                if index == time_field {
                    return Err(DataError::ColumnTwice {
                        index: index + 1,
                        first: "`t`".into(),
                        second: format!("`{key}{}`", j + 1),
                    });
                }
                assign.push((index, role, j));
            }
        }
        Plan::build(
            recipe,
            width,
            line,
            names,
            time_field,
            &assign,
            n,
            (c.v.is_some(), c.a.is_some(), false),
        )
    }

    /// The writer's column order, without a header: the layout follows from the
    /// field count.
    fn positional(recipe: &Recipe, width: usize, line: u64, dof: Option<usize>) -> Result<Plan, DataError> {
        let layouts = |n: usize| {
            [(false, false), (true, false), (true, true)]
                .into_iter()
                .flat_map(move |(v, a)| [(v, a, false), (v, a, true)])
                .filter(move |&(v, a, w)| {
                    1 + n * (2 + usize::from(v) + usize::from(a) + if w { 6 } else { 0 }) == width
                })
        };
        let found = match dof {
            Some(n) => layouts(n).next().map(|l| (n, l)),
            None if width >= 3 && width % 2 == 1 => Some(((width - 1) / 2, (false, false, false))),
            None => None,
        };
        let Some((n, (has_v, has_a, has_w))) = found else {
            return Err(DataError::NoLayout {
                line,
                found: width,
                dof,
            });
        };
        let mut assign = Vec::new();
        let mut index = 1;
        let mut roles = vec![Role::Q];
        if has_v {
            roles.push(Role::V);
        }
        if has_a {
            roles.push(Role::A);
        }
        roles.push(Role::Tau);
        for role in roles {
            for j in 0..n {
                assign.push((index, role, j));
                index += 1;
            }
        }
        if has_w {
            for j in 0..n {
                for c in 0..6 {
                    assign.push((index, Role::Wrench(c), j));
                    index += 1;
                }
            }
        }
        Plan::build(recipe, width, line, None, 0, &assign, n, (has_v, has_a, has_w))
    }
}

/// Everything read so far.
struct State {
    t: Vec<f64>,
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
    w: Vec<f64>,
    lines: Vec<u64>,
    row: Vec<f64>,
    previous: Vec<f64>,
    /// The last accepted row's time and line (decimated or not).
    last: Option<(f64, u64)>,
    origin: Option<f64>,
    accepted: usize,
    report: LoadReport,
}

fn parse_field(text: &[u8]) -> Result<f64, String> {
    match std::str::from_utf8(text) {
        Ok(s) => s.parse::<f64>().map_err(|_| s.to_string()),
        Err(_) => Err(String::from_utf8_lossy(text).into_owned()),
    }
}

/// Data lines read ahead, then split and parsed on every core before their rows
/// are taken in order (the numbers are most of the reading time).
const BATCH_LINES: usize = 8192;

/// Data lines read ahead: their bytes, and each line's number and byte range.
#[derive(Default)]
struct Batch {
    bytes: Vec<u8>,
    lines: Vec<(u64, usize, usize)>,
}

/// One line split and parsed: per field, its number (`parse_field`), or
/// `Err(String::new())` for a field the plan does not read.
#[derive(Clone, Copy)]
struct ParsedLine<'a> {
    values: &'a [Result<f64, String>],
}

/// Lines of a batch split into fields and parsed; `starts[k]..starts[k + 1]` are
/// line `k`'s fields.
struct Parsed {
    values: Vec<Result<f64, String>>,
    starts: Vec<usize>,
}

impl Parsed {
    fn line(&self, k: usize) -> ParsedLine<'_> {
        ParsedLine {
            values: &self.values[self.starts[k]..self.starts[k + 1]],
        }
    }
}

/// Splits and parses `lines` of `bytes`: the fields `read[i]` selects (all beyond
/// its length are skipped).
fn parse_lines(bytes: &[u8], lines: &[(u64, usize, usize)], delimiter: Delimiter, read: &[bool]) -> Parsed {
    let mut values = Vec::with_capacity(lines.len() * read.len());
    let mut starts = Vec::with_capacity(lines.len() + 1);
    starts.push(0);
    for &(_, a, b) in lines {
        for (i, field) in Fields::new(&bytes[a..b], delimiter).enumerate() {
            values.push(if read.get(i).copied().unwrap_or(false) {
                parse_field(field)
            } else {
                Err(String::new())
            });
        }
        starts.push(values.len());
    }
    Parsed { values, starts }
}

/// [`parse_lines`] on the whole batch, in contiguous parts on every core.
fn parse_batch(batch: &Batch, delimiter: Delimiter, read: &[bool]) -> Vec<Parsed> {
    let parts = crate::accumulate::cores().min(batch.lines.len() / 1024).max(1);
    if parts == 1 {
        return vec![parse_lines(&batch.bytes, &batch.lines, delimiter, read)];
    }
    let size = batch.lines.len().div_ceil(parts);
    std::thread::scope(|scope| {
        let handles: Vec<_> = batch
            .lines
            .chunks(size)
            .map(|lines| scope.spawn(move || parse_lines(&batch.bytes, lines, delimiter, read)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
            .collect()
    })
}

impl State {
    /// Reads one data row into the arrays, or says why not. `Ok(false)` when the
    /// error list is full.
    fn row(&mut self, plan: &Plan, recipe: &Recipe, line: u64, parsed: ParsedLine<'_>, errors: &mut Errors) -> bool {
        let found = parsed.values.len();
        if found != plan.width {
            return errors.push(DataError::RowWidth {
                line,
                expected: plan.width,
                found,
                reference: plan.reference,
            });
        }
        let field = |i: usize| {
            plan.fields[i].clone().unwrap_or(Field {
                index: i + 1,
                name: None,
                role: String::new(),
            })
        };
        let mut ok = true;
        let mut check = |i: usize, raw: Result<f64, String>, scale: f64, errors: &mut Errors| -> Option<f64> {
            let e = match raw {
                Ok(x) if x.is_finite() => {
                    let si = x * scale;
                    if si.abs() <= MAX_ABS_VALUE {
                        return Some(si);
                    }
                    DataError::OutOfRange {
                        line,
                        field: field(i),
                        value: si,
                    }
                }
                Ok(x) => DataError::NonFiniteIn {
                    line,
                    field: field(i),
                    value: x,
                },
                Err(text) => DataError::NotANumberIn {
                    line,
                    field: field(i),
                    text,
                },
            };
            ok = false;
            errors.push(e);
            None
        };

        // Time first: rows outside the window are left unread, so that a window
        // can cut away a damaged part of a log.
        let raw_t = parsed
            .values
            .get(plan.time_field)
            .cloned()
            .unwrap_or(Err(String::new()));
        if recipe.time_origin == TimeOrigin::FirstRow && self.origin.is_none() {
            if let Ok(x) = raw_t {
                self.origin = Some(x).filter(|x| x.is_finite());
            }
        }
        let origin = self.origin.unwrap_or(0.0);
        let t = check(
            plan.time_field,
            raw_t.map(|x| x - origin),
            recipe.time_unit.seconds(),
            errors,
        );
        if let (Some(t), Some(w)) = (t, recipe.window) {
            if w.start.is_some_and(|s| t < s) || w.end.is_some_and(|e| t > e) {
                self.report.outside_window += 1;
                return true;
            }
        }
        for (i, value) in parsed.values.iter().enumerate() {
            if let Target::Value { pos, scale } = plan.targets[i] {
                if let Some(x) = check(i, value.clone(), scale, errors) {
                    self.row[pos] = x;
                }
            }
        }
        let Some(t) = t.filter(|_| ok) else {
            return !errors.full();
        };
        if let Some((previous, previous_line)) = self.last {
            if t == previous {
                if self.row == self.previous {
                    self.report.repeated += 1;
                } else {
                    self.report.same_time += 1;
                }
                return true;
            }
            if t < previous {
                return errors.push(DataError::TimeNotIncreasing {
                    line,
                    field: field(plan.time_field),
                    t,
                    previous,
                    previous_line,
                });
            }
            if recipe.stale == Stale::Drop && self.row == self.previous {
                self.report.stale += 1;
                return true;
            }
        }
        self.last = Some((t, line));
        self.previous.copy_from_slice(&self.row);
        self.accepted += 1;
        if !(self.accepted - 1).is_multiple_of(recipe.decimate) {
            self.report.decimated += 1;
            return true;
        }
        let n = plan.dof;
        let row = &self.row;
        self.t.push(t);
        self.q.extend_from_slice(&row[plan.offset(Role::Q, 0)..][..n]);
        if plan.has_v {
            self.v.extend_from_slice(&row[plan.offset(Role::V, 0)..][..n]);
        }
        if plan.has_a {
            self.a.extend_from_slice(&row[plan.offset(Role::A, 0)..][..n]);
        }
        self.tau.extend_from_slice(&row[plan.offset(Role::Tau, 0)..][..n]);
        if plan.has_wrenches {
            self.w
                .extend_from_slice(&row[plan.offset(Role::Wrench(0), 0)..][..6 * n]);
        }
        self.lines.push(line);
        true
    }
}

fn read(reader: impl Read, recipe: &Recipe, dof: Option<usize>, path: Option<&Path>) -> Result<Loaded, DataError> {
    recipe.check().map_err(DataError::Recipe)?;
    if dof == Some(0) {
        return Err(DataError::InvalidArgument {
            name: "dof",
            value: 0.0,
            expected: "at least 1 joint (or `None` to take it from the columns)".into(),
        });
    }
    let io_error = |e: io::Error| line_error(&e).unwrap_or_else(|| DataError::io(path.map(Path::to_path_buf), e));
    let mut lines = Lines::new(skip_bom(reader).map_err(io_error)?);
    for _ in 0..recipe.skip {
        if lines.next_line().map_err(io_error)?.is_none() {
            return Err(DataError::Empty);
        }
    }
    let mut plan: Option<Plan> = None;
    let mut names: Option<Vec<String>> = None;
    if recipe.header {
        let (line, header, other) = loop {
            match lines.next_line().map_err(io_error)? {
                None => return Err(DataError::Empty),
                Some((_, bytes)) if is_blank(bytes) => {}
                Some((line, bytes)) => {
                    let fields = Fields::new(bytes, recipe.delimiter);
                    break (
                        line,
                        fields
                            .map(|f| String::from_utf8_lossy(f).into_owned())
                            .collect::<Vec<_>>(),
                        Delimiter::guess_other(bytes, recipe.delimiter),
                    );
                }
            }
        };
        let named = if recipe.columns.is_default() {
            Plan::named(recipe, &header, line, dof)
        } else {
            Plan::explicit(recipe, Some(&header), header.len(), line, dof)
        };
        plan = Some(named.map_err(|e| separator_hint(e, line, recipe.delimiter, other))?);
        names = Some(header);
    }

    let mut state: Option<State> = None;
    let mut errors = Errors::new();
    let mut data_row = 0usize;
    let mut rows = 0usize;
    let mut any_line = false;
    let mut batch = Batch::default();
    let mut read_fields: Vec<bool> = Vec::new();
    'reading: loop {
        // Read ahead up to a batch of data lines (blank lines and rows before the
        // row window skipped, as they would be one by one).
        batch.bytes.clear();
        batch.lines.clear();
        // A line (blank or not) read after the batch's last data line; whether the
        // input goes on after the batch, when that is full.
        let mut after_last = false;
        let mut last_batch = true;
        while let Some((line, bytes)) = lines.next_line().map_err(io_error)? {
            if is_blank(bytes) {
                after_last = true;
                continue;
            }
            any_line = true;
            data_row += 1;
            if let Some(w) = recipe.rows {
                if w.first.is_some_and(|f| data_row < f) {
                    continue;
                }
                if w.last.is_some_and(|l| data_row > l) {
                    after_last = true;
                    break;
                }
            }
            rows += 1;
            if plan.is_none() {
                let width = Fields::new(bytes, recipe.delimiter).count();
                let positional = if recipe.columns.is_default() {
                    Plan::positional(recipe, width, line, dof)
                } else {
                    Plan::explicit(recipe, None, width, line, dof)
                };
                let other = Delimiter::guess_other(bytes, recipe.delimiter);
                plan = Some(positional.map_err(|e| separator_hint(e, line, recipe.delimiter, other))?);
            }
            let start = batch.bytes.len();
            batch.bytes.extend_from_slice(bytes);
            batch.lines.push((line, start, batch.bytes.len()));
            after_last = false;
            if batch.lines.len() == BATCH_LINES {
                last_batch = false;
                break;
            }
        }
        let Some(plan) = plan.as_ref().filter(|_| !batch.lines.is_empty()) else {
            break;
        };
        if read_fields.is_empty() {
            read_fields = (0..plan.width)
                .map(|i| i == plan.time_field || matches!(plan.targets[i], Target::Value { .. }))
                .collect();
        }
        let state = state.get_or_insert_with(|| new_state(plan));
        let mut k = 0;
        for parsed in parse_batch(&batch, recipe.delimiter, &read_fields) {
            for j in 0..parsed.starts.len() - 1 {
                let line = batch.lines[k].0;
                k += 1;
                if !state.row(plan, recipe, line, parsed.line(j), &mut errors) || errors.full() {
                    errors.truncated = k < batch.lines.len()
                        || after_last
                        || (!last_batch && lines.next_line().map_err(io_error)?.is_some());
                    break 'reading;
                }
            }
        }
        if last_batch {
            break;
        }
    }
    errors.into_result()?;
    let (Some(plan), Some(mut state)) = (plan, state) else {
        return Err(if any_line || names.is_some() {
            DataError::TooFewSamples { found: 0, needed: 2 }
        } else {
            DataError::Empty
        });
    };
    state.report.rows = rows;
    finish(plan, state, recipe)
}

fn new_state(plan: &Plan) -> State {
    let len = plan.row_len();
    State {
        t: Vec::new(),
        q: Vec::new(),
        v: Vec::new(),
        a: Vec::new(),
        tau: Vec::new(),
        w: Vec::new(),
        lines: Vec::new(),
        row: vec![0.0; len],
        previous: vec![0.0; len],
        last: None,
        origin: None,
        accepted: 0,
        report: LoadReport {
            rows: 0,
            samples: 0,
            dof: plan.dof,
            repeated: 0,
            same_time: 0,
            stale: 0,
            outside_window: 0,
            decimated: 0,
            steps: TimeSteps {
                min: 0.0,
                median: 0.0,
                max: 0.0,
            },
            uniform: true,
            resampled: None,
            q_columns: plan.q_columns.clone(),
            tau_columns: plan.tau_columns.clone(),
            currents: false,
            velocity: if plan.has_v {
                Provenance::Measured {
                    columns: plan.v_columns.clone(),
                }
            } else {
                Provenance::Missing
            },
            acceleration: if plan.has_a {
                Provenance::Measured {
                    columns: plan.a_columns.clone(),
                }
            } else {
                Provenance::Missing
            },
            states_low_passed: None,
            states_above_nyquist: None,
        },
    }
}

fn steps(t: &[f64]) -> (TimeSteps, bool) {
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let n = t.len();
    let mean = (t[n - 1] - t[0]) / (n - 1) as f64;
    let uniform = d.iter().all(|s| (s - mean).abs() <= SAMPLING_TOLERANCE * mean);
    let mid = d.len() / 2;
    let (_, &mut median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    let min = d.iter().copied().fold(f64::INFINITY, f64::min);
    let max = d.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (TimeSteps { min, median, max }, uniform)
}

fn finish(plan: Plan, mut s: State, recipe: &Recipe) -> Result<Loaded, DataError> {
    let mut report = s.report.clone();
    report.currents = recipe.gains.is_some();
    if s.t.len() < 2 {
        return Err(DataError::TooFewSamplesLeft {
            found: s.t.len(),
            needed: 2,
            purpose: "a trajectory",
            rows: report.rows,
            dropped: report.dropped(),
        });
    }
    (report.steps, report.uniform) = steps(&s.t);
    let n = plan.dof;
    let mut lines = Some(std::mem::take(&mut s.lines));
    if let Sampling::Resample(dt) = recipe.sampling {
        let grid = grid(&s.t, dt)?;
        let at = intervals(&s.t, &grid);
        s.q = resample(&s.t, &at, &s.q, n)?;
        s.tau = resample(&s.t, &at, &s.tau, n)?;
        if plan.has_v {
            s.v = resample(&s.t, &at, &s.v, n)?;
        }
        if plan.has_a {
            s.a = resample(&s.t, &at, &s.a, n)?;
        }
        if plan.has_wrenches {
            s.w = resample(&s.t, &at, &s.w, 6 * n)?;
        }
        s.t = grid;
        lines = None;
        report.resampled = Some(dt);
    }
    report.samples = s.t.len();
    let wrenches = plan.has_wrenches.then(|| {
        s.w.chunks_exact(6)
            .map(|w| Wrench {
                force: Vector3::new(w[0], w[1], w[2]),
                torque: Vector3::new(w[3], w[4], w[5]),
            })
            .collect()
    });
    let trajectory = Trajectory::from_checked_parts(
        n,
        s.t,
        s.q,
        plan.has_v.then_some(s.v),
        plan.has_a.then_some(s.a),
        s.tau,
        wrenches,
        lines,
    )?;
    Ok(Loaded { trajectory, report })
}

/// `t₀ + k·dt` up to the last time stamp.
fn grid(t: &[f64], dt: f64) -> Result<Vec<f64>, DataError> {
    let (t0, t1) = (t[0], t[t.len() - 1]);
    let span = t1 - t0;
    // A step that lands on the last stamp up to rounding still reaches it.
    let count = (span / dt * (1.0 + 1e-12)).floor();
    if !(dt.is_finite() && dt > 0.0 && count >= 1.0) {
        return Err(DataError::InvalidArgument {
            name: "resample",
            value: dt,
            expected: format!("a step > 0 s and at most the log's duration, {span} s"),
        });
    }
    if count > (MAX_RESAMPLE_FACTOR * t.len()) as f64 {
        return Err(DataError::InvalidArgument {
            name: "resample",
            value: dt,
            expected: format!(
                "a step giving at most {MAX_RESAMPLE_FACTOR} times the {} samples read (at least {} s)",
                t.len(),
                span / (MAX_RESAMPLE_FACTOR * t.len()) as f64
            ),
        });
    }
    Ok((0..=count as usize).map(|k| t0 + k as f64 * dt).collect())
}

/// Every column of the row-major `values` (`width` per sample) interpolated to the
/// grid points `at` ([`intervals`]) by [`hermite`].
fn resample(t: &[f64], at: &[(usize, f64)], values: &[f64], width: usize) -> Result<Vec<f64>, DataError> {
    let mut out = vec![0.0; at.len() * width];
    for c in 0..width {
        set_column(&mut out, width, c, &hermite(t, &column(values, width, c), at)?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{from_reader, JointUnit};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn load(recipe: &str, csv: &str, dof: Option<usize>) -> Result<Loaded, DataError> {
        Recipe::parse(recipe).expect("recipe").read_from(csv.as_bytes(), dof)
    }

    fn load_err(recipe: &str, csv: &str, dof: Option<usize>) -> String {
        load(recipe, csv, dof).expect_err("an error").to_string()
    }

    /// A row of `values` joined by `sep`.
    fn row(sep: &str, values: &[f64]) -> String {
        values.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(sep) + "\n"
    }

    #[test]
    fn default_recipe_reads_the_schema_as_read_csv_does() {
        let csv = "t, q1, q2, v1, v2, tau1, tau2\n\n0, 0.1, 0.2, 1, 2, 3, 4\r\n0.01, 0.11, 0.22, 1.5, 2.5, 3.5, 4.5\n0.02, 0.12, 0.24, 1.6, 2.6, 3.6, 4.6\n";
        let plain = from_reader(csv.as_bytes(), Some(2)).unwrap();
        let loaded = Recipe::default().read_from(csv.as_bytes(), Some(2)).unwrap();
        assert_eq!(loaded.trajectory, plain);
        for k in 0..plain.len() {
            assert_eq!(loaded.trajectory.location(k), plain.location(k));
        }
        assert_eq!(loaded.report.velocity, Provenance::Measured { columns: vec![4, 5] });
        assert_eq!(loaded.report.acceleration, Provenance::Missing);
        assert_eq!((loaded.report.rows, loaded.report.dropped()), (3, 0));
        assert!(loaded.report.uniform);
        // Derivatives on a uniform grid are exactly those of the schema reader's path.
        let full = loaded.with_derivatives(10.0).unwrap();
        assert_eq!(full.trajectory, plain.with_derivatives(10.0).unwrap());
    }

    #[test]
    fn default_recipe_matches_the_schema_reader_with_wrenches_and_errors() {
        let mut csv = String::from("t,q1,tau1,fx1,fy1,fz1,mx1,my1,mz1\n");
        for k in 0..5 {
            let x = k as f64;
            csv += &row(",", &[0.01 * x, 0.1 * x, 1.0 + x, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0 + x]);
        }
        let plain = from_reader(csv.as_bytes(), None).unwrap();
        assert_eq!(
            Recipe::default().read_from(csv.as_bytes(), None).unwrap().trajectory,
            plain
        );
        // The schema's own column names in errors, as the schema reader writes them.
        let bad = "t,q1,tau1\n0,0,0\n0.01,oops,0\n";
        assert_eq!(load_err("", bad, None), "line 3, column `q1`: `oops` is not a number");
    }

    #[test]
    fn headerless_files_in_the_writers_order() {
        let csv = "0,0.1,1.0\n0.01,0.2,1.1\n0.02,0.3,1.2\n";
        let log = load("header = false", csv, Some(1)).unwrap();
        assert_eq!(log.trajectory.positions(), &[0.1, 0.2, 0.3]);
        assert_eq!(log.trajectory.torques(), &[1.0, 1.1, 1.2]);
        // Without the joint count: t, q, tau.
        assert_eq!(load("header = false", csv, None).unwrap().trajectory.dof(), 1);
        // 1 + 3n fields: measured velocities before the torques.
        let csv = "0,0.1,0.2,5,6,1.0,2.0\n0.01,0.2,0.3,5,6,1.1,2.1\n";
        let log = load("header = false", csv, Some(2)).unwrap();
        assert_eq!(log.trajectory.velocities().unwrap(), &[5.0, 6.0, 5.0, 6.0]);
        assert_eq!(log.trajectory.torques(), &[1.0, 2.0, 1.1, 2.1]);
        assert_eq!(log.trajectory.location(1), crate::data::Location::Line(2));
    }

    #[test]
    fn a_line_the_delimiter_does_not_split_gets_a_separator_hint() {
        let hint = |delimiter: &str, found: &str, fields: usize| {
            format!(
                "line 1: no {delimiter} separates the fields, but a {found} splits the line into {fields}: the file \
                 looks"
            )
        };
        let csv = "t;q1;q2;tau1;tau2\n0;0;0;0;0\n0.01;0;0;0;0\n";
        assert!(load_err("", csv, None).starts_with(&hint("`,`", "`;`", 5)));
        assert!(load_err("", &csv.replace(';', "\t"), None).starts_with(&hint("`,`", "tab", 5)));
        // Without a header, from the first row; and a comma file read as semicolons.
        assert!(
            load_err("header = false", &csv[csv.find('\n').unwrap() + 1..], None).starts_with(&hint("`,`", "`;`", 5))
        );
        let e = load_err("delimiter = semicolon", &csv.replace(';', ","), None);
        assert!(e.starts_with(&hint("`;`", "`,`", 5)), "{e}");
        assert!(e.ends_with("read it with `delimiter = comma` in a recipe (`--delimiter comma` on the command line)"));
        // A header the delimiter splits keeps its own errors.
        let e = load_err("", "t,q1;x,tau1\n0,0,0\n", None);
        assert!(e.contains("unknown column `q1;x`"), "{e}");
    }

    #[test]
    fn semicolons_names_and_ignored_columns() {
        let recipe = "delimiter = semicolon\ntime = stamp\nq = j1, j2\ntau = 5-6";
        let csv = "stamp; j1; j2; status; m1; m2\n0; 0.5; 0.6; ok; 7; 8\n0.01; 0.7; 0.8; ok; 9; 10\n";
        let log = load(recipe, csv, Some(2)).unwrap();
        assert_eq!(log.trajectory.positions(), &[0.5, 0.6, 0.7, 0.8]);
        assert_eq!(log.trajectory.torques(), &[7.0, 8.0, 9.0, 10.0]);
        assert_eq!(log.report.q_columns, vec![2, 3]);
        assert_eq!(log.report.tau_columns, vec![5, 6]);
        // Tabs and runs of spaces.
        let tabbed = csv.replace("; ", "\t");
        let log = load(&recipe.replace("semicolon", "tab"), &tabbed, Some(2)).unwrap();
        assert_eq!(log.trajectory.positions(), &[0.5, 0.6, 0.7, 0.8]);
        let spaced = csv.replace("; ", "   ");
        let log = load(
            &recipe.replace("semicolon", "whitespace"),
            &format!("  {spaced}"),
            Some(2),
        )
        .unwrap();
        assert_eq!(log.trajectory.torques(), &[7.0, 8.0, 9.0, 10.0]);
    }

    #[test]
    fn degrees_currents_gains_and_sign_flips() {
        let recipe = "header = false\nq = 2-3\nv = 4-5\ntau = 6-7\nunits = deg\ngains = 0.5, 2\nsign = 1, -1";
        let csv = "0,90,180,45,-45,1,1\n0.01,-90,0,0,90,2,-3\n";
        let log = load(recipe, csv, Some(2)).unwrap();
        let pi = std::f64::consts::PI;
        let t = &log.trajectory;
        assert_eq!(t.q(0), &[pi / 2.0, -pi]);
        assert_eq!(t.q(1), &[-pi / 2.0, -0.0]);
        assert_eq!(t.v(0).unwrap(), &[pi / 4.0, pi / 4.0]);
        assert_eq!(t.tau(0), &[0.5, -2.0]);
        assert_eq!(t.tau(1), &[1.0, 6.0]);
        assert!(log.report.currents);
        assert!(log
            .report
            .to_string()
            .contains("torque: motor currents × gains (columns 6–7)"));
        // Per-joint units.
        let mut r = Recipe::parse(recipe).unwrap();
        r.set("units", "deg, mm").unwrap();
        assert_eq!(r.units, vec![JointUnit::Deg, JointUnit::Mm]);
        let log = r.read_from(csv.as_bytes(), Some(2)).unwrap();
        assert_eq!(log.trajectory.q(0), &[pi / 2.0, -0.18]);
    }

    /// A 2-joint sine logged by a 10 ms logger whose steps are 8–13 ms.
    fn jittered(seed: u64, len: usize) -> (String, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut t = 0.0;
        let mut csv = String::from("t,q1,q2,tau1,tau2\n");
        let mut stamps = Vec::new();
        for _ in 0..len {
            csv += &row(",", &[t, (2.0 * t).sin(), (3.0 * t).cos(), t, 1.0]);
            stamps.push(t);
            t += rng.gen_range(0.008..0.013);
        }
        (csv, stamps)
    }

    #[test]
    fn jittered_time_as_it_is() {
        let (csv, stamps) = jittered(7, 400);
        let log = load("", &csv, Some(2)).unwrap();
        assert_eq!(log.trajectory.t(), &stamps[..]);
        let r = &log.report;
        assert!(!r.uniform);
        assert!(r.steps.min >= 0.008 && r.steps.max < 0.013, "{:?}", r.steps);
        assert!(r.steps.median > 0.0095 && r.steps.median < 0.0115, "{:?}", r.steps);
        assert!(r.to_string().contains("(irregular: used as they are)"), "{r}");
        let full = log.with_derivatives(15.0).unwrap();
        assert_eq!(
            full.report.acceleration,
            Provenance::Estimated {
                cutoff_hz: 15.0,
                uniform: false
            }
        );
        // Away from the ends, derivatives of the smooth motion on the true stamps.
        let t = full.trajectory.t();
        for k in 50..350 {
            let v = full.trajectory.v(k).unwrap();
            let a = full.trajectory.a(k).unwrap();
            assert!((v[0] - 2.0 * (2.0 * t[k]).cos()).abs() < 2e-3, "v at {k}: {v:?}");
            assert!((a[0] + 4.0 * (2.0 * t[k]).sin()).abs() < 2e-2, "a at {k}: {a:?}");
        }
    }

    #[test]
    fn jittered_time_resampled() {
        let (csv, stamps) = jittered(8, 400);
        let log = load("resample = 0.01", &csv, Some(2)).unwrap();
        let t = log.trajectory.t();
        assert_eq!(t[0], 0.0);
        assert!(t.windows(2).all(|w| ((w[1] - w[0]) - 0.01).abs() < 1e-12));
        assert!(*t.last().unwrap() <= *stamps.last().unwrap());
        assert_eq!(log.report.resampled, Some(0.01));
        assert_eq!(log.report.samples, t.len());
        // Resampled samples are not file lines.
        assert_eq!(log.trajectory.location(3), crate::data::Location::Sample(3));
        for (k, &tk) in t.iter().enumerate() {
            assert!((log.trajectory.q(k)[0] - (2.0 * tk).sin()).abs() < 1e-5, "q at {tk}");
            assert!((log.trajectory.tau(k)[0] - tk).abs() < 1e-12);
        }
        let full = log.with_derivatives(15.0).unwrap();
        assert_eq!(
            full.report.velocity,
            Provenance::Estimated {
                cutoff_hz: 15.0,
                uniform: true
            }
        );
    }

    #[test]
    fn duplicates_are_dropped_and_counted() {
        let csv = "t,q1,tau1\n0,1,1\n0,1,1\n0.01,2,2\n0.01,2.5,2\n0.01,2,2\n0.02,3,3\n0.03,3,3\n";
        let log = load("", csv, Some(1)).unwrap();
        assert_eq!(log.trajectory.t(), &[0.0, 0.01, 0.02, 0.03]);
        // The first row of a time stamp wins.
        assert_eq!(log.trajectory.positions(), &[1.0, 2.0, 3.0, 3.0]);
        assert_eq!((log.report.repeated, log.report.same_time, log.report.stale), (2, 1, 0));
        assert!(log
            .report
            .to_string()
            .contains("dropped 2 repeated rows, 1 rows repeating a time stamp"));
        // Stale rows, on request.
        let log = load("stale = drop", csv, Some(1)).unwrap();
        assert_eq!(log.trajectory.t(), &[0.0, 0.01, 0.02]);
        assert_eq!(log.report.stale, 1);
    }

    #[test]
    fn time_and_row_windows_units_and_origin() {
        let mut csv = String::new();
        for k in 0..10 {
            csv += &row(" ", &[1.7e12 + 10.0 * k as f64, k as f64, 0.0]);
        }
        let recipe = "delimiter = whitespace\nheader = false\ntime_unit = ms\ntime_origin = first";
        let log = load(&format!("{recipe}\nwindow = 0.02:0.05"), &csv, Some(1)).unwrap();
        assert_eq!(log.trajectory.positions(), &[2.0, 3.0, 4.0, 5.0]);
        assert!((log.trajectory.t()[0] - 0.02).abs() < 1e-12);
        assert_eq!(log.report.outside_window, 6);
        assert_eq!(log.trajectory.location(0), crate::data::Location::Line(3));
        // Open-ended windows.
        let log = load(&format!("{recipe}\nwindow = :0.015"), &csv, Some(1)).unwrap();
        assert_eq!(log.trajectory.positions(), &[0.0, 1.0]);
        // Rows 4 to 7: the origin is the first row read.
        let log = load(&format!("{recipe}\nrows = 4:7"), &csv, Some(1)).unwrap();
        assert_eq!(log.trajectory.positions(), &[3.0, 4.0, 5.0, 6.0]);
        assert_eq!(log.trajectory.t()[0], 0.0);
        assert_eq!(log.report.rows, 4);
        // A window skips a damaged part unread.
        let damaged = csv.replace("1700000000080 8 0", "1700000000080 oops 0");
        assert!(load(&format!("{recipe}\nrows = :8"), &damaged, Some(1)).is_ok());
        assert!(load(&format!("{recipe}\nwindow = :0.07"), &damaged, Some(1)).is_ok());
    }

    #[test]
    fn decimation_keeps_every_nth_sample() {
        let mut csv = String::from("t,q1,tau1\n");
        for k in 0..10 {
            csv += &row(",", &[0.01 * k as f64, k as f64, 0.0]);
        }
        let log = load("decimate = 3", &csv, None).unwrap();
        assert_eq!(log.trajectory.positions(), &[0.0, 3.0, 6.0, 9.0]);
        assert_eq!(log.report.decimated, 6);
        assert!(log.report.uniform);
    }

    #[test]
    fn measured_velocities_are_used_and_reported() {
        let mut csv = String::new();
        for k in 0..50 {
            let t = 0.01 * k as f64;
            csv += &row(",", &[t, t.sin(), 7.0, 0.0]);
        }
        let log = load("header = false\nq = 2\nv = 3\ntau = 4", &csv, Some(1)).unwrap();
        let full = log.with_derivatives(10.0).unwrap();
        assert!(full.trajectory.velocities().unwrap().iter().all(|&v| v == 7.0));
        // Accelerations from the measured velocities: a constant's derivative.
        assert!(full.trajectory.accelerations().unwrap().iter().all(|a| a.abs() < 1e-9));
        let text = full.report.to_string();
        assert!(
            text.contains("velocity: measured (column 3); acceleration: estimated by zero-phase differentiation"),
            "{text}"
        );
        assert!(!text.contains("low-passed"), "{text}");
        let filtered = full.clone().with_states_low_passed(10.0).unwrap();
        assert!(filtered
            .trajectory
            .velocities()
            .unwrap()
            .iter()
            .all(|&v| (v - 7.0).abs() < 1e-9));
        let text = filtered.report.to_string();
        assert!(
            text.ends_with("\npositions and measured velocities low-passed at 10 Hz (zero phase)"),
            "{text}"
        );
        // At or above the Nyquist frequency (50 Hz here) the states are kept as read.
        let kept = full.clone().with_states_low_passed(50.0).unwrap();
        assert_eq!(kept.report.states_low_passed, None);
        assert_eq!(kept.report.states_above_nyquist, Some(50.0));
        assert_eq!(kept.trajectory.positions(), full.trajectory.positions());
        let text = kept.report.to_string();
        assert!(
            text.ends_with(
                "\npositions used as read: the cutoff is at or above the Nyquist frequency (50 Hz) of the samples"
            ),
            "{text}"
        );
        assert!(full.with_states_low_passed(f64::NAN).is_err());
    }

    #[test]
    fn line_endings_are_counted_as_lines() {
        let csv = "t,q1,tau1\r\n0,0,0\r0.01,0,0\r\n\n0.02,x,0\n";
        let e = load_err("", csv, None);
        assert_eq!(e, "line 5, column `q1`: `x` is not a number");
    }

    #[test]
    fn a_byte_order_mark_is_skipped_by_both_readers() {
        let csv = "\u{feff}t,q1,tau1\n0,0,1\n0.01,0.1,1\n0.02,0.2,1\n";
        assert_eq!(load("", csv, None).unwrap().trajectory.len(), 3);
        assert_eq!(from_reader(csv.as_bytes(), None).unwrap().len(), 3);
        // Without a header too, and only at the very start.
        assert_eq!(
            load("header = false", &format!("\u{feff}{}", &csv[3 + 10..]), None)
                .unwrap()
                .trajectory
                .len(),
            3
        );
        let e = load_err("", "t,q1,tau1\n\u{feff}0,0,1\n0.01,0.1,1\n", None);
        assert!(e.starts_with("line 2, column `t`: `\u{feff}0` is not a number"), "{e}");
    }

    #[test]
    fn a_line_longer_than_the_limit_is_refused_by_both_readers() {
        let mut long = b"t,q1,tau1\n0,0,1\n".to_vec();
        long.extend(std::iter::repeat_n(b'7', MAX_LINE_BYTES + 1));
        long.extend_from_slice(b"\n0.02,0.2,1\n");
        let message = "line 3 is longer than 1048576 bytes (1 MiB) without a line break; a recording holds one \
                       sample per line, so this is not a text recording (a binary file?) or its line breaks are lost";
        let e = Recipe::default().read_from(&long[..], None).unwrap_err();
        assert!(matches!(e, DataError::LineTooLong { line: 3, .. }), "{e}");
        assert_eq!(e.to_string(), message);
        let e = from_reader(&long[..], None).unwrap_err();
        assert_eq!((e.to_string(), e.line()), (message.to_string(), Some(3)));
        // A line of exactly the limit is read (spaces around fields are ignored),
        // also after `\r` line breaks.
        let mut at_limit = b"t,q1,tau1\r0,0,1\r\n0.01,0.1,1\r".to_vec();
        let row = b"0.02,0.2,1";
        at_limit.extend_from_slice(row);
        at_limit.extend(std::iter::repeat_n(b' ', MAX_LINE_BYTES - row.len()));
        at_limit.push(b'\r');
        assert_eq!(
            Recipe::default()
                .read_from(&at_limit[..], None)
                .unwrap()
                .trajectory
                .len(),
            3
        );
        assert_eq!(from_reader(&at_limit[..], None).unwrap().len(), 3);
    }

    #[test]
    fn error_fields_name_line_and_column() {
        let recipe = "header = false\nq = 2\ntau = 3\ngains = 2";
        assert_eq!(
            load_err(recipe, "0,0,0\n0.01,zz,0\n", None),
            "line 2, column 2 (q1): `zz` is not a number"
        );
        assert_eq!(
            load_err(recipe, "0,0,0\n0.01,0,NaN\n", None),
            "line 2, column 3 (current1): NaN is not a finite number"
        );
        assert_eq!(
            load_err(recipe, "0,0,0\n0.01,0,\n", None),
            "line 2, column 3 (current1): empty field; expected a number"
        );
        let e = load_err(recipe, "0,0,0\n0.01,0,6e5\n", None);
        assert!(
            e.starts_with("line 2, column 3 (current1): 1.2e6 after scaling to SI units; values must lie within ±1e6"),
            "{e}"
        );
        let e = load_err("time_unit = ns", "t,q1,tau1\n1.7e18,0,0\n1.7e18,0,0\n", None);
        assert!(
            e.contains("line 2, column `t`") && e.contains("time_origin = first"),
            "{e}"
        );
        // Named columns carry their header name.
        let e = load_err("q = pos\ntau = cur", "t,pos,cur\n0,0,0\n0.01,1e9,0\n", None);
        assert!(e.starts_with("line 3, column 2 `pos` (q1): 1e9"), "{e}");
    }

    #[test]
    fn error_time_going_back() {
        let e = load_err("", "t,q1,tau1\n0,0,0\n0.02,0,0\n0.01,0,0\n", None);
        assert_eq!(
            e,
            "line 4, column `t`: time t = 0.01 s is before t = 0.02 s on line 3; time must increase (rows with an \
             equal time stamp are dropped as duplicates)"
        );
    }

    #[test]
    fn error_columns_of_the_recipe() {
        let csv = "a,b,c\n0,0,0\n0.01,0,0\n";
        let e = load_err("q = 2\ntau = 9", csv, None);
        assert_eq!(
            e,
            "line 1: recipe `tau` names column 9, but the line has 3 field(s); columns are numbered 1 to 3"
        );
        let e = load_err("q = b\ntau = z", csv, None);
        assert_eq!(
            e,
            "line 1: recipe `tau` names column `z`, which the header does not have; its columns are `a`, `b`, `c`"
        );
        let e = load_err("q = 2\ntau = 2", csv, None);
        assert_eq!(
            e,
            "column 2 is given both as `q1` and as `tau1`; each column holds one quantity"
        );
        let e = load_err("q = 2\ntau = 3\ntime = 3", csv, None);
        assert!(e.starts_with("column 3 is given both as `t`"), "{e}");
        let e = load_err("q = 2\ntau = 3", csv, Some(2));
        assert!(
            e.starts_with("recipe `q` names 1 column(s); give one per joint (2"),
            "{e}"
        );
        let e = load_err("q = 2\ntau = 3\ngains = 1, 2", csv, None);
        assert_eq!(
            e,
            "recipe `gains` has 2 value(s); give 1 (for every joint) or 1 (one per joint)"
        );
        let e = load_err("header = false\nq = b\ntau = 3", "0,0,0\n", None);
        assert!(e.contains("`q = b`: expected column numbers"), "{e}");
    }

    #[test]
    fn error_layout_and_row_width() {
        let e = load_err("header = false", "0,1,2,3,4,5\n", Some(1));
        assert!(e.starts_with("line 1: 6 fields and no header or column settings; for 1 joints the columns must be t, q1..q1, tau1..tau1 (3 fields)"), "{e}");
        let e = load_err("header = false", "0,1,2\n0.01,1\n", None);
        assert_eq!(
            e,
            "line 2: 2 fields, expected 3 like line 1; every row needs the same columns"
        );
    }

    /// Logs longer than a batch read as they would line by line: the schema reader
    /// gives the same trajectory, and errors past the first batch name their line.
    #[test]
    fn logs_longer_than_a_batch() {
        let rows = 3 * BATCH_LINES + 17;
        let mut csv = String::from("t,q1,q2,tau1,tau2\n");
        for k in 0..rows {
            let t = 0.001 * k as f64;
            csv += &row(",", &[t, t.sin(), t.cos(), 2.0 * t, -t]);
            if k % 1000 == 7 {
                csv += "\n";
            }
        }
        let plain = from_reader(csv.as_bytes(), Some(2)).unwrap();
        let loaded = Recipe::default().read_from(csv.as_bytes(), Some(2)).unwrap();
        assert_eq!(loaded.trajectory, plain);
        assert_eq!(loaded.report.rows, rows);
        for k in [0, BATCH_LINES - 1, BATCH_LINES, rows - 1] {
            assert_eq!(loaded.trajectory.location(k), plain.location(k));
        }
        // A bad value two batches in: its line, counting the header and blank lines.
        let bad_row = 2 * BATCH_LINES + 5;
        let mut lines: Vec<&str> = csv.lines().collect();
        let index = lines
            .iter()
            .position(|l| l.starts_with(&format!("{},", 0.001 * bad_row as f64)))
            .unwrap();
        let mut fields: Vec<&str> = lines[index].split(',').collect();
        fields[1] = "oops";
        let broken = fields.join(",");
        lines[index] = &broken;
        let e = load_err("", &(lines.join("\n") + "\n"), None);
        assert_eq!(e, format!("line {}, column `q1`: `oops` is not a number", index + 1));
    }

    #[test]
    fn error_too_few_samples_left() {
        let csv = "t,q1,tau1\n0,0,0\n0,0,0\n0.01,0,0\n0.02,0,0\n";
        let e = load_err("window = 0.015:", csv, None);
        assert_eq!(
            e,
            "1 sample(s) left of 4 row(s) read (3 dropped as duplicates, outside the windows or by decimation); a \
             trajectory needs at least 2"
        );
        let log = load("window = 0.005:", csv, None).unwrap();
        let e = log.with_derivatives(10.0).unwrap_err().to_string();
        assert!(
            e.starts_with("2 sample(s) left of 4 row(s) read")
                && e.ends_with("estimating velocities and accelerations needs at least 3"),
            "{e}"
        );
        assert_eq!(load_err("", "t,q1,tau1\n", None), "0 sample(s); at least 2 are needed");
        assert_eq!(
            load_err("header = false", "", None).to_string(),
            DataError::Empty.to_string()
        );
    }

    #[test]
    fn error_resample_step() {
        let csv = "t,q1,tau1\n0,0,0\n0.01,0,0\n0.02,0,0\n";
        let e = load_err("resample = 1", csv, None);
        assert!(e.contains("at most the log's duration"), "{e}");
        let e = load_err("resample = 1e-6", csv, None);
        assert!(e.contains("at most 100 times the 3 samples read"), "{e}");
    }

    #[test]
    fn errors_are_collected_over_the_file() {
        let e = load("", "t,q1,tau1\n0,a,0\n0.01,b,0\n0.02,0,c\n", None).unwrap_err();
        let lines: Vec<_> = e.errors().iter().map(|e| e.line()).collect();
        assert_eq!(lines, vec![Some(2), Some(3), Some(4)]);
    }

    /// 150,000 rows of a 7-joint arm (t, q, v, tau: 22 columns) load in one pass.
    #[test]
    fn a_long_log_loads() {
        let rows = 150_000;
        let mut csv = String::with_capacity(rows * 22 * 12);
        let mut rng = ChaCha8Rng::seed_from_u64(150);
        let mut t = 0.0f64;
        let mut line = Vec::with_capacity(22);
        for k in 0..rows {
            line.clear();
            line.push(t);
            for j in 0..21 {
                line.push(((k + j) as f64 * 1e-3).sin());
            }
            csv += &row(",", &line);
            t += rng.gen_range(0.0008..0.0012);
        }
        let recipe = "header = false\nq = 2-8\nv = 9-15\ntau = 16-22";
        let log = load(recipe, &csv, Some(7)).unwrap();
        assert_eq!((log.trajectory.len(), log.trajectory.dof()), (rows, 7));
        assert_eq!(log.report.rows, rows);
        let full = log.with_derivatives(20.0).unwrap();
        assert_eq!(full.trajectory.accelerations().unwrap().len(), rows * 7);
    }
}
