//! URDF front end: reads a URDF with `urdf-rs` into a [`Description`] and checks it
//! into a [`Model`]. `urdf-rs` keeps no source positions, so a light scan of the raw
//! text supplies line numbers, spots unexpanded xacro, and tells which optional
//! elements (`<inertial>`, `<limit>`) were actually written.

use crate::desc::{
    DeclaredJointType, Description, JointDesc, LinkDesc, LoadOptions, MimicDesc, SiblingOrder, DEFAULT_GRAVITY,
};
use crate::error::{Element, ErrorKind, ModelError, ModelErrors};
use crate::ir::{Inertial, JointDynamics, JointKind, Limits, Model, Placement};
use crate::math;
use crate::xml::{is_xml_space, scan, shorten, SyntaxError, Tag};
use std::io::Read as _;
use std::path::Path;

/// Largest URDF accepted, in bytes. The biggest public descriptions (humanoids with
/// inline meshes stripped) are a few MiB; anything far larger is not a robot
/// description, and reading it would only exhaust memory.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// Parses and checks URDF text; errors carry line numbers but no file name.
/// Inertias within [`INERTIA_TOLERANCE`](crate::desc::INERTIA_TOLERANCE) of
/// physical are accepted as written, each with a warning in [`Model::warnings`].
pub fn parse_urdf(text: &str) -> Result<Model, ModelErrors> {
    parse_urdf_with(text, false)
}

/// [`parse_urdf`]; `strict` refuses what it would accept with a warning.
pub fn parse_urdf_with(text: &str, strict: bool) -> Result<Model, ModelErrors> {
    parse_urdf_options(
        text,
        LoadOptions {
            strict,
            ..LoadOptions::default()
        },
    )
}

/// [`parse_urdf`] with every [`LoadOptions`] (a free flyer under the root link).
pub fn parse_urdf_options(text: &str, options: LoadOptions) -> Result<Model, ModelErrors> {
    build(text, options).map_err(|errors| ModelErrors { file: None, errors })
}

/// Reads, parses and checks a URDF file; errors are prefixed with its path.
/// Warnings as for [`parse_urdf`].
pub fn load_urdf(path: &Path) -> Result<Model, ModelErrors> {
    load_urdf_with(path, false)
}

/// [`load_urdf`]; `strict` refuses what it would accept with a warning.
pub fn load_urdf_with(path: &Path, strict: bool) -> Result<Model, ModelErrors> {
    load_urdf_options(
        path,
        LoadOptions {
            strict,
            ..LoadOptions::default()
        },
    )
}

/// [`load_urdf`] with every [`LoadOptions`] (a free flyer under the root link).
pub fn load_urdf_options(path: &Path, options: LoadOptions) -> Result<Model, ModelErrors> {
    let file = Some(path.display().to_string());
    let fail = |kind: ErrorKind| ModelErrors {
        file: file.clone(),
        errors: vec![robot_error(None, kind)],
    };
    let io = |e: std::io::Error| fail(ErrorKind::Io(e.to_string()));
    let mut text = String::new();
    // Never more than the limit in memory, whatever the metadata says.
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_string(&mut text))
        .map_err(io)?;
    if text.len() as u64 > MAX_FILE_BYTES {
        let bytes = std::fs::metadata(path).map_or(text.len() as u64, |m| m.len());
        return Err(fail(ErrorKind::TooLarge { bytes }));
    }
    build(&text, options).map_err(|errors| ModelErrors { file, errors })
}

/// The unchecked description of URDF text, before [`Description::build`]: for
/// callers that want to adjust it (gravity, say) before checking.
pub fn urdf_description(text: &str) -> Result<Description, ModelErrors> {
    let fail = |errors| ModelErrors { file: None, errors };
    let (desc, _, _) = read(text).map_err(fail)?;
    Ok(desc)
}

