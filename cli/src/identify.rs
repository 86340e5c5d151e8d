//! `dyngen identify`: inertial parameters from measured data: the standard or the
//! principal parameters from joint torques, or the principal parameters of every body
//! by MIM from joint wrenches.

use crate::common::{check_overwrite, load_moving_model, GravityArg, Progress, Result};
use dyngen_identify::data::{Recipe, Trajectory};
use dyngen_identify::mim::{self, MimEstimate, MimOptions};
use dyngen_identify::report::{self, MergedLinks, ParamStatus, ParameterReport, Parameterisation, ReportError};
use dyngen_identify::simulate::Recording;
use dyngen_identify::{Accumulation, Accumulator, Channels, Estimate, Options};
use dyngen_model::names::standard_param_names;
use dyngen_model::{ErrorKind, Inertial, Model};
use dyngen_reference::Dynamics;
use dyngen_reference::Reference;
use std::path::{Path, PathBuf};

pub const EXAMPLES: &str = "\
Examples:
  dyngen simulate robots/ur5/ur5.urdf -o ur5.csv --experiment fourier
  dyngen identify robots/ur5/ur5.urdf ur5.csv
  dyngen identify robots/ur5/ur5.urdf measured.csv --method wls --cutoff 15
  dyngen identify robots/ur5/ur5.urdf measured.csv --method ridge --lambda 1e-3
  dyngen identify robots/ur5/ur5.urdf ur5.csv --params-json ur5.json --svg ur5.svg \\
      --truth-from-urdf --urdf-out ur5-identified.urdf --force
  dyngen identify robots/ur5/ur5.urdf ur5.csv --mode principal
  dyngen identify robots/ur5/ur5.urdf ur5.csv --mode mim --urdf-out ur5-mim.urdf

The CSV needs t, q1..qn and tau1..taun; v and a are estimated from q (zero-phase
low-pass at --cutoff Hz, then central differences) when the file does not have them.
Other layouts (no header, other names and order, semicolons, degrees, motor
currents, sign flips, time in ms) are read through a recipe file (--recipe) or the
flags for the common cases; duplicate time stamps are dropped and counted, irregular
ones used as they are or resampled (--resample), and a summary says what was
measured and what estimated:
  dyngen identify robots/ur5/ur5.urdf robot.log --recipe docs/example.recipe
  dyngen identify robots/ur5/ur5.urdf log.csv --no-header --delimiter semicolon \\
      --degrees --gains 0.11,0.11,0.11,0.05,0.05,0.05 --window 5:65 --resample 0.01
--mode mim also needs the joint wrench columns fx1, fy1, fz1, mx1, my1, mz1, … (what
`dyngen simulate` writes).

Modes: standard (default) identifies the 10 standard parameters per body from the
joint torques; principal the paper's θ = (m, J1, J2, J3) per body (centre of mass and
principal axes taken from the URDF) from the joint torques; mim the same θ body by
body from the joint wrenches (the paper's MIM), where every θ that enters a body's
equations is identifiable. Parameters the data cannot determine are shown as — (or
n/i), with the identifiable combinations they enter.

--params-json writes the estimate as JSON (schema dyngen-parameters/1).
--truth-from-urdf takes the URDF's inertials as the truth and prints each
parameter's error; with --svg it also plots them.
--svg plots measured against predicted torques per joint (mim: torques of the
identified model by inverse dynamics; a θ that is not identified keeps the URDF's).
--urdf-out writes the URDF with the identified inertial of every body whose
parameters (10, or θ with the URDF's centre of mass and axes) are all identified and
physically valid; the other bodies keep their URDF inertials. From joint torques
usually few bodies, if any, are fully identifiable; by MIM usually all.
Existing files are kept unless --force.";

/// What is identified, from what.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// The 10 standard parameters per body from the joint torques.
    Standard,
    /// θ = (m, J1, J2, J3) per body from the joint torques (principal regressor).
    Principal,
    /// θ per body from the joint wrenches, body by body (the paper's MIM).
    Mim,
}

/// How the rows are compressed (dyngen_identify::Accumulation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AccumulationArg {
    Qr,
    NormalEquations,
}

/// The estimator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Ordinary least squares.
    Ols,
    /// Weighted least squares, one noise variance per joint (Gautier).
    Wls,
    /// Total least squares (noise on the regressor too).
    Tls,
    /// Ridge regression toward the URDF's nominal parameters (weight --lambda).
    Ridge,
}

