//! `dyngen validate`: predicts a recording's joint torques with identified parameters
//! (the JSON `identify --params-json` writes) and reports the errors per joint and
//! overall, optionally as an SVG of measured against predicted torque.

use crate::common::{check_overwrite, load_moving_model, Progress, Result};
use crate::error::CliError;
use crate::identify::{pipeline_error, RecordingArgs};
use dyngen_identify::data::Trajectory;
use dyngen_identify::pipeline;
use dyngen_identify::report::{self, ParameterReport};
use dyngen_identify::validate::Validation;
use dyngen_model::Model;
use dyngen_reference::Reference;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction auto --params-json ur5.json
  dyngen validate robots/ur5/ur5.urdf ur5.json run2.csv --svg run2.svg

The parameters must come from --mode standard or principal (they predict through
the regressor and its full solution vector, which the JSON holds); the recording is
read as `identify` reads it (same recipe flags). Relative errors are
‖τ̂ − τ‖ / ‖τ‖ per joint and over all joints; a joint at or above 100 % is predicted no
better than by zero torque.";

#[derive(Debug, clap::Args)]
pub struct ValidateArgs {
    /// The robot description (URDF, or MJCF as `.xml`) the parameters were identified for.
    pub urdf: PathBuf,
    /// The identified parameters (JSON from `dyngen identify --params-json`).
    pub params: PathBuf,
    /// The recording to predict.
    pub data: PathBuf,

    #[command(flatten)]
    pub recording: RecordingArgs,

    /// Write measured against predicted torque per joint as SVG.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,

    /// Replace an existing SVG.
    #[arg(long)]
    pub force: bool,
}

/// The errors of `predicted` against `data`'s torques, named by the model's joints.
pub fn validation(model: &Model, data: &Trajectory, predicted: &[Vec<f64>]) -> Result<Validation> {
    let names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    Validation::new(
        &names,
        (0..data.len()).map(|k| data.tau(k)),
        predicted.iter().map(|p| &p[..]),
    )
    .map_err(CliError::failed)
}

pub fn run(args: &ValidateArgs, _progress: &Progress) -> Result<()> {
    if let Some(svg) = &args.svg {
        check_overwrite(svg, args.force)?;
    }
    let model = load_moving_model(&args.urdf, &args.recording.gravity)?;
    let text = std::fs::read_to_string(&args.params).map_err(|e| CliError::input(&args.params, e))?;
    let params = ParameterReport::from_json(&text).map_err(|e| CliError::input(&args.params, e))?;
    let prediction = params.prediction.as_ref().ok_or_else(|| {
        CliError::input(
            &args.params,
            "holds no prediction model (parameters from --mode mim or NIM predict by inverse dynamics; \
             identify with --mode standard or principal to validate)",
        )
    })?;
    if params.robot != model.name {
        println!(
            "note: the parameters were identified for `{}`, the URDF describes `{}`",
            params.robot, model.name
        );
    }
    let data = args.recording.load(&args.data, model.dof())?;
    let robot = Reference::new(&model);
    let predicted = pipeline::predict_with(prediction, &robot, &data).map_err(|e| match e {
        pipeline::PipelineError::InvalidOption { reason, .. } => CliError::input(&args.params, reason),
        e => pipeline_error(&args.data, e),
    })?;
    let validation = validation(&model, &data, &predicted)?;
    println!("{validation}");
    if let Some(path) = &args.svg {
        let measured: Vec<Vec<f64>> = (0..data.len()).map(|k| data.tau(k).to_vec()).collect();
        let joints: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        let title = format!(
            "{}: {} predicting {} ({:.2} % overall)",
            model.name,
            params.method,
            args.data.display(),
            100.0 * validation.overall
        );
        let svg = crate::svg::svg_report(&title, data.t(), &measured, &predicted, &joints, None)
            .map_err(|e| CliError::report(path, e))?;
        report::write_report(path, &svg, args.force).map_err(|e| CliError::report(path, e))?;
        println!("wrote the SVG to {}", path.display());
    }
    Ok(())
}
