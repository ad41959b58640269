//! Statistical tests of the lights' sampling against their pdfs (area lights' incident
//! directions and emission, point lights, the environment map), with the machinery of
//! sampling.rs.

use crate::sampling::{
    Frame, Polar, SphereGrid, assert_gof, check_directions, cone_edges, d, rgb_close, uniform_edges,
};
use foton_core::Rgb;
use foton_core::envmap::EnvironmentMap;
use foton_core::geometry::Shape;
use foton_core::light::{EnvmapLight, Light, PointLight, SceneSphere, area_light};
use foton_core::sampling::Rng;
use foton_core::texture::Bitmap;
use foton_tests::stats::{assert_close, assert_rel};
use glam::{DVec3, Mat3, Vec3};
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

// ---------------------------------------------------------------------------------------------
// Lights
// ---------------------------------------------------------------------------------------------

/// Nearest intersection of the ray x + t w (t > 0) with `shape`: (t, point, unit normal with the
/// shape's own orientation), computed here in f64.
fn hit(shape: &Shape, x: DVec3, w: DVec3) -> Option<(f64, DVec3, DVec3)> {
    let plane = |o: DVec3, a: DVec3, b: DVec3| {
        let n = a.cross(b);
        let denom = n.dot(w);
        if denom == 0.0 {
            return None;
        }
        let t = n.dot(o - x) / denom;
        if t <= 0.0 {
            return None;
        }
        let q = x + w * t - o;
        let nn = n.dot(n);
        Some((
            t,
            q.cross(b).dot(n) / nn,
            a.cross(q).dot(n) / nn,
            n.normalize(),
        ))
    };
    match *shape {
        Shape::Sphere { center, radius, .. } => {
            let (c, r) = (d(center), radius as f64);
            let f = x - c;
            let b = f.dot(w);
            let disc = b * b - (f.dot(f) - r * r);
            if disc < 0.0 {
                return None;
            }
            let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
            let t = if t0 > 0.0 {
                t0
            } else if t1 > 0.0 {
                t1
            } else {
                return None;
            };
            let p = x + w * t;
            Some((t, p, (p - c) / r))
        }
        Shape::Quad { origin, u, v, .. } => {
            let (t, a, b, n) = plane(d(origin), d(u), d(v))?;
            ((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)).then(|| (t, x + w * t, n))
        }
        Shape::Triangle { p0, e1, e2 } => {
            let (t, a, b, n) = plane(d(p0), d(e1), d(e2))?;
            (a >= 0.0 && b >= 0.0 && a + b <= 1.0).then(|| (t, x + w * t, n))
        }
        Shape::Disk {
            center,
            u,
            v,
            normal,
            ..
        } => {
            let (t, a, b, _) = plane(d(center), d(u), d(v))?;
            (a * a + b * b <= 1.0).then(|| (t, x + w * t, d(normal)))
        }
        Shape::Curve { .. } => unreachable!("a curve is never a light"),
    }
}

/// Area of a shape, computed here.
fn shape_area(shape: &Shape) -> f64 {
    match *shape {
        Shape::Sphere { radius, .. } => 4.0 * PI * (radius as f64).powi(2),
        Shape::Quad { u, v, .. } => d(u).cross(d(v)).length(),
        Shape::Triangle { e1, e2, .. } => 0.5 * d(e1).cross(d(e2)).length(),
        Shape::Disk { u, v, .. } => PI * d(u).cross(d(v)).length(),
        Shape::Curve { .. } => unreachable!("a curve is never a light"),
    }
}

