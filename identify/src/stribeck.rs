//! Stribeck friction, identified by nonlinear least squares from the linear fit.
//!
//! Each joint's friction becomes
//!
//! ```text
//! τ_f = (Fc + (Fs − Fc)·exp(−(q̇/vs)²))·s(q̇) + Fv·q̇ + F0
//! ```
//!
//! (plus the rotor inertia `Ia·q̈`), with `s` the sign or `tanh(q̇/ε)`
//! ([`Coulomb`]): the friction at rest is the static `Fs`, falling (or rising) to the
//! Coulomb `Fc` as the speed passes the Stribeck velocity `vs > 0`. With `Fs = Fc` it
//! is the linear model of [`dyngen_model::joint_params`]; the extra torque is
//! [`excess_torque`].
//!
//! For fixed `vs` the model is linear in every other parameter; only `vs` is
//! nonlinear, and it acts on its own joint. [`refine`] therefore alternates, from the
//! linear fit: (1) with the rigid-body torques of the current fit fixed, every
//! joint's `[Ia, Fv, Fc, Fs, F0, ln vs]` by Levenberg–Marquardt on that joint's rows
//! alone ([`fit_joint`]; the first time from the best `vs` of a grid, each point a
//! linear fit); (2) with every joint's `Fs − Fc` and `vs` fixed, the whole linear fit
//! again on the torques without the Stribeck term. Both steps only accept what lowers
//! the sum of squared torque residuals, so the fit never gets worse than the linear
//! start; the loop stops when a round gains less than [`REFINE_TOLERANCE`].
//!
//! Two more parameters per joint can fit noise instead of friction (a tiny `vs`
//! fitting a few samples at the velocity reversals, a negative `Fc` under a large
//! `Fs`), so the fit is bounded and checked: `Fs ≥ 0` and `vs` within a range from
//! the joint's own speeds ([`velocity_range`]); each joint keeps its term only if it
//! lowers the joint's error on held-out time blocks of the recording by
//! [`MIN_GAIN`] and stays physical, and falls back to the linear model otherwise
//! ([`JointChoice`], printed one line per joint).

use crate::data::Trajectory;
use crate::report::{ParamReport, ParamStatus};
use crate::Estimate;
use dyngen_model::joint_params::{Coulomb, PER_JOINT};
use dyngen_model::names::param_name;
use dyngen_reference::Dynamics;
use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use serde::{Deserialize, Serialize};
use std::fmt;

/// One joint's Stribeck parameters (the rest, `[Ia, Fv, Fc, F0]`, are the linear
/// model's): static friction `fs` (N·m or N) and Stribeck velocity `vs` (rad/s or
/// m/s, positive).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stribeck {
    pub fs: f64,
    pub vs: f64,
}

/// A Stribeck parameter that cannot describe a joint.
#[derive(Clone, Debug, PartialEq)]
pub enum StribeckError {
    /// `vs` must be positive and finite (joint numbered from 1).
    Velocity { joint: usize, vs: f64 },
    /// `fs` must be finite.
    StaticFriction { joint: usize, fs: f64 },
    /// One entry per joint is needed.
    Joints { expected: usize, found: usize },
}

impl fmt::Display for StribeckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Velocity { joint, vs } => {
                write!(
                    f,
                    "joint {joint}: the Stribeck velocity must be positive and finite, got {vs}"
                )
            }
            Self::StaticFriction { joint, fs } => {
                write!(f, "joint {joint}: the static friction must be finite, got {fs}")
            }
            Self::Joints { expected, found } => {
                write!(f, "{found} Stribeck parameter sets for {expected} joints")
            }
        }
    }
}

impl std::error::Error for StribeckError {}

/// Checks one set per joint, each with a finite `fs` and a positive, finite `vs`.
pub fn check(stribeck: &[Stribeck], joints: usize) -> Result<(), StribeckError> {
    if stribeck.len() != joints {
        return Err(StribeckError::Joints {
            expected: joints,
            found: stribeck.len(),
        });
    }
    for (j, s) in stribeck.iter().enumerate() {
        if !(s.vs.is_finite() && s.vs > 0.0) {
            return Err(StribeckError::Velocity { joint: j + 1, vs: s.vs });
        }
        if !s.fs.is_finite() {
            return Err(StribeckError::StaticFriction { joint: j + 1, fs: s.fs });
        }
    }
    Ok(())
}

/// `exp(−(v/vs)²)`: 1 at rest, 0 well above `vs`.
pub fn stribeck_factor(v: f64, vs: f64) -> f64 {
    (-(v / vs).powi(2)).exp()
}

/// What the Stribeck model adds to the linear model's `Fc·s(q̇)` at velocity `v`:
/// `(Fs − Fc)·exp(−(v/vs)²)·s(v)`.
pub fn excess_torque(fc: f64, stribeck: Stribeck, v: f64, coulomb: Coulomb) -> f64 {
    (stribeck.fs - fc) * stribeck_factor(v, stribeck.vs) * coulomb.eval(v)
}

/// Every joint's [`excess_torque`] added to `tau` (`n`), with the linear joint
/// parameters `joint_params` (`4n`, `[Ia, Fv, Fc, F0]` per joint) giving `Fc`.
pub fn add_excess(tau: &mut [f64], v: &[f64], joint_params: &[f64], stribeck: &[Stribeck], coulomb: Coulomb) {
    for (j, (t, s)) in tau.iter_mut().zip(stribeck).enumerate() {
        *t += excess_torque(joint_params[PER_JOINT * j + 2], *s, v[j], coulomb);
    }
}

/// Iteration limits of [`fit_joint`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LmOptions {
    /// Levenberg–Marquardt iterations (accepted or rejected steps), at most.
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this fraction.
    pub tolerance: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 200,
            tolerance: 1e-12,
        }
    }
}

/// One joint's Stribeck fit: `[Ia, Fv, Fc, F0]`, `Fs`, `vs`, and how it went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointFit {
    pub linear: [f64; PER_JOINT],
    pub stribeck: Stribeck,
    /// Standard deviations of `Fs` and `vs` from the Gauss–Newton curvature `JᵀJ`
    /// of the joint's residual at the solution (`σ² = cost / (rows − fitted)`), the
    /// rigid bodies taken as known; `None` where not determined.
    pub sigma: [Option<f64>; 2],
    /// Sum of squared residuals at the start and at the end.
    pub initial_cost: f64,
    pub cost: f64,
    pub iterations: usize,
}

/// What the joint terms of a fit may do: which of `[Ia, Fv, Fc, F0]` are fitted
/// (the others are held at 0: left out of the model), and whether `Ia`, `Fv` and
/// `Fc` are held `≥ 0` (the physically consistent estimator). The static friction
/// is always held `Fs ≥ 0`, and `vs` within its [`velocity_range`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointConstraints {
    pub fitted: [bool; PER_JOINT],
    pub nonnegative: bool,
}

impl Default for JointConstraints {
    fn default() -> Self {
        JointConstraints {
            fitted: [true; PER_JOINT],
            nonnegative: false,
        }
    }
}

impl JointConstraints {
    /// Per entry of `[Ia, Fv, Fc, Fs, F0, ln vs]`: held fixed.
    fn fixed(&self) -> [bool; 6] {
        let f = self.fitted;
        [!f[0], !f[1], !f[2], false, !f[3], false]
    }

    /// Per entry of `[Ia, Fv, Fc, Fs, F0]`: held `≥ 0`.
    fn bounded(&self) -> [bool; 5] {
        let nn = self.nonnegative;
        [nn, nn, nn, true, false]
    }

