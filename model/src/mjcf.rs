//! MJCF (MuJoCo XML) front end for the subset robot arms use: reads the text with the
//! scan of [`crate::xml`] (lines, size and nesting limits) into the same
//! [`Description`] as the URDF front end, so checking, merging and numbering are
//! shared.
//!
//! Read: `<mujoco model>`, `<compiler angle eulerseq autolimits alignfree
//! inertiafromgeom inertiagrouprange boundmass boundinertia balanceinertia
//! settotalmass meshdir assetdir strippath fitaabb>` (MuJoCo's default angle unit is the
//! degree), `<option gravity>` and its `<flag gravity="disable">` (no gravity),
//! `<default>` classes (nested, `class` on joints, geoms, sites and meshes,
//! `childclass` on bodies) for joint, geom, site and mesh attributes, `<asset><mesh>`
//! (below), `<worldbody>` with nested `<body name
//! pos quat|euler|axisangle|xyaxes|zaxis>`, `<inertial pos mass diaginertia (with an
//! orientation) | fullinertia (without one)>`, any number of `<joint
//! type="hinge|slide|ball|free" pos axis range limited ref damping frictionloss
//! armature actuatorfrcrange>` and `<freejoint name align>` per body, `<geom>` for
//! the inertia (below) and `<site name pos quat|euler|axisangle|xyaxes|zaxis|fromto>`.
//! A body without a joint is a fixed link, merged as a URDF fixed joint. MuJoCo's
//! worldbody is the base, the link `world`.
//!
//! A joint's `pos` (a point on its axis, in the body frame) moves the link frame onto
//! the joint, as URDF has it: the joint origin is the body placement followed by a
//! translation by `pos`, and the body's inertial and its children's placements are
//! re-expressed in that frame (`pos` subtracted).
//!
//! A joint's `ref` is its position in the placement the XML writes (MuJoCo's
//! `qpos0`): the joint origin is that placement turned back by `ref` about the axis
//! (hinge, in the file's angle unit) or moved back by `ref` along it (slide), so the
//! model's `q` is MuJoCo's `qpos`. MuJoCo ignores `ref` on ball and free joints, and
//! so does this reader.
//!
//! Several joints in one body compose in order, as MuJoCo composes them, each about
//! its own `pos` in the body frame: every joint but the last moves a massless link
//! named `BODY (JOINT)` (its frame at that joint's `pos`, with the body's axes before
//! the later joints move it), the last carries the body itself, whose link frame is
//! at the last joint's `pos`. A free joint must be its body's only joint.
//!
//! `armature` is the rotor inertia `Ia` of [`JointDynamics::armature`], on each of the
//! joint's coordinates (MuJoCo's `dof_armature`: `M + diag(Ia)` is MuJoCo's `qM`).
//! On a free joint MuJoCo's armature acts on the linear acceleration in world axes
//! and dyngen's on the one in body axes: the mass matrices agree, the bias forces do
//! not, which a warning says. A negative armature is refused. `stiffness` (and its
//! `springref`) is left out with a warning: the model has no joint springs.
//!
//! # Inertia
//!
//! A body's inertial is its `<inertial>`, or, as MuJoCo's compiler makes it with
//! `inertiafromgeom="auto"` (the default) for a body without `<inertial>` and with
//! `"true"` for every body, the sum of its geoms': each geom of a group in
//! `inertiagrouprange` (default `0 5`) with mass (its `mass`, or `density` (default
//! 1000) times its volume; `mass="0"` or `density="0"` give none) is a solid sphere
//! (`size` r), capsule or cylinder (`size` r, half length; or `fromto` and r), box
//! (half sizes; with `fromto`, `size[0]` for x and y and half the length for z) or
//! ellipsoid (semi-axes, `fromto` as the box), at its `pos` and orientation (or
//! `fromto`'s middle, `z` along it), combined about their common centre of mass; or
//! a mesh (below), or a primitive fitted to a mesh (below). Sdf, plane and hfield
//! geoms that would give a body its inertia and `shellinertia="true"` (which MuJoCo
//! refuses on a mesh geom) are refused naming the geom and line. Then each body's
//! mass is raised to `boundmass` and its principal moments to `boundinertia`
//! (MuJoCo leaves a body without mass of its own with its inertial frame at the
//! numbers of its `pos`, so the mass `boundmass` gives it sits there too); with
//! `balanceinertia`, moments that break the triangle inequality are all set to their
//! mean; last, `settotalmass` scales every body's mass and inertia so that they add
//! up to it. A moving body with no mass at all is left to the checks of
//! [`Description::build_checked`].
//!
//! ## Meshes
//!
//! A `type="mesh"` geom gives the inertia of its `<asset><mesh>` (named by `name`,
//! else by its file's name without folder and extension), as MuJoCo's compiler makes
//! it (`mjCMesh::Process` in MuJoCo's `user_mesh.cc`, `mjCGeom::SetInertia` in
//! `user_objects.cc`; the formulas are in `model/src/mjcf_mesh.rs`):
//!
//! - the triangles of `file`, a binary STL (an ASCII STL is refused, as MuJoCo refuses
//!   it) or a Wavefront OBJ (its first object's triangles and quadrilaterals), found
//!   at `meshdir` (else `assetdir`) joined with `file` (its folders dropped with
//!   `strippath`), relative to the model file's folder and never outside it (the
//!   `<include>` rule; MJCF text read without its file has no folder, so only inline
//!   meshes); or `vertex` (and `face`, else the convex hull's triangles) inline;
//! - the vertices in single precision, as MuJoCo keeps them, moved by `refpos`,
//!   turned by `refquat`, scaled by `scale` (a mirroring scale reverses the
//!   triangles);
//! - `inertia="legacy"` (MuJoCo's default): tetrahedra from the triangles'
//!   area-weighted centroid, their volumes taken positive (too much volume for a
//!   non-convex mesh); `"convex"`: the same over the convex hull; `"exact"`: signed
//!   tetrahedra, for a closed mesh with outward triangles; `"shell"`: unit surface
//!   density on the triangles;
//! - `maxhullvert` (-1, no limit, or above 3, as MuJoCo requires it): MuJoCo stops
//!   its hull (qhull's `TA` option) once it has that many vertices, at points
//!   chosen by qhull's order of additions, which is not reproduced here. So where
//!   the hull gives the inertia (`"convex"`, or a mesh of vertices alone, whose
//!   faces are the hull's) and the mesh has more distinct vertices than the limit,
//!   the mesh is refused; a limit at least that count stops nothing and is read;
//!   elsewhere the hull is MuJoCo's collision shape only and the limit changes no
//!   inertia;
//! - mass: the geom's `mass`, else `density` times the volume (area for a shell);
//!   the inertia about the centre of mass through MuJoCo's eigen decomposition and
//!   box of equal inertia; the geom's `pos` and orientation place the mesh frame.
//!
//! A box, sphere, capsule, cylinder or ellipsoid geom naming a `mesh` is fitted to
//! it, as MuJoCo 4's compiler fits it (`mjCMesh::FitGeom`), its `size` ignored: from
//! half sides `h` along the mesh's principal axes, those of its box of equal inertia
//! (the default), or with `<compiler fitaabb="true">` those of its vertices'
//! bounding box in that frame, a box or ellipsoid takes `h`; by default a sphere
//! their mean, a cylinder the radius `r = (h0 + h1) / 2` and half length `h2`, a
//! capsule that `r` and `max(0, h2 - r / 2)`; with `fitaabb` a sphere the largest,
//! a cylinder `r = max(h0, h1)` and `h2`, a capsule that `r` and `h2 - r`; every size
//! then times the geom's `fitscale` (default 1). The primitive sits in the mesh's
//! principal frame (its origin at the bounding box's centre with `fitaabb`) placed
//! by the geom's `pos` and orientation, and weighs its `mass` or `density` times its
//! own volume. Refused naming the geom and line: another type naming a mesh, a
//! `fromto` with a mesh, a `fitscale` that is not a positive number, and a fitted
//! size that is not positive (MuJoCo refuses it too: a capsule fitted to a round
//! mesh's bounding box has no length).
//!
//! Refused, each naming the `<mesh>`, its line and the file as written: a file that
//! is missing, unreadable, of another format (`.msh` included), an OBJ without faces
//! or with faces of more than 4 vertices, a path out of the model's folder, and a
//! mesh MuJoCo refuses (no area, no volume in a volume mode, inside out with
//! `exact`, an inertia breaking the triangle inequality). A geom naming an unknown
//! mesh is refused on its own line.
//!
//! # Sites
//!
//! A named `<site>` is a frame of the model ([`crate::ir::Frame`]), a link without
//! inertial fixed to its body (or to the base, in `<worldbody>`), at its `pos` and
//! orientation (or `fromto`) in the body frame. An unnamed site (MuJoCo allows them)
//! is skipped: no frame. A site named as a body (MuJoCo's sites and bodies have
//! separate names, dyngen's frames and bodies one namespace) is left out with a
//! warning: no frame.
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
//!   `<worldbody>` (MuJoCo refuses a free joint deeper down, see
//!   [`ErrorKind::FreeFlyerNotAtRoot`]); several free bodies load, each a free flyer
//!   on the world, as in MuJoCo (a robot and a ball, say). MuJoCo ignores a
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
//! `<worldbody>` or with other joints in its body, `<frame>`,
//! `<replicate>`, `<attach>`, `<composite>`, `<flexcomp>`, unknown classes,
//! `fullinertia` with an orientation on the `<inertial>` (MuJoCo refuses it too),
//! `<compiler coordinate="global">`, the geoms above, the `<equality><joint>`s MuJoCo
//! refuses (below). Left out with a warning naming the element and its line: the
//! elements of `<equality>` the model cannot hold (below) and each element of
//! `<tendon>` (the dynamics treat the joints as independent), a joint's `stiffness`, a
//! ball joint's `range`, and every `<compiler>` attribute not read that is not known to
//! leave the dynamics alone (and `exactmeshinertia`, which MuJoCo 4 refuses). Cameras, lights,
//! assets other than meshes (and meshes that no geom giving an inertia uses),
//! actuators, sensors, geoms of bodies with an `<inertial>` and the rest are
//! skipped.
//!
//! # Equality constraints
//!
//! MuJoCo's `<equality><joint joint1 joint2 polycoef="c0 c1 c2 c3 c4">` holds
//! `q1 - ref1 = c0 + c1 (q2 - ref2) + c2 (q2 - ref2)² + c3 (…)³ + c4 (…)⁴`, with `ref`
//! each joint's `qpos0` (in radians for a hinge whatever the file's angle unit;
//! `polycoef` is used as written, never converted) and the numbers not written
//! keeping the default `0 1 0 0 0`. Where that is linear (`c2 = c3 = c4 = 0`) and
//! `joint2` is given, joint1 follows joint2 as a mimic joint ([`MimicDesc`], see
//! [`crate::ir::JointMimic`]): multiplier `c1`, offset `ref1 + c0 - c1 ref2`, so that
//! `q1 = c1 q2 + offset` in `qpos` terms. MuJoCo enforces the coupling softly,
//! through its constraint solver; the model holds it exactly, with one coordinate
//! for a leader and its followers. `active` (of the element, else of its `<default>`
//! class's `<equality>`) `"false"` skips a constraint without a warning: MuJoCo
//! starts with it off, so its dynamics are the model's (MuJoCo can switch it on at
//! run time; the model cannot).
//!
//! Refused as MuJoCo refuses them, naming the `<equality>` element and its line, active
//! or not: a `<joint>` without `joint1`, naming no joint of the model or a ball or
//! free joint, with `joint1` and `joint2` the same joint, a `polycoef` that is not up
//! to 5 numbers, an `active` that is neither `true` nor `false`, an unknown `class`.
//!
//! Left out with a warning naming the element, its line and why: a `<joint>` with a
//! nonlinear `polycoef` (naming the nonzero `c2`, `c3`, `c4`; the joints stay
//! independent), one without `joint2` (MuJoCo locks joint1 at `ref + c0`; the joint
//! is left free, and the warning tells how to lock it: remove the joint, and place
//! its body at that position), one whose joint1 already follows a joint (a joint
//! follows one at most) or whose joint2 follows joint1 through the couplings before
//! it (a cycle); `<connect>` and `<weld>` (a closed loop or a fixed pose the tree does
//! not hold), `<tendon>` (no tendons in the model), `<flex>` and `<flexstrain>`.
//!
//! Siblings are numbered in declaration order, as MuJoCo numbers its bodies. An
//! element with `name=""` is unnamed, as in MuJoCo (a body `body_ID`, a joint
//! `joint_ID`, a site no frame).
//!
//! # Includes
//!
//! `<include file="x.xml"/>`, anywhere, is replaced by the children of the included
//! file's document element, which must be `<mujoco>`. As in MuJoCo, `file` is
//! relative to the folder of the top-level file, also in nested includes (at most
//! [`MAX_INCLUDE_DEPTH`] deep), and a file is included at most once. Refused, naming
//! the `<include>` and its line: no `file`, an absolute path or one that leads out of
//! the top-level file's folder (after `..` are resolved, and through links), a file
//! that cannot be read or is larger than [`MAX_FILE_BYTES`], a file included again
//! or including a file that includes it (a cycle), children in the `<include>`, and
//! any `<include>` in text read without its file ([`parse_mjcf`]: load it with
//! [`load_mjcf`]). Nesting is limited across files as in one file.
//!
//! [`ModelErrors`] names one file, so an error or warning about an element of an
//! included file carries the line of the top-level file's `<include>` that brings it
//! in, and its message starts with ``in `FILE` line N`` (and `, included from `FILE`
//! line N` for each include in between); errors whose kind has no message of its own
//! are given as [`ErrorKind::InvalidMjcf`] with that prefix and their text.

