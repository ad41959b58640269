//! The spot light (Mitsuba's `spot`, and pbrt-v4's with `falloff = "smoothstep"`): its
//! falloff, its power, its photons and its light on a plane against the formulas, and path
//! and photon mapping agreeing under it.

use foton_core::Rgb;
use foton_core::light::{Falloff, Light, SpotLight, smoothstep, spot_falloff, spot_solid_angle};
use foton_core::sampling::Rng;
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, render_toml};
use glam::{Vec2, Vec3};
use std::f64::consts::PI;

fn spot() -> Light {
    spot_with(Falloff::Linear)
}

fn spot_with(falloff: Falloff) -> Light {
    Light::Spot(SpotLight {
        position: Vec3::new(0.0, 2.0, 0.0),
        axis: Vec3::NEG_Y,
        intensity: Rgb::new(3.0, 2.0, 1.0),
        beam_width: 15f32.to_radians(),
        cutoff: 30f32.to_radians(),
        falloff,
        texture: None,
    })
}

/// pbrt-v4's falloff: smoothstep(cos cutoff, cos beam width, cos theta), its power
/// 2 pi [(1 - cos b) + (cos b - cos c) / 2] I against a quadrature of the falloff the light
/// applies (through its light sample), and the photons' mean flux against that power.
#[test]
fn smoothstep_falloff_power_and_photons() {
    let (b, c) = (15f32.to_radians(), 30f32.to_radians());
    assert_eq!(smoothstep(0.2, 0.4, 0.1), 0.0);
    assert_eq!(smoothstep(0.2, 0.4, 0.5), 1.0);
    assert!((smoothstep(0.2, 0.4, 0.3) - 0.5).abs() < 1e-6);
    assert!((smoothstep(0.0, 1.0, 0.25) - 0.15625).abs() < 1e-6);
    assert_eq!(smoothstep(0.5, 0.5, 0.4), 0.0);
    assert_eq!(smoothstep(0.5, 0.5, 0.5), 1.0);
    let light = spot_with(Falloff::Smoothstep);
    // The falloff as the light applies it: I f / d^2 at distance 1 along each angle.
    let falloff = |theta: f64| {
        let p =
            Vec3::new(0.0, 2.0, 0.0) + Vec3::new(theta.sin() as f32, -(theta.cos() as f32), 0.0);
        light.sample_li(p, Vec2::splat(0.5), 0.5).unwrap().li.x as f64 / 3.0
    };
    assert!((falloff(0.0) - 1.0).abs() < 1e-5);
    assert_eq!(falloff(31f64.to_radians()), 0.0);
    let mid = ((b.cos() + c.cos()) / 2.0).acos() as f64;
    assert!((falloff(mid) - 0.5).abs() < 1e-3, "{}", falloff(mid));
    let n = 100_000;
    let quadrature: f64 = (0..n)
        .map(|i| {
            let theta = (i as f64 + 0.5) / n as f64 * PI / 2.0;
            falloff(theta) * 2.0 * PI * theta.sin() * PI / 2.0 / n as f64
        })
        .sum();
    let power = light.power().x as f64 / 3.0;
    let closed = 2.0 * PI * ((1.0 - b.cos() as f64) + (b.cos() as f64 - c.cos() as f64) / 2.0);
    assert!(
        (power - closed).abs() < 1e-5 * closed,
        "{power} against {closed}"
    );
    assert!(
        (power - quadrature).abs() < 1e-3 * power,
        "{power} against {quadrature}"
    );
    let mut rng = Rng::new(&[7]);
    let photons = 400_000;
    let mut sum = 0.0;
    for _ in 0..photons {
        let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
        sum += e.flux.x as f64 / 3.0;
    }
    let mean = sum / photons as f64;
    assert!(
        (mean - power).abs() < 5e-3 * power,
        "{mean} against {power}"
    );
}

/// Full intensity inside the beam, none past the cutoff, linear in the angle between.
#[test]
fn falloff_is_linear_in_the_angle_between_beam_and_cutoff() {
    let (b, c) = (15f32.to_radians(), 30f32.to_radians());
    let f = |degrees: f32| spot_falloff(degrees.to_radians().cos(), b, c);
    assert_eq!(f(0.0), 1.0);
    assert_eq!(f(14.9), 1.0);
    assert!((f(22.5) - 0.5).abs() < 1e-4, "{}", f(22.5));
    assert!((f(18.75) - 0.75).abs() < 1e-4, "{}", f(18.75));
    assert_eq!(f(30.1), 0.0);
    assert_eq!(f(120.0), 0.0);
}

