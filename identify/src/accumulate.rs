//! Sufficient statistics of a linear least-squares problem in O(p²) memory.
//!
//! Per channel, a factor `R` of `[A y]` with `RᵀR = [A y]ᵀ[A y]`, so that
//! `‖A x − y‖² = ‖R [x; −1]‖²` for every `x`: residuals per channel, weighted stacks
//! and the total problem all follow from the factors without keeping a single data
//! row. Two ways to get it ([`Accumulation`]): the upper-triangular factor of
//! Householder QR (TSQR: stack the old `R` on a block of new rows and re-factor;
//! backward stable, the default), or the Gram matrix `[A y]ᵀ[A y]` summed by one
//! matrix product per block of rows and factored at the end (the normal equations:
//! faster, but it squares the condition number).

use std::sync::OnceLock;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::qr::no_pivoting::factor as qr;
use faer::prelude::default;
use faer::{Accum, Mat, MatRef, Par, Side};

use super::error::{check_finite_vector, check_len, IdentifyError, Input};
use super::subspace::Subspace;
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
/// use dyngen_identify::{Accumulator, Options};
/// use dyngen_identify::faer::Mat;
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
    accumulation: Accumulation,
    blocks: Vec<Block>,
    rows: usize,
    /// Fold ready channels on every core (off for an accumulator that is itself one
    /// of several filled in parallel).
    parallel_folds: bool,
}

/// How an [`Accumulator`] compresses its rows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Accumulation {
    /// Householder QR of `[A y]` per channel, folded block by block: backward
    /// stable at any condition number.
    #[default]
    Qr,
    /// The normal equations: `[A y]ᵀ[A y]` per channel, one matrix product per
    /// block of rows (no data reordering, about half the work of QR at a higher
    /// rate), factored by an eigendecomposition when an estimate is asked for. It
    /// squares the condition number, so it resolves fewer directions: the rank
    /// tolerance is at least `max(10⁻⁶, √(max(m, p) ε)) σ₁`
    /// ([`NORMAL_EQUATIONS_RESOLUTION`]), and a direction weaker than that is
    /// reported as unidentifiable where `Qr` might still give it a value; residuals
    /// are resolved only down to about `√ε` of the data (a noise-free fit shows
    /// ~10⁻⁸ relative residuals rather than ~10⁻¹⁶). For well-conditioned, noisy
    /// problems (a good excitation, real sensors) the estimates are QR's.
    NormalEquations,
}

/// The weakest direction, relative to the strongest singular value, that
/// [`Accumulation::NormalEquations`] resolves (unless `√(max(m, p) ε)` is larger):
/// its squared condition number then costs at most 12 of the 16 digits of a double.
pub const NORMAL_EQUATIONS_RESOLUTION: f64 = 1e-6;

/// An [`Accumulator`]'s content ([`Accumulator::to_state`]), serialisable.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AccumulatorState {
    /// The number of parameters `p` (columns of `A`).
    pub parameters: usize,
    pub channels: Channels,
    pub accumulation: Accumulation,
    /// One entry per channel.
    pub per_channel: Vec<ChannelState>,
}

/// One channel of an [`AccumulatorState`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ChannelState {
    /// Rows taken.
    pub rows: usize,
    /// Rows left out ([`Accumulator::push_rows_masked`]).
    pub excluded: usize,
    /// The columns the channel's rows may be non-zero in
    /// ([`Accumulator::with_column_support`]); `None`: all.
    pub support: Option<Vec<usize>>,
    /// Over the supported columns and `y` (`width` numbers): for
    /// [`Accumulation::Qr`] the rows of the upper-trapezoidal factor `R` of the
    /// channel's rows of `[A y]` (at most `width`); for
    /// [`Accumulation::NormalEquations`] the upper triangle of `[A y]ᵀ[A y]`, row
    /// `i` from the diagonal on (`width − i` numbers).
    pub factor: Vec<Vec<f64>>,
}

