//! [`Dynamics`]: the algorithms simulation and identification need, behind one
//! object-safe trait, so the same code runs on a generated robot ([`Generated`]) or
//! on any URDF loaded at run time ([`Reference`]).
//!
//! Everything is `f64` over slices, with the layouts of [`Robot`]: `q, v, a, tau` of
//! length `nv()`, standard parameters `params` of length `10 nv()` in Pinocchio's
//! order, row-major matrices. Base parameters are not part of the trait: a generated
//! robot has them from generation time, the reference would have to compute them, so
//! code that needs them asks `dyngen_model::base::analyse`.

use crate::BodyMotion;
use crate::Reference;
use dyngen::{BodyRegressor, Pose, Robot, Wrench};
use dyngen_model::Model;
use nalgebra::SMatrix;
use std::marker::PhantomData;

/// Rigid-body algorithms over one checked [`Model`], in `f64`. Implemented by
/// [`Reference`] (any model, allocates) and by [`Generated`] (a generated robot's
/// unrolled code). Every method panics when a slice has the wrong length.
pub trait Dynamics: Sync {
    /// The checked model, gravity included: the description the algorithms use.
    fn model(&self) -> &Model;

    /// Number of velocity coordinates (`n` when every joint has one coordinate).
    fn nv(&self) -> usize {
        self.model().nv()
    }

    /// Number of standard parameters, 10 per moving body.
    fn nparams(&self) -> usize {
        10 * self.model().dof()
    }

    /// Inverse dynamics `tau = M(q) a + C(q, v) v + g(q)`. `q, v, a, tau`: `n`;
    /// `params`: `10 n`.
    fn rnea(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], tau: &mut [f64]);

    /// Forward dynamics `a = M(q)⁻¹ (tau − C(q, v) v − g(q))`, the inverse of
    /// [`Dynamics::rnea`]. `q, v, tau, a`: `n`; `params`: `10 n`.
    fn aba(&self, q: &[f64], v: &[f64], tau: &[f64], params: &[f64], a: &mut [f64]);

    /// The joint-space mass matrix `M(q)`, row-major into `m` (`n × n`).
    fn crba(&self, q: &[f64], params: &[f64], m: &mut [f64]);

    /// Every moving body's pose in the base frame, body 1 first. `poses`: `n`.
    fn forward_kinematics(&self, q: &[f64], poses: &mut [Pose<f64>]);

    /// Every moving body's spatial velocity and gravity-free spatial acceleration in
    /// its own frame (Pinocchio's `data.v`, `data.a`), body 1 first. `out`: `n`.
    fn body_motions(&self, q: &[f64], v: &[f64], a: &[f64], out: &mut [BodyMotion]);

    /// The wrench joint `j` applies to body `j` (moment about the joint origin, in
    /// frame `j`): Pinocchio's `data.f[j]` after `rnea`. `wrenches`: `n`.
    fn joint_wrenches(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], wrenches: &mut [Wrench<f64>]);

    /// The paper's per-body regressors `A_i` (centroidal principal frames,
    /// docs/design.md, "The paper's decoupled body model"). `out`: `n`.
    fn body_regressors(&self, q: &[f64], v: &[f64], a: &[f64], out: &mut [BodyRegressor<f64>]);

    /// Each body's resultant of the joint reactions, moment about the centre of mass,
    /// in its centroidal principal frame (docs/design.md, "The paper's graph theory"). `out`: `n`.
    fn body_resultants(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], out: &mut [Wrench<f64>]);

    /// `Y(q, v, a)` with `tau = Y π`, row-major into `y` (`n × 10 n`).
    fn joint_torque_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]);

    /// The joint wrench regressor, row-major into `y` (`6 n × 10 n`, rows
    /// `[force; moment]` of joint 1, 2, …).
    fn joint_wrench_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]);

    /// `Y_θ = Y · blkdiag(P_i)` with `tau = Y_θ θ`, row-major into `y` (`n × 4 n`).
    fn principal_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]);
}

fn check_len(name: &str, x: &[impl Sized], expected: usize) {
    assert_eq!(
        x.len(),
        expected,
        "`{name}` has length {}, the model needs {expected}",
        x.len()
    );
}

/// Copies `src` (any length) into `dst` of the same length, naming `dst` when the
/// lengths differ.
fn copy_into<T: Copy>(name: &str, src: &[T], dst: &mut [T]) {
    check_len(name, dst, src.len());
    dst.copy_from_slice(src);
}

/// A column-major nalgebra matrix into a row-major slice.
fn copy_row_major(name: &str, m: &nalgebra::DMatrix<f64>, dst: &mut [f64]) {
    check_len(name, dst, m.nrows() * m.ncols());
    for (r, row) in dst.chunks_exact_mut(m.ncols()).enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = m[(r, c)];
        }
    }
}

fn to_body_regressor(a: &SMatrix<f64, 6, 4>) -> BodyRegressor<f64> {
    BodyRegressor {
        force: a.fixed_rows::<3>(0).into(),
        moment: a.fixed_rows::<3>(3).into(),
    }
}