/// Power = I times the falloff's integral over the sphere: the closed form against a
/// quadrature, and the mean flux of the photons the light emits against it.
#[test]
fn power_is_the_falloff_integral_and_photons_carry_it() {
    let (b, c) = (15f32.to_radians(), 30f32.to_radians());
    let n = 200_000;
    let quadrature: f64 = (0..n)
        .map(|i| {
            let theta = (i as f64 + 0.5) / n as f64 * PI;
            spot_falloff(theta.cos() as f32, b, c) as f64 * 2.0 * PI * theta.sin() * PI / n as f64
        })
        .sum();
    let closed = spot_solid_angle(b, c) as f64;
    assert!(
        (closed - quadrature).abs() < 1e-4 * closed,
        "{closed} against {quadrature}"
    );
    let light = spot();
    let power = light.power();
    assert!((power.x as f64 - 3.0 * closed).abs() < 1e-4 * power.x as f64);

    let mut rng = Rng::new(&[5]);
    let photons = 400_000;
    let mut sum = glam::DVec3::ZERO;
    for _ in 0..photons {
        let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
        assert!(e.dir.dot(Vec3::NEG_Y) >= 30f32.to_radians().cos() - 1e-5);
        sum += e.flux.as_dvec3();
    }
    let mean = sum / photons as f64;
    let rel = ((mean - power.as_dvec3()) / power.as_dvec3())
        .abs()
        .max_element();
    // The flux varies by at most a factor 1 / (fraction of the cone's solid angle at full
    // falloff): the mean of 400k is within 0.5%.
    assert!(rel < 5e-3, "mean photon flux {mean} against power {power}");
}

/// Irradiance on the plane y = 0 from the spot 2 above it: E = I f(theta) cos(theta) / r^2,
/// from the light sample the integrators use.
#[test]
fn irradiance_on_a_plane_is_i_falloff_cos_over_r2() {
    let light = spot();
    for x in [0.0f32, 0.4, 0.7, 0.9, 1.1, 1.3] {
        let p = Vec3::new(x, 0.0, 0.3);
        let ls = light.sample_li(p, Vec2::splat(0.5), 0.5).unwrap();
        let d = Vec3::new(0.0, 2.0, 0.0) - p;
        let cos = d.normalize().dot(Vec3::Y);
        let want = Rgb::new(3.0, 2.0, 1.0)
            * spot_falloff(cos, 15f32.to_radians(), 30f32.to_radians())
            * cos
            / d.length_squared();
        let got = ls.li * ls.wi.dot(Vec3::Y);
        assert!(
            (got - want).abs().max_element() < 1e-5,
            "x = {x}: {got} against {want}"
        );
    }
}

/// A white floor under a spot light in an open scene: `photon` with direct light from the
/// photons (the spot's emission sampler) and `path` (its light sample) agree by blocks.
/// Tolerance: 5% (the photon estimate's blur over the beam's edge and its noise at 400k
/// photons), 4 standard errors, and a floor for the dark blocks outside the cone.
#[test]
fn path_and_photon_agree_under_a_spot_light() {
    let scene = |integrator: &str, spp: u32| {
        header(integrator, spp, 2, 32, 32)
            + r#"
[camera]
position = [0.0, 3.0, 2.5]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 50.0

[integrators.photon]
global_photons = 400000
caustic_photons = 0
k = 80
max_radius = 0.08
direct = "photons"

[materials.white]
type = "diffuse"
reflectance = [0.8, 0.8, 0.8]

[[shapes]]
type = "quad"
origin = [-3.0, 0.0, -3.0]
u = [0.0, 0.0, 6.0]
v = [6.0, 0.0, 0.0]
material = "white"

[[lights]]
type = "spot"
position = [0.0, 2.0, 0.0]
look_at = [0.3, 0.0, 0.0]
intensity = [3.0, 3.0, 3.0]
cutoff_angle = 30.0
beam_width = 15.0
"#
    };
    let path = render_toml("spot-path", &scene("path", 256), &[], 2);
    let photon = render_toml("spot-photon", &scene("photon", 16), &[], 2);
    assert!(
        path.mean().x > 0.01,
        "the spot lights the floor: {}",
        path.mean()
    );
    assert_blocks_agree(
        "photon against path under a spot light",
        &photon,
        &path,
        4,
        Tolerance {
            rel: 0.05,
            z: 4.0,
            floor: 0.01 * path.mean().x as f64,
        },
    );
}

