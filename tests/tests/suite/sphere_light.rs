//! A small or distant sphere light (issue 18): the cone of directions it subtends, sin^2 =
//! r^2 / d^2, is sampled and its pdf computed without the cancellation of 1 - sqrt(1 - r^2/d^2)
//! in 32-bit floats (which made the pdf 1.07x off at r/d = 1e-3, 3x at 2e-4 and infinite at
//! 1e-4). Checked against the exact solid angle and the exact irradiance, in renders against
//! a point light of the same power (I cos theta / d^2), and for the photons it emits.

use foton_core::Rgb;
use foton_core::geometry::Shape;
use foton_core::integrator::{NoProgress, RenderContext};
use foton_core::light::area_light;
use foton_photonmap::surface::{Budgets, trace_surface_photons};
use foton_tests::stats::rel_err;
use foton_tests::{header, render_toml, temp_dir, write};
use glam::{Vec2, Vec3};
use std::f64::consts::PI;

/// 1 - cos theta_max of a sphere of radius r at distance d, in 64 bits without cancellation.
fn one_minus_cos_max(r: f64, d: f64) -> f64 {
    let s2 = (r / d) * (r / d);
    s2 / (1.0 + (1.0 - s2).sqrt())
}

/// From a point at distance d (along an oblique axis), for r/d from 0.3 down to 1e-4: the pdf
/// is one over the solid angle, every sample lands on the sphere's near side inside the cone
/// with that pdf, and the irradiance estimate on a surface facing the sphere is pi L sin^2
/// theta_max (the exact irradiance from a uniformly bright sphere above the horizon).
#[test]
fn sphere_cone_pdf_and_irradiance_are_exact_down_to_tiny_angles() {
    let x = Vec3::new(0.3, -0.2, 0.1);
    let axis = Vec3::new(0.36, 0.48, 0.8);
    let radiance = 2.0f32;
    for (r, d) in [
        (0.3f32, 1.0f32),
        (1e-2, 1.0),
        (1e-3, 1.0),
        (2e-4, 1.0),
        (1e-4, 1.0),
        (1.0, 1e4),
    ] {
        let center = x + axis * d;
        let sphere = Shape::sphere(center, r);
        let light = area_light(vec![sphere], Rgb::splat(radiance), 0);
        let want_pdf = 1.0 / (2.0 * PI * one_minus_cos_max(r as f64, d as f64));
        let n = 4096;
        let mut irradiance = 0.0f64;
        for i in 0..n {
            let u = Vec2::new(
                (i as f32 + 0.5) / n as f32,
                ((i * 37) % n) as f32 / n as f32,
            );
            let ls = light.sample_li(x, u, 0.5).expect("a sample");
            let what = format!("r = {r}, d = {d}, sample {i}");
            assert!(
                (ls.pdf as f64 / want_pdf - 1.0).abs() < 1e-4,
                "{what}: pdf {} against {want_pdf}",
                ls.pdf
            );
            let pdf_li = light.pdf_li(x, ls.p, ls.n) as f64;
            assert!(
                (pdf_li / want_pdf - 1.0).abs() < 1e-4,
                "{what}: pdf_li {pdf_li}"
            );
            // On the sphere, on its side facing x, in the cone (in 64 bits).
            let (p, c) = (ls.p.as_dvec3(), center.as_dvec3());
            assert!(
                ((p - c).length() / r as f64 - 1.0).abs() < 1e-3,
                "{what}: off the sphere"
            );
            assert!(
                ls.n.as_dvec3().dot(x.as_dvec3() - p) > 0.0,
                "{what}: far side"
            );
            // The angle from the axis by its sine (1 - cos of a 32-bit direction is noise at
            // these angles), allowing for the rounding of the directions.
            let (wi, a) = (ls.wi.as_dvec3(), axis.as_dvec3().normalize());
            let cos = wi.dot(a);
            let sin = wi.cross(a).length();
            assert!(
                cos > 0.0 && sin <= 1.01 * (r / d) as f64 + 2e-7,
                "{what}: outside the cone"
            );
            assert_eq!(ls.li, Rgb::splat(radiance), "{what}");
            irradiance += ls.li.x as f64 * cos / ls.pdf as f64;
        }
        irradiance /= n as f64;
        let s2 = (r as f64 / d as f64).powi(2);
        let want = PI * radiance as f64 * s2;
        assert!(
            (irradiance / want - 1.0).abs() < 1e-3,
            "r = {r}, d = {d}: irradiance {irradiance} against pi L sin^2 = {want}"
        );
    }
}

