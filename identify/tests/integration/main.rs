//! Integration tests of the identification crate.
//!
//! One test binary: it links once, and its tests share the cores.

mod common;

mod data;
mod extras;
mod identify;
mod joint_friction;
mod mujoco;
mod payload;
mod report;
mod simulate;
mod stribeck;
