//! Configuration-space operations on a robot's position coordinates `q` (the
//! configuration manifold): what a simulator, an integrator or an estimator needs once a
//! floating base or a ball joint makes `q` no longer a plain vector. The operations and
//! their conventions are Pinocchio's (`pinocchio::integrate`, `difference`, `neutral`,
//! `normalize`).
//!
//! # Layout
//!
//! Coordinates are laid out joint after joint in [`RobotModel::joints`] order, `nq` of
//! them for positions and `nv` for velocities ([`JointType::nq`], [`JointType::nv`]);
//! a joint that follows another ([`JointModel::mimic`](crate::JointModel)) has none
//! ([`RobotModel::own_joints`]):
//!
//! | joint | `q` | `v` |
//! |---|---|---|
//! | revolute, continuous, prismatic | the angle or displacement | its rate |
//! | ball ([`JointType::Spherical`]) | unit quaternion `[x, y, z, w]` of the child in the joint frame | angular velocity `ω` in the child frame |
//! | free flyer ([`JointType::FreeFlyer`]) | `[p; x, y, z, w]`: position of the body in the parent frame, unit quaternion of its orientation | `[v; ω]`, linear velocity of the body origin and angular velocity, both in the body frame |
//! | planar ([`JointType::Planar`]) | `[x, y, θ]`: the body origin along the plane's axes, its turn about the normal | `[vx, vy, ω]`, linear velocity of the body origin along the body's plane axes and angular velocity about the normal |
//!
//! A quaternion `[x, y, z, w]` stands for the rotation `R(q)` of
//! [`quaternion_to_matrix`]; `q` and `−q` are the same rotation.
//!
//! # Operations
//!
//! * [`integrate`]: `q ⊕ v`, the configuration reached from `q` by moving with the
//!   constant velocity `v` for unit time (multiply `v` by the time step first).
//! * [`difference`]: `q₁ ⊖ q₀`, the velocity `v` with `q₀ ⊕ v = q₁` (the shortest one:
//!   rotation vectors have `|ω| ≤ π`).
//! * [`neutral`]: zeros, identity quaternions.
//! * [`normalize`]: each quaternion scaled to unit norm.
//!
//! All are generic over [`OrderedScalar`], allocate nothing and never panic: a slice of the
//! wrong length or a non-finite result (a NaN or infinite input, a zero quaternion) is a
//! [`ConfigurationError`].
//!
//! # Example
//!
//! A body on a free flyer, with a pendulum hinged below it:
//!
//! ```
//! use dyngen::configuration::{difference, integrate, neutral, ConfigurationError};
//! use dyngen::{BodyModel, JointModel, JointType, RobotModel};
//!
//! const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
//! const BODY: BodyModel = BodyModel {
//!     name: "body",
//!     mass: 1.0,
//!     com: [0.0, 0.0, 0.0],
//!     inertia: [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]],
//!     merged: &[],
//! };
//! const MODEL: RobotModel = RobotModel {
//!     name: "floating_pendulum",
//!     gravity: [0.0, 0.0, -9.81],
//!     base: "world",
//!     joints: &[
//!         JointModel {
//!             name: "root",
//!             kind: JointType::FreeFlyer,
//!             parent: 0,
//!             rotation: IDENTITY,
//!             translation: [0.0, 0.0, 0.0],
//!             axis: [0.0, 0.0, 0.0],
//!             limits: None,
//!             armature: 0.0,
//!             damping: 0.0,
//!             friction: 0.0,
//!             mimic: None,
//!         },
//!         JointModel {
//!             name: "hinge",
//!             kind: JointType::Revolute,
//!             parent: 1,
//!             rotation: IDENTITY,
//!             translation: [0.0, 0.0, -0.5],
//!             axis: [0.0, 1.0, 0.0],
//!             limits: None,
//!             armature: 0.0,
//!             damping: 0.0,
//!             friction: 0.0,
//!             mimic: None,
//!         },
//!     ],
//!     bodies: &[BodyModel { name: "base", ..BODY }, BodyModel { name: "pendulum", ..BODY }],
//!     frames: &[],
//! };
//!
//! // nq = 7 + 1, nv = 6 + 1.
//! let mut q0 = [0.0; 8];
//! neutral(&MODEL, &mut q0)?;
//! assert_eq!(q0, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
//!
//! // One explicit Euler step of 10 ms: forward at 1 m/s while yawing at 2 rad/s.
//! let (v, dt) = ([1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.5], 0.01);
//! let mut q1 = [0.0; 8];
//! integrate(&MODEL, &q0, &v.map(|x| x * dt), &mut q1)?;
//! // Half-angle quaternion of a 0.02 rad yaw; the hinge moved by 0.005 rad.
//! assert!((q1[5] - 0.01_f64.sin()).abs() < 1e-15 && (q1[6] - 0.01_f64.cos()).abs() < 1e-15);
//! assert!((q1[7] - 0.005).abs() < 1e-15);
//!
//! // The difference recovers the step.
//! let mut dq = [0.0; 7];
//! difference(&MODEL, &q0, &q1, &mut dq)?;
//! assert!(dq.iter().zip(v).all(|(d, v)| (d - v * dt).abs() < 1e-15));
//!
//! // Wrong lengths are errors, not panics.
//! assert_eq!(
//!     integrate(&MODEL, &q0, &v[..6], &mut q1),
//!     Err(ConfigurationError::Length { argument: "v", expected: 7, found: 6 })
//! );
//! # Ok::<(), ConfigurationError>(())
//! ```

