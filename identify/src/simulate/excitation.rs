//! Optimal excitation: Fourier coefficients that make the identification problem
//! well conditioned (Swevers et al. 1997), within joint position, velocity and
//! acceleration limits ([`JointLimits`]), everywhere along the continuous motion and
//! so at any sampling of it.
//!
//! The criterion is evaluated on a fixed grid of [`ExcitationDesign::samples`]
//! instants over one period (by default `20 L` for `L` harmonics, see
//! [`ExcitationDesign::default_samples`] for why that suffices), never on the
//! recording itself: a design costs the same for a recording of 100 steps or of 10⁶,
//! and [`regressor_condition`] checks the result on the recorded instants. It is
//! minimised by the Nelder–Mead method of the `argmin` crate, with restarts, within
//! a fixed number of evaluations and from a seeded random start, so the result is
//! reproducible.
//!
//! Two criteria ([`Criterion`]):
//!
//! * for identification from joint torques, the condition number `σ_max/σ_min` of
//!   the stacked base regressor `W_b = [Y(q_k, v_k, a_k)]_{k}` restricted to the
//!   identifiable columns of `Y`. Those columns are the model's base-parameter
//!   columns ([`dyngen_model::base::analyse`]): with them, `Y π = Y_b β` where
//!   `Y_b = Y[:, base]` and `β` the base parameters built on those columns, so
//!   `cond(W_b)` is the condition number of the base-parameter least squares problem
//!   the trajectory will feed, and the same columns the generated base regressor has;
//! * for MIM on body measurements, the worst relative standard deviation of a
//!   principal moment: per body `i`, with `B_i` stacked over the samples and
//!   `M_i = B_i J_i` its moments at the nominal parameters,
//!   `max_k √([(B_iᵀ B_i)⁻¹]_kk) · rms(M_i) / J_ik` over the bodies and the moments
//!   that enter their equations. It is the relative σ of `Ĵ_ik` per unit of relative
//!   noise on the moments (5.7 means 5.7 % at 1 % noise). Masses are left out: gravity
//!   alone makes them well conditioned.

use super::motion::{FourierExcitation, JointMotion};
use crate::minimise::minimise;
use crate::IdentifyError;
use dyngen::BodyRegressor;
use dyngen_model::base::{self, Parameterisation};
use dyngen_model::{JointKind, Model};
use dyngen_reference::Dynamics;
use dyngen_reference::{sample_states, SplitMix64};
use nalgebra::{DMatrix, Matrix3, Vector3};
use std::f64::consts::PI;

/// Where one joint may go: positions in `[lower, upper]`, speeds up to `velocity`,
/// accelerations up to `acceleration` (rad, rad/s, rad/s²; m, m/s, m/s² for a
/// prismatic joint).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    pub lower: f64,
    pub upper: f64,
    pub velocity: f64,
    pub acceleration: f64,
}

impl JointLimits {
    /// The acceleration limit per unit of velocity limit, s⁻¹, where the description
    /// gives none (URDF and MJCF have no acceleration limits): full speed from rest in
    /// 0.2 s. Published arms are in this range: the Franka Panda allows 15 rad/s² at
    /// 2.175 rad/s (6.9 s⁻¹) on its first joint, 7.5 rad/s² (3.4 s⁻¹) on its second.
    pub const ACCELERATION_PER_VELOCITY: f64 = 5.0;

    /// Each joint's limits from the model, with defaults where the description has
    /// none: positions within `[−π, π]` rad (rotation) or `[−0.5, 0.5]` m
    /// (translation), narrowed to the joint's limits when it has any; speed the
    /// joint's velocity limit when it is positive and below `10⁵` (URDF writers put
    /// `10⁶` for "none"), else 2 rad/s or 0.5 m/s; acceleration
    /// [`JointLimits::ACCELERATION_PER_VELOCITY`] times the speed.
    pub fn from_model(model: &Model) -> Vec<JointLimits> {
        model
            .own_joints()
            .map(|j| {
                let (reach, speed) = if j.kind == JointKind::Prismatic {
                    (0.5, 0.5)
                } else {
                    (PI, 2.0)
                };
                let (lower, upper, velocity) = match j.limits {
                    Some(l) if l.upper > l.lower => (
                        l.lower.max(-reach),
                        l.upper.min(reach),
                        if l.velocity > 0.0 && l.velocity < 1e5 {
                            l.velocity
                        } else {
                            speed
                        },
                    ),
                    _ => (-reach, reach, speed),
                };
                JointLimits {
                    lower,
                    upper,
                    velocity,
                    acceleration: JointLimits::ACCELERATION_PER_VELOCITY * velocity,
                }
            })
            .collect()
    }

