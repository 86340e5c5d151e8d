//! MJCF (MuJoCo XML) front end for the subset robot arms use: reads the text with the
//! scan of [`crate::xml`] (lines, size and nesting limits) into the same
//! [`Description`] as the URDF front end, so checking, merging and numbering are
//! shared.
//!
//! Read: `<mujoco model>`, `<compiler angle eulerseq autolimits alignfree>` (MuJoCo's
//! default angle unit is the degree), `<option gravity>`, `<default>` classes (nested,
//! `class` on joints, `childclass` on bodies) for joint attributes, `<worldbody>` with
//! nested `<body name pos quat|euler|axisangle|xyaxes|zaxis>`, `<inertial pos mass
//! diaginertia (with an orientation) | fullinertia>` and at most one `<joint
//! type="hinge|slide|ball|free" pos axis range limited damping frictionloss armature
//! actuatorfrcrange>` or `<freejoint name align>` per body. A body without a joint is
//! a fixed link, merged as a URDF fixed joint. MuJoCo's worldbody is the base, the
//! link `world`.
//!
//! A joint's `pos` (a point on its axis, in the body frame) moves the link frame onto
//! the joint, as URDF has it: the joint origin is the body placement followed by a
//! translation by `pos`, and the body's inertial and its children's placements are
//! re-expressed in that frame (`pos` subtracted).
//!
//! # Joints and their coordinates
//!
//! - `hinge`: [`JointKind::Revolute`] (limited) or [`JointKind::Continuous`]; `slide`:
//!   [`JointKind::Prismatic`]. One coordinate each, MuJoCo's own.
//! - `ball`: [`JointKind::Spherical`], rotating about `pos` (its frame is the body
//!   frame with its origin moved to `pos`, as a hinge's). `axis` is ignored, as MuJoCo
//!   ignores it. The model has no limits for a ball joint: a `range` in effect
//!   (`limited="true"`, or `auto` with `autolimits`; MuJoCo bounds the rotation angle)
//!   is left out with an [`ErrorKind::Ignored`] warning. Positions: MuJoCo's `qpos`
//!   holds the quaternion as `w x y z`, the model's `q` as Pinocchio's `[x, y, z, w]`
//!   (the same rotation, of the body in the joint frame). Velocities are the same in
//!   both: the angular velocity in the body frame.
//! - `free` and `<freejoint>`: [`JointKind::FreeFlyer`], only in a body directly in
//!   `<worldbody>` (MuJoCo refuses a free joint deeper down; a floating base is also
//!   the first moving joint, see [`ErrorKind::FreeFlyerNotAtRoot`]). MuJoCo ignores a
//!   free joint's `pos`, `axis` and `range`, and so does this reader; `<freejoint>`
//!   has no damping or friction. The free flyer's origin is the world frame: the
//!   body's own `pos` and orientation are only MuJoCo's initial `qpos0`, and `q` is
//!   the body's pose in the world, as in MuJoCo. The coordinates differ, with `R` the
//!   body's orientation in the world:
//!
//!   ```text
//!   MuJoCo  qpos = [p; w x y z]    qvel = [ṗ (world axes); ω (body axes)]
//!   dyngen  q    = [p; x y z w]    v    = [Rᵀ ṗ; ω]   (both in body axes)
//!   ```
//!
//!   So `v = T v_mj` with `T = blkdiag(Rᵀ, E, …, E)`, and by power (`τᵀv = τ_mjᵀv_mj`)
//!   the generalised forces are `τ = T⁻ᵀ τ_mj` (the base force `Rᵀ f`, the torques
//!   unchanged), the mass matrix `M = T⁻ᵀ M_mj T⁻¹`. `T` moves with the body, so the
//!   accelerations differ by more than `T`: `v̇ = T v̇_mj + Ṫ v_mj` with
//!   `Ṫ v_mj = [−ω × Rᵀṗ; 0]`, and MuJoCo's bias forces `qfrc_bias` become
//!   `b = T⁻ᵀ b_mj + M [ω × Rᵀṗ; 0]`.
//!
//!   MuJoCo moves the frame of a free body without child bodies onto its principal
//!   axes of inertia when asked (`<freejoint align="true">`, or `<compiler
//!   alignfree="true">` without `align="false"`), which changes its coordinates: that
//!   is refused.
//!
//! Refused, each naming the element and its line: a free joint not directly in
//! `<worldbody>`, several joints in one body, a nonzero `ref` on a hinge or slide
//! joint, `<include>`, `<frame>`, `<replicate>`, `<attach>`, `<composite>`,
//! `<flexcomp>`, unknown classes. A moving body without `<inertial>` is an error
//! (MuJoCo would infer the inertia from its geoms; dyngen does not). Geometry, sites,
//! cameras, lights, assets, actuators, sensors and the rest are skipped. A nonzero
//! `armature` or `stiffness` has no place in the model and is left out with a warning.
//!
//! Siblings are numbered in declaration order, as MuJoCo numbers its bodies.

