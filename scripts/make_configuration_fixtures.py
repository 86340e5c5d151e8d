#!/usr/bin/env python3
"""Write Pinocchio's integrate / difference reference values for dyngen's
configuration-space operations (core/src/configuration.rs).

Usage, from the project root (needs a python with `pip install pin==4.1.0 numpy`;
the shared oracle's venv has both):

    PY=python3    # or $PIN_HOME/.venv/bin/python
    $PY scripts/make_configuration_fixtures.py

Writes tests/fixtures/configuration/pinocchio.json, read by core/tests/configuration.rs.

The model is built by hand: a JointModelFreeFlyer on the universe ("root"), a
JointModelSpherical child ("ball"), a JointModelRevoluteZ child of the ball ("wrist").
nq = 7 + 4 + 1 = 12, nv = 6 + 3 + 1 = 10. Conventions are Pinocchio's and dyngen's:
free flyer q = [px, py, pz, qx, qy, qz, qw] (position of the body in the parent frame,
unit quaternion of its orientation), v = [v; w] in the body frame; ball q = [qx, qy,
qz, qw] of the child in the joint frame, v = angular velocity in the child frame.

Per sample (fixed numpy seed): q, v, integrate = pin.integrate(model, q, v), q1 (a
second, independent random configuration) and difference = pin.difference(model, q,
q1). The rotation vectors of v have chosen magnitudes (ANGLES below, from 1e-7 rad
to pi - 0.1, and 4 rad beyond pi) in random directions; the translations are
uniform in [-1, 1]^3. Numbers are written with repr, so they read back bit for bit.
"""
import json
import os

import numpy as np
import pinocchio as pin

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "fixtures", "configuration", "pinocchio.json")
SEED = 7
# (|w| of the free flyer, |w| of the ball) per sample. Beyond pi (4.0) Pinocchio's free
# flyer flips the quaternion to q0's side (q0 . q1 >= 0) while its ball joint keeps
# q0 * exp(w): the samples with 4.0 check both signs.
ANGLES = [
    (0.3, 4.0),
    (1.0e-7, 2.5),
    (4.0, 1.0e-4),
    (np.pi - 0.1, 0.7),
    (1.5, np.pi - 0.1),
]


def build_model():
    model = pin.Model()
    placement = pin.SE3(pin.rpy.rpyToMatrix(0.1, -0.2, 0.3), np.array([0.0, 0.1, 0.4]))
    root = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    ball = model.addJoint(root, pin.JointModelSpherical(), placement, "ball")
    model.addJoint(ball, pin.JointModelRZ(), placement, "wrist")
    return model


def unit_quaternion(rng):
    x = rng.normal(size=4)
    return x / np.linalg.norm(x)


def random_config(rng):
    p = rng.uniform(-1.0, 1.0, size=3)
    return np.concatenate([p, unit_quaternion(rng), unit_quaternion(rng), [rng.uniform(-np.pi, np.pi)]])


def rotation_vector(rng, angle):
    d = rng.normal(size=3)
    return angle * d / np.linalg.norm(d)


def flat(x):
    return [float(y) for y in np.asarray(x, dtype=float).reshape(-1)]


def main():
    model = build_model()
    assert (model.nq, model.nv) == (12, 10)
    rng = np.random.default_rng(SEED)
    samples = []
    for w_root, w_ball in ANGLES:
        q = random_config(rng)
        v = np.concatenate(
            [
                rng.uniform(-1.0, 1.0, size=3),
                rotation_vector(rng, w_root),
                rotation_vector(rng, w_ball),
                [rng.uniform(-2.0, 2.0)],
            ]
        )
        q1 = random_config(rng)
        samples.append(
            {
                "q": flat(q),
                "v": flat(v),
                "integrate": flat(pin.integrate(model, q, v)),
                "q1": flat(q1),
                "difference": flat(pin.difference(model, q, q1)),
            }
        )
    out = {
        "name": "configuration",
        "pinocchio_version": pin.__version__,
        "generator": "scripts/make_configuration_fixtures.py",
        "seed": SEED,
        "joints": ["root: JointModelFreeFlyer", "ball: JointModelSpherical", "wrist: JointModelRZ"],
        "nq": model.nq,
        "nv": model.nv,
        "conventions": {
            "q": "[px, py, pz, qx, qy, qz, qw] (root), [qx, qy, qz, qw] (ball), angle (wrist)",
            "v": "[vx, vy, vz, wx, wy, wz] (root, body frame), [wx, wy, wz] (ball, child frame), rate (wrist)",
            "integrate": "pin.integrate(model, q, v)",
            "difference": "pin.difference(model, q, q1)",
        },
        "neutral": flat(pin.neutral(model)),
        "samples": samples,
    }
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"wrote {os.path.relpath(OUT, ROOT)}: {len(samples)} samples, pinocchio {pin.__version__}")


if __name__ == "__main__":
    main()
