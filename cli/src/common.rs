//! What every subcommand shares: loading a URDF, the gravity option, progress bars.

use crate::error::CliError;
use dyngen_model::{Model, ModelError};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write as _};
use std::path::Path;
use std::time::Duration;

/// A subcommand's result: the error is printed after `error: ` and sets the exit code.
pub type Result<T> = std::result::Result<T, CliError>;

/// How the URDF is read: `--gravity gx gy gz`, `--strict`, `--balance-inertia`,
/// `--free-flyer`.
#[derive(Clone, Debug, clap::Args)]
pub struct ModelArgs {
    /// Gravity in the base frame, m/s², each component within ±1000 (default: the
    /// URDF's model default, 0 0 -9.81).
    #[arg(long, num_args = 3, value_names = ["GX", "GY", "GZ"], allow_negative_numbers = true,
          value_parser = crate::ranges::GRAVITY)]
    pub gravity: Option<Vec<f64>>,
    /// Refuse what is otherwise loaded with a warning: a body whose inertia breaks
    /// positive definiteness or the triangle inequality (kept as written otherwise, as
    /// Pinocchio reads it), a joint along which nothing with mass moves (a singular
    /// mass matrix).
    #[arg(long)]
    pub strict: bool,
    /// Replace each non-physical body inertia by the nearest physical one (same mass,
    /// centre of mass and principal axes; the moments moved least), with a warning
    /// giving the moments before and after.
    #[arg(long, conflicts_with = "strict")]
    pub balance_inertia: bool,
    /// Put the root link on a free flyer (a floating base, as Pinocchio's
    /// `JointModelFreeFlyer` root joint): `q = [p; quaternion x y z w; joints]`,
    /// `v = [v; ω; joints]` in the base frame.
    #[arg(long)]
    pub free_flyer: bool,
}

impl ModelArgs {
    pub fn get(&self) -> Result<Option<[f64; 3]>> {
        match &self.gravity {
            None => Ok(None),
            // Each component was checked by its value parser (`ranges::GRAVITY`).
            Some(g) if g.len() == 3 => Ok(Some([g[0], g[1], g[2]])),
            Some(g) => Err(CliError::usage(format!("--gravity needs three numbers, got {g:?}"))),
        }
    }
}

/// Reads, parses and checks the URDF or MJCF (`.xml`) at `path` (all errors as `file:line: message`),
/// as `args` says (`--strict`, `--balance-inertia`, `--free-flyer`), prints its warnings, then sets the
/// gravity when given.
pub fn load_model(path: &Path, args: &ModelArgs) -> Result<Model> {
    let gravity = args.get()?;
    let options = dyngen_model::LoadOptions {
        strict: args.strict,
        free_flyer: args.free_flyer,
        balance_inertia: args.balance_inertia,
    };
    // The model's errors already read `file:line: message`.
    let mut model = dyngen_model::load_robot_options(path, options).map_err(|e| CliError::Input(e.to_string()))?;
    for w in &model.warnings {
        let at = w.line.map(|l| format!(":{l}")).unwrap_or_default();
        let message = ModelError {
            line: None,
            ..w.clone()
        }
        .warning_message();
        eprintln!("warning: {}{at}: {message}", path.display());
    }
    if let Some(g) = gravity {
        model.gravity = g;
    }
    Ok(model)
}

/// Like [`load_model`], for the commands that run the dynamics at run time
/// (identification, simulation, validation, NIM): refuses a model without moving
/// joints, and one with a free flyer, a ball or a planar joint, which only the
/// generated code handles so far. Joints that follow others (`<mimic>`) are taken:
/// a recording has one joint per velocity coordinate, the leaders' (NIM refuses
/// them, [`refuse_followers`]).
pub fn load_moving_model(path: &Path, args: &ModelArgs) -> Result<Model> {
    let model = load_model(path, args)?;
    if model.dof() == 0 {
        return Err(CliError::input(path, "the robot has no moving joints"));
    }
    if let Some(j) = model.multi_dof_joint() {
        return Err(CliError::input(
            path,
            format!(
                "joint `{}` is a {} joint ({} positions, {} velocities); this command runs on robots whose joints \
                 each have one degree of freedom. Floating bases, ball and planar joints are handled by the \
                 generated code (`dyngen generate`, `build.rs`), including the floating-base regressor for identification",
                j.name,
                j.kind.urdf_name(),
                j.kind.nq(),
                j.kind.nv()
            ),
        ));
    }
    Ok(model)
}

