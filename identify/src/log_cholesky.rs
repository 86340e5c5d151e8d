//! Physically consistent estimation of standard parameters through the
//! log-Cholesky parameterisation (Rucker & Wensing, RA-L 2022).
//!
//! Per body `π = [m, m·c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (Pinocchio's order), the
//! pseudo-inertia `J = [[Σ, h], [hᵀ, m]]`, `Σ = ½ tr(I) 1 − I`, `h = m c`, is
//! positive definite exactly when the body is physically consistent. With
//! `φ = (α, d1, d2, d3, s12, s23, s13, t1, t2, t3)`,
//!
//! ```text
//! U = e^α [[e^d1, s12,  s13,  t1],
//!          [0,    e^d2, s23,  t2],
//!          [0,    0,    e^d3, t3],
//!          [0,    0,    0,    1 ]],     J = U Uᵀ,
//! ```
//!
//! maps all of ℝ¹⁰ smoothly onto the positive-definite pseudo-inertias, so the
//! constrained fit becomes an unconstrained Levenberg–Marquardt problem in `φ`.

use faer::prelude::*;
use faer::{Mat, MatRef, Side};
use nalgebra::{Matrix4, SymmetricEigen};

use super::accumulate::Accumulator;
use super::dense::{column, first_column, mat_vec};
use super::error::{check_finite_vector, check_len, IdentifyError, Input};
use super::estimate::{Estimate, Method, Residuals, Status};
use super::least_squares::scale;
use super::{Layout, Options};

/// Options of [`Accumulator::log_cholesky`].
#[derive(Clone, Debug, PartialEq)]
pub struct LogCholeskyOptions {
    /// Where the 10-parameter body blocks are; `None`: every parameter.
    pub layout: Option<Layout>,
    /// Start (standard parameters, length `p`); default the OLS solution. Bodies
    /// whose pseudo-inertia is not positive definite are projected (eigenvalues
    /// raised to `eigenvalue_floor · max|λ|`). Directions the data do not determine
    /// stay where the start puts them: pass nominal parameters for rank-deficient
    /// regressors.
    pub start: Option<Vec<f64>>,
    pub eigenvalue_floor: f64,
    /// Weight of the regulariser `−Σ_b log det J_b`, relative to the starting
    /// objective per unit of barrier parameter (4 per body). It keeps boundary
    /// optima at a finite `φ` (so the iteration converges quadratically) and the
    /// pseudo-inertias definite by more than roundoff, at a cost of at most about
    /// this fraction of the objective. Default `1e-12`; 0 disables it.
    pub log_det_weight: f64,
    /// Levenberg–Marquardt iterations before [`IdentifyError::NotConverged`]. Default 500.
    pub max_iterations: usize,
}

impl Default for LogCholeskyOptions {
    fn default() -> Self {
        Self {
            layout: None,
            start: None,
            eigenvalue_floor: 1e-6,
            log_det_weight: 1e-12,
            max_iterations: 500,
        }
    }
}

/// The 4 × 4 pseudo-inertia of standard parameters `π` (10, Pinocchio's order).
pub fn pseudo_inertia(pi: &[f64; 10]) -> Matrix4<f64> {
    let [m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz] = *pi;
    let half = 0.5 * (ixx + iyy + izz);
    Matrix4::new(
        half - ixx,
        -ixy,
        -ixz,
        hx,
        -ixy,
        half - iyy,
        -iyz,
        hy,
        -ixz,
        -iyz,
        half - izz,
        hz,
        hx,
        hy,
        hz,
        m,
    )
}

/// Standard parameters from a pseudo-inertia (the inverse of [`pseudo_inertia`];
/// linear, so it also maps derivatives).
pub fn standard_from_pseudo_inertia(j: &Matrix4<f64>) -> [f64; 10] {
    let tr = j[(0, 0)] + j[(1, 1)] + j[(2, 2)];
    [
        j[(3, 3)],
        j[(0, 3)],
        j[(1, 3)],
        j[(2, 3)],
        tr - j[(0, 0)],
        -j[(0, 1)],
        tr - j[(1, 1)],
        -j[(0, 2)],
        -j[(1, 2)],
        tr - j[(2, 2)],
    ]
}

