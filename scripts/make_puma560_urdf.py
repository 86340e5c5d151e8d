#!/usr/bin/env python3
"""Generate robots/puma560/puma560.urdf: Unimation PUMA 560 with the Armstrong, Khatib &
Burdick (1986) inertial parameters as in Corke's Robotics Toolbox `mdl_puma560`.

Usage (any python with numpy, e.g. the Pinocchio oracle venv; works from any directory):
    PY=${PIN_HOME:-$HOME/.cache/pinocchio-oracle}/.venv/bin/python
    $PY scripts/make_puma560_urdf.py            # writes robots/puma560/puma560.urdf
    $PY scripts/make_puma560_urdf.py -o -       # prints to stdout

Source: P. Corke, Robotics Toolbox for MATLAB, mdl_puma560.m (standard DH, "params of
8/95"; reference: P. Corke, B. Armstrong-Helouvry, "A search for consensus among model
parameters reported for the PUMA 560 robot", ICRA 1994; inertial data from B. Armstrong,
O. Khatib, J. Burdick, "The Explicit Dynamic Model and Inertial Parameters of the PUMA
560 Arm", ICRA 1986): DH d, a, alpha, link masses m, centres of mass r and inertias I
(Ixx, Iyy, Izz about the centre of mass, products 0) in the DH frame of each link, and
the joint limits qlim. Motor inertias Jm, gear ratios G and friction B, Tc are not
included (URDF has no place for them; Pinocchio's rnea ignores them).

Fixes needed for a physical rigid body (the project's validator and Pinocchio's
fixture script require mass > 0 and a positive-definite inertia satisfying the
triangle inequalities):
- link 1: the toolbox has m1 = 0 and I1 = (0, 0.35, 0) (Armstrong found no m1; only the
  moment about the joint-1 axis, y of DH frame 1, matters). We give link 1 a nominal
  mass of 13.0 kg with its centre of mass on the joint-1 axis (origin of DH frame 1)
  and Ixx = Izz = 0.18 kg m^2 (the triangle inequality needs Ixx + Izz >= Iyy = 0.35),
  keeping Iyy = 0.35. None of this changes any joint torque of the fixed-base arm
  (it only adds the link's own weight and moments about x1, z1 to the joint-1 wrench).
- link 3: (0.066, 0.086, 0.0125) violates the triangle inequality
  (0.086 > 0.066 + 0.0125 = 0.0785). We keep Ixx and Iyy (Iyy is the moment about the
  joint-3 axis) and raise Izz (about z3, the forearm / joint-4 axis) from 0.0125 to
  0.0205, just above the bound 0.020.
- links 2, 4, 5, 6 are physical as published.

Frames, as in scripts/make_ur5_urdf.py. Standard DH: frame i = frame (i-1) Rz(theta_i)
Tz(d_i) Tx(a_i) Rx(alpha_i), joint i turns about z of DH frame i-1. The URDF frame of
link i is L_i = F_(i-1) Rz(theta_i), so joint 1's origin is the identity and joint
i+1's origin in link i is Tz(d_i) Tx(a_i) Rx(alpha_i) = xyz (a_i, 0, d_i), rpy
(alpha_i, 0, 0); the fixed `flange` frame (massless) is DH frame 6. A centre of mass c
in DH frame i is (a_i, 0, d_i) + Rx(alpha_i) c in L_i and an inertia I is
Rx(alpha_i) I Rx(alpha_i)^T; multiples of pi/2 are built exactly.
"""
import argparse
import math
import os
import sys

import numpy as np

PI = math.pi
DEG = PI / 180.0

# --- Corke, mdl_puma560.m (standard DH, params of 8/95) ------------------------------
D = [0.0, 0.0, 0.15005, 0.4318, 0.0, 0.0]
A = [0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0]
ALPHA = [PI / 2, 0.0, -PI / 2, PI / 2, -PI / 2, 0.0]
ALPHA_TXT = "[pi/2, 0, -pi/2, pi/2, -pi/2, 0]"
MASS_PUB = [0.0, 17.4, 4.8, 0.82, 0.34, 0.09]
COM_DH = [  # r: centre of mass of link i in DH frame i
    [0.0, 0.0, 0.0],
    [-0.3638, 0.006, 0.2275],
    [-0.0203, -0.0141, 0.070],
    [0.0, 0.019, 0.0],
    [0.0, 0.0, 0.0],
    [0.0, 0.0, 0.032],
]
I_PUB = [  # Ixx, Iyy, Izz about the centre of mass, DH frame i axes; products are 0
    [0.0, 0.35, 0.0],
    [0.13, 0.524, 0.539],
    [0.066, 0.086, 0.0125],
    [1.8e-3, 1.3e-3, 1.8e-3],
    [0.3e-3, 0.4e-3, 0.3e-3],
    [0.15e-3, 0.15e-3, 0.04e-3],
]
QLIM_DEG = [(-160, 160), (-45, 225), (-225, 45), (-110, 170), (-100, 100), (-266, 266)]

