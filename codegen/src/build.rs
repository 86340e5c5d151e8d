//! The `build.rs` front door: read a URDF, generate, write to `OUT_DIR` only when the
//! content changed, and tell Cargo what to watch. Errors print as `file:line: message`.

use crate::generate::{self, Options};
use dyngen_model::{Model, ModelErrors};
use std::fmt;
use std::path::{Path, PathBuf};

/// Why generation from a file failed.
pub enum Error {
    /// The description has errors; each prints as `file:line: message`.
    Model(ModelErrors),
    /// The type name is not a Rust identifier.
    TypeName(String),
    /// Neither an output directory was set nor `OUT_DIR` (not running in `build.rs`).
    NoOutDir,
    /// The model holds what generated code does not support ([`crate::unsupported`]).
    Unsupported(String),
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Model(e) => write!(f, "{e}"),
            Error::TypeName(n) => write!(
                f,
                "`{n}` is not a valid Rust type name; use an identifier such as `Ur5`"
            ),
            Error::NoOutDir => write!(f, "OUT_DIR is not set: call this from build.rs, or set Config::out_dir"),
            Error::Unsupported(why) => write!(f, "{why}"),
            Error::Io { path, error } => write!(f, "{}: {error}", path.display()),
        }
    }
}

// `build.rs` mains that return `Result` print errors with `Debug`: make that readable.
impl fmt::Debug for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl std::error::Error for Error {}

/// Generator configuration for `build.rs`, prost-build style: one method per option,
/// then [`Config::compile_urdf`].
///
/// ```no_run
/// // build.rs
/// fn main() -> Result<(), dyngen_codegen::Error> {
///     dyngen_codegen::Config::new().max_statements(800).compile_urdf("ur5.urdf", "Ur5")?;
///     Ok(())
/// }
/// ```
/// and in the crate: `include!(concat!(env!("OUT_DIR"), "/ur5.rs"));`
#[derive(Clone, Debug, Default)]
pub struct Config {
    out_dir: Option<PathBuf>,
    file_name: Option<String>,
    gravity: Option<[f64; 3]>,
    load: dyngen_model::LoadOptions,
    options: Options,
}

impl Config {
    pub fn new() -> Config {
        Config::default()
    }

    /// Where to write; defaults to `OUT_DIR`.
    pub fn out_dir(&mut self, dir: impl Into<PathBuf>) -> &mut Config {
        self.out_dir = Some(dir.into());
        self
    }

    /// The output file name; defaults to the URDF's file stem with `.rs`.
    pub fn file_name(&mut self, name: impl Into<String>) -> &mut Config {
        self.file_name = Some(name.into());
        self
    }

    /// Gravity in the base frame, m/s²; defaults to `[0, 0, -9.81]`.
    pub fn gravity(&mut self, gravity: [f64; 3]) -> &mut Config {
        self.gravity = Some(gravity);
        self
    }

    /// Refuse what is otherwise accepted with a `cargo:warning`: body inertias that
    /// break positive definiteness or the triangle inequality (within the tolerance
    /// for CAD rounding, [`INERTIA_TOLERANCE`](dyngen_model::INERTIA_TOLERANCE), or
    /// beyond it), a joint along which nothing with mass moves (a singular mass
    /// matrix). By default they are accepted as written, as Pinocchio reads them.
    pub fn strict(&mut self, strict: bool) -> &mut Config {
        self.load.strict = strict;
        self
    }

    /// Replace every non-physical body inertia by the nearest physical one (MuJoCo's
    /// `balanceinertia`; each printed as a `cargo:warning` with the moments before
    /// and after) instead of keeping it as written.
    pub fn balance_inertia(&mut self, balance: bool) -> &mut Config {
        self.load.balance_inertia = balance;
        self
    }

    /// Put the description's root link on a free flyer: a floating base, as
    /// Pinocchio's `buildModel(urdf, JointModelFreeFlyer())` (joint 1 `root_joint`,
    /// `q = [p; x, y, z, w; joints]`, `v = [v; ω; joints]` in the base frame).
    pub fn free_flyer(&mut self, free_flyer: bool) -> &mut Config {
        self.load.free_flyer = free_flyer;
        self
    }

    /// Statements per generated function before it is split into parts (default
    /// 6,000; the regressors and the derivatives are split at no more than 1,200 and
    /// 800).
    pub fn max_statements(&mut self, n: usize) -> &mut Config {
        self.options.max_statements = n.max(1);
        self
    }

