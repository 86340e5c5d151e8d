//! Writes the URDF of each DSL-declared robot to `tests/fixtures/<name>.urdf`, the
//! input of `scripts/make_fixtures.py` for their Pinocchio fixtures.

use robot_paper6::Paper6;
use robot_planar2::Planar2;

fn main() -> std::io::Result<()> {
    let dir = dyngen_tests::workspace_root().join("tests/fixtures");
    for (name, urdf) in [
        ("planar2", dyngen_reference::urdf_of::<Planar2>()),
        ("paper6", dyngen_reference::urdf_of::<Paper6>()),
    ] {
        let path = dir.join(format!("{name}.urdf"));
        std::fs::write(&path, urdf)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
