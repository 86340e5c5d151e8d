//! `dyngen identify`: inertial parameters from measured data: the standard or the
//! principal parameters from joint torques, or the principal parameters of every body
//! by MIM from joint wrenches.

use crate::common::{check_overwrite, load_moving_model, out, outln, with_spinner, ModelArgs, Progress, Result};
use crate::error::CliError;
use dyngen_identify::choice::{DEFAULT_EXTRAS, MIN_SAMPLES};
use dyngen_identify::data::{Recipe, Trajectory};
use dyngen_identify::extras::ExtraTerms;
use dyngen_identify::pipeline::{
    self, Estimator, Identification, IdentifyOptions, JointTerms, PipelineError, Prediction,
};
use dyngen_identify::report::{self, DataSpan, MergedLinks, Parameterisation};
use dyngen_identify::{Accumulation, Estimate};
use dyngen_model::joint_params::Coulomb;
use dyngen_model::Model;
use dyngen_nim::residual::{fit_residual, ResidualOptions};
use dyngen_nim::NimError;
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
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction auto --params-json ur5.json \\
      --validate run2.csv
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction sign --method consistent \\
      --exclude-below 0.05 --validate run2.csv
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction stribeck --validate run2.csv \\
      --urdf-out ur5-identified.urdf
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction best --validate run2.csv
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction auto \\
      --extra-terms asymmetric,ripple=1,load --validate run2.csv
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction sign --rotor-inertia no
  dyngen identify robots/ur5/ur5.urdf run1.csv --friction sign --partial run1.part
  dyngen identify robots/ur5/ur5.urdf --merge run1.part run2.part --method wls \\
      --params-json fleet.json
  dyngen identify robots/ur5/ur5.urdf --merge run1.part run2.part --partial both.part

A real robot's joint torques carry friction and rotor inertia: --friction auto adds
[Ia, Fv, Fc, F0] per joint (rotor inertia, viscous and Coulomb friction, offset) with
the Coulomb term smoothed per joint as held-out parts of the recording best support; --rotor-inertia no leaves Ia out
(friction only), --rotor-inertia yes without --friction fits Ia alone. --friction
stribeck replaces the Coulomb term by (Fc + (Fs − Fc)·exp(−(q̇/vs)²))·sign(q̇),
static friction Fs >= 0 and Stribeck velocity vs per joint fitted by nonlinear least
squares from the linear fit, vs between 0.005 and 0.5 times the joint's speed range
(and above the slowest 1 % of its samples). A joint keeps the term only if it lowers
the joint's error on held-out data of the recording (4 time blocks, each predicted
by the fit on the others) by 1 % and stays physical (Fc, Fv not negative, Fs and vs
determined); otherwise it falls back to sign friction, and one line per joint says
which was kept and why. --extra-terms asymmetric,ripple=2,load (any of them) adds
per joint direction-dependent viscous friction Fva·|q̇|, harmonics of the joint angle
(torque ripple and position-dependent Coulomb friction), harmonics of the motor angle
(motor-ripple=H, with --gear-ratios) and Coulomb friction growing with the links'
load Fcl·|τ_rigid|·s(q̇), with --friction sign, smooth or auto.
--friction best, the default, fits none, sign (without and with Ia), auto and
stribeck on three of four time blocks of the recording, scores each on the block
left out (a more complex model must lower the error by 1 %), adds extra terms to the
best linear model one at a time while each lowers the held-out error by 1 %, prints
the errors and identifies with the best. --residual FILE adds a learned residual
(one small network per joint) where it lowers the error on the recording's last
quarter. --validate predicts a second
recording with the result.
--method consistent keeps every body physical and (with friction) Ia, Fv, Fc (and Fcl) >= 0,
with --friction stribeck too; --exclude-below SPEED leaves out a joint's rows where
it moves slower than SPEED (rad/s), where sticking defeats the Coulomb model.

The CSV needs t, q1..qn and tau1..taun; v and a are estimated from q (zero-phase
low-pass at --cutoff Hz, then central differences) when the file does not have them,
and measured q and v are low-passed at the same cutoff (--raw-states: as read).
Other layouts (no header, other names and order, semicolons, degrees, motor
currents, sign flips, time in ms) are read through a recipe file (--recipe) or the
flags for the common cases; duplicate time stamps are dropped and counted, irregular
ones used as they are or resampled (--resample), and a summary says what was
measured and what estimated:
  dyngen identify robots/ur5/ur5.urdf robot.log --recipe docs/example.recipe
  dyngen identify robots/ur5/ur5.urdf log.csv --no-header --delimiter semicolon \\
      --degrees --gains 0.11,0.11,0.11,0.05,0.05,0.05 --window 5:65 --resample 0.01
Unknown torque constants: --drive-gains identifies them with the dynamics (Gautier
and Briot) from two logs of motor currents, the second recorded with a known payload
fixed to --payload-frame; the parameters then come from DATA read with the identified
gains, which --params-json records for `dyngen validate`:
  dyngen identify robots/ur5/ur5.urdf currents.csv --friction sign \\
      --drive-gains loaded.csv --payload-frame tool0 --payload-mass 5 \\
      --payload-com 0.1,0,0.05 --payload-inertia 0.0073,0.0073,0.0063
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
usually few bodies, if any, are fully identifiable; by MIM usually all. With joint
terms, each joint's Fv and Fc go to its <dynamics damping friction>, and every
identified joint term (Ia, Fv, Fc, F0, Fs, vs, the Coulomb model and its ε) to
NAME.joint-params.json beside NAME.urdf (schema dyngen-joint-params/1).
Existing files are kept unless --force.

