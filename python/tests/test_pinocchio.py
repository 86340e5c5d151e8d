"""Every algorithm against Pinocchio's Python bindings (`pip install pin`) on the
shipped UR5, Panda, and 31-joint humanoid on a free flyer, 20 random states each."""

import numpy as np
import pinocchio as pin
import pytest

from conftest import ROBOTS, load, random_states, record

TOLERANCE = 1e-12
STATES = 20


def error(x, y):
    """Largest difference, relative to the magnitude of the reference where it
    exceeds 1."""
    x, y = np.asarray(x), np.asarray(y)
    assert x.shape == y.shape, (x.shape, y.shape)
    return np.max(np.abs(x - y), initial=0.0) / max(1.0, np.max(np.abs(y), initial=0.0))


class Pair:
    """A robot loaded by dyngen and by Pinocchio, with the maps between their
    coordinates: Pinocchio numbers the joints as dyngen does (checked by name), but
    gives a continuous joint two positions (cos θ, sin θ) where dyngen has θ."""

    def __init__(self, name, path, free_flyer):
        self.name = name
        self.robot = load(path, free_flyer)
        if free_flyer:
            self.model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        else:
            self.model = pin.buildModelFromUrdf(str(path))
        self.data = self.model.createData()
        pin_names = list(self.model.names)[1:]
        assert sorted(pin_names) == sorted(self.robot.joint_names)
        # Pinocchio joint (1-based) of each dyngen joint, in dyngen's order.
        self.joints = [self.model.getJointId(n) for n in self.robot.joint_names]
        self.v_perm = []  # dyngen velocity k is Pinocchio's v_perm[k]
        self.param_perm = []  # dyngen parameter k is Pinocchio's param_perm[k]
        self.q_layout = []  # (dyngen offset, Pinocchio offset, nq dyngen, continuous)
        q_off = 0
        for j in self.joints:
            joint = self.model.joints[j]
            continuous = joint.nq == 2 and joint.nv == 1
            nq = 1 if continuous else joint.nq
            self.q_layout.append((q_off, joint.idx_q, nq, continuous))
            q_off += nq
            self.v_perm.extend(range(joint.idx_v, joint.idx_v + joint.nv))
            self.param_perm.extend(range(10 * (j - 1), 10 * j))
        assert q_off == self.robot.nq and len(self.v_perm) == self.robot.nv
        self.v_perm = np.array(self.v_perm)
        self.param_perm = np.array(self.param_perm)
        self.same_order = pin_names == self.robot.joint_names

    def q(self, q):
        """dyngen's configuration as Pinocchio's."""
        out = np.zeros(self.model.nq)
        for (dq, pq, nq, continuous) in self.q_layout:
            if continuous:
                out[pq : pq + 2] = [np.cos(q[dq]), np.sin(q[dq])]
            else:
                out[pq : pq + nq] = q[dq : dq + nq]
        return out

    def v(self, v):
        """A dyngen velocity-space vector in Pinocchio's order."""
        out = np.empty(self.model.nv)
        out[self.v_perm] = v
        return out

    def from_v(self, x):
        """A Pinocchio velocity-space vector (or the rows of a matrix) in dyngen's order."""
        return np.asarray(x)[self.v_perm]

    def params(self):
        """Pinocchio's standard parameters, in dyngen's order."""
        pi = np.concatenate([self.model.inertias[j].toDynamicParameters() for j in range(1, self.model.njoints)])
        return pi[self.param_perm]

    def set_params(self, params):
        """Gives Pinocchio the standard parameters `params` (dyngen's order)."""
        pi = np.empty_like(params)
        pi[self.param_perm] = params
        for j in range(1, self.model.njoints):
            self.model.inertias[j] = pin.Inertia.FromDynamicParameters(pi[10 * (j - 1) : 10 * j])


@pytest.fixture(scope="module", params=[r[0] for r in ROBOTS])
def pair(request):
    name, path, free_flyer = next(r for r in ROBOTS if r[0] == request.param)
    return Pair(name, path, free_flyer)


@pytest.fixture(scope="module")
def states(pair):
    return random_states(pair.robot, STATES, np.random.default_rng(1))


def check(pair, algorithm, ours, theirs):
    e = error(ours, theirs)
    record(pair.name, algorithm, e)
    assert e <= TOLERANCE, f"{pair.name} {algorithm}: error {e:.3e}"