/// The shape's own normal at `p` if `p` lies on it (within `tol`), else None.
fn on_shape(shape: &Shape, p: DVec3, tol: f64) -> Option<DVec3> {
    let plane = |o: DVec3, a: DVec3, b: DVec3| {
        let n = a.cross(b);
        let q = p - o;
        let nn = n.dot(n);
        let dist = q.dot(n) / nn.sqrt();
        (dist.abs() <= tol).then(|| {
            (
                q.cross(b).dot(n) / nn,
                a.cross(q).dot(n) / nn,
                n.normalize(),
            )
        })
    };
    match *shape {
        Shape::Sphere { center, radius, .. } => {
            let r = p - d(center);
            ((r.length() - radius as f64).abs() <= tol).then(|| r.normalize())
        }
        Shape::Quad { origin, u, v, .. } => {
            let (a, b, n) = plane(d(origin), d(u), d(v))?;
            (a >= -tol && a <= 1.0 + tol && b >= -tol && b <= 1.0 + tol).then_some(n)
        }
        Shape::Triangle { p0, e1, e2 } => {
            let (a, b, n) = plane(d(p0), d(e1), d(e2))?;
            (a >= -tol && b >= -tol && a + b <= 1.0 + tol).then_some(n)
        }
        Shape::Disk {
            center,
            u,
            v,
            normal,
            ..
        } => {
            let (a, b, _) = plane(d(center), d(u), d(v))?;
            (a * a + b * b <= 1.0 + tol).then_some(d(normal))
        }
        Shape::Curve { .. } => unreachable!("a curve is never a light"),
    }
}

/// Solid-angle density of `light.sample_li(x, ..)` returning a sample in direction w: the sum
/// of `pdf_li` at the points of the shapes along w (sample_li does not test occlusion), only
/// those facing x unless `back_too` (sample_li returns None for the others).
fn li_density(light: &Light, shapes: &[Shape], x: DVec3, w: DVec3, back_too: bool) -> f64 {
    shapes
        .iter()
        .filter_map(|s| hit(s, x, w))
        .filter(|&(_, _, n)| back_too || n.dot(-w) > 0.0)
        .map(|(_, p, n)| light.pdf_li(x.as_vec3(), p.as_vec3(), n.as_vec3()) as f64)
        .sum()
}

/// A grid around the direction from x to the mean of `points`, wide enough for all of them.
fn grid_towards(x: DVec3, points: &[DVec3]) -> SphereGrid {
    let axis = (points.iter().copied().sum::<DVec3>() / points.len() as f64 - x).normalize();
    let cos_min = points
        .iter()
        .map(|&p| (p - x).normalize().dot(axis))
        .fold(1.0f64, f64::min);
    let lo = cos_min - 0.1 * (1.0 - cos_min);
    SphereGrid::new(axis, Polar::Cos, uniform_edges(lo, 1.0, 10), 20)
}

fn vertices(shape: &Shape) -> Vec<DVec3> {
    match *shape {
        Shape::Quad { origin, u, v, .. } => {
            let (o, u, v) = (d(origin), d(u), d(v));
            vec![o, o + u, o + v, o + u + v]
        }
        Shape::Triangle { p0, e1, e2 } => vec![d(p0), d(p0 + e1), d(p0 + e2)],
        Shape::Disk { center, u, v, .. } => {
            let (c, u, v) = (d(center), d(u), d(v));
            vec![c + u, c - u, c + v, c - v]
        }
        Shape::Sphere { .. } | Shape::Curve { .. } => unreachable!(),
    }
}

