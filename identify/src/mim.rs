//! MIM, the Model Identification Method of the source paper (Advances in Mechanical Engineering, 2025, doi:10.1177/16878132251321050;
//! docs/design.md, "The paper's decoupled body model"): identification of the principal
//! parameters `θ_i = (m, J1, J2, J3)` on the decoupled multibody model, and of the
//! identifiable combinations from joint torques alone.
//!
//! On a [`Recording`]:
//!
//! * [`instant`]: every body from its resultant at **one** instant (the paper uses
//!   `t = 1.5 s`), `A_i θ_i = [F_i; M_i]`, 6 equations for 4 unknowns;
//! * [`samples`]: every body by least squares over a range of samples;
//! * [`whole_robot`]: the whole robot as one block-diagonal problem (the paper's
//!   eq. 19–20);
//! * [`torque`] with [`TorqueRegressor::Principal`], and [`torque_principal_base`]:
//!   from joint torques alone, `τ = Y_θ θ` (or the generated principal base
//!   regressor), saying which `θ` are identifiable alone and which only in
//!   combinations;
//! * [`torque`] with [`TorqueRegressor::Standard`] (or `StandardAndJoints`, with
//!   friction and rotor inertia): the standard parameters from joint torques, i.e.
//!   the base parameters, with rank handling.
//!
//! Rank is explicit (every solve goes through the estimators of this crate): a parameter the
//! data do not determine — e.g. the `J1`, `J2` of a turret that only turns about its
//! `z` axis, which never enter `B(ω, ω̇)` — is reported as not identifiable, never as
//! a number. On noisy data a column that carries only noise (the turret's `J1` column
//! is then `ω̇1` noise) is numerically full rank; such parameters are reported as
//! "not significant" when `|x̂| < k σ̂` ([`MimOptions::significance`], default 3)
//! instead of printing the number noise made up.
//!
//! ```
//! use dyngen_identify::mim::{self, MimOptions};
//! use dyngen_identify::simulate::{record, Experiment};
//! let urdf = r#"<robot name="pendulum">
//!   <link name="base"/>
//!   <link name="arm"><inertial><mass value="1"/><origin xyz="0 0 -0.5"/>
//!     <inertia ixx="0.1" iyy="0.12" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
//!   <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
//!     <axis xyz="0 1 0"/></joint>
//! </robot>"#;
//! let model = dyngen_model::parse_urdf(urdf).unwrap();
//! let robot = dyngen_reference::Reference::new(&model);
//! let recording = record(&robot, &model.standard_params(), &Experiment::paper(&model));
//! let truth = dyngen_model::principal_params(&model);
//! let est = mim::instant(&recording, 1.5, Some(&truth), &MimOptions::default()).unwrap();
//! assert!((est.value(0, 0).unwrap() - 1.0).abs() < 1e-9); // the mass
//! assert!((est.value(0, 2).unwrap() - 0.12).abs() < 1e-9); // J2, about the hinge
//! assert_eq!(est.value(0, 1), None); // J1 never enters: a hinge about y only
//! println!("{est}");
//! ```

use crate::extras::ExtraTerms;
use crate::faer::Mat;
use crate::simulate::Recording;
use crate::{Accumulator, Channels, Estimate, IdentifyError, Options, ParamEstimate, Status};
use dyngen::Robot;
use dyngen_model::joint_params::{joint_regressor_row, Coulomb, PER_JOINT};
use dyngen_model::names::{principal_param_names, standard_param_names};
use dyngen_model::Model;
use dyngen_reference::Dynamics;
use nalgebra::DMatrix;
use std::fmt;
use std::ops::Range;
use std::sync::Arc;

/// Names of the four principal parameters of a body.
pub use dyngen_model::names::PRINCIPAL as THETA_NAMES;

/// Settings of the MIM solvers.
#[derive(Clone, Debug, PartialEq)]
pub struct MimOptions {
    /// Rank tolerance and identifiability tolerance of the least-squares solves.
    pub identify: Options,
    /// A parameter the data determine but whose estimate is below `significance · σ̂`
    /// in magnitude is reported as [`Verdict::NotSignificant`], without a value.
    /// `0` turns the test off. Default 3.
    pub significance: f64,
}

impl Default for MimOptions {
    fn default() -> Self {
        MimOptions {
            identify: Options::default(),
            significance: 3.0,
        }
    }
}

/// What MIM says about one principal parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Determined by the data; has a value.
    Identified,
    /// Only identifiable in combination with others (joint torques).
    InCombination,
    /// Does not enter the equations at all (e.g. a turret's `J1`, `J2`).
    NoEffect,
    /// Numerically determined, but `|x̂| < k σ̂`: the data carry no information on
    /// it beyond noise.
    NotSignificant,
}

impl Verdict {
    pub fn short(self) -> &'static str {
        match self {
            Verdict::Identified => "",
            Verdict::InCombination => "comb.",
            Verdict::NoEffect => "n/i",
            Verdict::NotSignificant => "n/s",
        }
    }
}

