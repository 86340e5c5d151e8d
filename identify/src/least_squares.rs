//! Ordinary, weighted (Gautier), total and ridge least squares, all on the
//! compressed factors of an [`Accumulator`].

use faer::Mat;

use super::accumulate::{channel_rss, combine, Accumulator};
use super::error::{check_finite_vector, check_len, IdentifyError, Input};
use super::estimate::{Estimate, Method, Residuals, Status};
use super::subspace::Subspace;
use super::Options;

impl Accumulator {
    /// Ordinary least squares, `min ‖A x − y‖²`.
    ///
    /// Rank from the SVD of the triangle of `[A y]` (faer), tolerance
    /// [`Options::rank_tolerance`]. The solution is the minimum-norm one; only
    /// identifiable parameters and combinations get values. `σ̂² = ‖r‖² / (m − r)`
    /// and `Cov = σ̂² (AᵀA)⁺` on the identifiable subspace.
    pub fn ols(&self, opts: &Options) -> Result<Estimate, IdentifyError> {
        let factors = self.factors()?;
        let tri = combine(&factors, None, self.n_params());
        let sub = Subspace::analyse(tri.r.as_ref(), tri.rows, tri.floor, opts)?;
        let x = sub.min_norm_solution(&tri.z);
        let dof = tri.rows as f64 - sub.rank as f64;
        let residuals = Residuals::from_factors(&factors, &x, dof);
        let noise = (dof > 0.0).then(|| (residuals.sum_of_squares / dof).sqrt());
        let cov = noise.map(|s| scale(sub.unit_covariance(), s * s));
        let status = sub.status.clone();
        Ok(Estimate::assemble(
            Method::Ols,
            sub,
            x,
            cov,
            status,
            residuals,
            noise,
            opts.identifiability_tolerance,
        ))
    }

    /// Weighted least squares with per-channel variances estimated as Gautier does:
    /// OLS first, then `σ_c² = ‖r_c‖² / (m_c (m − r)/m)` per channel (each channel's
    /// share of the degrees of freedom), then [`Accumulator::wls_with_variances`].
    /// Variances below `1e-12` of the largest are raised to it (noise-free channels
    /// would otherwise get infinite weight); all-zero residuals give equal weights.
    ///
    /// One reweighting step, as Gautier does: a very quiet channel next to noisy
    /// ones gets its σ overestimated (its OLS residual is dominated by the error of
    /// the OLS estimate); [`Accumulator::wls_iterated`] repeats the step.
    pub fn wls(&self, opts: &Options) -> Result<Estimate, IdentifyError> {
        self.wls_iterated(1, opts)
    }

    /// Iterated (feasible generalised) least squares: re-estimates the channel
    /// variances from the residuals of the previous weighted fit, up to `iterations`
    /// times (1 = [`Accumulator::wls`]) or until no channel σ changes by more than
    /// `1e-6` relative.
    pub fn wls_iterated(&self, iterations: usize, opts: &Options) -> Result<Estimate, IdentifyError> {
        if iterations == 0 {
            return Err(IdentifyError::InvalidArgument {
                what: "WLS iterations",
                reason: "must be ≥ 1".into(),
            });
        }
        let factors = self.factors()?;
        let p = self.n_params();
        let tri = combine(&factors, None, p);
        let sub = Subspace::analyse(tri.r.as_ref(), tri.rows, tri.floor, opts)?;
        let m = tri.rows;
        if m <= sub.rank {
            return Err(IdentifyError::TooFewRows {
                needed: sub.rank + 1,
                found: m,
            });
        }
        let mut x = sub.min_norm_solution(&tri.z);
        let mut var = channel_variances(&factors, &x, sub.rank);
        for _ in 1..iterations {
            let weights: Vec<f64> = var.iter().map(|v| 1.0 / v.sqrt()).collect();
            let wtri = combine(&factors, Some(&weights), p);
            let wsub = Subspace::analyse(wtri.r.as_ref(), wtri.rows, wtri.floor, opts)?;
            x = wsub.min_norm_solution(&wtri.z);
            let next = channel_variances(&factors, &x, wsub.rank);
            let change = next
                .iter()
                .zip(&var)
                .map(|(a, b)| (a / b).sqrt() - 1.0)
                .fold(0.0, |a: f64, d| a.max(d.abs()));
            var = next;
            if change <= 1e-6 {
                break;
            }
        }
        self.wls_with_variances(&var, opts)
    }

