//! `dyngen.identify`: the library entry of `dyngen identify` (`dyngen-identify`'s
//! pipeline: read a recording, estimate what it does not measure, identify).

use crate::LoadError;
use dyngen_identify::data::Recipe;
use dyngen_identify::pipeline::{self, Estimator, IdentifyOptions, JointTerms, Mode};
use dyngen_model::joint_params::Coulomb;
use dyngen_model::LoadOptions;
use dyngen_reference::Reference;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// The options of `identify`, as given from Python.
struct Choices<'a> {
    mode: &'a str,
    method: &'a str,
    friction: &'a str,
    epsilon: f64,
    ridge_lambda: f64,
    cutoff: f64,
    raw_states: bool,
}

fn invalid(option: &str, value: &str, valid: &[&str]) -> PyErr {
    PyValueError::new_err(format!(
        "identify: unknown {option} `{value}`; it must be one of: {}",
        valid.join(", ")
    ))
}

impl Choices<'_> {
    fn options(&self) -> PyResult<IdentifyOptions> {
        let mode = match self.mode {
            "standard" => Mode::Standard,
            "principal" => Mode::Principal,
            "mim" => Mode::Mim,
            other => return Err(invalid("mode", other, &["standard", "principal", "mim"])),
        };
        let estimator = match self.method {
            "ols" => Estimator::Ols,
            "wls" => Estimator::Wls,
            "tls" => Estimator::Tls { column_scaling: true },
            "tls-unscaled" => Estimator::Tls { column_scaling: false },
            "ridge" => Estimator::Ridge {
                lambda: self.ridge_lambda,
            },
            "consistent" => Estimator::Consistent,
            other => {
                return Err(invalid(
                    "method",
                    other,
                    &["ols", "wls", "tls", "tls-unscaled", "ridge", "consistent"],
                ))
            }
        };
        let smooth = Coulomb::Smooth { epsilon: self.epsilon };
        let joints = match self.friction {
            "none" => JointTerms::None,
            "sign" => JointTerms::Friction(Coulomb::Sign),
            "smooth" => JointTerms::Friction(smooth),
            "auto" => JointTerms::FrictionAuto,
            "stribeck" => JointTerms::Stribeck(Coulomb::Sign),
            "stribeck-smooth" => JointTerms::Stribeck(smooth),
            other => {
                return Err(invalid(
                    "friction",
                    other,
                    &["none", "sign", "smooth", "auto", "stribeck", "stribeck-smooth"],
                ))
            }
        };
        let options = IdentifyOptions {
            mode,
            estimator,
            joints,
            cutoff_hz: self.cutoff,
            low_pass_states: !self.raw_states,
            ..IdentifyOptions::default()
        };
        options
            .check()
            .map_err(|e| PyValueError::new_err(format!("identify: {e}")))?;
        Ok(options)
    }
}

