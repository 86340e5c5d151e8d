//! A learned residual on top of an identified physical model: per joint a small
//! network over the joint's own state that predicts what the physical model leaves
//! in its torque (friction shapes, ripple, effects it has no term for). The
//! physical parameters stay as identified, interpretable and exported; the networks
//! only add to their prediction.
//!
//! The networks are trained on the identification recording only, on its first
//! [`1 − HELD_OUT`](HELD_OUT) in time, and kept only if they lower the relative
//! torque error of the physical model on the last [`HELD_OUT`] (which they have not
//! seen) by [`MIN_GAIN`]: networks that only learn the noise of their own samples
//! are not.
//!
//! Each joint's network reads `sin q, cos q, q̇` of that joint alone (the first
//! harmonic of the angle, which a revolute joint's effects follow, and the
//! velocity friction depends on) and returns its torque. Those inputs are chosen by
//! what predicts another recording: on the MuJoCo fixtures, a network over every
//! joint's state, or one that also reads `q` itself (which it then extrapolates)
//! and `q̈` (which carries the differentiation's noise), improved the held-out end
//! of the identification recording and predicted the other recording worse than
//! the physical model alone. Each is an [`Mlp`] with standardisers, so it works in
//! the recording's units; the file ([`RESIDUAL_SCHEMA`]) holds one MLP per joint.
//!
//! ```
//! use dyngen_nim::residual::{ResidualNet, FEATURES};
//! let nets = (0..2).map(|j| dyngen_nim::Mlp::new(&[FEATURES, 8, 1], j).unwrap()).collect();
//! let net = ResidualNet::new(nets).unwrap();
//! let mut out = [0.0; 2];
//! net.predict(&[0.1, 0.2], &[0.0, 1.0], &mut net.workspace(), &mut out);
//! assert!(out.iter().all(|x| x.is_finite()));
//! let again = ResidualNet::from_json(&net.to_json()).unwrap();
//! assert_eq!(again, net);
//! ```

use crate::mlp::{read_json, write_json};
use crate::{train, Dataset, Decay, Mlp, NimError, Optimizer, TrainOptions, Workspace};
use dyngen_identify::data::Trajectory;
use dyngen_identify::faer::Mat;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::Path;

/// Inputs of each joint's network: `sin q, cos q, q̇`.
pub const FEATURES: usize = 3;

/// The `schema` string of the residual's JSON file.
pub const RESIDUAL_SCHEMA: &str = "dyngen-residual/1";

/// The part of the recording, at its end, held out to decide whether the networks
/// are kept.
pub const HELD_OUT: f64 = 0.25;

/// The relative drop of the held-out error the networks must bring to be kept.
pub const MIN_GAIN: f64 = 0.01;

/// Training samples at most (spread evenly over the training part).
pub const TRAINING_SAMPLES: usize = 20_000;

/// How the networks are trained.
#[derive(Clone, Debug, PartialEq)]
pub struct ResidualOptions {
    /// The hidden layers' widths.
    pub hidden: Vec<usize>,
    /// Adam steps per joint (mini-batches of 64, cosine-decayed learning rate from
    /// 3e-3).
    pub steps: usize,
    pub seed: u64,
}

impl Default for ResidualOptions {
    /// Two hidden layers of 16, 3,000 steps, seed 0.
    fn default() -> Self {
        ResidualOptions {
            hidden: vec![16, 16],
            steps: 3_000,
            seed: 0,
        }
    }
}

/// One network per joint.
#[derive(Clone, Debug, PartialEq)]
pub struct ResidualNet {
    nets: Vec<Mlp>,
}

/// The JSON file: the schema and each joint's MLP file ([`crate::SCHEMA`]).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ResidualFile {
    schema: String,
    joints: Vec<serde_json::Value>,
}

impl ResidualNet {
    /// The networks `nets`, joint by joint: each takes [`FEATURES`] inputs and
    /// returns one torque.
    pub fn new(nets: Vec<Mlp>) -> Result<ResidualNet, NimError> {
        for net in &nets {
            for (what, expected, found) in [
                ("residual network inputs", FEATURES, net.n_inputs()),
                ("residual network outputs", 1, net.n_outputs()),
            ] {
                if expected != found {
                    return Err(NimError::DimensionMismatch { what, expected, found });
                }
            }
        }
        Ok(ResidualNet { nets })
    }

