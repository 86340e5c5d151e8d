//! An invented humanoid (not a commercial product) with a floating base, generated in
//! `build.rs` from `humanoid31.urdf` with its root link, the pelvis, on a free flyer:
//! joint 1 is `root_joint` (Pinocchio's `JointModelFreeFlyer`), then 6-joint legs, a
//! 3-joint waist, 7-joint arms and a 2-joint neck whose yaw is continuous (its
//! coordinate is the angle); soles, hands and a camera are merged.
//!
//! `q` has 38 numbers (`[p; x, y, z, w]` of the pelvis, then 31 joint positions), `v`
//! 37 (the pelvis's linear and angular velocity in its own frame, then 31 rates).
//!
//! ```
//! use robot_humanoid31::Humanoid31;
//! let mut q = [0.0; 38];
//! q[6] = 1.0; // identity quaternion (w)
//! let g = Humanoid31::generalized_gravity(&q, &Humanoid31::NOMINAL_PARAMS);
//! let mass: f64 = Humanoid31::MODEL.bodies.iter().map(|b| b.mass).sum();
//! assert!((g[2] - mass * 9.81).abs() < 1e-9);
//! ```

include!(concat!(env!("OUT_DIR"), "/humanoid31.rs"));
