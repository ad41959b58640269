//! `roughdielectric`: a rough interface between two dielectrics, microfacet reflection and
//! refraction (Mitsuba's `roughdielectric`; the lobe is [`RoughDielectric`]). Two-sided by
//! nature.
//!
//! | Parameter                | Type          | Meaning                                | Default    |
//! |--------------------------|---------------|----------------------------------------|------------|
//! | `ior`                    | number        | inside relative to outside, as `dielectric`'s | `1.5` |
//! | `distribution`           | string        | `beckmann` or `ggx`                    | `beckmann` |
//! | `alpha`                  | number / texture | roughness (or `alpha_u` and `alpha_v`); a texture's luminance | `0.1` |
//! | `remaproughness`         | bool          | alpha is the square root of the values given (pbrt-v4's) | `false` |
//! | `specular_reflectance`   | RGB / texture | scales the reflection                  | `1`        |
//! | `specular_transmittance` | RGB / texture | scales the refraction                  | `1`        |

use crate::texture::TextureEvalContext;
use super::{RoughnessTextures, SurfaceMaterial, read_ior, read_roughness};
use crate::Rgb;
use crate::glossy::RoughDielectric;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct RoughDielectricMaterial {
    /// The lobe, its colours set at each point from the textures.
    pub lobe: RoughDielectric,
    pub specular_reflectance: Texture,
    pub specular_transmittance: Texture,
    /// A roughness that varies over the surface (`alpha` a texture).
    pub roughness: Option<RoughnessTextures>,
}

impl SurfaceMaterial for RoughDielectricMaterial {
    type Bxdf = RoughDielectric;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> RoughDielectric {
        let distribution = match &self.roughness {
            Some(r) => r.at(self.lobe.distribution, ctx),
            None => self.lobe.distribution,
        };
        RoughDielectric {
            specular_reflectance: self.specular_reflectance.at(ctx),
            specular_transmittance: self.specular_transmittance.at(ctx),
            distribution,
            ..self.lobe
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.lobe.distribution.is_isotropic()
            || !self.specular_reflectance.is_constant()
            || !self.specular_transmittance.is_constant()
            || self.roughness.is_some()
    }

    fn encloses_volume(&self) -> bool {
        true
    }
}

impl Bxdf for RoughDielectric {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        RoughDielectric::eval(self, wo, wi, TransportMode::Radiance)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        RoughDielectric::pdf(self, wo, wi)
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        RoughDielectric::sample(self, wo, u, uc, mode)
    }

    #[inline]
    fn roughness(&self) -> f32 {
        RoughDielectric::roughness(self)
    }

    fn transmits(&self) -> bool {
        true
    }
}

pub const FACTORY: Factory<RoughDielectricMaterial> = Factory {
    name: "roughdielectric",
    description: "a rough dielectric interface: microfacet reflection and refraction",
    create: |m, _, resources| {
        let (distribution, roughness) = read_roughness(m, true, resources)?;
        let lobe = RoughDielectric {
            distribution,
            eta: read_ior(m, 1.5)?,
            specular_reflectance: Rgb::ONE,
            specular_transmittance: Rgb::ONE,
        };
        Ok(Box::new(RoughDielectricMaterial {
            lobe,
            specular_reflectance: resources.texture(m, "specular_reflectance", Rgb::ONE)?,
            specular_transmittance: resources.texture(m, "specular_transmittance", Rgb::ONE)?,
            roughness,
        }))
    },
};
