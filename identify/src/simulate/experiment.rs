//! The paper's experiment as ADAMS runs it: joints driven along prescribed motions
//! from rest, sampled at equal steps, recording what the paper measures on every
//! body (orientation as Cardano angles and their rates, angular velocity and
//! acceleration, centre-of-mass acceleration, the reaction wrenches) plus the joint
//! quantities an identification from joint torques needs.

use super::cardano::{cardano_angles, cardano_matrix, cardano_rates, unwrap_angle};
use super::excitation::JointLimits;
use super::motion::{FourierExcitation, JointMotion, RaisedCosine};
use crate::data::DataError;
use dyngen::{BodyRegressor, Pose, Wrench};
use dyngen_model::{principal_frames, Model};
use dyngen_reference::spatial::{vec3 as vector3, Motion as SpatialMotion};
use dyngen_reference::Dynamics;
use dyngen_reference::Reference;
use dyngen_reference::{euler_matrix, BodyMotion};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3, Vector6};
use std::ops::Range;

/// A prescribed motion of an [`Experiment`].
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    RaisedCosine(RaisedCosine),
    Fourier(FourierExcitation),
}

impl JointMotion for Motion {
    fn nv(&self) -> usize {
        match self {
            Motion::RaisedCosine(m) => m.nv(),
            Motion::Fourier(m) => m.nv(),
        }
    }

    fn eval(&self, t: f64, q: &mut [f64], v: &mut [f64], a: &mut [f64]) {
        match self {
            Motion::RaisedCosine(m) => m.eval(t, q, v, a),
            Motion::Fourier(m) => m.eval(t, q, v, a),
        }
    }
}

/// A simulated experiment: the joints follow `motion` for `duration` seconds,
/// measured every `duration / steps` seconds, `t_k = k · duration / steps` for
/// `k = 0..=steps` (`steps + 1` samples, the initial state included, as ADAMS
/// reports them).
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    pub duration: f64,
    pub steps: usize,
    pub motion: Motion,
}

impl Experiment {
    /// The paper's experiment on `model`: 2 s in 100 steps, from rest, each joint on
    /// its own [`RaisedCosine::paper`] profile within the model's
    /// [`JointLimits`] (rotations within ±π).
    pub fn paper(model: &Model) -> Experiment {
        let ranges: Vec<(f64, f64)> = JointLimits::from_model(model)
            .iter()
            .map(|l| (l.lower, l.upper))
            .collect();
        Experiment {
            duration: 2.0,
            steps: 100,
            motion: Motion::RaisedCosine(RaisedCosine::paper(&ranges)),
        }
    }

    /// The sample times `t_k = k · duration / steps`, `k = 0..=steps`.
    pub fn times(&self) -> Vec<f64> {
        (0..=self.steps)
            .map(|k| k as f64 * self.duration / self.steps as f64)
            .collect()
    }
}

/// What the sensors of one body report at one instant, all in the body's
/// centroidal principal frame (origin at the nominal centre of mass, axes the
/// principal axes `R_p` of [`dyngen_model::PrincipalFrame`]) — the frame of
/// [`Dynamics::body_regressors`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyMeasurement {
    /// Cardano angles `α` of the principal frame in the base frame:
    /// `R_base_body · R_p = Rx(α1) Ry(α2) Rz(α3)` (see [`cardano_angles`]), with
    /// `α1` and `α3` unwrapped along the recording.
    pub cardano: Vector3<f64>,
    /// `α̇ = K(α)⁻¹ ω` ([`cardano_rates`]).
    pub cardano_rates: Vector3<f64>,
    /// `ω`, rad/s.
    pub angular_velocity: Vector3<f64>,
    /// `ω̇`, rad/s².
    pub angular_acceleration: Vector3<f64>,
    /// The kinematic acceleration `a_c` of the centre of mass, m/s², gravity
    /// **excluded** (an accelerometer would read `a_c − g`; Newton's law is
    /// `F = m (a_c − g)`).
    pub com_acceleration: Vector3<f64>,
    /// Resultant of the joint reactions on the body (moment about the centre of
    /// mass): [`Dynamics::body_resultants`].
    pub resultant: Wrench<f64>,
}

/// Everything measured at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    /// Joint torques (N·m) or forces (N): `rnea(q, v, a)`.
    pub tau: Vec<f64>,
    /// Joint `j`'s reaction on body `j` ([`Dynamics::joint_wrenches`]: frame `j`,
    /// moment about the joint origin), joint 1 first.
    pub joint_wrenches: Vec<Wrench<f64>>,
    /// Body 1 first.
    pub bodies: Vec<BodyMeasurement>,
}

