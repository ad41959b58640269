//! Triangle meshes: OBJ, PLY and Mitsuba serialized files, and whether a triangle set is closed
//! (needed for a medium inside it).
//!
//! Each file format reads into a [`RawMesh`] (`raw`): `obj` (through tobj), [`ply`] and
//! [`serialized`]. A new format is a file here and one arm in `load_mesh`'s match on the
//! extension; what follows (transform, normals, texture coordinates, closedness) is shared.

mod obj;
pub mod ply;
mod raw;
pub mod serialized;

use foton_core::error::Result;
use foton_core::geometry::{Shape, TriangleAttrs};
use foton_core::props::Properties;
use glam::{Mat3, Mat4, Vec2, Vec3};
pub use raw::RawMesh;
use rayon::prelude::*;
use std::io::Read;
use std::path::Path;

/// How a mesh is shaded (Mitsuba's `face_normals` and the OBJ reader's `flip_tex_coords`).
#[derive(Clone, Copy, Debug)]
pub struct MeshOptions {
    /// Shade with the triangles' own normals, ignoring vertex normals.
    pub face_normals: bool,
    /// Texture coordinates count v from the top: v = 1 - v (Mitsuba's default for OBJ; for
    /// PLY only when the scene gives it).
    pub flip_tex_coords: bool,
    /// Turn the mesh inside out: reversed triangles, negated vertex normals.
    pub flip_normals: bool,
    /// Without vertex normals of its own (the file's, or `normals`), compute smooth ones
    /// (Mitsuba's way); false: shade with the triangles' own normals (pbrt-v4's way).
    pub compute_normals: bool,
}

/// A mesh in the scene: its triangles, their attributes (empty, or one per triangle) and
/// their corners, from which [`Mesh::closed`] tells whether it is closed.
pub struct Mesh {
    pub triangles: Vec<Shape>,
    pub attrs: Vec<TriangleAttrs>,
    /// The mesh attribute at each triangle's corners (empty, or one per triangle), if the
    /// scene asked for one.
    pub attribute: Vec<[Vec3; 3]>,
    /// The triangles' corners as the file gives them (after the transform): closedness
    /// compares positions bit for bit, which corners rebuilt from `triangles` would not keep.
    pub corners: Vec<[Vec3; 3]>,
    /// How many of the file's triangles had zero area and were left out (Mitsuba keeps them,
    /// but nothing can hit them; 0.6 warns about them), for a note.
    pub dropped: usize,
}

impl Mesh {
    /// Whether the mesh is closed ([`is_closed`]). Asked only of meshes that may bound a
    /// medium: at a million triangles it costs a sixth of the load.
    pub fn closed(&self) -> bool {
        is_closed(&self.corners)
    }
}

