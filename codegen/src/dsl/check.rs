//! Rules that span more than one token: one function per rule, each reporting at
//! the token that breaks it. Parts that failed to parse are skipped (their error is
//! already recorded), and rules that need the size `n` run only once the incidence
//! matrix has a consistent shape, so one mistake does not cascade.

use super::ast::{Body, BodyTable, FrameTable, Joint, JointList, Matrix, Robot, Shape, VectorTable};
use super::ctxt::{Ctxt, Loc};
use super::symbol;
use dyngen_model::graph::{self, IncidenceError, IncidenceTree};
use dyngen_model::JointKind;
use proc_macro2::Span;
use std::collections::HashSet;

/// Runs every rule; returns the tree the incidence matrix describes, if it does.
pub fn check(cx: &Ctxt, robot: &Robot) -> Option<IncidenceTree> {
    check_required_keywords(cx, robot);
    check_urdf_excludes_inline(cx, robot);

    // `n` once the matrix is (n+1) x n; `s` and the tree once it describes a tree.
    // Rules that compare with `S` wait for a valid tree: against a wrong matrix they
    // would only echo its mistake.
    let (mut n, mut valid) = (None, None);
    if let Some(m) = &robot.incidence.value {
        n = check_incidence_shape(cx, m);
        valid = check_incidence_tree(cx, m, n);
    }

    if let Some(list) = &robot.joints.value {
        check_joint_count(cx, list, n);
        for (a, joint) in list.joints.iter().enumerate() {
            let Some(joint) = joint else { continue };
            check_axis_nonzero(cx, joint);
            check_limits_ordered(cx, joint);
            check_continuous_has_no_limits(cx, joint);
            check_free_is_first(cx, joint, a);
        }
    }

    if let Some(table) = &robot.body_joint_vectors.value {
        check_vector_indices(cx, table, n);
        check_vector_duplicates(cx, table);
        if let Some((s, _)) = &valid {
            check_vectors_match_incidence(cx, table, s);
        }
    }

    if let Some(table) = &robot.bodies.value {
        check_body_not_base(cx, table);
        check_body_indices(cx, table, n);
        check_body_duplicates(cx, table);
        check_bodies_complete(cx, table, n);
        for body in table.entries.iter().filter_map(|e| e.body.as_ref()) {
            check_mass_positive(cx, body);
            check_cylinder_dimensions(cx, body);
            check_moments_positive(cx, body);
            check_triangle_inequality(cx, body);
        }
    }

    if let Some(table) = &robot.frames.value {
        check_frame_names(cx, table, n);
        check_frame_bodies(cx, table, n);
        check_frame_numbers(cx, table);
    }
    valid.map(|(_, tree)| tree)
}

/// A robot needs a name and a source; without them there is nothing to generate.
fn check_required_keywords(cx: &Ctxt, robot: &Robot) {
    let inline = [
        (symbol::INCIDENCE, robot.incidence.is_given()),
        (symbol::JOINTS, robot.joints.is_given()),
        (symbol::BODY_JOINT_VECTORS, robot.body_joint_vectors.is_given()),
        (symbol::BODIES, robot.bodies.is_given()),
    ];
    let inline_started = robot.gravity.is_given() || robot.frames.is_given() || inline.iter().any(|(_, given)| *given);
    let mut missing: Vec<String> = Vec::new();
    if !robot.name.is_given() {
        missing.push(format!("`{}`", symbol::NAME));
    }
    let form = if robot.urdf.is_given() {
        format!(
            "a URDF robot is `{}: .., {}: \"file.urdf\"`",
            symbol::NAME,
            symbol::URDF
        )
    } else {
        if inline_started {
            missing.extend(inline.iter().filter(|(_, given)| !given).map(|(s, _)| format!("`{s}`")));
        } else {
            missing.push("the robot's source".to_string());
        }
        let keys: Vec<String> = std::iter::once(symbol::NAME)
            .chain(symbol::INLINE_REQUIRED.iter().copied())
            .map(|s| format!("{s}: .."))
            .collect();
        let optional: Vec<String> = symbol::INLINE_OPTIONAL.iter().map(|s| format!("`{s}`")).collect();
        let inline_form = format!(
            "an inline robot is `{}` ({} optional)",
            keys.join(", "),
            optional.join(" and ")
        );
        if inline_started {
            inline_form
        } else {
            format!(
                "a robot is either `{}: .., {}: \"file.urdf\"` or {inline_form}",
                symbol::NAME,
                symbol::URDF
            )
        }
    };
    if missing.is_empty() {
        return;
    }
    let list = match missing.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => missing.join(""),
    };
    // Point at the name when there is one: the whole call would underline everything.
    let at = robot
        .name
        .key
        .as_ref()
        .map_or(Loc::at(Span::call_site()), |k| Loc::at(k.span()));
    cx.error_spanned_by(at, format!("missing {list}; {form}"));
}

