//! The algorithms, run symbolically: each builds its outputs as nodes of a [`Graph`].
//! This is the classical 3D Newton–Euler formulation (Luh, Walker, Paul), written
//! independently of the runtime's 6D spatial reference so the two check each other.
//!
//! Function arguments are numbered: `q` = 0, `v` = 1, `a` = 2 (or `tau` for `aba`),
//! `params` = 3, `joint_params` = 4.

use crate::sym::{Expr, Graph};
use dyngen_model::{JointKind, Model};
use std::ops::{Add, Sub};

pub const ARG_Q: u8 = 0;
pub const ARG_V: u8 = 1;
pub const ARG_A: u8 = 2;
pub const ARG_PARAMS: u8 = 3;
/// `aba` reads joint torques in the slot of `a`.
pub const ARG_TAU: u8 = ARG_A;
/// The joint parameters `[Ia, Fv, Fc, F0]`, 4 per joint.
pub const ARG_JOINT_PARAMS: u8 = 4;

/// A 3-vector of expressions.
#[derive(Clone, Copy, Debug)]
pub struct V3<'g>(pub [Expr<'g>; 3]);

/// A 3×3 matrix of expressions, row-major.
#[derive(Clone, Copy, Debug)]
pub struct M3<'g>(pub [[Expr<'g>; 3]; 3]);

