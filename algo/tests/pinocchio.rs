//! The algorithms on `f64`, on every robot description with Pinocchio 4.1 fixtures
//! (fixed bases, free flyers, planar joints; `tests/fixtures/`, made by the
//! `scripts/make_*fixtures.py` scripts): the URDF loaded at run time, then rnea, the
//! joint wrenches, nonlinear effects, gravity, crba, aba, the body placements and
//! frame Jacobians against Pinocchio's numbers.

use dyngen_algo::{
    aba, crba, forward_kinematics, frame_jacobian, joint_torque_regressor, joint_wrench_regressor, rnea, Multibody,
    ReferenceFrame, Se3, Workspace,
};
use dyngen_model::{load_urdf_options, LoadOptions, Model};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Agreement required with Pinocchio: normwise, relative to the largest entry (at
/// least 1).
const TOL: f64 = 1e-12;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn nums(v: &Value) -> Vec<f64> {
    match v {
        Value::Number(x) => vec![x.as_f64().unwrap()],
        Value::Array(xs) => xs.iter().flat_map(nums).collect(),
        Value::Object(o) => nums(&o["rotation"])
            .into_iter()
            .chain(nums(&o["translation"]))
            .collect(),
        _ => panic!("not a number, a list or a placement: {v}"),
    }
}

fn rel_err(x: &[f64], y: &[f64]) -> f64 {
    assert_eq!(x.len(), y.len());
    let diff = x.iter().zip(y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    diff / y.iter().map(|b| b.abs()).fold(1.0, f64::max)
}

fn pose(p: &Se3<f64>) -> Vec<f64> {
    p.rotation.iter().flatten().chain(&p.translation).copied().collect()
}

/// Every fixture with a URDF and Pinocchio samples.
const FIXTURES: [&str; 17] = [
    "ur5",
    "panda",
    "puma560",
    "paper6",
    "planar2",
    "tree12",
    "gripper_arm",
    "corpus/hand20",
    "corpus/quadruped12",
    "corpus/humanoid31",
    "floating/quadruped12",
    "floating/humanoid31",
    "floating/mobile_arm",
    "census/arm_gripper",
    "census/dummy_root_quadruped",
    "census/quadrotor",
    "census/massless_tip",
];

struct Loaded {
    model: Model,
    body: Multibody,
    fixture: Value,
}

fn load(name: &str) -> Loaded {
    let path = root().join("tests/fixtures").join(format!("{name}.json"));
    let fixture: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let options = LoadOptions {
        free_flyer: fixture["root_joint"].as_str() == Some("freeflyer"),
        ..LoadOptions::default()
    };
    let model = load_urdf_options(&root().join(fixture["urdf"].as_str().unwrap()), options).unwrap();
    let mut body = model.multibody().unwrap();
    // A fixture made with another gravity than the description's default says so.
    if let Some(g) = fixture.get("gravity") {
        body.gravity.copy_from_slice(&nums(g));
    }
    Loaded { model, body, fixture }
}

/// The largest error of each quantity on one fixture.
#[derive(Default)]
struct Worst(Vec<(&'static str, f64)>);

impl Worst {
    fn add(&mut self, what: &'static str, ours: &[f64], theirs: &[f64]) {
        let e = rel_err(ours, theirs);
        match self.0.iter_mut().find(|(w, _)| *w == what) {
            Some((_, x)) => *x = x.max(e),
            None => self.0.push((what, e)),
        }
    }
}

fn check(name: &str) -> Worst {
    let Loaded { model, body, fixture } = load(name);
    let (nv, nb) = (body.nv(), body.bodies());
    let params = body.params.clone();
    let mut ws = Workspace::new(&body, ());
    let mut worst = Worst::default();
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let theirs = &fixture["model"];
    let their_names = theirs.get("joints").or(theirs.get("joint_names")).unwrap();
    let their_names: Vec<&str> = their_names
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert_eq!(names, their_names, "{name}: joint order");
    for s in fixture["samples"].as_array().unwrap() {
        let (q, v, a) = (nums(&s["q"]), nums(&s["v"]), nums(&s["a"]));
        assert_eq!((q.len(), v.len()), (body.nq(), nv), "{name}: coordinates");
        let mut out = vec![0.0; nv];
        rnea(&body, &mut ws, &q, &v, &a, &params, &mut out);
        worst.add("rnea", &out, &nums(&s["tau"]));
        if let Some(f) = s.get("f") {
            let ours: Vec<f64> = ws.force[1..].iter().flat_map(|f| f.to_array()).collect();
            worst.add("joint wrenches", &ours, &nums(f));
            let mut w = vec![0.0; 6 * nb * 10 * nb];
            joint_wrench_regressor(&body, &mut ws, &q, &v, &a, &mut w);
            let wpi: Vec<f64> = (0..6 * nb)
                .map(|r| (0..10 * nb).map(|c| w[r * 10 * nb + c] * params[c]).sum())
                .collect();
            worst.add("joint wrench regressor · π", &wpi, &nums(f));
        }
        if let Some(theirs) = s.get("Y") {
            let mut y = vec![0.0; nv * 10 * nb];
            joint_torque_regressor(&body, &mut ws, &q, &v, &a, &mut y);
            worst.add("joint torque regressor", &y, &nums(theirs));
        }
        let zero = vec![0.0; nv];
        rnea(&body, &mut ws, &q, &v, &zero, &params, &mut out);
        worst.add("nonlinear effects", &out, &nums(&s["nle"]));
        rnea(&body, &mut ws, &q, &zero, &zero, &params, &mut out);
        worst.add("gravity", &out, &nums(s.get("gravity").or(s.get("g")).unwrap()));
        let mut m = vec![0.0; nv * nv];
        crba(&body, &mut ws, &q, &params, &mut m);
        let theirs_m = nums(&s["M"]);
        worst.add("crba", &m, &theirs_m);
        // Forward dynamics where M is regular (the massless tip's is not).
        if !name.contains("massless") {
            let tau = nums(s.get("tau_rand").or(s.get("tau_fd")).unwrap());
            aba(&body, &mut ws, &q, &v, &tau, &params, &[], &mut out);
            worst.add("aba", &out, &nums(&s["ddq"]));
        }
        forward_kinematics(&body, &mut ws, &q);
        if let Some(o_m_i) = s.get("oMi") {
            let ours: Vec<f64> = ws.world[1..=nb].iter().flat_map(pose).collect();
            worst.add("placements", &ours, &nums(o_m_i));
        }
        for f in s.get("frames").and_then(Value::as_array).into_iter().flatten() {
            let frame = f["name"].as_str().unwrap();
            let fr = model
                .frames
                .iter()
                .find(|x| x.name == frame)
                .unwrap_or_else(|| panic!("{name}: no frame {frame}"));
            let offset = Se3 {
                rotation: fr.placement.rotation,
                translation: fr.placement.translation,
            };
            let mut jac = vec![0.0; 6 * nv];
            frame_jacobian(
                &body,
                &ws,
                fr.body,
                &offset,
                ReferenceFrame::LocalWorldAligned,
                &mut jac,
            );
            worst.add("frame Jacobian", &jac, &nums(&f["jacobian"]));
            worst.add(
                "frame placement",
                &pose(&ws.world[fr.body].compose(&offset)),
                &nums(&f["placement"]),
            );
        }
    }
    worst
}

#[test]
fn every_algorithm_matches_pinocchio_on_every_fixture() {
    let mut failures = Vec::new();
    for name in FIXTURES {
        let worst = check(name);
        let line: Vec<String> = worst.0.iter().map(|(w, e)| format!("{w} {e:.1e}")).collect();
        println!("{name}: {}", line.join(", "));
        for (what, e) in worst.0 {
            if e.is_nan() || e >= TOL {
                failures.push(format!("{name}: {what} differs from Pinocchio by {e:e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
