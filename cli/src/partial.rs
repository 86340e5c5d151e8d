//! `dyngen identify --partial` and `--merge`: one recording's partial factor, and
//! the identification from many (dyngen_identify::partial).

use crate::common::{check_overwrite, load_moving_model, outln, with_spinner, Progress, Result};
use crate::error::CliError;
use crate::identify::{
    check_outputs, load_recording, pipeline_error, print_identification, write_outputs, IdentifyArgs, DEFAULT_LAMBDA,
};
use dyngen_identify::partial::{self, Partial, PartialError};
use dyngen_identify::report::{self, DataSpan};
use dyngen_reference::Reference;
use std::path::Path;

/// Refuses the flags that do not apply: those of the estimate when only a partial
/// is written, the recipe when partials are merged (it was applied when they were
/// written), and those that need a recording's samples.
fn check_flags(args: &IdentifyArgs) -> Result<()> {
    let writing = args.partial.is_some();
    let merging = !args.merge.is_empty();
    let to_merge_run = "give it to the run that merges the partials: dyngen identify ROBOT --merge PART… ";
    let needs_samples = "it needs a recording's samples, which partial factors do not keep; predict or plot a \
                         recording with the merged result: dyngen identify ROBOT --merge PART… --params-json P.json, \
                         then dyngen validate ROBOT P.json RUN.csv [--svg FILE]";
    let mut refused: Vec<(&str, String)> = Vec::new();
    if args.validate.is_some() {
        refused.push((
            "--validate",
            format!("it predicts a recording with the estimate: {needs_samples}"),
        ));
    }
    if args.svg.is_some() {
        refused.push(("--svg", format!("it plots the recording's torques: {needs_samples}")));
    }
    if args.gear_ratios.is_some() {
        refused.push((
            "--gear-ratios",
            "it serves --extra-terms motor-ripple, which partial factors cannot carry (a partial does not keep the \
             gear ratios); identify from one recording"
                .into(),
        ));
    }
    if writing {
        let no_estimate = |what: &str| format!("it {what}, which --partial does not make; {to_merge_run}");
        if args.method.is_some() {
            refused.push(("--method", no_estimate("chooses the estimator of the estimate")));
        }
        if args.lambda != DEFAULT_LAMBDA {
            refused.push(("--lambda", no_estimate("weighs the ridge estimate")));
        }
        for (flag, given) in [
            ("--params-json", args.params_json.is_some()),
            ("--urdf-out", args.urdf_out.is_some()),
            ("--lump-merged", args.lump_merged),
            ("--truth-from-urdf", args.truth_from_urdf),
        ] {
            if given {
                refused.push((flag, no_estimate("writes or judges the estimate")));
            }
        }
    }
    if merging {
        let mut recipe = args.recording.recipe.flags_given();
        if args.recording.recipe.recipe.is_some() {
            recipe.insert(0, "--recipe");
        }
        for flag in recipe {
            refused.push((
                flag,
                "it says how to read a recording; partials were read when they were written, and their recipe is \
                 used (give it to `dyngen identify ROBOT DATA --partial OUT`)"
                    .to_string(),
            ));
        }
    }
    match refused.into_iter().next() {
        Some((flag, why)) => Err(CliError::usage(format!(
            "{flag} does not apply with {}: {why}",
            if merging { "--merge" } else { "--partial" }
        ))),
        None => Ok(()),
    }
}

/// Reads the partial factor file at `path`.
pub fn read_partial(path: &Path) -> Result<Partial> {
    let text = std::fs::read_to_string(path).map_err(|e| CliError::input(path, e))?;
    Partial::from_json(&text).map_err(|e| CliError::input(path, e))
}

