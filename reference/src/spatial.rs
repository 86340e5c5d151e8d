//! 6D spatial algebra (Featherstone, *Rigid Body Dynamics Algorithms*, ch. 2) in
//! Pinocchio's ordering: motion vectors `[linear; angular]`, force vectors
//! `[force; torque]`. Everything is a plain 6×6 matrix or 6-vector, as in the book,
//! so that each line of an algorithm reads like its equation.

use dyngen_model::math::{Mat3, Vec3};
use dyngen_model::Placement;
use nalgebra::{Matrix3, Matrix6, SMatrix, Vector3, Vector6};

/// A spatial motion `[v; ω]` or force `[f; n]` vector, in some body's coordinates.
pub type SpatialVector = Vector6<f64>;
/// A spatial transform, inertia or cross-product operator.
pub type SpatialMatrix = Matrix6<f64>;
/// A body's spatial force as a linear function of its 10 standard parameters
/// (see [`force_regressor`]).
pub type ForceRegressor = SMatrix<f64, 6, 10>;

/// A spatial motion vector with named parts: the linear velocity (or acceleration)
/// of the point at the frame origin, and the angular velocity (or acceleration).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    pub linear: Vector3<f64>,
    pub angular: Vector3<f64>,
}

impl Motion {
    /// Splits `[v; ω]`.
    pub fn from_vector(m: &SpatialVector) -> Motion {
        Motion {
            linear: m.fixed_rows::<3>(0).into(),
            angular: m.fixed_rows::<3>(3).into(),
        }
    }

    /// Stacks `[v; ω]`.
    pub fn to_vector(&self) -> SpatialVector {
        stack(&self.linear, &self.angular)
    }
}

/// `[top; bottom]`.
pub fn stack(top: &Vector3<f64>, bottom: &Vector3<f64>) -> SpatialVector {
    Vector6::new(top.x, top.y, top.z, bottom.x, bottom.y, bottom.z)
}

/// A 3-vector of the model crate as a column vector.
pub fn vec3(v: &Vec3) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// A row-major 3×3 matrix of the model crate as a matrix.
pub fn mat3(m: &Mat3) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| m[r][c])
}

/// The cross-product matrix `[x]×`, with `[x]× y = x × y`.
pub fn skew(x: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -x.z, x.y, x.z, 0.0, -x.x, -x.y, x.x, 0.0)
}

/// Rotation by `angle` about the unit vector `axis` (Rodrigues):
/// `R = E + sin θ [k]× + (1 − cos θ) [k]×²`.
pub fn rotation_about(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    let k = skew(axis);
    let (s, c) = angle.sin_cos();
    Matrix3::identity() + k * s + k * k * (1.0 - c)
}

/// The placement of a frame B in a frame A: `x_A = E x_B + r` (Pinocchio's `SE3`,
/// `aMb`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// `E`: B's axes in A coordinates.
    pub rotation: Matrix3<f64>,
    /// `r`: B's origin in A coordinates.
    pub translation: Vector3<f64>,
}

impl Transform {
    pub fn identity() -> Transform {
        Transform {
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        }
    }

    pub fn from_placement(p: &Placement) -> Transform {
        Transform {
            rotation: mat3(&p.rotation),
            translation: vec3(&p.translation),
        }
    }

    /// `aMc = aMb · bMc` for `self = aMb`: first `other`, then `self`.
    pub fn compose(&self, other: &Transform) -> Transform {
        Transform {
            rotation: self.rotation * other.rotation,
            translation: self.rotation * other.translation + self.translation,
        }
    }

    /// Featherstone's `ᴮX_A`: maps a motion vector from A coordinates to B
    /// coordinates (moving the reference point from A's origin to B's),
    ///
    /// ```text
    /// ᴮX_A = [ Eᵀ   −Eᵀ[r]× ]
    ///        [ 0     Eᵀ     ]
    /// ```
    ///
    /// Its transpose `(ᴮX_A)ᵀ = ᴬX*_B` maps a force vector from B to A.
    pub fn motion_matrix(&self) -> SpatialMatrix {
        let et = self.rotation.transpose();
        let mut x = SpatialMatrix::zeros();
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&et);
        x.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-et * skew(&self.translation)));
        x.fixed_view_mut::<3, 3>(3, 3).copy_from(&et);
        x
    }
}

