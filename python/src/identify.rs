//! `dyngen.identify`: the library entry of `dyngen identify` (`dyngen-identify`'s
//! pipeline: read a recording, estimate what it does not measure, identify).

use crate::LoadError;
use dyngen_identify::choice::DEFAULT_EXTRAS;
use dyngen_identify::data::Recipe;
use dyngen_identify::extras::ExtraTerms;
use dyngen_identify::partial::{self, Partial, PartialError};
use dyngen_identify::pipeline::{self, Estimator, Identification, IdentifyOptions, JointTerms, Mode};
use dyngen_identify::report::DataSpan;
use dyngen_identify::validate::Validation;
use dyngen_model::joint_params::Coulomb;
use dyngen_model::{LoadOptions, Model};
use dyngen_reference::Reference;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple, PyType};
use std::path::{Path, PathBuf};

/// The options of `identify`, as given from Python.
struct Choices<'a> {
    /// The Python function, for the messages.
    function: &'a str,
    mode: &'a str,
    method: &'a str,
    friction: &'a str,
    epsilon: f64,
    ridge_lambda: f64,
    cutoff: f64,
    raw_states: bool,
    /// `extra_terms` as given (`None`: not given).
    extra_terms: Option<&'a str>,
    /// Each joint's gear ratio, for `motor-ripple=H`.
    gear_ratios: Option<Vec<f64>>,
}

fn invalid(function: &str, option: &str, value: &str, valid: &[&str]) -> PyErr {
    PyValueError::new_err(format!(
        "{function}: unknown {option} `{value}`; it must be one of: {}",
        valid.join(", ")
    ))
}

