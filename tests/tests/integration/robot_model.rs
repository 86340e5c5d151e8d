//! Every shipped robot carries its checked model as Rust data: `R::MODEL` equals,
//! field by field, the model built from the robot's source (its URDF or its inline
//! description), in the same numbering.

use dyngen::Robot;
use dyngen_model::Model;
use dyngen_tests::tree12::Tree12;
use robot_gripper_arm::GripperArm;
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_puma560::Puma560;
use robot_ur5::Ur5;

fn check<R: Robot>(want: &Model) {
    let got = R::MODEL;
    let who = R::NAME;
    assert_eq!(got.name, want.name, "{who}: name");
    assert_eq!(got.gravity, want.gravity, "{who}: gravity");
    assert_eq!(got.base, want.base, "{who}: base");
    assert_eq!(got.joints.len(), want.joints.len(), "{who}: joints");
    for (g, w) in got.joints.iter().zip(&want.joints) {
        let j = &w.name;
        assert_eq!(g.name, w.name, "{who}: joint name");
        assert_eq!(g.kind, w.kind, "{who}: {j} kind");
        assert_eq!(g.parent, w.parent, "{who}: {j} parent");
        assert_eq!(g.rotation, w.origin.rotation, "{who}: {j} rotation");
        assert_eq!(g.translation, w.origin.translation, "{who}: {j} translation");
        assert_eq!(g.axis, w.axis, "{who}: {j} axis");
        assert_eq!(
            [g.damping, g.friction],
            [w.dynamics.damping, w.dynamics.friction],
            "{who}: {j} dynamics"
        );
        match (&g.limits, &w.limits) {
            (None, None) => {}
            (Some(g), Some(w)) => {
                assert_eq!(
                    [g.lower, g.upper, g.velocity, g.effort],
                    [w.lower, w.upper, w.velocity, w.effort],
                    "{who}: {j} limits"
                );
            }
            (g, w) => panic!("{who}: {j} limits {g:?}, expected {w:?}"),
        }
    }
    assert_eq!(got.bodies.len(), want.bodies.len(), "{who}: bodies");
    for (g, w) in got.bodies.iter().zip(&want.bodies) {
        let b = &w.name;
        assert_eq!(g.name, w.name, "{who}: body name");
        assert_eq!(g.mass, w.inertial.mass, "{who}: {b} mass");
        assert_eq!(g.com, w.inertial.com, "{who}: {b} centre of mass");
        assert_eq!(g.inertia, w.inertial.inertia, "{who}: {b} inertia");
        assert_eq!(g.merged, w.merged, "{who}: {b} merged links");
    }
    assert_eq!(got.frames.len(), want.frames.len(), "{who}: frames");
    for (g, w) in got.frames.iter().zip(&want.frames) {
        let f = &w.name;
        assert_eq!(g.name, w.name, "{who}: frame name");
        assert_eq!(g.body, w.body, "{who}: {f} body");
        assert_eq!(g.rotation, w.placement.rotation, "{who}: {f} rotation");
        assert_eq!(g.translation, w.placement.translation, "{who}: {f} translation");
    }
    // What the other constants say agrees with the model.
    assert_eq!(
        R::parents(),
        got.joints.iter().map(|j| j.parent).collect::<Vec<_>>(),
        "{who}"
    );
    assert_eq!(
        R::joint_names(),
        got.joints.iter().map(|j| j.name).collect::<Vec<_>>(),
        "{who}"
    );
    assert_eq!(
        R::body_names(),
        got.bodies.iter().map(|b| b.name).collect::<Vec<_>>(),
        "{who}"
    );
    assert_eq!(R::gravity(), got.gravity, "{who}");
}

fn crate_model(dir: &str) -> Model {
    dyngen_tests::robot_crate_model(dir).1
}

#[test]
fn shipped_robots_carry_their_checked_model() {
    check::<Planar2>(&crate_model("planar2"));
    check::<Paper6>(&crate_model("paper6"));
    check::<Ur5>(&crate_model("ur5"));
    check::<GripperArm>(&crate_model("gripper_arm"));
    check::<Puma560>(&crate_model("puma560"));
    check::<Panda>(&crate_model("panda"));
    let tree12 = dyngen_model::load_urdf(&dyngen_tests::workspace_root().join("tests/fixtures/tree12.urdf"));
    check::<Tree12>(&tree12.unwrap_or_else(|e| panic!("{e}")));
    let mobile = dyngen_model::load_urdf(&dyngen_tests::workspace_root().join("tests/fixtures/mobile_arm.urdf"));
    check::<dyngen_tests::mobile_arm::MobileArm>(&mobile.unwrap_or_else(|e| panic!("{e}")));
}