    /// Above this many velocity coordinates (default
    /// [`DEFAULT_COMPOSE_ABOVE_NV`](crate::DEFAULT_COMPOSE_ABOVE_NV), 24), functions whose
    /// own graph would repeat another one's code are composed of the others instead:
    /// `aba_joints`, `nonlinear_effects`, the base regressors, `aba_derivatives`,
    /// `aba_joints_derivatives`, `frame_placement` and `frame_motion`. Composition
    /// builds faster and runs slower: on the 31-joint floating humanoid the crate with
    /// every function rebuilt in 28–30 s instead of about 45 s (one host; timings in
    /// `docs/benchmarks.md`), and `aba_derivatives` takes 24.9 µs instead of 22.2 µs.
    /// `usize::MAX` never composes.
    pub fn compose_above(&mut self, nv: usize) -> &mut Config {
        self.options.compose_above_nv = nv;
        self
    }

    /// The functions to generate, by capability trait (default all): e.g.
    /// `Selection::parse("rnea,crba,aba,frame_jacobian")` generates
    /// `dyngen::InverseDynamics`, `MassMatrix`, `ForwardDynamics` and `Frames` (with
    /// `Centroidal`, generated together), and nothing else: a controller that needs a
    /// few functions does not compile the regressors and derivatives. What the selected
    /// functions are built from comes with them ([`Selection::closure`](crate::Selection::closure)). The type then
    /// implements `dyngen::RobotDescription` and the generated traits, not `dyngen::Robot`
    /// (which needs all of them).
    pub fn functions(&mut self, functions: crate::Selection) -> &mut Config {
        self.options.functions = functions;
        self
    }

    /// Generates type `type_name` from the URDF at `urdf` (relative paths are taken
    /// from `CARGO_MANIFEST_DIR` when set) and writes it; returns the file written.
    pub fn compile_urdf(&self, urdf: impl AsRef<Path>, type_name: &str) -> Result<PathBuf, Error> {
        let urdf = resolve(urdf.as_ref());
        println!("cargo:rerun-if-changed={}", urdf.display());
        if !generate::is_type_name(type_name) {
            return Err(Error::TypeName(type_name.to_string()));
        }
        let model = dyngen_model::load_robot_options(&urdf, self.load).map_err(Error::Model)?;
        for w in &model.warnings {
            println!("cargo:warning={}: {}", urdf.display(), w.warning_message());
        }
        let source = urdf
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let content = self.generate_file(&model, type_name, &source)?;
        let out_dir = match &self.out_dir {
            Some(d) => d.clone(),
            None => std::env::var_os("OUT_DIR").map(PathBuf::from).ok_or(Error::NoOutDir)?,
        };
        let file_name = match &self.file_name {
            Some(n) => n.clone(),
            None => format!("{}.rs", urdf.file_stem().and_then(|s| s.to_str()).unwrap_or(type_name)),
        };
        let path = out_dir.join(file_name);
        write_if_changed(&path, &content)?;
        Ok(path)
    }

    /// The file [`Config::compile_urdf`] writes, for a model already loaded (`source`
    /// names it in the header), with this configuration's gravity and options; for
    /// tools that write elsewhere than `OUT_DIR`, such as the `dyngen` command.
    pub fn generate_file(&self, model: &Model, type_name: &str, source: &str) -> Result<String, Error> {
        if !generate::is_type_name(type_name) {
            return Err(Error::TypeName(type_name.to_string()));
        }
        if let Some(why) = crate::unsupported(model) {
            return Err(Error::Unsupported(why));
        }
        let mut model = model.clone();
        if let Some(g) = self.gravity {
            model.gravity = g;
        }
        let bases = crate::base::analyse_model(&model);
        Ok(generate::generate(&model, type_name, &bases, &self.options).file(source))
    }
}

/// The one-call shortcut: `Config::new().compile_urdf(urdf, type_name)`.
pub fn compile_urdf(urdf: impl AsRef<Path>, type_name: &str) -> Result<PathBuf, Error> {
    Config::new().compile_urdf(urdf, type_name)
}

fn resolve(path: &Path) -> PathBuf {
    match std::env::var_os("CARGO_MANIFEST_DIR") {
        Some(dir) if path.is_relative() => PathBuf::from(dir).join(path),
        _ => path.to_path_buf(),
    }
}

/// Writes only when the content differs, so Cargo does not rebuild needlessly.
pub fn write_if_changed(path: &Path, content: &str) -> Result<(), Error> {
    if std::fs::read_to_string(path).is_ok_and(|old| old == content) {
        return Ok(());
    }
    std::fs::write(path, content).map_err(|error| Error::Io {
        path: path.to_path_buf(),
        error,
    })
}