def test_joint_order_and_parameters(pair):
    # The shipped robots are numbered as Pinocchio numbers them; the maps above
    # would cover a different order.
    assert pair.same_order
    assert pair.robot.nv == pair.model.nv
    check(pair, "params", pair.robot.params, pair.params())
    np.testing.assert_array_equal(pair.robot.gravity, pair.model.gravity.linear)


def test_rnea(pair, states):
    for q, v, a in zip(*states):
        ours = pair.robot.rnea(q, v, a)
        theirs = pin.rnea(pair.model, pair.data, pair.q(q), pair.v(v), pair.v(a))
        check(pair, "rnea", ours, pair.from_v(theirs))


def test_nonlinear_effects_and_gravity(pair, states):
    for q, v, _ in zip(*states):
        ours = pair.robot.nonlinear_effects(q, v)
        theirs = pin.nonLinearEffects(pair.model, pair.data, pair.q(q), pair.v(v))
        check(pair, "nonlinear_effects", ours, pair.from_v(theirs))
        ours = pair.robot.generalized_gravity(q)
        theirs = pin.computeGeneralizedGravity(pair.model, pair.data, pair.q(q))
        check(pair, "generalized_gravity", ours, pair.from_v(theirs))


def test_crba(pair, states):
    for q in states[0]:
        theirs = pin.crba(pair.model, pair.data, pair.q(q))
        theirs = np.triu(theirs) + np.triu(theirs, 1).T  # Pinocchio fills the upper triangle
        theirs = theirs[np.ix_(pair.v_perm, pair.v_perm)]
        check(pair, "crba", pair.robot.crba(q), theirs)


def test_aba(pair, states):
    rng = np.random.default_rng(1)
    for q, v, _ in zip(*states):
        tau = rng.uniform(-10.0, 10.0, pair.robot.nv)
        ours = pair.robot.aba(q, v, tau)
        theirs = pin.aba(pair.model, pair.data, pair.q(q), pair.v(v), pair.v(tau))
        check(pair, "aba", ours, pair.from_v(theirs))


def test_forward_kinematics(pair, states):
    for q in states[0]:
        rotations, translations = pair.robot.forward_kinematics(q)
        pin.forwardKinematics(pair.model, pair.data, pair.q(q))
        for i, j in enumerate(pair.joints):
            check(pair, "forward_kinematics", rotations[i], pair.data.oMi[j].rotation)
            check(pair, "forward_kinematics", translations[i], pair.data.oMi[j].translation)


def frame_ids(pair):
    """Every dyngen frame with Pinocchio's id of the body frame of that name (the
    world of a free flyer is Pinocchio's `universe`)."""
    ids = []
    for name in pair.robot.frame_names:
        assert pair.model.existFrame(name), name
        fid = pair.model.getFrameId(name)
        ids.append((name, fid))
    assert len(ids) == len(pair.robot.frame_names)
    return ids


def test_frame_placement(pair, states):
    ids = frame_ids(pair)
    for q in states[0]:
        pin.framesForwardKinematics(pair.model, pair.data, pair.q(q))
        for name, fid in ids:
            rotation, translation = pair.robot.frame_placement(q, name)
            check(pair, "frame_placement", rotation, pair.data.oMf[fid].rotation)
            check(pair, "frame_placement", translation, pair.data.oMf[fid].translation)


@pytest.mark.parametrize(
    "reference, pin_reference",
    [("local_world_aligned", pin.LOCAL_WORLD_ALIGNED), ("local", pin.LOCAL), ("world", pin.WORLD)],
)
def test_frame_jacobian(pair, states, reference, pin_reference):
    ids = frame_ids(pair)
    for q in states[0]:
        for name, fid in ids:
            ours = pair.robot.frame_jacobian(q, name, reference=reference)
            theirs = pin.computeFrameJacobian(pair.model, pair.data, pair.q(q), fid, pin_reference)
            check(pair, f"frame_jacobian {reference}", ours, theirs[:, pair.v_perm])


def test_joint_torque_regressor(pair, states):
    for q, v, a in zip(*states):
        ours = pair.robot.joint_torque_regressor(q, v, a)
        theirs = pin.computeJointTorqueRegressor(pair.model, pair.data, pair.q(q), pair.v(v), pair.v(a))
        check(pair, "joint_torque_regressor", ours, theirs[np.ix_(pair.v_perm, pair.param_perm)])


