//! Mass properties of MJCF mesh assets, as MuJoCo's compiler makes them
//! (`mjCMesh::Process` in MuJoCo's `user_mesh.cc`): the vertices as single-precision
//! numbers (what the files hold and MuJoCo keeps) moved by `refpos`, turned by
//! `refquat` and scaled by `scale`; then, by the mesh's `inertia`,
//!
//! - `legacy` (MuJoCo's default, "for backward compatibility"): the solid the
//!   triangles enclose with every tetrahedron's volume taken positive, which counts
//!   too much volume for a non-convex mesh,
//! - `convex` (the one MuJoCo recommends): the solid convex hull of the vertices,
//! - `exact`: the solid the triangles enclose (signed tetrahedra, so a closed,
//!   consistently oriented mesh of any shape),
//! - `shell`: a thin shell of unit surface density on the triangles.
//!
//! Volumes and centres are summed over pyramids from the area-weighted centroid of
//! the triangles, the second moments over tetrahedra from the centre of mass (or over
//! the triangles, for a shell), exactly as MuJoCo sums them, so the numbers agree to
//! rounding.

use crate::math::{self, Mat3, Vec3};

/// MuJoCo's `mjMINVAL`.
const MINVAL: f64 = 1e-15;

/// Largest mesh file read (MuJoCo reads at most 200,000 STL triangles, 10 MB).
pub(crate) const MAX_MESH_BYTES: u64 = 64 << 20;

/// The `inertia` attribute of a `<mesh>`.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum MeshInertia {
    Convex,
    Exact,
    Legacy,
    Shell,
}

impl MeshInertia {
    pub(crate) fn parse(value: &str) -> Option<MeshInertia> {
        match value {
            "convex" => Some(MeshInertia::Convex),
            "exact" => Some(MeshInertia::Exact),
            "legacy" => Some(MeshInertia::Legacy),
            "shell" => Some(MeshInertia::Shell),
            _ => None,
        }
    }
}

/// A triangle mesh: vertices and the vertex indices of each triangle
/// (counter-clockwise seen from outside).
#[derive(Clone, Debug, Default)]
pub(crate) struct TriMesh {
    pub vertices: Vec<Vec3>,
    pub faces: Vec<[usize; 3]>,
}

/// What a mesh gives a geom: its volume (its area for a shell), its centre of mass,
/// and the principal axes (columns) and moments per unit mass of its inertia about
/// that centre, in the mesh frame (after `refpos`, `refquat` and `scale`). The
/// moments are MuJoCo's: through the sides of the box of equal inertia
/// (`mjCMesh::Process`, `mjCGeom::SetInertia`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MeshMass {
    pub measure: f64,
    pub com: Vec3,
    pub axes: Mat3,
    pub moments: Vec3,
    /// The half sides of the box of equal inertia (MuJoCo's `boxsz`), along `axes`.
    pub box_half: Vec3,
    /// What a primitive fitted to the mesh's bounding box takes from it.
    pub aabb: AabbFit,
}

/// The axis-aligned bounding box of a mesh's vertices in its principal frame (the
/// frame of `com` and `axes`, MuJoCo's `aamm`), which a primitive geom is fitted to
/// with `<compiler fitaabb="true">`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AabbFit {
    /// The box's centre, in the principal frame.
    pub center: Vec3,
    /// The box's half sides.
    pub half: Vec3,
}

impl AabbFit {
    /// The box of `vertices` (mesh frame) moved to the principal frame of centre
    /// `com` and axes `axes`, as MuJoCo moves them (`v' = axesᵀ (v - com)`).
    fn of(vertices: &[Vec3], com: &Vec3, axes: &Mat3) -> AabbFit {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for v in vertices {
            let v = math::mat_vec(&math::transpose(axes), &math::sub(v, com));
            for i in 0..3 {
                lo[i] = lo[i].min(v[i]);
                hi[i] = hi[i].max(v[i]);
            }
        }
        let center = [0, 1, 2].map(|i| (lo[i] + hi[i]) / 2.0);
        AabbFit {
            center,
            half: [0, 1, 2].map(|i| hi[i] - center[i]),
        }
    }
}

