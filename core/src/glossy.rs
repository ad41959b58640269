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

use crate::Rgb;
use crate::microfacet::{Microfacet, MicrofacetKind};
use crate::sampling::cosine_hemisphere;
use crate::scattering::{TransportMode, fresnel_conductor, fresnel_dielectric};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;
use std::sync::Mutex;

pub use crate::scattering::LocalSample;

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

/// Mirror reflection of `v` about the microfacet normal `m`.
#[inline]
fn reflect(v: Vec3, m: Vec3) -> Vec3 {
    2.0 * v.dot(m) * m - v
}

/// Dielectric Fresnel for a signed cosine (negative: incident from inside), `eta` the index of
/// the inside relative to the outside, as Mitsuba's `fresnel`: (F, cos_theta_t with the sign
/// of the transmitted side, eta_it, eta_ti), eta_it the relative index in the direction of
/// travel and eta_ti its reciprocal.
#[inline]
fn fresnel(cos_i: f32, eta: f32) -> (f32, f32, f32, f32) {
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
fn refract(v: Vec3, m: Vec3, cos_t: f32, eta_ti: f32) -> Vec3 {
    m * (v.dot(m) * eta_ti + cos_t) - v * eta_ti
}

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

// ---------------------------------------------------------------------------------------------
// Rough conductor
// ---------------------------------------------------------------------------------------------

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

    fn fresnel(&self, cos: f32) -> Rgb {
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
        // f cos_i / pdf: D G F / (4 cos_o) over D G1(wo) / (4 cos_o) leaves G1(wi) F.
        let weight =
            self.specular_reflectance * self.fresnel(wo.dot(m)) * self.distribution.smith_g1(wi, m);
        Some(LocalSample {
            wi,
            weight,
            pdf: pdf_m / (4.0 * cos_im),
            delta: false,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Rough dielectric
// ---------------------------------------------------------------------------------------------

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
        Some(LocalSample {
            wi,
            weight: weight * g1,
            pdf,
            delta: false,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Smooth plastic
// ---------------------------------------------------------------------------------------------

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

// ---------------------------------------------------------------------------------------------
// Rough plastic
// ---------------------------------------------------------------------------------------------

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

    fn prob_specular(&self, t_o: f32) -> f32 {
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
    fn specular_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize_or_zero();
        let md = &self.distribution;
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

/// Gauss-Legendre nodes mapped to [0, 1] with weights summing to one, for the coat's
/// integrals (Mitsuba's `quad::gauss_legendre`, nodes by Newton's method on P_n in f64).
fn gauss_legendre_unit(n: usize) -> Vec<(f32, f64)> {
    let legendre = |x: f64| {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
            p0 = p1;
            p1 = p2;
        }
        // P_n and its derivative.
        (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
    };
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            let (_, dp) = legendre(x);
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            ((0.5 * x + 0.5) as f32, 0.5 * w)
        })
        .collect()
}

/// Fraction of light from `w` reflected by a rough dielectric interface of relative index
/// `eta` and not masked on the way out: E over visible normals of F G1(reflected, m)
/// (Mitsuba's `eval_reflectance`).
fn coat_reflectance(md: &Microfacet, w: Vec3, eta: f32, rule: &[(f32, f64)]) -> f64 {
    let nodes: Vec<f32> = rule.iter().map(|r| r.0).collect();
    let mut sum = 0.0;
    md.for_each_normal_on_grid(w, &nodes, |i, j, m| {
        let r = reflect(w, m);
        if r.z > 0.0 {
            let (f, ..) = fresnel(w.dot(m), eta);
            sum += rule[i].1 * rule[j].1 * (f * md.smith_g1(r, m)) as f64;
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
    md.for_each_normal_on_grid(w, &nodes, |i, j, m| {
        let (f, cos_t, _, eta_ti) = fresnel(w.dot(m), eta);
        let t = refract(w, m, cos_t, eta_ti);
        if t.z * w.z < 0.0 {
            sum += rule[i].1 * rule[j].1 * ((1.0 - f) * md.smith_g1(t, m)) as f64;
        }
    });
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::chi2::{self, Outcome};
    use crate::sampling::{Rng, uniform_sphere};
    use std::f64::consts::PI;

    const BECKMANN: MicrofacetKind = MicrofacetKind::Beckmann;
    const GGX: MicrofacetKind = MicrofacetKind::Ggx;

    /// Distributions of the sampling tests: narrow, anisotropic both ways, wide.
    const DISTRIBUTIONS: [(MicrofacetKind, f32, f32); 4] = [
        (BECKMANN, 0.1, 0.1),
        (BECKMANN, 0.15, 0.6),
        (GGX, 0.4, 0.4),
        (GGX, 0.6, 0.15),
    ];
    /// Viewing directions above the surface: normal, oblique (off-axis in phi), grazing.
    fn views() -> [Vec3; 3] {
        [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.5, -0.4, 0.75).normalize(),
            Vec3::new(-0.7, 0.7, 0.08).normalize(),
        ]
    }
    /// Viewing directions of the dielectric from inside: oblique, and beyond the critical
    /// angle (total internal reflection on most microfacets).
    fn inside_views() -> [Vec3; 2] {
        [
            Vec3::new(0.3, 0.2, -0.9).normalize(),
            Vec3::new(0.2, -0.85, -0.5).normalize(),
        ]
    }
    const ROUGH_PLASTICS: [(MicrofacetKind, f32); 2] = [(BECKMANN, 0.1), (GGX, 0.4)];
    const PLASTICS: [(f32, bool); 2] = [(1.5, false), (1.9, true)];

    /// All chi-square tests of this module, for the Sidak correction.
    const GOF_TESTS: usize = DISTRIBUTIONS.len() * 3 // conductor
        + DISTRIBUTIONS.len() * 5 // dielectric, 3 views outside and 2 inside
        + PLASTICS.len() * 3
        + ROUGH_PLASTICS.len() * 3;
    const N_SAMPLES: usize = 150_000;

    /// One lobe, whichever it is, for the tests that go over all of them.
    #[derive(Clone, Copy, Debug)]
    enum Lobe {
        Conductor(RoughConductor),
        Dielectric(RoughDielectric),
        Plastic(Plastic),
        RoughPlastic(RoughPlastic),
    }

    impl Lobe {
        fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
            match self {
                Lobe::Conductor(b) => b.eval(wo, wi, mode),
                Lobe::Dielectric(b) => b.eval(wo, wi, mode),
                Lobe::Plastic(b) => b.eval(wo, wi, mode),
                Lobe::RoughPlastic(b) => b.eval(wo, wi, mode),
            }
        }
        fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
            match self {
                Lobe::Conductor(b) => b.pdf(wo, wi),
                Lobe::Dielectric(b) => b.pdf(wo, wi),
                Lobe::Plastic(b) => b.pdf(wo, wi),
                Lobe::RoughPlastic(b) => b.pdf(wo, wi),
            }
        }
        fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
            match self {
                Lobe::Conductor(b) => b.sample(wo, u, uc, mode),
                Lobe::Dielectric(b) => b.sample(wo, u, uc, mode),
                Lobe::Plastic(b) => b.sample(wo, u, uc, mode),
                Lobe::RoughPlastic(b) => b.sample(wo, u, uc, mode),
            }
        }
        /// The density of `sample`, exact: `pdf` with the microfacet part rescaled by the
        /// exact over the fitted Beckmann G1(wo) (see `chi2::g1_correction`).
        fn exact_pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
            let up = wo * wo.z.signum();
            match self {
                Lobe::Conductor(b) => {
                    b.pdf(wo, wi) as f64 * chi2::g1_correction(&b.distribution, up)
                }
                Lobe::Dielectric(b) => {
                    b.pdf(wo, wi) as f64 * chi2::g1_correction(&b.distribution, up)
                }
                Lobe::Plastic(b) => b.pdf(wo, wi) as f64,
                Lobe::RoughPlastic(b) => {
                    if !above(wo) || !above(wi) {
                        return 0.0;
                    }
                    let p = b.prob_specular(b.external_transmittance(wo.z)) as f64;
                    p * b.specular_pdf(wo, wi) as f64 * chi2::g1_correction(&b.distribution, up)
                        + (1.0 - p) * wi.z as f64 / PI
                }
            }
        }
    }

    fn conductor(kind: MicrofacetKind, au: f32, av: f32) -> RoughConductor {
        RoughConductor {
            distribution: Microfacet::new(kind, au, av),
            eta: Rgb::new(0.2, 0.9, 1.1),
            k: Rgb::new(3.9, 2.4, 2.1),
            specular_reflectance: Rgb::new(0.9, 0.8, 0.7),
        }
    }

    fn dielectric(kind: MicrofacetKind, au: f32, av: f32, eta: f32) -> RoughDielectric {
        RoughDielectric {
            distribution: Microfacet::new(kind, au, av),
            eta,
            specular_reflectance: Rgb::ONE,
            specular_transmittance: Rgb::ONE,
        }
    }

    fn plastic(eta: f32, nonlinear: bool) -> Plastic {
        Plastic {
            eta,
            diffuse_reflectance: Rgb::new(0.5, 0.3, 0.2),
            specular_reflectance: Rgb::new(1.0, 0.9, 0.8),
            nonlinear,
        }
    }

    fn rough_plastic(kind: MicrofacetKind, alpha: f32) -> RoughPlastic {
        RoughPlastic::new(
            kind,
            alpha,
            1.5,
            Rgb::new(0.5, 0.3, 0.2),
            Rgb::new(1.0, 0.9, 0.8),
            false,
        )
    }

    /// Every lobe of the sampling tests with the views it is tested from.
    fn cases() -> Vec<(Lobe, Vec<Vec3>)> {
        let mut v = Vec::new();
        for (kind, au, av) in DISTRIBUTIONS {
            v.push((Lobe::Conductor(conductor(kind, au, av)), views().to_vec()));
        }
        for (kind, au, av) in DISTRIBUTIONS {
            let mut w = views().to_vec();
            w.extend(inside_views());
            v.push((Lobe::Dielectric(dielectric(kind, au, av, 1.5)), w));
        }
        for (eta, nonlinear) in PLASTICS {
            v.push((Lobe::Plastic(plastic(eta, nonlinear)), views().to_vec()));
        }
        for (kind, alpha) in ROUGH_PLASTICS {
            v.push((
                Lobe::RoughPlastic(rough_plastic(kind, alpha)),
                views().to_vec(),
            ));
        }
        v
    }

    fn gof(lobe: Lobe, wo: Vec3, seed: u64) {
        chi2::assert_fits(
            &format!("{lobe:?} wo {wo}"),
            N_SAMPLES,
            seed,
            |rng: &mut Rng| {
                let u = rng.next_2d();
                match lobe.sample(wo, u, rng.next_f32(), TransportMode::Radiance) {
                    Some(s) if !s.delta => Outcome::Dir(s.wi),
                    _ => Outcome::Other,
                }
            },
            &|wi| lobe.exact_pdf(wo, wi),
            chi2::sidak(GOF_TESTS),
        );
    }

    // The chi-square tests are split by lobe so that they run in parallel.

    #[test]
    fn conductor_samples_follow_its_pdf() {
        for (i, (lobe, views)) in cases().into_iter().enumerate() {
            if let Lobe::Conductor(_) = lobe {
                for (j, wo) in views.into_iter().enumerate() {
                    gof(lobe, wo, (100 * i + j) as u64);
                }
            }
        }
    }

    #[test]
    fn dielectric_samples_follow_its_pdf() {
        for (i, (lobe, views)) in cases().into_iter().enumerate() {
            if let Lobe::Dielectric(_) = lobe {
                for (j, wo) in views.into_iter().enumerate() {
                    gof(lobe, wo, (100 * i + j) as u64);
                }
            }
        }
    }

    #[test]
    fn plastic_samples_follow_their_pdf() {
        for (i, (lobe, views)) in cases().into_iter().enumerate() {
            if let Lobe::Plastic(_) | Lobe::RoughPlastic(_) = lobe {
                for (j, wo) in views.into_iter().enumerate() {
                    gof(lobe, wo, (100 * i + j) as u64);
                }
            }
        }
    }

    #[test]
    fn sample_weight_is_eval_over_pdf() {
        let mut rng = Rng::new(&[7]);
        for (lobe, _) in cases() {
            let two_sided = matches!(lobe, Lobe::Dielectric(_));
            for _ in 0..2000 {
                let mut wo = uniform_sphere(rng.next_2d());
                if !two_sided {
                    wo.z = wo.z.abs();
                }
                let (u, uc) = (rng.next_2d(), rng.next_f32());
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    let Some(s) = lobe.sample(wo, u, uc, mode) else {
                        continue;
                    };
                    assert!(
                        s.pdf > 0.0 && s.weight.is_finite() && s.weight.min_element() >= 0.0,
                        "{lobe:?}: {s:?}"
                    );
                    if s.delta {
                        continue;
                    }
                    let (f, pdf) = (lobe.eval(wo, s.wi, mode), lobe.pdf(wo, s.wi));
                    let tol = 2e-3 * (1.0 + s.weight.max_element());
                    assert!(
                        (s.pdf - pdf).abs() <= 2e-3 * pdf,
                        "{lobe:?} wo {wo}: sample pdf {} vs pdf {pdf}",
                        s.pdf
                    );
                    assert!(
                        (s.weight - f / pdf).abs().max_element() <= tol,
                        "{lobe:?} wo {wo} wi {}: weight {} vs eval / pdf {}",
                        s.wi,
                        s.weight,
                        f / pdf
                    );
                }
            }
        }
    }

    #[test]
    fn conductor_is_reciprocal() {
        let mut rng = Rng::new(&[8]);
        for (kind, au, av) in DISTRIBUTIONS {
            let b = conductor(kind, au, av);
            for _ in 0..1000 {
                let mut wo = uniform_sphere(rng.next_2d());
                let mut wi = uniform_sphere(rng.next_2d());
                wo.z = wo.z.abs();
                wi.z = wi.z.abs();
                let m = TransportMode::Radiance;
                let a = b.eval(wo, wi, m) / wi.z;
                let c = b.eval(wi, wo, m) / wo.z;
                assert!(
                    (a - c).abs().max_element() <= 1e-4 * a.max_element() + 1e-6,
                    "{b:?}: {a} vs {c}"
                );
            }
        }
    }

    /// Directional albedo, the integral of eval over wi, estimated by the mean sample weight
    /// (delta lobes included), with its standard error.
    fn albedo(lobe: &Lobe, wo: Vec3, mode: TransportMode, n: usize, seed: u64) -> (Rgb, f32) {
        let mut rng = Rng::new(&[seed]);
        let (mut sum, mut sum2) = (Rgb::ZERO, 0.0f64);
        for _ in 0..n {
            let u = rng.next_2d();
            if let Some(s) = lobe.sample(wo, u, rng.next_f32(), mode) {
                sum += s.weight;
                sum2 += (s.weight.max_element() as f64).powi(2);
            }
        }
        let mean = sum / n as f32;
        let var = sum2 / n as f64 - (mean.max_element() as f64).powi(2);
        (mean, (var.max(0.0) / n as f64).sqrt() as f32)
    }

    const ALPHAS: [f32; 5] = [0.01, 0.05, 0.2, 0.5, 1.0];

    #[test]
    fn conductor_conserves_energy_and_tends_to_the_smooth_one() {
        for kind in [BECKMANN, GGX] {
            for alpha in ALPHAS {
                // eta = 0, k = 1 (Mitsuba's defaults) reflects everything: F = 1.
                let white = Lobe::Conductor(RoughConductor {
                    distribution: Microfacet::isotropic(kind, alpha),
                    eta: Rgb::ZERO,
                    k: Rgb::ONE,
                    specular_reflectance: Rgb::ONE,
                });
                for wo in views() {
                    let (a, se) = albedo(&white, wo, TransportMode::Radiance, 40_000, 1);
                    assert!(
                        a.max_element() <= 1.0 + 4.0 * se + 1e-3,
                        "{white:?} {wo}: {a}"
                    );
                    if alpha == 0.01 && wo.z > 0.5 {
                        assert!(a.min_element() > 0.99, "{white:?} {wo}: {a}");
                    }
                }
            }
            // Gold, nearly smooth: the smooth conductor's Fresnel reflectance.
            let (eta, k) = crate::material::conductor("Au").unwrap();
            let gold = RoughConductor {
                distribution: Microfacet::isotropic(kind, 0.01),
                eta,
                k,
                specular_reflectance: Rgb::ONE,
            };
            let wo = views()[1];
            let (a, _) = albedo(
                &Lobe::Conductor(gold),
                wo,
                TransportMode::Radiance,
                20_000,
                2,
            );
            let smooth = gold.fresnel(wo.z);
            assert!((a - smooth).abs().max_element() < 0.01, "{a} vs {smooth}");
        }
    }

    #[test]
    fn dielectric_conserves_energy_and_tends_to_the_smooth_one() {
        for kind in [BECKMANN, GGX] {
            for alpha in ALPHAS {
                for eta in [1.5, 1.0 / 1.33] {
                    let lobe = Lobe::Dielectric(dielectric(kind, alpha, alpha, eta));
                    for wo in views().into_iter().chain(inside_views()) {
                        let (a, se) = albedo(&lobe, wo, TransportMode::Importance, 40_000, 3);
                        assert!(
                            a.max_element() <= 1.0 + 4.0 * se + 1e-3,
                            "{lobe:?} {wo}: {a}"
                        );
                        if alpha == 0.01 && wo.z.abs() > 0.5 {
                            assert!(a.min_element() > 0.99, "{lobe:?} {wo}: {a}");
                            // Radiance: the transmitted part scaled by 1 / eta^2 (relative
                            // to the side of wo), as the smooth dielectric does.
                            let (r, _) = albedo(&lobe, wo, TransportMode::Radiance, 40_000, 4);
                            let eta_o = if wo.z > 0.0 { eta } else { 1.0 / eta };
                            let f = fresnel_dielectric(wo.z.abs(), eta_o);
                            let smooth = f + (1.0 - f) / (eta_o * eta_o);
                            assert!(
                                (r.x - smooth).abs() < 0.01 * smooth,
                                "{lobe:?} {wo}: {r} vs {smooth}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// Fresnel reflectance of a dielectric in f64, written out from Snell's law.
    fn fresnel64(cos_i: f64, eta: f64) -> f64 {
        let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
        if sin2_t >= 1.0 {
            return 1.0;
        }
        let cos_t = (1.0 - sin2_t).sqrt();
        let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
        let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
        0.5 * (rs * rs + rp * rp)
    }

    /// Fdr = 2 int_0^1 F(mu) mu dmu, by Simpson's rule.
    fn fdr_exact(eta: f64) -> f64 {
        let n = 20_000;
        let h = 1.0 / n as f64;
        let f = |mu: f64| 2.0 * fresnel64(mu, eta) * mu;
        let mut s = f(0.0) + f(1.0);
        for i in 1..n {
            s += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        s * h / 3.0
    }

    #[test]
    fn fresnel_diffuse_reflectance_fits_the_integral() {
        for eta in [1.2f32, 1.5, 1.9, 1.0 / 1.2, 1.0 / 1.5, 1.0 / 1.9] {
            let (fit, exact) = (
                fresnel_diffuse_reflectance(eta) as f64,
                fdr_exact(eta as f64),
            );
            assert!(
                (fit - exact).abs() < 0.01 * exact,
                "{eta}: {fit} vs {exact}"
            );
        }
    }

    #[test]
    fn plastic_eval_matches_the_formula() {
        let mut rng = Rng::new(&[9]);
        for (eta, nonlinear) in [(1.5f32, false), (1.5, true), (1.9, false)] {
            let b = plastic(eta, nonlinear);
            let e = eta as f64;
            let fdr_int = fdr_exact(1.0 / e);
            for _ in 0..20 {
                let mut wo = uniform_sphere(rng.next_2d());
                let mut wi = uniform_sphere(rng.next_2d());
                wo.z = wo.z.abs();
                wi.z = wi.z.abs();
                let got = b.eval(wo, wi, TransportMode::Radiance);
                for c in 0..3 {
                    let rho = b.diffuse_reflectance[c] as f64;
                    let internal = if nonlinear { rho * fdr_int } else { fdr_int };
                    let (co, ci) = (wo.z as f64, wi.z as f64);
                    let want = rho / (1.0 - internal)
                        * (1.0 - fresnel64(co, e))
                        * (1.0 - fresnel64(ci, e))
                        / (e * e * PI)
                        * ci;
                    // Fdr from the fits, within 1% of the integral.
                    assert!(
                        (got[c] as f64 - want).abs() <= 0.01 * want + 1e-7,
                        "{b:?}: {} vs {want}",
                        got[c]
                    );
                }
            }
            // The coat and below: one-sided.
            assert_eq!(
                b.eval(-Vec3::Z, Vec3::Z, TransportMode::Radiance),
                Rgb::ZERO
            );
            assert_eq!(
                b.eval(Vec3::Z, -Vec3::Z, TransportMode::Radiance),
                Rgb::ZERO
            );
        }
    }

    #[test]
    fn plastics_conserve_energy() {
        for nonlinear in [false, true] {
            for eta in [1.3f32, 1.5, 1.9] {
                let white = Plastic {
                    eta,
                    diffuse_reflectance: Rgb::ONE,
                    specular_reflectance: Rgb::ONE,
                    nonlinear,
                };
                let mut lobes = vec![Lobe::Plastic(white)];
                for kind in [BECKMANN, GGX] {
                    for alpha in [0.05, 0.3, 0.8] {
                        lobes.push(Lobe::RoughPlastic(RoughPlastic::new(
                            kind,
                            alpha,
                            eta,
                            Rgb::ONE,
                            Rgb::ONE,
                            nonlinear,
                        )));
                    }
                }
                for lobe in lobes {
                    for wo in views() {
                        let (a, se) = albedo(&lobe, wo, TransportMode::Radiance, 40_000, 5);
                        // The Fdr fits are within about 1% of the integral they stand for.
                        assert!(a.max_element() <= 1.01 + 4.0 * se, "{lobe:?} {wo}: {a}");
                    }
                }
            }
        }
    }

    #[test]
    fn rough_coat_tends_to_the_smooth_one() {
        for kind in [BECKMANN, GGX] {
            let b = RoughPlastic::new(kind, 0.01, 1.5, Rgb::ONE, Rgb::ONE, false);
            for cos in [1.0f32, 0.7, 0.3] {
                let t = b.external_transmittance(cos) as f64;
                let smooth = 1.0 - fresnel64(cos as f64, 1.5);
                assert!((t - smooth).abs() < 2e-3, "{cos}: {t} vs {smooth}");
            }
            // Mitsuba's mean over 64 cosines is a coarse quadrature of 2 int F mu dmu.
            let (r, smooth) = (b.internal_reflectance() as f64, fdr_exact(1.0 / 1.5));
            assert!((r - smooth).abs() < 0.02 * smooth, "{r} vs {smooth}");
        }
    }

    /// Values computed with mitsuba 3.9.1 (`scalar_rgb`, `mi.load_dict` of the plugin named
    /// with `int_ior` 1.5 and `ext_ior` 1.0, si.wi = wo, eval/pdf at wi; directions
    /// normalised in f32).
    #[test]
    #[allow(clippy::excessive_precision)] // Mitsuba's values as printed
    fn matches_mitsuba_3_9_1() {
        let n = |x: f32, y: f32, z: f32| Vec3::new(x, y, z).normalize();
        let metal = |kind, au, av| RoughConductor {
            distribution: Microfacet::new(kind, au, av),
            eta: Rgb::new(0.2, 0.9, 1.1),
            k: Rgb::new(3.9, 2.4, 2.1),
            specular_reflectance: Rgb::ONE,
        };
        let red = Rgb::new(0.5, 0.3, 0.2);
        let (a, b, c) = (n(0.3, 0.2, 0.93), n(-0.4, -0.1, 0.91), n(0.8, 0.2, 0.3));
        let d = n(-0.6, -0.1, 0.5);
        /// (lobe, wo, wi, eval in Radiance mode, in Importance mode, pdf).
        type Case = (Lobe, Vec3, Vec3, [f32; 3], [f32; 3], f32);
        #[rustfmt::skip]
        let cases: [Case; 9] = [
            (Lobe::Conductor(metal(GGX, 0.3, 0.3)), a, b,
             [0.798_209_4, 0.516_357, 0.420_422_2], [0.798_209_4, 0.516_357, 0.420_422_2], 0.842_452_05),
            (Lobe::Conductor(metal(BECKMANN, 0.1, 0.3)), n(0.5, 0.0, 0.866), n(-0.45, 0.1, 0.887),
             [2.614_171, 1.691_253, 1.378_187_8], [2.614_171, 1.691_253, 1.378_187_8], 2.746_974),
            (Lobe::Dielectric(dielectric(GGX, 0.2, 0.2, 1.5)), a, b,
             [0.066_089_88; 3], [0.066_089_88; 3], 0.066_225_28),
            (Lobe::Dielectric(dielectric(GGX, 0.2, 0.2, 1.5)), a, n(-0.2, -0.1, -0.97),
             [17.241_796; 3], [38.794_037; 3], 38.814_644),
            (Lobe::Dielectric(dielectric(BECKMANN, 0.3, 0.3, 1.5)), n(0.2, 0.1, -0.97), n(-0.3, -0.2, 0.93),
             [22.354_83; 3], [9.935_481; 3], 9.935_481),
            (Lobe::Plastic(Plastic { eta: 1.5, diffuse_reflectance: red, specular_reflectance: Rgb::ONE, nonlinear: false }), a, d,
             [0.100_626_08, 0.060_375_65, 0.040_250_435], [0.100_626_08, 0.060_375_65, 0.040_250_435], 0.179_492_03),
            (Lobe::Plastic(Plastic { eta: 1.5, diffuse_reflectance: red, specular_reflectance: Rgb::ONE, nonlinear: true }), c, d,
             [0.049_944_922, 0.025_609_938, 0.015_916_23], [0.049_944_922, 0.025_609_938, 0.015_916_23], 0.124_810_35),
            (Lobe::RoughPlastic(RoughPlastic::new(BECKMANN, 0.2, 1.5, red, Rgb::ONE, false)), a, b,
             [0.210_431_29, 0.156_394_99, 0.129_376_83], [0.210_431_29, 0.156_394_99, 0.129_376_83], 0.468_084_4),
            (Lobe::RoughPlastic(RoughPlastic::new(GGX, 0.3, 1.5, red, Rgb::ONE, true)), c, d,
             [0.154_053_81, 0.134_249_24, 0.125_690_88], [0.154_053_81, 0.134_249_24, 0.125_690_88], 0.598_558_07),
        ];
        for (lobe, wo, wi, radiance, importance, pdf) in cases {
            let r = lobe.eval(wo, wi, TransportMode::Radiance);
            let i = lobe.eval(wo, wi, TransportMode::Importance);
            let p = lobe.pdf(wo, wi);
            let close = |x: f32, y: f32| (x - y).abs() <= 1e-4 * y.abs();
            for ch in 0..3 {
                assert!(
                    close(r[ch], radiance[ch]),
                    "{lobe:?}: radiance {r} vs {radiance:?}"
                );
                assert!(
                    close(i[ch], importance[ch]),
                    "{lobe:?}: importance {i} vs {importance:?}"
                );
            }
            assert!(close(p, pdf), "{lobe:?}: pdf {p} vs {pdf}");
        }
    }

    /// The two glossy materials of scenes/glossy-caustic.xml as Mitsuba 3.9.1 reads them
    /// (`scalar_rgb`, `mi.load_dict`): `roughconductor` "Au" (its RGB eta and k), GGX alpha
    /// 0.2; `roughplastic` GGX alpha 0.15 with the default indices (polypropylene 1.49 in
    /// air 1.000277), linear. Where foton's image of that scene stood 0.45 % above Mitsuba's,
    /// these agreed: the cause was the light's BSDF (see the Mitsuba reader).
    #[test]
    #[allow(clippy::excessive_precision)] // Mitsuba's values as printed
    fn matches_mitsuba_3_9_1_on_glossy_caustic() {
        let n = |x: f32, y: f32, z: f32| Vec3::new(x, y, z).normalize();
        let (eta, k) = crate::material::conductor("Au").unwrap();
        let gold = Lobe::Conductor(RoughConductor {
            distribution: Microfacet::isotropic(GGX, 0.2),
            eta,
            k,
            specular_reflectance: Rgb::ONE,
        });
        let wall = Rgb::new(0.3, 0.35, 0.5);
        let plastic = Lobe::RoughPlastic(RoughPlastic::new(
            GGX,
            0.15,
            1.49 / 1.000277,
            wall,
            Rgb::ONE,
            false,
        ));
        let pairs = [
            (n(0.3, 0.2, 0.93), n(-0.4, -0.1, 0.91)),
            (n(0.8, 0.2, 0.3), n(-0.6, -0.1, 0.5)),
            (n(0.1, 0.0, 0.99), n(0.2, 0.1, 0.3)),
        ];
        /// Mitsuba's eval (cosine included) and pdf at each of the pairs.
        type Values = [([f32; 3], f32); 3];
        #[rustfmt::skip]
        let expected: [(&Lobe, Values); 2] = [
            (&plastic, [
                ([0.168_216_48, 0.180_573_03, 0.217_642_68], 0.504_718_42),
                ([0.191_406_86, 0.198_772_59, 0.220_869_78], 0.691_449_22),
                ([0.068_173_267, 0.079_004_869, 0.111_499_69], 0.238_227_43),
            ]),
            (&gold, [
                ([1.579_997_2, 1.310_744_5, 0.530_818_22], 1.637_943_9),
                ([1.604_143_5, 1.341_361_3, 0.620_336_95], 1.691_573_3),
                ([0.115_657_23, 0.095_953_36, 0.038_797_796], 0.120_307_33),
            ]),
        ];
        for (lobe, values) in expected {
            for (&(wo, wi), (f, pdf)) in pairs.iter().zip(values) {
                let e = lobe.eval(wo, wi, TransportMode::Radiance);
                let p = lobe.pdf(wo, wi);
                let close = |x: f32, y: f32| (x - y).abs() <= 1e-4 * y.abs();
                for ch in 0..3 {
                    assert!(close(e[ch], f[ch]), "{lobe:?} {wo} {wi}: {e} vs {f:?}");
                }
                assert!(close(p, pdf), "{lobe:?} {wo} {wi}: pdf {p} vs {pdf}");
            }
        }
    }

    #[test]
    fn odd_input_gives_zero_not_nan() {
        let odd = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::splat(f32::NAN),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1e-8),
        ];
        let mut lobes: Vec<Lobe> = cases().into_iter().map(|(l, _)| l).collect();
        lobes.push(Lobe::Dielectric(dielectric(GGX, 0.3, 0.3, 1.0)));
        lobes.push(Lobe::Dielectric(dielectric(GGX, 0.3, 0.3, 0.0)));
        lobes.push(Lobe::Conductor(conductor(GGX, 0.0, 0.0)));
        for lobe in lobes {
            for &wo in odd.iter().chain(&[Vec3::Z, -Vec3::Z]) {
                for &wi in odd.iter().chain(&[Vec3::Z, -Vec3::Z]) {
                    for mode in [TransportMode::Radiance, TransportMode::Importance] {
                        let f = lobe.eval(wo, wi, mode);
                        assert!(
                            f.is_finite() && f.min_element() >= 0.0,
                            "{lobe:?} {wo} {wi}: {f}"
                        );
                    }
                    let p = lobe.pdf(wo, wi);
                    assert!(p.is_finite() && p >= 0.0, "{lobe:?} {wo} {wi}: {p}");
                }
                for u in [Vec2::ZERO, Vec2::ONE, Vec2::new(0.5, 0.999_999_9)] {
                    for uc in [0.0, 0.999_999_9] {
                        if let Some(s) = lobe.sample(wo, u, uc, TransportMode::Radiance) {
                            assert!(
                                s.wi.is_finite() && s.weight.is_finite() && s.pdf > 0.0,
                                "{lobe:?} {wo}: {s:?}"
                            );
                        }
                    }
                }
            }
        }
    }
}