fn build(text: &str, options: LoadOptions) -> Result<Model, Vec<ModelError>> {
    let strict = options.strict;
    let (mut desc, robot_line, notes) = read(text)?;
    if options.free_flyer {
        desc = desc.with_free_flyer();
    }
    // Siblings by joint name, as urdfdom and so Pinocchio number them.
    let mut errors = match desc.build_checked(SiblingOrder::Name, options) {
        Ok(mut model) if !strict || notes.is_empty() => {
            model.warnings.extend(notes);
            return Ok(model);
        }
        // A strict build refuses what it would accept with a warning.
        Ok(_) if strict => notes,
        Ok(_) => Vec::new(),
        Err(mut errors) => {
            if strict {
                errors.extend(notes);
            }
            errors
        }
    };
    // Robot-wide errors (several roots, nothing moves) point at `<robot>`.
    for e in &mut errors {
        if e.element == Element::Robot && e.line.is_none() {
            e.line = robot_line;
        }
    }
    // In file order, as a compiler lists them; the sort is stable for ties.
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

/// What [`read`] gives: the description, the line of `<robot>`, and what it is read
/// with a warning for (a planar joint without `<axis>`).
type ReadOutcome = (Description, Option<usize>, Vec<ModelError>);

/// Reads URDF text into a description and the line of its `<robot>` element.
fn read(text: &str) -> Result<ReadOutcome, Vec<ModelError>> {
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
        // Past the depth limit the text must not reach urdf-rs, whose recursive
        // descent would overflow the stack.
        Err(SyntaxError {
            line,
            too_deep: Some(tag),
            ..
        }) => return Err(vec![robot_error(Some(line), ErrorKind::TooDeep { tag })]),
        // Nor any text the scan cannot read: the scan is what holds the nesting limit
        // (past a DOCTYPE it could not close, say) and refuses what urdf-rs would
        // read wrongly (a second document element, a NUL).
        Err(e) => return Err(vec![robot_error(Some(e.line), ErrorKind::Parse(e.message))]),
    };
    if let Some(line) = xacro_line(&tags) {
        return Err(vec![robot_error(Some(line), ErrorKind::Xacro)]);
    }
    // urdf-rs stops at the first unreadable number without a position; it also reads
    // any document element as <robot>, a link named "", and an unusable `quat_xyzw`
    // as no rotation ([`urdf_errors`]).
    let numbers = [urdf_errors(&tags), number_errors(&tags)].concat();
    if !numbers.is_empty() {
        return Err(numbers);
    }
    let robot = match urdf_rs::read_from_string(&without_geometry(text, &tags)) {
        Ok(robot) => robot,
        Err(e) => return Err(parse_errors(&tags, &e.to_string())),
    };
    let outline = Outline::new(&tags);

    let links = robot
        .links
        .iter()
        .enumerate()
        .map(|(k, link)| {
            let source = outline.link(k, &link.name);
            let has_inertial = match source {
                Some(s) => s.has_child("inertial"),
                // urdf-rs fills a missing <inertial> with zeros.
                None => link.inertial.mass.value != 0.0 || inertia_matrix(&link.inertial.inertia) != [[0.0; 3]; 3],
            };
            LinkDesc {
                name: link.name.clone(),
                inertial: has_inertial.then(|| convert_inertial(&link.inertial)),
                line: source.map(|s| s.tag.line),
            }
        })
        .collect();

    let joints = robot
        .joints
        .iter()
        .enumerate()
        .map(|(k, joint)| {
            let source = outline.joint(k, &joint.name);
            let kind = convert_type(&joint.joint_type);
            // urdf-rs fills a missing <limit> with zeros, which would lock the joint.
            let has_limit = source.is_none_or(|s| s.has_child("limit"));
            let limits = match kind {
                DeclaredJointType::Moving(JointKind::Revolute | JointKind::Prismatic) if has_limit => Some(Limits {
                    lower: joint.limit.lower,
                    upper: joint.limit.upper,
                    velocity: joint.limit.velocity,
                    effort: joint.limit.effort,
                }),
                _ => None,
            };
            JointDesc {
                name: joint.name.clone(),
                kind,
                parent: joint.parent.link.clone(),
                child: joint.child.link.clone(),
                origin: Placement::from_xyz_rpy(joint.origin.xyz.0, joint.origin.rpy.0),
                axis: joint.axis.xyz.0,
                limits,
                dynamics: joint
                    .dynamics
                    .as_ref()
                    .map(|d| JointDynamics {
                        armature: 0.0,
                        damping: d.damping,
                        friction: d.friction,
                    })
                    .unwrap_or_default(),
                line: source.map(|s| s.tag.line),
            }
        })
        .collect();

    // A planar joint without <axis> moves, as URDF says, in the plane normal to x;
    // Pinocchio's reader takes z whatever the axis, and a base on the floor wants z.
    let notes = robot
        .joints
        .iter()
        .enumerate()
        .filter_map(|(k, joint)| {
            let source = outline.joint(k, &joint.name)?;
            (matches!(joint.joint_type, urdf_rs::JointType::Planar) && !source.has_child("axis")).then(|| ModelError {
                element: Element::Joint(joint.name.clone()),
                line: Some(source.tag.line),
                kind: ErrorKind::Ignored(
                    "this planar joint has no <axis>, so its plane is normal to URDF's default axis x (it \
                         moves along y and z); Pinocchio's reader would take z. Give <axis xyz=\"0 0 1\"/> for a \
                         base moving on the floor"
                        .to_string(),
                ),
            })
        })
        .collect();
    // A <mimic> on a fixed joint has nothing to follow with: ignored, as urdfdom does.
    let mimics = robot
        .joints
        .iter()
        .filter(|j| !matches!(j.joint_type, urdf_rs::JointType::Fixed))
        .filter_map(|j| {
            let m = j.mimic.as_ref()?;
            Some(MimicDesc {
                joint: j.name.clone(),
                leader: m.joint.clone(),
                multiplier: m.multiplier.unwrap_or(1.0),
                offset: m.offset.unwrap_or(0.0),
                line: mimic_line(&tags, &j.name),
            })
        })
        .collect();
    let desc = Description {
        name: robot.name.clone(),
        gravity: DEFAULT_GRAVITY,
        links,
        joints,
        mimics,
    };
    Ok((desc, outline.robot_line, notes))
}

