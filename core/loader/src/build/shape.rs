//! `[[shapes]]`: spheres, quads, disks, meshes (read through [`crate::mesh`]), round curves
//! (read through [`crate::curve`]) and the zero sets of signed distance grids (meshed by
//! [`crate::sdfgrid`]), each with its material, its emission (an area light) and the media on
//! its two sides.

use super::common::{
    Geometry, Index, Loader, array_of_tables, read_transform_at, type_of, undefined,
};
use super::material::ShadingMaps;
use super::medium::medium_ref;
use crate::curve::Basis;
use crate::mesh::{MeshOptions, inline_mesh, load_mesh};
use crate::sdfgrid::{MAX_SUBDIVISIONS, SdfNormals, sdf_mesh};
use foton_core::Rgb;
use foton_core::error::Result;
use foton_core::geometry::{NO_ATTRS, Primitive, Shape, TriangleAttrs};
use foton_core::light::Light;
use foton_core::light::area::AreaLight;
use foton_core::material::Material;
use foton_core::medium::grid::VolFile;
use foton_core::props::Properties;
use foton_core::registry::Resources;
use foton_core::scene::{Named, Object};
use foton_core::texture::{Texture, luminance};
use foton_core::value::Value;
use glam::{Mat3, Mat4, Vec2, Vec3};

/// Sub-cells per grid cell along each axis in which an `sdfgrid`'s surface is meshed: its
/// trilinear zero set is followed to within a small fraction of a sub-cell.
const SDF_SUBDIVISIONS: usize = 4;

const SHAPE_TYPES: &[&str] = &["sphere", "quad", "disk", "mesh", "curve", "sdfgrid"];

fn read_transform(s: &Properties<'_>, ld: &mut Loader) -> Result<Mat4> {
    read_transform_at(s, "transform", ld)
}