/// Reads a binary STL file as MuJoCo does (`mjCMesh::LoadSTL`): 1 to 200,000
/// triangles and a size of `84 + 50 n` bytes; an ASCII STL file is refused, as
/// MuJoCo refuses it. `flip` reverses the triangles (a mirroring `scale`).
pub(crate) fn read_stl(bytes: &[u8], flip: bool) -> Result<TriMesh, String> {
    if bytes.is_empty() {
        return Err("the file is empty".into());
    }
    let count = (bytes.len() >= 84).then(|| u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize);
    let binary = matches!(count, Some(n) if (1..=200_000).contains(&n) && bytes.len() == 84 + 50 * n);
    if !binary {
        let text = bytes
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .map_or(&[][..], |i| &bytes[i..]);
        if text.starts_with(b"solid") && stl_io::read_stl(&mut std::io::Cursor::new(bytes)).is_ok() {
            return Err(
                "it is an ASCII STL file, which MuJoCo does not read (it reads binary STL only); \
                 convert it to binary STL"
                    .into(),
            );
        }
        return Err(match count {
            None => "it is shorter than the 84-byte header of a binary STL file".into(),
            Some(n) if !(1..=200_000).contains(&n) => {
                format!("its header counts {n} triangles, not 1 to 200000 (MuJoCo's limits) of a binary STL file")
            }
            Some(n) => format!(
                "its header counts {n} triangles, which take {} bytes, but the file has {}; it is not a binary STL \
                 file",
                84 + 50 * n,
                bytes.len()
            ),
        });
    }
    // The 80-byte header is free text: blank it, so that a header starting with
    // `solid` is not taken for ASCII.
    let mut copy = bytes.to_vec();
    copy[..80].fill(b' ');
    let mesh = stl_io::read_stl(&mut std::io::Cursor::new(copy)).map_err(|e| format!("it is not binary STL: {e}"))?;
    let mut out = TriMesh {
        vertices: Vec::with_capacity(mesh.vertices.len()),
        faces: Vec::with_capacity(mesh.faces.len()),
    };
    for v in &mesh.vertices {
        let p = v.0.map(f64::from);
        if p.iter().any(|x| !x.is_finite()) {
            return Err("it has a vertex that is not a finite number".into());
        }
        if p.iter().any(|x| x.abs() > (1u64 << 30) as f64) {
            return Err("it has a vertex coordinate beyond 2^30 (MuJoCo's bound)".into());
        }
        out.vertices.push(p);
    }
    for f in &mesh.faces {
        let [a, b, c] = f.vertices;
        out.faces.push(if flip { [a, c, b] } else { [a, b, c] });
    }
    Ok(out)
}

/// Reads a Wavefront OBJ file as MuJoCo does (`mjCMesh::LoadOBJ`, with
/// tinyobjloader): the faces of its first object, each a triangle or a quadrilateral
/// (split into `0 1 2`, `0 2 3`); the vertices of all objects (they all enter the
/// convex hull). `flip` reverses the triangles.
pub(crate) fn read_obj(bytes: &[u8], flip: bool) -> Result<TriMesh, String> {
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = tobj::load_obj_buf(&mut std::io::Cursor::new(bytes), &options, |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| format!("it is not a readable OBJ file: {e}"))?;
    let Some(first) = models.first().filter(|m| !m.mesh.indices.is_empty()) else {
        return Err(
            "it has no faces (`f` lines); MuJoCo would take the convex hull of its vertices as the mesh, \
                    which is not read here: give the faces"
                .into(),
        );
    };
    let mut out = TriMesh::default();
    let mut offsets = Vec::with_capacity(models.len());
    for m in &models {
        offsets.push(out.vertices.len());
        for p in m.mesh.positions.chunks_exact(3) {
            let p = [p[0], p[1], p[2]].map(f64::from);
            if p.iter().any(|x| !x.is_finite()) {
                return Err("it has a vertex that is not a finite number".into());
            }
            out.vertices.push(p);
        }
    }
    let mesh = &first.mesh;
    let index = |k: usize| mesh.indices[k] as usize + offsets[0];
    let arities: Vec<usize> = if mesh.face_arities.is_empty() {
        vec![3; mesh.indices.len() / 3]
    } else {
        mesh.face_arities.iter().map(|&n| n as usize).collect()
    };
    let mut k = 0;
    for (n, &arity) in arities.iter().enumerate() {
        if !(3..=4).contains(&arity) || k + arity > mesh.indices.len() {
            return Err(format!(
                "face {} has {arity} vertices; MuJoCo reads OBJ faces of 3 or 4 vertices only",
                n + 1
            ));
        }
        let mut push = |a: usize, b: usize, c: usize| {
            let t = [index(k + a), index(k + b), index(k + c)];
            out.faces.push(if flip { [t[0], t[2], t[1]] } else { t });
        };
        push(0, 1, 2);
        if arity == 4 {
            push(0, 2, 3);
        }
        k += arity;
    }
    if out.faces.iter().flatten().any(|&i| i >= out.vertices.len()) {
        return Err("a face names a vertex the file does not have".into());
    }
    Ok(out)
}