    /// Finite, `lower < upper`, and positive speed and acceleration.
    fn check(&self, joint: usize) -> Result<(), IdentifyError> {
        let JointLimits {
            lower,
            upper,
            velocity,
            acceleration,
        } = *self;
        let reason = if !(lower.is_finite() && upper.is_finite() && velocity.is_finite() && acceleration.is_finite()) {
            "not finite"
        } else if lower >= upper {
            "the lower position limit is not below the upper"
        } else if velocity <= 0.0 {
            "the velocity limit is not positive"
        } else if acceleration <= 0.0 {
            "the acceleration limit is not positive"
        } else {
            return Ok(());
        };
        Err(IdentifyError::InvalidArgument {
            what: "joint limits",
            reason: format!(
                "joint {}: {reason} (lower {lower}, upper {upper}, velocity {velocity}, acceleration {acceleration})",
                joint + 1
            ),
        })
    }
}

/// What [`ExcitationDesign::optimise`] minimises (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Criterion {
    /// `cond(W_b)` of the stacked base torque regressor: for identification from
    /// joint torques.
    #[default]
    JointTorques,
    /// The worst relative σ of a principal moment per unit of relative noise: for
    /// MIM (and NIM) on each body's measured motion and resultant.
    BodyModel,
}

/// Settings of [`ExcitationDesign::optimise`].
#[derive(Clone, Debug, PartialEq)]
pub struct ExcitationDesign {
    /// What to minimise.
    pub criterion: Criterion,
    /// Harmonics `L` per joint (Swevers: 5).
    pub harmonics: usize,
    /// Base frequency `f_f`, Hz; the trajectory repeats every `1/f_f` s.
    pub base_frequency: f64,
    /// Length of the experiment, s (default one period); the criterion and the
    /// limits are evaluated over `T = min(duration, 1/f_f)`, since the motion
    /// repeats after one period.
    pub duration: f64,
    /// Samples `t_k = k · T / samples`, `k = 0..samples`, stacked into the
    /// criterion: a fixed design grid, independent of how densely the experiment is
    /// then recorded ([`ExcitationDesign::default_samples`]).
    pub samples: usize,
    /// Per joint. Checked on a grid of `max(4 · samples, 64 L)` intervals over `T`,
    /// ends included, with the largest overshoot the curvature allows between grid
    /// points added (see [`ExcitationDesign::optimise`]): the whole continuous
    /// trajectory, hence any recording of it, stays within them.
    pub limits: Vec<JointLimits>,
    /// Objective evaluations allowed in total (each one evaluates `samples`
    /// regressors and one small QR and SVD, or a few 3 × 3 inverses).
    pub max_evaluations: usize,
    /// Nelder–Mead runs; each after the first restarts from the best point with a
    /// fresh simplex.
    pub restarts: usize,
    /// Impose `v(0) = 0` and `a(0) = 0` (so also at every multiple of the period):
    /// `a_i1 = −Σ_{l≥2} a_il`, `b_i1 = −Σ_{l≥2} l b_il`. Needs `L ≥ 2`.
    pub start_at_rest: bool,
    /// Seeds the random initial coefficients and the states on which the moments
    /// that enter the body equations are found.
    pub seed: u64,
    /// Wall-clock time allowed to the optimisation; `None` (the default) for none.
    /// When it runs out, the best point found so far is kept. The result then
    /// depends on the machine's speed: [`ExcitationDesign::max_evaluations`] is the
    /// reproducible bound.
    pub time_budget: Option<std::time::Duration>,
}