/// How the MIM equations were set up.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// One instant: sample `index` at time `t`.
    Instant { index: usize, t: f64 },
    /// Every body separately over the samples `range`.
    Samples { range: Range<usize> },
    /// The whole robot as one block-diagonal problem over `range` (eq. 19–20).
    WholeRobot { range: Range<usize> },
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Source::Instant { index, t } => write!(f, "single instant t = {t:.3} s (sample {index})"),
            Source::Samples { range } => write!(
                f,
                "least squares per body over {} samples ({}..{})",
                range.len(),
                range.start,
                range.end
            ),
            Source::WholeRobot { range } => write!(
                f,
                "whole robot, block-diagonal least squares over {} samples ({}..{})",
                range.len(),
                range.start,
                range.end
            ),
        }
    }
}

/// A parameter's estimate against the truth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamError {
    pub body: usize,
    /// 0 = m, 1..=3 = J1..J3.
    pub index: usize,
    pub truth: f64,
    /// `None` unless [`Verdict::Identified`].
    pub estimate: Option<f64>,
    pub verdict: Verdict,
    /// `|x̂ − x|`.
    pub absolute: Option<f64>,
    /// `|x̂ − x| / |x|`.
    pub relative: Option<f64>,
}

/// MIM on the body equations: one [`Estimate`] per body (4 parameters each) or one
/// for the whole robot (`4n`), plus the truth comparison when the truth is known.
#[derive(Clone, Debug)]
pub struct MimEstimate {
    pub source: Source,
    pub body_names: Vec<String>,
    /// Per body (`n` estimates of 4 parameters) or, for [`Source::WholeRobot`], one
    /// estimate of `4n` parameters.
    pub estimates: Vec<Estimate>,
    /// The true `θ` (`4n`), when known.
    pub truth: Option<Vec<f64>>,
    pub significance: f64,
}

impl MimEstimate {
    fn locate(&self, body: usize, k: usize) -> (&Estimate, usize) {
        match self.source {
            Source::WholeRobot { .. } => (&self.estimates[0], 4 * body + k),
            _ => (&self.estimates[body], k),
        }
    }

    /// Number of bodies.
    pub fn bodies(&self) -> usize {
        self.body_names.len()
    }

    /// The raw least-squares report of parameter `k` (0 = m, 1..=3 = J1..J3) of
    /// `body` (0-based).
    pub fn param(&self, body: usize, k: usize) -> &ParamEstimate {
        let (e, j) = self.locate(body, k);
        &e.params[j]
    }

    /// What MIM says about parameter `k` of `body`.
    pub fn verdict(&self, body: usize, k: usize) -> Verdict {
        let p = self.param(body, k);
        match p.status {
            Status::InCombination => Verdict::InCombination,
            Status::NoEffect => Verdict::NoEffect,
            _ => match (p.value, p.sigma) {
                (Some(v), Some(s)) if v.abs() < self.significance * s => Verdict::NotSignificant,
                (Some(_), _) => Verdict::Identified,
                (None, _) => Verdict::NoEffect,
            },
        }
    }

    /// The identified value of parameter `k` of `body`; `None` unless
    /// [`Verdict::Identified`].
    pub fn value(&self, body: usize, k: usize) -> Option<f64> {
        (self.verdict(body, k) == Verdict::Identified)
            .then(|| self.param(body, k).value)
            .flatten()
    }

    /// Its standard deviation, when identified.
    pub fn sigma(&self, body: usize, k: usize) -> Option<f64> {
        (self.verdict(body, k) == Verdict::Identified)
            .then(|| self.param(body, k).sigma)
            .flatten()
    }

    /// All `4n` values, body 1 first (`None` = not identified).
    pub fn theta(&self) -> Vec<Option<f64>> {
        (0..self.bodies())
            .flat_map(|i| (0..4).map(move |k| (i, k)))
            .map(|(i, k)| self.value(i, k))
            .collect()
    }

    /// Every parameter against the truth; `None` when the truth is unknown.
    pub fn errors(&self) -> Option<Vec<ParamError>> {
        let truth = self.truth.as_ref()?;
        Some(
            (0..self.bodies())
                .flat_map(|i| (0..4).map(move |k| (i, k)))
                .map(|(body, index)| {
                    let t = truth[4 * body + index];
                    let estimate = self.value(body, index);
                    let absolute = estimate.map(|e| (e - t).abs());
                    ParamError {
                        body,
                        index,
                        truth: t,
                        estimate,
                        verdict: self.verdict(body, index),
                        absolute,
                        relative: estimate.map(|e| crate::relative_error(e, t)),
                    }
                })
                .collect(),
        )
    }

    /// The largest relative error over the identified parameters (`None` without
    /// truth or without any identified parameter).
    pub fn max_relative_error(&self) -> Option<f64> {
        self.errors()?.iter().filter_map(|e| e.relative).reduce(f64::max)
    }
}

