"""Identities between the algorithms, and the model's attributes."""

import numpy as np

import dyngen
from conftest import ROBOTS, random_states


def close(x, y, tolerance=1e-11):
    scale = max(1.0, np.max(np.abs(y)))
    assert np.max(np.abs(np.asarray(x) - y)) <= tolerance * scale


def test_mass_matrix_symmetric_positive_definite(robot):
    q, _, _ = random_states(robot, 20, np.random.default_rng(1))
    for m in robot.crba(q):
        assert np.array_equal(m, m.T)
        assert np.min(np.linalg.eigvalsh(m)) > 0.0


def test_aba_inverts_rnea(robot):
    q, v, a = random_states(robot, 20, np.random.default_rng(1))
    tau = robot.rnea(q, v, a)
    close(robot.aba(q, v, tau), a, 1e-9)


def test_rnea_is_mass_matrix_times_a_plus_bias(robot):
    q, v, a = random_states(robot, 20, np.random.default_rng(1))
    m = robot.crba(q)
    close(robot.rnea(q, v, a), np.einsum("nij,nj->ni", m, a) + robot.nonlinear_effects(q, v))
    close(robot.generalized_gravity(q), robot.rnea(q, np.zeros_like(v), np.zeros_like(a)))


def test_regressors_are_linear_in_params(robot):
    q, v, a = random_states(robot, 5, np.random.default_rng(1))
    params = robot.params * np.repeat(np.random.default_rng(2).uniform(0.5, 2.0, robot.nbodies), 10)
    y = robot.joint_torque_regressor(q, v, a)
    close(y @ params, robot.rnea(q, v, a, params=params))
    w = robot.joint_wrench_regressor(q, v, a)
    close((w @ params).reshape(5, robot.nbodies, 6), robot.joint_wrenches(q, v, a, params=params))


def test_jacobian_matches_placements(robot):
    """The LOCAL_WORLD_ALIGNED Jacobian's linear rows are the derivative of the frame's
    position along a joint coordinate (central differences, on a revolute joint)."""
    q, _, _ = random_states(robot, 1, np.random.default_rng(1))
    q = q[0]
    frame = robot.frame_names[-1]
    j = robot.frame_jacobian(q, frame)
    # The last joint's coordinate (a 1-coordinate joint on every shipped robot).
    h = 1e-6
    dq = np.zeros(robot.nq)
    dq[-1] = h
    _, t_plus = robot.frame_placement(q + dq, frame)
    _, t_minus = robot.frame_placement(q - dq, frame)
    close((t_plus - t_minus) / (2 * h), j[:3, -1], 1e-7)


def test_derivatives_and_time_variations_are_differences(ur5):
    """On the UR5 (one coordinate per joint, so `q + t v` is the motion): ∂τ/∂q and
    ∂q̈/∂q, J̇ and Ȧ_g against central differences; ∂τ/∂a is M, M⁻¹ inverts it, and the
    classical acceleration with a = 0 is J̇ v in LOCAL_WORLD_ALIGNED."""
    q, v, a = (x[0] for x in random_states(ur5, 1, np.random.default_rng(3)))
    h, frame = 1e-6, "tool0"
    dq, dv, m = ur5.rnea_derivatives(q, v, a)
    assert np.array_equal(m, ur5.crba(q))
    along = lambda f, x, d: (f(x + h * d) - f(x - h * d)) / (2 * h)
    for k in range(ur5.nv):
        e = np.eye(ur5.nv)[k]
        close(dq[:, k], along(lambda x: ur5.rnea(x, v, a), q, e), 1e-7)
        close(dv[:, k], along(lambda x: ur5.rnea(q, x, a), v, e), 1e-7)
    tau = ur5.rnea(q, v, a)
    ddq, ddq_dq, _, minv = ur5.aba_derivatives(q, v, tau)
    close(ddq, a, 1e-9)
    close(minv @ m, np.eye(ur5.nv), 1e-9)
    close(ddq_dq[:, 0], along(lambda x: ur5.aba(x, v, tau), q, np.eye(ur5.nv)[0]), 1e-6)
    j, dj = ur5.frame_jacobian_time_variation(q, v, frame)
    close(dj, along(lambda x: ur5.frame_jacobian(x, frame), q, v), 1e-7)
    close(ur5.frame_classical_acceleration(q, v, np.zeros(ur5.nv), frame), dj @ v)
    ag, ag_dot = ur5.centroidal_map_time_variation(q, v)
    close(ag_dot, along(ur5.centroidal_map, q, v), 1e-7)
    close(ur5.com_jacobian(q) * ur5.params[::10].sum(), ag[:3])