impl ExcitationDesign {
    /// Defaults for `model`: the joint-torque criterion, `L = 5`, `f_f = 0.1` Hz, one
    /// 10 s period sampled [`ExcitationDesign::default_samples`]`(5) = 100` times,
    /// the model's [`JointLimits`], [`ExcitationDesign::default_evaluations`] in 3
    /// runs, free start, seed 1, no time budget.
    pub fn new(model: &Model) -> ExcitationDesign {
        ExcitationDesign {
            criterion: Criterion::JointTorques,
            harmonics: 5,
            base_frequency: 0.1,
            duration: 10.0,
            samples: ExcitationDesign::default_samples(5),
            limits: JointLimits::from_model(model),
            max_evaluations: ExcitationDesign::default_evaluations(model.nv()),
            restarts: 3,
            start_at_rest: false,
            seed: 1,
            time_budget: None,
        }
    }

    /// The design samples for `L` harmonics: `20 L` over one period, whatever the
    /// length and sampling of the recording.
    ///
    /// The criterion sums `YᵀY` over the samples, and a recording of whole periods,
    /// however dense, approximates `K` times its mean over one period. `K` equally
    /// spaced samples over a period give that mean exactly for every harmonic of
    /// `YᵀY` below `K` (the rectangle rule on a periodic function). `Y` is linear in
    /// the accelerations (harmonics up to `L`) and quadratic in the velocities (up to
    /// `2L`), so `YᵀY` reaches `4L`, and the sines and cosines of the joint angles
    /// multiplying them widen that spectrum further, with weights that fall off
    /// quickly for swings of a few radians. `20 L` leaves five times `4L`: the
    /// condition number on the design samples is then that of a dense recording to
    /// within a few per cent (the test `fourier_design_condition_holds_on_the_full_recording`
    /// checks 2 % on a UR5 recording of 2,000 steps), while an evaluation costs the
    /// same for 100 or 10⁶ recorded steps.
    pub fn default_samples(harmonics: usize) -> usize {
        20 * harmonics.max(1)
    }

    /// The default number of objective evaluations for `n` joints: 3000 up to 12
    /// joints, then `3000 (12/n)²`, since one evaluation stacks `n` rows of `10 n`
    /// columns per sample and so costs about `n²`: the default takes about the same
    /// time whatever the robot (under 2 s for a 6-joint arm in a release build).
    pub fn default_evaluations(n: usize) -> usize {
        if n <= 12 {
            3000
        } else {
            (3000.0 * (12.0 / n as f64).powi(2)).round() as usize
        }
    }