/// The mesh file `path` of shape `s` in the scene: OBJ or PLY by its extension, Mitsuba
/// serialized by its extension or its first bytes (mesh number `shape_index` of `s`, default 0),
/// with the mesh attribute named `attribute` (which only a PLY file carries).
pub(super) fn load_mesh(
    s: &Properties<'_>,
    path: &Path,
    transform: Mat4,
    options: MeshOptions,
    attribute: Option<&str>,
) -> Result<Mesh> {
    let fail = |message: String| s.error("file", format!("{}: {message}", path.display()));
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let raw = match extension.as_deref() {
        Some("obj") => {
            let mut raw = obj::read(open(s, path)?).map_err(fail)?;
            if options.flip_tex_coords {
                for uv in &mut raw.uvs {
                    uv.y = 1.0 - uv.y;
                }
            }
            raw
        }
        Some("ply") | Some("gz") => {
            let mut bytes = read_all(s, path)?;
            if extension.as_deref() == Some("gz") {
                // pbrt-v4 reads `.ply.gz` files (gzip-compressed PLY).
                let inner = path.file_stem().map(Path::new).and_then(Path::extension);
                if !inner.is_some_and(|e| e.eq_ignore_ascii_case("ply")) {
                    return Err(s.error(
                        "file",
                        format!(
                            "mesh {}: unknown mesh format; a compressed mesh must be a .ply.gz",
                            path.display()
                        ),
                    ));
                }
                let mut plain = Vec::new();
                flate2::read::GzDecoder::new(&bytes[..])
                    .read_to_end(&mut plain)
                    .map_err(|e| fail(format!("cannot decompress: {e}")))?;
                bytes = plain;
            }
            let mut raw = ply::parse(&bytes).map_err(fail)?;
            if let Some(name) = attribute {
                raw.attribute = ply::attribute(&bytes, name).map_err(fail)?;
                if raw.attribute.is_none() {
                    let names = ply::attribute_names(&bytes);
                    return Err(fail(format!(
                        "the material reads the mesh attribute `{name}`, which the file does not have ({})",
                        if names.is_empty() {
                            "it has none".to_string()
                        } else {
                            format!("it has {}", names.join(", "))
                        }
                    )));
                }
            }
            // A PLY's texture coordinates are flipped only when the scene says so (Mitsuba 3's
            // default for PLY, unlike OBJ).
            if options.flip_tex_coords && s.has("flip_tex_coords") {
                for uv in &mut raw.uvs {
                    uv.y = 1.0 - uv.y;
                }
            }
            raw
        }
        _ => {
            let bytes = read_all(s, path)?;
            // Mitsuba reads a `serialized` shape's file whatever its name.
            if extension.as_deref() != Some("serialized") && !serialized::is_serialized(&bytes) {
                return Err(s.error(
                    "file",
                    format!(
                        "mesh {}: unknown mesh format; expected a file ending in .obj or .ply, or a Mitsuba serialized mesh (.serialized)",
                        path.display()
                    ),
                ));
            }
            serialized::parse(&bytes, s.u32("shape_index", 0)?).map_err(fail)?
        }
    };
    if let (Some(name), None) = (attribute, &raw.attribute) {
        return Err(fail(format!(
            "the material reads the mesh attribute `{name}`: foton reads mesh attributes from PLY files only"
        )));
    }
    let options = MeshOptions {
        face_normals: if s.has("face_normals") {
            options.face_normals
        } else {
            options.face_normals || raw.face_normals
        },
        ..options
    };
    let crease = s.f32_opt("max_smooth_angle")?;
    if crease.is_some() && options.face_normals {
        return Err(s.error(
            "max_smooth_angle",
            "`max_smooth_angle` and `face_normals` both: Mitsuba refuses the pair (smooth normals within an angle, or none)",
        ));
    }
    let mesh = triangles(raw, transform, options, crease).map_err(fail)?;
    // A mesh of zero-area triangles only is invisible, and Mitsuba opens it; as an emitter it
    // would be a light of no area.
    if mesh.triangles.is_empty() && s.has("emission") {
        return Err(fail(format!(
            "an emitting mesh with no triangle of non-zero area ({} of zero area)",
            mesh.dropped
        )));
    }
    Ok(mesh)
}

