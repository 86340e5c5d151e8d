"""Bad input raises the documented exception with a message that says what is wrong."""

import re

import numpy as np
import pytest

import dyngen
from conftest import ROOT, random_states


@pytest.fixture
def state(ur5):
    q, v, a = random_states(ur5, 5, np.random.default_rng(1))
    return q, v, a


def test_wrong_length_names_argument_and_shapes(ur5, state):
    q, v, a = state
    with pytest.raises(ValueError, match=re.escape("rnea: `v` must have shape (6,) for one state or (N, 6) for a batch; found shape (5,)")):
        ur5.rnea(q[0], v[0][:5], a[0])


def test_wrong_dimension(ur5, state):
    with pytest.raises(ValueError, match=re.escape("crba: `q` must have shape (6,) for one state or (N, 6) for a batch; found shape (5, 6, 1)")):
        ur5.crba(state[0][:, :, None])


def test_batch_rows_differ(ur5, state):
    q, v, a = state
    with pytest.raises(ValueError, match=re.escape("rnea: `a` has 4 rows but `q` has 5")):
        ur5.rnea(q, v, a[:4])


def test_one_state_mixed_with_batch(ur5, state):
    q, v, a = state
    with pytest.raises(ValueError, match=re.escape("aba: `v` has shape (5, 6) but `q` has shape (6,)")):
        ur5.aba(q[0], v, a[0])


def test_non_finite_input_names_row(ur5, state):
    q, v, a = (x.copy() for x in state)
    v[3, 2] = np.nan
    with pytest.raises(ValueError, match=re.escape("rnea: row 3 of `v` has a non-finite entry at index 2")):
        ur5.rnea(q, v, a)


def test_non_finite_input_one_state(ur5, state):
    q = state[0][0].copy()
    q[1] = np.inf
    with pytest.raises(ValueError, match=re.escape("frame_jacobian: `q` has a non-finite entry at index 1")):
        ur5.frame_jacobian(q, "tool0")


def test_non_finite_input_first_row_across_threads(ur5):
    q, v, a = random_states(ur5, 2000, np.random.default_rng(1))
    q[1900, 0] = np.nan
    q[1500, 4] = -np.inf
    ur5.max_threads = 4
    try:
        with pytest.raises(ValueError, match=re.escape("row 1500 of `q` has a non-finite entry at index 4")):
            ur5.crba(q)
    finally:
        ur5.max_threads = None


def test_non_finite_result_names_row(ur5, state):
    # Without mass nothing resists: M = 0 and forward dynamics divides by zero.
    q, v, a = state
    massless = np.zeros_like(ur5.params)
    with pytest.raises(ValueError, match=re.escape("aba: the result of row 0 is not finite")):
        ur5.aba(q, v, a, params=massless)


def test_unknown_frame_lists_frames(ur5, state):
    with pytest.raises(ValueError, match=re.escape("no frame `hand` in `ur5`; its frames are: base_link, shoulder_link")) as info:
        ur5.frame_placement(state[0][0], "hand")
    assert "tool0" in str(info.value)


def test_unknown_reference(ur5, state):
    with pytest.raises(ValueError, match=re.escape("unknown reference `base`; it must be one of: local_world_aligned, local, world")):
        ur5.frame_jacobian(state[0][0], "tool0", reference="base")


def test_unknown_reference_of_the_frame_motions(ur5, state):
    q, v, a = state
    for call in (lambda: ur5.frame_velocity(q[0], v[0], "tool0", "base"),
                 lambda: ur5.frame_classical_acceleration(q[0], v[0], a[0], "tool0", "base"),
                 lambda: ur5.frame_jacobian_time_variation(q[0], v[0], "tool0", "base")):
        with pytest.raises(ValueError, match=re.escape("unknown reference `base`; it must be one of")):
            call()


def test_singular_mass_matrix_in_the_derivatives(ur5, state):
    q, v, a = state
    massless = np.zeros_like(ur5.params)
    with pytest.raises(ValueError, match=re.escape("aba_derivatives: the result of row 0 is not finite")):
        ur5.aba_derivatives(q, v, a, params=massless)


def test_unknown_base_parameter_kind(ur5):
    with pytest.raises(ValueError, match=re.escape("base_parameters: unknown kind `minimal`; it must be one of: standard, principal")):
        ur5.base_parameters("minimal")


def test_params_wrong_length(ur5, state):
    q, v, a = state
    with pytest.raises(ValueError, match=re.escape("rnea: `params` must have shape (60,) (10 per body, 6 bodies); found shape (59,)")):
        ur5.rnea(q, v, a, params=ur5.params[:59])


def test_params_setter_refuses_non_finite(ur5):
    params = ur5.params
    params[7] = np.nan
    with pytest.raises(ValueError, match=re.escape("`params` has a non-finite entry at index 7")):
        ur5.params = params
    assert np.all(np.isfinite(ur5.params))


def test_not_numbers(ur5, state):
    q, v, a = state
    with pytest.raises(TypeError, match=re.escape("`q` must be an array of real numbers")):
        ur5.rnea("not a state", v[0], a[0])


def test_max_threads_zero(ur5):
    with pytest.raises(ValueError, match="at least 1"):
        ur5.max_threads = 0


def test_missing_file():
    with pytest.raises(dyngen.LoadError, match="no_such_robot.urdf"):
        dyngen.load(ROOT / "no_such_robot.urdf")


def test_bad_file_reports_file_and_line(tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text(
        '<robot name="bad">\n'
        '  <link name="base"/>\n'
        '  <link name="arm"/>\n'
        '  <joint name="j" type="revolute">\n'
        '    <parent link="base"/><child link="nowhere"/>\n'
        '    <axis xyz="0 0 1"/>\n'
        "  </joint>\n"
        "</robot>\n"
    )
    with pytest.raises(dyngen.LoadError, match=re.escape(f"{path}:4: ")) as info:
        dyngen.load(path)
    assert "nowhere" in str(info.value)
    assert issubclass(dyngen.LoadError, ValueError)
