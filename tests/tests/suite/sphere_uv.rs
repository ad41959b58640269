//! A sphere's texture coordinates run about its own axes, as each format's renderer has
//! them: pbrt-v4's u = phi / 2 pi about the sphere's object-space z, v = 1 - theta / pi (from
//! its -z pole); Mitsuba's u the same, v = theta / pi (from its +z pole); both under the
//! sphere's rotation (a shape's `axes` in TOML).

use foton_core::geometry::Ray;
use foton_tests::{temp_dir, write};
use glam::{Mat3, Vec2, Vec3};

/// The uv of the sphere hit by rays from `dir` towards the centre `c` (radius 1): each
/// against `want(local direction)`, with `rot` the sphere's rotation (local to world).
fn check(scene: &foton_core::scene::Scene, c: Vec3, rot: Mat3, want: impl Fn(Vec3) -> Vec2) {
    let mut checked = 0;
    for dir in [
        Vec3::new(0.3, 0.2, 1.0),
        Vec3::new(-0.5, 0.4, 1.0),
        Vec3::new(0.2, -0.6, 1.0),
        Vec3::new(-0.1, -0.1, 1.0),
    ] {
        let d = dir.normalize();
        let ray = Ray::new(c + 5.0 * d, -d);
        let hit = scene.intersect(&ray, f32::INFINITY).expect("a hit");
        let local = rot.transpose() * (hit.p - c).normalize();
        let (got, want) = (scene.surface(&hit).uv, want(local));
        // u wraps at the seam.
        let du = (got.x - want.x).abs().min(1.0 - (got.x - want.x).abs());
        assert!(
            du < 1e-3 && (got.y - want.y).abs() < 1e-3,
            "at local {local}: uv {got}, expected {want}"
        );
        checked += 1;
    }
    assert_eq!(checked, 4);
}

fn u_of(l: Vec3) -> f32 {
    let phi = l.y.atan2(l.x);
    (if phi < 0.0 {
        phi + std::f32::consts::TAU
    } else {
        phi
    }) / std::f32::consts::TAU
}

#[test]
fn sphere_texture_coordinates_follow_each_formats_convention() {
    let dir = temp_dir("sphere-uv");
    // Rotate 60 degrees about x, then 30 about y (local to world).
    let rot = Mat3::from_rotation_y(30f32.to_radians()) * Mat3::from_rotation_x(60f32.to_radians());
    let c = Vec3::new(0.0, 0.0, 0.0);
    let pbrt = write(
        &dir,
        "s.pbrt",
        r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
LightSource "point" "rgb I" [1 1 1]
AttributeBegin
Rotate 30 0 1 0
Rotate 60 1 0 0
Shape "sphere" "float radius" 1
AttributeEnd
"#,
    );
    let scene = foton_loader::load(&pbrt, &[]).unwrap();
    check(&scene, c, rot, |l| {
        Vec2::new(
            u_of(l),
            1.0 - l.z.clamp(-1.0, 1.0).acos() / std::f32::consts::PI,
        )
    });

    let xml = write(
        &dir,
        "s.xml",
        r#"<scene version="3.0.0">
<sensor type="perspective"><transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform></sensor>
<emitter type="point"><point name="position" x="0" y="0" z="5"/></emitter>
<shape type="sphere"><transform name="to_world"><rotate x="1" angle="60"/><rotate y="1" angle="30"/></transform></shape>
</scene>"#,
    );
    let scene = foton_loader::load(&xml, &[]).unwrap();
    check(&scene, c, rot, |l| {
        Vec2::new(u_of(l), l.z.clamp(-1.0, 1.0).acos() / std::f32::consts::PI)
    });

    // TOML: `axes` must be orthonormal.
    let bad = write(
        &dir,
        "s.toml",
        &(foton_tests::header("path", 1, 1, 4, 4)
            + "[camera]\nposition = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\n\n[materials.m]\ntype = \"diffuse\"\n\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"m\"\naxes = [1, 0, 0, 1, 0, 0, 0, 0, 1]\n"),
    );
    let err = foton_loader::load(&bad, &[])
        .err()
        .expect("refused")
        .to_string();
    assert!(
        err.contains("shapes[0].axes") && err.contains("orthonormal"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
