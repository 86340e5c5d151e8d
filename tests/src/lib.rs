//! Shared helpers of dyngen's cross-crate tests: the reference model of a generated
//! robot, Pinocchio fixtures, and error measures.

/// UR5 generated with every function split into parts of at most 40 statements
/// (see `build.rs`).
pub mod split {
    include!(concat!(env!("OUT_DIR"), "/ur5_split.rs"));
}

/// UR5 generated with every composable function composed of the others, as robots
/// of more than `Config::compose_above` velocity coordinates have them (see
/// `build.rs`).
pub mod composed {
    include!(concat!(env!("OUT_DIR"), "/ur5_composed.rs"));
}

/// A robot with joints that follow others (`<mimic>`; see `build.rs`): the mimic
/// probe tree on a free flyer (followers with multipliers other than ±1 and offsets, a
/// prismatic one, one in another branch than its leader).
pub mod mimic {
    include!(concat!(env!("OUT_DIR"), "/mimic_probe_free_flyer.rs"));
}

/// A 12-DOF branched tree (torso, head, two arms; revolute, continuous and
/// prismatic joints, unaligned axes, a merged fixed link): the largest tree the
/// tests generate and compile.
pub mod tree12 {
    dyngen::robot!(name: Tree12, urdf: "fixtures/tree12.urdf");
}

/// A mobile manipulator on two URDF `planar` joints (the base on the ground, a stage
/// at the wrist with a tilted plane) and five one-coordinate joints: `nq = nv = 11`.
pub mod mobile_arm {
    dyngen::robot!(name: MobileArm, urdf: "fixtures/mobile_arm.urdf");
}

