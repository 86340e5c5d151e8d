#!/usr/bin/env python3
"""Write Pinocchio reference fixtures (JSON) for floating-base robots and robots with
planar joints.

Usage (needs a python with `pip install pin==4.1.0 numpy`):

    PY=python3
    $PY scripts/make_floating_fixtures.py            # every robot of ROBOTS
    $PY scripts/make_floating_fixtures.py --name quadruped12

Each URDF of ROBOTS marked "freeflyer" is loaded with its root link on a free flyer, as
`pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())` does (joint 1 `root_joint`);
the others as they are (`mobile_arm`: two URDF `planar` joints, Pinocchio's
JointModelPlanar). Per sample, in dyngen's coordinates (`q = [p; x, y, z, w]` for a free
flyer, `[x, y, theta]` for a planar joint instead of Pinocchio's x, y, cos, sin, the
angle of a continuous joint instead of Pinocchio's cos, sin; `v`, `a` as Pinocchio's):
`tau = rnea(q, v, a)`, `nle = rnea(q, v, 0)`, `gravity = rnea(q, 0, 0)`, `M` (crba,
mirrored), `ddq = aba(q, v, tau_rand)` for a random `tau_rand`, the joint torque
regressor `Y`, every body's placement `oMi`, every BODY frame's placement and
LOCAL_WORLD_ALIGNED Jacobian, the centre of mass and its Jacobian, the centroidal
map `Ag`, `dAg v` (computeCentroidalMapTimeVariation) and the centroidal momentum
`Ag v`, the derivatives of rnea (`dtau_dq`, `dtau_dv` at `q, v, a`) and of aba
(`ddq_dq`, `ddq_dv`, `Minv` at `q, v, tau_rand`), with respect to the tangent of the
configuration (Pinocchio's convention: `q ⊕ δ`). Matrices are lists of rows; spatial vectors linear first.

Before writing, the script checks Pinocchio's values against identities (`Y π = τ`,
`M ddq + nle = τ`, the linear rows of `Ag` against `m J_com`, `Ag v` against the
centroidal momentum) to 1e-9, and `dAg v` against central differences of `Ag` along
`q ⊕ t v` to 1e-6 (relative), and refuses to write otherwise.
"""
import argparse
import json
import math
import os
import sys

import numpy as np
import pinocchio as pin

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT_DIR = os.path.join(ROOT, "tests", "fixtures", "floating")
GENERATOR = "scripts/make_floating_fixtures.py"
# name: (URDF, samples, seed, root joint)
ROBOTS = {
    "quadruped12": ("robots/quadruped12/quadruped12.urdf", 6, 11, "freeflyer"),
    "humanoid31": ("robots/humanoid31/humanoid31.urdf", 4, 12, "freeflyer"),
    "mobile_arm": ("tests/fixtures/mobile_arm.urdf", 6, 13, None),
}
TOL = 1e-9
FD_TOL = 1e-6  # central differences (step 1e-6), relative to max(1, |dAg v|)


def flat(x):
    return [float(v) for v in np.asarray(x).reshape(-1)]


def rows(m):
    return [flat(r) for r in np.asarray(m)]


def se3(m):
    return {"rotation": rows(m.rotation), "translation": flat(m.translation)}


def sample(model, rng):
    """Pinocchio's q, dyngen's q, v, a, tau_rand."""
    q = np.zeros(model.nq)
    ours = []
    for j in model.joints[1:]:
        iq, name = j.idx_q, j.shortname()
        if name == "JointModelFreeFlyer":
            p = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            quat /= np.linalg.norm(quat)
            q[iq:iq + 3] = p
            q[iq + 3:iq + 7] = quat
            ours += list(p) + list(quat)
        elif name == "JointModelPlanar":
            p = rng.uniform(-1.0, 1.0, 2)
            t = rng.uniform(-math.pi, math.pi)
            q[iq:iq + 4] = [p[0], p[1], math.cos(t), math.sin(t)]
            ours += list(p) + [t]
        elif j.nq == 2:
            t = rng.uniform(-math.pi, math.pi)
            q[iq:iq + 2] = [math.cos(t), math.sin(t)]
            ours.append(t)
        elif j.nq == 1:
            lo, hi = model.lowerPositionLimit[iq], model.upperPositionLimit[iq]
            if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
                lo, hi = -math.pi, math.pi
            x = rng.uniform(max(lo, -math.pi), min(hi, math.pi))
            q[iq] = x
            ours.append(x)
        else:
            sys.exit(f"unsupported joint {name}")
    v = rng.uniform(-2.0, 2.0, model.nv)
    a = rng.uniform(-2.0, 2.0, model.nv)
    tau = rng.uniform(-10.0, 10.0, model.nv)
    return q, np.array(ours), v, a, tau


