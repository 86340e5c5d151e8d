//! `dyngen validate`: predicts a recording's joint torques with identified parameters
//! (the JSON `identify --params-json` writes) and reports the errors per joint and
//! overall, optionally as an SVG of measured against predicted torque.

use crate::common::{check_overwrite, load_moving_model, outln, ModelArgs, Progress, Result};
use crate::error::CliError;
use crate::identify::{load_recording, pipeline_error, RecordingArgs, DEFAULT_CUTOFF_HZ};
use dyngen_identify::data::{Recipe, Trajectory};
use dyngen_identify::pipeline;
use dyngen_identify::report::{self, ParameterReport};
use dyngen_identify::validate::Validation;
use dyngen_model::Model;
use dyngen_nim::residual::ResidualNet;
use dyngen_reference::Reference;
use std::path::{Path, PathBuf};

pub const EXAMPLES: &str = "\
Examples:
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction auto --params-json ur5.json
  dyngen validate robots/ur5/ur5.urdf ur5.json run2.csv --svg run2.svg

The parameters must come from --mode standard or principal (they predict through
the regressor and its full solution vector, which the JSON holds); the recording is
read as the parameters file records it was identified from (cutoff, recipe without
the training window, gravity: printed as `preprocessing from FILE: …`); a flag given
here overrides the recorded choice, and says so. Relative errors are
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

    /// Add the learned residual that `dyngen identify --residual FILE` wrote to
    /// the parameters' prediction.
    #[arg(long, value_name = "FILE")]
    pub residual: Option<PathBuf>,

    /// Replace an existing SVG.
    #[arg(long)]
    pub force: bool,
}

/// The errors of `predicted` against `data`'s torques, named by the model's joints.
/// A prediction or an error that is not finite (parameters so large that the torques
/// or their squares overflow) is refused, as bad input in `params` when given (the
/// parameters file), as a failed computation otherwise.
pub fn validation(
    model: &Model,
    data: &Trajectory,
    predicted: &[Vec<f64>],
    params: Option<&Path>,
) -> Result<Validation> {
    let names: Vec<String> = model.own_joints().map(|j| j.name.clone()).collect();
    let overflow = |message: String| match params {
        Some(path) => CliError::input(path, message),
        None => CliError::failed(message),
    };
    for (k, row) in predicted.iter().enumerate() {
        if let Some(j) = row.iter().position(|x| !x.is_finite()) {
            return Err(overflow(format!(
                "the predicted torque of joint `{}` at sample {k} is {}; the parameters are too large for a finite \
                 prediction",
                names.get(j).map_or("?", String::as_str),
                row[j]
            )));
        }
    }
    let v = Validation::new(
        &names,
        (0..data.len()).map(|k| data.tau(k)),
        predicted.iter().map(|p| &p[..]),
    )
    .map_err(CliError::failed)?;
    let metrics = v.rms.iter().chain(&v.relative).chain([&v.overall]);
    if let Some(x) = metrics.into_iter().find(|x| !x.is_finite()) {
        return Err(overflow(format!(
            "the prediction errors overflow ({x}): the predicted torques are finite but too large to compare (the \
             parameters are absurdly large)"
        )));
    }
    Ok(v)
}

/// The overall relative error to full precision, for comparing two runs exactly.
/// `predicted` (one row per sample of `data`) plus the residual network's torques;
/// `path` names the recording in errors.
pub fn with_residual(
    net: &ResidualNet,
    data: &Trajectory,
    mut predicted: Vec<Vec<f64>>,
    path: &Path,
) -> Result<Vec<Vec<f64>>> {
    let residual = net.predict_all(data).map_err(|e| CliError::input(path, e))?;
    for (row, r) in predicted.iter_mut().zip(&residual) {
        for (p, r) in row.iter_mut().zip(r) {
            *p += r;
        }
    }
    Ok(predicted)
}

pub fn exact_overall(v: &Validation) -> String {
    format!("(as a fraction, full precision: {:?})", v.overall)
}

