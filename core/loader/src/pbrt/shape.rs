//! `Shape`: `sphere`, `disk`, `trianglemesh` (written inline in the document) and `plymesh`
//! as `[[shapes]]` entries, each with the current material and, under an `AreaLightSource`,
//! its emission (shapes.cpp, lights.cpp's `DiffuseAreaLight::Create`).
//!
//! Orientation as pbrt-v4 computes a surface's normal: a triangle's is its winding's in the
//! object's space (pbrt-v4 flips the world-space cross product when the transform mirrors),
//! turned towards its vertex normals when it has them; a sphere's and a disk's are their
//! object-space cross products dp/du x dp/dv (outward, +z) flipped when the transform
//! mirrors, then transformed as normals: a mirrored sphere faces inward, as in pbrt-v4, while
//! a disk's u x v already carries the mirror. `ReverseOrientation` turns each of them.

use super::params::Bag;
use super::parse::{Directive, Param, Type, Values};
use super::spectra::{Kind, rgb};
use super::texture::Tex;
use super::{Loc, Reader, State};
use foton_core::error::Result;
use foton_core::value::{Node, Table, Value};
use glam::{DMat3, DMat4, DVec3};

impl Reader {
    pub(super) fn shape(&mut self, d: &Directive, state: &State) -> Result<()> {
        let mut p = Bag::new(d).with_defaults(&state.attributes.shape);
        let loc = d.loc.clone();
        let what = d.what();
        let m = state.ctm;
        let mirrored = m.determinant() < 0.0;
        let mut entries: Vec<(&str, Node)> = Vec::new();
        // The shape's area in the world, for an area light's `power`.
        let area: Option<f64>;
        let mut flip = state.reverse_orientation;
        match d.string(0) {
            "sphere" => {
                let r = p.float("radius", 1.0)?;
                if r <= 0.0 {
                    return Err(loc.error(&what, format!("\"radius\" {r}: must be positive")));
                }
                let partial = [
                    p.float_opt("zmin")?.filter(|(z, _)| *z > -r),
                    p.float_opt("zmax")?.filter(|(z, _)| *z < r),
                    p.float_opt("phimax")?.filter(|(x, _)| *x < 360.0),
                ];
                if let Some((_, l)) = partial.into_iter().flatten().next() {
                    return self.unsupported(
                        &l,
                        &what,
                        "a partial sphere (zmin, zmax, phimax) is not supported",
                    );
                }
                let Some(s) = uniform_scale(m) else {
                    return self.unsupported(&loc, &what, "a sphere under a transform that is not a rotation and a uniform scale (an ellipsoid) is not supported");
                };
                flip ^= mirrored;
                area = Some(4.0 * std::f64::consts::PI * (r * s) * (r * s));
                entries.push(("type", self.string("sphere", &loc)));
                entries.push(("center", self.vec3(m.transform_point3(DVec3::ZERO), &loc)));
                entries.push(("radius", self.num(r * s, &loc)));
                // pbrt-v4's texture coordinates: u = phi / 2 pi about the sphere's own z, v =
                // 1 - theta / pi (from its -z pole): foton's about the axes x, y, -z.
                let (x, y, z) = (
                    m.transform_vector3(DVec3::X) / s,
                    m.transform_vector3(DVec3::Y) / s,
                    m.transform_vector3(DVec3::Z) / s,
                );
                let axes: Vec<Node> = [x, y, -z]
                    .iter()
                    .flat_map(|r| r.to_array())
                    .map(|v| self.num(v, &loc))
                    .collect();
                entries.push(("axes", self.node(Value::Array(axes), &loc)));
            }
            "disk" => {
                let h = p.float("height", 0.0)?;
                let r = p.float("radius", 1.0)?;
                if r <= 0.0 {
                    return Err(loc.error(&what, format!("\"radius\" {r}: must be positive")));
                }
                let partial = [
                    p.float_opt("innerradius")?.filter(|(x, _)| *x > 0.0),
                    p.float_opt("phimax")?.filter(|(x, _)| *x < 360.0),
                ];
                if let Some((_, l)) = partial.into_iter().flatten().next() {
                    return self.unsupported(
                        &l,
                        &what,
                        "a partial disk (innerradius, phimax) is not supported",
                    );
                }
                let (u, v) = (
                    m.transform_vector3(DVec3::X * r),
                    m.transform_vector3(DVec3::Y * r),
                );
                area = Some(std::f64::consts::PI * u.cross(v).length());
                entries.push(("type", self.string("disk", &loc)));
                entries.push(("center", self.vec3(m.transform_point3(DVec3::Z * h), &loc)));
                entries.push(("u", self.vec3(u, &loc)));
                entries.push(("v", self.vec3(v, &loc)));
            }
            "trianglemesh" => {
                let Some(mesh) = self.triangle_mesh(&mut p, &what, &loc)? else {
                    return Ok(());
                };
                area = Some(mesh.light_area(m));
                entries.push(("type", self.string("mesh", &loc)));
                entries.extend(mesh.entries(self, &loc));
                entries.push(("transform", self.matrix(m, &loc)));
                // pbrt-v4 shades a mesh without "N" with its triangles' own normals.
                if mesh.normals.is_none() {
                    entries.push(("compute_normals", self.node(Value::Bool(false), &loc)));
                }
            }
            "plymesh" => {
                let (name, l) = p
                    .string_opt("filename")?
                    .ok_or_else(|| loc.error(&what, "missing \"string filename\""))?;
                let path = super::parse::resolve(&self.dir, &l.file, &name);
                if !path.is_file() {
                    return Err(l.error(&what, format!("\"filename\" {name:?}: no such file")));
                }
                let rel = path
                    .strip_prefix(&self.dir)
                    .map_or(path.clone(), std::path::Path::to_path_buf);
                if p.has("displacement") {
                    let q = p.take("displacement").expect("has it");
                    self.warn(
                        &q.loc,
                        &what,
                        "displacement ignored: the mesh is rendered as its file's triangles",
                    );
                }
                p.float_opt("edgelength")?;
                area = None;
                entries.push(("type", self.string("mesh", &loc)));
                entries.push(("file", self.string(&rel.to_string_lossy(), &l)));
                entries.push(("transform", self.matrix(m, &loc)));
                // The file's vertex normals if it has them, else the triangles' own (pbrt-v4).
                entries.push(("compute_normals", self.node(Value::Bool(false), &loc)));
                if !self.ply_noted {
                    self.ply_noted = true;
                    self.note(&loc, &what, "a PLY mesh's triangles keep their winding's side; pbrt-v4 turns a triangle with vertex normals towards them (the same for consistently oriented meshes)");
                }
            }
            "bilinearmesh" | "cylinder" => {
                let mesh = if d.string(0) == "cylinder" {
                    self.cylinder(&mut p, &what, &loc)?
                } else {
                    self.bilinear_mesh(&mut p, &what, &loc)?
                };
                let Some(mesh) = mesh else {
                    return Ok(());
                };
                area = Some(mesh.light_area(m));
                entries.push(("type", self.string("mesh", &loc)));
                entries.extend(mesh.entries(self, &loc));
                entries.push(("transform", self.matrix(m, &loc)));
            }
            "loopsubdiv" => {
                let Some(mesh) = self.loop_subdivision(&mut p, &what, &loc)? else {
                    return Ok(());
                };
                area = Some(mesh.light_area(m));
                entries.push(("type", self.string("mesh", &loc)));
                entries.extend(mesh.entries(self, &loc));
                entries.push(("transform", self.matrix(m, &loc)));
            }
            other @ "curve" => {
                return self.unsupported(
                    &loc,
                    &what,
                    &format!("the {other} shape is not read yet"),
                );
            }
            other => {
                return Err(loc.error(&what, format!("unknown shape {other:?}; pbrt-v4 has sphere, disk, cylinder, trianglemesh, plymesh, bilinearmesh, loopsubdiv and curve")));
            }
        }
        let alpha = match p.take("alpha") {
            None => None,
            Some(q) => self.alpha(&q, &what)?.map(|a| (a, q.loc.clone())),
        };
        self.finish(&mut p)?;
        if flip {
            entries.push(("flip_normals", self.node(Value::Bool(true), &loc)));
        }
        if let Some(light) = state.area_light.clone()
            && let Some((emission, twosided)) = self.area_light(&light, area)?
        {
            entries.push(("emission", emission));
            if twosided {
                entries.push((
                    "emission_twosided",
                    self.node(Value::Bool(true), &light.loc),
                ));
            }
        }
        let material = self.current_material(state);
        entries.push(("material", self.string(&material, &loc)));
        let sides = self.medium_sides(state, &loc);
        if let Some((alpha, aloc)) = alpha {
            if !sides.is_empty() {
                self.unsupported(&aloc, &what, "\"alpha\" on a shape between two media: a cut-out medium boundary is not rendered yet")?;
            } else {
                entries.push(("alpha", alpha));
            }
        }
        entries.extend(sides);
        let shape = self.table(entries, &loc);
        self.shapes.push(shape);
        Ok(())
    }

