//! Identified parameters as JSON, in a schema other tools can rely on.
//!
//! ```json
//! {
//!   "schema": "dyngen-parameters/1",
//!   "robot": "ur5",
//!   "parameterisation": "standard",          // "standard" | "principal" | "base"
//!   "method": "ordinary least squares",
//!   "rank": 36,
//!   "condition_number": 812.4,               // σ₁/σ_rank; null if not finite
//!   "residual_rms": [0.011, 0.009],          // per channel (joint), SI units
//!   "channels": ["shoulder_pan_joint", "shoulder_lift_joint"],   // may be empty
//!   "parameters": [
//!     { "name": "m1", "value": 3.7, "sigma": 0.01, "sigma_percent": 0.27, "status": "identified" },
//!     { "name": "mx1", "value": null, "sigma": null, "sigma_percent": null, "status": "in_combination" }
//!   ],
//!   "combinations": [
//!     { "expression": "mx1 + 0.425·m2", "terms": [{ "name": "mx1", "coefficient": 1.0 }, ...],
//!       "value": 1.2, "sigma": 0.003 }
//!   ],
//!   "prediction": {                          // absent for MIM
//!     "regressor": "standard_and_joints",
//!     "coulomb": { "kind": "sign" },
//!     "solution": [ ... ],
//!     "stribeck": [{ "fs": 9.0, "vs": 0.05 }, ...]   // only with Stribeck friction
//!   }
//! }
//! ```
//!
//! With Stribeck friction `parameters` ends with `Fs1, vs1, …, Fsn, vsn`
//! ([`crate::stribeck`]).
//!
//! `status` is one of `identified` (value and σ from the data), `in_combination`
//! (no value: only enters the listed combinations), `no_effect` (no value: the data
//! carry nothing about it), `from_prior` (ridge: value mostly from the prior),
//! `constrained` (value shaped by physical-consistency constraints, no σ),
//! `not_significant` (MIM: the estimate is below 3σ, so no value) and `excluded`
//! (left out of the model by choice: a joint term not fitted, or a Stribeck term
//! that fell back to the linear model; no value, no effect on the prediction). A
//! parameter without a value is `null`, never a number. `combinations` lists only
//! combinations of two or more parameters. Floats round-trip exactly.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{write_new, ReportError};
use crate::extras::ExtraTerms;
use crate::mim::{MimEstimate, Verdict};
use crate::{Estimate, Status};
use dyngen_model::names::principal_param_names;

/// The `schema` field this module writes and accepts.
pub const SCHEMA: &str = "dyngen-parameters/1";

/// Which parameter vector was identified.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameterisation {
    /// 10 per body, `[m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` about the body-frame origin.
    Standard,
    /// 4 per body, `(m, J1, J2, J3)` in the centroidal principal frame (the paper's form).
    Principal,
    /// The base parameters (identifiable combinations) only.
    Base,
    /// The standard parameters, then per joint `[Ia, Fv, Fc, F0]` (rotor inertia,
    /// viscous and Coulomb friction, offset).
    StandardAndJoints,
}

/// How the Coulomb term `Fc·s(q̇)` was modelled.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum CoulombReport {
    /// `sign(q̇)`.
    Sign,
    /// `tanh(q̇ / epsilon)`.
    Tanh { epsilon: f64 },
}

/// Enough to predict joint torques with the identified model in any tool:
/// `τ = Y(q, q̇, q̈) x` with `Y` the regressor named by `regressor` (Pinocchio's
/// `computeJointTorqueRegressor` for `standard`; for `standard_and_joints` it is
/// followed per joint by the columns `[q̈_j, q̇_j, s(q̇_j), 1]` in row `j`; for
/// `principal` it is `Y · blkdiag(P_i)`) and `x` the full solution vector (minimum
/// norm along the directions the data do not determine, which the prediction
/// does not see).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PredictionModel {
    pub regressor: Parameterisation,
    /// For `standard_and_joints`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coulomb: Option<CoulombReport>,
    /// For `standard_and_joints` with the smoothing chosen per joint: `ε_j` of
    /// `tanh(q̇_j/ε_j)`, in place of `coulomb`'s one `ε`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub epsilons: Option<Vec<f64>>,
    /// For `standard_and_joints`: the joint terms past friction, whose parameters
    /// follow the `[Ia, Fv, Fc, F0]` of every joint in the solution
    /// ([`crate::extras`]).
    #[serde(default, skip_serializing_if = "ExtraTerms::is_empty")]
    pub extras: ExtraTerms,
    /// With the extras' motor ripple: each joint's gear ratio.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gear_ratios: Option<Vec<f64>>,
    pub solution: Vec<f64>,
    /// For `standard_and_joints` with Stribeck friction: per joint the static
    /// friction `fs` and Stribeck velocity `vs`; row `j` of the prediction gains
    /// `(fs − Fc)·exp(−(q̇_j/vs)²)·s(q̇_j)`, `Fc` the joint's Coulomb entry of the
    /// solution ([`crate::stribeck`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stribeck: Option<Vec<crate::stribeck::Stribeck>>,
    /// How the recording was read and filtered before the fit; `dyngen validate`
    /// reads a recording to predict the same way. Absent in files from before it
    /// was recorded (the defaults then apply).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preprocessing: Option<Preprocessing>,
    /// Joint parameters whose reported value is not physical (negative rotor
    /// inertia, viscous or Coulomb friction).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub nonphysical: Vec<NonPhysical>,
}

