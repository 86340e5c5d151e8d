//! Joint models: what each joint type the front ends accept contributes to the
//! algorithms, its placement at `q`, its motion subspace `S` (constant in the child
//! frame for every type here, so the joint's bias acceleration `c_J` is zero) and
//! `Sᵀ f`.

use crate::spatial::{
    cross, mat_mul, mat_tr_vec, mat_vec, Force, Inertia, Mat3, Motion, Rotate, Se3, SpatialMatrix, Vec3,
};
use crate::Real;

/// What a joint allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum JointType {
    /// Rotation about the axis, with position limits.
    Revolute,
    /// Rotation about the axis without limits; its coordinate is the angle (not
    /// Pinocchio's `(cos, sin)` pair).
    Continuous,
    /// Translation along the axis.
    Prismatic,
    /// A ball joint: 4 positions, the unit quaternion `[x, y, z, w]` of the child in
    /// the joint frame; 3 velocities, the angular velocity in the child frame.
    /// Pinocchio's `JointModelSpherical`.
    Spherical,
    /// The free flyer of a floating base (the joint of body 1 on the fixed world): 7
    /// positions `[p; x, y, z, w]`, 6 velocities `[v; ω]` in the body frame.
    /// Pinocchio's `JointModelFreeFlyer`; its "torques" are the wrench on the base.
    FreeFlyer,
    /// Motion in the plane normal to the axis: 3 positions `[x, y, θ]` (the child's
    /// origin on the plane axes `e1`, `e2` of the normal, its turn about the normal),
    /// 3 velocities `[vx, vy, ω]` in the child frame. With the normal `z`,
    /// Pinocchio's `JointModelPlanar` with the angle for its `(cos θ, sin θ)`.
    Planar,
}

impl JointType {
    /// Number of position coordinates: 1, 3, 4 or 7.
    pub const fn nq(self) -> usize {
        match self {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => 1,
            JointType::Planar => 3,
            JointType::Spherical => 4,
            JointType::FreeFlyer => 7,
        }
    }

    /// Number of velocity coordinates: 1, 3 or 6.
    pub const fn nv(self) -> usize {
        match self {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => 1,
            JointType::Spherical | JointType::Planar => 3,
            JointType::FreeFlyer => 6,
        }
    }

    /// A rotation about an axis (revolute or continuous).
    pub const fn is_revolute(self) -> bool {
        matches!(self, JointType::Revolute | JointType::Continuous)
    }

    /// Whether the joint has an axis: the axis of a one-coordinate joint, or the plane
    /// normal of a planar joint. A ball joint and a free flyer have none.
    pub const fn has_axis(self) -> bool {
        self.nv() == 1 || matches!(self, JointType::Planar)
    }

    /// The URDF `type` attribute.
    pub const fn urdf_name(self) -> &'static str {
        match self {
            JointType::Revolute => "revolute",
            JointType::Continuous => "continuous",
            JointType::Prismatic => "prismatic",
            JointType::Spherical => "spherical",
            JointType::FreeFlyer => "floating",
            JointType::Planar => "planar",
        }
    }
}

/// A joint axis, with the coordinate axes told apart so that `f64` code does not
/// multiply by their zeros.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Axis {
    X,
    Y,
    Z,
    /// Any other unit vector.
    Other([f64; 3]),
}

impl Axis {
    /// The axis of the unit vector `a` (`X`, `Y`, `Z` when it is exactly one).
    pub fn new(a: [f64; 3]) -> Axis {
        match a {
            [1.0, 0.0, 0.0] => Axis::X,
            [0.0, 1.0, 0.0] => Axis::Y,
            [0.0, 0.0, 1.0] => Axis::Z,
            _ => Axis::Other(a),
        }
    }

    pub fn vector(self) -> [f64; 3] {
        match self {
            Axis::X => [1.0, 0.0, 0.0],
            Axis::Y => [0.0, 1.0, 0.0],
            Axis::Z => [0.0, 0.0, 1.0],
            Axis::Other(a) => a,
        }
    }

