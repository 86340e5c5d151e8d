//! The kinematic tree the algorithms run on, and the workspace they write into.

use crate::joint::{Axis, Joint, JointPlacement, JointType, Rotation};
use crate::spatial::{Force, Inertia, Motion, Se3, SpatialMatrix, Vec3};
use crate::Real;
use alloc::vec::Vec;

/// Standard parameters per body: `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`,
/// inertia about the body-frame origin.
pub const PARAMS_PER_BODY: usize = 10;

/// A kinematic tree in regular labelling: joint `i` (0-based) carries body `i + 1`,
/// whose parent is a body `< i + 1`; body 0 is fixed (the base, or the world under a
/// free flyer).
#[derive(Clone, Debug, PartialEq)]
pub struct Multibody {
    pub joints: Vec<Joint>,
    /// Gravity in the base frame, m/s².
    pub gravity: [f64; 3],
    /// The nominal standard parameters, [`PARAMS_PER_BODY`] per body.
    pub params: Vec<f64>,
    nq: usize,
    nv: usize,
    /// The velocity coordinates that move each body, root first: body `i`'s are
    /// `supports[support_offsets[i]..support_offsets[i + 1]]` (body 0 has none).
    pub(crate) supports: Vec<usize>,
    pub(crate) support_offsets: Vec<usize>,
    /// Per velocity coordinate, the one before it on the path to the base (the
    /// previous coordinate of its joint, or the last of the parent's joint), or
    /// [`NO_PARENT`]: the tree of `M`'s sparsity.
    pub(crate) dof_parent: Vec<usize>,
    /// The joints that follow others ([`Multibody::with_mimics`]), and how the
    /// coordinates of the tree follow those of the multibody; `None` without any.
    pub(crate) reduction: Option<alloc::boxed::Box<Reduction>>,
}

/// A joint that moves with another (URDF's `<mimic>`, Pinocchio's mimic joint): its
/// coordinate is `multiplier · q_leader + offset`, its velocity and acceleration
/// `multiplier` times the leader's, and it has no coordinate of its own. Both joints
/// have one coordinate (revolute, continuous or prismatic). Joints are 0-based, as
/// in [`Multibody::joints`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mimic {
    pub joint: usize,
    pub leader: usize,
    pub multiplier: f64,
    pub offset: f64,
}

/// How a joint of a description follows another, in the 1-based joint numbering of
/// the model layers (`dyngen_model::Model`, a generated robot's `RobotModel`): its
/// coordinate is `multiplier · q_leader + offset`, its velocity and acceleration
/// `multiplier` times the leader's. The leader follows no other joint (chains are
/// resolved with [`Mimic::resolve`] when a model is built). [`Mimic`] is the same rule
/// with both joints 0-based, as [`Multibody::with_mimics`] takes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointMimic {
    pub leader: usize,
    pub multiplier: f64,
    pub offset: f64,
}

impl JointMimic {
    /// The rule of joint `joint` (1-based) for [`Multibody::with_mimics`].
    pub fn of_joint(self, joint: usize) -> Mimic {
        Mimic {
            joint: joint - 1,
            leader: self.leader - 1,
            multiplier: self.multiplier,
            offset: self.offset,
        }
    }
}

/// Why a joint in a cycle of followers cannot be resolved ([`Mimic::resolve`]).
pub const MIMIC_CYCLE: &str = "its leaders, followed in turn, run in a cycle; one joint of the cycle must lead";

impl Mimic {
    /// Each of `mimics` (at most one per joint, of a tree of `joints` joints) with its
    /// leader followed to one that follows no other: `q = k (k' q_leader + b') + b`.
    ///
    /// # Errors
    /// A joint whose leaders, followed in turn, run in a cycle.
    pub fn resolve(mimics: &[Mimic], joints: usize) -> Result<Vec<Mimic>, usize> {
        let leader_of = |j: usize| mimics.iter().find(|m| m.joint == j);
        mimics
            .iter()
            .map(|m| {
                let (mut r, mut steps) = (*m, 0);
                while let Some(next) = leader_of(r.leader) {
                    steps += 1;
                    if steps > joints {
                        return Err(m.joint);
                    }
                    r = Mimic {
                        joint: r.joint,
                        leader: next.leader,
                        multiplier: r.multiplier * next.multiplier,
                        offset: r.multiplier * next.offset + r.offset,
                    };
                }
                Ok(r)
            })
            .collect()
    }
}

