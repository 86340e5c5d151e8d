//! The traits every generated robot type implements ([`RobotDescription`], one
//! capability trait per group of functions, and [`Robot`], all of them), and the small
//! spatial types of their API.

use crate::{Coulomb, FrameMotion, ReferenceFrame, RobotModel, Scalar};
use nalgebra::{Matrix3, SMatrix, Vector3};

/// A body's pose in the base frame: `x_base = rotation · x_body + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose<S: Scalar> {
    pub rotation: Matrix3<S>,
    pub translation: Vector3<S>,
}

impl<S: Scalar> Default for Pose<S> {
    fn default() -> Self {
        Pose {
            rotation: Matrix3::from_element(S::ZERO),
            translation: Vector3::from_element(S::ZERO),
        }
    }
}

/// A force and the moment about a stated point, in a stated frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wrench<S: Scalar> {
    pub force: Vector3<S>,
    pub torque: Vector3<S>,
}

impl<S: Scalar> Default for Wrench<S> {
    fn default() -> Self {
        Wrench {
            force: Vector3::from_element(S::ZERO),
            torque: Vector3::from_element(S::ZERO),
        }
    }
}

/// The paper's per-body regressor `A_i` (6 × 4): `[F; M] = A_i θ_i` with
/// `θ_i = (m, J1, J2, J3)`, force and moment about the centre of mass in the body's
/// centroidal principal frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyRegressor<S: Scalar> {
    /// Rows of the force: `m (a_c − g)`.
    pub force: SMatrix<S, 3, 4>,
    /// Rows of the moment: `diag(J) ω̇ + ω × diag(J) ω`.
    pub moment: SMatrix<S, 3, 4>,
}

impl<S: Scalar> BodyRegressor<S> {
    /// Row `r` of `A_i` (`0..3` the force, `3..6` the moment). Panics when `r ≥ 6`.
    pub fn row(&self, r: usize) -> [S; 4] {
        let m = if r < 3 { &self.force } else { &self.moment };
        let r = r % 3;
        [m[(r, 0)], m[(r, 1)], m[(r, 2)], m[(r, 3)]]
    }
}

impl<S: Scalar> Default for BodyRegressor<S> {
    fn default() -> Self {
        BodyRegressor {
            force: SMatrix::from_element(S::ZERO),
            moment: SMatrix::from_element(S::ZERO),
        }
    }
}

/// What every generated robot type carries whatever functions were generated: its
/// sizes, names, tree, nominal parameters, base-parameter maps and the operation
/// counts of its functions. The functions themselves come in capability traits
/// ([`InverseDynamics`], [`MassMatrix`], [`ForwardDynamics`], [`Kinematics`],
/// [`Regressors`], [`JointDynamics`], [`Frames`], [`Centroidal`], [`Derivatives`]),
/// each implemented when it was selected (all by default); [`Robot`] is all of them.
///
/// Sizes follow Pinocchio: `NQ` positions (a unit quaternion per ball joint and free
/// flyer), `NV` velocities, `NBODIES` moving bodies. The standard parameters are 10
/// per body in Pinocchio's order `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`,
/// inertia about the body-frame origin (`NPARAMS = 10 · NBODIES`).
///
/// The capability traits' slice methods panic when a slice does not have the
/// documented length, as indexing does; the generated inherent functions take
/// fixed-size arrays instead.
pub trait RobotDescription {
    const NAME: &'static str;
    const NQ: usize;
    const NV: usize;
    const NBODIES: usize;
    const NPARAMS: usize;
    /// Principal parameters `θ = (m, J1, J2, J3)`, 4 per body.
    const NTHETA: usize;
    /// Base parameters of the standard parameterisation.
    const NBASE: usize;
    /// Base parameters of the principal parameterisation.
    const NBASE_PRINCIPAL: usize;
    /// Joint parameters `[Ia, Fv, Fc, F0]`, 4 per joint ([`crate::JointParams`]).
    const NJOINT_PARAMS: usize;
    /// Base parameters of the standard and joint parameters together.
    const NBASE_JOINTS: usize;
    /// The checked model the code was generated from (fixed joints merged), in the
    /// generated numbering: `MODEL.joints[j - 1]` carries `MODEL.bodies[j - 1]`.
    const MODEL: RobotModel;

