//! `point`: a point light, emitting the same intensity in every direction.
//!
//! | Parameter   | Type      | Meaning                                   | Default           |
//! |-------------|-----------|-------------------------------------------|-------------------|
//! | `position`  | point     | where it is                               | required          |
//! | `intensity` | RGB (W/sr)| radiant intensity                         | one of the two    |
//! | `power`     | RGB (W)   | total power, 4 pi intensity               | one of the two    |

use super::{EmittedRay, LightSample, LightSource, LightType, towards};
use crate::Rgb;
use crate::registry::Factory;
use crate::sampling::{UNIFORM_SPHERE_PDF, uniform_sphere};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3,
    /// W/sr.
    pub intensity: Rgb,
}

impl LightSource for PointLight {
    fn light_type(&self) -> LightType {
        LightType::DeltaPosition
    }

    /// 4 pi I.
    fn power(&self) -> Rgb {
        4.0 * PI * self.intensity
    }

    fn position(&self) -> Option<Vec3> {
        Some(self.position)
    }

    /// Intensity over distance squared, pdf 1 (delta).
    // A few operations, inlined into the integrators' loops: a call per path vertex, with the
    // sample copied out through memory, was 3 % of the path tracer's instructions on the
    // Cornell box. The other lights' samples are calls, which their sampling outweighs.
    #[inline(always)]
    fn sample_li(&self, x: Vec3, _: Vec2, _: f32) -> Option<LightSample> {
        let (wi, dist, dist2) = towards(x, self.position)?;
        Some(LightSample {
            wi,
            dist,
            li: self.intensity / dist2,
            pdf: 1.0,
            delta: true,
            p: self.position,
            n: Vec3::ZERO,
        })
    }

    fn pdf_li(&self, _: Vec3, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    /// Uniform over the sphere of directions.
    fn sample_emission(&self, _: Vec2, u_dir: Vec2, _: f32) -> EmittedRay {
        EmittedRay {
            origin: self.position,
            dir: uniform_sphere(u_dir),
            n: Vec3::ZERO,
            flux: 4.0 * PI * self.intensity,
            le: self.intensity,
            uv: Vec2::ZERO,
            pdf_pos: 1.0,
            pdf_dir: UNIFORM_SPHERE_PDF,
        }
    }

    fn pdf_le(&self, _: Vec3, _: Vec3) -> (f32, f32) {
        (1.0, UNIFORM_SPHERE_PDF)
    }
}

pub const FACTORY: Factory<PointLight> = Factory {
    name: "point",
    description: "a point light, the same intensity in every direction",
    create: |l, _, _| {
        let position = l.vec3_required("position")?;
        let intensity = match (l.rgb_opt("intensity")?, l.rgb_opt("power")?) {
            (Some(i), None) => i,
            (None, Some(p)) => p / (4.0 * PI),
            (Some(_), Some(_)) => {
                return Err(l.error(
                    "power",
                    "give either intensity (W/sr) or power (W), not both",
                ));
            }
            (None, None) => {
                return Err(l.error(
                    "intensity",
                    "missing; expected intensity = [r, g, b] (W/sr) or power = [r, g, b] (W)",
                ));
            }
        };
        Ok(Box::new(PointLight {
            position,
            intensity,
        }))
    },
};
