//! `principled`: Disney's principled BSDF as Mitsuba 3's `principled` (Burley 2012 and 2015;
//! the lobe is [`PrincipledBxdf`]): a diffuse base with retro-reflection, fake subsurface and
//! sheen, a GGX specular reflection with the principled Fresnel term (dielectric, tinted,
//! metallic), a GGX specular transmission, and a GTR1 clearcoat.
//!
//! | Parameter         | Type             | Meaning                                          | Default |
//! |-------------------|------------------|--------------------------------------------------|---------|
//! | `base_color`      | RGB / texture    | the colour                                       | `0.5`   |
//! | `roughness`       | number / texture | roughness of the main specular lobes             | `0.5`   |
//! | `anisotropic`     | number / texture | 0: isotropic; towards 1, stretched along the tangent | `0` |
//! | `metallic`        | number / texture | blends the dielectric towards a metal            | `0`     |
//! | `spec_trans`      | number / texture | blends the diffuse base towards specular transmission | `0` |
//! | `eta`             | number           | inside over outside index (or give `specular`)   | from `specular` |
//! | `specular`        | number           | reflectance at normal incidence, eta = 2 / (1 - sqrt(0.08 specular)) - 1 | `0.5` |
//! | `spec_tint`       | number / texture | tints the dielectric reflection with `base_color` | `0`    |
//! | `sheen`           | number / texture | amount of the grazing sheen lobe                 | `0`     |
//! | `sheen_tint`      | number / texture | tints the sheen with `base_color`                | `0`     |
//! | `flatness`        | number / texture | blends the diffuse towards the fake subsurface   | `0`     |
//! | `clearcoat`       | number / texture | amount of the clearcoat lobe                     | `0`     |
//! | `clearcoat_gloss` | number / texture | 0: a rough (alpha 0.1), 1: a glossy (0.001) coat | `0`     |
//! | `diffuse_reflectance_sampling_rate` | number | weight of the diffuse lobe in sampling | `1`     |
//! | `main_specular_sampling_rate` | number | weight of the specular lobes in sampling     | `1`     |
//! | `clearcoat_sampling_rate` | number   | weight of the clearcoat in sampling              | `1`     |
//! | `twosided`        | bool             | the front's scattering on both sides (Mitsuba's `twosided` around it); not with `spec_trans` | `false` |
//!
//! Weights lie in [0, 1]; `roughness`, `sheen` and `clearcoat` may exceed 1. A numeric
//! parameter given as a texture table reads the texture's luminance. Given `spec_trans`, an
//! `eta` of 1 is taken as 1.001 and a `specular` of 0 as 0.001 (as Mitsuba does: there is no
//! transmission lobe without an interface).
//!
//! Seen from the front (wo above the surface), every lobe applies. Seen from behind, the
//! surface is the inside of the transmitting part alone: GGX reflection with the plain
//! dielectric Fresnel term and transmission, both weighted by (1 - metallic) spec_trans;
//! black without `spec_trans`. Lobes are chosen with probabilities proportional to the
//! diffuse weight (1 - metallic)(1 - spec_trans), a quarter of `clearcoat` and 1 for the
//! specular lobes (times the sampling rates), the specular ones split between reflection and
//! transmission by the dielectric Fresnel term of the sampled microfacet; from behind,
//! reflection and transmission by that Fresnel term alone.
//!
//! Differences from Mitsuba 3: from behind without transmission Mitsuba's `pdf` is that of
//! the specular reflection although `sample` returns nothing there (and `eval` is black); it
//! is zero here, so that `pdf` is the density `sample` draws from. The sheen is added
//! wherever its terms say (Mitsuba's vectorised variants); Mitsuba's `scalar_rgb` adds it
//! only where the diffuse lobe is on, which differs when `spec_trans` is 1.

