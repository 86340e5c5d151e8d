"""Type stubs of the native module ``dyngen._dyngen``."""

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]
Reference = str  # "local_world_aligned" | "local" | "world"

class LoadError(ValueError):
    """A robot description that does not load; the message is dyngen-model's, every
    error as ``file:line: message``."""

def load(path: Union[str, "os.PathLike[str]"], free_flyer: bool = False, strict: bool = False) -> Model:
    """Loads a URDF, or MJCF for a file ending in ``.xml`` or ``.mjcf``.

    ``free_flyer`` puts the root link on a free flyer (7 more positions
    ``[x, y, z, qx, qy, qz, qw]``, 6 more velocities); ``strict`` refuses what is
    otherwise loaded with a warning. Raises :class:`LoadError`."""

def identify(
    robot_path: Union[str, "os.PathLike[str]"],
    data_path: Union[str, "os.PathLike[str]"],
    *,
    mode: str = "standard",
    method: str = "ols",
    friction: Optional[str] = None,
    epsilon: float = 0.01,
    extra_terms: Optional[str] = None,
    gear_ratios: Optional[Sequence[float]] = None,
    ridge_lambda: float = 1e-6,
    cutoff: float = 10.0,
    raw_states: bool = False,
    recipe: Optional[Union[str, "os.PathLike[str]"]] = None,
    validate: Optional[Union[str, "os.PathLike[str]"]] = None,
    validate_recipe: Optional[Union[str, "os.PathLike[str]"]] = None,
    report: Optional[Union[str, "os.PathLike[str]"]] = None,
    overwrite: bool = False,
) -> Dict[str, Any]:
    """Identifies the robot's inertial parameters from a recording, as ``dyngen
    identify`` does: ``mode`` ``"standard"``, ``"principal"`` or ``"mim"``; ``method``
    ``"ols"``, ``"wls"``, ``"tls"``, ``"tls-unscaled"``, ``"ridge"``, ``"consistent"``;
    ``friction`` ``"none"``, ``"sign"``, ``"smooth"``, ``"auto"``, ``"stribeck"``,
    ``"stribeck-smooth"``, ``"best"`` (the model that predicts held-out time blocks
    of the recording best; the errors in ``model_choice``); by default ``"best"`` in
    the standard mode, ``"none"`` otherwise. ``extra_terms``: joint
    terms past friction (``"asymmetric"``, ``"ripple=H"``, ``"load"``, comma-separated)
    and ``"motor-ripple=H"`` with ``gear_ratios`` (one per joint), with ``"sign"``,
    ``"smooth"`` or ``"auto"``; with ``"best"`` the terms it may add
    (default ``"asymmetric,ripple=2,load"``, ``"none"`` for none). ``report``: write ``dyngen identify --report``'s SVG there
    (measured against predicted efforts per joint); an existing file raises
    ``FileExistsError`` unless ``overwrite``. Returns ``names``, ``values``, ``sigma``,
    ``sigma_percent``, ``status``, ``rank``, ``condition_number``, ``residual_rms``,
    ``channels``, ``combinations``, ``combination_matrix``, ``combination_values``, ``combination_sigma``,
    ``warnings``, and with ``friction="best"`` ``model_choice`` (``chosen``,
    ``held_out``, ``epsilons``). Raises :class:`LoadError` or ``ValueError``."""

