//! The plugin API has an edge: the crates under integrators/ reach foton-core only through
//! `foton_core::api`, and `PLUGIN_API_VERSION` is a hash of what that module exposes
//! (core/api_surface.rs, the function build.rs runs): a change that could break a plugin built
//! against the module changes it, and no other change does. Both directions are checked on
//! copies of core's sources with one change each.

#[path = "../../../core/api_surface.rs"]
mod api_surface;

use crate::build_id::copy_dir;
use foton_core::plugin::PLUGIN_API_VERSION;
use foton_tests::{repo_root, temp_dir};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            if path.file_name().is_some_and(|n| n != "target") {
                rust_files(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a line: what precedes a `//` comment outside a string.
fn code(line: &str) -> &str {
    let mut in_string = false;
    let mut prev = ' ';
    for (i, c) in line.char_indices() {
        if c == '"' && prev != '\\' {
            in_string = !in_string;
        }
        if !in_string && c == '/' && prev == '/' {
            return &line[..i - 1];
        }
        prev = c;
    }
    line
}

/// Uses of foton-core outside `foton_core::api` in the Rust files below `dir`, as file:line.
fn reaches_past_api(dir: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(dir, &mut files);
    let mut found = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        for (i, line) in text.lines().enumerate() {
            let code = code(line);
            let mut rest = code;
            while let Some(at) = rest.find("foton_core") {
                let after = &rest[at + "foton_core".len()..];
                if !after.starts_with("::api::") && !after.starts_with("::api;") {
                    found.push(format!("{}:{}: {}", file.display(), i + 1, line.trim()));
                    break;
                }
                rest = after;
            }
        }
    }
    found
}

#[test]
fn integrators_reach_core_only_through_the_api_module() {
    let integrators = repo_root().join("integrators");
    let found = reaches_past_api(&integrators);
    assert!(
        found.is_empty(),
        "integrators/ must use foton-core through `foton_core::api` only (add what is missing to core/src/api.rs):\n{}",
        found.join("\n")
    );
    // The check finds what it must: a path past the module, a brace list, a macro call.
    let dir = temp_dir("api-edge");
    std::fs::write(
        dir.join("lib.rs"),
        "use foton_core::api::Scene;\nuse foton_core::scene::Object; // past it\n\
         use foton_core::{Rgb, Vec3};\nfoton_core::declare_integrator!(\"x\", \"y\", f);\n\
         // foton_core::walk in a comment\nlet s = \"foton_core::x\"; foton_core::api::average(c);\n",
    )
    .unwrap();
    let found = reaches_past_api(&dir);
    assert_eq!(found.len(), 4, "{found:#?}");
}

fn surface_of(src: &Path) -> String {
    api_surface::surface(src).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_version_is_the_hash_of_the_api_surface() {
    let surface = surface_of(&repo_root().join("core/src"));
    assert_eq!(api_surface::version(&surface), PLUGIN_API_VERSION);
    // What a plugin uses is on the surface, with the members of what it names.
    for key in [
        "scene::Scene",
        "integrator::Integrator",
        "walk::RayWalk",
        "kernel::NormalizedKernel",
        "plugin::declaration::declare_integrator",
        // Written inside a registration macro, and reached through it.
        "light::Light",
        "light::point::PointLight",
        "light::area::AreaLight",
    ] {
        assert!(
            api_surface::keys(&surface).contains_key(key),
            "{key} is not on the surface"
        );
    }
    assert!(
        surface.contains("pub fn intersect (& self , ray : & Ray , tmax : f32) -> Option < Hit >")
    );
    // The methods a registration macro adds are on the surface through its text.
    assert!(surface.contains("light::Light: expanded by lights: macro_rules !"));
}

/// The version of core's sources with `file`'s text `from` replaced by `to` (which must be
/// there, so that this test follows the code it edits).
fn version_after(name: &str, file: &str, from: &str, to: &str) -> u32 {
    let dir = temp_dir(&format!("api-surface-{name}"));
    let src = dir.join("src");
    let _ = std::fs::remove_dir_all(&src);
    copy_dir(&repo_root().join("core/src"), &src);
    let path = src.join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains(from),
        "{file} no longer holds {from:?}: update this test"
    );
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
    api_surface::version(&surface_of(&src))
}

#[test]
fn changes_off_the_surface_keep_the_version() {
    let changes = [
        // A method's body.
        (
            "body",
            "scene/mod.rs",
            "self.accel.intersect(ray, tmax)",
            "{ let t = tmax; self.accel.intersect(ray, t) }",
        ),
        // Documentation and comments.
        (
            "doc",
            "api.rs",
            "//! The plugin API:",
            "//! The plugin interface:",
        ),
        (
            "comment",
            "scene/mod.rs",
            "pub fn intersect(",
            "// a comment\n    pub fn intersect(",
        ),
        // Formatting.
        (
            "format",
            "scene/mod.rs",
            "pub fn intersect(&self, ray: &Ray, tmax: f32)",
            "pub fn intersect(\n        &self,\n        ray: &Ray,\n        tmax: f32,\n    )",
        ),
        // Private and crate-private items, of exposed types too.
        (
            "private",
            "scene/mod.rs",
            "impl Scene {",
            "impl Scene {\n    pub(crate) fn extra(&self, _: u64) -> u8 { 0 }\n    fn other(&self) {}",
        ),
        // A light kind's arithmetic, in the file the registration line names.
        (
            "kind body",
            "light/point.rs",
            "4.0 * PI * self.intensity",
            "self.intensity * (4.0 * PI)",
        ),
        // A public item that nothing on the surface reaches.
        (
            "unreached",
            "filter.rs",
            "use ",
            "pub fn unreached_by_the_api(x: f64) -> f64 { x }\nuse ",
        ),
    ];
    for (name, file, from, to) in changes {
        assert_eq!(
            version_after(name, file, from, to),
            PLUGIN_API_VERSION,
            "{name}: {file} changed off the API surface, but the version changed"
        );
    }
}

#[test]
fn changes_to_the_surface_change_the_version() {
    let changes = [
        // A method's signature.
        (
            "signature",
            "scene/mod.rs",
            "pub fn intersect(&self, ray: &Ray, tmax: f32)",
            "pub fn intersect(&self, ray: &Ray, tmax: f64)",
        ),
        // A new public method of an exposed type.
        (
            "method",
            "scene/mod.rs",
            "impl Scene {",
            "impl Scene {\n    pub fn extra(&self) {}",
        ),
        // A field of an exposed struct.
        (
            "field",
            "geometry/mod.rs",
            "pub struct Hit {",
            "pub struct Hit {\n    pub extra: u32,",
        ),
        // A variant of an exposed enum.
        (
            "variant",
            "walk.rs",
            "pub enum Reached {",
            "pub enum Reached {\n    Extra,",
        ),
        // A method of the plugin trait.
        (
            "trait",
            "integrator.rs",
            "pub trait Integrator: Send + Sync {",
            "pub trait Integrator: Send + Sync {\n    fn extra(&self) -> u32 { 0 }",
        ),
        // The declaration macro's expansion.
        (
            "macro",
            "plugin/declaration.rs",
            "$crate::plugin::guarded_create(props, scene, $create)",
            "$crate::plugin::guarded_create(props, scene, $create).map(|i| i)",
        ),
        // One more item re-exported.
        (
            "export",
            "api.rs",
            "pub use crate::props::Properties;",
            "pub use crate::props::Properties;\npub use crate::filter::FilterSampler;",
        ),
        // A light kind registered (a variant of `Light`, written in the `lights!` line).
        (
            "registered",
            "light/mod.rs",
            "        Collimated(collimated::CollimatedLight),\n    }",
            "        Collimated(collimated::CollimatedLight),\n        Extra(point::PointLight),\n    }",
        ),
        // A field of a light kind, reached through the variant's path.
        (
            "kind field",
            "light/point.rs",
            "pub struct PointLight {",
            "pub struct PointLight {\n    pub extra: u8,",
        ),
        // A method the registration macro adds to `Light`.
        (
            "dispatch",
            "light/mod.rs",
            "pub fn power(&self) -> Rgb {",
            "pub fn power(&self) -> crate::Rgb {",
        ),
        // A type that a plugin reaches through a signature: `Scene::bsdf` returns a `Bsdf`.
        (
            "chain",
            "bsdf.rs",
            "pub struct Bsdf {",
            "pub struct Bsdf {\n    pub extra: u8,",
        ),
    ];
    for (name, file, from, to) in changes {
        assert_ne!(
            version_after(name, file, from, to),
            PLUGIN_API_VERSION,
            "{name}: {file} changed the API surface, but the version did not change"
        );
    }
}
