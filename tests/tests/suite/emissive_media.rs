//! Media that emit (pbrt-v4's `Le`): sigma_a Le per metre along a ray, in the integrators
//! that render it, against closed forms and against `path`; photons leave it with its power.

use foton_core::Rgb;
use foton_core::geometry::Ray;
use foton_core::medium::Medium;
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, region_mean, render_toml, repo_root};
use glam::Vec3;

/// A cube [-1, 1]^3 of `medium` (TOML of `[media.glow]`) behind a null boundary, seen by an
/// orthographic camera along -z: every ray crosses 2 m of it, and nothing else.
fn slab(integrator: &str, spp: u32, medium: &str) -> String {
    header(integrator, spp, 8, 8, 8)
        + &format!(
            r#"
[camera]
type = "orthographic"
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
view_height = 1.0

[materials.boundary]
type = "null"

[media.glow]
{medium}

[[shapes]]
type = "mesh"
file = "{cube}"
material = "boundary"
interior = "glow"

[[lights]]
type = "point"
position = [0.0, 0.0, -40.0]
intensity = [0.0, 0.0, 0.0]
"#,
            cube = repo_root().join("scenes/meshes/cube.obj").display()
        )
}

/// A camera at the origin inside `medium` (TOML of `[media.glow]`), the scene's medium that
/// fills all space, and a point light of `intensity` 4 m ahead.
fn glow_everywhere(
    integrator: &str,
    spp: u32,
    max_depth: u32,
    medium: &str,
    intensity: f32,
) -> String {
    header(integrator, spp, max_depth, 8, 8)
        + &format!(
            r#"
[scene]
medium = "glow"

[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
up = [0.0, 1.0, 0.0]
fov = 60.0

[media.glow]
{medium}

[[lights]]
type = "point"
position = [0.0, 0.0, -4.0]
intensity = [{intensity}, {intensity}, {intensity}]
"#
        )
}

/// The mean over the image and its standard error.
fn image_mean(film: &foton_core::film::Film) -> (Vec3, Vec3) {
    region_mean(film, 0, 0, film.width, film.height)
}

fn assert_within(what: &str, got: (Vec3, Vec3), want: Vec3, rel: f32) {
    let (mean, se) = got;
    for c in 0..3 {
        let err = (mean[c] - want[c]).abs();
        assert!(
            err <= rel * want[c] + 4.0 * se[c],
            "{what}: channel {c}: {} against {} (standard error {})",
            mean[c],
            want[c],
            se[c]
        );
    }
}

/// A purely absorbing medium whose emission falls linearly from a + b where the rays enter to
/// a where they leave, 2 m on: L = int_0^2 sigma e^(-sigma t) (a + b (1 - t/2)) dt
/// = (a + b)(1 - e^(-2 sigma)) - (b / 2)(1 - e^(-2 sigma)(1 + 2 sigma)) / sigma, per channel
/// (sigma coloured: the spectral MIS of the emission estimate).
#[test]
fn an_absorbing_slab_with_an_emission_gradient_shows_its_integral() {
    let sigma = Vec3::new(0.3, 1.0, 2.0);
    let (a, b) = (Vec3::new(1.0, 0.5, 2.0), Vec3::new(3.0, 1.0, 0.5));
    let e2 = (-2.0 * sigma).exp();
    let want =
        (a + b) * (Vec3::ONE - e2) - b / 2.0 * (Vec3::ONE - e2 * (Vec3::ONE + 2.0 * sigma)) / sigma;
    // Two samples along z on the cube's corners: z = -1 (where rays leave) and z = +1.
    let lo = a;
    let hi = a + b;
    let medium = format!(
        r#"type = "heterogeneous"
sigma_t = [{}, {}, {}]
density = 1.0
albedo = 0.0
emission = {{ resolution = [1, 1, 2], values = [{}, {}, {}, {}, {}, {}], samples = "corners", transform = {{ translate = [-1.0, -1.0, -1.0], scale = [2.0, 2.0, 2.0] }} }}
"#,
        sigma.x, sigma.y, sigma.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
    );
    for integrator in ["path", "bdpt"] {
        let film = render_toml(
            &format!("emission-slab-{integrator}"),
            &slab(integrator, 1024, &medium),
            &[],
            2,
        );
        assert_within(
            &format!("{integrator}, emission gradient"),
            image_mean(&film),
            want,
            0.01,
        );
    }
}

/// In an emitting medium that fills all space, radiance is Le everywhere, whatever the
/// albedo: L = int_0^inf e^(-sigma_t t) (sigma_s L + sigma_a Le) dt gives
/// sigma_t L = sigma_s L + sigma_a Le, so L = Le (the furnace of emission). Coloured
/// coefficients; the camera in the medium, scattered paths collecting emission at every
/// event.
#[test]
fn an_emitting_medium_filling_space_is_in_equilibrium() {
    let le = Vec3::new(1.0, 2.0, 0.5);
    let medium = "type = \"homogeneous\"\nsigma_a = [0.5, 0.2, 1.0]\nsigma_s = [0.5, 0.8, 0.25]\nemission = [1.0, 2.0, 0.5]";
    for integrator in ["path", "bdpt"] {
        let film = render_toml(
            &format!("emission-furnace-{integrator}"),
            &glow_everywhere(integrator, 64, 400, medium, 0.0),
            &[],
            2,
        );
        assert_within(
            &format!("{integrator}, emitting medium everywhere"),
            image_mean(&film),
            le,
            0.01,
        );
    }
}

/// The estimate of one free-flight sample: emission weight times the integrand equals, in
/// expectation, int_0^tmax Tr sigma_a Le dt; here checked exactly for the pieces it is made of
/// (the medium's `emitted` at an event is Tr(t) sigma_a Le, zero when passing).
#[test]
fn a_free_flight_event_carries_the_emission_integrand() {
    let m = foton_core::medium::Homogeneous {
        sigma_a: Rgb::new(0.5, 1.0, 0.0),
        sigma_s: Rgb::new(0.5, 0.0, 1.0),
        phase: foton_core::medium::Phase::Isotropic,
        emission: Rgb::new(2.0, 3.0, 4.0),
    };
    assert!(m.is_emissive());
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    let f = m.sample_free_flight(&ray, 100.0, 0, 0.5);
    assert!(f.scattered);
    let tr = (-(m.sigma_a + m.sigma_s) * f.t).exp();
    let want = m.sigma_a * m.emission * tr;
    assert!(
        (f.emitted - want).abs().max_element() < 1e-6,
        "{:?} against {want:?}",
        f.emitted
    );
    let passed = m.sample_free_flight(&ray, 1e-3, 0, 0.5);
    assert!(!passed.scattered);
    assert_eq!(passed.emitted, Rgb::ZERO);
    // Not emitting without absorption.
    let clear = foton_core::medium::Homogeneous {
        sigma_a: Rgb::ZERO,
        ..m
    };
    assert!(!clear.is_emissive());
}

/// The power photons leave an emitting medium with is 4 pi int sigma_a Le dV over the region
/// it fills: a homogeneous sphere of radius 1 (its region's box is the cube around it: the
/// points drawn outside the sphere carry nothing) and a cube whose emission grows linearly
/// along x, from 1 to 3 (mean 2).
#[test]
fn photons_leave_an_emitting_medium_with_its_power() {
    use foton_photonmap::sources::Sources;
    let sphere = r#"
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "boundary"
interior = "glow"
"#;
    let homogeneous =
        "type = \"homogeneous\"\nsigma_a = [0.5, 1.0, 2.0]\nemission = [1.0, 2.0, 3.0]\n";
    let ramp = "type = \"heterogeneous\"\ndensity = 1.0\nsigma_t = 2.0\nalbedo = 0.5\nemission = { resolution = [2, 1, 1], values = [1.0, 3.0], samples = \"corners\", transform = { translate = [-1.0, -1.0, -1.0], scale = [2.0, 2.0, 2.0] } }\n";
    let four_pi = 4.0 * std::f64::consts::PI;
    let cases = [
        (
            "sphere",
            slab("path", 1, homogeneous).replace(
                &format!(
                    "[[shapes]]\ntype = \"mesh\"\nfile = \"{}\"\nmaterial = \"boundary\"\ninterior = \"glow\"\n",
                    repo_root().join("scenes/meshes/cube.obj").display()
                ),
                sphere,
            ),
            glam::DVec3::new(0.5, 2.0, 6.0) * four_pi * 4.0 / 3.0 * std::f64::consts::PI,
        ),
        // sigma_a = 2 x (1 - 0.5) = 1, the mean emission 2, volume 8.
        ("ramp", slab("path", 1, ramp), glam::DVec3::splat(four_pi * 2.0 * 8.0)),
    ];
    for (name, toml, want) in cases {
        assert!(toml.contains("interior = \"glow\""), "{name}");
        let dir = foton_tests::temp_dir(&format!("emission-power-{name}"));
        let scene =
            foton_loader::load(&foton_tests::write(&dir, "scene.toml", &toml), &[]).unwrap();
        let _ = std::fs::remove_dir_all(dir);
        let sources = Sources::new(&scene).unwrap();
        let mut rng = foton_core::sampling::Rng::new(&[5]);
        let n = 400_000;
        let (mut sum, mut sum2) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
        for _ in 0..n {
            let u = [
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
            ];
            let start = sources
                .sample(
                    &scene,
                    u[0],
                    glam::Vec2::new(u[1], u[2]),
                    glam::Vec2::new(u[3], u[4]),
                    u[5],
                )
                .unwrap();
            // The light of the scene is black: every photon is the medium's.
            assert!(start.from_medium, "{name}");
            let phi = (start.power / start.pdf).as_dvec3();
            sum += phi;
            sum2 += phi * phi;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean) / n as f64)
            .max(glam::DVec3::ZERO)
            .map(f64::sqrt);
        for c in 0..3 {
            assert!(
                (mean[c] - want[c]).abs() <= 4.0 * se[c] + 1e-3 * want[c],
                "{name}: channel {c}: {} against {} (standard error {})",
                mean[c],
                want[c],
                se[c]
            );
        }
    }
}

