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

  dyngen generate robots/ur5/ur5.urdf --name Ur5 --python ur5-python && pip install ./ur5-python

Use the file with `include!(\"arm.rs\");` in a crate that depends on `dyngen`. With
--python the folder is a Python package (the module `ur5`: rnea, crba, aba, ... on
numpy arrays, a batch on SIMD lanes and threads) that `pip install` builds.";

#[derive(Debug, clap::Args)]
pub struct GenerateArgs {
    /// The robot description (URDF, or MJCF as `.xml`).
    pub urdf: PathBuf,

    /// Name of the generated type (a Rust identifier such as `Ur5`).
    #[arg(long, short)]
    pub name: String,

    /// Output file (default: stdout). An existing file is kept unless --force.
    #[arg(long, short, conflicts_with = "python")]
    pub output: Option<PathBuf>,

    /// Write a Python package to this folder instead: the generated code and a
    /// module of the same name in snake case (`Ur5` → `ur5`) with the batched
    /// kernels on numpy arrays; `pip install DIR` builds it (Rust toolchain needed).
    /// An existing non-empty folder is kept unless --force.
    #[arg(long, value_name = "DIR")]
    pub python: Option<PathBuf>,

    /// With --python: the `dyngen` crate the package builds against (the `core`
    /// folder of a dyngen checkout; default: the one this program was built from).
    #[arg(long, value_name = "PATH", requires = "python")]
    pub dyngen_path: Option<PathBuf>,

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
    /// trait of `dyngen`. Default: all (and always all with --python, whose module
    /// exposes inverse and forward dynamics, the mass matrix, regressors, frames and
    /// centroidal dynamics).
    #[arg(long, value_name = "LIST", value_parser = parse_functions, conflicts_with = "python")]
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
    let python = match &args.python {
        Some(dir) => Some(python_package(dir, args)?),
        None => None,
    };
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
    if let Some(package) = python {
        return package.write(&content, &args.name, &model.name, model.dof());
    }
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

/// A Python package to write (`--python`): its folder, module name and the `dyngen`
/// crate it builds against, checked before anything is generated.
struct PythonPackage {
    dir: PathBuf,
    module: String,
    dyngen: PathBuf,
}

/// The templates of the package; `@MODULE@`, `@ROBOT@`, `@TYPE@` and `@DYNGEN@` are
/// replaced.
const PYTHON_LIB: &str = include_str!("../templates/python/lib.rs");
const PYTHON_CARGO: &str = include_str!("../templates/python/Cargo.toml");
const PYTHON_PYPROJECT: &str = include_str!("../templates/python/pyproject.toml");

/// `Ur5Arm` → `ur5_arm`: the module name of a type name (a Rust identifier, so an
/// ASCII letter or `_` first, then letters, digits and `_`).
pub fn snake_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let mut previous_lower = false;
    for c in name.chars() {
        if c.is_ascii_uppercase() {
            if previous_lower {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
            previous_lower = false;
        } else {
            out.push(c);
            previous_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
        }
    }
    out
}

fn python_package(dir: &std::path::Path, args: &GenerateArgs) -> Result<PythonPackage> {
    let module = snake_case(&args.name);
    let valid = module
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && module.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !valid {
        return Err(CliError::usage(format!(
            "--python: the module name `{module}` (from --name `{}`) is not a Python identifier; \
             give --name as ASCII letters, digits and `_`, starting with a letter",
            args.name
        )));
    }
    let non_empty = std::fs::read_dir(dir).is_ok_and(|mut entries| entries.next().is_some());
    if non_empty && !args.force {
        return Err(CliError::usage(format!(
            "--python: `{}` exists and is not empty; choose a new folder, or pass --force to write over its files",
            dir.display()
        )));
    }
    if dir.exists() && !dir.is_dir() {
        return Err(CliError::usage(format!(
            "--python: `{}` is a file, not a folder",
            dir.display()
        )));
    }
    let dyngen = match &args.dyngen_path {
        Some(path) => path.clone(),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("core"),
    };
    let manifest = std::fs::read_to_string(dyngen.join("Cargo.toml")).unwrap_or_default();
    if !manifest.lines().any(|l| l.trim() == "name = \"dyngen\"") {
        return Err(CliError::usage(format!(
            "--dyngen-path: `{}` is not the `dyngen` crate (the `core` folder of a dyngen checkout, with its Cargo.toml)",
            dyngen.display()
        )));
    }
    let dyngen = dyngen.canonicalize().map_err(|e| CliError::input(&dyngen, e))?;
    Ok(PythonPackage {
        dir: dir.to_path_buf(),
        module,
        dyngen,
    })
}

impl PythonPackage {
    fn write(&self, code: &str, type_name: &str, robot: &str, dof: usize) -> Result<()> {
        let fill = |template: &str| {
            template
                .replace("@MODULE@", &self.module)
                .replace("@TYPE@", type_name)
                .replace("@ROBOT@", robot)
                .replace("@DYNGEN@", &self.dyngen.display().to_string().replace('\\', "/"))
        };
        let src = self.dir.join("src");
        std::fs::create_dir_all(&src).map_err(|e| CliError::output(&src, e))?;
        for (path, text) in [
            (src.join("robot.rs"), code.to_string()),
            (src.join("lib.rs"), fill(PYTHON_LIB)),
            (self.dir.join("Cargo.toml"), fill(PYTHON_CARGO)),
            (self.dir.join("pyproject.toml"), fill(PYTHON_PYPROJECT)),
        ] {
            std::fs::write(&path, text).map_err(|e| CliError::output(&path, e))?;
        }
        eprintln!(
            "wrote the Python package of `{type_name}` ({dof} joints; module `{}`) to {}; build it with `pip install {}`",
            self.module,
            self.dir.display(),
            self.dir.display()
        );
        Ok(())
    }
}
