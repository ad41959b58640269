//! `plastic`: a diffuse base under a smooth dielectric coat (Mitsuba's `plastic`; the lobe is
//! [`Plastic`]).
//!
//! | Parameter              | Type          | Meaning                                   | Default  |
//! |------------------------|---------------|-------------------------------------------|----------|
//! | `ior`                  | number        | the coat's index relative to the outside  | `1.49 / 1.000277` (polypropylene in air) |
//! | `diffuse_reflectance`  | RGB / texture | the base's albedo                         | `0.5`    |
//! | `specular_reflectance` | RGB / texture | scales the coat's reflection              | `1`      |
//! | `nonlinear`            | bool          | the base's colour shifts with its internal reflections | `false` |
//! | `twosided`             | bool          | the same seen from behind                 | `true`   |

use crate::texture::TextureEvalContext;
use super::{SurfaceMaterial, read_ior, reflectance};
use crate::Rgb;
use crate::glossy::Plastic;
use crate::props::Properties;
use crate::registry::{Factory, Resources};
use crate::scattering::{Bxdf, LocalSample, TransportMode};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct PlasticMaterial {
    /// The lobe, its colours set at each point from the textures.
    pub lobe: Plastic,
    pub diffuse_reflectance: Texture,
    pub specular_reflectance: Texture,
    pub twosided: bool,
}

impl SurfaceMaterial for PlasticMaterial {
    type Bxdf = Plastic;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> Plastic {
        Plastic {
            diffuse_reflectance: self.diffuse_reflectance.at(ctx),
            specular_reflectance: self.specular_reflectance.at(ctx),
            ..self.lobe
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.diffuse_reflectance.is_constant() || !self.specular_reflectance.is_constant()
    }

    fn twosided(&self) -> bool {
        self.twosided
    }
}

impl Bxdf for Plastic {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        Plastic::eval(self, wo, wi, TransportMode::Radiance)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        Plastic::pdf(self, wo, wi)
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        Plastic::sample(self, wo, u, uc, mode)
    }

    /// The non-delta part is the diffuse base.
    fn roughness(&self) -> f32 {
        f32::INFINITY
    }

    #[inline]
    fn delta_probability(&self, wo: Vec3) -> f32 {
        Plastic::delta_probability(self, wo)
    }
}

/// What both plastics read: the coat's index, the two colours, `nonlinear` and `twosided`.
pub(super) struct Coated {
    pub eta: f32,
    pub diffuse_reflectance: Texture,
    pub specular_reflectance: Texture,
    pub nonlinear: bool,
    pub twosided: bool,
}

pub(super) fn read_coated(
    m: &Properties<'_>,
    resources: &mut dyn Resources,
) -> crate::error::Result<Coated> {
    Ok(Coated {
        // Mitsuba's default: polypropylene in air.
        eta: read_ior(m, 1.49 / 1.000277)?,
        diffuse_reflectance: reflectance(m, "diffuse_reflectance", Rgb::splat(0.5), resources)?,
        specular_reflectance: resources.texture(m, "specular_reflectance", Rgb::ONE)?,
        nonlinear: m.bool("nonlinear", false)?,
        twosided: m.bool("twosided", true)?,
    })
}

pub const FACTORY: Factory<PlasticMaterial> = Factory {
    name: "plastic",
    description: "a diffuse base under a smooth dielectric coat",
    create: |m, _, resources| {
        let c = read_coated(m, resources)?;
        Ok(Box::new(PlasticMaterial {
            // The lobe's colours are set at each point from the textures.
            lobe: Plastic {
                eta: c.eta,
                diffuse_reflectance: Rgb::splat(0.5),
                specular_reflectance: Rgb::ONE,
                nonlinear: c.nonlinear,
            },
            diffuse_reflectance: c.diffuse_reflectance,
            specular_reflectance: c.specular_reflectance,
            twosided: c.twosided,
        }))
    },
};