/// Refuses parameters identified for another robot: their joints (the residual
/// channels of the JSON) must be the robot's, in order.
fn check_joints(params: &ParameterReport, model: &Model, path: &Path) -> Result<()> {
    let joints: Vec<&str> = model.own_joints().map(|j| j.name.as_str()).collect();
    let theirs: Vec<&str> = params.channels.iter().map(String::as_str).collect();
    if theirs.is_empty() || theirs == joints {
        return Ok(());
    }
    let missing: Vec<&str> = joints.iter().copied().filter(|j| !theirs.contains(j)).collect();
    let extra: Vec<&str> = theirs.iter().copied().filter(|j| !joints.contains(j)).collect();
    let mut differences = Vec::new();
    if theirs.len() != joints.len() {
        differences.push(format!("{} joints instead of {}", theirs.len(), joints.len()));
    }
    if !extra.is_empty() {
        differences.push(format!("joints the robot does not have: {}", extra.join(", ")));
    }
    if !missing.is_empty() {
        differences.push(format!("robot joints it lacks: {}", missing.join(", ")));
    }
    if missing.is_empty() && extra.is_empty() {
        differences.push(format!("the joints in another order: [{}]", theirs.join(", ")));
    }
    Err(CliError::input(
        path,
        format!(
            "the parameters were identified for `{}` with joints [{}], but robot `{}` has joints [{}]: {}; identify \
             this robot's parameters with `dyngen identify --params-json`",
            params.robot,
            theirs.join(", "),
            model.name,
            joints.join(", "),
            differences.join("; ")
        ),
    ))
}

/// Reads the parameters JSON, at most [`MAX_PARAMS_BYTES`].
fn read_params(path: &Path) -> Result<ParameterReport> {
    use std::io::Read;
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_PARAMS_BYTES + 1).read_to_string(&mut text))
        .map_err(|e| CliError::input(path, e))?;
    if text.len() as u64 > MAX_PARAMS_BYTES {
        return Err(CliError::input(
            path,
            format!("larger than {MAX_PARAMS_BYTES} bytes (256 MiB); not a parameters file dyngen wrote"),
        ));
    }
    ParameterReport::from_json(&text).map_err(|e| CliError::input(path, e))
}

/// Largest parameters JSON read: a few kB in practice.
const MAX_PARAMS_BYTES: u64 = 1 << 28;

/// How to read and filter the recording: the parameters file's preprocessing, each
/// choice overridden by a flag given on the command line; prints which applies.
struct Reading {
    recipe: Recipe,
    cutoff: f64,
    low_pass_states: bool,
    gravity: ModelArgs,
}

fn reading(args: &ValidateArgs, params: &ParameterReport) -> Result<Reading> {
    let file = args.params.display().to_string();
    let flags = &args.recording;
    let pre = params.prediction.as_ref().and_then(|p| p.preprocessing.as_ref());
    let mut said = Vec::new();
    let mut overrides = Vec::new();
    let stored_recipe = match pre.and_then(|p| p.recipe.as_deref()) {
        Some(text) => Some(Recipe::parse(text).map_err(|e| CliError::input(&args.params, format!("its recipe: {e}")))?),
        None => None,
    };
    match (pre.and_then(|p| p.cutoff_hz), flags.cutoff) {
        (Some(c), None) => said.push(format!("cutoff {c} Hz")),
        (Some(c), Some(f)) if c != f => overrides.push(format!("--cutoff {f} Hz instead of its {c} Hz")),
        _ => {}
    }
    let stored_low_pass = pre.and_then(|p| p.low_pass_states);
    match (stored_low_pass, flags.raw_states) {
        (Some(true), true) => overrides.push("--raw-states instead of its low-passed positions and velocities".into()),
        (Some(true), false) => said.push("positions and velocities low-passed".into()),
        (Some(false), _) => said.push("positions and velocities as read (raw)".into()),
        (None, _) => {}
    }
    if let Some(text) = pre.and_then(|p| p.recipe.as_deref()) {
        let lines = text.trim_end().replace('\n', "; ");
        let lines = if lines.is_empty() {
            "the default CSV schema".to_string()
        } else {
            lines
        };
        match &flags.recipe.recipe {
            Some(path) => overrides.push(format!("--recipe {} instead of its recipe ({lines})", path.display())),
            None => said.push(format!("recipe: {lines}")),
        }
    }
    let given = flags.recipe.flags_given();
    if pre.is_some() && !given.is_empty() {
        overrides.push(format!("{} on top of the recipe", given.join(", ")));
    }
    if let Some(window) = pre.and_then(|p| p.window.as_deref()) {
        said.push(format!("its training window ({window}) not applied"));
    }
    if let Some(f) = pre.and_then(|p| p.friction.as_deref()) {
        let per_joint = pre.and_then(|p| p.coulomb_epsilons.as_ref());
        let epsilon = match (
            pre.and_then(|p| p.coulomb_epsilon),
            per_joint,
            pre.and_then(|p| p.epsilon_auto),
        ) {
            (_, Some(e), _) => format!(
                " (ε per joint {} chosen by the fit)",
                e.iter().map(|e| format!("{e:e}")).collect::<Vec<_>>().join(", ")
            ),
            (Some(e), _, Some(true)) => format!(" (ε = {e:e} chosen by the fit)"),
            (Some(e), _, _) => format!(" (ε = {e:e})"),
            _ => String::new(),
        };
        said.push(format!("friction {f}{epsilon}"));
    }
    let mut gravity = flags.gravity.clone();
    match (pre.and_then(|p| p.gravity), &flags.gravity.gravity) {
        (Some(g), None) => {
            said.push(format!("gravity {} {} {}", g[0], g[1], g[2]));
            gravity.gravity = Some(g.to_vec());
        }
        (Some(g), Some(f)) if f[..] != g[..] => overrides.push(format!(
            "--gravity {} instead of its {} {} {}",
            f.iter().map(f64::to_string).collect::<Vec<_>>().join(" "),
            g[0],
            g[1],
            g[2]
        )),
        _ => {}
    }
    match pre {
        Some(_) => outln!("preprocessing from {file}: {}", said.join(", ")),
        None => outln!(
            "note: {file} records no preprocessing (written by an older dyngen): reading the recording with the \
             defaults and the flags given (cutoff {} Hz{})",
            flags.cutoff(),
            if flags.raw_states {
                ", raw states"
            } else {
                ", positions and velocities low-passed"
            }
        ),
    }
    if !overrides.is_empty() {
        outln!("overriding {file} from the command line: {}", overrides.join("; "));
    }
    Ok(Reading {
        recipe: flags.recipe.recipe_over(stored_recipe)?,
        cutoff: flags
            .cutoff
            .or(pre.and_then(|p| p.cutoff_hz))
            .unwrap_or(DEFAULT_CUTOFF_HZ),
        low_pass_states: !flags.raw_states && stored_low_pass.unwrap_or(true),
        gravity,
    })
}

