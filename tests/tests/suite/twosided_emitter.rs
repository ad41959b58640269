//! Two-sided area lights (`emission_twosided`, pbrt-v4's `twosided`): the same radiance on
//! both sides of the shape, twice the power. A two-sided quad lights a room as two one-sided
//! quads back to back do, for the path tracer (emission hit, next-event estimation) and for
//! the estimators that start paths at the light (bdpt's light tracing, photons).

use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, render_toml};

/// A closed white box [-1, 1]^3 with a black quad light across its middle, seen from a
/// corner: `lights` the light's shapes.
fn room(integrator: &str, spp: u32, lights: &str) -> String {
    header(integrator, spp, 4, 24, 24)
        + r#"
[camera]
position = [0.9, 0.3, 0.9]
look_at = [-1.0, -0.2, -1.0]
fov = 80.0

[materials.white]
type = "diffuse"
reflectance = [0.6, 0.6, 0.6]

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "mesh"
material = "white"
positions = [-1, -1, -1,  1, -1, -1,  1, 1, -1,  -1, 1, -1,  -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1]
indices = [0, 2, 1, 0, 3, 2,  4, 5, 6, 4, 6, 7,  0, 1, 5, 0, 5, 4,  3, 7, 6, 3, 6, 2,  0, 4, 7, 0, 7, 3,  1, 2, 6, 1, 6, 5]
"# + lights
}

const TWOSIDED: &str = r#"
[[shapes]]
type = "quad"
origin = [-0.4, 0.0, -0.4]
u = [0.8, 0.0, 0.0]
v = [0.0, 0.0, 0.8]
material = "black"
emission = [1.0, 1.0, 1.0]
emission_twosided = true
"#;

/// The same as two one-sided quads 1e-3 apart, facing away from each other.
const BACK_TO_BACK: &str = r#"
[[shapes]]
type = "quad"
origin = [-0.4, -0.0005, -0.4]
u = [0.8, 0.0, 0.0]
v = [0.0, 0.0, 0.8]
material = "black"
emission = [1.0, 1.0, 1.0]

[[shapes]]
type = "quad"
origin = [-0.4, 0.0005, -0.4]
u = [0.0, 0.0, 0.8]
v = [0.8, 0.0, 0.0]
material = "black"
emission = [1.0, 1.0, 1.0]
"#;

const Z: Tolerance = Tolerance {
    rel: 0.0,
    z: 4.5,
    floor: 1e-4,
};

#[test]
fn a_twosided_light_is_two_one_sided_lights_back_to_back() {
    let pair = render_toml("twosided", &room("path", 512, BACK_TO_BACK), &[], 2);
    let path = render_toml("twosided", &room("path", 512, TWOSIDED), &[], 2);
    assert_blocks_agree("two-sided against back to back (path)", &path, &pair, 4, Z);
    let light = render_toml(
        "twosided",
        &room("bdpt", 128, TWOSIDED),
        &["integrators.bdpt.strategy=\"light\""],
        2,
    );
    assert_blocks_agree("light tracing against path", &light, &path, 4, Z);
    let bdpt = render_toml("twosided", &room("bdpt", 64, TWOSIDED), &[], 2);
    assert_blocks_agree("bdpt against path", &bdpt, &path, 4, Z);
    // The photon estimators (photons leave both sides): their means, within their bias.
    for (integrator, spp) in [("photon", 32), ("sppm", 32), ("vcm", 32)] {
        let film = render_toml("twosided", &room(integrator, spp, TWOSIDED), &[], 2);
        let (m, want) = (film.mean().x, path.mean().x);
        assert!(
            (m / want - 1.0).abs() < 0.03,
            "{integrator}: mean {m}, path {want}"
        );
    }
    // Both sides are seen: the light's power is 2 pi A L.
    let scene = foton_tests::write(
        &foton_tests::temp_dir("twosided-power"),
        "s.toml",
        &room("path", 1, TWOSIDED),
    );
    let loaded = foton_loader::load(&scene, &[]).unwrap();
    let power = loaded.total_power().x;
    let want = 2.0 * std::f32::consts::PI * 0.64;
    assert!(
        (power / want - 1.0).abs() < 1e-5,
        "power {power}, 2 pi A L = {want}"
    );
}
