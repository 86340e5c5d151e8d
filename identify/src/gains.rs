//! Drive gains identified with the robot (Gautier and Briot's global
//! identification): motor currents `i` relate to torques by `τ_j = k_j·i_j` with
//! unknown `k`. Without a known load the scale of `k` and of every dynamic parameter
//! is free (`k` and the parameters can all be doubled); one recording with a known
//! payload fixes it. The unknowns `x = [π; φ; k]` (`10n` standard parameters, `4n`
//! joint parameters `[Ia, Fv, Fc, F0]`, `n` gains) solve, stacked over both
//! recordings,
//!
//! ```text
//! Y(q, q̇, q̈) π + J(q̇, q̈) φ − diag(i) k = −Y_L(q, q̇, q̈) π_L
//! ```
//!
//! where `Y_L` is the payload regressor (the 10 columns of the body carrying the
//! load) and `π_L` the payload's known standard parameters; the right side is zero
//! for the recording without payload.
//!
//! Solved as it stands by least squares, the measured current sits in the regressor
//! and its noise biases every gain toward zero (errors in variables: 2–3 % at 1 %
//! current noise on a joint the payload barely loads). So the stacked solution only
//! starts an alternating least squares in current units, where the noise belongs:
//! `i_j = w_j (Y_j π + J_j φ + Y_Lj π_L)` with `w_j = 1/k_j`; for fixed `w` the
//! parameters solve a weighted linear problem, for fixed parameters each `w_j` is a
//! ratio of sums. Each step lowers the same sum of squares, so it converges; all the
//! sums come from one pass over the data (the Gram matrices of the accumulator).

use crate::data::Trajectory;
use crate::faer::{Mat, MatRef};
use crate::mim::TorqueRegressor;
use crate::{Accumulator, Channels, Estimate, IdentifyError, Options};
use dyngen_model::joint_params::{Coulomb, PER_JOINT};
use dyngen_reference::Dynamics;

use crate::payload::Payload;

/// The outcome.
#[derive(Clone, Debug)]
pub struct GainEstimate {
    /// The stacked least-squares estimate over `[π; φ; k]` that starts the
    /// alternation: its rank and identifiable combinations hold for the final one.
    pub initial: Estimate,
    /// `k_j` per joint.
    pub gains: Vec<f64>,
    /// The standard deviation of each `k_j`, to first order at the solution: the
    /// residuals in current units, one noise level for every joint's current, the
    /// covariance of `w = 1/k` from the normal matrix of all unknowns `[π; φ; w]`
    /// (the parameters the data cannot determine left out, as a pseudo-inverse
    /// does), then `σ(k) = σ(w)/w²`.
    pub gain_sigma: Vec<f64>,
    /// `[π; φ]` (`14n`) at the end: a minimum-norm solution (use it to predict; the
    /// identifiable combinations are those of [`GainEstimate::initial`]).
    pub solution: Vec<f64>,
    /// Linear solves spent (alternations and simplex trials), and the relative
    /// change of the gains the simplex search made after the alternation.
    pub iterations: usize,
    pub last_change: f64,
}

