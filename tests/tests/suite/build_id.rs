//! The build identifier covers exactly what defines the plugin ABI (core/build_id.rs): a
//! change to the `foton` program, to the scene loader (core/loader: the TOML, XML, PLY, OBJ
//! and image readers) or to a dependency only they link leaves it as it is (plugins built
//! before still load), a change to core or to one of its dependencies changes it (such
//! plugins are refused, with both identifiers named: bad_input_plugins.rs). The function tested here
//! is the one build.rs runs: it reproduces this build's identifier.

#[path = "../../../core/build_id.rs"]
mod core_build_id;

use core_build_id::{Inputs, build_id, dependency_closure};
use foton_tests::{repo_root, temp_dir};
use std::path::Path;

pub(crate) fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let dest = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_dir(&path, &dest);
        } else {
            std::fs::copy(&path, &dest).unwrap();
        }
    }
}

fn settings() -> Vec<String> {
    foton_core::BUILD_SETTINGS
        .split(';')
        .map(str::to_string)
        .collect()
}

fn id(core: &Path, lock: &str) -> u64 {
    build_id(&Inputs {
        core_dir: core,
        lock: Some(lock),
        rustc: foton_core::RUSTC_VERSION,
        settings: &settings(),
    })
}

/// `lock` with the version of package `name` replaced (every occurrence in its entry).
fn bump(lock: &str, name: &str) -> String {
    let entry = format!("name = \"{name}\"\nversion = \"");
    let at = lock
        .find(&entry)
        .unwrap_or_else(|| panic!("{name} is not locked"))
        + entry.len();
    let end = at + lock[at..].find('"').unwrap();
    format!("{}999.0.0{}", &lock[..at], &lock[end..])
}

#[test]
fn the_identifier_is_the_one_this_build_computed() {
    let lock = std::fs::read_to_string(repo_root().join("Cargo.lock")).unwrap();
    let computed = format!("{:016x}", id(&repo_root().join("core"), &lock));
    assert!(
        foton_core::BUILD_ID.starts_with(&computed),
        "{} is not {computed}",
        foton_core::BUILD_ID
    );
}

#[test]
fn tools_do_not_change_the_identifier_and_core_does() {
    let dir = temp_dir("build-id");
    let core = dir.join("core");
    copy_dir(&repo_root().join("core"), &core);
    let lock = std::fs::read_to_string(repo_root().join("Cargo.lock")).unwrap();
    let before = id(&core, &lock);

    // The program's sources (core/cli) and dependencies only the program links.
    let tool = core.join("cli/src/compare.rs");
    let text = std::fs::read_to_string(&tool).unwrap();
    std::fs::write(&tool, text + "\n// an edit to a tool\n").unwrap();
    assert_eq!(id(&core, &lock), before, "an edit to the tools changed it");
    for tool_only in ["indicatif", "ctrlc", "font8x8"] {
        assert_eq!(
            id(&core, &bump(&lock, tool_only)),
            before,
            "{tool_only} changed it"
        );
    }

    // Every reader (core/loader) and the file formats only the loader links: a fix to the XML
    // reader must not refuse the plugins built before it.
    for reader in [
        "reader.rs",
        "mitsuba/mod.rs",
        "mitsuba/shape.rs",
        "load.rs",
        "build/mod.rs",
        "mesh/ply.rs",
        "mesh/mod.rs",
        "texture.rs",
        "image.rs",
    ] {
        let path = core.join("loader/src").join(reader);
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, text + "\n// a fix to a reader\n").unwrap();
        assert_eq!(id(&core, &lock), before, "an edit to {reader} changed it");
    }
    for loader_only in ["roxmltree", "tobj", "toml", "image", "exr"] {
        assert_eq!(
            id(&core, &bump(&lock, loader_only)),
            before,
            "{loader_only} changed it"
        );
    }

    // A type that crosses the boundary, and a dependency of core (glam, whose vectors are in
    // every core type).
    assert_ne!(
        id(&core, &bump(&lock, "glam")),
        before,
        "glam did not change it"
    );
    let integrator = core.join("src/integrator.rs");
    let text = std::fs::read_to_string(&integrator).unwrap();
    std::fs::write(
        &integrator,
        text.replace(
            "pub struct MapPhoton {",
            "pub struct MapPhoton {\n    pub extra: u8,",
        ),
    )
    .unwrap();
    assert_ne!(
        id(&core, &lock),
        before,
        "a change to a boundary type did not change it"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn core_dependency_closure_holds_its_dependencies_and_not_the_tools_or_readers() {
    let lock = std::fs::read_to_string(repo_root().join("Cargo.lock")).unwrap();
    let closure = dependency_closure(&lock, "foton-core");
    let has = |name: &str| closure.iter().any(|p| p.starts_with(&format!("{name} ")));
    for name in ["foton-core", "glam", "obvhs", "rayon", "rayon-core"] {
        assert!(has(name), "{name} missing from {closure:?}");
    }
    // (clap may be in it: the lock file's closure holds the optional dependencies of core's
    // dependencies, obvhs's rdst has criterion, which has clap: more than needed, never less.)
    for name in [
        "indicatif",
        "ctrlc",
        "font8x8",
        "foton",
        "foton-photonmap",
        "foton-loader",
        // The readers' formats, linked by the loader only.
        "roxmltree",
        "tobj",
        "toml",
        "image",
        "exr",
    ] {
        assert!(!has(name), "{name} is in core's closure");
    }
}
