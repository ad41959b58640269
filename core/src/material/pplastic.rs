//! `pplastic`: a rough plastic without internal reflections (Mitsuba 3's `pplastic`, as its
//! RGB variants render it: the polarisation it models is not tracked; the lobe is
//! [`PPlasticBxdf`]).
//!
//! | Parameter              | Type          | Meaning                                   | Default  |
//! |------------------------|---------------|-------------------------------------------|----------|
//! | `ior`                  | number        | the coat's index relative to the outside  | `1.49 / 1.000277` (polypropylene in air) |
//! | `diffuse_reflectance`  | RGB / texture | the base's albedo                         | `0.5`    |
//! | `specular_reflectance` | RGB / texture | scales the microfacet reflection          | `1`      |
//! | `distribution`, `alpha`, `alpha_u`, `alpha_v` | | the coat's microfacet roughness, as `roughconductor`'s | `beckmann`, `0.1` |
//! | `twosided`             | bool          | the same seen from behind                 | `false`  |
//!
//! f = specular_reflectance F(wo.h) D G / (4 cos_o cos_i) + diffuse_reflectance / pi
//! (1 - F(cos_o)) (1 - F(cos_i)): the microfacet reflection of a dielectric, and a Lambertian
//! base seen through two smooth refractions, nothing reflected back onto it. Samples the
//! microfacet lobe (visible normals) with probability s / (s + d), s and d the mean specular
//! and diffuse reflectances, the cosine-weighted hemisphere otherwise.

use crate::texture::TextureEvalContext;
use super::{RoughnessTextures, SurfaceMaterial, read_ior, read_roughness, reflectance};
use crate::Rgb;
use crate::microfacet::Microfacet;
use crate::registry::Factory;
use crate::sampling::cosine_hemisphere;
use crate::scattering::{
    Bxdf, LocalSample, TransportMode, fresnel_dielectric, reflect, sampled_direction,
};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PPlasticBxdf {
    pub distribution: Microfacet,
    pub eta: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    /// The probability of sampling the microfacet lobe.
    pub specular_weight: f32,
}

impl PPlasticBxdf {
    fn specular_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize_or_zero();
        if wo.dot(h) <= 0.0 || wi.dot(h) <= 0.0 {
            return 0.0;
        }
        self.distribution.d(h) * self.distribution.smith_g1(wo, h) / (4.0 * wo.z)
    }
}

impl Bxdf for PPlasticBxdf {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let h = (wo + wi).normalize_or_zero();
        let d = self.distribution.d(h);
        let specular = if d > 0.0 {
            let g = self.distribution.g(wo, wi, h);
            self.specular_reflectance
                * (fresnel_dielectric(wo.dot(h), self.eta) * d * g / (4.0 * wo.z))
        } else {
            Rgb::ZERO
        };
        let (f_o, f_i) = (
            fresnel_dielectric(wo.z, self.eta),
            fresnel_dielectric(wi.z, self.eta),
        );
        specular + self.diffuse_reflectance * ((1.0 - f_o) * (1.0 - f_i) * FRAC_1_PI * wi.z)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let p = self.specular_weight;
        p * self.specular_pdf(wo, wi) + (1.0 - p) * wi.z * FRAC_1_PI
    }

    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, _mode: TransportMode) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if uc < self.specular_weight {
            let (m, pdf_m) = self.distribution.sample(wo, u);
            if pdf_m <= 0.0 {
                return None;
            }
            reflect(wo, m)
        } else {
            cosine_hemisphere(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        sampled_direction(self, wo, wi)
    }

    fn roughness(&self) -> f32 {
        self.distribution.roughness()
    }
}

#[derive(Clone, Debug)]
pub struct PPlasticMaterial {
    /// The lobe, its colours and roughness set at each point.
    pub lobe: PPlasticBxdf,
    pub diffuse_reflectance: Texture,
    pub specular_reflectance: Texture,
    pub roughness: Option<RoughnessTextures>,
    pub twosided: bool,
}

impl SurfaceMaterial for PPlasticMaterial {
    type Bxdf = PPlasticBxdf;

    #[inline]
    fn bxdf(&self, ctx: TextureEvalContext) -> PPlasticBxdf {
        PPlasticBxdf {
            distribution: match &self.roughness {
                Some(r) => r.at(self.lobe.distribution, ctx),
                None => self.lobe.distribution,
            },
            diffuse_reflectance: self.diffuse_reflectance.at(ctx),
            specular_reflectance: self.specular_reflectance.at(ctx),
            ..self.lobe
        }
    }

    fn needs_coordinates(&self) -> bool {
        !self.lobe.distribution.is_isotropic()
            || !self.diffuse_reflectance.is_constant()
            || !self.specular_reflectance.is_constant()
            || self.roughness.is_some()
    }

    fn twosided(&self) -> bool {
        self.twosided
    }
}

pub const FACTORY: Factory<PPlasticMaterial> = Factory {
    name: "pplastic",
    description: "a rough plastic without internal reflections (Mitsuba 3's pplastic)",
    create: |m, _, resources| {
        let diffuse_reflectance =
            reflectance(m, "diffuse_reflectance", Rgb::splat(0.5), resources)?;
        let specular_reflectance = resources.texture(m, "specular_reflectance", Rgb::ONE)?;
        let (distribution, roughness) = read_roughness(m, true, resources)?;
        // Mitsuba 3: s / (d + s) of the textures' means.
        let mean = |t: &Texture| {
            let c = t.mean();
            (c.x + c.y + c.z) / 3.0
        };
        let (s, d) = (mean(&specular_reflectance), mean(&diffuse_reflectance));
        let specular_weight = if s + d > 0.0 { s / (s + d) } else { 0.5 };
        Ok(Box::new(PPlasticMaterial {
            lobe: PPlasticBxdf {
                distribution,
                eta: read_ior(m, 1.49 / 1.000277)?,
                diffuse_reflectance: Rgb::splat(0.5),
                specular_reflectance: Rgb::ONE,
                specular_weight,
            },
            diffuse_reflectance,
            specular_reflectance,
            roughness,
            twosided: m.bool("twosided", false)?,
        }))
    },
};
