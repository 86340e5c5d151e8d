//! # dyngen
//!
//! Specialised, unrolled, allocation-free rigid-body dynamics for one robot.
//!
//! A robot comes from the [`robot!`] macro (inline graph-theoretic description, or a
//! URDF file) or from `dyngen_codegen::compile_urdf` in `build.rs`; either way it is
//! a type implementing [`Robot`], with generated functions that agree with the
//! readable [`reference`] implementation (and with Pinocchio) to 1e-10.

pub mod reference;
mod robot;
mod scalar;

pub use dyngen_macros::robot;
pub use dyngen_model as model;
pub use nalgebra;
pub use robot::{Pose, Robot, Wrench};
pub use scalar::Scalar;
