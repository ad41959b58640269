//! Area lights whose radiance is a texture (Mitsuba's textured `radiance`, pbrt-v4's image
//! area light, TOML's `emission` table): a 2 x 2 image of four colours on a 2 x 2 quad facing
//! down 1 above a diffuse floor. The floor at a point off-centre shows rho E / pi, E found
//! here by integrating the image's radiance over the quad (cos cos / r^2): the texture must
//! be looked up at the right place for next-event estimation, for rays that hit the light
//! (bdpt's light tracing to the camera, MIS) and for the photons it emits.

use foton_tests::{header, region_mean, render_toml, temp_dir, write};
use glam::{DVec3, Vec3};
use std::f64::consts::PI;

/// The texels, row by row from the image's top (uv (0, 0) is its top-left corner).
const TEXELS: [[f32; 3]; 4] = [
    [4.0, 1.0, 0.5],
    [0.5, 3.0, 1.0],
    [1.0, 0.5, 5.0],
    [0.2, 0.2, 0.2],
];
/// The floor point the camera looks at.
const TARGET: [f64; 3] = [0.5, 0.0, 0.3];

/// The quad light: origin (-1, 1, -1), u = (2, 0, 0), v = (0, 0, 2) (so its normal is -y),
/// its uv (s, t) at origin + s u + t v.
fn radiance(s: f64, t: f64) -> DVec3 {
    let (i, j) = (((2.0 * s) as usize).min(1), ((2.0 * t) as usize).min(1));
    Vec3::from(TEXELS[2 * j + i]).as_dvec3()
}

/// E at the target: the midpoint rule over the quad.
fn irradiance() -> DVec3 {
    irradiance_of(radiance)
}

/// E at the target from a quad of radiance `l(s, t)`.
fn irradiance_of(l: impl Fn(f64, f64) -> DVec3) -> DVec3 {
    let x = DVec3::from(TARGET);
    let n = 800;
    let h = 1.0 / n as f64;
    let mut e = DVec3::ZERO;
    for a in 0..n {
        for b in 0..n {
            let (s, t) = ((a as f64 + 0.5) * h, (b as f64 + 0.5) * h);
            let p = DVec3::new(-1.0 + 2.0 * s, 1.0, -1.0 + 2.0 * t);
            let d = p - x;
            let r2 = d.length_squared();
            let cos_x = d.y / r2.sqrt();
            // The light's normal is -y: its cosine towards x is the same as x's towards it.
            e += l(s, t) * (cos_x * cos_x / r2) * (4.0 * h * h);
        }
    }
    e
}

/// Writes the four-colour image into `dir`: the light's `emission` line reading it.
fn light_image(dir: &std::path::Path) -> String {
    let texels: Vec<f32> = TEXELS.iter().flatten().copied().collect();
    image::Rgb32FImage::from_raw(2, 2, texels)
        .unwrap()
        .save(dir.join("light.exr"))
        .unwrap();
    let file = dir.join("light.exr").display().to_string();
    format!(
        "emission = {{ type = \"bitmap\", filename = \"{file}\", raw = true, filter_type = \"nearest\" }}"
    )
}

fn scene(dir: &std::path::Path, integrator: &str, spp: u32) -> String {
    scene_with(integrator, spp, &light_image(dir))
}

/// The scene with the light's `emission` (and `alpha`) lines.
fn scene_with(integrator: &str, spp: u32, light: &str) -> String {
    let [tx, ty, tz] = TARGET;
    header(integrator, spp, 1, 16, 16)
        + &format!(
            r#"
[camera]
position = [{tx}, 0.3, {cz}]
look_at = [{tx}, {ty}, {tz}]
up = [0.0, 1.0, 0.0]
fov = 4.0

[integrators.photon]
global_photons = 1000000
caustic_photons = 0

[integrators.sppm]
iterations = 16
photons_per_iteration = 200000

[materials.floor]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-3.0, 0.0, 3.0]
u = [6.0, 0.0, 0.0]
v = [0.0, 0.0, -6.0]
material = "floor"

[[shapes]]
type = "quad"
origin = [-1.0, 1.0, -1.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 0.0, 2.0]
material = "black"
{light}
"#,
            cz = tz + 1.5,
        )
}

/// The floor shows rho E / pi within 2 % in every integrator that renders area lights.
#[test]
fn a_floor_under_a_textured_light_shows_rho_e_over_pi() {
    let dir = temp_dir("textured-light");
    let want = (irradiance() * (0.5 / PI)).as_vec3();
    let light = light_image(&dir);
    assert_floor_shows("textured-light", &light, want);
    let _ = std::fs::remove_dir_all(dir);
}

