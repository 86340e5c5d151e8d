//! A generated robot in a `#![no_std]` crate, as on a microcontroller: the crate
//! compiles only if the generated code and `dyngen` use nothing from `std` (no
//! allocation, no `std::` paths, no float methods of `std`). Built alone
//! (`cargo build -p robot-no-std`), `dyngen` has only its `libm` feature.
//!
//! ```
//! let tau = robot_no_std::gravity_torques(&[0.0, 0.0]);
//! assert!((tau[1] - 3.0 * 9.81 * 0.2).abs() < 1e-12);
//! ```

#![no_std]

dyngen::robot! {
    name: Planar2,
    gravity: [0.0, -9.81, 0.0],
    incidence: [
        [-1,  0],
        [ 1, -1],
        [ 0,  1],
    ],
    joints: [revolute(z), revolute(z)],
    body_joint_vectors: {
        (0, 1): [0.0, 0.0, 0.0],
        (1, 1): [-0.25, 0.0, 0.0],
        (1, 2): [0.25, 0.0, 0.0],
        (2, 2): [-0.2, 0.0, 0.0],
    },
    bodies: {
        1: cylinder(mass: 5.0, radius: 0.04, length: 0.5, axis: x),
        2: cylinder(mass: 3.0, radius: 0.03, length: 0.4, axis: x),
    },
}

/// Joint torques holding the arm still at `q`: `rnea(q, 0, 0)`, in `f32`-free,
/// allocation-free code.
pub fn gravity_torques(q: &[f64; 2]) -> [f64; 2] {
    Planar2::rnea(q, &[0.0; 2], &[0.0; 2], &Planar2::NOMINAL_PARAMS)
}

/// The same in `f32`, as a microcontroller without a double-precision unit runs it.
pub fn gravity_torques_f32(q: &[f32; 2]) -> [f32; 2] {
    let params = Planar2::NOMINAL_PARAMS.map(|p| p as f32);
    Planar2::rnea(q, &[0.0; 2], &[0.0; 2], &params)
}
