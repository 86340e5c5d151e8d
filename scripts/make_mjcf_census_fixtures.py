#!/usr/bin/env python3
"""Write the MJCF census: the DeepMind control suite models (`dm_control/suite/*.xml`,
Apache-2.0) with MuJoCo's mass matrices and bias forces, for
`tests/tests/integration/census_mjcf.rs`.

Needs `pip install dm_control` (which installs `mujoco`; written against
dm_control 1.0.50 and MuJoCo 4.0.0). From the project root:

    python scripts/make_mjcf_census_fixtures.py   # writes tests/fixtures/census/mjcf/

For each `suite/NAME.xml` it copies the file and the files it `<include>`s
(`common/*.xml`) into `tests/fixtures/census/mjcf/` with the package's `LICENSE`
(mesh, skin and texture files are not copied: the dyngen reader does not read them,
and MuJoCo is loaded from the package's own folder), and writes `NAME.json` with, in
MuJoCo's coordinates (`qpos` quaternions `w x y z`, a free joint's linear velocity
in world axes; the test converts them to dyngen's):

- `nq`, `nv`, `joints` (MuJoCo's names in id order, `null` when unnamed),
  `joint_types` (`free`, `ball`, `slide`, `hinge`), `gravity` (zero under
  `<flag gravity="disable">`), `armature`
  (`dof_armature`);
- `samples`: three states (a fixed seed), each with `qpos`, `qvel`, `M`
  (`mj_fullM` of `qM` after `mj_forward`, armature on its diagonal), `M_rigid` (the
  same with every `dof_armature` set to zero) and `bias` (`qfrc_bias`: Coriolis,
  centrifugal and gravity forces only; springs, damping and gravity compensation are
  in `qfrc_passive`, not here).

States: hinge and slide joints at `qpos0` plus a uniform number in [-0.8, 0.8], ball
and free joints at random unit quaternions (free positions uniform in [-1, 1]),
velocities normal with deviation 0.7.
"""
import glob
import json
import os
import re
import shutil

import dm_control
import mujoco
import numpy as np

SUITE = os.path.join(os.path.dirname(dm_control.__file__), "suite")
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures", "census", "mjcf")
TYPES = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}


def includes(path, seen):
    """The files `path` includes, transitively, relative to the suite folder."""
    text = open(path).read()
    for f in re.findall(r'<include\s+file="([^"]+)"', text):
        rel = os.path.normpath(f)
        if rel not in seen:
            seen.add(rel)
            includes(os.path.join(SUITE, rel), seen)
    return seen


def states(model, rng):
    out = []
    for _ in range(3):
        qpos = model.qpos0.copy()
        for j in range(model.njnt):
            qa = model.jnt_qposadr[j]
            t = TYPES[int(model.jnt_type[j])]
            if t in ("hinge", "slide"):
                qpos[qa] += rng.uniform(-0.8, 0.8)
            else:
                if t == "free":
                    qpos[qa:qa + 3] = rng.uniform(-1.0, 1.0, 3)
                    qa += 3
                quat = rng.standard_normal(4)
                qpos[qa:qa + 4] = quat / np.linalg.norm(quat)
        qvel = 0.7 * rng.standard_normal(model.nv)
        out.append((qpos, qvel))
    return out


def reference(path):
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    rigid = mujoco.MjModel.from_xml_path(path)
    rigid.dof_armature[:] = 0.0
    rigid_data = mujoco.MjData(rigid)
    rng = np.random.default_rng(2026)
    samples = []
    # The gravity in effect: none under `<flag gravity="disable">`.
    gravity = model.opt.gravity * (0.0 if model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY else 1.0)
    for qpos, qvel in states(model, rng):
        mats = []
        for m, d in ((model, data), (rigid, rigid_data)):
            d.qpos[:] = qpos
            d.qvel[:] = qvel
            mujoco.mj_forward(m, d)
            full = np.zeros((m.nv, m.nv))
            mujoco.mj_fullM(m, d, full)
            mats.append((full, d.qfrc_bias.copy()))
        assert np.array_equal(mats[0][1], mats[1][1]), "armature is not in qfrc_bias"
        samples.append({"qpos": qpos.tolist(), "qvel": qvel.tolist(), "M": mats[0][0].tolist(),
                        "M_rigid": mats[1][0].tolist(), "bias": mats[0][1].tolist()})
    return {
        "source": "dm_control 1.0.50, suite/",
        "mujoco": mujoco.__version__,
        "nq": int(model.nq),
        "nv": int(model.nv),
        "joints": [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)],
        "joint_types": [TYPES[int(t)] for t in model.jnt_type],
        "gravity": gravity.tolist(),
        "armature": model.dof_armature.tolist(),
        "samples": samples,
    }


def main():
    os.makedirs(os.path.join(OUT, "common"), exist_ok=True)
    licence = os.path.join(os.path.dirname(dm_control.__file__), "..",
                           "dm_control-1.0.50.dist-info", "licenses", "LICENSE")
    shutil.copy(licence, os.path.join(OUT, "LICENSE"))
    for path in sorted(glob.glob(os.path.join(SUITE, "*.xml"))):
        name = os.path.basename(path)[:-4]
        shutil.copy(path, os.path.join(OUT, name + ".xml"))
        for rel in includes(path, set()):
            shutil.copy(os.path.join(SUITE, rel), os.path.join(OUT, rel))
        with open(os.path.join(OUT, name + ".json"), "w") as f:
            json.dump(reference(path), f)
            f.write("\n")
        print(name)


if __name__ == "__main__":
    main()