/// A recorded experiment: samples in time order, plus what is needed to turn them
/// into identification equations.
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    /// Gravity in the base frame, m/s².
    pub gravity: Vector3<f64>,
    pub joint_names: Vec<String>,
    pub body_names: Vec<String>,
    pub samples: Vec<Sample>,
}

/// Runs `experiment` on `dynamics` with standard parameters `params` (`10 n`).
/// Noise-free; see [`super::NoiseModel::apply`].
pub fn record(dynamics: &dyn Dynamics, params: &[f64], experiment: &Experiment) -> Recording {
    record_trajectory(dynamics, params, &experiment.motion, &experiment.times())
}

/// Records any [`JointMotion`] at the given times (ascending, for the angle
/// unwrapping). Panics if `params` or the trajectory do not fit the model.
pub fn record_trajectory(
    dynamics: &dyn Dynamics,
    params: &[f64],
    trajectory: &dyn JointMotion,
    times: &[f64],
) -> Recording {
    let model = dynamics.model();
    let n = dynamics.nv();
    assert_eq!(
        trajectory.nv(),
        n,
        "the trajectory has {} joints, the model {n}",
        trajectory.nv()
    );
    assert_eq!(
        params.len(),
        dynamics.nparams(),
        "`params` has length {}, the model needs {}",
        params.len(),
        dynamics.nparams()
    );
    let frames = Frames::of(model);
    let nb = model.dof();
    let mut poses = vec![Pose::default(); nb];
    let rest = SpatialMotion {
        linear: Vector3::zeros(),
        angular: Vector3::zeros(),
    };
    let mut motions = vec![
        BodyMotion {
            velocity: rest,
            acceleration: rest,
        };
        nb
    ];
    let mut resultants = vec![Wrench::default(); nb];
    let mut samples: Vec<Sample> = Vec::with_capacity(times.len());
    for &t in times {
        let (mut q, mut v, mut a) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        trajectory.eval(t, &mut q, &mut v, &mut a);
        let mut tau = vec![0.0; n];
        dynamics.rnea(&q, &v, &a, params, &mut tau);
        let mut joint_wrenches = vec![Wrench::default(); nb];
        dynamics.joint_wrenches(&q, &v, &a, params, &mut joint_wrenches);
        dynamics.forward_kinematics(&q, &mut poses);
        dynamics.body_motions(&q, &v, &a, &mut motions);
        dynamics.body_resultants(&q, &v, &a, params, &mut resultants);
        let bodies = frames.measure(&poses, &motions, &resultants, samples.last());
        samples.push(Sample {
            t,
            q,
            v,
            a,
            tau,
            joint_wrenches,
            bodies,
        });
    }
    Recording {
        gravity: vector3(&model.gravity),
        joint_names: model.own_joints().map(|j| j.name.clone()).collect(),
        body_names: model.bodies.iter().map(|b| b.name.clone()).collect(),
        samples,
    }
}

/// The bodies' centroidal principal frames, in which [`BodyMeasurement`]s are taken.
struct Frames {
    rotations: Vec<Matrix3<f64>>,
    coms: Vec<Vector3<f64>>,
}

impl Frames {
    fn of(model: &Model) -> Frames {
        let frames = principal_frames(model);
        Frames {
            rotations: frames
                .iter()
                .map(|f| Matrix3::from_fn(|r, c| f.rotation[r][c]))
                .collect(),
            coms: frames.iter().map(|f| vector3(&f.com)).collect(),
        }
    }

    /// Every body's measurement from its pose, motion and resultant (in principal
    /// axes, as [`Dynamics::body_resultants`] gives it); Cardano angles unwrapped
    /// against the `previous` sample.
    fn measure(
        &self,
        poses: &[Pose<f64>],
        motions: &[BodyMotion],
        resultants: &[Wrench<f64>],
        previous: Option<&Sample>,
    ) -> Vec<BodyMeasurement> {
        (0..poses.len())
            .map(|i| {
                let to_principal = self.rotations[i].transpose();
                let mut cardano = cardano_angles(&(poses[i].rotation * self.rotations[i]));
                if let Some(previous) = previous {
                    let before = previous.bodies[i].cardano;
                    cardano.x = unwrap_angle(cardano.x, before.x);
                    cardano.z = unwrap_angle(cardano.z, before.z);
                }
                let angular_velocity = to_principal * motions[i].velocity.angular;
                BodyMeasurement {
                    cardano,
                    cardano_rates: cardano_rates(&cardano, &angular_velocity),
                    angular_velocity,
                    angular_acceleration: to_principal * motions[i].acceleration.angular,
                    com_acceleration: to_principal * motions[i].point_acceleration(&self.coms[i]),
                    resultant: resultants[i],
                }
            })
            .collect()
    }
}