/// A robot comes from one source; mixing them would leave one silently ignored.
fn check_urdf_excludes_inline(cx: &Ctxt, robot: &Robot) {
    if !robot.urdf.is_given() {
        return;
    }
    let keys = [
        &robot.gravity.key,
        &robot.incidence.key,
        &robot.joints.key,
        &robot.body_joint_vectors.key,
        &robot.bodies.key,
        &robot.frames.key,
    ];
    for key in keys.into_iter().flatten() {
        cx.error_spanned_by(
            key,
            format!(
                "`{key}` cannot be combined with `{}`: a robot comes either from a URDF file \
                 (`{}` and `{}` only) or from an inline description",
                symbol::URDF,
                symbol::NAME,
                symbol::URDF
            ),
        );
    }
}

/// `S` must be (n+1) × n for the graph theory to apply; returns `n` when it is.
fn check_incidence_shape(cx: &Ctxt, m: &Matrix) -> Option<usize> {
    if m.rows.iter().any(Option::is_none) {
        return None;
    }
    let rows: Vec<_> = m.rows.iter().flatten().collect();
    let Some(first) = rows.first() else {
        cx.error_spanned_by(
            m.loc,
            "the incidence matrix is empty; n joints need n + 1 rows (body 0, the base, first) \
             of n entries (joints 1..n)",
        );
        return None;
    };
    let cols = first.entries.len();
    let mut consistent = true;
    for (i, row) in rows.iter().enumerate().skip(1) {
        if row.entries.len() != cols {
            consistent = false;
            cx.error_spanned_by(
                row.loc,
                format!(
                    "row {i} (body {i}) has {} entries but row 0 has {cols}; every row has one \
                     entry per joint",
                    row.entries.len()
                ),
            );
        }
    }
    if !consistent {
        return None;
    }
    if cols == 0 {
        cx.error_spanned_by(
            m.loc,
            "the incidence matrix has no columns; every joint is a column, and a robot needs at \
             least one joint",
        );
        return None;
    }
    if rows.len() != cols + 1 {
        cx.error_spanned_by(
            m.loc,
            format!(
                "the incidence matrix has {} rows and {cols} columns; n joints need n + 1 rows \
                 (bodies 0..n, the base first) and n columns (joints 1..n)",
                rows.len()
            ),
        );
        return None;
    }
    Some(cols)
}

