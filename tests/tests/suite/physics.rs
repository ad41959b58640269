//! Physics checks of the path tracer against closed-form answers: the irradiance of a point
//! light on a plane, white furnaces (with and without glass and mirrors), an area light seen
//! directly, far-field equivalence of lights of equal power, and determinism.

use foton_core::geometry::Ray;
use foton_core::scene::Scene;
use foton_loader::FilmFile;
use foton_tests::{header, region_mean, render_file, render_toml, temp_dir, write};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A camera looking straight down at the plane y = 0 from `height`.
fn top_camera(height: f32, fov: f32) -> String {
    format!(
        r#"
[camera]
position = [0.0, {height}, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = {fov}
"#
    )
}

/// For each pixel, the mean over a sub-pixel grid of an analytic radiance function of the
/// point where the camera ray meets the plane y = 0.
fn analytic_image(scene: &Scene, radiance: impl Fn(Vec3) -> f32) -> Vec<f32> {
    let (w, h) = scene.camera().resolution();
    let n = 8;
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let mut sum = 0.0;
            for j in 0..n {
                for i in 0..n {
                    let film = Vec2::new(
                        x as f32 + (i as f32 + 0.5) / n as f32,
                        y as f32 + (j as f32 + 0.5) / n as f32,
                    );
                    let ray: Ray = scene.camera().generate_ray(film);
                    let t = -ray.origin.y / ray.dir.y;
                    sum += radiance(ray.at(t));
                }
            }
            out.push(sum / (n * n) as f32);
        }
    }
    out
}

#[test]
fn point_light_over_diffuse_plane_gives_rho_over_pi_i_cos_over_r2() {
    let rho = 0.6f32;
    let intensity = 2.5f32;
    let light = Vec3::new(0.3, 1.0, -0.2);
    let toml = format!(
        r#"{}{}
[materials.floor]
type = "diffuse"
reflectance = [{rho}, {rho}, {rho}]

[[shapes]]
type = "quad"
origin = [-10.0, 0.0, -10.0]
u = [20.0, 0.0, 0.0]
v = [0.0, 0.0, 20.0]
material = "floor"

[[lights]]
type = "point"
position = [{}, {}, {}]
intensity = [{intensity}, {intensity}, {intensity}]
"#,
        header("path", 1024, 4, 24, 24),
        top_camera(3.0, 60.0),
        light.x,
        light.y,
        light.z
    );
    let dir = temp_dir("point-plane");
    let path = write(&dir, "scene.toml", &toml);
    let scene = foton_loader::load(&path, &[]).unwrap();
    let film = render_file(&path, &[], 2);
    let expected = analytic_image(&scene, |p| {
        let d = light - p;
        let r2 = d.length_squared();
        let cos = d.y / r2.sqrt();
        rho / PI * intensity * cos / r2
    });
    let mut worst = 0.0f32;
    for (i, want) in expected.iter().enumerate() {
        let got = film.pixel(i as u32 % 24, i as u32 / 24);
        // Point-light NEE is exact; what remains is the pixel-jitter noise of a smooth function.
        let rel = (got.x - want).abs() / want;
        worst = worst.max(rel);
        assert!(
            (got.x - got.y).abs() < 1e-6 && (got.y - got.z).abs() < 1e-6,
            "grey in, grey out"
        );
    }
    assert!(worst < 0.01, "worst relative pixel error {worst}");
    let _ = std::fs::remove_dir_all(dir);
}

/// Six inward-facing quads forming the box [-1, 1]^3, all diffuse with albedo `rho` and
/// emitting `le` on the inside, plus `extra` shapes; camera in the box.
fn furnace_box(rho: f32, le: f32, extra: &str, spp: u32) -> String {
    let c = |x: f32, y: f32, z: f32| format!("[{x}, {y}, {z}]");
    // (origin, u, v) with u x v pointing into the box.
    let faces = [
        (c(-1., -1., -1.), c(0., 0., 2.), c(2., 0., 0.)), // floor, normal +y
        (c(-1., 1., -1.), c(2., 0., 0.), c(0., 0., 2.)),  // ceiling, normal -y
        (c(-1., -1., -1.), c(2., 0., 0.), c(0., 2., 0.)), // back, normal +z
        (c(-1., -1., 1.), c(0., 2., 0.), c(2., 0., 0.)),  // front, normal -z
        (c(-1., -1., -1.), c(0., 2., 0.), c(0., 0., 2.)), // left, normal +x
        (c(1., -1., -1.), c(0., 0., 2.), c(0., 2., 0.)),  // right, normal -x
    ];
    let mut s = header("path", spp, 1000, 24, 24);
    s += r#"
[camera]
position = [0.0, 0.0, 0.9]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 90.0
"#;
    s += &format!("[materials.wall]\ntype = \"diffuse\"\nreflectance = [{rho}, {rho}, {rho}]\n");
    s += "[materials.glass]\ntype = \"dielectric\"\nior = 1.5\n";
    s += "[materials.mirror]\ntype = \"mirror\"\nreflectance = [1.0, 1.0, 1.0]\n";
    for (o, u, v) in faces {
        s += &format!(
            "[[shapes]]\ntype = \"quad\"\norigin = {o}\nu = {u}\nv = {v}\nmaterial = \"wall\"\nemission = [{le}, {le}, {le}]\n"
        );
    }
    s + extra
}

