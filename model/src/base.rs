//! Base parameters: which combinations of the inertial parameters the joint torques
//! determine.
//!
//! The joint torque regressor ([`crate::regressor`]) is evaluated on random states
//! ([`state_count`] of them, [`SAMPLES`] for every model up to
//! [`ALL_SAMPLES_UP_TO`] columns), stacked (`W`), and factored by a QR that takes
//! the columns in parameter order and sets aside every column already in the span of
//! those kept (see `ordered_qr`). Kept columns are the base; every other column is
//! a fixed combination of them, `W_dep = W_ind R₁₁⁻¹ R₁₂`, so `Y π = Y_b β` with
//!
//! ```text
//! β = K π = π_ind + R₁₁⁻¹ R₁₂ π_dep
//! ```
//!
//! Taking columns in order (rather than pivoting by norm) makes the choice
//! independent of the sample and gives the classical groupings: earlier bodies'
//! parameters absorb later ones (`Izz1 + Iyy2 + …`).
//!
//! The states come from [`structure_states`]: full turns for revolute joints and
//! ±0.5 m for prismatic ones, whatever the limits, so a joint with placeholder limits
//! (`lower = upper = 0`) is not pinned and no parameter is lost.
//!
//! Two independent checks come with every answer: the analysis is repeated with a
//! second seed ([`BaseParams::confirmed`]), and the numerical rank of `W` is counted
//! from its singular values ([`BaseParams::rank_check`]), which must equal the number
//! of columns the QR kept (for large models by bounds that prove the count, see
//! `large_rank`).

use crate::joint_params::{append_joint_columns, joint_param_names, Coulomb};
#[cfg(test)]
use crate::math::singular_values;
use crate::math::singular_values_of;
use crate::names::{principal_param_names, standard_param_names};
use crate::regressor::{principal_from_standard, torque_regressor, PRINCIPAL_PER_BODY, STANDARD_PER_BODY};
use crate::sample::structure_states;
use crate::Model;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::householder::{
    apply_block_householder_sequence_transpose_on_the_left_in_place_scratch as apply_scratch,
    apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj as apply_transpose,
};
use faer::linalg::qr::no_pivoting::factor as qr;
use faer::linalg::triangular_inverse::invert_upper_triangular;
use faer::linalg::triangular_solve::solve_upper_triangular_in_place;
use faer::{Conj, Mat, Par};
use std::fmt;

/// A column whose residual, relative to its own norm, falls below this is in the
/// span of the columns kept before it; a column whose norm, relative to the largest
/// column's, falls below it is zero. The singular-value check counts
/// `σ > RANK_TOLERANCE · σ₁`.
pub const RANK_TOLERANCE: f64 = 1e-8;
/// Random states stacked per analysis (rows = `SAMPLES · n`) for every model of at most
/// [`ALL_SAMPLES_UP_TO`] columns; larger models stack fewer ([`state_count`]).
pub const SAMPLES: usize = 40;
/// The largest column count (parameters) analysed on all [`SAMPLES`] states and
/// rank-checked by a full SVD: every robot in the repository (the largest, the
/// floating 31-joint humanoid with joint parameters, has 468 columns) and anything of
/// similar size.
pub const ALL_SAMPLES_UP_TO: usize = 600;
/// Above [`ALL_SAMPLES_UP_TO`] columns: at least `ROWS_PER_COLUMN.0 / ROWS_PER_COLUMN.1`
/// stacked rows per column (1.5), and never fewer than `MIN_SAMPLES` states.
const ROWS_PER_COLUMN: (usize, usize) = (3, 2);
const MIN_SAMPLES: usize = 20;
/// The seed of the analysis, and the seed of the check that repeats it.
pub const SEEDS: [u64; 2] = [0x5eed_0001, 0x5eed_0002];

/// Which parameters the regressor is linear in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Parameterisation {
    /// `π_i = [m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, 10 per body:
    /// `τ = Y π`.
    Standard,
    /// `θ_i = (m, J1, J2, J3)` with the nominal centre of mass and principal axes,
    /// 4 per body: `τ = Y blkdiag(P_i) θ` ([`crate::PrincipalFrame::p_matrix`]).
    Principal,
    /// The standard parameters followed by the joint parameters `[Ia, Fv, Fc, F0]` of
    /// every joint (`10n + 4n` columns, [`crate::joint_params`]), with the Coulomb
    /// term as `sign(q̇)`: the model identified on a real robot.
    StandardAndJoints,
}

impl Parameterisation {
    /// Parameters per body: 10 or 4.
    pub fn per_body(self) -> usize {
        match self {
            Parameterisation::Standard | Parameterisation::StandardAndJoints => STANDARD_PER_BODY,
            Parameterisation::Principal => PRINCIPAL_PER_BODY,
        }
    }

    /// The parameter names of a model of `n` bodies, each on a joint with one
    /// degree of freedom ([`crate::names`]); [`Parameterisation::names_of`] for any.
    pub fn names(self, n: usize) -> Vec<String> {
        self.names_with(n, n)
    }

    /// The parameter names of `model`: per body, then (joint parameters) per velocity
    /// coordinate.
    pub fn names_of(self, model: &Model) -> Vec<String> {
        self.names_with(model.dof(), model.nv())
    }

    fn names_with(self, bodies: usize, dofs: usize) -> Vec<String> {
        match self {
            Parameterisation::Standard => standard_param_names(bodies),
            Parameterisation::Principal => principal_param_names(bodies),
            Parameterisation::StandardAndJoints => {
                let mut names = standard_param_names(bodies);
                names.extend(joint_param_names(dofs));
                names
            }
        }
    }
}

