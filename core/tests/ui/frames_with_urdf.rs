// Frames belong to the inline form; a URDF robot declares its frames as links.
fn main() {}

dyngen::robot! {
    name: Ur5,
    urdf: "robots/ur5.urdf",
    frames: { tool: (6, [0.0, 0.0, 0.1]) },
}
