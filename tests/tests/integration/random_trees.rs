//! Property tests on random kinematic trees: the symbolic algorithms of
//! `dyngen_codegen::algo`, evaluated straight from the expression graph (nothing is
//! compiled), against the Featherstone reference of `dyngen_reference`.
//!
//! A seeded generator builds valid trees of 1 to 8 moving bodies: random topology,
//! revolute, continuous and prismatic joints, axis-aligned and skew axes, quarter-turn
//! and arbitrary joint origins, physically consistent inertials with rotated principal
//! axes, optional limits, now and then a fixed joint carrying an extra link (merged
//! into its body) and a gravity that does not point down. Every tree goes through
//! `Description::build`; its merged inertials are checked against a sum computed here,
//! and every algorithm against the reference on a few random states with perturbed
//! parameters.

use dyngen_codegen::algo::{self, Force, Inputs, ARG_Q};
use dyngen_codegen::sym::{Expr, Graph, NodeId};
use dyngen_model::math::{self, Mat3, Vec3};
use dyngen_model::{
    DeclaredJointType, Description, Inertial, JointDesc, JointKind, Limits, LinkDesc, Model, Placement, DEFAULT_GRAVITY,
};
use dyngen_reference::{perturbed_params, sample_states, Reference, SplitMix64, State};
use dyngen_tests::{eval_graph as eval, pose_vec, rel_err, wrench_vec};
use std::f64::consts::{FRAC_PI_2, PI};

/// Agreement required between the graph and the reference (normwise, relative).
const TOL: f64 = 1e-9;
/// Tree sizes and seeds per size: 8 × 10 = 80 trees.
const SIZES: std::ops::RangeInclusive<usize> = 1..=8;
const SEEDS_PER_SIZE: u64 = 10;
/// Random states per tree, each with its own perturbed parameters.
const STATES: usize = 4;
/// Failure messages shown at most (the count is always given).
const SHOWN: usize = 40;
/// Reference entries where the graph has a structural zero must be this small.
const STRUCTURAL_ZERO: f64 = 1e-12;

/// The seed of tree number `k` of `bodies` moving bodies.
fn tree_seed(bodies: usize, k: u64) -> u64 {
    0x7265_0000 + 0x100 * bodies as u64 + k
}

// ---------------------------------------------------------------------------------
// The generator
// ---------------------------------------------------------------------------------

/// One link of a random tree as generated: how it hangs from its parent, and its
/// own inertial (before any merging).
struct GenLink {
    name: String,
    /// Index of the parent link in `RandomTree::links` (0 is the base).
    parent: usize,
    /// `None` for a fixed joint.
    kind: Option<JointKind>,
    origin: Placement,
    inertial: Option<Inertial>,
}

/// A random valid tree: the generated links (entry 0 the base) and what was drawn.
struct RandomTree {
    seed: u64,
    links: Vec<GenLink>,
    gravity: Vec3,
    desc: Description,
}

impl RandomTree {
    /// A tree of `bodies` moving bodies (and possibly extra fixed links), fully
    /// determined by `seed`.
    fn generate(seed: u64, bodies: usize) -> RandomTree {
        let mut rng = SplitMix64::new(seed);
        let mut links = vec![GenLink {
            name: "base".into(),
            parent: 0,
            kind: None,
            origin: Placement::IDENTITY,
            inertial: None,
        }];
        let mut joints = Vec::new();
        let mut moving = 0;
        while moving < bodies {
            // Now and then a fixed joint with an extra link (a third of them massless
            // frames), whose inertial the build must lump into the body it hangs from.
            let fixed = rng.next_f64() < 0.2;
            let parent = index(&mut rng, links.len());
            let origin = random_origin(&mut rng);
            let (kind, name, inertial) = if fixed {
                let inertial = (rng.next_f64() < 2.0 / 3.0).then(|| random_inertial(&mut rng));
                (DeclaredJointType::Fixed, format!("fixed{}", links.len()), inertial)
            } else {
                moving += 1;
                let kind = [JointKind::Revolute, JointKind::Continuous, JointKind::Prismatic][index(&mut rng, 3)];
                (
                    DeclaredJointType::Moving(kind),
                    format!("body{moving}"),
                    Some(random_inertial(&mut rng)),
                )
            };
            let axis = random_axis(&mut rng);
            let limits = (rng.next_f64() < 0.5).then(|| random_limits(&mut rng, &kind));
            joints.push(JointDesc {
                name: format!("j_{name}"),
                kind: kind.clone(),
                parent: links[parent].name.clone(),
                child: name.clone(),
                origin,
                axis,
                limits,
                dynamics: Default::default(),
                line: None,
            });
            links.push(GenLink {
                name,
                parent,
                kind: match kind {
                    DeclaredJointType::Moving(k) => Some(k),
                    _ => None,
                },
                origin,
                inertial,
            });
        }
        let gravity = match index(&mut rng, 6) {
            0 => [0.0; 3],
            1 | 2 => math::scale(9.81, &unit_vector(&mut rng)),
            _ => DEFAULT_GRAVITY,
        };
        let desc = Description {
            name: format!("random_{seed:x}"),
            gravity,
            links: links
                .iter()
                .map(|l| LinkDesc {
                    name: l.name.clone(),
                    inertial: l.inertial,
                    line: None,
                })
                .collect(),
            joints,
            mimics: Vec::new(),
        };
        RandomTree {
            seed,
            links,
            gravity,
            desc,
        }
    }

