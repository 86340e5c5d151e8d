#!/usr/bin/env python3
"""Write Pinocchio's integrate / difference reference values for dyngen's
configuration-space operations (core/src/configuration.rs).

Usage, from the project root (needs a python with `pip install pin==4.1.0 numpy`;
the shared oracle's venv has both):

    PY=python3    # or $PIN_HOME/.venv/bin/python
    $PY scripts/make_configuration_fixtures.py

Writes tests/fixtures/configuration/pinocchio.json and planar.json, read by
core/tests/configuration.rs.

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

planar.json: a JointModelPlanar on the universe ("base") and a JointModelRevoluteZ
child ("arm"), nv = 3 + 1, Pinocchio nq = 4 + 1. dyngen's planar q is [x, y, theta]
(Pinocchio's [x, y, cos theta, sin theta]), v = [vx, vy, w] in the child frame. The
samples have |w| from 1e-7 to 3 rad; q1 turns the base by less than pi from q, since
Pinocchio's difference wraps the angle and dyngen's does not. Written in dyngen's
coordinates: `integrate` and `q1` with the angle, `integrate_cos_sin` Pinocchio's
cos, sin of the result's angle. `integrate_exact` is the same step in 50-digit decimal
arithmetic: Pinocchio's own result is off by 4.7e-10 at |w| = 1e-7 (its (1 - cos w)/w
cancels), so the test holds dyngen to the exact value and to Pinocchio's loosely.
"""
import json
import os
from decimal import Decimal, getcontext

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


PLANAR_OUT = os.path.join(ROOT, "tests", "fixtures", "configuration", "planar.json")
PLANAR_W = [1.0e-7, 1.0e-3, 0.5, -2.0, 3.0]


def dec_sin_cos(x):
    """sin and cos of a float, by their Taylor series in 50-digit decimals."""
    getcontext().prec = 50
    x = Decimal(x)
    s, c, term, n = Decimal(0), Decimal(0), Decimal(1), 0
    while n < 200:
        c += term
        term *= x / (n + 1)
        s += term
        term *= -x / (n + 2)
        n += 2
    return s, c


def planar_step_exact(q, v):
    """The base's [x, y] after `integrate`, exactly: p + R(theta) V(w) [vx, vy]."""
    x, y, t = (Decimal(a) for a in q[:3])
    vx, vy, w = (Decimal(a) for a in v[:3])
    sw, cw = dec_sin_cos(v[2])
    st, ct = dec_sin_cos(q[2])
    a, b = sw / w, (1 - cw) / w
    dx, dy = a * vx - b * vy, b * vx + a * vy
    return [float(x + ct * dx - st * dy), float(y + st * dx + ct * dy)]


def planar():
    model = pin.Model()
    placement = pin.SE3(pin.rpy.rpyToMatrix(0.1, -0.2, 0.3), np.array([0.0, 0.1, 0.4]))
    base = model.addJoint(0, pin.JointModelPlanar(), pin.SE3.Identity(), "base")
    model.addJoint(base, pin.JointModelRZ(), placement, "arm")
    assert (model.nq, model.nv) == (5, 4)
    rng = np.random.default_rng(SEED)

    def pin_q(ours):
        x, y, t, arm = ours
        return np.array([x, y, np.cos(t), np.sin(t), arm])

    samples = []
    for w in PLANAR_W:
        q = np.concatenate([rng.uniform(-1.0, 1.0, 2), [rng.uniform(-np.pi, np.pi), rng.uniform(-2.0, 2.0)]])
        v = np.array([rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), w, rng.uniform(-2.0, 2.0)])
        moved = pin.integrate(model, pin_q(q), v)
        q1 = np.concatenate([rng.uniform(-1.0, 1.0, 2), [q[2] + rng.uniform(-3.0, 3.0), rng.uniform(-2.0, 2.0)]])
        samples.append({
            "q": flat(q),
            "v": flat(v),
            "integrate": flat([moved[0], moved[1], q[2] + w, moved[4]]),
            "integrate_cos_sin": flat(moved[2:4]),
            "integrate_exact": planar_step_exact(q, v) + [float(q[2] + w), float(moved[4])],
            "q1": flat(q1),
            "difference": flat(pin.difference(model, pin_q(q), pin_q(q1))),
        })
    out = {
        "name": "configuration_planar",
        "pinocchio_version": pin.__version__,
        "generator": "scripts/make_configuration_fixtures.py",
        "seed": SEED,
        "joints": ["base: JointModelPlanar", "arm: JointModelRZ"],
        "conventions": {
            "q": "[x, y, theta] (base; Pinocchio's x, y, cos theta, sin theta), angle (arm)",
            "v": "[vx, vy, w] (base, child frame), rate (arm)",
            "integrate": "pin.integrate(model, q, v), the base angle as q's plus w",
            "integrate_cos_sin": "cos, sin of the base angle of pin.integrate(model, q, v)",
            "integrate_exact": "the same step in 50-digit decimals, rounded",
            "difference": "pin.difference(model, q, q1)",
        },
        "samples": samples,
    }
    with open(PLANAR_OUT, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"wrote {os.path.relpath(PLANAR_OUT, ROOT)}: {len(samples)} samples, pinocchio {pin.__version__}")


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
    planar()


if __name__ == "__main__":
    main()