/// The numeric attributes of the elements dyngen reads, with how many numbers each
/// holds. Geometry (`<visual>`, `<collision>`) is not read, so not checked.
fn numeric_attributes(owner: &str, element: &str) -> &'static [(&'static str, usize)] {
    match (owner, element) {
        (_, "origin") => &[("xyz", 3), ("rpy", 3)],
        ("link", "mass") => &[("value", 1)],
        ("link", "inertia") => &[("ixx", 1), ("ixy", 1), ("ixz", 1), ("iyy", 1), ("iyz", 1), ("izz", 1)],
        ("joint", "axis") => &[("xyz", 3)],
        ("joint", "mimic") => &[("multiplier", 1), ("offset", 1)],
        ("joint", "limit") => &[("lower", 1), ("upper", 1), ("effort", 1), ("velocity", 1)],
        ("joint", "dynamics") => &[("damping", 1), ("friction", 1)],
        ("joint", "calibration") => &[("rising", 1), ("falling", 1)],
        ("joint", "safety_controller") => &[
            ("soft_lower_limit", 1),
            ("soft_upper_limit", 1),
            ("k_position", 1),
            ("k_velocity", 1),
        ],
        _ => &[],
    }
}

/// The `<link>` or `<joint>` directly under `<robot>` that a numeric element belongs
/// to: its parent for a joint's elements, its grandparent through `<inertial>` for a
/// link's.
fn owner_of<'t>(tags: &'t [Tag], tag: &Tag) -> Option<&'t Tag> {
    let is_top = |t: &Tag| t.parent.is_some_and(|p| tags[p].parent.is_none());
    let parent = &tags[tag.parent?];
    if parent.name == "joint" && is_top(parent) {
        return Some(parent);
    }
    let owner = &tags[parent.parent?];
    (parent.name == "inertial" && owner.name == "link" && is_top(owner)).then_some(owner)
}

fn element_of(owner: &Tag) -> Element {
    let name = owner.attr("name").unwrap_or_default().to_string();
    match owner.name.as_str() {
        "link" => Element::Link(name),
        _ => Element::Joint(name),
    }
}

/// Every numeric attribute that does not hold the numbers its element needs, with
/// its line and the link or joint it belongs to. Numbers as Rust and urdfdom read
/// them (`nan` and `inf` are numbers here; the model's checks refuse them).
fn number_errors(tags: &[Tag]) -> Vec<ModelError> {
    let mut errors = Vec::new();
    for tag in tags {
        let Some(owner) = owner_of(tags, tag) else { continue };
        for &(attribute, expected) in numeric_attributes(&owner.name, &tag.name) {
            let Some(value) = tag.attr(attribute) else { continue };
            let words: Vec<&str> = value.split_whitespace().collect();
            if words.len() != expected || words.iter().any(|w| w.parse::<f64>().is_err()) {
                errors.push(ModelError {
                    element: element_of(owner),
                    line: Some(tag.line),
                    kind: ErrorKind::BadNumber {
                        attribute: format!("{} {attribute}", tag.name),
                        value: value.to_string(),
                        expected,
                    },
                });
            }
        }
    }
    errors
}