/// The outcome of a base-parameter analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct BaseParams {
    pub parameterisation: Parameterisation,
    /// Columns of the parameter vector that form the base, ascending.
    pub independent: Vec<usize>,
    /// `K` (b × p, one row per base parameter): `β = K π`, so `Y π = Y_b β` with
    /// `Y_b` the columns `independent` of `Y`.
    pub k: Vec<Vec<f64>>,
    /// A readable formula for each base parameter, e.g. `Izz1 + Iyy2 + 0.1817·m3`.
    pub groupings: Vec<String>,
    /// Whether the analysis repeated with the second seed chose the same columns.
    pub confirmed: bool,
    /// The numerical rank of the stacked regressor from its singular values
    /// (`σ > RANK_TOLERANCE · σ₁`); equal to [`BaseParams::count`] when the QR's
    /// decisions were clear-cut.
    pub rank_check: usize,
}

impl BaseParams {
    /// The number of base parameters `b`.
    pub fn count(&self) -> usize {
        self.independent.len()
    }

    /// Whether both checks agree with the QR: the second seed chose the same columns
    /// and the singular values give the same rank. When this is false the count is
    /// not to be trusted (a tolerance decision was borderline); [`fmt::Display`]
    /// says which check failed.
    pub fn is_consistent(&self) -> bool {
        self.confirmed && self.rank_check == self.count()
    }
}

impl fmt::Display for BaseParams {
    /// `b` base parameters, one grouping per line, then any failed check.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} base parameters:", self.count())?;
        for g in &self.groupings {
            writeln!(f, "  {g}")?;
        }
        if self.rank_check != self.count() {
            writeln!(
                f,
                "warning: the singular values give rank {}, the QR kept {} columns",
                self.rank_check,
                self.count()
            )?;
        }
        if !self.confirmed {
            writeln!(f, "warning: a second sample chose different columns")?;
        }
        Ok(())
    }
}

/// The base parameters of `model` in `parameterisation`: the QR of the module docs
/// on the regressor stacked over [`state_count`] states from [`structure_states`]
/// with `SEEDS[0]`, confirmed with `SEEDS[1]`, and the rank counted from the
/// singular values of the same stacked matrix (above [`ALL_SAMPLES_UP_TO`] columns:
/// proved equal by bounds, or counted on the factor, see `large_rank`).
pub fn analyse(model: &Model, parameterisation: Parameterisation) -> BaseParams {
    analysed(model, parameterisation, None)
}

/// [`analyse`] on some rows of the dynamics only: `rows` lists the velocity
/// coordinates whose equations are measured (e.g. `0..6`, the base wrench of a
/// floating base from contact forces, or `6..nv`, the joint torques alone).
pub fn analyse_rows(model: &Model, parameterisation: Parameterisation, rows: &[usize]) -> BaseParams {
    analysed(model, parameterisation, Some(rows))
}

/// [`analyse`] on the rows `keep` (all when `None`).
fn analysed(model: &Model, parameterisation: Parameterisation, keep: Option<&[usize]>) -> BaseParams {
    let names = parameterisation.names_of(model);
    // The second seed's analysis runs on a thread of its own (on the 31-joint
    // humanoid's standard and joint parameters: 1.2 s on one core, 0.65 s on two).
    let (mut base, rank_check, second) = std::thread::scope(|s| {
        // Only its choice of columns is compared: no K, no groupings.
        let second = s.spawn(|| ordered_qr(stacked(model, parameterisation, SEEDS[1], keep)).kept);
        let first = stacked(model, parameterisation, SEEDS[0], keep);
        // Small models: the singular values of the stacked matrix itself.
        let counted = (first.ncols() <= ALL_SAMPLES_UP_TO).then(|| {
            let sv = singular_values_of(first.as_ref());
            let largest = sv.first().copied().unwrap_or(0.0);
            sv.iter().filter(|&&s| s > RANK_TOLERANCE * largest && s > 0.0).count()
        });
        let (base, factored) = from_matrix(first, &names);
        let rank_check = counted.unwrap_or_else(|| large_rank(&factored));
        // A panic in the analysis is a bug; it is carried over as it was.
        let second = second.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
        (base, rank_check, second)
    });
    base.confirmed = second == base.independent;
    BaseParams {
        parameterisation,
        rank_check,
        ..base
    }
}

/// How many states to stack for `columns` parameters when one state gives
/// `rows_per_state` rows. Up to [`ALL_SAMPLES_UP_TO`] columns: [`SAMPLES`] (40 states
/// of a serial arm give `4 p` rows of the standard parameters, `2.9 p` with joint
/// parameters). Above, the rows grow no further than needed: the stacked rank is
/// reached once the rows exceed it, and every extra row adds to the cost of the QR
/// (`rows · columns · rank`) and to the memory (`rows · columns`). So 1.5 rows per
/// column, and never fewer than 20 states (a parameter seen in one joint's equation
/// only, e.g. a joint's friction, has one row per state) nor more than [`SAMPLES`]:
/// a serial chain of more than 60 joints stacks 20 states for the standard
/// parameters (1.5 per column would be 15) and 21 with joint parameters, not 40.
pub fn state_count(rows_per_state: usize, columns: usize) -> usize {
    if columns <= ALL_SAMPLES_UP_TO || rows_per_state == 0 {
        return SAMPLES;
    }
    (ROWS_PER_COLUMN.0 * columns)
        .div_ceil(ROWS_PER_COLUMN.1 * rows_per_state)
        .clamp(MIN_SAMPLES, SAMPLES)
}

