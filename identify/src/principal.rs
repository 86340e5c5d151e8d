//! Physically consistent estimation in the paper's principal form.
//!
//! Per body `θ = (m, J1, J2, J3)` with `m ≥ ε_m`, `J_i ≥ ε_J` and the triangle
//! inequalities `J_j + J_k − J_i ≥ ε_t`: a convex QP `min ½‖R θ − z‖²` over linear
//! inequalities, solved by a primal active-set method (Nocedal & Wright, Alg. 16.3)
//! on the compressed triangle, every subproblem by QR (no normal equations).

use faer::prelude::*;
use faer::{Mat, MatRef};

use super::accumulate::{prior_or_zero, Accumulator};
use super::dense::{column, dot, first_column, mat_t_vec, mat_vec};
use super::error::IdentifyError;
use super::estimate::{ActiveConstraint, ConstraintKind, Estimate, Method, Residuals, Status};
use super::least_squares::scale;
use super::{Layout, Options};

/// Margins of the principal-form constraints (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Margins {
    /// `m ≥ mass` (kg). Default `1e-6`.
    pub mass: f64,
    /// `J_i ≥ inertia` (kg m²). Default `1e-9`.
    pub inertia: f64,
    /// `J_j + J_k − J_i ≥ triangle` (kg m²). Default 0 (planar bodies are allowed).
    pub triangle: f64,
}

impl Default for Margins {
    fn default() -> Self {
        Self {
            mass: 1e-6,
            inertia: 1e-9,
            triangle: 0.0,
        }
    }
}

/// Options of [`Accumulator::principal_consistent`].
#[derive(Clone, Debug, PartialEq)]
pub struct PrincipalOptions {
    /// Where the `(m, J1, J2, J3)` blocks are; `None`: every parameter, 4 per body.
    pub layout: Option<Layout>,
    pub margins: Margins,
    /// Directions the data do not determine are pulled toward this vector (length
    /// `p`; default zero, i.e. the minimum-norm choice), as far as the constraints
    /// allow. It never moves the identifiable part of an unconstrained solution.
    pub prior: Option<Vec<f64>>,
    /// Active-set iterations before [`IdentifyError::NotConverged`]. Default 1000.
    pub max_iterations: usize,
}

impl Default for PrincipalOptions {
    fn default() -> Self {
        Self {
            layout: None,
            margins: Margins::default(),
            prior: None,
            max_iterations: 1000,
        }
    }
}

/// Linear inequalities `G x ≥ h`.
struct Constraints {
    g: Vec<Vec<f64>>,
    h: Vec<f64>,
    kind: Vec<(usize, ConstraintKind)>,
}

fn principal_constraints(p: usize, layout: Layout, margins: &Margins) -> Constraints {
    let mut c = Constraints {
        g: Vec::new(),
        h: Vec::new(),
        kind: Vec::new(),
    };
    for body in 0..layout.bodies {
        let o = layout.first + 4 * body;
        let mut push = |coef: &[(usize, f64)], h: f64, kind| {
            let mut row = vec![0.0; p];
            for &(j, v) in coef {
                row[o + j] = v;
            }
            c.g.push(row);
            c.h.push(h);
            c.kind.push((body, kind));
        };
        push(&[(0, 1.0)], margins.mass, ConstraintKind::Mass);
        for i in 1..=3 {
            push(&[(i, 1.0)], margins.inertia, ConstraintKind::Inertia(i));
        }
        for i in 1..=3 {
            let (j, k) = match i {
                1 => (2, 3),
                2 => (1, 3),
                _ => (1, 2),
            };
            push(
                &[(j, 1.0), (k, 1.0), (i, -1.0)],
                margins.triangle,
                ConstraintKind::Triangle(i),
            );
        }
    }
    c
}