    fn build(&self) -> Model {
        self.desc
            .build()
            .unwrap_or_else(|e| panic!("seed {:#x}: a random tree does not build: {e:?}", self.seed))
    }

    /// The moving body link `k` belongs to (its own index if its joint moves; 0 for
    /// links rigidly attached to the base), and its placement in that body's frame.
    fn owner(&self, mut k: usize) -> (usize, Placement) {
        let mut placement = Placement::IDENTITY;
        while k != 0 && self.links[k].kind.is_none() {
            placement = self.links[k].origin.compose(&placement);
            k = self.links[k].parent;
        }
        (k, placement)
    }

    /// The standard parameters each moving link's body should have after merging,
    /// computed independently of the build: `m = Σ m_k`, `h = Σ m_k p_k`,
    /// `I = Σ R_k I_k R_kᵀ + m_k (|p_k|² E − p_k p_kᵀ)` with `p_k` link `k`'s centre
    /// of mass in the body frame.
    fn expected_params(&self, body_link: usize) -> [f64; 10] {
        let (mut m, mut h, mut i) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
        for k in 1..self.links.len() {
            let (owner, placement) = self.owner(k);
            let Some(part) = &self.links[k].inertial else { continue };
            if owner != body_link {
                continue;
            }
            let p = placement.transform_point(&part.com);
            m += part.mass;
            h = math::add(&h, &math::scale(part.mass, &p));
            let about_origin = math::mat_add(
                &math::rotate_inertia(&placement.rotation, &part.inertia),
                &math::parallel_axis(part.mass, &p),
            );
            i = math::mat_add(&i, &about_origin);
        }
        [
            m, h[0], h[1], h[2], i[0][0], i[0][1], i[1][1], i[0][2], i[1][2], i[2][2],
        ]
    }
}

/// Uniform in `0..n`.
fn index(rng: &mut SplitMix64, n: usize) -> usize {
    ((rng.next_f64() * n as f64) as usize).min(n - 1)
}

/// Uniformly distributed on the unit sphere (rejection from the cube).
fn unit_vector(rng: &mut SplitMix64) -> Vec3 {
    loop {
        let v = [0; 3].map(|_| rng.uniform(-1.0, 1.0));
        let r = math::norm(&v);
        if (0.1..=1.0).contains(&r) {
            return math::scale(1.0 / r, &v);
        }
    }
}

/// A uniformly distributed rotation, from a random unit quaternion.
fn random_rotation(rng: &mut SplitMix64) -> Mat3 {
    let q = loop {
        let v = [0; 4].map(|_| rng.uniform(-1.0, 1.0));
        let r = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        if (0.1..=1.0).contains(&r) {
            break v.map(|c| c / r);
        }
    };
    math::quaternion_to_matrix(q)
}

/// Half the time ±x, ±y or ±z exactly; otherwise a random direction of random
/// length in [0.5, 2] (the build normalises it).
fn random_axis(rng: &mut SplitMix64) -> Vec3 {
    if rng.next_f64() < 0.5 {
        let mut a = [0.0; 3];
        a[index(rng, 3)] = if rng.next_f64() < 0.5 { -1.0 } else { 1.0 };
        a
    } else {
        let length = rng.uniform(0.5, 2.0);
        math::scale(length, &unit_vector(rng))
    }
}

/// Translation in [−0.5, 0.5]³; roll, pitch and yaw either quarter turns (exact
/// 0/±1 entries) or arbitrary.
fn random_origin(rng: &mut SplitMix64) -> Placement {
    let xyz = [0; 3].map(|_| rng.uniform(-0.5, 0.5));
    let rpy = if rng.next_f64() < 0.5 {
        [0; 3].map(|_| (index(rng, 5) as f64 - 2.0) * FRAC_PI_2)
    } else {
        [0; 3].map(|_| rng.uniform(-PI, PI))
    };
    Placement::from_xyz_rpy(xyz, rpy)
}