def test_joint_wrenches(pair, states):
    for q, v, a in zip(*states):
        ours = pair.robot.joint_wrenches(q, v, a)
        pin.rnea(pair.model, pair.data, pair.q(q), pair.v(v), pair.v(a))
        theirs = np.array([pair.data.f[j].vector for j in pair.joints])
        check(pair, "joint_wrenches", ours, theirs)


def test_other_params(pair, states):
    """`params=` reaches every algorithm: each body's parameters scaled by its own
    factor (still physical), on both sides."""
    rng = np.random.default_rng(1)
    params = pair.robot.params * np.repeat(rng.uniform(0.5, 2.0, pair.robot.nbodies), 10)
    nominal = pair.params()
    try:
        pair.set_params(params)
        for q, v, a in zip(*states):
            pq, pv, pa = pair.q(q), pair.v(v), pair.v(a)
            check(pair, "rnea params=", pair.robot.rnea(q, v, a, params=params),
                  pair.from_v(pin.rnea(pair.model, pair.data, pq, pv, pa)))
            m = pin.crba(pair.model, pair.data, pq)
            m = (np.triu(m) + np.triu(m, 1).T)[np.ix_(pair.v_perm, pair.v_perm)]
            check(pair, "crba params=", pair.robot.crba(q, params=params), m)
            tau = pair.robot.rnea(q, v, a, params=params)
            check(pair, "aba params=", pair.robot.aba(q, v, tau, params=params),
                  pair.from_v(pin.aba(pair.model, pair.data, pq, pv, pair.v(tau))))
    finally:
        pair.set_params(nominal)


def test_rnea_derivatives(pair, states):
    perm = np.ix_(pair.v_perm, pair.v_perm)
    for q, v, a in zip(*states):
        dq, dv, m = pair.robot.rnea_derivatives(q, v, a)
        theirs = pin.computeRNEADerivatives(pair.model, pair.data, pair.q(q), pair.v(v), pair.v(a))
        check(pair, "rnea_derivatives dq", dq, theirs[0][perm])
        check(pair, "rnea_derivatives dv", dv, theirs[1][perm])
        full = np.triu(theirs[2]) + np.triu(theirs[2], 1).T  # the upper triangle, as crba
        check(pair, "rnea_derivatives M", m, full[perm])


# M⁻¹ and the forward-dynamics derivatives of the humanoid (M's condition number up to
# 2.5e5) differ from Pinocchio's by up to 1.3e-12, Pinocchio's own error: the Rust
# tests hold dyngen's to 1e-12 against an extended-precision evaluation.
FORWARD_DERIVATIVES_TOLERANCE = 5e-12


def test_aba_derivatives(pair, states):
    perm = np.ix_(pair.v_perm, pair.v_perm)
    rng = np.random.default_rng(2)
    for q, v, _ in zip(*states):
        tau = rng.uniform(-10.0, 10.0, pair.robot.nv)
        ddq, dq, dv, minv = pair.robot.aba_derivatives(q, v, tau)
        theirs = pin.computeABADerivatives(pair.model, pair.data, pair.q(q), pair.v(v), pair.v(tau))
        check(pair, "aba_derivatives ddq", ddq, pair.from_v(pair.data.ddq))
        for name, ours, their in [("dq", dq, theirs[0]), ("dv", dv, theirs[1]), ("Minv", minv, theirs[2])]:
            e = error(ours, their[perm])
            record(pair.name, f"aba_derivatives {name}", e)
            assert e <= FORWARD_DERIVATIVES_TOLERANCE, f"{pair.name} aba_derivatives {name}: {e:.3e}"


REFERENCES = [("local_world_aligned", pin.LOCAL_WORLD_ALIGNED), ("local", pin.LOCAL), ("world", pin.WORLD)]