impl Accumulator {
    /// Physically consistent least squares in the principal form: `min ‖A θ − y‖²`
    /// subject to, per body block `(m, J1, J2, J3)`, `m ≥ ε_m`, `J_i ≥ ε_J`,
    /// `J_j + J_k − J_i ≥ ε_t` ([`Margins`]).
    ///
    /// Returns the OLS solution unchanged when it is feasible; otherwise a feasible
    /// point satisfying the KKT conditions (active constraints and their
    /// multipliers in [`Method::PrincipalConsistent`]). Directions the data do not
    /// determine are regularised toward [`PrincipalOptions::prior`] with weight
    /// `σ_r²` (the smallest retained singular value squared) so the QP is strictly
    /// convex; they still get no value in [`Estimate::params`]. Parameters touched
    /// by an active constraint are [`Status::Constrained`] (no σ); the others'
    /// σ come from the covariance restricted to the active face,
    /// `σ̂² Z (Zᵀ H Z)⁻¹ Zᵀ`, with the OLS noise level.
    pub fn principal_consistent(&self, popts: &PrincipalOptions, opts: &Options) -> Result<Estimate, IdentifyError> {
        let p = self.n_params();
        let layout = Layout::resolve(popts.layout, p, 4)?;
        let mg = &popts.margins;
        for (what, v) in [
            ("mass margin", mg.mass),
            ("inertia margin", mg.inertia),
            ("triangle margin", mg.triangle),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(IdentifyError::InvalidArgument {
                    what,
                    reason: format!("{v}: must be finite and ≥ 0"),
                });
            }
        }
        let prior = prior_or_zero(popts.prior.as_ref(), p)?;
        let ols = self.ols_start(opts)?;
        let (factors, tri, sub, dof, noise) = (ols.factors, ols.tri, ols.sub, ols.dof, ols.noise);

        // ½‖M x − b‖² with M = [R; √δ V₂ᵀ], b = [z; √δ V₂ᵀ prior].
        let q = p - sub.rank;
        let sd = sub.s[sub.rank - 1];
        let m = Mat::from_fn(p + q, p, |i, j| {
            if i < p {
                tri.r[(i, j)]
            } else {
                sd * sub.v[(j, sub.rank + i - p)]
            }
        });
        let mut b = tri.z.clone();
        for k in 0..q {
            b.push(sd * (0..p).map(|j| sub.v[(j, sub.rank + k)] * prior[j]).sum::<f64>());
        }
        let cons = principal_constraints(p, layout, mg);
        let x_free = first_column(m.qr().solve_lstsq(column(&b)).as_ref());
        let start = if feasible(&cons, &x_free) {
            x_free
        } else {
            feasible_start(&x_free, layout, mg)
        };
        let QpSolution {
            x,
            working,
            multipliers: mu,
            iterations,
        } = active_set(m.as_ref(), &b, &cons, start, popts.max_iterations)?;

