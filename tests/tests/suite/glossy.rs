//! Glossy materials (issue 10): Mitsuba's `roughconductor`, `roughdielectric`, `plastic` and
//! `roughplastic` in every integrator. The lobes themselves (chi-square of their samplers,
//! pdfs that integrate to one, furnaces of the lobes alone, Mitsuba's values) are tested in
//! core/src/glossy/ and microfacet.rs; here, whole renders:
//!
//! * white furnaces: inside a constant environment L, a sphere of a lossless material never
//!   shows more than L (energy is never gained), and single-scattering microfacet lobes lose
//!   only a little;
//! * the photon integrators' method for glossy surfaces seen from the camera (core's camera
//!   walk: lobes smoother than `glossy_roughness` are followed by sampling, with next-event
//!   estimation at the glossy vertex; rougher ones are estimated from photons) converges to the
//!   path tracer's image either way: with the default threshold, and with 0 (every glossy
//!   surface estimated from photons).

use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, region_mean, render_toml};

/// A sphere of `material` (a TOML material body) filling the view's centre, in a constant
/// environment of radiance 1.
fn furnace(integrator: &str, spp: u32, material: &str) -> String {
    header(integrator, spp, 64, 16, 16)
        + &format!(
            r#"
[camera]
position = [0, 0, 6]
look_at = [0, 0, 0]
fov = 12

[materials.m]
{material}

[[shapes]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "m"

[[lights]]
type = "constant"
radiance = [1, 1, 1]

[integrators.photon]
global_photons = 20000
caustic_photons = 0

[integrators.sppm]
iterations = 8
photons_per_iteration = 5000
"#
        )
}

/// Energy is never gained: the centre of a lossless glossy sphere in a white furnace is at most
/// the environment's radiance (within the noise), and about what single scattering keeps: the
/// lobes leave out light that would bounce between microfacets, as Mitsuba 3's do (its
/// directional albedos at normal incidence, by sampling its BSDFs: GGX conductor alpha 0.3
/// 0.876, GGX rough plastic alpha 0.2 over a white base 0.797). The lower bounds are those
/// less 3 points.
#[test]
fn glossy_spheres_in_a_white_furnace_gain_no_energy() {
    for (material, least) in [
        // No index of refraction: Mitsuba's perfect (F = 1) rough mirror.
        (
            "type = \"roughconductor\"\ndistribution = \"ggx\"\nalpha = 0.3",
            0.84,
        ),
        (
            "type = \"roughconductor\"\ndistribution = \"beckmann\"\nalpha_u = 0.1\nalpha_v = 0.4",
            0.96,
        ),
        (
            "type = \"roughdielectric\"\ndistribution = \"ggx\"\nalpha = 0.3\nior = 1.5",
            0.8,
        ),
        (
            "type = \"plastic\"\ndiffuse_reflectance = [1, 1, 1]\nnonlinear = true",
            0.96,
        ),
        (
            "type = \"roughplastic\"\ndistribution = \"ggx\"\nalpha = 0.2\ndiffuse_reflectance = [1, 1, 1]\nnonlinear = true",
            0.76,
        ),
    ] {
        let film = render_toml("glossy-furnace", &furnace("path", 256, material), &[], 2);
        let (centre, se) = region_mean(&film, 5, 5, 11, 11);
        assert!(
            centre.max_element() <= 1.0 + 4.0 * se.max_element() + 1e-4,
            "{material}: {centre} > 1 (se {se})"
        );
        assert!(
            centre.min_element() >= least,
            "{material}: {centre} < {least}: energy lost"
        );
    }
}

/// A small scene with each glossy material, a disk area light and a point light (so that
/// glossy reflections of a delta light must come from next-event estimation at the glossy
/// vertex: a sampled ray never hits a point light).
fn glossy_scene(integrator: &str, spp: u32, extra: &str) -> String {
    header(integrator, spp, 8, 24, 24)
        + &format!(
            r#"
[camera]
position = [0, 2.2, 7]
look_at = [0, 0.6, 0]
fov = 40

[materials.floor]
type = "roughplastic"
distribution = "ggx"
alpha = 0.3
diffuse_reflectance = [0.2, 0.4, 0.7]
twosided = false

[materials.wall]
type = "diffuse"
reflectance = [0.6, 0.6, 0.5]

[materials.gold]
type = "roughconductor"
material = "Au"
distribution = "ggx"
alpha = 0.2

[materials.glass]
type = "roughdielectric"
alpha = 0.15
ior = 1.5

[materials.red]
type = "plastic"
diffuse_reflectance = [0.7, 0.15, 0.1]

[materials.black]
type = "diffuse"
reflectance = [0, 0, 0]

[[shapes]]
type = "quad"
origin = [-4, 0, 4]
u = [8, 0, 0]
v = [0, 0, -8]
material = "floor"

[[shapes]]
type = "quad"
origin = [-4, -2, -2.5]
u = [8, 0, 0]
v = [0, 8, 0]
material = "wall"

[[shapes]]
type = "sphere"
center = [-1.6, 0.7, 0]
radius = 0.7
material = "gold"

[[shapes]]
type = "sphere"
center = [0, 0.7, 0.3]
radius = 0.7
material = "glass"

[[shapes]]
type = "sphere"
center = [1.6, 0.7, 0]
radius = 0.7
material = "red"

[[shapes]]
type = "disk"
center = [0, 3.5, 1]
normal = [0, -1, 0]
radius = 0.5
material = "black"
emission = [25, 25, 25]

[[lights]]
type = "point"
position = [2, 3, 3]
intensity = [6, 6, 6]

[integrators.photon]
global_photons = 200000
caustic_photons = 100000
k = 30

[integrators.vpm]
global_photons = 200000
caustic_photons = 100000
k = 30

[integrators.sppm]
iterations = 64
photons_per_iteration = 20000
{extra}
"#
        )
}

/// `photon`, `vpm` and `sppm` (with glossy surfaces followed by sampling, and, for sppm, with
/// them estimated from photons) agree with the path tracer by blocks. Tolerance: 10% per block for the photon
/// maps' blur and bias (the glass sphere's caustic, the edges of the spheres' shadows), 4
/// standard errors of the pixel noise, and a floor for dark blocks.
#[test]
fn photon_integrators_agree_with_path_on_glossy_materials() {
    let path = render_toml("glossy-path", &glossy_scene("path", 512, ""), &[], 2);
    let mean = path.mean();
    assert!(mean.min_element() > 0.02, "the scene is lit: {mean}");
    let tolerance = Tolerance {
        rel: 0.10,
        z: 4.0,
        floor: 0.03 * mean.max_element() as f64,
    };
    for (name, integrator, spp, extra) in [
        ("photon", "photon", 16, ""),
        ("vpm", "vpm", 16, ""),
        ("sppm", "sppm", 1, ""),
        (
            "sppm, glossy estimated from photons",
            "sppm",
            1,
            "glossy_roughness = 0",
        ),
    ] {
        let film = render_toml(
            "glossy-photons",
            &glossy_scene(integrator, spp, extra),
            &[],
            2,
        );
        assert_blocks_agree(&format!("{name} against path"), &film, &path, 4, tolerance);
        let m = film.mean();
        let rel = ((m - mean) / mean).abs().max_element();
        assert!(rel < 0.03, "{name}: image mean {m} against path's {mean}");
    }
}
