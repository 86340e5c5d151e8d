#!/usr/bin/env python3
"""Independent check of the Pinocchio fixtures (numpy only, no Pinocchio).

Usage (any python with numpy; works from any directory):
    python3 scripts/check_fixtures.py                 # every tests/fixtures/*.json
    python3 scripts/check_fixtures.py tests/fixtures/panda.json ...

For each fixture it re-reads the URDF with its own parser (xml.etree), merges links on
fixed joints into the moving body above them, orders sibling joints by name (as
urdfdom, hence Pinocchio, does) and recomputes with its own spatial-vector code
(linear first, then angular; Featherstone's recursions):
  model: joint names, parents, placements, motion subspaces, dyn_params;
  per sample: oMi, tau and f (RNEA), g (RNEA at v = a = 0), nle (RNEA at a = 0),
  M (column j = RNEA(q, 0, e_j) - g), ddq = M^-1 (tau_fd - nle), and Y (column k of
  the regressor = RNEA with the 10-vector of body parameters set to unit vector k,
  which is exact because RNEA is linear in the parameters, gravity included).
It prints the largest absolute difference per quantity (relative for ddq, whose
magnitude varies widely) and exits non-zero when one exceeds its tolerance.
"""
import glob
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rpy_matrix(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return (np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
            @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
            @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]]))


def vec(text, default):
    return np.array([float(x) for x in text.split()]) if text is not None else np.array(default, dtype=float)


def origin_of(el):
    o = el.find("origin") if el is not None else None
    if o is None:
        return np.eye(3), np.zeros(3)
    return rpy_matrix(*vec(o.get("rpy"), [0, 0, 0])), vec(o.get("xyz"), [0, 0, 0])


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def rodrigues(axis, angle):
    K = skew(axis)
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


class Body:
    pass


def load(urdf):
    """Moving bodies in Pinocchio order, each with placement (R, p) in the parent body's
    joint frame, axis, kind and inertial (m, c, I_c) in its own joint frame."""
    robot = ET.parse(urdf).getroot()
    links = {l.get("name"): l for l in robot.findall("link")}
    joints = robot.findall("joint")
    children = {}
    child_links = set()
    for j in joints:
        children.setdefault(j.find("parent").get("link"), []).append(j)
        child_links.add(j.find("child").get("link"))
    (root,) = [n for n in links if n not in child_links]

    def inertial(link):
        el = links[link].find("inertial")
        if el is None:
            return 0.0, np.zeros(3), np.zeros((3, 3))
        R, p = origin_of(el)
        m = float(el.find("mass").get("value"))
        a = el.find("inertia").attrib
        g = lambda k: float(a.get(k, 0.0))
        I = np.array([[g("ixx"), g("ixy"), g("ixz")], [g("ixy"), g("iyy"), g("iyz")], [g("ixz"), g("iyz"), g("izz")]])
        return m, p, R @ I @ R.T

    def add_inertial(body, R, p, part):
        """Add a part (m, c, Ic) given in a frame (R, p) relative to the body frame."""
        m2, c2, I2 = part
        if m2 == 0.0 and not I2.any():
            return
        c2 = R @ c2 + p
        I2 = R @ I2 @ R.T
        m1, c1, I1 = body.m, body.c, body.Ic
        m = m1 + m2
        c = (m1 * c1 + m2 * c2) / m
        shift = lambda mm, d: mm * (d @ d * np.eye(3) - np.outer(d, d))
        body.m, body.c, body.Ic = m, c, I1 + shift(m1, c1 - c) + I2 + shift(m2, c2 - c)

    bodies = []

    def walk(link, parent_idx, R, p, body):
        # R, p: frame of `link` relative to the frame of moving body `parent_idx`
        # (or of `body` when the link is merged into it).
        for j in sorted(children.get(link, []), key=lambda e: e.get("name")):
            Rj, pj = origin_of(j)
            child = j.find("child").get("link")
            R2, p2 = R @ Rj, R @ pj + p
            if j.get("type") == "fixed":
                if body is not None:
                    add_inertial(body, R2, p2, inertial(child))
                walk(child, parent_idx, R2, p2, body)
                continue
            b = Body()
            b.name, b.parent, b.R, b.p = j.get("name"), parent_idx, R2, p2
            b.kind = "P" if j.get("type") == "prismatic" else "R"
            ax = vec(j.find("axis").get("xyz") if j.find("axis") is not None else None, [1, 0, 0])
            b.axis = ax / np.linalg.norm(ax)
            b.m, b.c, b.Ic = 0.0, np.zeros(3), np.zeros((3, 3))
            add_inertial(b, np.eye(3), np.zeros(3), inertial(child))
            bodies.append(b)
            walk(child, len(bodies), np.eye(3), np.zeros(3), b)

    walk(root, 0, np.eye(3), np.zeros(3), None)
    return bodies


def params(b):
    m, c, Ic = b.m, b.c, b.Ic
    I = Ic + m * (c @ c * np.eye(3) - np.outer(c, c))
    return np.array([m, *(m * c), I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]])


def spatial_inertia(pi):
    m, h = pi[0], pi[1:4]
    I = np.array([[pi[4], pi[5], pi[7]], [pi[5], pi[6], pi[8]], [pi[7], pi[8], pi[9]]])
    return np.block([[m * np.eye(3), -skew(h)], [skew(h), I]])


def subspace(b):
    return np.concatenate([b.axis, np.zeros(3)]) if b.kind == "P" else np.concatenate([np.zeros(3), b.axis])


def crm(v):  # motion cross product matrix, [lin; ang]
    return np.block([[skew(v[3:]), skew(v[:3])], [np.zeros((3, 3)), skew(v[3:])]])