/// What a URDF must hold that urdf-rs does not check, each with its element and
/// line: `<robot>` as the document element, a non-empty name on every link and
/// joint, and a `quat_xyzw` (URDF 1.1) that is a rotation. urdf-rs reads any
/// document element as the robot, a link named "", and turns a `quat_xyzw` that is
/// not a number (`nan`), has no direction (`0 0 0 0`, `1e-200 0 0 0`) or no finite
/// norm (`1e300 1e300 0 0`) into the identity; a URDF 1.0 reader ignores
/// `quat_xyzw`. `tags` is an outline from [`scan`].
fn urdf_errors(tags: &[Tag]) -> Vec<ModelError> {
    let Some(root) = tags.first() else { return Vec::new() };
    let error = |element: Element, line: usize, message: String| ModelError {
        element,
        line: Some(line),
        kind: ErrorKind::Parse(message),
    };
    if root.name != "robot" {
        return vec![error(
            Element::Robot,
            root.line,
            format!(
                "the document element is <{}>, not <robot>; a URDF describes one <robot name=\"...\"> holding its \
                 <link> and <joint> elements",
                shorten(&root.name)
            ),
        )];
    }
    let mut errors = Vec::new();
    for t in tags.iter().filter(|t| t.parent == Some(0)) {
        let element: fn(String) -> Element = match t.name.as_str() {
            "link" => Element::Link,
            "joint" => Element::Joint,
            _ => continue,
        };
        let name = t.attr("name").unwrap_or_default();
        if name.trim_matches(is_xml_space).is_empty() {
            let what = if t.attr("name").is_some() {
                "an empty name"
            } else {
                "no name"
            };
            errors.push(error(
                element(name.to_string()),
                t.line,
                format!(
                    "this <{}> has {what}; every link and joint needs a unique name, such as name=\"{}_1\"",
                    t.name, t.name
                ),
            ));
        }
    }
    let version = root
        .attr("version")
        .and_then(|v| {
            let (major, minor) = v.trim().split_once('.')?;
            Some((major.parse::<u32>().ok()?, minor.parse::<u32>().ok()?))
        })
        .unwrap_or((1, 0));
    for t in tags.iter().filter(|t| t.name == "origin") {
        let Some(quat) = t.attr("quat_xyzw") else { continue };
        // The link or joint (a child of <robot>) the origin belongs to.
        let mut owner = t.parent;
        while let Some(k) = owner.filter(|&k| tags[k].parent.is_some_and(|p| p != 0)) {
            owner = tags[k].parent;
        }
        let element = match owner.map(|k| &tags[k]) {
            Some(o) if o.name == "link" || o.name == "joint" => element_of(o),
            _ => Element::Robot,
        };
        let shown = format!("<origin quat_xyzw=\"{}\">", shorten(quat));
        let message = if version < (1, 1) {
            Some(format!(
                "{shown} is URDF 1.1, but this file is URDF {}.{} (the `version` of <robot>), whose readers ignore \
                 quat_xyzw and would leave this origin unrotated; write version=\"1.1\" on <robot>, or give the \
                 rotation as rpy",
                version.0, version.1
            ))
        } else if t.attr("rpy").is_some() {
            Some(format!(
                "{shown} also gives rpy; give the rotation once, as rpy or as quat_xyzw"
            ))
        } else {
            quaternion_problem(quat).map(|problem| format!("{shown} {problem}"))
        };
        if let Some(message) = message {
            errors.push(error(element, t.line, message));
        }
    }
    errors
}

/// Smallest and largest norm of a `quat_xyzw` taken as a rotation: within them
/// the quaternion normalises exactly (its squares neither underflow nor overflow).
pub const QUATERNION_NORM_RANGE: (f64, f64) = (1e-6, 1e6);

/// Why `quat_xyzw` text is not a rotation: not four numbers, not finite, or a norm
/// outside [`QUATERNION_NORM_RANGE`].
fn quaternion_problem(quat: &str) -> Option<String> {
    const VALID: &str = "write a rotation as a unit quaternion x y z w, such as `0 0 0 1` (none) or \
                         `0 0 0.7071068 0.7071068` (90° about z)";
    let q: Vec<f64> = match quat
        .split_whitespace()
        .map(str::parse::<f64>)
        .collect::<Result<Vec<_>, _>>()
    {
        Ok(q) if q.len() == 4 => q,
        _ => return Some(format!("is not four numbers; {VALID}")),
    };
    if q.iter().any(|x| !x.is_finite()) {
        return Some(format!("holds a value that is not a finite number; {VALID}"));
    }
    // The norm, scaled so that its squares neither underflow nor overflow.
    let scale = q.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let norm = if scale == 0.0 {
        0.0
    } else {
        scale * q.iter().map(|x| (x / scale).powi(2)).sum::<f64>().sqrt()
    };
    let (low, high) = QUATERNION_NORM_RANGE;
    (!(low..=high).contains(&norm)).then(|| {
        format!(
            "has norm {norm:e}, not a rotation: it is normalised to norm 1, which needs a norm between {low:e} and \
             {high:e}; {VALID}"
        )
    })
}

