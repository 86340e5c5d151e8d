//! The readable reference implementation: the oracle generated code is checked
//! against. Textbook 6D spatial algebra (Featherstone, *Rigid Body Dynamics
//! Algorithms*, ch. 2–6), deliberately a different formulation from the generator's
//! 3D Newton–Euler, so that agreement between the two means something.
//!
//! Conventions are Pinocchio's: motion vectors `[linear; angular]`, force vectors
//! `[force; torque]`, everything of body `i` in body `i`'s frame (= joint `i`'s
//! frame), gravity entering as a base acceleration `a_0 = −a_g = [−g; 0]`.
//! Bodies are numbered `0..=n` here with `0` the fixed base, so `λ(i)` indexes
//! directly; public results list the moving bodies `1..=n` only.
//!
//! The algorithms, each a method of [`Reference`]:
//!
//! - kinematics: [`Reference::forward_kinematics`], [`Reference::body_motions`];
//! - inverse dynamics: [`Reference::rnea`] (recursive Newton–Euler),
//!   [`Reference::joint_wrenches`], [`Reference::nonlinear_effects`],
//!   [`Reference::generalized_gravity`];
//! - the mass matrix: [`Reference::crba`] (composite rigid body algorithm);
//! - forward dynamics: [`Reference::aba`] (articulated body algorithm) and
//!   [`Reference::forward_dynamics`] (`M⁻¹` by Cholesky, a second opinion);
//! - regressors, linear in the standard parameters: [`Reference::joint_torque_regressor`],
//!   [`Reference::joint_wrench_regressor`], and in the principal parameters
//!   [`Reference::principal_regressor`];
//! - the paper's decoupled body model (MIM, docs/design.md, "The paper's decoupled body model"): [`Reference::body_regressor`]
//!   and [`Reference::body_resultants`], per body in its centroidal principal frame.

mod aba;
mod dynamics;
mod from_static;
mod mim;
mod regressor;
mod sample;
pub mod spatial;

pub use dynamics::{Dynamics, Generated};
pub use from_static::{model_from_static, urdf_of};
pub use mim::euler_matrix;
pub use regressor::{principal_matrix, principal_params_to_standard};
pub use sample::{perturbed_params, sample_states, SplitMix64, State};
pub use spatial::Motion;

use dyngen::{Pose, Wrench};
use dyngen_model::{JointKind, Model, PrincipalFrame};
use nalgebra::{DMatrix, DVector, Vector3};
use spatial::{cross_force, cross_motion, spatial_inertia, stack, vec3, SpatialMatrix, SpatialVector, Transform};

/// Reference rigid-body algorithms for one checked [`Model`].
///
/// Every method takes `q, v, a` (and `tau`) of length `nq() = nv() = n` and the
/// standard parameters `params` of length `10 n` (per body, in Pinocchio's order
/// `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, inertia about the body-frame
/// origin, see [`Model::standard_params`]). They panic if a length differs: that
/// is a programming error, not bad data.
#[derive(Clone, Debug)]
pub struct Reference {
    model: Model,
    joints: Vec<JointData>,
    /// `a_g = [g; 0]`: gravity as a spatial acceleration of the base frame.
    gravity: SpatialVector,
    /// Each moving body's centroidal principal frame (nominal centre of mass and
    /// principal axes), body 1 first.
    frames: Vec<PrincipalFrame>,
}

/// What the algorithms need of joint `i`, converted once.
#[derive(Clone, Debug)]
struct JointData {
    kind: JointKind,
    parent: usize,
    /// `λ(i)M_i` at `q = 0`.
    origin: Transform,
    /// Unit axis in the joint frame.
    axis: Vector3<f64>,
    /// Motion subspace `S_i` (6 × 1): `[0; k]` for rotation about `k`, `[k; 0]` for
    /// translation along it.
    subspace: SpatialVector,
}

/// One body's motion from [`Reference::body_motions`], in the body's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyMotion {
    /// Spatial velocity `v_i = [v; ω]`: velocity of the point at the body origin and
    /// angular velocity (Pinocchio's `data.v[i]`).
    pub velocity: Motion,
    /// Spatial acceleration `a_i = v̇_i`, gravity-free (Pinocchio's `data.a[i]`).
    /// Its linear part is **not** the acceleration of the origin point; see
    /// [`BodyMotion::point_acceleration`].
    pub acceleration: Motion,
}