impl fmt::Display for MimEstimate {
    /// The paper's Tables 2–3: identified parameters per body, then absolute (and
    /// relative) errors when the truth is known.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "MIM, {}", self.source)?;
        let cells: Vec<Result<f64, &str>> = (0..self.bodies())
            .flat_map(|i| (0..4).map(move |k| (i, k)))
            .map(|(i, k)| self.value(i, k).ok_or(self.verdict(i, k).short()))
            .collect();
        let table = ThetaTable {
            body_names: &self.body_names,
            cells: &cells,
            truth: self.truth.as_deref(),
            tables: [2, 3],
        };
        write!(f, "{table}")?;
        if cells.iter().any(Result::is_err) {
            writeln!(
                f,
                "n/i: not identifiable (does not enter the equations); n/s: not significant (|x̂| < {}σ̂); \
                 comb.: only in combination",
                self.significance
            )?;
        }
        Ok(())
    }
}

/// θ per body in the layout of the paper's tables: the values (or why there is
/// none), then, with the truth, the absolute errors and the largest relative one.
/// `tables` are the paper's table numbers to cite (2–3 for MIM, 4–5 for NIM).
pub struct ThetaTable<'a> {
    pub body_names: &'a [String],
    /// `4n` cells, body 1 first: a value or a short note (`n/i`, …).
    pub cells: &'a [Result<f64, &'a str>],
    pub truth: Option<&'a [f64]>,
    pub tables: [u32; 2],
}

impl fmt::Display for ThetaTable<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let width = self
            .body_names
            .iter()
            .map(|s| s.chars().count())
            .max()
            .unwrap_or(4)
            .max(6);
        let [values, errors] = self.tables;
        writeln!(f, "identified parameters (cf. the paper's Table {values})")?;
        writeln!(
            f,
            "{:<width$}  {:>13}  {:>13}  {:>13}  {:>13}",
            "body", "m (kg)", "J1 (kg·m²)", "J2 (kg·m²)", "J3 (kg·m²)"
        )?;
        for (i, name) in self.body_names.iter().enumerate() {
            write!(f, "{name:<width$}")?;
            for cell in &self.cells[4 * i..4 * i + 4] {
                let cell = match cell {
                    Ok(v) => format!("{v:.6}"),
                    Err(note) => note.to_string(),
                };
                write!(f, "  {cell:>13}")?;
            }
            writeln!(f)?;
        }
        let Some(truth) = self.truth else {
            return Ok(());
        };
        writeln!(f, "absolute errors (cf. the paper's Table {errors})")?;
        writeln!(
            f,
            "{:<width$}  {:>13}  {:>13}  {:>13}  {:>13}",
            "body", "Δm (kg)", "ΔJ1 (kg·m²)", "ΔJ2 (kg·m²)", "ΔJ3 (kg·m²)"
        )?;
        let mut worst: Option<(f64, usize)> = None;
        for (i, name) in self.body_names.iter().enumerate() {
            write!(f, "{name:<width$}")?;
            for j in 4 * i..4 * i + 4 {
                let cell = match self.cells[j] {
                    Ok(v) => {
                        let absolute = (v - truth[j]).abs();
                        let relative = crate::relative_error(v, truth[j]);
                        if worst.is_none_or(|(w, _)| relative > w) {
                            worst = Some((relative, j));
                        }
                        format!("{absolute:.3e}")
                    }
                    Err(note) => note.to_string(),
                };
                write!(f, "  {cell:>13}")?;
            }
            writeln!(f)?;
        }
        if let Some((w, j)) = worst {
            writeln!(
                f,
                "largest relative error {w:.3e} ({} of {})",
                THETA_NAMES[j % 4],
                self.body_names[j / 4]
            )?;
        }
        Ok(())
    }
}

fn to_faer(a: &DMatrix<f64>) -> Mat<f64> {
    Mat::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)])
}

/// Fewer samples than this are solved by ordinary least squares (too few rows per
/// channel to estimate per-channel noise levels).
pub const MIN_SAMPLES_FOR_WEIGHTING: usize = 10;

/// Least squares on body equations stacked as [`Recording::body_system`] or
/// [`Recording::robot_body_system`] (`bodies` bodies per sample, six rows
/// `[force; moment]` each). With at least [`MIN_SAMPLES_FOR_WEIGHTING`] samples,
/// every body's six axes are separate channels of Gautier's weighted least squares:
/// an axis whose signal is small (the moment about a cylinder's own axis) has a
/// small noise too, and equal weights would let the other, noisier axes, in which
/// the same `J` appears through the gyroscopic terms, dominate its estimate; and a
/// pooled σ would be set by the force rows (newtons) and overstate every moment's
/// σ by orders of magnitude. Fewer samples: ordinary least squares.
fn solve(a: &DMatrix<f64>, y: &[f64], bodies: usize, opts: &MimOptions) -> Result<Estimate, IdentifyError> {
    let samples = a.nrows() / (6 * bodies);
    if samples < MIN_SAMPLES_FOR_WEIGHTING {
        return Accumulator::from_rows(to_faer(a).as_ref(), y, Channels::Single)?.ols(&opts.identify);
    }
    Accumulator::from_rows(to_faer(a).as_ref(), y, Channels::Interleaved(6 * bodies))?.wls(&opts.identify)
}

