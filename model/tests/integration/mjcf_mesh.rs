//! Inertia of MJCF mesh geoms: the models of `tests/fixtures/mjcf_mesh/` (binary STL
//! and OBJ meshes in each of MuJoCo's `inertia` modes, scaled, moved, with `mass`,
//! given inline) give MuJoCo's body masses, centres of mass and inertias and its mass
//! matrix and bias forces (`scripts/make_mjcf_mesh_fixtures.py`), and each refused
//! mesh names its element, line and file.

use dyngen_model::regressor::{inverse_dynamics, mass_matrix};
use dyngen_model::{load_mjcf, parse_mjcf, Model};

use crate::common::{load_error, TempDir};
use serde_json::Value;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/mjcf_mesh")
        .join(name)
}

fn numbers(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().flat_map(numbers).collect(),
        Value::Number(x) => vec![x.as_f64().unwrap()],
        _ => panic!("not a number: {v}"),
    }
}

/// Largest `|a - b|` over the largest `|b|`.
fn relative(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
}

/// The largest relative difference from MuJoCo's of the bodies' masses, centres of
/// mass and inertias, and of `M` and the bias over the fixture's states.
fn against_mujoco(name: &str) -> (f64, f64) {
    let model: Model = load_mjcf(&fixture(&format!("{name}.xml"))).unwrap();
    let text = std::fs::read_to_string(fixture(&format!("{name}.json"))).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let mut inertial = 0.0f64;
    for b in reference["bodies"].as_array().unwrap() {
        let body = b["name"].as_str().unwrap();
        let ours = &model.bodies.iter().find(|x| x.name == body).unwrap().inertial;
        let mass = b["mass"].as_f64().unwrap();
        let d = [
            (ours.mass - mass).abs() / mass,
            relative(&ours.com, &numbers(&b["com"])),
            relative(&ours.inertia.concat(), &numbers(&b["inertia"])),
        ];
        eprintln!(
            "{name}: {body}: mass {:.1e}, com {:.1e}, inertia {:.1e}",
            d[0], d[1], d[2]
        );
        inertial = d.iter().fold(inertial, |m, x| m.max(*x));
    }
    let mut dynamics = 0.0f64;
    for s in reference["samples"].as_array().unwrap() {
        let (q, v) = (numbers(&s["q"]), numbers(&s["v"]));
        let m: Vec<f64> = mass_matrix(&model, &q).unwrap().concat();
        let bias = inverse_dynamics(&model, &q, &v, &vec![0.0; model.nv()]).unwrap();
        dynamics = dynamics
            .max(relative(&m, &numbers(&s["M"])))
            .max(relative(&bias, &numbers(&s["bias"])));
    }
    eprintln!("{name}: inertials within {inertial:.1e}, M and bias within {dynamics:.1e} (relative)");
    (inertial, dynamics)
}

#[test]
fn each_inertia_mode_gives_mujocos_inertia() {
    let (inertial, dynamics) = against_mujoco("modes");
    assert!(inertial < 1e-10 && dynamics < 1e-10, "{inertial:e} {dynamics:e}");
}

#[test]
fn primitives_fitted_to_a_meshs_box_of_equal_inertia_give_mujocos_inertia() {
    let (inertial, dynamics) = against_mujoco("fit_inertia");
    assert!(inertial < 1e-10 && dynamics < 1e-10, "{inertial:e} {dynamics:e}");
}

#[test]
fn primitives_fitted_to_a_meshs_bounding_box_give_mujocos_inertia() {
    let (inertial, dynamics) = against_mujoco("fit_aabb");
    assert!(inertial < 1e-10 && dynamics < 1e-10, "{inertial:e} {dynamics:e}");
}

