#!/usr/bin/env python3
"""Write Pinocchio reference fixtures (JSON) for dyngen's tests.

Usage, from anywhere (needs a python with `pip install pin==4.1.0 numpy`):

    PY=python3
    $PY scripts/make_fixtures.py --all
    $PY scripts/make_fixtures.py --urdf path/to/robot.urdf --name robot [--samples 50] [--seed 0]

--all regenerates every fixture the project ships (FIXTURES below). --urdf/--name
writes tests/fixtures/NAME.json (or --out-dir DIR/NAME.json) for any URDF, e.g. one
that dyngen wrote out. The schema is documented in tests/fixtures/README.md.

Conventions are Pinocchio's: spatial vectors linear first then angular; per joint i
everything is in the local frame of joint i (the URDF child-link frame of that joint);
links on fixed joints are merged into the moving body above them; `q` holds one
coordinate per joint (the angle for revolute and continuous joints, the displacement
for prismatic ones), converted to Pinocchio's q (cos, sin for continuous joints)
internally.
"""
import argparse
import json
import math
import os
import sys

import numpy as np
import pinocchio as pin

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIXTURE_DIR = os.path.join(ROOT, "tests", "fixtures")

# Every fixture the project ships: (URDF relative to the project root, name, samples, seed).
# (urdf, name, samples, seed, gravity). The DSL robots' URDFs are written by
# `cargo run -p dyngen-tests --example export_urdfs`; URDF cannot carry gravity.
FIXTURES = [
    ("robots/ur5/ur5.urdf", "ur5", 50, 0, None),
    ("robots/gripper_arm/gripper_arm.urdf", "gripper_arm", 50, 0, None),
    ("tests/fixtures/planar2.urdf", "planar2", 50, 0, [0.0, -9.81, 0.0]),
    ("tests/fixtures/paper6.urdf", "paper6", 50, 0, None),
    ("robots/puma560/puma560.urdf", "puma560", 50, 0, None),
    ("robots/panda/panda.urdf", "panda", 50, 0, None),
    ("tests/fixtures/tree12.urdf", "tree12", 50, 0, None),
]

# 2: adds per sample M, nle, g, Y, tau_fd, ddq (and more self-checks); every schema-1
# field and value is unchanged.
SCHEMA_VERSION = 2
TAU_FD_RANGE = 10.0  # tau_fd uniform in [-10, 10]^nv


def flat(x):
    return [float(y) for y in np.asarray(x, dtype=float).reshape(-1)]


def rows(R):
    return [flat(r) for r in np.asarray(R, dtype=float)]


def se3(M):
    return {"rotation": rows(M.rotation), "translation": flat(M.translation)}


def coord_range(model, j):
    """Sampling range for the single coordinate of 1-DOF joint j."""
    if j.nq == 2:  # continuous revolute: angle in [-pi, pi]
        return -math.pi, math.pi
    lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
    if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
        return -math.pi, math.pi
    # Wide or placeholder limits: sample one turn (revolute) or +-0.5 m (prismatic).
    reach = 0.5 if "P" in j.shortname() else math.pi
    return max(float(lo), -reach), min(float(hi), reach)


def to_pin_q(model, theta):
    """One coordinate per joint -> Pinocchio configuration vector."""
    q = np.zeros(model.nq)
    for j in model.joints[1:]:
        t = theta[j.idx_v]
        if j.nq == 1:
            q[j.idx_q] = t
        else:
            q[j.idx_q:j.idx_q + 2] = [math.cos(t), math.sin(t)]
    return q


def check_model(model):
    for i in range(1, model.njoints):
        j = model.joints[i]
        if j.nv != 1 or j.nq not in (1, 2):
            sys.exit(f"{model.names[i]}: joint type {j.shortname()} is not 1-DOF "
                     "(only revolute, continuous and prismatic are supported)")
        I = model.inertias[i]
        ev = np.linalg.eigvalsh(I.inertia)
        if I.mass <= 0 or ev[0] <= 0 or ev[2] > ev[0] + ev[1] + 1e-12 * ev.sum():
            sys.exit(f"{model.names[i]}: body inertia not physical "
                     f"(mass {I.mass}, principal moments {ev})")


