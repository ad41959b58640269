//! `ao` (ambient occlusion, pbrt-v4's `ambientocclusion`) against its closed form beside a
//! wall: a point on a floor at distance d from an unbounded wall sees the wall in exactly the
//! directions with w · x > 0, half the hemisphere; occlusion rays of length R meet it where
//! d / (w · x) <= R. Under the cosine the directions' projections onto the floor are uniform
//! on the unit disc, so the occluded fraction is the disc's segment beyond c = d / R:
//!
//!     A = 1 - (acos c - c sqrt(1 - c^2)) / pi.

use foton_tests::{header, render_toml};
use std::f64::consts::PI;

/// A floor (y = 0, facing up) and a wall (x = 1, facing -x), both far larger than the
/// occlusion rays reach; an orthographic camera looks down on a 2 cm patch of floor at x = 0,
/// d = 1 from the wall.
fn scene(extra: &str) -> String {
    header("ao", 256, 1, 8, 8)
        + r#"
[camera]
type = "orthographic"
position = [0.0, 5.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
view_height = 0.02

[materials.m]
type = "diffuse"

[[shapes]]
type = "quad"
origin = [-1000.0, 0.0, -1000.0]
u = [0.0, 0.0, 2000.0]
v = [2000.0, 0.0, 0.0]
material = "m"

[[shapes]]
type = "quad"
origin = [1.0, 0.0, -1000.0]
u = [0.0, 1000.0, 0.0]
v = [0.0, 0.0, 2000.0]
material = "m"
"# + extra
}

fn open_fraction(c: f64) -> f64 {
    if c >= 1.0 {
        return 1.0;
    }
    1.0 - (c.acos() - c * (1.0 - c * c).sqrt()) / PI
}

/// The image's mean and the standard deviation of that mean (64 pixels x 256 samples).
fn mean(name: &str, sets: &[&str]) -> (f64, Vec<f64>) {
    let film = render_toml(name, &scene(""), sets, 2);
    let px: Vec<f64> = film.pixels().iter().map(|p| p.x as f64).collect();
    for p in film.pixels() {
        assert!(p.x == p.y && p.y == p.z, "grey: {p}");
    }
    (px.iter().sum::<f64>() / px.len() as f64, px)
}

#[test]
fn occlusion_beside_a_wall_is_the_disc_segment_beyond_d_over_r() {
    let samples = 64.0 * 256.0;
    for (r, cosine) in [
        (None, true),
        (Some(2.0), true),
        (Some(1.25), false),
        (None, false),
    ] {
        let c = r.map_or(0.0, |r| 1.0 / r);
        let expected = open_fraction(c);
        let mut sets = vec![format!("integrators.ao.cosine={cosine}")];
        if let Some(r) = r {
            sets.push(format!("integrators.ao.max_distance={r}"));
        }
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let (m, _) = mean(&format!("ao-wall-{}-{cosine}", r.unwrap_or(0.0)), &sets);
        // Cosine sampling: Bernoulli of mean A. Uniform: 2 V cos, variance 2 A' - A^2 at most
        // 2 A - A^2 (E[4 V cos^2] <= 2 E[2 V cos] / 1 as cos <= 1).
        let var = if cosine {
            expected * (1.0 - expected)
        } else {
            2.0 * expected - expected * expected
        };
        let sigma = (var / samples).sqrt().max(1e-9);
        assert!(
            (m - expected).abs() < 5.0 * sigma + 1e-6,
            "R {r:?}, cosine {cosine}: mean {m}, expected {expected} (sigma {sigma})"
        );
    }
    // Beyond the wall's reach every ray is open: exactly 1 (cosine sampling).
    let (m, px) = mean("ao-short", &["integrators.ao.max_distance=0.9"]);
    assert_eq!(m, 1.0, "{px:?}");
}

/// Seen from below, the floor's hemisphere is the one facing the camera (pbrt-v4's face-
/// forwarded geometric normal): below the floor there is nothing, so it is open.
#[test]
fn the_hemisphere_faces_the_camera() {
    let sets = ["camera.position=[0.0, -5.0, 0.0]"];
    let (m, px) = mean("ao-below", &sets);
    assert_eq!(m, 1.0, "{px:?}");
}