use crate::texture::TextureEvalContext;
use super::principled_common::{
    Gtr1, Scalar, clearcoat_g1, compatible, diffuse, distribution, fresnel, lerp, read_rate, read_scalar, refract,
    schlick_fresnel, schlick_fresnel_weight, schlick_r0, schlick_weight, sheen_color, tint,
};
use super::{SurfaceMaterial, reflectance};
use crate::Rgb;
use crate::registry::Factory;
use crate::sampling::cosine_hemisphere;
use crate::scattering::{Bxdf, LocalSample, TransportMode, reflect};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct PrincipledMaterial {
    pub base_color: Texture,
    pub roughness: Scalar,
    pub anisotropic: Scalar,
    pub metallic: Scalar,
    pub spec_trans: Scalar,
    pub spec_tint: Scalar,
    pub sheen: Scalar,
    pub sheen_tint: Scalar,
    pub flatness: Scalar,
    pub clearcoat: Scalar,
    pub clearcoat_gloss: Scalar,
    /// Inside over outside.
    pub eta: f32,
    /// The sampling rates of the diffuse, main specular and clearcoat lobes.
    pub diffuse_rate: f32,
    pub specular_rate: f32,
    pub clearcoat_rate: f32,
    pub twosided: bool,
}

/// The principled BSDF at a point, its parameters looked up there, with the front side's
/// lobe-selection probabilities (which depend on the point's weights only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledBxdf {
    pub base_color: Rgb,
    pub roughness: f32,
    pub anisotropic: f32,
    pub metallic: f32,
    pub spec_trans: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    pub clearcoat: f32,
    /// The clearcoat's GTR1 roughness, 0.1 to 0.001 as `clearcoat_gloss` goes from 0 to 1.
    pub clearcoat_alpha: f32,
    pub eta: f32,
    /// Probabilities of choosing the diffuse, the specular (reflection or transmission) and
    /// the clearcoat lobe for wo above the surface.
    pub p_diffuse: f32,
    pub p_specular: f32,
    pub p_clearcoat: f32,
}

impl SurfaceMaterial for PrincipledMaterial {
    type Bxdf = PrincipledBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> PrincipledBxdf {
        let metallic = self.metallic.at(ctx);
        let spec_trans = self.spec_trans.at(ctx);
        let clearcoat = self.clearcoat.at(ctx);
        let p_diffuse = (1.0 - metallic) * (1.0 - spec_trans) * self.diffuse_rate;
        let p_clearcoat = 0.25 * clearcoat * self.clearcoat_rate;
        let total = p_diffuse + p_clearcoat + self.specular_rate;
        let norm = if total > 0.0 { 1.0 / total } else { 0.0 };
        PrincipledBxdf {
            base_color: self.base_color.at(ctx),
            roughness: self.roughness.at(ctx),
            anisotropic: self.anisotropic.at(ctx),
            metallic,
            spec_trans,
            spec_tint: self.spec_tint.at(ctx),
            sheen: self.sheen.at(ctx),
            sheen_tint: self.sheen_tint.at(ctx),
            flatness: self.flatness.at(ctx),
            clearcoat,
            clearcoat_alpha: lerp(0.1, 0.001, self.clearcoat_gloss.at(ctx)),
            eta: self.eta,
            p_diffuse: p_diffuse * norm,
            p_specular: self.specular_rate * norm,
            p_clearcoat: p_clearcoat * norm,
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.base_color.is_constant()
            || [
                &self.roughness,
                &self.anisotropic,
                &self.metallic,
                &self.spec_trans,
                &self.spec_tint,
                &self.sheen,
                &self.sheen_tint,
                &self.flatness,
                &self.clearcoat,
                &self.clearcoat_gloss,
            ]
            .iter()
            .any(|s| !s.is_constant())
            || self.anisotropic.given()
    }

    fn twosided(&self) -> bool {
        self.twosided
    }

    fn encloses_volume(&self) -> bool {
        self.spec_trans.given()
    }
}

impl PrincipledBxdf {
    /// Weight of the diffuse base.
    #[inline]
    fn brdf(&self) -> f32 {
        (1.0 - self.metallic) * (1.0 - self.spec_trans)
    }

    /// Weight of the transmitting part.
    #[inline]
    fn bsdf(&self) -> f32 {
        (1.0 - self.metallic) * self.spec_trans
    }

    /// The half vector of (wo, wi) pointing out of the surface, and the relative index along
    /// the path (from wo's side); None when undefined.
    #[inline]
    fn half_vector(&self, wo: Vec3, wi: Vec3, reflection: bool) -> Option<(Vec3, f32)> {
        let eta_path = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let h = (wo + wi * if reflection { 1.0 } else { eta_path }).normalize();
        if !h.is_finite() {
            return None;
        }
        Some((if h.z < 0.0 { -h } else { h }, eta_path))
    }

