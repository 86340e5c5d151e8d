//! Cardano angles, the orientation the paper measures (docs/design.md, "The paper's decoupled body model"): `R = Rx(α1)
//! Ry(α2) Rz(α3)` (x–y–z, each rotation about the axis already turned by the ones
//! before it), and their rates from the body-axes angular velocity.
//!
//! ```text
//! R = [  c2c3             −c2s3              s2   ]
//!     [  c1s3 + s1s2c3     c1c3 − s1s2s3    −s1c2 ]
//!     [  s1s3 − c1s2c3     s1c3 + c1s2s3     c1c2 ]
//! ```

use nalgebra::{Matrix3, Vector3};

/// `R = Rx(α1) Ry(α2) Rz(α3)`.
pub fn cardano_matrix(alpha: &Vector3<f64>) -> Matrix3<f64> {
    let (s1, c1) = alpha.x.sin_cos();
    let (s2, c2) = alpha.y.sin_cos();
    let (s3, c3) = alpha.z.sin_cos();
    #[rustfmt::skip]
    let r = Matrix3::new(
        c2 * c3,                 -c2 * s3,                 s2,
        c1 * s3 + s1 * s2 * c3,   c1 * c3 - s1 * s2 * s3, -s1 * c2,
        s1 * s3 - c1 * s2 * c3,   s1 * c3 + c1 * s2 * s3,  c1 * c2,
    );
    r
}

/// The Cardano angles of a rotation matrix, with `α2 = asin(R13) ∈ [−π/2, π/2]`,
/// `α1 = atan2(−R23, R33)`, `α3 = atan2(−R12, R11)` (both in `(−π, π]`). At the
/// gimbal lock `|α2| = π/2` only `α1 ± α3` is defined; this returns one valid split.
pub fn cardano_angles(r: &Matrix3<f64>) -> Vector3<f64> {
    let alpha2 = r[(0, 2)].clamp(-1.0, 1.0).asin();
    let alpha1 = (-r[(1, 2)]).atan2(r[(2, 2)]);
    let alpha3 = (-r[(0, 1)]).atan2(r[(0, 0)]);
    if alpha2.cos() < 1e-12 {
        // Gimbal lock, α3 = 0: R21 = s1 s2, R22 = c1.
        let alpha1 = (r[(1, 0)] * alpha2.signum()).atan2(r[(1, 1)]);
        return Vector3::new(alpha1, alpha2, 0.0);
    }
    Vector3::new(alpha1, alpha2, alpha3)
}

/// `K(α)` with `ω = K(α) α̇`, `ω` the angular velocity in body axes (docs/design.md, "The paper's decoupled body model"):
///
/// ```text
/// K = [  c2c3   s3   0 ]
///     [ −c2s3   c3   0 ]
///     [  s2     0    1 ]
/// ```
///
/// singular at the gimbal lock `c2 = 0`.
pub fn cardano_rate_matrix(alpha: &Vector3<f64>) -> Matrix3<f64> {
    let (s2, c2) = alpha.y.sin_cos();
    let (s3, c3) = alpha.z.sin_cos();
    Matrix3::new(c2 * c3, s3, 0.0, -c2 * s3, c3, 0.0, s2, 0.0, 1.0)
}

/// `α̇ = K(α)⁻¹ ω` in closed form:
/// `α̇1 = (c3 ω1 − s3 ω2) / c2`, `α̇2 = s3 ω1 + c3 ω2`, `α̇3 = ω3 − s2 α̇1`.
/// Infinite or NaN at the gimbal lock.
pub fn cardano_rates(alpha: &Vector3<f64>, omega: &Vector3<f64>) -> Vector3<f64> {
    let (s2, c2) = alpha.y.sin_cos();
    let (s3, c3) = alpha.z.sin_cos();
    let rate1 = (c3 * omega.x - s3 * omega.y) / c2;
    Vector3::new(rate1, s3 * omega.x + c3 * omega.y, omega.z - s2 * rate1)
}

/// `x` shifted by a multiple of `2π` to lie within `π` of `previous`: keeps an angle
/// continuous along a recording.
pub(crate) fn unwrap_angle(x: f64, previous: f64) -> f64 {
    let turn = std::f64::consts::TAU;
    x - turn * ((x - previous) / turn).round()
}
