//! Pixel filters (box, tent, gaussian; Mitsuba's rfilter) placed by filter importance
//! sampling, and the camera's fov_axis: the sampled offsets follow each filter's density
//! (chi-square), an edge seen through the camera comes out with the filter's profile, and the
//! field of view spans the axis asked for.

use foton_core::filter::{FilmSample, Filter, FilterSampler};
use foton_core::sampling::Rng;
use foton_tests::stats::assert_gof;
use foton_tests::{header, render_toml, temp_dir, write};
use glam::Vec2;

/// The offsets from the pixel's centre along x follow the filter's 1-D density: counts in 40
/// cells over the support against the profile's integral over each (Simpson's rule).
#[test]
fn sampled_offsets_follow_the_filters_density() {
    for filter in [Filter::tent(1.0), Filter::tent(2.5), Filter::gaussian(0.5)] {
        let sampler = FilterSampler::new(filter.clone());
        let r = filter.radius().x as f64;
        const CELLS: usize = 40;
        const N: usize = 200_000;
        let edge = |i: usize| -r + 2.0 * r * i as f64 / CELLS as f64;
        let mass: Vec<f64> = (0..CELLS)
            .map(|i| {
                let (a, b) = (edge(i), edge(i + 1));
                let f = |x: f64| filter.profile(0, x as f32);
                (b - a) / 6.0 * (f(a) + 4.0 * f(0.5 * (a + b)) + f(b))
            })
            .collect();
        let total: f64 = mass.iter().sum();
        let expected: Vec<f64> = mass.iter().map(|m| m / total * N as f64).collect();
        let mut observed = vec![0u64; CELLS];
        let mut rng = Rng::new(&[11]);
        for _ in 0..N {
            let s = sampler.sample(0, 0, rng.next_2d());
            assert_eq!(s.weight, 1.0);
            let p = s.film - Vec2::splat(0.5);
            assert!(p.x.abs() <= r as f32 && p.y.abs() <= r as f32, "{p}");
            let cell = (((p.x as f64 + r) / (2.0 * r)) * CELLS as f64) as usize;
            observed[cell.min(CELLS - 1)] += 1;
        }
        assert_gof(&filter.describe(), &observed, &expected, 1e-4);
    }
    // The box filter is the uniform jitter inside the pixel, exactly as before filters.
    let boxed = FilterSampler::new(Filter::Box);
    let u = Vec2::new(0.25, 0.75);
    assert_eq!(
        boxed.sample(3, 5, u),
        FilmSample {
            film: Vec2::new(3.25, 5.75),
            weight: 1.0
        }
    );
}

