//! The rough plastic (Mitsuba 3's `roughplastic`) and its coat's integrated tables.

use super::{
    LocalSample, above, fresnel, positive, refract, specular_probability, specular_sampling_weight,
};
use crate::Rgb;
use crate::microfacet::{Microfacet, MicrofacetKind, gauss_legendre};
use crate::sampling::cosine_hemisphere;
use crate::scattering::{TransportMode, reflect};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;
use std::sync::Mutex;

/// Resolution of the table of the rough coat's transmittance over cos theta (Mitsuba's
/// MI_ROUGH_TRANSMITTANCE_RES).
pub const ROUGH_TRANSMITTANCE_RES: usize = 64;

/// A diffuse base under a rough dielectric coat (Mitsuba's `roughplastic`): the coat's
/// microfacet reflection, plus the base seen through the coat,
/// f = rho / (1 - R_int) T(cos_o) T(cos_i) / (eta^2 pi), where T(cos) is the coat's
/// directional transmittance (Mitsuba's table, integrated numerically) and R_int its
/// internal diffuse reflectance. Isotropic only, as in Mitsuba (which rejects anisotropic
/// roughness); Beckmann or GGX. One-sided.
///
/// Built by [`RoughPlastic::new`], which gets the coat's tables from [`Coat::get`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    pub distribution: Microfacet,
    pub eta: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    pub nonlinear: bool,
    coat: &'static Coat,
}

/// What the rough plastic's diffuse part needs to know of its rough dielectric coat,
/// integrated once as Mitsuba does: T at 64 cosines in [1e-6, 1] (linearly spaced) by a
/// 32 x 32 Gauss-Legendre rule over the visible-normal sample space, E[G1(wt, m) (1 - F)];
/// R_int as 2 x the mean over the same cosines of cos E[G1(wr, m) F] with eta inverted, by a
/// 128 x 128 rule (Mitsuba's rule sizes: 32 when the relative index exceeds 1, else 128).
#[derive(Debug, PartialEq)]
pub struct Coat {
    pub external_transmittance: [f32; ROUGH_TRANSMITTANCE_RES],
    pub internal_reflectance: f32,
}

impl Coat {
    /// The coat of a distribution and relative index. Coats are interned for the life of the
    /// program: the lobe stays a small `Copy` value, and identical coats (most materials of a
    /// scene share a few) are integrated once (about 0.1 s for GGX, 0.03 s for Beckmann).
    /// `eta` must be positive and differ from 1 (Mitsuba rejects equal indices); otherwise the
    /// coat is taken as absent (T = 1, R_int = 0).
    pub fn get(distribution: Microfacet, eta: f32) -> &'static Coat {
        type Key = (MicrofacetKind, u32, u32, u32);
        static COATS: Mutex<Vec<(Key, &'static Coat)>> = Mutex::new(Vec::new());
        let key = (
            distribution.kind,
            distribution.alpha_u.to_bits(),
            distribution.alpha_v.to_bits(),
            eta.to_bits(),
        );
        let mut coats = COATS.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, coat)) = coats.iter().find(|(k, _)| *k == key) {
            return coat;
        }
        let coat: &'static Coat = Box::leak(Box::new(Coat::integrate(&distribution, eta)));
        coats.push((key, coat));
        coat
    }

    fn integrate(distribution: &Microfacet, eta: f32) -> Coat {
        let mut external_transmittance = [1.0; ROUGH_TRANSMITTANCE_RES];
        let mut internal_reflectance = 0.0;
        if eta > 0.0 && eta != 1.0 && eta.is_finite() {
            let cosines = (0..ROUGH_TRANSMITTANCE_RES)
                .map(|i| (i as f32 / (ROUGH_TRANSMITTANCE_RES - 1) as f32).max(1e-6));
            let rule_t = gauss_legendre_unit(if eta > 1.0 { 32 } else { 128 });
            let rule_r = gauss_legendre_unit(if 1.0 / eta > 1.0 { 32 } else { 128 });
            let mut sum_r = 0.0f64;
            for (t, mu) in external_transmittance.iter_mut().zip(cosines) {
                let w = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                *t = coat_transmittance(distribution, w, eta, &rule_t) as f32;
                sum_r += coat_reflectance(distribution, w, 1.0 / eta, &rule_r) * mu as f64;
            }
            internal_reflectance = (2.0 * sum_r / ROUGH_TRANSMITTANCE_RES as f64) as f32;
        }
        Coat {
            external_transmittance,
            internal_reflectance,
        }
    }
}

impl RoughPlastic {
    pub fn new(
        kind: MicrofacetKind,
        alpha: f32,
        eta: f32,
        diffuse_reflectance: Rgb,
        specular_reflectance: Rgb,
        nonlinear: bool,
    ) -> Self {
        let distribution = Microfacet::isotropic(kind, alpha);
        RoughPlastic {
            distribution,
            eta,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            coat: Coat::get(distribution, eta),
        }
    }

    pub fn roughness(&self) -> f32 {
        self.distribution.roughness()
    }