/// MuJoCo's `triangle`: area, unit normal and centre of a triangle (area 0 and no
/// normal for a degenerate one).
fn triangle(a: &Vec3, b: &Vec3, c: &Vec3) -> (f64, Vec3, Vec3) {
    let center = [0, 1, 2].map(|i| (a[i] + b[i] + c[i]) / 3.0);
    let n = cross(&math::sub(b, a), &math::sub(c, a));
    let len = math::dot(&n, &n).sqrt();
    if len < MINVAL {
        return (0.0, [0.0; 3], center);
    }
    (0.5 * len, n.map(|x| x / len), center)
}

fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The triangles of the convex hull of `vertices`, counter-clockwise seen from
/// outside: quickhull (each point outside a face waits on it until the farthest is
/// added), with Shewchuk's exact orientation test (a point on a face's plane is not
/// outside it), so the hull is exact for any input. MuJoCo builds the hull with
/// qhull; another triangulation of the same hull gives the same integrals to
/// rounding.
pub(crate) fn convex_hull(vertices: &[Vec3]) -> Result<Vec<[usize; 3]>, String> {
    let at = |i: usize| robust::Coord3D {
        x: vertices[i][0],
        y: vertices[i][1],
        z: vertices[i][2],
    };
    // > 0: `d` below the plane of `a b c` (counter-clockwise seen from above).
    let orient = |a: usize, b: usize, c: usize, d: usize| robust::orient3d(at(a), at(b), at(c), at(d));
    // Each distinct point once.
    let mut seen = std::collections::HashSet::new();
    let points: Vec<usize> = (0..vertices.len())
        .filter(|&i| seen.insert(vertices[i].map(f64::to_bits)))
        .collect();
    if points.len() < 4 {
        return Err(format!(
            "its convex hull needs at least 4 distinct vertices, and it has {}",
            points.len()
        ));
    }
    let collinear = |a: usize, b: usize, c: usize| {
        let plane = |i: usize, j: usize| {
            let p = |k: usize| robust::Coord {
                x: vertices[k][i],
                y: vertices[k][j],
            };
            robust::orient2d(p(a), p(b), p(c)) == 0.0
        };
        plane(0, 1) && plane(1, 2) && plane(2, 0)
    };
    let (a, b) = (points[0], points[1]);
    let flat = || "its vertices are all in one plane: no convex hull with a volume".to_string();
    let c = *points[2..].iter().find(|&&c| !collinear(a, b, c)).ok_or_else(flat)?;
    let d = *points[2..]
        .iter()
        .find(|&&d| d != c && orient(a, b, c, d) != 0.0)
        .ok_or_else(flat)?;
    // The first tetrahedron, each face turned so that the fourth vertex is inside.
    struct Face {
        v: [usize; 3],
        /// Points strictly outside this face, not yet on the hull.
        outside: Vec<usize>,
        alive: bool,
    }
    let mut faces: Vec<Face> = [[a, b, c, d], [a, b, d, c], [a, c, d, b], [b, c, d, a]]
        .iter()
        .map(|&[p, q, r, inside]| Face {
            v: if orient(p, q, r, inside) > 0.0 {
                [p, q, r]
            } else {
                [p, r, q]
            },
            outside: Vec::new(),
            alive: true,
        })
        .collect();
    let sides = |v: [usize; 3]| [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])];
    // Each directed edge of the hull, with its face.
    let mut edge: std::collections::HashMap<(usize, usize), usize> = std::collections::HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        for e in sides(f.v) {
            edge.insert(e, i);
        }
    }
    // Quickhull: each point waits on one face it is strictly outside of; a point
    // outside no face is on or in the hull and is dropped.
    for &p in &points {
        if [a, b, c, d].contains(&p) {
            continue;
        }
        if let Some(f) = faces.iter_mut().find(|f| orient(f.v[0], f.v[1], f.v[2], p) < 0.0) {
            f.outside.push(p);
        }
    }
    let mut pending: Vec<usize> = (0..4).collect();
    while let Some(start) = pending.pop() {
        if !faces[start].alive || faces[start].outside.is_empty() {
            continue;
        }
        // The farthest point outside this face.
        let v = faces[start].v;
        let p = faces[start]
            .outside
            .iter()
            .copied()
            .min_by(|&x, &y| orient(v[0], v[1], v[2], x).total_cmp(&orient(v[0], v[1], v[2], y)))
            .unwrap_or(usize::MAX);
        // The faces it sees, connected, from this one.
        let mut visible = vec![start];
        let mut looked = std::collections::HashSet::from([start]);
        let mut k = 0;
        while k < visible.len() {
            for (u, w) in sides(faces[visible[k]].v) {
                let next = edge[&(w, u)];
                if looked.insert(next) {
                    let g = faces[next].v;
                    if orient(g[0], g[1], g[2], p) < 0.0 {
                        visible.push(next);
                    }
                }
            }
            k += 1;
        }
        let seen: std::collections::HashSet<usize> = visible.iter().copied().collect();
        // The horizon: edges of visible faces whose other face is not visible.
        let mut horizon = Vec::new();
        let mut orphans = Vec::new();
        for &f in &visible {
            for (u, w) in sides(faces[f].v) {
                if !seen.contains(&edge[&(w, u)]) {
                    horizon.push((u, w));
                }
            }
            faces[f].alive = false;
            orphans.append(&mut faces[f].outside);
        }
        for &f in &visible {
            for e in sides(faces[f].v) {
                edge.remove(&e);
            }
        }
        // The cone from the point to the horizon.
        let first = faces.len();
        for &(u, w) in &horizon {
            let i = faces.len();
            faces.push(Face {
                v: [u, w, p],
                outside: Vec::new(),
                alive: true,
            });
            for e in sides([u, w, p]) {
                edge.insert(e, i);
            }
        }
        for q in orphans.into_iter().filter(|&q| q != p) {
            if let Some(f) = faces[first..]
                .iter_mut()
                .find(|f| orient(f.v[0], f.v[1], f.v[2], q) < 0.0)
            {
                f.outside.push(q);
            }
        }
        pending.extend(first..faces.len());
    }
    Ok(faces.into_iter().filter(|f| f.alive).map(|f| f.v).collect())
}

