//! The thin dielectric (Mitsuba's `thindielectric`): an emitter seen through a thin sheet of
//! glass keeps the fraction T' = 1 - 2R / (1 + R) of its radiance (R the Fresnel reflectance
//! of one face, the sheet's interreflections summed), undeviated, for path and photon.

use foton_core::material::fresnel_dielectric;
use foton_tests::{header, region_mean, render_toml};
use glam::Vec3;

fn scene(integrator: &str) -> String {
    header(integrator, 256, 8, 16, 16)
        + r#"
[camera]
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 10.0

[integrators.photon]
global_photons = 50000
caustic_photons = 0
k = 5

[materials.sheet]
type = "thindielectric"
ior = 1.5
[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-1.0, -1.0, 0.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "sheet"

[[shapes]]
type = "quad"
origin = [-3.0, -3.0, -2.0]
u = [6.0, 0.0, 0.0]
v = [0.0, 6.0, 0.0]
material = "black"
emission = [1.0, 1.0, 1.0]
"#
}

/// Near normal incidence (within 7 degrees) R = 0.04, so T' = 0.9231: the image's mean within
/// 1% (each sample passes or is reflected: binary, 256 per pixel, so the image mean's standard
/// error is about 0.001). A plain dielectric sheet would also pass 0.92 but shift the
/// emitter's image; a sheet that forgot the interreflections would pass 0.96.
#[test]
fn an_emitter_seen_through_a_thin_sheet_keeps_t_prime() {
    let r = fresnel_dielectric(1.0, 1.5);
    let t = 1.0 - 2.0 * r / (1.0 + r);
    assert!((t - 0.923_077).abs() < 1e-5, "{t}");
    for integrator in ["path", "photon"] {
        let film = render_toml("thin-sheet", &scene(integrator), &[], 2);
        let (mean, _) = region_mean(&film, 0, 0, 16, 16);
        let rel = ((mean - Vec3::splat(t)) / t).abs().max_element();
        assert!(rel < 0.01, "{integrator}: {mean} against T' = {t}");
    }
}
