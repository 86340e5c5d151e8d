//! The `robot!` front end: tokens → syntax tree ([`parse`](self::parse())) → rules
//! (`check`) → [`Description`](dyngen_model::Description) (`lower`), every error
//! collected with its span and reported together.
//!
//! # Two forms
//!
//! ```text
//! dyngen::robot! { name: Ur5, urdf: "robots/ur5.urdf" }   // path relative to Cargo.toml
//!
//! dyngen::robot! {
//!     name: Planar2,
//!     gravity: [0.0, -9.81, 0.0],            // optional; default [0, 0, -9.81]
//!     incidence: [                            // rows: bodies 0 (base), 1..n; columns: joints 1..n
//!         [-1,  0],
//!         [ 1, -1],
//!         [ 0,  1],
//!     ],
//!     joints: [revolute(z), revolute(z)],     // one per column, in column order
//!     body_joint_vectors: {                   // c_ia for every nonzero S_ia: (body, joint): [x, y, z]
//!         (0, 1): [0.0, 0.0, 0.0],
//!         (1, 1): [-0.5, 0.0, 0.0], (1, 2): [0.5, 0.0, 0.0],
//!         (2, 2): [-0.5, 0.0, 0.0],
//!     },
//!     bodies: {
//!         1: cylinder(mass: 10.0, radius: 0.05, length: 1.0, axis: x),
//!         2: principal(mass: 5.0, moments: [0.005, 0.4, 0.4]),
//!     },
//!     frames: {                               // optional; name: (body, [x, y, z])
//!         tool: (2, [0.5, 0.0, 0.0]),         //   from the centre of mass, in body axes
//!         camera: (1, [0.0, 0.05, 0.0], rest: [0.0, 0.0, 1.5707963267948966]),
//!         base_mark: (0, [0.1, 0.0, 0.0]),    //   body 0: from the base origin
//!     },
//! }
//! ```
//!
//! # Grammar
//!
//! ```text
//! robot     := field (',' field)* ','?            each keyword at most once, any order
//! field     := 'name' ':' IDENT | 'urdf' ':' STRING | 'gravity' ':' vec3
//!            | 'functions' ':' '[' IDENT,* ']'    functions or groups to generate (both forms;
//!                                                 default all; see dyngen_codegen::Capability)
//!            | 'incidence' ':' '[' row,* ']'      row := '[' INTEGER,* ']'
//!            | 'joints' ':' '[' joint,* ']'
//!            | 'body_joint_vectors' ':' '{' ('(' INTEGER ',' INTEGER ')' ':' vec3),* '}'
//!            | 'bodies' ':' '{' (INTEGER ':' body),* '}'
//!            | 'frames' ':' '{' (IDENT ':' frame),* '}'
//! joint     := ('revolute' | 'continuous' | 'prismatic') '(' axis (',' option)* ','? ')'
//! option    := 'rest' ':' vec3                    [roll, pitch, yaw], rad
//!            | 'limits' ':' '[' num ',' num ']'   [lower, upper]; not on continuous joints
//! axis      := '-'? ('x' | 'y' | 'z') | vec3      nonzero
//! body      := 'cylinder' '(' 'mass' ':' num ',' 'radius' ':' num ',' 'length' ':' num
//!                             ',' 'axis' ':' ('x' | 'y' | 'z') ')'     (arguments in any order)
//!            | 'principal' '(' 'mass' ':' num ',' 'moments' ':' vec3 ')'
//! frame     := '(' INTEGER ',' vec3 (',' 'rest' ':' vec3)? ','? ')'    body, position, [roll, pitch, yaw]
//! vec3      := '[' num ',' num ',' num ']'
//! num       := '-'? (INTEGER | FLOAT)             e.g. -1, 0.5, -9.81, 1e-3; finite
//! ```
//!
//! Trailing commas are allowed in every list.
//!
//! # Meaning
//!
//! The paper's conventions (docs/design.md, "The paper's graph theory"): every body frame is that body's centroidal
//! principal frame. `S_ia` is +1/−1 where joint `a` touches body `i`; a column may
//! be oriented either way. `c_ia`, in body `i`'s frame, goes from body `i`'s centre of
//! mass (for body 0: the base frame origin) to the point of joint `a` on body `i`; it
//! is given exactly for the nonzero `S_ia`. A joint's frame sits at its joint point
//! with the outboard body's axes, and its axis is expressed there. `rest` is the
//! rotation of the outboard body frame relative to the inboard one at `q = 0` (URDF
//! roll-pitch-yaw, `R = Rz(yaw) Ry(pitch) Rx(roll)`); identity when omitted.
//!
//! The description produced has links `body0` (the base, no inertial) and
//! `body1..bodyn` in the user's numbering, and joints `joint1..jointn`. For joint `a`
//! from inboard body `p` to outboard body `c`: origin translation `c_pa − c_pb`, `b`
//! being the joint whose outboard body is `p` (for `p = 0`: `c_0a`), origin rotation
//! from `rest`. Body `c` gets mass `m`, centre of mass `−c_ca` (its frame is at joint
//! `a`'s point) and inertia `diag(J1, J2, J3)`. `principal(mass: m, moments: [J1, J2,
//! J3])` gives them directly; `cylinder(mass, radius, length, axis)` is a homogeneous
//! cylinder along that body axis: `J_axis = m r²/2`, the other two `m (3r² + l²)/12`.
//! Limits carry velocity and effort 0.0, meaning "not specified". A frame
//! `name: (i, p, rest: r)` is a link `name` without inertial on a fixed joint
//! `name_fixed` from link `body<i>`: origin translation `p − c_ia` (`a` the joint
//! whose outboard body is `i`; for the base, `p`), rotation from `r`. The model
//! merges it into body `i` (listed in that body's `merged`; on the base, into the
//! fixed base). The model then
//! renumbers bodies to regular labelling if the user's numbering is not (names keep
//! the user's numbers).
//!
//! # Checks
//!
//! Each is a compile error at the offending token, all reported at once: unknown,
//! duplicate or missing keywords (and mixing `urdf` with inline keywords); malformed
//! values (not a name, not a number, not 3 numbers, a non-integer incidence entry,
//! non-finite numbers); the incidence matrix's shape, entries, columns (one +1 and one
//! −1), connectivity and loops; the number of joints against the columns; unknown
//! joint types, axes and options, zero axes, `lower > upper`, limits on a continuous
//! joint; `c_ia` missing where `S_ia ≠ 0`, given where `S_ia = 0`, duplicated or out
//! of range; bodies missing, duplicated, out of range or body 0; unknown body kinds
//! or arguments, missing arguments; mass, radius, length or moments not positive;
//! moments breaking the triangle inequality; frames malformed, with an unknown option,
//! a duplicate name, a name that is not a plain identifier or is a body's link
//! (`body0..bodyn`), a body out of range, or a position or angle beyond ±1e9.

