//! `dyngen identify`: standard inertial parameters from joint torques.

use crate::common::{check_overwrite, load_moving_model, GravityArg, Progress, Result};
use dyngen::data::{read_csv, Trajectory};
use dyngen::dynamics::Dynamics;
use dyngen::identify::{Accumulator, Channels, Estimate, Options, Status};
use dyngen::report::{self, MergedLinks, ParameterReport, Parameterisation, ReportError};
use dyngen::Reference;
use dyngen_codegen::standard_param_names;
use dyngen_model::{ErrorKind, Inertial, Model};
use std::path::{Path, PathBuf};

pub const EXAMPLES: &str = "\
Examples:
  dyngen simulate robots/ur5/ur5.urdf -o ur5.csv --experiment fourier
  dyngen identify robots/ur5/ur5.urdf ur5.csv
  dyngen identify robots/ur5/ur5.urdf measured.csv --method wls --cutoff 15
  dyngen identify robots/ur5/ur5.urdf measured.csv --method ridge --lambda 1e-3
  dyngen identify robots/ur5/ur5.urdf ur5.csv --params-json ur5.json --svg ur5.svg \\
      --truth-from-urdf --urdf-out ur5-identified.urdf --force

The CSV needs t, q1..qn and tau1..taun; v and a are estimated from q (zero-phase
low-pass at --cutoff Hz, then central differences) when the file does not have them.
Parameters the data cannot determine are shown as —, with the identifiable
combinations (base parameters) they enter.

