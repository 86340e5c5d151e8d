//! The identified joint terms a URDF cannot hold, written beside the URDF that
//! `--urdf-out` rewrites.
//!
//! URDF's `<dynamics damping=".." friction=".."/>` holds a joint's viscous (`Fv`)
//! and Coulomb (`Fc`) friction; the rotor inertia `Ia`, the torque offset `F0`, the
//! Stribeck terms `Fs`, `vs` and the Coulomb smoothing `ε` have no place there.
//! This file holds every identified joint term, those in the URDF too, so that one
//! file says what the model of each joint is:
//!
//! ```json
//! {
//!   "schema": "dyngen-joint-params/1",
//!   "robot": "ur5",
//!   "urdf": "ur5-identified.urdf",          // the URDF written beside it
//!   "coulomb": { "kind": "tanh", "epsilon": 0.0072 },   // or { "kind": "sign" }
//!   "joints": [
//!     {
//!       "name": "shoulder_pan_joint",
//!       "in_urdf": true,                     // Fv and Fc written to its <dynamics>
//!       "parameters": [
//!         { "name": "Ia1", "value": 0.41, "sigma": 0.002, "sigma_percent": 0.5, "status": "identified" },
//!         { "name": "Fv1", ... }, { "name": "Fc1", ... }, { "name": "F0_1", ... },
//!         { "name": "Fs1", ... }, { "name": "vs1", ... }      // Stribeck friction only
//!       ]
//!     }
//!   ]
//! }
//! ```
//!
//! Each parameter is as in the parameter JSON ([`super::ParamReport`]: `null`
//! without a value; `excluded` for a term left out of the model). The joint's
//! torque is `Ia·q̈ + Fv·q̇ + (Fc + (Fs − Fc)·exp(−(q̇/vs)²))·s(q̇) + F0`, `s` the
//! sign or `tanh(q̇/ε)`, and without Stribeck terms `Fs = Fc`.

use serde::{Deserialize, Serialize};

use super::{write_new, CoulombReport, ParamReport, ReportError};

/// The `schema` field of a joint parameter file.
pub const JOINT_PARAMS_SCHEMA: &str = "dyngen-joint-params/1";

/// Every identified joint term, per joint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointParamsFile {
    pub schema: String,
    pub robot: String,
    /// The URDF this file accompanies (its file name), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub urdf: Option<String>,
    /// How the Coulomb term `Fc·s(q̇)` was modelled.
    pub coulomb: CoulombReport,
    pub joints: Vec<JointParams>,
}

/// One joint's terms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointParams {
    pub name: String,
    /// `Fv` and `Fc` were written to the joint's `<dynamics>` in the URDF.
    pub in_urdf: bool,
    /// `Ia, Fv, Fc, F0`, then `Fs, vs` with Stribeck friction, or the extra terms
    /// (`Fva, Ts1, Tc1, Fcs1, Fcc1, …, Fcl`) with them.
    pub parameters: Vec<ParamReport>,
    /// `ε` of this joint's `tanh(q̇/ε)` where the fit chose one per joint (`coulomb`
    /// then has the first joint's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub epsilon: Option<f64>,
}

impl JointParamsFile {
    /// The file's text; a value or σ that is not finite is an error.
    pub fn to_json(&self) -> Result<String, ReportError> {
        for joint in &self.joints {
            for (k, p) in joint.parameters.iter().enumerate() {
                if [p.value, p.sigma].iter().flatten().any(|x| !x.is_finite()) {
                    return Err(ReportError::NonFinite {
                        what: format!("joint `{}` parameter {}", joint.name, p.name),
                        index: k,
                    });
                }
            }
        }
        let mut s = serde_json::to_string_pretty(self).map_err(|e| ReportError::Json {
            message: e.to_string(),
            line: e.line(),
            column: e.column(),
        })?;
        s.push('\n');
        Ok(s)
    }

    /// Parses a file, checking the `schema` field.
    pub fn from_json(text: &str) -> Result<JointParamsFile, ReportError> {
        let file: JointParamsFile = serde_json::from_str(text).map_err(|e| ReportError::Json {
            message: e.to_string(),
            line: e.line(),
            column: e.column(),
        })?;
        if file.schema != JOINT_PARAMS_SCHEMA {
            return Err(ReportError::Json {
                message: format!(
                    "unsupported schema `{}` (expected `{JOINT_PARAMS_SCHEMA}`)",
                    file.schema
                ),
                line: 1,
                column: 1,
            });
        }
        Ok(file)
    }

    /// Writes the file to `path`; an existing file is replaced only with `overwrite`.
    pub fn write(&self, path: &std::path::Path, overwrite: bool) -> Result<(), ReportError> {
        write_new(path, &self.to_json()?, overwrite)
    }
}
