//! The run-time dynamics of a loaded model with `nalgebra` results: the
//! algorithms of `dyngen-algo` (written once, generic over the scalar, checked
//! against Pinocchio and MuJoCo) on `f64`, for every joint type, plus the paper's
//! decoupled body model. Generated code is checked against it, and both against
//! Pinocchio's and MuJoCo's numbers.
//!
//! Conventions are Pinocchio's: motion vectors `[linear; angular]`, force vectors
//! `[force; torque]`, everything of body `i` in body `i`'s frame (= joint `i`'s
//! frame), gravity entering as a base acceleration `a_0 = −a_g = [−g; 0]`.
//! Public results list the moving bodies `1..=n`, body 1 first.
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
use dyngen_algo::{Multibody, Workspace};
use dyngen_model::{Model, PrincipalFrame};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// The run-time dynamics of one checked [`Model`].
///
/// Every method takes `q` of length `nq()`, `v, a` (and `tau`) of length `nv()`, and
/// the standard parameters `params` of length `10 n` for the `n` moving bodies
/// (per body, in Pinocchio's order `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz,
/// Izz]`, inertia about the body-frame origin, see [`Model::standard_params`]). They
/// panic if a length differs: that is a programming error, not bad data.
#[derive(Clone, Debug)]
pub struct Reference {
    model: Model,
    body: Multibody,
    /// Each moving body's centroidal principal frame (nominal centre of mass and
    /// principal axes), body 1 first.
    frames: Vec<PrincipalFrame>,
    workspaces: Pool,
}

/// Workspaces made for this model, reused across calls (one per thread in use), so
/// that a call allocates only its result.
#[derive(Default)]
struct Pool(std::sync::Mutex<Vec<Workspace<f64>>>);

impl Clone for Pool {
    fn clone(&self) -> Pool {
        Pool::default()
    }
}

impl std::fmt::Debug for Pool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Pool")
    }
}

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

impl Reference {
    /// The reference implementation of a generated robot, on the model it carries
    /// (`R::MODEL`: the generator's numbering, the gravity it was specialised for).
    pub fn of<R: dyngen::RobotDescription>() -> Reference {
        Reference::new(&model_from_static(&R::MODEL))
    }

    /// # Panics
    /// If `model` is not a tree in regular labelling (only a model whose fields were
    /// edited by hand can be: every loaded model is).
    pub fn new(model: &Model) -> Reference {
        let body = model
            .multibody()
            .unwrap_or_else(|e| panic!("model `{}` is not a checked tree: {e}", model.name));
        Reference {
            model: model.clone(),
            body,
            frames: dyngen_model::principal_frames(model),
            workspaces: Pool::default(),
        }
    }

    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The tree the algorithms run on.
    pub fn multibody(&self) -> &Multibody {
        &self.body
    }

    /// Number of position coordinates.
    pub fn nq(&self) -> usize {
        self.body.nq()
    }

    /// Number of velocity coordinates.
    pub fn nv(&self) -> usize {
        self.body.nv()
    }

    /// Number of moving bodies (= joints).
    pub fn bodies(&self) -> usize {
        self.body.bodies()
    }

    /// Runs `f` on a workspace of this model's, taken from the pool (or made) and
    /// put back after.
    pub(crate) fn with_workspace<T>(&self, f: impl FnOnce(&mut Workspace<f64>) -> T) -> T {
        // A poisoned pool only lost workspaces; take it over as it is.
        let taken = self.workspaces.0.lock().unwrap_or_else(|e| e.into_inner()).pop();
        let mut ws = taken.unwrap_or_else(|| Workspace::new(&self.body, ()));
        let out = f(&mut ws);
        self.workspaces.0.lock().unwrap_or_else(|e| e.into_inner()).push(ws);
        out
    }

    /// Every body's pose in the base frame, body 1 first:
    /// `⁰M_i = ⁰M_λ(i) · λ(i)M_i(q)`, so `x_base = R_i x_i + t_i`.
    pub fn forward_kinematics(&self, q: &[f64]) -> Vec<Pose<f64>> {
        self.with_workspace(|ws| {
            dyngen_algo::forward_kinematics(&self.body, ws, q);
            ws.world[1..]
                .iter()
                .map(|t| Pose {
                    rotation: Matrix3::from_fn(|r, c| t.rotation[r][c]),
                    translation: Vector3::from(t.translation),
                })
                .collect()
        })
    }