    /// Joint names, joint 1 first.
    fn joint_names() -> &'static [&'static str];
    /// Moving body names, body 1 first (body `j` is carried by joint `j`).
    fn body_names() -> &'static [&'static str];
    /// Parent body of each moving body (0 = base), body 1 first.
    fn parents() -> &'static [usize];
    /// The nominal standard parameters of the description, length `NPARAMS`.
    fn nominal_params() -> &'static [f64];
    /// The nominal principal parameters, length `NTHETA`.
    fn nominal_theta() -> &'static [f64];
    /// A readable formula for each base parameter, e.g. `Izz1 + Iyy2 + 0.1817·m3`.
    fn base_groupings() -> &'static [&'static str];
    /// The standard parameters the base parameters are built on (columns of `Y`).
    fn base_index() -> &'static [usize];
    /// `K` (`NBASE × NPARAMS`, row-major): `β = K π`.
    fn base_k() -> &'static [f64];
    /// Readable formulas of the principal base parameters.
    fn principal_base_groupings() -> &'static [&'static str];
    /// The principal parameters the principal base parameters are built on.
    fn principal_base_index() -> &'static [usize];
    /// `K_θ` (`NBASE_PRINCIPAL × NTHETA`, row-major): `β_θ = K_θ θ`.
    fn principal_base_k() -> &'static [f64];
    /// The nominal joint parameters, length `NJOINT_PARAMS`: `Ia` (MJCF `armature`),
    /// `Fv`, `Fc` from the description (URDF `<dynamics damping friction>`), `F0` zero.
    fn nominal_joint_params() -> &'static [f64];
    /// Readable formulas of the base parameters of `[params; joint_params]`.
    fn base_joints_groupings() -> &'static [&'static str];
    /// The columns of `[params; joint_params]` those base parameters are built on.
    fn base_joints_index() -> &'static [usize];
    /// `K_j` (`NBASE_JOINTS × (NPARAMS + NJOINT_PARAMS)`, row-major):
    /// `β_j = K_j [params; joint_params]`.
    fn base_joints_k() -> &'static [f64];
    /// Gravity in the base frame the generated code was specialised for, m/s².
    fn gravity() -> [f64; 3];
    /// Operation counts of each generated function, by function name.
    fn op_counts() -> &'static [(&'static str, OpCount)];
}

/// Inverse dynamics: `rnea`, its special cases `nonlinear_effects` and
/// `generalized_gravity`, and the joint reaction wrenches. Selected by `inverse_dynamics`.
pub trait InverseDynamics: RobotDescription {
    /// Inverse dynamics by the generated Newton–Euler recursion:
    /// `tau = M(q) a + C(q, v) v + g(q)`. `q, v, a, tau`: `NV`; `params`: `NPARAMS`.
    fn rnea<S: Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], tau: &mut [S]);
    /// `h(q, v) = rnea(q, v, 0)`. `tau`: `NV`.
    fn nonlinear_effects<S: Scalar>(q: &[S], v: &[S], params: &[S], tau: &mut [S]);
    /// `g(q) = rnea(q, 0, 0)`. `tau`: `NV`.
    fn generalized_gravity<S: Scalar>(q: &[S], params: &[S], tau: &mut [S]);
    /// The wrench joint `j` applies to body `j` (force, and moment about the joint
    /// frame origin), in body `j`'s frame: Pinocchio's `data.f[j]` after `rnea`.
    /// `wrenches`: `NBODIES`.
    fn joint_wrenches<S: Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], wrenches: &mut [Wrench<S>]);
}

/// The joint-space inertia matrix by the composite-rigid-body algorithm. Selected by
/// `mass_matrix`.
pub trait MassMatrix: RobotDescription {
    /// Joint-space inertia matrix `M(q)`, row-major into `m` (`NV × NV`).
    fn crba<S: Scalar>(q: &[S], params: &[S], m: &mut [S]);
}

/// Forward dynamics by the articulated-body algorithm. Selected by `forward_dynamics`.
pub trait ForwardDynamics: RobotDescription {
    /// Forward dynamics by the articulated-body algorithm: `a = M⁻¹ (tau − h)`.
    /// Where `M` is singular (a coordinate along which nothing with mass moves: the
    /// model's load warned about it, naming the joint) or an input is not finite, `a`
    /// is not finite; [`ForwardDynamics::try_aba`] says so instead.
    fn aba<S: Scalar>(q: &[S], v: &[S], tau: &[S], params: &[S], a: &mut [S]);

