//! The recipe: how to read one logger's files (layout, units, windows), as `key = value`
//! lines (format in the [module docs](super#recipes)) or set key by key from code or
//! command-line flags through [`Recipe::set`].

use std::fmt;
use std::path::{Path, PathBuf};

use super::error::MAX_COLUMNS;

/// Field separator of a log.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Delimiter {
    #[default]
    Comma,
    Semicolon,
    Tab,
    /// Any run of spaces and tabs; leading and trailing ones are ignored.
    Whitespace,
}

impl Delimiter {
    /// The recipe value naming this delimiter.
    pub fn name(self) -> &'static str {
        match self {
            Delimiter::Comma => "comma",
            Delimiter::Semicolon => "semicolon",
            Delimiter::Tab => "tab",
            Delimiter::Whitespace => "whitespace",
        }
    }

    /// The separator byte; `None` for runs of whitespace.
    pub(super) fn byte(self) -> Option<u8> {
        match self {
            Delimiter::Comma => Some(b','),
            Delimiter::Semicolon => Some(b';'),
            Delimiter::Tab => Some(b'\t'),
            Delimiter::Whitespace => None,
        }
    }

    /// The delimiter a line not split by `used` seems to use instead, and the
    /// number of fields it gives: one that splits the line into at least two
    /// non-empty fields (semicolon, tab, comma, in that order). `None` when `used`
    /// splits the line already.
    pub(super) fn guess_other(line: &[u8], used: Delimiter) -> Option<(Delimiter, usize)> {
        let already = match used.byte() {
            Some(b) => line.contains(&b),
            None => line.trim_ascii().iter().any(u8::is_ascii_whitespace),
        };
        if already {
            return None;
        }
        [Delimiter::Semicolon, Delimiter::Tab, Delimiter::Comma]
            .into_iter()
            .filter(|&d| d != used)
            .find_map(|d| {
                let b = d.byte()?;
                let fields = line.split(|&c| c == b).filter(|f| !f.trim_ascii().is_empty()).count();
                (fields >= 2).then_some((d, fields))
            })
    }
}

/// Unit of the time column; time stamps are converted to seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TimeUnit {
    #[default]
    Seconds,
    Milliseconds,
    Microseconds,
    Nanoseconds,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn seconds(self) -> f64 {
        match self {
            TimeUnit::Seconds => 1.0,
            TimeUnit::Milliseconds => 1e-3,
            TimeUnit::Microseconds => 1e-6,
            TimeUnit::Nanoseconds => 1e-9,
        }
    }
}

/// Where time zero is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TimeOrigin {
    /// The file's time stamps as they are.
    #[default]
    File,
    /// The first data row read (within `rows`) is t = 0: for clock time stamps.
    FirstRow,
}

/// Unit of a joint's position column (and of its velocity and acceleration per s, s²).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JointUnit {
    /// Radians (revolute) or metres (prismatic): no conversion.
    #[default]
    Rad,
    Deg,
    /// Metres: the same as `Rad` (SI), for readability of prismatic joints.
    M,
    Mm,
}

impl JointUnit {
    /// SI units per unit.
    pub fn scale(self) -> f64 {
        match self {
            JointUnit::Rad | JointUnit::M => 1.0,
            JointUnit::Deg => std::f64::consts::PI / 180.0,
            JointUnit::Mm => 1e-3,
        }
    }
}

/// What to do with irregular time stamps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Sampling {
    /// Keep the time stamps; derivatives are taken on the non-uniform grid.
    #[default]
    AsIs,
    /// Interpolate every column onto `t₀ + k·dt` (cubic Hermite), `dt` in s.
    Resample(f64),
}

/// Rows whose values all equal the previous row's under a new time stamp (a logger
/// repeating a sensor value it did not update).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Stale {
    /// Kept: a robot at rest with quantised sensors repeats values legitimately.
    #[default]
    Keep,
    Drop,
}

/// A column given by its 1-based position or its header name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ColumnRef {
    Index(usize),
    Name(String),
}

impl fmt::Display for ColumnRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ColumnRef::Index(i) => write!(f, "{i}"),
            ColumnRef::Name(n) => write!(f, "`{n}`"),
        }
    }
}

