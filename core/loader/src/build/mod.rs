//! The scene builder: a [`Document`] (what every scene format reads into, see
//! [`crate::reader`]) into a [`Scene`]. It knows no file format: a TOML scene and a Mitsuba
//! XML one reach it as the same tree of values, each value with its file and line.
//!
//! Every table is read through a [`Properties`] bag, so every error names file, line, key path
//! and what was expected, and every key that was never read is reported as unused. One file
//! per section: `settings` (`[render]`, `[film]`, `[camera]`), `material` (`[materials]`),
//! `medium` (`[media]`), `shape` (`[[shapes]]`, meshes through [`crate::mesh`]) and `light`
//! (`[[lights]]`); this file assembles what they read into [`Scene::new`].

mod light;
mod material;
mod medium;
mod settings;
mod shape;

use light::read_lights;
use material::read_materials;
use medium::read_media;
use settings::{read_camera, read_film, read_render};
use shape::read_shapes;

use foton_core::error::{Error, Result};
use foton_core::geometry::{Primitive, TriangleAttrs};
use foton_core::light::Light;
use foton_core::props::{Properties, Unused};
use foton_core::scene::{Object, Scene, SceneParts};
use foton_core::value::{Document, Value};
use glam::{Mat4, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

const SECTIONS: &[&str] = &[
    "render",
    "film",
    "camera",
    "integrators",
    "materials",
    "media",
    "shapes",
    "lights",
    "scene",
];

/// Collects the bags of a load so that unused keys can be listed at the end.
struct Loader {
    dir: PathBuf,
    sources: Vec<PathBuf>,
    bags: Vec<Vec<Unused>>,
    warnings: Vec<String>,
}

impl Loader {
    fn done(&mut self, bag: &Properties<'_>) {
        self.bags.push(bag.unused());
    }

    fn warn(&mut self, bag: &Properties<'_>, key: &str, message: String) {
        self.warnings.push(format!(
            "{}: `{}`: {message}",
            bag.location(key),
            bag.key_path(key)
        ));
    }
}

/// What `[[shapes]]` and `[[lights]]` add to the scene, in the arrays [`Scene::new`] takes.
#[derive(Default)]
struct Geometry {
    objects: Vec<Object>,
    primitives: Vec<Primitive>,
    triangle_attrs: Vec<TriangleAttrs>,
    lights: Vec<Light>,
    /// Per light: the medium the file puts it in (None: found from where it lies).
    light_media: Vec<Option<Option<u32>>>,
}

/// The scene a parsed document describes.
pub fn from_document(doc: Document) -> Result<Scene> {
    let file = doc.file.clone();
    let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut ld = Loader {
        dir,
        sources: Vec::new(),
        bags: Vec::new(),
        warnings: Vec::new(),
    };
    let root = Properties::root(&file, &doc.root);
    for key in root.keys() {
        if !SECTIONS.contains(&key) {
            return Err(root.error(
                key,
                format!("unknown section; expected one of: {}", SECTIONS.join(", ")),
            ));
        }
    }
    root.node("integrators");

    let render = read_render(&root, &mut ld)?;
    let film = read_film(&root, &mut ld)?;
    let (materials, material_index) = read_materials(&root, &mut ld)?;
    let (media, medium_index) = read_media(&root, &mut ld)?;
    let (camera, camera_medium) = read_camera(&root, &film, &medium_index, &mut ld)?;

    let mut geometry = Geometry::default();
    read_shapes(
        &root,
        &mut ld,
        &materials,
        &material_index,
        &medium_index,
        &mut geometry,
    )?;
    read_lights(&root, &mut ld, &medium_index, &mut geometry)?;

    let mut medium = None;
    if let Some(scene) = root.table("scene")? {
        if let Some(name) = scene.string_opt("medium")? {
            medium =
                Some(*medium_index.get(name).ok_or_else(|| {
                    scene.error("medium", undefined("medium", name, &medium_index))
                })?);
        }
        ld.done(&scene);
    }

    if geometry.lights.is_empty() {
        ld.warnings.push(format!(
            "{}: the scene has no lights: the image will be black",
            file.display()
        ));
    }
    ld.done(&root);
    let mut unused: Vec<Unused> = ld.bags.into_iter().flatten().collect();
    unused.sort_by(|a, b| (a.location.line, &a.key).cmp(&(b.location.line, &b.key)));
    let warnings = ld.warnings;
    let sources = ld.sources;
    // Where the error is if the medium around the camera turns out undefined (the scene
    // takes the document, which the bags borrow).
    let camera_error = match root.table("camera").ok().flatten() {
        Some(t) => t.error("position", ""),
        None => root.error("camera", ""),
    };
    Scene::new(SceneParts {
        file,
        render,
        film,
        camera,
        camera_medium,
        materials,
        media,
        objects: geometry.objects,
        primitives: geometry.primitives,
        triangle_attrs: geometry.triangle_attrs,
        lights: geometry.lights,
        light_media: geometry.light_media,
        medium,
        document: doc,
        sources,
        unused,
        warnings,
    })
    .map_err(|why| match camera_error {
        Error::Scene { location, key, .. } => Error::Scene {
            location,
            key,
            message: format!("the medium around the camera is undefined: {why}; move the camera"),
        },
        other => other,
    })
}

fn undefined(kind: &str, name: &str, known: &HashMap<String, u32>) -> String {
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
fn type_of<'a>(t: &Properties<'a>, types: &[&str]) -> Result<&'a str> {
    t.string_opt("type")?.ok_or_else(|| {
        t.error(
            "type",
            format!("missing; expected one of: {}", types.join(", ")),
        )
    })
}

type Index = HashMap<String, u32>;

/// The `[[shapes]]` or `[[lights]]` array: (key path, bag) per element.
fn array_of_tables<'a>(root: &Properties<'a>, key: &str) -> Result<Vec<Properties<'a>>> {
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
fn read_transform_at(s: &Properties<'_>, key: &str, ld: &mut Loader) -> Result<Mat4> {
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