    pub fn joints(&self) -> usize {
        self.nets.len()
    }

    /// Joint `j`'s network.
    pub fn net(&self, j: usize) -> &Mlp {
        &self.nets[j]
    }

    /// A workspace that fits every joint's network.
    pub fn workspace(&self) -> Workspace {
        Workspace::with_width(
            self.nets
                .iter()
                .flat_map(|n| n.sizes().iter().copied())
                .max()
                .unwrap_or(0),
        )
    }

    /// A joint's network inputs at `(q, q̇)`.
    pub fn features(q: f64, v: f64) -> [f64; FEATURES] {
        let (sin, cos) = q.sin_cos();
        [sin, cos, v]
    }

    /// The residual torques at `(q, q̇)` into `out` (one per joint), without
    /// allocating.
    pub fn predict(&self, q: &[f64], v: &[f64], workspace: &mut Workspace, out: &mut [f64]) {
        for (j, net) in self.nets.iter().enumerate() {
            let mut y = [0.0];
            net.predict(&Self::features(q[j], v[j]), workspace, &mut y);
            out[j] = y[0];
        }
    }

    /// The residual torques at every sample of `traj` (which must have velocities
    /// and one coordinate per joint), one row per sample.
    pub fn predict_all(&self, traj: &Trajectory) -> Result<Vec<Vec<f64>>, NimError> {
        if traj.dof() != self.joints() {
            return Err(NimError::DimensionMismatch {
                what: "recording joints",
                expected: self.joints(),
                found: traj.dof(),
            });
        }
        let rows: Vec<usize> = (0..traj.len()).collect();
        let mut out = vec![vec![0.0; self.joints()]; traj.len()];
        for (j, net) in self.nets.iter().enumerate() {
            let y = net.predict_batch(inputs(traj, j, &rows)?.as_ref());
            for (k, row) in out.iter_mut().enumerate() {
                row[j] = y[(k, 0)];
            }
        }
        Ok(out)
    }

    pub fn to_json(&self) -> String {
        let file = ResidualFile {
            schema: RESIDUAL_SCHEMA.to_string(),
            joints: self
                .nets
                .iter()
                .map(|n| serde_json::from_str(&n.to_json()).expect("an Mlp's JSON reads back"))
                .collect(),
        };
        serde_json::to_string_pretty(&file).expect("a residual serialises to JSON")
    }

    /// Reads [`ResidualNet::to_json`]'s text.
    pub fn from_json(text: &str) -> Result<ResidualNet, NimError> {
        let file: ResidualFile = serde_json::from_str(text).map_err(|e| NimError::Json { message: e.to_string() })?;
        if file.schema != RESIDUAL_SCHEMA {
            return Err(NimError::Schema {
                found: Some(file.schema),
                expected: RESIDUAL_SCHEMA,
            });
        }
        ResidualNet::new(
            file.joints
                .iter()
                .map(|n| Mlp::from_json(&n.to_string()))
                .collect::<Result<_, _>>()?,
        )
    }

    /// Writes [`ResidualNet::to_json`] to `path`; an existing file only with
    /// `overwrite`.
    pub fn save(&self, path: impl AsRef<Path>, overwrite: bool) -> Result<(), NimError> {
        write_json(path.as_ref(), &self.to_json(), overwrite)
    }

    /// Reads a file of [`ResidualNet::save`]; its joints must number `joints`.
    pub fn load(path: impl AsRef<Path>, joints: usize) -> Result<ResidualNet, NimError> {
        let net = ResidualNet::from_json(&read_json(path.as_ref())?)?;
        if net.joints() != joints {
            return Err(NimError::DimensionMismatch {
                what: "residual networks (one per joint)",
                expected: joints,
                found: net.joints(),
            });
        }
        Ok(net)
    }
}

/// Joint `j`'s network inputs at the samples `rows` of `traj`, one row each.
fn inputs(traj: &Trajectory, j: usize, rows: &[usize]) -> Result<Mat<f64>, NimError> {
    let Some(v) = traj.velocities() else {
        return Err(NimError::InvalidOption {
            field: "recording",
            reason: "the residual needs velocities; load the recording through the pipeline, which estimates them"
                .into(),
        });
    };
    let n = traj.dof();
    let mut x = Mat::zeros(rows.len(), FEATURES);
    for (r, &k) in rows.iter().enumerate() {
        let f = ResidualNet::features(traj.q(k)[j], v[k * n + j]);
        for (c, &value) in f.iter().enumerate() {
            x[(r, c)] = value;
        }
    }
    Ok(x)
}

