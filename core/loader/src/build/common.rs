//! What the section readers share: the bags of a load (for the unused keys), the arrays the
//! shapes and lights fill, names defined in a section, a table's `type`, arrays of tables and
//! transform tables.

use crate::texture::{Bitmaps, load_bitmap, read_texture_param};
use foton_core::Rgb;
use foton_core::error::Result;
use foton_core::geometry::{Primitive, Shape, TriangleAttrs};
use foton_core::light::Light;
use foton_core::props::{Properties, Unused};
use foton_core::registry::Resources;
use foton_core::scene::Object;
use foton_core::texture::{Bitmap, Texture};
use foton_core::value::Value;
use glam::{Mat4, Vec3};
use std::collections::HashMap;
use std::path::PathBuf;

/// Collects the bags of a load so that unused keys can be listed at the end.
pub(super) struct Loader {
    pub(super) dir: PathBuf,
    pub(super) sources: Vec<PathBuf>,
    pub(super) bags: Vec<Vec<Unused>>,
    pub(super) warnings: Vec<String>,
    pub(super) bitmaps: Bitmaps,
}

impl Loader {
    pub(super) fn done(&mut self, bag: &Properties<'_>) {
        self.bags.push(bag.unused());
    }
}

impl Resources for Loader {
    fn bitmap(&mut self, bag: &Properties<'_>, key: &str, raw: bool) -> Result<Bitmap> {
        let path = self.dir.join(bag.string_required(key)?);
        let bitmap = load_bitmap(&path, raw).map_err(|e| bag.error(key, e.to_string()))?;
        self.sources.push(path);
        Ok(bitmap)
    }

    fn file(&mut self, bag: &Properties<'_>, key: &str) -> Result<Vec<u8>> {
        let name = bag.string_required(key)?;
        let path = self.dir.join(name);
        let bytes =
            std::fs::read(&path).map_err(|e| bag.error(key, format!("{}: {e}", path.display())))?;
        self.sources.push(path);
        Ok(bytes)
    }

    fn transform(&mut self, bag: &Properties<'_>, key: &str) -> Result<Mat4> {
        read_transform_at(bag, key, self)
    }

    fn texture(&mut self, bag: &Properties<'_>, key: &str, default: Rgb) -> Result<Texture> {
        // A volume texture's grid is read as a medium's (its file through the loader).
        let is_volume = matches!(
            bag.node(key).map(|n| &n.value),
            Some(Value::Table(t)) if t.get("type").is_some_and(|n| matches!(&n.value, Value::Str(s) if s == "volume"))
        );
        if is_volume && let Some(t) = bag.table(key)? {
            t.string_required("type")?;
            let mut nested = Vec::new();
            let grid = foton_core::medium::heterogeneous::volume(
                &t,
                "volume",
                &[1, 3],
                &mut nested,
                self,
            )?
            .ok_or_else(|| {
                t.error(
                    "volume",
                    "missing: a volume table ({ file = ... } or resolution and values)",
                )
            })?;
            for n in &nested {
                self.done(n);
            }
            self.done(&t);
            return Ok(Texture::Volume(std::sync::Arc::new(grid)));
        }
        let (texture, table) = read_texture_param(bag, key, default, &self.dir, &mut self.bitmaps)?;
        if let Some(table) = table {
            self.done(&table);
        }
        Ok(texture)
    }

    fn warn(&mut self, bag: &Properties<'_>, key: &str, message: String) {
        self.warnings.push(format!(
            "{}: `{}`: {message}",
            bag.location(key),
            bag.key_path(key)
        ));
    }
}

/// What `[[shapes]]` and `[[lights]]` add to the scene, in the arrays `Scene::new` takes.
#[derive(Default)]
pub(super) struct Geometry {
    pub(super) objects: Vec<Object>,
    pub(super) primitives: Vec<Primitive>,
    pub(super) triangle_attrs: Vec<TriangleAttrs>,
    /// The mesh attribute at each triangle's corners, aligned with `triangle_attrs` up to the
    /// last mesh that carries one (empty if none does).
    pub(super) triangle_attributes: Vec<[Rgb; 3]>,
    pub(super) lights: Vec<Light>,
    /// Per light: the medium the file puts it in (None: found from where it lies).
    pub(super) light_media: Vec<Option<Option<u32>>>,
    /// Whether the camera is an irradiance meter, whose surface a shape marks (`sensor`).
    pub(super) meter_wanted: bool,
    /// The shapes of those marked `sensor = true`: the irradiance meter's surface.
    pub(super) sensor: Option<Vec<Shape>>,
}

