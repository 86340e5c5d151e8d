//! The joint model chosen by the data: each candidate (rigid bodies alone; friction
//! with and without rotor inertia; the Coulomb smoothing fitted; Stribeck) is fitted
//! on all but one of [`BLOCKS`] contiguous time blocks of the recording and predicts
//! the block left out, every block in turn. The candidate with the lowest error on
//! the held-out blocks wins, a more complex one only where it lowers the error of
//! the simpler by [`MIN_GAIN`]: a model that only fits the noise of its own data
//! does not. The choice is never worse than sign friction on the held-out blocks:
//! where a simpler model within the margin would be, sign friction is chosen (but
//! for one that predicts to rounding, [`EXACT`]).
//!
//! Then the extra joint terms ([`crate::extras`]) are added to the best linear
//! friction model (sign, with or without rotor inertia, or the fitted smoothing)
//! one at a time, forward selection: each round tries every term not yet in
//! (direction-dependent viscous friction, one more ripple harmonic of the joint
//! angle, one more of the motor angle where the gear ratios are given,
//! load-dependent friction) and keeps the one that lowers the held-out error most,
//! if it lowers it by at least [`MIN_GAIN`]. With the fitted smoothing, its `ε` stay
//! those chosen without the extra terms.
//!
//! Every candidate is scored from one pass of one wide regressor over the sampled
//! recording (module `blocks`): a fit on three blocks and its error on the fourth come
//! from the blocks' Gram matrices, so the choice costs a regressor pass and a few
//! hundred small factorisations, not a fit per candidate and block. Candidates are
//! scored by least squares (the identification that follows uses the estimator
//! asked for). `auto`'s `ε` per joint and the Stribeck velocity per joint are
//! chosen on the held-out blocks too, each from a grid ([`EPSILON_GRID`] values;
//! [`VS_GRID`] values over the range of [`crate::stribeck::velocity_range`]); the
//! identification that follows takes `auto`'s `ε` from the choice, and fits
//! Stribeck's by nonlinear least squares.

mod blocks;

use crate::accumulate::in_parallel;
use crate::data::Trajectory;
use crate::extras::ExtraTerms;
use crate::friction::EPSILON_RANGE;
use crate::mim::{JointModel, TorqueRegressor};
use crate::pipeline::{IdentifyOptions, JointTerms, Mode, PipelineError, LOAD_CHANGE, LOAD_ROUNDS};
use crate::validate::Validation;
use blocks::{Blocks, Folds, JointColumn, Solution};
use dyngen_model::joint_params::{Coulomb, PER_JOINT};
use dyngen_reference::Dynamics;
use std::fmt;

/// Time blocks of the cross-validation.
pub const BLOCKS: usize = 4;

/// The fewest samples the choice takes: 2 per block.
pub const MIN_SAMPLES: usize = 2 * BLOCKS;

/// The choice is made on at most this many samples, spread evenly over the
/// recording (the identification that follows uses all of them).
pub const CHOICE_SAMPLES: usize = 10_000;

/// At most this many numbers of the wide regressor's rows are held (16 M: 128 MB);
/// fewer samples are taken where they would pass it.
const CHOICE_VALUES: usize = 1 << 24;

/// A held-out error below this is exact for any purpose: no model replaces one
/// that predicts so well (on noise-free data every candidate's error is rounding
/// and the ridge's bias, and which is lowest means nothing).
pub const EXACT: f64 = 1e-6;

/// Values of `auto`'s `ε` tried per joint, evenly spaced in `log ε` over
/// [`EPSILON_RANGE`] (neighbours 27 % apart).
pub const EPSILON_GRID: usize = 25;

/// Values of the Stribeck velocity tried per joint, evenly spaced in `log vs` over
/// the joint's range ([`crate::stribeck::velocity_range`]).
pub const VS_GRID: usize = 16;

/// Sweeps over the joints of the per-joint searches.
const SWEEPS: usize = 2;

/// The relative drop of the held-out error an extra term must bring to be kept, and
/// a friction model to be chosen over a simpler one.
pub const MIN_GAIN: f64 = 0.01;