#[derive(Clone, Debug)]
struct Block {
    /// [`Accumulation::Qr`]: column-major, `(p + 1 + fold_rows(p)) × (p + 1)`: rows
    /// `0..k` hold the upper-trapezoidal factor of the folded rows of `[A y]`
    /// (`k ≤ p + 1`), the rows below are the room a fold factors the pending rows in.
    /// [`Accumulation::NormalEquations`]: `(p + 1) × (p + 1)`, the upper triangle of
    /// `[A y]ᵀ[A y]` over the folded rows.
    work: Mat<f64>,
    k: usize,
    /// Rows not yet folded, row-major, `width` numbers each.
    pending: Vec<f64>,
    rows: usize,
    /// Rows of this channel left out by [`Accumulator::push_rows_masked`].
    excluded: usize,
    /// The columns of `A` this channel's rows may be non-zero in, increasing
    /// ([`Accumulator::with_column_support`]); `None`: all `p`. The block holds only
    /// these columns and `y`, so `work` and `pending` are `width = len + 1` wide.
    support: Option<Vec<usize>>,
    /// The other columns, checked to be zero in every pushed row.
    outside: Vec<usize>,
}

impl Block {
    /// Numbers per buffered row: the supported columns and `y`.
    fn width(&self, p: usize) -> usize {
        self.support.as_ref().map_or(p, Vec::len) + 1
    }

    /// The factor of the rows folded so far, `k × (p + 1)`.
    fn r(&self, p: usize) -> Mat<f64> {
        expand(self.support.as_deref(), self.work.as_ref().subrows(0, self.k), p)
    }
}

/// A factor over a channel's supported columns and `y` (`k × (len + 1)`) as a
/// factor over all `p` columns and `y`: columns put back in place, zero elsewhere.
fn expand(support: Option<&[usize]>, factor: MatRef<'_, f64>, p: usize) -> Mat<f64> {
    match support {
        None => factor.to_owned(),
        Some(cols) => {
            let mut r = Mat::zeros(factor.nrows(), p + 1);
            for (m, &c) in cols.iter().chain(std::iter::once(&p)).enumerate() {
                r.as_mut().col_mut(c).copy_from(factor.col(m));
            }
            r
        }
    }
}

/// One channel's factor with all rows folded in.
#[derive(Clone, Debug)]
pub(crate) struct Factor {
    pub r: Mat<f64>,
    pub rows: usize,
    /// Made from the normal equations ([`Accumulation::NormalEquations`]).
    pub normal_equations: bool,
}

/// [`Accumulator::ols_start`].
pub(crate) struct OlsStart {
    pub factors: Vec<Factor>,
    pub tri: Triangle,
    pub sub: Subspace,
    pub x_ols: Vec<f64>,
    /// Rows less rank.
    pub dof: f64,
    /// The OLS residual's standard deviation (`None` without spare rows).
    pub noise: Option<f64>,
}

/// `prior` checked against `p` parameters, or zeros when there is none.
pub(crate) fn prior_or_zero(prior: Option<&Vec<f64>>, p: usize) -> Result<Vec<f64>, IdentifyError> {
    match prior {
        Some(x) => {
            check_len(x, p, "prior")?;
            check_finite_vector(x, Input::Prior)?;
            Ok(x.clone())
        }
        None => Ok(vec![0.0; p]),
    }
}

/// The total (possibly weighted) problem, compressed: `‖A x − y‖² = ‖R x − z‖² + ρ²`.
#[derive(Clone, Debug)]
pub(crate) struct Triangle {
    /// `p × p`, upper triangular (zero rows padded when fewer than `p` rows were seen).
    pub r: Mat<f64>,
    pub z: Vec<f64>,
    pub rho2: f64,
    pub rows: usize,
    /// Singular values below `floor · σ₁` are not resolved by the accumulation (0
    /// for QR; see [`NORMAL_EQUATIONS_RESOLUTION`] for the normal equations).
    pub floor: f64,
}