Many recordings (a fleet, or one long log in pieces): --partial OUT writes a
recording's partial factor instead of an estimate, the sufficient statistics of its
joint-torque rows (per joint the triangular factor of [A y], the robot, and every
option that shapes the rows), on whichever machine holds the recording. --merge
PART… merges partials of the same robot and row options exactly (in any grouping:
--merge with --partial writes the merged partial, a reduce tree) and solves with
--method, as one run on all their samples would: each recording is read, filtered
and differentiated on its own, so the result equals one run on one file holding
them all when that run's preprocessing sees the same rows (measured velocities and
accelerations with --raw-states). Partials made for another robot or with other row
options are refused, naming both files and the difference. What needs the rows
themselves has no partial: --friction auto (use --friction smooth --epsilon E),
stribeck, --extra-terms load, --mode mim; --svg and --validate with --merge (use `dyngen validate` on
the --params-json).";

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

/// Friction and rotor inertia per joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Friction {
    /// Rigid bodies only.
    None,
    /// [Ia, Fv, Fc, F0] per joint, Coulomb term Fc·sign(q̇).
    Sign,
    /// The same with Fc·tanh(q̇/ε), ε from --epsilon.
    Smooth,
    /// The same with each joint's ε chosen by the error on held-out time blocks of
    /// the recording.
    Auto,
    /// Sign, plus per joint a Stribeck term: static friction Fs at rest falling to
    /// Fc above the Stribeck velocity vs, fitted by nonlinear least squares; a joint
    /// keeps it only where it predicts held-out data better and stays physical.
    Stribeck,
    /// Stribeck with the Coulomb term Fc·tanh(q̇/ε), ε from --epsilon.
    StribeckSmooth,
    /// The model the data choose: none, sign without and with rotor inertia, auto
    /// and stribeck are each fitted on three of four time blocks of the recording
    /// and predict the fourth, every block in turn; the lowest error on the
    /// held-out blocks wins (printed for each), and the recording is identified
    /// with it.
    Best,
}

/// Whether a term is in the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum YesNo {
    Yes,
    No,
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
    /// Total least squares (noise on the regressor too), every column of [A y]
    /// scaled by its norm first, so that units do not matter.
    Tls,
    /// Total least squares on [A y] as it is (equal noise in every entry assumed).
    TlsUnscaled,
    /// Ridge regression toward the URDF's nominal parameters (scale-free weight
    /// --lambda).
    Ridge,
    /// Physically consistent least squares: every body's mass and inertia physical
    /// (a positive-definite pseudo-inertia; principal mode: mass and principal
    /// moments positive, triangle inequalities); with --friction also Ia, Fv, Fc ≥ 0.
    Consistent,
}