    /// `p` moved into the constraints, `ln vs` into `[u_lo, u_hi]`.
    fn project(&self, p: &mut SVector<f64, 6>, (u_lo, u_hi): (f64, f64)) {
        for (i, (fixed, bounded)) in self.fixed().iter().zip(self.bounded()).enumerate() {
            if *fixed {
                p[i] = 0.0;
            } else if bounded {
                p[i] = p[i].max(0.0);
            }
        }
        p[5] = p[5].clamp(u_lo, u_hi);
    }
}

/// `vs` is searched no lower than this fraction of the joint's speed range.
pub const VS_LOW: f64 = 0.005;
/// `vs` is searched no higher than this fraction of the joint's speed range.
pub const VS_HIGH: f64 = 0.5;
/// At least this fraction of the joint's samples must be slower than `vs`.
pub const VS_SLOWEST: f64 = 0.01;
/// The joint's speed range is this quantile of its `|q̇|` (a spike does not move it).
pub const SPEED_QUANTILE: f64 = 0.99;

/// The range `[lo, hi]` in which `vs` is searched for a joint with velocities `v`,
/// from the data: with `v_r` the joint's speed range (the [`SPEED_QUANTILE`]
/// quantile of `|q̇|`), `hi = VS_HIGH·v_r` (above it the term is a second Coulomb
/// friction over most of the motion, not a static friction) and `lo` the larger of
/// `VS_LOW·v_r` and the speed below which [`VS_SLOWEST`] of the samples lie (below
/// it the term acts on a handful of samples around the velocity reversals and fits
/// their noise). `None` for a joint that does not move, or whose slowest samples are
/// already faster than `hi` (it never comes near rest: the data say nothing about
/// its static friction).
pub fn velocity_range(v: &[f64]) -> Option<(f64, f64)> {
    let mut speed: Vec<f64> = v.iter().map(|x| x.abs()).filter(|x| x.is_finite()).collect();
    if speed.len() < 2 {
        return None;
    }
    speed.sort_unstable_by(f64::total_cmp);
    let quantile = |q: f64| speed[((speed.len() - 1) as f64 * q).round() as usize];
    let range = quantile(SPEED_QUANTILE);
    if !(range > 0.0 && range.is_finite()) {
        return None;
    }
    let (lo, hi) = ((VS_LOW * range).max(quantile(VS_SLOWEST)), VS_HIGH * range);
    (lo > 0.0 && lo < hi).then_some((lo, hi))
}

/// One joint's `[Ia, Fv, Fc, Fs, F0]` and `vs` fitted by Levenberg–Marquardt to
/// `target` (the joint's torque without its rigid-body part) at velocities `v` and
/// accelerations `a`, from `start` (`[Ia, Fv, Fc, F0]`, Stribeck), within
/// `constraints` (projected after every step) and with `vs` in `range` ([`velocity_range`];
/// searched as `ln vs`). Only steps that lower the sum of squared residuals are
/// taken, so the result is never worse than the (projected) start. `starts` gives
/// other values of `vs` to try first (each a linear fit of the other five
/// parameters within the constraints); the best of them replaces the start when it
/// is better.
#[allow(clippy::too_many_arguments)]
pub fn fit_joint(
    v: &[f64],
    a: &[f64],
    target: &[f64],
    start: ([f64; PER_JOINT], Stribeck),
    coulomb: Coulomb,
    range: (f64, f64),
    constraints: JointConstraints,
    starts: Starts,
    options: &LmOptions,
) -> JointFit {
    let (lo, hi) = range;
    let (u_lo, u_hi) = (lo.ln(), hi.ln());
    let (linear, s) = start;
    let mut p = SVector::<f64, 6>::from([linear[0], linear[1], linear[2], s.fs, linear[3], s.vs.ln()]);
    let free = constraints.fixed().iter().filter(|f| !**f).count();
    let out =
        |p: &SVector<f64, 6>, initial_cost: f64, cost: f64, iterations: usize, sigma: [Option<f64>; 2]| JointFit {
            linear: [p[0], p[1], p[2], p[4]],
            stribeck: Stribeck {
                fs: p[3],
                vs: p[5].exp(),
            },
            sigma,
            initial_cost,
            cost,
            iterations,
        };
    // Too few samples, or a range that is not one, say nothing about vs.
    if !(lo > 0.0 && lo < hi && hi.is_finite()) || v.len() <= free + 1 {
        let cost = joint_cost(v, a, target, &p, coulomb);
        return JointFit {
            stribeck: s,
            ..out(&p, cost, cost, 0, [None, None])
        };
    }
    constraints.project(&mut p, (u_lo, u_hi));
    let mut cost = joint_cost(v, a, target, &p, coulomb);
    let initial_cost = cost;
    let candidates: Vec<f64> = match starts {
        Starts::None => Vec::new(),
        Starts::Grid => (0..=GRID)
            .map(|k| lo * (hi / lo).powf(k as f64 / GRID as f64))
            .collect(),
    };
    for vs in candidates {
        if let Some(q) = linear_at(v, a, target, vs, coulomb, constraints) {
            let c = joint_cost(v, a, target, &q, coulomb);
            if c < cost {
                (p, cost) = (q, c);
            }
        }
    }
    let mut lambda = 1e-3;
    let mut iterations = 0;
    let fixed = constraints.fixed();
    while iterations < options.max_iterations {
        iterations += 1;
        let (h, g) = normal_equations(v, a, target, &p, coulomb, fixed);
        let scale = h.diagonal().max().max(f64::MIN_POSITIVE);
        let mut damped = h;
        for i in 0..6 {
            damped[(i, i)] += lambda * h[(i, i)].max(1e-12 * scale);
        }
        let Some(step) = damped.cholesky().map(|c| c.solve(&g)) else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
            continue;
        };
        let mut trial = p + step;
        constraints.project(&mut trial, (u_lo, u_hi));
        let c = joint_cost(v, a, target, &trial, coulomb);
        if c < cost {
            let gain = (cost - c) / cost.max(f64::MIN_POSITIVE);
            (p, cost) = (trial, c);
            lambda = (lambda / 10.0).max(1e-12);
            if gain < options.tolerance {
                break;
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
    }
    // σ of Fs and vs = vs·σ(ln vs) from σ²·(JᵀJ)⁻¹ over the fitted entries,
    // σ² = cost / (rows − fitted).
    let (h, _) = normal_equations(v, a, target, &p, coulomb, fixed);
    let dof = (v.len() - free) as f64;
    let sigma = match h.try_inverse() {
        Some(inv) if inv[(3, 3)] >= 0.0 && inv[(5, 5)] >= 0.0 => {
            let s2 = cost / dof;
            let finite = |x: f64| x.is_finite().then_some(x);
            [
                finite((s2 * inv[(3, 3)]).sqrt()),
                finite(p[5].exp() * (s2 * inv[(5, 5)]).sqrt()),
            ]
        }
        _ => [None, None],
    };
    out(&p, initial_cost, cost, iterations, sigma)
}

/// Values of `vs` [`fit_joint`] tries before its Levenberg–Marquardt iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Starts {
    /// Only the start.
    None,
    /// A grid of 17 log-spaced values over the range.
    Grid,
}

/// Points of the `vs` grid in [`fit_joint`], minus one (log-spaced over the range).
const GRID: usize = 16;

