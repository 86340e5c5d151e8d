//! Integration tests of the model layer: URDF and MJCF loading, validation, base parameters.
//!
//! One test binary: it links once, and its tests share the cores.

#[macro_use]
mod common;

mod base;
mod graph;
mod hostile;
mod mjcf;
mod mjcf_mesh;
mod urdf;
