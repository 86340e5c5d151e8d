//! The Python module `@MODULE@`: the dynamics dyngen generated for `@ROBOT@` (the type
//! `@TYPE@` in `robot.rs`), on numpy arrays. One state (1-D arrays) is one call of the
//! generated function on `f64`; a batch (2-D arrays, one state per row) runs on SIMD
//! lanes, eight states per call, split across threads (`dyngen::batch`), bit for bit
//! the states one at a time. Written by `dyngen generate --python`.

#[allow(clippy::all, unused)]
mod robot {
    include!("robot.rs");
}

use dyngen::batch::{Batch, BatchError, Input, Layout, Output, Threads};
use dyngen::lanes::F64x8;
use dyngen::prelude::*;
use dyngen::ReferenceFrame;
use numpy::{IxDyn, PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
// The traits' functions (on slices), not the type's own (on arrays of its sizes).
use robot::@TYPE@ as R;

/// An input as C-contiguous `float64`, and its rows (`None` for one state).
fn read<'py>(
    function: &str,
    name: &str,
    value: &Bound<'py, PyAny>,
    width: usize,
) -> PyResult<(PyReadonlyArrayDyn<'py, f64>, Option<usize>)> {
    let py = value.py();
    let numpy = PyModule::import(py, "numpy")?;
    let array = numpy
        .call_method1("ascontiguousarray", (value, numpy.getattr("float64")?))
        .and_then(|a| Ok(a.cast_into::<PyArrayDyn<f64>>()?))
        .map_err(|e| PyTypeError::new_err(format!("{function}: `{name}` must be an array of real numbers: {e}")))?;
    let rows = match array.shape() {
        [n] if *n == width => None,
        [n, w] if *w == width => Some(*n),
        shape => {
            return Err(PyValueError::new_err(format!(
                "{function}: `{name}` must have shape ({width},) for one state or (N, {width}) for a batch; found shape {shape:?}"
            )))
        }
    };
    let array = array
        .try_readonly()
        .map_err(|e| PyValueError::new_err(format!("{function}: `{name}` cannot be read: {e}")))?;
    let values = array.as_slice().map_err(|e| PyValueError::new_err(format!("{function}: `{name}`: {e}")))?;
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        let at = match rows {
            None => format!("index {i}"),
            Some(_) => format!("row {}, index {}", i / width, i % width),
        };
        return Err(PyValueError::new_err(format!("{function}: `{name}` has a non-finite entry at {at}")));
    }
    Ok((array, rows))
}