        let mut status = sub.status.clone();
        for &i in &working {
            for j in 0..p {
                if cons.g[i][j] != 0.0 && status[j] == Status::Identified {
                    status[j] = Status::Constrained;
                }
            }
        }
        let cov = noise.map(|s| scale(face_covariance(m.as_ref(), &cons, &working), s * s));
        let active = working
            .iter()
            .zip(&mu)
            .map(|(&i, &multiplier)| ActiveConstraint {
                body: cons.kind[i].0,
                kind: cons.kind[i].1,
                multiplier,
            })
            .collect();
        let residuals = Residuals::from_factors(&factors, &x, dof);
        let method = Method::PrincipalConsistent { active, iterations };
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

fn slack(cons: &Constraints, i: usize, x: &[f64]) -> f64 {
    dot(&cons.g[i], x) - cons.h[i]
}

fn feasible(cons: &Constraints, x: &[f64]) -> bool {
    (0..cons.h.len()).all(|i| slack(cons, i, x) >= 0.0)
}

/// A point inside every constraint: infeasible bodies become `(max(m, ε_m), c, c, c)`.
fn feasible_start(x: &[f64], layout: Layout, mg: &Margins) -> Vec<f64> {
    let mut out = x.to_vec();
    for body in 0..layout.bodies {
        let o = layout.first + 4 * body;
        let mean = (x[o + 1].max(0.0) + x[o + 2].max(0.0) + x[o + 3].max(0.0)) / 3.0;
        let c = mean.max(mg.inertia).max(mg.triangle).max(f64::MIN_POSITIVE);
        out[o] = x[o].max(mg.mass);
        out[o + 1] = c;
        out[o + 2] = c;
        out[o + 3] = c;
    }
    out
}

/// Orthonormal basis of `{d : G_W d = 0}` (`p × (p − |W|)`).
fn face_basis(cons: &Constraints, working: &[usize], p: usize) -> Mat<f64> {
    if working.is_empty() {
        return Mat::identity(p, p);
    }
    let gt = Mat::from_fn(p, working.len(), |i, k| cons.g[working[k]][i]);
    let q = gt.qr().compute_Q();
    q.as_ref().subcols(working.len(), p - working.len()).to_owned()
}

/// `Z (Zᵀ MᵀM Z)⁻¹ Zᵀ` via the QR of `M Z`.
fn face_covariance(m: MatRef<'_, f64>, cons: &Constraints, working: &[usize]) -> Mat<f64> {
    let p = m.ncols();
    let z = face_basis(cons, working, p);
    let k = z.ncols();
    if k == 0 {
        return Mat::zeros(p, p);
    }
    let mz = m * z.as_ref();
    let rz = mz.qr().thin_R().to_owned();
    // T = Z R⁻¹, from Rᵀ Tᵀ = Zᵀ.
    let mut tt = z.transpose().to_owned();
    rz.transpose().solve_lower_triangular_in_place(tt.as_mut());
    tt.transpose() * tt.as_ref()
}

/// The solution of [`active_set`]: the point, the working set at the end, its
/// multipliers and the iteration count.
struct QpSolution {
    x: Vec<f64>,
    working: Vec<usize>,
    multipliers: Vec<f64>,
    iterations: usize,
}

/// Primal active set for `min ½‖M x − b‖²` s.t. `G x ≥ h`, from a feasible `x`.
fn active_set(
    m: MatRef<'_, f64>,
    b: &[f64],
    cons: &Constraints,
    mut x: Vec<f64>,
    max_iterations: usize,
) -> Result<QpSolution, IdentifyError> {
    let p = x.len();
    let mut working: Vec<usize> = Vec::new();
    let mtb = mat_t_vec(m, b);
    for iteration in 1..=max_iterations {
        // Step to the minimiser on the current face.
        let z = face_basis(cons, &working, p);
        let d = if z.ncols() == 0 {
            vec![0.0; p]
        } else {
            let mx = mat_vec(m, &x);
            let res: Vec<f64> = b.iter().zip(&mx).map(|(b, m)| b - m).collect();
            let mz = m * z.as_ref();
            let w = mz.qr().solve_lstsq(column(&res));
            first_column((z.as_ref() * w.as_ref()).as_ref())
        };
        let dn = super::dense::norm(&d);
        let mut alpha = 1.0;
        let mut blocking = None;
        for i in 0..cons.h.len() {
            if working.contains(&i) {
                continue;
            }
            let gd = dot(&cons.g[i], &d);
            // Roundoff-level decrease along a constraint already in the span of the
            // working set must not block (it would make the working set dependent).
            if gd < -1e-12 * super::dense::norm(&cons.g[i]) * dn {
                let a = slack(cons, i, &x).max(0.0) / -gd;
                if a < alpha {
                    alpha = a;
                    blocking = Some(i);
                }
            }
        }
        for (xi, di) in x.iter_mut().zip(&d) {
            *xi += alpha * di;
        }
        if let Some(i) = blocking {
            working.push(i);
            continue;
        }
        // x minimises on the face: check the multipliers of ∇f = G_Wᵀ μ.
        if working.is_empty() {
            return Ok(QpSolution {
                x,
                working,
                multipliers: Vec::new(),
                iterations: iteration,
            });
        }
        let mx = mat_vec(m, &x);
        let mtmx = mat_t_vec(m, &mx);
        let grad: Vec<f64> = mtmx.iter().zip(&mtb).map(|(a, b)| a - b).collect();
        let gt = Mat::from_fn(p, working.len(), |i, k| cons.g[working[k]][i]);
        let mu = first_column(gt.qr().solve_lstsq(column(&grad)).as_ref());
        let scale = mtmx.iter().chain(&mtb).fold(0.0f64, |a, v| a.max(v.abs()));
        let tol = 1e-10 * scale.max(f64::MIN_POSITIVE);
        let (worst, &most_negative) = mu
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .expect("working set is not empty");
        if most_negative >= -tol {
            return Ok(QpSolution {
                x,
                working,
                multipliers: mu,
                iterations: iteration,
            });
        }
        working.remove(worst);
    }
    Err(IdentifyError::NotConverged {
        algorithm: "principal-form active-set QP",
        iterations: max_iterations,
    })
}