    /// Inverse dynamics, `tau = M(q) a + C(q, v) v + g(q)` (`dyngen_algo::rnea`).
    /// Linear in `params`: this is `Y(q, v, a) · params`.
    pub fn rnea(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64]) -> Vec<f64> {
        let mut tau = vec![0.0; self.nv()];
        self.with_workspace(|ws| dyngen_algo::rnea(&self.body, ws, q, v, a, params, &mut tau));
        tau
    }

    /// `C(q, v) v + g(q) = rnea(q, v, 0)`.
    pub fn nonlinear_effects(&self, q: &[f64], v: &[f64], params: &[f64]) -> Vec<f64> {
        self.rnea(q, v, &vec![0.0; self.nv()], params)
    }

    /// `g(q) = rnea(q, 0, 0)`.
    pub fn generalized_gravity(&self, q: &[f64], params: &[f64]) -> Vec<f64> {
        let zero = vec![0.0; self.nv()];
        self.rnea(q, &zero, &zero, params)
    }

    /// The wrench joint `i` applies to body `i` (force, and moment about the joint
    /// frame origin), in body `i`'s frame, body 1 first: Pinocchio's `data.f[i]`
    /// after `rnea`. The joint torques are its projection on the motion subspace,
    /// `tau_i = S_iᵀ f_i`: `k · torque` for a revolute joint, `k · force` for a
    /// prismatic one.
    pub fn joint_wrenches(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64]) -> Vec<Wrench<f64>> {
        let mut tau = vec![0.0; self.nv()];
        self.with_workspace(|ws| {
            dyngen_algo::rnea(&self.body, ws, q, v, a, params, &mut tau);
            ws.force[1..]
                .iter()
                .map(|f| Wrench {
                    force: Vector3::from(f.linear),
                    torque: Vector3::from(f.angular),
                })
                .collect()
        })
    }

    /// Every body's spatial velocity and gravity-free spatial acceleration in its own
    /// frame, body 1 first: Pinocchio's `data.v`, `data.a` after
    /// `forwardKinematics(q, v, a)`.
    pub fn body_motions(&self, q: &[f64], v: &[f64], a: &[f64]) -> Vec<BodyMotion> {
        let motion = |m: &dyngen_algo::Motion<f64>| Motion {
            linear: Vector3::from(m.linear),
            angular: Vector3::from(m.angular),
        };
        self.with_workspace(|ws| {
            dyngen_algo::body_motions(&self.body, ws, q, v, a);
            (1..=self.bodies())
                .map(|i| BodyMotion {
                    velocity: motion(&ws.velocity[i]),
                    acceleration: motion(&ws.acceleration[i]),
                })
                .collect()
        })
    }

    /// The joint-space mass matrix `M(q)` (`nv × nv`, symmetric) by the composite
    /// rigid body algorithm (`dyngen_algo::crba`).
    pub fn crba(&self, q: &[f64], params: &[f64]) -> DMatrix<f64> {
        let nv = self.nv();
        let mut m = vec![0.0; nv * nv];
        self.with_workspace(|ws| dyngen_algo::crba(&self.body, ws, q, params, &mut m));
        DMatrix::from_row_slice(nv, nv, &m)
    }

    /// The joint-space mass matrix: another name for [`Reference::crba`].
    pub fn mass_matrix(&self, q: &[f64], params: &[f64]) -> DMatrix<f64> {
        self.crba(q, params)
    }

    /// Forward dynamics `q̈ = M(q)⁻¹ (τ − C(q, v) v − g(q))` by the articulated body
    /// algorithm (`dyngen_algo::aba`), in `O(n)` without forming `M`. Where `M(q)` is
    /// singular (non-physical parameters, a massless tip) the result is not finite.
    pub fn aba(&self, q: &[f64], v: &[f64], tau: &[f64], params: &[f64]) -> Vec<f64> {
        let mut qdd = vec![0.0; self.nv()];
        self.with_workspace(|ws| dyngen_algo::aba(&self.body, ws, q, v, tau, params, &[], &mut qdd));
        qdd
    }

    /// Forward dynamics `a = M(q)⁻¹ (tau − C(q, v) v − g(q))`, by a Cholesky
    /// factorisation of [`Reference::crba`]; [`Reference::aba`] computes the same
    /// without forming `M`. `None` when `M(q)` is not positive definite (never for
    /// physically consistent parameters).
    pub fn forward_dynamics(&self, q: &[f64], v: &[f64], tau: &[f64], params: &[f64]) -> Option<Vec<f64>> {
        assert_eq!(
            tau.len(),
            self.nv(),
            "`tau` has {} entries; the model has {} velocities",
            tau.len(),
            self.nv()
        );
        let bias = DVector::from_vec(self.nonlinear_effects(q, v, params));
        let rhs = DVector::from_column_slice(tau) - bias;
        let cholesky = self.crba(q, params).cholesky()?;
        Some(cholesky.solve(&rhs).iter().copied().collect())
    }
}
