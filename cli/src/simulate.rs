//! `dyngen simulate`: an identification experiment on the nominal parameters, as CSV.

use crate::common::{check_overwrite, load_moving_model, with_spinner, ModelArgs, Progress, Result};
use crate::error::CliError;
use crate::ranges::per_joint;
use dyngen_identify::data::{overwrite_csv, write_csv, DataError};
use dyngen_identify::extras::ExtraTerms;
use dyngen_identify::simulate::{
    add_extra_terms, add_joint_terms, add_stribeck_terms, record, record_trajectory, regressor_condition, Criterion,
    ExcitationDesign, Experiment, Logger, Motion, NoiseModel,
};
use dyngen_identify::stribeck::Stribeck;
use dyngen_model::joint_params::Coulomb;
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
    /// optimised (--criterion) within the joint position, velocity and acceleration
    /// limits (default one 10 s period in 100 steps).
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
    /// The robot description (URDF, or MJCF as `.xml`); its inertials are the nominal parameters.
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

    /// Length of the experiment, s, 0 < s ≤ 1e6 (default: 2 for paper, one Fourier
    /// period for fourier).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::ranges::DURATION)]
    pub duration: Option<f64>,

    /// Sampling steps, 1 to 1000000; the file has steps + 1 samples, t = 0 included.
    #[arg(long, default_value_t = 100, value_parser = crate::ranges::STEPS)]
    pub steps: usize,

    /// Relative Gaussian noise on every recorded channel (0.01 = 1 % of each
    /// channel's RMS), 0 to 1; 0 for exact data.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = crate::ranges::NOISE)]
    pub noise: f64,

    /// Seed of the noise and of the excitation optimisation.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,

    /// Rotor inertia Ia per joint (kg·m² or kg), one value for all joints or one per
    /// joint: τ += Ia·q̈.
    #[arg(long, value_name = "IA", allow_hyphen_values = true)]
    pub armature: Option<String>,

    /// Viscous friction Fv per joint (default: the URDF's `<dynamics damping>`): τ += Fv·q̇.
    #[arg(long, value_name = "FV", allow_hyphen_values = true)]
    pub damping: Option<String>,

    /// Coulomb friction Fc per joint (default: the URDF's `<dynamics friction>`):
    /// τ += Fc·sign(q̇).
    #[arg(long, value_name = "FC", allow_hyphen_values = true)]
    pub coulomb: Option<String>,

    /// Static friction Fs per joint, with --stribeck-velocity: the Coulomb term
    /// becomes the Stribeck model (Fc + (Fs − Fc)·exp(−(q̇/vs)²))·sign(q̇).
    #[arg(long, value_name = "FS", allow_hyphen_values = true, requires = "stribeck_velocity")]
    pub static_friction: Option<String>,

    /// Stribeck velocity vs per joint (rad/s or m/s, positive), with --static-friction.
    #[arg(long, value_name = "VS", allow_hyphen_values = true, requires = "static_friction")]
    pub stribeck_velocity: Option<String>,

    /// Torque offset F0 per joint: τ += F0.
    #[arg(long, value_name = "F0", allow_hyphen_values = true)]
    pub offset: Option<String>,

    /// Joint terms past friction, with --extra-params: a comma-separated list of
    /// `asymmetric` (Fva·|q̇|), `ripple=H` (per harmonic k: Ts_k·sin(kq) +
    /// Tc_k·cos(kq) + (Fcs_k·sin(kq) + Fcc_k·cos(kq))·sign(q̇)) and `load`
    /// (Fcl·|τ_rigid|·sign(q̇)), as `identify --extra-terms` fits them.
    #[arg(long, value_name = "LIST", value_parser = crate::ranges::extra_terms, requires = "extra_params")]
    pub extra_terms: Option<ExtraTerms>,

    /// The --extra-terms' parameters in their order (Fva, Ts1, Tc1, Fcs1, Fcc1, …,
    /// Fcl): one set for all joints, or one set per joint, joint by joint.
    #[arg(long, value_name = "VALUES", allow_hyphen_values = true, requires = "extra_terms")]
    pub extra_params: Option<String>,

    /// Each joint's gear ratio N (one for all joints or one per joint), for
    /// --extra-terms motor-ripple=H (harmonics of the motor angle N·q: Tms·sin(mNq) +
    /// Tmc·cos(mNq)).
    #[arg(long, value_name = "N", allow_hyphen_values = true, requires = "extra_terms")]
    pub gear_ratios: Option<String>,

    /// Write the recording as a robot's logger does: sampled every DT seconds with
    /// jittered steps, some rows duplicated or stale, columns t, q, v and tau (or
    /// motor currents with --current-gains); no accelerations or wrenches. The
    /// experiment's --steps is then ignored. 0 < DT ≤ 1000 s, and at most 1000000
    /// samples (--duration / DT).
    #[arg(long, value_name = "DT", allow_negative_numbers = true, value_parser = crate::ranges::LOGGER_PERIOD)]
    pub logger_period: Option<f64>,

    /// Logger: each step is DT·(1 + u), u uniform within ±this fraction, 0 ≤ x < 1.
    #[arg(long, default_value_t = 0.25, allow_negative_numbers = true, value_parser = crate::ranges::JITTER)]
    pub jitter: f64,

    /// Logger: fraction of rows written twice with the same time stamp, 0 to 1.
    #[arg(long, default_value_t = 0.005, allow_negative_numbers = true, value_parser = crate::ranges::FRACTION)]
    pub duplicates: f64,

    /// Logger: fraction of rows repeating the previous row's values under a new time
    /// stamp, 0 to 1.
    #[arg(long, default_value_t = 0.005, allow_negative_numbers = true, value_parser = crate::ranges::FRACTION)]
    pub stale: f64,

    /// Logger: write motor currents i = τ/k with these torque constants (N·m/A),
    /// one for all joints or one per joint, as columns i1..in.
    #[arg(long, value_name = "K1,K2,…")]
    pub current_gains: Option<String>,

    /// Logger: round the currents to multiples of this resolution (A), 0 to 1000.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = crate::ranges::CURRENT_QUANTUM)]
    pub current_quantum: f64,

    /// Fourier: what the coefficients are optimised for.
    #[arg(long, value_enum, default_value_t = CriterionArg::Torques)]
    pub criterion: CriterionArg,

    /// Fourier: harmonics per joint, 1 to 50.
    #[arg(long, default_value_t = 5, value_parser = crate::ranges::HARMONICS)]
    pub harmonics: usize,

    /// Fourier: base frequency, Hz, 1e-6 ≤ f ≤ 1000 (the trajectory repeats every 1/f s).
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true, value_parser = crate::ranges::BASE_FREQUENCY)]
    pub base_frequency: f64,

    /// Fourier: objective evaluations allowed to the optimiser (each one evaluates
    /// the regressor at 20·harmonics instants over one period, however many --steps
    /// are recorded). Default: 3000 up to 12 joints, then 3000·(12/n)², so that it
    /// takes about as long on any robot: under 2 s for a 6-joint arm in a
    /// release build, with a progress bar. Too few for one Nelder–Mead run (0, say; a
    /// run needs more than one evaluation per variable, 1 + 2·harmonics per joint)
    /// keep the random feasible start. At most 10000000.
    #[arg(long, value_parser = crate::ranges::EVALUATIONS)]
    pub evaluations: Option<usize>,

    /// Fourier: stop optimising after this many seconds and keep the best excitation
    /// so far (the result then depends on the machine's speed; `--evaluations` is the
    /// reproducible bound); 0 < s ≤ 1e6.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = crate::ranges::TIME_BUDGET)]
    pub time_budget: Option<f64>,

    /// Fourier: joint acceleration limits (rad/s² or m/s², positive), one for all
    /// joints or one per joint. Default: 5/s times each joint's velocity limit
    /// (full speed from rest in 0.2 s), since URDF and MJCF give none.
    #[arg(long, value_name = "A1,A2,…", allow_hyphen_values = true)]
    pub max_acceleration: Option<String>,

    #[command(flatten)]
    pub gravity: ModelArgs,
}

