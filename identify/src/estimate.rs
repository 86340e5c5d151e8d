//! The result every estimator returns, and its table.
//!
//! A parameter gets a value only when the data (or, for ridge, the prior) determine
//! it; the rest are reported as "only in combination" with the combinations that
//! are identifiable, or as having no effect on the data.

use std::fmt;

use faer::Mat;

use super::accumulate::{channel_rss, Factor};
use super::subspace::Subspace;

/// How a parameter's value was determined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Determined by the data alone; has a value and a σ.
    Identified,
    /// Not identifiable alone: it only enters identifiable combinations (see
    /// [`Estimate::combinations`]). No value.
    InCombination,
    /// Not identifiable: its regressor column is zero, the data carry nothing about it.
    NoEffect,
    /// Ridge: the value comes mostly from the prior (data weight below ½).
    FromPrior,
    /// Physically consistent estimation: identifiable, but the value is shaped by
    /// the consistency constraints (an active bound, or a projected start), so no σ.
    Constrained,
    /// Left out of the model by choice (a joint term not fitted): held at 0 in the
    /// solution, not estimated. No value.
    Excluded,
}

/// One parameter of an [`Estimate`].
#[derive(Clone, Debug, PartialEq)]
pub struct ParamEstimate {
    /// The estimate; `None` when the parameter is not identifiable.
    pub value: Option<f64>,
    /// Its standard deviation; `None` where not meaningful.
    pub sigma: Option<f64>,
    pub status: Status,
}

impl ParamEstimate {
    /// Whether the value stands out of its own noise: `|value| ≥ σ`. An identifiable
    /// parameter whose σ exceeds its value is estimated as "somewhere around zero"
    /// and must not be read as a number. True where no σ is known.
    pub fn is_significant(&self) -> bool {
        match (self.value, self.sigma) {
            (Some(v), Some(s)) => v.abs() >= s,
            _ => true,
        }
    }

    /// `100 σ / |value|`, when both exist and the value is not zero.
    pub fn relative_sigma_percent(&self) -> Option<f64> {
        match (self.value, self.sigma) {
            (Some(v), Some(s)) if v != 0.0 => Some(100.0 * s / v.abs()),
            _ => None,
        }
    }
}

/// An identifiable linear combination `Σ c_j x_j` (a base parameter). The first
/// term is the lead parameter with coefficient 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Combination {
    pub terms: Vec<(usize, f64)>,
    pub value: f64,
    pub sigma: Option<f64>,
}

/// Residual statistics, unweighted, `y − A x̂`.
#[derive(Clone, Debug, PartialEq)]
pub struct Residuals {
    pub rows: usize,
    pub sum_of_squares: f64,
    /// `√(‖r‖² / m)`.
    pub rms: f64,
    /// RMS per channel (0 for a channel without rows).
    pub per_channel_rms: Vec<f64>,
    pub per_channel_rows: Vec<usize>,
    /// Degrees of freedom used for the noise variance: `m − rank` (ridge: `m − tr H`).
    pub dof: f64,
}

impl Residuals {
    pub(crate) fn from_factors(factors: &[Factor], x: &[f64], dof: f64) -> Self {
        let rss = channel_rss(factors, x);
        let rows: usize = factors.iter().map(|f| f.rows).sum();
        let sum: f64 = rss.iter().sum();
        Self {
            rows,
            sum_of_squares: sum,
            rms: (sum / rows as f64).sqrt(),
            per_channel_rms: rss
                .iter()
                .zip(factors)
                .map(|(s, f)| if f.rows == 0 { 0.0 } else { (s / f.rows as f64).sqrt() })
                .collect(),
            per_channel_rows: factors.iter().map(|f| f.rows).collect(),
            dof,
        }
    }
}