/// The extra terms `--friction best` tries when none are given: direction-dependent
/// viscous friction, up to two ripple harmonics, load-dependent friction.
pub const DEFAULT_EXTRAS: ExtraTerms = ExtraTerms {
    asymmetric: true,
    harmonics: 2,
    motor_harmonics: 0,
    load: true,
};

/// One joint model the choice tries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// The friction model as the command line calls it (`--friction NAME`, with
    /// `--rotor-inertia no` for `sign-no-rotor-inertia`).
    pub name: &'static str,
    pub joints: JointTerms,
    pub rotor_inertia: Option<bool>,
    /// The extra terms on top (`--extra-terms`).
    pub extras: ExtraTerms,
}

impl Candidate {
    /// `base` with this joint model.
    pub fn options(&self, base: &IdentifyOptions) -> IdentifyOptions {
        IdentifyOptions {
            joints: self.joints,
            rotor_inertia: self.rotor_inertia,
            extras: self.extras,
            ..base.clone()
        }
    }

    /// The name and the extra terms: `auto + asymmetric,load`.
    pub fn label(&self) -> String {
        if self.extras.is_empty() {
            self.name.to_string()
        } else {
            format!("{} + {}", self.name, self.extras)
        }
    }

    /// Whether the friction model is linear in its parameters (extra terms can
    /// join it).
    fn linear(&self) -> bool {
        matches!(self.joints, JointTerms::Friction(_) | JointTerms::FrictionAuto)
    }
}

/// The friction models, simplest first (a tie goes to the simpler).
pub const CANDIDATES: [Candidate; 5] = [
    Candidate {
        name: "none",
        joints: JointTerms::None,
        rotor_inertia: None,
        extras: ExtraTerms::NONE,
    },
    Candidate {
        name: "sign-no-rotor-inertia",
        joints: JointTerms::Friction(Coulomb::Sign),
        rotor_inertia: Some(false),
        extras: ExtraTerms::NONE,
    },
    Candidate {
        name: "sign",
        joints: JointTerms::Friction(Coulomb::Sign),
        rotor_inertia: None,
        extras: ExtraTerms::NONE,
    },
    Candidate {
        name: "auto",
        joints: JointTerms::FrictionAuto,
        rotor_inertia: None,
        extras: ExtraTerms::NONE,
    },
    Candidate {
        name: "stribeck",
        joints: JointTerms::Stribeck(Coulomb::Sign),
        rotor_inertia: None,
        extras: ExtraTerms::NONE,
    },
];

/// A candidate's score: its held-out errors, or why it could not be fitted.
#[derive(Clone, Debug)]
pub struct Score {
    pub candidate: Candidate,
    /// The held-out blocks' measured against predicted torques, pooled.
    pub held_out: Result<Validation, String>,
}

/// The outcome: every candidate's score and the one chosen.
#[derive(Clone, Debug)]
pub struct ModelChoice {
    /// The friction models first ([`CANDIDATES`]), then the extra terms' trials in
    /// the order they were tried.
    pub scores: Vec<Score>,
    /// Index into `scores`.
    pub chosen: usize,
    /// `auto`'s Coulomb smoothing `ε` per joint, chosen on the held-out blocks.
    pub epsilons: Option<Vec<f64>>,
}

impl ModelChoice {
    /// `options` with the chosen joint model (with `auto`, the `ε` chosen).
    pub fn apply(&self, options: &IdentifyOptions) -> IdentifyOptions {
        let mut options = self.chosen().options(options);
        if options.joints == JointTerms::FrictionAuto {
            options.epsilons = self.epsilons.clone();
        }
        options
    }

    pub fn chosen(&self) -> &Candidate {
        &self.scores[self.chosen].candidate
    }

    /// The held-out error of the candidate labelled `label`, if it was fitted.
    pub fn error(&self, label: &str) -> Option<f64> {
        let score = self.scores.iter().find(|s| s.candidate.label() == label)?;
        score.held_out.as_ref().ok().map(|v| v.overall)
    }
}

