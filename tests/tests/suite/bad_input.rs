//! Bad input: every case must end in a clear error (exit code 1) that names the file, and for
//! scene errors the TOML key path and line, with the essential words of what was expected;
//! never a panic or a hang. Warnings (reflectance above one, unknown fields without
//! `--strict`) leave the exit code at 0.
//!
//! The `foton` command runs in-process (foton_cli::run) on a helper thread, so that a
//! panic is reported as a bug of the command and a hang as a timeout instead of stalling the
//! suite. Renders are 8x8 pixels at 1 sample per pixel.
//!
//! Plugin cases use the `panicky` fixture plugin (tests/fixtures/panicky), copies of shared
//! libraries that are not foton plugins, and small C libraries compiled at test time with `cc`
//! that imitate plugins built against another foton-core or another plugin API.

use foton_tests::{Run, foton_with_plugins, temp_dir, write};
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Duration;

/// Longer than any of these runs can legitimately take; past it, the command hangs.
const TIMEOUT: Duration = Duration::from_secs(120);

/// A small valid scene. Tests replace one line of it (see [`edit`]) to make it invalid.
pub(crate) const BASE: &str = r#"# A valid 8x8 test scene.
[render]
integrator = "path"
spp = 1
seed = 3

[film]
width = 8
height = 8
output = "out.png"

[camera]
position = [0, 1, 3.9]
look_at = [0, 1, 0]
up = [0, 1, 0]
fov = 40

[materials.white]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[[shapes]]
type = "sphere"
center = [0, 1, 0]
radius = 0.5
material = "white"

[[lights]]
type = "point"
position = [0, 1.8, 0]
intensity = [1, 1, 1]
"#;

/// A quad instead of the sphere of [`BASE`].
pub(crate) const QUAD: &str = "type = \"quad\"\norigin = [-1, 0, 0]\nu = [2, 0, 0]\nv = [0, 2, 0]";

/// The sphere of [`BASE`], to be replaced by another shape.
pub(crate) const SPHERE: &str = "type = \"sphere\"\ncenter = [0, 1, 0]\nradius = 0.5";

/// A homogeneous medium `fog`, appended to a scene.
pub(crate) const FOG: &str =
    "\n[media.fog]\ntype = \"homogeneous\"\nsigma_a = [0.1, 0.1, 0.1]\nsigma_s = [0.5, 0.5, 0.5]\n";

/// The messages the `panicky` fixture panics with.
pub(crate) const CREATE_PANIC: &str = "deliberate panic in create";
pub(crate) const RENDER_PANIC: &str = "deliberate panic in render";

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// `text` with the one occurrence of `from` replaced by `to`.
pub(crate) fn edit(text: &str, from: &str, to: &str) -> String {
    assert_eq!(
        text.matches(from).count(),
        1,
        "test bug: {from:?} must occur exactly once in the scene"
    );
    text.replace(from, to)
}

/// The 1-based line of the one line of `text` containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    let lines: Vec<usize> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains(needle))
        .map(|(i, _)| i + 1)
        .collect();
    assert_eq!(
        lines.len(),
        1,
        "test bug: {needle:?} must be on exactly one line of the scene"
    );
    lines[0]
}

fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(non-string payload)".into()
    }
}

/// Runs `foton ARGS... --plugin-dir <test plugins>` in-process on a helper thread: a panic of
/// the command, or a run longer than [`TIMEOUT`], fails the test with a message saying so.
pub(crate) fn foton(args: &[&str]) -> Run {
    let owned: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    let shown = owned.join(" ");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let refs: Vec<&str> = owned.iter().map(String::as_str).collect();
        let result = std::panic::catch_unwind(|| foton_with_plugins(&refs));
        let _ = tx.send(result.map_err(|p| panic_text(p.as_ref())));
    });
    match rx.recv_timeout(TIMEOUT) {
        Ok(Ok(run)) => run,
        Ok(Err(message)) => panic!(
            "`foton {shown}` panicked instead of reporting an error (a bug in foton): {message}"
        ),
        Err(_) => panic!("`foton {shown}` hung: no result after {TIMEOUT:?}"),
    }
}

pub(crate) fn show(run: &Run) -> String {
    format!(
        "exit code {}\n--- stdout ---\n{}--- stderr ---\n{}",
        run.code, run.stdout, run.stderr
    )
}

