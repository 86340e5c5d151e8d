#!/usr/bin/env python3
"""Write a serial chain of N moving joints as URDF, for timing the model layer on
large robots (parsing, checks, base-parameter analysis).

Usage (plain python 3, no packages):
    python3 scripts/make_chain_urdf.py 100 > chain100.urdf
    python3 scripts/make_chain_urdf.py 200 --seed 7 -o chain200.urdf

The chain is spatial, not planar: every joint origin has a random offset and a
random rpy, the axes are random unit vectors (every third one axis-aligned), and
every seventh joint is prismatic. Links are homogeneous boxes with random
dimensions whose principal axes are turned by a random rpy, so every inertia is a
full, physical tensor. The same N and seed give the same file byte for byte.
"""
import argparse
import math
import random
import sys


def rpy_matrix(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]


def box_inertia(m, dims, rpy):
    a, b, c = dims
    d = [m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12]
    R = rpy_matrix(*rpy)
    return [[sum(R[i][k] * d[k] * R[j][k] for k in range(3)) for j in range(3)] for i in range(3)]


def num(x):
    x = float(f"{x:.6g}")
    return "0" if x == 0.0 else repr(x)


def vec(v):
    return " ".join(num(x) for x in v)


def unit(rng):
    while True:
        v = [rng.uniform(-1, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if 0.2 < n <= 1:
            return [x / n for x in v]


def chain(n, seed):
    rng = random.Random(seed)
    out = [f'<?xml version="1.0"?>\n<robot name="chain{n}">\n  <link name="link0"/>\n']
    for k in range(1, n + 1):
        m = rng.uniform(0.3, 3.0)
        dims = [rng.uniform(0.04, 0.3) for _ in range(3)]
        rpy = [rng.uniform(-1, 1) for _ in range(3)]
        inertia = box_inertia(m, dims, rpy)
        com = [rng.uniform(-0.05, 0.05) for _ in range(2)] + [rng.uniform(0.02, 0.15)]
        out.append(
            f'  <link name="link{k}">\n    <inertial>\n      <origin xyz="{vec(com)}" rpy="0 0 0"/>\n'
            f'      <mass value="{num(m)}"/>\n'
            f'      <inertia ixx="{num(inertia[0][0])}" ixy="{num(inertia[0][1])}" ixz="{num(inertia[0][2])}" '
            f'iyy="{num(inertia[1][1])}" iyz="{num(inertia[1][2])}" izz="{num(inertia[2][2])}"/>\n'
            f'    </inertial>\n  </link>\n'
        )
        prismatic = k % 7 == 0
        if k % 3 == 0:
            axis = [[1, 0, 0], [0, 1, 0], [0, 0, 1]][rng.randrange(3)]
        else:
            axis = unit(rng)
        xyz = [rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(0.05, 0.3)]
        jrpy = [rng.uniform(-0.8, 0.8) for _ in range(3)]
        kind = "prismatic" if prismatic else "revolute"
        lower, upper = (-0.2, 0.2) if prismatic else (-2.5, 2.5)
        out.append(
            f'  <joint name="joint{k}" type="{kind}">\n    <parent link="link{k - 1}"/>\n    <child link="link{k}"/>\n'
            f'    <origin xyz="{vec(xyz)}" rpy="{vec(jrpy)}"/>\n    <axis xyz="{vec(axis)}"/>\n'
            f'    <limit lower="{lower}" upper="{upper}" effort="100" velocity="2"/>\n  </joint>\n'
        )
    out.append("</robot>\n")
    return "".join(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("joints", type=int)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("-o", "--output", default="-")
    args = parser.parse_args()
    text = chain(args.joints, args.seed)
    if args.output == "-":
        sys.stdout.write(text)
    else:
        with open(args.output, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
