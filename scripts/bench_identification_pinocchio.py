#!/usr/bin/env python3
"""Peer of tests/benches/identification.rs: identification of the Panda from
100,000 samples with Pinocchio's joint torque regressor and numpy least squares.

Per sample `pin.computeJointTorqueRegressor` (7 x 70) is written into a
preallocated 700,000 x 70 array; `numpy.linalg.lstsq` with an explicit rcond
solves it (rank handling by SVD, as ours). States are uniform within the joint
limits (positions clipped to one turn, velocities and accelerations in [-2, 2],
as dyngen's `sample_states`), torques from `pin.rnea` plus Gaussian noise
(sigma 0.01 N m), all prepared outside the timed region. Regressor loop, solve and
total are timed separately; median of --reps runs.

Run with the Pinocchio oracle's python, in the same sitting as
`cargo bench -p dyngen-tests --bench identification`:

    python3 \
        scripts/bench_identification_pinocchio.py

`--alt` also times the same compressed algorithm dyngen uses (QR of the stacked
rows to a 71 x 71 triangle, then lstsq on the triangle) as a stronger numpy
baseline.
"""

import argparse
import os
import statistics
import sys
import time

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
URDF = os.path.join(HERE, "..", "robots", "panda", "panda.urdf")
NOISE_SIGMA = 0.01


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--alt", action="store_true", help="also time QR compression + lstsq on the triangle")
    args = ap.parse_args()
    n = args.samples

    model = pin.buildModelFromUrdf(URDF)
    data = model.createData()
    model.gravity.linear = np.array([0.0, 0.0, -9.81])
    nv = model.nv
    assert model.nq == nv == 7, (model.nq, model.nv)
    p = 10 * nv

    rng = np.random.default_rng(args.seed)
    lo = np.maximum(model.lowerPositionLimit, -np.pi)
    hi = np.minimum(model.upperPositionLimit, np.pi)
    Q = rng.uniform(lo, hi, size=(n, nv))
    V = rng.uniform(-2.0, 2.0, size=(n, nv))
    A = rng.uniform(-2.0, 2.0, size=(n, nv))
    tau_true = np.empty(n * nv)
    for i in range(n):
        tau_true[nv * i : nv * (i + 1)] = pin.rnea(model, data, Q[i], V[i], A[i])
    tau = tau_true + NOISE_SIGMA * rng.standard_normal(n * nv)
    Qs, Vs, As = list(Q), list(V), list(A)  # row views, no slicing in the timed loop

    Y = np.empty((n * nv, p))
    rcond = max(Y.shape) * np.finfo(float).eps  # numpy's / LAPACK's default, spelled out

    reg, sol, tot, alt = [], [], [], []
    for rep in range(args.reps):
        t0 = time.perf_counter()
        for i in range(n):
            Y[nv * i : nv * (i + 1)] = pin.computeJointTorqueRegressor(model, data, Qs[i], Vs[i], As[i])
        t1 = time.perf_counter()
        x, _res, rank, sv = np.linalg.lstsq(Y, tau, rcond=rcond)
        t2 = time.perf_counter()
        reg.append(t1 - t0)
        sol.append(t2 - t1)
        tot.append(t2 - t0)
        if rep == 0:
            r = tau - Y @ x
            rms = np.sqrt(np.mean(r**2))
            per_joint = np.sqrt(np.mean(r.reshape(n, nv) ** 2, axis=0))
            pred = np.sqrt(np.mean((Y[: 7000] @ x - tau_true[: 7000]) ** 2))
            print(
                f"verify: rank {rank} of {p}, cond {sv[0] / sv[rank - 1]:.3e}, residual RMS {rms:.5f} N m "
                f"(noise sigma {NOISE_SIGMA}), per joint [{', '.join(f'{v:.5f}' for v in per_joint)}], "
                f"noise-free torque RMS error {pred:.2e} N m",
                file=sys.stderr,
            )
            assert rank == 43, rank
            assert abs(rms / NOISE_SIGMA - 1) < 0.05, rms
        if args.alt:
            t3 = time.perf_counter()
            R = np.linalg.qr(np.column_stack([Y, tau]), mode="r")
            xa = np.linalg.lstsq(R[:, :p], R[:, p], rcond=rcond)[0]
            t4 = time.perf_counter()
            alt.append(t4 - t3)
            if rep == 0:
                assert np.allclose(Y[:7000] @ xa, Y[:7000] @ x, atol=1e-8)

    def show(name, ts):
        m = statistics.median(ts)
        print(f"{name:<28} {m:9.3f} s   {m / n * 1e9:10.0f} ns/sample   (runs: {', '.join(f'{t:.3f}' for t in ts)})")

    print(f"pinocchio {pin.__version__}, numpy {np.__version__}, N = {n} samples ({n * nv} x {p}), median of {args.reps}")
    show("regressor loop", reg)
    show("lstsq (gelsd, rcond)", sol)
    show("total", tot)
    if args.alt:
        show("alt solve: qr(r) + lstsq", alt)
        show("alt total", [r + a for r, a in zip(reg, alt)])


if __name__ == "__main__":
    main()