    /// The principled Fresnel term of the main reflection at the microfacet cosine `cos_h`:
    /// from the front, the dielectric term blended with Schlick's towards the tinted and the
    /// metallic colours; from behind, the dielectric term of the transmitting part.
    #[inline]
    fn fresnel(&self, f_dielectric: f32, cos_h: f32, front: bool) -> Rgb {
        if !front {
            return Rgb::splat(self.bsdf() * f_dielectric);
        }
        let (m, st) = (self.metallic, self.spec_tint);
        let mut f = Rgb::splat((1.0 - m) * (1.0 - st) * f_dielectric);
        if m > 0.0 {
            f += m * schlick_fresnel(self.base_color, cos_h, self.eta);
        }
        if st > 0.0 {
            let eta_it = if cos_h >= 0.0 {
                self.eta
            } else {
                1.0 / self.eta
            };
            let r0 = tint(self.base_color) * schlick_r0(eta_it);
            f += (1.0 - m) * st * schlick_fresnel(r0, cos_h, self.eta);
        }
        f
    }

    /// f(wo, wi) |cos theta_i| for light carried as `mode` says (radiance is scaled by
    /// 1 / eta^2 through the transmission).
    pub fn eval_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || !wo.is_finite() || !wi.is_finite() {
            return Rgb::ZERO;
        }
        let reflection = cos_o * cos_i > 0.0;
        let transmission = cos_o * cos_i < 0.0;
        if !reflection && !transmission {
            return Rgb::ZERO;
        }
        let front = cos_o > 0.0;
        let Some((h, eta_path)) = self.half_vector(wo, wi, reflection) else {
            return Rgb::ZERO;
        };
        let md = distribution(self.roughness, self.anisotropic);
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        let (f_dielectric, ..) = fresnel(oh, self.eta);
        let compatible = compatible(h, wo, wi, cos_o, reflection);
        let (brdf, bsdf) = (self.brdf(), self.bsdf());
        let mut value = Rgb::ZERO;

        if reflection && compatible && f_dielectric > 0.0 {
            let f = self.fresnel(f_dielectric, oh, front);
            value += f * (md.d(h) * md.g(wo, wi, h) / (4.0 * cos_o.abs()));
        }
        if transmission && compatible && bsdf > 0.0 && f_dielectric < 1.0 {
            // Radiance is compressed into the smaller solid angle on the denser side; flux
            // (importance) is not (Veach 1997, 5.2).
            let scale = match mode {
                TransportMode::Radiance => 1.0 / (eta_path * eta_path),
                TransportMode::Importance => 1.0,
            };
            let denom = oh + eta_path * ih;
            let t = scale * (1.0 - f_dielectric) * md.d(h) * md.g(wo, wi, h) * eta_path * eta_path
                * oh
                * ih
                / (cos_o * denom * denom);
            value += self.base_color.map(f32::sqrt) * (bsdf * t.abs());
        }
        if !(reflection && front) {
            return value;
        }
        if self.clearcoat > 0.0 && compatible {
            let f = schlick_fresnel_weight(oh, self.eta) * 0.96 + 0.04;
            let d = Gtr1 {
                alpha: self.clearcoat_alpha,
            }
            .d(h);
            let g = clearcoat_g1(wo, h) * clearcoat_g1(wi, h);
            value += Rgb::splat(self.clearcoat * 0.25 * f * d * g * cos_i.abs());
        }
        let cos_d = h.dot(wi);
        if brdf > 0.0 {
            let f = diffuse(
                cos_i.abs(),
                cos_o.abs(),
                cos_d,
                self.roughness,
                self.flatness,
            );
            value += self.base_color * (brdf * cos_i.abs() * FRAC_1_PI * f);
        }
        if self.sheen > 0.0 && self.metallic < 1.0 {
            let c = sheen_color(self.base_color, self.sheen_tint);
            value += c * (self.sheen
                * (1.0 - self.metallic)
                * schlick_weight(cos_d.abs())
                * cos_i.abs());
        }
        value
    }