/// The parameters: `params` checked, or the description's.
fn parameters(function: &str, params: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<f64>> {
    match params.filter(|p| !p.is_none()) {
        None => Ok(<R as RobotDescription>::nominal_params().to_vec()),
        Some(p) => {
            let (array, rows) = read(function, "params", p, R::NPARAMS)?;
            if rows.is_some() {
                return Err(PyValueError::new_err(format!(
                    "{function}: `params` must have shape ({},)",
                    R::NPARAMS
                )));
            }
            Ok(array.as_slice()?.to_vec())
        }
    }
}

/// Evaluates `one` (one state, `f64`) or `batch` (rows on lanes) on the inputs into a
/// new array of the per-state shape `shape`.
fn evaluate<'py>(
    py: Python<'py>,
    function: &str,
    inputs: &[(&str, &Bound<'py, PyAny>, usize)],
    shape: &[usize],
    threads: Option<usize>,
    one: impl Fn(&[&[f64]], &mut [f64]) + Send + Sync,
    batch: impl Fn(&Batch<F64x8>, &[&[f64]], &mut [f64]) -> Result<(), BatchError> + Send + Sync,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let mut read_inputs = Vec::with_capacity(inputs.len());
    for (name, value, width) in inputs {
        read_inputs.push(read(function, name, value, *width)?);
    }
    let rows = read_inputs[0].1;
    if read_inputs.iter().any(|(_, r)| *r != rows) {
        return Err(PyValueError::new_err(format!(
            "{function}: give every argument as one state (1-D) or every one as a batch with the same number of rows"
        )));
    }
    if threads == Some(0) {
        return Err(PyValueError::new_err(format!("{function}: `threads` must be at least 1 (or None)")));
    }
    let full: Vec<usize> = rows.into_iter().chain(shape.iter().copied()).collect();
    let out = PyArrayDyn::<f64>::zeros(py, IxDyn(&full), false);
    {
        let mut guard = out.try_readwrite()?;
        let result = guard.as_slice_mut()?;
        let slices: Vec<&[f64]> = read_inputs.iter().map(|(a, _)| a.as_slice()).collect::<Result<_, _>>()?;
        let failure = py.detach(|| match rows {
            None => {
                one(&slices, result);
                match result.iter().all(|x| x.is_finite()) {
                    true => Ok(()),
                    false => Err(PyValueError::new_err(format!(
                        "{function}: the result is not finite (a singular mass matrix, or inputs too large)"
                    ))),
                }
            }
            Some(n) => {
                let most = (n / Batch::<F64x8>::STATES_PER_THREAD).max(1);
                let threads = threads.map_or(Threads::Auto, |t| Threads::Count(t.min(most)));
                batch(&Batch::new(n, Layout::Rows).threads(threads), &slices, result).map_err(|e| match e {
                    BatchError::NonFinite { state, .. } => PyValueError::new_err(format!(
                        "{function}: the result of row {state} is not finite (a singular mass matrix, or inputs too large)"
                    )),
                    other => PyRuntimeError::new_err(format!("{function}: {other}")),
                })
            }
        });
        failure?;
    }
    Ok(out)
}

/// Inverse dynamics `tau = M(q) a + C(q, v) v + g(q)`: `q` (nq,) or (N, nq), `v`, `a`
/// (nv,) or (N, nv); `params` (nparams,), the description's by default; `threads` caps
/// the threads of a batch. Returns (nv,) or (N, nv).
#[pyfunction]
#[pyo3(signature = (q, v, a, params = None, threads = None))]
fn rnea<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let p = parameters("rnea", params)?;
    evaluate(
        py,
        "rnea",
        &[("q", q, R::NQ), ("v", v, R::NV), ("a", a, R::NV)],
        &[R::NV],
        threads,
        |x, y| <R as InverseDynamics>::rnea(x[0], x[1], x[2], &p, y),
        |b, x, y| b.rnea::<R>(x[0], x[1], x[2], &p, y),
    )
}

/// The bias forces `C(q, v) v + g(q)`: (nv,) or (N, nv).
#[pyfunction]
#[pyo3(signature = (q, v, params = None, threads = None))]
fn nonlinear_effects<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let p = parameters("nonlinear_effects", params)?;
    evaluate(
        py,
        "nonlinear_effects",
        &[("q", q, R::NQ), ("v", v, R::NV)],
        &[R::NV],
        threads,
        |x, y| <R as InverseDynamics>::nonlinear_effects(x[0], x[1], &p, y),
        |b, x, y| b.nonlinear_effects::<R>(x[0], x[1], &p, y),
    )
}

/// The generalized gravity `g(q)`: (nv,) or (N, nv).
#[pyfunction]
#[pyo3(signature = (q, params = None, threads = None))]
fn generalized_gravity<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let p = parameters("generalized_gravity", params)?;
    evaluate(
        py,
        "generalized_gravity",
        &[("q", q, R::NQ)],
        &[R::NV],
        threads,
        |x, y| <R as InverseDynamics>::generalized_gravity(x[0], &p, y),
        |b, x, y| b.generalized_gravity::<R>(x[0], &p, y),
    )
}

/// The joint-space mass matrix `M(q)`: (nv, nv) or (N, nv, nv).
#[pyfunction]
#[pyo3(signature = (q, params = None, threads = None))]
fn crba<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let p = parameters("crba", params)?;
    evaluate(
        py,
        "crba",
        &[("q", q, R::NQ)],
        &[R::NV, R::NV],
        threads,
        |x, y| <R as MassMatrix>::crba(x[0], &p, y),
        |b, x, y| b.crba::<R>(x[0], &p, y),
    )
}

/// Forward dynamics `a = M(q)⁻¹ (tau − C(q, v) v − g(q))`: (nv,) or (N, nv).
#[pyfunction]
#[pyo3(signature = (q, v, tau, params = None, threads = None))]
fn aba<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let p = parameters("aba", params)?;
    evaluate(
        py,
        "aba",
        &[("q", q, R::NQ), ("v", v, R::NV), ("tau", tau, R::NV)],
        &[R::NV],
        threads,
        |x, y| <R as ForwardDynamics>::aba(x[0], x[1], x[2], &p, y),
        |b, x, y| b.aba::<R>(x[0], x[1], x[2], &p, y),
    )
}

/// The joint torque regressor `Y(q, v, a)`, `tau = Y @ params`: (nv, nparams) or
/// (N, nv, nparams).
#[pyfunction]
#[pyo3(signature = (q, v, a, threads = None))]
fn joint_torque_regressor<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    evaluate(
        py,
        "joint_torque_regressor",
        &[("q", q, R::NQ), ("v", v, R::NV), ("a", a, R::NV)],
        &[R::NV, R::NPARAMS],
        threads,
        |x, y| <R as Regressors>::joint_torque_regressor(x[0], x[1], x[2], y),
        |b, x, y| b.joint_torque_regressor::<R>(x[0], x[1], x[2], y),
    )
}

