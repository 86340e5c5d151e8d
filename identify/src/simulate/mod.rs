//! Simulated experiments for identification: the paper's ADAMS
//! experiment ([`Experiment`], [`record`]), optimal Fourier excitation
//! ([`FourierExcitation`], [`ExcitationDesign`]), forward simulation from torques
//! ([`simulate_rk4`]) and seeded sensor noise ([`NoiseModel`]). Everything runs on a
//! [`Dynamics`](dyngen_reference::Dynamics): a generated robot or any URDF loaded at
//! run time.
//!
//! ```
//! use dyngen_reference::Dynamics;
//! use dyngen_identify::simulate::{record, Experiment, NoiseModel};
//! let urdf = r#"<robot name="pendulum">
//!   <link name="base"/>
//!   <link name="arm"><inertial><mass value="1"/><origin xyz="0 0 -0.5"/>
//!     <inertia ixx="0.1" iyy="0.1" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
//!   <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
//!     <axis xyz="0 1 0"/></joint>
//! </robot>"#;
//! let model = dyngen_model::parse_urdf(urdf).unwrap();
//! let robot = dyngen_reference::Reference::new(&model);
//! let experiment = Experiment::paper(&model);
//! let clean = record(&robot, &model.standard_params(), &experiment);
//! assert_eq!(clean.len(), 101); // 2 s in 100 steps, t = 0 included
//! let noisy = NoiseModel::mim(0.01).apply(&clean, 7);
//! let k = noisy.nearest(1.5).unwrap();
//! let (a, y) = noisy.body_system(0, k..k + 1); // one instant, as the paper
//! assert_eq!((a.nrows(), a.ncols(), y.len()), (6, 4, 6));
//! ```

mod cardano;
mod excitation;
mod experiment;
mod integrate;
mod logger;
mod motion;
mod noise;

pub use cardano::{cardano_angles, cardano_matrix, cardano_rate_matrix, cardano_rates};
pub use excitation::{
    moment_sigma, regressor_condition, Criterion, ExcitationDesign, JointLimits, OptimisedExcitation,
};
pub use experiment::{record, record_trajectory, BodyMeasurement, Experiment, Motion, Recording, Sample};
pub use integrate::{simulate_rk4, Simulation};
pub use logger::{add_extra_terms, add_joint_terms, add_stribeck_terms, Logger};
pub use motion::{FourierExcitation, JointMotion, RaisedCosine, SampledMotion};
pub use noise::{Channel, Gaussian, NoiseModel, Sigma};