    /// A shape's `alpha` (a float, or a float texture named) as a shape table's `alpha`; None
    /// where it leaves the shape opaque everywhere (1) or was left out (`lenient`).
    fn alpha(&mut self, q: &Param, what: &str) -> Result<Option<Node>> {
        let a = match (&q.ty, &q.values) {
            (Type::Float, Values::Nums(v)) if v.len() == 1 => v[0],
            (Type::Texture, _) => match self.named_texture(q, true, what)? {
                Some(Tex::Constant(c)) => c.x,
                Some(Tex::Table(t)) => return Ok(Some(t)),
                None => return Ok(None),
            },
            _ => {
                return Err(q.loc.error(
                    what,
                    format!(
                        "{}: expected one \"float alpha\" or a float texture",
                        q.decl()
                    ),
                ));
            }
        };
        // pbrt-v4 keeps a hit where alpha >= 1 and drops it where alpha <= 0.
        Ok((a < 1.0).then(|| self.num(a.max(0.0), &q.loc)))
    }

    /// The 4x4 transform as the document's `{ matrix = [16 numbers, row-major] }`.
    pub(super) fn matrix(&self, m: DMat4, loc: &Loc) -> Node {
        let rows: Vec<Node> = (0..4)
            .flat_map(|r| m.row(r).to_array())
            .map(|x| self.num(x, loc))
            .collect();
        let mut t = Table::default();
        t.insert("matrix", self.node(Value::Array(rows), loc));
        self.node(Value::Table(t), loc)
    }

