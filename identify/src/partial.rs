//! Partial factors: identification from many recordings, each compressed on its
//! own (on any machine) and merged exactly.
//!
//! The joint-torque identification of [`crate::pipeline`] is a sum over samples:
//! per joint, the triangular factor `R` of the rows of `[A y]` (or their Gram
//! matrix) summarises every row it has seen, and the factors of two sets of rows
//! stacked and re-factored are the factor of all the rows. A [`Partial`] is that
//! summary of one recording (or of several, merged), with what it takes to merge it
//! safely: the robot it was made for ([`RobotIdentity`]), every option that shaped
//! its rows ([`RowOptions`]) and the recordings it holds. Partials of the same robot
//! and row options merge in any order and grouping ([`Partial::merge`], a reduce
//! tree) and [`Partial::identify`] then solves with any estimator, giving what one
//! run on all the samples gives, up to rounding.
//!
//! What needs the rows themselves cannot be formed from merged factors, and is
//! refused when a partial is made ([`Partial::from_trajectory`]): the Coulomb
//! smoothing ε chosen on held-out time blocks (`FrictionAuto`), the nonlinear Stribeck
//! fit with its held-out blocks, and MIM (body by body from the joint wrenches).
//! A partial holds no estimate, so predicting or plotting recordings is left to the
//! merged result.
//!
//! A partial is stored as JSON (schema [`PARTIAL_SCHEMA`]); its numbers read back
//! bit for bit.

use crate::data::{Recipe, Trajectory};
use crate::extras::ExtraTerms;
use crate::mim::TorqueRegressor;
use crate::pipeline::{self, Identification, IdentifyOptions, JointTerms, Mode, PipelineError};
use crate::report::DataSpan;
use crate::{Accumulation, Accumulator, AccumulatorState};
use dyngen_model::joint_params::Coulomb;
use dyngen_reference::Dynamics;
use serde::{Deserialize, Serialize};
use std::fmt;

/// The schema (and version) of a partial factor file.
pub const PARTIAL_SCHEMA: &str = "dyngen-partial/1";

/// The sufficient statistics of the joint-torque rows of some recordings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Partial {
    /// [`PARTIAL_SCHEMA`].
    pub schema: String,
    pub robot: RobotIdentity,
    pub rows: RowOptions,
    /// Every recording whose rows it holds, and the part of it used.
    pub recordings: Vec<DataSpan>,
    /// Per joint, the factor of its rows of `[A y]`.
    pub accumulator: AccumulatorState,
}

/// What a partial's regressor columns mean: the robot and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotIdentity {
    /// The robot's name.
    pub name: String,
    /// Its joints, in the order of the channels.
    pub joints: Vec<String>,
    /// The parameters, in the order of the regressor's columns.
    pub parameters: Vec<String>,
    /// Gravity in the base frame (m/s²).
    pub gravity: [f64; 3],
    /// The regressor at a fixed state ([`signature_state`]), row-major: two robots
    /// with the same names but other kinematics (or, for the principal parameters,
    /// other centres of mass and axes) differ here.
    pub signature: Vec<f64>,
}

/// Every option that shapes the rows of a partial (the estimator does not: it is
/// chosen when the merged partial is solved).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowOptions {
    /// `standard` or `principal`.
    pub mode: String,
    /// `none`, `sign` or `smooth`.
    pub friction: String,
    /// ε of `Fc·tanh(q̇/ε)` with `smooth` friction.
    pub epsilon: Option<f64>,
    /// [`IdentifyOptions::rotor_inertia`].
    pub rotor_inertia: Option<bool>,
    /// [`IdentifyOptions::extras`] (absent: none).
    #[serde(default, skip_serializing_if = "ExtraTerms::is_empty")]
    pub extras: ExtraTerms,
    pub accumulation: Accumulation,
    /// [`IdentifyOptions::exclude_below`].
    pub exclude_below: Option<f64>,
    /// Low-pass cutoff (Hz) of the estimated derivatives and the states.
    pub cutoff_hz: f64,
    /// Measured positions and velocities low-passed at the cutoff too.
    pub low_pass_states: bool,
    /// The recipe the recordings were read through, as `key = value` lines, without
    /// its time and row windows (each recording's span is in
    /// [`Partial::recordings`]); empty: dyngen's own CSV schema.
    pub recipe: String,
}