    /// Weighted least squares with known per-channel noise variances (weights
    /// `1/σ_c`). The covariance is `s² (AᵀWA)⁺` with the a-posteriori variance
    /// factor `s² = ‖W^{1/2} r‖² / (m − r)` (≈ 1 when the variances are right).
    pub fn wls_with_variances(&self, variances: &[f64], opts: &Options) -> Result<Estimate, IdentifyError> {
        let factors = self.factors()?;
        check_len(variances, factors.len(), "channel variances")?;
        if let Some(c) = variances.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(IdentifyError::InvalidArgument {
                what: "channel variances",
                reason: format!("channel {c} has variance {}, must be finite and > 0", variances[c]),
            });
        }
        let weights: Vec<f64> = variances.iter().map(|v| 1.0 / v.sqrt()).collect();
        let tri = combine(&factors, Some(&weights), self.n_params());
        let sub = Subspace::analyse(tri.r.as_ref(), tri.rows, tri.floor, opts)?;
        let x = sub.min_norm_solution(&tri.z);
        let dof = tri.rows as f64 - sub.rank as f64;
        let wrss: f64 = channel_rss(&factors, &x)
            .iter()
            .zip(&weights)
            .map(|(s, w)| s * w * w)
            .sum();
        let factor = (dof > 0.0).then(|| wrss / dof);
        let cov = factor.map(|s2| scale(sub.unit_covariance(), s2));
        let residuals = Residuals::from_factors(&factors, &x, dof);
        let status = sub.status.clone();
        let method = Method::Wls {
            channel_sigma: variances.iter().map(|v| v.sqrt()).collect(),
            variance_factor: factor.unwrap_or(f64::NAN).max(0.0),
        };
        Ok(Estimate::assemble(
            method,
            sub,
            x,
            cov,
            status,
            residuals,
            None,
            opts.identifiability_tolerance,
        ))
    }

    /// Total least squares with column scaling: `min ‖[ΔA Δy]‖_F` s.t.
    /// `(A + ΔA) x = y + Δy` on `[A y]` with every column divided by its norm, the
    /// solution scaled back. The default TLS: its answer does not depend on the units
    /// of the parameters or the observations, and it assumes each column's noise is
    /// proportional to its norm (the same relative noise everywhere), which is what
    /// a regressor whose columns span orders of magnitude needs.
    ///
    /// From the smallest right singular vector of `[Ã Ṽ₁, ỹ]` (scaled, restricted to
    /// the identifiable subspace `Ṽ₁` of `Ã`), so unidentifiable directions stay
    /// unassigned: the solution is projected onto the identifiable subspace of `A`.
    /// `noise_sigma` is the σ of the entries of `y` (`‖y‖` times the per-entry σ of
    /// the scaled problem, `√(σ²_min / m)`); the covariance is the first-order one,
    /// `σ² (1 + ‖x̃‖²) Ṽ₁ (Σ̃₁² − σ²_min I)⁻¹ Ṽ₁ᵀ` in the scaled parameters, scaled back.
    /// A column weaker than `√ε` of the strongest is numerically zero and is divided
    /// by the strongest's norm (never blown up to a unit column of roundoff).
    pub fn tls(&self, opts: &Options) -> Result<Estimate, IdentifyError> {
        self.total_least_squares(true, opts)
    }

    /// Total least squares on `[A y]` as it is ([`Accumulator::tls`] without the
    /// column scaling): right when every entry of `A` and `y` has noise of the same
    /// variance in the units given, and far off when the columns' scales differ.
    /// `noise_sigma` is then that per-entry σ.
    pub fn tls_unscaled(&self, opts: &Options) -> Result<Estimate, IdentifyError> {
        self.total_least_squares(false, opts)
    }

    fn total_least_squares(&self, column_scaling: bool, opts: &Options) -> Result<Estimate, IdentifyError> {
        let factors = self.factors()?;
        let p = self.n_params();
        let tri = combine(&factors, None, p);
        let sub = Subspace::analyse(tri.r.as_ref(), tri.rows, tri.floor, opts)?;
        // Column scales of [A y] (their norms, read off the triangle), 1 unscaled.
        let (d, dy) = if column_scaling {
            let ny = (super::dense::dot(&tri.z, &tri.z) + tri.rho2).sqrt();
            (column_scales(&sub.column_norms), if ny > 0.0 { ny } else { 1.0 })
        } else {
            (vec![1.0; p], 1.0)
        };
        let rs = Mat::from_fn(p, p, |i, j| tri.r[(i, j)] / d[j]);
        let scaled_sub;
        let ssub = if column_scaling {
            scaled_sub = Subspace::analyse(rs.as_ref(), tri.rows, tri.floor, opts)?;
            &scaled_sub
        } else {
            &sub
        };
        let r = ssub.rank;
        // B = [R̃ Ṽ₁, z̃; 0, ρ̃] has the singular values of [Ã Ṽ₁, ỹ].
        let rv = rs.as_ref() * ssub.v.as_ref().subcols(0, r);
        let b = Mat::from_fn(p + 1, r + 1, |i, j| match (i < p, j < r) {
            (true, true) => rv[(i, j)],
            (true, false) => tri.z[i] / dy,
            (false, true) => 0.0,
            (false, false) => tri.rho2.sqrt() / dy,
        });
        let svd = b
            .svd()
            .map_err(|_| IdentifyError::DecompositionFailed { what: "SVD of [A y]" })?;
        let s_min = svd.S().column_vector()[r];
        let v = svd.V();
        let last = v[(r, r)];
        if last.abs() <= f64::EPSILON.sqrt() || s_min >= ssub.s[r - 1] * (1.0 - 1e-12) {
            return Err(IdentifyError::TlsNongeneric);
        }
        let zeta: Vec<f64> = (0..r).map(|k| -v[(k, r)] / last).collect();
        // x = D⁻¹ Ṽ₁ ζ ‖y‖.
        let unscale: Vec<f64> = d.iter().map(|dj| dy / dj).collect();
        let mut x = vec![0.0; p];
        for k in 0..r {
            for i in 0..p {
                x[i] += ssub.v[(i, k)] * zeta[k] * unscale[i];
            }
        }
        let m = tri.rows as f64;
        let sigma2 = s_min * s_min / m;
        let zn2: f64 = zeta.iter().map(|z| z * z).sum();
        let w: Vec<f64> = ssub.s[..r].iter().map(|s| 1.0 / (s * s - s_min * s_min)).collect();
        let mut cov = scale(super::dense::scaled_gram(ssub.v.as_ref(), &w), sigma2 * (1.0 + zn2));
        for j in 0..p {
            for i in 0..p {
                cov[(i, j)] *= unscale[i] * unscale[j];
            }
        }
        if column_scaling {
            // Zero in the null space of A, like every least-squares solution here.
            let v1 = sub.v.as_ref().subcols(0, sub.rank);
            let proj = v1 * v1.transpose();
            x = super::dense::mat_vec(proj.as_ref(), &x);
            cov = proj.as_ref() * cov.as_ref() * proj.as_ref();
        }
        let dof = m - sub.rank as f64;
        let residuals = Residuals::from_factors(&factors, &x, dof);
        let status = sub.status.clone();
        Ok(Estimate::assemble(
            Method::Tls { column_scaling },
            sub,
            x,
            Some(cov),
            status,
            residuals,
            Some(sigma2.sqrt() * dy),
            opts.identifiability_tolerance,
        ))
    }

    /// Ridge regression toward a prior with a scale-free weight:
    /// `min ‖A x − y‖² + λ ‖D (x − x₀)‖²`, `D² = diag(AᵀA)`, `λ ≥ 0`.
    ///
    /// With `D` the column norms of `A`, `λ` is dimensionless: it weighs the prior
    /// against the data column by column (`λ = 10⁻³`: each parameter is pulled
    /// toward `x₀` as hard as a thousandth of its column's own signal), and the fit
    /// does not change when a column is rescaled (a parameter given in other units).
    /// It equals [`Accumulator::ridge_unscaled`] on `A D⁻¹` in the parameters `D x`.
    /// A column weaker than `√ε` of the strongest is numerically zero and gets the
    /// strongest's `D` (its parameter stays at the prior's; its roundoff is not
    /// promoted to a signal).
    ///
    /// Every parameter gets a value; `Method::Ridge::data_weight` (diagonal of
    /// `(AᵀA + λD²)⁻¹AᵀA`) says how much of it comes from the data, and parameters
    /// not identifiable by the data or with data weight below ½ are marked
    /// [`Status::FromPrior`]. σ is the posterior standard deviation under the
    /// prior `x ~ N(x₀, σ²/λ D⁻²)`: `Cov = σ̂² (AᵀA + λD²)⁻¹`, `σ̂² = ‖r‖² / (m − tr H)`.
    /// `λ → 0` gives OLS; with `λ = 0` directions below the rank tolerance (of `A D⁻¹`)
    /// are left at `x₀`.
    pub fn ridge(&self, x0: &[f64], lambda: f64, opts: &Options) -> Result<Estimate, IdentifyError> {
        self.ridge_regression(x0, lambda, true, opts)
    }

    /// Ridge regression with the plain penalty `λ ‖x − x₀‖²` (`D = I` in
    /// [`Accumulator::ridge`]): `λ` then carries the units of `AᵀA`, and each
    /// parameter is pulled in proportion to its units. The batch form of
    /// [`super::Rls`] started at `x₀` with `P₀ = I/λ`.
    pub fn ridge_unscaled(&self, x0: &[f64], lambda: f64, opts: &Options) -> Result<Estimate, IdentifyError> {
        self.ridge_regression(x0, lambda, false, opts)
    }

    fn ridge_regression(
        &self,
        x0: &[f64],
        lambda: f64,
        column_scaling: bool,
        opts: &Options,
    ) -> Result<Estimate, IdentifyError> {
        let p = self.n_params();
        check_len(x0, p, "prior x0")?;
        check_finite_vector(x0, Input::Prior)?;
        if !(lambda.is_finite() && lambda >= 0.0) {
            return Err(IdentifyError::InvalidArgument {
                what: "ridge weight λ",
                reason: format!("{lambda}: must be finite and ≥ 0"),
            });
        }
        let factors = self.factors()?;
        let tri = combine(&factors, None, p);
        let sub = Subspace::analyse(tri.r.as_ref(), tri.rows, tri.floor, opts)?;
        // In u = D (x − x₀): min ‖R D⁻¹ u − (z − R x₀)‖² + λ ‖u‖².
        let d: Vec<f64> = if column_scaling {
            column_scales(&sub.column_norms)
        } else {
            vec![1.0; p]
        };
        let scaled_sub;
        let ssub = if column_scaling {
            let rs = Mat::from_fn(p, p, |i, j| tri.r[(i, j)] / d[j]);
            scaled_sub = Subspace::analyse(rs.as_ref(), tri.rows, tri.floor, opts)?;
            &scaled_sub
        } else {
            &sub
        };
        // u = V diag(sᵢ/(sᵢ²+λ)) Uᵀ (z − R x₀).
        let rx0 = super::dense::mat_vec(tri.r.as_ref(), x0);
        let b: Vec<f64> = tri.z.iter().zip(&rx0).map(|(z, r)| z - r).collect();
        let mut x = x0.to_vec();
        let mut trace_h = 0.0;
        let mut post = vec![0.0; p];
        let mut share = vec![0.0; p];
        for k in 0..p {
            let s = ssub.s[k];
            let used = if lambda > 0.0 { true } else { k < ssub.rank };
            if !used {
                continue;
            }
            let c = (0..p).map(|i| ssub.u[(i, k)] * b[i]).sum::<f64>() * s / (s * s + lambda);
            for i in 0..p {
                x[i] += ssub.v[(i, k)] * c / d[i];
            }
            trace_h += s * s / (s * s + lambda);
            post[k] = 1.0 / (s * s + lambda);
            share[k] = s * s / (s * s + lambda);
        }
        // diag(D⁻¹ M D) = diag(M): the data weights are those of the scaled problem.
        let data_weight: Vec<f64> = (0..p)
            .map(|j| (0..p).map(|k| ssub.v[(j, k)].powi(2) * share[k]).sum::<f64>())
            .collect();
        let dof = tri.rows as f64 - trace_h;
        let residuals = Residuals::from_factors(&factors, &x, dof);
        let noise = (dof > 0.0).then(|| (residuals.sum_of_squares / dof).sqrt());
        let cov = noise.map(|s| {
            let mut c = scale(super::dense::scaled_gram(ssub.v.as_ref(), &post), s * s);
            for j in 0..p {
                for i in 0..p {
                    c[(i, j)] /= d[i] * d[j];
                }
            }
            c
        });
        let status = sub
            .status
            .iter()
            .zip(&data_weight)
            .map(|(st, &w)| {
                if *st == Status::Identified && w >= 0.5 {
                    Status::Identified
                } else {
                    Status::FromPrior
                }
            })
            .collect();
        let method = Method::Ridge {
            lambda,
            column_scaling,
            data_weight,
        };
        Ok(Estimate::assemble(
            method,
            sub,
            x,
            cov,
            status,
            residuals,
            noise,
            opts.identifiability_tolerance,
        ))
    }
}

