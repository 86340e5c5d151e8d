//! The source paper's experiment (Advances in Mechanical Engineering, 2025, doi:10.1177/16878132251321050) on its 6-DOF
//! manipulator (paper6), end to end, as
//! `dyngen demo` shows it. MIM: the paper's Tables 2–3 from the single instant t = 1.5 s and from all
//! samples, noise-free and with sensor noise; an excitation designed for MIM; a noise
//! study on both experiments. NIM: the paper's network as described (Tables 4–5,
//! Fig. 5) and what it really does; the generalising NIM trained on parameter draws;
//! MIM and both NIMs side by side on draws none of them has seen; a payload picked up
//! mid-motion, followed by NIM and by recursive least squares.

//!
//! [`run`] prints the tables to stdout and writes the figures into
//! [`Options::out`]; a front end supplies progress reporting and the drawing of the
//! figures through [`Hooks`] (so this crate links no plotting library).

use dyngen_identify::mim::{self, MimOptions, Verdict, THETA_NAMES};
use dyngen_identify::report;
use dyngen_identify::simulate::{
    moment_sigma, record, Criterion, ExcitationDesign, Experiment, Motion, NoiseModel, Recording,
};
use dyngen_nim::online::{track, Tracking, TrackingSummary};
use dyngen_nim::{draw_theta, paper_nim, Nim, NimConfig, PaperNim, PaperNimConfig};
use dyngen_reference::{principal_params_to_standard, SplitMix64};
use dyngen_reference::{Dynamics, Generated};
use robot_paper6::Paper6;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// `dyngen demo --help`'s examples and the noise model.
pub const EXAMPLES: &str = "\
Examples:
  dyngen demo
  dyngen demo --noise 0.02 --seed 7
  dyngen demo --pooled-noise
  dyngen demo --out figures          # also the figures, as SVG files in figures/

Noise: σ of every measured curve (each axis of each body's Cardano angles and
rates, angular velocity and acceleration, centre-of-mass acceleration and
resultant force and moment) is --noise times that curve's RMS over the recording;
with --pooled-noise the three axes of one sensor share one σ, --noise times the RMS
over all three (an axis that barely moves then gets the noise of the busiest one).";

/// What [`run`] does; the defaults are `dyngen demo`'s.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Relative sensor noise of the noisy runs (0.01 is 1 %).
    pub noise: f64,
    /// Seed of the sensor noise.
    pub seed: u64,
    /// One σ per 3-axis sensor (pooled over its axes) instead of one per curve.
    pub pooled_noise: bool,
    /// Write the figures as SVG files into this directory, created if missing.
    pub out: Option<PathBuf>,
    /// Replace figures that already exist in `out`.
    pub force: bool,
    /// Generalising NIM: parameter draws to train on.
    pub draws: usize,
    /// Generalising NIM: Adam steps per body.
    pub steps: usize,
    /// Unseen parameter draws for the side-by-side comparison.
    pub test_draws: usize,
    /// Bodies trained at once; 0 = one per core.
    pub threads: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            noise: 0.01,
            seed: 1,
            pooled_noise: false,
            out: None,
            force: false,
            draws: 1500,
            steps: 6000,
            test_draws: 100,
            threads: 0,
        }
    }
}