fn u_from_phi(phi: &[f64]) -> Matrix4<f64> {
    let [a, d1, d2, d3, s12, s23, s13, t1, t2, t3] = phi[..10] else {
        unreachable!()
    };
    let e = a.exp();
    e * Matrix4::new(
        d1.exp(),
        s12,
        s13,
        t1,
        0.0,
        d2.exp(),
        s23,
        t2,
        0.0,
        0.0,
        d3.exp(),
        t3,
        0.0,
        0.0,
        0.0,
        1.0,
    )
}

/// Standard parameters from log-Cholesky parameters `φ`: always physically consistent.
pub fn standard_from_log_cholesky(phi: &[f64; 10]) -> [f64; 10] {
    let u = u_from_phi(phi);
    standard_from_pseudo_inertia(&(u * u.transpose()))
}

/// Log-Cholesky parameters of standard parameters `π`, or `None` when the
/// pseudo-inertia is not positive definite.
pub fn log_cholesky_from_standard(pi: &[f64; 10]) -> Option<[f64; 10]> {
    phi_from_pseudo(&pseudo_inertia(pi))
}

/// `J = U Uᵀ` with `U` upper triangular: Cholesky of the index-reversed matrix.
fn phi_from_pseudo(j: &Matrix4<f64>) -> Option<[f64; 10]> {
    let rev = Matrix4::from_fn(|r, c| j[(3 - r, 3 - c)]);
    let l = rev.cholesky()?.l();
    let u = Matrix4::from_fn(|r, c| l[(3 - r, 3 - c)]);
    let e = u[(3, 3)];
    let phi = [
        e.ln(),
        (u[(0, 0)] / e).ln(),
        (u[(1, 1)] / e).ln(),
        (u[(2, 2)] / e).ln(),
        u[(0, 1)] / e,
        u[(1, 2)] / e,
        u[(0, 2)] / e,
        u[(0, 3)] / e,
        u[(1, 3)] / e,
        u[(2, 3)] / e,
    ];
    phi.iter().all(|v| v.is_finite()).then_some(phi)
}

/// `∂π/∂φ` (10 × 10, column k = derivative along φ_k).
fn jacobian(phi: &[f64]) -> [[f64; 10]; 10] {
    let u = u_from_phi(phi);
    let e = phi[0].exp();
    let mut cols = [[0.0; 10]; 10];
    for (k, col) in cols.iter_mut().enumerate() {
        let du = match k {
            0 => u,
            1..=3 => {
                let mut d = Matrix4::zeros();
                d[(k - 1, k - 1)] = u[(k - 1, k - 1)];
                d
            }
            _ => {
                let (r, c) = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)][k - 4];
                let mut d = Matrix4::zeros();
                d[(r, c)] = e;
                d
            }
        };
        let dj = du * u.transpose() + u * du.transpose();
        *col = standard_from_pseudo_inertia(&dj);
    }
    cols
}

/// `∂²π/∂φ_a∂φ_b` (10 × 10 × 10). `U = e^α Ũ(φ)` with `Ũ` linear in `s, t` and
/// exponential in `d`, so the only second derivatives of `U` are
/// `∂²U/∂α² = U`, `∂²U/∂α∂φ_k = ∂U/∂φ_k` and `∂²U/∂d_i² = ∂U/∂d_i`.
fn second_derivatives(phi: &[f64]) -> [[[f64; 10]; 10]; 10] {
    let u = u_from_phi(phi);
    let e = phi[0].exp();
    let du: Vec<Matrix4<f64>> = (0..10)
        .map(|k| match k {
            0 => u,
            1..=3 => {
                let mut d = Matrix4::zeros();
                d[(k - 1, k - 1)] = u[(k - 1, k - 1)];
                d
            }
            _ => {
                let (r, c) = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)][k - 4];
                let mut d = Matrix4::zeros();
                d[(r, c)] = e;
                d
            }
        })
        .collect();
    let mut out = [[[0.0; 10]; 10]; 10];
    for a in 0..10 {
        for b in 0..=a {
            let dd = match (a, b) {
                (0, 0) => u,
                (k, 0) => du[k],
                (k, l) if k == l && (1..=3).contains(&k) => du[k],
                _ => Matrix4::zeros(),
            };
            let d2j = dd * u.transpose() + du[a] * du[b].transpose() + du[b] * du[a].transpose() + u * dd.transpose();
            let v = standard_from_pseudo_inertia(&d2j);
            out[a][b] = v;
            out[b][a] = v;
        }
    }
    out
}

