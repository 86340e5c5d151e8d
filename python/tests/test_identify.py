"""`dyngen.identify` on a recording simulated with other parameters than the URDF's:
exact torques, so the identifiable parameters come back exactly."""

import re

import numpy as np
import pytest

import dyngen
from conftest import ROBOTS, ROOT, dyngen_command


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A UR5 moving along sums of sines (100 Hz, 20 s) with every body's parameters
    scaled by its own factor; positions, velocities, accelerations and the torques of
    the scaled parameters, in dyngen's CSV schema."""
    robot = dyngen.load(ROBOTS[0][1])
    rng = np.random.default_rng(1)
    truth = robot.params * np.repeat(rng.uniform(0.7, 1.4, robot.nbodies), 10)
    path = tmp_path_factory.mktemp("identify") / "ur5.csv"
    write_sines(robot, truth, 2000, (0.3, 0.8), rng, path)
    return robot, truth, path


def write_sines(robot, params, samples, amplitudes, rng, path):
    """Every coordinate along a sum of three sines (100 Hz), with the torques of
    `params`, written to `path` in dyngen's CSV schema."""
    t = np.arange(samples) * 0.01
    n = robot.nv
    amplitude = rng.uniform(*amplitudes, (n, 3))
    frequency = rng.uniform(0.1, 0.6, (n, 3)) * 2 * np.pi
    phase = rng.uniform(0, 2 * np.pi, (n, 3))
    arg = frequency[None] * t[:, None, None] + phase[None]
    q = np.sum(amplitude[None] * np.sin(arg), axis=2)
    v = np.sum(amplitude[None] * frequency[None] * np.cos(arg), axis=2)
    a = -np.sum(amplitude[None] * frequency[None] ** 2 * np.sin(arg), axis=2)
    tau = robot.rnea(q, v, a, params=params)
    header = ["t"] + [f"{x}{j + 1}" for x in ("q", "v", "a", "tau") for j in range(n)]
    np.savetxt(path, np.column_stack([t, q, v, a, tau]), delimiter=",", header=",".join(header), comments="",
               fmt="%.17g")


def test_identifies_what_the_data_determines(recording):
    robot, truth, path = recording
    result = dyngen.identify(ROBOTS[0][1], path, raw_states=True)
    names, values, status = result["names"], result["values"], result["status"]
    assert len(names) == len(values) == len(status) == robot.nbodies * 10
    determined = sum(s in ("identified", "not_significant") for s in status)
    assert result["rank"] == determined + len(result["combinations"]) < len(names)
    assert np.max(result["residual_rms"]) < 1e-9 * np.max(np.abs(robot.rnea(*np.zeros((3, robot.nv)), params=truth)))
    identified = [k for k, s in enumerate(status) if s == "identified"]
    assert identified, status
    np.testing.assert_allclose(values[identified], truth[identified], rtol=1e-7, atol=1e-9)
    # The combinations (base parameters) are those of the simulated parameters, not
    # of the URDF's.
    k = result["combination_matrix"]
    assert k.shape == (len(result["combinations"]), len(names))
    np.testing.assert_allclose(result["combination_values"], k @ truth, rtol=1e-8, atol=1e-10)
    assert np.max(np.abs(result["combination_values"] - k @ robot.params)) > 1e-2


def test_unknown_option(recording):
    _, _, path = recording
    with pytest.raises(ValueError, match=re.escape("identify: unknown method `lsq`; it must be one of: ols, wls")):
        dyngen.identify(ROBOTS[0][1], path, method="lsq")


def test_missing_recording(tmp_path):
    with pytest.raises(ValueError, match=re.escape(str(tmp_path / "missing.csv"))):
        dyngen.identify(ROBOTS[0][1], tmp_path / "missing.csv")


def test_recording_of_another_robot(recording):
    _, _, path = recording
    with pytest.raises(ValueError, match="identify: ") as info:
        dyngen.identify(ROBOTS[1][1], path)  # the Panda has 7 joints, the recording 6
    assert "7" in str(info.value)


def test_validation_and_parameters_json(recording, tmp_path):
    """`validate=` predicts a second recording (here the first with a quarter of its
    rows through a recipe window, and all of it): exact data, so every joint's
    relative error is at rounding level; `parameters_json` is what `dyngen validate`
    reads, and gives the same overall error there."""
    robot, truth, path = recording
    window = tmp_path / "window.recipe"
    window.write_text("window = 0:5\n")
    result = dyngen.identify(ROBOTS[0][1], path, raw_states=True, recipe=window, validate=path)
    v = result["validation"]
    assert v["samples"] == 2000  # the training window is not applied to the validation recording
    assert v["joint_names"] == robot.joint_names
    assert v["rms"].shape == v["relative"].shape == v["measured_rms"].shape == (robot.nv,)
    assert np.max(v["relative"]) < 1e-8 and v["overall"] < 1e-8
    assert dyngen.identify(ROBOTS[0][1], path, raw_states=True, validate=path,
                           validate_recipe=window)["validation"]["samples"] == 501
    params = tmp_path / "params.json"
    params.write_text(result["parameters_json"])
    assert '"window": "window = 0:5"' in result["parameters_json"]
    out = dyngen_command("validate", ROBOTS[0][1], params, path)
    overall = float(re.search(r"full precision: ([0-9.e+-]+)", out).group(1))
    assert abs(overall - v["overall"]) <= 1e-12, out
    assert "validation" not in dyngen.identify(ROBOTS[0][1], path, raw_states=True)


def test_validate_recipe_needs_validate(recording):
    _, _, path = recording
    with pytest.raises(ValueError, match=re.escape("`validate_recipe` is the recipe of the `validate` recording")):
        dyngen.identify(ROBOTS[0][1], path, validate_recipe=path)


