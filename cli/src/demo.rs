//! `dyngen demo`: the paper reproduction of `dyngen_paper`, with progress bars and
//! the figures drawn as SVG.

use crate::common::{Progress, Result};
use crate::error::CliError;
use clap::Args;
use dyngen_identify::report as svg;
use dyngen_paper::{Hooks, LineChart, PaperError};
use indicatif::ProgressBar;
use std::path::PathBuf;
use std::sync::Mutex;

pub use dyngen_paper::EXAMPLES;

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Relative sensor noise of the noisy runs (0.01 is 1 %); see the noise model
    /// below; 0 to 1.
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true, value_parser = crate::ranges::NOISE)]
    pub noise: f64,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// One σ per 3-axis sensor (pooled over its axes) instead of one per curve.
    #[arg(long)]
    pub pooled_noise: bool,
    /// Write the figures (the paper's Fig. 5, the NIM training curves, the payload
    /// tracking) as SVG files into this directory, created if missing.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Replace figures that already exist in --out.
    #[arg(long)]
    pub force: bool,
    /// Generalising NIM: parameter draws to train on, 1 to 10000000.
    #[arg(long, default_value_t = 1500, value_parser = crate::ranges::DRAWS)]
    pub draws: usize,
    /// Generalising NIM: Adam steps per body, 1 to 100000000.
    #[arg(long, default_value_t = 6000, value_parser = crate::ranges::ADAM_STEPS)]
    pub steps: usize,
    /// Unseen parameter draws for the side-by-side comparison, 1 to 1000000.
    #[arg(long, default_value_t = 100, value_parser = crate::ranges::DEMO_TEST_DRAWS)]
    pub test_draws: usize,
    /// Bodies trained at once, 0 to 1024; 0 = one per core.
    #[arg(long, default_value_t = 0, value_parser = crate::ranges::THREADS)]
    pub threads: usize,
}

/// Progress bars and SVG figures for the reproduction.
struct Terminal<'a> {
    progress: &'a Progress,
    current: Mutex<Option<ProgressBar>>,
}

impl Hooks for Terminal<'_> {
    fn begin(&self, message: &str, steps: Option<u64>) {
        let bar = match steps {
            Some(len) => self.progress.bar(len, message),
            None => self.progress.spinner(message),
        };
        if let Ok(mut current) = self.current.lock() {
            *current = Some(bar);
        }
    }

    fn advance(&self) {
        if let Ok(current) = self.current.lock() {
            if let Some(bar) = current.as_ref() {
                bar.inc(1);
            }
        }
    }

    fn end(&self) {
        if let Ok(mut current) = self.current.lock() {
            if let Some(bar) = current.take() {
                bar.finish_and_clear();
            }
        }
    }

    fn draws(&self) -> bool {
        true
    }

    fn draw(&self, chart: &LineChart<'_>) -> Option<std::result::Result<String, String>> {
        Some(svg::svg_lines(chart).map_err(|e| e.to_string()))
    }
}

pub fn run(args: &DemoArgs, progress: &Progress) -> Result<()> {
    let options = dyngen_paper::Options {
        noise: args.noise,
        seed: args.seed,
        pooled_noise: args.pooled_noise,
        out: args.out.clone(),
        force: args.force,
        draws: args.draws,
        steps: args.steps,
        test_draws: args.test_draws,
        threads: args.threads,
    };
    let terminal = Terminal {
        progress,
        current: Mutex::new(None),
    };
    dyngen_paper::run(&options, &terminal).map_err(|e| match e {
        PaperError::InvalidOption { option, reason } => {
            let flags: Vec<String> = option
                .split(" and ")
                .map(|o| format!("--{}", o.replace('_', "-")))
                .collect();
            CliError::usage(format!("{} {reason}", flags.join(" and ")))
        }
        PaperError::FigureExists(path) => CliError::OutputExists(path),
        e @ PaperError::Output { .. } => CliError::Output(e.to_string()),
        PaperError::Failed(message) => CliError::Failed(message),
    })
}
