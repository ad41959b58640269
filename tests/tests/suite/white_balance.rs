//! `[film] white_balance` (pbrt-v4's `whitebalance`): light of the colour of a temperature's
//! white renders grey once balanced for that temperature; the balance is one matrix on every
//! pixel, in the EXR too; parts merged with it equal the whole render byte for byte.

use foton_core::spectrum::{daylight_chromaticity, white_balance, xyz_to_srgb};
use foton_tests::{Run, foton, foton_with_plugins, header, render_toml, repo_root, temp_dir};
use glam::DVec3;

/// A grey diffuse quad facing the camera, lit head-on by a directional light of colour
/// `light`: each pixel is 0.5 / pi x light exactly (no noise at max_depth 1).
fn scene(light: DVec3, white_balance: Option<f64>) -> String {
    let wb = white_balance.map_or(String::new(), |k| format!("white_balance = {k}\n"));
    header("path", 2, 1, 4, 4).replace("[film]\n", &format!("[film]\n{wb}"))
        + &format!(
            r#"
[camera]
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
fov = 20.0
[materials.grey]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]
[[shapes]]
type = "quad"
origin = [-2.0, -2.0, 0.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 4.0, 0.0]
material = "grey"
[[lights]]
type = "directional"
direction = [0.0, 0.0, -1.0]
irradiance = [{}, {}, {}]
"#,
            light.x, light.y, light.z
        )
}

#[test]
fn the_temperatures_white_renders_grey() {
    for kelvin in [3000.0, 5500.0, 9000.0] {
        let (x, y) = daylight_chromaticity(kelvin);
        let white = xyz_to_srgb(DVec3::new(x / y, 1.0, (1.0 - x - y) / y));
        let raw = render_toml("wb-raw", &scene(white, None), &[], 2);
        let balanced = render_toml("wb", &scene(white, Some(kelvin)), &[], 2);
        for (r, b) in raw.pixels().iter().zip(balanced.pixels()) {
            let r = r.as_dvec3();
            let expected = white * 0.5 / std::f64::consts::PI;
            assert!((r - expected).abs().max_element() < 1e-5, "{kelvin} K: {r}");
            // Unbalanced the light's colour shows; balanced it is grey.
            assert!(r.max_element() / r.min_element() > 1.1, "{kelvin} K: {r}");
            let b = b.as_dvec3();
            assert!(
                b.max_element() / b.min_element() - 1.0 < 1e-3,
                "{kelvin} K: {b}"
            );
            // One matrix on each pixel.
            let m = white_balance(kelvin) * r;
            assert!((b - m).abs().max_element() < 1e-6, "{kelvin} K: {b} vs {m}");
        }
    }
}

fn render(args: &[&str]) -> Run {
    let scene = repo_root().join("scenes/cornell-box.toml");
    let mut all = vec![
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "4",
        "-q",
        "--set",
        "film.width=32",
        "--set",
        "film.height=32",
        "--set",
        "film.white_balance=4000",
    ];
    all.extend(args);
    let run = foton_with_plugins(&all);
    assert_eq!(run.code, 0, "{}", run.stderr);
    run
}

#[test]
fn balanced_parts_merge_to_the_whole_render() {
    let dir = temp_dir("wb-parts");
    let whole = dir.join("whole.exr");
    render(&["-o", whole.to_str().unwrap()]);
    let parts: Vec<_> = (0..3)
        .map(|i| {
            let out = dir.join(format!("part-{i}.exr"));
            render(&["--part", &format!("{i}/3"), "-o", out.to_str().unwrap()]);
            out
        })
        .collect();
    let merged = dir.join("merged.exr");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|p| p.to_str().unwrap()));
    args.extend(["-o", merged.to_str().unwrap()]);
    let run = foton(&args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let bytes = |p: &std::path::Path| std::fs::read(p).unwrap();
    assert!(bytes(&merged) == bytes(&whole));
    // And the balance is in the EXR: without it the image differs.
    let raw = dir.join("raw.exr");
    render(&[
        "--set",
        "film.white_balance=6500",
        "-o",
        raw.to_str().unwrap(),
    ]);
    assert!(bytes(&raw) != bytes(&whole));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_temperature_out_of_range_is_a_scene_error() {
    let dir = temp_dir("wb-bad");
    let path = foton_tests::write(&dir, "scene.toml", &scene(DVec3::ONE, Some(20.0)));
    let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
    assert_ne!(run.code, 0);
    assert!(
        run.stderr.contains("scene.toml:")
            && run.stderr.contains("white_balance")
            && run.stderr.contains("between 1000 and 100000 K"),
        "{}",
        run.stderr
    );
    let _ = std::fs::remove_dir_all(&dir);
}
