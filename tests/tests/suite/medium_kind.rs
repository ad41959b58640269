//! `Medium` is the interface every integrator uses: a second kind of medium, written here in
//! the tests and unknown to core and to the plugins, is rendered by `path` and `vpm` through it
//! alone (free-flight sampling, transmittance, sigma_s and the phase function).
//!
//! The kind: a grey medium whose extinction grows linearly with height, sigma_t(p) = a + b p.y,
//! with a constant single-scattering albedo. Its optical depth along a ray is a quadratic in
//! the distance, so transmittance and free-flight sampling have closed forms.

use foton_cli::{TermProgress, prepare, render_prepared};
use foton_core::Rgb;
use foton_core::film::Film;
use foton_core::geometry::Ray;
use foton_core::medium::{FreeFlight, Medium, Phase};
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, plugin_dir, temp_dir, write};
use glam::{Vec2, Vec3};

#[derive(Debug)]
struct Ramp {
    a: f32,
    b: f32,
    albedo: f32,
}

impl Ramp {
    fn sigma(&self, p: Vec3) -> f32 {
        (self.a + self.b * p.y).max(0.0)
    }

    /// Optical depth along `ray` from its origin to distance t.
    fn depth(&self, ray: &Ray, t: f32) -> f32 {
        self.a * t + self.b * (ray.origin.y * t + 0.5 * ray.dir.y * t * t)
    }
}

impl Medium for Ramp {
    fn is_vacuum(&self) -> bool {
        false
    }
    fn sigma_a(&self, p: Vec3) -> Rgb {
        Rgb::splat(self.sigma(p) * (1.0 - self.albedo))
    }
    fn sigma_s(&self, p: Vec3) -> Rgb {
        Rgb::splat(self.sigma(p) * self.albedo)
    }
    fn phase(&self) -> Phase {
        Phase::Isotropic
    }
    fn transmittance(&self, ray: &Ray, d: f32) -> Rgb {
        if d.is_finite() {
            Rgb::splat((-self.depth(ray, d)).exp())
        } else {
            Rgb::ZERO
        }
    }
    fn sample_free_flight(&self, ray: &Ray, tmax: f32, _channel: usize, u: f32) -> FreeFlight {
        // Solve depth(t) = tau: (b d.y / 2) t^2 + sigma(origin) t - tau = 0, the smaller
        // positive root in the form that stays exact as the quadratic term vanishes.
        let tau = -(1.0 - u).ln();
        let (qa, qb) = (0.5 * self.b * ray.dir.y, self.sigma(ray.origin));
        let disc = qb * qb + 4.0 * qa * tau;
        let t = if disc < 0.0 || qb + disc.sqrt() <= 0.0 {
            f32::INFINITY
        } else {
            2.0 * tau / (qb + disc.sqrt())
        };
        if t < tmax {
            let (sigma_t, tr) = (self.sigma(ray.at(t)), (-tau).exp());
            FreeFlight {
                t,
                scattered: true,
                f: Rgb::splat(self.albedo * sigma_t * tr),
                pdf: Rgb::splat(sigma_t * tr),
                emitted: Rgb::ZERO,
            }
        } else {
            let tr = self.transmittance(ray, tmax);
            FreeFlight {
                t: tmax,
                scattered: false,
                f: tr,
                pdf: tr,
                emitted: Rgb::ZERO,
            }
        }
    }
}

const SIZE: u32 = 16;
const RADIUS: f32 = 0.5;