/// How the coordinates of the tree (every joint its own, as [`Joint::q_offset`] and
/// [`Joint::v_offset`] lay them out) follow the multibody's: `q_tree = E q + b`,
/// `v_tree = E v`. The algorithms run on the tree, and reduce what they return with
/// `Eᵀ` (the virtual work of a follower's effort goes to its leader).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Reduction {
    pub(crate) mimics: Vec<Mimic>,
    /// The multibody's coordinates.
    pub(crate) nq: usize,
    pub(crate) nv: usize,
    /// Per tree position coordinate: the multibody coordinate it follows, the
    /// multiplier and the offset.
    pub(crate) q: Vec<(usize, f64, f64)>,
    /// Per tree velocity coordinate: the multibody coordinate it follows, the multiplier.
    pub(crate) v: Vec<(usize, f64)>,
    /// Per joint, its first position and velocity coordinate in the multibody's
    /// coordinates; `None` for a follower.
    pub(crate) offsets: Vec<Option<(usize, usize)>>,
}

/// No velocity coordinate ([`Multibody`]'s `dof_parent` of a root coordinate).
pub(crate) const NO_PARENT: usize = usize::MAX;

/// One joint of [`Multibody::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointSpec {
    pub kind: JointType,
    /// The parent body (0 the base), smaller than this joint's body.
    pub parent: usize,
    /// The joint frame at `q = 0` in the parent body's frame.
    pub origin: Se3<f64>,
    /// Unit axis (plane normal of a planar joint; ignored for a ball and a free flyer).
    pub axis: [f64; 3],
    /// The in-plane axes of a planar joint (ignored otherwise).
    pub plane: [[f64; 3]; 2],
    /// The carried body's standard parameters.
    pub params: [f64; PARAMS_PER_BODY],
}

/// Why [`Multibody::new`] refused a tree.
#[derive(Clone, Debug, PartialEq)]
pub enum TreeError {
    /// Joint `joint` (0-based) names a parent that is not an earlier body.
    ParentNotBefore { joint: usize, parent: usize },
    /// A free flyer on a moving body (free flyers hang from the base: a floating base
    /// first, then any free bodies beside it).
    FreeFlyerNotAtRoot { joint: usize },
    /// A [`Mimic`] that cannot be: a joint or a leader out of range or without
    /// exactly one coordinate, a joint following itself, following twice, or a cycle.
    BadMimic { joint: usize, reason: &'static str },
}

impl core::fmt::Display for TreeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            TreeError::ParentNotBefore { joint, parent } => write!(
                f,
                "joint {joint} (body {}) has parent body {parent}; a parent must be 0 (the base) or an earlier body",
                joint + 1
            ),
            TreeError::FreeFlyerNotAtRoot { joint } => {
                write!(
                    f,
                    "joint {joint} is a free flyer on a moving body; a free flyer hangs from the base (parent 0)"
                )
            }
            TreeError::BadMimic { joint, reason } => write!(f, "mimic joint {joint}: {reason}"),
        }
    }
}

