//! Model-based control of the Panda in closed loop, against a plant that is not the
//! model: the plant carries a 0.5 kg payload 5 cm beyond the flange and every link is
//! 3 % heavier than the controller believes. The plant is integrated with the generated
//! `aba` (RK4, torque held over each 1 ms control period) for 2 s.
//!
//! 1. Joint-space computed torque (inverse dynamics): the controller asks the generated
//!    `rnea` for `τ = M(q) (q̈_d + Kp e + Kd ė) + h(q, v)` in one call, tracking a smooth
//!    7-joint trajectory; the same with an integral term `Ki ∫e` removes most of what
//!    the model mismatch leaves.
//! 2. Operational-space control of the flange position: from the flange's
//!    `LOCAL_WORLD_ALIGNED` Jacobian `J` (its 3 translational rows), the drift `J̇v` (the
//!    classical acceleration at `q̈ = 0`), `M⁻¹` and `h`,
//!    `Λ = (J M⁻¹ Jᵀ)⁻¹`, `τ = Jᵀ Λ (ẍ_d − J̇v) + h + (I − Jᵀ Λ J M⁻¹) τ₀`, with `τ₀` a
//!    joint-space PD towards the start posture acting only in the null space of the task.
//!    The flange follows a minimum-jerk path to a point 20 cm away.
//!
//! Everything per step lives on the stack; nothing in the loops allocates.
//!
//!     cargo run --release -p dyngen-examples --example computed_torque

use dyngen::nalgebra::{SMatrix, SVector, Vector3};
use dyngen::ReferenceFrame;
use robot_panda::{Panda, PandaFrame};

/// 7 joint positions, velocities, accelerations or torques.
pub type Joints = [f64; 7];
/// 10 standard parameters per body: `[m, m·c, I about the body origin]`.
pub type Params = [f64; 70];

/// The Panda's ready pose.
pub const Q_READY: Joints = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

/// The simulation: control period and plant step, and duration.
#[derive(Clone, Copy, Debug)]
pub struct SimSettings {
    pub dt: f64,
    pub duration: f64,
}

impl Default for SimSettings {
    fn default() -> Self {
        SimSettings {
            dt: 1e-3,
            duration: 2.0,
        }
    }
}

/// `params` with a point mass `mass` at `at` (body frame) added to body `body`
/// (1-based): `m`, `m·c` and the inertia about the body origin, `m (|c|² E − c cᵀ)`.
pub fn with_point_mass(params: &Params, body: usize, mass: f64, at: [f64; 3]) -> Params {
    let mut p = *params;
    let b = &mut p[10 * (body - 1)..10 * body];
    let [x, y, z] = at;
    b[0] += mass;
    b[1] += mass * x;
    b[2] += mass * y;
    b[3] += mass * z;
    // [Ixx, Ixy, Iyy, Ixz, Iyz, Izz]
    b[4] += mass * (y * y + z * z);
    b[5] -= mass * x * y;
    b[6] += mass * (x * x + z * z);
    b[7] -= mass * x * z;
    b[8] -= mass * y * z;
    b[9] += mass * (x * x + y * y);
    p
}

/// The plant of both controllers: every link 3 % heavier (all ten parameters scaled:
/// the same shape, denser) and 0.5 kg held 5 cm beyond the flange, along its z axis.
pub fn perturbed_plant() -> Params {
    let heavier = Panda::NOMINAL_PARAMS.map(|p| 1.03 * p);
    // The flange `panda_link8` in the frame of the body that carries it.
    let flange = &Panda::MODEL.frames[PandaFrame::PandaLink8.index()];
    let (r, t) = (&flange.rotation, &flange.translation);
    let at = core::array::from_fn(|i| t[i] + r[i][2] * 0.05);
    with_point_mass(&heavier, PandaFrame::PandaLink8.body(), 0.5, at)
}

