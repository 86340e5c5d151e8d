//! The polynomial sine and cosine every number and lane type computes with, against
//! the standard library's: within 2 units in the last place over the whole range it
//! is used on (dense random points and the neighbourhoods of multiples of π/2), and
//! the standard library's own beyond it.

use dyngen_algo::{polynomial_sin_cos, Precision, Real};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `|got − want|` in units in the last place of `want` (of at least the smallest
/// normal's, so that values near zero are judged absolutely).
fn ulps(got: f64, want: f64, epsilon: f64, tiny: f64) -> f64 {
    (got - want).abs() / (epsilon * want.abs().max(tiny))
}

fn points(limit: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut x: Vec<f64> = (0..100_000).map(|_| rng.gen_range(-4.0..4.0)).collect();
    x.extend((0..100_000).map(|_| rng.gen_range(-limit..limit)));
    // Around multiples of π/2, where the reduction cancels most.
    for k in -200..=200 {
        let c = k as f64 * core::f64::consts::FRAC_PI_2;
        x.extend((-5..=5).map(|d| c + d as f64 * 1e-9));
    }
    x
}

#[test]
fn double_within_two_ulps_of_std() {
    let mut worst: f64 = 0.0;
    for x in points(Precision::Double.limit(), 1) {
        let (s, c) = polynomial_sin_cos((), x, Precision::Double);
        worst = worst
            .max(ulps(s, x.sin(), f64::EPSILON, 1e-3))
            .max(ulps(c, x.cos(), f64::EPSILON, 1e-3));
        let (rs, rc) = Real::sin_cos(x);
        assert_eq!(
            (rs.to_bits(), rc.to_bits()),
            (s.to_bits(), c.to_bits()),
            "f64 uses it at {x}"
        );
    }
    assert!(worst <= 2.0, "worst {worst} ulps");
    assert!(worst > 0.0, "differs from the standard library somewhere: not its copy");
}

#[test]
fn single_within_two_ulps_of_the_rounded_value() {
    let mut worst: f64 = 0.0;
    for x in points(Precision::Single.limit(), 2) {
        let x = x as f32;
        let (s, c) = polynomial_sin_cos((), x, Precision::Single);
        let (ws, wc) = (x as f64).sin_cos();
        worst =
            worst
                .max(ulps(s as f64, ws, f32::EPSILON as f64, 1e-3))
                .max(ulps(c as f64, wc, f32::EPSILON as f64, 1e-3));
        let (rs, rc) = Real::sin_cos(x);
        assert_eq!(
            (rs.to_bits(), rc.to_bits()),
            (s.to_bits(), c.to_bits()),
            "f32 uses it at {x}"
        );
    }
    assert!(worst <= 2.0, "worst {worst} ulps");
}

#[test]
fn beyond_the_limit_the_standard_library() {
    for x in [1.0e5, -7.0e5, 1.0e300, f64::INFINITY, f64::NAN] {
        let (s, c) = Real::sin_cos(x);
        let (ws, wc) = x.sin_cos();
        assert!(s.to_bits() == ws.to_bits() || (s.is_nan() && ws.is_nan()), "{x}");
        assert!(c.to_bits() == wc.to_bits() || (c.is_nan() && wc.is_nan()), "{x}");
    }
    let (s, c) = Real::sin_cos(1.0e4f32);
    assert_eq!((s, c), 1.0e4f32.sin_cos());
}