/// Asserts that the run failed with exit code 1 and that stderr contains every needle.
pub(crate) fn assert_error(run: &Run, needles: &[&str]) {
    assert_eq!(run.code, 1, "expected exit code 1:\n{}", show(run));
    assert!(
        run.stderr.starts_with("error: "),
        "expected an `error: ` message:\n{}",
        show(run)
    );
    for needle in needles {
        assert!(
            run.stderr.contains(needle),
            "the error does not contain {needle:?}:\n{}",
            show(run)
        );
    }
}

/// A scene file `scene.toml` holding `text`, in a fresh folder.
pub(crate) struct SceneFile {
    pub(crate) dir: PathBuf,
    path: PathBuf,
    text: String,
}

impl SceneFile {
    pub(crate) fn new(name: &str, text: &str) -> SceneFile {
        let dir = temp_dir(name);
        let path = write(&dir, "scene.toml", text);
        SceneFile {
            dir,
            path,
            text: text.to_string(),
        }
    }

    pub(crate) fn path_str(&self) -> &str {
        self.path.to_str().expect("temporary paths are UTF-8")
    }

    /// `foton check SCENE EXTRA...`.
    pub(crate) fn check(&self, extra: &[&str]) -> Run {
        let mut args = vec!["check", self.path_str()];
        args.extend_from_slice(extra);
        foton(&args)
    }

    /// `foton render SCENE -q EXTRA...`.
    pub(crate) fn render(&self, extra: &[&str]) -> Run {
        let mut args = vec!["render", self.path_str(), "-q"];
        args.extend_from_slice(extra);
        foton(&args)
    }

    /// "PATH:LINE:" for the line of the scene holding `needle`.
    pub(crate) fn at(&self, needle: &str) -> String {
        format!("{}:{}:", self.path.display(), line_of(&self.text, needle))
    }

    /// Asserts a scene error: exit code 1, the file and line of `needle`, the key path
    /// (between backticks, as the messages write it) and the expected words.
    pub(crate) fn assert_scene_error(&self, run: &Run, needle: &str, key: &str, words: &[&str]) {
        let at = self.at(needle);
        let key = format!("`{key}`");
        let mut needles = vec![at.as_str(), key.as_str()];
        needles.extend_from_slice(words);
        assert_error(run, &needles);
    }

    /// Checks `foton check` fails with the scene error described (see assert_scene_error).
    pub(crate) fn check_fails(&self, needle: &str, key: &str, words: &[&str]) {
        let run = self.check(&[]);
        self.assert_scene_error(&run, needle, key, words);
    }
}

impl Drop for SceneFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// [`BASE`] with one replacement, written to a fresh folder.
pub(crate) fn scene_with(name: &str, from: &str, to: &str) -> SceneFile {
    SceneFile::new(name, &edit(BASE, from, to))
}

/// The scene, with the one line holding `from` replaced by `to`, must fail `foton check` at
/// the line holding `to` (its first line) with `key` and `words` in the message.
pub(crate) fn assert_bad_value(name: &str, from: &str, to: &str, key: &str, words: &[&str]) {
    let scene = scene_with(name, from, to);
    let needle = to.lines().next().unwrap();
    scene.check_fails(needle, key, words);
}

// ---------------------------------------------------------------------------------------------
// The valid scene is valid (otherwise every other test proves nothing)
// ---------------------------------------------------------------------------------------------

#[test]
fn base_scene_is_valid_and_renders() {
    let scene = SceneFile::new("base", BASE);
    let run = scene.check(&[]);
    assert_eq!(run.code, 0, "{}", show(&run));
    assert!(
        !run.stderr.contains("warning"),
        "unexpected warning:\n{}",
        show(&run)
    );
    let run = scene.render(&[]);
    assert_eq!(run.code, 0, "{}", show(&run));
    assert!(scene.dir.join("out.png").is_file());
}

// ---------------------------------------------------------------------------------------------
// Files and TOML syntax
// ---------------------------------------------------------------------------------------------

