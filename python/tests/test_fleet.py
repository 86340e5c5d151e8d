"""Partial factors from Python, and the fleet example's map-reduce on a local Dask
cluster: the merged identification equals the one-file identification."""

import importlib.util
import pickle
import re

import numpy as np
import pytest

import dyngen
from conftest import ROBOTS, ROOT

UR5 = ROBOTS[0][1]


def load_example():
    spec = importlib.util.spec_from_file_location("fleet_dask", ROOT / "python" / "examples" / "fleet_dask.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


fleet_dask = load_example()


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    """Five recordings, pieces of one noisy UR5 motion, and the whole motion as one file."""
    return fleet_dask.simulate(UR5, tmp_path_factory.mktemp("fleet"), count=5, samples=300, seed=3)


def max_difference(a, b):
    """The largest difference between two results of :func:`dyngen.identify` (every
    parameter value and identifiable combination), relative to the largest of
    ``b``'s; the same parameters must have values."""
    known = ~np.isnan(b["values"])
    assert np.array_equal(known, ~np.isnan(a["values"]))
    x = np.concatenate([a["values"][known], a["combination_values"]])
    y = np.concatenate([b["values"][known], b["combination_values"]])
    return np.max(np.abs(x - y)) / np.max(np.abs(y))


@pytest.mark.parametrize("method", ["ols", "wls"])
def test_merged_partials_identify_as_one_file(recordings, method):
    parts, whole = recordings
    one = dyngen.identify(UR5, whole, method=method, friction="none", raw_states=True)
    partials = [dyngen.identify_partial(UR5, p, raw_states=True) for p in parts]
    merged = dyngen.merge_partials(partials)
    assert merged.recordings == [str(p) for p in parts]
    assert merged.samples == 1500
    result = merged.solve(UR5, method=method)
    assert result["names"] == one["names"] and result["status"] == one["status"]
    assert max_difference(result, one) <= 1e-12
    # A tree: (0 + 1) + (2 + (3 + 4)).
    tree = partials[0].merge(partials[1]).merge(partials[2].merge(partials[3].merge(partials[4])))
    assert max_difference(tree.solve(UR5, method=method), one) <= 1e-12


def test_a_partial_pickles_and_saves_exactly(recordings, tmp_path):
    parts, _ = recordings
    partial = dyngen.identify_partial(UR5, parts[0], raw_states=True, friction="sign")
    again = pickle.loads(pickle.dumps(partial))
    assert isinstance(again, dyngen.Partial)
    assert again.to_json() == partial.to_json()
    path = tmp_path / "run.part"
    partial.save(path)
    assert dyngen.load_partial(path).to_json() == partial.to_json()
    assert dyngen.Partial(path.read_text()).parameters == partial.parameters
    assert len(partial.parameters) == 14 * 6
    assert repr(partial).startswith("Partial(ur5: 1 recordings, 300 samples, 84 parameters")


def test_dask_map_reduce_on_a_local_cluster(recordings):
    distributed = pytest.importorskip("dask.distributed")
    parts, whole = recordings
    one = dyngen.identify(UR5, whole, method="wls", friction="none", raw_states=True)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            result, partial = fleet_dask.fleet_identify(client, UR5, parts, method="wls", raw_states=True)
    assert partial.recordings == [str(p) for p in parts]
    assert max_difference(result, one) <= 1e-12


def test_partials_of_other_options_are_refused(recordings):
    parts, _ = recordings
    a = dyngen.identify_partial(UR5, parts[0], raw_states=True)
    b = dyngen.identify_partial(UR5, parts[1], raw_states=True, cutoff=5.0)
    message = (f"merge_partials: the partial of {parts[0]} and the partial of {parts[1]} were made for different "
               "cutoff: 10 Hz against 5 Hz")
    with pytest.raises(ValueError, match=re.escape(message)):
        dyngen.merge_partials([a, b])
    with pytest.raises(ValueError, match="different cutoff"):
        a.merge(b)
    with pytest.raises(ValueError, match=re.escape("merge_partials: no partial factors to merge")):
        dyngen.merge_partials([])


def test_another_robot_is_refused(recordings):
    parts, _ = recordings
    a = dyngen.identify_partial(UR5, parts[0], raw_states=True)
    with pytest.raises(ValueError, match=re.escape(f"Partial.solve: {ROBOTS[1][1]}: not the robot the partial was "
                                                   "made for: different robots: the partial's robot `ur5`")):
        a.solve(ROBOTS[1][1])


def test_options_that_need_the_rows_are_refused(recordings):
    parts, _ = recordings
    with pytest.raises(ValueError, match=re.escape("identify_partial: friction auto cannot be written as a partial")):
        dyngen.identify_partial(UR5, parts[0], friction="auto")
    with pytest.raises(ValueError, match=re.escape("identify_partial: mode mim cannot be written as a partial")):
        dyngen.identify_partial(UR5, parts[0], mode="mim")


def test_corrupt_and_other_version_files_are_refused(recordings, tmp_path):
    parts, _ = recordings
    text = dyngen.identify_partial(UR5, parts[0], raw_states=True).to_json()
    cut = tmp_path / "cut.part"
    cut.write_text(text[: len(text) // 2])
    with pytest.raises(ValueError, match=re.escape(f"load_partial: {cut}: not a partial factor file (")):
        dyngen.load_partial(cut)
    with pytest.raises(ValueError, match=re.escape("a `dyngen-partial/2` file; this dyngen reads partial factors of "
                                                   "schema `dyngen-partial/1`")):
        dyngen.Partial(text.replace("dyngen-partial/1", "dyngen-partial/2"))
    with pytest.raises(OSError, match="missing.part"):
        dyngen.load_partial(tmp_path / "missing.part")
