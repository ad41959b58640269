//! Triangle meshes: OBJ and PLY files, and whether a triangle set is closed (needed for a
//! medium inside it).

use super::ply;
use crate::error::Result;
use crate::geometry::{Shape, TriangleAttrs};
use crate::props::Properties;
use glam::{Mat3, Mat4, Vec2, Vec3};
use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

/// A mesh as a file describes it, before the shape's transform.
#[derive(Clone, Debug, Default)]
pub struct RawMesh {
    pub positions: Vec<Vec3>,
    /// Indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// How the format numbers its first vertex (1 in OBJ, 0 in PLY), for messages.
    pub first_index: u32,
    /// Vertex normals and, per triangle, the indices of its corners' normals (empty if the
    /// file has none).
    pub normals: Vec<Vec3>,
    pub normal_triangles: Vec<[u32; 3]>,
    /// Texture coordinates, likewise.
    pub uvs: Vec<Vec2>,
    pub uv_triangles: Vec<[u32; 3]>,
}

/// How a mesh is shaded (Mitsuba's `face_normals` and the OBJ reader's `flip_tex_coords`).
#[derive(Clone, Copy, Debug)]
pub struct MeshOptions {
    /// Shade with the triangles' own normals, ignoring vertex normals.
    pub face_normals: bool,
    /// OBJ texture coordinates count v from the top: v = 1 - v (Mitsuba's default).
    pub flip_tex_coords: bool,
    /// Turn the mesh inside out: reversed triangles, negated vertex normals.
    pub flip_normals: bool,
}

/// A mesh in the scene: its triangles, their attributes (empty, or one per triangle) and
/// whether it is closed.
pub struct Mesh {
    pub triangles: Vec<Shape>,
    pub attrs: Vec<TriangleAttrs>,
    pub closed: bool,
}

/// The mesh file `path` (OBJ or PLY, by extension) of shape `s` in the scene.
pub(super) fn load_mesh(
    s: &Properties<'_>,
    path: &Path,
    transform: Mat4,
    options: MeshOptions,
) -> Result<Mesh> {
    let fail = |message: String| s.error("file", format!("{}: {message}", path.display()));
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let raw = match extension.as_deref() {
        Some("obj") => {
            let mut raw = read_obj(open(s, path)?).map_err(fail)?;
            if options.flip_tex_coords {
                for uv in &mut raw.uvs {
                    uv.y = 1.0 - uv.y;
                }
            }
            raw
        }
        Some("ply") => {
            let mut file = open(s, path)?;
            let mut bytes = Vec::new();
            file.read_to_end(&mut bytes)
                .map_err(|e| fail(format!("cannot read: {e}")))?;
            ply::parse(&bytes).map_err(fail)?
        }
        _ => {
            return Err(s.error(
                "file",
                format!(
                    "mesh {}: unknown mesh format; expected a file ending in .obj or .ply",
                    path.display()
                ),
            ));
        }
    };
    triangles(raw, transform, options).map_err(fail)
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

fn read_obj(file: std::fs::File) -> std::result::Result<RawMesh, String> {
    let mut reader = std::io::BufReader::new(file);
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    // Material libraries are not followed: materials come from the scene file.
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| format!("malformed OBJ: {e}"))?;
    // tobj numbers the vertices of each model from 0: one mesh needs them offset.
    let mut raw = RawMesh {
        first_index: 1,
        ..RawMesh::default()
    };
    let corners = |indices: &[u32], base: usize| -> Vec<[u32; 3]> {
        let base = base as u32;
        indices
            .chunks_exact(3)
            .map(|f| [f[0], f[1], f[2]].map(|i| base.saturating_add(i)))
            .collect()
    };
    // A model without normals (or texture coordinates) leaves the mesh without them: Mitsuba
    // computes all the normals then, and a texture lookup without coordinates is meaningless.
    let all_normals = models.iter().all(|m| !m.mesh.normal_indices.is_empty());
    let all_uvs = models.iter().all(|m| !m.mesh.texcoord_indices.is_empty());
    for model in &models {
        let mesh = &model.mesh;
        raw.triangles
            .extend(corners(&mesh.indices, raw.positions.len()));
        raw.positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        if all_normals {
            raw.normal_triangles
                .extend(corners(&mesh.normal_indices, raw.normals.len()));
            raw.normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        }
        if all_uvs {
            raw.uv_triangles
                .extend(corners(&mesh.texcoord_indices, raw.uvs.len()));
            raw.uvs.extend(
                mesh.texcoords
                    .chunks_exact(2)
                    .map(|t| Vec2::new(t[0], t[1])),
            );
        }
    }
    Ok(raw)
}

/// The mesh's triangles in the scene (degenerate ones dropped), their shading attributes and
/// whether it is closed. Vertex normals: the file's, else (unless `face_normals`) computed as
/// Mitsuba 3 computes them: per vertex, the sum of its faces' unit normals weighted by the
/// face's angle at that vertex (Thuermer and Wuethrich 1998).
fn triangles(
    raw: RawMesh,
    transform: Mat4,
    options: MeshOptions,
) -> std::result::Result<Mesh, String> {
    let face_normals = options.face_normals;
    // A mirroring transform reverses the winding (undone below, so that outward stays
    // outward); flip_normals reverses it on purpose.
    let mirrored = transform.determinant() < 0.0;
    let swap = mirrored != options.flip_normals;
    let positions: Vec<Vec3> = raw
        .positions
        .iter()
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
    let (normals, normal_triangles) = if face_normals {
        (Vec::new(), &[][..])
    } else if !raw.normal_triangles.is_empty() {
        let n = raw
            .normals
            .iter()
            .map(|&n| (normal_matrix * n).normalize_or_zero())
            .collect();
        (n, &raw.normal_triangles[..])
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
    let mut tris = Vec::with_capacity(raw.triangles.len());
    let mut attrs = Vec::new();
    let mut corners = Vec::with_capacity(raw.triangles.len());
    let smooth = !normals.is_empty();
    let textured = !raw.uv_triangles.is_empty();
    for (f, face) in raw.triangles.iter().enumerate() {
        let mut v = [Vec3::ZERO; 3];
        for (slot, &i) in v.iter_mut().zip(face) {
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
        if swap {
            v.swap(1, 2);
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
        if e1.cross(e2).length_squared() > 0.0 {
            tris.push(Shape::Triangle { p0: v[0], e1, e2 });
            corners.push(v);
            if smooth || textured {
                attrs.push(a);
            }
        }
    }
    if tris.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    let closed = is_closed(&corners);
    Ok(Mesh {
        triangles: tris,
        attrs,
        closed,
    })
}

/// Angle-weighted vertex normals (see [`triangles`]); a vertex no face gives a normal keeps
/// zero (shaded with the face normal).
fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; positions.len()];
    for face in triangles {
        let Some(p) = face
            .iter()
            .map(|&i| positions.get(i as usize).copied())
            .collect::<Option<Vec<_>>>()
        else {
            continue; // reported by the caller
        };
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
    type Vertex = (u32, u32, u32);
    // Adding +0.0 turns -0.0 into +0.0.
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_is_closed_and_open_box_is_not() {
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
        assert!(is_closed(&tris));
        tris.pop();
        assert!(!is_closed(&tris));
    }
}