/// Every column must have one +1 and one -1 and the bodies must form a tree rooted
/// at the base (docs/design.md, "The paper's graph theory"); returns the entries and the tree when it does.
fn check_incidence_tree(cx: &Ctxt, m: &Matrix, n: Option<usize>) -> Option<(Vec<Vec<i64>>, IncidenceTree)> {
    n?;
    let rows: Vec<_> = m.rows.iter().flatten().collect();
    let s: Option<Vec<Vec<i64>>> = rows
        .iter()
        .map(|r| r.entries.iter().map(|e| e.value).collect())
        .collect();
    let s = s?;
    let errors = match graph::check_incidence(&s) {
        Ok(tree) => return Some((s, tree)),
        Err(errors) => errors,
    };
    let entry = |row: usize, col: usize| rows[row].entries[col].loc;
    for e in &errors {
        match *e {
            IncidenceError::Entry { row, col, value } => {
                cx.error_spanned_by(
                    entry(row, col),
                    format!(
                        "entry {value} (body {row}, joint {}): incidence entries are -1, 0 or 1",
                        col + 1
                    ),
                );
            }
            IncidenceError::Column { col, plus, minus } => {
                let s = &s;
                let at = |v: i64, k: usize| (0..s.len()).filter(|&r| s[r][col] == v).nth(k);
                let row = (if plus > 1 { at(1, 1) } else { None })
                    .or(if minus > 1 { at(-1, 1) } else { None })
                    .or_else(|| (0..s.len()).find(|&r| s[r][col] != 0))
                    .unwrap_or(0);
                cx.error_spanned_by(
                    entry(row, col),
                    format!(
                        "joint {}'s column has {plus} entries +1 and {minus} entries -1; a joint \
                         connects exactly two bodies, so its column has one +1 and one -1",
                        col + 1
                    ),
                );
            }
            IncidenceError::Disconnected { row } => cx.error_spanned_by(
                rows[row].loc,
                format!(
                    "body {row} is not connected to the base: no chain of joints leads from it \
                     to body 0; the bodies must form one tree rooted at body 0"
                ),
            ),
            IncidenceError::Loop { col } => {
                let ends: Vec<usize> = (0..s.len()).filter(|&r| s[r][col] != 0).collect();
                let loc = match ends[..] {
                    [a, .., b] => entry(a, col).to(entry(b, col)),
                    _ => m.loc,
                };
                let between = match ends[..] {
                    [a, b] => format!(" between bodies {a} and {b}"),
                    _ => String::new(),
                };
                cx.error_spanned_by(
                    loc,
                    format!(
                        "joint {}{between} closes a loop: those bodies are already connected \
                         through other joints; the bodies must form a tree (one path from \
                         every body to the base)",
                        col + 1
                    ),
                );
            }
            // Ruled out by `check_incidence_shape`; kept so no error is ever lost.
            IncidenceError::Shape { .. } | IncidenceError::RowLength { .. } => cx.error_spanned_by(m.loc, e),
        }
    }
    None
}

/// Joints are matched to columns by position, so the counts must agree.
fn check_joint_count(cx: &Ctxt, list: &JointList, n: Option<usize>) {
    let Some(n) = n else { return };
    let k = list.joints.len();
    if k != n {
        cx.error_spanned_by(
            list.loc,
            format!(
                "{k} joint{} given but the incidence matrix has {n} column{}; give one joint per \
                 column, in column order",
                plural(k),
                plural(n)
            ),
        );
    }
}

/// A zero axis defines no motion.
fn check_axis_nonzero(cx: &Ctxt, joint: &Joint) {
    let Some(axis) = &joint.axis else { return };
    if dyngen_model::math::norm(&axis.value) < 1e-12 {
        cx.error_spanned_by(
            axis.loc,
            "the joint axis is zero; give a direction such as `z`, `-x` or `[0.0, 0.6, 0.8]`",
        );
    }
}

/// An empty range of motion is a typo, not a robot.
fn check_limits_ordered(cx: &Ctxt, joint: &Joint) {
    let Some(l) = &joint.limits else { return };
    if l.lower.value > l.upper.value {
        cx.error_spanned_by(
            l.loc,
            format!(
                "lower limit {} is above upper limit {}; write `limits: [lower, upper]`",
                l.lower.value, l.upper.value
            ),
        );
    }
}