/// Why the reproduction stopped.
#[derive(Debug)]
pub enum PaperError {
    /// An option out of its range (`option` names it).
    InvalidOption { option: &'static str, reason: String },
    /// A figure exists and `force` was not set.
    FigureExists(PathBuf),
    /// A figure or the output directory could not be drawn or written.
    Output { path: PathBuf, message: String },
    /// A step of the reproduction failed.
    Failed(String),
}

impl fmt::Display for PaperError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PaperError::InvalidOption { option, reason } => write!(f, "{option} {reason}"),
            PaperError::FigureExists(path) => write!(f, "{} already exists", path.display()),
            PaperError::Output { path, message } => write!(f, "{}: {message}", path.display()),
            PaperError::Failed(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for PaperError {}

type Result<T> = std::result::Result<T, PaperError>;

fn failed(e: impl fmt::Display) -> PaperError {
    PaperError::Failed(e.to_string())
}

pub use dyngen_identify::report::{Corner, LineChart};

/// What a front end supplies: progress reporting and drawing. Every method has a
/// default that does nothing (and draws nothing: then `Options::out` is refused).
pub trait Hooks: Sync {
    /// A step of `steps` units (`None`: of unknown length) starts.
    fn begin(&self, _message: &str, _steps: Option<u64>) {}
    /// One unit of the current step is done (called from worker threads too).
    fn advance(&self) {}
    /// The current step is over.
    fn end(&self) {}
    /// Whether [`Hooks::draw`] draws.
    fn draws(&self) -> bool {
        false
    }
    /// The SVG text of `chart`, or `None` when this front end does not draw.
    fn draw(&self, _chart: &LineChart<'_>) -> Option<std::result::Result<String, String>> {
        None
    }
}

/// Hooks that report nothing and draw nothing.
pub struct Silent;

impl Hooks for Silent {}

/// Progress through the front end's hooks, shaped like a progress bar.
struct Progress<'a> {
    hooks: &'a dyn Hooks,
}

impl Progress<'_> {
    fn bar(&self, len: u64, message: &str) -> Bar<'_> {
        self.hooks.begin(message, Some(len));
        Bar { hooks: self.hooks }
    }
}

struct Bar<'a> {
    hooks: &'a dyn Hooks,
}

impl Bar<'_> {
    fn inc(&self, _units: u64) {
        self.hooks.advance();
    }

    fn finish_and_clear(&self) {
        self.hooks.end();
    }
}

fn with_spinner<T>(progress: &Progress<'_>, message: &str, work: impl FnOnce() -> T) -> T {
    progress.hooks.begin(message, None);
    let out = work();
    progress.hooks.end();
    out
}

fn check_overwrite(path: &Path, force: bool) -> Result<()> {
    if !force && path.exists() {
        return Err(PaperError::FigureExists(path.to_path_buf()));
    }
    Ok(())
}

/// The figures `--out` receives.
pub const FIGURES: [&str; 3] = ["fig5_paper_nim_mse.svg", "nim_training.svg", "payload_tracking.svg"];

/// Seeds of the noise study: the worst case over several draws, so no number rests
/// on one lucky draw.
const STUDY_SEEDS: Range<u64> = 1..6;
const STUDY_LEVELS: [f64; 3] = [0.001, 0.01, 0.05];

