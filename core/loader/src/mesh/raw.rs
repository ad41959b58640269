//! The mesh a file format reads, before the scene's transform: what the OBJ and PLY readers
//! share with the code that turns it into the scene's triangles.

use glam::{Vec2, Vec3};

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
    /// The file asks for face normals (a version 5 serialized mesh's flag), which a scene's
    /// own `face_normals` overrides.
    pub face_normals: bool,
    /// The mesh attribute the scene reads, if it asked for one (see `ply::attribute`).
    pub attribute: Option<super::ply::Attribute>,
}