/// The model `[a, v, s(1−g), s·g, 1]·[Ia, Fv, Fc, Fs, F0]` with `g` the Stribeck
/// factor of `vs = exp(p[5])`, and its derivative along `ln vs`.
fn model(v: f64, a: f64, p: &SVector<f64, 6>, coulomb: Coulomb) -> (f64, [f64; 6]) {
    let vs = p[5].exp();
    let s = coulomb.eval(v);
    let g = stribeck_factor(v, vs);
    let row = [
        a,
        v,
        s * (1.0 - g),
        s * g,
        1.0,
        (p[3] - p[2]) * s * 2.0 * g * (v / vs).powi(2),
    ];
    let m = row[..5].iter().zip(p.iter()).map(|(r, x)| r * x).sum();
    (m, row)
}

fn joint_cost(v: &[f64], a: &[f64], target: &[f64], p: &SVector<f64, 6>, coulomb: Coulomb) -> f64 {
    (0..v.len())
        .map(|k| (target[k] - model(v[k], a[k], p, coulomb).0).powi(2))
        .sum()
}

/// `JᵀJ` and `Jᵀr` of the residual `target − model` at `p`, with the `fixed`
/// entries' rows and columns replaced by the identity (no step along them).
fn normal_equations(
    v: &[f64],
    a: &[f64],
    target: &[f64],
    p: &SVector<f64, 6>,
    coulomb: Coulomb,
    fixed: [bool; 6],
) -> (SMatrix<f64, 6, 6>, SVector<f64, 6>) {
    let mut h = SMatrix::<f64, 6, 6>::zeros();
    let mut g = SVector::<f64, 6>::zeros();
    for k in 0..v.len() {
        let (m, mut row) = model(v[k], a[k], p, coulomb);
        for (r, f) in row.iter_mut().zip(fixed) {
            if f {
                *r = 0.0;
            }
        }
        let r = target[k] - m;
        for i in 0..6 {
            g[i] += row[i] * r;
            for j in i..6 {
                h[(i, j)] += row[i] * row[j];
            }
        }
    }
    for i in 0..6 {
        if fixed[i] {
            h[(i, i)] = 1.0;
        }
        for j in 0..i {
            h[(i, j)] = h[(j, i)];
        }
    }
    (h, g)
}

/// The least-squares solution of the normal equations `h x = g` with the `fixed`
/// entries at 0 and the `bounded` ones `≥ 0`: an active set (each round fixes the
/// most negative bounded entry at 0 and solves again; minimum norm where the free
/// columns are dependent). `None` if not finite.
fn bounded_solve<const M: usize>(
    h: &SMatrix<f64, M, M>,
    g: &SVector<f64, M>,
    mut fixed: [bool; M],
    bounded: [bool; M],
) -> Option<SVector<f64, M>> {
    loop {
        let (mut hf, mut gf) = (*h, *g);
        for i in (0..M).filter(|&i| fixed[i]) {
            for j in 0..M {
                hf[(i, j)] = 0.0;
                hf[(j, i)] = 0.0;
            }
            gf[i] = 0.0;
        }
        let eps = 1e-12 * hf.diagonal().max();
        let (hd, gd) = (
            DMatrix::from_column_slice(M, M, hf.as_slice()),
            DVector::from_column_slice(gf.as_slice()),
        );
        let x = SVector::<f64, M>::from_column_slice(hd.svd(true, true).solve(&gd, eps).ok()?.as_slice());
        if !x.iter().all(|x| x.is_finite()) {
            return None;
        }
        let worst = (0..M)
            .filter(|&i| bounded[i] && !fixed[i] && x[i] < 0.0)
            .min_by(|&i, &j| x[i].total_cmp(&x[j]));
        match worst {
            Some(i) => fixed[i] = true,
            None => return Some(x),
        }
    }
}

/// The best `[Ia, Fv, Fc, Fs, F0]` for a fixed `vs` within `constraints` (a linear
/// least-squares fit, [`bounded_solve`]), with `ln vs` as sixth entry.
fn linear_at(
    v: &[f64],
    a: &[f64],
    target: &[f64],
    vs: f64,
    coulomb: Coulomb,
    constraints: JointConstraints,
) -> Option<SVector<f64, 6>> {
    let probe = SVector::<f64, 6>::from([0.0, 0.0, 0.0, 0.0, 0.0, vs.ln()]);
    let mut h = SMatrix::<f64, 5, 5>::zeros();
    let mut g = SVector::<f64, 5>::zeros();
    for k in 0..v.len() {
        let (_, row) = model(v[k], a[k], &probe, coulomb);
        for i in 0..5 {
            g[i] += row[i] * target[k];
            for j in 0..5 {
                h[(i, j)] += row[i] * row[j];
            }
        }
    }
    let fixed = constraints.fixed();
    let x = bounded_solve(
        &h,
        &g,
        [fixed[0], fixed[1], fixed[2], fixed[3], fixed[4]],
        constraints.bounded(),
    )?;
    Some(SVector::<f64, 6>::from([x[0], x[1], x[2], x[3], x[4], vs.ln()]))
}

/// The linear model `[Ia, Fv, Fc, F0]` of one joint fitted to `target` within
/// `constraints` (`Fc·s(q̇)`, no Stribeck term).
fn linear_joint(v: &[f64], a: &[f64], target: &[f64], coulomb: Coulomb, c: JointConstraints) -> Option<[f64; 4]> {
    let mut h = SMatrix::<f64, 4, 4>::zeros();
    let mut g = SVector::<f64, 4>::zeros();
    for k in 0..v.len() {
        let row = [a[k], v[k], coulomb.eval(v[k]), 1.0];
        for i in 0..4 {
            g[i] += row[i] * target[k];
            for j in 0..4 {
                h[(i, j)] += row[i] * row[j];
            }
        }
    }
    let nn = c.nonnegative;
    let f = c.fitted;
    let x = bounded_solve(&h, &g, [!f[0], !f[1], !f[2], !f[3]], [nn, nn, nn, false])?;
    Some([x[0], x[1], x[2], x[3]])
}

/// The time blocks of `held_out`: each is scored with the models fitted on the others.
pub const BLOCKS: usize = 4;

/// A Stribeck term is kept only if it lowers the joint's held-out sum of squares by
/// at least this fraction: two more parameters must earn their place.
pub const MIN_GAIN: f64 = 0.01;

/// One joint's held-out sums of squared residuals `[sign, Stribeck]`: its samples
/// cut into [`BLOCKS`] contiguous time blocks, each scored with the linear model
/// and with the Stribeck model ([`fit_joint`] from a grid) fitted on the other
/// blocks. Deterministic. `None` with too few samples per block.
fn held_out(
    v: &[f64],
    a: &[f64],
    target: &[f64],
    coulomb: Coulomb,
    range: (f64, f64),
    constraints: JointConstraints,
) -> Option<[f64; 2]> {
    let len = v.len();
    if len < 20 * BLOCKS {
        return None;
    }
    let mut sse = [0.0; 2];
    for b in 0..BLOCKS {
        let (from, to) = (b * len / BLOCKS, (b + 1) * len / BLOCKS);
        let train = |x: &[f64]| -> Vec<f64> { x[..from].iter().chain(&x[to..]).copied().collect() };
        let (tv, ta, tt) = (train(v), train(a), train(target));
        let sign = linear_joint(&tv, &ta, &tt, coulomb, constraints)?;
        let fit = fit_joint(
            &tv,
            &ta,
            &tt,
            (
                sign,
                Stribeck {
                    fs: sign[2].max(0.0),
                    vs: (range.0 * range.1).sqrt(),
                },
            ),
            coulomb,
            range,
            constraints,
            Starts::Grid,
            &ROUND_LM,
        );
        let as_p = |l: [f64; 4], s: Stribeck| SVector::<f64, 6>::from([l[0], l[1], l[2], s.fs, l[3], s.vs.ln()]);
        let (hv, ha, ht) = (&v[from..to], &a[from..to], &target[from..to]);
        sse[0] += joint_cost(hv, ha, ht, &as_p(sign, Stribeck { fs: sign[2], vs: 1.0 }), coulomb);
        sse[1] += joint_cost(hv, ha, ht, &as_p(fit.linear, fit.stribeck), coulomb);
    }
    sse.iter().all(|x| x.is_finite()).then_some(sse)
}

