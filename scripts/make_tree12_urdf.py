#!/usr/bin/env python3
"""Generate tests/fixtures/tree12.urdf: an invented branched test robot with 12 moving
joints (a torso yaw, two 4-DOF arms, a 3-DOF head), not a commercial product.

Usage (any python with numpy, e.g. the Pinocchio oracle venv; works from any directory):
    PY=${PIN_HOME:-$HOME/.cache/pinocchio-oracle}/.venv/bin/python
    $PY scripts/make_tree12_urdf.py            # writes tests/fixtures/tree12.urdf
    $PY scripts/make_tree12_urdf.py -o -       # prints to stdout

What it exercises: revolute, continuous and prismatic joints; three branches off the
torso; general rpy joint origins; non-axis-aligned axes (revolutes neck_pitch and
l_shoulder_roll, prismatic camera_slide); negative axes (-x, -y, -z); a fixed joint in the middle of the right arm whose (massive)
child link is merged into the upper arm and whose child joint then hangs off the merged
frame; full (non-diagonal) inertia tensors everywhere; and sibling joints declared in a
different order than their names sort in (urdfdom, and so Pinocchio, orders siblings
by joint name).

Inertias: each link is a homogeneous box (dimensions below) whose principal axes are
turned by a fixed rpy relative to the link frame, giving full tensors that are
physical by construction; the tensors are rounded to 6 significant digits and
re-checked (positive definite, triangle inequalities with margin).
"""
from urdf_writer import box_inertia, joint_xml, link_xml, main

# Links: name -> (mass kg, com xyz in link frame, box dims (x, y, z) m, box rpy in link frame)
LINKS = {
    "base_link":        (6.0, [0.0, 0.0, 0.12], [0.30, 0.30, 0.24], [0.0, 0.0, 0.0]),
    "torso_link":       (9.5, [0.012, -0.004, 0.24], [0.22, 0.32, 0.46], [0.03, -0.02, 0.05]),
    "l_shoulder_link":  (1.4, [0.004, 0.035, 0.002], [0.09, 0.10, 0.09], [0.2, 0.1, -0.15]),
    "l_upper_arm_link": (2.1, [0.008, 0.006, -0.13], [0.08, 0.085, 0.28], [0.05, -0.08, 0.3]),
    "l_forearm_link":   (1.3, [-0.004, 0.003, -0.11], [0.07, 0.065, 0.24], [-0.06, 0.04, 0.7]),
    "l_hand_link":      (0.55, [0.006, -0.002, -0.045], [0.05, 0.09, 0.11], [0.1, 0.2, -0.4]),
    "r_shoulder_link":  (1.4, [0.004, -0.035, 0.002], [0.09, 0.10, 0.09], [-0.2, 0.1, 0.15]),
    "r_upper_arm_link": (2.0, [0.006, -0.005, -0.12], [0.08, 0.085, 0.26], [-0.05, -0.07, -0.25]),
    "r_bracket_link":   (0.35, [0.01, 0.0, -0.015], [0.06, 0.08, 0.04], [0.3, -0.2, 0.1]),
    "r_forearm_link":   (1.1, [0.003, -0.002, -0.12], [0.065, 0.06, 0.25], [0.07, 0.03, -0.5]),
    "neck_link":        (0.5, [0.0, 0.002, 0.035], [0.06, 0.06, 0.08], [0.0, 0.1, 0.4]),
    "head_link":        (1.8, [0.03, 0.0, 0.06], [0.16, 0.18, 0.15], [0.05, -0.1, 0.12]),
    "camera_link":      (0.25, [0.012, 0.0, 0.004], [0.04, 0.12, 0.035], [0.0, 0.15, -0.2]),
}

# Joints in declaration order: name, type, parent, child, xyz, rpy, axis, (lower, upper), effort, velocity.
# Declared on purpose as: torso, neck/head branch, right arm, left arm (names sort l_, neck_, r_).
JOINTS = [
    ("torso_yaw", "revolute", "base_link", "torso_link",
     [0.0, 0.0, 0.24], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], (-2.6, 2.6), 120.0, 1.5),
    ("neck_yaw", "continuous", "torso_link", "neck_link",
     [0.02, 0.0, 0.50], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], None, 8.0, 3.0),
    ("neck_pitch", "revolute", "neck_link", "head_link",
     [0.0, 0.0, 0.07], [0.0, 0.0, 0.3], [0.0, 0.8, 0.6], (-0.7, 0.9), 8.0, 3.0),
    ("camera_slide", "prismatic", "head_link", "camera_link",
     [0.08, 0.0, 0.06], [0.0, -0.15, 0.0], [0.28, 0.96, 0.0], (-0.03, 0.03), 20.0, 0.2),
    ("r_shoulder_pitch", "revolute", "torso_link", "r_shoulder_link",
     [0.0, -0.19, 0.40], [-0.2618, 0.0, 0.0], [0.0, 1.0, 0.0], (-2.5, 2.5), 60.0, 2.0),
    ("r_shoulder_roll", "revolute", "r_shoulder_link", "r_upper_arm_link",
     [0.0, -0.06, 0.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0], (-0.3, 2.8), 60.0, 2.0),
    ("r_elbow_bracket", "fixed", "r_upper_arm_link", "r_bracket_link",
     [0.0, 0.0, -0.26], [0.05, 0.25, -0.1], None, None, None, None),
    ("r_elbow", "revolute", "r_bracket_link", "r_forearm_link",
     [0.015, 0.0, -0.03], [0.0, 0.0, 0.0], [0.0, -1.0, 0.0], (-2.4, 0.1), 40.0, 2.5),
    ("r_forearm_extend", "prismatic", "r_forearm_link", "r_hand_link",
     [0.0, 0.0, -0.12], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], (0.0, 0.12), 150.0, 0.3),
    ("l_shoulder_pitch", "revolute", "torso_link", "l_shoulder_link",
     [0.0, 0.19, 0.40], [0.2618, 0.0, 0.0], [0.0, 1.0, 0.0], (-2.5, 2.5), 60.0, 2.0),
    ("l_shoulder_roll", "revolute", "l_shoulder_link", "l_upper_arm_link",
     [0.0, 0.06, 0.0], [0.0, 0.0, 0.0], [0.8, 0.0, 0.6], (-0.3, 2.8), 60.0, 2.0),
    ("l_elbow", "revolute", "l_upper_arm_link", "l_forearm_link",
     [0.02, 0.0, -0.28], [0.1, -0.3, 0.2], [0.0, 1.0, 0.0], (-2.4, 0.1), 40.0, 2.5),
    ("l_wrist_roll", "continuous", "l_forearm_link", "l_hand_link",
     [0.0, 0.0, -0.24], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], None, 10.0, 4.0),
]
# r_forearm_extend moves a right hand; it reuses the left hand's data mirrored.
LINKS["r_hand_link"] = (0.55, [0.006, 0.002, -0.045], [0.05, 0.09, 0.11], [-0.1, 0.2, 0.4])