    /// [`ExcitationDesign::try_optimise`], panicking on invalid settings (the message
    /// says which).
    pub fn optimise(&self, dynamics: &dyn Dynamics) -> OptimisedExcitation {
        self.try_optimise(dynamics).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Optimises the Fourier coefficients and offsets for the smallest value of the
    /// [`Criterion`] (see the module docs) within the position, velocity and
    /// acceleration limits.
    ///
    /// Variables: per joint `q0_i` and the free `a_il`, `b_il`. Objective:
    /// `log10` of the criterion on feasible points, `10⁶ +` (total limit violation,
    /// relative to each joint's range, speed or acceleration) on infeasible ones, so
    /// infeasible points always lose to feasible ones yet still point back to
    /// feasibility. Limits are checked on the grid of [`ExcitationDesign::limits`],
    /// spacing `h`: between grid points a quantity `x` peaks where `ẋ = 0`, within
    /// `h/2` of a grid point, so by at most `h²/8 · max|ẍ|` above it, and `max|ẍ|` is
    /// bounded by `Σ_l r_il (ω_f l)^k` (`k` = 1, 2, 3 for `q`, `v`, `a`); that
    /// margin is added. The start is random (seeded): `a_il, b_il ~ U(−1, 1)/l`,
    /// `q0` mid-range, scaled per joint until the
    /// [`FourierExcitation::amplitude_bounds`] use half the range, half the speed
    /// and half the acceleration, hence feasible. Minimised by argmin's Nelder–Mead
    /// with restarts ([`ExcitationDesign::restarts`]) within
    /// [`ExcitationDesign::max_evaluations`].
    ///
    /// Errors: `limits` without one valid entry per joint ([`JointLimits`]: finite,
    /// `lower < upper`, positive speed and acceleration), no harmonic,
    /// `start_at_rest` with fewer than 2 harmonics, a base frequency or duration
    /// that is not finite and positive, no samples, or a criterion that is not
    /// finite for the result (too few samples for the parameters, say).
    pub fn try_optimise(&self, dynamics: &dyn Dynamics) -> Result<OptimisedExcitation, IdentifyError> {
        self.optimise_with_progress(dynamics, &mut |_| {})
    }

    /// [`ExcitationDesign::try_optimise`], calling `progress(evaluations)` after each
    /// objective evaluation (at most [`ExcitationDesign::max_evaluations`]), for a
    /// progress bar: on a large tree one evaluation takes milliseconds.
    pub fn optimise_with_progress(
        &self,
        dynamics: &dyn Dynamics,
        progress: &mut dyn FnMut(usize),
    ) -> Result<OptimisedExcitation, IdentifyError> {
        let n = dynamics.nv();
        let harmonics = self.harmonics;
        self.check(n)?;
        let base = base::analyse(dynamics.model(), Parameterisation::Standard).independent;
        let objective = Objective::new(self, dynamics, &base);
        let layout = Layout {
            n,
            harmonics,
            start_at_rest: self.start_at_rest,
            omega: 2.0 * PI * self.base_frequency,
        };

        // Random start, scaled into the limits.
        let mut rng = SplitMix64::new(self.seed ^ 0x5157_4552_5345_5331);
        let mut x = vec![0.0; layout.len()];
        for i in 0..n {
            let l = &self.limits[i];
            x[layout.q0(i)] = 0.5 * (l.lower + l.upper);
            for k in 0..layout.free() {
                let harmonic = (k + layout.first_free()) as f64;
                x[layout.a(i, k)] = rng.uniform(-1.0, 1.0) / harmonic;
                x[layout.b(i, k)] = rng.uniform(-1.0, 1.0) / harmonic;
            }
        }
        let guess = layout.decode(&x);
        for (i, (position, speed, acceleration)) in guess.amplitude_bounds().into_iter().enumerate() {
            let l = &self.limits[i];
            let scale = (0.5 * 0.5 * (l.upper - l.lower) / position)
                .min(0.5 * l.velocity / speed)
                .min(0.5 * l.acceleration / acceleration);
            for k in 0..layout.free() {
                x[layout.a(i, k)] *= scale;
                x[layout.b(i, k)] *= scale;
            }
        }
        let initial = layout.decode(&x);
        let initial_value = objective.criterion(&initial);

        // Simplex steps: a tenth of the half-range for offsets, a quarter of the
        // speed share of one harmonic for coefficients.
        let mut steps = vec![0.0; layout.len()];
        for i in 0..n {
            let l = &self.limits[i];
            steps[layout.q0(i)] = 0.05 * (l.upper - l.lower);
            for k in 0..layout.free() {
                steps[layout.a(i, k)] = 0.25 * l.velocity / harmonics as f64;
                steps[layout.b(i, k)] = 0.25 * l.velocity / harmonics as f64;
            }
        }

        let mut evaluations = 0;
        let mut done = 0;
        let deadline = self.time_budget.map(|t| std::time::Instant::now() + t);
        let mut f = |x: &[f64]| {
            // Past the deadline every point loses, at no cost, and the run stops
            // after the current step; the best point so far stays.
            if deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                return f64::INFINITY;
            }
            let y = objective.value(&layout.decode(x));
            done += 1;
            progress(done);
            y
        };
        let mut best = (x.clone(), f64::INFINITY);
        let runs = self.restarts.max(1);
        for run in 0..runs {
            let budget = (self.max_evaluations.saturating_sub(evaluations)) / (runs - run);
            if budget <= layout.len() + 1 || deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                break;
            }
            let start = best.0.clone();
            let m = minimise(&mut f, &start, &steps, budget, deadline);
            evaluations += m.evaluations;
            if m.f <= best.1 {
                best = (m.x, m.f);
            }
        }

