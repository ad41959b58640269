//! `<shape>`: meshes (obj, ply, serialized), spheres, disks, rectangles, cubes and cylinders as
//! `[[shapes]]` entries, each with its material (a nested or referenced BSDF, or Mitsuba's
//! default), its area emitter and the media on its two sides; `shapegroup` and `instance`
//! flattened into transformed copies of the group's shapes, `merge` into its shapes.
//!
//! A nested object or a `<ref>` is taken for what it is, as Mitsuba 3 does (a BSDF, an area
//! emitter, a medium named `interior` or `exterior`), whatever the property's name. foton has
//! no analytic cylinder: a `cylinder` is its polygonal prism of [`CYLINDER_FACETS`] flat
//! quads (with a note).

use super::object::{Obj, Prop, show};
use super::plugins::not_read;
use super::{Reader, at, matrix_table, table_mut, vec3};
use foton_core::error::Result;
use foton_core::value::{Node, Table, Value};
use glam::{DMat4, DVec3};

/// Quads of a cylinder: the largest angle between neighbouring facets' normals is 360/64 =
/// 5.6 degrees.
pub(super) const CYLINDER_FACETS: usize = 64;

/// The key of a shape group in the reader's side table `Reader::textures`: ids come from XML
/// attribute values and so never hold a NUL. (A `<ref>` to a top-level area emitter reaches a
/// shape as the emitter itself: the document reader resolves it.)
const GROUP_KEY: &str = "\0shapegroup:";

/// The faces of Mitsuba 3's `cube` (src/shapes/cube.cpp: `side_normals`, `side_uv` and
/// `position_index`), in its order: each its outward normal, then its corners with uv
/// (0, 0), (1, 0) and (0, 1).
#[rustfmt::skip]
fn cube_faces() -> [[DVec3; 4]; 6] {
    [
        //  outward         uv (0, 0)        uv (1, 0)        uv (0, 1)
        [[ 0., -1.,  0.], [-1., -1., -1.], [-1., -1.,  1.], [ 1., -1., -1.]],
        [[ 0.,  1.,  0.], [ 1.,  1.,  1.], [-1.,  1.,  1.], [ 1.,  1., -1.]],
        [[ 1.,  0.,  0.], [ 1., -1.,  1.], [ 1.,  1.,  1.], [ 1., -1., -1.]],
        [[ 0.,  0.,  1.], [-1., -1.,  1.], [-1.,  1.,  1.], [ 1., -1.,  1.]],
        [[-1.,  0.,  0.], [-1., -1., -1.], [-1.,  1., -1.], [-1., -1.,  1.]],
        [[ 0.,  0., -1.], [-1.,  1., -1.], [-1., -1., -1.], [ 1.,  1., -1.]],
    ]
    .map(|face| face.map(DVec3::from_array))
}