/// The motion cross-product operator `v×` (Featherstone's `crm`), for
/// `v = [v; ω]`:
///
/// ```text
/// v× = [ [ω]×  [v]× ]
///      [ 0     [ω]× ]
/// ```
///
/// `v × m` is the rate of change of a motion vector `m` fixed in a body moving
/// with velocity `v`.
pub fn cross_motion(v: &SpatialVector) -> SpatialMatrix {
    let (lin, ang) = (v.fixed_rows::<3>(0).into(), v.fixed_rows::<3>(3).into());
    let mut x = SpatialMatrix::zeros();
    x.fixed_view_mut::<3, 3>(0, 0).copy_from(&skew(&ang));
    x.fixed_view_mut::<3, 3>(0, 3).copy_from(&skew(&lin));
    x.fixed_view_mut::<3, 3>(3, 3).copy_from(&skew(&ang));
    x
}

/// The force cross-product operator `v×* = −(v×)ᵀ` (Featherstone's `crf`):
///
/// ```text
/// v×* = [ [ω]×  0    ]
///       [ [v]×  [ω]× ]
/// ```
pub fn cross_force(v: &SpatialVector) -> SpatialMatrix {
    -cross_motion(v).transpose()
}

/// The spatial inertia of a body about its frame origin, from its 10 standard
/// parameters `[m, h_x, h_y, h_z, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (`h = m c`, `I`
/// about the origin):
///
/// ```text
/// I = [ m E     −[h]× ]
///     [ [h]×     I_o  ]
/// ```
///
/// so that `I [v; ω] = [m (v + ω × c); I_o ω + c × m v]` (momentum and angular
/// momentum about the origin). Linear in the parameters.
///
/// Panics if `params` does not have 10 entries.
pub fn spatial_inertia(params: &[f64]) -> SpatialMatrix {
    assert_eq!(params.len(), 10, "one body has 10 standard parameters");
    let m = params[0];
    let h = Vector3::new(params[1], params[2], params[3]);
    #[rustfmt::skip]
    let inertia = Matrix3::new(
        params[4], params[5], params[7],
        params[5], params[6], params[8],
        params[7], params[8], params[9],
    );
    let mut x = SpatialMatrix::zeros();
    x.fixed_view_mut::<3, 3>(0, 0).copy_from(&(Matrix3::identity() * m));
    x.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew(&h)));
    x.fixed_view_mut::<3, 3>(3, 0).copy_from(&skew(&h));
    x.fixed_view_mut::<3, 3>(3, 3).copy_from(&inertia);
    x
}

/// `L(w)` (3 × 6) with `I w = L(w) ι` for the six entries of a symmetric inertia in
/// Pinocchio's order `ι = [Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`:
///
/// ```text
/// L(w) = [ w1  w2  0   w3  0   0  ]
///        [ 0   w1  w2  0   w3  0  ]
///        [ 0   0   0   w1  w2  w3 ]
/// ```
pub fn inertia_product_matrix(w: &Vector3<f64>) -> SMatrix<f64, 3, 6> {
    #[rustfmt::skip]
    let l = SMatrix::<f64, 3, 6>::new(
        w.x, w.y, 0.0, w.z, 0.0, 0.0,
        0.0, w.x, w.y, 0.0, w.z, 0.0,
        0.0, 0.0, 0.0, w.x, w.y, w.z,
    );
    l
}

