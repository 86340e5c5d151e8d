//! The algorithms on `f64`, on every robot description with Pinocchio 4.1 fixtures
//! (fixed bases, free flyers, planar joints; `tests/fixtures/`, made by the
//! `scripts/make_*fixtures.py` scripts): the URDF loaded at run time, then rnea, the
//! joint wrenches, nonlinear effects, gravity, crba, aba, the body placements and
//! frame Jacobians against Pinocchio's numbers; on the free flyers also the derivatives
//! of rnea and aba, `M⁻¹`, the centre of mass, its Jacobian, `A_g` and `Ȧ_g v`; and on
//! the control fixtures (`tests/fixtures/control/`) every frame's velocity, classical
//! acceleration, drift and `J̇` in the three reference frames, the derivatives and the
//! centroidal quantities of the fixed bases.

use dyngen_algo::{
    aba, aba_derivatives, body_motions, centroidal_map, centroidal_map_time_variation, com_jacobian, crba,
    forward_kinematics, frame_classical_acceleration, frame_jacobian, frame_jacobian_time_variation, frame_velocity,
    joint_torque_regressor, joint_wrench_regressor, rnea, rnea_derivatives, DualWorkspace, Multibody, ReferenceFrame,
    Se3, Workspace,
};
use dyngen_model::{load_urdf_options, LoadOptions, Model};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Agreement required with Pinocchio: normwise, relative to the largest entry (at
/// least 1).
const TOL: f64 = 1e-12;
/// `M⁻¹` and the forward-dynamics derivatives of the humanoid (`M`'s condition number
/// up to 2.5e5) differ from Pinocchio's by up to 1.3e-12, Pinocchio's own error:
/// `forward_derivatives_against_extended_precision` holds ours to [`TOL`] against
/// the `long double` values.
const TOL_FORWARD_DERIVATIVES: f64 = 5e-12;

/// The tolerance of `what` against Pinocchio.
fn tolerance(what: &str) -> f64 {
    if what.starts_with("aba ∂") || what == "M⁻¹" {
        TOL_FORWARD_DERIVATIVES
    } else {
        TOL
    }
}

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
        if s.get("dtau_dq").is_some() {
            derivatives_and_centroidal(&body, s, &mut worst);
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

/// The derivatives of rnea (at `q, v, a`) and of aba (at `q, v` and the torques of
/// `ddq`), `M⁻¹`, the centre of mass, its Jacobian, `A_g`, `Ȧ_g v` and `h_g = A_g v`
/// of one sample.
fn derivatives_and_centroidal(body: &Multibody, s: &Value, worst: &mut Worst) {
    let (nv, params) = (body.nv(), &body.params);
    let (q, v, a) = (nums(&s["q"]), nums(&s["v"]), nums(&s["a"]));
    let mut ws = Workspace::new(body, ());
    // Eight directions per pass for the derivatives, one for the time variations.
    let mut dual8 = DualWorkspace::<f64, 8>::new(body, ());
    let mut dual1 = DualWorkspace::<f64, 1>::new(body, ());
    let [mut d1, mut d2, mut d3] = [(); 3].map(|_| vec![0.0; nv * nv]);
    rnea_derivatives(body, &mut dual8, &mut ws, &q, &v, &a, params, &mut d1, &mut d2, &mut d3);
    worst.add("rnea ∂τ/∂q", &d1, &nums(&s["dtau_dq"]));
    worst.add("rnea ∂τ/∂v", &d2, &nums(&s["dtau_dv"]));
    worst.add("rnea ∂τ/∂a", &d3, &nums(&s["M"]));
    let tau = nums(s.get("tau_rand").or(s.get("tau_fd")).unwrap_or(&s["tau"]));
    let mut ddq = vec![0.0; nv];
    aba_derivatives(
        body,
        &mut dual8,
        &mut ws,
        &q,
        &v,
        &tau,
        params,
        &[],
        &mut ddq,
        &mut d1,
        &mut d2,
        &mut d3,
    );
    worst.add("aba (derivatives)", &ddq, &nums(&s["ddq"]));
    worst.add("aba ∂q̈/∂q", &d1, &nums(&s["ddq_dq"]));
    worst.add("aba ∂q̈/∂v", &d2, &nums(&s["ddq_dv"]));
    worst.add("M⁻¹", &d3, &nums(&s["Minv"]));
    let mut jcom = vec![0.0; 3 * nv];
    let com = com_jacobian(body, &mut ws, &q, params, &mut jcom);
    worst.add("centre of mass", &com, &nums(&s["com"]));
    worst.add("centre-of-mass Jacobian", &jcom, &nums(&s["Jcom"]));
    let (mut ag, mut ag_dot) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
    centroidal_map(body, &mut ws, &q, params, &mut ag);
    worst.add("A_g", &ag, &nums(&s["Ag"]));
    let mut ag1 = vec![0.0; 6 * nv];
    centroidal_map_time_variation(body, &mut dual1, &q, &v, params, &mut ag1, &mut ag_dot);
    worst.add("A_g (time variation)", &ag1, &nums(&s["Ag"]));
    let times = |m: &[f64], x: &[f64]| -> Vec<f64> {
        m.chunks(nv)
            .map(|r| r.iter().zip(x).map(|(a, b)| a * b).sum())
            .collect()
    };
    worst.add("Ȧ_g v", &times(&ag_dot, &v), &nums(&s["dAg_v"]));
    if let Some(hg) = s.get("hg") {
        worst.add("h_g", &times(&ag, &v), &nums(hg));
    }
}

#[test]
fn every_algorithm_matches_pinocchio_on_every_fixture() {
    let mut failures = Vec::new();
    for name in FIXTURES {
        let worst = check(name);
        let line: Vec<String> = worst.0.iter().map(|(w, e)| format!("{w} {e:.1e}")).collect();
        println!("{name}: {}", line.join(", "));
        for (what, e) in worst.0 {
            if e.is_nan() || e >= tolerance(what) {
                failures.push(format!("{name}: {what} differs from Pinocchio by {e:e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `M⁻¹` and `∂q̈/∂q` against their `long double` evaluation (`*_extended.json`, from
/// `scripts/forward_derivative_conditioning.py`): within [`TOL`] where Pinocchio's
/// own double-precision results are up to 1.3e-12 away.
#[test]
fn forward_derivatives_against_extended_precision() {
    for name in ["floating/humanoid31", "floating/quadruped12"] {
        let Loaded { body, fixture, .. } = load(name);
        let extended: Value = serde_json::from_str(
            &std::fs::read_to_string(root().join(format!("tests/fixtures/{name}_extended.json"))).unwrap(),
        )
        .unwrap();
        let nv = body.nv();
        let mut dual = DualWorkspace::<f64, 8>::new(&body, ());
        let mut ws = Workspace::new(&body, ());
        let mut worst = Worst::default();
        for (s, e) in fixture["samples"]
            .as_array()
            .unwrap()
            .iter()
            .zip(extended["samples"].as_array().unwrap())
        {
            let (q, v, tau) = (nums(&s["q"]), nums(&s["v"]), nums(&s["tau_rand"]));
            let mut ddq = vec![0.0; nv];
            let [mut dq, mut dv, mut minv] = [(); 3].map(|_| vec![0.0; nv * nv]);
            aba_derivatives(
                &body,
                &mut dual,
                &mut ws,
                &q,
                &v,
                &tau,
                &body.params,
                &[],
                &mut ddq,
                &mut dq,
                &mut dv,
                &mut minv,
            );
            worst.add("M⁻¹", &minv, &nums(&e["Minv"]));
            worst.add("∂q̈/∂q", &dq, &nums(&e["ddq_dq"]));
        }
        for (what, err) in worst.0 {
            println!("{name}: {what} {err:.1e} from the extended-precision value");
            assert!(err < TOL, "{name}: {what} is {err:e} from the extended-precision value");
        }
    }
}

/// The control fixtures: fixed bases, every frame of the URDF.
const CONTROL: [&str; 7] = ["ur5", "gripper_arm", "planar2", "paper6", "puma560", "panda", "tree12"];

#[test]
fn frames_derivatives_and_centroidal_match_pinocchio_on_the_control_fixtures() {
    let references = [
        ("world", ReferenceFrame::World),
        ("local", ReferenceFrame::Local),
        ("lwa", ReferenceFrame::LocalWorldAligned),
    ];
    let mut failures = Vec::new();
    for name in CONTROL {
        let path = root().join("tests/fixtures/control").join(format!("{name}.json"));
        let fixture: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let model = load_urdf_options(&root().join(fixture["urdf"].as_str().unwrap()), LoadOptions::default()).unwrap();
        let mut body = model.multibody().unwrap();
        body.gravity.copy_from_slice(&nums(&fixture["gravity"]));
        let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        let theirs: Vec<&str> = fixture["joint_names"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_str().unwrap())
            .collect();
        assert_eq!(names, theirs, "{name}: joint order");
        let nv = body.nv();
        let mut ws = Workspace::new(&body, ());
        let mut dual = DualWorkspace::<f64, 1>::new(&body, ());
        let mut worst = Worst::default();
        for s in fixture["samples"].as_array().unwrap() {
            let (q, v, a) = (nums(&s["q"]), nums(&s["v"]), nums(&s["a"]));
            derivatives_and_centroidal(&body, s, &mut worst);
            let zero = vec![0.0; nv];
            for (k, f) in s["frames"].as_array().unwrap().iter().enumerate() {
                let description = &fixture["frames"][k];
                let fr = model
                    .frames
                    .iter()
                    .find(|x| x.name == description["name"].as_str().unwrap())
                    .unwrap();
                let offset = Se3 {
                    rotation: fr.placement.rotation,
                    translation: fr.placement.translation,
                };
                body_motions(&body, &mut ws, &q, &v, &a);
                for (key, reference) in references {
                    let vel = frame_velocity(&body, &ws, fr.body, &offset, reference).to_array();
                    worst.add("frame velocity", &vel, &nums(&f[format!("v_{key}").as_str()]));
                    let acc = frame_classical_acceleration(&body, &mut dual, &q, &v, &a, fr.body, &offset, reference);
                    worst.add(
                        "classical acceleration",
                        &acc.to_array(),
                        &nums(&f[format!("acc_{key}").as_str()]),
                    );
                    let drift =
                        frame_classical_acceleration(&body, &mut dual, &q, &v, &zero, fr.body, &offset, reference);
                    worst.add("drift", &drift.to_array(), &nums(&f[format!("drift_{key}").as_str()]));
                    let (mut j, mut jd) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
                    frame_jacobian_time_variation(
                        &body, &mut dual, &q, &v, fr.body, &offset, reference, &mut j, &mut jd,
                    );
                    worst.add("frame Jacobian", &j, &nums(&f[format!("J_{key}").as_str()]));
                    worst.add("J̇", &jd, &nums(&f[format!("dJ_{key}").as_str()]));
                }
            }
        }
        let line: Vec<String> = worst.0.iter().map(|(w, e)| format!("{w} {e:.1e}")).collect();
        println!("{name}: {}", line.join(", "));
        for (what, e) in worst.0 {
            if e.is_nan() || e >= tolerance(what) {
                failures.push(format!("{name}: {what} differs from Pinocchio by {e:e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