/// Its power is pi A times the texture's mean over the area, and its photons carry it.
#[test]
fn a_textured_lights_power_is_its_mean_radiance_times_pi_a() {
    let dir = temp_dir("textured-light-power");
    let path = write(&dir, "scene.toml", &scene(&dir, "path", 1));
    let scene = foton_loader::load(&path, &[]).unwrap();
    let mean: Vec3 = TEXELS.iter().map(|&t| Vec3::from(t)).sum::<Vec3>() / 4.0;
    let want = mean * (PI as f32 * 4.0);
    let power = scene.lights()[0].power();
    assert!(
        ((power - want) / want).abs().max_element() < 1e-3,
        "{power} against {want}"
    );
    // The emitted samples' flux: pi A L(uv) at their origin, whose mean is the power.
    let light = &scene.lights()[0];
    let n = 64;
    let mut sum = Vec3::ZERO;
    for a in 0..n {
        for b in 0..n {
            let u = glam::Vec2::new((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
            let e = light.sample_emission(u, glam::Vec2::splat(0.3), 0.5);
            let want = Vec3::from(TEXELS[2 * (b * 2 / n) + (a * 2 / n)]);
            assert!(
                (e.le - want).abs().max_element() < 1e-5,
                "at {u}: {} against {want}",
                e.le
            );
            sum += e.flux;
        }
    }
    let mean_flux = sum / (n * n) as f32;
    assert!(
        ((mean_flux - power) / power).abs().max_element() < 1e-3,
        "{mean_flux} against {power}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// pbrt-v4's image area light: "power" divides by the image's mean luminance (k_e), so the
/// light emits that power; "L" and "filename" together are refused, as pbrt-v4 refuses them.
#[test]
fn pbrt_image_area_lights_emit_their_power() {
    let dir = temp_dir("textured-light-pbrt");
    let texels: Vec<f32> = TEXELS.iter().flatten().copied().collect();
    image::Rgb32FImage::from_raw(2, 2, texels)
        .unwrap()
        .save(dir.join("light.exr"))
        .unwrap();
    let scene = |light: &str| {
        format!(
            r#"LookAt 0 2 4  0 0 0  0 1 0
Camera "perspective" "float fov" 45
WorldBegin
AttributeBegin
AreaLightSource "diffuse" {light}
Shape "bilinearmesh" "point3 P" [-1 1 -1  1 1 -1  -1 1 1  1 1 1] "point2 uv" [0 0  1 0  0 1  1 1]
AttributeEnd
"#
        )
    };
    let path = write(
        &dir,
        "power.pbrt",
        &scene(r#""string filename" "light.exr" "float power" 10"#),
    );
    let loaded = foton_loader::load(&path, &[]).unwrap();
    let power = loaded.lights()[0].power();
    let y = foton_core::texture::luminance(power);
    // The mean over the quad of the bilinear image (clamped at its edges) is the mean of
    // its texels: the four quadrants weigh the same.
    assert!((y - 10.0).abs() < 0.01 * 10.0, "luminance of {power}: {y}");
    let path = write(
        &dir,
        "both.pbrt",
        &scene(r#""string filename" "light.exr" "rgb L" [1 1 1]"#),
    );
    let e = foton_loader::load(&path, &[])
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("both \"L\" and \"filename\""), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// A cut-out light (pbrt-v4's `alpha` on an area light): a constant radiance through a
/// 2 x 2 opacity image lights the floor as alpha x L would, E integrated here: the points
/// next-event estimation and the photons sample emit alpha L, rays that meet the surface
/// pass its cut-out test first.
#[test]
fn a_cut_out_light_emits_alpha_times_its_radiance() {
    let dir = temp_dir("cut-out-light");
    const ALPHA: [f32; 4] = [1.0, 0.0, 0.5, 0.25];
    let texels: Vec<f32> = ALPHA.iter().flat_map(|&a| [a, a, a]).collect();
    image::Rgb32FImage::from_raw(2, 2, texels)
        .unwrap()
        .save(dir.join("alpha.exr"))
        .unwrap();
    let l = DVec3::new(2.0, 1.5, 1.0);
    let want = (irradiance_of(|s, t| {
        let (i, j) = (((2.0 * s) as usize).min(1), ((2.0 * t) as usize).min(1));
        l * ALPHA[2 * j + i] as f64
    }) * (0.5 / PI))
        .as_vec3();
    let light = format!(
        "emission = [{}, {}, {}]\nalpha = {{ type = \"bitmap\", filename = \"{}\", raw = true, filter_type = \"nearest\" }}",
        l.x,
        l.y,
        l.z,
        dir.join("alpha.exr").display()
    );
    assert_floor_shows("cut-out-light", &light, want);
    let _ = std::fs::remove_dir_all(dir);
}

/// Renders the floor under the quad light of `light` (its `emission` and `alpha` lines) with
/// every integrator that renders area lights: its centre shows `want` within 2 %.
fn assert_floor_shows(name: &str, light: &str, want: Vec3) {
    for (integrator, spp) in [
        ("path", 64),
        ("bdpt", 32),
        ("vcm", 16),
        ("photon", 16),
        ("sppm", 4),
    ] {
        let film = render_toml(name, &scene_with(integrator, spp, light), &[], 2);
        let (mean, se) = region_mean(&film, 4, 4, 12, 12);
        let rel = ((mean - want) / want).abs().max_element();
        assert!(
            rel < 0.02,
            "{integrator}: floor {mean} (standard error {se}) against rho E / pi {want} ({rel})"
        );
    }
}