use crate::desc::{DeclaredJointType, Description, JointDesc, LinkDesc, LoadOptions, SiblingOrder, DEFAULT_GRAVITY};
use crate::error::{Element, ErrorKind, ModelError, ModelErrors};
use crate::ir::{Inertial, JointDynamics, JointKind, Limits, Model, Placement};
use crate::math::{self, Mat3, Vec3};
use crate::urdf::MAX_FILE_BYTES;
use crate::xml::{scan, SyntaxError, Tag};
use std::collections::HashMap;
use std::io::Read as _;
use std::path::Path;

/// The name of the base link: MuJoCo's `<worldbody>`, body 0, is called `world`.
pub const WORLD: &str = "world";

/// Bound given to the velocity of every limited joint, and to its effort when no
/// `actuatorfrcrange` is written: MJCF joints have no velocity limit. As the URDF
/// writer's bound for joints without limits.
const UNLIMITED: f64 = 1e6;

/// Parses and checks MJCF text; errors carry line numbers but no file name.
/// Warnings as for [`parse_urdf`](crate::parse_urdf), and for what is left out.
pub fn parse_mjcf(text: &str) -> Result<Model, ModelErrors> {
    parse_mjcf_with(text, false)
}

/// [`parse_mjcf`]; `strict` refuses the inertias it would accept with a warning.
pub fn parse_mjcf_with(text: &str, strict: bool) -> Result<Model, ModelErrors> {
    parse_mjcf_options(
        text,
        LoadOptions {
            strict,
            ..LoadOptions::default()
        },
    )
}

/// [`parse_mjcf`] with every [`LoadOptions`] (a free flyer under the root link).
pub fn parse_mjcf_options(text: &str, options: LoadOptions) -> Result<Model, ModelErrors> {
    build(text, options).map_err(|errors| ModelErrors { file: None, errors })
}

/// Reads, parses and checks an MJCF file; errors are prefixed with its path.
pub fn load_mjcf(path: &Path) -> Result<Model, ModelErrors> {
    load_mjcf_with(path, false)
}

/// [`load_mjcf`]; `strict` as for [`parse_mjcf_with`].
pub fn load_mjcf_with(path: &Path, strict: bool) -> Result<Model, ModelErrors> {
    load_mjcf_options(
        path,
        LoadOptions {
            strict,
            ..LoadOptions::default()
        },
    )
}

/// [`load_mjcf`] with every [`LoadOptions`] (a free flyer under the root link).
pub fn load_mjcf_options(path: &Path, options: LoadOptions) -> Result<Model, ModelErrors> {
    let file = Some(path.display().to_string());
    let text = read_file(path).map_err(|errors| ModelErrors {
        file: file.clone(),
        errors,
    })?;
    build(&text, options).map_err(|errors| ModelErrors { file, errors })
}

/// Loads a robot by its file name: `.xml` or `.mjcf` as MJCF ([`load_mjcf`], siblings
/// in declaration order), anything else as URDF ([`load_urdf`](crate::load_urdf),
/// siblings by joint name), as the command line and `build.rs` did before MJCF.
pub fn load_robot(path: &Path) -> Result<Model, ModelErrors> {
    load_robot_with(path, false)
}

/// [`load_robot`]; `strict` refuses CAD-rounded inertias, as for URDF and MJCF.
pub fn load_robot_with(path: &Path, strict: bool) -> Result<Model, ModelErrors> {
    load_robot_options(
        path,
        LoadOptions {
            strict,
            ..LoadOptions::default()
        },
    )
}

/// [`load_robot`] with every [`LoadOptions`]: `free_flyer` puts the root link on a
/// free flyer (a floating base).
pub fn load_robot_options(path: &Path, options: LoadOptions) -> Result<Model, ModelErrors> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("xml" | "mjcf") => load_mjcf_options(path, options),
        _ => crate::urdf::load_urdf_options(path, options),
    }
}

/// The unchecked description of MJCF text, before [`Description::build`] (which
/// should be called with [`SiblingOrder::Declaration`]). Errors of the MJCF itself
/// (not of the tree it describes) are returned here.
pub fn mjcf_description(text: &str) -> Result<Description, ModelErrors> {
    let fail = |errors| ModelErrors { file: None, errors };
    let read = read(text).map_err(fail)?;
    if !read.errors.is_empty() {
        return Err(fail(read.errors));
    }
    Ok(read.desc)
}

fn read_file(path: &Path) -> Result<String, Vec<ModelError>> {
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_string(&mut text))
        .map_err(|e| vec![robot_error(None, ErrorKind::Io(e.to_string()))])?;
    if text.len() as u64 > MAX_FILE_BYTES {
        let bytes = std::fs::metadata(path).map_or(text.len() as u64, |m| m.len());
        return Err(vec![robot_error(None, ErrorKind::TooLarge { bytes })]);
    }
    Ok(text)
}

