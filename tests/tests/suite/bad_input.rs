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

use foton_tests::{Run, foton_with_plugins, plugin_dir, temp_dir, write};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

/// Longer than any of these runs can legitimately take; past it, the command hangs.
const TIMEOUT: Duration = Duration::from_secs(120);

/// A small valid scene. Tests replace one line of it (see [`edit`]) to make it invalid.
const BASE: &str = r#"# A valid 8x8 test scene.
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
const QUAD: &str = "type = \"quad\"\norigin = [-1, 0, 0]\nu = [2, 0, 0]\nv = [0, 2, 0]";

/// The sphere of [`BASE`], to be replaced by another shape.
const SPHERE: &str = "type = \"sphere\"\ncenter = [0, 1, 0]\nradius = 0.5";

/// A homogeneous medium `fog`, appended to a scene.
const FOG: &str =
    "\n[media.fog]\ntype = \"homogeneous\"\nsigma_a = [0.1, 0.1, 0.1]\nsigma_s = [0.5, 0.5, 0.5]\n";

/// The messages the `panicky` fixture panics with.
const CREATE_PANIC: &str = "deliberate panic in create";
const RENDER_PANIC: &str = "deliberate panic in render";

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// `text` with the one occurrence of `from` replaced by `to`.
fn edit(text: &str, from: &str, to: &str) -> String {
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
fn foton(args: &[&str]) -> Run {
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

fn show(run: &Run) -> String {
    format!(
        "exit code {}\n--- stdout ---\n{}--- stderr ---\n{}",
        run.code, run.stdout, run.stderr
    )
}

/// Asserts that the run failed with exit code 1 and that stderr contains every needle.
fn assert_error(run: &Run, needles: &[&str]) {
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
struct SceneFile {
    dir: PathBuf,
    path: PathBuf,
    text: String,
}

impl SceneFile {
    fn new(name: &str, text: &str) -> SceneFile {
        let dir = temp_dir(name);
        let path = write(&dir, "scene.toml", text);
        SceneFile {
            dir,
            path,
            text: text.to_string(),
        }
    }

    fn path_str(&self) -> &str {
        self.path.to_str().expect("temporary paths are UTF-8")
    }

    /// `foton check SCENE EXTRA...`.
    fn check(&self, extra: &[&str]) -> Run {
        let mut args = vec!["check", self.path_str()];
        args.extend_from_slice(extra);
        foton(&args)
    }

    /// `foton render SCENE -q EXTRA...`.
    fn render(&self, extra: &[&str]) -> Run {
        let mut args = vec!["render", self.path_str(), "-q"];
        args.extend_from_slice(extra);
        foton(&args)
    }

    /// "PATH:LINE:" for the line of the scene holding `needle`.
    fn at(&self, needle: &str) -> String {
        format!("{}:{}:", self.path.display(), line_of(&self.text, needle))
    }

    /// Asserts a scene error: exit code 1, the file and line of `needle`, the key path
    /// (between backticks, as the messages write it) and the expected words.
    fn assert_scene_error(&self, run: &Run, needle: &str, key: &str, words: &[&str]) {
        let at = self.at(needle);
        let key = format!("`{key}`");
        let mut needles = vec![at.as_str(), key.as_str()];
        needles.extend_from_slice(words);
        assert_error(run, &needles);
    }

    /// Checks `foton check` fails with the scene error described (see assert_scene_error).
    fn check_fails(&self, needle: &str, key: &str, words: &[&str]) {
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
fn scene_with(name: &str, from: &str, to: &str) -> SceneFile {
    SceneFile::new(name, &edit(BASE, from, to))
}

/// The scene, with the one line holding `from` replaced by `to`, must fail `foton check` at
/// the line holding `to` (its first line) with `key` and `words` in the message.
fn assert_bad_value(name: &str, from: &str, to: &str, key: &str, words: &[&str]) {
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
        &["unknown shape type \"cube\"", "sphere, quad, disk, mesh"],
    );
}

#[test]
fn missing_shape_type_lists_the_types() {
    // Reported at the `[[shapes]]` header, the table the key is missing from.
    let scene = scene_with("missing-shape-type", "type = \"sphere\"\n", "");
    scene.check_fails(
        "[[shapes]]",
        "shapes[0].type",
        &["missing", "sphere, quad, disk, mesh"],
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
            "diffuse, mirror, conductor, roughconductor, dielectric, thindielectric, roughdielectric, plastic, roughplastic, null",
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
        &edit(&text, "type = \"homogeneous\"", "type = \"heterogeneous\""),
    );
    scene.check_fails(
        "type = \"heterogeneous\"",
        "media.fog.type",
        &[
            "unknown medium type \"heterogeneous\"",
            "expected one of: homogeneous",
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
// Wrong type or length of a value
// ---------------------------------------------------------------------------------------------

#[test]
fn number_instead_of_an_rgb_array() {
    assert_bad_value(
        "reflectance-number",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = 2",
        "materials.white.reflectance",
        &["expected an array of 3 numbers", "found an integer `2`"],
    );
}

#[test]
fn rgb_array_of_the_wrong_length() {
    assert_bad_value(
        "reflectance-length",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [1, 2]",
        "materials.white.reflectance",
        &["expected an array of 3 numbers", "found 2 element(s)"],
    );
}

#[test]
fn array_with_a_non_number() {
    assert_bad_value(
        "center-string",
        "center = [0, 1, 0]",
        "center = [0, \"a\", 0]",
        "shapes[0].center",
        &["expected an array of 3 numbers"],
    );
}

#[test]
fn string_instead_of_a_number() {
    assert_bad_value(
        "radius-string",
        "radius = 0.5",
        "radius = \"big\"",
        "shapes[0].radius",
        &["expected a number", "found a string"],
    );
}

#[test]
fn float_instead_of_an_integer() {
    assert_bad_value(
        "spp-float",
        "spp = 1",
        "spp = 1.5",
        "render.spp",
        &["expected an integer", "found a float `1.5`"],
    );
}

#[test]
fn negative_integer() {
    assert_bad_value(
        "seed-negative",
        "seed = 3",
        "seed = -1",
        "render.seed",
        &["expected a non-negative integer", "-1"],
    );
}

#[test]
fn table_instead_of_a_string() {
    assert_bad_value(
        "material-table",
        "material = \"white\"",
        "material = { name = \"white\" }",
        "shapes[0].material",
        &["expected a string", "found a table"],
    );
}

#[test]
fn section_that_is_not_a_table() {
    // A root key, so before the first table header; the `[film]` table goes.
    let text = edit(BASE, "# A valid 8x8 test scene.\n", "film = 3\n");
    let text = edit(
        &text,
        "[film]\nwidth = 8\nheight = 8\noutput = \"out.png\"\n",
        "",
    );
    let scene = SceneFile::new("film-not-table", &text);
    scene.check_fails(
        "film = 3",
        "film",
        &["expected a table", "found an integer"],
    );
}

// ---------------------------------------------------------------------------------------------
// Numbers that make no sense
// ---------------------------------------------------------------------------------------------

#[test]
fn negative_radius() {
    assert_bad_value(
        "radius-negative",
        "radius = 0.5",
        "radius = -1",
        "shapes[0].radius",
        &["must be positive", "-1"],
    );
    assert_bad_value(
        "radius-zero",
        "radius = 0.5",
        "radius = 0",
        "shapes[0].radius",
        &["must be positive", "0"],
    );
}

#[test]
fn nan_and_infinite_numbers() {
    assert_bad_value(
        "radius-nan",
        "radius = 0.5",
        "radius = nan",
        "shapes[0].radius",
        &["expected a finite number", "NaN"],
    );
    assert_bad_value(
        "center-inf",
        "center = [0, 1, 0]",
        "center = [0, inf, 0]",
        "shapes[0].center",
        &["expected a finite number", "inf"],
    );
    assert_bad_value(
        "intensity-inf",
        "intensity = [1, 1, 1]",
        "intensity = [1, -inf, 1]",
        "lights[0].intensity",
        &["expected a finite number", "inf"],
    );
}

/// Core bug: `Properties::finite` checks the f64 before narrowing it to f32, so 1e40 passes
/// and becomes an infinite radius, on which the BVH builder (obvhs) panics.
#[test]
fn number_too_large_for_f32_radius() {
    assert_bad_value(
        "radius-huge",
        "radius = 0.5",
        "radius = 1e40",
        "shapes[0].radius",
        &["finite"],
    );
}

/// Core bug (same cause): a camera position of 1e39 becomes infinite and is accepted.
#[test]
fn number_too_large_for_f32_camera_position() {
    assert_bad_value(
        "position-huge",
        "position = [0, 1, 3.9]",
        "position = [0, 1e39, 3.9]",
        "camera.position",
        &["finite"],
    );
}

#[test]
fn reflectance_above_one_is_a_warning() {
    let scene = scene_with(
        "reflectance-above-one",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [1.5, 0.5, 0.5]",
    );
    let run = scene.check(&[]);
    assert_eq!(run.code, 0, "a warning, not an error:\n{}", show(&run));
    let warning = run
        .stderr
        .lines()
        .find(|l| l.starts_with("warning: "))
        .unwrap_or_else(|| panic!("no warning:\n{}", show(&run)));
    for needle in [
        scene.at("reflectance = [1.5"),
        "`materials.white.reflectance`".into(),
        "above 1".into(),
    ] {
        assert!(
            warning.contains(&needle),
            "the warning lacks {needle:?}:\n{}",
            show(&run)
        );
    }
    // It renders, with the warning.
    let run = scene.render(&[]);
    assert_eq!(run.code, 0, "{}", show(&run));
    assert!(run.stderr.contains("above 1"), "{}", show(&run));
}

#[test]
fn negative_reflectance_is_an_error() {
    assert_bad_value(
        "reflectance-negative",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [0.5, -0.1, 0.5]",
        "materials.white.reflectance",
        &["expected non-negative values"],
    );
}

#[test]
fn non_positive_index_of_refraction() {
    let text = edit(BASE, "type = \"diffuse\"", "type = \"dielectric\"");
    let text = edit(&text, "reflectance = [0.5, 0.5, 0.5]", "ior = 0");
    let scene = SceneFile::new("ior-zero", &text);
    scene.check_fails("ior = 0", "materials.white.ior", &["must be positive"]);
}

#[test]
fn zero_area_quad() {
    // Parallel edges.
    let quad = edit(QUAD, "v = [0, 2, 0]", "v = [4, 0, 0]");
    let scene = scene_with("quad-parallel", SPHERE, &quad);
    scene.check_fails("v = [4, 0, 0]", "shapes[0].v", &["zero area"]);
    // A zero edge.
    let quad = edit(QUAD, "u = [2, 0, 0]", "u = [0, 0, 0]");
    let scene = scene_with("quad-zero", SPHERE, &quad);
    scene.check_fails("v = [0, 2, 0]", "shapes[0].v", &["zero area"]);
}

#[test]
fn field_of_view_outside_0_180() {
    for (i, fov) in ["0", "180", "-10", "200"].iter().enumerate() {
        assert_bad_value(
            &format!("fov-{i}"),
            "fov = 40",
            &format!("fov = {fov}"),
            "camera.fov",
            &["must be in (0, 180) degrees", &format!("found {fov}")],
        );
    }
    assert_bad_value(
        "fov-nan",
        "fov = 40",
        "fov = nan",
        "camera.fov",
        &["expected a finite number"],
    );
}

#[test]
fn film_width_or_height_zero() {
    assert_bad_value(
        "width-zero",
        "width = 8",
        "width = 0",
        "film.width",
        &["must be between 1 and 32768", "found 0"],
    );
    assert_bad_value(
        "height-zero",
        "height = 8",
        "height = 0",
        "film.height",
        &["must be between 1 and 32768", "found 0"],
    );
}

#[test]
fn samples_per_pixel_zero() {
    assert_bad_value(
        "spp-zero",
        "spp = 1",
        "spp = 0",
        "render.spp",
        &["must be at least 1"],
    );
    // From the command line: one message about the option, whatever the bad value (clap
    // would otherwise take `-4` for an unknown flag and advise `-- -4`).
    let scene = SceneFile::new("spp-zero-flag", BASE);
    for (value, words) in [
        ("0", "at least 1, not 0"),
        ("-4", "at least 1, not -4"),
        ("four", "expected a whole number"),
    ] {
        let run = scene.render(&["--spp", value]);
        assert_ne!(run.code, 0, "--spp {value} rendered:\n{}", show(&run));
        let errors: Vec<&str> = run
            .stderr
            .lines()
            .filter(|l| l.starts_with("error"))
            .collect();
        assert_eq!(
            errors.len(),
            1,
            "--spp {value}: one message:\n{}",
            show(&run)
        );
        assert!(
            errors[0].contains("--spp") && errors[0].contains(words),
            "--spp {value}:\n{}",
            show(&run)
        );
        assert!(!run.stderr.contains("tip:"), "{}", show(&run));
    }
}

/// A value set on the command line that nothing reads is an error (the user asked for it),
/// naming what it probably meant; the same key written in the file stays a warning (the test
/// above). Values for another integrator than the rendering one are checked by that one.
#[test]
fn set_keys_that_nothing_reads_are_errors() {
    let scene = SceneFile::new("set-typo", BASE);
    for (set, words) in [
        (
            "integrators.path.rr_dept=3",
            &[
                "--set integrators.path.rr_dept",
                "did you mean `integrators.path.rr_depth`",
            ][..],
        ),
        (
            "render.sppp=2",
            &["--set render.sppp", "did you mean `render.spp`"][..],
        ),
        (
            "film.colour=1",
            &[
                "--set film.colour",
                "neither the scene nor the integrator `path`",
            ][..],
        ),
        (
            "integrators.photon.kk=10",
            &[
                "--set integrators.photon.kk",
                "the integrator `photon`",
                "did you mean `integrators.photon.k`",
            ][..],
        ),
        (
            "integrators.pth.rr_depth=3",
            &[
                "--set integrators.pth.rr_depth",
                "no integrator plugin named `pth`",
            ][..],
        ),
    ] {
        let run = scene.render(&["--set", set]);
        assert_error(&run, words);
    }
    // Keys that are read are fine, also those of another integrator than the rendering one
    // (settings for several, switched with --integrator, as a file holds them).
    let run = scene.render(&[
        "--set",
        "integrators.photon.k=10",
        "--set",
        "integrators.path.rr_depth=3",
        "--set",
        "render.spp=1",
    ]);
    assert_eq!(run.code, 0, "{}", show(&run));
    // A sweep over a misspelt key renders nothing (it used to render identical cells).
    let out = scene.dir.join("sweep.png");
    let run = foton(&[
        "sweep",
        scene.path_str(),
        "--set",
        "integrators.path.rr_dept=3,4",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_error(&run, &["integrators.path.rr_dept", "did you mean"]);
    assert!(!out.exists());
}

#[test]
fn camera_looking_at_itself() {
    assert_bad_value(
        "look-at-self",
        "look_at = [0, 1, 0]",
        "look_at = [0, 1, 3.9]",
        "camera.look_at",
        &["same point as position"],
    );
}

// ---------------------------------------------------------------------------------------------
// OBJ meshes
// ---------------------------------------------------------------------------------------------

/// A scene whose shape is the mesh `file`, with `obj` (if any) written next to it.
fn mesh_scene(name: &str, file: &str, obj: Option<&str>, extra: &str) -> SceneFile {
    let shape = format!("type = \"mesh\"\nfile = \"{file}\"{extra}");
    let scene = scene_with(name, SPHERE, &shape);
    if let Some(obj) = obj {
        write(&scene.dir, file, obj);
    }
    scene
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

#[test]
fn obj_missing() {
    let scene = mesh_scene("obj-missing", "missing.obj", None, "");
    scene.check_fails(
        "file = \"missing.obj\"",
        "shapes[0].file",
        &["cannot open mesh", "missing.obj", "No such file"],
    );
}

#[test]
fn obj_malformed() {
    for (i, obj) in [
        "v 0 zz 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
    ]
    .iter()
    .enumerate()
    {
        let scene = mesh_scene(&format!("obj-malformed-{i}"), "bad.obj", Some(obj), "");
        scene.check_fails(
            "file = \"bad.obj\"",
            "shapes[0].file",
            &["bad.obj", "malformed OBJ"],
        );
    }
}

#[test]
fn obj_index_out_of_range() {
    for (i, face) in ["f 1 2 7", "f 0 1 2", "f -10 1 2", "f 1 2 4294967299"]
        .iter()
        .enumerate()
    {
        let obj = format!("{TRIANGLE}{face}\n");
        let scene = mesh_scene(&format!("obj-range-{i}"), "range.obj", Some(&obj), "");
        scene.check_fails(
            "file = \"range.obj\"",
            "shapes[0].file",
            &["range.obj", "index out of bounds"],
        );
    }
}

#[test]
fn obj_without_triangles() {
    for (i, obj) in [
        "",
        "# only a comment\n",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    ]
    .iter()
    .enumerate()
    {
        let scene = mesh_scene(&format!("obj-empty-{i}"), "empty.obj", Some(obj), "");
        scene.check_fails(
            "file = \"empty.obj\"",
            "shapes[0].file",
            &["empty.obj", "no triangles"],
        );
    }
}

#[test]
fn obj_non_finite_vertex() {
    let obj = "v 0 nan 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let scene = mesh_scene("obj-nan", "nan.obj", Some(obj), "");
    scene.check_fails(
        "file = \"nan.obj\"",
        "shapes[0].file",
        &["nan.obj", "non-finite vertex"],
    );
}

#[test]
fn mesh_transform_with_zero_scale() {
    let obj = format!("{TRIANGLE}f 1 2 3\n");
    let scene = mesh_scene(
        "obj-scale-zero",
        "tri.obj",
        Some(&obj),
        "\ntransform = { scale = [1, 0, 1] }",
    );
    scene.check_fails(
        "transform = { scale",
        "shapes[0].transform.scale",
        &["must not be zero"],
    );
}

// ---------------------------------------------------------------------------------------------
// Media
// ---------------------------------------------------------------------------------------------

#[test]
fn medium_negative_sigma() {
    let text = edit(
        &format!("{BASE}{FOG}"),
        "sigma_a = [0.1, 0.1, 0.1]",
        "sigma_a = [0.1, -0.1, 0.1]",
    );
    let scene = SceneFile::new("medium-sigma", &text);
    scene.check_fails(
        "sigma_a = [0.1, -0.1, 0.1]",
        "media.fog.sigma_a",
        &["expected non-negative values"],
    );
}

#[test]
fn medium_phase_g_out_of_range() {
    for (i, g) in ["1", "-1.5"].iter().enumerate() {
        let text = format!("{BASE}{FOG}phase = {{ type = \"hg\", g = {g} }}\n");
        let scene = SceneFile::new(&format!("medium-g-{i}"), &text);
        scene.check_fails(
            "phase = {",
            "media.fog.phase.g",
            &["|g| < 1", &format!("found {g}")],
        );
    }
}

#[test]
fn interior_medium_on_a_quad() {
    let text = edit(
        &format!("{BASE}{FOG}"),
        SPHERE,
        &format!("{QUAD}\ninterior = \"fog\""),
    );
    let scene = SceneFile::new("interior-quad", &text);
    scene.check_fails(
        "interior = \"fog\"",
        "shapes[0].interior",
        &["quad", "not closed", "interior medium"],
    );
}

#[test]
fn interior_medium_on_an_open_mesh() {
    let obj = format!("{TRIANGLE}f 1 2 3\n");
    let shape = "type = \"mesh\"\nfile = \"open.obj\"\ninterior = \"fog\"";
    let text = edit(&format!("{BASE}{FOG}"), SPHERE, shape);
    let scene = SceneFile::new("interior-open-mesh", &text);
    write(&scene.dir, "open.obj", &obj);
    scene.check_fails(
        "interior = \"fog\"",
        "shapes[0].interior",
        &["mesh", "not closed", "interior medium"],
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

// ---------------------------------------------------------------------------------------------
// Output
// ---------------------------------------------------------------------------------------------

/// Arguments that make the render itself panic (the `panicky` plugin): an error about the
/// output that comes with them was found before rendering.
const PANIC_IF_RENDERED: [&str; 4] = [
    "--integrator",
    "panicky",
    "--set",
    "integrators.panicky.panic_in=\"render\"",
];

#[test]
fn output_folder_that_does_not_exist() {
    let scene = SceneFile::new("output-missing", BASE);
    let mut args = vec!["-o", "/nonexistent-dir/x.png"];
    args.extend_from_slice(&PANIC_IF_RENDERED);
    let run = scene.render(&args);
    assert_error(
        &run,
        &[
            "/nonexistent-dir/x.png",
            "output folder /nonexistent-dir does not exist",
        ],
    );
    assert!(
        !run.stderr.contains("panicked"),
        "the render started before the output was checked:\n{}",
        show(&run)
    );
}

#[test]
fn scene_output_folder_that_does_not_exist() {
    let scene = scene_with(
        "film-output-missing",
        "output = \"out.png\"",
        "output = \"no-such-folder/out.png\"",
    );
    let run = scene.render(&PANIC_IF_RENDERED);
    assert_error(&run, &["no-such-folder", "does not exist"]);
    assert!(!run.stderr.contains("panicked"), "{}", show(&run));
}

#[test]
fn output_folder_that_is_not_writable() {
    use std::os::unix::fs::PermissionsExt;
    let scene = SceneFile::new("output-read-only", BASE);
    let ro = scene.dir.join("read-only");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let probe = ro.join("probe");
    let can_still_write = std::fs::write(&probe, b"").is_ok();
    let _ = std::fs::remove_file(&probe);
    if can_still_write {
        // Running as root (or with CAP_DAC_OVERRIDE): permissions are not enforced, the folder
        // is writable after all, and there is no error to expect. Only this assertion is
        // skipped.
        eprintln!("output_folder_that_is_not_writable: permissions not enforced (root?); skipped");
    } else {
        let out = ro.join("x.png");
        let mut args = vec!["-o", out.to_str().unwrap()];
        args.extend_from_slice(&PANIC_IF_RENDERED);
        let run = scene.render(&args);
        assert_error(
            &run,
            &[
                &out.display().to_string(),
                &format!("output folder {} is not writable", ro.display()),
            ],
        );
        assert!(!run.stderr.contains("panicked"), "{}", show(&run));
    }
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// Core bug: `check_output` checks the folder but not the path itself, so an output path that
/// is an existing folder is only found out when the image is written, after the render.
#[test]
fn output_path_that_is_a_folder_fails_before_rendering() {
    let scene = SceneFile::new("output-is-folder", BASE);
    let out = scene.dir.join("image.png");
    std::fs::create_dir(&out).unwrap();
    let mut args = vec!["-o", out.to_str().unwrap()];
    args.extend_from_slice(&PANIC_IF_RENDERED);
    let run = scene.render(&args);
    assert_error(&run, &[&out.display().to_string()]);
    assert!(
        !run.stderr.contains("panicked"),
        "the render started before the output was checked:\n{}",
        show(&run)
    );
}

#[test]
fn output_with_an_unsupported_extension() {
    let scene = SceneFile::new("output-extension", BASE);
    let out = scene.dir.join("x.jpg");
    let run = scene.render(&["-o", out.to_str().unwrap()]);
    assert_error(
        &run,
        &[
            &out.display().to_string(),
            "unsupported output format",
            ".exr",
            ".png",
        ],
    );
    assert_bad_value(
        "film-output-extension",
        "output = \"out.png\"",
        "output = \"out.jpg\"",
        "film.output",
        &["unsupported format", ".exr", ".png"],
    );
}

// ---------------------------------------------------------------------------------------------
// Plugins
// ---------------------------------------------------------------------------------------------

fn lib_name(stem: &str) -> String {
    format!(
        "{}foton_{stem}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    )
}

/// A real shared library that is not a foton plugin: a proc-macro library cargo built next to
/// the test executable, or else the system's libm. None if neither can be found.
fn some_shared_library() -> Option<PathBuf> {
    let (prefix, suffix) = (std::env::consts::DLL_PREFIX, std::env::consts::DLL_SUFFIX);
    let mut candidates: Vec<PathBuf> = std::fs::read_dir(plugin_dir())
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                // Not the Python extension (lib_foton.so, after a wheel build): it needs the
                // interpreter's symbols and cannot be loaded by a program.
                n.starts_with(prefix)
                    && n.ends_with(suffix)
                    && !n.starts_with("libfoton")
                    && !n.starts_with("lib_foton")
            })
        })
        .collect();
    candidates.sort();
    if let Some(p) = candidates.into_iter().next() {
        return Some(p);
    }
    for p in [
        "/lib/x86_64-linux-gnu/libm.so.6",
        "/usr/lib/x86_64-linux-gnu/libm.so.6",
        "/lib/aarch64-linux-gnu/libm.so.6",
        "/usr/lib64/libm.so.6",
        "/lib64/libm.so.6",
    ] {
        if Path::new(p).is_file() {
            return Some(p.into());
        }
    }
    let out = std::process::Command::new("ldconfig")
        .arg("-p")
        .output()
        .ok()?;
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| l.trim_start().starts_with("libm.so"))
        .filter_map(|l| l.split(" => ").nth(1))
        .map(|p| PathBuf::from(p.trim()))
        .find(|p| p.is_file())
}

/// A C string literal for `s` (NULL for None).
fn c_literal(s: Option<&str>) -> String {
    let Some(s) = s else {
        return "NULL".into();
    };
    let mut out = String::from("\"");
    for b in s.bytes() {
        match b {
            b'"' | b'\\' => {
                out.push('\\');
                out.push(b as char);
            }
            0x20..=0x7e => out.push(b as char),
            _ => out.push_str(&format!("\\{b:03o}")),
        }
    }
    out.push('"');
    out
}

/// What a C imitation of an integrator plugin declares.
struct FakeDeclaration<'a> {
    api_version: u32,
    core_version: Option<&'a str>,
    rustc_version: Option<&'a str>,
    build_id: Option<&'a str>,
    name: &'a str,
}

/// Compiles a C library exporting `FOTON_INTEGRATOR_PLUGIN` with the layout of
/// `foton_core::plugin::IntegratorDeclaration` into `dir/libfoton_STEM.so`. Panics with a clear
/// message when there is no C compiler.
fn build_c_plugin(dir: &Path, stem: &str, decl: &FakeDeclaration<'_>) -> PathBuf {
    let source = format!(
        r#"#include <stddef.h>
#include <stdint.h>
struct foton_integrator_declaration {{
    uint32_t api_version;
    const char *core_version;
    const char *rustc_version;
    const char *build_id;
    const char *name;
    const char *description;
    void (*create)(void);
}};
static void create(void) {{}}
const struct foton_integrator_declaration FOTON_INTEGRATOR_PLUGIN = {{
    {api}, {core}, {rustc}, {build}, {name}, "a C imitation of a plugin (test)", create
}};
"#,
        api = decl.api_version,
        core = c_literal(decl.core_version),
        rustc = c_literal(decl.rustc_version),
        build = c_literal(decl.build_id),
        name = c_literal(Some(decl.name)),
    );
    let src = write(dir, &format!("{stem}.c"), &source);
    let lib = dir.join(lib_name(stem));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let output = std::process::Command::new(&cc)
        .args(["-shared", "-fPIC", "-o"])
        .arg(&lib)
        .arg(&src)
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "cannot run the C compiler `{cc}` ({e}); these tests need one to build fake \
                 plugins (install cc, or set CC)"
            )
        });
    assert!(
        output.status.success(),
        "`{cc} -shared -fPIC` failed on {}:\n{}",
        src.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    lib
}

/// The line of `foton plugins --plugin-dir DIR` that reports `file` as skipped.
fn skipped_line(dir: &Path, file: &Path) -> String {
    let run = foton(&["plugins", "--plugin-dir", dir.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", show(&run));
    let shown = file.display().to_string();
    run.stdout
        .lines()
        .find(|l| l.contains(&shown))
        .unwrap_or_else(|| panic!("{shown} is not listed:\n{}", show(&run)))
        .to_string()
}

/// `foton render SCENE --integrator NAME --plugin-dir DIR` must fail, naming `file` and `words`.
fn assert_integrator_refused(dir: &Path, name: &str, file: &Path, words: &[&str]) {
    let scene = SceneFile::new(&format!("refused-{name}"), BASE);
    let run = scene.render(&["--integrator", name, "--plugin-dir", dir.to_str().unwrap()]);
    let shown = file.display().to_string();
    let mut needles = vec![
        format!("no integrator plugin named `{name}`"),
        format!("skipped {shown}"),
    ];
    needles.extend(words.iter().map(|w| w.to_string()));
    let needles: Vec<&str> = needles.iter().map(String::as_str).collect();
    assert_error(&run, &needles);
}

#[test]
fn files_that_are_not_foton_plugins_are_skipped_with_a_reason() {
    let dir = temp_dir("not-plugins");
    let garbage = write(
        &dir,
        &lib_name("garbage"),
        "this is not a shared library, just text long enough to hold an ELF header\n",
    );
    let line = skipped_line(&dir, &garbage);
    assert!(
        line.starts_with("skipped") && line.contains("cannot be loaded"),
        "{line}"
    );
    assert_integrator_refused(&dir, "garbage", &garbage, &["cannot be loaded"]);

    match some_shared_library() {
        Some(real) => {
            let fake = dir.join(lib_name("fake"));
            std::fs::copy(&real, &fake).unwrap();
            let line = skipped_line(&dir, &fake);
            assert!(
                line.starts_with("skipped")
                    && line.contains("not a foton plugin")
                    && line.contains("FOTON_INTEGRATOR_PLUGIN"),
                "{} (a copy of {}) is not skipped as not a plugin: {line}",
                fake.display(),
                real.display()
            );
            assert_integrator_refused(&dir, "fake", &fake, &["not a foton plugin"]);
        }
        None => eprintln!(
            "no shared library found to copy (no proc-macro library next to the test \
             executable, no libm): only the garbage file was tried"
        ),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Core bug: the reason given for a file that cannot be loaded is libloading's bare
/// "dlopen failed": the dynamic loader's own explanation (here "invalid ELF header"), which is
/// the error's `source()`, is dropped.
#[test]
fn unloadable_plugin_reason_says_why() {
    let dir = temp_dir("garbage-reason");
    let garbage = write(
        &dir,
        &lib_name("garbage"),
        "this is not a shared library, just text long enough to hold an ELF header\n",
    );
    let line = skipped_line(&dir, &garbage);
    assert!(
        line.contains("ELF header"),
        "the reason does not say what is wrong with the file: {line}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plugin_built_against_another_core_is_refused() {
    let core = foton_core::CORE_VERSION;
    let rustc = foton_core::RUSTC_VERSION;
    let build = foton_core::BUILD_ID;
    let cases = [
        (
            "othercore",
            FakeDeclaration {
                api_version: foton_core::plugin::PLUGIN_API_VERSION,
                core_version: Some("0.0.0-other"),
                rustc_version: Some(rustc),
                build_id: Some(build),
                name: "othercore",
            },
            "foton-core version",
            "0.0.0-other",
            core,
        ),
        (
            "otherrustc",
            FakeDeclaration {
                api_version: foton_core::plugin::PLUGIN_API_VERSION,
                core_version: Some(core),
                rustc_version: Some("rustc 0.0.0-other"),
                build_id: Some(build),
                name: "otherrustc",
            },
            "rustc version",
            "rustc 0.0.0-other",
            rustc,
        ),
        (
            "otherbuild",
            FakeDeclaration {
                api_version: foton_core::plugin::PLUGIN_API_VERSION,
                core_version: Some(core),
                rustc_version: Some(rustc),
                build_id: Some("0000000000000000-other"),
                name: "otherbuild",
            },
            "core build identifier",
            "0000000000000000-other",
            build,
        ),
    ];
    let dir = temp_dir("other-core");
    for (stem, decl, what, theirs, ours) in &cases {
        let lib = build_c_plugin(&dir, stem, decl);
        let expected = format!("built against {what} `{theirs}`, but this foton has `{ours}`");
        let line = skipped_line(&dir, &lib);
        assert!(
            line.starts_with("skipped") && line.contains(&expected),
            "expected `{expected}` in: {line}"
        );
        assert_integrator_refused(&dir, stem, &lib, &[&expected, "rebuild the plugin"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plugin_with_another_api_version_is_refused() {
    let dir = temp_dir("other-api");
    let decl = FakeDeclaration {
        api_version: 999,
        core_version: Some(foton_core::CORE_VERSION),
        rustc_version: Some(foton_core::RUSTC_VERSION),
        build_id: Some(foton_core::BUILD_ID),
        name: "api999",
    };
    let lib = build_c_plugin(&dir, "api999", &decl);
    let expected = format!(
        "plugin API version 999, but this foton expects {}",
        foton_core::plugin::PLUGIN_API_VERSION
    );
    let line = skipped_line(&dir, &lib);
    assert!(line.contains(&expected), "expected `{expected}` in: {line}");
    assert_integrator_refused(&dir, "api999", &lib, &[&expected]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plugin_declaration_with_a_null_version_is_refused() {
    let dir = temp_dir("null-version");
    let decl = FakeDeclaration {
        api_version: foton_core::plugin::PLUGIN_API_VERSION,
        core_version: None,
        rustc_version: Some(foton_core::RUSTC_VERSION),
        build_id: Some(foton_core::BUILD_ID),
        name: "nullcore",
    };
    let lib = build_c_plugin(&dir, "nullcore", &decl);
    let line = skipped_line(&dir, &lib);
    assert!(
        line.contains("its declaration has no foton-core version"),
        "{line}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `foton render` with the `panicky` plugin set to panic in `panic_in`.
fn render_panicky(name: &str, panic_in: &str) -> (SceneFile, Run) {
    let scene = SceneFile::new(name, BASE);
    let set = format!("integrators.panicky.panic_in={panic_in}");
    let run = scene.render(&["--integrator", "panicky", "--set", &set]);
    (scene, run)
}

/// After a plugin panicked, the process is still alive and renders normally.
fn assert_still_works(scene: &SceneFile) {
    let run = scene.render(&[]);
    assert_eq!(run.code, 0, "after a plugin panic:\n{}", show(&run));
}

#[test]
fn panic_in_plugin_create_is_an_error() {
    // The value quoted as TOML, and bare (taken as a string).
    for value in ["\"create\"", "create"] {
        let (scene, run) = render_panicky("panic-create", value);
        assert_error(&run, &["panicked", CREATE_PANIC]);
        assert_still_works(&scene);
    }
}

#[test]
fn panic_in_plugin_render_is_an_error() {
    let (scene, run) = render_panicky("panic-render", "\"render\"");
    assert_error(&run, &["panicked", RENDER_PANIC, "panicky"]);
    assert!(!scene.dir.join("out.png").exists(), "an image was written");
    assert_still_works(&scene);
}

/// Core bug: a panic in a plugin's `create` is reported as "render failed: integrator creation
/// panicked: ..." without saying which plugin (or file) panicked.
#[test]
fn panic_in_plugin_create_names_the_plugin() {
    let (_scene, run) = render_panicky("panic-create-name", "\"create\"");
    assert_error(&run, &["panicked", CREATE_PANIC]);
    assert!(
        run.stderr.contains("panicky") || run.stderr.contains("foton_test_panicky"),
        "the error does not say which plugin panicked:\n{}",
        show(&run)
    );
}

#[test]
fn bad_plugin_parameter_is_a_scene_error() {
    let scene = SceneFile::new(
        "panicky-bad-parameter",
        &format!("{BASE}\n[integrators.panicky]\npanic_in = \"elsewhere\"\n"),
    );
    let run = scene.render(&["--integrator", "panicky"]);
    scene.assert_scene_error(
        &run,
        "panic_in = \"elsewhere\"",
        "integrators.panicky.panic_in",
        &["unknown value \"elsewhere\"", "create, render"],
    );
}

// ---------------------------------------------------------------------------------------------
// Media: values that are not numbers, and cameras in no well-defined medium
// ---------------------------------------------------------------------------------------------

#[test]
fn medium_non_finite_sigma() {
    for (i, bad) in ["[nan, 0.5, 0.5]", "[0.5, inf, 0.5]"].iter().enumerate() {
        let text = edit(
            &format!("{BASE}{FOG}"),
            "sigma_s = [0.5, 0.5, 0.5]",
            &format!("sigma_s = {bad}"),
        );
        let scene = SceneFile::new(&format!("medium-sigma-nan-{i}"), &text);
        scene.check_fails(
            &format!("sigma_s = {bad}"),
            "media.fog.sigma_s",
            &["expected a finite number"],
        );
    }
}

#[test]
fn camera_on_a_medium_boundary() {
    // The sphere of BASE (centre [0, 1, 0], radius 0.5) filled with fog, the camera on it.
    let text = edit(
        &edit(
            &format!("{BASE}{FOG}"),
            SPHERE,
            &format!("{SPHERE}\ninterior = \"fog\""),
        ),
        "position = [0, 1, 3.9]",
        "position = [0, 1, 0.5]",
    );
    let scene = SceneFile::new("camera-on-boundary", &text);
    scene.check_fails(
        "position = [0, 1, 0.5]",
        "camera.position",
        &[
            "medium around the camera is undefined",
            "shapes[0]",
            "boundary",
        ],
    );
    // The render fails the same way, before rendering.
    let run = scene.render(&[]);
    assert_error(&run, &["medium around the camera is undefined"]);
}

#[test]
fn camera_inside_overlapping_media() {
    let second = "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.6, 1, 0]\nradius = 0.5\nmaterial = \"white\"\ninterior = \"fog\"\n";
    let text = edit(
        &edit(
            &format!("{BASE}{FOG}{second}"),
            SPHERE,
            &format!("{SPHERE}\ninterior = \"fog\""),
        ),
        "position = [0, 1, 3.9]",
        "position = [0.3, 1, 0]",
    );
    let scene = SceneFile::new("camera-in-overlap", &text);
    scene.check_fails(
        "position = [0.3, 1, 0]",
        "camera.position",
        &[
            "medium around the camera is undefined",
            "shapes[0] and shapes[1]",
            "overlap",
        ],
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
