//! Helpers shared by the integration tests: finding the plugins cargo built, running the
//! `foton` command in-process, writing scenes to temporary folders, rendering.

use foton_cli::{TermProgress, prepare, render_prepared};
use foton_core::film::Film;
use foton_core::plugin::Registry;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

/// The folder with the plugin cdylibs: cargo puts the dev-dependencies' cdylibs in
/// target/<profile>/deps, the folder of the test executables.
pub fn plugin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.parent().expect("test executable folder").to_path_buf()
}

pub fn registry() -> Registry {
    Registry::discover(&[plugin_dir()])
}

/// A folder holding the `panicky` fixture plugin as `libfoton_panicky.so`. Cargo builds it as
/// `libpanicky_fixture.so`, a name the plugin search skips, so that it never lies beside the
/// real plugins under a plugin's name; the tests that want it add this folder.
pub fn fixture_plugin_dir() -> PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let file = |stem: &str| {
            format!(
                "{}{stem}{}",
                std::env::consts::DLL_PREFIX,
                std::env::consts::DLL_SUFFIX
            )
        };
        let built = plugin_dir().join(file("panicky_fixture"));
        assert!(built.is_file(), "{} was not built", built.display());
        let dir = temp_dir("fixture-plugins");
        std::fs::copy(&built, dir.join(file("foton_panicky"))).unwrap();
        dir
    })
    .clone()
}

/// Output of one in-process run of the `foton` command.
pub struct Run {
    pub code: u8,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `foton ARGS...` in-process (the command's code lives in the foton crate's library).
pub fn foton(args: &[&str]) -> Run {
    let mut argv: Vec<std::ffi::OsString> = vec!["foton".into()];
    argv.extend(args.iter().map(|a| a.into()));
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = foton_cli::run(argv, &mut out, &mut err);
    Run {
        code,
        stdout: String::from_utf8_lossy(&out).into_owned(),
        stderr: String::from_utf8_lossy(&err).into_owned(),
    }
}

/// `foton ARGS... --plugin-dir <the test plugin folder> --plugin-dir <the fixture folder>`.
pub fn foton_with_plugins(args: &[&str]) -> Run {
    let (dir, fixtures) = (plugin_dir(), fixture_plugin_dir());
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["--plugin-dir", dir.to_str().unwrap()]);
    all.extend(["--plugin-dir", fixtures.to_str().unwrap()]);
    foton(&all)
}

/// A fresh, empty folder for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let dir = std::env::temp_dir().join(format!(
        "foton-test-{}-{}-{name}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `text` to `dir/name` and returns the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The repository's root folder.
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// Renders a scene file in-process with the test plugins; `overrides` as `--set` values.
pub fn render_file(scene: &Path, overrides: &[&str], threads: usize) -> Film {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let prepared = prepare(scene, &overrides, &[plugin_dir()], true)
        .unwrap_or_else(|e| panic!("cannot prepare {}: {e}", scene.display()));
    let progress = TermProgress::new(true);
    let (film, _) = render_prepared(&prepared, threads, &progress)
        .unwrap_or_else(|e| panic!("render of {} failed: {e}", scene.display()));
    film
}

/// Renders a scene given as TOML text.
pub fn render_toml(name: &str, toml: &str, overrides: &[&str], threads: usize) -> Film {
    let dir = temp_dir(name);
    let path = write(&dir, "scene.toml", toml);
    render_film_and_clean(&dir, &path, overrides, threads)
}

fn render_film_and_clean(dir: &Path, path: &Path, overrides: &[&str], threads: usize) -> Film {
    let film = render_file(path, overrides, threads);
    let _ = std::fs::remove_dir_all(dir);
    film
}

/// Mean and standard error of the mean of per-pixel values over a pixel rectangle (see
/// `stats::block_stats`).
pub fn region_mean(film: &Film, x0: u32, y0: u32, x1: u32, y1: u32) -> (glam::Vec3, glam::Vec3) {
    let b = stats::block_stats(film, stats::Rect::new(x0, y0, x1, y1));
    (b.mean.as_vec3(), b.se.as_vec3())
}

/// The standard scene header with a camera looking down -z from z = `cam_z`.
pub fn header(integrator: &str, spp: u32, max_depth: u32, width: u32, height: u32) -> String {
    format!(
        r#"
[render]
integrator = "{integrator}"
spp = {spp}
seed = 7
max_depth = {max_depth}

[film]
width = {width}
height = {height}
output = "out.exr"
"#
    )
}