impl Recording {
    /// A recording of measured data, for MIM on a user's own measurements: each
    /// body's kinematics come from the measured `q, v, a` through `robot`'s
    /// kinematics (the body-mounted sensors the paper assumes, reconstructed from
    /// the joints), and each body's resultant from the measured joint wrenches
    /// ([`Reference::resultants_of_joint_wrenches`]). Torques and joint wrenches
    /// are kept as measured.
    ///
    /// Errors: the data have no velocities or accelerations (estimate them first,
    /// [`Trajectory::with_derivatives`](crate::data::Trajectory::with_derivatives)),
    /// no joint wrench columns, or a number of joints other than `robot`'s.
    pub fn from_measurements(robot: &Reference, data: &crate::data::Trajectory) -> Result<Recording, DataError> {
        let model = robot.model();
        let n = model.nv();
        if data.dof() != n {
            return Err(DataError::LengthMismatch {
                what: "joints of the data",
                expected: n,
                found: data.dof(),
            });
        }
        let missing = |group, columns: &str| DataError::MissingGroup {
            group,
            columns: columns.replace('n', &n.to_string()),
            needed_for: "MIM from body measurements",
        };
        if data.velocities().is_none() {
            return Err(missing("velocity", "v1..vn"));
        }
        if data.accelerations().is_none() {
            return Err(missing("acceleration", "a1..an"));
        }
        if data.joint_wrenches().is_none() {
            return Err(missing("joint wrench", "fx1, fy1, fz1, mx1, my1, mz1, …, mzn"));
        }
        let frames = Frames::of(model);
        let mut samples: Vec<Sample> = Vec::with_capacity(data.len());
        for s in data.samples() {
            let (v, a, wrenches) = (
                s.v.unwrap_or_default(),
                s.a.unwrap_or_default(),
                s.wrenches.unwrap_or_default(),
            );
            let poses = robot.forward_kinematics(s.q);
            let motions = robot.body_motions(s.q, v, a);
            let resultants = robot.resultants_of_joint_wrenches(s.q, wrenches);
            let bodies = frames.measure(&poses, &motions, &resultants, samples.last());
            samples.push(Sample {
                t: s.t,
                q: s.q.to_vec(),
                v: v.to_vec(),
                a: a.to_vec(),
                tau: s.tau.to_vec(),
                joint_wrenches: wrenches.to_vec(),
                bodies,
            });
        }
        Ok(Recording {
            gravity: vector3(&model.gravity),
            joint_names: model.own_joints().map(|j| j.name.clone()).collect(),
            body_names: model.bodies.iter().map(|b| b.name.clone()).collect(),
            samples,
        })
    }

    /// The joint-space channels (t, q, v, a, τ and the joint wrenches) as a
    /// [`crate::data::Trajectory`], e.g. to write as CSV; the inverse of
    /// [`Recording::from_measurements`] up to rounding. Errors only on a recording
    /// that is not a valid trajectory (fewer than 2 samples, time not increasing,
    /// a non-finite value).
    pub fn to_trajectory(&self) -> Result<crate::data::Trajectory, DataError> {
        let n = self.nv();
        let t = self.samples.iter().map(|s| s.t).collect();
        let flat = |f: fn(&Sample) -> &Vec<f64>| -> Vec<f64> {
            self.samples.iter().flat_map(|s| f(s).iter().copied()).collect()
        };
        let trajectory = crate::data::Trajectory::new(n, t, flat(|s| &s.q), flat(|s| &s.tau))?
            .with_velocities(flat(|s| &s.v))?
            .with_accelerations(flat(|s| &s.a))?;
        // A trajectory holds a wrench per joint with a coordinate: with joints that
        // follow others (`<mimic>`, more joints than coordinates) it holds none.
        if self.body_names.len() != n {
            return Ok(trajectory);
        }
        trajectory.with_wrenches(
            self.samples
                .iter()
                .flat_map(|s| s.joint_wrenches.iter().copied())
                .collect(),
        )
    }

