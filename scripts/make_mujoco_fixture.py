#!/usr/bin/env python3
"""Simulate the UR5 in MuJoCo with rotor inertia and friction, and write logger-like
CSV recordings as test data that dyngen's own simulator did not make.

Needs `pip install mujoco pin numpy` (written against MuJoCo 4.0.0 and Pinocchio
4.1.0, Python >= 3.9), e.g. in a virtual environment outside the repository. From the
project root, with that environment's python:

    python scripts/make_mujoco_fixture.py                       # writes tests/fixtures/mujoco/
    python scripts/make_mujoco_fixture.py --out-dir OUT --duration 30

The run is deterministic for a given MuJoCo version (seeded noise and logger).

What is simulated
-----------------
`robots/ur5/ur5.urdf` is loaded by MuJoCo's URDF importer with
`<compiler discardvisual="true" balanceinertia="false" fusestatic="false"/>` (the URDF
has no geometry, so there are no contacts). The script checks that MuJoCo kept the
inertial data: body masses and principal moments against the URDF, and the joint-space
mass matrix and bias forces against Pinocchio's `crba`/`rnea` at random states (they
agree to ~1e-14). One motor actuator per joint (gear 1, no limits) applies the joint
torque `ctrl`. Each joint gets, from the tables below:

- `armature` (reflected rotor inertia, kg m^2): MuJoCo adds it to the diagonal of the
  mass matrix, so it enters as `armature * qdd`;
- `damping` (viscous friction, N m s/rad): a passive force `-damping * qd`;
- `frictionloss` (dry friction, N m): a friction *constraint* on the joint's velocity,
  solved with the other constraints at every evaluation. Its force is bounded,
  `|f| <= frictionloss`. While the joint slides it sits on the bound and opposes the
  motion, which is exactly `frictionloss * sign(qd)`. Near zero velocity it is not a
  sign function: MuJoCo's constraints are soft (default `solreffriction` time
  constant 0.02 s, `solimp` 0.9-0.95), so in "stick" the force is inside the bound, a
  smooth, steep function of velocity and of the other forces, and the joint creeps
  instead of locking. So `Fc * sign(qd)` is the model form only away from velocity
  reversals; the numbers the script prints say how far.

The equation of motion the recorded torque obeys is therefore

    tau_applied = M(q) qdd + C(q, qd) qd + g(q) + armature * qdd + damping * qd + f_dry

with `f_dry = -qfrc_constraint` (= frictionloss * sign(qd) while sliding). The script
verifies this on the 1 kHz internal states before noise: with MuJoCo's own dry-friction
force the residual against Pinocchio's `rnea` is at rounding level; with
`frictionloss * sign(qd)` in its place it prints the per-joint RMS (all samples, and
away from velocity reversals). Gravity is [0, 0, -9.81]. For the shipped files
(identification recording): RMS residual with MuJoCo's dry-friction force <= 1.2e-14
N m per joint; with `frictionloss * sign(qd)` 0.93, 0.77, 0.42, 0.25, 0.28, 0.19 N m
(13, 2.3, 2.5, 11, 15, 10 % of the joints' RMS torque), 0.04-0.12 N m where
|qd| > 0.01 rad/s; the joints slide 90-98 % of the time.

Motion: a PD + feed-forward controller (feed-forward = Pinocchio rnea of the desired
motion + armature and damping terms, no friction compensation; PD at 8 Hz natural
frequency, critically damped on the joint's inertia at the start pose) tracks a
5-harmonic Fourier excitation per joint within the joint limits; the torque is held
over each 1 ms step and MuJoCo integrates with RK4 at 1 kHz. The arm starts on the
desired trajectory 1 s before the recording, so the start transient is not logged. The excitation of the
validation recording has a different base frequency and coefficients.

What is logged
--------------
A logger samples the latest 1 kHz control cycle at jittered intervals of 8-13 ms
(whole milliseconds, mean ~10.3 ms, seeded); a few rows are stale (a new time stamp
with the previous row's values repeated). Logged per joint: position q (rounded to
1e-5 rad, like a 19-bit encoder), measured velocity qd (simulator velocity + Gaussian
noise, sigma 0.002 rad/s), and the applied joint torque `ctrl` (= `qfrc_actuator`, the
torque a joint torque sensor or the motor current would show: it does NOT include the
friction) plus Gaussian noise with sigma = 1 % of that joint's RMS torque over the
recording. The same noisy torque is also logged as motor current `i = tau / k` with the
per-joint gains `k` (N m/A) below.

Files (in --out-dir, default tests/fixtures/mujoco/):

- `ur5_identify.csv`, `ur5_validate.csv`: dyngen's CSV layout, header
  `t,q1..q6,v1..v6,tau1..tau6`, SI units (s, rad, rad/s, N m), t from 0;
- `ur5_identify_raw.csv`: the identification recording as a robot logger writes it: no
  header, columns `t, q1..q6, qd1..qd6, i1..i6` in s (logger clock, not starting at 0),
  degrees, degrees/s and amperes; besides the stale rows it holds a few exact duplicate
  lines (same stamp and values, a buffer written twice). Dropping the exact duplicates
  and converting units gives `ur5_identify.csv` up to print rounding;
- `ur5_truth.json`: the ground truth and how everything was made.
"""

