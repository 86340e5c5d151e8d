//! The paper's decoupled body model (docs/design.md, "The paper's decoupled body model"), the ground truth of MIM.
//!
//! Cut every joint: each body `i` then carries the reaction wrenches of the joints
//! it touches, and its Newton–Euler equations about its own centre of mass, in its
//! own centroidal principal frame, involve only its own four parameters
//! `θ_i = (m, J1, J2, J3)`:
//!
//! ```text
//! F_i = m (a_ci − g)                       = Σ_a S_ia F_a
//! M_i = diag(J) ω̇ + ω × (diag(J) ω)        = Σ_a S_ia (M_a + c_ia × F_a)
//! ```
//!
//! [`Reference::body_regressor`] is the left-hand side, `A_i θ_i`;
//! [`Reference::body_resultants`] the right-hand side, computed literally from the
//! graph matrices `S` and `c_ia` and the joint reactions of the RNEA.

use super::spatial::{mat3, vec3};
use super::Reference;
use dyngen::Wrench;
use dyngen_model::graph;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// Euler's equations about the centre of mass in principal axes are linear in the
/// principal moments: `diag(J) ω̇ + ω × (diag(J) ω) = B(ω, ω̇) J`, with
///
/// ```text
/// B = [  ω̇1    −ω2ω3   ω2ω3 ]
///     [  ω3ω1   ω̇2    −ω3ω1 ]
///     [ −ω1ω2   ω1ω2   ω̇3   ]
/// ```
pub fn euler_matrix(w: &Vector3<f64>, dw: &Vector3<f64>) -> Matrix3<f64> {
    let (w1, w2, w3) = (w.x, w.y, w.z);
    #[rustfmt::skip]
    let b = Matrix3::new(
        dw.x,     -w2 * w3,  w2 * w3,
        w3 * w1,   dw.y,    -w3 * w1,
        -w1 * w2,  w1 * w2,  dw.z,
    );
    b
}

impl Reference {
    /// The paper's per-body regressor (docs/design.md, "The paper's decoupled body model"), one `6 × 4` matrix per moving
    /// body, body 1 first: in body `i`'s centroidal principal frame (origin at the
    /// nominal centre of mass `c_i`, axes the columns of `R_i`, both from
    /// [`dyngen_model::PrincipalFrame`]),
    ///
    /// ```text
    /// A_i = [ a_ci − g   0        ]     [F_i; M_i] = A_i θ_i,  θ_i = (m, J1, J2, J3)
    ///       [ 0          B(ω, ω̇)  ]
    /// ```
    ///
    /// with `a_ci` the classical acceleration of the centre of mass, `g` gravity,
    /// `ω`, `ω̇` the body's angular velocity and acceleration, all in principal
    /// axes, and `B` the [`euler_matrix`]. Panics if a length differs.
    pub fn body_regressor(&self, q: &[f64], v: &[f64], a: &[f64]) -> Vec<SMatrix<f64, 6, 4>> {
        let poses = self.forward_kinematics(q);
        let motions = self.body_motions(q, v, a);
        let gravity = vec3(&self.model.gravity);
        (0..self.bodies())
            .map(|k| {
                let frame = &self.frames[k];
                // Body axes → principal axes.
                let to_principal = mat3(&frame.rotation).transpose();
                let com = vec3(&frame.com);
                let a_c = to_principal * motions[k].point_acceleration(&com);
                let g = to_principal * poses[k].rotation.transpose() * gravity;
                let w = to_principal * motions[k].velocity.angular;
                let dw = to_principal * motions[k].acceleration.angular;
                let mut block = SMatrix::<f64, 6, 4>::zeros();
                block.fixed_view_mut::<3, 1>(0, 0).copy_from(&(a_c - g));
                block.fixed_view_mut::<3, 3>(3, 1).copy_from(&euler_matrix(&w, &dw));
                block
            })
            .collect()
    }