/// Why a partial could not be read, merged or solved.
#[derive(Debug)]
pub enum PartialError {
    /// Not JSON, or not the fields of a partial.
    Json(serde_json::Error),
    /// The file's schema is not [`PARTIAL_SCHEMA`] (`None`: it has none).
    Schema(Option<String>),
    /// The factors are inconsistent (sizes, non-finite numbers, not whole samples).
    Invalid(String),
    /// Two partials, or a partial and a robot or options, do not describe the same
    /// rows: `what` differs, `ours` against `theirs`.
    Mismatch {
        what: &'static str,
        ours: String,
        theirs: String,
    },
    /// Making or solving failed in the pipeline.
    Pipeline(PipelineError),
}

impl fmt::Display for PartialError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Json(e) => write!(f, "not a partial factor file ({e})"),
            Self::Schema(Some(s)) => write!(
                f,
                "a `{s}` file; this dyngen reads partial factors of schema `{PARTIAL_SCHEMA}` (write the partials \
                 again with this version: `dyngen identify ROBOT DATA --partial OUT`)"
            ),
            Self::Schema(None) => write!(
                f,
                "not a partial factor file: no `schema` field (expected `{PARTIAL_SCHEMA}`, written by `dyngen \
                 identify ROBOT DATA --partial OUT`)"
            ),
            Self::Invalid(reason) => write!(f, "an invalid partial factor: {reason}"),
            Self::Mismatch { what, ours, theirs } => write!(f, "different {what}: {ours} against {theirs}"),
            Self::Pipeline(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for PartialError {}

impl From<PipelineError> for PartialError {
    fn from(e: PipelineError) -> Self {
        PartialError::Pipeline(e)
    }
}

/// The state the [`RobotIdentity::signature`] regressor is evaluated at, for `n`
/// joints: fixed, generic values (no joint at a symmetric angle or at rest).
pub fn signature_state(n: usize) -> [Vec<f64>; 3] {
    let at = |a: f64, b: f64| (0..n).map(|j| a + b * j as f64).collect::<Vec<_>>();
    [at(0.31, 0.17), at(-0.23, 0.11), at(0.41, -0.07)]
}

/// Signatures equal to this, relative to their largest entry, are the same robot
/// (the same model loaded on another machine may round differently).
const SIGNATURE_TOLERANCE: f64 = 1e-9;

impl RobotIdentity {
    /// The identity of `dynamics` with the columns of `regressor`.
    fn of(dynamics: &dyn Dynamics, regressor: &TorqueRegressor, parameters: Vec<String>) -> Self {
        let model = dynamics.model();
        let n = dynamics.nv();
        let [q, v, a] = signature_state(n);
        let mut signature = vec![0.0; n * regressor.columns(model)];
        regressor.eval(dynamics, &q, &v, &a, &mut signature);
        RobotIdentity {
            name: model.name.clone(),
            joints: model.own_joints().map(|j| j.name.clone()).collect(),
            parameters,
            gravity: model.gravity,
            signature,
        }
    }

    /// The first difference from `other`.
    fn compare(&self, other: &RobotIdentity) -> Result<(), PartialError> {
        let mismatch = |what, ours: String, theirs: String| Err(PartialError::Mismatch { what, ours, theirs });
        let joints = |r: &RobotIdentity| format!("robot `{}` with joints [{}]", r.name, r.joints.join(", "));
        if self.name != other.name || self.joints != other.joints {
            return mismatch("robots", joints(self), joints(other));
        }
        if self.parameters != other.parameters {
            let list = |r: &RobotIdentity| format!("{} parameters [{}]", r.parameters.len(), r.parameters.join(", "));
            return mismatch("parameters", list(self), list(other));
        }
        if self.gravity != other.gravity {
            return mismatch(
                "gravity",
                format!("{:?} m/s²", self.gravity),
                format!("{:?} m/s²", other.gravity),
            );
        }
        let scale = self.signature.iter().fold(1e-300_f64, |m, x| m.max(x.abs()));
        let off = self
            .signature
            .iter()
            .zip(&other.signature)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        if self.signature.len() != other.signature.len() || off > SIGNATURE_TOLERANCE * scale {
            return mismatch(
                "kinematics",
                format!("robot `{}`", self.name),
                format!(
                    "a robot of the same name and joints whose regressor differs by {:.1e} relative at a test state \
                     (other joint origins, axes{})",
                    off / scale,
                    if self.parameters.iter().any(|p| p.starts_with("J1")) {
                        ", centres of mass or principal axes"
                    } else {
                        ""
                    }
                ),
            );
        }
        Ok(())
    }
}

impl RowOptions {
    /// The row options of `options` read through `recipe`; refuses the options
    /// whose estimate needs the rows themselves.
    fn of(options: &IdentifyOptions, recipe: &Recipe) -> Result<Self, PipelineError> {
        let refuse = |option, reason: &str| {
            Err(PipelineError::InvalidOption {
                option,
                reason: reason.to_string(),
            })
        };
        let mode =
            match options.mode {
                Mode::Standard => "standard",
                Mode::Principal => "principal",
                Mode::Mim => return refuse(
                    "mode",
                    "mim cannot be written as a partial factor: MIM identifies body by body from the joint wrenches \
                     of the recording itself, not from accumulated torque rows; use --mode standard or principal \
                     with partial factors, or identify from one recording",
                ),
            };
        let (friction, epsilon) =
            match options.joints {
                JointTerms::None => ("none", None),
                JointTerms::Friction(Coulomb::Sign) => ("sign", None),
                JointTerms::Friction(Coulomb::Smooth { epsilon }) => ("smooth", Some(epsilon)),
                JointTerms::FrictionAuto => {
                    return refuse(
                        "friction",
                        "auto cannot be written as a partial factor: it chooses the Coulomb smoothing ε by the fit \
                     residual of the recording's own rows, which a partial does not keep (and each recording would \
                     choose its own); give the ε instead: --friction smooth --epsilon E (a run on one recording with \
                     --friction auto prints the ε it chose), or --friction sign",
                    )
                }
                JointTerms::Stribeck(_) => return refuse(
                    "friction",
                    "stribeck and stribeck-smooth cannot be written as partial factors: the Stribeck terms are fitted \
                     by nonlinear least squares on the recording's rows and checked on held-out blocks of it, which a \
                     partial does not keep; use --friction sign or smooth with partial factors",
                ),
            };
        if options.extras.motor_harmonics > 0 {
            return refuse(
                "extra-terms",
                "motor-ripple cannot be written as a partial factor: a partial does not keep the gear ratios its \
                 rows were made with; use the other extra terms with partial factors",
            );
        }
        if options.extras.load {
            return refuse(
                "extra-terms",
                "load cannot be written as a partial factor: its rows take the load from the rigid-body parameters \
                 of a fit on the same rows, refitted until they settle, which a partial does not keep; use the \
                 other extra terms with partial factors",
            );
        }
        Ok(RowOptions {
            mode: mode.into(),
            friction: friction.into(),
            epsilon,
            rotor_inertia: options.rotor_inertia,
            extras: options.extras,
            accumulation: options.accumulation,
            exclude_below: options.exclude_below,
            cutoff_hz: options.cutoff_hz,
            low_pass_states: options.low_pass_states,
            recipe: recipe.without_window().to_text(),
        })
    }

    /// These row options in `options` (the estimator, tolerances and truth kept).
    fn apply(&self, options: &mut IdentifyOptions) -> Result<(), PartialError> {
        let invalid = |what: &str, value: &str| PartialError::Invalid(format!("unknown {what} `{value}`"));
        options.mode = match self.mode.as_str() {
            "standard" => Mode::Standard,
            "principal" => Mode::Principal,
            other => return Err(invalid("mode (standard or principal)", other)),
        };
        options.joints = match (self.friction.as_str(), self.epsilon) {
            ("none", _) => JointTerms::None,
            ("sign", _) => JointTerms::Friction(Coulomb::Sign),
            ("smooth", Some(epsilon)) => JointTerms::Friction(Coulomb::Smooth { epsilon }),
            (other, _) => return Err(invalid("friction (none, sign, or smooth with an epsilon)", other)),
        };
        options.rotor_inertia = self.rotor_inertia;
        options.extras = self.extras;
        options.accumulation = self.accumulation;
        options.exclude_below = self.exclude_below;
        options.cutoff_hz = self.cutoff_hz;
        options.low_pass_states = self.low_pass_states;
        Ok(())
    }

    /// Each row option by its command-line name, as text.
    fn shown(&self) -> [(&'static str, String); 10] {
        let or_none = |x: Option<f64>| x.map_or_else(|| "none".to_string(), |x| x.to_string());
        [
            ("mode", self.mode.clone()),
            ("friction", self.friction.clone()),
            ("epsilon", or_none(self.epsilon)),
            (
                "rotor-inertia",
                match self.rotor_inertia {
                    None => "with the friction terms",
                    Some(true) => "yes",
                    Some(false) => "no",
                }
                .to_string(),
            ),
            ("extra-terms", self.extras.to_string()),
            (
                "accumulation",
                match self.accumulation {
                    Accumulation::Qr => "qr",
                    Accumulation::NormalEquations => "normal-equations",
                }
                .to_string(),
            ),
            ("exclude-below", or_none(self.exclude_below)),
            ("cutoff", format!("{} Hz", self.cutoff_hz)),
            (
                "raw-states",
                if self.low_pass_states {
                    "states low-passed"
                } else {
                    "raw states"
                }
                .to_string(),
            ),
            ("recipe", format!("{:?}", self.recipe.trim_end())),
        ]
    }

    /// The first difference from `other`, by option name.
    fn compare(&self, other: &RowOptions) -> Result<(), PartialError> {
        match self
            .shown()
            .into_iter()
            .zip(other.shown())
            .find(|((_, a), (_, b))| a != b)
        {
            Some(((what, ours), (_, theirs))) => Err(PartialError::Mismatch { what, ours, theirs }),
            None => Ok(()),
        }
    }
}

/// Refuses the options whose estimate needs the rows themselves (before any
/// recording is read): `FrictionAuto`, `Stribeck`, [`Mode::Mim`].
pub fn check_options(options: &IdentifyOptions) -> Result<(), PipelineError> {
    RowOptions::of(options, &Recipe::default()).map(|_| ())
}

impl Partial {
    /// The partial factor of `traj` (read through `recipe` as `span` says, with
    /// velocities and accelerations: see [`pipeline::load`]) for `dynamics` with the
    /// row options of `options` (its estimator is not used).
    ///
    /// Errors: the options [`pipeline::identify`] refuses, and those whose estimate
    /// needs the rows (`--friction auto`, `stribeck`, `--mode mim`), each naming the
    /// option and what works instead; a recording of another robot or without
    /// derivatives; a row the accumulation refuses.
    pub fn from_trajectory(
        dynamics: &dyn Dynamics,
        traj: &Trajectory,
        options: &IdentifyOptions,
        recipe: &Recipe,
        span: DataSpan,
    ) -> Result<Partial, PipelineError> {
        options.check()?;
        let rows = RowOptions::of(options, recipe)?;
        let regressor = pipeline::torque_regressor(options);
        let names = regressor.names(dynamics.model());
        let accumulator = pipeline::accumulate_recording(dynamics, traj, &regressor, options)?
            .to_state()
            .map_err(PipelineError::from)?;
        if accumulator
            .per_channel
            .iter()
            .any(|c| c.factor.iter().flatten().any(|x| !x.is_finite()))
        {
            return Err(PipelineError::NonFiniteEstimate {
                largest: Some(pipeline::largest_input(traj)),
            });
        }
        Ok(Partial {
            schema: PARTIAL_SCHEMA.into(),
            robot: RobotIdentity::of(dynamics, &regressor, names),
            rows,
            recordings: vec![span],
            accumulator,
        })
    }

    /// Adds `other`'s rows to these, as if its recordings had been read after
    /// these: the factors stacked and re-factored, the recordings listed.
    ///
    /// Errors: another robot ([`RobotIdentity`]) or other row options
    /// ([`PartialError::Mismatch`], naming the first difference).
    pub fn merge(&mut self, other: &Partial) -> Result<(), PartialError> {
        self.robot.compare(&other.robot)?;
        self.rows.compare(&other.rows)?;
        let mut acc = self.accumulator()?;
        acc.merge(&other.accumulator()?)
            .map_err(|e| PartialError::Invalid(e.to_string()))?;
        self.accumulator = acc.to_state().map_err(|e| PartialError::Invalid(e.to_string()))?;
        self.recordings.extend(other.recordings.iter().cloned());
        Ok(())
    }

    /// The accumulator the partial describes, checked.
    fn accumulator(&self) -> Result<Accumulator, PartialError> {
        let acc = Accumulator::from_state(&self.accumulator).map_err(|e| PartialError::Invalid(e.to_string()))?;
        let (n, p) = (self.robot.joints.len(), self.robot.parameters.len());
        if acc.n_params() != p || acc.channels() != &crate::Channels::Interleaved(n) {
            return Err(PartialError::Invalid(format!(
                "factors of {} parameters in {:?}, for a robot of {n} joints and {p} parameters",
                acc.n_params(),
                acc.channels()
            )));
        }
        Ok(acc)
    }

    /// The options the rows were made with, the estimator and the rest
    /// [`IdentifyOptions::default`].
    pub fn options(&self) -> Result<IdentifyOptions, PartialError> {
        let mut options = IdentifyOptions::default();
        self.rows.apply(&mut options)?;
        Ok(options)
    }

    /// `given` with the partial's row options wherever `given` leaves one at its
    /// default; a row option `given` sets to another value than the partial's is
    /// [`PartialError::Mismatch`] (`ours`: the partial's, `theirs`: `given`'s).
    pub fn options_with(&self, given: &IdentifyOptions) -> Result<IdentifyOptions, PartialError> {
        let default = IdentifyOptions::default();
        let theirs = RowOptions::of(given, &Recipe::default())?;
        let mut asked = self.rows.clone();
        if given.mode != default.mode {
            asked.mode = theirs.mode;
        }
        if given.joints != default.joints {
            (asked.friction, asked.epsilon) = (theirs.friction, theirs.epsilon);
        }
        if given.rotor_inertia != default.rotor_inertia {
            asked.rotor_inertia = theirs.rotor_inertia;
        }
        if given.extras != default.extras {
            asked.extras = theirs.extras;
        }
        if given.accumulation != default.accumulation {
            asked.accumulation = theirs.accumulation;
        }
        if given.exclude_below != default.exclude_below {
            asked.exclude_below = theirs.exclude_below;
        }
        if given.cutoff_hz != default.cutoff_hz {
            asked.cutoff_hz = theirs.cutoff_hz;
        }
        if given.low_pass_states != default.low_pass_states {
            asked.low_pass_states = theirs.low_pass_states;
        }
        self.rows.compare(&asked)?;
        let mut options = given.clone();
        self.rows.apply(&mut options)?;
        Ok(options)
    }

    /// Identifies `dynamics`'s parameters from the merged rows with the estimator,
    /// tolerances and truth of `given`, and the row options of the partial
    /// ([`Partial::options_with`]), as [`pipeline::identify`] does on one
    /// recording; the report's preprocessing lists the recordings.
    ///
    /// Errors: `dynamics` is not the robot the partial was made for, `given` sets a
    /// row option to another value than the partial's, and the estimator's failures.
    pub fn identify(&self, dynamics: &dyn Dynamics, given: &IdentifyOptions) -> Result<Identification, PartialError> {
        let options = self.options_with(given)?;
        options.check()?;
        let regressor = pipeline::torque_regressor(&options);
        let names = regressor.names(dynamics.model());
        self.robot.compare(&RobotIdentity::of(dynamics, &regressor, names))?;
        let acc = self.accumulator()?;
        let mut identified = pipeline::from_accumulator(dynamics.model(), &acc, &regressor, &options)?;
        if let Some(pre) = identified
            .report
            .prediction
            .as_mut()
            .and_then(|p| p.preprocessing.as_mut())
        {
            pre.recipe = Some(self.rows.recipe.clone());
            pre.recordings = self.recordings.clone();
        }
        Ok(identified)
    }

    /// The partial as JSON text (compact; every number written so that it reads
    /// back bit for bit).
    pub fn to_json(&self) -> Result<String, PartialError> {
        serde_json::to_string(self).map_err(PartialError::Json)
    }

    /// The partial in `text` ([`Partial::to_json`]), its schema and factors checked.
    pub fn from_json(text: &str) -> Result<Partial, PartialError> {
        let value: serde_json::Value = serde_json::from_str(text).map_err(PartialError::Json)?;
        match value.get("schema").and_then(|s| s.as_str()) {
            Some(PARTIAL_SCHEMA) => {}
            Some(other) => return Err(PartialError::Schema(Some(other.to_string()))),
            None => return Err(PartialError::Schema(None)),
        }
        let partial: Partial = serde_json::from_value(value).map_err(PartialError::Json)?;
        partial.options()?;
        partial.accumulator()?;
        if partial.robot.signature.len() != partial.robot.joints.len() * partial.robot.parameters.len() {
            return Err(PartialError::Invalid(format!(
                "a robot signature of {} numbers for {} joints and {} parameters",
                partial.robot.signature.len(),
                partial.robot.joints.len(),
                partial.robot.parameters.len()
            )));
        }
        Ok(partial)
    }
}

/// Merges `parts` in order (a left fold; any grouping gives the same result up to
/// rounding). `labels[i]` names part `i` in the error (a file name), which says
/// which two parts differ in what.
pub fn merge_all(parts: &[Partial], labels: &[String]) -> Result<Partial, String> {
    let label = |i: usize| labels.get(i).cloned().unwrap_or_else(|| format!("partial {}", i + 1));
    let (first, rest) = parts
        .split_first()
        .ok_or_else(|| "no partial factors to merge".to_string())?;
    let mut merged = first.clone();
    for (i, part) in rest.iter().enumerate() {
        merged.merge(part).map_err(|e| match e {
            PartialError::Mismatch { what, ours, theirs } => format!(
                "{} and {} were made for different {what}: {ours} against {theirs}; only partials of the same robot \
                 with the same row options (mode, friction, rotor inertia, extra terms, accumulation, exclude-below, cutoff, \
                 raw states, recipe) merge",
                label(0),
                label(i + 1)
            ),
            e => format!("{}: {e}", label(i + 1)),
        })?;
    }
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::{Estimator, Prediction};
    use dyngen_model::Model;
    use dyngen_reference::Reference;
    use rand::{Rng, SeedableRng};
    use rand_distr::Distribution;
    use std::path::Path;
    use std::sync::OnceLock;

    fn ur5() -> &'static Model {
        static MODEL: OnceLock<Model> = OnceLock::new();
        MODEL.get_or_init(|| {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../robots/ur5/ur5.urdf");
            dyngen_model::load_urdf(&path).expect("the UR5 URDF loads")
        })
    }

    /// The UR5 along sums of sines (100 Hz, 20 s; seeded amplitudes, frequencies
    /// and phases), its torques those of the URDF's parameters plus seeded noise
    /// (σ = 0.05 N·m), so that WLS's weights and the residuals are those of real data.
    fn recording() -> &'static Trajectory {
        static TRAJ: OnceLock<Trajectory> = OnceLock::new();
        TRAJ.get_or_init(|| {
            let model = ur5();
            let robot = Reference::new(model);
            let (n, len) = (model.dof(), 2000);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(25);
            let uniform = |rng: &mut rand_chacha::ChaCha8Rng, lo: f64, hi: f64| lo + (hi - lo) * rng.gen::<f64>();
            let waves: Vec<[f64; 3]> = (0..3 * n)
                .map(|_| {
                    let amplitude = uniform(&mut rng, 0.3, 0.8);
                    let omega = uniform(&mut rng, 0.1, 0.6) * std::f64::consts::TAU;
                    [amplitude, omega, uniform(&mut rng, 0.0, std::f64::consts::TAU)]
                })
                .collect();
            let noise = rand_distr::Normal::new(0.0, 0.05).unwrap();
            let params = model.standard_params();
            let (mut t, mut q, mut v, mut a, mut tau) = (vec![], vec![], vec![], vec![], vec![]);
            for k in 0..len {
                let time = 0.01 * k as f64;
                t.push(time);
                let at = k * n;
                for j in 0..n {
                    let (mut qj, mut vj, mut aj) = (0.0, 0.0, 0.0);
                    for [amplitude, omega, phase] in &waves[3 * j..3 * j + 3] {
                        let (s, c) = (omega * time + phase).sin_cos();
                        (qj, vj, aj) = (
                            qj + amplitude * s,
                            vj + amplitude * omega * c,
                            aj - amplitude * omega * omega * s,
                        );
                    }
                    q.push(qj);
                    v.push(vj);
                    a.push(aj);
                }
                let mut torque = vec![0.0; n];
                Dynamics::rnea(
                    &robot,
                    &q[at..at + n],
                    &v[at..at + n],
                    &a[at..at + n],
                    &params,
                    &mut torque,
                );
                tau.extend(torque.iter().map(|x| x + noise.sample(&mut rng)));
            }
            Trajectory::new(n, t, q, tau)
                .and_then(|t| t.with_velocities(v))
                .and_then(|t| t.with_accelerations(a))
                .unwrap()
        })
    }

    /// Samples `range` of `traj`.
    fn piece(traj: &Trajectory, range: std::ops::Range<usize>) -> Trajectory {
        let n = traj.dof();
        let cut = |x: &[f64]| x[n * range.start..n * range.end].to_vec();
        Trajectory::new(
            n,
            traj.t()[range.clone()].to_vec(),
            cut(traj.positions()),
            cut(traj.torques()),
        )
        .and_then(|t| t.with_velocities(cut(traj.velocities().unwrap())))
        .and_then(|t| t.with_accelerations(cut(traj.accelerations().unwrap())))
        .unwrap()
    }

    fn partial_of(robot: &Reference, traj: &Trajectory, options: &IdentifyOptions, name: &str) -> Partial {
        let span = DataSpan::of(Path::new(name), traj);
        Partial::from_trajectory(robot, traj, options, &Recipe::default(), span).unwrap()
    }

    /// `traj` cut into `k` pieces of unequal lengths, each a partial.
    fn pieces(robot: &Reference, traj: &Trajectory, k: usize, options: &IdentifyOptions) -> Vec<Partial> {
        let len = traj.len();
        let mut bounds: Vec<usize> = (0..k).map(|i| len * i * i / (k * k)).collect();
        bounds.push(len);
        bounds
            .windows(2)
            .enumerate()
            .map(|(i, b)| partial_of(robot, &piece(traj, b[0]..b[1]), options, &format!("piece{i}.csv")))
            .collect()
    }

    /// The largest difference between two identifications' estimates (the
    /// solution, every reported parameter value and identifiable combination),
    /// relative to the largest entry of `b`'s solution; the same parameters must
    /// have values.
    fn max_difference(a: &Identification, b: &Identification) -> f64 {
        let solution = |i: &Identification| match &i.prediction {
            Prediction::Regressor(t) => t.estimate.solution.clone(),
            Prediction::Parameters(_) => panic!("no regressor estimate"),
        };
        let values = |i: &Identification| i.report.parameters.iter().map(|p| p.value).collect::<Vec<_>>();
        let combinations = |i: &Identification| i.report.combinations.iter().map(|c| c.value).collect::<Vec<_>>();
        let (va, vb) = (values(a), values(b));
        assert_eq!(
            va.iter().map(Option::is_some).collect::<Vec<_>>(),
            vb.iter().map(Option::is_some).collect::<Vec<_>>()
        );
        let (ca, cb) = (combinations(a), combinations(b));
        assert_eq!(ca.len(), cb.len());
        let (sa, sb) = (solution(a), solution(b));
        let scale = sb.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let pairs = sa.iter().zip(&sb).chain(ca.iter().zip(&cb));
        let values = va.iter().zip(&vb).filter_map(|(x, y)| Some((x.as_ref()?, y.as_ref()?)));
        pairs.chain(values).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
    }

    #[test]
    fn merged_pieces_identify_as_the_whole_recording() {
        let robot = Reference::new(ur5());
        let traj = recording();
        let mut worst = 0.0_f64;
        for (estimator, accumulation, joints) in [
            (Estimator::Ols, Accumulation::Qr, JointTerms::None),
            (Estimator::Wls, Accumulation::Qr, JointTerms::None),
            (Estimator::Wls, Accumulation::Qr, JointTerms::Friction(Coulomb::Sign)),
            (Estimator::Ols, Accumulation::NormalEquations, JointTerms::None),
            (Estimator::Ridge { lambda: 1e-4 }, Accumulation::Qr, JointTerms::None),
        ] {
            let options = IdentifyOptions {
                estimator,
                accumulation,
                joints,
                ..IdentifyOptions::default()
            };
            let whole = pipeline::identify(&robot, traj, &options).unwrap();
            for k in [1, 3, 7] {
                let parts = pieces(&robot, traj, k, &options);
                let merged = merge_all(&parts, &[]).unwrap();
                assert_eq!(merged.recordings.len(), k);
                let identified = merged.identify(&robot, &options).unwrap();
                let diff = max_difference(&identified, &whole);
                assert!(
                    diff <= 1e-12,
                    "{estimator:?} {accumulation:?} {joints:?}, {k} pieces: {diff:e}"
                );
                worst = worst.max(diff);
                let rms = |i: &Identification| i.report.residual_rms.clone();
                for (a, b) in rms(&identified).iter().zip(&rms(&whole)) {
                    assert!((a - b).abs() <= 1e-10 * b, "residual {a} against {b}");
                }
            }
        }
        println!("merged against one pass: largest relative difference {worst:e}");
    }

    #[test]
    fn a_reduce_tree_and_a_saved_partial_give_the_same_estimate() {
        let robot = Reference::new(ur5());
        let options = IdentifyOptions {
            estimator: Estimator::Wls,
            ..IdentifyOptions::default()
        };
        let parts = pieces(&robot, recording(), 4, &options);
        let left = merge_all(&parts, &[]).unwrap();
        let mut tree = merge_all(&parts[..2], &[]).unwrap();
        tree.merge(&merge_all(&parts[2..], &[]).unwrap()).unwrap();
        let text = tree.to_json().unwrap();
        let read = Partial::from_json(&text).unwrap();
        // Every number reads back bit for bit.
        assert_eq!(read, tree);
        let a = left.identify(&robot, &options).unwrap();
        let b = read.identify(&robot, &options).unwrap();
        assert!(max_difference(&a, &b) <= 1e-12);
        let pre = b.report.prediction.unwrap().preprocessing.unwrap();
        let files: Vec<&str> = pre.recordings.iter().map(|r| r.file.as_str()).collect();
        assert_eq!(files, ["piece0.csv", "piece1.csv", "piece2.csv", "piece3.csv"]);
    }

    #[test]
    fn options_that_need_the_rows_are_refused() {
        let robot = Reference::new(ur5());
        let traj = piece(recording(), 0..50);
        for (options, needle) in [
            (
                IdentifyOptions {
                    joints: JointTerms::FrictionAuto,
                    ..IdentifyOptions::default()
                },
                "friction auto cannot be written as a partial factor",
            ),
            (
                IdentifyOptions {
                    joints: JointTerms::Stribeck(Coulomb::Sign),
                    ..IdentifyOptions::default()
                },
                "friction stribeck and stribeck-smooth cannot be written as partial factors",
            ),
            (
                IdentifyOptions {
                    mode: Mode::Mim,
                    ..IdentifyOptions::default()
                },
                "mode mim cannot be written as a partial factor",
            ),
        ] {
            let span = DataSpan::of(Path::new("x.csv"), &traj);
            let err = Partial::from_trajectory(&robot, &traj, &options, &Recipe::default(), span).unwrap_err();
            assert!(err.to_string().contains(needle), "{err}");
            assert!(check_options(&options).is_err());
        }
    }

    #[test]
    fn partials_of_other_robots_or_rows_are_refused_naming_both() {
        let model = ur5();
        let robot = Reference::new(model);
        let traj = piece(recording(), 0..60);
        let options = IdentifyOptions::default();
        let ours = partial_of(&robot, &traj, &options, "a.csv");
        let labels = ["a.part".to_string(), "b.part".to_string()];
        // Another cutoff.
        let other_cutoff = partial_of(
            &robot,
            &traj,
            &IdentifyOptions {
                cutoff_hz: 5.0,
                ..options.clone()
            },
            "b.csv",
        );
        let err = merge_all(&[ours.clone(), other_cutoff], &labels).unwrap_err();
        assert!(
            err.contains("a.part and b.part were made for different cutoff: 10 Hz against 5 Hz"),
            "{err}"
        );
        // Another friction model: other parameters.
        let sign = partial_of(
            &robot,
            &traj,
            &IdentifyOptions {
                joints: JointTerms::Friction(Coulomb::Sign),
                ..options.clone()
            },
            "b.csv",
        );
        let err = merge_all(&[ours.clone(), sign], &labels).unwrap_err();
        assert!(err.contains("different parameters: 60 parameters"), "{err}");
        // The same names with another kinematics: a joint origin moved.
        let mut moved = model.clone();
        moved.joints[2].origin.translation[0] += 0.01;
        let moved_robot = Reference::new(&moved);
        let err = merge_all(
            &[ours.clone(), partial_of(&moved_robot, &traj, &options, "b.csv")],
            &labels,
        )
        .unwrap_err();
        assert!(err.contains("different kinematics"), "{err}");
        // Solving with another robot.
        let err = ours.identify(&moved_robot, &options).unwrap_err();
        assert!(
            matches!(err, PartialError::Mismatch { what: "kinematics", .. }),
            "{err}"
        );
        // A row option given that is not the partial's.
        let err = ours
            .options_with(&IdentifyOptions {
                low_pass_states: false,
                ..options.clone()
            })
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "different raw-states: states low-passed against raw states"
        );
        // A robot with other joints.
        let pendulum = dyngen_model::parse_urdf(
            r#"<robot name="p"><link name="b"/><link name="l"><inertial><mass value="1"/>
            <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
            <joint name="j" type="continuous"><parent link="b"/><child link="l"/><axis xyz="0 0 1"/></joint></robot>"#,
        )
        .unwrap();
        let one = Reference::new(&pendulum);
        let err = ours.identify(&one, &options).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("different robots: robot `ur5` with joints ["),
            "{err}"
        );
    }

    #[test]
    fn corrupt_or_other_version_files_are_refused() {
        let robot = Reference::new(ur5());
        let good = partial_of(&robot, &piece(recording(), 0..40), &IdentifyOptions::default(), "a.csv");
        let text = good.to_json().unwrap();
        let err = Partial::from_json(&text[..text.len() / 2]).unwrap_err();
        assert!(err.to_string().starts_with("not a partial factor file ("), "{err}");
        let err = Partial::from_json(&text.replace(PARTIAL_SCHEMA, "dyngen-partial/2")).unwrap_err();
        assert!(
            err.to_string()
                .contains("a `dyngen-partial/2` file; this dyngen reads partial factors of schema `dyngen-partial/1`"),
            "{err}"
        );
        let err = Partial::from_json(r#"{"robot": 1}"#).unwrap_err();
        assert!(err.to_string().contains("no `schema` field"), "{err}");
        // A factor row cut short.
        let mut short = good.clone();
        short.accumulator.per_channel[1].factor[0].pop();
        let err = Partial::from_json(&short.to_json().unwrap()).unwrap_err();
        assert!(err.to_string().contains("channel 1: factor row 0 has"), "{err}");
        // Rows that are not whole samples.
        let mut uneven = good;
        uneven.accumulator.per_channel[0].rows += 1;
        let err = Partial::from_json(&uneven.to_json().unwrap()).unwrap_err();
        assert!(err.to_string().contains("are not whole samples of 6 rows"), "{err}");
    }
}