# --- Our fixes (see the docstring) ---------------------------------------------------
MASS = [13.0] + MASS_PUB[1:]
I_USED = [list(x) for x in I_PUB]
I_USED[0] = [0.18, 0.35, 0.18]
I_USED[2] = [0.066, 0.086, 0.0205]

# Not in the toolbox model: nominal placeholders so every <limit> is complete. Unused by
# the dynamics.
EFFORT = [100.0, 200.0, 100.0, 25.0, 25.0, 25.0]
VELOCITY = [3.0] * 6

LINKS = [f"link{i}" for i in range(1, 7)]
JOINTS = [f"joint{i}" for i in range(1, 7)]


def exact_cs(angle):
    """cos/sin, exact for multiples of pi/2."""
    k = angle / (PI / 2)
    if abs(k - round(k)) < 1e-12:
        return [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][int(round(k)) % 4]
    return math.cos(angle), math.sin(angle)


def rotx(angle):
    c, s = exact_cs(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def clean(x):
    x = float(x)
    return 0.0 if x == 0.0 else x  # no "-0.0"


def fmt(v):
    return " ".join(repr(clean(x)) for x in v)


def check_physical(i):
    ev = np.sort(np.array(I_USED[i]))
    if MASS[i] <= 0 or ev[0] <= 0 or ev[2] >= ev[0] + ev[1]:
        sys.exit(f"{LINKS[i]}: not physical (mass {MASS[i]}, principal moments {ev})")


def link_params():
    """(mass, com, inertia about com) of links 1..6 in URDF link frames."""
    out = []
    for i in range(6):
        check_physical(i)
        R = rotx(ALPHA[i])
        c = np.array([A[i], 0.0, D[i]]) + R @ np.array(COM_DH[i])
        I = R @ np.diag(I_USED[i]) @ R.T
        out.append((MASS[i], c, I))
    return out


def urdf_text():
    s = ['<?xml version="1.0"?>\n']
    s.append(
        "<!--\n"
        "  Unimation PUMA 560, 6 revolute joints, standard DH chain, fixed base.\n"
        "  GENERATED by scripts/make_puma560_urdf.py - edit that script, not this file.\n"
        "\n"
        "  Source: P. Corke, Robotics Toolbox for MATLAB, mdl_puma560.m (standard DH,\n"
        "  \"params of 8/95\"; P. Corke, B. Armstrong-Helouvry, \"A search for consensus among\n"
        "  model parameters reported for the PUMA 560 robot\", ICRA 1994), inertial data of\n"
        "  B. Armstrong, O. Khatib, J. Burdick, \"The Explicit Dynamic Model and Inertial\n"
        "  Parameters of the PUMA 560 Arm\", ICRA 1986:\n"
        f"    d     = {D}\n"
        f"    a     = {A}\n"
        f"    alpha = {ALPHA_TXT}\n"
        f"    m     = {MASS_PUB} kg\n"
        f"    r (com, DH frame i) = {COM_DH} m\n"
        f"    I (Ixx Iyy Izz about com, DH frame i) = {I_PUB} kg m^2\n"
        f"    qlim  = {[list(q) for q in QLIM_DEG]} deg\n"
        "  Motor inertia, gear ratios and friction of the toolbox model are not included.\n"
        "\n"
        "  FIXES for physical rigid bodies (mass > 0, positive definite, triangle inequality):\n"
        "  - link1: m1 = 0 and I1 = (0, 0.35, 0) in the toolbox (AKB give no m1; only the\n"
        "    moment about the joint-1 axis, y1, matters for a fixed base). Used: nominal\n"
        "    m1 = 13.0 kg, com on the joint-1 axis (origin of DH frame 1), I1 = (0.18, 0.35,\n"
        "    0.18): Iyy = 0.35 kept, Ixx + Izz >= 0.35 needed by the triangle inequality.\n"
        "    No joint torque changes (only the joint-1 wrench gains the link's weight).\n"
        "  - link3: (0.066, 0.086, 0.0125) violates the triangle inequality (0.086 > 0.0785).\n"
        "    Used: Izz (about z3, the forearm axis) raised from 0.0125 to 0.0205 (bound 0.020);\n"
        "    Iyy (about the joint-3 axis) and Ixx kept.\n"
        "  Links 2, 4, 5, 6 as published.\n"
        "\n"
        "  Frames reproduce the standard DH chain exactly: joint i turns about z of DH frame\n"
        "  i-1; the URDF frame of link i is DH frame i-1 turned by theta_i, so joint i+1's\n"
        "  origin is Tz(d_i) Tx(a_i) Rx(alpha_i) = xyz (a_i 0 d_i), rpy (alpha_i 0 0); the\n"
        "  fixed, massless `flange` is DH frame 6. Centres of mass and inertias are\n"
        "  transformed exactly from DH frame i into these link frames.\n"
        f"  Limits: qlim above; effort {EFFORT} N m and velocity {VELOCITY[0]} rad/s are\n"
        "  nominal placeholders (not in the toolbox model; unused by the dynamics).\n"
        "  Forward kinematics at q = 0: flange at (a2 + a3, -d3, d4) = (0.4521, -0.15005,\n"
        "  0.4318), rotation identity (the toolbox's p560.fkine(qz)).\n"
        "-->\n")
    s.append('<robot name="puma560">\n')
    s.append('  <link name="base_link"/>\n')
    params = link_params()
    parent = "base_link"
    for i in range(6):
        if i == 0:
            xyz, rpy = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        else:
            xyz, rpy = [A[i - 1], 0.0, D[i - 1]], [ALPHA[i - 1], 0.0, 0.0]
        lo, hi = QLIM_DEG[i]
        s.append(f'  <joint name="{JOINTS[i]}" type="revolute">\n'
                 f'    <parent link="{parent}"/>\n'
                 f'    <child link="{LINKS[i]}"/>\n'
                 f'    <origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/>\n'
                 f'    <axis xyz="0 0 1"/>\n'
                 f'    <limit lower="{repr(lo * DEG)}" upper="{repr(hi * DEG)}" '
                 f'effort="{repr(EFFORT[i])}" velocity="{repr(VELOCITY[i])}"/>\n'
                 f'  </joint>\n')
        m, c, I = params[i]
        s.append(f'  <link name="{LINKS[i]}">\n'
                 f'    <inertial>\n'
                 f'      <origin xyz="{fmt(c)}" rpy="0 0 0"/>\n'
                 f'      <mass value="{repr(float(m))}"/>\n'
                 f'      <inertia ixx="{repr(clean(I[0, 0]))}" ixy="{repr(clean(I[0, 1]))}" '
                 f'ixz="{repr(clean(I[0, 2]))}" iyy="{repr(clean(I[1, 1]))}" '
                 f'iyz="{repr(clean(I[1, 2]))}" izz="{repr(clean(I[2, 2]))}"/>\n'
                 f'    </inertial>\n'
                 f'  </link>\n')
        parent = LINKS[i]
    s.append('  <joint name="flange_fixed_joint" type="fixed">\n'
             '    <parent link="link6"/>\n'
             '    <child link="flange"/>\n'
             f'    <origin xyz="{fmt([A[5], 0.0, D[5]])}" rpy="{fmt([ALPHA[5], 0.0, 0.0])}"/>\n'
             '  </joint>\n')
    s.append('  <link name="flange"/>\n')
    s.append('</robot>\n')
    return "".join(s)


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-o", "--output", default=os.path.join(root, "robots", "puma560", "puma560.urdf"),
                    help="output path, '-' for stdout")
    args = ap.parse_args()
    text = urdf_text()
    if args.output == "-":
        sys.stdout.write(text)
    else:
        os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
        with open(args.output, "w") as f:
            f.write(text)
        print(f"wrote {os.path.relpath(args.output)}")


if __name__ == "__main__":
    main()
