//! Joint terms past viscous and Coulomb friction: each is a few more regressor
//! columns per joint, after the `[Ia, Fv, Fc, F0]` of every joint
//! ([`dyngen_model::joint_params`]), so the fit stays linear and every term is
//! identified with its σ like the others. With `s(q̇)` the Coulomb model (`sign` or
//! `tanh(q̇/ε)`), joint `j` gains
//!
//! ```text
//! τ_j += Fva_j·|q̇_j|                                    direction-dependent viscous friction
//!      + Σ_k  Ts_k·sin(k q_j) + Tc_k·cos(k q_j)          torque ripple (position-dependent torque)
//!      + Σ_k (Fcs_k·sin(k q_j) + Fcc_k·cos(k q_j))·s(q̇_j) position-dependent Coulomb friction
//!      + Σ_m Tms_m·sin(m N_j q_j) + Tmc_m·cos(m N_j q_j)  ripple of the motor angle
//!      + Fcl_j·|τ_j^rigid|·s(q̇_j)                       load-dependent Coulomb friction
//! ```
//!
//! for `k = 1..=harmonics` and `m = 1..=motor_harmonics`, in this order; `N_j` is
//! the joint's gear ratio (motor angle `N_j q_j`: cogging and gear ripple repeat
//! many times per joint turn, so a joint that moves a little sweeps many periods).
//! Direction-dependent *Coulomb* friction needs no new term: `Fc·s(q̇) + F0` is `Fc + F0` forward and `Fc − F0` backward.
//! Likewise `Fv·q̇ + Fva·|q̇|` is `Fv + Fva` forward and `Fv − Fva` backward.
//!
//! The load term's `τ_j^rigid` is the torque the links load the joint's
//! transmission with: the rigid-body part `Y_j π` of the joint torque (the inverse
//! dynamics of the links, without the joint's own friction and rotor inertia, as in
//! Hamon, Gautier and Garrec's load-dependent friction model). It is linear in
//! `Fcl` once `π` is known, so the fit alternates: the rigid-body parameters of the
//! fit before give each row's load, the next fit gives `Fcl` and new parameters
//! ([`crate::pipeline`]); a prediction takes the load from the parameters it
//! predicts with. (The measured torque is no load signal: on a joint whose torque
//! is mostly friction, `|τ|·s(q̇)` is `τ` itself, and the fit would explain the
//! torque by itself with `Fcl = 1`.)
//!
//! Harmonics are of the joint coordinate as it is (radians; metres on a prismatic
//! joint, where the period is 2π m), and need one position coordinate per velocity
//! coordinate.
//!
//! ```
//! use dyngen_identify::extras::ExtraTerms;
//! let extras: ExtraTerms = "asymmetric,ripple=2,load".parse().unwrap();
//! assert_eq!(extras.per_joint(), 1 + 4 * 2 + 1);
//! assert_eq!(extras.names(1)[..3], ["Fva1", "Ts1_1", "Tc1_1"]);
//! assert_eq!(extras.to_string(), "asymmetric,ripple=2,load");
//! ```

use dyngen_model::joint_params::Coulomb;
use dyngen_model::names::param_name;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Which extra terms each joint gets (the same for every joint).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExtraTerms {
    /// Direction-dependent viscous friction `Fva·|q̇|`.
    pub asymmetric: bool,
    /// Harmonics of the joint angle, `k = 1..=harmonics`: torque ripple and
    /// position-dependent Coulomb friction, 4 columns each.
    pub harmonics: u8,
    /// Harmonics of the motor angle (the joint angle times the gear ratio),
    /// `m = 1..=motor_harmonics`: torque ripple, 2 columns each.
    pub motor_harmonics: u8,
    /// Load-dependent Coulomb friction `Fcl·|τ_rigid|·s(q̇)`, `τ_rigid` the links' load.
    pub load: bool,
}

/// The most harmonics [`ExtraTerms::harmonics`] takes.
pub const MAX_HARMONICS: u8 = 8;

