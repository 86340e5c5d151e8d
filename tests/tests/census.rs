//! The loading census (`tests/fixtures/census/`, written with Pinocchio 4.1 fixtures by
//! `scripts/make_census_fixtures.py`): descriptions that carry what public robot
//! descriptions carry and a link-by-link loader refuses (a dummy root link with a
//! noise inertia on a free flyer, an inertia-only rotor, massless knuckle and tip
//! links, an inertia 20 % beyond the triangle inequality, a `<mimic>` on a fixed
//! joint, a single rigid body on a free flyer). Each loads with exactly the warnings
//! listed, and as Pinocchio loads it: the same joints, parents and merged parameters,
//! and the generator's algorithms (rnea, nonlinear effects, gravity, crba, and aba
//! where the mass matrix is regular), evaluated from the expression graph, give
//! Pinocchio's numbers.

use dyngen_codegen::sym::Graph;
use dyngen_model::{load_urdf_options, ErrorKind, LoadOptions, Model};
use dyngen_tests::{eval_graph as eval, json_numbers, load_json, rel_err, workspace_root, DynamicsGraph};

/// Agreement required with Pinocchio (normwise, relative).
const TOL: f64 = 1e-10;

/// name, on a free flyer, the warnings expected (element, kind).
type Case = (&'static str, bool, &'static [(&'static str, fn(&ErrorKind) -> bool)]);

const CENSUS: [Case; 4] = [
    ("dummy_root_quadruped", true, &[]),
    (
        "arm_gripper",
        false,
        &[("link `left_finger`", |k| matches!(k, ErrorKind::TriangleInequality(_)))],
    ),
    ("quadrotor", true, &[]),
    (
        "massless_tip",
        false,
        &[("joint `wrist`", |k| *k == ErrorKind::SingularMassMatrix)],
    ),
];

fn load(name: &str, free_flyer: bool) -> Model {
    let path = workspace_root().join(format!("tests/fixtures/census/{name}.urdf"));
    let options = LoadOptions {
        free_flyer,
        ..LoadOptions::default()
    };
    load_urdf_options(&path, options).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn census_loads_with_the_warnings_listed() {
    for (name, free_flyer, expected) in CENSUS {
        let model = load(name, free_flyer);
        assert_eq!(model.warnings.len(), expected.len(), "{name}: {:#?}", model.warnings);
        for (w, (element, kind)) in model.warnings.iter().zip(expected) {
            assert_eq!(w.element.to_string(), *element, "{name}");
            assert!(kind(&w.kind), "{name}: {w:?}");
        }
        // Strict refuses exactly what was warned about.
        let path = workspace_root().join(format!("tests/fixtures/census/{name}.urdf"));
        let strict = LoadOptions {
            free_flyer,
            strict: true,
            ..LoadOptions::default()
        };
        match load_urdf_options(&path, strict) {
            Ok(_) => assert!(expected.is_empty(), "{name}: a strict load accepted it"),
            Err(e) => assert_eq!(e.errors.len(), expected.len(), "{name}: {e}"),
        }
    }
}

#[test]
fn census_models_are_pinocchios() {
    for (name, free_flyer, _) in CENSUS {
        let model = load(name, free_flyer);
        let fx = load_json(&format!("census/{name}.json"));
        let joints: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        let theirs: Vec<&str> = fx["model"]["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap())
            .collect();
        assert_eq!(joints, theirs, "{name}: joints differ from Pinocchio's");
        let parents: Vec<f64> = model.joints.iter().map(|j| j.parent as f64).collect();
        assert_eq!(parents, json_numbers(&fx["model"]["parents"]), "{name}");
        let e = rel_err(&model.standard_params(), &json_numbers(&fx["model"]["params"]), 1e-9);
        assert!(e < TOL, "{name}: merged parameters differ from Pinocchio's by {e:e}");
    }
}

#[test]
fn census_generated_algorithms_match_pinocchio() {
    for (name, free_flyer, _) in CENSUS {
        let model = load(name, free_flyer);
        let fx = load_json(&format!("census/{name}.json"));
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
        let samples = fx["samples"].as_array().unwrap();
        let mut forward = 0;
        for (k, s) in samples.iter().enumerate() {
            let x = |key: &str| json_numbers(&s[key]);
            let (q, v, a) = (x("q"), x("v"), x("a"));
            let mut check = |what: &str, ours: Vec<f64>, theirs: Vec<f64>| {
                let e = rel_err(&ours, &theirs, 1e-9);
                assert!(e < TOL, "{name} sample {k}: {what} differs from Pinocchio's by {e:e}");
                worst = worst.max(e);
            };
            check("rnea", eval(&g, &rnea, &q, &v, &a, &params), x("tau"));
            check("nonlinear effects", eval(&g, &nle, &q, &v, &a, &params), x("nle"));
            check("gravity", eval(&g, &gravity, &q, &v, &a, &params), x("gravity"));
            check("crba", eval(&g, &crba, &q, &v, &a, &params), x("M"));
            if s.get("ddq").is_some() {
                check("aba", eval(&g, &aba, &q, &v, &x("tau_rand"), &params), x("ddq"));
                forward += 1;
            }
        }
        // Forward dynamics wherever the mass matrix is regular, and only there.
        let singular = model.warnings.iter().any(|w| w.kind == ErrorKind::SingularMassMatrix);
        assert_eq!(forward, if singular { 0 } else { samples.len() }, "{name}");
        println!("{name}: worst relative error against Pinocchio {worst:.1e}");
    }
}