#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {
    /// The robot description (URDF, or MJCF as `.xml`); its inertials are the nominal parameters.
    pub urdf: PathBuf,

    /// Measured data (CSV: t, q1..qn[, v1..vn, a1..an], tau1..taun[, wrenches]);
    /// not with --merge.
    #[arg(required_unless_present = "merge")]
    pub data: Option<PathBuf>,

    /// Write the recording's partial factor (the sufficient statistics of its
    /// joint-torque rows, JSON schema dyngen-partial/1) to this file instead of
    /// identifying; with --merge, the merged partial (a reduce tree). Refused with
    /// the options that need the rows themselves: --friction auto, stribeck and
    /// stribeck-smooth, --extra-terms load, --mode mim; and with those of the estimate (--method,
    /// --lambda, --params-json, --urdf-out, --svg, --validate, --truth-from-urdf),
    /// which belong to the run that merges.
    #[arg(long, value_name = "OUT")]
    pub partial: Option<PathBuf>,

    /// Identify from these partial factors (written by --partial) instead of a
    /// recording: merged exactly, then solved with --method as one run on all
    /// their samples would. They must be of this robot and share the options that
    /// shape the rows (mode, friction and ε, rotor inertia, extra terms, accumulation,
    /// exclude-below, cutoff, raw states, recipe), which are taken from them.
    #[arg(long, value_name = "PART", num_args = 1.., conflicts_with = "data")]
    pub merge: Vec<PathBuf>,

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

    /// Friction and rotor inertia per joint (--mode standard): 4 more parameters per
    /// joint, [Ia, Fv, Fc, F0], and more. Default: `best` (the data choose, `none`
    /// among the candidates) for one recording in --mode standard without
    /// --rotor-inertia and --drive-gains; `none` otherwise.
    #[arg(long, value_enum)]
    pub friction: Option<Friction>,

    /// Rotor inertia Ia per joint (--mode standard), on its own: `no` fits the
    /// --friction terms without it (Ia held at 0), `yes` fits it, also without
    /// --friction (Ia alone, no friction terms). Default: with the friction terms.
    #[arg(long, value_enum, value_name = "yes|no")]
    pub rotor_inertia: Option<YesNo>,

    /// Joint terms past viscous and Coulomb friction, with --friction sign, smooth
    /// or auto: a comma-separated list of `asymmetric` (direction-dependent viscous
    /// friction Fva·|q̇|), `ripple=H` (H harmonics of the joint angle: torque ripple
    /// and position-dependent Coulomb friction), `motor-ripple=H` (H harmonics of the
    /// motor angle, with --gear-ratios) and `load` (Coulomb friction growing
    /// with the links' load, Fcl·|τ_rigid|·s(q̇)). With --friction best: the terms
    /// it may add (default asymmetric,ripple=2,load; `none` for none).
    #[arg(long, value_name = "LIST", value_parser = crate::ranges::extra_terms)]
    pub extra_terms: Option<ExtraTerms>,

    /// Each joint's gear ratio N (one for all joints or one per joint), for
    /// --extra-terms motor-ripple=H: harmonics of the motor angle N·q, the ripple of
    /// cogging and gears, which repeats many times per joint turn.
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub gear_ratios: Option<String>,

    /// --friction smooth and stribeck-smooth: ε of Fc·tanh(q̇/ε), rad/s (m/s for
    /// prismatic joints), 0 < ε ≤ 1000.
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true, value_parser = crate::ranges::EPSILON)]
    pub epsilon: f64,

    /// Predict the torques of this second recording (read with the same recipe)
    /// with the identified model and print the errors per joint and overall.
    #[arg(long, value_name = "CSV")]
    pub validate: Option<PathBuf>,

    /// Train a learned residual on what the identified model leaves in the torques:
    /// per joint a small network over the joint's sin q, cos q and q̇, trained on
    /// the first 75 % of the recording and kept, written to FILE (the networks'
    /// JSON), only if it lowers the error on the last 25 % by 1 %. The
    /// physical parameters are those identified either way. --validate then
    /// predicts with and without it; `dyngen validate --residual FILE` adds it.
    #[arg(long, value_name = "FILE")]
    pub residual: Option<PathBuf>,

    /// With --validate: use only the validation recording's samples with
    /// t0 ≤ t ≤ t1 (s). The training --window (or the recipe's window and rows) is
    /// never applied to the validation recording: without this flag all of it is used.
    #[arg(long, value_name = "T0:T1", allow_hyphen_values = true, requires = "validate")]
    pub validate_window: Option<String>,

    /// With --validate: read the validation recording through this recipe file
    /// instead of the training one (whose window and rows are dropped in any case;
    /// the recipe flags such as --degrees do not apply to it either).
    #[arg(long, value_name = "FILE", requires = "validate")]
    pub validate_recipe: Option<PathBuf>,

    /// Ridge: weight of the pull toward the nominal parameters, dimensionless (the
    /// penalty is λ·Σ ‖column j‖²·(x_j − x0_j)², so units do not matter), 0 to 1e12.
    #[arg(long, default_value_t = DEFAULT_LAMBDA, allow_negative_numbers = true, value_parser = crate::ranges::LAMBDA)]
    pub lambda: f64,

    /// Leave a joint's rows out of its equations where its |velocity| is below
    /// SPEED (rad/s, m/s for prismatic joints): near velocity reversals a real
    /// joint sticks, and the Coulomb term sign(q̇) does not describe it. The number
    /// of rows left out is printed. 0 < SPEED ≤ 1000.
    #[arg(long, value_name = "SPEED", allow_negative_numbers = true, value_parser = crate::ranges::EXCLUDE_BELOW)]
    pub exclude_below: Option<f64>,

    #[command(flatten)]
    pub recording: RecordingArgs,

    /// Write the estimate as JSON (schema dyngen-parameters/1) to this file.
    #[arg(long, value_name = "FILE")]
    pub params_json: Option<PathBuf>,

    /// Write the URDF with the identified inertials of the fully identified,
    /// physically valid bodies (the others keep their URDF inertials) to this file;
    /// with joint terms also each joint's Fv and Fc to its <dynamics>, and every
    /// joint term (those a URDF cannot hold too) to NAME.joint-params.json beside it.
    #[arg(long, value_name = "FILE")]
    pub urdf_out: Option<PathBuf>,

    /// With --urdf-out: a body that lumped links attached by fixed joints gets the
    /// whole identified inertial, and the merged links lose their `<inertial>`
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

    #[command(flatten)]
    pub drive: crate::gains::DriveGainArgs,
}

/// The robot's gravity and how to read and differentiate a recording: shared by the
/// commands that read one.
#[derive(Debug, clap::Args)]
pub struct RecordingArgs {
    /// Low-pass cutoff, Hz (zero phase): velocities and accelerations the file does
    /// not have are estimated through it, and the measured positions and velocities
    /// are filtered by it too (see --raw-states). 0 < Hz ≤ 1e6; default 10 (`validate`:
    /// the cutoff recorded in the parameters file).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::ranges::CUTOFF)]
    pub cutoff: Option<f64>,

    /// Use the measured positions and velocities as read, without the low-pass
    /// filter (only estimated derivatives are filtered).
    #[arg(long)]
    pub raw_states: bool,

    #[command(flatten)]
    pub gravity: ModelArgs,

    #[command(flatten)]
    pub recipe: RecipeArgs,
}

/// --lambda when not given.
pub const DEFAULT_LAMBDA: f64 = 1e-6;

/// The cutoff when --cutoff is not given (and no parameters file records one).
pub const DEFAULT_CUTOFF_HZ: f64 = 10.0;

impl RecordingArgs {
    /// --cutoff, or its default.
    pub fn cutoff(&self) -> f64 {
        self.cutoff.unwrap_or(DEFAULT_CUTOFF_HZ)
    }
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