impl Reader {
    /// What a `<ref id>` names, for messages about a reference of the wrong kind.
    fn named(&self, id: &str) -> Option<&'static str> {
        if self.bsdfs.contains_key(id) {
            Some("a BSDF")
        } else if self.media.contains_key(id) {
            Some("a medium")
        } else if self.textures.contains_key(&format!("{GROUP_KEY}{id}")) {
            Some("a shapegroup")
        } else if self.textures.contains_key(id) {
            Some("a texture")
        } else {
            None
        }
    }

    pub(super) fn shape(&mut self, mut o: Obj) -> Result<()> {
        match o.ty.as_str() {
            "shapegroup" => return self.shapegroup(o),
            "instance" => return self.instance(o),
            "merge" => return self.merge(o),
            _ => {}
        }
        let line = o.line;
        let m = o.transform("to_world")?;
        // The material: a nested BSDF, a reference, or Mitsuba's default (diffuse 0.5).
        let mut material = None;
        let mut emission = None;
        // Mitsuba's interior (behind the normal) and exterior (in front of it).
        let mut interior = None;
        let mut exterior = None;
        // Whether the shape is the surface of the irradiance meter that renders the file.
        let mut measured = false;
        let props = std::mem::take(&mut o.props);
        for (name, p, l) in props {
            // Errors at the property's own line.
            let here = Obj {
                line: l,
                props: Vec::new(),
                ..o.clone()
            };
            let once = |slot: bool, what: &str| {
                if slot {
                    Err(here.error(format!("a second {what}: a shape has one (as in Mitsuba)")))
                } else {
                    Ok(())
                }
            };
            match p {
                Prop::Object(b) if b.tag == "bsdf" => {
                    once(material.is_some(), "BSDF")?;
                    material = Some(self.bsdf(b)?);
                }
                // Mitsuba 3 takes another kind of emitter in a shape for a light of its own,
                // placed by its own to_world (the shape's plays no part).
                Prop::Object(e) if e.tag == "emitter" && e.ty != "area" => {
                    self.note(
                        &e,
                        "an emitter other than `area` inside a shape is a light of its own, placed by its own to_world, as Mitsuba 3 reads it",
                    );
                    self.emitter(e)?;
                }
                Prop::Object(mut e) if e.tag == "emitter" => {
                    once(emission.is_some(), "emitter")?;
                    // A texture left out (lenient, reported): the default radiance.
                    let radiance = self.texture(&mut e, "radiance", DVec3::ONE)?;
                    emission = Some(radiance.unwrap_or_else(|| vec3(DVec3::ONE, e.line)));
                    // Noise, not the image: see `Reader::emitter`.
                    e.take("sampling_weight");
                    self.manifold_hints(&mut e);
                    self.leftovers(&e)?;
                }
                Prop::Object(med) if med.tag == "medium" => match name.as_str() {
                    "interior" => interior = Some(self.medium(med)?),
                    "exterior" => exterior = Some(self.medium(med)?),
                    // Mitsuba 3 attaches a medium to a shape by these two names only.
                    _ => self.warn(
                        &o,
                        l,
                        &format!(
                            "{} named `{name}` is ignored, as Mitsuba 3 ignores it (a shape's media are named `interior` and `exterior`)",
                            med.what()
                        ),
                    ),
                },
                Prop::Object(sensor) if sensor.tag == "sensor" => {
                    if sensor.ty == "irradiancemeter" {
                        once(measured, "sensor")?;
                        measured = self.irradiance_meter(sensor)?;
                    } else {
                        self.unsupported(
                            &Obj {
                                props: Vec::new(),
                                ..sensor.clone()
                            },
                            "a sensor other than an irradiancemeter attached to a shape is not supported",
                        )?;
                    }
                }
                Prop::Ref(id) if name == "interior" || name == "exterior" => {
                    let Some(found) = self.media.get(&id).cloned() else {
                        let what = self
                            .named(&id)
                            .map_or(String::new(), |k| format!(" (`{id}` is {k})"));
                        return Err(here.error(format!(
                            "<ref name=\"{name}\" id=\"{id}\">: no medium with id `{id}` before it{what}"
                        )));
                    };
                    if name == "interior" {
                        interior = Some(found);
                    } else {
                        exterior = Some(found);
                    }
                }
                Prop::Ref(id) => {
                    if let Some(found) = self.bsdfs.get(&id).cloned() {
                        once(material.is_some(), "BSDF")?;
                        material = Some(Some(found));
                    } else if self.media.contains_key(&id) {
                        self.warn(
                            &o,
                            l,
                            &format!(
                                "<ref id=\"{id}\"> names a medium without saying which side: ignored, as Mitsuba 3 ignores it (name it `interior` or `exterior`)"
                            ),
                        );
                    } else if let Some(kind) = self.named(&id) {
                        return Err(here.error(format!(
                            "<ref id=\"{id}\">: `{id}` is {kind}; a shape takes a BSDF, an area emitter or a medium (`interior`, `exterior`)"
                        )));
                    } else {
                        // Most likely an element left out before (lenient): the shape is
                        // rendered without it, with Mitsuba's default BSDF if it was its BSDF.
                        self.unsupported(
                            &here,
                            &format!(
                                "<ref id=\"{id}\">: no BSDF, area emitter or medium with id `{id}` before it"
                            ),
                        )?;
                    }
                }
                other => o.props.push((name, other, l)),
            }
        }
        let material = match material {
            Some(Some(name)) => name,
            Some(None) => return Ok(()), // left out with its BSDF (lenient)
            // Mitsuba 0.x gives a medium transition without a BSDF the null BSDF (its
            // Shape::configure): an index-matched boundary of the fog (Bitterli's
            // volumetric caustic); Mitsuba 3 gives every shape its diffuse default.
            None if self.v1 && emission.is_none() && (interior.is_some() || exterior.is_some()) => {
                let name = "null_boundary".to_string();
                let mut t = Table::default();
                t.insert("type", at(Value::Str("null".into()), line));
                table_mut(&mut self.root, "materials").insert(&name, at(Value::Table(t), line));
                name
            }
            None => {
                let name = format!("default_diffuse_{line}");
                let mut t = Table::default();
                t.insert("type", at(Value::Str("diffuse".into()), line));
                t.insert("twosided", at(Value::Bool(false), line));
                // ... and an emitter without one an all-absorbing diffuse BSDF: a pure
                // emitter, in Mitsuba 3 (Shape's constructor, 3.0 to 3.9) as in 0.x.
                if emission.is_some() {
                    t.insert("reflectance", vec3(DVec3::ZERO, line));
                }
                table_mut(&mut self.root, "materials").insert(&name, at(Value::Table(t), line));
                name
            }
        };
        let flip_normals = o.boolean("flip_normals", false)?;
        let mut shapes: Vec<Table> = Vec::new();
        let quad = |origin: DVec3, u: DVec3, v: DVec3| {
            let mut t = Table::default();
            t.insert("type", at(Value::Str("quad".into()), line));
            t.insert("origin", vec3(origin, line));
            t.insert("u", vec3(u, line));
            t.insert("v", vec3(v, line));
            t
        };
        // A shape's normal is its transformed normal, M^-T n; u x v = det(M) M^-T (x x y)
        // points the other way under a mirroring to_world: flipped back (which keeps the
        // texture coordinates, as swapping the edges would not).
        let mirrored = m.determinant() < 0.0;
        let flip = mirrored != flip_normals;
        let rectangle = |corner: DVec3, a: DVec3, b: DVec3| {
            let origin = m.transform_point3(corner);
            let (u, v) = (m.transform_vector3(a), m.transform_vector3(b));
            let mut t = quad(origin, u, v);
            if flip {
                t.insert("flip_normals", at(Value::Bool(true), line));
            }
            t
        };
        match o.ty.as_str() {
            "obj" | "ply" | "serialized" => {
                let file = self.filename(&mut o)?;
                let mut t = Table::default();
                t.insert("type", at(Value::Str("mesh".into()), line));
                if o.boolean("face_normals", false)? {
                    t.insert("face_normals", at(Value::Bool(true), line));
                }
                // Mitsuba flips an OBJ's v unless told not to, a PLY's only when told.
                if o.ty == "obj" && !o.boolean("flip_tex_coords", true)? {
                    t.insert("flip_tex_coords", at(Value::Bool(false), line));
                }
                if o.ty == "ply" && o.boolean("flip_tex_coords", false)? {
                    t.insert("flip_tex_coords", at(Value::Bool(true), line));
                }
                if flip_normals {
                    t.insert("flip_normals", at(Value::Bool(true), line));
                }
                if o.ty == "serialized" {
                    let index = o.int("shape_index", 0)?;
                    if index < 0 {
                        return Err(o.error(format!(
                            "`shape_index` = {index}: expected a mesh number, 0 or more"
                        )));
                    }
                    if index > 0 {
                        t.insert("shape_index", at(Value::Int(index), line));
                    }
                }
                // Mitsuba 0.6's: an OBJ's groups as separate shapes (the same surfaces), its
                // MTL materials for a shape without a BSDF, a PLY's vertex colours as sRGB.
                self.ignored(&mut o, "collapse", &|_| true, "");
                self.ignored(
                    &mut o,
                    "load_materials",
                    &|p| matches!(p, Prop::Bool(false)),
                    "the OBJ's MTL materials are not read: the shape's BSDF (or Mitsuba's default) is used",
                );
                self.ignored(&mut o, "srgb", &|_| true, "");
                // Mitsuba 0.6's (Mitsuba 3 refuses it): normals smoothed within an angle.
                if let Some((p, l)) = o.take("max_smooth_angle") {
                    let angle = match p {
                        Prop::Float(x) => x,
                        Prop::Int(i) => i as f64,
                        other => {
                            return Err(o.error(format!(
                                "line {l}: `max_smooth_angle`: expected an angle in degrees, found {}",
                                show(&other)
                            )));
                        }
                    };
                    t.insert("max_smooth_angle", at(Value::Float(angle), l));
                }
                t.insert("file", file);
                if m != DMat4::IDENTITY {
                    t.insert("transform", matrix_table(m, line));
                }
                shapes.push(t);
            }
            "linearcurve" | "bsplinecurve" | "sdfgrid" => {
                let file = self.filename(&mut o)?;
                let mut t = Table::default();
                let kind = if o.ty == "sdfgrid" {
                    "sdfgrid"
                } else {
                    "curve"
                };
                t.insert("type", at(Value::Str(kind.into()), line));
                t.insert("file", file);
                if o.ty == "bsplinecurve" {
                    t.insert("basis", at(Value::Str("bspline".into()), line));
                }
                if o.ty == "sdfgrid"
                    && let Some(normals) = o.string("normals")?
                {
                    if normals != "smooth" && normals != "analytic" {
                        return Err(o.error(format!(
                            "`normals` = {normals:?}: expected \"smooth\" or \"analytic\" (as Mitsuba 3)"
                        )));
                    }
                    t.insert("normals", at(Value::Str(normals), line));
                }
                if m != DMat4::IDENTITY {
                    t.insert("transform", matrix_table(m, line));
                }
                // Neither has an inside to turn out in Mitsuba 3: a curve is seen from
                // outside only, a grid's surface from both sides.
                if flip_normals {
                    self.warn(
                        &o,
                        line,
                        &format!(
                            "`flip_normals` on {} is ignored, as Mitsuba 3 ignores it",
                            o.ty
                        ),
                    );
                }
                shapes.push(t);
            }
            "disk" => {
                let mut t = Table::default();
                t.insert("type", at(Value::Str("disk".into()), line));
                t.insert("center", vec3(m.transform_point3(DVec3::ZERO), line));
                t.insert("u", vec3(m.transform_vector3(DVec3::X), line));
                t.insert("v", vec3(m.transform_vector3(DVec3::Y), line));
                if flip {
                    t.insert("flip_normals", at(Value::Bool(true), line));
                }
                shapes.push(t);
            }
            "sphere" => {
                // Mitsuba 3: to_world * translate(center) * scale(radius), whose x axis gives
                // the radius; a non-uniform scale is warned about and rendered so too.
                let center = o.point("center")?.unwrap_or(DVec3::ZERO);
                let radius = o.float("radius", 1.0)?;
                let full =
                    m * DMat4::from_translation(center) * DMat4::from_scale(DVec3::splat(radius));
                if !is_similarity(full) {
                    self.warn(
                        &o,
                        line,
                        "`to_world` scales non-uniformly or shears: rendered, as by Mitsuba 3, as the sphere of radius |to_world x|",
                    );
                }
                let mut t = Table::default();
                t.insert("type", at(Value::Str("sphere".into()), line));
                t.insert("center", vec3(full.transform_point3(DVec3::ZERO), line));
                t.insert(
                    "radius",
                    at(
                        Value::Float(full.transform_vector3(DVec3::X).length()),
                        line,
                    ),
                );
                // A mirroring turns the sphere inside out in Mitsuba 3 (its scale factor is
                // then negative).
                if flip_normals != (full.determinant() < 0.0) {
                    t.insert("flip_normals", at(Value::Bool(true), line));
                }
                // Its texture coordinates run about its own axes (to_world's).
                if is_similarity(full) {
                    let axes = [DVec3::X, DVec3::Y, DVec3::Z]
                        .map(|a| full.transform_vector3(a).normalize());
                    if axes != [DVec3::X, DVec3::Y, DVec3::Z] {
                        t.insert("axes", axes_node(axes, line));
                    }
                }
                shapes.push(t);
            }
            "cylinder" => {
                let p0 = o.point("p0")?.unwrap_or(DVec3::ZERO);
                let p1 = o.point("p1")?.unwrap_or(DVec3::Z);
                let radius = o.float("radius", 1.0)?;
                let axis = p1 - p0;
                if axis.length_squared() == 0.0 || radius == 0.0 {
                    return Err(o.error(
                        "a cylinder of zero length or radius: `p0` = `p1` or `radius` = 0",
                    ));
                }
                let n = axis.normalize();
                let s = n.any_orthonormal_vector();
                let frame = DMat4::from_cols(
                    s.extend(0.0),
                    n.cross(s).extend(0.0),
                    n.extend(0.0),
                    p0.extend(1.0),
                );
                // The prism's facets at the radius that keeps Mitsuba's area 2 pi r l (and so
                // an emitter's power): r (pi/N) / sin(pi/N).
                let k = std::f64::consts::PI / CYLINDER_FACETS as f64;
                let r = radius * k / k.sin();
                let full = m * frame * DMat4::from_scale(DVec3::new(r, r, axis.length()));
                let flip = flip_normals != (full.determinant() < 0.0);
                for i in 0..CYLINDER_FACETS {
                    let angle = |i: usize| 2.0 * k * i as f64;
                    let a = DVec3::new(angle(i).cos(), angle(i).sin(), 0.0);
                    let b = DVec3::new(angle(i + 1).cos(), angle(i + 1).sin(), 0.0);
                    // (b - a) x z points outward.
                    let mut t = quad(
                        full.transform_point3(a),
                        full.transform_vector3(b - a),
                        full.transform_vector3(DVec3::Z),
                    );
                    if flip {
                        t.insert("flip_normals", at(Value::Bool(true), line));
                    }
                    shapes.push(t);
                }
                self.note(
                    &o,
                    &format!(
                        "a cylinder is rendered as {CYLINDER_FACETS} flat facets of the same area (foton has no analytic cylinder); its texture coordinates are each facet's"
                    ),
                );
            }
            "rectangle" => shapes.push(rectangle(
                DVec3::new(-1.0, -1.0, 0.0),
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
            )),
            "cube" => {
                // The six faces of [-1, 1]^3 with Mitsuba 3's texture coordinates: a face's
                // (s, t) is its uv in cube.cpp, so the quad runs from the corner with uv
                // (0, 0) along u to the one with (1, 0) and along v to the one with (0, 1)
                // (the fourth, (1, 1), is then origin + u + v, as in cube.cpp). Where u x v
                // points inward the quad is flipped, on top of `flip`, so that it faces out.
                for [outward, origin, u_end, v_end] in cube_faces() {
                    let (u, v) = (u_end - origin, v_end - origin);
                    let mut t = rectangle(origin, u, v);
                    if u.cross(v).dot(outward) < 0.0 {
                        t.insert("flip_normals", at(Value::Bool(!flip), line));
                    }
                    shapes.push(t);
                }
            }
            _ => {
                o.props.clear();
                let m = not_read("shape", &o.ty, "this shape is not supported yet");
                return self.unsupported(&o, &m);
            }
        }
        // Only for differentiable rendering.
        self.ignored(&mut o, "silhouette_sampling_weight", &|_| true, "");
        self.manifold_hints(&mut o);
        self.leftovers(&o)?;
        let mut alpha = self.masks.get(&material).cloned();
        if alpha.is_some() && (emission.is_some() || interior.is_some() || exterior.is_some()) {
            o.props.clear();
            self.unsupported(
                &o,
                "a mask BSDF on a shape that emits or bounds a medium: a cut-out emitter or medium boundary is not rendered yet",
            )?;
            alpha = None;
        }
        for mut t in shapes {
            t.insert("material", at(Value::Str(material.clone()), line));
            if let Some(a) = &alpha {
                t.insert("alpha", a.clone());
            }
            if let Some(e) = &emission {
                t.insert("emission", e.clone());
            }
            if measured {
                t.insert("sensor", at(Value::Bool(true), line));
            }
            // Both sides, as Mitsuba crosses them: a side without a medium is vacuum.
            if interior.is_some() || exterior.is_some() {
                self.shape_media = true;
                for (key, side) in [("interior", &interior), ("exterior", &exterior)] {
                    let name = side.clone().unwrap_or_else(|| "vacuum".into());
                    t.insert(key, at(Value::Str(name), line));
                }
            }
            self.shapes.push(at(Value::Table(t), line));
        }
        Ok(())
    }
}

