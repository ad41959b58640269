//! Signed distance grids (Mitsuba 3's `sdfgrid`, foton's `sdfgrid` shape): the zero set of the
//! trilinear interpolant of a `.vol` grid whose samples sit on the corners of the unit cube,
//! placed by the transform; seen from outside, a convex one in a constant environment shows
//! rho L; texture coordinates are (0, 0) everywhere, as Mitsuba's; bad grids are reported.

use foton_core::geometry::Ray;
use foton_tests::{header, region_mean, render_toml, temp_dir, write};
use glam::{Vec2, Vec3};
use std::path::Path;

/// A Mitsuba `.vol` file (version 3, float32) of `n`^3 samples of `f` at the unit cube's
/// lattice corners (i / (n - 1)), x fastest, `channels` copies of each value.
fn vol(path: &Path, n: usize, channels: usize, f: impl Fn(Vec3) -> f32) {
    let mut bytes = b"VOL\x03".to_vec();
    for x in [1i32, n as i32, n as i32, n as i32, channels as i32] {
        bytes.extend(x.to_le_bytes());
    }
    for b in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        bytes.extend(b.to_le_bytes());
    }
    let step = 1.0 / (n - 1) as f32;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let v = f(Vec3::new(i as f32, j as f32, k as f32) * step);
                for _ in 0..channels {
                    bytes.extend(v.to_le_bytes());
                }
            }
        }
    }
    std::fs::write(path, bytes).unwrap();
}

/// A ball of radius 0.3 at the cube's centre.
fn ball(p: Vec3) -> f32 {
    (p - Vec3::splat(0.5)).length() - 0.3
}

/// The trilinear interpolant of `f` sampled on an `n`^3 lattice of the unit cube, at `p`.
fn trilinear(n: usize, f: impl Fn(Vec3) -> f32, p: Vec3) -> f32 {
    let q = p * (n - 1) as f32;
    let i = q.floor().clamp(Vec3::ZERO, Vec3::splat((n - 2) as f32));
    let t = q - i;
    let mut sum = 0.0;
    for corner in 0..8 {
        let o = Vec3::new(
            (corner & 1) as f32,
            (corner >> 1 & 1) as f32,
            (corner >> 2) as f32,
        );
        let w = (o * t + (Vec3::ONE - o) * (Vec3::ONE - t)).element_product();
        sum += w * f((i + o) / (n - 1) as f32);
    }
    sum
}

/// The ball, moved by a Mitsuba file's `to_world` (scale 2, then translate), seen by rays:
/// they meet the zero set of the grid's trilinear interpolant (within a hundredth of a cell
/// of it, written out here), about radius 0.6 around (1, 1, 2), with normals along the
/// radius, and texture coordinates (0, 0); rays from inside meet it too (Mitsuba's sdfgrid is
/// not culled).
#[test]
fn a_grid_ball_is_where_its_zero_set_is() {
    let dir = temp_dir("sdfgrid-ball");
    vol(&dir.join("ball.vol"), 24, 1, ball);
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="30"/></sensor>
    <shape type="shapegroup" id="group">
        <shape type="sdfgrid">
            <string name="filename" value="ball.vol"/>
            <string name="normals" value="analytic"/>
        </shape>
    </shape>
    <shape type="instance">
        <ref id="group"/>
        <transform name="to_world"><scale value="2"/><translate z="1"/></transform>
    </shape>
</scene>"#;
    let path = write(&dir, "scene.xml", xml);
    let scene = foton_loader::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    let centre = Vec3::new(1.0, 1.0, 2.0);
    let cell = 2.0 / 23.0;
    let mut seen = 0;
    for k in 0..50 {
        let a = k as f32 * 0.37;
        let dir = Vec3::new(a.cos() * (1.0 + 0.1 * k as f32).sin(), a.sin(), 0.8).normalize();
        let ray = Ray::new(centre + 3.0 * dir, -dir);
        let hit = scene
            .intersect(&ray, f32::INFINITY)
            .expect("the ball is there");
        let object = (hit.p - Vec3::Z) / 2.0;
        let f = trilinear(24, ball, object);
        // |grad f| is about 1 (a distance), in object units: a cell is 1 / 23.
        assert!(
            f.abs() < 0.01 / 23.0,
            "the field is {f} at the hit {}",
            hit.p
        );
        let r = hit.p.distance(centre);
        assert!((r - 0.6).abs() < 0.1 * cell, "radius {r}, not about 0.6");
        let s = scene.surface(&hit);
        let radial = (hit.p - centre).normalize();
        // `analytic`: the gradient of the interpolant of the cell the point is in.
        let h = 1e-4;
        let gradient =
            Vec3::from_array([Vec3::X, Vec3::Y, Vec3::Z].map(|e| {
                trilinear(24, ball, object + h * e) - trilinear(24, ball, object - h * e)
            }))
            .normalize();
        assert!(s.ns.dot(gradient) > 0.999, "{} against {gradient}", s.ns);
        assert!(s.ng.dot(radial) > 0.99, "{} against {radial}", s.ng);
        assert_eq!(s.uv, Vec2::ZERO);
        let inside = Ray::new(centre, dir);
        let out = scene
            .intersect(&inside, f32::INFINITY)
            .expect("seen from inside");
        assert!((out.t - 0.6).abs() < 0.1 * cell);
        let f = trilinear(24, ball, (out.p - Vec3::Z) / 2.0);
        assert!(f.abs() < 0.01 / 23.0, "the field is {f} at {}", out.p);
        seen += 1;
    }
    assert_eq!(seen, 50);
    let _ = std::fs::remove_dir_all(dir);
}

