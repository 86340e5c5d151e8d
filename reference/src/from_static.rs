//! The model a generated robot carries (`Robot::MODEL`, plain `'static` data in the
//! core crate) as the runtime's [`Model`]: no file is parsed and no joint renumbered,
//! so the reference, identification and NIM see exactly the generator's numbering.

use dyngen::{Robot, RobotModel};
use dyngen_model::{Body, Frame, Inertial, Joint, JointDynamics, Limits, Model, Placement};

/// The runtime model of a generated robot's `MODEL`.
pub fn model_from_static(m: &RobotModel) -> Model {
    Model {
        warnings: Vec::new(),
        name: m.name.to_string(),
        gravity: m.gravity,
        base: m.base.to_string(),
        joints: m
            .joints
            .iter()
            .map(|j| Joint {
                name: j.name.to_string(),
                kind: j.kind,
                parent: j.parent,
                origin: Placement {
                    rotation: j.rotation,
                    translation: j.translation,
                },
                axis: j.axis,
                limits: j.limits.map(|l| Limits {
                    lower: l.lower,
                    upper: l.upper,
                    velocity: l.velocity,
                    effort: l.effort,
                }),
                dynamics: JointDynamics {
                    armature: j.armature,
                    damping: j.damping,
                    friction: j.friction,
                },
                mimic: j.mimic,
            })
            .collect(),
        bodies: m
            .bodies
            .iter()
            .map(|b| Body {
                name: b.name.to_string(),
                inertial: Inertial {
                    mass: b.mass,
                    com: b.com,
                    inertia: b.inertia,
                },
                merged: b.merged.iter().map(|s| s.to_string()).collect(),
            })
            .collect(),
        frames: m
            .frames
            .iter()
            .map(|f| Frame {
                name: f.name.to_string(),
                body: f.body,
                placement: Placement {
                    rotation: f.rotation,
                    translation: f.translation,
                },
            })
            .collect(),
    }
}

/// A generated robot's model as URDF text (fixed joints merged), for tools that read
/// URDF: `dyngen_model::to_urdf` of [`model_from_static`] of `R::MODEL`.
pub fn urdf_of<R: Robot>() -> String {
    dyngen_model::to_urdf(&model_from_static(&R::MODEL))
}