/// Every preprocessing choice of an identification: what a tool needs to read and
/// filter another recording as this one was. Every field may be missing (its
/// default then); unknown fields are ignored, so later versions may add some.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Preprocessing {
    /// Zero-phase low-pass cutoff (Hz) of the estimated derivatives.
    pub cutoff_hz: Option<f64>,
    /// Measured positions and velocities low-passed at the cutoff too.
    pub low_pass_states: Option<bool>,
    /// The recipe the recording was read through, as `key = value` lines, without
    /// its time and row windows (empty: dyngen's own CSV schema).
    pub recipe: Option<String>,
    /// The training recording's window as recipe lines (`window = 5:65`,
    /// `rows = …`); not applied to other recordings.
    pub window: Option<String>,
    /// The training recording and the part of it used.
    pub data: Option<DataSpan>,
    /// Gravity in the base frame (m/s²) when it was not the model's default.
    pub gravity: Option<[f64; 3]>,
    /// `none`, `sign`, `smooth`, `auto`, `stribeck` or `stribeck_smooth`.
    pub friction: Option<String>,
    /// ε of the Coulomb smoothing `tanh(q̇/ε)` (rad/s), when smoothed with one ε.
    pub coulomb_epsilon: Option<f64>,
    /// ε of `tanh(q̇_j/ε_j)` per joint, when the fit chose them (`auto`).
    pub coulomb_epsilons: Option<Vec<f64>>,
    /// `true` when ε was chosen by the fit (one per joint).
    pub epsilon_auto: Option<bool>,
    /// Rows of a joint slower than this (rad/s) left out of the fit.
    pub exclude_below: Option<f64>,
    /// Whether the rotor inertias `Ia` were fitted (`false`: left out, 0), when
    /// joint terms were.
    pub rotor_inertia: Option<bool>,
    /// Identified from merged partial factors ([`crate::partial`]): every
    /// recording and the part of it used (`data` and `window` are then absent).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub recordings: Vec<DataSpan>,
}

/// Which samples of which file an identification used.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DataSpan {
    pub file: String,
    pub samples: usize,
    /// Where the first and last sample used are (`line 12` or `sample 0 (0-based)`).
    pub first: String,
    pub last: String,
    /// Their time stamps (s).
    pub t_first: Option<f64>,
    pub t_last: Option<f64>,
}

impl DataSpan {
    /// Which samples of the file `path` `traj` holds.
    pub fn of(path: &Path, traj: &crate::data::Trajectory) -> DataSpan {
        let last = traj.len().saturating_sub(1);
        DataSpan {
            file: path.display().to_string(),
            samples: traj.len(),
            first: traj.location(0).to_string(),
            last: traj.location(last).to_string(),
            t_first: traj.t().first().copied(),
            t_last: traj.t().last().copied(),
        }
    }
}

/// A joint parameter reported with a value that is not physical.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NonPhysical {
    /// The joint's name.
    pub joint: String,
    /// The parameter's name (`Fv3`).
    pub parameter: String,
    pub value: f64,
    /// Why it is not physical.
    pub reason: String,
}

/// [`Status`] as written in the JSON.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ParamStatus {
    Identified,
    InCombination,
    NoEffect,
    FromPrior,
    Constrained,
    /// Determined by the data but not out of its noise: MIM, `|x̂| < kσ̂`
    /// ([`crate::mim::Verdict::NotSignificant`]), without a value; joint torques,
    /// `|x̂| < σ̂`, with its value and σ for the record.
    NotSignificant,
    /// Left out of the model by choice (a joint term not fitted, a Stribeck term
    /// that fell back to the linear model): no value.
    Excluded,
}

