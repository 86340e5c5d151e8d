//! Frames and their kinematics: the value types of the generated frame functions and
//! the change of reference frame, in Pinocchio's conventions. Generated code computes
//! everything `LOCAL_WORLD_ALIGNED` (at the frame origin, world axes); the other two
//! reference frames follow from the frame's placement in a few products.

use crate::{OrderedScalar, Pose, Scalar};
use nalgebra::{Matrix3, SMatrix, Vector3};

/// In which frame a velocity, an acceleration or a Jacobian is expressed, as
/// Pinocchio's `ReferenceFrame`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ReferenceFrame {
    /// The frame's own axes, at its origin (Pinocchio's `LOCAL`).
    Local,
    /// World axes, at the frame's origin (Pinocchio's `LOCAL_WORLD_ALIGNED`): the
    /// linear part is the velocity of the frame origin as a world vector. What
    /// operational-space controllers usually want.
    #[default]
    LocalWorldAligned,
    /// World axes, at the world origin (Pinocchio's `WORLD`): the spatial velocity of
    /// the body seen at the world origin.
    World,
}

/// A spatial motion vector (a twist, or an acceleration) with named parts: linear
/// first, then angular, as Pinocchio orders them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion<S: Scalar> {
    pub linear: Vector3<S>,
    pub angular: Vector3<S>,
}

impl<S: Scalar> Default for Motion<S> {
    fn default() -> Self {
        Motion {
            linear: Vector3::from_element(S::ZERO),
            angular: Vector3::from_element(S::ZERO),
        }
    }
}

impl<S: Scalar> Motion<S> {
    /// `[linear; angular]`.
    pub fn to_array(&self) -> [S; 6] {
        let (l, a) = (&self.linear, &self.angular);
        [l[0], l[1], l[2], a[0], a[1], a[2]]
    }
}

/// A frame's placement and its Jacobian `J` (6 × N, rows `[linear; angular]`,
/// column `k` the motion of the frame for a unit velocity of joint `k`), the output of
/// the generated `frame_jacobian`. Columns of joints that do not move the frame are
/// exact zeros.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameJacobian<S: Scalar, const N: usize> {
    /// The frame in the world: `x_world = rotation · x_frame + translation`.
    pub placement: Pose<S>,
    pub jacobian: [[S; N]; 6],
}

impl<S: Scalar, const N: usize> Default for FrameJacobian<S, N> {
    fn default() -> Self {
        FrameJacobian {
            placement: Pose::default(),
            jacobian: [[S::ZERO; N]; 6],
        }
    }
}

impl<S: Scalar, const N: usize> FrameJacobian<S, N> {
    /// The frame's velocity `J · v` for joint velocities `v`, in the reference frame
    /// the Jacobian is expressed in.
    pub fn velocity(&self, v: &[S; N]) -> Motion<S> {
        let row = |r: usize| {
            let mut s = S::ZERO;
            for k in 0..N {
                s += self.jacobian[r][k] * v[k];
            }
            s
        };
        Motion {
            linear: Vector3::new(row(0), row(1), row(2)),
            angular: Vector3::new(row(3), row(4), row(5)),
        }
    }

    /// The Jacobian as an nalgebra matrix (6 × N). (`SMatrix::from` of the nested
    /// array would read its rows as columns.)
    pub fn matrix(&self) -> SMatrix<S, 6, N> {
        SMatrix::from_fn(|r, c| self.jacobian[r][c])
    }

    /// Re-expresses a `LOCAL_WORLD_ALIGNED` Jacobian (as the generated code writes it)
    /// in `reference`.
    pub(crate) fn express_from_lwa(&mut self, reference: ReferenceFrame) {
        for k in 0..N {
            let column = Motion {
                linear: Vector3::new(self.jacobian[0][k], self.jacobian[1][k], self.jacobian[2][k]),
                angular: Vector3::new(self.jacobian[3][k], self.jacobian[4][k], self.jacobian[5][k]),
            };
            let c = velocity_from_lwa(&self.placement, &column, reference).to_array();
            for r in 0..6 {
                self.jacobian[r][k] = c[r];
            }
        }
    }
}

/// A frame's placement, Jacobian `J` and its time variation `J̇(q, v)` (6 × N each,
/// rows `[linear; angular]`), both in the same reference frame, the output of the
/// generated `frame_jacobian_time_variation` (Pinocchio's
/// `getFrameJacobianTimeVariation`): `ẍ = J q̈ + J̇ q̇` in that frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameJacobianTimeVariation<S: Scalar, const N: usize> {
    pub placement: Pose<S>,
    pub jacobian: [[S; N]; 6],
    pub jacobian_dot: [[S; N]; 6],
}

