//! The cross-validation of the model choice from one pass of one regressor.
//!
//! Every candidate the choice scores is a subset of the columns of one wide
//! regressor (the rigid bodies, every joint's `[Ia, Fv, Fc, F0]`, every extra term
//! allowed), plus at most one more column per joint that lives in that joint's rows
//! only (a Coulomb smoothing `tanh(q̇/ε)`, a Stribeck term, the load-dependent
//! friction). The rows of the wide regressor are evaluated once, and each time
//! block keeps per joint the Gram matrix `[A y]ᵀ[A y]` of its rows: a fit on every
//! block but one is the sum of their Gram matrices restricted to the candidate's
//! columns, and its error on the block left out is a quadratic form in that
//! block's Gram matrix. Scoring a candidate costs a Cholesky factorisation per
//! block, not a pass over the data.
//!
//! A joint's own column enters by the Schur complement of the factored columns, so
//! a search over a joint's smoothing or Stribeck velocity costs a few triangular
//! solves per trial.
//!
//! The normal equations carry a ridge of [`RIDGE`] times their diagonal: the
//! directions the data cannot see (a rotor inertia on the same axis as its link's
//! inertia, say) get the minimum-norm share a rank-revealing solver would give
//! them, and a prediction on the held-out block (which cannot see them either)
//! does not depend on it.

use crate::accumulate::in_parallel;
use crate::data::Trajectory;
use crate::mim::TorqueRegressor;
use crate::pipeline::PipelineError;
use crate::{IdentifyError, Input};
use dyngen_reference::Dynamics;
use faer::prelude::Solve;
use faer::{Mat, Side};

/// The ridge on the normal equations, relative to their diagonal (up to 10⁶ times
/// more where rounding makes them indefinite).
const RIDGE: f64 = 1e-12;

/// One joint's rows in one time block: the regressor on the columns the joint's
/// rows can be non-zero in, then the torque.
pub(crate) struct JointRows {
    /// The wide regressor's columns, then `p` (the torque).
    columns: Vec<usize>,
    /// `rows × columns.len()`.
    x: Mat<f64>,
    /// The joint's velocity at each row.
    pub v: Vec<f64>,
    /// Rows the fit takes (all but those below `--exclude-below`); `None`: all.
    keep: Option<Vec<bool>>,
    /// `xᵀx` over all rows.
    gram: Mat<f64>,
}

impl JointRows {
    /// `x` (`rows × columns.len()`) on the wide regressor's `columns`, the last of
    /// which is the torque's; the rows `keep` says (all with `None`) are fitted.
    fn new(columns: Vec<usize>, x: Mat<f64>, v: Vec<f64>, keep: Option<Vec<bool>>) -> JointRows {
        let gram = x.transpose() * &x;
        JointRows {
            columns,
            x,
            v,
            keep,
            gram,
        }
    }

    /// `Σ_c x[r, c]·params[c]` over the regressor columns `c < params.len()`, per row.
    pub(crate) fn times(&self, params: &[f64]) -> Vec<f64> {
        let used: Vec<(usize, f64)> = self
            .columns
            .iter()
            .enumerate()
            .filter(|(_, &c)| c < params.len())
            .map(|(k, &c)| (k, params[c]))
            .filter(|(_, w)| *w != 0.0)
            .collect();
        (0..self.x.nrows())
            .map(|r| used.iter().map(|&(k, w)| self.x[(r, k)] * w).sum())
            .collect()
    }

    /// The products of the columns `t` (`rows × m`) with this block's regressor
    /// and torque, of the rows the fit takes and of all rows.
    fn cross(&self, t: &Mat<f64>, width: usize) -> Vec<(Cross, Cross)> {
        let all = self.x.transpose() * t;
        let fit = match &self.keep {
            None => None,
            Some(keep) => {
                let masked = Mat::from_fn(t.nrows(), t.ncols(), |r, c| if keep[r] { t[(r, c)] } else { 0.0 });
                Some((self.x.transpose() * &masked, masked))
            }
        };
        (0..t.ncols())
            .map(|e| {
                let scatter = |m: &Mat<f64>, col: &Mat<f64>| {
                    let mut xc = vec![0.0; width];
                    for (k, &c) in self.columns.iter().enumerate() {
                        xc[c] = m[(k, e)];
                    }
                    let cc = (0..col.nrows()).map(|r| col[(r, e)] * col[(r, e)]).sum();
                    Cross { xc, cc }
                };
                let all = scatter(&all, t);
                let fit = match &fit {
                    None => all.clone(),
                    Some((m, masked)) => scatter(m, masked),
                };
                (fit, all)
            })
            .collect()
    }
}