use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Normwise relative error `‖x − y‖∞ / max(‖y‖∞, floor)`.
pub fn rel_err(x: &[f64], y: &[f64], floor: f64) -> f64 {
    assert_eq!(x.len(), y.len());
    let diff = x.iter().zip(y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let scale = y.iter().map(|b| b.abs()).fold(floor, f64::max);
    diff / scale
}

/// Evaluates the symbolic graph's `outputs` with `q`, `v`, `a` (or `tau`, for
/// `aba`) and `params` as its arguments: the generator's algorithms without
/// compiling them.
pub fn eval_graph(
    g: &dyngen_codegen::sym::Graph,
    outputs: &[dyngen_codegen::sym::NodeId],
    q: &[f64],
    v: &[f64],
    a_or_tau: &[f64],
    params: &[f64],
) -> Vec<f64> {
    use dyngen_codegen::algo::{ARG_A, ARG_PARAMS, ARG_Q, ARG_V};
    g.eval(outputs, |arg, index| {
        let i = index as usize;
        match arg {
            ARG_Q => q[i],
            ARG_V => v[i],
            ARG_A => a_or_tau[i],
            ARG_PARAMS => params[i],
            _ => panic!("unknown argument {arg}"),
        }
    })
}

/// The outputs of the generator's joint-space dynamics for `model`, as nodes of `g`:
/// `rnea(q, v, a)`, `rnea(q, v, 0)`, `rnea(q, 0, 0)`, `M(q)` row-major and
/// `aba(q, v, τ)` (evaluate them with [`eval_graph`]).
pub struct DynamicsGraph {
    pub rnea: Vec<dyngen_codegen::sym::NodeId>,
    pub nonlinear_effects: Vec<dyngen_codegen::sym::NodeId>,
    pub gravity: Vec<dyngen_codegen::sym::NodeId>,
    pub crba: Vec<dyngen_codegen::sym::NodeId>,
    pub aba: Vec<dyngen_codegen::sym::NodeId>,
}

impl DynamicsGraph {
    pub fn new(g: &dyngen_codegen::sym::Graph, model: &dyngen_model::Model) -> DynamicsGraph {
        use dyngen_codegen::algo::{self, Inputs};
        let ids = |e: &[dyngen_codegen::sym::Expr<'_>]| e.iter().map(|x| x.id()).collect();
        DynamicsGraph {
            rnea: ids(&algo::rnea(g, model, Inputs::Full).tau),
            nonlinear_effects: ids(&algo::rnea(g, model, Inputs::NoAcceleration).tau),
            gravity: ids(&algo::rnea(g, model, Inputs::Static).tau),
            crba: algo::crba(g, model).iter().flatten().map(|x| x.id()).collect(),
            aba: ids(&algo::aba(g, model, algo::Armature::None)),
        }
    }
}

/// A pose as 12 numbers: rotation row-major, then translation.
pub fn pose_vec(p: &dyngen::Pose<f64>) -> Vec<f64> {
    let mut v = Vec::with_capacity(12);
    for r in 0..3 {
        for c in 0..3 {
            v.push(p.rotation[(r, c)]);
        }
    }
    v.extend(p.translation.iter());
    v
}

/// A wrench as 6 numbers: force, then torque (Pinocchio's order).
pub fn wrench_vec(w: &dyngen::Wrench<f64>) -> Vec<f64> {
    w.force.iter().chain(w.torque.iter()).copied().collect()
}

#[derive(Deserialize)]
pub struct Fixture {
    pub name: String,
    pub pinocchio_version: String,
    pub model: FixtureModel,
    pub gravity: [f64; 3],
    pub samples: Vec<FixtureSample>,
}

#[derive(Deserialize)]
pub struct FixtureModel {
    pub joint_names: Vec<String>,
    pub parents: Vec<usize>,
    pub dyn_params: Vec<[f64; 10]>,
}

#[derive(Deserialize)]
pub struct FixturePose {
    pub rotation: [[f64; 3]; 3],
    pub translation: [f64; 3],
}

#[derive(Deserialize)]
pub struct FixtureSample {
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    pub tau: Vec<f64>,
    pub f: Vec<[f64; 6]>,
    #[serde(rename = "oMi")]
    pub o_m_i: Vec<FixturePose>,
    /// `crba`, rows.
    #[serde(rename = "M")]
    pub m: Vec<Vec<f64>>,
    pub nle: Vec<f64>,
    pub g: Vec<f64>,
    /// Joint torque regressor, rows.
    #[serde(rename = "Y")]
    pub y: Vec<Vec<f64>>,
    pub tau_fd: Vec<f64>,
    /// `aba(q, v, tau_fd)`.
    pub ddq: Vec<f64>,
}

impl FixturePose {
    pub fn to_vec(&self) -> Vec<f64> {
        self.rotation
            .iter()
            .flatten()
            .chain(self.translation.iter())
            .copied()
            .collect()
    }
}

/// The workspace root.
/// The checked model of the robot a robot crate's source declares, with its type
/// name: the `robot!` invocation in `robots/<dir>/src/lib.rs` (inline description or
/// `urdf: "path"`), or, for a crate generated in `build.rs`, the URDF `urdf`.
pub fn robot_crate_model(dir: &str) -> (String, dyngen_model::Model) {
    let crate_dir = workspace_root().join("robots").join(dir);
    let path = crate_dir.join("src/lib.rs");
    let source = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let file = syn::parse_file(&source).expect("robot crate parses");
    let tokens = file.items.iter().find_map(|item| match item {
        syn::Item::Macro(m) if m.mac.path.segments.last().is_some_and(|s| s.ident == "robot") => {
            Some(m.mac.tokens.clone())
        }
        _ => None,
    });
    let Some(tokens) = tokens else {
        let urdf = crate_dir.join(format!("{dir}.urdf"));
        let model = dyngen_model::load_urdf(&urdf).unwrap_or_else(|e| panic!("{e}"));
        return (String::new(), model);
    };
    let input = dyngen_codegen::dsl::parse(tokens).expect("description parses");
    let model = match input.source {
        dyngen_codegen::RobotSource::Dsl(d) => d.build().expect("description is valid"),
        dyngen_codegen::RobotSource::Urdf(lit) => {
            dyngen_model::load_urdf(&crate_dir.join(lit.value())).unwrap_or_else(|e| panic!("{e}"))
        }
    };
    (input.name.to_string(), model)
}

pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

/// The worst relative error of each quantity compared with a fixture, by name, in the
/// order first met; every comparison is asserted below `tolerance(what)`.
#[derive(Debug)]
pub struct Worst {
    pub items: Vec<(&'static str, f64)>,
    tolerance: fn(&str) -> f64,
}

impl Worst {
    pub fn new(tolerance: fn(&str) -> f64) -> Worst {
        Worst {
            items: Vec::new(),
            tolerance,
        }
    }

    /// Compares `got` with `want` ([`rel_err`] with `floor`) for `who`'s `sample`.
    pub fn add(&mut self, what: &'static str, who: &str, sample: usize, got: &[f64], want: &[f64], floor: f64) {
        let e = rel_err(got, want, floor);
        let tol = (self.tolerance)(what);
        assert!(
            e < tol,
            "{who}: {what}, sample {sample}: relative error {e:e} (tolerance {tol:e})\n got {got:?}\nwant {want:?}"
        );
        match self.items.iter_mut().find(|(w, _)| *w == what) {
            Some((_, x)) => *x = x.max(e),
            None => self.items.push((what, e)),
        }
    }
}

/// Reads `tests/fixtures/<path>` (a JSON file) as an untyped value.
pub fn load_json(path: &str) -> serde_json::Value {
    let path = workspace_root().join("tests/fixtures").join(path);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The numbers of a JSON value, nested lists flattened row-major; a placement
/// `{"rotation", "translation"}` as its 12 numbers (as [`pose_vec`]).
pub fn json_numbers(v: &serde_json::Value) -> Vec<f64> {
    use serde_json::Value;
    match v {
        Value::Number(x) => vec![x.as_f64().expect("f64")],
        Value::Array(xs) => xs.iter().flat_map(json_numbers).collect(),
        Value::Object(o) if o.contains_key("rotation") => json_numbers(&o["rotation"])
            .into_iter()
            .chain(json_numbers(&o["translation"]))
            .collect(),
        _ => panic!("not a number, a list or a placement: {v}"),
    }
}

/// Loads `tests/fixtures/<name>.json`.
pub fn load_fixture(name: &str) -> Fixture {
    let path = workspace_root().join("tests/fixtures").join(format!("{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}