impl BodyMotion {
    /// Classical acceleration of the body-fixed point `p` (body coordinates):
    /// `a_p = a + ω̇ × p + ω × (v + ω × p)`, with `[v; ω]` the velocity and
    /// `[a; ω̇]` the spatial acceleration. With `p` the centre of mass this is the
    /// `a_c` of Newton's law.
    pub fn point_acceleration(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let (v, w) = (self.velocity.linear, self.velocity.angular);
        let (a, dw) = (self.acceleration.linear, self.acceleration.angular);
        a + dw.cross(p) + w.cross(&(v + w.cross(p)))
    }
}

/// Result of the forward (base-to-tip) pass, indexed `0..=n`, entry 0 the base.
struct Kinematics {
    /// `X_i = ⁱX_λ(i)`; entry 0 unused.
    x: Vec<SpatialMatrix>,
    v: Vec<SpatialVector>,
    a: Vec<SpatialVector>,
}

impl Reference {
    /// The reference implementation of a generated robot, on the model it carries
    /// (`R::MODEL`: the generator's numbering, the gravity it was specialised for).
    pub fn of<R: dyngen::Robot>() -> Reference {
        Reference::new(&model_from_static(&R::MODEL))
    }

    /// # Panics
    /// If a joint has more than one degree of freedom (a free flyer or a ball joint,
    /// [`Model::multi_dof_joint`]): the reference implementation is for trees of
    /// one-coordinate joints; the generated code handles the others.
    pub fn new(model: &Model) -> Reference {
        let joints = model
            .joints
            .iter()
            .map(|j| {
                let axis = vec3(&j.axis);
                let subspace = match j.kind {
                    JointKind::Revolute | JointKind::Continuous => stack(&Vector3::zeros(), &axis),
                    JointKind::Prismatic => stack(&axis, &Vector3::zeros()),
                    JointKind::Spherical | JointKind::FreeFlyer | JointKind::Planar => panic!(
                        "joint `{}` is a {} joint: the reference implementation takes joints with one degree \
                         of freedom (check `Model::multi_dof_joint` first)",
                        j.name,
                        j.kind.urdf_name()
                    ),
                };
                JointData {
                    kind: j.kind,
                    parent: j.parent,
                    origin: Transform::from_placement(&j.origin),
                    axis,
                    subspace,
                }
            })
            .collect();
        Reference {
            model: model.clone(),
            joints,
            gravity: stack(&vec3(&model.gravity), &Vector3::zeros()),
            frames: dyngen_model::principal_frames(model),
        }
    }

    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Number of position coordinates `n` (one per joint, continuous joints included).
    pub fn nq(&self) -> usize {
        self.joints.len()
    }

    /// Number of velocity coordinates, equal to [`Reference::nq`].
    pub fn nv(&self) -> usize {
        self.joints.len()
    }

    /// The placement `λ(i)M_i(q_i) = origin_i ∘ joint_i(q_i)` of body `i` (1-based)
    /// in its parent: the joint motion is a rotation by `q_i` about the axis
    /// (Rodrigues) or a translation by `q_i` along it.
    fn joint_placement(&self, i: usize, q: f64) -> Transform {
        let j = &self.joints[i - 1];
        let motion = match j.kind {
            JointKind::Revolute | JointKind::Continuous => Transform {
                rotation: spatial::rotation_about(&j.axis, q),
                translation: Vector3::zeros(),
            },
            JointKind::Prismatic => Transform {
                rotation: nalgebra::Matrix3::identity(),
                translation: j.axis * q,
            },
            JointKind::Spherical | JointKind::FreeFlyer | JointKind::Planar => {
                unreachable!("refused by `Reference::new`")
            }
        };
        j.origin.compose(&motion)
    }

    fn check_len(&self, name: &str, x: &[f64], expected: usize) {
        assert_eq!(
            x.len(),
            expected,
            "`{name}` has length {}, the model needs {expected}",
            x.len()
        );
    }

    /// Every body's pose in the base frame, body 1 first (`n` poses):
    /// `⁰M_i = ⁰M_λ(i) · λ(i)M_i(q_i)`, so `x_base = R_i x_i + t_i`.
    ///
    /// Panics if `q.len() != n`.
    pub fn forward_kinematics(&self, q: &[f64]) -> Vec<Pose<f64>> {
        let n = self.nq();
        self.check_len("q", q, n);
        let mut world = vec![Transform::identity(); n + 1];
        for i in 1..=n {
            world[i] = world[self.joints[i - 1].parent].compose(&self.joint_placement(i, q[i - 1]));
        }
        world[1..]
            .iter()
            .map(|t| Pose {
                rotation: t.rotation,
                translation: t.translation,
            })
            .collect()
    }

