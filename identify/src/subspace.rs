//! Rank, null space and identifiable combinations of a regressor, from the SVD of
//! its compressed triangle `R` (same singular values and right singular vectors as
//! `A`).
//!
//! Rank: `#{σᵢ > tol}`. Null space: the right singular vectors past the rank.
//! Combinations: `p − r` *dependent* parameters are picked by Gram–Schmidt with
//! threshold pivoting on the rows of the null-space basis (preferring later
//! parameters, so a column that is a combination of earlier ones is the one
//! expressed through them), the basis is normalised to the identity on them, and each
//! remaining *lead* parameter `k` gives the identifiable combination
//! `β_k = x_k − Σ_l N_{k,l} x_{D_l}`, the base parameter of Gautier's grouping.

use faer::prelude::*;
use faer::{Mat, MatRef};

use super::error::IdentifyError;
use super::estimate::Status;
use super::{Options, RankTolerance};

#[derive(Clone, Debug)]
pub(crate) struct Subspace {
    pub rank: usize,
    pub tolerance: f64,
    /// All `p` singular values, nonincreasing.
    pub s: Vec<f64>,
    pub u: Mat<f64>,
    pub v: Mat<f64>,
    /// Column norms of `A` (read off the triangle), for unit-free comparisons.
    pub column_norms: Vec<f64>,
    /// Identifiable combinations, each lead first with coefficient 1, sorted by lead.
    pub combinations: Vec<Vec<(usize, f64)>>,
    pub status: Vec<Status>,
}

impl Subspace {
    /// Analyses the `p × p` triangle of a problem with `rows` data rows, whose
    /// accumulation resolves singular values down to `floor · σ₁` (0: all of them;
    /// see [`super::Accumulation`]).
    pub fn analyse(r: MatRef<'_, f64>, rows: usize, floor: f64, opts: &Options) -> Result<Self, IdentifyError> {
        let p = r.ncols();
        let svd = r.svd().map_err(|_| IdentifyError::DecompositionFailed {
            what: "SVD of the regressor",
        })?;
        let s: Vec<f64> = (0..p).map(|i| svd.S().column_vector()[i]).collect();
        let s1 = s.first().copied().unwrap_or(0.0);
        let tolerance = match opts.rank_tolerance {
            RankTolerance::Default => rows.max(p) as f64 * f64::EPSILON * s1,
            RankTolerance::Relative(t) => t * s1,
            RankTolerance::Absolute(t) => t,
        }
        .max(floor * s1);
        let rank = s.iter().filter(|&&si| si > tolerance).count();
        if rank == 0 {
            return Err(IdentifyError::RankZero { tolerance });
        }

        let column_norms: Vec<f64> = (0..p)
            .map(|j| (0..p).map(|i| r[(i, j)] * r[(i, j)]).sum::<f64>().sqrt())
            .collect();
        let mut sub = Self {
            rank,
            tolerance,
            s,
            u: svd.U().to_owned(),
            v: svd.V().to_owned(),
            column_norms,
            combinations: Vec::new(),
            status: vec![Status::Identified; p],
        };
        sub.group(opts.identifiability_tolerance);
        Ok(sub)
    }

    pub fn n_params(&self) -> usize {
        self.s.len()
    }

    pub fn condition_number(&self) -> f64 {
        self.s[0] / self.s[self.rank - 1]
    }

    /// Orthonormal null-space basis, one vector per entry.
    pub fn null_space(&self) -> Vec<Vec<f64>> {
        let p = self.n_params();
        (self.rank..p)
            .map(|k| (0..p).map(|i| self.v[(i, k)]).collect())
            .collect()
    }

    /// The minimum-norm least-squares solution `V₁ Σ₁⁻¹ U₁ᵀ z`.
    pub fn min_norm_solution(&self, z: &[f64]) -> Vec<f64> {
        let p = self.n_params();
        let mut x = vec![0.0; p];
        for k in 0..self.rank {
            let c = (0..p).map(|i| self.u[(i, k)] * z[i]).sum::<f64>() / self.s[k];
            for i in 0..p {
                x[i] += self.v[(i, k)] * c;
            }
        }
        x
    }

    /// `(AᵀA)⁺ = V₁ Σ₁⁻² V₁ᵀ`, the unit-variance covariance on the identifiable subspace.
    pub fn unit_covariance(&self) -> Mat<f64> {
        let w: Vec<f64> = self.s[..self.rank].iter().map(|s| 1.0 / (s * s)).collect();
        super::dense::scaled_gram(self.v.as_ref(), &w)
    }

