//! Base parameters: which combinations of the inertial parameters the joint torques
//! determine.
//!
//! The joint torque regressor ([`crate::regressor`]) is evaluated on [`SAMPLES`]
//! random states, stacked (`W`, `SAMPLES · n` rows), and factored by Householder QR
//! that takes the columns in parameter order and sets aside every column already in
//! the span of those kept. Kept columns are the base; every other column is a fixed
//! combination of them, `W_dep = W_ind R₁₁⁻¹ R₁₂`, so `Y π = Y_b β` with
//!
//! ```text
//! β = K π = π_ind + R₁₁⁻¹ R₁₂ π_dep
//! ```
//!
//! Taking columns in order (rather than pivoting by norm) makes the choice
//! independent of the sample and gives the classical groupings: earlier bodies'
//! parameters absorb later ones (`Izz1 + Iyy2 + …`).
//!
//! The states come from [`structure_states`]: full turns for revolute joints and
//! ±0.5 m for prismatic ones, whatever the limits, so a joint with placeholder limits
//! (`lower = upper = 0`) is not pinned and no parameter is lost.
//!
//! Two independent checks come with every answer: the analysis is repeated with a
//! second seed ([`BaseParams::confirmed`]), and the numerical rank of `W` is counted
//! from its singular values ([`BaseParams::rank_check`]), which must equal the number
//! of columns the QR kept.

use crate::joint_params::{append_joint_columns, joint_param_names, Coulomb};
use crate::math::singular_values;
use crate::names::{principal_param_names, standard_param_names};
use crate::regressor::{principal_from_standard, torque_regressor, PRINCIPAL_PER_BODY, STANDARD_PER_BODY};
use crate::sample::structure_states;
use crate::Model;
use std::fmt;

/// A column whose residual, relative to its own norm, falls below this is in the
/// span of the columns kept before it; a column whose norm, relative to the largest
/// column's, falls below it is zero. The singular-value check counts
/// `σ > RANK_TOLERANCE · σ₁`.
pub const RANK_TOLERANCE: f64 = 1e-8;
/// Random states stacked per analysis (rows = `SAMPLES · n`).
pub const SAMPLES: usize = 40;
/// The seed of the analysis, and the seed of the check that repeats it.
pub const SEEDS: [u64; 2] = [0x5eed_0001, 0x5eed_0002];

/// Which parameters the regressor is linear in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Parameterisation {
    /// `π_i = [m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, 10 per body:
    /// `τ = Y π`.
    Standard,
    /// `θ_i = (m, J1, J2, J3)` with the nominal centre of mass and principal axes,
    /// 4 per body: `τ = Y blkdiag(P_i) θ` ([`crate::PrincipalFrame::p_matrix`]).
    Principal,
    /// The standard parameters followed by the joint parameters `[Ia, Fv, Fc, F0]` of
    /// every joint (`10n + 4n` columns, [`crate::joint_params`]), with the Coulomb
    /// term as `sign(q̇)`: the model identified on a real robot.
    StandardAndJoints,
}

impl Parameterisation {
    /// Parameters per body: 10 or 4.
    pub fn per_body(self) -> usize {
        match self {
            Parameterisation::Standard | Parameterisation::StandardAndJoints => STANDARD_PER_BODY,
            Parameterisation::Principal => PRINCIPAL_PER_BODY,
        }
    }

    /// The parameter names of a model of `n` bodies, each on a joint with one
    /// degree of freedom ([`crate::names`]); [`Parameterisation::names_of`] for any.
    pub fn names(self, n: usize) -> Vec<String> {
        self.names_with(n, n)
    }

    /// The parameter names of `model`: per body, then (joint parameters) per velocity
    /// coordinate.
    pub fn names_of(self, model: &Model) -> Vec<String> {
        self.names_with(model.dof(), model.nv())
    }

    fn names_with(self, bodies: usize, dofs: usize) -> Vec<String> {
        match self {
            Parameterisation::Standard => standard_param_names(bodies),
            Parameterisation::Principal => principal_param_names(bodies),
            Parameterisation::StandardAndJoints => {
                let mut names = standard_param_names(bodies);
                names.extend(joint_param_names(dofs));
                names
            }
        }
    }
}

