//! `mirror`: perfect specular reflection.
//!
//! | Parameter     | Type          | Meaning                      | Default |
//! |---------------|---------------|------------------------------|---------|
//! | `reflectance` | RGB / texture | what fraction is reflected   | `1`     |

use crate::texture::TextureEvalContext;
use super::{SurfaceMaterial, reflectance};
use crate::Rgb;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct MirrorMaterial {
    pub reflectance: Texture,
}

/// A delta reflection scaled by `reflectance`, from either side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MirrorBxdf {
    pub reflectance: Rgb,
}

impl SurfaceMaterial for MirrorMaterial {
    type Bxdf = MirrorBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> MirrorBxdf {
        MirrorBxdf {
            reflectance: self.reflectance.at(ctx),
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.reflectance.is_constant()
    }
}

/// `w` mirrored about the local normal (z).
#[inline]
pub fn reflect_local(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// A delta sample: direction, weight and the probability of having chosen it.
#[inline]
pub fn delta_sample(wi: Vec3, weight: Rgb, pdf: f32) -> Option<LocalSample> {
    Some(LocalSample {
        wi,
        weight,
        pdf,
        delta: true,
    })
}

impl Bxdf for MirrorBxdf {
    const DELTA: bool = true;

    fn eval(&self, _: Vec3, _: Vec3) -> Rgb {
        Rgb::ZERO
    }

    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    #[inline]
    fn sample(&self, wo: Vec3, _: Vec2, _: f32, _: TransportMode) -> Option<LocalSample> {
        delta_sample(reflect_local(wo), self.reflectance, 1.0)
    }

    fn roughness(&self) -> f32 {
        0.0
    }
}

pub const FACTORY: Factory<MirrorMaterial> = Factory {
    name: "mirror",
    description: "perfect specular reflection",
    create: |m, _, resources| {
        Ok(Box::new(MirrorMaterial {
            reflectance: reflectance(m, "reflectance", Rgb::ONE, resources)?,
        }))
    },
};