    /// Whether the functional `cᵀx` is determined by the data: `c` is a combination
    /// of the identifiable combinations. Write `c = Σ_k c_k β_k` over the leads `k`;
    /// what is left lives on dependent parameters and must vanish, measured in
    /// column-norm-scaled parameters so the answer does not depend on units.
    pub fn is_identifiable(&self, c: &[f64], tol: f64) -> bool {
        let mut rest = c.to_vec();
        for terms in &self.combinations {
            let gamma = c[terms[0].0];
            for &(j, v) in terms {
                rest[j] -= gamma * v;
            }
        }
        let floor = self.column_norms.iter().cloned().fold(0.0, f64::max) * f64::EPSILON;
        let scaled = |v: &[f64]| -> f64 {
            v.iter()
                .zip(&self.column_norms)
                .map(|(x, n)| (x / n.max(floor).max(f64::MIN_POSITIVE)).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        scaled(&rest) <= tol * scaled(c)
    }

    fn group(&mut self, tol: f64) {
        let p = self.n_params();
        let q = p - self.rank;
        if q == 0 {
            self.combinations = (0..p).map(|k| vec![(k, 1.0)]).collect();
            return;
        }
        let w = self.v.as_ref().subcols(self.rank, q);
        // Gram–Schmidt on the rows of the null basis with threshold pivoting: the
        // dependent parameter is the largest index whose residual row is within
        // PIVOT_THRESHOLD of the largest. By matroid duality this makes the leads the
        // leftmost independent columns of A (Gautier's convention: a column that is
        // a combination of earlier ones is expressed through them), while keeping
        // the normalising matrix well conditioned.
        const PIVOT_THRESHOLD: f64 = 0.25;
        let mut rows: Vec<Vec<f64>> = (0..p).map(|i| (0..q).map(|k| w[(i, k)]).collect()).collect();
        let mut dependent = Vec::with_capacity(q);
        let mut chosen = vec![false; p];
        for _ in 0..q {
            let norms: Vec<f64> = rows.iter().map(|r| super::dense::norm(r)).collect();
            let max = (0..p).filter(|&i| !chosen[i]).map(|i| norms[i]).fold(0.0, f64::max);
            let j = (0..p)
                .rev()
                .find(|&i| !chosen[i] && norms[i] >= PIVOT_THRESHOLD * max)
                .expect("q ≤ p − #chosen");
            chosen[j] = true;
            dependent.push(j);
            let n = norms[j];
            if n > 0.0 {
                let u: Vec<f64> = rows[j].iter().map(|x| x / n).collect();
                for row in rows.iter_mut() {
                    let c = super::dense::dot(row, &u);
                    for (x, uk) in row.iter_mut().zip(&u) {
                        *x -= c * uk;
                    }
                }
            }
        }
        dependent.sort_unstable();
        // N' = W (W_D)⁻¹, via (W_D)ᵀ N'ᵀ = Wᵀ.
        let wd_t = Mat::from_fn(q, q, |a, b| w[(dependent[b], a)]);
        let n_t = wd_t.full_piv_lu().solve(w.transpose().to_owned());
        let mut appears = vec![false; p];
        let mut combinations = Vec::new();
        for k in 0..p {
            if chosen[k] {
                continue;
            }
            let mut terms = vec![(k, 1.0)];
            for (l, &dl) in dependent.iter().enumerate() {
                let coef = -n_t[(l, k)];
                // Unit-free size: the coefficient in column-norm-scaled parameters
                // (raw when the dependent column is the smaller, so the roundoff
                // coefficients of a zero column are dropped).
                let scale = self.column_norms[dl].max(self.column_norms[k]);
                if coef.abs() * self.column_norms[k] > tol * scale {
                    terms.push((dl, coef));
                    appears[dl] = true;
                }
            }
            combinations.push(terms);
        }
        for terms in &combinations {
            let k = terms[0].0;
            self.status[k] = if terms.len() == 1 {
                Status::Identified
            } else {
                Status::InCombination
            };
        }
        for &dl in &dependent {
            self.status[dl] = if appears[dl] {
                Status::InCombination
            } else {
                Status::NoEffect
            };
        }
        self.combinations = combinations;
    }
}
