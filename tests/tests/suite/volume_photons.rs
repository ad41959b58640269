//! The photon pass through participating media: energy is conserved, every photon ends
//! absorbed or escaped in the right proportion.

use foton_core::scene::Scene;
use foton_photonmap::trace::{PathClass, STREAM_GLOBAL, Site, TraceOptions, trace_one};
use foton_tests::{header, temp_dir, write};
use glam::DVec3;

/// A black (albedo 0) sphere of radius 1 filled with a grey medium, a point light of power
/// 4 pi at its centre: a photon hitting the wall has escaped the medium.
fn absorbing_sphere(sigma_a: f32, sigma_s: f32, g: f32) -> Scene {
    let mut toml = header("vpm", 1, 100_000, 8, 8);
    toml += &format!(
        r#"
[camera]
position = [0.0, 0.0, -0.5]
look_at = [0.0, 0.0, 0.5]
up = [0.0, 1.0, 0.0]
fov = 60.0
[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]
[media.fog]
type = "homogeneous"
sigma_a = [{sigma_a}, {sigma_a}, {sigma_a}]
sigma_s = [{sigma_s}, {sigma_s}, {sigma_s}]
phase = {{ type = "hg", g = {g} }}
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "black"
interior = "fog"
[[lights]]
type = "point"
position = [0.0, 0.0, 0.0]
intensity = [1.0, 1.0, 1.0]
"#
    );
    let dir = temp_dir("volume-photons");
    let scene = foton_loader::load(&write(&dir, "scene.toml", &toml), &[]).unwrap();
    let _ = std::fs::remove_dir_all(dir);
    scene
}

/// Power that reached the wall (escaped) and power absorbed in the medium, per unit of
/// emitted power. A volume photon carries the flux that scattered at its event, flux before
/// times albedo; the rest of the flux before, (1 - albedo) / albedo times it, was absorbed.
fn balance(scene: &Scene, albedo: f64, photons: u64) -> (f64, f64, u64) {
    let opts = TraceOptions {
        photons,
        max_depth: 100_000,
        seed: 11,
        stream: STREAM_GLOBAL,
        stop_at_diffuse: false,
        sobol_emission: false,
    };
    let sources = foton_photonmap::sources::Sources::new(scene).unwrap();
    assert_eq!(
        sources.light_media,
        vec![Some(0)],
        "the light is in the fog"
    );
    let (mut escaped, mut absorbed, mut events) = (DVec3::ZERO, DVec3::ZERO, 0);
    for i in 0..photons {
        trace_one(scene, &opts, &sources, i, |p, site, class| match site {
            Site::Surface => escaped += p.power().as_dvec3(),
            Site::Volume => {
                absorbed += p.power().as_dvec3() * (1.0 - albedo) / albedo;
                events += 1;
                if events == 1 {
                    assert_eq!(class, PathClass::Direct);
                }
            }
        });
    }
    let power = 4.0 * std::f64::consts::PI;
    (escaped.x / power, absorbed.x / power, events)
}

#[test]
fn a_pure_absorber_transmits_exp_minus_sigma_t_r() {
    // No scattering: every photon flies straight to the wall with weight exp(-sigma_a R)
    // (free-flight sampling with spectral MIS of a grey medium: it arrives with probability
    // exp(-sigma_a) and flux unchanged).
    let scene = absorbing_sphere(1.0, 0.0, 0.0);
    let (escaped, _, events) = balance(&scene, 0.5, 200_000);
    assert_eq!(events, 0, "a medium without scattering stores no photon");
    let expect = (-1.0f64).exp();
    // Binomial noise of 200k photons: 0.1 % of the power.
    assert!((escaped - expect).abs() < 0.004, "{escaped} vs {expect}");
}

#[test]
fn a_conservative_medium_lets_all_the_power_out() {
    // Albedo 1: nothing is absorbed, every photon reaches the wall however often it scatters.
    let scene = absorbing_sphere(0.0, 2.0, 0.3);
    let (escaped, _, events) = balance(&scene, 1.0, 50_000);
    assert!(events > 50_000, "photons scatter ({events} events)");
    assert!(
        (escaped - 1.0).abs() < 1e-4,
        "escaped {escaped} of the power"
    );
}

#[test]
fn escaped_and_absorbed_power_add_up_to_the_light_power() {
    for (sigma_a, sigma_s) in [(0.5f32, 1.5f32), (1.5, 0.5)] {
        let albedo = (sigma_s / (sigma_a + sigma_s)) as f64;
        let scene = absorbing_sphere(sigma_a, sigma_s, 0.0);
        let (escaped, absorbed, _) = balance(&scene, albedo, 200_000);
        assert!(
            (escaped + absorbed - 1.0).abs() < 0.01,
            "albedo {albedo}: escaped {escaped} + absorbed {absorbed}"
        );
        // More absorption, less escapes; the escaped fraction lies between the
        // no-scattering bound exp(-sigma_t R) and exp(-sigma_a R) (scattering lengthens the
        // way out, never shortens it below the straight line).
        let t = (sigma_a + sigma_s) as f64;
        assert!(
            escaped > (-t).exp() && escaped < (-(sigma_a as f64)).exp(),
            "{escaped}"
        );
    }
}