impl Multibody {
    pub fn new(gravity: [f64; 3], specs: &[JointSpec]) -> Result<Multibody, TreeError> {
        let (mut nq, mut nv) = (0, 0);
        let mut joints = Vec::with_capacity(specs.len());
        let mut params = Vec::with_capacity(PARAMS_PER_BODY * specs.len());
        for (i, s) in specs.iter().enumerate() {
            if s.parent > i {
                return Err(TreeError::ParentNotBefore {
                    joint: i,
                    parent: s.parent,
                });
            }
            if s.kind == JointType::FreeFlyer && s.parent != 0 {
                return Err(TreeError::FreeFlyerNotAtRoot { joint: i });
            }
            let joint = Joint {
                kind: s.kind,
                parent: s.parent,
                origin: s.origin,
                axis: Axis::new(s.axis),
                plane: s.plane,
                q_offset: nq,
                v_offset: nv,
            };
            nq += s.kind.nq();
            nv += s.kind.nv();
            joints.push(joint);
            params.extend_from_slice(&s.params);
        }
        let (mut supports, mut support_offsets) = (Vec::new(), alloc::vec![0, 0]);
        for j in &joints {
            let (from, to) = (support_offsets[j.parent], support_offsets[j.parent + 1]);
            for t in from..to {
                supports.push(supports[t]);
            }
            supports.extend(j.v_offset..j.v_offset + j.nv());
            support_offsets.push(supports.len());
        }
        let mut dof_parent = Vec::with_capacity(nv);
        for j in &joints {
            let mut before = match j.parent {
                0 => NO_PARENT,
                p => joints[p - 1].v_offset + joints[p - 1].nv() - 1,
            };
            for d in j.v_offset..j.v_offset + j.nv() {
                dof_parent.push(before);
                before = d;
            }
        }
        Ok(Multibody {
            joints,
            gravity,
            params,
            nq,
            nv,
            supports,
            support_offsets,
            dof_parent,
            reduction: None,
        })
    }

    /// The same tree with some joints following others ([`Mimic`]): the multibody
    /// then has the leaders' coordinates only (`nq`, `nv` count them), every
    /// algorithm takes and returns those, and its results are Pinocchio's for a model
    /// with mimic joints: `τ = Eᵀ τ_tree`, `M = Eᵀ M_tree E`, Jacobians `J_tree E`,
    /// regressors `Eᵀ Y_tree`. A follower of a follower follows the first leader
    /// (multipliers and offsets composed). Forward dynamics then solves with `M`
    /// (dense, `O(n³)`): the articulated-body recursion does not apply.
    ///
    /// # Errors
    /// [`TreeError::BadMimic`] for a joint or leader out of range or with more than
    /// one coordinate, a joint following itself or twice, or a cycle.
    pub fn with_mimics(mut self, mimics: &[Mimic]) -> Result<Multibody, TreeError> {
        if mimics.is_empty() {
            return Ok(self);
        }
        let n = self.joints.len();
        let bad = |joint, reason| Err(TreeError::BadMimic { joint, reason });
        let mut follows: Vec<Option<Mimic>> = alloc::vec![None; n];
        for m in mimics {
            if m.joint >= n || m.leader >= n {
                return bad(m.joint, "the joint or its leader is not a joint of the tree");
            }
            if self.joints[m.joint].nv() != 1 || self.joints[m.joint].nq() != 1 {
                return bad(
                    m.joint,
                    "only a joint with one coordinate (revolute, continuous, prismatic) can follow",
                );
            }
            if self.joints[m.leader].nv() != 1 || self.joints[m.leader].nq() != 1 {
                return bad(
                    m.joint,
                    "its leader does not have one coordinate (revolute, continuous, prismatic)",
                );
            }
            if m.joint == m.leader {
                return bad(m.joint, "a joint cannot follow itself");
            }
            if !(m.multiplier.is_finite() && m.offset.is_finite()) {
                return bad(m.joint, "its multiplier and offset must be finite");
            }
            if follows[m.joint].replace(*m).is_some() {
                return bad(m.joint, "it follows two leaders");
            }
        }
        let resolved = Mimic::resolve(mimics, n).map_err(|joint| TreeError::BadMimic {
            joint,
            reason: MIMIC_CYCLE,
        })?;
        let (mut nq, mut nv) = (0, 0);
        let mut offsets = Vec::with_capacity(n);
        for (k, j) in self.joints.iter().enumerate() {
            if follows[k].is_some() {
                offsets.push(None);
            } else {
                offsets.push(Some((nq, nv)));
                nq += j.nq();
                nv += j.nv();
            }
        }
        let (mut q, mut v) = (Vec::with_capacity(self.nq), Vec::with_capacity(self.nv));
        for (k, j) in self.joints.iter().enumerate() {
            match offsets[k] {
                Some((qo, vo)) => {
                    q.extend((0..j.nq()).map(|e| (qo + e, 1.0, 0.0)));
                    v.extend((0..j.nv()).map(|e| (vo + e, 1.0)));
                }
                None => {
                    let r = resolved.iter().find(|r| r.joint == k).copied();
                    let r = r.expect("every follower is resolved");
                    let (lq, lv) = offsets[r.leader].expect("a resolved leader follows nobody");
                    q.push((lq, r.multiplier, r.offset));
                    v.push((lv, r.multiplier));
                }
            }
        }
        // M couples a leader with its followers' paths: no longer the tree's
        // sparsity, so its factor is dense (each coordinate under the one before).
        self.dof_parent = (0..nv).map(|d| if d == 0 { NO_PARENT } else { d - 1 }).collect();
        self.reduction = Some(alloc::boxed::Box::new(Reduction {
            mimics: resolved,
            nq,
            nv,
            q,
            v,
            offsets,
        }));
        Ok(self)
    }