/// Draws `n` light samples from x, checks each against the geometry (the point lies on the
/// light, along wi, at dist, facing x, with the radiance, pdf = pdf_li = `point_pdf`, the
/// density computed here) and tests their directions against pdf_li by chi-square.
/// Returns the integral of the sampled density over the grid.
#[allow(clippy::too_many_arguments)]
fn check_sample_li(
    name: &str,
    light: &Light,
    shapes: &[Shape],
    radiance: Rgb,
    x: Vec3,
    grid: &SphereGrid,
    p_none: f64,
    seed: u64,
    point_pdf: &dyn Fn(DVec3, DVec3) -> f64,
) -> f64 {
    let x64 = d(x);
    let mut rng = Rng::new(&[seed]);
    let mut grazing = 0usize;
    const N: usize = 1_000_000;
    let pdf = |w: DVec3| li_density(light, shapes, x64, w, false);
    let integral = check_directions(name, grid, N, p_none, &pdf, &mut || {
        let ls = light.sample_li(x, rng.next_2d(), rng.next_f32())?;
        let (wi, p) = (d(ls.wi), d(ls.p));
        assert!(!ls.delta);
        assert_close("|wi|", wi.length(), 1.0, 1e-5);
        let dist = (p - x64).length();
        assert_rel("dist", ls.dist as f64, dist, 1e-4);
        assert!(
            (x64 + wi * dist - p).length() < 1e-4 * (1.0 + dist),
            "{name}: p is not along wi"
        );
        let n = shapes
            .iter()
            .find_map(|s| on_shape(s, p, 1e-4))
            .unwrap_or_else(|| panic!("{name}: sampled point {p} is not on the light"));
        assert!(
            (d(ls.n) - n).length() < 1e-4,
            "{name}: normal {} is not {n}",
            ls.n
        );
        let cos_l = n.dot(-wi);
        if cos_l < 1e-3 {
            // Rounding may turn a silhouette point of a sphere away from x.
            grazing += 1;
            assert!(
                cos_l > -1e-3,
                "{name}: sampled a point facing away, cos = {cos_l}"
            );
        } else {
            assert_eq!(ls.li, radiance, "{name}: li");
        }
        let pdf_li = light.pdf_li(x, ls.p, ls.n) as f64;
        assert_rel(
            &format!("{name}: sample pdf vs pdf_li"),
            ls.pdf as f64,
            pdf_li,
            1e-4,
        );
        assert_rel(
            &format!("{name}: pdf_li vs independent pdf"),
            pdf_li,
            point_pdf(p, n),
            1e-3,
        );
        Some(wi)
    });
    assert!(grazing < N / 10_000, "{name}: {grazing} grazing samples");
    integral
}

fn quad_light() -> (Light, Vec<Shape>, Rgb) {
    let quad = Shape::quad(
        Vec3::new(-0.5, 2.0, -0.3),
        Vec3::new(1.2, 0.1, 0.0),
        Vec3::new(0.0, 0.2, 0.8),
    );
    let radiance = Rgb::new(3.0, 2.0, 1.0);
    (area_light(vec![quad], radiance, 0), vec![quad], radiance)
}

fn sphere_light() -> (Light, Vec<Shape>, Rgb) {
    let sphere = Shape::sphere(Vec3::new(0.3, -0.2, 2.5), 0.6);
    let radiance = Rgb::new(1.0, 4.0, 2.0);
    (
        area_light(vec![sphere], radiance, 1),
        vec![sphere],
        radiance,
    )
}

/// Three triangles of different areas: two facing the origin (overlapping as seen from it),
/// one facing away.
fn triangle_light() -> (Light, Vec<Shape>, Rgb) {
    let tris = vec![
        Shape::Triangle {
            p0: Vec3::new(-0.5, -0.4, 2.0),
            e1: Vec3::new(0.0, 1.0, 0.1),
            e2: Vec3::new(0.9, 0.0, 0.2),
        },
        Shape::Triangle {
            p0: Vec3::new(0.0, 0.0, 2.6),
            e1: Vec3::new(0.0, 0.7, -0.3),
            e2: Vec3::new(1.0, 0.2, 0.0),
        },
        Shape::Triangle {
            p0: Vec3::new(-0.8, 0.3, 2.2),
            e1: Vec3::new(0.6, 0.0, 0.0),
            e2: Vec3::new(0.0, 0.5, 0.1),
        },
    ];
    let radiance = Rgb::new(0.5, 1.5, 2.5);
    (area_light(tris.clone(), radiance, 2), tris, radiance)
}

/// d^2 / (|cos| A): the solid-angle density of a point chosen uniformly by area.
fn area_to_solid_angle(x: DVec3, p: DVec3, n: DVec3, area: f64) -> f64 {
    let v = p - x;
    v.length_squared() / (n.dot(v.normalize()).abs() * area)
}