impl Choices<'_> {
    fn options(&self) -> PyResult<IdentifyOptions> {
        let mode = match self.mode {
            "standard" => Mode::Standard,
            "principal" => Mode::Principal,
            "mim" => Mode::Mim,
            other => return Err(invalid(self.function, "mode", other, &["standard", "principal", "mim"])),
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
                    self.function,
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
            // Replaced by the model the data choose (`dyngen_identify::choice`) once
            // the recording is read.
            "best" if self.function == "identify" => JointTerms::Friction(Coulomb::Sign),
            other => {
                // A partial factor holds the rows of one model: no choice among several.
                let valid: Vec<&str> = ["none", "sign", "smooth", "auto", "stribeck", "stribeck-smooth", "best"]
                    .into_iter()
                    .filter(|&f| f != "best" || self.function == "identify")
                    .collect();
                return Err(invalid(self.function, "friction", other, &valid));
            }
        };
        let extras = match (self.friction, self.extra_terms) {
            // With best, the terms the choice may add (`Choices::allowed_extras`).
            ("best", _) | (_, None) => ExtraTerms::NONE,
            (_, Some(text)) => self.extras(text)?,
        };
        let options = IdentifyOptions {
            mode,
            estimator,
            joints,
            extras,
            cutoff_hz: self.cutoff,
            low_pass_states: !self.raw_states,
            gear_ratios: self.gear_ratios.clone(),
            ..IdentifyOptions::default()
        };
        options
            .check()
            .map_err(|e| PyValueError::new_err(format!("{}: {e}", self.function)))?;
        Ok(options)
    }

    fn extras(&self, text: &str) -> PyResult<ExtraTerms> {
        text.parse()
            .map_err(|e| PyValueError::new_err(format!("{}: extra_terms `{text}`: {e}", self.function)))
    }

    /// The extra terms `friction="best"` may add: those given, else
    /// [`DEFAULT_EXTRAS`].
    fn allowed_extras(&self) -> PyResult<ExtraTerms> {
        self.extra_terms.map_or(Ok(DEFAULT_EXTRAS), |text| self.extras(text))
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
///     friction: joint terms of the standard mode: `"none"`, `"sign"`,
///         `"smooth"` (`tanh(v/epsilon)`), `"auto"`, `"stribeck"`, `"stribeck-smooth"`,
///         `"best"` (the one of `"none"`, `"sign"` without and with rotor inertia,
///         `"auto"` and `"stribeck"` that predicts held-out time blocks of the
///         recording best, with the extra terms that do; each candidate's error is
///         in `model_choice`). Default: `"best"` in the standard mode (`"none"`
///         for a recording too short for its time blocks), `"none"` otherwise.
///     epsilon: the Coulomb smoothing of `"smooth"` friction, rad/s.
///     extra_terms: joint terms past friction, with `"sign"`, `"smooth"` or
///         `"auto"`: a comma-separated list of `"asymmetric"` (direction-dependent
///         viscous friction), `"ripple=H"` (`H` harmonics of the joint angle: torque
///         ripple and position-dependent Coulomb friction) and `"load"` (Coulomb
///         friction growing with the links' load) and `"motor-ripple=H"` (`H`
///         harmonics of the motor angle, with `gear_ratios`). With `"best"`: the
///         terms it may add (default `"asymmetric,ripple=2,load"`; `"none"` for
///         none).
///     gear_ratios: each joint's gear ratio `N_j` (motor angle `N_j q_j`), for
///         `"motor-ripple=H"`.
///     ridge_lambda: the scale-free weight of `"ridge"`.
///     cutoff: low-pass cutoff (Hz) of the velocities and accelerations estimated
///         from positions, and of the measured states.
///     raw_states: use the measured positions and velocities as read, not low-passed.
///     recipe: the path of a recipe file saying how to read a log of another layout.
///     validate: a second recording to predict with the result (held-out data).
///     validate_recipe: the recipe of the validation recording; by default the
///         training recipe without its time and row windows.
///
/// Returns:
///     A dict: `names` (list of str), `values`, `sigma`, `sigma_percent` (numpy
///     arrays, NaN where a parameter has none), `status` (list of str), `rank`,
///     `condition_number` (None when not computed), `residual_rms` (numpy array per
///     channel), `channels` (list of str), `combinations` (the identifiable
///     combinations as text), `combination_matrix` (their coefficients, one row
///     per combination, one column per name), `combination_values`,
///     `combination_sigma` (numpy arrays), `warnings` (list of str),
///     `parameters_json` (the text `dyngen identify --params-json` writes, with the
///     preprocessing, for `dyngen validate`; None for `mode="mim"`), and with
///     `validate` a dict `validation`: `samples`, `joint_names`, per joint `rms`
///     (of the prediction error), `measured_rms`, `relative` (‖τ̂ − τ‖ / ‖τ‖), and
///     `overall` (over every joint and sample); with `friction="best"` a dict
///     `model_choice`: `chosen` (the candidate's label: `"auto + asymmetric,load"`,
///     say), `held_out` (each candidate's overall relative error on the held-out
///     blocks, None where it could not be fitted) and `epsilons` (`"auto"`'s
///     Coulomb smoothing per joint chosen on the blocks, or None).
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
    friction = None,
    epsilon = 0.01,
    extra_terms = None,
    gear_ratios = None,
    ridge_lambda = 1e-6,
    cutoff = 10.0,
    raw_states = false,
    recipe = None,
    validate = None,
    validate_recipe = None,
    report = None,
    overwrite = false,
))]
#[allow(clippy::too_many_arguments)]
pub fn identify<'py>(
    py: Python<'py>,
    robot_path: PathBuf,
    data_path: PathBuf,
    mode: &str,
    method: &str,
    friction: Option<&str>,
    epsilon: f64,
    extra_terms: Option<&str>,
    gear_ratios: Option<Vec<f64>>,
    ridge_lambda: f64,
    cutoff: f64,
    raw_states: bool,
    recipe: Option<PathBuf>,
    validate: Option<PathBuf>,
    validate_recipe: Option<PathBuf>,
    report: Option<PathBuf>,
    overwrite: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if validate_recipe.is_some() && validate.is_none() {
        return Err(PyValueError::new_err(
            "identify: `validate_recipe` is the recipe of the `validate` recording; give `validate` too",
        ));
    }
    // By default the data choose the joint model in the standard mode.
    let defaulted = friction.is_none();
    let friction = friction.unwrap_or(if mode == "standard" { "best" } else { "none" });
    let choices = Choices {
        function: "identify",
        mode,
        method,
        friction,
        epsilon,
        ridge_lambda,
        cutoff,
        raw_states,
        extra_terms,
        gear_ratios,
    };
    let options = choices.options()?;
    let allowed_extras = choices.allowed_extras()?;
    let recipe = read_recipe("identify", recipe.as_deref())?;
    let validation_recipe = match &validate_recipe {
        Some(_) => read_recipe("identify", validate_recipe.as_deref())?,
        None => recipe.without_window(),
    };
    let model = load_robot(&robot_path)?;
    let failed =
        |path: &Path, e: pipeline::PipelineError| PyValueError::new_err(format!("identify: {}: {e}", path.display()));
    let robot = Reference::new(&model);
    let (identified, validation, choice) = py.detach(|| {
        let loaded = pipeline::load(&data_path, &recipe, model.nv(), &options).map_err(|e| failed(&data_path, e))?;
        let too_short = loaded.trajectory.len() < dyngen_identify::choice::MIN_SAMPLES;
        let (options, choice) = if friction == "best" && defaulted && too_short {
            // Too short to choose on time blocks: the rigid bodies alone.
            let options = pipeline::IdentifyOptions {
                joints: pipeline::JointTerms::None,
                ..options
            };
            (options, None)
        } else if friction == "best" {
            let choice = dyngen_identify::choice::choose(&robot, &loaded.trajectory, &options, allowed_extras)
                .map_err(|e| failed(&data_path, e))?;
            (choice.apply(&options), Some(choice))
        } else {
            (options, None)
        };
        let mut identified =
            pipeline::identify(&robot, &loaded.trajectory, &options).map_err(|e| failed(&data_path, e))?;
        // What `--params-json` records of the preprocessing, for `dyngen validate`.
        if let Some(pre) = identified
            .report
            .prediction
            .as_mut()
            .and_then(|p| p.preprocessing.as_mut())
        {
            pre.recipe = Some(recipe.without_window().to_text());
            pre.window = recipe.window_text();
            pre.data = Some(DataSpan::of(&data_path, &loaded.trajectory));
        }
        // The SVG report of `dyngen identify --report`: measured against predicted
        // efforts on the identification data.
        if let Some(path) = &report {
            let traj = &loaded.trajectory;
            let predicted = identified.predict(&robot, traj).map_err(|e| failed(&data_path, e))?;
            let method = &identified.report.method;
            let svg =
                dyngen_identify::report::identification_report(&model, method, &data_path, traj, &predicted, None)
                    .map_err(|e| report_error(path, e))?;
            dyngen_identify::report::write_report(path, &svg, overwrite).map_err(|e| report_error(path, e))?;
        }
        let validation = match &validate {
            None => None,
            Some(path) => {
                let other =
                    pipeline::load(path, &validation_recipe, model.nv(), &options).map_err(|e| failed(path, e))?;
                let predicted = identified
                    .predict(&robot, &other.trajectory)
                    .map_err(|e| failed(path, e))?;
                let names: Vec<String> = model.own_joints().map(|j| j.name.clone()).collect();
                let t = &other.trajectory;
                let v = Validation::new(&names, (0..t.len()).map(|k| t.tau(k)), predicted.iter().map(|p| &p[..]))
                    .map_err(|e| PyValueError::new_err(format!("identify: validation {}: {e}", path.display())))?;
                Some(v)
            }
        };
        Ok::<_, PyErr>((identified, validation, choice))
    })?;
    let out = to_dict(py, &identified)?;
    if let Some(choice) = choice {
        let held_out = PyDict::new(py);
        for score in &choice.scores {
            held_out.set_item(score.candidate.label(), score.held_out.as_ref().ok().map(|v| v.overall))?;
        }
        let d = PyDict::new(py);
        d.set_item("chosen", choice.chosen().label())?;
        d.set_item("held_out", held_out)?;
        d.set_item("epsilons", choice.epsilons.clone())?;
        out.set_item("model_choice", d)?;
    }
    let json = match identified.mim {
        Some(_) => None,
        None => Some(
            identified
                .report
                .to_json()
                .map_err(|e| PyValueError::new_err(format!("identify: {e}")))?,
        ),
    };
    out.set_item("parameters_json", json)?;
    if let Some(v) = validation {
        let d = PyDict::new(py);
        d.set_item("samples", v.samples)?;
        d.set_item("joint_names", v.joint_names.clone())?;
        d.set_item("rms", PyArray1::from_slice(py, &v.rms))?;
        d.set_item("measured_rms", PyArray1::from_slice(py, &v.measured_rms))?;
        d.set_item("relative", PyArray1::from_slice(py, &v.relative))?;
        d.set_item("overall", v.overall)?;
        out.set_item("validation", d)?;
    }
    Ok(out)
}

