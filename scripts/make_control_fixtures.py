#!/usr/bin/env python3
"""Write Pinocchio reference fixtures (JSON) for dyngen's control kernels.

Usage, from anywhere (needs a python with `pip install pin==4.1.0 numpy`):

    PY=python3
    $PY scripts/make_control_fixtures.py --all
    $PY scripts/make_control_fixtures.py --urdf path/to/robot.urdf --name robot \
        [--gravity GX GY GZ] [--samples 6] [--seed 7] [--out-dir DIR]

--all regenerates tests/fixtures/control/NAME.json for every robot of make_fixtures.py's
FIXTURES (same URDFs, same gravity). --urdf/--name writes tests/fixtures/control/NAME.json
(or DIR/NAME.json) for any URDF.

Per sample: frame placements, frame Jacobians and velocities in the three Pinocchio
reference frames (WORLD, LOCAL, LOCAL_WORLD_ALIGNED), the classical acceleration of
each frame for the given `a` and for `a = 0` (the drift; in LOCAL_WORLD_ALIGNED it is
J̇_lwa(q, v) v, the acceleration of the frame origin at a = 0), the centre of mass
and its Jacobian, the joint-space inertia matrix, the RNEA and ABA derivatives and the
inverse inertia. Frames are the BODY frames of the Pinocchio model: one per URDF link,
including the root link and links on fixed joints.

Sampling and conventions are those of make_fixtures.py (imported from it): `q` holds
one coordinate per joint (the angle for revolute and continuous joints, the
displacement for prismatic ones) and is converted to Pinocchio's q (cos, sin for
continuous joints) internally; spatial vectors are linear first, then angular;
matrices are lists of rows. Before writing, the script checks Pinocchio's values
against finite differences (step 1e-6, central) and identities (see CHECKS) and
refuses to write if any error exceeds its tolerance (1e-6 for the finite differences,
judged relative to max(1, |f|); 1e-9 for the identities). The schema is documented in tests/fixtures/control/README.md.
"""
import json
import os
import sys

import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_fixtures import ROOT, FIXTURE_DIR, FIXTURES, run_cli, check_model, coord_range, flat, rows, se3, to_pin_q  # noqa: E402

CONTROL_DIR = os.path.join(FIXTURE_DIR, "control")
SCHEMA_VERSION = 1
GENERATOR = "scripts/make_control_fixtures.py"
SAMPLES = 6
SEED = 7
V_RANGE = 2.0     # v uniform in [-2, 2]^nv
A_RANGE = 2.0     # a uniform in [-2, 2]^nv
TAU_RANGE = 10.0  # tau uniform in [-10, 10]^nv
FD_STEP = 1e-6    # central differences

REFS = (("world", pin.WORLD), ("local", pin.LOCAL), ("lwa", pin.LOCAL_WORLD_ALIGNED))

# Self-checks: name -> (tolerance, what). Each is the max abs error over samples (and
# frames), recorded in "checks_max_abs". The finite-difference checks (FD_CHECKS) are
# judged scaled instead: abs error / max(1, max |f|), f the differenced function over
# the sample's evaluations (recorded in "checks_max_scaled"). Their rounding error is
# about 1e-16 |f| / FD_STEP, and ddq reaches 1e5 on arms with light wrists (so the
# abs error of the aba differences reaches 1e-5 while the scaled one stays below 1e-9).
CHECKS = {
    "rnea_fd_dq": (1e-6, "central difference of pin.rnea in theta vs dtau_dq"),
    "rnea_fd_dv": (1e-6, "central difference of pin.rnea in v vs dtau_dv"),
    "aba_fd_dq": (1e-6, "central difference of pin.aba in theta vs ddq_dq"),
    "aba_fd_dv": (1e-6, "central difference of pin.aba in v vs ddq_dv"),
    "position_fd": (1e-6, "central difference of oMf translation along theta + t v vs (J_lwa v) linear"),
    "drift_fd": (1e-6, "central difference of J_lwa v along theta + t v vs drift_lwa (all 6 rows)"),
    "drift_fd_refs": (1e-6, "central difference of J_ref v along theta + t v, plus [w x v_lin; 0] of v_ref, "
                      "vs drift_ref, ref in world, local"),
    "com_fd": (1e-6, "central difference of com along theta + t v vs Jcom v"),
    "rnea_da_M": (1e-9, "dtau_da of computeRNEADerivatives vs M"),
    "dJ_fd": (1e-6, "central difference of J_ref along theta + t v vs dJ_ref (getFrameJacobianTimeVariation), every ref"),
    "dAg_fd": (1e-6, "central difference of Ag along theta + t v, times v, vs dAg v"),
    "Ag_linear_mass_Jcom": (1e-9, "linear rows of Ag vs total mass times Jcom"),
    "aba_ddq": (1e-9, "M ddq + rnea(q, v, 0) - tau"),
    "minv_M_identity": (1e-9, "Minv M - I"),
    "jacobian_velocity": (1e-9, "J_ref v - v_ref, ref in world, local, lwa, for a and a = 0"),
    "jacobian_refs": (1e-9, "J_local, J_world recomputed from J_lwa and oMf"),
    "acc_drift_Ja": (1e-9, "acc_ref - (drift_ref + J_ref a), ref in world, local, lwa"),
    "acc_refs": (1e-9, "acc_local, acc_world, drift_local, drift_world recomputed from the lwa ones and oMf"),
}
FD_CHECKS = [k for k in CHECKS if k.endswith("_fd") or "_fd_" in k]


