//! Identification from a recording, end to end: read a log through a
//! [`Recipe`], estimate the derivatives it does not measure, stack the regressor
//! rows of any [`Dynamics`] (the reference on a URDF, or a generated robot), estimate,
//! predict the torques, and produce the report: the JSON [`ParameterReport`] and the
//! identified inertials for a URDF rewrite.
//!
//! Plain structs in and out, one error enum, no printing: `dyngen identify` is a
//! front end of this module, and any other front end calls the same functions.
//!
//! ```no_run
//! use dyngen_identify::data::Recipe;
//! use dyngen_identify::pipeline::{self, Estimator, IdentifyOptions, Mode};
//! let model = dyngen_model::load_urdf(std::path::Path::new("ur5.urdf")).unwrap();
//! let robot = dyngen_reference::Reference::new(&model);
//! let options = IdentifyOptions {
//!     mode: Mode::Standard,
//!     estimator: Estimator::Wls,
//!     ..IdentifyOptions::default()
//! };
//! let loaded = pipeline::load(std::path::Path::new("ur5.csv"), &Recipe::default(), model.dof(), &options).unwrap();
//! let identified = pipeline::identify(&robot, &loaded.trajectory, &options).unwrap();
//! println!("{}", identified.report.to_json().unwrap());
//! ```

use crate::data::{DataError, Loaded, Location, Recipe, RecipeError, Trajectory};
use crate::extras::ExtraTerms;
use crate::mim::{self, JointModel, MimEstimate, MimOptions, TorqueEstimate, TorqueRegressor};
use crate::report::{
    self, CoulombReport, JointParams, JointParamsFile, MergedLinks, NonPhysical, ParamReport, ParamStatus,
    ParameterReport, Parameterisation, PredictionModel, Preprocessing, ReportError, JOINT_PARAMS_SCHEMA,
};
use crate::simulate::Recording;
use crate::stribeck::StribeckFit;
use crate::{Accumulation, Accumulator, Channels, IdentifyError, Layout, Options, PrincipalOptions, StandardOptions};
use dyngen_model::joint_params::{Coulomb, PER_JOINT};
use dyngen_model::{ErrorKind, Inertial, Model};
use dyngen_reference::{principal_params_to_standard, Dynamics, Reference};
use std::fmt;
use std::path::{Path, PathBuf};

/// What is identified, from what.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// The 10 standard parameters per body from the joint torques.
    #[default]
    Standard,
    /// `θ = (m, J1, J2, J3)` per body from the joint torques (principal regressor;
    /// centres of mass and principal axes from the model).
    Principal,
    /// `θ` per body from the joint wrenches, body by body (the paper's MIM).
    Mim,
}

/// The estimator of [`Mode::Standard`] and [`Mode::Principal`]. MIM always uses
/// least squares weighted per body axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Estimator {
    /// Ordinary least squares.
    #[default]
    Ols,
    /// Gautier's weighted least squares, one noise variance per joint.
    Wls,
    /// Total least squares (noise on the regressor too), with every column of
    /// `[A y]` scaled by its norm first ([`Accumulator::tls`]) or, without
    /// `column_scaling`, as it is ([`Accumulator::tls_unscaled`]).
    Tls { column_scaling: bool },
    /// Ridge regression toward the model's own parameters with this scale-free
    /// weight (≥ 0; the penalty is `λ ‖D (x − x₀)‖²`, `D² = diag(AᵀA)`, see
    /// [`Accumulator::ridge`]).
    Ridge { lambda: f64 },
    /// Physically consistent least squares: principal form with `m > 0`, `J > 0`
    /// and the triangle inequalities, or standard form with a positive-definite
    /// pseudo-inertia per body and, with [`JointTerms`], every joint's rotor
    /// inertia and viscous and Coulomb friction `≥ 0` (the offset free). The
    /// directions the data do not determine are pulled toward the model's own
    /// parameters (the `prior` of [`StandardOptions`] and [`PrincipalOptions`]),
    /// as far as the constraints allow.
    Consistent,
}

/// What the joints do besides carrying the bodies, in [`Mode::Standard`]: nothing,
/// or per joint rotor inertia, viscous and Coulomb friction and an offset
/// `[Ia, Fv, Fc, F0]` ([`dyngen_model::joint_params`]), which a real robot's
/// torques always contain.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum JointTerms {
    /// Rigid bodies only (simulated data, or torques measured after the drive).
    #[default]
    None,
    /// Friction and rotor inertia with the Coulomb term as given.
    Friction(Coulomb),
    /// Friction and rotor inertia with `Fc·tanh(q̇_j/ε_j)`, each joint's `ε` chosen
    /// by the error on held-out time blocks of the recording
    /// ([`crate::choice::epsilons`]), or given ([`IdentifyOptions::epsilons`]).
    FrictionAuto,
    /// Friction and rotor inertia with the Coulomb term as given, and per joint a
    /// Stribeck term: static friction `Fs ≥ 0` and Stribeck velocity `vs` within a
    /// range from the joint's speeds ([`crate::stribeck`]), fitted by nonlinear
    /// least squares from the linear fit. A joint keeps the term only where it
    /// lowers the joint's error on held-out time blocks of the recording and stays
    /// physical; the others fall back to the linear model
    /// ([`crate::stribeck::JointChoice`]).
    ///
    /// With [`Estimator::Consistent`] the linear fit is the consistent one and the
    /// refinement keeps its bounds: each joint's nonlinear fit holds `Ia, Fv, Fc ≥ 0`
    /// (projected after every step) and every linear refit is the consistent
    /// estimator's, so the result is physical and still never a worse fit than the
    /// consistent linear start. (Without the bounds in the joint fits, a joint fit
    /// that drives `Fc` below zero cannot be carried into the consistent refit, and
    /// no round is ever accepted.)
    Stribeck(Coulomb),
}

/// Refits of the load-dependent friction's alternation, at most.
pub const LOAD_ROUNDS: usize = 8;
/// The alternation stops when the links' load (every row's rigid-body torque)
/// changes by less than this fraction (relative RMS).
pub const LOAD_CHANGE: f64 = 1e-4;

/// Samples the load-dependent friction's alternation runs on, at most (then it fits
/// once on all).
pub const LOAD_SAMPLES: usize = 10_000;

/// Everything [`load`] and [`identify`] need besides the data and the robot.
#[derive(Clone, Debug, PartialEq)]
pub struct IdentifyOptions {
    pub mode: Mode,
    pub estimator: Estimator,
    /// Friction and rotor inertia ([`Mode::Standard`] only).
    pub joints: JointTerms,
    /// With [`JointTerms::FrictionAuto`]: each joint's Coulomb smoothing `ε`, found
    /// elsewhere (by the model choice, [`crate::choice::choose`]). `None`: chosen on
    /// held-out time blocks of the recording ([`crate::choice::epsilons`]).
    pub epsilons: Option<Vec<f64>>,
    /// The rotor inertias `Ia` on their own ([`Mode::Standard`] only): `None` fits
    /// them with the friction terms, as [`IdentifyOptions::joints`] says;
    /// `Some(false)` leaves them out (friction without rotor inertia: the `Ia`
    /// columns are held at 0); `Some(true)` fits them, and with
    /// [`JointTerms::None`] alone (rotor inertia without friction: the `Fv`, `Fc`
    /// and `F0` columns held at 0). Terms left out are reported
    /// [`ParamStatus::Excluded`].
    pub rotor_inertia: Option<bool>,
    /// Joint terms past viscous and Coulomb friction ([`crate::extras`]): with
    /// [`JointTerms::Friction`] or [`JointTerms::FrictionAuto`] only.
    pub extras: ExtraTerms,
    /// Each joint's gear ratio `N_j` (motor angle `N_j q_j`), for the extra terms'
    /// motor ripple, which needs them.
    pub gear_ratios: Option<Vec<f64>>,
    /// How the torque rows are compressed (MIM accumulates by QR).
    pub accumulation: Accumulation,
    /// Leave a joint's torque rows out of its equations at the samples where its
    /// `|q̇|` is below this speed (rad/s, m/s for prismatic joints): near velocity
    /// reversals real joints stick and creep, which `Fc·sign(q̇)` does not describe.
    /// [`Identification::excluded_rows`] counts them. `None`: every row is used.
    pub exclude_below: Option<f64>,
    /// Low-pass cutoff (Hz) for velocities and accelerations estimated from
    /// positions or measured velocities, and for [`IdentifyOptions::low_pass_states`].
    pub cutoff_hz: f64,
    /// Low-pass the measured positions and velocities at `cutoff_hz` as well
    /// ([`Loaded::with_states_low_passed`]), so that the regressor sees the same
    /// band as the accelerations. Default `true`; `false` uses them as read.
    pub low_pass_states: bool,
    /// Rank and identifiability tolerances of the estimators.
    pub tolerances: Options,
    /// Take the model's own inertials as the truth: MIM then reports each
    /// parameter's error in its estimate.
    pub model_is_truth: bool,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        IdentifyOptions {
            mode: Mode::Standard,
            estimator: Estimator::Ols,
            joints: JointTerms::None,
            epsilons: None,
            rotor_inertia: None,
            extras: ExtraTerms::NONE,
            gear_ratios: None,
            accumulation: Accumulation::Qr,
            exclude_below: None,
            cutoff_hz: 10.0,
            low_pass_states: true,
            tolerances: Options::default(),
            model_is_truth: false,
        }
    }
}

