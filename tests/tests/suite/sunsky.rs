//! The sun and sky (`sunsky`, Mitsuba 0.6's `sunsky`, `sky` and `sun`): a diffuse ground
//! under them shows rho E / pi, where E, the irradiance of a horizontal surface, is found
//! here by integrating the sky model itself (not its rasterised map) over the upper
//! hemisphere, plus the sun's L_sun Omega_sun cos(theta_sun). This checks the map's
//! orientation (+y the zenith, the sun where its direction says), its interpolation and
//! sampling, and the sun's power, in every integrator that renders environment light.

use foton_core::sky::{Spherical, SunSky};
use foton_tests::{header, region_mean, render_toml, temp_dir, write};
use glam::{DVec3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

const SUN: [f64; 3] = [-0.5, 0.6, 0.3];

fn sunsky() -> SunSky {
    let d = DVec3::from(SUN).normalize();
    SunSky {
        sun: Spherical::of(d),
        turbidity: 4.0,
        albedo: DVec3::new(0.1, 0.2, 0.3),
        stretch: 1.0,
        sky_scale: 1.0,
        sun_scale: 0.05,
        sun_radius_scale: 4.0,
        extend: false,
    }
}

/// E on a horizontal surface: the sky by the midpoint rule on a fine (theta, phi) grid,
/// the sun as a small disc at its zenith angle.
fn irradiance(s: &SunSky) -> DVec3 {
    let model = s.model();
    let (nt, np) = (600, 1200);
    let (dt, dp) = (FRAC_PI_2 / nt as f64, 2.0 * PI / np as f64);
    let mut e = DVec3::ZERO;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) * dt;
        for j in 0..np {
            let phi = (j as f64 + 0.5) * dp;
            let l = s.sky_radiance(&model, Spherical { theta, phi });
            e += l * (theta.cos() * theta.sin() * dt * dp);
        }
    }
    e + s.sun_radiance() * SunSky::sun_solid_angle() * s.sun.theta.cos()
}