/// The outcome of a base-parameter analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct BaseParams {
    pub parameterisation: Parameterisation,
    /// Columns of the parameter vector that form the base, ascending.
    pub independent: Vec<usize>,
    /// `K` (b × p, one row per base parameter): `β = K π`, so `Y π = Y_b β` with
    /// `Y_b` the columns `independent` of `Y`.
    pub k: Vec<Vec<f64>>,
    /// A readable formula for each base parameter, e.g. `Izz1 + Iyy2 + 0.1817·m3`.
    pub groupings: Vec<String>,
    /// Whether the analysis repeated with the second seed chose the same columns.
    pub confirmed: bool,
    /// The numerical rank of the stacked regressor from its singular values
    /// (`σ > RANK_TOLERANCE · σ₁`); equal to [`BaseParams::count`] when the QR's
    /// decisions were clear-cut.
    pub rank_check: usize,
}

impl BaseParams {
    /// The number of base parameters `b`.
    pub fn count(&self) -> usize {
        self.independent.len()
    }

    /// Whether both checks agree with the QR: the second seed chose the same columns
    /// and the singular values give the same rank. When this is false the count is
    /// not to be trusted (a tolerance decision was borderline); [`fmt::Display`]
    /// says which check failed.
    pub fn is_consistent(&self) -> bool {
        self.confirmed && self.rank_check == self.count()
    }
}

impl fmt::Display for BaseParams {
    /// `b` base parameters, one grouping per line, then any failed check.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} base parameters:", self.count())?;
        for g in &self.groupings {
            writeln!(f, "  {g}")?;
        }
        if self.rank_check != self.count() {
            writeln!(
                f,
                "warning: the singular values give rank {}, the QR kept {} columns",
                self.rank_check,
                self.count()
            )?;
        }
        if !self.confirmed {
            writeln!(f, "warning: a second sample chose different columns")?;
        }
        Ok(())
    }
}

/// The base parameters of `model` in `parameterisation`: the QR of the module docs
/// on the regressor stacked over [`SAMPLES`] states from [`structure_states`] with
/// `SEEDS[0]`, confirmed with `SEEDS[1]`, and the rank counted from the singular
/// values of the same stacked matrix.
pub fn analyse(model: &Model, parameterisation: Parameterisation) -> BaseParams {
    analysed(model, parameterisation, None)
}

/// [`analyse`] on some rows of the dynamics only: `rows` lists the velocity
/// coordinates whose equations are measured (e.g. `0..6`, the base wrench of a
/// floating base from contact forces, or `6..nv`, the joint torques alone).
pub fn analyse_rows(model: &Model, parameterisation: Parameterisation, rows: &[usize]) -> BaseParams {
    analysed(model, parameterisation, Some(rows))
}

/// [`analyse`] on the rows `keep` (all when `None`).
fn analysed(model: &Model, parameterisation: Parameterisation, keep: Option<&[usize]>) -> BaseParams {
    let names = parameterisation.names_of(model);
    // The second seed's analysis runs on a thread of its own (on the 31-joint
    // humanoid's standard and joint parameters: 1.2 s on one core, 0.65 s on two).
    let (mut base, rank_check, second) = std::thread::scope(|s| {
        let second = s.spawn(|| from_stacked(&stacked(model, parameterisation, SEEDS[1], keep), &names));
        let first = stacked(model, parameterisation, SEEDS[0], keep);
        let sv = singular_values(&first);
        let largest = sv.first().copied().unwrap_or(0.0);
        let rank_check = sv.iter().filter(|&&s| s > RANK_TOLERANCE * largest && s > 0.0).count();
        let base = from_stacked(&first, &names);
        // A panic in the analysis is a bug; it is carried over as it was.
        let second = second.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
        (base, rank_check, second)
    });
    base.confirmed = second.independent == base.independent;
    BaseParams {
        parameterisation,
        rank_check,
        ..base
    }
}