/// One RK4 step of the plant `q̈ = aba(q, v, τ)` over `dt` with `τ` held.
pub fn rk4_step(q: &mut Joints, v: &mut Joints, tau: &Joints, params: &Params, dt: f64) {
    let add = |x: &Joints, dx: &Joints, h: f64| -> Joints { core::array::from_fn(|j| x[j] + h * dx[j]) };
    let (q0, v0) = (*q, *v);
    let a1 = Panda::aba(&q0, &v0, tau, params);
    let (q1, v1) = (add(&q0, &v0, 0.5 * dt), add(&v0, &a1, 0.5 * dt));
    let a2 = Panda::aba(&q1, &v1, tau, params);
    let (q2, v2) = (add(&q0, &v1, 0.5 * dt), add(&v0, &a2, 0.5 * dt));
    let a3 = Panda::aba(&q2, &v2, tau, params);
    let (q3, v3) = (add(&q0, &v2, dt), add(&v0, &a3, dt));
    let a4 = Panda::aba(&q3, &v3, tau, params);
    for j in 0..7 {
        q[j] = q0[j] + dt / 6.0 * (v0[j] + 2.0 * v1[j] + 2.0 * v2[j] + v3[j]);
        v[j] = v0[j] + dt / 6.0 * (a1[j] + 2.0 * a2[j] + 2.0 * a3[j] + a4[j]);
    }
}

/// The reference of the joint-space controller: each joint swings
/// `q_d = q_ready + A (1 − cos ωt)` from rest, `A` 0.3 to 0.5 rad (swings of 0.6 to
/// 1 rad), periods 1.6 to 2.4 s. Returns `(q_d, q̇_d, q̈_d)`.
pub fn joint_reference(t: f64) -> (Joints, Joints, Joints) {
    const AMPLITUDE: Joints = [0.4, 0.3, 0.4, 0.4, 0.5, 0.4, 0.5];
    const PERIOD: Joints = [2.0, 2.4, 1.8, 2.2, 1.6, 2.0, 1.7];
    let (mut q, mut v, mut a) = ([0.0; 7], [0.0; 7], [0.0; 7]);
    for j in 0..7 {
        let w = 2.0 * core::f64::consts::PI / PERIOD[j];
        let (s, c) = (w * t).sin_cos();
        q[j] = Q_READY[j] + AMPLITUDE[j] * (1.0 - c);
        v[j] = AMPLITUDE[j] * w * s;
        a[j] = AMPLITUDE[j] * w * w * c;
    }
    (q, v, a)
}

/// Gains of the joint-space controller, the same for every joint (computed torque
/// makes every joint a unit mass).
#[derive(Clone, Copy, Debug)]
pub struct JointGains {
    pub kp: f64,
    pub kd: f64,
    /// Integral gain; 0 for the textbook PD.
    pub ki: f64,
}

impl JointGains {
    /// PD with both poles at `−ω`.
    pub fn pd(omega: f64) -> Self {
        JointGains {
            kp: omega * omega,
            kd: 2.0 * omega,
            ki: 0.0,
        }
    }

    /// PID with all three poles at `−ω`: `(s + ω)³ = s³ + 3ω s² + 3ω² s + ω³`.
    pub fn pid(omega: f64) -> Self {
        JointGains {
            kp: 3.0 * omega * omega,
            kd: 3.0 * omega,
            ki: omega * omega * omega,
        }
    }
}

/// How the joint-space run went.
#[derive(Clone, Copy, Debug)]
pub struct TrackingResult {
    /// Largest `|q_d − q|` of any joint at any step, rad.
    pub max_error: f64,
    /// `max_j |q_d − q|` at the end, rad.
    pub final_error: f64,
    /// Largest torque commanded, N·m.
    pub max_torque: f64,
}

