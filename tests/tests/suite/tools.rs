//! The seeing-and-comparing commands: `foton photons`, `foton compare`, `foton sweep`. Their
//! images are checked by size and by a few pixels (no snapshots), their numbers through the
//! printed counts and the JSON of `compare`; every bad input must end in a message naming
//! the problem and a non-zero exit. Images are 32x32 with few samples and photons.

use foton_cli::montage::BORDER;
use foton_cli::sweep::{SweepSet, parse_set};
use foton_loader::image::read_image;
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

pub(crate) fn setup(name: &str) -> (PathBuf, PathBuf) {
    let dir = temp_dir(name);
    let scene = write(&dir, "box.toml", &box_scene());
    (dir, scene)
}

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

pub(crate) fn ok(run: &Run) {
    assert_eq!(
        run.code, 0,
        "stdout:\n{}\nstderr:\n{}",
        run.stdout, run.stderr
    );
}

/// Fails unless the run failed with a message containing every one of `words`.
pub(crate) fn fails_with(run: &Run, words: &[&str]) {
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

/// The text of the JSON value of `field` after the first `anchor` (from the start when
/// empty): a number, `null` or a string with its quotes.
fn json_value<'a>(json: &'a str, anchor: &str, field: &str) -> &'a str {
    let at = json
        .find(anchor)
        .unwrap_or_else(|| panic!("no {anchor} in {json}"));
    let rest = &json[at..];
    let key = format!("\"{field}\": ");
    let i = rest
        .find(&key)
        .unwrap_or_else(|| panic!("no {field} after {anchor} in {json}"))
        + key.len();
    rest[i..].split([',', '\n', '}']).next().unwrap().trim()
}

/// A numeric field of one integrator's entry in compare's JSON (None for null).
fn json_number(json: &str, integrator: &str, field: &str) -> Option<f64> {
    let value = json_value(json, &format!("\"name\": \"{integrator}\""), field);
    (value != "null").then(|| value.parse().unwrap())
}

// ---------------------------------------------------------------------------------------------
// foton photons
// ---------------------------------------------------------------------------------------------