pub(super) fn read_shapes(
    root: &Properties<'_>,
    ld: &mut Loader,
    material_defs: &[Named<Material>],
    materials: &Index,
    normal_maps: &[ShadingMaps],
    media: &Index,
    g: &mut Geometry,
) -> Result<()> {
    for s in array_of_tables(root, "shapes")? {
        let ty = type_of(&s, SHAPE_TYPES)?;
        let mut closed = ty == "sphere";
        let flip = s.bool("flip_normals", false)?;
        let mut attrs = Vec::new();
        let mut attribute = Vec::new();
        let attribute_name = mesh_attribute_of(root, &s)?;
        if let Some(name) = &attribute_name
            && ty != "mesh"
        {
            return Err(s.error(
                "material",
                format!("the material reads the mesh attribute `{name}`, which only a mesh carries (this shape is a {ty})"),
            ));
        }
        let mut shapes = match ty {
            "sphere" => {
                let center = s.vec3_required("center")?;
                let radius = s.f32_required("radius")?;
                if radius <= 0.0 {
                    return Err(s.error("radius", format!("must be positive, found {radius}")));
                }
                match s.floats_opt("axes", 9)? {
                    None => vec![Shape::sphere(center, radius)],
                    Some(a) => {
                        let rows = [
                            Vec3::new(a[0], a[1], a[2]),
                            Vec3::new(a[3], a[4], a[5]),
                            Vec3::new(a[6], a[7], a[8]),
                        ];
                        let orthonormal = rows.iter().all(|r| (r.length() - 1.0).abs() < 1e-3)
                            && rows[0].dot(rows[1]).abs() < 1e-3
                            && rows[1].dot(rows[2]).abs() < 1e-3
                            && rows[2].dot(rows[0]).abs() < 1e-3;
                        if !orthonormal {
                            return Err(s.error(
                                "axes",
                                "expected three orthonormal rows: the directions of the sphere's x, y and z axes",
                            ));
                        }
                        let to_local = Mat3::from_cols(rows[0], rows[1], rows[2]).transpose();
                        vec![Shape::sphere_with_axes(center, radius, to_local)]
                    }
                }
            }
            "quad" => {
                let origin = s.vec3_required("origin")?;
                let u = s.vec3_required("u")?;
                let v = s.vec3_required("v")?;
                if u.cross(v).length_squared() == 0.0 {
                    return Err(
                        s.error("v", "u and v are parallel or zero: the quad has zero area")
                    );
                }
                vec![Shape::quad(origin, u, v)]
            }
            "disk" => {
                let center = s.vec3_required("center")?;
                // Either the two semi-axes (an ellipse; Mitsuba's disk under its to_world, which
                // also fixes where the angle of its texture coordinates starts) or a circle.
                let (u, v) = if s.has("u") || s.has("v") {
                    (s.vec3_required("u")?, s.vec3_required("v")?)
                } else {
                    let normal = s.vec3_required("normal")?;
                    let radius = s.f32_required("radius")?;
                    if radius <= 0.0 {
                        return Err(s.error("radius", format!("must be positive, found {radius}")));
                    }
                    if normal.length_squared() == 0.0 {
                        return Err(s.error("normal", "must not be the zero vector"));
                    }
                    let f = foton_core::bsdf::Frame::from_normal(normal.normalize());
                    (f.s * radius, f.t * radius)
                };
                if u.cross(v).length_squared() == 0.0 {
                    return Err(
                        s.error("v", "u and v are parallel or zero: the disk has zero area")
                    );
                }
                vec![Shape::disk(center, u, v)]
            }
            "mesh" => {
                let transform = read_transform(&s, ld)?;
                let options = MeshOptions {
                    face_normals: s.bool("face_normals", false)?,
                    flip_tex_coords: s.bool("flip_tex_coords", true)?,
                    flip_normals: flip,
                    compute_normals: s.bool("compute_normals", true)?,
                };
                // The triangles written in the scene (a pbrt-v4 trianglemesh), or a file.
                let mesh = if s.has("positions") && !s.has("file") {
                    inline_mesh(&s, transform, options)?
                } else {
                    let file = s.string_required("file")?;
                    let path = ld.dir.join(file);
                    let mesh = load_mesh(&s, &path, transform, options, attribute_name.as_deref())?;
                    ld.sources.push(path);
                    mesh
                };
                // Closedness matters only to a shape that may bound a medium (as
                // `volumes::medium_interfaces` decides): one with media named, or whose
                // material is null or encloses a volume. An unknown material is an error below.
                let may_bound = s.has("interior")
                    || s.has("exterior")
                    || s.string_opt("material")?
                        .and_then(|m| materials.get(m))
                        .is_none_or(|&m| {
                            let m = &material_defs[m as usize].value;
                            m.is_null() || m.encloses_volume()
                        });
                closed = may_bound && mesh.closed();
                attrs = mesh.attrs;
                attribute = mesh.attribute;
                mesh.triangles
            }
            "curve" => {
                let transform = read_transform(&s, ld)?;
                let basis = match s.choice("basis", &["linear", "bspline"], "linear")? {
                    "linear" => Basis::Linear,
                    _ => Basis::BSpline,
                };
                if flip {
                    return Err(s.error(
                        "flip_normals",
                        "a curve has no inside to turn out (nor has Mitsuba's)",
                    ));
                }
                let file = s.string_required("file")?;
                let path = ld.dir.join(file);
                let text = std::fs::read_to_string(&path).map_err(|e| {
                    s.error(
                        "file",
                        format!("cannot read curve file {}: {e}", path.display()),
                    )
                })?;
                let curves = crate::curve::parse(&text, basis).map_err(|(line, message)| {
                    let at = if line > 0 {
                        format!("{}:{line}", path.display())
                    } else {
                        path.display().to_string()
                    };
                    s.error("file", format!("{at}: {message}"))
                })?;
                let radius_scale = s.f32("radius_scale", 1.0)?;
                if !(radius_scale > 0.0 && radius_scale.is_finite()) {
                    return Err(s.error(
                        "radius_scale",
                        format!("must be positive, found {radius_scale}"),
                    ));
                }
                ld.sources.push(path);
                crate::curve::pieces(&curves, basis, transform, radius_scale)
            }
            "sdfgrid" => {
                let transform = read_transform(&s, ld)?;
                let normals = match s.choice("normals", &["smooth", "analytic"], "smooth")? {
                    "smooth" => SdfNormals::Smooth,
                    _ => SdfNormals::Analytic,
                };
                let subdivisions = s.u32("subdivisions", SDF_SUBDIVISIONS as u32)?;
                if !(1..=MAX_SUBDIVISIONS as u32).contains(&subdivisions) {
                    return Err(s.error(
                        "subdivisions",
                        format!("expected 1 to {MAX_SUBDIVISIONS}, found {subdivisions}"),
                    ));
                }
                let file = s.string_required("file")?;
                let path = ld.dir.join(file);
                let fail = |m: String| s.error("file", format!("{}: {m}", path.display()));
                let bytes = std::fs::read(&path).map_err(|e| fail(format!("cannot read: {e}")))?;
                let vol = VolFile::parse(&bytes).map_err(fail)?;
                let mesh = sdf_mesh(&vol, normals, subdivisions as usize).map_err(fail)?;
                ld.sources.push(path);
                let normal_matrix = Mat3::from_mat4(transform).inverse().transpose();
                let mirrored = transform.determinant() < 0.0;
                let mut shapes = Vec::with_capacity(mesh.triangles.len());
                for (tri, n) in mesh.triangles.iter().zip(&mesh.normals) {
                    let mut p = tri.map(|q| transform.transform_point3(q));
                    let mut n = n.map(|v| (normal_matrix * v).normalize_or_zero());
                    // A mirroring reverses the winding: put the outside back in front.
                    if mirrored {
                        p.swap(1, 2);
                        n.swap(1, 2);
                    }
                    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
                    if e1.cross(e2).length_squared() == 0.0 {
                        continue;
                    }
                    shapes.push(Shape::Triangle { p0: p[0], e1, e2 });
                    // Mitsuba's sdfgrid has no texture coordinates: (0, 0) everywhere.
                    attrs.push(TriangleAttrs {
                        normals: Some(n),
                        uvs: Some([Vec2::ZERO; 3]),
                    });
                }
                shapes
            }
            other => {
                return Err(s.error(
                    "type",
                    format!(
                        "unknown shape type {other:?}; expected one of: {}",
                        SHAPE_TYPES.join(", ")
                    ),
                ));
            }
        };
        if flip {
            if ty == "sphere" && s.has("interior") && !s.has("exterior") {
                return Err(s.error(
                    "flip_normals",
                    "a sphere turned inside out cannot hold an interior medium (its inside would be all of space outside it)",
                ));
            }
            if ty != "mesh" {
                // The mesh reader reversed its triangles itself.
                shapes.iter_mut().for_each(Shape::flip);
            }
        }
        // The BVH is built in f32: coordinates beyond 1e15 overflow its cost estimates (and
        // any renderer's precision long before).
        if let Some(b) = shapes.iter().map(Shape::aabb).find(|b| {
            let (lo, hi) = (Vec3::from(b.min), Vec3::from(b.max));
            !(lo.is_finite() && hi.is_finite() && lo.abs().max(hi.abs()).max_element() <= 1e15)
        }) {
            let key = ["positions", "file", "center", "origin"]
                .into_iter()
                .find(|k| s.has(k))
                .unwrap_or("type");
            return Err(s.error(
                key,
                format!(
                    "the shape reaches from {} to {}: coordinates must be finite and within 1e15",
                    Vec3::from(b.min),
                    Vec3::from(b.max)
                ),
            ));
        }
        if ty == "curve" {
            for (key, what) in [
                ("sensor", "the surface of an irradiance meter"),
                ("emission", "an area light"),
            ] {
                if s.has(key) && (key == "emission" || s.bool(key, false)?) {
                    return Err(s.error(
                        key,
                        format!(
                            "a curve cannot be {what} (nor can Mitsuba 3 sample a point on one)"
                        ),
                    ));
                }
            }
        }
        if s.bool("sensor", false)? {
            if !g.meter_wanted {
                return Err(s.error(
                    "sensor",
                    "marks the surface of an irradiance meter, and the camera is not one (`[camera] type = \"irradiancemeter\"`)",
                ));
            }
            g.sensor
                .get_or_insert_default()
                .extend(shapes.iter().cloned());
        }
        let material_name = s.string_required("material")?;
        let material = *materials
            .get(material_name)
            .ok_or_else(|| s.error("material", undefined("material", material_name, materials)))?;
        // With `exterior` the file names both sides (Mitsuba's media: interior behind the
        // normal, exterior in front, whatever the shape); with `interior` alone the shape
        // must close its medium in, and its outside is found from where it lies.
        let exterior = medium_ref(&s, "exterior", media)?;
        let interior = medium_ref(&s, "interior", media)?;
        if let (Some(inside), None) = (interior, exterior) {
            if inside.is_none() {
                return Err(s.error(
                    "interior",
                    "`vacuum` as the only medium of a shape says nothing; give `exterior` too",
                ));
            }
            if !closed {
                return Err(s.error(
                    "interior",
                    format!("a {ty} that is not closed cannot hold an interior medium by itself: light would leak out of the medium through its edges (a mesh needs every edge shared by exactly two consistently oriented triangles); close it, or give `exterior` too (the medium on the side its normal points to) if other shapes close the medium"),
                ));
            }
        }
        let explicit_media = exterior.is_some();
        let (interior, exterior) = (interior.flatten(), exterior.flatten());
        let alpha = read_alpha(&s, ld)?;
        if alpha.is_some() && (interior.is_some() || exterior.is_some()) {
            return Err(s.error(
                "alpha",
                "a cut-out shape cannot bound a medium (a ray through its cut-out parts would leave the medium's volume undefined); give the medium to a shape without `alpha`",
            ));
        }
        let object = g.objects.len() as u32;
        let mut light = None;
        // A colour, or a texture (radiance varying over the surface, at its uv).
        let emission = if s.has("emission") {
            Some(ld.texture(&s, "emission", Rgb::ZERO)?)
        } else {
            None
        };
        // An area light looks its textures up by uv alone.
        let by_point =
            |t: &Texture| matches!(t, Texture::MeshAttribute { .. } | Texture::Volume(_));
        if let Some(t) = emission.as_ref().filter(|t| by_point(t)) {
            let what = match t.mesh_attribute() {
                Some(name) => format!("the mesh attribute `{name}`"),
                None => "a volume texture".to_string(),
            };
            return Err(s.error(
                "emission",
                format!("{what} as emitted radiance is not supported yet"),
            ));
        }
        if emission
            .as_ref()
            .is_some_and(|e| e.max().max_element() > 0.0)
            && alpha.as_ref().is_some_and(by_point)
        {
            return Err(s.error(
                "alpha",
                "a mesh attribute or a volume texture as the cut-out of an emitting shape is not supported yet",
            ));
        }
        if let Some(emission) = emission
            && emission.max().max_element() > 0.0
        {
            if material_defs[material as usize].value.is_null() {
                return Err(s.error(
                    "emission",
                    "a shape with the null material is invisible and cannot emit; give it a real material (e.g. a black diffuse one)",
                ));
            }
            light = Some(g.lights.len() as u32);
            let twosided = s.bool("emission_twosided", false)?;
            let (radiance, texture) = match emission {
                Texture::Constant(c) => (c, None),
                texture => (Rgb::ONE, Some(texture)),
            };
            let mut area = AreaLight::new(shapes.clone(), radiance, object);
            if texture.is_some() || alpha.is_some() {
                area = area.with_texture(texture, alpha.clone(), attrs.clone());
            }
            g.lights.push(Light::Area(area.with_twosided(twosided)));
            // Mitsuba's area emitter emits into its shape's exterior.
            g.light_media.push(explicit_media.then_some(exterior));
        }
        g.objects.push(Object {
            name: s.path().to_string(),
            material,
            light,
            interior,
            exterior,
            explicit_media,
            closed,
            alpha,
            normal_map: normal_maps[material as usize].normal_map.clone(),
            bump_map: normal_maps[material as usize].bump_map.clone(),
            map_light: normal_maps[material as usize].map_light,
        });
        let first_attrs = g.triangle_attrs.len() as u32;
        let with_attrs = !attrs.is_empty();
        g.triangle_attrs.extend(attrs);
        if !attribute.is_empty() {
            // Aligned with `triangle_attrs`: zero for the triangles of meshes without one.
            g.triangle_attributes
                .resize(first_attrs as usize, [Vec3::ZERO; 3]);
            g.triangle_attributes.extend(attribute);
        }
        g.primitives
            .extend(shapes.into_iter().enumerate().map(|(i, shape)| Primitive {
                shape,
                object,
                attrs: if with_attrs {
                    first_attrs + i as u32
                } else {
                    NO_ATTRS
                },
            }));
        ld.done(&s);
    }
    Ok(())
}