/// What the flags' own ranges (`crate::ranges`, checked by clap) cannot say: the
/// logger's number of samples, which depends on two flags.
fn check_args(args: &SimulateArgs) -> Result<()> {
    if let Some(period) = args.logger_period {
        let duration = args.duration.unwrap_or(match args.experiment {
            ExperimentKind::Paper => 2.0,
            ExperimentKind::Fourier => 1.0 / args.base_frequency,
        });
        let samples = duration / period;
        if samples > crate::ranges::MAX_LOGGER_SAMPLES as f64 {
            return Err(CliError::usage(format!(
                "--logger-period {period} over {duration} s gives {samples:.3e} samples; at most {} are written: \
                 give a longer period or a shorter --duration",
                crate::ranges::MAX_LOGGER_SAMPLES
            )));
        }
    }
    Ok(())
}

pub fn run(args: &SimulateArgs, progress: &Progress) -> Result<()> {
    check_args(args)?;
    check_overwrite(&args.output, args.force)?;
    let model = load_moving_model(&args.urdf, &args.gravity)?;
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
            // A fixed design grid over one period, whatever --steps records (see
            // ExcitationDesign::default_samples).
            design.samples = ExcitationDesign::default_samples(args.harmonics);
            if let Some(text) = &args.max_acceleration {
                let limits = per_joint("--max-acceleration", text, model.nv())?;
                if let Some(bad) = limits.iter().find(|&&a| a <= 0.0) {
                    return Err(CliError::usage(format!(
                        "--max-acceleration: {bad} is not a positive acceleration"
                    )));
                }
                for (l, a) in design.limits.iter_mut().zip(limits) {
                    l.acceleration = a;
                }
            }
            if let Some(n) = args.evaluations {
                design.max_evaluations = n;
            }
            design.time_budget = args.time_budget.map(std::time::Duration::from_secs_f64);
            design.seed = args.seed;
            // A bar with the evaluations spent and the time left: one evaluation stacks
            // the regressor at every design sample, milliseconds on a 30-joint tree.
            let bar = progress.bar(design.max_evaluations as u64, "optimising the Fourier excitation");
            let found = design.optimise_with_progress(&robot, &mut |done| bar.set_position(done as u64));
            bar.finish_and_clear();
            let found = found.map_err(CliError::failed)?;
            match found.criterion {
                Criterion::JointTorques => eprintln!(
                    "excitation: condition number of the base regressor {:.4e} on {} design samples (start {:.4e}, {} \
                     evaluations, {} base columns)",
                    found.value,
                    design.samples,
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

    // Per velocity coordinate: a joint that follows another (`<mimic>`) has none.
    let n = model.nv();
    let nominal = dyngen_model::joint_params::nominal_joint_params(&model);
    let column = |flag: &str, text: &Option<String>, k: usize| -> Result<Vec<f64>> {
        match text {
            Some(t) => per_joint(flag, t, n),
            None => Ok((0..n).map(|j| nominal[4 * j + k]).collect()),
        }
    };
    let [ia, fv, fc, f0] = [
        column("--armature", &args.armature, 0)?,
        column("--damping", &args.damping, 1)?,
        column("--coulomb", &args.coulomb, 2)?,
        column("--offset", &args.offset, 3)?,
    ];
    let joint_params: Vec<f64> = (0..n).flat_map(|j| [ia[j], fv[j], fc[j], f0[j]]).collect();
    let extras = match (args.extra_terms, &args.extra_params) {
        (Some(extras), Some(text)) => {
            if (extras.harmonics > 0 || extras.motor_harmonics > 0) && model.nq() != n {
                return Err(CliError::usage(format!(
                    "--extra-terms: ripple harmonics are of each joint's one angle; `{}` has {} position and {n} \
                     velocity coordinates",
                    model.name,
                    model.nq()
                )));
            }
            let params = crate::ranges::per_joint_sets("--extra-params", text, n, extras.per_joint())?;
            let ratios = args
                .gear_ratios
                .as_deref()
                .map(|t| per_joint("--gear-ratios", t, n))
                .transpose()?;
            if extras.motor_harmonics > 0 && ratios.is_none() {
                return Err(CliError::usage(
                    "--extra-terms motor-ripple needs each joint's gear ratio: give --gear-ratios",
                ));
            }
            Some((extras, params, ratios))
        }
        _ => None,
    };
    let stribeck = match (&args.static_friction, &args.stribeck_velocity) {
        (Some(fs), Some(vs)) => {
            let (fs, vs) = (
                per_joint("--static-friction", fs, n)?,
                per_joint("--stribeck-velocity", vs, n)?,
            );
            let stribeck: Vec<Stribeck> = fs.iter().zip(&vs).map(|(&fs, &vs)| Stribeck { fs, vs }).collect();
            dyngen_identify::stribeck::check(&stribeck, n)
                .map_err(|e| CliError::usage(format!("--stribeck-velocity: {e}")))?;
            Some(stribeck)
        }
        _ => None,
    };
    let logger = match args.logger_period {
        Some(period) => Some(Logger {
            period,
            jitter: args.jitter,
            duplicates: args.duplicates,
            stale: args.stale,
            gains: args
                .current_gains
                .as_ref()
                .map(|g| per_joint("--current-gains", g, n))
                .transpose()?,
            current_quantum: args.current_quantum,
            seed: args.seed,
        }),
        None => None,
    };
    if let Some(l) = &logger {
        check_logger(l)?;
    }
    let mut clean = with_spinner(progress, "recording the experiment", || match &logger {
        Some(l) => record_trajectory(&robot, &params, &experiment.motion, &l.times(experiment.duration)),
        None => record(&robot, &params, &experiment),
    });
    if let (Motion::Fourier(e), CriterionArg::Torques) = (&experiment.motion, args.criterion) {
        // The design's samples stand for the recording: say how the recording itself
        // is conditioned.
        let times: Vec<f64> = clean.samples.iter().map(|s| s.t).collect();
        eprintln!(
            "excitation: condition number of the base regressor {:.4e} over the {} recorded samples",
            regressor_condition(&robot, e, &times),
            times.len()
        );
    }
    // The load-dependent friction's load is the rigid-body torque: first.
    if let Some((extras, params, ratios)) = &extras {
        add_extra_terms(&mut clean, *extras, params, Coulomb::Sign, ratios.as_deref()).map_err(CliError::failed)?;
    }
    if joint_params.iter().any(|&x| x != 0.0) {
        add_joint_terms(&mut clean, &joint_params, Coulomb::Sign);
    }
    if let Some(stribeck) = &stribeck {
        add_stribeck_terms(&mut clean, &joint_params, stribeck, Coulomb::Sign).map_err(CliError::failed)?;
    }
    let recording = if args.noise > 0.0 {
        NoiseModel::relative(args.noise).apply(&clean, args.seed)
    } else {
        clean
    };
    if let Some(l) = &logger {
        // The output was checked before any work (`check_overwrite` above).
        std::fs::write(&args.output, l.write(&recording))
            .map_err(|e| CliError::Output(format!("{}: {e}", args.output.display())))?;
        eprintln!(
            "wrote {} logged samples of {n} joints ({} s, noise {}) to {}",
            recording.len(),
            experiment.duration,
            args.noise,
            args.output.display()
        );
        return Ok(());
    }
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

/// A logger that can write something sensible (the numeric flags were checked by
/// their value parsers, `crate::ranges`).
fn check_logger(l: &Logger) -> Result<()> {
    if let Some(k) = &l.gains {
        if k.contains(&0.0) {
            return Err(CliError::usage("--current-gains must not be zero"));
        }
    }
    Ok(())
}