/// A report that could not be written: `FileExistsError` for a file kept (without
/// `overwrite`), `OSError` otherwise.
fn report_error(path: &Path, e: dyngen_identify::report::ReportError) -> PyErr {
    let message = format!("identify: report {}: {e}", path.display());
    match e {
        dyngen_identify::report::ReportError::Exists { .. } => pyo3::exceptions::PyFileExistsError::new_err(message),
        _ => pyo3::exceptions::PyOSError::new_err(message),
    }
}

/// The recipe at `path`, or the default.
fn read_recipe(function: &str, path: Option<&Path>) -> PyResult<Recipe> {
    match path {
        Some(path) => Recipe::from_file(path)
            .map_err(|e| PyValueError::new_err(format!("{function}: recipe {}: {e}", path.display()))),
        None => Ok(Recipe::default()),
    }
}

/// The robot at `robot_path`, with joints of one degree of freedom each (joints that
/// follow others, `<mimic>`, have none and are taken).
fn load_robot(robot_path: &Path) -> PyResult<Model> {
    let model = dyngen_model::load_robot_options(robot_path, LoadOptions::default())
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
    Ok(model)
}

/// An identification as the dict `identify` returns.
fn to_dict<'py>(py: Python<'py>, identified: &Identification) -> PyResult<Bound<'py, PyDict>> {
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

