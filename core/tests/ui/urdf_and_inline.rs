// A robot comes from a URDF file or from an inline description, not both.
fn main() {}

dyngen::robot! {
    name: Ur5,
    urdf: "robots/ur5.urdf",
    gravity: [0.0, 0.0, -9.81],
}