use crate::{JointType, OrderedScalar, RobotModel};
use core::fmt;
use nalgebra::Matrix3;

/// Why a configuration-space operation refused its arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigurationError {
    /// A slice does not have the model's length: `nq` for positions (`q`, `q0`, `q1`,
    /// and the output of [`integrate`], [`neutral`]), `nv` for velocities (`v` and the
    /// output of [`difference`]).
    Length {
        /// The argument's name in the function's signature.
        argument: &'static str,
        /// The model's `nq` or `nv`.
        expected: usize,
        /// The slice's length.
        found: usize,
    },
    /// A joint's result has a NaN or infinite coordinate: an input was not finite, or a
    /// quaternion was zero.
    NonFinite {
        /// The joint, 1-based as [`RobotModel`] numbers them.
        joint: usize,
        /// Its name.
        name: &'static str,
    },
}

impl fmt::Display for ConfigurationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConfigurationError::Length {
                argument,
                expected,
                found,
            } => write!(f, "`{argument}` has {found} entries, expected {expected}"),
            ConfigurationError::NonFinite { joint, name } => write!(
                f,
                "joint {joint} (`{name}`): the result is not finite (a NaN or infinite input, or a zero quaternion)"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ConfigurationError {}

/// `q ⊕ v`: the configuration reached from `q` by the constant velocity `v` in unit
/// time, Pinocchio's `integrate(model, q, v)` (scale `v` by the time step first), into
/// `out` (`nq` entries).
///
/// Per joint:
/// * revolute, continuous, prismatic: `q + v`;
/// * ball: `R₁ = R₀ exp₃(ω)`, as the quaternion `q₁ = q₀ ⊗ exp(ω)` normalised, where
///   `exp(ω) = [sin(θ/2) ω/θ, cos(θ/2)]`, `θ = |ω|`;
/// * free flyer: `M₁ = M₀ exp₆([v; ω])`: the rotation as for the ball joint, the
///   position `p₁ = p₀ + R₀ V(ω) v` with
///   `V(ω) = E + (1 − cos θ)/θ² [ω]× + (θ − sin θ)/θ³ [ω]×²` (Taylor series below
///   `θ = 10⁻²`); the quaternion's sign is then chosen on `q₀`'s side (`q₀ · q₁ ≥ 0`),
///   as Pinocchio's free flyer does (the ball joint keeps `q₀ ⊗ exp(ω)`, which is the
///   same for `|ω| ≤ π`);
/// * planar: `M₁ = M₀ exp(v)` on SE(2) (Pinocchio's planar joint): `θ₁ = θ₀ + ω`,
///   `[x₁, y₁] = [x₀, y₀] + R(θ₀) V(ω) [vx, vy]` with `V(ω) = [[a, −b], [b, a]]`,
///   `a = sin ω / ω`, `b = (1 − cos ω)/ω`, from the half angle (`a = 2 sin(ω/2) cos(ω/2)/ω`,
///   `b = 2 sin²(ω/2)/ω`, no cancellation) and by Taylor series below `|ω| = 10⁻²`.
///
/// The input quaternions need not be exactly unit: the result is that of the
/// normalised input.
///
/// # Errors
///
/// [`ConfigurationError::Length`] when `q` or `out` does not have `nq` entries or `v`
/// does not have `nv`; [`ConfigurationError::NonFinite`] for the first joint whose
/// result is not finite (the content of `out` is then unspecified).
pub fn integrate<S: OrderedScalar>(
    model: &RobotModel,
    q: &[S],
    v: &[S],
    out: &mut [S],
) -> Result<(), ConfigurationError> {
    let (nq, nv) = dimensions(model);
    check_length("q", q.len(), nq)?;
    check_length("v", v.len(), nv)?;
    check_length("out", out.len(), nq)?;
    let (mut iq, mut iv) = (0, 0);
    for (j, joint) in model.own_joints() {
        let (kq, kv) = (joint.kind.nq(), joint.kind.nv());
        let (q, v, out) = (&q[iq..iq + kq], &v[iv..iv + kv], &mut out[iq..iq + kq]);
        match joint.kind {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => out[0] = q[0] + v[0],
            JointType::Spherical => {
                let (e, _, _) = exp_so3([v[0], v[1], v[2]]);
                out.copy_from_slice(&normalized(quat_mul([q[0], q[1], q[2], q[3]], e)));
            }
            JointType::FreeFlyer => {
                let q0 = normalized([q[3], q[4], q[5], q[6]]);
                let (w, lin) = ([v[3], v[4], v[5]], [v[0], v[1], v[2]]);
                let (e, a, b) = exp_so3(w);
                // V(ω) v = v + a ω×v + b ω×(ω×v).
                let wxv = cross(w, lin);
                let wwxv = cross(w, wxv);
                let t = rotate(q0, [0, 1, 2].map(|i| lin[i] + a * wxv[i] + b * wwxv[i]));
                let mut q1 = quat_mul(q0, e);
                if dot4(q1, q0) < S::ZERO {
                    q1 = q1.map(|x| -x);
                }
                let q1 = normalized(q1);
                out[..3].copy_from_slice(&[q[0] + t[0], q[1] + t[1], q[2] + t[2]]);
                out[3..].copy_from_slice(&q1);
            }
            JointType::Planar => {
                let (a, b) = planar_v(v[2]);
                let (dx, dy) = (a * v[0] - b * v[1], b * v[0] + a * v[1]);
                let (s0, c0) = q[2].sin_cos();
                out.copy_from_slice(&[q[0] + (c0 * dx - s0 * dy), q[1] + (s0 * dx + c0 * dy), q[2] + v[2]]);
            }
        }
        check_finite(out, j, model)?;
        iq += kq;
        iv += kv;
    }
    Ok(())
}

/// `q₁ ⊖ q₀`: the velocity `v` with `q₀ ⊕ v = q₁` ([`integrate`]), Pinocchio's
/// `difference(model, q0, q1)`, into `out` (`nv` entries).
///
/// Per joint:
/// * revolute, continuous, prismatic: `q₁ − q₀` (no wrapping of angles, as Pinocchio's
///   one-coordinate joints);
/// * ball: `ω = log₃(R₀ᵀ R₁)`, computed as the logarithm of the quaternion
///   `r = q₀* ⊗ q₁` on its `w ≥ 0` side: `θ = 2 atan2(|r_xyz|, r_w)` in `[0, π]`,
///   `ω = θ r_xyz / |r_xyz|`. Accurate at every angle (no `acos`, no division by
///   `sin θ`); at exactly `θ = π` either of the two opposite rotation vectors.
/// * free flyer: `log₆(M₀⁻¹ M₁) = [V(ω)⁻¹ R₀ᵀ(p₁ − p₀); ω]` with `ω` as for the ball
///   joint and
///   `V(ω)⁻¹ = E − ½[ω]× + (1/θ²)(1 − θ sin θ / (2(1 − cos θ)))[ω]×²`, whose last
///   coefficient is evaluated as `(1 − (θ/2) cot(θ/2))/θ²` from the half angle of `r`
///   (no cancellation in `1 − cos θ`, finite up to `θ = π`), and by its Taylor series
///   `1/12 + θ²/720 + θ⁴/30240` below `θ = 10⁻²`;
/// * planar: `log(M₀⁻¹ M₁)` on SE(2): `ω = θ₁ − θ₀` (no wrapping, as for the other
///   angles), `[vx, vy] = V(ω)⁻¹ R(θ₀)ᵀ [x₁ − x₀, y₁ − y₀]` with
///   `V(ω)⁻¹ = [[α, ω/2], [−ω/2, α]]`, `α = (ω/2) cot(ω/2)` (Taylor series
///   `1 − ω²/12 − ω⁴/720 − ω⁶/30240` below `|ω| = 10⁻²`). `V(ω)` is singular at
///   `ω = ±2π, ±4π, …`: angles that far apart have no such velocity unless the
///   positions agree, and the result there is meaningless.
///
/// The input quaternions need not be exactly unit: they are normalised first.
///
/// # Errors
///
/// [`ConfigurationError::Length`] when `q0` or `q1` does not have `nq` entries or
/// `out` does not have `nv`; [`ConfigurationError::NonFinite`] for the first joint
/// whose result is not finite (the content of `out` is then unspecified).
pub fn difference<S: OrderedScalar>(
    model: &RobotModel,
    q0: &[S],
    q1: &[S],
    out: &mut [S],
) -> Result<(), ConfigurationError> {
    let (nq, nv) = dimensions(model);
    check_length("q0", q0.len(), nq)?;
    check_length("q1", q1.len(), nq)?;
    check_length("out", out.len(), nv)?;
    let (mut iq, mut iv) = (0, 0);
    for (j, joint) in model.own_joints() {
        let (kq, kv) = (joint.kind.nq(), joint.kind.nv());
        let (a, b, out) = (&q0[iq..iq + kq], &q1[iq..iq + kq], &mut out[iv..iv + kv]);
        match joint.kind {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => out[0] = b[0] - a[0],
            JointType::Spherical => {
                let r = quat_mul(
                    conjugate(normalized([a[0], a[1], a[2], a[3]])),
                    normalized([b[0], b[1], b[2], b[3]]),
                );
                let (w, _) = log_so3(r);
                out.copy_from_slice(&w);
            }
            JointType::FreeFlyer => {
                let qa = normalized([a[3], a[4], a[5], a[6]]);
                let r = quat_mul(conjugate(qa), normalized([b[3], b[4], b[5], b[6]]));
                let (w, beta) = log_so3(r);
                let d = rotate(conjugate(qa), [b[0] - a[0], b[1] - a[1], b[2] - a[2]]);
                // V(ω)⁻¹ d = d − ½ ω×d + β ω×(ω×d).
                let wxd = cross(w, d);
                let wwxd = cross(w, wxd);
                let half = S::from_f64(0.5);
                out[..3].copy_from_slice(&[0, 1, 2].map(|i| d[i] - half * wxd[i] + beta * wwxd[i]));
                out[3..].copy_from_slice(&w);
            }
            JointType::Planar => {
                let w = b[2] - a[2];
                let (s0, c0) = a[2].sin_cos();
                let (px, py) = (b[0] - a[0], b[1] - a[1]);
                let (dx, dy) = (c0 * px + s0 * py, c0 * py - s0 * px);
                let (alpha, half) = (planar_v_inverse(w), S::from_f64(0.5) * w);
                out.copy_from_slice(&[alpha * dx + half * dy, alpha * dy - half * dx, w]);
            }
        }
        check_finite(out, j, model)?;
        iq += kq;
        iv += kv;
    }
    Ok(())
}

/// The neutral configuration into `out` (`nq` entries), Pinocchio's `neutral(model)`:
/// zero for one-coordinate joints, planar joints and free-flyer positions, the identity
/// quaternion `[0, 0, 0, 1]` for ball joints and free flyers.
///
/// # Errors
///
/// [`ConfigurationError::Length`] when `out` does not have `nq` entries.
pub fn neutral<S: OrderedScalar>(model: &RobotModel, out: &mut [S]) -> Result<(), ConfigurationError> {
    let (nq, _) = dimensions(model);
    check_length("out", out.len(), nq)?;
    let mut iq = 0;
    for (_, joint) in model.own_joints() {
        let k = joint.kind.nq();
        let out = &mut out[iq..iq + k];
        out.fill(S::ZERO);
        if matches!(joint.kind, JointType::Spherical | JointType::FreeFlyer) {
            out[k - 1] = S::ONE;
        }
        iq += k;
    }
    Ok(())
}

/// Scales each quaternion of `q` (`nq` entries; ball joints and free flyers) to unit
/// norm, in place, as Pinocchio's `normalize(model, q)`; other coordinates are left as
/// they are. Quaternions of any finite non-zero size are handled (no overflow or
/// underflow in the norm).
///
/// # Errors
///
/// [`ConfigurationError::Length`] when `q` does not have `nq` entries;
/// [`ConfigurationError::NonFinite`] for the first joint with a zero quaternion or a
/// non-finite coordinate. Its quaternion is left as it was, as are the joints after
/// it; the joints before it are normalised.
pub fn normalize<S: OrderedScalar>(model: &RobotModel, q: &mut [S]) -> Result<(), ConfigurationError> {
    let (nq, _) = dimensions(model);
    check_length("q", q.len(), nq)?;
    let mut iq = 0;
    for (j, joint) in model.own_joints() {
        let k = joint.kind.nq();
        let q = &mut q[iq..iq + k];
        if matches!(joint.kind, JointType::Spherical | JointType::FreeFlyer) {
            let r = normalized([q[k - 4], q[k - 3], q[k - 2], q[k - 1]]);
            check_finite(&q[..k - 4], j, model)?;
            check_finite(&r, j, model)?;
            q[k - 4..].copy_from_slice(&r);
        } else {
            check_finite(q, j, model)?;
        }
        iq += k;
    }
    Ok(())
}

/// The rotation matrix of the quaternion `[x, y, z, w]`, with the same formula and
/// operation order as Eigen's `Quaternion::toRotationMatrix` (and so Pinocchio's
/// `quat.matrix()`):
///
/// ```text
///     ⎡ 1 − 2(y² + z²)   2(xy − wz)       2(xz + wy)     ⎤
/// R = ⎢ 2(xy + wz)       1 − 2(x² + z²)   2(yz − wx)     ⎥
///     ⎣ 2(xz − wy)       2(yz + wx)       1 − 2(x² + y²) ⎦
/// ```
///
/// `R` rotates vectors of the child frame into the parent frame
/// (`x_parent = R x_child`). For a unit quaternion it is a rotation; the quaternion is
/// not normalised here (as Eigen).
pub fn quaternion_to_matrix<S: OrderedScalar>(q: [S; 4]) -> Matrix3<S> {
    let [x, y, z, w] = q;
    let two = S::from_f64(2.0);
    let (tx, ty, tz) = (two * x, two * y, two * z);
    let (twx, twy, twz) = (tx * w, ty * w, tz * w);
    let (txx, txy, txz) = (tx * x, ty * x, tz * x);
    let (tyy, tyz, tzz) = (ty * y, tz * y, tz * z);
    let one = S::ONE;
    Matrix3::new(
        one - (tyy + tzz),
        txy - twz,
        txz + twy,
        txy + twz,
        one - (txx + tzz),
        tyz - twx,
        txz - twy,
        tyz + twx,
        one - (txx + tyy),
    )
}

/// The unit quaternion `[x, y, z, w]` of a rotation matrix, with `w ≥ 0` (of the two
/// quaternions `±q` of the rotation), by Shepperd's method: of `4w² = 1 + tr R`,
/// `4x² = 1 + 2R₀₀ − tr R`, `4y² = 1 + 2R₁₁ − tr R`, `4z² = 1 + 2R₂₂ − tr R` the
/// largest is taken from the diagonal (a square root of at least 1), the other three
/// from the off-diagonal sums and differences divided by it, e.g. when `w` is largest
/// `w = ½√(1 + tr R)`, `x = (R₂₁ − R₁₂)/(4w)`, `y = (R₀₂ − R₂₀)/(4w)`,
/// `z = (R₁₀ − R₀₁)/(4w)`. Accurate at every angle; the inverse of
/// [`quaternion_to_matrix`] for a rotation `r` (for another matrix the result is
/// meaningless, possibly NaN, but nothing panics).
pub fn matrix_to_quaternion<S: OrderedScalar>(r: &Matrix3<S>) -> [S; 4] {
    let (one, quarter) = (S::ONE, S::from_f64(0.25));
    let two = S::from_f64(2.0);
    let (r00, r11, r22) = (r[(0, 0)], r[(1, 1)], r[(2, 2)]);
    let tr = r00 + r11 + r22;
    let q = if tr >= r00 && tr >= r11 && tr >= r22 {
        let s = two * (one + tr).sqrt(); // 4w
        [
            (r[(2, 1)] - r[(1, 2)]) / s,
            (r[(0, 2)] - r[(2, 0)]) / s,
            (r[(1, 0)] - r[(0, 1)]) / s,
            quarter * s,
        ]
    } else if r00 >= r11 && r00 >= r22 {
        let s = two * (one + r00 - r11 - r22).sqrt(); // 4x
        [
            quarter * s,
            (r[(0, 1)] + r[(1, 0)]) / s,
            (r[(0, 2)] + r[(2, 0)]) / s,
            (r[(2, 1)] - r[(1, 2)]) / s,
        ]
    } else if r11 >= r22 {
        let s = two * (one + r11 - r00 - r22).sqrt(); // 4y
        [
            (r[(0, 1)] + r[(1, 0)]) / s,
            quarter * s,
            (r[(1, 2)] + r[(2, 1)]) / s,
            (r[(0, 2)] - r[(2, 0)]) / s,
        ]
    } else {
        let s = two * (one + r22 - r00 - r11).sqrt(); // 4z
        [
            (r[(0, 2)] + r[(2, 0)]) / s,
            (r[(1, 2)] + r[(2, 1)]) / s,
            quarter * s,
            (r[(1, 0)] - r[(0, 1)]) / s,
        ]
    };
    if q[3] < S::ZERO {
        q.map(|x| -x)
    } else {
        q
    }
}

/// `(nq, nv)` of the model.
fn dimensions(model: &RobotModel) -> (usize, usize) {
    model
        .own_joints()
        .fold((0, 0), |(nq, nv), (_, j)| (nq + j.kind.nq(), nv + j.kind.nv()))
}

fn check_length(argument: &'static str, found: usize, expected: usize) -> Result<(), ConfigurationError> {
    if found == expected {
        Ok(())
    } else {
        Err(ConfigurationError::Length {
            argument,
            expected,
            found,
        })
    }
}

/// Joint `j` (0-based index into `model.joints`) is finite, or its error.
fn check_finite<S: OrderedScalar>(x: &[S], j: usize, model: &RobotModel) -> Result<(), ConfigurationError> {
    if x.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ConfigurationError::NonFinite {
            joint: j + 1,
            name: model.joints[j].name,
        })
    }
}

