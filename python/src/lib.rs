//! The native module `dyngen._dyngen` of the Python package `dyngen`: a robot loaded
//! at run time by `dyngen-model` (URDF or MJCF), its dynamics evaluated by
//! `dyngen-algo` on numpy arrays.
//!
//! Every algorithm takes one state (1-D arrays) or a batch (2-D arrays, one state per
//! row). Inputs that are C-contiguous `float64` arrays are read in place, others are
//! converted once; results are written into freshly allocated numpy arrays. The
//! evaluation runs with the GIL released: one state on `f64`, a batch on SIMD lanes
//! of eight states ([`dyngen::batch::Batch`]), split across threads for a large one,
//! bit for bit the states one at a time. Every kernel is written once for both
//! (the `evaluate!` macro). Bad input raises a Python exception naming the argument and, for a
//! batch, the row. `identify` runs the identification pipeline of `dyngen identify`.

mod identify;

use dyngen::batch::{Batch, BatchError, Input, Layout, Output, Threads};
use dyngen::lanes::F64x8;
use dyngen_algo::{DualWorkspace, Multibody, Real, ReferenceFrame, Se3, Workspace, PARAMS_PER_BODY};
use dyngen_model::{BaseParams, LoadOptions, Model, Parameterisation};
use numpy::{IxDyn, PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

pyo3::create_exception!(
    dyngen,
    LoadError,
    PyValueError,
    "A robot description that does not load; the message is dyngen-model's, every \
     error as `file:line: message`."
);

/// The lanes a batch is evaluated on: eight states per call.
type Lane = F64x8;

/// The valid names of the `reference` argument of the frame Jacobian.
const REFERENCES: [(&str, ReferenceFrame); 3] = [
    ("local_world_aligned", ReferenceFrame::LocalWorldAligned),
    ("local", ReferenceFrame::Local),
    ("world", ReferenceFrame::World),
];

/// Loads a robot description: a URDF, or MJCF for a file ending in `.xml` or `.mjcf`.
///
/// Args:
///     path: the file (`str` or `os.PathLike`).
///     free_flyer: put the root link on a free flyer (a floating base, as Pinocchio's
///         `buildModelFromUrdf(path, JointModelFreeFlyer())`): 7 more positions
///         `[x, y, z, qx, qy, qz, qw]` and 6 more velocities `[v; ω]` in the base frame.
///     strict: refuse what is otherwise loaded with a warning (non-physical inertias,
///         a singular mass matrix).
///
/// Returns:
///     The checked `Model`. Its warnings (`Model.warnings`) are also issued as Python
///     `UserWarning`s.
///
/// Raises:
///     LoadError: the file does not load, with dyngen-model's messages
///         (`file:line: message`, every error at once).
#[pyfunction]
#[pyo3(signature = (path, free_flyer = false, strict = false))]
fn load(py: Python<'_>, path: PathBuf, free_flyer: bool, strict: bool) -> PyResult<PyModel> {
    let options = LoadOptions {
        strict,
        free_flyer,
        ..LoadOptions::default()
    };
    let model = py
        .detach(|| dyngen_model::load_robot_options(&path, options))
        .map_err(|e| LoadError::new_err(e.to_string()))?;
    let warnings: Vec<String> = model.warnings.iter().map(|w| w.warning_message()).collect();
    let user_warning = py.get_type::<pyo3::exceptions::PyUserWarning>();
    for w in &warnings {
        PyErr::warn(py, &user_warning, &std::ffi::CString::new(w.replace('\0', " "))?, 1)?;
    }
    PyModel::new(model, warnings)
}

/// A robot loaded by `dyngen.load`: its kinematic tree, its standard inertial
/// parameters, and the rigid-body algorithms of dyngen-algo on it.
///
/// Every algorithm takes one state (1-D arrays: `q` of length `nq`, `v`, `a`, `tau`
/// of length `nv`) or a batch (2-D arrays of shape `(N, nq)`, `(N, nv)`, one state
/// per row, every argument with the same `N`), and returns a result of the state's
/// shape, or with a leading `N` for a batch. Inputs may be anything numpy converts to
/// `float64`; C-contiguous `float64` arrays are read without a copy. The algorithms
/// that depend on the inertial parameters take `params` (10 per body, see `params`),
/// by default the model's.
///
/// Raises:
///     ValueError: an argument of the wrong shape (naming it, the expected and the
///         found shape), a non-finite input or result (naming the row of a batch),
///         an unknown frame or reference (listing the valid names).
#[pyclass(name = "Model", module = "dyngen")]
struct PyModel {
    model: Model,
    body: Multibody,
    /// Per frame of the model: its body and its placement in that body.
    frames: Vec<(usize, Se3<f64>)>,
    warnings: Vec<String>,
    /// States for one-state calls, made for `body` and reused across calls: one per
    /// thread in use.
    pool: Mutex<Vec<State<f64>>>,
    max_threads: Option<usize>,
    /// Per body, `P_i` (10 × 4, row-major) of the principal parameters: `π_i = P_i θ_i`.
    principal: Vec<[f64; 40]>,
    /// The base-parameter analyses, made on first use: standard, principal.
    base: [OnceLock<BaseParams>; 2],
}

/// One input of an algorithm: its name and the number of entries per state.
struct Arg<'a, 'py> {
    name: &'static str,
    value: &'a Bound<'py, PyAny>,
    width: usize,
}

/// The input `name`, `width` values per state.
fn arg<'a, 'py>(name: &'static str, value: &'a Bound<'py, PyAny>, width: usize) -> Arg<'a, 'py> {
    Arg { name, value, width }
}

/// An input read as C-contiguous `float64`, checked against its width.
struct Read<'py> {
    name: &'static str,
    array: PyReadonlyArrayDyn<'py, f64>,
    width: usize,
    /// `None` for one state, the number of rows for a batch.
    rows: Option<usize>,
}

