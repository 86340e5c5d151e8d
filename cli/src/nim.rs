//! `dyngen nim`: the generalising neural-network identifier on any URDF: `train`
//! along the joint motion of a CSV file (on simulated parameter draws), `predict`
//! the principal parameters from measured data.

use crate::common::{check_overwrite, load_moving_model, outln, refuse_followers, ModelArgs, Progress, Result};
use crate::error::CliError;
use clap::{Args, Subcommand};
use dyngen_identify::data::Trajectory;
use dyngen_identify::mim;
use dyngen_identify::report;
use dyngen_identify::simulate::{record_trajectory, Recording, SampledMotion};
use dyngen_model::Model;
use dyngen_nim::{draw_theta, Nim, NimConfig, NimError, Optimizer};
use dyngen_reference::Reference;
use dyngen_reference::{principal_params_to_standard, SplitMix64};
use std::path::{Path, PathBuf};
use std::time::Instant;

pub const EXAMPLES: &str = "\
Examples:
  dyngen simulate arm.urdf -o run.csv --experiment fourier --criterion body-model --base-frequency 0.5 --duration 4 --steps 200
  dyngen nim train arm.urdf run.csv -o arm-nim.json
  dyngen nim predict arm.urdf arm-nim.json measured.csv --params-json nim.json

train simulates the robot along the joint motion of the CSV (t, q and, if present,
v and a) with many parameter draws around the URDF's inertials and trains one
network per body; predict reads measured data along that motion (with the joint
wrench columns fx1..mzn) and prints each body's (m, J1, J2, J3). A network only
knows the motion it was trained on: predict warns when the data move otherwise.";

#[derive(Debug, Args)]
pub struct NimArgs {
    #[command(subcommand)]
    pub command: NimCommand,
}

#[derive(Debug, Subcommand)]
pub enum NimCommand {
    /// Train the identifier along the joint motion of a CSV file.
    #[command(after_help = EXAMPLES)]
    Train(TrainArgs),
    /// Identify every body's (m, J1, J2, J3) from measured data with a trained
    /// identifier.
    #[command(after_help = EXAMPLES)]
    Predict(PredictArgs),
}

#[derive(Debug, Args)]
pub struct TrainArgs {
    /// The robot (URDF); its inertials are the centre of the parameter draws.
    pub urdf: PathBuf,
    /// The joint motion to train along (CSV: t, q1..qn[, v, a], tau1..taun; v and a
    /// are estimated from q when missing).
    pub motion: PathBuf,
    /// Where to write the identifier (JSON). An existing file is kept unless --force.
    #[arg(long, short)]
    pub output: PathBuf,
    #[arg(long)]
    pub force: bool,
    /// Samples per window, 1 to 10000.
    #[arg(long, default_value_t = 20, value_parser = crate::ranges::WINDOW)]
    pub window: usize,
    /// Parameter draws to train on, 1 to 10000000.
    #[arg(long, default_value_t = 1500, value_parser = crate::ranges::DRAWS)]
    pub draws: usize,
    /// Relative half-width of the draws: masses and principal second moments
    /// within ±spread of the URDF's, 0 ≤ spread < 1.
    #[arg(long, default_value_t = 0.3, allow_negative_numbers = true, value_parser = crate::ranges::SPREAD)]
    pub spread: f64,
    /// Relative sensor noise added to the training windows (0.01 = 1 %), 0 to 1.
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true, value_parser = crate::ranges::NOISE)]
    pub noise: f64,
    /// Adam steps per body, 1 to 100000000.
    #[arg(long, default_value_t = 6000, value_parser = crate::ranges::ADAM_STEPS)]
    pub steps: usize,
    /// After training, identify this many further unseen draws simulated along the
    /// motion and print the worst errors (0 to 1000000).
    #[arg(long, default_value_t = 50, value_parser = crate::ranges::TEST_DRAWS)]
    pub test_draws: usize,
    /// Bodies trained at once, 0 to 1024; 0 = one per core.
    #[arg(long, default_value_t = 0, value_parser = crate::ranges::THREADS)]
    pub threads: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Low-pass cutoff (Hz, 0 < Hz ≤ 1e6) for estimating v and a when the file has no
    /// such columns.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true, value_parser = crate::ranges::CUTOFF)]
    pub cutoff: f64,
    /// Read the recording through this recipe (layout, units, windows; see the README).
    #[arg(long, value_name = "FILE")]
    pub recipe: Option<PathBuf>,
    /// Also write the training curves (MSE against step, per body) as SVG.
    #[arg(long, value_name = "FILE")]
    pub loss_svg: Option<PathBuf>,
    #[command(flatten)]
    pub gravity: ModelArgs,
}

