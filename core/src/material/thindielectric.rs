//! `thindielectric`: a thin sheet of glass (Mitsuba's `thindielectric`): light is reflected
//! or passes straight through, with the Fresnel reflectance of the sheet's two faces and
//! their interreflections. It bounds no volume.
//!
//! | Parameter | Type   | Meaning                                 | Default |
//! |-----------|--------|-----------------------------------------|---------|
//! | `ior`     | number | the sheet's index relative to the outside | `1.5` |

use super::mirror::{delta_sample, reflect_local};
use super::{SurfaceMaterial, read_ior};
use crate::Rgb;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode, fresnel_dielectric};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct ThinDielectricMaterial {
    pub ior: f32,
}

/// Delta reflection with probability R' = 2R / (1 + R), straight through with 1 - R'.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectricBxdf {
    pub ior: f32,
}

impl SurfaceMaterial for ThinDielectricMaterial {
    type Bxdf = ThinDielectricBxdf;

    #[inline(always)]
    fn bxdf(&self, _: Vec2) -> ThinDielectricBxdf {
        ThinDielectricBxdf { ior: self.ior }
    }

    fn needs_coordinates(&self) -> bool {
        false
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
            return delta_sample(reflect_local(wo), Rgb::ONE, r);
        }
        // Straight through: the two refractions undo each other (no 1/eta^2 either).
        delta_sample(-wo, Rgb::ONE, 1.0 - r)
    }

    fn roughness(&self) -> f32 {
        0.0
    }
}

pub const FACTORY: Factory<ThinDielectricMaterial> = Factory {
    name: "thindielectric",
    description: "a thin sheet of glass: reflected or straight through",
    create: |m, _, _| {
        Ok(Box::new(ThinDielectricMaterial {
            ior: read_ior(m, 1.5)?,
        }))
    },
};