/// A column's products with the wide regressor and the torque (`xc`, the torque's
/// at index `p`) and with itself (`cc`).
#[derive(Clone)]
struct Cross {
    xc: Vec<f64>,
    cc: f64,
}

/// One more column of one joint, in every block: its products over the rows the fit
/// takes and over all rows.
pub(crate) struct JointColumn {
    fit: Vec<Cross>,
    all: Vec<Cross>,
}

/// The rows of the wide regressor in every time block, and their Gram matrices.
pub(crate) struct Blocks {
    /// Columns of the wide regressor (the torque is index `p` of the Gram matrices).
    p: usize,
    n: usize,
    /// `[block][joint]`.
    rows: Vec<Vec<JointRows>>,
    /// Per block, the Gram matrix of the rows the fit takes, over every joint.
    fit: Vec<Mat<f64>>,
    /// Per block, the Gram matrix of all rows, over every joint.
    all: Vec<Mat<f64>>,
    /// Per block and joint, `‖τ_j‖²` over all rows.
    tau2: Vec<Vec<f64>>,
}

impl Blocks {
    /// The rows of `regressor` at the samples `blocks` of `traj` (one list of sample
    /// indices per block), a joint's rows below `exclude_below` left out of the fits.
    pub(crate) fn new(
        dynamics: &dyn Dynamics,
        traj: &Trajectory,
        blocks: &[Vec<usize>],
        regressor: &TorqueRegressor,
        exclude_below: Option<f64>,
    ) -> Result<Blocks, PipelineError> {
        let (n, model) = (dynamics.nv(), dynamics.model());
        let p = regressor.columns(model);
        let support: Vec<Vec<usize>> = match regressor.row_support(model) {
            Some(s) => s
                .into_iter()
                .map(|mut cols| {
                    cols.sort_unstable();
                    cols.push(p);
                    cols
                })
                .collect(),
            None => vec![(0..=p).collect(); n],
        };
        let built = in_parallel(blocks.len(), |b| -> Result<Vec<JointRows>, PipelineError> {
            let samples = &blocks[b];
            let mut y = vec![0.0; n * p];
            let mut data: Vec<Vec<f64>> = support
                .iter()
                .map(|s| Vec::with_capacity(s.len() * samples.len()))
                .collect();
            let mut v = vec![Vec::with_capacity(samples.len()); n];
            for &k in samples {
                let (q, vk, a) = crate::pipeline::state(traj, k);
                regressor.eval(dynamics, q, vk, a, &mut y);
                let tau = traj.tau(k);
                for j in 0..n {
                    let row = &y[j * p..(j + 1) * p];
                    data[j].extend(support[j].iter().map(|&c| if c == p { tau[j] } else { row[c] }));
                    v[j].push(vk[j]);
                }
                let bad = match y.iter().position(|x| !x.is_finite()) {
                    Some(i) => Some((Input::Regressor, i / p, i % p)),
                    None => tau
                        .iter()
                        .position(|x| !x.is_finite())
                        .map(|j| (Input::Observation, j, 0)),
                };
                if let Some((input, row, column)) = bad {
                    return Err(PipelineError::Identify {
                        at: Some(traj.location(k)),
                        error: IdentifyError::NonFinite { input, row, column },
                    });
                }
            }
            Ok((0..n)
                .map(|j| {
                    let m = support[j].len();
                    let x = Mat::from_fn(samples.len(), m, |r, c| data[j][r * m + c]);
                    let keep = exclude_below.map(|speed| v[j].iter().map(|x| x.abs() >= speed).collect());
                    JointRows::new(support[j].clone(), x, std::mem::take(&mut v[j]), keep)
                })
                .collect())
        });
        Ok(Blocks::from_rows(p, built.into_iter().collect::<Result<_, _>>()?))
    }

