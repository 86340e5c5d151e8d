//! Sufficient statistics of a linear least-squares problem in O(p²) memory.
//!
//! Per channel, the upper-triangular factor `R` of `[A y]` (TSQR: stack the old `R`
//! on a block of new rows and re-factor). `‖A x − y‖² = ‖R [x; −1]‖²` for every `x`,
//! so residuals per channel, weighted stacks and the total problem all follow from
//! the factors without keeping a single data row.

use faer::{Mat, MatRef};

use super::error::{IdentifyError, Input};
use super::Channels;

/// Streaming accumulation of `y = A x + e`, the common entry point of every batch
/// estimator.
///
/// Memory is `O(channels · p²)` whatever the number of rows: rows are buffered per
/// channel and folded into a triangular factor `R` of `[A y]` by Householder QR
/// (faer) every few hundred rows. Estimators ([`Accumulator::ols`],
/// [`Accumulator::wls`], [`Accumulator::tls`], [`Accumulator::ridge`],
/// [`Accumulator::principal_consistent`], [`Accumulator::log_cholesky`]) read the
/// factors and give exactly what they would give on the stacked rows.
///
/// ```
/// use dyngen::identify::{Accumulator, Options};
/// use dyngen::identify::faer::Mat;
/// let a = Mat::from_fn(6, 2, |i, j| if j == 0 { 1.0 } else { i as f64 });
/// let y: Vec<f64> = (0..6).map(|i| 2.0 + 0.5 * i as f64).collect();
/// let mut acc = Accumulator::new(2);
/// acc.push_rows(a.as_ref(), &y).unwrap();
/// let est = acc.finish().unwrap();
/// assert!((est.params[1].value.unwrap() - 0.5).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct Accumulator {
    p: usize,
    channels: Channels,
    blocks: Vec<Block>,
    rows: usize,
}

#[derive(Clone, Debug)]
struct Block {
    /// Upper-trapezoidal factor of the folded rows of `[A y]`, `k × (p+1)`, `k ≤ p+1`.
    r: Mat<f64>,
    /// Rows not yet folded, row-major, `p+1` numbers each.
    pending: Vec<f64>,
    rows: usize,
}

/// One channel's factor with all rows folded in.
#[derive(Clone, Debug)]
pub(crate) struct Factor {
    pub r: Mat<f64>,
    pub rows: usize,
}

/// The total (possibly weighted) problem, compressed: `‖A x − y‖² = ‖R x − z‖² + ρ²`.
#[derive(Clone, Debug)]
pub(crate) struct Triangle {
    /// `p × p`, upper triangular (zero rows padded when fewer than `p` rows were seen).
    pub r: Mat<f64>,
    pub z: Vec<f64>,
    pub rho2: f64,
    pub rows: usize,
}

impl Accumulator {
    /// An empty accumulator for `p` parameters, all rows in one channel.
    pub fn new(p: usize) -> Self {
        Self::build(p, Channels::Single)
    }

    /// An empty accumulator whose rows are grouped into channels (e.g. joints:
    /// `Channels::Interleaved(n)` for regressors stacked sample by sample).
    pub fn with_channels(p: usize, channels: Channels) -> Result<Self, IdentifyError> {
        if let Channels::Interleaved(0) = channels {
            return Err(IdentifyError::InvalidArgument {
                what: "channels",
                reason: "Interleaved(0): the channel count must be positive".into(),
            });
        }
        Ok(Self::build(p, channels))
    }

    /// An accumulator holding the rows of `a` (`m × p`) and `y` (`m`).
    pub fn from_rows(a: MatRef<'_, f64>, y: &[f64], channels: Channels) -> Result<Self, IdentifyError> {
        let mut acc = Self::with_channels(a.ncols(), channels)?;
        acc.push_rows(a, y)?;
        Ok(acc)
    }

    fn build(p: usize, channels: Channels) -> Self {
        let blocks = (0..channels.count())
            .map(|_| Block {
                r: Mat::zeros(0, p + 1),
                pending: Vec::new(),
                rows: 0,
            })
            .collect();
        Self {
            p,
            channels,
            blocks,
            rows: 0,
        }
    }

    /// Number of parameters `p`.
    pub fn n_params(&self) -> usize {
        self.p
    }

    /// Rows pushed so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The channel grouping.
    pub fn channels(&self) -> &Channels {
        &self.channels
    }

    /// Rows pushed so far per channel.
    pub fn rows_per_channel(&self) -> Vec<usize> {
        self.blocks.iter().map(|b| b.rows).collect()
    }

