"""Identify one robot model from many recordings with Dask.

Identification from joint torques is a sum over samples: each recording is
compressed on its own into a partial factor (per joint the triangular factor of its
rows of ``[A y]``), the partials merge exactly, and the merged partial is solved
once. Here that is a map-reduce on a Dask cluster:

* map: one recording -> :func:`dyngen.identify_partial` (on a worker, in parallel);
* reduce: merge the partials pairwise, a tree of :func:`dyngen.merge_partials`;
* solve: :meth:`dyngen.Partial.solve` with the estimator of your choice.

The result equals :func:`dyngen.identify` on one file holding all the samples, up
to rounding (each recording is read, filtered and differentiated on its own, so the
equality is exact when the recordings are the pieces of one: with measured
velocities and accelerations and ``--raw-states``).

On a local cluster (the default), with recordings of your own::

    python fleet_dask.py ROBOT.urdf run1.csv run2.csv ...

or with recordings simulated here (a UR5 along sums of sines, torques with noise)::

    python fleet_dask.py --simulate 16

On a real cluster: install dyngen on every machine (``pip install ./python``), start
a scheduler and workers::

    dask scheduler                       # on one machine; prints tcp://HOST:8786
    dask worker tcp://HOST:8786          # on every worker machine

and run this script against it. The workers read the robot and the recordings by
the paths given, so put them where every worker sees them under the same path (a
shared file system)::

    python fleet_dask.py --scheduler tcp://HOST:8786 /shared/ur5.urdf /shared/runs/*.csv

Only the partials travel between the machines (about 100 kB each for a 6-joint
arm, pickled as their JSON text), never the recordings.
"""

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np

import dyngen

UR5 = Path(__file__).resolve().parents[2] / "robots" / "ur5" / "ur5.urdf"


def simulate(robot_path, directory, count, samples=1000, seed=1, noise=0.05):
    """One motion of the robot along sums of sines (100 Hz), its torques those of
    the URDF's parameters with every body scaled by its own factor plus Gaussian
    noise of ``noise`` N·m, written in dyngen's CSV schema (positions, velocities,
    accelerations, torques) as ``count`` recordings of ``samples`` samples each, and
    as one file holding them all.

    Returns ``(recordings, whole)``: the paths."""
    robot = dyngen.load(robot_path)
    rng = np.random.default_rng(seed)
    truth = robot.params * np.repeat(rng.uniform(0.7, 1.4, robot.nbodies), 10)
    n = robot.nv
    t = np.arange(count * samples) * 0.01
    amplitude = rng.uniform(0.3, 0.8, (n, 3))
    frequency = rng.uniform(0.1, 0.6, (n, 3)) * 2 * np.pi
    phase = rng.uniform(0, 2 * np.pi, (n, 3))
    arg = frequency[None] * t[:, None, None] + phase[None]
    q = np.sum(amplitude[None] * np.sin(arg), axis=2)
    v = np.sum(amplitude[None] * frequency[None] * np.cos(arg), axis=2)
    a = -np.sum(amplitude[None] * frequency[None] ** 2 * np.sin(arg), axis=2)
    tau = robot.rnea(q, v, a, params=truth) + rng.normal(0.0, noise, (len(t), n))
    rows = np.column_stack([t, q, v, a, tau])
    header = ",".join(["t"] + [f"{x}{j + 1}" for x in ("q", "v", "a", "tau") for j in range(n)])
    directory = Path(directory)

    def write(path, part):
        np.savetxt(path, part, delimiter=",", header=header, comments="", fmt="%.17g")
        return path

    recordings = [write(directory / f"run{k:03d}.csv", rows[k * samples:(k + 1) * samples]) for k in range(count)]
    return recordings, write(directory / "all.csv", rows)