/// Runs the reproduction, printing every table to stdout and writing the figures
/// into `options.out` (drawn by `hooks`).
pub fn run(options: &Options, hooks: &dyn Hooks) -> Result<()> {
    let (args, progress) = (options, &Progress { hooks });
    if !(args.noise.is_finite() && args.noise >= 0.0) {
        return Err(PaperError::InvalidOption {
            option: "noise",
            reason: format!("{} is not a non-negative number", args.noise),
        });
    }
    if args.draws == 0 || args.test_draws == 0 {
        return Err(PaperError::InvalidOption {
            option: "draws and test_draws",
            reason: "must be at least 1".into(),
        });
    }
    if let Some(dir) = &args.out {
        if !hooks.draws() {
            return Err(PaperError::InvalidOption {
                option: "out",
                reason: "needs hooks that draw figures".into(),
            });
        }
        std::fs::create_dir_all(dir).map_err(|e| PaperError::Output {
            path: dir.clone(),
            message: e.to_string(),
        })?;
        for name in FIGURES {
            check_overwrite(&dir.join(name), args.force)?;
        }
    }
    let robot = Generated::<Paper6>::new();
    let model = robot.model().clone();
    let experiment = Experiment::paper(&model);
    let clean = with_spinner(
        progress,
        "simulating the paper's experiment on paper6 (2 s, 100 steps)",
        || record(&robot, &Paper6::NOMINAL_PARAMS, &experiment),
    );
    let truth = dyngen_model::principal_params(&model);
    let options = MimOptions::default();
    // Samples 1..=100: the paper's 100 sets (sample 0 is the state at rest).
    let all = 1..clean.samples.len();

    println!("dyngen demo: the paper's MIM on its 6-DOF manipulator of homogeneous cylinders");
    println!(
        "(robot-paper6; {} samples over {:.1} s; generated dynamics; θ = (m, J1, J2, J3) per body)\n",
        all.len(),
        experiment.duration
    );
    let mim_tables = |title: String, recording: &Recording| -> Result<()> {
        println!("== {title}, single instant t = 1.5 s (the paper's Tables 2 and 3) ==");
        let instant = mim::instant(recording, 1.5, Some(&truth), &options).map_err(failed)?;
        println!("{instant}");
        println!("== {title}, least squares over all samples ==");
        let samples = mim::samples(recording, all.clone(), Some(&truth), &options).map_err(failed)?;
        println!("{samples}");
        Ok(())
    };
    mim_tables("noise-free".into(), &clean)?;
    let noisy = noise_model(args.noise, args.pooled_noise).apply(&clean, args.seed);
    mim_tables(
        format!(
            "{}% sensor noise ({}, seed {})",
            100.0 * args.noise,
            if args.pooled_noise {
                "pooled per sensor"
            } else {
                "per curve"
            },
            args.seed
        ),
        &noisy,
    )?;

    // The same length and sampling as the paper's experiment, with the joint motion
    // chosen for MIM: a Fourier excitation optimised for the worst relative σ of a
    // principal moment (Criterion::BodyModel).
    let designed = with_spinner(progress, "optimising an excitation for MIM", || {
        mim_excitation(&robot, &experiment)
    });
    let designed_clean = record(&robot, &Paper6::NOMINAL_PARAMS, &designed);
    println!("== an excitation designed for MIM ==");
    println!(
        "worst relative σ of a principal moment at 1% noise on the moments, over all {} samples: the paper's \
         motion {:.2}%, a Fourier excitation optimised for MIM {:.3}% (5 harmonics, period {} s, same samples)\n",
        all.len(),
        moment_sigma(&robot, &experiment.motion, &experiment.times()[all.clone()]),
        moment_sigma(&robot, &designed.motion, &designed.times()[all.clone()]),
        designed.duration
    );
    noise_study(
        &[("the paper's motion", &clean), ("excitation for MIM", &designed_clean)],
        &truth,
        all.clone(),
        &options,
    )?;

    let figure = |name: &str| args.out.as_ref().map(|dir| dir.join(name));
    let paper = paper_faithful_nim(
        &clean,
        &truth,
        all.clone(),
        progress,
        figure(FIGURES[0]).as_deref(),
        args.force,
    )?;
    let trained = generalising_nim(args, &robot, &designed, &truth, progress, figure(FIGURES[1]).as_deref())?;
    side_by_side(
        args,
        &robot,
        &designed,
        &designed_clean,
        &truth,
        &paper,
        &trained,
        progress,
    )?;
    payload(
        args,
        &robot,
        &designed,
        &truth,
        &trained.nim,
        figure(FIGURES[2]).as_deref(),
        progress,
    )
}

/// A Fourier excitation over the paper's duration and sampling, optimised for MIM.
fn mim_excitation(robot: &dyn Dynamics, paper: &Experiment) -> Experiment {
    let design = ExcitationDesign {
        criterion: Criterion::BodyModel,
        base_frequency: 1.0 / paper.duration,
        duration: paper.duration,
        samples: paper.steps,
        ..ExcitationDesign::new(robot.model())
    };
    Experiment {
        duration: paper.duration,
        steps: paper.steps,
        motion: Motion::Fourier(design.optimise(robot).excitation),
    }
}

/// The SVG text of `chart`, drawn by the front end.
fn draw(progress: &Progress<'_>, chart: &LineChart<'_>) -> std::result::Result<String, String> {
    progress
        .hooks
        .draw(chart)
        .unwrap_or_else(|| Err("this front end draws no figures".into()))
}

/// Writes an SVG figure (`None`: no figure directory) and says where.
fn write_figure(
    path: Option<&Path>,
    force: bool,
    svg: impl FnOnce() -> std::result::Result<String, String>,
) -> Result<()> {
    let Some(path) = path else { return Ok(()) };
    let output = |message: String| PaperError::Output {
        path: path.to_path_buf(),
        message,
    };
    let text = svg().map_err(output)?;
    report::write_new(path, &text, force).map_err(|e| match e {
        report::ReportError::Exists { .. } => PaperError::FigureExists(path.to_path_buf()),
        e => output(e.to_string()),
    })?;
    println!("figure: {}", path.display());
    Ok(())
}