import argparse
import json
import math
import os
import re
import sys

import mujoco
import numpy as np
import pinocchio as pin

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Per joint (shoulder_pan, shoulder_lift, elbow, wrist_1, wrist_2, wrist_3). Values of
# the order of a UR5's geared drives; the wrists' friction dominates their torque.
ARMATURE = [0.40, 0.40, 0.20, 0.08, 0.08, 0.08]  # kg m^2, reflected rotor inertia
DAMPING = [3.0, 3.0, 2.0, 0.6, 0.6, 0.6]  # N m s/rad, viscous friction
FRICTIONLOSS = [6.0, 6.0, 4.0, 1.5, 1.5, 1.5]  # N m, dry friction bound
GAINS = [14.0, 13.0, 12.0, 9.0, 8.5, 8.0]  # N m/A, tau = k * i (torque constant x gear ratio)
TORQUE_NOISE_REL = 0.01  # sigma = 1 % of the joint's RMS torque over the recording
VELOCITY_NOISE = 0.002  # rad/s, sigma of the measured velocity
Q_RESOLUTION = 1e-5  # rad, logged positions are rounded to this

DT = 0.001  # s, control and integration step
LOGGER_STEPS_MS = [8, 9, 10, 11, 12, 13]
LOGGER_STEP_PROBS = [0.10, 0.20, 0.35, 0.20, 0.10, 0.05]
N_STALE = 4  # rows with a new stamp but the previous row's values
N_EXACT_DUPLICATES = 3  # raw file only: lines written twice
RAW_CLOCK_OFFSET = 41.237  # s, the raw logger's clock at the recording's first row

# Excitation: q_j(t) = q0_j + sum_l a_jl sin(l w t) + b_jl cos(l w t), scaled to the
# amplitude and velocity bounds.
HARMONICS = 5
Q0 = [0.0, -1.2, 1.0, -1.4, -1.57, 0.0]  # rad, centre pose
AMPLITUDE = [1.2, 0.7, 1.0, 1.2, 1.2, 1.5]  # rad, max |q - q0|
VMAX = [1.2, 1.0, 1.2, 1.5, 1.5, 2.0]  # rad/s, max |qd|
PD_NATURAL_FREQUENCY = 8.0  # Hz
WARMUP = 1.0  # s simulated before the recording starts (the start transient is not logged)

RECORDINGS = [
    # (name, base frequency Hz, seed)
    ("ur5_identify", 0.10, 1),
    ("ur5_validate", 0.125, 2),
]