fn check_truth(truth: Option<&[f64]>, expected: usize) -> Result<(), IdentifyError> {
    match truth {
        Some(t) if t.len() != expected => Err(IdentifyError::DimensionMismatch {
            what: "true parameters",
            expected,
            found: t.len(),
        }),
        _ => Ok(()),
    }
}

fn check_range(recording: &Recording, range: &Range<usize>) -> Result<(), IdentifyError> {
    if range.is_empty() {
        return Err(IdentifyError::Empty);
    }
    if range.end > recording.len() {
        return Err(IdentifyError::InvalidArgument {
            what: "range",
            reason: format!(
                "ends at {} but the recording has {} samples",
                range.end,
                recording.len()
            ),
        });
    }
    Ok(())
}

fn per_body(
    recording: &Recording,
    range: Range<usize>,
    source: Source,
    truth: Option<&[f64]>,
    opts: &MimOptions,
) -> Result<MimEstimate, IdentifyError> {
    check_range(recording, &range)?;
    check_truth(truth, 4 * recording.nv())?;
    let estimates = (0..recording.nv())
        .map(|i| {
            let (a, y) = recording.body_system(i, range.clone());
            solve(&a, y.as_slice(), 1, opts)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(MimEstimate {
        source,
        body_names: recording.body_names.clone(),
        estimates,
        truth: truth.map(<[f64]>::to_vec),
        significance: opts.significance,
    })
}

/// Every body from its resultant at the one sample nearest to `t` (the paper:
/// `t = 1.5 s`): `A_i θ_i = [F_i; M_i]`, 6 × 4 per body, solved with rank
/// handling. `truth`: `θ` (`4n`) for the error table, e.g. [`dyngen_model::principal_params`].
pub fn instant(
    recording: &Recording,
    t: f64,
    truth: Option<&[f64]>,
    opts: &MimOptions,
) -> Result<MimEstimate, IdentifyError> {
    let index = recording.nearest(t).ok_or(IdentifyError::Empty)?;
    let source = Source::Instant {
        index,
        t: recording.samples[index].t,
    };
    per_body(recording, index..index + 1, source, truth, opts)
}

/// Every body by least squares over the samples `range` (`0..recording.len()` for
/// all).
pub fn samples(
    recording: &Recording,
    range: Range<usize>,
    truth: Option<&[f64]>,
    opts: &MimOptions,
) -> Result<MimEstimate, IdentifyError> {
    let source = Source::Samples { range: range.clone() };
    per_body(recording, range, source, truth, opts)
}

/// The whole robot as one block-diagonal least-squares problem over `range`
/// (the paper's eq. 19–20; the rows of [`Recording::robot_body_system`], streamed
/// so memory does not grow with the samples). Same estimates as [`samples`] since
/// the blocks decouple, but one report with one rank.
pub fn whole_robot(
    recording: &Recording,
    range: Range<usize>,
    truth: Option<&[f64]>,
    opts: &MimOptions,
) -> Result<MimEstimate, IdentifyError> {
    check_range(recording, &range)?;
    let n = recording.nv();
    check_truth(truth, 4 * n)?;
    // The rows of `Recording::robot_body_system`, streamed into the accumulator
    // (memory O(n²) whatever the number of samples), weighted as `solve` does.
    let weighted = range.len() >= MIN_SAMPLES_FOR_WEIGHTING;
    let channels = if weighted {
        Channels::Interleaved(6 * n)
    } else {
        Channels::Single
    };
    let mut acc = Accumulator::with_channels(4 * n, channels)?;
    let mut row = vec![0.0; 4 * n];
    for k in range.clone() {
        for i in 0..n {
            let block = recording.body_regressor(k, i);
            let wrench = recording.body_wrench(k, i);
            for r in 0..6 {
                row.fill(0.0);
                row[4 * i..4 * i + 4].copy_from_slice(&block.row(r));
                acc.push_row(&row, wrench[r])?;
            }
        }
    }
    let estimate = if weighted {
        acc.wls(&opts.identify)?
    } else {
        acc.ols(&opts.identify)?
    };
    Ok(MimEstimate {
        source: Source::WholeRobot { range },
        body_names: recording.body_names.clone(),
        estimates: vec![estimate],
        truth: truth.map(<[f64]>::to_vec),
        significance: opts.significance,
    })
}

/// A regressor `(q, v, a, y)` with `y` row-major, such as
/// [`dyngen::Regressors::principal_base_regressor`] for `f64`.
pub type RegressorFn = fn(&[f64], &[f64], &[f64], &mut [f64]);

/// What the joints add to the rigid bodies' torques in
/// [`TorqueRegressor::StandardAndJoints`]: the Coulomb model (with, for the
/// smoothing, one `ε` per joint where `epsilons` gives them), and the extra terms.
#[derive(Clone, Debug, PartialEq)]
pub struct JointModel {
    pub coulomb: Coulomb,
    /// `ε` of `tanh(q̇_j/ε_j)` per joint, in place of the Coulomb model's (one
    /// per velocity coordinate).
    pub epsilons: Option<Arc<[f64]>>,
    pub extras: ExtraTerms,
    /// The gear ratio `N_j` of each joint (motor angle `N_j q_j`), for the motor
    /// ripple of the extra terms.
    pub gear_ratios: Option<Arc<[f64]>>,
}

impl JointModel {
    /// The same Coulomb model on every joint.
    pub fn new(coulomb: Coulomb, extras: ExtraTerms) -> Self {
        JointModel {
            coulomb,
            epsilons: None,
            extras,
            gear_ratios: None,
        }
    }

    /// The same with the joints' gear ratios (one per joint).
    pub fn with_gear_ratios(mut self, ratios: Option<&[f64]>) -> Self {
        self.gear_ratios = ratios.map(Into::into);
        self
    }

    /// Joint `j`'s motor angle at joint angle `q` (0 without gear ratios).
    pub fn motor_angle(&self, j: usize, q: f64) -> f64 {
        self.gear_ratios.as_ref().map_or(0.0, |n| n[j] * q)
    }

    /// `Fc·tanh(q̇_j/ε_j)` with `epsilons[j]` on joint `j`.
    pub fn per_joint(epsilons: &[f64], extras: ExtraTerms) -> Self {
        JointModel {
            coulomb: Coulomb::Smooth {
                epsilon: epsilons.first().copied().unwrap_or(1.0),
            },
            epsilons: Some(epsilons.into()),
            extras,
            gear_ratios: None,
        }
    }

    /// Joint `j`'s Coulomb model.
    pub fn coulomb(&self, j: usize) -> Coulomb {
        match &self.epsilons {
            Some(e) => Coulomb::Smooth { epsilon: e[j] },
            None => self.coulomb,
        }
    }
}

impl From<Coulomb> for JointModel {
    fn from(coulomb: Coulomb) -> Self {
        JointModel::new(coulomb, ExtraTerms::NONE)
    }
}

/// The regressor a [`TorqueEstimate`] was computed with.
#[derive(Clone)]
pub enum TorqueRegressor {
    /// `Y` (`n × 10n`), standard parameters.
    Standard,
    /// `Y_θ = Y · blkdiag(P_i)` (`n × 4n`), principal parameters.
    Principal,
    /// A generated robot's principal base regressor (`n × NBASE_PRINCIPAL`).
    PrincipalBase { columns: usize, regressor: RegressorFn },
    /// `[Y | J | E]` (`n × (14 + e)n`): the standard parameters, then per joint rotor
    /// inertia, viscous and Coulomb friction and an offset `[Ia, Fv, Fc, F0]`
    /// ([`dyngen_model::joint_params`]): the model of a real robot's joint torques;
    /// then per joint the `e` columns of the extra terms ([`crate::extras`]), none
    /// with [`ExtraTerms::NONE`].
    StandardAndJoints(JointModel),
}

impl fmt::Debug for TorqueRegressor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TorqueRegressor::Standard => write!(f, "Standard"),
            TorqueRegressor::Principal => write!(f, "Principal"),
            TorqueRegressor::PrincipalBase { columns, .. } => write!(f, "PrincipalBase({columns})"),
            TorqueRegressor::StandardAndJoints(m) => {
                match &m.epsilons {
                    Some(e) => write!(f, "StandardAndJoints(tanh, ε {e:?}")?,
                    None => write!(f, "StandardAndJoints({:?}", m.coulomb)?,
                }
                if !m.extras.is_empty() {
                    write!(f, ", {}", m.extras)?;
                }
                write!(f, ")")
            }
        }
    }
}

