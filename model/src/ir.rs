//! The checked intermediate representation: a fixed-base kinematic tree in regular
//! labelling (joint `j` carries body `j`, its parent `λ(j) < j`), fixed joints merged.

use crate::math::{self, Mat3, Vec3};

/// What a joint allows: the algorithms' joint type (`dyngen_algo::JointType`), one
/// enum for every layer. Fixed joints never reach the checked model: they are merged.
/// A planar joint's plane axes are [`math::plane_basis`] of its normal.
pub type JointKind = dyngen_algo::JointType;

/// A rigid placement: maps child coordinates to parent coordinates,
/// `x_parent = rotation · x_child + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub rotation: Mat3,
    pub translation: Vec3,
}

impl Placement {
    pub const IDENTITY: Placement = Placement {
        rotation: math::IDENTITY,
        translation: [0.0; 3],
    };

    /// From URDF `xyz` and `rpy`; quarter-turn angles give exact 0/±1 entries.
    pub fn from_xyz_rpy(xyz: Vec3, rpy: Vec3) -> Placement {
        Placement {
            rotation: math::rpy_to_matrix(rpy),
            translation: xyz,
        }
    }

    pub fn rpy(&self) -> Vec3 {
        math::matrix_to_rpy(&self.rotation)
    }

    /// `self · other`: first `other`, then `self`.
    pub fn compose(&self, other: &Placement) -> Placement {
        Placement {
            rotation: math::mat_mul(&self.rotation, &other.rotation),
            translation: math::add(&math::mat_vec(&self.rotation, &other.translation), &self.translation),
        }
    }

    pub fn transform_point(&self, p: &Vec3) -> Vec3 {
        math::add(&math::mat_vec(&self.rotation, p), &self.translation)
    }
}

/// Joint position, velocity and effort limits, as URDF writes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    pub lower: f64,
    pub upper: f64,
    pub velocity: f64,
    pub effort: f64,
}

/// Mass properties of one body: `inertia` is about the centre of mass `com`, in the
/// body frame's axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertial {
    pub mass: f64,
    pub com: Vec3,
    pub inertia: Mat3,
}

impl Inertial {
    /// A body whose frame is its centroidal principal frame: `θ = (m, J1, J2, J3)`.
    pub fn principal(mass: f64, moments: Vec3) -> Inertial {
        Inertial {
            mass,
            com: [0.0; 3],
            inertia: [[moments[0], 0.0, 0.0], [0.0, moments[1], 0.0], [0.0, 0.0, moments[2]]],
        }
    }

    /// The 10 standard parameters in Pinocchio's order,
    /// `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, inertia about the
    /// body-frame origin: `I = I_c + m(|c|²E − c cᵀ)`.
    pub fn standard_params(&self) -> [f64; 10] {
        let m = self.mass;
        let c = self.com;
        let i = math::mat_add(&self.inertia, &math::parallel_axis(m, &c));
        [
            m,
            m * c[0],
            m * c[1],
            m * c[2],
            i[0][0],
            i[0][1],
            i[1][1],
            i[0][2],
            i[1][2],
            i[2][2],
        ]
    }

    /// Inverse of [`Inertial::standard_params`]; `None` when the mass is not positive.
    pub fn from_standard_params(p: &[f64; 10]) -> Option<Inertial> {
        let m = p[0];
        if m.is_nan() || m <= 0.0 {
            return None;
        }
        let com = [p[1] / m, p[2] / m, p[3] / m];
        let origin = [[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]];
        let pa = math::parallel_axis(m, &com);
        let mut inertia = origin;
        for r in 0..3 {
            for c in 0..3 {
                inertia[r][c] -= pa[r][c];
            }
        }
        Some(Inertial { mass: m, com, inertia })
    }

    /// The same mass properties seen from another frame: `placement` maps this
    /// body's coordinates into the new frame.
    pub fn transformed(&self, placement: &Placement) -> Inertial {
        Inertial {
            mass: self.mass,
            com: placement.transform_point(&self.com),
            inertia: math::rotate_inertia(&placement.rotation, &self.inertia),
        }
    }