    /// Drop stale rows: rows that repeat every value of the row before under a new
    /// time stamp (a logger that polled before the controller published).
    #[arg(long)]
    pub drop_stale: bool,
}

impl RecipeArgs {
    /// The recipe: the file's (or the default), then the flags.
    pub fn recipe(&self) -> Result<Recipe> {
        self.recipe_over(None)
    }

    /// The recipe: the --recipe file's, else `stored` (a parameters file's), else
    /// the default; then the flags.
    pub fn recipe_over(&self, stored: Option<Recipe>) -> Result<Recipe> {
        let mut recipe = match (&self.recipe, stored) {
            (Some(path), _) => Recipe::from_file(path).map_err(|e| CliError::input(path, e))?,
            (None, Some(stored)) => stored,
            (None, None) => Recipe::default(),
        };
        for (flag, key, value) in self.flags() {
            if let Some(value) = value {
                recipe
                    .set(key, value)
                    .map_err(|e| CliError::usage(format!("{flag}: {e}")))?;
            }
        }
        recipe.check().map_err(|e| CliError::Input(format!("recipe: {e}")))?;
        Ok(recipe)
    }

    /// The recipe flags given (not --recipe itself).
    pub fn flags_given(&self) -> Vec<&'static str> {
        self.flags()
            .into_iter()
            .filter_map(|(flag, _, value)| value.map(|_| flag))
            .collect()
    }

    /// Each recipe flag, the recipe key it sets, and its value when given.
    fn flags(&self) -> [(&'static str, &'static str, Option<&str>); 8] {
        [
            ("--no-header", "header", self.no_header.then_some("false")),
            ("--delimiter", "delimiter", self.delimiter.as_deref()),
            ("--degrees", "units", self.degrees.then_some("deg")),
            ("--gains", "gains", self.gains.as_deref()),
            ("--resample", "resample", self.resample.as_deref()),
            ("--window", "window", self.window.as_deref()),
            ("--decimate", "decimate", self.decimate.as_deref()),
            ("--drop-stale", "stale", self.drop_stale.then_some("drop")),
        ]
    }
}

/// Reads a recording through `recipe`, estimates what it does not measure, and
/// prints what was done.
pub fn load_recording(
    path: &Path,
    recipe: &Recipe,
    dof: usize,
    cutoff: f64,
    low_pass_states: bool,
) -> Result<Trajectory> {
    let options = IdentifyOptions {
        cutoff_hz: cutoff,
        low_pass_states,
        ..IdentifyOptions::default()
    };
    let loaded = pipeline::load(path, recipe, dof, &options).map_err(|e| pipeline_error(path, e))?;
    outln!("{}: {}", path.display(), loaded.report);
    Ok(loaded.trajectory)
}

/// `1000 samples of run.csv, line 2 to line 1001 (t = 0 … 9.99 s)`.
pub fn describe_span(span: &DataSpan) -> String {
    let times = match (span.t_first, span.t_last) {
        (Some(a), Some(b)) => format!(" (t = {a} … {b} s)"),
        _ => String::new(),
    };
    format!(
        "{} samples of {}, {} to {}{times}",
        span.samples, span.file, span.first, span.last
    )
}

/// A pipeline error as a command-line error; `data` names the recording.
pub fn pipeline_error(data: &Path, e: PipelineError) -> CliError {
    match e {
        PipelineError::InvalidOption { option, reason } => CliError::usage(format!("--{option} {reason}")),
        PipelineError::Recipe(_) | PipelineError::Data { path: Some(_), .. } => CliError::Input(e.to_string()),
        PipelineError::Data { path: None, .. } | PipelineError::DofMismatch { .. } => CliError::input(data, e),
        PipelineError::MissingWrenches { dof } => CliError::Input(format!(
            "{}: --mode mim needs the joint wrench columns fx1, fy1, fz1, mx1, my1, mz1, …, mz{dof}, which the file \
             does not have; identify from the joint torques with --mode standard or principal instead",
            data.display()
        )),
        // A row the estimator refuses is a bad line of the recording.
        PipelineError::Identify { at: Some(at), error } => {
            CliError::Input(format!("{}, {at}: {error}", data.display()))
        }
        PipelineError::Identify { at: None, error } => CliError::failed(error),
        PipelineError::MergedLinks { body, merged } => CliError::usage(format!(
            "--urdf-out: body `{body}` is fully identified, but its inertial includes the links [{}] attached by \
             fixed joints; pass --lump-merged to write it to `{body}` and remove their `<inertial>` elements",
            merged.join(", ")
        )),
        PipelineError::Report(e) => CliError::Input(e.to_string()),
        PipelineError::TooFewRows { .. } | PipelineError::NonFiniteEstimate { .. } => CliError::input(data, e),
    }
}

impl IdentifyArgs {
    /// The friction model: as given, or by default `best` where it can choose (one
    /// recording in the standard mode, the rotor inertia not fixed, no drive gains
    /// to identify), `none` otherwise.
    pub fn friction(&self) -> Friction {
        self.friction.unwrap_or(
            if self.mode == Mode::Standard
                && self.partial.is_none()
                && self.merge.is_empty()
                && self.rotor_inertia.is_none()
                && self.drive.drive_gains.is_none()
            {
                Friction::Best
            } else {
                Friction::None
            },
        )
    }