    /// The probabilities of the specular reflection and transmission for the dielectric
    /// Fresnel term `f` of their microfacet, as `sample` chooses them.
    #[inline]
    fn specular_probabilities(&self, f: f32, front: bool) -> (f32, f32) {
        if front {
            let t = self.bsdf() * (1.0 - f);
            (self.p_specular * (1.0 - t), self.p_specular * t)
        } else {
            (f, 1.0 - f)
        }
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || !wo.is_finite() || !wi.is_finite() {
            return 0.0;
        }
        let front = cos_o > 0.0;
        // From behind only the transmitting part is sampled.
        if !front && self.bsdf() <= 0.0 {
            return 0.0;
        }
        let reflection = cos_o * cos_i > 0.0;
        let transmission = cos_o * cos_i < 0.0;
        if !reflection && !transmission {
            return 0.0;
        }
        let Some((h, eta_path)) = self.half_vector(wo, wi, reflection) else {
            return 0.0;
        };
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        let (f, ..) = fresnel(oh, self.eta);
        let (p_reflect, p_transmit) = self.specular_probabilities(f, front);
        let dh_dwi = if reflection {
            1.0 / (4.0 * ih)
        } else {
            eta_path * eta_path * ih / (oh + eta_path * ih).powi(2)
        }
        .abs();
        let mut pdf = 0.0;
        if compatible(h, wo, wi, cos_o, reflection) {
            let md = distribution(self.roughness, self.anisotropic);
            let visible = md.pdf(wo * cos_o.signum(), h) * dh_dwi;
            pdf += visible * if reflection { p_reflect } else { p_transmit };
            if reflection && front && self.p_clearcoat > 0.0 {
                let cc = Gtr1 {
                    alpha: self.clearcoat_alpha,
                };
                pdf += self.p_clearcoat * cc.pdf(h) * dh_dwi;
            }
        }
        if reflection && front {
            pdf += self.p_diffuse * cos_i * FRAC_1_PI;
        }
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        let cos_o = wo.z;
        if cos_o == 0.0 || !wo.is_finite() {
            return None;
        }
        let front = cos_o > 0.0;
        if !front && self.bsdf() <= 0.0 {
            return None;
        }
        let (p_diffuse, p_clearcoat) = if front {
            (self.p_diffuse, self.p_clearcoat)
        } else {
            (0.0, 0.0)
        };
        let wi = if uc < p_diffuse {
            cosine_hemisphere(u)
        } else if uc < p_diffuse + p_clearcoat {
            let m = Gtr1 {
                alpha: self.clearcoat_alpha,
            }
            .sample(u);
            let wi = reflect(wo, m);
            if wi.z <= 0.0 || !compatible(m, wo, wi, cos_o, true) {
                return None;
            }
            wi
        } else {
            let md = distribution(self.roughness, self.anisotropic);
            let (m, pdf_m) = md.sample(wo * cos_o.signum(), u);
            if pdf_m <= 0.0 {
                return None;
            }
            let (f, cos_t, _, eta_ti) = fresnel(wo.dot(m), self.eta);
            let (_, p_transmit) = self.specular_probabilities(f, front);
            let reflection = uc >= p_diffuse + p_clearcoat + p_transmit;
            let wi = if reflection {
                reflect(wo, m)
            } else {
                refract(wo, m, cos_t, eta_ti)
            };
            let side = if reflection { 1.0 } else { -1.0 };
            if wi.z * cos_o * side <= 0.0 || !compatible(m, wo, wi, cos_o, reflection) {
                return None;
            }
            wi
        };
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        let weight = self.eval_mode(wo, wi, mode) / pdf;
        if weight == Rgb::ZERO || !weight.is_finite() {
            return None;
        }
        Some(LocalSample {
            wi,
            weight,
            pdf,
            delta: false,
        })
    }

    /// The sharpest glossy part: the main specular lobe, or the clearcoat if present.
    pub fn roughness(&self) -> f32 {
        let md = distribution(self.roughness, self.anisotropic);
        if self.clearcoat > 0.0 {
            md.roughness().min(self.clearcoat_alpha)
        } else {
            md.roughness()
        }
    }
}

impl Bxdf for PrincipledBxdf {
    #[inline(never)]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.eval_mode(wo, wi, TransportMode::Radiance)
    }

    #[inline(never)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        PrincipledBxdf::pdf(self, wo, wi)
    }

    #[inline(never)]
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        PrincipledBxdf::sample(self, wo, u, uc, mode)
    }

    #[inline]
    fn roughness(&self) -> f32 {
        PrincipledBxdf::roughness(self)
    }

    fn transmits(&self) -> bool {
        self.bsdf() > 0.0
    }
}