/// An active physical-consistency constraint of the principal-form estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveConstraint {
    /// Body index within the layout (0-based).
    pub body: usize,
    pub kind: ConstraintKind,
    /// Lagrange multiplier (≥ 0): how much the fit would improve per unit relaxation.
    pub multiplier: f64,
}

/// The principal-form constraints on `θ = (m, J1, J2, J3)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstraintKind {
    /// `m ≥ ε_m`.
    Mass,
    /// `J_i ≥ ε_J`, `i ∈ {1, 2, 3}`.
    Inertia(usize),
    /// `J_j + J_k − J_i ≥ ε_t`, `i ∈ {1, 2, 3}`.
    Triangle(usize),
}

/// Which estimator produced an [`Estimate`], with what it alone reports.
#[derive(Clone, Debug, PartialEq)]
pub enum Method {
    Ols,
    /// Weighted least squares; `channel_sigma` the per-channel noise σ used as
    /// weights `1/σ_c`; `variance_factor` the a-posteriori unit variance
    /// `‖W r‖² / (m − r)` that scales the covariance.
    Wls {
        channel_sigma: Vec<f64>,
        variance_factor: f64,
    },
    /// Total least squares; `column_scaling` whether the columns of `[A y]` were
    /// divided by their norms first (the default).
    Tls {
        column_scaling: bool,
    },
    /// Ridge toward a prior, `min ‖A x − y‖² + λ ‖D (x − x₀)‖²`; `column_scaling`:
    /// `D² = diag(AᵀA)` (the default: `λ` dimensionless), else `D = I`.
    /// `data_weight[j]` is the diagonal of the resolution matrix
    /// `(AᵀA + λD²)⁻¹AᵀA`: 1 = fixed by the data, 0 = by the prior.
    Ridge {
        lambda: f64,
        column_scaling: bool,
        data_weight: Vec<f64>,
    },
    PrincipalConsistent {
        active: Vec<ActiveConstraint>,
        iterations: usize,
    },
    /// Log-Cholesky (Rucker & Wensing 2022); `min_eigenvalues` per body of the
    /// pseudo-inertia at the solution (all > 0), `projected` whether the start had
    /// to be projected onto physical consistency, `log_cholesky` the solution's
    /// variables `φ` (10 per body in the layout, free parameters as they are; a warm
    /// start for [`super::standard_from_log_cholesky`]).
    LogCholesky {
        iterations: usize,
        min_eigenvalues: Vec<f64>,
        projected: bool,
        log_cholesky: Vec<f64>,
    },
    /// Pseudo-inertia barrier method: `gap_bound` certifies the objective `½‖Aπ − y‖²`
    /// is within it of the consistent optimum; `bodies_at_bound` are held by the
    /// constraint, `params_at_bound` the parameters kept `≥ 0`
    /// ([`super::StandardOptions::nonnegative`]) that the bound holds near zero;
    /// `min_eigenvalues` per body of the pseudo-inertia (all > 0).
    StandardConsistent {
        iterations: usize,
        gap_bound: f64,
        bodies_at_bound: Vec<usize>,
        params_at_bound: Vec<usize>,
        min_eigenvalues: Vec<f64>,
    },
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Method::Ols => write!(f, "ordinary least squares"),
            Method::Wls { channel_sigma, .. } => {
                write!(f, "weighted least squares (channel σ = [{}])", list(channel_sigma))
            }
            Method::Tls { column_scaling: true } => write!(f, "total least squares (columns scaled)"),
            Method::Tls { column_scaling: false } => write!(f, "total least squares (unscaled)"),
            Method::Ridge {
                lambda,
                column_scaling: true,
                ..
            } => write!(f, "ridge toward prior (scale-free λ = {})", num(*lambda)),
            Method::Ridge { lambda, .. } => write!(f, "ridge toward prior (unscaled λ = {})", num(*lambda)),
            Method::PrincipalConsistent { active, iterations } => write!(
                f,
                "physically consistent, principal form ({} active constraints, {iterations} iterations)",
                active.len()
            ),
            Method::LogCholesky {
                iterations, projected, ..
            } => write!(
                f,
                "physically consistent, log-Cholesky ({iterations} iterations{})",
                if *projected { ", projected start" } else { "" }
            ),
            Method::StandardConsistent {
                iterations,
                bodies_at_bound,
                params_at_bound,
                ..
            } => {
                write!(
                    f,
                    "physically consistent, pseudo-inertia barrier ({iterations} Newton steps, {} bodies at the bound",
                    bodies_at_bound.len()
                )?;
                match params_at_bound.len() {
                    0 => {}
                    1 => write!(f, ", 1 parameter held at 0")?,
                    k => write!(f, ", {k} parameters held at 0")?,
                }
                write!(f, ")")
            }
        }
    }
}