impl<S: Scalar, const N: usize> Default for FrameJacobianTimeVariation<S, N> {
    fn default() -> Self {
        FrameJacobianTimeVariation {
            placement: Pose::default(),
            jacobian: [[S::ZERO; N]; 6],
            jacobian_dot: [[S::ZERO; N]; 6],
        }
    }
}

impl<S: Scalar, const N: usize> FrameJacobianTimeVariation<S, N> {
    /// Re-expresses `LOCAL_WORLD_ALIGNED` `J` and `J̇` (as the generated code writes
    /// them) in `reference`, with the joint velocities `v` they were taken at:
    /// `LOCAL`: `J̇_l = Rᵀ (J̇ − ω × J)`; `WORLD`: `J̇_w = [J̇_lin + ṗ × J_ang + p × J̇_ang;
    /// J̇_ang]`, `ω` and `ṗ` the frame's angular and linear velocity.
    pub(crate) fn express_from_lwa(&mut self, v: &[S; N], reference: ReferenceFrame) {
        if reference == ReferenceFrame::LocalWorldAligned {
            return;
        }
        let col = |m: &[[S; N]; 6], k: usize, r0: usize| Vector3::new(m[r0][k], m[r0 + 1][k], m[r0 + 2][k]);
        let mut w = Vector3::from_element(S::ZERO);
        let mut pdot = Vector3::from_element(S::ZERO);
        for k in 0..N {
            pdot += col(&self.jacobian, k, 0) * v[k];
            w += col(&self.jacobian, k, 3) * v[k];
        }
        let p = self.placement.translation;
        for k in 0..N {
            let (jl, ja) = (col(&self.jacobian, k, 0), col(&self.jacobian, k, 3));
            let (dl, da) = (col(&self.jacobian_dot, k, 0), col(&self.jacobian_dot, k, 3));
            let j = Motion {
                linear: jl,
                angular: ja,
            };
            let dj = match reference {
                ReferenceFrame::World => Motion {
                    linear: dl + pdot.cross(&ja) + p.cross(&da),
                    angular: da,
                },
                _ => rotate_back(
                    &self.placement,
                    &Motion {
                        linear: dl - w.cross(&jl),
                        angular: da - w.cross(&ja),
                    },
                ),
            };
            let j = velocity_from_lwa(&self.placement, &j, reference);
            let (j, dj) = (j.to_array(), dj.to_array());
            for r in 0..6 {
                self.jacobian[r][k] = j[r];
                self.jacobian_dot[r][k] = dj[r];
            }
        }
    }
}

/// Support for generated code: the conversion the generated
/// `frame_jacobian_time_variation` applies.
#[doc(hidden)]
pub fn __express_jacobian_time_variation<S: Scalar, const N: usize>(
    j: &mut FrameJacobianTimeVariation<S, N>,
    v: &[S; N],
    reference: ReferenceFrame,
) {
    j.express_from_lwa(v, reference);
}

/// Support for generated code: a frame's motion from its `LOCAL_WORLD_ALIGNED`
/// Jacobian and its time variation: the velocity `J v` (the origin's velocity and the
/// angular velocity) and the classical acceleration `J a + J̇ v`, the time derivative
/// of `J v`.
#[doc(hidden)]
pub fn __frame_motion<S: Scalar, const N: usize>(
    j: &FrameJacobianTimeVariation<S, N>,
    v: &[S; N],
    a: &[S; N],
) -> FrameMotion<S> {
    let placement = j.placement;
    let (jac, jac_dot) = (
        FrameJacobian {
            placement,
            jacobian: j.jacobian,
        },
        FrameJacobian {
            placement,
            jacobian: j.jacobian_dot,
        },
    );
    let (ja, jdv) = (jac.velocity(a), jac_dot.velocity(v));
    FrameMotion {
        placement,
        velocity: jac.velocity(v),
        acceleration: Motion {
            linear: ja.linear + jdv.linear,
            angular: ja.angular + jdv.angular,
        },
    }
}

/// A frame's placement, velocity and classical acceleration, `LOCAL_WORLD_ALIGNED`,
/// as the generated `frame_motion` computes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameMotion<S: Scalar> {
    pub placement: Pose<S>,
    /// Linear: the velocity of the frame origin; angular: the body's angular velocity.
    pub velocity: Motion<S>,
    /// Linear: the classical acceleration of the frame origin (the second time
    /// derivative of its position); angular: the body's angular acceleration.
    pub acceleration: Motion<S>,
}

