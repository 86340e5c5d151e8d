//! Snapshots of generated code: planar2 (every function) and paper6 (rnea). They
//! show what the generator emits and how a change alters it; correctness is proven
//! numerically in `generated_vs_reference.rs` and `pinocchio.rs`. The descriptions
//! are read from the robot crates' sources, so there is one copy of each.

use dyngen_codegen::{generate, Generated, Options};

/// Generates the robot declared by the `robot!` invocation in a robot crate's source.
fn generate_from_crate(dir: &str) -> Generated {
    let path = dyngen_tests::workspace_root()
        .join("robots")
        .join(dir)
        .join("src/lib.rs");
    let source = std::fs::read_to_string(&path).expect("robot crate source");
    let file = syn::parse_file(&source).expect("robot crate parses");
    let tokens = file
        .items
        .iter()
        .find_map(|item| match item {
            syn::Item::Macro(m) if m.mac.path.segments.last().is_some_and(|s| s.ident == "robot") => {
                Some(m.mac.tokens.clone())
            }
            _ => None,
        })
        .expect("a robot! invocation");
    let input = dyngen_codegen::dsl::parse(tokens).expect("description parses");
    let desc = match input.source {
        dyngen_codegen::RobotSource::Dsl(d) => d,
        dyngen_codegen::RobotSource::Urdf(_) => panic!("expected an inline description"),
    };
    let model = desc.build().expect("description is valid");
    generate(&model, &input.name.to_string(), &Options::default())
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
