//! An invented quadruped (not a commercial product) with a floating base, generated in
//! `build.rs` from `quadruped12.urdf` with its root link, the trunk, on a free flyer:
//! joint 1 is `root_joint` (Pinocchio's `JointModelFreeFlyer`), then four 3-joint legs
//! (hip abduction about x, hip flexion and knee about y), feet merged into the shanks.
//!
//! `q = [p; x, y, z, w; 12 joint angles]` (19 numbers: the trunk's position in the
//! world, its orientation as a unit quaternion, then the legs), `v = [v; ω; 12 joint
//! rates]` (18 numbers, the trunk's linear and angular velocity in the trunk frame).
//! The first six entries of `rnea` are the wrench on the trunk in the trunk frame.
//!
//! ```
//! use robot_quadruped12::Quadruped12;
//! // Standing still, level: the free flyer carries the weight, the legs their share.
//! let mut q = [0.0; 19];
//! q[6] = 1.0; // identity quaternion (w)
//! let g = Quadruped12::generalized_gravity(&q, &Quadruped12::NOMINAL_PARAMS);
//! let mass: f64 = Quadruped12::MODEL.bodies.iter().map(|b| b.mass).sum();
//! assert!((g[2] - mass * 9.81).abs() < 1e-9);
//! ```

include!(concat!(env!("OUT_DIR"), "/quadruped12.rs"));
