//! The paper's principal parameterisation: each body's `θ = (m, J1, J2, J3)`, with
//! its centre of mass and principal axes fixed by the description, and the constant
//! 10 × 4 matrix `P` with `π = P θ` (docs/design.md, "Conventions").

use crate::ir::{Inertial, Model};
use crate::math::{Mat3, Vec3, IDENTITY};

/// A body's centroidal principal frame: origin at the centre of mass `com` and axes
/// the columns of `rotation` (both in the body frame), with the principal moments
/// `moments` about those axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipalFrame {
    pub com: Vec3,
    pub rotation: Mat3,
    pub moments: Vec3,
}

impl PrincipalFrame {
    /// The principal frame of an inertial. When the inertia about the centre of mass is
    /// already diagonal in body axes (every body of the `robot!` DSL, whose frames
    /// are principal by construction) the axes are the body axes and `J1, J2, J3`
    /// are about x, y, z in that order; otherwise they come from the eigen-decomposition
    /// (ascending moments, a proper rotation).
    pub fn of(inertial: &Inertial) -> PrincipalFrame {
        let i = &inertial.inertia;
        if i[0][1] == 0.0 && i[0][2] == 0.0 && i[1][2] == 0.0 && i[1][0] == 0.0 && i[2][0] == 0.0 && i[2][1] == 0.0 {
            return PrincipalFrame {
                com: inertial.com,
                rotation: IDENTITY,
                moments: [i[0][0], i[1][1], i[2][2]],
            };
        }
        let (moments, rotation) = inertial.principal_axes();
        PrincipalFrame {
            com: inertial.com,
            rotation,
            moments,
        }
    }

    /// `θ = (m, J1, J2, J3)` of a body with this frame and mass `mass`.
    pub fn theta(&self, mass: f64) -> [f64; 4] {
        [mass, self.moments[0], self.moments[1], self.moments[2]]
    }

    /// `P` (10 × 4, row-major) with `π = P θ`, in Pinocchio's standard order
    /// `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`:
    /// `I = R diag(J) Rᵀ + m (|c|² E − c cᵀ)`.
    pub fn p_matrix(&self) -> [[f64; 4]; 10] {
        let c = self.com;
        let r = &self.rotation;
        let c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        // Index pairs of the six inertia entries in standard order.
        const ENTRIES: [(usize, usize); 6] = [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)];
        let mut p = [[0.0; 4]; 10];
        p[0][0] = 1.0;
        for k in 0..3 {
            p[1 + k][0] = c[k];
        }
        for (e, &(a, b)) in ENTRIES.iter().enumerate() {
            let delta = if a == b { c2 } else { 0.0 };
            p[4 + e][0] = delta - c[a] * c[b];
            for k in 0..3 {
                // (R e_k e_kᵀ Rᵀ)_ab = R_ak R_bk
                p[4 + e][1 + k] = r[a][k] * r[b][k];
            }
        }
        p
    }
}

/// Principal frames of every moving body of a model, body 1 first.
pub fn principal_frames(model: &Model) -> Vec<PrincipalFrame> {
    model.bodies.iter().map(|b| PrincipalFrame::of(&b.inertial)).collect()
}

/// The nominal `θ` of every body, 4 per body, body 1 first.
pub fn principal_params(model: &Model) -> Vec<f64> {
    model
        .bodies
        .iter()
        .flat_map(|b| PrincipalFrame::of(&b.inertial).theta(b.inertial.mass))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn p_theta_reproduces_standard_params() {
        let inertial = Inertial {
            mass: 2.5,
            com: [0.1, -0.2, 0.05],
            inertia: [[0.03, 0.002, -0.001], [0.002, 0.02, 0.0015], [-0.001, 0.0015, 0.025]],
        };
        let f = PrincipalFrame::of(&inertial);
        let p = f.p_matrix();
        let theta = f.theta(inertial.mass);
        let pi = inertial.standard_params();
        for r in 0..10 {
            let v: f64 = (0..4).map(|k| p[r][k] * theta[k]).sum();
            assert!((v - pi[r]).abs() < 1e-15, "row {r}: {v} vs {}", pi[r]);
        }
    }

    #[test]
    fn diagonal_inertia_keeps_body_axes_and_order() {
        let inertial = Inertial::principal(3.0, [0.5, 0.1, 0.3]);
        let f = PrincipalFrame::of(&inertial);
        assert_eq!(f.rotation, IDENTITY);
        assert_eq!(f.theta(3.0), [3.0, 0.5, 0.1, 0.3]);
    }
}