#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {
    /// The robot description (URDF); its inertials are the nominal parameters.
    pub urdf: PathBuf,

    /// Measured data (CSV: t, q1..qn[, v1..vn, a1..an], tau1..taun[, wrenches]).
    pub data: PathBuf,

    /// What to identify, from what.
    #[arg(long, value_enum, default_value_t = Mode::Standard)]
    pub mode: Mode,

    /// The estimator of --mode standard and principal (default ols). MIM always uses
    /// least squares weighted per body axis (Gautier).
    #[arg(long, value_enum)]
    pub method: Option<Method>,

    /// How --mode standard and principal compress the rows: Householder QR
    /// (backward stable), or the normal equations (faster; directions weaker than
    /// 1e-6 of the strongest are then reported as not identifiable).
    #[arg(long, value_enum, default_value_t = AccumulationArg::Qr)]
    pub accumulation: AccumulationArg,

    /// Ridge: weight of the pull toward the nominal parameters.
    #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
    pub lambda: f64,

    /// Low-pass cutoff, Hz, for velocities and accelerations estimated from
    /// positions (only used when the file has no v or a columns).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub cutoff: f64,

    #[command(flatten)]
    pub gravity: GravityArg,

    #[command(flatten)]
    pub recipe: RecipeArgs,

    /// Write the estimate as JSON (schema dyngen-parameters/1) to this file.
    #[arg(long, value_name = "FILE")]
    pub params_json: Option<PathBuf>,

    /// Write the URDF with the identified inertials of the fully identified,
    /// physically valid bodies (the others keep their URDF inertials) to this file.
    #[arg(long, value_name = "FILE")]
    pub urdf_out: Option<PathBuf>,

    /// With --urdf-out: a body that lumped links attached by fixed joints gets the
    /// whole identified inertial, and the merged links lose their <inertial>
    /// (default: refuse to update such a body).
    #[arg(long)]
    pub lump_merged: bool,

    /// Write an SVG report (measured vs predicted torques per joint) to this file.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,

    /// Take the URDF's inertials as the true parameters: print each identified
    /// parameter's error, and with --svg plot them.
    #[arg(long)]
    pub truth_from_urdf: bool,

    /// Replace existing output files.
    #[arg(long)]
    pub force: bool,
}

/// How to read a recording that is not in dyngen's own CSV schema: a recipe file,
/// and flags for the common cases (they override the file's settings).
#[derive(Debug, Default, clap::Args)]
pub struct RecipeArgs {
    /// Read the recording through this recipe: `key = value` lines giving the
    /// delimiter, header, columns, units, gains, signs, windows, … (see the README).
    #[arg(long, value_name = "FILE")]
    pub recipe: Option<PathBuf>,

    /// The recording has no header line: columns in the order dyngen writes them
    /// (t, q…, [v…, a…,] tau…), or as the recipe's `time`, `q`, `tau` say.
    #[arg(long)]
    pub no_header: bool,

    /// Field separator: comma, semicolon, tab or whitespace.
    #[arg(long, value_name = "SEP")]
    pub delimiter: Option<String>,

    /// Joint positions (and velocities) are in degrees.
    #[arg(long)]
    pub degrees: bool,

    /// The torque columns hold motor currents: torque = k·current with these
    /// torque constants (N·m/A), one for all joints or one per joint.
    #[arg(long, value_name = "K1,K2,…", allow_hyphen_values = true)]
    pub gains: Option<String>,

