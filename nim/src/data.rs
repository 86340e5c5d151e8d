//! Training data: a checked [`Dataset`] of (input, target) samples, its splits, and
//! the per-feature [`Standardizer`].

use super::error::{NimError, Part};
use dyngen_identify::faer::MatRef;
use dyngen_reference::SplitMix64;

/// Samples of (input, target) pairs, one sample per row, every value finite and at
/// least one sample, one input and one target column. Stored row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    inputs: Vec<f64>,
    targets: Vec<f64>,
    n_inputs: usize,
    n_outputs: usize,
}

impl Dataset {
    /// From rows: `inputs[k]` and `targets[k]` are sample `k`. Every input row must
    /// have the length of the first, likewise every target row.
    ///
    /// ```
    /// use dyngen_nim::Dataset;
    /// let d = Dataset::from_rows(&[[0.0, 1.0], [2.0, 3.0]], &[[1.0], [5.0]]).unwrap();
    /// assert_eq!((d.len(), d.n_inputs(), d.n_outputs()), (2, 2, 1));
    /// assert_eq!(d.input(1), &[2.0, 3.0]);
    /// let bad = Dataset::from_rows(&[[0.0, 1.0], [2.0, f64::NAN]], &[[1.0], [5.0]]);
    /// assert!(bad.unwrap_err().to_string().contains("row 1, input column 1"));
    /// ```
    pub fn from_rows<I: AsRef<[f64]>, T: AsRef<[f64]>>(inputs: &[I], targets: &[T]) -> Result<Dataset, NimError> {
        if inputs.is_empty() {
            return Err(NimError::Empty { what: "the dataset" });
        }
        if targets.len() != inputs.len() {
            return Err(NimError::DimensionMismatch {
                what: "number of target rows (one per input row)",
                expected: inputs.len(),
                found: targets.len(),
            });
        }
        let flatten = |rows: &[&[f64]], part: Part| -> Result<(usize, Vec<f64>), NimError> {
            let width = rows[0].len();
            let mut flat = Vec::with_capacity(width * rows.len());
            for (row, r) in rows.iter().enumerate() {
                if r.len() != width {
                    return Err(NimError::RowLength {
                        part,
                        row,
                        expected: width,
                        found: r.len(),
                    });
                }
                flat.extend_from_slice(r);
            }
            Ok((width, flat))
        };
        let input_rows: Vec<&[f64]> = inputs.iter().map(AsRef::as_ref).collect();
        let target_rows: Vec<&[f64]> = targets.iter().map(AsRef::as_ref).collect();
        let (n_inputs, inputs) = flatten(&input_rows, Part::Inputs)?;
        let (n_outputs, targets) = flatten(&target_rows, Part::Targets)?;
        Dataset::from_flat(n_inputs, n_outputs, inputs, targets)
    }

    /// From flat row-major storage: sample `k`'s inputs are
    /// `inputs[k n_inputs .. (k + 1) n_inputs]`, its targets likewise.
    pub fn from_flat(
        n_inputs: usize,
        n_outputs: usize,
        inputs: Vec<f64>,
        targets: Vec<f64>,
    ) -> Result<Dataset, NimError> {
        for (n, part) in [(n_inputs, Part::Inputs), (n_outputs, Part::Targets)] {
            if n == 0 {
                return Err(NimError::InvalidOption {
                    field: if part == Part::Inputs { "n_inputs" } else { "n_outputs" },
                    reason: format!("a dataset needs at least one {part} column, got 0"),
                });
            }
        }
        if inputs.is_empty() {
            return Err(NimError::Empty { what: "the dataset" });
        }
        if !inputs.len().is_multiple_of(n_inputs) {
            return Err(NimError::InvalidOption {
                field: "inputs",
                reason: format!(
                    "{} values are not a whole number of rows of {n_inputs} inputs",
                    inputs.len()
                ),
            });
        }
        let len = inputs.len() / n_inputs;
        if targets.len() != len * n_outputs {
            return Err(NimError::DimensionMismatch {
                what: "number of target values (samples × outputs)",
                expected: len * n_outputs,
                found: targets.len(),
            });
        }
        for (values, width, part) in [(&inputs, n_inputs, Part::Inputs), (&targets, n_outputs, Part::Targets)] {
            if let Some(k) = values.iter().position(|v| !v.is_finite()) {
                return Err(NimError::NonFinite {
                    part,
                    row: k / width,
                    column: k % width,
                    value: values[k],
                });
            }
        }
        Ok(Dataset {
            inputs,
            targets,
            n_inputs,
            n_outputs,
        })
    }

