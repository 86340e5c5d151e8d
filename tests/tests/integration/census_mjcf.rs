//! The MJCF census (`tests/fixtures/census/mjcf/`, written with MuJoCo 4.0 by
//! `scripts/make_mjcf_census_fixtures.py`): the DeepMind control suite models of
//! dm_control (Apache-2.0), read with their `<include>`s. Each file either loads and
//! gives MuJoCo's dynamics — `M + diag(Ia)` is MuJoCo's `qM`, `M` is `qM` with the
//! armature zeroed and the bias forces are `qfrc_bias`, at three states, to 1e-10
//! normwise — or is refused (or known to differ) for the reason listed in
//! [`REFUSED`], so that a regression or an improvement shows.
//!
//! MuJoCo's coordinates are converted here to dyngen's, as `model/src/mjcf.rs`
//! documents and `scripts/make_mjcf_fixtures.py` does for `floating.xml`: quaternions
//! `w x y z` to `x y z w`; on a free joint with world orientation `R`, `v = T v_mj`
//! with `T = blkdiag(Rᵀ, I)`, `M = T⁻ᵀ M_mj T⁻¹` and `b = T⁻ᵀ b_mj + M [ω × Rᵀṗ; 0]`
//! (`M` without armature: `qfrc_bias` is the rigid bodies' alone).
//!
//! Also `equality.xml` (`scripts/make_mjcf_equality_fixtures.py`): joint couplings
//! read as mimic joints, against MuJoCo's dynamics reduced to the leaders'
//! coordinates.
//!
//! `cargo test -p dyngen-tests --test integration census_mjcf -- --nocapture` prints the table.

use dyngen_model::regressor::{inverse_dynamics, mass_matrix};
use dyngen_model::{load_mjcf, Model};
use dyngen_tests::{json_numbers, load_json, rel_err, workspace_root};
use serde_json::Value;

/// Agreement required with MuJoCo (normwise, relative).
const TOL: f64 = 1e-10;

/// Every model of the census, `tests/fixtures/census/mjcf/NAME.xml`.
const FILES: [&str; 19] = [
    "acrobot",
    "ball_in_cup",
    "cartpole",
    "cheetah",
    "dog",
    "finger",
    "fish",
    "hopper",
    "humanoid",
    "humanoid_CMU",
    "lqr",
    "manipulator",
    "pendulum",
    "point_mass",
    "quadruped",
    "reacher",
    "stacker",
    "swimmer",
    "walker",
];

/// Files refused, with a part of the (first) error's message.
const REFUSED: &[(&str, &str)] = &[
    // The dog's bones are meshes whose inertia MuJoCo computes from the STL files,
    // which are not copied here.
    (
        "dog",
        "line 166: robot: <mesh name=\"C_1\" file=\"BONEC_1.stl\">: cannot read `dog_assets/BONEC_1.stl`",
    ),
    // A template the Python task fills in: no body moves.
    ("lqr", "has no moving joint"),
];

/// The dyngen coordinates of MuJoCo's `qpos` and `qvel`, and the matrix `T⁻¹`
/// (`v_mj = T⁻¹ v`), row-major.
fn convert(model: &Model, types: &[&str], qpos: &[f64], qvel: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let nv = model.nv();
    let (mut q, mut v) = (qpos.to_vec(), qvel.to_vec());
    let mut t_inv = vec![0.0; nv * nv];
    for k in 0..nv {
        t_inv[k * nv + k] = 1.0;
    }
    for (j, kind) in types.iter().enumerate() {
        let (qa, da) = (model.q_offset(j + 1), model.v_offset(j + 1));
        match *kind {
            "ball" => q[qa..qa + 4].rotate_left(1),
            "free" => {
                q[qa + 3..qa + 7].rotate_left(1);
                let r = dyngen_model::regressor::quaternion_xyzw(&q[qa + 3..qa + 7]);
                for a in 0..3 {
                    v[da + a] = (0..3).map(|b| r[b][a] * qvel[da + b]).sum();
                    for b in 0..3 {
                        t_inv[(da + a) * nv + da + b] = r[a][b];
                    }
                }
            }
            _ => {}
        }
    }
    (q, v, t_inv)
}

/// `Aᵀ B A` for square row-major matrices.
fn congruence(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut ba = vec![0.0; n * n];
    for r in 0..n {
        for c in 0..n {
            ba[r * n + c] = (0..n).map(|k| b[r * n + k] * a[k * n + c]).sum();
        }
    }
    let mut out = vec![0.0; n * n];
    for r in 0..n {
        for c in 0..n {
            out[r * n + c] = (0..n).map(|k| a[k * n + r] * ba[k * n + c]).sum();
        }
    }
    out
}

/// The rigid mass matrix (row-major) and the bias `τ(q, v, 0)`.
fn dynamics(model: &Model, q: &[f64], v: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let zero = vec![0.0; model.nv()];
    (
        mass_matrix(model, q).unwrap().concat(),
        inverse_dynamics(model, q, v, &zero).unwrap(),
    )
}