impl Reader {
    /// `<shape type="merge">`: Mitsuba 3 merges its meshes of the same material into one
    /// for speed; read one by one they are the same surfaces.
    fn merge(&mut self, mut o: Obj) -> Result<()> {
        for (name, p, l) in std::mem::take(&mut o.props) {
            match p {
                Prop::Object(member) if member.tag == "shape" => self.shape(member)?,
                other => o.props.push((name, other, l)),
            }
        }
        self.leftovers(&o)
    }

    /// `<shape type="shapegroup" id="...">`: its shapes are read (materials and media bound
    /// there, as in Mitsuba) and kept for the `instance`s that place them; alone it renders
    /// nothing.
    fn shapegroup(&mut self, mut o: Obj) -> Result<()> {
        let Some(id) = o.id.clone() else {
            return Err(o.error("a shapegroup needs an id, for the instances that <ref> it"));
        };
        let before = self.shapes.len();
        for (name, p, l) in std::mem::take(&mut o.props) {
            match p {
                Prop::Object(member) if member.tag == "shape" => {
                    if matches!(member.ty.as_str(), "shapegroup" | "instance") {
                        return Err(member.error(
                            "a shapegroup inside a shapegroup: Mitsuba does not nest instancing",
                        ));
                    }
                    let emits = member
                        .props
                        .iter()
                        .any(|(_, p, _)| matches!(p, Prop::Object(e) if e.tag == "emitter"));
                    if emits {
                        return Err(member.error(
                            "an emitting shape inside a shapegroup: Mitsuba does not instance emitters",
                        ));
                    }
                    self.shape(member)?;
                }
                other => o.props.push((name, other, l)),
            }
        }
        let members: Vec<Node> = self.shapes.drain(before..).collect();
        self.leftovers(&o)?;
        let mut t = Table::default();
        t.insert("shapes", at(Value::Array(members), o.line));
        self.textures.insert(format!("{GROUP_KEY}{id}"), t);
        Ok(())
    }

