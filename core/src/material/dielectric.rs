//! `dielectric`: a smooth interface between two dielectrics (glass, water), with Fresnel
//! reflection and refraction (Mitsuba's `dielectric`). Two-sided by nature.
//!
//! | Parameter | Type   | Meaning                                                     | Default |
//! |-----------|--------|-------------------------------------------------------------|---------|
//! | `ior`     | number | the index of the side the normal points away from (inside), relative to the outside | `1.5` |

use super::mirror::{delta_sample, reflect_local};
use super::{SurfaceMaterial, read_ior};
use crate::Rgb;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode, fresnel_dielectric, refract};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct DielectricMaterial {
    pub ior: f32,
}

/// Delta reflection with probability F, delta refraction with 1 - F.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricBxdf {
    pub ior: f32,
}

impl SurfaceMaterial for DielectricMaterial {
    type Bxdf = DielectricBxdf;

    #[inline(always)]
    fn bxdf(&self, _: Vec2) -> DielectricBxdf {
        DielectricBxdf { ior: self.ior }
    }

    fn needs_coordinates(&self) -> bool {
        false
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
            return delta_sample(reflect_local(wo), Rgb::ONE, f);
        }
        let n = if cos_o > 0.0 { Vec3::Z } else { Vec3::NEG_Z };
        let wi = refract(wo, n, eta)?;
        // Radiance is compressed into the narrower cone of the denser side; flux is not.
        let scale = match mode {
            TransportMode::Radiance => 1.0 / (eta * eta),
            TransportMode::Importance => 1.0,
        };
        delta_sample(wi, Rgb::splat(scale), 1.0 - f)
    }

    fn roughness(&self) -> f32 {
        0.0
    }
}

pub const FACTORY: Factory<DielectricMaterial> = Factory {
    name: "dielectric",
    description: "a smooth dielectric interface: Fresnel reflection and refraction",
    create: |m, _, _| {
        Ok(Box::new(DielectricMaterial {
            ior: read_ior(m, 1.5)?,
        }))
    },
};
