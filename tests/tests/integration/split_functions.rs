//! Functions split into `#[inline(never)]` parts compute exactly what the unsplit
//! ones do: the same operations in the same order, only passed through an array.

use dyngen_reference::sample_states;
use dyngen_reference::Reference;
use dyngen_tests::split::Ur5Split;
use robot_ur5::Ur5;

#[test]
fn the_functions_compared_are_split() {
    for (name, ops) in Ur5Split::OP_COUNTS {
        if [
            "rnea",
            "forward_kinematics",
            "joint_wrenches",
            "crba",
            "aba",
            "joint_torque_regressor",
            "aba_joints",
        ]
        .contains(&name)
        {
            assert!(
                ops.statements > 40,
                "{name} has only {} statements: not split",
                ops.statements
            );
        }
    }
    assert_eq!(Ur5Split::OP_COUNTS, Ur5::OP_COUNTS);
}

#[test]
fn split_code_is_bit_identical_to_unsplit() {
    let model = Reference::of::<Ur5>().model().clone();
    for s in sample_states(&model, 200, 11) {
        let (q, v, a): ([f64; 6], [f64; 6], [f64; 6]) = (
            s.q.try_into().unwrap(),
            s.v.try_into().unwrap(),
            s.a.try_into().unwrap(),
        );
        let p = &Ur5::NOMINAL_PARAMS;
        assert_eq!(Ur5Split::rnea(&q, &v, &a, p), Ur5::rnea(&q, &v, &a, p));
        assert_eq!(
            Ur5Split::joint_wrenches(&q, &v, &a, p),
            Ur5::joint_wrenches(&q, &v, &a, p)
        );
        assert_eq!(Ur5Split::forward_kinematics(&q), Ur5::forward_kinematics(&q));
        assert_eq!(Ur5Split::aba(&q, &v, &a, p), Ur5::aba(&q, &v, &a, p));
        let (mut m1, mut m2) = ([[0.0; 6]; 6], [[0.0; 6]; 6]);
        Ur5Split::crba(&q, p, &mut m1);
        Ur5::crba(&q, p, &mut m2);
        assert_eq!(m1, m2);
        let (mut y1, mut y2) = ([[0.0; 60]; 6], [[0.0; 60]; 6]);
        Ur5Split::joint_torque_regressor(&q, &v, &a, &mut y1);
        Ur5::joint_torque_regressor(&q, &v, &a, &mut y2);
        assert_eq!(y1, y2);
        let jp: [f64; 24] = std::array::from_fn(|k| 0.05 * (k % 4 + 1) as f64);
        let c = dyngen::Coulomb::Sign;
        assert_eq!(
            Ur5Split::aba_joints(&q, &v, &a, p, &jp, c),
            Ur5::aba_joints(&q, &v, &a, p, &jp, c)
        );
    }
}
