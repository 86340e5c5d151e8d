//! The robot description a generated type carries as Rust data (`RobotDescription::MODEL`): the
//! checked model it was generated from, in the generator's numbering, so that nothing
//! at run time re-parses a file or renumbers a joint.

/// What a joint allows: one enum for every layer, the algorithms' own.
pub use dyngen_algo::JointType;

/// How a joint follows another (URDF `<mimic>`, MJCF `<equality><joint>`), the leader
/// 1-based.
pub use dyngen_algo::JointMimic;

/// Joint position, velocity and effort limits (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    pub lower: f64,
    pub upper: f64,
    pub velocity: f64,
    pub effort: f64,
}

/// One joint: joint `j` (1-based) carries body `j`; its parent body is `< j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointModel {
    pub name: &'static str,
    pub kind: JointType,
    /// Parent body: 0 is the fixed base.
    pub parent: usize,
    /// Joint frame at `q = 0` in the parent body's frame:
    /// `x_parent = rotation · x_joint + translation`.
    pub rotation: [[f64; 3]; 3],
    pub translation: [f64; 3],
    /// Unit axis in the joint (= child body) frame: the plane normal of a planar joint;
    /// zero for a ball joint and a free flyer.
    pub axis: [f64; 3],
    pub limits: Option<JointLimits>,
    /// Nominal rotor inertia `Ia` (MJCF `armature`; 0 from a URDF): `τ += Ia·q̈` on
    /// each velocity coordinate of the joint.
    pub armature: f64,
    /// Nominal viscous friction `Fv` (URDF `<dynamics damping>`): `τ += Fv·q̇`.
    pub damping: f64,
    /// Nominal Coulomb friction `Fc` (URDF `<dynamics friction>`): `τ += Fc·sign(q̇)`.
    pub friction: f64,
    /// The joint this one follows: then it has no coordinate of its own, its position
    /// being `multiplier · q_leader + offset`.
    pub mimic: Option<JointMimic>,
}

/// One moving body; its frame is its joint's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyModel {
    pub name: &'static str,
    pub mass: f64,
    /// Centre of mass in the body frame.
    pub com: [f64; 3],
    /// Inertia about the centre of mass, in the body frame's axes.
    pub inertia: [[f64; 3]; 3],
    /// Links rigidly attached through fixed joints whose inertia was lumped here.
    pub merged: &'static [&'static str],
}

/// A named frame rigidly attached to a body: a link of the description (the base
/// link, a moving body's own link, a link merged through a fixed joint such as a
/// tool flange) or a frame a `robot!` description declares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameModel {
    pub name: &'static str,
    /// The body it is attached to: 0 is the fixed base.
    pub body: usize,
    /// The frame in the body's frame: `x_body = rotation · x_frame + translation`.
    pub rotation: [[f64; 3]; 3],
    pub translation: [f64; 3],
}

/// A kinematic tree in regular labelling: `joints[j - 1]` carries `bodies[j - 1]`
/// (body `j`); body 0 is fixed (the base, or the world when joint 1 is a free flyer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotModel {
    pub name: &'static str,
    /// Gravity in the base frame, m/s².
    pub gravity: [f64; 3],
    /// Name of the fixed base (body 0).
    pub base: &'static str,
    pub joints: &'static [JointModel],
    pub bodies: &'static [BodyModel],
    /// Every named frame, the base link first; a generated robot's frame index
    /// ([`RobotModel::frame_index`], its frame enum) indexes this list.
    pub frames: &'static [FrameModel],
}

impl RobotModel {
    /// The index in [`RobotModel::frames`] of the frame named `name`.
    pub fn frame_index(&self, name: &str) -> Option<usize> {
        self.frames.iter().position(|f| f.name == name)
    }

    /// The joints with coordinates of their own (every joint but those that follow
    /// another), with their 0-based index in [`RobotModel::joints`], in the order of
    /// their coordinates in `q` and `v`.
    pub fn own_joints(&self) -> impl Iterator<Item = (usize, &JointModel)> {
        self.joints.iter().enumerate().filter(|(_, j)| j.mimic.is_none())
    }
}