/// Rounds of [`refine`], at most.
pub const MAX_ROUNDS: usize = 20;

/// [`refine`] stops when a round lowers the cost by less than this fraction.
pub const REFINE_TOLERANCE: f64 = 1e-5;

/// Why a joint keeps its Stribeck term or falls back to the linear model.
#[derive(Clone, Debug, PartialEq)]
pub struct JointChoice {
    /// The Stribeck term is kept; otherwise the joint's friction is the linear
    /// model's (`Fs = Fc`, no effect).
    pub kept: bool,
    /// The range `vs` was searched in ([`velocity_range`]).
    pub range: Option<(f64, f64)>,
    /// Held-out RMS torque residual `[sign, Stribeck]` of the joint ([`BLOCKS`]
    /// time blocks, each predicted by the models fitted on the others).
    pub held_out: Option<[f64; 2]>,
    /// Why, in words.
    pub reason: String,
}

impl JointChoice {
    fn sign(range: Option<(f64, f64)>, held_out: Option<[f64; 2]>, reason: impl Into<String>) -> Self {
        JointChoice {
            kept: false,
            range,
            held_out,
            reason: reason.into(),
        }
    }
}

impl JointChoice {
    /// `Stribeck kept: why` or `{fallback} kept: why` (the linear model's Coulomb
    /// term, `sign` or `tanh`), with the held-out errors and the range of `vs`.
    pub fn line(&self, fallback: &str) -> String {
        let held_out = self.held_out.map_or_else(String::new, |[sign, stribeck]| {
            format!(
                "held-out residual RMS {stribeck:.4e} with it against {sign:.4e} without ({:+.1} %)",
                100.0 * (stribeck / sign - 1.0)
            )
        });
        let range = self
            .range
            .map_or_else(String::new, |(lo, hi)| format!("vs searched in [{lo:.3e}, {hi:.3e}]"));
        let mut text = if self.kept {
            "Stribeck kept: ".to_string()
        } else {
            format!("{fallback} kept: ")
        };
        text.push_str(&self.reason);
        for part in [held_out, range] {
            if !part.is_empty() && !self.reason.contains(&part) {
                text.push_str("; ");
                text.push_str(&part);
            }
        }
        text
    }
}

impl fmt::Display for JointChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.line("sign"))
    }
}

/// What [`refine`] found: per joint the Stribeck parameters and their fits, and the
/// sum of squared torque residuals (all joints, N²·m²) of the linear start and of
/// the result.
#[derive(Clone, Debug, PartialEq)]
pub struct StribeckFit {
    pub coulomb: Coulomb,
    /// Per joint `Fs` and `vs`; a joint that fell back to the linear model has
    /// `Fs = Fc` (no effect, whatever `vs`).
    pub joints: Vec<Stribeck>,
    /// Per joint, the Coulomb friction `Fc` of the final linear fit.
    pub fc: Vec<f64>,
    /// Per joint, σ of `Fs` and `vs` (see [`JointFit::sigma`]); `None` for a
    /// joint without the term.
    pub sigma: Vec<[Option<f64>; 2]>,
    /// Per joint, whether the term is kept and why.
    pub choices: Vec<JointChoice>,
    /// Per joint, Levenberg–Marquardt iterations over all rounds.
    pub iterations: Vec<usize>,
    /// Alternating rounds run (each: the joints' nonlinear fits, then one linear fit).
    pub rounds: usize,
    pub initial_cost: f64,
    pub cost: f64,
    /// Torque rows (samples × joints) the costs sum over.
    pub rows: usize,
}

impl StribeckFit {
    /// RMS torque residual of the linear start and of the result.
    pub fn rms(&self) -> (f64, f64) {
        let rows = self.rows.max(1) as f64;
        ((self.initial_cost / rows).sqrt(), (self.cost / rows).sqrt())
    }

    /// `Fs1, vs1, Fs2, vs2, …` for the parameter report: identified with their σ,
    /// or `excluded` (no value) for a joint that fell back to the linear model.
    pub fn param_reports(&self) -> Vec<ParamReport> {
        let mut out = Vec::with_capacity(2 * self.joints.len());
        for (j, (s, sigma)) in self.joints.iter().zip(&self.sigma).enumerate() {
            let kept = self.choices.get(j).is_some_and(|c| c.kept);
            for (name, value, sigma) in [("Fs", s.fs, sigma[0]), ("vs", s.vs, sigma[1])] {
                let sigma = sigma.filter(|_| kept);
                out.push(ParamReport {
                    name: param_name(name, j + 1),
                    value: kept.then_some(value),
                    sigma,
                    sigma_percent: sigma.filter(|_| value != 0.0).map(|s| 100.0 * s / value.abs()),
                    status: if kept {
                        ParamStatus::Identified
                    } else {
                        ParamStatus::Excluded
                    },
                });
            }
        }
        out
    }
}

impl fmt::Display for StribeckFit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (before, after) = self.rms();
        writeln!(
            f,
            "Stribeck friction (Fs at rest falling to Fc above vs): {} rounds, torque residual RMS {before:.4e} → \
             {after:.4e}",
            self.rounds
        )?;
        writeln!(
            f,
            "joint          Fc            Fs        σ(Fs)            vs        σ(vs)  LM iterations"
        )?;
        let cell = |x: Option<f64>| x.map_or_else(|| format!("{:>12}", "—"), |x| format!("{x:>12.5}"));
        for (j, (s, sigma)) in self.joints.iter().zip(&self.sigma).enumerate() {
            let known = self.choices.get(j).is_some_and(|c| c.kept);
            writeln!(
                f,
                "{:>5} {:>11.5} {} {} {} {} {:>14}",
                j + 1,
                self.fc[j],
                cell(known.then_some(s.fs)),
                cell(sigma[0].filter(|_| known)),
                cell(known.then_some(s.vs)),
                cell(sigma[1].filter(|_| known)),
                self.iterations[j]
            )?;
        }
        let fallback = match self.coulomb {
            Coulomb::Sign => "sign",
            Coulomb::Smooth { .. } => "tanh",
        };
        for (j, choice) in self.choices.iter().enumerate() {
            writeln!(f, "joint {}: {}", j + 1, choice.line(fallback))?;
        }
        Ok(())
    }
}