/// A mesh written in the scene itself (`positions`, `indices`, optional `normals` and
/// `uvs`, flat lists: 3 numbers a vertex, 3 indices a triangle, 2 numbers a texture
/// coordinate), as a file's mesh would be read.
pub(super) fn inline_mesh(
    s: &Properties<'_>,
    transform: Mat4,
    options: MeshOptions,
) -> Result<Mesh> {
    let numbers = |name: &str| -> Result<Option<Vec<f32>>> {
        let Some(node) = s.node(name) else {
            return Ok(None);
        };
        let foton_core::value::Value::Array(items) = &node.value else {
            return Err(s.error(name, "expected an array of numbers"));
        };
        items
            .iter()
            .map(|n| {
                n.value
                    .as_f64()
                    .map(|x| x as f32)
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        s.error(
                            name,
                            format!("expected finite numbers, found `{}`", n.value.show()),
                        )
                    })
            })
            .collect::<Result<Vec<_>>>()
            .map(Some)
    };
    let positions = numbers("positions")?.ok_or_else(|| {
        s.error(
            "positions",
            "missing: a mesh needs `file` or `positions` and `indices`",
        )
    })?;
    if positions.len() % 3 != 0 {
        return Err(s.error(
            "positions",
            format!("{} numbers: not 3 per vertex", positions.len()),
        ));
    }
    let n = positions.len() / 3;
    let Some(indices) = s.node("indices") else {
        return Err(s.error(
            "indices",
            "missing: the triangles' vertex indices, 3 a triangle",
        ));
    };
    let foton_core::value::Value::Array(items) = &indices.value else {
        return Err(s.error("indices", "expected an array of integers"));
    };
    let mut flat = Vec::with_capacity(items.len());
    for item in items {
        match item.value {
            foton_core::value::Value::Int(i) if i >= 0 && (i as usize) < n => flat.push(i as u32),
            _ => {
                return Err(s.error(
                    "indices",
                    format!(
                        "`{}`: expected an integer in 0..{n} (the vertices)",
                        item.value.show()
                    ),
                ));
            }
        }
    }
    if flat.len() % 3 != 0 {
        return Err(s.error(
            "indices",
            format!("{} indices: not 3 per triangle", flat.len()),
        ));
    }
    let tris: Vec<[u32; 3]> = flat.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
    let mut raw = RawMesh {
        positions: positions
            .chunks(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect(),
        triangles: tris.clone(),
        ..RawMesh::default()
    };
    if let Some(normals) = numbers("normals")? {
        if normals.len() != positions.len() {
            return Err(s.error(
                "normals",
                format!(
                    "{} numbers for {n} vertices: expected 3 per vertex",
                    normals.len()
                ),
            ));
        }
        raw.normals = normals
            .chunks(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect();
        raw.normal_triangles = tris.clone();
    }
    if let Some(uvs) = numbers("uvs")? {
        if uvs.len() != 2 * n {
            return Err(s.error(
                "uvs",
                format!(
                    "{} numbers for {n} vertices: expected 2 per vertex",
                    uvs.len()
                ),
            ));
        }
        raw.uvs = uvs.chunks(2).map(|p| Vec2::new(p[0], p[1])).collect();
        raw.uv_triangles = tris;
    }
    triangles(raw, transform, options, None).map_err(|m| s.error("positions", m))
}

fn read_all(s: &Properties<'_>, path: &Path) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    open(s, path)?
        .read_to_end(&mut bytes)
        .map_err(|e| s.error("file", format!("{}: cannot read: {e}", path.display())))?;
    Ok(bytes)
}

fn open(s: &Properties<'_>, path: &Path) -> Result<std::fs::File> {
    if path.exists() && !path.is_file() {
        return Err(s.error(
            "file",
            format!("mesh {} is not a regular file", path.display()),
        ));
    }
    std::fs::File::open(path)
        .map_err(|e| s.error("file", format!("cannot open mesh {}: {e}", path.display())))
}

/// The mesh's triangles in the scene (zero-area ones dropped), their shading attributes and
/// whether it is closed. Vertex normals: the file's, else (unless `face_normals`) computed as
/// Mitsuba 3 computes them: per vertex, the sum of its faces' unit normals weighted by the
/// face's angle at that vertex (Thuermer and Wuethrich 1998). With `crease` (Mitsuba 0.6's
/// `maxSmoothAngle`, degrees) the file's normals are replaced by normals smoothed only across
/// faces within that angle ([`crease_normals`]).
fn triangles(
    raw: RawMesh,
    transform: Mat4,
    options: MeshOptions,
    crease: Option<f32>,
) -> std::result::Result<Mesh, String> {
    // A file without faces is most likely a broken export; one whose faces all have zero area
    // is invisible, and Mitsuba opens it.
    if raw.triangles.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    let face_normals = options.face_normals;
    // A mirroring transform reverses the winding (undone below, so that outward stays
    // outward); flip_normals reverses it on purpose.
    let mirrored = transform.determinant() < 0.0;
    let swap = mirrored != options.flip_normals;
    let positions: Vec<Vec3> = raw
        .positions
        .par_iter()
        .map(|&p| transform.transform_point3(p))
        .collect();
    // `what`: the index's name and the plural of what it counts.
    let range = |i: u32, len: usize, what: (&str, &str)| -> std::result::Result<usize, String> {
        if (i as usize) < len {
            Ok(i as usize)
        } else {
            Err(format!(
                "face {}index {} out of range ({len} {})",
                what.0,
                i as u64 + raw.first_index as u64,
                what.1
            ))
        }
    };
    // Normals transform with the inverse transpose (outward stays outward, a mirroring
    // included).
    let normal_matrix = Mat3::from_mat4(transform).inverse().transpose();
    let creased: Vec<[u32; 3]>;
    let (normals, normal_triangles) = if face_normals {
        (Vec::new(), &[][..])
    } else if let Some(angle) = crease {
        let uvs = (!raw.uv_triangles.is_empty()).then_some((&raw.uvs[..], &raw.uv_triangles[..]));
        let (mut n, t) = crease_normals(&positions, &raw.triangles, uvs, angle);
        if mirrored {
            n.iter_mut().for_each(|n| *n = -*n);
        }
        creased = t;
        (n, &creased[..])
    } else if !raw.normal_triangles.is_empty() {
        let n = raw
            .normals
            .par_iter()
            .map(|&n| (normal_matrix * n).normalize_or_zero())
            .collect();
        (n, &raw.normal_triangles[..])
    } else if !options.compute_normals {
        (Vec::new(), &[][..])
    } else {
        let mut n = vertex_normals(&positions, &raw.triangles);
        if mirrored {
            // Computed from the file's winding, which the mirroring reversed.
            n.iter_mut().for_each(|n| *n = -*n);
        }
        (n, &raw.triangles[..])
    };
    let normals: Vec<Vec3> = if options.flip_normals {
        normals.into_iter().map(|n| -n).collect()
    } else {
        normals
    };
    let smooth = !normals.is_empty();
    let textured = !raw.uv_triangles.is_empty();
    let attribute = raw.attribute.as_ref();
    if let Some(a) = attribute {
        let expected = if a.per_face {
            raw.triangles.len()
        } else {
            raw.positions.len()
        };
        if a.values.len() != expected {
            return Err(format!(
                "the mesh attribute has {} values for {expected} {}",
                a.values.len(),
                if a.per_face { "triangles" } else { "vertices" }
            ));
        }
    }
    // Face f in the scene: None if it has zero area.
    type Face = Option<(Shape, [Vec3; 3], TriangleAttrs, [Vec3; 3])>;
    let face = |f: usize| -> std::result::Result<Face, String> {
        let mut v = [Vec3::ZERO; 3];
        for (slot, &i) in v.iter_mut().zip(&raw.triangles[f]) {
            *slot = positions[range(i, positions.len(), ("", "vertices"))?];
        }
        let mut a = TriangleAttrs::default();
        if smooth {
            let mut n = [Vec3::ZERO; 3];
            for (slot, &i) in n.iter_mut().zip(&normal_triangles[f]) {
                *slot = normals[range(i, normals.len(), ("normal ", "normals"))?];
            }
            a.normals = Some(n);
        }
        if textured {
            let mut t = [Vec2::ZERO; 3];
            for (slot, &i) in t.iter_mut().zip(&raw.uv_triangles[f]) {
                *slot = raw.uvs[range(
                    i,
                    raw.uvs.len(),
                    ("texture coordinate ", "texture coordinates"),
                )?];
            }
            a.uvs = Some(t);
        }
        let mut c = [Vec3::ZERO; 3];
        if let Some(at) = attribute {
            c = if at.per_face {
                [at.values[f]; 3]
            } else {
                raw.triangles[f].map(|i| at.values[i as usize])
            };
        }
        if swap {
            v.swap(1, 2);
            c.swap(1, 2);
            if let Some(n) = &mut a.normals {
                n.swap(1, 2);
            }
            if let Some(t) = &mut a.uvs {
                t.swap(1, 2);
            }
        }
        if !v.iter().all(|p| p.is_finite()) {
            return Err("non-finite vertex".into());
        }
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        Ok((e1.cross(e2).length_squared() > 0.0).then_some((
            Shape::Triangle { p0: v[0], e1, e2 },
            v,
            a,
            c,
        )))
    };
    // In chunks on every thread, each into its own arrays, kept in order; the first bad face
    // (in file order) is the one reported.
    const CHUNK: usize = 1 << 14;
    type Part = (
        Vec<Shape>,
        Vec<[Vec3; 3]>,
        Vec<TriangleAttrs>,
        Vec<[Vec3; 3]>,
    );
    let parts: Vec<std::result::Result<Part, String>> = (0..raw.triangles.len())
        .into_par_iter()
        .step_by(CHUNK)
        .map(|start| {
            let end = (start + CHUNK).min(raw.triangles.len());
            let mut part: Part = (
                Vec::with_capacity(end - start),
                Vec::new(),
                Vec::new(),
                Vec::new(),
            );
            part.1.reserve(end - start);
            for f in start..end {
                if let Some((shape, v, a, c)) = face(f)? {
                    part.0.push(shape);
                    part.1.push(v);
                    if smooth || textured || attribute.is_some() {
                        part.2.push(a);
                    }
                    if attribute.is_some() {
                        part.3.push(c);
                    }
                }
            }
            Ok(part)
        })
        .collect();
    let mut tris = Vec::with_capacity(raw.triangles.len());
    let mut attrs = Vec::new();
    let mut values = Vec::new();
    let mut corners = Vec::with_capacity(raw.triangles.len());
    for part in parts {
        let (t, c, a, v) = part?;
        tris.extend(t);
        corners.extend(c);
        attrs.extend(a);
        values.extend(v);
    }
    Ok(Mesh {
        dropped: raw.triangles.len() - tris.len(),
        triangles: tris,
        attrs,
        attribute: values,
        corners,
    })
}

/// Mitsuba 0.6's normals for `maxSmoothAngle` (its `TriMesh::rebuildTopology`): the corners
/// at one point (one position and, with texture coordinates, one uv) are clustered greedily in
/// face order, each unclustered corner starting a cluster that takes every later unclustered
/// one whose face normal is within `max_angle` degrees of its own; each cluster gets the
/// angle-weighted normal of its faces (as [`vertex_normals`]). Returns the normals and, per
/// triangle, its corners' indices into them.
fn crease_normals(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    uvs: Option<(&[Vec2], &[[u32; 3]])>,
    max_angle: f32,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let corner = |f: usize, k: usize| positions.get(triangles[f][k] as usize).copied();
    let face_normal: Vec<Vec3> = (0..triangles.len())
        .into_par_iter()
        .map(|f| match (corner(f, 0), corner(f, 1), corner(f, 2)) {
            (Some(a), Some(b), Some(c)) => (b - a).cross(c - a).normalize_or_zero(),
            _ => Vec3::ZERO,
        })
        .collect();
    // The key of a corner: its point's bits (+0 and -0 alike); corners whose position is out
    // of range (reported by the caller) all share one.
    let key = |c: usize| -> [u32; 5] {
        let (f, k) = (c / 3, c % 3);
        let p = corner(f, k).map_or(Vec3::NAN, |p| p + Vec3::ZERO);
        let uv = uvs
            .and_then(|(uvs, tris)| uvs.get(tris[f][k] as usize).copied())
            .map_or(Vec2::ZERO, |t| t + Vec2::ZERO);
        [p.x, p.y, p.z, uv.x, uv.y].map(f32::to_bits)
    };
    let mut order: Vec<u32> = (0..3 * triangles.len() as u32).collect();
    // Stable: within a point, corners stay in face order, as Mitsuba's multimap keeps them.
    order.par_sort_by_key(|&c| key(c as usize));
    let threshold = max_angle.to_radians().cos();
    let mut cluster = vec![u32::MAX; order.len()];
    let mut clusters = 0u32;
    let mut start = 0;
    while start < order.len() {
        let k0 = key(order[start] as usize);
        let mut end = start + 1;
        while end < order.len() && key(order[end] as usize) == k0 {
            end += 1;
        }
        let group = &order[start..end];
        for (i, &seed) in group.iter().enumerate() {
            if cluster[seed as usize] != u32::MAX {
                continue;
            }
            let n1 = face_normal[seed as usize / 3];
            for &other in &group[i..] {
                let n2 = face_normal[other as usize / 3];
                if cluster[other as usize] == u32::MAX && (n1 == n2 || n1.dot(n2) > threshold) {
                    cluster[other as usize] = clusters;
                }
            }
            clusters += 1;
        }
        start = end;
    }
    let mut sum = vec![Vec3::ZERO; clusters as usize];
    for (f, n) in face_normal.iter().enumerate() {
        if *n == Vec3::ZERO {
            continue;
        }
        let p = [0, 1, 2].map(|k| corner(f, k).unwrap_or(Vec3::ZERO));
        for k in 0..3 {
            let a = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let b = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            sum[cluster[3 * f + k] as usize] += *n * a.dot(b).clamp(-1.0, 1.0).acos();
        }
    }
    let normals = sum.into_iter().map(Vec3::normalize_or_zero).collect();
    let corners = cluster
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (normals, corners)
}

/// Angle-weighted vertex normals (see [`triangles`]); a vertex no face gives a normal keeps
/// zero (shaded with the face normal).
fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; positions.len()];
    for face in triangles {
        let (Some(&a), Some(&b), Some(&c)) = (
            positions.get(face[0] as usize),
            positions.get(face[1] as usize),
            positions.get(face[2] as usize),
        ) else {
            continue; // reported by the caller
        };
        let p = [a, b, c];
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        if n.length_squared() == 0.0 {
            continue;
        }
        let n = n.normalize();
        for k in 0..3 {
            let a = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let b = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            let angle = a.dot(b).clamp(-1.0, 1.0).acos();
            sum[face[k] as usize] += n * angle;
        }
    }
    sum.into_iter().map(Vec3::normalize_or_zero).collect()
}