/// A frame's Jacobian `J(q)` in `reference` (`"local_world_aligned"`, the default,
/// `"local"` or `"world"`), rows `[linear; angular]`: (6, nv) or (N, 6, nv). `frame` is
/// a name of `FRAME_NAMES`.
#[pyfunction]
#[pyo3(signature = (q, frame, reference = "local_world_aligned", threads = None))]
fn frame_jacobian<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    frame: &str,
    reference: &str,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let frames = R::MODEL.frames;
    let Some(index) = frames.iter().position(|f| f.name == frame) else {
        let names: Vec<&str> = frames.iter().map(|f| f.name).collect();
        return Err(PyValueError::new_err(format!(
            "frame_jacobian: no frame `{frame}`; the frames are {}",
            names.join(", ")
        )));
    };
    let reference = match reference {
        "local_world_aligned" => ReferenceFrame::LocalWorldAligned,
        "local" => ReferenceFrame::Local,
        "world" => ReferenceFrame::World,
        other => {
            return Err(PyValueError::new_err(format!(
                "frame_jacobian: reference `{other}` is none of \"local_world_aligned\", \"local\", \"world\""
            )))
        }
    };
    evaluate(
        py,
        "frame_jacobian",
        &[("q", q, R::NQ)],
        &[6, R::NV],
        threads,
        |x, y| {
            <R as Frames>::frame_jacobian(x[0], index, reference, y);
        },
        |b, x, y| {
            b.apply(
                &[Input { name: "q", data: x[0], width: R::NQ }],
                &mut [Output { name: "jacobian", data: y, width: 6 * R::NV }],
                |x, y| {
                    <R as Frames>::frame_jacobian(&x[0], index, reference, &mut y[0]);
                },
            )
        },
    )
}

/// The centroidal momentum matrix `A_g(q)` (rows `[linear; angular]`, the angular
/// momentum about the centre of mass, world axes): (6, nv) or (N, 6, nv).
#[pyfunction]
#[pyo3(signature = (q, params = None, threads = None))]
fn centroidal_map<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let p = parameters("centroidal_map", params)?;
    let lanes: Vec<F64x8> = p.iter().map(|&x| F64x8::from_f64(x)).collect();
    evaluate(
        py,
        "centroidal_map",
        &[("q", q, R::NQ)],
        &[6, R::NV],
        threads,
        |x, y| <R as Centroidal>::centroidal_map(x[0], &p, y),
        |b, x, y| {
            b.apply(
                &[Input { name: "q", data: x[0], width: R::NQ }],
                &mut [Output { name: "a_g", data: y, width: 6 * R::NV }],
                |x, y| <R as Centroidal>::centroidal_map(&x[0], &lanes, &mut y[0]),
            )
        },
    )
}

/// The description's standard parameters, 10 per body in Pinocchio's order.
#[pyfunction]
fn nominal_params(py: Python<'_>) -> Bound<'_, PyArray1<f64>> {
    PyArray1::from_slice(py, <R as RobotDescription>::nominal_params())
}

/// The dynamics of `@ROBOT@`, generated by dyngen: `rnea`, `nonlinear_effects`,
/// `generalized_gravity`, `crba`, `aba`, `joint_torque_regressor`, `frame_jacobian`,
/// `centroidal_map` on one state or a batch of numpy arrays.
#[pymodule]
fn @MODULE@(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(rnea, m)?)?;
    m.add_function(wrap_pyfunction!(nonlinear_effects, m)?)?;
    m.add_function(wrap_pyfunction!(generalized_gravity, m)?)?;
    m.add_function(wrap_pyfunction!(crba, m)?)?;
    m.add_function(wrap_pyfunction!(aba, m)?)?;
    m.add_function(wrap_pyfunction!(joint_torque_regressor, m)?)?;
    m.add_function(wrap_pyfunction!(frame_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(centroidal_map, m)?)?;
    m.add_function(wrap_pyfunction!(nominal_params, m)?)?;
    m.add("NAME", R::NAME)?;
    m.add("NQ", R::NQ)?;
    m.add("NV", R::NV)?;
    m.add("NPARAMS", R::NPARAMS)?;
    m.add("JOINT_NAMES", R::MODEL.joints.iter().map(|j| j.name).collect::<Vec<_>>())?;
    m.add("FRAME_NAMES", R::MODEL.frames.iter().map(|f| f.name).collect::<Vec<_>>())?;
    Ok(())
}
