"""Shared fixtures: the shipped robots loaded by dyngen and by Pinocchio, the mapping
between their coordinates, and random states."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import dyngen

ROOT = Path(__file__).resolve().parents[2]

# name, URDF, on a free flyer
ROBOTS = [
    ("ur5", ROOT / "robots" / "ur5" / "ur5.urdf", False),
    ("panda", ROOT / "robots" / "panda" / "panda.urdf", False),
    ("humanoid31", ROOT / "robots" / "humanoid31" / "humanoid31.urdf", True),
]

# Worst error against Pinocchio per (robot, algorithm), printed after the run.
WORST = {}


def record(robot, algorithm, error):
    key = (robot, algorithm)
    WORST[key] = max(WORST.get(key, 0.0), float(error))


# Under pytest-xdist (`-n`), each worker hands its worst errors to the controller in
# a file of this folder.
WORST_FILES = ROOT / "target" / "pytest-worst"


def pytest_sessionfinish(session):
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if worker and WORST:
        WORST_FILES.mkdir(parents=True, exist_ok=True)
        rows = [[robot, algorithm, error] for (robot, algorithm), error in WORST.items()]
        (WORST_FILES / f"{worker}.json").write_text(json.dumps(rows))


def pytest_terminal_summary(terminalreporter):
    if os.environ.get("PYTEST_XDIST_WORKER"):
        return  # the controller prints every worker's
    worst = dict(WORST)
    for f in sorted(WORST_FILES.glob("*.json")) if WORST_FILES.exists() else []:
        for robot, algorithm, error in json.loads(f.read_text()):
            worst[robot, algorithm] = max(worst.get((robot, algorithm), 0.0), error)
        f.unlink()
    if not worst:
        return
    terminalreporter.section("worst error against Pinocchio (relative to max(1, |value|))")
    for (robot, algorithm), error in sorted(worst.items()):
        terminalreporter.write_line(f"{robot:12s} {algorithm:28s} {error:.2e}")


def dyngen_command(*args):
    """Runs the `dyngen` command (`target/debug/dyngen`, as `cargo test --workspace`
    leaves it; built with `cargo build -p dyngen-cli` when missing) and returns its
    standard output; a failure raises."""
    binary = ROOT / "target" / "debug" / "dyngen"
    if not binary.exists():
        subprocess.run(["cargo", "build", "--quiet", "-p", "dyngen-cli"], cwd=ROOT, check=True)
    return subprocess.run([str(binary), *map(str, args)], cwd=ROOT, capture_output=True, text=True,
                          check=True).stdout


def load(path, free_flyer):
    return dyngen.load(path, free_flyer=free_flyer)


def random_states(robot, n, rng):
    """`n` random states (q, v, a) of a dyngen model: joint angles in [-π, π], a free
    flyer's position in [-1, 1]³ and a uniformly drawn unit quaternion, v and a in
    [-2, 2]."""
    qs = np.empty((n, robot.nq))
    for k in range(n):
        q = rng.uniform(-np.pi, np.pi, robot.nq)
        if robot.joint_names[0] == "root_joint":
            q[:3] = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            q[3:7] = quat / np.linalg.norm(quat)
        qs[k] = q
    vs = rng.uniform(-2.0, 2.0, (n, robot.nv))
    as_ = rng.uniform(-2.0, 2.0, (n, robot.nv))
    return qs, vs, as_


@pytest.fixture(scope="session", params=[r[0] for r in ROBOTS])
def robot_name(request):
    return request.param


@pytest.fixture(scope="session")
def robot(robot_name):
    _, path, free_flyer = next(r for r in ROBOTS if r[0] == robot_name)
    return load(path, free_flyer)


@pytest.fixture(scope="session")
def ur5():
    return load(ROBOTS[0][1], False)
