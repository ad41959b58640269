//! The orthographic camera (TOML `type = "orthographic"`, pbrt-v4's `orthographic`, Mitsuba's
//! `orthographic` sensor): parallel rays from a view `view_height` world units tall. Its
//! importance is a delta in direction, so light tracing reaches it along the optical axis only
//! and the first segment's densities have no distance (as a directional light's): light
//! tracing and bdpt agree with the path tracer; a glowing sphere covers its true area of the
//! view whatever its distance; the readers size the view as each format does.

use crate::bdpt::{CEILING_LIGHT, cornell};
use foton_core::film::Film;
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, render_toml, temp_dir, write};

const Z: Tolerance = Tolerance {
    rel: 0.0,
    z: 4.5,
    floor: 1e-4,
};

/// The bdpt tests' Cornell box seen by an orthographic camera 2.2 units tall from the front.
const ORTHO: [&str; 5] = [
    "camera.type=\"orthographic\"",
    "camera.view_height=2.2",
    "camera.fov=[]",
    "camera.position=[0.0, 1.0, 3.0]",
    "camera.look_at=[0.0, 1.0, 0.0]",
];

fn render(integrator: &str, spp: u32, extra: &[&str]) -> Film {
    let scene = cornell("white", "white", "", CEILING_LIGHT).replace("fov = 39.3\n", "");
    let mut sets = vec![
        format!("render.integrator=\"{integrator}\""),
        format!("render.spp={spp}"),
    ];
    sets.extend(
        ORTHO
            .iter()
            .filter(|s| !s.starts_with("camera.fov"))
            .map(|s| s.to_string()),
    );
    sets.extend(extra.iter().map(|s| s.to_string()));
    let refs: Vec<&str> = sets.iter().map(String::as_str).collect();
    render_toml("orthographic", &scene, &refs, 2)
}

/// Light tracing alone (each light vertex projected onto the view along the axis, with no
/// distance in its density) and the full bidirectional estimator agree with the path tracer.
#[test]
fn light_tracing_and_bdpt_agree_with_path_through_an_orthographic_camera() {
    let path = render("path", 2048, &[]);
    let light = render("bdpt", 512, &["integrators.bdpt.strategy=\"light\""]);
    assert_blocks_agree(
        "orthographic light tracing against path",
        &light,
        &path,
        4,
        Z,
    );
    let all = render("bdpt", 128, &[]);
    assert_blocks_agree("orthographic bdpt against path", &all, &path, 4, Z);
}

/// A sphere of radius r and radiance 1 seen by an orthographic camera covers pi r^2 of the
/// view's area A whatever its distance: the image's mean is pi r^2 / A, for the path tracer
/// and for light tracing (the sphere's points connected to the camera along the axis).
#[test]
fn a_glowing_sphere_covers_its_true_area_of_the_view() {
    let (radius, height) = (0.5f64, 2.0f64);
    let scene = |integrator: &str, spp: u32, z: f64| {
        header(integrator, spp, 0, 32, 32)
            + &format!(
                r#"
[camera]
type = "orthographic"
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
view_height = {height}

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "sphere"
center = [0.2, -0.1, {z}]
radius = {radius}
material = "black"
emission = [1.0, 1.0, 1.0]
"#
            )
    };
    let want = std::f64::consts::PI * radius * radius / (height * height);
    for z in [-1.0, -6.0] {
        for (integrator, spp) in [("path", 64), ("bdpt", 64)] {
            let sets: &[&str] = if integrator == "bdpt" {
                &["integrators.bdpt.strategy=\"light\""]
            } else {
                &[]
            };
            let film = render_toml("ortho-sphere", &scene(integrator, spp, z), sets, 2);
            let mean = film.mean().x as f64;
            assert!(
                (mean / want - 1.0).abs() < 0.02,
                "{integrator} at depth {z}: mean {mean}, the sphere's share of the view {want}"
            );
        }
    }
}

