//! Physically consistent estimation of standard parameters as a convex problem:
//! `min ½‖R π − z‖²` subject to every body's pseudo-inertia `J_b(π) ⪰ 0`, solved by
//! the log-barrier interior-point method (Boyd & Vandenberghe §11.3) with Newton
//! steps (faer Cholesky) in `π` itself.
//!
//! Parameters outside the bodies (a joint's rotor inertia and friction) can be kept
//! `≥ 0` too, by `−log x_i` ([`StandardOptions::nonnegative`]).
//!
//! `−log det J` is a self-concordant barrier of parameter 4 per body and `−log x`
//! one of parameter 1, so after the last centring step with weight `μ` the objective
//! is within `ν μ`, `ν = 4 · bodies + nonnegative`, of the optimum: the method
//! returns that bound as a certificate. Unlike a fit in
//! log-Cholesky variables, it converges as fast to optima on the boundary of
//! consistency (a singular pseudo-inertia, the usual case when OLS is inconsistent)
//! as to interior ones.

use faer::prelude::*;
use faer::{Mat, Side};
use nalgebra::{Matrix4, SymmetricEigen};

use super::accumulate::{prior_or_zero, Accumulator};
use super::dense::{dot, mat_t_vec, mat_vec};
use super::error::IdentifyError;
use super::estimate::{Estimate, Method, Residuals, Status};
use super::least_squares::scale;
use super::log_cholesky::pseudo_inertia;
use super::{Layout, Options};

/// Options of [`Accumulator::standard_consistent`].
#[derive(Clone, Debug, PartialEq)]
pub struct StandardOptions {
    /// Where the 10-parameter body blocks are; `None`: every parameter.
    pub layout: Option<Layout>,
    /// Directions the data do not determine are pulled toward this vector (length
    /// `p`, e.g. nominal parameters; default zero) as far as consistency allows.
    /// Pass nominal parameters for rank-deficient regressors.
    pub prior: Option<Vec<f64>>,
    /// Parameters outside the body blocks kept `≥ 0` (strictly positive at the
    /// returned point), e.g. the rotor inertia and the viscous and Coulomb friction
    /// of every joint (an offset stays free). Default none.
    pub nonnegative: Vec<usize>,
    /// Stop when the certified suboptimality `ν μ` (`ν = 4 · bodies +
    /// nonnegative.len()`) is below this fraction of the objective. Default `1e-12`.
    pub gap_tolerance: f64,
    /// Newton steps in all, before [`IdentifyError::NotConverged`]. Default 500.
    pub max_iterations: usize,
}

impl Default for StandardOptions {
    fn default() -> Self {
        Self {
            layout: None,
            prior: None,
            nonnegative: Vec::new(),
            gap_tolerance: 1e-12,
            max_iterations: 500,
        }
    }
}

/// `−log det J_b`, its gradient and Hessian in `π_b`, or `None` outside the cone.
fn barrier(pi: &[f64]) -> Option<(f64, [f64; 10], [[f64; 10]; 10])> {
    let j = pseudo_inertia(pi.try_into().expect("10"));
    let chol = j.cholesky()?;
    let l = chol.l();
    let logdet = 2.0 * (0..4).map(|i| l[(i, i)].ln()).sum::<f64>();
    let jinv = chol.inverse();
    // ∂J/∂π_k is constant: the pseudo-inertia of the k-th unit vector.
    let m: Vec<Matrix4<f64>> = (0..10)
        .map(|k| {
            let mut e = [0.0; 10];
            e[k] = 1.0;
            jinv * pseudo_inertia(&e)
        })
        .collect();
    let mut grad = [0.0; 10];
    let mut hess = [[0.0; 10]; 10];
    for k in 0..10 {
        grad[k] = -m[k].trace();
        for l in 0..=k {
            let h = (m[k] * m[l]).trace();
            hess[k][l] = h;
            hess[l][k] = h;
        }
    }
    Some((-logdet, grad, hess))
}

struct Problem<'a> {
    r: &'a Mat<f64>,
    z: &'a [f64],
    /// Null-space regularisation `½ δ ‖V₂ᵀ(π − prior)‖²`.
    delta: f64,
    v2: Mat<f64>,
    prior: Vec<f64>,
    layout: Layout,
    /// Parameters kept positive by `−log x_i`.
    nonnegative: Vec<usize>,
}