use crate::desc::{
    DeclaredJointType, Description, JointDesc, LinkDesc, LoadOptions, MimicDesc, SiblingOrder, DEFAULT_GRAVITY,
};
use crate::error::{Element, ErrorKind, ModelError, ModelErrors};
use crate::ir::{Inertial, JointDynamics, JointKind, Limits, Model, Placement};
use crate::math::{self, Mat3, Vec3};
use crate::mjcf_mesh::{self, MeshInertia, MeshMass, TriMesh};
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
/// Text has no folder: an `<include>` is refused (read the file with [`load_mjcf`]).
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
    build(text, None, options).map_err(|errors| ModelErrors { file: None, errors })
}

/// Reads, parses and checks an MJCF file and the files it `<include>`s (relative to
/// its folder); errors are prefixed with its path (see the module documentation for
/// errors in included files).
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
    build(&text, Some(path), options).map_err(|errors| ModelErrors { file, errors })
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
    let read = read(text, None).map_err(fail)?;
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

fn build(text: &str, path: Option<&Path>, options: LoadOptions) -> Result<Model, Vec<ModelError>> {
    let mut read = read(text, path)?;
    let sources = std::mem::take(&mut read.sources);
    built(read, options)
        .map_err(|errors| relocate(&sources, errors))
        .map(|mut model| {
            model.warnings = relocate(&sources, std::mem::take(&mut model.warnings));
            model
        })
}

fn built(mut read: Read, options: LoadOptions) -> Result<Model, Vec<ModelError>> {
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
    let built = read.desc.build_checked(SiblingOrder::Declaration, options);
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
    /// The files read, the top-level one first, for [`relocate`].
    sources: Vec<Source>,
}

fn read(text: &str, path: Option<&Path>) -> Result<Read, Vec<ModelError>> {
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(vec![robot_error(
            None,
            ErrorKind::TooLarge {
                bytes: text.len() as u64,
            },
        )]);
    }
    let tags = scan_mjcf(text, 0)?;
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
    let mut includes = Includes {
        top: path.map(|p| {
            let dir = p
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            let canonical = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
            (dir.to_path_buf(), canonical)
        }),
        tags: Vec::new(),
        children: Vec::new(),
        sources: vec![Source {
            name: path.map_or_else(|| "the MJCF text".to_string(), |p| p.display().to_string()),
            base: 0,
            lines: crate::xml::line_of(text, text.len()),
            included_at: None,
        }],
        seen: Vec::new(),
        errors: Vec::new(),
    };
    let main = path.and_then(|p| std::fs::canonicalize(p).ok());
    let root = includes.add(tags, 0, &mut main.into_iter().collect());
    let Includes {
        top,
        tags,
        children,
        sources,
        errors: include_errors,
        ..
    } = includes;
    // Each file was scanned within the nesting limit; the model, its includes in
    // place, must be too.
    let mut stack = vec![(root, 1usize)];
    while let Some((k, depth)) = stack.pop() {
        if depth > crate::xml::MAX_DEPTH {
            let e = robot_error(
                Some(tags[k].line),
                ErrorKind::TooDeep {
                    tag: tags[k].name.clone(),
                },
            );
            return Err(relocate(&sources, vec![e]));
        }
        stack.extend(children[k].iter().map(|&c| (c, depth + 1)));
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
        from_geom: FromGeom::Auto,
        group_range: [0, 5],
        mass_rules: MassRules {
            bound_mass: 0.0,
            bound_inertia: 0.0,
            balance: false,
            total: None,
        },
        records: Vec::new(),
        sites: Vec::new(),
        uncounted: Vec::new(),
        folder: top,
        meshdir: None,
        assetdir: None,
        strippath: false,
        fit_aabb: false,
        meshes: HashMap::new(),
        mesh_masses: HashMap::new(),
        joint_refs: HashMap::new(),
        mimics: Vec::new(),
    };
    reader.errors = include_errors;
    reader.read_document(root);
    reader.apply_mass_rules();
    reader.check_site_names();
    let name = tags[root].attr("model").unwrap_or("MuJoCo Model").to_string();
    Ok(Read {
        desc: Description {
            name,
            gravity: reader.gravity,
            links: reader.links,
            joints: reader.joints,
            mimics: reader.mimics,
        },
        root_line: Some(tags[root].line),
        errors: reader.errors,
        warnings: reader.warnings,
        sources,
    })
}

/// Deepest nesting of `<include>`s: the top-level file's includes are at depth 1.
pub const MAX_INCLUDE_DEPTH: usize = 8;

/// Why a path named in the model does not name a file inside the model's folder.
enum PathProblem {
    /// More `..` than folders: out of the folder.
    LeadsOut,
    Absolute,
    Empty,
}

/// `path` normalised (`.` dropped, `..` taking back a folder), if it stays inside
/// the folder it is relative to (checked for links by the caller, on the canonical
/// path).
fn inside_folder(path: &Path) -> Result<std::path::PathBuf, PathProblem> {
    use std::path::Component;
    let mut relative = std::path::PathBuf::new();
    for part in path.components() {
        match part {
            Component::Normal(p) => relative.push(p),
            Component::CurDir => {}
            Component::ParentDir => {
                if !relative.pop() {
                    return Err(PathProblem::LeadsOut);
                }
            }
            Component::RootDir | Component::Prefix(_) => return Err(PathProblem::Absolute),
        }
    }
    if relative.as_os_str().is_empty() {
        return Err(PathProblem::Empty);
    }
    Ok(relative)
}

/// Scans MJCF text, its lines counted from `base` (see [`Source`]).
fn scan_mjcf(text: &str, base: usize) -> Result<Vec<Tag>, Vec<ModelError>> {
    let mut tags = match scan(text) {
        Ok(tags) => tags,
        Err(SyntaxError {
            line,
            too_deep: Some(tag),
            ..
        }) => return Err(vec![robot_error(Some(base + line), ErrorKind::TooDeep { tag })]),
        Err(e) => {
            return Err(vec![robot_error(
                Some(base + e.line),
                ErrorKind::InvalidMjcf(format!("not valid XML: {}", e.message)),
            )])
        }
    };
    for t in &mut tags {
        t.line += base;
        // MuJoCo reads `name=""` as no name.
        t.attrs.retain(|(n, v)| !(n == "name" && v.is_empty()));
    }
    Ok(tags)
}

/// A file of the model. Included files' lines are numbered on from the lines of the
/// files before them (line `l` of a file is `base + l` in the tags), so that every
/// tag, error and warning carries one number; [`relocate`] turns the numbers of
/// included files back into their own.
struct Source {
    /// The top-level file's path, or an included file's path as resolved against
    /// the top-level file's folder.
    name: String,
    base: usize,
    lines: usize,
    /// The source and (numbered-on) line of the `<include>` that brought it in.
    included_at: Option<(usize, usize)>,
}

/// The files of a model, `<include>`s replaced by the children of the `<mujoco>`
/// of the file they name, in one list of tags.
struct Includes {
    /// The top-level file's folder, as written and canonical; `None` for text.
    top: Option<(std::path::PathBuf, std::path::PathBuf)>,
    tags: Vec<Tag>,
    children: Vec<Vec<usize>>,
    sources: Vec<Source>,
    /// Canonical paths of the files included so far, with their source.
    seen: Vec<(std::path::PathBuf, usize)>,
    errors: Vec<ModelError>,
}

impl Includes {
    /// Adds the tags of source `source` and, in place of each `<include>`, the
    /// files it names; returns the index of its document element. `stack` holds the
    /// canonical paths of the files including this one, and this one.
    fn add(&mut self, tags: Vec<Tag>, source: usize, stack: &mut Vec<std::path::PathBuf>) -> usize {
        let offset = self.tags.len();
        let count = tags.len();
        self.children.extend((0..count).map(|_| Vec::new()));
        let mut root = offset;
        for (k, mut t) in tags.into_iter().enumerate() {
            match t.parent {
                Some(p) => {
                    t.parent = Some(p + offset);
                    self.children[p + offset].push(offset + k);
                }
                None => root = offset + k,
            }
            self.tags.push(t);
        }
        for k in offset..offset + count {
            if self.tags[k].name != "include" {
                continue;
            }
            let parent = self.tags[k].parent.unwrap_or(root);
            let spliced = match self.include(k, source, stack) {
                Ok(included_root) => self.children[included_root].clone(),
                Err(e) => {
                    self.errors.push(e);
                    Vec::new()
                }
            };
            let at = self.children[parent].iter().position(|&c| c == k).unwrap_or(0);
            self.children[parent].splice(at..=at, spliced);
        }
        root
    }

