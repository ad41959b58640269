//! The rough conductor (Mitsuba 3's `roughconductor`).

use super::{LocalSample, above};
use crate::Rgb;
use crate::microfacet::Microfacet;
use crate::scattering::{TransportMode, fresnel_conductor, reflect};
use glam::{Vec2, Vec3};

/// A metal with a rough surface (Mitsuba's `roughconductor`): Torrance-Sparrow microfacet
/// reflection f = F D G / (4 cos_o cos_i), with the conductor's Fresnel reflectance for the
/// complex index eta + i k (per channel), scaled by `specular_reflectance`. One-sided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    pub distribution: Microfacet,
    pub eta: Rgb,
    pub k: Rgb,
    pub specular_reflectance: Rgb,
}

impl RoughConductor {
    pub fn roughness(&self) -> f32 {
        self.distribution.roughness()
    }

    pub(super) fn fresnel(&self, cos: f32) -> Rgb {
        Rgb::new(
            fresnel_conductor(cos, self.eta.x, self.k.x),
            fresnel_conductor(cos, self.eta.y, self.k.y),
            fresnel_conductor(cos, self.eta.z, self.k.z),
        )
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if !above(wo) || !above(wi) {
            return Rgb::ZERO;
        }
        let h = (wo + wi).normalize_or_zero();
        let d = self.distribution.d(h);
        if d == 0.0 {
            return Rgb::ZERO;
        }
        let g = self.distribution.g(wo, wi, h);
        self.specular_reflectance * self.fresnel(wo.dot(h)) * (d * g / (4.0 * wo.z))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize_or_zero();
        if !above(wo) || !above(wi) || wo.dot(h) <= 0.0 || wi.dot(h) <= 0.0 {
            return 0.0;
        }
        if !self.distribution.samples_visible_normals() {
            // The sampler's density of h over 4 wi.h.
            return self.distribution.pdf(wo, h) / (4.0 * wo.dot(h));
        }
        // D_wo(h) / (4 wi.h), with wo.h = wi.h.
        self.distribution.d(h) * self.distribution.smith_g1(wo, h) / (4.0 * wo.z)
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, _uc: f32, _mode: TransportMode) -> Option<LocalSample> {
        if !above(wo) {
            return None;
        }
        let (m, pdf_m) = self.distribution.sample(wo, u);
        if pdf_m <= 0.0 {
            return None;
        }
        let wi = reflect(wo, m);
        let cos_im = wi.dot(m);
        if wi.z <= 0.0 || cos_im <= 0.0 {
            return None;
        }
        let pdf = pdf_m / (4.0 * cos_im);
        let weight = if !self.distribution.samples_visible_normals() {
            self.eval(wo, wi, TransportMode::Radiance) / pdf
        } else {
            // f cos_i / pdf: D G F / (4 cos_o) over D G1(wo) / (4 cos_o) leaves G1(wi) F.
            self.specular_reflectance * self.fresnel(wo.dot(m)) * self.distribution.smith_g1(wi, m)
        };
        Some(LocalSample {
            wi,
            weight,
            pdf,
            delta: false,
        })
    }
}