impl From<Status> for ParamStatus {
    fn from(s: Status) -> Self {
        match s {
            Status::Identified => ParamStatus::Identified,
            Status::InCombination => ParamStatus::InCombination,
            Status::NoEffect => ParamStatus::NoEffect,
            Status::FromPrior => ParamStatus::FromPrior,
            Status::Constrained => ParamStatus::Constrained,
            Status::Excluded => ParamStatus::Excluded,
        }
    }
}

/// One parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamReport {
    pub name: String,
    pub value: Option<f64>,
    pub sigma: Option<f64>,
    pub sigma_percent: Option<f64>,
    pub status: ParamStatus,
}

/// `coefficient · name`, one term of a combination.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Term {
    pub name: String,
    pub coefficient: f64,
}

/// An identifiable combination of parameters (a base parameter).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CombinationReport {
    /// Human-readable, e.g. `mx1 + 0.425·m2 − I3`.
    pub expression: String,
    pub terms: Vec<Term>,
    pub value: f64,
    pub sigma: Option<f64>,
}

/// The whole document; see the module docs for the schema.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterReport {
    pub schema: String,
    pub robot: String,
    pub parameterisation: Parameterisation,
    pub method: String,
    pub rank: usize,
    pub condition_number: Option<f64>,
    pub residual_rms: Vec<f64>,
    #[serde(default)]
    pub channels: Vec<String>,
    pub parameters: Vec<ParamReport>,
    pub combinations: Vec<CombinationReport>,
    /// How to predict with this estimate, when it predicts through a regressor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prediction: Option<PredictionModel>,
}

impl ParameterReport {
    /// The report of `estimate`, with a name per parameter (missing names become
    /// `x<j>`) and optionally a name per residual channel.
    pub fn from_estimate(
        robot: &str,
        parameterisation: Parameterisation,
        estimate: &Estimate,
        names: &[&str],
        channels: &[&str],
    ) -> ParameterReport {
        let name = |j: usize| names.get(j).map_or_else(|| format!("x{j}"), |s| s.to_string());
        let finite = |v: f64| v.is_finite().then_some(v);
        let parameters = estimate
            .params
            .iter()
            .enumerate()
            .map(|(j, p)| ParamReport {
                name: name(j),
                value: p.value.and_then(finite),
                sigma: p.sigma.and_then(finite),
                sigma_percent: p.relative_sigma_percent().and_then(finite),
                status: if p.status == Status::Identified && !p.is_significant() {
                    ParamStatus::NotSignificant
                } else {
                    p.status.into()
                },
            })
            .collect();
        let combinations = estimate
            .combinations
            .iter()
            .filter(|c| c.terms.len() > 1)
            .map(|c| {
                let terms: Vec<Term> = c
                    .terms
                    .iter()
                    .map(|&(j, coefficient)| Term {
                        name: name(j),
                        coefficient,
                    })
                    .collect();
                CombinationReport {
                    expression: expression(&terms),
                    terms,
                    value: c.value,
                    sigma: c.sigma.and_then(finite),
                }
            })
            .collect();
        ParameterReport {
            schema: SCHEMA.to_string(),
            robot: robot.to_string(),
            parameterisation,
            method: estimate.method.to_string(),
            rank: estimate.rank,
            condition_number: finite(estimate.condition_number),
            residual_rms: estimate.residuals.per_channel_rms.clone(),
            channels: channels.iter().map(|s| s.to_string()).collect(),
            parameters,
            combinations,
            prediction: None,
        }
    }

