//! Inverse kinematics by damped-least-squares Newton iterations on the generated frame
//! functions: the Panda's flange (`panda_link8`, 7 joints, redundant) and the UR5's
//! `tool0` (6 joints) are driven from a start configuration to a reachable target pose,
//! position and orientation, within 1e-12 m and rad, joint limits respected by clamping.
//!
//! Each iteration takes the frame's placement and `LOCAL_WORLD_ALIGNED` Jacobian from one
//! call to the generated `frame_jacobian`, forms the pose error `e = [p* − p; log(R* Rᵀ)]`
//! (both world vectors, as that Jacobian's rows are) and steps
//! `Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e` (a 6 × 6 Cholesky solve, whatever the number of joints).
//! The solver is written once over `N` joints and takes the robot as a closure; nothing
//! in the loop allocates.
//!
//!     cargo run --release -p dyngen-examples --example inverse_kinematics

use dyngen::nalgebra::{SMatrix, SVector, Vector6};
use dyngen::{FrameJacobian, Pose, ReferenceFrame, RobotModel};
use robot_panda::{Panda, PandaFrame};
use robot_ur5::{Ur5, Ur5Frame};

/// The knobs of [`solve`].
#[derive(Clone, Copy, Debug)]
pub struct IkSettings {
    /// Damping `λ` of the least-squares step (m or rad): small, so that the iteration
    /// converges quadratically, large enough to keep the step bounded near singularities.
    pub damping: f64,
    /// Largest change of one joint in one step, rad: bounds the first, far-off steps.
    pub max_step: f64,
    /// Stop when both the position error (m) and the orientation error (rad) are below.
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl Default for IkSettings {
    fn default() -> Self {
        IkSettings {
            damping: 1e-6,
            max_step: 0.5,
            tolerance: 1e-12,
            max_iterations: 100,
        }
    }
}

/// What [`solve`] reached.
#[derive(Clone, Copy, Debug)]
pub struct IkResult<const N: usize> {
    pub q: [f64; N],
    pub iterations: usize,
    /// `|p* − p|`, m.
    pub position_error: f64,
    /// `|log(R* Rᵀ)|`, rad.
    pub orientation_error: f64,
    /// Iterations in which at least one joint was clamped to a limit.
    pub clamped_iterations: usize,
    pub converged: bool,
}

/// Position limits of the `N` joints of `model` (`±∞` where there are none).
pub fn joint_limits<const N: usize>(model: &RobotModel) -> [(f64, f64); N] {
    core::array::from_fn(|j| match model.joints[j].limits {
        Some(l) => (l.lower, l.upper),
        None => (f64::NEG_INFINITY, f64::INFINITY),
    })
}

/// Damped-least-squares Newton IK of one frame. `jacobian(q, out)` writes the frame's
/// placement and `LOCAL_WORLD_ALIGNED` Jacobian (a generated `frame_jacobian` with the
/// frame and reference frame fixed); `q0` is the start, clamped into `limits` first.
pub fn solve<const N: usize>(
    jacobian: impl Fn(&[f64; N], &mut FrameJacobian<f64, N>),
    target: &Pose<f64>,
    q0: &[f64; N],
    limits: &[(f64, f64); N],
    settings: &IkSettings,
) -> IkResult<N> {
    let mut q: [f64; N] = core::array::from_fn(|j| q0[j].clamp(limits[j].0, limits[j].1));
    let mut frame = FrameJacobian::<f64, N>::default();
    let mut clamped_iterations = 0;
    let mut iterations = 0;
    loop {
        jacobian(&q, &mut frame);
        // [p* − p; log3(R* Rᵀ)], world vectors like the Jacobian's rows.
        let e = Vector6::from(frame.placement.error_to(target).to_array());
        let (position_error, orientation_error) = (e.fixed_rows::<3>(0).norm(), e.fixed_rows::<3>(3).norm());
        let converged = position_error < settings.tolerance && orientation_error < settings.tolerance;
        if converged || iterations == settings.max_iterations {
            return IkResult {
                q,
                iterations,
                position_error,
                orientation_error,
                clamped_iterations,
                converged,
            };
        }
        iterations += 1;

        // Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e.
        let j = frame.matrix();
        let jjt = j * j.transpose() + SMatrix::<f64, 6, 6>::identity() * settings.damping.powi(2);
        let Some(chol) = jjt.cholesky() else {
            // J Jᵀ + λ² I is positive definite for λ > 0; only NaNs get here.
            return IkResult {
                q,
                iterations,
                position_error,
                orientation_error,
                clamped_iterations,
                converged: false,
            };
        };
        let mut dq: SVector<f64, N> = j.transpose() * chol.solve(&e);
        let largest = dq.amax();
        if largest > settings.max_step {
            dq *= settings.max_step / largest;
        }
        let mut clamped = false;
        for k in 0..N {
            let (lo, hi) = limits[k];
            let next = q[k] + dq[k];
            q[k] = next.clamp(lo, hi);
            clamped |= q[k] != next;
        }
        clamped_iterations += usize::from(clamped);
    }
}

/// The Panda's flange to the pose it has at a reference configuration, from the usual
/// ready pose: far enough that the first Newton steps run joints into their limits.
pub fn panda_flange(settings: &IkSettings) -> IkResult<7> {
    let q_target = [2.5, 1.2, 2.0, -0.2, 2.5, 0.2, 2.5];
    let target = Panda::frame_placement(&q_target, PandaFrame::PandaLink8);
    let q_start = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];
    let flange = |q: &[f64; 7], out: &mut FrameJacobian<f64, 7>| {
        Panda::frame_jacobian(q, PandaFrame::PandaLink8, ReferenceFrame::LocalWorldAligned, out)
    };
    solve(flange, &target, &q_start, &joint_limits(&Panda::MODEL), settings)
}

/// The UR5's `tool0` to the pose it has at a reference configuration, from an elbow-up
/// pose.
pub fn ur5_tool0(settings: &IkSettings) -> IkResult<6> {
    let q_target = [0.5, -1.1, 1.4, -1.8, -1.3, 0.7];
    let target = Ur5::frame_placement(&q_target, Ur5Frame::Tool0);
    let q_start = [0.0, -1.57, 1.57, -1.57, -1.57, 0.0];
    let tool = |q: &[f64; 6], out: &mut FrameJacobian<f64, 6>| {
        Ur5::frame_jacobian(q, Ur5Frame::Tool0, ReferenceFrame::LocalWorldAligned, out)
    };
    solve(tool, &target, &q_start, &joint_limits(&Ur5::MODEL), settings)
}

fn print_result<const N: usize>(what: &str, r: &IkResult<N>) {
    println!(
        "{what}: {} after {} iterations ({} with a joint clamped to its limit)",
        if r.converged { "converged" } else { "NOT converged" },
        r.iterations,
        r.clamped_iterations
    );
    println!(
        "  position error {:.1e} m, orientation error {:.1e} rad",
        r.position_error, r.orientation_error
    );
    println!("  q = [{}]", r.q.map(|x| format!("{x:.4}")).join(", "));
}

#[allow(dead_code)]
fn main() {
    let settings = IkSettings::default();
    println!(
        "Damped-least-squares IK (λ = {:.0e}, steps ≤ {} rad, tolerance {:.0e}):\n",
        settings.damping, settings.max_step, settings.tolerance
    );
    print_result("Panda panda_link8", &panda_flange(&settings));
    print_result("UR5 tool0", &ur5_tool0(&settings));
}