impl TorqueRegressor {
    /// Number of columns for `model`: 10 (standard) or 4 (principal) per body, and
    /// with the joint terms 4 per velocity coordinate and the extra terms' (a joint
    /// that follows another, `<mimic>`, has none: its rotor and friction act on its
    /// leader's).
    pub fn columns(&self, model: &Model) -> usize {
        let (bodies, nv) = (model.dof(), model.nv());
        match self {
            TorqueRegressor::Standard => 10 * bodies,
            TorqueRegressor::Principal => 4 * bodies,
            TorqueRegressor::PrincipalBase { columns, .. } => *columns,
            TorqueRegressor::StandardAndJoints(m) => 10 * bodies + (PER_JOINT + m.extras.per_joint()) * nv,
        }
    }

    /// The names of the parameters, `columns(model)` of them ([`dyngen_model::names`],
    /// [`dyngen_model::joint_params`]; `β1, β2, …` for a generated base regressor).
    pub fn names(&self, model: &Model) -> Vec<String> {
        let (bodies, nv) = (model.dof(), model.nv());
        match self {
            TorqueRegressor::Standard => standard_param_names(bodies),
            TorqueRegressor::Principal => principal_param_names(bodies),
            TorqueRegressor::PrincipalBase { columns, .. } => (1..=*columns).map(|k| format!("β{k}")).collect(),
            TorqueRegressor::StandardAndJoints(m) => {
                let e = m.extras;
                let mut names = standard_param_names(bodies);
                names.extend(dyngen_model::joint_params::joint_param_names(nv));
                names.extend(e.names(nv));
                names
            }
        }
    }

