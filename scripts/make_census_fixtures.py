#!/usr/bin/env python3
"""Write the loading census: URDFs with what public descriptions carry and a strict
loader refuses, and Pinocchio reference fixtures (JSON) for each.

Usage (needs a python with `pip install pin==4.1.0 numpy`):

    PY=python3
    $PY scripts/make_census_fixtures.py            # every robot of ROBOTS
    $PY scripts/make_census_fixtures.py --name quadrotor

The URDFs are written here, from the dimensions below (no file is copied from
anywhere), into `tests/fixtures/census/`:

- `dummy_root_quadruped` (on a free flyer): a dummy root link whose exported inertia is
  rounding noise (a moment of -1.2e-22, the triangle inequality broken by 3e-6 > 0 + 0)
  fixed to a 5.6 kg trunk, an IMU link with noise, a rotor with inertia but no mass
  (`<mass value="0"/>`) and four 3-joint legs with point-mass feet;
- `arm_gripper` (fixed base): a 6-joint arm with a tool frame, and a gripper whose left
  finger hangs from a massless knuckle link (two revolute joints, different axes), has
  an inertia that breaks the triangle inequality by 20 % (Pinocchio keeps it as
  written), and whose right finger is locked (`type="fixed"`) with a `<mimic>` left in;
- `quadrotor` (on a free flyer): one rigid body with four propellers on fixed joints;
- `massless_tip` (fixed base): a 3-joint arm whose last link has no mass, so the mass
  matrix is singular along its joint (no forward dynamics is written for it).

Per sample, in dyngen's coordinates (`q = [p; x, y, z, w]` for the free flyer; `v`,
`a` as Pinocchio's): `tau = rnea(q, v, a)`, `nle = rnea(q, v, 0)`, `gravity = rnea(q,
0, 0)`, `M` (crba, mirrored), and where `M` is positive definite `ddq = aba(q, v,
tau_rand)` for a random `tau_rand`. The script checks `M ddq + nle = tau_rand` to 1e-9
before writing. Matrices are lists of rows.
"""
import argparse
import json
import math
import os
import sys

import numpy as np
import pinocchio as pin

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT_DIR = os.path.join(ROOT, "tests", "fixtures", "census")
GENERATOR = "scripts/make_census_fixtures.py"
TOL = 1e-9


def inertial(mass, moments=(0.0, 0.0, 0.0), products=(0.0, 0.0, 0.0), xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)):
    ixx, iyy, izz = moments
    ixy, ixz, iyz = products
    return (
        f'<inertial><origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/>'
        f'<mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/></inertial>'
    )


def link(name, body=""):
    return f'  <link name="{name}">{body}</link>'


def joint(name, kind, parent, child, xyz=(0, 0, 0), rpy=(0, 0, 0), axis=None, extra=""):
    text = f'  <joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
    text += f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/>'
    if axis is not None:
        text += f'<axis xyz="{axis[0]} {axis[1]} {axis[2]}"/>'
    if kind in ("revolute", "prismatic"):
        text += '<limit lower="-3" upper="3" effort="100" velocity="5"/>'
    return text + extra + "</joint>"


def robot(name, lines):
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "\n".join(lines) + "\n</robot>\n"


def dummy_root_quadruped():
    lines = [
        link("base", inertial(0.001, (-1.2e-22, 0.0, 3e-6))),
        link("trunk", inertial(5.6, (0.018, 0.068, 0.077), (1e-4, -2e-4, 3e-5), xyz=(0.01, 0.002, -0.003))),
        link("imu_link", inertial(1e-9, (-1e-20, 1e-12, 0.0))),
        link("rotor", inertial(0.0, (2e-5, 2e-5, 3e-5))),
        joint("floating_base", "fixed", "base", "trunk"),
        joint("imu_joint", "fixed", "trunk", "imu_link", xyz=(0.05, 0.0, 0.02)),
        joint("rotor_joint", "fixed", "trunk", "rotor", xyz=(0.1, 0.05, 0.0), rpy=(0.0, 1.5707963267948966, 0.0)),
    ]
    for leg, (sx, sy) in {"FL": (1, 1), "FR": (1, -1), "RL": (-1, 1), "RR": (-1, -1)}.items():
        lines += [
            link(f"{leg}_hip", inertial(0.7, (4e-4, 7e-4, 5e-4), xyz=(-0.005 * sx, 0.01 * sy, 0.0))),
            link(f"{leg}_thigh", inertial(1.0, (5e-3, 5e-3, 1e-3), (0.0, 1e-5, 0.0), xyz=(0.0, -0.02 * sy, -0.03))),
            link(f"{leg}_calf", inertial(0.15, (2e-3, 2e-3, 3e-5), xyz=(0.005, 0.0, -0.1))),
            link(f"{leg}_foot", inertial(0.06)),
            joint(f"{leg}_hip_joint", "revolute", "trunk", f"{leg}_hip", xyz=(0.19 * sx, 0.05 * sy, 0.0), axis=(1, 0, 0)),
            joint(f"{leg}_thigh_joint", "revolute", f"{leg}_hip", f"{leg}_thigh", xyz=(0.0, 0.08 * sy, 0.0), axis=(0, 1, 0)),
            joint(f"{leg}_calf_joint", "revolute", f"{leg}_thigh", f"{leg}_calf", xyz=(0.0, 0.0, -0.2), axis=(0, 1, 0)),
            joint(f"{leg}_foot_joint", "fixed", f"{leg}_calf", f"{leg}_foot", xyz=(0.0, 0.0, -0.2)),
        ]
    return robot("dummy_root_quadruped", lines)