/// Rows of one input for the evaluation, without the GIL.
#[derive(Clone, Copy)]
struct Rows<'a> {
    name: &'static str,
    data: &'a [f64],
    width: usize,
}

/// Why a row failed.
#[derive(Clone, Debug)]
enum RowFailure {
    /// Entry `index` of input `arg` in row `row` is not finite.
    Input {
        row: usize,
        arg: &'static str,
        index: usize,
    },
    /// The result of row `row` is not finite.
    Output { row: usize },
    /// The batch could not run (a thread the system refused).
    Batch(String),
}

impl RowFailure {
    fn error(&self, algorithm: &str, batch: bool) -> PyErr {
        let message = match (self, batch) {
            (RowFailure::Input { arg, index, .. }, false) => {
                format!("{algorithm}: `{arg}` has a non-finite entry at index {index}")
            }
            (RowFailure::Input { row, arg, index }, true) => {
                format!("{algorithm}: row {row} of `{arg}` has a non-finite entry at index {index}")
            }
            (RowFailure::Output { .. }, false) => {
                format!("{algorithm}: the result is not finite (a singular mass matrix, or inputs too large)")
            }
            (RowFailure::Output { row }, true) => format!(
                "{algorithm}: the result of row {row} is not finite (a singular mass matrix, or inputs too large)"
            ),
            (RowFailure::Batch(error), _) => {
                return pyo3::exceptions::PyRuntimeError::new_err(format!("{algorithm}: {error}"))
            }
        };
        PyValueError::new_err(message)
    }
}

fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ")
        ),
    }
}

/// `value` as a C-contiguous `float64` array: itself when it is one, else converted by
/// `numpy.ascontiguousarray`.
fn as_f64<'py>(value: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    let py = value.py();
    let array = match value.cast::<PyArrayDyn<f64>>() {
        Ok(a) if a.is_c_contiguous() => a.clone(),
        _ => {
            let numpy = PyModule::import(py, "numpy")?;
            let converted = numpy
                .call_method1("ascontiguousarray", (value, numpy.getattr("float64")?))
                .map_err(|e| PyTypeError::new_err(format!("`{name}` must be an array of real numbers: {e}")))?;
            converted
                .cast_into::<PyArrayDyn<f64>>()
                .map_err(|e| PyTypeError::new_err(format!("`{name}`: {e}")))?
        }
    };
    array
        .try_readonly()
        .map_err(|e| PyValueError::new_err(format!("`{name}` cannot be read: {e}")))
}

fn slice<'a>(array: &'a PyReadonlyArrayDyn<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    array
        .as_slice()
        .map_err(|e| PyValueError::new_err(format!("`{name}` cannot be read: {e}")))
}

/// Reads the inputs and checks their shapes: all one state, or all batches of the
/// same number of rows. Returns them and the number of rows of a batch.
fn read_all<'py>(algorithm: &str, args: &[Arg<'_, 'py>]) -> PyResult<(Vec<Read<'py>>, Option<usize>)> {
    let mut read = Vec::with_capacity(args.len());
    for arg in args {
        let array = as_f64(arg.value, arg.name)?;
        let shape = array.shape().to_vec();
        let rows = match shape.as_slice() {
            [n] if *n == arg.width => None,
            [n, w] if *w == arg.width => Some(*n),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "{algorithm}: `{}` must have shape ({w},) for one state or (N, {w}) for a batch; found shape {}",
                    arg.name,
                    shape_text(&shape),
                    w = arg.width
                )))
            }
        };
        read.push(Read {
            name: arg.name,
            array,
            width: arg.width,
            rows,
        });
    }
    let first = &read[0];
    for r in &read[1..] {
        match (first.rows, r.rows) {
            (None, None) => {}
            (Some(a), Some(b)) if a == b => {}
            (Some(a), Some(b)) => {
                return Err(PyValueError::new_err(format!(
                    "{algorithm}: `{}` has {b} rows but `{}` has {a}; a batch needs one row per state in every argument",
                    r.name, first.name
                )))
            }
            _ => {
                return Err(PyValueError::new_err(format!(
                    "{algorithm}: `{}` has shape {} but `{}` has shape {}; give every argument as one state (1-D) or every one as a batch (2-D)",
                    r.name,
                    shape_text(r.array.shape()),
                    first.name,
                    shape_text(first.array.shape())
                )))
            }
        }
    }
    let rows = first.rows;
    Ok((read, rows))
}

/// What one thread keeps while it evaluates, in the scalar it evaluates on (`f64` for
/// one state, [`Lane`] for a batch): the workspaces of the algorithms, the
/// parameters, and `nv` zeros.
struct State<S: Real> {
    plain: Workspace<S>,
    params: Vec<S>,
    zero: Vec<S>,
    /// Made on first use: the derivatives (8 directions per pass) and the time
    /// variations (1 direction).
    dual8: Option<DualWorkspace<S, 8>>,
    dual1: Option<DualWorkspace<S, 1>>,
    /// Room for an intermediate result (the standard regressor of the principal one).
    scratch: Vec<S>,
}

impl<S: Real<Context = ()>> State<S> {
    fn new(body: &Multibody, params: &[f64]) -> Self {
        State {
            plain: Workspace::new(body, ()),
            params: params.iter().map(|&x| S::constant((), x)).collect(),
            zero: vec![S::constant((), 0.0); body.nv()],
            dual8: None,
            dual1: None,
            scratch: Vec::new(),
        }
    }
}

/// `Y blkdiag(P_i)` into `yp` (`nv × 4 nbodies`) from the standard regressor `y`
/// (`nv × 10 nbodies`) and the bodies' `P_i` (10 × 4 row-major).
fn principal_columns<S: Real<Context = ()>>(y: &[S], principal: &[[f64; 40]], yp: &mut [S]) {
    let (np, nb) = (10 * principal.len(), principal.len());
    for (row, out) in y.chunks_exact(np).zip(yp.chunks_exact_mut(4 * nb)) {
        for (i, p) in principal.iter().enumerate() {
            for c in 0..4 {
                let mut x = row[10 * i] * S::constant((), p[c]);
                for k in 1..10 {
                    x = x + row[10 * i + k] * S::constant((), p[4 * k + c]);
                }
                out[4 * i + c] = x;
            }
        }
    }
}

