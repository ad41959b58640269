//! The directional light (Mitsuba's `directional`, a sun): its irradiance on a plane, its
//! photons (leaving a disc of the scene's bounding sphere) delivering E x area to a floor
//! facing it, and path and photon mapping agreeing under it with a shadow.

use foton_core::scene::Scene;
use foton_photonmap::trace::{STREAM_GLOBAL, TraceOptions, trace_one};
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, render_toml, temp_dir, write};
use glam::{DVec3, Vec2, Vec3};

/// A 2x2 white floor at y = 0, a low box on it, and a sun with irradiance [2, 1, 0.5] shining
/// along `direction`.
fn scene(integrator: &str, spp: u32, direction: &str) -> String {
    header(integrator, spp, 3, 32, 32)
        + &format!(
            r#"
[camera]
position = [0.0, 3.0, 2.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 45.0

[integrators.photon]
global_photons = 400000
caustic_photons = 0
k = 80
max_radius = 0.06
direct = "photons"

[materials.white]
type = "diffuse"
reflectance = [0.7, 0.7, 0.7]

[[shapes]]
type = "quad"
origin = [-1.0, 0.0, -1.0]
u = [0.0, 0.0, 2.0]
v = [2.0, 0.0, 0.0]
material = "white"

[[shapes]]
type = "sphere"
center = [0.2, 0.25, 0.0]
radius = 0.25
material = "white"

[[lights]]
type = "directional"
direction = {direction}
irradiance = [2.0, 1.0, 0.5]
"#
        )
}

fn load(text: &str) -> Scene {
    let dir = temp_dir("directional");
    let path = write(&dir, "scene.toml", text);
    let scene = foton_loader::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(dir);
    scene
}

/// E cos(theta) on a surface at angle theta to the light, from the light sample the
/// integrators use; the shadow ray ends beyond the scene.
#[test]
fn irradiance_on_a_plane_is_e_cos_theta() {
    let scene = load(&scene("path", 1, "[0.6, -0.8, 0.0]"));
    let light = &scene.lights()[0];
    let p = Vec3::new(0.5, 0.0, 0.5);
    let ls = light.sample_li(p, Vec2::splat(0.5), 0.5).unwrap();
    assert!(ls.delta);
    assert!((ls.wi - Vec3::new(-0.6, 0.8, 0.0)).length() < 1e-6);
    let e = ls.li * ls.wi.dot(Vec3::Y);
    assert!(
        (e - glam::Vec3::new(2.0, 1.0, 0.5) * 0.8)
            .abs()
            .max_element()
            < 1e-6,
        "{e}"
    );
    let (lo, hi) = scene.bounds();
    assert!(
        ls.p.distance(p) > (hi - lo).length(),
        "the shadow ray must leave the scene"
    );
}

/// Photons straight down onto the floor: their first hits on it carry E x its area (the disc
/// they leave covers the floor), the rest miss; every photon carries E pi R^2 / N.
#[test]
fn photons_deliver_irradiance_times_area() {
    let scene = load(&scene("photon", 1, "[0.0, -1.0, 0.0]"));
    let power = scene.lights()[0].power().as_dvec3();
    let opts = TraceOptions {
        photons: 200_000,
        max_depth: 1,
        seed: 4,
        stream: STREAM_GLOBAL,
        stop_at_diffuse: true,
        sobol_emission: false,
    };
    let sources = foton_photonmap::sources::Sources::new(&scene).unwrap();
    let mut total = DVec3::ZERO;
    for i in 0..opts.photons {
        trace_one(&scene, &opts, &sources, i, |p, _, _| {
            // Those on the sphere's top were stored there: count the floor's only.
            if p.position.y.abs() < 1e-3 {
                total += p.power().as_dvec3();
            }
        });
    }
    // The floor's 4 m^2 less the sphere's shadow (pi 0.25^2) receive E each.
    let area = 4.0 - std::f64::consts::PI * 0.25 * 0.25;
    let want = DVec3::new(2.0, 1.0, 0.5) * area;
    // Binomial: the fraction of the disc's photons hitting it has a relative standard
    // deviation sqrt((1 - q) / (q N)) with q = area / (pi R^2): 4 sigma.
    let q = area / (power.x / 2.0);
    let sigma = ((1.0 - q) / (q * opts.photons as f64)).sqrt();
    let rel = ((total - want) / want).abs().max_element();
    assert!(
        rel < 4.0 * sigma,
        "{total} against {want} ({rel}, sigma {sigma})"
    );
}

/// `photon` (direct light from the sun's photons) and `path` (its light sample) agree by
/// blocks on the floor with the sphere's slanted shadow. Tolerance: 6% (the photon estimate's
/// blur over the shadow's edge at radius 0.06 and its noise), 4 standard errors, and a floor
/// for the black blocks beyond the floor.
#[test]
fn path_and_photon_agree_under_the_sun() {
    let direction = "[0.5, -1.0, 0.3]";
    let path = render_toml("sun-path", &scene("path", 256, direction), &[], 2);
    let photon = render_toml("sun-photon", &scene("photon", 16, direction), &[], 2);
    assert!(
        path.mean().x > 0.1,
        "the sun lights the floor: {}",
        path.mean()
    );
    assert_blocks_agree(
        "photon against path under a directional light",
        &photon,
        &path,
        4,
        Tolerance {
            rel: 0.06,
            z: 4.0,
            floor: 0.01 * path.mean().x as f64,
        },
    );
}

/// A directional light needs a direction.
#[test]
fn a_directional_light_without_a_direction_is_an_error() {
    let text = scene("path", 1, "[0.0, 0.0, 0.0]");
    let dir = temp_dir("directional-bad");
    let path = write(&dir, "scene.toml", &text);
    let err = foton_loader::load(&path, &[]).err().unwrap().to_string();
    assert!(
        err.contains("lights[0].direction") && err.contains("zero length"),
        "{err}"
    );
    let text = text.replace("direction = [0.0, 0.0, 0.0]\n", "");
    let path = write(&dir, "scene.toml", &text);
    let err = foton_loader::load(&path, &[]).err().unwrap().to_string();
    assert!(
        err.contains("lights[0].direction") && err.contains("missing"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(dir);
}
