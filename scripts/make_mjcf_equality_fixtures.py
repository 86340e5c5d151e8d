#!/usr/bin/env python3
"""Write an MJCF tree with `<equality><joint>` couplings and MuJoCo's reduced dynamics
for it: `tests/fixtures/mjcf/equality.xml` and `equality.json`.

Needs `pip install mujoco numpy` (written against MuJoCo 4.0.0), e.g. in a virtual
environment outside the repository. From the project root, with its python:

    python scripts/make_mjcf_equality_fixtures.py     # writes tests/fixtures/mjcf/equality.*

MuJoCo's `<equality><joint joint1 joint2 polycoef="c0 c1 c2 c3 c4">` holds
`y - y0 = c0 + c1 (x - x0) + c2 (x - x0)^2 + ...` with `y`, `x` the positions of
joint1 and joint2 and `y0`, `x0` their `qpos0` (the joints' `ref`, in radians for a
hinge whatever the file's angle unit; `polycoef` is never converted). A linear one
(`c2 = c3 = c4 = 0`) makes joint1 follow joint2: `y = c1 x + (y0 + c0 - c1 x0)`,
which dyngen reads as a mimic joint. MuJoCo enforces the coupling softly, through its
constraint solver, so its `qM` and `qfrc_bias` are in all the joints' coordinates:
with `E` the full velocities from the reduced ones (one per joint that follows no
other) and `b` the offsets, at `qpos = E q + b` (which satisfies the couplings: the
script checks that MuJoCo's equality residuals `efc_pos` are zero there) and
`qvel = E v`, the reduced dynamics are `Eᵀ qM E` and `Eᵀ qfrc_bias` (`E` is constant,
so no `Ė v` term), and the reduced armature is `Eᵀ diag(dof_armature) E`, diagonal:
`k² Ia` of each follower folded into its leader.

The tree (angles in degrees, so `ref` is converted and `polycoef` is not):

- `lead` (hinge, ref 30°) leads `mirror` (hinge, ref -50°, polycoef `0.1 -1`) and
  `half` (slide, ref 0.07, polycoef `-0.05 0.5`, armature 0.3);
- `elbow` (hinge, ref 20°) leads `twin` (hinge, ref 15°, polycoef `0.2`: c1 keeps
  its default 1), in a branch declared before `elbow`'s, so the follower is numbered
  before its leader;
- `wrist` is coupled to `elbow` by `polycoef="0 1 0.2"`, nonlinear: dyngen warns and
  keeps `wrist` independent, so here too (MuJoCo's `qM` and `qfrc_bias` do not hold
  the coupling);
- an inactive coupling (`active="false"` from its class) of `wrist` to `lead`: off in
  MuJoCo at the start, skipped by dyngen.

`equality.json`: `joints` (MuJoCo's order, dyngen's too), `followers` (joint, leader,
multiplier, offset, from MuJoCo's `eq_data` and `qpos0`), `E` (rows: joints, columns:
reduced coordinates), `armature` (reduced), and at three fixed states (q around the
leaders' `qpos0`, v = 0 then fixed numbers) `q`, `v` (reduced, dyngen's), `qpos`,
`qvel`, `M` = `Eᵀ qM E` (armature included), `M_rigid` (the same with every
`dof_armature` zeroed) and `bias` = `Eᵀ qfrc_bias`. Gravity is MuJoCo's default.
"""
import argparse
import json
import os

import mujoco
import numpy as np

from make_mjcf_armature_fixtures import mass_and_bias

XML = """<!--
  Written by scripts/make_mjcf_equality_fixtures.py: a tree with <equality><joint>
  couplings. Linear ones (lead leads mirror and the slide half; elbow leads twin,
  numbered before it) are dyngen mimic joints; the nonlinear one (wrist, elbow) is
  left out with a warning; the inactive one is skipped. MuJoCo's dynamics reduced to
  the leaders' coordinates are in equality.json.
-->
<mujoco model="equality">
  <compiler angle="degree"/>
  <default>
    <default class="off">
      <equality active="false"/>
    </default>
  </default>
  <worldbody>
    <body name="a" pos="0 0 0.2" euler="10 20 30">
      <joint name="lead" axis="0 0 1" ref="30" pos="0.02 0 0.01" armature="0.02" damping="0.3"/>
      <inertial pos="0.05 0.01 0.1" mass="2" diaginertia="0.02 0.018 0.01"/>
      <body name="f" pos="-0.1 0.05 0.1" euler="0 40 0">
        <joint name="twin" axis="0 1 0.3" ref="15" pos="0 0 0.02" armature="0.01"/>
        <inertial pos="0.02 0 0.06" mass="0.6" diaginertia="0.003 0.002 0.001"/>
      </body>
      <body name="b" pos="0.1 0 0.3" euler="-15 5 40">
        <joint name="mirror" axis="0.2 1 0.1" ref="-50" pos="0 0.03 0.02" range="-120 60"/>
        <inertial pos="0 0.02 0.15" quat="0.9 0.1 0.2 -0.1" mass="1.2" diaginertia="0.015 0.012 0.004"/>
        <body name="c" pos="0 0 0.3">
          <joint name="half" type="slide" axis="1 0.5 0.2" ref="0.07" pos="0.01 0 0" armature="0.3"/>
          <inertial pos="0.03 0 0.05" mass="0.8" diaginertia="0.004 0.005 0.003"/>
          <body name="d" pos="0 0.05 0.1" axisangle="1 0 1 35">
            <joint name="elbow" axis="1 0 0" pos="0.01 0.02 0.03" ref="20" armature="0.05"/>
            <inertial pos="0.02 0.01 0.1" mass="0.7" diaginertia="0.003 0.0025 0.0015"/>
            <body name="e" pos="0 0 0.15" euler="0 30 0">
              <joint name="wrist" axis="0 1 0" pos="0 0 0.02" ref="-10"/>
              <inertial pos="0.01 0 0.05" mass="0.3" diaginertia="0.001 0.0009 0.0004"/>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <equality>
    <joint name="mirror_lead" joint1="mirror" joint2="lead" polycoef="0.1 -1"/>
    <joint joint1="half" joint2="lead" polycoef="-0.05 0.5 0 0 0"/>
    <joint name="twins" joint1="twin" joint2="elbow" polycoef="0.2"/>
    <joint name="bend" joint1="wrist" joint2="elbow" polycoef="0 1 0.2"/>
    <joint joint1="wrist" joint2="lead" class="off"/>
  </equality>
</mujoco>
"""