    /// The forward pass (Featherstone Table 5.1), from a base acceleration `a_0`:
    ///
    /// ```text
    /// X_i = ⁱX_λ(i)(q_i)
    /// v_i = X_i v_λ(i) + S_i q̇_i
    /// a_i = X_i a_λ(i) + S_i q̈_i + v_i × (S_i q̇_i)
    /// ```
    fn forward_pass(&self, q: &[f64], v: &[f64], a: &[f64], base_acceleration: SpatialVector) -> Kinematics {
        let n = self.nq();
        self.check_len("q", q, n);
        self.check_len("v", v, n);
        self.check_len("a", a, n);
        let mut k = Kinematics {
            x: vec![SpatialMatrix::identity(); n + 1],
            v: vec![SpatialVector::zeros(); n + 1],
            a: vec![SpatialVector::zeros(); n + 1],
        };
        k.a[0] = base_acceleration;
        for i in 1..=n {
            let (parent, s) = (self.joints[i - 1].parent, self.joints[i - 1].subspace);
            let x = self.joint_placement(i, q[i - 1]).motion_matrix();
            let joint_velocity = s * v[i - 1];
            k.v[i] = x * k.v[parent] + joint_velocity;
            k.a[i] = x * k.a[parent] + s * a[i - 1] + cross_motion(&k.v[i]) * joint_velocity;
            k.x[i] = x;
        }
        k
    }