/// Identifies drive gains, standard and joint parameters from two recordings whose
/// "torque" columns hold motor currents (read without gains), with velocities and
/// accelerations: `unloaded` without the payload, `loaded` with it.
pub fn identify_gains(
    dynamics: &dyn Dynamics,
    unloaded: &Trajectory,
    loaded: &Trajectory,
    payload: &Payload,
    coulomb: Coulomb,
    opts: &Options,
) -> Result<GainEstimate, IdentifyError> {
    let n = dynamics.nv();
    Payload::check_body(payload.body, dynamics.model().dof())?;
    let rigid = dynamics.nparams();
    let pa = rigid + PER_JOINT * n;
    // Columns: A (π, φ), then −i_j of each joint (the stacked problem's k), then the
    // payload term l; the observation is −l. One accumulator serves both the stacked
    // solution and, through its per-joint Gram matrices, the alternation.
    let p = pa + n + 1;
    let mut acc = Accumulator::with_channels(p, Channels::Interleaved(n))?;
    let regressor = TorqueRegressor::StandardAndJoints(coulomb.into());
    let mut y = vec![0.0; n * pa];
    let mut row = Mat::<f64>::zeros(n, p);
    let mut rhs = vec![0.0; n];
    let mut samples = 0;
    for (traj, with_load) in [(unloaded, false), (loaded, true)] {
        if traj.dof() != n {
            return Err(IdentifyError::DimensionMismatch {
                what: "joints of a recording",
                expected: n,
                found: traj.dof(),
            });
        }
        for s in traj.samples() {
            let (v, a) = match (s.v, s.a) {
                (Some(v), Some(a)) => (v, a),
                _ => {
                    return Err(IdentifyError::InvalidArgument {
                        what: "recording",
                        reason: "velocities and accelerations are needed (estimate them first)".into(),
                    })
                }
            };
            regressor.eval(dynamics, s.q, v, a, &mut y);
            for j in 0..n {
                let yj = &y[j * pa..(j + 1) * pa];
                for c in 0..p {
                    row[(j, c)] = if c < pa { yj[c] } else { 0.0 };
                }
                row[(j, pa + j)] = -s.tau[j];
                // The payload regressor: the 10 columns of the carrying body.
                let l = if with_load { payload.torque(yj) } else { 0.0 };
                row[(j, p - 1)] = l;
                rhs[j] = -l;
            }
            acc.push_rows(row.as_ref(), &rhs)?;
            samples += 1;
        }
    }
    // The stacked solution, without the payload column (it is known: 0 there).
    let grams: Vec<Mat<f64>> = acc.factors()?.iter().map(|f| f.r.transpose() * &f.r).collect();
    let mut stacked = Accumulator::new(pa + n);
    let gram_all = grams.iter().fold(Mat::<f64>::zeros(p + 1, p + 1), |s, g| s + g);
    let initial = {
        // ‖[A −I] x − (−l)‖²: push the Gram's factor of the first pa + n columns and
        // the observation column.
        let keep: Vec<usize> = (0..pa + n).chain([p]).collect();
        let g = Mat::from_fn(keep.len(), keep.len(), |r, c| gram_all[(keep[r], keep[c])]);
        let f = gram_root(g.as_ref())?;
        stacked.push_rows(
            f.as_ref().subcols(0, pa + n),
            &(0..f.nrows()).map(|r| f[(r, pa + n)]).collect::<Vec<_>>(),
        )?;
        stacked.ols(opts)?
    };
    let mut w: Vec<f64> = (0..n)
        .map(|j| {
            let k = initial.solution[pa + j];
            if k.is_finite() && k != 0.0 {
                Ok(1.0 / k)
            } else {
                Err(IdentifyError::InvalidArgument {
                    what: "recordings",
                    reason: format!("they do not determine the gain of joint {}", j + 1),
                })
            }
        })
        .collect::<Result<_, _>>()?;
    let block = |g: &Mat<f64>, r0: usize, c0: usize, rows: usize, cols: usize| {
        Mat::from_fn(rows, cols, |r, c| g[(r0 + r, c0 + c)])
    };
    // For fixed w the parameters solve Σ_j w_j² A_jᵀA_j x = Σ_j w_j (A_jᵀ i_j − w_j A_jᵀ l_j)
    // (column pa + j holds −i_j); the sum of squares in current units is then
    // Σ_j (Σ i² − 2 w_j Σ i f + w_j² Σ f²) with f = A_j x + l_j.
    let ata: Vec<Mat<f64>> = grams.iter().map(|g| block(g, 0, 0, pa, pa)).collect();
    // Its matrix is singular where the data leave parameters undetermined, and its
    // range (the sum of the joints' ranges) is the same for every nonzero w: so the
    // minimum-norm solution is U z with U an orthonormal basis of that range, found
    // once, and z from the positive definite Uᵀ(Σ_j w_j² A_jᵀA_j)U by Cholesky, at
    // every step of the searches below.
    let basis = {
        let total = ata.iter().fold(Mat::<f64>::zeros(pa, pa), |s, a| s + a);
        let (values, vectors) = eigen(total.as_ref())?;
        let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let kept: Vec<usize> = (0..pa).filter(|&i| values[i] > 1e-12 * largest).collect();
        Mat::from_fn(pa, kept.len(), |r, k| vectors[(r, kept[k])])
    };
    let projected: Vec<Mat<f64>> = ata.iter().map(|a| basis.transpose() * a * &basis).collect();
    let subspace = Subspace {
        basis: &basis,
        projected: &projected,
    };
    let solve = |w: &[f64]| -> Result<Vec<f64>, IdentifyError> {
        let mut b = Mat::<f64>::zeros(pa, 1);
        for (j, g) in grams.iter().enumerate() {
            for c in 0..pa {
                b[(c, 0)] += w[j] * (-g[(c, pa + j)] - w[j] * g[(c, p - 1)]);
            }
        }
        let x = subspace.solve(w, b.as_ref())?;
        Ok((0..pa).map(|i| x[(i, 0)]).collect())
    };
    // Per joint: (Σ i f, Σ f²) at x.
    let sums = |x: &[f64]| -> Vec<(f64, f64)> {
        grams
            .iter()
            .enumerate()
            .map(|(j, g)| {
                let i_f: f64 = (0..pa).map(|c| -g[(c, pa + j)] * x[c]).sum::<f64>() - g[(pa + j, p - 1)];
                let quad: f64 = (0..pa)
                    .map(|r| x[r] * (0..pa).map(|c| ata[j][(r, c)] * x[c]).sum::<f64>())
                    .sum();
                let cross: f64 = (0..pa).map(|c| g[(c, p - 1)] * x[c]).sum();
                (i_f, quad + 2.0 * cross + g[(p - 1, p - 1)])
            })
            .collect()
    };
    let objective = |w: &[f64], x: &[f64]| -> f64 {
        sums(x)
            .iter()
            .enumerate()
            .map(|(j, (i_f, ff))| grams[j][(pa + j, pa + j)] - 2.0 * w[j] * i_f + w[j] * w[j] * ff)
            .sum()
    };
    // Alternating least squares first (each step lowers the sum of squares) ...
    let mut iterations = 0;
    for _ in 0..30 {
        iterations += 1;
        let x = solve(&w)?;
        for (j, (i_f, ff)) in sums(&x).into_iter().enumerate() {
            let new = i_f / ff;
            if !(new.is_finite() && new != 0.0) {
                return Err(IdentifyError::NotConverged {
                    algorithm: "alternating least squares of the drive gains",
                    iterations,
                });
            }
            w[j] = new;
        }
    }
    // ... then, as alternation crawls along the weakly determined common scale, the
    // sum of squares minimised over the gains alone (the parameters solved for each
    // trial), by a simplex search in log w.
    let start: Vec<f64> = w.iter().map(|w| w.abs().ln()).collect();
    let signs: Vec<f64> = w.iter().map(|w| w.signum()).collect();
    let to_w = |u: &[f64]| -> Vec<f64> { u.iter().zip(&signs).map(|(u, s)| s * u.exp()).collect() };
    let best = crate::minimise::minimise(
        &mut |u: &[f64]| {
            let w = to_w(u);
            match solve(&w) {
                Ok(x) => objective(&w, &x),
                Err(_) => f64::INFINITY,
            }
        },
        &start,
        &vec![1e-3; n],
        4000,
        None,
    );
    let last_change = best
        .x
        .iter()
        .zip(&start)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    w = to_w(&best.x);
    iterations += best.evaluations;
    let x = solve(&w)?;
    let ff: Vec<f64> = sums(&x).into_iter().map(|(_, ff)| ff).collect();
    let gain_sigma = gain_sigma(&grams, &ata, &subspace, &w, &x, &ff, objective(&w, &x), samples)?;
    Ok(GainEstimate {
        initial,
        gains: w.iter().map(|w| 1.0 / w).collect(),
        gain_sigma,
        solution: x,
        iterations,
        last_change,
    })
}

