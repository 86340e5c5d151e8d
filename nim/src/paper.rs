//! The paper's NIM as the paper describes it: per body, a multilayer perceptron with
//! six inputs, five ReLU hidden layers and the four outputs `(m, J1, J2, J3)`, trained
//! by full-batch gradient descent on the MSE until a threshold, on the first 80 of
//! the 100 samples of the 2 s experiment; the 20 predictions on the last 20 samples
//! are averaged into the identified parameters (Tables 4–5, Fig. 5).
//!
//! **The inputs.** The paper lists six measured items per sample (the Cardano
//! angles, angular velocity, angular acceleration, centre-of-mass acceleration, and
//! the force and moment on the body) and a six-unit input layer; each item is read
//! here as its magnitude: `|α|, |ω|, |ω̇|, |a_c|, |F|, |M|` ([`PAPER_INPUTS`]).
//!
//! **What it can and cannot do.** Every training sample has the same targets, the
//! true parameters of the one simulated robot, so the net learns a constant and the
//! average of its predictions returns its training labels, whatever the inputs are.
//! [`paper_nim`] takes the labels as an argument so this can be shown: trained on
//! labels 20 % off, the same net "identifies" values 20 % off with the same loss
//! curve. The generalising NIM ([`Nim`](super::Nim)) is the version that identifies
//! parameters it was not given.

use super::data::Dataset;
use super::error::NimError;
use super::mlp::Mlp;
use super::train::{train, Decay, Optimizer, TrainHistory, TrainOptions};
use dyngen_identify::mim::{self, MimOptions, ThetaTable, Verdict};
use dyngen_identify::simulate::Recording;
use std::fmt;
use std::ops::Range;

/// The six inputs per sample, in order.
pub const PAPER_INPUTS: [&str; 6] = ["|α|", "|ω|", "|ω̇|", "|a_c|", "|F|", "|M|"];

/// Settings of [`paper_nim`].
#[derive(Clone, Debug, PartialEq)]
pub struct PaperNimConfig {
    /// Width of each of the five hidden layers (the paper does not give it).
    pub hidden: usize,
    /// Gradient-descent step size.
    pub learning_rate: f64,
    /// Stop when the training MSE, in standardised units, is at or below this.
    /// The targets of one body are constant, so each is standardised by its own
    /// size: `10⁻³` is an RMS deviation of 3.2 % from the labels.
    pub mse_threshold: f64,
    pub max_steps: usize,
    /// Leading samples to train on; the rest validate (the paper: 80 of 100).
    pub n_train: usize,
    pub seed: u64,
}

impl Default for PaperNimConfig {
    /// Hidden layers of 16, step size 0.05, threshold 10⁻³ (reached in a few hundred
    /// steps, as the paper's Fig. 5 shows), at most 5,000 steps, 80 training samples,
    /// seed 1.
    fn default() -> PaperNimConfig {
        PaperNimConfig {
            hidden: 16,
            learning_rate: 0.05,
            mse_threshold: 1e-3,
            max_steps: 5000,
            n_train: 80,
            seed: 1,
        }
    }
}

/// The result of [`paper_nim`].
#[derive(Clone, Debug, PartialEq)]
pub struct PaperNim {
    pub body_names: Vec<String>,
    /// The mean prediction over the validation samples, `4n`.
    pub theta: Vec<f64>,
    /// The training targets, `4n`.
    pub labels: Vec<f64>,
    /// Whether each parameter enters its body's equations along the recording
    /// (MIM's rank analysis); the others are printed `n/i`.
    pub identifiable: Vec<bool>,
    /// The training curve of each body (Fig. 5).
    pub histories: Vec<TrainHistory>,
    /// The trained net of each body.
    pub nets: Vec<Mlp>,
    pub n_train: usize,
    pub n_validate: usize,
    /// The true θ, when known, for Table 5.
    pub truth: Option<Vec<f64>>,
}

/// The six [`PAPER_INPUTS`] of body `body` at sample `k`.
pub fn paper_inputs(recording: &Recording, k: usize, body: usize) -> [f64; 6] {
    let b = &recording.samples[k].bodies[body];
    [
        b.cardano.norm(),
        b.angular_velocity.norm(),
        b.angular_acceleration.norm(),
        b.com_acceleration.norm(),
        b.resultant.force.norm(),
        b.resultant.torque.norm(),
    ]
}