/// How many distinct points `vertices` holds (`-0` and `0` the same coordinate).
pub(crate) fn distinct_points(vertices: &[Vec3]) -> usize {
    vertices
        .iter()
        .map(|v| v.map(|x| (x + 0.0).to_bits()))
        .collect::<std::collections::HashSet<_>>()
        .len()
}

/// The mesh moved by `refpos`, turned by `refquat` (`w x y z`, normalised) and scaled
/// by `scale`, in MuJoCo's order (`mjCMesh::ApplyTransformations`).
pub(crate) fn transform(mesh: &mut TriMesh, refpos: Vec3, refquat: [f64; 4], scale: Vec3) {
    if refpos != [0.0; 3] {
        for v in &mut mesh.vertices {
            *v = math::sub(v, &refpos);
        }
    }
    if refquat != [1.0, 0.0, 0.0, 0.0] {
        let n = refquat.iter().map(|x| x * x).sum::<f64>().sqrt();
        let r = math::quaternion_to_matrix(refquat.map(|x| x / n));
        for v in &mut mesh.vertices {
            *v = math::mat_vec(&math::transpose(&r), v);
        }
    }
    if scale != [1.0; 3] {
        for v in &mut mesh.vertices {
            *v = [v[0] * scale[0], v[1] * scale[1], v[2] * scale[2]];
        }
    }
}