/// Each filter's 1-D profile at a few points against values of the published formulas:
/// Mitchell and Netravali's cubic (B = C = 1/3: 8/9 at 0, 1/18 at 1, -5/144 at 1.5), Catmull-Rom
/// (B = 0, C = 1/2: 9/16 at 0.5, -1/16 at 1.5), the Lanczos window sinc(x) sinc(x / 3)
/// (6 / pi^2 at 0.5, -4 / (3 pi^2) at 1.5), pbrt-v4's scaled Mitchell m(2 x / radius), its
/// windowed sinc and its Gaussian and triangle of two radii.
#[test]
fn new_filter_profiles_match_their_formulas() {
    use std::f64::consts::PI;
    let pi2 = PI * PI;
    let gauss = |x: f64, s: f64| (-x * x / (2.0 * s * s)).exp();
    let cases: Vec<(Filter, usize, f32, f64)> = vec![
        (Filter::mitchell(1.0 / 3.0, 1.0 / 3.0), 0, 0.0, 8.0 / 9.0),
        (Filter::mitchell(1.0 / 3.0, 1.0 / 3.0), 0, 1.0, 1.0 / 18.0),
        (
            Filter::mitchell(1.0 / 3.0, 1.0 / 3.0),
            1,
            -1.5,
            -5.0 / 144.0,
        ),
        (Filter::mitchell(1.0 / 3.0, 1.0 / 3.0), 0, 2.0, 0.0),
        (Filter::mitchell(1.0 / 3.0, 1.0 / 3.0), 0, 2.5, 0.0),
        (Filter::catmull_rom(), 0, 0.0, 1.0),
        (Filter::catmull_rom(), 0, 0.5, 9.0 / 16.0),
        (Filter::catmull_rom(), 0, 1.0, 0.0),
        (Filter::catmull_rom(), 0, 1.5, -1.0 / 16.0),
        (Filter::lanczos(3), 0, 0.0, 1.0),
        (Filter::lanczos(3), 0, 0.5, 6.0 / pi2),
        (Filter::lanczos(3), 0, 1.5, -4.0 / (3.0 * pi2)),
        (Filter::lanczos(3), 0, 2.0, 0.0),
        (Filter::lanczos(3), 0, 3.5, 0.0),
        // pbrt-v4's mitchell of radius [4, 1]: m(2 x / 4) along x, m(2 y) along y.
        (
            Filter::Mitchell {
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
                radius: Vec2::new(4.0, 1.0),
            },
            0,
            3.0,
            -5.0 / 144.0,
        ),
        (
            Filter::Mitchell {
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
                radius: Vec2::new(4.0, 1.0),
            },
            1,
            0.5,
            1.0 / 18.0,
        ),
        // pbrt-v4's sinc (radius 4, tau 3): sinc(3.5) sinc(7/6) = 3 / (24.5 pi^2).
        (
            Filter::Sinc {
                radius: Vec2::splat(4.0),
                tau: 3.0,
            },
            0,
            3.5,
            3.0 / (24.5 * pi2),
        ),
        (
            Filter::Sinc {
                radius: Vec2::splat(4.0),
                tau: 3.0,
            },
            1,
            4.5,
            0.0,
        ),
        // pbrt-v4's gaussian (sigma 0.5, radius [1.5, 1]): g(x) - g(radius) per axis.
        (
            Filter::Gaussian {
                stddev: 0.5,
                radius: Vec2::new(1.5, 1.0),
            },
            0,
            1.0,
            gauss(1.0, 0.5) - gauss(1.5, 0.5),
        ),
        (
            Filter::Gaussian {
                stddev: 0.5,
                radius: Vec2::new(1.5, 1.0),
            },
            1,
            1.0,
            0.0,
        ),
        // pbrt-v4's triangle of radii [2, 1] (as 1 - |x| / r).
        (
            Filter::Tent {
                radius: Vec2::new(2.0, 1.0),
            },
            0,
            1.0,
            0.5,
        ),
        (
            Filter::Tent {
                radius: Vec2::new(2.0, 1.0),
            },
            1,
            0.75,
            0.25,
        ),
    ];
    for (filter, axis, x, want) in cases {
        let got = filter.profile(axis, x);
        assert!(
            (got - want).abs() < 1e-6,
            "{} axis {axis} at {x}: {got} against {want}",
            filter.describe()
        );
    }
}