/// The paper's NIM on `recording` over `samples` (the paper: its 100 samples,
/// `1..101`), every body trained on the targets `labels` (`4n`; the truth
/// reproduces the paper). Errors when the ranges or lengths do not fit, or training
/// diverges.
pub fn paper_nim(
    recording: &Recording,
    samples: Range<usize>,
    labels: &[f64],
    config: &PaperNimConfig,
) -> Result<PaperNim, NimError> {
    let n = recording.nv();
    if labels.len() != 4 * n {
        return Err(NimError::DimensionMismatch {
            what: "labels (4 per body)",
            expected: 4 * n,
            found: labels.len(),
        });
    }
    check_samples(recording, &samples)?;
    let options = TrainOptions {
        optimizer: Optimizer::GradientDescent {
            learning_rate: config.learning_rate,
        },
        max_steps: config.max_steps,
        mse_threshold: Some(config.mse_threshold),
        seed: config.seed,
        record_every: 1,
        decay: Decay::Constant,
    };
    let mut sizes = vec![6];
    sizes.extend([config.hidden; 5]);
    sizes.push(4);
    let identifiable = match mim::samples(recording, samples.clone(), None, &MimOptions::default()) {
        Ok(est) => (0..4 * n)
            .map(|j| est.verdict(j / 4, j % 4) == Verdict::Identified)
            .collect(),
        Err(_) => vec![false; 4 * n],
    };
    let mut theta = Vec::with_capacity(4 * n);
    let mut histories = Vec::with_capacity(n);
    let mut nets = Vec::with_capacity(n);
    let mut n_validate = 0;
    for i in 0..n {
        let inputs: Vec<[f64; 6]> = samples.clone().map(|k| paper_inputs(recording, k, i)).collect();
        let targets = vec![&labels[4 * i..4 * i + 4]; inputs.len()];
        let data = Dataset::from_rows(&inputs, &targets)?;
        let (fit, check) = data.split_at(config.n_train)?;
        let body_options = TrainOptions {
            seed: config.seed.wrapping_add(i as u64),
            ..options.clone()
        };
        let (net, history): (Mlp, TrainHistory) =
            train(&sizes, &fit, Some(&check), &body_options).map_err(|e| e.within(format!("body {}", i + 1)))?;
        let predictions = net.predict_batch(check.inputs());
        for k in 0..4 {
            let mean = (0..check.len()).map(|r| predictions[(r, k)]).sum::<f64>() / check.len() as f64;
            theta.push(mean);
        }
        n_validate = check.len();
        histories.push(history);
        nets.push(net);
    }
    Ok(PaperNim {
        body_names: recording.body_names.clone(),
        theta,
        labels: labels.to_vec(),
        identifiable,
        histories,
        nets,
        n_train: config.n_train,
        n_validate,
        truth: None,
    })
}

/// Errors unless `samples` is a non-empty range of the recording's samples.
fn check_samples(recording: &Recording, samples: &Range<usize>) -> Result<(), NimError> {
    if samples.end > recording.len() || samples.start >= samples.end {
        return Err(NimError::InvalidOption {
            field: "samples",
            reason: format!(
                "{samples:?} is not a non-empty range within the recording's {} samples",
                recording.len()
            ),
        });
    }
    Ok(())
}

impl PaperNim {
    /// The result with the true θ attached (Table 5).
    pub fn with_truth(mut self, truth: &[f64]) -> PaperNim {
        self.truth = Some(truth.to_vec());
        self
    }

    /// The trained nets applied to another recording of the same robot: every
    /// body's mean prediction over `samples` (`4n`), as the paper averages its 20
    /// validation predictions. Errors when the recording has another number of
    /// bodies or `samples` does not fit it.
    pub fn predict(&self, recording: &Recording, samples: Range<usize>) -> Result<Vec<f64>, NimError> {
        if recording.nv() != self.nets.len() {
            return Err(NimError::DimensionMismatch {
                what: "bodies of the recording",
                expected: self.nets.len(),
                found: recording.nv(),
            });
        }
        check_samples(recording, &samples)?;
        let mut workspace = self.nets[0].workspace();
        let mut out = [0.0; 4];
        let mut theta = vec![0.0; 4 * self.nets.len()];
        for (i, net) in self.nets.iter().enumerate() {
            for k in samples.clone() {
                net.predict(&paper_inputs(recording, k, i), &mut workspace, &mut out);
                for (t, o) in theta[4 * i..4 * i + 4].iter_mut().zip(out) {
                    *t += o / samples.len() as f64;
                }
            }
        }
        Ok(theta)
    }

    /// Gradient-descent steps each body took to reach the threshold (or the budget).
    pub fn steps(&self) -> Vec<usize> {
        self.histories.iter().map(|h| h.steps_taken).collect()
    }