/// An emitting cloud above a floor lights it, and scatters its own light: `vpm` and `ppb`
/// (photons from the medium, the camera rays' emission through it) against `path`.
#[test]
fn photon_mappers_render_an_emitting_medium_as_path_does() {
    let scene = |integrator: &str, spp: u32, tables: &str| {
        header(integrator, spp, 8, 24, 24)
            + &format!(
                r#"
[camera]
position = [0.0, 1.5, 4.0]
look_at = [0.0, -0.3, 0.0]
up = [0.0, 1.0, 0.0]
fov = 50.0

[materials.boundary]
type = "null"

[materials.floor]
type = "diffuse"
reflectance = [0.6, 0.6, 0.6]

[media.glow]
type = "heterogeneous"
sigma_t = [1.5, 1.5, 1.5]
albedo = [0.6, 0.5, 0.4]
density = 1.0
emission = {{ resolution = [2, 1, 1], values = [0.5, 2.0], samples = "corners", transform = {{ translate = [-0.6, -0.6, -0.6], scale = [1.2, 1.2, 1.2] }} }}

[[shapes]]
type = "mesh"
file = "{cube}"
material = "boundary"
interior = "glow"
transform = {{ scale = [0.6, 0.6, 0.6] }}

[[shapes]]
type = "quad"
origin = [-3.0, -1.0, 3.0]
u = [6.0, 0.0, 0.0]
v = [0.0, 0.0, -6.0]
material = "floor"

[[lights]]
type = "point"
position = [0.0, 3.0, 0.0]
intensity = [0.0, 0.0, 0.0]
{tables}
"#,
                cube = repo_root().join("scenes/meshes/cube.obj").display()
            )
    };
    let path = render_toml("emission-cloud-path", &scene("path", 1024, ""), &[], 2);
    let bdpt = render_toml("emission-cloud-bdpt", &scene("bdpt", 512, ""), &[], 2);
    let exact = Tolerance {
        rel: 0.02,
        z: 4.0,
        floor: 0.0,
    };
    assert_blocks_agree("bdpt against path, emitting cloud", &bdpt, &path, 4, exact);
    let vpm = "[integrators.vpm]\nvolume_photons = 400000\nglobal_photons = 400000";
    let vpm = render_toml("emission-cloud-vpm", &scene("vpm", 64, vpm), &[], 2);
    let biased = Tolerance {
        rel: 0.06,
        z: 4.0,
        floor: 0.0,
    };
    assert_blocks_agree("vpm against path, emitting cloud", &vpm, &path, 4, biased);
    let ppb = "[integrators.ppb]\niterations = 64\nphotons_per_iteration = 10000\nsurface_photons = 10000";
    let ppb = render_toml("emission-cloud-ppb", &scene("ppb", 1, ppb), &[], 2);
    assert_blocks_agree("ppb against path, emitting cloud", &ppb, &path, 4, biased);
}

/// An emitting medium that fills all space has no region to draw photons in: the photon
/// mappers refuse it, naming the medium and what renders it.
#[test]
fn photon_mappers_refuse_an_emitting_medium_around_everything() {
    let medium = "type = \"homogeneous\"\nsigma_a = [1.0, 1.0, 1.0]\nemission = [1.0, 1.0, 1.0]";
    for integrator in ["vpm", "ppb"] {
        let dir = foton_tests::temp_dir(&format!("emission-refused-{integrator}"));
        let toml = glow_everywhere(integrator, 1, 8, medium, 1.0);
        let path = foton_tests::write(&dir, "scene.toml", &toml);
        let run = foton_tests::foton_with_plugins(&[
            "render",
            path.to_str().unwrap(),
            "-o",
            dir.join("out.exr").to_str().unwrap(),
        ]);
        assert_ne!(
            run.code, 0,
            "{integrator} rendered an unbounded emitting medium"
        );
        assert!(
            run.stderr.contains("\"glow\" emits light")
                && run.stderr.contains("use `path` or `bdpt`"),
            "{integrator}: {}",
            run.stderr
        );
        assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
        let _ = std::fs::remove_dir_all(dir);
    }
}