    /// From faer matrices, one sample per row.
    pub fn from_mats(inputs: MatRef<'_, f64>, targets: MatRef<'_, f64>) -> Result<Dataset, NimError> {
        if targets.nrows() != inputs.nrows() {
            return Err(NimError::DimensionMismatch {
                what: "number of target rows (one per input row)",
                expected: inputs.nrows(),
                found: targets.nrows(),
            });
        }
        let flat = |m: MatRef<'_, f64>| -> Vec<f64> {
            (0..m.nrows())
                .flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)]))
                .collect()
        };
        Dataset::from_flat(inputs.ncols(), targets.ncols(), flat(inputs), flat(targets))
    }

    /// Number of samples (at least 1).
    pub fn len(&self) -> usize {
        self.inputs.len() / self.n_inputs
    }

    /// Always `false`: a dataset has at least one sample.
    pub fn is_empty(&self) -> bool {
        self.inputs.is_empty()
    }

    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    pub fn n_outputs(&self) -> usize {
        self.n_outputs
    }

    /// The inputs, one sample per row.
    pub fn inputs(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.inputs, self.len(), self.n_inputs)
    }

    /// The targets, one sample per row.
    pub fn targets(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.targets, self.len(), self.n_outputs)
    }

    /// Sample `k`'s inputs. Panics when `k ≥ len()`.
    pub fn input(&self, k: usize) -> &[f64] {
        &self.inputs[k * self.n_inputs..(k + 1) * self.n_inputs]
    }

    /// Sample `k`'s targets. Panics when `k ≥ len()`.
    pub fn target(&self, k: usize) -> &[f64] {
        &self.targets[k * self.n_outputs..(k + 1) * self.n_outputs]
    }

    /// The samples at `rows`, in that order (repeats allowed). Panics on an index
    /// `≥ len()`; an empty `rows` is [`NimError::Empty`].
    pub fn select(&self, rows: &[usize]) -> Result<Dataset, NimError> {
        if rows.is_empty() {
            return Err(NimError::Empty { what: "the selection" });
        }
        let mut inputs = Vec::with_capacity(rows.len() * self.n_inputs);
        let mut targets = Vec::with_capacity(rows.len() * self.n_outputs);
        for &k in rows {
            inputs.extend_from_slice(self.input(k));
            targets.extend_from_slice(self.target(k));
        }
        Ok(Dataset {
            inputs,
            targets,
            n_inputs: self.n_inputs,
            n_outputs: self.n_outputs,
        })
    }

    /// The first `n_train` samples for training, the rest for validation, order kept
    /// (the paper trains on the first 80 of 100 samples and validates on the last
    /// 20). Both parts must be non-empty: `1 ≤ n_train < len()`.
    pub fn split_at(&self, n_train: usize) -> Result<(Dataset, Dataset), NimError> {
        let len = self.len();
        if n_train == 0 || n_train >= len {
            return Err(NimError::InvalidOption {
                field: "n_train",
                reason: format!(
                    "{n_train} training samples of {len} leaves a part empty; expected 1 ≤ n_train ≤ {}",
                    len.saturating_sub(1)
                ),
            });
        }
        let (a, b): (Vec<usize>, Vec<usize>) = (0..len).partition(|&k| k < n_train);
        Ok((self.select(&a)?, self.select(&b)?))
    }

    /// [`Dataset::split_at`] with `n_train = round(train_fraction · len())`;
    /// `split(0.8)` of 100 samples is the paper's 80/20.
    pub fn split(&self, train_fraction: f64) -> Result<(Dataset, Dataset), NimError> {
        self.split_at(self.fraction_count(train_fraction)?)
    }

    /// Like [`Dataset::split`], after a seeded Fisher–Yates shuffle of the samples
    /// (draws from [`SplitMix64`] seeded with `seed`); each part keeps the shuffled
    /// order.
    pub fn shuffled_split(&self, train_fraction: f64, seed: u64) -> Result<(Dataset, Dataset), NimError> {
        let n_train = self.fraction_count(train_fraction)?;
        let mut order: Vec<usize> = (0..self.len()).collect();
        shuffle(&mut order, &mut SplitMix64::new(seed));
        self.select(&order)?.split_at(n_train)
    }

    fn fraction_count(&self, fraction: f64) -> Result<usize, NimError> {
        if !(fraction > 0.0 && fraction < 1.0) {
            return Err(NimError::InvalidOption {
                field: "train_fraction",
                reason: format!("{fraction} is not in the open interval (0, 1)"),
            });
        }
        Ok((fraction * self.len() as f64).round() as usize)
    }
}

