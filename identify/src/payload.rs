//! Payloads: a load rigidly fixed to one body of a robot whose own parameters are
//! known. The load's 10 standard parameters `π_L` (in the carrying body's frame)
//! enter the joint torques exactly as that body's own do, so with `Y_b` the 10
//! columns of the standard regressor that belong to body `b`,
//!
//! ```text
//! τ − τ_known(q, q̇, q̈) = Y_b(q, q̇, q̈) · π_L
//! ```
//!
//! where `τ_known` is the robot without the load (rigid bodies, and the joint models
//! when given). [`identify`] solves this by least squares over a recording and turns
//! `π_L` into mass, centre of mass and inertia with their standard deviations;
//! [`Payload`] is a load of known parameters (what [`crate::gains`] calibrates drive
//! gains with, and what [`PayloadEstimate::payload`] gives back).

use crate::data::Trajectory;
use crate::mim::TorqueRegressor;
use crate::{Accumulator, IdentifyError, Options};
use dyngen_model::joint_params::Coulomb;
use dyngen_reference::Dynamics;

/// Standard parameters per body (and per payload).
const PER_BODY: usize = 10;

/// A load of known mass properties fixed to one body.
#[derive(Clone, Debug, PartialEq)]
pub struct Payload {
    /// The carrying body, `1..=n`.
    pub body: usize,
    /// Its standard parameters in that body's frame (`[m, m·c, I about the body
    /// origin]`, 10, the order of the standard parameters).
    pub params: [f64; 10],
}

impl Payload {
    /// A load of mass `mass` (kg) with its centre of mass at `com` (m, carrying
    /// body's frame) and inertia `inertia` about the centre of mass (kg·m², body axes).
    pub fn from_mass_properties(body: usize, mass: f64, com: [f64; 3], inertia: [[f64; 3]; 3]) -> Payload {
        let inertial = dyngen_model::Inertial { mass, com, inertia };
        Payload {
            body,
            params: inertial.standard_params(),
        }
    }

    /// An error naming the body unless it is a moving body of an `n`-body robot.
    pub fn check_body(body: usize, n: usize) -> Result<(), IdentifyError> {
        if body == 0 || body > n {
            return Err(IdentifyError::InvalidArgument {
                what: "payload body",
                reason: format!("{body} is not a moving body (1..={n})"),
            });
        }
        Ok(())
    }

    /// The load's torque on one joint, `Y_b · π_L`, from that joint's row of a
    /// regressor whose first `10n` columns are the standard ones.
    pub fn torque(&self, regressor_row: &[f64]) -> f64 {
        let at = PER_BODY * (self.body - 1);
        regressor_row[at..at + PER_BODY]
            .iter()
            .zip(&self.params)
            .map(|(y, p)| y * p)
            .sum()
    }
}

/// The robot a payload is identified on: its dynamics and its parameters without
/// the load.
#[derive(Clone, Copy)]
pub struct KnownRobot<'a> {
    pub dynamics: &'a dyn Dynamics,
    /// Standard parameters, `10n`.
    pub params: &'a [f64],
    /// Joint parameters `[Ia, Fv, Fc, F0]` (`4n`) and the Coulomb model, when the
    /// recorded torques include the drives ([`dyngen_model::joint_params`]).
    pub joints: Option<(&'a [f64], Coulomb)>,
}

/// A payload identified from a recording.
#[derive(Clone, Debug, PartialEq)]
pub struct PayloadEstimate {
    pub body: usize,
    /// `π_L`: `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, inertia about the
    /// body origin, in the carrying body's frame.
    pub params: [f64; 10],
    /// Standard deviation of each of `params`.
    pub sigma: [f64; 10],
    /// Mass, kg, and its standard deviation.
    pub mass: f64,
    pub mass_sigma: f64,
    /// Centre of mass `m·c / m`, m, in the body frame, and its standard deviations
    /// (first order, from the covariance of `m` and `m·c`).
    pub com: [f64; 3],
    pub com_sigma: [f64; 3],
    /// Inertia about the centre of mass, kg·m², body axes.
    pub inertia: [[f64; 3]; 3],
    /// RMS of the residual torques, N·m, and the rows used.
    pub residual_rms: f64,
    pub rows: usize,
    /// `σ₁ / σ₁₀` of the 10 payload columns over the recording.
    pub condition_number: f64,
}

impl PayloadEstimate {
    /// The estimate as a known [`Payload`].
    pub fn payload(&self) -> Payload {
        Payload {
            body: self.body,
            params: self.params,
        }
    }
}