def body_frames(model):
    return [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY]


def skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def sym_upper(A):
    A = np.array(A)
    return np.triu(A) + np.triu(A, 1).T


def kinematics(model, data, fids, q, v, a):
    """Per BODY frame: oMf, the three Jacobians, velocities and classical accelerations."""
    pin.computeJointJacobians(model, data, q)
    pin.forwardKinematics(model, data, q, v, a)
    pin.updateFramePlacements(model, data)
    out = []
    for fid in fids:
        fr = {"oMf": data.oMf[fid].copy()}
        for key, rf in REFS:
            fr["J_" + key] = pin.getFrameJacobian(model, data, fid, rf).copy()
            fr["v_" + key] = pin.getFrameVelocity(model, data, fid, rf).vector.copy()
            fr["acc_" + key] = pin.getFrameClassicalAcceleration(model, data, fid, rf).vector.copy()
        out.append(fr)
    return out


def frame_positions(model, data, fids, q):
    pin.framesForwardKinematics(model, data, q)
    return np.array([data.oMf[fid].translation for fid in fids])


def frame_jacobian_velocities(model, data, fids, q, v):
    """J_ref(q) v per BODY frame and reference frame (REFS order): shape (frames, 3, 6)."""
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    return np.array([[pin.getFrameJacobian(model, data, fid, rf) @ v for _, rf in REFS] for fid in fids])


def classical_from_lwa(acc_lwa, v_lwa, oMf):
    """Classical accelerations in LOCAL and WORLD from the LOCAL_WORLD_ALIGNED one.

    LOCAL: the same vector in frame axes. WORLD: the classical acceleration of the body
    point that is at the world origin, a_O = a_p + w' x (0 - p) + w x (w x (0 - p)).
    """
    R, p = oMf.rotation, oMf.translation
    w, dw = v_lwa[3:], acc_lwa[3:]
    local = np.concatenate([R.T @ acc_lwa[:3], R.T @ dw])
    world = np.concatenate([acc_lwa[:3] - np.cross(dw, p) - np.cross(w, np.cross(w, p)), dw])
    return local, world


