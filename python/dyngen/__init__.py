"""dyngen: rigid-body dynamics of a robot loaded at run time, on numpy arrays.

Load a URDF (or MJCF) with :func:`load`, then evaluate the algorithms of dyngen-algo
on one state (1-D arrays) or a batch (2-D arrays, one state per row)::

    import numpy as np, dyngen
    robot = dyngen.load("ur5.urdf")
    tau = robot.rnea(robot.neutral(), np.zeros(robot.nv), np.zeros(robot.nv))

Batches are evaluated in Rust with the GIL released, split across threads when
large. Conventions are Pinocchio's: spatial vectors ``[linear; angular]``, standard
parameters per body ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``, a free
flyer's quaternion ``[x, y, z, w]``; but a continuous joint has one coordinate, its
angle, where Pinocchio has ``(cos, sin)``.

:func:`identify` runs the identification of ``dyngen identify`` on a recording and
returns its estimate as a dict of numpy arrays. For many recordings,
:func:`identify_partial` compresses each into a :class:`Partial` (on any machine;
picklable), :func:`merge_partials` or :meth:`Partial.merge` merge them exactly, and
:meth:`Partial.solve` gives what :func:`identify` gives on all their samples (see
``examples/fleet_dask.py``).
"""

from ._dyngen import (
    LoadError,
    Model,
    Partial,
    __version__,
    identify,
    identify_partial,
    load,
    load_partial,
    merge_partials,
)

__all__ = [
    "LoadError",
    "Model",
    "Partial",
    "__version__",
    "identify",
    "identify_partial",
    "load",
    "load_partial",
    "merge_partials",
]