impl Accumulator {
    /// An empty accumulator for `p` parameters, all rows in one channel.
    pub fn new(p: usize) -> Self {
        Self::build(p, Channels::Single)
    }

    /// An empty accumulator whose rows are grouped into channels (e.g. joints:
    /// `Channels::Interleaved(n)` for regressors stacked sample by sample).
    pub fn with_channels(p: usize, channels: Channels) -> Result<Self, IdentifyError> {
        Self::with_accumulation(p, channels, Accumulation::Qr)
    }

    /// [`Accumulator::with_channels`] with the choice of [`Accumulation`].
    pub fn with_accumulation(p: usize, channels: Channels, accumulation: Accumulation) -> Result<Self, IdentifyError> {
        if let Channels::Interleaved(0) = channels {
            return Err(IdentifyError::InvalidArgument {
                what: "channels",
                reason: "Interleaved(0): the channel count must be positive".into(),
            });
        }
        let mut acc = Self::build(p, channels);
        acc.accumulation = accumulation;
        if accumulation == Accumulation::NormalEquations {
            for b in &mut acc.blocks {
                b.work = Mat::zeros(p + 1, p + 1);
            }
        }
        Ok(acc)
    }

    /// Declares, per channel, the only columns its rows can be non-zero in (e.g. a
    /// joint-torque regressor's row `j` involves only the bodies joint `j` supports
    /// and joint `j`'s own friction terms). Each channel is then compressed over
    /// those columns alone, which gives exactly the same estimates at a fraction of
    /// the work (a QR fold costs the square of the width). Pushed rows are checked:
    /// a non-zero entry elsewhere is [`IdentifyError::OutsideSupport`].
    ///
    /// Errors: rows already pushed, not one list per channel, a column `≥ p`.
    pub fn with_column_support(mut self, support: Vec<Vec<usize>>) -> Result<Self, IdentifyError> {
        if self.rows > 0 {
            return Err(IdentifyError::InvalidArgument {
                what: "column support",
                reason: "must be declared before any row is pushed".into(),
            });
        }
        if support.len() != self.blocks.len() {
            return Err(IdentifyError::DimensionMismatch {
                what: "column support (one list per channel)",
                expected: self.blocks.len(),
                found: support.len(),
            });
        }
        let p = self.p;
        for (block, mut cols) in self.blocks.iter_mut().zip(support) {
            cols.sort_unstable();
            cols.dedup();
            if let Some(&c) = cols.iter().find(|&&c| c >= p) {
                return Err(IdentifyError::InvalidArgument {
                    what: "column support",
                    reason: format!("column {c} of {p}"),
                });
            }
            block.outside = (0..p).filter(|c| cols.binary_search(c).is_err()).collect();
            let width = cols.len() + 1;
            block.support = Some(cols);
            block.work = match self.accumulation {
                Accumulation::Qr => Mat::zeros(0, width),
                Accumulation::NormalEquations => Mat::zeros(width, width),
            };
        }
        Ok(self)
    }

    /// An empty accumulator like this one (parameters, channels, accumulation,
    /// column support) that folds on the calling thread only: one of several filled
    /// in parallel and then [merged](Accumulator::merge).
    pub fn empty_part(&self) -> Self {
        let mut part = self.clone();
        part.rows = 0;
        part.parallel_folds = false;
        for (b, mine) in part.blocks.iter_mut().zip(&self.blocks) {
            b.work = match self.accumulation {
                Accumulation::Qr => Mat::zeros(0, mine.width(self.p)),
                Accumulation::NormalEquations => Mat::zeros(mine.width(self.p), mine.width(self.p)),
            };
            b.k = 0;
            b.pending.clear();
            b.rows = 0;
            b.excluded = 0;
        }
        part
    }

