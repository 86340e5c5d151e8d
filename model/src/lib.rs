//! # dyngen-model
//!
//! The robot description every other dyngen crate builds on: a checked fixed-base
//! kinematic tree ([`Model`]) in regular labelling, the front ends that produce it
//! (URDF and MJCF here; the `robot!` DSL lives in `dyngen-codegen`), the paper's graph theory
//! ([`graph`]), a URDF writer so any model can be opened in standard tools, the
//! numeric joint torque regressor ([`regressor`]) and the base-parameter analysis
//! built on it ([`base`]), with the project's parameter names ([`names`]).
//!
//! ```
//! let urdf = r#"<robot name="pendulum">
//!   <link name="base"/>
//!   <link name="arm"><inertial><mass value="1"/><origin xyz="0 0 -0.5"/>
//!     <inertia ixx="0.1" iyy="0.1" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
//!   <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
//!     <axis xyz="0 1 0"/></joint>
//! </robot>"#;
//! let model = dyngen_model::parse_urdf(urdf).unwrap();
//! assert_eq!(model.dof(), 1);
//! assert_eq!(dyngen_model::graph::incidence(&model), vec![vec![-1], vec![1]]);
//! ```

pub mod base;
pub mod desc;
pub mod error;
pub mod graph;
mod ir;
pub mod joint_params;
pub mod math;
pub mod mjcf;
mod mjcf_mesh;
mod multibody;
pub mod names;
pub mod principal;
pub mod regressor;
pub mod sample;
pub mod urdf;
mod write;
pub mod xml;

pub use base::{BaseParams, Parameterisation};
pub use desc::{
    check_inertial, check_physical, inertia_violation, nearest_physical_moments, DeclaredJointType, Description,
    JointDesc, LinkDesc, LoadOptions, MimicDesc, SiblingOrder, DEFAULT_GRAVITY, FREE_FLYER_JOINT, INERTIA_TOLERANCE,
    WORLD_LINK,
};
pub use error::{Element, ErrorKind, ModelError, ModelErrors};
pub use ir::{Body, Frame, Inertial, Joint, JointDynamics, JointKind, JointMimic, Limits, Model, Placement};
pub use mjcf::{
    load_mjcf, load_mjcf_options, load_mjcf_with, load_robot, load_robot_options, load_robot_with, parse_mjcf,
    parse_mjcf_options, parse_mjcf_with,
};
pub use principal::{principal_frames, principal_params, PrincipalFrame};
pub use urdf::{load_urdf, load_urdf_options, load_urdf_with, parse_urdf, parse_urdf_options, parse_urdf_with};
pub use write::{inertial_element, to_urdf};
