// A function that was not selected does not exist: its trait is not implemented.
fn main() {
    let mut m = [0.0; 4];
    <Planar2 as dyngen::MassMatrix>::crba(&[0.0; 2], &[0.0; 20], &mut m);
}

dyngen::robot! {
    name: Planar2,
    functions: [rnea],
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
}