def make_fixture(urdf, name, samples, seed, gravity=None):
    urdf = os.path.abspath(urdf)
    model = pin.buildModelFromUrdf(urdf)
    if gravity is not None:
        model.gravity.linear = np.array(gravity, dtype=float)
    check_model(model)
    data = model.createData()
    nj = model.njoints
    rng = np.random.default_rng(seed)
    pi_all = np.concatenate([model.inertias[i].toDynamicParameters() for i in range(1, nj)])
    ranges = [coord_range(model, model.joints[i]) for i in range(1, nj)]

    # Draws. q, v, a exactly as in schema 1 (per sample: q, then v, then a); the
    # forward-dynamics torques come from the same generator AFTER all of them, one
    # vector per sample, so that no schema-1 value changes.
    draws = []
    for _ in range(samples):
        theta = np.array([rng.uniform(lo, hi) for lo, hi in ranges])
        v = rng.uniform(-2.0, 2.0, model.nv)
        a = rng.uniform(-2.0, 2.0, model.nv)
        draws.append((theta, v, a))
    tau_fds = [rng.uniform(-TAU_FD_RANGE, TAU_FD_RANGE, model.nv) for _ in range(samples)]

    worst = {"tau_from_f": 0.0, "regressor": 0.0, "aba": 0.0,
             "crba_sym": 0.0, "crba_nle_rnea": 0.0, "gravity": 0.0, "aba_fd": 0.0}
    out_samples = []
    for (theta, v, a), tau_fd in zip(draws, tau_fds):
        q = to_pin_q(model, theta)

        tau = pin.rnea(model, data, q, v, a).copy()
        f = [data.f[i].vector.copy() for i in range(1, nj)]
        # self-checks: tau_i = S_i^T f_i, regressor, aba inverts rnea
        tf = np.array([float(np.asarray(data.joints[i].S).reshape(6) @ f[i - 1]) for i in range(1, nj)])
        worst["tau_from_f"] = max(worst["tau_from_f"], float(np.abs(tf - tau).max()))
        Y = pin.computeJointTorqueRegressor(model, data, q, v, a)
        worst["regressor"] = max(worst["regressor"], float(np.abs(Y @ pi_all - tau).max()))
        Y = Y.copy()
        ddq_inv = pin.aba(model, data, q, v, tau)
        worst["aba"] = max(worst["aba"], float(np.abs(ddq_inv - a).max()))

        # Joint-space quantities. crba computes the upper triangle (the Python binding
        # returns it already symmetrised); symmetrise from the upper triangle anyway.
        Mraw = np.array(pin.crba(model, data, q))
        M = np.triu(Mraw) + np.triu(Mraw, 1).T
        worst["crba_sym"] = max(worst["crba_sym"], float(np.abs(Mraw - M).max()))
        nle = pin.nonLinearEffects(model, data, q, v).copy()
        g = pin.computeGeneralizedGravity(model, data, q).copy()
        worst["crba_nle_rnea"] = max(worst["crba_nle_rnea"], float(np.abs(M @ a + nle - tau).max()))
        g_rnea = pin.rnea(model, data, q, np.zeros(model.nv), np.zeros(model.nv))
        worst["gravity"] = max(worst["gravity"], float(np.abs(g_rnea - g).max()))
        ddq = pin.aba(model, data, q, v, tau_fd).copy()
        worst["aba_fd"] = max(worst["aba_fd"], float(np.abs(M @ ddq + nle - tau_fd).max()))

        pin.forwardKinematics(model, data, q)
        out_samples.append({
            "q": flat(theta),
            "v": flat(v),
            "a": flat(a),
            "tau": flat(tau),
            "f": [flat(x) for x in f],
            "oMi": [se3(data.oMi[i]) for i in range(1, nj)],
            "M": rows(M),
            "nle": flat(nle),
            "g": flat(g),
            "Y": rows(Y),
            "tau_fd": flat(tau_fd),
            "ddq": flat(ddq),
        })
    tol = 1e-9
    bad = {k: x for k, x in worst.items() if not x < tol}
    if bad:
        sys.exit(f"{name}: Pinocchio self-check failed: {bad}")

    pin.forwardKinematics(model, data, pin.neutral(model))  # S_i is read from data.joints
    rel = os.path.relpath(urdf, ROOT)
    return {
        "schema_version": SCHEMA_VERSION,
        "name": name,
        "urdf": urdf if rel.startswith("..") else rel,
        "pinocchio_version": pin.__version__,
        "generator": "scripts/make_fixtures.py",
        "seed": seed,
        "conventions": {
            "q": "one coordinate per joint (angle for revolute/continuous, displacement for prismatic)",
            "spatial_order": "linear,angular",
            "f": "data.f[i] after rnea: wrench parent applies to body i through joint i, in frame of joint i",
            "oMi": "joint frame i -> world (rotation rows, translation)",
            "dyn_params": "[m, m*cx, m*cy, m*cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz], inertia about joint origin, joint-frame axes",
            "parents": "Pinocchio parent joint index, 0 = universe; joint i is joint_names[i-1]",
            "placements": "jointPlacements[i]: frame of parent joint -> frame of joint i at q = 0",
            "motion_subspace": "S_i in frame of joint i, [lin; ang]; tau_i = S_i . f_i",
            "M": "joint-space inertia matrix, pin.crba symmetrised, nv x nv, list of rows",
            "nle": "pin.nonLinearEffects(q, v) = C(q, v) v + g(q); tau = M a + nle",
            "g": "pin.computeGeneralizedGravity(q) = rnea(q, 0, 0)",
            "Y": "pin.computeJointTorqueRegressor(q, v, a), nv x 10 n, list of rows; Y . concat(dyn_params) = tau",
            "tau_fd": "forward-dynamics torque, uniform in [-10, 10]^nv, drawn after all samples' q, v, a",
            "ddq": "pin.aba(q, v, tau_fd); M ddq + nle = tau_fd",
        },
        "model": {
            "joint_names": [model.names[i] for i in range(1, nj)],
            "joint_types": [model.joints[i].shortname() for i in range(1, nj)],
            "parents": [int(model.parents[i]) for i in range(1, nj)],
            "nq": int(model.nq),
            "nv": int(model.nv),
            "placements": [se3(model.jointPlacements[i]) for i in range(1, nj)],
            "motion_subspace": [flat(np.asarray(data.joints[i].S).reshape(6)) for i in range(1, nj)],
            "dyn_params": [flat(model.inertias[i].toDynamicParameters()) for i in range(1, nj)],
        },
        "gravity": flat(model.gravity.linear),
        "checks_max_abs": worst,
        "samples": out_samples,
    }