impl ExtraTerms {
    /// No extra term.
    pub const NONE: ExtraTerms = ExtraTerms {
        asymmetric: false,
        harmonics: 0,
        motor_harmonics: 0,
        load: false,
    };

    pub fn is_empty(&self) -> bool {
        self.per_joint() == 0
    }

    /// Columns per joint.
    pub fn per_joint(&self) -> usize {
        usize::from(self.asymmetric)
            + 4 * usize::from(self.harmonics)
            + 2 * usize::from(self.motor_harmonics)
            + usize::from(self.load)
    }

    /// The load term's column within a joint's block.
    pub fn load_column(&self) -> Option<usize> {
        self.load.then(|| self.per_joint() - 1)
    }

    /// One joint's names, without the joint number: `Fva, Ts1, Tc1, Fcs1, Fcc1, …,
    /// Tms1, Tmc1, …, Fcl`.
    fn joint_names(&self) -> Vec<String> {
        let mut names = Vec::with_capacity(self.per_joint());
        if self.asymmetric {
            names.push("Fva".to_string());
        }
        for k in 1..=self.harmonics {
            names.extend(["Ts", "Tc", "Fcs", "Fcc"].map(|s| format!("{s}{k}")));
        }
        for m in 1..=self.motor_harmonics {
            names.extend(["Tms", "Tmc"].map(|s| format!("{s}{m}")));
        }
        if self.load {
            names.push("Fcl".to_string());
        }
        names
    }

    /// The names of the extra parameters of `n` joints, joint by joint:
    /// `Fva1, Ts1_1, Tc1_1, Fcs1_1, Fcc1_1, …, Fcl1, Fva2, …`.
    pub fn names(&self, n: usize) -> Vec<String> {
        let names = self.joint_names();
        (1..=n)
            .flat_map(|j| names.iter().map(move |s| param_name(s, j)))
            .collect()
    }

    /// One joint's regressor entries at position `q`, velocity `v` and motor angle
    /// `motor` (`N q`), with `load` the load column's value
    /// ([`ExtraTerms::load_entry`]), into `out` (`per_joint()` entries).
    pub fn row(&self, q: f64, v: f64, motor: f64, load: f64, coulomb: Coulomb, out: &mut [f64]) {
        let s = coulomb.eval(v);
        let mut at = 0;
        if self.asymmetric {
            out[0] = v.abs();
            at = 1;
        }
        for k in 1..=self.harmonics {
            let (sin, cos) = (f64::from(k) * q).sin_cos();
            out[at..at + 4].copy_from_slice(&[sin, cos, s * sin, s * cos]);
            at += 4;
        }
        for m in 1..=self.motor_harmonics {
            let (sin, cos) = (f64::from(m) * motor).sin_cos();
            out[at..at + 2].copy_from_slice(&[sin, cos]);
            at += 2;
        }
        if self.load {
            out[at] = load;
        }
    }

    /// The load column's value: `|τ^rigid|·s(v)`, `rigid` the joint's rigid-body
    /// torque.
    pub fn load_entry(rigid: f64, v: f64, coulomb: Coulomb) -> f64 {
        rigid.abs() * coulomb.eval(v)
    }
}

impl fmt::Display for ExtraTerms {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if self.asymmetric {
            parts.push("asymmetric".to_string());
        }
        if self.harmonics > 0 {
            parts.push(format!("ripple={}", self.harmonics));
        }
        if self.motor_harmonics > 0 {
            parts.push(format!("motor-ripple={}", self.motor_harmonics));
        }
        if self.load {
            parts.push("load".to_string());
        }
        if parts.is_empty() {
            parts.push("none".to_string());
        }
        write!(f, "{}", parts.join(","))
    }
}

impl FromStr for ExtraTerms {
    type Err = String;

