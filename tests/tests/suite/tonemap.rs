//! `[film] exposure` and `tonemap`: what a PNG holds is sRGB(tonemap(L x 2^exposure)) of the
//! radiance L an EXR of the same render holds, whichever tool writes it (render, checkpoints,
//! compare, sweep, photons); an EXR is never changed by them; bad values are scene errors.
//!
//! The expected bytes are worked out here in double precision from the formulas, not with
//! foton's own functions, so a wrong formula fails. foton works in single precision, so a
//! value on the edge between two 8-bit codes may round to either: one code of difference is
//! allowed for that alone. Every check also asserts that the transform changed the picture,
//! by far more than one code, so that a tool ignoring it fails.

use foton_cli::TermProgress;
use foton_cli::montage::BORDER;
use foton_core::Rgb;
use foton_core::film::{DisplayTransform, Film, ToneMap};
use foton_core::integrator::Progress;
use foton_loader::image::read_image;
use foton_tests::{Run, foton_with_plugins, header, repo_root, temp_dir, with_area_light, write};
use std::path::{Path, PathBuf};

/// The sRGB transfer curve (IEC 61966-2-1) of a display value in [0, 1].
fn srgb(v: f64) -> f64 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Narkowicz's fit of the ACES curve, capped at 1.
fn aces(x: f64) -> f64 {
    (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).min(1.0)
}

/// The 8-bit code of one channel of radiance `l` at `exposure` stops through `tonemap`.
fn code(l: f32, exposure: f64, tonemap: &str) -> i32 {
    let x = (l as f64 * 2f64.powf(exposure)).max(0.0);
    let v = match tonemap {
        "clamp" => x.min(1.0),
        "filmic" => aces(x),
        other => panic!("test bug: tone map {other}"),
    };
    (srgb(v) * 255.0).round() as i32
}

/// The 8-bit RGB of a PNG, row-major.
fn png_bytes(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    // read_image decodes the sRGB codes; encoding again gives them back exactly (the two
    // curves invert each other to 1e-5, far less than half a code).
    let (w, h, linear) = read_image(path).unwrap();
    let bytes = linear
        .iter()
        .map(|p| {
            p.to_array()
                .map(|c| (foton_core::film::srgb_encode(c) * 255.0).round() as u8)
        })
        .collect();
    (w, h, bytes)
}

fn show(run: &Run) -> String {
    format!(
        "exit {}\nstdout:\n{}stderr:\n{}",
        run.code, run.stdout, run.stderr
    )
}

fn ok(args: &[&str]) -> Run {
    let run = foton_with_plugins(args);
    assert_eq!(run.code, 0, "foton {}:\n{}", args.join(" "), show(&run));
    run
}

/// Asserts that each pixel's codes are those of `radiance` through `exposure` and `tonemap`,
/// and that at least `changed` of the channels differ by more than one code from the plain
/// clip (the transform did something).
fn assert_codes(
    what: &str,
    bytes: &[[u8; 3]],
    radiance: &[Rgb],
    exposure: f64,
    tonemap: &str,
    changed: usize,
) {
    assert_eq!(bytes.len(), radiance.len(), "{what}");
    let mut differs = 0;
    for (i, (b, l)) in bytes.iter().zip(radiance).enumerate() {
        for c in 0..3 {
            let want = code(l[c], exposure, tonemap);
            assert!(
                (b[c] as i32 - want).abs() <= 1,
                "{what}: pixel {i} channel {c}: code {} for radiance {}, expected {want}",
                b[c],
                l[c]
            );
            if (b[c] as i32 - code(l[c], 0.0, "clamp")).abs() > 1 {
                differs += 1;
            }
        }
    }
    assert!(
        differs >= changed,
        "{what}: only {differs} channels differ from the plain clip"
    );
}

/// The Cornell box with an area light of radiance 20 in view, in a folder of its own.
fn cornell() -> PathBuf {
    with_area_light("cornell-box.toml")
}

const SMALL: [&str; 6] = [
    "--set",
    "film.width=24",
    "--set",
    "film.height=24",
    "--set",
    "render.spp=4",
];

fn render(scene: &Path, output: &Path, sets: &[&str]) {
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-q",
        "-o",
        output.to_str().unwrap(),
    ];
    args.extend_from_slice(&SMALL);
    for s in sets {
        args.extend(["--set", s]);
    }
    ok(&args);
}