def fleet_identify(client, robot_path, recordings, method="wls", **row_options):
    """Identifies the robot at ``robot_path`` from ``recordings`` on the Dask
    ``client``: every recording's partial on a worker (``row_options``: those of
    :func:`dyngen.identify_partial`, e.g. ``raw_states=True``), merged pairwise in a
    tree on the workers, solved with ``method``. Returns ``(result, partial)``: the
    dict of :func:`dyngen.identify` and the merged partial."""
    robot_path = os.fspath(robot_path)
    paths = [os.fspath(p) for p in recordings]
    level = client.map(dyngen.identify_partial, [robot_path] * len(paths), paths, **row_options)
    while len(level) > 1:
        pairs = [level[i:i + 2] for i in range(0, len(level), 2)]
        level = [client.submit(dyngen.merge_partials, pair) if len(pair) == 2 else pair[0] for pair in pairs]
    partial = level[0].result()
    return partial.solve(robot_path, method=method), partial


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("robot", nargs="?", help="the URDF (default: the UR5 shipped with dyngen, with --simulate)")
    parser.add_argument("recordings", nargs="*", help="the recordings (CSV)")
    parser.add_argument("--scheduler", help="a Dask scheduler's address, tcp://HOST:8786 (default: a local cluster)")
    parser.add_argument("--workers", type=int, default=2, help="workers of the local cluster (default 2)")
    parser.add_argument("--simulate", type=int, metavar="N", help="simulate N recordings of the UR5 and use them")
    parser.add_argument("--samples", type=int, default=1000, help="samples per simulated recording (default 1000)")
    parser.add_argument("--method", default="wls", help="the estimator: ols, wls (default), tls, ridge, consistent")
    parser.add_argument("--friction", default="none", help="joint terms: none (default), sign or smooth")
    parser.add_argument("--cutoff", type=float, default=10.0, help="low-pass cutoff, Hz (default 10)")
    parser.add_argument("--raw-states", action="store_true", help="use measured positions and velocities as read")
    args = parser.parse_args()

    from dask.distributed import Client, LocalCluster

    workdir = None
    robot, recordings, whole = args.robot, args.recordings, None
    if args.simulate:
        workdir = tempfile.TemporaryDirectory()
        robot = robot or str(UR5)
        recordings, whole = simulate(robot, workdir.name, args.simulate, args.samples)
        # Pieces of one motion: read as they are, each piece's rows are the whole file's.
        args.raw_states = True
    if not robot or not recordings:
        parser.error("give a robot and recordings, or --simulate N")
    options = dict(friction=args.friction, cutoff=args.cutoff, raw_states=args.raw_states)

    if args.scheduler:
        client = Client(args.scheduler)
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, dashboard_address=None)
        client = Client(cluster)
    with client:
        start = time.perf_counter()
        result, partial = fleet_identify(client, robot, recordings, method=args.method, **options)
        elapsed = time.perf_counter() - start
    where = f"the cluster at {args.scheduler}" if args.scheduler else f"a local cluster of {args.workers} workers"
    print(f"{partial!r}, merged on {where}")
    print(f"identified in {elapsed:.2f} s ({args.method}): rank {result['rank']} of {len(result['names'])}, "
          f"residual RMS per joint {np.array2string(result['residual_rms'], precision=4)}")
    for name, value, sigma, status in zip(result["names"], result["values"], result["sigma"], result["status"]):
        if status == "identified":
            print(f"  {name:8s} {value: .6e} ± {sigma:.1e}")
    combinations = list(zip(result["combinations"], result["combination_values"], result["combination_sigma"]))
    print(f"{len(combinations)} identifiable combinations (base parameters), the first of them:")
    for expression, value, sigma in combinations[:5]:
        print(f"  {expression} = {value:.6e} ± {sigma:.1e}")
    if whole is not None:
        one = dyngen.identify(robot, whole, method=args.method, **options)
        known = ~np.isnan(one["values"])
        x = np.concatenate([result["values"][known], result["combination_values"]])
        y = np.concatenate([one["values"][known], one["combination_values"]])
        diff = np.abs(x - y) / np.max(np.abs(y))
        print(f"against one file of all {partial.samples} samples: largest difference {diff.max():.1e} "
              "(parameter values and identifiable combinations, relative to the largest)")
    if workdir is not None:
        workdir.cleanup()


if __name__ == "__main__":
    main()
