//! The joint model chosen by the data: each candidate (rigid bodies alone; friction
//! with and without rotor inertia; the Coulomb smoothing fitted; Stribeck) is fitted
//! on all but one of [`BLOCKS`] contiguous time blocks of the recording and predicts
//! the block left out, every block in turn. The candidate with the lowest error on
//! the held-out blocks wins: a model that only fits the noise of its own data does
//! not. Sign friction is a candidate, so the choice is never worse than it on the
//! held-out blocks.
//!
//! Then the extra joint terms ([`crate::extras`]) are added to the best linear
//! friction model (sign, with or without rotor inertia, or the fitted smoothing)
//! one at a time, forward selection: each round tries every term not yet in
//! (direction-dependent viscous friction, one more ripple harmonic of the joint
//! angle, one more of the motor angle where the gear ratios are given,
//! load-dependent friction) and keeps the one that lowers the held-out error most, if it lowers it
//! by at least [`MIN_GAIN`]. The fitted smoothing's ε are searched again with the
//! extra terms, on the training blocks only.

use crate::accumulate::in_parallel;
use crate::data::Trajectory;
use crate::extras::ExtraTerms;
use crate::pipeline::{self, IdentifyOptions, JointTerms, Mode, PipelineError};
use crate::validate::Validation;
use dyngen_model::joint_params::Coulomb;
use dyngen_reference::Dynamics;
use std::fmt;

/// Time blocks of the cross-validation.
pub const BLOCKS: usize = 4;

/// The choice is made on at most this many samples, spread evenly over the
/// recording (the identification that follows uses all of them).
pub const CHOICE_SAMPLES: usize = 20_000;

/// The relative drop of the held-out error an extra term must bring to be kept.
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
}

impl ModelChoice {
    /// `options` with the chosen joint model.
    pub fn apply(&self, options: &IdentifyOptions) -> IdentifyOptions {
        self.chosen().options(options)
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
             the others; an extra term is kept where it lowers the error by {:.0} %):",
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
        Ok(())
    }
}

/// The training and held-out parts of every block.
type Folds = Vec<(Trajectory, Trajectory)>;

/// Scores every candidate on `traj` with the rest of `options` (standard mode;
/// its joint model is ignored) and chooses the one with the lowest held-out error,
/// then adds those of the extra terms `allowed` ([`DEFAULT_EXTRAS`], say) that the
/// held-out blocks support, as the module says. Errors: another mode, too few
/// samples for the blocks, or no candidate that could be fitted.
pub fn choose(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    options: &IdentifyOptions,
    allowed: ExtraTerms,
) -> Result<ModelChoice, PipelineError> {
    if options.mode != Mode::Standard {
        return Err(PipelineError::InvalidOption {
            option: "friction",
            reason: "chooses the joint model of the standard mode".into(),
        });
    }
    // At most CHOICE_SAMPLES samples, spread over the recording.
    let stride = traj.len().div_ceil(CHOICE_SAMPLES).max(1);
    let sampled;
    let traj = if stride > 1 {
        sampled = traj
            .select(|k| k % stride == 0)
            .map_err(|e| PipelineError::InvalidOption {
                option: "friction",
                reason: e.to_string(),
            })?;
        &sampled
    } else {
        traj
    };
    let len = traj.len();
    let block = |k: usize| k * BLOCKS / len;
    let folds: Folds = (0..BLOCKS)
        .map(|b| {
            let training = traj.select(|k| block(k) != b);
            let held = traj.select(|k| block(k) == b);
            match (training, held) {
                (Ok(t), Ok(h)) => Ok((t, h)),
                _ => Err(PipelineError::InvalidOption {
                    option: "friction",
                    reason: format!(
                        "needs at least 2 samples in each of its {BLOCKS} time blocks; the recording has {len}"
                    ),
                }),
            }
        })
        .collect::<Result<_, _>>()?;
    let base = IdentifyOptions {
        extras: ExtraTerms::NONE,
        ..options.clone()
    };
    let mut scores = score(dynamics, &folds, &CANDIDATES, &base);
    let best = |scores: &[Score], among: &dyn Fn(&Candidate) -> bool| {
        scores
            .iter()
            .enumerate()
            .filter(|(_, s)| among(&s.candidate))
            .filter_map(|(i, s)| s.held_out.as_ref().ok().map(|v| (i, v.overall)))
            .fold(None, |best: Option<(usize, f64)>, (i, e)| match best {
                Some((_, b)) if b <= e => best,
                _ => Some((i, e)),
            })
    };
    let Some((overall, overall_error)) = best(&scores, &|_| true) else {
        return Err(PipelineError::InvalidOption {
            option: "friction",
            reason: format!(
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
        });
    };
    // Forward selection of the extra terms on the best linear friction model.
    let mut chosen = overall;
    if let Some((start, mut error)) = best(&scores, &|c| c.linear()) {
        let friction = scores[start].candidate;
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
            let candidates: Vec<Candidate> = trials.iter().map(|&extras| Candidate { extras, ..friction }).collect();
            let first = scores.len();
            scores.extend(score(dynamics, &folds, &candidates, &base));
            match best(&scores[first..], &|_| true) {
                Some((i, e)) if e <= (1.0 - MIN_GAIN) * error => {
                    (kept, error, current) = (first + i, e, trials[i]);
                }
                _ => break,
            }
        }
        if error < overall_error {
            chosen = kept;
        }
    }
    Ok(ModelChoice { scores, chosen })
}

/// Each candidate's held-out score, the rest of the options `base`'s. Every
/// (candidate, block) fit runs on its own core: the blocks of one candidate
/// alternate between cores, so that the slow candidates are shared.
fn score(dynamics: &dyn Dynamics, folds: &Folds, candidates: &[Candidate], base: &IdentifyOptions) -> Vec<Score> {
    let names: Vec<String> = (1..=dynamics.nv()).map(|j| format!("joint {j}")).collect();
    let predictions = in_parallel(candidates.len() * BLOCKS, |job| {
        let (training, held) = &folds[job % BLOCKS];
        let options = candidates[job / BLOCKS].options(base);
        let fit = pipeline::identify(dynamics, training, &options).map_err(|e| e.to_string())?;
        fit.predict(dynamics, held).map_err(|e| e.to_string())
    });
    candidates
        .iter()
        .zip(predictions.chunks(BLOCKS))
        .map(|(&candidate, blocks)| {
            let held_out = blocks
                .iter()
                .cloned()
                .collect::<Result<Vec<_>, String>>()
                .and_then(|blocks| {
                    let predicted: Vec<Vec<f64>> = blocks.into_iter().flatten().collect();
                    let measured = folds.iter().flat_map(|(_, held)| held.samples().map(|s| s.tau));
                    Validation::new(&names, measured, predicted.iter().map(Vec::as_slice)).map_err(|e| e.to_string())
                });
            Score { candidate, held_out }
        })
        .collect()
}