impl IdentifyOptions {
    /// Refuses options that cannot work, before any data is read.
    pub fn check(&self) -> Result<(), PipelineError> {
        let invalid = |option, reason: String| Err(PipelineError::InvalidOption { option, reason });
        if !(self.cutoff_hz.is_finite() && self.cutoff_hz > 0.0) {
            return invalid(
                "cutoff",
                format!("must be a positive frequency in Hz, got {}", self.cutoff_hz),
            );
        }
        if let Estimator::Ridge { lambda } = self.estimator {
            if !(lambda.is_finite() && lambda >= 0.0) {
                return invalid("lambda", format!("must be non-negative, got {lambda}"));
            }
        }
        if self.mode == Mode::Mim && self.estimator != Estimator::Ols {
            return invalid(
                "method",
                "applies to the standard and principal modes; MIM always uses least squares weighted per body axis"
                    .into(),
            );
        }
        if self.joints != JointTerms::None && self.mode != Mode::Standard {
            return invalid(
                "friction",
                "applies to the standard mode (the joint terms enter the joint torques, not the body equations)".into(),
            );
        }
        if self.rotor_inertia == Some(false) && self.joints == JointTerms::None {
            return invalid(
                "rotor-inertia",
                "no has nothing to leave the rotor inertia out of without friction terms (the rigid bodies alone \
                 have none); give friction terms, or drop it"
                    .into(),
            );
        }
        if self.rotor_inertia.is_some() && self.mode != Mode::Standard {
            return invalid(
                "rotor-inertia",
                "applies to the standard mode (the joint terms enter the joint torques, not the body equations)".into(),
            );
        }
        if let JointTerms::Friction(Coulomb::Smooth { epsilon }) | JointTerms::Stribeck(Coulomb::Smooth { epsilon }) =
            self.joints
        {
            if !(epsilon.is_finite() && epsilon > 0.0) {
                return invalid("friction", format!("the smoothing ε must be positive, got {epsilon}"));
            }
        }
        if let Some(e) = &self.epsilons {
            if self.joints != JointTerms::FrictionAuto {
                return invalid(
                    "epsilons",
                    "give the Coulomb smoothing per joint with auto friction only".into(),
                );
            }
            if let Some(j) = e.iter().position(|e| !(e.is_finite() && *e > 0.0)) {
                return invalid(
                    "epsilons",
                    format!("joint {}'s smoothing ε must be positive, got {}", j + 1, e[j]),
                );
            }
        }
        if !self.extras.is_empty() {
            match self.joints {
                JointTerms::Friction(_) | JointTerms::FrictionAuto => {}
                JointTerms::None => {
                    return invalid(
                        "extra-terms",
                        format!(
                            "{} extends the friction model: give --friction sign, smooth or auto as well",
                            self.extras
                        ),
                    )
                }
                JointTerms::Stribeck(_) => {
                    return invalid(
                        "extra-terms",
                        "do not combine with Stribeck friction (its joint fits model the friction alone); use \
                         --friction sign, smooth or auto with them"
                            .into(),
                    )
                }
            }
        }
        match &self.gear_ratios {
            None if self.extras.motor_harmonics > 0 => {
                return invalid(
                    "extra-terms",
                    "motor-ripple needs each joint's gear ratio (--gear-ratios)".into(),
                )
            }
            Some(r) => {
                if let Some(j) = r.iter().position(|n| !(n.is_finite() && *n != 0.0)) {
                    return invalid(
                        "gear-ratios",
                        format!("joint {}'s gear ratio must be finite and not 0, got {}", j + 1, r[j]),
                    );
                }
            }
            None => {}
        }
        if let Some(speed) = self.exclude_below {
            if !(speed.is_finite() && speed > 0.0) {
                return invalid(
                    "exclude-below",
                    format!("must be a positive speed (rad/s or m/s), got {speed}"),
                );
            }
            if self.mode == Mode::Mim {
                return invalid(
                    "exclude-below",
                    "applies to the standard and principal modes (joint torque rows); MIM uses every sample".into(),
                );
            }
        }
        if self.mode == Mode::Mim && self.accumulation != Accumulation::Qr {
            return invalid(
                "accumulation",
                "applies to the standard and principal modes; MIM accumulates by QR".into(),
            );
        }
        Ok(())
    }
}

