//! The [`Robot`] trait every generated robot type implements, and the small spatial
//! types of its API.

use crate::Scalar;
use nalgebra::{Matrix3, Vector3};

/// A body's pose in the base frame: `x_base = rotation · x_body + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose<S: Scalar> {
    pub rotation: Matrix3<S>,
    pub translation: Vector3<S>,
}

impl<S: Scalar> Default for Pose<S> {
    fn default() -> Self {
        Pose {
            rotation: Matrix3::from_element(S::ZERO),
            translation: Vector3::from_element(S::ZERO),
        }
    }
}

/// A force and the moment about a stated point, in a stated frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wrench<S: Scalar> {
    pub force: Vector3<S>,
    pub torque: Vector3<S>,
}

impl<S: Scalar> Default for Wrench<S> {
    fn default() -> Self {
        Wrench {
            force: Vector3::from_element(S::ZERO),
            torque: Vector3::from_element(S::ZERO),
        }
    }
}

/// A robot with generated dynamics. Implemented by the types `robot!` and
/// `dyngen_codegen::compile_urdf` generate; runtime code is generic over it.
///
/// Sizes follow Pinocchio: `NQ` positions, `NV` velocities (equal here: every joint
/// has one coordinate, continuous joints included), `NBODIES` moving bodies. The
/// standard parameters are 10 per body in Pinocchio's order
/// `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, inertia about the body-frame
/// origin (`NPARAMS = 10 · NBODIES`).
///
/// The slice methods panic when a slice does not have the documented length, as
/// indexing does; the generated inherent functions take fixed-size arrays instead.
pub trait Robot {
    const NAME: &'static str;
    const NQ: usize;
    const NV: usize;
    const NBODIES: usize;
    const NPARAMS: usize;

    /// Joint names, joint 1 first.
    fn joint_names() -> &'static [&'static str];
    /// Moving body names, body 1 first (body `j` is carried by joint `j`).
    fn body_names() -> &'static [&'static str];
    /// Parent body of each moving body (0 = base), body 1 first.
    fn parents() -> &'static [usize];
    /// The nominal standard parameters of the description, length `NPARAMS`.
    fn nominal_params() -> &'static [f64];
    /// The robot as URDF text (fixed joints already merged), from which the
    /// reference model is rebuilt: `dyngen_model::parse_urdf(R::urdf())`.
    fn urdf() -> &'static str;
    /// Gravity in the base frame the generated code was specialised for, m/s².
    fn gravity() -> [f64; 3];
    /// Operation counts of each generated function, by function name.
    fn op_counts() -> &'static [(&'static str, OpCount)];

    /// Inverse dynamics by the generated Newton–Euler recursion:
    /// `tau = M(q) a + C(q, v) v + g(q)`. `q, v, a, tau`: `NV`; `params`: `NPARAMS`.
    fn rnea<S: Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], tau: &mut [S]);

    /// Every body's pose in the base frame at `q`. `poses`: `NBODIES`.
    fn forward_kinematics<S: Scalar>(q: &[S], poses: &mut [Pose<S>]);

    /// The wrench joint `j` applies to body `j` (force, and moment about the joint
    /// frame origin), in body `j`'s frame: Pinocchio's `data.f[j]` after `rnea`.
    /// `wrenches`: `NBODIES`.
    fn joint_wrenches<S: Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], wrenches: &mut [Wrench<S>]);
}

/// Operation counts of one generated function, as the generator measured them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    pub muls: usize,
    /// Additions and subtractions.
    pub adds: usize,
    pub negs: usize,
    /// `sin` and `cos` evaluations (a fused `sin_cos` counts as two).
    pub trig: usize,
    /// `let` statements emitted.
    pub statements: usize,
}

impl core::fmt::Display for OpCount {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{} mul, {} add, {} neg, {} trig ({} statements)",
            self.muls, self.adds, self.negs, self.trig, self.statements
        )
    }
}