/// Fisher–Yates: for `i = n − 1, …, 1` swap `i` with `⌊u · (i + 1)⌋`, `u` the top 64
/// bits of one [`SplitMix64`] draw as a fraction of 2⁶⁴.
pub(crate) fn shuffle(items: &mut [usize], rng: &mut SplitMix64) {
    for i in (1..items.len()).rev() {
        let j = ((rng.next_u64() as u128 * (i as u128 + 1)) >> 64) as usize;
        items.swap(i, j);
    }
}

/// Per-feature affine standardisation `z = (x − mean) / std`.
///
/// [`Standardizer::fit`] uses the population standard deviation; a feature that is
/// constant (its standard deviation at most `16 ε |mean|`, i.e. zero up to rounding)
/// gets `std = |mean|` (1 when the mean is 0), so it standardises to `≈ 0` instead of
/// NaN and deviations from it are measured relative to its size. (A network trained
/// on one parameter set, as the paper's NIM is, has constant targets.)
#[derive(Clone, Debug, PartialEq)]
pub struct Standardizer {
    mean: Vec<f64>,
    std: Vec<f64>,
}

impl Standardizer {
    /// Mean 0, std 1 for `n` features: `z = x`.
    pub fn identity(n: usize) -> Standardizer {
        Standardizer {
            mean: vec![0.0; n],
            std: vec![1.0; n],
        }
    }