def identify_partial(
    robot_path: Union[str, "os.PathLike[str]"],
    data_path: Union[str, "os.PathLike[str]"],
    *,
    mode: str = "standard",
    friction: str = "none",
    epsilon: float = 0.01,
    cutoff: float = 10.0,
    raw_states: bool = False,
    recipe: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Partial:
    """The partial factor of one recording (``dyngen identify ROBOT DATA --partial
    OUT``): the options of :func:`identify` that shape the rows; ``mode`` ``"standard"``
    or ``"principal"``, ``friction`` ``"none"``, ``"sign"`` or ``"smooth"`` (``"mim"``,
    ``"auto"`` and the Stribeck models need the rows themselves and are refused).
    Raises :class:`LoadError` or ``ValueError``."""

def merge_partials(partials: List[Partial]) -> Partial:
    """The partials merged in order; ``ValueError`` names two that were made for
    other robots or with other row options."""

def load_partial(path: Union[str, "os.PathLike[str]"]) -> Partial:
    """A partial factor file (``--partial OUT`` or :meth:`Partial.save`). Raises
    ``OSError`` or ``ValueError`` (not a partial, another schema version)."""

class Partial:
    """The sufficient statistics of the joint-torque rows of one or more recordings:
    per joint the triangular factor of its rows of ``[A y]``, the robot, and the
    options that shaped the rows. Partials merge exactly; :meth:`solve` gives what
    :func:`identify` gives on all their samples. Picklable (as its JSON text)."""

    def __init__(self, text: str) -> None:
        """The partial in ``text``, the JSON of :meth:`to_json` or a ``--partial`` file."""
    def to_json(self) -> str:
        """The partial as JSON (schema ``dyngen-partial/1``); numbers read back bit for bit."""
    def save(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes the partial to ``path`` (read by ``dyngen identify ROBOT --merge``)."""
    def merge(self, other: Partial) -> Partial:
        """A new partial holding the rows of both; ``ValueError`` for other robots or row options."""
    def solve(
        self, robot_path: Union[str, "os.PathLike[str]"], *, method: str = "ols", ridge_lambda: float = 1e-6
    ) -> Dict[str, Any]:
        """Identifies the robot the partial was made for from its rows: ``method`` as in
        :func:`identify`; returns the dict of :func:`identify`. Raises
        :class:`LoadError` or ``ValueError`` (another robot, a failing estimate)."""
    @property
    def recordings(self) -> List[str]:
        """The recordings whose rows it holds, in merge order."""
    @property
    def samples(self) -> int:
        """Samples of all its recordings."""
    @property
    def robot(self) -> str:
        """The robot's name."""
    @property
    def parameters(self) -> List[str]:
        """The parameter names, in the regressor's column order."""

class Model:
    """A robot loaded by :func:`load` and the rigid-body algorithms on it.

    Every algorithm takes one state (1-D arrays: ``q`` of length ``nq``; ``v``, ``a``,
    ``tau`` of length ``nv``) or a batch (2-D arrays ``(N, nq)``, ``(N, nv)``) and
    returns the per-state shape, with a leading ``N`` for a batch. Raises
    ``ValueError`` for a wrong shape, a non-finite input or result, an unknown frame
    or reference."""

    @property
    def name(self) -> str:
        """The robot's name."""
    @property
    def nq(self) -> int:
        """Number of position coordinates."""
    @property
    def nv(self) -> int:
        """Number of velocity coordinates."""
    @property
    def nbodies(self) -> int:
        """Number of moving bodies (= joints)."""
    @property
    def joint_names(self) -> List[str]:
        """The joints' names, one per body, in the order of ``q`` and ``v`` (a joint
        that follows another by ``<mimic>`` is listed but has no coordinate)."""
    @property
    def body_names(self) -> List[str]:
        """The moving bodies' names, body 1 first."""
    @property
    def frame_names(self) -> List[str]:
        """Every named frame, the base first."""
    @property
    def gravity(self) -> Array:
        """Gravity in the base frame, shape (3,)."""
    @property
    def warnings(self) -> List[str]:
        """The loader's warnings."""
    @property
    def params(self) -> Array:
        """Standard parameters, shape (10 * nbodies,), per body
        ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``; settable."""
    @params.setter
    def params(self, value: ArrayLike) -> None: ...
    @property
    def max_threads(self) -> Optional[int]:
        """The most threads a batch is split across (``None``: every core)."""
    @max_threads.setter
    def max_threads(self, value: Optional[int]) -> None: ...
    def neutral(self) -> Array:
        """The neutral configuration, shape (nq,)."""
    def rnea(self, q: ArrayLike, v: ArrayLike, a: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """Inverse dynamics ``tau = M(q) a + C(q, v) v + g(q)``: (nv,) or (N, nv)."""
    def nonlinear_effects(self, q: ArrayLike, v: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """``C(q, v) v + g(q)``: (nv,) or (N, nv)."""
    def generalized_gravity(self, q: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """``g(q)``: (nv,) or (N, nv)."""
    def crba(self, q: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """The mass matrix ``M(q)``: (nv, nv) or (N, nv, nv)."""
    def aba(self, q: ArrayLike, v: ArrayLike, tau: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """Forward dynamics ``M(q)⁻¹ (tau − C(q, v) v − g(q))``: (nv,) or (N, nv)."""
    def forward_kinematics(self, q: ArrayLike) -> Tuple[Array, Array]:
        """Every body's placement ``(R, t)`` in the base frame: (nbodies, 3, 3) and
        (nbodies, 3), or with a leading N."""
    def frame_placement(self, q: ArrayLike, frame: str) -> Tuple[Array, Array]:
        """A frame's placement ``(R, t)``: (3, 3) and (3,), or with a leading N."""
    def frame_jacobian(self, q: ArrayLike, frame: str, reference: Reference = "local_world_aligned") -> Array:
        """A frame's Jacobian in ``"local_world_aligned"``, ``"local"`` or ``"world"``:
        (6, nv) or (N, 6, nv)."""
    def frame_jacobian_time_variation(
        self, q: ArrayLike, v: ArrayLike, frame: str, reference: Reference = "local_world_aligned"
    ) -> Tuple[Array, Array]:
        """A frame's Jacobian and its time variation d/dt J(q(t)) along dq/dt = v:
        (6, nv) each, or (N, 6, nv)."""
    def frame_velocity(self, q: ArrayLike, v: ArrayLike, frame: str, reference: Reference = "local_world_aligned") -> Array:
        """A frame's spatial velocity [v; ω] in ``reference``: (6,) or (N, 6)."""
    def frame_classical_acceleration(
        self, q: ArrayLike, v: ArrayLike, a: ArrayLike, frame: str, reference: Reference = "local_world_aligned"
    ) -> Array:
        """A frame's classical acceleration (Pinocchio's getFrameClassicalAcceleration);
        with a = 0 the drift J̇v: (6,) or (N, 6)."""
    def rnea_derivatives(
        self, q: ArrayLike, v: ArrayLike, a: ArrayLike, params: Optional[ArrayLike] = None
    ) -> Tuple[Array, Array, Array]:
        """(∂tau/∂q, ∂tau/∂v, M), each (nv, nv) or (N, nv, nv); ∂/∂q in the tangent space."""
    def aba_derivatives(
        self, q: ArrayLike, v: ArrayLike, tau: ArrayLike, params: Optional[ArrayLike] = None
    ) -> Tuple[Array, Array, Array, Array]:
        """(ddq, ∂ddq/∂q, ∂ddq/∂v, M⁻¹): (nv,) then (nv, nv) each, with a leading N for a batch."""
    def center_of_mass(self, q: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """The centre of mass in the base frame: (3,) or (N, 3)."""
    def com_jacobian(self, q: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """The centre of mass's Jacobian, base axes: (3, nv) or (N, 3, nv)."""
    def centroidal_map(self, q: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """The centroidal momentum matrix A_g (Pinocchio's ccrba): (6, nv) or (N, 6, nv)."""
    def centroidal_map_time_variation(
        self, q: ArrayLike, v: ArrayLike, params: Optional[ArrayLike] = None
    ) -> Tuple[Array, Array]:
        """A_g and d/dt A_g(q(t)) along dq/dt = v: (6, nv) each, or (N, 6, nv)."""
    def principal_regressor(self, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> Array:
        """tau = Yp @ principal_params: (nv, 4 nbodies) or (N, nv, 4 nbodies)."""
    @property
    def principal_params(self) -> Array:
        """Per body (m, J1, J2, J3): shape (4 nbodies,)."""
    def base_parameters(self, kind: str = "standard") -> Dict[str, Any]:
        """names, independent, K (beta = K @ params), groupings, confirmed, rank_check, consistent."""
    def joint_wrenches(self, q: ArrayLike, v: ArrayLike, a: ArrayLike, params: Optional[ArrayLike] = None) -> Array:
        """Each joint's wrench on its body, in the body frame: (nbodies, 6) or (N, nbodies, 6)."""
    def joint_torque_regressor(self, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> Array:
        """``Y`` with ``tau = Y @ params``: (nv, 10 nbodies) or (N, nv, 10 nbodies)."""
    def joint_wrench_regressor(self, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> Array:
        """``W`` with ``W @ params`` the joint wrenches: (6 nbodies, 10 nbodies) or with a leading N."""