/// Volume (or area), centre of mass and unit-density inertia of a transformed mesh,
/// as `mjCMesh::Process` computes them, or why MuJoCo refuses the mesh. `hull`: the
/// faces of its convex hull, for [`MeshInertia::Convex`].
pub(crate) fn mass_properties(
    mesh: &TriMesh,
    mode: MeshInertia,
    hull: Option<&[[usize; 3]]>,
) -> Result<MeshMass, String> {
    let v = &mesh.vertices;
    let tri = |f: &[usize; 3]| triangle(&v[f[0]], &v[f[1]], &v[f[2]]);
    // The area-weighted centroid of the triangles: the apex of the pyramids.
    let mut facecen = [0.0; 3];
    let mut area = 0.0;
    for f in &mesh.faces {
        let (a, _, c) = tri(f);
        facecen = math::add(&facecen, &math::scale(a, &c));
        area += a;
    }
    if area < MINVAL {
        return Err("its surface area is too small (MuJoCo refuses it)".into());
    }
    facecen = facecen.map(|x| x / area);
    let faces: &[[usize; 3]] = match (mode, hull) {
        (MeshInertia::Convex, Some(h)) => h,
        _ => &mesh.faces,
    };
    // Volume (or area) and centre of mass.
    let mut com = [0.0; 3];
    let mut measure = 0.0;
    for f in if mode == MeshInertia::Shell {
        &mesh.faces[..]
    } else {
        faces
    } {
        let (a, n, c) = tri(f);
        let mut w = match mode {
            MeshInertia::Shell => a,
            _ => math::dot(&math::sub(&c, &facecen), &n) * a / 3.0,
        };
        if mode == MeshInertia::Legacy {
            w = w.abs();
        }
        measure += w;
        for j in 0..3 {
            com[j] += w * (c[j] * 3.0 / 4.0 + facecen[j] / 4.0);
        }
    }
    if measure < MINVAL {
        return Err(match mode {
            MeshInertia::Shell => "its surface area is too small (MuJoCo refuses it)".into(),
            _ if measure < 0.0 => format!(
                "its volume is negative ({measure:e}): the triangles are oriented inwards (MuJoCo refuses it); \
                 orient them counter-clockwise seen from outside"
            ),
            _ => format!(
                "its volume is zero or too small ({measure:e}; MuJoCo refuses it); a flat or open mesh has no \
                 volume: give the <mesh> inertia=\"shell\", or the geom a mass of 0"
            ),
        });
    }
    com = com.map(|x| x / measure);
    // Second moments about the centre of mass.
    let k = [[0, 0], [1, 1], [2, 2], [0, 1], [0, 2], [1, 2]];
    let mut p = [0.0; 6];
    let mut total = 0.0;
    let faces = if mode == MeshInertia::Shell {
        &mesh.faces[..]
    } else {
        faces
    };
    for f in faces {
        let [d, e, g] = f.map(|i| math::sub(&v[i], &com));
        let (a, n, c) = triangle(&d, &e, &g);
        let mut w = match mode {
            MeshInertia::Shell => a,
            _ => math::dot(&c, &n) * a / 3.0,
        };
        if mode == MeshInertia::Legacy {
            w = w.abs();
        }
        total += w;
        let denominator = if mode == MeshInertia::Shell { 12.0 } else { 20.0 };
        for (pj, [r, s]) in p.iter_mut().zip(k) {
            *pj += w / denominator
                * (2.0 * (d[r] * d[s] + e[r] * e[s] + g[r] * g[s])
                    + d[r] * e[s]
                    + d[s] * e[r]
                    + d[r] * g[s]
                    + d[s] * g[r]
                    + e[r] * g[s]
                    + e[s] * g[r]);
        }
    }
    let inertia = [
        [p[1] + p[2], -p[3], -p[4]],
        [-p[3], p[0] + p[2], -p[5]],
        [-p[4], -p[5], p[0] + p[1]],
    ];
    let (ev, quat) = eig3(&inertia);
    let axes = math::quaternion_to_matrix(quat);
    if ev[2] <= 0.0 {
        return Err("an eigenvalue of its inertia is not positive (MuJoCo refuses it)".into());
    }
    // MuJoCo's tolerances on A + B >= C.
    let (rtol, atol) = (1e-6, 1e-9);
    let broken = |a: f64, b: f64, c: f64| a + b < c * (1.0 - rtol) - atol;
    if broken(ev[0], ev[1], ev[2]) || broken(ev[0], ev[2], ev[1]) || broken(ev[1], ev[2], ev[0]) {
        return Err("the principal moments of its inertia break A + B >= C (MuJoCo refuses it)".into());
    }
    // The box of equal inertia, and its moments per unit mass.
    let side = |a: f64, b: f64, c: f64| 0.5 * (6.0 * (b + c - a) / total).sqrt();
    let b = [
        side(ev[0], ev[1], ev[2]),
        side(ev[1], ev[0], ev[2]),
        side(ev[2], ev[0], ev[1]),
    ];
    let moments = [
        (b[1] * b[1] + b[2] * b[2]) / 3.0,
        (b[0] * b[0] + b[2] * b[2]) / 3.0,
        (b[0] * b[0] + b[1] * b[1]) / 3.0,
    ];
    Ok(MeshMass {
        measure: total,
        com,
        axes,
        moments,
        box_half: b,
        aabb: AabbFit::of(v, &com, &axes),
    })
}

