//! The rough dielectric interface (Mitsuba 3's `roughdielectric`).

use super::{LocalSample, fresnel, positive, refract};
use crate::Rgb;
use crate::microfacet::Microfacet;
use crate::scattering::{TransportMode, reflect};
use glam::{Vec2, Vec3};

/// A rough interface between two dielectrics (Mitsuba's `roughdielectric`, Walter et al.
/// 2007): microfacet reflection and refraction, chosen by the Fresnel reflectance of the
/// sampled microfacet. `eta` is the interior index over the exterior one (the interior is
/// below, z < 0). Two-sided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    pub distribution: Microfacet,
    pub eta: f32,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
}

impl RoughDielectric {
    pub fn roughness(&self) -> f32 {
        self.distribution.roughness()
    }

    /// The generalised half vector of (wo, wi) on the outside of the microsurface (m.z >= 0),
    /// with eta the relative index seen from wo's side; None when it is undefined.
    fn half_vector(wo: Vec3, wi: Vec3, reflect: bool, eta: f32) -> Option<Vec3> {
        let h = (wo + wi * if reflect { 1.0 } else { eta }).normalize_or_zero();
        if h == Vec3::ZERO {
            return None;
        }
        Some(if h.z < 0.0 { -h } else { h })
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || !wo.is_finite() || !wi.is_finite() || !positive(self.eta) {
            return Rgb::ZERO;
        }
        let reflect = cos_o * cos_i > 0.0;
        let (eta, inv_eta) = if cos_o > 0.0 {
            (self.eta, 1.0 / self.eta)
        } else {
            (1.0 / self.eta, self.eta)
        };
        let Some(m) = Self::half_vector(wo, wi, reflect, eta) else {
            return Rgb::ZERO;
        };
        let md = &self.distribution;
        let d = md.d(m);
        let g = md.g(wo, wi, m);
        if d == 0.0 || g == 0.0 {
            return Rgb::ZERO;
        }
        let (f, ..) = fresnel(wo.dot(m), self.eta);
        if reflect {
            self.specular_reflectance * (f * d * g / (4.0 * cos_o.abs()))
        } else {
            // Radiance is compressed into the smaller solid angle on the denser side; flux
            // (importance) is not (Veach 1997, 5.2).
            let scale = match mode {
                TransportMode::Radiance => inv_eta * inv_eta,
                TransportMode::Importance => 1.0,
            };
            let (om, im) = (wo.dot(m), wi.dot(m));
            let denom = om + eta * im;
            let value = scale * (1.0 - f) * d * g * eta * eta * om * im / (cos_o * denom * denom);
            self.specular_transmittance * value.abs()
        }
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || !wo.is_finite() || !wi.is_finite() || !positive(self.eta) {
            return 0.0;
        }
        let reflect = cos_o * cos_i > 0.0;
        let eta = if cos_o > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let Some(m) = Self::half_vector(wo, wi, reflect, eta) else {
            return 0.0;
        };
        let (om, im) = (wo.dot(m), wi.dot(m));
        // Microfacets seen from their back cannot have produced this pair (G1 is zero).
        if om * cos_o <= 0.0 || im * cos_i <= 0.0 {
            return 0.0;
        }
        let dm_dwi = if reflect {
            1.0 / (4.0 * im)
        } else {
            eta * eta * im / (om + eta * im).powi(2)
        };
        let (f, ..) = fresnel(om, self.eta);
        let lobe = if reflect { f } else { 1.0 - f };
        let pdf = self.distribution.pdf(wo * cos_o.signum(), m) * lobe * dm_dwi.abs();
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        let cos_o = wo.z;
        if cos_o == 0.0 || !wo.is_finite() || !positive(self.eta) {
            return None;
        }
        let md = &self.distribution;
        let (m, pdf_m) = md.sample(wo * cos_o.signum(), u);
        if pdf_m <= 0.0 {
            return None;
        }
        let om = wo.dot(m);
        let (f, cos_t, eta_it, eta_ti) = fresnel(om, self.eta);
        let (wi, weight, pdf) = if uc < f {
            let wi = reflect(wo, m);
            if wi.z * cos_o <= 0.0 {
                return None;
            }
            (
                wi,
                self.specular_reflectance,
                pdf_m * f / (4.0 * wi.dot(m)).abs(),
            )
        } else {
            let wi = refract(wo, m, cos_t, eta_ti);
            if wi.z * cos_o >= 0.0 {
                return None;
            }
            let im = wi.dot(m);
            let scale = match mode {
                TransportMode::Radiance => eta_ti * eta_ti,
                TransportMode::Importance => 1.0,
            };
            let dm_dwi = eta_it * eta_it * im / (om + eta_it * im).powi(2);
            (
                wi,
                self.specular_transmittance * scale,
                pdf_m * (1.0 - f) * dm_dwi.abs(),
            )
        };
        // f cos_i / pdf: the Fresnel factor and D G1(wo) cancel, G1(wi) remains.
        let g1 = md.smith_g1(wi, m);
        if g1 <= 0.0 || !positive(pdf) || !wi.is_finite() {
            return None;
        }
        let weight = if !md.samples_visible_normals() {
            // Nothing cancels when the normals are not the visible ones.
            self.eval(wo, wi, mode) / pdf
        } else {
            weight * g1
        };
        Some(LocalSample {
            wi,
            weight,
            pdf,
            delta: false,
        })
    }
}
