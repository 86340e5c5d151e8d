"""What the make_*_urdf.py scripts share: exact numbers and rotations, the
`<inertial>` element, and the command line that writes the URDF or prints it.

Numbers are written with repr, the shortest text that reads back as the same double,
so a URDF regenerated from the same data is the same file byte for byte.
"""
import argparse
import math
import os
import sys

import numpy as np

PI = math.pi

# The repository root, for default output paths.
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def exact_cs(angle):
    """cos/sin, exact for multiples of pi/2 (matches what a careful parser does)."""
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


def rpy_matrix(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def sig6(x):
    return float(f"{x:.6g}")


def box_inertia(name, m, dims, rpy):
    """The inertia (3 x 3, about the centre of mass) of a homogeneous box of mass `m` and
    dimensions `dims`, its axes turned by `rpy` in the link frame: full and physical by
    construction, rounded to 6 significant digits and re-checked (exits naming `name`
    if rounding broke it)."""
    a, b, c = dims
    box = np.diag([m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12])
    R = rpy_matrix(*rpy)
    inertia = R @ box @ R.T
    inertia = np.vectorize(sig6)(0.5 * (inertia + inertia.T))
    ev = np.linalg.eigvalsh(inertia)
    if not (ev[0] > 0 and ev[2] < ev[0] + ev[1] - 1e-6 * ev.sum()):
        sys.exit(f"{name}: rounded inertia not physical: {ev}")
    return inertia


def inertial_xml(mass, com, I, indent="    "):
    """The `<inertial>` element of a link: centre of mass `com`, inertia `I` (3 x 3)
    about it in link axes."""
    return (f"{indent}<inertial>\n"
            f"{indent}  <origin xyz=\"{fmt(com)}\" rpy=\"0 0 0\"/>\n"
            f"{indent}  <mass value=\"{repr(float(mass))}\"/>\n"
            f"{indent}  <inertia ixx=\"{repr(clean(I[0][0]))}\" ixy=\"{repr(clean(I[0][1]))}\" "
            f"ixz=\"{repr(clean(I[0][2]))}\" iyy=\"{repr(clean(I[1][1]))}\" "
            f"iyz=\"{repr(clean(I[1][2]))}\" izz=\"{repr(clean(I[2][2]))}\"/>\n"
            f"{indent}</inertial>\n")


def link_xml(name, mass, com, I):
    """A `<link>` with its inertial."""
    return f'  <link name="{name}">\n' + inertial_xml(mass, com, I) + '  </link>\n'


def joint_xml(name, kind, parent, child, xyz, rpy, axis=None, limit=None):
    """A `<joint>`. `xyz`, `rpy`, `axis`: lists, or text written as it is; `limit`: `(lower, upper,
    effort, velocity)`, or `(effort, velocity)` for a continuous joint."""
    def vec(v):
        return v if isinstance(v, str) else fmt(v)

    s = (f'  <joint name="{name}" type="{kind}">\n'
         f'    <parent link="{parent}"/>\n'
         f'    <child link="{child}"/>\n'
         f'    <origin xyz="{vec(xyz)}" rpy="{vec(rpy)}"/>\n')
    if axis is not None:
        s += f'    <axis xyz="{vec(axis)}"/>\n'
    if limit is not None and len(limit) == 4:
        lower, upper, effort, velocity = limit
        s += (f'    <limit lower="{repr(lower)}" upper="{repr(upper)}" '
              f'effort="{repr(effort)}" velocity="{repr(velocity)}"/>\n')
    elif limit is not None:
        effort, velocity = limit
        s += f'    <limit effort="{repr(effort)}" velocity="{repr(velocity)}"/>\n'
    return s + '  </joint>\n'


def main(doc, urdf_text, default_output):
    """The command line of a generator script: writes `urdf_text()` to
    `default_output` (relative to the repository root), `-o PATH`, or stdout (`-o -`)."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-o", "--output", default=os.path.join(ROOT, *default_output.split("/")),
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