    /// Adds the rows `other` holds, as if they had been pushed here after the rows
    /// already here (the channel sums, and so every estimate, are those of the
    /// stacked rows up to rounding): for filling accumulators over parts of the data
    /// in parallel ([`Accumulator::empty_part`]). Merging the parts in a fixed order
    /// gives the same result on any number of cores.
    ///
    /// Errors: a different parameter count, channel grouping, accumulation or column
    /// support; channels given by labels (their rows are numbered globally), or
    /// interleaved channels with a part that does not hold whole samples.
    pub fn merge(&mut self, other: &Accumulator) -> Result<(), IdentifyError> {
        let mismatch = |reason: &str| {
            Err(IdentifyError::InvalidArgument {
                what: "accumulator to merge",
                reason: reason.into(),
            })
        };
        if other.p != self.p || other.accumulation != self.accumulation || other.channels != self.channels {
            return mismatch("different parameters, channels or accumulation");
        }
        match self.channels {
            Channels::Labels(_) => return mismatch("channels given by labels number rows globally"),
            Channels::Interleaved(n) if !self.rows.is_multiple_of(n) || !other.rows.is_multiple_of(n) => {
                return mismatch("interleaved channels need whole samples in each part")
            }
            _ => {}
        }
        if self
            .blocks
            .iter()
            .zip(&other.blocks)
            .any(|(a, b)| a.support != b.support)
        {
            return mismatch("different column support");
        }
        let p = self.p;
        for (mine, theirs) in self.blocks.iter_mut().zip(&other.blocks) {
            let width = mine.width(p);
            match self.accumulation {
                // Their factor's rows are rows like any other: `RᵀR` is their sum.
                Accumulation::Qr => {
                    let r = theirs.work.as_ref().subrows(0, theirs.k);
                    for i in 0..theirs.k {
                        mine.pending.extend((0..width).map(|j| r[(i, j)]));
                    }
                }
                Accumulation::NormalEquations => {
                    for j in 0..width {
                        for i in 0..=j {
                            mine.work[(i, j)] += theirs.work[(i, j)];
                        }
                    }
                }
            }
            mine.pending.extend_from_slice(&theirs.pending);
            mine.rows += theirs.rows;
            mine.excluded += theirs.excluded;
            match self.accumulation {
                Accumulation::Qr => fold(mine),
                Accumulation::NormalEquations => add_gram(mine),
            }
        }
        self.rows += other.rows;
        Ok(())
    }

    /// Everything the accumulator holds, with the rows still buffered folded in, as
    /// plain numbers: what a partial factor file stores
    /// ([`crate::partial::Partial`]). [`Accumulator::from_state`] gives back an
    /// accumulator whose estimates, and whose merges with others, are this one's.
    ///
    /// Errors: channels given by labels (their rows are numbered globally, so they
    /// cannot be merged either).
    pub fn to_state(&self) -> Result<AccumulatorState, IdentifyError> {
        if let Channels::Labels(_) = self.channels {
            return Err(IdentifyError::InvalidArgument {
                what: "accumulator state",
                reason: "channels given by labels number rows globally".into(),
            });
        }
        let channels = self
            .blocks
            .iter()
            .map(|b| {
                let mut b = b.clone();
                let width = b.width(self.p);
                let factor = match self.accumulation {
                    Accumulation::Qr => {
                        fold(&mut b);
                        (0..b.k).map(|i| (0..width).map(|j| b.work[(i, j)]).collect()).collect()
                    }
                    Accumulation::NormalEquations => {
                        add_gram(&mut b);
                        (0..width)
                            .map(|i| (i..width).map(|j| b.work[(i, j)]).collect())
                            .collect()
                    }
                };
                ChannelState {
                    rows: b.rows,
                    excluded: b.excluded,
                    support: b.support,
                    factor,
                }
            })
            .collect();
        Ok(AccumulatorState {
            parameters: self.p,
            channels: self.channels.clone(),
            accumulation: self.accumulation,
            per_channel: channels,
        })
    }