    /// Appends a block of rows: `a` is `k × p`, `y` has `k` entries. All rows are
    /// checked before any is taken, so on error the accumulator is unchanged.
    pub fn push_rows(&mut self, a: MatRef<'_, f64>, y: &[f64]) -> Result<(), IdentifyError> {
        let p = self.p;
        if a.ncols() != p {
            return Err(IdentifyError::DimensionMismatch {
                what: "regressor columns",
                expected: p,
                found: a.ncols(),
            });
        }
        let k = a.nrows();
        if y.len() != k {
            return Err(IdentifyError::DimensionMismatch {
                what: "observations",
                expected: k,
                found: y.len(),
            });
        }
        for i in 0..k {
            for j in 0..p {
                if !a[(i, j)].is_finite() {
                    return Err(IdentifyError::NonFinite {
                        input: Input::Regressor,
                        row: self.rows + i,
                        column: j,
                    });
                }
            }
            if !y[i].is_finite() {
                return Err(IdentifyError::NonFinite {
                    input: Input::Observation,
                    row: self.rows + i,
                    column: 0,
                });
            }
        }
        if let Channels::Labels(labels) = &self.channels {
            if labels.len() < self.rows + k {
                return Err(IdentifyError::DimensionMismatch {
                    what: "channel labels",
                    expected: self.rows + k,
                    found: labels.len(),
                });
            }
        }
        let fold_at = fold_rows(p);
        for i in 0..k {
            let ch = self.channels.channel_of(self.rows + i);
            let block = &mut self.blocks[ch];
            block.pending.extend((0..p).map(|j| a[(i, j)]));
            block.pending.push(y[i]);
            block.rows += 1;
            if block.pending.len() >= fold_at * (p + 1) {
                block.r = fold(block.r.as_ref(), &block.pending, p);
                block.pending.clear();
            }
        }
        self.rows += k;
        Ok(())
    }

    /// Appends one row `a` (`p` entries) with observation `y`.
    pub fn push_row(&mut self, a: &[f64], y: f64) -> Result<(), IdentifyError> {
        self.push_rows(MatRef::from_row_major_slice(a, 1, a.len()), &[y])
    }

    /// Ordinary least squares on everything pushed so far, with default [`super::Options`].
    /// Equal to [`Accumulator::ols`] on the stacked rows.
    pub fn finish(&self) -> Result<super::Estimate, IdentifyError> {
        self.ols(&super::Options::default())
    }

    /// Every channel's factor with pending rows folded in (the accumulator is not
    /// changed).
    pub(crate) fn factors(&self) -> Result<Vec<Factor>, IdentifyError> {
        if self.rows == 0 {
            return Err(IdentifyError::Empty);
        }
        Ok(self
            .blocks
            .iter()
            .map(|b| Factor {
                r: if b.pending.is_empty() {
                    b.r.clone()
                } else {
                    fold(b.r.as_ref(), &b.pending, self.p)
                },
                rows: b.rows,
            })
            .collect())
    }
}

/// Rows buffered per channel before a QR fold: large enough that the fold's cost
/// is dominated by the new rows, small enough to keep memory O(p²).
fn fold_rows(p: usize) -> usize {
    (8 * (p + 1)).max(1024)
}

/// QR of `[r; pending]`, keeping the triangular factor.
fn fold(r: MatRef<'_, f64>, pending: &[f64], p: usize) -> Mat<f64> {
    let k = r.nrows();
    let b = pending.len() / (p + 1);
    let stacked = Mat::from_fn(k + b, p + 1, |i, j| {
        if i < k {
            r[(i, j)]
        } else {
            pending[(i - k) * (p + 1) + j]
        }
    });
    stacked.qr().thin_R().to_owned()
}

/// Stacks the channel factors, channel `c` scaled by `weights[c]` (all 1 when
/// `None`), and reduces them to one triangle.
pub(crate) fn combine(factors: &[Factor], weights: Option<&[f64]>, p: usize) -> Triangle {
    let total: usize = factors.iter().map(|f| f.r.nrows()).sum();
    let mut stacked = Mat::zeros(total, p + 1);
    let mut row = 0;
    for (c, f) in factors.iter().enumerate() {
        let w = weights.map_or(1.0, |w| w[c]);
        for i in 0..f.r.nrows() {
            for j in 0..=p {
                stacked[(row, j)] = w * f.r[(i, j)];
            }
            row += 1;
        }
    }
    let r_aug = stacked.qr().thin_R().to_owned();
    let k = r_aug.nrows();
    let rows = factors.iter().map(|f| f.rows).sum();
    let r = Mat::from_fn(p, p, |i, j| if i < k && j >= i { r_aug[(i, j)] } else { 0.0 });
    let z = (0..p).map(|i| if i < k { r_aug[(i, p)] } else { 0.0 }).collect();
    let rho2 = if k == p + 1 { r_aug[(p, p)].powi(2) } else { 0.0 };
    Triangle { r, z, rho2, rows }
}

/// `‖A_c x − y_c‖²` for every channel.
pub(crate) fn channel_rss(factors: &[Factor], x: &[f64]) -> Vec<f64> {
    factors
        .iter()
        .map(|f| {
            let p = x.len();
            (0..f.r.nrows())
                .map(|i| {
                    let e: f64 = (0..p).map(|j| f.r[(i, j)] * x[j]).sum::<f64>() - f.r[(i, p)];
                    e * e
                })
                .sum()
        })
        .collect()
}