/// The sufficient statistics of the joint-torque rows of one or more recordings:
/// per joint the triangular factor of its rows of `[A y]`, with the robot it was
/// made for and every option that shaped the rows. Partials of the same robot and
/// options merge exactly (`merge`, `merge_partials`, in any grouping) and `solve`
/// then gives what `identify` gives on all their samples.
///
/// Made by `identify_partial`, read by `load_partial` (the files of
/// `dyngen identify ROBOT DATA --partial OUT`), or `Partial(text)` from the JSON
/// text of `to_json()`. Picklable (as that text), so it travels between processes
/// and machines (e.g. Dask workers).
#[pyclass(name = "Partial", module = "dyngen", frozen)]
pub struct PyPartial {
    inner: Partial,
}

/// How a Python error names `partial`: by its recordings.
fn label(partial: &Partial) -> String {
    let files: Vec<&str> = partial.recordings.iter().map(|r| r.file.as_str()).collect();
    match files.as_slice() {
        [] => "a partial without recordings".to_string(),
        [one] => format!("the partial of {one}"),
        [first, rest @ ..] => format!("the partial of {first} and {} more recordings", rest.len()),
    }
}

fn partial_error(function: &str, e: PartialError) -> PyErr {
    PyValueError::new_err(format!("{function}: {e}"))
}

/// `partials` merged in order; an error names the two that differ.
fn merge(function: &str, partials: &[&Partial]) -> PyResult<Partial> {
    let labels: Vec<String> = partials.iter().map(|p| label(p)).collect();
    let owned: Vec<Partial> = partials.iter().map(|p| (*p).clone()).collect();
    partial::merge_all(&owned, &labels).map_err(|e| PyValueError::new_err(format!("{function}: {e}")))
}

#[pymethods]
impl PyPartial {
    /// The partial in `text`, the JSON of `to_json()` or of a `--partial` file.
    ///
    /// Raises:
    ///     ValueError: not a partial, another schema version, inconsistent factors.
    #[new]
    fn new(text: &str) -> PyResult<Self> {
        Partial::from_json(text)
            .map(|inner| PyPartial { inner })
            .map_err(|e| partial_error("Partial", e))
    }

