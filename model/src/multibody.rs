//! The bridge to the algorithms: a checked [`Model`] as the [`Multibody`] that
//! `dyngen-algo`'s rnea, crba, aba and Jacobians run on at run time.

use crate::math::plane_basis;
use crate::Model;
use dyngen_algo::{JointSpec, Multibody, Se3, TreeError};

impl Model {
    /// This model as the algorithms' [`Multibody`]: the same numbering, placements,
    /// axes, gravity and nominal standard parameters ([`Model::standard_params`]), and
    /// the joints that follow others ([`crate::JointMimic`]) as [`dyngen_algo::Mimic`]s.
    ///
    /// ```
    /// let model = dyngen_model::parse_urdf(r#"<robot name="r"><link name="base"/>
    ///   <link name="arm"><inertial><mass value="2"/><origin xyz="0 0 -0.5"/>
    ///     <inertia ixx="0.1" iyy="0.1" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
    ///   <joint name="j" type="continuous"><parent link="base"/><child link="arm"/>
    ///     <axis xyz="0 1 0"/></joint></robot>"#).unwrap();
    /// let body = model.multibody().unwrap();
    /// let mut ws = dyngen_algo::Workspace::new(&body, ());
    /// let mut m = [0.0];
    /// dyngen_algo::crba(&body, &mut ws, &[0.3], &body.params, &mut m);
    /// assert!((m[0] - (0.1 + 2.0 * 0.25)).abs() < 1e-12); // I_yy + m l²
    /// ```
    ///
    /// # Errors
    /// Only for a model that was not checked (its fields edited by hand): a parent
    /// that is not an earlier body, or a free flyer below the root.
    pub fn multibody(&self) -> Result<Multibody, TreeError> {
        let params = self.standard_params();
        let specs: Vec<JointSpec> = self
            .joints
            .iter()
            .enumerate()
            .map(|(k, j)| {
                let (e1, e2) = plane_basis(&j.axis);
                let mut p = [0.0; 10];
                p.copy_from_slice(&params[10 * k..10 * k + 10]);
                JointSpec {
                    kind: j.kind,
                    parent: j.parent,
                    origin: Se3 {
                        rotation: j.origin.rotation,
                        translation: j.origin.translation,
                    },
                    axis: j.axis,
                    plane: [e1, e2],
                    params: p,
                }
            })
            .collect();
        Multibody::new(self.gravity, &specs)?.with_mimics(&self.algo_mimics())
    }

    /// The joints that follow others as the algorithms number them (0-based).
    pub(crate) fn algo_mimics(&self) -> Vec<dyngen_algo::Mimic> {
        (self.joints.iter().enumerate())
            .filter_map(|(k, j)| j.mimic.map(|m| m.of_joint(k + 1)))
            .collect()
    }
}