/// Computed-torque tracking of [`joint_reference`]:
/// `τ = rnea(q, v, q̈_d + Kp e + Kd ė + Ki ∫e)` with the nominal parameters, against
/// the plant `plant`. Starts on the reference, at rest.
pub fn computed_torque(plant: &Params, gains: &JointGains, sim: &SimSettings) -> TrackingResult {
    let (mut q, mut v, _) = joint_reference(0.0);
    let mut integral = [0.0; 7];
    let mut result = TrackingResult {
        max_error: 0.0,
        final_error: 0.0,
        max_torque: 0.0,
    };
    let steps = (sim.duration / sim.dt).round() as usize;
    for k in 0..steps {
        let (q_d, v_d, a_d) = joint_reference(k as f64 * sim.dt);
        let mut a_cmd = [0.0; 7];
        for j in 0..7 {
            let e = q_d[j] - q[j];
            integral[j] += e * sim.dt;
            a_cmd[j] = a_d[j] + gains.kp * e + gains.kd * (v_d[j] - v[j]) + gains.ki * integral[j];
        }
        let tau = Panda::rnea(&q, &v, &a_cmd, &Panda::NOMINAL_PARAMS);
        result.max_torque = tau.iter().fold(result.max_torque, |m, t| m.max(t.abs()));
        rk4_step(&mut q, &mut v, &tau, plant, sim.dt);
        let (q_d, _, _) = joint_reference((k + 1) as f64 * sim.dt);
        let error = (0..7).fold(0.0f64, |m, j| m.max((q_d[j] - q[j]).abs()));
        result.max_error = result.max_error.max(error);
        result.final_error = error;
    }
    result
}

/// Minimum-jerk path from `from` to `to` in `duration`, then at rest at `to`:
/// `(x, ẋ, ẍ)` at `t`.
pub fn minimum_jerk(from: &Vector3<f64>, to: &Vector3<f64>, duration: f64, t: f64) -> [Vector3<f64>; 3] {
    let s = (t / duration).clamp(0.0, 1.0);
    let (s2, s3) = (s * s, s * s * s);
    let shape = 10.0 * s3 - 15.0 * s3 * s + 6.0 * s3 * s2;
    let rate = (30.0 * s2 - 60.0 * s3 + 30.0 * s2 * s2) / duration;
    let curvature = (60.0 * s - 180.0 * s2 + 120.0 * s3) / (duration * duration);
    let d = to - from;
    [from + shape * d, rate * d, curvature * d]
}

/// Gains of the operational-space controller.
#[derive(Clone, Copy, Debug)]
pub struct OscGains {
    /// Task natural frequency, rad/s (critically damped).
    pub omega: f64,
    /// Null-space posture stiffness and damping, N·m/rad and N·m·s/rad.
    pub kp_null: f64,
    pub kd_null: f64,
}

impl Default for OscGains {
    fn default() -> Self {
        OscGains {
            omega: 30.0,
            kp_null: 20.0,
            kd_null: 8.0,
        }
    }
}

/// How the operational-space run went.
#[derive(Clone, Copy, Debug)]
pub struct TaskResult {
    /// Distance of the goal from the start, m.
    pub distance: f64,
    /// Largest `|x_d − x|` along the way, m.
    pub max_error: f64,
    /// `|x_goal − x|` at the end, m.
    pub final_error: f64,
}

/// The operational-space torque for the flange position: the task-space PD with
/// feed-forward `ẍ_d`, decoupled by `Λ` and with the drift `J̇v` removed, plus `h`, plus
/// the joint-space posture PD projected into the task's null space. Model: nominal.
pub fn operational_space_torque(q: &Joints, v: &Joints, x_d: &[Vector3<f64>; 3], gains: &OscGains) -> Joints {
    type Mat3x7 = SMatrix<f64, 3, 7>;
    type Mat7 = SMatrix<f64, 7, 7>;
    let params = &Panda::NOMINAL_PARAMS;
    let flange = PandaFrame::PandaLink8;
    let lwa = ReferenceFrame::LocalWorldAligned;

    let mut frame = dyngen::FrameJacobian::<f64, 7>::default();
    Panda::frame_jacobian(q, flange, lwa, &mut frame);
    let drift = Panda::frame_classical_acceleration(q, v, &[0.0; 7], flange, lwa).linear;
    let mut minv = [[0.0; 7]; 7];
    Panda::inverse_inertia(q, params, &mut minv);
    let h = SVector::from(Panda::nonlinear_effects(q, v, params));

    let j = Mat3x7::from_fn(|r, c| frame.jacobian[r][c]);
    let minv = Mat7::from_fn(|r, c| minv[r][c]);
    let (x, xdot) = (frame.placement.translation, frame.velocity(v).linear);

    // Λ = (J M⁻¹ Jᵀ)⁻¹ (3 × 3; positive definite away from singularities).
    let j_minv = j * minv;
    let lambda = (j_minv * j.transpose())
        .cholesky()
        .expect("the flange Jacobian has full row rank")
        .inverse();
    let (kp, kd) = (gains.omega * gains.omega, 2.0 * gains.omega);
    let xddot = x_d[2] + kp * (x_d[0] - x) + kd * (x_d[1] - xdot);
    let force = lambda * (xddot - drift);

    // Posture PD, through the dynamically consistent null-space projector
    // I − Jᵀ J̄ᵀ with J̄ᵀ = Λ J M⁻¹.
    let tau0 = SVector::<f64, 7>::from_fn(|i, _| gains.kp_null * (Q_READY[i] - q[i]) - gains.kd_null * v[i]);
    let tau_null = tau0 - j.transpose() * (lambda * (j_minv * tau0));

    let tau = j.transpose() * force + h + tau_null;
    tau.into()
}

