//! `roughconductor`: a metal with a rough surface, microfacet reflection (Mitsuba's
//! `roughconductor`; the lobe is [`RoughConductor`]).
//!
//! | Parameter              | Type          | Meaning                                  | Default        |
//! |------------------------|---------------|------------------------------------------|----------------|
//! | `material`, `eta`, `k` |               | the index of refraction, as `conductor`'s | a perfect mirror |
//! | `distribution`         | string        | `beckmann` or `ggx`                      | `beckmann`     |
//! | `alpha`                | number / texture | roughness (or `alpha_u` and `alpha_v`: anisotropic); a texture's luminance | `0.1` |
//! | `remaproughness`       | bool          | alpha is the square root of the values given (pbrt-v4's) | `false` |
//! | `specular_reflectance` | RGB / texture | scales the reflection                    | `1`            |
//! | `twosided`             | bool          | the same seen from behind                | `true`         |

use crate::texture::TextureEvalContext;
use super::conductor::read_conductor_ior;
use super::{RoughnessTextures, SurfaceMaterial, read_roughness};
use crate::Rgb;
use crate::glossy::RoughConductor;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct RoughConductorMaterial {
    /// The lobe, its `specular_reflectance` set at each point from the texture.
    pub lobe: RoughConductor,
    pub specular_reflectance: Texture,
    pub twosided: bool,
    /// A roughness that varies over the surface (`alpha` a texture).
    pub roughness: Option<RoughnessTextures>,
}

impl SurfaceMaterial for RoughConductorMaterial {
    type Bxdf = RoughConductor;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> RoughConductor {
        let distribution = match &self.roughness {
            Some(r) => r.at(self.lobe.distribution, ctx),
            None => self.lobe.distribution,
        };
        RoughConductor {
            specular_reflectance: self.specular_reflectance.at(ctx),
            distribution,
            ..self.lobe
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.lobe.distribution.is_isotropic()
            || !self.specular_reflectance.is_constant()
            || self.roughness.is_some()
    }

    fn twosided(&self) -> bool {
        self.twosided
    }
}

impl Bxdf for RoughConductor {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        RoughConductor::eval(self, wo, wi, TransportMode::Radiance)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        RoughConductor::pdf(self, wo, wi)
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        RoughConductor::sample(self, wo, u, uc, mode)
    }

    #[inline]
    fn roughness(&self) -> f32 {
        RoughConductor::roughness(self)
    }
}

pub const FACTORY: Factory<RoughConductorMaterial> = Factory {
    name: "roughconductor",
    description: "a rough metal: microfacet reflection",
    create: |m, _, resources| {
        let specular_reflectance = resources.texture(m, "specular_reflectance", Rgb::ONE)?;
        // No named material and no eta, k: a perfect (rough) mirror, F = 1.
        let (eta, k) = read_conductor_ior(m)?.unwrap_or((Rgb::ZERO, Rgb::ZERO));
        let (distribution, roughness) = read_roughness(m, true, resources)?;
        Ok(Box::new(RoughConductorMaterial {
            roughness,
            lobe: RoughConductor {
                distribution,
                eta,
                k,
                specular_reflectance: Rgb::ONE,
            },
            specular_reflectance,
            twosided: m.bool("twosided", true)?,
        }))
    },
};
