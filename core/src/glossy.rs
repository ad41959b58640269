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

use crate::Rgb;
use crate::material::{TransportMode, fresnel_conductor, fresnel_dielectric};
use crate::microfacet::{Microfacet, MicrofacetKind};
use crate::sampling::cosine_hemisphere;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalSample {
    pub wi: Vec3,
    /// f |cos theta_i| / pdf: what the path throughput is multiplied by.
    pub weight: Rgb,
    /// Solid-angle pdf times the probability of the chosen lobe; for a delta lobe only that
    /// probability.
    pub pdf: f32,
    pub delta: bool,
}

/// True for a finite positive number (false for NaN).
#[inline]
fn positive(x: f32) -> bool {
    x > 0.0 && x.is_finite()
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
        if wo.z <= 0.0 || wi.z <= 0.0 {
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
        if wo.z <= 0.0 || wi.z <= 0.0 || wo.dot(h) <= 0.0 || wi.dot(h) <= 0.0 {
            return 0.0;
        }
        // D_wo(h) / (4 wi.h), with wo.h = wi.h.
        self.distribution.d(h) * self.distribution.smith_g1(wo, h) / (4.0 * wo.z)
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, _uc: f32, _mode: TransportMode) -> Option<LocalSample> {
        if wo.z <= 0.0 {
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
        if cos_o == 0.0 || !positive(self.eta) {
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
        if cos_o == 0.0 || !positive(self.eta) {
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
        if cos_o == 0.0 || !positive(self.eta) {
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

    /// Probability of sampling the delta coat for this wo (cos_o > 0).
    fn prob_specular(&self, f_o: f32) -> f32 {
        let w = specular_sampling_weight(self.specular_reflectance, self.diffuse_reflectance);
        specular_probability(f_o * w, (1.0 - f_o) * (1.0 - w))
    }

    /// The diffuse part only (the delta coat is not a function).
    pub fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta);
        let f_i = fresnel_dielectric(wi.z, self.eta);
        self.diffuse() * (wi.z * FRAC_1_PI * (1.0 - f_o) * (1.0 - f_i) / (self.eta * self.eta))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta);
        (1.0 - self.prob_specular(f_o)) * wi.z * FRAC_1_PI
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, uc: f32, _mode: TransportMode) -> Option<LocalSample> {
        if wo.z <= 0.0 {
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
/// Built by [`RoughPlastic::new`], which integrates the coat's transmittance and internal
/// reflectance once, exactly as Mitsuba does: T at 64 cosines in [1e-6, 1] (linearly spaced)
/// by a 32 x 32 Gauss-Legendre rule over the visible-normal sample space, E[G1(wt, m) (1 - F)];
/// R_int as 2 x the mean over the same cosines of cos E[G1(wr, m) F] with eta inverted, by a
/// 128 x 128 rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    pub distribution: Microfacet,
    pub eta: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    pub nonlinear: bool,
    external_transmittance: [f32; ROUGH_TRANSMITTANCE_RES],
    internal_reflectance: f32,
}

impl RoughPlastic {
    /// `eta` must be positive and differ from 1 (Mitsuba rejects equal indices); otherwise the
    /// coat is treated as absent (T = 1, R_int = 0).
    pub fn new(
        kind: MicrofacetKind,
        alpha: f32,
        eta: f32,
        diffuse_reflectance: Rgb,
        specular_reflectance: Rgb,
        nonlinear: bool,
    ) -> Self {
        let distribution = Microfacet::isotropic(kind, alpha);
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
                *t = coat_transmittance(&distribution, w, eta, &rule_t) as f32;
                sum_r += coat_reflectance(&distribution, w, 1.0 / eta, &rule_r) * mu as f64;
            }
            internal_reflectance = (2.0 * sum_r / ROUGH_TRANSMITTANCE_RES as f64) as f32;
        }
        RoughPlastic {
            distribution,
            eta,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            external_transmittance,
            internal_reflectance,
        }
    }

    pub fn roughness(&self) -> f32 {
        self.distribution.roughness()
    }

    /// The coat's directional transmittance T(cos theta) (linear in the table, as Mitsuba).
    pub fn external_transmittance(&self, cos: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0) * (ROUGH_TRANSMITTANCE_RES - 1) as f32;
        let i = (x as usize).min(ROUGH_TRANSMITTANCE_RES - 2);
        let (t0, t1) = (
            self.external_transmittance[i],
            self.external_transmittance[i + 1],
        );
        t0 + (t1 - t0) * (x - i as f32)
    }

    /// The coat's diffuse reflectance seen from inside, R_int.
    pub fn internal_reflectance(&self) -> f32 {
        self.internal_reflectance
    }

    fn prob_specular(&self, t_o: f32) -> f32 {
        let w = specular_sampling_weight(self.specular_reflectance, self.diffuse_reflectance);
        specular_probability((1.0 - t_o) * w, t_o * (1.0 - w))
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let md = &self.distribution;
        let h = (wo + wi).normalize_or_zero();
        let (f, ..) = fresnel(wo.dot(h), self.eta);
        let specular = self.specular_reflectance * (f * md.d(h) * md.g(wo, wi, h) / (4.0 * wo.z));

        let rho = self.diffuse_reflectance;
        let internal = if self.nonlinear {
            rho * self.internal_reflectance
        } else {
            Rgb::splat(self.internal_reflectance)
        };
        let t_o = self.external_transmittance(wo.z);
        let t_i = self.external_transmittance(wi.z);
        let diffuse =
            rho / (Rgb::ONE - internal) * (FRAC_1_PI * wi.z * t_o * t_i / (self.eta * self.eta));
        specular + diffuse
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
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
        if wo.z <= 0.0 {
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
    let mut sum = 0.0;
    for &(x, wx) in rule {
        for &(y, wy) in rule {
            let (m, pdf) = md.sample(w, Vec2::new(x, y));
            if pdf <= 0.0 {
                continue;
            }
            let r = reflect(w, m);
            if r.z <= 0.0 {
                continue;
            }
            let (f, ..) = fresnel(w.dot(m), eta);
            sum += wx * wy * (f * md.smith_g1(r, m)) as f64;
        }
    }
    sum
}

/// Fraction of light from `w` transmitted through a rough dielectric interface of relative
/// index `eta` and not masked on the other side: E over visible normals of (1 - F)
/// G1(refracted, m) (Mitsuba's `eval_transmittance`).
fn coat_transmittance(md: &Microfacet, w: Vec3, eta: f32, rule: &[(f32, f64)]) -> f64 {
    let mut sum = 0.0;
    for &(x, wx) in rule {
        for &(y, wy) in rule {
            let (m, pdf) = md.sample(w, Vec2::new(x, y));
            if pdf <= 0.0 {
                continue;
            }
            let (f, cos_t, _, eta_ti) = fresnel(w.dot(m), eta);
            let t = refract(w, m, cos_t, eta_ti);
            if t.z * w.z >= 0.0 {
                continue;
            }
            sum += wx * wy * ((1.0 - f) * md.smith_g1(t, m)) as f64;
        }
    }
    sum
}