    /// The joints that follow others, each resolved to an independent leader.
    pub fn mimics(&self) -> &[Mimic] {
        self.reduction.as_ref().map_or(&[], |r| &r.mimics)
    }

    /// Joint `k`'s first position and velocity coordinate in the multibody's `q` and
    /// `v`; `None` for a joint that follows another ([`Mimic`]).
    pub fn coordinates_of(&self, k: usize) -> Option<(usize, usize)> {
        match &self.reduction {
            None => Some((self.joints[k].q_offset, self.joints[k].v_offset)),
            Some(r) => r.offsets[k],
        }
    }

    /// Position and velocity coordinates of the tree, every joint counted (the
    /// algorithms' inner sizes).
    pub(crate) fn tree_nq(&self) -> usize {
        self.nq
    }

    pub(crate) fn tree_nv(&self) -> usize {
        self.nv
    }

    /// Number of moving bodies (= joints).
    pub fn bodies(&self) -> usize {
        self.joints.len()
    }

    /// Number of position coordinates (a follower's not counted: [`Mimic`]).
    pub fn nq(&self) -> usize {
        self.reduction.as_ref().map_or(self.nq, |r| r.nq)
    }

    /// Number of velocity coordinates (a follower's not counted: [`Mimic`]).
    pub fn nv(&self) -> usize {
        self.reduction.as_ref().map_or(self.nv, |r| r.nv)
    }

    /// Scales every quaternion of the configuration `q` to unit length (Pinocchio's
    /// `normalize`); a zero quaternion is left as it is.
    ///
    /// # Panics
    /// If `q` is not `nq` long.
    pub fn normalize(&self, q: &mut [f64]) {
        crate::kinematics::check_len("q", q, self.nq());
        for (k, j) in self.joints.iter().enumerate() {
            let Some((offset, _)) = self.coordinates_of(k) else {
                continue;
            };
            let k = match j.kind {
                JointType::Spherical => offset,
                JointType::FreeFlyer => offset + 3,
                _ => continue,
            };
            let n = sqrt(q[k..k + 4].iter().map(|x| x * x).sum::<f64>());
            if n > 0.0 {
                q[k..k + 4].iter_mut().for_each(|x| *x /= n);
            }
        }
    }

    /// The neutral configuration: zero coordinates, identity quaternions.
    pub fn neutral(&self) -> Vec<f64> {
        let mut q = alloc::vec![0.0; self.nq()];
        for (k, j) in self.joints.iter().enumerate() {
            let Some((offset, _)) = self.coordinates_of(k) else {
                continue;
            };
            match j.kind {
                JointType::Spherical => q[offset + 3] = 1.0,
                JointType::FreeFlyer => q[offset + 6] = 1.0,
                _ => {}
            }
        }
        q
    }
}

