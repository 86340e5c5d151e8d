// A second UR5 through the `Config` builder, with a statement budget small enough
// that every generated function is split into parts: the split code is checked
// against the unsplit `robot_ur5::Ur5` in `tests/split_functions.rs`.
fn main() -> Result<(), dyngen_codegen::Error> {
    dyngen_codegen::Config::new()
        .file_name("ur5_split.rs")
        .max_statements(40)
        .compile_urdf("../robots/ur5/ur5.urdf", "Ur5Split")?;
    Ok(())
}