#[test]
fn quad_light_sample_li_matches_pdf_li() {
    let (light, shapes, radiance) = quad_light();
    let x = Vec3::new(0.1, 0.3, 0.2);
    let area = shape_area(&shapes[0]);
    let grid = grid_towards(d(x), &vertices(&shapes[0]));
    let integral = check_sample_li(
        "quad light sample_li",
        &light,
        &shapes,
        radiance,
        x,
        &grid,
        0.0,
        30,
        &|p, n| area_to_solid_angle(d(x), p, n, area),
    );
    assert_close("integral of pdf_li over the quad", integral, 1.0, 1e-3);
}

#[test]
fn sphere_light_seen_from_outside_samples_its_cone() {
    let (light, shapes, radiance) = sphere_light();
    let Shape::Sphere { center, radius, .. } = shapes[0] else {
        unreachable!()
    };
    let x = Vec3::new(0.0, 0.1, 0.0);
    let (c, r) = (d(center), radius as f64);
    let dist2 = (c - d(x)).length_squared();
    let cos_max = (1.0 - r * r / dist2).sqrt();
    let cone_pdf = 1.0 / (TAU * (1.0 - cos_max));
    let grid = SphereGrid::new(c - d(x), Polar::Cos, cone_edges(cos_max, 10), 20);
    let integral = check_sample_li(
        "sphere light (outside) sample_li",
        &light,
        &shapes,
        radiance,
        x,
        &grid,
        0.0,
        31,
        &|_, _| cone_pdf,
    );
    assert_close("integral of pdf_li over the cone", integral, 1.0, 1e-3);
}

#[test]
fn sphere_light_seen_from_inside_is_dark_and_its_pdf_li_normalised() {
    // Emission is one-sided (outward), so from inside the light sends nothing: sample_li must
    // return no sample or one of zero radiance, consistently with `emitted`.
    let (light, shapes, _) = sphere_light();
    let Shape::Sphere { center, .. } = shapes[0] else {
        unreachable!()
    };
    let x = center + Vec3::new(0.1, 0.2, -0.15);
    let mut rng = Rng::new(&[32]);
    for _ in 0..100_000 {
        if let Some(ls) = light.sample_li(x, rng.next_2d(), rng.next_f32()) {
            assert_eq!(ls.li, Rgb::ZERO, "light from inside a one-sided sphere");
            assert_eq!(light.emitted(ls.n, glam::Vec2::ZERO, -ls.wi), Rgb::ZERO);
        }
    }
    // pdf_li (the area density converted to solid angle) still integrates to one over the
    // sphere of directions.
    let grid = SphereGrid::full_sphere(DVec3::new(0.2, 0.9, -0.3), 10, 20);
    let integral: f64 = grid
        .probabilities(&|w| li_density(&light, &shapes, d(x), w, true))
        .iter()
        .sum();
    assert_close("integral of pdf_li from inside", integral, 1.0, 1e-3);
}

#[test]
fn triangle_light_sample_li_matches_pdf_li() {
    let (light, shapes, radiance) = triangle_light();
    let x = Vec3::ZERO;
    let areas: Vec<f64> = shapes.iter().map(shape_area).collect();
    let total: f64 = areas.iter().sum();
    let facing: Vec<bool> = shapes
        .iter()
        .map(|s| {
            let v = vertices(s);
            let n = on_shape(s, v[0], 1e-9).unwrap();
            n.dot(d(x) - v[0]) > 0.0
        })
        .collect();
    assert_eq!(facing, [true, true, false], "test geometry");
    let front: Vec<DVec3> = shapes
        .iter()
        .zip(&facing)
        .filter(|&(_, &f)| f)
        .flat_map(|(s, _)| vertices(s))
        .collect();
    let p_none = areas[2] / total;
    let grid = grid_towards(d(x), &front);
    let integral = check_sample_li(
        "triangle light sample_li",
        &light,
        &shapes,
        radiance,
        x,
        &grid,
        p_none,
        33,
        &|p, n| area_to_solid_angle(d(x), p, n, total),
    );
    assert_close(
        "integral over the facing triangles",
        integral,
        1.0 - p_none,
        1e-3,
    );
    // Over all three triangles, pdf_li integrates to one.
    let all: Vec<DVec3> = shapes.iter().flat_map(vertices).collect();
    let grid = grid_towards(d(x), &all);
    let integral: f64 = grid
        .probabilities(&|w| li_density(&light, &shapes, d(x), w, true))
        .iter()
        .sum();
    assert_close("integral of pdf_li over all triangles", integral, 1.0, 1e-3);
}

