#!/usr/bin/env python3
"""The MuJoCo UR5 recordings of `make_mujoco_fixture.py`, with two joint effects past
viscous and Coulomb friction added by MuJoCo itself: direction-dependent viscous
friction and position-dependent torque (ripple) and Coulomb friction, the terms
`dyngen identify --extra-terms asymmetric,ripple=2` fits.

Needs `pip install mujoco pin numpy` (MuJoCo 4.0.0, Pinocchio 4.1.0). From the project
root:

    python scripts/make_mujoco_extras_fixture.py     # writes tests/fixtures/mujoco_extras/

Everything of `make_mujoco_fixture.py` is kept (robot, armature, damping, MuJoCo's
dry friction `frictionloss`, PD + feed-forward tracking of a Fourier excitation, RK4
at 1 kHz, jittered 8-13 ms logger with stale rows, position rounding, velocity and
1 % torque noise). On top, a passive-force callback (`mujoco.set_mjcb_passive`,
evaluated at every stage of the integrator) adds to each joint's passive force
`-e_j(q_j, qd_j)` with

    e_j = Fva_j |qd_j|
        + sum_k Ts_kj sin(k q_j) + Tc_kj cos(k q_j)
        + sum_k (Fcs_kj sin(k q_j) + Fcc_kj cos(k q_j)) sign(qd_j),   k = 1, 2

so the torque the motors apply (`qfrc_actuator`, what is logged) carries `+e_j`. The
script checks on the 1 kHz states, before noise, that the logged torque equals
Pinocchio's rnea + armature qdd + damping qd + MuJoCo's dry-friction force + e to
rounding. The feed-forward does not compensate `e` (the PD does), as a controller
that does not know these effects would not.

Files: `ur5_identify.csv`, `ur5_validate.csv` (dyngen's CSV layout, as the base
fixture's), `ur5_truth.json` (the truth of every term and the checks).
"""

import argparse
import json
import os
import sys

import mujoco
import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_mujoco_fixture as base  # noqa: E402

# Per joint: direction-dependent viscous friction (N m s/rad), then per harmonic
# k = 1, 2 the ripple (Ts, Tc) and the position-dependent Coulomb friction (Fcs, Fcc),
# N m: a few to 15 % of each joint's Coulomb friction.
FVA = [1.0, 1.0, 0.6, 0.2, 0.2, 0.2]
RIPPLE = [
    # (Ts1, Tc1, Fcs1, Fcc1, Ts2, Tc2, Fcs2, Fcc2)
    (0.4, -0.3, 0.5, 0.3, -0.3, 0.2, 0.4, -0.3),
    (0.4, -0.3, 0.5, 0.3, -0.3, 0.2, 0.4, -0.3),
    (0.3, -0.2, 0.4, 0.2, -0.2, 0.15, 0.3, -0.2),
    (0.1, -0.08, 0.12, 0.06, -0.08, 0.05, 0.1, -0.06),
    (0.1, -0.08, 0.12, 0.06, -0.08, 0.05, 0.1, -0.06),
    (0.1, -0.08, 0.12, 0.06, -0.08, 0.05, 0.1, -0.06),
]


def extra_torque(q, qd):
    """e(q, qd) per joint, as the module says."""
    s = np.sign(qd)
    e = np.array(FVA) * np.abs(qd)
    for j, r in enumerate(RIPPLE):
        for k in (1, 2):
            ts, tc, fcs, fcc = r[4 * (k - 1) : 4 * k]
            sin, cos = np.sin(k * q[j]), np.cos(k * q[j])
            e[j] += ts * sin + tc * cos + (fcs * sin + fcc * cos) * s[j]
    return e