/// The regressor stacked over [`SAMPLES`] structure states drawn with `seed`,
/// keeping only the rows `keep` of each state (all when `None`).
fn stacked(model: &Model, parameterisation: Parameterisation, seed: u64, keep: Option<&[usize]>) -> Vec<Vec<f64>> {
    let mut rows = Vec::with_capacity(SAMPLES * model.nv());
    for s in structure_states(model, SAMPLES, seed) {
        let mut y = torque_regressor(model, &s.q, &s.v, &s.a);
        match parameterisation {
            Parameterisation::Standard => {}
            Parameterisation::Principal => y = principal_from_standard(model, &y),
            Parameterisation::StandardAndJoints => append_joint_columns(&mut y, &s.v, &s.a, Coulomb::Sign),
        }
        match keep {
            None => rows.extend(y),
            Some(k) => rows.extend(y.into_iter().enumerate().filter(|(d, _)| k.contains(d)).map(|(_, r)| r)),
        }
    }
    rows
}

/// The ordered QR of the module docs on a stacked regressor whose columns `names`
/// names; `confirmed` and `rank_check` are left for the caller.
fn from_stacked(rows: &[Vec<f64>], names: &[String]) -> BaseParams {
    let p = names.len();
    let (perm, r, rank) = ordered_qr(rows, p);
    // W_dep = W_ind R11⁻¹ R12, so β = π_ind + (R11⁻¹ R12) π_dep.
    let mut coef = vec![vec![0.0; p - rank]; rank];
    for (d, col) in (rank..p).enumerate() {
        for row in (0..rank).rev() {
            let mut x = r[row][col];
            for k in row + 1..rank {
                x -= r[row][k] * coef[k][d];
            }
            coef[row][d] = x / r[row][row];
        }
    }
    let mut order: Vec<usize> = (0..rank).collect();
    order.sort_by_key(|&k| perm[k]);
    let independent: Vec<usize> = order.iter().map(|&k| perm[k]).collect();
    let k: Vec<Vec<f64>> = order
        .iter()
        .map(|&row| {
            let mut kr = vec![0.0; p];
            kr[perm[row]] = 1.0;
            for (d, col) in (rank..p).enumerate() {
                kr[perm[col]] = clean(coef[row][d]);
            }
            kr
        })
        .collect();
    let groupings = k.iter().map(|kr| grouping(kr, names)).collect();
    BaseParams {
        parameterisation: Parameterisation::Standard,
        independent,
        k,
        groupings,
        confirmed: true,
        rank_check: rank,
    }
}

/// Rounds away the noise of the factorisation: |x| < 1e-10 → 0, and values within
/// 1e-10 of ±1 → ±1, so exact groupings print exactly. Other values are snapped to a
/// short decimal when one lies within [`SNAP_RELATIVE`] (see [`snap_decimal`]).
fn clean(x: f64) -> f64 {
    if x.abs() < 1e-10 {
        0.0
    } else if (x.abs() - 1.0).abs() < 1e-10 {
        x.signum()
    } else {
        snap_decimal(x)
    }
}

/// How close, relative to its magnitude, a coefficient of `K` must be to a decimal of
/// at most [`SNAP_DIGITS`] significant digits to be replaced by it. The entries of `K`
/// are exact sums of products of the model's numbers (`0.425² = 0.180625`), which are
/// short decimals when the description's numbers are; the factorisation returns them
/// with its own rounding, some hundred ulps (`0.18062499999999998`). The snap is far
/// below what the factorisation resolves, so it changes nothing a test can see.
const SNAP_RELATIVE: f64 = 1e-13;
const SNAP_DIGITS: usize = 10;

/// `x`, or the decimal with the fewest significant digits (at most [`SNAP_DIGITS`])
/// within [`SNAP_RELATIVE`] of it.
fn snap_decimal(x: f64) -> f64 {
    (0..SNAP_DIGITS)
        .filter_map(|p| format!("{x:.p$e}").parse::<f64>().ok())
        .find(|y| (y - x).abs() <= SNAP_RELATIVE * x.abs())
        .unwrap_or(x)
}