impl<S: Scalar> Default for FrameMotion<S> {
    fn default() -> Self {
        FrameMotion {
            placement: Pose::default(),
            velocity: Motion::default(),
            acceleration: Motion::default(),
        }
    }
}

impl<S: Scalar> FrameMotion<S> {
    /// The velocity in `reference` (Pinocchio's `getFrameVelocity`).
    pub fn velocity_in(&self, reference: ReferenceFrame) -> Motion<S> {
        velocity_from_lwa(&self.placement, &self.velocity, reference)
    }

    /// The classical acceleration in `reference` (Pinocchio's
    /// `getFrameClassicalAcceleration`): the spatial acceleration in that frame plus
    /// `ω × v` on the linear part. In `LOCAL` and `LOCAL_WORLD_ALIGNED` its linear part
    /// is the acceleration of the frame origin; with `a = 0` it is the drift `J̇(q, v)·v`.
    pub fn classical_acceleration_in(&self, reference: ReferenceFrame) -> Motion<S> {
        let (acc, w) = (&self.acceleration, &self.velocity.angular);
        match reference {
            ReferenceFrame::LocalWorldAligned => *acc,
            ReferenceFrame::Local => rotate_back(&self.placement, acc),
            ReferenceFrame::World => {
                // At the world origin O: a_O = a_p − ω̇ × p − ω × (ω × p).
                let p = &self.placement.translation;
                Motion {
                    linear: acc.linear - acc.angular.cross(p) - w.cross(&w.cross(p)),
                    angular: acc.angular,
                }
            }
        }
    }
}

/// The rotation vector `ω` (`|ω| ≤ π`) with `exp([ω]×) = r`: the logarithm on SO(3)
/// (Pinocchio's `log3`), accurate to rounding at every angle: the angle from `atan2`
/// (an `acos` of the trace loses half the digits near 0), and near π, where the skew
/// part vanishes, the axis from the symmetric part.
pub fn log3<S: OrderedScalar>(r: &Matrix3<S>) -> Vector3<S> {
    let half = S::from_f64(0.5);
    // Rodrigues: r = c E + s [a]× + (1 − c) a aᵀ, so the skew part is 2 s a.
    let skew = Vector3::new(r[(2, 1)] - r[(1, 2)], r[(0, 2)] - r[(2, 0)], r[(1, 0)] - r[(0, 1)]);
    let s = half * (skew[0] * skew[0] + skew[1] * skew[1] + skew[2] * skew[2]).sqrt();
    let c = half * (r[(0, 0)] + r[(1, 1)] + r[(2, 2)] - S::ONE);
    let theta = s.atan2(c);
    if c > S::from_f64(-0.9) {
        // θ / sin θ, 1 at θ = 0.
        let factor = if s == S::ZERO { S::ONE } else { theta / s };
        return skew * (half * factor);
    }
    // Near π: the symmetric part less c E is (1 − c) a aᵀ; the axis from its largest
    // diagonal entry, its sign from the skew part.
    let one_c = S::ONE - c;
    let b = |i: usize, j: usize| half * (r[(i, j)] + r[(j, i)]) - if i == j { c } else { S::ZERO };
    let mut i = 0;
    for k in 1..3 {
        if b(k, k) > b(i, i) {
            i = k;
        }
    }
    let bii = b(i, i) / one_c;
    let ai = if bii > S::ZERO { bii.sqrt() } else { S::ZERO };
    if ai == S::ZERO {
        return Vector3::from_element(S::ZERO);
    }
    let mut axis = Vector3::from_fn(|j, _| if j == i { ai } else { b(i, j) / (one_c * ai) });
    if axis[0] * skew[0] + axis[1] * skew[1] + axis[2] * skew[2] < S::ZERO {
        axis = -axis;
    }
    axis * theta
}

impl<S: Scalar> Pose<S> {
    /// The identity placement.
    pub fn identity() -> Self {
        let (o, z) = (S::ONE, S::ZERO);
        Pose {
            rotation: Matrix3::new(o, z, z, z, o, z, z, z, o),
            translation: Vector3::from_element(z),
        }
    }
}