/// The tool draws whatever maps the integrator returns: `sppm`'s one iteration of photons too
/// (no budget or classification of any integrator is written in the tool).
#[test]
fn photons_draws_the_maps_any_integrator_returns() {
    let (dir, scene) = setup("photons-sppm");
    let out = dir.join("sppm.png");
    let args = [
        "photons",
        s(&scene),
        "--integrator",
        "sppm",
        "--set",
        "integrators.sppm.photons_per_iteration=5000",
        "-o",
        s(&out),
        "-q",
    ];
    let run = foton_with_plugins(&args);
    ok(&run);
    assert!(run.stdout.contains("sppm iteration map"), "{}", run.stdout);
    assert!(
        run.stdout.contains("of 5000 photons emitted"),
        "{}",
        run.stdout
    );
    assert!(count_before(&run.stdout, "drawn") > 0, "{}", run.stdout);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn photons_shows_the_floor_and_leaves_the_background_black() {
    let (dir, scene) = setup("photons");
    let run = foton_with_plugins(&["photons", s(&scene), "--integrator", "photon", "-q"]);
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
        "--integrator",
        "photon",
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
            "--integrator",
            "photon",
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
    let one = image("1");
    assert_eq!(one, image("2"));
    // Not two black images.
    assert!(one.iter().any(|p| p.max_element() > 0.0));
    let _ = std::fs::remove_dir_all(dir);
}

// ---------------------------------------------------------------------------------------------
// foton compare
// ---------------------------------------------------------------------------------------------

#[test]
fn compare_lays_the_renders_side_by_side_and_lists_them() {
    let (dir, scene) = setup("compare");
    let out = dir.join("compare.png");
    let run = foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path,photon",
        "--spp",
        "2",
        "-o",
        s(&out),
        "-q",
    ]);
    ok(&run);
    let (w, h, _) = read_image(&out).unwrap();
    assert_eq!(w, 2 * SIZE + 3 * BORDER);
    assert!(h > SIZE + 2 * BORDER, "a label band above the renders: {h}");
    for name in ["path", "photon"] {
        let (rw, rh, _) = read_image(&dir.join(format!("compare-{name}.exr"))).unwrap();
        assert_eq!((rw, rh), (SIZE, SIZE));
    }
    let json = std::fs::read_to_string(dir.join("compare.json")).unwrap();
    for name in ["path", "photon"] {
        assert_eq!(json_number(&json, name, "spp"), Some(2.0), "{json}");
        assert!(json_number(&json, name, "seconds").unwrap() > 0.0, "{json}");
        assert_eq!(json_number(&json, name, "rel_mse"), None, "{json}");
    }
    assert!(json.contains("\"description\": \"photon("), "{json}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn compare_with_its_own_reference_has_zero_error() {
    let (dir, scene) = setup("compare-ref");
    let reference = dir.join("ref.exr");
    let run = foton_with_plugins(&[
        "render",
        s(&scene),
        "--spp",
        "2",
        "--seed",
        "5",
        "-o",
        s(&reference),
        "-q",
    ]);
    ok(&run);
    let compare = |seed: &str, out: &Path| {
        let run = foton_with_plugins(&[
            "compare",
            s(&scene),
            "--integrators",
            "path,photon",
            "--spp",
            "2",
            "--seed",
            seed,
            "--reference",
            s(&reference),
            "-o",
            s(out),
            "-q",
        ]);
        ok(&run);
        let json = std::fs::read_to_string(out.with_extension("json")).unwrap();
        let (w, h, _) = read_image(out).unwrap();
        assert_eq!(w, 2 * SIZE + 3 * BORDER);
        assert!(h > 2 * SIZE + 3 * BORDER, "a row of differences: {h}");
        json
    };

    let same = compare("5", &dir.join("same.png"));
    assert_eq!(json_number(&same, "path", "rel_mse"), Some(0.0), "{same}");
    assert_eq!(json_number(&same, "path", "bias"), Some(0.0), "{same}");
    assert!(
        json_number(&same, "photon", "rel_mse").unwrap() > 0.0,
        "{same}"
    );

    let other = compare("6", &dir.join("other.png"));
    assert!(
        json_number(&other, "path", "rel_mse").unwrap() > 0.0,
        "{other}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn compare_with_a_time_budget_chooses_the_samples() {
    let (dir, scene) = setup("compare-time");
    let out = dir.join("timed.png");
    let run = foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path",
        "--time",
        "0.2",
        "-o",
        s(&out),
        "-q",
    ]);
    ok(&run);
    let json = std::fs::read_to_string(dir.join("timed.json")).unwrap();
    let spp = json_number(&json, "path", "spp").unwrap();
    // The scene asks for 2 spp; --time replaces that by the samples that fill 0.2 s. A 32x32
    // render of this box takes about a millisecond per sample, so that is far more than 2:
    // the calibration ends with renders at n and 2n spp of which the longer, t2, takes 0.02
    // to about 0.04 s; the cost model puts at most 90 % of t2 into a fixed cost and at most
    // half of it into n samples, which leaves at least 2n (0.2 - 0.9 t2) / t2 >= 8 spp (and
    // more than 2 as long as t2 < 0.08 s). Asserting spp >= 1 could not fail: the cost
    // model clamps to 1.
    assert!(spp > 2.0, "--time did not choose the samples: {json}");
    // The number recorded is the one --time chose.
    assert!(
        json.contains(&format!("\"set\": [\"render.spp={spp}\"]")),
        "{json}"
    );
    assert!(
        run.stdout
            .contains(&format!("(--time chose render.spp={spp})")),
        "{}",
        run.stdout
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn compare_reports_no_spp_for_an_integrator_with_a_budget_of_its_own() {
    // sppm runs its iterations whatever render.spp says.
    let (dir, scene) = setup("compare-own-budget");
    let out = dir.join("own.png");
    let run = |budget: &[&str]| {
        let mut args = vec![
            "compare",
            s(&scene),
            "--integrators",
            "path,sppm",
            "--set",
            "integrators.sppm.iterations=2",
            "--set",
            "integrators.sppm.photons_per_iteration=2000",
            "-o",
            s(&out),
            "-q",
        ];
        args.extend(budget);
        let run = foton_with_plugins(&args);
        ok(&run);
        (run, std::fs::read_to_string(dir.join("own.json")).unwrap())
    };
    let (_, json) = run(&["--spp", "2"]);
    assert_eq!(json_number(&json, "path", "spp"), Some(2.0), "{json}");
    assert_eq!(json_number(&json, "sppm", "spp"), None, "{json}");
    let (timed, json) = run(&["--time", "0.1"]);
    assert_eq!(json_number(&json, "sppm", "spp"), None, "{json}");
    assert!(
        timed
            .stderr
            .contains("`sppm` does not take its samples from render.spp"),
        "{}",
        timed.stderr
    );
    let _ = std::fs::remove_dir_all(dir);
}

// ---------------------------------------------------------------------------------------------
// foton sweep
// ---------------------------------------------------------------------------------------------

#[test]
fn sweep_renders_one_tile_per_combination() {
    let (dir, scene) = setup("sweep");
    let out = dir.join("sweep.png");
    let run = foton_with_plugins(&[
        "sweep",
        s(&scene),
        "--set",
        "render.max_depth=1,3",
        "--set",
        "render.seed=1,2,3",
        "--set",
        "render.spp=1",
        "-o",
        s(&out),
        "-q",
    ]);
    ok(&run);
    assert!(run.stdout.contains("6 cells (2 x 3)"), "{}", run.stdout);
    assert_eq!(run.stdout.matches("1 spp").count(), 6, "{}", run.stdout);
    let (w, h, _) = read_image(&out).unwrap();
    assert_eq!(w, 2 * SIZE + 3 * BORDER);
    assert!(h > 3 * SIZE + 4 * BORDER, "three rows with labels: {h}");
    let _ = std::fs::remove_dir_all(dir);
}

/// A sweep as an array job: `--cells` sizes it, `--cell I` renders each cell into its file
/// (the cell's own render, bit for bit), `--assemble` lays out the grid one process makes (but
/// for the times in the labels); a missing cell or one of another sweep is refused.
#[test]
fn sweep_runs_as_an_array_job() {
    let (dir, scene) = setup("sweep-array");
    let cells = dir.join("cells");
    std::fs::create_dir(&cells).unwrap();
    let sets = [
        "--set",
        "render.max_depth=1,3",
        "--set",
        "render.seed=1,2,3",
        "--set",
        "render.spp=1",
        "-q",
    ];
    let sweep = |extra: &[&str]| {
        let mut args = vec!["sweep", s(&scene)];
        args.extend(sets);
        args.extend(extra);
        foton_with_plugins(&args)
    };
    let run = sweep(&["--cells"]);
    ok(&run);
    assert_eq!(run.stdout.trim(), "6");
    fails_with(
        &sweep(&["--cell", "6", "--cells-dir", s(&cells)]),
        &["--cell 6", "6 cells"],
    );
    // Cells in any order, as the tasks of an array finish.
    for cell in [5, 0, 3, 1, 4] {
        ok(&sweep(&[
            "--cell",
            &cell.to_string(),
            "--cells-dir",
            s(&cells),
        ]));
    }
    let grid = dir.join("grid.png");
    fails_with(
        &sweep(&["--assemble", "--cells-dir", s(&cells), "-o", s(&grid)]),
        &["missing cell(s) 2 of 6"],
    );
    assert!(!grid.exists());
    ok(&sweep(&["--cell", "2", "--cells-dir", s(&cells)]));
    let run = sweep(&["--assemble", "--cells-dir", s(&cells), "-o", s(&grid)]);
    ok(&run);
    assert!(run.stdout.contains("6 cells (2 x 3)"), "{}", run.stdout);

    // Cell 4 is max_depth = 1 (the first list varies fastest), seed = 3.
    let single = dir.join("single.exr");
    ok(&foton_with_plugins(&[
        "render",
        s(&scene),
        "--set",
        "render.max_depth=1",
        "--set",
        "render.seed=3",
        "--set",
        "render.spp=1",
        "-q",
        "-o",
        s(&single),
    ]));
    assert_eq!(
        read_image(&cells.join("cell-4.exr")).unwrap(),
        read_image(&single).unwrap()
    );
    // The one-process grid: the same size, the same tiles; only label times differ.
    let one = dir.join("one.png");
    ok(&sweep(&["-o", s(&one)]));
    let (w, h, a) = read_image(&grid).unwrap();
    let (w1, h1, b) = read_image(&one).unwrap();
    assert_eq!((w, h), (w1, h1));
    let differing = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert!(
        differing * 100 < a.len() * 3,
        "{differing} of {} pixels differ",
        a.len()
    );
    // A cell of another sweep (another list of seeds) is refused.
    let mut args = vec!["sweep", s(&scene)];
    args.extend([
        "--set",
        "render.max_depth=1,3",
        "--set",
        "render.seed=1,2,4",
        "--set",
        "render.spp=1",
        "-q",
        "--assemble",
        "--cells-dir",
        s(&cells),
        "-o",
        s(&grid),
    ]);
    fails_with(&foton_with_plugins(&args), &["cell-0.exr", "another sweep"]);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn sweep_keeps_arrays_whole() {
    assert_eq!(
        parse_set("a=[1,2],x").unwrap(),
        SweepSet {
            key: "a".into(),
            values: vec!["[1,2]".into(), "x".into()]
        }
    );
    let (dir, scene) = setup("sweep-arrays");
    let out = dir.join("cameras.png");
    let run = foton_with_plugins(&[
        "sweep",
        s(&scene),
        "--set",
        "camera.position=[0,1,3.9],[0.5,1,3.9]",
        "--spp",
        "1",
        "-o",
        s(&out),
        "-q",
    ]);
    ok(&run);
    assert!(run.stdout.contains("2 cells (2 x 1)"), "{}", run.stdout);
    let (w, _, _) = read_image(&out).unwrap();
    assert_eq!(w, 2 * SIZE + 3 * BORDER);
    let _ = std::fs::remove_dir_all(dir);
}

// ---------------------------------------------------------------------------------------------
// foton compare --curve
// ---------------------------------------------------------------------------------------------

/// One point of an error curve in compare's JSON.
struct CurvePoint {
    seconds: f64,
    rel_mse: f64,
    /// The number of the first `--set` chosen (spp, or sppm's iterations).
    units: u64,
}

/// The points of one integrator's error curve in compare's JSON.
fn curve_points(json: &str, integrator: &str) -> Vec<CurvePoint> {
    let entry = json
        .find(&format!("\"name\": \"{integrator}\""))
        .unwrap_or_else(|| panic!("no entry for {integrator} in {json}"));
    let rest = &json[entry..];
    let start = rest
        .find("\"curve\": [")
        .unwrap_or_else(|| panic!("no curve for {integrator} in {json}"));
    // The curve's closing bracket is on a line of its own.
    let end = start + rest[start..].find("\n      ]").unwrap();
    let field = |line: &str, key: &str| -> f64 {
        let key = format!("\"{key}\": ");
        let at = line.find(&key).unwrap() + key.len();
        line[at..]
            .split([',', '}'])
            .next()
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    let units = |line: &str| -> u64 {
        let at = line.find("\"set\": [\"").unwrap() + 9;
        let set = line[at..].split('"').next().unwrap();
        set.split_once('=').unwrap().1.parse().unwrap()
    };
    rest[start..end]
        .lines()
        .filter(|l| l.contains("\"budget\""))
        .map(|l| CurvePoint {
            seconds: field(l, "seconds"),
            rel_mse: field(l, "rel_mse"),
            units: units(l),
        })
        .collect()
}

#[test]
fn compare_curve_plots_the_error_against_time() {
    use foton_cli::montage::{PLOT_HEIGHT, PLOT_WIDTH};
    let (dir, scene) = setup("compare-curve");
    let small = ["--set", "film.width=20", "--set", "film.height=20"];
    let reference = dir.join("ref.exr");
    // Far more samples than the curve's renders take, so that the reference's own noise does
    // not hide theirs; and another seed than theirs (they would share its first samples).
    let mut args = vec![
        "render",
        s(&scene),
        "--spp",
        "8192",
        "--seed",
        "99",
        "-o",
        s(&reference),
        "-q",
    ];
    args.extend(small);
    ok(&foton_with_plugins(&args));

    let out = dir.join("curve.png");
    let mut args = vec![
        "compare",
        s(&scene),
        "--integrators",
        "path,photon,sppm",
        "--time",
        "0.4",
        "--threads",
        "1",
        "--curve",
        "3",
        "--reference",
        s(&reference),
        "--set",
        "integrators.sppm.photons_per_iteration=10000",
        "-o",
        s(&out),
        "-q",
    ];
    args.extend(small);
    let run = foton_with_plugins(&args);
    ok(&run);
    let (w, h, _) = read_image(&dir.join("curve-curve.png")).unwrap();
    assert_eq!((w, h), (PLOT_WIDTH, PLOT_HEIGHT));
    let json = std::fs::read_to_string(dir.join("curve.json")).unwrap();
    for name in ["path", "photon", "sppm"] {
        let points = curve_points(&json, name);
        assert_eq!(points.len(), 3, "{name}: {json}");
        // Each budget twice the one before: more samples (iterations for sppm) each time,
        // and more seconds. Times on a shared machine are noisy, and a render of a tenth of
        // a second can take longer than one of twice its budget, so the seconds are compared
        // over the whole curve, a factor of four in budget.
        for pair in points.windows(2) {
            assert!(pair[0].units < pair[1].units, "{name}: {json}");
        }
        assert!(
            points[0].seconds < points[2].seconds,
            "{name}: seconds must grow: {json}"
        );
        // The last point is the render shown.
        assert_eq!(
            Some(points[2].rel_mse),
            json_number(&json, name, "rel_mse"),
            "{json}"
        );
    }
    // Four times the samples: about a quarter of the path tracer's error.
    let path = curve_points(&json, "path");
    assert!(path[2].rel_mse < path[0].rel_mse, "{json}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn curve_without_a_reference_or_a_time_is_refused() {
    let (dir, scene) = setup("bad-curve");
    let out = dir.join("c.png");
    let run = foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path",
        "--time",
        "1",
        "--curve",
        "3",
        "-o",
        s(&out),
    ]);
    fails_with(&run, &["--curve 3 needs --reference"]);
    assert!(run.stdout.is_empty(), "nothing rendered: {}", run.stdout);
    let reference = write(&dir, "ref.exr", "never read");
    let run = foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path",
        "--spp",
        "1",
        "--curve",
        "3",
        "--reference",
        s(&reference),
        "-o",
        s(&out),
    ]);
    fails_with(&run, &["--curve 3 needs --time"]);
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(dir);
}