/// The outcome of [`fit_residual`]: the network, and the relative torque errors
/// on the held-out end of the recording without and with it.
#[derive(Clone, Debug)]
pub struct ResidualFit {
    pub net: ResidualNet,
    /// `‖τ − τ̂‖ / ‖τ‖` of the physical model on the held-out part.
    pub without: f64,
    /// The same with the residual added.
    pub with: f64,
    /// Whether the residual lowers the held-out error by [`MIN_GAIN`].
    pub kept: bool,
    pub training_samples: usize,
    pub held_out_samples: usize,
}

impl fmt::Display for ResidualFit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sizes: Vec<String> = self
            .net
            .nets
            .first()
            .map_or(Vec::new(), |n| n.sizes().iter().map(usize::to_string).collect());
        write!(
            f,
            "learned residual (a network {} per joint, trained on {} samples of the first {:.0} % of the recording): error on \
             the last {:.0} % ({} samples) {:.2} % without, {:.2} % with: {}",
            sizes.join("→"),
            self.training_samples,
            100.0 * (1.0 - HELD_OUT),
            100.0 * HELD_OUT,
            self.held_out_samples,
            100.0 * self.without,
            100.0 * self.with,
            if self.kept {
                "kept".to_string()
            } else {
                format!("not kept (it must lower the error by {:.0} %)", 100.0 * MIN_GAIN)
            }
        )
    }
}