/// Everything an algorithm computes on the way, sized once for one [`Multibody`]
/// so that no call allocates. Entries are per body, 0 the base.
#[derive(Clone, Debug)]
pub struct Workspace<S: Real> {
    pub(crate) context: S::Context,
    /// `λ(i)M_i`: body `i` in its parent.
    pub placement: Vec<JointPlacement<S>>,
    /// `⁰M_i`: body `i` in the base frame.
    pub world: Vec<Se3<S>>,
    /// Spatial velocity of body `i` in its frame (after [`crate::body_motions`]).
    pub velocity: Vec<Motion<S>>,
    /// Spatial acceleration of body `i` in its frame (after [`crate::body_motions`],
    /// gravity-free; during aba, gravity included as a base acceleration `−g`).
    pub acceleration: Vec<Motion<S>>,
    /// The Newton–Euler pass (rnea, regressor), in body `i`'s axes: its angular
    /// velocity and acceleration, and the linear acceleration of its origin with
    /// gravity included as `−g`.
    pub(crate) angular_velocity: Vec<Vec3<S>>,
    pub(crate) angular_acceleration: Vec<Vec3<S>>,
    pub(crate) linear_acceleration: Vec<Vec3<S>>,
    /// After [`crate::rnea`]: the wrench joint `i` transmits to body `i`, in its
    /// frame (Pinocchio's `data.f`).
    pub force: Vec<Force<S>>,
    pub(crate) inertia: Vec<Inertia<S>>,
    pub(crate) articulated: Vec<SpatialMatrix<S>>,
    /// Per body: `p^A` (aba).
    pub(crate) bias_force: Vec<Force<S>>,
    /// Per body: the velocity-product acceleration `c_i = v_i × S_i q̇_i` (aba).
    pub(crate) bias_acceleration: Vec<Motion<S>>,
    /// Per velocity coordinate: `U = I^A S` (aba), `F = I^c S` (crba).
    pub(crate) u: Vec<Force<S>>,
    /// Per velocity coordinate: `u = τ − Sᵀ p^A`.
    pub(crate) u_torque: Vec<S>,
    /// Per joint, `D⁻¹` (nv × nv row-major, at most 36 entries).
    pub(crate) d_inv: Vec<[S; 36]>,
    /// Per body, the motion subspaces of the coordinates that move it, in its frame
    /// (the regressor), laid out as `Multibody::supports`.
    pub(crate) axes: Vec<Motion<S>>,
    /// A body's path to the base (frame Jacobians).
    pub(crate) path: Vec<usize>,
    /// The tree's coordinates and results when some joints follow others ([`Mimic`]).
    pub(crate) mimic: crate::mimic::MimicBuffers<S>,
}

impl<S: Real> Workspace<S> {
    /// A workspace for `multibody`, its numbers made in `context` (`()` for `f64`).
    pub fn new(multibody: &Multibody, context: S::Context) -> Workspace<S> {
        let n = multibody.bodies() + 1;
        let (z, o) = (S::constant(context, 0.0), S::constant(context, 1.0));
        Workspace {
            context,
            placement: alloc::vec![
                JointPlacement {
                    origin: None,
                    motion: Rotation::Identity,
                    translation: [z; 3],
                };
                n
            ],
            world: alloc::vec![Se3::identity(z, o); n],
            velocity: alloc::vec![Motion::zero(z); n],
            acceleration: alloc::vec![Motion::zero(z); n],
            angular_velocity: alloc::vec![[z; 3]; n],
            angular_acceleration: alloc::vec![[z; 3]; n],
            linear_acceleration: alloc::vec![[z; 3]; n],
            force: alloc::vec![Force::zero(z); n],
            inertia: alloc::vec![Inertia::zero(z); n],
            articulated: alloc::vec![Inertia::zero(z).to_matrix(z); n],
            bias_force: alloc::vec![Force::zero(z); n],
            bias_acceleration: alloc::vec![Motion::zero(z); n],
            u: alloc::vec![Force::zero(z); multibody.tree_nv()],
            u_torque: alloc::vec![z; multibody.tree_nv()],
            d_inv: alloc::vec![[z; 36]; n],
            axes: alloc::vec![Motion::zero(z); multibody.supports.len()],
            path: alloc::vec![0; multibody.bodies()],
            mimic: crate::mimic::MimicBuffers::new(multibody, z),
        }
    }

    pub(crate) fn zero(&self) -> S {
        S::constant(self.context, 0.0)
    }
}

#[cfg(feature = "std")]
fn sqrt(x: f64) -> f64 {
    x.sqrt()
}

#[cfg(all(not(feature = "std"), feature = "libm"))]
fn sqrt(x: f64) -> f64 {
    libm::sqrt(x)
}
