//! Loading a scene file into a [`Scene`]: the file read into a document by its format's
//! reader, `--set` overrides applied to the document, the scene built from it
//! ([`crate::build`]), and what the reader reported (warnings, included files) added.

use crate::build::from_document;
use crate::document::TomlDocument;
use crate::formats;
use crate::reader::Options;
use foton_core::error::Result;
use foton_core::scene::Scene;
use foton_core::value::{Document, Node, Table, Value};
use glam::Vec3;
use std::path::Path;

/// Loads a scene file, applying `--set` style overrides first.
pub fn load(path: &Path, overrides: &[String]) -> Result<Scene> {
    load_with(path, overrides, &[], false)
}

/// Loads a scene file: TOML, or a Mitsuba XML scene (`.xml`) whose `<default>`s `defines`
/// (`NAME=VALUE`, Mitsuba's `-D`) override and whose unsupported elements are left out and
/// listed among the warnings if `lenient`. `--set` style `overrides` apply to the document in
/// both cases (for XML: to the TOML it reads as).
pub fn load_with(
    path: &Path,
    overrides: &[String],
    defines: &[String],
    lenient: bool,
) -> Result<Scene> {
    let (read, report) = formats::read(path, &Options { defines, lenient })?;
    let with_overrides = |mut doc: Document| -> Result<Document> {
        for o in overrides {
            doc.set(o)?;
        }
        Ok(doc)
    };
    let mut scene = match report.default_camera {
        None => from_document(with_overrides(read)?)?,
        // The default camera stands where the scene's bounds say: built once to know them
        // (meshes read twice; only files without a camera pay for it).
        Some(fov) => {
            let first = from_document(with_overrides(read.clone())?)?;
            let mut doc = read;
            place_default_camera(&mut doc, first.bounds(), fov);
            from_document(with_overrides(doc)?)?
        }
    };
    if let Some((integrator, factor, line)) = &report.relative_radius {
        set_relative_radius(&mut scene, integrator, *factor, *line);
    }
    let left_out = report.left_out.iter().map(|l| format!("left out: {l}"));
    scene.add_report(
        report.included,
        left_out.chain(report.notes).collect::<Vec<_>>(),
        report.warnings,
    );
    Ok(scene)
}

/// Mitsuba 0.6's camera for a scene without one (`Scene::configure`): on the axis of the
/// bounds' centre in x and y, in front of their near (-z) face, looking down +z from the
/// distance at which `fov` spans the larger of their width and height. Empty bounds leave the
/// camera as the reader wrote it. For a reader's [`crate::reader::Report::default_camera`]:
/// `load_with` places it; a tool that writes the document out calls it with the bounds of a
/// first build.
pub fn place_default_camera(doc: &mut Document, (lo, hi): (Vec3, Vec3), fov: f64) {
    let extent = hi - lo;
    if !(extent.is_finite() && extent.min_element() >= 0.0) {
        return;
    }
    let center = (lo + hi) * 0.5;
    let distance = f64::from(extent.x.max(extent.y)) / (2.0 * (fov.to_radians() * 0.5).tan());
    let position = [
        f64::from(center.x),
        f64::from(center.y),
        f64::from(lo.z) - distance,
    ];
    let point = |p: [f64; 3]| Node {
        value: Value::Array(
            p.iter()
                .map(|x| Node {
                    value: Value::Float(*x),
                    line: 0,
                    column: 0,
                })
                .collect(),
        ),
        line: 0,
        column: 0,
    };
    if doc.root.get("camera").is_none() {
        doc.root.insert(
            "camera",
            Node {
                value: Value::Table(Table::default()),
                line: 0,
                column: 0,
            },
        );
    }
    if let Some(Node {
        value: Value::Table(camera),
        ..
    }) = doc.root.get_mut("camera")
    {
        camera.insert("position", point(position));
        let [x, y, z] = position;
        camera.insert("look_at", point([x, y, z + 1.0]));
    }
}

/// A Mitsuba photon mapper's lookup radius, a fraction of the radius of the scene's bounding
/// sphere (Mitsuba's `getBSphere`: around the bounding box, half its diagonal), as the
/// plugin's `max_radius` in world units, unless the document already gives one (`--set`).
pub fn set_relative_radius(scene: &mut Scene, integrator: &str, factor: f64, line: u32) {
    use foton_core::value::{Node, Value};
    let (lo, hi) = scene.bounds();
    let radius = 0.5 * f64::from((hi - lo).length());
    if !radius.is_finite() || radius <= 0.0 {
        return;
    }
    let node = |value| Node {
        value,
        line,
        column: u32::from(line > 0),
    };
    let root = &mut scene.document_mut().root;
    if root.get("integrators").is_none() {
        root.insert("integrators", node(Value::Table(Default::default())));
    }
    let Some(Value::Table(integrators)) = root.get_mut("integrators").map(|n| &mut n.value) else {
        return;
    };
    if integrators.get(integrator).is_none() {
        integrators.insert(integrator, node(Value::Table(Default::default())));
    }
    if let Some(Value::Table(t)) = integrators.get_mut(integrator).map(|n| &mut n.value)
        && t.get("max_radius").is_none()
    {
        t.insert("max_radius", node(Value::Float(factor * radius)));
    }
}