/// Bad spot parameters are errors naming the key and what was expected.
#[test]
fn bad_spot_parameters_are_clear_errors() {
    let base = header("path", 1, 1, 4, 4)
        + "[camera]\nposition = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\n"
        + "[[lights]]\ntype = \"spot\"\nposition = [0.0, 2.0, 0.0]\n";
    for (extra, key, words) in [
        ("", "lights[0].look_at", "needs look_at"),
        (
            "look_at = [0.0, 0.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\n",
            "lights[0].direction",
            "not both",
        ),
        (
            "direction = [0.0, 0.0, 0.0]\n",
            "lights[0].direction",
            "zero length",
        ),
        (
            "direction = [0.0, -1.0, 0.0]\ncutoff_angle = 120.0\n",
            "lights[0].cutoff_angle",
            "(0, 90]",
        ),
        (
            "direction = [0.0, -1.0, 0.0]\ncutoff_angle = 20.0\nbeam_width = 25.0\n",
            "lights[0].beam_width",
            "[0, cutoff_angle = 20]",
        ),
    ] {
        let dir = foton_tests::temp_dir("bad-spot");
        let path = foton_tests::write(&dir, "scene.toml", &(base.clone() + extra));
        let run = foton_tests::foton_with_plugins(&["check", path.to_str().unwrap()]);
        assert_eq!(run.code, 1, "{extra}: {}", run.stderr);
        assert!(
            run.stderr.contains(key)
                && run.stderr.contains(words)
                && run.stderr.contains("scene.toml:"),
            "{extra}: {}",
            run.stderr
        );
        assert!(!run.stderr.contains("panicked"));
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// Mitsuba 3's spot `texture`: an image across the cone, at uv = 1/2 + (x, y) / (2 z tan
/// cutoff) in the light's frame. A spot 2 above a grey floor, pointing down, with a 2 x 2
/// image of four colours (nearest): the floor under each quadrant shows rho I tex cos / (pi
/// r^2) in path (next-event estimation), bdpt and photon (its photons carry the image);
/// its power is I times the falloff's solid angle times the image's mean.
#[test]
fn a_textured_spot_projects_its_image() {
    let dir = foton_tests::temp_dir("spot-texture");
    let texels: [[f32; 3]; 4] = [
        [4.0, 1.0, 0.5],
        [0.5, 3.0, 1.0],
        [1.0, 0.5, 5.0],
        [2.0, 2.0, 2.0],
    ];
    let data: Vec<f32> = texels.iter().flatten().copied().collect();
    image::Rgb32FImage::from_raw(2, 2, data)
        .unwrap()
        .save(dir.join("slide.exr"))
        .unwrap();
    let scene = |integrator: &str, spp: u32| {
        header(integrator, spp, 1, 24, 24)
            + &format!(
                r#"
[camera]
position = [0.0, 1.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = 70.0

[integrators.photon]
global_photons = 2000000
caustic_photons = 0
k = 100

[materials.grey]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[[shapes]]
type = "quad"
origin = [-3.0, 0.0, 3.0]
u = [6.0, 0.0, 0.0]
v = [0.0, 0.0, -6.0]
material = "grey"

[[lights]]
type = "spot"
position = [0.0, 2.0, 0.0]
direction = [0.0, -1.0, 0.0]
up = [0.0, 0.0, -1.0]
intensity = [3.0, 3.0, 3.0]
cutoff_angle = 30.0
beam_width = 30.0
texture = {{ type = "bitmap", filename = "{}", raw = true, filter_type = "nearest" }}
"#,
                dir.join("slide.exr").display()
            )
    };
    // The light's frame: +x = up x axis = -X, +y = axis x x = -Z. A floor point (px, 0, pz)
    // is seen at local (-px, -pz, 2): u = 1/2 - px / (4 tan 30), v = 1/2 - pz / (4 tan 30).
    let t = 30f64.to_radians().tan();
    let want_at = |px: f64, pz: f64| {
        let (u, v) = (0.5 - px / (4.0 * t), 0.5 - pz / (4.0 * t));
        let texel = Vec3::from(texels[2 * ((2.0 * v) as usize) + (2.0 * u) as usize]).as_dvec3();
        let r2 = px * px + pz * pz + 4.0;
        let cos = 2.0 / r2.sqrt();
        (texel * (3.0 * cos / r2) * (0.5 / PI)).as_vec3()
    };
    // Pixel (x, y) of the 24 x 24 view from 1 above the origin, fov 70 (up = -z: image up is
    // -z, image right is +x).
    let half = 35f64.to_radians().tan();
    let floor_at = |x: u32, y: u32| {
        let sx = ((x as f64 + 0.5) / 12.0 - 1.0) * half;
        let sy = (1.0 - (y as f64 + 0.5) / 12.0) * half;
        (sx, -sy)
    };
    for (integrator, spp) in [("path", 64), ("bdpt", 32), ("photon", 16)] {
        let film = render_toml("spot-texture", &scene(integrator, spp), &[], 2);
        // A 4 x 4 block well inside each quadrant of the image.
        for (x0, y0) in [(3, 3), (17, 3), (3, 17), (17, 17)] {
            let (mut got, mut want) = (Vec3::ZERO, Vec3::ZERO);
            for y in y0..y0 + 4 {
                for x in x0..x0 + 4 {
                    got += film.pixel(x, y);
                    let (px, pz) = floor_at(x, y);
                    want += want_at(px, pz);
                }
            }
            let rel = ((got - want) / want).abs().max_element();
            assert!(
                rel < 0.03,
                "{integrator}: block ({x0}, {y0}) {} against {} ({rel})",
                got / 16.0,
                want / 16.0
            );
        }
    }
    let path = foton_tests::write(&dir, "scene.toml", &scene("path", 1));
    let loaded = foton_loader::load(&path, &[]).unwrap();
    let mean: Vec3 = texels.iter().map(|&c| Vec3::from(c)).sum::<Vec3>() / 4.0;
    let want = mean * 3.0 * (2.0 * std::f32::consts::PI * (1.0 - 30f32.to_radians().cos()));
    let power = loaded.lights()[0].power();
    // The grid over the cone weighs the four quadrants alike up to its resolution.
    assert!(
        ((power - want) / want).abs().max_element() < 0.02,
        "{power} against {want}"
    );
    let _ = std::fs::remove_dir_all(dir);
}
