//! Comparisons and conversions both reference test files use.

// Each test file is its own crate and uses only some of these.
#![allow(dead_code)]

use dyngen_reference::State;
use nalgebra::{Matrix3, Vector3};

/// `|actual − expected| ≤ tol (1 + |expected|)` entry by entry.
pub fn assert_close(actual: &[f64], expected: &[f64], tol: f64, what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}: lengths");
    for (k, (a, e)) in actual.iter().zip(expected).enumerate() {
        assert!(
            (a - e).abs() <= tol * (1.0 + e.abs()),
            "{what}[{k}]: {a} vs {e} (tol {tol})\n{actual:?}\n{expected:?}"
        );
    }
}

pub fn assert_vec3_close(actual: &Vector3<f64>, expected: &Vector3<f64>, tol: f64, what: &str) {
    assert_close(actual.as_slice(), expected.as_slice(), tol, what);
}

pub fn mat3(m: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| m[r][c])
}

pub fn vec3(v: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// The state along `q(t) = q + t q̇ + ½ t² q̈`, `q̇(t) = q̇ + t q̈`.
pub fn advance(s: &State, t: f64) -> State {
    State {
        q: (0..s.q.len())
            .map(|k| s.q[k] + t * s.v[k] + 0.5 * t * t * s.a[k])
            .collect(),
        v: (0..s.q.len()).map(|k| s.v[k] + t * s.a[k]).collect(),
        a: s.a.clone(),
    }
}
