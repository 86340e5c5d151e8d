//! Prescribed joint motions with analytic velocities and accelerations: the
//! smooth start of the paper's experiment and the finite Fourier series of
//! identification experiments.

use std::f64::consts::PI;

/// A prescribed joint-space motion `q(t)` with its derivatives `v = q̇`, `a = q̈`
/// (a recorded data set is a [`Trajectory`](crate::data::Trajectory)).
pub trait JointMotion {
    /// Number of joints `n`.
    fn nv(&self) -> usize;
    /// `q(t), v(t), a(t)`, `n` each. Panics if a slice has another length.
    fn eval(&self, t: f64, q: &mut [f64], v: &mut [f64], a: &mut [f64]);
}

fn check_out(n: usize, q: &[f64], v: &[f64], a: &[f64]) {
    assert!(
        q.len() == n && v.len() == n && a.len() == n,
        "`q, v, a` have lengths {}, {}, {}; the motion has {n} joints",
        q.len(),
        v.len(),
        a.len()
    );
}

/// Each joint rises from rest along a squared raised cosine,
///
/// ```text
/// q_i(t) = q0_i + A_i (1 − cos ω_i t)² / 4
/// v_i(t) = A_i ω_i (sin ω_i t − sin 2ω_i t / 2) / 2
/// a_i(t) = A_i ω_i² (cos ω_i t − cos 2ω_i t) / 2
/// ```
///
/// so that `q(0) = q0` with `v`, `a` and the jerk all zero: the start at rest of the
/// paper's ADAMS drives, with no step in the motor torques. `q_i` stays between `q0_i`
/// and `q0_i + A_i`, reaching `q0_i + A_i` at `ω_i t = π`.
#[derive(Clone, Debug, PartialEq)]
pub struct RaisedCosine {
    pub q0: Vec<f64>,
    pub amplitude: Vec<f64>,
    /// `ω_i`, rad/s.
    pub omega: Vec<f64>,
}

impl RaisedCosine {
    /// Panics unless the three vectors have one length.
    pub fn new(q0: Vec<f64>, amplitude: Vec<f64>, omega: Vec<f64>) -> RaisedCosine {
        assert!(
            q0.len() == amplitude.len() && q0.len() == omega.len(),
            "`q0`, `amplitude`, `omega` have lengths {}, {}, {}",
            q0.len(),
            amplitude.len(),
            omega.len()
        );
        RaisedCosine { q0, amplitude, omega }
    }

    /// The default motion of the paper's experiment (2 s) for a model with the given
    /// joint ranges `(lower, upper)`: joint `i` (0-based) gets
    ///
    /// ```text
    /// ω_i = π (0.9 + 0.23 i) rad/s
    /// A_i = (−1)ⁱ min(0.6 + 0.2 (i mod 4), (upper_i − lower_i) / 4)
    /// ```
    ///
    /// so that no two joints move in step and every body carried by two or more
    /// non-parallel joints turns about a changing axis (the MIM needs a regular
    /// `B(ω, ω̇)`). Starting posture `q0_i = 0` clamped into the range; `A_i` is
    /// flipped when `q0_i + A_i` would leave it, then shrunk to fit 90 % of the room
    /// left.
    pub fn paper(ranges: &[(f64, f64)]) -> RaisedCosine {
        let n = ranges.len();
        let mut q0 = vec![0.0; n];
        let mut amplitude = vec![0.0; n];
        let mut omega = vec![0.0; n];
        for (i, &(lower, upper)) in ranges.iter().enumerate() {
            omega[i] = PI * (0.9 + 0.23 * i as f64);
            let sign = if i.is_multiple_of(2) { 1.0 } else { -1.0 };
            // Narrow (prismatic) ranges get a quarter of their travel.
            let magnitude = (0.6 + 0.2 * (i % 4) as f64).min(0.25 * (upper - lower));
            let start = 0.0f64.clamp(lower, upper);
            let (room_up, room_down) = (upper - start, start - lower);
            let mut a = sign * magnitude;
            if (a > 0.0 && a > room_up) || (a < 0.0 && -a > room_down) {
                a = -a;
            }
            let room = if a > 0.0 { room_up } else { room_down };
            if a.abs() > 0.9 * room {
                a = a.signum() * 0.9 * room;
            }
            q0[i] = start;
            amplitude[i] = a;
        }
        RaisedCosine { q0, amplitude, omega }
    }
}

