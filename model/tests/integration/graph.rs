//! The graph-theoretic matrices of a branched tree: S with its base row, T = S⁻¹,
//! the body-joint vectors and D = C T.

use dyngen_model::graph::{
    body_joint_vectors, check_path_matrix, d_matrix, incidence, path_matrix, weighted_body_joint_matrix,
};
use dyngen_model::parse_urdf;

/// base ─ j1 ─ b1 ─ j2 ─ b2
///              └── j3 ─ b3 ─ j4 ─ b4
fn tree() -> dyngen_model::Model {
    let link = |name: &str, com: &str| {
        format!(
            r#"<link name="{name}"><inertial><origin xyz="{com}"/><mass value="1"/>
            <inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial></link>"#
        )
    };
    let joint = |name: &str, parent: &str, child: &str, xyz: &str| {
        format!(
            r#"<joint name="{name}" type="continuous"><parent link="{parent}"/><child link="{child}"/>
            <origin xyz="{xyz}"/><axis xyz="0 0 1"/></joint>"#
        )
    };
    let text = format!(
        r#"<robot name="tree"><link name="base"/>{}{}{}{}{}{}{}{}</robot>"#,
        link("b1", "0 0 0.1"),
        link("b2", "0.2 0 0"),
        link("b3", "0 0.2 0"),
        link("b4", "0.1 0.1 0"),
        joint("j1", "base", "b1", "0 0 0.5"),
        joint("j2", "b1", "b2", "0 0 0.3"),
        joint("j3", "b1", "b3", "0.1 0 0.2"),
        joint("j4", "b3", "b4", "0 0.4 0"),
    );
    parse_urdf(&text).unwrap()
}

#[test]
fn incidence_and_path_matrix_of_a_branched_tree() {
    let m = tree();
    let s = incidence(&m);
    assert_eq!(
        s,
        vec![
            vec![-1, 0, 0, 0],
            vec![1, -1, -1, 0],
            vec![0, 1, 0, 0],
            vec![0, 0, 1, -1],
            vec![0, 0, 0, 1],
        ]
    );
    let t = path_matrix(&m);
    // T_ai = 1 iff joint a is on the path from body i to the base.
    assert_eq!(
        t,
        vec![vec![1, 1, 1, 1], vec![0, 1, 0, 0], vec![0, 0, 1, 1], vec![0, 0, 0, 1]]
    );
    assert!(check_path_matrix(&s, &t), "S T = I and S0 T = -1");
    let mut wrong = t.clone();
    wrong[1][3] = 1;
    assert!(!check_path_matrix(&s, &wrong));
}

#[test]
fn body_joint_vectors_and_d() {
    let m = tree();
    let c = body_joint_vectors(&m);
    // From the base origin to joint 1.
    assert_eq!(c[0][0], [0.0, 0.0, 0.5]);
    // From b1's centre of mass (0, 0, 0.1) to joint 1 (its origin) and to joints 2, 3.
    assert_eq!(c[1][0], [0.0, 0.0, -0.1]);
    assert!((c[1][1][2] - 0.2).abs() < 1e-15);
    assert!((c[1][2][0] - 0.1).abs() < 1e-15 && (c[1][2][2] - 0.1).abs() < 1e-15);
    // Zero where S is zero.
    let s = incidence(&m);
    for i in 0..=m.dof() {
        for a in 0..m.dof() {
            if s[i][a] == 0 {
                assert_eq!(c[i][a], [0.0; 3]);
            }
        }
    }
    // D = C T, entry by entry.
    let cw = weighted_body_joint_matrix(&m);
    let t = path_matrix(&m);
    let d = d_matrix(&m);
    for i in 0..=m.dof() {
        for j in 0..m.dof() {
            let mut want = [0.0; 3];
            for a in 0..m.dof() {
                for k in 0..3 {
                    want[k] += cw[i][a][k] * f64::from(t[a][j]);
                }
            }
            assert_eq!(d[i][j], want);
        }
    }
    // Body 4's column: D_i4 sums the weighted vectors along its path to the base.
    assert_eq!(
        d[3][3],
        [
            cw[3][2][0] + cw[3][3][0],
            cw[3][2][1] + cw[3][3][1],
            cw[3][2][2] + cw[3][3][2]
        ]
    );
}
