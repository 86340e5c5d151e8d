//! # dyngen
//!
//! What generated robot code needs, and nothing more: the [`Robot`] trait (the
//! capability traits [`InverseDynamics`], [`MassMatrix`], … over [`RobotDescription`]), the
//! [`Scalar`] trait, the small spatial value types of the API ([`Pose`], [`Wrench`],
//! [`BodyRegressor`]), what the control kernels return ([`FrameJacobian`],
//! [`FrameMotion`], [`Motion`] in a [`ReferenceFrame`], [`RneaDerivatives`],
//! [`AbaDerivatives`] and the [`Linearization`] of a time step, [`log3`]), the model a
//! generated robot carries ([`RobotModel`]), the joint models beyond rigid bodies
//! ([`JointParams`], [`Coulomb`]), the operations on configurations with a floating
//! base or ball joints ([`configuration`]: integrate, difference, neutral, normalize,
//! as Pinocchio's), and the `robot!` macro (feature `macros`). `no_std`: maths come from the standard
//! library (feature `std`, the default) or from `libm` (feature `libm`).
//!
//! A robot comes from the `robot!` macro (feature `macros`: an inline graph-theoretic
//! description, or a URDF file) or from `dyngen_codegen::compile_urdf` in `build.rs`; either way it is
//! a type implementing [`Robot`]. The layers above (reference dynamics, identification,
//! neural-network identification, the command line) are separate crates, so a crate
//! that runs a robot in a control loop links only this one.

#![no_std]

#[cfg(feature = "std")]
extern crate std;

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("dyngen needs the `std` feature or the `libm` feature for sin, cos, sqrt and tanh");

#[cfg(feature = "batch")]
pub mod batch;
pub mod configuration;
mod derivatives;
mod frames;
mod joints;
#[cfg(feature = "batch")]
pub mod lanes;
mod robot;
mod robot_model;
mod scalar;

pub use derivatives::{AbaDerivatives, Linearization, RneaDerivatives};
#[cfg(feature = "macros")]
pub use dyngen_macros::robot;
pub use frames::{log3, FrameJacobian, FrameJacobianTimeVariation, FrameMotion, Motion, ReferenceFrame};
pub use joints::{Coulomb, InvalidEpsilon, JointParams, JOINT_PARAMS_PER_JOINT};
pub use nalgebra;
pub use robot::{
    BodyRegressor, Centroidal, Derivatives, ForwardDynamics, Frames, InverseDynamics, JointDynamics, Kinematics,
    MassMatrix, NotFinite, OpCount, Pose, Regressors, Robot, RobotDescription, Wrench,
};
pub use robot_model::{BodyModel, FrameModel, JointLimits, JointMimic, JointModel, JointType, RobotModel};
pub use scalar::{OrderedScalar, Scalar};

/// The traits a generated robot implements, to bring their methods into scope at
/// once: `use dyngen::prelude::*;`.
pub mod prelude {
    pub use crate::{
        Centroidal, Derivatives, ForwardDynamics, Frames, InverseDynamics, JointDynamics, Kinematics, MassMatrix,
        Regressors, Robot, RobotDescription, Scalar,
    };
}

/// Support for generated code; not a public API.
#[doc(hidden)]
pub mod __private {
    pub use crate::derivatives::__accelerations as accelerations;
    pub use crate::derivatives::__times_minus_minv as times_minus_minv;
    pub use crate::derivatives::__times_minus_minv_sparse as times_minus_minv_sparse;
    pub use crate::frames::__express_jacobian as express_jacobian;
    pub use crate::frames::__express_jacobian_time_variation as express_jacobian_time_variation;
    pub use crate::frames::__frame_jacobian_time_variation_from_axes as frame_jacobian_time_variation_from_axes;
    pub use crate::frames::__frame_motion as frame_motion;
    pub use crate::joints::__tree_ldl_solve as tree_ldl_solve;

    /// `Y_θ = Y · blkdiag(P_i)`: the principal regressor (4 columns per body) from the
    /// standard one (10 per body), `maps[i]` body `i`'s `P_i` (`π_i = P_i θ_i`). A body
    /// whose 10 columns are zero in a row (a joint that does not carry it) gives zeros
    /// without products; the others take a row of `P_i` at a time, four independent
    /// products that vectorise.
    pub fn principal_columns<S: crate::Scalar, const P: usize, const T: usize, const N: usize>(
        y: &[[S; P]; N],
        maps: &[[[f64; 4]; 10]],
        out: &mut [[S; T]; N],
    ) {
        for (row, full) in out.iter_mut().zip(y) {
            for ((theta, pi), map) in row.chunks_exact_mut(4).zip(full.chunks_exact(10)).zip(maps) {
                let mut t = [S::ZERO; 4];
                if pi.iter().any(|&x| x != S::ZERO) {
                    for (&x, m) in pi.iter().zip(map) {
                        for c in 0..4 {
                            t[c] = S::mul_add(x, S::from_f64(m[c]), t[c]);
                        }
                    }
                }
                theta.copy_from_slice(&t);
            }
        }
    }

    /// A slice as a fixed-size array, with a message naming the argument when the
    /// length is wrong.
    #[inline(always)]
    #[track_caller]
    pub fn as_array<'a, S, const N: usize>(x: &'a [S], what: &str) -> &'a [S; N] {
        match x.try_into() {
            Ok(a) => a,
            Err(_) => panic!("dyngen: `{what}` has length {}, expected {N}", x.len()),
        }
    }

    /// A row-major slice as a fixed-size matrix `[[S; C]; R]`, with a message naming
    /// the argument when the length is wrong.
    #[inline(always)]
    #[track_caller]
    pub fn as_rows_mut<'a, S, const C: usize, const R: usize>(x: &'a mut [S], what: &str) -> &'a mut [[S; C]; R] {
        let len = x.len();
        let (rows, rest) = x.as_chunks_mut::<C>();
        match (rest.is_empty(), <&mut [[S; C]; R]>::try_from(rows)) {
            (true, Ok(m)) => m,
            _ => panic!("dyngen: `{what}` has length {len}, expected {} ({R} × {C})", R * C),
        }
    }

    /// Joint `j`'s (0-based) parameters in `joint_params` (`[Ia, Fv, Fc, F0]` per joint);
    /// generated code passes arrays of `4n`.
    #[inline(always)]
    pub fn joint_at<S: crate::Scalar>(joint_params: &[S], j: usize) -> crate::JointParams<S> {
        let p = &joint_params[4 * j..4 * j + 4];
        crate::JointParams::from_array([p[0], p[1], p[2], p[3]])
    }

    /// Mutable variant of [`as_array`].
    #[inline(always)]
    #[track_caller]
    pub fn as_array_mut<'a, S, const N: usize>(x: &'a mut [S], what: &str) -> &'a mut [S; N] {
        let len = x.len();
        match x.try_into() {
            Ok(a) => a,
            Err(_) => panic!("dyngen: `{what}` has length {len}, expected {N}"),
        }
    }
}