    /// `<shape type="instance">`: the referenced group's shapes, each placed by the
    /// instance's `to_world` after its own.
    fn instance(&mut self, mut o: Obj) -> Result<()> {
        let m = o.transform("to_world")?;
        let mut group = None;
        for (name, p, l) in std::mem::take(&mut o.props) {
            match p {
                Prop::Ref(id) => {
                    let here = Obj {
                        line: l,
                        props: Vec::new(),
                        ..o.clone()
                    };
                    if group.is_some() {
                        return Err(here.error("a second shapegroup: an instance places one"));
                    }
                    let key = format!("{GROUP_KEY}{id}");
                    let Some(t) = self.textures.get(&key) else {
                        let what = self
                            .named(&id)
                            .map_or(String::new(), |k| format!(" (`{id}` is {k})"));
                        return Err(here.error(format!(
                            "<ref id=\"{id}\">: no shapegroup with id `{id}` before it{what}"
                        )));
                    };
                    group = Some(t.clone());
                }
                other => o.props.push((name, other, l)),
            }
        }
        let Some(group) = group else {
            return Err(o.error("an instance without a <ref> to its shapegroup"));
        };
        self.leftovers(&o)?;
        let Some(Value::Array(members)) = group.get("shapes").map(|n| &n.value) else {
            return Ok(());
        };
        for member in members {
            let Value::Table(t) = &member.value else {
                continue;
            };
            let mut t = t.clone();
            if !place(&mut t, m, o.line) {
                self.warn(
                    &o,
                    o.line,
                    "`to_world` scales a sphere or a curve of the group non-uniformly, into an ellipsoid or a tube of elliptic section in Mitsuba 3: foton has neither and renders the sphere of radius |to_world x|, or the curve with its radii times |to_world x|",
                );
            }
            self.shapes.push(at(Value::Table(t), o.line));
        }
        Ok(())
    }
}

