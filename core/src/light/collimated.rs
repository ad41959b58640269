//! `collimated`: a beam of light along one ray (Mitsuba's `collimated`), the limit of a spot
//! light whose cone closes. A delta in position and in direction: no point off the ray
//! receives it directly, so next-event estimation never samples it; it lights the scene
//! through the paths and photons traced from it, where it strikes.
//!
//! | Parameter   | Type       | Meaning                                | Default     |
//! |-------------|------------|----------------------------------------|-------------|
//! | `position`  | point      | where the beam starts                  | required    |
//! | `direction` | vector     | the direction it travels in            | required    |
//! | `power`     | RGB (W)    | the power it carries                   | `[1, 1, 1]` |

use super::{EmittedRay, LightSample, LightSource, LightType};
use crate::Rgb;
use crate::registry::Factory;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct CollimatedLight {
    pub position: Vec3,
    /// Unit.
    pub direction: Vec3,
    /// W.
    pub power: Rgb,
}

impl LightSource for CollimatedLight {
    fn light_type(&self) -> LightType {
        LightType::DeltaBeam
    }

    fn power(&self) -> Rgb {
        self.power
    }

    fn position(&self) -> Option<Vec3> {
        Some(self.position)
    }

    /// No point receives the beam with nonzero probability.
    fn sample_li(&self, _: Vec3, _: Vec2, _: f32) -> Option<LightSample> {
        None
    }

    fn pdf_li(&self, _: Vec3, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    /// The one ray, its densities deltas (1).
    fn sample_emission(&self, _: Vec2, _: Vec2, _: f32) -> EmittedRay {
        EmittedRay {
            origin: self.position,
            dir: self.direction,
            n: Vec3::ZERO,
            flux: self.power,
            le: self.power,
            uv: Vec2::ZERO,
            pdf_pos: 1.0,
            pdf_dir: 1.0,
        }
    }

    fn pdf_le(&self, _: Vec3, _: Vec3) -> (f32, f32) {
        (1.0, 1.0)
    }
}

pub const FACTORY: Factory<CollimatedLight> = Factory {
    name: "collimated",
    description: "a beam of light along one ray",
    create: |l, _, _| {
        let position = l.vec3_required("position")?;
        let direction = l.vec3_required("direction")?;
        if direction.length_squared() == 0.0 {
            return Err(l.error("direction", "gives no direction (zero length)"));
        }
        Ok(Box::new(CollimatedLight {
            position,
            direction: direction.normalize(),
            power: l.rgb("power", Rgb::ONE)?,
        }))
    },
};