/// Mass in [0.1, 10], centre of mass in [−0.3, 0.3]³, inertia `R diag(J) Rᵀ` with
/// `J_k = Σ L − L_k` from positive second moments `L` (the triangle inequality,
/// strictly) and a random rotation `R` (the identity a quarter of the time).
fn random_inertial(rng: &mut SplitMix64) -> Inertial {
    let mass = rng.uniform(0.1, 10.0);
    let com = [0; 3].map(|_| rng.uniform(-0.3, 0.3));
    let second = [0; 3].map(|_| mass * rng.uniform(0.002, 0.05));
    let sum: f64 = second.iter().sum();
    let j = second.map(|l| sum - l);
    let diagonal = [[j[0], 0.0, 0.0], [0.0, j[1], 0.0], [0.0, 0.0, j[2]]];
    let inertia = if rng.next_f64() < 0.25 {
        diagonal
    } else {
        math::rotate_inertia(&random_rotation(rng), &diagonal)
    };
    Inertial { mass, com, inertia }
}

fn random_limits(rng: &mut SplitMix64, kind: &DeclaredJointType) -> Limits {
    let reach = if *kind == DeclaredJointType::Moving(JointKind::Prismatic) {
        0.5
    } else {
        PI
    };
    Limits {
        lower: -reach * rng.uniform(0.1, 1.0),
        upper: reach * rng.uniform(0.1, 1.0),
        velocity: rng.uniform(1.0, 5.0),
        effort: rng.uniform(10.0, 100.0),
    }
}

// ---------------------------------------------------------------------------------
// The symbolic side
// ---------------------------------------------------------------------------------

/// Every algorithm's outputs as nodes of one graph, flattened row-major; `None`
/// marks the structural zeros of the regressors.
struct Symbolic {
    rnea: Vec<NodeId>,
    nonlinear_effects: Vec<NodeId>,
    gravity: Vec<NodeId>,
    /// 12 per body: rotation row-major, then translation.
    forward_kinematics: Vec<NodeId>,
    /// 6 per joint: force, then moment.
    wrenches: Vec<NodeId>,
    crba: Vec<NodeId>,
    /// Reads `tau` in the slot of `a`.
    aba: Vec<NodeId>,
    torque_regressor: Vec<Option<NodeId>>,
    wrench_regressor: Vec<Option<NodeId>>,
    principal_regressor: Vec<Option<NodeId>>,
    /// 24 per body: the 6 × 4 matrix row-major.
    body_regressors: Vec<NodeId>,
    /// 6 per body: force, then moment about the centre of mass.
    body_resultants: Vec<NodeId>,
}