#[derive(Debug, Args)]
pub struct PredictArgs {
    /// The robot (URDF) the identifier was trained for.
    pub urdf: PathBuf,
    /// The identifier written by `dyngen nim train`.
    pub nim: PathBuf,
    /// Measured data (CSV with t, q, tau and the joint wrench columns fx1..mzn).
    pub data: PathBuf,
    /// Windows start every `stride` samples, 1 to 1000000 (default: half a window).
    #[arg(long, value_parser = crate::ranges::STRIDE)]
    pub stride: Option<usize>,
    /// Write the estimate as JSON (schema dyngen-parameters/1).
    #[arg(long, value_name = "FILE")]
    pub params_json: Option<PathBuf>,
    /// Take the URDF's inertials as the truth and print the errors.
    #[arg(long)]
    pub truth_from_urdf: bool,
    #[arg(long)]
    pub force: bool,
    /// Low-pass cutoff (Hz, 0 < Hz ≤ 1e6) for estimating v and a when the file has no
    /// such columns.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true, value_parser = crate::ranges::CUTOFF)]
    pub cutoff: f64,
    /// Read the recording through this recipe (layout, units, windows; see the README).
    #[arg(long, value_name = "FILE")]
    pub recipe: Option<PathBuf>,
    #[command(flatten)]
    pub gravity: ModelArgs,
}

pub fn run(args: &NimArgs, progress: &Progress) -> Result<()> {
    match &args.command {
        NimCommand::Train(a) => train(a, progress),
        NimCommand::Predict(a) => predict(a),
    }
}

/// A recording with v and a (estimated when missing), read through `recipe` if given.
fn read_data(path: &Path, model: &Model, cutoff: f64, recipe: Option<&Path>) -> Result<Trajectory> {
    let recipe = crate::identify::RecipeArgs {
        recipe: recipe.map(Path::to_path_buf),
        ..Default::default()
    };
    crate::identify::load_recording(path, &recipe.recipe()?, model.dof(), cutoff, true)
}

/// A NIM error about the file `path`: reading it is input, writing it output.
fn nim_file_error(path: &Path, e: NimError, writing: bool) -> CliError {
    match e {
        NimError::AlreadyExists { .. } => CliError::OutputExists(path.to_path_buf()),
        e if writing => CliError::output(path, e),
        e => CliError::input(path, e),
    }
}

/// A training or identification error: options out of range are usage errors.
fn nim_error(path: &Path, e: NimError) -> CliError {
    match e {
        NimError::InvalidOption { .. } => CliError::usage(format!("{}: {e}", path.display())),
        e => CliError::failed(format!("{}: {e}", path.display())),
    }
}