    /// Reads the file `<include>` tag `k` (of source `source`) names; the index of
    /// its `<mujoco>`, or why it is refused.
    fn include(&mut self, k: usize, source: usize, stack: &mut Vec<std::path::PathBuf>) -> Result<usize, ModelError> {
        let line = self.tags[k].line;
        let fail = |message: String| robot_error(Some(line), ErrorKind::InvalidMjcf(message));
        let Some(file) = self.tags[k].attr("file").map(str::to_string) else {
            return Err(fail(
                "<include> has no `file`; write <include file=\"NAME.xml\"/> with a path relative to the top-level \
                 model file's folder"
                    .into(),
            ));
        };
        let what = format!("<include file=\"{file}\">");
        let Some((dir, canonical_dir)) = self.top.clone() else {
            return Err(robot_error(
                Some(line),
                ErrorKind::NotSupported(format!(
                    "{what}: MJCF text read without its file has no folder to resolve the include against; \
                     load the model from its file (load_mjcf)"
                )),
            ));
        };
        if !self.children[k].is_empty() {
            return Err(fail(format!("{what} has child elements; an <include> must be empty")));
        }
        // The path, normalised, must stay inside the top-level file's folder.
        let relative = match inside_folder(Path::new(&file)) {
            Ok(relative) => relative,
            Err(PathProblem::LeadsOut) => {
                return Err(fail(format!(
                    "{what} leads out of the top-level model file's folder; an included file must be in that \
                     folder or below it, named by a relative path such as `common/materials.xml`"
                )))
            }
            Err(PathProblem::Absolute) => {
                return Err(fail(format!(
                    "{what} is an absolute path; name the included file by a path relative to the top-level model \
                     file's folder, such as `common/materials.xml`"
                )))
            }
            Err(PathProblem::Empty) => {
                return Err(fail(format!(
                    "{what} names no file; name an XML file such as `common/materials.xml`"
                )))
            }
        };
        let path = dir.join(&relative);
        let canonical =
            std::fs::canonicalize(&path).map_err(|e| fail(format!("{what}: cannot read `{}`: {e}", path.display())))?;
        if !canonical.starts_with(&canonical_dir) {
            return Err(fail(format!(
                "{what} leads (through a link) out of the top-level model file's folder; an included file must be \
                 in that folder or below it"
            )));
        }
        if stack.contains(&canonical) {
            return Err(fail(format!(
                "{what} includes a file that is including it (an include cycle); remove this <include>"
            )));
        }
        if let Some(&(_, earlier)) = self.seen.iter().find(|(p, _)| *p == canonical) {
            let at = self.sources[earlier]
                .included_at
                .map_or(0, |(s, l)| l - self.sources[s].base);
            let by = self.sources[earlier].included_at.map_or(0, |(s, _)| s);
            return Err(fail(format!(
                "{what}: `{}` is already included (line {at} of `{}`); MuJoCo includes a file once: remove one \
                 of the <include>s",
                relative.display(),
                self.sources[by].name
            )));
        }
        if stack.len() > MAX_INCLUDE_DEPTH {
            return Err(fail(format!(
                "{what} is nested {} includes deep, more than the {MAX_INCLUDE_DEPTH} allowed; include the file \
                 from a file nearer the top",
                stack.len()
            )));
        }
        let text = read_file(&path).map_err(|errors| {
            let why = errors.first().map_or_else(String::new, |e| e.kind.to_string());
            fail(format!("{what}: `{}`: {why}", relative.display()))
        })?;
        let base = self.sources.iter().map(|s| s.base + s.lines).max().unwrap_or(0);
        let index = self.sources.len();
        self.sources.push(Source {
            name: relative.display().to_string(),
            base,
            lines: crate::xml::line_of(&text, text.len()),
            included_at: Some((source, line)),
        });
        self.seen.push((canonical.clone(), index));
        let tags = scan_mjcf(&text, base).map_err(|mut e| e.remove(0))?;
        let root = tags
            .iter()
            .find(|t| t.parent.is_none())
            .map_or(("", base + 1), |t| (t.name.as_str(), t.line));
        if root.0 != "mujoco" {
            return Err(robot_error(
                Some(root.1),
                ErrorKind::InvalidMjcf(format!(
                    "the document element of an included file is <{}>, not <mujoco>; an included file holds its \
                     elements in a <mujoco> element",
                    root.0
                )),
            ));
        }
        stack.push(canonical);
        let root = self.add(tags, index, stack);
        stack.pop();
        Ok(root)
    }
}

/// Gives the errors and warnings in included files the line of the top-level
/// file's `<include>` that brings them in, and says in the message which file and
/// line they are about (free-text messages are prefixed; other kinds become
/// [`ErrorKind::InvalidMjcf`] with the prefix and their text).
fn relocate(sources: &[Source], errors: Vec<ModelError>) -> Vec<ModelError> {
    let find = |line: usize| {
        sources
            .iter()
            .position(|s| line > s.base && line <= s.base + s.lines.max(1))
            .unwrap_or(0)
    };
    errors
        .into_iter()
        .map(|mut e| {
            let Some(line) = e.line else { return e };
            let mut s = find(line);
            if s == 0 {
                return e;
            }
            let mut place = format!("in `{}` line {}", sources[s].name, line - sources[s].base);
            let mut top = line;
            while let Some((by, at)) = sources[s].included_at {
                if by != 0 {
                    place.push_str(&format!(
                        ", included from `{}` line {}",
                        sources[by].name,
                        at - sources[by].base
                    ));
                }
                top = at;
                s = by;
            }
            e.line = Some(top);
            e.kind = match e.kind {
                ErrorKind::NotSupported(m) => ErrorKind::NotSupported(format!("{place}: {m}")),
                ErrorKind::Ignored(m) => ErrorKind::Ignored(format!("{place}: {m}")),
                ErrorKind::InvalidMjcf(m) => ErrorKind::InvalidMjcf(format!("{place}: {m}")),
                other => ErrorKind::InvalidMjcf(format!("{place}: {other}")),
            };
            e
        })
        .collect()
}

/// A `<default>` class: its parent class and the attributes it sets, by element
/// (`joint`, `geom`, `site`, `mesh`, `equality`).
struct Class {
    parent: Option<String>,
    attrs: HashMap<String, Vec<(String, String)>>,
}

/// Elements whose attributes `<default>` classes give here.
const CLASS_ELEMENTS: [&str; 5] = ["joint", "geom", "site", "mesh", "equality"];

/// `<compiler inertiafromgeom>`: whether a body's inertial comes from its geoms.
#[derive(Clone, Copy, PartialEq, Eq)]
enum FromGeom {
    /// Never: a body without `<inertial>` has no mass.
    False,
    /// Always, ignoring `<inertial>`.
    True,
    /// For bodies without `<inertial>` (MuJoCo's default).
    Auto,
}

/// What MuJoCo's compiler does to every body's mass properties (`<compiler
/// boundmass boundinertia balanceinertia settotalmass>`).
struct MassRules {
    bound_mass: f64,
    bound_inertia: f64,
    balance: bool,
    /// `settotalmass` when positive.
    total: Option<f64>,
}

