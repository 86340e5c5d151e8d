//! The native module `dyngen._dyngen` of the Python package `dyngen`: a robot loaded
//! at run time by `dyngen-model` (URDF or MJCF), its dynamics evaluated by
//! `dyngen-algo` on `f64`, on numpy arrays.
//!
//! Every algorithm takes one state (1-D arrays) or a batch (2-D arrays, one state per
//! row). Inputs that are C-contiguous `float64` arrays are read in place, others are
//! converted once; results are written into freshly allocated numpy arrays. The
//! evaluation runs with the GIL released, a large batch split across threads
//! (`std::thread::scope`), each thread with its own [`Workspace`], so that no state
//! allocates. Bad input raises a Python exception naming the argument and, for a
//! batch, the row. `identify` runs the identification pipeline of `dyngen identify`.

mod identify;

use dyngen_algo::{Multibody, ReferenceFrame, Se3, Workspace, PARAMS_PER_BODY};
use dyngen_model::{LoadOptions, Model};
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

/// A batch is split across threads only when every thread gets at least this many
/// rows: below, starting a thread costs more than it saves.
const MIN_ROWS_PER_THREAD: usize = 256;

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
    /// Workspaces made for `body`, reused across calls: one per thread in use.
    pool: Mutex<Vec<Workspace<f64>>>,
    max_threads: Option<usize>,
}

/// One input of an algorithm: its name and the number of entries per state.
struct Arg<'a, 'py> {
    name: &'static str,
    value: &'a Bound<'py, PyAny>,
    width: usize,
}

/// The cores, read once: `available_parallelism` reads the cgroup's quota (microseconds)
/// on every call.
fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
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
#[derive(Clone, Copy, Debug)]
enum RowFailure {
    /// Entry `index` of input `arg` in row `row` is not finite.
    Input {
        row: usize,
        arg: &'static str,
        index: usize,
    },
    /// The result of row `row` is not finite.
    Output { row: usize },
}

impl RowFailure {
    fn row(&self) -> usize {
        match *self {
            RowFailure::Input { row, .. } | RowFailure::Output { row } => row,
        }
    }

    fn message(&self, algorithm: &str, batch: bool) -> String {
        match (*self, batch) {
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
        }
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

/// Evaluates `kernel` on rows `start..start + count`, the outputs being those rows'
/// slices of every output; stops at the first row with a non-finite input or result.
fn run_chunk<const I: usize, const O: usize, F>(
    workspace: &mut Workspace<f64>,
    start: usize,
    count: usize,
    inputs: &[Rows<'_>; I],
    mut outputs: [&mut [f64]; O],
    widths: [usize; O],
    kernel: &F,
) -> Result<(), RowFailure>
where
    F: Fn(&mut Workspace<f64>, [&[f64]; I], [&mut [f64]; O]),
{
    for r in 0..count {
        let row = start + r;
        let ins: [&[f64]; I] = core::array::from_fn(|k| {
            let w = inputs[k].width;
            &inputs[k].data[row * w..(row + 1) * w]
        });
        for (k, x) in ins.iter().enumerate() {
            if let Some(index) = x.iter().position(|v| !v.is_finite()) {
                return Err(RowFailure::Input {
                    row,
                    arg: inputs[k].name,
                    index,
                });
            }
        }
        let mut k = 0;
        let outs = outputs.each_mut().map(|o| {
            let w = widths[k];
            k += 1;
            &mut o[r * w..(r + 1) * w]
        });
        kernel(workspace, ins, outs);
        for (o, w) in outputs.iter().zip(widths) {
            if o[r * w..(r + 1) * w].iter().any(|v| !v.is_finite()) {
                return Err(RowFailure::Output { row });
            }
        }
    }
    Ok(())
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
            model,
            body,
            frames,
            warnings,
            pool: Mutex::new(Vec::new()),
            max_threads: None,
        })
    }

    fn nparams(&self) -> usize {
        PARAMS_PER_BODY * self.body.bodies()
    }

    fn take_workspace(&self) -> Workspace<f64> {
        // A poisoned pool only lost workspaces; take it over as it is.
        let taken = self.pool.lock().unwrap_or_else(|e| e.into_inner()).pop();
        taken.unwrap_or_else(|| Workspace::new(&self.body, ()))
    }

