//! The paper's 6-DOF manipulator: six homogeneous cylinders B1..B6 in a serial
//! chain, written in the paper's graph-theoretic description with the full 7 × 6
//! incidence matrix. Dimensions and masses are those of a mid-size industrial arm
//! (about 10 kg payload class), in the manner of the paper's Table 1:
//!
//! | body | role        | mass (kg) | length (m) | radius (m) | cylinder axis | J_axis (kg·m²) | J_perp (kg·m²) |
//! |------|-------------|-----------|------------|------------|---------------|----------------|----------------|
//! | B1   | turret      | 35.0      | 0.45       | 0.12       | z             | 0.252          | 0.716625       |
//! | B2   | upper arm   | 22.0      | 0.70       | 0.09       | x             | 0.0891         | 0.942883       |
//! | B3   | forearm     | 12.0      | 0.60       | 0.07       | x             | 0.0294         | 0.3747         |
//! | B4   | wrist roll  | 4.0       | 0.16       | 0.05       | x             | 0.005          | 0.011033       |
//! | B5   | wrist pitch | 2.5       | 0.12       | 0.045      | x             | 0.002531       | 0.004266       |
//! | B6   | flange      | 1.2       | 0.08       | 0.04       | x             | 0.00096        | 0.00112        |
//!
//! Joints: J1 turret yaw about z at the base origin, J2 shoulder and J3 elbow pitch
//! about y, J4 wrist roll about x, J5 wrist pitch about y, J6 flange roll about x.
//! Every body frame is its centroidal principal frame; at rest (q = 0) the turret
//! stands on the base and the arm points along the base x axis; joints sit at the
//! cylinders' end faces. Gravity is −9.81 m/s² along the base z axis.
//!
//! ```
//! use robot_paper6::Paper6;
//! let tau = Paper6::rnea(&[0.0; 6], &[0.0; 6], &[0.0; 6], &Paper6::NOMINAL_PARAMS);
//! assert!(tau[0].abs() < 1e-12); // the turret axis is vertical
//! assert!(tau[1] < -100.0); // the shoulder holds the outstretched arm
//! ```

dyngen::robot! {
    name: Paper6,
    incidence: [
        // J1  J2  J3  J4  J5  J6
        [-1,  0,  0,  0,  0,  0],   // B0: base
        [ 1, -1,  0,  0,  0,  0],   // B1: turret
        [ 0,  1, -1,  0,  0,  0],   // B2: upper arm
        [ 0,  0,  1, -1,  0,  0],   // B3: forearm
        [ 0,  0,  0,  1, -1,  0],   // B4: wrist roll
        [ 0,  0,  0,  0,  1, -1],   // B5: wrist pitch
        [ 0,  0,  0,  0,  0,  1],   // B6: flange
    ],
    joints: [revolute(z), revolute(y), revolute(y), revolute(x), revolute(y), revolute(x)],
    body_joint_vectors: {
        (0, 1): [0.0, 0.0, 0.0],
        (1, 1): [0.0, 0.0, -0.225], (1, 2): [0.0, 0.0, 0.225],
        (2, 2): [-0.35, 0.0, 0.0],  (2, 3): [0.35, 0.0, 0.0],
        (3, 3): [-0.3, 0.0, 0.0],   (3, 4): [0.3, 0.0, 0.0],
        (4, 4): [-0.08, 0.0, 0.0],  (4, 5): [0.08, 0.0, 0.0],
        (5, 5): [-0.06, 0.0, 0.0],  (5, 6): [0.06, 0.0, 0.0],
        (6, 6): [-0.04, 0.0, 0.0],
    },
    bodies: {
        1: cylinder(mass: 35.0, radius: 0.12, length: 0.45, axis: z),
        2: cylinder(mass: 22.0, radius: 0.09, length: 0.7, axis: x),
        3: cylinder(mass: 12.0, radius: 0.07, length: 0.6, axis: x),
        4: cylinder(mass: 4.0, radius: 0.05, length: 0.16, axis: x),
        5: cylinder(mass: 2.5, radius: 0.045, length: 0.12, axis: x),
        6: cylinder(mass: 1.2, radius: 0.04, length: 0.08, axis: x),
    },
}
