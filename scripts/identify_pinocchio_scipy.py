#!/usr/bin/env python3
"""Baseline identification with per-joint friction: Pinocchio + numpy/scipy.

The plain pipeline a robotics engineer would write, as the reference dyngen's
`identify` is compared against (accuracy and time):

1. read a CSV in dyngen's layout (header `t, q1..qn[, v1..vn][, a1..an], tau1..taun`,
   SI units; other columns are ignored);
2. clean: drop rows whose stamp does not increase and stale rows (every value but the
   stamp equal to the previous row's);
3. resample q (cubic spline) and, if present, the measured velocity (linear) onto a
   uniform grid at the median logging step;
4. zero-phase low-pass (scipy.signal.butter, 4th order, --cutoff Hz, filtfilt) and
   differentiate (numpy.gradient): qd from the filtered measured velocity if the file
   has one, else from the filtered q; qdd from the filtered qd; then interpolate the
   states back to the cleaned rows' stamps, so the torques compared are the measured
   ones, unfiltered and not resampled;
5. per row, Pinocchio's joint torque regressor `pin.computeJointTorqueRegressor`
   (n x 10n) next to per-joint friction columns `[qdd_j, qd_j, sign(qd_j), 1]`
   (armature, viscous, Coulomb, offset; n x 4n, joint j's in row j only);
6. ordinary least squares, `numpy.linalg.lstsq` (minimum-norm for the unidentifiable
   directions);
7. predict the --validate file (same steps 1-5, then Y theta) and report per joint RMS
   and relative error ||tau_hat - tau|| / ||tau|| per joint and overall (all joints
   stacked), on both files.

Prints one JSON object: errors, rank, friction estimates and the time of each stage
(read, clean + resample + filter, regressor, solve, predict; median of --reps
runs of the whole pipeline, and the first run). Needs `pip install pin
numpy scipy`. From the project root:

    python scripts/identify_pinocchio_scipy.py --urdf robots/ur5/ur5.urdf \\
        --identify tests/fixtures/mujoco/ur5_identify.csv \\
        --validate tests/fixtures/mujoco/ur5_validate.csv

On a machine whose cores are busy with other work, a multi-threaded BLAS can make the
small least-squares solve 20x slower (thread contention); time it single-threaded,
`OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 python scripts/identify_pinocchio_scipy.py ...`
(the JSON records these variables).

Results on the MuJoCo fixture (tests/fixtures/mujoco/README.md) are in
scripts/README.md. Joints must have one coordinate each (revolute or prismatic, no
continuous joints); gravity is [0, 0, -9.81] unless --gravity says otherwise.
"""

import argparse
import json
import os
import re
import statistics
import sys
import time

import numpy as np
import pinocchio as pin
import scipy
from scipy.interpolate import CubicSpline
from scipy.signal import butter, filtfilt


def read_csv(path):
    """(t, q, v or None, tau) from a dyngen-layout CSV."""
    with open(path) as f:
        header = [h.strip() for h in f.readline().split(",")]
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)

    def group(prefix):
        cols = sorted(
            ((int(m.group(1)), i) for i, h in enumerate(header) if (m := re.fullmatch(prefix + r"([1-9][0-9]*)", h))),
        )
        return np.column_stack([data[:, i] for _, i in cols]) if cols else None

    q, v, tau = group("q"), group("v"), group("tau")
    if q is None or tau is None or "t" not in header:
        sys.exit(f"{path}: needs columns t, q1.., tau1..")
    return data[:, header.index("t")], q, v, tau


def clean(t, q, v, tau):
    """Drop rows whose stamp does not increase, and stale rows (values repeated)."""
    vals = np.column_stack([x for x in (q, v, tau) if x is not None])
    keep = np.ones(len(t), bool)
    last_t, last_vals = -np.inf, None
    for i in range(len(t)):
        if t[i] <= last_t or (last_vals is not None and np.array_equal(vals[i], last_vals)):
            keep[i] = False
            continue
        last_t, last_vals = t[i], vals[i]
    sel = lambda x: None if x is None else x[keep]
    return t[keep], q[keep], sel(v), tau[keep], int((~keep).sum())


def states(t, q, v, cutoff):
    """Filtered q, qd, qdd at the stamps t."""
    dt = float(np.median(np.diff(t)))
    tg = np.arange(t[0], t[-1] + 0.5 * dt, dt)
    tg = tg[tg <= t[-1]]
    b, a = butter(4, cutoff / (0.5 / dt))
    qf = filtfilt(b, a, CubicSpline(t, q, axis=0)(tg), axis=0)
    if v is not None:
        vg = np.column_stack([np.interp(tg, t, v[:, j]) for j in range(v.shape[1])])
        vf = filtfilt(b, a, vg, axis=0)
    else:
        vf = np.gradient(qf, dt, axis=0)
    af = np.gradient(vf, dt, axis=0)
    back = lambda x: np.column_stack([np.interp(t, tg, x[:, j]) for j in range(x.shape[1])])
    return back(qf), back(vf), back(af), dt