def load_mujoco(urdf_path):
    """The URDF as an MjModel with one torque motor per joint, RK4 at 1 kHz."""
    with open(urdf_path) as f:
        src = f.read()
    tag = '<mujoco><compiler discardvisual="true" balanceinertia="false" fusestatic="false" angle="radian"/></mujoco>'
    src, n = re.subn(r"(<robot[^>]*>)", lambda m: m.group(1) + tag, src, count=1)
    assert n == 1, "no <robot> element"
    spec = mujoco.MjSpec.from_string(src)
    assert len(spec.joints) == len(ARMATURE)
    for j, arm, damp, fl in zip(spec.joints, ARMATURE, DAMPING, FRICTIONLOSS):
        # Set before compiling: the compiler derives each constraint's regularisation
        # from the inverse inertia at qpos0 (`dof_invweight0`), which must include the
        # armature. Setting `dof_armature` on a compiled model leaves the light wrist's
        # friction constraint ~1000x too soft (it acts as weak viscous friction).
        j.armature, j.frictionloss = arm, fl
        j.damping = [damp, 0.0, 0.0]  # MuJoCo 4: linear coefficient first, higher orders zero
        a = spec.add_actuator()
        a.name = j.name + "_motor"
        a.target = j.name
        a.trntype = mujoco.mjtTrn.mjTRN_JOINT
        a.gear[0] = 1.0
        a.ctrllimited = 0
    m = spec.compile()
    m.opt.timestep = DT
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    m.opt.gravity[:] = [0.0, 0.0, -9.81]
    assert np.allclose(m.dof_armature, ARMATURE) and np.allclose(m.dof_damping, DAMPING)
    assert np.allclose(m.dof_frictionloss, FRICTIONLOSS) and not np.any(m.dof_dampingpoly)
    return m


def urdf_inertials(urdf_path):
    """{link: (mass, principal moments sorted)} from the URDF text."""
    import xml.etree.ElementTree as ET

    out = {}
    for link in ET.parse(urdf_path).getroot().iter("link"):
        inert = link.find("inertial")
        if inert is None:
            continue
        m = float(inert.find("mass").get("value"))
        i = inert.find("inertia")
        g = lambda k: float(i.get(k, "0"))
        I = np.array([[g("ixx"), g("ixy"), g("ixz")], [g("ixy"), g("iyy"), g("iyz")], [g("ixz"), g("iyz"), g("izz")]])
        rpy = inert.find("origin").get("rpy", "0 0 0") if inert.find("origin") is not None else "0 0 0"
        assert all(float(x) == 0 for x in rpy.split()), "inertial rpy not handled"
        out[link.get("name")] = (m, np.sort(np.linalg.eigvalsh(I)))
    return out


def check_inertias(m, pm, urdf_path):
    """MuJoCo must not have altered the inertial data: bodies, mass matrix, bias."""
    worst = 0.0
    for name, (mass, moments) in urdf_inertials(urdf_path).items():
        b = m.body(name)
        worst = max(worst, abs(b.mass[0] - mass), np.abs(np.sort(b.inertia) - moments).max())
    pd = pm.createData()
    d = mujoco.MjData(m)
    rng = np.random.default_rng(0)
    arm = np.diag(ARMATURE)
    worst_M = worst_b = 0.0
    for _ in range(20):
        q, v = rng.uniform(-3, 3, m.nq), rng.uniform(-2, 2, m.nv)
        d.qpos[:], d.qvel[:] = q, v
        mujoco.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        worst_M = max(worst_M, np.abs(M - arm - pin.crba(pm, pd, q)).max())
        worst_b = max(worst_b, np.abs(d.qfrc_bias - pin.rnea(pm, pd, q, v, np.zeros(m.nv))).max())
    print(
        f"inertias: body mass/principal moments vs URDF max diff {worst:.1e}; "
        f"M - armature vs pin.crba {worst_M:.1e}; bias vs pin.rnea {worst_b:.1e}",
        file=sys.stderr,
    )
    assert worst < 1e-12 and worst_M < 1e-10 and worst_b < 1e-10
    return {"body_mass_inertia": worst, "mass_matrix": worst_M, "bias": worst_b}


