//! `roughplastic`: a diffuse base under a rough dielectric coat (Mitsuba's `roughplastic`;
//! the lobe is [`RoughPlastic`]).
//!
//! | Parameter      | Type   | Meaning                                    | Default    |
//! |----------------|--------|--------------------------------------------|------------|
//! | as `plastic`'s |        | `ior`, the two colours, `nonlinear`, `twosided` |       |
//! | `distribution` | string | `beckmann` or `ggx`                        | `beckmann` |
//! | `alpha`        | number | the coat's roughness (isotropic)           | `0.1`      |

use crate::texture::TextureEvalContext;
use super::plastic::read_coated;
use super::{SurfaceMaterial, read_microfacet};
use crate::Rgb;
use crate::glossy::RoughPlastic;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct RoughPlasticMaterial {
    /// The lobe, its colours set at each point from the textures.
    pub lobe: RoughPlastic,
    pub diffuse_reflectance: Texture,
    pub specular_reflectance: Texture,
    pub twosided: bool,
}

impl SurfaceMaterial for RoughPlasticMaterial {
    type Bxdf = RoughPlastic;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> RoughPlastic {
        let mut l = self.lobe;
        l.diffuse_reflectance = self.diffuse_reflectance.at(ctx);
        l.specular_reflectance = self.specular_reflectance.at(ctx);
        l
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.diffuse_reflectance.is_constant() || !self.specular_reflectance.is_constant()
    }

    fn twosided(&self) -> bool {
        self.twosided
    }
}

impl Bxdf for RoughPlastic {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        RoughPlastic::eval(self, wo, wi, TransportMode::Radiance)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        RoughPlastic::pdf(self, wo, wi)
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        RoughPlastic::sample(self, wo, u, uc, mode)
    }

    #[inline]
    fn roughness(&self) -> f32 {
        RoughPlastic::roughness(self)
    }
}

pub const FACTORY: Factory<RoughPlasticMaterial> = Factory {
    name: "roughplastic",
    description: "a diffuse base under a rough dielectric coat",
    create: |m, _, resources| {
        let c = read_coated(m, resources)?;
        let d = read_microfacet(m, false)?;
        // The lobe's colours are set at each point from the textures.
        let lobe = RoughPlastic::new(
            d.kind,
            d.alpha_u,
            c.eta,
            Rgb::splat(0.5),
            Rgb::ONE,
            c.nonlinear,
        );
        Ok(Box::new(RoughPlasticMaterial {
            lobe,
            diffuse_reflectance: c.diffuse_reflectance,
            specular_reflectance: c.specular_reflectance,
            twosided: c.twosided,
        }))
    },
};