/// Whether `m` (its linear part) is a rotation, a uniform scale and perhaps a mirroring.
fn is_similarity(m: DMat4) -> bool {
    let (x, y, z) = (
        m.transform_vector3(DVec3::X),
        m.transform_vector3(DVec3::Y),
        m.transform_vector3(DVec3::Z),
    );
    let s = x.length();
    let tol = 1e-6 * s.max(1e-30);
    (y.length() - s).abs() <= tol
        && (z.length() - s).abs() <= tol
        && x.dot(y).abs() <= tol * s
        && y.dot(z).abs() <= tol * s
        && x.dot(z).abs() <= tol * s
}

fn node_vec3(n: &Node) -> Option<DVec3> {
    match &n.value {
        Value::Array(xs) if xs.len() == 3 => Some(DVec3::new(
            xs[0].value.as_f64()?,
            xs[1].value.as_f64()?,
            xs[2].value.as_f64()?,
        )),
        _ => None,
    }
}

/// The shape table `t` (as [`Reader::shape`] writes it) moved by `m`, applied after its own
/// placement, as Mitsuba 3's instance moves a shape; false if `m` turned a sphere into an
/// ellipsoid (rendered as a sphere) or a curve's round section into an ellipse (rendered
/// round, its radii scaled by |m x|).
fn place(t: &mut Table, m: DMat4, line: u32) -> bool {
    let point = |t: &mut Table, key: &str| {
        if let Some(p) = t.get(key).and_then(node_vec3) {
            t.insert(key, vec3(m.transform_point3(p), line));
        }
    };
    let vector = |t: &mut Table, key: &str| {
        if let Some(v) = t.get(key).and_then(node_vec3) {
            t.insert(key, vec3(m.transform_vector3(v), line));
        }
    };
    // A mirroring reverses u x v (quads, disks), which Mitsuba's instance does not: its
    // normals are the shape's, transformed as normals.
    let toggle_flip = |t: &mut Table| {
        if m.determinant() < 0.0 {
            let flipped = matches!(
                t.get("flip_normals").map(|n| &n.value),
                Some(Value::Bool(true))
            );
            t.insert("flip_normals", at(Value::Bool(!flipped), line));
        }
    };
    let ty = match t.get("type").map(|n| &n.value) {
        Some(Value::Str(s)) => s.clone(),
        _ => return true,
    };
    // An instance moves the whole curve, its radii too (Embree traces it in the group's
    // space): by the scale of a similarity.
    if ty == "curve" {
        let scale = m.transform_vector3(DVec3::X).length();
        let before = match t.get("radius_scale").map(|n| &n.value) {
            Some(Value::Float(r)) => *r,
            _ => 1.0,
        };
        if scale != 1.0 {
            t.insert("radius_scale", at(Value::Float(before * scale), line));
        }
    }
    let similar = ty != "curve" || is_similarity(m);
    match ty.as_str() {
        "mesh" | "curve" | "sdfgrid" => {
            let own = match t.get("transform").map(|n| &n.value) {
                Some(Value::Table(tt)) => match tt.get("matrix").map(|n| &n.value) {
                    Some(Value::Array(xs)) if xs.len() == 16 => {
                        let xs: Vec<f64> = xs.iter().filter_map(|x| x.value.as_f64()).collect();
                        DMat4::from_cols_slice(&xs).transpose()
                    }
                    _ => DMat4::IDENTITY,
                },
                _ => DMat4::IDENTITY,
            };
            t.insert("transform", matrix_table(m * own, line));
            similar
        }
        "sphere" => {
            // Mitsuba 3 transforms the sphere's own normals by the instance's: a mirroring
            // keeps them outward (unlike a mirroring in the sphere's own to_world).
            let uniform = is_similarity(m);
            if let Some(Value::Float(r)) = t.get("radius").map(|n| n.value.clone()) {
                let r = r * m.transform_vector3(DVec3::X).length();
                t.insert("radius", at(Value::Float(r), line));
            }
            point(t, "center");
            if uniform {
                let own = match t.get("axes").map(|n| &n.value) {
                    Some(Value::Array(xs)) if xs.len() == 9 => {
                        let x: Vec<f64> = xs.iter().filter_map(|x| x.value.as_f64()).collect();
                        [0, 3, 6].map(|i| DVec3::new(x[i], x[i + 1], x[i + 2]))
                    }
                    _ => [DVec3::X, DVec3::Y, DVec3::Z],
                };
                let axes = own.map(|a| m.transform_vector3(a).normalize());
                if axes != [DVec3::X, DVec3::Y, DVec3::Z] {
                    t.insert("axes", axes_node(axes, line));
                }
            }
            uniform
        }
        "quad" => {
            point(t, "origin");
            vector(t, "u");
            vector(t, "v");
            toggle_flip(t);
            true
        }
        "disk" => {
            point(t, "center");
            vector(t, "u");
            vector(t, "v");
            toggle_flip(t);
            true
        }
        _ => true,
    }
}

/// A sphere's `axes`: the directions of its x, y and z axes, row after row.
fn axes_node(axes: [DVec3; 3], line: u32) -> Node {
    let items = axes
        .iter()
        .flat_map(|a| a.to_array())
        .map(|x| at(Value::Float(x), line))
        .collect();
    at(Value::Array(items), line)
}