    /// Two bodies rigidly joined, expressed in a common frame.
    pub fn combined(&self, other: &Inertial) -> Inertial {
        let m = self.mass + other.mass;
        if m == 0.0 {
            // Massless parts: their rotational inertias add, wherever they are.
            return Inertial {
                inertia: math::mat_add(&self.inertia, &other.inertia),
                ..*self
            };
        }
        let com = math::scale(
            1.0 / m,
            &math::add(&math::scale(self.mass, &self.com), &math::scale(other.mass, &other.com)),
        );
        let mut inertia = [[0.0; 3]; 3];
        for part in [self, other] {
            let shifted = math::mat_add(
                &part.inertia,
                &math::parallel_axis(part.mass, &math::sub(&part.com, &com)),
            );
            inertia = math::mat_add(&inertia, &shifted);
        }
        Inertial { mass: m, com, inertia }
    }

    /// Principal moments about the centre of mass (ascending) and the principal axes
    /// as the columns of a proper rotation.
    pub fn principal_axes(&self) -> (Vec3, Mat3) {
        math::symmetric_eigen(&self.inertia)
    }

    /// The nearest physically consistent inertial: same mass, centre of mass and
    /// principal axes, principal moments moved by
    /// [`nearest_physical_moments`](crate::desc::nearest_physical_moments). Itself
    /// (to rounding) when already consistent.
    pub fn nearest_physical(&self) -> Inertial {
        let (ev, axes) = self.principal_axes();
        if crate::desc::inertia_violation(ev) == 0.0 {
            return *self;
        }
        let j = crate::desc::nearest_physical_moments(ev);
        let mut inertia = [[0.0; 3]; 3];
        for (r, row) in inertia.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                *x = (0..3).map(|k| axes[r][k] * j[k] * axes[c][k]).sum();
            }
        }
        Inertial { inertia, ..*self }
    }
}

/// What a joint does besides moving its body, as the description gives it (URDF
/// `<dynamics damping friction>`, MJCF `damping frictionloss armature`): the nominal
/// rotor inertia, viscous and Coulomb friction of the joint parameters
/// `[Ia, Fv, Fc, F0]` ([`crate::joint_params`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointDynamics {
    /// Rotor inertia `Ia` (kg·m² or kg), MJCF `armature` (Pinocchio's `armature`):
    /// `τ += Ia·q̈` on each velocity coordinate of the joint, so the joint-space mass
    /// matrix gains `Ia` on its diagonal (MuJoCo's `qM`). Zero from a URDF.
    pub armature: f64,
    /// Viscous friction `Fv` (N·m·s/rad or N·s/m): `τ += Fv·q̇`.
    pub damping: f64,
    /// Coulomb friction `Fc` (N·m or N): `τ += Fc·sign(q̇)`.
    pub friction: f64,
}

/// A joint of the checked model.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// Parent body: 0 is the fixed base, otherwise the index `1..j` of a moving body.
    pub parent: usize,
    /// Joint frame at `q = 0` in the parent body's frame.
    pub origin: Placement,
    /// Unit axis in the joint (= child body) frame; zero for a joint without one
    /// ([`JointKind::has_axis`]).
    pub axis: Vec3,
    pub limits: Option<Limits>,
    pub dynamics: JointDynamics,
    /// The joint this one follows (URDF `<mimic>`, MJCF `<equality><joint>`): then it
    /// has no coordinate of its own, its coordinate being `multiplier · q_leader +
    /// offset`.
    pub mimic: Option<JointMimic>,
}

/// How a joint follows another (URDF `<mimic>`, a linear MJCF `<equality><joint>`,
/// Pinocchio's mimic joint), the leader 1-based: one type for every layer, the
/// algorithms' own.
pub use dyngen_algo::JointMimic;

/// A moving body of the checked model; its frame is its joint's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub name: String,
    pub inertial: Inertial,
    /// Links rigidly attached through fixed joints whose inertia was lumped here.
    pub merged: Vec<String>,
}