pub fn run(args: &ValidateArgs, _progress: &Progress) -> Result<()> {
    if let Some(svg) = &args.svg {
        check_overwrite(svg, args.force)?;
    }
    // Read first: its recorded preprocessing (gravity among it) says how to load the rest.
    let params = read_params(&args.params)?;
    let reading = reading(args, &params)?;
    let model = load_moving_model(&args.urdf, &reading.gravity)?;
    let prediction = params.prediction.as_ref().ok_or_else(|| {
        CliError::input(
            &args.params,
            "holds no prediction model (parameters from --mode mim or NIM predict by inverse dynamics; \
             identify with --mode standard or principal to validate)",
        )
    })?;
    check_joints(&params, &model, &args.params)?;
    if params.robot != model.name {
        outln!(
            "note: the parameters were identified for `{}`, the URDF describes `{}` (with the same joints)",
            params.robot,
            model.name
        );
    }
    let data = load_recording(
        &args.data,
        &reading.recipe,
        model.nv(),
        reading.cutoff,
        reading.low_pass_states,
    )?;
    let robot = Reference::new(&model);
    let predicted = pipeline::predict_with(prediction, &robot, &data).map_err(|e| match e {
        pipeline::PipelineError::InvalidOption { reason, .. } => CliError::input(&args.params, reason),
        e => pipeline_error(&args.data, e),
    })?;
    let predicted = match &args.residual {
        None => predicted,
        Some(path) => {
            let net = ResidualNet::load(path, model.nv()).map_err(|e| CliError::input(path, e))?;
            outln!("with the learned residual of {}", path.display());
            with_residual(&net, &data, predicted, &args.data)?
        }
    };
    let validation = validation(&model, &data, &predicted, Some(&args.params))?;
    outln!("{validation}\n{}", exact_overall(&validation));
    if let Some(path) = &args.svg {
        let title = format!(
            "{}: {} predicting {} ({:.2} % overall)",
            model.name,
            params.method,
            args.data.display(),
            100.0 * validation.overall
        );
        let svg = report::trajectory_report(&title, &model, &data, &predicted, None)
            .map_err(|e| CliError::report(path, e))?;
        report::write_report(path, &svg, args.force).map_err(|e| CliError::report(path, e))?;
        outln!("wrote the SVG to {}", path.display());
    }
    Ok(())
}