/// A plane 1 below a light: a sphere of radius 1e-4 with radiance L, or a point light of the
/// same power, intensity I = pi r^2 L.
fn plane_scene(integrator: &str, light: &str) -> String {
    header(integrator, 4, 4, 16, 16)
        + &format!(
            r#"
[camera]
position = [0, 3, 4]
look_at = [0, 0, 0]
fov = 50

[materials.plane]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[materials.black]
type = "diffuse"
reflectance = [0, 0, 0]

[[shapes]]
type = "quad"
origin = [-10, 0, 10]
u = [20, 0, 0]
v = [0, 0, -20]
material = "plane"

{light}

[integrators.photon]
global_photons = 100000
caustic_photons = 0
direct = "photons"
k = 50
"#
        )
}

const RADIUS: f64 = 1e-4;
const RADIANCE: f64 = 1e8;

fn sphere_light() -> String {
    format!(
        "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 1, 0]\nradius = {RADIUS}\nmaterial = \"black\"\nemission = [{RADIANCE}, {RADIANCE}, {RADIANCE}]\n"
    )
}

fn point_light() -> String {
    let i = PI * RADIUS * RADIUS * RADIANCE;
    format!("[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [{i}, {i}, {i}]\n")
}

/// The path tracer: the plane under the tiny sphere is the plane under the point light, pixel
/// by pixel (both nearly noise-free: the sphere subtends 1e-4 radians).
#[test]
fn a_tiny_sphere_light_lights_a_plane_as_a_point_light_does() {
    let sphere = render_toml(
        "sphere-light",
        &plane_scene("path", &sphere_light()),
        &[],
        2,
    );
    let point = render_toml("point-light", &plane_scene("path", &point_light()), &[], 2);
    let mean = point.mean();
    assert!(mean.min_element() > 0.01, "the plane is lit: {mean}");
    for y in 0..16 {
        for x in 0..16 {
            let (a, b) = (sphere.pixel(x, y), point.pixel(x, y));
            if b.max_element() > 0.01 * mean.max_element() {
                assert!(
                    rel_err(a, b) < 0.01,
                    "pixel ({x}, {y}): sphere {a}, point {b}"
                );
            }
        }
    }
}

/// The photons the tiny sphere emits: the flux they bring to a disc of radius R under it is
/// the point light's, I 2 pi (1 - h / sqrt(h^2 + R^2)), within 4 standard errors.
#[test]
fn a_tiny_sphere_light_emits_photons_as_a_point_light_does() {
    let dir = temp_dir("sphere-photons");
    let i = PI * RADIUS * RADIUS * RADIANCE;
    let (h, big_r) = (1.0f64, 1.0f64);
    let want = i * 2.0 * PI * (1.0 - h / (h * h + big_r * big_r).sqrt());
    for (name, light) in [("sphere", sphere_light()), ("point", point_light())] {
        let path = write(
            &dir,
            &format!("{name}.toml"),
            &plane_scene("photon", &light),
        );
        let scene = foton_loader::load(&path, &[]).unwrap();
        let cancel = Default::default();
        let ctx = RenderContext::new(2, &cancel, &NoProgress);
        let budgets = Budgets {
            global: 100_000,
            caustic: 0,
            max_depth: 4,
        };
        let [direct, _, _] = trace_surface_photons(&scene, &ctx, &budgets, true, false).unwrap();
        let inside: Vec<f64> = direct
            .iter()
            .filter(|p| (p.position.x as f64).hypot(p.position.z as f64) < big_r)
            .map(|p| p.power().x as f64)
            .collect();
        let flux: f64 = inside.iter().sum();
        // Photon powers are equal: the count's binomial error is the flux's.
        let se = flux / (inside.len().max(1) as f64).sqrt();
        assert!(
            (flux - want).abs() < 4.0 * se + 1e-3 * want,
            "{name}: {flux} W on the disc ({} photons), want {want} (se {se})",
            inside.len()
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}
