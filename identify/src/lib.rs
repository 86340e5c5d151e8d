//! Inertial-parameter identification on a linear model `y = A x + e`.
//!
//! Rows go into an [`Accumulator`] (O(p²) memory: per-channel triangular factors of
//! `[A y]`); every batch estimator reads those factors: [`Accumulator::ols`],
//! [`Accumulator::wls`] (Gautier's per-channel weights), [`Accumulator::tls`],
//! [`Accumulator::ridge`], [`Accumulator::principal_consistent`] (the paper's
//! `θ = (m, J1, J2, J3)` with `m > 0`, `J > 0` and the triangle inequalities) and
//! [`Accumulator::standard_consistent`] (standard parameters with a positive-definite
//! pseudo-inertia, a barrier method with an optimality certificate) and
//! [`Accumulator::log_cholesky`] (the same constraint through the log-Cholesky
//! parameterisation). [`Rls`] is the recursive estimator with forgetting.
//!
//! **Rank is explicit everywhere.** The rank comes from the SVD of the compressed
//! regressor with a stated tolerance; a parameter the data do not determine gets no
//! value in [`Estimate::params`] and is listed as "only in combination" with the
//! identifiable combinations (base parameters) in [`Estimate::combinations`]; the
//! null space is in [`Estimate::null_space`]. Dense linear algebra is faer's.
//!
//! ```
//! use dyngen_identify::{self as identify, faer::Mat, Options};
//! // Columns 1 and 2 are equal: only x1 + x2 is identifiable.
//! let a = Mat::from_fn(8, 3, |i, j| if j == 0 { 1.0 } else { (i as f64).sin() });
//! let y: Vec<f64> = (0..8).map(|i| 1.0 + 3.0 * (i as f64).sin()).collect();
//! let est = identify::ols(a.as_ref(), &y).unwrap();
//! assert_eq!(est.rank, 2);
//! assert!(est.params[1].value.is_none() && est.params[2].value.is_none());
//! assert!((est.value_of(&[0.0, 1.0, 1.0]).unwrap() - 3.0).abs() < 1e-12);
//! println!("{}", est.table(&["offset", "a", "b"]));
//! ```

pub mod choice;
pub mod data;
pub mod extras;
pub mod floating;
pub mod friction;
pub mod gains;
pub mod mim;
pub mod partial;
pub mod payload;
pub mod pipeline;
pub mod report;
pub mod simulate;
pub mod stribeck;
pub mod validate;

mod accumulate;
mod dense;
mod error;
mod estimate;
mod least_squares;
mod log_cholesky;
mod minimise;
mod principal;
mod rls;
mod standard;
mod subspace;

pub use faer;

pub use accumulate::{
    in_parallel, Accumulation, Accumulator, AccumulatorState, ChannelState, NORMAL_EQUATIONS_RESOLUTION,
};
pub use error::{IdentifyError, Input};
pub use estimate::{
    ActiveConstraint, Combination, ConstraintKind, Estimate, Method, ParamEstimate, Residuals, Status, Table,
};
pub use log_cholesky::{
    log_cholesky_from_standard, pseudo_inertia, standard_from_log_cholesky, standard_from_pseudo_inertia,
    LogCholeskyOptions,
};
pub use principal::{Margins, PrincipalOptions};
pub use rls::Rls;
pub use standard::StandardOptions;

use faer::MatRef;

/// How far an estimate is from the truth, relative to the truth:
/// `|estimate − truth| / |truth|`. Where the truth is exactly 0 no relative error
/// exists, and the absolute error is given instead, so that a parameter that is
/// truly zero is still judged by how far its estimate strays.
pub fn relative_error(estimate: f64, truth: f64) -> f64 {
    let absolute = (estimate - truth).abs();
    if truth == 0.0 {
        absolute
    } else {
        absolute / truth.abs()
    }
}