/// The Stribeck model fitted from the linear fit `start` (whose solution is the
/// `10n` standard parameters then `[Ia, Fv, Fc, F0]` per joint, Coulomb term
/// `coulomb`, within `constraints`) of `traj`'s torques; `linear_fit` redoes that
/// linear fit on any trajectory (`traj`, a part of it, or either with the Stribeck
/// term taken out of the torques). Returns the final linear fit (its solution holds
/// the rigid-body parameters and `[Ia, Fv, Fc, F0]`; its residuals are those of the
/// whole model) and the Stribeck parameters. `traj` must have velocities and
/// accelerations.
///
/// Each joint first earns its term ([`JointChoice`]), with the rigid-body torques
/// of `start` held: its `vs` range must exist ([`velocity_range`]); the term must
/// lower the joint's held-out sum of squares by [`MIN_GAIN`] ([`BLOCKS`] time
/// blocks, each predicted by the models fitted on the others: a term that fits the
/// noise of a few velocity reversals does not predict the next ones); and fitted on
/// all the samples it must stay physical (`Fs ≥ 0` is a bound; `Fc` and `Fv` must
/// not turn negative) with a finite σ of `Fs` and `vs` and `σ(vs) < vs`. The
/// other joints keep the linear model (`Fs = Fc`).
///
/// The kept terms are then refined with the whole fit. A long recording is fitted
/// first on at most [`ROUND_SAMPLES`] samples spread over it (the rounds, each a
/// linear fit, are then cheap), and each joint's `Fs − Fc` and `vs` carried to
/// every sample by one linear fit with them held, kept only where it lowers the
/// cost over every sample (a round on the part, likewise, where it lowers the cost
/// there), so the fit is never worse than `start`. A joint whose refined term fails the physical check falls back, and the
/// refinement runs again without it.
pub fn refine<E>(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    coulomb: Coulomb,
    constraints: JointConstraints,
    start: Estimate,
    mut linear_fit: impl FnMut(&Trajectory) -> Result<Estimate, E>,
) -> Result<(Estimate, StribeckFit), E> {
    let n = dynamics.nv();
    let full = Columns::new(traj, n);
    let ranges: Vec<Option<(f64, f64)>> = (0..n).map(|j| velocity_range(&full.v[j])).collect();
    let (initial_cost, rigid) = total_cost(
        dynamics,
        traj,
        &start.solution,
        &no_effect(&start.solution, n, &ranges),
        coulomb,
    );
    // Which joints earn the term, on at most ROUND_SAMPLES samples spread over the
    // recording (in parallel).
    let stride = traj.len().div_ceil(ROUND_SAMPLES).max(1);
    let mut choices = crate::accumulate::in_parallel(n, |j| {
        let pick = |x: &[f64]| -> Vec<f64> { x.iter().step_by(stride).copied().collect() };
        let target: Vec<f64> = (0..traj.len())
            .step_by(stride)
            .map(|k| full.tau[j][k] - rigid[k * n + j])
            .collect();
        choose(
            &pick(&full.v[j]),
            &pick(&full.a[j]),
            &target,
            joint_linear(&start.solution, n, j),
            coulomb,
            ranges[j],
            constraints,
        )
    });
    loop {
        let allowed: Vec<bool> = choices.iter().map(|c| c.kept).collect();
        let (estimate, fit) = refine_allowed(
            dynamics,
            traj,
            coulomb,
            constraints,
            &start,
            &full,
            &ranges,
            &allowed,
            (initial_cost, &rigid),
            &mut linear_fit,
        )?;
        let mut dropped = false;
        for j in (0..n).filter(|&j| allowed[j]) {
            let linear = joint_linear(&estimate.solution, n, j);
            if let Some(why) = unphysical(&linear, fit.joints[j], fit.sigma[j], constraints) {
                choices[j] = JointChoice::sign(
                    choices[j].range,
                    choices[j].held_out,
                    format!("refined with the whole model, {why}"),
                );
                dropped = true;
            }
        }
        if !dropped {
            return Ok((estimate, StribeckFit { choices, ..fit }));
        }
    }
}

/// Whether joint terms `linear` with the Stribeck term `s` (σ `sigma`) are a
/// physical, determined fit; `Some(why)` if not.
fn unphysical(
    linear: &[f64; PER_JOINT],
    s: Stribeck,
    sigma: [Option<f64>; 2],
    constraints: JointConstraints,
) -> Option<String> {
    if s.fs < 0.0 {
        return Some(format!("its static friction Fs = {:.4e} is negative", s.fs));
    }
    for (k, name, what) in [(2, "Fc", "Coulomb"), (1, "Fv", "viscous")] {
        if constraints.fitted[k] && linear[k] < 0.0 {
            return Some(format!(
                "{name} = {:.4e} with it: a negative {what} friction is not physical",
                linear[k]
            ));
        }
    }
    match sigma {
        [Some(sf), Some(sv)] if sf.is_finite() && sv.is_finite() => {
            (sv >= s.vs).then(|| format!("vs = {:.4e} is not determined by the data (σ(vs) = {sv:.3e})", s.vs))
        }
        _ => Some("Fs and vs are not determined by the data (no finite σ)".into()),
    }
}

/// One joint's [`JointChoice`] from its velocities `v`, accelerations `a` and
/// torque `target` without its rigid-body part, from the linear terms `linear`.
fn choose(
    v: &[f64],
    a: &[f64],
    target: &[f64],
    linear: [f64; PER_JOINT],
    coulomb: Coulomb,
    range: Option<(f64, f64)>,
    constraints: JointConstraints,
) -> JointChoice {
    let Some(range) = range else {
        return JointChoice::sign(
            None,
            None,
            "the joint does not move, or never comes near rest: the data say nothing about static friction",
        );
    };
    let Some(sse) = held_out(v, a, target, coulomb, range, constraints) else {
        return JointChoice::sign(Some(range), None, "too few samples to test the term on held-out data");
    };
    let rms = sse.map(|x| (x / v.len() as f64).sqrt());
    if sse[1] >= (1.0 - MIN_GAIN) * sse[0] {
        return JointChoice::sign(
            Some(range),
            Some(rms),
            format!(
                "the Stribeck term does not lower the held-out error by {:.0} %",
                100.0 * MIN_GAIN
            ),
        );
    }
    let fit = fit_joint(
        v,
        a,
        target,
        (
            linear,
            Stribeck {
                fs: linear[2].max(0.0),
                vs: (range.0 * range.1).sqrt(),
            },
        ),
        coulomb,
        range,
        constraints,
        Starts::Grid,
        &ROUND_LM,
    );
    if let Some(why) = unphysical(&fit.linear, fit.stribeck, fit.sigma, constraints) {
        return JointChoice::sign(Some(range), Some(rms), format!("fitted on every sample, {why}"));
    }
    JointChoice {
        kept: true,
        range: Some(range),
        held_out: Some(rms),
        reason: "it lowers the held-out error".into(),
    }
}

/// Per joint a Stribeck term without effect (`Fs = Fc` of `x`), `vs` inside its range.
fn no_effect(x: &[f64], n: usize, ranges: &[Option<(f64, f64)>]) -> Vec<Stribeck> {
    (0..n)
        .map(|j| Stribeck {
            fs: joint_linear(x, n, j)[2],
            vs: ranges[j].map_or(1.0, |(lo, hi)| (lo * hi).sqrt()),
        })
        .collect()
}