/// The ball in a constant environment of radiance 1, diffuse 0.6: it sees only the
/// environment, rho L = 0.6, from path and bdpt.
#[test]
fn a_grid_ball_in_a_constant_environment_shows_rho_l() {
    let dir = temp_dir("sdfgrid-furnace");
    let file = dir.join("ball.vol");
    vol(&file, 16, 1, ball);
    for integrator in ["path", "bdpt"] {
        let scene = header(integrator, 64, 64, 8, 8)
            + &format!(
                r#"
[camera]
position = [0.5, 0.5, 4]
look_at = [0.5, 0.5, 0.5]
fov = 2

[materials.grey]
type = "diffuse"
reflectance = [0.6, 0.6, 0.6]

[[lights]]
type = "constant"
radiance = [1, 1, 1]

[[shapes]]
type = "sdfgrid"
file = "{}"
material = "grey"
"#,
                file.display()
            );
        let film = render_toml("sdfgrid-furnace-scene", &scene, &[], 2);
        let (m, se) = region_mean(&film, 0, 0, 8, 8);
        assert!(
            (m - Vec3::splat(0.6)).abs().max_element() < 4.0 * se.max_element() + 0.01,
            "{integrator}: rho L = 0.6, found {m} +- {se}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A grid of three channels, one with no surface, a bad `normals`: errors naming the shape
/// and the file.
#[test]
fn bad_grids_are_reported() {
    let dir = temp_dir("sdfgrid-bad");
    vol(&dir.join("rgb.vol"), 4, 3, ball);
    vol(&dir.join("empty.vol"), 4, 1, |_| 1.0);
    let err = |file: &str, extra: &str| {
        let toml = format!(
            "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 30\n\n[materials.m]\ntype = \"diffuse\"\n\n[[shapes]]\ntype = \"sdfgrid\"\nfile = \"{file}\"\nmaterial = \"m\"\n{extra}"
        );
        let path = write(&dir, "scene.toml", &toml);
        match foton_loader::load(&path, &[]) {
            Ok(_) => panic!("loaded: {toml}"),
            Err(e) => e.to_string(),
        }
    };
    let e = err("rgb.vol", "");
    assert!(e.contains("rgb.vol") && e.contains("one channel"), "{e}");
    let e = err("empty.vol", "");
    assert!(e.contains("empty.vol") && e.contains("same sign"), "{e}");
    let e = err("rgb.vol", "normals = \"flat\"\n");
    assert!(e.contains("normals") && e.contains("smooth"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}