    /// [`ForwardDynamics::aba`] with its result checked: an error naming the first
    /// coordinate of `a` that is not finite, and why, rather than a value.
    ///
    /// ```
    /// # #[cfg(feature = "macros")] {
    /// use dyngen::prelude::*;
    /// dyngen::robot! {
    ///     name: Pendulum,
    ///     incidence: [[-1], [1]],
    ///     joints: [revolute(y)],
    ///     body_joint_vectors: { (0, 1): [0.0, 0.0, 0.0], (1, 1): [0.0, 0.0, 0.5] },
    ///     bodies: { 1: principal(mass: 2.0, moments: [0.01, 0.01, 0.001]) },
    /// }
    /// let mut a = [0.0];
    /// // A pendulum of no mass: nothing resists the joint torque.
    /// let e = Pendulum::try_aba(&[0.3], &[0.0], &[1.0], &[0.0; 10], &mut a).unwrap_err();
    /// assert_eq!(e.coordinate, 0);
    /// assert!(e.to_string().contains("the mass matrix is singular"));
    /// // With its mass, the same torque gives an acceleration.
    /// Pendulum::try_aba(&[0.3], &[0.0], &[1.0], Pendulum::nominal_params(), &mut a).unwrap();
    /// # }
    /// ```
    fn try_aba(q: &[f64], v: &[f64], tau: &[f64], params: &[f64], a: &mut [f64]) -> Result<(), NotFinite> {
        Self::aba(q, v, tau, params, a);
        match a.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(coordinate) => Err(NotFinite {
                coordinate,
                inputs_finite: [q, v, tau, params].iter().all(|x| x.iter().all(|x| x.is_finite())),
            }),
        }
    }
}

/// Why [`ForwardDynamics::try_aba`] has no acceleration to give.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotFinite {
    /// The first coordinate (0-based) whose acceleration is not finite.
    pub coordinate: usize,
    /// Whether every input was finite (then `M` is singular at this state).
    pub inputs_finite: bool,
}

impl core::fmt::Display for NotFinite {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let k = self.coordinate;
        if self.inputs_finite {
            write!(
                f,
                "forward dynamics has no finite acceleration for coordinate {k}: the mass matrix is singular at this \
                 state (nothing with mass moves along some coordinate; the model's load warned which joint). Give the \
                 bodies mass, or lock that joint"
            )
        } else {
            write!(
                f,
                "forward dynamics has no finite acceleration for coordinate {k}: an input (q, v, tau or params) is \
                 not finite"
            )
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for NotFinite {}

/// Every body's pose. Selected by `kinematics`.
pub trait Kinematics: RobotDescription {
    /// Every body's pose in the base frame at `q`. `poses`: `NBODIES`.
    fn forward_kinematics<S: Scalar>(q: &[S], poses: &mut [Pose<S>]);
}

/// The regressors linear in the inertial parameters (standard, principal, base, the
/// joint-wrench and per-body ones) and the maps to the base parameters. Selected by
/// `regressors`.
pub trait Regressors: RobotDescription {
    /// `Y` with `tau = Y π`, row-major into `y` (`NV × NPARAMS`).
    fn joint_torque_regressor<S: Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]);
    /// Every joint's reaction wrench per parameter, row-major into `y`
    /// (`6·NBODIES × NPARAMS`, rows `[force; moment]` of joint 1, 2, …).
    fn joint_wrench_regressor<S: Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]);
    /// `Y_θ` with `tau = Y_θ θ`, row-major into `y` (`NV × NTHETA`).
    fn principal_regressor<S: Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]);
    /// `Y_b` with `tau = Y_b β`, row-major into `y` (`NV × NBASE`).
    fn base_regressor<S: Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]);
    /// The principal base regressor, row-major into `y` (`NV × NBASE_PRINCIPAL`).
    fn principal_base_regressor<S: Scalar>(q: &[S], v: &[S], a: &[S], y: &mut [S]);
    /// The paper's per-body regressors `A_i`. `out`: `NBODIES`.
    fn body_regressors<S: Scalar>(q: &[S], v: &[S], a: &[S], out: &mut [BodyRegressor<S>]);
    /// Each body's resultant of the joint reaction wrenches (moment about the centre
    /// of mass, centroidal principal frame). `out`: `NBODIES`.
    fn body_resultants<S: Scalar>(q: &[S], v: &[S], a: &[S], params: &[S], out: &mut [Wrench<S>]);
    /// `β = K π`. `params`: `NPARAMS`; `beta`: `NBASE`.
    fn base_params<S: Scalar>(params: &[S], beta: &mut [S]);
    /// `β_θ = K_θ θ`. `theta`: `NTHETA`; `beta`: `NBASE_PRINCIPAL`.
    fn principal_base_params<S: Scalar>(theta: &[S], beta: &mut [S]);
}