/// The workspace of `slot`, made for `body` on first use.
fn dual<'a, S: Real<Context = ()>, const N: usize>(
    slot: &'a mut Option<DualWorkspace<S, N>>,
    body: &Multibody,
) -> &'a mut DualWorkspace<S, N> {
    slot.get_or_insert_with(|| DualWorkspace::new(body, ()))
}

/// The first row (then argument, then entry) of the inputs that is not finite.
fn first_non_finite(inputs: &[Rows<'_>], rows: usize) -> Option<RowFailure> {
    (0..rows).find_map(|row| {
        inputs.iter().find_map(|x| {
            let values = &x.data[row * x.width..(row + 1) * x.width];
            values
                .iter()
                .position(|v| !v.is_finite())
                .map(|index| RowFailure::Input {
                    row,
                    arg: x.name,
                    index,
                })
        })
    })
}

/// [`PyModel::evaluate`] with its kernel written once for both scalars: `f64` for one
/// state, [`Lane`] for a batch.
macro_rules! evaluate {
    ($model:expr, $py:expr, $algorithm:expr, $params:expr, [$($arg:expr),* $(,)?], [$($out:expr),* $(,)?],
     |$state:ident, [$($i:ident),*], [$($o:ident),*]| $body:expr) => {
        $model.evaluate(
            $py,
            $algorithm,
            $params,
            [$($arg),*],
            [$($out),*],
            |$state, [$($i),*], [$($o),*]| $body,
            |$state, [$($i),*], [$($o),*]| $body,
        )
    };
}

impl PyModel {
    fn new(model: Model, warnings: Vec<String>) -> PyResult<PyModel> {
        let body = model
            .multibody()
            .map_err(|e| LoadError::new_err(format!("{}: {e}", model.name)))?;
        let frames = model
            .frames
            .iter()
            .map(|f| {
                (
                    f.body,
                    Se3 {
                        rotation: f.placement.rotation,
                        translation: f.placement.translation,
                    },
                )
            })
            .collect();
        Ok(PyModel {
            body,
            frames,
            warnings,
            pool: Mutex::new(Vec::new()),
            max_threads: None,
            principal: dyngen_model::principal_frames(&model)
                .iter()
                .map(|f| {
                    let p = f.p_matrix();
                    core::array::from_fn(|k| p[k / 4][k % 4])
                })
                .collect(),
            base: [OnceLock::new(), OnceLock::new()],
            model,
        })
    }

    fn nparams(&self) -> usize {
        PARAMS_PER_BODY * self.body.bodies()
    }

    fn take_state(&self) -> State<f64> {
        // A poisoned pool only lost states; take it over as it is.
        let taken = self.pool.lock().unwrap_or_else(|e| e.into_inner()).pop();
        taken.unwrap_or_else(|| State::new(&self.body, &self.body.params))
    }

    fn give_back(&self, state: State<f64>) {
        self.pool.lock().unwrap_or_else(|e| e.into_inner()).push(state);
    }

    /// The frame named `frame`: its body and its placement there.
    fn frame(&self, algorithm: &str, frame: &str) -> PyResult<(usize, Se3<f64>)> {
        match self.model.frame_index(frame) {
            Some(k) => Ok(self.frames[k]),
            None => Err(PyValueError::new_err(format!(
                "{algorithm}: no frame `{frame}` in `{}`; its frames are: {}",
                self.model.name,
                self.model
                    .frames
                    .iter()
                    .map(|f| f.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        }
    }

    /// The parameters to evaluate with: `params` read and checked, or the model's.
    fn read_params<'py>(
        &self,
        algorithm: &str,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Option<PyReadonlyArrayDyn<'py, f64>>> {
        let Some(params) = params.filter(|p| !p.is_none()) else {
            return Ok(None);
        };
        let array = as_f64(params, "params")?;
        let n = self.nparams();
        if array.shape() != [n] {
            return Err(PyValueError::new_err(format!(
                "{algorithm}: `params` must have shape ({n},) (10 per body, {} bodies); found shape {}",
                self.body.bodies(),
                shape_text(array.shape())
            )));
        }
        if let Some(index) = slice(&array, "params")?.iter().position(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "{algorithm}: `params` has a non-finite entry at index {index}"
            )));
        }
        Ok(Some(array))
    }

    /// Runs a kernel on every state of the inputs `args` (one state or a batch) with
    /// the parameters `params` (read and checked; the model's for `None`), with the GIL released, into
    /// new arrays of the per-state shapes `outputs` (with a leading `N` for a batch).
    /// One state runs `one` on `f64` (in a pooled [`State`]); a batch runs `lanes` on
    /// [`Lane`]s, eight states per call, split across threads by
    /// [`dyngen::batch::Batch`]: bit for bit the per-state results. Non-finite inputs
    /// and results are refused, naming the first such row.
    #[allow(clippy::too_many_arguments)]
    fn evaluate<'py, const I: usize, const O: usize, F, L>(
        &self,
        py: Python<'py>,
        algorithm: &str,
        params: Option<&Bound<'py, PyAny>>,
        args: [Arg<'_, 'py>; I],
        outputs: [&[usize]; O],
        one: F,
        lanes: L,
    ) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; O]>
    where
        F: Fn(&mut State<f64>, [&[f64]; I], [&mut [f64]; O]) + Sync,
        L: Fn(&mut State<Lane>, [&[Lane]; I], [&mut [Lane]; O]) + Sync,
    {
        let params = self.read_params(algorithm, params)?;
        let params = match &params {
            Some(p) => slice(p, "params")?,
            None => &self.body.params,
        };
        let (read, batch) = read_all(algorithm, &args)?;
        let rows = batch.unwrap_or(1);
        let mut data: Vec<Rows<'_>> = Vec::with_capacity(I);
        for r in &read {
            data.push(Rows {
                name: r.name,
                data: slice(&r.array, r.name)?,
                width: r.width,
            });
        }
        let arrays = outputs.map(|dims| {
            let shape: Vec<usize> = batch.into_iter().chain(dims.iter().copied()).collect();
            PyArrayDyn::<f64>::zeros(py, IxDyn(&shape), false)
        });
        let widths = outputs.map(|dims| dims.iter().product::<usize>());
        let mut guards = Vec::with_capacity(O);
        for a in &arrays {
            guards.push(
                a.try_readwrite()
                    .map_err(|e| PyValueError::new_err(format!("{algorithm}: result not writable: {e}")))?,
            );
        }
        let mut slices = Vec::with_capacity(O);
        for g in guards.iter_mut() {
            slices.push(
                g.as_slice_mut()
                    .map_err(|e| PyValueError::new_err(format!("{algorithm}: result not writable: {e}")))?,
            );
        }
        let Ok(mut slices) = <[&mut [f64]; O]>::try_from(slices) else {
            unreachable!("one slice per output")
        };
        // At most `max_threads`, each with a full share of states.
        let most = (rows / Batch::<Lane>::STATES_PER_THREAD).max(1);
        let threads = self.max_threads.map_or(Threads::Auto, |t| Threads::Count(t.min(most)));
        let body = &self.body;
        let result = py.detach(|| {
            if let Some(failure) = first_non_finite(&data, rows) {
                return Err(failure);
            }
            let inputs: [&[f64]; I] = core::array::from_fn(|k| data[k].data);
            if batch.is_none() {
                let mut state = self.take_state();
                state.params.copy_from_slice(params);
                one(&mut state, inputs, slices.each_mut().map(|s| &mut **s));
                self.give_back(state);
                return match slices.iter().all(|s| s.iter().all(|x| x.is_finite())) {
                    true => Ok(()),
                    false => Err(RowFailure::Output { row: 0 }),
                };
            }
            let ins: [Input<'_, f64>; I] = core::array::from_fn(|k| Input {
                name: data[k].name,
                data: data[k].data,
                width: data[k].width,
            });
            let mut k = 0;
            let mut outs = slices.map(|data| {
                k += 1;
                Output {
                    name: "result",
                    data,
                    width: widths[k - 1],
                }
            });
            Batch::<Lane>::new(rows, Layout::Rows)
                .threads(threads)
                .apply_with(
                    &ins,
                    &mut outs,
                    || State::<Lane>::new(body, params),
                    |state, x, y| {
                        let x: [&[Lane]; I] = core::array::from_fn(|k| x[k].as_slice());
                        let Ok(y) = <&mut [Vec<Lane>; O]>::try_from(y) else {
                            unreachable!("one output per array")
                        };
                        lanes(state, x, y.each_mut().map(|y| y.as_mut_slice()));
                    },
                )
                .map_err(|e| match e {
                    BatchError::NonFinite { state, .. } => RowFailure::Output { row: state },
                    other => RowFailure::Batch(other.to_string()),
                })
        });
        drop(guards);
        result.map_err(|f| f.error(algorithm, batch.is_some()))?;
        Ok(arrays)
    }
}

