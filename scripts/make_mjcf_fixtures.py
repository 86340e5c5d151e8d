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

For `robots/quadruped12/quadruped12.urdf`, (a) with the root link put on a URDF
`floating` joint from a `world` link first: `quadruped12.xml`, with MuJoCo's free
joint; `model/tests/integration/mjcf.rs` reads it and checks it against the URDF loaded with a
free flyer (the same robot in both formats).

(c) For the hand-written `small.xml` (not written by this script), MuJoCo's values as
    in (b): `small.json`.
(d) For the hand-written `floating.xml` (a free-floating torso and a ball joint),
    MuJoCo's values as in (b) at three fixed states, converted to dyngen's (Pinocchio's)
    coordinates: `floating.json`. See `floating_reference` for the conversion; the
    script checks it (kinetic energy and M's bilinear form equal in both coordinates,
    the bias against MuJoCo's own inverse dynamics at the acceleration that is zero in
    dyngen's coordinates, found by finite differences) and stops if it fails.

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
# Floating-base robots: the URDF's root link put on a `floating` joint from a `world`
# link before the export, which MuJoCo turns into a free joint (`<freejoint>`).
FLOATING = {"quadruped12": "robots/quadruped12/quadruped12.urdf"}
COMPILER = ('<mujoco><compiler discardvisual="true" fusestatic="false" '
            'balanceinertia="false" angle="radian"/></mujoco>')


def urdf_to_mjcf(urdf_path, out_path, floating=False):
    with open(urdf_path) as f:
        src = f.read()
    if floating:
        children = set(re.findall(r'<child\s+link="([^"]+)"', src))
        links = re.findall(r'<link\s+name="([^"]+)"', src)
        [root] = [l for l in links if l not in children]
        world = ('<link name="world"/><joint name="root_joint" type="floating">'
                 f'<parent link="world"/><child link="{root}"/></joint>')
        src, n = re.subn(r"(<robot[^>]*>)", lambda m: m.group(1) + world, src, count=1)
        assert n == 1, "no <robot> element"
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


def quat_matrix(wxyz):
    r = np.zeros(9)
    mujoco.mju_quat2Mat(r, np.asarray(wxyz, dtype=float))
    return r.reshape(3, 3)


def velocity_map(model, qpos):
    """`T` with dyngen's `v = T qvel`: `Rᵀ` on a free joint's linear velocity (MuJoCo's
    is in world axes, dyngen's in body axes, `R` the body's orientation), the identity
    elsewhere (a free joint's angular velocity, a ball joint's, hinges and slides are
    the same in both)."""
    t = np.eye(model.nv)
    for j in range(model.njnt):
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            qa, da = model.jnt_qposadr[j], model.jnt_dofadr[j]
            t[da:da + 3, da:da + 3] = quat_matrix(qpos[qa + 3:qa + 7]).T
    return t


def to_dyngen_q(model, qpos):
    """Quaternions `w x y z` (MuJoCo) to `x y z w` (Pinocchio, dyngen)."""
    q = qpos.copy()
    for j in range(model.njnt):
        qa = model.jnt_qposadr[j]
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            qa += 3
        elif model.jnt_type[j] != mujoco.mjtJoint.mjJNT_BALL:
            continue
        q[qa:qa + 4] = np.roll(qpos[qa:qa + 4], -1)
    return q


def floating_states(model):
    """Three fixed states in MuJoCo's coordinates: unit quaternions from fixed
    (unnormalised) numbers, hinge and slide inside their ranges; the first at rest."""
    unit = lambda *x: np.array(x) / np.linalg.norm(x)
    qpos = [
        np.concatenate([[0.1, -0.2, 1.1], unit(0.9, 0.1, -0.2, 0.3), unit(0.8, 0.3, -0.4, 0.2), [-0.7, 0.02]]),
        np.concatenate([[-0.4, 0.3, 0.8], unit(0.2, -0.7, 0.5, 0.4), unit(0.6, -0.1, 0.5, -0.3), [-1.9, -0.04]]),
        np.concatenate([[1.3, 0.9, -0.5], unit(-0.3, 0.4, 0.8, -0.2), unit(0.9, 0.2, 0.1, 0.35), [0.05, 0.045]]),
    ]
    qvel = [
        np.zeros(model.nv),
        np.array([0.3, -0.5, 0.2, 0.7, -1.1, 0.4, 1.2, -0.3, 0.8, 1.5, -0.3]),
        np.array([-1.2, 0.8, 2.1, -2.3, 0.9, 1.7, -0.6, 2.4, -1.1, -2.2, 0.6]),
    ]
    return list(zip(qpos, qvel))


def floating_reference(xml_path):
    """MuJoCo's `M` and bias in dyngen's coordinates. With `v = T qvel`
    (`velocity_map`), power `τᵀv = τ_mjᵀqvel` gives `τ = T⁻ᵀ τ_mj`, and
    `½ qvelᵀ M_mj qvel = ½ vᵀ M v` gives `M = T⁻ᵀ M_mj T⁻¹`. `T` moves with the body:
    `v̇ = T q̈vel + Ṫ qvel`, `Ṫ qvel = [−ω × v_lin; 0]` on a free joint (`Ṙᵀ = −[ω]ₓ Rᵀ`,
    `ω` in body axes), so `τ = M v̇ + b` with `b = T⁻ᵀ b_mj + M [ω × v_lin; 0]`."""
    model = mujoco.MjModel.from_xml_path(xml_path)
    data = mujoco.MjData(model)
    assert model.nu == 0 and not model.dof_armature.any(), "armature would be in M"
    joints = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    rng = np.random.default_rng(7)
    samples, worst = [], {"energy": 0.0, "bilinear": 0.0, "bias": 0.0}
    for qpos, qvel in floating_states(model):
        data.qpos[:] = qpos
        data.qvel[:] = qvel
        mujoco.mj_forward(model, data)
        m_mj = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, m_mj)
        b_mj = data.qfrc_bias.copy()
        t = velocity_map(model, qpos)
        t_inv = np.linalg.inv(t)
        m = t_inv.T @ m_mj @ t_inv
        m = 0.5 * (m + m.T)
        tdot_v = np.zeros(model.nv)
        for j in range(model.njnt):
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
                da = model.jnt_dofadr[j]
                v_lin = t[da:da + 3, da:da + 3] @ qvel[da:da + 3]
                tdot_v[da:da + 3] = -np.cross(qvel[da + 3:da + 6], v_lin)
        v = t @ qvel
        bias = t_inv.T @ b_mj - m @ tdot_v
        # Checks. Kinetic energy, and M's bilinear form on random velocities.
        rel = lambda a, b: abs(a - b) / max(abs(b), 1e-300)
        if qvel.any():
            worst["energy"] = max(worst["energy"], rel(v @ m @ v, qvel @ m_mj @ qvel))
        x, y = rng.standard_normal(model.nv), rng.standard_normal(model.nv)
        worst["bilinear"] = max(worst["bilinear"], rel((t @ x) @ m @ (t @ y), x @ m_mj @ y))
        # The bias is τ at v̇ = 0: MuJoCo's inverse dynamics (`mj_rne`, rigid bodies
        # only) at q̈vel = −T⁻¹ Ṫ qvel, with Ṫ qvel by central differences along qvel.
        h = 1e-6
        ends = []
        for sign in (1.0, -1.0):
            qh = qpos.copy()
            mujoco.mj_integratePos(model, qh, qvel, sign * h)
            ends.append(velocity_map(model, qh) @ qvel)
        tdot_v_fd = (ends[0] - ends[1]) / (2 * h)
        data.qacc[:] = -t_inv @ tdot_v_fd
        tau_mj = np.zeros(model.nv)
        mujoco.mj_rne(model, data, 1, tau_mj)
        bias_fd = t_inv.T @ tau_mj
        worst["bias"] = max(worst["bias"], np.abs(bias_fd - bias).max() / np.abs(bias).max())
        samples.append({"q": to_dyngen_q(model, qpos).tolist(), "v": v.tolist(), "M": m.tolist(),
                        "bias": bias.tolist(),
                        "mujoco": {"qpos": qpos.tolist(), "qvel": qvel.tolist(), "M": m_mj.tolist(),
                                   "bias": b_mj.tolist()}})
    assert worst["energy"] < 1e-13 and worst["bilinear"] < 1e-13, worst
    assert worst["bias"] < 1e-8, worst
    return {"mujoco": mujoco.__version__, "joints": joints, "nq": model.nq, "nv": model.nv,
            "gravity": model.opt.gravity.tolist(),
            "coordinates": "dyngen's (Pinocchio's): quaternions x y z w; the free joint's "
                           "v = [R^T v_world; omega_body]; M = T^-T M_mj T^-1, "
                           "bias = T^-T bias_mj + M [omega x v_body; 0]; MuJoCo's own in `mujoco`",
            "conversion_check": {k: float(x) for k, x in worst.items()}, "samples": samples}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out-dir", default="tests/fixtures/mjcf")
    ap.add_argument("--only", choices=[*ROBOTS, *FLOATING, "small", "floating"],
                    help="write this fixture alone")
    args = ap.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    wanted = lambda name: args.only in (None, name)
    for name, urdf in FLOATING.items():
        if not wanted(name):
            continue
        xml = os.path.join(args.out_dir, name + ".xml")
        urdf_to_mjcf(urdf, xml, floating=True)
        print(f"{name}: {xml} (floating; compared with the URDF on a free flyer by model/tests/integration/mjcf.rs)")
    for name, urdf in ROBOTS.items():
        if not wanted(name):
            continue
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
    hand_written = [("small", reference), ("floating", floating_reference)]
    for name, make in hand_written:
        if not wanted(name):
            continue
        ref = make(os.path.join(args.out_dir, name + ".xml"))
        ref["robot"] = name
        ref["source"] = f"tests/fixtures/mjcf/{name}.xml (hand-written)"
        with open(os.path.join(args.out_dir, name + ".json"), "w") as f:
            json.dump(ref, f, indent=1)
            f.write("\n")
        extra = f", conversion checked to {ref['conversion_check']}" if "conversion_check" in ref else ""
        print(f"{name}: {len(ref['samples'])} states, joints {ref['joints']}{extra}")


if __name__ == "__main__":
    main()