/// The paper's NIM as described, then the same net trained on wrong labels.
fn paper_faithful_nim(
    clean: &Recording,
    truth: &[f64],
    all: Range<usize>,
    progress: &Progress<'_>,
    figure: Option<&Path>,
    force: bool,
) -> Result<PaperNim> {
    println!("\n== NIM as the paper describes it (Tables 4 and 5, Fig. 5) ==");
    let config = PaperNimConfig::default();
    let (paper, seconds) = timed(|| {
        with_spinner(progress, "training the paper's NIM", || {
            paper_nim(clean, all.clone(), truth, &config)
        })
    });
    let paper = paper.map_err(failed)?.with_truth(truth);
    println!("{paper}");
    println!(
        "inputs per sample |α|, |ω|, |ω̇|, |a_c|, |F|, |M|; hidden layers of {}; step size {}; trained in {:.2} s",
        config.hidden,
        config.learning_rate,
        seconds.as_secs_f64()
    );
    let wrong: Vec<f64> = truth.iter().map(|x| 1.2 * x).collect();
    let relabelled = paper_nim(clean, all, &wrong, &config).map_err(failed)?;
    let offsets: Vec<f64> = relabelled
        .theta
        .iter()
        .zip(truth)
        .zip(&relabelled.identifiable)
        .filter(|(_, &ok)| ok)
        .map(|((v, t), _)| v / t - 1.0)
        .collect();
    println!(
        "what it really does: every training target is the one true θ, so the net learns a constant and returns its \
         labels. Trained on labels 20% above the truth, the same procedure \"identifies\" values {:.1}% above the \
         truth on average (from {:.1}% to {:.1}%): it identifies nothing it was not told. Its errors above are the \
         spread of a constant net extrapolated to the last 20 samples.",
        100.0 * offsets.iter().sum::<f64>() / offsets.len() as f64,
        100.0 * offsets.iter().copied().fold(f64::INFINITY, f64::min),
        100.0 * offsets.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    write_figure(figure, force, || {
        let curves = loss_curves(&paper.body_names, paper.histories.iter().map(Some), |h, k| {
            h.train_mse[k]
        });
        draw(
            progress,
            &LineChart {
                title: "paper-faithful NIM: MSE against training step (cf. the paper's Fig. 5)",
                x_label: "training step (full-batch gradient descent)",
                y_label: "MSE (each target over its own size)",
                log_y: true,
                curves: &curves,
                reference: Some(("threshold", config.mse_threshold)),
                legend: Corner::UpperRight,
            },
        )
    })?;
    Ok(paper)
}

/// Each body's training curve, `(step, value(history, record point))`.
fn loss_curves<'a>(
    names: &[String],
    histories: impl Iterator<Item = Option<&'a dyngen_nim::TrainHistory>>,
    value: impl Fn(&dyngen_nim::TrainHistory, usize) -> f64,
) -> Vec<(String, Vec<(f64, f64)>)> {
    names
        .iter()
        .zip(histories)
        .filter_map(|(name, h)| {
            h.map(|h| {
                let points = h
                    .steps
                    .iter()
                    .enumerate()
                    .map(|(k, &s)| (s as f64, value(h, k)))
                    .collect();
                (name.clone(), points)
            })
        })
        .collect()
}

fn timed<T>(work: impl FnOnce() -> T) -> (T, Duration) {
    let start = Instant::now();
    let out = work();
    (out, start.elapsed())
}

/// The generalising NIM and how long it took to train.
struct Trained {
    nim: Nim,
    seconds: f64,
    config: NimConfig,
}