#[test]
fn geoms_that_cannot_be_fitted_to_a_mesh_are_refused() {
    let dir = TempDir::new("mesh-fit");
    // A regular octahedron: with fitaabb a capsule fitted to it has no straight part.
    let octahedron = "<mesh name=\"m\" vertex=\"1 0 0 -1 0 0 0 1 0 0 -1 0 0 0 1 0 0 -1\"/>";
    let refused = |geom: &str, compiler: &str, line: usize, says: &str| {
        let text = model_with(octahedron)
            .replace("<geom type=\"mesh\" mesh=\"m\"/>", geom)
            .replace("<asset>", &format!("{compiler}<asset>"));
        let top = dir.write("top.xml", text.as_bytes());
        load_error(&top, line, says);
    };
    refused(
        "<geom type=\"plane\" mesh=\"m\"/>",
        "",
        7,
        "<geom type=\"plane\"> of type `plane` names a mesh, but MuJoCo fits only a box, sphere, capsule, \
         cylinder or ellipsoid to a mesh",
    );
    refused(
        "<geom name=\"g\" type=\"capsule\" mesh=\"m\" fromto=\"0 0 0 0 0 1\"/>",
        "",
        7,
        "geom `g` names a mesh and has a `fromto`, which MuJoCo refuses",
    );
    for scale in ["0", "-1", "big"] {
        refused(
            &format!("<geom name=\"g\" type=\"box\" mesh=\"m\" fitscale=\"{scale}\"/>"),
            "",
            7,
            &format!("geom `g` has fitscale=\"{scale}\", which is not a positive number"),
        );
    }
    refused(
        "<geom name=\"g\" type=\"capsule\" mesh=\"m\"/>",
        "<compiler fitaabb=\"true\"/>",
        7,
        "geom `g` fitted to mesh `m` from its bounding box (<compiler fitaabb=\"true\">) gets size=\"1 0\", which \
         MuJoCo refuses (a capsule's sizes must be positive)",
    );
    refused(
        "<geom name=\"g\" type=\"sphere\" mesh=\"n\"/>",
        "",
        7,
        "geom `g` names mesh `n`, which no <mesh> in <asset> defines",
    );
    refused(
        "<geom type=\"box\" mesh=\"m\"/>",
        "<compiler fitaabb=\"yes\"/>",
        2,
        "<compiler fitaabb=\"yes\"> is neither `true` nor `false`",
    );
    // Without fitaabb the same capsule fits the box of equal inertia.
    let text = model_with(octahedron).replace("type=\"mesh\"", "type=\"capsule\"");
    assert!(parse_mjcf(&text).is_ok());
}

#[test]
fn scaled_moved_weighed_and_inline_meshes_give_mujocos_inertia() {
    let (inertial, dynamics) = against_mujoco("scaled");
    assert!(inertial < 1e-10 && dynamics < 1e-10, "{inertial:e} {dynamics:e}");
}

/// A model whose body `b` (on a hinge) has one mesh geom of the mesh given by the
/// `<mesh>` element `mesh` (line 3 of `top.xml`; the geom is on line 7).
fn model_with(mesh: &str) -> String {
    format!(
        "<mujoco model=\"t\">\n<asset>\n{mesh}\n</asset>\n<worldbody>\n<body name=\"b\"><joint name=\"j\"/>\n\
         <geom type=\"mesh\" mesh=\"m\"/>\n</body>\n</worldbody>\n</mujoco>\n"
    )
}

fn box_stl() -> Vec<u8> {
    std::fs::read(fixture("meshes/box.stl")).unwrap()
}

#[test]
fn a_missing_mesh_file_is_refused_naming_it() {
    let dir = TempDir::new("mesh-missing");
    let top = dir.write(
        "top.xml",
        model_with("<mesh name=\"m\" file=\"parts/gone.stl\"/>").as_bytes(),
    );
    load_error(
        &top,
        3,
        "<mesh name=\"m\" file=\"parts/gone.stl\">: cannot read `parts/gone.stl`",
    );
    // With meshdir, the path as resolved against it.
    let text =
        model_with("<mesh name=\"m\" file=\"gone.stl\"/>").replace("<asset>", "<compiler meshdir=\"parts\"/><asset>");
    let top = dir.write("top.xml", text.as_bytes());
    load_error(&top, 3, "cannot read `parts/gone.stl`");
}

#[test]
fn a_mesh_file_outside_the_models_folder_is_refused() {
    let dir = TempDir::new("mesh-outside");
    dir.write("box.stl", box_stl());
    let top = dir.write(
        "model/top.xml",
        model_with("<mesh name=\"m\" file=\"../box.stl\"/>").as_bytes(),
    );
    load_error(&top, 3, "`../box.stl` leads out of the model file's folder");
    let text =
        model_with("<mesh name=\"m\" file=\"box.stl\"/>").replace("<asset>", "<compiler meshdir=\"..\"/><asset>");
    let top = dir.write("model/top.xml", text.as_bytes());
    load_error(&top, 3, "`../box.stl` leads out of the model file's folder");
    let absolute = dir.0.join("box.stl");
    let text = model_with(&format!("<mesh name=\"m\" file=\"{}\"/>", absolute.display()));
    let top = dir.write("model/top.xml", text.as_bytes());
    load_error(&top, 3, "is an absolute path");
    // Nor through a link.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.0.join("box.stl"), dir.0.join("model/link.stl")).unwrap();
        let top = dir.write(
            "model/top.xml",
            model_with("<mesh name=\"m\" file=\"link.stl\"/>").as_bytes(),
        );
        load_error(
            &top,
            3,
            "`link.stl` leads (through a link) out of the model file's folder",
        );
    }
}