def test_frame_velocity_acceleration_and_jacobian_time_variation(pair, states):
    ids = frame_ids(pair)
    for q, v, a in list(zip(*states))[:5]:
        pq, pv, pa = pair.q(q), pair.v(v), pair.v(a)
        pin.forwardKinematics(pair.model, pair.data, pq, pv, pa)
        pin.updateFramePlacements(pair.model, pair.data)
        velocities = {(fid, r): pin.getFrameVelocity(pair.model, pair.data, fid, pr).vector
                      for _, fid in ids for r, pr in REFERENCES}
        accelerations = {(fid, r): pin.getFrameClassicalAcceleration(pair.model, pair.data, fid, pr).vector
                         for _, fid in ids for r, pr in REFERENCES}
        pin.computeJointJacobiansTimeVariation(pair.model, pair.data, pq, pv)
        pin.updateFramePlacements(pair.model, pair.data)
        for name, fid in ids:
            for reference, pin_reference in REFERENCES:
                check(pair, f"frame_velocity {reference}",
                      pair.robot.frame_velocity(q, v, name, reference), velocities[fid, reference])
                check(pair, f"frame_classical_acceleration {reference}",
                      pair.robot.frame_classical_acceleration(q, v, a, name, reference),
                      accelerations[fid, reference])
                j, dj = pair.robot.frame_jacobian_time_variation(q, v, name, reference)
                theirs = pin.getFrameJacobianTimeVariation(pair.model, pair.data, fid, pin_reference)
                check(pair, f"frame_jacobian_time_variation {reference}", dj, theirs[:, pair.v_perm])
                check(pair, f"frame_jacobian (time variation) {reference}", j,
                      pin.getFrameJacobian(pair.model, pair.data, fid, pin_reference)[:, pair.v_perm])


def test_centroidal(pair, states):
    for q, v, _ in zip(*states):
        pq, pv = pair.q(q), pair.v(v)
        check(pair, "center_of_mass", pair.robot.center_of_mass(q), pin.centerOfMass(pair.model, pair.data, pq))
        check(pair, "com_jacobian", pair.robot.com_jacobian(q),
              pin.jacobianCenterOfMass(pair.model, pair.data, pq)[:, pair.v_perm])
        ag = pin.ccrba(pair.model, pair.data, pq, pv)[:, pair.v_perm]
        check(pair, "centroidal_map", pair.robot.centroidal_map(q), ag)
        ours, ours_dot = pair.robot.centroidal_map_time_variation(q, v)
        # Pinocchio's dAg is another matrix with the same product with v (its angular
        # rows leave out ċ × A_lin, whose product with v is ċ × m ċ = 0); dyngen's is
        # the time derivative of A_g, which test_identities checks by differences.
        their_dot = pin.computeCentroidalMapTimeVariation(pair.model, pair.data, pq, pv)
        check(pair, "centroidal_map_time_variation", ours, ag)
        check(pair, "centroidal_map_time_variation dAg v", ours_dot @ v, their_dot @ pv)


def test_mimic_joints_match_pinocchio():
    """A gripper whose knuckles and fingers follow one driven joint (`<mimic>`), as
    Pinocchio loads it with `mimic=True`: one coordinate for the leader and its
    followers."""
    from conftest import ROOT

    path = ROOT / "tests" / "fixtures" / "mimic" / "arm_linkage_gripper.urdf"
    robot = load(path, False)
    model = pin.buildModelFromUrdf(str(path), mimic=True)
    data = model.createData()
    assert (robot.nq, robot.nv) == (model.nq, model.nv) == (7, 7)
    rng = np.random.default_rng(26)
    q, v, a = (rng.uniform(-1, 1, (STATES, 7)) for _ in range(3))
    tau = robot.rnea(q, v, a)
    m = robot.crba(q)
    for k in range(STATES):
        want = pin.rnea(model, data, q[k], v[k], a[k])
        record("arm_linkage_gripper", "rnea (mimic)", error(tau[k], want))
        assert error(tau[k], want) < TOLERANCE
        want = pin.crba(model, data, q[k])
        want = np.triu(want) + np.triu(want, 1).T
        record("arm_linkage_gripper", "crba (mimic)", error(m[k], want))
        assert error(m[k], want) < TOLERANCE
        fid = model.getFrameId("tcp")
        pin.computeJointJacobians(model, data, q[k])
        pin.updateFramePlacements(model, data)
        want = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        got = robot.frame_jacobian(q[k], "tcp")
        record("arm_linkage_gripper", "frame_jacobian (mimic)", error(got, want))
        assert error(got, want) < TOLERANCE
    # Forward dynamics (which Pinocchio does not run on mimic joints) undoes rnea.
    assert error(robot.aba(q, v, tau), a) < 1e-10
