//! `dyngen identify --drive-gains`: each joint's drive gain (torque constant, `τ = k·i`)
//! identified with the dynamics from two recordings of motor currents, one of them
//! with a known payload (Gautier and Briot's global identification,
//! [`dyngen_identify::gains`]).

use crate::common::{outln, Result};
use crate::error::CliError;
use crate::identify::{load_recording, Friction, IdentifyArgs, YesNo};
use dyngen_identify::data::Recipe;
use dyngen_identify::gains::identify_gains;
use dyngen_identify::payload::Payload;
use dyngen_identify::Options;
use dyngen_model::desc::{inertia_violation, INERTIA_TOLERANCE};
use dyngen_model::joint_params::Coulomb;
use dyngen_model::{Inertial, Model};
use dyngen_reference::Reference;
use std::path::Path;

/// The flags of drive-gain identification.
#[derive(Debug, Default, clap::Args)]
pub struct DriveGainArgs {
    /// Identify each joint's drive gain k (τ = k·i) with the dynamics: DATA and
    /// LOADED hold motor currents in their torque columns, LOADED recorded with the
    /// known payload of --payload-mass and --payload-frame. The parameters are then
    /// identified from DATA read with the identified gains, which the parameters
    /// JSON records for `dyngen validate`.
    #[arg(
        long,
        value_name = "LOADED",
        requires_all = ["payload_mass", "payload_frame"],
        conflicts_with_all = ["gains", "partial", "merge"]
    )]
    pub drive_gains: Option<std::path::PathBuf>,

    /// --drive-gains: the payload's mass, kg (positive).
    #[arg(long, value_name = "KG", requires = "drive_gains", allow_negative_numbers = true)]
    pub payload_mass: Option<f64>,

    /// --drive-gains: the link or frame the payload is fixed to; its centre of mass
    /// and inertia are given in this frame.
    #[arg(long, value_name = "NAME", requires = "drive_gains")]
    pub payload_frame: Option<String>,

    /// --drive-gains: the payload's centre of mass in --payload-frame, m (default: its origin).
    #[arg(long, value_name = "X,Y,Z", requires = "drive_gains", allow_hyphen_values = true)]
    pub payload_com: Option<String>,

    /// --drive-gains: the payload's inertia about its centre of mass in the axes of
    /// --payload-frame, kg·m²: IXX,IYY,IZZ or IXX,IYY,IZZ,IXY,IXZ,IYZ (default: a point mass).
    #[arg(
        long,
        value_name = "IXX,IYY,IZZ[,IXY,IXZ,IYZ]",
        requires = "drive_gains",
        allow_hyphen_values = true
    )]
    pub payload_inertia: Option<String>,
}

impl DriveGainArgs {
    /// The payload in the frame of the body carrying it.
    pub fn payload(&self, model: &Model) -> Result<Payload> {
        let mass = self.payload_mass.unwrap_or(f64::NAN);
        if !(mass.is_finite() && mass > 0.0) {
            return Err(CliError::usage(format!(
                "--payload-mass: {mass} is not a mass; give the payload's mass in kg, a positive number"
            )));
        }
        let name = self.payload_frame.as_deref().unwrap_or_default();
        let frame = model.frame_index(name).map(|f| &model.frames[f]).ok_or_else(|| {
            let names: Vec<&str> = model.frames.iter().map(|f| f.name.as_str()).collect();
            CliError::usage(format!(
                "--payload-frame: the robot has no link or frame `{name}`; it has {}",
                names.join(", ")
            ))
        })?;
        if frame.body == 0 {
            return Err(CliError::usage(format!(
                "--payload-frame: `{name}` is fixed to the base, where a payload changes no joint torque; give a \
                 link that moves"
            )));
        }
        let com = match &self.payload_com {
            Some(text) => numbers("--payload-com", text, &[3])?,
            None => vec![0.0; 3],
        };
        let inertia = match &self.payload_inertia {
            Some(text) => {
                let v = numbers("--payload-inertia", text, &[3, 6])?;
                let (xy, xz, yz) = if v.len() == 6 {
                    (v[3], v[4], v[5])
                } else {
                    (0.0, 0.0, 0.0)
                };
                [[v[0], xy, xz], [xy, v[1], yz], [xz, yz, v[2]]]
            }
            None => [[0.0; 3]; 3],
        };
        let inertial = Inertial {
            mass,
            com: [com[0], com[1], com[2]],
            inertia,
        };
        let violation = inertia_violation(inertial.principal_axes().0);
        if violation > INERTIA_TOLERANCE {
            return Err(CliError::usage(format!(
                "--payload-inertia: not the inertia of a body: its principal moments break positive \
                 definiteness or the triangle inequality by {:.1} % of the largest",
                100.0 * violation
            )));
        }
        let carried = inertial.transformed(&frame.placement);
        Ok(Payload::from_mass_properties(
            frame.body,
            carried.mass,
            carried.com,
            carried.inertia,
        ))
    }
}

