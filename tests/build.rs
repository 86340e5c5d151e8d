// Two more UR5s through the `Config` builder, checked against `robot_ur5::Ur5`: one
// with a statement budget small enough that every generated function is split into
// parts (`tests/split_functions.rs`), one with every composable function composed of
// the others, as large trees have them (`tests/composed_functions.rs`). And a robot
// with joints that follow others (`<mimic>`, `tests/census.rs`): the mimic probe tree
// on a free flyer.
fn main() -> Result<(), dyngen_codegen::Error> {
    dyngen_codegen::Config::new()
        .file_name("ur5_split.rs")
        .max_statements(40)
        .compile_urdf("../robots/ur5/ur5.urdf", "Ur5Split")?;
    dyngen_codegen::Config::new()
        .file_name("ur5_composed.rs")
        .compose_above(0)
        .compile_urdf("../robots/ur5/ur5.urdf", "Ur5Composed")?;
    dyngen_codegen::Config::new()
        .file_name("mimic_probe_free_flyer.rs")
        .free_flyer(true)
        .compile_urdf("fixtures/mimic/mimic_probe.urdf", "MimicProbeFloating")?;
    Ok(())
}