    /// Interpolate onto a uniform grid of this step (s) instead of using irregular
    /// time stamps as they are.
    #[arg(long, value_name = "DT")]
    pub resample: Option<String>,

    /// Use only the samples with t0 ≤ t ≤ t1 (s); either end may be left out.
    #[arg(long, value_name = "T0:T1", allow_hyphen_values = true)]
    pub window: Option<String>,

    /// Keep every N-th sample.
    #[arg(long, value_name = "N")]
    pub decimate: Option<String>,
}

impl RecipeArgs {
    /// The recipe: the file's (or the default), then the flags.
    pub fn recipe(&self) -> Result<Recipe> {
        let mut recipe = match &self.recipe {
            Some(path) => Recipe::from_file(path).map_err(|e| format!("{}: {e}", path.display()))?,
            None => Recipe::default(),
        };
        let flags = [
            ("--no-header", "header", self.no_header.then_some("false")),
            ("--delimiter", "delimiter", self.delimiter.as_deref()),
            ("--degrees", "units", self.degrees.then_some("deg")),
            ("--gains", "gains", self.gains.as_deref()),
            ("--resample", "resample", self.resample.as_deref()),
            ("--window", "window", self.window.as_deref()),
            ("--decimate", "decimate", self.decimate.as_deref()),
        ];
        for (flag, key, value) in flags {
            if let Some(value) = value {
                recipe.set(key, value).map_err(|e| format!("{flag}: {e}"))?;
            }
        }
        recipe.check().map_err(|e| format!("recipe: {e}"))?;
        Ok(recipe)
    }
}

/// Reads a recording through the recipe the flags describe, estimates what it does
/// not measure, and prints what was done.
pub fn load_recording(path: &Path, recipe: &RecipeArgs, dof: usize, cutoff: f64) -> Result<Trajectory> {
    let data_err = |e: dyngen_identify::data::DataError| format!("{}: {e}", path.display());
    let loaded = recipe.recipe()?.read(path, Some(dof)).map_err(data_err)?;
    let loaded = loaded.with_derivatives(cutoff).map_err(data_err)?;
    println!("{}: {}", path.display(), loaded.report);
    Ok(loaded.trajectory)
}

pub fn run(args: &IdentifyArgs, progress: &Progress) -> Result<()> {
    if !(args.cutoff.is_finite() && args.cutoff > 0.0) {
        return Err(format!(
            "--cutoff must be a positive frequency in Hz, got {}",
            args.cutoff
        ));
    }
    if !(args.lambda.is_finite() && args.lambda >= 0.0) {
        return Err(format!("--lambda must be non-negative, got {}", args.lambda));
    }
    if args.mode == Mode::Mim && args.method.is_some() {
        return Err(
            "--method applies to --mode standard and principal; MIM always uses least squares weighted per body axis"
                .into(),
        );
    }
    if args.mode == Mode::Mim && args.accumulation != AccumulationArg::Qr {
        return Err("--accumulation applies to --mode standard and principal; MIM accumulates by QR".into());
    }
    check_outputs(args)?;
    let model = load_moving_model(&args.urdf, args.gravity.get()?)?;
    let n = model.dof();
    let traj = load_recording(&args.data, &args.recipe, n, args.cutoff)?;
    if args.mode == Mode::Mim && traj.joint_wrenches().is_none() {
        return Err(format!(
            "{}: --mode mim needs the joint wrench columns fx1, fy1, fz1, mx1, my1, mz1, …, mz{n}, which the file \
             does not have; identify from the joint torques with --mode standard or principal instead",
            args.data.display()
        ));
    }
    println!("{} samples of {} joints from {}", traj.len(), n, args.data.display());
    let identified = match args.mode {
        Mode::Standard | Mode::Principal => from_torques(args, &model, &traj, progress)?,
        Mode::Mim => by_mim(args, &model, &traj)?,
    };

    if let Some(path) = &args.params_json {
        identified
            .report
            .write(path, args.force)
            .map_err(|e| report_error(path, e))?;
        println!("wrote the parameters to {}", path.display());
    }
    if let Some(path) = &args.svg {
        write_svg(args, path, &model, &traj, &identified, progress)?;
    }
    if let Some(path) = &args.urdf_out {
        write_urdf(args, path, &model, &identified)?;
    }
    Ok(())
}