fn assert_uniform(film: &foton_core::film::Film, expected: f32, what: &str) {
    let (mean, err) = region_mean(film, 0, 0, film.width, film.height);
    for c in 0..3 {
        let (m, e) = (mean[c], err[c]);
        assert!(
            (m - expected).abs() < (4.0 * e).max(1e-4) && (m - expected).abs() < 0.02 * expected,
            "{what}: channel {c} mean {m} +- {e}, expected {expected}"
        );
    }
}

#[test]
fn white_furnace_gives_le_over_one_minus_rho() {
    for rho in [0.0f32, 0.5, 0.8] {
        let film = render_toml("furnace", &furnace_box(rho, 1.0, "", 64), &[], 2);
        assert_uniform(&film, 1.0 / (1.0 - rho), &format!("rho = {rho}"));
    }
}

#[test]
fn glass_and_mirror_in_a_furnace_are_invisible() {
    // Lossless delta surfaces in a uniform radiance field leave it uniform: this holds only if
    // Fresnel reflection and transmission sum to one and the 1/eta^2 radiance scaling on
    // entering is undone on leaving.
    let extra = r#"
[[shapes]]
type = "sphere"
center = [-0.35, 0.0, -0.2]
radius = 0.3
material = "glass"

[[shapes]]
type = "sphere"
center = [0.4, -0.1, -0.3]
radius = 0.3
material = "mirror"
"#;
    let film = render_toml("furnace-glass", &furnace_box(0.5, 1.0, extra, 64), &[], 2);
    assert_uniform(&film, 2.0, "furnace with glass and mirror");
    // And each sphere on its own: the pixels that see it.
    let (glass, err) = region_mean(&film, 6, 10, 10, 14);
    assert!(
        (glass.x - 2.0).abs() < (4.0 * err.x).max(0.04),
        "glass {glass} +- {err}"
    );
}