/// The regressor stacked over [`state_count`] structure states drawn with `seed`,
/// keeping only the rows `keep` of each state (all when `None`). Rows are ordered
/// by equation, then state (all states' rows of the first kept equation first): the
/// columns of a body are zero in the equations of joints that do not support it, so
/// in this order a chain's body `i` has its columns zero below the rows of joint `i`,
/// which `ordered_qr` uses. The row order changes nothing else (the QR's decisions
/// depend only on the columns' inner products).
fn stacked(model: &Model, parameterisation: Parameterisation, seed: u64, keep: Option<&[usize]>) -> Mat<f64> {
    let nv = model.nv();
    let rows: Vec<usize> = match keep {
        None => (0..nv).collect(),
        Some(k) => (0..nv).filter(|d| k.contains(d)).collect(),
    };
    let p = parameterisation.names_of(model).len();
    let count = state_count(rows.len(), p);
    let mut w = Mat::<f64>::zeros(count * rows.len(), p);
    for (s, state) in structure_states(model, count, seed).into_iter().enumerate() {
        let mut y = torque_regressor(model, &state.q, &state.v, &state.a);
        match parameterisation {
            Parameterisation::Standard => {}
            Parameterisation::Principal => y = principal_from_standard(model, &y),
            Parameterisation::StandardAndJoints => append_joint_columns(&mut y, &state.v, &state.a, Coulomb::Sign),
        }
        for (e, &d) in rows.iter().enumerate() {
            for (c, &x) in y[d].iter().enumerate() {
                if x != 0.0 {
                    w[(e * count + s, c)] = x;
                }
            }
        }
    }
    w
}

/// [`from_matrix`] on a stacked regressor given as rows.
#[cfg(test)]
fn from_stacked(rows: &[Vec<f64>], names: &[String]) -> BaseParams {
    let w = Mat::<f64>::from_fn(rows.len(), names.len(), |i, j| rows[i][j]);
    from_matrix(w, names).0
}

/// The ordered QR of the module docs on a stacked regressor (factored in place)
/// whose columns `names` names; `confirmed` and `rank_check` are left for the caller.
/// The factorisation comes back too, for `large_rank`.
fn from_matrix(w: Mat<f64>, names: &[String]) -> (BaseParams, OrderedQr) {
    let p = names.len();
    let qr = ordered_qr(w);
    let rank = qr.kept.len();
    // `R₁₁⁻¹ R₁₂`: each set-aside column as a combination of the kept columns.
    let mut coef = qr.r12.clone();
    solve_upper_triangular_in_place(qr.r11.as_ref(), coef.as_mut(), Par::Seq);
    let independent = qr.kept.clone();
    let k: Vec<Vec<f64>> = (0..rank)
        .map(|row| {
            let mut kr = vec![0.0; p];
            kr[qr.kept[row]] = 1.0;
            for (d, &col) in qr.dropped.iter().enumerate() {
                kr[col] = clean(coef[(row, d)]);
            }
            kr
        })
        .collect();
    let groupings = k.iter().map(|kr| grouping(kr, names)).collect();
    let base = BaseParams {
        parameterisation: Parameterisation::Standard,
        independent,
        k,
        groupings,
        confirmed: true,
        rank_check: rank,
    };
    (base, qr)
}

/// Rounds away the noise of the factorisation: |x| < 1e-10 → 0, and values within
/// 1e-10 of ±1 → ±1, so exact groupings print exactly. Other values are snapped to a
/// short decimal when one lies within [`SNAP_RELATIVE`] (see [`snap_decimal`]), or
/// else to a fraction of small denominator (see [`snap_ratio`]).
fn clean(x: f64) -> f64 {
    if x.abs() < 1e-10 {
        0.0
    } else if (x.abs() - 1.0).abs() < 1e-10 {
        x.signum()
    } else {
        snap_decimal(x).or_else(|| snap_ratio(x)).unwrap_or(x)
    }
}

/// How close, relative to its magnitude, a coefficient of `K` must be to a decimal of
/// at most [`SNAP_DIGITS`] significant digits to be replaced by it. The entries of `K`
/// are exact sums of products of the model's numbers (`0.425² = 0.180625`), which are
/// short decimals when the description's numbers are; the factorisation returns them
/// with its own rounding, some hundred ulps (`0.18062499999999998`). The snap is far
/// below what the factorisation resolves, so it changes nothing a test can see.
const SNAP_RELATIVE: f64 = 1e-13;
const SNAP_DIGITS: usize = 10;

/// The decimal with the fewest significant digits (at most [`SNAP_DIGITS`]) within
/// [`SNAP_RELATIVE`] of `x`, if there is one.
fn snap_decimal(x: f64) -> Option<f64> {
    // Most coefficients are no short decimal; they are told apart without formatting
    // (K of a 100-joint chain has 2 · 10⁵ of them): x · 10^s is within 10⁻¹² of an
    // integer, relative, for some scale s of up to SNAP_DIGITS digits (the decimal
    // exponent taken ±1 in case log10 rounds across a power of ten). That is ten
    // times the snap's own tolerance, far above the rounding of the product, so
    // every value the formatted search below would snap passes.
    let e = x.abs().log10().floor() as i32;
    let near = (0..SNAP_DIGITS as i32).any(|p| {
        (e - 1..=e + 1).any(|e| {
            let t = x * 10f64.powi(p - e);
            (t - t.round()).abs() <= 1e-12 * t.abs()
        })
    });
    if !near {
        return None;
    }
    (0..SNAP_DIGITS)
        .filter_map(|p| format!("{x:.p$e}").parse::<f64>().ok())
        .find(|y| (y - x).abs() <= SNAP_RELATIVE * x.abs())
}