/// Operational-space control of the flange position from the ready pose along a
/// minimum-jerk path to a point 20 cm away (three quarters of the run, then holding),
/// against `plant`.
pub fn operational_space(plant: &Params, gains: &OscGains, sim: &SimSettings) -> TaskResult {
    let (mut q, mut v) = (Q_READY, [0.0; 7]);
    let start = Panda::frame_placement(&q, PandaFrame::PandaLink8).translation;
    let goal = start + Vector3::new(0.10, -0.15, -0.08);
    let move_time = 0.75 * sim.duration;
    let mut max_error = 0.0f64;
    let steps = (sim.duration / sim.dt).round() as usize;
    for k in 0..steps {
        let x_d = minimum_jerk(&start, &goal, move_time, k as f64 * sim.dt);
        let tau = operational_space_torque(&q, &v, &x_d, gains);
        rk4_step(&mut q, &mut v, &tau, plant, sim.dt);
        let [x_d, _, _] = minimum_jerk(&start, &goal, move_time, (k + 1) as f64 * sim.dt);
        let x = Panda::frame_placement(&q, PandaFrame::PandaLink8).translation;
        max_error = max_error.max((x_d - x).norm());
    }
    let x = Panda::frame_placement(&q, PandaFrame::PandaLink8).translation;
    TaskResult {
        distance: (goal - start).norm(),
        max_error,
        final_error: (goal - x).norm(),
    }
}

#[allow(dead_code)]
fn main() {
    let sim = SimSettings::default();
    let plant = perturbed_plant();
    println!(
        "Panda, plant integrated by RK4 on aba, dt = {} ms, {} s; perturbed plant: links +3 %, 0.5 kg payload\n",
        sim.dt * 1e3,
        sim.duration
    );
    println!("Joint-space computed torque (rnea), 7 joints swinging 0.6 to 1 rad peak to peak:");
    let omega = 25.0;
    let (pd, pid) = (JointGains::pd(omega), JointGains::pid(omega));
    for (what, params, gains) in [
        ("plant = model, PD", &Panda::NOMINAL_PARAMS, &pd),
        ("perturbed, PD", &plant, &pd),
        ("perturbed, PID", &plant, &pid),
    ] {
        let r = computed_torque(params, gains, &sim);
        println!(
            "  {what:<18} (Kp {:>4}, Kd {:>2}, Ki {:>5}): max tracking error {:.1e} rad, final {:.1e} rad, max torque {:.1} N·m",
            gains.kp, gains.kd, gains.ki, r.max_error, r.final_error, r.max_torque
        );
    }
    println!("  (with plant = model, what is left is the torque held over each 1 ms period: it scales with dt)");

    let gains = OscGains::default();
    println!(
        "\nOperational-space control of the flange position (ω = {} rad/s; posture PD {}, {} in the null space):",
        gains.omega, gains.kp_null, gains.kd_null
    );
    for (what, params) in [("plant = model", &Panda::NOMINAL_PARAMS), ("perturbed", &plant)] {
        let r = operational_space(params, &gains, &sim);
        println!(
            "  {what:<14} move of {:.0} mm: max task error {:.1e} m, final {:.1e} m",
            r.distance * 1e3,
            r.max_error,
            r.final_error
        );
    }
    println!("  (a PD without integral action: the final error is the payload's weight over the task stiffness)");
}
