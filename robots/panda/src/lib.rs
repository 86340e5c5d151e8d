//! Franka Emika Panda, 7 revolute joints, generated in `build.rs` from `panda.urdf`:
//! kinematics from Franka's published modified-DH parameters, inertial parameters
//! identified by Gaz, Cognetti, Oliva, Robuffo Giordano and De Luca, "Dynamic
//! Identification of the Franka Emika Panda Robot With Retrieval of Feasible
//! Parameters Using Penalty-Based Optimization", IEEE RA-L 4(4), 2019 (sources and
//! choices in the comment at the top of the URDF).
//!
//! ```
//! use robot_panda::Panda;
//! let q = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];
//! let mut m = [[0.0; 7]; 7];
//! Panda::crba(&q, &Panda::NOMINAL_PARAMS, &mut m);
//! assert!((0..7).all(|i| m[i][i] > 0.0));
//! ```

include!(concat!(env!("OUT_DIR"), "/panda.rs"));