    /// Each moving body's resultant of the joint reaction wrenches acting on it,
    /// body 1 first: the force, and the moment about its (nominal) centre of mass,
    /// both in its centroidal principal frame. Computed through the graph matrices
    /// (docs/design.md, "The paper's graph theory"),
    ///
    /// ```text
    /// F_i = Σ_a S_ia F_a
    /// M_i = Σ_a S_ia (M_a + c_ia × F_a)
    /// ```
    ///
    /// with `S` the incidence matrix ([`graph::incidence`]), `c_ia` the body-joint
    /// vectors ([`graph::body_joint_vectors`]) and `(F_a, M_a)` the wrench joint `a`
    /// applies to its outboard body ([`Reference::joint_wrenches`]), seen from body
    /// `i`: in body `i`'s axes, moment about body `i`'s point of joint `a`. For the
    /// outboard body that is the wrench as given (frame `a`, moment about its
    /// origin). For the inboard body it is rotated by the joint placement `E_a`,
    /// and its moment moved from the outboard joint point to the inboard one, which
    /// is `c_ia`'s end: `M ← E_a M_a + z_a × E_a F_a`, with `z_a` the offset
    /// between them (the slide `R_0 k q` of a prismatic joint, zero for a revolute
    /// one). The inboard body gets the opposite wrench through `S_ia = −1`.
    ///
    /// With the description's parameters this equals `A_i θ_i` from
    /// [`Reference::body_regressor`], and so it does for any parameters of the form
    /// `π = blkdiag(P_i) θ` ([`super::principal_params_to_standard`]). Parameters
    /// that move a centre of mass or turn principal axes break that equality: `c_ia`
    /// and the principal frame stay the description's. Panics if a length differs.
    pub fn body_resultants(&self, q: &[f64], v: &[f64], a: &[f64], params: &[f64]) -> Vec<Wrench<f64>> {
        self.resultants_of_joint_wrenches(q, &self.joint_wrenches(q, v, a, params))
    }

    /// The body resultants of [`Reference::body_resultants`] from given (measured)
    /// joint wrenches instead of the RNEA's: `wrenches[j]` is joint `j + 1`'s
    /// reaction on its outboard body in that body's frame, moment about the joint
    /// origin (the convention of [`Reference::joint_wrenches`] and of the CSV
    /// wrench columns, `dyngen_identify::data`). Only `q` enters (the geometry). Panics if a
    /// length differs.
    pub fn resultants_of_joint_wrenches(&self, q: &[f64], wrenches: &[Wrench<f64>]) -> Vec<Wrench<f64>> {
        assert_eq!(wrenches.len(), self.bodies(), "one joint wrench per joint");
        let resultants = self.resultants_in_body_frames(q, wrenches);
        resultants[1..]
            .iter()
            .zip(&self.frames)
            .map(|((force, moment), frame)| {
                let to_principal = mat3(&frame.rotation).transpose();
                Wrench {
                    force: to_principal * force,
                    torque: to_principal * moment,
                }
            })
            .collect()
    }

    /// The resultants of [`Reference::body_resultants`] for bodies `0..=n` (the
    /// base included), in each body's own frame, moment about its centre of mass
    /// (about the base frame origin for body 0).
    fn resultants_in_body_frames(&self, q: &[f64], reactions: &[Wrench<f64>]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let n = self.bodies();
        let s = graph::incidence(&self.model);
        let c = graph::body_joint_vectors(&self.model);
        let placements: Vec<(Matrix3<f64>, Vector3<f64>)> = self.with_workspace(|ws| {
            dyngen_algo::forward_kinematics(self.multibody(), ws, q);
            ws.placement[1..]
                .iter()
                .map(|p| {
                    let x = p.se3(0.0, 1.0);
                    (mat3(&x.rotation), vec3(&x.translation))
                })
                .collect()
        });

        let mut resultants = vec![(Vector3::zeros(), Vector3::zeros()); n + 1];
        for (i, (force_i, moment_i)) in resultants.iter_mut().enumerate() {
            for joint in 1..=n {
                let sign = f64::from(s[i][joint - 1]);
                if sign == 0.0 {
                    continue;
                }
                let reaction = &reactions[joint - 1];
                // (F_a, M_a) in body i's axes, moment about body i's point of joint a.
                let (force, moment) = if i == joint {
                    (reaction.force, reaction.torque)
                } else {
                    let (rotation, translation) = &placements[joint - 1];
                    let inboard_point = vec3(&self.model.joints[joint - 1].origin.translation);
                    let z = translation - inboard_point;
                    let force = rotation * reaction.force;
                    (force, rotation * reaction.torque + z.cross(&force))
                };
                let c_ia = vec3(&c[i][joint - 1]);
                *force_i += sign * force;
                *moment_i += sign * (moment + c_ia.cross(&force));
            }
        }
        resultants
    }
}
