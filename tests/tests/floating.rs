//! The floating-base robots (`robot-quadruped12`, `robot-humanoid31`: the root link on
//! a free flyer) against Pinocchio 4.1 with `JointModelFreeFlyer` (fixtures in
//! `tests/fixtures/floating/`, made by `scripts/make_floating_fixtures.py`): every
//! generated algorithm, the base rows included, frames and Jacobians, the centre of
//! mass and the centroidal map. Then identities of the generated code itself.

use dyngen::{ReferenceFrame, RobotDerivatives};
use dyngen_tests::{pose_vec, rel_err, workspace_root};
use robot_humanoid31::Humanoid31;
use robot_quadruped12::Quadruped12;
use serde_json::Value;

const TOL: f64 = 1e-12;
/// The forward-dynamics derivatives and `M⁻¹` of the humanoid reach entries of 1e3
/// and are as accurate as `M`'s conditioning allows: Pinocchio's own `M q̈ + h − τ`
/// residual is 1.6e-12 there (`checks_max_abs` of the fixture).
const TOL_FORWARD_DERIVATIVES: f64 = 5e-12;

fn load(name: &str) -> Value {
    let path = workspace_root().join(format!("tests/fixtures/floating/{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("fixture JSON")
}

/// Numbers of a JSON value, nested lists flattened row-major.
fn nums(v: &Value) -> Vec<f64> {
    match v {
        Value::Number(x) => vec![x.as_f64().expect("f64")],
        Value::Array(xs) => xs.iter().flat_map(nums).collect(),
        Value::Object(o) => nums(&o["rotation"])
            .into_iter()
            .chain(nums(&o["translation"]))
            .collect(),
        _ => panic!("not a number or list: {v}"),
    }
}

/// Worst relative error of each quantity, by name.
#[derive(Default, Debug)]
struct Worst(Vec<(&'static str, f64)>);

impl Worst {
    fn add(&mut self, what: &'static str, who: &str, sample: usize, got: &[f64], want: &[f64]) {
        let e = rel_err(got, want, 1.0);
        let tol = if what.starts_with("aba_derivatives") || what == "inverse_inertia" {
            TOL_FORWARD_DERIVATIVES
        } else {
            TOL
        };
        assert!(
            e < tol,
            "{who}: {what}, sample {sample}: relative error {e:e}\n got {got:?}\nwant {want:?}"
        );
        match self.0.iter_mut().find(|(w, _)| *w == what) {
            Some((_, x)) => *x = x.max(e),
            None => self.0.push((what, e)),
        }
    }
}

fn check<R: RobotDerivatives>(fixture: &str) -> Worst {
    let fx = load(fixture);
    let who = R::NAME;
    let (nq, nv, nb) = (R::NQ, R::NV, R::NBODIES);
    let model = &fx["model"];
    assert_eq!(nv, model["nv"].as_u64().unwrap() as usize, "{who}: nv");
    assert_eq!(nq, nv + 1, "{who}: a free flyer and one coordinate per joint");
    let names: Vec<&str> = model["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert_eq!(names, R::joint_names(), "{who}: joint order");
    let parents: Vec<usize> = nums(&model["parents"]).iter().map(|&p| p as usize).collect();
    assert_eq!(parents, R::parents(), "{who}: parents");
    let mut worst = Worst::default();
    worst.add("params", who, 0, R::nominal_params(), &nums(&model["params"]));

    let params = R::nominal_params();
    for (s, x) in fx["samples"].as_array().unwrap().iter().enumerate() {
        let (q, v, a) = (nums(&x["q"]), nums(&x["v"]), nums(&x["a"]));
        let zero = vec![0.0; nv];
        let mut out = vec![0.0; nv];
        R::rnea(&q, &v, &a, params, &mut out);
        worst.add("rnea", who, s, &out, &nums(&x["tau"]));
        R::nonlinear_effects(&q, &v, params, &mut out);
        worst.add("nonlinear_effects", who, s, &out, &nums(&x["nle"]));
        R::generalized_gravity(&q, params, &mut out);
        worst.add("generalized_gravity", who, s, &out, &nums(&x["gravity"]));
        let mut m = vec![0.0; nv * nv];
        R::crba(&q, params, &mut m);
        worst.add("crba", who, s, &m, &nums(&x["M"]));
        R::aba(&q, &v, &nums(&x["tau_rand"]), params, &mut out);
        worst.add("aba", who, s, &out, &nums(&x["ddq"]));
        let mut y = vec![0.0; nv * 10 * nb];
        R::joint_torque_regressor(&q, &v, &a, &mut y);
        worst.add("joint_torque_regressor", who, s, &y, &nums(&x["Y"]));
        let mut poses = vec![dyngen::Pose::default(); nb];
        R::forward_kinematics(&q, &mut poses);
        let got: Vec<f64> = poses.iter().flat_map(pose_vec).collect();
        worst.add("forward_kinematics", who, s, &got, &nums(&x["oMi"]));
        for f in x["frames"].as_array().unwrap() {
            let name = f["name"].as_str().unwrap();
            let k = R::MODEL
                .frames
                .iter()
                .position(|m| m.name == name)
                .unwrap_or_else(|| panic!("{who}: no frame {name}"));
            let mut jac = vec![0.0; 6 * nv];
            let pose = R::frame_jacobian(&q, k, ReferenceFrame::LocalWorldAligned, &mut jac).unwrap();
            worst.add("frame_placement", who, s, &pose_vec(&pose), &nums(&f["placement"]));
            worst.add("frame_jacobian", who, s, &jac, &nums(&f["jacobian"]));
        }
        worst.add(
            "center_of_mass",
            who,
            s,
            &R::center_of_mass(&q, params),
            &nums(&x["com"]),
        );
        let mut jc = vec![0.0; 3 * nv];
        R::com_jacobian(&q, params, &mut jc);
        worst.add("com_jacobian", who, s, &jc, &nums(&x["Jcom"]));
        let (mut ag, mut ag_dot) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
        R::centroidal_map(&q, params, &mut ag);
        worst.add("centroidal_map", who, s, &ag, &nums(&x["Ag"]));
        R::centroidal_map_time_variation(&q, &v, params, &mut ag, &mut ag_dot);
        let hg: Vec<f64> = (0..6).map(|r| (0..nv).map(|c| ag[r * nv + c] * v[c]).sum()).collect();
        worst.add("centroidal momentum A_g v", who, s, &hg, &nums(&x["hg"]));
        let dag_v: Vec<f64> = (0..6)
            .map(|r| (0..nv).map(|c| ag_dot[r * nv + c] * v[c]).sum())
            .collect();
        worst.add(
            "centroidal_map_time_variation (Ȧ_g v)",
            who,
            s,
            &dag_v,
            &nums(&x["dAg_v"]),
        );
        // The base rows of rnea are the wrench on the base: joint_wrenches' first.
        let mut w = vec![dyngen::Wrench::default(); nb];
        R::joint_wrenches(&q, &v, &a, params, &mut w);
        R::rnea(&q, &v, &a, params, &mut out);
        let base = dyngen_tests::wrench_vec(&w[0]);
        worst.add("base rows of rnea = joint 1's wrench", who, s, &out[..6], &base);
        let (mut dq, mut dv, mut mm) = (vec![0.0; nv * nv], vec![0.0; nv * nv], vec![0.0; nv * nv]);
        R::rnea_derivatives(&q, &v, &a, params, &mut dq, &mut dv, &mut mm);
        worst.add("rnea_derivatives ∂τ/∂q", who, s, &dq, &nums(&x["dtau_dq"]));
        worst.add("rnea_derivatives ∂τ/∂v", who, s, &dv, &nums(&x["dtau_dv"]));
        worst.add("rnea_derivatives ∂τ/∂a", who, s, &mm, &nums(&x["M"]));
        let mut minv = vec![0.0; nv * nv];
        R::aba_derivatives(&q, &v, &nums(&x["tau_rand"]), params, &mut out, &mut dq, &mut dv, &mut minv);
        worst.add("aba_derivatives q̈", who, s, &out, &nums(&x["ddq"]));
        worst.add("aba_derivatives ∂q̈/∂q", who, s, &dq, &nums(&x["ddq_dq"]));
        worst.add("aba_derivatives ∂q̈/∂v", who, s, &dv, &nums(&x["ddq_dv"]));
        worst.add("aba_derivatives M⁻¹", who, s, &minv, &nums(&x["Minv"]));
        let mut alone = vec![0.0; nv * nv];
        R::inverse_inertia(&q, params, &mut alone);
        worst.add("inverse_inertia", who, s, &alone, &nums(&x["Minv"]));
        let _ = &zero;
    }
    worst
}

#[test]
fn quadruped12_matches_pinocchio_free_flyer() {
    let w = check::<Quadruped12>("quadruped12");
    eprintln!("quadruped12: {w:?}");
}

#[test]
fn humanoid31_matches_pinocchio_free_flyer() {
    let w = check::<Humanoid31>("humanoid31");
    eprintln!("humanoid31: {w:?}");
}