    /// The largest relative deviation of the identifiable estimates from the labels.
    pub fn max_deviation_from_labels(&self) -> f64 {
        self.theta
            .iter()
            .zip(&self.labels)
            .zip(&self.identifiable)
            .filter(|(_, &ok)| ok)
            .map(|((&v, &l), _)| dyngen_identify::relative_error(v, l))
            .fold(0.0, f64::max)
    }
}

impl fmt::Display for PaperNim {
    /// The paper's Tables 4–5.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let steps = self.steps();
        writeln!(
            f,
            "paper-faithful NIM: per body 6 → 5 × ReLU → 4, gradient descent on the first {} samples, mean of the \
             predictions on the last {} (steps to the threshold per body: {})",
            self.n_train,
            self.n_validate,
            steps.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")
        )?;
        let cells: Vec<Result<f64, &str>> = self
            .theta
            .iter()
            .zip(&self.identifiable)
            .map(|(&v, &ok)| if ok { Ok(v) } else { Err("n/i") })
            .collect();
        let table = ThetaTable {
            body_names: &self.body_names,
            cells: &cells,
            truth: self.truth.as_deref(),
            tables: [4, 5],
        };
        write!(f, "{table}")?;
        if cells.iter().any(Result::is_err) {
            writeln!(
                f,
                "n/i: does not enter the body's equations (the net still outputs its label for it; not shown)"
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_identify::simulate::{record, Experiment};
    use dyngen_reference::Reference;

    fn recording() -> (Vec<f64>, Recording) {
        let model = dyngen_model::parse_urdf(include_str!("../../tests/fixtures/paper6.urdf")).unwrap();
        let robot = Reference::new(&model);
        (
            dyngen_model::principal_params(&model),
            record(&robot, &model.standard_params(), &Experiment::paper(&model)),
        )
    }

    /// Trained as the paper trains it, the net reaches the threshold in hundreds of
    /// steps (the paper's Fig. 5: about 400) and returns roughly its labels; trained
    /// on labels 20 % high, it returns values about 20 % high.
    #[test]
    fn the_papers_nim_returns_its_labels() {
        let (truth, recording) = recording();
        let config = PaperNimConfig::default();
        let nim = paper_nim(&recording, 1..101, &truth, &config)
            .unwrap()
            .with_truth(&truth);
        assert_eq!((nim.n_train, nim.n_validate), (80, 20));
        for (i, h) in nim.histories.iter().enumerate() {
            assert_eq!(h.stopped, crate::StopReason::Threshold, "body {i}");
            assert!(h.steps_taken < 1000, "body {i}: {} steps", h.steps_taken);
        }
        assert_eq!(&nim.identifiable[..4], &[true, false, false, true]);
        assert!(nim.identifiable[4..].iter().all(|&x| x));
        let deviation = nim.max_deviation_from_labels();
        assert!(deviation < 0.3, "{nim}");
        let text = nim.to_string();
        assert!(
            text.contains("(cf. the paper's Table 5)") && text.contains("n/i"),
            "{text}"
        );

        let high: Vec<f64> = truth.iter().map(|x| 1.2 * x).collect();
        let relabelled = paper_nim(&recording, 1..101, &high, &config).unwrap();
        let offsets: Vec<f64> = relabelled
            .theta
            .iter()
            .zip(&truth)
            .zip(&relabelled.identifiable)
            .filter(|(_, &ok)| ok)
            .map(|((v, t), _)| v / t - 1.0)
            .collect();
        let mean = offsets.iter().sum::<f64>() / offsets.len() as f64;
        assert!((mean - 0.2).abs() < 0.05, "mean offset {mean}: {offsets:?}");
        // The nets applied to the same recording give back the table's values.
        let again = nim.predict(&recording, 81..101).unwrap();
        for (a, b) in again.iter().zip(&nim.theta) {
            assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()));
        }
    }

    #[test]
    fn the_papers_nim_checks_its_arguments() {
        let (truth, recording) = recording();
        let config = PaperNimConfig::default();
        let err = paper_nim(&recording, 1..101, &truth[..8], &config).unwrap_err();
        assert_eq!(
            err.to_string(),
            "dimension mismatch in labels (4 per body): expected 24, found 8"
        );
        let err = paper_nim(&recording, 50..200, &truth, &config).unwrap_err();
        assert!(
            err.to_string()
                .contains("not a non-empty range within the recording's 101 samples"),
            "{err}"
        );
        let few = PaperNimConfig {
            n_train: 100,
            max_steps: 1,
            ..config
        };
        let err = paper_nim(&recording, 1..101, &truth, &few).unwrap_err();
        assert!(err.to_string().contains("expected 1 ≤ n_train ≤ 99"), "{err}");
    }
}