fn ids(e: &[Expr<'_>]) -> Vec<NodeId> {
    e.iter().map(|x| x.id()).collect()
}

fn force_ids(forces: &[Force<'_>]) -> Vec<NodeId> {
    forces
        .iter()
        .flat_map(|w| w.f.0.iter().chain(w.n.0.iter()).map(|x| x.id()))
        .collect()
}

fn regressor_ids(y: &[Vec<Option<Expr<'_>>>]) -> Vec<Option<NodeId>> {
    y.iter().flatten().map(|e| e.map(|x| x.id())).collect()
}

impl Symbolic {
    fn build(g: &Graph, model: &Model) -> Symbolic {
        let rnea = algo::rnea(g, model, Inputs::Full);
        Symbolic {
            rnea: ids(&rnea.tau),
            nonlinear_effects: ids(&algo::rnea(g, model, Inputs::NoAcceleration).tau),
            gravity: ids(&algo::rnea(g, model, Inputs::Static).tau),
            forward_kinematics: algo::forward_kinematics(g, model)
                .iter()
                .flat_map(|(r, t)| r.0.iter().flatten().chain(t.0.iter()).map(|x| x.id()))
                .collect(),
            wrenches: force_ids(&rnea.wrenches),
            crba: algo::crba(g, model).iter().flatten().map(|x| x.id()).collect(),
            aba: ids(&algo::aba(g, model, algo::Armature::None)),
            torque_regressor: regressor_ids(&algo::torque_regressor(g, model, algo::standard_columns(g))),
            wrench_regressor: regressor_ids(&algo::wrench_regressor(g, model)),
            principal_regressor: regressor_ids(&algo::torque_regressor(g, model, algo::principal_columns(g, model))),
            body_regressors: algo::body_regressors(g, model)
                .iter()
                .flat_map(|a| a.iter().flatten().map(|x| x.id()))
                .collect(),
            body_resultants: force_ids(&algo::body_resultants(g, model)),
        }
    }
}

/// A regressor evaluated with its structural zeros as 0, and the positions of those
/// zeros.
fn eval_regressor(g: &Graph, y: &[Option<NodeId>], s: &State) -> (Vec<f64>, Vec<usize>) {
    let live: Vec<NodeId> = y.iter().flatten().copied().collect();
    let mut values = eval(g, &live, &s.q, &s.v, &s.a, &[]).into_iter();
    let mut zeros = Vec::new();
    let full = y
        .iter()
        .enumerate()
        .map(|(k, e)| match e {
            Some(_) => values.next().expect("one value per live entry"),
            None => {
                zeros.push(k);
                0.0
            }
        })
        .collect();
    (full, zeros)
}

fn row_major(m: &nalgebra::DMatrix<f64>) -> Vec<f64> {
    (0..m.nrows())
        .flat_map(|r| (0..m.ncols()).map(move |c| m[(r, c)]))
        .collect()
}

// ---------------------------------------------------------------------------------
// The checks
// ---------------------------------------------------------------------------------

/// Collects the failures of one tree, each naming the seed, size, state and
/// algorithm.
struct Failures<'a> {
    tree: &'a RandomTree,
    bodies: usize,
    list: Vec<String>,
}

impl Failures<'_> {
    fn fail(&mut self, state: usize, what: &str, detail: String) {
        self.list.push(format!(
            "seed {:#x}, {}-body tree, state {state}: {what}: {detail}",
            self.tree.seed, self.bodies
        ));
    }

    /// `got` against the reference `want`, normwise relative with the given floor.
    fn compare(&mut self, state: usize, what: &str, got: &[f64], want: &[f64], floor: f64) {
        if got.len() != want.len() {
            self.fail(
                state,
                what,
                format!("{} values, the reference has {}", got.len(), want.len()),
            );
            return;
        }
        let e = rel_err(got, want, floor);
        if e.is_nan() || e >= TOL {
            self.fail(
                state,
                what,
                format!("relative error {e:e}\n  graph:     {got:?}\n  reference: {want:?}"),
            );
        }
    }

    /// A regressor: values, and the reference's entries at structural zeros.
    fn compare_regressor(&mut self, state: usize, what: &str, (got, zeros): (Vec<f64>, Vec<usize>), want: &[f64]) {
        self.compare(state, what, &got, want, 1e-9);
        if let Some(&k) = zeros.iter().find(|&&k| want[k].abs() > STRUCTURAL_ZERO) {
            self.fail(
                state,
                what,
                format!("entry {k} is a structural zero, the reference has {:e}", want[k]),
            );
        }
    }
}

/// Structural zeros of a regressor with `rows` rows per joint and `cols` columns per
/// body: exactly the blocks of joints that do not support the body.
fn check_structure(model: &Model, y: &[Option<NodeId>], rows: usize, cols: usize) -> Result<(), String> {
    let n = model.dof();
    let width = cols * n;
    assert_eq!(y.len(), rows * n * width);
    for (k, e) in y.iter().enumerate() {
        let (joint, body) = (k / width / rows + 1, k % width / cols + 1);
        if e.is_some() != model.supports(joint, body) {
            return Err(format!(
                "entry {k} (joint {joint}, body {body}) is {}",
                if e.is_some() { "computed" } else { "a structural zero" }
            ));
        }
    }
    Ok(())
}

/// Everything for one tree: its build and merged inertials, then every algorithm on
/// `STATES` random states with perturbed parameters.
fn check_tree(tree: &RandomTree, bodies: usize) -> Vec<String> {
    let mut failures = Failures {
        tree,
        bodies,
        list: Vec::new(),
    };
    let model = tree.build();
    let n = model.dof();
    if n != bodies {
        failures.fail(0, "build", format!("{n} degrees of freedom, {bodies} moving joints"));
        return failures.list;
    }
    // Merged inertials: each body's standard parameters from its links.
    for body in &model.bodies {
        let link = tree
            .links
            .iter()
            .position(|l| l.name == body.name)
            .expect("a generated link");
        let want = tree.expected_params(link);
        let e = rel_err(&body.inertial.standard_params(), &want, 1e-9);
        if e.is_nan() || e >= 1e-12 {
            failures.fail(
                0,
                &format!("merged inertial of {}", body.name),
                format!("relative error {e:e}"),
            );
        }
    }

    let reference = Reference::new(&model);
    let g = Graph::new();
    let sym = Symbolic::build(&g, &model);
    for (what, y, rows, cols) in [
        ("torque regressor structure", &sym.torque_regressor, 1, 10),
        ("wrench regressor structure", &sym.wrench_regressor, 6, 10),
        ("principal regressor structure", &sym.principal_regressor, 1, 4),
    ] {
        if let Err(e) = check_structure(&model, y, rows, cols) {
            failures.fail(0, what, e);
        }
    }

    let zeros = vec![0.0; n];
    for (k, s) in sample_states(&model, STATES, tree.seed).iter().enumerate() {
        let params = perturbed_params(&model, tree.seed ^ (k as u64 + 1), 0.3);
        let (q, v, a, p) = (&s.q[..], &s.v[..], &s.a[..], &params[..]);
        let tau = reference.rnea(q, v, a, p);
        failures.compare(k, "rnea", &eval(&g, &sym.rnea, q, v, a, p), &tau, 1e-9);
        // The bias and gravity torques can vanish exactly (one joint, no gravity):
        // their rounding is then measured against the size of the state's torques.
        let torque_scale = tau.iter().fold(1e-9, |s: f64, x| s.max(x.abs()));
        failures.compare(
            k,
            "nonlinear effects",
            &eval(&g, &sym.nonlinear_effects, q, v, &zeros, p),
            &reference.nonlinear_effects(q, v, p),
            torque_scale,
        );
        failures.compare(
            k,
            "generalized gravity",
            &eval(&g, &sym.gravity, q, &zeros, &zeros, p),
            &reference.generalized_gravity(q, p),
            torque_scale,
        );
        let poses: Vec<f64> = reference.forward_kinematics(q).iter().flat_map(pose_vec).collect();
        failures.compare(
            k,
            "forward kinematics",
            &eval(&g, &sym.forward_kinematics, q, &zeros, &zeros, &[]),
            &poses,
            1e-9,
        );
        let wrenches: Vec<f64> = reference
            .joint_wrenches(q, v, a, p)
            .iter()
            .flat_map(wrench_vec)
            .collect();
        failures.compare(
            k,
            "joint wrenches",
            &eval(&g, &sym.wrenches, q, v, a, p),
            &wrenches,
            1e-9,
        );
        failures.compare(
            k,
            "crba",
            &eval(&g, &sym.crba, q, &zeros, &zeros, p),
            &row_major(&reference.crba(q, p)),
            1e-9,
        );
        // aba at the torque of (q, v, a): the reference's, and a itself back.
        let qdd = eval(&g, &sym.aba, q, v, &tau, p);
        failures.compare(k, "aba", &qdd, &reference.aba(q, v, &tau, p), 1.0);
        failures.compare(k, "aba(rnea(a)) = a", &qdd, a, 1.0);
        failures.compare_regressor(
            k,
            "torque regressor",
            eval_regressor(&g, &sym.torque_regressor, s),
            &row_major(&reference.joint_torque_regressor(q, v, a)),
        );
        failures.compare_regressor(
            k,
            "wrench regressor",
            eval_regressor(&g, &sym.wrench_regressor, s),
            &row_major(&reference.joint_wrench_regressor(q, v, a)),
        );
        failures.compare_regressor(
            k,
            "principal regressor",
            eval_regressor(&g, &sym.principal_regressor, s),
            &row_major(&reference.principal_regressor(q, v, a)),
        );
        let blocks: Vec<f64> = reference
            .body_regressor(q, v, a)
            .iter()
            .flat_map(|m| (0..6).flat_map(move |r| (0..4).map(move |c| m[(r, c)])))
            .collect();
        failures.compare(
            k,
            "body regressors",
            &eval(&g, &sym.body_regressors, q, v, a, &[]),
            &blocks,
            1e-9,
        );
        let resultants: Vec<f64> = reference
            .body_resultants(q, v, a, p)
            .iter()
            .flat_map(wrench_vec)
            .collect();
        failures.compare(
            k,
            "body resultants",
            &eval(&g, &sym.body_resultants, q, v, a, p),
            &resultants,
            1e-9,
        );
    }
    if !failures.list.is_empty() {
        failures.list.push(format!(
            "seed {:#x}: the tree, merged, with gravity {:?}:\n{}",
            tree.seed,
            model.gravity,
            dyngen_model::to_urdf(&model)
        ));
    }
    failures.list
}

fn all_trees() -> impl Iterator<Item = (RandomTree, usize)> {
    SIZES.flat_map(|bodies| {
        (0..SEEDS_PER_SIZE).map(move |k| (RandomTree::generate(tree_seed(bodies, k), bodies), bodies))
    })
}

#[test]
fn graph_agrees_with_reference_on_random_trees() {
    let mut failures = Vec::new();
    let mut trees = 0;
    for (tree, bodies) in all_trees() {
        failures.extend(check_tree(&tree, bodies));
        trees += 1;
    }
    assert!(trees >= 60, "only {trees} trees");
    assert!(
        failures.is_empty(),
        "{} failures on {trees} random trees (the first {SHOWN} shown):\n{}",
        failures.len(),
        failures[..failures.len().min(SHOWN)].join("\n")
    );
}

/// The generator really produces the variety the agreement test relies on.
#[test]
fn generator_covers_every_kind_of_tree() {
    let (mut revolute, mut continuous, mut prismatic) = (0, 0, 0);
    let (mut aligned, mut skew, mut limited, mut merged, mut branched) = (0, 0, 0, 0, 0);
    let (mut quarter_turn, mut general_turn, mut non_diagonal, mut gravities) = (0, 0, 0, Vec::new());
    for (tree, bodies) in all_trees() {
        let model = tree.build();
        assert_eq!(model.dof(), bodies, "seed {:#x}", tree.seed);
        for j in &model.joints {
            match j.kind {
                JointKind::Revolute => revolute += 1,
                JointKind::Continuous => continuous += 1,
                JointKind::Prismatic => prismatic += 1,
                JointKind::Spherical | JointKind::FreeFlyer | JointKind::Planar => {
                    panic!("random trees have one-coordinate joints")
                }
            }
            if j.axis.iter().filter(|&&c| c == 0.0).count() == 2 {
                aligned += 1;
            } else {
                skew += 1;
            }
            if j.origin.rotation.iter().flatten().all(|&x| x == 0.0 || x.abs() == 1.0) {
                quarter_turn += 1;
            } else {
                general_turn += 1;
            }
            limited += usize::from(j.limits.is_some());
            assert!(
                (math::norm(&j.axis) - 1.0).abs() < 1e-15,
                "seed {:#x}: axis not normalised",
                tree.seed
            );
        }
        merged += model.bodies.iter().filter(|b| !b.merged.is_empty()).count();
        non_diagonal += model
            .bodies
            .iter()
            .filter(|b| b.inertial.inertia[0][1] != 0.0 || b.inertial.inertia[1][2] != 0.0)
            .count();
        branched += usize::from((0..=model.dof()).any(|i| model.children(i).len() > 1));
        if !gravities.contains(&tree.gravity) {
            gravities.push(tree.gravity);
        }
    }
    let counts = [
        ("revolute", revolute),
        ("continuous", continuous),
        ("prismatic", prismatic),
        ("axis-aligned axes", aligned),
        ("skew axes", skew),
        ("quarter-turn origins", quarter_turn),
        ("general origins", general_turn),
        ("limited joints", limited),
        ("bodies with merged links", merged),
        ("non-diagonal inertias", non_diagonal),
        ("branched trees", branched),
    ];
    for (what, count) in counts {
        assert!(count >= 5, "only {count} {what}: {counts:?}");
    }
    assert!(gravities.contains(&DEFAULT_GRAVITY) && gravities.contains(&[0.0; 3]) && gravities.len() >= 5);
}

/// Hash-consing: building an algorithm a second time in the same graph finds every
/// node already there.
#[test]
fn building_rnea_twice_adds_no_nodes() {
    for (tree, bodies) in all_trees() {
        let model = tree.build();
        let g = Graph::new();
        let first = ids(&algo::rnea(&g, &model, Inputs::Full).tau);
        let len = g.len();
        let second = ids(&algo::rnea(&g, &model, Inputs::Full).tau);
        assert_eq!(
            g.len(),
            len,
            "seed {:#x}, {bodies}-body tree: rnea built twice added {} nodes",
            tree.seed,
            g.len() - len
        );
        assert_eq!(first, second, "seed {:#x}, {bodies}-body tree", tree.seed);
    }
}

/// A difference and its mirror share one node whichever is built first, and
/// building either again adds nothing.
#[test]
fn a_difference_and_its_mirror_share_one_node() {
    let g = Graph::new();
    let (x, y) = (g.input(ARG_Q, 0), g.input(ARG_Q, 1));
    let first = y - x;
    let mirror = x - y;
    let len = g.len();
    let again = y - x;
    assert_eq!(g.len(), len, "building y − x again added {:?}", again);
    assert_eq!(again.id(), first.id());
    assert_eq!(
        (-mirror).id(),
        first.id(),
        "x − y is {mirror:?}, not −(y − x) = −{first:?}"
    );
}

/// Central differences of `f` at `x`, one column per coordinate (row-major result,
/// `rows × x.len()`).
fn central(x: &[f64], h: f64, f: impl Fn(&[f64]) -> Vec<f64>) -> Vec<f64> {
    let cols: Vec<Vec<f64>> = (0..x.len())
        .map(|c| {
            let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
            xp[c] += h;
            xm[c] -= h;
            f(&xp).iter().zip(f(&xm)).map(|(p, m)| (p - m) / (2.0 * h)).collect()
        })
        .collect();
    let rows = cols.first().map_or(0, Vec::len);
    (0..rows).flat_map(|r| cols.iter().map(move |c| c[r])).collect()
}

/// The control kernels through the graph on every random tree: each frame's
/// Jacobian against differences of its placement (the angular part from `Ṙ Rᵀ`), its
/// velocity against `J v`, its classical acceleration against differences of the
/// velocity along `q + t v + t² a / 2`; the centre of mass against the reference's
/// poses and its Jacobian against differences; the derivatives of rnea and aba
/// against differences of the reference's rnea and aba.
#[test]
fn control_kernels_agree_with_differences_on_random_trees() {
    use dyngen_codegen::derivatives;
    use dyngen_codegen::frames;
    let mut failures = Vec::new();
    let mut frames_checked = 0;
    for (tree, _) in all_trees() {
        let model = tree.build();
        let n = model.dof();
        let reference = Reference::new(&model);
        let mut fail = |what: &str, k: usize, got: &[f64], want: &[f64], tol: f64| {
            let e = rel_err(got, want, 1.0);
            if e.is_nan() || e >= tol {
                failures.push(format!(
                    "seed {:#x} sample {k}: {what}: relative error {e:e}",
                    tree.seed
                ));
            }
        };
        let zeros = vec![0.0; n];
        let h = 1e-6;
        for (k, s) in sample_states(&model, 2, tree.seed).iter().enumerate() {
            let params = perturbed_params(&model, tree.seed ^ (k as u64 + 7), 0.3);
            let (q, v, a, p) = (&s.q[..], &s.v[..], &s.a[..], &params[..]);
            for f in 0..model.frames.len() {
                frames_checked += 1;
                let g = Graph::new();
                let place = frames::build_placement(&g, &model, f);
                let jac = eval(&g, &frames::build_jacobian(&g, &model, f), q, &zeros, &zeros, &[]);
                let pose_at = |x: &[f64]| eval(&g, &place, x, &zeros, &zeros, &[]);
                let pose = pose_at(q);
                fail("placement beside the Jacobian", k, &jac[..12], &pose, 1e-14);
                let dpose = central(q, h, pose_at);
                // Linear rows: d(translation)/dq.
                fail("frame Jacobian, linear", k, &jac[12..12 + 3 * n], &dpose[9 * n..], 1e-7);
                // Angular rows: the axial vector of (dR/dq_c) Rᵀ.
                let r = |i: usize, j: usize| pose[3 * i + j];
                let dr = |i: usize, j: usize, c: usize| dpose[(3 * i + j) * n + c];
                let w = |c: usize, i: usize, j: usize| (0..3).map(|m| dr(i, m, c) * r(j, m)).sum::<f64>();
                let angular: Vec<f64> = [(2, 1), (0, 2), (1, 0)]
                    .iter()
                    .flat_map(|&(i, j)| (0..n).map(move |c| w(c, i, j)).collect::<Vec<_>>())
                    .collect();
                fail("frame Jacobian, angular", k, &jac[12 + 3 * n..], &angular, 1e-7);
                // J̇: the derivative of the Jacobian along q + t v.
                let jd = frames::build_jacobian_time_variation(&g, &model, f);
                let jd_val = eval(&g, &jd, q, v, &zeros, &[]);
                let jac_at = |t: f64| {
                    let qt: Vec<f64> = (0..n).map(|i| q[i] + t * v[i]).collect();
                    eval(&g, &jd[12..12 + 6 * n], &qt, v, &zeros, &[])
                };
                let (jp, jm) = (jac_at(h), jac_at(-h));
                let fd: Vec<f64> = jp.iter().zip(&jm).map(|(x, y)| (x - y) / (2.0 * h)).collect();
                fail("frame Jacobian time variation", k, &jd_val[12 + 6 * n..], &fd, 1e-6);
                let motion = frames::build_motion(&g, &model, f);
                let m = eval(&g, &motion, q, v, a, &[]);
                let jv: Vec<f64> = (0..6)
                    .map(|row| (0..n).map(|c| jac[12 + row * n + c] * v[c]).sum())
                    .collect();
                fail("frame velocity = J v", k, &m[12..18], &jv, 1e-12);
                let vel_at = |t: f64| {
                    let qt: Vec<f64> = (0..n).map(|i| q[i] + t * v[i] + 0.5 * t * t * a[i]).collect();
                    let vt: Vec<f64> = (0..n).map(|i| v[i] + t * a[i]).collect();
                    eval(&g, &motion, &qt, &vt, a, &[])[12..18].to_vec()
                };
                let (vp, vm) = (vel_at(h), vel_at(-h));
                let dv: Vec<f64> = (0..6).map(|i| (vp[i] - vm[i]) / (2.0 * h)).collect();
                fail("frame classical acceleration", k, &m[18..24], &dv, 1e-6);
            }
            let g = Graph::new();
            let com = frames::build_com(&g, &model);
            let com_at = |x: &[f64]| eval(&g, &com, x, &zeros, &zeros, p);
            let poses = reference.forward_kinematics(q);
            let mut want = [0.0; 3];
            let mut mass = 0.0;
            for (i, pose) in poses.iter().enumerate() {
                let m = p[10 * i];
                let h = nalgebra::Vector3::new(p[10 * i + 1], p[10 * i + 2], p[10 * i + 3]);
                let c = pose.translation * m + pose.rotation * h;
                for d in 0..3 {
                    want[d] += c[d];
                }
                mass += m;
            }
            fail("centre of mass", k, &com_at(q), &want.map(|x| x / mass), 1e-12);
            let jc = eval(&g, &frames::build_com_jacobian(&g, &model), q, &zeros, &zeros, p);
            fail("centre of mass Jacobian", k, &jc, &central(q, h, com_at), 1e-7);
            // Linear momentum: the centroidal map's first rows are m · J_c.
            let ag = eval(&g, &frames::build_centroidal_map(&g, &model), q, &zeros, &zeros, p);
            let mjc: Vec<f64> = jc.iter().map(|x| x * mass).collect();
            fail("centroidal map, linear rows", k, &ag[..3 * n], &mjc, 1e-12);
            // Ȧ_g: the derivative of A_g along q + t v.
            let g = Graph::new();
            let both = frames::build_centroidal_map_time_variation(&g, &model);
            let got = eval(&g, &both, q, v, &zeros, p);
            fail("A_g beside Ȧ_g", k, &got[..6 * n], &ag, 1e-15);
            let along = |t: f64| {
                let qt: Vec<f64> = (0..n).map(|i| q[i] + t * v[i]).collect();
                eval(&g, &both[..6 * n], &qt, v, &zeros, p)
            };
            let (ap, am) = (along(h), along(-h));
            let fd: Vec<f64> = ap.iter().zip(&am).map(|(x, y)| (x - y) / (2.0 * h)).collect();
            fail("Ȧ_g", k, &got[6 * n..], &fd, 1e-6);

            let g = Graph::new();
            let d = derivatives::rnea_derivatives(&g, &model);
            let flat = |m: &[Vec<Expr<'_>>]| m.iter().flatten().map(|x| x.id()).collect::<Vec<_>>();
            let dq = eval(&g, &flat(&d.dtau_dq), q, v, a, p);
            let dv = eval(&g, &flat(&d.dtau_dv), q, v, a, p);
            fail("∂τ/∂q", k, &dq, &central(q, h, |x| reference.rnea(x, v, a, p)), 1e-6);
            fail("∂τ/∂v", k, &dv, &central(v, h, |x| reference.rnea(q, x, a, p)), 1e-6);
            let tau = reference.rnea(q, v, a, p);
            let g = Graph::new();
            let d = derivatives::aba_derivatives_with(&g, &model, derivatives::Ddq::InverseInertia);
            let ddq = eval(&g, &ids(&d.ddq), q, v, &tau, p);
            fail("aba", k, &ddq, a, 1e-9);
            // Relative to the largest acceleration the differences see.
            let fq = central(q, h, |x| reference.aba(x, v, &tau, p));
            let fv = central(v, h, |x| reference.aba(q, x, &tau, p));
            let ft = central(&tau, h, |x| reference.aba(q, v, x, p));
            let scale = a.iter().fold(1.0f64, |s, x| s.max(x.abs()));
            for (what, m, fd) in [("∂q̈/∂q", &d.ddq_dq, fq), ("∂q̈/∂v", &d.ddq_dv, fv), ("M⁻¹", &d.minv, ft)]
            {
                let got = eval(&g, &flat(m), q, v, &tau, p);
                let e = got.iter().zip(&fd).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
                let size = fd.iter().fold(scale, |s, x| s.max(x.abs()));
                fail(what, k, &[e / size], &[0.0], 1e-6);
            }
        }
    }
    assert!(frames_checked > 200, "only {frames_checked} frames");
    assert!(
        failures.is_empty(),
        "{} failures (the first {SHOWN} shown):\n{}",
        failures.len(),
        failures[..failures.len().min(SHOWN)].join("\n")
    );
}