    /// The joint torques `Y(q, v, a) x` of the parameters `x` (`columns(n)`), with
    /// `y` (`n × columns`) as room for the regressor; the load-dependent friction's
    /// load is the rigid-body torque of `x`'s own parameters.
    pub fn predict(
        &self,
        dynamics: &dyn Dynamics,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        x: &[f64],
        y: &mut [f64],
    ) -> Vec<f64> {
        let p = x.len();
        self.eval(dynamics, q, v, a, y);
        self.fill_load(dynamics.model(), v, &x[..dynamics.nparams().min(p)], y);
        y.chunks_exact(p).map(|row| crate::dense::dot(row, x)).collect()
    }

    /// Per joint row, the columns it can be non-zero in (for
    /// [`Accumulator::with_column_support`]): the parameters of the bodies the joint
    /// supports, and its own joint terms; `None` when not known (a generated base
    /// regressor mixes bodies).
    pub fn row_support(&self, model: &Model) -> Option<Vec<Vec<usize>>> {
        let n = model.dof();
        let per_body = match self {
            TorqueRegressor::Standard | TorqueRegressor::StandardAndJoints(..) => 10,
            TorqueRegressor::Principal => 4,
            TorqueRegressor::PrincipalBase { .. } => return None,
        };
        // A leader's row also holds the bodies its followers move: not known here.
        if model.mimic_joint().is_some() {
            return None;
        }
        Some(
            (1..=n)
                .map(|j| {
                    let mut cols: Vec<usize> = (1..=n)
                        .filter(|&i| model.supports(j, i))
                        .flat_map(|i| per_body * (i - 1)..per_body * i)
                        .collect();
                    if let TorqueRegressor::StandardAndJoints(m) = self {
                        let e = m.extras;
                        let at = 10 * n + PER_JOINT * (j - 1);
                        cols.extend(at..at + PER_JOINT);
                        let (e, at) = (e.per_joint(), 10 * n + PER_JOINT * n + e.per_joint() * (j - 1));
                        cols.extend(at..at + e);
                    }
                    cols
                })
                .collect(),
        )
    }

    /// The regressor at `(q, v, a)`, row-major into `y` (`n × columns`); the
    /// load-dependent friction's column is 0 until [`TorqueRegressor::fill_load`].
    pub fn eval(&self, dynamics: &dyn Dynamics, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        match self {
            TorqueRegressor::Standard => dynamics.joint_torque_regressor(q, v, a, y),
            TorqueRegressor::Principal => dynamics.principal_regressor(q, v, a, y),
            TorqueRegressor::PrincipalBase { regressor, .. } => regressor(q, v, a, y),
            TorqueRegressor::StandardAndJoints(model) => {
                let extras = model.extras;
                let (n, rigid, e) = (v.len(), dynamics.nparams(), extras.per_joint());
                let p = rigid + (PER_JOINT + e) * n;
                // The rigid-body rows land packed at the front of `y`; each is then
                // moved to its place in the wider layout, last row first so that no
                // row is overwritten before it is moved (no buffer on this hot path).
                dynamics.joint_torque_regressor(q, v, a, &mut y[..n * rigid]);
                for j in (0..n).rev() {
                    y.copy_within(j * rigid..(j + 1) * rigid, j * p);
                    y[j * p + rigid..(j + 1) * p].fill(0.0);
                    let at = j * p + rigid + PER_JOINT * j;
                    let coulomb = model.coulomb(j);
                    y[at..at + PER_JOINT].copy_from_slice(&joint_regressor_row(v[j], a[j], coulomb));
                    if e > 0 {
                        let at = j * p + rigid + PER_JOINT * n + e * j;
                        extras.row(q[j], v[j], model.motor_angle(j, q[j]), 0.0, coulomb, &mut y[at..at + e]);
                    }
                }
            }
        }
    }

    /// Fills the load-dependent friction's column of the rows `y` (from
    /// [`TorqueRegressor::eval`]) with the links' load of the rigid-body parameters
    /// `rigid` (`10` per body): `|Y_j π|·s(q̇_j)` in row `j`. Nothing to do without
    /// that term.
    pub fn fill_load(&self, model: &Model, v: &[f64], rigid: &[f64], y: &mut [f64]) {
        let TorqueRegressor::StandardAndJoints(joints) = self else {
            return;
        };
        let extras = joints.extras;
        let Some(c) = extras.load_column() else { return };
        let (n, p, e, r) = (v.len(), self.columns(model), extras.per_joint(), 10 * model.dof());
        let first = r + PER_JOINT * n;
        for j in 0..n {
            let load = crate::dense::dot(&y[j * p..j * p + r], rigid);
            y[j * p + first + e * j + c] = ExtraTerms::load_entry(load, v[j], joints.coulomb(j));
        }
    }
}

