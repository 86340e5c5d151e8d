#!/usr/bin/env python3
"""Write the rotor-inertia (armature) fixture for dyngen's joint functions.

Usage, from anywhere (needs a python with `pip install pin==4.1.0 numpy`):

    PY=python3
    $PY scripts/make_armature_fixture.py

Writes tests/fixtures/armature.json: for the UR5 and the Panda, Pinocchio's model
with `model.armature` set (a rotor inertia per joint, fixed values below), and for a
few random states (q, v, a, tau = rnea, M = crba, tau_fd, ddq = aba(q, v, tau_fd)).
Pinocchio adds the armature to the diagonal of M in crba and to the articulated
inertia in aba, and `rnea` adds `armature * a`; it has no friction in these
algorithms, so the fixture checks the generated `rnea_joints`, `crba_joints` and
`aba_joints` with zero friction. The state sampling and conventions are those of
make_fixtures.py (one coordinate per joint, row-major matrices).
"""
import json
import os
import sys

import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_fixtures import ROOT, FIXTURE_DIR, check_model, coord_range, flat, rows, to_pin_q  # noqa: E402

# (URDF relative to the project root, name, armature per joint in joint order).
# Values of the order of real drives' reflected rotor inertias (kg m^2).
ROBOTS = [
    ("robots/ur5/ur5.urdf", "ur5", [0.45, 0.45, 0.25, 0.08, 0.08, 0.08]),
    ("robots/panda/panda.urdf", "panda", [0.30, 0.30, 0.25, 0.25, 0.15, 0.12, 0.10]),
]
SAMPLES = 8
SEED = 11
TAU_FD_RANGE = 10.0


def robot_fixture(urdf, name, armature, rng):
    model = pin.buildModelFromUrdf(os.path.join(ROOT, urdf))
    check_model(model)
    if len(armature) != model.nv:
        sys.exit(f"{name}: {len(armature)} armature values for {model.nv} joints")
    model.armature = np.array(armature, dtype=float)
    data = model.createData()
    ranges = [coord_range(model, model.joints[i]) for i in range(1, model.njoints)]
    worst = {"crba_nle_rnea": 0.0, "aba_fd": 0.0, "rnea_armature": 0.0}
    samples = []
    rigid = pin.buildModelFromUrdf(os.path.join(ROOT, urdf))
    rigid_data = rigid.createData()
    for _ in range(SAMPLES):
        theta = np.array([rng.uniform(lo, hi) for lo, hi in ranges])
        v = rng.uniform(-2.0, 2.0, model.nv)
        a = rng.uniform(-2.0, 2.0, model.nv)
        tau_fd = rng.uniform(-TAU_FD_RANGE, TAU_FD_RANGE, model.nv)
        q = to_pin_q(model, theta)
        tau = pin.rnea(model, data, q, v, a).copy()
        Mraw = np.array(pin.crba(model, data, q))
        M = np.triu(Mraw) + np.triu(Mraw, 1).T
        nle = pin.nonLinearEffects(model, data, q, v).copy()
        ddq = pin.aba(model, data, q, v, tau_fd).copy()
        # Self-checks: M a + nle = rnea; M ddq + nle = tau_fd; the armature enters
        # rnea as armature * a on top of the rigid bodies.
        rigid_tau = pin.rnea(rigid, rigid_data, q, v, a)
        worst["crba_nle_rnea"] = max(worst["crba_nle_rnea"], float(np.abs(M @ a + nle - tau).max()))
        worst["aba_fd"] = max(worst["aba_fd"], float(np.abs(M @ ddq + nle - tau_fd).max()))
        worst["rnea_armature"] = max(
            worst["rnea_armature"], float(np.abs(rigid_tau + model.armature * a - tau).max()))
        samples.append({
            "q": flat(theta),
            "v": flat(v),
            "a": flat(a),
            "tau": flat(tau),
            "M": rows(M),
            "tau_fd": flat(tau_fd),
            "ddq": flat(ddq),
        })
    bad = {k: x for k, x in worst.items() if not x < 1e-9}
    if bad:
        sys.exit(f"{name}: Pinocchio self-check failed: {bad}")
    return {
        "name": name,
        "urdf": urdf,
        "joint_names": [model.names[i] for i in range(1, model.njoints)],
        "armature": flat(model.armature),
        "checks_max_abs": worst,
        "samples": samples,
    }


def main():
    rng = np.random.default_rng(SEED)
    out = {
        "name": "armature",
        "pinocchio_version": pin.__version__,
        "generator": "scripts/make_armature_fixture.py",
        "seed": SEED,
        "conventions": {
            "q": "one coordinate per joint, as in the other fixtures",
            "armature": "model.armature: rotor inertia per joint (kg m^2), added to M's diagonal",
            "tau": "pin.rnea(q, v, a) with the armature: rigid rnea + armature * a",
            "M": "pin.crba symmetrised, with the armature on the diagonal, list of rows",
            "tau_fd": "forward-dynamics torque, uniform in [-10, 10]^nv",
            "ddq": "pin.aba(q, v, tau_fd) with the armature",
        },
        "robots": [robot_fixture(u, n, arm, rng) for u, n, arm in ROBOTS],
    }
    path = os.path.join(FIXTURE_DIR, "armature.json")
    with open(path, "w") as fh:
        json.dump(out, fh, separators=(",", ":"))
        fh.write("\n")
    print(f"wrote {os.path.relpath(path)} ({', '.join(r['name'] for r in out['robots'])}; "
          f"{SAMPLES} samples each, seed {SEED}, pinocchio {pin.__version__})")


if __name__ == "__main__":
    main()