/// The identifiable subspace of `[π; φ]`: an orthonormal basis `U` of the range of
/// `Σ_j A_jᵀA_j` (the same for every nonzero `w`) and each joint's `UᵀA_jᵀA_jU`.
struct Subspace<'a> {
    basis: &'a Mat<f64>,
    projected: &'a [Mat<f64>],
}

impl Subspace<'_> {
    /// The minimum-norm solutions `x` (columns) of `(Σ_j w_j² A_jᵀA_j) x = b` for
    /// the columns of `b` in that range: `U z` with `z` by Cholesky of
    /// `Uᵀ(Σ_j w_j² A_jᵀA_j)U`, which is positive definite.
    fn solve(&self, w: &[f64], b: MatRef<'_, f64>) -> Result<Mat<f64>, IdentifyError> {
        use faer::prelude::Solve;
        let r = self.basis.ncols();
        let mut lhs = Mat::<f64>::zeros(r, r);
        for (j, p) in self.projected.iter().enumerate() {
            lhs += p * (w[j] * w[j]);
        }
        let z = lhs
            .llt(faer::Side::Lower)
            .map_err(|_| IdentifyError::DecompositionFailed {
                what: "normal equations of the drive-gain problem",
            })?
            .solve(self.basis.transpose() * b);
        Ok(self.basis * &z)
    }
}