/// A body read, for the compiler's mass rules applied once all are read.
struct BodyRecord {
    /// Its link in [`Reader::links`].
    link: usize,
    /// Where the link frame sits in the body frame (the last joint's `pos`).
    shift: Vec3,
    /// Its inertial in the body frame, as written or from its geoms.
    inertial: Option<Inertial>,
    /// The body's `pos` as written (in its parent's frame): where MuJoCo leaves the
    /// inertial frame of a body without mass of its own, so where `boundmass` puts
    /// the mass it gives such a body.
    pos: Vec3,
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

/// ` name="N"` for an element named N, else nothing: for messages.
fn named(t: &Tag) -> String {
    t.attr("name").map_or_else(String::new, |n| format!(" name=\"{n}\""))
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
    from_geom: FromGeom,
    /// `<compiler inertiagrouprange>`: geoms of these groups give the inertia.
    group_range: [i64; 2],
    mass_rules: MassRules,
    records: Vec<BodyRecord>,
    /// Named sites with their lines, to tell a site named as a body.
    sites: Vec<(String, usize)>,
    /// Bodies welded to the world whose geoms' inertia could not be computed:
    /// harmless unless `settotalmass` counts them.
    uncounted: Vec<(String, usize)>,
    /// The top-level file's folder, as written and canonical (`None` for text):
    /// mesh files are read from it or below it.
    folder: Option<(std::path::PathBuf, std::path::PathBuf)>,
    /// `<compiler meshdir>` and `assetdir` (the mesh folder when `meshdir` is not
    /// given), relative to the model's folder.
    meshdir: Option<String>,
    assetdir: Option<String>,
    /// `<compiler strippath>`: mesh files named without their folders.
    strippath: bool,
    /// `<compiler fitaabb>`: a primitive geom naming a mesh is fitted to the mesh's
    /// axis-aligned bounding box (in its principal frame) instead of its box of
    /// equal inertia.
    fit_aabb: bool,
    /// `<asset><mesh>` elements by name (their tags).
    meshes: HashMap<String, usize>,
    /// The mass properties of the meshes computed so far, or why they are refused.
    mesh_masses: HashMap<String, Result<MeshMass, ModelError>>,
    /// Each joint read, by name: its type and its `ref` in the model's units
    /// (radians or metres; 0 for ball and free joints), for `<equality><joint>`.
    joint_refs: HashMap<String, (MjcfJoint, f64)>,
    /// The joints that follow others (`<equality><joint>` couplings).
    mimics: Vec<MimicDesc>,
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
        for c in self.children_named(root, "compiler") {
            self.read_compiler(&tags[c]);
        }
        let mut gravity_on = true;
        for c in self.children_named(root, "option") {
            if let Some(g) = self.numbers(&tags[c], "gravity", 3, &Element::Robot) {
                self.gravity = [g[0], g[1], g[2]];
            }
            // `<flag gravity="disable">`: MuJoCo applies no gravity at all.
            for f in self.children_named(c, "flag") {
                match tags[f].attr("gravity") {
                    Some("disable") => gravity_on = false,
                    Some("enable") | None => {}
                    Some(other) => self.error(
                        Element::Robot,
                        tags[f].line,
                        ErrorKind::InvalidMjcf(format!("<flag gravity=\"{other}\"> is neither `enable` nor `disable`")),
                    ),
                }
            }
        }
        if !gravity_on {
            self.gravity = [0.0; 3];
        }
        self.classes.insert(
            "main".into(),
            Class {
                parent: None,
                attrs: HashMap::new(),
            },
        );
        for d in self.children_named(root, "default") {
            self.read_default(d, None);
        }
        for a in self.children_named(root, "asset") {
            for m in self.children_named(a, "mesh") {
                self.read_mesh_asset(m);
            }
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
                    "body" => self.read_body(c, WORLD, [0.0; 3], "main", false),
                    "joint" | "freejoint" => self.error(
                        Element::Robot,
                        tags[c].line,
                        ErrorKind::InvalidMjcf(format!(
                            "<{}> directly in <worldbody>: the world cannot move; put it in a <body>",
                            tags[c].name
                        )),
                    ),
                    name if TREE_ELEMENTS.contains(&name) => self.refuse_tree_element(c, Element::Robot),
                    "site" => self.read_site(c, WORLD, [0.0; 3], "main"),
                    _ => {}
                }
            }
        }
        // Joint couplings become followers; the other constraints are not in the model.
        for s in self.children_named(root, "equality") {
            for c in self.children[s].clone() {
                self.read_equality(&tags[c]);
            }
        }
        for s in self.children_named(root, "tendon") {
            for c in self.children[s].clone() {
                let t = &tags[c];
                self.warnings.push(ModelError {
                    element: Element::Robot,
                    line: Some(t.line),
                    kind: ErrorKind::Ignored(format!(
                        "<tendon> <{}{}> is left out: a tendon (its length, limits, stiffness, damping and any \
                         constraint or actuator on it) is not in the model, whose dynamics treat the joints as \
                         independent",
                        t.name,
                        named(t)
                    )),
                });
            }
        }
    }

    /// One element of `<equality>`: a linear `<joint>` coupling becomes a follower
    /// ([`MimicDesc`]); what MuJoCo refuses is refused; an inactive constraint is
    /// skipped; every other constraint is left out with a warning that says why.
    fn read_equality(&mut self, t: &'t Tag) {
        let label = format!("<equality> <{}{}>", t.name, named(t));
        let class = self.class_of(t, "class", "main", &Element::Robot);
        let active = match self.class_attr(t, &class, "equality", "active").as_deref() {
            None | Some("true") => true,
            Some("false") => false,
            Some(other) => {
                self.error(
                    Element::Robot,
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "{label}: active=\"{other}\" is neither `true` nor `false` (MuJoCo refuses it too)"
                    )),
                );
                return;
            }
        };
        let why = match t.name.as_str() {
            "joint" => return self.read_joint_coupling(t, &label, active),
            "connect" => {
                "a connect constraint (a ball joint between two bodies outside the tree: a closed kinematic loop) \
                 is not in the model, whose bodies form a tree; its dynamics are those of the open tree"
            }
            "weld" => {
                "a weld constraint (two bodies held in a fixed relative pose, or a body held to the world: a closed \
                 loop unless the bodies are parent and child) is not in the model, whose bodies form a tree; to \
                 weld a body to its parent, give it no joint"
            }
            "tendon" => "a tendon coupling is not in the model, which has no tendons; its joints stay independent",
            "flex" | "flexstrain" => "a flex constraint is not in the model, which has rigid bodies only",
            _ => "a constraint of this kind is not in the model, whose joints are independent",
        };
        if active {
            self.warnings.push(ModelError {
                element: Element::Robot,
                line: Some(t.line),
                kind: ErrorKind::Ignored(format!("{label} is left out: {why}")),
            });
        }
    }

    /// `<equality><joint joint1 joint2 polycoef>`: MuJoCo holds `q1 - ref1 = c0 + c1
    /// (q2 - ref2) + c2 (q2 - ref2)² + c3 (…)³ + c4 (…)⁴` (`ref` as `qpos0`, in radians
    /// or metres; `polycoef` as written, never converted from degrees). With `joint2`
    /// and `c2 = c3 = c4 = 0`, joint1 follows joint2: `q1 = c1 q2 + ref1 + c0 - c1 ref2`.
    fn read_joint_coupling(&mut self, t: &'t Tag, label: &str, active: bool) {
        let refuse = |this: &mut Self, why: String| {
            this.error(
                Element::Robot,
                t.line,
                ErrorKind::InvalidMjcf(format!("{label}: {why} (MuJoCo refuses it too)")),
            )
        };
        // MuJoCo keeps the default `0 1 0 0 0` past the numbers written.
        let mut c = [0.0, 1.0, 0.0, 0.0, 0.0];
        if let Some(v) = t.attr("polycoef") {
            let words: Vec<&str> = v.split_whitespace().collect();
            let numbers: Vec<f64> = words.iter().filter_map(|w| w.parse::<f64>().ok()).collect();
            if words.len() > 5 || numbers.len() != words.len() || numbers.iter().any(|x| !x.is_finite()) {
                return refuse(
                    self,
                    format!(
                        "polycoef=\"{v}\" is not up to 5 finite numbers; give `c0 c1 c2 c3 c4` (default `0 1 0 0 0`, \
                         the numbers not written keep it)"
                    ),
                );
            }
            c[..numbers.len()].copy_from_slice(&numbers);
        }
        let Some(joint1) = t.attr("joint1") else {
            return refuse(self, "no `joint1`; name the joint that the coupling moves".into());
        };
        let scalar = |this: &mut Self, attr: &str, name: &str| -> Option<f64> {
            match this.joint_refs.get(name) {
                Some(&(MjcfJoint::Hinge | MjcfJoint::Slide, reference)) => Some(reference),
                Some(&(kind, _)) => {
                    let kind = if kind == MjcfJoint::Ball { "ball" } else { "free" };
                    refuse(
                        this,
                        format!("{attr}=\"{name}\" is a {kind} joint; only hinge and slide joints can be coupled"),
                    );
                    None
                }
                None => {
                    refuse(
                        this,
                        format!("{attr}=\"{name}\" names no joint of this model; name a hinge or slide joint"),
                    );
                    None
                }
            }
        };
        let Some(ref1) = scalar(self, "joint1", joint1) else {
            return;
        };
        let joint2 = t.attr("joint2");
        let ref2 = match joint2 {
            Some(j) if j == joint1 => {
                return refuse(
                    self,
                    format!("joint1 and joint2 both name `{j}`; a joint cannot follow itself"),
                )
            }
            Some(j) => match scalar(self, "joint2", j) {
                Some(r) => Some(r),
                None => return,
            },
            None => None,
        };
        if !active {
            // MuJoCo starts with it off: the joints are independent, as in the model.
            return;
        }
        let warn = |this: &mut Self, why: String| {
            this.warnings.push(ModelError {
                element: Element::Robot,
                line: Some(t.line),
                kind: ErrorKind::Ignored(format!("{label} is left out: {why}")),
            })
        };
        let (Some(joint2), Some(ref2)) = (joint2, ref2) else {
            let held = ref1 + c[0];
            let unit = match self.joint_refs.get(joint1) {
                Some((MjcfJoint::Slide, _)) => "m",
                _ => "rad",
            };
            let how = if c[0] == 0.0 {
                "remove the <joint> from its body, which then stays where the file places it (at q = ref)".to_string()
            } else {
                format!(
                    "remove the <joint> from its body and place the body as it is at q = {held} {unit} (the file \
                     places it at q = ref = {ref1} {unit})"
                )
            };
            return warn(
                self,
                format!(
                    "without joint2 it locks joint `{joint1}` at q = ref + c0 = {held} {unit}, and the model has no locked \
                     joints: `{joint1}` is left free; to lock it, {how}"
                ),
            );
        };
        let nonlinear: Vec<String> = (2..5)
            .filter(|&k| c[k] != 0.0)
            .map(|k| format!("c{k} = {}", c[k]))
            .collect();
        if !nonlinear.is_empty() {
            return warn(
                self,
                format!(
                    "its polycoef has {}, a nonlinear coupling, and a follower moves linearly with its leader; \
                     joint `{joint1}` is left independent of `{joint2}` (only c0 and c1 may be nonzero for it to \
                     follow: q1 = c1 q2 + offset)",
                    nonlinear.join(", ")
                ),
            );
        }
        if let Some(m) = self.mimics.iter().find(|m| m.joint == joint1) {
            let (leader, line) = (m.leader.clone(), m.line.unwrap_or(0));
            return warn(
                self,
                format!(
                    "joint `{joint1}` already follows `{leader}` (the coupling at line {line}), and a joint \
                     follows one joint at most; couple `{leader}` and `{joint2}` instead if they move together"
                ),
            );
        }
        // joint2's leaders, followed in turn: joint1 among them closes a cycle.
        let mut leader = joint2;
        let mut steps = 0;
        while let Some(m) = self.mimics.iter().find(|m| m.joint == leader) {
            leader = m.leader.as_str();
            steps += 1;
            if leader == joint1 || steps > self.mimics.len() {
                return warn(
                    self,
                    format!(
                        "joint `{joint2}` already follows `{joint1}` through the couplings above, so this one \
                         closes a cycle of couplings; the model keeps the couplings above and leaves this one out \
                         (it is redundant if it agrees with them)"
                    ),
                );
            }
        }
        self.mimics.push(MimicDesc {
            joint: joint1.to_string(),
            leader: joint2.to_string(),
            multiplier: c[1],
            offset: ref1 + c[0] - c[1] * ref2,
            line: Some(t.line),
        });
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
        let mut balance = self.mass_rules.balance;
        for (attr, flag) in [
            ("autolimits", &mut self.autolimits),
            ("alignfree", &mut self.alignfree),
            ("balanceinertia", &mut balance),
            ("strippath", &mut self.strippath),
            ("fitaabb", &mut self.fit_aabb),
        ] {
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
        self.mass_rules.balance = balance;
        if let Some(d) = t.attr("meshdir") {
            self.meshdir = Some(d.to_string());
        }
        if let Some(d) = t.attr("assetdir") {
            self.assetdir = Some(d.to_string());
        }
        if let Some(v) = t.attr("exactmeshinertia") {
            self.warnings.push(ModelError {
                element: Element::Robot,
                line: Some(t.line),
                kind: ErrorKind::Ignored(format!(
                    "<compiler exactmeshinertia=\"{v}\"> is not read (MuJoCo 3 deprecated it and MuJoCo 4 refuses \
                     it); each <mesh>'s `inertia` (convex, exact, legacy or shell; convex by default) says how its \
                     inertia is computed"
                )),
            });
        }
        match t.attr("inertiafromgeom") {
            None => {}
            Some("true") => self.from_geom = FromGeom::True,
            Some("false") => self.from_geom = FromGeom::False,
            Some("auto") => self.from_geom = FromGeom::Auto,
            Some(other) => self.error(
                Element::Robot,
                t.line,
                ErrorKind::InvalidMjcf(format!(
                    "<compiler inertiafromgeom=\"{other}\"> is not `true`, `false` or `auto`"
                )),
            ),
        }
        if let Some(v) = t.attr("inertiagrouprange") {
            let words: Vec<Option<i64>> = v.split_whitespace().map(|w| w.parse().ok()).collect();
            match words[..] {
                [Some(lo), Some(hi)] => self.group_range = [lo, hi],
                _ => self.error(
                    Element::Robot,
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "<compiler inertiagrouprange=\"{v}\"> is not two integers (the first and last geom group \
                         whose geoms give the inertia, such as `0 5`)"
                    )),
                ),
            }
        }
        for attr in ["boundmass", "boundinertia", "settotalmass"] {
            let Some(x) = self.numbers(t, attr, 1, &Element::Robot).map(|v| v[0]) else {
                continue;
            };
            if !x.is_finite() {
                self.error(
                    Element::Robot,
                    t.line,
                    ErrorKind::InvalidMjcf(format!("<compiler {attr}=\"{x}\"> is not a finite number")),
                );
                continue;
            }
            match attr {
                "boundmass" => self.mass_rules.bound_mass = x,
                "boundinertia" => self.mass_rules.bound_inertia = x,
                _ => self.mass_rules.total = (x > 0.0).then_some(x),
            }
        }
        if let Some(c) = t.attr("coordinate").filter(|c| *c != "local") {
            self.error(
                Element::Robot,
                t.line,
                ErrorKind::NotSupported(format!(
                    "<compiler coordinate=\"{c}\"> is not supported (MuJoCo itself only reads `local` now); write \
                     body, joint and inertial positions in their parent's frame"
                )),
            );
        }
        // Attributes known not to change the dynamics of what is read here.
        const HARMLESS: [&str; 6] = [
            "texturedir",
            "discardvisual",
            "usethread",
            "fusestatic",
            "saveinertial",
            "coordinate",
        ];
        const READ: [&str; 15] = [
            "strippath",
            "fitaabb",
            "meshdir",
            "assetdir",
            "exactmeshinertia",
            "angle",
            "eulerseq",
            "autolimits",
            "alignfree",
            "balanceinertia",
            "inertiafromgeom",
            "inertiagrouprange",
            "boundmass",
            "boundinertia",
            "settotalmass",
        ];
        for (attr, value) in &t.attrs {
            if !HARMLESS.contains(&attr.as_str()) && !READ.contains(&attr.as_str()) {
                self.warnings.push(ModelError {
                    element: Element::Robot,
                    line: Some(t.line),
                    kind: ErrorKind::Ignored(format!(
                        "<compiler {attr}=\"{value}\"> is not read; if it changes the masses, inertias or joints, \
                         the model differs from MuJoCo's"
                    )),
                });
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
        let mut attrs: HashMap<String, Vec<(String, String)>> = HashMap::new();
        for element in CLASS_ELEMENTS {
            let set: Vec<(String, String)> = self
                .children_named(k, element)
                .iter()
                .flat_map(|&j| self.tags[j].attrs.clone())
                .collect();
            attrs.insert(element.to_string(), set);
        }
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
            attrs: HashMap::new(),
        });
        for (element, set) in attrs {
            entry.attrs.entry(element).or_default().extend(set);
        }
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
        self.class_attr(t, class, "joint", name)
    }

    /// An attribute of `t` (a `joint`, `geom` or `site` element): its own, else its
    /// class's, else an ancestor class's.
    fn class_attr(&self, t: &Tag, class: &str, element: &str, name: &str) -> Option<String> {
        if let Some(v) = t.attr(name) {
            return Some(v.to_string());
        }
        let mut c = Some(class);
        while let Some(name_c) = c {
            let class = self.classes.get(name_c)?;
            let set = class.attrs.get(element).map_or(&[][..], Vec::as_slice);
            if let Some((_, v)) = set.iter().rev().find(|(n, _)| n == name) {
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

    /// A `<body>` with its subtree. `shift` is the parent's last joint `pos`: the
    /// parent link frame sits there in the parent body frame; `moving` whether a
    /// joint moves the parent.
    fn read_body(&mut self, k: usize, parent: &str, shift: Vec3, childclass: &str, moving_parent: bool) {
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

        // The joints, in order: each after the first hangs from a massless link at
        // the previous joint's `pos`, the body's own link on the last.
        let mut joint_tags = Vec::new();
        for c in self.children[k].clone() {
            match tags[c].name.as_str() {
                "joint" | "freejoint" => joint_tags.push(c),
                name if TREE_ELEMENTS.contains(&name) => self.refuse_tree_element(c, el.clone()),
                _ => {}
            }
        }
        let childless = self.children_named(k, "body").is_empty();
        let mut link_parent = parent.to_string();
        let mut link_placement = placement;
        // The `pos` of the last joint read: where the current link frame sits in the body frame.
        let mut joint_pos = [0.0; 3];
        let mut moving = Vec::new();
        for (n, &c) in joint_tags.iter().enumerate() {
            let jt = &tags[c];
            let jid = self.joint_ids;
            self.joint_ids += 1;
            let jname = jt.attr("name").map_or_else(|| format!("joint_{jid}"), str::to_string);
            let jel = Element::Joint(jname.clone());
            let class = self.class_of(jt, "class", &childclass, &jel);
            let free = jt.name == "freejoint" || self.joint_attr(jt, &class, "type").as_deref() == Some("free");
            if free && joint_tags.len() > 1 {
                self.error(
                    jel,
                    jt.line,
                    ErrorKind::NotSupported(format!(
                        "body `{name}` has a free joint and other joints; a free joint must be the only joint of \
                         its body (MuJoCo refuses it too): move the other joints into a child body"
                    )),
                );
                continue;
            }
            let last = n + 1 == joint_tags.len();
            let child = if last {
                name.clone()
            } else {
                format!("{name} ({jname})")
            };
            let owner = Owner {
                parent: &link_parent,
                body: &child,
                placement: &link_placement,
                childless,
            };
            let read = if jt.name == "freejoint" {
                // MuJoCo's shorthand for a free joint without damping, friction,
                // armature or stiffness; it takes no class.
                self.free_joint(jt, jname, &owner, JointDynamics::default())
            } else {
                self.read_joint(jt, &class, jname, &owner)
            };
            let Some((desc, p)) = read else {
                continue;
            };
            if !last {
                self.links.push(LinkDesc {
                    name: child.clone(),
                    inertial: None,
                    line: Some(jt.line),
                });
            }
            moving.push(desc);
            link_parent = child;
            // The next joint's frame, at its own pos, from this link's (at `p`).
            link_placement = Placement {
                rotation: math::IDENTITY,
                translation: math::scale(-1.0, &p),
            };
            joint_pos = p;
        }

        // The inertial, in the body frame: as written, or from the geoms.
        let inertials = self.children_named(k, "inertial");
        if let Some(&extra) = inertials.get(1) {
            self.error(
                el.clone(),
                tags[extra].line,
                ErrorKind::InvalidMjcf(format!("body `{name}` has more than one <inertial>")),
            );
        }
        let from_geom = match self.from_geom {
            FromGeom::True => true,
            FromGeom::False => false,
            FromGeom::Auto => inertials.is_empty(),
        };
        let moves = moving_parent || !moving.is_empty();
        let inertial = if from_geom && !moves {
            // Welded to the world: its inertia does not enter the dynamics, so geoms
            // that cannot give one (meshes) are no error; only `settotalmass` counts it.
            let before = self.errors.len();
            let inertial = self.geom_inertial(k, &el, &childclass);
            if self.errors.len() > before {
                self.errors.truncate(before);
                self.uncounted.push((name.clone(), t.line));
            }
            inertial
        } else if from_geom {
            self.geom_inertial(k, &el, &childclass)
        } else {
            inertials.first().and_then(|&i| self.read_inertial(&tags[i], &el))
        };

        self.records.push(BodyRecord {
            link: self.links.len(),
            shift: joint_pos,
            inertial,
            pos,
        });
        self.links.push(LinkDesc {
            name: name.clone(),
            inertial: None,
            line: Some(t.line),
        });
        if moving.is_empty() {
            self.joints.push(JointDesc {
                name: format!("{name} (fixed)"),
                kind: DeclaredJointType::Fixed,
                parent: parent.to_string(),
                child: name.clone(),
                origin: placement,
                axis: [0.0, 0.0, 1.0],
                limits: None,
                dynamics: JointDynamics::default(),
                line: Some(t.line),
            });
        }
        self.joints.extend(moving);
        for c in self.children_named(k, "site") {
            self.read_site(c, &name, joint_pos, &childclass);
        }
        for c in self.children_named(k, "body") {
            self.read_body(c, &name, joint_pos, &childclass, moves);
        }
    }

    /// A `<site>`: a frame of the link `link`, whose frame sits at `shift` in the
    /// body frame; an unnamed site is skipped.
    fn read_site(&mut self, k: usize, link: &str, shift: Vec3, childclass: &str) {
        let t = &self.tags[k];
        let Some(name) = t.attr("name") else {
            return;
        };
        let el = Element::Link(name.to_string());
        let class = self.class_of(t, "class", childclass, &el);
        let (pos, rotation) = self.geom_frame(t, &class, "site", &el);
        self.sites.push((name.to_string(), t.line));
        self.links.push(LinkDesc {
            name: name.to_string(),
            inertial: None,
            line: Some(t.line),
        });
        self.joints.push(JointDesc {
            name: format!("{name} (site)"),
            kind: DeclaredJointType::Fixed,
            parent: link.to_string(),
            child: name.to_string(),
            origin: Placement {
                rotation,
                translation: math::sub(&pos, &shift),
            },
            axis: [0.0, 0.0, 1.0],
            limits: None,
            dynamics: JointDynamics::default(),
            line: Some(t.line),
        });
    }

    /// A site's or geom's frame in its body frame: `pos` and orientation, or the
    /// middle of `fromto` with `z` along it (MuJoCo's rule).
    fn geom_frame(&mut self, t: &Tag, class: &str, element: &str, el: &Element) -> (Vec3, Mat3) {
        if let Some(v) = self.class_attr(t, class, element, "fromto") {
            if let Some(f) = self.parse_numbers(t, "fromto", &v, 6, el) {
                let (a, b) = ([f[0], f[1], f[2]], [f[3], f[4], f[5]]);
                let d = math::sub(&b, &a);
                let n = math::norm(&d);
                if n < 1e-12 || !n.is_finite() {
                    self.error(
                        el.clone(),
                        t.line,
                        ErrorKind::InvalidMjcf(format!("<{} fromto=\"{v}\"> has its two ends at one point", t.name)),
                    );
                    return ([0.0; 3], math::IDENTITY);
                }
                return (math::scale(0.5, &math::add(&a, &b)), zaxis(&math::scale(1.0 / n, &d)));
            }
            return ([0.0; 3], math::IDENTITY);
        }
        let pos = match self.class_attr(t, class, element, "pos") {
            Some(v) => self
                .parse_numbers(t, "pos", &v, 3, el)
                .map_or([0.0; 3], |v| [v[0], v[1], v[2]]),
            None => [0.0; 3],
        };
        (pos, self.orientation(t, el))
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
        self.joint_refs.entry(name.clone()).or_insert((kind, 0.0));
        let scalar = |this: &mut Self, a: &str| number(this, a, 1).map_or(0.0, |v| v[0]);
        let dynamics = JointDynamics {
            armature: scalar(self, "armature"),
            damping: scalar(self, "damping"),
            friction: scalar(self, "frictionloss"),
        };
        if !(0.0..=crate::desc::MAX_MAGNITUDE).contains(&dynamics.armature) {
            self.error(
                el.clone(),
                t.line,
                ErrorKind::InvalidMjcf(format!(
                    "armature = {} is not a rotor inertia; give a value >= 0 (and at most 1e9 in SI units)",
                    dynamics.armature
                )),
            );
        } else if dynamics.armature != 0.0 && kind == MjcfJoint::Free {
            self.warnings.push(ModelError {
                element: el.clone(),
                line: Some(t.line),
                kind: ErrorKind::Ignored(format!(
                    "armature = {} on a free joint is kept as the rotor inertia Ia of its 6 coordinates: the mass \
                     matrix is MuJoCo's, but MuJoCo's armature acts on the linear acceleration in world axes and \
                     dyngen's on the one in body axes, so the bias forces differ by Ia (w x v) on the linear part",
                    dynamics.armature
                )),
            });
        }
        let stiffness = scalar(self, "stiffness");
        if stiffness != 0.0 {
            let springref = scalar(self, "springref");
            self.warnings.push(ModelError {
                element: el.clone(),
                line: Some(t.line),
                kind: ErrorKind::Ignored(format!(
                    "stiffness = {stiffness} (springref {springref}) is left out: the model has no joint springs \
                     (the dynamics are the rigid body's, rotor inertia and friction)"
                )),
            });
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
        let desc = |kind: JointKind, axis: Vec3, limits: Option<Limits>, origin: Placement| JointDesc {
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
            return Some((desc(JointKind::Spherical, [0.0; 3], None, origin), pos));
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
        // MuJoCo's body placement is at q = ref (`qpos0`): the joint's zero is that
        // placement moved back by `ref` about or along the axis.
        let reference = scalar(self, "ref");
        let model_ref = if slide { reference } else { self.angle(reference) };
        if let Some(entry) = self.joint_refs.get_mut(&name) {
            if entry.0 == kind {
                entry.1 = model_ref;
            }
        }
        let n = math::norm(&axis);
        let origin = if reference != 0.0 && n > 0.0 && n.is_finite() {
            let unit = math::scale(1.0 / n, &axis);
            if slide {
                Placement {
                    rotation: origin.rotation,
                    translation: owner
                        .placement
                        .transform_point(&math::sub(&pos, &math::scale(reference, &unit))),
                }
            } else {
                Placement {
                    rotation: math::mat_mul(&origin.rotation, &axis_angle(&unit, -self.angle(reference))),
                    translation: origin.translation,
                }
            }
        } else {
            origin
        };
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
        Some((desc(kind, axis, limits, origin), pos))
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
        self.joint_refs.entry(name.clone()).or_insert((MjcfJoint::Free, 0.0));
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

    /// An `<inertial>` in the body frame.
    fn read_inertial(&mut self, t: &Tag, el: &Element) -> Option<Inertial> {
        let pos = self.vec3(t, "pos", el).unwrap_or([0.0; 3]);
        const ORIENTATIONS: [&str; 5] = ["quat", "euler", "axisangle", "xyaxes", "zaxis"];
        if t.attr("fullinertia").is_some() {
            if let Some(o) = ORIENTATIONS.iter().find(|o| t.attr(o).is_some()) {
                // MuJoCo: "fullinertia and inertial orientation cannot both be specified".
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "<inertial> gives both `fullinertia` and an orientation (`{o}`), which MuJoCo refuses: \
                         give `fullinertia` in the body frame without an orientation, or `diaginertia` with `{o}`"
                    )),
                );
                return None;
            }
        }
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
        Some(symmetric(local.transformed(&Placement {
            rotation,
            translation: pos,
        })))
    }

    /// A body's inertial from its geoms, in the body frame, as MuJoCo's compiler
    /// makes it: each geom of a group in `inertiagrouprange` a solid of density
    /// `density` (1000) or of mass `mass`, combined about the common centre of mass.
    /// `None` when no geom has mass.
    fn geom_inertial(&mut self, k: usize, el: &Element, childclass: &str) -> Option<Inertial> {
        let mut total: Option<Inertial> = None;
        for g in self.children_named(k, "geom") {
            let t = &self.tags[g];
            let class = self.class_of(t, "class", childclass, el);
            let attr = |this: &Self, a: &str| this.class_attr(t, &class, "geom", a);
            let scalar = |this: &mut Self, a: &str| -> Option<f64> {
                let v = attr(this, a)?;
                this.parse_numbers(t, a, &v, 1, el).map(|v| v[0])
            };
            let group = match attr(self, "group") {
                Some(v) => match v.trim().parse::<i64>() {
                    Ok(g) => g,
                    Err(_) => {
                        self.error(
                            el.clone(),
                            t.line,
                            ErrorKind::InvalidMjcf(format!("<geom group=\"{v}\"> is not an integer")),
                        );
                        continue;
                    }
                },
                None => 0,
            };
            if group < self.group_range[0] || group > self.group_range[1] {
                continue;
            }
            let mass = scalar(self, "mass");
            let density = scalar(self, "density").unwrap_or(1000.0);
            if mass == Some(0.0) || (mass.is_none() && density == 0.0) {
                continue;
            }
            let kind = attr(self, "type").unwrap_or_else(|| "sphere".into());
            let geom = t
                .attr("name")
                .map_or_else(|| format!("<geom type=\"{kind}\">"), |n| format!("geom `{n}`"));
            if kind == "mesh" && attr(self, "shellinertia").as_deref() == Some("true") {
                // MuJoCo: "for mesh geoms, inertia should be specified in the mesh asset".
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "{geom} asks for shellinertia=\"true\", which MuJoCo refuses on a mesh geom; give the \
                         <mesh> inertia=\"shell\" instead"
                    )),
                );
                continue;
            }
            // A primitive naming a mesh is fitted to it (its size and frame from the mesh's).
            let fitted = kind != "mesh" && kind != "sdf" && attr(self, "mesh").is_some();
            if fitted && !matches!(kind.as_str(), "box" | "sphere" | "capsule" | "cylinder" | "ellipsoid") {
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "{geom} of type `{kind}` names a mesh, but MuJoCo fits only a box, sphere, capsule, \
                         cylinder or ellipsoid to a mesh (and refuses the model otherwise): give it one of those \
                         types, or type=\"mesh\", or no mesh"
                    )),
                );
                continue;
            }
            if attr(self, "shellinertia").as_deref() == Some("true") {
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::NotSupported(format!(
                        "{geom} asks for shellinertia=\"true\", which is not supported yet; give the body an \
                         <inertial>"
                    )),
                );
                continue;
            }
            let fromto = attr(self, "fromto").is_some();
            let sizes = match attr(self, "size") {
                Some(v) => {
                    let words: Vec<Option<f64>> = v.split_whitespace().map(|w| w.parse().ok()).collect();
                    if words.is_empty() || words.len() > 3 || words.iter().any(Option::is_none) {
                        self.error(
                            el.clone(),
                            t.line,
                            ErrorKind::BadNumber {
                                attribute: "geom size".into(),
                                value: v.clone(),
                                expected: 3,
                            },
                        );
                        continue;
                    }
                    let mut s = [0.0; 3];
                    for (x, w) in s.iter_mut().zip(&words) {
                        *x = w.unwrap_or(0.0);
                    }
                    s
                }
                None => [0.0; 3],
            };
            let (mut pos, mut rotation) = self.geom_frame(t, &class, "geom", el);
            if fromto && !matches!(kind.as_str(), "capsule" | "cylinder" | "box" | "ellipsoid") {
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "{geom} has a `fromto`, which only a capsule, cylinder, box or ellipsoid may have"
                    )),
                );
                continue;
            }
            let mut sizes = sizes;
            if fitted {
                if fromto {
                    self.error(
                        el.clone(),
                        t.line,
                        ErrorKind::InvalidMjcf(format!(
                            "{geom} names a mesh and has a `fromto`, which MuJoCo refuses (\"fromto cannot be used \
                             with mesh geom\"): place it with `pos` and an orientation"
                        )),
                    );
                    continue;
                }
                let fitscale = match attr(self, "fitscale") {
                    None => 1.0,
                    Some(v) => match v.trim().parse::<f64>() {
                        Ok(x) if x.is_finite() && x > 0.0 => x,
                        _ => {
                            self.error(
                                el.clone(),
                                t.line,
                                ErrorKind::InvalidMjcf(format!(
                                    "{geom} has fitscale=\"{v}\", which is not a positive number (it scales the \
                                     size fitted to the mesh, and MuJoCo refuses a size that is not positive)"
                                )),
                            );
                            continue;
                        }
                    },
                };
                let Some((s, placed)) = self.fitted_geom(t, &class, el, &geom, &kind, fitscale, (pos, rotation)) else {
                    continue;
                };
                sizes = s;
                (pos, rotation) = placed;
            }
            if kind == "mesh" {
                if let Some(part) = self.mesh_geom(t, &class, el, &geom, mass, density, (pos, rotation)) {
                    total = Some(match total {
                        Some(prev) => prev.combined(&part),
                        None => part,
                    });
                }
                continue;
            }
            // The half length along z given by fromto.
            let half = if fromto {
                let f = attr(self, "fromto").unwrap_or_default();
                let f: Vec<f64> = f.split_whitespace().filter_map(|w| w.parse().ok()).collect();
                if f.len() == 6 {
                    0.5 * math::norm(&[f[3] - f[0], f[4] - f[1], f[5] - f[2]])
                } else {
                    0.0
                }
            } else {
                0.0
            };
            use std::f64::consts::PI;
            // Volume and the moments of inertia per unit mass about the geom's axes.
            let (needed, volume, unit) = match kind.as_str() {
                "sphere" => {
                    let r = sizes[0];
                    (vec![r], 4.0 / 3.0 * PI * r.powi(3), [0.4 * r * r; 3])
                }
                "capsule" | "cylinder" => {
                    let r = sizes[0];
                    let hl = if fromto { half } else { sizes[1] };
                    let h = 2.0 * hl;
                    let vc = PI * r * r * h;
                    if kind == "cylinder" {
                        let ixx = (3.0 * r * r + h * h) / 12.0;
                        (vec![r, hl], vc, [ixx, ixx, 0.5 * r * r])
                    } else {
                        let vs = 4.0 / 3.0 * PI * r.powi(3);
                        let v = vc + vs;
                        let ixx = (vc * (r * r / 4.0 + h * h / 12.0)
                            + vs * (0.4 * r * r + h * h / 4.0 + 3.0 * h * r / 8.0))
                            / v;
                        let izz = (vc * 0.5 * r * r + vs * 0.4 * r * r) / v;
                        (vec![r, hl], v, [ixx, ixx, izz])
                    }
                }
                "box" | "ellipsoid" => {
                    // With fromto, MuJoCo takes size[0] for both x and y.
                    let s = if fromto { [sizes[0], sizes[0], half] } else { sizes };
                    let [a, b, c] = s.map(|x| x * x);
                    if kind == "box" {
                        (
                            s.to_vec(),
                            8.0 * s[0] * s[1] * s[2],
                            [(b + c) / 3.0, (a + c) / 3.0, (a + b) / 3.0],
                        )
                    } else {
                        let v = 4.0 / 3.0 * PI * s[0] * s[1] * s[2];
                        (s.to_vec(), v, [(b + c) / 5.0, (a + c) / 5.0, (a + b) / 5.0])
                    }
                }
                other => {
                    let why = match other {
                        "sdf" => "the inertia of a signed distance field is not computed here",
                        "plane" | "hfield" => "it has no volume",
                        _ => "it is not an MJCF geom type",
                    };
                    self.error(
                        el.clone(),
                        t.line,
                        ErrorKind::NotSupported(format!(
                            "{geom} of type `{other}` would give the body its inertia (<compiler \
                             inertiafromgeom>), but {why}; give the body an <inertial> (or the geom mass=\"0\", or \
                             a group outside inertiagrouprange)"
                        )),
                    );
                    continue;
                }
            };
            if fitted && needed.iter().any(|&x| x.is_nan() || x <= 0.0) {
                let mesh = attr(self, "mesh").unwrap_or_default();
                let how = if self.fit_aabb {
                    "its bounding box (<compiler fitaabb=\"true\">)"
                } else {
                    "its box of equal inertia"
                };
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "{geom} fitted to mesh `{mesh}` from {how} gets size=\"{}\", which MuJoCo refuses (a \
                         {kind}'s sizes must be positive); give it another type, or type=\"mesh\"",
                        needed.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ")
                    )),
                );
                continue;
            }
            if needed.iter().any(|&x| x.is_nan() || x <= 0.0) {
                self.error(
                    el.clone(),
                    t.line,
                    ErrorKind::InvalidMjcf(format!(
                        "{geom} needs a positive size for its inertia (size=\"{}\"{}); give its `size`",
                        sizes.map(|x| x.to_string()).join(" "),
                        if fromto { " with fromto" } else { "" }
                    )),
                );
                continue;
            }
            let m = mass.unwrap_or(density * volume);
            let part = Inertial {
                mass: m,
                com: [0.0; 3],
                inertia: [
                    [m * unit[0], 0.0, 0.0],
                    [0.0, m * unit[1], 0.0],
                    [0.0, 0.0, m * unit[2]],
                ],
            }
            .transformed(&Placement {
                rotation,
                translation: pos,
            });
            total = Some(match total {
                Some(prev) => prev.combined(&part),
                None => part,
            });
        }
        total.map(symmetric)
    }

    /// A mesh geom's inertial in the body frame: its mesh's volume (or area) and
    /// inertia for its mass or density, placed by the geom's `pos` and orientation.
    /// `None`, with the error, when the mesh cannot give it.
    #[allow(clippy::too_many_arguments)]
    fn mesh_geom(
        &mut self,
        t: &Tag,
        class: &str,
        el: &Element,
        geom: &str,
        mass: Option<f64>,
        density: f64,
        (pos, rotation): (Vec3, Mat3),
    ) -> Option<Inertial> {
        let (_, props) = self.geom_mesh(t, class, el, geom, "mesh")?;
        let m = mass.unwrap_or(density * props.measure);
        let local = Inertial {
            mass: m,
            com: props.com,
            inertia: from_principal(props.moments.map(|x| m * x), &props.axes),
        };
        Some(local.transformed(&Placement {
            rotation,
            translation: pos,
        }))
    }

    /// The name and mass properties of the mesh a geom of type `kind` names, or
    /// `None` with the error (on the geom's line when it names no mesh or an
    /// unknown one, on the `<mesh>`'s when the mesh cannot be had).
    fn geom_mesh(&mut self, t: &Tag, class: &str, el: &Element, geom: &str, kind: &str) -> Option<(String, MeshMass)> {
        let Some(name) = self.class_attr(t, class, "geom", "mesh") else {
            self.error(
                el.clone(),
                t.line,
                ErrorKind::InvalidMjcf(format!(
                    "{geom} of type `{kind}` names no mesh; give it mesh=\"NAME\" of a <mesh> in <asset>"
                )),
            );
            return None;
        };
        if !self.meshes.contains_key(&name) {
            self.error(
                el.clone(),
                t.line,
                ErrorKind::InvalidMjcf(format!(
                    "{geom} names mesh `{name}`, which no <mesh> in <asset> defines (a mesh without a name is \
                     named by its file, without folder and extension)"
                )),
            );
            return None;
        }
        let props = match self.mesh_masses.get(&name) {
            Some(r) => r.clone(),
            None => {
                let r = self.mesh_mass(&name);
                self.mesh_masses.insert(name.clone(), r.clone());
                r
            }
        };
        match props {
            Ok(p) => Some((name, p)),
            Err(e) => {
                // Once, however many geoms use the mesh.
                if !self.errors.contains(&e) {
                    self.errors.push(e);
                }
                None
            }
        }
    }

    /// A primitive geom naming a mesh, fitted to it as MuJoCo 4's compiler fits it
    /// (`mjCMesh::FitGeom`, called from `mjCGeom::Compile`), from half sides `h` in
    /// the mesh's principal frame: its box of equal inertia, or with `<compiler
    /// fitaabb="true">` its vertices' bounding box. By default a box or ellipsoid
    /// takes `h`, a sphere their mean, a cylinder `(h0 + h1) / 2` and `h2`, a capsule
    /// that radius `r` and `max(0, h2 - r / 2)`; with `fitaabb` a sphere takes the
    /// largest, a cylinder `max(h0, h1)` and `h2`, a capsule that radius and
    /// `h2 - r`. All times `fitscale`. Its frame is the mesh's principal frame (its
    /// origin moved to the bounding box's centre with `fitaabb`) placed by the
    /// geom's `pos` and orientation. The sizes and the placement in the body frame,
    /// or `None` with the error.
    #[allow(clippy::too_many_arguments)]
    fn fitted_geom(
        &mut self,
        t: &Tag,
        class: &str,
        el: &Element,
        geom: &str,
        kind: &str,
        fitscale: f64,
        (pos, rotation): (Vec3, Mat3),
    ) -> Option<([f64; 3], (Vec3, Mat3))> {
        let (_, props) = self.geom_mesh(t, class, el, geom, kind)?;
        let b = props.box_half;
        let a = &props.aabb;
        let (sizes, center) = if self.fit_aabb {
            let h = a.half;
            let s = match kind {
                "sphere" => [h[0].max(h[1]).max(h[2]), 0.0, 0.0],
                "capsule" => {
                    let r = h[0].max(h[1]);
                    [r, h[2] - r, 0.0]
                }
                "cylinder" => [h[0].max(h[1]), h[2], 0.0],
                _ => h,
            };
            (s, a.center)
        } else {
            let s = match kind {
                "sphere" => [(b[0] + b[1] + b[2]) / 3.0, 0.0, 0.0],
                "capsule" => {
                    let r = (b[0] + b[1]) / 2.0;
                    [r, (b[2] - r / 2.0).max(0.0), 0.0]
                }
                "cylinder" => [(b[0] + b[1]) / 2.0, b[2], 0.0],
                _ => b,
            };
            (s, [0.0; 3])
        };
        // The mesh frame in the geom frame: MuJoCo's mjuu_frameaccum of the geom's
        // frame with the mesh's (its position moved to the box's centre).
        let offset = math::add(&props.com, &math::mat_vec(&props.axes, &center));
        let placed = (
            math::add(&pos, &math::mat_vec(&rotation, &offset)),
            math::mat_mul(&rotation, &props.axes),
        );
        Some((sizes.map(|x| x * fitscale), placed))
    }

    /// Notes a `<mesh>` of `<asset>` under its name (its file's name without folder
    /// and extension when it has none).
    fn read_mesh_asset(&mut self, k: usize) {
        let t = &self.tags[k];
        let name = match (t.attr("name"), t.attr("file")) {
            (Some(n), _) => n.to_string(),
            (None, Some(f)) => {
                let base = f.rsplit(['/', '\\']).next().unwrap_or(f);
                base.rsplit_once('.').map_or(base, |(stem, _)| stem).to_string()
            }
            (None, None) => return,
        };
        if let Some(&earlier) = self.meshes.get(&name) {
            let at = self.tags[earlier].line;
            self.error(
                Element::Robot,
                t.line,
                ErrorKind::InvalidMjcf(format!(
                    "<mesh> `{name}` is defined twice (first on line {at}); MuJoCo refuses repeated names: rename one"
                )),
            );
            return;
        }
        self.meshes.insert(name, k);
    }

    /// The mass properties of mesh `name`, as MuJoCo's compiler makes them, or why
    /// they cannot be had (an error on the `<mesh>`'s line).
    fn mesh_mass(&mut self, name: &str) -> Result<MeshMass, ModelError> {
        let k = self.meshes[name];
        let tags = self.tags;
        let t = &tags[k];
        let el = Element::Robot;
        let class = match t.attr("class") {
            Some(c) if self.classes.contains_key(c) => c.to_string(),
            Some(c) => return Err(mesh_error(t.line, ErrorKind::UnknownClass(c.to_string()))),
            None => "main".to_string(),
        };
        let file = t.attr("file");
        let what = match file {
            Some(f) => format!("<mesh name=\"{name}\" file=\"{f}\">"),
            None => format!("<mesh name=\"{name}\">"),
        };
        let invalid = |message: String| mesh_error(t.line, ErrorKind::InvalidMjcf(format!("{what}: {message}")));
        let mode = match self.class_attr(t, &class, "mesh", "inertia") {
            None => MeshInertia::Legacy,
            Some(v) => MeshInertia::parse(&v).ok_or_else(|| {
                invalid(format!(
                    "inertia=\"{v}\" is not `convex`, `exact`, `legacy` or `shell` (MuJoCo's mesh inertia rules)"
                ))
            })?,
        };
        let mut vector = |attr: &str, count: usize, default: &[f64]| -> Result<Vec<f64>, ModelError> {
            match self.class_attr(t, &class, "mesh", attr) {
                None => Ok(default.to_vec()),
                Some(v) => {
                    let before = self.errors.len();
                    let parsed = self.parse_numbers(t, attr, &v, count, &el);
                    match parsed {
                        Some(x) if x.iter().all(|x| x.is_finite()) => Ok(x),
                        _ => {
                            let why = self.errors.drain(before..).next().map_or_else(
                                || format!("{attr}=\"{v}\" is not {count} finite numbers"),
                                |e| e.kind.to_string(),
                            );
                            Err(invalid(why))
                        }
                    }
                }
            }
        };
        let scale = vector("scale", 3, &[1.0; 3])?;
        let refpos = vector("refpos", 3, &[0.0; 3])?;
        let refquat = vector("refquat", 4, &[1.0, 0.0, 0.0, 0.0])?;
        let scale = [scale[0], scale[1], scale[2]];
        if refquat.iter().all(|&q| q == 0.0) {
            return Err(invalid("refquat=\"0 0 0 0\" is not a rotation".into()));
        }
        // A mirroring scale turns the triangles inside out: MuJoCo reverses them as it reads them.
        let flip = scale[0] * scale[1] * scale[2] < 0.0;
        let inline = t.attr("vertex");
        let mut mesh = match (file, inline) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "gives both `file` and `vertex` (MuJoCo refuses the repeated vertex specification); keep one"
                        .into(),
                ))
            }
            (None, None) => {
                return Err(invalid(
                    "has neither `file` nor `vertex`; name an STL or OBJ file, or give the vertices".into(),
                ))
            }
            (Some(f), None) => self.mesh_file(f, flip).map_err(invalid)?,
            (None, Some(v)) => inline_mesh(v, t.attr("face")).map_err(invalid)?,
        };
        // No faces (vertices alone), or the convex mode: the convex hull, built on
        // the vertices as read (as MuJoCo builds it) and turned outwards after the
        // transformation (a mirroring scale turns it inside out).
        let needs_hull = mode == MeshInertia::Convex || mesh.faces.is_empty();
        if let Some(v) = self.class_attr(t, &class, "mesh", "maxhullvert") {
            let limit = match v.trim().parse::<i64>() {
                Ok(n) if n == -1 || n > 3 => n,
                _ => {
                    return Err(invalid(format!(
                        "maxhullvert=\"{v}\" is neither -1 (no limit, the default) nor an integer above 3 \
                         (MuJoCo refuses it)"
                    )))
                }
            };
            // MuJoCo passes the limit to qhull as `TA(maxhullvert - 4)`: qhull stops
            // adding points once the hull has `maxhullvert` vertices, which it can
            // only reach, with a point still outside, when the mesh has more
            // distinct vertices than that.
            let distinct = mjcf_mesh::distinct_points(&mesh.vertices);
            if needs_hull && limit != -1 && (limit as u64) < distinct as u64 {
                let role = if mode == MeshInertia::Convex {
                    "the hull gives its inertia (inertia=\"convex\")"
                } else {
                    "the hull's triangles are its faces (it has no `face`)"
                };
                return Err(mesh_error(
                    t.line,
                    ErrorKind::NotSupported(format!(
                        "{what}: maxhullvert=\"{v}\" stops MuJoCo's convex hull (qhull, option TA{}) at {limit} of \
                         its {distinct} distinct vertices, at the points qhull's own order of additions picks, which \
                         is not reproduced here, and {role}; remove maxhullvert or make it at least {distinct}{}",
                        limit - 4,
                        if mesh.faces.is_empty() {
                            ""
                        } else {
                            ", or choose another inertia"
                        }
                    )),
                ));
            }
        }
        let mut hull = if needs_hull {
            Some(mjcf_mesh::convex_hull(&mesh.vertices).map_err(invalid)?)
        } else {
            None
        };
        mjcf_mesh::transform(
            &mut mesh,
            [refpos[0], refpos[1], refpos[2]],
            [refquat[0], refquat[1], refquat[2], refquat[3]],
            scale,
        );
        if flip {
            for f in hull.iter_mut().flatten() {
                f.swap(1, 2);
            }
        }
        if mesh.faces.is_empty() {
            mesh.faces = hull.clone().unwrap_or_default();
        }
        mjcf_mesh::mass_properties(&mesh, mode, hull.as_deref()).map_err(invalid)
    }

    /// Reads mesh file `file` (relative to `meshdir`, in the model's folder or below).
    fn mesh_file(&self, file: &str, flip: bool) -> Result<TriMesh, String> {
        let Some((dir, canonical_dir)) = self.folder.clone() else {
            return Err(
                "MJCF text read without its file has no folder to read the mesh file from; load the model from \
                 its file (load_mjcf)"
                    .into(),
            );
        };
        let file = if self.strippath {
            file.rsplit(['/', '\\']).next().unwrap_or(file)
        } else {
            file
        };
        let folder = self.meshdir.as_deref().or(self.assetdir.as_deref()).unwrap_or("");
        let joined = Path::new(folder).join(file);
        let shown = joined.display().to_string();
        let relative = inside_folder(&joined).map_err(|p| match p {
            PathProblem::LeadsOut => format!(
                "`{shown}` leads out of the model file's folder; a mesh file must be in that folder or below it"
            ),
            PathProblem::Absolute => format!(
                "`{shown}` is an absolute path; name the mesh file by a path relative to the model file's folder \
                 (and <compiler meshdir>)"
            ),
            PathProblem::Empty => "names no file".to_string(),
        })?;
        let extension = relative
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if !matches!(extension.as_str(), "stl" | "obj") {
            return Err(if extension == "msh" {
                format!(
                    "`{shown}` is in MuJoCo's own binary .msh format, which is not read here; convert it to STL or OBJ"
                )
            } else {
                format!(
                    "`{shown}` is not an STL or OBJ file (by its extension); MuJoCo reads .stl, .obj and .msh meshes"
                )
            });
        }
        let path = dir.join(&relative);
        let canonical = std::fs::canonicalize(&path).map_err(|e| format!("cannot read `{shown}`: {e}"))?;
        if !canonical.starts_with(&canonical_dir) {
            return Err(format!(
                "`{shown}` leads (through a link) out of the model file's folder; a mesh file must be in that folder \
                 or below it"
            ));
        }
        let mut bytes = Vec::new();
        std::fs::File::open(&path)
            .and_then(|f| f.take(mjcf_mesh::MAX_MESH_BYTES + 1).read_to_end(&mut bytes))
            .map_err(|e| format!("cannot read `{shown}`: {e}"))?;
        if bytes.len() as u64 > mjcf_mesh::MAX_MESH_BYTES {
            return Err(format!(
                "`{shown}` is larger than the {} MiB read for a mesh",
                mjcf_mesh::MAX_MESH_BYTES >> 20
            ));
        }
        let read = if extension == "stl" {
            mjcf_mesh::read_stl(&bytes, flip)
        } else {
            mjcf_mesh::read_obj(&bytes, flip)
        };
        read.map_err(|e| format!("`{shown}`: {e}"))
    }

    /// MuJoCo's `boundmass`, `boundinertia`, `balanceinertia` on each body's
    /// principal moments, then `settotalmass` over all bodies; each inertial then
    /// moved into its link frame.
    fn apply_mass_rules(&mut self) {
        let rules = &self.mass_rules;
        for r in &mut self.records {
            if rules.bound_mass > 0.0 || rules.bound_inertia > 0.0 || rules.balance {
                // MuJoCo leaves a body without mass of its own with its inertial frame
                // at the numbers of its `pos` (the rotation does not matter: its moments
                // are all `boundinertia`).
                let mut i = r.inertial.unwrap_or(Inertial {
                    com: r.pos,
                    ..Inertial::principal(0.0, [0.0; 3])
                });
                i.mass = i.mass.max(rules.bound_mass);
                let (written, axes) = i.principal_axes();
                let mut ev = written.map(|x| x.max(rules.bound_inertia));
                let broken = ev[0] + ev[1] < ev[2] || ev[0] + ev[2] < ev[1] || ev[1] + ev[2] < ev[0];
                if rules.balance && broken {
                    let mean = (ev[0] + ev[1] + ev[2]) / 3.0;
                    ev = [mean; 3];
                }
                if ev != written {
                    i.inertia = from_principal(ev, &axes);
                }
                if i.mass > 0.0 || ev.iter().any(|&x| x > 0.0) {
                    r.inertial = Some(i);
                }
            }
        }
        if let Some(target) = rules.total {
            for (body, line) in &self.uncounted {
                self.errors.push(ModelError {
                    element: Element::Link(body.clone()),
                    line: Some(*line),
                    kind: ErrorKind::NotSupported(format!(
                        "<compiler settotalmass> counts the mass of body `{body}`, whose geoms' inertia is not \
                         computed here (an sdf, plane or hfield geom, or a mesh that cannot be read); give the body \
                         an <inertial>"
                    )),
                });
            }
            let total: f64 = self.records.iter().filter_map(|r| r.inertial).map(|i| i.mass).sum();
            if total > 0.0 {
                let scale = target / total;
                for i in self.records.iter_mut().filter_map(|r| r.inertial.as_mut()) {
                    i.mass *= scale;
                    i.inertia = i.inertia.map(|row| row.map(|x| x * scale));
                }
            }
        }
        for r in &self.records {
            self.links[r.link].inertial = r.inertial.map(|i| Inertial {
                com: math::sub(&i.com, &r.shift),
                ..i
            });
        }
    }

    /// Sites and bodies are frames of one model: a site named as a body is refused.
    fn check_site_names(&mut self) {
        let bodies: std::collections::HashSet<&str> = self
            .records
            .iter()
            .map(|r| self.links[r.link].name.as_str())
            .chain([WORLD])
            .collect();
        let clashes: Vec<(String, usize)> = self
            .sites
            .iter()
            .filter(|(n, _)| bodies.contains(n.as_str()))
            .cloned()
            .collect();
        for (name, line) in clashes {
            // MuJoCo's sites and bodies have names of their own; here the site's frame
            // would be a second link of that name: leave the frame out.
            let site = |l: &Option<usize>| *l == Some(line);
            self.links.retain(|l| !(l.name == name && site(&l.line)));
            self.joints
                .retain(|j| !(j.kind == DeclaredJointType::Fixed && j.child == name && site(&j.line)));
            self.warnings.push(ModelError {
                element: Element::Link(name.clone()),
                line: Some(line),
                kind: ErrorKind::Ignored(format!(
                    "site `{name}` has the name of a body and is left out: sites become frames of the model, which \
                     share one namespace with the bodies (MuJoCo's do not); rename the site to have its frame"
                )),
            });
        }
    }
}

