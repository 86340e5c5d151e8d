//! The valid range of the numeric flags, in one place: clap value parsers that
//! refuse a value outside its range at parse time with the flag, the value and the
//! range (a usage error, exit code 2), so that no command runs on an absurd value
//! (`--duration 1e300`, `--steps 100000000000`, `--noise 1e300`).
//!
//! A flag declares its range with `value_parser = ranges::F64(…)` or
//! `ranges::Count(…)` using the constants below; its help text states the range.
//! Checks that involve two flags (the logger's samples, duration over period) are
//! in the commands and use the same constants.

use clap::builder::TypedValueParser;
use clap::error::ErrorKind;
use std::ffi::OsStr;

/// A real interval. `open_min`/`open_max` exclude the end.
#[derive(Clone, Copy, Debug)]
pub struct F64 {
    pub min: f64,
    pub max: f64,
    pub open_min: bool,
    pub open_max: bool,
    /// The unit or meaning, for the message (`s`, `m/s²`, `a fraction`).
    pub unit: &'static str,
}

impl F64 {
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite()
            && (if self.open_min { x > self.min } else { x >= self.min })
            && (if self.open_max { x < self.max } else { x <= self.max })
    }

    /// `0 < x ≤ 1e6 (s)`.
    pub fn describe(&self) -> String {
        format!(
            "{} {} x {} {} ({})",
            self.min,
            if self.open_min { "<" } else { "≤" },
            if self.open_max { "<" } else { "≤" },
            self.max,
            self.unit
        )
    }
}

/// A whole number in `min..=max`.
#[derive(Clone, Copy, Debug)]
pub struct Count {
    pub min: usize,
    pub max: usize,
}

/// The flag as the user wrote it (`--duration`), or the argument's name.
fn flag_name(arg: Option<&clap::Arg>) -> String {
    match arg {
        Some(a) => match a.get_long() {
            Some(long) => format!("--{long}"),
            None => a.get_id().to_string(),
        },
        None => "the value".into(),
    }
}

fn out_of_range(cmd: &clap::Command, arg: Option<&clap::Arg>, value: &OsStr, expected: String) -> clap::Error {
    let mut cmd = cmd.clone();
    cmd.error(
        ErrorKind::ValueValidation,
        format!(
            "{} {}: out of range; expected {expected}",
            flag_name(arg),
            value.to_string_lossy()
        ),
    )
}

impl TypedValueParser for F64 {
    type Value = f64;

    fn parse_ref(&self, cmd: &clap::Command, arg: Option<&clap::Arg>, value: &OsStr) -> Result<f64, clap::Error> {
        match value.to_str().and_then(|s| s.trim().parse::<f64>().ok()) {
            Some(x) if self.contains(x) => Ok(x),
            _ => Err(out_of_range(
                cmd,
                arg,
                value,
                format!("a number with {}", self.describe()),
            )),
        }
    }
}

impl TypedValueParser for Count {
    type Value = usize;

    fn parse_ref(&self, cmd: &clap::Command, arg: Option<&clap::Arg>, value: &OsStr) -> Result<usize, clap::Error> {
        match value.to_str().and_then(|s| s.trim().parse::<usize>().ok()) {
            Some(n) if (self.min..=self.max).contains(&n) => Ok(n),
            _ => Err(out_of_range(
                cmd,
                arg,
                value,
                format!("a whole number from {} to {}", self.min, self.max),
            )),
        }
    }
}

const fn closed(min: f64, max: f64, unit: &'static str) -> F64 {
    F64 {
        min,
        max,
        open_min: false,
        open_max: false,
        unit,
    }
}

/// `(min, max]`: a positive quantity.
const fn positive(max: f64, unit: &'static str) -> F64 {
    F64 {
        min: 0.0,
        max,
        open_min: true,
        open_max: false,
        unit,
    }
}