fn train(args: &TrainArgs, progress: &Progress) -> Result<()> {
    check_overwrite(&args.output, args.force)?;
    if let Some(svg) = &args.loss_svg {
        if svg == &args.output {
            return Err(CliError::usage(
                "--output and --loss-svg name the same file; give each its own",
            ));
        }
        check_overwrite(svg, args.force)?;
    }
    let model = load_moving_model(&args.urdf, &args.gravity)?;
    refuse_followers(&model, &args.urdf)?;
    let traj = read_data(&args.motion, &model, args.cutoff, args.recipe.as_deref())?;
    let motion = SampledMotion::from_data(&traj)
        .ok_or_else(|| CliError::input(&args.motion, "the motion has no velocities or accelerations"))?;
    let robot = Reference::new(&model);
    // Draws around the nominal parameters must be consistent: a CAD-rounded
    // inertia accepted with a warning is moved to the nearest physical one first.
    let nominal = dyngen_model::principal_params(&model.nearest_physical());
    let recording = record_trajectory(&robot, &model.standard_params(), &motion, motion.times());

    let mut config = NimConfig {
        window: args.window,
        draws: args.draws,
        spread: args.spread,
        noise: args.noise,
        seed: args.seed,
        threads: args.threads,
        ..NimConfig::default()
    };
    config.train.max_steps = args.steps;
    config.train.seed = args.seed;
    let batch_size = match config.train.optimizer {
        Optimizer::Adam { batch_size, .. } => batch_size,
        Optimizer::GradientDescent { .. } => config.draws,
    };
    outln!(
        "training one network per body of {} along {} samples of {}: {} draws within ±{}%, windows of {}, {} steps \
         of {} windows, {}% training noise",
        model.name,
        recording.len(),
        args.motion.display(),
        config.draws,
        100.0 * config.spread,
        config.window,
        args.steps,
        batch_size,
        100.0 * config.noise
    );
    let bar = progress.bar(model.dof() as u64, "training bodies");
    let start = Instant::now();
    let (nim, training) = Nim::train(&model.name, &recording, &nominal, &config, &|_| bar.inc(1))
        .map_err(|e| nim_error(&args.motion, e))?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    for (i, (body, history)) in nim.bodies.iter().zip(&training.histories).enumerate() {
        let outputs: Vec<&str> = body.outputs.iter().map(|&k| mim::THETA_NAMES[k]).collect();
        match history {
            // The targets are logarithms: the RMS error is a relative error.
            Some(h) => outln!(
                "  {}: predicts {}; {} windows per draw; RMS relative error of one window's prediction: training \
                 {:.2}%, validation draws {}",
                nim.body_names[i],
                outputs.join(", "),
                training.windows_per_draw[i],
                100.0 * h.train_mse_original.last().copied().unwrap_or(f64::NAN).sqrt(),
                h.validation_mse_original
                    .last()
                    .map_or_else(|| "—".to_string(), |v| format!("{:.2}%", 100.0 * v.sqrt()))
            ),
            None => outln!(
                "  {}: none of m, J1, J2, J3 enters its equations along this motion; no network",
                nim.body_names[i]
            ),
        }
    }
    outln!("trained in {seconds:.1} s");
    nim.save(&args.output, args.force)
        .map_err(|e| nim_file_error(&args.output, e, true))?;
    outln!("wrote the identifier to {}", args.output.display());
    if let Some(svg) = &args.loss_svg {
        // The targets are ln θ: the RMS error of a window's prediction is a relative
        // error of θ.
        let curves: Vec<(String, Vec<(f64, f64)>)> = training
            .histories
            .iter()
            .zip(&nim.body_names)
            .filter_map(|(h, name)| {
                let h = h.as_ref()?;
                let errors = if h.validation_mse_original.is_empty() {
                    &h.train_mse_original
                } else {
                    &h.validation_mse_original
                };
                let points = h.steps.iter().map(|&s| s as f64).zip(errors.iter().map(|e| e.sqrt()));
                Some((name.clone(), points.collect()))
            })
            .collect();
        let title = format!("{}: NIM training, RMS relative error of one window's θ", model.name);
        let text = dyngen_identify::report::svg_lines(&dyngen_identify::report::LineChart {
            title: &title,
            x_label: "Adam step",
            y_label: "RMS relative error",
            log_y: true,
            curves: &curves,
            reference: None,
            legend: dyngen_identify::report::Corner::UpperRight,
        })
        .map_err(|e| CliError::report(svg, e))?;
        report::write_new(svg, &text, args.force).map_err(|e| CliError::report(svg, e))?;
        outln!("wrote the training curves to {}", svg.display());
    }
    if args.test_draws > 0 {
        test_on_unseen_draws(args, &model, &robot, &motion, &nim, &nominal)?;
    }
    Ok(())
}

