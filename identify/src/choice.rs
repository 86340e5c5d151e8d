//! The joint model chosen by the data: each candidate (rigid bodies alone; friction
//! with and without rotor inertia; the Coulomb smoothing fitted; Stribeck) is fitted
//! on all but one of [`BLOCKS`] contiguous time blocks of the recording and predicts
//! the block left out, every block in turn. The candidate with the lowest error on
//! the held-out blocks wins: a model that only fits the noise of its own data does
//! not. Sign friction is a candidate, so the choice is never worse than it on the
//! held-out blocks.

use crate::accumulate::in_parallel;
use crate::data::Trajectory;
use crate::pipeline::{self, IdentifyOptions, JointTerms, Mode, PipelineError};
use crate::validate::Validation;
use dyngen_model::joint_params::Coulomb;
use dyngen_reference::Dynamics;
use std::fmt;

/// Time blocks of the cross-validation.
pub const BLOCKS: usize = 4;

/// One joint model the choice tries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// What the command line calls it (`--friction NAME`, with `--rotor-inertia no`
    /// for `sign-no-rotor-inertia`).
    pub name: &'static str,
    pub joints: JointTerms,
    pub rotor_inertia: Option<bool>,
}

impl Candidate {
    /// `base` with this joint model.
    pub fn options(&self, base: &IdentifyOptions) -> IdentifyOptions {
        IdentifyOptions {
            joints: self.joints,
            rotor_inertia: self.rotor_inertia,
            ..base.clone()
        }
    }
}

/// The candidates, simplest first (a tie goes to the simpler).
pub const CANDIDATES: [Candidate; 5] = [
    Candidate {
        name: "none",
        joints: JointTerms::None,
        rotor_inertia: None,
    },
    Candidate {
        name: "sign-no-rotor-inertia",
        joints: JointTerms::Friction(Coulomb::Sign),
        rotor_inertia: Some(false),
    },
    Candidate {
        name: "sign",
        joints: JointTerms::Friction(Coulomb::Sign),
        rotor_inertia: None,
    },
    Candidate {
        name: "auto",
        joints: JointTerms::FrictionAuto,
        rotor_inertia: None,
    },
    Candidate {
        name: "stribeck",
        joints: JointTerms::Stribeck(Coulomb::Sign),
        rotor_inertia: None,
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
}

impl fmt::Display for ModelChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "joint model chosen by the error on held-out data ({BLOCKS} time blocks, each predicted by the fit on \
             the others):"
        )?;
        for (i, s) in self.scores.iter().enumerate() {
            let mark = if i == self.chosen { "  <- chosen" } else { "" };
            match &s.held_out {
                Ok(v) => writeln!(f, "  {:<22} {:>7.3} %{mark}", s.candidate.name, 100.0 * v.overall)?,
                Err(e) => writeln!(f, "  {:<22} not fitted: {e}", s.candidate.name)?,
            }
        }
        Ok(())
    }
}

/// Scores every candidate on `traj` with the rest of `options` (standard mode) and
/// chooses the one with the lowest held-out error. Errors: another mode, too few
/// samples for the blocks, or no candidate that could be fitted.
pub fn choose(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    options: &IdentifyOptions,
) -> Result<ModelChoice, PipelineError> {
    if options.mode != Mode::Standard {
        return Err(PipelineError::InvalidOption {
            option: "friction",
            reason: "chooses the joint model of the standard mode".into(),
        });
    }
    let len = traj.len();
    let block = |k: usize| k * BLOCKS / len;
    let folds: Vec<(Trajectory, Trajectory)> = (0..BLOCKS)
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
    let names: Vec<String> = (1..=traj.dof()).map(|j| format!("joint {j}")).collect();
    // Every (candidate, block) fit on its own core: the blocks of one candidate
    // alternate between cores, so that the slow candidates are shared.
    let predictions = in_parallel(CANDIDATES.len() * BLOCKS, |job| {
        let candidate = CANDIDATES[job / BLOCKS];
        let (training, held) = &folds[job % BLOCKS];
        let fit = pipeline::identify(dynamics, training, &candidate.options(options)).map_err(|e| e.to_string())?;
        fit.predict(dynamics, held).map_err(|e| e.to_string())
    });
    let scores: Vec<Score> = CANDIDATES
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
        .collect();
    let chosen = scores
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.held_out.as_ref().ok().map(|v| (i, v.overall)))
        .fold(None, |best: Option<(usize, f64)>, (i, e)| match best {
            Some((_, b)) if b <= e => best,
            _ => Some((i, e)),
        })
        .map(|(i, _)| i)
        .ok_or_else(|| PipelineError::InvalidOption {
            option: "friction",
            reason: format!(
                "no joint model could be fitted on the time blocks: {}",
                scores
                    .iter()
                    .filter_map(|s| s.held_out.as_ref().err().map(|e| format!("{}: {e}", s.candidate.name)))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        })?;
    Ok(ModelChoice { scores, chosen })
}