        let excitation = layout.decode(&best.0);
        let value = objective.criterion(&excitation);
        let worse = value.is_nan() || value > initial_value;
        let (value, excitation) = if objective.violation(&excitation) > 0.0 || worse {
            // Never happens from a feasible start, but never return worse than it.
            (initial_value, initial)
        } else {
            (value, excitation)
        };
        if !value.is_finite() {
            return Err(IdentifyError::InvalidArgument {
                what: "excitation design",
                reason: format!(
                    "the criterion is {value} on the design's {} samples: they do not determine the parameters \
                     (more samples or harmonics, or wider limits, are needed)",
                    self.samples
                ),
            });
        }
        Ok(OptimisedExcitation {
            excitation,
            criterion: self.criterion,
            value,
            initial_value,
            evaluations: done,
            base_columns: base,
        })
    }

    /// The settings make sense for `n` joints.
    fn check(&self, n: usize) -> Result<(), IdentifyError> {
        let invalid = |reason: String| {
            Err(IdentifyError::InvalidArgument {
                what: "excitation design",
                reason,
            })
        };
        if self.limits.len() != n {
            return invalid(format!("`limits` has {} entries for {n} joints", self.limits.len()));
        }
        if self.harmonics == 0 {
            return invalid("need at least one harmonic".into());
        }
        if self.start_at_rest && self.harmonics < 2 {
            return invalid("`start_at_rest` needs at least 2 harmonics".into());
        }
        if !(self.base_frequency.is_finite() && self.base_frequency > 0.0) {
            return invalid(format!(
                "the base frequency must be finite and positive, got {}",
                self.base_frequency
            ));
        }
        if !(self.duration.is_finite() && self.duration > 0.0) {
            return invalid(format!(
                "the duration must be finite and positive, got {}",
                self.duration
            ));
        }
        if self.samples == 0 {
            return invalid("need at least one sample".into());
        }
        for (i, l) in self.limits.iter().enumerate() {
            l.check(i)?;
        }
        Ok(())
    }
}

/// What [`ExcitationDesign::optimise`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct OptimisedExcitation {
    pub excitation: FourierExcitation,
    /// The criterion minimised.
    pub criterion: Criterion,
    /// Its value for the result over the design's samples: `cond(W_b)`, or the worst
    /// relative σ of a principal moment per unit of relative noise.
    pub value: f64,
    /// Its value for the random feasible start.
    pub initial_value: f64,
    /// Objective evaluations spent.
    pub evaluations: usize,
    /// The identifiable columns of `Y` the criterion used
    /// ([`BaseParams::independent`](dyngen_model::base::BaseParams::independent)).
    pub base_columns: Vec<usize>,
}

/// The optimisation vector: per joint `q0_i`, then the free `a_il` and `b_il`
/// (all `L` of each, or `l = 2..L` when the first harmonic is fixed by the rest
/// conditions).
struct Layout {
    n: usize,
    harmonics: usize,
    start_at_rest: bool,
    omega: f64,
}

impl Layout {
    fn free(&self) -> usize {
        if self.start_at_rest {
            self.harmonics - 1
        } else {
            self.harmonics
        }
    }

    /// The harmonic number of free coefficient 0.
    fn first_free(&self) -> usize {
        if self.start_at_rest {
            2
        } else {
            1
        }
    }

    fn per_joint(&self) -> usize {
        1 + 2 * self.free()
    }

    fn len(&self) -> usize {
        self.n * self.per_joint()
    }

    fn q0(&self, i: usize) -> usize {
        i * self.per_joint()
    }

    fn a(&self, i: usize, k: usize) -> usize {
        i * self.per_joint() + 1 + k
    }

    fn b(&self, i: usize, k: usize) -> usize {
        i * self.per_joint() + 1 + self.free() + k
    }