    /// Checked: equal lengths, means finite, standard deviations finite and `> 0`.
    /// `what` names the standardiser in error messages (e.g. `"input"`).
    pub fn new(mean: Vec<f64>, std: Vec<f64>, what: &str) -> Result<Standardizer, NimError> {
        if std.len() != mean.len() {
            return Err(NimError::Shape {
                layer: None,
                field: format!("{what}.std"),
                expected: format!("{} values (one per feature, as {what}.mean)", mean.len()),
                found: format!("{} values", std.len()),
            });
        }
        if let Some(j) = mean.iter().position(|m| !m.is_finite()) {
            return Err(NimError::InvalidValue {
                field: format!("{what}.mean[{j}]"),
                reason: format!("{} is not finite", mean[j]),
            });
        }
        if let Some(j) = std.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(NimError::InvalidValue {
                field: format!("{what}.std[{j}]"),
                reason: format!("{}; a standard deviation must be finite and > 0", std[j]),
            });
        }
        Ok(Standardizer { mean, std })
    }

    /// Mean and standard deviation of every column of `data` (one sample per row).
    /// A matrix without rows gives the identity.
    pub fn fit(data: MatRef<'_, f64>) -> Standardizer {
        let (n, p) = (data.nrows(), data.ncols());
        if n == 0 {
            return Standardizer::identity(p);
        }
        let mut mean = vec![0.0; p];
        let mut std = vec![0.0; p];
        for j in 0..p {
            let m = (0..n).map(|i| data[(i, j)]).sum::<f64>() / n as f64;
            let var = (0..n).map(|i| (data[(i, j)] - m).powi(2)).sum::<f64>() / n as f64;
            let s = var.sqrt();
            mean[j] = m;
            std[j] = if s > 16.0 * f64::EPSILON * m.abs() {
                s
            } else if m != 0.0 {
                m.abs()
            } else {
                1.0
            };
        }
        Standardizer { mean, std }
    }

    /// Number of features.
    pub fn len(&self) -> usize {
        self.mean.len()
    }

    pub fn is_empty(&self) -> bool {
        self.mean.is_empty()
    }

    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    pub fn std(&self) -> &[f64] {
        &self.std
    }

    /// Feature `j` of `x` standardised: `(x − mean_j) / std_j`.
    #[inline(always)]
    pub fn apply(&self, j: usize, x: f64) -> f64 {
        (x - self.mean[j]) / self.std[j]
    }

    /// The inverse of [`Standardizer::apply`]: `z std_j + mean_j`.
    #[inline(always)]
    pub fn invert(&self, j: usize, z: f64) -> f64 {
        z * self.std[j] + self.mean[j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_datasets_name_the_row_and_column() {
        let err = |r: Result<Dataset, NimError>| r.unwrap_err().to_string();
        assert_eq!(
            err(Dataset::from_rows(&[[1.0, 2.0], [3.0, f64::INFINITY]], &[[0.0], [0.0]])),
            "non-finite input value inf at row 1, input column 1 (0-based); every value must be finite"
        );
        assert_eq!(
            err(Dataset::from_rows(&[vec![1.0, 2.0], vec![3.0]], &[[0.0], [0.0]])),
            "input row 1 has 1 values, expected 2 (the length of input row 0)"
        );
        assert_eq!(
            err(Dataset::from_rows(&[[1.0]], &[[0.0], [1.0]])),
            "dimension mismatch in number of target rows (one per input row): expected 1, found 2"
        );
        assert_eq!(
            err(Dataset::from_rows::<[f64; 1], [f64; 1]>(&[], &[])),
            "the dataset has no samples; at least one is needed"
        );
        assert!(err(Dataset::from_flat(2, 1, vec![1.0; 5], vec![0.0; 2])).contains("not a whole number of rows of 2"));
        assert!(err(Dataset::from_flat(0, 1, vec![], vec![])).contains("n_inputs"));
        let d = Dataset::from_rows(&[[0.0], [1.0], [2.0]], &[[0.0], [1.0], [2.0]]).unwrap();
        assert!(d
            .split_at(3)
            .unwrap_err()
            .to_string()
            .contains("expected 1 ≤ n_train ≤ 2"));
        assert!(d
            .split(1.0)
            .unwrap_err()
            .to_string()
            .contains("not in the open interval (0, 1)"));
    }

    #[test]
    fn the_papers_split_keeps_the_order_and_the_shuffled_one_is_seeded() {
        let x: Vec<[f64; 1]> = (0..100).map(|k| [k as f64]).collect();
        let d = Dataset::from_rows(&x, &x).unwrap();
        let (fit, check) = d.split(0.8).unwrap();
        assert_eq!((fit.len(), check.len()), (80, 20));
        assert_eq!((fit.input(79)[0], check.input(0)[0]), (79.0, 80.0));
        let (a, _) = d.shuffled_split(0.8, 3).unwrap();
        let (b, _) = d.shuffled_split(0.8, 3).unwrap();
        let (c, _) = d.shuffled_split(0.8, 4).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
        let mut seen: Vec<f64> = (0..80).map(|k| a.input(k)[0]).collect();
        seen.sort_by(f64::total_cmp);
        seen.dedup();
        assert_eq!(seen.len(), 80, "a shuffle draws without repetition");
    }

    #[test]
    fn a_constant_feature_is_scaled_by_its_size() {
        let data = MatRef::from_row_major_slice(&[2.0, 0.0, 1.0, 2.0, 0.0, 3.0, 2.0, 0.0, 5.0], 3, 3);
        let s = Standardizer::fit(data);
        assert_eq!(s.mean(), &[2.0, 0.0, 3.0]);
        assert_eq!(&s.std()[..2], &[2.0, 1.0]);
        assert!((s.std()[2] - (8.0f64 / 3.0).sqrt()).abs() < 1e-15);
        // A constant feature standardises to its relative deviation.
        assert!((s.apply(0, 2.2) - 0.1).abs() < 1e-15);
        assert_eq!(s.invert(2, s.apply(2, 7.0)), 7.0);
        assert!(Standardizer::new(vec![0.0], vec![-1.0], "input").is_err());
    }
}
