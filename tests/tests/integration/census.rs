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

/// Mimic joints (`tests/fixtures/mimic/`, `scripts/make_mimic_fixtures.py`): fixture name,
/// URDF, on a free flyer.
const MIMIC: [(&str, &str, bool); 3] = [
    ("arm_linkage_gripper", "arm_linkage_gripper", false),
    ("mimic_probe", "mimic_probe", false),
    ("mimic_probe_free_flyer", "mimic_probe", true),
];

/// The run-time algorithms on a model with mimic joints against Pinocchio 4.1's mimic
/// support (rnea, nonlinear effects, gravity, crba, frames and their Jacobians, centre
/// of mass, its Jacobian, `A_g`), and against Pinocchio's tree without followers
/// reduced with `E` for what Pinocchio does not run on mimic joints (regressor, rnea
/// derivatives); forward dynamics and its derivatives by their identities with those.
#[test]
fn mimic_joints_match_pinocchio() {
    use dyngen_algo::{ReferenceFrame, Workspace};
    let mut worst = dyngen_tests::Worst::new(|_| 1e-12);
    for (fixture, urdf, free_flyer) in MIMIC {
        let json = load_json(&format!("mimic/{fixture}.json"));
        let path = workspace_root().join(format!("tests/fixtures/mimic/{urdf}.urdf"));
        let options = LoadOptions {
            free_flyer,
            ..LoadOptions::default()
        };
        let model = load_urdf_options(&path, options).unwrap_or_else(|e| panic!("{e}"));
        assert!(model.warnings.is_empty(), "{fixture}: {:#?}", model.warnings);
        let (nq, nv) = (model.nq(), model.nv());
        assert_eq!(
            (nq, nv),
            (
                json["nq"].as_u64().unwrap() as usize,
                json["nv"].as_u64().unwrap() as usize
            )
        );
        let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        let tree: Vec<&str> = json["tree_joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_str().unwrap())
            .collect();
        assert_eq!(
            names[usize::from(free_flyer)..],
            tree[usize::from(free_flyer)..],
            "{fixture}"
        );
        let followers: Vec<&str> = model
            .joints
            .iter()
            .filter(|j| j.mimic.is_some())
            .map(|j| j.name.as_str())
            .collect();
        let mimic: Vec<&str> = json["mimic_joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_str().unwrap())
            .collect();
        let mut sorted = mimic.clone();
        sorted.sort();
        let mut ours = followers.clone();
        ours.sort();
        assert_eq!(ours, sorted, "{fixture}");
        let params = model.standard_params();
        worst.add("params", fixture, 0, &params, &json_numbers(&json["params"]), 1.0);
        let body = model.multibody().unwrap();
        let mut ws = Workspace::new(&body, ());
        let mut dual = dyngen_algo::DualWorkspace::<f64, 8>::new(&body, ());
        for (s, sample) in json["samples"].as_array().unwrap().iter().enumerate() {
            let [q, v, a] = ["q", "v", "a"].map(|k| json_numbers(&sample[k]));
            let zero = vec![0.0; nv];
            let mut out = vec![0.0; nv];
            let check = |what, got: &[f64], key: &str, w: &mut dyngen_tests::Worst| {
                w.add(what, fixture, s, got, &json_numbers(&sample[key]), 1.0)
            };
            dyngen_algo::rnea(&body, &mut ws, &q, &v, &a, &params, &mut out);
            check("rnea", &out, "tau", &mut worst);
            dyngen_algo::rnea(&body, &mut ws, &q, &v, &zero, &params, &mut out);
            check("nle", &out, "nle", &mut worst);
            dyngen_algo::rnea(&body, &mut ws, &q, &zero, &zero, &params, &mut out);
            check("gravity", &out, "gravity", &mut worst);
            let mut m = vec![0.0; nv * nv];
            dyngen_algo::crba(&body, &mut ws, &q, &params, &mut m);
            check("crba", &m, "M", &mut worst);
            let com = dyngen_algo::center_of_mass(&body, &mut ws, &q, &params);
            check("com", &com, "com", &mut worst);
            let mut jcom = vec![0.0; 3 * nv];
            dyngen_algo::com_jacobian(&body, &mut ws, &q, &params, &mut jcom);
            check("com_jacobian", &jcom, "com_jacobian", &mut worst);
            let mut ag = vec![0.0; 6 * nv];
            dyngen_algo::centroidal_map(&body, &mut ws, &q, &params, &mut ag);
            check("centroidal_map", &ag, "centroidal_map", &mut worst);
            for (name, want) in sample["frames"].as_object().unwrap() {
                let frame = &model.frames[model.frame_index(name).unwrap()];
                let offset = dyngen_algo::Se3 {
                    rotation: frame.placement.rotation,
                    translation: frame.placement.translation,
                };
                dyngen_algo::forward_kinematics(&body, &mut ws, &q);
                let placed = ws.world[frame.body].compose(&offset);
                let got: Vec<f64> = placed
                    .rotation
                    .iter()
                    .flatten()
                    .chain(&placed.translation)
                    .copied()
                    .collect();
                worst.add("frame placement", fixture, s, &got, &json_numbers(want), 1.0);
                let mut j = vec![0.0; 6 * nv];
                let lwa = ReferenceFrame::LocalWorldAligned;
                dyngen_algo::compute_frame_jacobian(&body, &mut ws, &q, frame.body, &offset, lwa, &mut j);
                worst.add("frame jacobian", fixture, s, &j, &json_numbers(&want["jacobian"]), 1.0);
            }
            let mut y = vec![0.0; nv * params.len()];
            dyngen_algo::joint_torque_regressor(&body, &mut ws, &q, &v, &a, &mut y);
            check("regressor", &y, "regressor", &mut worst);
            let (mut dq, mut dv, mut da) = (vec![0.0; nv * nv], vec![0.0; nv * nv], vec![0.0; nv * nv]);
            dyngen_algo::rnea_derivatives(
                &body, &mut dual, &mut ws, &q, &v, &a, &params, &mut dq, &mut dv, &mut da,
            );
            check("dtau_dq", &dq, "dtau_dq", &mut worst);
            check("dtau_dv", &dv, "dtau_dv", &mut worst);
            check("dtau_da", &da, "M", &mut worst);
            // Forward dynamics: aba(q, v, rnea(q, v, a)) = a; its derivatives by
            // M ∂q̈/∂x = −∂τ/∂x and M M⁻¹ = E, with Pinocchio's M and ∂τ/∂x.
            let tau = json_numbers(&sample["tau"]);
            dyngen_algo::aba(&body, &mut ws, &q, &v, &tau, &params, &[], &mut out);
            worst.add("aba", fixture, s, &out, &a, 1.0);
            let (mut ddq_dq, mut ddq_dv, mut minv) = (vec![0.0; nv * nv], vec![0.0; nv * nv], vec![0.0; nv * nv]);
            let mut ddq = vec![0.0; nv];
            dyngen_algo::aba_derivatives(
                &body,
                &mut dual,
                &mut ws,
                &q,
                &v,
                &tau,
                &params,
                &[],
                &mut ddq,
                &mut ddq_dq,
                &mut ddq_dv,
                &mut minv,
            );
            let mj = json_numbers(&sample["M"]);
            let times = |x: &[f64]| -> Vec<f64> {
                (0..nv * nv)
                    .map(|rc| (0..nv).map(|k| mj[rc / nv * nv + k] * x[k * nv + rc % nv]).sum())
                    .collect()
            };
            let identity: Vec<f64> = (0..nv * nv).map(|rc| f64::from(u8::from(rc / nv == rc % nv))).collect();
            worst.add("M minv", fixture, s, &times(&minv), &identity, 1.0);
            let neg = |k: &str| json_numbers(&sample[k]).iter().map(|x| -x).collect::<Vec<_>>();
            worst.add("M ddq_dq", fixture, s, &times(&ddq_dq), &neg("dtau_dq"), 1.0);
            worst.add("M ddq_dv", fixture, s, &times(&ddq_dv), &neg("dtau_dv"), 1.0);
        }
    }
    println!(
        "mimic joints against Pinocchio, worst relative errors: {:#?}",
        worst.items
    );
}

/// What Pinocchio does not take and dyngen does (a follower numbered before its
/// leader and upstream of it, a follower of a follower, a continuous follower): the
/// algorithms with followers equal the tree without them at `q_tree = E q + b`, reduced
/// (`τ = Eᵀ τ_tree`, `M = Eᵀ M_tree E`, `Y = Eᵀ Y_tree`, `J = J_tree E`).
#[test]
fn mimic_joints_reduce_the_tree() {
    use dyngen_algo::Workspace;
    let text = std::fs::read_to_string(workspace_root().join("tests/fixtures/mimic/mimic_probe.urdf")).unwrap();
    // a_joint follows c_joint, below it; e_joint follows d_joint, itself a follower;
    // f_joint, continuous, follows b_joint.
    let text = text
        .replace(
            r#"<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="5"/></joint>"#,
            r#"<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="5"/><mimic joint="c_joint" multiplier="0.5" offset="0.1"/></joint>"#,
        )
        .replacen(r#"<mimic joint="b_joint" multiplier="-0.2" offset="-0.22"/>"#, r#"<mimic joint="d_joint" multiplier="4" offset="-0.3"/>"#, 1)
        .replacen(r#"type="revolute"><parent link="c"/>"#, r#"type="continuous"><parent link="c"/>"#, 1);
    let model = dyngen_model::parse_urdf(&text).unwrap();
    let follower = |n: &str| model.joints.iter().find(|j| j.name == n).unwrap().mimic.unwrap();
    assert_eq!(follower("a_joint").leader, 3, "{:?}", model.joints);
    assert_eq!(model.joints[follower("e_joint").leader - 1].name, "b_joint");
    let f = model.joints.iter().find(|j| j.name == "f_joint").unwrap();
    assert_eq!(f.kind, dyngen_model::JointKind::Continuous);
    let mut tree = model.clone();
    tree.joints.iter_mut().for_each(|j| j.mimic = None);
    let (n, nv, nt) = (model.dof(), model.nv(), tree.nv());
    // E and b from the model's followers.
    let mut e = vec![vec![0.0; nv]; nt];
    let mut b = vec![0.0; nt];
    for (k, j) in model.joints.iter().enumerate() {
        match j.mimic {
            None => e[k][model.v_offset(k + 1)] = 1.0,
            Some(m) => {
                e[k][model.v_offset(m.leader)] = m.multiplier;
                b[k] = m.offset;
            }
        }
    }
    assert_eq!((n, nv), (7, 2));
    let (body, whole) = (model.multibody().unwrap(), tree.multibody().unwrap());
    let (mut ws, mut wt) = (Workspace::new(&body, ()), Workspace::new(&whole, ()));
    let params = model.standard_params();
    let np = params.len();
    for s in 0..4 {
        let x = |k: usize| ((s * 7 + k * 3) as f64 * 0.37).sin();
        let (q, v, a): (Vec<f64>, Vec<f64>, Vec<f64>) = (
            (0..nv).map(x).collect(),
            (0..nv).map(|k| x(k + 5)).collect(),
            (0..nv).map(|k| x(k + 9)).collect(),
        );
        let expand = |y: &[f64], offset: bool| -> Vec<f64> {
            (0..nt)
                .map(|d| (0..nv).map(|k| e[d][k] * y[k]).sum::<f64>() + if offset { b[d] } else { 0.0 })
                .collect()
        };
        let (qt, vt, at) = (expand(&q, true), expand(&v, false), expand(&a, false));
        // Eᵀ x for x of nt rows and `cols` columns.
        let reduce = |x: &[f64], cols: usize| -> Vec<f64> {
            (0..nv * cols)
                .map(|rc| (0..nt).map(|d| e[d][rc / cols] * x[d * cols + rc % cols]).sum())
                .collect()
        };
        let (mut tau, mut tau_t) = (vec![0.0; nv], vec![0.0; nt]);
        dyngen_algo::rnea(&body, &mut ws, &q, &v, &a, &params, &mut tau);
        dyngen_algo::rnea(&whole, &mut wt, &qt, &vt, &at, &params, &mut tau_t);
        assert!(rel_err(&tau, &reduce(&tau_t, 1), 1.0) < 1e-14, "sample {s}");
        let (mut m, mut m_t) = (vec![0.0; nv * nv], vec![0.0; nt * nt]);
        dyngen_algo::crba(&body, &mut ws, &q, &params, &mut m);
        dyngen_algo::crba(&whole, &mut wt, &qt, &params, &mut m_t);
        // Eᵀ M_tree E: rows reduced, then columns (M_tree symmetric).
        let half = reduce(&m_t, nt);
        let mt_e: Vec<f64> = (0..nv * nv)
            .map(|rc| (0..nt).map(|d| half[rc / nv * nt + d] * e[d][rc % nv]).sum())
            .collect();
        assert!(rel_err(&m, &mt_e, 1.0) < 1e-14, "sample {s}");
        let (mut y, mut y_t) = (vec![0.0; nv * np], vec![0.0; nt * np]);
        dyngen_algo::joint_torque_regressor(&body, &mut ws, &q, &v, &a, &mut y);
        dyngen_algo::joint_torque_regressor(&whole, &mut wt, &qt, &vt, &at, &mut y_t);
        assert!(rel_err(&y, &reduce(&y_t, np), 1.0) < 1e-14, "sample {s}");
        let frame = dyngen_algo::Se3::identity(0.0, 1.0);
        let (mut j, mut j_t) = (vec![0.0; 6 * nv], vec![0.0; 6 * nt]);
        let world = dyngen_algo::ReferenceFrame::World;
        dyngen_algo::compute_frame_jacobian(&body, &mut ws, &q, n, &frame, world, &mut j);
        dyngen_algo::compute_frame_jacobian(&whole, &mut wt, &qt, n, &frame, world, &mut j_t);
        let j_e: Vec<f64> = (0..6 * nv)
            .map(|rc| (0..nt).map(|d| j_t[rc / nv * nt + d] * e[d][rc % nv]).sum())
            .collect();
        assert!(rel_err(&j, &j_e, 1.0) < 1e-14, "sample {s}");
        // J̇ = J̇_tree E, along v_tree = E v.
        let (mut ds, mut dt) = (
            dyngen_algo::DualWorkspace::<f64, 1>::new(&body, ()),
            dyngen_algo::DualWorkspace::<f64, 1>::new(&whole, ()),
        );
        let (mut jd, mut jd_t) = (vec![0.0; 6 * nv], vec![0.0; 6 * nt]);
        dyngen_algo::frame_jacobian_time_variation(&body, &mut ds, &q, &v, n, &frame, world, &mut j, &mut jd);
        dyngen_algo::frame_jacobian_time_variation(&whole, &mut dt, &qt, &vt, n, &frame, world, &mut j_t, &mut jd_t);
        let jd_e: Vec<f64> = (0..6 * nv)
            .map(|rc| (0..nt).map(|d| jd_t[rc / nv * nt + d] * e[d][rc % nv]).sum())
            .collect();
        assert!(rel_err(&jd, &jd_e, 1.0) < 1e-14, "sample {s}");
        // Forward dynamics undoes inverse dynamics.
        let mut ddq = vec![0.0; nv];
        dyngen_algo::aba(&body, &mut ws, &q, &v, &tau, &params, &[], &mut ddq);
        assert!(rel_err(&ddq, &a, 1.0) < 1e-12, "sample {s}: {ddq:?} {a:?}");
    }
}

/// Generated code for a robot with mimic joints (`dyngen_tests::mimic`, generated in
/// `build.rs`; the linkage gripper's code is the same mechanism with multipliers ±1,
/// left out to keep the test build small): against Pinocchio 4.1's mimic model on its fixtures (rnea, nonlinear
/// effects, gravity, `M`, centre of mass, its Jacobian, `A_g`, frame Jacobians, and the
/// regressor and rnea derivatives of the reduced tree), against the run-time algorithms
/// (`Multibody::with_mimics`) for what the fixtures do not hold (`J̇`, `Ȧ_g`,
/// body poses), and by identities for the rest: `aba` and `aba_joints` invert `rnea` and
/// `rnea_joints`, `M⁻¹ M = E`, `M ∂q̈/∂x = −∂τ/∂x`, the frame motion is `J v` and
/// `J a + J̇ v`, the base, principal, joint-wrench and per-body regressors reproduce what
/// their parameters give.
#[test]
fn generated_mimic_robots_match_pinocchio() {
    let mut worst = dyngen_tests::Worst::new(|_| 1e-12);
    generated_mimic::<dyngen_tests::mimic::MimicProbeFloating>("mimic_probe_free_flyer", &mut worst);
    println!("generated mimic robot, worst relative errors: {:#?}", worst.items);
}

fn generated_mimic<R: dyngen::Robot>(fixture: &str, worst: &mut dyngen_tests::Worst) {
    use dyngen::{BodyRegressor, ReferenceFrame, Wrench};
    use dyngen_algo::{DualWorkspace, Workspace};
    let json = load_json(&format!("mimic/{fixture}.json"));
    let (nq, nv, np) = (R::NQ, R::NV, R::NPARAMS);
    assert_eq!(
        (nq, nv),
        (
            json["nq"].as_u64().unwrap() as usize,
            json["nv"].as_u64().unwrap() as usize
        )
    );
    let model = dyngen_reference::model_from_static(&R::MODEL);
    assert!(
        model.mimic_joint().is_some(),
        "{fixture}: the generated model lost its followers"
    );
    let params = R::nominal_params();
    worst.add("params", fixture, 0, params, &json_numbers(&json["params"]), 1.0);
    let body = model.multibody().unwrap();
    let mut ws = Workspace::new(&body, ());
    let mut dual = DualWorkspace::<f64, 1>::new(&body, ());
    let times = |y: &[f64], x: &[f64]| -> Vec<f64> {
        y.chunks(x.len())
            .map(|r| r.iter().zip(x).map(|(a, b)| a * b).sum())
            .collect()
    };
    let product = |a: &[f64], b: &[f64]| -> Vec<f64> {
        (0..nv * nv)
            .map(|rc| (0..nv).map(|k| a[rc / nv * nv + k] * b[k * nv + rc % nv]).sum())
            .collect()
    };
    let identity: Vec<f64> = (0..nv * nv).map(|rc| f64::from(u8::from(rc / nv == rc % nv))).collect();
    for (s, sample) in json["samples"].as_array().unwrap().iter().enumerate() {
        let [q, v, a] = ["q", "v", "a"].map(|k| json_numbers(&sample[k]));
        let want = |key: &str| json_numbers(&sample[key]);
        let mut tau = vec![0.0; nv];
        R::rnea(&q, &v, &a, params, &mut tau);
        worst.add("rnea", fixture, s, &tau, &want("tau"), 1.0);
        let mut out = vec![0.0; nv];
        R::nonlinear_effects(&q, &v, params, &mut out);
        worst.add("nle", fixture, s, &out, &want("nle"), 1.0);
        R::generalized_gravity(&q, params, &mut out);
        worst.add("gravity", fixture, s, &out, &want("gravity"), 1.0);
        let mut m = vec![0.0; nv * nv];
        R::crba(&q, params, &mut m);
        worst.add("crba", fixture, s, &m, &want("M"), 1.0);
        worst.add("com", fixture, s, &R::center_of_mass(&q, params), &want("com"), 1.0);
        let mut jcom = vec![0.0; 3 * nv];
        R::com_jacobian(&q, params, &mut jcom);
        worst.add("com_jacobian", fixture, s, &jcom, &want("com_jacobian"), 1.0);
        let (mut ag, mut ag_dot) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
        R::centroidal_map(&q, params, &mut ag);
        worst.add("centroidal_map", fixture, s, &ag, &want("centroidal_map"), 1.0);
        R::centroidal_map_time_variation(&q, &v, params, &mut ag, &mut ag_dot);
        let (mut ag_rt, mut ag_dot_rt) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
        dyngen_algo::centroidal_map_time_variation(&body, &mut dual, &q, &v, params, &mut ag_rt, &mut ag_dot_rt);
        worst.add("centroidal_map_time_variation", fixture, s, &ag_dot, &ag_dot_rt, 1.0);
        for (name, frame_want) in sample["frames"].as_object().unwrap() {
            let f = R::MODEL.frame_index(name).unwrap();
            let lwa = ReferenceFrame::LocalWorldAligned;
            let (mut j, mut j_dot) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
            R::frame_jacobian(&q, f, lwa, &mut j).unwrap();
            worst.add(
                "frame jacobian",
                fixture,
                s,
                &j,
                &json_numbers(&frame_want["jacobian"]),
                1.0,
            );
            R::frame_jacobian_time_variation(&q, &v, f, lwa, &mut j, &mut j_dot).unwrap();
            let frame = &model.frames[f];
            let offset = dyngen_algo::Se3 {
                rotation: frame.placement.rotation,
                translation: frame.placement.translation,
            };
            let (mut j_rt, mut j_dot_rt) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
            dyngen_algo::frame_jacobian_time_variation(
                &body,
                &mut dual,
                &q,
                &v,
                frame.body,
                &offset,
                dyngen_algo::ReferenceFrame::LocalWorldAligned,
                &mut j_rt,
                &mut j_dot_rt,
            );
            worst.add("frame jacobian time variation", fixture, s, &j_dot, &j_dot_rt, 1.0);
            let motion = R::frame_motion(&q, &v, &a, f).unwrap();
            let got: Vec<f64> = motion
                .velocity
                .linear
                .iter()
                .chain(motion.velocity.angular.iter())
                .copied()
                .collect();
            worst.add("frame velocity", fixture, s, &got, &times(&j, &v), 1.0);
            let got: Vec<f64> = motion
                .acceleration
                .linear
                .iter()
                .chain(motion.acceleration.angular.iter())
                .copied()
                .collect();
            let classical: Vec<f64> = times(&j, &a)
                .iter()
                .zip(times(&j_dot, &v))
                .map(|(x, y)| x + y)
                .collect();
            worst.add("frame classical acceleration", fixture, s, &got, &classical, 1.0);
        }
        let mut poses = vec![dyngen::Pose::default(); R::NBODIES];
        R::forward_kinematics(&q, &mut poses);
        dyngen_algo::forward_kinematics(&body, &mut ws, &q);
        for (b, pose) in poses.iter().enumerate() {
            let world = &ws.world[b + 1];
            let want: Vec<f64> = world
                .rotation
                .iter()
                .flatten()
                .chain(&world.translation)
                .copied()
                .collect();
            worst.add(
                "forward kinematics",
                fixture,
                s,
                &dyngen_tests::pose_vec(pose),
                &want,
                1.0,
            );
        }
        let mut y = vec![0.0; nv * np];
        R::joint_torque_regressor(&q, &v, &a, &mut y);
        worst.add("regressor", fixture, s, &y, &want("regressor"), 1.0);
        let (mut dq, mut dv, mut da) = (vec![0.0; nv * nv], vec![0.0; nv * nv], vec![0.0; nv * nv]);
        R::rnea_derivatives(&q, &v, &a, params, &mut dq, &mut dv, &mut da);
        worst.add("dtau_dq", fixture, s, &dq, &want("dtau_dq"), 1.0);
        worst.add("dtau_dv", fixture, s, &dv, &want("dtau_dv"), 1.0);
        worst.add("dtau_da", fixture, s, &da, &want("M"), 1.0);
        // Forward dynamics and its derivatives, by their identities.
        let pin_tau = want("tau");
        R::aba(&q, &v, &pin_tau, params, &mut out);
        worst.add("aba", fixture, s, &out, &a, 1.0);
        let (mut ddq, mut ddq_dq, mut ddq_dv, mut minv) = (
            vec![0.0; nv],
            vec![0.0; nv * nv],
            vec![0.0; nv * nv],
            vec![0.0; nv * nv],
        );
        R::aba_derivatives(&q, &v, &pin_tau, params, &mut ddq, &mut ddq_dq, &mut ddq_dv, &mut minv);
        worst.add("aba_derivatives ddq", fixture, s, &ddq, &a, 1.0);
        let pin_m = want("M");
        worst.add("M minv", fixture, s, &product(&pin_m, &minv), &identity, 1.0);
        let neg = |k: &str| want(k).iter().map(|x| -x).collect::<Vec<_>>();
        worst.add("M ddq_dq", fixture, s, &product(&pin_m, &ddq_dq), &neg("dtau_dq"), 1.0);
        worst.add("M ddq_dv", fixture, s, &product(&pin_m, &ddq_dv), &neg("dtau_dv"), 1.0);
        R::inverse_inertia(&q, params, &mut minv);
        worst.add("inverse_inertia", fixture, s, &product(&pin_m, &minv), &identity, 1.0);
        // The joint models: aba_joints inverts rnea_joints, the widened regressor
        // reproduces it.
        let joint_params: Vec<f64> = (0..nv).flat_map(|d| [0.01 * (d + 1) as f64, 0.2, 0.3, -0.05]).collect();
        let coulomb = dyngen::Coulomb::smooth(0.05).unwrap();
        let mut tau_j = vec![0.0; nv];
        R::rnea_joints(&q, &v, &a, params, &joint_params, coulomb, &mut tau_j);
        R::aba_joints(&q, &v, &tau_j, params, &joint_params, coulomb, &mut out);
        worst.add("aba_joints", fixture, s, &out, &a, 1.0);
        let mut yj = vec![0.0; nv * (np + 4 * nv)];
        R::torque_regressor_joints(&q, &v, &a, coulomb, &mut yj);
        let x: Vec<f64> = params.iter().chain(&joint_params).copied().collect();
        worst.add("torque_regressor_joints", fixture, s, &times(&yj, &x), &tau_j, 1.0);
        // The other regressors against what their parameters give.
        let (mut beta, mut beta_p) = (vec![0.0; R::NBASE], vec![0.0; R::NBASE_PRINCIPAL]);
        R::base_params(params, &mut beta);
        R::principal_base_params(R::nominal_theta(), &mut beta_p);
        let mut yb = vec![0.0; nv * R::NBASE];
        R::base_regressor(&q, &v, &a, &mut yb);
        worst.add("base_regressor", fixture, s, &times(&yb, &beta), &tau, 1.0);
        let mut yp = vec![0.0; nv * R::NTHETA];
        R::principal_regressor(&q, &v, &a, &mut yp);
        worst.add(
            "principal_regressor",
            fixture,
            s,
            &times(&yp, R::nominal_theta()),
            &tau,
            1.0,
        );
        let mut ypb = vec![0.0; nv * R::NBASE_PRINCIPAL];
        R::principal_base_regressor(&q, &v, &a, &mut ypb);
        worst.add("principal_base_regressor", fixture, s, &times(&ypb, &beta_p), &tau, 1.0);
        let mut wrenches = vec![Wrench::default(); R::NBODIES];
        R::joint_wrenches(&q, &v, &a, params, &mut wrenches);
        let wrenches: Vec<f64> = wrenches.iter().flat_map(dyngen_tests::wrench_vec).collect();
        let mut yw = vec![0.0; 6 * R::NBODIES * np];
        R::joint_wrench_regressor(&q, &v, &a, &mut yw);
        worst.add(
            "joint_wrench_regressor",
            fixture,
            s,
            &times(&yw, params),
            &wrenches,
            1.0,
        );
        let (mut bodies, mut resultants) = (
            vec![BodyRegressor::default(); R::NBODIES],
            vec![Wrench::default(); R::NBODIES],
        );
        R::body_regressors(&q, &v, &a, &mut bodies);
        R::body_resultants(&q, &v, &a, params, &mut resultants);
        for (i, (ai, ri)) in bodies.iter().zip(&resultants).enumerate() {
            let theta = nalgebra::Vector4::from_column_slice(&R::nominal_theta()[4 * i..4 * i + 4]);
            let got: Vec<f64> = (ai.force * theta)
                .iter()
                .chain((ai.moment * theta).iter())
                .copied()
                .collect();
            worst.add("body_regressors", fixture, s, &got, &dyngen_tests::wrench_vec(ri), 1.0);
        }
    }
}