/// One row of the table.
struct Row {
    name: &'static str,
    loads: bool,
    warnings: usize,
    /// Largest relative errors of `M` (rigid), `M + diag(Ia)` and the bias.
    errors: Option<[f64; 3]>,
    refusal: String,
}

fn compare(name: &'static str, model: &Model, reference: &Value) -> [f64; 3] {
    let nv = model.nv();
    assert_eq!(
        (model.nq() as u64, nv as u64),
        (reference["nq"].as_u64().unwrap(), reference["nv"].as_u64().unwrap()),
        "{name}: nq, nv"
    );
    let joints: Vec<String> = reference["joints"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .map(|(k, j)| j.as_str().map_or_else(|| format!("joint_{k}"), str::to_string))
        .collect();
    let ours: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(ours, joints, "{name}: joints");
    let types: Vec<&str> = reference["joint_types"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap())
        .collect();
    assert_eq!(
        model.gravity.to_vec(),
        json_numbers(&reference["gravity"]),
        "{name}: gravity"
    );
    let ia: Vec<f64> = dyngen_model::joint_params::nominal_joint_params(model)
        .chunks(4)
        .map(|p| p[0])
        .collect();
    assert_eq!(
        ia,
        json_numbers(&reference["armature"]),
        "{name}: Ia is MuJoCo's dof_armature"
    );
    let mut worst = [0.0f64; 3];
    for s in reference["samples"].as_array().unwrap() {
        let (q, v, t_inv) = convert(model, &types, &json_numbers(&s["qpos"]), &json_numbers(&s["qvel"]));
        let m_rigid_ref = congruence(&t_inv, &json_numbers(&s["M_rigid"]), nv);
        let m_ref = congruence(&t_inv, &json_numbers(&s["M"]), nv);
        // b = T⁻ᵀ b_mj + M [ω × Rᵀṗ; 0].
        let b_mj = json_numbers(&s["bias"]);
        let mut bias_ref: Vec<f64> = (0..nv)
            .map(|r| (0..nv).map(|k| t_inv[k * nv + r] * b_mj[k]).sum())
            .collect();
        let mut tdot = vec![0.0; nv];
        for (j, kind) in types.iter().enumerate() {
            if *kind == "free" {
                let da = model.v_offset(j + 1);
                let (l, w) = (&v[da..da + 3], &v[da + 3..da + 6]);
                tdot[da..da + 3].copy_from_slice(&[
                    w[1] * l[2] - w[2] * l[1],
                    w[2] * l[0] - w[0] * l[2],
                    w[0] * l[1] - w[1] * l[0],
                ]);
            }
        }
        for (r, b) in bias_ref.iter_mut().enumerate() {
            *b += (0..nv).map(|k| m_rigid_ref[r * nv + k] * tdot[k]).sum::<f64>();
        }
        let (m, bias) = dynamics(model, &q, &v);
        let with_rotors: Vec<f64> = (0..nv * nv)
            .map(|k| m[k] + if k / nv == k % nv { ia[k / nv] } else { 0.0 })
            .collect();
        let floor = 1e-12;
        worst[0] = worst[0].max(rel_err(&m, &m_rigid_ref, floor));
        worst[1] = worst[1].max(rel_err(&with_rotors, &m_ref, floor));
        worst[2] = worst[2].max(rel_err(&bias, &bias_ref, floor));
    }
    worst
}

#[test]
fn census_of_the_control_suite_is_mujocos() {
    let mut rows = Vec::new();
    for name in FILES {
        let path = workspace_root().join(format!("tests/fixtures/census/mjcf/{name}.xml"));
        let row = match load_mjcf(&path) {
            Ok(model) => {
                let reference = load_json(&format!("census/mjcf/{name}.json"));
                let errors = compare(name, &model, &reference);
                Row {
                    name,
                    loads: true,
                    warnings: model.warnings.len(),
                    errors: Some(errors),
                    refusal: String::new(),
                }
            }
            Err(e) => Row {
                name,
                loads: false,
                warnings: 0,
                errors: None,
                refusal: e.errors.first().map_or_else(String::new, |e| e.to_string()),
            },
        };
        rows.push(row);
    }
    println!("| file | loads | warnings | max rel. error M | max rel. error M + diag(Ia) | max rel. error bias |");
    println!("|---|---|---|---|---|---|");
    for r in &rows {
        match r.errors {
            Some([m, ma, b]) => println!(
                "| {}.xml | yes | {} | {m:.1e} | {ma:.1e} | {b:.1e} |",
                r.name, r.warnings
            ),
            None => println!("| {}.xml | no: {} | | | | |", r.name, r.refusal),
        }
    }
    for r in &rows {
        let listed = REFUSED.iter().find(|(n, _)| *n == r.name);
        match (r.errors, listed) {
            (Some(errors), None) => {
                assert!(errors.iter().all(|&e| e <= TOL), "{}: {errors:?}", r.name)
            }
            (Some(_), Some(_)) => panic!("{} loads now: take it out of REFUSED", r.name),
            (None, Some((_, why))) => assert!(r.refusal.contains(why), "{}: {}", r.name, r.refusal),
            (None, None) => panic!("{} is refused: {}", r.name, r.refusal),
        }
        assert_eq!(r.loads, r.errors.is_some());
    }
}

/// `<equality><joint>` couplings (`tests/fixtures/mjcf/equality.xml`, written with
/// MuJoCo 4.0 by `scripts/make_mjcf_equality_fixtures.py`): the linear ones are mimic
/// joints whose multiplier and offset are MuJoCo's rule (`q1 - ref1 = c0 + c1 (q2 -
/// ref2)`), and the run-time algorithms on the reduced coordinates give MuJoCo's
/// dynamics reduced by `E` — `crba + diag(Ia)` is `Eᵀ qM E` (`Ia` the nominal
/// armature, each follower's `k² Ia` folded into its leader), `crba` is the same
/// without armature and `rnea(q, v, 0)` is `Eᵀ qfrc_bias` — to 1e-12 relative; the
/// nonlinear coupling is left out with a warning on its line.
#[test]
fn joint_couplings_are_mimic_joints_with_mujocos_reduced_dynamics() {
    use dyngen_algo::Workspace;
    let model = load_mjcf(&workspace_root().join("tests/fixtures/mjcf/equality.xml")).unwrap();
    let reference = load_json("mjcf/equality.json");
    let names = |v: &Value| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_str().unwrap().to_string())
            .collect()
    };
    let ours: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    assert_eq!(ours, names(&reference["joints"]));
    let nv = model.nv();
    assert_eq!(nv, names(&reference["reduced"]).len());
    assert_eq!(model.gravity.to_vec(), json_numbers(&reference["gravity"]));
    // Followers: MuJoCo's leader, multiplier and offset.
    let followers = reference["followers"].as_array().unwrap();
    assert_eq!(
        model.joints.iter().filter(|j| j.mimic.is_some()).count(),
        followers.len()
    );
    for f in followers {
        let joint = model
            .joints
            .iter()
            .find(|j| j.name == f["joint"].as_str().unwrap())
            .unwrap();
        let m = joint.mimic.unwrap_or_else(|| panic!("{} follows no joint", joint.name));
        assert_eq!(model.joints[m.leader - 1].name, f["leader"].as_str().unwrap());
        let (k, b) = (f["multiplier"].as_f64().unwrap(), f["offset"].as_f64().unwrap());
        assert!(
            (m.multiplier - k).abs() <= 1e-15,
            "{}: {} vs {k}",
            joint.name,
            m.multiplier
        );
        assert!((m.offset - b).abs() <= 1e-15, "{}: {} vs {b}", joint.name, m.offset);
    }
    // The nonlinear coupling, and nothing else, is warned about.
    let warnings: Vec<String> = model.warnings.iter().map(|w| w.warning_message()).collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0]
            .starts_with("line 45: robot: <equality> <joint name=\"bend\"> is left out: its polycoef has c2 = 0.2"),
        "{warnings:?}"
    );
    let ia: Vec<f64> = dyngen_model::joint_params::nominal_joint_params(&model)
        .chunks(4)
        .map(|p| p[0])
        .collect();
    assert!(
        rel_err(&ia, &json_numbers(&reference["armature"]), 1e-12) <= 1e-15,
        "{ia:?}"
    );
    let body = model.multibody().unwrap();
    let mut ws = Workspace::new(&body, ());
    let params = model.standard_params();
    let mut worst = [0.0f64; 3];
    for s in reference["samples"].as_array().unwrap() {
        let (q, v) = (json_numbers(&s["q"]), json_numbers(&s["v"]));
        let mut m = vec![0.0; nv * nv];
        dyngen_algo::crba(&body, &mut ws, &q, &params, &mut m);
        let mut bias = vec![0.0; nv];
        dyngen_algo::rnea(&body, &mut ws, &q, &v, &vec![0.0; nv], &params, &mut bias);
        let with_rotors: Vec<f64> = (0..nv * nv)
            .map(|k| m[k] + if k / nv == k % nv { ia[k / nv] } else { 0.0 })
            .collect();
        worst[0] = worst[0].max(rel_err(&m, &json_numbers(&s["M_rigid"]), 1e-12));
        worst[1] = worst[1].max(rel_err(&with_rotors, &json_numbers(&s["M"]), 1e-12));
        worst[2] = worst[2].max(rel_err(&bias, &json_numbers(&s["bias"]), 1e-12));
    }
    // Generated code takes the followers (as the URDF ones, checked against Pinocchio
    // in `census.rs`): the rule is in the generated model, and `aba` solves densely.
    let code = dyngen_codegen::Config::new()
        .functions(dyngen_codegen::Selection::parse("aba").unwrap())
        .generate_file(&model, "Equality", "equality.xml")
        .unwrap();
    assert!(
        code.contains("JointMimic {"),
        "the coupling is lost from the generated model"
    );
    assert!(
        code.contains("tree_ldl_solve(&ANCESTORS"),
        "aba does not solve M densely"
    );
    println!(
        "equality.xml: max rel. error M {:.1e}, M + diag(Ia) {:.1e}, bias {:.1e}",
        worst[0], worst[1], worst[2]
    );
    assert!(worst.iter().all(|&e| e <= 1e-12), "{worst:?}");
}
