//! What every scattering model shares, below them all (pbrt-v4's `util/scattering.h` and
//! `base/bxdf.h`): the quantity a path carries, the Fresnel terms, the reflected and refracted
//! directions, a lobe's local sample and the [`Bxdf`] interface every lobe implements.
//! `glossy` (the microfacet lobes), `material` (the materials and their lobes) and `bsdf`
//! (which puts a lobe in a frame) use it; it uses none of them, so that they do not import
//! each other in a circle.

use crate::Rgb;
use glam::{Vec2, Vec3};

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

/// The sample of a lobe that drew `wi` for `wo` from the density its `pdf` gives: weighted
/// f cos / pdf (None where that density is zero).
#[inline]
pub fn sampled_direction<B: Bxdf + ?Sized>(lobe: &B, wo: Vec3, wi: Vec3) -> Option<LocalSample> {
    let pdf = lobe.pdf(wo, wi);
    if pdf <= 0.0 {
        return None;
    }
    Some(LocalSample {
        wi,
        weight: lobe.eval(wo, wi) / pdf,
        pdf,
        delta: false,
    })
}

/// A material's scattering at one point in the local shading frame, its textures looked up
/// (pbrt-v4's `BxDF`): z is the shading normal, both directions point away from the surface,
/// `wo` towards the viewer (or where a photon came from), `wi` the other one. `eval` is
/// f(wo, wi) |cos theta_i| (Mitsuba 3's convention: the cosine included), `pdf` the
/// solid-angle density with which `sample` produces `wi` (non-delta parts, times their
/// selection probability), `sample` a direction with the weight f |cos theta_i| / pdf.
pub trait Bxdf {
    /// Whether every part is a Dirac delta (a mirror, smooth glass): such a lobe is only
    /// sampled, never evaluated for a given pair of directions, and photons are not stored
    /// on it.
    const DELTA: bool = false;

    /// Whether this lobe is all Dirac deltas: [`Bxdf::DELTA`] but for a lobe whose kind is
    /// delta only with some parameters (a coating over a smooth metal).
    #[inline]
    fn is_delta(&self) -> bool {
        Self::DELTA
    }

    /// f(wo, wi) |cos theta_i| (zero for a delta lobe).
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb;

    /// The solid-angle density with which `sample` produces `wi` (zero for a delta lobe).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;

    /// Samples `wi` for `wo` (`wo.z` not zero): `u` within a lobe, `uc` between lobes
    /// (reflection or refraction); `mode` scales refraction for radiance. None where the
    /// sampled direction carries nothing.
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample>;

    /// How rough the non-delta part is: 0 for a delta lobe, infinite for a diffuse one (a
    /// microfacet lobe gives its alpha). Camera paths of the photon integrators continue
    /// through lobes below their `glossy_roughness` by sampling.
    fn roughness(&self) -> f32;

    /// Whether a non-delta part transmits light through the surface (a rough dielectric).
    /// Camera paths follow such lobes by sampling whatever their roughness: a surface
    /// estimate gathers the photons of one side only.
    fn transmits(&self) -> bool {
        false
    }

    /// The probability that `sample` picks a delta part for `wo`, for a lobe that mixes a
    /// delta part with a non-delta one (a smooth plastic's coat); 0 for the others. `sample`
    /// picks it exactly when its `uc` is below this probability.
    fn delta_probability(&self, _wo: Vec3) -> f32 {
        0.0
    }
}