    fn give_back(&self, workspaces: impl IntoIterator<Item = Workspace<f64>>) {
        self.pool.lock().unwrap_or_else(|e| e.into_inner()).extend(workspaces);
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

    /// Runs `kernel` on every state of the inputs `args` (one state or a batch), with
    /// the GIL released and a large batch split across threads, into new arrays of
    /// the per-state shapes `outputs` (with a leading `N` for a batch).
    fn evaluate<'py, const I: usize, const O: usize, F>(
        &self,
        py: Python<'py>,
        algorithm: &str,
        args: [Arg<'_, 'py>; I],
        outputs: [&[usize]; O],
        kernel: F,
    ) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; O]>
    where
        F: Fn(&mut Workspace<f64>, [&[f64]; I], [&mut [f64]; O]) + Sync,
    {
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
        let inputs: [Rows<'_>; I] = core::array::from_fn(|k| data[k]);
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
        let Ok(slices) = <[&mut [f64]; O]>::try_from(slices) else {
            unreachable!("one slice per output")
        };
        let max_threads = self.max_threads;
        let result = py.detach(|| {
            // The core count is read only for a batch that can be split.
            let threads = if rows < 2 * MIN_ROWS_PER_THREAD || max_threads == Some(1) {
                1
            } else {
                let cores = max_threads.unwrap_or_else(cores);
                cores.min(rows / MIN_ROWS_PER_THREAD).max(1)
            };
            if threads == 1 {
                let mut ws = self.take_workspace();
                let out = run_chunk(&mut ws, 0, rows, &inputs, slices, widths, &kernel);
                self.give_back([ws]);
                return out;
            }
            let chunk = rows.div_ceil(threads);
            let mut rest = slices;
            std::thread::scope(|s| {
                let mut handles = Vec::with_capacity(threads);
                let mut start = 0;
                while start < rows {
                    let count = chunk.min(rows - start);
                    let mut k = 0;
                    let mine = rest.each_mut().map(|r| {
                        let (head, tail) = std::mem::take(r).split_at_mut(count * widths[k]);
                        *r = tail;
                        k += 1;
                        head
                    });
                    let mut ws = self.take_workspace();
                    let (inputs, kernel) = (&inputs, &kernel);
                    handles.push(s.spawn(move || {
                        let out = run_chunk(&mut ws, start, count, inputs, mine, widths, kernel);
                        (ws, out)
                    }));
                    start += count;
                }
                // Each thread stops at its first failure; report the earliest row.
                let mut first: Option<RowFailure> = None;
                for h in handles {
                    let (ws, out) = h.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
                    self.give_back([ws]);
                    if let Err(f) = out {
                        if first.is_none_or(|g| f.row() < g.row()) {
                            first = Some(f);
                        }
                    }
                }
                first.map_or(Ok(()), Err)
            })
        });
        drop(guards);
        result.map_err(|f| PyValueError::new_err(f.message(algorithm, batch.is_some())))?;
        Ok(arrays)
    }
}

/// Rotations and translations, as numpy arrays.
type Placements<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);