    /// A `cylinder` (`radius` 1, `zmin` -1, `zmax` 1, `phimax` 360) as its prism of
    /// [`CYLINDER_FACETS`] facets per full turn with the cylinder's normals at the vertices
    /// (smooth shading), facing out (pbrt-v4's dp/du x dp/dv), uv = (phi / phimax, (z -
    /// zmin) / (zmax - zmin)).
    fn cylinder(&mut self, p: &mut Bag, what: &str, loc: &Loc) -> Result<Option<InlineMesh>> {
        let r = p.float("radius", 1.0)?;
        let (z0, z1) = (p.float("zmin", -1.0)?, p.float("zmax", 1.0)?);
        let (z0, z1) = (z0.min(z1), z0.max(z1));
        let phimax = p.float("phimax", 360.0)?.clamp(0.0, 360.0).to_radians();
        if r <= 0.0 || z1 <= z0 || phimax <= 0.0 {
            return Err(loc.error(what, "a cylinder of zero radius, height or angle"));
        }
        let segments =
            ((CYLINDER_FACETS as f64 * phimax / std::f64::consts::TAU).ceil() as usize).max(1);
        let (mut positions, mut normals, mut uvs, mut indices) = (vec![], vec![], vec![], vec![]);
        for i in 0..=segments {
            let u = i as f64 / segments as f64;
            let (sin, cos) = (u * phimax).sin_cos();
            for (v, z) in [(0.0, z0), (1.0, z1)] {
                positions.extend([r * cos, r * sin, z]);
                normals.extend([cos, sin, 0.0]);
                uvs.extend([u, v]);
            }
        }
        for i in 0..segments as u32 {
            let (a, d, b, c) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
            indices.extend([a, b, c, a, c, d]);
        }
        self.note(
            loc,
            what,
            &format!("a cylinder as its prism of {CYLINDER_FACETS} facets a turn, shaded smooth"),
        );
        Ok(Some(InlineMesh {
            positions,
            indices,
            normals: Some(normals),
            uvs: Some(uvs),
            lights: Some(1),
        }))
    }

