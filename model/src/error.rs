//! Model errors: every problem found in a description, each naming its element and,
//! where the front end knows it, the source line.

use std::fmt;

/// The element of a description an error is about.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Element {
    Robot,
    Link(String),
    Joint(String),
}

impl fmt::Display for Element {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Element::Robot => write!(f, "robot"),
            Element::Link(n) => write!(f, "link `{n}`"),
            Element::Joint(n) => write!(f, "joint `{n}`"),
        }
    }
}

/// One problem in a robot description.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelError {
    pub element: Element,
    /// 1-based line in the source file, when known.
    pub line: Option<usize>,
    pub kind: ErrorKind,
}

/// What is wrong, with what would be valid in the message.
#[derive(Clone, Debug, PartialEq)]
pub enum ErrorKind {
    /// The file could not be read.
    Io(String),
    /// The file is not well-formed URDF XML.
    Parse(String),
    /// The file still contains xacro macros.
    Xacro,
    /// The file is larger than [`MAX_FILE_BYTES`](crate::urdf::MAX_FILE_BYTES).
    TooLarge {
        bytes: u64,
    },
    /// Elements nested deeper than [`MAX_DEPTH`](crate::xml::MAX_DEPTH); `tag` is the
    /// first element past the limit.
    TooDeep {
        tag: String,
    },
    /// A numeric attribute that is not a number, or not the count of numbers its
    /// element needs: `<origin rpy="0 1.57">`, `<mass value="heavy">`.
    BadNumber {
        /// Element and attribute, as `origin rpy`.
        attribute: String,
        value: String,
        /// How many numbers the attribute holds (1 or 3).
        expected: usize,
    },
    /// A `<mimic>` that cannot be followed: the reason, and what would be valid.
    BadMimic(String),
    UnknownParentLink(String),
    UnknownChildLink(String),
    DuplicateLink,
    DuplicateJoint,
    /// A link is the child of more than one joint.
    SeveralParents(Vec<String>),
    /// More than one link has no parent joint.
    SeveralRoots(Vec<String>),
    /// No link is without a parent: the joints form a cycle.
    NoRoot,
    /// The joint closes a loop (its child is one of its ancestors).
    Cycle,
    UnsupportedJointType(String),
    /// A free flyer (URDF `floating`, MJCF `free`) that does not hang from the root
    /// link, or a second one: a floating base is one free body on the world.
    FreeFlyerNotAtRoot,
    ZeroAxis,
    NonFiniteValue(&'static str),
    /// A finite value beyond [`MAX_MAGNITUDE`](crate::desc::MAX_MAGNITUDE).
    OutOfRange {
        what: &'static str,
        value: f64,
    },
    NonPositiveMass(f64),
    NotPositiveDefinite([f64; 3]),
    TriangleInequality([f64; 3]),
    BadLimits {
        lower: f64,
        upper: f64,
    },
    /// `<dynamics>` with a negative damping or friction: friction dissipates.
    NegativeFriction {
        damping: f64,
        friction: f64,
    },
    NoMovingJoint,
    /// Nothing with mass moves along this joint's coordinates (its body and all it
    /// carries are massless, or the mass sits on its axis): the mass matrix is
    /// singular there, and forward dynamics has no solution. Only ever a warning, or
    /// an error in a strict build.
    SingularMassMatrix,
    /// An MJCF construct the MJCF front end does not read yet (`<include>`,
    /// `<frame>`, a free body aligned with its inertia, a mesh geom giving a body its
    /// inertia): what it is and what to do.
    NotSupported(String),
    /// An MJCF `class` or `childclass` naming no `<default class>`.
    UnknownClass(String),
    /// An MJCF element or attribute that is not valid MJCF: what is wrong.
    InvalidMjcf(String),
    /// Something the description says that the model cannot hold and leaves out
    /// (an MJCF joint's `stiffness`, a ball joint's `range`, `<equality>`): only ever
    /// a warning.
    Ignored(String),
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(line) = self.line {
            write!(f, "line {line}: ")?;
        }
        write!(f, "{}: {}", self.element, self.kind)
    }
}