    /// The blocks of the rows `rows` (`[block][joint]`) of a regressor of `p`
    /// columns.
    fn from_rows(p: usize, rows: Vec<Vec<JointRows>>) -> Blocks {
        let width = p + 1;
        let grams = |fit: bool| -> Vec<Mat<f64>> {
            rows.iter()
                .map(|block| {
                    let mut sum = Mat::zeros(width, width);
                    for joint in block {
                        let masked = match (&joint.keep, fit) {
                            (Some(keep), true) => {
                                let x = Mat::from_fn(joint.x.nrows(), joint.x.ncols(), |r, c| {
                                    if keep[r] {
                                        joint.x[(r, c)]
                                    } else {
                                        0.0
                                    }
                                });
                                Some(x.transpose() * &x)
                            }
                            _ => None,
                        };
                        let gram = masked.as_ref().unwrap_or(&joint.gram);
                        for (a, &ca) in joint.columns.iter().enumerate() {
                            for (c, &cc) in joint.columns.iter().enumerate() {
                                sum[(ca, cc)] += gram[(a, c)];
                            }
                        }
                    }
                    sum
                })
                .collect()
        };
        let (fit, all) = (grams(true), grams(false));
        let tau2 = rows
            .iter()
            .map(|block| {
                block
                    .iter()
                    .map(|j| j.gram[(j.columns.len() - 1, j.columns.len() - 1)])
                    .collect()
            })
            .collect();
        Blocks {
            p,
            n: rows.first().map_or(0, Vec::len),
            rows,
            fit,
            all,
            tau2,
        }
    }

    pub(crate) fn blocks(&self) -> usize {
        self.rows.len()
    }

    /// Joint `j`'s velocities, every block in turn.
    pub(crate) fn velocities(&self, j: usize) -> Vec<f64> {
        self.rows.iter().flat_map(|b| b[j].v.iter().copied()).collect()
    }

    /// Joint `j`'s rows in block `b`.
    pub(crate) fn rows(&self, b: usize, j: usize) -> &JointRows {
        &self.rows[b][j]
    }

    /// Columns of joint `j` given per row by each of `columns` (functions of the
    /// joint's velocity), one [`JointColumn`] each.
    pub(crate) fn columns_of_velocity(&self, j: usize, columns: &[&dyn Fn(f64) -> f64]) -> Vec<JointColumn> {
        let per_block: Vec<Vec<(Cross, Cross)>> = (0..self.blocks())
            .map(|b| {
                let rows = &self.rows[b][j];
                let t = Mat::from_fn(rows.v.len(), columns.len(), |r, e| columns[e](rows.v[r]));
                rows.cross(&t, self.p + 1)
            })
            .collect();
        (0..columns.len())
            .map(|e| JointColumn {
                fit: per_block.iter().map(|c| c[e].0.clone()).collect(),
                all: per_block.iter().map(|c| c[e].1.clone()).collect(),
            })
            .collect()
    }

    /// A column of joint `j` with the values `values(b, rows)` in block `b`.
    pub(crate) fn column(&self, j: usize, values: impl Fn(usize, &JointRows) -> Vec<f64>) -> JointColumn {
        let (fit, all) = (0..self.blocks())
            .map(|b| {
                let rows = &self.rows[b][j];
                let v = values(b, rows);
                let t = Mat::from_fn(v.len(), 1, |r, _| v[r]);
                rows.cross(&t, self.p + 1).remove(0)
            })
            .unzip();
        JointColumn { fit, all }
    }