    /// A `bilinearmesh` (`P`, `indices` four a patch: p00 p10 p01 p11; `uv`, `N`): a planar
    /// patch is two triangles, exactly; a curved one is tessellated into
    /// [`PATCH_STEPS`]^2 quads of two triangles, vertices on the patch (a note). Its side
    /// is pbrt-v4's dp/du x dp/dv, turned towards `N` when given; uv is `uv` interpolated,
    /// or the patch's (u, v).
    fn bilinear_mesh(&mut self, p: &mut Bag, what: &str, loc: &Loc) -> Result<Option<InlineMesh>> {
        let MeshData {
            positions,
            indices,
            normals: given_n,
            uvs: given_uv,
        } = mesh_data(p, what, loc, 4)?;
        let patches: Vec<usize> = indices.iter().map(|&i| i as usize).collect();
        if let Some(q) = p.take("emissionfilename") {
            self.unsupported(
                &q.loc,
                what,
                &format!("{}: textured emission is not read yet", q.decl()),
            )?;
        }
        let at = |v: &[f64], w: usize, i: usize| -> DVec3 {
            DVec3::new(
                v[i * w],
                v[i * w + 1],
                if w == 3 { v[i * w + 2] } else { 0.0 },
            )
        };
        let bilerp = |c: [DVec3; 4], u: f64, v: f64| {
            (1.0 - u) * (1.0 - v) * c[0]
                + u * (1.0 - v) * c[1]
                + (1.0 - u) * v * c[2]
                + u * v * c[3]
        };
        let mut mesh = InlineMesh {
            positions: Vec::new(),
            indices: Vec::new(),
            normals: given_n.as_ref().map(|_| Vec::new()),
            uvs: Some(Vec::new()),
            lights: Some(patches.len() / 4),
        };
        let mut curved = false;
        for q in patches.chunks(4) {
            let corners = [0, 1, 2, 3].map(|k| at(&positions, 3, q[k]));
            let uv = [0, 1, 2, 3].map(|k| match &given_uv {
                Some(uv) => at(uv, 2, q[k]),
                None => DVec3::new((k % 2) as f64, (k / 2) as f64, 0.0),
            });
            let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            let size = (corners[1] - corners[0])
                .length()
                .max((corners[2] - corners[0]).length());
            let off_plane = (corners[3] - corners[0])
                .dot(normal.normalize_or_zero())
                .abs();
            let steps = if off_plane <= 1e-6 * size {
                1
            } else {
                curved = true;
                PATCH_STEPS
            };
            let base = (mesh.positions.len() / 3) as u32;
            for j in 0..=steps {
                for i in 0..=steps {
                    let (u, v) = (i as f64 / steps as f64, j as f64 / steps as f64);
                    mesh.positions.extend(bilerp(corners, u, v).to_array());
                    let t = bilerp(uv, u, v);
                    mesh.uvs.as_mut().expect("set").extend([t.x, t.y]);
                    if let (Some(nn), Some(out)) = (&given_n, &mut mesh.normals) {
                        let c = [0, 1, 2, 3].map(|k| at(nn, 3, q[k]));
                        out.extend(bilerp(c, u, v).normalize_or_zero().to_array());
                    }
                }
            }
            let row = steps as u32 + 1;
            for j in 0..steps as u32 {
                for i in 0..steps as u32 {
                    let a = base + j * row + i;
                    let (b, c, d) = (a + 1, a + row + 1, a + row);
                    mesh.indices.extend([a, b, c, a, c, d]);
                }
            }
        }
        if curved {
            self.note(loc, what, &format!("curved bilinear patches tessellated into {PATCH_STEPS} x {PATCH_STEPS} quads each"));
        }
        mesh.orient_to_normals();
        Ok(Some(mesh))
    }

