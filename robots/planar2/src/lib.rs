//! The planar 2-DOF arm of the paper's Appendix A: two homogeneous cylinders on
//! revolute joints about z, moving in the vertical x–y plane (gravity along −y),
//! written in the paper's graph-theoretic description.
//!
//! | body | mass (kg) | length (m) | radius (m) | J1 = m r²/2 | J2 = J3 = m(3r² + l²)/12 |
//! |------|-----------|------------|------------|-------------|--------------------------|
//! | B1   | 5.0       | 0.5        | 0.04       | 0.004       | 0.106167                 |
//! | B2   | 3.0       | 0.4        | 0.03       | 0.00135     | 0.040675                 |
//!
//! Body frames are centroidal principal frames (cylinder axis along x); at rest both
//! links lie along the base x axis.
//!
//! ```
//! use robot_planar2::Planar2;
//! // Holding the arm horizontal: joint 1 carries both links' weight moments.
//! let tau = Planar2::rnea(&[0.0; 2], &[0.0; 2], &[0.0; 2], &Planar2::NOMINAL_PARAMS);
//! let g = 9.81;
//! let want1 = 5.0 * g * 0.25 + 3.0 * g * (0.5 + 0.2);
//! assert!((tau[0] - want1).abs() < 1e-12);
//! assert!((tau[1] - 3.0 * g * 0.2).abs() < 1e-12);
//! ```

dyngen::robot! {
    name: Planar2,
    gravity: [0.0, -9.81, 0.0],
    incidence: [
        [-1,  0],   // body 0: the base
        [ 1, -1],   // body 1
        [ 0,  1],   // body 2
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
