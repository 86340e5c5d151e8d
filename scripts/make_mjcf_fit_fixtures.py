#!/usr/bin/env python3
"""Write the fitted-primitive fixtures of `tests/fixtures/mjcf_mesh/` with MuJoCo itself.

Needs `pip install mujoco numpy` (written against MuJoCo 4.0.0) and the meshes that
`scripts/make_mjcf_mesh_fixtures.py` writes into `tests/fixtures/mjcf_mesh/meshes/`.
From the project root:

    python scripts/make_mjcf_fit_fixtures.py      # writes tests/fixtures/mjcf_mesh/fit_*

A box, sphere, capsule, cylinder or ellipsoid geom that names a mesh is fitted to it
by MuJoCo's compiler (`mjCMesh::FitGeom`): its size from the mesh's box of equal
inertia, or with `<compiler fitaabb="true">` from the mesh's bounding box in its
principal frame, times `fitscale`; its frame the mesh's principal frame (moved to the
bounding box's centre with `fitaabb`) placed by the geom's `pos` and orientation.
Both models below have the same bodies, each on a hinge, with fitted geoms of every
type on an asymmetric inline mesh (7 vertices, no faces: MuJoCo takes the convex
hull's) and on the L prism (`ell.obj`, scaled, in the `exact` and `shell` modes), with
`fitscale`, `mass`, `density`, a `pos` and an orientation, one beside a mesh geom of
the same mesh:

- `fit_inertia.xml`: MuJoCo's default, the box of equal inertia;
- `fit_aabb.xml`: `<compiler fitaabb="true">`.

For each model, `NAME.json` as `make_mjcf_mesh_fixtures.py` writes it: every body's
mass, centre of mass and inertia in the body frame, and at three fixed states the
mass matrix and bias forces.
"""
import json
import os

from make_mjcf_mesh_fixtures import HERE, reference

BODIES = """  <asset>
    <mesh name="rock" vertex="0 0 0  0.3 0 0  0 0.2 0  0 0 0.15  0.25 0.12 0.1  0.05 0.18 0.2  0.12 -0.03 0.07"/>
    <mesh name="ell" file="ell.obj" scale="1.2 0.8 1" inertia="exact"/>
    <mesh name="ell_shell" file="ell.obj" inertia="shell"/>
  </asset>
  <worldbody>
    <body name="box" pos="0 0 0.5">
      <joint name="j1" axis="0 1 0"/>
      <geom type="box" mesh="rock" pos="0.05 0 -0.1" euler="0.3 -0.2 0.7" fitscale="1.3"/>
      <body name="sphere" pos="0.4 0 0">
        <joint name="j2" axis="1 0 0"/>
        <geom type="sphere" mesh="rock" quat="0.9 0.1 -0.3 0.2" pos="0 0.1 0" density="700"/>
        <body name="capsule" pos="0 0.3 0">
          <joint name="j3" axis="0 0 1"/>
          <geom type="capsule" mesh="rock" fitscale="0.8" euler="0 0.4 0"/>
          <body name="cylinder" pos="0 0 -0.3">
            <joint name="j4" axis="0 1 0"/>
            <geom type="cylinder" mesh="rock" mass="1.7" axisangle="1 1 0 0.6"/>
            <body name="ellipsoid" pos="0.2 0 0">
              <joint name="j5" axis="1 0 0"/>
              <geom type="ellipsoid" mesh="rock" pos="0 0 0.1" fitscale="1.1"/>
              <geom type="mesh" mesh="rock" pos="0.1 0 0"/>
              <body name="ell" pos="0 0.2 0">
                <joint name="j6" axis="0 0 1"/>
                <geom type="box" mesh="ell" zaxis="1 0 1"/>
                <geom type="capsule" mesh="ell" pos="0 0 -0.2" fitscale="1.5" density="300"/>
                <body name="ell_shell" pos="0 0 0.2">
                  <joint name="j7" axis="1 0 0"/>
                  <geom type="cylinder" mesh="ell_shell" euler="0.2 0.1 0"/>
                  <geom type="sphere" mesh="ell_shell" pos="0.1 0 0" density="50"/>
                </body>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

MODELS = {
    "fit_inertia": """<mujoco model="fit_inertia">
  <!-- Written by scripts/make_mjcf_fit_fixtures.py: primitives fitted to meshes' boxes of equal inertia. -->
  <compiler meshdir="meshes" angle="radian"/>
""" + BODIES,
    "fit_aabb": """<mujoco model="fit_aabb">
  <!-- Written by scripts/make_mjcf_fit_fixtures.py: primitives fitted to meshes' bounding boxes. -->
  <compiler meshdir="meshes" angle="radian" fitaabb="true"/>
""" + BODIES,
}


def main():
    for name, text in MODELS.items():
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