/// Why the pipeline stopped. Every variant names the option, file, line or body.
#[derive(Debug)]
pub enum PipelineError {
    /// An option outside its domain or not valid in this mode.
    InvalidOption { option: &'static str, reason: String },
    /// The recipe's settings contradict each other.
    Recipe(RecipeError),
    /// The recording could not be read, or its derivatives not estimated.
    Data { path: Option<PathBuf>, error: DataError },
    /// The recording has a different number of joints than the robot.
    DofMismatch { expected: usize, found: usize },
    /// MIM needs the joint wrench columns, which the recording does not have.
    MissingWrenches { dof: usize },
    /// The estimator failed (`at`: the sample whose rows it refused).
    Identify { at: Option<Location>, error: IdentifyError },
    /// A fully identified body lumps links attached by fixed joints, and writing its
    /// inertial was not allowed to move theirs ([`MergedLinks::Refuse`]).
    MergedLinks { body: String, merged: Vec<String> },
    /// The URDF could not be edited.
    Report(ReportError),
    /// The torque rows taken (those left out by [`IdentifyOptions::exclude_below`]
    /// not counted) do not outnumber the parameters: no more equations than
    /// unknowns, fitted exactly or nearly whatever the noise.
    TooFewRows { samples: usize, rows: usize, params: usize },
    /// The estimate is not finite although every input was: values so large that
    /// the arithmetic overflowed. `largest`: the input of largest magnitude, where
    /// it is and what it is.
    NonFiniteEstimate {
        largest: Option<(f64, Location, &'static str)>,
    },
}

impl fmt::Display for PipelineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidOption { option, reason } => write!(f, "{option} {reason}"),
            Self::Recipe(e) => write!(f, "recipe: {e}"),
            Self::Data {
                path: Some(path),
                error,
            } => write!(f, "{}: {error}", path.display()),
            Self::Data { path: None, error } => write!(f, "{error}"),
            Self::DofMismatch { expected, found } => {
                write!(f, "the recording has {found} joints, the robot {expected}")
            }
            Self::MissingWrenches { dof } => write!(
                f,
                "MIM needs the joint wrench columns fx1, fy1, fz1, mx1, my1, mz1, …, mz{dof}, which the recording \
                 does not have; identify from the joint torques (standard or principal mode) instead"
            ),
            Self::Identify { at: Some(at), error } => write!(f, "{at}: {error}"),
            Self::Identify { at: None, error } => write!(f, "{error}"),
            Self::NonFiniteEstimate { largest: None } => write!(
                f,
                "the estimate is not finite: the merged factors overflow the arithmetic (values of a robot's motion \
                 and torques are below 1e6 in SI units)"
            ),
            Self::NonFiniteEstimate {
                largest: Some((value, at, what)),
            } => write!(
                f,
                "the estimate is not finite: the recording's values overflow the arithmetic; the largest is the \
                 {what} {value:e} at {at} (values of a robot's motion and torques are below 1e6 in SI units)"
            ),
            Self::TooFewRows { samples, rows, params } => write!(
                f,
                "{samples} samples give {rows} torque rows for {params} parameters: no more equations than \
                 unknowns, so the fit matches any data and its σ means nothing; record more than {} samples (in \
                 practice a few hundred along an exciting motion)",
                params / (rows / (*samples).max(1)).max(1)
            ),
            Self::MergedLinks { body, merged } => write!(
                f,
                "body `{body}` is fully identified, but its inertial includes the links [{}] attached by fixed \
                 joints; lump it into `{body}` (removing their <inertial> elements) to write it",
                merged.join(", ")
            ),
            Self::Report(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for PipelineError {}

impl From<IdentifyError> for PipelineError {
    fn from(error: IdentifyError) -> Self {
        PipelineError::Identify { at: None, error }
    }
}

/// Reads the log at `path` through `recipe` (checked), requiring `dof` joints, and
/// estimates what it does not measure at `options.cutoff_hz`. The [`Loaded`] report
/// says what was measured, estimated and dropped.
pub fn load(path: &Path, recipe: &Recipe, dof: usize, options: &IdentifyOptions) -> Result<Loaded, PipelineError> {
    options.check()?;
    let data = |error| PipelineError::Data {
        path: Some(path.to_path_buf()),
        error,
    };
    recipe.check().map_err(PipelineError::Recipe)?;
    let loaded = recipe
        .read(path, Some(dof))
        .and_then(|loaded| loaded.with_derivatives(options.cutoff_hz))
        .map_err(data)?;
    if options.low_pass_states {
        loaded.with_states_low_passed(options.cutoff_hz).map_err(data)
    } else {
        Ok(loaded)
    }
}

/// How an identification predicts the joint torques.
#[derive(Clone, Debug)]
pub enum Prediction {
    /// Regressor rows times the estimate's solution: exact on the identifiable
    /// subspace, whatever the unidentifiable directions hold.
    Regressor(Box<TorqueEstimate>),
    /// Inverse dynamics with these standard parameters (MIM: `θ` where identified,
    /// the model's elsewhere).
    Parameters(Vec<f64>),
}

/// What an identification produced.
#[derive(Clone, Debug)]
pub struct Identification {
    pub mode: Mode,
    /// Names, values, σ and status of every parameter; the identifiable combinations.
    pub report: ParameterReport,
    /// The MIM estimate with its verdicts (and errors when the model is the truth).
    pub mim: Option<MimEstimate>,
    pub prediction: Prediction,
    /// What the caller should know before trusting the numbers (e.g. a total least
    /// squares fit far worse than ordinary least squares on the same data).
    pub warnings: Vec<String>,
    /// Per joint, the torque rows left out by [`IdentifyOptions::exclude_below`]
    /// (all 0 without it, and for MIM).
    pub excluded_rows: Vec<usize>,
    /// The Stribeck terms, with [`JointTerms::Stribeck`].
    pub stribeck: Option<StribeckFit>,
}

/// A TLS residual this many times the OLS residual means TLS's assumption (noise
/// in every regressor column and the torques, equal after the column scaling) does
/// not hold for the data.
pub const TLS_RESIDUAL_WARNING: f64 = 1.5;

/// Identifies `dynamics`'s inertial parameters from `trajectory` (which must have
/// velocities and accelerations: see [`load`]).
pub fn identify(
    dynamics: &dyn Dynamics,
    trajectory: &Trajectory,
    options: &IdentifyOptions,
) -> Result<Identification, PipelineError> {
    options.check()?;
    let n = dynamics.nv();
    if trajectory.dof() != n {
        return Err(PipelineError::DofMismatch {
            expected: n,
            found: trajectory.dof(),
        });
    }
    need_derivatives(trajectory)?;
    let model = dynamics.model();
    for (option, values) in [("gear-ratios", &options.gear_ratios), ("epsilons", &options.epsilons)] {
        if let Some(r) = values.as_ref().filter(|r| r.len() != model.nv()) {
            return Err(PipelineError::InvalidOption {
                option,
                reason: format!("{} values for {} joints; give one per joint", r.len(), model.nv()),
            });
        }
    }
    if (options.extras.harmonics > 0 || options.extras.motor_harmonics > 0) && model.nq() != model.nv() {
        return Err(PipelineError::InvalidOption {
            option: "extra-terms",
            reason: format!(
                "ripple harmonics are of each joint's one angle; `{}` has {} position and {} velocity coordinates \
                 (a ball or free joint)",
                model.name,
                model.nq(),
                model.nv()
            ),
        });
    }
    match options.mode {
        Mode::Standard | Mode::Principal => from_torques(dynamics, trajectory, options),
        Mode::Mim => {
            if let Some(j) = dynamics.model().mimic_joint() {
                return Err(PipelineError::InvalidOption {
                    option: "mode",
                    reason: format!(
                        "mim takes one joint wrench per coordinate, and joint `{}` follows another (<mimic>) \
                         without a coordinate of its own; use --mode standard or principal",
                        j.name
                    ),
                });
            }
            by_mim(dynamics, trajectory, options)
        }
    }
}

/// Standard or principal parameters through the stacked joint-torque regressor.
fn from_torques(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    options: &IdentifyOptions,
) -> Result<Identification, PipelineError> {
    let regressor = match options.joints {
        JointTerms::FrictionAuto if options.mode == Mode::Standard => {
            // Their number was checked by `identify`.
            let epsilons = match &options.epsilons {
                Some(e) => e.clone(),
                None => crate::choice::epsilons(dynamics, traj, options)?,
            };
            TorqueRegressor::StandardAndJoints(
                JointModel::per_joint(&epsilons, options.extras).with_gear_ratios(options.gear_ratios.as_deref()),
            )
        }
        _ => torque_regressor(options),
    };
    let fit = TorqueFit::new(dynamics.model(), regressor.clone(), options);
    // With the load-dependent friction, the load of each row from the rigid-body
    // parameters of the fit before (the first fit has no load term), until the
    // load settles: on at most LOAD_SAMPLES samples spread over the recording, then
    // once on all.
    let stride = match options.extras.load {
        true => traj.len().div_ceil(LOAD_SAMPLES).max(1),
        false => 1,
    };
    let mut acc = accumulate(dynamics, traj, &regressor, stride, None, options)?;
    let (mut estimate, mut warnings) = fit.first(&acc, || Some(largest_input(traj)))?;
    if options.extras.load {
        let rigid = 10 * dynamics.model().dof();
        let loads = |params: &[f64]| -> Vec<f64> {
            let mut tau = vec![0.0; dynamics.nv()];
            (0..traj.len())
                .step_by(stride)
                .flat_map(|k| {
                    let (q, v, a) = state(traj, k);
                    dynamics.rnea(q, v, a, &params[..rigid], &mut tau);
                    tau.clone()
                })
                .collect()
        };
        let mut load = loads(&estimate.solution);
        for _ in 0..LOAD_ROUNDS {
            let sampled = accumulate(
                dynamics,
                traj,
                &regressor,
                stride,
                Some(&estimate.solution[..rigid]),
                options,
            )?;
            (estimate, _) = fit.first(&sampled, || Some(largest_input(traj)))?;
            let next = loads(&estimate.solution);
            let change = crate::dense::relative_change(&next, &load);
            load = next;
            if change < LOAD_CHANGE {
                break;
            }
        }
        acc = accumulate(
            dynamics,
            traj,
            &regressor,
            1,
            Some(&estimate.solution[..rigid]),
            options,
        )?;
        (estimate, warnings) = fit.first(&acc, || Some(largest_input(traj)))?;
    }
    let (estimate, stribeck) = match options.joints {
        JointTerms::Stribeck(coulomb) if options.mode == Mode::Standard => {
            let constraints = crate::stribeck::JointConstraints {
                fitted: fit.fitted,
                nonnegative: options.estimator == Estimator::Consistent,
            };
            let (estimate, stribeck) = crate::stribeck::refine(dynamics, traj, coulomb, constraints, estimate, |t| {
                let acc = accumulate(dynamics, t, &regressor, 1, None, options)?;
                Ok::<_, PipelineError>(fit.solve(&acc)?)
            })?;
            let finite = estimate.solution.iter().all(|x| x.is_finite())
                && stribeck.joints.iter().all(|s| s.fs.is_finite() && s.vs.is_finite())
                && stribeck.cost.is_finite();
            if !finite {
                return Err(PipelineError::NonFiniteEstimate {
                    largest: Some(largest_input(traj)),
                });
            }
            (estimate, Some(stribeck))
        }
        _ => (estimate, None),
    };
    Ok(fit.identification((estimate, warnings), acc.excluded_per_channel(), stribeck))
}

/// The regressor `options` ask for, but for [`JointTerms::FrictionAuto`], whose ε
/// the data choose per joint (it gets `Fc·sign(q̇)` here).
pub(crate) fn torque_regressor(options: &IdentifyOptions) -> TorqueRegressor {
    match (options.mode, options.joints) {
        (Mode::Principal | Mode::Mim, _) => TorqueRegressor::Principal,
        (Mode::Standard, JointTerms::None) if options.rotor_inertia == Some(true) => {
            TorqueRegressor::StandardAndJoints(Coulomb::Sign.into())
        }
        (Mode::Standard, JointTerms::None) => TorqueRegressor::Standard,
        (Mode::Standard, JointTerms::Friction(coulomb) | JointTerms::Stribeck(coulomb)) => {
            TorqueRegressor::StandardAndJoints(joint_model(options, coulomb))
        }
        (Mode::Standard, JointTerms::FrictionAuto) => {
            TorqueRegressor::StandardAndJoints(joint_model(options, Coulomb::Sign))
        }
    }
}

/// The joint model of `options` (extra terms, gear ratios) with `coulomb`.
fn joint_model(options: &IdentifyOptions, coulomb: Coulomb) -> JointModel {
    JointModel::new(coulomb, options.extras).with_gear_ratios(options.gear_ratios.as_deref())
}

/// Identifies from accumulated joint-torque rows of `regressor` (standard or
/// principal mode; no Stribeck terms and no data-chosen ε, which need the rows
/// themselves): what a merge of partial factors solves ([`crate::partial`]).
pub(crate) fn from_accumulator(
    model: &Model,
    acc: &Accumulator,
    regressor: &TorqueRegressor,
    options: &IdentifyOptions,
) -> Result<Identification, PipelineError> {
    let fit = TorqueFit::new(model, regressor.clone(), options);
    let first = fit.first(acc, || None)?;
    Ok(fit.identification(first, acc.excluded_per_channel(), None))
}

/// The estimator and the report of an identification from joint torques, on a
/// model and a regressor: one home for what a recording and merged partial
/// factors share.
struct TorqueFit<'a> {
    model: &'a Model,
    regressor: TorqueRegressor,
    options: &'a IdentifyOptions,
    /// The model's parameters, those held at 0 set to 0 (ridge's prior).
    nominal: Vec<f64>,
    /// Which of each joint's `[Ia, Fv, Fc, F0]` are fitted.
    fitted: [bool; PER_JOINT],
    /// The columns held at 0.
    excluded: Vec<usize>,
}

impl<'a> TorqueFit<'a> {
    fn new(model: &'a Model, regressor: TorqueRegressor, options: &'a IdentifyOptions) -> Self {
        let mut nominal = nominal(model, options.mode);
        if matches!(regressor, TorqueRegressor::StandardAndJoints(..)) {
            nominal.extend(dyngen_model::joint_params::nominal_joint_params(model));
            // A robot description has no extra term: 0.
            nominal.resize(regressor.columns(model), 0.0);
        }
        let fitted = fitted_joint_terms(options);
        let excluded = excluded_columns(&regressor, model, fitted);
        for &c in &excluded {
            // Ridge pulls a term left out toward 0, where it is held.
            nominal[c] = 0.0;
        }
        TorqueFit {
            model,
            regressor,
            options,
            nominal,
            fitted,
            excluded,
        }
    }

    /// The estimator of the options on `acc`, the columns held at 0 excluded.
    fn solve(&self, acc: &Accumulator) -> Result<crate::Estimate, IdentifyError> {
        let opts = &self.options.tolerances;
        let mut estimate = match self.options.estimator {
            Estimator::Ols => acc.ols(opts),
            Estimator::Wls => acc.wls(opts),
            Estimator::Tls { column_scaling: true } => acc.tls(opts),
            Estimator::Tls { column_scaling: false } => acc.tls_unscaled(opts),
            Estimator::Ridge { lambda } => acc.ridge(&self.nominal, lambda, opts),
            // What the data leave undetermined is taken from the model, as far as
            // physical consistency allows (not from 0, which no physical body has).
            Estimator::Consistent if matches!(self.regressor, TorqueRegressor::Principal) => {
                let popts = PrincipalOptions {
                    prior: Some(self.nominal.clone()),
                    ..PrincipalOptions::default()
                };
                acc.principal_consistent(&popts, opts)
            }
            Estimator::Consistent => {
                let sopts = StandardOptions {
                    prior: Some(self.nominal.clone()),
                    ..consistent_options(&self.regressor, self.model, self.fitted)
                };
                acc.standard_consistent(&sopts, opts)
            }
        }?;
        // The columns held at 0 are no parameters of the model.
        for &c in &self.excluded {
            estimate.solution[c] = 0.0;
            let p = &mut estimate.params[c];
            (p.value, p.sigma, p.status) = (None, None, crate::Status::Excluded);
        }
        Ok(estimate)
    }

    /// The first estimate on all of `acc`, checked: some row taken, a finite
    /// estimate (else the error names `largest()`, the input of largest magnitude
    /// when the data are at hand), more rows than parameters. TLS far worse than
    /// OLS is a warning (the second value).
    fn first(
        &self,
        acc: &Accumulator,
        largest: impl Fn() -> Option<(f64, Location, &'static str)>,
    ) -> Result<(crate::Estimate, Vec<String>), PipelineError> {
        let options = self.options;
        if acc.rows_per_channel().iter().all(|&r| r == 0) {
            return Err(PipelineError::InvalidOption {
                option: "exclude-below",
                reason: format!(
                    "{} leaves no torque row: every joint moves slower than that at every sample",
                    options.exclude_below.unwrap_or(0.0)
                ),
            });
        }
        let estimate = self.solve(acc)?;
        if !(estimate.solution.iter().all(|x| x.is_finite()) && estimate.residuals.rms.is_finite()) {
            return Err(PipelineError::NonFiniteEstimate { largest: largest() });
        }
        // The rows taken: those left out below a speed (--exclude-below) do not count.
        let rows: usize = acc.rows_per_channel().iter().sum();
        if rows <= estimate.solution.len() {
            return Err(PipelineError::TooFewRows {
                samples: acc.rows() / self.model.nv().max(1),
                rows,
                params: estimate.solution.len(),
            });
        }
        let mut warnings = Vec::new();
        if let Estimator::Tls { column_scaling } = options.estimator {
            let ols = acc.ols(&options.tolerances)?;
            let ratio = estimate.residuals.rms / ols.residuals.rms;
            if ratio > TLS_RESIDUAL_WARNING {
                let assumption = if column_scaling {
                    "the same relative noise in every regressor column and the torques"
                } else {
                    "equal noise in every regressor column and the torques"
                };
                warnings.push(format!(
                    "total least squares fits the torques {ratio:.1}× worse than ordinary least squares (residual \
                     RMS {:.4e} against {:.4e}): its assumption of {assumption} does not hold for these data, and \
                     its parameters can be far off; prefer ols or wls",
                    estimate.residuals.rms, ols.residuals.rms
                ));
            }
        }
        Ok((estimate, warnings))
    }

    /// The identification of `estimate` with its report.
    fn identification(
        self,
        (estimate, mut warnings): (crate::Estimate, Vec<String>),
        excluded_rows: Vec<usize>,
        stribeck: Option<StribeckFit>,
    ) -> Identification {
        let (model, options, regressor) = (self.model, self.options, self.regressor);
        let (bodies, n) = (model.dof(), model.nv());
        let names = regressor.names(model);
        let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
        // One joint per velocity coordinate (a joint that follows another has none).
        let joint_names: Vec<&str> = model.own_joints().map(|j| j.name.as_str()).collect();
        let joint_model = match &regressor {
            TorqueRegressor::StandardAndJoints(m) => Some(m),
            _ => None,
        };
        let extras = joint_model.map_or(ExtraTerms::NONE, |m| m.extras);
        let epsilons = joint_model.and_then(|m| m.epsilons.as_deref().map(<[f64]>::to_vec));
        let gear_ratios = joint_model
            .filter(|m| m.extras.motor_harmonics > 0)
            .and_then(|m| m.gear_ratios.as_deref().map(<[f64]>::to_vec));
        let (parameterisation, coulomb) = match (&regressor, joint_model) {
            (TorqueRegressor::Principal, _) => (Parameterisation::Principal, None),
            (_, Some(m)) => (
                Parameterisation::StandardAndJoints,
                Some(match m.coulomb {
                    Coulomb::Sign => CoulombReport::Sign,
                    Coulomb::Smooth { epsilon } => CoulombReport::Tanh { epsilon },
                }),
            ),
            _ => (Parameterisation::Standard, None),
        };
        let mut report =
            ParameterReport::from_estimate(&model.name, parameterisation, &estimate, &name_refs, &joint_names);
        let nonphysical = match &regressor {
            TorqueRegressor::StandardAndJoints(m) => {
                let values: Vec<Option<f64>> = report.parameters[10 * bodies..]
                    .iter()
                    .map(|p| match p.status {
                        // Not told apart from zero (or from the prior): not reported as identified.
                        ParamStatus::NotSignificant | ParamStatus::FromPrior => None,
                        _ => p.value,
                    })
                    .collect();
                let (joint_terms, extra_terms) = values.split_at(PER_JOINT * n);
                nonphysical_joint_terms(joint_terms, m.extras, extra_terms, &joint_names)
            }
            _ => Vec::new(),
        };
        if !nonphysical.is_empty() {
            let list: Vec<String> = nonphysical
                .iter()
                .map(|p| format!("{} = {:.4e} (`{}`)", p.parameter, p.value, p.joint))
                .collect();
            let remedy = if options.estimator == Estimator::Consistent {
                "--method consistent was used, which keeps Ia, Fv, Fc (and Fcl) >= 0 only to its numerical \
                 tolerance: treat these as zero"
            } else {
                "--method consistent keeps every joint's Ia, Fv, Fc and Fcl >= 0 (and every body physical): try it"
            };
            warnings.push(format!(
                "non-physical joint parameters reported: {} (a negative rotor inertia, viscous, Coulomb or \
                 load-dependent friction, or |Fva| above Fv, is not physical); {remedy}",
                list.join("; ")
            ));
        }
        let (coulomb_epsilon, friction) = match options.joints {
            JointTerms::None => (None, "none"),
            JointTerms::Friction(Coulomb::Sign) => (None, "sign"),
            JointTerms::Friction(Coulomb::Smooth { epsilon }) => (Some(epsilon), "smooth"),
            JointTerms::FrictionAuto => (None, "auto"),
            JointTerms::Stribeck(Coulomb::Sign) => (None, "stribeck"),
            JointTerms::Stribeck(Coulomb::Smooth { epsilon }) => (Some(epsilon), "stribeck_smooth"),
        };
        report.prediction = Some(PredictionModel {
            regressor: parameterisation,
            coulomb,
            epsilons: epsilons.clone(),
            extras,
            gear_ratios,
            solution: estimate.solution.clone(),
            stribeck: stribeck.as_ref().map(|f| f.joints.clone()),
            preprocessing: Some(Preprocessing {
                cutoff_hz: Some(options.cutoff_hz),
                low_pass_states: Some(options.low_pass_states),
                friction: Some(friction.to_string()),
                coulomb_epsilon,
                coulomb_epsilons: epsilons,
                epsilon_auto: Some(options.joints == JointTerms::FrictionAuto),
                exclude_below: options.exclude_below,
                rotor_inertia: joint_model.is_some().then_some(self.fitted[0]),
                ..Preprocessing::default()
            }),
            nonphysical,
        });
        if let Some(fit) = &stribeck {
            report.parameters.extend(fit.param_reports());
        }
        Identification {
            mode: options.mode,
            report,
            mim: None,
            prediction: Prediction::Regressor(Box::new(TorqueEstimate {
                regressor,
                names,
                estimate,
                truth: options.model_is_truth.then_some(self.nominal),
            })),
            warnings,
            excluded_rows,
            stribeck,
        }
    }
}

/// The joint parameters among `values` (per joint `[Ia, Fv, Fc, F0]`) and
/// `extra_values` (per joint the extra terms `extras`), `None` where no value is
/// reported, that are not physical: a negative rotor inertia `Ia`, viscous
/// friction `Fv`, Coulomb friction `Fc` or load-dependent friction `Fcl` (friction
/// that falls as the load grows turns negative under a large load), or a
/// direction-dependent viscous friction `|Fva|` above `Fv` (the viscous friction
/// `Fv ± Fva` is then negative in one direction). The offset `F0`, the ripple and
/// the position-dependent Coulomb terms may have either sign. `joints` names the
/// joints (missing names become `joint <j>`).
pub fn nonphysical_joint_terms(
    values: &[Option<f64>],
    extras: ExtraTerms,
    extra_values: &[Option<f64>],
    joints: &[&str],
) -> Vec<NonPhysical> {
    const WHAT: [&str; 3] = [
        "a negative rotor inertia",
        "a negative viscous friction",
        "a negative Coulomb friction",
    ];
    let joint = |j: usize| {
        joints
            .get(j)
            .map_or_else(|| format!("joint {}", j + 1), |s| s.to_string())
    };
    let per_joint = extras.per_joint();
    let mut flagged = Vec::new();
    for (j, terms) in values.chunks(PER_JOINT).enumerate() {
        for (k, v) in terms.iter().take(3).enumerate() {
            if let Some(v) = v.filter(|v| *v < 0.0) {
                flagged.push(NonPhysical {
                    joint: joint(j),
                    parameter: dyngen_model::names::param_name(dyngen_model::joint_params::NAMES[k], j + 1),
                    value: v,
                    reason: format!("{} is not physical", WHAT[k]),
                });
            }
        }
        let extra = |c: usize| extra_values.get(per_joint * j + c).copied().flatten();
        if let Some(fva) = extra(0).filter(|_| extras.asymmetric) {
            if terms.get(1).copied().flatten().is_some_and(|fv| fva.abs() > fv) {
                flagged.push(NonPhysical {
                    joint: joint(j),
                    parameter: dyngen_model::names::param_name("Fva", j + 1),
                    value: fva,
                    reason: "|Fva| above Fv makes the viscous friction Fv ± Fva negative in one direction, which is \
                             not physical"
                        .into(),
                });
            }
        }
        if let Some(fcl) = extras.load_column().and_then(extra).filter(|v| *v < 0.0) {
            flagged.push(NonPhysical {
                joint: joint(j),
                parameter: dyngen_model::names::param_name("Fcl", j + 1),
                value: fcl,
                reason: "a negative load-dependent friction (friction falling as the load grows, negative under a \
                         large load) is not physical"
                    .into(),
            });
        }
    }
    flagged
}

/// The input of `traj` of largest magnitude: its value, where it is and what it is.
pub(crate) fn largest_input(traj: &Trajectory) -> (f64, Location, &'static str) {
    let n = traj.dof();
    let columns: [(Option<&[f64]>, &'static str); 4] = [
        (Some(traj.positions()), "position"),
        (traj.velocities(), "velocity"),
        (traj.accelerations(), "acceleration"),
        (Some(traj.torques()), "torque"),
    ];
    let mut best = (0.0_f64, traj.location(0), "position");
    for (values, what) in columns {
        for (i, &x) in values.unwrap_or(&[]).iter().enumerate() {
            if x.abs() > best.0.abs() {
                best = (x, traj.location(i / n), what);
            }
        }
    }
    best
}

/// Which of each joint's `[Ia, Fv, Fc, F0]` are fitted
/// ([`IdentifyOptions::rotor_inertia`]); the others are held at 0.
pub fn fitted_joint_terms(options: &IdentifyOptions) -> [bool; PER_JOINT] {
    match (options.joints, options.rotor_inertia) {
        (JointTerms::None, Some(true)) => [true, false, false, false],
        (_, Some(false)) => [false, true, true, true],
        _ => [true; PER_JOINT],
    }
}

/// The columns of the joint terms `[Ia, Fv, Fc, F0]` (term `k` of each velocity
/// coordinate) for which `pick(k)` holds, for `regressor`: after the 10 standard
/// parameters per body, 4 per coordinate; none without joint terms.
fn joint_term_columns(regressor: &TorqueRegressor, model: &Model, pick: impl Fn(usize) -> bool) -> Vec<usize> {
    if !matches!(regressor, TorqueRegressor::StandardAndJoints(..)) {
        return Vec::new();
    }
    let rigid = 10 * model.dof();
    (0..model.nv())
        .flat_map(|j| (0..PER_JOINT).map(move |k| (j, k)))
        .filter(|&(_, k)| pick(k))
        .map(|(j, k)| rigid + PER_JOINT * j + k)
        .collect()
}

/// The columns of the joint terms held at 0 for `regressor`.
fn excluded_columns(regressor: &TorqueRegressor, model: &Model, fitted: [bool; PER_JOINT]) -> Vec<usize> {
    joint_term_columns(regressor, model, |k| !fitted[k])
}

/// The standard-form consistent estimator's options for `regressor`: the body
/// blocks first, then per coordinate `[Ia, Fv, Fc, F0]` with `Ia, Fv, Fc ≥ 0` (those
/// fitted).
fn consistent_options(regressor: &TorqueRegressor, model: &Model, fitted: [bool; PER_JOINT]) -> StandardOptions {
    let mut nonnegative = joint_term_columns(regressor, model, |k| k < 3 && fitted[k]);
    // The load-dependent friction's Fcl too.
    if let TorqueRegressor::StandardAndJoints(m) = regressor {
        if let Some(c) = m.extras.load_column() {
            let first = 10 * model.dof() + PER_JOINT * model.nv();
            nonnegative.extend((0..model.nv()).map(|j| first + m.extras.per_joint() * j + c));
        }
    }
    StandardOptions {
        layout: Some(Layout {
            first: 0,
            bodies: model.dof(),
        }),
        nonnegative,
        ..StandardOptions::default()
    }
}

/// The rows of `regressor` over every sample of `traj`, accumulated as `options`
/// say, after checking that `traj` fits `dynamics` and has velocities and
/// accelerations: a recording's partial factor ([`crate::partial`]).
pub(crate) fn accumulate_recording(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    regressor: &TorqueRegressor,
    options: &IdentifyOptions,
) -> Result<Accumulator, PipelineError> {
    if traj.dof() != dynamics.nv() {
        return Err(PipelineError::DofMismatch {
            expected: dynamics.nv(),
            found: traj.dof(),
        });
    }
    need_derivatives(traj)?;
    accumulate(dynamics, traj, regressor, 1, None, options)
}

/// The rows of `regressor` over every `stride`-th sample of `traj`, accumulated
/// as `options` say (compression, rows left out below a speed); a load-dependent
/// friction's load from the rigid-body parameters `load` (its column 0 without).
fn accumulate(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    regressor: &TorqueRegressor,
    stride: usize,
    load: Option<&[f64]>,
    options: &IdentifyOptions,
) -> Result<Accumulator, PipelineError> {
    let n = dynamics.nv();
    let p = regressor.columns(dynamics.model());
    let mut acc = Accumulator::with_accumulation(p, Channels::Interleaved(n), options.accumulation)?;
    // Joint terms left out of the model: their columns are zeroed in every row and
    // taken out of every row's support.
    let excluded = excluded_columns(regressor, dynamics.model(), fitted_joint_terms(options));
    if let Some(mut support) = regressor.row_support(dynamics.model()) {
        for cols in &mut support {
            cols.retain(|c| !excluded.contains(c));
        }
        acc = acc.with_column_support(support)?;
    }
    // The samples are cut into a fixed number of contiguous parts, each accumulated
    // on its own (regressor rows and QR folds on one core), and the parts are merged
    // in order: every core is busy all the time, and the result does not depend on
    // how many cores there are.
    let samples: Vec<usize> = (0..traj.len()).step_by(stride).collect();
    let parts: Vec<&[usize]> = samples.chunks(samples.len().div_ceil(PARTS).max(1)).collect();
    let threads = crate::accumulate::cores().clamp(1, parts.len().max(1));
    let template = &acc;
    let fill = |part: &[usize]| -> Result<Accumulator, PipelineError> {
        let mut acc = template.empty_part();
        let mut y = vec![0.0; n * p];
        let mut keep = vec![true; n];
        for &k in part {
            let (q, v, a) = state(traj, k);
            regressor.eval(dynamics, q, v, a, &mut y);
            if let Some(rigid) = load {
                regressor.fill_load(dynamics.model(), v, rigid, &mut y);
            }
            for row in y.chunks_exact_mut(p) {
                for &c in &excluded {
                    row[c] = 0.0;
                }
            }
            let rows = faer::MatRef::from_row_major_slice(&y, n, p);
            match options.exclude_below {
                Some(speed) => {
                    for (keep, v) in keep.iter_mut().zip(v) {
                        *keep = v.abs() >= speed;
                    }
                    acc.push_rows_masked(rows, traj.tau(k), &keep)
                }
                None => acc.push_rows(rows, traj.tau(k)),
            }
            .map_err(|error| PipelineError::Identify {
                at: Some(traj.location(k)),
                error,
            })?;
        }
        Ok(acc)
    };
    let mut filled: Vec<(usize, Result<Accumulator, PipelineError>)> = std::thread::scope(|s| {
        let (parts, fill) = (&parts, &fill);
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                s.spawn(move || {
                    (t..parts.len())
                        .step_by(threads)
                        .map(|i| (i, fill(parts[i])))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    filled.sort_by_key(|(i, _)| *i);
    let mut merged = acc;
    for (_, part) in filled {
        merged.merge(&part?)?;
    }
    Ok(merged)
}

/// Contiguous parts of the samples accumulated independently ([`accumulate`]).
const PARTS: usize = 8;

/// The paper's MIM on measured joint wrenches: every body's θ from its resultant,
/// the whole robot as one block-diagonal least-squares problem.
fn by_mim(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    options: &IdentifyOptions,
) -> Result<Identification, PipelineError> {
    let model = dynamics.model();
    if traj.joint_wrenches().is_none() {
        return Err(PipelineError::MissingWrenches { dof: model.dof() });
    }
    let reference = Reference::new(model);
    let recording =
        Recording::from_measurements(&reference, traj).map_err(|error| PipelineError::Data { path: None, error })?;
    let nominal = dyngen_model::principal_params(model);
    let truth = options.model_is_truth.then_some(nominal.as_slice());
    let mim_options = MimOptions {
        identify: options.tolerances.clone(),
        ..MimOptions::default()
    };
    let estimate = mim::whole_robot(&recording, 0..recording.len(), truth, &mim_options)?;
    // The torques of the identified model: θ where identified, the model's elsewhere.
    let theta: Vec<f64> = estimate
        .theta()
        .iter()
        .zip(&nominal)
        .map(|(x, t)| x.unwrap_or(*t))
        .collect();
    Ok(Identification {
        mode: Mode::Mim,
        report: ParameterReport::from_mim(&model.name, &estimate),
        prediction: Prediction::Parameters(principal_params_to_standard(model, &theta)),
        mim: Some(estimate),
        warnings: Vec::new(),
        excluded_rows: vec![0; model.dof()],
        stribeck: None,
    })
}

/// Refuses a trajectory without velocities or accelerations: the regressor needs them.
fn need_derivatives(trajectory: &Trajectory) -> Result<(), PipelineError> {
    if trajectory.velocities().is_none() || trajectory.accelerations().is_none() {
        return Err(PipelineError::Data {
            path: None,
            error: DataError::MissingGroup {
                group: "velocities and accelerations",
                columns: "v1.., a1..".into(),
                needed_for: "the regressor (estimate them first: pipeline::load)",
            },
        });
    }
    Ok(())
}

/// `(q, v, a)` of sample `k`; [`identify`] checked that `v` and `a` exist.
pub(crate) fn state(traj: &Trajectory, k: usize) -> (&[f64], &[f64], &[f64]) {
    (traj.q(k), traj.v(k).unwrap_or(&[]), traj.a(k).unwrap_or(&[]))
}

/// The model's own parameters in the parameterisation of `mode`.
fn nominal(model: &Model, mode: Mode) -> Vec<f64> {
    match mode {
        Mode::Standard => model.standard_params(),
        Mode::Principal | Mode::Mim => dyngen_model::principal_params(model),
    }
}

/// The joint torques that the identified model `prediction` (from a parameter JSON,
/// [`ParameterReport::prediction`]) predicts for every sample of `trajectory`.
pub fn predict_with(
    prediction: &PredictionModel,
    dynamics: &dyn Dynamics,
    trajectory: &Trajectory,
) -> Result<Vec<Vec<f64>>, PipelineError> {
    let n = dynamics.nv();
    if trajectory.dof() != n {
        return Err(PipelineError::DofMismatch {
            expected: n,
            found: trajectory.dof(),
        });
    }
    let regressor = match (prediction.regressor, prediction.coulomb) {
        (Parameterisation::Standard, None) => TorqueRegressor::Standard,
        (Parameterisation::Principal, None) => TorqueRegressor::Principal,
        (Parameterisation::StandardAndJoints, Some(c)) => {
            TorqueRegressor::StandardAndJoints(recorded_joint_model(prediction, c, n)?)
        }
        (r, c) => {
            return Err(PipelineError::InvalidOption {
                option: "prediction",
                reason: format!("a {r:?} regressor with Coulomb model {c:?} is not a model dyngen predicts with"),
            })
        }
    };
    if prediction.epsilons.is_some() && !matches!(regressor, TorqueRegressor::StandardAndJoints(..)) {
        return Err(PipelineError::InvalidOption {
            option: "prediction",
            reason: "Coulomb smoothings per joint need the standard_and_joints regressor".into(),
        });
    }
    let p = regressor.columns(dynamics.model());
    if prediction.solution.len() != p {
        return Err(PipelineError::InvalidOption {
            option: "prediction",
            reason: format!(
                "the solution has {} entries; this robot's {:?} regressor has {p} columns (another robot?)",
                prediction.solution.len(),
                prediction.regressor
            ),
        });
    }
    if let Some(k) = prediction.solution.iter().position(|x| !x.is_finite()) {
        return Err(PipelineError::InvalidOption {
            option: "prediction",
            reason: format!("entry {k} of the solution is not finite"),
        });
    }
    if !prediction.extras.is_empty()
        && (!matches!(regressor, TorqueRegressor::StandardAndJoints(..)) || prediction.stribeck.is_some())
    {
        return Err(PipelineError::InvalidOption {
            option: "prediction",
            reason: "extra joint terms need the standard_and_joints regressor without Stribeck terms".into(),
        });
    }
    let stribeck = match (&prediction.stribeck, &regressor) {
        (None, _) => None,
        (Some(s), TorqueRegressor::StandardAndJoints(m)) => {
            let coulomb = m.coulomb;
            crate::stribeck::check(s, n).map_err(|e| PipelineError::InvalidOption {
                option: "prediction",
                reason: format!("stribeck: {e}"),
            })?;
            Some((s, coulomb))
        }
        (Some(_), _) => {
            return Err(PipelineError::InvalidOption {
                option: "prediction",
                reason: "Stribeck terms need the standard_and_joints regressor".into(),
            })
        }
    };
    need_derivatives(trajectory)?;
    let mut y = vec![0.0; n * p];
    Ok((0..trajectory.len())
        .map(|k| {
            let (q, v, a) = state(trajectory, k);
            let mut tau = regressor.predict(dynamics, q, v, a, &prediction.solution, &mut y);
            if let Some((s, coulomb)) = stribeck {
                crate::stribeck::add_excess(&mut tau, v, &prediction.solution[dynamics.nparams()..], s, coulomb);
            }
            tau
        })
        .collect())
}

/// The joint model a parameters file records for the `standard_and_joints`
/// regressor (`coulomb`, and the ε per joint, extra terms and gear ratios of
/// `prediction`), checked against `n` joints.
fn recorded_joint_model(
    prediction: &PredictionModel,
    coulomb: CoulombReport,
    n: usize,
) -> Result<JointModel, PipelineError> {
    let invalid = |reason: String| PipelineError::InvalidOption {
        option: "prediction",
        reason,
    };
    let coulomb = match coulomb {
        CoulombReport::Sign => Coulomb::Sign,
        CoulombReport::Tanh { epsilon } if epsilon.is_finite() && epsilon > 0.0 => Coulomb::Smooth { epsilon },
        CoulombReport::Tanh { epsilon } => {
            return Err(invalid(format!(
                "the Coulomb smoothing must be positive, got {epsilon}"
            )))
        }
    };
    let mut model = JointModel::new(coulomb, prediction.extras);
    if let Some(epsilons) = &prediction.epsilons {
        if epsilons.len() != n {
            return Err(invalid(format!(
                "{} Coulomb smoothings ε for {n} joints",
                epsilons.len()
            )));
        }
        if let Some(j) = epsilons.iter().position(|e| !(e.is_finite() && *e > 0.0)) {
            return Err(invalid(format!(
                "joint {}'s Coulomb smoothing must be positive, got {}",
                j + 1,
                epsilons[j]
            )));
        }
        model.epsilons = Some(epsilons.as_slice().into());
    }
    if prediction.extras.motor_harmonics > 0 {
        let ratios = prediction
            .gear_ratios
            .as_deref()
            .filter(|r| r.len() == n && r.iter().all(|x| x.is_finite() && *x != 0.0))
            .ok_or_else(|| invalid(format!("the motor ripple needs {n} finite, non-zero gear ratios")))?;
        model = model.with_gear_ratios(Some(ratios));
    }
    Ok(model)
}

/// An identified parameter against the model's value.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterErrors {
    /// `(name, relative error)`; `None` for a parameter without a value.
    pub relative: Vec<(String, Option<f64>)>,
    /// Identified, but zero in the model, so without a relative error.
    pub zero_truth: Vec<String>,
    /// The largest relative error and its parameter.
    pub worst: Option<(f64, String)>,
    /// Parameters with a value and a nonzero true value.
    pub compared: usize,
}

impl Identification {
    /// Parameters per body: 10 standard, or 4 of `θ`.
    pub fn per_body(&self) -> usize {
        match self.mode {
            Mode::Standard => 10,
            Mode::Principal | Mode::Mim => 4,
        }
    }

    /// The model's own parameters in this identification's parameterisation.
    pub fn nominal(&self, model: &Model) -> Vec<f64> {
        nominal(model, self.mode)
    }

    /// The predicted joint torques of every sample of `trajectory`.
    pub fn predict(&self, dynamics: &dyn Dynamics, trajectory: &Trajectory) -> Result<Vec<Vec<f64>>, PipelineError> {
        let n = dynamics.nv();
        if trajectory.dof() != n {
            return Err(PipelineError::DofMismatch {
                expected: n,
                found: trajectory.dof(),
            });
        }
        let mut tau = vec![0.0; n];
        Ok((0..trajectory.len())
            .map(|k| {
                let (q, v, a) = state(trajectory, k);
                match &self.prediction {
                    Prediction::Regressor(estimate) => {
                        let mut tau = estimate.predict(dynamics, q, v, a);
                        if let Some(fit) = &self.stribeck {
                            let joints = &estimate.estimate.solution[dynamics.nparams()..];
                            crate::stribeck::add_excess(&mut tau, v, joints, &fit.joints, fit.coulomb);
                        }
                        tau
                    }
                    Prediction::Parameters(params) => {
                        dynamics.rnea(q, v, a, params, &mut tau);
                        tau.clone()
                    }
                }
            })
            .collect())
    }

    /// Every parameter's error against the model's value (relative errors only for
    /// a nonzero true value; non-finite ones are left out).
    pub fn errors(&self, model: &Model) -> ParameterErrors {
        let truth = self.nominal(model);
        let mut out = ParameterErrors {
            relative: Vec::new(),
            zero_truth: Vec::new(),
            worst: None,
            compared: 0,
        };
        for (p, &x) in self.report.parameters.iter().zip(&truth) {
            match p.value {
                None => out.relative.push((p.name.clone(), None)),
                Some(_) if x.abs() < 1e-12 => out.zero_truth.push(p.name.clone()),
                Some(v) => {
                    let rel = (v - x) / x;
                    if !rel.is_finite() {
                        continue;
                    }
                    out.compared += 1;
                    if out.worst.as_ref().is_none_or(|(w, _)| rel.abs() > *w) {
                        out.worst = Some((rel.abs(), p.name.clone()));
                    }
                    out.relative.push((p.name.clone(), Some(rel)));
                }
            }
        }
        out
    }

    /// Body `body`'s identified inertial, or why it has none: all of its parameters
    /// (10 standard, or θ with the model's centre of mass and principal axes)
    /// identified, and the result physically valid.
    pub fn inertial(&self, model: &Model, body: usize) -> Result<Inertial, String> {
        let k = self.per_body();
        let params = self
            .report
            .parameters
            .get(k * body..k * (body + 1))
            .ok_or_else(|| format!("no body {body}"))?;
        // A value not out of its noise is still the data's best estimate of a
        // parameter that is identifiable: a body with one is written.
        let missing = params
            .iter()
            .filter(|p| !matches!(p.status, ParamStatus::Identified | ParamStatus::NotSignificant) || p.value.is_none())
            .count();
        if missing > 0 {
            return Err(format!("{missing} of its {k} parameters not identified"));
        }
        let values: Vec<f64> = params
            .iter()
            .map(|p| p.value.ok_or("a parameter has no value"))
            .collect::<Result<_, _>>()?;
        let mut x = [0.0; 10];
        if k == 10 {
            x.copy_from_slice(&values);
        } else {
            // θ of this body, the model's θ elsewhere (only this body's 10 are used).
            let mut theta = dyngen_model::principal_params(model);
            theta[4 * body..4 * body + 4].copy_from_slice(&values);
            let standard = principal_params_to_standard(model, &theta);
            x.copy_from_slice(&standard[10 * body..10 * body + 10]);
        }
        let inertial = Inertial::from_standard_params(&x).ok_or("identified mass is not positive")?;
        dyngen_model::desc::check_inertial(&inertial).map_err(|e| match e {
            ErrorKind::NonPositiveMass(m) => format!("identified mass {m} is not positive"),
            ErrorKind::NotPositiveDefinite(ev) => {
                format!("identified inertia about the centre of mass is not positive definite (moments {ev:?})")
            }
            ErrorKind::TriangleInequality(ev) => {
                format!("identified principal moments {ev:?} violate the triangle inequality")
            }
            e => format!("identified inertial is not physical ({e:?})"),
        })?;
        Ok(inertial)
    }

    /// The URDF text `urdf` (the model's source) with the inertials of the fully
    /// identified, physically valid bodies replaced; every other byte is kept.
    pub fn rewrite_urdf(&self, urdf: &str, model: &Model, merged: MergedLinks) -> Result<UrdfRewrite, PipelineError> {
        let mut updated: Vec<(String, Inertial)> = Vec::new();
        let mut kept: Vec<(String, String)> = Vec::new();
        for (i, body) in model.bodies.iter().enumerate() {
            match self.inertial(model, i) {
                Ok(inertial) => {
                    if !body.merged.is_empty() && merged == MergedLinks::Refuse {
                        return Err(PipelineError::MergedLinks {
                            body: body.name.clone(),
                            merged: body.merged.clone(),
                        });
                    }
                    updated.push((body.name.clone(), inertial));
                }
                Err(why) => kept.push((body.name.clone(), why)),
            }
        }
        let text = report::rewrite_urdf_inertials_with(urdf, &updated, merged).map_err(PipelineError::Report)?;
        // With friction identified, each joint's viscous and Coulomb friction go to
        // its <dynamics> when both have a value and neither is negative (a value
        // shaped by the consistency bounds is a value).
        let (mut dynamics, mut dynamics_kept) = (Vec::new(), Vec::new());
        if self.report.parameterisation == Parameterisation::StandardAndJoints {
            let bodies = model.dof();
            for (j, joint) in model.own_joints().enumerate() {
                let value = |m: usize| {
                    let p = self.report.parameters.get(10 * bodies + 4 * j + m)?;
                    matches!(
                        p.status,
                        ParamStatus::Identified | ParamStatus::NotSignificant | ParamStatus::Constrained
                    )
                    .then_some(p.value)
                    .flatten()
                };
                match (value(1), value(2)) {
                    (Some(fv), Some(fc)) if fv >= 0.0 && fc >= 0.0 => dynamics.push((joint.name.clone(), fv, fc)),
                    (Some(fv), Some(fc)) => dynamics_kept.push((
                        joint.name.clone(),
                        format!("identified Fv {fv:.4}, Fc {fc:.4}: negative"),
                    )),
                    _ if self.report.parameters.get(10 * bodies + 4 * j + 1).map(|p| p.status)
                        == Some(ParamStatus::Excluded) =>
                    {
                        dynamics_kept.push((joint.name.clone(), "friction left out of the model".into()))
                    }
                    _ => dynamics_kept.push((joint.name.clone(), "friction not identified alone".into())),
                }
            }
        }
        let text = report::rewrite_urdf_dynamics(&text, &dynamics).map_err(PipelineError::Report)?;
        Ok(UrdfRewrite {
            text,
            updated,
            kept,
            dynamics,
            dynamics_kept,
        })
    }
}

impl Identification {
    /// Every identified joint term per joint ([`JointParamsFile`]): `Ia, Fv, Fc, F0`
    /// and with Stribeck friction `Fs, vs`, as the parameter report has them.
    /// `urdf`: the file name of the URDF it accompanies; `in_urdf`: the joints whose
    /// `Fv` and `Fc` were written there ([`UrdfRewrite::dynamics`]). `None` without
    /// joint terms.
    pub fn joint_params_file(&self, model: &Model, urdf: Option<&str>, in_urdf: &[&str]) -> Option<JointParamsFile> {
        let prediction = self.report.prediction.as_ref()?;
        if self.report.parameterisation != Parameterisation::StandardAndJoints {
            return None;
        }
        let coulomb = prediction.coulomb?;
        let (rigid, n) = (10 * model.dof(), model.nv());
        let params = &self.report.parameters;
        let stribeck = self.stribeck.is_some() && params.len() >= rigid + 6 * n;
        let extras = prediction.extras.per_joint();
        let joints = model
            .own_joints()
            .enumerate()
            .map(|(j, joint)| {
                let mut parameters: Vec<ParamReport> =
                    params[rigid + PER_JOINT * j..rigid + PER_JOINT * (j + 1)].to_vec();
                if stribeck {
                    let at = rigid + PER_JOINT * n + 2 * j;
                    parameters.extend_from_slice(&params[at..at + 2]);
                }
                let at = rigid + PER_JOINT * n + extras * j;
                parameters.extend_from_slice(&params[at..at + extras]);
                JointParams {
                    name: joint.name.clone(),
                    in_urdf: in_urdf.contains(&joint.name.as_str()),
                    parameters,
                    epsilon: prediction.epsilons.as_ref().map(|e| e[j]),
                }
            })
            .collect();
        Some(JointParamsFile {
            schema: JOINT_PARAMS_SCHEMA.to_string(),
            robot: model.name.clone(),
            urdf: urdf.map(str::to_string),
            coulomb,
            joints,
        })
    }
}

/// A URDF with identified inertials.
#[derive(Clone, Debug)]
pub struct UrdfRewrite {
    /// The new URDF text.
    pub text: String,
    /// The bodies written, with their identified inertials.
    pub updated: Vec<(String, Inertial)>,
    /// The bodies that keep their inertials, and why.
    pub kept: Vec<(String, String)>,
    /// The joints whose `<dynamics damping friction>` were written, with `Fv`, `Fc`.
    pub dynamics: Vec<(String, f64, f64)>,
    /// The joints whose `<dynamics>` were kept, and why.
    pub dynamics_kept: Vec<(String, String)>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::Experiment;
    use std::sync::OnceLock;

    fn ur5() -> &'static Model {
        static MODEL: OnceLock<Model> = OnceLock::new();
        MODEL.get_or_init(|| {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../robots/ur5/ur5.urdf");
            dyngen_model::load_urdf(&path).expect("the UR5 URDF loads")
        })
    }

    /// Noise-free UR5 data along the paper's prescribed motion, with joint wrenches.
    fn recording() -> Trajectory {
        let model = ur5();
        let robot = Reference::new(model);
        let experiment = Experiment::paper(model);
        let recording = crate::simulate::record(&robot, &model.standard_params(), &experiment);
        recording
            .to_trajectory()
            .expect("a simulated recording is a valid trajectory")
    }

    fn options(mode: Mode, estimator: Estimator) -> IdentifyOptions {
        IdentifyOptions {
            mode,
            estimator,
            model_is_truth: true,
            ..IdentifyOptions::default()
        }
    }

    #[test]
    fn a_simulated_ur5_is_identified_to_its_truth() {
        let model = ur5();
        let robot = Reference::new(model);
        let traj = recording();
        for estimator in [
            Estimator::Ols,
            Estimator::Wls,
            Estimator::Tls { column_scaling: true },
            Estimator::Tls { column_scaling: false },
            Estimator::Ridge { lambda: 1e-6 },
        ] {
            let id = identify(&robot, &traj, &options(Mode::Standard, estimator)).unwrap();
            let errors = id.errors(model);
            let (worst, name) = errors.worst.clone().unwrap_or((0.0, String::new()));
            assert!(worst < 1e-6, "{estimator:?}: {name} off by {worst:e}");
            // Joint torques never determine every standard parameter; ridge fills in
            // the rest from the prior.
            let without_value = errors.relative.iter().any(|(_, e)| e.is_none());
            assert_eq!(
                without_value,
                !matches!(estimator, Estimator::Ridge { .. }),
                "{estimator:?}"
            );
            let predicted = id.predict(&robot, &traj).unwrap();
            for (k, tau) in predicted.iter().enumerate() {
                for (p, m) in tau.iter().zip(traj.tau(k)) {
                    assert!((p - m).abs() < 1e-6 * (1.0 + m.abs()), "sample {k}: {p} vs {m}");
                }
            }
        }
    }

    #[test]
    fn mim_identifies_every_body_and_rewrites_the_urdf() {
        let model = ur5();
        let robot = Reference::new(model);
        let id = identify(&robot, &recording(), &options(Mode::Mim, Estimator::Ols)).unwrap();
        let errors = id.errors(model);
        assert!(errors.worst.as_ref().is_some_and(|(w, _)| *w < 1e-6), "{errors:?}");
        let urdf =
            std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../robots/ur5/ur5.urdf")).unwrap();
        match id.rewrite_urdf(&urdf, model, MergedLinks::Refuse) {
            Ok(rewrite) => assert!(!rewrite.updated.is_empty(), "{:?}", rewrite.kept),
            Err(PipelineError::MergedLinks { body, merged }) => assert!(!merged.is_empty(), "{body}"),
            Err(e) => panic!("{e}"),
        }
        let lumped = id.rewrite_urdf(&urdf, model, MergedLinks::Lump).unwrap();
        assert_eq!(lumped.updated.len() + lumped.kept.len(), model.bodies.len());
        assert_ne!(lumped.text, urdf);
    }

    #[test]
    fn principal_mode_reports_theta_names() {
        let model = ur5();
        let robot = Reference::new(model);
        let id = identify(
            &robot,
            &recording(),
            &options(Mode::Principal, Estimator::Tls { column_scaling: true }),
        )
        .unwrap();
        assert_eq!(id.report.parameters.len(), 4 * model.dof());
        assert_eq!(id.report.parameters[1].name, "J1_1");
        assert_eq!(id.per_body(), 4);
    }

    #[test]
    fn non_physical_joint_terms_are_named() {
        // Per joint [Ia, Fv, Fc, F0]: joint 1 physical (F0 < 0 is fine), joint 2 with
        // a negative Fv, joint 3 with every term negative but Fc unreported.
        let values = [
            Some(0.1),
            Some(2.0),
            Some(0.0),
            Some(-3.0),
            Some(0.2),
            Some(-1e-3),
            Some(4.0),
            Some(1.0),
            Some(-0.5),
            Some(-2.0),
            None,
            Some(-1.0),
        ];
        let flagged = nonphysical_joint_terms(&values, ExtraTerms::NONE, &[], &["a", "b"]);
        let got: Vec<(&str, &str, f64)> = flagged
            .iter()
            .map(|p| (p.joint.as_str(), p.parameter.as_str(), p.value))
            .collect();
        assert_eq!(
            got,
            [("b", "Fv2", -1e-3), ("joint 3", "Ia3", -0.5), ("joint 3", "Fv3", -2.0)]
        );
        assert!(flagged[0].reason.contains("viscous"), "{:?}", flagged[0]);
        assert!(flagged[1].reason.contains("rotor inertia"), "{:?}", flagged[1]);
        assert!(nonphysical_joint_terms(&[Some(0.0); 8], ExtraTerms::NONE, &[], &[]).is_empty());
        // The extra terms: |Fva| above Fv, and a negative Fcl; ripple of any sign.
        let extras: ExtraTerms = "asymmetric,ripple=1,load".parse().unwrap();
        let joint_terms = [
            Some(0.1),
            Some(2.0),
            Some(1.0),
            None,
            Some(0.1),
            Some(0.5),
            Some(1.0),
            None,
        ];
        let extra = |fva: f64, fcl: f64| [Some(fva), Some(-3.0), Some(3.0), Some(-1.0), Some(1.0), Some(fcl)];
        let extra_values: Vec<Option<f64>> = [extra(-1.5, 0.02), extra(0.6, -0.01)].concat();
        let flagged = nonphysical_joint_terms(&joint_terms, extras, &extra_values, &["a", "b"]);
        let got: Vec<(&str, f64)> = flagged.iter().map(|p| (p.parameter.as_str(), p.value)).collect();
        assert_eq!(got, [("Fva2", 0.6), ("Fcl2", -0.01)]);
        assert!(flagged[0].reason.contains("Fv ± Fva"), "{:?}", flagged[0]);
    }

    #[test]
    fn invalid_options_are_refused() {
        let bad = [
            IdentifyOptions {
                cutoff_hz: -1.0,
                ..IdentifyOptions::default()
            },
            options(Mode::Standard, Estimator::Ridge { lambda: f64::NAN }),
            options(Mode::Mim, Estimator::Wls),
            IdentifyOptions {
                mode: Mode::Mim,
                accumulation: Accumulation::NormalEquations,
                ..IdentifyOptions::default()
            },
        ];
        for o in bad {
            assert!(matches!(o.check(), Err(PipelineError::InvalidOption { .. })), "{o:?}");
        }
    }

    #[test]
    fn data_errors_name_the_file_and_line() {
        let dir = std::env::temp_dir().join(format!("dyngen-pipeline-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let csv = dir.join("bad.csv");
        std::fs::write(&csv, "t,q1,tau1\n0,0,0\n0.1,x,0\n0.2,0,0\n").unwrap();
        let err = load(&csv, &Recipe::default(), 1, &IdentifyOptions::default()).unwrap_err();
        assert!(matches!(err, PipelineError::Data { .. }));
        let text = err.to_string();
        assert!(text.contains("bad.csv") && text.contains("line 3"), "{text}");
        let missing = load(
            &dir.join("nope.csv"),
            &Recipe::default(),
            1,
            &IdentifyOptions::default(),
        )
        .unwrap_err();
        assert!(missing.to_string().contains("nope.csv"), "{missing}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn mismatched_or_incomplete_recordings_are_refused() {
        let model = ur5();
        let robot = Reference::new(model);
        let traj = recording();
        // Another robot's recording.
        let pendulum = dyngen_model::parse_urdf(
            r#"<robot name="p"><link name="b"/><link name="l"><inertial><mass value="1"/>
            <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
            <joint name="j" type="continuous"><parent link="b"/><child link="l"/><axis xyz="0 0 1"/></joint></robot>"#,
        )
        .unwrap();
        let one = Reference::new(&pendulum);
        assert!(matches!(
            identify(&one, &traj, &IdentifyOptions::default()),
            Err(PipelineError::DofMismatch { expected: 1, found: 6 })
        ));
        // MIM without the joint wrenches.
        let torques_only = Trajectory::new(6, traj.t().to_vec(), traj.positions().to_vec(), traj.torques().to_vec())
            .and_then(|t| t.with_velocities(traj.velocities().unwrap_or_default().to_vec()))
            .and_then(|t| t.with_accelerations(traj.accelerations().unwrap_or_default().to_vec()))
            .unwrap();
        assert!(matches!(
            identify(&robot, &torques_only, &options(Mode::Mim, Estimator::Ols)),
            Err(PipelineError::MissingWrenches { dof: 6 })
        ));
    }

    #[test]
    fn estimator_failures_are_typed() {
        // Held still without gravity, the robot's torques say nothing about its inertia.
        let mut model = ur5().clone();
        model.gravity = [0.0; 3];
        let robot = Reference::new(&model);
        let zeros = |len| vec![0.0; len];
        let still = Trajectory::new(6, vec![0.0, 0.1, 0.2], zeros(18), zeros(18))
            .and_then(|t| t.with_velocities(zeros(18)))
            .and_then(|t| t.with_accelerations(zeros(18)))
            .unwrap();
        let err = identify(&robot, &still, &IdentifyOptions::default()).unwrap_err();
        assert!(
            matches!(
                err,
                PipelineError::Identify {
                    error: IdentifyError::RankZero { .. },
                    ..
                }
            ),
            "{err:?}"
        );
        // Without velocities and accelerations there is no regressor.
        let positions_only = Trajectory::new(6, vec![0.0, 0.1, 0.2], zeros(18), zeros(18)).unwrap();
        let err = identify(&robot, &positions_only, &IdentifyOptions::default()).unwrap_err();
        assert!(matches!(err, PipelineError::Data { path: None, .. }), "{err:?}");
    }

    #[test]
    fn an_overflowing_input_is_named_not_a_nan_estimate() {
        let model = ur5();
        let robot = Reference::new(model);
        let traj = recording();
        let mut tau = traj.torques().to_vec();
        tau[6 * 17 + 2] = 1e300;
        let huge = traj.with_torques(tau).unwrap();
        let err = identify(&robot, &huge, &options(Mode::Standard, Estimator::Ols)).unwrap_err();
        let PipelineError::NonFiniteEstimate { largest } = &err else {
            panic!("{err:?}");
        };
        assert_eq!(*largest, Some((1e300, Location::Sample(17), "torque")));
        assert!(
            err.to_string().contains("the largest is the torque 1e300 at sample 17"),
            "{err}"
        );
    }
}