def regressor(model, data, q, v, a):
    """Stacked rows: rigid-body regressor (n x 10n) | friction (n x 4n) per sample."""
    n, nv = len(q), model.nv
    Y = np.zeros((n * nv, 14 * nv))
    rows = np.arange(nv)
    for i in range(n):
        r = slice(nv * i, nv * (i + 1))
        Y[r, : 10 * nv] = pin.computeJointTorqueRegressor(model, data, q[i], v[i], a[i])
        f = Y[r, 10 * nv :]
        f[rows, 4 * rows] = a[i]
        f[rows, 4 * rows + 1] = v[i]
        f[rows, 4 * rows + 2] = np.sign(v[i])
        f[rows, 4 * rows + 3] = 1.0
    return Y


def errors(tau, tau_hat):
    r = tau_hat - tau
    return {
        "rms_per_joint": np.sqrt(np.mean(r**2, axis=0)).tolist(),
        "relative_per_joint": (np.linalg.norm(r, axis=0) / np.linalg.norm(tau, axis=0)).tolist(),
        "relative_overall": float(np.linalg.norm(r) / np.linalg.norm(tau)),
    }


def load(path, cutoff, timings, key):
    t0 = time.perf_counter()
    t, q, v, tau = read_csv(path)
    t1 = time.perf_counter()
    t, q, v, tau, dropped = clean(t, q, v, tau)
    q, v, a, dt = states(t, q, v, cutoff)
    t2 = time.perf_counter()
    timings[f"{key}_read_s"] = t1 - t0
    timings[f"{key}_clean_resample_filter_s"] = t2 - t1
    info = {"file": path, "rows_used": len(t), "rows_dropped": dropped, "resample_step_s": dt}
    return q, v, a, tau, info


def run(args):
    """The whole pipeline once: (report, timings)."""
    timings = {}
    t_start = time.perf_counter()
    model = pin.buildModelFromUrdf(args.urdf)
    model.gravity.linear = np.array(args.gravity)
    data = model.createData()
    if model.nq != model.nv:
        sys.exit("joints with more than one coordinate (continuous) are not handled")
    nv = model.nv

    q, v, a, tau, info_id = load(args.identify, args.cutoff, timings, "identify")
    if q.shape[1] != nv:
        sys.exit(f"{args.identify}: {q.shape[1]} joints, the URDF has {nv}")
    t0 = time.perf_counter()
    Y = regressor(model, data, q, v, a)
    t1 = time.perf_counter()
    theta, _, rank, sv = np.linalg.lstsq(Y, tau.reshape(-1), rcond=None)
    t2 = time.perf_counter()
    timings["identify_regressor_s"] = t1 - t0
    timings["solve_s"] = t2 - t1
    fit = errors(tau, (Y @ theta).reshape(tau.shape))

    t3 = time.perf_counter()
    qv, vv, av, tauv, info_val = load(args.validate, args.cutoff, timings, "validate")
    t4 = time.perf_counter()
    tau_hat = (regressor(model, data, qv, vv, av) @ theta).reshape(tauv.shape)
    t5 = time.perf_counter()
    timings["validate_regressor_predict_s"] = t5 - t4
    timings["predict_total_s"] = t5 - t3
    timings["identify_total_s"] = t2 - t_start
    timings["total_s"] = t5 - t_start

    fr = theta[10 * nv :].reshape(nv, 4)
    out = {
        "pinocchio": pin.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "urdf": args.urdf,
        "cutoff_hz": args.cutoff,
        "identify": {**info_id, **fit},
        "validate": {**info_val, **errors(tauv, tau_hat)},
        "rank": int(rank),
        "columns": int(Y.shape[1]),
        "condition_number": float(sv[0] / sv[rank - 1]),
        # Armature is not separable from a body's inertia about a joint axis that never
        # tilts (e.g. the first joint's Izz): the minimum-norm solution splits them.
        "friction_per_joint": {
            "armature_min_norm": fr[:, 0].tolist(),
            "viscous": fr[:, 1].tolist(),
            "coulomb": fr[:, 2].tolist(),
            "offset": fr[:, 3].tolist(),
        },
    }
    return out, timings


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--urdf", required=True)
    ap.add_argument("--identify", required=True, help="CSV to identify on")
    ap.add_argument("--validate", required=True, help="CSV to predict")
    ap.add_argument("--cutoff", type=float, default=5.0, help="low-pass cutoff, Hz (default 5)")
    ap.add_argument("--gravity", type=float, nargs=3, default=[0.0, 0.0, -9.81])
    ap.add_argument("--reps", type=int, default=5, help="runs of the whole pipeline; timings are medians")
    args = ap.parse_args()

    runs = [run(args) for _ in range(max(1, args.reps))]
    out = runs[0][0]
    out["timings_median_s"] = {k: statistics.median(r[1][k] for r in runs) for k in runs[0][1]}
    out["timings_first_run_s"] = runs[0][1]
    out["reps"] = len(runs)
    out["blas_threads_env"] = {k: os.environ.get(k) for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