#[test]
fn a_corrupt_or_ascii_stl_is_refused() {
    let dir = TempDir::new("mesh-corrupt");
    let top = dir.write("top.xml", model_with("<mesh name=\"m\" file=\"bad.stl\"/>").as_bytes());
    // Cut short: the header's count of triangles does not fit the size.
    let stl = box_stl();
    dir.write("bad.stl", &stl[..stl.len() - 7]);
    load_error(
        &top,
        3,
        "`bad.stl`: its header counts 12 triangles, which take 684 bytes, but the file has 677",
    );
    dir.write("bad.stl", b"");
    load_error(&top, 3, "`bad.stl`: the file is empty");
    dir.write("bad.stl", [0u8; 40]);
    load_error(&top, 3, "shorter than the 84-byte header");
    // MuJoCo reads no ASCII STL.
    let ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n\
                 endfacet\nendsolid t\n";
    dir.write("bad.stl", ascii.as_bytes());
    load_error(&top, 3, "an ASCII STL file, which MuJoCo does not read");
}

#[test]
fn unsupported_mesh_formats_are_refused() {
    let dir = TempDir::new("mesh-format");
    dir.write("m.msh", [0u8; 64]);
    let top = dir.write("top.xml", model_with("<mesh name=\"m\" file=\"m.msh\"/>").as_bytes());
    load_error(
        &top,
        3,
        "`m.msh` is in MuJoCo's own binary .msh format, which is not read here",
    );
    dir.write("m.ply", b"ply\n");
    let top = dir.write("top.xml", model_with("<mesh name=\"m\" file=\"m.ply\"/>").as_bytes());
    load_error(&top, 3, "`m.ply` is not an STL or OBJ file");
    dir.write("m.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n");
    let top = dir.write("top.xml", model_with("<mesh name=\"m\" file=\"m.obj\"/>").as_bytes());
    load_error(&top, 3, "`m.obj`: it has no faces");
    dir.write("m.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3 4 5\n");
    load_error(
        &top,
        3,
        "face 1 has 5 vertices; MuJoCo reads OBJ faces of 3 or 4 vertices only",
    );
}

#[test]
fn a_mesh_without_volume_is_refused_in_a_volume_mode() {
    let dir = TempDir::new("mesh-flat");
    // A single triangle: area, but no volume (and a flat hull).
    let mut stl = vec![b' '; 80];
    stl.extend(1u32.to_le_bytes());
    for x in [0.0f32, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        stl.extend(x.to_le_bytes());
    }
    stl.extend([0, 0]);
    dir.write("flat.stl", &stl);
    let top = dir.write(
        "top.xml",
        model_with("<mesh name=\"m\" file=\"flat.stl\" inertia=\"exact\"/>").as_bytes(),
    );
    load_error(&top, 3, "its volume is zero or too small");
    let top = dir.write(
        "top.xml",
        model_with("<mesh name=\"m\" file=\"flat.stl\" inertia=\"convex\"/>").as_bytes(),
    );
    load_error(&top, 3, "its convex hull needs at least 4 distinct vertices");
    // MuJoCo's default (legacy) too.
    let top = dir.write("top.xml", model_with("<mesh name=\"m\" file=\"flat.stl\"/>").as_bytes());
    load_error(&top, 3, "its volume is zero or too small");
    // Inside out, in the exact mode.
    let mut stl = box_stl();
    for t in 0..12 {
        let at = 84 + 50 * t + 24;
        let second: Vec<u8> = stl[at..at + 12].to_vec();
        let third: Vec<u8> = stl[at + 12..at + 24].to_vec();
        stl[at..at + 12].copy_from_slice(&third);
        stl[at + 12..at + 24].copy_from_slice(&second);
    }
    dir.write("inside_out.stl", &stl);
    let top = dir.write(
        "top.xml",
        model_with("<mesh name=\"m\" file=\"inside_out.stl\" inertia=\"exact\"/>").as_bytes(),
    );
    load_error(&top, 3, "its volume is negative");
}