/// The name of the mesh attribute that shape `s` reads (a `mesh_attribute` texture anywhere in
/// its material's table under `[materials]`, or as its `alpha`), if any; a shape may read one.
fn mesh_attribute_of(root: &Properties<'_>, s: &Properties<'_>) -> Result<Option<String>> {
    fn scan(v: &Value, names: &mut Vec<String>) {
        match v {
            Value::Table(t) => {
                let is_attribute = t
                    .get("type")
                    .is_some_and(|n| matches!(&n.value, Value::Str(ty) if ty == "mesh_attribute"));
                if is_attribute
                    && let Some(Value::Str(name)) = t.get("name").map(|n| &n.value)
                    && !names.contains(name)
                {
                    names.push(name.clone());
                }
                for key in t.keys() {
                    if let Some(n) = t.get(key) {
                        scan(&n.value, names);
                    }
                }
            }
            Value::Array(items) => items.iter().for_each(|n| scan(&n.value, names)),
            _ => {}
        }
    }
    let mut names = Vec::new();
    if let Some(alpha) = s.node("alpha") {
        scan(&alpha.value, &mut names);
    }
    if let (Some(Value::Str(material)), Some(Value::Table(materials))) = (
        s.node("material").map(|n| &n.value),
        root.node("materials").map(|n| &n.value),
    ) && let Some(m) = materials.get(material)
    {
        scan(&m.value, &mut names);
    }
    match names.len() {
        0 => Ok(None),
        1 => Ok(names.pop()),
        _ => Err(s.error(
            "material",
            format!(
                "the shape's material and alpha read the mesh attributes {}: foton carries one per shape",
                names.join(" and ")
            ),
        )),
    }
}

