//! The collimated beam (Mitsuba 0.6's `collimated`): a delta in position and direction, seen
//! only where it strikes. A beam of power P hits a diffuse floor (albedo rho_f) at the origin,
//! which then shines as a point of intensity rho_f P cos(theta) / pi onto a diffuse wall
//! (albedo rho_w) at x = 1; the camera sees the wall alone. The wall's radiance at (1, y, z)
//! is rho_w / pi x rho_f P z / (pi r^4), r^2 = 1 + y^2 + z^2: bidirectional path tracing,
//! vertex connection and merging and stochastic progressive photon mapping render it; the path
//! tracer, whose next-event estimation never reaches a beam, renders black (as Mitsuba's).

use foton_core::film::Film;
use foton_tests::{header, render_toml};
use std::f64::consts::PI;

const POWER: [f64; 3] = [2.0, 1.0, 0.5];
const RHO_F: f64 = 0.5;
const RHO_W: f64 = 0.8;
const SIZE: u32 = 16;
const FOV: f64 = 40.0;

fn scene(integrator: &str, spp: u32) -> String {
    header(integrator, spp, 2, SIZE, SIZE)
        + &format!(
            r#"
[camera]
position = [0.5, 0.0, 0.5]
look_at = [1.0, 0.0, 0.5]
up = [0.0, 0.0, 1.0]
fov = {FOV}

[integrators.vcm]
iterations = 64

[integrators.sppm]
iterations = 64
photons_per_iteration = 20000

[materials.floor]
type = "diffuse"
reflectance = [{RHO_F}, {RHO_F}, {RHO_F}]

[materials.wall]
type = "diffuse"
reflectance = [{RHO_W}, {RHO_W}, {RHO_W}]

[[shapes]]
type = "quad"
origin = [-1.0, -1.0, 0.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "floor"

[[shapes]]
type = "quad"
origin = [1.0, -1.0, 0.0]
u = [0.0, 2.0, 0.0]
v = [0.0, 0.0, 2.0]
material = "wall"

[[lights]]
type = "collimated"
position = [0.0, 0.0, 1.0]
direction = [0.0, 0.0, -1.0]
power = [{}, {}, {}]
"#,
            POWER[0], POWER[1], POWER[2]
        )
}

/// The closed form's mean over the pixels' centres (the camera at (0.5, 0, 0.5) looking along
/// +x: a pixel's ray meets the wall at y, z = 0.5 + 0.5 x the pixel's offsets in the image
/// plane at distance 1; the mean is the same whichever way the image is flipped).
fn expected() -> [f64; 3] {
    let t = (FOV.to_radians() / 2.0).tan();
    let mut sum = 0.0;
    for i in 0..SIZE {
        for j in 0..SIZE {
            let a = ((i as f64 + 0.5) / SIZE as f64 * 2.0 - 1.0) * t;
            let b = ((j as f64 + 0.5) / SIZE as f64 * 2.0 - 1.0) * t;
            let (y, z) = (0.5 * a, 0.5 + 0.5 * b);
            let r2 = 1.0 + y * y + z * z;
            sum += RHO_W / PI * RHO_F * z / (PI * r2 * r2);
        }
    }
    let mean = sum / (SIZE * SIZE) as f64;
    POWER.map(|p| p * mean)
}

fn render(integrator: &str, spp: u32) -> Film {
    render_toml(
        &format!("collimated-{integrator}"),
        &scene(integrator, spp),
        &[],
        0,
    )
}

#[test]
fn a_beam_lights_a_wall_through_the_floor_it_strikes() {
    let want = expected();
    for (integrator, spp, tolerance) in [("bdpt", 64, 0.01), ("vcm", 1, 0.01), ("sppm", 1, 0.02)] {
        let mean = render(integrator, spp).mean();
        for c in 0..3 {
            let got = mean[c] as f64;
            assert!(
                (got / want[c] - 1.0).abs() < tolerance,
                "{integrator}: channel {c}: {got} against {} (the closed form)",
                want[c]
            );
        }
    }
}

/// Next-event estimation never samples the beam and no ray hits it: the path tracer sees
/// nothing of it, as Mitsuba's path tracers do.
#[test]
fn the_path_tracer_renders_a_beam_black() {
    let film = render("path", 4);
    assert_eq!(film.mean(), foton_core::Rgb::ZERO);
}

/// Mitsuba 0.6's `collimated`: the beam leaves the origin of `toWorld` along its +z, with
/// `power` (1 unless given).
#[test]
fn mitsuba_collimated_is_the_beam_along_to_world() {
    let dir = foton_tests::temp_dir("collimated-mitsuba");
    let xml = foton_tests::write(
        &dir,
        "beam.xml",
        r#"<scene version="0.5.0">
    <sensor type="perspective"><float name="fov" value="40"/>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
    <shape type="rectangle"><bsdf type="diffuse"/></shape>
    <emitter type="collimated">
        <rgb name="power" value="3, 2, 1"/>
        <transform name="toWorld"><lookAt origin="0, 0, 2" target="0, 1, 2"/></transform>
    </emitter>
</scene>"#,
    );
    let scene = foton_loader::load(&xml, &[]).unwrap_or_else(|e| panic!("{e}"));
    let light = &scene.lights()[0];
    assert_eq!(light.name(), "collimated");
    let e = light.sample_emission(glam::Vec2::splat(0.5), glam::Vec2::splat(0.5), 0.5);
    assert!(
        (e.origin - glam::Vec3::new(0.0, 0.0, 2.0)).length() < 1e-6,
        "{e:?}"
    );
    assert!((e.dir - glam::Vec3::Y).length() < 1e-6, "{e:?}");
    assert_eq!(light.power(), foton_core::Rgb::new(3.0, 2.0, 1.0));
    assert!(
        light
            .sample_li(glam::Vec3::ZERO, glam::Vec2::splat(0.5), 0.5)
            .is_none()
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// The photons of a beam's first bounce carry all of its power to the spot, and are not
/// classed as direct lighting: next-event estimation never reaches a beam, so the photon
/// mappers render that bounce from photons (as they do an emitting medium's) even where
/// their direct lighting is next-event estimation.
#[test]
fn a_beams_first_bounce_is_left_to_the_photons() {
    use foton_photonmap::trace::{PathClass, STREAM_GLOBAL, TraceOptions, trace_one};
    let dir = foton_tests::temp_dir("collimated-photons");
    let path = foton_tests::write(&dir, "scene.toml", &scene("sppm", 1));
    let scene = foton_loader::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(dir);
    let opts = TraceOptions {
        photons: 1000,
        max_depth: 1,
        seed: 4,
        stream: STREAM_GLOBAL,
        stop_at_diffuse: true,
        sobol_emission: false,
    };
    let sources = foton_photonmap::sources::Sources::new(&scene).unwrap();
    let mut total = glam::DVec3::ZERO;
    for i in 0..opts.photons {
        trace_one(&scene, &opts, &sources, i, |p, _, class| {
            assert_ne!(class, PathClass::Direct);
            assert!(p.position.length() < 1e-4, "{}", p.position);
            total += p.power().as_dvec3();
        });
    }
    let want = glam::DVec3::from(POWER);
    assert!(
        (total - want).abs().max_element() < 1e-3 * want.x,
        "{total} against {want}"
    );
}