/// Which columns hold what. All `None`: the named schema (with a header) or the
/// writer's column order (without one).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Columns {
    /// Default when other columns are given: column 1.
    pub time: Option<ColumnRef>,
    pub q: Option<Vec<ColumnRef>>,
    pub v: Option<Vec<ColumnRef>>,
    pub a: Option<Vec<ColumnRef>>,
    /// Torques, or motor currents when [`Recipe::gains`] is set.
    pub tau: Option<Vec<ColumnRef>>,
}

impl Columns {
    /// No column settings at all.
    pub fn is_default(&self) -> bool {
        *self == Columns::default()
    }
}

/// An inclusive time window in seconds (after `time_unit` and `time_origin`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TimeWindow {
    pub start: Option<f64>,
    pub end: Option<f64>,
}

/// An inclusive window of data rows, counted from 1 after the header (blank lines
/// not counted), before anything is dropped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RowWindow {
    pub first: Option<usize>,
    pub last: Option<usize>,
}

/// How to read a log: layout, units, which part, how to treat its time stamps.
/// [`Recipe::default`] reads the named CSV schema exactly as [`read_csv`](super::read_csv)
/// does (and drops duplicate time stamps, which that reader rejects).
#[derive(Clone, Debug, PartialEq)]
pub struct Recipe {
    pub delimiter: Delimiter,
    pub header: bool,
    /// Lines skipped before the header (or the first row): a logger's preamble.
    pub skip: usize,
    pub columns: Columns,
    pub time_unit: TimeUnit,
    pub time_origin: TimeOrigin,
    /// Empty: SI; one unit for every joint; or one per joint.
    pub units: Vec<JointUnit>,
    /// Motor torque constants: the `tau` columns hold currents and τ = k·i. One
    /// value for every joint or one per joint.
    pub gains: Option<Vec<f64>>,
    /// Per joint ±1, multiplying q, v, a and τ (after the gains): a joint whose
    /// positive direction differs from the model's. Empty: all +1.
    pub signs: Vec<f64>,
    pub window: Option<TimeWindow>,
    pub rows: Option<RowWindow>,
    /// Keep every `decimate`-th sample (1: all).
    pub decimate: usize,
    pub sampling: Sampling,
    pub stale: Stale,
}

impl Default for Recipe {
    fn default() -> Self {
        Recipe {
            delimiter: Delimiter::Comma,
            header: true,
            skip: 0,
            columns: Columns::default(),
            time_unit: TimeUnit::Seconds,
            time_origin: TimeOrigin::File,
            units: Vec::new(),
            gains: None,
            signs: Vec::new(),
            window: None,
            rows: None,
            decimate: 1,
            sampling: Sampling::AsIs,
            stale: Stale::Keep,
        }
    }
}

/// Largest recipe file read, in bytes.
const MAX_RECIPE_BYTES: u64 = 1 << 20;

/// Every key of the format, in the order of the docs.
pub const RECIPE_KEYS: [&str; 18] = [
    "delimiter",
    "header",
    "skip",
    "time",
    "q",
    "v",
    "a",
    "tau",
    "time_unit",
    "time_origin",
    "units",
    "gains",
    "sign",
    "window",
    "rows",
    "decimate",
    "resample",
    "stale",
];

/// A recipe file or setting that cannot be understood. `line` is the 1-based line
/// of the recipe file, `None` for a setting made through [`Recipe::set`].
#[derive(Debug)]
#[non_exhaustive]
pub enum RecipeError {
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A line that is neither blank, a comment, nor `key = value`.
    Syntax {
        line: u64,
        text: String,
    },
    UnknownKey {
        line: Option<u64>,
        key: String,
    },
    /// A key given twice in one file (`first`: the line of the first).
    RepeatedKey {
        line: u64,
        key: String,
        first: u64,
    },
    BadValue {
        line: Option<u64>,
        key: &'static str,
        value: String,
        expected: &'static str,
    },
    /// Column settings without the `q` or `tau` they need.
    MissingKey {
        key: &'static str,
    },
}

