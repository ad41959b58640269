//! The projector (TOML `type = "projector"`, Mitsuba 3's `projector`): the reverse of a
//! perspective camera. A camera at the projector with its field of view sees the image on a
//! plane across the axis, each texel where the camera sees it and with the radiance
//! rho scale E / d^2 (the irradiance pi scale E / d^2 on the plane, constant over it, Mitsuba
//! 3's normalisation); its photons deliver its power, each quarter of the image the quarter's
//! share; light tracing agrees with the path tracer; the Mitsuba reader places it as a
//! sensor of the same to_world.

use foton_core::scene::Scene;
use foton_photonmap::trace::{STREAM_GLOBAL, TraceOptions, trace_one};
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, render_toml, temp_dir, write};
use glam::DVec3;
use std::path::Path;

/// The image's texels, row by row from the top: 4 x 2, each a different colour.
const TEXELS: [[f32; 3]; 8] = [
    [1.0, 0.2, 0.2],
    [0.2, 1.0, 0.2],
    [0.2, 0.2, 1.0],
    [1.0, 1.0, 0.2],
    [0.2, 1.0, 1.0],
    [1.0, 0.2, 1.0],
    [0.6, 0.6, 0.6],
    [0.1, 0.4, 0.9],
];
const SCALE: f64 = 0.7;
const DISTANCE: f64 = 2.0;
const FOV: f64 = 50.0;

fn write_image(dir: &Path) -> String {
    let texels: Vec<f32> = TEXELS.iter().flatten().copied().collect();
    image::Rgb32FImage::from_raw(4, 2, texels)
        .unwrap()
        .save(dir.join("slide.exr"))
        .unwrap();
    dir.join("slide.exr").display().to_string()
}

/// A white plane at z = -DISTANCE, the projector at the origin looking down -z, and a camera
/// at the projector with its field of view (across the width) on a 32 x 16 film: each texel
/// covers 8 x 8 pixels.
fn scene(dir: &Path, integrator: &str, spp: u32) -> String {
    let file = write_image(dir);
    header(integrator, spp, 1, 32, 16)
        + &format!(
            r#"
[film.filter]
type = "box"

[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
up = [0.0, 1.0, 0.0]
fov = {FOV}
fov_axis = "x"

[integrators.photon]
global_photons = 200000
caustic_photons = 0

[materials.white]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[[shapes]]
type = "quad"
origin = [-20.0, -20.0, -{DISTANCE}]
u = [40.0, 0.0, 0.0]
v = [0.0, 40.0, 0.0]
material = "white"

[[lights]]
type = "projector"
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
up = [0.0, 1.0, 0.0]
fov = {FOV}
scale = {SCALE}
irradiance = {{ type = "bitmap", filename = "{file}", raw = true, filter_type = "nearest" }}
"#
        )
}

fn load(text: &str) -> Scene {
    let dir = temp_dir("projector-load");
    let path = write(&dir, "scene.toml", text);
    let scene = foton_loader::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(dir);
    scene
}

/// The texel (column, row) of the image a point of the plane shows, by the camera's
/// convention: uv (0, 0) at the top-left, x to the right as the projector looks.
fn texel_at(p: DVec3) -> Option<usize> {
    let tan_x = (FOV.to_radians() / 2.0).tan();
    let tan_y = tan_x / 2.0;
    let (sx, sy) = (p.x / -p.z, p.y / -p.z);
    let u = 0.5 + sx / (2.0 * tan_x);
    let v = 0.5 - sy / (2.0 * tan_y);
    if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
        return None;
    }
    Some((v * 2.0) as usize * 4 + (u * 4.0) as usize)
}

/// Every pixel inside a texel's 8 x 8 block is rho scale E / d^2 of that texel: the image
/// upright and unmirrored, its aspect ratio the image's, the irradiance pi scale E / d^2.
#[test]
fn a_camera_at_the_projector_sees_its_image_on_a_plane() {
    let dir = temp_dir("projector-image");
    let film = render_toml("projector-image", &scene(&dir, "path", 4), &[], 2);
    for (i, t) in TEXELS.iter().enumerate() {
        let (col, row) = ((i % 4) as u32, (i / 4) as u32);
        for (x, y) in [(1, 1), (4, 4), (6, 6), (1, 6), (6, 1)] {
            let got = film.pixel(col * 8 + x, row * 8 + y);
            for (c, (g, e)) in [got.x, got.y, got.z].iter().zip(t).enumerate() {
                let want = 0.5 * SCALE * f64::from(*e) / (DISTANCE * DISTANCE);
                assert!(
                    (f64::from(*g) - want).abs() < 1e-4 * want,
                    "texel {i} pixel ({}, {}) channel {c}: {g} against {want}",
                    col * 8 + x,
                    row * 8 + y
                );
            }
        }
    }
    // Nothing outside the image: the camera with a wider view sees a dark border.
    let wide = render_toml(
        "projector-wide",
        &scene(&dir, "path", 4).replacen("fov = 50\n", "fov = 80\n", 1),
        &[],
        2,
    );
    for (x, y) in [(0, 0), (31, 0), (0, 15), (31, 15), (1, 8), (30, 8)] {
        assert_eq!(wide.pixel(x, y).max_element(), 0.0, "({x}, {y})");
    }
}

