//! Deterministic sampling of joint states, from a tiny PRNG whose output is fixed
//! forever (no dependency on `rand`, whose streams may change between versions).
//! [`sample_states`] (within each joint's limits) serves the runtime (tests,
//! benchmarks, simulation); [`structure_states`] (full ranges, limits ignored) serves
//! the base-parameter analysis.

use crate::{JointKind, Model};
use std::f64::consts::PI;

/// SplitMix64 (Steele, Lea and Flood, *Fast splittable pseudorandom number
/// generators*, OOPSLA 2014; Vigna's public-domain reference code): a 64-bit state
/// advanced by the golden-ratio increment `0x9E3779B97F4A7C15`, output through a
/// bijective mixer. Small, fast, statistically fine for sampling; not for
/// cryptography. The stream for a given seed is part of this crate's stable API.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64 { state: seed }
    }

    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`: the top 53 bits as a fraction of `2⁵³`.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi)` (`lo` when they are equal).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
}

/// One joint-space state: `nq` positions (a unit quaternion per ball joint and free
/// flyer), `nv` velocities and `nv` accelerations.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
}

/// `count` states drawn from [`SplitMix64`] seeded with `seed`: `q_i` uniform in
/// `[−π, π]` (rotation) or `[−0.5, 0.5]` m (translation), narrowed to joint `i`'s
/// limits when it has them; ball joints and free flyers a uniform rotation (free-flyer
/// positions in `[−1, 1]` m), planar joints `[x, y]` in `[−1, 1]` m and the angle in
/// `[−π, π]`; `v_i` and `a_i` uniform in `[−2, 2]`.
///
/// The draw order is fixed (per state: all `q`, then all `v`, then all `a`), so
/// the same model, count and seed give the same states in every version.
pub fn sample_states(model: &Model, count: usize, seed: u64) -> Vec<State> {
    draw(model, count, seed, true)
}

/// `count` states for analysing the structure of the dynamics (which columns of a
/// regressor are independent), from [`SplitMix64`] seeded with `seed`: `q_i` uniform
/// in `[−π, π]` for every revolute and continuous joint and in `[−0.5, 0.5]` m for
/// every prismatic joint, whatever the limits say; `v_i` and `a_i` uniform in
/// `[−2, 2]`. Same draw order as [`sample_states`].
///
/// The limits are ignored on purpose: the regressor is a trigonometric polynomial in
/// the revolute angles and a polynomial in the prismatic displacements whatever the
/// limits, so its rank over the full range is its rank anywhere generic, while
/// placeholder limits (`lower = upper = 0`, or a narrow range) would pin a joint and
/// hide parameters. A prismatic range wider than ±0.5 m would add nothing but scale.
pub fn structure_states(model: &Model, count: usize, seed: u64) -> Vec<State> {
    draw(model, count, seed, false)
}

/// The draws of [`sample_states`] (`within_limits`) and [`structure_states`].
fn draw(model: &Model, count: usize, seed: u64, within_limits: bool) -> Vec<State> {
    let mut rng = SplitMix64::new(seed);
    (0..count)
        .map(|_| {
            let mut q = Vec::with_capacity(model.nq());
            // A follower (`<mimic>`) moves with its leader's coordinate.
            for j in model.joints.iter().filter(|j| j.mimic.is_none()) {
                match j.kind {
                    JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic => {
                        // One turn, or ±0.5 m, within the limits when asked and there
                        // are any (a model written without limits carries wide
                        // placeholders).
                        let reach = if j.kind == JointKind::Prismatic { 0.5 } else { PI };
                        q.push(match j.limits {
                            Some(l) if within_limits => rng.uniform(l.lower.max(-reach), l.upper.min(reach)),
                            _ => rng.uniform(-reach, reach),
                        });
                    }
                    JointKind::Spherical => q.extend(unit_quaternion(&mut rng)),
                    JointKind::FreeFlyer => {
                        q.extend((0..3).map(|_| rng.uniform(-1.0, 1.0)));
                        q.extend(unit_quaternion(&mut rng));
                    }
                    JointKind::Planar => {
                        q.extend((0..2).map(|_| rng.uniform(-1.0, 1.0)));
                        q.push(rng.uniform(-PI, PI));
                    }
                }
            }
            let v = (0..model.nv()).map(|_| rng.uniform(-2.0, 2.0)).collect();
            let a = (0..model.nv()).map(|_| rng.uniform(-2.0, 2.0)).collect();
            State { q, v, a }
        })
        .collect()
}

/// A unit quaternion `[x, y, z, w]`, uniform over rotations: four draws uniform in
/// `[−1, 1]` kept when their norm is in `[0.1, 1]` (rejection from the unit ball),
/// then normalised.
fn unit_quaternion(rng: &mut SplitMix64) -> [f64; 4] {
    loop {
        let x = [0; 4].map(|_| rng.uniform(-1.0, 1.0));
        let n = x.iter().map(|c| c * c).sum::<f64>().sqrt();
        if (0.1..=1.0).contains(&n) {
            return x.map(|c| c / n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_matches_the_reference_stream() {
        // First outputs of Vigna's splitmix64.c seeded with 1234567.
        let mut rng = SplitMix64::new(1234567);
        let expected = [6457827717110365317u64, 3203168211198807973, 9817491932198370423];
        for e in expected {
            assert_eq!(rng.next_u64(), e);
        }
    }

    #[test]
    fn uniform_stays_in_range() {
        let mut rng = SplitMix64::new(7);
        for _ in 0..10_000 {
            let x = rng.uniform(-2.0, 3.0);
            assert!((-2.0..3.0).contains(&x));
        }
    }
}