/// Tests `sample_emission` of an area light: flux = power = pi A L, the normal is the shape's,
/// the direction is cosine-distributed about it (whole sphere, so backward emission would land
/// in empty cells). `position_cell` bins the origin (None: not on the light); `position_exp`
/// gives the expected counts of those cells.
fn check_area_emission(
    name: &str,
    light: &Light,
    shapes: &[Shape],
    radiance: Rgb,
    seed: u64,
    position_cell: &dyn Fn(DVec3, DVec3) -> Option<usize>,
    position_exp: &[f64],
) {
    const N: usize = 1_000_000;
    let area: f64 = shapes.iter().map(shape_area).sum();
    let power = light.power();
    assert!(
        rgb_close(power, (PI * area) as f32 * radiance, 1e-5),
        "{name}: power {power} is not pi A L = {}",
        (PI * area) as f32 * radiance
    );
    let mut rng = Rng::new(&[seed]);
    let mut pos_obs = vec![0u64; position_exp.len()];
    let grid = SphereGrid::full_sphere(DVec3::Z, 10, 20);
    let pdf = |w: DVec3| w.z.max(0.0) / PI;
    check_directions(
        &format!("{name}: emitted directions"),
        &grid,
        N,
        0.0,
        &pdf,
        &mut || {
            let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
            assert_eq!(e.flux, power, "{name}: flux");
            let o = d(e.origin);
            let n = shapes
                .iter()
                .filter_map(|s| on_shape(s, o, 1e-4))
                .find(|&n| (n - d(e.n)).length() < 1e-4)
                .unwrap_or_else(|| {
                    panic!("{name}: origin {o} with normal {} is not on the light", e.n)
                });
            let cell =
                position_cell(o, n).unwrap_or_else(|| panic!("{name}: origin {o} not binned"));
            pos_obs[cell] += 1;
            assert_close("|dir|", e.dir.length() as f64, 1.0, 1e-5);
            Some(Frame::new(n).to_local(d(e.dir)))
        },
    );
    let exp: Vec<f64> = position_exp.iter().map(|p| p * N as f64).collect();
    assert_gof(&format!("{name}: emission positions"), &pos_obs, &exp);
}

#[test]
fn quad_light_emission() {
    let (light, shapes, radiance) = quad_light();
    let Shape::Quad { origin, u, v, .. } = shapes[0] else {
        unreachable!()
    };
    const G: usize = 10;
    let (o, u, v) = (d(origin), d(u), d(v));
    let nrm = u.cross(v);
    let cell = |p: DVec3, _: DVec3| {
        let q = p - o;
        let s = q.cross(v).dot(nrm) / nrm.dot(nrm);
        let t = u.cross(q).dot(nrm) / nrm.dot(nrm);
        let idx = |a: f64| ((a * G as f64).max(0.0) as usize).min(G - 1);
        Some(idx(s) * G + idx(t))
    };
    check_area_emission(
        "quad light",
        &light,
        &shapes,
        radiance,
        40,
        &cell,
        &[1.0 / (G * G) as f64; G * G],
    );
}