    /// The accumulator [`Accumulator::to_state`] describes, checked: one entry per
    /// channel, the same column support form in each, factor rows of the channel's
    /// width (at most width rows for QR; the upper triangle row by row for the
    /// normal equations), finite numbers, and interleaved channels holding whole
    /// samples.
    pub fn from_state(state: &AccumulatorState) -> Result<Self, IdentifyError> {
        let invalid = |reason: String| IdentifyError::InvalidArgument {
            what: "accumulator state",
            reason,
        };
        if let Channels::Labels(_) = state.channels {
            return Err(invalid("channels given by labels cannot be stored".into()));
        }
        let p = state.parameters;
        let mut acc = Self::with_accumulation(p, state.channels.clone(), state.accumulation)?;
        if state.per_channel.len() != acc.blocks.len() {
            return Err(invalid(format!(
                "{} channels, but {} channel entries",
                acc.blocks.len(),
                state.per_channel.len()
            )));
        }
        let supported = state.per_channel.iter().filter(|c| c.support.is_some()).count();
        if supported == state.per_channel.len() && supported > 0 {
            let support = state
                .per_channel
                .iter()
                .map(|c| c.support.clone().unwrap_or_default())
                .collect();
            acc = acc.with_column_support(support)?;
        } else if supported != 0 {
            return Err(invalid("a column support for some channels but not for others".into()));
        }
        let mut total = 0;
        for (c, (block, given)) in acc.blocks.iter_mut().zip(&state.per_channel).enumerate() {
            if block.support != given.support {
                return Err(invalid(format!(
                    "channel {c}: the column support is not increasing without repeats"
                )));
            }
            let width = block.width(p);
            let expected_rows = |i: usize| match state.accumulation {
                Accumulation::Qr => width,
                Accumulation::NormalEquations => width - i,
            };
            match state.accumulation {
                Accumulation::Qr if given.factor.len() > width => {
                    return Err(invalid(format!(
                        "channel {c}: a QR factor of {} rows; at most {width}",
                        given.factor.len()
                    )))
                }
                Accumulation::NormalEquations if given.factor.len() != width => {
                    return Err(invalid(format!(
                        "channel {c}: a Gram triangle of {} rows; expected {width}",
                        given.factor.len()
                    )))
                }
                _ => {}
            }
            for (i, row) in given.factor.iter().enumerate() {
                if row.len() != expected_rows(i) {
                    return Err(invalid(format!(
                        "channel {c}: factor row {i} has {} numbers; expected {}",
                        row.len(),
                        expected_rows(i)
                    )));
                }
                if let Some(j) = row.iter().position(|x| !x.is_finite()) {
                    return Err(invalid(format!("channel {c}: factor row {i}, entry {j} is not finite")));
                }
            }
            block.work = match state.accumulation {
                Accumulation::Qr => Mat::from_fn(given.factor.len(), width, |i, j| given.factor[i][j]),
                Accumulation::NormalEquations => {
                    Mat::from_fn(width, width, |i, j| if j >= i { given.factor[i][j - i] } else { 0.0 })
                }
            };
            block.k = match state.accumulation {
                Accumulation::Qr => given.factor.len(),
                Accumulation::NormalEquations => 0,
            };
            block.rows = given.rows;
            block.excluded = given.excluded;
            total += given.rows + given.excluded;
        }
        if let Channels::Interleaved(n) = state.channels {
            let per = state.per_channel.iter().map(|c| c.rows + c.excluded);
            if per.clone().any(|r| n * r != total) {
                return Err(invalid(format!(
                    "rows per channel (taken and left out) {:?} are not whole samples of {n} rows",
                    per.collect::<Vec<_>>()
                )));
            }
        }
        acc.rows = total;
        Ok(acc)
    }

