//! `dyngen demo`: the paper's experiment on its 6-DOF manipulator (paper6), identified
//! by MIM: the paper's Tables 2–3 from the single instant t = 1.5 s and from all
//! samples, noise-free and with sensor noise; an excitation designed for MIM; and a
//! noise study on both experiments.

use crate::common::{Progress, Result};
use clap::Args;
use dyngen::dynamics::{Dynamics, Generated};
use dyngen::mim::{self, MimOptions, Verdict, THETA_NAMES};
use dyngen::simulate::{moment_sigma, record, Criterion, ExcitationDesign, Experiment, Motion, NoiseModel, Recording};
use robot_paper6::Paper6;
use std::ops::Range;

pub const EXAMPLES: &str = "\
Examples:
  dyngen demo
  dyngen demo --noise 0.02 --seed 7
  dyngen demo --pooled-noise

Noise: σ of every measured curve (each axis of each body's Cardano angles and
rates, angular velocity and acceleration, centre-of-mass acceleration and
resultant force and moment) is --noise times that curve's RMS over the recording;
with --pooled-noise the three axes of one sensor share one σ, --noise times the RMS
over all three (an axis that barely moves then gets the noise of the busiest one).";

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Relative sensor noise of the noisy runs (0.01 is 1 %); see the noise model
    /// below.
    #[arg(long, default_value_t = 0.01)]
    pub noise: f64,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// One σ per 3-axis sensor (pooled over its axes) instead of one per curve.
    #[arg(long)]
    pub pooled_noise: bool,
}

/// Seeds of the noise study: the worst case over several draws, so no number rests
/// on one lucky draw.
const STUDY_SEEDS: Range<u64> = 1..6;
const STUDY_LEVELS: [f64; 3] = [0.001, 0.01, 0.05];

pub fn run(args: &DemoArgs, progress: &Progress) -> Result<()> {
    if !(args.noise.is_finite() && args.noise >= 0.0) {
        return Err(format!("--noise {} is not a non-negative number", args.noise));
    }
    let robot = Generated::<Paper6>::new();
    let model = robot.model().clone();
    let experiment = Experiment::paper(&model);
    let spinner = progress.spinner("simulating the paper's experiment on paper6 (2 s, 100 steps)");
    let clean = record(&robot, &Paper6::NOMINAL_PARAMS, &experiment);
    spinner.finish_and_clear();
    let truth = mim::true_theta(&model);
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
        let instant = mim::instant(recording, 1.5, Some(&truth), &options).map_err(|e| e.to_string())?;
        println!("{instant}");
        println!("== {title}, least squares over all samples ==");
        let samples = mim::samples(recording, all.clone(), Some(&truth), &options).map_err(|e| e.to_string())?;
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
    let designed = with_spinner_result(progress, "optimising an excitation for MIM", || {
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
        all,
        &options,
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

fn with_spinner_result<T>(progress: &Progress, message: &str, f: impl FnOnce() -> T) -> T {
    let spinner = progress.spinner(message);
    let out = f();
    spinner.finish_and_clear();
    out
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
        let reference = mim::samples(clean, all.clone(), Some(truth), options).map_err(|e| e.to_string())?;
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
                    let est = mim::samples(&noisy, all.clone(), Some(truth), options).map_err(|e| e.to_string())?;
                    for &(i, k) in &identifiable {
                        match est.value(i, k) {
                            Some(v) => {
                                let rel = ((v - truth[4 * i + k]) / truth[4 * i + k]).abs();
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