pub(super) fn undefined(kind: &str, name: &str, known: &HashMap<String, u32>) -> String {
    let mut names: Vec<&str> = known.keys().map(String::as_str).collect();
    names.sort();
    if names.is_empty() {
        {
            let plural = if kind == "medium" {
                "media"
            } else {
                "materials"
            };
            format!("{kind} {name:?} is not defined (no {plural} are defined)")
        }
    } else {
        format!(
            "{kind} {name:?} is not defined; defined: {}",
            names.join(", ")
        )
    }
}

/// A table's `type`, which must be given: the error lists the `types` there are.
pub(super) fn type_of<'a>(t: &Properties<'a>, types: &[&str]) -> Result<&'a str> {
    t.string_opt("type")?.ok_or_else(|| {
        t.error(
            "type",
            format!("missing; expected one of: {}", types.join(", ")),
        )
    })
}

pub(super) type Index = HashMap<String, u32>;

/// The `[[shapes]]` or `[[lights]]` array: (key path, bag) per element.
pub(super) fn array_of_tables<'a>(root: &Properties<'a>, key: &str) -> Result<Vec<Properties<'a>>> {
    let Some(node) = root.node(key) else {
        return Ok(Vec::new());
    };
    let Value::Array(items) = &node.value else {
        return Err(root.error(
            key,
            format!(
                "expected an array of tables ([[{key}]]), found {}",
                node.value.type_name()
            ),
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(i, item)| Properties::new(root.file(), &format!("{key}[{i}]"), item))
        .collect()
}

/// The transform table `key` of `s` (`matrix`, or translate, rotate and scale).
pub(super) fn read_transform_at(s: &Properties<'_>, key: &str, ld: &mut Loader) -> Result<Mat4> {
    let Some(t) = s.table(key)? else {
        return Ok(Mat4::IDENTITY);
    };
    if let Some(m) = t.floats_opt("matrix", 16)? {
        if let Some(other) = ["translate", "rotate", "scale"].iter().find(|k| t.has(k)) {
            return Err(t.error(
                other,
                "a transform is either `matrix` or translate, rotate and scale, not both",
            ));
        }
        // Row-major, as written (and as Mitsuba's <matrix value="..."/>).
        let m = Mat4::from_cols_slice(&m).transpose();
        if m.row(3) != glam::Vec4::W {
            return Err(t.error(
                "matrix",
                "the last row must be [0, 0, 0, 1] (an affine transform)",
            ));
        }
        if m.determinant() == 0.0 {
            return Err(t.error("matrix", "is singular (it flattens the mesh)"));
        }
        ld.done(&t);
        return Ok(m);
    }
    let translate = t.vec3("translate", Vec3::ZERO)?;
    let scale = match t.node("scale").map(|n| &n.value) {
        None => Vec3::ONE,
        Some(Value::Array(_)) => t.vec3_required("scale")?,
        Some(_) => Vec3::splat(t.f32_required("scale")?),
    };
    if scale.x * scale.y * scale.z == 0.0 {
        return Err(t.error("scale", "must not be zero"));
    }
    let rotate = match t.table("rotate")? {
        None => Mat4::IDENTITY,
        Some(r) => {
            let axis = r.vec3_required("axis")?;
            if axis.length_squared() == 0.0 {
                return Err(r.error("axis", "must not be the zero vector"));
            }
            let degrees = r.f32_required("degrees")?;
            ld.done(&r);
            Mat4::from_axis_angle(axis.normalize(), degrees.to_radians())
        }
    };
    ld.done(&t);
    Ok(Mat4::from_translation(translate) * rotate * Mat4::from_scale(scale))
}