fn grouping(kr: &[f64], names: &[String]) -> String {
    let mut s = String::new();
    for (c, &x) in kr.iter().enumerate() {
        if x == 0.0 {
            continue;
        }
        let sign = if x < 0.0 { "−" } else { "+" };
        let mag = x.abs();
        let term = if mag == 1.0 {
            names[c].clone()
        } else {
            format!("{}·{}", format_coef(mag), names[c])
        };
        if s.is_empty() {
            s = if x < 0.0 { format!("−{term}") } else { term };
        } else {
            s.push_str(&format!(" {sign} {term}"));
        }
    }
    s
}

fn format_coef(x: f64) -> String {
    let t = format!("{x:.6}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Householder QR of `a` (m × p, rows), columns in order, each column
/// kept only if it is not numerically zero and its residual after the reflectors of
/// the kept columns exceeds `RANK_TOLERANCE` times its own norm. Returns the column
/// order (kept first, then set aside, each in parameter order), `R` in that order
/// (rows, p wide) and the rank.
fn ordered_qr(a: &[Vec<f64>], p: usize) -> (Vec<usize>, Vec<Vec<f64>>, usize) {
    let m = a.len();
    // Column-major: the reflectors work on whole columns.
    let mut cols: Vec<Vec<f64>> = (0..p).map(|c| a.iter().map(|r| r[c]).collect()).collect();
    let norm = |x: &[f64]| x.iter().map(|x| x * x).sum::<f64>().sqrt();
    let original: Vec<f64> = cols.iter().map(|c| norm(c)).collect();
    let largest = original.iter().copied().fold(0.0, f64::max);
    let mut kept = Vec::new();
    let mut dropped = Vec::new();
    let mut k = 0;
    for c in 0..p {
        let residual = norm(&cols[c][k.min(m)..]);
        // Algebraic cancellations leave rounding noise where a column is exactly
        // zero, so "zero" is relative to the largest column.
        if k >= m || original[c] <= RANK_TOLERANCE * largest || residual <= RANK_TOLERANCE * original[c] {
            dropped.push(c);
            continue;
        }
        kept.push(c);
        crate::math::reflect(&mut cols, c, k, residual);
        k += 1;
    }
    let rank = kept.len();
    let perm: Vec<usize> = kept.iter().chain(dropped.iter()).copied().collect();
    let r: Vec<Vec<f64>> = (0..rank)
        .map(|row| perm.iter().map(|&c| cols[c][row]).collect())
        .collect();
    (perm, r, rank)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With rotor inertia and friction every joint adds 4 columns, all identifiable
    /// but the rotor inertias of the first two joints: the first moves only with body
    /// 1 about the same axis, and with the second axis perpendicular to and meeting
    /// the first, the second's rotor enters exactly as body 2's `Izz` does (the
    /// classical regrouping `ZZ2R = ZZ2 + Ia2`).
    #[test]
    fn joint_parameters_add_four_columns_per_joint_but_the_first_two_rotors() {
        let model = crate::parse_urdf(include_str!("../../robots/ur5/ur5.urdf")).unwrap();
        let standard = analyse(&model, Parameterisation::Standard);
        let all = analyse(&model, Parameterisation::StandardAndJoints);
        assert!(all.is_consistent(), "{all}");
        assert_eq!(all.count(), standard.count() + 4 * 6 - 2, "{all}");
        assert_eq!(Parameterisation::StandardAndJoints.names(6).len(), 84);
        assert_eq!(&all.independent[..standard.count()], &standard.independent[..]);
        for (ia, izz) in [(60, "Izz1"), (64, "Izz2")] {
            assert!(!all.independent.contains(&ia), "{all}");
            let name = &Parameterisation::StandardAndJoints.names(6)[ia];
            assert!(
                all.groupings
                    .iter()
                    .any(|g| g.starts_with(izz) && g.contains(name.as_str())),
                "{all}"
            );
        }
        for c in 60..84 {
            if c != 60 && c != 64 {
                assert!(all.independent.contains(&c), "column {c} of {all}");
            }
        }
    }

    #[test]
    fn coefficients_snap_to_short_decimals_only_when_within_rounding() {
        assert_eq!(clean(0.18062499999999998), 0.180625);
        assert_eq!(clean(-0.42500000000000004), -0.425);
        let irrational = std::f64::consts::PI / 10.0;
        assert_eq!(clean(irrational), irrational);
        assert_eq!(clean(3e-11), 0.0);
        assert_eq!(clean(-1.0 + 1e-12), -1.0);
    }
    use crate::regressor::{joint_torque_regressor, principal_regressor};
    use crate::sample::sample_states;

    fn robot(path: &str) -> Model {
        let file = format!("{}/../{path}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{file}: {e}"));
        crate::parse_urdf(&text).unwrap_or_else(|e| panic!("{file}: {e}"))
    }

    #[test]
    fn qr_finds_rank_and_combinations() {
        // Columns: c0, c1 = 2 c0, c2 independent, c3 = c0 − c2.
        let base = [[1.0, 0.5], [2.0, -1.0], [0.3, 0.7], [-1.0, 2.0], [0.0, 1.0]];
        let rows: Vec<Vec<f64>> = base.iter().map(|r| vec![r[0], 2.0 * r[0], r[1], r[0] - r[1]]).collect();
        let names: Vec<String> = ["a", "b", "c", "d"].map(String::from).to_vec();
        let b = from_stacked(&rows, &names);
        assert_eq!(b.independent, vec![0, 2]);
        assert_eq!(b.groupings, vec!["a + 2·b + d", "c − d"]);
    }

    #[test]
    fn shipped_robots_have_their_known_ranks() {
        for (path, standard) in [
            ("robots/ur5/ur5.urdf", 36),
            ("robots/puma560/puma560.urdf", 36),
            ("robots/panda/panda.urdf", 43),
        ] {
            let model = robot(path);
            let b = analyse(&model, Parameterisation::Standard);
            assert_eq!(b.count(), standard, "{path}\n{b}");
            assert!(b.is_consistent(), "{path}\n{b}");
            let p = analyse(&model, Parameterisation::Principal);
            assert!(p.is_consistent(), "{path}\n{p}");
            assert!(p.count() <= 4 * model.dof() && p.count() <= standard, "{path}\n{p}");
        }
    }

    /// Every fixture robot: the count equals the rank of Pinocchio's own regressor
    /// stacked over the fixture's 50 states (`σ > 10⁻⁸ σ₁`), as the Pinocchio
    /// comparison of generated code checks it.
    #[test]
    fn counts_match_the_rank_of_pinocchios_stacked_regressor() {
        for (name, path) in crate::regressor::PINOCCHIO_FIXTURES {
            let file = format!("{}/../tests/fixtures/{name}.json", env!("CARGO_MANIFEST_DIR"));
            let fx: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
            let vec = |v: &serde_json::Value| -> Vec<f64> {
                v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
            };
            let rows: Vec<Vec<f64>> = fx["samples"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|s| s["Y"].as_array().unwrap().iter().map(vec).collect::<Vec<_>>())
                .collect();
            let sv = singular_values(&rows);
            let pinocchio = sv.iter().filter(|&&x| x > RANK_TOLERANCE * sv[0]).count();
            let mut model = robot(path);
            let g = vec(&fx["gravity"]);
            model.gravity = [g[0], g[1], g[2]];
            let b = analyse(&model, Parameterisation::Standard);
            assert_eq!(b.count(), pinocchio, "{name}\n{b}");
            assert!(b.is_consistent(), "{name}\n{b}");
        }
    }

    /// `Y_b β = Y π` on states the analysis never saw, in both parameterisations.
    #[test]
    fn base_regressor_reproduces_the_torques() {
        for path in [
            "robots/ur5/ur5.urdf",
            "robots/panda/panda.urdf",
            "robots/gripper_arm/gripper_arm.urdf",
            "tests/fixtures/tree12.urdf",
        ] {
            let model = robot(path);
            for (param, full) in [
                (Parameterisation::Standard, model.standard_params()),
                (Parameterisation::Principal, crate::principal_params(&model)),
            ] {
                let b = analyse(&model, param);
                assert!(b.is_consistent(), "{path}\n{b}");
                let beta: Vec<f64> =
                    b.k.iter()
                        .map(|kr| kr.iter().zip(&full).map(|(k, x)| k * x).sum())
                        .collect();
                for s in sample_states(&model, 10, 99) {
                    let y = match param {
                        Parameterisation::Standard => joint_torque_regressor(&model, &s.q, &s.v, &s.a),
                        Parameterisation::Principal => principal_regressor(&model, &s.q, &s.v, &s.a),
                        Parameterisation::StandardAndJoints => unreachable!("not among the cases"),
                    }
                    .unwrap();
                    for row in &y {
                        let tau: f64 = row.iter().zip(&full).map(|(a, b)| a * b).sum();
                        let base: f64 = b.independent.iter().zip(&beta).map(|(&c, x)| row[c] * x).sum();
                        assert!(
                            (tau - base).abs() < 1e-9 * tau.abs().max(1.0),
                            "{path}: {tau} vs {base}"
                        );
                    }
                }
            }
        }
    }

    /// A spatial arm: shoulder yaw `j1`, shoulder pitch `j2` of type `kind2` with
    /// `limit2` (an empty string: no `<limit>`), then `j3` of type `kind3` with
    /// `limit3`. Pinning the shoulder pitch hides parameters (it is what turns
    /// gravity against the links beyond it).
    fn arm(kind2: &str, limit2: &str, kind3: &str, limit3: &str) -> Model {
        let link = |name: &str, com: &str| {
            format!(
                r#"<link name="{name}"><inertial><mass value="2"/><origin xyz="{com}"/>
                <inertia ixx="0.05" iyy="0.04" izz="0.03" ixy="0.001" ixz="0.002" iyz="0.003"/></inertial></link>"#
            )
        };
        let urdf = format!(
            r#"<robot name="arm"><link name="base"/>
            {}{}{}
            <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
              <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
            <joint name="j2" type="{kind2}"><parent link="l1"/><child link="l2"/>
              <origin xyz="0 0 0.3" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>{limit2}</joint>
            <joint name="j3" type="{kind3}"><parent link="l2"/><child link="l3"/>
              <origin xyz="0.4 0 0"/><axis xyz="0.6 0 0.8"/>{limit3}</joint>
            </robot>"#,
            link("l1", "0 0.02 0.1"),
            link("l2", "0.2 0 0.01"),
            link("l3", "0.15 0.01 0"),
        );
        crate::parse_urdf(&urdf).unwrap()
    }

    fn lim(lower: f64, upper: f64) -> String {
        format!(r#"<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/>"#)
    }

    #[test]
    fn placeholder_narrow_and_missing_limits_do_not_change_the_base() {
        let wide = lim(-3.0, 3.0);
        for param in [Parameterisation::Standard, Parameterisation::Principal] {
            let reference = analyse(&arm("revolute", &wide, "revolute", &wide), param);
            assert!(reference.is_consistent(), "{reference}");
            for (kind, limit) in [
                ("revolute", lim(0.0, 0.0)),
                ("revolute", lim(0.0, 0.01)),
                ("revolute", lim(0.0, 3.0)),
                ("revolute", lim(-0.2, -0.1)),
                ("continuous", String::new()),
            ] {
                let b = analyse(&arm(kind, &limit, "revolute", &wide), param);
                assert!(b.is_consistent(), "{kind} {limit}\n{b}");
                assert_eq!(b.independent, reference.independent, "{kind} {limit}");
            }
        }
    }

    #[test]
    fn placeholder_limits_on_a_prismatic_joint_do_not_change_the_base() {
        let wide = lim(-3.0, 3.0);
        let reference = analyse(
            &arm("revolute", &wide, "prismatic", &lim(-0.3, 0.3)),
            Parameterisation::Standard,
        );
        for limit in [lim(0.0, 0.0), lim(0.0, 0.001), lim(-100.0, 100.0)] {
            let b = analyse(&arm("revolute", &wide, "prismatic", &limit), Parameterisation::Standard);
            assert!(b.is_consistent(), "{limit}\n{b}");
            assert_eq!(b.independent, reference.independent, "{limit}");
        }
    }

    /// The failure the limit-free sampling prevents: within 0/0 limits the shoulder
    /// pitch never moves, and the stacked regressor loses rank.
    #[test]
    fn sampling_within_placeholder_limits_would_lose_parameters() {
        let wide = lim(-3.0, 3.0);
        let model = arm("revolute", &lim(0.0, 0.0), "revolute", &wide);
        let mut rows = Vec::new();
        for s in sample_states(&model, SAMPLES, SEEDS[0]) {
            rows.extend(torque_regressor(&model, &s.q, &s.v, &s.a));
        }
        let pinned = from_stacked(&rows, &Parameterisation::Standard.names(3));
        let b = analyse(&model, Parameterisation::Standard);
        assert!(pinned.count() < b.count(), "{} vs {}", pinned.count(), b.count());
    }

    #[test]
    fn planar_two_link_arm_has_the_textbook_base() {
        // Both axes along z, link 1 of length 0.5 along x, gravity in the plane.
        let urdf = r#"<robot name="planar"><link name="base"/>
          <link name="l1"><inertial><mass value="3"/><origin xyz="0.25 0.01 0"/>
            <inertia ixx="0.01" iyy="0.06" izz="0.065" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <link name="l2"><inertial><mass value="2"/><origin xyz="0.2 -0.01 0"/>
            <inertia ixx="0.01" iyy="0.03" izz="0.035" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
          <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/>
            <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/></joint></robot>"#;
        let mut model = crate::parse_urdf(urdf).unwrap();
        model.gravity = [0.0, -9.81, 0.0];
        let b = analyse(&model, Parameterisation::Standard);
        assert!(b.is_consistent(), "{b}");
        let names = Parameterisation::Standard.names(2);
        let chosen: Vec<&str> = b.independent.iter().map(|&c| names[c].as_str()).collect();
        assert_eq!(chosen, ["mx1", "my1", "Izz1", "mx2", "my2", "Izz2"]);
        assert_eq!(
            b.groupings,
            ["mx1 + 0.5·m2", "my1", "Izz1 + 0.25·m2", "mx2", "my2", "Izz2"]
        );
    }

    /// The DSL's planar arm as written to URDF: the same base as the generated code
    /// documents for it, in both parameterisations.
    #[test]
    fn planar2_fixture_keeps_the_generated_groupings() {
        let mut model = robot("tests/fixtures/planar2.urdf");
        model.gravity = [0.0, -9.81, 0.0];
        let b = analyse(&model, Parameterisation::Standard);
        assert_eq!(b.independent, [1, 2, 9, 11, 12, 19]);
        assert_eq!(
            b.groupings,
            ["mx1 + 0.5·m2", "my1", "Izz1 + 0.25·m2", "mx2", "my2", "Izz2"]
        );
        let p = analyse(&model, Parameterisation::Principal);
        assert_eq!(p.independent, [0, 3, 4, 7]);
        assert_eq!(p.groupings, ["m1", "J3_1", "m2", "J3_2"]);
        assert!(b.is_consistent() && p.is_consistent());
    }

    #[test]
    fn display_names_a_failed_check() {
        let mut b = analyse(&arm("continuous", "", "continuous", ""), Parameterisation::Standard);
        let text = b.to_string();
        assert!(text.starts_with(&format!("{} base parameters:\n", b.count())), "{text}");
        assert!(!text.contains("warning"), "{text}");
        b.rank_check += 1;
        b.confirmed = false;
        let text = b.to_string();
        assert!(
            text.contains("the singular values give rank") && text.contains("second sample"),
            "{text}"
        );
        assert!(!b.is_consistent());
    }
}
