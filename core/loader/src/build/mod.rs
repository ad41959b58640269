//! The scene builder: a [`Document`] (what every scene format reads into, see
//! [`crate::reader`]) into a [`Scene`]. It knows no file format: a TOML scene and a Mitsuba
//! XML one reach it as the same tree of values, each value with its file and line.
//!
//! Every table is read through a [`Properties`] bag, so every error names file, line, key path
//! and what was expected, and every key that was never read is reported as unused. One file
//! per section: `settings` (`[render]`, `[film]`, `[camera]`), `material` (`[materials]`),
//! `medium` (`[media]`), `shape` (`[[shapes]]`, meshes through [`crate::mesh`]) and `light`
//! (`[[lights]]`), with what they share in `common`; this file assembles what they read into
//! [`Scene::new`].

mod common;
mod light;
mod material;
mod medium;
mod settings;
mod shape;

use common::{Geometry, Loader, undefined};
use light::read_lights;
use material::read_materials;
use medium::read_media;
use settings::{read_camera, read_film, read_render};
use shape::read_shapes;

use foton_core::camera::Camera;
use foton_core::error::{Error, Result};
use foton_core::props::{Properties, Unused};
use foton_core::scene::{Scene, SceneParts};
use foton_core::value::Document;
use std::path::Path;

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

/// The scene a parsed document describes.
pub fn from_document(doc: Document) -> Result<Scene> {
    let file = doc.file.clone();
    let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut ld = Loader {
        dir,
        sources: Vec::new(),
        bags: Vec::new(),
        warnings: Vec::new(),
        bitmaps: Default::default(),
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
    let (materials, material_index, normal_maps) = read_materials(&root, &mut ld)?;
    let (media, medium_index) = read_media(&root, &mut ld)?;
    let (camera, camera_medium) = read_camera(&root, &film, &medium_index, &mut ld)?;

    let mut geometry = Geometry::default();
    let camera_table = root.table("camera")?;
    geometry.meter_wanted = matches!(
        camera_table
            .as_ref()
            .map(|t| t.string_opt("type"))
            .transpose()?
            .flatten(),
        Some("irradiancemeter")
    );
    read_shapes(
        &root,
        &mut ld,
        &materials,
        &material_index,
        &normal_maps,
        &medium_index,
        &mut geometry,
    )?;
    read_lights(&root, &mut ld, &medium_index, &mut geometry)?;
    let camera = match (geometry.meter_wanted, geometry.sensor.take()) {
        (true, Some(shapes)) => Camera::irradiance_meter(shapes).ok_or_else(|| {
            error_at(
                &camera_table,
                "type",
                "the irradiance meter's surface has no area",
            )
        })?,
        (true, None) => {
            return Err(error_at(
                &camera_table,
                "type",
                "an irradiancemeter measures over the shapes marked `sensor = true`, and none is",
            ));
        }
        _ => camera,
    };

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
            "{}: the scene has no lights: the image will be black (but for geometry passes such as ao and normals)",
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
        triangle_attributes: {
            let mut a = geometry.triangle_attributes;
            if !a.is_empty() {
                a.resize(geometry.triangle_attrs.len(), [glam::Vec3::ZERO; 3]);
            }
            a
        },
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

/// An error at `key` of the `[camera]` table (present wherever this is called).
fn error_at(t: &Option<Properties<'_>>, key: &str, message: &str) -> Error {
    match t {
        Some(t) => t.error(key, message),
        None => Error::Usage(message.to_string()),
    }
}