/// A sphere of medium (radius 0.5 at the origin, a null boundary) in front of an emissive
/// backdrop (radiance 1, facing the camera), seen from z = 3 through a field of view that the
/// sphere fills (no pixel straddles its silhouette); the `fog` placeholder is replaced by a
/// `Ramp` before rendering.
fn scene(integrator: &str, spp: u32) -> String {
    header(integrator, spp, 8, SIZE, SIZE)
        + r#"
[camera]
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 12.0

[integrators.vpm]
global_photons = 20000
caustic_photons = 0
k = 5
volume_photons = 200000
k_volume = 50
max_radius_volume = 0.1
step = 0.01

[materials.boundary]
type = "null"
[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[media.fog]
type = "homogeneous"
sigma_a = [1.0, 1.0, 1.0]

[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 0.5
material = "boundary"
interior = "fog"

[[shapes]]
type = "quad"
origin = [-2.0, -2.0, -1.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 4.0, 0.0]
material = "black"
emission = [1.0, 1.0, 1.0]
"#
}

fn render_with(
    name: &str,
    integrator: &str,
    spp: u32,
    ramp: Ramp,
) -> (Film, foton_core::camera::Camera) {
    let dir = temp_dir(name);
    let path = write(&dir, "scene.toml", &scene(integrator, spp));
    let mut p = prepare(&path, &[], &[plugin_dir()], true).unwrap_or_else(|e| panic!("{e}"));
    p.scene.media_mut()[0].value = Box::new(ramp);
    let (film, _) = render_prepared(&p, 2, &TermProgress::new(true)).unwrap();
    let _ = std::fs::remove_dir_all(dir);
    (film, p.scene.camera().clone())
}

/// exp(-optical depth) through the sphere along the camera ray through film position `at`.
fn exact_transmittance(camera: &foton_core::camera::Camera, ramp: &Ramp, at: Vec2) -> f32 {
    let ray = camera.generate_ray(at);
    let b = ray.origin.dot(ray.dir);
    let c = ray.origin.length_squared() - RADIUS * RADIUS;
    let disc = b * b - c;
    if disc <= 0.0 {
        return 1.0;
    }
    let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
    let entry = Ray::new(ray.at(t0), ray.dir);
    (-ramp.depth(&entry, t1 - t0)).exp()
}

/// The pixel's mean over its area (8 x 8 positions) of the exact transmittance.
fn exact_pixel(camera: &foton_core::camera::Camera, ramp: &Ramp, x: u32, y: u32) -> f32 {
    let mut sum = 0.0;
    for j in 0..8 {
        for i in 0..8 {
            let at = Vec2::new(
                x as f32 + (i as f32 + 0.5) / 8.0,
                y as f32 + (j as f32 + 0.5) / 8.0,
            );
            sum += exact_transmittance(camera, ramp, at);
        }
    }
    sum / 64.0
}

fn absorber() -> Ramp {
    Ramp {
        a: 1.0,
        b: 1.6,
        albedo: 0.0,
    }
}

/// A pure absorber: `vpm` multiplies by the medium's transmittance, which is exact, so each
/// pixel matches the closed form up to the sampling of the pixel's area (the transmittance
/// varies by up to about 0.1 across a pixel near the sphere's rim: 256 samples, within 0.01); `path` samples free flights, passing with probability Tr, so its pixels are binary
/// estimates of it: compared by blocks against the closed form within their standard error.
#[test]
fn a_medium_kind_of_the_tests_renders_through_the_medium_interface() {
    let (film, camera) = render_with("ramp-vpm", "vpm", 256, absorber());
    let ramp = absorber();
    let mut darkest = 1.0f32;
    for y in 0..SIZE {
        for x in 0..SIZE {
            let exact = exact_pixel(&camera, &ramp, x, y);
            darkest = darkest.min(exact);
            let got = film.pixel(x, y);
            assert!(
                (got - Rgb::splat(exact)).abs().max_element() < 0.01,
                "vpm pixel ({x}, {y}): {got} against exp(-tau) = {exact}"
            );
        }
    }
    // The medium matters: through its thick top the backdrop is well dimmed.
    assert!(darkest < 0.5, "{darkest}");

    let (film, camera) = render_with("ramp-path", "path", 256, absorber());
    let mut exact = Film::new(SIZE, SIZE);
    for y in 0..SIZE {
        for x in 0..SIZE {
            exact.set_pixel(x, y, Rgb::splat(exact_pixel(&camera, &ramp, x, y)));
        }
    }
    let tolerance = Tolerance {
        rel: 0.02,
        z: 4.0,
        floor: 0.0,
    };
    assert_blocks_agree("path through the ramp medium", &film, &exact, 4, tolerance);
}

/// With scattering (albedo 0.8), `vpm` (volume photons traced through the ramp by its
/// free-flight sampler, single scattering from its sigma_s) and `path` agree by blocks: both
/// use nothing of the medium but the interface.
#[test]
fn vpm_and_path_agree_in_a_scattering_medium_of_another_kind() {
    let ramp = || Ramp {
        a: 1.0,
        b: 1.6,
        albedo: 0.8,
    };
    let (vpm, _) = render_with("ramp-vpm-scattering", "vpm", 16, ramp());
    let (path, _) = render_with("ramp-path-scattering", "path", 1024, ramp());
    let tolerance = Tolerance {
        rel: 0.05,
        z: 4.0,
        floor: 0.0,
    };
    assert_blocks_agree(
        "vpm against path, scattering ramp",
        &vpm,
        &path,
        4,
        tolerance,
    );
}