pub fn run(args: &IdentifyArgs, progress: &Progress) -> Result<()> {
    check_flags(args)?;
    let given = args.options();
    check_outputs(args)?;
    if let Some(out) = &args.partial {
        check_overwrite(out, args.force)?;
        if args.merge.contains(out) {
            return Err(CliError::usage(format!(
                "--partial {} is also one of the --merge inputs; write the merged partial to a new file",
                out.display()
            )));
        }
    }
    let model = load_moving_model(&args.urdf, &args.recording.gravity)?;
    let robot = Reference::new(&model);
    let (merged, source) = match args.data.as_deref() {
        Some(data) if args.merge.is_empty() => {
            given.check().map_err(|e| pipeline_error(data, e))?;
            partial::check_options(&given).map_err(|e| pipeline_error(data, e))?;
            let recipe = args.recording.recipe.recipe()?;
            let traj = load_recording(
                data,
                &recipe,
                model.nv(),
                args.recording.cutoff(),
                !args.recording.raw_states,
            )?;
            let part = with_spinner(progress, "accumulating", || {
                Partial::from_trajectory(&robot, &traj, &given, &recipe, DataSpan::of(data, &traj))
            })
            .map_err(|e| pipeline_error(data, e))?;
            (part, data)
        }
        _ => {
            let parts = args.merge.iter().map(|p| read_partial(p)).collect::<Result<Vec<_>>>()?;
            let labels: Vec<String> = args.merge.iter().map(|p| p.display().to_string()).collect();
            let merged =
                with_spinner(progress, "merging", || partial::merge_all(&parts, &labels)).map_err(CliError::Input)?;
            (merged, args.merge[0].as_path())
        }
    };
    let samples: usize = merged.recordings.iter().map(|r| r.samples).sum();
    let rows: usize = merged.accumulator.per_channel.iter().map(|c| c.rows).sum();
    outln!(
        "{} recording{} ({samples} samples, {rows} torque rows) of {} with {} parameters",
        merged.recordings.len(),
        if merged.recordings.len() == 1 { "" } else { "s" },
        model.name,
        merged.robot.parameters.len()
    );
    if let Some(out) = &args.partial {
        let text = merged.to_json().map_err(CliError::failed)?;
        report::write_new(out, &text, args.force).map_err(|e| CliError::report(out, e))?;
        outln!("wrote the partial factor to {}", out.display());
        return Ok(());
    }
    let options = merged.options_with(&given).map_err(|e| option_error(e, &merged))?;
    let identified =
        with_spinner(progress, "identifying", || merged.identify(&robot, &options)).map_err(|e| match e {
            PartialError::Mismatch { what, ours, theirs } => CliError::input(
                &args.urdf,
                format!(
                    "not the robot the partials were made for: different {what}: the partials' {ours} against this \
                     {theirs}"
                ),
            ),
            PartialError::Pipeline(e) => pipeline_error(source, e),
            e => CliError::input(source, e),
        })?;
    let mut identified = identified;
    if let Some(pre) = identified
        .report
        .prediction
        .as_mut()
        .and_then(|p| p.preprocessing.as_mut())
    {
        pre.gravity = args.recording.gravity.get()?;
    }
    for w in &identified.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(speed) = options.exclude_below {
        let total: usize = identified.excluded_rows.iter().sum();
        outln!(
            "--exclude-below {speed}: left out {total} of {} torque rows",
            rows + total
        );
    }
    print_identification(args, &model, &identified, None)?;
    write_outputs(args, source, &model, &identified)
}

/// A command-line option that contradicts the partials.
fn option_error(e: PartialError, merged: &Partial) -> CliError {
    match e {
        PartialError::Mismatch { what, ours, theirs } => CliError::usage(format!(
            "--{what}: the partials were made with {ours}, the command line gives {theirs}; the options that shape \
             the rows are fixed when a partial is written: leave --{what} out to use the partials' (or write the \
             partials again with it)"
        )),
        PartialError::Pipeline(e) => {
            pipeline_error(Path::new(&merged.recordings.first().map_or("", |r| r.file.as_str())), e)
        }
        e => CliError::failed(e),
    }
}
