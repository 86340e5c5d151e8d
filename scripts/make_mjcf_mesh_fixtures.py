#!/usr/bin/env python3
"""Write the mesh-inertia fixtures of `tests/fixtures/mjcf_mesh/` with MuJoCo itself.

Needs `pip install mujoco numpy` (written against MuJoCo 4.0.0). From the project
root:

    python scripts/make_mjcf_mesh_fixtures.py      # writes tests/fixtures/mjcf_mesh/

Writes small meshes into `meshes/`:

- `box.stl`: a box of sides 0.2 x 0.4 x 0.6 with a corner at (0.1, -0.2, 0.05),
  binary STL (MuJoCo reads binary STL only);
- `ell.obj` and `ell.stl`: a non-convex L-shaped prism (an L of 0.3 x 0.2 with arms
  0.1 wide, 0.15 deep), as OBJ with quadrilateral faces and as binary STL;
- `tetra.stl`: a tetrahedron.

and MJCF models using them, each body on a hinge (joint `pos` 0, so the body frame is
the link frame), with `<compiler meshdir="meshes">`:

- `modes.xml`: the box (MuJoCo's default `inertia`, `legacy`), the L prism as OBJ
  with `exact`, as STL with `convex` (its hull), `legacy` (too much volume: the
  L's inner corner counted twice) and `shell`, the tetrahedron with `exact`, each
  geom with its own `pos` and orientation;
- `scaled.xml`: the box scaled (`scale`, through a `<default><mesh>` class) and
  moved (`refpos`, `refquat`), a mesh geom with `mass`, a mesh geom beside a
  primitive one in one body, an inline `vertex`/`face` mesh and one given by its
  vertices alone (MuJoCo takes the convex hull's faces), and the L prism mirrored
  (a negative `scale`) in the `convex` and `exact` modes.

For each model, `NAME.json`: every body's mass, centre of mass and inertia tensor in
the body frame (`body_ipos`, and `R diag(body_inertia) R^T` with `R` from
`body_iquat`), and at three fixed states the mass matrix (`mj_fullM`) and bias forces
(`qfrc_bias`).
"""
import json
import os
import struct

import mujoco
import numpy as np

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures", "mjcf_mesh")


def box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
         (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)]
    return v, f


def ell():
    """An L in the xy plane (outline counter-clockwise), extruded along z; faces as
    quadrilaterals (the caps split into convex quads)."""
    outline = [(0.0, 0.0), (0.3, 0.0), (0.3, 0.1), (0.1, 0.1), (0.1, 0.2), (0.0, 0.2)]
    n = len(outline)
    v = [(x, y, 0.0) for x, y in outline] + [(x, y, 0.15) for x, y in outline]
    # Bottom (seen from below: clockwise in xy), top, and the sides.
    quads = [(0, 5, 4, 3), (0, 3, 2, 1), (6, 7, 8, 9), (6, 9, 10, 11)]
    for i in range(n):
        j = (i + 1) % n
        quads.append((i, j, n + j, n + i))
    return v, quads


def triangles(quads):
    out = []
    for q in quads:
        out.append((q[0], q[1], q[2]))
        if len(q) == 4:
            out.append((q[0], q[2], q[3]))
    return out


def write_stl(path, v, f):
    with open(path, "wb") as fh:
        fh.write(b"binary STL written for dyngen's tests".ljust(80, b" "))
        fh.write(struct.pack("<I", len(f)))
        for t in f:
            fh.write(struct.pack("<3f", 0, 0, 0))
            for i in t:
                fh.write(struct.pack("<3f", *v[i]))
            fh.write(b"\0\0")


def write_obj(path, v, faces):
    with open(path, "w") as fh:
        fh.write("# an L-shaped prism\no ell\n")
        for p in v:
            fh.write("v %s %s %s\n" % p)
        for q in faces:
            fh.write("f " + " ".join(str(i + 1) for i in q) + "\n")


def states(model):
    n = model.nv
    k = np.arange(1, n + 1, dtype=float)
    return [
        (np.zeros(n), np.zeros(n)),
        (0.9 * np.sin(1.7 * k), 0.5 * np.cos(2.3 * k)),
        (1.1 * np.cos(0.9 * k + 0.4), -0.8 * np.sin(1.1 * k + 0.2)),
    ]


def reference(xml_path):
    model = mujoco.MjModel.from_xml_path(xml_path)
    data = mujoco.MjData(model)
    bodies = []
    for b in range(1, model.nbody):
        r = np.zeros(9)
        mujoco.mju_quat2Mat(r, model.body_iquat[b])
        r = r.reshape(3, 3)
        inertia = r @ np.diag(model.body_inertia[b]) @ r.T
        bodies.append({"name": mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b),
                       "mass": float(model.body_mass[b]), "com": model.body_ipos[b].tolist(),
                       "inertia": inertia.tolist()})
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
    return {"mujoco": mujoco.__version__, "joints": joints, "gravity": model.opt.gravity.tolist(),
            "bodies": bodies, "samples": samples}