#[test]
fn mesh_attributes_and_geoms_are_checked() {
    let dir = TempDir::new("mesh-attributes");
    dir.write("box.stl", box_stl());
    let top = dir.write(
        "top.xml",
        model_with("<mesh name=\"m\" file=\"box.stl\" inertia=\"solid\"/>").as_bytes(),
    );
    load_error(
        &top,
        3,
        "inertia=\"solid\" is not `convex`, `exact`, `legacy` or `shell`",
    );
    let top = dir.write(
        "top.xml",
        model_with("<mesh name=\"m\" file=\"box.stl\" scale=\"1 2\"/>").as_bytes(),
    );
    load_error(&top, 3, "<mesh name=\"m\" file=\"box.stl\">: ");
    let top = dir.write(
        "top.xml",
        model_with("<mesh name=\"other\" file=\"box.stl\"/>").as_bytes(),
    );
    load_error(&top, 7, "names mesh `m`, which no <mesh> in <asset> defines");
    let text =
        model_with("<mesh name=\"m\" file=\"box.stl\"/>").replace("mesh=\"m\"/>", "mesh=\"m\" shellinertia=\"true\"/>");
    let top = dir.write("top.xml", text.as_bytes());
    load_error(
        &top,
        7,
        "which MuJoCo refuses on a mesh geom; give the <mesh> inertia=\"shell\" instead",
    );
    // A box naming the box mesh is fitted to it: the same box (48 kg).
    let text = model_with("<mesh name=\"m\" file=\"box.stl\"/>").replace("type=\"mesh\"", "type=\"box\"");
    let top = dir.write("top.xml", text.as_bytes());
    assert!((load_mjcf(&top).unwrap().bodies[0].inertial.mass - 48.0).abs() < 1e-4);
    // Text without its file has no folder for the mesh file; an inline mesh needs none.
    let e = parse_mjcf(&model_with("<mesh name=\"m\" file=\"box.stl\"/>")).unwrap_err();
    assert!(
        e.to_string()
            .contains("line 3: robot: <mesh name=\"m\" file=\"box.stl\">: MJCF text read without its file"),
        "{e}"
    );
    let inline = "<mesh name=\"m\" vertex=\"0 0 0 1 0 0 0 1 0 0 0 1\"/>";
    let model = parse_mjcf(&model_with(inline)).unwrap();
    // The unit right tetrahedron: volume 1/6, centre at 1/4.
    let i = &model.bodies[0].inertial;
    assert!((i.mass - 1000.0 / 6.0).abs() < 1e-9, "{}", i.mass);
    assert!(i.com.iter().all(|c| (c - 0.25).abs() < 1e-12), "{:?}", i.com);
}