fn cross<S: OrderedScalar>(a: [S; 3], b: [S; 3]) -> [S; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot4<S: OrderedScalar>(a: [S; 4], b: [S; 4]) -> S {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

fn conjugate<S: OrderedScalar>(q: [S; 4]) -> [S; 4] {
    [-q[0], -q[1], -q[2], q[3]]
}

/// The Hamilton product `a ⊗ b` (rotation `R(a) R(b)`), in Eigen's operation order.
fn quat_mul<S: OrderedScalar>(a: [S; 4], b: [S; 4]) -> [S; 4] {
    let ([ax, ay, az, aw], [bx, by, bz, bw]) = (a, b);
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by + ay * bw + az * bx - ax * bz,
        aw * bz + az * bw + ax * by - ay * bx,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// `R(q) v` for a unit quaternion, as Eigen: `t = 2 q_xyz × v`, `v + w t + q_xyz × t`.
fn rotate<S: OrderedScalar>(q: [S; 4], v: [S; 3]) -> [S; 3] {
    let u = [q[0], q[1], q[2]];
    let t = cross(u, v).map(|x| x + x);
    let ut = cross(u, t);
    [0, 1, 2].map(|i| v[i] + q[3] * t[i] + ut[i])
}

/// `q / |q|`; NaN for a zero or non-finite quaternion. The norm is taken directly when
/// `|q|²` is a normal number, else after scaling by the largest component (no
/// overflow or underflow for any finite non-zero `q`).
fn normalized<S: OrderedScalar>(q: [S; 4]) -> [S; 4] {
    let n2 = dot4(q, q);
    if n2 >= S::from_f64(1e-30) && n2.is_finite() {
        let n = n2.sqrt();
        return q.map(|x| x / n);
    }
    let m = q.iter().fold(S::ZERO, |m, &x| if x.abs() > m { x.abs() } else { m });
    // m = 0: 0/0 = NaN; m = ∞: ∞/∞ or 0/∞ then 0/0 = NaN; a NaN component stays NaN.
    let s = q.map(|x| x / m);
    let n = dot4(s, s).sqrt();
    s.map(|x| x / n)
}

/// The coefficients `(a, b) = (sin ω / ω, (1 − cos ω)/ω)` of the planar joint's
/// `V(ω) = [[a, −b], [b, a]]`, from the half angle, by Taylor series below
/// `|ω| = 10⁻²` (exact to rounding there).
fn planar_v<S: OrderedScalar>(w: S) -> (S, S) {
    let c = S::from_f64;
    let w2 = w * w;
    if w < c(1e-2) && w > c(-1e-2) {
        (
            c(1.0) - w2 * (c(1.0 / 6.0) - w2 * (c(1.0 / 120.0) - w2 * c(1.0 / 5040.0))),
            w * (c(0.5) - w2 * (c(1.0 / 24.0) - w2 * (c(1.0 / 720.0) - w2 * c(1.0 / 40320.0)))),
        )
    } else {
        let (sh, ch) = (c(0.5) * w).sin_cos();
        let two_sh = c(2.0) * sh;
        (two_sh * ch / w, two_sh * sh / w)
    }
}

/// `α = (ω/2) cot(ω/2)`, the diagonal of the planar joint's `V(ω)⁻¹`, by Taylor series
/// below `|ω| = 10⁻²`.
fn planar_v_inverse<S: OrderedScalar>(w: S) -> S {
    let c = S::from_f64;
    let w2 = w * w;
    if w < c(1e-2) && w > c(-1e-2) {
        c(1.0) - w2 * (c(1.0 / 12.0) + w2 * (c(1.0 / 720.0) + w2 * c(1.0 / 30240.0)))
    } else {
        let (sh, ch) = (c(0.5) * w).sin_cos();
        c(0.5) * w * ch / sh
    }
}

/// `exp(ω)` as a unit quaternion `[sin(θ/2) ω/θ, cos(θ/2)]`, and the coefficients
/// `a = (1 − cos θ)/θ²`, `b = (θ − sin θ)/θ³` of `V(ω)`, all by Taylor series below
/// `θ = 10⁻²` (exact to rounding there).
fn exp_so3<S: OrderedScalar>(w: [S; 3]) -> ([S; 4], S, S) {
    let t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    let t = t2.sqrt();
    let (sh, ch) = (S::from_f64(0.5) * t).sin_cos();
    let c = S::from_f64;
    // sin(θ/2)/θ and (θ − sin θ)/θ³.
    let (sinc_half, b) = if t < c(1e-2) {
        (
            c(0.5) - t2 * (c(1.0 / 48.0) - t2 * (c(1.0 / 3840.0) - t2 * c(1.0 / 645120.0))),
            c(1.0 / 6.0) - t2 * (c(1.0 / 120.0) - t2 * (c(1.0 / 5040.0) - t2 * c(1.0 / 362880.0))),
        )
    } else {
        (sh / t, (t - c(2.0) * sh * ch) / (t2 * t))
    };
    // 1 − cos θ = 2 sin²(θ/2): no cancellation.
    let a = c(2.0) * sinc_half * sinc_half;
    ([w[0] * sinc_half, w[1] * sinc_half, w[2] * sinc_half, ch], a, b)
}

/// `log(r)` of a unit quaternion on its `w ≥ 0` side, `|ω| = θ ∈ [0, π]`, and the
/// coefficient `β = (1 − (θ/2) cot(θ/2))/θ²` of `[ω]×²` in `V(ω)⁻¹` (Taylor series
/// below `θ = 10⁻²`).
fn log_so3<S: OrderedScalar>(r: [S; 4]) -> ([S; 3], S) {
    let c = S::from_f64;
    let (v, w) = ([r[0], r[1], r[2]], r[3]);
    let (v, w) = if w < S::ZERO { (v.map(|x| -x), -w) } else { (v, w) };
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n == S::ZERO {
        return ([S::ZERO; 3], c(1.0 / 12.0));
    }
    let theta = c(2.0) * n.atan2(w);
    let k = theta / n;
    let beta = if theta < c(1e-2) {
        let t2 = theta * theta;
        c(1.0 / 12.0) + t2 * (c(1.0 / 720.0) + t2 * c(1.0 / 30240.0))
    } else {
        // cot(θ/2) = w / n.
        (S::ONE - c(0.5) * theta * w / n) / (theta * theta)
    };
    (v.map(|x| k * x), beta)
}