/// The point-light fog box of the photon-beam tests (tests/tests/suite/beams.rs, ppb.rs): a fog box
/// [-1, 1] x [-1.6, 1.6] x [-1, 1] behind a null boundary with a point light 0.2 above it,
/// nothing else, 24 x 24 pixels: the camera (in vacuum) sees only light scattered by the fog.
/// The light sits above the field of view: in view it would be a singularity (in-scattered
/// radiance ~ 1 / distance of the ray from it; a camera ray passing within the beam width of
/// it crosses every beam that leaves it) whose pixel alone made the image mean vary by +-5 %
/// from seed to seed. And outside the fog: inside it, the path tracer's next-event estimate
/// from the scattering points of multiply scattered paths has infinite variance (1 / r^2 from
/// vertices whose density near the light is flat: the integral of r^-2 at 0), so its
/// reference at max_depth 8 was off by up to +18 % for some seeds;
/// at 0.2 from the nearest fog, 1 / r^2 is bounded. `phase` as in TOML; `tables`: TOML
/// appended (the integrator's table).
pub fn point_light_fog(
    integrator: &str,
    spp: u32,
    max_depth: u32,
    phase: &str,
    tables: &str,
) -> String {
    let mut s = header(integrator, spp, max_depth, 24, 24);
    s += &format!(
        r#"
[camera]
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 36.0
[materials.boundary]
type = "null"
[media.fog]
type = "homogeneous"
sigma_a = [0.1, 0.1, 0.1]
sigma_s = [0.6, 0.6, 0.6]
phase = {phase}
[[shapes]]
type = "mesh"
file = "{cube}"
material = "boundary"
interior = "fog"
transform = {{ scale = [1.0, 1.6, 1.0] }}
[[lights]]
type = "point"
position = [0.3, 1.8, -0.2]
intensity = [2.0, 2.0, 2.0]
{tables}
"#,
        cube = repo_root().join("scenes/meshes/cube.obj").display()
    );
    s
}

/// `scenes/cornell-fog.toml` at 16 x 16 pixels with `set` (dotted overrides) on `threads`.
pub fn cornell_fog_16(set: &[&str], threads: usize) -> Film {
    let view = ["film.width=16", "film.height=16"];
    render_file(
        &repo_root().join("scenes/cornell-fog.toml"),
        &[&view[..], set].concat(),
        threads,
    )
}

/// A course scene (`scenes/NAME`) with its point light replaced by a small area light (0.5 x
/// 0.5, radiance 20, just below the ceiling), written to a temporary folder, so that the path
/// tracer can render its caustics too (through BSDF-sampled rays that reach the light through
/// glass).
pub fn with_area_light(scene: &str) -> PathBuf {
    let text = std::fs::read_to_string(repo_root().join("scenes").join(scene)).unwrap();
    let (before, _) = text.split_once("[[lights]]").unwrap();
    let text = before.to_string()
        + r#"
[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-0.25, 1.98, -0.25]
u = [0.5, 0.0, 0.0]
v = [0.0, 0.0, 0.5]
material = "black"
emission = [20.0, 20.0, 20.0]
"#;
    let dir = temp_dir("area-light");
    write(&dir, "scene.toml", &text)
}

/// Renders `scene` (a path from the repository root) with `integrator` and each `--set` of
/// `cases` after `extra`, and checks that each is refused: a non-zero exit, no panic, and an
/// error that contains the case's text (the parameter's name, or what was wrong).
pub fn assert_refused(scene: &str, integrator: &str, extra: &[&str], cases: &[(&str, &str)]) {
    let scene = repo_root().join(scene);
    for &(set, expect) in cases {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--integrator",
            integrator,
        ];
        for e in extra.iter().chain([&set]) {
            args.extend(["--set", e]);
        }
        args.extend(["-o", "/tmp/foton-never-written.png"]);
        let run = foton_with_plugins(&args);
        assert_ne!(run.code, 0, "{set} was accepted");
        assert!(run.stderr.contains(expect), "{set}: {}", run.stderr);
        assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    }
}

/// A white-furnace box: six inward-facing diffuse quads around [-1, 1]^3 of albedo `rho`,
/// each emitting `emission` inside (0: none), a camera in the box, `integrator` at `size` x
/// `size` pixels and 16 spp, then `extra` (lights, integrator tables).
pub fn closed_box(integrator: &str, size: u32, rho: f32, emission: f32, extra: &str) -> String {
    let c = |x: f32, y: f32, z: f32| format!("[{x}, {y}, {z}]");
    // (origin, u, v) with u x v pointing into the box.
    let faces = [
        (c(-1., -1., -1.), c(0., 0., 2.), c(2., 0., 0.)),
        (c(-1., 1., -1.), c(2., 0., 0.), c(0., 0., 2.)),
        (c(-1., -1., -1.), c(2., 0., 0.), c(0., 2., 0.)),
        (c(-1., -1., 1.), c(0., 2., 0.), c(2., 0., 0.)),
        (c(-1., -1., -1.), c(0., 2., 0.), c(0., 0., 2.)),
        (c(1., -1., -1.), c(0., 0., 2.), c(0., 2., 0.)),
    ];
    let mut s = header(integrator, 16, 1000, size, size);
    s += "[camera]\nposition = [0.0, 0.0, 0.9]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nfov = 90.0\n";
    s += &format!("[materials.wall]\ntype = \"diffuse\"\nreflectance = [{rho}, {rho}, {rho}]\n");
    for (o, u, v) in faces {
        s += &format!(
            "[[shapes]]\ntype = \"quad\"\norigin = {o}\nu = {u}\nv = {v}\nmaterial = \"wall\"\n"
        );
        if emission > 0.0 {
            s += &format!("emission = [{emission}, {emission}, {emission}]\n");
        }
    }
    s + extra
}

pub mod stats;