/// The line of the `<mimic>` of the joint named `joint`.
fn mimic_line(tags: &[Tag], joint: &str) -> Option<usize> {
    tags.iter()
        .filter(|t| t.name == "mimic")
        .find(|t| owner_of(tags, t).is_some_and(|o| o.name == "joint" && o.attr("name") == Some(joint)))
        .map(|t| t.line)
}

/// Turns a failure of urdf-rs into errors. urdf-rs stops at the first problem and
/// gives no position, so the scan's own findings come first when it has any.
fn parse_errors(tags: &[Tag], message: &str) -> Vec<ModelError> {
    let unknown_types: Vec<ModelError> = Outline::new(tags)
        .joints
        .iter()
        .filter_map(|j| {
            let t = j.tag.attr("type")?;
            (!KNOWN_JOINT_TYPES.contains(&t)).then(|| ModelError {
                element: Element::Joint(j.tag.attr("name").unwrap_or_default().to_string()),
                line: Some(j.tag.line),
                kind: ErrorKind::UnsupportedJointType(t.to_string()),
            })
        })
        .collect();
    if unknown_types.is_empty() {
        // serde's "custom: " prefix says nothing to a URDF author.
        let message = message.strip_prefix("custom: ").unwrap_or(message);
        vec![robot_error(None, ErrorKind::Parse(message.to_string()))]
    } else {
        unknown_types
    }
}

/// Joint types urdf-rs can read; any other is rejected by it without a position.
const KNOWN_JOINT_TYPES: [&str; 7] = [
    "revolute",
    "continuous",
    "prismatic",
    "fixed",
    "floating",
    "planar",
    "spherical",
];

fn convert_type(t: &urdf_rs::JointType) -> DeclaredJointType {
    use urdf_rs::JointType as T;
    match t {
        T::Revolute => DeclaredJointType::Moving(JointKind::Revolute),
        T::Continuous => DeclaredJointType::Moving(JointKind::Continuous),
        T::Prismatic => DeclaredJointType::Moving(JointKind::Prismatic),
        T::Fixed => DeclaredJointType::Fixed,
        T::Floating => DeclaredJointType::Moving(JointKind::FreeFlyer),
        T::Planar => DeclaredJointType::Moving(JointKind::Planar),
        T::Spherical => DeclaredJointType::Moving(JointKind::Spherical),
    }
}

fn inertia_matrix(i: &urdf_rs::Inertia) -> math::Mat3 {
    [[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]]
}

/// URDF gives the inertia about the centre of mass in the axes of the inertial
/// `<origin>`; the model wants it in the link axes: `R I Rᵀ`.
fn convert_inertial(i: &urdf_rs::Inertial) -> Inertial {
    let local = Inertial {
        mass: i.mass.value,
        com: [0.0; 3],
        inertia: inertia_matrix(&i.inertia),
    };
    let mut inertial = local.transformed(&Placement::from_xyz_rpy(i.origin.xyz.0, i.origin.rpy.0));
    // Rounding in the rotation can leave the tensor a few ulps off symmetric.
    let m = inertial.inertia;
    for (r, row) in inertial.inertia.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = 0.5 * (m[r][c] + m[c][r]);
        }
    }
    inertial
}

/// The text with every `<visual>`, `<collision>` and `<material>` blanked out (newlines
/// kept, so lines still match). Dynamics never needs them, and urdf-rs rejects some
/// geometry that urdfdom accepts, such as a `<texture/>` without a file name.
fn without_geometry(text: &str, tags: &[Tag]) -> String {
    let mut spans: Vec<std::ops::Range<usize>> = tags
        .iter()
        .filter(|t| matches!(t.name.as_str(), "visual" | "collision" | "material"))
        .map(|t| t.span.clone())
        .collect();
    if spans.is_empty() {
        return text.to_string();
    }
    spans.sort_by_key(|r| r.start);
    let mut out = String::with_capacity(text.len());
    let mut spans = spans.into_iter().peekable();
    for (k, c) in text.char_indices() {
        // Spans nest (a <material> inside a <visual>); drop those already passed.
        while spans.peek().is_some_and(|r| r.end <= k) {
            spans.next();
        }
        let blank = spans.peek().is_some_and(|r| r.contains(&k));
        out.push(if blank && c != '\n' { ' ' } else { c });
    }
    out
}