    /// The report of a MIM estimate ([`crate::mim`]): `θ` named `m1, J1_1, J2_1,
    /// J3_1, m2, …`, channels `<body>.Fx … <body>.Mz` (six per body), and the MIM
    /// verdicts: a parameter below the significance threshold is `not_significant`,
    /// without value or σ. A per-body estimate ([`crate::mim::samples`]) becomes one
    /// report: ranks add up, the condition number is the worst body's.
    pub fn from_mim(robot: &str, estimate: &MimEstimate) -> ParameterReport {
        let names = principal_param_names(estimate.bodies());
        let channels: Vec<String> = estimate
            .body_names
            .iter()
            .flat_map(|b| ["Fx", "Fy", "Fz", "Mx", "My", "Mz"].map(|c| format!("{b}.{c}")))
            .collect();
        let parts: Vec<ParameterReport> = if estimate.estimates.len() == 1 {
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            let channels: Vec<&str> = channels.iter().map(String::as_str).collect();
            vec![Self::from_estimate(
                robot,
                Parameterisation::Principal,
                &estimate.estimates[0],
                &names,
                &channels,
            )]
        } else {
            estimate
                .estimates
                .iter()
                .enumerate()
                .map(|(i, e)| {
                    let names: Vec<&str> = names[4 * i..4 * i + 4].iter().map(String::as_str).collect();
                    let channels: Vec<&str> = channels[6 * i..6 * i + 6].iter().map(String::as_str).collect();
                    Self::from_estimate(robot, Parameterisation::Principal, e, &names, &channels)
                })
                .collect()
        };
        let mut parts = parts.into_iter();
        let mut report = parts.next().expect("a MIM estimate has at least one body");
        for part in parts {
            report.rank += part.rank;
            report.condition_number = match (report.condition_number, part.condition_number) {
                (Some(a), Some(b)) => Some(a.max(b)),
                _ => None,
            };
            report.residual_rms.extend(part.residual_rms);
            report.channels.extend(part.channels);
            report.parameters.extend(part.parameters);
            report.combinations.extend(part.combinations);
        }
        for (j, p) in report.parameters.iter_mut().enumerate() {
            if estimate.verdict(j / 4, j % 4) == Verdict::NotSignificant {
                p.value = None;
                p.sigma = None;
                p.sigma_percent = None;
                p.status = ParamStatus::NotSignificant;
            }
        }
        report
    }

    /// Pretty-printed JSON. Non-finite numbers cannot be written in JSON: an
    /// optional field holding one is written as `null`, a required one is an error.
    pub fn to_json(&self) -> Result<String, ReportError> {
        if let Some(k) = self.residual_rms.iter().position(|x| !x.is_finite()) {
            return Err(ReportError::NonFinite {
                what: "residual_rms".into(),
                index: k,
            });
        }
        if let Some(k) = self.combinations.iter().position(|c| !c.value.is_finite()) {
            return Err(ReportError::NonFinite {
                what: "combination value".into(),
                index: k,
            });
        }
        let mut s = serde_json::to_string_pretty(self).map_err(|e| json_error(&e))?;
        s.push('\n');
        Ok(s)
    }

    /// Parses a document, checking the `schema` field.
    pub fn from_json(text: &str) -> Result<ParameterReport, ReportError> {
        let report: ParameterReport = serde_json::from_str(text).map_err(|e| json_error(&e))?;
        if report.schema != SCHEMA {
            return Err(ReportError::Json {
                message: format!("unsupported schema `{}` (expected `{SCHEMA}`)", report.schema),
                line: 1,
                column: 1,
            });
        }
        Ok(report)
    }

    /// Writes the JSON to `path`; an existing file is replaced only with `overwrite`.
    pub fn write(&self, path: &Path, overwrite: bool) -> Result<(), ReportError> {
        write_new(path, &self.to_json()?, overwrite)
    }

    /// Reads a document written by [`ParameterReport::write`].
    pub fn read(path: &Path) -> Result<ParameterReport, ReportError> {
        let text = std::fs::read_to_string(path).map_err(|e| ReportError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Self::from_json(&text).map_err(|e| match e {
            ReportError::Json { message, line, column } => ReportError::Json {
                message: format!("{}: {message}", path.display()),
                line,
                column,
            },
            e => e,
        })
    }
}

fn json_error(e: &serde_json::Error) -> ReportError {
    ReportError::Json {
        message: e.to_string(),
        line: e.line(),
        column: e.column(),
    }
}

/// `a + 0.5·b − c`, coefficients to six significant digits.
fn expression(terms: &[Term]) -> String {
    let mut s = String::new();
    for (k, t) in terms.iter().enumerate() {
        let sign = match (t.coefficient < 0.0, k) {
            (true, 0) => "−",
            (true, _) => " − ",
            (false, 0) => "",
            (false, _) => " + ",
        };
        let mag = t.coefficient.abs();
        let factor = if (mag - 1.0).abs() < 1e-12 {
            String::new()
        } else {
            let c = format!("{mag:.5e}").parse::<f64>().unwrap_or(mag);
            format!("{c}·")
        };
        s.push_str(&format!("{sign}{factor}{}", t.name));
    }
    s
}
