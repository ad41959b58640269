//! `directional`: parallel light from infinitely far (Mitsuba's `directional`, a sun).
//!
//! | Parameter    | Type         | Meaning                                        | Default     |
//! |--------------|--------------|------------------------------------------------|-------------|
//! | `direction`  | vector       | the direction the light travels in             | required    |
//! | `irradiance` | RGB (W/m^2)  | what it gives a surface facing it              | `[1, 1, 1]` |

use super::{EmittedRay, LightSample, LightSource, LightType, SceneSphere};
use crate::Rgb;
use crate::registry::Factory;
use glam::{Vec2, Vec3};

/// Light travelling along `direction`, giving `irradiance` (W/m^2) to a surface facing it.
/// Its photons leave the disc of the scene's bounding sphere facing it, as pbrt's distant
/// light's do.
#[derive(Clone, Debug)]
pub struct DirectionalLight {
    pub direction: Vec3,
    pub irradiance: Rgb,
    pub sphere: SceneSphere,
}

impl LightSource for DirectionalLight {
    fn light_type(&self) -> LightType {
        LightType::DeltaDirection
    }

    /// The irradiance through the bounding sphere's disc.
    fn power(&self) -> Rgb {
        self.irradiance * self.sphere.disc_area()
    }

    fn fit_to_scene(&mut self, sphere: SceneSphere) {
        self.sphere = sphere;
    }

    #[inline(never)]
    fn sample_li(&self, x: Vec3, _: Vec2, _: f32) -> Option<LightSample> {
        let mut ls = self.sphere.sample_at_infinity(x, -self.direction);
        ls.li = self.irradiance;
        Some(ls)
    }

    fn pdf_li(&self, _: Vec3, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    fn sample_emission(&self, u_pos: Vec2, _: Vec2, _: f32) -> EmittedRay {
        EmittedRay {
            origin: self.sphere.disc_origin(self.direction, u_pos),
            dir: self.direction,
            n: Vec3::ZERO,
            flux: self.irradiance * self.sphere.disc_area(),
            le: self.irradiance,
            uv: Vec2::ZERO,
            pdf_pos: 1.0 / self.sphere.disc_area(),
            pdf_dir: 1.0,
        }
    }

    fn pdf_le(&self, _: Vec3, _: Vec3) -> (f32, f32) {
        (1.0 / self.sphere.disc_area(), 1.0)
    }
}

pub const FACTORY: Factory<DirectionalLight> = Factory {
    name: "directional",
    description: "parallel light from infinitely far (a sun)",
    create: |l, _, _| {
        let direction = l.vec3_required("direction")?;
        if direction.length_squared() == 0.0 {
            return Err(l.error("direction", "gives no direction (zero length)"));
        }
        let irradiance = l.rgb("irradiance", Rgb::ONE)?;
        Ok(Box::new(DirectionalLight {
            direction: direction.normalize(),
            irradiance,
            sphere: SceneSphere::default(),
        }))
    },
};