    /// How the rows are compressed.
    pub fn accumulation(&self) -> Accumulation {
        self.accumulation
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
                work: Mat::zeros(0, p + 1),
                k: 0,
                pending: Vec::new(),
                rows: 0,
                excluded: 0,
                support: None,
                outside: Vec::new(),
            })
            .collect();
        Self {
            p,
            channels,
            accumulation: Accumulation::Qr,
            blocks,
            rows: 0,
            parallel_folds: true,
        }
    }

    /// Number of parameters `p`.
    pub fn n_params(&self) -> usize {
        self.p
    }

    /// Rows pushed so far, those [left out](Accumulator::push_rows_masked) included.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Rows left out by [`Accumulator::push_rows_masked`] so far, per channel.
    pub fn excluded_per_channel(&self) -> Vec<usize> {
        self.blocks.iter().map(|b| b.excluded).collect()
    }

    /// The channel grouping.
    pub fn channels(&self) -> &Channels {
        &self.channels
    }

    /// Rows taken so far per channel (left-out rows not counted).
    pub fn rows_per_channel(&self) -> Vec<usize> {
        self.blocks.iter().map(|b| b.rows).collect()
    }

    /// Appends a block of rows: `a` is `k × p`, `y` has `k` entries. All rows are
    /// checked before any is taken, so on error the accumulator is unchanged.
    pub fn push_rows(&mut self, a: MatRef<'_, f64>, y: &[f64]) -> Result<(), IdentifyError> {
        self.push(a, y, None)
    }

    /// [`Accumulator::push_rows`] taking only the rows with `keep[i]`: the others
    /// still occupy their place (the channel of a row is that of its position, so a
    /// joint-torque regressor keeps its joints apart) but enter no equation, and are
    /// counted per channel ([`Accumulator::excluded_per_channel`]). Rows left out are
    /// not checked. E.g. the rows of a joint moving too slowly for its Coulomb
    /// friction to be `Fc·sign(q̇)`.
    ///
    /// Errors: those of [`Accumulator::push_rows`], and `keep` not one flag per row.
    pub fn push_rows_masked(&mut self, a: MatRef<'_, f64>, y: &[f64], keep: &[bool]) -> Result<(), IdentifyError> {
        if keep.len() != a.nrows() {
            return Err(IdentifyError::DimensionMismatch {
                what: "row mask (one flag per row)",
                expected: a.nrows(),
                found: keep.len(),
            });
        }
        self.push(a, y, Some(keep))
    }

    fn push(&mut self, a: MatRef<'_, f64>, y: &[f64], keep: Option<&[bool]>) -> Result<(), IdentifyError> {
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
        let kept = |i: usize| keep.is_none_or(|keep| keep[i]);
        for i in (0..k).filter(|&i| kept(i)) {
            if let Some(j) = a.row(i).iter().position(|x| !x.is_finite()) {
                return Err(IdentifyError::NonFinite {
                    input: Input::Regressor,
                    row: self.rows + i,
                    column: j,
                });
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
        for i in (0..k).filter(|&i| kept(i)) {
            let ch = self.channels.channel_of(self.rows + i);
            let row = a.row(i);
            if let Some(&column) = self.blocks[ch].outside.iter().find(|&&c| row[c] != 0.0) {
                return Err(IdentifyError::OutsideSupport {
                    row: self.rows + i,
                    column,
                    channel: ch,
                });
            }
        }
        let mut i = 0;
        while i < k {
            // Buffer rows until some channel has a fold's worth, then fold every
            // channel with at least half of one (in parallel: the channels are
            // independent, and interleaved channels fill up together).
            while i < k {
                let ch = self.channels.channel_of(self.rows + i);
                let block = &mut self.blocks[ch];
                if !kept(i) {
                    block.excluded += 1;
                    i += 1;
                    continue;
                }
                let row = a.row(i);
                match &block.support {
                    None => block.pending.extend(row.iter()),
                    Some(cols) => block.pending.extend(cols.iter().map(|&c| row[c])),
                }
                block.pending.push(y[i]);
                block.rows += 1;
                i += 1;
                let width = block.width(p);
                if block.pending.len() >= fold_rows(width - 1) * width {
                    break;
                }
            }
            let ready = |b: &Block| {
                let width = b.width(p);
                2 * b.pending.len() >= fold_rows(width - 1) * width
            };
            // Rows pushed one at a time reach this point once per row: only build
            // the list (and go to the thread pool) when there is something to fold.
            if self.blocks.iter().any(ready) {
                let full: Vec<&mut Block> = self.blocks.iter_mut().filter(|b| ready(b)).collect();
                fold_all(full, self.accumulation, self.parallel_folds);
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

    /// The unweighted problem and its OLS solution: where every constrained
    /// estimator starts, and what its noise estimate is measured against.
    pub(crate) fn ols_start(&self, opts: &super::Options) -> Result<OlsStart, IdentifyError> {
        let factors = self.factors()?;
        let tri = combine(&factors, None, self.p);
        let sub = Subspace::analyse(tri.r.as_ref(), tri.rows, tri.floor, opts)?;
        let x_ols = sub.min_norm_solution(&tri.z);
        let dof = tri.rows as f64 - sub.rank as f64;
        let rss_ols: f64 = channel_rss(&factors, &x_ols).iter().sum();
        let noise = (dof > 0.0).then(|| (rss_ols / dof).sqrt());
        Ok(OlsStart {
            factors,
            tri,
            sub,
            x_ols,
            dof,
            noise,
        })
    }

    /// Every channel's factor with pending rows folded in (the accumulator is not
    /// changed).
    pub(crate) fn factors(&self) -> Result<Vec<Factor>, IdentifyError> {
        if self.blocks.iter().all(|b| b.rows == 0) {
            return Err(IdentifyError::Empty);
        }
        self.blocks
            .iter()
            .map(|b| {
                let mut b = b.clone();
                let r = match self.accumulation {
                    Accumulation::Qr => {
                        fold(&mut b);
                        b.r(self.p)
                    }
                    Accumulation::NormalEquations => {
                        add_gram(&mut b);
                        expand(b.support.as_deref(), gram_factor(b.work.as_ref())?.as_ref(), self.p)
                    }
                };
                Ok(Factor {
                    r,
                    rows: b.rows,
                    normal_equations: self.accumulation == Accumulation::NormalEquations,
                })
            })
            .collect()
    }
}

/// Rows buffered per channel before a QR fold: large enough that the fold's cost
/// is dominated by the new rows, small enough to keep memory O(p²).
fn fold_rows(p: usize) -> usize {
    (8 * (p + 1)).max(1024)
}

/// The machine's core count, asked once: `available_parallelism` reads cgroup files
/// on every call, far too slow for a path taken once per pushed row.
pub(crate) fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |t| t.get()))
}

/// `f(i)` for `i` in `0..n`, spread over the machine's cores (round robin), returned
/// in index order; on one core (or for one item) without spawning a thread.
pub fn in_parallel<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = cores().clamp(1, n.max(1));
    if threads <= 1 {
        return (0..n).map(f).collect();
    }
    let mut out: Vec<(usize, T)> = std::thread::scope(|s| {
        let f = &f;
        let handles: Vec<_> = (0..threads)
            .map(|t| s.spawn(move || (t..n).step_by(threads).map(|j| (j, f(j))).collect::<Vec<_>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    out.sort_by_key(|(j, _)| *j);
    out.into_iter().map(|(_, x)| x).collect()
}

/// Folds the pending rows of every block, spreading the blocks over the machine's
/// cores; each block's result does not depend on which thread folds it.
fn fold_all(mut blocks: Vec<&mut Block>, accumulation: Accumulation, parallel: bool) {
    let threads = if parallel { cores().min(blocks.len()) } else { 1 };
    let fold_block = |b: &mut Block| match accumulation {
        Accumulation::Qr => fold(b),
        Accumulation::NormalEquations => add_gram(b),
    };
    if threads <= 1 {
        blocks.into_iter().for_each(fold_block);
        return;
    }
    let per = blocks.len().div_ceil(threads);
    std::thread::scope(|scope| {
        for chunk in blocks.chunks_mut(per) {
            scope.spawn(move || chunk.iter_mut().for_each(|b| fold_block(b)));
        }
    });
}

/// QR of `[R; pending rows]` in the block's work matrix, in place (faer's blocked
/// Householder QR, no allocation of the matrix); `R` becomes the new factor and
/// the pending rows are cleared.
fn fold(block: &mut Block) {
    let n = block.work.ncols();
    let p = n - 1;
    let b = block.pending.len() / n;
    if b == 0 {
        return;
    }
    let m = block.k + b;
    if block.work.nrows() < m {
        // First fold (or an unusually large one): room for a fold's worth of rows.
        let mut work = Mat::zeros(m.max(n + fold_rows(p)), n);
        work.as_mut()
            .subrows_mut(0, block.k)
            .copy_from(block.work.as_ref().subrows(0, block.k));
        block.work = work;
    }
    block
        .work
        .as_mut()
        .subrows_mut(block.k, b)
        .copy_from(MatRef::from_row_major_slice(&block.pending, b, n));
    let size = m.min(n);
    let blocksize = qr::recommended_block_size::<f64>(m, n);
    let mut householder = Mat::<f64>::zeros(blocksize, size);
    let mut scratch = MemBuffer::new(qr::qr_in_place_scratch::<f64>(m, n, blocksize, Par::Seq, default()));
    qr::qr_in_place(
        block.work.as_mut().subrows_mut(0, m),
        householder.as_mut(),
        Par::Seq,
        MemStack::new(&mut scratch),
        default(),
    );
    // Keep R: clear the Householder vectors stored below its diagonal.
    for j in 0..n {
        for i in (j + 1)..size {
            block.work[(i, j)] = 0.0;
        }
    }
    block.k = size;
    block.pending.clear();
}

/// Adds the pending rows `P` (row-major, so `Pᵀ` column-major without a copy) to
/// the upper triangle of the block's Gram matrix: `G += Pᵀ P`.
fn add_gram(block: &mut Block) {
    let n = block.work.ncols();
    let b = block.pending.len() / n;
    if b == 0 {
        return;
    }
    let pt = MatRef::from_column_major_slice(&block.pending, n, b);
    triangular::matmul(
        block.work.as_mut(),
        BlockStructure::TriangularUpper,
        Accum::Add,
        pt,
        BlockStructure::Rectangular,
        pt.transpose(),
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
    block.pending.clear();
}

/// A square factor `R` of a Gram matrix `G` (upper triangle given): `RᵀR = G`, from
/// `G = V Λ Vᵀ` as `R = Λ^{1/2} Vᵀ` with the eigenvalues rounding made negative
/// set to zero.
fn gram_factor(upper: MatRef<'_, f64>) -> Result<Mat<f64>, IdentifyError> {
    let n = upper.nrows();
    let g = Mat::from_fn(n, n, |i, j| if i <= j { upper[(i, j)] } else { upper[(j, i)] });
    let eigen = g
        .self_adjoint_eigen(Side::Upper)
        .map_err(|_| IdentifyError::DecompositionFailed {
            what: "eigendecomposition of the normal equations",
        })?;
    let (values, vectors) = (eigen.S().column_vector(), eigen.U());
    Ok(Mat::from_fn(n, n, |i, j| values[i].max(0.0).sqrt() * vectors[(j, i)]))
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
    let rows: usize = factors.iter().map(|f| f.rows).sum();
    let r = Mat::from_fn(p, p, |i, j| if i < k && j >= i { r_aug[(i, j)] } else { 0.0 });
    let z = (0..p).map(|i| if i < k { r_aug[(i, p)] } else { 0.0 }).collect();
    let rho2 = if k == p + 1 { r_aug[(p, p)].powi(2) } else { 0.0 };
    let floor = if factors.iter().any(|f| f.normal_equations) {
        (rows.max(p) as f64 * f64::EPSILON)
            .sqrt()
            .max(NORMAL_EQUATIONS_RESOLUTION)
    } else {
        0.0
    };
    Triangle {
        r,
        z,
        rho2,
        rows,
        floor,
    }
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
