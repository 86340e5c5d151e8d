//! The robot description a generated type carries as Rust data (`Robot::MODEL`): the
//! checked model it was generated from, in the generator's numbering, so that nothing
//! at run time re-parses a file or renumbers a joint.

/// What a joint allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum JointType {
    /// Rotation about the axis, with position limits.
    Revolute,
    /// Rotation about the axis without limits; its coordinate is the angle.
    Continuous,
    /// Translation along the axis.
    Prismatic,
    /// A ball joint: 4 positions (unit quaternion `[x, y, z, w]`), 3 velocities (the
    /// angular velocity in the child frame).
    Spherical,
    /// The free flyer of a floating base (joint 1 only): 7 positions `[p; x, y, z, w]`,
    /// 6 velocities `[v; ω]` in the body frame, as Pinocchio's `JointModelFreeFlyer`.
    FreeFlyer,
    /// Motion in the plane normal to the axis: 3 positions `[x, y, θ]` (the child's
    /// origin along the plane's axes, its turn about the normal), 3 velocities
    /// `[vx, vy, ω]` in the child frame. Pinocchio's `JointModelPlanar` for the normal
    /// `z`, with the angle in place of its `(cos θ, sin θ)`.
    Planar,
}

impl JointType {
    /// Number of position coordinates: 1, 3, 4 or 7.
    pub const fn nq(self) -> usize {
        match self {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => 1,
            JointType::Planar => 3,
            JointType::Spherical => 4,
            JointType::FreeFlyer => 7,
        }
    }

    /// Number of velocity coordinates: 1, 3 or 6.
    pub const fn nv(self) -> usize {
        match self {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => 1,
            JointType::Spherical | JointType::Planar => 3,
            JointType::FreeFlyer => 6,
        }
    }
}

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
}
