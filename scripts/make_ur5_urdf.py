#!/usr/bin/env python3
"""Generate robots/ur5/ur5.urdf from Universal Robots' published DH and dynamics data.

Usage (any python with numpy, e.g. the Pinocchio oracle venv; works from any directory):
    PY=${PIN_HOME:-$HOME/.cache/pinocchio-oracle}/.venv/bin/python
    $PY scripts/make_ur5_urdf.py            # writes robots/ur5/ur5.urdf
    $PY scripts/make_ur5_urdf.py -o -       # prints to stdout

Source: Universal Robots, "DH parameters for calculations of kinematics and dynamics"
(support article, table for the UR5 CB3): standard (distal) Denavit-Hartenberg
parameters d, a, alpha, link masses, and centres of mass expressed in the DH frame of
each link. UR does not publish inertia tensors for the CB-series UR5, so every link's
inertia about its centre of mass is a homogeneous solid cylinder (dimensions in
CYLINDERS below).

Frames. Standard DH: frame i = frame (i-1) * Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i),
joint i rotates about z of DH frame i-1. The URDF link frame of link i sits at the
proximal joint: L_i = F_(i-1) * Rz(theta_i), so
    joint 1 origin (base_link -> shoulder_link)  = identity,
    joint i+1 origin (link i -> link i+1)        = Tz(d_i) Tx(a_i) Rx(alpha_i)
                                                 = xyz (a_i, 0, d_i), rpy (alpha_i, 0, 0),
    tool0 fixed joint (wrist_3_link -> tool0)    = Tz(d_6) Tx(a_6) Rx(alpha_6),
so tool0 coincides with DH frame 6 and the model is exactly the DH chain. Since
F_i = L_i * D_i with D_i = Tz(d_i) Tx(a_i) Rx(alpha_i), a centre of mass c given in DH
frame i is D_i c = (a_i, 0, d_i) + Rx(alpha_i) c in the URDF link frame, and an inertia
I (DH-frame axes) is Rx(alpha_i) I Rx(alpha_i)^T. Rotations by multiples of pi/2 are
built exactly (entries 0, +-1), so the numbers carry no 1e-17 noise.
"""
import argparse
import math
import os
import sys

import numpy as np

PI = math.pi

# --- Universal Robots UR5 (CB3) published data --------------------------------------
D = [0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823]
A = [0.0, -0.425, -0.39225, 0.0, 0.0, 0.0]
ALPHA = [PI / 2, 0.0, 0.0, PI / 2, -PI / 2, 0.0]
MASS = [3.7, 8.393, 2.275, 1.219, 1.219, 0.1879]
COM_DH = [  # centre of mass of link i in DH frame i
    [0.0, -0.02561, 0.00193],
    [0.2125, 0.0, 0.11336],
    [0.15, 0.0, 0.0265],
    [0.0, -0.0018, 0.01634],
    [0.0, 0.0018, 0.01634],
    [0.0, 0.0, -0.001159],
]

# --- Cylinder approximation of each link's inertia (our choice, not UR data) ----------
# (radius m, length m, cylinder axis in DH frame i)
CYLINDERS = [
    (0.06, 0.15, "y"),      # shoulder: housing along the joint-1 (base) axis = y1
    (0.06, 0.425, "x"),     # upper arm: tube along x2 (shoulder -> elbow, length |a2|)
    (0.06, 0.39225, "x"),   # forearm: tube along x3 (elbow -> wrist 1, length |a3|)
    (0.0375, 0.12, "z"),    # wrist 1: housing along z4 = joint-5 axis (75 mm wrist)
    (0.0375, 0.12, "z"),    # wrist 2: housing along z5 = joint-6 axis
    (0.0375, 0.0345, "z"),  # wrist 3: flange disc along z6 = joint-6 axis
]

LINKS = ["shoulder_link", "upper_arm_link", "forearm_link",
         "wrist_1_link", "wrist_2_link", "wrist_3_link"]
JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
          "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
EFFORT = [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]
VELOCITY = 3.15
LIMIT = 2 * PI