/// The result of every batch estimator.
///
/// Principle: unidentifiable directions are reported as such, never as numbers.
/// `params[j].value` is `None` unless parameter `j` is determined; the identifiable
/// combinations are in `combinations`, the null space in `null_space`.
#[derive(Clone, Debug)]
pub struct Estimate {
    pub method: Method,
    /// A full parameter vector that fits the data as well as the estimator can:
    /// OLS/WLS/TLS the minimum-norm solution (zero in the null space), ridge and the
    /// consistent estimators their solution. Use it to *predict* `A x`; read
    /// parameter values from `params`, not from here.
    pub solution: Vec<f64>,
    pub params: Vec<ParamEstimate>,
    /// Identifiable combinations (base parameters), one per lead parameter,
    /// singletons included; `rank` of them.
    pub combinations: Vec<Combination>,
    pub rank: usize,
    /// Singular values `≤ tolerance` count as zero.
    pub tolerance: f64,
    /// Singular values of the (weighted) regressor, nonincreasing.
    pub singular_values: Vec<f64>,
    /// Orthonormal basis of the null space (`p − rank` vectors).
    pub null_space: Vec<Vec<f64>>,
    /// `σ₁ / σ_rank`, the condition number of the identifiable part.
    pub condition_number: f64,
    pub residuals: Residuals,
    /// Estimated noise σ of one row (OLS, ridge: `√(‖r‖²/dof)`; TLS: of an entry
    /// of `y`, which unscaled TLS assumes of every entry of `[A y]`); `None` without
    /// degrees of freedom or for WLS (see `Method::Wls`).
    pub noise_sigma: Option<f64>,
    /// Covariance of `solution` (`p × p`) on the identifiable subspace, or the
    /// posterior covariance for ridge; `None` when no noise level is available.
    pub covariance: Option<Mat<f64>>,
    /// Tolerance for "`c` is orthogonal to the null space" in [`Estimate::value_of`].
    pub identifiability_tolerance: f64,
    pub(crate) subspace: Subspace,
}

