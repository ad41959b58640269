//! The one crossing limit (core/src/walk.rs): a ray may cross at most MAX_NULL_CROSSINGS null
//! boundaries in a row; past that it is ended and carries nothing. Checked with a stack of
//! null quads (0.01 apart, well above the origin offset of about 1e-4 per crossing) in front
//! of an emitter: every integrator sees the emitter through one boundary fewer than the limit
//! and nothing through one more.

use foton_core::walk::MAX_NULL_CROSSINGS;
use foton_tests::{header, render_toml};

/// `layers` null quads at z = 0, -0.01, ... in front of an emissive quad at z = -10 (radiance
/// 1, facing the camera at z = 3), rendered by `integrator` at 4x4 pixels.
fn stack(integrator: &str, layers: u32) -> String {
    let mut s = header(integrator, 1, 4, 4, 4);
    s += r#"
[camera]
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 5.0

[integrators.photon]
global_photons = 100
caustic_photons = 0
k = 2

[materials.boundary]
type = "null"
[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-20.0, -20.0, -10.0]
u = [40.0, 0.0, 0.0]
v = [0.0, 40.0, 0.0]
material = "black"
emission = [1.0, 1.0, 1.0]
"#;
    for i in 0..layers {
        let z = -0.01 * i as f32;
        s += &format!(
            "\n[[shapes]]\ntype = \"quad\"\norigin = [-1.0, -1.0, {z}]\nu = [2.0, 0.0, 0.0]\nv = [0.0, 2.0, 0.0]\nmaterial = \"boundary\"\n"
        );
    }
    s
}

#[test]
fn past_the_crossing_limit_a_ray_is_ended() {
    for integrator in ["path", "photon", "normals"] {
        let seen = render_toml(
            "limit-under",
            &stack(integrator, MAX_NULL_CROSSINGS),
            &[],
            2,
        );
        let lost = render_toml(
            "limit-over",
            &stack(integrator, MAX_NULL_CROSSINGS + 1),
            &[],
            2,
        );
        for y in 0..4 {
            for x in 0..4 {
                let (a, b) = (seen.pixel(x, y), lost.pixel(x, y));
                assert!(
                    a.min_element() > 0.4,
                    "{integrator} ({x}, {y}) through the limit: {a}"
                );
                assert_eq!(
                    b,
                    glam::Vec3::ZERO,
                    "{integrator} ({x}, {y}) past the limit"
                );
            }
        }
    }
}