/// The shape's `alpha`: a number in [0, 1], an RGB or a texture table (its luminance); None
/// where it is opaque everywhere (absent, or 1).
fn read_alpha(s: &Properties<'_>, ld: &mut Loader) -> Result<Option<Texture>> {
    let Some(node) = s.node("alpha") else {
        return Ok(None);
    };
    if matches!(node.value, Value::Table(_)) {
        let t = ld.texture(s, "alpha", Rgb::ONE)?;
        if luminance(t.max()) > 1.0 + 1e-6 {
            return Err(s.error(
                "alpha",
                "the texture's values must lie in [0, 1] (0: cut out, 1: opaque)",
            ));
        }
        return Ok(Some(t));
    }
    if matches!(node.value, Value::Array(_)) {
        let c = s.rgb("alpha", Rgb::ONE)?;
        let a = luminance(c);
        if c.min_element() < 0.0 || a > 1.0 + 1e-6 {
            return Err(s.error(
                "alpha",
                format!(
                    "expected a colour of luminance in [0, 1] (0: cut out, 1: opaque), found {c}"
                ),
            ));
        }
        return Ok((a < 1.0 - 1e-6).then_some(Texture::Constant(c)));
    }
    let a = s.f32("alpha", 1.0)?;
    if !(0.0..=1.0).contains(&a) {
        return Err(s.error(
            "alpha",
            format!("expected a number in [0, 1] (0: cut out, 1: opaque), found {a}"),
        ));
    }
    Ok((a < 1.0).then(|| Texture::Constant(Rgb::splat(a))))
}