impl Estimate {
    /// Builds the per-parameter and per-combination report from a solution.
    /// `status` overrides the data-identifiability status (ridge, constrained).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn assemble(
        method: Method,
        subspace: Subspace,
        solution: Vec<f64>,
        covariance: Option<Mat<f64>>,
        status: Vec<Status>,
        residuals: Residuals,
        noise_sigma: Option<f64>,
        identifiability_tolerance: f64,
    ) -> Self {
        let var = |c: &[(usize, f64)]| -> Option<f64> {
            covariance.as_ref().map(|cov| {
                let mut s = 0.0;
                for &(i, ci) in c {
                    for &(j, cj) in c {
                        s += ci * cj * cov[(i, j)];
                    }
                }
                s.max(0.0).sqrt()
            })
        };
        let params = status
            .iter()
            .enumerate()
            .map(|(j, &st)| {
                let has_value = matches!(st, Status::Identified | Status::FromPrior | Status::Constrained);
                let has_sigma = matches!(st, Status::Identified | Status::FromPrior);
                ParamEstimate {
                    value: has_value.then_some(solution[j]),
                    sigma: if has_sigma { var(&[(j, 1.0)]) } else { None },
                    status: st,
                }
            })
            .collect();
        let combinations = subspace
            .combinations
            .iter()
            .map(|terms| Combination {
                terms: terms.clone(),
                value: terms.iter().map(|&(j, c)| c * solution[j]).sum(),
                sigma: var(terms),
            })
            .collect();
        Self {
            method,
            params,
            combinations,
            rank: subspace.rank,
            tolerance: subspace.tolerance,
            singular_values: subspace.s.clone(),
            null_space: subspace.null_space(),
            condition_number: subspace.condition_number(),
            residuals,
            noise_sigma,
            covariance,
            identifiability_tolerance,
            solution,
            subspace,
        }
    }

    /// Number of parameters.
    pub fn n_params(&self) -> usize {
        self.params.len()
    }

    /// Values per parameter (`None` = not identifiable).
    pub fn values(&self) -> Vec<Option<f64>> {
        self.params.iter().map(|p| p.value).collect()
    }

    /// σ per parameter (`None` = not identifiable or not meaningful).
    pub fn sigmas(&self) -> Vec<Option<f64>> {
        self.params.iter().map(|p| p.sigma).collect()
    }

    /// Relative σ in percent per parameter.
    pub fn relative_sigma_percent(&self) -> Vec<Option<f64>> {
        self.params.iter().map(ParamEstimate::relative_sigma_percent).collect()
    }

    /// Whether each parameter is identifiable by the data alone.
    pub fn identifiable(&self) -> Vec<bool> {
        self.subspace.status.iter().map(|s| *s == Status::Identified).collect()
    }

    /// Whether the data determine `cᵀx` (`c` orthogonal to the null space).
    pub fn is_identifiable(&self, c: &[f64]) -> bool {
        c.len() == self.n_params() && self.subspace.is_identifiable(c, self.identifiability_tolerance)
    }

    /// The estimate of `cᵀx`, or `None` when the data do not determine it.
    pub fn value_of(&self, c: &[f64]) -> Option<f64> {
        self.is_identifiable(c).then(|| super::dense::dot(c, &self.solution))
    }

    /// The standard deviation of `cᵀx̂`, or `None` when `cᵀx` is not identifiable
    /// or no covariance is available.
    pub fn sigma_of(&self, c: &[f64]) -> Option<f64> {
        if !self.is_identifiable(c) {
            return None;
        }
        let cov = self.covariance.as_ref()?;
        Some(super::dense::quadratic_form(cov.as_ref(), c).max(0.0).sqrt())
    }

    /// `aᵀ x̂`: the prediction of one observation (the same for every least-squares
    /// solution as long as `a` lies in the excited subspace).
    pub fn predict(&self, a: &[f64]) -> f64 {
        super::dense::dot(a, &self.solution)
    }

    /// A printable table with the caller's parameter names (missing names are
    /// shown as `x<j>`).
    pub fn table<'a>(&'a self, names: &'a [&'a str]) -> Table<'a> {
        Table { estimate: self, names }
    }
}

impl fmt::Display for Estimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.table(&[]).fmt(f)
    }
}

/// [`Estimate::table`]: name, value, σ, σ% and a note per parameter, then the
/// identifiable combinations of unidentifiable parameters.
pub struct Table<'a> {
    estimate: &'a Estimate,
    names: &'a [&'a str],
}

impl Table<'_> {
    fn name(&self, j: usize) -> String {
        self.names.get(j).map_or_else(|| format!("x{j}"), |s| s.to_string())
    }
}