/// A continuous joint is by definition a revolute joint without limits, and a ball
/// joint, a free flyer or a planar joint has no single coordinate to limit; limits on
/// them would be silently dropped.
fn check_continuous_has_no_limits(cx: &Ctxt, joint: &Joint) {
    let several = match joint.kind {
        JointKind::Spherical | JointKind::FreeFlyer => Some(
            "a `spherical` or `free` joint has no position limits (its coordinates are a quaternion); remove `limits`",
        ),
        JointKind::Planar => {
            Some("a `planar` joint has no position limits (it has three coordinates); remove `limits`")
        }
        _ => None,
    };
    if let (Some(message), Some(l)) = (several, &joint.limits) {
        cx.error_spanned_by(joint.kind_loc.to(l.key_loc), message);
    }
    if let (JointKind::Continuous, Some(l)) = (joint.kind, &joint.limits) {
        cx.error_spanned_by(
            joint.kind_loc.to(l.key_loc),
            format!(
                "a `{}` joint has no limits; use `{}(axis, {}: [lower, upper])` for a limited \
                 rotation",
                symbol::CONTINUOUS,
                symbol::REVOLUTE,
                symbol::LIMITS
            ),
        );
    }
}

/// A free flyer is the floating base: joint 1, between the base (body 0) and body 1.
fn check_free_is_first(cx: &Ctxt, joint: &Joint, column: usize) {
    if joint.kind == JointKind::FreeFlyer && column != 0 {
        cx.error_spanned_by(
            joint.kind_loc,
            format!(
                "a `{}` joint is the floating base: it must be joint 1 (the first column of the incidence \
                 matrix), between the base (body 0) and body 1; this is joint {}",
                symbol::FREE,
                column + 1
            ),
        );
    }
}

/// `c_ia` exists only for bodies 0..n and joints 1..n.
fn check_vector_indices(cx: &Ctxt, table: &VectorTable, n: Option<usize>) {
    let Some(n) = n else { return };
    for e in &table.entries {
        if !(0..=n as i64).contains(&e.body.value) {
            cx.error_spanned_by(
                e.body.loc,
                format!("body {} does not exist; bodies are 0 (the base) to {n}", e.body.value),
            );
        }
        if !(1..=n as i64).contains(&e.joint.value) {
            cx.error_spanned_by(
                e.joint.loc,
                format!("joint {} does not exist; joints are 1 to {n}", e.joint.value),
            );
        }
    }
}

/// Two values for one `c_ia`: which one is meant is anyone's guess.
fn check_vector_duplicates(cx: &Ctxt, table: &VectorTable) {
    let mut seen = HashSet::new();
    for e in &table.entries {
        if !seen.insert((e.body.value, e.joint.value)) {
            cx.error_spanned_by(
                e.key_loc,
                format!(
                    "duplicate body-joint vector ({}, {}); each (body, joint) pair appears once",
                    e.body.value, e.joint.value
                ),
            );
        }
    }
}

/// `c_ia` is given exactly where body `i` touches joint `a`, i.e. `S_ia ≠ 0`: a
/// missing one leaves a joint without a location, an extra one is a mistaken index.
fn check_vectors_match_incidence(cx: &Ctxt, table: &VectorTable, s: &[Vec<i64>]) {
    let entry_of = |i: usize, a: usize| s.get(i).and_then(|row| row.get(a.checked_sub(1)?));
    let mut given = HashSet::new();
    for e in &table.entries {
        let (Ok(i), Ok(a)) = (usize::try_from(e.body.value), usize::try_from(e.joint.value)) else {
            continue;
        };
        given.insert((i, a));
        if entry_of(i, a) == Some(&0) {
            cx.error_spanned_by(
                e.loc,
                format!(
                    "body {i} does not touch joint {a} (the incidence matrix has 0 there), so \
                     there is no vector c_{i},{a}; remove this entry or fix the matrix"
                ),
            );
        }
    }
    let missing: Vec<String> = s
        .iter()
        .enumerate()
        .flat_map(|(i, row)| {
            row.iter()
                .enumerate()
                .filter(|(_, &v)| v != 0)
                .map(move |(col, _)| (i, col + 1))
        })
        .filter(|key| !given.contains(key))
        .map(|(i, a)| format!("({i}, {a})"))
        .collect();
    if !missing.is_empty() {
        cx.error_spanned_by(
            table.loc,
            format!(
                "missing body-joint vector{} {}: every nonzero entry (body i, joint a) of the \
                 incidence matrix needs `(i, a): [x, y, z]`, from body i's centre of mass (the \
                 base frame origin for body 0) to joint a, in body i's frame",
                plural(missing.len()),
                missing.join(", ")
            ),
        );
    }
}