fn build(text: &str, options: LoadOptions) -> Result<Model, Vec<ModelError>> {
    let strict = options.strict;
    let mut read = read(text)?;
    if options.free_flyer {
        let free = DeclaredJointType::Moving(JointKind::FreeFlyer);
        match read.desc.joints.iter().find(|j| j.kind == free) {
            // Floating the world under the file's own floating base would leave a
            // second free flyer and a world without mass: say what is wrong instead.
            Some(j) => read.errors.push(ModelError {
                element: Element::Joint(j.name.clone()),
                line: j.line,
                kind: ErrorKind::NotSupported(format!(
                    "body `{}` already floats on this free joint; the free-flyer load option would put the \
                     world on a second one: load this file without it",
                    j.child
                )),
            }),
            None => read.desc = read.desc.with_free_flyer(),
        }
    }
    let built = read.desc.build_checked(SiblingOrder::Declaration, strict);
    if read.errors.is_empty() {
        match built {
            Ok(mut model) => {
                model.warnings.extend(read.warnings);
                return Ok(model);
            }
            Err(mut errors) => {
                for e in &mut errors {
                    if e.element == Element::Robot && e.line.is_none() {
                        e.line = read.root_line;
                    }
                }
                errors.sort_by_key(|e| e.line.unwrap_or(usize::MAX));
                return Err(errors);
            }
        }
    }
    // The MJCF's own errors first; of the tree's, only those about elements not
    // already named (a refused joint leaves its body fixed, which says nothing new).
    let mut errors = read.errors;
    if let Err(more) = built {
        let named: Vec<Element> = errors.iter().map(|e| e.element.clone()).collect();
        errors.extend(
            more.into_iter()
                .filter(|e| e.element != Element::Robot && !named.contains(&e.element)),
        );
    }
    errors.sort_by_key(|e| e.line.unwrap_or(usize::MAX));
    Err(errors)
}

fn robot_error(line: Option<usize>, kind: ErrorKind) -> ModelError {
    ModelError {
        element: Element::Robot,
        line,
        kind,
    }
}

/// What [`read`] gives: the description, the line of `<mujoco>`, the errors of the
/// MJCF itself and what was left out with a warning.
struct Read {
    desc: Description,
    root_line: Option<usize>,
    errors: Vec<ModelError>,
    warnings: Vec<ModelError>,
}

fn read(text: &str) -> Result<Read, Vec<ModelError>> {
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(vec![robot_error(
            None,
            ErrorKind::TooLarge {
                bytes: text.len() as u64,
            },
        )]);
    }
    let tags = match scan(text) {
        Ok(tags) => tags,
        Err(SyntaxError {
            line,
            too_deep: Some(tag),
            ..
        }) => return Err(vec![robot_error(Some(line), ErrorKind::TooDeep { tag })]),
        Err(e) => {
            return Err(vec![robot_error(
                Some(e.line),
                ErrorKind::InvalidMjcf(format!("not valid XML: {}", e.message)),
            )])
        }
    };
    let root = tags.iter().position(|t| t.parent.is_none()).unwrap_or(0);
    if tags[root].name != "mujoco" {
        return Err(vec![robot_error(
            Some(tags[root].line),
            ErrorKind::InvalidMjcf(format!(
                "the document element is <{}>, not <mujoco>; this is not an MJCF (MuJoCo) file",
                tags[root].name
            )),
        )]);
    }
    let mut children = vec![Vec::new(); tags.len()];
    for (k, t) in tags.iter().enumerate() {
        if let Some(p) = t.parent {
            children[p].push(k);
        }
    }
    let mut reader = Reader {
        tags: &tags,
        children,
        radian: false,
        autolimits: true,
        alignfree: false,
        eulerseq: *b"xyz",
        classes: HashMap::new(),
        errors: Vec::new(),
        warnings: Vec::new(),
        links: Vec::new(),
        joints: Vec::new(),
        bodies: 0,
        joint_ids: 0,
        gravity: DEFAULT_GRAVITY,
    };
    reader.read_document(root);
    let name = tags[root].attr("model").unwrap_or("MuJoCo Model").to_string();
    Ok(Read {
        desc: Description {
            name,
            gravity: reader.gravity,
            links: reader.links,
            joints: reader.joints,
        },
        root_line: Some(tags[root].line),
        errors: reader.errors,
        warnings: reader.warnings,
    })
}

/// A `<default>` class: its parent class and the joint attributes it sets.
struct Class {
    parent: Option<String>,
    joint: Vec<(String, String)>,
}

/// Elements that build or move bodies in ways this front end does not follow.
const TREE_ELEMENTS: [&str; 5] = ["frame", "replicate", "attach", "composite", "flexcomp"];

/// The body a joint belongs to, as [`Reader::read_joint`] needs it.
struct Owner<'a> {
    /// Name of the parent link (`world` for a body directly in `<worldbody>`).
    parent: &'a str,
    body: &'a str,
    /// The body's placement in its parent link's frame.
    placement: &'a Placement,
    /// Whether the body has no child bodies (MuJoCo aligns only those).
    childless: bool,
}

/// MJCF joint types.
#[derive(Clone, Copy, PartialEq, Eq)]
enum MjcfJoint {
    Hinge,
    Slide,
    Ball,
    Free,
}