/// How rows are grouped into channels (e.g. joints) for per-channel weights and
/// residual RMS.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Channels {
    /// One channel.
    #[default]
    Single,
    /// Row `i` belongs to channel `i % n`: regressors stacked sample by sample,
    /// `n` joints per sample.
    Interleaved(usize),
    /// Channel of every row, by global row index (channels `0..=max`).
    Labels(Vec<usize>),
}

impl Channels {
    /// Number of channels.
    pub fn count(&self) -> usize {
        match self {
            Channels::Single => 1,
            Channels::Interleaved(n) => (*n).max(1),
            Channels::Labels(l) => l.iter().max().map_or(1, |m| m + 1),
        }
    }

    pub(crate) fn channel_of(&self, row: usize) -> usize {
        match self {
            Channels::Single => 0,
            Channels::Interleaved(n) => row % n,
            Channels::Labels(l) => l[row],
        }
    }
}

/// How small a singular value must be to count as zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RankTolerance {
    /// `max(m, p) · ε · σ₁` (LAPACK/numpy's `matrix_rank` default).
    Default,
    /// `t · σ₁`.
    Relative(f64),
    /// `t`.
    Absolute(f64),
}

/// Options shared by the batch estimators.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub rank_tolerance: RankTolerance,
    /// A coefficient of an identifiable combination, measured in column-norm-scaled
    /// parameters (so independent of units), below this counts as zero; also the
    /// tolerance of [`Estimate::is_identifiable`]. Default `1e-8`.
    pub identifiability_tolerance: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rank_tolerance: RankTolerance::Default,
            identifiability_tolerance: 1e-8,
        }
    }
}

/// Where the inertial blocks sit in the parameter vector: `bodies` consecutive
/// blocks (4 parameters each for the principal form, 10 for the standard form)
/// starting at parameter `first`. Parameters outside (friction, offsets) are free.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub first: usize,
    pub bodies: usize,
}

impl Layout {
    /// Checks the layout against `p` parameters and a block size; `None` means all
    /// parameters, which must then be a multiple of the block size.
    pub(crate) fn resolve(layout: Option<Layout>, p: usize, block: usize) -> Result<Layout, IdentifyError> {
        let l = match layout {
            Some(l) => l,
            None if p.is_multiple_of(block) => Layout {
                first: 0,
                bodies: p / block,
            },
            None => {
                return Err(IdentifyError::DimensionMismatch {
                    what: "parameters (a multiple of the body block size)",
                    expected: p.div_ceil(block) * block,
                    found: p,
                })
            }
        };
        if l.first + block * l.bodies > p {
            return Err(IdentifyError::DimensionMismatch {
                what: "parameters (layout end)",
                expected: l.first + block * l.bodies,
                found: p,
            });
        }
        Ok(l)
    }
}

/// OLS on in-memory data, one channel, default options (see [`Accumulator::ols`]).
pub fn ols(a: MatRef<'_, f64>, y: &[f64]) -> Result<Estimate, IdentifyError> {
    Accumulator::from_rows(a, y, Channels::Single)?.ols(&Options::default())
}

/// Gautier WLS on in-memory data grouped into channels (see [`Accumulator::wls`]).
pub fn wls(a: MatRef<'_, f64>, y: &[f64], channels: Channels) -> Result<Estimate, IdentifyError> {
    Accumulator::from_rows(a, y, channels)?.wls(&Options::default())
}

/// Column-scaled TLS on in-memory data (see [`Accumulator::tls`]).
pub fn tls(a: MatRef<'_, f64>, y: &[f64]) -> Result<Estimate, IdentifyError> {
    Accumulator::from_rows(a, y, Channels::Single)?.tls(&Options::default())
}

/// Ridge toward `x0` with the scale-free weight `lambda` on in-memory data (see
/// [`Accumulator::ridge`]).
pub fn ridge(a: MatRef<'_, f64>, y: &[f64], x0: &[f64], lambda: f64) -> Result<Estimate, IdentifyError> {
    Accumulator::from_rows(a, y, Channels::Single)?.ridge(x0, lambda, &Options::default())
}