/// Trains the residual networks on `traj` (velocities as the identification used
/// them) over the physical model's predicted torques
/// `physical` (one row per sample), and scores it on the held-out end, as the
/// module says. Errors: a recording too short to hold out a part, rows of the
/// wrong length, non-finite values, or training that diverges.
pub fn fit_residual(
    traj: &Trajectory,
    physical: &[Vec<f64>],
    options: &ResidualOptions,
) -> Result<ResidualFit, NimError> {
    let (len, n) = (traj.len(), traj.dof());
    if physical.len() != len {
        return Err(NimError::DimensionMismatch {
            what: "predicted samples",
            expected: len,
            found: physical.len(),
        });
    }
    if let Some(row) = physical.iter().find(|row| row.len() != n) {
        return Err(NimError::DimensionMismatch {
            what: "predicted torques per sample",
            expected: n,
            found: row.len(),
        });
    }
    let split = ((1.0 - HELD_OUT) * len as f64).round() as usize;
    if split < 10 || len - split < 10 {
        return Err(NimError::InvalidOption {
            field: "recording",
            reason: format!(
                "{len} samples: the residual needs at least 10 to train on and 10 to hold out (the last {:.0} %)",
                100.0 * HELD_OUT
            ),
        });
    }
    let stride = split.div_ceil(TRAINING_SAMPLES).max(1);
    let rows: Vec<usize> = (0..split).step_by(stride).collect();
    if traj.positions().len() != len * n {
        return Err(NimError::InvalidOption {
            field: "recording",
            reason: "the residual needs one position coordinate per joint (no ball or free joints)".into(),
        });
    }
    let mut sizes = vec![FEATURES];
    sizes.extend(&options.hidden);
    sizes.push(1);
    let train_options = TrainOptions {
        optimizer: Optimizer::Adam {
            learning_rate: 3e-3,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-8,
            batch_size: 64,
        },
        max_steps: options.steps,
        record_every: options.steps.max(1),
        decay: Decay::Cosine { final_fraction: 0.05 },
        ..TrainOptions::default()
    };
    // The joints' networks spread over the cores, each from its own seed.
    let train_joint = |j: usize| -> Result<Mlp, NimError> {
        let targets = Mat::from_fn(rows.len(), 1, |r, _| traj.tau(rows[r])[j] - physical[rows[r]][j]);
        let data = Dataset::from_mats(inputs(traj, j, &rows)?.as_ref(), targets.as_ref())?;
        let options = TrainOptions {
            seed: options.seed.wrapping_add(j as u64),
            ..train_options.clone()
        };
        Ok(train(&sizes, &data, None, &options)?.0)
    };
    let nets = dyngen_identify::in_parallel(n, train_joint)
        .into_iter()
        .collect::<Result<Vec<Mlp>, NimError>>()?;
    let net = ResidualNet::new(nets)?;
    // The held-out end: the physical model alone and with the residual.
    let held: Vec<usize> = (split..len).collect();
    let (mut without, mut with, mut tau2) = (0.0, 0.0, 0.0);
    for j in 0..n {
        let residual = net.nets[j].predict_batch(inputs(traj, j, &held)?.as_ref());
        for (r, &k) in held.iter().enumerate() {
            let e = traj.tau(k)[j] - physical[k][j];
            without += e * e;
            with += (e - residual[(r, 0)]).powi(2);
            tau2 += traj.tau(k)[j].powi(2);
        }
    }
    if !(without.is_finite() && with.is_finite() && tau2 > 0.0) {
        return Err(NimError::InvalidOption {
            field: "recording",
            reason: "the held-out torques or their predictions are zero or not finite".into(),
        });
    }
    let (without, with) = ((without / tau2).sqrt(), (with / tau2).sqrt());
    Ok(ResidualFit {
        net,
        without,
        with,
        kept: with <= (1.0 - MIN_GAIN) * without,
        training_samples: rows.len(),
        held_out_samples: held.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_reference::SplitMix64;

    /// Two joints moving along two sine sweeps of different frequencies, their
    /// torques `effect(q, q̇)` plus noise, predicted by a "physical model" of 0:
    /// the trajectory and the predictions.
    fn recording(seed: u64, phase: f64, effect: impl Fn(f64, f64) -> f64) -> (Trajectory, Vec<Vec<f64>>) {
        let (len, dt) = (4_000, 0.005);
        let mut rng = SplitMix64::new(seed);
        let (mut t, mut q, mut v, mut tau) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for k in 0..len {
            let time = k as f64 * dt;
            t.push(time);
            for (j, w) in [0.7, 1.3].iter().enumerate() {
                let (angle, speed) = (2.0 * (w * time + phase).sin(), 2.0 * w * (w * time + phase).cos());
                q.push(angle);
                v.push(speed);
                tau.push(effect(angle, speed) + 0.01 * (j as f64 + 1.0) + 0.02 * rng.uniform(-1.0, 1.0));
            }
        }
        let traj = Trajectory::new(2, t, q, tau).unwrap().with_velocities(v).unwrap();
        (traj, vec![vec![0.0; 2]; len])
    }

    #[test]
    fn an_effect_of_the_joint_state_is_learned_and_noise_is_not() {
        let effect = |q: f64, v: f64| 0.5 * (2.0 * q).sin() + 0.3 * v.abs();
        let options = ResidualOptions::default();
        let (traj, physical) = recording(1, 0.0, effect);
        let fit = fit_residual(&traj, &physical, &options).unwrap();
        println!("{fit}");
        assert!(fit.kept && fit.with < 0.2 * fit.without, "{fit}");
        // It predicts another recording (other phases, other noise) as well.
        let (other, _) = recording(2, 1.0, effect);
        let predicted = fit.net.predict_all(&other).unwrap();
        let (mut err, mut tau2) = (0.0, 0.0);
        for (k, row) in predicted.iter().enumerate() {
            for j in 0..2 {
                err += (other.tau(k)[j] - row[j]).powi(2);
                tau2 += other.tau(k)[j].powi(2);
            }
        }
        assert!((err / tau2).sqrt() < 0.1, "{}", (err / tau2).sqrt());
        // Noise alone (and a constant) leaves nothing to learn: not kept.
        let (traj, physical) = recording(3, 0.0, |_, _| 0.0);
        let physical: Vec<Vec<f64>> = physical.iter().map(|_| vec![0.01, 0.02]).collect();
        let fit = fit_residual(&traj, &physical, &options).unwrap();
        println!("{fit}");
        assert!(!fit.kept, "{fit}");
    }

    #[test]
    fn recordings_too_short_and_mismatched_predictions_are_refused() {
        let (traj, physical) = recording(1, 0.0, |_, _| 1.0);
        let short = traj.select(|k| k < 30).unwrap();
        let e = fit_residual(&short, &physical[..30], &ResidualOptions::default()).unwrap_err();
        assert!(
            e.to_string().contains("30 samples: the residual needs at least 10"),
            "{e}"
        );
        let e = fit_residual(&traj, &physical[..10], &ResidualOptions::default()).unwrap_err();
        assert!(e.to_string().contains("predicted samples"), "{e}");
    }
}