/// MuJoCo's eigen decomposition of a symmetric 3x3 matrix (`mjuu_eig3`, Jacobi
/// rotations accumulated in a quaternion until the largest off-diagonal element is
/// below 1e-12 or the rotation's cosine above 1 - 1e-12; eigenvalues in decreasing
/// order): the eigenvalues and the quaternion (`w x y z`) whose rotation has the
/// eigenvectors as columns. Ported rather than replaced by an exact decomposition
/// because its stopping rule shows in MuJoCo's inertias (up to ~1e-9 relative: the
/// off-diagonal remainder it leaves out).
pub(crate) fn eig3(mat: &Mat3) -> (Vec3, [f64; 4]) {
    const EPS: f64 = 1e-12;
    let normalize = |q: [f64; 4]| {
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.map(|x| x / n)
    };
    let mul = |a: [f64; 4], b: [f64; 4]| {
        [
            a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
        ]
    };
    let mut quat = [1.0, 0.0, 0.0, 0.0];
    let mut eigval = [0.0; 3];
    for _ in 0..500 {
        let v = math::quaternion_to_matrix(quat);
        let d = math::mat_mul(&math::mat_mul(&math::transpose(&v), mat), &v);
        eigval = [d[0][0], d[1][1], d[2][2]];
        let (rk, ck, rotk) = if d[0][1].abs() > d[0][2].abs() && d[0][1].abs() > d[1][2].abs() {
            (0, 1, 2)
        } else if d[0][2].abs() > d[1][2].abs() {
            (0, 2, 1)
        } else {
            (1, 2, 0)
        };
        if d[rk][ck].abs() < EPS {
            break;
        }
        let tau = (d[ck][ck] - d[rk][rk]) / (2.0 * d[rk][ck]);
        let t = if tau >= 0.0 {
            1.0 / (tau + (1.0 + tau * tau).sqrt())
        } else {
            -1.0 / (-tau + (1.0 + tau * tau).sqrt())
        };
        let c = 1.0 / (1.0 + t * t).sqrt();
        if c > 1.0 - EPS {
            break;
        }
        let mut rot = [0.0; 4];
        let s = (0.5 - 0.5 * c).sqrt();
        rot[rotk + 1] = if tau >= 0.0 { -s } else { s };
        if rotk == 1 {
            rot[rotk + 1] = -rot[rotk + 1];
        }
        rot[0] = (1.0 - rot[rotk + 1] * rot[rotk + 1]).sqrt();
        quat = normalize(mul(quat, normalize(rot)));
    }
    // Decreasing order (bubble sort: 0, 1, 0), each swap a quarter turn.
    for j in 0..3 {
        let j1 = j % 2;
        if eigval[j1] + EPS < eigval[j1 + 1] {
            eigval.swap(j1, j1 + 1);
            // MuJoCo's literal, one digit short of 1/√2.
            #[allow(clippy::approx_constant)]
            let mut rot = [0.707106781186548, 0.0, 0.0, 0.0];
            rot[(j1 + 2) % 3 + 1] = rot[0];
            quat = normalize(mul(quat, rot));
        }
    }
    (eigval, quat)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(lo: f64, hi: f64) -> TriMesh {
        let v = |x: usize, y: usize, z: usize| [[lo, hi][x], [lo, hi][y], [lo, hi][z]];
        TriMesh {
            vertices: vec![
                v(0, 0, 0),
                v(1, 0, 0),
                v(1, 1, 0),
                v(0, 1, 0),
                v(0, 0, 1),
                v(1, 0, 1),
                v(1, 1, 1),
                v(0, 1, 1),
            ],
            faces: vec![
                [0, 2, 1],
                [0, 3, 2],
                [4, 5, 6],
                [4, 6, 7],
                [0, 1, 5],
                [0, 5, 4],
                [1, 2, 6],
                [1, 6, 5],
                [2, 3, 7],
                [2, 7, 6],
                [3, 0, 4],
                [3, 4, 7],
            ],
        }
    }

    #[test]
    fn a_cube_has_its_textbook_mass_properties_in_every_mode() {
        let mesh = cube(1.0, 3.0);
        let hull = convex_hull(&mesh.vertices).unwrap();
        assert_eq!(hull.len(), 12);
        for mode in [MeshInertia::Convex, MeshInertia::Exact, MeshInertia::Legacy] {
            let m = mass_properties(&mesh, mode, Some(&hull)).unwrap();
            assert!((m.measure - 8.0).abs() < 1e-12);
            assert!(m.com.iter().all(|c| (c - 2.0).abs() < 1e-12));
            // (a² + b²) / 12 per unit mass with sides 2.
            assert!(
                m.moments.iter().all(|i| (i - 8.0 / 12.0).abs() < 1e-12),
                "{:?}",
                m.moments
            );
        }
        let shell = mass_properties(&mesh, MeshInertia::Shell, None).unwrap();
        assert!((shell.measure - 24.0).abs() < 1e-12);
    }

    #[test]
    fn eig3_diagonalises_in_decreasing_order_as_mujoco_stops() {
        let m = [[2.0, 0.3, -0.1], [0.3, 1.0, 0.2], [-0.1, 0.2, 3.0]];
        let (ev, q) = eig3(&m);
        // MuJoCo 4.0.0's mju_eig3 on the same matrix.
        let mujoco = [3.02480578, 2.08117089, 0.89402333];
        assert!(ev.iter().zip(mujoco).all(|(a, b)| (a - b).abs() < 1e-8), "{ev:?}");
        // Diagonal up to what the last rotation not taken would remove (a cosine
        // above 1 - 1e-12: an angle below 1.5e-6).
        let r = math::quaternion_to_matrix(q);
        let d = math::mat_mul(&math::mat_mul(&math::transpose(&r), &m), &r);
        for i in 0..3 {
            assert!((d[i][i] - ev[i]).abs() < 1e-13, "{d:?}");
            for j in (0..3).filter(|&j| j != i) {
                assert!(d[i][j].abs() < 1.5e-6, "{d:?}");
            }
        }
    }

    #[test]
    fn the_hull_of_points_on_a_sphere_has_them_all_and_not_its_centre() {
        // Points on the unit sphere (a spiral) and its centre.
        let n = 2000;
        let mut points: Vec<Vec3> = (0..n)
            .map(|i| {
                let z = 1.0 - (2 * i + 1) as f64 / n as f64;
                let r = (1.0 - z * z).sqrt();
                let a = i as f64 * 2.399963229728653;
                [r * a.cos(), r * a.sin(), z]
            })
            .collect();
        points.push([0.0; 3]);
        let start = std::time::Instant::now();
        let hull = convex_hull(&points).unwrap();
        eprintln!("hull of {} points: {:?}", points.len(), start.elapsed());
        // Euler: a triangulated sphere of n vertices has 2n - 4 triangles.
        assert_eq!(hull.len(), 2 * n - 4);
        assert!(hull.iter().flatten().all(|&i| i < n));
        // Closed and consistently oriented: every edge once in each direction.
        let edges: std::collections::HashSet<(usize, usize)> = hull
            .iter()
            .flat_map(|f| [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])])
            .collect();
        assert_eq!(edges.len(), 3 * hull.len());
        assert!(edges.iter().all(|&(a, b)| edges.contains(&(b, a))));
        let mesh = TriMesh {
            vertices: points,
            faces: hull.clone(),
        };
        let m = mass_properties(&mesh, MeshInertia::Exact, None).unwrap();
        assert!(
            (m.measure - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.02,
            "{}",
            m.measure
        );
    }

    #[test]
    fn inward_triangles_have_a_negative_volume() {
        let mut mesh = cube(0.0, 1.0);
        for f in &mut mesh.faces {
            f.swap(1, 2);
        }
        let e = mass_properties(&mesh, MeshInertia::Exact, None).unwrap_err();
        assert!(e.contains("negative"), "{e}");
        // The hull does not care.
        let hull = convex_hull(&mesh.vertices).unwrap();
        assert!(mass_properties(&mesh, MeshInertia::Convex, Some(&hull)).is_ok());
    }
}
