//! The thin-lens camera (TOML `lens_radius` / `focus_distance`, pbrt-v4's `lensradius`,
//! Mitsuba's `thinlens`): every estimator that starts paths at the camera draws its rays
//! from the lens, and those that connect light vertices to the camera (light tracing, bdpt,
//! vcm) sample a point of the lens and weigh it by the lens's importance. Rendered with a lens,
//! light tracing alone and bdpt agree with the path tracer; the lens visibly blurs what lies
//! off the plane of focus; and the readers carry the lens from each file format.

use crate::bdpt::{CEILING_LIGHT, cornell};
use foton_core::film::Film;
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{render_toml, temp_dir, write};

/// Block means within 4.5 standard errors of the pixel-wise difference (as bdpt.rs).
const Z: Tolerance = Tolerance {
    rel: 0.0,
    z: 4.5,
    floor: 1e-4,
};

/// A lens of radius 0.25 focused on the front sphere (3.65 from the camera along the view):
/// the back wall and the other sphere are out of focus.
const LENS: [&str; 2] = ["camera.lens_radius=0.25", "camera.focus_distance=3.65"];

fn render(integrator: &str, spp: u32, extra: &[&str]) -> Film {
    let scene = cornell("white", "white", "", CEILING_LIGHT);
    let mut sets = vec![
        format!("render.integrator=\"{integrator}\""),
        format!("render.spp={spp}"),
    ];
    sets.extend(extra.iter().map(|s| s.to_string()));
    let refs: Vec<&str> = sets.iter().map(String::as_str).collect();
    render_toml("thin-lens", &scene, &refs, 2)
}

/// Light tracing alone (each light vertex connected to a sampled point of the lens) and the
/// full bidirectional estimator agree with the path tracer's camera rays from the lens.
#[test]
fn light_tracing_and_bdpt_agree_with_path_through_a_thin_lens() {
    let path = render("path", 2048, &LENS);
    let light = render(
        "bdpt",
        512,
        &[LENS[0], LENS[1], "integrators.bdpt.strategy=\"light\""],
    );
    assert_blocks_agree(
        "light tracing through a lens against path",
        &light,
        &path,
        4,
        Z,
    );
    let all = render("bdpt", 128, &LENS);
    assert_blocks_agree("bdpt through a lens against path", &all, &path, 4, Z);
}