    /// The fits of the wide regressor's columns `columns` (sorted) on every block
    /// but one, for each block.
    pub(crate) fn prepare(&self, columns: &[usize]) -> Result<Folds<'_>, String> {
        let s = columns.len();
        let folds = (0..self.blocks())
            .map(|f| {
                let mut g = Mat::<f64>::zeros(s, s);
                let mut rhs = vec![0.0; s];
                for block in self.fit.iter().enumerate().filter(|(b, _)| *b != f).map(|(_, g)| g) {
                    for (i, &ci) in columns.iter().enumerate() {
                        for (k, &ck) in columns.iter().enumerate() {
                            g[(i, k)] += block[(ci, ck)];
                        }
                        rhs[i] += block[(ci, self.p)];
                    }
                }
                // A larger ridge where rounding leaves a pivot of a direction the
                // data cannot see below zero.
                let l = [RIDGE, 1e3 * RIDGE, 1e6 * RIDGE]
                    .into_iter()
                    .find_map(|ridge| {
                        let mut g = g.clone();
                        for i in 0..s {
                            let d = g[(i, i)];
                            g[(i, i)] = if d > 0.0 { d * (1.0 + ridge) } else { 1.0 };
                        }
                        g.llt(Side::Lower).ok().map(|llt| llt.L().to_owned())
                    })
                    .ok_or_else(|| "the normal equations are not positive definite".to_string())?;
                let mut u = Mat::from_fn(s, 1, |i, _| rhs[i]);
                l.solve_lower_triangular_in_place(u.as_mut());
                Ok(Fold { l, u })
            })
            .collect::<Result<_, String>>()?;
        Ok(Folds {
            blocks: self,
            columns: columns.to_vec(),
            folds,
        })
    }
}

/// One fold's factored normal equations: `L Lᵀ = G` (ridged) and `u = L⁻¹g`.
struct Fold {
    l: Mat<f64>,
    u: Mat<f64>,
}

/// The fits of one set of columns on every block but one, ready to take one more
/// column per joint.
pub(crate) struct Folds<'a> {
    blocks: &'a Blocks,
    columns: Vec<usize>,
    folds: Vec<Fold>,
}

/// A fold's solution: the coefficients of the columns, then of each joint's own
/// column (0 where it has none).
pub(crate) struct Solution {
    pub x: Vec<f64>,
    pub z: Vec<f64>,
}

