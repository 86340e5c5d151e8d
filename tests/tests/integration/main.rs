//! The workspace's integration tests: generated robots against the reference, Pinocchio and MuJoCo; identities; identification; fuzzing.
//!
//! One test binary: it links once, and its tests share the cores.

mod batch;
mod census;
mod census_mjcf;
mod composed_functions;
mod control;
mod corpus;
mod floating;
mod fuzz;
mod generated_vs_reference;
mod identities;
mod joints;
mod mim;
mod nim;
mod pinocchio;
mod random_trees;
mod robot_model;
mod selected_functions;
mod sibling_order;
mod snapshots;
mod split_functions;
