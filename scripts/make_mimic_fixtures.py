#!/usr/bin/env python3
"""Write the mimic-joint census: URDFs with `<mimic>` joints as grippers and hands carry
them, and Pinocchio 4.1 reference fixtures (JSON) for each, Pinocchio's model built with
`mimic=True` (one coordinate for a leader and its followers).

Usage (needs a python with `pip install pin==4.1.0 numpy`):

    python3 scripts/make_mimic_fixtures.py

The URDFs are written here, from the dimensions below, into `tests/fixtures/mimic/`:

- `arm_linkage_gripper` (fixed base): a 6-joint arm and a four-bar linkage gripper in
  the style of common two-finger grippers: one driven knuckle and five knuckles and
  fingers that follow it with multipliers of +1 and -1;
- `mimic_probe` (fixed base, and again on a free flyer): a prismatic follower with an
  offset, a follower under a follower, and followers in other branches than their
  leaders', one at the tip. (Pinocchio needs a leader before its followers in its
  numbering, a leader that follows no other, and the two of one configuration size, so
  not a continuous joint, nq = 2 there, after a revolute one; dyngen needs none of
  these, which `tests/tests/integration/mimic.rs` checks against the tree without followers.)

Per sample, in Pinocchio's coordinates (`q = [p; x, y, z, w]` for the free flyer):
`tau = rnea(q, v, a)`, `nle`, `gravity`, `M` (crba, mirrored), the centre of mass, its
Jacobian, the centroidal map `A_g`, and for the frames listed their placement
(rotation, translation) and Jacobian in LOCAL_WORLD_ALIGNED. Pinocchio does not run
its regressor or its derivatives on a mimic model: those come from the same URDF
loaded without `mimic` (every joint its own coordinate) at `q_tree = E q + b`, reduced
with `E` (`Y = Eᵀ Y_tree`, `∂τ/∂q = Eᵀ ∂τ_tree/∂q_tree E`, and `∂τ/∂v` alike), and the
script checks `Eᵀ rnea_tree = rnea` and `Eᵀ M_tree E = M` to 1e-12 first. Matrices are
lists of rows.
"""
import json
import os

import numpy as np
import pinocchio as pin

from make_census_fixtures import inertial, link, robot
from make_census_fixtures import joint as census_joint

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT_DIR = os.path.join(ROOT, "tests", "fixtures", "mimic")
GENERATOR = "scripts/make_mimic_fixtures.py"
SAMPLES = 4
SEED = 2611


def joint(name, kind, parent, child, xyz=(0, 0, 0), rpy=(0, 0, 0), axis=None, mimic=None):
    """The census's joint, with a `<mimic>` of (leader, multiplier, offset)."""
    extra = ""
    if mimic is not None:
        leader, multiplier, offset = mimic
        extra = f'<mimic joint="{leader}" multiplier="{multiplier}" offset="{offset}"/>'
    return census_joint(name, kind, parent, child, xyz, rpy, axis, extra)


def body(m, spread=1.0, xyz=(0.0, 0.01, 0.03)):
    return inertial(m, (0.01 * m * spread, 0.012 * m * spread, 0.008 * m * spread), (1e-4 * m * spread, 0.0, -1e-4 * m * spread), xyz)


