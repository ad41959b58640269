//! What the progressive integrators (`sppm`, `ppb`) share: the global radius schedule of
//! Knaus and Zwicker, the automatic first radius from a pixel's footprint, and the gather of
//! one iteration's photons on a disc around a camera path's visible point.

use crate::map::{DISC_THICKNESS, PhotonMap};
use foton_core::Rgb;
use foton_core::kernel::NormalizedKernel;
use foton_core::render::usable;
use foton_core::scene::Scene;
use foton_core::walk::VisiblePoint;
use glam::{DVec3, Vec2};

/// Knaus and Zwicker's radius schedule: the factor prod_{j=1}^{i-1} (j + alpha) / (j + 1) of
/// iteration i (1-based). It falls like i^(alpha - 1). Applied to r^2 for a 2-D kernel
/// (surfaces: r_i^2 = r_1^2 x factor) and to r for a 1-D kernel (photon beams, Jarosz et al.
/// 2011: r_i = r_1 x factor): in both the kernel's support, and with it the photons an
/// iteration gathers, shrinks by the factor, slowly enough that the average over iterations
/// converges: variance and bias both vanish.
pub fn global_radius2_scale(iteration: u64, alpha: f64) -> f64 {
    (1..iteration).fold(1.0, |s, j| s * (j as f64 + alpha) / (j as f64 + 1.0))
}

/// The angle one pixel subtends at the centre of the image.
pub fn pixel_angle(scene: &Scene) -> f32 {
    let (w, h) = (scene.film.width as f32, scene.film.height as f32);
    let a = scene.camera.generate_ray(Vec2::new(w / 2.0, h / 2.0)).dir;
    let b = scene
        .camera
        .generate_ray(Vec2::new(w / 2.0, h / 2.0 + 1.0))
        .dir;
    a.dot(b).clamp(-1.0, 1.0).acos()
}

/// The automatic first gather radius of a pixel whose visible point lies `distance` along
/// the camera path: three times the pixel's footprint there, kept within [1/1000, 1/50] of the
/// scene's bounding-box diagonal (a few pixels wide, so that early iterations find photons,
/// and small against the scene; an infinite distance gets the largest).
pub fn auto_radius(scene: &Scene, pixel_angle: f32, distance: f32) -> f64 {
    let diagonal = (scene.bounds.1 - scene.bounds.0).length().max(1e-6) as f64;
    (3.0 * pixel_angle as f64 * distance as f64).clamp(diagonal / 1000.0, diagonal / 50.0)
}

/// One gather: the (kernel-weighted) photon count and the reflected flux.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Gathered {
    /// Weighted count M: each photon counts w = pi r^2 K(d, r) (1 for the box).
    pub m: f64,
    /// Reflected flux Phi = sum_p f(x, w_p, w) Phi_p w_p (not weighted by the path's
    /// throughput).
    pub phi: DVec3,
    /// Contributions that were not finite and non-negative, left out.
    pub bad: u64,
}

/// Gathers the photons of `map` within `r` of the visible point `vp` that lie on a disc of
/// its surface: the same side (stored normal within about 25 degrees of the point's), no
/// farther from the tangent plane than [`DISC_THICKNESS`] of r, and of at most `depth`
/// scattering events.
pub fn gather_disc(
    map: &PhotonMap,
    vp: &VisiblePoint,
    r: f32,
    depth: u32,
    kernel: &NormalizedKernel,
) -> Gathered {
    let disc = std::f32::consts::PI * r * r;
    let thickness = DISC_THICKNESS * r;
    let mut g = Gathered::default();
    map.within(vp.hit.p, r, |photon, d2| {
        if photon.depth() > depth
            || photon.normal().dot(vp.n) <= 0.9
            || (photon.position - vp.hit.p).dot(vp.n).abs() > thickness
        {
            return; // too long, another surface, or its other side
        }
        let w = kernel.weight_2d(d2.sqrt(), r) * disc;
        let f = vp.bsdf.eval_density(vp.wo, photon.wi());
        let flux: Rgb = f * photon.power() * w;
        if !(usable(flux) && w.is_finite() && w >= 0.0) {
            g.bad += 1;
            return;
        }
        g.m += w as f64;
        g.phi += flux.as_dvec3();
    });
    g
}
