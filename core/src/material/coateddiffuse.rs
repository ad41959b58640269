//! `coateddiffuse`: a Lambertian base under a dielectric coat, with an optional scattering
//! slab between them (pbrt-v4's `coateddiffuse`, its `CoatedDiffuseBxDF`; the lobe is a
//! [`Layered`] random walk, see `layered.rs`).
//!
//! | Parameter        | Type          | Meaning                                          | Default |
//! |------------------|---------------|--------------------------------------------------|---------|
//! | `reflectance`    | RGB / texture | the base's albedo (clamped to [0, 1])            | `0.5`   |
//! | `roughness`      | number / texture | the coat's roughness (or `uroughness`, `vroughness`) | `0` (smooth) |
//! | `remaproughness` | bool          | alpha = sqrt(roughness), as pbrt's `RoughnessToAlpha` | `true` |
//! | `eta`            | number        | the coat's index relative to the outside        | `1.5`   |
//! | `thickness`      | number        | the slab's depth in mean free paths              | `0.01`  |
//! | `albedo`         | RGB / texture | the slab's single-scattering albedo (0: it only absorbs) | `0` |
//! | `g`              | number        | the slab's Henyey-Greenstein asymmetry           | `0`     |
//! | `maxdepth`       | integer       | events per random walk                           | `10`    |
//! | `nsamples`       | integer       | random walks per evaluation                      | `1`     |

use crate::texture::TextureEvalContext;
use super::SurfaceMaterial;
use super::layered::{self, Diffuse, Dielectric, Layered};
use crate::Rgb;
use crate::registry::Factory;
use crate::texture::Texture;

/// The lobe: pbrt's `LayeredBxDF<DielectricBxDF, DiffuseBxDF, true>`.
pub type CoatedDiffuseBxdf = Layered<Diffuse>;

#[derive(Clone, Debug)]
pub struct CoatedDiffuseMaterial {
    /// The lobe, its colours set at each point from the textures.
    pub lobe: CoatedDiffuseBxdf,
    pub reflectance: Texture,
    pub albedo: Texture,
    /// The coat's roughness where it varies over the surface.
    pub roughness: Option<super::RoughnessTextures>,
}

impl SurfaceMaterial for CoatedDiffuseMaterial {
    type Bxdf = CoatedDiffuseBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> CoatedDiffuseBxdf {
        let clamp = |c: Rgb| c.clamp(Rgb::ZERO, Rgb::ONE);
        let mut top = self.lobe.top;
        if let Some(r) = &self.roughness {
            top.ggx = r.ggx_at(ctx);
        }
        Layered {
            top,
            base: Diffuse {
                reflectance: clamp(self.reflectance.at(ctx)),
            },
            albedo: clamp(self.albedo.at(ctx)),
            ..self.lobe
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.lobe.top.ggx.distribution.is_isotropic()
            || !self.reflectance.is_constant()
            || !self.albedo.is_constant()
            || self.roughness.is_some()
    }
}

pub const FACTORY: Factory<CoatedDiffuseMaterial> = Factory {
    name: "coateddiffuse",
    description: "a diffuse base under a dielectric coat, by a random walk between them (pbrt-v4's)",
    create: |m, _, resources| {
        let reflectance = super::reflectance(m, "reflectance", Rgb::splat(0.5), resources)?;
        let slab = layered::read_slab(m, resources)?;
        let (ggx, roughness) = layered::read_ggx_textured(m, "", resources)?;
        let lobe = Layered {
            top: Dielectric {
                ggx,
                eta: layered::read_eta(m, "eta")?,
            },
            base: Diffuse {
                reflectance: Rgb::splat(0.5),
            },
            thickness: slab.thickness,
            albedo: Rgb::ZERO,
            g: slab.g,
            max_depth: slab.max_depth,
            n_samples: slab.n_samples,
        };
        Ok(Box::new(CoatedDiffuseMaterial {
            lobe,
            reflectance,
            albedo: slab.albedo,
            roughness,
        }))
    },
};