/// Identifies `--test-draws` further draws (a stream the training never saw),
/// simulated along the motion by the full dynamics, and prints the worst errors.
fn test_on_unseen_draws(
    args: &TrainArgs,
    model: &Model,
    robot: &Reference,
    motion: &SampledMotion,
    nim: &Nim,
    nominal: &[f64],
) -> Result<()> {
    let mut rng = SplitMix64::new(args.seed ^ 0x7465_7374_0000);
    let (mut mass, mut moments): (f64, f64) = (0.0, 0.0);
    for _ in 0..args.test_draws {
        let theta = draw_theta(nominal, args.spread, &mut rng);
        let recording: Recording = record_trajectory(
            robot,
            &principal_params_to_standard(model, &theta),
            motion,
            motion.times(),
        );
        let estimate = nim
            .identify(&recording, (nim.window / 2).max(1))
            .map_err(CliError::failed)?
            .with_truth(&theta);
        let (m, j) = estimate.max_relative_errors().unwrap_or((f64::NAN, f64::NAN));
        mass = mass.max(m);
        moments = moments.max(j);
    }
    outln!(
        "on {} unseen draws (noise-free, full dynamics): worst relative error {:.3}% on a mass, {:.3}% on a principal \
         moment",
        args.test_draws,
        100.0 * mass,
        100.0 * moments
    );
    Ok(())
}

fn predict(args: &PredictArgs) -> Result<()> {
    if let Some(path) = &args.params_json {
        check_overwrite(path, args.force)?;
    }
    let model = load_moving_model(&args.urdf, &args.gravity)?;
    refuse_followers(&model, &args.urdf)?;
    let nim = Nim::load(&args.nim).map_err(|e| nim_file_error(&args.nim, e, false))?;
    let body_names: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    if nim.body_names != body_names {
        return Err(CliError::Input(format!(
            "{} was trained for {} with bodies [{}], but {} has bodies [{}]; train an identifier for this robot \
             with `dyngen nim train`",
            args.nim.display(),
            nim.robot,
            nim.body_names.join(", "),
            args.urdf.display(),
            body_names.join(", ")
        )));
    }
    let traj = read_data(&args.data, &model, args.cutoff, args.recipe.as_deref())?;
    if traj.joint_wrenches().is_none() {
        return Err(CliError::Input(format!(
            "{}: NIM reads each body's resultant from the joint wrench columns fx1, fy1, fz1, mx1, my1, mz1, …, \
             mz{}, which the file does not have",
            args.data.display(),
            model.dof()
        )));
    }
    let robot = Reference::new(&model);
    let recording = Recording::from_measurements(&robot, &traj).map_err(|e| CliError::input(&args.data, e))?;
    let unfamiliar = nim.unfamiliar_fraction(&recording);
    if unfamiliar > 0.01 {
        eprintln!(
            "warning: {:.0}% of the body samples of {} move unlike the training motion (beyond 6σ of a training \
             feature); the estimate is an extrapolation",
            100.0 * unfamiliar,
            args.data.display()
        );
    }
    let stride = args.stride.unwrap_or((nim.window / 2).max(1));
    let estimate = nim.identify(&recording, stride).map_err(|e| nim_error(&args.data, e))?;
    let estimate = if args.truth_from_urdf {
        estimate.with_truth(&dyngen_model::principal_params(&model))
    } else {
        estimate
    };
    outln!(
        "{} samples of {} joints from {}",
        traj.len(),
        model.dof(),
        args.data.display()
    );
    outln!("{estimate}");
    if let Some(path) = &args.params_json {
        estimate
            .report(&model.name)
            .write(path, args.force)
            .map_err(|e| CliError::report(path, e))?;
        outln!("wrote the parameters to {}", path.display());
    }
    Ok(())
}