/// The dynamics with the joint models (rotor inertia, viscous and Coulomb friction,
/// offset; [`crate::JointParams`]) and their regressors. Selected by `joint_dynamics`.
pub trait JointDynamics: RobotDescription {
    /// Inverse dynamics with the joint models:
    /// `tau = rnea(q, v, a) + Ia·a + Fv·v + Fc·c(v) + F0` per joint.
    /// `joint_params`: `NJOINT_PARAMS`; the rest as for [`InverseDynamics::rnea`].
    fn rnea_joints<S: Scalar>(
        q: &[S],
        v: &[S],
        a: &[S],
        params: &[S],
        joint_params: &[S],
        coulomb: Coulomb<S>,
        tau: &mut [S],
    );
    /// `M(q) + diag(Ia)`, row-major into `m` (`NV × NV`).
    fn crba_joints<S: Scalar>(q: &[S], params: &[S], joint_params: &[S], m: &mut [S]);
    /// Forward dynamics with the joint models:
    /// `a = (M + diag(Ia))⁻¹ (tau − h − Fv·v − Fc·c(v) − F0)`, inverting
    /// [`JointDynamics::rnea_joints`].
    fn aba_joints<S: Scalar>(
        q: &[S],
        v: &[S],
        tau: &[S],
        params: &[S],
        joint_params: &[S],
        coulomb: Coulomb<S>,
        a: &mut [S],
    );
    /// `[Y | Y_j]` with `tau = [Y | Y_j] · [params; joint_params]` ([`JointDynamics::rnea_joints`]),
    /// row-major into `y` (`NV × (NPARAMS + NJOINT_PARAMS)`): row `j` has
    /// `[a_j, v_j, c(v_j), 1]` at columns `NPARAMS + 4j ..`.
    fn torque_regressor_joints<S: Scalar>(q: &[S], v: &[S], a: &[S], coulomb: Coulomb<S>, y: &mut [S]);
    /// The base regressor of `[params; joint_params]`, row-major into `y`
    /// (`NV × NBASE_JOINTS`): `tau = Y_bj · base_params_joints(params, joint_params)`.
    fn base_regressor_joints<S: Scalar>(q: &[S], v: &[S], a: &[S], coulomb: Coulomb<S>, y: &mut [S]);
    /// `β_j = K_j [params; joint_params]`. `beta`: `NBASE_JOINTS`.
    fn base_params_joints<S: Scalar>(params: &[S], joint_params: &[S], beta: &mut [S]);
}

/// Frame placements, Jacobians, their time variation and frame motions. Selected by
/// `frames`.
pub trait Frames: RobotDescription {
    /// Frame `frame`'s placement in the world (`frame` indexes `MODEL.frames`; the
    /// generated frame enum gives the same through `index()`); `None` when there is no
    /// such frame.
    fn frame_placement<S: Scalar>(q: &[S], frame: usize) -> Option<Pose<S>>;
    /// Frame `frame`'s Jacobian (6 × `NV`, rows `[linear; angular]`) in `reference`,
    /// row-major into `jacobian`; returns the frame's placement, `None` (and `jacobian`
    /// untouched) when there is no such frame.
    fn frame_jacobian<S: Scalar>(
        q: &[S],
        frame: usize,
        reference: ReferenceFrame,
        jacobian: &mut [S],
    ) -> Option<Pose<S>>;
    /// Frame `frame`'s Jacobian and its time variation `J̇(q, v)` (each 6 × `NV`,
    /// row-major) in `reference`; returns the frame's placement, `None` when there is no
    /// such frame.
    fn frame_jacobian_time_variation<S: Scalar>(
        q: &[S],
        v: &[S],
        frame: usize,
        reference: ReferenceFrame,
        jacobian: &mut [S],
        jacobian_dot: &mut [S],
    ) -> Option<Pose<S>>;
    /// Frame `frame`'s placement, velocity and classical acceleration,
    /// `LOCAL_WORLD_ALIGNED`; `None` when there is no such frame.
    fn frame_motion<S: Scalar>(q: &[S], v: &[S], a: &[S], frame: usize) -> Option<FrameMotion<S>>;
}