/// Comma-separated finite numbers, as many as one of `counts`.
fn numbers(flag: &str, text: &str, counts: &[usize]) -> Result<Vec<f64>> {
    let values: Option<Vec<f64>> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect();
    match values {
        Some(v) if counts.contains(&v.len()) => Ok(v),
        _ => Err(CliError::usage(format!(
            "{flag}: `{text}` is not {} comma-separated numbers",
            counts.iter().map(usize::to_string).collect::<Vec<_>>().join(" or ")
        ))),
    }
}

/// Checks the options that drive-gain identification fixes, identifies the gains
/// from `data` and `loaded` (read through `recipe`, the currents as they are),
/// prints them, and returns `recipe` with them.
pub fn identify(args: &IdentifyArgs, model: &Model, data: &Path, loaded: &Path, recipe: &Recipe) -> Result<Recipe> {
    let coulomb = match args.friction() {
        Friction::Sign => Coulomb::Sign,
        Friction::Smooth => Coulomb::Smooth { epsilon: args.epsilon },
        _ => {
            return Err(CliError::usage(
                "--drive-gains identifies the gains with the standard parameters and the joint terms [Ia, Fv, Fc, \
                 F0], whose Coulomb term must be linear: give --friction sign or smooth",
            ))
        }
    };
    if args.rotor_inertia == Some(YesNo::No) {
        return Err(CliError::usage(
            "--drive-gains identifies the gains with the rotor inertia Ia; drop --rotor-inertia no",
        ));
    }
    if recipe.gains.is_some() {
        return Err(CliError::usage(
            "--drive-gains identifies the gains, and the recipe gives them (`gains =`); remove them from the recipe",
        ));
    }
    let payload = args.drive.payload(model)?;
    let n = model.nv();
    let cutoff = args.recording.cutoff();
    let low_pass_states = !args.recording.raw_states;
    let unloaded = load_recording(data, recipe, n, cutoff, low_pass_states)?;
    let with_payload = load_recording(loaded, &recipe.without_window(), n, cutoff, low_pass_states)?;
    let robot = Reference::new(model);
    let estimate = identify_gains(&robot, &unloaded, &with_payload, &payload, coulomb, &Options::default())
        .map_err(|e| CliError::Failed(format!("--drive-gains: {e}")))?;
    let names: Vec<&str> = model.own_joints().map(|j| j.name.as_str()).collect();
    outln!(
        "drive gains (τ = k·i, N·m/A or N/A), from {} and {} with the {} kg payload on body `{}`:",
        data.display(),
        loaded.display(),
        payload.params[0],
        model.bodies[payload.body - 1].name
    );
    for (j, name) in names.iter().enumerate() {
        outln!(
            "  k{} ({name}) = {:.6e} ± {:.2e}",
            j + 1,
            estimate.gains[j],
            estimate.gain_sigma[j]
        );
    }
    let mut with_gains = recipe.clone();
    with_gains.gains = Some(estimate.gains.clone());
    with_gains
        .check()
        .map_err(|e| CliError::Failed(format!("--drive-gains: the identified gains: {e}")))?;
    outln!("reading {} again with these gains", data.display());
    Ok(with_gains)
}