/// [`refine`]'s rounds with the Stribeck term on the `allowed` joints only (the
/// others held at `Fs = Fc`); `initial` is the cost of `start` and its rigid-body
/// torques.
#[allow(clippy::too_many_arguments)]
fn refine_allowed<E>(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    coulomb: Coulomb,
    constraints: JointConstraints,
    start: &Estimate,
    full: &Columns,
    ranges: &[Option<(f64, f64)>],
    allowed: &[bool],
    initial: (f64, &[f64]),
    linear_fit: &mut impl FnMut(&Trajectory) -> Result<Estimate, E>,
) -> Result<(Estimate, StribeckFit), E> {
    let n = dynamics.nv();
    let (initial_cost, rigid) = initial;
    let mut state = State {
        estimate: start.clone(),
        stribeck: no_effect(&start.solution, n, ranges),
        sigma: vec![[None, None]; n],
        iterations: vec![0; n],
        rounds: 0,
        cost: initial_cost,
        rigid: rigid.to_vec(),
    };
    let setup = Setup {
        coulomb,
        constraints,
        ranges,
        allowed,
    };
    let stride = traj.len().div_ceil(ROUND_SAMPLES).max(1);
    if !allowed.iter().any(|&a| a) {
        // Nothing to refine: the linear fit as it is.
    } else if stride == 1 {
        state = rounds(dynamics, traj, full, &setup, state, MAX_ROUNDS, linear_fit)?;
    } else if let Some(part) = every(traj, stride) {
        let columns = Columns::new(&part, n);
        let estimate = linear_fit(&part)?;
        let (cost, rigid) = total_cost(dynamics, &part, &estimate.solution, &state.stribeck, coulomb);
        let found = rounds(
            dynamics,
            &part,
            &columns,
            &setup,
            State {
                estimate,
                cost,
                rigid,
                ..state.clone()
            },
            MAX_ROUNDS,
            linear_fit,
        )?;
        // Each joint's Fs − Fc and vs carried to every sample by one linear fit
        // with them held, kept if it lowers the cost there. The σ of Fs and vs,
        // from the part, scale as 1/√samples to every sample.
        let excess: Vec<f64> = (0..n)
            .map(|j| found.stribeck[j].fs - joint_linear(&found.estimate.solution, n, j)[2])
            .collect();
        if let Some((estimate, stribeck)) = relinearise(traj, full, coulomb, &excess, &found.stribeck, linear_fit)? {
            let (cost, rigid) = total_cost(dynamics, traj, &estimate.solution, &stribeck, coulomb);
            if cost < state.cost {
                let scale = (part.len() as f64 / traj.len() as f64).sqrt();
                state = State {
                    estimate,
                    stribeck,
                    sigma: found.sigma.iter().map(|s| s.map(|x| x.map(|x| x * scale))).collect(),
                    iterations: found.iterations,
                    rounds: found.rounds,
                    cost,
                    rigid,
                };
            }
        }
    }
    let fc = (0..n)
        .map(|j| joint_linear(&state.estimate.solution, n, j)[2])
        .collect();
    let sigma = state
        .sigma
        .iter()
        .zip(allowed)
        .map(|(s, &a)| if a { *s } else { [None, None] })
        .collect();
    Ok((
        state.estimate,
        StribeckFit {
            coulomb,
            joints: state.stribeck,
            fc,
            sigma,
            choices: Vec::new(),
            iterations: state.iterations,
            rounds: state.rounds,
            initial_cost,
            cost: state.cost,
            rows: traj.len() * n,
        },
    ))
}

/// What every round of [`refine`] works with besides the data.
struct Setup<'a> {
    coulomb: Coulomb,
    constraints: JointConstraints,
    ranges: &'a [Option<(f64, f64)>],
    allowed: &'a [bool],
}

/// Samples the rounds of [`refine`] run on, at most.
pub const ROUND_SAMPLES: usize = 20_000;

/// Where [`refine`] is: the linear fit, the Stribeck terms, and the cost with the
/// rigid-body torques it was computed with (row-major, samples × joints).
#[derive(Clone)]
struct State {
    estimate: Estimate,
    stribeck: Vec<Stribeck>,
    sigma: Vec<[Option<f64>; 2]>,
    iterations: Vec<usize>,
    rounds: usize,
    cost: f64,
    rigid: Vec<f64>,
}

/// A trajectory's velocities, accelerations and torques by joint.
struct Columns {
    v: Vec<Vec<f64>>,
    a: Vec<Vec<f64>>,
    tau: Vec<Vec<f64>>,
}

impl Columns {
    fn new(traj: &Trajectory, n: usize) -> Columns {
        let len = traj.len();
        let column = |data: Option<&[f64]>, j: usize| -> Vec<f64> {
            data.map_or_else(|| vec![0.0; len], |d| (0..len).map(|k| d[k * n + j]).collect())
        };
        Columns {
            v: (0..n).map(|j| column(traj.velocities(), j)).collect(),
            a: (0..n).map(|j| column(traj.accelerations(), j)).collect(),
            tau: (0..n).map(|j| column(Some(traj.torques()), j)).collect(),
        }
    }
}

/// `[Ia, Fv, Fc, F0]` of joint `j` of `n` in a solution of the bodies' parameters then
/// `4n` joint terms.
fn joint_linear(x: &[f64], n: usize, j: usize) -> [f64; PER_JOINT] {
    let at = x.len() - PER_JOINT * (n - j);
    [x[at], x[at + 1], x[at + 2], x[at + 3]]
}

/// Every `stride`-th sample of `traj`.
fn every(traj: &Trajectory, stride: usize) -> Option<Trajectory> {
    traj.select(|k| k % stride == 0).ok()
}

/// The linear fit of `traj` with each joint's Stribeck term `excess[j]·g(q̇; vs)·s(q̇)`
/// (`vs` from `stribeck`) taken out of the torques, and the Stribeck terms with
/// `Fs = Fc + excess` for its `Fc`. `None` if the torques cannot be replaced.
fn relinearise<E>(
    traj: &Trajectory,
    columns: &Columns,
    coulomb: Coulomb,
    excess: &[f64],
    stribeck: &[Stribeck],
    linear_fit: &mut impl FnMut(&Trajectory) -> Result<Estimate, E>,
) -> Result<Option<(Estimate, Vec<Stribeck>)>, E> {
    let n = traj.dof();
    let mut without = traj.torques().to_vec();
    for (k, row) in without.chunks_exact_mut(n).enumerate() {
        for j in 0..n {
            let v = columns.v[j][k];
            row[j] -= excess[j] * stribeck_factor(v, stribeck[j].vs) * coulomb.eval(v);
        }
    }
    let Ok(shifted) = traj.clone().with_torques(without) else {
        return Ok(None);
    };
    let estimate = linear_fit(&shifted)?;
    let moved = (0..n)
        .map(|j| Stribeck {
            fs: joint_linear(&estimate.solution, n, j)[2] + excess[j],
            vs: stribeck[j].vs,
        })
        .collect();
    Ok(Some((estimate, moved)))
}