impl Problem<'_> {
    /// The value of parameter `i` that would explain the data alone,
    /// `‖z‖ / ‖column i‖`, in its units (1 when either norm is zero): the scale of
    /// a nonnegative parameter.
    fn explaining(&self, i: usize) -> f64 {
        let z_norm = dot(self.z, self.z).sqrt();
        let column = (0..self.r.nrows()).map(|k| self.r[(k, i)].powi(2)).sum::<f64>().sqrt();
        if column > 0.0 && z_norm > 0.0 {
            z_norm / column
        } else {
            1.0
        }
    }

    fn body(&self, b: usize) -> std::ops::Range<usize> {
        let o = self.layout.first + 10 * b;
        o..o + 10
    }

    /// `f` (without barrier) and its gradient.
    fn fit(&self, pi: &[f64]) -> (f64, Vec<f64>) {
        let res: Vec<f64> = mat_vec(self.r.as_ref(), pi)
            .iter()
            .zip(self.z)
            .map(|(a, b)| a - b)
            .collect();
        let mut g = mat_t_vec(self.r.as_ref(), &res);
        let mut f = 0.5 * dot(&res, &res);
        if self.v2.ncols() > 0 {
            let d: Vec<f64> = pi.iter().zip(&self.prior).map(|(a, b)| a - b).collect();
            let w = mat_t_vec(self.v2.as_ref(), &d);
            f += 0.5 * self.delta * dot(&w, &w);
            let back = mat_vec(self.v2.as_ref(), &w);
            for (gi, bi) in g.iter_mut().zip(&back) {
                *gi += self.delta * bi;
            }
        }
        (f, g)
    }

    /// `f + μ B`, or `None` outside the cone.
    fn value(&self, pi: &[f64], mu: f64) -> Option<f64> {
        let mut v = self.fit(pi).0;
        for b in 0..self.layout.bodies {
            v += mu * barrier(&pi[self.body(b)])?.0;
        }
        for &i in &self.nonnegative {
            if pi[i] <= 0.0 {
                return None;
            }
            v -= mu * pi[i].ln();
        }
        Some(v)
    }

    /// Whether `pi` is strictly inside every constraint.
    fn interior(&self, pi: &[f64]) -> bool {
        (0..self.layout.bodies).all(|b| barrier(&pi[self.body(b)]).is_some())
            && self.nonnegative.iter().all(|&i| pi[i] > 0.0)
    }

    /// The barrier parameter `ν`: 4 per body, 1 per nonnegative parameter.
    fn nu(&self) -> f64 {
        (4 * self.layout.bodies + self.nonnegative.len()) as f64
    }
}

