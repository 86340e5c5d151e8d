//! The algorithms, run symbolically: each builds its outputs as nodes of a [`Graph`].
//! This is the classical 3D Newton–Euler formulation (Luh, Walker, Paul), written
//! independently of the runtime's 6D spatial reference so the two check each other.
//!
//! Function arguments are numbered: `q` = 0, `v` = 1, `a` = 2, `params` = 3.

use crate::sym::{Expr, Graph};
use dyngen_model::{JointKind, Model};
use std::ops::{Add, Sub};

pub const ARG_Q: u8 = 0;
pub const ARG_V: u8 = 1;
pub const ARG_A: u8 = 2;
pub const ARG_PARAMS: u8 = 3;

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
        let q = g.input(ARG_Q, (j - 1) as u32);
        let origin = M3::constant(g, joint.origin.rotation);
        let t0 = V3::constant(g, joint.origin.translation);
        let axis = joint.axis;
        match joint.kind {
            JointKind::Revolute | JointKind::Continuous => JointTransform {
                origin,
                motion: rotation_about(g, axis, q),
                translation: t0,
            },
            JointKind::Prismatic => JointTransform {
                origin,
                motion: M3::constant(g, dyngen_model::math::IDENTITY),
                translation: t0 + origin.mul_vec(V3::constant(g, axis).scale(q)),
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

/// Every body's pose in the base frame: `(rotation, translation)`, body 1 first.
pub fn forward_kinematics<'g>(g: &'g Graph, model: &Model) -> Vec<(M3<'g>, V3<'g>)> {
    let mut poses: Vec<(M3<'g>, V3<'g>)> = Vec::with_capacity(model.dof());
    for j in 1..=model.dof() {
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

/// The standard parameters of body `j` as symbols: mass, first moment `h = m c`,
/// and the inertia about the body-frame origin.
struct BodyParams<'g> {
    m: Expr<'g>,
    h: V3<'g>,
    inertia: M3<'g>,
}

impl<'g> BodyParams<'g> {
    fn input(g: &'g Graph, j: usize) -> BodyParams<'g> {
        let p = |k: usize| g.input(ARG_PARAMS, (10 * (j - 1) + k) as u32);
        BodyParams {
            m: p(0),
            h: V3([p(1), p(2), p(3)]),
            inertia: M3([[p(4), p(5), p(7)], [p(5), p(6), p(8)], [p(7), p(8), p(9)]]),
        }
    }
}

/// Outputs of the Newton–Euler recursion.
pub struct Rnea<'g> {
    pub tau: Vec<Expr<'g>>,
    /// For each joint `j`: the force and the moment about the joint-frame origin that
    /// joint `j` applies to body `j`, in body `j`'s frame.
    pub wrenches: Vec<(V3<'g>, V3<'g>)>,
}

/// Recursive Newton–Euler: forward pass for body velocities and accelerations
/// (gravity as a base acceleration `−g`), per-body Newton–Euler with the symbolic
/// standard parameters, backward pass accumulating what each joint transmits.
pub fn rnea<'g>(g: &'g Graph, model: &Model) -> Rnea<'g> {
    let n = model.dof();
    let x: Vec<JointTransform<'g>> = (1..=n).map(|j| JointTransform::new(g, model, j)).collect();
    // Index 0 is the base.
    let mut w = vec![V3::zero(g)];
    let mut wd = vec![V3::zero(g)];
    let mut acc = vec![V3::constant(g, model.gravity.map(|c| -c))];
    for j in 1..=n {
        let joint = &model.joints[j - 1];
        let p = joint.parent;
        let xj = &x[j - 1];
        let axis = V3::constant(g, joint.axis);
        let qd = g.input(ARG_V, (j - 1) as u32);
        let qdd = g.input(ARG_A, (j - 1) as u32);
        let t = xj.translation;
        // Acceleration of the joint-frame origin, still in parent axes.
        let a_origin = acc[p] + wd[p].cross(t) + w[p].cross(w[p].cross(t));
        let w_in = xj.to_child(w[p]);
        let wd_in = xj.to_child(wd[p]);
        let a_in = xj.to_child(a_origin);
        let (wj, wdj, aj) = if joint.kind.is_revolute() {
            let wq = axis.scale(qd);
            (w_in + wq, wd_in + axis.scale(qdd) + w_in.cross(wq), a_in)
        } else {
            let vq = axis.scale(qd);
            let two_w_vq = w_in.cross(vq).scale(g.constant(2.0));
            (w_in, wd_in, a_in + two_w_vq + axis.scale(qdd))
        };
        w.push(wj);
        wd.push(wdj);
        acc.push(aj);
    }
    // Per-body net wrench about the body origin: f = m a + ω̇×h + ω×(ω×h),
    // n = I ω̇ + ω×(I ω) + h×a.
    let mut f: Vec<V3<'g>> = Vec::with_capacity(n);
    let mut nm: Vec<V3<'g>> = Vec::with_capacity(n);
    for j in 1..=n {
        let b = BodyParams::input(g, j);
        let (wj, wdj, aj) = (w[j], wd[j], acc[j]);
        f.push(aj.scale(b.m) + wdj.cross(b.h) + wj.cross(wj.cross(b.h)));
        nm.push(b.inertia.mul_vec(wdj) + wj.cross(b.inertia.mul_vec(wj)) + b.h.cross(aj));
    }
    // Backward pass: children first (regular labelling: higher index first).
    for j in (1..=n).rev() {
        let p = model.parent(j);
        if p == 0 {
            continue;
        }
        let xj = &x[j - 1];
        let fp = xj.to_parent(f[j - 1]);
        let np = xj.to_parent(nm[j - 1]) + xj.translation.cross(fp);
        f[p - 1] = f[p - 1] + fp;
        nm[p - 1] = nm[p - 1] + np;
    }
    let tau = (1..=n)
        .map(|j| {
            let joint = &model.joints[j - 1];
            let axis = V3::constant(g, joint.axis);
            if joint.kind.is_revolute() {
                axis.dot(nm[j - 1])
            } else {
                axis.dot(f[j - 1])
            }
        })
        .collect();
    Rnea {
        tau,
        wrenches: f.into_iter().zip(nm).collect(),
    }
}