/// Trains the generalising NIM along two periods of the designed excitation (so
/// that windows at every phase of the periodic motion are seen).
fn generalising_nim(
    args: &Options,
    robot: &dyn Dynamics,
    designed: &Experiment,
    truth: &[f64],
    progress: &Progress<'_>,
    figure: Option<&Path>,
) -> Result<Trained> {
    let mut config = NimConfig {
        draws: args.draws,
        threads: args.threads,
        ..NimConfig::default()
    };
    config.train.max_steps = args.steps;
    println!("\n== the generalising NIM ==");
    let two_periods = Experiment {
        duration: 2.0 * designed.duration,
        steps: 2 * designed.steps,
        motion: designed.motion.clone(),
    };
    let recording = record(robot, &Paper6::NOMINAL_PARAMS, &two_periods);
    let bar = progress.bar(recording.nv() as u64, "training the generalising NIM, body by body");
    let (result, elapsed) = timed(|| Nim::train("paper6", &recording, truth, &config, &|_| bar.inc(1)));
    bar.finish_and_clear();
    let (nim, training) = result.map_err(failed)?;
    let seconds = elapsed.as_secs_f64();
    println!(
        "per body a window network (18 features per sample: F/ρ_F, a_c − g, M/ρ_M, ω, ω̇, gyroscopic products, in body \
         axes) → encoder {:?} → mean over {} samples → decoder {:?} → ln(θ/ρ); {} parameters per body",
        config.shape.encoder,
        config.window,
        config.shape.decoder,
        nim.bodies
            .iter()
            .find_map(|b| b.net.as_ref())
            .map_or(0, |n| n.parameter_count())
    );
    println!(
        "trained along the excitation designed for MIM ({} samples, two periods) on {} draws of θ within ±{}% \
         (mass and principal second moments), {}% sensor noise, {} Adam steps per body: {:.1} s on {} threads",
        recording.len(),
        config.draws,
        100.0 * config.spread,
        100.0 * config.noise,
        config.train.max_steps,
        seconds,
        match config.threads {
            0 => std::thread::available_parallelism().map_or(1, |t| t.get()),
            t => t,
        }
    );
    for (i, body) in nim.bodies.iter().enumerate() {
        if body.outputs.len() < 4 {
            let missing: Vec<&str> = (0..4)
                .filter(|k| !body.outputs.contains(k))
                .map(|k| THETA_NAMES[k])
                .collect();
            println!(
                "{}: {} not an output (never enters the body's equations)",
                nim.body_names[i],
                missing.join(", ")
            );
        }
    }
    write_figure(figure, args.force, || {
        // The targets are ln θ: the RMS error of a window's prediction is a relative
        // error of θ.
        let curves = loss_curves(
            &nim.body_names,
            training.histories.iter().map(Option::as_ref),
            |h, k| h.validation_mse_original[k].sqrt(),
        );
        draw(
            progress,
            &LineChart {
                title: "generalising NIM: RMS relative error of one window's θ, on validation draws",
                x_label: "Adam step (64 windows each)",
                y_label: "RMS relative error",
                log_y: true,
                curves: &curves,
                reference: None,
                legend: Corner::UpperRight,
            },
        )
    })?;
    Ok(Trained { nim, seconds, config })
}

/// The worst relative error on a mass and on a principal moment over the values
/// that are given, and how many of the `expected` values are missing.
#[derive(Clone, Copy, Default)]
struct Worst {
    mass: f64,
    moment: f64,
    missing: usize,
}

impl Worst {
    fn add(&mut self, values: &[Option<f64>], truth: &[f64], expected: &[bool]) {
        for (j, (v, t)) in values.iter().zip(truth).enumerate() {
            match v {
                Some(v) if expected[j] => {
                    let rel = dyngen_identify::relative_error(*v, *t);
                    if j % 4 == 0 {
                        self.mass = self.mass.max(rel);
                    } else {
                        self.moment = self.moment.max(rel);
                    }
                }
                None if expected[j] => self.missing += 1,
                _ => {}
            }
        }
    }

    fn cells(&self) -> [String; 2] {
        let missing = if self.missing > 0 {
            format!(" ({} n/s)", self.missing)
        } else {
            String::new()
        };
        [percent(self.mass), format!("{}{missing}", percent(self.moment))]
    }
}