/// `σ(k_j)` at the solution `(x, w)` of the problem in current units, whose residual
/// of joint `j` is `i_j − w_j·f_j` with `f_j = A_j x + l_j`: the Jacobian's columns
/// are `−w_j A_j` for `x` and `−f_j` for `w_j`, so the normal matrix has the blocks
/// `N_xx = Σ_j w_j² A_jᵀA_j`, `N_x,w_j = w_j (A_jᵀA_j x + A_jᵀ l_j)` and
/// `N_w_j,w_j = f_jᵀf_j` (`ff`), all from the per-joint Gram matrices of
/// `[A, −i, l]`. The covariance of `w` is `s²·S⁻¹` with the Schur complement
/// `S = N_ww − N_wx N_xx⁺ N_xw` (`N_xx⁺` on the identifiable subspace) and `s²` the
/// residual sum of squares over the rows left after the unknowns the data determine.
#[allow(clippy::too_many_arguments)]
fn gain_sigma(
    grams: &[Mat<f64>],
    ata: &[Mat<f64>],
    subspace: &Subspace<'_>,
    w: &[f64],
    x: &[f64],
    ff: &[f64],
    sum_of_squares: f64,
    samples: usize,
) -> Result<Vec<f64>, IdentifyError> {
    let n = w.len();
    let pa = x.len();
    let p = pa + n + 1;
    // N_xw, one column per joint.
    let b = Mat::from_fn(pa, n, |r, j| {
        w[j] * ((0..pa).map(|c| ata[j][(r, c)] * x[c]).sum::<f64>() + grams[j][(r, p - 1)])
    });
    let solved = subspace.solve(w, b.as_ref())?;
    let coupling = b.transpose() * &solved;
    let schur = Mat::from_fn(n, n, |r, c| {
        let diagonal = if r == c { ff[r] } else { 0.0 };
        diagonal - coupling[(r, c)]
    });
    let dof = (samples * n).saturating_sub(subspace.basis.ncols() + n);
    let undetermined = || IdentifyError::InvalidArgument {
        what: "recordings",
        reason: "they do not determine the drive gains apart from the dynamic parameters".into(),
    };
    if dof == 0 {
        return Err(undetermined());
    }
    let s2 = sum_of_squares / dof as f64;
    let (values, vectors) = eigen(schur.as_ref())?;
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if values.iter().any(|&v| v <= 1e-12 * largest) {
        return Err(undetermined());
    }
    let sigma: Vec<f64> = (0..n)
        .map(|j| {
            let variance: f64 = (0..n)
                .map(|i| vectors[(j, i)] * vectors[(j, i)] / values[i])
                .sum::<f64>()
                * s2;
            variance.sqrt() / (w[j] * w[j])
        })
        .collect();
    if sigma.iter().any(|s| !s.is_finite()) {
        return Err(undetermined());
    }
    Ok(sigma)
}

/// The eigenvalues and eigenvectors (columns) of a symmetric `G`.
fn eigen(g: faer::MatRef<'_, f64>) -> Result<(Vec<f64>, Mat<f64>), IdentifyError> {
    let e = g
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|_| IdentifyError::DecompositionFailed {
            what: "eigendecomposition of the normal equations",
        })?;
    let values = (0..g.nrows()).map(|i| e.S().column_vector()[i]).collect();
    Ok((values, e.U().to_owned()))
}

/// `F` with `FᵀF = G` for a symmetric positive semi-definite `G`.
fn gram_root(g: faer::MatRef<'_, f64>) -> Result<Mat<f64>, IdentifyError> {
    let n = g.nrows();
    let (values, vectors) = eigen(g)?;
    Ok(Mat::from_fn(n, n, |i, j| values[i].max(0.0).sqrt() * vectors[(j, i)]))
}
