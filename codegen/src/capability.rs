//! Which functions a robot type gets: the capability traits of `dyngen`, selected by
//! name in `Config::functions`, the `robot!` macro's `functions: [..]` and
//! `dyngen generate --functions`.

use std::fmt;

/// A group of generated functions: one capability trait of `dyngen`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Capability {
    /// `rnea`, `nonlinear_effects`, `generalized_gravity`, `joint_wrenches`.
    InverseDynamics,
    /// `crba`.
    MassMatrix,
    /// `aba`.
    ForwardDynamics,
    /// `forward_kinematics`.
    Kinematics,
    /// The standard, principal, base, joint-wrench and per-body regressors, and the maps
    /// to the base parameters.
    Regressors,
    /// The dynamics with rotor inertia and friction, and their regressors.
    JointDynamics,
    /// Frame placements, Jacobians, their time variation, frame motions.
    Frames,
    /// Centre of mass, its Jacobian, the centroidal momentum matrix.
    Centroidal,
    /// The derivatives of inverse and forward dynamics, and `M⁻¹`.
    Derivatives,
}

impl Capability {
    /// Every capability, in the order the generated code holds them.
    pub const ALL: [Capability; 9] = [
        Capability::InverseDynamics,
        Capability::MassMatrix,
        Capability::ForwardDynamics,
        Capability::Kinematics,
        Capability::Regressors,
        Capability::JointDynamics,
        Capability::Frames,
        Capability::Centroidal,
        Capability::Derivatives,
    ];

    /// The name it is selected by (`inverse_dynamics`, …).
    pub fn name(self) -> &'static str {
        match self {
            Capability::InverseDynamics => "inverse_dynamics",
            Capability::MassMatrix => "mass_matrix",
            Capability::ForwardDynamics => "forward_dynamics",
            Capability::Kinematics => "kinematics",
            Capability::Regressors => "regressors",
            Capability::JointDynamics => "joint_dynamics",
            Capability::Frames => "frames",
            Capability::Centroidal => "centroidal",
            Capability::Derivatives => "derivatives",
        }
    }

    /// The `dyngen` trait it implements.
    pub fn trait_name(self) -> &'static str {
        match self {
            Capability::InverseDynamics => "InverseDynamics",
            Capability::MassMatrix => "MassMatrix",
            Capability::ForwardDynamics => "ForwardDynamics",
            Capability::Kinematics => "Kinematics",
            Capability::Regressors => "Regressors",
            Capability::JointDynamics => "JointDynamics",
            Capability::Frames => "Frames",
            Capability::Centroidal => "Centroidal",
            Capability::Derivatives => "Derivatives",
        }
    }

    /// The functions of its trait.
    pub fn functions(self) -> &'static [&'static str] {
        match self {
            Capability::InverseDynamics => &["rnea", "nonlinear_effects", "generalized_gravity", "joint_wrenches"],
            Capability::MassMatrix => &["crba"],
            Capability::ForwardDynamics => &["aba"],
            Capability::Kinematics => &["forward_kinematics"],
            Capability::Regressors => &[
                "joint_torque_regressor",
                "joint_wrench_regressor",
                "principal_regressor",
                "base_regressor",
                "principal_base_regressor",
                "body_regressors",
                "body_resultants",
                "base_params",
                "principal_base_params",
            ],
            Capability::JointDynamics => &[
                "rnea_joints",
                "crba_joints",
                "aba_joints",
                "torque_regressor_joints",
                "base_regressor_joints",
                "base_params_joints",
            ],
            Capability::Frames => &[
                "frame_placement",
                "frame_jacobian",
                "frame_jacobian_time_variation",
                "frame_motion",
            ],
            Capability::Centroidal => &[
                "center_of_mass",
                "com_jacobian",
                "centroidal_map",
                "centroidal_map_time_variation",
            ],
            Capability::Derivatives => &["rnea_derivatives", "aba_derivatives", "inverse_inertia"],
        }
    }

    /// The capability selected by `name`: its own name, or the name of one of its
    /// functions (`rnea` selects `inverse_dynamics`).
    pub fn from_name(name: &str) -> Option<Capability> {
        Capability::ALL
            .into_iter()
            .find(|c| c.name() == name || c.functions().contains(&name))
    }

    /// What its generated functions are built from: `joint_dynamics` calls `rnea`,
    /// `nonlinear_effects`, `crba` and the torque and base regressors; `derivatives`
    /// calls `nonlinear_effects`; frames and the centroidal functions are generated
    /// together (they share the frames' kinematics).
    fn needs(self) -> &'static [Capability] {
        match self {
            Capability::JointDynamics => &[
                Capability::InverseDynamics,
                Capability::MassMatrix,
                Capability::Regressors,
            ],
            Capability::Derivatives => &[Capability::InverseDynamics],
            Capability::Frames => &[Capability::Centroidal],
            Capability::Centroidal => &[Capability::Frames],
            _ => &[],
        }
    }

    fn bit(self) -> u16 {
        1 << self as u16
    }
}