def kinematics(bodies, q):
    """Per body: rotation R and translation p of joint frame i relative to the parent's
    frame at configuration q, and world placements."""
    rel, world = [], []
    for i, b in enumerate(bodies):
        if b.kind == "R":
            R, p = b.R @ rodrigues(b.axis, q[i]), b.p.copy()
        else:
            R, p = b.R, b.p + b.R @ (b.axis * q[i])
        rel.append((R, p))
        if b.parent == 0:
            world.append((R, p))
        else:
            Rw, pw = world[b.parent - 1]
            world.append((Rw @ R, Rw @ p + pw))
    return rel, world


def motion_x(R, p):
    """Motion transform from parent coordinates to child coordinates, child = (R, p) in parent."""
    Rt = R.T
    return np.block([[Rt, -Rt @ skew(p)], [np.zeros((3, 3)), Rt]])


def rnea(bodies, rel, pis, qd, qdd, gravity):
    n = len(bodies)
    X = [motion_x(R, p) for R, p in rel]
    S = [subspace(b) for b in bodies]
    v, a, f = [None] * n, [None] * n, [None] * n
    a0 = np.concatenate([-np.asarray(gravity), np.zeros(3)])
    for i, b in enumerate(bodies):
        vp = np.zeros(6) if b.parent == 0 else v[b.parent - 1]
        ap = a0 if b.parent == 0 else a[b.parent - 1]
        v[i] = X[i] @ vp + S[i] * qd[i]
        a[i] = X[i] @ ap + S[i] * qdd[i] + crm(v[i]) @ (S[i] * qd[i])
        Ii = spatial_inertia(pis[i])
        f[i] = Ii @ a[i] - crm(v[i]).T @ (Ii @ v[i])
    for i in reversed(range(n)):
        if bodies[i].parent != 0:
            f[bodies[i].parent - 1] = f[bodies[i].parent - 1] + X[i].T @ f[i]
    tau = np.array([S[i] @ f[i] for i in range(n)])
    return tau, f


def check(path):
    fx = json.load(open(path))
    urdf = fx["urdf"] if os.path.isabs(fx["urdf"]) else os.path.join(ROOT, fx["urdf"])
    bodies = load(urdf)
    n = len(bodies)
    mod = fx["model"]
    err = {}

    def upd(k, x):
        err[k] = max(err.get(k, 0.0), float(np.max(np.abs(x))) if np.size(x) else 0.0)

    assert [b.name for b in bodies] == mod["joint_names"], ([b.name for b in bodies], mod["joint_names"])
    assert [b.parent for b in bodies] == mod["parents"]
    pis = [params(b) for b in bodies]
    upd("dyn_params", np.array(pis) - np.array(mod["dyn_params"]))
    for b, P, S in zip(bodies, mod["placements"], mod["motion_subspace"]):
        upd("placements", np.concatenate([(b.R - np.array(P["rotation"])).ravel(), b.p - np.array(P["translation"])]))
        upd("motion_subspace", subspace(b) - np.array(S))
    g = fx["gravity"]
    zero = np.zeros(n)
    for s in fx["samples"]:
        q, qd, qdd = (np.array(s[k]) for k in ("q", "v", "a"))
        rel, world = kinematics(bodies, q)
        for (R, p), o in zip(world, s["oMi"]):
            upd("oMi", np.concatenate([(R - np.array(o["rotation"])).ravel(), p - np.array(o["translation"])]))
        tau, f = rnea(bodies, rel, pis, qd, qdd, g)
        upd("tau", tau - s["tau"])
        upd("f", np.array(f) - np.array(s["f"]))
        if fx["schema_version"] < 2:
            continue
        gv = rnea(bodies, rel, pis, zero, zero, g)[0]
        nle = rnea(bodies, rel, pis, qd, zero, g)[0]
        M = np.column_stack([rnea(bodies, rel, pis, zero, np.eye(n)[j], g)[0] - gv for j in range(n)])
        upd("g", gv - s["g"])
        upd("nle", nle - s["nle"])
        upd("M", M - np.array(s["M"]))
        ddq = np.linalg.solve(M, np.array(s["tau_fd"]) - nle)
        upd("ddq (rel)", (ddq - s["ddq"]) / max(1.0, float(np.abs(ddq).max())))
        Y = np.zeros((n, 10 * n))
        for k in range(n):
            for j in range(10):
                unit = [np.zeros(10) for _ in range(n)]
                unit[k][j] = 1.0
                Y[:, 10 * k + j] = rnea(bodies, rel, unit, qd, qdd, g)[0]
        upd("Y", Y - np.array(s["Y"]))
        assert np.all(np.abs(np.array(s["M"]) - np.array(s["M"]).T) == 0.0), "M not symmetric"
    return err


TOL = {"dyn_params": 1e-12, "placements": 1e-12, "motion_subspace": 1e-12, "oMi": 1e-12,
       "tau": 1e-10, "f": 1e-10, "g": 1e-10, "nle": 1e-10, "M": 1e-12, "ddq (rel)": 1e-10, "Y": 1e-10}


def main():
    paths = sys.argv[1:] or sorted(glob.glob(os.path.join(ROOT, "tests", "fixtures", "*.json")))
    ok = True
    for path in paths:
        err = check(path)
        bad = [k for k, x in err.items() if not x <= TOL[k]]
        ok &= not bad
        print(f"{os.path.basename(path)}: " + ", ".join(f"{k} {x:.1e}" for k, x in err.items())
              + ("" if not bad else f"  FAIL {bad}"))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