impl fmt::Display for ErrorKind {
    /// What is wrong, without the element and line a [`ModelError`] adds.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::Io(m) => write!(f, "cannot read the file: {m}"),
            ErrorKind::Parse(m) => write!(f, "not valid URDF: {m}"),
            ErrorKind::Xacro => write!(
                f,
                "the file contains xacro macros; expand it first (`xacro robot.urdf.xacro > robot.urdf`)"
            ),
            ErrorKind::TooLarge { bytes } => write!(
                f,
                "the file has {bytes} bytes, more than the {} MiB a robot description may have",
                crate::urdf::MAX_FILE_BYTES >> 20
            ),
            ErrorKind::TooDeep { tag } => write!(
                f,
                "<{tag}> is nested more than {} elements deep; a URDF needs fewer than 10 levels",
                crate::xml::MAX_DEPTH
            ),
            ErrorKind::BadNumber {
                attribute,
                value,
                expected,
            } => {
                let (element, name) = attribute.split_once(' ').unwrap_or((attribute.as_str(), ""));
                match expected {
                    1 => write!(f, "<{element} {name}=\"{value}\"> is not a number; write one number such as `0.5`"),
                    n => write!(
                        f,
                        "<{element} {name}=\"{value}\"> is not {n} numbers; write {n} numbers separated by spaces, such as `0 0 0.5`"
                    ),
                }
            }
            ErrorKind::BadMimic(why) => write!(f, "<mimic>: {why}"),
            ErrorKind::UnknownParentLink(p) => {
                write!(f, "parent link `{p}` does not exist; a joint's parent must name a <link> of this robot")
            }
            ErrorKind::UnknownChildLink(c) => {
                write!(f, "child link `{c}` does not exist; a joint's child must name a <link> of this robot")
            }
            ErrorKind::DuplicateLink => write!(f, "defined more than once; link names must be unique"),
            ErrorKind::DuplicateJoint => write!(f, "defined more than once; joint names must be unique"),
            ErrorKind::SeveralParents(js) => write!(
                f,
                "is the child of several joints ({}); in a tree every link has at most one parent joint",
                js.join(", ")
            ),
            ErrorKind::SeveralRoots(ls) => write!(
                f,
                "has several root links ({}); a fixed-base tree has exactly one link without a parent joint",
                ls.join(", ")
            ),
            ErrorKind::NoRoot => write!(f, "every link has a parent joint, so the joints form a cycle; a tree needs one root link"),
            ErrorKind::Cycle => write!(f, "closes a kinematic loop; only trees are supported (every link reachable from the root exactly once)"),
            ErrorKind::UnsupportedJointType(t) => write!(
                f,
                "joint type `{t}` is not supported; use revolute, continuous, prismatic, planar, spherical, floating or fixed"
            ),
            ErrorKind::FreeFlyerNotAtRoot => write!(
                f,
                "a floating (free-flyer) joint must join the root link to a body (in MJCF: a free joint only in a \
                 body directly in <worldbody>); make it the joint of a child of the root link, or leave the body \
                 fixed"
            ),
            ErrorKind::ZeroAxis => write!(f, "the axis is zero; give a nonzero direction such as `0 0 1`"),
            ErrorKind::NonFiniteValue(what) => write!(f, "{what} is not a finite number"),
            ErrorKind::OutOfRange { what, value } => write!(
                f,
                "{what} holds {value:e}, beyond ±{:e} in SI units (m, kg, kg·m²); check the unit",
                crate::desc::MAX_MAGNITUDE
            ),
            ErrorKind::NonPositiveMass(m) if *m < 0.0 => {
                write!(f, "mass {m} is negative; a mass is ≥ 0 kg (0 for a massless link)")
            }
            ErrorKind::NonPositiveMass(m) => write!(
                f,
                "mass {m} with a nonzero rotational inertia is not a rigid body; give the mass, or zero the inertia \
                 for a massless link"
            ),
            ErrorKind::NotPositiveDefinite(ev) => write!(
                f,
                "inertia is not positive definite (principal moments {:.6e}, {:.6e}, {:.6e}); all must be > 0",
                ev[0], ev[1], ev[2]
            ),
            ErrorKind::TriangleInequality(ev) => write!(
                f,
                "principal moments {:.6e}, {:.6e}, {:.6e} break the triangle inequality; each must be at most the sum of the other two",
                ev[0], ev[1], ev[2]
            ),
            ErrorKind::BadLimits { lower, upper } => {
                write!(f, "limits lower = {lower} > upper = {upper}; the lower limit must not exceed the upper")
            }
            ErrorKind::NegativeFriction { damping, friction } => write!(
                f,
                "<dynamics damping=\"{damping}\" friction=\"{friction}\"> is negative; friction only dissipates, \
                 give values ≥ 0"
            ),
            ErrorKind::SingularMassMatrix => write!(
                f,
                "the mass matrix is singular along this joint: nothing with mass moves with it that the joints \
                 before it do not already move (its link and every link it carries are massless, or their mass \
                 sits on its axis), so forward dynamics (aba) has no solution; give the link an <inertial> with a \
                 mass and inertia, or make the joint fixed"
            ),
            ErrorKind::NoMovingJoint => write!(f, "has no moving joint (revolute, continuous, prismatic, spherical or floating); nothing moves"),
            ErrorKind::NotSupported(m) | ErrorKind::InvalidMjcf(m) | ErrorKind::Ignored(m) => write!(f, "{m}"),
            ErrorKind::UnknownClass(c) => write!(
                f,
                "default class `{c}` is not defined; define it with <default class=\"{c}\"> inside <default>"
            ),
        }
    }
}

