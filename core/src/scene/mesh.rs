//! Triangle meshes: OBJ and PLY files, and whether a triangle set is closed (needed for a
//! medium inside it).

use super::ply;
use crate::error::Result;
use crate::geometry::Shape;
use crate::props::Properties;
use glam::{Mat4, Vec3};
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
}

/// The triangles of the mesh file `path` (OBJ or PLY, by extension) of shape `s`, and
/// whether the mesh is closed.
pub(super) fn load_mesh(
    s: &Properties<'_>,
    path: &Path,
    transform: Mat4,
) -> Result<(Vec<Shape>, bool)> {
    let fail = |message: String| s.error("file", format!("{}: {message}", path.display()));
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let raw = match extension.as_deref() {
        Some("obj") => read_obj(open(s, path)?).map_err(fail)?,
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
    triangles(raw, transform).map_err(fail)
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
    for model in &models {
        let mesh = &model.mesh;
        let base = raw.positions.len() as u32;
        raw.positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        raw.triangles.extend(
            mesh.indices
                .chunks_exact(3)
                .map(|f| [f[0], f[1], f[2]].map(|i| base.saturating_add(i))),
        );
    }
    Ok(raw)
}

/// The mesh's triangles in the scene (degenerate ones dropped), and whether it is closed.
fn triangles(raw: RawMesh, transform: Mat4) -> std::result::Result<(Vec<Shape>, bool), String> {
    let mirrored = transform.determinant() < 0.0;
    let positions: Vec<Vec3> = raw
        .positions
        .iter()
        .map(|&p| transform.transform_point3(p))
        .collect();
    let mut tris = Vec::with_capacity(raw.triangles.len());
    let mut corners = Vec::with_capacity(raw.triangles.len());
    for face in &raw.triangles {
        let mut v = [Vec3::ZERO; 3];
        for (slot, &i) in v.iter_mut().zip(face) {
            *slot = *positions.get(i as usize).ok_or_else(|| {
                format!(
                    "face index {} out of range ({} vertices)",
                    i as u64 + raw.first_index as u64,
                    positions.len()
                )
            })?;
        }
        if mirrored {
            // A mirroring transform reverses the winding; undo it so that normals keep
            // their side (outward stays outward).
            v.swap(1, 2);
        }
        if !v.iter().all(|p| p.is_finite()) {
            return Err("non-finite vertex".into());
        }
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        if e1.cross(e2).length_squared() > 0.0 {
            tris.push(Shape::Triangle { p0: v[0], e1, e2 });
            corners.push(v);
        }
    }
    if tris.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    let closed = is_closed(&corners);
    Ok((tris, closed))
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