/// pbrt-v4's orthographic screen window is in camera-space units (by default [-1, 1] on the
/// shorter axis); Mitsuba's orthographic view is [-1, 1] across the width, sized by the
/// transform's scale; a non-uniform scale (non-square pixels) is refused.
#[test]
fn readers_size_the_orthographic_view() {
    let dir = temp_dir("ortho-readers");
    let pbrt = |camera: &str| {
        format!(
            r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic" {camera}
Film "rgb" "integer xresolution" 32 "integer yresolution" 16 "string filename" "o.exr"
WorldBegin
LightSource "point" "rgb I" [1 1 1]
Shape "sphere" "float radius" 1
"#
        )
    };
    // A world point seen where each format's view puts it.
    let at = |file: &std::path::Path, x: f32| {
        let scene = foton_loader::load(file, &[]).unwrap();
        let cam = scene.camera();
        assert!(cam.is_orthographic());
        cam.project(glam::Vec3::new(x, 0.5, 0.0)).unwrap()
    };
    // pbrt's LookAt down -z with y up puts camera +x along world -x (its camera space is
    // left-handed), and the image's x follows camera x: world (-0.5, 0.5) is camera
    // (0.5, 0.5). The window [-2, 2] x [-1, 1] over 32 x 16 pixels puts it at pixel 20, row 4.
    let f = at(&write(&dir, "default.pbrt", &pbrt("")), -0.5);
    assert!((f - glam::Vec2::new(20.0, 4.0)).length() < 1e-3, "{f}");
    let f = at(
        &write(
            &dir,
            "window.pbrt",
            &pbrt(r#""float screenwindow" [0 4 0 2]"#),
        ),
        -0.5,
    );
    assert!((f - glam::Vec2::new(4.0, 12.0)).length() < 1e-3, "{f}");

    let xml = |scale: &str| {
        format!(
            r#"<scene version="3.0.0">
<sensor type="orthographic">
  <transform name="to_world"><scale {scale}/><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="16"/></film>
</sensor>
<emitter type="point"><point name="position" x="0" y="3" z="3"/></emitter>
<shape type="sphere"/>
</scene>"#
        )
    };
    // Mitsuba's camera +x is the image's left, world -x here: the view is world [-4, 4]
    // across 32 pixels and [-2, 2] up 16 rows, so world (0.5, 0.5) is at pixel 18, row 6.
    let f = at(&write(&dir, "ortho.xml", &xml(r#"x="4" y="4""#)), 0.5);
    assert!((f - glam::Vec2::new(18.0, 6.0)).length() < 1e-3, "{f}");
    let file = write(&dir, "stretched.xml", &xml(r#"x="4" y="2""#));
    let err = foton_loader::load(&file, &[])
        .err()
        .expect("non-square pixels")
        .to_string();
    assert!(err.contains("square"), "{err}");
}

/// An orthographic camera's TOML is checked: a view size is needed, fov and a lens are not
/// its parameters.
#[test]
fn bad_orthographic_cameras_are_clear_errors() {
    let base = header("path", 1, 1, 4, 4)
        + "[camera]\ntype = \"orthographic\"\nposition = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\n";
    for (extra, words) in [
        ("", "needs `view_height`"),
        (
            "view_height = 2.0\nfov = 40.0\n",
            "no meaning for an orthographic",
        ),
        (
            "view_height = 2.0\nlens_radius = 0.1\n",
            "no meaning for an orthographic",
        ),
        ("view_height = -1.0\n", "must be positive"),
        ("view_height = 1.0\nview_width = 1.0\n", "not both"),
    ] {
        let dir = temp_dir("ortho-bad");
        let file = write(&dir, "s.toml", &format!("{base}{extra}"));
        let err = foton_loader::load(&file, &[])
            .err()
            .expect("refused")
            .to_string();
        assert!(
            err.contains(words) && err.contains("camera."),
            "{extra}: {err}"
        );
    }
}