    pub fn options(&self) -> IdentifyOptions {
        IdentifyOptions {
            mode: match self.mode {
                Mode::Standard => pipeline::Mode::Standard,
                Mode::Principal => pipeline::Mode::Principal,
                Mode::Mim => pipeline::Mode::Mim,
            },
            estimator: match self.method.unwrap_or(Method::Ols) {
                Method::Ols => Estimator::Ols,
                Method::Wls => Estimator::Wls,
                Method::Tls => Estimator::Tls { column_scaling: true },
                Method::TlsUnscaled => Estimator::Tls { column_scaling: false },
                Method::Ridge => Estimator::Ridge { lambda: self.lambda },
                Method::Consistent => Estimator::Consistent,
            },
            accumulation: match self.accumulation {
                AccumulationArg::Qr => Accumulation::Qr,
                AccumulationArg::NormalEquations => Accumulation::NormalEquations,
            },
            joints: match self.friction() {
                Friction::None => JointTerms::None,
                Friction::Sign => JointTerms::Friction(Coulomb::Sign),
                Friction::Smooth => JointTerms::Friction(Coulomb::Smooth { epsilon: self.epsilon }),
                Friction::Auto => JointTerms::FrictionAuto,
                Friction::Stribeck => JointTerms::Stribeck(Coulomb::Sign),
                Friction::StribeckSmooth => JointTerms::Stribeck(Coulomb::Smooth { epsilon: self.epsilon }),
                // Replaced by the choice (`dyngen_identify::choice`) once the recording is read.
                Friction::Best => JointTerms::Friction(Coulomb::Sign),
            },
            rotor_inertia: self.rotor_inertia.map(|r| r == YesNo::Yes),
            // With best, the terms the choice may add (`run`).
            extras: match self.friction() {
                Friction::Best => ExtraTerms::NONE,
                _ => self.extra_terms.unwrap_or(ExtraTerms::NONE),
            },
            exclude_below: self.exclude_below,
            cutoff_hz: self.recording.cutoff(),
            low_pass_states: !self.recording.raw_states,
            model_is_truth: self.truth_from_urdf,
            ..IdentifyOptions::default()
        }
    }
}