impl Folds<'_> {
    /// `solution`'s coefficients on the wide regressor's columns (0 off these
    /// folds' columns).
    pub(crate) fn wide(&self, solution: &Solution) -> Vec<f64> {
        let mut w = vec![0.0; self.blocks.p];
        for (&c, &x) in self.columns.iter().zip(&solution.x) {
            w[c] = x;
        }
        w
    }

    /// The fit on every block but `f`, with each joint's own column `added[j]`.
    pub(crate) fn solve(&self, f: usize, added: &[Option<&JointColumn>]) -> Result<Solution, String> {
        let fold = &self.folds[f];
        let (s, n, p) = (self.columns.len(), self.blocks.n, self.blocks.p);
        // The joints' columns' products over the training blocks: A (s × n), d, h.
        let mut a = Mat::<f64>::zeros(s, n);
        let (mut d, mut h) = (vec![1.0; n], vec![0.0; n]);
        for (j, col) in added.iter().enumerate() {
            let Some(col) = col else { continue };
            let mut dd = 0.0;
            for cross in col.fit.iter().enumerate().filter(|(b, _)| *b != f).map(|(_, c)| c) {
                for (i, &c) in self.columns.iter().enumerate() {
                    a[(i, j)] += cross.xc[c];
                }
                dd += cross.cc;
                h[j] += cross.xc[p];
            }
            d[j] = if dd > 0.0 { dd * (1.0 + RIDGE) } else { 1.0 };
        }
        // Schur complement of the factored columns: W = L⁻¹A, S = D − WᵀW,
        // z = S⁻¹(h − Wᵀu), x = L⁻ᵀ(u − W z).
        fold.l.solve_lower_triangular_in_place(a.as_mut());
        let w = a;
        let mut schur = Mat::from_fn(n, n, |i, k| if i == k { d[i] } else { 0.0 });
        schur -= w.transpose() * &w;
        let rhs_z = Mat::from_fn(n, 1, |i, _| h[i]) - w.transpose() * &fold.u;
        let z = schur
            .llt(Side::Lower)
            .map_err(|_| "a joint's own column is a combination of the others".to_string())?
            .solve(&rhs_z);
        let mut x = &fold.u - &w * &z;
        fold.l.transpose().solve_upper_triangular_in_place(x.as_mut());
        let x: Vec<f64> = (0..s).map(|i| x[(i, 0)]).collect();
        let z: Vec<f64> = (0..n).map(|i| z[(i, 0)]).collect();
        if x.iter().chain(&z).any(|v| !v.is_finite()) {
            return Err("the fit is not finite".into());
        }
        Ok(Solution { x, z })
    }

    /// `‖τ̂ − τ‖²` of `solution` on block `f`, per joint or (`per_joint` false) the
    /// sum over the joints as one entry.
    pub(crate) fn held_out(
        &self,
        f: usize,
        solution: &Solution,
        added: &[Option<&JointColumn>],
        per_joint: bool,
    ) -> Vec<f64> {
        let (p, cols) = (self.blocks.p, &self.columns);
        let quadratic = |g: &dyn Fn(usize, usize) -> f64| -> f64 {
            let x = &solution.x;
            let mut e = g(p, p);
            for (i, &ci) in cols.iter().enumerate() {
                e -= 2.0 * x[i] * g(ci, p);
                let mut gx = 0.0;
                for (k, &ck) in cols.iter().enumerate() {
                    gx += g(ci, ck) * x[k];
                }
                e += x[i] * gx;
            }
            e
        };
        // A joint's own column: −2 z (cᵀy − cᵀA x) + z² cᵀc, on its rows only.
        let own = |j: usize| -> f64 {
            match added[j] {
                Some(col) if solution.z[j] != 0.0 => {
                    let cross = &col.all[f];
                    let z = solution.z[j];
                    let ax: f64 = cols.iter().zip(&solution.x).map(|(&c, x)| cross.xc[c] * x).sum();
                    -2.0 * z * (cross.xc[p] - ax) + z * z * cross.cc
                }
                _ => 0.0,
            }
        };
        if per_joint {
            (0..self.blocks.n)
                .map(|j| {
                    let rows = &self.blocks.rows[f][j];
                    let gram = &rows.gram;
                    let mut at = vec![usize::MAX; p + 1];
                    for (k, &c) in rows.columns.iter().enumerate() {
                        at[c] = k;
                    }
                    let g = |a: usize, b: usize| {
                        if at[a] == usize::MAX || at[b] == usize::MAX {
                            0.0
                        } else {
                            gram[(at[a], at[b])]
                        }
                    };
                    (quadratic(&g) + own(j)).max(0.0)
                })
                .collect()
        } else {
            let all = &self.blocks.all[f];
            let e = quadratic(&|a, b| all[(a, b)]) + (0..self.blocks.n).map(own).sum::<f64>();
            vec![e.max(0.0)]
        }
    }

    /// The held-out error `‖τ̂ − τ‖ / ‖τ‖` pooled over the blocks, each predicted by
    /// the fit on the others, with each joint's own column `added(f)[j]` in fold `f`.
    pub(crate) fn error<'c>(&self, added: &dyn Fn(usize) -> Vec<Option<&'c JointColumn>>) -> Result<f64, String> {
        let (mut err, mut tau) = (0.0, 0.0);
        for f in 0..self.folds.len() {
            let added = added(f);
            let solution = self.solve(f, &added)?;
            err += self.held_out(f, &solution, &added, false)[0];
            tau += self.blocks.tau2[f].iter().sum::<f64>();
        }
        Ok((err / tau).sqrt())
    }

    /// Per joint `‖τ̂_j − τ_j‖²` and `‖τ_j‖²` over the held-out blocks, with the
    /// solutions `solutions` (one per fold).
    pub(crate) fn held_out_sums<'c>(
        &self,
        solutions: &[Solution],
        added: &dyn Fn(usize) -> Vec<Option<&'c JointColumn>>,
    ) -> (Vec<f64>, Vec<f64>) {
        let n = self.blocks.n;
        let (mut err, mut tau) = (vec![0.0; n], vec![0.0; n]);
        for (f, solution) in solutions.iter().enumerate() {
            let e = self.held_out(f, solution, &added(f), true);
            for j in 0..n {
                err[j] += e[j];
                tau[j] += self.blocks.tau2[f][j];
            }
        }
        (err, tau)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_model::sample::SplitMix64;

    /// The held-out errors from the blocks' Gram matrices, with a joint's own
    /// column by its Schur complement and rows left out of the fits, equal those of
    /// least-squares fits made directly on the training rows and predictions of the
    /// rows left out.
    #[test]
    fn the_gram_scores_are_those_of_direct_fits() {
        let (p, blocks, rows) = (6, 4, 40);
        let support = [vec![0, 1, 2, 3, 4, 5, p], vec![2, 3, 5, p]];
        let theta = [0.7, -1.2, 2.0, 0.4, -0.3, 1.1];
        let own = |v: f64| (v / 0.3).tanh();
        let mut rng = SplitMix64::new(11);
        let data: Vec<Vec<JointRows>> = (0..blocks)
            .map(|_| {
                (0..2)
                    .map(|j| {
                        let cols = &support[j];
                        let v: Vec<f64> = (0..rows).map(|_| rng.uniform(-1.0, 1.0)).collect();
                        let mut x = Mat::<f64>::zeros(rows, cols.len());
                        for r in 0..rows {
                            let mut tau = 1.5 * own(v[r]) + rng.uniform(-0.05, 0.05);
                            for (k, &c) in cols.iter().enumerate().take(cols.len() - 1) {
                                x[(r, k)] = rng.uniform(-1.0, 1.0);
                                tau += theta[c] * x[(r, k)];
                            }
                            x[(r, cols.len() - 1)] = tau;
                        }
                        let keep = (j == 0).then(|| v.iter().map(|v| v.abs() >= 0.2).collect());
                        JointRows::new(cols.clone(), x, v, keep)
                    })
                    .collect()
            })
            .collect();
        let data = Blocks::from_rows(p, data);
        let columns = [0, 2, 3, 5];
        let folds = data.prepare(&columns).unwrap();
        let grid = [
            data.columns_of_velocity(0, &[&own]),
            data.columns_of_velocity(1, &[&own]),
        ];
        for added in [
            [None, None],
            [Some(&grid[0][0]), None],
            [Some(&grid[0][0]), Some(&grid[1][0])],
        ] {
            let solutions: Vec<Solution> = (0..blocks).map(|f| folds.solve(f, &added).unwrap()).collect();
            let (err, _) = folds.held_out_sums(&solutions, &|_| added.to_vec());
            // The same, directly: the training rows into an accumulator, OLS, and the
            // held-out rows predicted.
            let own_columns: Vec<usize> = (0..2).filter(|&j| added[j].is_some()).collect();
            let width = columns.len() + own_columns.len();
            let row_of = |b: usize, j: usize, r: usize| -> (Vec<f64>, f64) {
                let rows = &data.rows[b][j];
                let mut row = vec![0.0; width];
                for (i, &c) in columns.iter().enumerate() {
                    if let Some(k) = rows.columns.iter().position(|&s| s == c) {
                        row[i] = rows.x[(r, k)];
                    }
                }
                if let Some(i) = own_columns.iter().position(|&o| o == j) {
                    row[columns.len() + i] = own(rows.v[r]);
                }
                (row, rows.x[(r, rows.columns.len() - 1)])
            };
            let mut direct = [0.0; 2];
            for f in 0..blocks {
                let mut acc = crate::Accumulator::new(width);
                for b in (0..blocks).filter(|&b| b != f) {
                    for j in 0..2 {
                        let keep = data.rows[b][j].keep.clone();
                        for r in (0..rows).filter(|&r| keep.as_ref().is_none_or(|k| k[r])) {
                            let (row, tau) = row_of(b, j, r);
                            acc.push_row(&row, tau).unwrap();
                        }
                    }
                }
                let x = acc.ols(&crate::Options::default()).unwrap().solution;
                for (j, direct) in direct.iter_mut().enumerate() {
                    for r in 0..rows {
                        let (row, tau) = row_of(f, j, r);
                        *direct += (crate::dense::dot(&row, &x) - tau).powi(2);
                    }
                }
            }
            for j in 0..2 {
                assert!(
                    (err[j] / direct[j] - 1.0).abs() < 1e-8,
                    "{added:?}: {err:?} {direct:?}",
                    added = added.map(|a| a.is_some())
                );
            }
        }
    }
}