/// The inertial with its tensor made exactly symmetric (rotations leave it a few
/// ulps off).
fn symmetric(mut inertial: Inertial) -> Inertial {
    let m = inertial.inertia;
    for (r, row) in inertial.inertia.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = 0.5 * (m[r][c] + m[c][r]);
        }
    }
    inertial
}

/// `axes · diag(moments) · axesᵀ`.
fn from_principal(moments: Vec3, axes: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (r, row) in m.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|k| axes[r][k] * moments[k] * axes[c][k]).sum();
        }
    }
    m
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

/// An error about a `<mesh>` asset, on its line.
fn mesh_error(line: usize, kind: ErrorKind) -> ModelError {
    ModelError {
        element: Element::Robot,
        line: Some(line),
        kind,
    }
}

/// A mesh given in the XML: `vertex` (three numbers a vertex, kept in single
/// precision as MuJoCo keeps them) and, if given, `face` (three vertex indices a
/// triangle); without faces MuJoCo takes the convex hull's.
fn inline_mesh(vertex: &str, face: Option<&str>) -> Result<TriMesh, String> {
    let numbers: Vec<Option<f32>> = vertex.split_whitespace().map(|w| w.parse().ok()).collect();
    if numbers.iter().any(Option::is_none) || !numbers.len().is_multiple_of(3) || numbers.is_empty() {
        return Err(format!(
            "vertex=\"{vertex}\" is not a list of numbers, three for each vertex"
        ));
    }
    let vertices: Vec<Vec3> = numbers
        .chunks_exact(3)
        .map(|c| [0, 1, 2].map(|i| f64::from(c[i].unwrap_or(0.0))))
        .collect();
    if vertices.iter().flatten().any(|x| !x.is_finite()) {
        return Err("a vertex is not a finite number".into());
    }
    let mut faces = Vec::new();
    if let Some(face) = face {
        let indices: Vec<Option<usize>> = face.split_whitespace().map(|w| w.parse().ok()).collect();
        if indices.iter().any(|i| !matches!(i, Some(i) if *i < vertices.len())) || !indices.len().is_multiple_of(3) {
            return Err(format!(
                "face=\"{face}\" is not a list of vertex indices (0 to {}), three for each triangle",
                vertices.len().saturating_sub(1)
            ));
        }
        faces = indices
            .chunks_exact(3)
            .map(|c| [c[0].unwrap_or(0), c[1].unwrap_or(0), c[2].unwrap_or(0)])
            .collect();
    }
    Ok(TriMesh { vertices, faces })
}