pub fn run(args: &IdentifyArgs, progress: &Progress) -> Result<()> {
    if args.mode == Mode::Mim && args.method.is_some() {
        return Err(CliError::usage(
            "--method applies to --mode standard and principal; MIM always uses least squares weighted per body axis",
        ));
    }
    if args.mode == Mode::Mim && args.accumulation != AccumulationArg::Qr {
        return Err(CliError::usage(
            "--accumulation applies to --mode standard and principal; MIM accumulates by QR",
        ));
    }
    if args.friction == Some(Friction::Best) {
        if args.partial.is_some() || !args.merge.is_empty() {
            return Err(CliError::usage(
                "--friction best cannot be written as or solved from partial factors: it fits every candidate \
                 model on time blocks of the recording's rows; choose on one recording, then use the model it \
                 printed",
            ));
        }
        if args.rotor_inertia.is_some() {
            return Err(CliError::usage(
                "--friction best chooses the rotor inertia too (with and without); drop --rotor-inertia",
            ));
        }
    }
    if args.partial.is_some() || !args.merge.is_empty() {
        if args.residual.is_some() {
            return Err(CliError::usage(
                "--residual trains on the recording's samples, which partial factors do not keep; train it on one \
                 recording",
            ));
        }
        return crate::partial::run(args, progress);
    }
    let data = args
        .data
        .as_deref()
        .ok_or_else(|| CliError::usage("give the recording DATA, or --merge PART…"))?;
    let mut options = args.options();
    check_outputs(args)?;
    let model = load_moving_model(&args.urdf, &args.recording.gravity)?;
    // The recording's joints: one per velocity coordinate (a joint that follows
    // another has none).
    let n = model.nv();
    options.gear_ratios = args
        .gear_ratios
        .as_deref()
        .map(|text| crate::ranges::per_joint("--gear-ratios", text, n))
        .transpose()?;
    options.check().map_err(|e| pipeline_error(data, e))?;
    let recipe = args.recording.recipe.recipe()?;
    // Drive gains first: the recordings are then read as torques, with them.
    let recipe = match &args.drive.drive_gains {
        Some(loaded) => crate::gains::identify(args, &model, data, loaded, &recipe)?,
        None => recipe,
    };
    // The validation recording's recipe, checked before any work.
    let validation_recipe = match &args.validate_recipe {
        Some(path) => Recipe::from_file(path).map_err(|e| CliError::input(path, e))?,
        None => recipe.without_window(),
    };
    let validation_recipe = match &args.validate_window {
        Some(window) => {
            let mut r = validation_recipe;
            r.set("window", window)
                .map_err(|e| CliError::usage(format!("--validate-window: {e}")))?;
            r
        }
        None => validation_recipe,
    };
    validation_recipe
        .check()
        .map_err(|e| CliError::Input(format!("validation recipe: {e}")))?;
    let cutoff = args.recording.cutoff();
    let low_pass_states = !args.recording.raw_states;
    let traj = load_recording(data, &recipe, n, cutoff, low_pass_states)?;
    if args.mode == Mode::Mim && traj.joint_wrenches().is_none() {
        return Err(pipeline_error(data, PipelineError::MissingWrenches { dof: n }));
    }
    outln!("{} samples of {} joints from {}", traj.len(), n, data.display());
    let training = DataSpan::of(data, &traj);
    if args.validate.is_some() {
        outln!("training: {}", describe_span(&training));
    }
    let robot = Reference::new(&model);
    let options = if args.friction.is_none() && args.friction() == Friction::Best && traj.len() < MIN_SAMPLES {
        // Too short to choose on time blocks: the rigid bodies alone, by default.
        IdentifyOptions {
            joints: JointTerms::None,
            ..options
        }
    } else if args.friction() == Friction::Best {
        let choice = with_spinner(progress, "choosing the joint model", || {
            let allowed = args.extra_terms.unwrap_or(DEFAULT_EXTRAS);
            dyngen_identify::choice::choose(&robot, &traj, &options, allowed)
        })
        .map_err(|e| pipeline_error(data, e))?;
        out!("{choice}");
        choice.apply(&options)
    } else {
        options
    };
    let identified = with_spinner(progress, "identifying", || pipeline::identify(&robot, &traj, &options))
        .map_err(|e| pipeline_error(data, e))?;
    for w in &identified.warnings {
        eprintln!("warning: {w}");
    }
    let mut identified = identified;
    if let Some(prediction) = identified.report.prediction.as_mut() {
        if let Some(pre) = prediction.preprocessing.as_mut() {
            pre.recipe = Some(recipe.without_window().to_text());
            pre.window = recipe.window_text();
            pre.data = Some(training.clone());
            pre.gravity = args.recording.gravity.get()?;
        }
    }
    let identified = identified;
    if options.joints == JointTerms::FrictionAuto {
        if let Some(epsilons) = identified
            .report
            .prediction
            .as_ref()
            .and_then(|p| p.preprocessing.as_ref())
            .and_then(|p| p.coulomb_epsilons.as_ref())
        {
            let list: Vec<String> = epsilons.iter().map(|e| format!("{e:.4e}")).collect();
            outln!(
                "--friction auto: Coulomb smoothing tanh(q̇_j/ε_j) with ε per joint {} rad/s (m/s for prismatic \
                 joints), chosen on held-out time blocks",
                list.join(", ")
            );
        }
    }
    if let Some(speed) = args.exclude_below {
        let total: usize = identified.excluded_rows.iter().sum();
        let per_joint: Vec<String> = identified.excluded_rows.iter().map(usize::to_string).collect();
        outln!(
            "--exclude-below {speed}: left out {total} of {} torque rows (|q̇| below it; per joint: {})",
            traj.len() * n,
            per_joint.join(", ")
        );
    }
    print_identification(args, &model, &identified, Some(&traj))?;
    write_outputs(args, data, &model, &identified)?;
    if let Some(path) = &args.svg {
        write_svg(args, data, path, &robot, &traj, &identified, progress)?;
    }
    let residual = match &args.residual {
        None => None,
        Some(path) => {
            let predicted = identified.predict(&robot, &traj).map_err(|e| pipeline_error(data, e))?;
            let fit = with_spinner(progress, "training the residual network", || {
                fit_residual(&traj, &predicted, &ResidualOptions::default())
            })
            .map_err(|e| CliError::failed(format!("--residual: {e}")))?;
            outln!("{fit}");
            if fit.kept {
                fit.net.save(path, args.force).map_err(|e| match e {
                    NimError::AlreadyExists { .. } => CliError::OutputExists(path.clone()),
                    e => CliError::output(path, e),
                })?;
                outln!("wrote the residual network to {}", path.display());
                Some(fit.net)
            } else {
                outln!("--residual: {} not written", path.display());
                None
            }
        }
    };
    if let Some(path) = &args.validate {
        let other = load_recording(path, &validation_recipe, n, cutoff, low_pass_states)?;
        let how = match (&args.validate_recipe, &args.validate_window) {
            (Some(r), _) => format!("read through --validate-recipe {}", r.display()),
            (None, _) => "read through the training recipe".to_string(),
        };
        let window = match (&args.validate_window, recipe.window_text()) {
            (Some(w), _) => format!("--validate-window {w}"),
            (None, Some(training)) => format!("all of it: the training window ({training}) is not applied to it"),
            (None, None) => "all of it".to_string(),
        };
        outln!(
            "validation: {} ({how}; {window})",
            describe_span(&DataSpan::of(path, &other))
        );
        let predicted = with_spinner(progress, "predicting the validation recording", || {
            identified.predict(&robot, &other)
        })
        .map_err(|e| pipeline_error(path, e))?;
        let validation = crate::validate::validation(&model, &other, &predicted, None)?;
        outln!(
            "prediction of {}:\n{validation}\n{}",
            path.display(),
            crate::validate::exact_overall(&validation)
        );
        if let Some(net) = &residual {
            let with = crate::validate::with_residual(net, &other, predicted, path)?;
            let validation = crate::validate::validation(&model, &other, &with, None)?;
            outln!(
                "prediction of {} with the learned residual:\n{validation}\n{}",
                path.display(),
                crate::validate::exact_overall(&validation)
            );
        }
    }
    Ok(())
}

