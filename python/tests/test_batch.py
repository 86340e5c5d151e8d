"""A batch gives bit for bit the results of the states one at a time, on one thread
and split across threads, whatever the layout and type of the input arrays."""

import numpy as np
import pytest

from conftest import random_states

# A batch large enough to be split: at least 512 states per thread.
ROWS = 1200
# The derivatives (dual numbers, many times the work of one evaluation): more than
# one group of lanes and a partial last one, on one thread.
HEAVY_ROWS = 43


def one_by_one(f, *batches):
    """Stacks `f` evaluated state by state; a tuple result is stacked per entry."""
    rows = [f(*row) for row in zip(*batches)]
    if isinstance(rows[0], tuple):
        return tuple(np.stack(parts) for parts in zip(*rows))
    return np.stack(rows)


def assert_identical(x, y):
    if isinstance(x, tuple):
        assert isinstance(y, tuple) and len(x) == len(y)
        for a, b in zip(x, y):
            assert_identical(a, b)
        return
    assert x.dtype == np.float64 and x.flags.c_contiguous
    assert x.shape == y.shape
    assert np.array_equal(x, y)  # bit for bit (no NaN in these results)


def algorithms(robot):
    frame = robot.frame_names[-1]
    params = robot.params * 1.5
    return {
        "rnea": (robot.rnea, 3),
        "rnea params=": (lambda q, v, a: robot.rnea(q, v, a, params=params), 3),
        "nonlinear_effects": (robot.nonlinear_effects, 2),
        "generalized_gravity": (robot.generalized_gravity, 1),
        "crba": (robot.crba, 1),
        "aba": (robot.aba, 3),
        "forward_kinematics": (robot.forward_kinematics, 1),
        "frame_placement": (lambda q: robot.frame_placement(q, frame), 1),
        "frame_jacobian local": (lambda q: robot.frame_jacobian(q, frame, reference="local"), 1),
        "frame_jacobian world": (lambda q: robot.frame_jacobian(q, frame, reference="world"), 1),
        "frame_jacobian lwa": (lambda q: robot.frame_jacobian(q, frame), 1),
        "joint_wrenches": (robot.joint_wrenches, 3),
        "joint_torque_regressor": (robot.joint_torque_regressor, 3),
        "joint_wrench_regressor": (robot.joint_wrench_regressor, 3),
        "rnea_derivatives": (robot.rnea_derivatives, 3),
        "aba_derivatives": (robot.aba_derivatives, 3),
        "frame_velocity": (lambda q, v: robot.frame_velocity(q, v, frame, "local"), 2),
        "frame_classical_acceleration": (lambda q, v, a: robot.frame_classical_acceleration(q, v, a, frame, "world"), 3),
        "frame_jacobian_time_variation": (lambda q, v: robot.frame_jacobian_time_variation(q, v, frame), 2),
        "center_of_mass": (robot.center_of_mass, 1),
        "com_jacobian": (robot.com_jacobian, 1),
        "centroidal_map": (robot.centroidal_map, 1),
        "centroidal_map_time_variation": (robot.centroidal_map_time_variation, 2),
    }


ALGORITHMS = [
    "rnea",
    "rnea params=",
    "nonlinear_effects",
    "generalized_gravity",
    "crba",
    "aba",
    "forward_kinematics",
    "frame_placement",
    "frame_jacobian local",
    "frame_jacobian world",
    "frame_jacobian lwa",
    "joint_wrenches",
    "joint_torque_regressor",
    "joint_wrench_regressor",
    "rnea_derivatives",
    "aba_derivatives",
    "frame_velocity",
    "frame_classical_acceleration",
    "frame_jacobian_time_variation",
    "center_of_mass",
    "com_jacobian",
    "centroidal_map",
    "centroidal_map_time_variation",
]