/// The filters with negative lobes, by their offsets and weights: the offsets along each axis
/// follow |w| (chi-square over 40 cells), and the mean of weight * g(offset) over the samples
/// is the filter-weighted mean of a smooth g, int w g / int w (within 4 standard errors);
/// some weights are negative, all have the magnitude int |w| / int w per axis.
#[test]
fn signed_filters_are_sampled_by_their_magnitude_and_weighted_by_their_sign() {
    let filters = [
        Filter::mitchell(1.0 / 3.0, 1.0 / 3.0),
        Filter::catmull_rom(),
        Filter::lanczos(3),
        Filter::Sinc {
            radius: Vec2::new(4.0, 2.5),
            tau: 3.0,
        },
        Filter::Mitchell {
            b: 0.0,
            c: 0.75,
            radius: Vec2::new(2.0, 3.0),
        },
    ];
    // Smooth, not symmetric, so that both lobes and both sides count.
    let g = |d: Vec2| -> f64 {
        let (x, y) = (d.x as f64, d.y as f64);
        (0.6 * x).exp() * (1.0 + 0.3 * y + 0.2 * y * y)
    };
    for filter in filters {
        let sampler = FilterSampler::new(filter.clone());
        assert!(sampler.is_signed(), "{}", filter.describe());
        let r = filter.radius();
        // The 1-D integrals by a fine midpoint rule.
        let integral = |axis: usize, f: &dyn Fn(f64) -> f64| -> f64 {
            let n = 20_000;
            let r = r[axis] as f64;
            let h = 2.0 * r / n as f64;
            (0..n)
                .map(|k| {
                    let x = -r + (k as f64 + 0.5) * h;
                    filter.profile(axis, x as f32) * f(x) * h
                })
                .sum()
        };
        const N: usize = 400_000;
        const CELLS: usize = 40;
        let mut rng = Rng::new(&[23]);
        let mut observed = [vec![0u64; CELLS], vec![0u64; CELLS]];
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        let mut negative = 0usize;
        let ratio = [0, 1].map(|a| {
            integral(a, &|_| 1.0).recip() * {
                let n = 20_000;
                let ra = r[a] as f64;
                let h = 2.0 * ra / n as f64;
                (0..n)
                    .map(|k| filter.profile(a, (-ra + (k as f64 + 0.5) * h) as f32).abs() * h)
                    .sum::<f64>()
            }
        });
        for _ in 0..N {
            let s = sampler.sample(4, 6, rng.next_2d());
            let d = s.film - Vec2::new(4.5, 6.5);
            assert!(d.x.abs() <= r.x && d.y.abs() <= r.y, "{d}");
            assert!(
                ((s.weight.abs() as f64) - ratio[0] * ratio[1]).abs() < 1e-3 * ratio[0] * ratio[1],
                "{}: weight {} against {}",
                filter.describe(),
                s.weight,
                ratio[0] * ratio[1]
            );
            negative += (s.weight < 0.0) as usize;
            for axis in 0..2 {
                let cell = (((d[axis] + r[axis]) / (2.0 * r[axis])) * CELLS as f32) as usize;
                observed[axis][cell.min(CELLS - 1)] += 1;
            }
            let v = s.weight as f64 * g(d);
            sum += v;
            sum2 += v * v;
        }
        assert!(
            negative > N / 100,
            "{}: {negative} negative weights",
            filter.describe()
        );
        for axis in 0..2 {
            let ra = r[axis] as f64;
            let edge = |i: usize| -ra + 2.0 * ra * i as f64 / CELLS as f64;
            let mass: Vec<f64> = (0..CELLS)
                .map(|i| {
                    let (a, b) = (edge(i), edge(i + 1));
                    let m = 200;
                    (0..m)
                        .map(|k| {
                            let x = a + (b - a) * (k as f64 + 0.5) / m as f64;
                            filter.profile(axis, x as f32).abs() * (b - a) / m as f64
                        })
                        .sum()
                })
                .collect();
            let total: f64 = mass.iter().sum();
            let expected: Vec<f64> = mass.iter().map(|m| m / total * N as f64).collect();
            assert_gof(
                &format!("{} axis {axis}", filter.describe()),
                &observed[axis],
                &expected,
                1e-4,
            );
        }
        let mean = sum / N as f64;
        let se = ((sum2 / N as f64 - mean * mean) / N as f64).sqrt();
        let want = integral(0, &|x| (0.6 * x).exp()) / integral(0, &|_| 1.0)
            * (integral(1, &|y| 1.0 + 0.3 * y + 0.2 * y * y) / integral(1, &|_| 1.0));
        assert!(
            (mean - want).abs() < 4.0 * se,
            "{}: mean of weight * g {mean} against {want} (standard error {se})",
            filter.describe()
        );
    }
}