/// Copies the `Se3` `x` into a row-major rotation (9 entries) and a translation (3).
fn write_se3(x: &Se3<f64>, rotation: &mut [f64], translation: &mut [f64]) {
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

    /// The joints' names in the model's order (the order of `q` and `v`; a free flyer
    /// is `root_joint`).
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
    /// every thread gets at least 256 states; results do not depend on the split.
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
        let p = self.read_params("rnea", params)?;
        let p = p
            .as_ref()
            .map(|p| slice(p, "params"))
            .transpose()?
            .unwrap_or(&self.body.params);
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [tau] = self.evaluate(
            py,
            "rnea",
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[nv]],
            |ws, [q, v, a], [tau]| dyngen_algo::rnea(body, ws, q, v, a, p, tau),
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
        let p = self.read_params("nonlinear_effects", params)?;
        let p = p
            .as_ref()
            .map(|p| slice(p, "params"))
            .transpose()?
            .unwrap_or(&self.body.params);
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let zero = vec![0.0; nv];
        let [h] = self.evaluate(
            py,
            "nonlinear_effects",
            [arg("q", q, nq), arg("v", v, nv)],
            [&[nv]],
            |ws, [q, v], [h]| dyngen_algo::rnea(body, ws, q, v, &zero, p, h),
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
        let p = self.read_params("generalized_gravity", params)?;
        let p = p
            .as_ref()
            .map(|p| slice(p, "params"))
            .transpose()?
            .unwrap_or(&self.body.params);
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let zero = vec![0.0; nv];
        let [g] = self.evaluate(py, "generalized_gravity", [arg("q", q, nq)], [&[nv]], |ws, [q], [g]| {
            dyngen_algo::rnea(body, ws, q, &zero, &zero, p, g)
        })?;
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
        let p = self.read_params("crba", params)?;
        let p = p
            .as_ref()
            .map(|p| slice(p, "params"))
            .transpose()?
            .unwrap_or(&self.body.params);
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [m] = self.evaluate(py, "crba", [arg("q", q, nq)], [&[nv, nv]], |ws, [q], [m]| {
            dyngen_algo::crba(body, ws, q, p, m)
        })?;
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
        let p = self.read_params("aba", params)?;
        let p = p
            .as_ref()
            .map(|p| slice(p, "params"))
            .transpose()?
            .unwrap_or(&self.body.params);
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [qdd] = self.evaluate(
            py,
            "aba",
            [arg("q", q, nq), arg("v", v, nv), arg("tau", tau, nv)],
            [&[nv]],
            |ws, [q, v, tau], [qdd]| dyngen_algo::aba(body, ws, q, v, tau, p, &[], qdd),
        )?;
        Ok(qdd)
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
        let [r, t] = self.evaluate(
            py,
            "forward_kinematics",
            [arg("q", q, nq)],
            [&[nb, 3, 3], &[nb, 3]],
            |ws, [q], [r, t]| {
                dyngen_algo::forward_kinematics(body, ws, q);
                for i in 0..nb {
                    write_se3(&ws.world[i + 1], &mut r[9 * i..9 * i + 9], &mut t[3 * i..3 * i + 3]);
                }
            },
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
        let [r, t] = self.evaluate(
            py,
            "frame_placement",
            [arg("q", q, nq)],
            [&[3, 3], &[3]],
            |ws, [q], [r, t]| {
                dyngen_algo::forward_kinematics(body, ws, q);
                write_se3(&ws.world[index].compose(&offset), r, t);
            },
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
        let Some(&(_, reference)) = REFERENCES.iter().find(|(name, _)| *name == reference) else {
            return Err(PyValueError::new_err(format!(
                "frame_jacobian: unknown reference `{reference}`; it must be one of: {}",
                REFERENCES.map(|(name, _)| name).join(", ")
            )));
        };
        let (body, nq, nv) = (&self.body, self.body.nq(), self.body.nv());
        let [j] = self.evaluate(py, "frame_jacobian", [arg("q", q, nq)], [&[6, nv]], |ws, [q], [j]| {
            dyngen_algo::compute_frame_jacobian(body, ws, q, index, &offset, reference, j)
        })?;
        Ok(j)
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
        let p = self.read_params("joint_wrenches", params)?;
        let p = p
            .as_ref()
            .map(|p| slice(p, "params"))
            .transpose()?
            .unwrap_or(&self.body.params);
        let (body, nq, nv, nb) = (&self.body, self.body.nq(), self.body.nv(), self.body.bodies());
        let [f] = self.evaluate(
            py,
            "joint_wrenches",
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[nb, 6]],
            |ws, [q, v, a], [f]| {
                // The torques go to the result's first nv entries (nv ≤ 6 nbodies: no
                // joint has more than 6 velocities), then the wrenches over them.
                dyngen_algo::rnea(body, ws, q, v, a, p, &mut f[..nv]);
                for i in 0..nb {
                    f[6 * i..6 * i + 6].copy_from_slice(&ws.force[i + 1].to_array());
                }
            },
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
        let [y] = self.evaluate(
            py,
            "joint_torque_regressor",
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[nv, np]],
            |ws, [q, v, a], [y]| dyngen_algo::joint_torque_regressor(body, ws, q, v, a, y),
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
        let [w] = self.evaluate(
            py,
            "joint_wrench_regressor",
            [arg("q", q, nq), arg("v", v, nv), arg("a", a, nv)],
            [&[6 * self.body.bodies(), np]],
            |ws, [q, v, a], [w]| dyngen_algo::joint_wrench_regressor(body, ws, q, v, a, w),
        )?;
        Ok(w)
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
