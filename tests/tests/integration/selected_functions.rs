//! A robot generated with a selection of functions (`robot!`'s `functions: [..]`):
//! it implements the selected capability traits (and what they are built from) with
//! the same code as the robot with every function, and nothing else.

use dyngen::{Centroidal, ForwardDynamics, Frames, InverseDynamics, MassMatrix, ReferenceFrame};
use dyngen_reference::{sample_states, Reference};
use robot_ur5::Ur5;

mod control {
    dyngen::robot!(
        name: Ur5Control,
        urdf: "../robots/ur5/ur5.urdf",
        functions: [rnea, crba, aba, frame_jacobian],
    );
}
use control::Ur5Control;

/// What a controller needs, by trait: the selection implements it.
fn control_step<R: InverseDynamics + MassMatrix + ForwardDynamics + Frames + Centroidal>(
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Vec<f64> {
    let n = R::NV;
    let (mut tau, mut m, mut acc, mut jac) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n], vec![0.0; 6 * n]);
    R::rnea(q, v, a, R::nominal_params(), &mut tau);
    R::crba(q, R::nominal_params(), &mut m);
    R::aba(q, v, &tau, R::nominal_params(), &mut acc);
    R::frame_jacobian(
        q,
        R::MODEL.frames.len() - 1,
        ReferenceFrame::LocalWorldAligned,
        &mut jac,
    )
    .unwrap();
    let com = R::center_of_mass(q, R::nominal_params());
    [tau, m, acc, jac, com.to_vec()].concat()
}

#[test]
fn selected_functions_are_the_full_robots() {
    let groups = [
        "inverse_dynamics",
        "mass_matrix",
        "forward_dynamics",
        "frames",
        "centroidal",
    ];
    for (name, _) in Ur5Control::OP_COUNTS {
        // Per-frame functions are reported as `frame_jacobian[tool0]`.
        let function = name.split('[').next().unwrap_or(name);
        // Helpers such as `frame_placements` belong to no trait.
        if let Some(c) = dyngen_codegen::Capability::from_name(function) {
            assert!(groups.contains(&c.name()), "{name} generated");
        }
    }
    let names: Vec<&str> = Ur5Control::OP_COUNTS.iter().map(|(n, _)| *n).collect();
    for wanted in ["rnea", "crba", "aba"] {
        assert!(names.contains(&wanted), "{wanted} missing from {names:?}");
    }
    let statements = |counts: &[(&str, dyngen::OpCount)]| counts.iter().map(|(_, c)| c.statements).sum::<usize>();
    let (some, all) = (statements(&Ur5Control::OP_COUNTS), statements(&Ur5::OP_COUNTS));
    println!("{some} of {all} statements generated");
    assert!(some * 2 < all, "{some} of {all} statements generated");
    let reference = Reference::of::<Ur5>();
    for s in sample_states(reference.model(), 5, 11) {
        // The same graphs emitted the same way: equal to the last bit.
        assert_eq!(
            control_step::<Ur5Control>(&s.q, &s.v, &s.a),
            control_step::<Ur5>(&s.q, &s.v, &s.a)
        );
    }
}
