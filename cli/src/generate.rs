//! `dyngen generate`: what `build.rs` (`dyngen_codegen::Config::compile_urdf`) does,
//! to a file or stdout, through the same `Config`.

use crate::common::{check_overwrite, load_model, out, with_spinner, ModelArgs, Progress, Result};
use crate::error::CliError;
use dyngen_codegen::{Config, Selection};
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  dyngen generate robots/ur5/ur5.urdf --name Ur5 -o src/ur5.rs
  dyngen generate arm.urdf --name Arm --max-statements 800 > arm.rs
  dyngen generate arm.urdf --name Arm -o arm.rs --force   # replace arm.rs
  dyngen generate arm.urdf --name Arm -o arm.rs --functions rnea,crba,aba,frame_jacobian

Use the file with `include!(\"arm.rs\");` in a crate that depends on `dyngen`.";

#[derive(Debug, clap::Args)]
pub struct GenerateArgs {
    /// The robot description (URDF, or MJCF as `.xml`).
    pub urdf: PathBuf,

    /// Name of the generated type (a Rust identifier such as `Ur5`).
    #[arg(long, short)]
    pub name: String,

    /// Output file (default: stdout). An existing file is kept unless --force.
    #[arg(long, short)]
    pub output: Option<PathBuf>,

    /// Replace the output file if it exists.
    #[arg(long)]
    pub force: bool,

    /// Statements per generated function before it is split into parts, 100 to
    /// 10000000 (default 6000; the regressors and derivatives are split at no more
    /// than 1200 and 800).
    #[arg(long, value_name = "N", value_parser = crate::ranges::MAX_STATEMENTS)]
    pub max_statements: Option<usize>,

    /// Compose functions whose own code would repeat another's (aba_derivatives,
    /// frame_motion, the base regressors, ...) when the robot has more than N velocity
    /// coordinates (default 24): faster builds, slower functions.
    #[arg(long, value_name = "N")]
    pub compose_above: Option<usize>,

    /// Generate only these functions, comma-separated, by function name (rnea,
    /// crba, aba, frame_jacobian, …) or group (inverse_dynamics, mass_matrix,
    /// forward_dynamics, kinematics, regressors, joint_dynamics, frames, centroidal,
    /// derivatives); each brings its whole group, the type implements that group's
    /// trait of `dyngen`. Default: all.
    #[arg(long, value_name = "LIST", value_parser = parse_functions)]
    pub functions: Option<Selection>,

    #[command(flatten)]
    pub gravity: ModelArgs,
}

fn parse_functions(list: &str) -> std::result::Result<Selection, String> {
    Selection::parse(list).map_err(|e| e.to_string())
}

pub fn run(args: &GenerateArgs, progress: &Progress) -> Result<()> {
    if let Some(out) = &args.output {
        check_overwrite(out, args.force)?;
    }
    let model = load_model(&args.urdf, &args.gravity)?;
    let mut config = Config::new();
    if let Some(g) = args.gravity.get()? {
        config.gravity(g);
    }
    if let Some(n) = args.max_statements {
        config.max_statements(n);
    }
    if let Some(n) = args.compose_above {
        config.compose_above(n);
    }
    if let Some(functions) = args.functions {
        config.functions(functions);
    }
    let source = args
        .urdf
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let content = with_spinner(progress, &format!("generating `{}`", args.name), || {
        config.generate_file(&model, &args.name, &source)
    })
    .map_err(|e| match e {
        dyngen_codegen::Error::TypeName(_) => CliError::usage(e.to_string()),
        e => CliError::failed(e),
    })?;
    match &args.output {
        None => out!("{content}"),
        Some(path) => {
            std::fs::write(path, &content).map_err(|e| CliError::output(path, e))?;
            eprintln!(
                "wrote `{}` ({} joints, {} lines) to {}",
                args.name,
                model.dof(),
                content.lines().count(),
                path.display()
            );
        }
    }
    Ok(())
}