/// Up to `max` alternating rounds from `state`, each accepted only if it lowers the
/// cost: (1) every joint's Levenberg–Marquardt fit with the rigid-body torques held
/// (from a grid of `vs` in the first round), (2) the linear fit with each
/// joint's `Fs − Fc` and `vs` held.
#[allow(clippy::too_many_arguments)]
fn rounds<E>(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    columns: &Columns,
    setup: &Setup<'_>,
    mut state: State,
    max: usize,
    linear_fit: &mut impl FnMut(&Trajectory) -> Result<Estimate, E>,
) -> Result<State, E> {
    let n = dynamics.nv();
    let len = traj.len();
    let coulomb = setup.coulomb;
    for round in 0..max {
        let before = state.cost;
        // (1) Every joint with the term on its own (in parallel), the rigid-body
        // torques held; the others as they are, without it.
        let fits = crate::accumulate::in_parallel(n, |j| {
            let target: Vec<f64> = (0..len).map(|k| columns.tau[j][k] - state.rigid[k * n + j]).collect();
            let linear = joint_linear(&state.estimate.solution, n, j);
            match (setup.allowed[j], setup.ranges[j]) {
                (true, Some(range)) => fit_joint(
                    &columns.v[j],
                    &columns.a[j],
                    &target,
                    (linear, state.stribeck[j]),
                    coulomb,
                    range,
                    setup.constraints,
                    if round == 0 { Starts::Grid } else { Starts::None },
                    &ROUND_LM,
                ),
                _ => {
                    let s = Stribeck {
                        fs: linear[2],
                        vs: state.stribeck[j].vs,
                    };
                    let p = SVector::<f64, 6>::from([linear[0], linear[1], linear[2], s.fs, linear[3], s.vs.ln()]);
                    let cost = joint_cost(&columns.v[j], &columns.a[j], &target, &p, coulomb);
                    JointFit {
                        linear,
                        stribeck: s,
                        sigma: [None, None],
                        initial_cost: cost,
                        cost,
                        iterations: 0,
                    }
                }
            }
        });
        for (count, f) in state.iterations.iter_mut().zip(&fits) {
            *count += f.iterations;
        }
        let lm_cost: f64 = fits.iter().map(|f| f.cost).sum();
        if lm_cost.is_nan() || lm_cost >= state.cost {
            break;
        }
        // (2) The whole linear fit with each joint's Fs − Fc and vs held: Fc moves,
        // and Fs with it.
        let excess: Vec<f64> = fits.iter().map(|f| f.stribeck.fs - f.linear[2]).collect();
        let trial: Vec<Stribeck> = fits.iter().map(|f| f.stribeck).collect();
        let Some((estimate, stribeck)) = relinearise(traj, columns, coulomb, &excess, &trial, linear_fit)? else {
            break;
        };
        let (cost, rigid) = total_cost(dynamics, traj, &estimate.solution, &stribeck, coulomb);
        if cost.is_nan() || cost >= state.cost {
            break;
        }
        state = State {
            estimate,
            stribeck,
            sigma: fits.iter().map(|f| f.sigma).collect(),
            iterations: state.iterations,
            rounds: state.rounds + 1,
            cost,
            rigid,
        };
        if before - cost < REFINE_TOLERANCE * before {
            break;
        }
    }
    Ok(state)
}

/// The Levenberg–Marquardt limits of one round of [`refine`].
const ROUND_LM: LmOptions = LmOptions {
    max_iterations: 100,
    tolerance: 1e-10,
};

/// `rnea(q, v, a)` with the standard parameters `params` at every sample
/// (row-major, `len × n`): the regressor times `params`, without forming it.
fn rigid_torques(dynamics: &dyn Dynamics, traj: &Trajectory, params: &[f64]) -> Vec<f64> {
    let n = dynamics.nv();
    let mut out = vec![0.0; traj.len() * n];
    for (k, tau) in out.chunks_exact_mut(n).enumerate() {
        let (q, v, a) = (traj.q(k), traj.v(k).unwrap_or(&[]), traj.a(k).unwrap_or(&[]));
        dynamics.rnea(q, v, a, params, tau);
    }
    out
}

