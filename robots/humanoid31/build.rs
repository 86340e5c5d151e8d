// Generates the `Humanoid31` type from the URDF at build time, its root link on a free flyer.
fn main() -> Result<(), dyngen_codegen::Error> {
    dyngen_codegen::Config::new()
        .free_flyer(true)
        .compile_urdf("humanoid31.urdf", "Humanoid31")?;
    Ok(())
}
