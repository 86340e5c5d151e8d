//! Universal Robots UR5 (CB3), generated in `build.rs` from `ur5.urdf`: kinematics
//! from UR's published DH parameters, masses and centres of mass from UR's published
//! dynamics data, inertia tensors from homogeneous-cylinder approximations (see the
//! comment at the top of the URDF).
//!
//! ```
//! use robot_ur5::Ur5;
//! let q = [0.0, -1.57, 1.57, 0.0, 1.57, 0.0];
//! let tau = Ur5::rnea(&q, &[0.0; 6], &[0.0; 6], &Ur5::NOMINAL_PARAMS);
//! assert!(tau[1].abs() > 10.0); // the shoulder holds the arm against gravity
//! ```
//!
//! The tool frame's Jacobian and drift, and one linearised time step for MPC:
//!
//! ```
//! use dyngen::{AbaDerivatives, FrameJacobian, ReferenceFrame};
//! use robot_ur5::{Ur5, Ur5Frame};
//!
//! let (q, v) = ([0.1, -1.2, 1.4, -0.3, 1.5, 0.2], [0.3; 6]);
//! let mut j = FrameJacobian::<f64, 6>::default();
//! Ur5::frame_jacobian(&q, Ur5Frame::Tool0, ReferenceFrame::LocalWorldAligned, &mut j);
//! let tool_velocity = j.velocity(&v); // linear, angular
//! let drift = Ur5::frame_classical_acceleration(
//!     &q, &v, &[0.0; 6], Ur5Frame::Tool0, ReferenceFrame::LocalWorldAligned,
//! ); // J̇ v
//! assert_eq!(Ur5Frame::from_name("tool0"), Some(Ur5Frame::Tool0));
//!
//! let mut d = AbaDerivatives::<f64, 6>::default();
//! Ur5::aba_derivatives(&q, &v, &[0.0; 6], &Ur5::NOMINAL_PARAMS, &mut d);
//! let step = d.semi_implicit_euler(&q, &v, 0.01); // x⁺ and (A, B)
//! assert!(step.a(0, 0).is_some() && tool_velocity.linear.norm() > 0.0);
//! assert!(drift.linear.norm() > 0.0);
//! ```

include!(concat!(env!("OUT_DIR"), "/ur5.rs"));
