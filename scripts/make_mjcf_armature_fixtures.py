#!/usr/bin/env python3
"""Write MuJoCo's reference values for the hand-written MJCF fixtures of
`tests/fixtures/mjcf/` that exercise joint armature, sites, geom-derived inertia,
joint `ref` and several joints in one body.

Needs `pip install mujoco numpy` (written against MuJoCo 4.0.0), e.g. in a virtual
environment outside the repository. From the project root, with its python:

    python scripts/make_mjcf_armature_fixtures.py     # writes tests/fixtures/mjcf/*.json

For each `NAME.xml` of `FIXTURES` (hand-written, not written by this script) it writes
`NAME.json` with, at fixed states (no free joint in these files, so MuJoCo's velocities
are dyngen's; ball-joint quaternions are reordered from MuJoCo's `w x y z` to dyngen's
`x y z w`):

- `M`: MuJoCo's joint-space inertia `qM` (`mj_fullM` after `mj_forward`), armature on
  its diagonal; `M_rigid`: the same with every `dof_armature` set to zero;
  `bias`: `qfrc_bias` (armature does not enter it);
- `armature`: `dof_armature`, one per velocity coordinate;
- `sites`: each named site's position and rotation (row-major) in the world at
  `qpos0` (`mj_kinematics`);
- `bodies`: each body's `body_mass`, `body_ipos`, `body_iquat` (`w x y z`) and
  `body_inertia` (principal moments), as MuJoCo's compiler made them (from geoms when
  `inertiafromgeom` says so);
- `qpos0`: MuJoCo's reference configuration (joint `ref` values).

MuJoCo 4.0 warns that `settotalmass` (in compiler.xml) is deprecated, and writes the
warning to `MUJOCO_LOG.TXT` in the working directory: delete that file afterwards.

States: q at fixed numbers (hinges and slides 0.3 sin(1.3 k + 0.2) + 0.1 k around
`qpos0`, ball joints from fixed unnormalised quaternions), v = 0.7 cos(1.9 k + 0.5).
Gravity is the file's.
"""
import argparse
import json
import os

import mujoco
import numpy as np

FIXTURES = ["armature", "geoms", "compiler", "ref"]


def to_dyngen_q(model, qpos):
    """Ball-joint quaternions `w x y z` (MuJoCo) to `x y z w` (Pinocchio, dyngen)."""
    q = qpos.copy()
    for j in range(model.njnt):
        assert model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE, "free joints need floating_reference"
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL:
            qa = model.jnt_qposadr[j]
            q[qa:qa + 4] = np.roll(qpos[qa:qa + 4], -1)
    return q


def states(model):
    out = []
    for s in range(3):
        qpos = model.qpos0.copy()
        for j in range(model.njnt):
            qa = model.jnt_qposadr[j]
            k = j + 1 + 5 * s
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL:
                quat = np.array([0.9 - 0.2 * s, 0.3 * np.sin(k), -0.4 * np.cos(0.7 * k), 0.2 + 0.1 * s])
                qpos[qa:qa + 4] = quat / np.linalg.norm(quat)
            else:
                qpos[qa] += 0.3 * np.sin(1.3 * k + 0.2) + 0.1 * k
        kv = np.arange(1, model.nv + 1, dtype=float) + 7 * s
        qvel = 0.7 * np.cos(1.9 * kv + 0.5) if s else np.zeros(model.nv)
        out.append((qpos, qvel))
    return out


def mass_and_bias(model, data, qpos, qvel):
    """MuJoCo's `M` (with armature), `M` without armature, and `qfrc_bias` at (qpos, qvel)."""
    armature = model.dof_armature.copy()
    data.qpos[:] = qpos
    data.qvel[:] = qvel
    mujoco.mj_forward(model, data)
    m = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, m)
    bias = data.qfrc_bias.copy()
    model.dof_armature[:] = 0
    mujoco.mj_forward(model, data)
    m_rigid = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, m_rigid)
    model.dof_armature[:] = armature
    mujoco.mj_forward(model, data)
    return m, m_rigid, bias


def reference(xml_path):
    model = mujoco.MjModel.from_xml_path(xml_path)
    data = mujoco.MjData(model)
    name = lambda obj, i: mujoco.mj_id2name(model, obj, i)
    joints = [name(mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    armature = model.dof_armature.copy()
    samples = []
    for qpos, qvel in states(model):
        m, m_rigid, bias = mass_and_bias(model, data, qpos, qvel)
        assert np.allclose(m - m_rigid, np.diag(armature), atol=1e-14, rtol=0)
        samples.append({"q": to_dyngen_q(model, qpos).tolist(), "v": qvel.tolist(), "M": m.tolist(),
                        "M_rigid": m_rigid.tolist(), "bias": bias.tolist(),
                        "mujoco_qpos": qpos.tolist()})
    data.qpos[:] = model.qpos0
    mujoco.mj_kinematics(model, data)
    sites = {}
    for i in range(model.nsite):
        n = name(mujoco.mjtObj.mjOBJ_SITE, i)
        if n is not None:
            sites[n] = {"pos": data.site_xpos[i].tolist(), "rotation": data.site_xmat[i].tolist(),
                        "body": name(mujoco.mjtObj.mjOBJ_BODY, model.site_bodyid[i])}
    bodies = {}
    for b in range(1, model.nbody):
        bodies[name(mujoco.mjtObj.mjOBJ_BODY, b)] = {
            "mass": float(model.body_mass[b]), "ipos": model.body_ipos[b].tolist(),
            "iquat": model.body_iquat[b].tolist(), "inertia": model.body_inertia[b].tolist()}
    return {"mujoco": mujoco.__version__, "joints": joints, "nq": model.nq, "nv": model.nv,
            "gravity": model.opt.gravity.tolist(), "armature": armature.tolist(),
            "qpos0": model.qpos0.tolist(), "sites": sites, "bodies": bodies, "samples": samples}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out-dir", default="tests/fixtures/mjcf")
    args = ap.parse_args()
    for name in FIXTURES:
        ref = reference(os.path.join(args.out_dir, name + ".xml"))
        ref["robot"] = name
        ref["source"] = f"tests/fixtures/mjcf/{name}.xml (hand-written)"
        with open(os.path.join(args.out_dir, name + ".json"), "w") as f:
            json.dump(ref, f, indent=1)
            f.write("\n")
        print(f"{name}: {len(ref['samples'])} states, joints {ref['joints']}, armature {ref['armature']}")


if __name__ == "__main__":
    main()