/// Photons leave through uniform points of the image's rectangle: on a plane that catches
/// them all they deliver the light's power, pi scale A mean(E) (A = 4 tan_x tan_y), and each
/// of the eight texels its own share, pi scale (A / 8) E.
#[test]
fn projector_photons_deliver_its_power_texel_by_texel() {
    let dir = temp_dir("projector-photons");
    let scene = load(&scene(&dir, "photon", 1));
    let tan_x = (FOV.to_radians() / 2.0).tan();
    let area = 4.0 * tan_x * tan_x / 2.0;
    let mean = TEXELS.iter().fold(DVec3::ZERO, |s, t| {
        s + DVec3::new(t[0].into(), t[1].into(), t[2].into())
    }) / 8.0;
    let power = scene.lights()[0].power().as_dvec3();
    let want = std::f64::consts::PI * SCALE * area * mean;
    assert!(
        (power - want).abs().max_element() < 1e-4 * want.max_element(),
        "{power} against {want}"
    );
    let opts = TraceOptions {
        photons: 80_000,
        max_depth: 1,
        seed: 3,
        stream: STREAM_GLOBAL,
        stop_at_diffuse: true,
        sobol_emission: false,
    };
    let sources = foton_photonmap::sources::Sources::new(&scene).unwrap();
    let mut per_texel = [DVec3::ZERO; 8];
    let mut count = [0u32; 8];
    for i in 0..opts.photons {
        trace_one(&scene, &opts, &sources, i, |p, _, _| {
            let t = texel_at(p.position.as_dvec3()).expect("a photon outside the image");
            per_texel[t] += p.power().as_dvec3();
            count[t] += 1;
        });
    }
    for (t, texel) in TEXELS.iter().enumerate() {
        let e = DVec3::new(texel[0].into(), texel[1].into(), texel[2].into());
        let share = std::f64::consts::PI * SCALE * area / 8.0 * e;
        // Each photon carries pi scale A E of its texel: the texel's sum is that times the
        // binomial fraction of photons through it (1/8 expected).
        let q = f64::from(count[t]) / opts.photons as f64;
        let sigma = ((1.0 - 0.125) / (0.125 * opts.photons as f64)).sqrt();
        assert!(
            (q - 0.125).abs() < 4.5 * sigma * 0.125 + 1e-12,
            "texel {t}: a fraction {q} of the photons"
        );
        let rel = ((per_texel[t] - share) / share).abs().max_element();
        assert!(
            rel < 4.5 * sigma,
            "texel {t}: {} against {share} ({rel})",
            per_texel[t]
        );
    }
}

/// Light tracing (the projector's photons connected to the camera) against the path tracer
/// (next-event estimation towards it), on a plane seen from aside.
#[test]
fn light_tracing_agrees_with_the_path_tracer_under_a_projector() {
    let dir = temp_dir("projector-bdpt");
    let aside = |s: String| {
        s.replace(
            "[camera]\nposition = [0.0, 0.0, 0.0]",
            "[camera]\nposition = [0.8, 0.5, 0.3]",
        )
        .replace("fov = 50\nfov_axis", "fov = 70\nfov_axis")
    };
    let path = render_toml("projector-path", &aside(scene(&dir, "path", 256)), &[], 2);
    let light = render_toml(
        "projector-light",
        &aside(scene(&dir, "bdpt", 256)),
        &["integrators.bdpt.strategy=\"light\""],
        2,
    );
    let z = Tolerance {
        rel: 0.0,
        z: 4.5,
        floor: 1e-4,
    };
    assert_blocks_agree("projector: light tracing against path", &light, &path, 4, z);
}

/// Mitsuba 3's projector, read from its `to_world` and `fov` (the camera's frame and field of
/// view), `irradiance` and `scale`: inside its view the plane at distance 2 shows
/// rho scale E / 4, outside it nothing.
#[test]
fn mitsuba_projectors_are_read_as_mitsuba_places_them() {
    let dir = temp_dir("projector-mitsuba");
    let frame = r#"<transform name="to_world"><lookat origin="0, 0, 0" target="0, 0, -1" up="0, 1, 0"/></transform>"#;
    let xml = format!(
        r#"<scene version="3.0.0">
    <integrator type="direct"/>
    <sensor type="perspective">
        <float name="fov" value="60"/>
        {frame}
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    </sensor>
    <emitter type="projector">
        <float name="fov" value="30"/>
        {frame}
        <rgb name="irradiance" value="2, 1, 0.5"/>
        <float name="scale" value="0.5"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="20"/><translate z="-2"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    </shape>
</scene>
"#
    );
    let path = write(&dir, "projector.xml", &xml);
    let film = foton_tests::render_file(&path, &[], 2);
    let centre = film.pixel(8, 8);
    for (c, e) in [centre.x, centre.y, centre.z]
        .iter()
        .zip([2.0f32, 1.0, 0.5])
    {
        let want = 0.5 * 0.5 * e / 4.0;
        assert!((c - want).abs() < 1e-4 * want, "{centre} against {want}");
    }
    // A 30-degree view inside the camera's 60: the camera's corners are dark.
    assert_eq!(film.pixel(0, 0).max_element(), 0.0);
    assert_eq!(film.pixel(15, 15).max_element(), 0.0);
}