/// A small glowing sphere at depth d, seen by a lens of radius R focused at f, is spread over
/// a disc: the rays from lens offset l through a point at depth d cross the image plane (at
/// distance 1) at the pinhole's projection plus l (1/f - 1/d), so the disc's radius there is
/// R |1/f - 1/d|, and a uniform disc of radius rho has mean squared radius rho^2 / 2 (plus the
/// sphere's own image's). The image's second moment about its centroid matches that, for
/// the path tracer and for light tracing alone (the light's points connected to sampled lens
/// points), and the total light on the film is the pinhole's: the lens's importance is
/// normalised by its area.
#[test]
fn an_out_of_focus_point_spreads_over_the_circle_of_confusion() {
    let (size, fov, depth, radius, lens, focus) = (64u32, 40.0f32, 2.0f32, 0.02f32, 0.2, 4.0);
    let scene = |integrator: &str, spp: u32| {
        foton_tests::header(integrator, spp, 0, size, size)
            + &format!(
                r#"
[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
fov = {fov}

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "sphere"
center = [0.1, 0.05, -{depth}]
radius = {radius}
material = "black"
emission = [1.0, 1.0, 1.0]
"#
            )
    };
    let pixels = |film: &Film| {
        let film = film.clone();
        (0..film.height).flat_map(move |y| {
            let row: Vec<_> = (0..film.width).map(|x| (x, y, film.pixel(x, y))).collect();
            row
        })
    };
    let moments = |film: &Film| {
        let (mut sum, mut sx, mut sy) = (0.0f64, 0.0f64, 0.0f64);
        for (x, y, v) in pixels(film) {
            let w = v.x as f64;
            sum += w;
            sx += w * (x as f64 + 0.5);
            sy += w * (y as f64 + 0.5);
        }
        let (cx, cy) = (sx / sum, sy / sum);
        let mut r2 = 0.0f64;
        for (x, y, v) in pixels(film) {
            let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
            r2 += v.x as f64 * (dx * dx + dy * dy);
        }
        (sum, r2 / sum)
    };
    let pixels_per_unit = size as f64 / (2.0 * (fov as f64 / 2.0).to_radians().tan());
    // The circle of confusion and the sphere's own disc (its radius seen from the camera),
    // in pixels; each pixel's box adds 1/6 (1/12 per axis).
    let rho = lens * (1.0 / focus - 1.0 / depth as f64).abs() * pixels_per_unit;
    let own = radius as f64 / depth as f64 * pixels_per_unit;
    let want = rho * rho / 2.0 + own * own / 2.0 + 1.0 / 6.0;
    let pinhole = render_toml("coc-pinhole", &scene("path", 256), &[], 2);
    let sets = [
        format!("camera.lens_radius={lens}"),
        format!("camera.focus_distance={focus}"),
    ];
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let path = render_toml("coc-path", &scene("path", 256), &sets, 2);
    let mut light_sets = sets.clone();
    light_sets.push("integrators.bdpt.strategy=\"light\"");
    let light = render_toml("coc-light", &scene("bdpt", 64), &light_sets, 2);
    let (total, sharp) = moments(&pinhole);
    assert!(
        sharp < 1.0,
        "the pinhole's image of the sphere: mean r^2 {sharp}"
    );
    for (what, film) in [("path", &path), ("light tracing", &light)] {
        let (sum, r2) = moments(film);
        assert!(
            (r2 / want - 1.0).abs() < 0.04,
            "{what}: mean squared radius {r2} px^2, the circle of confusion gives {want}"
        );
        assert!(
            (sum / total - 1.0).abs() < 0.02,
            "{what}: {sum} on the film through the lens, {total} through the pinhole"
        );
    }
}

/// pbrt-v4's `lensradius` / `focaldistance` and Mitsuba's `thinlens` (`aperture_radius`,
/// `focus_distance`) reach the camera, in world units; Mitsuba's thinlens needs its radius.
#[test]
fn readers_carry_the_lens() {
    let dir = temp_dir("thin-lens-readers");
    let pbrt = write(
        &dir,
        "lens.pbrt",
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 40 "float lensradius" 0.1 "float focaldistance" 4.5
Film "rgb" "integer xresolution" 16 "integer yresolution" 16 "string filename" "lens.exr"
WorldBegin
LightSource "point" "rgb I" [1 1 1]
Shape "sphere" "float radius" 1
"#,
    );
    let scene = foton_loader::load(&pbrt, &[]).unwrap();
    let (r, f) = scene.camera().lens();
    assert!((r - 0.1).abs() < 1e-6 && (f - 4.5).abs() < 1e-5, "{r} {f}");

    let xml = |sensor: &str| {
        format!(
            r#"<scene version="3.0.0">
<sensor type="{sensor}">
  <float name="fov" value="40"/>
  <float name="focus_distance" value="4.5"/>
  {{radius}}
  <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
</sensor>
<emitter type="point"><point name="position" x="0" y="3" z="3"/></emitter>
<shape type="sphere"/>
</scene>"#
        )
    };
    let with_radius =
        xml("thinlens").replace("{radius}", r#"<float name="aperture_radius" value="0.2"/>"#);
    let file = write(&dir, "lens.xml", &with_radius);
    let scene = foton_loader::load(&file, &[]).unwrap();
    let (r, f) = scene.camera().lens();
    assert!((r - 0.2).abs() < 1e-6 && (f - 4.5).abs() < 1e-5, "{r} {f}");
    // The perspective sensor stays a pinhole whatever its focus distance.
    let file = write(
        &dir,
        "pinhole.xml",
        &xml("perspective").replace("{radius}", ""),
    );
    let scene = foton_loader::load(&file, &[]).unwrap();
    assert_eq!(scene.camera().lens().0, 0.0);
    let file = write(
        &dir,
        "missing.xml",
        &xml("thinlens").replace("{radius}", ""),
    );
    let err = foton_loader::load(&file, &[])
        .err()
        .expect("a thinlens sensor without aperture_radius is refused")
        .to_string();
    assert!(
        err.contains("aperture_radius") && err.contains("missing.xml"),
        "{err}"
    );
}