    fn decode(&self, x: &[f64]) -> FourierExcitation {
        let (n, big_l) = (self.n, self.harmonics);
        let mut a = vec![0.0; n * big_l];
        let mut b = vec![0.0; n * big_l];
        let offset = self.first_free() - 1;
        for i in 0..n {
            for k in 0..self.free() {
                a[i * big_l + offset + k] = x[self.a(i, k)];
                b[i * big_l + offset + k] = x[self.b(i, k)];
            }
            if self.start_at_rest {
                a[i * big_l] = -(1..big_l).map(|l| a[i * big_l + l]).sum::<f64>();
                b[i * big_l] = -(1..big_l).map(|l| (l + 1) as f64 * b[i * big_l + l]).sum::<f64>();
            }
        }
        FourierExcitation {
            omega: self.omega,
            q0: (0..n).map(|i| x[self.q0(i)]).collect(),
            a,
            b,
            harmonics: big_l,
        }
    }
}

/// The criterion with its sample times and base columns fixed.
struct Objective<'a> {
    dynamics: &'a dyn Dynamics,
    criterion: Criterion,
    base: &'a [usize],
    samples: Vec<f64>,
    /// The limit grid, both ends of the window included, and its spacing.
    grid: Vec<f64>,
    spacing: f64,
    limits: &'a [JointLimits],
    /// [`Criterion::BodyModel`]: the nominal principal moments of each body and
    /// whether each enters the body's equations at all.
    moments: Vec<([f64; 3], [bool; 3])>,
}