/// How the joint-torque rows are weighted.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Weighting {
    /// Ordinary least squares.
    #[default]
    Ols,
    /// Gautier's weighted least squares, one noise level per joint estimated from
    /// the OLS residuals ([`Accumulator::wls`]).
    Wls,
    /// Weighted least squares with the per-joint noise levels re-estimated from the
    /// weighted residuals up to this many times ([`Accumulator::wls_iterated`]):
    /// better than [`Weighting::Wls`] when one joint is much quieter than the others
    /// (a wrist), whose σ one step overestimates.
    WlsIterated(usize),
    /// Weighted least squares with known per-joint noise variances (`n`), e.g. from
    /// the sensors' data sheets ([`Accumulator::wls_with_variances`]).
    KnownVariances(Vec<f64>),
}

/// An identifiable combination against the truth.
#[derive(Clone, Debug, PartialEq)]
pub struct CombinationError {
    /// `Σ c_j x_j`, lead parameter first.
    pub terms: Vec<(usize, f64)>,
    pub estimate: f64,
    pub truth: f64,
    pub absolute: f64,
    /// Relative to `|truth|` (absolute when the truth is 0).
    pub relative: f64,
}

/// Identification from joint torques alone: the estimate, the names of its
/// parameters, and the truth comparison when the truth is known.
#[derive(Clone, Debug)]
pub struct TorqueEstimate {
    pub regressor: TorqueRegressor,
    /// One name per parameter (`m1`, `J1_1`, … or the generated groupings).
    pub names: Vec<String>,
    pub estimate: Estimate,
    /// True parameters in the regressor's parameterisation, when known.
    pub truth: Option<Vec<f64>>,
}

impl TorqueEstimate {
    /// The predicted joint torques `Y(q, v, a) x̂` (any least-squares solution gives
    /// the same prediction on the identifiable subspace: this is `Y_b β̂`).
    pub fn predict(&self, dynamics: &dyn Dynamics, q: &[f64], v: &[f64], a: &[f64]) -> Vec<f64> {
        let n = dynamics.nv();
        let p = self.regressor.columns(dynamics.model());
        let mut y = vec![0.0; n * p];
        self.regressor
            .predict(dynamics, q, v, a, &self.estimate.solution, &mut y)
    }

    /// RMS per joint of `τ_measured − τ_predicted` over `recording` (a validation
    /// trajectory, say).
    pub fn validation_rms(&self, dynamics: &dyn Dynamics, recording: &Recording) -> Vec<f64> {
        let n = dynamics.nv();
        let mut sum = vec![0.0; n];
        for s in &recording.samples {
            let tau = self.predict(dynamics, &s.q, &s.v, &s.a);
            for j in 0..n {
                sum[j] += (s.tau[j] - tau[j]).powi(2);
            }
        }
        sum.iter().map(|x| (x / recording.len().max(1) as f64).sqrt()).collect()
    }

    /// Identified single parameters against the truth: `(index, estimate, truth)`.
    pub fn identified(&self) -> Vec<(usize, f64, Option<f64>)> {
        self.estimate
            .params
            .iter()
            .enumerate()
            .filter_map(|(j, p)| {
                (p.status == Status::Identified)
                    .then(|| p.value.map(|v| (j, v, self.truth.as_ref().map(|t| t[j]))))
                    .flatten()
            })
            .collect()
    }

    /// Every identifiable combination (singletons included) against the truth.
    pub fn combination_errors(&self) -> Option<Vec<CombinationError>> {
        let truth = self.truth.as_ref()?;
        Some(
            self.estimate
                .combinations
                .iter()
                .map(|c| {
                    let t: f64 = c.terms.iter().map(|&(j, k)| k * truth[j]).sum();
                    let absolute = (c.value - t).abs();
                    CombinationError {
                        terms: c.terms.clone(),
                        estimate: c.value,
                        truth: t,
                        absolute,
                        relative: crate::relative_error(c.value, t),
                    }
                })
                .collect(),
        )
    }
}