/// A closed (watertight), consistently oriented triangle set: every directed edge is used by
/// exactly one triangle and its reverse by exactly one other. Needed for `interior`: inside
/// and outside must be well defined. Vertices are matched by position (+0 and -0 alike).
pub fn is_closed(tris: &[[Vec3; 3]]) -> bool {
    // Sorting instead of a hash map keyed by pairs of positions, which at a million triangles
    // took longer than the BVH build: positions get ids by a sort, directed edges become u64s
    // sorted by their first vertex, and each edge's reverse is looked up among the edges
    // leaving its second vertex.
    if tris.is_empty() {
        return false;
    }
    let corners = 3 * tris.len();
    // Corners and position ids are numbered in 32 bits; more than 1.4 billion triangles would
    // not fit in memory anyway.
    assert!(
        u32::try_from(corners).is_ok(),
        "is_closed: too many triangles"
    );
    // The position's bits above, its corner's number below. Adding +0.0 turns -0.0 into +0.0.
    let mut keyed = vec![0u128; corners];
    keyed
        .par_chunks_mut(3)
        .zip(tris)
        .enumerate()
        .for_each(|(t, (out, v))| {
            for (k, (slot, &p)) in out.iter_mut().zip(v).enumerate() {
                let p = p + Vec3::ZERO;
                let bits = (p.x.to_bits() as u128) << 64
                    | (p.y.to_bits() as u128) << 32
                    | p.z.to_bits() as u128;
                *slot = bits << 32 | (3 * t + k) as u128;
            }
        });
    keyed.par_sort_unstable();
    let mut id = vec![0u32; corners];
    let mut next = 0u32;
    for (i, &c) in keyed.iter().enumerate() {
        if i > 0 && c >> 32 != keyed[i - 1] >> 32 {
            next += 1;
        }
        id[c as u32 as usize] = next;
    }
    let positions = next as usize + 1;
    drop(keyed);
    let mut edges = vec![0u64; corners];
    edges
        .par_chunks_mut(3)
        .zip(id.par_chunks_exact(3))
        .for_each(|(out, t)| {
            for k in 0..3 {
                out[k] = (t[k] as u64) << 32 | t[(k + 1) % 3] as u64;
            }
        });
    drop(id);
    edges.par_sort_unstable();
    if edges.windows(2).any(|w| w[0] == w[1]) {
        return false;
    }
    // The edges leaving position a are edges[first[a]..first[a + 1]], sorted.
    let mut first = vec![0u32; positions + 1];
    for &e in &edges {
        first[(e >> 32) as usize + 1] += 1;
    }
    for a in 0..positions {
        first[a + 1] += first[a];
    }
    edges.par_iter().all(|&e| {
        let b = (e & 0xffff_ffff) as usize;
        edges[first[b] as usize..first[b + 1] as usize]
            .binary_search(&e.rotate_left(32))
            .is_ok()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// A unit cube of 12 outward-facing triangles.
    fn cube() -> Vec<[Vec3; 3]> {
        let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let quads = [
            (c(0., 0., 0.), c(0., 1., 0.), c(1., 0., 0.)),
            (c(0., 0., 1.), c(1., 0., 0.), c(0., 1., 0.)),
            (c(0., 0., 0.), c(1., 0., 0.), c(0., 0., 1.)),
            (c(0., 1., 0.), c(0., 0., 1.), c(1., 0., 0.)),
            (c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 0.)),
            (c(1., 0., 0.), c(0., 1., 0.), c(0., 0., 1.)),
        ];
        let mut tris = Vec::new();
        for (o, u, v) in quads {
            tris.push([o, o + u, o + u + v]);
            tris.push([o, o + u + v, o + v]);
        }
        tris
    }

    /// The definition, written the slow and obvious way (is_closed before it was sorted).
    fn closed_by_definition(tris: &[[Vec3; 3]]) -> bool {
        type Vertex = (u32, u32, u32);
        let key = |p: Vec3| -> Vertex {
            let p = p + Vec3::ZERO;
            (p.x.to_bits(), p.y.to_bits(), p.z.to_bits())
        };
        let mut directed: HashMap<(Vertex, Vertex), u32> = HashMap::new();
        for v in tris {
            for i in 0..3 {
                *directed
                    .entry((key(v[i]), key(v[(i + 1) % 3])))
                    .or_default() += 1;
            }
        }
        !directed.is_empty()
            && directed
                .iter()
                .all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1))
    }

    #[test]
    fn zero_area_triangles_are_counted_and_left_out() {
        let options = MeshOptions {
            face_normals: false,
            flip_tex_coords: false,
            flip_normals: false,
            compute_normals: true,
        };
        let raw = |triangles: Vec<[u32; 3]>| RawMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, 2.0 * Vec3::X],
            triangles,
            ..RawMesh::default()
        };
        // Collinear corners, a repeated corner, and one real triangle.
        let mesh = triangles(
            raw(vec![[0, 1, 3], [0, 0, 2], [0, 1, 2]]),
            Mat4::IDENTITY,
            options,
            None,
        )
        .unwrap();
        assert_eq!((mesh.triangles.len(), mesh.dropped), (1, 2));
        let mesh = triangles(
            raw(vec![[0, 1, 3], [2, 2, 2]]),
            Mat4::IDENTITY,
            options,
            None,
        )
        .unwrap();
        assert_eq!((mesh.triangles.len(), mesh.dropped), (0, 2));
        assert!(!mesh.closed());
        // A zero scale flattens every triangle.
        let flat = Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0));
        let mesh = triangles(raw(vec![[0, 1, 2]]), flat, options, None).unwrap();
        assert_eq!((mesh.triangles.len(), mesh.dropped), (0, 1));
        let e = triangles(raw(Vec::new()), Mat4::IDENTITY, options, None)
            .err()
            .unwrap();
        assert!(e.contains("no triangles"), "{e}");
    }

    #[test]
    fn crease_normals_smooth_only_within_the_angle() {
        // Two triangles folded 45 degrees along their shared edge (the x axis).
        let s = std::f32::consts::FRAC_1_SQRT_2;
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.0, -s, s)];
        let triangles = [[0, 1, 2], [1, 0, 3]];
        let up = Vec3::Z;
        let folded = Vec3::new(0.0, s, s);
        let (n, t) = crease_normals(&positions, &triangles, None, 30.0);
        // Each corner keeps its own face's normal: 45 degrees apart is beyond 30.
        for (f, normal) in [(0, up), (1, folded)] {
            for k in 0..3 {
                assert!((n[t[f][k] as usize] - normal).length() < 1e-6, "{f} {k}");
            }
        }
        let (n, t) = crease_normals(&positions, &triangles, None, 60.0);
        // The shared edge's corners are one cluster each: both faces' normals, weighted by
        // their angles at the corner (45 degrees in both faces at each of them).
        let shared = (up + folded).normalize();
        assert_eq!(t[0][0], t[1][1]);
        assert_eq!(t[0][1], t[1][0]);
        assert!((n[t[0][0] as usize] - shared).length() < 1e-6);
        assert!((n[t[0][1] as usize] - shared).length() < 1e-6);
        // The corners only one face has keep its normal.
        assert!((n[t[0][2] as usize] - up).length() < 1e-6);
        assert!((n[t[1][2] as usize] - folded).length() < 1e-6);
        // Different texture coordinates at one position split the point, as in Mitsuba.
        let uvs = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
        let uv_triangles = [[0, 1, 2], [1, 3, 3]];
        let (_, t) = crease_normals(&positions, &triangles, Some((&uvs, &uv_triangles)), 60.0);
        assert_ne!(t[0][0], t[1][1]);
        assert_eq!(t[0][1], t[1][0]);
    }

    #[test]
    fn cube_is_closed_and_open_box_is_not() {
        let mut tris = cube();
        assert!(is_closed(&tris));
        tris.pop();
        assert!(!is_closed(&tris));
        assert!(!is_closed(&[]));
    }

    #[test]
    fn a_duplicated_triangle_is_not_closed() {
        let mut tris = cube();
        tris.push(tris[3]);
        assert!(!is_closed(&tris));
        // Whereas a triangle and its reverse satisfy the definition, which is about edges.
        let t = tris[0];
        assert!(is_closed(&[t, [t[0], t[2], t[1]]]));
    }

    #[test]
    fn one_flipped_triangle_is_not_closed() {
        for f in 0..12 {
            let mut tris = cube();
            tris[f].swap(1, 2);
            assert!(!is_closed(&tris), "triangle {f} flipped");
        }
    }

    #[test]
    fn minus_zero_matches_plus_zero() {
        let mut tris = cube();
        // The same corners, written with -0.0 in some triangles only.
        for t in tris.iter_mut().step_by(2) {
            for p in t.iter_mut() {
                *p = Vec3::select(p.cmpeq(Vec3::ZERO), Vec3::splat(-0.0), *p);
            }
        }
        assert!(
            tris.iter()
                .flatten()
                .any(|p| p.x.to_bits() == (-0.0f32).to_bits())
        );
        assert!(is_closed(&tris));
    }

    #[test]
    fn agrees_with_the_definition_on_random_triangle_sets() {
        // Triangles over a few grid points, so that edges coincide often; some sets are
        // cubes with triangles removed, flipped or repeated.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        let mut seen = [0; 2];
        for _ in 0..2000 {
            let tris: Vec<[Vec3; 3]> = if next(2) == 0 {
                let mut tris = cube();
                match next(4) {
                    0 => {}
                    1 => {
                        tris.remove(next(12) as usize);
                    }
                    2 => tris[next(12) as usize].swap(0, 1),
                    _ => tris.push(tris[next(12) as usize]),
                }
                tris
            } else {
                let point = |i: u64| {
                    let s = if i & 8 != 0 { -0.0 } else { 0.0 };
                    Vec3::new(
                        (i & 1) as f32 + s,
                        ((i >> 1) & 1) as f32,
                        (i >> 2 & 1) as f32,
                    )
                };
                let n = 1 + next(6) as usize;
                (0..n)
                    .map(|_| [point(next(16)), point(next(16)), point(next(16))])
                    .collect()
            };
            let expected = closed_by_definition(&tris);
            assert_eq!(is_closed(&tris), expected, "{tris:?}");
            seen[expected as usize] += 1;
        }
        assert!(seen[0] > 100 && seen[1] > 100, "{seen:?}");
    }
}