MODES = """<mujoco model="mesh_modes">
  <!-- Written by scripts/make_mjcf_mesh_fixtures.py: mesh inertia in each of MuJoCo's modes. -->
  <compiler meshdir="meshes" angle="radian"/>
  <asset>
    <mesh file="box.stl"/>
    <mesh name="ell_exact" file="ell.obj" inertia="exact"/>
    <mesh name="ell_hull" file="ell.stl" inertia="convex"/>
    <mesh name="ell_legacy" file="ell.stl" inertia="legacy"/>
    <mesh name="ell_shell" file="ell.obj" inertia="shell"/>
    <mesh name="tetra" file="tetra.stl" inertia="exact"/>
  </asset>
  <worldbody>
    <body name="box" pos="0 0 0.5">
      <joint name="j1" axis="0 1 0"/>
      <geom type="mesh" mesh="box" pos="0.05 0 -0.1" euler="0.3 -0.2 0.7"/>
      <body name="ell_exact" pos="0.4 0 0">
        <joint name="j2" axis="1 0 0"/>
        <geom type="mesh" mesh="ell_exact" quat="0.9 0.1 -0.3 0.2" pos="0 0.1 0"/>
        <body name="ell_hull" pos="0 0.3 0">
          <joint name="j3" axis="0 0 1"/>
          <geom type="mesh" mesh="ell_hull" density="700"/>
          <body name="ell_legacy" pos="0 0 -0.3">
            <joint name="j4" axis="0 1 0"/>
            <geom type="mesh" mesh="ell_legacy" axisangle="1 1 0 0.6"/>
            <body name="ell_shell" pos="0.2 0 0">
              <joint name="j5" axis="1 0 0"/>
              <geom type="mesh" mesh="ell_shell" density="2" pos="0 0 0.1"/>
              <body name="tetra" pos="0 0.2 0">
                <joint name="j6" axis="0 0 1"/>
                <geom type="mesh" mesh="tetra" zaxis="1 0 1"/>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

SCALED = """<mujoco model="mesh_scaled">
  <!-- Written by scripts/make_mjcf_mesh_fixtures.py: scaled and moved meshes, mass, inline meshes. -->
  <compiler meshdir="meshes" angle="radian"/>
  <default>
    <default class="big">
      <mesh scale="1.5 0.5 2"/>
    </default>
  </default>
  <asset>
    <mesh name="box_scaled" class="big" file="box.stl" refpos="0.1 0.2 0.3" refquat="0.8 0.2 0.1 -0.3"/>
    <mesh name="ell_small" file="ell.obj" scale="0.5 0.5 0.5" inertia="exact"/>
    <mesh name="wedge" vertex="0 0 0  0.2 0 0  0 0.3 0  0 0 0.1  0.2 0 0.1  0 0.3 0.1"
          face="0 2 1  3 4 5  0 1 4  0 4 3  1 2 5  1 5 4  2 0 3  2 3 5" inertia="exact"/>
    <mesh name="cloud" vertex="0 0 0  0.1 0 0  0 0.1 0  0 0 0.1  0.1 0.1 0.1  0.05 0.05 0.05"/>
    <mesh name="mirror_hull" file="ell.stl" scale="-0.8 1 1" inertia="convex"/>
    <mesh name="mirror_exact" file="ell.obj" scale="1 -1 1.2" inertia="exact"/>
  </asset>
  <worldbody>
    <body name="scaled" pos="0 0 0.5">
      <joint name="j1" axis="0 1 0"/>
      <geom type="mesh" mesh="box_scaled" pos="0.1 0 0"/>
      <body name="massive" pos="0.4 0 0">
        <joint name="j2" axis="1 0 0"/>
        <geom type="mesh" mesh="ell_small" mass="2.5" euler="0.1 0.2 0.3"/>
        <geom type="box" size="0.05 0.04 0.03" pos="0 0 -0.2"/>
        <body name="inline" pos="0 0.3 0">
          <joint name="j3" axis="0 0 1"/>
          <geom type="mesh" mesh="wedge" pos="0.02 0 0"/>
          <geom type="mesh" mesh="cloud" pos="0 -0.1 0" density="500"/>
          <body name="mirror" pos="0 0 -0.3">
            <joint name="j4" axis="0 1 0"/>
            <geom type="mesh" mesh="mirror_hull" euler="0.5 0 0"/>
            <geom type="mesh" mesh="mirror_exact" pos="0.1 0 0"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def main():
    meshes = os.path.join(HERE, "meshes")
    os.makedirs(meshes, exist_ok=True)
    v, f = box((0.1, -0.2, 0.05), (0.3, 0.2, 0.65))
    write_stl(os.path.join(meshes, "box.stl"), v, f)
    v, quads = ell()
    write_obj(os.path.join(meshes, "ell.obj"), v, quads)
    write_stl(os.path.join(meshes, "ell.stl"), v, triangles(quads))
    tv = [(0.0, 0.0, 0.0), (0.2, 0.0, 0.0), (0.0, 0.3, 0.0), (0.05, 0.05, 0.25)]
    write_stl(os.path.join(meshes, "tetra.stl"), tv, [(0, 2, 1), (0, 1, 3), (1, 2, 3), (2, 0, 3)])
    for name, text in [("modes", MODES), ("scaled", SCALED)]:
        path = os.path.join(HERE, name + ".xml")
        with open(path, "w") as fh:
            fh.write(text)
        ref = reference(path)
        with open(os.path.join(HERE, name + ".json"), "w") as fh:
            json.dump(ref, fh, indent=1)
            fh.write("\n")
        print(name, [(b["name"], round(b["mass"], 6)) for b in ref["bodies"]])


if __name__ == "__main__":
    main()