#[test]
fn missing_scene_file() {
    let dir = temp_dir("missing-scene");
    let path = dir.join("no-such-scene.toml");
    for cmd in ["check", "render"] {
        let run = foton(&[cmd, path.to_str().unwrap()]);
        assert_error(
            &run,
            &[&path.display().to_string(), "No such file or directory"],
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scene_path_is_a_folder() {
    let dir = temp_dir("scene-is-folder");
    let run = foton(&["check", dir.to_str().unwrap()]);
    assert_error(&run, &[&dir.display().to_string(), "directory"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn toml_syntax_error_names_file_line_and_column() {
    let scene = scene_with("syntax", "spp = 1", "spp = = 1");
    let line = line_of(&scene.text, "spp = = 1");
    // The second `=` is the unexpected token: 1-based column 7.
    let column = "spp = = 1".rfind('=').unwrap() + 1;
    let run = scene.check(&[]);
    assert_error(
        &run,
        &[
            &format!("{}:{line}:{column}:", scene.path.display()),
            "TOML syntax error",
        ],
    );
}

#[test]
fn toml_unclosed_table_header() {
    let scene = scene_with("syntax-header", "[film]", "[film");
    let run = scene.check(&[]);
    assert_error(&run, &[&scene.at("[film"), "TOML syntax error", "]"]);
}

#[test]
fn toml_duplicate_key() {
    let scene = scene_with("syntax-duplicate", "seed = 3", "seed = 3\nspp = 2");
    let run = scene.check(&[]);
    assert_error(
        &run,
        &[&scene.at("spp = 2"), "TOML syntax error", "duplicate"],
    );
}

#[test]
fn toml_duplicate_key_names_its_path_and_first_line() {
    let scene = scene_with(
        "duplicate-key-path",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [0.5, 0.5, 0.5]\nreflectance = [0.9, 0.9, 0.9]",
    );
    let first = line_of(&scene.text, "reflectance = [0.5, 0.5, 0.5]");
    let run = scene.check(&[]);
    assert_error(
        &run,
        &[
            &scene.at("reflectance = [0.9, 0.9, 0.9]"),
            "`materials.white.reflectance`: duplicate key",
            &format!("first written on line {first}"),
        ],
    );
    // A table header written twice, and a key repeated in the second of two [[shapes]].
    let second_shape = "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0.3, 0]\nradius = 0.2\nradius = 0.3\nmaterial = \"white\"\n";
    let text = format!("{BASE}\n[film]\nwidth = 16\n{second_shape}");
    let scene = SceneFile::new("duplicate-header-and-array", &text);
    let run = scene.check(&[]);
    assert_error(&run, &["`film`: duplicate key", "first written on line 7"]);
    let text = format!("{BASE}{second_shape}");
    let scene = SceneFile::new("duplicate-in-array", &text);
    let run = scene.check(&[]);
    assert_error(
        &run,
        &[
            &scene.at("radius = 0.3"),
            "`shapes[1].radius`: duplicate key",
            &format!("first written on line {}", line_of(&text, "radius = 0.2")),
        ],
    );
}

// ---------------------------------------------------------------------------------------------
// Unknown sections and types: the message lists the known ones
// ---------------------------------------------------------------------------------------------

#[test]
fn unknown_section_lists_the_sections() {
    let scene = SceneFile::new("unknown-section", &format!("{BASE}\n[renderer]\nspp = 4\n"));
    scene.check_fails(
        "[renderer]",
        "renderer",
        &[
            "unknown section",
            "render, film, camera, integrators, materials, media, shapes, lights, scene",
        ],
    );
}

#[test]
fn unknown_shape_type_lists_the_types() {
    assert_bad_value(
        "unknown-shape",
        "type = \"sphere\"",
        "type = \"cube\"",
        "shapes[0].type",
        &[
            "unknown shape type \"cube\"",
            "sphere, quad, disk, mesh, curve, sdfgrid",
        ],
    );
}

#[test]
fn missing_shape_type_lists_the_types() {
    // Reported at the `[[shapes]]` header, the table the key is missing from.
    let scene = scene_with("missing-shape-type", "type = \"sphere\"\n", "");
    scene.check_fails(
        "[[shapes]]",
        "shapes[0].type",
        &["missing", "sphere, quad, disk, mesh, curve, sdfgrid"],
    );
}

#[test]
fn unknown_material_type_lists_the_types() {
    assert_bad_value(
        "unknown-material",
        "type = \"diffuse\"",
        "type = \"velvet\"",
        "materials.white.type",
        &[
            "unknown material type \"velvet\"",
            "diffuse, mirror, conductor, dielectric, thindielectric, roughconductor, roughdielectric, plastic, roughplastic, phong, ward, roughdiffuse, principled, principledthin, difftrans, coateddiffuse, coatedconductor, coating, pplastic, disney_sheen, disney_clearcoat, null, blend",
        ],
    );
}

#[test]
fn unknown_light_type_lists_the_types() {
    assert_bad_value(
        "unknown-light",
        "type = \"point\"",
        "type = \"sun\"",
        "lights[0].type",
        &["unknown light type \"sun\"", "expected one of: point, spot"],
    );
}

#[test]
fn unknown_medium_type_lists_the_types() {
    let text = format!("{BASE}{FOG}");
    let scene = SceneFile::new(
        "unknown-medium",
        &edit(&text, "type = \"homogeneous\"", "type = \"volumetric\""),
    );
    scene.check_fails(
        "type = \"volumetric\"",
        "media.fog.type",
        &[
            "unknown medium type \"volumetric\"",
            "expected one of: homogeneous, heterogeneous",
        ],
    );
}

#[test]
fn unknown_integrator_lists_the_available_ones() {
    // Named on the command line.
    let scene = SceneFile::new("unknown-integrator-flag", BASE);
    let run = scene.check(&["--integrator", "nope"]);
    assert_error(
        &run,
        &[
            "no integrator plugin named `nope`",
            "available:",
            "path",
            "panicky",
        ],
    );
    // Named in the scene file.
    let scene = scene_with(
        "unknown-integrator-file",
        "integrator = \"path\"",
        "integrator = \"nope\"",
    );
    let run = scene.check(&[]);
    assert_error(
        &run,
        &[
            "no integrator plugin named `nope`",
            "available:",
            "path",
            "panicky",
        ],
    );
}

/// Core bug: an unknown integrator named in the scene is reported without the scene file, the
/// key path `render.integrator` or its line (see the final report).
#[test]
fn unknown_integrator_in_the_scene_names_file_key_and_line() {
    let scene = scene_with(
        "unknown-integrator-where",
        "integrator = \"path\"",
        "integrator = \"nope\"",
    );
    let run = scene.check(&[]);
    scene.assert_scene_error(
        &run,
        "integrator = \"nope\"",
        "render.integrator",
        &["nope", "available:", "path"],
    );
}

// ---------------------------------------------------------------------------------------------
// References to undefined materials and media
// ---------------------------------------------------------------------------------------------

#[test]
fn undefined_material() {
    assert_bad_value(
        "undefined-material",
        "material = \"white\"",
        "material = \"red\"",
        "shapes[0].material",
        &["material \"red\" is not defined", "defined: white"],
    );
}

#[test]
fn undefined_interior_medium() {
    // No media at all.
    assert_bad_value(
        "undefined-interior-none",
        "material = \"white\"",
        "interior = \"smoke\"\nmaterial = \"white\"",
        "shapes[0].interior",
        &["medium \"smoke\" is not defined"],
    );
    // Another medium is defined: it is listed.
    let text = edit(
        &format!("{BASE}{FOG}"),
        "material = \"white\"",
        "interior = \"smoke\"\nmaterial = \"white\"",
    );
    let scene = SceneFile::new("undefined-interior", &text);
    scene.check_fails(
        "interior = \"smoke\"",
        "shapes[0].interior",
        &["medium \"smoke\" is not defined", "defined: fog"],
    );
}

#[test]
fn undefined_scene_medium() {
    let text = format!("{BASE}{FOG}\n[scene]\nmedium = \"smoke\"\n");
    let scene = SceneFile::new("undefined-scene-medium", &text);
    scene.check_fails(
        "medium = \"smoke\"",
        "scene.medium",
        &["medium \"smoke\" is not defined", "defined: fog"],
    );
}

// ---------------------------------------------------------------------------------------------
// --set
// ---------------------------------------------------------------------------------------------

#[test]
fn set_without_equals_sign() {
    let scene = SceneFile::new("set-no-equals", BASE);
    let run = scene.check(&["--set", "render.spp"]);
    assert_error(&run, &["--set render.spp", "expected KEY.PATH=VALUE"]);
}

#[test]
fn set_with_an_empty_key() {
    let scene = SceneFile::new("set-empty-key", BASE);
    for bad in [".spp=3", "render..spp=3", "=3"] {
        let run = scene.check(&["--set", bad]);
        assert_error(&run, &[&format!("--set {bad}"), "empty key"]);
    }
}

#[test]
fn set_through_a_value_that_is_not_a_table() {
    let scene = SceneFile::new("set-not-table", BASE);
    let run = scene.check(&["--set", "render.spp.x=3"]);
    assert_error(
        &run,
        &["--set render.spp.x=3", "`spp` is an integer, not a table"],
    );
    let run = scene.check(&["--set", "shapes.radius=3"]);
    assert_error(
        &run,
        &["--set shapes.radius=3", "`shapes` is an array, not a table"],
    );
}

#[test]
fn set_value_of_the_wrong_type() {
    let scene = SceneFile::new("set-wrong-type", BASE);
    let run = scene.check(&["--set", "render.spp=abc"]);
    assert_error(
        &run,
        &[
            scene.path_str(),
            "`render.spp`",
            "expected an integer",
            "\"abc\"",
        ],
    );
    let run = scene.check(&["--set", "materials.white.reflectance=[1,2]"]);
    assert_error(
        &run,
        &[
            "`materials.white.reflectance`",
            "expected an array of 3 numbers",
        ],
    );
}

/// Core bug: a `--set` value that fails to convert (an integer too large for i64) is reported
/// as a TOML syntax error at line 1, column 5 of the scene file, which has nothing there.
#[test]
fn set_integer_too_large_is_blamed_on_set() {
    let scene = SceneFile::new("set-too-large", BASE);
    let run = scene.check(&["--set", "render.seed=99999999999999999999"]);
    assert_eq!(run.code, 1, "{}", show(&run));
    assert!(
        !run.stderr.contains(&format!("{}:1:", scene.path.display())),
        "the error blames line 1 of the scene file for a --set value:\n{}",
        show(&run)
    );
    assert!(
        run.stderr.contains("render.seed"),
        "the error does not name the key set:\n{}",
        show(&run)
    );
}

/// Core bug: the nodes inside a `--set` inline table keep the line and column they had in the
/// text `v = VALUE` the value was parsed from, so the error points at line 1 of the scene file.
#[test]
fn set_inline_table_error_is_not_blamed_on_line_1() {
    let scene = SceneFile::new("set-inline-table", &format!("{BASE}{FOG}"));
    let run = scene.check(&["--set", "media.fog.phase={ type = \"hg\", g = 1 }"]);
    assert_error(&run, &["`media.fog.phase.g`", "|g| < 1"]);
    assert!(
        !run.stderr.contains(&format!("{}:1:", scene.path.display())),
        "the error blames line 1 of the scene file for a --set value:\n{}",
        show(&run)
    );
}

// ---------------------------------------------------------------------------------------------
// Unknown fields: a warning, an error with --strict
// ---------------------------------------------------------------------------------------------

#[test]
fn unknown_field_is_a_warning_without_strict_and_an_error_with_it() {
    let scene = scene_with("unknown-field", "width = 8", "widht = 8");
    // Without `width` the film is 256 wide: still fine for `check`.
    let run = scene.check(&[]);
    assert_eq!(run.code, 0, "only a warning:\n{}", show(&run));
    let warning = scene.at("widht");
    assert!(
        run.stderr.lines().any(|l| l.starts_with("warning: ")
            && l.contains(&warning)
            && l.contains("`film.widht`")
            && l.contains("unknown field")),
        "no warning naming file, line and key:\n{}",
        show(&run)
    );
    let run = scene.check(&["--strict"]);
    scene.assert_scene_error(&run, "widht", "film.widht", &["unknown field"]);
    let run = scene.render(&["--strict"]);
    scene.assert_scene_error(&run, "widht", "film.widht", &["unknown field"]);
}

#[test]
fn unknown_integrator_parameter_is_a_warning_without_strict_and_an_error_with_it() {
    let scene = SceneFile::new(
        "unknown-integrator-parameter",
        &format!("{BASE}\n[integrators.path]\nrr_dept = 3\n"),
    );
    let run = scene.check(&[]);
    assert_eq!(run.code, 0, "only a warning:\n{}", show(&run));
    assert!(
        run.stderr.lines().any(|l| l.starts_with("warning: ")
            && l.contains(&scene.at("rr_dept"))
            && l.contains("`integrators.path.rr_dept`")),
        "no warning naming file, line and key:\n{}",
        show(&run)
    );
    let run = scene.check(&["--strict"]);
    scene.assert_scene_error(
        &run,
        "rr_dept",
        "integrators.path.rr_dept",
        &["unknown field"],
    );
}
