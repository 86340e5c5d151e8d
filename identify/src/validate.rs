//! How well a model predicts a recording it was not identified on: per joint the RMS
//! of `τ̂ − τ` and the relative error `‖τ̂_j − τ_j‖ / ‖τ_j‖`, and overall
//! `‖τ̂ − τ‖ / ‖τ‖` over all joints and samples (Frobenius norms). A joint whose
//! relative error is at or above 1 is predicted no better than by zero torque.

use crate::IdentifyError;
use std::fmt;

/// Prediction errors of one recording.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    pub joint_names: Vec<String>,
    pub samples: usize,
    /// RMS of the prediction error per joint (N·m or N).
    pub rms: Vec<f64>,
    /// RMS of the measured torque per joint.
    pub measured_rms: Vec<f64>,
    /// `‖τ̂_j − τ_j‖ / ‖τ_j‖` per joint.
    pub relative: Vec<f64>,
    /// `‖τ̂ − τ‖ / ‖τ‖` over everything.
    pub overall: f64,
}

impl Validation {
    /// Compares `predicted` with `measured`, one slice of `n` torques per sample.
    /// Errors: no samples, rows of different lengths, a non-finite value, or a joint
    /// whose measured torque is zero throughout (its relative error is undefined).
    pub fn new<'a>(
        joint_names: &[String],
        measured: impl IntoIterator<Item = &'a [f64]>,
        predicted: impl IntoIterator<Item = &'a [f64]>,
    ) -> Result<Validation, IdentifyError> {
        let n = joint_names.len();
        let (mut err2, mut tau2) = (vec![0.0; n], vec![0.0; n]);
        let mut samples = 0;
        let mut predicted = predicted.into_iter();
        for (k, m) in measured.into_iter().enumerate() {
            let p = predicted.next().ok_or(IdentifyError::DimensionMismatch {
                what: "predicted samples",
                expected: k + 1,
                found: k,
            })?;
            for (what, row) in [("measured", m), ("predicted", p)] {
                if row.len() != n {
                    return Err(IdentifyError::DimensionMismatch {
                        what,
                        expected: n,
                        found: row.len(),
                    });
                }
                if let Some(j) = row.iter().position(|x| !x.is_finite()) {
                    return Err(IdentifyError::InvalidArgument {
                        what,
                        reason: format!("the torque of sample {k}, joint {} is not finite", j + 1),
                    });
                }
            }
            for j in 0..n {
                err2[j] += (p[j] - m[j]).powi(2);
                tau2[j] += m[j] * m[j];
            }
            samples += 1;
        }
        Validation::from_sums(joint_names, samples, &err2, &tau2)
    }

    /// From the sums over `samples` samples, per joint, of the squared prediction
    /// errors `err2` and the squared measured torques `tau2`. Errors: no samples, or
    /// a joint whose measured torque is zero throughout.
    pub fn from_sums(
        joint_names: &[String],
        samples: usize,
        err2: &[f64],
        tau2: &[f64],
    ) -> Result<Validation, IdentifyError> {
        let n = joint_names.len();
        for (what, sums) in [("prediction errors", err2), ("measured torques", tau2)] {
            if sums.len() != n {
                return Err(IdentifyError::DimensionMismatch {
                    what,
                    expected: n,
                    found: sums.len(),
                });
            }
        }
        if samples == 0 {
            return Err(IdentifyError::Empty);
        }
        if let Some(j) = tau2.iter().position(|&t| t == 0.0) {
            return Err(IdentifyError::InvalidArgument {
                what: "measured",
                reason: format!(
                    "the torque of joint {} is zero throughout, so its relative error is undefined",
                    j + 1
                ),
            });
        }
        let s = samples as f64;
        Ok(Validation {
            joint_names: joint_names.to_vec(),
            samples,
            rms: err2.iter().map(|e| (e / s).sqrt()).collect(),
            measured_rms: tau2.iter().map(|t| (t / s).sqrt()).collect(),
            relative: err2.iter().zip(tau2).map(|(e, t)| (e / t).sqrt()).collect(),
            overall: (err2.iter().sum::<f64>() / tau2.iter().sum::<f64>()).sqrt(),
        })
    }
}

impl fmt::Display for Validation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let width = self.joint_names.iter().map(|s| s.len()).max().unwrap_or(5).max(5);
        writeln!(
            f,
            "{:<width$}  {:>12}  {:>12}  {:>9}",
            "joint", "RMS error", "RMS torque", "relative"
        )?;
        for j in 0..self.joint_names.len() {
            let worse = if self.relative[j] >= 1.0 {
                "  (no better than zero)"
            } else {
                ""
            };
            writeln!(
                f,
                "{:<width$}  {:>12.4e}  {:>12.4e}  {:>8.2} %{worse}",
                self.joint_names[j],
                self.rms[j],
                self.measured_rms[j],
                100.0 * self.relative[j]
            )?;
        }
        write!(
            f,
            "overall relative error {:.2} % over {} samples",
            100.0 * self.overall,
            self.samples
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_per_joint_and_overall() {
        let names = vec!["a".to_string(), "b".to_string()];
        let measured = [[1.0, 2.0], [-1.0, 2.0]];
        let predicted = [[1.1, 2.0], [-0.9, 0.0]];
        let v = Validation::new(
            &names,
            measured.iter().map(|r| &r[..]),
            predicted.iter().map(|r| &r[..]),
        )
        .unwrap();
        assert!((v.rms[0] - 0.1).abs() < 1e-12);
        assert!((v.rms[1] - 2f64.sqrt()).abs() < 1e-12);
        assert!((v.relative[0] - 0.1).abs() < 1e-12);
        assert!((v.relative[1] - (4.0f64 / 8.0).sqrt()).abs() < 1e-12);
        assert!((v.overall - (4.02f64 / 10.0).sqrt()).abs() < 1e-12);
        assert!(v.to_string().contains("overall relative error 63.40 %"), "{v}");
    }

    #[test]
    fn bad_input_is_an_error() {
        let names = vec!["a".to_string()];
        let m = [[1.0]];
        let none: [[f64; 1]; 0] = [];
        assert!(matches!(
            Validation::new(&names, none.iter().map(|r| &r[..]), none.iter().map(|r| &r[..])),
            Err(IdentifyError::Empty)
        ));
        let nan = [[f64::NAN]];
        let e = Validation::new(&names, m.iter().map(|r| &r[..]), nan.iter().map(|r| &r[..])).unwrap_err();
        assert_eq!(
            e.to_string(),
            "invalid predicted: the torque of sample 0, joint 1 is not finite"
        );
        let zero = [[0.0]];
        let e = Validation::new(&names, zero.iter().map(|r| &r[..]), m.iter().map(|r| &r[..])).unwrap_err();
        assert!(e.to_string().contains("zero throughout"), "{e}");
    }
}
