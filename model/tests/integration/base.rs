//! The base-parameter analysis against a plain reference on random trees: the same
//! stacked regressor, factored one column at a time by Gram–Schmidt with
//! reorthogonalisation, with no blocking, no row structure and no faer. The
//! analysis must keep the same columns and give the same `K` (to 1e-9).

use dyngen_model::base::{analyse, state_count, Parameterisation, RANK_TOLERANCE, SEEDS};
use dyngen_model::joint_params::{append_joint_columns, Coulomb};
use dyngen_model::regressor::{joint_torque_regressor, principal_regressor};
use dyngen_model::sample::{structure_states, SplitMix64};
use dyngen_model::{parse_urdf, Model};

/// A random tree of `n` moving joints: each link hangs off a random earlier one,
/// one joint in five is prismatic, one in three has an axis along x, y or z with an
/// axis-aligned origin (which makes neighbouring axes parallel or perpendicular and
/// so adds exact regroupings), the rest have random axes and placements.
fn random_tree(n: usize, seed: u64) -> Model {
    let mut rng = SplitMix64::new(seed);
    let mut u = |lo: f64, hi: f64| rng.uniform(lo, hi);
    let mut urdf = String::from(r#"<robot name="tree"><link name="l0"/>"#);
    for k in 1..=n {
        let (a, b, c) = (u(1e-3, 0.02), u(1e-3, 0.02), u(1e-3, 0.02));
        let (ixy, ixz, iyz) = (u(-1.0, 1.0) * 1e-4, u(-1.0, 1.0) * 1e-4, u(-1.0, 1.0) * 1e-4);
        urdf += &format!(
            r#"<link name="l{k}"><inertial><origin xyz="{} {} {}"/><mass value="{}"/>
            <inertia ixx="{}" iyy="{}" izz="{}" ixy="{ixy}" ixz="{ixz}" iyz="{iyz}"/></inertial></link>"#,
            u(-0.05, 0.05),
            u(-0.05, 0.05),
            u(0.0, 0.2),
            u(0.5, 3.0),
            b + c,
            a + c,
            a + b,
        );
        let parent = if k == 1 {
            0
        } else {
            (u(0.0, 1.0) * k as f64) as usize % k
        };
        let kind = if k % 5 == 0 { "prismatic" } else { "revolute" };
        let pick = (u(0.0, 3.0) as usize).min(2);
        let (axis, origin) = if k % 3 == 0 {
            let mut axis = [0.0; 3];
            axis[pick] = 1.0;
            let rpy = ["0 0 0", "1.5707963267948966 0 0", "0 1.5707963267948966 0"][pick];
            (axis, format!(r#"<origin xyz="{} 0 0" rpy="{rpy}"/>"#, u(0.0, 0.4)))
        } else {
            let v = [u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)];
            let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(0.1);
            (
                [v[0] / r, v[1] / r, v[2] / r],
                format!(
                    r#"<origin xyz="{} {} {}" rpy="{} {} {}"/>"#,
                    u(-0.1, 0.1),
                    u(-0.1, 0.1),
                    u(0.05, 0.3),
                    u(-1.0, 1.0),
                    u(-1.0, 1.0),
                    u(-1.0, 1.0)
                ),
            )
        };
        urdf += &format!(
            r#"<joint name="j{k}" type="{kind}"><parent link="l{parent}"/><child link="l{k}"/>{origin}
            <axis xyz="{} {} {}"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#,
            axis[0], axis[1], axis[2]
        );
    }
    urdf += "</robot>";
    parse_urdf(&urdf).unwrap()
}

/// The regressor of `param` stacked over the states the analysis draws with the
/// first seed, as columns.
fn stacked_columns(model: &Model, param: Parameterisation) -> Vec<Vec<f64>> {
    let p = param.names_of(model).len();
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for s in structure_states(model, state_count(model.nv(), p), SEEDS[0]) {
        let mut y = match param {
            Parameterisation::Principal => principal_regressor(model, &s.q, &s.v, &s.a),
            _ => joint_torque_regressor(model, &s.q, &s.v, &s.a),
        }
        .unwrap();
        if param == Parameterisation::StandardAndJoints {
            append_joint_columns(&mut y, &s.v, &s.a, Coulomb::Sign);
        }
        rows.extend(y);
    }
    (0..p).map(|c| rows.iter().map(|r| r[c]).collect()).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The definition, one column at a time: column `c` is kept when it is not zero
/// (relative to the largest column) and its distance to the span of the columns kept
/// before it exceeds `RANK_TOLERANCE` times its norm; a column set aside is the
/// least-squares combination of the columns kept before it, which gives its entries
/// in `K` (the row of each kept column gets the coefficient).
fn reference(cols: &[Vec<f64>]) -> (Vec<usize>, Vec<Vec<f64>>) {
    let p = cols.len();
    let norms: Vec<f64> = cols.iter().map(|c| dot(c, c).sqrt()).collect();
    let largest = norms.iter().copied().fold(0.0, f64::max);
    // Orthonormal basis q of the kept columns, and r with kept column t = Σ r[t][i] q_i.
    let mut q: Vec<Vec<f64>> = Vec::new();
    let mut r: Vec<Vec<f64>> = Vec::new();
    let mut kept = Vec::new();
    // For each set-aside column: (column, its coordinates on q so far).
    let mut aside: Vec<(usize, Vec<f64>)> = Vec::new();
    for c in 0..p {
        let mut v = cols[c].clone();
        let mut coord = vec![0.0; q.len()];
        for _ in 0..2 {
            for (i, qi) in q.iter().enumerate() {
                let f = dot(qi, &v);
                coord[i] += f;
                v.iter_mut().zip(qi).for_each(|(x, y)| *x -= f * y);
            }
        }
        let residual = dot(&v, &v).sqrt();
        if norms[c] <= RANK_TOLERANCE * largest || residual <= RANK_TOLERANCE * norms[c] {
            aside.push((c, coord));
            continue;
        }
        coord.push(residual);
        q.push(v.iter().map(|x| x / residual).collect());
        r.push(coord);
        kept.push(c);
    }
    let rank = kept.len();
    let mut k = vec![vec![0.0; p]; rank];
    for (t, &c) in kept.iter().enumerate() {
        k[t][c] = 1.0;
    }
    for (d, coord) in aside {
        // Back substitution: Σ_t x_t r[t][i] = coord[i] for i < coord.len().
        let b = coord.len();
        let mut x = vec![0.0; b];
        for i in (0..b).rev() {
            let s: f64 = (i + 1..b).map(|t| x[t] * r[t][i]).sum();
            x[i] = (coord[i] - s) / r[i][i];
        }
        for (t, xt) in x.into_iter().enumerate() {
            k[t][d] = xt;
        }
    }
    (kept, k)
}

fn compare(model: &Model, param: Parameterisation, what: &str) {
    let b = analyse(model, param);
    assert!(b.is_consistent(), "{what}\n{b}");
    let (kept, k) = reference(&stacked_columns(model, param));
    assert_eq!(b.independent, kept, "{what}");
    let mut worst: f64 = 0.0;
    for (lib, reference) in b.k.iter().zip(&k) {
        for (x, y) in lib.iter().zip(reference) {
            worst = worst.max((x - y).abs() / y.abs().max(1.0));
        }
    }
    assert!(worst < 1e-9, "{what}: K differs by {worst:e}");
}

#[test]
fn analysis_matches_the_column_by_column_reference_on_random_trees() {
    for (n, seed) in [(3, 1), (6, 2), (9, 3), (14, 4)] {
        let model = random_tree(n, seed);
        for param in [
            Parameterisation::Standard,
            Parameterisation::Principal,
            Parameterisation::StandardAndJoints,
        ] {
            compare(&model, param, &format!("{n} joints, seed {seed}, {param:?}"));
        }
    }
}

/// Above `ALL_SAMPLES_UP_TO` columns the analysis stacks fewer states and proves the
/// rank from bounds instead of an SVD; 44 joints with joint parameters are 616
/// columns.
#[test]
fn large_analysis_matches_the_reference() {
    let model = random_tree(44, 5);
    let p = Parameterisation::StandardAndJoints.names_of(&model).len();
    assert!(p > dyngen_model::base::ALL_SAMPLES_UP_TO);
    assert!(state_count(model.nv(), p) < dyngen_model::base::SAMPLES);
    compare(&model, Parameterisation::StandardAndJoints, "44 joints");
}