/// Rotations and translations, as numpy arrays.
type Placements<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);
/// Two and three matrices (or batches of them), as numpy arrays.
type Matrices2<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);
type Matrices3<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
);
type Arrays4<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
);

/// The reference frame named `name`.
fn reference_frame(algorithm: &str, name: &str) -> PyResult<ReferenceFrame> {
    match REFERENCES.iter().find(|(n, _)| *n == name) {
        Some(&(_, reference)) => Ok(reference),
        None => Err(PyValueError::new_err(format!(
            "{algorithm}: unknown reference `{name}`; it must be one of: {}",
            REFERENCES.map(|(n, _)| n).join(", ")
        ))),
    }
}

/// Copies the `Se3` `x` into a row-major rotation (9 entries) and a translation (3).
fn write_se3<S: Copy>(x: &Se3<S>, rotation: &mut [S], translation: &mut [S]) {
    for r in 0..3 {
        rotation[3 * r..3 * r + 3].copy_from_slice(&x.rotation[r]);
    }
    translation.copy_from_slice(&x.translation);
}

#[pymethods]
impl PyModel {
    /// The robot's name (the URDF `<robot name>`, the MJCF `<mujoco model>`).
    #[getter]
    fn name(&self) -> &str {
        &self.model.name
    }

    /// Number of position coordinates (a free flyer has 7, a ball joint 4).
    #[getter]
    fn nq(&self) -> usize {
        self.body.nq()
    }

    /// Number of velocity coordinates (degrees of freedom).
    #[getter]
    fn nv(&self) -> usize {
        self.body.nv()
    }

    /// Number of moving bodies (= joints); body `i` is carried by joint `i`.
    #[getter]
    fn nbodies(&self) -> usize {
        self.body.bodies()
    }