def make_fixture(urdf, name, samples, seed, gravity=None):
    urdf = os.path.abspath(urdf)
    model = pin.buildModelFromUrdf(urdf)
    if gravity is not None:
        model.gravity.linear = np.array(gravity, dtype=float)
    check_model(model)
    data = model.createData()
    nj, nv = model.njoints, model.nv
    fids = body_frames(model)
    ranges = [coord_range(model, model.joints[i]) for i in range(1, nj)]
    rng = np.random.default_rng(seed)
    h = FD_STEP
    eye = np.eye(nv)
    zero = np.zeros(nv)

    worst = {k: 0.0 for k in CHECKS}
    scaled = {k: 0.0 for k in FD_CHECKS}

    def record(key, err, scale=None):
        e = float(np.max(np.abs(err))) if np.size(err) else 0.0
        worst[key] = max(worst[key], e)
        if scale is not None:
            scaled[key] = max(scaled[key], e / max(1.0, scale))

    def fd(f, dirs):
        """Central differences of f along each direction; also max |f| over the evaluations."""
        cols, big = [], 0.0
        for d in dirs:
            fp, fm = np.asarray(f(h * d)), np.asarray(f(-h * d))
            big = max(big, float(np.max(np.abs(fp))), float(np.max(np.abs(fm))))
            cols.append((fp - fm) / (2 * h))
        return np.column_stack(cols), big

    out_samples = []
    for _ in range(samples):
        # Draws, per sample in this order: theta, v, a, tau.
        theta = np.array([rng.uniform(lo, hi) for lo, hi in ranges])
        v = rng.uniform(-V_RANGE, V_RANGE, nv)
        a = rng.uniform(-A_RANGE, A_RANGE, nv)
        tau = rng.uniform(-TAU_RANGE, TAU_RANGE, nv)
        q = to_pin_q(model, theta)
        qp = lambda d: to_pin_q(model, theta + d)  # noqa: E731

        # Frames: given a, then a = 0 (drift).
        kin = kinematics(model, data, fids, q, v, a)
        kin0 = kinematics(model, data, fids, q, v, zero)

        # Centre of mass.
        com = pin.centerOfMass(model, data, q).copy()
        Jcom = pin.jacobianCenterOfMass(model, data, q).copy()
        Ag = pin.computeCentroidalMap(model, data, q).copy()
        dAg = np.array(pin.computeCentroidalMapTimeVariation(model, data, q, v)).copy()
        h = 1e-6
        dAg_fd = (pin.computeCentroidalMap(model, data, qp(h * v)).copy()
                  - pin.computeCentroidalMap(model, data, qp(-h * v)).copy()) / (2 * h)
        # Pinocchio's dAg is not the time derivative of Ag (they differ by terms that
        # vanish on v), but dAg v is: the rate of the centroidal momentum at a = 0.
        record("dAg_fd", dAg_fd @ v - dAg @ v, 1.0)
        record("Ag_linear_mass_Jcom", Ag[:3] - data.mass[0] * Jcom)

        # Joint space.
        M = sym_upper(pin.crba(model, data, q))
        dtau_dq, dtau_dv, dtau_da = (np.array(x) for x in pin.computeRNEADerivatives(model, data, q, v, a))
        ddq = pin.aba(model, data, q, v, tau).copy()
        ddq_dq, ddq_dv, Minv = (np.array(x) for x in pin.computeABADerivatives(model, data, q, v, tau))
        Minv = sym_upper(Minv)

        # --- checks: derivatives by central differences (theta perturbed, then to_pin_q)
        for key, f, ref in (
                ("rnea_fd_dq", lambda d: pin.rnea(model, data, qp(d), v, a).copy(), dtau_dq),
                ("rnea_fd_dv", lambda d: pin.rnea(model, data, q, v + d, a).copy(), dtau_dv),
                ("aba_fd_dq", lambda d: pin.aba(model, data, qp(d), v, tau).copy(), ddq_dq),
                ("aba_fd_dv", lambda d: pin.aba(model, data, q, v + d, tau).copy(), ddq_dv)):
            J, big = fd(f, eye)
            record(key, J - ref, big)
        record("rnea_da_M", sym_upper(dtau_da) - M)
        record("aba_ddq", M @ ddq + pin.rnea(model, data, q, v, zero) - tau)
        record("minv_M_identity", Minv @ M - eye)

        # --- checks: frames
        dpos, pos_big = fd(lambda d: frame_positions(model, data, fids, qp(d)).reshape(-1), [v])
        dpos = dpos.reshape(len(fids), 3)
        dvel, vel_big = fd(lambda d: frame_jacobian_velocities(model, data, fids, qp(d), v).reshape(-1), [v])
        dvel = dvel.reshape(len(fids), len(REFS), 6)
        dcom, com_big = fd(lambda d: pin.centerOfMass(model, data, qp(d)).copy(), [v])
        record("com_fd", dcom[:, 0] - Jcom @ v, com_big)
        for k, (fr, fr0) in enumerate(zip(kin, kin0)):
            R, p = fr["oMf"].rotation, fr["oMf"].translation
            for key, _ in REFS:
                record("jacobian_velocity", fr["J_" + key] @ v - fr["v_" + key])
                record("jacobian_velocity", fr0["J_" + key] @ v - fr0["v_" + key])
                record("acc_drift_Ja", fr["acc_" + key] - (fr0["acc_" + key] + fr["J_" + key] @ a))
            Jl = fr["J_lwa"]
            record("jacobian_refs", np.vstack([R.T @ Jl[:3], R.T @ Jl[3:]]) - fr["J_local"])
            record("jacobian_refs", np.vstack([Jl[:3] + skew(p) @ Jl[3:], Jl[3:]]) - fr["J_world"])
            for f in (fr, fr0):
                local, world = classical_from_lwa(f["acc_lwa"], f["v_lwa"], f["oMf"])
                record("acc_refs", local - f["acc_local"])
                record("acc_refs", world - f["acc_world"])
            record("position_fd", dpos[k] - (Jl @ v)[:3], pos_big)
            for r, (key, _) in enumerate(REFS):
                # d/dt (J_ref v) is the spatial acceleration in that frame (a = 0); the
                # classical one adds w x (linear velocity). For lwa the term is zero.
                vr = fr0["v_" + key]
                dd = dvel[k, r] + np.concatenate([np.cross(vr[3:], vr[:3]), np.zeros(3)]) * (key != "lwa")
                record("drift_fd" if key == "lwa" else "drift_fd_refs", dd - fr0["acc_" + key], vel_big)

        # Jacobian time variation: Pinocchio's dJ is d/dt J along q + t v in each frame.
        pin.computeJointJacobiansTimeVariation(model, data, q, v)
        pin.updateFramePlacements(model, data)
        djac = [[pin.getFrameJacobianTimeVariation(model, data, fid, rf).copy() for _, rf in REFS] for fid in fids]
        def jac_at(t):
            pin.computeJointJacobians(model, data, qp(t * v))
            pin.updateFramePlacements(model, data)
            return [[pin.getFrameJacobian(model, data, fid, rf).copy() for _, rf in REFS] for fid in fids]
        jplus, jminus = jac_at(1e-6), jac_at(-1e-6)
        for k in range(len(fids)):
            for r in range(len(REFS)):
                record("dJ_fd", (jplus[k][r] - jminus[k][r]) / 2e-6 - djac[k][r], 1.0)

        frames_out = []
        for k, (fr, fr0) in enumerate(zip(kin, kin0)):
            e = {"oMf": se3(fr["oMf"])}
            for key, _ in REFS:
                e["J_" + key] = rows(fr["J_" + key])
            for key, _ in REFS:
                e["v_" + key] = flat(fr["v_" + key])
            for key, _ in REFS:
                e["acc_" + key] = flat(fr["acc_" + key])
            for key, _ in REFS:
                e["drift_" + key] = flat(fr0["acc_" + key])
            for r, (key, _) in enumerate(REFS):
                e["dJ_" + key] = rows(djac[k][r])
            frames_out.append(e)
        out_samples.append({
            "q": flat(theta),
            "v": flat(v),
            "a": flat(a),
            "tau": flat(tau),
            "frames": frames_out,
            "com": flat(com),
            "Jcom": rows(Jcom),
            "Ag": rows(Ag),
            "dAg_v": flat(dAg @ v),
            "M": rows(M),
            "dtau_dq": rows(dtau_dq),
            "dtau_dv": rows(dtau_dv),
            "ddq": flat(ddq),
            "ddq_dq": rows(ddq_dq),
            "ddq_dv": rows(ddq_dv),
            "Minv": rows(Minv),
        })

    judged = {**worst, **scaled}
    bad = {k: x for k, x in judged.items() if not x <= CHECKS[k][0]}
    if bad:
        sys.exit(f"{name}: self-check failed (tolerances in CHECKS): {bad}")

    rel = os.path.relpath(urdf, ROOT)
    return {
        "schema_version": SCHEMA_VERSION,
        "name": name,
        "urdf": urdf if rel.startswith("..") else rel,
        "pinocchio_version": pin.__version__,
        "generator": GENERATOR,
        "seed": seed,
        "gravity": flat(model.gravity.linear),
        "joint_names": [model.names[i] for i in range(1, nj)],
        "frames": [{"name": model.frames[i].name,
                    "parent_joint": int(model.frames[i].parentJoint),
                    "placement": se3(model.frames[i].placement)} for i in fids],
        "checks_max_abs": worst,
        "checks_max_scaled": scaled,
        "samples": out_samples,
    }


def write(fix, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, fix["name"] + ".json")
    with open(path, "w") as fh:
        json.dump(fix, fh, separators=(",", ":"), allow_nan=False)
        fh.write("\n")
    judged = {**fix["checks_max_abs"], **fix["checks_max_scaled"]}
    worst = max(judged.items(), key=lambda kv: kv[1] / CHECKS[kv[0]][0])
    print(f"wrote {os.path.relpath(path)}  ({fix['urdf']}, {len(fix['samples'])} samples, seed {fix['seed']}, "
          f"{len(fix['frames'])} frames, {os.path.getsize(path)} bytes, worst check vs its limit: {worst[0]} {worst[1]:.2e})")


def main():
    run_cli(__doc__, make_fixture, write, CONTROL_DIR, SAMPLES, SEED, all_samples=True, what="control fixture")


if __name__ == "__main__":
    main()