/// Refuses a model with a joint that follows another (`<mimic>`), for NIM, whose
/// body networks take one joint per body.
pub fn refuse_followers(model: &Model, path: &Path) -> Result<()> {
    match model.mimic_joint() {
        Some(j) => Err(CliError::input(
            path,
            format!(
                "joint `{}` follows another (a URDF <mimic> or an MJCF <equality><joint>); NIM runs on robots whose \
                 joints each have a coordinate of their own (identify, simulate and validate take such joints); \
                 remove the coupling to treat the joint as an independent one",
                j.name
            ),
        )),
        None => Ok(()),
    }
}

/// Progress bars on stderr, hidden with `--quiet` or when stdout is not a terminal.
pub struct Progress {
    visible: bool,
}

impl Progress {
    pub fn new(quiet: bool) -> Progress {
        Progress {
            visible: !quiet && std::io::stdout().is_terminal(),
        }
    }

    fn target(&self) -> ProgressDrawTarget {
        if self.visible {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        }
    }

    /// A spinner for work without a known length; finish it with `finish_and_clear`.
    pub fn spinner(&self, message: impl Into<String>) -> ProgressBar {
        let bar = ProgressBar::with_draw_target(None, self.target());
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_message(message.into());
        if self.visible {
            bar.enable_steady_tick(Duration::from_millis(100));
        }
        bar
    }

    /// A bar over `len` steps.
    pub fn bar(&self, len: u64, message: impl Into<String>) -> ProgressBar {
        let bar = ProgressBar::with_draw_target(Some(len), self.target());
        bar.set_style(
            ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.set_message(message.into());
        bar
    }
}

/// Runs `work` under a spinner showing `message`.
pub fn with_spinner<T>(progress: &Progress, message: &str, work: impl FnOnce() -> T) -> T {
    let spinner = progress.spinner(message);
    let out = work();
    spinner.finish_and_clear();
    out
}

/// Refuses to replace an existing file unless `force`.
pub fn check_overwrite(path: &Path, force: bool) -> Result<()> {
    if !force && path.exists() {
        return Err(CliError::OutputExists(path.to_path_buf()));
    }
    Ok(())
}

/// Writes to stdout, checked: a full disk, a closed pipe or a closed stdout is an
/// output error (exit code 5), never a panic (`println!`) or a silent loss. Each
/// call flushes, so that the error belongs to the write that failed.
pub fn write_stdout(args: std::fmt::Arguments<'_>) -> Result<()> {
    if stdout_was_closed() {
        return Err(CliError::Output(
            "cannot write to stdout: it is closed; redirect it to a file (or use -o FILE where the command has it)"
                .into(),
        ));
    }
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.flush())
        .map_err(|e| CliError::Output(format!("cannot write to stdout: {e}")))
}

/// `print!` through [`write_stdout`]; `?` returns its error from the caller.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::common::write_stdout(format_args!($($arg)*))?
    };
}

/// `println!` through [`write_stdout`]; `?` returns its error from the caller.
macro_rules! outln {
    () => {
        $crate::common::write_stdout(format_args!("\n"))?
    };
    ($($arg:tt)*) => {
        $crate::common::write_stdout(format_args!("{}\n", format_args!($($arg)*)))?
    };
}
pub(crate) use {out, outln};

/// Whether file descriptor 1 was closed when the process started (`dyngen … >&-`).
/// Rust's runtime then opens `/dev/null` on it before `main`, and every write would
/// vanish without an error, so the state is recorded before the runtime starts, by
/// a function in `.init_array` ([`CHECK_STDOUT`]).
#[cfg(target_os = "linux")]
fn stdout_was_closed() -> bool {
    STDOUT_CLOSED.load(std::sync::atomic::Ordering::Relaxed)
}

#[cfg(target_os = "linux")]
static STDOUT_CLOSED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Runs before `main`: `/proc/self/fd/1` is missing exactly when fd 1 is not open
/// (when /proc is mounted at all); `lstat` opens nothing, so no descriptor is taken.
#[cfg(target_os = "linux")]
extern "C" fn check_stdout() {
    let fds = Path::new("/proc/self/fd");
    if fds.is_dir() && std::fs::symlink_metadata(fds.join("1")).is_err() {
        STDOUT_CLOSED.store(true, std::sync::atomic::Ordering::Relaxed);
    }
}

#[cfg(target_os = "linux")]
#[used]
#[link_section = ".init_array"]
static CHECK_STDOUT: extern "C" fn() = check_stdout;

#[cfg(not(target_os = "linux"))]
fn stdout_was_closed() -> bool {
    false
}