def arm_linkage_gripper():
    dims = [(0.0, 0.0, 0.089), (0.0, 0.135, 0.0), (0.0, -0.12, 0.425), (0.0, 0.0, 0.392), (0.0, 0.093, 0.0), (0.0, 0.0, 0.095)]
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (0, 1, 0), (0, 0, 1), (0, 1, 0)]
    masses = [3.7, 8.4, 2.3, 1.2, 1.2, 0.19]
    lines = [link("base_link", inertial(4.0, (4e-3, 4e-3, 7e-3)))]
    parent = "base_link"
    for k in range(6):
        name = f"link{k + 1}"
        lines.append(link(name, body(masses[k])))
        lines.append(joint(f"joint{k + 1}", "revolute", parent, name, xyz=dims[k], axis=axes[k]))
        parent = name
    g = 0.05
    lines += [
        link("gripper_base", inertial(0.6, (4e-4, 5e-4, 4e-4), xyz=(0.0, 0.0, 0.04))),
        joint("gripper_mount", "fixed", "link6", "gripper_base", xyz=(0.0, 0.08, 0.0), rpy=(-1.5707963267948966, 0.0, 0.0)),
        link("left_outer_knuckle", body(g, 0.02)),
        joint("finger_joint", "revolute", "gripper_base", "left_outer_knuckle", xyz=(0.0, -0.03, 0.055), axis=(1, 0, 0)),
        link("left_outer_finger", body(0.03, 0.02, (0.0, 0.0, 0.02))),
        joint("left_outer_finger_joint", "fixed", "left_outer_knuckle", "left_outer_finger", xyz=(0.0, 0.03, 0.0)),
        link("left_inner_knuckle", body(0.02, 0.02)),
        joint("left_inner_knuckle_joint", "revolute", "gripper_base", "left_inner_knuckle", xyz=(0.0, -0.013, 0.061),
              axis=(1, 0, 0), mimic=("finger_joint", 1, 0)),
        link("left_inner_finger", body(0.02, 0.02, (0.0, 0.005, 0.02))),
        joint("left_inner_finger_joint", "revolute", "left_outer_finger", "left_inner_finger", xyz=(0.0, 0.037, 0.044),
              axis=(1, 0, 0), mimic=("finger_joint", -1, 0)),
        link("right_outer_knuckle", body(g, 0.02)),
        joint("right_outer_knuckle_joint", "revolute", "gripper_base", "right_outer_knuckle", xyz=(0.0, 0.03, 0.055),
              rpy=(0.0, 0.0, 3.141592653589793), axis=(1, 0, 0), mimic=("finger_joint", 1, 0)),
        link("right_inner_knuckle", body(0.02, 0.02)),
        joint("right_inner_knuckle_joint", "revolute", "gripper_base", "right_inner_knuckle", xyz=(0.0, 0.013, 0.061),
              rpy=(0.0, 0.0, 3.141592653589793), axis=(1, 0, 0), mimic=("finger_joint", 1, 0)),
        link("right_inner_finger", body(0.02, 0.02, (0.0, 0.005, 0.02))),
        joint("right_inner_finger_joint", "revolute", "right_inner_knuckle", "right_inner_finger", xyz=(0.0, 0.037, 0.044),
              axis=(1, 0, 0), mimic=("finger_joint", -1, 0)),
        link("tcp"),
        joint("tcp_joint", "fixed", "gripper_base", "tcp", xyz=(0.0, 0.0, 0.15)),
    ]
    return robot("arm_linkage_gripper", lines), ["tcp", "left_inner_finger", "right_inner_finger"]


def mimic_probe():
    lines = [
        link("base", inertial(1.0, (0.01, 0.01, 0.01))),
        link("a", body(1.5)),
        link("b", body(0.8)),
        link("c", body(0.6, 1.3)),
        link("d", body(0.4)),
        link("e", body(0.3, 0.7)),
        link("f", body(0.5)),
        link("g", body(0.2)),
        link("tip"),
        joint("a_joint", "revolute", "base", "a", xyz=(0.0, 0.0, 0.1), axis=(0, 0, 1)),
        joint("b_joint", "revolute", "a", "b", xyz=(0.0, 0.1, 0.3), axis=(1, 0, 0)),
        joint("c_joint", "revolute", "b", "c", xyz=(0.0, 0.0, 0.25), axis=(0, 0.6, 0.8)),
        # A prismatic follower with an offset.
        joint("d_joint", "prismatic", "a", "d", xyz=(0.0, -0.1, 0.3), axis=(0, 1, 0), mimic=("b_joint", -0.05, 0.02)),
        joint("e_joint", "revolute", "d", "e", xyz=(0.1, 0.0, 0.1), axis=(0, 0, 1), mimic=("b_joint", -0.2, -0.22)),
        joint("f_joint", "revolute", "c", "f", xyz=(0.0, 0.0, 0.2), axis=(1, 0, 0), mimic=("b_joint", -2.0, 0.0)),
        joint("g_joint", "revolute", "f", "g", xyz=(0.0, 0.05, 0.1), axis=(0, 1, 0), mimic=("a_joint", 0.5, 0.1)),
        joint("tip_joint", "fixed", "g", "tip", xyz=(0.0, 0.0, 0.08)),
    ]
    return robot("mimic_probe", lines), ["tip", "e", "d"]


def mirrored(m):
    return np.triu(m) + np.triu(m, 1).T


def reduction(model_mimic, model_tree):
    """E (nv_tree x nv) and b (nq_tree) with q_tree = E q + b, from Pinocchio's mimic joints."""
    tree_names = list(model_tree.names)
    e = np.zeros((model_tree.nv, model_mimic.nv))
    b = np.zeros(model_tree.nq)
    eq = np.zeros((model_tree.nq, model_mimic.nq))
    for jid in range(1, model_mimic.njoints):
        jm = model_mimic.joints[jid]
        jt = model_tree.joints[tree_names.index(model_mimic.names[jid])]
        if jm.shortname() == "JointModelMimic":
            ex = jm.extract()
            mult, off = ex.scaling, ex.offset
            # The leader (primary) joint's coordinate, resolved to its index in the mimic model.
            e[jt.idx_v, jm.idx_v] = mult
            eq[jt.idx_q, jm.idx_q] = mult
            b[jt.idx_q] = off
        else:
            for k in range(jm.nv):
                e[jt.idx_v + k, jm.idx_v + k] = 1.0
            for k in range(jm.nq):
                eq[jt.idx_q + k, jm.idx_q + k] = 1.0
    return e, eq, b


