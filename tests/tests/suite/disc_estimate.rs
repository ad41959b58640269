//! The surface estimate gathers photons from a disc, not a ball: photons on a parallel surface
//! within the estimate's radius (the top of a low box beside the floor, a step, a rug) are not
//! counted on the floor beside it.

use foton_cli::{TermProgress, prepare, render_prepared};
use foton_core::film::Film;
use foton_core::kernel::{BoxKernel, NormalizedKernel};
use foton_core::scene::Scene;
use foton_photonmap::map::{DISC_THICKNESS, Disc, Estimate, Photon, PhotonMap};
use foton_tests::{header, plugin_dir, region_mean, temp_dir, write};
use glam::Vec3;

/// Photons of flux 1 on a floor (y = 0, x > 0) at density `floor` per unit area and on a box
/// top (y = h, x < 0) at density `top`, on a jittered grid; the irradiance estimate on the
/// floor just beside the box must see the floor's density alone.
#[test]
fn photons_on_a_parallel_surface_within_the_radius_are_not_counted() {
    let (h, spacing) = (0.08f32, 0.01f32);
    let mut photons = Vec::new();
    let n = (1.0 / spacing) as i32;
    for i in -n..n {
        for j in -n..n {
            let (x, z) = ((i as f32 + 0.5) * spacing, (j as f32 + 0.5) * spacing);
            let (y, power) = if x > 0.0 { (0.0, 1.0) } else { (h, 10.0) };
            photons.push(Photon::new(
                Vec3::new(x, y, z),
                foton_core::Rgb::splat(power),
                Vec3::Y,
                Vec3::Y,
            ));
        }
    }
    let map = PhotonMap::build(photons);
    let kernel = NormalizedKernel::new(Box::new(BoxKernel)).unwrap();
    // A radius well above the box's height, so that a ball would reach the box top.
    let r = 0.2;
    assert!(h > DISC_THICKNESS * r);
    let estimate = Estimate {
        k: 100_000,
        max_radius: r,
        kernel: &kernel,
    };
    let mut scratch = Vec::new();
    let floor_irradiance = 1.0 / (spacing * spacing);
    // At x = 0.1 the disc of radius 0.2 reaches half-way over the box top: a ball would count
    // its ten times brighter photons there too.
    let e = map.irradiance(
        &Disc::new(Vec3::new(0.1, 0.0, 0.0), Vec3::Y, 16),
        &estimate,
        &mut scratch,
    );
    // The disc over the floor covers x in (0, 0.3): 1 - (the segment of the disc past x = 0),
    // a fraction of the disc's area; the estimate divides by the whole disc.
    let covered = {
        let d = 0.1f32 / r;
        1.0 - (d.acos() - d * (1.0 - d * d).sqrt()) / std::f32::consts::PI
    };
    let expected = floor_irradiance * covered;
    assert!(
        ((e.x - expected) / expected).abs() < 0.03,
        "{} against the floor's own {expected}",
        e.x
    );
}

/// A low box (height 0.06) on a floor, lit at a grazing angle from its left: its top is bright
/// and the floor just right of it lies in its shadow. With direct light from photons and an
/// estimate radius (0.1) above the box's height, the floor in the shadow must match the path
/// tracer; a ball would count the box top's photons there. The strip sees only a little
/// indirect light (well under a percent of the box top's radiance), so the tolerance is stated
/// against the top: within 2% of the top's radiance, where a ball's leak adds tens of percent.
#[test]
fn the_floor_beside_a_low_bright_box_matches_the_path_tracer() {
    let h = 0.06;
    let mut s = header("photon", 64, 8, 32, 32);
    s += &format!(
        r#"
[camera]
position = [0.05, 1.2, 0.0]
look_at = [0.05, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = 28.0

[integrators.photon]
global_photons = 400000
caustic_photons = 0
k = 50
max_radius = 0.1
direct = "photons"

[materials.white]
type = "diffuse"
reflectance = [0.7, 0.7, 0.7]

[[shapes]]
type = "quad"
origin = [-4.0, 0.0, -4.0]
u = [0.0, 0.0, 8.0]
v = [8.0, 0.0, 0.0]
material = "white"

[[shapes]]
type = "quad"
origin = [-1.0, {h}, -0.5]
u = [0.0, 0.0, 1.0]
v = [1.0, 0.0, 0.0]
material = "white"

[[shapes]]
type = "quad"
origin = [0.0, 0.0, -0.5]
u = [0.0, {h}, 0.0]
v = [0.0, 0.0, 1.0]
material = "white"

[[shapes]]
type = "quad"
origin = [-1.0, 0.0, -0.5]
u = [0.0, 0.0, 1.0]
v = [0.0, {h}, 0.0]
material = "white"

[[shapes]]
type = "quad"
origin = [-1.0, 0.0, 0.5]
u = [1.0, 0.0, 0.0]
v = [0.0, {h}, 0.0]
material = "white"

[[shapes]]
type = "quad"
origin = [-1.0, 0.0, -0.5]
u = [0.0, {h}, 0.0]
v = [1.0, 0.0, 0.0]
material = "white"

[[lights]]
type = "point"
position = [-3.0, 0.55, 0.0]
intensity = [60.0, 60.0, 60.0]
"#
    );
    let dir = temp_dir("low-box");
    let path = write(&dir, "scene.toml", &s);
    let render = |sets: &[&str]| -> (Film, Scene) {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let p = prepare(&path, &sets, &[plugin_dir()], true).unwrap_or_else(|e| panic!("{e}"));
        let (film, _) = render_prepared(&p, 2, &TermProgress::new(true)).unwrap();
        (film, p.scene)
    };
    let (photon, scene) = render(&[]);
    let (reference, _) = render(&["render.integrator=\"path\"", "render.spp=1024"]);
    let _ = std::fs::remove_dir_all(dir);

    // The pixels of the floor strip x in [0.02, 0.08], |z| < 0.1: within the radius of the
    // box's edge and inside its shadow (about 0.37 long).
    let corners = [(0.02, -0.1), (0.08, -0.1), (0.02, 0.1), (0.08, 0.1)]
        .map(|(x, z)| scene.camera().project(Vec3::new(x, 0.0, z)).unwrap());
    let x0 = corners
        .iter()
        .map(|c| c.x)
        .fold(f32::INFINITY, f32::min)
        .ceil() as u32;
    let x1 = corners.iter().map(|c| c.x).fold(0.0, f32::max).floor() as u32;
    let y0 = corners
        .iter()
        .map(|c| c.y)
        .fold(f32::INFINITY, f32::min)
        .ceil() as u32;
    let y1 = corners.iter().map(|c| c.y).fold(0.0, f32::max).floor() as u32;
    assert!(x1 > x0 && y1 > y0, "({x0}, {y0})-({x1}, {y1})");
    let (a, sa) = region_mean(&photon, x0, y0, x1, y1);
    let (b, sb) = region_mean(&reference, x0, y0, x1, y1);
    // The box top, for scale: the strip is much darker.
    let top = scene.camera().project(Vec3::new(-0.1, h, 0.0)).unwrap();
    let (t, _) = region_mean(
        &reference,
        top.x as u32 - 1,
        top.y as u32 - 1,
        top.x as u32 + 1,
        top.y as u32 + 1,
    );
    assert!(b.x < 0.2 * t.x, "strip {b}, box top {t}");
    let diff = (a - b).abs().max_element();
    assert!(
        diff < 0.02 * t.x,
        "floor beside the box: photon {a} (standard error {sa}) against path {b} ({sb}), box top {t}"
    );
}