def followers(model):
    """Linear active joint couplings: {follower joint id: (leader id, multiplier, offset)}."""
    out = {}
    for i in range(model.neq):
        if model.eq_type[i] != mujoco.mjtEq.mjEQ_JOINT or not model.eq_active0[i]:
            continue
        j1, j2 = model.eq_obj1id[i], model.eq_obj2id[i]
        c = model.eq_data[i, :5]
        if j2 < 0 or np.any(c[2:] != 0):
            continue
        y0, x0 = model.qpos0[model.jnt_qposadr[j1]], model.qpos0[model.jnt_qposadr[j2]]
        out[j1] = (j2, float(c[1]), float(y0 + c[0] - c[1] * x0))
    return out


def reference(path):
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    assert model.nq == model.nv == model.njnt, "hinges and slides only"
    name = lambda j: mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
    follow = followers(model)
    # No chains here: every leader leads itself.
    assert all(leader not in follow for leader, _, _ in follow.values())
    own = [j for j in range(model.njnt) if j not in follow]
    e = np.zeros((model.njnt, len(own)))
    b = np.zeros(model.njnt)
    for j in range(model.njnt):
        if j in follow:
            leader, k, offset = follow[j]
            e[j, own.index(leader)] = k
            b[j] = offset
        else:
            e[j, own.index(j)] = 1.0
    armature = model.dof_armature.copy()
    reduced_armature = e.T @ np.diag(armature) @ e
    assert np.allclose(reduced_armature, np.diag(np.diag(reduced_armature)), atol=0, rtol=0)
    linear = [i for i in range(model.neq) if model.eq_obj1id[i] in follow
              and model.eq_obj2id[i] == follow[model.eq_obj1id[i]][0]]
    samples = []
    for s in range(3):
        kq = np.arange(1, len(own) + 1, dtype=float) + 5 * s
        q = np.array([model.qpos0[j] for j in own]) + 0.3 * np.sin(1.3 * kq + 0.2) + 0.1 * kq
        v = 0.7 * np.cos(1.9 * kq + 0.5) if s else np.zeros(len(own))
        qpos, qvel = e @ q + b, e @ v
        m, m_rigid, bias = mass_and_bias(model, data, qpos, qvel)
        # The linear couplings hold exactly at qpos: MuJoCo's residuals are zero.
        for r in range(data.nefc):
            if data.efc_type[r] == mujoco.mjtConstraint.mjCNSTR_EQUALITY and data.efc_id[r] in linear:
                assert abs(data.efc_pos[r]) < 1e-14, (s, data.efc_id[r], data.efc_pos[r])
        samples.append({"q": q.tolist(), "v": v.tolist(), "qpos": qpos.tolist(), "qvel": qvel.tolist(),
                        "M": (e.T @ m @ e).tolist(), "M_rigid": (e.T @ m_rigid @ e).tolist(),
                        "bias": (e.T @ bias).tolist()})
    return {"mujoco": mujoco.__version__, "joints": [name(j) for j in range(model.njnt)],
            "reduced": [name(j) for j in own],
            "followers": [{"joint": name(j), "leader": name(l), "multiplier": k, "offset": o}
                          for j, (l, k, o) in sorted(follow.items())],
            "E": e.tolist(), "gravity": model.opt.gravity.tolist(),
            "armature": np.diag(reduced_armature).tolist(), "qpos0": model.qpos0.tolist(),
            "samples": samples}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out-dir", default="tests/fixtures/mjcf")
    args = ap.parse_args()
    path = os.path.join(args.out_dir, "equality.xml")
    with open(path, "w") as f:
        f.write(XML)
    ref = reference(path)
    ref["robot"] = "equality"
    ref["source"] = "tests/fixtures/mjcf/equality.xml (written by scripts/make_mjcf_equality_fixtures.py)"
    with open(os.path.join(args.out_dir, "equality.json"), "w") as f:
        json.dump(ref, f, indent=1)
        f.write("\n")
    print(f"equality: {len(ref['samples'])} states, joints {ref['joints']}, reduced {ref['reduced']}, "
          f"followers {ref['followers']}")


if __name__ == "__main__":
    main()
