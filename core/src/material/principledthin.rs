//! `principledthin`: the principled BSDF of a thin sheet (a leaf, paper, a curtain) as Mitsuba
//! 3's `principledthin` (Burley 2015; the lobe is [`PrincipledThinBxdf`]): Burley's diffuse
//! with retro-reflection, fake subsurface and sheen, a Lambertian diffuse transmission, and
//! a GGX specular reflection and transmission through the sheet without refraction (the
//! transmitted direction is the reflected one mirrored through the surface, on a GGX
//! distribution whose roughness is scaled by the index, (0.65 eta - 0.35) roughness). The
//! sheet bounds no volume and looks the same from both sides.
//!
//! | Parameter     | Type             | Meaning                                              | Default |
//! |---------------|------------------|------------------------------------------------------|---------|
//! | `base_color`  | RGB / texture    | the colour                                           | `0.5`   |
//! | `roughness`   | number / texture | roughness of the specular lobes                      | `0.5`   |
//! | `anisotropic` | number / texture | 0: isotropic; towards 1, stretched along the tangent | `0`     |
//! | `spec_trans`  | number / texture | blends the diffuse lobes towards the specular ones   | `0`     |
//! | `eta`         | number / texture | the sheet's index relative to the outside            | `1.5`   |
//! | `spec_tint`   | number / texture | tints the specular reflection with `base_color`      | `0`     |
//! | `sheen`       | number / texture | amount of the grazing sheen lobe                     | `0`     |
//! | `sheen_tint`  | number / texture | tints the sheen with `base_color`                    | `0`     |
//! | `flatness`    | number / texture | blends the diffuse towards the fake subsurface       | `0`     |
//! | `diff_trans`  | number / texture | 0: diffuse reflection only, 2: diffuse transmission only | `0` |
//! | `specular_reflectance_sampling_rate` | number | weight of the specular reflection in sampling | `1` |
//! | `specular_transmittance_sampling_rate` | number | weight of the specular transmission in sampling | `1` |
//! | `diffuse_reflectance_sampling_rate` | number | weight of the diffuse reflection in sampling | `1` |
//! | `diffuse_transmittance_sampling_rate` | number | weight of the diffuse transmission in sampling | `1` |
//!
//! Weights lie in [0, 1] (`diff_trans` in [0, 2]); `roughness` and `sheen` may exceed 1. A
//! numeric parameter given as a texture table reads the texture's luminance. Lobes are
//! chosen with probabilities proportional to spec_trans / 2 for each specular lobe,
//! (1 - spec_trans)(1 - diff_trans / 2) for the diffuse reflection and
//! (1 - spec_trans) diff_trans / 2 for the diffuse transmission (times the sampling rates).
//!
//! As Mitsuba's, the specular transmission masks the transmitted direction itself against the
//! half vector of its mirror image; where that direction sees the microfacet from behind the
//! lobe is black, which makes it non-reciprocal over part of the sphere (the light's and the
//! viewer's directions swapped give different values there).

use crate::texture::TextureEvalContext;
use super::principled_common::{
    Scalar, compatible, diffuse, distribution, fresnel, read_rate, read_scalar, schlick_fresnel,
    schlick_r0, schlick_weight, sheen_color, tint,
};
use super::{SurfaceMaterial, reflectance};
use crate::Rgb;
use crate::microfacet::Microfacet;
use crate::registry::Factory;
use crate::sampling::cosine_hemisphere;
use crate::scattering::{Bxdf, LocalSample, TransportMode, reflect};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct PrincipledThinMaterial {
    pub base_color: Texture,
    pub roughness: Scalar,
    pub anisotropic: Scalar,
    pub spec_trans: Scalar,
    pub eta: Scalar,
    pub spec_tint: Scalar,
    pub sheen: Scalar,
    pub sheen_tint: Scalar,
    pub flatness: Scalar,
    /// As given: in [0, 2].
    pub diff_trans: Scalar,
    /// The sampling rates of the specular reflection and transmission and of the diffuse
    /// reflection and transmission.
    pub rates: [f32; 4],
}

/// The thin principled BSDF at a point, its parameters looked up there, with the lobes'
/// selection probabilities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledThinBxdf {
    pub base_color: Rgb,
    pub roughness: f32,
    pub anisotropic: f32,
    pub spec_trans: f32,
    pub eta: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    /// Half the parameter: the fraction of the diffuse energy transmitted, in [0, 1].
    pub diff_trans: f32,
    /// Probabilities of choosing the specular reflection, the specular transmission, the
    /// diffuse reflection and the diffuse transmission.
    pub p: [f32; 4],
}