impl RecipeError {
    /// The recipe file line, when the error is about one.
    pub fn line(&self) -> Option<u64> {
        match self {
            RecipeError::Syntax { line, .. } | RecipeError::RepeatedKey { line, .. } => Some(*line),
            RecipeError::UnknownKey { line, .. } | RecipeError::BadValue { line, .. } => *line,
            _ => None,
        }
    }

    fn at_line(mut self, at: u64) -> Self {
        match &mut self {
            RecipeError::UnknownKey { line, .. } | RecipeError::BadValue { line, .. } => *line = Some(at),
            _ => {}
        }
        self
    }
}

impl fmt::Display for RecipeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = |line: &Option<u64>| line.map(|l| format!("line {l}: ")).unwrap_or_default();
        match self {
            RecipeError::Io { path, source } => write!(f, "cannot read `{}`: {source}", path.display()),
            RecipeError::Syntax { line, text } => write!(
                f,
                "line {line}: `{text}` is not a setting; expected `key = value`, a blank line or a `#` comment"
            ),
            RecipeError::UnknownKey { line, key } => write!(
                f,
                "{}unknown key `{key}`; valid keys: {}",
                at(line),
                RECIPE_KEYS.join(", ")
            ),
            RecipeError::RepeatedKey { line, key, first } => {
                write!(
                    f,
                    "line {line}: `{key}` is already set on line {first}; give each key once"
                )
            }
            RecipeError::BadValue {
                line,
                key,
                value,
                expected,
            } => {
                write!(f, "{}`{key} = {value}`: expected {expected}", at(line))
            }
            RecipeError::MissingKey { key } => write!(
                f,
                "column settings need `{key}` too (`time` defaults to column 1; `v` and `a` are optional)"
            ),
        }
    }
}

impl std::error::Error for RecipeError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RecipeError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// The canonical spelling of `key`, or `None` if it is not a key.
fn canonical(key: &str) -> Option<&'static str> {
    RECIPE_KEYS.iter().copied().find(|k| *k == key)
}

fn list(value: &str) -> impl Iterator<Item = &str> {
    value.split(',').map(str::trim)
}

/// `a:b` with either end optional.
fn split_window(value: &str) -> Option<(&str, &str)> {
    let (a, b) = value.split_once(':')?;
    Some((a.trim(), b.trim()))
}

/// `3`, `q_act_2`, or ranges `2-7` in a comma list.
fn parse_columns(value: &str) -> Option<Vec<ColumnRef>> {
    let mut out = Vec::new();
    for item in list(value) {
        if item.is_empty() {
            return None;
        }
        let range = item.split_once('-').and_then(|(a, b)| {
            let (a, b) = (a.trim().parse::<usize>().ok()?, b.trim().parse::<usize>().ok()?);
            Some((a, b))
        });
        // Bounded before a range is expanded: `2-4000000000` is no file's columns.
        match (range, item.parse::<usize>()) {
            (Some((a, b)), _) if a >= 1 && a <= b && b <= MAX_COLUMNS => out.extend((a..=b).map(ColumnRef::Index)),
            (Some(_), _) => return None,
            (None, Ok(0)) => return None,
            (None, Ok(i)) if i > MAX_COLUMNS => return None,
            (None, Ok(i)) => out.push(ColumnRef::Index(i)),
            (None, Err(_)) => out.push(ColumnRef::Name(item.to_string())),
        }
        if out.len() > MAX_COLUMNS {
            return None;
        }
    }
    Some(out)
}

fn parse_bool(value: &str) -> Option<bool> {
    match value {
        "true" | "yes" => Some(true),
        "false" | "no" => Some(false),
        _ => None,
    }
}

fn parse_number(value: &str) -> Option<f64> {
    value.parse::<f64>().ok().filter(|x| x.is_finite())
}