/// The body regressor (Atkeson, An and Hollerbach 1986; Pinocchio's
/// `bodyRegressor`): the net spatial force a body needs, `f = I a + v ×* I v`, is
/// linear in its standard parameters `π = [m, h, ι]` (`h = m c`, `ι` the inertia
/// about the origin, see [`spatial_inertia`]), `f = A(v, a) π` with, for
/// `v = [v; ω]` and `a = [a; ω̇]`,
///
/// ```text
/// force  = m (a + ω × v) + ([ω̇]× + [ω]×²) h
/// torque = −[a + ω × v]× h + (L(ω̇) + [ω]× L(ω)) ι
/// ```
///
/// (`L` from [`inertia_product_matrix`]). Gravity enters through `a` when the
/// base is given the acceleration `−a_g`.
pub fn force_regressor(v: &SpatialVector, a: &SpatialVector) -> ForceRegressor {
    let (lin, w): (Vector3<f64>, Vector3<f64>) = (v.fixed_rows::<3>(0).into(), v.fixed_rows::<3>(3).into());
    let (acc, dw): (Vector3<f64>, Vector3<f64>) = (a.fixed_rows::<3>(0).into(), a.fixed_rows::<3>(3).into());
    let classical = acc + w.cross(&lin);
    let mut y = ForceRegressor::zeros();
    // force
    y.fixed_view_mut::<3, 1>(0, 0).copy_from(&classical);
    y.fixed_view_mut::<3, 3>(0, 1)
        .copy_from(&(skew(&dw) + skew(&w) * skew(&w)));
    // torque
    y.fixed_view_mut::<3, 3>(3, 1).copy_from(&(-skew(&classical)));
    y.fixed_view_mut::<3, 6>(3, 4)
        .copy_from(&(inertia_product_matrix(&dw) + skew(&w) * inertia_product_matrix(&w)));
    y
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Unit};

    fn close(a: &SpatialMatrix, b: &SpatialMatrix, tol: f64) -> bool {
        (a - b).amax() <= tol
    }

    fn sample_transform() -> Transform {
        let axis = Vector3::new(0.3, -0.5, 0.8).normalize();
        Transform {
            rotation: rotation_about(&axis, 0.7),
            translation: Vector3::new(0.1, -0.4, 0.25),
        }
    }

    #[test]
    fn rodrigues_matches_nalgebra() {
        let axis = Vector3::new(-0.2, 0.9, 0.4).normalize();
        for angle in [-3.0, -0.4, 0.0, 1.3, 2.9] {
            let expected = Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle);
            assert!((rotation_about(&axis, angle) - expected.matrix()).amax() < 1e-15);
        }
    }

    #[test]
    fn motion_matrix_composes_and_inverts() {
        let a_m_b = sample_transform();
        let b_m_c = Transform {
            rotation: rotation_about(&Vector3::x(), -1.1),
            translation: Vector3::new(0.0, 0.3, -0.2),
        };
        let a_m_c = a_m_b.compose(&b_m_c);
        // ᶜX_A = ᶜX_B ᴮX_A
        let composed = b_m_c.motion_matrix() * a_m_b.motion_matrix();
        assert!(close(&a_m_c.motion_matrix(), &composed, 1e-15));
        // ᴮX_A is invertible with the inverse placement's matrix.
        let inv = Transform {
            rotation: a_m_b.rotation.transpose(),
            translation: -a_m_b.rotation.transpose() * a_m_b.translation,
        };
        assert!(close(
            &(inv.motion_matrix() * a_m_b.motion_matrix()),
            &SpatialMatrix::identity(),
            1e-15
        ));
    }

    #[test]
    fn motion_matrix_moves_the_reference_point() {
        // A pure rotation ω about A's origin, seen at B's origin r: v = ω × r.
        let t = sample_transform();
        let omega = Vector3::new(0.2, 1.0, -0.7);
        let in_b = t.motion_matrix() * stack(&Vector3::zeros(), &omega);
        let expected_lin = t.rotation.transpose() * omega.cross(&t.translation);
        assert!((in_b.fixed_rows::<3>(0) - expected_lin).amax() < 1e-15);
        assert!((in_b.fixed_rows::<3>(3) - t.rotation.transpose() * omega).amax() < 1e-15);
    }

    #[test]
    fn power_is_invariant() {
        // fᵀ v is the same in both frames: (ᴮX_A v)ᵀ f_B = vᵀ (ᴮX_Aᵀ f_B).
        let x = sample_transform().motion_matrix();
        let v = SpatialVector::new(0.1, 0.2, -0.3, 0.4, -0.5, 0.6);
        let f = SpatialVector::new(1.0, -2.0, 0.5, 0.3, 0.0, -0.7);
        assert!(((x * v).dot(&f) - v.dot(&(x.transpose() * f))).abs() < 1e-15);
    }

    #[test]
    fn cross_products_match_3d_formulas() {
        let v = SpatialVector::new(0.3, -0.1, 0.8, 1.2, -0.4, 0.5);
        let m = SpatialVector::new(-0.6, 0.2, 0.1, 0.7, 0.9, -1.1);
        let (lin, ang) = (v.fixed_rows::<3>(0).into_owned(), v.fixed_rows::<3>(3).into_owned());
        let (m_lin, m_ang) = (m.fixed_rows::<3>(0).into_owned(), m.fixed_rows::<3>(3).into_owned());
        let expected = stack(&(ang.cross(&m_lin) + lin.cross(&m_ang)), &ang.cross(&m_ang));
        assert!((cross_motion(&v) * m - expected).amax() < 1e-15);
        let expected = stack(&ang.cross(&m_lin), &(lin.cross(&m_lin) + ang.cross(&m_ang)));
        assert!((cross_force(&v) * m - expected).amax() < 1e-15);
        // v × v = 0
        assert!((cross_motion(&v) * v).amax() < 1e-15);
    }

    #[test]
    fn spatial_inertia_gives_momentum() {
        let (m, c) = (2.0, Vector3::new(0.1, -0.2, 0.3));
        let ic = Matrix3::new(0.05, 0.01, 0.0, 0.01, 0.04, -0.002, 0.0, -0.002, 0.03);
        let io: Matrix3<f64> = ic + m * (Matrix3::identity() * c.norm_squared() - c * c.transpose());
        let params = [
            m,
            m * c.x,
            m * c.y,
            m * c.z,
            io[(0, 0)],
            io[(0, 1)],
            io[(1, 1)],
            io[(0, 2)],
            io[(1, 2)],
            io[(2, 2)],
        ];
        let (v, w) = (Vector3::new(0.4, 0.1, -0.3), Vector3::new(-1.0, 0.5, 0.2));
        let h = spatial_inertia(&params) * stack(&v, &w);
        let momentum = m * (v + w.cross(&c));
        // Angular momentum about the origin: centroidal part plus c × momentum.
        let angular = ic * w + c.cross(&momentum);
        assert!((h.fixed_rows::<3>(0) - momentum).amax() < 1e-15);
        assert!((h.fixed_rows::<3>(3) - angular).amax() < 1e-15);
    }
    #[test]
    fn force_regressor_columns_are_forces_of_unit_parameters() {
        // Column k of A(v, a) is the force of a "body" whose only parameter is π_k = 1.
        let v = SpatialVector::new(0.3, -0.1, 0.8, 1.2, -0.4, 0.5);
        let a = SpatialVector::new(-0.6, 0.2, 0.1, 0.7, 0.9, -1.1);
        let y = force_regressor(&v, &a);
        for k in 0..10 {
            let mut unit = [0.0; 10];
            unit[k] = 1.0;
            let inertia = spatial_inertia(&unit);
            let f = inertia * a + cross_force(&v) * (inertia * v);
            assert!((y.column(k) - f).amax() < 1e-15, "column {k}");
        }
        let w = Vector3::new(0.4, -0.3, 0.2);
        let iota = [1.0, 0.1, 2.0, -0.2, 0.3, 3.0];
        #[rustfmt::skip]
        let i = Matrix3::new(1.0, 0.1, -0.2, 0.1, 2.0, 0.3, -0.2, 0.3, 3.0);
        let l = inertia_product_matrix(&w) * nalgebra::Vector6::from_column_slice(&iota);
        assert!((l - i * w).amax() < 1e-15);
    }
}
