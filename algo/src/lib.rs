//! The rigid-body dynamics algorithms of dyngen, written once and generic over the
//! scalar ([`Real`]): on `f64` for a robot loaded at run time, on a symbolic
//! expression type to generate code.
//!
//! Conventions are Pinocchio's: motion vectors `[v; ω]`, force vectors `[f; n]`,
//! everything of body `i` in body `i`'s frame (its joint's frame), gravity entering
//! as a base acceleration `a_0 = [−g; 0]`; joint types and their coordinates as
//! [`JointType`] describes. Every algorithm writes into a [`Workspace`] made once
//! for its [`Multibody`], so that no call allocates.
//!
//! One file per algorithm:
//!
//! - [`forward_kinematics`], [`body_motions`] (`kinematics.rs`): every body's
//!   placement, velocity and acceleration;
//! - [`rnea`] (`rnea.rs`): inverse dynamics, and the joint wrenches on the way;
//! - [`crba`] (`crba.rs`): the joint-space mass matrix;
//! - [`aba`] (`aba.rs`): forward dynamics, with rotor inertia;
//! - [`joint_torque_regressor`] (`regressor.rs`): `τ = Y π`, linear in the standard
//!   parameters, and [`joint_wrench_regressor`], `6 n` rows of joint wrenches;
//! - [`frame_jacobian`], [`compute_frame_jacobian`], [`frame_velocity`],
//!   [`frame_classical_acceleration`], [`frame_jacobian_time_variation`]
//!   (`jacobian.rs`): a frame's Jacobian, velocity, classical acceleration (the drift
//!   `J̇ v` at `a = 0`) and `J̇` in any [`ReferenceFrame`];
//! - [`center_of_mass`], [`com_jacobian`], [`centroidal_map`],
//!   [`centroidal_map_time_variation`] (`centroidal.rs`): the centre of mass, its
//!   Jacobian, the centroidal momentum matrix `A_g` and `Ȧ_g`;
//! - [`rnea_derivatives`], [`aba_derivatives`] (`derivatives.rs`): the derivatives of
//!   inverse and forward dynamics, and `M⁻¹`;
//! - [`Dual`] (`dual.rs`): forward-mode differentiation, on which the time variations
//!   and the derivatives run the algorithms above.
//!
//! ```
//! use dyngen_algo::{rnea, JointSpec, JointType, Multibody, Se3, Workspace};
//! // A pendulum: one revolute joint about y, a 2 kg point mass 0.5 m below it.
//! let mut origin = Se3::identity(0.0, 1.0);
//! origin.translation = [0.0, 0.0, 1.0];
//! let (m, l) = (2.0, -0.5);
//! let params = [m, 0.0, 0.0, m * l, m * l * l, 0.0, m * l * l, 0.0, 0.0, 0.0];
//! let joint = JointSpec { kind: JointType::Revolute, parent: 0, origin, axis: [0.0, 1.0, 0.0],
//!     plane: [[0.0; 3]; 2], params };
//! let pendulum = Multibody::new([0.0, 0.0, -9.81], &[joint]).unwrap();
//! let mut workspace = Workspace::new(&pendulum, ());
//! let mut tau = [0.0];
//! let q = [core::f64::consts::FRAC_PI_2]; // the mass straight out along −x
//! rnea(&pendulum, &mut workspace, &q, &[0.0], &[0.0], &pendulum.params, &mut tau);
//! // Holding it takes m g l about y: the weight 19.62 N at 0.5 m.
//! assert!((tau[0] - m * 9.81 * 0.5).abs() < 1e-12);
//! ```

#![cfg_attr(not(feature = "std"), no_std)]

extern crate alloc;

mod aba;
mod centroidal;
mod crba;
mod derivatives;
mod dual;
mod jacobian;
mod joint;
mod kinematics;
mod mimic;
mod multibody;
mod real;
mod regressor;
mod rnea;
pub mod spatial;

pub use aba::aba;
pub use centroidal::{center_of_mass, centroidal_map, centroidal_map_time_variation, com_jacobian};
pub use crba::crba;
pub use derivatives::{aba_derivatives, rnea_derivatives};
pub use dual::{Dual, DualWorkspace};
pub use jacobian::{
    compute_frame_jacobian, frame_classical_acceleration, frame_jacobian, frame_jacobian_time_variation,
    frame_velocity, ReferenceFrame,
};
pub use joint::{constant_se3, quaternion_rotation, Axis, Joint, JointPlacement, JointType, Rotation};
pub use kinematics::{body_motions, forward_kinematics};
pub use multibody::{JointMimic, JointSpec, Mimic, Multibody, TreeError, Workspace, MIMIC_CYCLE, PARAMS_PER_BODY};
pub use real::{polynomial_sin_cos, Precision, Real};
pub use regressor::{force_regressor, joint_torque_regressor, joint_wrench_regressor};
pub use rnea::rnea;
pub use spatial::{Force, Inertia, Motion, Rotate, Se3};
