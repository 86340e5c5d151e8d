// Frame positions and angles are finite and within ±1e9 (SI).
fn main() {}

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
        (1, 1): [-0.5, 0.0, 0.0], (1, 2): [0.5, 0.0, 0.0],
        (2, 2): [-0.5, 0.0, 0.0],
    },
    bodies: {
        1: cylinder(mass: 10.0, radius: 0.05, length: 1.0, axis: x),
        2: principal(mass: 5.0, moments: [0.005, 0.4, 0.4]),
    },
    frames: {
        tool: (2, [2e9, 0.0, 0.0]),
        camera: (1, [0.0, 0.05, 0.0], rest: [0.0, 1e999, 0.0]),
    },
}