impl fmt::Display for Capability {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A set of capabilities; by default all of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Selection(u16);

impl Default for Selection {
    fn default() -> Self {
        Selection::all()
    }
}

impl Selection {
    pub fn all() -> Selection {
        Selection::of(Capability::ALL)
    }

    pub fn empty() -> Selection {
        Selection(0)
    }

    pub fn of(capabilities: impl IntoIterator<Item = Capability>) -> Selection {
        Selection(capabilities.into_iter().fold(0, |bits, c| bits | c.bit()))
    }

    /// Parses a comma-separated list of capability or function names
    /// (`inverse_dynamics,frames`, `rnea,crba,aba,frame_jacobian`); `all` selects every
    /// one. The error names the first unknown name and lists the
    /// valid ones.
    pub fn parse(list: &str) -> Result<Selection, UnknownCapability> {
        let mut selection = Selection::empty();
        for name in list.split(',').map(str::trim) {
            if name == "all" {
                selection = Selection::all();
                continue;
            }
            match Capability::from_name(name) {
                Some(c) => selection.insert(c),
                None => return Err(UnknownCapability(name.to_string())),
            }
        }
        Ok(selection)
    }

    pub fn insert(&mut self, capability: Capability) {
        self.0 |= capability.bit();
    }

    pub fn contains(self, capability: Capability) -> bool {
        self.0 & capability.bit() != 0
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    pub fn iter(self) -> impl Iterator<Item = Capability> {
        Capability::ALL.into_iter().filter(move |&c| self.contains(c))
    }

    /// The selection with what its functions are built from (see
    /// [`Capability`]'s groups): what is generated, and implemented.
    pub fn closure(self) -> Selection {
        let mut out = self;
        loop {
            let grown = Selection::of(out.iter().flat_map(|c| c.needs().iter().copied()).chain(out.iter()));
            if grown == out {
                return out;
            }
            out = grown;
        }
    }
}

impl fmt::Display for Selection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.iter().map(Capability::name).collect();
        f.write_str(&names.join(", "))
    }
}

/// A name that is not a capability.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownCapability(pub String);

impl fmt::Display for UnknownCapability {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "unknown function or group `{}`; valid are a function's name (`rnea`, `crba`, `aba`, `frame_jacobian`, …) or a group: {}",
            self.0,
            valid_names()
        )
    }
}

impl std::error::Error for UnknownCapability {}

/// The valid names, for messages: `inverse_dynamics`, `mass_matrix`, … and `all`.
pub fn valid_names() -> String {
    let names: Vec<String> = Capability::ALL.iter().map(|c| format!("`{}`", c.name())).collect();
    format!("{} (or `all`)", names.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_closure_adds_what_functions_are_built_from() {
        for c in Capability::ALL {
            assert_eq!(Capability::from_name(c.name()), Some(c));
        }
        let s = Selection::parse("inverse_dynamics, joint_dynamics").unwrap();
        assert_eq!(s.to_string(), "inverse_dynamics, joint_dynamics");
        assert_eq!(
            s.closure().to_string(),
            "inverse_dynamics, mass_matrix, regressors, joint_dynamics"
        );
        assert_eq!(
            Selection::parse("frames").unwrap().closure().to_string(),
            "frames, centroidal"
        );
        assert_eq!(Selection::parse("all").unwrap(), Selection::all());
        assert_eq!(
            Selection::parse("rnea,crba,aba,frame_jacobian").unwrap().to_string(),
            "inverse_dynamics, mass_matrix, forward_dynamics, frames"
        );
        let e = Selection::parse("rnea,cbra").unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown function or group `cbra`; valid are a function's name (`rnea`, `crba`, `aba`, `frame_jacobian`, \
             …) or a group: `inverse_dynamics`, `mass_matrix`, `forward_dynamics`, `kinematics`, `regressors`, \
             `joint_dynamics`, `frames`, `centroidal`, `derivatives` (or `all`)"
        );
        assert!(Selection::parse("").is_err());
    }
}