--params-json writes the estimate as JSON (schema dyngen-parameters/1).
--svg plots measured against predicted torques per joint (with --truth-from-urdf
also the relative error of each identified parameter against the URDF's values).
--urdf-out writes the URDF with the identified inertial of every body whose ten
standard parameters are all identified and physically valid; the other bodies
keep their URDF inertials (from joint torques alone usually only a few bodies,
if any, are fully identifiable). Existing files are kept unless --force.";

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

    /// The estimator.
    #[arg(long, value_enum, default_value_t = Method::Ols)]
    pub method: Method,

    /// Ridge: weight of the pull toward the nominal parameters.
    #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
    pub lambda: f64,

    /// Low-pass cutoff, Hz, for velocities and accelerations estimated from
    /// positions (only used when the file has no v or a columns).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub cutoff: f64,

    #[command(flatten)]
    pub gravity: GravityArg,

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

    /// With --svg: take the URDF's inertials as the true parameters and also plot
    /// the relative error of each identified parameter.
    #[arg(long, requires = "svg")]
    pub truth_from_urdf: bool,

    /// Replace existing output files.
    #[arg(long)]
    pub force: bool,
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
    check_outputs(args)?;
    let model = load_moving_model(&args.urdf, args.gravity.get()?)?;
    let n = model.dof();
    let data_err = |e: dyngen::data::DataError| format!("{}: {e}", args.data.display());
    let mut traj = read_csv(&args.data, Some(n)).map_err(data_err)?;
    if traj.velocities().is_none() || traj.accelerations().is_none() {
        eprintln!(
            "{} has no velocities or accelerations: estimating them from positions (low-pass at {} Hz)",
            args.data.display(),
            args.cutoff
        );
        traj = traj.with_derivatives(args.cutoff).map_err(data_err)?;
    }

    let robot = Reference::new(&model);
    let p = Dynamics::nparams(&robot);
    let mut acc = Accumulator::with_channels(p, Channels::Interleaved(n)).map_err(|e| e.to_string())?;
    let mut y = vec![0.0; n * p];
    let bar = progress.bar(traj.len() as u64, "stacking regressors");
    for k in 0..traj.len() {
        let (q, tau) = (traj.q(k), traj.tau(k));
        let (v, a) = match (traj.v(k), traj.a(k)) {
            (Some(v), Some(a)) => (v, a),
            _ => {
                return Err(format!(
                    "{}: sample {k} has no velocities or accelerations",
                    args.data.display()
                ))
            }
        };
        Dynamics::joint_torque_regressor(&robot, q, v, a, &mut y);
        for j in 0..n {
            acc.push_row(&y[j * p..(j + 1) * p], tau[j])
                .map_err(|e| format!("{}, {}: {e}", args.data.display(), traj.location(k)))?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();

    let opts = Options::default();
    let estimate = match args.method {
        Method::Ols => acc.ols(&opts),
        Method::Wls => acc.wls(&opts),
        Method::Tls => acc.tls(&opts),
        Method::Ridge => acc.ridge(&model.standard_params(), args.lambda, &opts),
    }
    .map_err(|e| e.to_string())?;

    let names = standard_param_names(n);
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    println!("{} samples of {} joints from {}", traj.len(), n, args.data.display());
    println!("{}", estimate.table(&names));
    print_fit(&estimate);

    let joint_names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    if let Some(path) = &args.params_json {
        ParameterReport::from_estimate(&model.name, Parameterisation::Standard, &estimate, &names, &joint_names)
            .write(path, args.force)
            .map_err(|e| report_error(path, e))?;
        println!("wrote the parameters to {}", path.display());
    }
    if let Some(path) = &args.svg {
        write_svg(args, path, &model, &traj, &estimate, &names, &joint_names, progress)?;
    }
    if let Some(path) = &args.urdf_out {
        write_urdf(args, path, &model, &estimate)?;
    }
    Ok(())
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
/// solution, valid on the identifiable subspace), and with --truth-from-urdf the
/// relative errors of the parameters that have a value.
#[allow(clippy::too_many_arguments)]
fn write_svg(
    args: &IdentifyArgs,
    path: &Path,
    model: &Model,
    traj: &Trajectory,
    estimate: &Estimate,
    names: &[&str],
    joint_names: &[&str],
    progress: &Progress,
) -> Result<()> {
    let robot = Reference::new(model);
    let n = model.dof();
    let p = Dynamics::nparams(&robot);
    let mut y = vec![0.0; n * p];
    let mut measured = Vec::with_capacity(traj.len());
    let mut predicted = Vec::with_capacity(traj.len());
    let bar = progress.bar(traj.len() as u64, "predicting torques");
    for k in 0..traj.len() {
        let (Some(v), Some(a)) = (traj.v(k), traj.a(k)) else {
            return Err(format!(
                "{}: sample {k} has no velocities or accelerations",
                args.data.display()
            ));
        };
        Dynamics::joint_torque_regressor(&robot, traj.q(k), v, a, &mut y);
        predicted.push((0..n).map(|j| estimate.predict(&y[j * p..(j + 1) * p])).collect());
        measured.push(traj.tau(k).to_vec());
        bar.inc(1);
    }
    bar.finish_and_clear();

    let errors = args.truth_from_urdf.then(|| {
        let truth = model.standard_params();
        let mut zero_truth = Vec::new();
        let errors: Vec<(String, Option<f64>)> = estimate
            .params
            .iter()
            .zip(&truth)
            .enumerate()
            .filter_map(|(j, (est, &x))| match est.value {
                None => Some((names[j].to_string(), None)),
                // A relative error needs a nonzero true value.
                Some(_) if x.abs() < 1e-12 => {
                    zero_truth.push(names[j]);
                    None
                }
                Some(v) => Some((names[j].to_string(), Some((v - x) / x))),
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
        estimate.method,
        args.data
            .file_name()
            .map_or_else(|| args.data.display().to_string(), |f| f.to_string_lossy().into_owned())
    );
    let svg = report::svg_report(&title, traj.t(), &measured, &predicted, joint_names, errors.as_deref())
        .map_err(|e| report_error(path, e))?;
    report::write_report(path, &svg, args.force).map_err(|e| report_error(path, e))?;
    println!("wrote the SVG report to {}", path.display());
    Ok(())
}

/// Why a body's inertial is not written, or its identified inertial.
fn identified_inertial(estimate: &Estimate, body: usize) -> std::result::Result<Inertial, String> {
    let params = &estimate.params[10 * body..10 * body + 10];
    let missing = params.iter().filter(|p| p.status != Status::Identified).count();
    if missing > 0 {
        return Err(format!("{missing} of its 10 parameters not identified"));
    }
    let mut x = [0.0; 10];
    for (x, p) in x.iter_mut().zip(params) {
        *x = p.value.ok_or("a parameter has no value")?;
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
fn write_urdf(args: &IdentifyArgs, path: &Path, model: &Model, estimate: &Estimate) -> Result<()> {
    let text = std::fs::read_to_string(&args.urdf).map_err(|e| format!("{}: {e}", args.urdf.display()))?;
    let mut updates: Vec<(&str, Inertial)> = Vec::new();
    let mut kept: Vec<String> = Vec::new();
    for (i, body) in model.bodies.iter().enumerate() {
        match identified_inertial(estimate, i) {
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
            "wrote {} unchanged: no body has all 10 standard parameters identified, so every inertial is the URDF's",
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
        println!(
            "note: this is expected: joint torques determine only the base parameters (combinations), \
             so few bodies, if any, have all 10 parameters identifiable; see --params-json for the combinations"
        );
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