/// The base is fixed: an inertial on it would be silently ignored.
fn check_body_not_base(cx: &Ctxt, table: &BodyTable) {
    for e in table.entries.iter().filter(|e| e.index.value == 0) {
        cx.error_spanned_by(
            e.index.loc,
            "body 0 is the fixed base and has no inertial; give the moving bodies 1 to n",
        );
    }
}

/// Bodies are rows 1..n of the incidence matrix.
fn check_body_indices(cx: &Ctxt, table: &BodyTable, n: Option<usize>) {
    let Some(n) = n else { return };
    for e in &table.entries {
        if e.index.value < 0 || e.index.value > n as i64 {
            cx.error_spanned_by(
                e.index.loc,
                format!(
                    "body {} does not exist; the moving bodies are 1 to {n} (rows 1 to {n} of the \
                     incidence matrix)",
                    e.index.value
                ),
            );
        }
    }
}

/// Two inertials for one body: which one is meant is anyone's guess.
fn check_body_duplicates(cx: &Ctxt, table: &BodyTable) {
    let mut seen = HashSet::new();
    for e in &table.entries {
        if !seen.insert(e.index.value) {
            cx.error_spanned_by(
                e.index.loc,
                format!("duplicate body {}; each body is given once", e.index.value),
            );
        }
    }
}

/// Every moving body needs mass properties: dynamics without them are undefined.
fn check_bodies_complete(cx: &Ctxt, table: &BodyTable, n: Option<usize>) {
    let Some(n) = n else { return };
    let given: HashSet<i64> = table.entries.iter().map(|e| e.index.value).collect();
    let missing: Vec<String> = (1..=n as i64)
        .filter(|i| !given.contains(i))
        .map(|i| i.to_string())
        .collect();
    if !missing.is_empty() {
        cx.error_spanned_by(
            table.loc,
            format!(
                "missing bod{} {}: every moving body 1 to {n} needs `i: {}(..)` or `i: {}(..)`",
                if missing.len() == 1 { "y" } else { "ies" },
                missing.join(", "),
                symbol::PRINCIPAL,
                symbol::CYLINDER
            ),
        );
    }
}

/// A massless moving body makes the mass matrix singular.
fn check_mass_positive(cx: &Ctxt, body: &Body) {
    let m = body.shape.mass();
    if m.value <= 0.0 {
        cx.error_spanned_by(
            m.loc,
            format!("mass {} is not positive; a body needs a mass > 0 kg", m.value),
        );
    }
}

/// A cylinder of no radius or length is not a solid.
fn check_cylinder_dimensions(cx: &Ctxt, body: &Body) {
    let Shape::Cylinder { radius, length, .. } = &body.shape else {
        return;
    };
    for (what, x) in [("radius", radius), ("length", length)] {
        if x.value <= 0.0 {
            cx.error_spanned_by(
                x.loc,
                format!("cylinder {what} {} is not positive; give it in m, > 0", x.value),
            );
        }
    }
    if body.shape.moments().iter().any(|j| !j.is_finite()) {
        cx.error_spanned_by(body.kind_loc, "this cylinder's moments of inertia overflow an f64");
    }
}