fn scene(integrator: &str, spp: u32) -> String {
    let s = sunsky();
    header(integrator, spp, 1, 16, 16)
        + &format!(
            r#"
[camera]
position = [0.0, 3.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = 20.0

[integrators.photon]
global_photons = 400000
caustic_photons = 0

[integrators.sppm]
iterations = 16
photons_per_iteration = 100000

[materials.ground]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[[shapes]]
type = "quad"
origin = [-2.0, 0.0, 2.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 0.0, -4.0]
material = "ground"

[[lights]]
type = "sunsky"
sun_direction = {sun:?}
turbidity = {turbidity}
albedo = [{a0}, {a1}, {a2}]
sky_scale = {sky}
sun_scale = {sun_scale}
sun_radius_scale = {radius}
to_world = {{ rotate = {{ axis = [0, 1, 0], degrees = 35 }} }}
"#,
            sun = SUN,
            turbidity = s.turbidity,
            a0 = s.albedo.x,
            a1 = s.albedo.y,
            a2 = s.albedo.z,
            sky = s.sky_scale,
            sun_scale = s.sun_scale,
            radius = s.sun_radius_scale,
        )
}

/// A diffuse ground (rho = 1/2) seen from above shows rho E / pi, within 2 % (path: MIS of
/// the map's samples and the BSDF's; bdpt; the photon mappers' photons emitted through the
/// map's distribution). The rotation of the light's frame turns the map and the sun's
/// direction with it, which leaves E unchanged: the sun's direction is given in world space.
#[test]
fn a_ground_under_the_sun_and_sky_shows_rho_e_over_pi() {
    let want = (irradiance(&sunsky()) * (0.5 / PI)).as_vec3();
    assert!(want.min_element() > 0.0);
    for (integrator, spp) in [("path", 64), ("bdpt", 32), ("photon", 16), ("sppm", 4)] {
        let film = render_toml("sunsky", &scene(integrator, spp), &[], 2);
        let (mean, se) = region_mean(&film, 2, 2, 14, 14);
        let rel = ((mean - want) / want).abs().max_element();
        assert!(
            rel < 0.02,
            "{integrator}: ground {mean} (standard error {se}) against rho E / pi {want} ({rel})"
        );
    }
}

/// Mitsuba 0.6's `sun` of radius 0 is the directional light of the true sun's irradiance
/// (Mitsuba's own substitution); its `sky` is the map without the sun; its `sunsky` with
/// a date, a time and a place finds the sun as the TOML light does.
#[test]
fn mitsuba_sun_and_sky_read_as_mitsuba_makes_them() {
    let dir = temp_dir("sunsky-xml");
    let load = |name: &str, emitter: &str| {
        let path = write(
            &dir,
            name,
            &format!(
                r#"<scene version="0.6.0">
    <sensor type="perspective">
        <transform name="toWorld"><lookat origin="0, 1, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    </sensor>
    {emitter}
</scene>"#
            ),
        );
        foton_loader::load(&path, &[]).unwrap()
    };
    let sun = load(
        "sun.xml",
        r#"<emitter type="sun"><vector name="sunDirection" x="-0.5" y="0.6" z="0.3"/>
            <float name="sunRadiusScale" value="0"/><float name="turbidity" value="4"/></emitter>"#,
    );
    let lights = sun.lights();
    assert_eq!(lights.len(), 1);
    let s = SunSky {
        sun_scale: 1.0,
        ..sunsky()
    };
    let e = (s.sun_radiance() * SunSky::sun_solid_angle()).as_vec3();
    let toward = Vec3::from(SUN.map(|x| x as f32)).normalize();
    // A directional light's power is its irradiance times the scene disc's area: compare
    // the direct light it gives a point facing it.
    let ls = lights[0]
        .sample_li(Vec3::ZERO, glam::Vec2::splat(0.5), 0.5)
        .expect("a directional light sample");
    assert!(ls.delta, "a sun of radius 0 is a delta light");
    assert!(
        (ls.wi - toward).length() < 1e-5,
        "{} against {toward}",
        ls.wi
    );
    assert!(
        ((ls.li - e) / e).abs().max_element() < 1e-4,
        "{} against {e}",
        ls.li
    );

    let sky = load(
        "sky.xml",
        r#"<emitter type="sky"><vector name="sunDirection" x="-0.5" y="0.6" z="0.3"/>
            <float name="turbidity" value="4"/></emitter>"#,
    );
    // Towards the sun, the sky alone: the circumsolar sky (the model's, up to the map's
    // interpolation of its peak), not the sun's disc (thousands of times brighter).
    let l = sky.lights()[0].environment(toward);
    let model = s.model();
    let want = s.sky_radiance(&model, s.sun).as_vec3();
    assert!(
        l.cmpgt(want * 0.5).all() && l.cmplt(want * 2.0).all(),
        "the sky towards the sun {l} against the model's {want}"
    );
    assert!(s.sun_radiance().min_element() > 100.0 * want.max_element() as f64);

    let dated = load(
        "dated.xml",
        r#"<emitter type="sunsky"><float name="hour" value="11"/><float name="sunScale" value="0.01"/>
            <transform name="toWorld"><rotate y="1" angle="90"/></transform></emitter>"#,
    );
    let toml = write(
        &dir,
        "dated.toml",
        r#"
[camera]
position = [0.0, 1.0, 4.0]
look_at = [0.0, 0.0, 0.0]

[[lights]]
type = "sunsky"
hour = 11.0
sun_scale = 0.01
to_world = { rotate = { axis = [0, 1, 0], degrees = 90 } }
"#,
    );
    let from_toml = foton_loader::load(&toml, &[]).unwrap();
    for d in [Vec3::Y, Vec3::new(0.3, 0.5, -0.8).normalize(), Vec3::X] {
        let (a, b) = (
            dated.lights()[0].environment(d),
            from_toml.lights()[0].environment(d),
        );
        assert!(
            (a - b).abs().max_element() <= 1e-6 * b.max_element(),
            "{d}: {a} against {b}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// What Mitsuba 0.6 refuses, foton refuses, saying which parameter.
#[test]
fn sunsky_errors_name_the_parameter() {
    let dir = temp_dir("sunsky-errors");
    let load = |extra: &str| {
        let path = write(
            &dir,
            "scene.toml",
            &format!(
                "[camera]\nposition = [0.0, 1.0, 4.0]\nlook_at = [0.0, 0.0, 0.0]\n\n[[lights]]\ntype = \"sunsky\"\n{extra}\n"
            ),
        );
        foton_loader::load(&path, &[])
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    for (extra, key, want) in [
        ("turbidity = 12.0", "turbidity", "must be in [1, 10]"),
        (
            "sun_direction = [0.0, -1.0, 0.2]",
            "sun_direction",
            "below the horizon",
        ),
        ("hour = 23.0", "hour", "below the horizon"),
        (
            "sun_direction = [0.0, 1.0, 0.0]\nhour = 9.0",
            "hour",
            "not both",
        ),
        (
            "sun_radius_scale = 0.0",
            "sun_radius_scale",
            "`directional` light",
        ),
        ("stretch = 3.0", "stretch", "must be in [1, 2]"),
    ] {
        let e = load(extra);
        assert!(
            e.contains(want) && e.contains(&format!("lights[0].{key}")),
            "{extra}: {e}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}
