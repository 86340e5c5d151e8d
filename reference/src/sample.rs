//! Deterministic sampling for tests and benchmarks: joint states within limits (from
//! `dyngen_model::sample`, which the generator shares) and physically consistent
//! parameters around nominal.

use dyngen_model::math;
pub use dyngen_model::sample::{sample_states, SplitMix64, State};
use dyngen_model::{Inertial, Model};

/// Physically consistent standard parameters (`10 n`, as
/// [`Model::standard_params`]) scattered around the model's nominal ones by a
/// relative amount `rel ∈ [0, 1)`. Per body, drawn in this order:
///
/// - mass `m' = m · U[1 − rel, 1 + rel]`;
/// - centre of mass `c' = c + rel · ℓ · U[−1, 1]³`, with the length scale
///   `ℓ = |c| + √(tr I_c / m)`;
/// - the centroidal inertia keeps its principal axes; its second moments of mass
///   along them, `L_k = tr(J)/2 − J_k ≥ 0`, are each scaled by `U[1 − rel, 1 + rel]`
///   and the principal moments rebuilt as `J_k = Σ L − L_k`. Non-negative `L` is
///   exactly the triangle inequality, so the result stays physically consistent.
///
/// `rel = 0` gives the nominal parameters (up to rounding). Panics unless
/// `0 ≤ rel < 1`.
pub fn perturbed_params(model: &Model, seed: u64, rel: f64) -> Vec<f64> {
    assert!((0.0..1.0).contains(&rel), "`rel` must lie in [0, 1), got {rel}");
    let mut rng = SplitMix64::new(seed);
    let factor = |rng: &mut SplitMix64| rng.uniform(1.0 - rel, 1.0 + rel);
    let mut params = Vec::with_capacity(10 * model.dof());
    for body in &model.bodies {
        let nominal = &body.inertial;
        let mass = nominal.mass * factor(&mut rng);

        let trace = nominal.inertia[0][0] + nominal.inertia[1][1] + nominal.inertia[2][2];
        let length = math::norm(&nominal.com) + (trace / nominal.mass).sqrt();
        let mut com = nominal.com;
        for x in &mut com {
            *x += rel * length * rng.uniform(-1.0, 1.0);
        }

        let (moments, axes) = nominal.principal_axes();
        let half_trace = 0.5 * (moments[0] + moments[1] + moments[2]);
        let second_moments = moments.map(|j| (half_trace - j).max(0.0) * factor(&mut rng));
        let sum: f64 = second_moments.iter().sum();
        let principal = second_moments.map(|l| sum - l);
        let diagonal = [
            [principal[0], 0.0, 0.0],
            [0.0, principal[1], 0.0],
            [0.0, 0.0, principal[2]],
        ];
        let inertia = math::rotate_inertia(&axes, &diagonal);

        params.extend(Inertial { mass, com, inertia }.standard_params());
    }
    params
}
