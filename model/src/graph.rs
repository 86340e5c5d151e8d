//! The Roberson–Wittenburg description of a tree (docs/design.md, "The paper's graph theory"): incidence matrix `S`
//! with its base row, path matrix `T = S⁻¹`, body-joint vectors `c_ia`, `C = [S_ia c_ia]`
//! and `D = C T`. Arcs point to the base: `S_ia = +1` on the outboard body `i⁺(a)`,
//! `−1` on the inboard body `i⁻(a)`.

use crate::ir::Model;
use crate::math::{self, Vec3};

/// A problem in a user-given incidence matrix, with the row (body) or column
/// (joint) it concerns, both 0-based as written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IncidenceError {
    /// The matrix has no rows, or is not (n+1) × n.
    Shape { rows: usize, cols: usize },
    /// A row has a different length from the first.
    RowLength { row: usize, len: usize, expected: usize },
    /// An entry other than −1, 0, +1.
    Entry { row: usize, col: usize, value: i64 },
    /// A column without exactly one +1 and one −1.
    Column { col: usize, plus: usize, minus: usize },
    /// A body not connected to the base (row index).
    Disconnected { row: usize },
    /// A joint that closes a loop (column index).
    Loop { col: usize },
}

impl std::fmt::Display for IncidenceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IncidenceError::Shape { rows, cols } => write!(
                f,
                "incidence matrix is {rows} × {cols}; a tree of n joints has n + 1 rows (base first) and n columns"
            ),
            IncidenceError::RowLength { row, len, expected } => {
                write!(f, "row {row} has {len} entries; every row needs {expected} (one per joint)")
            }
            IncidenceError::Entry { row, col, value } => {
                write!(f, "entry ({row}, {col}) is {value}; entries are -1, 0 or 1")
            }
            IncidenceError::Column { col, plus, minus } => write!(
                f,
                "column {col} (joint {}) has {plus} entries +1 and {minus} entries -1; each joint connects exactly two bodies: one +1 and one -1",
                col + 1
            ),
            IncidenceError::Disconnected { row } => {
                write!(f, "body {row} is not connected to the base (body 0); the bodies must form one tree rooted at the base")
            }
            IncidenceError::Loop { col } => write!(
                f,
                "joint {} closes a loop; the bodies must form a tree (exactly one path from every body to the base)",
                col + 1
            ),
        }
    }
}

/// The tree a valid incidence matrix describes: for each column, which row is the
/// inboard body and which the outboard one, and whether the user wrote it reversed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IncidenceTree {
    pub inboard: Vec<usize>,
    pub outboard: Vec<usize>,
    pub reversed: Vec<bool>,
}