def fourier(base_hz, seed, lo, hi):
    """Coefficients (a, b) of shape (n, HARMONICS), scaled to the bounds."""
    n = len(Q0)
    rng = np.random.default_rng(seed)
    w = 2 * math.pi * base_hz
    ls = np.arange(1, HARMONICS + 1)
    t = np.linspace(0, 1 / base_hz, 4001)
    a = rng.standard_normal((n, HARMONICS)) / ls
    b = rng.standard_normal((n, HARMONICS)) / ls
    for j in range(n):
        S, C = np.sin(np.outer(t, ls * w)), np.cos(np.outer(t, ls * w))
        q = S @ a[j] + C @ b[j]
        v = (C * ls * w) @ a[j] - (S * ls * w) @ b[j]
        amp = min(AMPLITUDE[j], Q0[j] - lo[j] - 0.1, hi[j] - 0.1 - Q0[j])
        s = min(amp / np.abs(q).max(), VMAX[j] / np.abs(v).max())
        a[j] *= s
        b[j] *= s
    return w, a, b


def desired(t, w, a, b):
    ls = np.arange(1, HARMONICS + 1)
    s, c = np.sin(ls * w * t), np.cos(ls * w * t)
    q = np.array(Q0) + a @ s + b @ c
    v = a @ (c * ls * w) - b @ (s * ls * w)
    acc = -a @ (s * (ls * w) ** 2) - b @ (c * (ls * w) ** 2)
    return q, v, acc


def simulate(m, pm, base_hz, seed, duration):
    """1 kHz states: t, q, qd, qdd, ctrl, dry friction force (= -qfrc_constraint)."""
    pd = pm.createData()
    w, a, b = fourier(base_hz, seed, pm.lowerPositionLimit, pm.upperPositionLimit)
    d = mujoco.MjData(m)
    q_d, v_d, _ = desired(-WARMUP, w, a, b)
    d.qpos[:], d.qvel[:] = q_d, v_d
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    J = np.diag(M)  # includes armature
    wn = 2 * math.pi * PD_NATURAL_FREQUENCY
    kp, kd = wn**2 * J, 2 * wn * J
    arm, damp = np.array(ARMATURE), np.array(DAMPING)
    steps = int(round(duration / DT)) + 1
    warmup = int(round(WARMUP / DT))
    nv = m.nv
    rec = {k: np.empty((steps, nv)) for k in ("q", "qd", "qdd", "tau", "fdry", "qref")}
    rec["t"] = np.arange(steps) * DT
    for k in range(-warmup, steps):
        t = k * DT
        q_d, v_d, a_d = desired(t, w, a, b)
        ff = pin.rnea(pm, pd, q_d, v_d, a_d) + arm * a_d + damp * v_d
        d.ctrl[:] = ff + kp * (q_d - d.qpos) + kd * (v_d - d.qvel)
        mujoco.mj_forward(m, d)
        if k >= 0:
            rec["q"][k], rec["qd"][k], rec["qdd"][k] = d.qpos, d.qvel, d.qacc
            rec["tau"][k] = d.qfrc_actuator
            rec["fdry"][k] = -d.qfrc_constraint
            rec["qref"][k] = q_d
        mujoco.mj_step(m, d)
    assert np.isfinite(rec["tau"]).all() and np.isfinite(rec["q"]).all()
    excitation = {
        "base_frequency_hz": base_hz,
        "seed": seed,
        "q0": Q0,
        "a_sin": a.tolist(),
        "b_cos": b.tolist(),
        "pd_kp": kp.tolist(),
        "pd_kd": kd.tolist(),
    }
    return rec, excitation