    /// `s · axis`.
    #[inline(always)]
    pub fn scaled<S: Real>(self, c: S::Context, s: S) -> Vec3<S> {
        let z = S::constant(c, 0.0);
        match self {
            Axis::X => [s, z, z],
            Axis::Y => [z, s, z],
            Axis::Z => [z, z, s],
            Axis::Other(a) => [
                S::constant(c, a[0]) * s,
                S::constant(c, a[1]) * s,
                S::constant(c, a[2]) * s,
            ],
        }
    }

    /// `axis · x`.
    #[inline(always)]
    pub fn dot<S: Real>(self, c: S::Context, x: Vec3<S>) -> S {
        match self {
            Axis::X => x[0],
            Axis::Y => x[1],
            Axis::Z => x[2],
            Axis::Other(a) => {
                crate::spatial::dot([S::constant(c, a[0]), S::constant(c, a[1]), S::constant(c, a[2])], x)
            }
        }
    }

    /// The rotation about the axis by the angle whose sine and cosine are `s` and
    /// `c` (Rodrigues, `R = c E + s [a]× + (1 − c) a aᵀ`).
    #[inline(always)]
    pub fn rotation_of<S: Real>(self, ctx: S::Context, s: S, c: S) -> Mat3<S> {
        let (z, o) = (S::constant(ctx, 0.0), S::constant(ctx, 1.0));
        match self {
            Axis::X => [[o, z, z], [z, c, -s], [z, s, c]],
            Axis::Y => [[c, z, s], [z, o, z], [-s, z, c]],
            Axis::Z => [[c, -s, z], [s, c, z], [z, z, o]],
            Axis::Other(a) => {
                let skew = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
                let k = |x: f64| S::constant(ctx, x);
                let e = |r: usize, col: usize| {
                    let delta = if r == col { 1.0 } else { 0.0 };
                    let aa = a[r] * a[col];
                    k(aa) + k(delta - aa) * c + k(skew[r][col]) * s
                };
                [
                    [e(0, 0), e(0, 1), e(0, 2)],
                    [e(1, 0), e(1, 1), e(1, 2)],
                    [e(2, 0), e(2, 1), e(2, 2)],
                ]
            }
        }
    }
}

/// The rotation of the quaternion `[x, y, z, w]`, by the formula Eigen's
/// `toRotationMatrix` uses (no normalisation, as Pinocchio).
#[inline(always)]
pub fn quaternion_rotation<S: Real>(ctx: S::Context, [x, y, z, w]: [S; 4]) -> Mat3<S> {
    let two = S::constant(ctx, 2.0);
    let one = S::constant(ctx, 1.0);
    let (tx, ty, tz) = (two * x, two * y, two * z);
    let (twx, twy, twz) = (tx * w, ty * w, tz * w);
    let (txx, txy, txz) = (tx * x, ty * x, tz * x);
    let (tyy, tyz, tzz) = (ty * y, tz * y, tz * z);
    [
        [one - (tyy + tzz), txy - twz, txz + twy],
        [txy + twz, one - (txx + tzz), tyz - twx],
        [txz - twy, tyz + twx, one - (txx + tyy)],
    ]
}

/// One joint of a [`crate::Multibody`]: joint `i` (0-based) carries body `i + 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    pub kind: JointType,
    /// The parent body: 0 is the fixed base (the world under a free flyer).
    pub parent: usize,
    /// The joint frame at `q = 0` in the parent body's frame.
    pub origin: Se3<f64>,
    /// The axis of a revolute or prismatic joint, the plane normal of a planar one;
    /// unused otherwise.
    pub axis: Axis,
    /// The in-plane axes of a planar joint (`x`, `y` for the normal `z`).
    pub plane: [[f64; 3]; 2],
    /// First position and velocity coordinate.
    pub q_offset: usize,
    pub v_offset: usize,
}

