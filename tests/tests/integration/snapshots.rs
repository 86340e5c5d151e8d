//! Snapshots of generated code: planar2 (every function) and paper6 (rnea). They
//! show what the generator emits and how a change alters it; correctness is proven
//! numerically in `generated_vs_reference.rs` and `pinocchio.rs`. The descriptions
//! are read from the robot crates' sources, so there is one copy of each.

use dyngen_codegen::{analyse_model, generate, GeneratedCode, Options};

/// Generates the robot declared by the `robot!` invocation in a robot crate's source.
fn generate_from_crate(dir: &str) -> GeneratedCode {
    let (name, model) = dyngen_tests::robot_crate_model(dir);
    generate(&model, &name, &analyse_model(&model), &Options::default())
}

#[test]
fn planar2_generated_code() {
    let g = generate_from_crate("planar2");
    insta::assert_snapshot!("planar2", g.pretty());
}

#[test]
fn paper6_rnea() {
    let g = generate_from_crate("paper6");
    insta::assert_snapshot!("paper6_rnea", g.pretty_function("rnea").expect("rnea is generated"));
}

#[test]
fn op_counts() {
    let report: String = ["planar2", "paper6"]
        .iter()
        .map(|r| format!("{r}\n{}", generate_from_crate(r).op_report()))
        .collect();
    insta::assert_snapshot!("op_counts", report);
}
