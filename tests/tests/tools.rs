//! The seeing-and-comparing commands: `foton photons`. Its images are checked by size and
//! by a few pixels (no snapshots), its numbers through the printed counts; every bad input must end in a message naming
//! the problem and a non-zero exit. Images are 32x32 with few samples and photons.

use foton_core::film::read_image;
use foton_tests::{Run, foton_with_plugins, header, temp_dir, write};
use std::path::{Path, PathBuf};

const SIZE: u32 = 32;

/// A white box [-1, 1] x [0, 2] x [-1, 1] with red and green side walls, open towards the
/// camera, and a sphere in it that hides part of the floor; lit by a point light; diffuse
/// only; rendered by `path`. The camera's field of view
/// is wide enough that the image corners see past the box, into nothing.
fn box_scene() -> String {
    let mut s = header("path", 2, 5, SIZE, SIZE);
    s += r#"
[camera]
position = [0.0, 1.0, 3.9]
look_at = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 60.0

[integrators.photon]
global_photons = 20000
caustic_photons = 2000
k = 10

[materials.white]
type = "diffuse"
reflectance = [0.7, 0.7, 0.7]

[materials.red]
type = "diffuse"
reflectance = [0.6, 0.1, 0.1]

[materials.green]
type = "diffuse"
reflectance = [0.1, 0.6, 0.1]
"#;
    let quads = [
        ("[-1, 0, 1]", "[2, 0, 0]", "[0, 0, -2]", "white"), // floor
        ("[-1, 2, -1]", "[2, 0, 0]", "[0, 0, 2]", "white"), // ceiling
        ("[-1, 0, -1]", "[2, 0, 0]", "[0, 2, 0]", "white"), // back
        ("[-1, 0, -1]", "[0, 2, 0]", "[0, 0, 2]", "red"),
        ("[1, 0, -1]", "[0, 0, 2]", "[0, 2, 0]", "green"),
    ];
    for (origin, u, v, material) in quads {
        s += &format!(
            "\n[[shapes]]\ntype = \"quad\"\norigin = {origin}\nu = {u}\nv = {v}\nmaterial = \"{material}\"\n"
        );
    }
    s += "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.4, 0.35, -0.3]\nradius = 0.35\nmaterial = \"white\"\n";
    s + "\n[[lights]]\ntype = \"point\"\nposition = [0.0, 1.8, 0.0]\nintensity = [2, 2, 2]\n"
}

fn setup(name: &str) -> (PathBuf, PathBuf) {
    let dir = temp_dir(name);
    let scene = write(&dir, "box.toml", &box_scene());
    (dir, scene)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(run: &Run) {
    assert_eq!(
        run.code, 0,
        "stdout:\n{}\nstderr:\n{}",
        run.stdout, run.stderr
    );
}

/// Fails unless the run failed with a message containing every one of `words`.
fn fails_with(run: &Run, words: &[&str]) {
    assert_ne!(run.code, 0, "expected a failure; stdout:\n{}", run.stdout);
    for w in words {
        assert!(
            run.stderr.contains(w),
            "expected {w:?} in the message:\n{}",
            run.stderr
        );
    }
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
}

/// The number printed just before `word` ("1234 stored").
fn count_before(text: &str, word: &str) -> u64 {
    let end = text
        .find(&format!(" {word}"))
        .unwrap_or_else(|| panic!("no `{word}` in {text}"));
    let start = text[..end].rfind(' ').map_or(0, |i| i + 1);
    text[start..end]
        .parse()
        .unwrap_or_else(|_| panic!("no number before `{word}` in {text}"))
}

// ---------------------------------------------------------------------------------------------
// foton photons
// ---------------------------------------------------------------------------------------------

#[test]
fn photons_shows_the_floor_and_leaves_the_background_black() {
    let (dir, scene) = setup("photons");
    let run = foton_with_plugins(&["photons", s(&scene), "-q"]);
    ok(&run);
    // The default output lies beside the scene.
    let (w, h, px) = read_image(&dir.join("box-global-photons.png")).unwrap();
    assert_eq!((w, h), (SIZE, SIZE));
    let at = |x: u32, y: u32| px[(y * w + x) as usize];
    // The floor spans rows 22-25 (see box_scene's camera): photons show there.
    let floor: Vec<_> = (22..26)
        .flat_map(|y| (12..20).map(move |x| (x, y)))
        .collect();
    let lit = floor
        .iter()
        .filter(|&&(x, y)| at(x, y).max_element() > 0.0)
        .count();
    assert!(
        lit * 2 > floor.len(),
        "{lit} of {} floor pixels",
        floor.len()
    );
    // The corners see past the box.
    for (x0, y0) in [(0, 0), (SIZE - 3, 0), (0, SIZE - 3), (SIZE - 3, SIZE - 3)] {
        for y in y0..y0 + 3 {
            for x in x0..x0 + 3 {
                assert_eq!(at(x, y).max_element(), 0.0, "pixel ({x}, {y})");
            }
        }
    }
    let stored = count_before(&run.stdout, "stored");
    let drawn = count_before(&run.stdout, "drawn");
    assert!(drawn > 0, "{}", run.stdout);
    // Photons behind the sphere and on its far side are not drawn.
    assert!(drawn < stored, "{}", run.stdout);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn caustic_map_of_a_diffuse_scene_is_empty() {
    let (dir, scene) = setup("photons-caustic");
    let out = dir.join("caustic.png");
    let run = foton_with_plugins(&[
        "photons",
        s(&scene),
        "--map",
        "caustic",
        "-o",
        s(&out),
        "-q",
    ]);
    ok(&run);
    assert_eq!(count_before(&run.stdout, "stored"), 0, "{}", run.stdout);
    assert_eq!(count_before(&run.stdout, "drawn"), 0, "{}", run.stdout);
    let (_, _, px) = read_image(&out).unwrap();
    assert!(px.iter().all(|p| p.max_element() == 0.0));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn photons_are_the_same_for_any_number_of_threads() {
    let (dir, scene) = setup("photons-threads");
    let image = |threads: &str| {
        let out = dir.join(format!("t{threads}.exr"));
        let run = foton_with_plugins(&[
            "photons",
            s(&scene),
            "-o",
            s(&out),
            "--threads",
            threads,
            "--dot",
            "3",
            "-q",
        ]);
        ok(&run);
        read_image(&out).unwrap().2
    };
    assert_eq!(image("1"), image("2"));
    let _ = std::fs::remove_dir_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

#[test]
fn set_without_a_value_is_refused() {
    let (dir, scene) = setup("bad-set");
    let out = dir.join("x.png");
    let run = foton_with_plugins(&["photons", s(&scene), "--set", "render.seed", "-o", s(&out)]);
    fails_with(&run, &["render.seed", "expected KEY.PATH=VALUE"]);
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn unknown_map_is_refused() {
    let (dir, scene) = setup("bad-map");
    let run = foton_with_plugins(&["photons", s(&scene), "--map", "volume"]);
    fails_with(&run, &["invalid value 'volume'", "global", "caustic"]);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn missing_output_folder_is_found_before_rendering() {
    let (dir, scene) = setup("bad-output");
    let out = dir.join("no-such-folder").join("x.png");
    let run = foton_with_plugins(&["photons", s(&scene), "-o", s(&out)]);
    fails_with(&run, &["no-such-folder", "does not exist"]);
    assert!(run.stdout.is_empty(), "nothing rendered: {}", run.stdout);
    let _ = std::fs::remove_dir_all(dir);
}
