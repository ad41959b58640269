//! Glossy BSDF lobes matching Mitsuba 3's plugins of the same names: `roughconductor`,
//! `roughdielectric`, `plastic` and `roughplastic`.
//!
//! All work in the local shading frame: z is the shading normal, `wo` points towards the
//! viewer (the previous vertex of the path), `wi` is the other direction (the sampled one),
//! both away from the surface. In Mitsuba's names `wo` is `si.wi` and `wi` is `wo`.
//! `eval` returns f(wo, wi) |cos theta_i| (Mitsuba's `eval` includes the cosine), `pdf` the
//! solid-angle density with which `sample` produces wi (non-delta parts only, times their
//! selection probability), and `sample` the weight f |cos theta_i| / pdf.
//!
//! The conductor and the plastics are one-sided (black when wo.z <= 0 or wi.z <= 0); the
//! rough dielectric is two-sided: wo below the surface means the viewer is inside, and the
//! relative index of refraction is inverted.
//!
//! Directions are unit vectors. Where Mitsuba's `sample` returns a sample of zero weight (the
//! sampled direction on the wrong side of the surface), `sample` returns None here. The
//! indices `eta` are relative (interior over exterior): Mitsuba's `int_ior` / `ext_ior`, whose
//! default exterior is air, 1.000277, not 1.
//!
//! One file a model, as Mitsuba 3 keeps one plugin a file: `conductor.rs` (`roughconductor`),
//! `dielectric.rs` (`roughdielectric`), `plastic.rs` (`plastic`) and `rough_plastic.rs`
//! (`roughplastic`, with the integrated tables of its rough coat), each re-exported here; what
//! two of them share (the dielectric Fresnel term with its refracted direction, the choice
//! between a specular and a diffuse lobe) is here too.

use crate::Rgb;
use crate::scattering::fresnel_dielectric;
use glam::Vec3;

mod conductor;
mod dielectric;
mod plastic;
mod rough_plastic;

pub use crate::scattering::LocalSample;
pub use conductor::RoughConductor;
pub use dielectric::RoughDielectric;
pub use plastic::{Plastic, fresnel_diffuse_reflectance};
pub use rough_plastic::{Coat, ROUGH_TRANSMITTANCE_RES, RoughPlastic};

/// True for a finite positive number (false for NaN).
#[inline]
fn positive(x: f32) -> bool {
    x > 0.0 && x.is_finite()
}

/// True for a finite direction strictly above the surface (one-sided lobes).
#[inline]
fn above(v: Vec3) -> bool {
    v.z > 0.0 && v.is_finite()
}

/// Dielectric Fresnel for a signed cosine (negative: incident from inside), `eta` the index of
/// the inside relative to the outside, as Mitsuba's `fresnel`: (F, cos_theta_t with the sign
/// of the transmitted side, eta_it, eta_ti), eta_it the relative index in the direction of
/// travel and eta_ti its reciprocal.
#[inline]
pub(crate) fn fresnel(cos_i: f32, eta: f32) -> (f32, f32, f32, f32) {
    let (eta_it, eta_ti) = if cos_i >= 0.0 {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let f = fresnel_dielectric(cos_i.abs(), eta_it);
    let cos_t = (1.0 - (1.0 - cos_i * cos_i) * eta_ti * eta_ti)
        .max(0.0)
        .sqrt();
    (f, if cos_i >= 0.0 { -cos_t } else { cos_t }, eta_it, eta_ti)
}

/// Refraction of `v` through the microfacet `m`, given the signed cos_theta_t and eta_ti of
/// [`fresnel`].
#[inline]
pub(crate) fn refract(v: Vec3, m: Vec3, cos_t: f32, eta_ti: f32) -> Vec3 {
    m * (v.dot(m) * eta_ti + cos_t) - v * eta_ti
}

/// Mitsuba's choice between a specular and a diffuse lobe: each weighted by the mean of its
/// reflectance (channel average).
fn specular_sampling_weight(specular: Rgb, diffuse: Rgb) -> f32 {
    let (s, d) = (crate::average(specular), crate::average(diffuse));
    if s + d > 0.0 { s / (s + d) } else { 0.5 }
}

/// Probability of choosing the specular lobe given the lobes' weights for this wo.
fn specular_probability(w_specular: f32, w_diffuse: f32) -> f32 {
    let total = w_specular + w_diffuse;
    if total > 0.0 { w_specular / total } else { 0.0 }
}

#[cfg(test)]
mod tests;