@pytest.mark.parametrize(
    "algorithm, threads",
    [(a, t) for a in ALGORITHMS for t in (1, 2) if t == 1 or "derivatives" not in a],
)
def test_batch_equals_loop(robot, algorithm, threads):
    f, arity = algorithms(robot)[algorithm]
    if "derivatives" in algorithm:
        rows = HEAVY_ROWS
    else:
        rows = ROWS if robot.nv < 20 or "regressor" not in algorithm else 600
    states = random_states(robot, rows, np.random.default_rng(1))[:arity]
    robot.max_threads = threads
    try:
        batch = f(*states)
    finally:
        robot.max_threads = None
    assert_identical(batch, one_by_one(f, *states))


def test_every_algorithm_is_covered(robot):
    assert sorted(algorithms(robot)) == sorted(ALGORITHMS)


def test_input_layouts(ur5):
    """Fortran-ordered, strided, float32 and list inputs give what their float64
    C-contiguous copies give."""
    q, v, a = random_states(ur5, 40, np.random.default_rng(1))
    expected = ur5.rnea(q, v, a)
    assert_identical(ur5.rnea(np.asfortranarray(q), np.asfortranarray(v), np.asfortranarray(a)), expected)
    wide = np.repeat(q, 2, axis=1)  # every column twice: [:, ::2] is a strided view of q
    assert_identical(ur5.rnea(wide[:, ::2], v, a), expected)
    q32 = q.astype(np.float32)
    assert_identical(ur5.rnea(q32, v, a), ur5.rnea(q32.astype(np.float64), v, a))
    assert_identical(ur5.rnea(q.tolist(), v.tolist(), a.tolist()), expected)
    assert_identical(ur5.rnea(list(q[3]), v[3], a[3]), expected[3])


def test_inputs_are_not_written(ur5):
    q, v, a = random_states(ur5, 300, np.random.default_rng(1))
    copies = [x.copy() for x in (q, v, a)]
    ur5.rnea(q, v, a)
    for x, y in zip((q, v, a), copies):
        assert np.array_equal(x, y)


def test_empty_batch(ur5):
    empty = np.zeros((0, ur5.nv))
    assert ur5.rnea(empty, empty, empty).shape == (0, ur5.nv)
    assert ur5.crba(empty).shape == (0, ur5.nv, ur5.nv)
    r, t = ur5.forward_kinematics(empty)
    assert r.shape == (0, ur5.nbodies, 3, 3) and t.shape == (0, ur5.nbodies, 3)


def test_shapes(robot):
    q, v, a = random_states(robot, 3, np.random.default_rng(1))
    nq, nv, nb = robot.nq, robot.nv, robot.nbodies
    assert robot.rnea(q[0], v[0], a[0]).shape == (nv,)
    assert robot.crba(q).shape == (3, nv, nv)
    assert robot.joint_torque_regressor(q[0], v[0], a[0]).shape == (nv, 10 * nb)
    assert robot.joint_wrench_regressor(q, v, a).shape == (3, 6 * nb, 10 * nb)
    assert robot.joint_wrenches(q, v, a).shape == (3, nb, 6)
    r, t = robot.frame_placement(q[0], robot.frame_names[-1])
    assert r.shape == (3, 3) and t.shape == (3,)
    assert robot.frame_jacobian(q, robot.frame_names[-1]).shape == (3, 6, nv)
    assert robot.neutral().shape == (nq,)
    assert [x.shape for x in robot.rnea_derivatives(q, v, a)] == [(3, nv, nv)] * 3
    assert [x.shape for x in robot.aba_derivatives(q[0], v[0], a[0])] == [(nv,)] + [(nv, nv)] * 3
    assert robot.frame_velocity(q[0], v[0], robot.frame_names[-1]).shape == (6,)
    assert robot.frame_classical_acceleration(q, v, a, robot.frame_names[-1]).shape == (3, 6)
    assert [x.shape for x in robot.frame_jacobian_time_variation(q, v, robot.frame_names[-1])] == [(3, 6, nv)] * 2
    assert robot.center_of_mass(q).shape == (3, 3)
    assert robot.com_jacobian(q[0]).shape == (3, nv)
    assert robot.centroidal_map(q).shape == (3, 6, nv)
    assert [x.shape for x in robot.centroidal_map_time_variation(q[0], v[0])] == [(6, nv)] * 2
