//! `dyngen demo`: the paper's experiment on its 6-DOF manipulator (paper6), identified
//! by MIM: the paper's Tables 2–3 from the single instant t = 1.5 s and from all
//! samples, noise-free and with sensor noise.

use crate::common::{Progress, Result};
use clap::Args;
use dyngen::dynamics::{Dynamics, Generated};
use dyngen::mim::{self, MimOptions};
use dyngen::simulate::{record, Experiment, NoiseModel};
use robot_paper6::Paper6;

pub const EXAMPLES: &str = "\
Examples:
  dyngen demo
  dyngen demo --noise 0.02 --seed 7";

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Relative sensor noise of the noisy run: σ of each sensor channel as a fraction
    /// of that channel's RMS over the recording.
    #[arg(long, default_value_t = 0.01)]
    pub noise: f64,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

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
    println!("== noise-free, single instant t = 1.5 s (the paper's Tables 2 and 3) ==");
    println!(
        "{}",
        mim::instant(&clean, 1.5, Some(&truth), &options).map_err(|e| e.to_string())?
    );
    println!("== noise-free, least squares over all samples ==");
    println!(
        "{}",
        mim::samples(&clean, all.clone(), Some(&truth), &options).map_err(|e| e.to_string())?
    );

    let noisy = NoiseModel::relative(args.noise).apply(&clean, args.seed);
    println!(
        "== {}% sensor noise (every channel, seed {}), single instant t = 1.5 s ==",
        100.0 * args.noise,
        args.seed
    );
    println!(
        "{}",
        mim::instant(&noisy, 1.5, Some(&truth), &options).map_err(|e| e.to_string())?
    );
    println!(
        "== {}% sensor noise, least squares over all samples ==",
        100.0 * args.noise
    );
    println!(
        "{}",
        mim::samples(&noisy, all, Some(&truth), &options).map_err(|e| e.to_string())?
    );
    Ok(())
}
