//! One-sided diffuse surfaces (`twosided = false`, what a Mitsuba BSDF is unless wrapped in
//! `twosided`): seen from the side the normal points away from they are black, for every
//! integrator; seen from the front they are the two-sided surface.

use foton_tests::{header, render_toml};

/// A quad facing +z (u x v), lit by a point light on each side, seen from `camera_z`.
fn scene(integrator: &str, twosided: bool, camera_z: f32) -> String {
    header(integrator, 16, 4, 8, 8)
        + &format!(
            r#"
[camera]
position = [0, 0, {camera_z}]
look_at = [0, 0, 0]
fov = 20

[materials.wall]
type = "diffuse"
reflectance = [0.8, 0.8, 0.8]
twosided = {twosided}

[[shapes]]
type = "quad"
origin = [-1, -1, 0]
u = [2, 0, 0]
v = [0, 2, 0]
material = "wall"

[[lights]]
type = "point"
position = [0, 0, 2]
intensity = [4, 4, 4]

[[lights]]
type = "point"
position = [0, 0, -2]
intensity = [4, 4, 4]

[integrators.sppm]
iterations = 4
photons_per_iteration = 20000

[integrators.photon]
global_photons = 20000
caustic_photons = 0
"#
        )
}

#[test]
fn a_one_sided_surface_is_black_from_behind() {
    for integrator in ["path", "photon", "sppm"] {
        let front = render_toml("one-sided", &scene(integrator, false, 3.0), &[], 2).mean();
        let two = render_toml("one-sided", &scene(integrator, true, 3.0), &[], 2).mean();
        let back = render_toml("one-sided", &scene(integrator, false, -3.0), &[], 2).mean();
        let two_back = render_toml("one-sided", &scene(integrator, true, -3.0), &[], 2).mean();
        // Irradiance I cos / r^2 = 1 at the centre: the front is clearly lit.
        assert!(front.x > 0.05, "{integrator}: {front}");
        assert_eq!(front, two, "{integrator}: the front side");
        assert!(
            two_back.x > 0.05,
            "{integrator}: a two-sided back is lit: {two_back}"
        );
        assert_eq!(
            back.max_element(),
            0.0,
            "{integrator}: the back side: {back}"
        );
    }
}
