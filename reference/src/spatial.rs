//! Spatial values with `nalgebra` types, in Pinocchio's ordering: motion vectors
//! `[linear; angular]`. The algebra itself is `dyngen_algo::spatial`.

use dyngen_model::math::{Mat3, Vec3};
use nalgebra::{Matrix3, Vector3, Vector6};

/// A spatial motion vector with named parts: the linear velocity (or acceleration)
/// of the point at the frame origin, and the angular velocity (or acceleration).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    pub linear: Vector3<f64>,
    pub angular: Vector3<f64>,
}

impl Motion {
    /// Stacks `[v; ω]`.
    pub fn to_vector(&self) -> Vector6<f64> {
        let (v, w) = (self.linear, self.angular);
        Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z)
    }
}

/// A 3-vector of the model crate as a column vector.
pub fn vec3(v: &Vec3) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// A row-major 3×3 matrix of the model crate as a matrix.
pub fn mat3(m: &Mat3) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| m[r][c])
}
