"""A tour of dyngen's Python package on the UR5: load it, evaluate the algorithms on
one state, then time inverse dynamics on a batch of 10,000 states (state by state
from Python, as one batch on one thread, as one batch on every core), and compare
with Pinocchio when its Python bindings (`pip install pin`) are installed.

    python python/examples/tour.py [path/to/robot.urdf]
"""

import sys
import time
from pathlib import Path

import numpy as np

import dyngen

HERE = Path(__file__).resolve().parent
URDF = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE.parents[1] / "robots" / "ur5" / "ur5.urdf"
N = 10_000


def timed(f, repeat=5):
    """The best of `repeat` wall-clock times of `f()`, in seconds, and its result."""
    best, out = float("inf"), None
    for _ in range(repeat):
        start = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - start)
    return best, out


robot = dyngen.load(URDF)
print(robot)
print("joints:", ", ".join(robot.joint_names))
print("frames:", ", ".join(robot.frame_names))

rng = np.random.default_rng(1)
q = rng.uniform(-np.pi, np.pi, robot.nq)
v, a = rng.uniform(-2.0, 2.0, (2, robot.nv))
frame = robot.frame_names[-1]

tau = robot.rnea(q, v, a)
m = robot.crba(q)
rotation, translation = robot.frame_placement(q, frame)
jacobian = robot.frame_jacobian(q, frame)
y = robot.joint_torque_regressor(q, v, a)
np.set_printoptions(precision=4, suppress=True)
print("\none state")
print("  tau = rnea(q, v, a):        ", tau)
print("  eigenvalues of M = crba(q): ", np.linalg.eigvalsh(m))
print("  |aba(q, v, tau) - a|:        %.1e" % np.max(np.abs(robot.aba(q, v, tau) - a)))
print("  |Y params - tau|:            %.1e" % np.max(np.abs(y @ robot.params - tau)))
print(f"  {frame} at", translation, "; J is", jacobian.shape)

Q = rng.uniform(-np.pi, np.pi, (N, robot.nq))
V, A = rng.uniform(-2.0, 2.0, (2, N, robot.nv))
loop_time, loop = timed(lambda: np.stack([robot.rnea(*s) for s in zip(Q, V, A)]), repeat=2)
robot.max_threads = 1
one_time, one = timed(lambda: robot.rnea(Q, V, A))
robot.max_threads = None
all_time, every = timed(lambda: robot.rnea(Q, V, A))
assert np.array_equal(loop, one) and np.array_equal(one, every)
print(f"\nrnea on {N} states (best wall-clock time, this machine):")
print(f"  state by state from Python:   {1e9 * loop_time / N:8.0f} ns per state")
print(f"  one batch, one thread:        {1e9 * one_time / N:8.0f} ns per state")
print(f"  one batch, every core:        {1e9 * all_time / N:8.0f} ns per state")

try:
    import pinocchio as pin
except ImportError:
    print("\nPinocchio's Python bindings are not installed (pip install pin): no comparison.")
else:
    model = pin.buildModelFromUrdf(str(URDF))
    if list(model.names)[1:] != robot.joint_names or model.nq != robot.nq:
        print("\nPinocchio numbers this robot's coordinates differently: no comparison.")
    else:
        data = model.createData()
        pin_time, theirs = timed(lambda: np.stack([pin.rnea(model, data, *s) for s in zip(Q, V, A)]), repeat=2)
        difference = np.max(np.abs(theirs - every)) / np.max(np.abs(theirs))
        print(f"  Pinocchio, state by state:    {1e9 * pin_time / N:8.0f} ns per state")
        print(f"  largest difference to Pinocchio, relative to the largest torque: {difference:.1e}")