impl JointMotion for RaisedCosine {
    fn nv(&self) -> usize {
        self.q0.len()
    }

    fn eval(&self, t: f64, q: &mut [f64], v: &mut [f64], a: &mut [f64]) {
        check_out(self.nv(), q, v, a);
        for i in 0..self.nv() {
            let (amp, w) = (self.amplitude[i], self.omega[i]);
            let (s1, c1) = (w * t).sin_cos();
            let (s2, c2) = (2.0 * w * t).sin_cos();
            q[i] = self.q0[i] + amp * (1.0 - c1) * (1.0 - c1) / 4.0;
            v[i] = amp * w * (s1 - s2 / 2.0) / 2.0;
            a[i] = amp * w * w * (c1 - c2) / 2.0;
        }
    }
}

/// A finite Fourier series per joint (Swevers, Ganseman, Tükel, De Schutter and Van
/// Brussel, *Optimal robot excitation and identification*, IEEE TRA 13(5), 1997):
///
/// ```text
/// q_i(t) = q0_i + Σ_{l=1..L} [ a_il/(ω_f l) sin(ω_f l t) − b_il/(ω_f l) cos(ω_f l t) ]
/// v_i(t) =        Σ_{l=1..L} [ a_il cos(ω_f l t) + b_il sin(ω_f l t) ]
/// a_i(t) =        Σ_{l=1..L} ω_f l [ −a_il sin(ω_f l t) + b_il cos(ω_f l t) ]
/// ```
///
/// periodic with period `2π/ω_f`, so that measurements can be averaged over periods
/// and the spectrum is known. `a_il`, `b_il` are velocities (rad/s or m/s).
#[derive(Clone, Debug, PartialEq)]
pub struct FourierExcitation {
    /// `ω_f = 2π f_f`, rad/s.
    pub omega: f64,
    pub q0: Vec<f64>,
    /// `a_il`, row-major `n × L`.
    pub a: Vec<f64>,
    /// `b_il`, row-major `n × L`.
    pub b: Vec<f64>,
    pub harmonics: usize,
}

impl FourierExcitation {
    /// From the base frequency `f_f` in Hz, the offsets `q0` (`n`) and the
    /// coefficients `a[i][l−1]`, `b[i][l−1]` (`n` rows of `L`). Panics if the shapes
    /// disagree or `f_f ≤ 0`.
    pub fn new(base_frequency: f64, q0: Vec<f64>, a: &[Vec<f64>], b: &[Vec<f64>]) -> FourierExcitation {
        assert!(
            base_frequency > 0.0,
            "the base frequency must be positive, got {base_frequency}"
        );
        let n = q0.len();
        let harmonics = a.first().map_or(0, Vec::len);
        assert!(
            a.len() == n && b.len() == n && a.iter().chain(b).all(|row| row.len() == harmonics),
            "`a` and `b` must both be {n} rows of {harmonics} coefficients"
        );
        FourierExcitation {
            omega: 2.0 * PI * base_frequency,
            q0,
            a: a.concat(),
            b: b.concat(),
            harmonics,
        }
    }

