//! The Coulomb term's smoothing, identified: `Fc·tanh(q̇/ε)` is linear in `Fc` but
//! not in `ε`, so `ε` is found by a one-dimensional search on the least-squares
//! residual (variable projection: every trial `ε` is a complete linear fit). Real
//! joints stick and creep around velocity reversals, where `sign(q̇)` jumps and the
//! measured torque does not; the smoothing that fits the data best is the one the
//! data support.

/// The search range of `ε` (rad/s or m/s): below it `tanh` is a sign at any logged
/// velocity resolution; above it the term is a second viscous friction.
pub const EPSILON_RANGE: (f64, f64) = (1e-3, 0.3);

/// The `ε` in [`EPSILON_RANGE`] minimising `residual(ε)` (the RMS residual of a
/// linear fit with `Coulomb::Smooth { epsilon: ε }`): a grid of 13 points evenly
/// spaced in `log ε`, then golden-section refinement around the best point (to 1 %
/// in `ε`). Returns the `ε` and its residual; `residual` must be finite.
pub fn best_epsilon(mut residual: impl FnMut(f64) -> f64) -> (f64, f64) {
    let (lo, hi) = (EPSILON_RANGE.0.ln(), EPSILON_RANGE.1.ln());
    let steps = 12;
    let grid: Vec<f64> = (0..=steps).map(|k| lo + (hi - lo) * k as f64 / steps as f64).collect();
    let values: Vec<f64> = grid.iter().map(|&x| residual(x.exp())).collect();
    let best = (0..=steps)
        .min_by(|&a, &b| values[a].total_cmp(&values[b]))
        .unwrap_or(0);
    let (mut a, mut b) = (grid[best.saturating_sub(1)], grid[(best + 1).min(steps)]);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (residual(c.exp()), residual(d.exp()));
    while b - a > 0.01 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = residual(c.exp());
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = residual(d.exp());
        }
    }
    let (x, f) = if fc < fd { (c, fc) } else { (d, fd) };
    if values[best] < f {
        (grid[best].exp(), values[best])
    } else {
        (x.exp(), f)
    }
}

/// One joint's rows of the sampled regressor (its Coulomb column at 0), row-major
/// `p` wide, with the joint's velocity and torque at each.
pub(crate) struct JointRows {
    pub rows: Vec<f64>,
    pub v: Vec<f64>,
    pub tau: Vec<f64>,
}

/// The least-squares residual as a function of the Coulomb smoothing, without
/// evaluating the regressor again: the columns that do not depend on `ε` (`A₀`,
/// every joint's Coulomb column at 0) are factored once, `A₀ = Q₀R₀` with the SVD
/// `R₀ = UΣVᵀ` (rank `r`), and a trial `ε` only builds the Coulomb columns `C`, each
/// non-zero in its own joint's rows. With `w = Σ_r⁻¹V_rᵀA₀ᵀC`, the Schur complement
/// `S = CᵀC − wᵀw` and `f = Cᵀy − wᵀU_rᵀQ₀ᵀy`, the residual is
/// `‖y − A₀x₀‖² − fᵀS⁺f`: `O(n·N·p)` per trial for `N` samples, `n` joints and `p`
/// parameters, against a regressor evaluation and a QR of every row.
pub(crate) struct SmoothingFit {
    p: usize,
    /// `Σ_r⁻¹V_rᵀ`, `r × p` row-major.
    projector: Vec<f64>,
    /// `U_rᵀQ₀ᵀy`.
    u: Vec<f64>,
    /// `‖y − A₀x₀‖²`.
    rss0: f64,
    rows: usize,
    joints: Vec<JointRows>,
}

impl SmoothingFit {
    /// From the joints' rows and the accumulation of the same rows (`acc`).
    pub(crate) fn new(
        joints: Vec<JointRows>,
        acc: &crate::Accumulator,
        opts: &crate::Options,
    ) -> Result<Self, crate::IdentifyError> {
        let p = acc.n_params();
        let tri = crate::accumulate::combine(&acc.factors()?, None, p);
        let sub = crate::subspace::Subspace::analyse(tri.r.as_ref(), tri.rows, tri.floor, opts)?;
        let r = sub.rank;
        let projector: Vec<f64> = (0..r)
            .flat_map(|k| {
                let (v, s) = (&sub.v, sub.s[k]);
                (0..p).map(move |i| v[(i, k)] / s)
            })
            .collect();
        let u: Vec<f64> = (0..r).map(|k| (0..p).map(|i| sub.u[(i, k)] * tri.z[i]).sum()).collect();
        let z2: f64 = tri.z.iter().map(|z| z * z).sum();
        let u2: f64 = u.iter().map(|u| u * u).sum();
        Ok(SmoothingFit {
            p,
            projector,
            u,
            rss0: tri.rho2 + (z2 - u2).max(0.0),
            rows: tri.rows,
            joints,
        })
    }

    /// The RMS residual of the fit with `Fc_j·tanh(q̇_j/ε_j)` (`epsilon`: one per
    /// joint).
    pub(crate) fn rms(&self, epsilon: &[f64]) -> f64 {
        let (p, n, r) = (self.p, self.joints.len(), self.u.len());
        let mut w = vec![0.0; r * n];
        let mut cc = vec![0.0; n];
        let mut f = vec![0.0; n];
        let mut g = vec![0.0; p];
        for (j, joint) in self.joints.iter().enumerate() {
            g.fill(0.0);
            let (mut tt, mut ty) = (0.0, 0.0);
            for (k, row) in joint.rows.chunks_exact(p).enumerate() {
                let t = (joint.v[k] / epsilon[j]).tanh();
                for (g, a) in g.iter_mut().zip(row) {
                    *g += t * a;
                }
                tt += t * t;
                ty += t * joint.tau[k];
            }
            cc[j] = tt;
            f[j] = ty;
            for k in 0..r {
                w[k * n + j] = crate::dense::dot(&self.projector[k * p..(k + 1) * p], &g);
            }
        }
        // S = diag(cc) − wᵀw, f −= wᵀu.
        let s = faer::Mat::from_fn(n, n, |i, j| {
            let d = if i == j { cc[i] } else { 0.0 };
            d - (0..r).map(|k| w[k * n + i] * w[k * n + j]).sum::<f64>()
        });
        for (j, f) in f.iter_mut().enumerate() {
            *f -= (0..r).map(|k| w[k * n + j] * self.u[k]).sum::<f64>();
        }
        let Ok(eigen) = s.self_adjoint_eigen(faer::Side::Lower) else {
            return f64::INFINITY;
        };
        let (values, vectors) = (eigen.S().column_vector(), eigen.U());
        let scale = cc.iter().copied().fold(0.0, f64::max);
        let mut explained = 0.0;
        for k in 0..n {
            if values[k] > 1e-12 * scale {
                let c: f64 = (0..n).map(|i| vectors[(i, k)] * f[i]).sum();
                explained += c * c / values[k];
            }
        }
        ((self.rss0 - explained).max(0.0) / self.rows.max(1) as f64).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_a_smooth_residual() {
        let (eps, r) = best_epsilon(|e: f64| 1.0 + (e.ln() - 0.02f64.ln()).powi(2));
        assert!((eps / 0.02 - 1.0).abs() < 0.01, "{eps}");
        assert!((r - 1.0).abs() < 1e-3);
        // At the edge of the range.
        let (eps, _) = best_epsilon(|e: f64| e);
        assert!((eps / EPSILON_RANGE.0 - 1.0).abs() < 0.01, "{eps}");
    }
}