/// A named frame rigidly attached to a body: every link of the description (the
/// base link, each moving body's own link, the links merged through fixed joints)
/// and the frames a `robot!` description declares.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub name: String,
    /// The body it is attached to: 0 is the fixed base.
    pub body: usize,
    /// The frame in the body's frame: `x_body = rotation · x_frame + translation`.
    pub placement: Placement,
}

/// A checked kinematic tree in regular labelling: `joints[j - 1]` carries
/// `bodies[j - 1]` (body `j`), and `joints[j - 1].parent < j`. Body 0 is fixed: the
/// robot's base, or the world when joint 1 is a [`JointKind::FreeFlyer`] (a floating
/// base). Coordinates are laid out joint after joint: joint `j`'s positions start at
/// [`Model::q_offset`]`(j)` and its velocities at [`Model::v_offset`]`(j)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    pub name: String,
    /// Gravity in the base frame, m/s².
    pub gravity: Vec3,
    /// Name of the fixed base (body 0).
    pub base: String,
    pub joints: Vec<Joint>,
    pub bodies: Vec<Body>,
    /// Every named frame: the base link first, then the links in the order the
    /// depth-first numbering reaches them (each body's own link before the links
    /// merged into it). Names are unique.
    pub frames: Vec<Frame>,
    /// What the front end accepted but the user should know, each printed by
    /// [`ModelError::warning_message`](crate::ModelError::warning_message): body
    /// inertias that break physical consistency (kept as written, or replaced when
    /// [`LoadOptions::balance_inertia`](crate::LoadOptions) asks), joints along which
    /// nothing with mass moves, what the description says that the model leaves out.
    /// A strict build refuses the first two.
    pub warnings: Vec<crate::ModelError>,
}

impl Model {
    /// The model with every body's inertial replaced by its
    /// [`Inertial::nearest_physical`]: for what needs physical consistency (draws of
    /// consistent parameters around the nominal ones) when the description was
    /// accepted with [`Model::warnings`] about non-physical inertias (which it drops).
    /// Identical otherwise.
    pub fn nearest_physical(&self) -> Model {
        let mut model = self.clone();
        for body in &mut model.bodies {
            body.inertial = body.inertial.nearest_physical();
        }
        model.warnings.retain(|w| {
            !matches!(
                w.kind,
                crate::ErrorKind::NotPositiveDefinite(_) | crate::ErrorKind::TriangleInequality(_)
            )
        });
        model
    }

    /// Number of joints, which is the number of moving bodies; also the number of
    /// degrees of freedom when every joint has one ([`Model::multi_dof_joint`]) and
    /// none follows another ([`Model::mimic_joint`]).
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Number of position coordinates, `Σ nq` over the joints that follow no other.
    pub fn nq(&self) -> usize {
        own(&self.joints).map(|j| j.kind.nq()).sum()
    }

    /// Number of velocity coordinates (degrees of freedom), `Σ nv` over the joints that
    /// follow no other.
    pub fn nv(&self) -> usize {
        own(&self.joints).map(|j| j.kind.nv()).sum()
    }

    /// Index in `q` of joint `j`'s first position (1-based joint); a follower's is its
    /// leader's.
    pub fn q_offset(&self, j: usize) -> usize {
        let j = self.joints[j - 1].mimic.map_or(j, |m| m.leader);
        own(&self.joints[..j - 1]).map(|j| j.kind.nq()).sum()
    }

    /// Index in `v` of joint `j`'s first velocity (1-based joint); a follower's is its
    /// leader's.
    pub fn v_offset(&self, j: usize) -> usize {
        let j = self.joints[j - 1].mimic.map_or(j, |m| m.leader);
        own(&self.joints[..j - 1]).map(|j| j.kind.nv()).sum()
    }

    /// The joints with coordinates of their own (every joint but those that follow
    /// another), in the order of their coordinates in `q` and `v`: with joints of one
    /// coordinate each, joint `own_joints()[d]` moves velocity coordinate `d`.
    pub fn own_joints(&self) -> impl Iterator<Item = &Joint> {
        own(&self.joints)
    }

    /// The first joint that follows another (`<mimic>`), if any: what the layers that
    /// take one coordinate per joint refuse by name.
    pub fn mimic_joint(&self) -> Option<&Joint> {
        self.joints.iter().find(|j| j.mimic.is_some())
    }