    /// The period `2π/ω_f`, s.
    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }

    /// `a_il` (`l` from 1).
    pub fn a(&self, i: usize, l: usize) -> f64 {
        self.a[i * self.harmonics + l - 1]
    }

    /// `b_il` (`l` from 1).
    pub fn b(&self, i: usize, l: usize) -> f64 {
        self.b[i * self.harmonics + l - 1]
    }

    /// Bounds that hold at every instant, from the triangle inequality:
    /// `|q_i − q0_i| ≤ Σ_l r_il/(ω_f l)`, `|v_i| ≤ Σ_l r_il`, `|a_i| ≤ Σ_l ω_f l r_il`,
    /// `r_il = √(a_il² + b_il²)`; per joint, `(position, velocity, acceleration)`.
    pub fn amplitude_bounds(&self) -> Vec<(f64, f64, f64)> {
        (0..self.q0.len())
            .map(|i| {
                (1..=self.harmonics).fold((0.0, 0.0, 0.0), |(p, v, a), l| {
                    let r = self.a(i, l).hypot(self.b(i, l));
                    let wl = self.omega * l as f64;
                    (p + r / wl, v + r, a + r * wl)
                })
            })
            .collect()
    }
}

impl JointMotion for FourierExcitation {
    fn nv(&self) -> usize {
        self.q0.len()
    }

    fn eval(&self, t: f64, q: &mut [f64], v: &mut [f64], a: &mut [f64]) {
        check_out(self.nv(), q, v, a);
        q.copy_from_slice(&self.q0);
        v.fill(0.0);
        a.fill(0.0);
        for l in 1..=self.harmonics {
            let wl = self.omega * l as f64;
            let (s, c) = (wl * t).sin_cos();
            for i in 0..self.nv() {
                let (ail, bil) = (self.a(i, l), self.b(i, l));
                q[i] += (ail * s - bil * c) / wl;
                v[i] += ail * c + bil * s;
                a[i] += wl * (bil * c - ail * s);
            }
        }
    }
}

/// A joint motion given by samples (measured, say): `q`, `v`, `a` at the times `t`,
/// linearly interpolated in between and held constant outside, so that replaying it
/// at the sample times gives the samples back exactly. Lets the simulator run a
/// robot, with other parameters, along a motion that was recorded.
#[derive(Clone, Debug, PartialEq)]
pub struct SampledMotion {
    t: Vec<f64>,
    n: usize,
    /// `q`, `v`, `a` of sample `k`: `states[k][0..n]`, `[n..2n]`, `[2n..3n]`.
    states: Vec<Vec<f64>>,
}

impl SampledMotion {
    /// From a checked [`Trajectory`](crate::data::Trajectory) of measured data with
    /// velocities and accelerations; `None` when it has neither (estimate them
    /// first with [`with_derivatives`](crate::data::Trajectory::with_derivatives)).
    pub fn from_data(data: &crate::data::Trajectory) -> Option<SampledMotion> {
        let states = (0..data.len())
            .map(|k| {
                let (v, a) = (data.v(k)?, data.a(k)?);
                Some([data.q(k), v, a].concat())
            })
            .collect::<Option<Vec<_>>>()?;
        Some(SampledMotion {
            t: data.t().to_vec(),
            n: data.dof(),
            states,
        })
    }

    /// The sample times.
    pub fn times(&self) -> &[f64] {
        &self.t
    }
}

impl JointMotion for SampledMotion {
    fn nv(&self) -> usize {
        self.n
    }

    fn eval(&self, t: f64, q: &mut [f64], v: &mut [f64], a: &mut [f64]) {
        check_out(self.n, q, v, a);
        let k = self.t.partition_point(|&s| s <= t);
        let (lo, hi, w) = if k == 0 {
            (0, 0, 0.0)
        } else if k == self.t.len() {
            (k - 1, k - 1, 0.0)
        } else {
            (k - 1, k, (t - self.t[k - 1]) / (self.t[k] - self.t[k - 1]))
        };
        let (x, y) = (&self.states[lo], &self.states[hi]);
        for (i, out) in [q, v, a].into_iter().enumerate() {
            for (j, o) in out.iter_mut().enumerate() {
                let c = i * self.n + j;
                *o = x[c] + w * (y[c] - x[c]);
            }
        }
    }
}