/// Checks a user-given incidence matrix (rows bodies 0..=n, base first; columns
/// joints) and returns the tree it describes. Columns may be oriented either way.
/// Every problem found is returned, not only the first.
pub fn check_incidence(s: &[Vec<i64>]) -> Result<IncidenceTree, Vec<IncidenceError>> {
    let rows = s.len();
    let cols = s.first().map_or(0, |r| r.len());
    let mut errors = Vec::new();
    if rows == 0 || cols + 1 != rows {
        errors.push(IncidenceError::Shape { rows, cols });
    }
    for (row, r) in s.iter().enumerate() {
        if r.len() != cols {
            errors.push(IncidenceError::RowLength {
                row,
                len: r.len(),
                expected: cols,
            });
        }
        for (col, &value) in r.iter().enumerate() {
            if !(-1..=1).contains(&value) {
                errors.push(IncidenceError::Entry { row, col, value });
            }
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let mut ends = Vec::with_capacity(cols);
    for col in 0..cols {
        let plus: Vec<usize> = (0..rows).filter(|&r| s[r][col] == 1).collect();
        let minus: Vec<usize> = (0..rows).filter(|&r| s[r][col] == -1).collect();
        if plus.len() != 1 || minus.len() != 1 {
            errors.push(IncidenceError::Column {
                col,
                plus: plus.len(),
                minus: minus.len(),
            });
        } else {
            ends.push((col, plus[0], minus[0]));
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    // Breadth-first from the base; the end reached first is the inboard body.
    let mut depth = vec![usize::MAX; rows];
    depth[0] = 0;
    let mut inboard = vec![usize::MAX; cols];
    let mut outboard = vec![usize::MAX; cols];
    let mut reversed = vec![false; cols];
    let mut frontier = vec![0usize];
    let mut used = vec![false; cols];
    while !frontier.is_empty() {
        let mut next = Vec::new();
        for &b in &frontier {
            for &(col, p, m) in &ends {
                if used[col] || (p != b && m != b) {
                    continue;
                }
                let other = if p == b { m } else { p };
                used[col] = true;
                if depth[other] != usize::MAX {
                    errors.push(IncidenceError::Loop { col });
                    continue;
                }
                depth[other] = depth[b] + 1;
                inboard[col] = b;
                outboard[col] = other;
                reversed[col] = p == b;
                next.push(other);
            }
        }
        frontier = next;
    }
    for (row, &d) in depth.iter().enumerate() {
        if d == usize::MAX {
            errors.push(IncidenceError::Disconnected { row });
        }
    }
    for (col, &u) in used.iter().enumerate() {
        if !u
            && !errors
                .iter()
                .any(|e| matches!(e, IncidenceError::Loop { col: c } if *c == col))
        {
            // Joints among disconnected bodies: a loop there, or a separate tree.
            let (_, p, m) = ends.iter().find(|e| e.0 == col).copied().unwrap_or((col, 0, 0));
            if depth[p] != usize::MAX || depth[m] != usize::MAX {
                errors.push(IncidenceError::Loop { col });
            }
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    Ok(IncidenceTree {
        inboard,
        outboard,
        reversed,
    })
}

/// `S` with its base row: (n+1) × n, rows bodies 0..=n, columns joints 1..=n.
pub fn incidence(model: &Model) -> Vec<Vec<i8>> {
    let n = model.dof();
    let mut s = vec![vec![0i8; n]; n + 1];
    for a in 1..=n {
        s[a][a - 1] = 1;
        s[model.parent(a)][a - 1] = -1;
    }
    s
}

/// `T = S⁻¹` (n × n, rows joints, columns bodies): `T_ai = 1` iff joint `a` lies on
/// the path from body `i` to the base. Each body's path is walked once (`O(n ·
/// depth)`, not a walk per entry).
pub fn path_matrix(model: &Model) -> Vec<Vec<i8>> {
    let n = model.dof();
    let mut t = vec![vec![0i8; n]; n];
    for i in 1..=n {
        let mut a = i;
        while a != 0 {
            t[a - 1][i - 1] = 1;
            a = model.parent(a);
        }
    }
    t
}

/// Whether `S T = I` (S without its base row) and `S_0 T = −1ᵀ`, exactly.
pub fn check_path_matrix(s: &[Vec<i8>], t: &[Vec<i8>]) -> bool {
    let n = t.len();
    if s.len() != n + 1 {
        return false;
    }
    for i in 0..=n {
        for j in 0..n {
            let v: i32 = (0..n).map(|a| i32::from(s[i][a]) * i32::from(t[a][j])).sum();
            let want = if i == 0 {
                -1
            } else if i == j + 1 {
                1
            } else {
                0
            };
            if v != want {
                return false;
            }
        }
    }
    true
}

/// Body-joint vectors `c_ia` ((n+1) × n): from the centre of mass of body `i` (the
/// base frame origin for body 0) to the point of joint `a` on body `i`, in body `i`'s
/// frame; zero where `S_ia = 0`.
pub fn body_joint_vectors(model: &Model) -> Vec<Vec<Vec3>> {
    let n = model.dof();
    let mut c = vec![vec![[0.0; 3]; n]; n + 1];
    for a in 1..=n {
        let joint = &model.joints[a - 1];
        let p = joint.parent;
        let parent_com = if p == 0 {
            [0.0; 3]
        } else {
            model.bodies[p - 1].inertial.com
        };
        c[p][a - 1] = math::sub(&joint.origin.translation, &parent_com);
        c[a][a - 1] = math::scale(-1.0, &model.bodies[a - 1].inertial.com);
    }
    c
}

/// Weighted body-joint matrix `C_ia = S_ia c_ia`.
pub fn weighted_body_joint_matrix(model: &Model) -> Vec<Vec<Vec3>> {
    let s = incidence(model);
    let mut c = body_joint_vectors(model);
    for (i, row) in c.iter_mut().enumerate() {
        for (a, v) in row.iter_mut().enumerate() {
            *v = math::scale(f64::from(s[i][a]), v);
        }
    }
    c
}

/// `D = C T` ((n+1) × n). Each `c_ia` is in body `i`'s own frame, so `D` is the
/// paper's matrix at the rest configuration where all body frames are parallel.
pub fn d_matrix(model: &Model) -> Vec<Vec<Vec3>> {
    let c = weighted_body_joint_matrix(model);
    let t = path_matrix(model);
    let n = model.dof();
    let mut d = vec![vec![[0.0; 3]; n]; n + 1];
    for i in 0..=n {
        for j in 0..n {
            for a in 0..n {
                if t[a][j] != 0 {
                    d[i][j] = math::add(&d[i][j], &math::scale(f64::from(t[a][j]), &c[i][a]));
                }
            }
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn serial_chain_incidence_checks() {
        let s = vec![vec![-1, 0], vec![1, -1], vec![0, 1]];
        let t = check_incidence(&s).unwrap();
        assert_eq!(t.inboard, vec![0, 1]);
        assert_eq!(t.outboard, vec![1, 2]);
        assert_eq!(t.reversed, vec![false, false]);
    }

    #[test]
    fn reversed_column_is_accepted_and_reported() {
        let s = vec![vec![-1, 0], vec![1, 1], vec![0, -1]];
        let t = check_incidence(&s).unwrap();
        assert_eq!(t.reversed, vec![false, true]);
    }

    #[test]
    fn bad_column_and_loop_and_disconnected() {
        let s = vec![vec![-1, 0], vec![1, 1], vec![0, 0]];
        let e = check_incidence(&s).unwrap_err();
        assert!(
            matches!(
                e[0],
                IncidenceError::Column {
                    col: 1,
                    plus: 1,
                    minus: 0
                }
            ),
            "{e:?}"
        );
        // Two joints between the same two bodies: a loop, and body 2 unreachable.
        let s = vec![vec![-1, -1], vec![1, 1], vec![0, 0]];
        let e = check_incidence(&s).unwrap_err();
        assert!(e.contains(&IncidenceError::Loop { col: 1 }), "{e:?}");
        assert!(e.contains(&IncidenceError::Disconnected { row: 2 }), "{e:?}");
    }
}
