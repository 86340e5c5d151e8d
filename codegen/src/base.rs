//! Base parameters, the analysis pass between the checked model and generation. The
//! analysis itself is `dyngen_model::base` (one home, shared with the command line
//! and identification); this module only asks it for all three parameterisations.

use dyngen_model::base::{analyse, Parameterisation};
use dyngen_model::Model;

pub use dyngen_model::base::{BaseParams, RANK_TOLERANCE};

/// The base parameters of every parameterisation of one model: what
/// [`crate::generate`] needs besides the model.
#[derive(Clone, Debug, PartialEq)]
pub struct Bases {
    /// Of the standard parameters, 10 per body.
    pub standard: BaseParams,
    /// Of the principal parameters `θ = (m, J1, J2, J3)`, 4 per body.
    pub principal: BaseParams,
    /// Of the standard parameters followed by the joint parameters `[Ia, Fv, Fc, F0]`
    /// of every joint (`14n` columns, Coulomb friction as `sign(q̇)`).
    pub joints: BaseParams,
}

/// The base-parameter analysis of `model` in the three parameterisations
/// (`dyngen_model::base::analyse`: ordered QR on stacked random regressors, with a
/// second seed and a singular-value count as checks). The largest, of the standard
/// and joint parameters together, runs on a thread of its own beside the other two.
pub fn analyse_model(model: &Model) -> Bases {
    std::thread::scope(|s| {
        let joints = s.spawn(|| analyse(model, Parameterisation::StandardAndJoints));
        let (standard, principal) = analyse_rigid(model);
        Bases {
            standard,
            principal,
            // A panic in the analysis is a bug; it is carried over as it was.
            joints: joints.join().unwrap_or_else(|e| std::panic::resume_unwind(e)),
        }
    })
}

/// The base parameters of the standard and of the principal parameterisation, each on
/// a thread of its own: what `dyngen info` prints, without the larger analysis of the
/// standard and joint parameters together that only generation needs (on a
/// 200-joint chain it is more than half of [`analyse_model`]'s time).
pub fn analyse_rigid(model: &Model) -> (BaseParams, BaseParams) {
    std::thread::scope(|s| {
        let principal = s.spawn(|| analyse(model, Parameterisation::Principal));
        let standard = analyse(model, Parameterisation::Standard);
        // A panic in the analysis is a bug; it is carried over as it was.
        (
            standard,
            principal.join().unwrap_or_else(|e| std::panic::resume_unwind(e)),
        )
    })
}

#[cfg(test)]
mod tests {
    use crate::algo::{self, ARG_A, ARG_Q, ARG_V};
    use crate::sym::Graph;
    use dyngen_model::{regressor, sample};

    /// The analysis runs on the model layer's numeric regressor; the generated base
    /// regressor is built from the symbolic one. Both must be the same matrix, or the
    /// base chosen would not fit the code generated.
    #[test]
    fn symbolic_and_numeric_regressors_agree() {
        for urdf in [
            include_str!("../../robots/ur5/ur5.urdf"),
            include_str!("../../robots/gripper_arm/gripper_arm.urdf"),
        ] {
            let model = dyngen_model::parse_urdf(urdf).unwrap();
            let g = Graph::new();
            let y = algo::torque_regressor(&g, &model, algo::standard_columns(&g));
            let ids: Vec<_> = y
                .iter()
                .flat_map(|row| row.iter().map(|e| e.unwrap_or_else(|| g.zero()).id()))
                .collect();
            for s in sample::sample_states(&model, 5, 7) {
                let vals = g.eval(&ids, |arg, i| match arg {
                    ARG_Q => s.q[i as usize],
                    ARG_V => s.v[i as usize],
                    ARG_A => s.a[i as usize],
                    _ => 0.0,
                });
                let numeric = regressor::joint_torque_regressor(&model, &s.q, &s.v, &s.a).unwrap();
                let flat: Vec<f64> = numeric.concat();
                for (k, (a, b)) in vals.iter().zip(&flat).enumerate() {
                    assert!(
                        (a - b).abs() < 1e-10 * (1.0 + b.abs()),
                        "{}: entry {k}: {a} vs {b}",
                        model.name
                    );
                }
            }
        }
    }
}