/// The estimate's table, fit and notes (`traj`: the recording, for the friction
/// hint; `None` for merged partial factors).
pub fn print_identification(
    args: &IdentifyArgs,
    model: &Model,
    identified: &Identification,
    traj: Option<&Trajectory>,
) -> Result<()> {
    match (&identified.prediction, &identified.mim) {
        (_, Some(mim)) => outln!("{mim}"),
        (Prediction::Regressor(torque), None) => {
            let names: Vec<&str> = torque.names.iter().map(String::as_str).collect();
            outln!("{}", torque.estimate.table(&names));
            if let Some(prediction) = &identified.report.prediction {
                for p in &prediction.nonphysical {
                    outln!(
                        "non-physical: {} = {:.4e} (joint `{}`): {}",
                        p.parameter,
                        p.value,
                        p.joint,
                        p.reason
                    );
                }
            }
            print_fit(&torque.estimate)?;
            if let Some(fit) = &identified.stribeck {
                out!("{fit}");
            }
            if args.mode == Mode::Standard && args.friction() == Friction::None {
                if let Some(traj) = traj {
                    hint_friction(&torque.estimate, traj)?;
                }
            }
            if args.truth_from_urdf {
                print_errors(identified, model)?;
            }
        }
        (Prediction::Parameters(_), None) => {}
    }

    Ok(())
}

/// --params-json and --urdf-out; `source` names the data in errors.
pub fn write_outputs(args: &IdentifyArgs, source: &Path, model: &Model, identified: &Identification) -> Result<()> {
    if let Some(path) = &args.params_json {
        identified
            .report
            .write(path, args.force)
            .map_err(|e| CliError::report(path, e))?;
        outln!("wrote the parameters to {}", path.display());
    }
    if let Some(path) = &args.urdf_out {
        write_urdf(args, source, path, model, identified)?;
    }
    Ok(())
}

/// Each identified parameter against the URDF's value (torque modes; MIM prints its
/// own error table).
fn print_errors(identified: &Identification, model: &Model) -> Result<()> {
    let errors = identified.errors(model);
    match errors.worst {
        Some((w, name)) => outln!(
            "against the URDF: {} identified parameters with a nonzero true value, largest relative error {w:.3e} ({name})",
            errors.compared
        ),
        None => outln!("against the URDF: no identified parameter with a nonzero true value"),
    }
    Ok(())
}

/// Refuses, before any work, existing output files without --force and two
/// outputs to the same file.
pub fn check_outputs(args: &IdentifyArgs) -> Result<()> {
    let beside = joint_params_output(args);
    let outputs: Vec<(&str, &PathBuf)> = [
        ("--params-json", &args.params_json),
        ("--svg", &args.svg),
        ("--urdf-out", &args.urdf_out),
        ("--urdf-out's joint parameters", &beside),
        ("--residual", &args.residual),
    ]
    .into_iter()
    .filter_map(|(flag, p)| p.as_ref().map(|p| (flag, p)))
    .collect();
    for (i, (flag, path)) in outputs.iter().enumerate() {
        if let Some((other, _)) = outputs[..i].iter().find(|(_, p)| p == path) {
            return Err(CliError::usage(format!(
                "{other} and {flag} both name {}; give each output its own file",
                path.display()
            )));
        }
        check_overwrite(path, args.force)?;
    }
    if args.lump_merged && args.urdf_out.is_none() {
        return Err(CliError::usage("--lump-merged only applies with --urdf-out"));
    }
    Ok(())
}

/// Whether the identification has joint terms (friction or rotor inertia).
fn has_joint_terms(args: &IdentifyArgs) -> bool {
    args.mode == Mode::Standard && (args.friction() != Friction::None || args.rotor_inertia == Some(YesNo::Yes))
}

/// Where --urdf-out's companion file goes: beside the URDF, its name with
/// `.joint-params.json` for the extension (`ur5-id.urdf` → `ur5-id.joint-params.json`);
/// `None` without --urdf-out or without joint terms.
pub fn joint_params_output(args: &IdentifyArgs) -> Option<PathBuf> {
    let urdf = args.urdf_out.as_ref().filter(|_| has_joint_terms(args))?;
    Some(joint_params_path(urdf))
}

/// `dir/name.urdf` → `dir/name.joint-params.json`.
pub fn joint_params_path(urdf: &Path) -> PathBuf {
    let stem = urdf
        .file_stem()
        .map_or_else(|| "robot".into(), |s| s.to_string_lossy().into_owned());
    urdf.with_file_name(format!("{stem}.joint-params.json"))
}

/// Measured against predicted torques (regressor rows times the estimate's
/// solution, valid on the identifiable subspace; for MIM, inverse dynamics of the
/// identified model), and with --truth-from-urdf the relative errors of the
/// parameters that have a value.
fn write_svg(
    args: &IdentifyArgs,
    data: &Path,
    path: &Path,
    robot: &Reference,
    traj: &Trajectory,
    identified: &Identification,
    progress: &Progress,
) -> Result<()> {
    let model = dyngen_reference::Dynamics::model(robot);
    let predicted = with_spinner(progress, "predicting torques", || identified.predict(robot, traj))
        .map_err(|e| pipeline_error(data, e))?;
    let errors = match args.truth_from_urdf {
        true => {
            let errors = identified.errors(model);
            if !errors.zero_truth.is_empty() {
                outln!(
                    "note: parameter errors leave out {} (identified, but zero in the URDF, so no relative error)",
                    errors.zero_truth.join(", ")
                );
            }
            Some(errors.relative)
        }
        false => None,
    };
    let method = &identified.report.method;
    let svg = report::identification_report(model, method, data, traj, &predicted, errors.as_deref())
        .map_err(|e| CliError::report(path, e))?;
    report::write_report(path, &svg, args.force).map_err(|e| CliError::report(path, e))?;
    outln!("wrote the SVG report to {}", path.display());
    Ok(())
}