def frame_data(model, data, frames):
    out = {}
    for name in frames:
        fid = model.getFrameId(name)
        oMf = data.oMf[fid]
        out[name] = {
            "rotation": oMf.rotation.tolist(),
            "translation": oMf.translation.tolist(),
            "jacobian": pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED).tolist(),
        }
    return out


def fixture(name, text, frames, free_flyer):
    path = os.path.join(OUT_DIR, f"{name}.urdf")
    if free_flyer:
        mm = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer(), mimic=True)
        mt = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    else:
        mm = pin.buildModelFromUrdf(path, mimic=True)
        mt = pin.buildModelFromUrdf(path)
    dm, dt = mm.createData(), mt.createData()
    e, eq, b = reduction(mm, mt)
    rng = np.random.default_rng(SEED)
    samples = []
    for _ in range(SAMPLES):
        if free_flyer:
            q = rng.uniform(-1, 1, mm.nq)
            q[3:7] /= np.linalg.norm(q[3:7])
        else:
            q = rng.uniform(-1, 1, mm.nq)
        v = rng.uniform(-1, 1, mm.nv)
        a = rng.uniform(-1, 1, mm.nv)
        qt = eq @ q + b
        if free_flyer:
            qt[3:7] = q[3:7]
        vt, at = e @ v, e @ a
        tau = pin.rnea(mm, dm, q, v, a).copy()
        assert np.allclose(e.T @ pin.rnea(mt, dt, qt, vt, at), tau, atol=1e-12, rtol=0)
        m = mirrored(pin.crba(mm, dm, q))
        assert np.allclose(e.T @ mirrored(pin.crba(mt, dt, qt)) @ e, m, atol=1e-12, rtol=0)
        nle = pin.nonLinearEffects(mm, dm, q, v).copy()
        gravity = pin.computeGeneralizedGravity(mm, dm, q).copy()
        com = pin.centerOfMass(mm, dm, q).copy()
        jcom = pin.jacobianCenterOfMass(mm, dm, q).copy()
        ag = pin.computeCentroidalMap(mm, dm, q).copy()
        pin.forwardKinematics(mm, dm, q)
        pin.computeJointJacobians(mm, dm, q)
        pin.updateFramePlacements(mm, dm)
        fr = frame_data(mm, dm, frames)
        y = e.T @ pin.computeJointTorqueRegressor(mt, dt, qt, vt, at)
        dq, dv, _ = pin.computeRNEADerivatives(mt, dt, qt, vt, at)
        samples.append({
            "q": q.tolist(), "v": v.tolist(), "a": a.tolist(),
            "tau": tau.tolist(), "nle": nle.tolist(), "gravity": gravity.tolist(), "M": m.tolist(),
            "com": com.tolist(), "com_jacobian": jcom.tolist(), "centroidal_map": ag.tolist(),
            "frames": fr,
            "regressor": y.tolist(),
            "dtau_dq": (e.T @ dq @ e).tolist(), "dtau_dv": (e.T @ dv @ e).tolist(),
        })
    suffix = "_free_flyer" if free_flyer else ""
    out = {
        "generator": GENERATOR, "pinocchio": pin.__version__, "robot": f"{name}.urdf", "free_flyer": free_flyer,
        "nq": mm.nq, "nv": mm.nv, "tree_joints": list(mt.names)[1:],
        "mimic_joints": [mm.names[j] for j in range(1, mm.njoints) if mm.joints[j].shortname() == "JointModelMimic"],
        "params": np.concatenate([mt.inertias[j].toDynamicParameters() for j in range(1, mt.njoints)]).tolist(),
        "samples": samples,
    }
    with open(os.path.join(OUT_DIR, f"{name}{suffix}.json"), "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    for make, free in [(arm_linkage_gripper, [False]), (mimic_probe, [False, True])]:
        text, frames = make()
        name = make.__name__
        with open(os.path.join(OUT_DIR, f"{name}.urdf"), "w") as f:
            f.write(text)
        for free_flyer in free:
            fixture(name, text, frames, free_flyer)
            print(f"wrote {name}{'_free_flyer' if free_flyer else ''}.json")


if __name__ == "__main__":
    main()
