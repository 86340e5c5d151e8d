//! # dyngen
//!
//! Specialised, unrolled, allocation-free rigid-body dynamics for one robot.
//!
//! A robot comes from the [`robot!`] macro (inline graph-theoretic description, or a
//! URDF file) or from `dyngen_codegen::compile_urdf` in `build.rs`; either way it is
//! a type implementing [`Robot`], with generated functions that agree with the
//! readable [`reference`](mod@reference) implementation (and with Pinocchio) to 1e-10.

pub mod data;
pub mod dynamics;
pub mod identify;
pub mod mim;
pub mod nim;
pub mod reference;
pub mod report;
mod robot;
mod robot_model;
mod scalar;
pub mod simulate;

pub use dyngen_macros::robot;
pub use dyngen_model as model;
pub use nalgebra;
pub use reference::Reference;
pub use robot::{BodyRegressor, OpCount, Pose, Robot, Wrench};
pub use robot_model::{BodyModel, JointLimits, JointModel, JointType, RobotModel};
pub use scalar::Scalar;

/// Support for generated code; not a public API.
#[doc(hidden)]
pub mod __private {
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