    /// The joints' names in the model's order, one per body (a free flyer is
    /// `root_joint`): the order of `q` and `v`, where a joint that follows another
    /// (`<mimic>`) is listed but has no coordinate of its own.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model.joints.iter().map(|j| j.name.clone()).collect()
    }

    /// The moving bodies' names (the link each joint carries, with the links fixed to
    /// it merged in), body 1 first: the order of `params` and of `forward_kinematics`.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.model.bodies.iter().map(|b| b.name.clone()).collect()
    }

    /// Every named frame (every link of the description, the base first), for
    /// `frame_placement` and `frame_jacobian`.
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.model.frames.iter().map(|f| f.name.clone()).collect()
    }

    /// Gravity in the base frame, m/s², shape (3,).
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.body.gravity)
    }

    /// What the loader accepted but reported (non-physical inertias kept as written,
    /// joints along which nothing with mass moves, what the file says that the model
    /// leaves out), one message each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The standard inertial parameters the algorithms use when no `params` is given,
    /// shape (10 * nbodies,): per body, in Pinocchio's order,
    /// `[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (the inertia about the
    /// body frame's origin, in its axes). Initially the description's; settable (a
    /// copy is returned and stored; every entry must be finite).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.body.params)
    }

    #[setter]
    fn set_params(&mut self, value: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let Some(value) = value else {
            return Err(PyTypeError::new_err("`params` cannot be deleted"));
        };
        let array = self
            .read_params("params", Some(value))?
            .ok_or_else(|| PyTypeError::new_err("`params` must be an array, not None"))?;
        let new = slice(&array, "params")?.to_vec();
        self.body.params = new;
        Ok(())
    }

    /// The most threads a batch is split across; `None` (the default) uses every
    /// core `std::thread::available_parallelism` reports. A batch is split only when
    /// every thread gets at least 512 states; results do not depend on the split.
    #[getter]
    fn max_threads(&self) -> Option<usize> {
        self.max_threads
    }

    #[setter]
    fn set_max_threads(&mut self, value: Option<usize>) -> PyResult<()> {
        if value == Some(0) {
            return Err(PyValueError::new_err("`max_threads` must be at least 1 (or None)"));
        }
        self.max_threads = value;
        Ok(())
    }

    /// The neutral configuration, shape (nq,): zero coordinates, identity quaternions.
    fn neutral<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.body.neutral())
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(name={:?}, nq={}, nv={}, nbodies={})",
            self.model.name,
            self.body.nq(),
            self.body.nv(),
            self.body.bodies()
        )
    }

    /// Inverse dynamics by the recursive Newton–Euler algorithm:
    /// `tau = M(q) a + C(q, v) v + g(q)`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, a: shape (nv,) or (N, nv).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     tau, shape (nv,) or (N, nv).
    #[pyo3(signature = (q, v, a, params = None))]
    fn rnea<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [tau] = evaluate!(
            self,
            py,
            "rnea",
            params,
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[nv]],
            |st, [q, v, a], [tau]| dyngen_algo::rnea(body, &mut st.plain, q, v, a, &st.params, tau)
        )?;
        Ok(tau)
    }

    /// The bias forces `C(q, v) v + g(q)`, which is `rnea(q, v, 0)`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v: shape (nv,) or (N, nv).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     shape (nv,) or (N, nv).
    #[pyo3(signature = (q, v, params = None))]
    fn nonlinear_effects<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [h] = evaluate!(
            self,
            py,
            "nonlinear_effects",
            params,
            [arg("q", q, nq), arg("v", v, nv)],
            [&[nv]],
            |st, [q, v], [h]| dyngen_algo::rnea(body, &mut st.plain, q, v, &st.zero, &st.params, h)
        )?;
        Ok(h)
    }

    /// The generalized gravity `g(q)`, which is `rnea(q, 0, 0)`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     shape (nv,) or (N, nv).
    #[pyo3(signature = (q, params = None))]
    fn generalized_gravity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [g] = evaluate!(
            self,
            py,
            "generalized_gravity",
            params,
            [arg("q", q, nq)],
            [&[nv]],
            |st, [q], [g]| dyngen_algo::rnea(body, &mut st.plain, q, &st.zero, &st.zero, &st.params, g)
        )?;
        Ok(g)
    }

    /// The joint-space mass matrix `M(q)` by the composite rigid body algorithm, both
    /// triangles filled.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     M, shape (nv, nv) or (N, nv, nv).
    #[pyo3(signature = (q, params = None))]
    fn crba<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [m] = evaluate!(
            self,
            py,
            "crba",
            params,
            [arg("q", q, nq)],
            [&[nv, nv]],
            |st, [q], [m]| { dyngen_algo::crba(body, &mut st.plain, q, &st.params, m) }
        )?;
        Ok(m)
    }

    /// Forward dynamics by the articulated body algorithm:
    /// `a = M(q)⁻¹ (tau − C(q, v) v − g(q))`, without forming `M`. Rotor inertias
    /// (MJCF `armature`) are not included, as in `rnea` and `crba`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, tau: shape (nv,) or (N, nv).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     a, shape (nv,) or (N, nv).
    ///
    /// Raises:
    ///     ValueError: also where `M(q)` is singular (the result is not finite).
    #[pyo3(signature = (q, v, tau, params = None))]
    fn aba<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [qdd] = evaluate!(
            self,
            py,
            "aba",
            params,
            [arg("q", q, nq), arg("v", v, nv), arg("tau", tau, nv)],
            [&[nv]],
            |st, [q, v, tau], [qdd]| dyngen_algo::aba(body, &mut st.plain, q, v, tau, &st.params, &[], qdd)
        )?;
        Ok(qdd)
    }

    /// The derivatives of inverse dynamics at `(q, v, a)` (Pinocchio's
    /// `computeRNEADerivatives`): `∂tau/∂q` (in the tangent space: a free flyer's or
    /// a ball joint's columns along its own angular velocity, as `v`), `∂tau/∂v` and
    /// `∂tau/∂a = M(q)`. Exact to rounding: rnea itself run on dual numbers.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, a: shape (nv,) or (N, nv).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     (dtau_dq, dtau_dv, M), each shape (nv, nv) or (N, nv, nv), row `i` the
    ///     derivatives of `tau[i]`.
    #[pyo3(signature = (q, v, a, params = None))]
    fn rnea_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Matrices3<'py>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [dq, dv, m] = evaluate!(
            self,
            py,
            "rnea_derivatives",
            params,
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[nv, nv], &[nv, nv], &[nv, nv]],
            |st, [q, v, a], [dq, dv, m]| {
                let State {
                    plain, params, dual8, ..
                } = st;
                dyngen_algo::rnea_derivatives(body, dual(dual8, body), plain, q, v, a, params, dq, dv, m)
            }
        )?;
        Ok((dq, dv, m))
    }

    /// Forward dynamics and its derivatives (Pinocchio's `computeABADerivatives`):
    /// `ddq = aba(q, v, tau)`, `∂ddq/∂q` (in the tangent space), `∂ddq/∂v` and
    /// `∂ddq/∂tau = M(q)⁻¹`. Exact to rounding: aba itself run on dual numbers.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, tau: shape (nv,) or (N, nv).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     (ddq, ddq_dq, ddq_dv, Minv): shape (nv,) then three (nv, nv), with a
    ///     leading N for a batch.
    ///
    /// Raises:
    ///     ValueError: also where `M(q)` is singular (the result is not finite).
    #[pyo3(signature = (q, v, tau, params = None))]
    fn aba_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Arrays4<'py>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [ddq, dq, dv, minv] = evaluate!(
            self,
            py,
            "aba_derivatives",
            params,
            [arg("q", q, nq), arg("v", v, nv), arg("tau", tau, nv)],
            [&[nv], &[nv, nv], &[nv, nv], &[nv, nv]],
            |st, [q, v, tau], [ddq, dq, dv, minv]| {
                let State {
                    plain, params, dual8, ..
                } = st;
                dyngen_algo::aba_derivatives(
                    body,
                    dual(dual8, body),
                    plain,
                    q,
                    v,
                    tau,
                    params,
                    &[],
                    ddq,
                    dq,
                    dv,
                    minv,
                )
            }
        )?;
        Ok((ddq, dq, dv, minv))
    }

    /// Every moving body's placement in the base frame, body 1 first (the order of
    /// `body_names`): `x_base = R x_body + t`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///
    /// Returns:
    ///     (R, t): rotations of shape (nbodies, 3, 3) and translations of shape
    ///     (nbodies, 3), or (N, nbodies, 3, 3) and (N, nbodies, 3).
    fn forward_kinematics<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Placements<'py>> {
        let (body, nq, nb) = (&self.body, self.body.nq(), self.body.bodies());
        let [r, t] = evaluate!(
            self,
            py,
            "forward_kinematics",
            None,
            [arg("q", q, nq)],
            [&[nb, 3, 3], &[nb, 3]],
            |st, [q], [r, t]| {
                dyngen_algo::forward_kinematics(body, &mut st.plain, q);
                for i in 0..nb {
                    write_se3(
                        &st.plain.world[i + 1],
                        &mut r[9 * i..9 * i + 9],
                        &mut t[3 * i..3 * i + 3],
                    );
                }
            }
        )?;
        Ok((r, t))
    }

    /// A frame's placement in the base frame: `x_base = R x_frame + t`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     frame: a name of `frame_names`.
    ///
    /// Returns:
    ///     (R, t): shapes (3, 3) and (3,), or (N, 3, 3) and (N, 3).
    fn frame_placement<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>, frame: &str) -> PyResult<Placements<'py>> {
        let (index, offset) = self.frame("frame_placement", frame)?;
        let (body, nq) = (&self.body, self.body.nq());
        let [r, t] = evaluate!(
            self,
            py,
            "frame_placement",
            None,
            [arg("q", q, nq)],
            [&[3, 3], &[3]],
            |st, [q], [r, t]| {
                dyngen_algo::forward_kinematics(body, &mut st.plain, q);
                write_se3(
                    &st.plain.world[index].compose(&dyngen_algo::constant_se3((), &offset)),
                    r,
                    t,
                );
            }
        )?;
        Ok((r, t))
    }

    /// A frame's Jacobian `J(q)`, so that its spatial velocity `[v; ω]` is `J v` in
    /// `reference` (Pinocchio's `computeFrameJacobian`).
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     frame: a name of `frame_names`.
    ///     reference: `"local_world_aligned"` (the frame's origin, the base's axes;
    ///         the default), `"local"` (the frame's own axes) or `"world"` (the base
    ///         frame's origin and axes).
    ///
    /// Returns:
    ///     J, shape (6, nv) or (N, 6, nv), rows `[linear; angular]`.
    #[pyo3(signature = (q, frame, reference = "local_world_aligned"))]
    fn frame_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (index, offset) = self.frame("frame_jacobian", frame)?;
        let reference = reference_frame("frame_jacobian", reference)?;
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [j] = evaluate!(
            self,
            py,
            "frame_jacobian",
            None,
            [arg("q", q, nq)],
            [&[6, nv]],
            |st, [q], [j]| dyngen_algo::compute_frame_jacobian(body, &mut st.plain, q, index, &offset, reference, j)
        )?;
        Ok(j)
    }

    /// A frame's Jacobian and its time variation `dJ = d/dt J(q(t))` along `dq/dt = v`
    /// (Pinocchio's `getFrameJacobianTimeVariation`), in `reference`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v: shape (nv,) or (N, nv).
    ///     frame: a name of `frame_names`.
    ///     reference: as `frame_jacobian`.
    ///
    /// Returns:
    ///     (J, dJ), each shape (6, nv) or (N, 6, nv).
    #[pyo3(signature = (q, v, frame, reference = "local_world_aligned"))]
    fn frame_jacobian_time_variation<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
    ) -> PyResult<Matrices2<'py>> {
        let name = "frame_jacobian_time_variation";
        let (index, offset) = self.frame(name, frame)?;
        let reference = reference_frame(name, reference)?;
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [j, dj] = evaluate!(
            self,
            py,
            name,
            None,
            [arg("q", q, nq), arg("v", v, nv)],
            [&[6, nv], &[6, nv]],
            |st, [q, v], [j, dj]| {
                let d = dual(&mut st.dual1, body);
                dyngen_algo::frame_jacobian_time_variation(body, d, q, v, index, &offset, reference, j, dj)
            }
        )?;
        Ok((j, dj))
    }

    /// A frame's spatial velocity `[v; ω]` in `reference` (Pinocchio's
    /// `getFrameVelocity`): in `"local_world_aligned"` the velocity of its origin and
    /// its angular velocity, in the base's axes.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v: shape (nv,) or (N, nv).
    ///     frame: a name of `frame_names`.
    ///     reference: as `frame_jacobian`.
    ///
    /// Returns:
    ///     shape (6,) or (N, 6).
    #[pyo3(signature = (q, v, frame, reference = "local_world_aligned"))]
    fn frame_velocity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (index, offset) = self.frame("frame_velocity", frame)?;
        let reference = reference_frame("frame_velocity", reference)?;
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [out] = evaluate!(
            self,
            py,
            "frame_velocity",
            None,
            [arg("q", q, nq), arg("v", v, nv)],
            [&[6]],
            |st, [q, v], [out]| {
                let State { plain, zero, .. } = st;
                dyngen_algo::body_motions(body, plain, q, v, zero);
                out.copy_from_slice(&dyngen_algo::frame_velocity(body, plain, index, &offset, reference).to_array());
            }
        )?;
        Ok(out)
    }

    /// A frame's classical acceleration (Pinocchio's `getFrameClassicalAcceleration`):
    /// in `"local_world_aligned"` the second derivative of its origin and the
    /// derivative of its angular velocity, in the base's axes; in `"local"` the same
    /// in its own axes; in `"world"` those of the body-fixed point at the base's
    /// origin. With `a = 0` it is the drift `dJ v` of `"local_world_aligned"`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, a: shape (nv,) or (N, nv).
    ///     frame: a name of `frame_names`.
    ///     reference: as `frame_jacobian`.
    ///
    /// Returns:
    ///     shape (6,) or (N, 6), `[linear; angular]`.
    #[pyo3(signature = (q, v, a, frame, reference = "local_world_aligned"))]
    #[allow(clippy::too_many_arguments)]
    fn frame_classical_acceleration<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let name = "frame_classical_acceleration";
        let (index, offset) = self.frame(name, frame)?;
        let reference = reference_frame(name, reference)?;
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [out] = evaluate!(
            self,
            py,
            name,
            None,
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[6]],
            |st, [q, v, a], [out]| {
                let d = dual(&mut st.dual1, body);
                let acc = dyngen_algo::frame_classical_acceleration(body, d, q, v, a, index, &offset, reference);
                out.copy_from_slice(&acc.to_array());
            }
        )?;
        Ok(out)
    }

    /// The centre of mass of the moving bodies in the base frame (Pinocchio's
    /// `centerOfMass`).
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     shape (3,) or (N, 3).
    #[pyo3(signature = (q, params = None))]
    fn center_of_mass<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq) = (&self.body, self.body.nq());
        let [c] = evaluate!(
            self,
            py,
            "center_of_mass",
            params,
            [arg("q", q, nq)],
            [&[3]],
            |st, [q], [c]| c.copy_from_slice(&dyngen_algo::center_of_mass(body, &mut st.plain, q, &st.params))
        )?;
        Ok(c)
    }

    /// The Jacobian of the centre of mass (Pinocchio's `jacobianCenterOfMass`): its
    /// velocity is `J v`, in the base's axes.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     shape (3, nv) or (N, 3, nv).
    #[pyo3(signature = (q, params = None))]
    fn com_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [j] = evaluate!(
            self,
            py,
            "com_jacobian",
            params,
            [arg("q", q, nq)],
            [&[3, nv]],
            |st, [q], [j]| {
                dyngen_algo::com_jacobian(body, &mut st.plain, q, &st.params, j);
            }
        )?;
        Ok(j)
    }

    /// The centroidal momentum matrix `A_g` (Pinocchio's `ccrba`): the centroidal
    /// momentum `[linear; angular]` (the angular part about the centre of mass, the
    /// base's axes) is `A_g v`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     shape (6, nv) or (N, 6, nv).
    #[pyo3(signature = (q, params = None))]
    fn centroidal_map<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [ag] = evaluate!(
            self,
            py,
            "centroidal_map",
            params,
            [arg("q", q, nq)],
            [&[6, nv]],
            |st, [q], [ag]| {
                dyngen_algo::centroidal_map(body, &mut st.plain, q, &st.params, ag);
            }
        )?;
        Ok(ag)
    }

    /// `A_g` and its time variation `dA_g = d/dt A_g(q(t))` along `dq/dt = v`: the
    /// rate of the centroidal momentum is `A_g a + dA_g v`. (Pinocchio's `dccrba`
    /// gives another matrix with the same product with `v`.)
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v: shape (nv,) or (N, nv).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     (A_g, dA_g), each shape (6, nv) or (N, 6, nv).
    #[pyo3(signature = (q, v, params = None))]
    fn centroidal_map_time_variation<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Matrices2<'py>> {
        let name = "centroidal_map_time_variation";
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [ag, ag_dot] = evaluate!(
            self,
            py,
            name,
            params,
            [arg("q", q, nq), arg("v", v, nv)],
            [&[6, nv], &[6, nv]],
            |st, [q, v], [ag, ag_dot]| {
                let State { params, dual1, .. } = st;
                dyngen_algo::centroidal_map_time_variation(body, dual(dual1, body), q, v, params, ag, ag_dot)
            }
        )?;
        Ok((ag, ag_dot))
    }

    /// The wrench each joint applies to the body it carries, in that body's frame
    /// (force, then moment about the body frame's origin): Pinocchio's `data.f`
    /// after `rnea`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, a: shape (nv,) or (N, nv).
    ///     params: standard parameters, shape (10 * nbodies,); the model's by default.
    ///
    /// Returns:
    ///     shape (nbodies, 6) or (N, nbodies, 6), body 1 first.
    #[pyo3(signature = (q, v, a, params = None))]
    fn joint_wrenches<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        params: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv, nb) = (&self.body, self.body.nq(), self.body.nv(), self.body.bodies());
        let [f] = evaluate!(
            self,
            py,
            "joint_wrenches",
            params,
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[nb, 6]],
            |st, [q, v, a], [f]| {
                // The torques go to the result's first nv entries (nv ≤ 6 nbodies: no
                // joint has more than 6 velocities), then the wrenches over them.
                dyngen_algo::rnea(body, &mut st.plain, q, v, a, &st.params, &mut f[..nv]);
                for i in 0..nb {
                    f[6 * i..6 * i + 6].copy_from_slice(&st.plain.force[i + 1].to_array());
                }
            }
        )?;
        Ok(f)
    }

    /// The joint torque regressor `Y(q, v, a)`, with `tau = Y @ params` for every
    /// choice of the standard parameters (Pinocchio's `computeJointTorqueRegressor`).
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, a: shape (nv,) or (N, nv).
    ///
    /// Returns:
    ///     Y, shape (nv, 10 * nbodies) or (N, nv, 10 * nbodies).
    fn joint_torque_regressor<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv, np) = (&self.body, self.body.nq(), self.body.nv(), self.nparams());
        let [y] = evaluate!(
            self,
            py,
            "joint_torque_regressor",
            None,
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[nv, np]],
            |st, [q, v, a], [y]| dyngen_algo::joint_torque_regressor(body, &mut st.plain, q, v, a, y)
        )?;
        Ok(y)
    }

    /// The joint wrench regressor `W(q, v, a)`: `W @ params`, reshaped to
    /// (nbodies, 6), is `joint_wrenches(q, v, a, params)`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, a: shape (nv,) or (N, nv).
    ///
    /// Returns:
    ///     W, shape (6 * nbodies, 10 * nbodies) or (N, 6 * nbodies, 10 * nbodies).
    fn joint_wrench_regressor<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv, np) = (&self.body, self.body.nq(), self.body.nv(), self.nparams());
        let [w] = evaluate!(
            self,
            py,
            "joint_wrench_regressor",
            None,
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[6 * self.body.bodies(), np]],
            |st, [q, v, a], [w]| dyngen_algo::joint_wrench_regressor(body, &mut st.plain, q, v, a, w)
        )?;
        Ok(w)
    }

    /// The principal regressor (the paper's per-body principal form): `tau = Yp @ theta`
    /// with, per body, `theta_i = (m, J1, J2, J3)`: its mass and principal moments of
    /// inertia about its nominal centre of mass, along its nominal principal axes
    /// (`principal_params`). It is `joint_torque_regressor(q, v, a)` times
    /// `blkdiag(P_i)`, `params_i = P_i theta_i`.
    ///
    /// Args:
    ///     q: shape (nq,) or (N, nq).
    ///     v, a: shape (nv,) or (N, nv).
    ///
    /// Returns:
    ///     Yp, shape (nv, 4 * nbodies) or (N, nv, 4 * nbodies).
    fn principal_regressor<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (body, nq, nv, nb) = (&self.body, self.body.nq(), self.body.nv(), self.body.bodies());
        let (np, principal) = (self.nparams(), &self.principal);
        let [yp] = evaluate!(
            self,
            py,
            "principal_regressor",
            None,
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[nv, 4 * nb]],
            |st, [q, v, a], [yp]| {
                let State { plain, scratch, .. } = st;
                scratch.resize(nv * np, Real::constant((), 0.0));
                dyngen_algo::joint_torque_regressor(body, plain, q, v, a, scratch);
                principal_columns(scratch, principal, yp);
            }
        )?;
        Ok(yp)
    }

    /// The principal parameters of the description, shape (4 * nbodies,): per body
    /// `(m, J1, J2, J3)` (see `principal_regressor`).
    #[getter]
    fn principal_params<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, dyngen_model::principal_params(&self.model))
    }

    /// Which combinations of the parameters the joint torques determine (the base
    /// parameters), by a QR of the regressor stacked over random states, in parameter
    /// order (earlier bodies absorb later ones), confirmed with a second sample and
    /// by the singular values. Computed once per model and kind.
    ///
    /// Args:
    ///     kind: `"standard"` (10 per body, `params`) or `"principal"` (4 per body,
    ///         `principal_params`).
    ///
    /// Returns:
    ///     dict: `names` (the parameters'), `independent` (the columns kept, so that
    ///     the base regressor is `Y[..., independent]`), `K` (b × p: `beta = K @
    ///     params`, and `Y @ params = Y[..., independent] @ beta`), `groupings` (each
    ///     base parameter as text, e.g. `Izz1 + Iyy2`), `confirmed` and `rank_check`
    ///     (the second sample's and the singular values' verdicts), `consistent`.
    #[pyo3(signature = (kind = "standard"))]
    fn base_parameters<'py>(&self, py: Python<'py>, kind: &str) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let (slot, parameterisation) = match kind {
            "standard" => (&self.base[0], Parameterisation::Standard),
            "principal" => (&self.base[1], Parameterisation::Principal),
            other => {
                return Err(PyValueError::new_err(format!(
                    "base_parameters: unknown kind `{other}`; it must be one of: standard, principal"
                )))
            }
        };
        let base = py.detach(|| slot.get_or_init(|| dyngen_model::base::analyse(&self.model, parameterisation)));
        let out = pyo3::types::PyDict::new(py);
        out.set_item("names", parameterisation.names_of(&self.model))?;
        out.set_item("independent", base.independent.clone())?;
        let p = base.k.first().map_or(0, |row| row.len());
        let k: Vec<f64> = base.k.iter().flatten().copied().collect();
        out.set_item("K", PyArray1::from_vec(py, k).reshape([base.k.len(), p])?)?;
        out.set_item("groupings", base.groupings.clone())?;
        out.set_item("confirmed", base.confirmed)?;
        out.set_item("rank_check", base.rank_check)?;
        out.set_item("consistent", base.is_consistent())?;
        Ok(out)
    }
}

/// dyngen's rigid-body dynamics on a robot loaded at run time (URDF or MJCF), one
/// state or a batch of numpy arrays at a time.
#[pymodule]
fn _dyngen(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(identify::identify, m)?)?;
    identify::register(m)?;
    m.add_class::<PyModel>()?;
    m.add("LoadError", m.py().get_type::<LoadError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