def write(fix, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, fix["name"] + ".json")
    with open(path, "w") as fh:
        json.dump(fix, fh, separators=(",", ":"))
        fh.write("\n")
    print(f"wrote {os.path.relpath(path)}  ({fix['urdf']}, {len(fix['samples'])} samples, "
          f"seed {fix['seed']}, nv {fix['model']['nv']}, pinocchio {fix['pinocchio_version']})")


def run_cli(description, make, write, out_dir, samples, seed, all_samples=False, what="fixture"):
    """The command line both fixture scripts share: --all (every robot of FIXTURES, with
    `samples` and `seed` for all when `all_samples`, else each with FIXTURES' own) or
    --urdf and --name for any URDF; `make(urdf, name, samples, seed, gravity)` builds a
    fixture and `write(fixture, out_dir)` writes it."""
    ap = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--all", action="store_true", help=f"regenerate every {what} the project ships")
    ap.add_argument("--urdf", help="URDF path (relative to the current directory)")
    ap.add_argument("--name", help="fixture name: writes OUT_DIR/NAME.json")
    ap.add_argument("--samples", type=int, default=samples)
    ap.add_argument("--seed", type=int, default=seed)
    ap.add_argument("--out-dir", default=out_dir, help=f"default: {os.path.relpath(out_dir, ROOT)} of the project")
    ap.add_argument("--gravity", type=float, nargs=3, metavar=("GX", "GY", "GZ"),
                    help="gravity in the base frame (default Pinocchio's 0 0 -9.81)")
    args = ap.parse_args()

    if args.all == bool(args.urdf or args.name):
        ap.error("give either --all or both --urdf and --name")
    if args.all:
        if not all_samples:
            jobs = [(os.path.join(ROOT, u), n, s, sd, g) for u, n, s, sd, g in FIXTURES]
        else:
            jobs = [(os.path.join(ROOT, u), n, samples, seed, g) for u, n, _s, _sd, g in FIXTURES]
    else:
        if not (args.urdf and args.name):
            ap.error("--urdf and --name go together")
        if not os.path.isfile(args.urdf):
            ap.error(f"URDF not found: {args.urdf}")
        jobs = [(args.urdf, args.name, args.samples, args.seed, args.gravity)]
    for urdf, name, n, sd, gravity in jobs:
        write(make(urdf, name, n, sd, gravity), args.out_dir)


def main():
    run_cli(__doc__, make_fixture, write, FIXTURE_DIR, 50, 0)


if __name__ == "__main__":
    main()
