//! The integrator plugins built by cargo are found, and the minimal example plugin of
//! docs/plugins.md (`normals`) loads and renders what it says.

use foton_tests::{header, plugin_dir, registry, render_toml};
use glam::Vec3;

#[test]
fn built_plugins_are_registered_with_descriptions() {
    let reg = registry();
    for name in ["path", "photon", "normals"] {
        let p = reg
            .integrators
            .iter()
            .find(|p| p.name == name)
            .unwrap_or_else(|| panic!("{name} not found; problems: {:?}", reg.problems));
        assert!(!p.description.is_empty());
        // Loaded from the file cargo built for it (the search only lists existing files, so
        // `is_file` could not fail; this can, if a name were read from the wrong library).
        let file = plugin_dir().join(format!(
            "{}foton_{name}{}",
            std::env::consts::DLL_PREFIX,
            std::env::consts::DLL_SUFFIX
        ));
        assert_eq!(p.file, file, "{name}");
    }
    assert!(
        reg.problems
            .iter()
            .all(|p| !p.file.to_string_lossy().contains("foton_path")),
        "{:?}",
        reg.problems
    );
}

#[test]
fn example_plugin_renders_normals() {
    let scene = format!(
        r#"{}
[camera]
position = [0.0, 0.0, 2.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 30.0
[materials.m]
type = "diffuse"
[[shapes]]
type = "quad"
origin = [-1.0, -1.0, 0.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "m"
"#,
        header("normals", 2, 0, 8, 8)
    );
    // u x v = +z faces the camera: colour (0.5, 0.5, 1).
    let film = render_toml("normals", &scene, &[], 2);
    for p in film.pixels() {
        assert!(
            (p - Vec3::new(0.5, 0.5, 1.0)).abs().max_element() < 1e-6,
            "{p}"
        );
    }
    // Seen from behind it keeps its own orientation (+z), unless flipped to the camera (-z).
    let back = ["camera.position=[0.0, 0.0, -2.0]"];
    let film = render_toml("normals-back", &scene, &back, 2);
    assert!(
        (film.pixel(4, 4) - Vec3::new(0.5, 0.5, 1.0))
            .abs()
            .max_element()
            < 1e-6
    );
    let flipped = [back[0], "integrators.normals.flip_to_camera=true"];
    let film = render_toml("normals-flip", &scene, &flipped, 2);
    assert!(
        (film.pixel(4, 4) - Vec3::new(0.5, 0.5, 0.0))
            .abs()
            .max_element()
            < 1e-6
    );
}

/// The test fixture that panics on purpose is built beside the real plugins (cargo puts every
/// cdylib of the workspace in target/<profile>/, and `cargo build --workspace` builds it), but
/// under a name the plugin search skips: the folder cargo built into lists the real plugins
/// only, and the fixture is found only where the tests copy it under a plugin's name.
#[test]
fn the_panicking_fixture_is_not_found_beside_the_real_plugins() {
    let mut names: Vec<String> = registry()
        .integrators
        .iter()
        .map(|p| p.name.clone())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "ao", "bdpt", "normals", "path", "photon", "ppb", "sppm", "vcm", "vpm"
        ]
    );
    let built = plugin_dir().join(format!(
        "{}panicky_fixture{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    assert!(built.is_file(), "{}", built.display());
    assert!(!foton_core::plugin::is_plugin_file(&built));
    let copied = foton_core::plugin::Registry::discover(&[foton_tests::fixture_plugin_dir()]);
    assert!(copied.integrators.iter().any(|p| p.name == "panicky"));
}
