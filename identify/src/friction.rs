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

    /// Joint `j`'s Coulomb column `tanh(q̇_j/ε)` as the residual needs it.
    fn column(&self, j: usize, epsilon: f64) -> Column {
        let (p, joint) = (self.p, &self.joints[j]);
        let mut g = vec![0.0; p];
        let (mut cc, mut f) = (0.0, 0.0);
        for (k, row) in joint.rows.chunks_exact(p).enumerate() {
            let t = (joint.v[k] / epsilon).tanh();
            for (g, a) in g.iter_mut().zip(row) {
                *g += t * a;
            }
            cc += t * t;
            f += t * joint.tau[k];
        }
        let w: Vec<f64> = self
            .projector
            .chunks_exact(p)
            .map(|row| crate::dense::dot(row, &g))
            .collect();
        Column { w, cc, f }
    }

    /// The RMS residual with the Coulomb columns `columns` (one per joint).
    fn rms_of(&self, columns: &[Column]) -> f64 {
        let n = columns.len();
        // S = diag(cᵀc) − wᵀw, f − wᵀu.
        let s = faer::Mat::from_fn(n, n, |i, j| {
            let d = if i == j { columns[i].cc } else { 0.0 };
            d - crate::dense::dot(&columns[i].w, &columns[j].w)
        });
        let f: Vec<f64> = columns.iter().map(|c| c.f - crate::dense::dot(&c.w, &self.u)).collect();
        let Ok(eigen) = s.self_adjoint_eigen(faer::Side::Lower) else {
            return f64::INFINITY;
        };
        let (values, vectors) = (eigen.S().column_vector(), eigen.U());
        let scale = columns.iter().map(|c| c.cc).fold(0.0, f64::max);
        let mut explained = 0.0;
        for k in 0..n {
            if values[k] > 1e-12 * scale {
                let c: f64 = (0..n).map(|i| vectors[(i, k)] * f[i]).sum();
                explained += c * c / values[k];
            }
        }
        ((self.rss0 - explained).max(0.0) / self.rows.max(1) as f64).sqrt()
    }

    /// The RMS residual of the fit with `Fc_j·tanh(q̇_j/ε_j)` (`epsilon`: one per
    /// joint).
    pub(crate) fn rms(&self, epsilon: &[f64]) -> f64 {
        let columns: Vec<Column> = (0..self.joints.len()).map(|j| self.column(j, epsilon[j])).collect();
        self.rms_of(&columns)
    }

    /// One `ε` per joint, each within [`EPSILON_RANGE`], by the fit residual: the
    /// best common `ε` first ([`best_epsilon`]), then each joint's in turn with the
    /// others held, [`EPSILON_SWEEPS`] times over the joints. A joint's `ε` changes
    /// only where it lowers the residual.
    pub(crate) fn best_epsilons(&self) -> Vec<f64> {
        let n = self.joints.len();
        let (common, mut best) = best_epsilon(|e| self.rms(&vec![e; n]));
        let mut epsilons = vec![common; n];
        let mut columns: Vec<Column> = (0..n).map(|j| self.column(j, common)).collect();
        for _ in 0..EPSILON_SWEEPS {
            for j in 0..n {
                let (e, r) = best_epsilon(|e| {
                    let mut trial = columns.clone();
                    trial[j] = self.column(j, e);
                    self.rms_of(&trial)
                });
                if r < best {
                    (epsilons[j], best) = (e, r);
                    columns[j] = self.column(j, e);
                }
            }
        }
        epsilons
    }
}

/// Sweeps over the joints of the per-joint `ε` search (`auto` friction).
pub const EPSILON_SWEEPS: usize = 2;

/// A Coulomb column's products: `w = Σ_r⁻¹V_rᵀA₀ᵀc`, `cᵀc`, `cᵀy`.
#[derive(Clone)]
struct Column {
    w: Vec<f64>,
    cc: f64,
    f: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The residual from the factored columns equals a direct least-squares fit of
    /// every column, rank-deficient `A₀` included.
    #[test]
    fn the_factored_residual_is_that_of_the_direct_fit() {
        use dyngen_model::sample::SplitMix64;
        let (n, p, samples) = (3, 9, 200);
        let mut rng = SplitMix64::new(4);
        let mut joints: Vec<JointRows> = (0..n)
            .map(|_| JointRows {
                rows: Vec::new(),
                v: Vec::new(),
                tau: Vec::new(),
            })
            .collect();
        let mut acc = crate::Accumulator::new(p);
        // The Coulomb columns are 5, 6, 7 (one per joint); column 8 is column 0 +
        // column 1.
        let coulomb = |j: usize| 5 + j;
        for _ in 0..samples {
            for joint in joints.iter_mut() {
                let mut row: Vec<f64> = (0..p).map(|_| rng.uniform(-1.0, 1.0)).collect();
                for c in 5..8 {
                    row[c] = 0.0;
                }
                row[8] = row[0] + row[1];
                let v = rng.uniform(-0.3, 0.3);
                let tau = row.iter().sum::<f64>() + 2.0 * (v / 0.05).tanh() + rng.uniform(-0.1, 0.1);
                acc.push_row(&row, tau).unwrap();
                joint.rows.extend_from_slice(&row);
                joint.v.push(v);
                joint.tau.push(tau);
            }
        }
        let fit = SmoothingFit::new(joints, &acc, &crate::Options::default()).unwrap();
        for epsilon in [[0.05, 0.05, 0.05], [0.01, 0.2, 0.05], [0.3, 0.002, 0.1]] {
            let mut direct = crate::Accumulator::new(p);
            for (j, joint) in fit.joints.iter().enumerate() {
                for (k, row) in joint.rows.chunks_exact(p).enumerate() {
                    let mut row = row.to_vec();
                    row[coulomb(j)] = (joint.v[k] / epsilon[j]).tanh();
                    direct.push_row(&row, joint.tau[k]).unwrap();
                }
            }
            let direct = direct.ols(&crate::Options::default()).unwrap();
            let rss = direct.residuals.sum_of_squares;
            let factored = fit.rms(&epsilon).powi(2) * (n * samples) as f64;
            assert!((factored / rss - 1.0).abs() < 1e-9, "{epsilon:?}: {factored} {rss}");
        }
        let best = fit.best_epsilons();
        assert!(best.iter().all(|e| (e / 0.05 - 1.0).abs() < 0.2), "{best:?}");
    }

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