/// The placement `x` in the numbers `S` (made in context `c`).
#[inline(always)]
pub fn constant_se3<S: Real>(c: S::Context, x: &Se3<f64>) -> Se3<S> {
    let r = &x.rotation;
    Se3 {
        rotation: [constant_vec(c, r[0]), constant_vec(c, r[1]), constant_vec(c, r[2])],
        translation: constant_vec(c, x.translation),
    }
}

#[inline(always)]
pub(crate) fn constant_vec<S: Real>(c: S::Context, v: [f64; 3]) -> Vec3<S> {
    [S::constant(c, v[0]), S::constant(c, v[1]), S::constant(c, v[2])]
}

impl Joint {
    pub fn nq(&self) -> usize {
        self.kind.nq()
    }

    pub fn nv(&self) -> usize {
        self.kind.nv()
    }

    /// The child body's placement in the parent at the joint's coordinates `q`
    /// (its `nq` entries): the origin, then the joint's own motion, kept as factors.
    #[inline(always)]
    pub fn placement<S: Real>(&self, c: S::Context, q: &[S]) -> JointPlacement<S> {
        let origin = constant_se3::<S>(c, &self.origin);
        let about = |angle: S| {
            let (s, co) = angle.sin_cos();
            match self.axis {
                Axis::X => Rotation::X { s, c: co },
                Axis::Y => Rotation::Y { s, c: co },
                Axis::Z => Rotation::Z { s, c: co },
                Axis::Other(_) => Rotation::Matrix(self.axis.rotation_of(c, s, co)),
            }
        };
        let (motion, offset) = match self.kind {
            JointType::Revolute | JointType::Continuous => (about(q[0]), None),
            JointType::Prismatic => (Rotation::Identity, Some(self.axis.scaled(c, q[0]))),
            JointType::Spherical => (Rotation::Matrix(quaternion_rotation(c, [q[0], q[1], q[2], q[3]])), None),
            JointType::FreeFlyer => (
                Rotation::Matrix(quaternion_rotation(c, [q[3], q[4], q[5], q[6]])),
                Some([q[0], q[1], q[2]]),
            ),
            JointType::Planar => {
                let [e1, e2] = self.plane;
                let t = crate::spatial::add(
                    crate::spatial::scale(q[0], constant_vec(c, e1)),
                    crate::spatial::scale(q[1], constant_vec(c, e2)),
                );
                (about(q[2]), Some(t))
            }
        };
        let rotated = |t: Vec3<S>| {
            if self.origin_is_rotated() {
                crate::spatial::mat_vec(&origin.rotation, t)
            } else {
                t
            }
        };
        JointPlacement {
            origin: self.origin_is_rotated().then_some(origin.rotation),
            motion,
            translation: match offset {
                Some(t) => crate::spatial::add(origin.translation, rotated(t)),
                None => origin.translation,
            },
        }
    }

    /// Whether the joint moves its child's origin (`S` has a linear part).
    #[inline(always)]
    pub fn moves_linearly(&self) -> bool {
        matches!(
            self.kind,
            JointType::Prismatic | JointType::Planar | JointType::FreeFlyer
        )
    }