def model_form_check(pm, rec):
    """Residuals of the documented model form on the 1 kHz states, before noise."""
    pd = pm.createData()
    arm, damp, fc = np.array(ARMATURE), np.array(DAMPING), np.array(FRICTIONLOSS)
    rb = np.array([pin.rnea(pm, pd, q, v, a) for q, v, a in zip(rec["q"], rec["qd"], rec["qdd"])])
    smooth = rb + arm * rec["qdd"] + damp * rec["qd"]
    exact = rec["tau"] - (smooth + rec["fdry"])
    sign_res = rec["tau"] - (smooth + fc * np.sign(rec["qd"]))
    sliding = np.abs(np.abs(rec["fdry"]) - fc) < 1e-3 * fc
    moving = np.abs(rec["qd"]) > 0.01
    rms = lambda x: np.sqrt(np.mean(x**2, axis=0))
    rms_tau = rms(rec["tau"])
    out = {
        "samples_1khz": len(rec["t"]),
        "rms_tau": rms_tau.tolist(),
        "rms_residual_with_mujoco_dry_friction": rms(exact).tolist(),
        "rms_residual_with_fc_sign_qd": rms(sign_res).tolist(),
        "relative_rms_with_fc_sign_qd": (rms(sign_res) / rms_tau).tolist(),
        "rms_residual_with_fc_sign_qd_where_abs_qd_gt_0.01": [
            float(np.sqrt(np.mean(sign_res[moving[:, j], j] ** 2))) for j in range(sign_res.shape[1])
        ],
        "fraction_sliding": sliding.mean(axis=0).tolist(),
        "fraction_abs_qd_le_0.01": (1 - moving.mean(axis=0)).tolist(),
        "max_abs_residual_with_fc_sign_qd": np.abs(sign_res).max(axis=0).tolist(),
    }
    return out


def logger(rec, seed, stale_rows):
    """Indices of the 1 kHz cycles the logger read, and which rows are stale."""
    rng = np.random.default_rng(1000 + seed)
    steps = len(rec["t"])
    idx = [0]
    while True:
        nxt = idx[-1] + int(rng.choice(LOGGER_STEPS_MS, p=LOGGER_STEP_PROBS))
        if nxt >= steps:
            break
        idx.append(nxt)
    idx = np.array(idx)
    stale = np.sort(rng.choice(np.arange(5, len(idx) - 5), size=stale_rows, replace=False))
    src = idx.copy()
    for r in stale:
        src[r] = src[r - 1]  # the values of the previous row, under the new stamp
    return idx, src, stale, rng