    /// The spatial forces `f_i` across every joint (entry 0 collects what the base
    /// receives): forward pass with `a_0 = −a_g`, then tip to base
    ///
    /// ```text
    /// f_i = I_i a_i + v_i ×* I_i v_i − Σ_{c: λ(c) = i} X_cᵀ f_c
    /// ```
    ///
    /// i.e. the net spatial force on body `i` plus what it passes to its children.
    fn joint_forces(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64]) -> Vec<SpatialVector> {
        let n = self.nq();
        self.check_len("params", params, 10 * n);
        let k = self.forward_pass(q, v, a, -self.gravity);
        let mut f = vec![SpatialVector::zeros(); n + 1];
        for i in 1..=n {
            let inertia = spatial_inertia(&params[10 * (i - 1)..10 * i]);
            f[i] = inertia * k.a[i] + cross_force(&k.v[i]) * (inertia * k.v[i]);
        }
        for i in (1..=n).rev() {
            let parent = self.joints[i - 1].parent;
            let to_parent = k.x[i].transpose() * f[i];
            f[parent] += to_parent;
        }
        f
    }

    /// Inverse dynamics by the recursive Newton–Euler algorithm,
    /// `tau = M(q) a + C(q, v) v + g(q)`, with `tau_i = S_iᵀ f_i` (see
    /// [`Reference::joint_wrenches`] for `f_i`). `q, v, a`: `n`; `params`: `10 n`;
    /// returns `n` joint torques (N·m) or forces (N).
    ///
    /// Linear in `params`: this is `Y(q, v, a) · params`. Panics if a length differs.
    pub fn rnea(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64]) -> Vec<f64> {
        let f = self.joint_forces(q, v, a, params);
        (1..=self.nq())
            .map(|i| self.joints[i - 1].subspace.dot(&f[i]))
            .collect()
    }

    /// `C(q, v) v + g(q) = rnea(q, v, 0)`. Returns `n` values. Panics if a length differs.
    pub fn nonlinear_effects(&self, q: &[f64], v: &[f64], params: &[f64]) -> Vec<f64> {
        self.rnea(q, v, &vec![0.0; self.nv()], params)
    }

    /// `g(q) = rnea(q, 0, 0)`. Returns `n` values. Panics if a length differs.
    pub fn generalized_gravity(&self, q: &[f64], params: &[f64]) -> Vec<f64> {
        let zero = vec![0.0; self.nv()];
        self.rnea(q, &zero, &zero, params)
    }

    /// The wrench joint `i` applies to body `i` (force, and moment about the joint
    /// frame origin), in body `i`'s frame, body 1 first (`n` wrenches): the `f_i` of
    /// the RNEA backward pass, Pinocchio's `data.f[i]` after `rnea`. The joint torque
    /// is its projection on the motion subspace, `tau_i = S_iᵀ f_i`: `k · torque` for
    /// a revolute joint, `k · force` for a prismatic one.
    ///
    /// Panics if a length differs.
    pub fn joint_wrenches(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64]) -> Vec<Wrench<f64>> {
        self.joint_forces(q, v, a, params)[1..]
            .iter()
            .map(|f| Wrench {
                force: f.fixed_rows::<3>(0).into(),
                torque: f.fixed_rows::<3>(3).into(),
            })
            .collect()
    }

    /// Every body's spatial velocity and gravity-free spatial acceleration in its own
    /// frame, body 1 first (`n` entries): Pinocchio's `data.v`, `data.a` after
    /// `forwardKinematics(q, v, a)`. Panics if a length differs.
    pub fn body_motions(&self, q: &[f64], v: &[f64], a: &[f64]) -> Vec<BodyMotion> {
        let k = self.forward_pass(q, v, a, SpatialVector::zeros());
        (1..=self.nq())
            .map(|i| BodyMotion {
                velocity: Motion::from_vector(&k.v[i]),
                acceleration: Motion::from_vector(&k.a[i]),
            })
            .collect()
    }

    /// The joint-space mass matrix `M(q)` (`n × n`, symmetric) by the composite
    /// rigid body algorithm (Featherstone Table 6.2): composite inertias
    /// `I^c_λ(i) += X_iᵀ I^c_i X_i` from tip to base, then
    /// `M_ij = S_jᵀ (ʲX_i)ᵀ I^c_i S_i` for every ancestor `j` of `i`.
    ///
    /// Independent of `rnea`: `M(q) e_j = rnea(q, 0, e_j) − rnea(q, 0, 0)`.
    /// Panics if a length differs.
    pub fn crba(&self, q: &[f64], params: &[f64]) -> DMatrix<f64> {
        let n = self.nq();
        self.check_len("q", q, n);
        self.check_len("params", params, 10 * n);
        let x: Vec<SpatialMatrix> = (1..=n)
            .map(|i| self.joint_placement(i, q[i - 1]).motion_matrix())
            .collect();
        let mut composite: Vec<SpatialMatrix> = (1..=n)
            .map(|i| spatial_inertia(&params[10 * (i - 1)..10 * i]))
            .collect();
        for i in (1..=n).rev() {
            let parent = self.joints[i - 1].parent;
            if parent != 0 {
                let moved = x[i - 1].transpose() * composite[i - 1] * x[i - 1];
                composite[parent - 1] += moved;
            }
        }
        let mut m = DMatrix::zeros(n, n);
        for i in 1..=n {
            // F = I^c_i S_i, carried towards the base one joint at a time.
            let mut force = composite[i - 1] * self.joints[i - 1].subspace;
            m[(i - 1, i - 1)] = self.joints[i - 1].subspace.dot(&force);
            let mut j = i;
            while self.joints[j - 1].parent != 0 {
                force = x[j - 1].transpose() * force;
                j = self.joints[j - 1].parent;
                m[(i - 1, j - 1)] = self.joints[j - 1].subspace.dot(&force);
                m[(j - 1, i - 1)] = m[(i - 1, j - 1)];
            }
        }
        m
    }

    /// The joint-space mass matrix: another name for [`Reference::crba`].
    pub fn mass_matrix(&self, q: &[f64], params: &[f64]) -> DMatrix<f64> {
        self.crba(q, params)
    }

    /// Forward dynamics `a = M(q)⁻¹ (tau − C(q, v) v − g(q))`, by a Cholesky
    /// factorisation of [`Reference::crba`]; [`Reference::aba`] computes the same
    /// without forming `M`. Returns `n` accelerations, or
    /// `None` when `M(q)` is not positive definite (never for physically consistent
    /// parameters). Panics if a length differs.
    pub fn forward_dynamics(&self, q: &[f64], v: &[f64], tau: &[f64], params: &[f64]) -> Option<Vec<f64>> {
        self.check_len("tau", tau, self.nv());
        let bias = DVector::from_vec(self.nonlinear_effects(q, v, params));
        let rhs = DVector::from_column_slice(tau) - bias;
        let cholesky = self.crba(q, params).cholesky()?;
        Some(cholesky.solve(&rhs).iter().copied().collect())
    }
}
