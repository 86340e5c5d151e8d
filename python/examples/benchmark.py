"""Times dyngen's Python package against Pinocchio: per call from Python (one state,
the interpreter's overhead included) and per state in a batch of 10,000 (one thread,
and every core), beside Pinocchio's Python bindings called state by state and,
when given its benchmark binary, Pinocchio's C++ per state.

    python python/examples/benchmark.py                       # needs `pip install pin`
    python python/examples/benchmark.py --pinocchio-bench PATH/bench_hdr

`--pinocchio-bench` is a program that takes `URDF STATES SECONDS` and prints one line
`name nanoseconds` per algorithm (`rnea`, `regressor`, `crba_local`, `aba_local`,
`rnea_derivatives`, `aba_derivatives`, `frame_jacobian`, `ccrba`), as the C++
benchmark of Pinocchio's own algorithms compiled on the machine. Build the package
optimised (`pip install ./python`) before timing it. Times are the best of a few
repetitions; only ratios measured in one sitting on one machine mean anything.
"""

import argparse
import os
import subprocess
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

import dyngen

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = [
    ("ur5", ROOT / "robots" / "ur5" / "ur5.urdf", False),
    ("panda", ROOT / "robots" / "panda" / "panda.urdf", False),
    ("humanoid31", ROOT / "robots" / "humanoid31" / "humanoid31.urdf", True),
]
N = 10_000


def best(f, repeat):
    """The best of `repeat` wall-clock times of `f()`, in seconds."""
    t = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        t = min(t, time.perf_counter() - start)
    return t


def states(robot, model, n, rng):
    """`n` random states for dyngen, and the same configurations for Pinocchio (whose
    continuous joints have two coordinates, cos θ and sin θ, where dyngen has θ; both
    number the joints alike on the shipped robots)."""
    q = rng.uniform(-np.pi, np.pi, (n, robot.nq))
    if robot.joint_names[0] == "root_joint":
        q[:, :3] = rng.uniform(-1, 1, (n, 3))
        quat = rng.normal(size=(n, 4))
        q[:, 3:7] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    v, a = rng.uniform(-2, 2, (2, n, robot.nv))
    assert list(model.names)[1:] == robot.joint_names
    pin_q = np.empty((n, model.nq))
    offset = 0
    for joint in list(model.joints)[1:]:
        if joint.nq == 2 and joint.nv == 1:  # continuous
            pin_q[:, joint.idx_q] = np.cos(q[:, offset])
            pin_q[:, joint.idx_q + 1] = np.sin(q[:, offset])
            offset += 1
        else:
            pin_q[:, joint.idx_q : joint.idx_q + joint.nq] = q[:, offset : offset + joint.nq]
            offset += joint.nq
    return q, pin_q, v, a


def cases(robot, model, data, frame, fid):
    """Per algorithm: dyngen's call, Pinocchio's Python call, the C++ benchmark's name."""
    lwa = pin.LOCAL_WORLD_ALIGNED
    return [
        ("rnea", lambda q, v, a: robot.rnea(q, v, a), lambda q, v, a: pin.rnea(model, data, q, v, a), "rnea"),
        ("crba", lambda q, v, a: robot.crba(q), lambda q, v, a: pin.crba(model, data, q), "crba_local"),
        ("aba", lambda q, v, a: robot.aba(q, v, a), lambda q, v, a: pin.aba(model, data, q, v, a), "aba_local"),
        ("regressor", lambda q, v, a: robot.joint_torque_regressor(q, v, a),
         lambda q, v, a: pin.computeJointTorqueRegressor(model, data, q, v, a), "regressor"),
        ("rnea_derivatives", lambda q, v, a: robot.rnea_derivatives(q, v, a),
         lambda q, v, a: pin.computeRNEADerivatives(model, data, q, v, a), "rnea_derivatives"),
        ("aba_derivatives", lambda q, v, a: robot.aba_derivatives(q, v, a),
         lambda q, v, a: pin.computeABADerivatives(model, data, q, v, a), "aba_derivatives"),
        ("frame_jacobian", lambda q, v, a: robot.frame_jacobian(q, frame),
         lambda q, v, a: pin.computeFrameJacobian(model, data, q, fid, lwa), "frame_jacobian"),
        ("centroidal_map", lambda q, v, a: robot.centroidal_map(q), lambda q, v, a: pin.ccrba(model, data, q, v),
         "ccrba"),
    ]


def cpp_times(bench, urdf, free_flyer):
    """Pinocchio's C++ per state, ns per algorithm, from its benchmark program."""
    env = dict(os.environ, BENCH_FREEFLYER="1" if free_flyer else "0")
    out = subprocess.run([bench, str(urdf), "1000", "0.5"], capture_output=True, text=True, env=env, check=True)
    times = {}
    for line in out.stdout.splitlines():
        parts = line.split()
        if len(parts) == 2:
            try:
                times[parts[0]] = float(parts[1])
            except ValueError:
                pass
    return times


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pinocchio-bench", help="Pinocchio's C++ benchmark program (URDF STATES SECONDS)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    print("ns per state; best of", args.repeat, "; per call = a Python loop of one-state calls;")
    print("batch = one call on", N, "states (1 thread / every core); Pinocchio: its Python loop, its C++")
    header = f"{'robot':11s} {'algorithm':17s} {'per call':>9s} {'batch 1t':>9s} {'batch all':>9s} " \
             f"{'pin py':>9s} {'pin C++':>9s}"
    print(header)
    for name, urdf, free_flyer in ROBOTS:
        robot = dyngen.load(urdf, free_flyer=free_flyer)
        model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer()) if free_flyer \
            else pin.buildModelFromUrdf(str(urdf))
        data = model.createData()
        frame = robot.frame_names[-1]
        fid = model.getFrameId(frame)
        q, pin_q, v, a = states(robot, model, N, rng)
        cpp = cpp_times(args.pinocchio_bench, urdf, free_flyer) if args.pinocchio_bench else {}
        loop = 1000
        for algorithm, ours, theirs, cpp_name in cases(robot, model, data, frame, fid):
            rows = list(zip(q[:loop], v[:loop], a[:loop]))
            pin_rows = list(zip(pin_q[:loop], v[:loop], a[:loop]))
            per_call = best(lambda: [ours(*s) for s in rows], args.repeat) / loop
            robot.max_threads = 1
            batch_one = best(lambda: ours(q, v, a), args.repeat) / N
            robot.max_threads = None
            batch_all = best(lambda: ours(q, v, a), args.repeat) / N
            pin_py = best(lambda: [theirs(*s) for s in pin_rows], args.repeat) / loop
            c = cpp.get(cpp_name)
            print(f"{name:11s} {algorithm:17s} {1e9 * per_call:9.0f} {1e9 * batch_one:9.0f} "
                  f"{1e9 * batch_all:9.0f} {1e9 * pin_py:9.0f} {'' if c is None else f'{c:9.0f}':>9s}")


if __name__ == "__main__":
    main()
