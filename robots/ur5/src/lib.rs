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

include!(concat!(env!("OUT_DIR"), "/ur5.rs"));
