"""A generated robot as a Python module (`dyngen generate --python`): the UR5's package
written, built by pip, imported; its batched kernels against Pinocchio and the
run-time model, one state against the batch, and its errors."""

import importlib
import os
import re
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

from conftest import ROBOTS, ROOT, dyngen_command, random_states

URDF = ROBOTS[0][1]


@pytest.fixture(scope="module")
def ur5_module(tmp_path_factory):
    package = tmp_path_factory.mktemp("generated") / "ur5-python"
    dyngen_command("generate", URDF, "--name", "Ur5", "--python", package)
    # Built in the dev profile against the workspace's target folder, so that what
    # the package's own build left (pyo3, numpy) is reused.
    env = dict(os.environ, CARGO_TARGET_DIR=str(ROOT / "target"), MATURIN_PEP517_ARGS="--profile dev")
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--force-reinstall",
         "--no-deps", str(package)],
        env=env, check=True,
    )
    importlib.invalidate_caches()
    return importlib.import_module("ur5")


@pytest.fixture(scope="module")
def states(ur5):
    return random_states(ur5, 300, np.random.default_rng(5))


def test_sizes_and_names(ur5_module, ur5):
    assert (ur5_module.NQ, ur5_module.NV, ur5_module.NPARAMS) == (ur5.nq, ur5.nv, 10 * ur5.nbodies)
    assert ur5_module.JOINT_NAMES == ur5.joint_names
    assert np.array_equal(ur5_module.nominal_params(), ur5.params)


def test_batched_kernels_match_pinocchio_and_the_run_time_model(ur5_module, ur5, states):
    model = pin.buildModelFromUrdf(str(URDF))
    data = model.createData()
    q, v, a = states
    tau = ur5_module.rnea(q, v, a)
    for k in range(0, 300, 37):
        theirs = pin.rnea(model, data, q[k], v[k], a[k])
        assert np.max(np.abs(tau[k] - theirs)) <= 1e-12 * max(1.0, np.max(np.abs(theirs)))
        m = pin.crba(model, data, q[k])
        m = np.triu(m) + np.triu(m, 1).T
        assert np.max(np.abs(ur5_module.crba(q[k]) - m)) <= 1e-12 * max(1.0, np.max(np.abs(m)))
    scale = lambda y: max(1.0, np.max(np.abs(y)))
    for ours, theirs in [
        (tau, ur5.rnea(q, v, a)),
        (ur5_module.nonlinear_effects(q, v), ur5.nonlinear_effects(q, v)),
        (ur5_module.generalized_gravity(q), ur5.generalized_gravity(q)),
        (ur5_module.crba(q), ur5.crba(q)),
        (ur5_module.aba(q, v, tau), a),
        (ur5_module.joint_torque_regressor(q, v, a), ur5.joint_torque_regressor(q, v, a)),
        (ur5_module.rnea(q, v, a, params=2 * ur5.params), 2 * tau),
        (ur5_module.centroidal_map(q), ur5.centroidal_map(q)),
    ] + [
        (ur5_module.frame_jacobian(q, "tool0", reference), ur5.frame_jacobian(q, "tool0", reference))
        for reference in ("local_world_aligned", "local", "world")
    ]:
        assert np.max(np.abs(ours - theirs)) <= 1e-11 * scale(theirs)
    assert ur5_module.FRAME_NAMES == ur5.frame_names


def test_one_state_equals_its_row_and_threads_do_not_change_results(ur5_module, states):
    q, v, a = states
    batch = ur5_module.rnea(q, v, a)
    for k in (0, 7, 299):
        assert np.array_equal(ur5_module.rnea(q[k], v[k], a[k]), batch[k])
    big = [np.tile(x, (4, 1)) for x in states]
    assert np.array_equal(ur5_module.crba(big[0], threads=1), ur5_module.crba(big[0], threads=2))


def test_errors(ur5_module, states):
    q, v, a = states
    with pytest.raises(ValueError, match=re.escape("rnea: `v` must have shape (6,) for one state or (N, 6) for a batch")):
        ur5_module.rnea(q[0], v[0, :5], a[0])
    with pytest.raises(ValueError, match="give every argument as one state"):
        ur5_module.rnea(q, v[0], a)
    bad = q.copy()
    bad[4, 2] = np.nan
    with pytest.raises(ValueError, match=re.escape("crba: `q` has a non-finite entry at row 4, index 2")):
        ur5_module.crba(bad)
    with pytest.raises(ValueError, match=re.escape("aba: the result of row 0 is not finite")):
        ur5_module.aba(q, v, a, params=np.zeros(60))
    with pytest.raises(ValueError, match=re.escape("rnea: `params` must have shape (60,) for one state")):
        ur5_module.rnea(q, v, a, params=np.zeros(59))
    with pytest.raises(ValueError, match="`threads` must be at least 1"):
        ur5_module.rnea(q, v, a, threads=0)
    with pytest.raises(ValueError, match="frame_jacobian: no frame `hand`; the frames are base_link, "):
        ur5_module.frame_jacobian(q, "hand")
    with pytest.raises(ValueError, match="frame_jacobian: reference `global` is none of"):
        ur5_module.frame_jacobian(q, "tool0", "global")