mod ast;
mod check;
mod ctxt;
mod lower;
mod parse;
mod symbol;

use crate::{RobotInput, RobotSource};
use ctxt::Ctxt;
use proc_macro2::{Span, TokenStream};

/// Parses and checks one `robot!` invocation.
pub fn parse(input: TokenStream) -> syn::Result<RobotInput> {
    let cx = Ctxt::new();
    let robot = parse::robot(&cx, input);
    let tree = check::check(&cx, &robot);
    cx.check()?;

    let internal = || {
        syn::Error::new(
            Span::call_site(),
            "internal error in the robot! front end: a checked part is missing; please report \
             this with the invocation",
        )
    };
    let name = robot.name.value.clone().ok_or_else(internal)?;
    let functions = robot.functions.value.unwrap_or_default();
    if let Some(path) = &robot.urdf.value {
        return Ok(RobotInput {
            name,
            source: RobotSource::Urdf(path.clone()),
            functions,
        });
    }
    let tree = tree.ok_or_else(internal)?;
    let description = lower::lower(&robot, &tree).ok_or_else(internal)?;
    // The checks above should leave nothing for the model to find; if they do, the
    // model's message (naming the link or joint) is still better than none.
    if let Err(errors) = description.build() {
        let mut all = errors.iter().map(|e| syn::Error::new(Span::call_site(), e.to_string()));
        let mut first = all.next().ok_or_else(internal)?;
        for e in all {
            first.combine(e);
        }
        return Err(first);
    }
    Ok(RobotInput {
        name,
        source: RobotSource::Dsl(Box::new(description)),
        functions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_model::{JointKind, Model};
    use quote::quote;

    fn planar2() -> TokenStream {
        quote! {
            name: Planar2,
            gravity: [0.0, -9.81, 0.0],
            incidence: [
                [-1,  0],
                [ 1, -1],
                [ 0,  1],
            ],
            joints: [revolute(z), revolute(z)],
            body_joint_vectors: {
                (0, 1): [0.0, 0.0, 0.0],
                (1, 1): [-0.5, 0.0, 0.0], (1, 2): [0.5, 0.0, 0.0],
                (2, 2): [-0.5, 0.0, 0.0],
            },
            bodies: {
                1: cylinder(mass: 10.0, radius: 0.05, length: 1.0, axis: x),
                2: principal(mass: 5.0, moments: [0.005, 0.4, 0.4]),
            },
        }
    }

    fn description(input: TokenStream) -> dyngen_model::Description {
        match parse(input) {
            Ok(RobotInput {
                source: RobotSource::Dsl(d),
                ..
            }) => *d,
            Ok(_) => panic!("expected the inline form"),
            Err(e) => panic!("{:#?}", e.into_iter().map(|e| e.to_string()).collect::<Vec<_>>()),
        }
    }

    fn messages(input: TokenStream) -> Vec<String> {
        match parse(input) {
            Ok(_) => Vec::new(),
            Err(e) => e.into_iter().map(|e| e.to_string()).collect(),
        }
    }

    fn close(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn free_and_spherical_joints_lower_to_a_floating_model() {
        let d = description(quote! {
            name: Floater,
            incidence: [
                [-1,  0,  0],
                [ 1, -1,  0],
                [ 0,  1, -1],
                [ 0,  0,  1],
            ],
            joints: [free(), spherical(rest: [0.0, 0.0, 0.5]), revolute(y)],
            body_joint_vectors: {
                (0, 1): [0.0, 0.0, 0.0],
                (1, 1): [0.0, 0.0, 0.0], (1, 2): [0.2, 0.0, 0.0],
                (2, 2): [-0.1, 0.0, 0.0], (2, 3): [0.1, 0.0, 0.0],
                (3, 3): [-0.1, 0.0, 0.0],
            },
            bodies: {
                1: principal(mass: 5.0, moments: [0.1, 0.2, 0.25]),
                2: cylinder(mass: 1.0, radius: 0.03, length: 0.2, axis: x),
                3: cylinder(mass: 0.5, radius: 0.02, length: 0.2, axis: x),
            },
        });
        let model = d.build().unwrap();
        let kinds: Vec<JointKind> = model.joints.iter().map(|j| j.kind).collect();
        assert_eq!(kinds, [JointKind::FreeFlyer, JointKind::Spherical, JointKind::Revolute]);
        assert!(model.is_floating());
        assert_eq!((model.nq(), model.nv()), (12, 10));
        assert_eq!(model.joints[1].axis, [0.0; 3]);
    }

    #[test]
    fn free_and_spherical_joints_take_no_axis_and_no_limits() {
        let robot = |joints: TokenStream| {
            quote! {
                name: Bad,
                incidence: [[-1], [1]],
                joints: #joints,
                body_joint_vectors: { (0, 1): [0.0, 0.0, 0.0], (1, 1): [0.0, 0.0, 0.0] },
                bodies: { 1: principal(mass: 1.0, moments: [0.1, 0.1, 0.1]) },
            }
        };
        let m = messages(robot(quote!([spherical(z)])));
        assert!(
            m.iter()
                .any(|e| e.contains("a `spherical` joint has no axis: write `spherical()`")),
            "{m:?}"
        );
        let m = messages(robot(quote!([free(limits: [-1.0, 1.0])])));
        assert!(m.iter().any(|e| e.contains("has no position limits")), "{m:?}");
        assert!(messages(robot(quote!([free()]))).is_empty());
    }

    #[test]
    fn a_planar_joint_takes_its_normal_as_axis_and_no_limits() {
        let robot = |joints: TokenStream| {
            quote! {
                name: Rover,
                incidence: [[-1], [1]],
                joints: #joints,
                body_joint_vectors: { (0, 1): [0.0, 0.0, 0.1], (1, 1): [0.0, 0.0, 0.0] },
                bodies: { 1: principal(mass: 1.0, moments: [0.1, 0.1, 0.1]) },
            }
        };
        let model = description(robot(quote!([planar(-y)]))).build().unwrap();
        assert_eq!(model.joints[0].kind, JointKind::Planar);
        assert_eq!(model.joints[0].axis, [0.0, -1.0, 0.0]);
        assert_eq!((model.nq(), model.nv()), (3, 3));
        let m = messages(robot(quote!([planar()])));
        assert!(
            m.iter()
                .any(|e| e.contains("expected the joint axis, as in `planar(z)`")),
            "{m:?}"
        );
        let m = messages(robot(quote!([planar(z, limits: [-1.0, 1.0])])));
        assert!(
            m.iter().any(|e| e.contains("a `planar` joint has no position limits")),
            "{m:?}"
        );
    }

    #[test]
    fn planar2_lowers_to_the_expected_description() {
        let d = description(planar2());
        assert_eq!(d.name, "Planar2");
        assert_eq!(d.gravity, [0.0, -9.81, 0.0]);
        let names: Vec<&str> = d.links.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["body0", "body1", "body2"]);
        assert!(d.links[0].inertial.is_none());
        let j2 = &d.joints[1];
        assert_eq!(
            (j2.name.as_str(), j2.parent.as_str(), j2.child.as_str()),
            ("joint2", "body1", "body2")
        );
        // c_12 - c_11 = 0.5 - (-0.5).
        assert!(close(&j2.origin.translation, &[1.0, 0.0, 0.0]));
        assert!(close(&d.joints[0].origin.translation, &[0.0; 3]));
        assert_eq!(j2.origin.rotation, dyngen_model::math::IDENTITY);
        assert_eq!(j2.axis, [0.0, 0.0, 1.0]);
        assert_eq!(j2.limits, None);

        let b1 = d.links[1].inertial.unwrap();
        assert_eq!(b1.mass, 10.0);
        assert!(close(&b1.com, &[0.5, 0.0, 0.0]));
        let across = 10.0 * (3.0 * 0.05 * 0.05 + 1.0) / 12.0;
        let diag = [b1.inertia[0][0], b1.inertia[1][1], b1.inertia[2][2]];
        assert!(close(&diag, &[10.0 * 0.05 * 0.05 / 2.0, across, across]));
        let b2 = d.links[2].inertial.unwrap();
        assert!(close(&b2.com, &[0.5, 0.0, 0.0]));
        assert!(close(
            &[b2.inertia[0][0], b2.inertia[1][1], b2.inertia[2][2]],
            &[0.005, 0.4, 0.4]
        ));
    }

    /// Planar2 with a frame on each kind of body: a moving body, one with a rest
    /// rotation, and the base.
    fn planar2_with_frames() -> TokenStream {
        let mut tokens = planar2();
        tokens.extend(quote! {
            frames: {
                tool: (2, [0.2, 0.0, 0.0]),
                camera: (1, [0.0, 0.05, 0.0], rest: [0.0, 0.0, 1.5707963267948966]),
                base_mark: (0, [0.1, 0.0, 0.0],),
            },
        });
        tokens
    }

    #[test]
    fn frames_lower_to_massless_links_on_fixed_joints() {
        let d = description(planar2_with_frames());
        let links: Vec<(&str, bool)> = d
            .links
            .iter()
            .map(|l| (l.name.as_str(), l.inertial.is_some()))
            .collect();
        assert_eq!(
            links,
            [
                ("body0", false),
                ("body1", true),
                ("body2", true),
                ("tool", false),
                ("camera", false),
                ("base_mark", false)
            ]
        );
        let joints: Vec<(&str, &str, &str, bool)> = d
            .joints
            .iter()
            .map(|j| {
                let fixed = j.kind == dyngen_model::DeclaredJointType::Fixed;
                (j.name.as_str(), j.parent.as_str(), j.child.as_str(), fixed)
            })
            .collect();
        assert_eq!(
            joints,
            [
                ("joint1", "body0", "body1", false),
                ("joint2", "body1", "body2", false),
                ("tool_fixed", "body2", "tool", true),
                ("camera_fixed", "body1", "camera", true),
                ("base_mark_fixed", "body0", "base_mark", true),
            ]
        );
        // Body 2's link frame is at joint 2's point, c_22 = [-0.5, 0, 0] from the
        // centre of mass: the tool is at p - c_22.
        let tool = &d.joints[2].origin;
        assert!(close(&tool.translation, &[0.7, 0.0, 0.0]));
        assert_eq!(tool.rotation, dyngen_model::math::IDENTITY);
        // Body 1's at joint 1's point, c_11 = [-0.5, 0, 0]; the camera turned by a
        // quarter turn about z.
        let camera = &d.joints[3].origin;
        assert!(close(&camera.translation, &[0.5, 0.05, 0.0]));
        let r = camera.rotation;
        assert!(close(
            &[r[0][0], r[0][1], r[1][0], r[1][1], r[2][2]],
            &[0.0, -1.0, 1.0, 0.0, 1.0]
        ));
        let want = dyngen_model::Placement::from_xyz_rpy([0.5, 0.05, 0.0], [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        assert_eq!(camera.rotation, want.rotation);
        // The base's link frame is the base frame: the position as written.
        let mark = &d.joints[4].origin;
        assert!(close(&mark.translation, &[0.1, 0.0, 0.0]));
        assert_eq!(mark.rotation, dyngen_model::math::IDENTITY);
    }

    #[test]
    fn frames_build_and_merge_into_their_bodies() {
        let with = description(planar2_with_frames()).build().unwrap();
        let without = description(planar2()).build().unwrap();
        assert_eq!(with.dof(), 2);
        assert_eq!(with.joints, without.joints);
        let merged: Vec<(&str, Vec<&str>)> = with
            .bodies
            .iter()
            .map(|b| (b.name.as_str(), b.merged.iter().map(String::as_str).collect()))
            .collect();
        assert_eq!(merged, [("body1", vec!["camera"]), ("body2", vec!["tool"])]);
        // Massless frames leave the bodies' inertials as they were.
        for (a, b) in with.bodies.iter().zip(&without.bodies) {
            assert_eq!(a.inertial, b.inertial);
        }
        assert!(with.warnings.is_empty());
    }

    #[test]
    fn frame_rules() {
        let mut tokens = planar2();
        tokens.extend(quote! {
            frames: {
                tool: (3, [0.2, 0.0, 0.0]),
                tool: (2, [0.0, 0.0, 0.0]),
                body2: (2, [0.0, 0.0, 0.0]),
                body3: (2, [0.0, 0.0, 0.0]),
                body02: (2, [0.0, 0.0, 0.0]),
                far: (-1, [2e9, 0.0, 0.0], rest: [0.0, -1e10, 0.0]),
            },
        });
        let e = messages(tokens);
        let want = [
            "duplicate frame `tool`",
            "frame name `body2` is the link of body 2; the bodies' links are `body0` to `body2`",
            "body 3 does not exist; a frame is fixed to one of the bodies 0 (the base) to 2",
            "body -1 does not exist",
            "frame position 2000000000 is out of range; give it in m, within ±1e9",
            "frame rest angle -10000000000 is out of range; give it in rad, within ±1e9",
        ];
        assert_eq!(e.len(), want.len(), "{e:#?}");
        for (got, want) in e.iter().zip(want) {
            assert!(got.contains(want), "{got:?} should contain {want:?}");
        }
    }

    #[test]
    fn frames_belong_to_the_inline_form() {
        let e = messages(quote!(name: R, urdf: "r.urdf", frames: {}));
        assert_eq!(e.len(), 1, "{e:#?}");
        assert!(e[0].starts_with("`frames` cannot be combined with `urdf`"), "{e:?}");
        let e = messages(quote!(name: R, frames: {}));
        assert!(
            e[0].starts_with("missing `incidence`, `joints`, `body_joint_vectors` and `bodies`"),
            "{e:?}"
        );
        assert!(e[0].ends_with("(`gravity` and `frames` optional)"), "{e:?}");
    }

    #[test]
    fn planar2_builds_a_model_whose_graph_matches_the_input() {
        let model: Model = description(planar2()).build().unwrap();
        assert_eq!(model.dof(), 2);
        assert_eq!((model.parent(1), model.parent(2)), (0, 1));
        assert!(model.joints.iter().all(|j| j.kind == JointKind::Revolute));
        assert_eq!(
            dyngen_model::graph::incidence(&model),
            vec![vec![-1, 0], vec![1, -1], vec![0, 1]]
        );
        // The model's own c_ia are the ones written.
        let c = dyngen_model::graph::body_joint_vectors(&model);
        assert!(close(&c[1][0], &[-0.5, 0.0, 0.0]));
        assert!(close(&c[1][1], &[0.5, 0.0, 0.0]));
        assert!(close(&c[2][1], &[-0.5, 0.0, 0.0]));
    }

    #[test]
    fn urdf_form() {
        let input = parse(quote!(name: Ur5, urdf: "robots/ur5.urdf",)).unwrap();
        assert_eq!(input.name, "Ur5");
        assert!(matches!(input.source, RobotSource::Urdf(ref p) if p.value() == "robots/ur5.urdf"));
    }

    /// A branched robot, a reversed column, a non-regular numbering, rest rotations,
    /// limits and default gravity.
    #[test]
    fn branched_reversed_and_renumbered() {
        let d = description(quote! {
            name: Branch,
            incidence: [
                [ 0, -1,  0],
                [ 0,  1,  1],   // joint 3 written reversed: +1 on the inboard body 1
                [ 1,  0,  0],
                [-1,  0, -1],
            ],
            joints: [
                prismatic([0, 0, 2], limits: [-0.1, 0.2]),
                continuous(-y, rest: [0.0, 0.0, 1.5707963267948966]),
                revolute(x, limits: [-1, 1]),
            ],
            body_joint_vectors: {
                (0, 2): [0, 0, 1],
                (1, 2): [0, 0, -0.25], (1, 3): [0, 0, 0.25],
                (3, 3): [0, 0, -0.1], (3, 1): [0.1, 0, 0],
                (2, 1): [-0.2, 0, 0],
            },
            bodies: {
                3: principal(mass: 1, moments: [1, 1, 1]),
                1: principal(mass: 2, moments: [1, 2, 2]),
                2: cylinder(mass: 3, radius: 0.1, length: 0.4, axis: z),
            },
        });
        assert_eq!(d.gravity, dyngen_model::DEFAULT_GRAVITY);
        let ends: Vec<(&str, &str)> = d.joints.iter().map(|j| (j.parent.as_str(), j.child.as_str())).collect();
        assert_eq!(ends, [("body3", "body2"), ("body0", "body1"), ("body1", "body3")]);
        // Joint 1 from body 3: c_31 - c_33.
        assert!(close(&d.joints[0].origin.translation, &[0.1, 0.0, 0.1]));
        assert!(close(&d.joints[1].origin.translation, &[0.0, 0.0, 1.0]));
        assert!(close(&d.joints[2].origin.translation, &[0.0, 0.0, 0.5]));
        assert_eq!(d.joints[1].origin.rotation[0], [0.0, -1.0, 0.0]);
        assert_eq!(d.joints[0].limits.map(|l| (l.lower, l.upper)), Some((-0.1, 0.2)));
        let model = d.build().unwrap();
        let order: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(order, ["body1", "body3", "body2"]);
        assert_eq!((model.parent(1), model.parent(2), model.parent(3)), (0, 1, 2));
        assert_eq!(model.joints[2].axis, [0.0, 0.0, 1.0]);
    }

    #[test]
    fn every_mistake_of_one_invocation_is_reported() {
        let e = messages(quote! {
            name: Planar2,
            incidence: [[-1, 0], [1, -1], [0, 1]],
            joints: [revolute(z)],
            body_joint_vectors: {
                (0, 1): [0.0, 0.0, 0.0],
                (1, 1): [-0.5, 0.0, 0.0],
                (2, 1): [0.0, 0.0, 0.0],
                (2, 2): [-0.5, 0.0, 0.0],
            },
            bodies: { 1: principal(mass: -1, moments: [1, 1, 3]) },
        });
        let want = [
            "1 joint given but the incidence matrix has 2 columns",
            "body 2 does not touch joint 1",
            "missing body-joint vector (1, 2)",
            "missing body 2",
            "mass -1 is not positive",
            "J3 = 3 exceeds J1 + J2 = 2",
        ];
        assert_eq!(e.len(), want.len(), "{e:#?}");
        for (got, want) in e.iter().zip(want) {
            assert!(got.contains(want), "{got:?} should contain {want:?}");
        }
    }

    #[test]
    fn incidence_errors() {
        let robot = |s: TokenStream| {
            quote! {
                name: R, incidence: #s, joints: [revolute(z), revolute(z)],
                body_joint_vectors: {}, bodies: {},
            }
        };
        let e = messages(robot(quote!([[-1, -1], [1, 1], [0, 0]])));
        assert!(
            e.iter()
                .any(|m| m.contains("joint 2 between bodies 0 and 1 closes a loop")),
            "{e:#?}"
        );
        assert!(e.iter().any(|m| m.starts_with("body 2 is not connected")), "{e:#?}");
        let e = messages(robot(quote!([[-1, 0], [1, 1], [0, 1]])));
        assert!(
            e[0].contains("joint 2's column has 2 entries +1 and 0 entries -1"),
            "{e:#?}"
        );
        let e = messages(robot(quote!([[-1, 0], [1, -1, 0], [0, 1]])));
        assert_eq!(e.len(), 1, "{e:#?}");
        assert!(
            e[0].starts_with("row 1 (body 1) has 3 entries but row 0 has 2"),
            "{e:#?}"
        );
        let e = messages(robot(quote!([[-1, 0], [2, -1], [0, 1.0]])));
        assert!(e[0].contains("integers"), "{e:#?}");
        let e = messages(robot(quote!([[-1, 0], [1, -1]])));
        assert!(e[0].contains("has 2 rows and 2 columns"), "{e:#?}");
        let e = messages(robot(quote!([[-1, 0], [2, -1], [0, 1]])));
        assert!(e[0].contains("entry 2 (body 1, joint 1)"), "{e:#?}");
    }

    #[test]
    fn missing_keywords() {
        let e = messages(quote!());
        assert_eq!(e.len(), 1);
        assert!(e[0].starts_with("missing `name` and the robot's source"), "{e:?}");
        let e = messages(quote!(name: R, incidence: [[-1], [1]]));
        assert!(
            e[0].starts_with("missing `joints`, `body_joint_vectors` and `bodies`"),
            "{e:?}"
        );
        let e = messages(quote!(name: R, urdf: "r.urdf", joints: []));
        assert!(e[0].starts_with("`joints` cannot be combined with `urdf`"), "{e:?}");
    }

    #[test]
    fn joint_rules() {
        let e = messages(quote! {
            name: R,
            incidence: [[-1, 0, 0], [1, -1, 0], [0, 1, -1], [0, 0, 1]],
            joints: [revolute([0, 0, 0]), continuous(z, limits: [-1, 1]), prismatic(x, limits: [1, -1])],
            body_joint_vectors: { (0, 1): [0, 0, 0], (1, 1): [0, 0, 0], (1, 2): [0, 0, 0],
                (2, 2): [0, 0, 0], (2, 3): [0, 0, 0], (3, 3): [0, 0, 0] },
            bodies: { 1: principal(mass: 1, moments: [1, 1, 1]), 2: principal(mass: 1, moments: [1, 1, 1]),
                3: cylinder(mass: 1, radius: 0, length: 1, axis: y) },
        });
        let want = [
            "the joint axis is zero",
            "a `continuous` joint has no limits",
            "lower limit 1 is above upper limit -1",
            "cylinder radius 0 is not positive",
        ];
        assert_eq!(e.len(), want.len(), "{e:#?}");
        for (got, want) in e.iter().zip(want) {
            assert!(got.contains(want), "{got:?} should contain {want:?}");
        }
    }

    #[test]
    fn body_and_vector_indices() {
        let e = messages(quote! {
            name: R,
            incidence: [[-1], [1]],
            joints: [revolute(z)],
            body_joint_vectors: { (0, 1): [0, 0, 0], (1, 1): [0, 0, 0], (1, 1): [0, 0, 0], (2, 1): [0, 0, 0], (1, 0): [0, 0, 0] },
            bodies: { 0: principal(mass: 1, moments: [1, 1, 1]), 1: principal(mass: 1, moments: [1, 1, 1]),
                1: principal(mass: 1, moments: [1, 1, 1]), 5: principal(mass: 1, moments: [1, 1, 1]) },
        });
        let want = [
            "body 2 does not exist; bodies are 0 (the base) to 1",
            "joint 0 does not exist; joints are 1 to 1",
            "duplicate body-joint vector (1, 1)",
            "body 0 is the fixed base",
            "body 5 does not exist",
            "duplicate body 1",
        ];
        assert_eq!(e.len(), want.len(), "{e:#?}");
        for (got, want) in e.iter().zip(want) {
            assert!(got.contains(want), "{got:?} should contain {want:?}");
        }
    }
}
