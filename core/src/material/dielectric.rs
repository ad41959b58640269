//! `dielectric`: a smooth interface between two dielectrics (glass, water), with Fresnel
//! reflection and refraction (Mitsuba's `dielectric`). Two-sided by nature.
//!
//! | Parameter | Type   | Meaning                                                     | Default |
//! |-----------|--------|-------------------------------------------------------------|---------|
//! | `ior`     | number | the index of the side the normal points away from (inside), relative to the outside | `1.5` |
//! | `specular_reflectance`   | RGB / texture | scales the reflection (Mitsuba's)   | `1`     |
//! | `specular_transmittance` | RGB / texture | scales the refraction (Mitsuba's)   | `1`     |

use crate::texture::TextureEvalContext;
use super::mirror::{delta_sample, reflect_local};
use super::{SurfaceMaterial, read_ior};
use crate::Rgb;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode, fresnel_dielectric, refract};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct DielectricMaterial {
    pub ior: f32,
    pub specular_reflectance: Texture,
    pub specular_transmittance: Texture,
}

impl DielectricMaterial {
    /// Clear glass of index `ior`: both factors 1.
    pub fn new(ior: f32) -> DielectricMaterial {
        DielectricMaterial {
            ior,
            specular_reflectance: Texture::Constant(Rgb::ONE),
            specular_transmittance: Texture::Constant(Rgb::ONE),
        }
    }
}

/// Delta reflection with probability F, delta refraction with 1 - F; the reflected weight
/// is multiplied by `specular_reflectance`, the refracted one by `specular_transmittance`
/// (as in Mitsuba, the probabilities do not depend on them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricBxdf {
    pub ior: f32,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
}

impl SurfaceMaterial for DielectricMaterial {
    type Bxdf = DielectricBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> DielectricBxdf {
        DielectricBxdf {
            ior: self.ior,
            specular_reflectance: self.specular_reflectance.at(ctx),
            specular_transmittance: self.specular_transmittance.at(ctx),
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.specular_reflectance.is_constant() || !self.specular_transmittance.is_constant()
    }

    fn encloses_volume(&self) -> bool {
        true
    }
}

impl Bxdf for DielectricBxdf {
    const DELTA: bool = true;

    fn eval(&self, _: Vec3, _: Vec3) -> Rgb {
        Rgb::ZERO
    }

    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    #[inline]
    fn sample(&self, wo: Vec3, _: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        let cos_o = wo.z;
        let eta = if cos_o > 0.0 { self.ior } else { 1.0 / self.ior };
        let f = fresnel_dielectric(cos_o.abs(), eta);
        if uc < f {
            return delta_sample(reflect_local(wo), self.specular_reflectance, f);
        }
        let n = if cos_o > 0.0 { Vec3::Z } else { Vec3::NEG_Z };
        let wi = refract(wo, n, eta)?;
        // Radiance is compressed into the narrower cone of the denser side; flux is not.
        let scale = match mode {
            TransportMode::Radiance => 1.0 / (eta * eta),
            TransportMode::Importance => 1.0,
        };
        delta_sample(wi, self.specular_transmittance * scale, 1.0 - f)
    }

    fn roughness(&self) -> f32 {
        0.0
    }
}

pub const FACTORY: Factory<DielectricMaterial> = Factory {
    name: "dielectric",
    description: "a smooth dielectric interface: Fresnel reflection and refraction",
    create: |m, _, resources| {
        Ok(Box::new(DielectricMaterial {
            ior: read_ior(m, 1.5)?,
            specular_reflectance: resources.texture(m, "specular_reflectance", Rgb::ONE)?,
            specular_transmittance: resources.texture(m, "specular_transmittance", Rgb::ONE)?,
        }))
    },
};
