//! `dyngen_algo` run on the symbolic expression type records the same functions as
//! the generator's own graph builders (`dyngen_codegen::algo`): evaluated on random
//! states of every shipped robot description (fixed bases, free flyers, planar
//! joints), they agree to rounding. `--nocapture` prints both operation counts.

use dyngen_algo::{aba, crba, joint_torque_regressor, rnea, Workspace};
use dyngen_codegen::algo::{self, Armature, Inputs, ARG_A, ARG_PARAMS, ARG_Q, ARG_V};
use dyngen_codegen::sym::{Expr, Graph, NodeId, OpCount};
use dyngen_model::{load_urdf_options, LoadOptions, Model};
use rand::{Rng, SeedableRng};
use std::path::Path;

const ROBOTS: [(&str, bool); 9] = [
    ("robots/ur5/ur5.urdf", false),
    ("robots/panda/panda.urdf", false),
    ("robots/puma560/puma560.urdf", false),
    ("robots/gripper_arm/gripper_arm.urdf", false),
    ("tests/fixtures/paper6.urdf", false),
    ("tests/fixtures/tree12.urdf", false),
    ("tests/fixtures/mobile_arm.urdf", false),
    ("robots/quadruped12/quadruped12.urdf", true),
    ("robots/humanoid31/humanoid31.urdf", true),
];

fn load(path: &str, free_flyer: bool) -> Model {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let options = LoadOptions {
        free_flyer,
        ..LoadOptions::default()
    };
    load_urdf_options(&root.join(path), options).unwrap()
}

fn ids(e: &[Expr<'_>]) -> Vec<NodeId> {
    e.iter().map(|x| x.id()).collect()
}

#[test]
fn the_algorithms_on_expressions_are_the_generators_functions() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    for (path, free_flyer) in ROBOTS {
        let model = load(path, free_flyer);
        let body = model.multibody().unwrap();
        let (nq, nv, nb) = (body.nq(), body.nv(), body.bodies());
        let g = Graph::new();
        let input = |arg: u8, n: usize| (0..n).map(|i| g.input(arg, i as u32)).collect::<Vec<_>>();
        let (q, v, a, p) = (
            input(ARG_Q, nq),
            input(ARG_V, nv),
            input(ARG_A, nv),
            input(ARG_PARAMS, 10 * nb),
        );
        let mut ws = Workspace::new(&body, &g);
        let zero = g.zero();
        let (mut tau, mut m, mut qdd, mut y) = (
            vec![zero; nv],
            vec![zero; nv * nv],
            vec![zero; nv],
            vec![zero; nv * 10 * nb],
        );
        rnea(&body, &mut ws, &q, &v, &a, &p, &mut tau);
        crba(&body, &mut ws, &q, &p, &mut m);
        // aba reads the torque from the third argument, as the generated aba.
        aba(&body, &mut ws, &q, &v, &a, &p, &[], &mut qdd);
        joint_torque_regressor(&body, &mut ws, &q, &v, &a, &mut y);
        let ours = [
            ("rnea", ids(&tau)),
            ("crba", ids(&m)),
            ("aba", ids(&qdd)),
            ("regressor", ids(&y)),
        ];
        let theirs = [
            ("rnea", ids(&algo::rnea(&g, &model, Inputs::Full).tau)),
            (
                "crba",
                algo::crba(&g, &model).iter().flatten().map(|x| x.id()).collect(),
            ),
            ("aba", ids(&algo::aba(&g, &model, Armature::None))),
            (
                "regressor",
                algo::torque_regressor(&g, &model, algo::standard_columns(&g))
                    .iter()
                    .flatten()
                    .map(|x| x.unwrap_or(zero).id())
                    .collect(),
            ),
        ];
        // A random state: unit quaternions where the coordinates are one.
        let mut state: Vec<Vec<f64>> = vec![
            body.neutral().iter().map(|x| x + rng.gen_range(-1.0..1.0)).collect(),
            (0..nv).map(|_| rng.gen_range(-1.0..1.0)).collect(),
            (0..nv).map(|_| rng.gen_range(-1.0..1.0)).collect(),
            body.params.clone(),
        ];
        body.normalize(&mut state[0]);
        let read = |arg: u8, i: u32| state[arg as usize][i as usize];
        let mut line = Vec::new();
        for ((what, ours), (_, theirs)) in ours.iter().zip(&theirs) {
            let (x, y) = (g.eval(ours, read), g.eval(theirs, read));
            let scale = y.iter().fold(1.0f64, |s, b| s.max(b.abs()));
            let err = x.iter().zip(&y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / scale;
            assert!(err < 1e-11, "{path}: {what} differs from the generator's by {err:e}");
            let (co, ct) = (OpCount::of(&g, ours), OpCount::of(&g, theirs));
            line.push(format!("{what} {} vs {} flops", co.flops(), ct.flops()));
        }
        println!("{path}: {}", line.join(", "));
    }
}