def fmt_rows(cols, fmts):
    return "\n".join(",".join(f.format(x) for f, x in zip(fmts, row)) for row in zip(*cols)) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--urdf", default=os.path.join(ROOT, "robots", "ur5", "ur5.urdf"))
    ap.add_argument("--out-dir", default=os.path.join(ROOT, "tests", "fixtures", "mujoco"))
    ap.add_argument("--duration", type=float, default=20.0, help="seconds per recording")
    args = ap.parse_args()

    m = load_mujoco(args.urdf)
    pm = pin.buildModelFromUrdf(args.urdf)
    pm.gravity.linear = np.array([0.0, 0.0, -9.81])
    assert pm.nq == pm.nv == m.nv == len(ARMATURE), "a 6-joint arm with one coordinate per joint"
    names = [m.joint(i).name for i in range(m.njnt)]
    assert names == [pm.names[i] for i in range(1, pm.njoints)], (names, list(pm.names))
    inertia_check = check_inertias(m, pm, args.urdf)
    os.makedirs(args.out_dir, exist_ok=True)
    n = m.nv
    k = np.array(GAINS)
    truth = {
        "robot": "ur5",
        "urdf": os.path.relpath(os.path.abspath(args.urdf), ROOT).replace(os.sep, "/"),
        "joints": names,
        "generator": "scripts/make_mujoco_fixture.py",
        "mujoco_version": mujoco.__version__,
        "pinocchio_version": pin.__version__,
        "numpy_version": np.__version__,
        "simulation": {
            "integrator": "RK4",
            "timestep_s": DT,
            "gravity": [0.0, 0.0, -9.81],
            "compiler": 'discardvisual="true" balanceinertia="false" fusestatic="false"',
            "friction_constraint": {
                "solreffriction": m.dof_solref[0].tolist(),
                "solimpfriction": m.dof_solimp[0].tolist(),
                "solver": "Newton",
            },
            "inertia_check_max_abs": inertia_check,
            "model_form": "tau = M(q) qdd + C(q,qd) qd + g(q) + armature*qdd + damping*qd + f_dry, "
            "f_dry = frictionloss*sign(qd) while sliding, inside [-frictionloss, frictionloss] near qd = 0",
        },
        "armature_kgm2": ARMATURE,
        "damping_Nms_per_rad": DAMPING,
        "frictionloss_Nm": FRICTIONLOSS,
        "current_gain_Nm_per_A": GAINS,
        "noise": {
            "torque": "additive Gaussian, sigma = 1 % of the joint's RMS torque over the recording "
            "(sigma per recording below); currents carry the same noise divided by k",
            "torque_relative": TORQUE_NOISE_REL,
            "velocity_sigma_rad_per_s": VELOCITY_NOISE,
            "position_resolution_rad": Q_RESOLUTION,
        },
        "logger": {
            "description": "reads the latest 1 kHz control cycle at jittered intervals; "
            "stamps are that cycle's time; stale rows repeat the previous row's values under a new stamp",
            "interval_ms": LOGGER_STEPS_MS,
            "interval_probability": LOGGER_STEP_PROBS,
            "stale_rows_per_recording": N_STALE,
            "raw_exact_duplicate_lines": N_EXACT_DUPLICATES,
            "raw_clock_offset_s": RAW_CLOCK_OFFSET,
        },
        "recordings": {},
    }

    for name, base_hz, seed in RECORDINGS:
        rec, excitation = simulate(m, pm, base_hz, seed, args.duration)
        check = model_form_check(pm, rec)
        idx, src, stale, rng = logger(rec, seed, N_STALE)
        t = rec["t"][idx]
        tau_true = rec["tau"][src]
        sigma = TORQUE_NOISE_REL * np.sqrt(np.mean(rec["tau"] ** 2, axis=0))
        noise_tau = rng.standard_normal(tau_true.shape) * sigma
        noise_v = rng.standard_normal(tau_true.shape) * VELOCITY_NOISE
        for r in stale:  # a stale row repeats the previous row exactly, noise included
            noise_tau[r], noise_v[r] = noise_tau[r - 1], noise_v[r - 1]
        q = np.round(rec["q"][src] / Q_RESOLUTION) * Q_RESOLUTION
        v = rec["qd"][src] + noise_v
        tau = tau_true + noise_tau
        track = np.abs(rec["q"] - rec["qref"]).max(axis=0)

        header = ",".join(["t"] + [f"q{j+1}" for j in range(n)] + [f"v{j+1}" for j in range(n)] + [f"tau{j+1}" for j in range(n)])
        fmts = ["{:.3f}"] + ["{:.5f}"] * n + ["{:.4f}"] * n + ["{:.3f}"] * n
        cols = [t] + [q[:, j] for j in range(n)] + [v[:, j] for j in range(n)] + [tau[:, j] for j in range(n)]
        path = os.path.join(args.out_dir, name + ".csv")
        with open(path, "w") as f:
            f.write(header + "\n" + fmt_rows(cols, fmts))
        files = {name + ".csv": {"layout": "dyngen", "header": header, "units": "s, rad, rad/s, N m", "rows": len(t)}}

        if name == "ur5_identify":
            cur = tau / k
            deg = 180 / math.pi
            raw_cols = (
                [t + RAW_CLOCK_OFFSET]
                + [q[:, j] * deg for j in range(n)]
                + [v[:, j] * deg for j in range(n)]
                + [cur[:, j] for j in range(n)]
            )
            raw_fmts = ["{:.3f}"] + ["{:.4f}"] * n + ["{:.3f}"] * n + ["{:.5f}"] * n
            lines = fmt_rows(raw_cols, raw_fmts).splitlines()
            dup = np.sort(rng.choice(np.arange(5, len(lines) - 5), size=N_EXACT_DUPLICATES, replace=False))
            out = []
            for r, line in enumerate(lines):
                out.append(line)
                if r in dup:
                    out.append(line)
            raw_name = name + "_raw.csv"
            with open(os.path.join(args.out_dir, raw_name), "w") as f:
                f.write("\n".join(out) + "\n")
            files[raw_name] = {
                "layout": "raw logger, no header",
                "columns": ["t"] + [f"q{j+1}" for j in range(n)] + [f"qd{j+1}" for j in range(n)] + [f"i{j+1}" for j in range(n)],
                "units": "s (logger clock, first row at raw_clock_offset_s), deg, deg/s, A (tau = k * i)",
                "rows": len(out),
                "exact_duplicate_lines_1based": [int(r) + 2 + i for i, r in enumerate(dup)],
            }

        steps = np.diff(t) * 1000
        truth["recordings"][name] = {
            "files": files,
            "duration_s": float(t[-1]),
            "logger_rows": int(len(t)),
            "logger_interval_ms": {"min": float(steps.min()), "max": float(steps.max()), "mean": float(steps.mean())},
            "stale_rows_1based_data_row": (stale + 1).tolist(),
            "torque_noise_sigma_Nm": sigma.tolist(),
            "max_abs_torque_Nm": np.abs(rec["tau"]).max(axis=0).tolist(),
            "max_abs_qd_rad_per_s": np.abs(rec["qd"]).max(axis=0).tolist(),
            "max_tracking_error_rad": track.tolist(),
            "excitation": excitation,
            "model_form_check_1khz": check,
        }
        fmt = lambda xs: "[" + ", ".join(f"{x:.3g}" for x in xs) + "]"
        print(f"{name}: {len(t)} rows, steps {steps.min():.0f}-{steps.max():.0f} ms (mean {steps.mean():.2f}), "
              f"{len(stale)} stale rows", file=sys.stderr)
        print(f"  RMS tau                      {fmt(check['rms_tau'])} N m", file=sys.stderr)
        print(f"  max |tau|                    {fmt(np.abs(rec['tau']).max(axis=0))} N m", file=sys.stderr)
        print(f"  max tracking error           {fmt(track)} rad", file=sys.stderr)
        print(f"  model form, MuJoCo's f_dry:  RMS residual {fmt(check['rms_residual_with_mujoco_dry_friction'])} N m",
              file=sys.stderr)
        print(f"  model form, Fc*sign(qd):     RMS residual {fmt(check['rms_residual_with_fc_sign_qd'])} N m "
              f"(relative {fmt(check['relative_rms_with_fc_sign_qd'])})", file=sys.stderr)
        print(f"    where |qd| > 0.01 rad/s:   RMS residual {fmt(check['rms_residual_with_fc_sign_qd_where_abs_qd_gt_0.01'])} N m",
              file=sys.stderr)
        print(f"    fraction sliding (|f_dry| = Fc): {fmt(check['fraction_sliding'])}", file=sys.stderr)

    with open(os.path.join(args.out_dir, "ur5_truth.json"), "w") as f:
        json.dump(truth, f, indent=1)
        f.write("\n")
    for fn in sorted(os.listdir(args.out_dir)):
        print(f"wrote {os.path.join(args.out_dir, fn)} ({os.path.getsize(os.path.join(args.out_dir, fn))} bytes)",
              file=sys.stderr)


if __name__ == "__main__":
    main()