/// The largest denominator [`snap_ratio`] tries.
const SNAP_DENOMINATOR: u32 = 100;

/// `p / q` (the double nearest to it) for the smallest `q ≤ SNAP_DENOMINATOR` with
/// `|p/q − x| ≤ SNAP_RELATIVE · |x|`, if there is one. Entries of `K` divide by the
/// model's numbers too (`17/30` from lengths 0.5 and 0.3), and two entries equal in
/// exact arithmetic then come out of the factorisation a few ulps apart, differently
/// for every factorisation; the snap makes them one number again (the generated
/// code shares a product by a repeated constant). A value of no such fraction is
/// within the tolerance of one by chance with a probability of about 10⁻⁹.
fn snap_ratio(x: f64) -> Option<f64> {
    if x.abs() >= 1e12 {
        return None;
    }
    (2..=SNAP_DENOMINATOR).map(f64::from).find_map(|q| {
        let p = (x * q).round();
        let y = p / q;
        (p != 0.0 && (y - x).abs() <= SNAP_RELATIVE * x.abs()).then_some(y)
    })
}

fn grouping(kr: &[f64], names: &[String]) -> String {
    let mut s = String::new();
    for (c, &x) in kr.iter().enumerate() {
        if x == 0.0 {
            continue;
        }
        let sign = if x < 0.0 { "−" } else { "+" };
        let mag = x.abs();
        let term = if mag == 1.0 {
            names[c].clone()
        } else {
            format!("{}·{}", format_coef(mag), names[c])
        };
        if s.is_empty() {
            s = if x < 0.0 { format!("−{term}") } else { term };
        } else {
            s.push_str(&format!(" {sign} {term}"));
        }
    }
    s
}