    /// A `loopsubdiv` (`levels` 3, `P`, `indices`): Loop's subdivision surface refined at
    /// load, as pbrt-v4's `LoopSubdivide` does: `levels` rounds of splitting every triangle
    /// in four, then every vertex moved to its limit position; vertex normals the
    /// area-weighted normals of the refined triangles (pbrt-v4 takes the limit surface's
    /// tangents: the same to within the refinement).
    fn loop_subdivision(
        &mut self,
        p: &mut Bag,
        what: &str,
        loc: &Loc,
    ) -> Result<Option<InlineMesh>> {
        let levels = p.int("levels", 3)?;
        p.string_opt("scheme")?;
        let Some(base) = self.triangle_mesh(p, what, loc)? else {
            return Ok(None);
        };
        if !(0..=10).contains(&levels) {
            return Err(loc.error(what, format!("\"levels\" {levels}: expected 0 to 10")));
        }
        let triangles = (base.indices.len() / 3) << (2 * levels);
        if triangles > 50_000_000 {
            return Err(loc.error(
                what,
                format!("{levels} levels make {triangles} triangles: more than 50 million"),
            ));
        }
        let points = base
            .positions
            .chunks(3)
            .map(|v| DVec3::new(v[0], v[1], v[2]))
            .collect();
        let tris = base.indices.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
        let (points, tris) = loop_subdivide(points, tris, levels as usize);
        let mut normals = vec![DVec3::ZERO; points.len()];
        for t in &tris {
            let [a, b, c] = t.map(|i| points[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                normals[i as usize] += n;
            }
        }
        Ok(Some(InlineMesh {
            positions: points.iter().flat_map(|v| v.to_array()).collect(),
            indices: tris.iter().flatten().copied().collect(),
            normals: Some(
                normals
                    .iter()
                    .flat_map(|n| n.normalize_or_zero().to_array())
                    .collect(),
            ),
            uvs: None,
            lights: None,
        }))
    }

    /// A `trianglemesh`'s data, checked (None: left out, `lenient`).
    fn triangle_mesh(&mut self, p: &mut Bag, what: &str, loc: &Loc) -> Result<Option<InlineMesh>> {
        let MeshData {
            positions,
            indices,
            normals,
            uvs,
        } = mesh_data(p, what, loc, 3)?;
        if let Some(q) = p.take("S") {
            self.warn(
                &q.loc,
                what,
                "\"S\" (tangents) ignored: foton takes the shading frame from dp/du",
            );
        }
        if let Some(q) = p.take("faceIndices") {
            let _ = q;
        }
        let mut mesh = InlineMesh {
            positions,
            indices,
            normals,
            uvs,
            lights: None,
        };
        mesh.orient_to_normals();
        Ok(Some(mesh))
    }
}

/// A mesh's vertices (`P`), its elements' vertex indices (`indices`, `corners` a face; they
/// may be left out for a single face), and per-vertex `N` and `uv`, checked.
struct MeshData {
    positions: Vec<f64>,
    indices: Vec<u32>,
    normals: Option<Vec<f64>>,
    uvs: Option<Vec<f64>>,
}

fn mesh_data(p: &mut Bag, what: &str, loc: &Loc, corners: usize) -> Result<MeshData> {
    let (positions, ploc) = p
        .numbers("P", &[Type::Point3])?
        .ok_or_else(|| loc.error(what, "missing \"point3 P\" (the vertices)"))?;
    let n = positions.len() / 3;
    let indices = match p.numbers("indices", &[Type::Integer])? {
        Some((v, l)) => {
            if v.len() % corners != 0 {
                return Err(l.error(
                    what,
                    format!(
                        "\"indices\": {} values, not a multiple of {corners}",
                        v.len()
                    ),
                ));
            }
            if let Some(bad) = v.iter().find(|&&i| i < 0.0 || i as usize >= n) {
                return Err(l.error(
                    what,
                    format!("\"indices\": {bad} is out of range: there are {n} vertices"),
                ));
            }
            v.iter().map(|&i| i as u32).collect()
        }
        None if n == corners => (0..corners as u32).collect(),
        None => {
            return Err(ploc.error(
                what,
                format!("missing \"integer indices\" (only a mesh of exactly {corners} vertices may leave them out)"),
            ));
        }
    };
    let mut per_vertex = |name: &str, ty: Type, width: usize| -> Result<Option<Vec<f64>>> {
        match p.numbers(name, &[ty])? {
            Some((v, l)) if v.len() != n * width => Err(l.error(
                what,
                format!(
                    "\"{name}\": {} values for {n} vertices, expected {}",
                    v.len(),
                    n * width
                ),
            )),
            v => Ok(v.map(|(v, _)| v)),
        }
    };
    let normals = per_vertex("N", Type::Normal, 3)?;
    let uvs = per_vertex("uv", Type::Point2, 2)?;
    Ok(MeshData {
        positions,
        indices,
        normals,
        uvs,
    })
}

/// Loop's subdivision: `levels` rounds of Loop's rules, then the limit positions.
///
/// Each round keeps the triangles' winding and splits each in four at new vertices on its
/// edges. An edge shared by two triangles puts its vertex at 3/8 of each end and 1/8 of each
/// opposite vertex, a boundary edge at its middle; an old vertex of valence n inside the
/// mesh moves to (1 - n beta) v + beta (sum of its neighbours), beta = 3/16 for n = 3 and
/// 3 / (8 n) otherwise, one on the boundary to 3/4 v + 1/8 of each of its two boundary
/// neighbours. At the end each vertex goes to its limit: inside, the same rule with gamma =
/// 1 / (n + 3 / (8 beta)); on the boundary, 3/5 v + 1/5 of each boundary neighbour.
fn loop_subdivide(
    mut p: Vec<DVec3>,
    mut tris: Vec<[u32; 3]>,
    levels: usize,
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    use std::collections::HashMap;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let beta = |n: usize| {
        if n == 3 {
            3.0 / 16.0
        } else {
            3.0 / (8.0 * n as f64)
        }
    };
    // Per vertex: its neighbours, and those along boundary edges.
    let rings = |p: &[DVec3], tris: &[[u32; 3]]| {
        let mut opposite: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        for t in tris {
            for k in 0..3 {
                opposite
                    .entry(key(t[k], t[(k + 1) % 3]))
                    .or_default()
                    .push(t[(k + 2) % 3]);
            }
        }
        let mut ring = vec![Vec::new(); p.len()];
        let mut boundary = vec![Vec::new(); p.len()];
        let mut edges: Vec<_> = opposite.iter().collect();
        edges.sort_unstable_by_key(|(k, _)| **k);
        for &(&(a, b), o) in &edges {
            ring[a as usize].push(b);
            ring[b as usize].push(a);
            if o.len() == 1 {
                boundary[a as usize].push(b);
                boundary[b as usize].push(a);
            }
        }
        (opposite, ring, boundary)
    };
    let moved =
        |p: &[DVec3], ring: &[Vec<u32>], boundary: &[Vec<u32>], limit: bool| -> Vec<DVec3> {
            (0..p.len())
                .map(|i| {
                    let v = p[i];
                    if boundary[i].is_empty() {
                        let n = ring[i].len();
                        if n == 0 {
                            return v;
                        }
                        let w = if limit {
                            1.0 / (n as f64 + 3.0 / (8.0 * beta(n)))
                        } else {
                            beta(n)
                        };
                        let sum: DVec3 = ring[i].iter().map(|&j| p[j as usize]).sum();
                        (1.0 - n as f64 * w) * v + w * sum
                    } else if boundary[i].len() == 2 {
                        let w = if limit { 1.0 / 5.0 } else { 1.0 / 8.0 };
                        let [a, b] = [boundary[i][0], boundary[i][1]].map(|j| p[j as usize]);
                        (1.0 - 2.0 * w) * v + w * (a + b)
                    } else {
                        // A non-manifold corner: kept where it is.
                        v
                    }
                })
                .collect()
        };
    for _ in 0..levels {
        let (opposite, ring, boundary) = rings(&p, &tris);
        let mut next = moved(&p, &ring, &boundary, false);
        let mut edge_vertex: HashMap<(u32, u32), u32> = HashMap::new();
        let mut split = Vec::with_capacity(tris.len() * 4);
        for t in &tris {
            let mut mid = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                mid[k] = *edge_vertex.entry(key(a, b)).or_insert_with(|| {
                    let o = &opposite[&key(a, b)];
                    let (pa, pb) = (p[a as usize], p[b as usize]);
                    next.push(if o.len() == 2 {
                        3.0 / 8.0 * (pa + pb) + 1.0 / 8.0 * (p[o[0] as usize] + p[o[1] as usize])
                    } else {
                        0.5 * (pa + pb)
                    });
                    next.len() as u32 - 1
                });
            }
            let [ab, bc, ca] = mid;
            split.extend([[t[0], ab, ca], [t[1], bc, ab], [t[2], ca, bc], [ab, bc, ca]]);
        }
        p = next;
        tris = split;
    }
    let (_, ring, boundary) = rings(&p, &tris);
    (moved(&p, &ring, &boundary, true), tris)
}