/// The column scales `D` of the column-scaled estimators: the column norms, except
/// that a column below `√ε` of the largest norm is numerically zero (roundoff of a
/// parameter that has no effect) and is divided by the largest norm, so that it
/// stays as negligible next to the others as it was (1 when every column is zero).
fn column_scales(norms: &[f64]) -> Vec<f64> {
    let top = norms.iter().cloned().fold(0.0, f64::max);
    if top == 0.0 {
        return vec![1.0; norms.len()];
    }
    let negligible = f64::EPSILON.sqrt() * top;
    norms.iter().map(|&n| if n > negligible { n } else { top }).collect()
}

/// Per-channel residual variances with each channel's share of the degrees of
/// freedom, floored at `1e-12` of the largest (all 1 when every residual is zero).
fn channel_variances(factors: &[super::accumulate::Factor], x: &[f64], rank: usize) -> Vec<f64> {
    let m: usize = factors.iter().map(|f| f.rows).sum();
    let rss = channel_rss(factors, x);
    let mut var: Vec<f64> = rss
        .iter()
        .zip(factors)
        .map(|(s, f)| {
            if f.rows == 0 {
                0.0
            } else {
                s / (f.rows as f64 * (m - rank) as f64 / m as f64)
            }
        })
        .collect();
    let max = var.iter().cloned().fold(0.0, f64::max);
    for v in &mut var {
        *v = if max == 0.0 { 1.0 } else { v.max(1e-12 * max) };
    }
    var
}

pub(crate) fn scale(mut m: Mat<f64>, s: f64) -> Mat<f64> {
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            m[(i, j)] *= s;
        }
    }
    m
}