    /// The joint (1-based) that owns velocity coordinate `d`.
    pub fn joint_of_v(&self, d: usize) -> usize {
        self.joint_owning(d, JointKind::nv).unwrap_or_else(|| {
            // ok: the generator's own indices, always below `nv`.
            panic!(
                "velocity index {d} out of range: the model has {} velocities",
                self.nv()
            )
        })
    }

    /// The tree of velocity coordinates (0-based): coordinate `d`'s parent coordinate,
    /// `None` at the base. The coordinates of a joint with several form a chain, the
    /// first one hanging from the last coordinate of the parent joint (Featherstone's
    /// expanded tree), so the joint-space inertia matrix is nonzero only where one
    /// coordinate supports another and factors without fill-in. With joints that
    /// follow others, a leader's coordinate also moves bodies off its own path and the
    /// matrix has no such structure: the coordinates then form one chain (`d − 1` is
    /// `d`'s parent), and what factors on this tree factors densely.
    pub fn coordinate_parents(&self) -> Vec<Option<usize>> {
        if self.mimic_joint().is_some() {
            return (0..self.nv()).map(|d| d.checked_sub(1)).collect();
        }
        (0..self.nv())
            .map(|d| {
                let j = self.joint_of_v(d);
                if d > self.v_offset(j) {
                    Some(d - 1)
                } else {
                    match self.parent(j) {
                        0 => None,
                        p => Some(self.v_offset(p) + self.joints[p - 1].kind.nv() - 1),
                    }
                }
            })
            .collect()
    }

    /// The joint (1-based) that owns position coordinate `i`, if any.
    pub fn joint_of_q(&self, i: usize) -> Option<usize> {
        self.joint_owning(i, JointKind::nq)
    }

    /// The joint whose coordinates, `width` of them per joint, include `index` (a
    /// leader, never one that follows it).
    fn joint_owning(&self, index: usize, width: fn(JointKind) -> usize) -> Option<usize> {
        let mut end = 0;
        self.joints
            .iter()
            .position(|j| {
                end += if j.mimic.is_some() { 0 } else { width(j.kind) };
                index < end
            })
            .map(|k| k + 1)
    }

    /// Whether the base floats: joint 1 is a free flyer.
    pub fn is_floating(&self) -> bool {
        self.joints.first().is_some_and(|j| j.kind == JointKind::FreeFlyer)
    }

    /// The first joint with more than one degree of freedom (a free flyer, a ball or a
    /// planar joint), if any: what the runtime layers that assume one coordinate per
    /// joint refuse by name.
    pub fn multi_dof_joint(&self) -> Option<&Joint> {
        self.joints.iter().find(|j| j.kind.nv() > 1)
    }

    /// Parent body of body `i` (1-based), 0 for the base.
    pub fn parent(&self, i: usize) -> usize {
        self.joints[i - 1].parent
    }

    /// Children of body `i` (0 = base), as 1-based body indices.
    pub fn children(&self, i: usize) -> Vec<usize> {
        (1..=self.dof()).filter(|&j| self.parent(j) == i).collect()
    }

    /// The nominal standard parameters of every body, 10 per body, body 1 first.
    pub fn standard_params(&self) -> Vec<f64> {
        self.bodies.iter().flat_map(|b| b.inertial.standard_params()).collect()
    }

    /// The frame named `name`, by its index in [`Model::frames`].
    pub fn frame_index(&self, name: &str) -> Option<usize> {
        self.frames.iter().position(|f| f.name == name)
    }

    /// Whether joint `a` (1-based) lies on the path from body `i` to the base.
    pub fn supports(&self, a: usize, i: usize) -> bool {
        let mut k = i;
        while k != 0 {
            if k == a {
                return true;
            }
            k = self.parent(k);
        }
        false
    }
}

/// The joints among `joints` with coordinates of their own (following no other).
fn own(joints: &[Joint]) -> impl Iterator<Item = &Joint> {
    joints.iter().filter(|j| j.mimic.is_none())
}
