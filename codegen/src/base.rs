//! Base parameters, found at generation time: the regressor is evaluated numerically
//! (straight from the symbolic graph) on random states, stacked, and factored by
//! Householder QR that takes the columns in parameter order and sets aside every
//! column already in the span of those kept (a rank-revealing choice that, unlike
//! norm pivoting, does not depend on the sample). Kept columns are the base; every
//! other column is a fixed combination of them, so `Y π = Y_b β` with `β = K π`, and
//! earlier bodies' parameters absorb later ones (`Izz1 + Iyy2 + …`), as in the
//! classical regrouping rules.

use crate::algo::{self, ARG_A, ARG_Q, ARG_V};
use crate::sym::{Expr, Graph, NodeId};
use dyngen_model::Model;

/// A column whose residual, relative to its own norm, falls below this is in the
/// span of the columns kept before it; a column whose norm, relative to the largest
/// column's, falls below it is zero.
pub const RANK_TOLERANCE: f64 = 1e-8;
/// Random states stacked per analysis (rows = `SAMPLES · n`).
pub const SAMPLES: usize = 40;
/// The seed of the analysis, and the seed of the check that repeats it.
pub const SEEDS: [u64; 2] = [0x5eed_0001, 0x5eed_0002];

/// The outcome of one rank analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct BaseParams {
    /// Columns of the parameter vector that form the base, ascending.
    pub independent: Vec<usize>,
    /// `K` (b × p, row-major per base parameter): `β = K π`.
    pub k: Vec<Vec<f64>>,
    /// A readable formula for each base parameter, e.g. `Izz1 + Iyy2 + 0.1817·m3`.
    pub groupings: Vec<String>,
    /// Whether the analysis repeated with a second seed chose the same columns.
    pub confirmed: bool,
}

impl BaseParams {
    pub fn count(&self) -> usize {
        self.independent.len()
    }
}

/// The base parameters of both parameterisations of one model: what
/// [`crate::generate`] needs besides the model.
#[derive(Clone, Debug, PartialEq)]
pub struct Bases {
    /// Of the standard parameters, 10 per body.
    pub standard: BaseParams,
    /// Of the principal parameters `θ = (m, J1, J2, J3)`, 4 per body.
    pub principal: BaseParams,
}

/// The base-parameter analysis of `model`: the joint torque regressor, standard and
/// principal, built symbolically and evaluated numerically on random states (see the
/// module docs), each analysis repeated with a second seed as a check
/// ([`BaseParams::confirmed`]).
pub fn analyse_model(model: &Model) -> Bases {
    let n = model.dof();
    let standard = {
        let g = Graph::new();
        let y = algo::torque_regressor(&g, model, algo::standard_columns(&g));
        confirmed(model, &crate::standard_param_names(n), &g, &matrix_ids(&g, &y))
    };
    let principal = {
        let g = Graph::new();
        let y = algo::torque_regressor(&g, model, algo::principal_columns(&g, model));
        confirmed(model, &crate::principal_param_names(n), &g, &matrix_ids(&g, &y))
    };
    Bases { standard, principal }
}

fn matrix_ids<'g>(g: &'g Graph, y: &[Vec<Option<Expr<'g>>>]) -> Vec<NodeId> {
    y.iter()
        .flat_map(|row| row.iter().map(|e| e.unwrap_or_else(|| g.zero()).id()))
        .collect()
}

/// [`analyse`] of the regressor `ids` (row-major, one column per name), repeated
/// with the second seed.
fn confirmed(model: &Model, names: &[String], g: &Graph, ids: &[NodeId]) -> BaseParams {
    let p = names.len();
    let regressor = |q: &[f64], v: &[f64], a: &[f64]| {
        let vals = g.eval(ids, |arg, i| {
            let i = i as usize;
            match arg {
                ARG_Q => q[i],
                ARG_V => v[i],
                ARG_A => a[i],
                _ => 0.0,
            }
        });
        vals.chunks(p).map(<[f64]>::to_vec).collect()
    };
    let mut first = analyse(model, names, SEEDS[0], regressor);
    first.confirmed = analyse(model, names, SEEDS[1], regressor).independent == first.independent;
    first
}

/// Finds the base parameters of a regressor given as a function of `(q, v, a)`
/// returning `n` rows of `p` numbers. `names[c]` names column `c` in groupings.
pub fn analyse(
    model: &Model,
    names: &[String],
    seed: u64,
    regressor: impl Fn(&[f64], &[f64], &[f64]) -> Vec<Vec<f64>>,
) -> BaseParams {
    let n = model.dof();
    let p = names.len();
    let mut rows: Vec<Vec<f64>> = Vec::with_capacity(SAMPLES * n);
    for state in dyngen_model::sample::sample_states(model, SAMPLES, seed) {
        rows.extend(regressor(&state.q, &state.v, &state.a));
    }
    let (perm, r, rank) = ordered_qr(&mut rows, p);
    // Y_dep = Y_ind R11⁻¹ R12, so β = π_ind + (R11⁻¹ R12) π_dep.
    let mut coef = vec![vec![0.0; p - rank]; rank];
    for (d, col) in (rank..p).enumerate() {
        for row in (0..rank).rev() {
            let mut x = r[row][col];
            for k in row + 1..rank {
                x -= r[row][k] * coef[k][d];
            }
            coef[row][d] = x / r[row][row];
        }
    }
    let mut order: Vec<usize> = (0..rank).collect();
    order.sort_by_key(|&k| perm[k]);
    let independent: Vec<usize> = order.iter().map(|&k| perm[k]).collect();
    let k: Vec<Vec<f64>> = order
        .iter()
        .map(|&row| {
            let mut kr = vec![0.0; p];
            kr[perm[row]] = 1.0;
            for (d, col) in (rank..p).enumerate() {
                kr[perm[col]] = clean(coef[row][d]);
            }
            kr
        })
        .collect();
    let groupings = k.iter().map(|kr| grouping(kr, names)).collect();
    BaseParams {
        independent,
        k,
        groupings,
        confirmed: true,
    }
}