/// Facets of a cylinder per full turn (as the Mitsuba reader's cylinders).
const CYLINDER_FACETS: usize = 64;

/// Quads per side of a curved bilinear patch.
const PATCH_STEPS: usize = 8;

/// A `trianglemesh` as the document's inline mesh: flat lists, 3 numbers a vertex, 3 indices
/// a triangle.
struct InlineMesh {
    positions: Vec<f64>,
    indices: Vec<u32>,
    normals: Option<Vec<f64>>,
    uvs: Option<Vec<f64>>,
    /// How many lights pbrt-v4 makes of the shape under an area light (each normalises
    /// `power` by its own area): one per patch of a bilinear mesh, one for a cylinder;
    /// None: one per triangle.
    lights: Option<usize>,
}

impl InlineMesh {
    fn vertex(v: &[f64], i: u32) -> DVec3 {
        let i = i as usize * 3;
        DVec3::new(v[i], v[i + 1], v[i + 2])
    }

    /// pbrt-v4 turns a triangle's geometric normal towards its interpolated vertex normal:
    /// where the winding disagrees with the vertex normals, it is reversed here.
    fn orient_to_normals(&mut self) {
        let Some(n) = &self.normals else { return };
        for t in self.indices.chunks_mut(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| Self::vertex(&self.positions, i));
            let winding = (b - a).cross(c - a);
            let shading: DVec3 = [t[0], t[1], t[2]].iter().map(|&i| Self::vertex(n, i)).sum();
            if winding.dot(shading) < 0.0 {
                t.swap(1, 2);
            }
        }
    }

    /// The area pbrt-v4 normalises an area light's `power` by: each triangle of a mesh
    /// (each patch of a bilinear mesh) is a light of its own, of its own area, so the mesh
    /// emits `power` per triangle. foton gives the mesh one radiance: that of the mean
    /// light, which keeps the total power and is exact where they are of one area (a quad's
    /// two triangles).
    fn light_area(&self, m: DMat4) -> f64 {
        let n = self.lights.unwrap_or(self.indices.len() / 3).max(1);
        self.area(m) / n as f64
    }

    fn area(&self, m: DMat4) -> f64 {
        self.indices
            .chunks(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]]
                    .map(|i| m.transform_point3(Self::vertex(&self.positions, i)));
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    fn entries(&self, r: &Reader, loc: &Loc) -> Vec<(&'static str, Node)> {
        let nums = |v: &[f64]| {
            r.node(
                Value::Array(v.iter().map(|x| r.num(*x, loc)).collect()),
                loc,
            )
        };
        let mut e = vec![
            ("positions", nums(&self.positions)),
            (
                "indices",
                r.node(
                    Value::Array(
                        self.indices
                            .iter()
                            .map(|&i| r.node(Value::Int(i64::from(i)), loc))
                            .collect(),
                    ),
                    loc,
                ),
            ),
        ];
        if let Some(n) = &self.normals {
            e.push(("normals", nums(n)));
        }
        if let Some(uv) = &self.uvs {
            e.push(("uvs", nums(uv)));
        }
        e
    }
}