/// Gravity components: within ±100 g.
pub const GRAVITY: F64 = closed(-1000.0, 1000.0, "m/s², each component");
/// Lengths of an experiment: up to 10⁶ s (11.6 days).
pub const DURATION: F64 = positive(1e6, "s");
/// Samples of a simulated experiment: `--steps` + 1, up to a million (about 0.5 GB
/// for a 6-joint arm with its wrenches).
pub const STEPS: Count = Count { min: 1, max: 1_000_000 };
/// The most samples a simulated logger writes (`--duration` / `--logger-period`).
pub const MAX_LOGGER_SAMPLES: usize = 1_000_000;
/// Relative noise: a fraction of each channel's RMS, up to 1 (100 %).
pub const NOISE: F64 = closed(0.0, 1.0, "a fraction of the RMS: 0.01 = 1 %");
/// A logger's sampling period.
pub const LOGGER_PERIOD: F64 = positive(1e3, "s");
/// The logger's jitter, a fraction of the period.
pub const JITTER: F64 = F64 {
    min: 0.0,
    max: 1.0,
    open_min: false,
    open_max: true,
    unit: "a fraction of the period",
};
/// Fractions of rows (duplicates, stale rows).
pub const FRACTION: F64 = closed(0.0, 1.0, "a fraction of the rows");
/// The logger's current resolution.
pub const CURRENT_QUANTUM: F64 = closed(0.0, 1e3, "A");
/// Fourier harmonics per joint.
pub const HARMONICS: Count = Count { min: 1, max: 50 };
/// The Fourier base frequency: a period (the default duration) of at most
/// [`DURATION`]'s 1e6 s.
pub const BASE_FREQUENCY: F64 = closed(1e-6, 1e3, "Hz");
/// Objective evaluations of the excitation optimiser.
pub const EVALUATIONS: Count = Count {
    min: 0,
    max: 10_000_000,
};
/// A time budget.
pub const TIME_BUDGET: F64 = positive(1e6, "s");
/// `generate --max-statements`: below 100 a function splits into thousands of parts.
pub const MAX_STATEMENTS: Count = Count {
    min: 100,
    max: 10_000_000,
};
/// Ridge weight.
pub const LAMBDA: F64 = closed(0.0, 1e12, "dimensionless");
/// Low-pass cutoffs.
pub const CUTOFF: F64 = positive(1e6, "Hz");
/// The smoothing ε of Fc·tanh(q̇/ε).
pub const EPSILON: F64 = positive(1e3, "rad/s or m/s");
/// `identify --exclude-below`: a joint speed.
pub const EXCLUDE_BELOW: F64 = positive(1e3, "rad/s or m/s");
/// NIM: relative half-width of the parameter draws.
pub const SPREAD: F64 = F64 {
    min: 0.0,
    max: 1.0,
    open_min: false,
    open_max: true,
    unit: "a fraction of the nominal value",
};
/// `demo --test-draws`: at least one draw to compare on.
pub const DEMO_TEST_DRAWS: Count = Count { min: 1, max: 1_000_000 };
/// NIM: samples per window.
pub const WINDOW: Count = Count { min: 1, max: 10_000 };
/// NIM: parameter draws.
pub const DRAWS: Count = Count {
    min: 1,
    max: 10_000_000,
};
/// NIM: Adam steps per body.
pub const ADAM_STEPS: Count = Count {
    min: 1,
    max: 100_000_000,
};
/// NIM: test draws (0: none).
pub const TEST_DRAWS: Count = Count { min: 0, max: 1_000_000 };
/// Worker threads (0: one per core).
pub const THREADS: Count = Count { min: 0, max: 1024 };
/// NIM predict: window stride.
pub const STRIDE: Count = Count { min: 1, max: 1_000_000 };

/// One value for every joint, or one per joint, comma-separated, each within
/// ±[`dyngen_identify::data::MAX_ABS_VALUE`] (what a recording may hold).
pub fn per_joint(flag: &str, text: &str, n: usize) -> Result<Vec<f64>, crate::error::CliError> {
    per_joint_sets(flag, text, n, 1)
}

/// One set of `per` values for every joint, or one set per joint (joint by joint),
/// comma-separated, each within ±[`dyngen_identify::data::MAX_ABS_VALUE`]: `per·n`
/// values in joint order.
pub fn per_joint_sets(flag: &str, text: &str, n: usize, per: usize) -> Result<Vec<f64>, crate::error::CliError> {
    use crate::error::CliError;
    let limit = dyngen_identify::data::MAX_ABS_VALUE;
    let values: Vec<f64> = text
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && v.abs() <= limit)
        })
        .collect::<Option<_>>()
        .ok_or_else(|| CliError::usage(format!("{flag}: `{text}` is not a list of numbers within ±{limit:e}")))?;
    match values.len() {
        k if k == per => Ok(values.repeat(n)),
        k if k == per * n => Ok(values),
        k if per == 1 => Err(CliError::usage(format!(
            "{flag}: {k} values for {n} joints; give one for all joints or one per joint"
        ))),
        k => Err(CliError::usage(format!(
            "{flag}: {k} values for {n} joints; give {per} for all joints or {} ({per} per joint, joint by joint)",
            per * n
        ))),
    }
}

/// `--extra-terms`: the list [`ExtraTerms`](dyngen_identify::extras::ExtraTerms)
/// parses.
pub fn extra_terms(text: &str) -> Result<dyngen_identify::extras::ExtraTerms, String> {
    text.parse()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_describe_themselves() {
        assert_eq!(DURATION.describe(), "0 < x ≤ 1000000 (s)");
        assert_eq!(JITTER.describe(), "0 ≤ x < 1 (a fraction of the period)");
        assert!(DURATION.contains(1e6) && !DURATION.contains(0.0) && !DURATION.contains(f64::NAN));
        assert!(!GRAVITY.contains(-1e300) && GRAVITY.contains(-9.81));
    }
}