struct Reader<'t> {
    tags: &'t [Tag],
    children: Vec<Vec<usize>>,
    radian: bool,
    autolimits: bool,
    /// `<compiler alignfree>`: free bodies without children aligned with their inertia.
    alignfree: bool,
    eulerseq: [u8; 3],
    classes: HashMap<String, Class>,
    errors: Vec<ModelError>,
    warnings: Vec<ModelError>,
    links: Vec<LinkDesc>,
    joints: Vec<JointDesc>,
    /// Bodies met so far, the world included: MuJoCo's body id of the next one.
    bodies: usize,
    /// Joints met so far: MuJoCo's joint id of the next one.
    joint_ids: usize,
    gravity: Vec3,
}

impl<'t> Reader<'t> {
    fn error(&mut self, element: Element, line: usize, kind: ErrorKind) {
        self.errors.push(ModelError {
            element,
            line: Some(line),
            kind,
        });
    }

    fn children_named(&self, k: usize, name: &str) -> Vec<usize> {
        self.children[k]
            .iter()
            .copied()
            .filter(|&c| self.tags[c].name == name)
            .collect()
    }

    fn read_document(&mut self, root: usize) {
        let tags = self.tags;
        for t in tags.iter().filter(|t| t.name == "include") {
            let file = t.attr("file").unwrap_or_default();
            self.error(
                Element::Robot,
                t.line,
                ErrorKind::NotSupported(format!(
                    "<include file=\"{file}\"> is not supported yet; paste the included file's elements in its place"
                )),
            );
        }
        for c in self.children_named(root, "compiler") {
            self.read_compiler(&tags[c]);
        }
        for c in self.children_named(root, "option") {
            if let Some(g) = self.numbers(&tags[c], "gravity", 3, &Element::Robot) {
                self.gravity = [g[0], g[1], g[2]];
            }
        }
        self.classes.insert(
            "main".into(),
            Class {
                parent: None,
                joint: Vec::new(),
            },
        );
        for d in self.children_named(root, "default") {
            self.read_default(d, None);
        }
        let world_line = self.children_named(root, "worldbody").first().map(|&w| tags[w].line);
        self.links.push(LinkDesc {
            name: WORLD.into(),
            inertial: None,
            line: world_line.or(Some(tags[root].line)),
        });
        self.bodies = 1;
        for w in self.children_named(root, "worldbody") {
            for &c in &self.children[w].clone() {
                match tags[c].name.as_str() {
                    "body" => self.read_body(c, WORLD, [0.0; 3], "main"),
                    "joint" | "freejoint" => self.error(
                        Element::Robot,
                        tags[c].line,
                        ErrorKind::InvalidMjcf(format!(
                            "<{}> directly in <worldbody>: the world cannot move; put it in a <body>",
                            tags[c].name
                        )),
                    ),
                    name if TREE_ELEMENTS.contains(&name) => self.refuse_tree_element(c, Element::Robot),
                    _ => {}
                }
            }
        }
    }