/// An emitter covering the right part of the view (radiance 1, its left edge at film x = e)
/// rendered by `path` at 2048 samples: the pixel at column i sees the fraction of the filter's
/// mass centred on i + 0.5 that lies right of the edge, within 0.04 (the sampling noise of a
/// fraction is at most 0.011 at 2048 samples).
#[test]
fn an_edge_is_seen_through_the_filter() {
    for (spec, filter) in [
        ("\"box\"", Filter::Box),
        ("{ type = \"tent\", radius = 1.5 }", Filter::tent(1.5)),
        (
            "{ type = \"gaussian\", stddev = 0.6 }",
            Filter::gaussian(0.6),
        ),
        ("\"mitchell\"", Filter::mitchell(1.0 / 3.0, 1.0 / 3.0)),
        ("{ type = \"lanczos\", lobes = 2 }", Filter::lanczos(2)),
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
        let r = filter.radius().x as f64;
        // The fraction of the filter's mass right of the edge, by a fine Riemann sum.
        let beyond = |centre: f64| {
            let n = 4000;
            let (mut right, mut all) = (0.0, 0.0);
            for k in 0..n {
                let x = -r + 2.0 * r * (k as f64 + 0.5) / n as f64;
                let w = filter.profile(0, x as f32);
                all += w;
                if centre + x > e {
                    right += w;
                }
            }
            right / all
        };
        let mut columns = Vec::new();
        for i in 0..16u32 {
            let want = beyond(i as f64 + 0.5);
            let got = film.pixel(i, 2).x as f64;
            assert!(
                (got - want).abs() < 0.04,
                "{}: column {i} (edge at {e:.3}): {got} against {want}",
                filter.describe()
            );
            columns.push((want, got));
        }
        // A filter with negative lobes rings: a pixel on the dark side of the edge comes out
        // below black (expected to by more than 0.01, some three standard errors of the
        // render there: its samples rarely reach the emitter). The bright side's overshoot
        // (about 0.01 for mitchell) is within the noise of samples that all carry weights of
        // either sign, so it is only printed.
        if FilterSampler::new(filter.clone()).is_signed() {
            let darkest = columns.iter().min_by(|a, b| a.0.total_cmp(&b.0)).unwrap();
            let brightest = columns.iter().max_by(|a, b| a.0.total_cmp(&b.0)).unwrap();
            eprintln!(
                "{}: darkest (expected, rendered) {darkest:?}, brightest {brightest:?}",
                filter.describe()
            );
            assert!(
                darkest.0 < -0.01 && darkest.1 < 0.0,
                "{}: {darkest:?}",
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

/// `[film] filter` in TOML: each name with its defaults, each table with its parameters (one
/// radius or two), and the values that cannot filter refused with the key named.
#[test]
fn toml_filters_are_read_with_their_parameters() {
    let load = |spec: &str| -> Result<Filter, String> {
        let mut s = header("path", 1, 1, 4, 4);
        s += &format!("filter = {spec}\n");
        s += "[camera]\nposition = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nfov = 40.0\n";
        let dir = temp_dir("filter-toml");
        let path = write(&dir, "scene.toml", &s);
        let out = foton_loader::load(&path, &[])
            .map(|scene| scene.film().filter.filter().clone())
            .map_err(|e| e.to_string());
        let _ = std::fs::remove_dir_all(dir);
        out
    };
    let third = 1.0f32 / 3.0;
    for (spec, want) in [
        ("\"mitchell\"", Filter::mitchell(third, third)),
        ("\"catmullrom\"", Filter::catmull_rom()),
        ("\"lanczos\"", Filter::lanczos(3)),
        (
            "\"sinc\"",
            Filter::Sinc {
                radius: Vec2::splat(4.0),
                tau: 3.0,
            },
        ),
        ("{ type = \"tent\", radius = 1.5 }", Filter::tent(1.5)),
        (
            "{ type = \"tent\", radius = [2.0, 1.0] }",
            Filter::Tent {
                radius: Vec2::new(2.0, 1.0),
            },
        ),
        (
            "{ type = \"gaussian\", stddev = 0.6 }",
            Filter::gaussian(0.6),
        ),
        (
            "{ type = \"gaussian\", stddev = 0.5, radius = 1.5 }",
            Filter::Gaussian {
                stddev: 0.5,
                radius: Vec2::splat(1.5),
            },
        ),
        (
            "{ type = \"mitchell\", b = 0.0, c = 0.5, radius = [3.0, 2.0] }",
            Filter::Mitchell {
                b: 0.0,
                c: 0.5,
                radius: Vec2::new(3.0, 2.0),
            },
        ),
        (
            "{ type = \"catmullrom\", radius = 4 }",
            Filter::Mitchell {
                b: 0.0,
                c: 0.5,
                radius: Vec2::splat(4.0),
            },
        ),
        ("{ type = \"lanczos\", lobes = 2 }", Filter::lanczos(2)),
        (
            "{ type = \"sinc\", radius = [4.0, 2.0], tau = 2.5 }",
            Filter::Sinc {
                radius: Vec2::new(4.0, 2.0),
                tau: 2.5,
            },
        ),
    ] {
        let got = load(spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
        assert_eq!(got, want, "{spec}");
    }
    for (spec, needle) in [
        ("\"bogus\"", "unknown filter"),
        ("{ type = \"lanczos\", lobes = 0 }", "lobes"),
        ("{ type = \"sinc\", radius = [4.0, -1.0] }", "radius"),
        ("{ type = \"sinc\", radius = [4.0, 2.0, 1.0] }", "radius"),
        ("{ type = \"sinc\", tau = 0.0 }", "tau"),
    ] {
        let e = load(spec).unwrap_err();
        assert!(e.contains(needle), "{spec}: {e}");
    }
}