/// Identifies a robot's inertial parameters from a recording, as `dyngen identify`
/// does.
///
/// Args:
///     robot_path: the URDF (or MJCF); every joint must have one degree of freedom.
///     data_path: the recording, a CSV of dyngen's schema (`t`, `q1`…`qn`, optionally
///         `v1`…, `a1`…, `tau1`…`taun`, and the joint wrenches for `mode="mim"`) or
///         as `recipe` describes it.
///     mode: `"standard"` (10 parameters per body from the joint torques, the
///         default), `"principal"` (mass and principal moments per body), `"mim"`
///         (the principal parameters body by body from the joint wrenches).
///     method: the estimator of the standard and principal modes: `"ols"` (default),
///         `"wls"`, `"tls"`, `"tls-unscaled"`, `"ridge"` (with `ridge_lambda`),
///         `"consistent"`.
///     friction: joint terms of the standard mode: `"none"` (default), `"sign"`,
///         `"smooth"` (`tanh(v/epsilon)`), `"auto"`, `"stribeck"`, `"stribeck-smooth"`.
///     epsilon: the Coulomb smoothing of `"smooth"` friction, rad/s.
///     ridge_lambda: the scale-free weight of `"ridge"`.
///     cutoff: low-pass cutoff (Hz) of the velocities and accelerations estimated
///         from positions, and of the measured states.
///     raw_states: use the measured positions and velocities as read, not low-passed.
///     recipe: the path of a recipe file saying how to read a log of another layout.
///
/// Returns:
///     A dict: `names` (list of str), `values`, `sigma`, `sigma_percent` (numpy
///     arrays, NaN where a parameter has none), `status` (list of str), `rank`,
///     `condition_number` (None when not computed), `residual_rms` (numpy array per
///     channel), `channels` (list of str), `combinations` (the identifiable
///     combinations as text), `combination_matrix` (their coefficients, one row
///     per combination, one column per name), `combination_values`,
///     `combination_sigma` (numpy arrays), `warnings` (list of str).
///
/// Raises:
///     LoadError: the robot does not load.
///     ValueError: an unknown option, a recording that does not read or does not fit
///         the robot, an identification that fails (each with dyngen's message).
#[pyfunction]
#[pyo3(signature = (
    robot_path,
    data_path,
    *,
    mode = "standard",
    method = "ols",
    friction = "none",
    epsilon = 0.01,
    ridge_lambda = 1e-6,
    cutoff = 10.0,
    raw_states = false,
    recipe = None,
))]
#[allow(clippy::too_many_arguments)]
pub fn identify<'py>(
    py: Python<'py>,
    robot_path: PathBuf,
    data_path: PathBuf,
    mode: &str,
    method: &str,
    friction: &str,
    epsilon: f64,
    ridge_lambda: f64,
    cutoff: f64,
    raw_states: bool,
    recipe: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = Choices {
        mode,
        method,
        friction,
        epsilon,
        ridge_lambda,
        cutoff,
        raw_states,
    }
    .options()?;
    let recipe = match &recipe {
        Some(path) => Recipe::from_file(path)
            .map_err(|e| PyValueError::new_err(format!("identify: recipe {}: {e}", path.display())))?,
        None => Recipe::default(),
    };
    let model = dyngen_model::load_robot_options(&robot_path, LoadOptions::default())
        .map_err(|e| LoadError::new_err(e.to_string()))?;
    if model.dof() == 0 {
        return Err(LoadError::new_err(format!(
            "{}: the robot has no moving joints",
            robot_path.display()
        )));
    }
    if let Some(j) = model.multi_dof_joint() {
        return Err(LoadError::new_err(format!(
            "{}: joint `{}` is a {} joint; identification runs on robots whose joints each have one degree of freedom",
            robot_path.display(),
            j.name,
            j.kind.urdf_name()
        )));
    }
    let failed = |e: pipeline::PipelineError| PyValueError::new_err(format!("identify: {}: {e}", data_path.display()));
    let identified = py.detach(|| {
        let loaded = pipeline::load(&data_path, &recipe, model.dof(), &options).map_err(failed)?;
        let robot = Reference::new(&model);
        pipeline::identify(&robot, &loaded.trajectory, &options).map_err(failed)
    })?;
    let report = &identified.report;
    let nan = |x: Option<f64>| x.unwrap_or(f64::NAN);
    let out = PyDict::new(py);
    let params = &report.parameters;
    out.set_item("names", params.iter().map(|p| p.name.clone()).collect::<Vec<_>>())?;
    out.set_item("values", PyArray1::from_iter(py, params.iter().map(|p| nan(p.value))))?;
    out.set_item("sigma", PyArray1::from_iter(py, params.iter().map(|p| nan(p.sigma))))?;
    out.set_item(
        "sigma_percent",
        PyArray1::from_iter(py, params.iter().map(|p| nan(p.sigma_percent))),
    )?;
    let status: Vec<String> = params
        .iter()
        .map(|p| match serde_json::to_value(p.status) {
            Ok(serde_json::Value::String(s)) => s,
            _ => format!("{:?}", p.status),
        })
        .collect();
    out.set_item("status", status)?;
    out.set_item("rank", report.rank)?;
    out.set_item("condition_number", report.condition_number)?;
    out.set_item("residual_rms", PyArray1::from_slice(py, &report.residual_rms))?;
    out.set_item("channels", report.channels.clone())?;
    let combinations = &report.combinations;
    out.set_item(
        "combinations",
        combinations.iter().map(|c| c.expression.clone()).collect::<Vec<_>>(),
    )?;
    out.set_item(
        "combination_values",
        PyArray1::from_iter(py, combinations.iter().map(|c| c.value)),
    )?;
    let index: std::collections::HashMap<&str, usize> =
        params.iter().enumerate().map(|(k, p)| (p.name.as_str(), k)).collect();
    let mut matrix = vec![0.0; combinations.len() * params.len()];
    for (r, c) in combinations.iter().enumerate() {
        for term in &c.terms {
            if let Some(&k) = index.get(term.name.as_str()) {
                matrix[r * params.len() + k] += term.coefficient;
            }
        }
    }
    let matrix = PyArray1::from_vec(py, matrix).reshape([combinations.len(), params.len()])?;
    out.set_item("combination_matrix", matrix)?;
    out.set_item(
        "combination_sigma",
        PyArray1::from_iter(py, combinations.iter().map(|c| nan(c.sigma))),
    )?;
    out.set_item("warnings", identified.warnings.clone())?;
    Ok(out)
}