/// The parameter map `φ ↦ π` over the whole vector: body blocks through the
/// log-Cholesky map, free parameters unchanged.
struct Map {
    layout: Layout,
}

impl Map {
    fn in_body(&self, j: usize) -> bool {
        j >= self.layout.first && j < self.layout.first + 10 * self.layout.bodies
    }

    fn pi(&self, phi: &[f64]) -> Vec<f64> {
        let mut pi = phi.to_vec();
        for b in 0..self.layout.bodies {
            let o = self.layout.first + 10 * b;
            let blk: [f64; 10] = phi[o..o + 10].try_into().expect("10");
            pi[o..o + 10].copy_from_slice(&standard_from_log_cholesky(&blk));
        }
        pi
    }

    /// `h += Σ_k w_k ∇²π_k(φ)` (free parameters are linear: no term).
    fn add_second_order(&self, phi: &[f64], w: &[f64], h: &mut Mat<f64>) {
        for b in 0..self.layout.bodies {
            let o = self.layout.first + 10 * b;
            let d2 = second_derivatives(&phi[o..o + 10]);
            for a in 0..10 {
                for c in 0..10 {
                    h[(o + a, o + c)] += (0..10).map(|k| w[o + k] * d2[a][c][k]).sum::<f64>();
                }
            }
        }
    }

    /// `R ∂π/∂φ`.
    fn jr(&self, r: MatRef<'_, f64>, phi: &[f64]) -> Mat<f64> {
        let p = phi.len();
        let mut d = Mat::<f64>::zeros(p, p);
        for j in 0..p {
            if !self.in_body(j) {
                d[(j, j)] = 1.0;
            }
        }
        for b in 0..self.layout.bodies {
            let o = self.layout.first + 10 * b;
            let jac = jacobian(&phi[o..o + 10]);
            for (k, col) in jac.iter().enumerate() {
                for (i, v) in col.iter().enumerate() {
                    d[(o + i, o + k)] = *v;
                }
            }
        }
        r * d.as_ref()
    }
}

fn block(x: &[f64], o: usize) -> [f64; 10] {
    x[o..o + 10].try_into().expect("10")
}

fn min_eigenvalue(pi: &[f64; 10]) -> f64 {
    SymmetricEigen::new(pseudo_inertia(pi)).eigenvalues.min()
}

/// The nearest (in eigenvalues) positive-definite pseudo-inertia.
fn project(pi: &[f64; 10], floor: f64) -> Option<[f64; 10]> {
    let eig = SymmetricEigen::new(pseudo_inertia(pi));
    let top = eig.eigenvalues.amax().max(f64::MIN_POSITIVE);
    let lam = eig.eigenvalues.map(|l| l.max(floor * top));
    let j = eig.eigenvectors * Matrix4::from_diagonal(&lam) * eig.eigenvectors.transpose();
    phi_from_pseudo(&(0.5 * (j + j.transpose())))
}