#[test]
fn maxhullvert_is_refused_only_where_it_stops_the_hull_that_gives_the_inertia() {
    // A wedge with its faces (6 distinct vertices) and the same vertices alone.
    let vertex = "0 0 0  0.2 0 0  0 0.3 0  0 0 0.1  0.2 0 0.1  0 0.3 0.1";
    let face = "0 2 1  3 4 5  0 1 4  0 4 3  1 2 5  1 5 4  2 0 3  2 3 5";
    let mass = |mesh: &str| parse_mjcf(&model_with(mesh)).map(|m| m.bodies[0].inertial.mass);
    let full = mass(&format!("<mesh name=\"m\" vertex=\"{vertex}\"/>")).unwrap();
    // 0.2 x 0.3 / 2 x 0.1 at 1000 kg/m³, in single precision.
    assert!((full - 3.0).abs() < 1e-6, "{full}");
    // The convex mode stopped early.
    let e = mass(&format!(
        "<mesh name=\"m\" vertex=\"{vertex}\" face=\"{face}\" inertia=\"convex\" maxhullvert=\"5\"/>"
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains(
            "line 3: robot: <mesh name=\"m\">: maxhullvert=\"5\" stops MuJoCo's convex hull (qhull, option TA1) at 5 \
             of its 6 distinct vertices, at the points qhull's own order of additions picks, which is not reproduced \
             here, and the hull gives its inertia (inertia=\"convex\"); remove maxhullvert or make it at least 6, \
             or choose another inertia"
        ),
        "{e}"
    );
    // Vertices alone: the hull's triangles are the faces, in every mode (MuJoCo's
    // default, legacy, here).
    let e = mass(&format!("<mesh name=\"m\" vertex=\"{vertex}\" maxhullvert=\"4\"/>"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(
            "line 3: robot: <mesh name=\"m\">: maxhullvert=\"4\" stops MuJoCo's convex hull (qhull, option TA0) at 4 \
             of its 6 distinct vertices, at the points qhull's own order of additions picks, which is not reproduced \
             here, and the hull's triangles are its faces (it has no `face`); remove maxhullvert or make it at least 6"
        ),
        "{e}"
    );
    // A limit qhull cannot reach, and a hull that gives no inertia (legacy with
    // faces: MuJoCo's hull is then for collisions only), change nothing.
    for mesh in [
        format!("<mesh name=\"m\" vertex=\"{vertex}\" maxhullvert=\"6\"/>"),
        format!("<mesh name=\"m\" vertex=\"{vertex}\" inertia=\"convex\" maxhullvert=\"40\"/>"),
        format!("<mesh name=\"m\" vertex=\"{vertex}\" face=\"{face}\" maxhullvert=\"4\"/>"),
        format!("<mesh name=\"m\" vertex=\"{vertex}\" face=\"{face}\" inertia=\"convex\" maxhullvert=\"-1\"/>"),
    ] {
        assert!((mass(&mesh).unwrap() - full).abs() < 1e-9, "{mesh}");
    }
    // MuJoCo's own bounds.
    for v in ["3", "0", "-2", "8.5", "many", ""] {
        let e = mass(&format!(
            "<mesh name=\"m\" vertex=\"{vertex}\" face=\"{face}\" maxhullvert=\"{v}\"/>"
        ))
        .unwrap_err()
        .to_string();
        assert!(
            e.contains(&format!(
                "line 3: robot: <mesh name=\"m\">: maxhullvert=\"{v}\" is neither -1 (no limit, the default) nor an \
                 integer above 3 (MuJoCo refuses it)"
            )),
            "{e}"
        );
    }
}

#[test]
fn a_mesh_in_an_included_file_is_read_from_the_models_folder() {
    let dir = TempDir::new("mesh-include");
    dir.write("meshes/box.stl", box_stl());
    dir.write(
        "parts/assets.xml",
        b"<mujoco>\n<asset>\n<mesh name=\"m\" file=\"meshes/box.stl\"/>\n<mesh name=\"n\" file=\"gone.stl\"/>\n</asset>\n</mujoco>\n",
    );
    let top = dir.write(
        "top.xml",
        b"<mujoco model=\"t\">\n<include file=\"parts/assets.xml\"/>\n<worldbody>\n<body name=\"b\"><joint name=\"j\"/>\n\
          <geom type=\"mesh\" mesh=\"m\"/>\n</body>\n</worldbody>\n</mujoco>\n",
    );
    let model = load_mjcf(&top).unwrap();
    // The box of sides 0.2, 0.4, 0.6.
    assert!((model.bodies[0].inertial.mass - 48.0).abs() < 1e-4);
    let text = std::fs::read_to_string(&top)
        .unwrap()
        .replace("mesh=\"m\"", "mesh=\"n\"");
    let top = dir.write("top.xml", text.as_bytes());
    let message = load_error(&top, 2, "cannot read `gone.stl`");
    assert!(
        message.contains("in `parts/assets.xml` line 4: <mesh name=\"n\" file=\"gone.stl\">"),
        "{message}"
    );
}

#[test]
fn assetdir_strippath_and_exactmeshinertia_are_read() {
    let dir = TempDir::new("mesh-compiler");
    dir.write("parts/box.stl", box_stl());
    let box_mass = |text: &str| {
        let top = dir.write("top.xml", text.as_bytes());
        let model = load_mjcf(&top).unwrap();
        (model.bodies[0].inertial.mass, model.warnings.len())
    };
    // `assetdir` is the mesh folder when `meshdir` is not given.
    let text =
        model_with("<mesh name=\"m\" file=\"box.stl\"/>").replace("<asset>", "<compiler assetdir=\"parts\"/><asset>");
    let (mass, warnings) = box_mass(&text);
    assert!((mass - 48.0).abs() < 1e-4 && warnings == 0, "{mass} {warnings}");
    // `strippath` drops the folders the file names.
    let text = model_with("<mesh name=\"m\" file=\"C:\\cad\\export\\box.stl\"/>")
        .replace("<asset>", "<compiler meshdir=\"parts\" strippath=\"true\"/><asset>");
    assert!((box_mass(&text).0 - 48.0).abs() < 1e-4);
    // MuJoCo 4 no longer reads `exactmeshinertia`: a warning, the mesh's own rule kept.
    let text = model_with("<mesh name=\"m\" file=\"box.stl\"/>").replace(
        "<asset>",
        "<compiler meshdir=\"parts\" exactmeshinertia=\"true\"/><asset>",
    );
    let top = dir.write("top.xml", text.as_bytes());
    let model = load_mjcf(&top).unwrap();
    assert_eq!(model.warnings.len(), 1);
    assert!(model.warnings[0]
        .to_string()
        .contains("<compiler exactmeshinertia=\"true\"> is not read"));
}
