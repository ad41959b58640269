//! The environment lights (Mitsuba's `constant` and `envmap`): a diffuse sphere inside a
//! constant environment L shows rho L (it sees L over its whole upper hemisphere everywhere),
//! the background shows L, for every integrator; the photons it emits deliver pi L to every
//! point of the sphere. An envmap of a constant image L is the same environment, sampled and
//! emitted through its image's distribution.

use foton_photonmap::trace::{STREAM_GLOBAL, TraceOptions, trace_one};
use foton_tests::{header, region_mean, render_toml, temp_dir, write};
use glam::{DVec3, Vec3};
use std::path::PathBuf;

const L: [f32; 3] = [1.0, 0.8, 0.6];

const CONSTANT: &str = r#"
[[lights]]
type = "constant"
radiance = [1.0, 0.8, 0.6]
"#;

/// A 6 x 4 OpenEXR image of L everywhere (scale 2 brings its 0.5 L back to L) in a folder of
/// its own, and the `[[lights]]` table of an envmap reading it, turned about an oblique axis.
fn constant_envmap(name: &str) -> (PathBuf, String) {
    let dir = temp_dir(name);
    let texels: Vec<f32> = (0..24).flat_map(|_| L.map(|c| 0.5 * c)).collect();
    let path = dir.join("sky.exr");
    image::Rgb32FImage::from_raw(6, 4, texels)
        .unwrap()
        .save(&path)
        .unwrap();
    let light = format!(
        r#"
[[lights]]
type = "envmap"
filename = "{}"
scale = 2.0
to_world = {{ rotate = {{ axis = [1, 1, 0], degrees = 40 }} }}
"#,
        path.display()
    );
    (dir, light)
}

fn scene(integrator: &str, spp: u32, light: &str) -> String {
    header(integrator, spp, 4, 32, 32)
        + r#"
[camera]
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40.0

[integrators.photon]
global_photons = 200000
caustic_photons = 0
k = 50

[integrators.sppm]
iterations = 16
photons_per_iteration = 50000

[integrators.vpm]
global_photons = 200000
caustic_photons = 0

[materials.grey]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "grey"
"# + light
}

/// The sphere's centre (8x8 pixels) is rho L = [0.5, 0.4, 0.3] within 3% (path: 64 spp of
/// MIS between the environment's samples and the BSDF's; the photon mappers' shadow rays);
/// the image's corners see the environment itself, L exactly.
#[test]
fn a_diffuse_sphere_in_a_constant_environment_shows_rho_l() {
    let rho_l = Vec3::from(L) * 0.5;
    for (integrator, spp) in [("path", 64), ("photon", 16), ("sppm", 1), ("vpm", 16)] {
        let film = render_toml("environment", &scene(integrator, spp, CONSTANT), &[], 2);
        let (centre, _) = region_mean(&film, 12, 12, 20, 20);
        let rel = ((centre - rho_l) / rho_l).abs().max_element();
        assert!(
            rel < 0.03,
            "{integrator}: sphere {centre} against rho L {rho_l} ({rel})"
        );
        assert_eq!(film.pixel(0, 0), Vec3::from(L), "{integrator}: background");
    }
}

