//! `dyngen`: the command line of dyngen. Every subcommand works on any URDF given at
//! run time, through the reference implementation (`dyngen_reference::Reference`, behind the
//! `dyngen_reference::Dynamics` trait).
//!
//! Errors are printed as `error: …` on stderr; bad input never panics. The exit code
//! says what kind of failure it was:
//!
//! | code | meaning |
//! |---|---|
//! | 0 | success (also `--help`, `--version`) |
//! | 1 | the computation failed (identification, training, an internal error) |
//! | 2 | usage: unknown flag, missing argument, invalid or conflicting option values |
//! | 3 | bad input: a URDF, recording, recipe or weights file that cannot be read or is invalid |
//! | 4 | an output file exists (pass `--force` to replace it) |
//! | 5 | an output file could not be written |

mod common;
mod demo;
mod error;
mod gains;
mod generate;
mod identify;
mod info;
mod nim;
mod partial;
mod ranges;
mod simulate;
mod validate;

use clap::{Parser, Subcommand};
use std::io::Write as _;
use std::process::ExitCode;

const EXAMPLES: &str = "\
Examples:
  dyngen info robots/ur5/ur5.urdf
  dyngen generate robots/ur5/ur5.urdf --name Ur5 -o ur5.rs
  dyngen simulate robots/ur5/ur5.urdf -o ur5.csv --experiment fourier --noise 0.01
  dyngen identify robots/ur5/ur5.urdf ur5.csv --method wls
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction auto --params-json p.json --validate run2.csv
  dyngen validate robots/ur5/ur5.urdf p.json run2.csv --svg run2.svg
  dyngen nim train robots/ur5/ur5.urdf ur5.csv -o ur5-nim.json
  dyngen demo

Run `dyngen <command> --help` for the options of one command.
";

/// Robot dynamics from a URDF: inspect it, generate specialised Rust for it, simulate
/// identification experiments, identify its inertial parameters.
#[derive(Debug, Parser)]
#[command(name = "dyngen", version, after_help = format!("{EXAMPLES}\n{}", error::EXIT_CODES))]
pub struct Cli {
    /// No progress bars (they are also hidden when stdout is not a terminal).
    #[arg(short, long, global = true)]
    pub quiet: bool,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Topology, incidence and path matrices, parameter counts, base parameters and
    /// operation counts of a URDF.
    #[command(after_help = info::EXAMPLES)]
    Info(info::InfoArgs),
    /// Generate the specialised Rust code for a URDF (what `build.rs` does), to a file
    /// or stdout.
    #[command(after_help = generate::EXAMPLES)]
    Generate(generate::GenerateArgs),
    /// Simulate an identification experiment with the URDF's nominal parameters and
    /// write the measurements as CSV.
    #[command(after_help = simulate::EXAMPLES)]
    Simulate(simulate::SimulateArgs),
    /// Identify the inertial parameters from measured data in a CSV file: from joint
    /// torques (standard or principal parameters) or body by body from joint
    /// wrenches (MIM).
    #[command(after_help = identify::EXAMPLES)]
    Identify(identify::IdentifyArgs),
    /// Predict a recording's joint torques with identified parameters (JSON from
    /// `identify --params-json`) and report the errors per joint and overall.
    #[command(after_help = validate::EXAMPLES)]
    Validate(validate::ValidateArgs),
    /// The neural-network identifier (NIM): train it for a robot and a joint motion,
    /// or identify with it.
    #[command(after_help = nim::EXAMPLES)]
    Nim(nim::NimArgs),
    /// The paper's experiment on its 6-DOF manipulator end to end: MIM (Tables 2–3,
    /// noise study), NIM as the paper describes it (Tables 4–5, Fig. 5), the
    /// generalising NIM, all three side by side on unseen parameters, and a payload
    /// followed online by NIM and recursive least squares.
    #[command(after_help = demo::EXAMPLES)]
    Demo(demo::DemoArgs),
}

fn main() -> ExitCode {
    install_panic_hook();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // `--help` and `--version` are not errors; usage errors exit with 2.
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let progress = common::Progress::new(cli.quiet);
    let result = match &cli.command {
        Command::Info(args) => info::run(args, &progress),
        Command::Generate(args) => generate::run(args, &progress),
        Command::Simulate(args) => simulate::run(args, &progress),
        Command::Identify(args) => identify::run(args, &progress),
        Command::Validate(args) => validate::run(args, &progress),
        Command::Nim(args) => nim::run(args, &progress),
        Command::Demo(args) => demo::run(args, &progress),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Not `eprintln!`: a stderr that cannot be written must not turn the
            // error into a panic; the exit code still says what happened.
            let _ = writeln!(std::io::stderr(), "error: {e}");
            e.into()
        }
    }
}

/// A last resort: a panic is a bug of dyngen, never of the input, but it should
/// still read like the other errors and exit with 1 (the computation failed).
fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".to_string());
        let location = info.location().map(|l| format!(" at {l}")).unwrap_or_default();
        let _ = writeln!(
            std::io::stderr(),
            "error: internal error{location}: {message} (this is a bug of dyngen; please report it)"
        );
        std::process::exit(1);
    }));
}