/// Centre of mass, its Jacobian, and the centroidal momentum matrix. Selected by
/// `centroidal`.
pub trait Centroidal: RobotDescription {
    /// The centre of mass of the moving bodies in the world. `params`: `NPARAMS`.
    fn center_of_mass<S: Scalar>(q: &[S], params: &[S]) -> [S; 3];
    /// The centre of mass's Jacobian (3 × `NV`, world axes), row-major into `jacobian`.
    fn com_jacobian<S: Scalar>(q: &[S], params: &[S], jacobian: &mut [S]);
    /// The centroidal momentum matrix `A_g` (6 × `NV`, rows `[linear; angular]`, the
    /// angular part about the centre of mass, world axes), row-major into `a_g`.
    fn centroidal_map<S: Scalar>(q: &[S], params: &[S], a_g: &mut [S]);
    /// `A_g` and its time derivative `Ȧ_g(q, v)` (each 6 × `NV`, row-major):
    /// `ḣ_g = A_g a + Ȧ_g v`.
    fn centroidal_map_time_variation<S: Scalar>(q: &[S], v: &[S], params: &[S], a_g: &mut [S], a_g_dot: &mut [S]);
}

/// The derivatives of inverse and forward dynamics, and `M⁻¹`. Selected by
/// `derivatives`.
pub trait Derivatives: RobotDescription {
    /// `∂τ/∂q`, `∂τ/∂v` and `∂τ/∂a = M` of [`InverseDynamics::rnea`], each `NV × NV` row-major.
    fn rnea_derivatives<S: Scalar>(
        q: &[S],
        v: &[S],
        a: &[S],
        params: &[S],
        dtau_dq: &mut [S],
        dtau_dv: &mut [S],
        dtau_da: &mut [S],
    );
    /// `q̈ = aba(q, v, tau)` and `∂q̈/∂q`, `∂q̈/∂v`, `M⁻¹ = ∂q̈/∂τ`, each `NV × NV`
    /// row-major.
    #[allow(clippy::too_many_arguments)]
    fn aba_derivatives<S: Scalar>(
        q: &[S],
        v: &[S],
        tau: &[S],
        params: &[S],
        ddq: &mut [S],
        ddq_dq: &mut [S],
        ddq_dv: &mut [S],
        minv: &mut [S],
    );
    /// `M(q)⁻¹`, row-major into `minv` (`NV × NV`).
    fn inverse_inertia<S: Scalar>(q: &[S], params: &[S], minv: &mut [S]);
}

/// A robot with every generated function (see [`RobotDescription`] for its sizes
/// and conventions): implemented for every type that has all the capability traits,
/// as the types `robot!` and `dyngen_codegen::compile_urdf` generate by default.
/// Run-time code that needs the whole set (the reference wrapper, identification) is
/// generic over it. A robot generated with a selection of functions implements
/// [`RobotDescription`] and the selected traits only.
pub trait Robot:
    InverseDynamics
    + MassMatrix
    + ForwardDynamics
    + Kinematics
    + Regressors
    + JointDynamics
    + Frames
    + Centroidal
    + Derivatives
{
}

impl<
        T: InverseDynamics
            + MassMatrix
            + ForwardDynamics
            + Kinematics
            + Regressors
            + JointDynamics
            + Frames
            + Centroidal
            + Derivatives,
    > Robot for T
{
}

/// Operation counts of one generated function, as the generator measured them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    pub muls: usize,
    pub divs: usize,
    /// Additions and subtractions.
    pub adds: usize,
    pub negs: usize,
    /// `sin` and `cos` evaluations (a fused `sin_cos` counts as two).
    pub trig: usize,
    /// `let` statements emitted.
    pub statements: usize,
}

impl core::fmt::Display for OpCount {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{} mul, {} div, {} add, {} neg, {} trig ({} statements)",
            self.muls, self.divs, self.adds, self.negs, self.trig, self.statements
        )
    }
}