/// A real body has positive principal moments (zero only for ideal points and rods).
fn check_moments_positive(cx: &Ctxt, body: &Body) {
    let Shape::Principal { moments, .. } = &body.shape else {
        return;
    };
    for (k, j) in moments.parts.iter().enumerate() {
        if j.value <= 0.0 {
            cx.error_spanned_by(
                j.loc,
                format!(
                    "principal moment J{} = {} is not positive; moments of inertia are > 0 kg m²",
                    k + 1,
                    j.value
                ),
            );
        }
    }
}

/// Each principal moment is at most the sum of the other two for any real mass
/// distribution (`J1 + J2 - J3 = 2∫z² dm ≥ 0`); identification relies on it.
fn check_triangle_inequality(cx: &Ctxt, body: &Body) {
    let Shape::Principal { moments, .. } = &body.shape else {
        return;
    };
    let j = moments.value();
    if j.iter().any(|&x| x <= 0.0) {
        return; // reported by `check_moments_positive`
    }
    // The model's rule, so the DSL and URDF accept the same bodies.
    if let Some(k) = dyngen_model::desc::triangle_violation(j) {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        cx.error_spanned_by(
            moments.loc,
            format!(
                "principal moments break the triangle inequality: J{} = {} exceeds J{} + J{} \
                 = {}; no rigid body has one moment larger than the sum of the other two",
                k + 1,
                j[k],
                a.min(b) + 1,
                a.max(b) + 1,
                rounded(j[a] + j[b])
            ),
        );
    }
}

/// A frame names a link of its own: two frames of one name, or a frame named like a
/// body's link (`body0` to `bodyn`), would make one name mean two links.
fn check_frame_names(cx: &Ctxt, table: &FrameTable, n: Option<usize>) {
    let mut seen = HashSet::new();
    for e in &table.entries {
        let name = e.name.to_string();
        if !seen.insert(name.clone()) {
            cx.error_spanned_by(
                &e.name,
                format!("duplicate frame `{name}`; each frame name appears once"),
            );
            continue;
        }
        let Some(n) = n else { continue };
        let body = name
            .strip_prefix("body")
            .and_then(|k| k.parse::<usize>().ok().filter(|i| i.to_string() == k));
        if let Some(i) = body.filter(|&i| i <= n) {
            cx.error_spanned_by(
                &e.name,
                format!(
                    "frame name `{name}` is the link of body {i}; the bodies' links are `body0` to `body{n}`, so a \
                     frame needs another name, such as `tool`"
                ),
            );
        }
    }
}

/// A frame is fixed to one of the bodies 0..n.
fn check_frame_bodies(cx: &Ctxt, table: &FrameTable, n: Option<usize>) {
    let Some(n) = n else { return };
    for f in table.entries.iter().filter_map(|e| e.frame.as_ref()) {
        if !(0..=n as i64).contains(&f.body.value) {
            cx.error_spanned_by(
                f.body.loc,
                format!(
                    "body {} does not exist; a frame is fixed to one of the bodies 0 (the base) to {n}",
                    f.body.value
                ),
            );
        }
    }
}

/// Every number of a description lies within the model's ±1e9 (SI); checked here so
/// the error points at the number.
fn check_frame_numbers(cx: &Ctxt, table: &FrameTable) {
    let max = dyngen_model::desc::MAX_MAGNITUDE;
    for f in table.entries.iter().filter_map(|e| e.frame.as_ref()) {
        let rest = f
            .rest
            .iter()
            .flat_map(|r| r.parts.iter().map(|p| (p, "rest angle", "rad")));
        let position = f.position.parts.iter().map(|p| (p, "position", "m"));
        for (x, what, unit) in position.chain(rest) {
            if x.value.abs() > max {
                cx.error_spanned_by(
                    x.loc,
                    format!(
                        "frame {what} {} is out of range; give it in {unit}, within ±{max:e}",
                        x.value
                    ),
                );
            }
        }
    }
}

/// `x` to 12 significant digits, so a sum reads `0.105`, not `0.10500000000000001`.
fn rounded(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}