impl<S: OrderedScalar> Pose<S> {
    /// The error from `self` to `target` as a world-aligned twist,
    /// `[p_target − p; log3(R_target Rᵀ)]`: what carries `self` onto `target` in unit
    /// time to first order, so that `J_lwa Δq = error` is the Newton step of inverse
    /// kinematics with a `LOCAL_WORLD_ALIGNED` Jacobian.
    pub fn error_to(&self, target: &Pose<S>) -> Motion<S> {
        Motion {
            linear: target.translation - self.translation,
            angular: log3(&Matrix3::from_fn(|i, j| {
                let (a, b) = (&target.rotation, &self.rotation);
                a[(i, 0)] * b[(j, 0)] + a[(i, 1)] * b[(j, 1)] + a[(i, 2)] * b[(j, 2)]
            })),
        }
    }
}

/// `Rᵀ m`: a world-aligned motion in the frame's own axes.
fn rotate_back<S: Scalar>(placement: &Pose<S>, m: &Motion<S>) -> Motion<S> {
    let r = &placement.rotation;
    let back = |x: &Vector3<S>| {
        Vector3::new(
            r[(0, 0)] * x[0] + r[(1, 0)] * x[1] + r[(2, 0)] * x[2],
            r[(0, 1)] * x[0] + r[(1, 1)] * x[1] + r[(2, 1)] * x[2],
            r[(0, 2)] * x[0] + r[(1, 2)] * x[1] + r[(2, 2)] * x[2],
        )
    };
    Motion {
        linear: back(&m.linear),
        angular: back(&m.angular),
    }
}

/// A twist (or a Jacobian column) given at the frame origin in world axes, in
/// `reference`: `LOCAL` rotates it into the frame's axes, `WORLD` moves its point to
/// the world origin (`v_O = v_p + p × ω`).
fn velocity_from_lwa<S: Scalar>(placement: &Pose<S>, m: &Motion<S>, reference: ReferenceFrame) -> Motion<S> {
    match reference {
        ReferenceFrame::LocalWorldAligned => *m,
        ReferenceFrame::Local => rotate_back(placement, m),
        ReferenceFrame::World => Motion {
            linear: m.linear + placement.translation.cross(&m.angular),
            angular: m.angular,
        },
    }
}

/// Support for generated code (trees composing their frames' `J̇`): frame `frame`'s
/// placement, `LOCAL_WORLD_ALIGNED` Jacobian and its time variation from `axes`, which
/// holds each velocity coordinate's axis `z` and origin `o` in the world (6 per
/// coordinate), each of the `nframes` frames' placements (12 per frame, the rotation
/// row-major), then the time derivatives `ż, ȯ` of each coordinate's axis and origin
/// (6 per coordinate) and `ṗ` of each frame's origin (3 per frame). Column `c` of `J`
/// is `[z × (p − o); z]` where `rotates[c]`, `[z; 0]` otherwise, `p` the frame's
/// origin, and of `J̇` its time derivative, `[ż × (p − o) + z × (ṗ − ȯ); ż]` or
/// `[ż; 0]`; only the columns `support` are, the others are zero.
#[doc(hidden)]
pub fn __frame_jacobian_time_variation_from_axes<S: Scalar, const N: usize>(
    axes: &[S],
    nframes: usize,
    rotates: &[bool; N],
    support: &[usize],
    frame: usize,
    out: &mut FrameJacobianTimeVariation<S, N>,
) {
    let at = |k: usize| Vector3::new(axes[k], axes[k + 1], axes[k + 2]);
    let f = &axes[6 * N + 12 * frame..6 * N + 12 * frame + 12];
    out.placement = Pose {
        rotation: Matrix3::new(f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8]),
        translation: Vector3::new(f[9], f[10], f[11]),
    };
    out.jacobian = [[S::ZERO; N]; 6];
    out.jacobian_dot = [[S::ZERO; N]; 6];
    let dots = 6 * N + 12 * nframes;
    let (p, p_dot) = (out.placement.translation, at(dots + 6 * N + 3 * frame));
    for &c in support {
        let (z, z_dot) = (at(6 * c), at(dots + 6 * c));
        let zero = Vector3::from_element(S::ZERO);
        let [(linear, angular), (linear_dot, angular_dot)] = if rotates[c] {
            let (o, o_dot) = (at(6 * c + 3), at(dots + 6 * c + 3));
            [
                (z.cross(&(p - o)), z),
                (z_dot.cross(&(p - o)) + z.cross(&(p_dot - o_dot)), z_dot),
            ]
        } else {
            [(z, zero), (z_dot, zero)]
        };
        for r in 0..3 {
            (out.jacobian[r][c], out.jacobian[3 + r][c]) = (linear[r], angular[r]);
            (out.jacobian_dot[r][c], out.jacobian_dot[3 + r][c]) = (linear_dot[r], angular_dot[r]);
        }
    }
}