    /// A comma-separated list of `asymmetric`, `ripple=H` and `motor-ripple=H` (`H`
    /// harmonics, 1 to [`MAX_HARMONICS`]; alone 1) and `load`, or `none`.
    fn from_str(text: &str) -> Result<Self, String> {
        let mut extras = ExtraTerms::NONE;
        let valid = "valid: a comma-separated list of asymmetric, ripple=H, motor-ripple=H (H harmonics, 1 to 8) \
                     and load, or none";
        let harmonics = |k: usize, part: &str, h: Option<&str>| match h {
            None => Ok(1),
            Some(h) => match h.parse::<u8>() {
                Ok(h) if (1..=MAX_HARMONICS).contains(&h) => Ok(h),
                _ => Err(format!(
                    "term {} `{part}`: the harmonics must be 1 to 8; {valid}",
                    k + 1
                )),
            },
        };
        for (k, part) in text.split(',').map(str::trim).enumerate() {
            match part
                .split_once('=')
                .map_or((part, None), |(a, b)| (a.trim(), Some(b.trim())))
            {
                ("none", None) if text.trim() == "none" => {}
                ("asymmetric", None) if !extras.asymmetric => extras.asymmetric = true,
                ("load", None) if !extras.load => extras.load = true,
                ("ripple", h) if extras.harmonics == 0 => extras.harmonics = harmonics(k, part, h)?,
                ("motor-ripple", h) if extras.motor_harmonics == 0 => extras.motor_harmonics = harmonics(k, part, h)?,
                _ => return Err(format!("term {} `{part}` is unknown or repeated; {valid}", k + 1)),
            }
        }
        Ok(extras)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_prints_the_same_list() {
        for text in [
            "none",
            "asymmetric",
            "ripple=3",
            "load",
            "asymmetric,ripple=2,motor-ripple=1,load",
        ] {
            assert_eq!(text.parse::<ExtraTerms>().unwrap().to_string(), text);
        }
        assert_eq!("ripple".parse::<ExtraTerms>().unwrap().harmonics, 1);
        assert_eq!(" load , asymmetric ".parse::<ExtraTerms>().unwrap().per_joint(), 2);
        for (bad, says) in [
            ("ripple=0", "term 1 `ripple=0`: the harmonics must be 1 to 8"),
            ("load,ripple=x", "term 2 `ripple=x`: the harmonics must be 1 to 8"),
            ("load,load", "term 2 `load` is unknown or repeated"),
            ("asymetric", "term 1 `asymetric` is unknown"),
            ("none,load", "term 1 `none` is unknown"),
        ] {
            let e = bad.parse::<ExtraTerms>().unwrap_err();
            assert!(e.starts_with(says) && e.contains("valid:"), "{bad}: {e}");
        }
    }

    #[test]
    fn rows_and_names_line_up() {
        let extras: ExtraTerms = "asymmetric,ripple=2,load".parse().unwrap();
        assert_eq!(
            extras.names(2)[..10],
            ["Fva1", "Ts1_1", "Tc1_1", "Fcs1_1", "Fcc1_1", "Ts2_1", "Tc2_1", "Fcs2_1", "Fcc2_1", "Fcl1"]
        );
        assert_eq!(extras.names(2)[10], "Fva2");
        let motor: ExtraTerms = "motor-ripple=2".parse().unwrap();
        assert_eq!(motor.names(1), ["Tms1_1", "Tmc1_1", "Tms2_1", "Tmc2_1"]);
        let mut row = [0.0; 4];
        motor.row(0.3, 0.1, 30.0, 0.0, Coulomb::Sign, &mut row);
        assert_eq!(row, [30f64.sin(), 30f64.cos(), 60f64.sin(), 60f64.cos()]);
        let mut row = [0.0; 10];
        let (q, v) = (0.3, -0.5);
        extras.row(
            q,
            v,
            0.0,
            ExtraTerms::load_entry(-4.0, v, Coulomb::Sign),
            Coulomb::Sign,
            &mut row,
        );
        let expect = [
            0.5,
            q.sin(),
            q.cos(),
            -q.sin(),
            -q.cos(),
            (2.0 * q).sin(),
            (2.0 * q).cos(),
            -(2.0 * q).sin(),
            -(2.0 * q).cos(),
            -4.0,
        ];
        assert_eq!(row, expect);
    }
}