impl Accumulator {
    /// Physically consistent least squares on standard parameters: `min ‖A π − y‖²`
    /// subject to a positive-semidefinite pseudo-inertia for every body (strictly
    /// definite at the returned point), the convex form of the problem
    /// [`Accumulator::log_cholesky`] parameterises.
    ///
    /// With [`StandardOptions::nonnegative`], those parameters (outside the body
    /// blocks) are kept `≥ 0` as well.
    ///
    /// Returns OLS unchanged when OLS is strictly consistent. Otherwise runs the
    /// barrier method from the projected OLS solution, `μ ← μ/10` per centring,
    /// until `ν μ ≤ gap_tolerance · f`; the final bound is in
    /// [`Method::StandardConsistent`]. Bodies and parameters held by a constraint
    /// are listed there; their identifiable parameters are [`Status::Constrained`],
    /// and the covariance is withheld (`σ = None`) since the fit is no longer linear.
    ///
    /// Errors: a nonnegative index `≥ p` or inside a body block, besides those of
    /// the estimate itself.
    pub fn standard_consistent(&self, sopts: &StandardOptions, opts: &Options) -> Result<Estimate, IdentifyError> {
        let p = self.n_params();
        let layout = Layout::resolve(sopts.layout, p, 10)?;
        if !(sopts.gap_tolerance.is_finite() && sopts.gap_tolerance > 0.0) {
            return Err(IdentifyError::InvalidArgument {
                what: "gap tolerance",
                reason: format!("{}: must be finite and > 0", sopts.gap_tolerance),
            });
        }
        let prior = prior_or_zero(sopts.prior.as_ref(), p)?;
        let mut nonnegative = sopts.nonnegative.clone();
        nonnegative.sort_unstable();
        nonnegative.dedup();
        let bodies = layout.first..layout.first + 10 * layout.bodies;
        if let Some(&i) = nonnegative.iter().find(|&&i| i >= p || bodies.contains(&i)) {
            return Err(IdentifyError::InvalidArgument {
                what: "nonnegative parameters",
                reason: if i >= p {
                    format!("index {i} of {p} parameters")
                } else {
                    format!(
                        "index {i} lies in the body blocks {}..{}, which the pseudo-inertia constrains",
                        bodies.start, bodies.end
                    )
                },
            });
        }
        let ols = self.ols_start(opts)?;
        let (factors, tri, sub, x_ols, dof, noise) = (ols.factors, ols.tri, ols.sub, ols.x_ols, ols.dof, ols.noise);
        let q = p - sub.rank;
        let problem = Problem {
            r: &tri.r,
            z: &tri.z,
            delta: sub.s[sub.rank - 1].powi(2),
            v2: sub.v.as_ref().subcols(sub.rank, q).to_owned(),
            prior: prior.clone(),
            layout,
            nonnegative,
        };
        // The unconstrained minimiser: OLS with the null-space part at the prior's.
        let mut x_free = x_ols.clone();
        let back = mat_vec(problem.v2.as_ref(), &mat_t_vec(problem.v2.as_ref(), &prior));
        for (x, b) in x_free.iter_mut().zip(&back) {
            *x += b;
        }
        let BarrierSolution {
            x,
            iterations,
            gap,
            active,
            params_at_bound,
        } = if problem.interior(&x_free) {
            BarrierSolution {
                x: x_free,
                iterations: 0,
                gap: 0.0,
                active: vec![false; layout.bodies],
                params_at_bound: Vec::new(),
            }
        } else {
            solve_barrier(&problem, &x_free, sopts)?
        };
        let min_eigenvalues = (0..layout.bodies)
            .map(|b| {
                SymmetricEigen::new(pseudo_inertia(x[problem.body(b)].try_into().expect("10")))
                    .eigenvalues
                    .min()
            })
            .collect();
        let mut status = sub.status.clone();
        for b in (0..layout.bodies).filter(|&b| active[b]) {
            for j in problem.body(b) {
                if status[j] == Status::Identified {
                    status[j] = Status::Constrained;
                }
            }
        }
        for &j in &params_at_bound {
            if status[j] == Status::Identified {
                status[j] = Status::Constrained;
            }
        }
        let any_active = active.iter().any(|&a| a) || !params_at_bound.is_empty();
        let cov = if any_active {
            None
        } else {
            noise.map(|s| scale(sub.unit_covariance(), s * s))
        };
        let bodies_at_bound = (0..layout.bodies).filter(|&b| active[b]).collect();
        let residuals = Residuals::from_factors(&factors, &x, dof);
        let method = Method::StandardConsistent {
            iterations,
            gap_bound: gap,
            bodies_at_bound,
            params_at_bound,
            min_eigenvalues,
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

/// The Newton step `−H⁻¹ g` by Cholesky. `H` is positive definite in exact
/// arithmetic, but where the data determine some directions to a singular value
/// near the regularisation's and the barrier's weight `μ` has become small, its
/// condition number reaches `1/ε` and the factorisation fails on rounding: then
/// `H + τ·max(diag H)·E` with `τ` from `1e-14` up by factors of 100 (a Hessian
/// modification, Nocedal and Wright §3.4), which still gives a descent direction.
fn newton_step(h: &Mat<f64>, g: &[f64]) -> Result<Vec<f64>, IdentifyError> {
    let p = g.len();
    let rhs = Mat::from_fn(p, 1, |i, _| -g[i]);
    let largest = (0..p).fold(0.0f64, |m, i| m.max(h[(i, i)].abs()));
    let mut shift = 0.0;
    loop {
        let mut shifted = h.clone();
        for i in 0..p {
            shifted[(i, i)] += shift * largest;
        }
        if let Ok(llt) = shifted.llt(Side::Lower) {
            let step = llt.solve(&rhs);
            let d: Vec<f64> = (0..p).map(|i| step[(i, 0)]).collect();
            if d.iter().all(|v| v.is_finite()) {
                return Ok(d);
            }
        }
        shift = if shift == 0.0 { 1e-14 } else { shift * 100.0 };
        if shift > 1.0 {
            return Err(IdentifyError::DecompositionFailed { what: "Newton system" });
        }
    }
}

/// The result of [`solve_barrier`].
struct BarrierSolution {
    x: Vec<f64>,
    iterations: usize,
    /// Certified suboptimality `ν μ`.
    gap: f64,
    /// Bodies the barrier holds (their constraint is active).
    active: Vec<bool>,
    /// Nonnegative parameters the barrier holds at their bound, increasing.
    params_at_bound: Vec<usize>,
}

/// Path-following barrier method from the projected unconstrained minimiser.
fn solve_barrier(
    problem: &Problem<'_>,
    x_free: &[f64],
    sopts: &StandardOptions,
) -> Result<BarrierSolution, IdentifyError> {
    let p = x_free.len();
    let layout = problem.layout;
    let nu = problem.nu();
    // Strictly feasible start: each body's pseudo-inertia with eigenvalues raised.
    let mut x = x_free.to_vec();
    for b in 0..layout.bodies {
        let range = problem.body(b);
        let eig = SymmetricEigen::new(pseudo_inertia(x[range.clone()].try_into().expect("10")));
        let top = eig.eigenvalues.amax().max(f64::MIN_POSITIVE);
        let lam = eig.eigenvalues.map(|l| l.max(1e-3 * top));
        let j = eig.eigenvectors * Matrix4::from_diagonal(&lam) * eig.eigenvectors.transpose();
        x[range].copy_from_slice(&super::log_cholesky::standard_from_pseudo_inertia(
            &(0.5 * (j + j.transpose())),
        ));
    }
    // Nonnegative parameters start well inside: at least 10⁻³ of the value that
    // would explain the data alone (`‖z‖ / ‖column‖`, in the parameter's units).
    for &i in &problem.nonnegative {
        x[i] = x[i].max(1e-3 * problem.explaining(i));
    }
    let (f0, _) = problem.fit(&x);
    let mut mu = f0.max(f64::MIN_POSITIVE) / nu;
    let mut iterations = 0;
    loop {
        // Centring: Newton on f + μ B with backtracking.
        loop {
            if iterations >= sopts.max_iterations {
                return Err(IdentifyError::NotConverged {
                    algorithm: "pseudo-inertia barrier method",
                    iterations: sopts.max_iterations,
                });
            }
            iterations += 1;
            let (f, mut g) = problem.fit(&x);
            let mut h = problem.r.transpose() * problem.r;
            if problem.v2.ncols() > 0 {
                let vv = problem.v2.as_ref() * problem.v2.transpose();
                for i in 0..p {
                    for j in 0..p {
                        h[(i, j)] += problem.delta * vv[(i, j)];
                    }
                }
            }
            let mut value = f;
            for b in 0..layout.bodies {
                let o = problem.body(b).start;
                let (bv, bg, bh) = barrier(&x[problem.body(b)]).expect("iterates stay inside the cone");
                value += mu * bv;
                for k in 0..10 {
                    g[o + k] += mu * bg[k];
                    for l in 0..10 {
                        h[(o + k, o + l)] += mu * bh[k][l];
                    }
                }
            }
            for &i in &problem.nonnegative {
                value -= mu * x[i].ln();
                g[i] -= mu / x[i];
                h[(i, i)] += mu / (x[i] * x[i]);
            }
            let d = newton_step(&h, &g)?;
            let decrement = -dot(&g, &d);
            if decrement <= 0.0 || 0.5 * decrement <= 1e-14 * (f + mu * nu).max(f64::MIN_POSITIVE) {
                break;
            }
            let mut t = 1.0;
            loop {
                let trial: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + t * b).collect();
                if let Some(v) = problem.value(&trial, mu) {
                    if v <= value - 1e-4 * t * decrement {
                        x = trial;
                        break;
                    }
                }
                t *= 0.5;
                if t < 1e-20 {
                    break;
                }
            }
            if t < 1e-20 {
                // No progress at roundoff level: centred as well as it can be.
                break;
            }
        }
        let (f, _) = problem.fit(&x);
        if nu * mu <= sopts.gap_tolerance * f || f == 0.0 {
            break;
        }
        mu /= 10.0;
    }
    // A body is held by the barrier when its pull is not negligible next to the data's.
    let scale = mat_t_vec(problem.r.as_ref(), problem.z)
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()));
    let active = (0..layout.bodies)
        .map(|b| {
            let (_, bg, _) = barrier(&x[problem.body(b)]).expect("inside");
            bg.iter().fold(0.0f64, |a, v| a.max((mu * v).abs())) > 1e-6 * scale
        })
        .collect();
    let params_at_bound = problem
        .nonnegative
        .iter()
        .copied()
        // Held by its multiplier, or at the bound itself: a value of a millionth of
        // what would explain the data alone (a multiplier that vanishes with the
        // barrier's weight means a constraint that is weakly active, not inactive).
        .filter(|&i| mu / x[i] > 1e-6 * scale || x[i] < 1e-6 * problem.explaining(i))
        .collect();
    Ok(BarrierSolution {
        x,
        iterations,
        gap: nu * mu,
        active,
        params_at_bound,
    })
}
