//! `thindielectric`: a thin sheet of glass (Mitsuba's `thindielectric`): light is reflected
//! or passes straight through, with the Fresnel reflectance of the sheet's two faces and
//! their interreflections. It bounds no volume.
//!
//! | Parameter | Type   | Meaning                                 | Default |
//! |-----------|--------|-----------------------------------------|---------|
//! | `ior`     | number | the sheet's index relative to the outside | `1.5` |
//! | `specular_reflectance`   | RGB / texture | scales the reflection (Mitsuba's)   | `1`     |
//! | `specular_transmittance` | RGB / texture | scales the transmission (Mitsuba's) | `1`     |

use crate::texture::TextureEvalContext;
use super::mirror::{delta_sample, reflect_local};
use super::{SurfaceMaterial, read_ior};
use crate::Rgb;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode, fresnel_dielectric};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct ThinDielectricMaterial {
    pub ior: f32,
    pub specular_reflectance: Texture,
    pub specular_transmittance: Texture,
}

/// Delta reflection with probability R' = 2R / (1 + R), straight through with 1 - R'; the
/// reflected weight is multiplied by `specular_reflectance`, the transmitted one by
/// `specular_transmittance` (as in Mitsuba, the probabilities do not depend on them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectricBxdf {
    pub ior: f32,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
}

impl SurfaceMaterial for ThinDielectricMaterial {
    type Bxdf = ThinDielectricBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> ThinDielectricBxdf {
        ThinDielectricBxdf {
            ior: self.ior,
            specular_reflectance: self.specular_reflectance.at(ctx),
            specular_transmittance: self.specular_transmittance.at(ctx),
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.specular_reflectance.is_constant() || !self.specular_transmittance.is_constant()
    }
}

impl Bxdf for ThinDielectricBxdf {
    const DELTA: bool = true;

    fn eval(&self, _: Vec3, _: Vec3) -> Rgb {
        Rgb::ZERO
    }

    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    #[inline]
    fn sample(&self, wo: Vec3, _: Vec2, uc: f32, _: TransportMode) -> Option<LocalSample> {
        // Air-glass-air: the same reflectance from either side; the infinite series of
        // reflections inside the sheet sums to R' = R + T^2 R / (1 - R^2) = 2R / (1 + R).
        let r = fresnel_dielectric(wo.z.abs(), self.ior);
        let r = 2.0 * r / (1.0 + r);
        if uc < r {
            return delta_sample(reflect_local(wo), self.specular_reflectance, r);
        }
        // Straight through: the two refractions undo each other (no 1/eta^2 either).
        delta_sample(-wo, self.specular_transmittance, 1.0 - r)
    }

    fn roughness(&self) -> f32 {
        0.0
    }
}

pub const FACTORY: Factory<ThinDielectricMaterial> = Factory {
    name: "thindielectric",
    description: "a thin sheet of glass: reflected or straight through",
    create: |m, _, resources| {
        Ok(Box::new(ThinDielectricMaterial {
            ior: read_ior(m, 1.5)?,
            specular_reflectance: resources.texture(m, "specular_reflectance", Rgb::ONE)?,
            specular_transmittance: resources.texture(m, "specular_transmittance", Rgb::ONE)?,
        }))
    },
};