    pub fn len(&self) -> usize {
        self.samples.len()
    }

    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Number of joints with a coordinate of their own (= moving bodies, unless joints
    /// follow others).
    pub fn nv(&self) -> usize {
        self.joint_names.len()
    }

    /// Index of the sample nearest to time `t` (the first on a tie); `None` when
    /// empty.
    pub fn nearest(&self, t: f64) -> Option<usize> {
        (0..self.len()).min_by(|&i, &j| (self.samples[i].t - t).abs().total_cmp(&(self.samples[j].t - t).abs()))
    }

    /// Body `body`'s (0-based: body 1 is 0) regressor `A_i` at sample `k`, from the
    /// recorded channels, noisy or not (docs/design.md, "The paper's decoupled body model"):
    ///
    /// ```text
    /// force  = [a_c − R(α)ᵀ g, 0, 0, 0]
    /// moment = [0, B(ω, ω̇)]
    /// ```
    ///
    /// with gravity turned into the principal frame by the recorded Cardano angles.
    /// On a noise-free recording this equals [`Dynamics::body_regressors`].
    pub fn body_regressor(&self, k: usize, body: usize) -> BodyRegressor<f64> {
        let m = &self.samples[k].bodies[body];
        let g = cardano_matrix(&m.cardano).transpose() * self.gravity;
        let mut out = BodyRegressor::default();
        out.force.set_column(0, &(m.com_acceleration - g));
        out.moment
            .fixed_view_mut::<3, 3>(0, 1)
            .copy_from(&euler_matrix(&m.angular_velocity, &m.angular_acceleration));
        out
    }

    /// Body `body`'s measured resultant `[F; M]` at sample `k`: the right-hand side
    /// of `A_i θ_i = [F; M]`.
    pub fn body_wrench(&self, k: usize, body: usize) -> Vector6<f64> {
        let w = &self.samples[k].bodies[body].resultant;
        Vector6::new(w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z)
    }

    /// Body `body`'s equations over the samples `range`, stacked:
    /// `A θ_i = y` with `A` (`6K × 4`) and `y` (`6K`), six rows per sample
    /// (`[force; moment]`), samples in order.
    pub fn body_system(&self, body: usize, range: Range<usize>) -> (DMatrix<f64>, DVector<f64>) {
        let count = range.len();
        let mut a = DMatrix::zeros(6 * count, 4);
        let mut y = DVector::zeros(6 * count);
        for (r, k) in range.enumerate() {
            let block = self.body_regressor(k, body);
            a.view_mut((6 * r, 0), (3, 4)).copy_from(&block.force);
            a.view_mut((6 * r + 3, 0), (3, 4)).copy_from(&block.moment);
            y.rows_mut(6 * r, 6).copy_from(&self.body_wrench(k, body));
        }
        (a, y)
    }

    /// The whole robot as one block-diagonal problem (the paper's eq. 19–20):
    /// `A θ = y` with `θ = (θ_1, …, θ_n)` (`4n`), `A` (`6nK × 4n`) and `y` (`6nK`);
    /// rows per sample, then per body, then `[force; moment]`.
    pub fn robot_body_system(&self, range: Range<usize>) -> (DMatrix<f64>, DVector<f64>) {
        let n = self.nv();
        let count = range.len();
        let mut a = DMatrix::zeros(6 * n * count, 4 * n);
        let mut y = DVector::zeros(6 * n * count);
        for (r, k) in range.enumerate() {
            for i in 0..n {
                let row = 6 * (n * r + i);
                let block = self.body_regressor(k, i);
                a.view_mut((row, 4 * i), (3, 4)).copy_from(&block.force);
                a.view_mut((row + 3, 4 * i), (3, 4)).copy_from(&block.moment);
                y.rows_mut(row, 6).copy_from(&self.body_wrench(k, i));
            }
        }
        (a, y)
    }

    /// The joint torque equations over the samples `range`, stacked:
    /// `Y π = τ` with `Y` (`nK × 10n`) evaluated at the recorded `q, v, a` and `τ`
    /// (`nK`) the recorded torques; rows per sample, then per joint.
    pub fn torque_system(&self, dynamics: &dyn Dynamics, range: Range<usize>) -> (DMatrix<f64>, DVector<f64>) {
        let n = dynamics.nv();
        let p = dynamics.nparams();
        let count = range.len();
        let mut w = DMatrix::zeros(n * count, p);
        let mut tau = DVector::zeros(n * count);
        let mut y = vec![0.0; n * p];
        for (r, k) in range.enumerate() {
            let s = &self.samples[k];
            dynamics.joint_torque_regressor(&s.q, &s.v, &s.a, &mut y);
            for j in 0..n {
                for c in 0..p {
                    w[(n * r + j, c)] = y[j * p + c];
                }
                tau[n * r + j] = s.tau[j];
            }
        }
        (w, tau)
    }
}