#[test]
fn render_png_is_srgb_of_the_exposed_clamped_or_filmic_radiance() {
    let scene = cornell();
    let dir = scene.parent().unwrap().to_path_buf();
    let exr = dir.join("linear.exr");
    render(&scene, &exr, &[]);
    let (w, h, radiance) = read_image(&exr).unwrap();
    assert!(
        radiance.iter().any(|p| p.max_element() > 4.0),
        "the light should be in view, far above 1"
    );
    for (exposure, tonemap) in [
        (-1.0, "clamp"),
        (1.5, "clamp"),
        (0.0, "filmic"),
        (-2.0, "filmic"),
    ] {
        let png = dir.join(format!("out{exposure}{tonemap}.png"));
        render(
            &scene,
            &png,
            &[
                &format!("film.exposure={exposure}"),
                &format!("film.tonemap=\"{tonemap}\""),
            ],
        );
        let (pw, ph, bytes) = png_bytes(&png);
        assert_eq!((pw, ph), (w, h));
        let what = format!("exposure {exposure}, {tonemap}");
        // Most of the picture is far from both black and white: a stop or a curve moves it.
        assert_codes(&what, &bytes, &radiance, exposure, tonemap, 3 * 24 * 24 / 2);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn exr_is_the_radiance_whatever_the_exposure_and_tone_map() {
    let scene = cornell();
    let dir = scene.parent().unwrap().to_path_buf();
    let plain = dir.join("plain.exr");
    render(&scene, &plain, &[]);
    let exposed = dir.join("exposed.exr");
    render(
        &scene,
        &exposed,
        &["film.exposure=-3.5", "film.tonemap=\"filmic\""],
    );
    let (a, b) = (read_image(&plain).unwrap(), read_image(&exposed).unwrap());
    assert_eq!(a.2, b.2, "an EXR must hold the unscaled radiance");
    assert!(a.2.iter().any(|p| p.max_element() > 1.0), "HDR values kept");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A camera facing a large black emitter of radiance `EMISSION`: every pixel sees it.
const EMISSION: [f32; 3] = [0.3, 1.2, 5.0];

fn flat_scene(dir: &Path, exposure: f32, tonemap: &str) -> PathBuf {
    let [r, g, b] = EMISSION;
    let text = header("path", 2, 1, 32, 24).replace(
        "[film]\n",
        &format!("[film]\nexposure = {exposure}\ntonemap = \"{tonemap}\"\n"),
    ) + &format!(
        r#"
[camera]
position = [0, 0, 1]
look_at = [0, 0, 0]
up = [0, 1, 0]
fov = 40

[materials.black]
type = "diffuse"
reflectance = [0, 0, 0]

[[shapes]]
type = "quad"
origin = [-10, -10, -1]
u = [20, 0, 0]
v = [0, 20, 0]
material = "black"
emission = [{r}, {g}, {b}]
"#
    );
    write(dir, "flat.toml", &text)
}

/// The codes at the centre of cell `column` of a one-row montage of renders `w` x `h` pixels
/// (its tiles sit at the bottom of their cells, under the label band).
fn montage_tile_centre(path: &Path, column: u32, w: u32, h: u32) -> [u8; 3] {
    let (mw, mh, bytes) = png_bytes(path);
    let x = BORDER + column * (w + BORDER) + w / 2;
    let y = mh - BORDER - h / 2;
    bytes[(y * mw + x) as usize]
}

#[test]
fn compare_png_shows_each_render_through_the_scene_exposure() {
    let dir = temp_dir("tonemap-compare");
    let scene = flat_scene(&dir, -1.0, "clamp");
    let out = dir.join("cmp.png");
    ok(&[
        "compare",
        scene.to_str().unwrap(),
        "--integrators",
        "path",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    // The render beside it keeps the radiance; the montage shows it one stop down.
    let (_, _, radiance) = read_image(&dir.join("cmp-path.exr")).unwrap();
    let l = radiance[(12 * 32 + 16) as usize];
    for c in 0..3 {
        assert!((l[c] - EMISSION[c]).abs() < 1e-4, "{l} vs {EMISSION:?}");
    }
    let tile = montage_tile_centre(&out, 0, 32, 24);
    // 0.3 -> 0.15, 1.2 -> 0.6 (white without the exposure), 5 -> still clipped.
    assert_codes("compare", &[tile], &[l], -1.0, "clamp", 2);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_png_shows_each_cell_through_its_own_exposure() {
    let dir = temp_dir("tonemap-sweep");
    let scene = flat_scene(&dir, 0.0, "filmic");
    let out = dir.join("sweep.png");
    ok(&[
        "sweep",
        scene.to_str().unwrap(),
        "--set",
        "film.exposure=0,-2,1",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    let l = Rgb::from_array(EMISSION);
    for (column, exposure) in [0.0, -2.0, 1.0].into_iter().enumerate() {
        let tile = montage_tile_centre(&out, column as u32, 32, 24);
        // The filmic curve moves every channel, and the clip would leave two at white.
        assert_codes(
            &format!("sweep cell {column}"),
            &[tile],
            &[l],
            exposure,
            "filmic",
            2,
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn photons_png_goes_through_the_scene_exposure() {
    let scene = cornell();
    let dir = scene.parent().unwrap().to_path_buf();
    let draw = |output: &Path, exposure: f32| {
        ok(&[
            "photons",
            scene.to_str().unwrap(),
            "--integrator",
            "photon",
            "-q",
            "--set",
            "film.width=48",
            "--set",
            "film.height=48",
            "--set",
            "integrators.photon.global_photons=20000",
            "--set",
            &format!("film.exposure={exposure}"),
            "-o",
            output.to_str().unwrap(),
        ]);
    };
    // The picture's own exposure (the 99th percentile to 1) is in the EXR; the scene's
    // exposure applies to the PNG only.
    let (exr, exr_exposed, png) = (
        dir.join("p.exr"),
        dir.join("p-exposed.exr"),
        dir.join("p.png"),
    );
    draw(&exr, 0.0);
    draw(&exr_exposed, -1.5);
    draw(&png, -1.5);
    let (_, _, linear) = read_image(&exr).unwrap();
    assert_eq!(linear, read_image(&exr_exposed).unwrap().2);
    let (_, _, bytes) = png_bytes(&png);
    let dots = linear.iter().filter(|p| p.max_element() > 0.5).count();
    assert!(dots > 100, "only {dots} bright dots");
    assert_codes("photons", &bytes, &linear, -1.5, "clamp", dots);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn checkpoints_go_through_the_display_transform() {
    let dir = temp_dir("tonemap-checkpoint");
    let png = dir.join("checkpoint.png");
    let display = DisplayTransform::new(-1.0, ToneMap::Filmic);
    let progress = TermProgress::new(true).with_checkpoint(1, png.clone(), display, None);
    let mut film = Film::new(2, 1);
    let radiance = [Rgb::new(0.1, 1.0, 3.0), Rgb::new(10.0, 0.5, 0.02)];
    film.set_pixel(0, 0, radiance[0]);
    film.set_pixel(1, 0, radiance[1]);
    progress.checkpoint(1, &|| film.clone());
    assert!(progress.take_warnings().is_empty());
    let (_, _, bytes) = png_bytes(&png);
    assert_codes("checkpoint", &bytes, &radiance, -1.0, "filmic", 4);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `foton check` of the Cornell box with `line` added to its `[film]` must fail at that line
/// with `key` and `words` in the message.
fn assert_film_error(name: &str, line: &str, key: &str, words: &[&str]) {
    let dir = temp_dir(name);
    let text = std::fs::read_to_string(repo_root().join("scenes/cornell-box.toml")).unwrap();
    assert_eq!(text.matches("[film]\n").count(), 1);
    let text = text.replace("[film]\n", &format!("[film]\n{line}\n"));
    let number = text.lines().position(|l| l == line).unwrap() + 1;
    let scene = write(&dir, "scene.toml", &text);
    let run = foton_with_plugins(&["check", scene.to_str().unwrap()]);
    assert_eq!(run.code, 1, "{line}: {}", show(&run));
    let at = format!("{}:{number}:", scene.display());
    for needle in [at.as_str(), &format!("`{key}`")]
        .into_iter()
        .chain(words.iter().copied())
    {
        assert!(
            run.stderr.contains(needle),
            "{line}: the error lacks {needle:?}:\n{}",
            show(&run)
        );
    }
    assert!(!run.stderr.contains("panicked"), "{}", show(&run));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_exposure_and_tonemap_are_scene_errors() {
    assert_film_error(
        "tonemap-name",
        "tonemap = \"aces\"",
        "film.tonemap",
        &["\"aces\"", "expected one of: clamp, filmic"],
    );
    assert_film_error(
        "tonemap-type",
        "tonemap = 1",
        "film.tonemap",
        &["expected a string"],
    );
    assert_film_error(
        "exposure-inf",
        "exposure = inf",
        "film.exposure",
        &["expected a finite number, found inf"],
    );
    assert_film_error(
        "exposure-nan",
        "exposure = nan",
        "film.exposure",
        &["expected a finite number, found NaN"],
    );
    assert_film_error(
        "exposure-huge",
        "exposure = 1000",
        "film.exposure",
        &["between -64 and 64 stops", "1000"],
    );
    assert_film_error(
        "exposure-string",
        "exposure = \"+1\"",
        "film.exposure",
        &["expected a number"],
    );
}