impl SurfaceMaterial for PrincipledThinMaterial {
    type Bxdf = PrincipledThinBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> PrincipledThinBxdf {
        let spec_trans = self.spec_trans.at(ctx);
        let diff_trans = self.diff_trans.at(ctx) / 2.0;
        let r = self.rates;
        let mut p = [
            spec_trans * r[0] / 2.0,
            spec_trans * r[1] / 2.0,
            r[2] * (1.0 - spec_trans) * (1.0 - diff_trans),
            r[3] * (1.0 - spec_trans) * diff_trans,
        ];
        let total: f32 = p.iter().sum();
        let norm = if total > 0.0 { 1.0 / total } else { 0.0 };
        for x in &mut p {
            *x *= norm;
        }
        PrincipledThinBxdf {
            base_color: self.base_color.at(ctx),
            roughness: self.roughness.at(ctx),
            anisotropic: self.anisotropic.at(ctx),
            spec_trans,
            eta: self.eta.at(ctx),
            spec_tint: self.spec_tint.at(ctx),
            sheen: self.sheen.at(ctx),
            sheen_tint: self.sheen_tint.at(ctx),
            flatness: self.flatness.at(ctx),
            diff_trans,
            p,
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.base_color.is_constant()
            || [
                &self.roughness,
                &self.anisotropic,
                &self.spec_trans,
                &self.eta,
                &self.spec_tint,
                &self.sheen,
                &self.sheen_tint,
                &self.flatness,
                &self.diff_trans,
            ]
            .iter()
            .any(|s| !s.is_constant())
            || self.anisotropic.given()
    }
}

impl PrincipledThinBxdf {
    /// The distributions of the specular reflection and of the specular transmission, whose
    /// roughness Burley scales by the index (2015, figure 15).
    #[inline]
    fn reflection_distribution(&self) -> Microfacet {
        distribution(self.roughness, self.anisotropic)
    }

    #[inline]
    fn transmission_distribution(&self) -> Microfacet {
        distribution((0.65 * self.eta - 0.35) * self.roughness, self.anisotropic)
    }

    /// wo and wi turned so that wo lies above the sheet (the sheet is the same from both
    /// sides), and the half vector of wo and wi mirrored above the sheet.
    #[inline]
    fn turned(wo: Vec3, wi: Vec3) -> (Vec3, Vec3, Vec3) {
        let s = if wo.z < 0.0 { -1.0 } else { 1.0 };
        let (wo, wi) = (wo * s, wi * s);
        let h = (wo + Vec3::new(wi.x, wi.y, wi.z.abs())).normalize();
        (wo, wi, h)
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z == 0.0 || !wo.is_finite() || !wi.is_finite() {
            return Rgb::ZERO;
        }
        let (wo, wi, h) = Self::turned(wo, wi);
        let (cos_o, cos_i) = (wo.z, wi.z);
        let reflection = cos_i > 0.0;
        let transmission = cos_i < 0.0;
        if !(reflection || transmission) || !h.is_finite() {
            return Rgb::ZERO;
        }
        let (st, dt) = (self.spec_trans, self.diff_trans);
        let mut value = Rgb::ZERO;
        if st > 0.0 && compatible(h, wo, wi, cos_o, reflection) {
            let (f, ..) = fresnel(wo.dot(h), self.eta);
            if reflection {
                let md = self.reflection_distribution();
                let mut f_thin = Rgb::splat(f);
                if self.spec_tint > 0.0 {
                    let r0 = tint(self.base_color) * schlick_r0(self.eta);
                    let schlick = schlick_fresnel(r0, wo.dot(h), self.eta);
                    f_thin += (schlick - f_thin) * self.spec_tint;
                }
                value += f_thin * (st * md.d(h) * md.g(wo, wi, h) / (4.0 * cos_o));
            } else {
                let md = self.transmission_distribution();
                value += self.base_color
                    * (st * (1.0 - f) * md.d(h) * md.g(wo, wi, h) / (4.0 * cos_o));
            }
        }
        if st < 1.0 && reflection && dt < 1.0 {
            let cos_d = h.dot(wi);
            let f = diffuse(cos_i, cos_o, cos_d, self.roughness, self.flatness);
            let w = (1.0 - st) * (1.0 - dt);
            value += self.base_color * (w * cos_i * FRAC_1_PI * f);
            if self.sheen > 0.0 {
                let c = sheen_color(self.base_color, self.sheen_tint);
                value += c * (self.sheen * w * schlick_weight(cos_d.abs()) * cos_i);
            }
        }
        if st < 1.0 && transmission && dt > 0.0 {
            value += self.base_color * ((1.0 - st) * dt * FRAC_1_PI * cos_i.abs());
        }
        value
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z == 0.0 || !wo.is_finite() || !wi.is_finite() {
            return 0.0;
        }
        let (wo, wi, h) = Self::turned(wo, wi);
        let reflection = wi.z > 0.0;
        let transmission = wi.z < 0.0;
        let [p_sr, p_st, p_dr, p_dt] = self.p;
        let mut pdf = 0.0;
        if reflection {
            pdf += p_dr * wi.z * FRAC_1_PI;
        } else if transmission {
            pdf += p_dt * -wi.z * FRAC_1_PI;
        } else {
            return 0.0;
        }
        let p_specular = if reflection { p_sr } else { p_st };
        if p_specular > 0.0 && h.is_finite() && compatible(h, wo, wi, wo.z, reflection) {
            let md = if reflection {
                self.reflection_distribution()
            } else {
                self.transmission_distribution()
            };
            let wr = Vec3::new(wi.x, wi.y, wi.z.abs());
            pdf += p_specular * md.pdf(wo, h) / (4.0 * wr.dot(h)).abs();
        }
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, uc: f32, _: TransportMode) -> Option<LocalSample> {
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        let s = if wo.z < 0.0 { -1.0 } else { 1.0 };
        let wo_up = wo * s;
        let [p_sr, p_st, p_dr, p_dt] = self.p;
        let local = if uc < p_sr + p_st {
            let reflection = uc < p_sr;
            let md = if reflection {
                self.reflection_distribution()
            } else {
                self.transmission_distribution()
            };
            let (m, pdf_m) = md.sample(wo_up, u);
            if pdf_m <= 0.0 {
                return None;
            }
            let mut w = reflect(wo_up, m);
            if !reflection {
                // Through the sheet without bending: the reflection mirrored to the far side.
                w.z = -w.z;
            }
            if (w.z > 0.0) != reflection || !compatible(m, wo_up, w, wo_up.z, reflection) {
                return None;
            }
            w
        } else if uc < p_sr + p_st + p_dr {
            cosine_hemisphere(u)
        } else if p_dt > 0.0 {
            -cosine_hemisphere(u)
        } else {
            return None;
        };
        let wi = local * s;
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        let weight = self.eval(wo, wi) / pdf;
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

    /// The sharper specular lobe's roughness.
    pub fn roughness(&self) -> f32 {
        let r = self.reflection_distribution().roughness();
        if self.spec_trans > 0.0 {
            r.min(self.transmission_distribution().roughness())
        } else {
            r
        }
    }
}

impl Bxdf for PrincipledThinBxdf {
    #[inline(never)]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        PrincipledThinBxdf::eval(self, wo, wi)
    }