def arm_gripper():
    dims = [(0.0, 0.0, 0.089), (0.0, 0.135, 0.0), (0.0, -0.12, 0.425), (0.0, 0.0, 0.392), (0.0, 0.093, 0.0), (0.0, 0.0, 0.095)]
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (0, 1, 0), (0, 0, 1), (0, 1, 0)]
    masses = [3.7, 8.4, 2.3, 1.2, 1.2, 0.19]
    lines = [link("base_link", inertial(4.0, (4e-3, 4e-3, 7e-3)))]
    parent = "base_link"
    for k in range(6):
        name = f"link{k + 1}"
        m = masses[k]
        lines.append(link(name, inertial(m, (0.01 * m, 0.012 * m, 0.008 * m), (1e-4, 0.0, -1e-4), xyz=(0.0, 0.01, 0.05))))
        lines.append(joint(f"joint{k + 1}", "revolute", parent, name, xyz=dims[k], axis=axes[k]))
        parent = name
    lines += [
        link("tool0"),
        joint("tool0_joint", "fixed", "link6", "tool0", xyz=(0.0, 0.08, 0.0), rpy=(-1.5707963267948966, 0.0, 0.0)),
        link("palm", inertial(0.4, (3e-4, 4e-4, 3e-4), xyz=(0.0, 0.0, 0.03))),
        joint("palm_joint", "fixed", "tool0", "palm"),
        # The knuckle carries no mass: Pinocchio reads a zero inertia.
        link("left_knuckle"),
        joint("left_knuckle_joint", "revolute", "palm", "left_knuckle", xyz=(0.0, 0.03, 0.06), axis=(1, 0, 0)),
        # J3 = 2.4e-5 > J1 + J2 = 2e-5: 20 % of the largest moment beyond physical.
        link("left_finger", inertial(0.05, (1e-5, 1e-5, 2.4e-5), xyz=(0.0, 0.01, 0.03))),
        joint("left_finger_joint", "revolute", "left_knuckle", "left_finger", xyz=(0.0, 0.0, 0.01), axis=(0, 1, 0)),
        link("right_finger", inertial(0.05, (1e-5, 1e-5, 1.5e-5), xyz=(0.0, -0.01, 0.03))),
        joint("right_finger_joint", "fixed", "palm", "right_finger", xyz=(0.0, -0.03, 0.06),
              extra='<mimic joint="left_knuckle_joint" multiplier="-1" offset="0"/>'),
    ]
    return robot("arm_gripper", lines)


def quadrotor():
    lines = [link("body", inertial(1.2, (0.012, 0.013, 0.022), (1e-4, 0.0, 2e-5), xyz=(0.0, 0.0, -0.01)))]
    for k, (x, y) in enumerate([(0.17, 0.17), (-0.17, 0.17), (-0.17, -0.17), (0.17, -0.17)]):
        lines.append(link(f"prop{k}", inertial(0.01, (1e-6, 1e-6, 2e-6))))
        lines.append(joint(f"prop{k}_joint", "fixed", "body", f"prop{k}", xyz=(x, y, 0.03)))
    return robot("quadrotor", lines)


