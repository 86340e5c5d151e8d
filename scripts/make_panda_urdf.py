#!/usr/bin/env python3
"""Generate robots/panda/panda.urdf: Franka Emika Panda, kinematics from Franka's
modified DH table, dynamics from Gaz et al. (2019).

Usage (any python with numpy, e.g. the Pinocchio oracle venv; works from any directory):
    PY=${PIN_HOME:-$HOME/.cache/pinocchio-oracle}/.venv/bin/python
    $PY scripts/make_panda_urdf.py            # writes robots/panda/panda.urdf
    $PY scripts/make_panda_urdf.py -o -       # prints to stdout

Sources
- Kinematics and limits: Franka Emika, "Robot and interface specifications" /
  "Control parameters" (frankaemika.github.io/docs/control_parameters.html): modified
  (Craig) DH parameters a_(i-1), d_i, alpha_(i-1) of joints 1..7 plus the flange
  (d = 0.107), joint position limits, velocity limits and torque limits of the Panda
  (FE-3). The same table is in Load_Franka_DH.m of the authors' repository below.
- Dynamics: C. Gaz, M. Cognetti, A. Oliva, P. Robuffo Giordano, A. De Luca, "Dynamic
  Identification of the Franka Emika Panda Robot With Retrieval of Feasible Parameters
  Using Penalty-Based Optimization", IEEE RA-L 4(4):4147-4154, 2019, supplementary
  material tables VIII and IX, as transcribed in the authors' repository
  github.com/marcocognetti/FrankaEmikaPandaDynModel (matlab/ConvertDynPars2VREP/
  DynPars2VREP.m: masses m, centres of mass CoM_l, barycentric inertias Il) and in
  franka_ros (franka_description/robots/common/inertial.yaml, "values are from the
  identification results published in" that paper). Each link's centre of mass and
  inertia tensor (about the centre of mass, axes parallel to the link frame) are given
  in the link frame of the modified DH convention, which is exactly the URDF frame of
  link i used here, so they are written unchanged.

Where the two transcriptions differ:
- link 1 centre of mass z: DynPars2VREP.m has 0, franka_ros and JeanElsner/panda_mujoco
  (whose author took the values from the supplementary PDF) -0.04762. We use -0.04762.
  (The PDF itself could not be read here.) For a fixed
  base it does not change any joint torque (link 1 only turns about its own z axis);
  it does change Pinocchio's joint-1 wrench f_1 (moments about x, y).
- link 5 centre of mass x: both have -0.011953 (an early panda_mujoco had +, a typo
  acknowledged by its author). We use -0.011953.

Checked: every tensor is positive definite and satisfies the triangle inequalities as
published (smallest margin: link 2, lambda_1 + lambda_2 - lambda_3 = 1.7e-6 kg m^2),
so no value was changed.

Frames: modified DH, T_(i-1,i) = Rx(alpha_(i-1)) Tx(a_(i-1)) Rz(theta_i) Tz(d_i). The
URDF origin of joint i is therefore xyz (a_(i-1), -sin(alpha_(i-1)) d_i,
cos(alpha_(i-1)) d_i), rpy (alpha_(i-1), 0, 0), axis z; sines and cosines of the
multiples of pi/2 are taken exactly, so translations carry no 1e-17 noise.
"""
import math
import sys

import numpy as np

from urdf_writer import exact_cs, joint_xml, link_xml, main

PI = math.pi

# --- Franka Emika Panda modified DH (Craig) parameters, joints 1..7 then flange ----
A = [0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088, 0.0]          # a_(i-1), m
D = [0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0, 0.107]           # d_i, m
ALPHA = [0.0, -PI / 2, PI / 2, PI / 2, -PI / 2, PI / 2, PI / 2, 0.0]  # alpha_(i-1)
ALPHA_TXT = ["0", "-pi/2", "pi/2", "pi/2", "-pi/2", "pi/2", "pi/2", "0"]

# --- Franka datasheet limits (Panda, FE-3) ------------------------------------------
Q_MIN = [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973]
Q_MAX = [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973]
DQ_MAX = [2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100]
TAU_MAX = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]

# --- Gaz et al. 2019, identified feasible parameters (supplementary tables VIII, IX) --
MASS = [4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522]  # kg
COM = [  # centre of mass in link frame i, m
    [3.875e-03, 2.081e-03, -4.762e-02],
    [-3.141e-03, -2.872e-02, 3.495e-03],
    [2.7518e-02, 3.9252e-02, -6.6502e-02],
    [-5.317e-02, 1.04419e-01, 2.7454e-02],
    [-1.1953e-02, 4.1065e-02, -3.8437e-02],
    [6.0149e-02, -1.4117e-02, -1.0517e-02],
    [1.0517e-02, -4.252e-03, 6.1597e-02],
]
INERTIA = [  # about the centre of mass, link-frame axes: Ixx, Ixy, Ixz, Iyy, Iyz, Izz (kg m^2)
    [7.0337e-01, -1.3900e-04, 6.7720e-03, 7.0661e-01, 1.9169e-02, 9.1170e-03],
    [7.9620e-03, -3.9250e-03, 1.0254e-02, 2.8110e-02, 7.0400e-04, 2.5995e-02],
    [3.7242e-02, -4.7610e-03, -1.1396e-02, 3.6155e-02, -1.2805e-02, 1.0830e-02],
    [2.5853e-02, 7.7960e-03, -1.3320e-03, 1.9552e-02, 8.6410e-03, 2.8323e-02],
    [3.5549e-02, -2.1170e-03, -4.0370e-03, 2.9474e-02, 2.2900e-04, 8.6270e-03],
    [1.9640e-03, 1.0900e-04, -1.1580e-03, 4.3540e-03, 3.4100e-04, 5.4330e-03],
    [1.2516e-02, -4.2800e-04, -1.1960e-03, 1.0027e-02, -7.4100e-04, 4.8150e-03],
]