fn format_coef(x: f64) -> String {
    let t = format!("{x:.6}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Columns per panel of `ordered_qr`: the decisions within a panel are taken one
/// column at a time, the panel's kept columns then update the rest in one blocked
/// Householder product.
const PANEL: usize = 32;

/// What `ordered_qr` found.
struct OrderedQr {
    /// Kept columns, ascending (the base), and the columns set aside, ascending.
    kept: Vec<usize>,
    dropped: Vec<usize>,
    /// `R₁₁` (rank × rank, upper triangular): the kept columns' factor.
    r11: Mat<f64>,
    /// `R₁₂` (rank × dropped), each column cut to the rows of the kept columns before
    /// it: `W' = Q [R₁₁ R₁₂]` (columns reordered).
    r12: Mat<f64>,
    /// `‖E‖_F`: the norm of what setting aside ignores, the residuals of the
    /// set-aside columns (whole columns for the numerically zero ones). `W` is
    /// `W' + E` with `W'` of rank exactly `rank`.
    residual: f64,
    /// `‖W‖_F` and the largest column norm: bounds on `σ₁(W)` from above and below.
    frobenius: f64,
    largest: f64,
}

/// The QR of `w` (m × p) that takes the columns in order and keeps column `c` only if
/// it is not numerically zero (its norm, relative to the largest column's, above
/// [`RANK_TOLERANCE`]) and its residual after projecting out the columns kept before
/// it exceeds [`RANK_TOLERANCE`] times its own norm. A column set aside does not take
/// part in the factorisation: its tiny residual never becomes a direction the later
/// columns are reduced by.
///
/// Blocked, right-looking: the columns go in panels of [`PANEL`]. Within a panel,
/// whose columns are already reduced by every earlier kept column, the decisions
/// are taken in order by Gram–Schmidt with reorthogonalisation against the panel's
/// own kept columns (the residual of the rule above, to working precision). The kept
/// columns of the panel are then factored by faer's Householder QR and their block
/// reflector is applied to the panel's set-aside columns (giving their coefficients)
/// and to all later columns (faer's blocked Householder product: matrix products).
///
/// Only rows that can be non-zero are touched: the panel's reflectors live in the
/// rows from the first not yet taken by a kept column to the last row in which any
/// column up to the panel is non-zero (every row below is zero in all of them and was
/// never changed). With the rows of [`stacked`] (by equation) a chain's panel of body
/// `i` works on about `i · (states − kept per body)` rows instead of all of them.
///
/// The coefficients of a set-aside column `d` are `R₁₁⁻¹ R₁₂` with its column of
/// `R₁₂` cut to the kept columns before it (the rest is its residual, which the rule
/// above called noise): the least-squares combination of the columns kept before it.
fn ordered_qr(mut a: Mat<f64>) -> OrderedQr {
    let p = a.ncols();
    let norms: Vec<f64> = (0..p).map(|c| a.col(c).norm_l2()).collect();
    let largest = norms.iter().copied().fold(0.0, f64::max);
    let frobenius = norms.iter().map(|x| x * x).sum::<f64>().sqrt();
    // The rows below `depth[c]` are zero in column c.
    let depth: Vec<usize> = (0..p)
        .map(|c| {
            let col = a.col_as_slice(c);
            col.iter().rposition(|&x| x != 0.0).map_or(0, |i| i + 1)
        })
        .collect();
    let mut kept = Vec::new();
    let mut dropped = Vec::new();
    // For each column: the rows kept columns before it had taken.
    let mut before = vec![0usize; p];
    let mut residual2 = 0.0;
    let mut k = 0;
    let mut end = 0;
    let mut c0 = 0;
    while c0 < p {
        let c1 = (c0 + PANEL).min(p);
        end = depth[c0..c1].iter().copied().fold(end.max(k), usize::max);
        let h = end - k;
        // The panel's kept columns, orthonormalised (rows k..end).
        let mut basis: Vec<Vec<f64>> = Vec::new();
        let mut taken = Vec::new();
        let mut set_aside = Vec::new();
        for c in c0..c1 {
            before[c] = k + taken.len();
            if norms[c] <= RANK_TOLERANCE * largest {
                // Algebraic cancellations leave rounding noise where a column is
                // exactly zero, so "zero" is relative to the largest column.
                residual2 += norms[c] * norms[c];
                set_aside.push(c);
                continue;
            }
            let mut v = a.col_as_slice(c)[k..end].to_vec();
            for _ in 0..2 {
                for u in &basis {
                    let f = dot(u, &v);
                    v.iter_mut().zip(u).for_each(|(x, y)| *x -= f * y);
                }
            }
            let residual = dot(&v, &v).sqrt();
            // With as many kept columns as rows the residual is rounding noise.
            if taken.len() >= h || residual <= RANK_TOLERANCE * norms[c] {
                residual2 += residual * residual;
                set_aside.push(c);
                continue;
            }
            v.iter_mut().for_each(|x| *x /= residual);
            basis.push(v);
            taken.push(c);
        }
        let t = taken.len();
        if t > 0 {
            // Householder QR (faer, blocked) of the kept columns' rows k..end.
            let mut f = Mat::<f64>::from_fn(h, t, |i, j| a[(k + i, taken[j])]);
            let block = qr::recommended_block_size::<f64>(h, t);
            let mut coeff = Mat::<f64>::zeros(block, t);
            let later = p - c1;
            let scratch = qr::qr_in_place_scratch::<f64>(h, t, block, Par::Seq, Default::default())
                .or(apply_scratch::<f64>(h, block, later.max(1)));
            let mut mem = MemBuffer::new(scratch);
            qr::qr_in_place(
                f.as_mut(),
                coeff.as_mut(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            );
            for (j, &c) in taken.iter().enumerate() {
                for i in 0..h {
                    a[(k + i, c)] = if i <= j { f[(i, j)] } else { 0.0 };
                }
            }
            let mut reduce = |target: faer::MatMut<'_, f64>| {
                apply_transpose(
                    f.as_ref(),
                    coeff.as_ref(),
                    Conj::No,
                    target,
                    Par::Seq,
                    MemStack::new(&mut mem),
                )
            };
            for &d in &set_aside {
                reduce(a.as_mut().submatrix_mut(k, d, h, 1));
            }
            if later > 0 {
                reduce(a.as_mut().submatrix_mut(k, c1, h, later));
            }
        }
        kept.extend_from_slice(&taken);
        dropped.extend_from_slice(&set_aside);
        k += t;
        c0 = c1;
    }
    let rank = kept.len();
    let r11 = Mat::<f64>::from_fn(rank, rank, |i, j| if i <= j { a[(i, kept[j])] } else { 0.0 });
    let r12 = Mat::<f64>::from_fn(rank, dropped.len(), |i, j| {
        let d = dropped[j];
        if i < before[d] {
            a[(i, d)]
        } else {
            0.0
        }
    });
    OrderedQr {
        kept,
        dropped,
        r11,
        r12,
        residual: residual2.sqrt(),
        frobenius,
        largest,
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The rank check above [`ALL_SAMPLES_UP_TO`] columns, without an SVD of `W` when
/// bounds prove the count.
///
/// A full SVD of a `p`-column matrix costs `O(p³)` in a bidiagonalisation that is half
/// matrix-vector products: for a 200-joint chain with joint parameters (2800 columns)
/// it takes longer than the whole analysis. The QR leaves `W = W' + E` with `W'`
/// of rank `r` exactly (`W' = Q [R₁₁ R₁₂]`, columns reordered) and `‖E‖_F` the
/// set-aside residuals ([`OrderedQr::residual`]). By Weyl's inequality
///
/// ```text
/// σ_{r+1}(W) ≤ ‖E‖₂ ≤ ‖E‖_F
/// σ_r(W) ≥ σ_r(W') − ‖E‖_F = σ_min(L) − ‖E‖_F ≥ 1/‖L⁻¹‖_F − ‖E‖_F
/// max column norm ≤ σ₁(W) ≤ ‖W‖_F
/// ```
///
/// with `L` (`r × r`) the triangle of the QR of `[R₁₁ R₁₂]ᵀ` (same singular values
/// as `W'`). So the count `#{σ > RANK_TOLERANCE · σ₁}` is `r` if
/// `‖E‖_F ≤ tol · max column norm` and `1/‖L⁻¹‖_F − ‖E‖_F > tol · ‖W‖_F`: one QR and
/// one triangular inverse, matrix products both. The second test is pessimistic by
/// at most `√r` in each norm; on a 200-joint chain `σ_r/σ₁` is `10⁻⁵` (standard) and
/// `2 · 10⁻⁶` (with joint parameters), far enough from `10⁻⁸` for it to hold. When it
/// does not, the singular values of `L` are counted (faer's SVD), which is the count
/// of `W`'s unless a singular value lies within `‖E‖_F` of the threshold (`‖E‖_F` is
/// rounding noise where columns are exactly dependent: about `10⁻¹²` of `σ₁` on that
/// chain).
///
/// Like an SVD of `W` it checks the QR's decisions: a kept column nearly in the span
/// of the others makes `L` ill-conditioned, a set-aside column with a sizeable
/// residual makes `E` large.
fn large_rank(qr: &OrderedQr) -> usize {
    let (r, d) = (qr.kept.len(), qr.dropped.len());
    if r == 0 {
        return 0;
    }
    let mut top_t = Mat::<f64>::zeros(r + d, r);
    top_t.as_mut().submatrix_mut(0, 0, r, r).copy_from(qr.r11.transpose());
    top_t.as_mut().submatrix_mut(r, 0, d, r).copy_from(qr.r12.transpose());
    let triangle = top_t.qr().thin_R().to_owned();
    let e = qr.residual;
    if e <= RANK_TOLERANCE * qr.largest {
        let mut inverse = Mat::<f64>::zeros(r, r);
        invert_upper_triangular(inverse.as_mut(), triangle.as_ref(), Par::Seq);
        let norm = inverse.norm_l2();
        if norm.is_finite() && 1.0 / norm - e > RANK_TOLERANCE * qr.frobenius {
            return r;
        }
    }
    let sv = singular_values_of(triangle.as_ref());
    let largest = sv.first().copied().unwrap_or(0.0);
    sv.iter().filter(|&&s| s > RANK_TOLERANCE * largest && s > 0.0).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With rotor inertia and friction every joint adds 4 columns, all identifiable
    /// but the rotor inertias of the first two joints: the first moves only with body
    /// 1 about the same axis, and with the second axis perpendicular to and meeting
    /// the first, the second's rotor enters exactly as body 2's `Izz` does (the
    /// classical regrouping `ZZ2R = ZZ2 + Ia2`).
    #[test]
    fn joint_parameters_add_four_columns_per_joint_but_the_first_two_rotors() {
        let model = crate::parse_urdf(include_str!("../../robots/ur5/ur5.urdf")).unwrap();
        let standard = analyse(&model, Parameterisation::Standard);
        let all = analyse(&model, Parameterisation::StandardAndJoints);
        assert!(all.is_consistent(), "{all}");
        assert_eq!(all.count(), standard.count() + 4 * 6 - 2, "{all}");
        assert_eq!(Parameterisation::StandardAndJoints.names(6).len(), 84);
        assert_eq!(&all.independent[..standard.count()], &standard.independent[..]);
        for (ia, izz) in [(60, "Izz1"), (64, "Izz2")] {
            assert!(!all.independent.contains(&ia), "{all}");
            let name = &Parameterisation::StandardAndJoints.names(6)[ia];
            assert!(
                all.groupings
                    .iter()
                    .any(|g| g.starts_with(izz) && g.contains(name.as_str())),
                "{all}"
            );
        }
        for c in 60..84 {
            if c != 60 && c != 64 {
                assert!(all.independent.contains(&c), "column {c} of {all}");
            }
        }
    }

    /// The large models' rank check: proved by the bounds when the kept columns are
    /// well conditioned, counted from singular values when a kept column is barely
    /// independent (its residual 3 · 10⁻⁸ of its norm: kept by the QR, but below the
    /// threshold of the singular values, whose `σ₁` comes from a column 100 times
    /// larger). `large_rank` must give what the SVD of the matrix gives.
    #[test]
    fn large_rank_agrees_with_the_singular_values() {
        let base = [
            [1.0, 0.5, 0.2],
            [2.0, -1.0, 0.1],
            [0.3, 0.7, -0.4],
            [-1.0, 2.0, 0.3],
            [0.0, 1.0, 1.0],
        ];
        for (scale, nudge, qr_rank, svd_rank) in [(1.0, 0.0, 2, 2), (100.0, 1e-7, 3, 2)] {
            // Columns: c0, c1 = 2 c0, c2, c3 = c0 − c2 + nudge · x.
            let rows: Vec<Vec<f64>> = base
                .iter()
                .map(|r| vec![scale * r[0], 2.0 * scale * r[0], r[1], r[0] - r[1] + nudge * r[2]])
                .collect();
            let sv = singular_values(&rows);
            let by_svd = sv.iter().filter(|&&s| s > RANK_TOLERANCE * sv[0]).count();
            assert_eq!(by_svd, svd_rank, "{sv:?}");
            let w = Mat::<f64>::from_fn(5, 4, |i, j| rows[i][j]);
            let (b, qr) = from_matrix(w, &["a", "b", "c", "d"].map(String::from));
            assert_eq!(b.count(), qr_rank);
            assert_eq!(large_rank(&qr), svd_rank, "{sv:?}");
        }
    }

    /// Two entries equal in exact arithmetic (17/30) that a factorisation returned
    /// 10 ulps apart become one number; a value near no small fraction stays.
    #[test]
    fn coefficients_snap_to_fractions_of_small_denominator() {
        assert_eq!(clean(0.5666666666666652), 17.0 / 30.0);
        assert_eq!(clean(0.5666666666666669), 17.0 / 30.0);
        assert_eq!(clean(-4.222222222222227), -38.0 / 9.0);
        let irrational = std::f64::consts::E / 7.0;
        assert_eq!(clean(irrational), irrational);
        assert_eq!(clean(0.56666666667), 0.56666666667);
    }

    #[test]
    fn coefficients_snap_to_short_decimals_only_when_within_rounding() {
        assert_eq!(clean(0.18062499999999998), 0.180625);
        assert_eq!(clean(-0.42500000000000004), -0.425);
        let irrational = std::f64::consts::PI / 10.0;
        assert_eq!(clean(irrational), irrational);
        assert_eq!(clean(3e-11), 0.0);
        assert_eq!(clean(-1.0 + 1e-12), -1.0);
    }
    use crate::regressor::{joint_torque_regressor, principal_regressor};
    use crate::sample::sample_states;

    fn robot(path: &str) -> Model {
        let file = format!("{}/../{path}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{file}: {e}"));
        crate::parse_urdf(&text).unwrap_or_else(|e| panic!("{file}: {e}"))
    }

    #[test]
    fn qr_finds_rank_and_combinations() {
        // Columns: c0, c1 = 2 c0, c2 independent, c3 = c0 − c2.
        let base = [[1.0, 0.5], [2.0, -1.0], [0.3, 0.7], [-1.0, 2.0], [0.0, 1.0]];
        let rows: Vec<Vec<f64>> = base.iter().map(|r| vec![r[0], 2.0 * r[0], r[1], r[0] - r[1]]).collect();
        let names: Vec<String> = ["a", "b", "c", "d"].map(String::from).to_vec();
        let b = from_stacked(&rows, &names);
        assert_eq!(b.independent, vec![0, 2]);
        assert_eq!(b.groupings, vec!["a + 2·b + d", "c − d"]);
    }

    #[test]
    fn shipped_robots_have_their_known_ranks() {
        for (path, standard) in [
            ("robots/ur5/ur5.urdf", 36),
            ("robots/puma560/puma560.urdf", 36),
            ("robots/panda/panda.urdf", 43),
        ] {
            let model = robot(path);
            let b = analyse(&model, Parameterisation::Standard);
            assert_eq!(b.count(), standard, "{path}\n{b}");
            assert!(b.is_consistent(), "{path}\n{b}");
            let p = analyse(&model, Parameterisation::Principal);
            assert!(p.is_consistent(), "{path}\n{p}");
            assert!(p.count() <= 4 * model.dof() && p.count() <= standard, "{path}\n{p}");
        }
    }

    /// Every fixture robot: the count equals the rank of Pinocchio's own regressor
    /// stacked over the fixture's 50 states (`σ > 10⁻⁸ σ₁`), as the Pinocchio
    /// comparison of generated code checks it.
    #[test]
    fn counts_match_the_rank_of_pinocchios_stacked_regressor() {
        for (name, path) in crate::regressor::PINOCCHIO_FIXTURES {
            let file = format!("{}/../tests/fixtures/{name}.json", env!("CARGO_MANIFEST_DIR"));
            let fx: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
            let vec = |v: &serde_json::Value| -> Vec<f64> {
                v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
            };
            let rows: Vec<Vec<f64>> = fx["samples"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|s| s["Y"].as_array().unwrap().iter().map(vec).collect::<Vec<_>>())
                .collect();
            let sv = singular_values(&rows);
            let pinocchio = sv.iter().filter(|&&x| x > RANK_TOLERANCE * sv[0]).count();
            let mut model = robot(path);
            let g = vec(&fx["gravity"]);
            model.gravity = [g[0], g[1], g[2]];
            let b = analyse(&model, Parameterisation::Standard);
            assert_eq!(b.count(), pinocchio, "{name}\n{b}");
            assert!(b.is_consistent(), "{name}\n{b}");
        }
    }

    /// `Y_b β = Y π` on states the analysis never saw, in both parameterisations.
    #[test]
    fn base_regressor_reproduces_the_torques() {
        for path in [
            "robots/ur5/ur5.urdf",
            "robots/panda/panda.urdf",
            "robots/gripper_arm/gripper_arm.urdf",
            "tests/fixtures/tree12.urdf",
        ] {
            let model = robot(path);
            for (param, full) in [
                (Parameterisation::Standard, model.standard_params()),
                (Parameterisation::Principal, crate::principal_params(&model)),
            ] {
                let b = analyse(&model, param);
                assert!(b.is_consistent(), "{path}\n{b}");
                let beta: Vec<f64> =
                    b.k.iter()
                        .map(|kr| kr.iter().zip(&full).map(|(k, x)| k * x).sum())
                        .collect();
                for s in sample_states(&model, 10, 99) {
                    let y = match param {
                        Parameterisation::Standard => joint_torque_regressor(&model, &s.q, &s.v, &s.a),
                        Parameterisation::Principal => principal_regressor(&model, &s.q, &s.v, &s.a),
                        Parameterisation::StandardAndJoints => unreachable!("not among the cases"),
                    }
                    .unwrap();
                    for row in &y {
                        let tau: f64 = row.iter().zip(&full).map(|(a, b)| a * b).sum();
                        let base: f64 = b.independent.iter().zip(&beta).map(|(&c, x)| row[c] * x).sum();
                        assert!(
                            (tau - base).abs() < 1e-9 * tau.abs().max(1.0),
                            "{path}: {tau} vs {base}"
                        );
                    }
                }
            }
        }
    }

    /// A spatial arm: shoulder yaw `j1`, shoulder pitch `j2` of type `kind2` with
    /// `limit2` (an empty string: no `<limit>`), then `j3` of type `kind3` with
    /// `limit3`. Pinning the shoulder pitch hides parameters (it is what turns
    /// gravity against the links beyond it).
    fn arm(kind2: &str, limit2: &str, kind3: &str, limit3: &str) -> Model {
        let link = |name: &str, com: &str| {
            format!(
                r#"<link name="{name}"><inertial><mass value="2"/><origin xyz="{com}"/>
                <inertia ixx="0.05" iyy="0.04" izz="0.03" ixy="0.001" ixz="0.002" iyz="0.003"/></inertial></link>"#
            )
        };
        let urdf = format!(
            r#"<robot name="arm"><link name="base"/>
            {}{}{}
            <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
              <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
            <joint name="j2" type="{kind2}"><parent link="l1"/><child link="l2"/>
              <origin xyz="0 0 0.3" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>{limit2}</joint>
            <joint name="j3" type="{kind3}"><parent link="l2"/><child link="l3"/>
              <origin xyz="0.4 0 0"/><axis xyz="0.6 0 0.8"/>{limit3}</joint>
            </robot>"#,
            link("l1", "0 0.02 0.1"),
            link("l2", "0.2 0 0.01"),
            link("l3", "0.15 0.01 0"),
        );
        crate::parse_urdf(&urdf).unwrap()
    }

    fn lim(lower: f64, upper: f64) -> String {
        format!(r#"<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/>"#)
    }

    #[test]
    fn placeholder_narrow_and_missing_limits_do_not_change_the_base() {
        let wide = lim(-3.0, 3.0);
        for param in [Parameterisation::Standard, Parameterisation::Principal] {
            let reference = analyse(&arm("revolute", &wide, "revolute", &wide), param);
            assert!(reference.is_consistent(), "{reference}");
            for (kind, limit) in [
                ("revolute", lim(0.0, 0.0)),
                ("revolute", lim(0.0, 0.01)),
                ("revolute", lim(0.0, 3.0)),
                ("revolute", lim(-0.2, -0.1)),
                ("continuous", String::new()),
            ] {
                let b = analyse(&arm(kind, &limit, "revolute", &wide), param);
                assert!(b.is_consistent(), "{kind} {limit}\n{b}");
                assert_eq!(b.independent, reference.independent, "{kind} {limit}");
            }
        }
    }

    #[test]
    fn placeholder_limits_on_a_prismatic_joint_do_not_change_the_base() {
        let wide = lim(-3.0, 3.0);
        let reference = analyse(
            &arm("revolute", &wide, "prismatic", &lim(-0.3, 0.3)),
            Parameterisation::Standard,
        );
        for limit in [lim(0.0, 0.0), lim(0.0, 0.001), lim(-100.0, 100.0)] {
            let b = analyse(&arm("revolute", &wide, "prismatic", &limit), Parameterisation::Standard);
            assert!(b.is_consistent(), "{limit}\n{b}");
            assert_eq!(b.independent, reference.independent, "{limit}");
        }
    }

    /// The failure the limit-free sampling prevents: within 0/0 limits the shoulder
    /// pitch never moves, and the stacked regressor loses rank.
    #[test]
    fn sampling_within_placeholder_limits_would_lose_parameters() {
        let wide = lim(-3.0, 3.0);
        let model = arm("revolute", &lim(0.0, 0.0), "revolute", &wide);
        let mut rows = Vec::new();
        for s in sample_states(&model, SAMPLES, SEEDS[0]) {
            rows.extend(torque_regressor(&model, &s.q, &s.v, &s.a));
        }
        let pinned = from_stacked(&rows, &Parameterisation::Standard.names(3));
        let b = analyse(&model, Parameterisation::Standard);
        assert!(pinned.count() < b.count(), "{} vs {}", pinned.count(), b.count());
    }

    #[test]
    fn planar_two_link_arm_has_the_textbook_base() {
        // Both axes along z, link 1 of length 0.5 along x, gravity in the plane.
        let urdf = r#"<robot name="planar"><link name="base"/>
          <link name="l1"><inertial><mass value="3"/><origin xyz="0.25 0.01 0"/>
            <inertia ixx="0.01" iyy="0.06" izz="0.065" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <link name="l2"><inertial><mass value="2"/><origin xyz="0.2 -0.01 0"/>
            <inertia ixx="0.01" iyy="0.03" izz="0.035" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
          <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/>
            <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/></joint></robot>"#;
        let mut model = crate::parse_urdf(urdf).unwrap();
        model.gravity = [0.0, -9.81, 0.0];
        let b = analyse(&model, Parameterisation::Standard);
        assert!(b.is_consistent(), "{b}");
        let names = Parameterisation::Standard.names(2);
        let chosen: Vec<&str> = b.independent.iter().map(|&c| names[c].as_str()).collect();
        assert_eq!(chosen, ["mx1", "my1", "Izz1", "mx2", "my2", "Izz2"]);
        assert_eq!(
            b.groupings,
            ["mx1 + 0.5·m2", "my1", "Izz1 + 0.25·m2", "mx2", "my2", "Izz2"]
        );
    }

    /// The DSL's planar arm as written to URDF: the same base as the generated code
    /// documents for it, in both parameterisations.
    #[test]
    fn planar2_fixture_keeps_the_generated_groupings() {
        let mut model = robot("tests/fixtures/planar2.urdf");
        model.gravity = [0.0, -9.81, 0.0];
        let b = analyse(&model, Parameterisation::Standard);
        assert_eq!(b.independent, [1, 2, 9, 11, 12, 19]);
        assert_eq!(
            b.groupings,
            ["mx1 + 0.5·m2", "my1", "Izz1 + 0.25·m2", "mx2", "my2", "Izz2"]
        );
        let p = analyse(&model, Parameterisation::Principal);
        assert_eq!(p.independent, [0, 3, 4, 7]);
        assert_eq!(p.groupings, ["m1", "J3_1", "m2", "J3_2"]);
        assert!(b.is_consistent() && p.is_consistent());
    }

    #[test]
    fn display_names_a_failed_check() {
        let mut b = analyse(&arm("continuous", "", "continuous", ""), Parameterisation::Standard);
        let text = b.to_string();
        assert!(text.starts_with(&format!("{} base parameters:\n", b.count())), "{text}");
        assert!(!text.contains("warning"), "{text}");
        b.rank_check += 1;
        b.confirmed = false;
        let text = b.to_string();
        assert!(
            text.contains("the singular values give rank") && text.contains("second sample"),
            "{text}"
        );
        assert!(!b.is_consistent());
    }
}