/// The uniform scale of a transform's linear part when it is a rotation (or mirror) times a
/// uniform scale.
fn uniform_scale(m: DMat4) -> Option<f64> {
    let l = DMat3::from_mat4(m);
    let s = l.x_axis.length();
    let ok =
        |a: DVec3, b: DVec3| (a.length() - s).abs() <= 1e-6 * s && a.dot(b).abs() <= 1e-6 * s * s;
    (s > 0.0 && ok(l.y_axis, l.z_axis) && ok(l.z_axis, l.x_axis) && ok(l.x_axis, l.y_axis))
        .then_some(s)
}

impl Reader {
    /// The emission of a shape under the `AreaLightSource` `d` (pbrt-v4's `DiffuseAreaLight`):
    /// `L` (default: the colour space's illuminant, white), or an image `filename` looked
    /// up at the shape's (u, 1 - v) (bilinear, clamped at its edges; PNG sRGB-decoded, other
    /// files linear), times `scale`; `power` sets the emitted power (with the shape's
    /// `area`, over both sides when `twosided`; an image's power by its mean luminance);
    /// and whether it is two-sided. None: nothing emitted (left out, `lenient`).
    fn area_light(&mut self, d: &Directive, area: Option<f64>) -> Result<Option<(Node, bool)>> {
        let mut p = Bag::new(d);
        let what = d.what();
        if d.string(0) != "diffuse" {
            return Err(d
                .loc
                .error(&what, "unknown area light; pbrt-v4 has diffuse"));
        }
        let l = match p.take("L") {
            Some(q) => Some(rgb(&q, Kind::Illuminant, &what, &self.dir)?),
            None => None,
        };
        let mut scale = p.float("scale", 1.0)?;
        // The image and the mean luminance of its pixels (pbrt-v4's k_e for `power`).
        let image = match p.string_opt("filename")? {
            Some((f, fl)) => {
                if l.is_some() {
                    return Err(fl.error(
                        &what,
                        "both \"L\" and \"filename\" are given; pbrt-v4 takes one of them",
                    ));
                }
                let path = super::parse::resolve(&self.dir, &fl.file, &f);
                let png = f.to_ascii_lowercase().ends_with(".png");
                let decode = if png {
                    crate::texture::Decode::Srgb
                } else {
                    crate::texture::Decode::Linear
                };
                let bitmap = crate::texture::load_bitmap_decoded(&path, decode)
                    .map_err(|e| fl.error(&what, format!("\"filename\" {f:?}: {e}")))?;
                let mean = bitmap.mean().as_dvec3();
                Some((f, fl, png, super::spectra::luminance(mean)))
            }
            None => None,
        };
        let twosided = p.bool("twosided", false)?;
        let sides = if twosided { 2.0 } else { 1.0 };
        if let Some((phi, pl)) = p.float_opt("power")?
            && phi > 0.0
        {
            // k_e: the power of unit radiance (pbrt-v4 does not count an rgb's colour; an
            // image's mean luminance it does).
            let k = image.as_ref().map_or(1.0, |i| i.3);
            match area {
                Some(a) if a > 0.0 && k > 0.0 => {
                    scale *= phi / (k * sides * std::f64::consts::PI * a)
                }
                _ => {
                    self.unsupported(
                        &pl,
                        &what,
                        "\"power\" on a shape whose area the reader does not know (a plymesh)",
                    )?;
                }
            }
        }
        self.finish(&mut p)?;
        let loc = &d.loc;
        let emission = match image {
            None => self.vec3(l.unwrap_or(DVec3::ONE) * scale, loc),
            Some((f, fl, png, _)) => {
                let mut entries = vec![
                    ("type", self.string("bitmap", loc)),
                    ("filename", self.string(&f, &fl)),
                    ("wrap_mode", self.string("clamp", loc)),
                    ("to_uv", self.to_uv([1.0, -1.0], [0.0, 1.0], loc)),
                ];
                if !png {
                    entries.push(("raw", self.node(Value::Bool(true), loc)));
                }
                if scale != 1.0 {
                    entries.push(("scale", self.num(scale, loc)));
                }
                self.table(entries, loc)
            }
        };
        Ok(Some((emission, twosided)))
    }
}
