//! `<shape>`: meshes (obj, ply), spheres, disks, rectangles and cubes as `[[shapes]]` entries,
//! each with its material (a nested or referenced BSDF, or Mitsuba's default), its area
//! emitter and the media on its two sides.

use super::object::{Obj, Prop, show};
use super::plugins::not_read;
use super::{Reader, at, matrix_table, table_mut, vec3};
use foton_core::error::Result;
use foton_core::value::{Table, Value};
use glam::{DMat4, DVec3};

impl Reader {
    pub(super) fn shape(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        let m = o.transform("to_world")?;
        // The material: a nested BSDF, a reference, or Mitsuba's default (diffuse 0.5).
        let mut material = None;
        let mut emission = None;
        // Mitsuba's interior (behind the normal) and exterior (in front of it).
        let mut interior = None;
        let mut exterior = None;
        let props = std::mem::take(&mut o.props);
        for (name, p, l) in props {
            match p {
                Prop::Object(b) if b.tag == "bsdf" => material = Some(self.bsdf(b)?),
                Prop::Ref(id) if name.is_empty() || name == "bsdf" => {
                    let found = self.bsdfs.get(&id).cloned();
                    if found.is_none() && !self.lenient {
                        return Err(o.error(format!("line {l}: no BSDF with id `{id}` before it")));
                    }
                    material = Some(found);
                }
                Prop::Object(mut e) if e.tag == "emitter" => {
                    if e.ty != "area" {
                        return Err(e.error("a shape's emitter must be `area`"));
                    }
                    emission = Some(e.color("radiance", DVec3::ONE)?);
                    self.leftovers(&e)?;
                }
                Prop::Object(med) if med.tag == "medium" && name == "interior" => {
                    interior = Some(self.medium(med)?)
                }
                Prop::Ref(id) if name == "interior" => {
                    interior = Some(self.media.get(&id).cloned().ok_or_else(|| {
                        o.error(format!("line {l}: no medium with id `{id}` before it"))
                    })?)
                }
                Prop::Object(med) if med.tag == "medium" && name == "exterior" => {
                    exterior = Some(self.medium(med)?)
                }
                Prop::Ref(id) if name == "exterior" => {
                    exterior = Some(self.media.get(&id).cloned().ok_or_else(|| {
                        o.error(format!("line {l}: no medium with id `{id}` before it"))
                    })?)
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
                if o.ty == "obj" && !o.boolean("flip_tex_coords", true)? {
                    t.insert("flip_tex_coords", at(Value::Bool(false), line));
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
                if let Some((p, l)) = o.take("max_smooth_angle") {
                    self.warn(
                        &o,
                        l,
                        &format!(
                            "`max_smooth_angle` = {}: not honoured; the mesh is shaded with its own vertex normals, or smooth ones computed over every angle",
                            show(&p)
                        ),
                    );
                }
                t.insert("file", file);
                if m != DMat4::IDENTITY {
                    t.insert("transform", matrix_table(m, line));
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
                let center = o.point("center")?.unwrap_or(DVec3::ZERO);
                let radius = o.float("radius", 1.0)?;
                let (x, y, z) = (
                    m.transform_vector3(DVec3::X),
                    m.transform_vector3(DVec3::Y),
                    m.transform_vector3(DVec3::Z),
                );
                let s = x.length();
                let tol = 1e-6 * s.max(1e-30);
                if (y.length() - s).abs() > tol
                    || (z.length() - s).abs() > tol
                    || x.dot(y).abs() > tol * s
                    || y.dot(z).abs() > tol * s
                {
                    self.unsupported(
                        &o,
                        "a sphere with a non-uniform scale (an ellipsoid) is not supported",
                    )?;
                    return Ok(());
                }
                let mut t = Table::default();
                t.insert("type", at(Value::Str("sphere".into()), line));
                t.insert("center", vec3(m.transform_point3(center), line));
                t.insert("radius", at(Value::Float(radius * s), line));
                if flip_normals {
                    t.insert("flip_normals", at(Value::Bool(true), line));
                }
                shapes.push(t);
            }
            "rectangle" => shapes.push(rectangle(
                DVec3::new(-1.0, -1.0, 0.0),
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
            )),
            "cube" => {
                // Six outward-facing faces of [-1, 1]^3.
                for axis in 0..3 {
                    for side in [-1.0, 1.0] {
                        let n = DVec3::AXES[axis] * side;
                        let a = DVec3::AXES[(axis + 1) % 3] * 2.0;
                        let b = DVec3::AXES[(axis + 2) % 3] * 2.0;
                        let (a, b) = if side > 0.0 { (a, b) } else { (b, a) };
                        shapes.push(rectangle(n - a / 2.0 - b / 2.0, a, b));
                    }
                }
            }
            _ => {
                o.props.clear();
                let m = not_read("shape", &o.ty, "this shape is not supported yet");
                return self.unsupported(&o, &m);
            }
        }
        self.leftovers(&o)?;
        for mut t in shapes {
            t.insert("material", at(Value::Str(material.clone()), line));
            if let Some(e) = emission {
                t.insert("emission", vec3(e, line));
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
