//! The smooth plastic (Mitsuba 3's `plastic`), and the Fresnel reflectance averaged over the
//! hemisphere that both plastics use.

use super::{LocalSample, above, specular_probability, specular_sampling_weight};
use crate::Rgb;
use crate::sampling::cosine_hemisphere;
use crate::scattering::{TransportMode, fresnel_dielectric};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Mitsuba's `fresnel_diffuse_reflectance`: the Fresnel reflectance of a dielectric interface
/// averaged over a cosine-weighted hemisphere of incident directions (Fdr), from fits: Egan
/// and Hilgeman (1973) for eta < 1, d'Eon and Irving (2011) above.
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    let inv = 1.0 / eta;
    if eta < 1.0 {
        -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 * inv
    } else {
        let c = [0.919317, -3.4793, 6.75335, -7.80989, 4.98554, -1.36881];
        c.iter().rev().fold(0.0, |acc, &ci| acc * inv + ci)
    }
}

/// A diffuse base under a smooth dielectric coat (Mitsuba's `plastic`): a delta reflection on
/// the coat with its Fresnel reflectance, and light refracted into the coat, scattered by the
/// base with its internal reflections accounted for (Mitsuba's formula), refracted out:
/// f = rho / (1 - Fdr_int) (1 - F(cos_o)) (1 - F(cos_i)) / (eta^2 pi), with rho Fdr_int in
/// place of Fdr_int if `nonlinear`. `eta` is the coat's index relative to the outside.
/// One-sided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    pub eta: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    pub nonlinear: bool,
}

impl Plastic {
    /// Fdr of the coat seen from inside (light reflected back onto the base).
    pub fn fdr_int(&self) -> f32 {
        fresnel_diffuse_reflectance(1.0 / self.eta)
    }

    /// Fdr of the coat seen from outside (not used by the model; Mitsuba computes it too).
    pub fn fdr_ext(&self) -> f32 {
        fresnel_diffuse_reflectance(self.eta)
    }

    fn diffuse(&self) -> Rgb {
        let rho = self.diffuse_reflectance;
        let fdr = self.fdr_int();
        let internal = if self.nonlinear {
            rho * fdr
        } else {
            Rgb::splat(fdr)
        };
        rho / (Rgb::ONE - internal)
    }

    /// The probability that `sample` picks the delta coat for `wo`.
    pub fn delta_probability(&self, wo: Vec3) -> f32 {
        if !above(wo) {
            return 0.0;
        }
        self.prob_specular(fresnel_dielectric(wo.z, self.eta))
    }

    /// Probability of sampling the delta coat for this wo (cos_o > 0).
    fn prob_specular(&self, f_o: f32) -> f32 {
        let w = specular_sampling_weight(self.specular_reflectance, self.diffuse_reflectance);
        specular_probability(f_o * w, (1.0 - f_o) * (1.0 - w))
    }

    /// The diffuse part only (the delta coat is not a function).
    pub fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if !above(wo) || !above(wi) {
            return Rgb::ZERO;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta);
        let f_i = fresnel_dielectric(wi.z, self.eta);
        self.diffuse() * (wi.z * FRAC_1_PI * (1.0 - f_o) * (1.0 - f_i) / (self.eta * self.eta))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !above(wo) || !above(wi) {
            return 0.0;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta);
        (1.0 - self.prob_specular(f_o)) * wi.z * FRAC_1_PI
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, uc: f32, _mode: TransportMode) -> Option<LocalSample> {
        if !above(wo) {
            return None;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta);
        let p_spec = self.prob_specular(f_o);
        if uc < p_spec {
            return Some(LocalSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: self.specular_reflectance * (f_o / p_spec),
                pdf: p_spec,
                delta: true,
            });
        }
        let wi = cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        let p_diff = 1.0 - p_spec;
        let f_i = fresnel_dielectric(wi.z, self.eta);
        // f cos_i / (p_diff cos_i / pi): the cosine and 1/pi cancel.
        let weight = self.diffuse() * ((1.0 - f_o) * (1.0 - f_i) / (self.eta * self.eta * p_diff));
        Some(LocalSample {
            wi,
            weight,
            pdf: p_diff * wi.z * FRAC_1_PI,
            delta: false,
        })
    }
}