/// Rounds away the noise of the factorisation: |x| < 1e-10 → 0, and values within
/// 1e-10 of ±1 → ±1. Other values are snapped to a short decimal when one lies within
/// [`SNAP_RELATIVE`] (see [`snap_decimal`]).
fn clean(x: f64) -> f64 {
    if x.abs() < 1e-10 {
        0.0
    } else if (x.abs() - 1.0).abs() < 1e-10 {
        x.signum()
    } else {
        snap_decimal(x)
    }
}

/// How close, relative to its magnitude, a coefficient of `K` must be to a decimal of
/// at most [`SNAP_DIGITS`] significant digits to be replaced by it. The entries of `K`
/// are exact sums of products of the model's numbers (`0.425² = 0.180625`), which are
/// short decimals when the description's numbers are; the factorisation returns them
/// with its own rounding, some hundred ulps (`0.18062499999999998`). The snap is
/// far below what the factorisation resolves, so it changes nothing a test can see.
const SNAP_RELATIVE: f64 = 1e-13;
const SNAP_DIGITS: usize = 10;

/// `x`, or the decimal with the fewest significant digits (at most [`SNAP_DIGITS`])
/// within [`SNAP_RELATIVE`] of it.
fn snap_decimal(x: f64) -> f64 {
    (0..SNAP_DIGITS)
        .filter_map(|p| format!("{x:.p$e}").parse::<f64>().ok())
        .find(|y| (y - x).abs() <= SNAP_RELATIVE * x.abs())
        .unwrap_or(x)
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

/// Householder QR of `a` (m × p, rows) in place, columns in order, each column
/// kept only if it is not numerically zero and its residual after the reflectors of
/// the kept columns exceeds `RANK_TOLERANCE` times its own norm. Returns the column order (kept first, then
/// set aside, each in parameter order), `R` in that order (rows, p wide) and the rank.
fn ordered_qr(a: &mut [Vec<f64>], p: usize) -> (Vec<usize>, Vec<Vec<f64>>, usize) {
    let m = a.len();
    let original: Vec<f64> = (0..p)
        .map(|c| a.iter().map(|r| r[c] * r[c]).sum::<f64>().sqrt())
        .collect();
    let largest = original.iter().copied().fold(0.0, f64::max);
    let mut kept = Vec::new();
    let mut dropped = Vec::new();
    let mut k = 0;
    for c in 0..p {
        let residual = a[k.min(m)..].iter().map(|r| r[c] * r[c]).sum::<f64>().sqrt();
        // Numerically zero columns (algebraic cancellations leave rounding noise) and
        // columns in the span of those kept are set aside.
        if k >= m || original[c] <= RANK_TOLERANCE * largest || residual <= RANK_TOLERANCE * original[c] {
            dropped.push(c);
            continue;
        }
        kept.push(c);
        // Householder reflector zeroing a[k+1.., c], applied to this and later columns.
        let sign = if a[k][c] >= 0.0 { 1.0 } else { -1.0 };
        let mut v: Vec<f64> = a[k..].iter().map(|r| r[c]).collect();
        v[0] += sign * residual;
        let vnorm2: f64 = v.iter().map(|x| x * x).sum();
        for col in c..p {
            let dot: f64 = v.iter().zip(&a[k..]).map(|(vi, r)| vi * r[col]).sum();
            let f = 2.0 * dot / vnorm2;
            for (vi, r) in v.iter().zip(a[k..].iter_mut()) {
                r[col] -= f * vi;
            }
        }
        k += 1;
    }
    let rank = kept.len();
    let perm: Vec<usize> = kept.iter().chain(dropped.iter()).copied().collect();
    let r: Vec<Vec<f64>> = (0..rank).map(|row| perm.iter().map(|&c| a[row][c]).collect()).collect();
    (perm, r, rank)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_snap_to_short_decimals_only_when_within_rounding() {
        assert_eq!(snap_decimal(0.18062499999999998), 0.180625);
        assert_eq!(snap_decimal(-0.42500000000000043), -0.425);
        assert_eq!(snap_decimal(0.3463987849999999), 0.346398785);
        // Not a short decimal, or too far from one: kept.
        assert_eq!(snap_decimal(0.08328028447377561), 0.08328028447377561);
        assert_eq!(snap_decimal(0.4250001), 0.4250001);
    }

    #[test]
    fn qr_finds_rank_and_combinations() {
        // Columns: c0, c1 = 2 c0, c2 independent, c3 = c0 − c2.
        let base = [[1.0, 0.5], [2.0, -1.0], [0.3, 0.7], [-1.0, 2.0], [0.0, 1.0]];
        let mut rows: Vec<Vec<f64>> = base.iter().map(|r| vec![r[0], 2.0 * r[0], r[1], r[0] - r[1]]).collect();
        let (perm, r, rank) = ordered_qr(&mut rows, 4);
        assert_eq!(rank, 2);
        // c0 and c2 are kept; c1 and c3 are set aside.
        assert_eq!(perm, vec![0, 2, 1, 3]);
        assert_eq!(r.len(), 2);
    }
}