/// The same with the constant environment given as an envmap (path: light samples drawn
/// through the image's distribution, MIS against the BSDF's; photon: its photons).
#[test]
fn a_diffuse_sphere_in_a_constant_envmap_shows_rho_l() {
    let rho_l = Vec3::from(L) * 0.5;
    let (dir, light) = constant_envmap("envmap-render");
    for (integrator, spp) in [("path", 64), ("photon", 16)] {
        let film = render_toml("envmap", &scene(integrator, spp, &light), &[], 2);
        // The photon mapper's direct light is light sampling alone: a relative standard
        // deviation of about 1.3 per sample, so 4 standard errors of the block's mean.
        let (centre, se) = region_mean(&film, 12, 12, 20, 20);
        let off = ((centre - rho_l).abs() - 4.0 * se).max_element();
        assert!(
            off < 0.005,
            "{integrator}: sphere {centre} against rho L {rho_l} (standard error {se})"
        );
        let background = film.pixel(0, 0);
        assert!(
            ((background - Vec3::from(L)) / Vec3::from(L))
                .abs()
                .max_element()
                < 1e-5,
            "{integrator}: background {background}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// The environment's photons: those whose first hit is the unit sphere carry, in all, the
/// irradiance pi L times its area 4 pi (every point of a convex shape sees the whole
/// environment above it). Binomial noise of the share of photons that hit it: 4 sigma.
#[test]
fn environment_photons_deliver_pi_l_everywhere() {
    environment_photons(CONSTANT);
}

#[test]
fn envmap_photons_deliver_pi_l_everywhere() {
    let (dir, light) = constant_envmap("envmap-photons");
    environment_photons(&light);
    let _ = std::fs::remove_dir_all(dir);
}

fn environment_photons(light: &str) {
    let dir = temp_dir("environment-photons");
    let path = write(&dir, "scene.toml", &scene("photon", 1, light));
    let scene = foton_loader::load(&path, &[]).unwrap();
    let _ = std::fs::remove_dir_all(dir);
    let power = scene.lights()[0].power().as_dvec3();
    let opts = TraceOptions {
        photons: 200_000,
        max_depth: 1,
        seed: 8,
        stream: STREAM_GLOBAL,
        stop_at_diffuse: true,
        sobol_emission: false,
    };
    let sources = foton_photonmap::sources::Sources::new(&scene).unwrap();
    let mut total = DVec3::ZERO;
    for i in 0..opts.photons {
        trace_one(&scene, &opts, &sources, i, |p, _, _| {
            total += p.power().as_dvec3()
        });
    }
    let want = Vec3::from(L).as_dvec3() * (4.0 * std::f64::consts::PI.powi(2));
    let q = want.x / power.x;
    let sigma = ((1.0 - q) / (q * opts.photons as f64)).sqrt();
    let rel = ((total - want) / want).abs().max_element();
    assert!(
        rel < 4.0 * sigma,
        "{total} against {want} ({rel}, sigma {sigma})"
    );
}

/// A scene has one environment at most; an envmap's image must be readable.
#[test]
fn envmap_errors_name_the_key_and_the_file() {
    let (dir, light) = constant_envmap("envmap-errors");
    let load = |text: &str| {
        let d = temp_dir("envmap-errors-scene");
        let path = write(&d, "scene.toml", text);
        let e = foton_loader::load(&path, &[])
            .map(|_| ())
            .unwrap_err()
            .to_string();
        let _ = std::fs::remove_dir_all(d);
        e
    };
    let e = load(&(scene("path", 1, CONSTANT) + &light));
    assert!(e.contains("at most one environment light"), "{e}");
    let missing = light.replace("sky.exr", "nowhere.exr");
    let e = load(&scene("path", 1, &missing));
    assert!(
        e.contains("lights[0].filename") && e.contains("nowhere.exr"),
        "{e}"
    );
    let squashed = light.replace(
        "rotate = { axis = [1, 1, 0], degrees = 40 }",
        "scale = [1, 2, 1]",
    );
    let e = load(&scene("path", 1, &squashed));
    assert!(
        e.contains("lights[0].to_world") && e.contains("rotation"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// Mitsuba's `<emitter type="envmap">` reads as the TOML envmap: the file relative to the
/// XML's folder, `scale`, and `to_world` turning the map (+z of the map onto +x here).
#[test]
fn the_xml_envmap_is_the_toml_envmap() {
    let dir = temp_dir("envmap-xml");
    // 4 x 3 texels, each its own colour.
    let texels: Vec<f32> = (0..12)
        .flat_map(|i| [i as f32, 1.0 + (i % 3) as f32, 0.5])
        .collect();
    image::Rgb32FImage::from_raw(4, 3, texels)
        .unwrap()
        .save(dir.join("sky.exr"))
        .unwrap();
    let xml = write(
        &dir,
        "scene.xml",
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    </sensor>
    <emitter type="envmap">
        <string name="filename" value="sky.exr"/>
        <float name="scale" value="2"/>
        <transform name="to_world"><rotate y="1" angle="90"/></transform>
    </emitter>
</scene>"#,
    );
    let toml = write(
        &dir,
        "scene.toml",
        r#"
[camera]
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]

[[lights]]
type = "envmap"
filename = "sky.exr"
scale = 2.0
to_world = { rotate = { axis = [0, 1, 0], degrees = 90 } }
"#,
    );
    let from_xml = foton_loader::load(&xml, &[]).unwrap();
    let from_toml = foton_loader::load(&toml, &[]).unwrap();
    let (a, b) = (&from_xml.lights()[0], &from_toml.lights()[0]);
    for d in [
        Vec3::X,
        Vec3::Y,
        -Vec3::Z,
        Vec3::new(0.3, -0.5, 0.8).normalize(),
    ] {
        let (la, lb) = (a.environment(d), b.environment(d));
        assert!(
            (la - lb).abs().max_element() < 1e-5,
            "{d}: {la} against {lb}"
        );
    }
    // The map's +z, the image's centre (between columns 1 and 2 of the middle row: texels 5
    // and 6), turned onto +x, times the scale.
    let centre = a.environment(Vec3::X);
    let want = Vec3::new(5.5, 2.0, 0.5) * 2.0;
    assert!(
        (centre - want).abs().max_element() < 1e-4,
        "{centre} against {want}"
    );
    let _ = std::fs::remove_dir_all(dir);
}