def test_params_setter(ur5):
    q, v, a = random_states(ur5, 3, np.random.default_rng(1))
    nominal = ur5.params
    doubled = 2.0 * nominal
    try:
        ur5.params = doubled
        assert np.array_equal(ur5.params, doubled)
        assert np.array_equal(ur5.rnea(q, v, a), ur5.rnea(q, v, a, params=doubled))
        close(ur5.rnea(q, v, a), 2.0 * ur5.rnea(q, v, a, params=nominal))
    finally:
        ur5.params = nominal
    assert np.array_equal(ur5.params, nominal)


def test_attributes():
    ur5 = dyngen.load(ROBOTS[0][1])
    assert (ur5.name, ur5.nq, ur5.nv, ur5.nbodies) == ("ur5", 6, 6, 6)
    assert ur5.joint_names[0] == "shoulder_pan_joint" and len(ur5.joint_names) == 6
    assert ur5.body_names[-1] == "wrist_3_link"
    assert "tool0" in ur5.frame_names
    assert np.array_equal(ur5.gravity, [0.0, 0.0, -9.81])
    assert ur5.params.shape == (60,)
    assert ur5.warnings == []
    assert repr(ur5) == 'Model(name="ur5", nq=6, nv=6, nbodies=6)'
    humanoid = dyngen.load(ROBOTS[2][1], free_flyer=True)
    assert humanoid.joint_names[0] == "root_joint"
    assert (humanoid.nq, humanoid.nv) == (38, 37)  # 7 + 6 for the free flyer, one continuous joint
    neutral = humanoid.neutral()
    assert np.array_equal(neutral[:7], [0, 0, 0, 0, 0, 0, 1])
    assert dyngen.__version__


def test_docstrings():
    assert dyngen.load.__doc__ and dyngen.Model.__doc__
    for name in ["rnea", "crba", "aba", "forward_kinematics", "frame_placement", "frame_jacobian",
                 "joint_torque_regressor", "joint_wrench_regressor", "joint_wrenches",
                 "nonlinear_effects", "generalized_gravity", "neutral"]:
        assert getattr(dyngen.Model, name).__doc__, name


def test_principal_regressor_and_base_parameters(robot):
    """Yp @ principal_params is rnea; for both kinds, the base regressor
    Y[..., independent] times beta = K @ params is rnea too, with K's shape and the
    analysis's own checks agreeing."""
    q, v, a = random_states(robot, 4, np.random.default_rng(4))
    tau = robot.rnea(q, v, a)
    yp = robot.principal_regressor(q, v, a)
    assert yp.shape == (4, robot.nv, 4 * robot.nbodies)
    close(yp @ robot.principal_params, tau)
    y = robot.joint_torque_regressor(q, v, a)
    for kind, regressor, params, per_body in [
        ("standard", y, robot.params, 10),
        ("principal", yp, robot.principal_params, 4),
    ]:
        base = robot.base_parameters(kind)
        p = per_body * robot.nbodies
        b = len(base["independent"])
        assert base["K"].shape == (b, p) and len(base["groupings"]) == b and len(base["names"]) == p
        assert base["consistent"] and base["confirmed"] and base["rank_check"] == b
        assert 0 < b < p
        close(regressor[..., base["independent"]] @ (base["K"] @ params), tau)
