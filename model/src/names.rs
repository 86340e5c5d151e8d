//! Parameter names, one format for the whole project: the per-body name followed by
//! the 1-based body number, with an underscore in between when the per-body name
//! ends in a digit, so that the number stays readable:
//!
//! - standard: `m1, mx1, my1, mz1, Ixx1, Ixy1, Iyy1, Ixz1, Iyz1, Izz1, m2, …`
//! - principal: `m1, J1_1, J2_1, J3_1, m2, …` (`J1_12` is `J1` of body 12, never
//!   `J11` of body 2).
//!
//! These are the names the base-parameter groupings are written in
//! (`Izz1 + 0.25·m2`), and so the names of the generated code's documentation.

/// Per-body standard parameter names in Pinocchio's order
/// `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`.
pub const STANDARD: [&str; 10] = ["m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz"];

/// Per-body principal parameter names, `θ = (m, J1, J2, J3)`.
pub const PRINCIPAL: [&str; 4] = ["m", "J1", "J2", "J3"];

/// `name` of body `body` (1-based): `name` + `body`, with `_` between when `name`
/// ends in a digit.
pub fn param_name(name: &str, body: usize) -> String {
    if name.ends_with(|c: char| c.is_ascii_digit()) {
        format!("{name}_{body}")
    } else {
        format!("{name}{body}")
    }
}

/// The `10 n` standard parameter names, body 1 first: `m1, mx1, …, Izz1, m2, …`.
pub fn standard_param_names(n: usize) -> Vec<String> {
    per_body(&STANDARD, n)
}

/// The `4 n` principal parameter names, body 1 first: `m1, J1_1, J2_1, J3_1, m2, …`.
pub fn principal_param_names(n: usize) -> Vec<String> {
    per_body(&PRINCIPAL, n)
}

fn per_body(names: &[&str], n: usize) -> Vec<String> {
    (1..=n)
        .flat_map(|i| names.iter().map(move |s| param_name(s, i)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_format_for_both_parameterisations() {
        let s = standard_param_names(2);
        assert_eq!(s.len(), 20);
        assert_eq!(&s[..4], ["m1", "mx1", "my1", "mz1"]);
        assert_eq!(&s[9..12], ["Izz1", "m2", "mx2"]);
        assert_eq!(
            principal_param_names(12)[44..],
            ["m12", "J1_12", "J2_12", "J3_12"].map(String::from)
        );
        assert_eq!(principal_param_names(1), ["m1", "J1_1", "J2_1", "J3_1"]);
    }
}
