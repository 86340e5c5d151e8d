// Generates the `Ur5` type from the URDF at build time.
fn main() -> Result<(), dyngen_codegen::Error> {
    dyngen_codegen::compile_urdf("ur5.urdf", "Ur5")?;
    Ok(())
}