impl<'g> V3<'g> {
    pub fn zero(g: &'g Graph) -> V3<'g> {
        V3([g.zero(); 3])
    }

    pub fn constant(g: &'g Graph, v: [f64; 3]) -> V3<'g> {
        V3(v.map(|x| g.constant(x)))
    }

    pub fn scale(self, s: Expr<'g>) -> V3<'g> {
        V3(self.0.map(|x| x * s))
    }

    pub fn cross(self, o: V3<'g>) -> V3<'g> {
        let [a0, a1, a2] = self.0;
        let [b0, b1, b2] = o.0;
        V3([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])
    }

    pub fn dot(self, o: V3<'g>) -> Expr<'g> {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }
}

impl<'g> Add for V3<'g> {
    type Output = V3<'g>;
    fn add(self, o: V3<'g>) -> V3<'g> {
        V3([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
}

impl<'g> Sub for V3<'g> {
    type Output = V3<'g>;
    fn sub(self, o: V3<'g>) -> V3<'g> {
        V3([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
}

impl<'g> M3<'g> {
    pub fn zero(g: &'g Graph) -> M3<'g> {
        M3([[g.zero(); 3]; 3])
    }

    /// `s · E`.
    pub fn diagonal(g: &'g Graph, s: Expr<'g>) -> M3<'g> {
        let z = g.zero();
        M3([[s, z, z], [z, s, z], [z, z, s]])
    }

    /// The cross-product matrix `S(v)`, `S(v) x = v × x`.
    pub fn skew(v: V3<'g>) -> M3<'g> {
        let [x, y, z] = v.0;
        let o = x.graph().zero();
        M3([[o, -z, y], [z, o, -x], [-y, x, o]])
    }

    pub fn transpose(&self) -> M3<'g> {
        let m = &self.0;
        M3([0, 1, 2].map(|r| [0, 1, 2].map(|c| m[c][r])))
    }

    pub fn add(&self, o: &M3<'g>) -> M3<'g> {
        M3([0, 1, 2].map(|r| [0, 1, 2].map(|c| self.0[r][c] + o.0[r][c])))
    }

    pub fn sub(&self, o: &M3<'g>) -> M3<'g> {
        M3([0, 1, 2].map(|r| [0, 1, 2].map(|c| self.0[r][c] - o.0[r][c])))
    }

    /// `R · self · Rᵀ` for a symmetric `self`: the upper triangle is computed and
    /// mirrored, so both halves are the same nodes.
    pub fn rotate_sym(&self, r: &M3<'g>) -> M3<'g> {
        r.mul(self).mul(&r.transpose()).mirror_upper()
    }

    /// The symmetric matrix of the upper triangle: the lower entries replaced by the
    /// upper ones (the same nodes), for results known to be symmetric.
    pub fn mirror_upper(self) -> M3<'g> {
        let mut m = self.0;
        for a in 0..3 {
            for b in 0..a {
                m[a][b] = m[b][a];
            }
        }
        M3(m)
    }

    /// `R · self · Rᵀ` for a general `self`.
    pub fn rotate(&self, r: &M3<'g>) -> M3<'g> {
        r.mul(self).mul(&r.transpose())
    }

    /// `u vᵀ`.
    pub fn outer(u: V3<'g>, v: V3<'g>) -> M3<'g> {
        M3([0, 1, 2].map(|r| [0, 1, 2].map(|c| u.0[r] * v.0[c])))
    }

    pub fn scale(&self, s: Expr<'g>) -> M3<'g> {
        M3(self.0.map(|row| row.map(|x| x * s)))
    }

    pub fn constant(g: &'g Graph, m: [[f64; 3]; 3]) -> M3<'g> {
        M3(m.map(|row| row.map(|x| g.constant(x))))
    }

    pub fn mul_vec(&self, v: V3<'g>) -> V3<'g> {
        V3(self.0.map(|row| row[0] * v.0[0] + row[1] * v.0[1] + row[2] * v.0[2]))
    }

    /// `selfᵀ · v`.
    pub fn tr_mul_vec(&self, v: V3<'g>) -> V3<'g> {
        let m = &self.0;
        V3([0, 1, 2].map(|c| m[0][c] * v.0[0] + m[1][c] * v.0[1] + m[2][c] * v.0[2]))
    }

    pub fn mul(&self, o: &M3<'g>) -> M3<'g> {
        let (a, b) = (&self.0, &o.0);
        M3([0, 1, 2].map(|r| [0, 1, 2].map(|c| a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c])))
    }
}

/// The placement of body `j` in its parent at the symbolic `q`, kept as two factors
/// so axis-aligned origins and axes fold separately:
/// `x_parent = origin · (motion · x_child) + translation`.
pub struct JointTransform<'g> {
    pub origin: M3<'g>,
    pub motion: M3<'g>,
    pub translation: V3<'g>,
}

impl<'g> JointTransform<'g> {
    pub fn new(g: &'g Graph, model: &Model, j: usize) -> JointTransform<'g> {
        let joint = &model.joints[j - 1];
        let qo = model.q_offset(j) as u32;
        let q = |k: u32| g.input(ARG_Q, qo + k);
        let origin = M3::constant(g, joint.origin.rotation);
        let t0 = V3::constant(g, joint.origin.translation);
        let axis = joint.axis;
        match joint.kind {
            JointKind::Revolute | JointKind::Continuous => JointTransform {
                origin,
                motion: rotation_about(g, axis, q(0)),
                translation: t0,
            },
            JointKind::Prismatic => JointTransform {
                origin,
                motion: M3::constant(g, dyngen_model::math::IDENTITY),
                translation: t0 + origin.mul_vec(V3::constant(g, axis).scale(q(0))),
            },
            JointKind::Spherical => JointTransform {
                origin,
                motion: quaternion_rotation([q(0), q(1), q(2), q(3)]),
                translation: t0,
            },
            JointKind::FreeFlyer => JointTransform {
                origin,
                motion: quaternion_rotation([q(3), q(4), q(5), q(6)]),
                translation: t0 + origin.mul_vec(V3([q(0), q(1), q(2)])),
            },
            JointKind::Planar => JointTransform {
                origin,
                motion: rotation_about(g, axis, q(2)),
                translation: t0 + origin.mul_vec(in_plane(g, axis, q(0), q(1))),
            },
        }
    }

    /// Child coordinates of a parent-frame vector (a rotation only).
    pub fn to_child(&self, x: V3<'g>) -> V3<'g> {
        self.motion.tr_mul_vec(self.origin.tr_mul_vec(x))
    }

    /// Parent coordinates of a child-frame vector (a rotation only).
    pub fn to_parent(&self, x: V3<'g>) -> V3<'g> {
        self.origin.mul_vec(self.motion.mul_vec(x))
    }

    pub fn rotation(&self) -> M3<'g> {
        self.origin.mul(&self.motion)
    }
}

/// `x e₁ + y e₂` on the plane axes ([`dyngen_model::math::plane_basis`]) of the normal
/// `axis`: a planar joint's in-plane coordinates (positions, velocities or
/// accelerations) as a vector of its frame.
pub fn in_plane<'g>(g: &'g Graph, axis: [f64; 3], x: Expr<'g>, y: Expr<'g>) -> V3<'g> {
    let (e1, e2) = dyngen_model::math::plane_basis(&axis);
    V3::constant(g, e1).scale(x) + V3::constant(g, e2).scale(y)
}

/// The rotation of a unit quaternion stored `[x, y, z, w]` (Pinocchio's order), by
/// the formula Eigen's `toRotationMatrix` uses (no normalisation).
pub fn quaternion_rotation<'g>([x, y, z, w]: [Expr<'g>; 4]) -> M3<'g> {
    let g = x.graph();
    let two = g.constant(2.0);
    let (tx, ty, tz) = (two * x, two * y, two * z);
    let (twx, twy, twz) = (tx * w, ty * w, tz * w);
    let (txx, txy, txz) = (tx * x, ty * x, tz * x);
    let (tyy, tyz, tzz) = (ty * y, tz * y, tz * z);
    let one = g.one();
    M3([
        [one - (tyy + tzz), txy - twz, txz + twy],
        [txy + twz, one - (txx + tzz), tyz - twx],
        [txz - twy, tyz + twx, one - (txx + tyy)],
    ])
}

/// The time derivative of position coordinate `index` of `model` at velocity `v`
/// (inputs [`ARG_Q`] and [`ARG_V`]): `v` itself for a joint with an axis; for a
/// quaternion `q̇ = ½ q ⊗ (ω, 0)` with `ω` in the child frame; for a free flyer's
/// position `ṗ = R(q) v`; for a planar joint's `[ẋ, ẏ] = R(θ) [vx, vy]`, `θ̇ = ω`.
/// `None` if `index` is out of range. What forward-mode tangents along the motion
/// ([`Graph::tangents`]) seed each `q` with.
pub fn q_dot<'g>(g: &'g Graph, model: &Model, index: usize) -> Option<Expr<'g>> {
    let j = model.joint_of_q(index)?;
    let joint = &model.joints[j - 1];
    let (k, qo, vo) = (
        index - model.q_offset(j),
        model.q_offset(j) as u32,
        model.v_offset(j) as u32,
    );
    let q = |i: u32| g.input(ARG_Q, qo + i);
    let v = |i: u32| g.input(ARG_V, vo + i);
    let quaternion_rate = |first: u32, w0: u32, k: usize| {
        let (qv, qw) = (V3([q(first), q(first + 1), q(first + 2)]), q(first + 3));
        let w = V3([v(w0), v(w0 + 1), v(w0 + 2)]);
        let half = g.constant(0.5);
        if k < 3 {
            (w.scale(qw) + qv.cross(w)).0[k] * half
        } else {
            -(qv.dot(w) * half)
        }
    };
    Some(match joint.kind {
        JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic => v(0),
        JointKind::Spherical => quaternion_rate(0, 0, k),
        JointKind::FreeFlyer if k < 3 => {
            let r = quaternion_rotation([q(3), q(4), q(5), q(6)]);
            r.mul_vec(V3([v(0), v(1), v(2)])).0[k]
        }
        JointKind::FreeFlyer => quaternion_rate(3, 3, k - 3),
        JointKind::Planar if k < 2 => {
            let (s, c) = (q(2).sin(), q(2).cos());
            if k == 0 {
                c * v(0) - s * v(1)
            } else {
                s * v(0) + c * v(1)
            }
        }
        JointKind::Planar => v(2),
    })
}

/// Rodrigues' formula `R = c E + s [a]× + (1 − c) a aᵀ`, with the numeric
/// coefficients of `c`, `s` and `1` combined before any symbol is built, so that an
/// axis along x, y or z gives the familiar four-entry rotation.
pub fn rotation_about<'g>(g: &'g Graph, a: [f64; 3], q: Expr<'g>) -> M3<'g> {
    let (s, c) = (q.sin(), q.cos());
    let skew = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
    M3([0, 1, 2].map(|r| {
        [0, 1, 2].map(|k| {
            let delta = if r == k { 1.0 } else { 0.0 };
            let aa = a[r] * a[k];
            g.constant(aa) + g.constant(delta - aa) * c + g.constant(skew[r][k]) * s
        })
    }))
}

/// Starts the section of emitted code where body `j`'s step of a pass is computed
/// (see [`Graph::mark`]), so the code says where each body's recursion starts.
fn mark_body(g: &Graph, model: &Model, j: usize, step: &str) {
    g.mark(format!("body {j} ({}): {step}", model.bodies[j - 1].name));
}

/// Every body's pose in the base frame: `(rotation, translation)`, body 1 first.
pub fn forward_kinematics<'g>(g: &'g Graph, model: &Model) -> Vec<(M3<'g>, V3<'g>)> {
    let mut poses: Vec<(M3<'g>, V3<'g>)> = Vec::with_capacity(model.dof());
    for j in 1..=model.dof() {
        mark_body(g, model, j, "pose");
        let x = JointTransform::new(g, model, j);
        let pose = match model.parent(j) {
            0 => (x.rotation(), x.translation),
            p => {
                let (rp, tp) = poses[p - 1];
                (rp.mul(&x.origin).mul(&x.motion), tp + rp.mul_vec(x.translation))
            }
        };
        poses.push(pose);
    }
    poses
}

/// One body's standard parameters as expressions: mass, first moment `h = m c`, and
/// the inertia about the body-frame origin. Inputs for the dynamics; constants
/// (unit vectors, columns of `P`) for the regressors, where folding then yields each
/// column of the regressor directly.
#[derive(Clone, Copy)]
pub struct BodyParams<'g> {
    pub m: Expr<'g>,
    pub h: V3<'g>,
    pub inertia: M3<'g>,
}

impl<'g> BodyParams<'g> {
    /// Body `j`'s 10 parameters read from `params`.
    pub fn input(g: &'g Graph, j: usize) -> BodyParams<'g> {
        let p = |k: usize| g.input(ARG_PARAMS, (10 * (j - 1) + k) as u32);
        BodyParams::from_standard([0, 1, 2, 3, 4, 5, 6, 7, 8, 9].map(p))
    }

    /// Constant parameters (Pinocchio order).
    pub fn constant(g: &'g Graph, p: [f64; 10]) -> BodyParams<'g> {
        BodyParams::from_standard(p.map(|x| g.constant(x)))
    }

    /// The `k`-th unit parameter vector: the regressor column of parameter `k`.
    pub fn unit(g: &'g Graph, k: usize) -> BodyParams<'g> {
        let mut p = [0.0; 10];
        p[k] = 1.0;
        BodyParams::constant(g, p)
    }

    fn from_standard(p: [Expr<'g>; 10]) -> BodyParams<'g> {
        BodyParams {
            m: p[0],
            h: V3([p[1], p[2], p[3]]),
            inertia: M3([[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]]),
        }
    }

    /// The net wrench about the body origin that produces the body's motion:
    /// `f = m a + ω̇×h + ω×(ω×h)`, `n = I ω̇ + ω×(I ω) + h×a`, with `a` the origin's
    /// acceleration (gravity included as `−g`).
    pub fn wrench(&self, m: &BodyMotion<'g>) -> Force<'g> {
        let (w, wd, a) = (m.w, m.wd, m.acc);
        Force {
            f: a.scale(self.m) + wd.cross(self.h) + w.cross(w.cross(self.h)),
            n: self.inertia.mul_vec(wd) + w.cross(self.inertia.mul_vec(w)) + self.h.cross(a),
        }
    }
}

/// A spatial force: force `f`, moment `n` about the frame origin.
#[derive(Clone, Copy, Debug)]
pub struct Force<'g> {
    pub f: V3<'g>,
    pub n: V3<'g>,
}

/// A spatial motion: linear part `v` of the frame origin, angular part `w`.
#[derive(Clone, Copy, Debug)]
pub struct Motion<'g> {
    pub v: V3<'g>,
    pub w: V3<'g>,
}

impl<'g> Force<'g> {
    pub fn zero(g: &'g Graph) -> Force<'g> {
        Force {
            f: V3::zero(g),
            n: V3::zero(g),
        }
    }

    /// Power with a motion: `f·v + n·ω`.
    pub fn dot(self, m: Motion<'g>) -> Expr<'g> {
        self.f.dot(m.v) + self.n.dot(m.w)
    }
}

impl<'g> Motion<'g> {
    pub fn zero(g: &'g Graph) -> Motion<'g> {
        Motion {
            v: V3::zero(g),
            w: V3::zero(g),
        }
    }

    pub fn scale(self, s: Expr<'g>) -> Motion<'g> {
        Motion {
            v: self.v.scale(s),
            w: self.w.scale(s),
        }
    }

    /// Motion cross product `self ×m m`.
    pub fn cross_motion(self, m: Motion<'g>) -> Motion<'g> {
        Motion {
            v: self.w.cross(m.v) + self.v.cross(m.w),
            w: self.w.cross(m.w),
        }
    }

    /// Force cross product `self ×* f`.
    pub fn cross_force(self, f: Force<'g>) -> Force<'g> {
        Force {
            f: self.w.cross(f.f),
            n: self.w.cross(f.n) + self.v.cross(f.f),
        }
    }
}

impl<'g> Add for Force<'g> {
    type Output = Force<'g>;
    fn add(self, o: Force<'g>) -> Force<'g> {
        Force {
            f: self.f + o.f,
            n: self.n + o.n,
        }
    }
}

impl<'g> Add for Motion<'g> {
    type Output = Motion<'g>;
    fn add(self, o: Motion<'g>) -> Motion<'g> {
        Motion {
            v: self.v + o.v,
            w: self.w + o.w,
        }
    }
}

impl<'g> JointTransform<'g> {
    /// A parent-frame motion seen at the child origin in child axes.
    pub fn motion_to_child(&self, m: Motion<'g>) -> Motion<'g> {
        Motion {
            v: self.to_child(m.v + m.w.cross(self.translation)),
            w: self.to_child(m.w),
        }
    }

    /// A child-frame force re-expressed in the parent frame, moment about its origin.
    pub fn force_to_parent(&self, f: Force<'g>) -> Force<'g> {
        let fp = self.to_parent(f.f);
        Force {
            f: fp,
            n: self.to_parent(f.n) + self.translation.cross(fp),
        }
    }
}

/// Joint `j`'s motion subspace in its own frame, one motion per degree of freedom:
/// `(0, axis)` for rotation, `(axis, 0)` for translation, the three unit angular
/// motions for a ball joint, the six unit motions (linear first) for a free flyer,
/// `(e₁, 0)`, `(e₂, 0)`, `(0, axis)` for a planar joint.
pub fn subspace<'g>(g: &'g Graph, model: &Model, j: usize) -> Vec<Motion<'g>> {
    let joint = &model.joints[j - 1];
    let unit = |k: usize| {
        let mut e = [0.0; 3];
        e[k] = 1.0;
        V3::constant(g, e)
    };
    match joint.kind {
        JointKind::Revolute | JointKind::Continuous => vec![Motion {
            v: V3::zero(g),
            w: V3::constant(g, joint.axis),
        }],
        JointKind::Prismatic => vec![Motion {
            v: V3::constant(g, joint.axis),
            w: V3::zero(g),
        }],
        JointKind::Spherical => (0..3)
            .map(|k| Motion {
                v: V3::zero(g),
                w: unit(k),
            })
            .collect(),
        JointKind::FreeFlyer => (0..6)
            .map(|k| Motion {
                v: if k < 3 { unit(k) } else { V3::zero(g) },
                w: if k < 3 { V3::zero(g) } else { unit(k - 3) },
            })
            .collect(),
        JointKind::Planar => {
            let (e1, e2) = dyngen_model::math::plane_basis(&joint.axis);
            vec![
                Motion {
                    v: V3::constant(g, e1),
                    w: V3::zero(g),
                },
                Motion {
                    v: V3::constant(g, e2),
                    w: V3::zero(g),
                },
                Motion {
                    v: V3::zero(g),
                    w: V3::constant(g, joint.axis),
                },
            ]
        }
    }
}

/// `S_j x`: joint `j`'s motion for its coordinates `x` (velocities or accelerations).
pub fn subspace_times<'g>(g: &'g Graph, model: &Model, j: usize, x: &[Expr<'g>]) -> Motion<'g> {
    let joint = &model.joints[j - 1];
    let axis = V3::constant(g, joint.axis);
    match joint.kind {
        JointKind::Revolute | JointKind::Continuous => Motion {
            v: V3::zero(g),
            w: axis.scale(x[0]),
        },
        JointKind::Prismatic => Motion {
            v: axis.scale(x[0]),
            w: V3::zero(g),
        },
        JointKind::Spherical => Motion {
            v: V3::zero(g),
            w: V3([x[0], x[1], x[2]]),
        },
        JointKind::FreeFlyer => Motion {
            v: V3([x[0], x[1], x[2]]),
            w: V3([x[3], x[4], x[5]]),
        },
        JointKind::Planar => Motion {
            v: in_plane(g, joint.axis, x[0], x[1]),
            w: axis.scale(x[2]),
        },
    }
}

/// The velocity coordinates of joint `j`: `v_offset(j)..v_offset(j) + nv`.
pub fn dofs(model: &Model, j: usize) -> std::ops::Range<usize> {
    let o = model.v_offset(j);
    o..o + model.joints[j - 1].kind.nv()
}

/// Which of `v` and `a` are inputs; the others are zero (and fold away).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inputs {
    /// `rnea(q, v, a)`.
    Full,
    /// `nonlinear_effects(q, v) = rnea(q, v, 0)`.
    NoAcceleration,
    /// `generalized_gravity(q) = rnea(q, 0, 0)`.
    Static,
}

/// A body's angular velocity `w`, angular acceleration `wd`, and the acceleration
/// `acc` of its frame origin (gravity included as `−g`), all in body axes.
#[derive(Clone, Copy, Debug)]
pub struct BodyMotion<'g> {
    pub w: V3<'g>,
    pub wd: V3<'g>,
    pub acc: V3<'g>,
}

/// Everything the algorithms share: joint transforms and body motions (index 0 is
/// the base, at rest, accelerating at `−g`).
pub struct Kinematics<'g> {
    pub x: Vec<JointTransform<'g>>,
    pub motion: Vec<BodyMotion<'g>>,
}

/// The forward Newton–Euler pass.
pub fn kinematics<'g>(g: &'g Graph, model: &Model, inputs: Inputs) -> Kinematics<'g> {
    let qd = |d: usize| {
        if inputs == Inputs::Static {
            g.zero()
        } else {
            g.input(ARG_V, d as u32)
        }
    };
    let qdd = |d: usize| {
        if inputs == Inputs::Full {
            g.input(ARG_A, d as u32)
        } else {
            g.zero()
        }
    };
    kinematics_with(g, model, qd, qdd)
}

/// The forward Newton–Euler pass with the velocity `qd(d)` and acceleration `qdd(d)`
/// of each velocity coordinate `d` given as expressions (asked for joint by joint,
/// a joint's velocities first).
pub fn kinematics_with<'g>(
    g: &'g Graph,
    model: &Model,
    qd: impl Fn(usize) -> Expr<'g>,
    qdd: impl Fn(usize) -> Expr<'g>,
) -> Kinematics<'g> {
    let n = model.dof();
    let mut x: Vec<JointTransform<'g>> = Vec::with_capacity(n);
    let mut motion = vec![BodyMotion {
        w: V3::zero(g),
        wd: V3::zero(g),
        acc: V3::constant(g, model.gravity.map(|c| -c)),
    }];
    for j in 1..=n {
        mark_body(g, model, j, "joint transform, velocities and accelerations");
        x.push(JointTransform::new(g, model, j));
        let joint = &model.joints[j - 1];
        let p = joint.parent;
        let xj = &x[j - 1];
        let qds: Vec<Expr<'g>> = dofs(model, j).map(&qd).collect();
        let qdds: Vec<Expr<'g>> = dofs(model, j).map(&qdd).collect();
        let t = xj.translation;
        let mp = motion[p];
        // Acceleration of the joint-frame origin, still in parent axes.
        let a_origin = mp.acc + mp.wd.cross(t) + mp.w.cross(mp.w.cross(t));
        let w_in = xj.to_child(mp.w);
        let wd_in = xj.to_child(mp.wd);
        let a_in = xj.to_child(a_origin);
        // The joint's velocity (ω_q, v_q) and acceleration (ω̇_q, a_q) in body axes
        // (terms a joint does not have fold away): ω = ω_in + ω_q,
        // ω̇ = ω̇_in + ω̇_q + ω_in × ω_q, a = a_in + 2 ω_in × v_q + a_q + ω_q × v_q.
        let vq = subspace_times(g, model, j, &qds);
        let two_w_vq = w_in.cross(vq.v).scale(g.constant(2.0));
        let aq = subspace_times(g, model, j, &qdds);
        let m = BodyMotion {
            w: w_in + vq.w,
            wd: wd_in + aq.w + w_in.cross(vq.w),
            acc: a_in + two_w_vq + aq.v + vq.w.cross(vq.v),
        };
        motion.push(m);
    }
    Kinematics { x, motion }
}

/// Outputs of the Newton–Euler recursion.
pub struct Rnea<'g> {
    pub tau: Vec<Expr<'g>>,
    /// For each joint `j`: the force and the moment about the joint-frame origin that
    /// joint `j` applies to body `j`, in body `j`'s frame.
    pub wrenches: Vec<Force<'g>>,
}

/// Recursive Newton–Euler: forward pass for body velocities and accelerations
/// (gravity as a base acceleration `−g`), per-body Newton–Euler with the symbolic
/// standard parameters, backward pass accumulating what each joint transmits.
pub fn rnea<'g>(g: &'g Graph, model: &Model, inputs: Inputs) -> Rnea<'g> {
    let k = kinematics(g, model, inputs);
    rnea_from(g, model, k)
}

/// [`rnea`] with the accelerations given as expressions (`a[d]` for velocity
/// coordinate `d`), e.g. the outputs of [`aba`]; `q`, `v` and the parameters are inputs.
pub fn rnea_with_acceleration<'g>(g: &'g Graph, model: &Model, a: &[Expr<'g>]) -> Rnea<'g> {
    assert_eq!(a.len(), model.nv(), "one acceleration per velocity coordinate");
    let k = kinematics_with(g, model, |d| g.input(ARG_V, d as u32), |d| a[d]);
    rnea_from(g, model, k)
}

/// The Newton–Euler wrenches and the backward pass over given kinematics.
fn rnea_from<'g>(g: &'g Graph, model: &Model, k: Kinematics<'g>) -> Rnea<'g> {
    let n = model.dof();
    let mut f: Vec<Force<'g>> = (1..=n)
        .map(|j| {
            mark_body(g, model, j, "Newton–Euler wrench");
            BodyParams::input(g, j).wrench(&k.motion[j])
        })
        .collect();
    // Backward pass: children first (regular labelling: higher index first).
    for j in (1..=n).rev() {
        let p = model.parent(j);
        if p > 0 {
            mark_body(g, model, j, "wrench carried to the parent");
            f[p - 1] = f[p - 1] + k.x[j - 1].force_to_parent(f[j - 1]);
        }
    }
    g.mark("joint torques");
    let tau = (1..=n)
        .flat_map(|j| {
            let fj = f[j - 1];
            subspace(g, model, j).into_iter().map(move |s| fj.dot(s))
        })
        .collect();
    Rnea { tau, wrenches: f }
}

/// The joint torque regressor `Y` (n × cols·n) for per-body parameter columns
/// `columns(i)`: entry `(j, cols·(i−1) + c)` is `S_jᵀ` (in body `i`'s frame) times the
/// wrench that column `c` of body `i`'s parameters needs. Blocks where joint `j` does
/// not support body `i` are `None`: structurally zero, never computed.
///
/// Each `S_j` is carried down the tree one body at a time, right before that body's
/// columns use it, so the emitted code keeps few values alive at once.
pub fn torque_regressor<'g>(
    g: &'g Graph,
    model: &Model,
    columns: impl Fn(usize) -> Vec<BodyParams<'g>>,
) -> Vec<Vec<Option<Expr<'g>>>> {
    let (n, nv) = (model.dof(), model.nv());
    let k = kinematics(g, model, Inputs::Full);
    // s[i][d]: the motion of velocity coordinate d in body i's frame (body i 1-based),
    // where d's joint supports body i.
    let mut s: Vec<Vec<Option<Motion<'g>>>> = vec![vec![None; nv]; n + 1];
    let mut y: Vec<Vec<Option<Expr<'g>>>> = vec![Vec::new(); nv];
    for i in 1..=n {
        mark_body(g, model, i, "regressor columns");
        let p = model.parent(i);
        for d in 0..model.v_offset(i) {
            s[i][d] = s[p][d].map(|sd| k.x[i - 1].motion_to_child(sd));
        }
        for (d, sd) in dofs(model, i).zip(subspace(g, model, i)) {
            s[i][d] = Some(sd);
        }
        let wrenches: Vec<Force<'g>> = columns(i).iter().map(|b| b.wrench(&k.motion[i])).collect();
        for (d, row) in y.iter_mut().enumerate() {
            for w in &wrenches {
                row.push(s[i][d].map(|sd| w.dot(sd)));
            }
        }
    }
    y
}

/// Standard parameter columns of body `i`: the 10 unit vectors.
pub fn standard_columns<'g>(g: &'g Graph) -> impl Fn(usize) -> Vec<BodyParams<'g>> + 'g {
    move |_| (0..10).map(|k| BodyParams::unit(g, k)).collect()
}

/// Principal parameter columns of body `i`: the 4 columns of `P_i`.
pub fn principal_columns<'g>(g: &'g Graph, model: &Model) -> impl Fn(usize) -> Vec<BodyParams<'g>> + 'g {
    let ps: Vec<[[f64; 4]; 10]> = dyngen_model::principal_frames(model)
        .iter()
        .map(|f| f.p_matrix())
        .collect();
    move |i| {
        (0..4)
            .map(|c| BodyParams::constant(g, ps[i - 1].map(|row| row[c])))
            .collect()
    }
}

/// The joint wrench regressor (6n × 10n): rows `6(j−1)..6j` are joint `j`'s reaction
/// wrench `[force; moment]` (as [`rnea`]'s `wrenches`) per standard parameter.
pub fn wrench_regressor<'g>(g: &'g Graph, model: &Model) -> Vec<Vec<Option<Expr<'g>>>> {
    let n = model.dof();
    let k = kinematics(g, model, Inputs::Full);
    let mut y: Vec<Vec<Option<Expr<'g>>>> = vec![vec![None; 10 * n]; 6 * n];
    for i in 1..=n {
        mark_body(g, model, i, "regressor columns");
        for c in 0..10 {
            let mut w = BodyParams::unit(g, c).wrench(&k.motion[i]);
            let mut j = i;
            loop {
                for (r, e) in w.f.0.iter().chain(w.n.0.iter()).enumerate() {
                    y[6 * (j - 1) + r][10 * (i - 1) + c] = Some(*e);
                }
                let p = model.parent(j);
                if p == 0 {
                    break;
                }
                w = k.x[j - 1].force_to_parent(w);
                j = p;
            }
        }
    }
    y
}

/// Composite rigid-body algorithm: the joint-space inertia matrix `M(q)` (nv × nv,
/// symmetric; entries for joints on different branches are exact zeros).
pub fn crba<'g>(g: &'g Graph, model: &Model) -> Vec<Vec<Expr<'g>>> {
    let n = model.dof();
    g.mark("joint transforms");
    let x: Vec<JointTransform<'g>> = (1..=n).map(|j| JointTransform::new(g, model, j)).collect();
    let mut composite: Vec<BodyParams<'g>> = (1..=n).map(|j| BodyParams::input(g, j)).collect();
    for i in (1..=n).rev() {
        let p = model.parent(i);
        if p > 0 {
            mark_body(g, model, i, "composite inertia carried to the parent");
            let moved = composite_to_parent(&x[i - 1], &composite[i - 1]);
            let c = &mut composite[p - 1];
            *c = BodyParams {
                m: c.m + moved.m,
                h: c.h + moved.h,
                inertia: c.inertia.add(&moved.inertia),
            };
        }
    }
    let nv = model.nv();
    let mut m = vec![vec![g.zero(); nv]; nv];
    for i in 1..=n {
        mark_body(g, model, i, "row and column of M");
        let si = subspace(g, model, i);
        let c = &composite[i - 1];
        for (a, sa) in dofs(model, i).zip(&si) {
            // F = I_c S_a: the momentum of the composite body moving along S_a.
            let mut f = Force {
                f: sa.v.scale(c.m) + sa.w.cross(c.h),
                n: c.inertia.mul_vec(sa.w) + c.h.cross(sa.v),
            };
            for (b, sb) in dofs(model, i).zip(&si) {
                if b <= a {
                    let e = f.dot(*sb);
                    m[a][b] = e;
                    m[b][a] = e;
                }
            }
            let mut j = i;
            while model.parent(j) != 0 {
                f = x[j - 1].force_to_parent(f);
                j = model.parent(j);
                for (b, sb) in dofs(model, j).zip(subspace(g, model, j)) {
                    let e = f.dot(sb);
                    m[a][b] = e;
                    m[b][a] = e;
                }
            }
        }
    }
    m
}

/// A body's parameters seen from its parent frame: `h' = R h + m p`,
/// `I' = R I Rᵀ − m S(p)S(p) − S(p)S(R h) − S(R h)S(p)`.
pub fn composite_to_parent<'g>(x: &JointTransform<'g>, b: &BodyParams<'g>) -> BodyParams<'g> {
    let p = x.translation;
    let rh = x.to_parent(b.h);
    let rot = b.inertia.rotate_sym(&x.motion).rotate_sym(&x.origin);
    let (sp, srh) = (M3::skew(p), M3::skew(rh));
    let shift = sp.mul(&sp).scale(b.m).add(&sp.mul(&srh)).add(&srh.mul(&sp));
    BodyParams {
        m: b.m,
        h: rh + p.scale(b.m),
        inertia: rot.sub(&shift).mirror_upper(),
    }
}

/// A spatial (articulated) inertia `[[M, H], [Hᵀ, J]]` acting on `(v, ω)`.
#[derive(Clone, Copy)]
struct Inertia6<'g> {
    m: M3<'g>,
    h: M3<'g>,
    j: M3<'g>,
}

impl<'g> Inertia6<'g> {
    fn rigid(g: &'g Graph, b: &BodyParams<'g>) -> Inertia6<'g> {
        Inertia6 {
            m: M3::diagonal(g, b.m),
            h: M3::skew(b.h).scale(g.constant(-1.0)),
            j: b.inertia,
        }
    }

    fn apply(&self, v: Motion<'g>) -> Force<'g> {
        Force {
            f: self.m.mul_vec(v.v) + self.h.mul_vec(v.w),
            n: self.h.tr_mul_vec(v.v) + self.j.mul_vec(v.w),
        }
    }

    fn add(&self, o: &Inertia6<'g>) -> Inertia6<'g> {
        Inertia6 {
            m: self.m.add(&o.m),
            h: self.h.add(&o.h),
            j: self.j.add(&o.j),
        }
    }

    /// `self − Σ_a W_a U_aᵀ` for `W = U D⁻¹` with `D` symmetric, so `U D⁻¹ Uᵀ` (the
    /// result is symmetric; for one coordinate, `self − U Uᵀ / D`).
    fn minus_products(&self, u: &[Force<'g>], w: &[Force<'g>]) -> Inertia6<'g> {
        let mut out = *self;
        for (ua, wa) in u.iter().zip(w) {
            out.m = out.m.sub(&M3::outer(wa.f, ua.f));
            out.h = out.h.sub(&M3::outer(wa.f, ua.n));
            out.j = out.j.sub(&M3::outer(wa.n, ua.n));
        }
        Inertia6 {
            m: out.m.mirror_upper(),
            h: out.h,
            j: out.j.mirror_upper(),
        }
    }

    /// The inertia with row and column `k` of the 6 × 6 matrix `[[m, h], [hᵀ, j]]`
    /// (acting on `[v; ω]`) set to zero: `k < 3` the linear coordinate `k`, else the
    /// angular coordinate `k − 3`.
    fn without(&self, g: &'g Graph, k: usize) -> Inertia6<'g> {
        let mut out = *self;
        let z = g.zero();
        for r in 0..3 {
            if k < 3 {
                out.m.0[k][r] = z;
                out.m.0[r][k] = z;
                out.h.0[k][r] = z;
            } else {
                out.j.0[k - 3][r] = z;
                out.j.0[r][k - 3] = z;
                out.h.0[r][k - 3] = z;
            }
        }
        out
    }

    /// The same inertia seen from the parent frame: rotate every block, then shift
    /// the reference point: `H' = H − M S(p)`, `J' = J − Hᵀ S(p) + S(p) H − S(p) M S(p)`.
    fn in_parent(&self, x: &JointTransform<'g>) -> Inertia6<'g> {
        let r = |m: &M3<'g>, sym: bool| {
            if sym {
                m.rotate_sym(&x.motion).rotate_sym(&x.origin)
            } else {
                m.rotate(&x.motion).rotate(&x.origin)
            }
        };
        let (m, h, j) = (r(&self.m, true), r(&self.h, false), r(&self.j, true));
        let sp = M3::skew(x.translation);
        let h2 = h.sub(&m.mul(&sp));
        let j2 = j
            .sub(&h.transpose().mul(&sp))
            .add(&sp.mul(&h))
            .sub(&sp.mul(&m).mul(&sp));
        Inertia6 {
            m,
            h: h2,
            j: j2.mirror_upper(),
        }
    }
}

/// The coordinate `k` (0–2 linear, 3–5 angular) when `m` is the unit motion `±e_k`
/// of the body frame, with constant entries.
fn unit_motion(m: Motion<'_>) -> Option<usize> {
    let entries = [m.v.0, m.w.0].concat();
    let values: Option<Vec<f64>> = entries.iter().map(|e| e.as_const()).collect();
    let values = values?;
    let nonzero: Vec<usize> = (0..6).filter(|&k| values[k] != 0.0).collect();
    match nonzero[..] {
        [k] if values[k].abs() == 1.0 => Some(k),
        _ => None,
    }
}

/// Whether [`aba`] adds rotor inertias to the joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Armature {
    /// Rigid bodies only.
    None,
    /// Joint `j`'s rotor inertia `Ia` read from `joint_params[4(j−1)]`, added to the
    /// articulated inertia seen along the joint axis (`D_j = Sᵀ Iᴬ S + Ia`), as
    /// Pinocchio's `armature`: `a = (M(q) + diag(Ia))⁻¹ (tau − h(q, v))`.
    Input,
}

/// The inverse of a small symmetric positive definite matrix (a joint's `D = Sᵀ Iᴬ S`),
/// by `LDLᵀ`: one division per row. A 1 × 1 matrix is one division.
pub fn spd_inverse<'g>(g: &'g Graph, a: &[Vec<Expr<'g>>]) -> Vec<Vec<Expr<'g>>> {
    let k = a.len();
    let mut l = vec![vec![g.zero(); k]; k];
    let mut d = vec![g.zero(); k];
    let mut inv_d = vec![g.zero(); k];
    for j in 0..k {
        d[j] = (0..j).fold(a[j][j], |acc, m| acc - l[j][m] * l[j][m] * d[m]);
        inv_d[j] = g.one() / d[j];
        for i in j + 1..k {
            let e = (0..j).fold(a[i][j], |acc, m| acc - l[i][m] * l[j][m] * d[m]);
            l[i][j] = e * inv_d[j];
        }
    }
    // L⁻¹ (unit lower triangular), then A⁻¹ = L⁻ᵀ D⁻¹ L⁻¹.
    let mut li = vec![vec![g.zero(); k]; k];
    for c in 0..k {
        li[c][c] = g.one();
        for r in c + 1..k {
            li[r][c] = -(c..r).fold(g.zero(), |acc, m| acc + l[r][m] * li[m][c]);
        }
    }
    let mut inv = vec![vec![g.zero(); k]; k];
    for r in 0..k {
        for c in 0..=r {
            let e = (r..k).fold(g.zero(), |acc, m| acc + li[m][r] * inv_d[m] * li[m][c]);
            inv[r][c] = e;
            inv[c][r] = e;
        }
    }
    inv
}

/// Featherstone's articulated-body algorithm: `a = M(q)⁻¹ (tau − h(q, v))`, with
/// `tau` read from the `a` argument slot. One division per degree of freedom: a
/// joint with an axis divides by `D = Sᵀ Iᴬ S`; a ball joint or a free flyer inverts
/// its 3 × 3 or 6 × 6 `D` ([`spd_inverse`]).
pub fn aba<'g>(g: &'g Graph, model: &Model, armature: Armature) -> Vec<Expr<'g>> {
    let n = model.dof();
    g.mark("joint transforms");
    let x: Vec<JointTransform<'g>> = (1..=n).map(|j| JointTransform::new(g, model, j)).collect();
    let s: Vec<Vec<Motion<'g>>> = (1..=n).map(|j| subspace(g, model, j)).collect();
    // Pass 1: velocities, velocity-product accelerations, bias forces.
    let mut v = vec![Motion::zero(g)];
    let mut c = vec![Motion::zero(g)];
    let mut ia = vec![Inertia6 {
        m: M3::zero(g),
        h: M3::zero(g),
        j: M3::zero(g),
    }];
    let mut pa = vec![Force::zero(g)];
    for i in 1..=n {
        mark_body(g, model, i, "velocity and bias force");
        let p = model.parent(i);
        let qd: Vec<Expr<'g>> = dofs(model, i).map(|d| g.input(ARG_V, d as u32)).collect();
        let vj = subspace_times(g, model, i, &qd);
        let vi = x[i - 1].motion_to_child(v[p]) + vj;
        let inertia = Inertia6::rigid(g, &BodyParams::input(g, i));
        pa.push(vi.cross_force(inertia.apply(vi)));
        c.push(vi.cross_motion(vj));
        v.push(vi);
        ia.push(inertia);
    }
    // Pass 2: articulated inertias and bias forces, leaves first. Per joint:
    // U = Iᴬ S, D⁻¹, u = tau − Sᵀ pᴬ.
    let mut u_vec = vec![Vec::new(); n + 1];
    let mut inv_d = vec![Vec::new(); n + 1];
    let mut u = vec![Vec::new(); n + 1];
    for i in (1..=n).rev() {
        mark_body(g, model, i, "articulated inertia");
        let ui: Vec<Force<'g>> = s[i - 1].iter().map(|sk| ia[i].apply(*sk)).collect();
        let rotor = |d: usize| g.input(ARG_JOINT_PARAMS, (4 * d) as u32);
        // D = Sᵀ Iᴬ S (+ the rotor inertias): one division for one coordinate.
        let d: Vec<Vec<Expr<'g>>> = dofs(model, i)
            .zip(&ui)
            .map(|(a, ua)| {
                dofs(model, i)
                    .zip(&s[i - 1])
                    .map(|(b, sb)| match armature {
                        Armature::Input if a == b => ua.dot(*sb) + rotor(a),
                        _ => ua.dot(*sb),
                    })
                    .collect()
            })
            .collect();
        let id = spd_inverse(g, &d);
        let ui_scalar: Vec<Expr<'g>> = dofs(model, i)
            .zip(&s[i - 1])
            .map(|(d, sk)| g.input(ARG_TAU, d as u32) - pa[i].dot(*sk))
            .collect();
        let p = model.parent(i);
        if p > 0 {
            // W = U D⁻¹: Iᴬ − U D⁻¹ Uᵀ = Iᴬ − Σ_a W_a U_aᵀ, and D⁻¹ u.
            let w: Vec<Force<'g>> = (0..ui.len())
                .map(|a| {
                    (0..ui.len()).fold(Force::zero(g), |acc, b| {
                        acc + Force {
                            f: ui[b].f.scale(id[a][b]),
                            n: ui[b].n.scale(id[a][b]),
                        }
                    })
                })
                .collect();
            let gain: Vec<Expr<'g>> = (0..ui.len())
                .map(|a| (0..ui.len()).fold(g.zero(), |acc, b| acc + id[a][b] * ui_scalar[b]))
                .collect();
            // Without rotor inertias Iᵃ S = U − U D⁻¹ D = 0 exactly. Where a column of S
            // is a unit motion of the body frame (an axis along x, y or z), Iᵃ's row
            // and column there are zero: say so rather than compute them as rounding
            // noise, which spares their products here and in the transform to the
            // parent. (With a rotor inertia, D = Sᵀ Iᴬ S + Ia and Iᵃ S = U Ia / D.)
            let rigid = armature == Armature::None;
            let a_ia = s[i - 1]
                .iter()
                .filter(|_| rigid)
                .filter_map(|sk| unit_motion(*sk))
                .fold(ia[i].minus_products(&ui, &w), |acc, k| acc.without(g, k));
            let a_pa = ui.iter().zip(&gain).fold(pa[i] + a_ia.apply(c[i]), |acc, (uk, gk)| {
                acc + Force {
                    f: uk.f.scale(*gk),
                    n: uk.n.scale(*gk),
                }
            });
            ia[p] = ia[p].add(&a_ia.in_parent(&x[i - 1]));
            pa[p] = pa[p] + x[i - 1].force_to_parent(a_pa);
        }
        u_vec[i] = ui;
        inv_d[i] = id;
        u[i] = ui_scalar;
    }
    // Pass 3: accelerations, root first; the base accelerates at −g.
    let mut acc = vec![Motion {
        v: V3::constant(g, model.gravity.map(|x| -x)),
        w: V3::zero(g),
    }];
    let mut qdd = Vec::with_capacity(model.nv());
    for i in 1..=n {
        mark_body(g, model, i, "acceleration");
        let p = model.parent(i);
        let a_prime = x[i - 1].motion_to_child(acc[p]) + c[i];
        let r: Vec<Expr<'g>> = (0..u[i].len()).map(|k| u[i][k] - u_vec[i][k].dot(a_prime)).collect();
        let qi: Vec<Expr<'g>> = (0..r.len())
            .map(|a| (0..r.len()).fold(g.zero(), |acc, b| acc + inv_d[i][a][b] * r[b]))
            .collect();
        acc.push(a_prime + subspace_times(g, model, i, &qi));
        qdd.extend(qi);
    }
    qdd
}

/// The paper's per-body model (`docs/design.md`, "The generated algorithms"): for each body, `A_i` (6 × 4, row-major)
/// with `[F; M] = A_i θ_i` in the body's centroidal principal frame:
/// `A = blkdiag(a_c − g, B(ω, ω̇))`.
pub fn body_regressors<'g>(g: &'g Graph, model: &Model) -> Vec<[[Expr<'g>; 4]; 6]> {
    let k = kinematics(g, model, Inputs::Full);
    let frames = dyngen_model::principal_frames(model);
    (1..=model.dof())
        .map(|i| {
            mark_body(g, model, i, "regressor");
            let f = &frames[i - 1];
            let r = M3::constant(g, f.rotation);
            let c = V3::constant(g, f.com);
            let m = k.motion[i];
            let a_c = r.tr_mul_vec(m.acc + m.wd.cross(c) + m.w.cross(m.w.cross(c)));
            let [w1, w2, w3] = r.tr_mul_vec(m.w).0;
            let [d1, d2, d3] = r.tr_mul_vec(m.wd).0;
            let z = g.zero();
            [
                [a_c.0[0], z, z, z],
                [a_c.0[1], z, z, z],
                [a_c.0[2], z, z, z],
                [z, d1, -(w2 * w3), w2 * w3],
                [z, w3 * w1, d2, -(w3 * w1)],
                [z, -(w1 * w2), w1 * w2, d3],
            ]
        })
        .collect()
}

/// Each body's resultant of the joint reaction wrenches, through the incidence
/// matrix and the body-joint vectors: `F_i = Σ_a S_ia F_a`,
/// `M_i = Σ_a S_ia (M_a + c_ia × F_a)`, moment about the centre of mass, in the
/// body's centroidal principal frame. (For a prismatic joint the point on its
/// inboard body moves with `q`; `c_ia` follows it.)
pub fn body_resultants<'g>(g: &'g Graph, model: &Model) -> Vec<Force<'g>> {
    let n = model.dof();
    let r = rnea(g, model, Inputs::Full);
    g.mark("joint transforms");
    let x: Vec<JointTransform<'g>> = (1..=n).map(|j| JointTransform::new(g, model, j)).collect();
    let s = dyngen_model::graph::incidence(model);
    let c = dyngen_model::graph::body_joint_vectors(model);
    let frames = dyngen_model::principal_frames(model);
    (1..=n)
        .map(|i| {
            mark_body(g, model, i, "resultant");
            let mut total = Force::zero(g);
            for a in 1..=n {
                let sign = s[i][a - 1];
                if sign == 0 {
                    continue;
                }
                // Joint a's wrench in body i's axes: its own frame is body a's.
                let w = r.wrenches[a - 1];
                let (fa, ma) = if a == i {
                    (w.f, w.n)
                } else {
                    (x[a - 1].to_parent(w.f), x[a - 1].to_parent(w.n))
                };
                // c_ia is constant, except that a prismatic joint's point slides along
                // the inboard body with q: use where its frame origin is now.
                let cia = if a != i && model.joints[a - 1].kind == dyngen_model::JointKind::Prismatic {
                    x[a - 1].translation - V3::constant(g, model.bodies[i - 1].inertial.com)
                } else {
                    V3::constant(g, c[i][a - 1])
                };
                let sg = g.constant(f64::from(sign));
                total = total
                    + Force {
                        f: fa.scale(sg),
                        n: (ma + cia.cross(fa)).scale(sg),
                    };
            }
            let rot = M3::constant(g, frames[i - 1].rotation);
            Force {
                f: rot.tr_mul_vec(total.f),
                n: rot.tr_mul_vec(total.n),
            }
        })
        .collect()
}