# Fixed base (ignored by dynamics: it does not move), same cylinder rule.
BASE = dict(mass=4.0, com=[0.0, 0.0, 0.0], radius=0.075, length=0.038)
# tool0 = DH frame 6 (flange). A 0.1 kg flange adapter disc just outside the flange so
# that fixed-joint merging into wrist_3_link is exercised.
TOOL0 = dict(mass=0.1, com=[0.0, 0.0, 0.005], radius=0.0315, length=0.01)
# ee_link: massless frame 0.05 m along the tool z axis (a TCP), no <inertial>.
EE_XYZ = [0.0, 0.0, 0.05]


def exact_cs(angle):
    """cos/sin, exact for multiples of pi/2 (matches what a careful parser does)."""
    k = angle / (PI / 2)
    if abs(k - round(k)) < 1e-12:
        return [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][int(round(k)) % 4]
    return math.cos(angle), math.sin(angle)


def rotx(angle):
    c, s = exact_cs(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def cylinder(mass, radius, length, axis):
    """Inertia about the centre of a solid cylinder, axis one of x, y, z."""
    i_ax = 0.5 * mass * radius ** 2
    i_tr = mass * (3.0 * radius ** 2 + length ** 2) / 12.0
    d = {"x": [i_ax, i_tr, i_tr], "y": [i_tr, i_ax, i_tr], "z": [i_tr, i_tr, i_ax]}[axis]
    return np.diag(d)


def clean(x):
    x = float(x)
    return 0.0 if x == 0.0 else x  # no "-0.0"


def fmt(v):
    return " ".join(repr(clean(x)) for x in v)


def inertial_xml(mass, com, I, indent="    "):
    return (f"{indent}<inertial>\n"
            f"{indent}  <origin xyz=\"{fmt(com)}\" rpy=\"0 0 0\"/>\n"
            f"{indent}  <mass value=\"{repr(float(mass))}\"/>\n"
            f"{indent}  <inertia ixx=\"{repr(clean(I[0, 0]))}\" ixy=\"{repr(clean(I[0, 1]))}\" "
            f"ixz=\"{repr(clean(I[0, 2]))}\" iyy=\"{repr(clean(I[1, 1]))}\" "
            f"iyz=\"{repr(clean(I[1, 2]))}\" izz=\"{repr(clean(I[2, 2]))}\"/>\n"
            f"{indent}</inertial>\n")


def link_params():
    """(mass, com, inertia about com) of links 1..6 in URDF link frames."""
    out = []
    for i in range(6):
        R = rotx(ALPHA[i])
        t = np.array([A[i], 0.0, D[i]])
        c = t + R @ np.array(COM_DH[i])
        r, l, ax = CYLINDERS[i]
        I = R @ cylinder(MASS[i], r, l, ax) @ R.T
        out.append((MASS[i], c, I))
    return out


def urdf_text():
    s = []
    s.append('<?xml version="1.0"?>\n')
    s.append("<!--\n"
             "  Universal Robots UR5 (CB-series, CB3) as a 6-DOF serial chain.\n"
             "  GENERATED by scripts/make_ur5_urdf.py - edit that script, not this file.\n"
             "\n"
             "  Sources: Universal Robots, \"DH parameters for calculations of kinematics and\n"
             "  dynamics\" (support article), UR5 CB3 table: standard DH parameters\n"
             f"    d     = {D}\n"
             f"    a     = {A}\n"
             "    alpha = [pi/2, 0, 0, pi/2, -pi/2, 0]\n"
             f"    mass  = {MASS} kg\n"
             f"    com (DH frame i) = {COM_DH} m\n"
             "  Joint frames reproduce the standard DH chain exactly: joint i rotates about z of\n"
             "  DH frame i-1; the URDF frame of link i is DH frame i-1 rotated by theta_i, and the\n"
             "  origin of joint i+1 in it is Tz(d_i) Tx(a_i) Rx(alpha_i) = xyz (a_i 0 d_i),\n"
             "  rpy (alpha_i 0 0). tool0 coincides with DH frame 6. The published centres of\n"
             "  mass (DH frame i) are transformed exactly into these link frames.\n"
             "\n"
             "  INERTIAS ARE AN APPROXIMATION: UR publishes no inertia tensors for the CB UR5.\n"
             "  Each link's inertia about its centre of mass is that of a homogeneous solid\n"
             "  cylinder of the link's mass, principal axes along the DH frame axes, with:\n")
    names = ["shoulder ", "upper arm", "forearm  ", "wrist 1  ", "wrist 2  ", "wrist 3  "]
    axdesc = ["y1 (joint-1 axis)", "x2 (along the arm)", "x3 (along the arm)",
              "z4 (joint-5 axis)", "z5 (joint-6 axis)", "z6 (joint-6 axis)"]
    for i in range(6):
        r, l, _ = CYLINDERS[i]
        s.append(f"    {names[i]}: radius {r} m, length {l} m, axis {axdesc[i]}\n")
    s.append("  (I_axis = m r^2 / 2, I_transverse = m (3 r^2 + l^2) / 12.)\n"
             f"  base_link (fixed, ignored by dynamics): {BASE['mass']} kg cylinder r {BASE['radius']} m,"
             f" l {BASE['length']} m, axis z.\n"
             f"  tool0: {TOOL0['mass']} kg flange-adapter disc r {TOOL0['radius']} m, l {TOOL0['length']} m,"
             f" axis z, com {TOOL0['com']} (merged into wrist_3_link by fixed-joint merging).\n"
             f"  ee_link: massless frame (no inertial) at {EE_XYZ} in tool0.\n"
             "  Limits: +-2 pi rad, 3.15 rad/s, effort [150 150 150 28 28 28] N m.\n"
             "  Forward kinematics at q = 0: tool0 at (a2+a3, -(d4+d6), d1-d5)\n"
             "  = (-0.81725, -0.19145, -0.005491) in base_link.\n"
             "-->\n")
    s.append('<robot name="ur5">\n')
    Ib = cylinder(BASE["mass"], BASE["radius"], BASE["length"], "z")
    s.append('  <link name="base_link">\n' + inertial_xml(BASE["mass"], BASE["com"], Ib) + "  </link>\n")
    params = link_params()
    parent = "base_link"
    for i in range(6):
        if i == 0:
            xyz, rpy = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        else:
            xyz, rpy = [A[i - 1], 0.0, D[i - 1]], [ALPHA[i - 1], 0.0, 0.0]
        s.append(f'  <joint name="{JOINTS[i]}" type="revolute">\n'
                 f'    <parent link="{parent}"/>\n'
                 f'    <child link="{LINKS[i]}"/>\n'
                 f'    <origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/>\n'
                 f'    <axis xyz="0 0 1"/>\n'
                 f'    <limit lower="{repr(-LIMIT)}" upper="{repr(LIMIT)}" effort="{repr(EFFORT[i])}" velocity="{repr(VELOCITY)}"/>\n'
                 f'  </joint>\n')
        m, c, I = params[i]
        s.append(f'  <link name="{LINKS[i]}">\n' + inertial_xml(m, c, I) + "  </link>\n")
        parent = LINKS[i]
    It = cylinder(TOOL0["mass"], TOOL0["radius"], TOOL0["length"], "z")
    s.append('  <joint name="wrist_3_link-tool0_fixed_joint" type="fixed">\n'
             '    <parent link="wrist_3_link"/>\n'
             '    <child link="tool0"/>\n'
             f'    <origin xyz="{fmt([A[5], 0.0, D[5]])}" rpy="{fmt([ALPHA[5], 0.0, 0.0])}"/>\n'
             '  </joint>\n')
    s.append('  <link name="tool0">\n' + inertial_xml(TOOL0["mass"], TOOL0["com"], It) + "  </link>\n")
    s.append('  <joint name="ee_fixed_joint" type="fixed">\n'
             '    <parent link="tool0"/>\n'
             '    <child link="ee_link"/>\n'
             f'    <origin xyz="{fmt(EE_XYZ)}" rpy="0 0 0"/>\n'
             '  </joint>\n')
    s.append('  <link name="ee_link"/>\n')
    s.append("</robot>\n")
    return "".join(s)


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-o", "--output", default=os.path.join(root, "robots", "ur5", "ur5.urdf"),
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