def make(name, urdf, samples, seed, root_joint):
    path = os.path.join(ROOT, urdf)
    model = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer()) if root_joint else pin.buildModelFromUrdf(path)
    data = model.createData()
    rng = np.random.default_rng(seed)
    pi = np.concatenate([model.inertias[i].toDynamicParameters() for i in range(1, model.njoints)])
    body_frames = [f for f in range(model.nframes) if model.frames[f].type == pin.FrameType.BODY]
    checks = {"regressor": 0.0, "aba": 0.0, "Ag_mass_Jcom": 0.0, "Ag_momentum": 0.0, "dAg_fd": 0.0}
    out_samples = []
    for _ in range(samples):
        q, ours, v, a, tau_rand = sample(model, rng)
        tau = pin.rnea(model, data, q, v, a).copy()
        nle = pin.rnea(model, data, q, v, np.zeros(model.nv)).copy()
        grav = pin.rnea(model, data, q, np.zeros(model.nv), np.zeros(model.nv)).copy()
        m = pin.crba(model, data, q).copy()
        m = np.triu(m) + np.triu(m, 1).T
        ddq = pin.aba(model, data, q, v, tau_rand).copy()
        checks["aba"] = max(checks["aba"], float(np.abs(m @ ddq + nle - tau_rand).max()))
        y = pin.computeJointTorqueRegressor(model, data, q, v, a).copy()
        checks["regressor"] = max(checks["regressor"], float(np.abs(y @ pi - tau).max()))
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        omi = [se3(data.oMi[i]) for i in range(1, model.njoints)]
        pin.computeJointJacobians(model, data, q)
        frames = []
        for f in body_frames:
            jac = pin.getFrameJacobian(model, data, f, pin.LOCAL_WORLD_ALIGNED)
            frames.append({"name": model.frames[f].name, "placement": se3(data.oMf[f]), "jacobian": rows(jac)})
        com = pin.centerOfMass(model, data, q).copy()
        jcom = pin.jacobianCenterOfMass(model, data, q).copy()
        ag = pin.computeCentroidalMap(model, data, q).copy()
        mass = sum(model.inertias[i].mass for i in range(1, model.njoints))
        checks["Ag_mass_Jcom"] = max(checks["Ag_mass_Jcom"], float(np.abs(ag[:3] - mass * jcom).max()))
        pin.computeCentroidalMomentum(model, data, q, v)
        hg = data.hg.vector.copy()
        checks["Ag_momentum"] = max(checks["Ag_momentum"], float(np.abs(ag @ v - hg).max()))
        pin.computeCentroidalMapTimeVariation(model, data, q, v)
        dag_v = (data.dAg @ v).copy()
        # d(Ag)/dt v by central differences along q(t) = q ⊕ t v.
        h = 1e-6
        ag_p = pin.computeCentroidalMap(model, data, pin.integrate(model, q, h * v)).copy()
        ag_m = pin.computeCentroidalMap(model, data, pin.integrate(model, q, -h * v)).copy()
        fd = (ag_p - ag_m) @ v / (2 * h)
        checks["dAg_fd"] = max(checks["dAg_fd"], float(np.abs(fd - dag_v).max()) / max(1.0, float(np.abs(dag_v).max())))
        # Copies: both return views of data's buffers, which the next call overwrites.
        dtau_dq, dtau_dv = (x.copy() for x in pin.computeRNEADerivatives(model, data, q, v, a)[:2])
        ddq_dq, ddq_dv, minv = (x.copy() for x in pin.computeABADerivatives(model, data, q, v, tau_rand))
        minv = np.triu(minv) + np.triu(minv, 1).T
        out_samples.append({
            "dtau_dq": rows(dtau_dq), "dtau_dv": rows(dtau_dv), "ddq_dq": rows(ddq_dq), "ddq_dv": rows(ddq_dv),
            "Minv": rows(minv),
            "q": flat(ours), "v": flat(v), "a": flat(a), "tau": flat(tau), "nle": flat(nle),
            "gravity": flat(grav), "M": rows(m), "tau_rand": flat(tau_rand), "ddq": flat(ddq), "Y": rows(y),
            "oMi": omi, "frames": frames, "com": flat(com), "Jcom": rows(jcom), "Ag": rows(ag),
            "dAg_v": flat(dag_v), "hg": flat(hg),
        })
    bad = {k: x for k, x in checks.items() if not x <= (FD_TOL if k == "dAg_fd" else TOL)}
    if bad:
        sys.exit(f"{name}: Pinocchio self-checks failed: {bad}")
    return {
        "generator": GENERATOR,
        "pinocchio": pin.__version__,
        "urdf": urdf,
        "root_joint": root_joint or "none",
        "seed": seed,
        "model": {
            "nq_pinocchio": model.nq, "nv": model.nv,
            "joints": [model.names[i] for i in range(1, model.njoints)],
            "parents": [int(model.parents[i]) for i in range(1, model.njoints)],
            "params": flat(pi),
        },
        "checks_max_abs": checks,
        "samples": out_samples,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--name", choices=sorted(ROBOTS), help="one robot (default: all)")
    args = ap.parse_args()
    os.makedirs(OUT_DIR, exist_ok=True)
    for name, (urdf, samples, seed, root_joint) in ROBOTS.items():
        if args.name and name != args.name:
            continue
        fix = make(name, urdf, samples, seed, root_joint)
        path = os.path.join(OUT_DIR, f"{name}.json")
        with open(path, "w") as f:
            json.dump(fix, f, separators=(",", ":"))
            f.write("\n")
        print(f"wrote {os.path.relpath(path, ROOT)}: {len(fix['samples'])} samples, checks {fix['checks_max_abs']}")


if __name__ == "__main__":
    main()