impl Dynamics for Reference {
    fn model(&self) -> &Model {
        Reference::model(self)
    }

    fn nv(&self) -> usize {
        Reference::nv(self)
    }

    fn rnea(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], tau: &mut [f64]) {
        copy_into("tau", &Reference::rnea(self, q, v, a, params), tau);
    }

    fn aba(&self, q: &[f64], v: &[f64], tau: &[f64], params: &[f64], a: &mut [f64]) {
        copy_into("a", &Reference::aba(self, q, v, tau, params), a);
    }

    fn crba(&self, q: &[f64], params: &[f64], m: &mut [f64]) {
        copy_row_major("m", &Reference::crba(self, q, params), m);
    }

    fn forward_kinematics(&self, q: &[f64], poses: &mut [Pose<f64>]) {
        copy_into("poses", &Reference::forward_kinematics(self, q), poses);
    }

    fn body_motions(&self, q: &[f64], v: &[f64], a: &[f64], out: &mut [BodyMotion]) {
        copy_into("out", &Reference::body_motions(self, q, v, a), out);
    }

    fn joint_wrenches(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], wrenches: &mut [Wrench<f64>]) {
        copy_into("wrenches", &Reference::joint_wrenches(self, q, v, a, params), wrenches);
    }

    fn body_regressors(&self, q: &[f64], v: &[f64], a: &[f64], out: &mut [BodyRegressor<f64>]) {
        let blocks = Reference::body_regressor(self, q, v, a);
        check_len("out", out, blocks.len());
        for (o, b) in out.iter_mut().zip(&blocks) {
            *o = to_body_regressor(b);
        }
    }

    fn body_resultants(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], out: &mut [Wrench<f64>]) {
        copy_into("out", &Reference::body_resultants(self, q, v, a, params), out);
    }

    fn joint_torque_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        Reference::joint_torque_regressor_into(self, q, v, a, y);
    }

    fn joint_wrench_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        copy_row_major("y", &Reference::joint_wrench_regressor(self, q, v, a), y);
    }

    fn principal_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        copy_row_major("y", &Reference::principal_regressor(self, q, v, a), y);
    }
}

/// A generated robot `R` as [`Dynamics`]: every algorithm runs `R`'s generated code,
/// except [`Dynamics::body_motions`], which generated robots do not provide and which
/// runs the reference implementation on the model `R` carries (`R::MODEL`).
///
/// Not zero-sized: it keeps that model as the runtime's [`Model`] (converted once, in
/// [`Generated::new`]), because a generic type cannot own a static.
pub struct Generated<R> {
    reference: Reference,
    robot: PhantomData<fn() -> R>,
}

impl<R: Robot> Generated<R> {
    /// The generated robot `R` with the reference on its own model.
    pub fn new() -> Generated<R> {
        Generated {
            reference: Reference::of::<R>(),
            robot: PhantomData,
        }
    }

    /// The reference implementation of the same model, for cross-checks.
    pub fn reference(&self) -> &Reference {
        &self.reference
    }
}

impl<R: Robot> Default for Generated<R> {
    fn default() -> Self {
        Generated::new()
    }
}

impl<R> Clone for Generated<R> {
    fn clone(&self) -> Self {
        Generated {
            reference: self.reference.clone(),
            robot: PhantomData,
        }
    }
}

impl<R> std::fmt::Debug for Generated<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Generated")
            .field("model", &self.reference.model().name)
            .finish()
    }
}

impl<R: Robot> Dynamics for Generated<R> {
    fn model(&self) -> &Model {
        self.reference.model()
    }

    fn nv(&self) -> usize {
        R::NV
    }

    fn rnea(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], tau: &mut [f64]) {
        R::rnea(q, v, a, params, tau);
    }

    fn aba(&self, q: &[f64], v: &[f64], tau: &[f64], params: &[f64], a: &mut [f64]) {
        R::aba(q, v, tau, params, a);
    }

    fn crba(&self, q: &[f64], params: &[f64], m: &mut [f64]) {
        R::crba(q, params, m);
    }

    fn forward_kinematics(&self, q: &[f64], poses: &mut [Pose<f64>]) {
        R::forward_kinematics(q, poses);
    }

    fn body_motions(&self, q: &[f64], v: &[f64], a: &[f64], out: &mut [BodyMotion]) {
        Dynamics::body_motions(&self.reference, q, v, a, out);
    }

    fn joint_wrenches(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], wrenches: &mut [Wrench<f64>]) {
        R::joint_wrenches(q, v, a, params, wrenches);
    }

    fn body_regressors(&self, q: &[f64], v: &[f64], a: &[f64], out: &mut [BodyRegressor<f64>]) {
        R::body_regressors(q, v, a, out);
    }

    fn body_resultants(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64], out: &mut [Wrench<f64>]) {
        R::body_resultants(q, v, a, params, out);
    }

    fn joint_torque_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        R::joint_torque_regressor(q, v, a, y);
    }

    fn joint_wrench_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        R::joint_wrench_regressor(q, v, a, y);
    }

    fn principal_regressor(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        R::principal_regressor(q, v, a, y);
    }
}
