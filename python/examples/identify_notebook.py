"""Identification from Python, notebook style, on the UR5: load the robot, evaluate its
dynamics, record two motions of a "real" robot (its parameters scaled body by body,
torques with 1 % noise), identify the parameters on the first recording, predict the
second, and plot measured against predicted torques with matplotlib.

    python python/examples/identify_notebook.py [--plot torques.png]

Each `# %%` cell runs on its own in a notebook or an editor that knows cells.
"""

# %% Load the robot and evaluate its dynamics.
import argparse
import tempfile
from pathlib import Path

import numpy as np

import dyngen

ROOT = Path(__file__).resolve().parents[2]
URDF = ROOT / "robots" / "ur5" / "ur5.urdf"
parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--plot", help="write the figure to this file (default: show it, when matplotlib can)")
args = parser.parse_args()

robot = dyngen.load(URDF)
print(robot, "joints:", ", ".join(robot.joint_names))
q0 = robot.neutral()
print("gravity torques at the neutral configuration:", np.round(robot.generalized_gravity(q0), 3))

# %% Two recordings of a robot that is not quite its description.
rng = np.random.default_rng(7)
truth = robot.params * np.repeat(rng.uniform(0.8, 1.25, robot.nbodies), 10)


def record(path, seconds, seed):
    """Sums of sines at 100 Hz through `robot.rnea` with the true parameters (one batch
    call), 1 % noise on the torques, written in dyngen's CSV schema."""
    r = np.random.default_rng(seed)
    t = np.arange(int(seconds * 100)) * 0.01
    amplitude = r.uniform(0.3, 0.8, (robot.nv, 3))
    omega = r.uniform(0.1, 0.6, (robot.nv, 3)) * 2 * np.pi
    phase = r.uniform(0, 2 * np.pi, (robot.nv, 3))
    arg = omega[None] * t[:, None, None] + phase[None]
    q = np.sum(amplitude * np.sin(arg), axis=2)
    v = np.sum(amplitude * omega * np.cos(arg), axis=2)
    a = -np.sum(amplitude * omega**2 * np.sin(arg), axis=2)
    tau = robot.rnea(q, v, a, params=truth)
    tau += 0.01 * np.std(tau, axis=0) * r.standard_normal(tau.shape)
    header = ["t"] + [f"{x}{j + 1}" for x in ("q", "v", "a", "tau") for j in range(robot.nv)]
    np.savetxt(path, np.column_stack([t, q, v, a, tau]), delimiter=",", header=",".join(header), comments="",
               fmt="%.17g")
    return t, q, v, a, tau


folder = Path(tempfile.mkdtemp())
record(folder / "train.csv", 30, 1)
t, q, v, a, tau = record(folder / "test.csv", 10, 2)

# %% Identify on one recording, predict the other.
result = dyngen.identify(URDF, folder / "train.csv", method="wls", raw_states=True, validate=folder / "test.csv")
print(f"rank {result['rank']} of {len(result['names'])}; identifiable combinations:")
for text, value, sigma in zip(result["combinations"][:5], result["combination_values"], result["combination_sigma"]):
    print(f"  {text} = {value:.4f} ± {sigma:.1e}")
validation = result["validation"]
print("held-out relative error per joint:", np.round(validation["relative"], 4), "overall", round(validation["overall"], 4))
truth_combinations = result["combination_matrix"] @ truth
print("largest error of the combinations against the truth:",
      f"{np.max(np.abs(result['combination_values'] - truth_combinations)):.2e}")

# %% Measured against predicted torques of the held-out recording.
# Parameters with a value are taken as they are; the others (NaN) only in identifiable
# combinations: any parameters with those combinations predict the same torques.
values = result["values"].copy()
known = ~np.isnan(values)
k, c = result["combination_matrix"], result["combination_values"]
rest = np.linalg.lstsq(k[:, ~known], c - k[:, known] @ values[known], rcond=None)[0]
values[~known] = rest
predicted = robot.joint_torque_regressor(q, v, a) @ values
try:
    import matplotlib

    if args.plot:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed (pip install matplotlib): no figure")
else:
    fig, axes = plt.subplots(robot.nv, 1, sharex=True, figsize=(8, 10))
    for j, ax in enumerate(axes):
        ax.plot(t, tau[:, j], label="measured", lw=1)
        ax.plot(t, predicted[:, j], label="predicted", lw=1, ls="--")
        ax.set_ylabel(f"τ{j + 1} (N·m)")
    axes[0].legend(loc="upper right")
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(f"UR5, held-out recording: overall relative error {validation['overall']:.3%}")
    if args.plot:
        fig.savefig(args.plot, dpi=100)
        print("wrote", args.plot)
    else:
        plt.show()