impl ModelError {
    /// The message of a problem accepted with a warning ([`Model::warnings`](crate::Model)):
    /// what is wrong, and why it was let through.
    pub fn warning_message(&self) -> String {
        let tolerance = crate::desc::INERTIA_TOLERANCE;
        let remedy = "balance_inertia (`--balance-inertia`) replaces it by the nearest physical inertia; a strict \
                      build refuses it";
        match &self.kind {
            ErrorKind::NotPositiveDefinite(ev) | ErrorKind::TriangleInequality(ev) => {
                let violation = crate::desc::inertia_violation(*ev);
                if violation <= tolerance {
                    format!(
                        "{self}; accepted as written: within the relative tolerance of {tolerance:e} for CAD \
                         rounding (the nearest physical inertia is used where consistency is needed; a strict \
                         build refuses it)"
                    )
                } else {
                    format!(
                        "{self}; accepted as written, as Pinocchio reads it, although it is {:.3} % of its largest \
                         moment away from physical, beyond the relative tolerance of {tolerance:e} for CAD \
                         rounding: check the file; {remedy}",
                        100.0 * violation
                    )
                }
            }
            ErrorKind::NonPositiveMass(_) => {
                format!("{self}; accepted as written, as Pinocchio reads it (a strict build refuses it)")
            }
            ErrorKind::SingularMassMatrix => {
                format!("{self}; loaded as Pinocchio loads it (a strict build refuses it)")
            }
            _ => self.to_string(),
        }
    }
}

impl std::error::Error for ModelError {}

/// All errors found in one description, printed one per line, each prefixed with the
/// file name when it is known.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelErrors {
    pub file: Option<String>,
    pub errors: Vec<ModelError>,
}

impl fmt::Display for ModelErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, e) in self.errors.iter().enumerate() {
            if k > 0 {
                writeln!(f)?;
            }
            match (&self.file, e.line) {
                (Some(file), Some(line)) => {
                    let rest = ModelError {
                        line: None,
                        ..e.clone()
                    };
                    write!(f, "{file}:{line}: {rest}")?
                }
                (Some(file), None) => write!(f, "{file}: {e}")?,
                (None, _) => write!(f, "{e}")?,
            }
        }
        Ok(())
    }
}

impl std::error::Error for ModelErrors {}
