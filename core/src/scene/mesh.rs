//! Triangle meshes: OBJ files, and whether a triangle set is closed (needed for a medium
//! inside it).

use crate::error::Result;
use crate::geometry::Shape;
use crate::props::Properties;
use glam::{Mat4, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// The mesh's triangles, and whether it is closed.
pub(super) fn load_obj(
    s: &Properties<'_>,
    path: &Path,
    transform: Mat4,
) -> Result<(Vec<Shape>, bool)> {
    if path.exists() && !path.is_file() {
        return Err(s.error(
            "file",
            format!("mesh {} is not a regular file", path.display()),
        ));
    }
    let file = std::fs::File::open(path)
        .map_err(|e| s.error("file", format!("cannot open mesh {}: {e}", path.display())))?;
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
    .map_err(|e| s.error("file", format!("{}: malformed OBJ: {e}", path.display())))?;
    let mirrored = transform.determinant() < 0.0;
    let mut tris = Vec::new();
    let mut corners = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let positions: Vec<Vec3> = mesh
            .positions
            .chunks_exact(3)
            .map(|p| transform.transform_point3(Vec3::new(p[0], p[1], p[2])))
            .collect();
        for face in mesh.indices.chunks_exact(3) {
            let mut v = [Vec3::ZERO; 3];
            for (slot, &i) in v.iter_mut().zip(face) {
                *slot = *positions.get(i as usize).ok_or_else(|| {
                    s.error(
                        "file",
                        format!(
                            "{}: face index {} out of range ({} vertices)",
                            path.display(),
                            i + 1,
                            positions.len()
                        ),
                    )
                })?;
            }
            if mirrored {
                // A mirroring transform reverses the winding; undo it so that normals keep
                // their side (outward stays outward).
                v.swap(1, 2);
            }
            if !v.iter().all(|p| p.is_finite()) {
                return Err(s.error("file", format!("{}: non-finite vertex", path.display())));
            }
            let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
            if e1.cross(e2).length_squared() > 0.0 {
                tris.push(Shape::Triangle { p0: v[0], e1, e2 });
                corners.push(v);
            }
        }
    }
    if tris.is_empty() {
        return Err(s.error(
            "file",
            format!("{}: the mesh has no triangles", path.display()),
        ));
    }
    Ok((tris, is_closed(&corners)))
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