/// An identification, whatever the mode: the report (names, values, σ, status per
/// parameter) and how to predict the joint torques.
struct Identified {
    report: ParameterReport,
    /// Standard (10 per body) or θ (4 per body).
    per_body: usize,
    prediction: Prediction,
}

enum Prediction {
    /// Rows of this regressor times the estimate's solution.
    Regressor { estimate: Box<Estimate>, principal: bool },
    /// Inverse dynamics with these standard parameters.
    Parameters(Vec<f64>),
}

impl Identified {
    fn truth(&self, model: &Model) -> Vec<f64> {
        if self.per_body == 10 {
            model.standard_params()
        } else {
            dyngen_model::principal_params(model)
        }
    }
}

/// Standard or principal parameters from the joint torques, through the stacked
/// regressor.
fn from_torques(args: &IdentifyArgs, model: &Model, traj: &Trajectory, progress: &Progress) -> Result<Identified> {
    let principal = args.mode == Mode::Principal;
    let robot = Reference::new(model);
    let n = model.dof();
    let p = if principal { 4 * n } else { 10 * n };
    let accumulation = match args.accumulation {
        AccumulationArg::Qr => Accumulation::Qr,
        AccumulationArg::NormalEquations => Accumulation::NormalEquations,
    };
    let mut acc =
        Accumulator::with_accumulation(p, Channels::Interleaved(n), accumulation).map_err(|e| e.to_string())?;
    let mut y = vec![0.0; n * p];
    let bar = progress.bar(traj.len() as u64, "stacking regressors");
    for k in 0..traj.len() {
        let (q, v, a) = joint_state(args, traj, k)?;
        regressor(&robot, principal, q, v, a, &mut y);
        for j in 0..n {
            acc.push_row(&y[j * p..(j + 1) * p], traj.tau(k)[j])
                .map_err(|e| format!("{}, {}: {e}", args.data.display(), traj.location(k)))?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();

    let opts = Options::default();
    let estimate = match args.method.unwrap_or(Method::Ols) {
        Method::Ols => acc.ols(&opts),
        Method::Wls => acc.wls(&opts),
        Method::Tls => acc.tls(&opts),
        Method::Ridge => {
            let prior = if principal {
                dyngen_model::principal_params(model)
            } else {
                model.standard_params()
            };
            acc.ridge(&prior, args.lambda, &opts)
        }
    }
    .map_err(|e| e.to_string())?;

    let names = if principal {
        dyngen_model::names::principal_param_names(n)
    } else {
        standard_param_names(n)
    };
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    println!("{}", estimate.table(&names));
    print_fit(&estimate);
    let joint_names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let parameterisation = if principal {
        Parameterisation::Principal
    } else {
        Parameterisation::Standard
    };
    let report = ParameterReport::from_estimate(&model.name, parameterisation, &estimate, &names, &joint_names);
    let identified = Identified {
        report,
        per_body: if principal { 4 } else { 10 },
        prediction: Prediction::Regressor {
            estimate: Box::new(estimate),
            principal,
        },
    };
    if args.truth_from_urdf {
        print_errors(&identified, model);
    }
    Ok(identified)
}

/// The paper's MIM on measured joint wrenches: every body's θ from its resultant,
/// the whole robot as one block-diagonal least-squares problem.
fn by_mim(args: &IdentifyArgs, model: &Model, traj: &Trajectory) -> Result<Identified> {
    let robot = Reference::new(model);
    let recording = Recording::from_measurements(&robot, traj).map_err(|e| format!("{}: {e}", args.data.display()))?;
    let truth = args.truth_from_urdf.then(|| dyngen_model::principal_params(model));
    let estimate: MimEstimate =
        mim::whole_robot(&recording, 0..recording.len(), truth.as_deref(), &MimOptions::default())
            .map_err(|e| format!("{}: {e}", args.data.display()))?;
    println!("{estimate}");
    // The torques of the identified model: θ where identified, the URDF's elsewhere.
    let nominal = dyngen_model::principal_params(model);
    let theta: Vec<f64> = estimate
        .theta()
        .iter()
        .zip(&nominal)
        .map(|(x, t)| x.unwrap_or(*t))
        .collect();
    Ok(Identified {
        report: ParameterReport::from_mim(&model.name, &estimate),
        per_body: 4,
        prediction: Prediction::Parameters(dyngen_reference::principal_params_to_standard(model, &theta)),
    })
}

/// `(q, v, a)` of sample `k` (v and a exist once the derivatives are estimated).
fn joint_state<'a>(args: &IdentifyArgs, traj: &'a Trajectory, k: usize) -> Result<(&'a [f64], &'a [f64], &'a [f64])> {
    match (traj.v(k), traj.a(k)) {
        (Some(v), Some(a)) => Ok((traj.q(k), v, a)),
        _ => Err(format!(
            "{}: sample {k} has no velocities or accelerations",
            args.data.display()
        )),
    }
}

/// The joint torque regressor, standard (`n × 10n`) or principal (`n × 4n`).
fn regressor(robot: &Reference, principal: bool, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
    if principal {
        Dynamics::principal_regressor(robot, q, v, a, y);
    } else {
        Dynamics::joint_torque_regressor(robot, q, v, a, y);
    }
}

/// Each identified parameter against the URDF's value (torque modes; MIM prints its
/// own error table).
fn print_errors(identified: &Identified, model: &Model) {
    let truth = identified.truth(model);
    let mut worst: Option<(f64, &str)> = None;
    let mut count = 0;
    for (p, t) in identified.report.parameters.iter().zip(&truth) {
        if let (Some(v), true) = (p.value, t.abs() > 1e-12) {
            let rel = dyngen_identify::relative_error(v, *t);
            count += 1;
            if worst.is_none_or(|(w, _)| rel > w) {
                worst = Some((rel, &p.name));
            }
        }
    }
    match worst {
        Some((w, name)) => println!(
            "against the URDF: {count} identified parameters with a nonzero true value, largest relative error {w:.3e} ({name})"
        ),
        None => println!("against the URDF: no identified parameter with a nonzero true value"),
    }
}

/// Refuses, before any work, existing output files without --force and two
/// outputs to the same file.
fn check_outputs(args: &IdentifyArgs) -> Result<()> {
    let outputs: Vec<(&str, &PathBuf)> = [
        ("--params-json", &args.params_json),
        ("--svg", &args.svg),
        ("--urdf-out", &args.urdf_out),
    ]
    .into_iter()
    .filter_map(|(flag, p)| p.as_ref().map(|p| (flag, p)))
    .collect();
    for (i, (flag, path)) in outputs.iter().enumerate() {
        if let Some((other, _)) = outputs[..i].iter().find(|(_, p)| p == path) {
            return Err(format!(
                "{other} and {flag} both name {}; give each output its own file",
                path.display()
            ));
        }
        check_overwrite(path, args.force)?;
    }
    if args.lump_merged && args.urdf_out.is_none() {
        return Err("--lump-merged only applies with --urdf-out".into());
    }
    Ok(())
}

/// A report error as CLI text (`--force`, not the library's `overwrite`).
fn report_error(path: &Path, e: ReportError) -> String {
    match e {
        ReportError::Exists { .. } => format!("{} already exists; pass --force to overwrite it", path.display()),
        e => format!("{}: {e}", path.display()),
    }
}

/// Measured against predicted torques (regressor rows times the estimate's
/// solution, valid on the identifiable subspace; for MIM, inverse dynamics of the
/// identified model), and with --truth-from-urdf the relative errors of the
/// parameters that have a value.
fn write_svg(
    args: &IdentifyArgs,
    path: &Path,
    model: &Model,
    traj: &Trajectory,
    identified: &Identified,
    progress: &Progress,
) -> Result<()> {
    let robot = Reference::new(model);
    let n = model.dof();
    let mut y = Vec::new();
    let mut measured = Vec::with_capacity(traj.len());
    let mut predicted = Vec::with_capacity(traj.len());
    let bar = progress.bar(traj.len() as u64, "predicting torques");
    for k in 0..traj.len() {
        let (q, v, a) = joint_state(args, traj, k)?;
        predicted.push(match &identified.prediction {
            Prediction::Regressor { estimate, principal } => {
                let p = estimate.n_params();
                y.resize(n * p, 0.0);
                regressor(&robot, *principal, q, v, a, &mut y);
                (0..n).map(|j| estimate.predict(&y[j * p..(j + 1) * p])).collect()
            }
            Prediction::Parameters(params) => robot.rnea(q, v, a, params),
        });
        measured.push(traj.tau(k).to_vec());
        bar.inc(1);
    }
    bar.finish_and_clear();

    let errors = args.truth_from_urdf.then(|| {
        let truth = identified.truth(model);
        let mut zero_truth = Vec::new();
        let errors: Vec<(String, Option<f64>)> = identified
            .report
            .parameters
            .iter()
            .zip(&truth)
            .filter_map(|(p, &x)| match p.value {
                None => Some((p.name.clone(), None)),
                // A relative error needs a nonzero true value.
                Some(_) if x.abs() < 1e-12 => {
                    zero_truth.push(p.name.as_str());
                    None
                }
                Some(v) => Some((p.name.clone(), Some((v - x) / x))),
            })
            .filter(|(_, e)| e.is_none_or(f64::is_finite))
            .collect();
        if !zero_truth.is_empty() {
            println!(
                "note: parameter errors leave out {} (identified, but zero in the URDF, so no relative error)",
                zero_truth.join(", ")
            );
        }
        errors
    });
    let title = format!(
        "{}: {} on {}",
        model.name,
        identified.report.method,
        args.data
            .file_name()
            .map_or_else(|| args.data.display().to_string(), |f| f.to_string_lossy().into_owned())
    );
    let joint_names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let svg = crate::svg::svg_report(&title, traj.t(), &measured, &predicted, &joint_names, errors.as_deref())
        .map_err(|e| report_error(path, e))?;
    report::write_report(path, &svg, args.force).map_err(|e| report_error(path, e))?;
    println!("wrote the SVG report to {}", path.display());
    Ok(())
}

/// Why a body's inertial is not written, or its identified inertial: all of the
/// body's parameters (10 standard, or θ with the URDF's centre of mass and principal
/// axes) identified, and the result physically valid.
fn identified_inertial(identified: &Identified, model: &Model, body: usize) -> std::result::Result<Inertial, String> {
    let k = identified.per_body;
    let params = &identified.report.parameters[k * body..k * (body + 1)];
    let missing = params.iter().filter(|p| p.status != ParamStatus::Identified).count();
    if missing > 0 {
        return Err(format!("{missing} of its {k} parameters not identified"));
    }
    let values: Vec<f64> = params
        .iter()
        .map(|p| p.value.ok_or("a parameter has no value"))
        .collect::<std::result::Result<_, _>>()?;
    let mut x = [0.0; 10];
    if k == 10 {
        x.copy_from_slice(&values);
    } else {
        // θ of this body, the URDF's θ elsewhere (only this body's 10 are used).
        let mut theta = dyngen_model::principal_params(model);
        theta[4 * body..4 * body + 4].copy_from_slice(&values);
        let standard = dyngen_reference::principal_params_to_standard(model, &theta);
        x.copy_from_slice(&standard[10 * body..10 * body + 10]);
    }
    let inertial = Inertial::from_standard_params(&x).ok_or("identified mass is not positive")?;
    dyngen_model::desc::check_inertial(&inertial).map_err(|e| match e {
        ErrorKind::NonPositiveMass(m) => format!("identified mass {m} is not positive"),
        ErrorKind::NotPositiveDefinite(ev) => {
            format!("identified inertia about the centre of mass is not positive definite (moments {ev:?})")
        }
        ErrorKind::TriangleInequality(ev) => {
            format!("identified principal moments {ev:?} violate the triangle inequality")
        }
        e => format!("identified inertial is not physical ({e:?})"),
    })?;
    Ok(inertial)
}

/// The input URDF with the inertials of the fully identified, physically valid
/// bodies replaced; every other byte is kept.
fn write_urdf(args: &IdentifyArgs, path: &Path, model: &Model, identified: &Identified) -> Result<()> {
    let text = std::fs::read_to_string(&args.urdf).map_err(|e| format!("{}: {e}", args.urdf.display()))?;
    let mut updates: Vec<(&str, Inertial)> = Vec::new();
    let mut kept: Vec<String> = Vec::new();
    for (i, body) in model.bodies.iter().enumerate() {
        match identified_inertial(identified, model, i) {
            Ok(inertial) => {
                if !body.merged.is_empty() && !args.lump_merged {
                    return Err(format!(
                        "--urdf-out: body `{}` is fully identified, but its inertial includes the links [{}] \
                         attached by fixed joints; pass --lump-merged to write it to `{}` and remove their \
                         <inertial> elements",
                        body.name,
                        body.merged.join(", "),
                        body.name
                    ));
                }
                updates.push((&body.name, inertial));
            }
            Err(why) => kept.push(format!("{} ({why})", body.name)),
        }
    }
    let merged = if args.lump_merged {
        MergedLinks::Lump
    } else {
        MergedLinks::Refuse
    };
    let out = report::rewrite_urdf_inertials_with(&text, &updates, merged)
        .map_err(|e| format!("{}: {e}", args.urdf.display()))?;
    report::write_new(path, &out, args.force).map_err(|e| report_error(path, e))?;
    if updates.is_empty() {
        println!(
            "wrote {} unchanged: no body has all its parameters identified, so every inertial is the URDF's",
            path.display()
        );
    } else {
        let names: Vec<&str> = updates.iter().map(|(n, _)| *n).collect();
        println!(
            "wrote {} with the identified inertials of {}",
            path.display(),
            names.join(", ")
        );
    }
    if !kept.is_empty() {
        println!(
            "note: kept the URDF inertials of {} of {} bodies: {}",
            kept.len(),
            model.bodies.len(),
            kept.join("; ")
        );
        if args.mode != Mode::Mim {
            println!(
                "note: this is expected: joint torques determine only the base parameters (combinations), \
                 so few bodies, if any, have all their parameters identifiable; see --params-json for the \
                 combinations, or identify body by body from joint wrenches with --mode mim"
            );
        }
    }
    Ok(())
}

/// Torque residuals per joint and relative to the measured torques.
fn print_fit(estimate: &Estimate) {
    let r = &estimate.residuals;
    let per_joint: Vec<String> = r.per_channel_rms.iter().map(|x| format!("{x:.3e}")).collect();
    println!(
        "torque residual RMS {:.3e} N·m over {} rows (per joint: {}); {} of {} parameter directions identifiable",
        r.rms,
        r.rows,
        per_joint.join(", "),
        estimate.rank,
        estimate.n_params()
    );
}