    /// Whether the origin turns the joint frame (its rotation is not exactly `E`).
    #[inline(always)]
    fn origin_is_rotated(&self) -> bool {
        self.origin.rotation != [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    }

    /// `S v`: the joint's spatial velocity in the child frame for its `nv`
    /// velocity (or acceleration) coordinates.
    #[inline(always)]
    pub fn motion<S: Real>(&self, c: S::Context, v: &[S]) -> Motion<S> {
        let z = S::constant(c, 0.0);
        match self.kind {
            JointType::Revolute | JointType::Continuous => Motion {
                linear: [z; 3],
                angular: self.axis.scaled(c, v[0]),
            },
            JointType::Prismatic => Motion {
                linear: self.axis.scaled(c, v[0]),
                angular: [z; 3],
            },
            JointType::Spherical => Motion {
                linear: [z; 3],
                angular: [v[0], v[1], v[2]],
            },
            JointType::FreeFlyer => Motion {
                linear: [v[0], v[1], v[2]],
                angular: [v[3], v[4], v[5]],
            },
            JointType::Planar => {
                let [e1, e2] = self.plane;
                Motion {
                    linear: crate::spatial::add(
                        crate::spatial::scale(v[0], constant_vec(c, e1)),
                        crate::spatial::scale(v[1], constant_vec(c, e2)),
                    ),
                    angular: self.axis.scaled(c, v[2]),
                }
            }
        }
    }

    /// Column `k` of `S`: [`Joint::motion`] of the unit vector `e_k`.
    #[inline(always)]
    pub fn column<S: Real>(&self, c: S::Context, k: usize) -> Motion<S> {
        let mut e = [S::constant(c, 0.0); 6];
        e[k] = S::constant(c, 1.0);
        self.motion(c, &e)
    }

    /// The coordinate `k` of the spatial motion `[v; ω]` (0–2 linear, 3–5 angular)
    /// when column `e` of `S` is the unit motion along it, `None` when it is not.
    #[inline(always)]
    fn unit_column(&self, e: usize) -> Option<usize> {
        let axis = match self.axis {
            Axis::X => Some(0),
            Axis::Y => Some(1),
            Axis::Z => Some(2),
            Axis::Other(_) => None,
        };
        match self.kind {
            JointType::Revolute | JointType::Continuous => axis.map(|k| 3 + k),
            JointType::Prismatic => axis,
            JointType::Spherical => Some(3 + e),
            JointType::FreeFlyer => Some(e),
            JointType::Planar => None,
        }
    }

    /// `A S_e`, the operator `a` applied to column `e` of `S`: one column of `a`
    /// where `S_e` is a coordinate axis, [`SpatialMatrix::apply`] otherwise.
    #[inline(always)]
    pub fn apply_column<S: Real>(&self, c: S::Context, a: &SpatialMatrix<S>, e: usize) -> Force<S> {
        // Column k of [[a, b], [bᵀ, d]]: k < 3 linear (a's column, b's row), else
        // angular (b's column, d's column).
        let column = |k: usize| {
            if k < 3 {
                Force {
                    linear: [a.a[0][k], a.a[1][k], a.a[2][k]],
                    angular: a.b[k],
                }
            } else {
                let k = k - 3;
                Force {
                    linear: [a.b[0][k], a.b[1][k], a.b[2][k]],
                    angular: [a.d[0][k], a.d[1][k], a.d[2][k]],
                }
            }
        };
        match self.unit_column(e) {
            Some(k) => column(k),
            None => a.apply(self.column(c, e)),
        }
    }

    /// `I S_e` for a rigid-body inertia: the momentum of moving along column `e` of
    /// `S`, read off `I`'s parameters where `S_e` is a coordinate axis.
    #[inline(always)]
    pub fn inertia_column<S: Real>(&self, c: S::Context, i: &Inertia<S>, e: usize) -> Force<S> {
        let z = S::constant(c, 0.0);
        let h = i.first_moment;
        let r = &i.rotational;
        // Unit motion k (< 3 linear, else angular): [m e_k; h × e_k] or
        // [e_k × h; I e_k].
        let column = |k: usize| {
            let unit = |k: usize| {
                let mut u = [z; 3];
                u[k] = S::constant(c, 1.0);
                u
            };
            if k < 3 {
                let mut f = [z; 3];
                f[k] = i.mass;
                Force {
                    linear: f,
                    angular: cross(h, unit(k)),
                }
            } else {
                let k = k - 3;
                let sym = [[r[0], r[1], r[3]], [r[1], r[2], r[4]], [r[3], r[4], r[5]]];
                Force {
                    linear: cross(unit(k), h),
                    angular: sym[k],
                }
            }
        };
        match self.unit_column(e) {
            Some(k) => column(k),
            None => i.apply(self.column(c, e)),
        }
    }

    /// `Sᵀ f` into `out` (its `nv` entries).
    #[inline(always)]
    pub fn project<S: Real>(&self, c: S::Context, f: &Force<S>, out: &mut [S]) {
        match self.kind {
            JointType::Revolute | JointType::Continuous => out[0] = self.axis.dot(c, f.angular),
            JointType::Prismatic => out[0] = self.axis.dot(c, f.linear),
            JointType::Spherical => out[..3].copy_from_slice(&f.angular),
            JointType::FreeFlyer => {
                out[..3].copy_from_slice(&f.linear);
                out[3..6].copy_from_slice(&f.angular);
            }
            JointType::Planar => {
                let [e1, e2] = self.plane;
                out[0] = crate::spatial::dot(constant_vec(c, e1), f.linear);
                out[1] = crate::spatial::dot(constant_vec(c, e2), f.linear);
                out[2] = self.axis.dot(c, f.angular);
            }
        }
    }

    /// `d/dε (q ⊕ ε dv)` at `ε = 0` into `dq` (its `nq` entries): how the joint's
    /// coordinates `q` move along the tangent `dv` (its `nv` entries), `⊕` being
    /// Pinocchio's `integrate` (motion in the child frame). A quaternion
    /// `r = [u; w]` moves by `½ r ⊗ [dω; 0] = ½ [w dω + u × dω; −u·dω]`, a free
    /// flyer's position by `R dv`, a planar joint's by its in-plane velocity turned by
    /// `θ`; one-coordinate joints by `dv` itself.
    #[inline(always)]
    pub fn integrate_tangent<S: Real>(&self, c: S::Context, q: &[S], dv: &[S], dq: &mut [S]) {
        let half = S::constant(c, 0.5);
        let quaternion = |r: &[S], w: [S; 3], out: &mut [S]| {
            let (u, s) = ([r[0], r[1], r[2]], r[3]);
            let x = crate::spatial::add(crate::spatial::scale(s, w), crate::spatial::cross(u, w));
            out[..3].copy_from_slice(&x.map(|x| half * x));
            out[3] = -(half * crate::spatial::dot(u, w));
        };
        match self.kind {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => dq[0] = dv[0],
            JointType::Spherical => quaternion(q, [dv[0], dv[1], dv[2]], dq),
            JointType::FreeFlyer => {
                let r = quaternion_rotation(c, [q[3], q[4], q[5], q[6]]);
                dq[..3].copy_from_slice(&crate::spatial::mat_vec(&r, [dv[0], dv[1], dv[2]]));
                quaternion(&q[3..], [dv[3], dv[4], dv[5]], &mut dq[3..]);
            }
            JointType::Planar => {
                let (s, co) = q[2].sin_cos();
                dq[0] = co * dv[0] - s * dv[1];
                dq[1] = s * dv[0] + co * dv[1];
                dq[2] = dv[2];
            }
        }
    }
}

/// A rotation with its structure kept: about a coordinate axis it is four entries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rotation<S> {
    Identity,
    /// About `x` by the angle of sine `s` and cosine `c`.
    X {
        s: S,
        c: S,
    },
    Y {
        s: S,
        c: S,
    },
    Z {
        s: S,
        c: S,
    },
    Matrix(Mat3<S>),
}