/// The sum of squared torque residuals of the whole model (rigid bodies' parameters
/// `x[..10 bodies]`, linear joint terms after them, the Stribeck terms), and the rigid-body
/// torques (row-major, samples × joints).
fn total_cost(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    x: &[f64],
    stribeck: &[Stribeck],
    coulomb: Coulomb,
) -> (f64, Vec<f64>) {
    let n = dynamics.nv();
    let (bodies, joints) = x.split_at(dynamics.nparams());
    let rigid = rigid_torques(dynamics, traj, bodies);
    let mut cost = 0.0;
    for k in 0..traj.len() {
        let (v, a, tau) = (traj.v(k).unwrap_or(&[]), traj.a(k).unwrap_or(&[]), traj.tau(k));
        for j in 0..n {
            let p: &[f64; PER_JOINT] = joints[PER_JOINT * j..PER_JOINT * (j + 1)]
                .try_into()
                .expect("4 joint parameters per joint");
            let predicted = rigid[k * n + j]
                + dyngen_model::joint_params::joint_torque(p, v[j], a[j], coulomb)
                + excess_torque(p[2], stribeck[j], v[j], coulomb);
            cost += (tau[j] - predicted).powi(2);
        }
    }
    (cost, rigid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_model::sample::SplitMix64;

    /// One joint's friction torque with noise, along a slow sine sweep.
    fn joint_data(truth: ([f64; 4], Stribeck), noise: f64, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let mut rng = SplitMix64::new(seed);
        let (mut v, mut a, mut tau) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..20_000 {
            let t = k as f64 * 1e-3;
            let (vk, ak) = (
                0.8 * (0.7 * t).sin() + 0.2 * (2.3 * t).cos(),
                0.56 * (0.7 * t).cos() - 0.46 * (2.3 * t).sin(),
            );
            let [ia, fv, fc, f0] = truth.0;
            let clean = ia * ak + fv * vk + fc * vk.signum() + f0 + excess_torque(fc, truth.1, vk, Coulomb::Sign);
            v.push(vk);
            a.push(ak);
            tau.push(clean + noise * rng.uniform(-1.0, 1.0));
        }
        (v, a, tau)
    }

    #[test]
    fn recovers_a_joint_from_the_linear_start() {
        let truth = ([0.3, 2.0, 4.0, 0.1], Stribeck { fs: 6.0, vs: 0.05 });
        let (v, a, tau) = joint_data(truth, 0.02, 3);
        let start = ([0.0, 0.0, 0.0, 0.0], Stribeck { fs: 0.0, vs: 0.08 });
        let range = velocity_range(&v).unwrap();
        let c = JointConstraints::default();
        let fit = fit_joint(
            &v,
            &a,
            &tau,
            start,
            Coulomb::Sign,
            range,
            c,
            Starts::Grid,
            &LmOptions::default(),
        );
        assert!(fit.cost < fit.initial_cost);
        assert!((fit.stribeck.fs / 6.0 - 1.0).abs() < 0.01, "{fit:?}");
        assert!((fit.stribeck.vs / 0.05 - 1.0).abs() < 0.02, "{fit:?}");
        for (x, t) in fit.linear.iter().zip(truth.0) {
            assert!((x - t).abs() < 0.01 * (1.0 + t.abs()), "{fit:?}");
        }
        let [sf, sv] = fit.sigma;
        assert!(
            sf.is_some_and(|s| s > 0.0 && s < 0.05) && sv.is_some_and(|s| s > 0.0 && s < 1e-3),
            "{fit:?}"
        );
    }

    #[test]
    fn never_worse_than_the_start_and_vs_stays_in_bounds() {
        // No Stribeck effect at all: Fs stays near Fc, the cost does not grow.
        let truth = ([0.0, 1.0, 2.0, 0.0], Stribeck { fs: 2.0, vs: 0.1 });
        let (v, a, tau) = joint_data(truth, 0.05, 5);
        let start = (truth.0, truth.1);
        let range = velocity_range(&v).unwrap();
        let c = JointConstraints::default();
        let fit = fit_joint(
            &v,
            &a,
            &tau,
            start,
            Coulomb::Sign,
            range,
            c,
            Starts::Grid,
            &LmOptions::default(),
        );
        assert!(fit.cost <= fit.initial_cost);
        let (lo, hi) = range;
        assert!(
            fit.stribeck.vs >= lo * (1.0 - 1e-12) && fit.stribeck.vs <= hi * (1.0 + 1e-12),
            "{fit:?}"
        );
        assert!(fit.stribeck.fs.is_finite());
        // A joint that never moves has no range for vs.
        assert_eq!(velocity_range(&[0.0; 10]), None);
    }

    /// 60 s at 100 Hz of one joint sweeping back and forth (velocity reversals every
    /// few seconds) with friction `truth`, noise of `noise` and, at every reversal
    /// of the first 15 s, a burst of `spike` N·m with the sign of the velocity (a
    /// glitch the later reversals do not repeat).
    fn sweeps(truth: ([f64; 4], Stribeck), noise: f64, spike: f64, seed: u64) -> [Vec<f64>; 3] {
        let mut rng = SplitMix64::new(seed);
        let (mut v, mut a, mut tau) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..6000 {
            let t = k as f64 * 0.01;
            let (vk, ak) = (
                0.5 * (0.9 * t).sin() + 0.15 * (2.1 * t).cos(),
                0.45 * (0.9 * t).cos() - 0.315 * (2.1 * t).sin(),
            );
            let [ia, fv, fc, f0] = truth.0;
            let mut x = ia * ak + fv * vk + fc * vk.signum() + f0 + excess_torque(fc, truth.1, vk, Coulomb::Sign);
            x += noise * rng.uniform(-1.0, 1.0);
            if k < 1500 && vk.abs() < 2e-3 {
                x += spike * vk.signum();
            }
            v.push(vk);
            a.push(ak);
            tau.push(x);
        }
        [v, a, tau]
    }

    fn choice(data: &[Vec<f64>; 3], linear: [f64; 4]) -> JointChoice {
        let [v, a, tau] = data;
        let range = velocity_range(v);
        let c = choose(v, a, tau, linear, Coulomb::Sign, range, JointConstraints::default());
        println!("{c}");
        c
    }

    #[test]
    fn the_velocity_range_comes_from_the_data() {
        // A sine of amplitude 2: the 99 % quantile of |v| is about 2, and 1 % of the
        // samples are slower than 2·sin(π/2·0.01) ≈ 0.031.
        let v: Vec<f64> = (0..10_000).map(|k| 2.0 * (k as f64 * 1e-3).sin()).collect();
        let (lo, hi) = velocity_range(&v).unwrap();
        assert!((hi - 0.5 * 2.0).abs() < 0.01, "{hi}");
        assert!(
            (lo - 2.0 * (0.005f64 * std::f64::consts::PI).sin()).abs() < 3e-3,
            "{lo}"
        );
        // Never near rest (1.5 ± 0.5): nothing to say about static friction.
        let fast: Vec<f64> = (0..1000).map(|k| 1.5 + 0.5 * (k as f64 * 0.01).sin()).collect();
        assert_eq!(velocity_range(&fast), None);
        assert_eq!(velocity_range(&[f64::NAN; 10]), None);
    }

    #[test]
    fn a_joint_keeps_the_term_only_where_it_predicts_held_out_data_and_is_physical() {
        let linear = [0.3, 2.0, 4.0, 0.1];
        // A real Stribeck effect: kept, and the held-out error falls.
        let real = sweeps((linear, Stribeck { fs: 6.0, vs: 0.05 }), 0.05, 0.0, 1);
        let c = choice(&real, linear);
        let [sign, stribeck] = c.held_out.unwrap();
        assert!(c.kept && stribeck < 0.5 * sign, "{c}");
        // Sign friction and noise only: the term fits nothing that comes back.
        let none = sweeps((linear, Stribeck { fs: 4.0, vs: 0.05 }), 0.05, 0.0, 2);
        let c = choice(&none, linear);
        assert!(!c.kept && c.reason.contains("does not lower the held-out error"), "{c}");
        // Glitches at the reversals of the first 15 s only: a small vs fits them
        // in training, and predicts the rest no better.
        let glitches = sweeps((linear, Stribeck { fs: 4.0, vs: 0.05 }), 0.05, 30.0, 3);
        let c = choice(&glitches, linear);
        assert!(!c.kept, "{c}");
        // A static friction with a negative Coulomb friction under it: the term
        // predicts, but is not physical.
        let negative = ([0.3, 2.0, -1.0, 0.1], Stribeck { fs: 3.0, vs: 0.05 });
        let c = choice(&sweeps(negative, 0.05, 0.0, 4), negative.0);
        assert!(!c.kept && c.reason.contains("Fc = -"), "{c}");
        assert!(
            c.to_string().starts_with("sign kept: fitted on every sample, Fc = -"),
            "{c}"
        );
    }

    #[test]
    fn bounds_hold_in_the_fit() {
        // Fs ≥ 0 and, constrained, Ia, Fv, Fc ≥ 0; a term not fitted stays 0.
        let truth = ([-0.2, 2.0, -1.0, 0.1], Stribeck { fs: -2.0, vs: 0.05 });
        let [v, a, tau] = sweeps(truth, 0.01, 0.0, 5);
        let range = velocity_range(&v).unwrap();
        let start = ([0.0; 4], Stribeck { fs: 0.0, vs: 0.1 });
        for constraints in [
            JointConstraints::default(),
            JointConstraints {
                fitted: [false, true, true, true],
                nonnegative: true,
            },
        ] {
            let fit = fit_joint(
                &v,
                &a,
                &tau,
                start,
                Coulomb::Sign,
                range,
                constraints,
                Starts::Grid,
                &ROUND_LM,
            );
            assert!(fit.stribeck.fs >= 0.0, "{fit:?}");
            assert!(fit.stribeck.vs >= range.0 && fit.stribeck.vs <= range.1, "{fit:?}");
            if constraints.nonnegative {
                assert!(fit.linear[..3].iter().all(|x| *x >= 0.0), "{fit:?}");
                assert_eq!(fit.linear[0], 0.0);
            }
        }
    }

    #[test]
    fn excess_vanishes_when_static_equals_coulomb_and_far_from_rest() {
        let s = Stribeck { fs: 3.0, vs: 0.1 };
        assert_eq!(excess_torque(3.0, s, 0.05, Coulomb::Sign), 0.0);
        assert!((excess_torque(2.0, s, 0.0001, Coulomb::Sign) - 1.0).abs() < 1e-5);
        assert!((excess_torque(2.0, s, -0.0001, Coulomb::Sign) + 1.0).abs() < 1e-5);
        assert!(excess_torque(2.0, s, 1.0, Coulomb::Sign).abs() < 1e-40);
        let smooth = Coulomb::Smooth { epsilon: 0.01 };
        assert_eq!(excess_torque(2.0, s, 0.0, smooth), 0.0);
    }

    #[test]
    fn bad_parameters_name_the_joint() {
        let good = Stribeck { fs: 1.0, vs: 0.1 };
        let e = check(&[good, Stribeck { fs: 1.0, vs: 0.0 }], 2).unwrap_err();
        assert_eq!(e, StribeckError::Velocity { joint: 2, vs: 0.0 });
        assert!(
            e.to_string().contains("joint 2") && e.to_string().contains("positive"),
            "{e}"
        );
        let e = check(&[Stribeck { fs: f64::NAN, vs: 0.1 }], 1).unwrap_err();
        assert!(e.to_string().contains("joint 1: the static friction"), "{e}");
        assert_eq!(check(&[good], 2), Err(StribeckError::Joints { expected: 2, found: 1 }));
        assert_eq!(check(&[good, good], 2), Ok(()));
    }
}