LINK_ORDER = ["base_link", "torso_link", "neck_link", "head_link", "camera_link",
              "r_shoulder_link", "r_upper_arm_link", "r_bracket_link", "r_forearm_link",
              "r_hand_link", "l_shoulder_link", "l_upper_arm_link", "l_forearm_link", "l_hand_link"]


def inertia(name):
    m, _, dims, rpy = LINKS[name]
    return box_inertia(name, m, dims, rpy)


def tree_joint_xml(j):
    name, typ, parent, child, xyz, rpy, axis, lim, effort, vel = j
    if typ in ("revolute", "prismatic"):
        limit = (lim[0], lim[1], effort, vel)
    elif typ == "continuous":
        limit = (effort, vel)
    else:
        limit = None
    return joint_xml(name, typ, parent, child, xyz, rpy, axis, limit)


HEADER = """<?xml version="1.0"?>
<!--
  tree12: an invented branched test robot (not a commercial product), 12 moving joints,
  fixed base. GENERATED by scripts/make_tree12_urdf.py - edit that script, not this file.

    base_link (fixed base, ignored by dynamics)
     `- torso_yaw        revolute  z                      -> torso_link
        +- neck_yaw      continuous z                     -> neck_link
        |  `- neck_pitch revolute  axis (0, 0.8, 0.6), rpy -> head_link
        |     `- camera_slide prismatic axis (0.28, 0.96, 0), rpy -> camera_link
        +- r_shoulder_pitch revolute y, rpy               -> r_shoulder_link
        |  `- r_shoulder_roll revolute -x                 -> r_upper_arm_link
        |     `- r_elbow_bracket FIXED, rpy               -> r_bracket_link (0.35 kg, merged
        |        |                                           into r_upper_arm_link)
        |        `- r_elbow   revolute -y                 -> r_forearm_link
        |           `- r_forearm_extend prismatic -z, 0..0.12 m -> r_hand_link
        `- l_shoulder_pitch revolute y, rpy               -> l_shoulder_link
           `- l_shoulder_roll revolute axis (0.8, 0, 0.6) -> l_upper_arm_link
              `- l_elbow  revolute y, general rpy         -> l_forearm_link
                 `- l_wrist_roll continuous z             -> l_hand_link

  Declared in the order torso, head branch, right arm, left arm; urdfdom (and so
  Pinocchio) orders siblings by joint name, so Pinocchio's depth-first joint order is
  torso_yaw, l_shoulder_pitch, l_shoulder_roll, l_elbow, l_wrist_roll, neck_yaw,
  neck_pitch, camera_slide, r_shoulder_pitch, r_shoulder_roll, r_elbow,
  r_forearm_extend; parents 0, 1, 2, 3, 4, 1, 6, 7, 1, 9, 10, 11.
  nv = 12, Pinocchio nq = 14 (two continuous joints).

  Masses (total moving {total_mass} kg, about a small humanoid upper body) and centres of mass
  are hand-picked. Each inertia is a homogeneous box of the link's mass, turned by a
  fixed rpy in the link frame (full tensors), rounded to 6 significant digits; every
  tensor is positive definite and satisfies the triangle inequalities.
-->
<robot name="tree12">
"""


def urdf_text():
    total = sum(m for k, (m, _, _, _) in LINKS.items() if k != "base_link")
    s = [HEADER.replace("{total_mass}", f"{total:.4g}")]
    by_child = {j[3]: j for j in JOINTS}
    for name in LINK_ORDER:
        if name in by_child:
            s.append(tree_joint_xml(by_child[name]))
        m, com, _, _ = LINKS[name]
        s.append(link_xml(name, m, com, inertia(name)))
    s.append("</robot>\n")
    return "".join(s)


if __name__ == "__main__":
    main(__doc__, urdf_text, "tests/fixtures/tree12.urdf")
