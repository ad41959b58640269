//! Round curves (Mitsuba 3's `linearcurve` and `bsplinecurve`, foton's `curve` shape): a convex
//! piece in a constant environment shows rho L under every integrator that renders it (it never
//! sees itself), the radii stay as written under `to_world`, texture coordinates run as
//! Mitsuba's do, a ray from inside passes out, and a bad curve file is reported at its line.

use foton_core::geometry::Ray;
use foton_tests::{header, region_mean, render_toml, temp_dir, write};
use glam::{Vec2, Vec3};

/// A curve file with one piece along x (radii r0, r1) and a camera looking at its middle
/// from +z, inside a constant environment of radiance 1.
fn furnace(integrator: &str, basis: &str, points: &str) -> String {
    header(integrator, 64, 64, 12, 12)
        + &format!(
            r#"
[camera]
position = [0, 0, 4]
look_at = [0, 0, 0]
fov = 4

[materials.grey]
type = "diffuse"
reflectance = [0.6, 0.6, 0.6]

[[lights]]
type = "constant"
radiance = [1, 1, 1]

[[shapes]]
type = "curve"
basis = "{basis}"
file = "{points}"
material = "grey"
"#
        )
}

/// A convex curve (one tapered piece; a straight B-spline, an open tube seen from its side)
/// sees only the environment: rho L at every point, 0.6, from path, bdpt and vcm; the
/// corners see L itself.
#[test]
fn a_convex_curve_in_a_constant_environment_shows_rho_l() {
    for (basis, points) in [
        ("linear", "-1 0 0 0.08\n1 0 0 0.05\n"),
        (
            "bspline",
            "-3 0 0 0.06\n-1 0 0 0.06\n1 0 0 0.06\n3 0 0 0.06\n",
        ),
    ] {
        for integrator in ["path", "bdpt", "vcm"] {
            let dir = temp_dir("curve-furnace");
            let file = write(&dir, "curve.txt", points);
            let scene = furnace(integrator, basis, &file.display().to_string());
            let film = render_toml("curve-furnace-scene", &scene, &[], 2);
            let (m, se) = region_mean(&film, 2, 5, 10, 7);
            assert!(
                (m - Vec3::splat(0.6)).abs().max_element() < 4.0 * se.max_element() + 0.01,
                "{basis}, {integrator}: rho L = 0.6 on the curve, found {m} +- {se}"
            );
            let (corner, _) = region_mean(&film, 0, 0, 2, 2);
            assert!(
                (corner - Vec3::ONE).abs().max_element() < 1e-3,
                "{basis}, {integrator}: L = 1 beside the curve, found {corner}"
            );
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

fn load_xml(name: &str, curve_type: &str, points: &str) -> foton_core::scene::Scene {
    let dir = temp_dir(name);
    write(&dir, "curve.txt", points);
    let xml = format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="30"/></sensor>
    <shape type="{curve_type}">
        <string name="filename" value="curve.txt"/>
        <transform name="to_world"><scale value="2"/><translate z="1"/></transform>
    </shape>
</scene>"#
    );
    let path = write(&dir, "scene.xml", &xml);
    let scene = foton_loader::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(dir);
    scene
}

/// Mitsuba 3 moves a curve's points by `to_world` and leaves its radii as written; its
/// texture coordinates: v along all segments of the file from 0 to 1, u the angle about the
/// axis / 2 pi from the axis' frame, whose first vector is +z made orthogonal to the axis
/// (a point on the +y side of an x-axis curve has u = 0, one on the +z side u = 1/4).
#[test]
fn curves_keep_their_radii_and_run_their_coordinates_as_mitsuba() {
    let scene = load_xml(
        "curve-xml",
        "linearcurve",
        "0 0 0 0.1\n1 0 0 0.1\n2 0 0 0.1\n",
    );
    // Points at (0, 0, 1), (2, 0, 1), (4, 0, 1) after to_world; radius 0.1, not 0.2.
    let down = |x: f32| scene.intersect(&Ray::new(Vec3::new(x, 0.0, 3.0), -Vec3::Z), f32::INFINITY);
    let hit = down(1.0).expect("the curve is below");
    assert!(
        (hit.t - 1.9).abs() < 1e-4,
        "the top at z = 1.1: t = {}",
        hit.t
    );
    let s = scene.surface(&hit);
    assert!((s.ng - Vec3::Z).length() < 1e-4);
    assert!((s.uv - Vec2::new(0.25, 0.25)).length() < 1e-4, "{}", s.uv);
    let side = scene
        .intersect(&Ray::new(Vec3::new(3.0, 2.0, 1.0), -Vec3::Y), f32::INFINITY)
        .unwrap();
    assert!((side.t - 1.9).abs() < 1e-4);
    let uv = scene.surface(&side).uv;
    assert!(
        uv.x.min(1.0 - uv.x) < 1e-4 && (uv.y - 0.75).abs() < 1e-4,
        "{uv}"
    );
    // Capped at both ends: the first point's sphere.
    assert!(down(-0.05).is_some() && down(4.05).is_some() && down(4.2).is_none());
    // A ray from inside passes out unseen.
    let inside = Ray::new(Vec3::new(1.0, 0.0, 1.0), Vec3::Z);
    assert!(scene.intersect(&inside, f32::INFINITY).is_none());
    // A B-spline's ends are open: the tube, not a sphere, is all there is.
    let spline = load_xml(
        "curve-xml-spline",
        "bsplinecurve",
        "0 0 0 0.1\n1 0 0 0.1\n2 0 0 0.1\n3 0 0 0.1\n",
    );
    // The curve runs from x = 1 to x = 2 (written), 2 to 4 in the scene.
    let along = Ray::new(Vec3::new(0.0, 0.05, 1.0), Vec3::X);
    assert!(spline.intersect(&along, f32::INFINITY).is_none());
    let hit = spline
        .intersect(&Ray::new(Vec3::new(3.0, 0.0, 3.0), -Vec3::Z), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 1.9).abs() < 1e-4);
    assert!((spline.surface(&hit).uv.y - 0.5).abs() < 1e-3);
}

/// A line that is not `x y z radius` is reported with the curve file's name and line; a
/// B-spline of three points is refused (it needs four); a curve cannot emit.
#[test]
fn bad_curves_are_reported_where_they_are() {
    let dir = temp_dir("curve-bad");
    write(&dir, "bad.txt", "0 0 0 0.1\n1 0 zero 0.1\n");
    write(&dir, "short.txt", "0 0 0 0.1\n1 0 0 0.1\n2 0 0 0.1\n");
    let scene = |file: &str, basis: &str, extra: &str| {
        format!(
            "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 30\n\n[materials.m]\ntype = \"diffuse\"\n\n[[shapes]]\ntype = \"curve\"\nbasis = \"{basis}\"\nfile = \"{file}\"\nmaterial = \"m\"\n{extra}"
        )
    };
    let err = |toml: String| {
        let path = write(&dir, "scene.toml", &toml);
        match foton_loader::load(&path, &[]) {
            Ok(_) => panic!("loaded: {toml}"),
            Err(e) => e.to_string(),
        }
    };
    let e = err(scene("bad.txt", "linear", ""));
    assert!(e.contains("bad.txt:2") && e.contains("x y z radius"), "{e}");
    let e = err(scene("short.txt", "bspline", ""));
    assert!(e.contains("at least 4"), "{e}");
    let e = err(scene("short.txt", "linear", "emission = [1, 1, 1]\n"));
    assert!(
        e.contains("emission") && e.contains("cannot be an area light"),
        "{e}"
    );
    let e = err(scene("short.txt", "cubic", ""));
    assert!(e.contains("basis"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// Path, bdpt and sppm agree on a bent curve over a floor under a small area light (its
/// shadow, light paths that hit the curve and leave it): image means within noise.
#[test]
fn integrators_agree_on_a_lit_curve() {
    let dir = temp_dir("curve-lit");
    let file = write(
        &dir,
        "curve.txt",
        "-0.8 0.3 0 0.1\n-0.2 0.3 0.3 0.1\n0.3 0.3 -0.2 0.1\n0.8 0.3 0.2 0.1\n",
    );
    let scene = |integrator: &str| {
        header(integrator, 64, 8, 16, 16)
            + &format!(
                r#"
[camera]
position = [0, 3, 0.01]
look_at = [0, 0, 0]
fov = 45

[materials.white]
type = "diffuse"
reflectance = [0.7, 0.7, 0.7]

[materials.black]
type = "diffuse"
reflectance = [0, 0, 0]

[[shapes]]
type = "quad"
origin = [-2, 0, 2]
u = [4, 0, 0]
v = [0, 0, -4]
material = "white"

[[shapes]]
type = "curve"
file = "{}"
material = "white"

[[shapes]]
type = "quad"
origin = [-0.25, 1.5, -0.25]
u = [0, 0, 0.5]
v = [0.5, 0, 0]
material = "black"
emission = [8, 8, 8]

[integrators.sppm]
iterations = 64
photons_per_iteration = 20000
"#,
                file.display()
            )
    };
    let mean = |integrator: &str| {
        let film = render_toml("curve-lit-scene", &scene(integrator), &[], 2);
        region_mean(&film, 0, 0, 16, 16)
    };
    let (reference, se) = mean("path");
    for integrator in ["bdpt", "sppm"] {
        let (m, se2) = mean(integrator);
        let tolerance = 4.0 * (se.x * se.x + se2.x * se2.x).sqrt() + 0.01 * reference.x;
        assert!(
            (m.x - reference.x).abs() < tolerance,
            "{integrator}: mean {m} against path's {reference}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// An instance moves a curve whole, radii too (Embree traces it in the group's space): a
/// curve of radius 0.1 in a group instanced at scale 2 has radius 0.2 (its own `to_world`
/// still leaves radii as written).
#[test]
fn an_instance_scales_a_curve_with_its_radii() {
    let dir = temp_dir("curve-instance");
    write(&dir, "curve.txt", "0 0 0 0.1\n1 0 0 0.1\n");
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="30"/></sensor>
    <shape type="shapegroup" id="group">
        <shape type="linearcurve">
            <string name="filename" value="curve.txt"/>
            <transform name="to_world"><scale value="3"/></transform>
        </shape>
    </shape>
    <shape type="instance">
        <ref id="group"/>
        <transform name="to_world"><scale value="2"/></transform>
    </shape>
</scene>"#;
    let path = write(&dir, "scene.xml", xml);
    let scene = foton_loader::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    // Points at x = 0 and 6; radius 0.1 x 2.
    let hit = scene
        .intersect(&Ray::new(Vec3::new(3.0, 0.0, 2.0), -Vec3::Z), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 1.8).abs() < 1e-4, "t = {}", hit.t);
    let end = Ray::new(Vec3::new(6.15, 0.0, 2.0), -Vec3::Z);
    assert!(scene.intersect(&end, f32::INFINITY).is_some());
    let _ = std::fs::remove_dir_all(dir);
}