impl<S: Real> Rotation<S> {
    /// `R x`.
    #[inline(always)]
    pub fn apply(&self, x: Vec3<S>) -> Vec3<S> {
        match *self {
            Rotation::Identity => x,
            Rotation::X { s, c } => [x[0], c * x[1] - s * x[2], s * x[1] + c * x[2]],
            Rotation::Y { s, c } => [c * x[0] + s * x[2], x[1], c * x[2] - s * x[0]],
            Rotation::Z { s, c } => [c * x[0] - s * x[1], s * x[0] + c * x[1], x[2]],
            Rotation::Matrix(ref m) => mat_vec(m, x),
        }
    }

    /// `Rᵀ x`.
    #[inline(always)]
    pub fn apply_tr(&self, x: Vec3<S>) -> Vec3<S> {
        match *self {
            Rotation::Identity => x,
            Rotation::X { s, c } => [x[0], c * x[1] + s * x[2], c * x[2] - s * x[1]],
            Rotation::Y { s, c } => [c * x[0] - s * x[2], x[1], s * x[0] + c * x[2]],
            Rotation::Z { s, c } => [c * x[0] + s * x[1], c * x[1] - s * x[0], x[2]],
            Rotation::Matrix(ref m) => mat_tr_vec(m, x),
        }
    }