impl Recipe {
    /// Reads a recipe file (format in the [module docs](super#recipes)).
    pub fn from_file(path: impl AsRef<Path>) -> Result<Recipe, RecipeError> {
        use std::io::Read;
        let path = path.as_ref();
        let io = |source| RecipeError::Io {
            path: path.to_path_buf(),
            source,
        };
        // A recipe is a few lines: read at most 1 MiB and a byte, so that a wrong
        // path (`/dev/zero`, a recording) fails instead of filling the memory.
        let mut text = String::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_RECIPE_BYTES + 1).read_to_string(&mut text))
            .map_err(io)?;
        if text.len() as u64 > MAX_RECIPE_BYTES {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("longer than {MAX_RECIPE_BYTES} bytes; a recipe is a few `key = value` lines"),
            )));
        }
        Recipe::parse(text.strip_prefix('\u{feff}').unwrap_or(&text))
    }

    /// Parses a recipe from its text: `key = value` lines, `#` comments, blank
    /// lines; keys not given keep their defaults.
    pub fn parse(text: &str) -> Result<Recipe, RecipeError> {
        let mut recipe = Recipe::default();
        let mut seen: Vec<(&'static str, u64)> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = i as u64 + 1;
            let content = raw.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            let Some((key, value)) = content.split_once('=') else {
                return Err(RecipeError::Syntax {
                    line,
                    text: raw.trim().to_string(),
                });
            };
            let key = key.trim();
            let Some(canonical) = canonical(key) else {
                return Err(RecipeError::UnknownKey {
                    line: Some(line),
                    key: key.to_string(),
                });
            };
            if let Some(&(_, first)) = seen.iter().find(|(k, _)| *k == canonical) {
                return Err(RecipeError::RepeatedKey {
                    line,
                    key: key.to_string(),
                    first,
                });
            }
            seen.push((canonical, line));
            recipe.set(key, value.trim()).map_err(|e| e.at_line(line))?;
        }
        recipe.check()?;
        Ok(recipe)
    }

    /// The recipe without its time and row windows: how to read any recording
    /// of the same logger, not which part of one.
    pub fn without_window(&self) -> Recipe {
        Recipe {
            window: None,
            rows: None,
            ..self.clone()
        }
    }

    /// Its time and row windows alone as recipe lines joined by `; ` (`window = 5:65;
    /// rows = 1:900`), `None` when it has neither: the part of one recording it
    /// reads, as the parameters JSON records it.
    pub fn window_text(&self) -> Option<String> {
        let windows = Recipe {
            window: self.window,
            rows: self.rows,
            ..Recipe::default()
        };
        let text = windows.to_text();
        (!text.is_empty()).then(|| text.trim_end().replace('\n', "; "))
    }

    /// The recipe as `key = value` lines that [`Recipe::parse`] reads back to the
    /// same recipe; only the keys that differ from [`Recipe::default`] are written
    /// (the default recipe is the empty text). Header names holding `,` or `#`
    /// cannot be written as recipe lines and come back differently.
    pub fn to_text(&self) -> String {
        let d = Recipe::default();
        let mut lines: Vec<String> = Vec::new();
        let mut put = |key: &str, value: String| lines.push(format!("{key} = {value}"));
        let columns = |c: &[ColumnRef]| {
            c.iter()
                .map(|c| match c {
                    ColumnRef::Index(i) => i.to_string(),
                    ColumnRef::Name(n) => n.clone(),
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        // `start:end`, an open end left empty.
        fn span<T: ToString>(start: Option<T>, end: Option<T>) -> String {
            let bound = |x: Option<T>| x.map(|x| x.to_string()).unwrap_or_default();
            format!("{}:{}", bound(start), bound(end))
        }
        if self.delimiter != d.delimiter {
            put("delimiter", self.delimiter.name().into());
        }
        if self.header != d.header {
            put("header", self.header.to_string());
        }
        if self.skip != d.skip {
            put("skip", self.skip.to_string());
        }
        if let Some(t) = &self.columns.time {
            put("time", columns(std::slice::from_ref(t)));
        }
        for (key, c) in [
            ("q", &self.columns.q),
            ("v", &self.columns.v),
            ("a", &self.columns.a),
            ("tau", &self.columns.tau),
        ] {
            if let Some(c) = c {
                put(key, columns(c));
            }
        }
        if self.time_unit != d.time_unit {
            let unit = match self.time_unit {
                TimeUnit::Seconds => "s",
                TimeUnit::Milliseconds => "ms",
                TimeUnit::Microseconds => "us",
                TimeUnit::Nanoseconds => "ns",
            };
            put("time_unit", unit.into());
        }
        if self.time_origin != d.time_origin {
            put("time_origin", "first".into());
        }
        if !self.units.is_empty() {
            let units: Vec<&str> = self
                .units
                .iter()
                .map(|u| match u {
                    JointUnit::Rad => "rad",
                    JointUnit::Deg => "deg",
                    JointUnit::M => "m",
                    JointUnit::Mm => "mm",
                })
                .collect();
            put("units", units.join(", "));
        }
        if let Some(gains) = &self.gains {
            put("gains", gains.iter().map(f64::to_string).collect::<Vec<_>>().join(", "));
        }
        if !self.signs.is_empty() {
            let signs: Vec<&str> = self.signs.iter().map(|s| if *s < 0.0 { "-1" } else { "1" }).collect();
            put("sign", signs.join(", "));
        }
        if let Some(w) = &self.window {
            put("window", span(w.start, w.end));
        }
        if let Some(r) = &self.rows {
            put("rows", span(r.first, r.last));
        }
        if self.decimate != d.decimate {
            put("decimate", self.decimate.to_string());
        }
        if let Sampling::Resample(dt) = self.sampling {
            put("resample", dt.to_string());
        }
        if self.stale != d.stale {
            put("stale", "drop".into());
        }
        lines.iter().map(|l| format!("{l}\n")).collect()
    }

    /// Sets one key as a recipe line `key = value` would (a later setting replaces
    /// an earlier one): how command-line flags override a recipe file.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), RecipeError> {
        let key = canonical(key).ok_or_else(|| RecipeError::UnknownKey {
            line: None,
            key: key.to_string(),
        })?;
        let value = value.trim();
        let bad = |expected: &'static str| RecipeError::BadValue {
            line: None,
            key,
            value: value.to_string(),
            expected,
        };
        const COLUMNS: &str =
            "column numbers (from 1 to 524288, the most fields a line of 1 MiB holds) or header names, separated by \
             commas; ranges as `2-7`";
        const _: () = assert!(MAX_COLUMNS == 524288, "the message above states MAX_COLUMNS");
        match key {
            "delimiter" => {
                self.delimiter = match value {
                    "comma" | "," => Delimiter::Comma,
                    "semicolon" | ";" => Delimiter::Semicolon,
                    "tab" | "\\t" => Delimiter::Tab,
                    "whitespace" | "space" => Delimiter::Whitespace,
                    _ => return Err(bad("`comma`, `semicolon`, `tab` or `whitespace`")),
                }
            }
            "header" => self.header = parse_bool(value).ok_or_else(|| bad("`true` or `false`"))?,
            "skip" => self.skip = value.parse().map_err(|_| bad("a number of lines, 0 or more"))?,
            "time" => {
                let mut c = parse_columns(value).ok_or_else(|| bad(COLUMNS))?;
                if c.len() != 1 {
                    return Err(bad("one column number (from 1) or header name"));
                }
                self.columns.time = c.pop();
            }
            "q" | "v" | "a" | "tau" => {
                let c = parse_columns(value).ok_or_else(|| bad(COLUMNS))?;
                let slot = match key {
                    "q" => &mut self.columns.q,
                    "v" => &mut self.columns.v,
                    "a" => &mut self.columns.a,
                    _ => &mut self.columns.tau,
                };
                *slot = Some(c);
            }
            "time_unit" => {
                self.time_unit = match value {
                    "s" => TimeUnit::Seconds,
                    "ms" => TimeUnit::Milliseconds,
                    "us" | "µs" | "μs" => TimeUnit::Microseconds,
                    "ns" => TimeUnit::Nanoseconds,
                    _ => return Err(bad("`s`, `ms`, `us` (or `µs`) or `ns`")),
                }
            }
            "time_origin" => {
                self.time_origin = match value {
                    "file" => TimeOrigin::File,
                    "first" => TimeOrigin::FirstRow,
                    _ => {
                        return Err(bad(
                            "`file` (time stamps as they are) or `first` (the first row is t = 0)",
                        ))
                    }
                }
            }
            "units" => {
                self.units = list(value)
                    .map(|u| match u {
                        "rad" => Some(JointUnit::Rad),
                        "deg" => Some(JointUnit::Deg),
                        "m" => Some(JointUnit::M),
                        "mm" => Some(JointUnit::Mm),
                        _ => None,
                    })
                    .collect::<Option<_>>()
                    .ok_or_else(|| bad("`rad`, `deg`, `m` or `mm`, once for every joint or once per joint"))?
            }
            "gains" => {
                let gains: Vec<f64> = list(value)
                    .map(|g| parse_number(g).filter(|g| *g != 0.0))
                    .collect::<Option<_>>()
                    .ok_or_else(|| {
                        bad("finite non-zero torque constants (N·m/A), one for all joints or one per joint")
                    })?;
                self.gains = Some(gains);
            }
            "sign" => {
                self.signs = list(value)
                    .map(|s| match s {
                        "1" | "+1" | "+" => Some(1.0),
                        "-1" | "-" => Some(-1.0),
                        _ => None,
                    })
                    .collect::<Option<_>>()
                    .ok_or_else(|| bad("one `1` or `-1` per joint"))?
            }
            "window" => {
                let (a, b) =
                    split_window(value).ok_or_else(|| bad("`t0:t1` in seconds (either end may be left out)"))?;
                let end = |s: &str| {
                    if s.is_empty() {
                        Some(None)
                    } else {
                        parse_number(s).map(Some)
                    }
                };
                let (Some(start), Some(end)) = (end(a), end(b)) else {
                    return Err(bad("`t0:t1` in seconds (either end may be left out)"));
                };
                if let (Some(s), Some(e)) = (start, end) {
                    if s >= e {
                        return Err(bad("`t0:t1` with t0 < t1"));
                    }
                }
                self.window = Some(TimeWindow { start, end });
            }
            "rows" => {
                let expected = "`first:last`, data rows counted from 1 (either end may be left out)";
                let (a, b) = split_window(value).ok_or_else(|| bad(expected))?;
                let end = |s: &str| {
                    if s.is_empty() {
                        Some(None)
                    } else {
                        s.parse::<usize>().ok().filter(|r| *r >= 1).map(Some)
                    }
                };
                let (Some(first), Some(last)) = (end(a), end(b)) else {
                    return Err(bad(expected));
                };
                if let (Some(f), Some(l)) = (first, last) {
                    if f > l {
                        return Err(bad("`first:last` with first ≤ last"));
                    }
                }
                self.rows = Some(RowWindow { first, last });
            }
            "decimate" => {
                self.decimate = value
                    .parse::<usize>()
                    .ok()
                    .filter(|d| *d >= 1)
                    .ok_or_else(|| bad("a whole number ≥ 1 (keep every N-th sample)"))?
            }
            "resample" => {
                self.sampling = match value {
                    "off" | "none" => Sampling::AsIs,
                    _ => Sampling::Resample(
                        parse_number(value)
                            .filter(|dt| *dt > 0.0)
                            .ok_or_else(|| bad("a time step > 0 in seconds, or `off`"))?,
                    ),
                }
            }
            "stale" => {
                self.stale = match value {
                    "keep" => Stale::Keep,
                    "drop" => Stale::Drop,
                    _ => return Err(bad("`keep` or `drop`")),
                }
            }
            _ => {
                return Err(RecipeError::UnknownKey {
                    line: None,
                    key: key.to_string(),
                })
            }
        }
        Ok(())
    }

    /// Checks what single settings cannot: column settings need `q` and `tau`.
    pub fn check(&self) -> Result<(), RecipeError> {
        let c = &self.columns;
        if c.is_default() {
            return Ok(());
        }
        if c.q.is_none() {
            return Err(RecipeError::MissingKey { key: "q" });
        }
        if c.tau.is_none() {
            return Err(RecipeError::MissingKey { key: "tau" });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        Recipe::parse(text).expect_err("an error").to_string()
    }

    #[test]
    fn to_text_reads_back_to_the_same_recipe() {
        assert_eq!(Recipe::default().to_text(), "");
        for text in [
            "delimiter = tab\nheader = false\nskip = 2\ntime = 1\nq = 2-3, 5\nv = 6,7,8\na = 9-11\n\
             tau = t1, t2, t3\ntime_unit = µs\ntime_origin = first\nunits = deg, rad, mm\ngains = 0.1, 0.2, 1e-7\n\
             sign = 1, -1, +1\nwindow = -1.5:\nrows = :100\ndecimate = 3\nresample = 0.001\nstale = drop\n",
            "window = :7.25\nrows = 4:\nunits = deg\n",
            "time_unit = ms\nq = q_a, q_b\ntau = 8-9\n",
        ] {
            let recipe = Recipe::parse(text).unwrap();
            let written = recipe.to_text();
            assert_eq!(Recipe::parse(&written).unwrap(), recipe, "{written}");
        }
    }

    #[test]
    fn every_key_parses() {
        let r = Recipe::parse(
            "# a logger
delimiter = tab
header = false   # no names
skip = 2
time = 1
q = 2-3, 5
v = 6,7,8
a = 9-11
tau = t1, t2, t3
time_unit = µs
time_origin = first
units = deg, rad, mm
gains = 0.1, 0.2, 0.3
sign = 1, -1, +1
window = 1.5:
rows = :100
decimate = 4
resample = 0.005
stale = drop
",
        )
        .unwrap();
        assert_eq!(r.delimiter, Delimiter::Tab);
        assert!(!r.header);
        assert_eq!(r.skip, 2);
        assert_eq!(r.columns.time, Some(ColumnRef::Index(1)));
        let idx = |v: &[usize]| v.iter().map(|&i| ColumnRef::Index(i)).collect::<Vec<_>>();
        assert_eq!(r.columns.q, Some(idx(&[2, 3, 5])));
        assert_eq!(r.columns.a, Some(idx(&[9, 10, 11])));
        assert_eq!(r.columns.tau.as_ref().unwrap()[1], ColumnRef::Name("t2".into()));
        assert_eq!(r.time_unit, TimeUnit::Microseconds);
        assert_eq!(r.time_origin, TimeOrigin::FirstRow);
        assert_eq!(r.units, vec![JointUnit::Deg, JointUnit::Rad, JointUnit::Mm]);
        assert_eq!(r.gains, Some(vec![0.1, 0.2, 0.3]));
        assert_eq!(r.signs, vec![1.0, -1.0, 1.0]);
        assert_eq!(
            r.window,
            Some(TimeWindow {
                start: Some(1.5),
                end: None
            })
        );
        assert_eq!(
            r.rows,
            Some(RowWindow {
                first: None,
                last: Some(100)
            })
        );
        assert_eq!(r.decimate, 4);
        assert_eq!(r.sampling, Sampling::Resample(0.005));
        assert_eq!(r.stale, Stale::Drop);
    }

    #[test]
    fn empty_recipe_is_the_default() {
        assert_eq!(Recipe::parse("\n# nothing\n").unwrap(), Recipe::default());
    }

    #[test]
    fn set_overrides_a_file_setting() {
        let mut r = Recipe::parse("delimiter = semicolon\nresample = 0.01").unwrap();
        r.set("delimiter", "whitespace").unwrap();
        r.set("resample", "off").unwrap();
        assert_eq!((r.delimiter, r.sampling), (Delimiter::Whitespace, Sampling::AsIs));
        let e = r.set("gains", "1,x").unwrap_err();
        assert_eq!(e.line(), None);
        assert_eq!(
            e.to_string(),
            "`gains = 1,x`: expected finite non-zero torque constants (N·m/A), one for all joints or one per joint"
        );
    }

    #[test]
    fn error_syntax_names_the_line() {
        assert_eq!(
            err("header = true\n\njust words\n"),
            "line 3: `just words` is not a setting; expected `key = value`, a blank line or a `#` comment"
        );
    }

    #[test]
    fn error_unknown_key_lists_the_valid_ones() {
        let e = err("delimter = tab");
        assert!(
            e.starts_with("line 1: unknown key `delimter`; valid keys: delimiter, header, skip,"),
            "{e}"
        );
    }

    #[test]
    fn error_repeated_key() {
        assert_eq!(
            err("q = 1\nsign = 1\nq = 2"),
            "line 3: `q` is already set on line 1; give each key once"
        );
    }

    #[test]
    fn error_bad_values_say_what_is_valid() {
        let cases = [
            ("delimiter = pipe", "line 1: `delimiter = pipe`: expected `comma`, `semicolon`, `tab` or `whitespace`"),
            ("header = maybe", "line 1: `header = maybe`: expected `true` or `false`"),
            ("skip = -1", "line 1: `skip = -1`: expected a number of lines, 0 or more"),
            ("time = 1, 2", "line 1: `time = 1, 2`: expected one column number (from 1) or header name"),
            ("q = 0", "line 1: `q = 0`: expected column numbers (from 1 to 524288, the most fields a line of 1 MiB holds) or header names, separated by commas; ranges as `2-7`"),
            ("q = 5-2", "line 1: `q = 5-2`: expected column numbers (from 1 to 524288, the most fields a line of 1 MiB holds) or header names, separated by commas; ranges as `2-7`"),
            ("q = 1,,2", "line 1: `q = 1,,2`: expected column numbers (from 1 to 524288, the most fields a line of 1 MiB holds) or header names, separated by commas; ranges as `2-7`"),
            ("q = 2-4000000000", "line 1: `q = 2-4000000000`: expected column numbers (from 1 to 524288, the most fields a line of 1 MiB holds) or header names, separated by commas; ranges as `2-7`"),
            ("tau = 524289", "line 1: `tau = 524289`: expected column numbers (from 1 to 524288, the most fields a line of 1 MiB holds) or header names, separated by commas; ranges as `2-7`"),
            ("time_unit = h", "line 1: `time_unit = h`: expected `s`, `ms`, `us` (or `µs`) or `ns`"),
            ("time_origin = 0", "line 1: `time_origin = 0`: expected `file` (time stamps as they are) or `first` (the first row is t = 0)"),
            ("units = grad", "line 1: `units = grad`: expected `rad`, `deg`, `m` or `mm`, once for every joint or once per joint"),
            ("gains = 0", "line 1: `gains = 0`: expected finite non-zero torque constants (N·m/A), one for all joints or one per joint"),
            ("sign = 2", "line 1: `sign = 2`: expected one `1` or `-1` per joint"),
            ("window = 3", "line 1: `window = 3`: expected `t0:t1` in seconds (either end may be left out)"),
            ("window = 3:1", "line 1: `window = 3:1`: expected `t0:t1` with t0 < t1"),
            ("window = a:1", "line 1: `window = a:1`: expected `t0:t1` in seconds (either end may be left out)"),
            ("rows = 0:5", "line 1: `rows = 0:5`: expected `first:last`, data rows counted from 1 (either end may be left out)"),
            ("rows = 5:2", "line 1: `rows = 5:2`: expected `first:last` with first ≤ last"),
            ("decimate = 0", "line 1: `decimate = 0`: expected a whole number ≥ 1 (keep every N-th sample)"),
            ("resample = -0.01", "line 1: `resample = -0.01`: expected a time step > 0 in seconds, or `off`"),
            ("stale = maybe", "line 1: `stale = maybe`: expected `keep` or `drop`"),
        ];
        for (text, message) in cases {
            assert_eq!(err(text), message);
        }
    }

    #[test]
    fn error_columns_need_q_and_tau() {
        assert_eq!(
            err("q = 2-3"),
            "column settings need `tau` too (`time` defaults to column 1; `v` and `a` are optional)"
        );
        assert!(err("tau = 2").contains("need `q`"));
    }

    #[test]
    fn error_missing_file() {
        let e = Recipe::from_file("/nonexistent/dir/log.recipe").unwrap_err();
        assert!(
            e.to_string().starts_with("cannot read `/nonexistent/dir/log.recipe`"),
            "{e}"
        );
    }
}