impl fmt::Display for ModelChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "joint model chosen by the error on held-out data ({BLOCKS} time blocks, each predicted by the fit on \
             the others; a more complex model or an extra term where it lowers the error by {:.0} %):",
            100.0 * MIN_GAIN
        )?;
        for (i, s) in self.scores.iter().enumerate() {
            let mark = if i == self.chosen { "  <- chosen" } else { "" };
            let label = s.candidate.label();
            match &s.held_out {
                Ok(v) => writeln!(f, "  {label:<34} {:>7.3} %{mark}", 100.0 * v.overall)?,
                Err(e) => writeln!(f, "  {label:<34} not fitted: {e}")?,
            }
        }
        if let Some(e) = &self.epsilons {
            let list: Vec<String> = e.iter().map(|e| format!("{e:.3e}")).collect();
            writeln!(
                f,
                "  (auto's ε per joint, chosen on the held-out blocks: {})",
                list.join(", ")
            )?;
        }
        Ok(())
    }
}

/// Scores every candidate on `traj` with the rest of `options` (standard mode;
/// its joint model is ignored) and chooses the one with the lowest held-out error,
/// then adds those of the extra terms `allowed` ([`DEFAULT_EXTRAS`], say) that the
/// held-out blocks support, as the module says. Errors: another mode, motor ripple
/// without gear ratios, too few samples for the blocks, a non-finite regressor row,
/// or no candidate that could be fitted.
pub fn choose(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    options: &IdentifyOptions,
    allowed: ExtraTerms,
) -> Result<ModelChoice, PipelineError> {
    let invalid = |option, reason: String| PipelineError::InvalidOption { option, reason };
    if options.mode != Mode::Standard {
        return Err(invalid(
            "friction",
            "chooses the joint model of the standard mode".into(),
        ));
    }
    let (model, n) = (dynamics.model(), dynamics.nv());
    if traj.dof() != n {
        return Err(PipelineError::DofMismatch {
            expected: n,
            found: traj.dof(),
        });
    }
    if traj.velocities().is_none() || traj.accelerations().is_none() {
        return Err(invalid(
            "friction",
            "chooses the joint model from velocities and accelerations; load the recording through the \
             pipeline, which estimates them"
                .into(),
        ));
    }
    if allowed.motor_harmonics > 0 && options.gear_ratios.as_ref().is_none_or(|r| r.len() != n) {
        return Err(invalid(
            "extra-terms",
            format!("motor-ripple needs each joint's gear ratio (--gear-ratios, {n} values)"),
        ));
    }
    // Harmonics are of a joint's one angle: none on a robot with ball or free joints.
    let allowed = if model.nq() == model.nv() {
        allowed
    } else {
        ExtraTerms {
            harmonics: 0,
            motor_harmonics: 0,
            ..allowed
        }
    };
    // The wide regressor: sign friction and every extra term but the load's, which
    // each fold fills from its own rigid-body parameters.
    let wide_terms = ExtraTerms { load: false, ..allowed };
    let gears = options.gear_ratios.as_deref();
    let (blocks, data, scoring) = sampled(dynamics, traj, options, wide_terms)?;
    let layout = scoring.layout;
    let mut scores: Vec<Score> = CANDIDATES[..3]
        .iter()
        .map(|&candidate| Score {
            candidate,
            held_out: scoring.plain(&data, &layout.columns(&candidate, true)),
        })
        .collect();
    let (auto, epsilons) = match scoring.auto(&data, &CANDIDATES[3]) {
        Ok((v, e)) => (Ok(v), Some(e)),
        Err(e) => (Err(e), None),
    };
    scores.push(Score {
        candidate: CANDIDATES[3],
        held_out: auto,
    });
    scores.push(Score {
        candidate: CANDIDATES[4],
        held_out: scoring.stribeck(&data),
    });
    // The lowest error among the scores `among`; a later (more complex) one must be
    // lower by the fraction `margin`, and nothing replaces a model that predicts to
    // rounding (EXACT).
    let best = |scores: &[Score], among: &dyn Fn(&Candidate) -> bool, margin: f64| {
        scores
            .iter()
            .enumerate()
            .filter(|(_, s)| among(&s.candidate))
            .filter_map(|(i, s)| s.held_out.as_ref().ok().map(|v| (i, v.overall)))
            .fold(None, |best: Option<(usize, f64)>, (i, e)| match best {
                Some((_, b)) if e > (1.0 - margin) * b || b < EXACT => best,
                _ => Some((i, e)),
            })
    };
    let Some((overall, overall_error)) = best(&scores, &|_| true, MIN_GAIN) else {
        return Err(invalid(
            "friction",
            format!(
                "no joint model could be fitted on the time blocks: {}",
                scores
                    .iter()
                    .filter_map(|s| s
                        .held_out
                        .as_ref()
                        .err()
                        .map(|e| format!("{}: {e}", s.candidate.label())))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        ));
    };
    // Forward selection of the extra terms on the best linear friction model.
    let mut chosen = overall;
    if let Some((start, mut error)) = best(&scores, &|c| c.linear(), MIN_GAIN) {
        let friction = scores[start].candidate;
        // With `auto`, the rows again with its ε (the harmonics' Coulomb columns
        // and the load's carry the smoothing).
        let smoothed;
        let (data, coulomb) = match (&epsilons, friction.joints) {
            (Some(e), JointTerms::FrictionAuto) => {
                let regressor =
                    TorqueRegressor::StandardAndJoints(JointModel::per_joint(e, wide_terms).with_gear_ratios(gears));
                smoothed = Blocks::new(dynamics, traj, &blocks, &regressor, options.exclude_below)?;
                let coulomb: Vec<Coulomb> = e.iter().map(|&epsilon| Coulomb::Smooth { epsilon }).collect();
                (&smoothed, coulomb)
            }
            _ => (&data, vec![Coulomb::Sign; n]),
        };
        let mut current = ExtraTerms::NONE;
        let mut kept = start;
        loop {
            let trials: Vec<ExtraTerms> = [
                (allowed.asymmetric && !current.asymmetric).then_some(ExtraTerms {
                    asymmetric: true,
                    ..current
                }),
                (current.harmonics < allowed.harmonics).then_some(ExtraTerms {
                    harmonics: current.harmonics + 1,
                    ..current
                }),
                (current.motor_harmonics < allowed.motor_harmonics).then_some(ExtraTerms {
                    motor_harmonics: current.motor_harmonics + 1,
                    ..current
                }),
                (allowed.load && !current.load).then_some(ExtraTerms { load: true, ..current }),
            ]
            .into_iter()
            .flatten()
            .collect();
            if trials.is_empty() {
                break;
            }
            let first = scores.len();
            for &extras in &trials {
                let candidate = Candidate { extras, ..friction };
                let columns = layout.columns(&candidate, true);
                let held_out = if extras.load {
                    scoring.with_load(data, &columns, &coulomb)
                } else {
                    scoring.plain(data, &columns)
                };
                scores.push(Score { candidate, held_out });
            }
            match best(&scores[first..], &|_| true, 0.0) {
                Some((i, e)) if error >= EXACT && e <= (1.0 - MIN_GAIN) * error => {
                    (kept, error, current) = (first + i, e, trials[i]);
                }
                _ => break,
            }
        }
        if error < overall_error && overall_error >= EXACT {
            chosen = kept;
        }
    }
    // Never worse than sign friction on the held-out blocks (a simpler model within
    // the margin of it may be), but for a model that predicts to rounding.
    let error_of = |i: usize| scores[i].held_out.as_ref().map_or(f64::INFINITY, |v| v.overall);
    if let Some(sign) = scores.iter().position(|s| s.candidate == CANDIDATES[2]) {
        if error_of(chosen) > error_of(sign) && error_of(chosen) >= EXACT {
            chosen = sign;
        }
    }
    Ok(ModelChoice {
        scores,
        chosen,
        epsilons,
    })
}

/// `--friction auto`'s Coulomb smoothing `ε` per joint for `options` (their
/// rotor inertia and extra terms), chosen on the held-out blocks as
/// [`choose`] does for its `auto` candidate. Errors: too few samples for the
/// blocks, a non-finite regressor row, or normal equations that cannot be solved.
pub fn epsilons(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    options: &IdentifyOptions,
) -> Result<Vec<f64>, PipelineError> {
    let extras = ExtraTerms {
        load: false,
        ..options.extras
    };
    let (_, data, scoring) = sampled(dynamics, traj, options, extras)?;
    let candidate = Candidate {
        rotor_inertia: options.rotor_inertia,
        extras,
        ..CANDIDATES[3]
    };
    scoring
        .auto(&data, &candidate)
        .map(|(_, e)| e)
        .map_err(|reason| PipelineError::InvalidOption {
            option: "friction",
            reason: format!("auto could not choose the Coulomb smoothing: {reason}"),
        })
}

/// The rows of sign friction with the extra terms `wide` at most
/// [`CHOICE_SAMPLES`] samples spread over `traj` (fewer where their rows would
/// pass [`CHOICE_VALUES`] numbers), in [`BLOCKS`] contiguous blocks: the samples
/// of each block, their rows, and the scoring of candidates on them.
fn sampled(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    options: &IdentifyOptions,
    wide: ExtraTerms,
) -> Result<(Vec<Vec<usize>>, Blocks, Scoring), PipelineError> {
    let (model, n) = (dynamics.model(), dynamics.nv());
    let regressor = TorqueRegressor::StandardAndJoints(
        JointModel::new(Coulomb::Sign, wide).with_gear_ratios(options.gear_ratios.as_deref()),
    );
    let p = regressor.columns(model);
    let samples = CHOICE_SAMPLES.min(CHOICE_VALUES / (n * (p + 1)).max(1)).max(1);
    let stride = traj.len().div_ceil(samples).max(1);
    let picked: Vec<usize> = (0..traj.len()).step_by(stride).collect();
    let len = picked.len();
    let blocks: Vec<Vec<usize>> = (0..BLOCKS)
        .map(|b| {
            picked
                .iter()
                .enumerate()
                .filter(|(i, _)| i * BLOCKS / len == b)
                .map(|(_, &k)| k)
                .collect()
        })
        .collect();
    if blocks.iter().any(|b| b.len() < 2) {
        return Err(PipelineError::InvalidOption {
            option: "friction",
            reason: format!("needs at least 2 samples in each of its {BLOCKS} time blocks; the recording has {len}"),
        });
    }
    let data = Blocks::new(dynamics, traj, &blocks, &regressor, options.exclude_below)?;
    let scoring = Scoring {
        names: (1..=n).map(|j| format!("joint {j}")).collect(),
        samples: len,
        layout: Layout {
            rigid: 10 * model.dof(),
            n,
            wide,
        },
    };
    Ok((blocks, data, scoring))
}

/// Where the candidates' columns are in the wide regressor: the rigid bodies' 10
/// per body, every joint's `[Ia, Fv, Fc, F0]`, then every joint's extra terms
/// `wide` (without the load's).
#[derive(Clone, Copy)]
struct Layout {
    rigid: usize,
    n: usize,
    wide: ExtraTerms,
}

impl Layout {
    /// The columns of `candidate` (its Coulomb columns only `with_coulomb`), sorted;
    /// its load term is not a column of the wide regressor.
    fn columns(&self, candidate: &Candidate, with_coulomb: bool) -> Vec<usize> {
        let (rigid, n, wide) = (self.rigid, self.n, self.wide);
        let mut columns: Vec<usize> = (0..rigid).collect();
        if candidate.joints != JointTerms::None {
            let terms = [candidate.rotor_inertia != Some(false), true, with_coulomb, true];
            for j in 0..n {
                columns.extend((0..PER_JOINT).filter(|&k| terms[k]).map(|k| rigid + PER_JOINT * j + k));
            }
        }
        let extras = candidate.extras;
        let first = rigid + PER_JOINT * n;
        let harmonics = usize::from(wide.asymmetric);
        let motor = harmonics + 4 * usize::from(wide.harmonics);
        for j in 0..n {
            let at = first + wide.per_joint() * j;
            if extras.asymmetric {
                columns.push(at);
            }
            columns.extend((0..4 * usize::from(extras.harmonics)).map(|k| at + harmonics + k));
            columns.extend((0..2 * usize::from(extras.motor_harmonics)).map(|k| at + motor + k));
        }
        columns.sort_unstable();
        columns
    }
}

/// A function of a joint's velocity: one column of a grid.
type OfVelocity = Box<dyn Fn(f64) -> f64 + Send + Sync>;

/// What every candidate's score needs besides the rows.
struct Scoring {
    names: Vec<String>,
    samples: usize,
    layout: Layout,
}

impl Scoring {
    /// The held-out errors of the fits `solutions` (one per fold) with each fold's
    /// own joint columns `added(f)`.
    fn validation<'c>(
        &self,
        folds: &Folds<'_>,
        solutions: &[Solution],
        added: &dyn Fn(usize) -> Vec<Option<&'c JointColumn>>,
    ) -> Result<Validation, String> {
        let (err2, tau2) = folds.held_out_sums(solutions, added);
        if err2.iter().chain(&tau2).any(|x| !x.is_finite()) {
            return Err("the held-out errors are not finite (values too large)".into());
        }
        Validation::from_sums(&self.names, self.samples, &err2, &tau2).map_err(|e| e.to_string())
    }

    /// The columns `columns` and nothing else.
    fn plain(&self, data: &Blocks, columns: &[usize]) -> Result<Validation, String> {
        let folds = data.prepare(columns)?;
        let none = vec![None; self.layout.n];
        let solutions = (0..data.blocks())
            .map(|f| folds.solve(f, &none))
            .collect::<Result<Vec<_>, _>>()?;
        self.validation(&folds, &solutions, &|_| none.clone())
    }

    /// One column per joint from a grid each (`grids[j]`, empty for none), each
    /// joint's grid point chosen by the held-out error: every joint at the same
    /// point first where `common` (the grids are then of one length), then each
    /// joint in turn with the others held, [`SWEEPS`] times. A joint's point is
    /// `None` (no column) where no point lowers the error. Returns every joint's
    /// point and the score.
    fn search(
        &self,
        data: &Blocks,
        folds: &Folds<'_>,
        grids: &[Vec<JointColumn>],
        common: bool,
    ) -> Result<(Vec<Option<usize>>, Validation), String> {
        let n = self.layout.n;
        let added = |at: &[Option<usize>]| -> Vec<Option<&JointColumn>> {
            (0..n).map(|j| at[j].map(|e| &grids[j][e])).collect()
        };
        let error = |at: &[Option<usize>]| {
            let columns = added(at);
            folds.error(&|_| columns.clone()).unwrap_or(f64::INFINITY)
        };
        let mut at: Vec<Option<usize>> = vec![None; n];
        let mut best = error(&at);
        if common {
            let points = grids.iter().map(Vec::len).max().unwrap_or(0);
            for e in 0..points {
                let trial: Vec<Option<usize>> = (0..n).map(|j| (e < grids[j].len()).then_some(e)).collect();
                let err = error(&trial);
                if err < best {
                    (at, best) = (trial, err);
                }
            }
        }
        for _ in 0..SWEEPS {
            for j in (0..n).filter(|&j| !grids[j].is_empty()) {
                for e in std::iter::once(None).chain((0..grids[j].len()).map(Some)) {
                    if e == at[j] {
                        continue;
                    }
                    let mut trial = at.clone();
                    trial[j] = e;
                    let err = error(&trial);
                    if err < best {
                        (at, best) = (trial, err);
                    }
                }
            }
        }
        let columns = added(&at);
        let solutions = (0..data.blocks())
            .map(|f| folds.solve(f, &columns))
            .collect::<Result<Vec<_>, _>>()?;
        let validation = self.validation(folds, &solutions, &|_| columns.clone())?;
        Ok((at, validation))
    }

    /// Each joint's columns `functions` of its velocity, the joints spread over
    /// the cores.
    fn grids(&self, data: &Blocks, functions: impl Fn(usize) -> Vec<OfVelocity> + Sync) -> Vec<Vec<JointColumn>> {
        in_parallel(self.layout.n, |j| {
            let functions = functions(j);
            let refs: Vec<&dyn Fn(f64) -> f64> = functions.iter().map(|f| f.as_ref() as &dyn Fn(f64) -> f64).collect();
            data.columns_of_velocity(j, &refs)
        })
    }

    /// `auto`: `candidate`'s columns but the Coulomb ones, which are
    /// `tanh(q̇_j/ε_j)` with each joint's `ε` one of [`EPSILON_GRID`] values.
    /// Returns the score and the `ε`.
    fn auto(&self, data: &Blocks, candidate: &Candidate) -> Result<(Validation, Vec<f64>), String> {
        let folds = data.prepare(&self.layout.columns(candidate, false))?;
        let (lo, hi) = (EPSILON_RANGE.0.ln(), EPSILON_RANGE.1.ln());
        let epsilons: Vec<f64> = (0..EPSILON_GRID)
            .map(|k| (lo + (hi - lo) * k as f64 / (EPSILON_GRID - 1) as f64).exp())
            .collect();
        let grids = self.grids(data, |_| {
            epsilons
                .iter()
                .map(|&e| Box::new(move |v: f64| (v / e).tanh()) as OfVelocity)
                .collect()
        });
        let (at, validation) = self.search(data, &folds, &grids, true)?;
        // A joint whose Coulomb column lowers no error keeps the largest ε (the
        // nearest the model has to none: a second viscous friction).
        Ok((
            validation,
            at.iter().map(|e| epsilons[e.unwrap_or(EPSILON_GRID - 1)]).collect(),
        ))
    }

    /// `stribeck`: sign friction plus per joint `exp(−(q̇/vs)²)·sign(q̇)`, `vs` one
    /// of [`VS_GRID`] values over the joint's range (a joint without a range, or
    /// whose held-out error the term does not lower, has none).
    fn stribeck(&self, data: &Blocks) -> Result<Validation, String> {
        let folds = data.prepare(&self.layout.columns(&CANDIDATES[2], true))?;
        let grids = self.grids(data, |j| {
            let Some((lo, hi)) = crate::stribeck::velocity_range(&data.velocities(j)) else {
                return Vec::new();
            };
            let (lo, hi) = (lo.ln(), hi.ln());
            (0..VS_GRID)
                .map(|k| {
                    let vs = (lo + (hi - lo) * k as f64 / (VS_GRID - 1) as f64).exp();
                    Box::new(move |v: f64| crate::stribeck::stribeck_factor(v, vs) * Coulomb::Sign.eval(v))
                        as OfVelocity
                })
                .collect()
        });
        Ok(self.search(data, &folds, &grids, false)?.1)
    }

    /// `columns` and the load-dependent friction `Fcl_j·|τ_j^rigid|·s_j(q̇_j)`
    /// (`coulomb[j]`): each fold alternates between the load of its rigid-body
    /// parameters and the fit with it, as the identification does, until the load
    /// changes by less than [`LOAD_CHANGE`] (at most [`LOAD_ROUNDS`] rounds).
    fn with_load(&self, data: &Blocks, columns: &[usize], coulomb: &[Coulomb]) -> Result<Validation, String> {
        let folds = data.prepare(columns)?;
        let (n, rigid) = (self.layout.n, self.layout.rigid);
        let none: Vec<Option<&JointColumn>> = vec![None; n];
        // Every row's rigid-body torque, [joint][block][row].
        let loads = |solution: &Solution| -> Vec<Vec<Vec<f64>>> {
            let pi = folds.wide(solution);
            (0..n)
                .map(|j| {
                    (0..data.blocks())
                        .map(|b| data.rows(b, j).times(&pi[..rigid]))
                        .collect()
                })
                .collect()
        };
        let fitted = in_parallel(data.blocks(), |f| -> Result<(Solution, Vec<JointColumn>), String> {
            let mut solution = folds.solve(f, &none)?;
            let mut load = loads(&solution);
            let mut columns: Vec<JointColumn>;
            let mut round = 0;
            loop {
                columns = (0..n)
                    .map(|j| {
                        data.column(j, |b, rows| {
                            load[j][b]
                                .iter()
                                .zip(&rows.v)
                                .map(|(&t, &v)| ExtraTerms::load_entry(t, v, coulomb[j]))
                                .collect()
                        })
                    })
                    .collect();
                solution = folds.solve(f, &columns.iter().map(Some).collect::<Vec<_>>())?;
                round += 1;
                if round == LOAD_ROUNDS {
                    break;
                }
                let next = loads(&solution);
                let flat = |l: &[Vec<Vec<f64>>]| -> Vec<f64> { l.iter().flatten().flatten().copied().collect() };
                let change = crate::dense::relative_change(&flat(&next), &flat(&load));
                load = next;
                if change < LOAD_CHANGE {
                    break;
                }
            }
            Ok((solution, columns))
        })
        .into_iter()
        .collect::<Result<Vec<_>, String>>()?;
        let (solutions, columns): (Vec<Solution>, Vec<Vec<JointColumn>>) = fitted.into_iter().unzip();
        self.validation(&folds, &solutions, &|f| columns[f].iter().map(Some).collect())
    }
}