impl fmt::Display for TorqueEstimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.names.iter().map(String::as_str).collect();
        let e = &self.estimate;
        let alone = e.params.iter().filter(|p| p.status == Status::Identified).count();
        writeln!(
            f,
            "from joint torques ({:?} regressor): {} parameters, rank {}, {} identifiable alone, {} only in combination, {} without effect",
            self.regressor,
            e.n_params(),
            e.rank,
            alone,
            e.params.iter().filter(|p| p.status == Status::InCombination).count(),
            e.params.iter().filter(|p| p.status == Status::NoEffect).count(),
        )?;
        write!(f, "{}", e.table(&names))?;
        if let Some(errors) = self.combination_errors() {
            writeln!(f, "identifiable combinations against the truth:")?;
            for c in &errors {
                let mut expr = String::new();
                for (t, &(j, k)) in c.terms.iter().enumerate() {
                    let sign = match (t, k < 0.0) {
                        (0, false) => "",
                        (0, true) => "−",
                        (_, false) => " + ",
                        (_, true) => " − ",
                    };
                    let factor = if (k.abs() - 1.0).abs() < 1e-12 {
                        String::new()
                    } else {
                        format!("{:.6}·", k.abs())
                    };
                    expr.push_str(&format!("{sign}{factor}{}", names[j]));
                }
                writeln!(
                    f,
                    "  {:<40} estimate {:>14.6e}  truth {:>14.6e}  abs err {:.3e}  rel err {:.3e}",
                    expr, c.estimate, c.truth, c.absolute, c.relative
                )?;
            }
        }
        Ok(())
    }
}

#[allow(clippy::too_many_arguments)]
fn torque_estimate(
    dynamics: &dyn Dynamics,
    recording: &Recording,
    range: Range<usize>,
    regressor: TorqueRegressor,
    names: Vec<String>,
    truth: Option<&[f64]>,
    weighting: Weighting,
    opts: &Options,
) -> Result<TorqueEstimate, IdentifyError> {
    check_range(recording, &range)?;
    let n = dynamics.nv();
    let p = regressor.columns(dynamics.model());
    check_truth(truth, p)?;
    let mut acc = Accumulator::with_channels(p, Channels::Interleaved(n))?;
    if let Some(support) = regressor.row_support(dynamics.model()) {
        acc = acc.with_column_support(support)?;
    }
    let mut y = vec![0.0; n * p];
    // The load of load-dependent friction: the model's own rigid-body parameters.
    let nominal = dynamics.model().standard_params();
    for s in &recording.samples[range] {
        regressor.eval(dynamics, &s.q, &s.v, &s.a, &mut y);
        regressor.fill_load(dynamics.model(), &s.v, &nominal, &mut y);
        acc.push_rows(crate::faer::MatRef::from_row_major_slice(&y, n, p), &s.tau)?;
    }
    let estimate = match &weighting {
        Weighting::Ols => acc.ols(opts)?,
        Weighting::Wls => acc.wls(opts)?,
        Weighting::WlsIterated(k) => acc.wls_iterated(*k, opts)?,
        Weighting::KnownVariances(v) => acc.wls_with_variances(v, opts)?,
    };
    Ok(TorqueEstimate {
        regressor,
        names,
        estimate,
        truth: truth.map(<[f64]>::to_vec),
    })
}

/// Identification from joint torques through `regressor` with rank handling: the
/// identifiable combinations come from the data ([`Estimate::combinations`]); each
/// parameter is reported as identifiable alone, only in combination, or without
/// effect. [`TorqueRegressor::Standard`]: `τ = Y π`, the combinations are the base
/// parameters; [`TorqueRegressor::Principal`]: the paper's MIM from joint torques
/// alone, `τ = Y_θ θ`; [`TorqueRegressor::StandardAndJoints`]: a real robot's
/// torques, with rotor inertia and friction per joint (and a load-dependent
/// friction's load from the model's own rigid-body parameters). `truth`: in the
/// regressor's parameters ([`TorqueRegressor::names`]).
pub fn torque(
    dynamics: &dyn Dynamics,
    recording: &Recording,
    range: Range<usize>,
    regressor: TorqueRegressor,
    truth: Option<&[f64]>,
    weighting: Weighting,
    opts: &Options,
) -> Result<TorqueEstimate, IdentifyError> {
    let names = regressor.names(dynamics.model());
    torque_estimate(dynamics, recording, range, regressor, names, truth, weighting, opts)
}

/// MIM from joint torques through a generated robot's principal base regressor: the
/// parameters are `R`'s principal base parameters, named by
/// [`dyngen::RobotDescription::principal_base_groupings`], the truth `R::principal_base_params` of
/// `R::nominal_theta()`. `dynamics` must be the same robot (e.g.
/// [`dyngen_reference::Generated<R>`]).
pub fn torque_principal_base<R: Robot>(
    dynamics: &dyn Dynamics,
    recording: &Recording,
    range: Range<usize>,
    weighting: Weighting,
    opts: &Options,
) -> Result<TorqueEstimate, IdentifyError> {
    let mut truth = vec![0.0; R::NBASE_PRINCIPAL];
    R::principal_base_params(R::nominal_theta(), &mut truth);
    let names = R::principal_base_groupings().iter().map(|s| s.to_string()).collect();
    let regressor = TorqueRegressor::PrincipalBase {
        columns: R::NBASE_PRINCIPAL,
        regressor: R::principal_base_regressor::<f64>,
    };
    torque_estimate(
        dynamics,
        recording,
        range,
        regressor,
        names,
        Some(&truth),
        weighting,
        opts,
    )
}