#[test]
fn sphere_light_emission() {
    let (light, shapes, radiance) = sphere_light();
    let grid = SphereGrid::full_sphere(DVec3::new(0.5, 0.5, -0.7), 10, 20);
    let exp = vec![1.0 / grid.len() as f64; grid.len()];
    check_area_emission(
        "sphere light",
        &light,
        &shapes,
        radiance,
        41,
        &|_, n| grid.cell(n),
        &exp,
    );
}

#[test]
fn triangle_light_emission() {
    let (light, shapes, radiance) = triangle_light();
    // Per triangle, (b1, b2) binned as in uniform_triangle (exact expected counts).
    const G: usize = 5;
    let areas: Vec<f64> = shapes.iter().map(shape_area).collect();
    let total: f64 = areas.iter().sum();
    let mut exp = Vec::new();
    for a in &areas {
        for i in 0..G {
            for j in 0..G {
                let frac = match (i + j).cmp(&(G - 1)) {
                    std::cmp::Ordering::Less => 2.0,
                    std::cmp::Ordering::Equal => 1.0,
                    std::cmp::Ordering::Greater => 0.0,
                } / (G * G) as f64;
                exp.push(a / total * frac);
            }
        }
    }
    let cell = |p: DVec3, n: DVec3| {
        shapes.iter().enumerate().find_map(|(k, s)| {
            let Shape::Triangle { p0, e1, e2 } = *s else {
                unreachable!()
            };
            let (e1, e2) = (d(e1), d(e2));
            let m = e1.cross(e2);
            if (m.normalize() - n).length() > 1e-6 {
                return None;
            }
            let q = p - d(p0);
            let b1 = q.cross(e2).dot(m) / m.dot(m);
            let b2 = e1.cross(q).dot(m) / m.dot(m);
            let idx = |a: f64| ((a * G as f64).max(0.0) as usize).min(G - 1);
            Some(k * G * G + idx(b1) * G + idx(b2))
        })
    };
    check_area_emission("triangle light", &light, &shapes, radiance, 42, &cell, &exp);
}

#[test]
fn point_light_emission_is_uniform_with_its_power() {
    let position = Vec3::new(0.4, -1.0, 2.0);
    let intensity = Rgb::new(2.0, 1.0, 0.5);
    let light = Light::Point(PointLight {
        position,
        intensity,
    });
    let power = light.power();
    assert!(rgb_close(power, (4.0 * PI) as f32 * intensity, 1e-6));
    let grid = SphereGrid::full_sphere(DVec3::new(-0.3, 0.2, 0.9), 10, 20);
    let mut rng = Rng::new(&[43]);
    let pdf = |_: DVec3| 1.0 / (4.0 * PI);
    check_directions(
        "point light emission",
        &grid,
        1_000_000,
        0.0,
        &pdf,
        &mut || {
            let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
            assert_eq!(e.origin, position);
            assert_eq!(e.n, Vec3::ZERO);
            assert_eq!(e.flux, power);
            assert_close("|dir|", e.dir.length() as f64, 1.0, 1e-5);
            Some(d(e.dir))
        },
    );
}

// ---------------------------------------------------------------------------------------------
// The environment map
// ---------------------------------------------------------------------------------------------

/// A 16 x 8 map, turned away from the axes: a dim sky, a brighter ground with a red column
/// and a small bright sun (a texel and its neighbour).
fn envmap_light() -> (Light, Mat3) {
    let (w, h) = (16, 8);
    let mut texels = Vec::with_capacity(w * h);
    for j in 0..h {
        for i in 0..w {
            texels.push(if i == 3 {
                Rgb::new(1.5, 0.0, 0.0)
            } else if j < h / 2 {
                Rgb::new(0.2, 0.3, 0.6)
            } else {
                Rgb::new(0.5, 0.4, 0.3)
            });
        }
    }
    texels[2 * w + 9] = Rgb::new(300.0, 250.0, 200.0);
    texels[2 * w + 10] = Rgb::new(100.0, 80.0, 60.0);
    let to_world = Mat3::from_axis_angle(Vec3::new(1.0, 0.5, -0.3).normalize(), 0.7);
    let bitmap = Bitmap::new(w, h, texels).unwrap();
    let map = EnvironmentMap::new(&bitmap, 1.5, to_world).unwrap();
    let light = Light::Envmap(EnvmapLight {
        map: Arc::new(map),
        sphere: SceneSphere {
            centre: Vec3::new(0.1, 0.2, 0.3),
            radius: 2.0,
        },
    });
    (light, to_world)
}

