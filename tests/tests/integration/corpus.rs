//! The robot corpus (`tests/fixtures/corpus/`: a 20-joint hand, a 12-joint
//! quadruped and a 31-joint humanoid, all fixed base, written by
//! `scripts/make_corpus_urdfs.py`) against Pinocchio 4.1 fixtures: the URDF as
//! dyngen loads it, the symbolic algorithms the generator emits (evaluated straight
//! from the expression graph, so nothing this large is compiled here), and the
//! reference implementation.

use dyngen_codegen::sym::Graph;
use dyngen_model::{load_urdf, Model};
use dyngen_reference::Reference;
use dyngen_tests::{
    eval_graph as eval, load_fixture, pose_vec, rel_err, workspace_root, wrench_vec, DynamicsGraph, Fixture,
};

/// Agreement required with Pinocchio (normwise, relative).
const TOL: f64 = 1e-10;

const CORPUS: [(&str, usize); 3] = [("hand20", 20), ("quadruped12", 12), ("humanoid31", 31)];

fn load(name: &str) -> (Model, Fixture) {
    let urdf = workspace_root().join(format!("tests/fixtures/corpus/{name}.urdf"));
    let model = load_urdf(&urdf).unwrap_or_else(|e| panic!("{e}"));
    (model, load_fixture(&format!("corpus/{name}")))
}

fn rows(m: &[Vec<f64>]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

/// The model as loaded has Pinocchio's joints, numbering, parents and parameters.
#[test]
fn corpus_models_are_pinocchios() {
    for (name, dof) in CORPUS {
        let (model, fx) = load(name);
        assert_eq!(model.dof(), dof, "{name}");
        let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        assert_eq!(
            names, fx.model.joint_names,
            "{name}: joint order differs from Pinocchio's"
        );
        let parents: Vec<usize> = model.joints.iter().map(|j| j.parent).collect();
        assert_eq!(parents, fx.model.parents, "{name}: parents differ from Pinocchio's");
        assert_eq!(model.gravity, fx.gravity, "{name}");
        let theirs: Vec<f64> = fx.model.dyn_params.iter().flatten().copied().collect();
        let e = rel_err(&model.standard_params(), &theirs, 1e-9);
        assert!(e < TOL, "{name}: parameters differ from Pinocchio's by {e:e}");
    }
}

/// The reference implementation: kinematics, rnea, joint wrenches, crba, the torque
/// regressor and aba.
#[test]
fn corpus_reference_matches_pinocchio() {
    for (name, _) in CORPUS {
        let (model, fx) = load(name);
        let r = Reference::new(&model);
        let params = model.standard_params();
        let mut worst = 0.0f64;
        for (k, s) in fx.samples.iter().enumerate() {
            let mut check = |what: &str, ours: &[f64], theirs: &[f64], floor: f64| {
                let e = rel_err(ours, theirs, floor);
                assert!(e < TOL, "{name} sample {k}: {what} differs from Pinocchio's by {e:e}");
                worst = worst.max(e);
            };
            let poses = r.forward_kinematics(&s.q);
            for (b, p) in poses.iter().enumerate() {
                check(
                    &format!("pose of body {}", b + 1),
                    &pose_vec(p),
                    &s.o_m_i[b].to_vec(),
                    1.0,
                );
            }
            check("rnea", &r.rnea(&s.q, &s.v, &s.a, &params), &s.tau, 1e-9);
            let wrenches: Vec<f64> = r
                .joint_wrenches(&s.q, &s.v, &s.a, &params)
                .iter()
                .flat_map(wrench_vec)
                .collect();
            let theirs: Vec<f64> = s.f.iter().flatten().copied().collect();
            check("joint wrenches", &wrenches, &theirs, 1e-9);
            let m = r.crba(&s.q, &params);
            let ours: Vec<f64> = (0..m.nrows())
                .flat_map(|i| (0..m.ncols()).map(move |j| (i, j)))
                .map(|(i, j)| m[(i, j)])
                .collect();
            check("crba", &ours, &rows(&s.m), 1e-9);
            let y = r.joint_torque_regressor(&s.q, &s.v, &s.a);
            let ours: Vec<f64> = (0..y.nrows())
                .flat_map(|i| (0..y.ncols()).map(move |j| (i, j)))
                .map(|(i, j)| y[(i, j)])
                .collect();
            check("torque regressor", &ours, &rows(&s.y), 1e-9);
            check("aba", &r.aba(&s.q, &s.v, &s.tau_fd, &params), &s.ddq, 1e-9);
        }
        println!("{name}: reference, worst relative error against Pinocchio {worst:.1e}");
    }
}

/// The algorithms the generator emits for each robot: rnea, the nonlinear effects,
/// gravity, crba and aba.
#[test]
fn corpus_generated_algorithms_match_pinocchio() {
    for (name, _) in CORPUS {
        let (model, fx) = load(name);
        let g = Graph::new();
        let DynamicsGraph {
            rnea,
            nonlinear_effects: nle,
            gravity,
            crba,
            aba,
        } = DynamicsGraph::new(&g, &model);
        let params = model.standard_params();
        let mut worst = 0.0f64;
        for (k, s) in fx.samples.iter().enumerate() {
            let mut check = |what: &str, ours: Vec<f64>, theirs: &[f64]| {
                let e = rel_err(&ours, theirs, 1e-9);
                assert!(
                    e < TOL,
                    "{name} sample {k}: generated {what} differs from Pinocchio's by {e:e}"
                );
                worst = worst.max(e);
            };
            check("rnea", eval(&g, &rnea, &s.q, &s.v, &s.a, &params), &s.tau);
            check("nonlinear effects", eval(&g, &nle, &s.q, &s.v, &s.a, &params), &s.nle);
            check("gravity", eval(&g, &gravity, &s.q, &s.v, &s.a, &params), &s.g);
            check("crba", eval(&g, &crba, &s.q, &s.v, &s.a, &params), &rows(&s.m));
            check("aba", eval(&g, &aba, &s.q, &s.v, &s.tau_fd, &params), &s.ddq);
        }
        println!("{name}: generated algorithms, worst relative error against Pinocchio {worst:.1e}");
    }
}
