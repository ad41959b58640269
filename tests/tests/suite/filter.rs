//! Pixel filters (box, tent, gaussian; Mitsuba's rfilter) placed by filter importance
//! sampling, and the camera's fov_axis: the sampled offsets follow each filter's density
//! (chi-square), an edge seen through the camera comes out with the filter's profile, and the
//! field of view spans the axis asked for.

use foton_core::filter::{Filter, FilterSampler};
use foton_core::sampling::Rng;
use foton_tests::stats::assert_gof;
use foton_tests::{header, render_toml, temp_dir, write};
use glam::Vec2;

/// The offsets from the pixel's centre along x follow the filter's 1-D density: counts in 40
/// cells over the support against the profile's integral over each (Simpson's rule).
#[test]
fn sampled_offsets_follow_the_filters_density() {
    for filter in [
        Filter::Tent { radius: 1.0 },
        Filter::Tent { radius: 2.5 },
        Filter::Gaussian { stddev: 0.5 },
    ] {
        let sampler = FilterSampler::new(filter.clone());
        let r = filter.radius() as f64;
        const CELLS: usize = 40;
        const N: usize = 200_000;
        let edge = |i: usize| -r + 2.0 * r * i as f64 / CELLS as f64;
        let mass: Vec<f64> = (0..CELLS)
            .map(|i| {
                let (a, b) = (edge(i), edge(i + 1));
                let f = |x: f64| filter.profile(x as f32);
                (b - a) / 6.0 * (f(a) + 4.0 * f(0.5 * (a + b)) + f(b))
            })
            .collect();
        let total: f64 = mass.iter().sum();
        let expected: Vec<f64> = mass.iter().map(|m| m / total * N as f64).collect();
        let mut observed = vec![0u64; CELLS];
        let mut rng = Rng::new(&[11]);
        for _ in 0..N {
            let p = sampler.film_position(0, 0, rng.next_2d()) - Vec2::splat(0.5);
            assert!(p.x.abs() <= r as f32 && p.y.abs() <= r as f32, "{p}");
            let cell = (((p.x as f64 + r) / (2.0 * r)) * CELLS as f64) as usize;
            observed[cell.min(CELLS - 1)] += 1;
        }
        assert_gof(&filter.describe(), &observed, &expected, 1e-4);
    }
    // The box filter is the uniform jitter inside the pixel, exactly as before filters.
    let boxed = FilterSampler::new(Filter::Box);
    let u = Vec2::new(0.25, 0.75);
    assert_eq!(boxed.film_position(3, 5, u), Vec2::new(3.25, 5.75));
}

/// An emitter covering the right part of the view (radiance 1, its left edge at film x = e)
/// rendered by `path` at 2048 samples: the pixel at column i sees the fraction of the filter's
/// mass centred on i + 0.5 that lies right of the edge, within 0.04 (the sampling noise of a
/// fraction is at most 0.011 at 2048 samples).
#[test]
fn an_edge_is_seen_through_the_filter() {
    for (spec, filter) in [
        ("\"box\"", Filter::Box),
        (
            "{ type = \"tent\", radius = 1.5 }",
            Filter::Tent { radius: 1.5 },
        ),
        (
            "{ type = \"gaussian\", stddev = 0.6 }",
            Filter::Gaussian { stddev: 0.6 },
        ),
    ] {
        let mut s = header("path", 2048, 1, 16, 4);
        s += &format!("filter = {spec}\n");
        s += r#"
[camera]
position = [0.0, 0.0, 10.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 2.0
fov_axis = "x"

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [0.0123, -5.0, 0.0]
u = [5.0, 0.0, 0.0]
v = [0.0, 10.0, 0.0]
material = "black"
emission = [1.0, 1.0, 1.0]
"#;
        let dir = temp_dir("filter-edge");
        let path = write(&dir, "scene.toml", &s);
        let scene = foton_loader::load(&path, &[]).unwrap();
        let e = scene
            .camera()
            .project(glam::Vec3::new(0.0123, 0.0, 0.0))
            .unwrap()
            .x as f64;
        let _ = std::fs::remove_dir_all(dir);
        let film = render_toml("filter-edge", &s, &[], 2);
        let r = filter.radius() as f64;
        // The fraction of the filter's mass right of the edge, by a fine Riemann sum.
        let beyond = |centre: f64| {
            let n = 4000;
            let (mut right, mut all) = (0.0, 0.0);
            for k in 0..n {
                let x = -r + 2.0 * r * (k as f64 + 0.5) / n as f64;
                let w = filter.profile(x as f32);
                all += w;
                if centre + x > e {
                    right += w;
                }
            }
            right / all
        };
        for i in 0..16u32 {
            let want = beyond(i as f64 + 0.5);
            let got = film.pixel(i, 2).x as f64;
            assert!(
                (got - want).abs() < 0.04,
                "{}: column {i} (edge at {e:.3}): {got} against {want}",
                filter.describe()
            );
        }
    }
}

/// `fov_axis`: the field of view spans the image's width (x), height (y), diagonal, or its
/// smaller or larger side; checked on a 40x20 film by the angle between the rays through the
/// two ends of that extent.
#[test]
fn the_field_of_view_spans_the_axis_asked_for() {
    let (w, h) = (40.0f32, 20.0f32);
    let ends = |axis: &str| -> (Vec2, Vec2) {
        match axis {
            "x" | "larger" => (Vec2::new(0.0, h / 2.0), Vec2::new(w, h / 2.0)),
            "y" | "smaller" => (Vec2::new(w / 2.0, 0.0), Vec2::new(w / 2.0, h)),
            _ => (Vec2::new(0.0, 0.0), Vec2::new(w, h)),
        }
    };
    for axis in ["x", "y", "diagonal", "smaller", "larger"] {
        let mut s = header("path", 1, 1, 40, 20);
        s += &format!(
            "[camera]\nposition = [0.0, 0.0, 0.0]\nlook_at = [0.0, 0.0, -1.0]\nfov = 50.0\nfov_axis = \"{axis}\"\n"
        );
        let dir = temp_dir("fov-axis");
        let path = write(&dir, "scene.toml", &s);
        let scene = foton_loader::load(&path, &[]).unwrap();
        let _ = std::fs::remove_dir_all(dir);
        let (a, b) = ends(axis);
        let (ra, rb) = (
            scene.camera().generate_ray(a),
            scene.camera().generate_ray(b),
        );
        let angle = ra.dir.dot(rb.dir).clamp(-1.0, 1.0).acos().to_degrees();
        assert!((angle - 50.0).abs() < 0.01, "{axis}: {angle}");
    }
}