    fn read_compiler(&mut self, t: &Tag) {
        if let Some(angle) = t.attr("angle") {
            match angle {
                "radian" => self.radian = true,
                "degree" => self.radian = false,
                other => self.error(
                    Element::Robot,
                    t.line,
                    ErrorKind::InvalidMjcf(format!("<compiler angle=\"{other}\"> is neither `radian` nor `degree`")),
                ),
            }
        }
        if let Some(seq) = t.attr("eulerseq") {
            let b = seq.as_bytes();
            if b.len() == 3 && b.iter().all(|c| b"xyzXYZ".contains(c)) {
                self.eulerseq = [b[0], b[1], b[2]];
            } else {
                self.error(
                    Element::Robot,
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "<compiler eulerseq=\"{seq}\"> is not three of x, y, z, X, Y, Z (lower case: rotating axes)"
                    )),
                );
            }
        }
        for (attr, flag) in [("autolimits", &mut self.autolimits), ("alignfree", &mut self.alignfree)] {
            match t.attr(attr) {
                None => {}
                Some("true") => *flag = true,
                Some("false") => *flag = false,
                Some(other) => self.errors.push(ModelError {
                    element: Element::Robot,
                    line: Some(t.line),
                    kind: ErrorKind::InvalidMjcf(format!(
                        "<compiler {attr}=\"{other}\"> is neither `true` nor `false`"
                    )),
                }),
            }
        }
    }

    fn read_default(&mut self, k: usize, parent: Option<String>) {
        let t = &self.tags[k];
        let name = match (t.attr("class"), &parent) {
            (Some(c), _) => c.to_string(),
            (None, None) => "main".to_string(),
            (None, Some(_)) => {
                self.error(
                    Element::Robot,
                    t.line,
                    ErrorKind::InvalidMjcf("a nested <default> needs a `class` name".into()),
                );
                return;
            }
        };
        let joint: Vec<(String, String)> = self
            .children_named(k, "joint")
            .iter()
            .flat_map(|&j| self.tags[j].attrs.clone())
            .collect();
        if parent.is_some() && self.classes.contains_key(&name) {
            self.error(
                Element::Robot,
                t.line,
                ErrorKind::InvalidMjcf(format!("default class `{name}` is defined more than once")),
            );
            return;
        }
        let entry = self.classes.entry(name.clone()).or_insert(Class {
            parent: parent.clone(),
            joint: Vec::new(),
        });
        entry.joint.extend(joint);
        for d in self.children_named(k, "default") {
            self.read_default(d, Some(name.clone()));
        }
    }

    /// The class an element names, checked; `inherited` when it names none.
    fn class_of(&mut self, t: &Tag, attr: &str, inherited: &str, element: &Element) -> String {
        match t.attr(attr) {
            Some(c) if self.classes.contains_key(c) => c.to_string(),
            Some(c) => {
                self.error(element.clone(), t.line, ErrorKind::UnknownClass(c.to_string()));
                inherited.to_string()
            }
            None => inherited.to_string(),
        }
    }

    /// A joint attribute: the element's own, else its class's, else an ancestor class's.
    fn joint_attr(&self, t: &'t Tag, class: &str, name: &str) -> Option<String> {
        if let Some(v) = t.attr(name) {
            return Some(v.to_string());
        }
        let mut c = Some(class);
        while let Some(name_c) = c {
            let class = self.classes.get(name_c)?;
            if let Some((_, v)) = class.joint.iter().rev().find(|(n, _)| n == name) {
                return Some(v.clone());
            }
            c = class.parent.as_deref();
        }
        None
    }

    /// `count` numbers of `value` (the attribute `attr` of `t`), or an error.
    fn parse_numbers(&mut self, t: &Tag, attr: &str, value: &str, count: usize, element: &Element) -> Option<Vec<f64>> {
        let words: Vec<&str> = value.split_whitespace().collect();
        let numbers: Vec<f64> = words.iter().filter_map(|w| w.parse::<f64>().ok()).collect();
        if words.len() == count && numbers.len() == count {
            return Some(numbers);
        }
        self.error(
            element.clone(),
            t.line,
            ErrorKind::BadNumber {
                attribute: format!("{} {attr}", t.name),
                value: value.to_string(),
                expected: count,
            },
        );
        None
    }

    fn numbers(&mut self, t: &Tag, attr: &str, count: usize, element: &Element) -> Option<Vec<f64>> {
        let value = t.attr(attr)?;
        self.parse_numbers(t, attr, value, count, element)
    }

    fn vec3(&mut self, t: &Tag, attr: &str, element: &Element) -> Option<Vec3> {
        self.numbers(t, attr, 3, element).map(|v| [v[0], v[1], v[2]])
    }

    fn angle(&self, x: f64) -> f64 {
        if self.radian {
            x
        } else {
            x.to_radians()
        }
    }

    /// The orientation of a body or inertial frame from whichever of `quat`, `euler`,
    /// `axisangle`, `xyaxes`, `zaxis` it gives (identity if none).
    fn orientation(&mut self, t: &Tag, element: &Element) -> Mat3 {
        const KINDS: [&str; 5] = ["quat", "euler", "axisangle", "xyaxes", "zaxis"];
        let given: Vec<&str> = KINDS.iter().copied().filter(|k| t.attr(k).is_some()).collect();
        if given.len() > 1 {
            self.error(
                element.clone(),
                t.line,
                ErrorKind::InvalidMjcf(format!(
                    "<{}> gives its orientation twice ({}); give one of quat, euler, axisangle, xyaxes, zaxis",
                    t.name,
                    given.join(", ")
                )),
            );
            return math::IDENTITY;
        }
        let Some(&kind) = given.first() else {
            return math::IDENTITY;
        };
        let count = match kind {
            "quat" | "axisangle" => 4,
            "xyaxes" => 6,
            _ => 3,
        };
        let Some(v) = self.numbers(t, kind, count, element) else {
            return math::IDENTITY;
        };
        let zero = |this: &mut Self, what: &str| {
            this.error(
                element.clone(),
                t.line,
                ErrorKind::InvalidMjcf(format!("<{} {kind}> has a zero {what}", t.name)),
            );
            math::IDENTITY
        };
        match kind {
            "quat" => quat_matrix([v[0], v[1], v[2], v[3]]).unwrap_or_else(|| zero(self, "quaternion")),
            "axisangle" => {
                let axis = [v[0], v[1], v[2]];
                let n = math::norm(&axis);
                if n == 0.0 || !n.is_finite() {
                    return zero(self, "axis");
                }
                axis_angle(&math::scale(1.0 / n, &axis), self.angle(v[3]))
            }
            "euler" => {
                let mut r = math::IDENTITY;
                for (k, &c) in self.eulerseq.iter().enumerate() {
                    let axis = match c.to_ascii_lowercase() {
                        b'x' => [1.0, 0.0, 0.0],
                        b'y' => [0.0, 1.0, 0.0],
                        _ => [0.0, 0.0, 1.0],
                    };
                    let step = axis_angle(&axis, self.angle(v[k]));
                    // Lower case: about the rotated (moving) axes; upper case: fixed axes.
                    r = if c.is_ascii_lowercase() {
                        math::mat_mul(&r, &step)
                    } else {
                        math::mat_mul(&step, &r)
                    };
                }
                r
            }
            "xyaxes" => {
                let x = [v[0], v[1], v[2]];
                let nx = math::norm(&x);
                if nx == 0.0 || !nx.is_finite() {
                    return zero(self, "x axis");
                }
                let x = math::scale(1.0 / nx, &x);
                let y = [v[3], v[4], v[5]];
                let y = math::sub(&y, &math::scale(math::dot(&x, &y), &x));
                let ny = math::norm(&y);
                if ny < 1e-12 * math::norm(&[v[3], v[4], v[5]]).max(1e-300) || !ny.is_finite() {
                    return zero(self, "y axis (or one parallel to x)");
                }
                let y = math::scale(1.0 / ny, &y);
                columns(x, y, cross(&x, &y))
            }
            _ => {
                let z = [v[0], v[1], v[2]];
                let n = math::norm(&z);
                if n == 0.0 || !n.is_finite() {
                    return zero(self, "axis");
                }
                zaxis(&math::scale(1.0 / n, &z))
            }
        }
    }

    /// A `<body>` with its subtree. `shift` is the parent's joint `pos`: the parent
    /// link frame sits there in the parent body frame.
    fn read_body(&mut self, k: usize, parent: &str, shift: Vec3, childclass: &str) {
        let tags = self.tags;
        let t = &tags[k];
        let id = self.bodies;
        self.bodies += 1;
        let name = t.attr("name").map_or_else(|| format!("body_{id}"), str::to_string);
        let el = Element::Link(name.clone());
        let childclass = self.class_of(t, "childclass", childclass, &el);
        let pos = self.vec3(t, "pos", &el).unwrap_or([0.0; 3]);
        let placement = Placement {
            rotation: self.orientation(t, &el),
            translation: math::sub(&pos, &shift),
        };

        // The joint, if any.
        let mut joint: Option<(JointDesc, Vec3)> = None;
        for c in self.children[k].clone() {
            let jt = &tags[c];
            match jt.name.as_str() {
                "joint" | "freejoint" => {}
                name if TREE_ELEMENTS.contains(&name) => {
                    self.refuse_tree_element(c, el.clone());
                    continue;
                }
                _ => continue,
            }
            let jid = self.joint_ids;
            self.joint_ids += 1;
            let jname = jt.attr("name").map_or_else(|| format!("joint_{jid}"), str::to_string);
            let jel = Element::Joint(jname.clone());
            if joint.is_some() {
                self.error(
                    jel,
                    jt.line,
                    ErrorKind::NotSupported(format!(
                        "body `{name}` already has a joint; several joints in one body are not supported yet \
                         (split the body into a chain of massless bodies with one joint each)"
                    )),
                );
                continue;
            }
            let owner = Owner {
                parent,
                body: &name,
                placement: &placement,
                childless: self.children_named(k, "body").is_empty(),
            };
            if jt.name == "freejoint" {
                // MuJoCo's shorthand for a free joint without damping, friction,
                // armature or stiffness; it takes no class.
                joint = self.free_joint(jt, jname, &owner, JointDynamics::default());
                continue;
            }
            let class = self.class_of(jt, "class", &childclass, &jel);
            if let Some(desc) = self.read_joint(jt, &class, jname, &owner) {
                joint = Some(desc);
            }
        }

        // The inertial, in the link frame (on the joint).
        let joint_pos = joint.as_ref().map_or([0.0; 3], |(_, p)| *p);
        let inertials = self.children_named(k, "inertial");
        if let Some(&extra) = inertials.get(1) {
            self.error(
                el.clone(),
                tags[extra].line,
                ErrorKind::InvalidMjcf(format!("body `{name}` has more than one <inertial>")),
            );
        }
        let inertial = inertials
            .first()
            .and_then(|&i| self.read_inertial(&tags[i], &el, &joint_pos));

        self.links.push(LinkDesc {
            name: name.clone(),
            inertial,
            line: Some(t.line),
        });
        self.joints.push(match joint {
            Some((j, _)) => j,
            None => JointDesc {
                name: format!("{name} (fixed)"),
                kind: DeclaredJointType::Fixed,
                parent: parent.to_string(),
                child: name.clone(),
                origin: placement,
                axis: [0.0, 0.0, 1.0],
                limits: None,
                dynamics: JointDynamics::default(),
                line: Some(t.line),
            },
        });
        for c in self.children_named(k, "body") {
            self.read_body(c, &name, joint_pos, &childclass);
        }
    }

    fn refuse_tree_element(&mut self, k: usize, element: Element) {
        let t = &self.tags[k];
        self.error(
            element,
            t.line,
            ErrorKind::NotSupported(format!(
                "<{}> is not supported yet; write its bodies out as nested <body> elements",
                t.name
            )),
        );
    }

    /// One `<joint>` of the body `owner` describes: the description's joint and its
    /// `pos` (where the link frame sits in the body frame).
    fn read_joint(&mut self, t: &'t Tag, class: &str, name: String, owner: &Owner) -> Option<(JointDesc, Vec3)> {
        let el = Element::Joint(name.clone());
        let attr = |this: &Self, a: &str| this.joint_attr(t, class, a);
        let number = |this: &mut Self, a: &str, count: usize| -> Option<Vec<f64>> {
            let v = attr(this, a)?;
            this.parse_numbers(t, a, &v, count, &el)
        };
        let kind = attr(self, "type").unwrap_or_else(|| "hinge".into());
        let kind = match kind.as_str() {
            "hinge" => MjcfJoint::Hinge,
            "slide" => MjcfJoint::Slide,
            "ball" => MjcfJoint::Ball,
            "free" => MjcfJoint::Free,
            other => {
                self.error(
                    el,
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "joint type `{other}` is not an MJCF joint type (hinge, slide, ball, free)"
                    )),
                );
                return None;
            }
        };
        let scalar = |this: &mut Self, a: &str| number(this, a, 1).map_or(0.0, |v| v[0]);
        let dynamics = JointDynamics {
            damping: scalar(self, "damping"),
            friction: scalar(self, "frictionloss"),
        };
        for what in ["armature", "stiffness"] {
            let x = scalar(self, what);
            if x != 0.0 {
                self.warnings.push(ModelError {
                    element: el.clone(),
                    line: Some(t.line),
                    kind: ErrorKind::Ignored(format!(
                        "{what} = {x} is left out: the model has no place for it (the dynamics are the rigid \
                         body's alone)"
                    )),
                });
            }
        }
        if kind == MjcfJoint::Free {
            // MuJoCo ignores a free joint's pos, axis, range and ref.
            return self.free_joint(t, name, owner, dynamics);
        }
        let pos = number(self, "pos", 3).map_or([0.0; 3], |v| [v[0], v[1], v[2]]);
        let range = number(self, "range", 2);
        let limited = match attr(self, "limited").as_deref() {
            None | Some("auto") => self.autolimits && range.is_some(),
            Some("true") => true,
            Some("false") => false,
            Some(other) => {
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf(format!("<joint limited=\"{other}\"> is not `true`, `false` or `auto`")),
                );
                false
            }
        };
        let origin = Placement {
            rotation: owner.placement.rotation,
            translation: owner.placement.transform_point(&pos),
        };
        let desc = |kind: JointKind, axis: Vec3, limits: Option<Limits>| JointDesc {
            name: name.clone(),
            kind: DeclaredJointType::Moving(kind),
            parent: owner.parent.to_string(),
            child: owner.body.to_string(),
            origin,
            axis,
            limits,
            dynamics,
            line: Some(t.line),
        };
        if kind == MjcfJoint::Ball {
            // MuJoCo ignores a ball joint's axis and ref; its range bounds the angle of
            // rotation, which the model has no limit for.
            if limited {
                let range = range.map_or_else(String::new, |r| format!(" (range {} {})", r[0], r[1]));
                self.warnings.push(ModelError {
                    element: el.clone(),
                    line: Some(t.line),
                    kind: ErrorKind::Ignored(format!(
                        "the limit of this ball joint{range} is left out: the model has no limits for ball joints"
                    )),
                });
            }
            return Some((desc(JointKind::Spherical, [0.0; 3], None), pos));
        }
        let slide = kind == MjcfJoint::Slide;
        let axis = number(self, "axis", 3).map_or([0.0, 0.0, 1.0], |v| [v[0], v[1], v[2]]);
        if limited && range.is_none() {
            self.error(
                el.clone(),
                t.line,
                ErrorKind::InvalidMjcf("limited=\"true\" without a `range`; give range=\"lower upper\"".into()),
            );
        }
        let reference = scalar(self, "ref");
        if reference != 0.0 {
            self.error(
                el.clone(),
                t.line,
                ErrorKind::NotSupported(format!(
                    "a joint `ref` ({reference}) is not supported yet: it moves the joint's zero; rotate or \
                     move the body to the reference position instead"
                )),
            );
        }
        let effort = number(self, "actuatorfrcrange", 2).map_or(UNLIMITED, |v| v[0].abs().max(v[1].abs()));
        let limits = match (limited, range) {
            (true, Some(r)) => {
                let (lower, upper) = if slide {
                    (r[0], r[1])
                } else {
                    (self.angle(r[0]), self.angle(r[1]))
                };
                Some(Limits {
                    lower,
                    upper,
                    velocity: UNLIMITED,
                    effort,
                })
            }
            _ => None,
        };
        let kind = match (slide, limits.is_some()) {
            (true, _) => JointKind::Prismatic,
            (false, true) => JointKind::Revolute,
            (false, false) => JointKind::Continuous,
        };
        Some((desc(kind, axis, limits), pos))
    }

    /// A free joint (`<joint type="free">` or `<freejoint>`): a free flyer from the
    /// world, whose origin is the world frame (the body's placement is only MuJoCo's
    /// initial `qpos0`), or the error that refuses it.
    fn free_joint(
        &mut self,
        t: &Tag,
        name: String,
        owner: &Owner,
        dynamics: JointDynamics,
    ) -> Option<(JointDesc, Vec3)> {
        let el = Element::Joint(name.clone());
        if owner.parent != WORLD {
            // MuJoCo: "free joint can only be used on top level".
            self.error(el, t.line, ErrorKind::FreeFlyerNotAtRoot);
            return None;
        }
        // Only `<freejoint>` takes `align`; `<compiler alignfree>` is its default.
        let align = match t.attr("align").filter(|_| t.name == "freejoint") {
            None | Some("auto") => self.alignfree,
            Some("true") => true,
            Some("false") => false,
            Some(other) => {
                self.error(
                    el,
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "<{} align=\"{other}\"> is not `true`, `false` or `auto`",
                        t.name
                    )),
                );
                return None;
            }
        };
        if align && owner.childless {
            self.error(
                el,
                t.line,
                ErrorKind::NotSupported(format!(
                    "body `{}` would be aligned with its principal axes of inertia (align=\"true\", or <compiler \
                     alignfree=\"true\">), which moves its frame and so its free-joint coordinates; this is not \
                     supported: write align=\"false\"",
                    owner.body
                )),
            );
            return None;
        }
        let desc = JointDesc {
            name,
            kind: DeclaredJointType::Moving(JointKind::FreeFlyer),
            parent: owner.parent.to_string(),
            child: owner.body.to_string(),
            origin: Placement::IDENTITY,
            axis: [0.0; 3],
            limits: None,
            dynamics,
            line: Some(t.line),
        };
        Some((desc, [0.0; 3]))
    }

    /// An `<inertial>` in the link frame, which sits at `shift` in the body frame.
    fn read_inertial(&mut self, t: &Tag, el: &Element, shift: &Vec3) -> Option<Inertial> {
        let pos = self.vec3(t, "pos", el).unwrap_or([0.0; 3]);
        let rotation = self.orientation(t, el);
        let mass = match t.attr("mass") {
            Some(_) => self.numbers(t, "mass", 1, el)?[0],
            None => {
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf("<inertial> has no `mass`".into()),
                );
                return None;
            }
        };
        let inertia = match (t.attr("diaginertia"), t.attr("fullinertia")) {
            (Some(_), None) => {
                let d = self.numbers(t, "diaginertia", 3, el)?;
                [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]]
            }
            (None, Some(_)) => {
                // MuJoCo's order: ixx iyy izz ixy ixz iyz.
                let f = self.numbers(t, "fullinertia", 6, el)?;
                [[f[0], f[3], f[4]], [f[3], f[1], f[5]], [f[4], f[5], f[2]]]
            }
            (d, _) => {
                let why = if d.is_some() { "both" } else { "neither" };
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "<inertial> gives {why} `diaginertia` and `fullinertia`; give exactly one"
                    )),
                );
                return None;
            }
        };
        let local = Inertial {
            mass,
            com: [0.0; 3],
            inertia,
        };
        let mut inertial = local.transformed(&Placement {
            rotation,
            translation: math::sub(&pos, shift),
        });
        // Rounding in the rotation can leave the tensor a few ulps off symmetric.
        let m = inertial.inertia;
        for (r, row) in inertial.inertia.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                *x = 0.5 * (m[r][c] + m[c][r]);
            }
        }
        Some(inertial)
    }
}

fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn columns(x: Vec3, y: Vec3, z: Vec3) -> Mat3 {
    [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
}

/// The rotation of a MuJoCo quaternion `w x y z` (normalised first, as MuJoCo
/// does); `None` for a zero or non-finite one.
pub fn quat_matrix(q: [f64; 4]) -> Option<Mat3> {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n == 0.0 || !n.is_finite() {
        return None;
    }
    Some(math::quaternion_to_matrix(q.map(|c| c / n)))
}

/// Rotation by `angle` about the unit `axis` (Rodrigues); quarter turns exact.
fn axis_angle(axis: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = math::sin_cos_exact(angle);
    let [x, y, z] = *axis;
    let t = 1.0 - c;
    [
        [c + x * x * t, x * y * t - z * s, x * z * t + y * s],
        [y * x * t + z * s, c + y * y * t, y * z * t - x * s],
        [z * x * t - y * s, z * y * t + x * s, c + z * z * t],
    ]
}

/// MuJoCo's `zaxis`: the smallest rotation taking `0 0 1` to the unit `z`.
fn zaxis(z: &Vec3) -> Mat3 {
    let up = [0.0, 0.0, 1.0];
    let axis = cross(&up, z);
    let s = math::norm(&axis);
    if s < 1e-12 {
        return if z[2] > 0.0 {
            math::IDENTITY
        } else {
            axis_angle(&[1.0, 0.0, 0.0], std::f64::consts::PI)
        };
    }
    axis_angle(&math::scale(1.0 / s, &axis), s.atan2(z[2]))
}