#[test]
fn directly_seen_area_light_gives_its_radiance_exactly() {
    let toml = format!(
        r#"{}
[camera]
position = [0.0, 0.0, 2.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40.0

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

# facing the camera (normal +z)
[[shapes]]
type = "quad"
origin = [-1.0, -1.0, 0.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "black"
emission = [3.0, 2.0, 0.5]
"#,
        header("path", 4, 0, 16, 16)
    );
    let film = render_toml("area-direct", &toml, &[], 2);
    for y in 0..16 {
        for x in 0..16 {
            let p = film.pixel(x, y);
            assert!(
                (p - Vec3::new(3.0, 2.0, 0.5)).abs().max_element() < 1e-5,
                "({x},{y}) = {p}"
            );
        }
    }
    // Seen from behind, a one-sided emitter is black.
    let film = render_toml("area-back", &toml, &["camera.position=[0.0, 0.0, -2.0]"], 2);
    assert_eq!(film.mean(), Vec3::ZERO);
}

/// A small light above a large diffuse floor, seen from above; returns the rendered and the
/// analytic floor radiance for the given far-field intensity I(theta) of the light.
fn far_field(light: &str, intensity: impl Fn(f32) -> f32, height: f32) -> (f32, f32) {
    let rho = 0.5f32;
    let toml = format!(
        r#"{}{}
[materials.floor]
type = "diffuse"
reflectance = [{rho}, {rho}, {rho}]

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-50.0, 0.0, -50.0]
u = [100.0, 0.0, 0.0]
v = [0.0, 0.0, 100.0]
material = "floor"
{light}
"#,
        header("path", 64, 1, 8, 8),
        top_camera(height * 0.5, 20.0)
    );
    let dir = temp_dir("far-field");
    let path = write(&dir, "scene.toml", &toml);
    let scene = foton_loader::load(&path, &[]).unwrap();
    let film = render_file(&path, &[], 2);
    let light_pos = Vec3::new(0.0, height, 0.0);
    let expected = analytic_image(&scene, |p| {
        let d = light_pos - p;
        let r2 = d.length_squared();
        let cos = d.y / r2.sqrt();
        rho / PI * intensity(cos) * cos / r2
    });
    let _ = std::fs::remove_dir_all(dir);
    (
        film.mean().x,
        expected.iter().sum::<f32>() / expected.len() as f32,
    )
}

#[test]
fn sphere_light_and_point_light_of_equal_power_light_a_far_floor_alike() {
    // A sphere of radius r and radiance L emits P = 4 pi^2 r^2 L isotropically, I = P / (4 pi).
    let (r, l, h) = (0.05f32, 40.0f32, 10.0f32);
    let power = 4.0 * PI * PI * r * r * l;
    let sphere = format!(
        "[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, {h}, 0.0]\nradius = {r}\nmaterial = \"black\"\nemission = [{l}, {l}, {l}]\n"
    );
    let point = format!(
        "[[lights]]\ntype = \"point\"\nposition = [0.0, {h}, 0.0]\npower = [{power}, {power}, {power}]\n"
    );
    let iso = |_: f32| power / (4.0 * PI);
    // Both expectations come from the same camera and I(theta): the same number.
    let (got_sphere, want) = far_field(&sphere, iso, h);
    let (got_point, _) = far_field(&point, iso, h);
    assert!(
        (got_point - want).abs() < 0.005 * want,
        "point {got_point} vs {want}"
    );
    assert!(
        (got_sphere - want).abs() < 0.02 * want,
        "sphere {got_sphere} vs {want}"
    );
    assert!((got_sphere - got_point).abs() < 0.02 * want);
}

#[test]
fn quad_light_far_field_is_lambertian_with_power_pi_a_l() {
    // A one-sided quad light of area A and radiance L facing down has intensity L A cos(theta)
    // far away (total power pi A L); rendered floor radiance must match rho/pi E.
    let (s, l, h) = (0.1f32, 30.0f32, 10.0f32);
    let quad = format!(
        "[[shapes]]\ntype = \"quad\"\norigin = [{}, {h}, {}]\nu = [{s}, 0.0, 0.0]\nv = [0.0, 0.0, {s}]\nmaterial = \"black\"\nemission = [{l}, {l}, {l}]\n",
        -s / 2.0,
        -s / 2.0
    );
    let area = s * s;
    let (got, want) = far_field(&quad, |cos| l * area * cos, h);
    assert!((got - want).abs() < 0.02 * want, "quad {got} vs {want}");
}

#[test]
fn image_is_identical_for_one_and_many_threads() {
    let path = foton_tests::repo_root().join("scenes/cornell-box.toml");
    let small = ["film.width=32", "film.height=32", "render.spp=4"];
    let one = render_file(&path, &small, 1);
    let many = render_file(&path, &small, 3);
    assert_eq!(one.pixels(), many.pixels());
    let other_seed = render_file(&path, &[&small[..], &["render.seed=1"]].concat(), 3);
    assert_ne!(one.pixels(), other_seed.pixels(), "the seed must matter");
}

#[test]
fn exr_reads_back_identically_and_png_is_srgb() {
    let path = foton_tests::repo_root().join("scenes/cornell-box.toml");
    let film = render_file(
        &path,
        &["film.width=16", "film.height=12", "render.spp=2"],
        2,
    );
    let dir = temp_dir("exr");
    let exr = dir.join("out.exr");
    film.write(&exr, &Default::default()).unwrap();
    let (w, h, px) = foton_loader::image::read_image(&exr).unwrap();
    assert_eq!((w, h), (16, 12));
    assert_eq!(px, film.pixels());
    let png = dir.join("out.png");
    film.write(&png, &Default::default()).unwrap();
    let (_, _, back) = foton_loader::image::read_image(&png).unwrap();
    for (a, b) in back.iter().zip(film.pixels()) {
        let b = b.clamp(Vec3::ZERO, Vec3::ONE);
        // 8-bit sRGB quantisation: at most half a step in encoded space.
        let step = |c: f32| foton_core::film::srgb_encode(c);
        for c in 0..3 {
            assert!((step(a[c]) - step(b[c])).abs() <= 0.5 / 255.0 + 1e-4);
        }
    }
    // No temporary files are left behind.
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
    let _ = std::fs::remove_dir_all(dir);
}
