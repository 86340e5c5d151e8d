//! Recursive least squares with exponential forgetting.
//!
//! `k = P a / (λ + aᵀ P a)`, `x ← x + k (y − aᵀ x)`, `P ← (P − k aᵀ P) / λ`, with `P`
//! re-symmetrised after every update. With `λ = 1` and `P₀ = δ I` the estimate
//! after `m` rows equals ridge regression toward `x₀` with weight `1/δ`, hence
//! OLS as `δ → ∞`; with `λ < 1` old rows fade with weight `λ^age` and the
//! estimate tracks changing parameters.

use faer::{Mat, MatRef};

use super::error::{check_finite_vector, check_len, IdentifyError, Input};

/// Recursive least-squares state.
#[derive(Clone, Debug)]
pub struct Rls {
    x: Vec<f64>,
    p: Mat<f64>,
    lambda: f64,
    updates: usize,
}

impl Rls {
    /// `n` parameters starting at zero, forgetting factor `lambda ∈ (0, 1]`, initial
    /// covariance `initial_covariance · I` (> 0; large = weak prior).
    pub fn new(n: usize, lambda: f64, initial_covariance: f64) -> Result<Self, IdentifyError> {
        Self::with_initial(&vec![0.0; n], lambda, initial_covariance)
    }

    /// As [`Rls::new`], starting from `x0`.
    pub fn with_initial(x0: &[f64], lambda: f64, initial_covariance: f64) -> Result<Self, IdentifyError> {
        if !(lambda > 0.0 && lambda <= 1.0) {
            return Err(IdentifyError::InvalidArgument {
                what: "forgetting factor λ",
                reason: format!("{lambda}: must lie in (0, 1]"),
            });
        }
        if !(initial_covariance.is_finite() && initial_covariance > 0.0) {
            return Err(IdentifyError::InvalidArgument {
                what: "initial covariance",
                reason: format!("{initial_covariance}: must be finite and > 0"),
            });
        }
        check_finite_vector(x0, Input::Prior)?;
        let n = x0.len();
        let p = Mat::from_fn(n, n, |i, j| if i == j { initial_covariance } else { 0.0 });
        Ok(Self {
            x: x0.to_vec(),
            p,
            lambda,
            updates: 0,
        })
    }

    /// Number of parameters.
    pub fn n_params(&self) -> usize {
        self.x.len()
    }

    /// Rows absorbed so far.
    pub fn updates(&self) -> usize {
        self.updates
    }

    /// Absorbs one row `a` (length `n`) with observation `y`; returns the a-priori
    /// prediction error `y − aᵀx` (before the update).
    pub fn update(&mut self, a: &[f64], y: f64) -> Result<f64, IdentifyError> {
        let n = self.x.len();
        check_len(a, n, "regressor row")?;
        if let Some(j) = a.iter().position(|v| !v.is_finite()) {
            return Err(IdentifyError::NonFinite {
                input: Input::Regressor,
                row: self.updates,
                column: j,
            });
        }
        if !y.is_finite() {
            return Err(IdentifyError::NonFinite {
                input: Input::Observation,
                row: self.updates,
                column: 0,
            });
        }
        let pa: Vec<f64> = (0..n).map(|i| (0..n).map(|j| self.p[(i, j)] * a[j]).sum()).collect();
        let denom = self.lambda + super::dense::dot(a, &pa);
        let err = y - super::dense::dot(a, &self.x);
        for i in 0..n {
            self.x[i] += pa[i] / denom * err;
        }
        let inv_lambda = 1.0 / self.lambda;
        for i in 0..n {
            for j in 0..n {
                self.p[(i, j)] = (self.p[(i, j)] - pa[i] * pa[j] / denom) * inv_lambda;
            }
        }
        // Symmetrise against drift (the update above is symmetric in exact arithmetic).
        for i in 0..n {
            for j in 0..i {
                let s = 0.5 * (self.p[(i, j)] + self.p[(j, i)]);
                self.p[(i, j)] = s;
                self.p[(j, i)] = s;
            }
        }
        self.updates += 1;
        Ok(err)
    }

    /// Absorbs a block of rows (`a`: `k × n`, `y`: `k`), row by row. On error the
    /// rows before the offending one have been absorbed.
    pub fn update_block(&mut self, a: MatRef<'_, f64>, y: &[f64]) -> Result<(), IdentifyError> {
        check_len(y, a.nrows(), "observations")?;
        if a.ncols() != self.x.len() {
            return Err(IdentifyError::DimensionMismatch {
                what: "regressor columns",
                expected: self.x.len(),
                found: a.ncols(),
            });
        }
        let mut row = vec![0.0; a.ncols()];
        for i in 0..a.nrows() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = a[(i, j)];
            }
            self.update(&row, y[i])?;
        }
        Ok(())
    }

    /// The current estimate.
    pub fn estimate(&self) -> &[f64] {
        &self.x
    }

    /// The current `P` (covariance of the estimate divided by the noise variance).
    pub fn covariance(&self) -> MatRef<'_, f64> {
        self.p.as_ref()
    }

    /// Standard deviations `σ √P_jj` for a given noise σ of one row.
    pub fn sigma(&self, noise_sigma: f64) -> Vec<f64> {
        (0..self.x.len())
            .map(|j| noise_sigma * self.p[(j, j)].max(0.0).sqrt())
            .collect()
    }
}
