//! `difftrans`: a diffuse transmitter (Mitsuba 0.6's `difftrans`): light that reaches the
//! surface leaves it on the other side, cosine-distributed, f = transmittance / pi; nothing is
//! reflected. The same from both sides; it bounds no volume.
//!
//! | Parameter       | Type          | Meaning                                  | Default |
//! |-----------------|---------------|------------------------------------------|---------|
//! | `transmittance` | RGB / texture | the fraction of the light passed through | `0.5`   |

use crate::texture::TextureEvalContext;
use super::{SurfaceMaterial, reflectance};
use crate::Rgb;
use crate::registry::Factory;
use crate::sampling::cosine_hemisphere;
use crate::scattering::{Bxdf, LocalSample, TransportMode};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct DiffTransMaterial {
    pub transmittance: Texture,
}

/// The diffuse transmission lobe: f = transmittance / pi for `wi` on the other side of the
/// surface from `wo`, zero on the same side; sampled by the cosine on the other side, with
/// weight `transmittance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffTransBxdf {
    pub transmittance: Rgb,
}

impl SurfaceMaterial for DiffTransMaterial {
    type Bxdf = DiffTransBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> DiffTransBxdf {
        DiffTransBxdf {
            transmittance: self.transmittance.at(ctx),
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.transmittance.is_constant()
    }
}

impl Bxdf for DiffTransBxdf {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z * wi.z < 0.0 {
            self.transmittance * (FRAC_1_PI * wi.z.abs())
        } else {
            Rgb::ZERO
        }
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z * wi.z < 0.0 {
            wi.z.abs() * FRAC_1_PI
        } else {
            0.0
        }
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2, _: f32, _: TransportMode) -> Option<LocalSample> {
        let mut wi = cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = wi.z * FRAC_1_PI;
        if wo.z > 0.0 {
            wi.z = -wi.z;
        }
        Some(LocalSample {
            wi,
            weight: self.transmittance,
            pdf,
            delta: false,
        })
    }

    #[inline]
    fn roughness(&self) -> f32 {
        f32::INFINITY
    }

    fn transmits(&self) -> bool {
        true
    }
}

pub const FACTORY: Factory<DiffTransMaterial> = Factory {
    name: "difftrans",
    description: "a diffuse transmitter: f = transmittance / pi on the other side",
    create: |m, _, resources| {
        Ok(Box::new(DiffTransMaterial {
            transmittance: reflectance(m, "transmittance", Rgb::splat(0.5), resources)?,
        }))
    },
};
