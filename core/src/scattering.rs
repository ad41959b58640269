//! What every scattering model shares, below them all (pbrt-v4's `util/scattering.h` and the
//! `TransportMode` of `base/bxdf.h`): the quantity a path carries, the Fresnel terms, the
//! reflected and refracted directions, and a lobe's local sample. `bsdf` (the smooth lobes),
//! `glossy` (the microfacet lobes) and `material` (which builds them) use it; it uses none of
//! them, so that the three do not import each other in a circle.

use crate::Rgb;
use glam::Vec3;

/// Which quantity a path carries: radiance (camera paths) or importance/flux (photon paths).
/// It matters at refraction, where radiance is scaled by 1/eta^2 and flux is not (Veach 1997,
/// non-symmetric scattering due to refraction).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    Radiance,
    Importance,
}

/// Unpolarised Fresnel reflectance of a dielectric interface. `cos_i` >= 0 is the cosine on
/// the incident side, `eta` = n_transmitted / n_incident.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0; // total internal reflection
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Unpolarised Fresnel reflectance of a conductor with complex index of refraction eta + i k
/// (relative to the incident side) at incident cosine `cos_i`: the dielectric formulas with a
/// complex eta, cos_t = sqrt(1 - sin^2 i / eta^2), F = (|r_parallel|^2 + |r_perpendicular|^2) / 2.
pub fn fresnel_conductor(cos_i: f32, eta: f32, k: f32) -> f32 {
    #[derive(Clone, Copy)]
    struct C(f64, f64);
    let mul = |a: C, b: C| C(a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let div = |a: C, b: C| {
        let d = b.0 * b.0 + b.1 * b.1;
        C((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    let sqrt = |a: C| {
        let r = (a.0 * a.0 + a.1 * a.1).sqrt();
        let re = ((r + a.0) / 2.0).max(0.0).sqrt();
        let im = ((r - a.0) / 2.0).max(0.0).sqrt().copysign(a.1);
        C(re, im)
    };
    let norm = |a: C| a.0 * a.0 + a.1 * a.1;
    let cos_i = (cos_i as f64).clamp(0.0, 1.0);
    let eta = C(eta as f64, k as f64);
    if norm(eta) == 0.0 {
        return 1.0;
    }
    let sin2_t = div(C(1.0 - cos_i * cos_i, 0.0), mul(eta, eta));
    let cos_t = sqrt(C(1.0 - sin2_t.0, -sin2_t.1));
    let eci = C(eta.0 * cos_i, eta.1 * cos_i);
    let ect = mul(eta, cos_t);
    let r_parl = div(
        C(eci.0 - cos_t.0, eci.1 - cos_t.1),
        C(eci.0 + cos_t.0, eci.1 + cos_t.1),
    );
    let r_perp = div(C(cos_i - ect.0, -ect.1), C(cos_i + ect.0, ect.1));
    (0.5 * (norm(r_parl) + norm(r_perp))) as f32
}

/// Mirror reflection of `wo` about the normal `n` (a surface's, or a microfacet's).
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * wo.dot(n) * n - wo
}

/// Refracts `wo` (pointing away from the surface, on the side of `n`) through the interface;
/// `eta` = n_transmitted / n_incident. None on total internal reflection.
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wo.dot(n);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + (cos_i / eta - cos_t) * n).normalize())
}

/// A sampled direction in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalSample {
    pub wi: Vec3,
    pub weight: Rgb,
    pub pdf: f32,
    pub delta: bool,
}
