//! `dyngen simulate`: an identification experiment on the nominal parameters, as CSV.

use crate::common::{check_overwrite, load_moving_model, with_spinner, GravityArg, Progress, Result};
use crate::error::CliError;
use dyngen_identify::data::{overwrite_csv, write_csv, DataError};
use dyngen_identify::simulate::{record, Criterion, ExcitationDesign, Experiment, Motion, NoiseModel};
use dyngen_reference::Reference;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  dyngen simulate robots/ur5/ur5.urdf -o paper.csv                 # the paper's 2 s, 100 steps
  dyngen simulate robots/ur5/ur5.urdf -o ur5.csv --experiment fourier --noise 0.01 --seed 3
  dyngen simulate arm.urdf -o arm.csv --experiment fourier --duration 20 --steps 2000 --force
  dyngen simulate arm.urdf -o mim.csv --experiment fourier --criterion body-model --base-frequency 0.5

The CSV has the columns t, q1..qn, v1..vn, a1..an, tau1..taun and the joint wrenches
fx1, fy1, fz1, mx1, my1, mz1, … (SI units; see the dyngen_identify::data module docs).";

/// Which motion drives the joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ExperimentKind {
    /// The paper's experiment: from rest, each joint on a raised-cosine profile
    /// within its limits (default 2 s in 100 steps).
    Paper,
    /// A finite Fourier series per joint (Swevers et al. 1997), coefficients
    /// optimised (--criterion) within the joint position and velocity limits
    /// (default one 10 s period in 100 steps).
    Fourier,
}

/// What the Fourier coefficients are optimised for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CriterionArg {
    /// The condition number of the stacked base torque regressor: for
    /// `identify --mode standard|principal` (joint torques).
    Torques,
    /// The worst relative σ of a principal moment from each body's motion and
    /// resultant: for `identify --mode mim` and `dyngen nim`.
    BodyModel,
}

#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    /// The robot description (URDF); its inertials are the nominal parameters.
    pub urdf: PathBuf,

    /// Output CSV file. An existing file is kept unless --force.
    #[arg(long, short)]
    pub output: PathBuf,

    /// Replace the output file if it exists.
    #[arg(long)]
    pub force: bool,

    /// The motion.
    #[arg(long, value_enum, default_value_t = ExperimentKind::Paper)]
    pub experiment: ExperimentKind,

    /// Length of the experiment, s (default: 2 for paper, one Fourier period for
    /// fourier).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// Sampling steps; the file has steps + 1 samples, t = 0 included.
    #[arg(long, default_value_t = 100)]
    pub steps: usize,

    /// Relative Gaussian noise on every recorded channel (0.01 = 1 % of each
    /// channel's RMS); 0 for exact data.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub noise: f64,

    /// Seed of the noise and of the excitation optimisation.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,

    /// Fourier: what the coefficients are optimised for.
    #[arg(long, value_enum, default_value_t = CriterionArg::Torques)]
    pub criterion: CriterionArg,

    /// Fourier: harmonics per joint.
    #[arg(long, default_value_t = 5)]
    pub harmonics: usize,

    /// Fourier: base frequency, Hz (the trajectory repeats every 1/f s).
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    pub base_frequency: f64,

    /// Fourier: objective evaluations allowed to the optimiser (each one evaluates
    /// the regressor at every sample; the default takes seconds in a release build,
    /// minutes in a debug one). Too few for one Nelder–Mead run (0, say) keep the
    /// random feasible start.
    #[arg(long, default_value_t = 3000)]
    pub evaluations: usize,

    #[command(flatten)]
    pub gravity: GravityArg,
}

fn check_args(args: &SimulateArgs) -> Result<()> {
    if let Some(d) = args.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(CliError::usage(format!(
                "--duration must be a positive number of seconds, got {d}"
            )));
        }
    }
    if args.steps < 1 {
        return Err(CliError::usage("--steps must be at least 1"));
    }
    if !(args.noise.is_finite() && args.noise >= 0.0) {
        return Err(CliError::usage(format!(
            "--noise must be a non-negative fraction (0.01 = 1 %), got {}",
            args.noise
        )));
    }
    if args.experiment == ExperimentKind::Fourier {
        if args.harmonics < 1 {
            return Err(CliError::usage("--harmonics must be at least 1"));
        }
        if !(args.base_frequency.is_finite() && args.base_frequency > 0.0) {
            return Err(CliError::usage(format!(
                "--base-frequency must be positive, got {}",
                args.base_frequency
            )));
        }
    }
    Ok(())
}

pub fn run(args: &SimulateArgs, progress: &Progress) -> Result<()> {
    check_args(args)?;
    check_overwrite(&args.output, args.force)?;
    let model = load_moving_model(&args.urdf, args.gravity.get()?)?;
    let robot = Reference::new(&model);
    let params = model.standard_params();

    let experiment = match args.experiment {
        ExperimentKind::Paper => {
            let mut e = Experiment::paper(&model);
            e.duration = args.duration.unwrap_or(e.duration);
            e.steps = args.steps;
            e
        }
        ExperimentKind::Fourier => {
            let mut design = ExcitationDesign::new(&model);
            design.criterion = match args.criterion {
                CriterionArg::Torques => Criterion::JointTorques,
                CriterionArg::BodyModel => Criterion::BodyModel,
            };
            design.harmonics = args.harmonics;
            design.base_frequency = args.base_frequency;
            design.duration = args.duration.unwrap_or(1.0 / args.base_frequency);
            design.samples = args.steps;
            design.max_evaluations = args.evaluations;
            design.seed = args.seed;
            let found = with_spinner(progress, "optimising the Fourier excitation", || {
                design.optimise(&robot)
            });
            match found.criterion {
                Criterion::JointTorques => eprintln!(
                    "excitation: condition number of the base regressor {:.4e} (start {:.4e}, {} evaluations, {} base \
                     columns)",
                    found.value,
                    found.initial_value,
                    found.evaluations,
                    found.base_columns.len()
                ),
                Criterion::BodyModel => eprintln!(
                    "excitation: worst relative σ of a principal moment {:.3} % at 1 % noise (start {:.3} %, {} \
                     evaluations)",
                    found.value, found.initial_value, found.evaluations
                ),
            }
            Experiment {
                duration: design.duration,
                steps: args.steps,
                motion: Motion::Fourier(found.excitation),
            }
        }
    };

    let clean = with_spinner(progress, "recording the experiment", || {
        record(&robot, &params, &experiment)
    });
    let recording = if args.noise > 0.0 {
        NoiseModel::relative(args.noise).apply(&clean, args.seed)
    } else {
        clean
    };
    let traj = recording.to_trajectory().map_err(CliError::failed)?;
    if args.force {
        overwrite_csv(&args.output, &traj)
    } else {
        write_csv(&args.output, &traj)
    }
    .map_err(|e| match e {
        DataError::FileExists { path } => CliError::OutputExists(path),
        e => CliError::Output(e.to_string()),
    })?;
    eprintln!(
        "wrote {} samples of {} joints ({} s, noise {}) to {}",
        traj.len(),
        traj.dof(),
        experiment.duration,
        args.noise,
        args.output.display()
    );
    Ok(())
}
