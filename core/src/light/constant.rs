//! `constant`: the same radiance from every direction at infinity (Mitsuba's `constant`, a
//! uniform sky). Rays leaving the scene see it; a scene has at most one such environment.
//!
//! | Parameter  | Type              | Meaning                | Default     |
//! |------------|-------------------|------------------------|-------------|
//! | `radiance` | RGB (W/(sr m^2))  | radiance from the sky  | `[1, 1, 1]` |

use super::{EmittedRay, LightSample, LightSource, LightType, SceneSphere};
use crate::Rgb;
use crate::registry::Factory;
use crate::sampling::{UNIFORM_SPHERE_PDF, uniform_sphere};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Its photons leave the disc of the scene's bounding sphere facing their direction.
#[derive(Clone, Debug)]
pub struct ConstantLight {
    pub radiance: Rgb,
    pub sphere: SceneSphere,
}

impl LightSource for ConstantLight {
    fn light_type(&self) -> LightType {
        LightType::Infinite
    }

    /// The flux through the bounding sphere's disc from every direction: 4 pi L pi R^2.
    fn power(&self) -> Rgb {
        let radius = self.sphere.radius;
        self.radiance * (4.0 * PI * PI * radius * radius)
    }

    fn fit_to_scene(&mut self, sphere: SceneSphere) {
        self.sphere = sphere;
    }

    /// Uniform over the sphere of directions.
    #[inline(never)]
    fn sample_li(&self, x: Vec3, u: Vec2, _: f32) -> Option<LightSample> {
        let wi = uniform_sphere(u);
        let mut ls = self.sphere.sample_at_infinity(x, wi);
        ls.li = self.radiance;
        ls.pdf = UNIFORM_SPHERE_PDF;
        ls.delta = false;
        Some(ls)
    }

    fn pdf_li(&self, _: Vec3, _: Vec3, _: Vec3) -> f32 {
        UNIFORM_SPHERE_PDF
    }

    #[inline]
    fn environment(&self, _: Vec3) -> Rgb {
        self.radiance
    }

    /// A uniform direction, then a uniform point of the disc facing it: L cos / (1/(pi R^2)
    /// x 1/(4 pi)) with cos = 1 on the disc.
    fn sample_emission(&self, u_pos: Vec2, u_dir: Vec2, _: f32) -> EmittedRay {
        let radius = self.sphere.radius;
        let dir = -uniform_sphere(u_dir);
        EmittedRay {
            origin: self.sphere.disc_origin(dir, u_pos),
            dir,
            n: Vec3::ZERO,
            flux: self.radiance * (4.0 * PI * PI * radius * radius),
            le: self.radiance,
            uv: Vec2::ZERO,
            pdf_pos: 1.0 / self.sphere.disc_area(),
            pdf_dir: UNIFORM_SPHERE_PDF,
        }
    }

    fn pdf_le(&self, _: Vec3, _: Vec3) -> (f32, f32) {
        (1.0 / self.sphere.disc_area(), UNIFORM_SPHERE_PDF)
    }
}

pub const FACTORY: Factory<ConstantLight> = Factory {
    name: "constant",
    description: "the same radiance from every direction (a uniform sky)",
    create: |l, _, _| {
        Ok(Box::new(ConstantLight {
            radiance: l.rgb("radiance", Rgb::ONE)?,
            sphere: SceneSphere::default(),
        }))
    },
};