/// A grid in theta about the map's pole, whose sin(theta) cancels the 1/sin(theta) of the
/// map's density.
fn envmap_grid(to_world: Mat3) -> SphereGrid {
    SphereGrid::new(
        d(to_world * Vec3::Y),
        Polar::Theta,
        uniform_edges(0.0, PI, 16),
        32,
    )
}

#[test]
fn envmap_sample_li_matches_pdf_li() {
    let (light, to_world) = envmap_light();
    let x = Vec3::new(0.3, -0.2, 0.5);
    let pdf = |w: DVec3| light.pdf_li(x, x + w.as_vec3(), Vec3::ZERO) as f64;
    let mut rng = Rng::new(&[51]);
    let n = 1_000_000;
    // The density is piecewise constant: a direction within rounding of a cell's edge (x + wi
    // - x is not quite wi) may find the neighbour's.
    let mut mismatches = 0;
    let integral = check_directions(
        "envmap sample_li",
        &envmap_grid(to_world),
        n,
        0.0,
        &pdf,
        &mut || {
            let ls = light.sample_li(x, rng.next_2d(), rng.next_f32())?;
            assert!(!ls.delta);
            if ((ls.pdf as f64 - pdf(d(ls.wi))) / pdf(d(ls.wi))).abs() > 1e-3 {
                mismatches += 1;
            }
            let le = light.environment(ls.wi);
            assert!(rgb_close(ls.li, le, 1e-3), "{} against {le}", ls.li);
            assert!(ls.dist > 0.0 && (ls.p - (x + ls.wi * ls.dist)).length() < 1e-3);
            Some(d(ls.wi))
        },
    );
    assert_close("integral of the envmap's pdf_li", integral, 1.0, 2e-3);
    assert!(
        mismatches <= n / 10_000,
        "{mismatches} samples whose pdf is not pdf_li's"
    );
}

#[test]
fn envmap_emission_follows_its_pdf_with_its_power() {
    let (light, to_world) = envmap_light();
    let Light::Envmap(EnvmapLight {
        sphere: SceneSphere { centre, radius },
        ..
    }) = light
    else {
        unreachable!()
    };
    let pdf = |w: DVec3| light.pdf_li(Vec3::ZERO, -w.as_vec3(), Vec3::ZERO) as f64;
    let mut rng = Rng::new(&[52]);
    let n = 1_000_000;
    let mut flux = DVec3::ZERO;
    let mut flux2 = DVec3::ZERO;
    check_directions(
        "envmap emission directions",
        &envmap_grid(to_world),
        n,
        0.0,
        &pdf,
        &mut || {
            let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
            // From the disc of the bounding sphere facing the photon's direction, outside it.
            let o = e.origin - centre;
            assert_close(
                "origin behind the centre",
                o.dot(e.dir) as f64,
                -radius as f64,
                1e-4,
            );
            assert!((o - o.dot(e.dir) * e.dir).length() <= radius * 1.0001);
            flux += e.flux.as_dvec3();
            flux2 += (e.flux * e.flux).as_dvec3();
            Some(d(e.dir))
        },
    );
    // The mean flux is the power, within 4 standard errors.
    let mean = flux / n as f64;
    let se = ((flux2 / n as f64 - mean * mean) / n as f64)
        .max(DVec3::ZERO)
        .sqrt();
    let power = light.power().as_dvec3();
    for c in 0..3 {
        assert!(
            (mean[c] - power[c]).abs() < 4.0 * se[c] + 1e-6 * power[c],
            "mean flux {mean} against power {power} (se {se})"
        );
    }
}
