//! Wavefront OBJ meshes, read by tobj: positions, triangulated faces, and the normals and
//! texture coordinates where every model has them.

use super::raw::RawMesh;
use glam::{Vec2, Vec3};

/// The OBJ file's mesh, its models one after another. Errors are plain text; the caller adds
/// the file and the scene key.
pub(super) fn read(file: std::fs::File) -> std::result::Result<RawMesh, String> {
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
