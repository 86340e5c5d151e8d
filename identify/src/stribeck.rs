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

use crate::data::Trajectory;
use crate::report::{ParamReport, ParamStatus};
use crate::Estimate;
use dyngen_model::joint_params::{Coulomb, PER_JOINT};
use dyngen_model::names::param_name;
use dyngen_reference::Dynamics;
use nalgebra::{SMatrix, SVector};
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
    /// Standard deviations of `Fs` and `vs` from the Gauss–Newton curvature at the
    /// solution, the rigid bodies taken as known; `None` where not determined.
    pub sigma: [Option<f64>; 2],
    /// Sum of squared residuals at the start and at the end.
    pub initial_cost: f64,
    pub cost: f64,
    pub iterations: usize,
}

/// The bounds of `vs` for a joint whose largest speed is `v_max`: `vs` below
/// `1e-4·v_max` acts on no sample, above `v_max` the term is a second Coulomb
/// friction.
pub fn velocity_bounds(v_max: f64) -> (f64, f64) {
    (1e-4 * v_max, v_max)
}

/// One joint's `[Ia, Fv, Fc, Fs, F0]` and `vs` fitted by Levenberg–Marquardt to
/// `target` (the joint's torque without its rigid-body part) at velocities `v` and
/// accelerations `a`, from `start` (`[Ia, Fv, Fc, F0]`, Stribeck). `vs` is searched
/// as `ln vs` within [`velocity_bounds`]; only steps that lower the sum of squared
/// residuals are taken, so the result is never worse than the start. `starts`
/// gives other values of `vs` to try first (each a linear fit of the other five
/// parameters); the best of them replaces the start when it is better.
pub fn fit_joint(
    v: &[f64],
    a: &[f64],
    target: &[f64],
    start: ([f64; PER_JOINT], Stribeck),
    coulomb: Coulomb,
    starts: Starts<'_>,
    options: &LmOptions,
) -> JointFit {
    let v_max = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (lo, hi) = velocity_bounds(v_max);
    let (linear, s) = start;
    let mut p = SVector::<f64, 6>::from([linear[0], linear[1], linear[2], s.fs, linear[3], s.vs.ln()]);
    let mut cost = joint_cost(v, a, target, &p, coulomb);
    let initial_cost = cost;
    let out = |p: &SVector<f64, 6>, cost: f64, iterations: usize, sigma: [Option<f64>; 2]| JointFit {
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
    // A joint that never moves (or too few samples) says nothing about vs.
    if !(v_max > 0.0 && v_max.is_finite()) || v.len() <= 6 {
        return JointFit {
            stribeck: s,
            ..out(&p, cost, 0, [None, None])
        };
    }
    let candidates: Vec<f64> = match starts {
        Starts::None => Vec::new(),
        Starts::Grid => (0..=GRID)
            .map(|k| lo * (hi / lo).powf(k as f64 / GRID as f64))
            .collect(),
        Starts::These(vs) => vs.iter().map(|v| v.clamp(lo, hi)).collect(),
    };
    {
        for vs in candidates {
            if let Some(q) = linear_at(v, a, target, vs, coulomb) {
                let c = joint_cost(v, a, target, &q, coulomb);
                if c < cost {
                    (p, cost) = (q, c);
                }
            }
        }
    }
    let (u_lo, u_hi) = (lo.ln(), hi.ln());
    p[5] = p[5].clamp(u_lo, u_hi);
    cost = cost.min(joint_cost(v, a, target, &p, coulomb));
    let mut lambda = 1e-3;
    let mut iterations = 0;
    while iterations < options.max_iterations {
        iterations += 1;
        let (h, g) = normal_equations(v, a, target, &p, coulomb);
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
        trial[5] = trial[5].clamp(u_lo, u_hi);
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
    // σ of Fs and vs = vs·σ(ln vs) from σ²·H⁻¹, σ² = cost / (rows − 6).
    let (h, _) = normal_equations(v, a, target, &p, coulomb);
    let dof = (v.len() - 6) as f64;
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
    out(&p, cost, iterations, sigma)
}

/// Values of `vs` [`fit_joint`] tries before its Levenberg–Marquardt iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Starts<'a> {
    /// Only the start.
    None,
    /// A grid of 17 log-spaced values over [`velocity_bounds`].
    Grid,
    /// These (clamped to [`velocity_bounds`]).
    These(&'a [f64]),
}

/// Points of the `vs` grid in [`fit_joint`], minus one (log-spaced over [`velocity_bounds`]).
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

/// `JᵀJ` and `Jᵀr` of the residual `target − model` at `p`.
fn normal_equations(
    v: &[f64],
    a: &[f64],
    target: &[f64],
    p: &SVector<f64, 6>,
    coulomb: Coulomb,
) -> (SMatrix<f64, 6, 6>, SVector<f64, 6>) {
    let mut h = SMatrix::<f64, 6, 6>::zeros();
    let mut g = SVector::<f64, 6>::zeros();
    for k in 0..v.len() {
        let (m, row) = model(v[k], a[k], p, coulomb);
        let r = target[k] - m;
        for i in 0..6 {
            g[i] += row[i] * r;
            for j in i..6 {
                h[(i, j)] += row[i] * row[j];
            }
        }
    }
    for i in 0..6 {
        for j in 0..i {
            h[(i, j)] = h[(j, i)];
        }
    }
    (h, g)
}

/// The best `[Ia, Fv, Fc, Fs, F0]` for a fixed `vs` (a linear least-squares fit;
/// minimum norm where the columns are dependent), with `ln vs` as sixth entry.
fn linear_at(v: &[f64], a: &[f64], target: &[f64], vs: f64, coulomb: Coulomb) -> Option<SVector<f64, 6>> {
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
    let eps = 1e-12 * h.diagonal().max();
    let x = h.svd(true, true).solve(&g, eps).ok()?;
    x.iter()
        .all(|x| x.is_finite())
        .then(|| SVector::<f64, 6>::from([x[0], x[1], x[2], x[3], x[4], vs.ln()]))
}

/// Rounds of [`refine`], at most.
pub const MAX_ROUNDS: usize = 20;

/// [`refine`] stops when a round lowers the cost by less than this fraction.
pub const REFINE_TOLERANCE: f64 = 1e-5;

/// What [`refine`] found: per joint the Stribeck parameters and their fits, and the
/// sum of squared torque residuals (all joints, N²·m²) of the linear start and of
/// the result.
#[derive(Clone, Debug, PartialEq)]
pub struct StribeckFit {
    pub coulomb: Coulomb,
    pub joints: Vec<Stribeck>,
    /// Per joint, the Coulomb friction `Fc` of the final linear fit.
    pub fc: Vec<f64>,
    /// Per joint, σ of `Fs` and `vs` (see [`JointFit::sigma`]).
    pub sigma: Vec<[Option<f64>; 2]>,
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
    /// or without a value (`no_effect`) for a joint whose fit found nothing to
    /// improve (its prediction is the linear one whatever `vs` holds).
    pub fn param_reports(&self) -> Vec<ParamReport> {
        let mut out = Vec::with_capacity(2 * self.joints.len());
        for (j, (s, sigma)) in self.joints.iter().zip(&self.sigma).enumerate() {
            for (name, value, sigma) in [("Fs", s.fs, sigma[0]), ("vs", s.vs, sigma[1])] {
                let known = sigma.is_some();
                out.push(ParamReport {
                    name: param_name(name, j + 1),
                    value: known.then_some(value),
                    sigma,
                    sigma_percent: sigma.filter(|_| value != 0.0).map(|s| 100.0 * s / value.abs()),
                    status: if known {
                        ParamStatus::Identified
                    } else {
                        ParamStatus::NoEffect
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
            let known = sigma[0].is_some();
            writeln!(
                f,
                "{:>5} {:>11.5} {} {} {} {} {:>14}",
                j + 1,
                self.fc[j],
                cell(known.then_some(s.fs)),
                cell(sigma[0]),
                cell(known.then_some(s.vs)),
                cell(sigma[1]),
                self.iterations[j]
            )?;
        }
        Ok(())
    }
}

/// The Stribeck model fitted from the linear fit `start` (whose solution is the
/// `10n` standard parameters then `[Ia, Fv, Fc, F0]` per joint, Coulomb term
/// `coulomb`) of `traj`'s torques; `linear_fit` redoes that linear fit on any
/// trajectory (`traj`, a part of it, or either with the Stribeck term taken out of
/// the torques). Returns the final linear fit (its solution holds the rigid-body
/// parameters and `[Ia, Fv, Fc, F0]`; its residuals are those of the whole model)
/// and the Stribeck parameters. `traj` must have velocities and accelerations.
///
/// A long recording is fitted first on at most [`ROUND_SAMPLES`] samples spread
/// over it (the rounds, each a linear fit, are then cheap), and the result carried
/// to every sample by one linear fit and at most [`FINAL_ROUNDS`] more rounds; the
/// result is accepted only where it lowers the cost over every sample, so it is
/// never worse than `start`.
pub fn refine<E>(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    coulomb: Coulomb,
    start: Estimate,
    mut linear_fit: impl FnMut(&Trajectory) -> Result<Estimate, E>,
) -> Result<(Estimate, StribeckFit), E> {
    let n = dynamics.nv();
    let full = Columns::new(traj, n);
    // The start: Fs = Fc, vs a tenth of the joint's largest speed.
    let first: Vec<Stribeck> = (0..n)
        .map(|j| {
            let v_max = full.v[j].iter().fold(0.0f64, |m, x| m.max(x.abs()));
            Stribeck {
                fs: joint_linear(&start.solution, n, j)[2],
                vs: if v_max > 0.0 && v_max.is_finite() {
                    0.1 * v_max
                } else {
                    1.0
                },
            }
        })
        .collect();
    let (initial_cost, rigid) = total_cost(dynamics, traj, &start.solution, &first, coulomb);
    let mut state = State {
        estimate: start,
        stribeck: first,
        sigma: vec![[None, None]; n],
        iterations: vec![0; n],
        rounds: 0,
        cost: initial_cost,
        rigid,
    };
    let stride = traj.len().div_ceil(ROUND_SAMPLES).max(1);
    if stride == 1 {
        state = rounds(dynamics, traj, &full, coulomb, state, None, MAX_ROUNDS, &mut linear_fit)?;
    } else if let Some(part) = every(traj, stride) {
        let columns = Columns::new(&part, n);
        let estimate = linear_fit(&part)?;
        let (cost, rigid) = total_cost(dynamics, &part, &estimate.solution, &state.stribeck, coulomb);
        let found = rounds(
            dynamics,
            &part,
            &columns,
            coulomb,
            State {
                estimate,
                cost,
                rigid,
                ..state.clone()
            },
            None,
            MAX_ROUNDS,
            &mut linear_fit,
        )?;
        // Each joint's vs carried to every sample: the first round there starts
        // from it (Fs and the linear terms fitted for it), rounds counted on.
        let vs: Vec<f64> = found.stribeck.iter().map(|s| s.vs).collect();
        state.rounds = found.rounds;
        state.iterations = found.iterations;
        state = rounds(
            dynamics,
            traj,
            &full,
            coulomb,
            state,
            Some(&vs),
            FINAL_ROUNDS,
            &mut linear_fit,
        )?;
    }
    let fc = (0..n)
        .map(|j| joint_linear(&state.estimate.solution, n, j)[2])
        .collect();
    Ok((
        state.estimate,
        StribeckFit {
            coulomb,
            joints: state.stribeck,
            fc,
            sigma: state.sigma,
            iterations: state.iterations,
            rounds: state.rounds,
            initial_cost,
            cost: state.cost,
            rows: traj.len() * n,
        },
    ))
}

/// Samples the rounds of [`refine`] run on, at most.
pub const ROUND_SAMPLES: usize = 20_000;

/// Rounds of [`refine`] on every sample of a recording longer than [`ROUND_SAMPLES`].
pub const FINAL_ROUNDS: usize = 2;

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

/// `[Ia, Fv, Fc, F0]` of joint `j` in a solution of `10n + 4n` entries.
fn joint_linear(x: &[f64], n: usize, j: usize) -> [f64; PER_JOINT] {
    let at = 10 * n + PER_JOINT * j;
    [x[at], x[at + 1], x[at + 2], x[at + 3]]
}

/// Every `stride`-th sample of `traj`.
fn every(traj: &Trajectory, stride: usize) -> Option<Trajectory> {
    let n = traj.dof();
    let keep: Vec<usize> = (0..traj.len()).step_by(stride).collect();
    let rows = |data: &[f64]| -> Vec<f64> { keep.iter().flat_map(|&k| data[k * n..(k + 1) * n].to_vec()).collect() };
    let t = keep.iter().map(|&k| traj.t()[k]).collect();
    Trajectory::new(n, t, rows(traj.positions()), rows(traj.torques()))
        .and_then(|p| p.with_velocities(rows(traj.velocities().unwrap_or(&[]))))
        .and_then(|p| p.with_accelerations(rows(traj.accelerations().unwrap_or(&[]))))
        .ok()
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
/// (from a grid of `vs` in the first round when `grid`), (2) the linear fit with each
/// joint's `Fs − Fc` and `vs` held.
#[allow(clippy::too_many_arguments)]
fn rounds<E>(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    columns: &Columns,
    coulomb: Coulomb,
    mut state: State,
    hint: Option<&[f64]>,
    max: usize,
    linear_fit: &mut impl FnMut(&Trajectory) -> Result<Estimate, E>,
) -> Result<State, E> {
    let n = dynamics.nv();
    let len = traj.len();
    for round in 0..max {
        let before = state.cost;
        // (1) Every joint on its own (in parallel), the rigid-body torques held.
        let fit = |j: usize| {
            let target: Vec<f64> = (0..len).map(|k| columns.tau[j][k] - state.rigid[k * n + j]).collect();
            fit_joint(
                &columns.v[j],
                &columns.a[j],
                &target,
                (joint_linear(&state.estimate.solution, n, j), state.stribeck[j]),
                coulomb,
                match (round, hint) {
                    (0, None) => Starts::Grid,
                    (0, Some(vs)) => Starts::These(&vs[j..j + 1]),
                    _ => Starts::None,
                },
                &ROUND_LM,
            )
        };
        let threads = crate::accumulate::cores().clamp(1, n.max(1));
        let mut fits: Vec<(usize, JointFit)> = std::thread::scope(|s| {
            let fit = &fit;
            let handles: Vec<_> = (0..threads)
                .map(|t| s.spawn(move || (t..n).step_by(threads).map(|j| (j, fit(j))).collect::<Vec<_>>()))
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .collect()
        });
        fits.sort_by_key(|(j, _)| *j);
        let fits: Vec<JointFit> = fits.into_iter().map(|(_, f)| f).collect();
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

/// The sum of squared torque residuals of the whole model (rigid bodies
/// `x[..10n]`, linear joint terms `x[10n..]`, the Stribeck terms), and the rigid-body
/// torques (row-major, samples × joints).
fn total_cost(
    dynamics: &dyn Dynamics,
    traj: &Trajectory,
    x: &[f64],
    stribeck: &[Stribeck],
    coulomb: Coulomb,
) -> (f64, Vec<f64>) {
    let n = dynamics.nv();
    let rigid = rigid_torques(dynamics, traj, &x[..10 * n]);
    let joints = &x[10 * n..];
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
        let fit = fit_joint(&v, &a, &tau, start, Coulomb::Sign, Starts::Grid, &LmOptions::default());
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
        let fit = fit_joint(&v, &a, &tau, start, Coulomb::Sign, Starts::Grid, &LmOptions::default());
        assert!(fit.cost <= fit.initial_cost);
        let (lo, hi) = velocity_bounds(v.iter().fold(0.0f64, |m, x| m.max(x.abs())));
        assert!(
            fit.stribeck.vs >= lo * (1.0 - 1e-12) && fit.stribeck.vs <= hi * (1.0 + 1e-12),
            "{fit:?}"
        );
        assert!(fit.stribeck.fs.is_finite());
        // A joint that never moves keeps its start.
        let fit = fit_joint(
            &[0.0; 10],
            &[0.0; 10],
            &[1.0; 10],
            start,
            Coulomb::Sign,
            Starts::Grid,
            &LmOptions::default(),
        );
        assert_eq!((fit.stribeck, fit.iterations), (truth.1, 0));
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