    /// The partial as JSON text (schema `dyngen-partial/1`); numbers read back bit
    /// for bit.
    fn to_json(&self) -> PyResult<String> {
        self.inner.to_json().map_err(|e| partial_error("Partial.to_json", e))
    }

    /// Pickled as its JSON text.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyType>, Bound<'py, PyTuple>)> {
        let text = slf.get().to_json()?;
        Ok((slf.get_type(), PyTuple::new(slf.py(), [text])?))
    }

    /// Writes the partial to `path` (a file `dyngen identify ROBOT --merge` reads),
    /// replacing it if it exists.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        let text = self.to_json()?;
        std::fs::write(&path, text)
            .map_err(|e| pyo3::exceptions::PyOSError::new_err(format!("Partial.save: {}: {e}", path.display())))
    }

    /// This partial merged with `other` (a new partial; neither is changed): the
    /// rows of both, as if `other`'s recordings had been read after these.
    ///
    /// Raises:
    ///     ValueError: they were made for other robots or with other row options
    ///         (the message names both and the difference).
    fn merge(&self, py: Python<'_>, other: &Bound<'_, PyPartial>) -> PyResult<PyPartial> {
        let other = &other.get().inner;
        let inner = py.detach(|| merge("Partial.merge", &[&self.inner, other]))?;
        Ok(PyPartial { inner })
    }

    /// Identifies the robot at `robot_path` (the one the partial was made for)
    /// from the merged rows, as `identify` does on all the samples.
    ///
    /// Args:
    ///     robot_path: the URDF (or MJCF) the partials were made with.
    ///     method: `"ols"` (default), `"wls"`, `"tls"`, `"tls-unscaled"`, `"ridge"`
    ///         (with `ridge_lambda`) or `"consistent"`.
    ///     ridge_lambda: the scale-free weight of `"ridge"`.
    ///
    /// Returns:
    ///     The dict of `identify`.
    ///
    /// Raises:
    ///     LoadError: the robot does not load.
    ///     ValueError: an unknown method, another robot than the partial's, a
    ///         failing estimate.
    #[pyo3(signature = (robot_path, *, method = "ols", ridge_lambda = 1e-6))]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        robot_path: PathBuf,
        method: &str,
        ridge_lambda: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let given = Choices {
            function: "Partial.solve",
            mode: "standard",
            method,
            friction: "none",
            epsilon: 0.01,
            ridge_lambda,
            cutoff: 10.0,
            raw_states: false,
            extra_terms: None,
            gear_ratios: None,
        }
        .options()?;
        let model = load_robot(&robot_path)?;
        let identified = py.detach(|| {
            self.inner
                .identify(&Reference::new(&model), &given)
                .map_err(|e| match e {
                    PartialError::Mismatch { what, ours, theirs } => PyValueError::new_err(format!(
                        "Partial.solve: {}: not the robot the partial was made for: different {what}: the partial's \
                         {ours} against this {theirs}",
                        robot_path.display()
                    )),
                    e => partial_error("Partial.solve", e),
                })
        })?;
        to_dict(py, &identified)
    }

    /// The recordings whose rows the partial holds (file names, in merge order).
    #[getter]
    fn recordings(&self) -> Vec<String> {
        self.inner.recordings.iter().map(|r| r.file.clone()).collect()
    }

    /// Samples of all its recordings.
    #[getter]
    fn samples(&self) -> usize {
        self.inner.recordings.iter().map(|r| r.samples).sum()
    }

    /// The robot's name.
    #[getter]
    fn robot(&self) -> String {
        self.inner.robot.name.clone()
    }

    /// The parameter names, in the order of the regressor's columns.
    #[getter]
    fn parameters(&self) -> Vec<String> {
        self.inner.robot.parameters.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "Partial({}: {} recordings, {} samples, {} parameters)",
            self.inner.robot.name,
            self.inner.recordings.len(),
            self.samples(),
            self.inner.robot.parameters.len()
        )
    }
}