// ---------------------------------------------------------------------------------------------
// foton bench --json
// ---------------------------------------------------------------------------------------------

/// The phase profile of `sppm` on the box: its phases (the load, photon tracing, the map's
/// build, the gather, the camera pass) at one thread and at two, wall and CPU seconds that
/// add up to the totals, Amdahl's predictions consistent with the serial fraction, the peak
/// memory.
#[test]
fn bench_profiles_the_phases_of_a_render() {
    let (dir, scene) = setup("bench-json");
    let json = dir.join("profile.json");
    let run = foton_with_plugins(&[
        "bench",
        s(&scene),
        "--integrator",
        "sppm",
        "--set",
        "integrators.sppm.iterations=4",
        "--set",
        "integrators.sppm.photons_per_iteration=20000",
        "--threads",
        "2",
        "--json",
        s(&json),
    ]);
    ok(&run);
    let text = std::fs::read_to_string(&json).unwrap();
    let phases = [
        "scene load and BVH build",
        "camera pass",
        "photon tracing",
        "photon map build",
        "photon gather and radius update",
    ];
    let (mut sum_1, mut sum_all) = (0.0, 0.0);
    for phase in phases {
        let field = |f: &str| json_number(&text, phase, f).unwrap();
        let (w1, c1, wn, cn) = (
            field("wall_1"),
            field("cpu_1"),
            field("wall_all"),
            field("cpu_all"),
        );
        assert!(
            w1 > 0.0 && wn > 0.0 && c1 >= 0.0 && cn >= 0.0,
            "{phase}: {text}"
        );
        sum_1 += w1;
        sum_all += wn;
    }
    // The work of the passes is counted once per iteration, summed: the photon tracing of
    // four iterations of 20000 photons takes longer than no time, and the phases listed
    // are most of the total (the rest is set-up).
    let total = |f: &str| json_value(&text, "\"total\"", f).parse::<f64>().unwrap();
    assert!(
        sum_1 <= total("wall_1") * 1.0001 && sum_1 >= 0.8 * total("wall_1"),
        "{text}"
    );
    assert!(sum_all <= total("wall_all") * 1.0001, "{text}");
    let number = |key: &str| json_value(&text, "", key);
    let f: f64 = number("serial_fraction").parse().unwrap();
    let s16: f64 = number("predicted_speedup_16").parse().unwrap();
    let s64: f64 = number("predicted_speedup_64").parse().unwrap();
    assert!((0.0..=1.0).contains(&f), "{text}");
    assert!((1.0 / (f + (1.0 - f) / 16.0) - s16).abs() < 1e-3, "{text}");
    assert!(1.0 <= s16 && s16 <= s64 && s64 <= 64.0, "{text}");
    let rss: u64 = number("peak_rss_bytes").parse().unwrap();
    assert!(rss > 1 << 20, "peak RSS {rss}");
    let _ = std::fs::remove_dir_all(dir);
}