impl fmt::Display for Table<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let e = self.estimate;
        let p = e.n_params();
        writeln!(f, "{}", e.method)?;
        writeln!(
            f,
            "{} rows, {} parameters, rank {} (tolerance {:.3e}), condition number {}",
            e.residuals.rows,
            p,
            e.rank,
            e.tolerance,
            num(e.condition_number)
        )?;
        write!(f, "residual RMS {}", num(e.residuals.rms))?;
        if e.residuals.per_channel_rms.len() > 1 {
            write!(f, ", per channel [{}]", list(&e.residuals.per_channel_rms))?;
        }
        if let Some(s) = e.noise_sigma {
            write!(f, ", noise σ̂ {}", num(s))?;
        }
        writeln!(f)?;
        let width = (0..p).map(|j| self.name(j).chars().count()).max().unwrap_or(4).max(9);
        writeln!(
            f,
            "{:<width$}  {:>14}  {:>11}  {:>8}  note",
            "parameter", "value", "σ", "σ%"
        )?;
        // Combinations of more than one parameter, numbered β1, β2, … for the notes.
        let groups: Vec<(usize, &Combination)> = e
            .combinations
            .iter()
            .filter(|c| c.terms.len() > 1)
            .enumerate()
            .map(|(k, c)| (k + 1, c))
            .collect();
        for (j, pe) in e.params.iter().enumerate() {
            let value = pe.value.map_or_else(|| "—".to_string(), num);
            let sigma = pe.sigma.map_or_else(|| "—".to_string(), num);
            let rel = pe
                .relative_sigma_percent()
                .map_or_else(|| "—".to_string(), |r| format!("{r:.2}"));
            let note = match pe.status {
                Status::Identified if pe.is_significant() => String::new(),
                Status::Identified => "not significant: σ exceeds the value".to_string(),
                Status::InCombination => {
                    let ids: Vec<String> = groups
                        .iter()
                        .filter(|(_, c)| c.terms.iter().any(|&(i, _)| i == j))
                        .map(|(k, _)| format!("β{k}"))
                        .collect();
                    format!("NOT IDENTIFIABLE alone; only in {}", ids.join(", "))
                }
                Status::NoEffect => "NOT IDENTIFIABLE: no effect on the data".to_string(),
                Status::FromPrior => match &e.method {
                    Method::Ridge { data_weight, .. } => {
                        format!("from the prior (data weight {:.2})", data_weight[j])
                    }
                    _ => "from the prior".to_string(),
                },
                Status::Constrained => "shaped by physical consistency".to_string(),
                Status::Excluded => "left out of the model (held at 0)".to_string(),
            };
            writeln!(
                f,
                "{:<width$}  {value:>14}  {sigma:>11}  {rel:>8}  {note}",
                self.name(j)
            )?;
        }
        if !groups.is_empty() {
            writeln!(f, "identifiable combinations:")?;
            for (k, c) in &groups {
                let mut expr = String::new();
                for (t, &(i, coef)) in c.terms.iter().enumerate() {
                    let sign = if coef < 0.0 {
                        " − "
                    } else if t == 0 {
                        ""
                    } else {
                        " + "
                    };
                    let mag = coef.abs();
                    let factor = if (mag - 1.0).abs() < 1e-12 {
                        String::new()
                    } else {
                        format!("{}·", coefficient(mag))
                    };
                    expr.push_str(&format!("{sign}{factor}{}", self.name(i)));
                }
                let sigma = c.sigma.map_or_else(String::new, |s| format!(" ± {}", num(s)));
                writeln!(f, "  β{k} = {expr} = {}{sigma}", num(c.value))?;
            }
        }
        Ok(())
    }
}

/// Six significant digits, fixed notation for ordinary magnitudes.
fn num(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".to_string()
    } else if (1e-3..1e6).contains(&a) {
        let decimals = (5 - a.log10().floor() as i32).clamp(0, 8) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.5e}")
    }
}

/// A coefficient with at most six significant digits and no trailing zeros.
fn coefficient(v: f64) -> String {
    let s = num(v);
    if s.contains('e') || !s.contains('.') {
        s
    } else {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn list(v: &[f64]) -> String {
    v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", ")
}