    /// The coat's directional transmittance T(cos theta) (linear in the table, as Mitsuba).
    pub fn external_transmittance(&self, cos: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0) * (ROUGH_TRANSMITTANCE_RES - 1) as f32;
        let i = (x as usize).min(ROUGH_TRANSMITTANCE_RES - 2);
        let table = &self.coat.external_transmittance;
        let (t0, t1) = (table[i], table[i + 1]);
        t0 + (t1 - t0) * (x - i as f32)
    }

    /// The coat's diffuse reflectance seen from inside, R_int.
    pub fn internal_reflectance(&self) -> f32 {
        self.coat.internal_reflectance
    }

    pub(super) fn prob_specular(&self, t_o: f32) -> f32 {
        let w = specular_sampling_weight(self.specular_reflectance, self.diffuse_reflectance);
        specular_probability((1.0 - t_o) * w, t_o * (1.0 - w))
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if !above(wo) || !above(wi) {
            return Rgb::ZERO;
        }
        let md = &self.distribution;
        let h = (wo + wi).normalize_or_zero();
        let (f, ..) = fresnel(wo.dot(h), self.eta);
        let specular = self.specular_reflectance * (f * md.d(h) * md.g(wo, wi, h) / (4.0 * wo.z));

        let rho = self.diffuse_reflectance;
        let internal = if self.nonlinear {
            rho * self.coat.internal_reflectance
        } else {
            Rgb::splat(self.coat.internal_reflectance)
        };
        let t_o = self.external_transmittance(wo.z);
        let t_i = self.external_transmittance(wi.z);
        let diffuse =
            rho / (Rgb::ONE - internal) * (FRAC_1_PI * wi.z * t_o * t_i / (self.eta * self.eta));
        specular + diffuse
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !above(wo) || !above(wi) {
            return 0.0;
        }
        let p_spec = self.prob_specular(self.external_transmittance(wo.z));
        p_spec * self.specular_pdf(wo, wi) + (1.0 - p_spec) * wi.z * FRAC_1_PI
    }

    /// Density of the coat's lobe alone, D_wo(h) / (4 wi.h).
    pub(super) fn specular_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize_or_zero();
        let md = &self.distribution;
        if !md.samples_visible_normals() {
            // The sampler's density of h over 4 wo.h.
            let oh = wo.dot(h);
            return if oh > 0.0 {
                md.pdf(wo, h) / (4.0 * oh)
            } else {
                0.0
            };
        }
        md.d(h) * md.smith_g1(wo, h) / (4.0 * wo.z)
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        if !above(wo) {
            return None;
        }
        let p_spec = self.prob_specular(self.external_transmittance(wo.z));
        let wi = if uc < p_spec {
            let (m, pdf_m) = self.distribution.sample(wo, u);
            if pdf_m <= 0.0 {
                return None;
            }
            reflect(wo, m)
        } else {
            cosine_hemisphere(u)
        };
        let pdf = self.pdf(wo, wi);
        if !positive(pdf) {
            return None;
        }
        Some(LocalSample {
            wi,
            weight: self.eval(wo, wi, mode) / pdf,
            pdf,
            delta: false,
        })
    }
}

/// [`gauss_legendre`]'s nodes mapped to [0, 1], with weights summing to one, for the coat's
/// integrals.
fn gauss_legendre_unit(n: usize) -> Vec<(f32, f64)> {
    gauss_legendre(n)
        .into_iter()
        .map(|(x, w)| ((0.5 * x + 0.5) as f32, 0.5 * w))
        .collect()
}

/// Fraction of light from `w` reflected by a rough dielectric interface of relative index
/// `eta` and not masked on the way out: E over visible normals of F G1(reflected, m)
/// (Mitsuba's `eval_reflectance`).
fn coat_reflectance(md: &Microfacet, w: Vec3, eta: f32, rule: &[(f32, f64)]) -> f64 {
    let nodes: Vec<f32> = rule.iter().map(|r| r.0).collect();
    let mut sum = 0.0;
    md.for_each_normal_on_grid(w, &nodes, |i, j, m, weight| {
        let r = reflect(w, m);
        if r.z > 0.0 {
            let (f, ..) = fresnel(w.dot(m), eta);
            sum += rule[i].1 * rule[j].1 * (f * md.smith_g1(r, m) * weight) as f64;
        }
    });
    sum
}

/// Fraction of light from `w` transmitted through a rough dielectric interface of relative
/// index `eta` and not masked on the other side: E over visible normals of (1 - F)
/// G1(refracted, m) (Mitsuba's `eval_transmittance`).
fn coat_transmittance(md: &Microfacet, w: Vec3, eta: f32, rule: &[(f32, f64)]) -> f64 {
    let nodes: Vec<f32> = rule.iter().map(|r| r.0).collect();
    let mut sum = 0.0;
    md.for_each_normal_on_grid(w, &nodes, |i, j, m, weight| {
        let (f, cos_t, _, eta_ti) = fresnel(w.dot(m), eta);
        let t = refract(w, m, cos_t, eta_ti);
        if t.z * w.z < 0.0 {
            sum += rule[i].1 * rule[j].1 * ((1.0 - f) * md.smith_g1(t, m) * weight) as f64;
        }
    });
    sum
}