def massless_tip():
    lines = [
        link("base"),
        link("upper", inertial(2.0, (0.02, 0.02, 0.004), xyz=(0.0, 0.0, 0.15))),
        link("lower", inertial(1.0, (0.01, 0.01, 0.002), xyz=(0.0, 0.0, 0.12))),
        link("tip"),
        joint("shoulder", "revolute", "base", "upper", axis=(0, 1, 0)),
        joint("elbow", "revolute", "upper", "lower", xyz=(0.0, 0.0, 0.3), axis=(0, 1, 0)),
        joint("wrist", "revolute", "lower", "tip", xyz=(0.0, 0.0, 0.25), axis=(0, 0, 1)),
    ]
    return robot("massless_tip", lines)


# name: (text, free flyer, samples, seed)
ROBOTS = {
    "dummy_root_quadruped": (dummy_root_quadruped, True, 4, 21),
    "arm_gripper": (arm_gripper, False, 4, 22),
    "quadrotor": (quadrotor, True, 4, 23),
    "massless_tip": (massless_tip, False, 4, 24),
}


def flat(x):
    return [float(v) for v in np.asarray(x).reshape(-1)]


def rows(m):
    return [flat(r) for r in np.asarray(m)]


def sample(model, rng):
    q = np.zeros(model.nq)
    for j in model.joints[1:]:
        iq, name = j.idx_q, j.shortname()
        if name == "JointModelFreeFlyer":
            quat = rng.normal(size=4)
            q[iq:iq + 3] = rng.uniform(-1.0, 1.0, 3)
            q[iq + 3:iq + 7] = quat / np.linalg.norm(quat)
        elif j.nq == 1:
            q[iq] = rng.uniform(-math.pi, math.pi)
        else:
            sys.exit(f"unsupported joint {name}")
    return q, rng.uniform(-2.0, 2.0, model.nv), rng.uniform(-2.0, 2.0, model.nv), rng.uniform(-10.0, 10.0, model.nv)


def make(name, path, free_flyer, samples, seed):
    model = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer()) if free_flyer else pin.buildModelFromUrdf(path)
    data = model.createData()
    rng = np.random.default_rng(seed)
    pi = np.concatenate([model.inertias[i].toDynamicParameters() for i in range(1, model.njoints)])
    worst = 0.0
    out = []
    for _ in range(samples):
        q, v, a, tau_rand = sample(model, rng)
        tau = pin.rnea(model, data, q, v, a).copy()
        nle = pin.rnea(model, data, q, v, np.zeros(model.nv)).copy()
        grav = pin.rnea(model, data, q, np.zeros(model.nv), np.zeros(model.nv)).copy()
        m = pin.crba(model, data, q).copy()
        m = np.triu(m) + np.triu(m, 1).T
        s = {"q": flat(q), "v": flat(v), "a": flat(a), "tau": flat(tau), "nle": flat(nle), "gravity": flat(grav),
             "M": rows(m)}
        if np.linalg.eigvalsh(m).min() > 1e-9 * np.abs(m).max():
            ddq = pin.aba(model, data, q, v, tau_rand).copy()
            worst = max(worst, float(np.abs(m @ ddq + nle - tau_rand).max()))
            s.update({"tau_rand": flat(tau_rand), "ddq": flat(ddq)})
        out.append(s)
    if not worst <= TOL:
        sys.exit(f"{name}: Pinocchio's aba does not invert M ddq + nle by {worst:e}")
    return {
        "generator": GENERATOR,
        "pinocchio": pin.__version__,
        "urdf": f"tests/fixtures/census/{name}.urdf",
        "root_joint": "freeflyer" if free_flyer else "none",
        "seed": seed,
        "model": {
            "nq": model.nq, "nv": model.nv,
            "joints": [model.names[i] for i in range(1, model.njoints)],
            "parents": [int(model.parents[i]) for i in range(1, model.njoints)],
            "params": flat(pi),
        },
        "checks_max_abs": {"aba": worst},
        "samples": out,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--name", choices=sorted(ROBOTS), help="one robot (default: all)")
    args = ap.parse_args()
    os.makedirs(OUT_DIR, exist_ok=True)
    for name, (text, free_flyer, samples, seed) in ROBOTS.items():
        if args.name and name != args.name:
            continue
        urdf = os.path.join(OUT_DIR, f"{name}.urdf")
        with open(urdf, "w") as f:
            f.write(text())
        fix = make(name, urdf, free_flyer, samples, seed)
        path = os.path.join(OUT_DIR, f"{name}.json")
        with open(path, "w") as f:
            json.dump(fix, f, separators=(",", ":"))
            f.write("\n")
        print(f"wrote {os.path.relpath(urdf, ROOT)} and {os.path.relpath(path, ROOT)}: {len(fix['samples'])} samples, "
              f"aba check {fix['checks_max_abs']['aba']:.1e}")


if __name__ == "__main__":
    main()
