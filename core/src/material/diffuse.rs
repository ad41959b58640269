//! `diffuse`: a Lambertian surface, f = reflectance / pi (Mitsuba's `diffuse`).
//!
//! | Parameter     | Type          | Meaning                                      | Default      |
//! |---------------|---------------|----------------------------------------------|--------------|
//! | `reflectance` | RGB / texture | the albedo                                   | `0.5`        |
//! | `twosided`    | bool          | false: black from behind (a Mitsuba BSDF not wrapped in `twosided`) | `true` |

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
pub struct DiffuseMaterial {
    pub reflectance: Texture,
    /// False: only on the side the normal points to.
    pub twosided: bool,
}

/// The Lambertian lobe: f = reflectance / pi on the side of `wo`, the front only unless
/// `twosided`; sampled by the cosine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseBxdf {
    pub reflectance: Rgb,
    pub twosided: bool,
}

impl SurfaceMaterial for DiffuseMaterial {
    type Bxdf = DiffuseBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> DiffuseBxdf {
        DiffuseBxdf {
            reflectance: self.reflectance.at(ctx),
            twosided: self.twosided,
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.reflectance.is_constant()
    }
}

impl DiffuseBxdf {
    /// f |cos theta_i| from the cosines of `wo` and `wi` with the normal: both on one side,
    /// and that side the front unless `twosided`. Isotropic and flat, the lobe reads nothing
    /// else of the directions, so that [`crate::bsdf::Bsdf`] can skip the local frame.
    #[inline]
    pub fn eval_cos(&self, twosided: bool, cos_o: f32, cos_i: f32) -> Rgb {
        if cos_o * cos_i > 0.0 && (twosided || cos_o > 0.0) {
            self.reflectance * (FRAC_1_PI * cos_i.abs())
        } else {
            Rgb::ZERO
        }
    }

    /// The cosine-weighted pdf, as [`DiffuseBxdf::eval_cos`].
    #[inline]
    pub fn pdf_cos(twosided: bool, cos_o: f32, cos_i: f32) -> f32 {
        if cos_o * cos_i > 0.0 && (twosided || cos_o > 0.0) {
            cos_i.abs() * FRAC_1_PI
        } else {
            0.0
        }
    }

    /// A cosine-weighted direction on the side of `wo` (`cos_o`, not zero), whatever
    /// `twosided` says: the caller has checked the side.
    #[inline(always)]
    pub fn sample_cos(&self, cos_o: f32, u: Vec2) -> Option<LocalSample> {
        let mut wi = cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = wi.z * FRAC_1_PI;
        if cos_o < 0.0 {
            wi.z = -wi.z;
        }
        Some(LocalSample {
            wi,
            weight: self.reflectance,
            pdf,
            delta: false,
        })
    }
}

impl Bxdf for DiffuseBxdf {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.eval_cos(self.twosided, wo.z, wi.z)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        DiffuseBxdf::pdf_cos(self.twosided, wo.z, wi.z)
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2, _: f32, _: TransportMode) -> Option<LocalSample> {
        if !self.twosided && wo.z < 0.0 {
            return None;
        }
        self.sample_cos(wo.z, u)
    }

    #[inline]
    fn roughness(&self) -> f32 {
        f32::INFINITY
    }
}

pub const FACTORY: Factory<DiffuseMaterial> = Factory {
    name: "diffuse",
    description: "a Lambertian surface, f = reflectance / pi",
    create: |m, _, resources| {
        Ok(Box::new(DiffuseMaterial {
            reflectance: reflectance(m, "reflectance", Rgb::splat(0.5), resources)?,
            twosided: m.bool("twosided", true)?,
        }))
    },
};