/// Names of the 10 payload parameters, for errors.
const NAMES: [&str; PER_BODY] = ["m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz"];

/// Identifies the load on `body` (`1..=n`) from `data` (joint positions,
/// velocities, accelerations and torques of the loaded robot): ordinary least squares
/// on `τ − τ_known = Y_body · π_L` over every sample. Errors name what is wrong: a
/// body that is not a moving body, parameter vectors of the wrong length, a
/// recording without velocities or accelerations or of another robot, or a motion
/// that does not determine one of the 10 parameters (e.g. a joint that never moved).
pub fn identify(
    robot: &KnownRobot<'_>,
    body: usize,
    data: &Trajectory,
    opts: &Options,
) -> Result<PayloadEstimate, IdentifyError> {
    let n = robot.dynamics.nv();
    Payload::check_body(body, robot.dynamics.model().dof())?;
    if data.dof() != n {
        return Err(IdentifyError::DimensionMismatch {
            what: "joints of the recording",
            expected: n,
            found: data.dof(),
        });
    }
    let mut known: Vec<f64> = robot.params.to_vec();
    if known.len() != PER_BODY * n {
        return Err(IdentifyError::DimensionMismatch {
            what: "robot standard parameters",
            expected: PER_BODY * n,
            found: known.len(),
        });
    }
    let regressor = match robot.joints {
        None => TorqueRegressor::Standard,
        Some((joint_params, coulomb)) => {
            let expected = dyngen_model::joint_params::PER_JOINT * n;
            if joint_params.len() != expected {
                return Err(IdentifyError::DimensionMismatch {
                    what: "robot joint parameters",
                    expected,
                    found: joint_params.len(),
                });
            }
            known.extend_from_slice(joint_params);
            TorqueRegressor::StandardAndJoints(coulomb.into())
        }
    };
    let p = regressor.columns(robot.dynamics.model());
    let at = PER_BODY * (body - 1);
    let mut y = vec![0.0; n * p];
    let mut acc = Accumulator::new(PER_BODY);
    for s in data.samples() {
        let (Some(v), Some(a)) = (s.v, s.a) else {
            return Err(IdentifyError::InvalidArgument {
                what: "recording",
                reason: "velocities and accelerations are needed (estimate them first)".into(),
            });
        };
        let tau_known = regressor.predict(robot.dynamics, s.q, v, a, &known, &mut y);
        for j in 0..n {
            let row = &y[j * p + at..j * p + at + PER_BODY];
            acc.push_row(row, s.tau[j] - tau_known[j])?;
        }
    }
    let est = acc.ols(opts)?;
    let mut params = [0.0; PER_BODY];
    let mut sigma = [0.0; PER_BODY];
    for (k, e) in est.params.iter().enumerate() {
        params[k] = e.value.ok_or_else(|| IdentifyError::InvalidArgument {
            what: "recording",
            reason: format!(
                "the motion does not determine the payload's {} on body {body} (rank {} of 10)",
                NAMES[k], est.rank
            ),
        })?;
        sigma[k] = e.sigma.unwrap_or(0.0);
    }
    // `None` exactly when the mass is not positive.
    let Some(inertial) = dyngen_model::Inertial::from_standard_params(&params) else {
        return Err(IdentifyError::InvalidArgument {
            what: "payload mass",
            reason: format!(
                "identified as {:e} kg (± {:.1e}): is there a load on body {body}?",
                params[0], sigma[0]
            ),
        });
    };
    let (mass, com) = (inertial.mass, inertial.com);
    // c = h/m: dc = dh/m − h dm/m², so var c = (var h − 2 c cov(h, m) + c² var m)/m².
    let com_sigma = std::array::from_fn(|i| match &est.covariance {
        Some(cov) => {
            let (vh, vm, chm) = (cov[(i + 1, i + 1)], cov[(0, 0)], cov[(i + 1, 0)]);
            let c = com[i];
            (vh - 2.0 * c * chm + c * c * vm).max(0.0).sqrt() / mass
        }
        None => 0.0,
    });
    let sv = &est.singular_values;
    Ok(PayloadEstimate {
        body,
        params,
        sigma,
        mass,
        mass_sigma: sigma[0],
        com,
        com_sigma,
        inertia: inertial.inertia,
        residual_rms: est.residuals.rms,
        rows: est.residuals.rows,
        condition_number: sv.first().copied().unwrap_or(0.0) / sv.last().copied().unwrap_or(f64::NAN),
    })
}