pub const FACTORY: Factory<PrincipledMaterial> = Factory {
    name: "principled",
    description: "Disney's principled BSDF (Mitsuba 3's): diffuse, sheen, metal, glass, clearcoat",
    create: |m, _, resources| {
        let unit = (0.0, 1.0);
        let amount = (0.0, f32::INFINITY);
        let spec_trans = read_scalar(m, "spec_trans", 0.0, unit, resources)?;
        let eta = match (m.has("eta"), m.has("specular")) {
            (true, true) => {
                return Err(m.error("specular", "give either `eta` or `specular`, not both"));
            }
            (true, false) => {
                let eta = m.f32_required("eta")?;
                if eta <= 0.0 {
                    return Err(m.error("eta", format!("must be positive, found {eta}")));
                }
                if eta == 1.0 && spec_trans.given() {
                    1.001
                } else {
                    eta
                }
            }
            (false, _) => {
                let mut specular = m.f32("specular", 0.5)?;
                if !(0.0..12.5).contains(&specular) {
                    return Err(m.error(
                        "specular",
                        format!("expected a number in [0, 12.5) (eta = 2 / (1 - sqrt(0.08 specular)) - 1), found {specular}"),
                    ));
                }
                if specular == 0.0 && spec_trans.given() {
                    specular = 1e-3;
                }
                2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
            }
        };
        let twosided = m.bool("twosided", false)?;
        if twosided && spec_trans.given() {
            return Err(m.error(
                "twosided",
                "a two-sided principled material cannot transmit (give no `spec_trans`)",
            ));
        }
        Ok(Box::new(PrincipledMaterial {
            base_color: reflectance(m, "base_color", Rgb::splat(0.5), resources)?,
            roughness: read_scalar(m, "roughness", 0.5, amount, resources)?,
            anisotropic: read_scalar(m, "anisotropic", 0.0, unit, resources)?,
            metallic: read_scalar(m, "metallic", 0.0, unit, resources)?,
            spec_trans,
            spec_tint: read_scalar(m, "spec_tint", 0.0, unit, resources)?,
            sheen: read_scalar(m, "sheen", 0.0, amount, resources)?,
            sheen_tint: read_scalar(m, "sheen_tint", 0.0, unit, resources)?,
            flatness: read_scalar(m, "flatness", 0.0, unit, resources)?,
            clearcoat: read_scalar(m, "clearcoat", 0.0, amount, resources)?,
            clearcoat_gloss: read_scalar(m, "clearcoat_gloss", 0.0, unit, resources)?,
            eta,
            diffuse_rate: read_rate(m, "diffuse_reflectance_sampling_rate")?,
            specular_rate: read_rate(m, "main_specular_sampling_rate")?,
            clearcoat_rate: read_rate(m, "clearcoat_sampling_rate")?,
            twosided,
        }))
    },
};

#[cfg(test)]
mod tests {
    use super::*;

    /// The GTR1 sampler draws from D cos: its pdf integrates to one over the hemisphere, and
    /// a sample's cosine has the CDF that inverts to the sampling formula.
    #[test]
    fn gtr1_is_normalised() {
        // Down to alpha 0.03: the midpoint rule in cos theta resolves the peak (a half-width
        // of about alpha^2 in cos theta).
        for alpha in [0.1f32, 0.03] {
            let cc = Gtr1 { alpha };
            // Integral of D cos over the hemisphere in cos theta (phi gives 2 pi).
            let n = 200_000;
            let mut sum = 0.0f64;
            for k in 0..n {
                let c = (k as f64 + 0.5) / n as f64;
                let m = Vec3::new((1.0 - c * c).sqrt() as f32, 0.0, c as f32);
                sum += cc.pdf(m) as f64;
            }
            let integral = sum / n as f64 * std::f64::consts::TAU;
            assert!((integral - 1.0).abs() < 2e-3, "alpha {alpha}: {integral}");
            let m = cc.sample(Vec2::new(0.3, 0.5));
            assert!((m.length() - 1.0).abs() < 1e-5 && m.z > 0.0);
        }
    }
}