/// MIM, the paper's NIM and the generalising NIM on the same unseen draws.
#[allow(clippy::too_many_arguments)]
fn side_by_side(
    args: &Options,
    robot: &dyn Dynamics,
    designed: &Experiment,
    designed_clean: &Recording,
    truth: &[f64],
    paper: &PaperNim,
    trained: &Trained,
    progress: &Progress<'_>,
) -> Result<()> {
    let model = robot.model();
    let n = model.dof();
    let all = 1..designed_clean.len();
    let options = MimOptions::default();
    // The paper's procedure on this experiment: trained on its nominal recording.
    let (paper_here, paper_training) =
        timed(|| paper_nim(designed_clean, all.clone(), truth, &PaperNimConfig::default()));
    let paper_here = paper_here.map_err(failed)?;
    let identifiable = &paper_here.identifiable;
    let nim = &trained.nim;
    let mut rng = SplitMix64::new(args.seed ^ 0x7369_6465_0000);
    let mut worst = [[Worst::default(); 2]; 3];
    let mut time = [Duration::ZERO; 3];
    let bar = progress.bar(args.test_draws as u64, "identifying unseen draws");
    let validate = paper_here.n_train + all.start..all.end;
    for d in 0..args.test_draws {
        let theta = draw_theta(truth, trained.config.spread, &mut rng);
        let clean = record(robot, &principal_params_to_standard(model, &theta), designed);
        let noisy = noise_model(args.noise, args.pooled_noise).apply(&clean, args.seed.wrapping_add(d as u64));
        for (r, recording) in [&clean, &noisy].into_iter().enumerate() {
            let (mim, t0) = timed(|| mim::samples(recording, all.clone(), None, &options));
            let mim = mim.map_err(failed)?.theta();
            let (by_paper, t1) = timed(|| paper_here.predict(recording, validate.clone()));
            let by_paper: Vec<Option<f64>> = by_paper.map_err(failed)?.into_iter().map(Some).collect();
            let (by_nim, t2) = timed(|| nim.identify(recording, nim.window / 2));
            let by_nim = by_nim.map_err(failed)?.theta;
            for (m, values) in [mim, by_paper, by_nim].iter().enumerate() {
                worst[m][r].add(values, &theta, identifiable);
            }
            for (slot, t) in time.iter_mut().zip([t0, t1, t2]) {
                *slot += t;
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    println!(
        "\n== side by side: {} parameter draws none of them has seen (θ within ±{}% of nominal), the excitation \
         designed for MIM, {} samples ==",
        args.test_draws,
        100.0 * trained.config.spread,
        all.len()
    );
    println!(
        "worst relative error over every draw and every identifiable mass / principal moment; {}% noise {}",
        100.0 * args.noise,
        if args.pooled_noise {
            "pooled per sensor"
        } else {
            "per curve"
        }
    );
    println!(
        "{:<40}  {:>10}  {:>16}  {:>10}  {:>16}  {:>9}  {:>17}",
        "method", "mass", "moment", "mass", "moment", "training", "per body-sample"
    );
    println!("{:<40}  {:>28}  {:>28}", "", "(noise-free)", "(with noise)");
    let per_sample = |t: Duration, samples: usize| t.as_secs_f64() / (2 * args.test_draws * samples * n) as f64;
    let rows = [
        (
            "MIM (least squares, all samples)".to_string(),
            "—".to_string(),
            per_sample(time[0], all.len()),
        ),
        (
            "paper-faithful NIM (labels: nominal θ)".to_string(),
            format!("{:.2} s", paper_training.as_secs_f64()),
            per_sample(time[1], validate.len()),
        ),
        (
            format!("generalising NIM (windows of {})", nim.window),
            format!("{:.1} s", trained.seconds),
            per_sample(time[2], all.len()),
        ),
    ];
    for (m, (name, training, seconds)) in rows.into_iter().enumerate() {
        let [a, b] = worst[m][0].cells();
        let [c, d] = worst[m][1].cells();
        println!(
            "{name:<40}  {a:>10}  {b:>16}  {c:>10}  {d:>16}  {training:>9}  {:>14.3} µs",
            1e6 * seconds
        );
    }
    println!(
        "(the paper-faithful NIM was trained on the nominal robot, as the paper trains on its one robot: on other \
         parameters it still answers the nominal values. Inference times are wall-clock means over this run; see \
         the benchmarks for measured figures. Paper's experiment, for reference: paper-faithful NIM on its own \
         training robot, largest relative error {:.1}%.)",
        100.0
            * paper
                .theta
                .iter()
                .zip(truth)
                .zip(&paper.identifiable)
                .filter(|(_, &ok)| ok)
                .map(|((v, t), _)| dyngen_identify::relative_error(*v, *t))
                .fold(0.0, f64::max)
    );
    Ok(())
}

/// A payload picked up by the flange mid-motion: NIM and RLS follow the flange's θ.
fn payload(
    args: &Options,
    robot: &dyn Dynamics,
    designed: &Experiment,
    truth: &[f64],
    nim: &Nim,
    figure: Option<&Path>,
    progress: &Progress<'_>,
) -> Result<()> {
    let model = robot.model();
    let n = model.dof();
    let body = n - 1;
    let periods = 4;
    let long = Experiment {
        duration: periods as f64 * designed.duration,
        steps: periods * designed.steps,
        motion: designed.motion.clone(),
    };
    let change = long.steps / 2;
    // A short cylinder of 0.3 kg, radius 4 cm and length 4 cm, coaxial with the
    // flange and centred on its centre of mass (so the change stays within θ).
    let (m, r, l) = (0.3, 0.04, 0.04);
    let before: [f64; 4] = truth[4 * body..4 * body + 4]
        .try_into()
        .map_err(|_| failed("θ has 4 values per body"))?;
    let transverse = m * (3.0 * r * r + l * l) / 12.0;
    let after = [
        before[0] + m,
        before[1] + m * r * r / 2.0,
        before[2] + transverse,
        before[3] + transverse,
    ];
    let mut theta_after = truth.to_vec();
    theta_after[4 * body..4 * body + 4].copy_from_slice(&after);
    let first = record(robot, &principal_params_to_standard(model, truth), &long);
    let second = record(robot, &principal_params_to_standard(model, &theta_after), &long);
    let mut spliced = first;
    spliced.samples[change..].clone_from_slice(&second.samples[change..]);
    let memory = nim.window;
    println!(
        "\n== a payload picked up mid-motion: {} kg on the flange ({}) at t = {} s, {} periods of the designed \
         excitation ==",
        m, model.bodies[body].name, spliced.samples[change].t, periods
    );
    println!(
        "θ of the flange {:?} → {:?}; NIM on the window of the last {} samples; RLS with forgetting λ per equation \
         row (6 per sample), memory 1/(1 − λ) rows",
        before.map(|x| (x * 1e6).round() / 1e6),
        after.map(|x| (x * 1e6).round() / 1e6),
        memory
    );
    println!(
        "settled: the relative error stays within 2% (mass) or 5% (moments) to the end; errors: RMS relative, \
         before the change and over the second half after it"
    );
    println!(
        "{:<34}  {:>10}  {:>12}  {:>20}  {:>20}  {:>12}",
        "estimator", "mass in", "moments in", "before (m, J)", "after (m, J)", "per sample"
    );
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for (noise, label) in [
        (0.0, "noise-free".to_string()),
        (args.noise, format!("{}% noise", 100.0 * args.noise)),
    ] {
        let recording = if noise > 0.0 {
            noise_model(noise, args.pooled_noise).apply(&spliced, args.seed)
        } else {
            spliced.clone()
        };
        for samples in [memory, 5 * memory] {
            let tracking = Tracking {
                body,
                change,
                before,
                after,
                lambda: 1.0 - 1.0 / (6 * samples) as f64,
                tolerance: (0.02, 0.05),
            };
            let (track, [by_nim, by_rls]) = track(nim, &recording, &tracking).map_err(failed)?;
            if samples == memory {
                print_tracking(&format!("NIM, {label}"), &by_nim);
                if noise > 0.0 {
                    curves.push((
                        format!("NIM ({label})"),
                        series(&track.t, track.nim.iter().map(|v| v[0])),
                    ));
                }
            }
            print_tracking(&format!("RLS, memory {samples} samples, {label}"), &by_rls);
            if noise > 0.0 {
                curves.push((
                    format!("RLS, memory {samples} samples ({label})"),
                    series(&track.t, track.rls.iter().map(|v| Some(v[0]))),
                ));
            }
            if curves.len() == 3 {
                curves.push((
                    "true mass".into(),
                    series(&track.t, track.truth.iter().map(|v| Some(v[0]))),
                ));
            }
        }
    }
    write_figure(figure, args.force, || {
        draw(
            progress,
            &LineChart {
                title: "flange mass while a payload is picked up: NIM and recursive least squares",
                x_label: "t (s)",
                y_label: "m (kg)",
                log_y: false,
                curves: &curves,
                reference: None,
                legend: Corner::LowerRight,
            },
        )
    })
}

/// A relative error in percent, in scientific notation when tiny.
fn percent(x: f64) -> String {
    if x < 1e-5 {
        format!("{:.1e}%", 100.0 * x)
    } else {
        format!("{:.3}%", 100.0 * x)
    }
}

fn series(t: &[f64], values: impl Iterator<Item = Option<f64>>) -> Vec<(f64, f64)> {
    t.iter().zip(values).filter_map(|(&t, v)| v.map(|v| (t, v))).collect()
}

fn print_tracking(name: &str, s: &TrackingSummary) {
    let delay = |d: Option<f64>| d.map_or_else(|| "never".to_string(), |d| format!("{d:.2} s"));
    let pair = |(m, j): (f64, f64)| format!("{:.2}%, {:.2}%", 100.0 * m, 100.0 * j);
    println!(
        "{name:<34}  {:>10}  {:>12}  {:>20}  {:>20}  {:>9.2} µs",
        delay(s.delay_mass),
        delay(s.delay_moments),
        pair(s.error_before),
        pair(s.error_after),
        1e6 * s.seconds_per_sample
    );
}

/// MIM's measurements (each body's kinematics and resultant) at a relative level,
/// per curve or pooled per 3-axis sensor.
fn noise_model(level: f64, pooled: bool) -> NoiseModel {
    let model = NoiseModel::mim(level);
    if pooled {
        model
    } else {
        model.per_axis()
    }
}

/// The worst relative error of MIM over all samples, at several noise levels, both
/// noise readings and several seeds, for each experiment; also how many parameters
/// that are identified noise-free were declared not significant.
fn noise_study(
    experiments: &[(&str, &Recording)],
    truth: &[f64],
    all: Range<usize>,
    options: &MimOptions,
) -> Result<()> {
    println!(
        "== noise study: MIM over all {} samples, worst relative error over the identifiable masses and \
         moments, seeds {}..={} ==",
        all.len(),
        STUDY_SEEDS.start,
        STUDY_SEEDS.end - 1
    );
    const WIDTH: usize = 30;
    for (name, clean) in experiments {
        let reference = mim::samples(clean, all.clone(), Some(truth), options).map_err(failed)?;
        let identifiable: Vec<(usize, usize)> = (0..reference.bodies())
            .flat_map(|i| (0..4).map(move |k| (i, k)))
            .filter(|&(i, k)| reference.verdict(i, k) == Verdict::Identified)
            .collect();
        println!("{name} ({} parameters identifiable noise-free):", identifiable.len());
        println!(
            "{:>6}  {:<WIDTH$}  {:<WIDTH$}",
            "noise", "σ per curve", "σ pooled per 3-axis sensor"
        );
        for level in STUDY_LEVELS {
            let mut cells = Vec::new();
            for pooled in [false, true] {
                let mut worst: Option<(f64, usize, usize)> = None;
                let mut not_significant = 0;
                for seed in STUDY_SEEDS {
                    let noisy = noise_model(level, pooled).apply(clean, seed);
                    let est = mim::samples(&noisy, all.clone(), Some(truth), options).map_err(failed)?;
                    for &(i, k) in &identifiable {
                        match est.value(i, k) {
                            Some(v) => {
                                let rel = dyngen_identify::relative_error(v, truth[4 * i + k]);
                                if worst.is_none_or(|(w, _, _)| rel > w) {
                                    worst = Some((rel, i, k));
                                }
                            }
                            None => not_significant += 1,
                        }
                    }
                }
                let mut cell = match worst {
                    Some((w, i, k)) => format!("{:.3}% ({} of {})", 100.0 * w, THETA_NAMES[k], reference.body_names[i]),
                    None => "—".to_string(),
                };
                if not_significant > 0 {
                    cell += &format!(", {not_significant} n/s");
                }
                cells.push(cell);
            }
            println!("{:>5}%  {:<WIDTH$}  {:<WIDTH$}", 100.0 * level, cells[0], cells[1]);
        }
    }
    println!("(n/s: over all seeds, how many identifiable parameters were declared not significant)");
    Ok(())
}