def tensor(p):
    xx, xy, xz, yy, yz, zz = p
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def check_physical(i):
    ev = np.linalg.eigvalsh(tensor(INERTIA[i]))
    margin = ev[0] + ev[1] - ev[2]
    if MASS[i] <= 0 or ev[0] <= 0 or margin <= 0:
        sys.exit(f"panda_link{i + 1}: not physical (mass {MASS[i]}, principal moments {ev})")
    return ev, margin


def origin(i):
    """xyz, rpy of joint i (0-based, 7 = flange) in the frame of link i."""
    c, s = exact_cs(ALPHA[i])
    return [A[i], -s * D[i], c * D[i]], [ALPHA[i], 0.0, 0.0]


def urdf_text():
    margins = [check_physical(i)[1] for i in range(7)]
    s = ['<?xml version="1.0"?>\n']
    s.append(
        "<!--\n"
        "  Franka Emika Panda (FE-3), 7 revolute joints, fixed base, flange panda_link8.\n"
        "  GENERATED by scripts/make_panda_urdf.py - edit that script, not this file.\n"
        "\n"
        "  Sources\n"
        "  - Kinematics, limits: Franka Emika, robot and interface specifications / control\n"
        "    parameters (frankaemika.github.io/docs/control_parameters.html), modified (Craig)\n"
        "    DH parameters, T = Rx(alpha_(i-1)) Tx(a_(i-1)) Rz(q_i) Tz(d_i):\n"
        f"      a_(i-1)     = {A[:7]}, flange 0\n"
        f"      d_i         = {D[:7]}, flange 0.107\n"
        f"      alpha_(i-1) = [{', '.join(ALPHA_TXT[:7])}], flange 0\n"
        f"      q_min  = {Q_MIN} rad\n"
        f"      q_max  = {Q_MAX} rad\n"
        f"      dq_max = {DQ_MAX} rad/s\n"
        f"      tau_max = {TAU_MAX} N m\n"
        "  - Dynamics: C. Gaz, M. Cognetti, A. Oliva, P. Robuffo Giordano, A. De Luca,\n"
        "    \"Dynamic Identification of the Franka Emika Panda Robot With Retrieval of\n"
        "    Feasible Parameters Using Penalty-Based Optimization\", IEEE RA-L 4(4),\n"
        "    pp. 4147-4154, 2019, supplementary material tables VIII and IX, as transcribed in\n"
        "    github.com/marcocognetti/FrankaEmikaPandaDynModel\n"
        "    (matlab/ConvertDynPars2VREP/DynPars2VREP.m) and in franka_ros\n"
        "    (franka_description/robots/common/inertial.yaml). Masses, centres of mass and\n"
        "    inertia tensors about the centre of mass are given in the modified-DH link\n"
        "    frames, which are the URDF link frames here, and are written unchanged.\n"
        "    Friction parameters of the paper are not included (URDF rnea ignores them).\n"
        "  Transcriptions differ on the link-1 centre of mass z: DynPars2VREP.m has 0;\n"
        "  franka_ros and JeanElsner/panda_mujoco (whose author took the values from the\n"
        "  supplementary PDF) have -0.04762, which is used. It changes no joint torque of\n"
        "  this fixed-base arm, only the x/y moments of the joint-1 wrench.\n"
        "  Every inertia is positive definite and satisfies the triangle inequalities as\n"
        "  published (smallest margin lambda1 + lambda2 - lambda3: "
        f"{min(margins):.2e} kg m^2, link 2);\n"
        "  no published value was changed.\n"
        "  panda_link0 (fixed base) carries no inertial: it does not move. panda_link8 is the\n"
        "  flange frame (massless, fixed joint d = 0.107 along z7).\n"
        "  Forward kinematics at q = 0: panda_link8 at (0.088, 0, 0.926), rotation\n"
        "  diag(1, -1, -1) in panda_link0.\n"
        "-->\n")
    s.append('<robot name="panda">\n')
    s.append('  <link name="panda_link0"/>\n')
    for i in range(7):
        xyz, rpy = origin(i)
        s.append(joint_xml(f"panda_joint{i + 1}", "revolute", f"panda_link{i}", f"panda_link{i + 1}", xyz, rpy,
                           "0 0 1", (Q_MIN[i], Q_MAX[i], TAU_MAX[i], DQ_MAX[i])))
        s.append(link_xml(f"panda_link{i + 1}", MASS[i], COM[i], tensor(INERTIA[i])))
    xyz, rpy = origin(7)
    s.append(joint_xml("panda_joint8", "fixed", "panda_link7", "panda_link8", xyz, rpy))
    s.append('  <link name="panda_link8"/>\n')
    s.append('</robot>\n')
    return "".join(s)


if __name__ == "__main__":
    main(__doc__, urdf_text, "robots/panda/panda.urdf")