/// Support for generated code: the conversion the generated `frame_jacobian` applies.
#[doc(hidden)]
pub fn __express_jacobian<S: Scalar, const N: usize>(j: &mut FrameJacobian<S, N>, reference: ReferenceFrame) {
    if reference != ReferenceFrame::LocalWorldAligned {
        j.express_from_lwa(reference);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    fn pose() -> Pose<f64> {
        // A rotation of 0.3 rad about z, at (1, 2, 3).
        let (s, c) = 0.3f64.sin_cos();
        Pose {
            rotation: Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
            translation: Vector3::new(1.0, 2.0, 3.0),
        }
    }

    #[test]
    fn local_is_the_rotated_world_aligned_motion() {
        let p = pose();
        let m = Motion {
            linear: Vector3::new(0.5, -1.0, 2.0),
            angular: Vector3::new(0.1, 0.2, -0.3),
        };
        let local = velocity_from_lwa(&p, &m, ReferenceFrame::Local);
        let back = p.rotation * local.linear;
        assert!((back - m.linear).norm() < 1e-15);
        assert!((p.rotation * local.angular - m.angular).norm() < 1e-15);
    }

    #[test]
    fn world_velocity_is_the_body_point_at_the_origin() {
        let p = pose();
        let m = Motion {
            linear: Vector3::new(0.5, -1.0, 2.0),
            angular: Vector3::new(0.1, 0.2, -0.3),
        };
        let w = velocity_from_lwa(&p, &m, ReferenceFrame::World);
        // The velocity of the body point at the world origin: v_p + ω × (0 − p).
        let want = m.linear + m.angular.cross(&(-p.translation));
        assert!((w.linear - want).norm() < 1e-15);
    }

    /// `exp` of a rotation vector, by Rodrigues.
    fn exp3(w: Vector3<f64>) -> Matrix3<f64> {
        let t = w.norm();
        if t == 0.0 {
            return Matrix3::identity();
        }
        let a = w / t;
        let k = Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0);
        Matrix3::identity() + k * t.sin() + k * k * (1.0 - t.cos())
    }

    #[test]
    fn log3_inverts_exp_at_every_angle() {
        let axis = Vector3::new(0.3, -0.5, 0.8).normalize();
        for t in [
            0.0,
            1e-12,
            1e-7,
            0.3,
            2.0,
            2.9,
            std::f64::consts::PI - 1e-9,
            std::f64::consts::PI,
        ] {
            let w = axis * t;
            let got = log3(&exp3(w));
            assert!(
                (got - w).norm() < 1e-15 * (1.0 + t) || (t == std::f64::consts::PI && (got + w).norm() < 1e-15),
                "angle {t}: {got:?} vs {w:?}"
            );
            assert!((exp3(got) - exp3(w)).norm() < 1e-15, "angle {t}");
        }
    }

    #[test]
    fn pose_error_is_the_twist_to_the_target() {
        let p = pose();
        let w = Vector3::new(0.1, -0.2, 0.05);
        let target = Pose {
            rotation: exp3(w) * p.rotation,
            translation: p.translation + Vector3::new(0.01, 0.0, -0.02),
        };
        let e = p.error_to(&target);
        assert!((e.angular - w).norm() < 1e-15);
        assert!((e.linear - Vector3::new(0.01, 0.0, -0.02)).norm() < 1e-15);
        assert_eq!(Pose::<f64>::identity().error_to(&Pose::identity()).to_array(), [0.0; 6]);
    }

    #[test]
    fn jacobian_matrix_keeps_rows() {
        let j = FrameJacobian::<f64, 2> {
            jacobian: [[1.0, 2.0], [0.0, 1.0], [3.0, 0.0], [0.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
            ..Default::default()
        };
        let m = j.matrix();
        assert_eq!((m[(0, 1)], m[(2, 0)], m[(5, 0)]), (2.0, 3.0, 1.0));
    }

    #[test]
    fn jacobian_velocity_is_j_times_v() {
        let j = FrameJacobian::<f64, 2> {
            jacobian: [[1.0, 2.0], [0.0, 1.0], [3.0, 0.0], [0.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
            ..Default::default()
        };
        let v = j.velocity(&[2.0, -1.0]);
        assert_eq!(v.to_array(), [0.0, -1.0, 6.0, 0.0, -1.0, 2.0]);
    }
}