def test_svg_report(recording, tmp_path):
    """`report=` writes `dyngen identify --report`'s SVG: one plot per joint, never over
    an existing file unless asked."""
    _, _, path = recording
    svg = tmp_path / "report.svg"
    dyngen.identify(ROBOTS[0][1], path, raw_states=True, report=svg)
    text = svg.read_text()
    assert text.startswith("<svg") and text.rstrip().endswith("</svg>"), text[:80]
    robot = dyngen.load(ROBOTS[0][1])
    assert all(name in text for name in robot.joint_names)
    assert "ur5.csv" in text
    with pytest.raises(FileExistsError, match="report.svg: file exists"):
        dyngen.identify(ROBOTS[0][1], path, raw_states=True, report=svg)
    svg.write_text("kept?")
    dyngen.identify(ROBOTS[0][1], path, raw_states=True, report=svg, overwrite=True)
    assert svg.read_text().startswith("<svg")


def test_identifies_a_robot_with_mimic_joints(tmp_path):
    """An arm with a linkage gripper (five joints follow one driven finger joint): the
    recording has one column per coordinate, the leaders', and the base parameters of
    the simulated parameters come back."""
    urdf = ROOT / "tests" / "fixtures" / "mimic" / "arm_linkage_gripper.urdf"
    robot = dyngen.load(urdf)
    assert (robot.nv, robot.nbodies) == (7, 12)
    rng = np.random.default_rng(4)
    truth = robot.params * np.repeat(rng.uniform(0.8, 1.3, robot.nbodies), 10)
    path = tmp_path / "gripper.csv"
    write_sines(robot, truth, 1500, (0.2, 0.6), rng, path)
    result = dyngen.identify(urdf, path, raw_states=True)
    assert len(result["names"]) == 10 * robot.nbodies
    k = result["combination_matrix"]
    np.testing.assert_allclose(result["combination_values"], k @ truth, rtol=1e-7, atol=1e-9)


def test_best_friction_is_chosen_on_held_out_blocks(tmp_path):
    """Joints with viscous, Coulomb and direction-dependent viscous friction and 1 %
    torque noise: the model chosen has friction and the direction-dependent term,
    and each candidate's held-out error is returned."""
    robot = dyngen.load(ROBOTS[0][1])
    rng = np.random.default_rng(7)
    path = tmp_path / "friction.csv"
    write_sines(robot, robot.params, 700, (0.3, 0.8), rng, path)
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    n = robot.nv
    v, tau = data[:, 1 + n:1 + 2 * n], data[:, 1 + 3 * n:]
    tau += 0.5 * v + 2.0 * np.sign(v) + 0.4 * np.abs(v)
    tau += 0.01 * rng.standard_normal(tau.shape) * np.sqrt(np.mean(tau**2, axis=0))
    header = open(path).readline().strip()
    np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.17g")
    base = {"none", "sign-no-rotor-inertia", "sign", "auto", "stribeck"}
    # The one extra term the joints have is the one tried (the default tries three).
    result = dyngen.identify(ROBOTS[0][1], path, friction="best", extra_terms="asymmetric", raw_states=True)
    choice = result["model_choice"]
    assert base < set(choice["held_out"]), choice
    assert "asymmetric" in choice["chosen"], choice
    errors = choice["held_out"]
    assert errors[choice["chosen"]] < min(errors[b] for b in base), choice
    assert errors["none"] > 3 * errors["sign"], choice
    # Without extra terms to try, the friction models alone.
    result = dyngen.identify(ROBOTS[0][1], path, friction="best", extra_terms="none", raw_states=True)
    choice = result["model_choice"]
    assert set(choice["held_out"]) == base
    assert choice["chosen"] in ("sign-no-rotor-inertia", "sign", "auto", "stribeck"), choice
    errors = choice["held_out"]
    assert errors[choice["chosen"]] == min(e for e in errors.values() if e is not None)
    # The term named, and a list that does not parse.
    result = dyngen.identify(ROBOTS[0][1], path, friction="sign", extra_terms="asymmetric", raw_states=True)
    assert [name for name in result["names"] if name.startswith("Fva")] == [f"Fva{j}" for j in range(1, n + 1)]
    with pytest.raises(ValueError, match=re.escape("identify: extra_terms `bogus`: term 1 `bogus` is unknown")):
        dyngen.identify(ROBOTS[0][1], path, friction="sign", extra_terms="bogus")
    # The motor angle's ripple with each joint's gear ratio, and without them.
    ratios = [101.0, 101.0, 101.0, 51.0, 51.0, 51.0][:n]
    result = dyngen.identify(ROBOTS[0][1], path, friction="sign", extra_terms="motor-ripple=1", gear_ratios=ratios,
                             raw_states=True)
    assert [name for name in result["names"] if name.startswith("Tms")] == [f"Tms1_{j}" for j in range(1, n + 1)]
    assert '"gear_ratios"' in result["parameters_json"]
    with pytest.raises(ValueError, match=re.escape("motor-ripple needs each joint's gear ratio")):
        dyngen.identify(ROBOTS[0][1], path, friction="sign", extra_terms="motor-ripple=1")
    with pytest.raises(ValueError, match=re.escape(f"2 values for {n} joints")):
        dyngen.identify(ROBOTS[0][1], path, friction="sign", extra_terms="motor-ripple=1", gear_ratios=[1.0, 2.0])
    with pytest.raises(ValueError, match=re.escape("unknown friction `best`")):
        dyngen.identify_partial(ROBOTS[0][1], path, friction="best")