def passive(m, d):
    d.qfrc_passive[:] -= extra_torque(d.qpos, d.qvel)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--urdf", default=os.path.join(base.ROOT, "robots", "ur5", "ur5.urdf"))
    ap.add_argument("--out-dir", default=os.path.join(base.ROOT, "tests", "fixtures", "mujoco_extras"))
    ap.add_argument("--duration", type=float, default=20.0, help="seconds per recording")
    args = ap.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    m = base.load_mujoco(args.urdf)
    pm = pin.buildModelFromUrdf(args.urdf)
    pm.gravity.linear[:] = [0.0, 0.0, -9.81]
    inertias = base.check_inertias(m, pm, args.urdf)
    mujoco.set_mjcb_passive(passive)
    n = m.nv
    truth = {
        "made_by": "scripts/make_mujoco_extras_fixture.py",
        "mujoco": mujoco.__version__,
        "pinocchio": pin.__version__,
        "armature": base.ARMATURE,
        "damping": base.DAMPING,
        "frictionloss": base.FRICTIONLOSS,
        "extra_terms": "asymmetric,ripple=2",
        "Fva": FVA,
        "ripple_per_joint_Ts1_Tc1_Fcs1_Fcc1_Ts2_Tc2_Fcs2_Fcc2": [list(r) for r in RIPPLE],
        "torque_noise_relative": base.TORQUE_NOISE_REL,
        "velocity_noise": base.VELOCITY_NOISE,
        "inertia_checks": inertias,
        "recordings": {},
    }
    pd = pm.createData()
    arm, damp = np.array(base.ARMATURE), np.array(base.DAMPING)
    for name, base_hz, seed in base.RECORDINGS:
        rec, excitation = base.simulate(m, pm, base_hz, seed, args.duration)
        # The logged torque against the model with every term, before noise.
        rb = np.array([pin.rnea(pm, pd, q, v, a) for q, v, a in zip(rec["q"], rec["qd"], rec["qdd"])])
        extras = np.array([extra_torque(q, v) for q, v in zip(rec["q"], rec["qd"])])
        model = rb + arm * rec["qdd"] + damp * rec["qd"] + rec["fdry"] + extras
        exact = np.abs(rec["tau"] - model).max(axis=0)
        rms = lambda x: np.sqrt(np.mean(x**2, axis=0))
        print(f"{name}: max |tau - model with every term| per joint {exact}", file=sys.stderr)
        assert exact.max() < 1e-8, exact
        idx, src, stale, rng = base.logger(rec, seed, base.N_STALE)
        t = rec["t"][idx]
        tau_true = rec["tau"][src]
        sigma = base.TORQUE_NOISE_REL * rms(rec["tau"])
        noise_tau = rng.standard_normal(tau_true.shape) * sigma
        noise_v = rng.standard_normal(tau_true.shape) * base.VELOCITY_NOISE
        for r in stale:
            noise_tau[r], noise_v[r] = noise_tau[r - 1], noise_v[r - 1]
        q = np.round(rec["q"][src] / base.Q_RESOLUTION) * base.Q_RESOLUTION
        v = rec["qd"][src] + noise_v
        tau = tau_true + noise_tau
        header = ",".join(
            ["t"] + [f"q{j+1}" for j in range(n)] + [f"v{j+1}" for j in range(n)] + [f"tau{j+1}" for j in range(n)]
        )
        fmts = ["{:.3f}"] + ["{:.5f}"] * n + ["{:.4f}"] * n + ["{:.3f}"] * n
        cols = [t] + [q[:, j] for j in range(n)] + [v[:, j] for j in range(n)] + [tau[:, j] for j in range(n)]
        with open(os.path.join(args.out_dir, name + ".csv"), "w") as f:
            f.write(header + "\n" + base.fmt_rows(cols, fmts))
        truth["recordings"][name + ".csv"] = {
            "rows": len(t),
            "stale_data_rows": [int(r) + 1 for r in stale],
            "excitation": excitation,
            "rms_tau": rms(rec["tau"]).tolist(),
            "rms_extra_torque": rms(extras).tolist(),
            "torque_noise_sigma": sigma.tolist(),
            "max_abs_residual_with_every_term": exact.tolist(),
        }
    with open(os.path.join(args.out_dir, "ur5_truth.json"), "w") as f:
        json.dump(truth, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
