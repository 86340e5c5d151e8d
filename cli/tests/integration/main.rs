//! Integration tests of the `dyngen` command: each runs the built binary.
//!
//! One test binary: it links once, and its tests share the cores.

mod common;

mod cli;
mod drive_gains;
mod exit_codes;
mod extra_terms;
mod hostile;
mod identify_outputs;
mod joint_terms;
mod logs;
mod nim;
mod partial;
mod preprocessing;
mod residual;
mod robust;
mod validate;