    /// The matrix.
    #[inline(always)]
    pub fn matrix(&self, z: S, o: S) -> Mat3<S> {
        match *self {
            Rotation::Identity => [[o, z, z], [z, o, z], [z, z, o]],
            Rotation::X { s, c } => [[o, z, z], [z, c, -s], [z, s, c]],
            Rotation::Y { s, c } => [[c, z, s], [z, o, z], [-s, z, c]],
            Rotation::Z { s, c } => [[c, -s, z], [s, c, z], [z, z, o]],
            Rotation::Matrix(m) => m,
        }
    }
}

/// A body's placement in its parent, `x_parent = R₀ (R_q x_child) + p`: the joint's
/// constant origin rotation `R₀` (`None` when it is `E`) and the rotation `R_q` of its
/// coordinates kept apart, so that applying either costs what its structure needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointPlacement<S> {
    pub origin: Option<Mat3<S>>,
    pub motion: Rotation<S>,
    /// The child's origin in the parent frame.
    pub translation: Vec3<S>,
}

impl<S: Real> JointPlacement<S> {
    /// A parent-frame vector in child axes: `R_qᵀ R₀ᵀ x`.
    #[inline(always)]
    pub fn to_child(&self, x: Vec3<S>) -> Vec3<S> {
        let x = match self.origin {
            Some(ref r) => mat_tr_vec(r, x),
            None => x,
        };
        self.motion.apply_tr(x)
    }

    /// A child-frame vector in parent axes: `R₀ R_q x`.
    #[inline(always)]
    pub fn to_parent(&self, x: Vec3<S>) -> Vec3<S> {
        let x = self.motion.apply(x);
        match self.origin {
            Some(ref r) => mat_vec(r, x),
            None => x,
        }
    }

    /// The placement as one rotation and translation.
    #[inline(always)]
    pub fn se3(&self, z: S, o: S) -> Se3<S> {
        let m = self.motion.matrix(z, o);
        Se3 {
            rotation: match self.origin {
                Some(ref r) => mat_mul(r, &m),
                None => m,
            },
            translation: self.translation,
        }
    }

    /// A parent-frame motion in the child frame: `ω' = Rᵀ ω`, `v' = Rᵀ (v − p × ω)`.
    #[inline(always)]
    pub fn motion_to_child(&self, m: Motion<S>) -> Motion<S> {
        Motion {
            linear: self.to_child(crate::spatial::sub(m.linear, cross(self.translation, m.angular))),
            angular: self.to_child(m.angular),
        }
    }

    /// A child-frame force in the parent frame: `f' = R f`, `n' = R n + p × f'`.
    #[inline(always)]
    pub fn force_to_parent(&self, f: Force<S>) -> Force<S> {
        let linear = self.to_parent(f.linear);
        Force {
            linear,
            angular: crate::spatial::add(self.to_parent(f.angular), cross(self.translation, linear)),
        }
    }

    /// A child-frame inertia in the parent frame ([`Inertia::act`]).
    #[inline(always)]
    pub fn inertia_to_parent(&self, i: &Inertia<S>) -> Inertia<S> {
        i.act_with(self, self.translation)
    }

    /// A child-frame articulated inertia in the parent frame ([`SpatialMatrix::act`]).
    #[inline(always)]
    pub fn matrix_to_parent(&self, a: &SpatialMatrix<S>) -> SpatialMatrix<S> {
        a.act_with(self, self.translation)
    }
}

impl<S: Real> Rotate<S> for JointPlacement<S> {
    #[inline(always)]
    fn rotate(&self, x: Vec3<S>) -> Vec3<S> {
        self.to_parent(x)
    }
}