impl Accumulator {
    /// Physically consistent least squares on standard parameters: `min ‖A π − y‖²`
    /// over pseudo-inertias `J = U Uᵀ` (log-Cholesky, Rucker & Wensing 2022), by
    /// Newton steps with Levenberg–Marquardt damping (exact Hessian, Marquardt
    /// scaling, Nielsen's damping update) on the compressed triangle. Every body's pseudo-inertia at the solution is positive
    /// definite (minimum eigenvalues in [`Method::LogCholesky`]).
    ///
    /// Stops when the objective decreases by less than `1e-14` relative or the step
    /// is below `1e-12` relative. When OLS is physically consistent the result is the OLS solution
    /// with its σ; otherwise identifiable parameters are [`Status::Constrained`]
    /// without σ (the optimum lies on the boundary, where no local covariance
    /// exists) and unidentifiable ones get no value, as always.
    pub fn log_cholesky(&self, lopts: &LogCholeskyOptions, opts: &Options) -> Result<Estimate, IdentifyError> {
        let p = self.n_params();
        let layout = Layout::resolve(lopts.layout, p, 10)?;
        if !(lopts.log_det_weight.is_finite() && lopts.log_det_weight >= 0.0) {
            return Err(IdentifyError::InvalidArgument {
                what: "log-det weight",
                reason: format!("{}: must be finite and ≥ 0", lopts.log_det_weight),
            });
        }
        if !(lopts.eigenvalue_floor.is_finite() && lopts.eigenvalue_floor > 0.0) {
            return Err(IdentifyError::InvalidArgument {
                what: "eigenvalue floor",
                reason: format!("{}: must be finite and > 0", lopts.eigenvalue_floor),
            });
        }
        let ols = self.ols_start(opts)?;
        let (factors, tri, sub, x_ols, dof, noise) = (ols.factors, ols.tri, ols.sub, ols.x_ols, ols.dof, ols.noise);
        let start = match &lopts.start {
            Some(s) => {
                check_len(s, p, "start")?;
                check_finite_vector(s, Input::Prior)?;
                s.clone()
            }
            None => x_ols.clone(),
        };
        let map = Map { layout };
        let mut phi = start.clone();
        let mut projected = false;
        for b in 0..layout.bodies {
            let o = layout.first + 10 * b;
            let pi = block(&start, o);
            let f = match log_cholesky_from_standard(&pi).filter(|_| min_eigenvalue(&pi) > 0.0) {
                Some(f) => f,
                None => {
                    projected = true;
                    project(&pi, lopts.eigenvalue_floor).ok_or(IdentifyError::InvalidArgument {
                        what: "start",
                        reason: format!("body {b}: pseudo-inertia cannot be projected to positive definite"),
                    })?
                }
            };
            phi[o..o + 10].copy_from_slice(&f);
        }
        let (phi, iterations) = levenberg_marquardt(
            &map,
            tri.r.as_ref(),
            &tri.z,
            tri.rho2,
            phi,
            lopts.log_det_weight,
            lopts.max_iterations,
        )?;
        let x = map.pi(&phi);

        // The same fit as OLS (to roundoff) means the constraints are inactive.
        let diff: Vec<f64> = x.iter().zip(&x_ols).map(|(a, b)| a - b).collect();
        let fit_ols = super::dense::norm(&mat_vec(tri.r.as_ref(), &x_ols));
        let is_ols = super::dense::norm(&mat_vec(tri.r.as_ref(), &diff)) <= 1e-9 * fit_ols.max(f64::MIN_POSITIVE);
        let (status, cov) = if is_ols {
            (sub.status.clone(), noise.map(|s| scale(sub.unit_covariance(), s * s)))
        } else {
            let st = sub
                .status
                .iter()
                .map(|s| {
                    if *s == Status::Identified {
                        Status::Constrained
                    } else {
                        *s
                    }
                })
                .collect();
            (st, None)
        };
        let min_eigenvalues = (0..layout.bodies)
            .map(|b| min_eigenvalue(&block(&x, layout.first + 10 * b)))
            .collect();
        let residuals = Residuals::from_factors(&factors, &x, dof);
        let method = Method::LogCholesky {
            iterations,
            min_eigenvalues,
            projected,
            log_cholesky: phi,
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

/// Minimises `½‖R π(φ) − z‖²` (plus the constant `½ρ²`, which only sets the scale of
/// the relative tolerance) by Newton steps with Levenberg–Marquardt damping.
///
/// The Hessian is the exact one, `JᵀJ + Σ_k (Rᵀr)_k ∇²π_k`: at an inconsistent
/// data set the optimum has a large residual and lies at infinity in `φ`, where the
/// Gauss–Newton model alone stalls; with the second-order term each step still
/// removes a fixed fraction of the remaining gap.
fn levenberg_marquardt(
    map: &Map,
    r: MatRef<'_, f64>,
    z: &[f64],
    rho2: f64,
    mut phi: Vec<f64>,
    log_det_weight: f64,
    max_iterations: usize,
) -> Result<(Vec<f64>, usize), IdentifyError> {
    let p = phi.len();
    let residual = |phi: &[f64]| -> Vec<f64> {
        let rp = mat_vec(r, &map.pi(phi));
        rp.iter().zip(z).map(|(a, b)| a - b).collect()
    };
    // −log det J_b = −2 (4α + d1 + d2 + d3): linear in φ.
    let mut barrier = vec![0.0; p];
    for b in 0..map.layout.bodies {
        let o = map.layout.first + 10 * b;
        barrier[o] = -8.0;
        barrier[o + 1..o + 4].fill(-2.0);
    }
    let mut res = residual(&phi);
    let f0 = 0.5 * super::dense::dot(&res, &res) + 0.5 * rho2;
    let mu_b = log_det_weight * f0 / (4.0 * map.layout.bodies.max(1) as f64);
    let c: Vec<f64> = barrier.iter().map(|v| mu_b * v).collect();
    let cost = |res: &[f64], phi: &[f64]| 0.5 * super::dense::dot(res, res) + super::dense::dot(&c, phi);
    let mut f = cost(&res, &phi);
    let mut mu: f64 = 1e-3;
    let mut nu = 2.0;
    for iteration in 1..=max_iterations {
        let fit = 0.5 * super::dense::dot(&res, &res);
        if fit <= 1e-30 * (fit + 0.5 * rho2).max(f64::MIN_POSITIVE) {
            return Ok((phi, iteration - 1));
        }
        let jr = map.jr(r, &phi);
        let mut g = super::dense::mat_t_vec(jr.as_ref(), &res);
        for (gi, ci) in g.iter_mut().zip(&c) {
            *gi += ci;
        }
        let mut h = jr.transpose() * jr.as_ref();
        let diag: Vec<f64> = (0..p).map(|j| h[(j, j)]).collect();
        let w = super::dense::mat_t_vec(r, &res);
        map.add_second_order(&phi, &w, &mut h);
        let dmax = diag.iter().cloned().fold(0.0, f64::max);
        let d2: Vec<f64> = diag
            .iter()
            .map(|c| c.max(1e-24 * dmax).max(f64::MIN_POSITIVE))
            .collect();
        loop {
            // (H + μ D²) δ = −g; an indefinite H just needs more damping.
            let mut hd = h.clone();
            for j in 0..p {
                hd[(j, j)] += mu * d2[j];
            }
            let step = match hd.llt(Side::Lower) {
                Ok(llt) => first_column(llt.solve(column(&g)).as_ref())
                    .iter()
                    .map(|v| -v)
                    .collect::<Vec<f64>>(),
                Err(_) => {
                    mu *= nu;
                    nu *= 2.0;
                    if mu > 1e20 {
                        return Err(IdentifyError::NotConverged {
                            algorithm: "log-Cholesky Levenberg–Marquardt",
                            iterations: iteration,
                        });
                    }
                    continue;
                }
            };
            let trial: Vec<f64> = phi.iter().zip(&step).map(|(a, b)| a + b).collect();
            let res_new = residual(&trial);
            let f_new = cost(&res_new, &trial);
            let hs = mat_vec(h.as_ref(), &step);
            let predicted = -(super::dense::dot(&g, &step) + 0.5 * super::dense::dot(&step, &hs));
            let actual = f - f_new;
            let small_step = super::dense::norm(&step) <= 1e-12 * (super::dense::norm(&phi) + 1e-12);
            if f_new.is_finite() && actual > 0.0 {
                let rho = if predicted > 0.0 { actual / predicted } else { 0.0 };
                mu *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
                nu = 2.0;
                phi = trial;
                res = res_new;
                f = f_new;
                if actual <= 1e-14 * (f + 0.5 * rho2) || small_step {
                    return Ok((phi, iteration));
                }
                break;
            }
            if small_step || mu > 1e20 {
                // No decrease is possible at roundoff level: a minimum.
                return Ok((phi, iteration));
            }
            mu *= nu;
            nu *= 2.0;
        }
    }
    Err(IdentifyError::NotConverged {
        algorithm: "log-Cholesky Levenberg–Marquardt",
        iterations: max_iterations,
    })
}