impl<'a> Objective<'a> {
    fn new(design: &'a ExcitationDesign, dynamics: &'a dyn Dynamics, base: &'a [usize]) -> Objective<'a> {
        // The motion repeats every period: a longer experiment adds nothing to either
        // criterion or to the limits, and sampling it sparsely would alias (samples
        // one period apart are one instant).
        let window = design.duration.min(1.0 / design.base_frequency);
        let intervals = (4 * design.samples).max(64 * design.harmonics);
        let spacing = window / intervals as f64;
        let moments = match design.criterion {
            Criterion::JointTorques => Vec::new(),
            Criterion::BodyModel => body_moments(dynamics, design.seed),
        };
        Objective {
            dynamics,
            criterion: design.criterion,
            base,
            samples: (0..design.samples)
                .map(|k| k as f64 * window / design.samples as f64)
                .collect(),
            grid: (0..=intervals).map(|k| k as f64 * spacing).collect(),
            spacing,
            limits: &design.limits,
            moments,
        }
    }

    fn criterion(&self, e: &FourierExcitation) -> f64 {
        match self.criterion {
            Criterion::JointTorques => stacked_condition(self.dynamics, self.base, e, &self.samples),
            Criterion::BodyModel => worst_moment_sigma(self.dynamics, &self.moments, e, &self.samples),
        }
    }

    /// Total relative violation of the position, velocity and acceleration limits
    /// anywhere over the window: the extremes on the grid plus the most the
    /// curvature allows between grid points (see [`ExcitationDesign::optimise`]).
    fn violation(&self, e: &FourierExcitation) -> f64 {
        let n = e.nv();
        let (mut q, mut v, mut a) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let (mut q_min, mut q_max) = (vec![f64::INFINITY; n], vec![f64::NEG_INFINITY; n]);
        let (mut v_max, mut a_max) = (vec![0.0f64; n], vec![0.0f64; n]);
        for &t in &self.grid {
            e.eval(t, &mut q, &mut v, &mut a);
            for i in 0..n {
                q_min[i] = q_min[i].min(q[i]);
                q_max[i] = q_max[i].max(q[i]);
                v_max[i] = v_max[i].max(v[i].abs());
                a_max[i] = a_max[i].max(a[i].abs());
            }
        }
        let h2 = self.spacing * self.spacing / 8.0;
        let mut total = 0.0;
        for i in 0..n {
            // Bounds on |q̈|, |v̈| and |ä|: Σ_l r_il (ω_f l)^k, k = 1, 2, 3.
            let (mut dq, mut dv, mut da) = (0.0, 0.0, 0.0);
            for l in 1..=e.harmonics {
                let r = e.a(i, l).hypot(e.b(i, l));
                let wl = e.omega * l as f64;
                dq += r * wl;
                dv += r * wl * wl;
                da += r * wl * wl * wl;
            }
            let lim = &self.limits[i];
            let range = lim.upper - lim.lower;
            let above = (q_max[i] + h2 * dq - lim.upper).max(0.0);
            let below = (lim.lower - (q_min[i] - h2 * dq)).max(0.0);
            total += above.max(below) / range;
            total += (v_max[i] + h2 * dv - lim.velocity).max(0.0) / lim.velocity;
            total += (a_max[i] + h2 * da - lim.acceleration).max(0.0) / lim.acceleration;
        }
        // A NaN (coefficients out of range) is infeasible, not feasible.
        if total.is_nan() {
            f64::INFINITY
        } else {
            total
        }
    }

    fn value(&self, e: &FourierExcitation) -> f64 {
        let violation = self.violation(e);
        if violation > 0.0 {
            return 1e6 + violation;
        }
        let c = self.criterion(e);
        if c.is_finite() {
            c.log10()
        } else {
            1e5
        }
    }
}

/// [`Criterion::JointTorques`] of any trajectory sampled at `times`: the condition
/// number `σ_max/σ_min` of the base regressor `W_b` stacked over the samples (∞ when
/// it is rank-deficient or not finite). With the design's result and the times of a
/// recording, it says how well the recording itself is conditioned:
///
/// ```
/// use dyngen_identify::simulate::{regressor_condition, ExcitationDesign};
/// let model = dyngen_model::parse_urdf(include_str!("../../../tests/fixtures/paper6.urdf")).unwrap();
/// let robot = dyngen_reference::Reference::new(&model);
/// let design = ExcitationDesign { max_evaluations: 0, ..ExcitationDesign::new(&model) };
/// let found = design.optimise(&robot);
/// let times: Vec<f64> = (0..=1000).map(|k| k as f64 * 0.01).collect();
/// let c = regressor_condition(&robot, &found.excitation, &times);
/// assert!((c / found.value - 1.0).abs() < 0.05, "{c} {}", found.value);
/// ```
///
/// Memory stays small for long recordings: the samples are folded into the `R` of a
/// QR factorisation a block at a time.
pub fn regressor_condition(dynamics: &dyn Dynamics, trajectory: &dyn JointMotion, times: &[f64]) -> f64 {
    let base = base::analyse(dynamics.model(), Parameterisation::Standard).independent;
    stacked_condition(dynamics, &base, trajectory, times)
}

/// `cond(W_b)` over `times`, with the base columns `base` of `Y`.
fn stacked_condition(dynamics: &dyn Dynamics, base: &[usize], trajectory: &dyn JointMotion, times: &[f64]) -> f64 {
    const BLOCK: usize = 128;
    let n = trajectory.nv();
    let p = dynamics.nparams();
    let nb = base.len();
    if nb == 0 {
        return f64::INFINITY;
    }
    let (mut q, mut v, mut a) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut y = vec![0.0; n * p];
    let mut r = DMatrix::<f64>::zeros(0, nb);
    for chunk in times.chunks(BLOCK) {
        let top = r.nrows();
        let mut w = DMatrix::zeros(top + n * chunk.len(), nb);
        w.rows_mut(0, top).copy_from(&r);
        for (k, &t) in chunk.iter().enumerate() {
            trajectory.eval(t, &mut q, &mut v, &mut a);
            dynamics.joint_torque_regressor(&q, &v, &a, &mut y);
            for row in 0..n {
                for (c, &col) in base.iter().enumerate() {
                    w[(top + k * n + row, c)] = y[row * p + col];
                }
            }
        }
        r = if w.nrows() > nb { w.qr().r() } else { w };
    }
    if !r.iter().all(|x| x.is_finite()) {
        return f64::INFINITY;
    }
    let s = r.singular_values();
    let (max, min) = s
        .iter()
        .fold((0.0f64, f64::INFINITY), |(hi, lo), &x| (hi.max(x), lo.min(x)));
    if s.len() < nb || min.is_nan() || min <= 0.0 {
        f64::INFINITY
    } else {
        max / min
    }
}

/// [`Criterion::BodyModel`] of any trajectory sampled at `times`: the worst relative
/// σ of a principal moment per unit of relative moment noise (see the module docs;
/// ∞ when a moment that enters the equations is not determined). It says how well
/// an experiment suits MIM before it is run:
///
/// ```
/// use dyngen_reference::Dynamics;
/// use dyngen_identify::simulate::{moment_sigma, Experiment};
/// let model = dyngen_model::parse_urdf(include_str!("../../../tests/fixtures/paper6.urdf")).unwrap();
/// let robot = dyngen_reference::Reference::new(&model);
/// let paper = Experiment::paper(&model);
/// let s = moment_sigma(&robot, &paper.motion, &paper.times());
/// assert!(s > 1.0 && s.is_finite()); // > 1 % σ at 1 % noise: some moment is barely excited
/// ```
pub fn moment_sigma(dynamics: &dyn Dynamics, trajectory: &dyn JointMotion, times: &[f64]) -> f64 {
    worst_moment_sigma(dynamics, &body_moments(dynamics, 1), trajectory, times)
}

fn worst_moment_sigma(
    dynamics: &dyn Dynamics,
    moments: &[([f64; 3], [bool; 3])],
    trajectory: &dyn JointMotion,
    times: &[f64],
) -> f64 {
    let n = trajectory.nv();
    let (mut q, mut v, mut a) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut blocks = vec![BodyRegressor::default(); n];
    let mut grams = vec![Matrix3::<f64>::zeros(); n];
    let mut squares = vec![0.0; n];
    for &t in times {
        trajectory.eval(t, &mut q, &mut v, &mut a);
        dynamics.body_regressors(&q, &v, &a, &mut blocks);
        for (i, block) in blocks.iter().enumerate() {
            let b: Matrix3<f64> = block.moment.fixed_columns::<3>(1).into_owned();
            grams[i] += b.transpose() * b;
            squares[i] += (b * Vector3::from(moments[i].0)).norm_squared();
        }
    }
    let mut worst = 0.0f64;
    for (i, (j, enters)) in moments.iter().enumerate() {
        let active: Vec<usize> = (0..3).filter(|&k| enters[k]).collect();
        if active.is_empty() {
            continue;
        }
        let g = DMatrix::from_fn(active.len(), active.len(), |r, c| grams[i][(active[r], active[c])]);
        let Some(inverse) = g.cholesky().map(|c| c.inverse()) else {
            return f64::INFINITY;
        };
        let rms = (squares[i] / (3 * times.len()) as f64).sqrt();
        for (r, &k) in active.iter().enumerate() {
            worst = worst.max(inverse[(r, r)].max(0.0).sqrt() * rms / j[k]);
        }
    }
    worst
}

/// Per body, the nominal principal moments `(J1, J2, J3)` and which of them enter
/// the body's equations: a column of `B(ω, ω̇)` that is zero (relative to the
/// body's largest) on 40 random states from [`sample_states`] is zero for every
/// motion (a turret turning about its own axis never feels its `J1`, `J2`).
fn body_moments(dynamics: &dyn Dynamics, seed: u64) -> Vec<([f64; 3], [bool; 3])> {
    let model = dynamics.model();
    let n = dynamics.nv();
    let theta = dyngen_model::principal_params(model);
    let mut norms = vec![[0.0f64; 3]; n];
    let mut blocks = vec![BodyRegressor::default(); n];
    for s in sample_states(model, 40, seed) {
        dynamics.body_regressors(&s.q, &s.v, &s.a, &mut blocks);
        for (i, block) in blocks.iter().enumerate() {
            for k in 0..3 {
                norms[i][k] += block.moment.column(k + 1).norm_squared();
            }
        }
    }
    (0..n)
        .map(|i| {
            let largest = norms[i].iter().copied().fold(0.0, f64::max);
            (
                [theta[4 * i + 1], theta[4 * i + 2], theta[4 * i + 3]],
                norms[i].map(|x| x > 1e-20 * largest && largest > 0.0),
            )
        })
        .collect()
}
