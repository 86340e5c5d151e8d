//! A generated robot in a `#![no_std]` crate, as on a microcontroller: the crate
//! compiles only if the generated code and `dyngen` use nothing from `std` (no
//! allocation, no `std::` paths, no float methods of `std`). Built alone
//! (`cargo build -p robot-no-std`), `dyngen` has only its `libm` feature.
//!
//! A SCARA arm: two revolute joints about the vertical and a quill sliding along
//! it, so gravity loads only the quill.
//!
//! ```
//! let tau = robot_no_std::gravity_torques(&[0.3, -0.5, 0.05]);
//! assert!(tau[0].abs() < 1e-12 && tau[1].abs() < 1e-12);
//! assert!((tau[2] - 0.8 * 9.81).abs() < 1e-12);
//! let tau32 = robot_no_std::gravity_torques_f32(&[0.3, -0.5, 0.05]);
//! assert!((tau32[2] - 0.8 * 9.81).abs() < 1e-4);
//! ```

#![no_std]

dyngen::robot! {
    name: Scara,
    incidence: [
        [-1,  0,  0],   // body 0: the base
        [ 1, -1,  0],   // body 1: the upper arm
        [ 0,  1, -1],   // body 2: the forearm
        [ 0,  0,  1],   // body 3: the quill, sliding along z
    ],
    joints: [revolute(z), revolute(z), prismatic(z)],
    body_joint_vectors: {
        (0, 1): [0.0, 0.0, 0.4],
        (1, 1): [-0.2, 0.0, 0.0], (1, 2): [0.2, 0.0, 0.0],
        (2, 2): [-0.15, 0.0, 0.0], (2, 3): [0.15, 0.0, 0.0],
        (3, 3): [0.0, 0.0, 0.1],
    },
    bodies: {
        1: cylinder(mass: 4.0, radius: 0.05, length: 0.4, axis: x),
        2: cylinder(mass: 2.5, radius: 0.04, length: 0.3, axis: x),
        3: principal(mass: 0.8, moments: [0.0027, 0.0027, 0.0004]),
    },
}

/// Joint torques and force holding the arm still at `q`: `rnea(q, 0, 0)`, in
/// allocation-free code.
pub fn gravity_torques(q: &[f64; 3]) -> [f64; 3] {
    Scara::rnea(q, &[0.0; 3], &[0.0; 3], &Scara::NOMINAL_PARAMS)
}

/// The same in `f32`, as a microcontroller without a double-precision unit runs it.
pub fn gravity_torques_f32(q: &[f32; 3]) -> [f32; 3] {
    let params = Scara::NOMINAL_PARAMS.map(|p| p as f32);
    Scara::rnea(q, &[0.0; 3], &[0.0; 3], &params)
}