    #[inline(never)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        PrincipledThinBxdf::pdf(self, wo, wi)
    }

    #[inline(never)]
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        PrincipledThinBxdf::sample(self, wo, u, uc, mode)
    }

    #[inline]
    fn roughness(&self) -> f32 {
        PrincipledThinBxdf::roughness(self)
    }

    fn transmits(&self) -> bool {
        self.spec_trans > 0.0 || (self.spec_trans < 1.0 && self.diff_trans > 0.0)
    }
}

pub const FACTORY: Factory<PrincipledThinMaterial> = Factory {
    name: "principledthin",
    description: "the principled BSDF of a thin sheet (Mitsuba 3's): diffuse and specular transmission",
    create: |m, _, resources| {
        let unit = (0.0, 1.0);
        let amount = (0.0, f32::INFINITY);
        let eta = read_scalar(m, "eta", 1.5, (0.0, f32::INFINITY), resources)?;
        if let Scalar::Constant(x) = eta
            && x <= 0.0
        {
            return Err(m.error("eta", format!("must be positive, found {x}")));
        }
        Ok(Box::new(PrincipledThinMaterial {
            base_color: reflectance(m, "base_color", Rgb::splat(0.5), resources)?,
            roughness: read_scalar(m, "roughness", 0.5, amount, resources)?,
            anisotropic: read_scalar(m, "anisotropic", 0.0, unit, resources)?,
            spec_trans: read_scalar(m, "spec_trans", 0.0, unit, resources)?,
            eta,
            spec_tint: read_scalar(m, "spec_tint", 0.0, unit, resources)?,
            sheen: read_scalar(m, "sheen", 0.0, amount, resources)?,
            sheen_tint: read_scalar(m, "sheen_tint", 0.0, unit, resources)?,
            flatness: read_scalar(m, "flatness", 0.0, unit, resources)?,
            diff_trans: read_scalar(m, "diff_trans", 0.0, (0.0, 2.0), resources)?,
            rates: [
                read_rate(m, "specular_reflectance_sampling_rate")?,
                read_rate(m, "specular_transmittance_sampling_rate")?,
                read_rate(m, "diffuse_reflectance_sampling_rate")?,
                read_rate(m, "diffuse_transmittance_sampling_rate")?,
            ],
        }))
    },
};