/// The line of the first xacro element, or of the first attribute that still holds
/// a `${...}` expression or `$(...)` substitution. Only markup counts: shipped URDFs
/// often keep xacro in comments, or a leftover `xmlns:xacro` on `<robot>`.
fn xacro_line(tags: &[Tag]) -> Option<usize> {
    tags.iter()
        .find(|t| t.name.starts_with("xacro:") || t.attrs.iter().any(|(_, v)| v.contains("${") || v.contains("$(")))
        .map(|t| t.line)
}

// ---------------------------------------------------------------------------------
// A minimal XML scan: start tags with their attributes, lines and nesting. It is not
// a validating parser; urdf-rs decides what is valid. It only has to be right on
// files urdf-rs accepts, and to name a line when a file is plainly malformed.

/// One `<link>` or `<joint>` directly under `<robot>`.
#[derive(Debug)]
struct Source<'a> {
    tag: &'a Tag,
    children: Vec<&'a str>,
}

impl Source<'_> {
    fn has_child(&self, name: &str) -> bool {
        self.children.contains(&name)
    }

    fn name(&self) -> &str {
        self.tag.attr("name").unwrap_or_default()
    }
}

/// The links and joints of the document in source order, which is also urdf-rs's
/// order, so the k-th link read is the k-th `<link>` here.
#[derive(Debug, Default)]
struct Outline<'a> {
    robot_line: Option<usize>,
    links: Vec<Source<'a>>,
    joints: Vec<Source<'a>>,
}

impl<'a> Outline<'a> {
    fn new(tags: &'a [Tag]) -> Outline<'a> {
        let mut outline = Outline::default();
        let Some(root) = tags.iter().position(|t| t.parent.is_none()) else {
            return outline;
        };
        outline.robot_line = Some(tags[root].line);
        // Only direct children of <robot>: a <transmission> holds <joint> elements too.
        let mut index = vec![None; tags.len()];
        for (k, t) in tags.iter().enumerate() {
            if t.parent != Some(root) {
                continue;
            }
            let list = match t.name.as_str() {
                "link" => &mut outline.links,
                "joint" => &mut outline.joints,
                _ => continue,
            };
            index[k] = Some((t.name == "link", list.len()));
            list.push(Source {
                tag: t,
                children: Vec::new(),
            });
        }
        for t in tags {
            if let Some((is_link, k)) = t.parent.and_then(|p| index[p]) {
                let list = if is_link {
                    &mut outline.links
                } else {
                    &mut outline.joints
                };
                list[k].children.push(t.name.as_str());
            }
        }
        outline
    }

    fn link(&self, k: usize, name: &str) -> Option<&Source<'a>> {
        Self::find(&self.links, k, name)
    }

    fn joint(&self, k: usize, name: &str) -> Option<&Source<'a>> {
        Self::find(&self.joints, k, name)
    }

    /// The k-th element if its name agrees, else the first of that name.
    fn find<'s>(list: &'s [Source<'a>], k: usize, name: &str) -> Option<&'s Source<'a>> {
        list.get(k)
            .filter(|s| s.name() == name)
            .or_else(|| list.iter().find(|s| s.name() == name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_reads_tags_lines_and_nesting() {
        let text = "<?xml version='1.0'?>\n<!-- <link name='ghost'/> -->\n<robot name = \"r\">\n  <link\n    name='a&amp;b' ><inertial/></link>\n</robot>\n";
        let tags = scan(text).unwrap();
        let names: Vec<&str> = tags.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["robot", "link", "inertial"]);
        assert_eq!(tags[0].line, 3);
        assert_eq!(tags[1].line, 4);
        assert_eq!(tags[1].attr("name"), Some("a&b"));
        assert_eq!(tags[2].parent, Some(1));
        let outline = Outline::new(&tags);
        assert_eq!(outline.robot_line, Some(3));
        assert!(outline.links[0].has_child("inertial"));
    }
}
