#!/usr/bin/env python3
"""Write the MJCF fixtures of `tests/fixtures/mjcf/` with MuJoCo itself.

Needs `pip install mujoco numpy` (written against MuJoCo 4.0.0), e.g. in a virtual
environment outside the repository. From the project root, with its python:

    python scripts/make_mjcf_fixtures.py            # writes tests/fixtures/mjcf/

For each of `robots/ur5/ur5.urdf` and `robots/panda/panda.urdf`:

(a) MuJoCo's URDF importer reads a copy of the URDF with
    `<mujoco><compiler discardvisual="true" fusestatic="false" balanceinertia="false"
    angle="radian"/></mujoco>` inserted (fusestatic off keeps the fixed links as
    jointless bodies), and `mj_saveLastXML` writes it as MJCF: `NAME.xml`. MuJoCo writes
    every body placement as `pos` + `quat` and every inertial as `pos` + `quat` +
    `diaginertia` (principal axes), all printed with its own number formatting.
(b) The model compiled from that MJCF (so exactly what dyngen reads) gives, at three
    fixed states, MuJoCo's joint-space mass matrix (`mj_fullM` after `mj_forward`) and
    bias forces `qfrc_bias` (gravity + Coriolis/centrifugal, dyngen's
    `nonlinear_effects`): `NAME.json`.

(c) For the hand-written `small.xml` (not written by this script), MuJoCo's values as
    in (b): `small.json`.

Gravity is MuJoCo's default `0 0 -9.81`. No armature, damping or friction is set, so
`qfrc_bias` and `M` are the rigid-body terms alone.
"""
import argparse
import json
import os
import re
import tempfile

import mujoco
import numpy as np

ROBOTS = {"ur5": "robots/ur5/ur5.urdf", "panda": "robots/panda/panda.urdf"}
COMPILER = ('<mujoco><compiler discardvisual="true" fusestatic="false" '
            'balanceinertia="false" angle="radian"/></mujoco>')


def urdf_to_mjcf(urdf_path, out_path):
    with open(urdf_path) as f:
        src = f.read()
    src, n = re.subn(r"(<robot[^>]*>)", lambda m: m.group(1) + COMPILER, src, count=1)
    assert n == 1, "no <robot> element"
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "robot.urdf")
        with open(path, "w") as f:
            f.write(src)
        mujoco.mj_saveLastXML(out_path, mujoco.MjModel.from_xml_path(path))


def states(model):
    """Three fixed states: q at fixed fractions (0.5, then 0.5 + 0.35 sin(1.7 k), then
    0.5 + 0.3 cos(0.9 k + 0.4)) of each joint's range (±pi when unlimited), v fixed."""
    n = model.nv
    k = np.arange(1, n + 1, dtype=float)
    lo, hi = model.jnt_range[:, 0].copy(), model.jnt_range[:, 1].copy()
    unlimited = ~model.jnt_limited.astype(bool)
    lo[unlimited], hi[unlimited] = -np.pi, np.pi
    at = lambda frac: lo + frac * (hi - lo)
    return [
        (at(np.full(n, 0.5)), np.zeros(n)),
        (at(0.5 + 0.35 * np.sin(1.7 * k)), 0.5 * np.cos(2.3 * k)),
        (at(0.5 + 0.3 * np.cos(0.9 * k + 0.4)), -0.8 * np.sin(1.1 * k + 0.2)),
    ]


def reference(xml_path):
    model = mujoco.MjModel.from_xml_path(xml_path)
    data = mujoco.MjData(model)
    joints = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    samples = []
    for q, v in states(model):
        data.qpos[:] = q
        data.qvel[:] = v
        mujoco.mj_forward(model, data)
        m = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, m)
        samples.append({"q": q.tolist(), "v": v.tolist(), "M": m.tolist(),
                        "bias": data.qfrc_bias.tolist()})
    return {"mujoco": mujoco.__version__, "joints": joints,
            "gravity": model.opt.gravity.tolist(), "samples": samples}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out-dir", default="tests/fixtures/mjcf")
    args = ap.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    for name, urdf in ROBOTS.items():
        xml = os.path.join(args.out_dir, name + ".xml")
        urdf_to_mjcf(urdf, xml)
        ref = reference(xml)
        ref["robot"] = name
        ref["source"] = urdf
        with open(os.path.join(args.out_dir, name + ".json"), "w") as f:
            json.dump(ref, f, indent=1)
            f.write("\n")
        print(f"{name}: {xml}, {len(ref['samples'])} states, joints {ref['joints']}")
    # The hand-written file: MuJoCo's values for it, so every feature it uses (classes,
    # degrees, euler, joint pos, slide, merged body) is checked against MuJoCo too.
    xml = os.path.join(args.out_dir, "small.xml")
    ref = reference(xml)
    ref["robot"] = "small"
    ref["source"] = "tests/fixtures/mjcf/small.xml (hand-written)"
    with open(os.path.join(args.out_dir, "small.json"), "w") as f:
        json.dump(ref, f, indent=1)
        f.write("\n")
    print(f"small: {len(ref['samples'])} states, joints {ref['joints']}")


if __name__ == "__main__":
    main()