/// The input URDF with the inertials of the fully identified, physically valid
/// bodies replaced; every other byte is kept.
fn write_urdf(
    args: &IdentifyArgs,
    source: &Path,
    path: &Path,
    model: &Model,
    identified: &Identification,
) -> Result<()> {
    let text = std::fs::read_to_string(&args.urdf).map_err(|e| CliError::input(&args.urdf, e))?;
    let merged = if args.lump_merged {
        MergedLinks::Lump
    } else {
        MergedLinks::Refuse
    };
    let rewrite = identified.rewrite_urdf(&text, model, merged).map_err(|e| match e {
        PipelineError::Report(e) => CliError::input(&args.urdf, e),
        e => pipeline_error(source, e),
    })?;
    report::write_new(path, &rewrite.text, args.force).map_err(|e| CliError::report(path, e))?;
    if rewrite.updated.is_empty() {
        outln!(
            "wrote {}{}: no body has all its parameters identified, so every inertial is the URDF's",
            path.display(),
            if rewrite.dynamics.is_empty() { " unchanged" } else { "" }
        );
    } else {
        let names: Vec<&str> = rewrite.updated.iter().map(|(n, _)| n.as_str()).collect();
        outln!(
            "wrote {} with the identified inertials of {}",
            path.display(),
            names.join(", ")
        );
    }
    if !rewrite.dynamics.is_empty() {
        let joints: Vec<String> = rewrite
            .dynamics
            .iter()
            .map(|(j, fv, fc)| format!("{j} (Fv {fv:.4}, Fc {fc:.4})"))
            .collect();
        outln!("with the identified <dynamics> of {}", joints.join(", "));
    }
    for (joint, why) in &rewrite.dynamics_kept {
        outln!("note: kept the URDF's <dynamics> of {joint}: {why}");
    }
    // Beside the URDF when the identification has joint terms (with --merge, the
    // partials' friction decides, not the flags).
    let joint_terms = identified.report.parameterisation == Parameterisation::StandardAndJoints;
    if let Some(beside) = joint_terms.then(|| joint_params_path(path)) {
        let in_urdf: Vec<&str> = rewrite.dynamics.iter().map(|(j, _, _)| j.as_str()).collect();
        let name = path.file_name().map(|f| f.to_string_lossy().into_owned());
        let file = identified
            .joint_params_file(model, name.as_deref(), &in_urdf)
            .ok_or_else(|| CliError::failed("the identification has no joint terms to write"))?;
        file.write(&beside, args.force)
            .map_err(|e| CliError::report(&beside, e))?;
        outln!(
            "wrote every identified joint term (Ia, Fv, Fc, F0{}, the Coulomb model), including those a URDF cannot \
             hold, to {}",
            if identified.stribeck.is_some() { ", Fs, vs" } else { "" },
            beside.display()
        );
    }
    if !rewrite.kept.is_empty() {
        let kept: Vec<String> = rewrite
            .kept
            .iter()
            .map(|(body, why)| format!("{body} ({why})"))
            .collect();
        outln!(
            "note: kept the URDF inertials of {} of {} bodies: {}",
            kept.len(),
            model.bodies.len(),
            kept.join("; ")
        );
        if args.mode != Mode::Mim {
            outln!(
                "note: this is expected: joint torques determine only the base parameters (combinations), \
                 so few bodies, if any, have all their parameters identifiable; see --params-json for the \
                 combinations, or identify body by body from joint wrenches with --mode mim"
            );
        }
    }
    Ok(())
}

/// Torque residuals per joint and relative to the measured torques.
/// Rigid bodies alone leave a real robot's friction in the residual: say so when the
/// residual of a joint is a noticeable part of its torque.
fn hint_friction(estimate: &Estimate, traj: &Trajectory) -> Result<()> {
    let n = traj.dof();
    let worst = (0..n)
        .filter_map(|j| {
            let rms = ((0..traj.len()).map(|k| traj.tau(k)[j].powi(2)).sum::<f64>() / traj.len() as f64).sqrt();
            let r = *estimate.residuals.per_channel_rms.get(j)?;
            (rms > 0.0).then_some((r / rms, j))
        })
        .max_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((ratio, j)) = worst {
        if ratio > FRICTION_HINT {
            outln!(
                "note: rigid bodies alone leave {:.0} % of joint {}'s torque unexplained; a real robot's joints add \
                 friction and rotor inertia: try --friction best (the default), which chooses them",
                100.0 * ratio,
                j + 1
            );
        }
    }
    Ok(())
}

/// A joint's residual RMS above this fraction of its torque RMS prompts the
/// friction hint.
const FRICTION_HINT: f64 = 0.05;

fn print_fit(estimate: &Estimate) -> Result<()> {
    let r = &estimate.residuals;
    let per_joint: Vec<String> = r.per_channel_rms.iter().map(|x| format!("{x:.3e}")).collect();
    outln!(
        "torque residual RMS {:.3e} N·m over {} rows (per joint: {}); {} of {} parameter directions identifiable",
        r.rms,
        r.rows,
        per_joint.join(", "),
        estimate.rank,
        estimate.n_params()
    );
    Ok(())
}
