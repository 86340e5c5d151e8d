//! `dyngen identify`: standard inertial parameters from joint torques.

use crate::common::{load_moving_model, GravityArg, Progress, Result};
use dyngen::data::read_csv;
use dyngen::dynamics::Dynamics;
use dyngen::identify::{Accumulator, Channels, Estimate, Options};
use dyngen::Reference;
use dyngen_codegen::standard_param_names;
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  dyngen simulate robots/ur5/ur5.urdf -o ur5.csv --experiment fourier
  dyngen identify robots/ur5/ur5.urdf ur5.csv
  dyngen identify robots/ur5/ur5.urdf measured.csv --method wls --cutoff 15
  dyngen identify robots/ur5/ur5.urdf measured.csv --method ridge --lambda 1e-3

The CSV needs t, q1..qn and tau1..taun; v and a are estimated from q (zero-phase
low-pass at --cutoff Hz, then central differences) when the file does not have them.
Parameters the data cannot determine are shown as —, with the identifiable
combinations (base parameters) they enter.";

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