/// The partial factor of one recording: what `identify` reads and accumulates,
/// without the estimate (`dyngen identify ROBOT DATA --partial OUT`).
///
/// Args: those of `identify` that shape the rows (`robot_path`, `data_path`,
/// `mode`, `friction`, `epsilon`, `cutoff`, `raw_states`, `recipe`). The estimator
/// is chosen by `Partial.solve`.
///
/// Returns:
///     A `Partial`.
///
/// Raises:
///     LoadError: the robot does not load.
///     ValueError: an unknown option; `mode="mim"`, `friction="auto"`, `"stribeck"`
///         or `"stribeck-smooth"` (they need the rows themselves, which a partial
///         does not keep: the message says what works); a recording that does not
///         read or does not fit the robot.
#[pyfunction]
#[pyo3(signature = (
    robot_path,
    data_path,
    *,
    mode = "standard",
    friction = "none",
    epsilon = 0.01,
    cutoff = 10.0,
    raw_states = false,
    recipe = None,
))]
#[allow(clippy::too_many_arguments)]
pub fn identify_partial(
    py: Python<'_>,
    robot_path: PathBuf,
    data_path: PathBuf,
    mode: &str,
    friction: &str,
    epsilon: f64,
    cutoff: f64,
    raw_states: bool,
    recipe: Option<PathBuf>,
) -> PyResult<PyPartial> {
    let options = Choices {
        function: "identify_partial",
        mode,
        method: "ols",
        friction,
        epsilon,
        ridge_lambda: 1e-6,
        cutoff,
        raw_states,
        extra_terms: None,
        gear_ratios: None,
    }
    .options()?;
    let failed =
        |e: pipeline::PipelineError| PyValueError::new_err(format!("identify_partial: {}: {e}", data_path.display()));
    partial::check_options(&options).map_err(|e| PyValueError::new_err(format!("identify_partial: {e}")))?;
    let recipe = read_recipe("identify_partial", recipe.as_deref())?;
    let model = load_robot(&robot_path)?;
    let inner = py.detach(|| {
        let loaded = pipeline::load(&data_path, &recipe, model.nv(), &options).map_err(failed)?;
        let span = DataSpan::of(&data_path, &loaded.trajectory);
        Partial::from_trajectory(&Reference::new(&model), &loaded.trajectory, &options, &recipe, span).map_err(failed)
    })?;
    Ok(PyPartial { inner })
}

/// `partials` merged in order (a left fold; any grouping gives the same estimate
/// up to rounding).
///
/// Raises:
///     ValueError: an empty list, or two partials made for other robots or with
///         other row options (the message names both and the difference).
#[pyfunction]
pub fn merge_partials(py: Python<'_>, partials: Vec<Bound<'_, PyPartial>>) -> PyResult<PyPartial> {
    let inner: Vec<&Partial> = partials.iter().map(|p| &p.get().inner).collect();
    let inner = py.detach(|| merge("merge_partials", &inner))?;
    Ok(PyPartial { inner })
}

/// The partial factor file at `path` (`dyngen identify ... --partial OUT`, or
/// `Partial.save`).
///
/// Raises:
///     OSError: the file does not read.
///     ValueError: not a partial, another schema version, inconsistent factors.
#[pyfunction]
pub fn load_partial(path: PathBuf) -> PyResult<PyPartial> {
    let text = std::fs::read_to_string(&path)
        .map_err(|e| pyo3::exceptions::PyOSError::new_err(format!("load_partial: {}: {e}", path.display())))?;
    Partial::from_json(&text)
        .map(|inner| PyPartial { inner })
        .map_err(|e| PyValueError::new_err(format!("load_partial: {}: {e}", path.display())))
}

/// Registers the partial factors' class and functions in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPartial>()?;
    m.add_function(wrap_pyfunction!(identify_partial, m)?)?;
    m.add_function(wrap_pyfunction!(merge_partials, m)?)?;
    m.add_function(wrap_pyfunction!(load_partial, m)?)?;
    Ok(())
}
