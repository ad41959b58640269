//! The smooth conductor (Mitsuba's `conductor`, issue 10): a sphere of it inside a constant
//! environment shows, where the camera looks straight at it, the environment times the
//! Fresnel reflectance at normal incidence, ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2), for every
//! integrator; named materials are Mitsuba's; bad parameters are clear errors.

use foton_core::Rgb;
use foton_core::material::conductor_ior;
use foton_tests::{foton_with_plugins, header, render_toml, temp_dir, write};

fn normal_reflectance(eta: Rgb, k: Rgb) -> Rgb {
    let f = |n: f32, k: f32| ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
    Rgb::new(f(eta.x, k.x), f(eta.y, k.y), f(eta.z, k.z))
}

fn scene(integrator: &str, material: &str) -> String {
    header(integrator, 4, 8, 9, 9)
        + &format!(
            r#"
[camera]
position = [0, 0, 10]
look_at = [0, 0, 0]
fov = 2

[materials.metal]
type = "conductor"
{material}

[[shapes]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "metal"

[[lights]]
type = "constant"
radiance = [2, 2, 2]

[integrators.sppm]
iterations = 2
photons_per_iteration = 1000

[integrators.photon]
global_photons = 1000
caustic_photons = 1000
"#
        )
}

#[test]
fn a_conductor_reflects_the_fresnel_reflectance_of_its_ior() {
    let (au_eta, au_k) = conductor_ior("Au").unwrap();
    let custom = (Rgb::new(0.2, 0.9, 1.1), Rgb::new(3.9, 2.4, 2.1));
    for (material, eta, k, scale) in [
        ("material = \"Au\"", au_eta, au_k, Rgb::ONE),
        (
            "eta = [0.2, 0.9, 1.1]\nk = [3.9, 2.4, 2.1]\nspecular_reflectance = [0.5, 1, 1]",
            custom.0,
            custom.1,
            Rgb::new(0.5, 1.0, 1.0),
        ),
    ] {
        let expected = normal_reflectance(eta, k) * scale * 2.0;
        for integrator in ["path", "photon", "sppm"] {
            let film = render_toml("conductor", &scene(integrator, material), &[], 2);
            let centre = film.pixel(4, 4);
            // The centre pixel spans about 0.2 degrees of the sphere around normal incidence.
            let err = ((centre - expected) / expected).abs().max_element();
            assert!(
                err < 2e-3,
                "{integrator}, {material}: {centre} vs {expected}"
            );
        }
    }
    // Gold is yellow: more red than blue is reflected.
    let f = normal_reflectance(au_eta, au_k);
    assert!(f.x > 0.9 && f.z < 0.5, "{f}");
}

#[test]
fn bad_conductors_are_clear_errors() {
    let dir = temp_dir("conductor-errors");
    for (material, needles) in [
        (
            "material = \"gold\"",
            vec!["unknown conductor `gold`", "Au"],
        ),
        (
            "eta = [1, 1, 1]",
            vec!["`materials.metal.k`", "both eta and k"],
        ),
        (
            "material = \"Au\"\neta = [1, 1, 1]",
            vec!["either a named `material`"],
        ),
    ] {
        let path = write(&dir, "s.toml", &scene("path", material));
        let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
        assert_eq!(run.code, 1, "{material}");
        for n in needles {
            assert!(run.stderr.contains(n), "{n}: {}", run.stderr);
        }
    }
    // No parameters: Mitsuba's default, a perfect mirror (the environment itself).
    let film = render_toml("conductor-none", &scene("path", ""), &[], 2);
    assert!((film.pixel(4, 4) - Rgb::splat(2.0)).abs().max_element() < 1e-5);
}
