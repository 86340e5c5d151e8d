// Generates the `Panda` type from the URDF at build time.
fn main() -> Result<(), dyngen_codegen::Error> {
    dyngen_codegen::compile_urdf("panda.urdf", "Panda")?;
    Ok(())
}
