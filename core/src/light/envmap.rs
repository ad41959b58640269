//! `envmap`: radiance from every direction at infinity read from a latitude-longitude image
//! (Mitsuba's `envmap`) or an equal-area octahedral one (pbrt-v4's image `infinite` light),
//! sampled by its luminance. Rays leaving the scene see it; a scene has
//! at most one such environment.
//!
//! | Parameter  | Type      | Meaning                                                          | Default  |
//! |------------|-----------|------------------------------------------------------------------|----------|
//! | `filename` | string    | the image: OpenEXR or Radiance HDR (linear), PNG or JPEG (sRGB)  | required |
//! | `scale`    | number    | radiance scale, >= 0                                             | `1`      |
//! | `to_world` | transform | turns the map (only its rotation counts)                         | identity |
//! | `mapping`  | string    | `"latlong"` (Mitsuba's) or `"equal_area"` (pbrt-v4's octahedral) | `"latlong"` |

use super::{EmittedRay, LightSample, LightSource, LightType, SceneSphere};
use crate::Rgb;
use crate::envmap::EnvironmentMap;
use crate::registry::Factory;
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// Its photons leave the disc of the scene's bounding sphere facing their direction.
#[derive(Clone, Debug)]
pub struct EnvmapLight {
    pub map: Arc<EnvironmentMap>,
    pub sphere: SceneSphere,
}

impl LightSource for EnvmapLight {
    fn light_type(&self) -> LightType {
        LightType::Infinite
    }

    /// pi R^2 times the integral of L over the sphere (pbrt's ImageInfiniteLight).
    fn power(&self) -> Rgb {
        self.map.integral() * self.sphere.disc_area()
    }

    fn fit_to_scene(&mut self, sphere: SceneSphere) {
        self.sphere = sphere;
    }

    #[inline(never)]
    fn sample_li(&self, x: Vec3, u: Vec2, _: f32) -> Option<LightSample> {
        let (wi, li, pdf) = self.map.sample(u)?;
        let mut ls = self.sphere.sample_at_infinity(x, wi);
        ls.li = li;
        ls.pdf = pdf;
        ls.delta = false;
        Some(ls)
    }

    /// The direction is all that counts: `p` is any point along it from `x`.
    fn pdf_li(&self, x: Vec3, p: Vec3, _: Vec3) -> f32 {
        self.map.pdf((p - x).normalize_or_zero())
    }

    #[inline]
    fn environment(&self, dir: Vec3) -> Rgb {
        self.map.eval(dir)
    }

    /// A direction by the map's density, then a uniform point of the disc facing it:
    /// L / (pdf_dir / (pi R^2)) (pbrt's ImageInfiniteLight::SampleLe).
    fn sample_emission(&self, u_pos: Vec2, u_dir: Vec2, _: f32) -> EmittedRay {
        let (dir, flux, le, pdf_dir) = match self.map.sample(u_dir) {
            Some((wi, li, pdf)) => (-wi, li * (self.sphere.disc_area() / pdf), li, pdf),
            None => (-Vec3::Z, Rgb::ZERO, Rgb::ZERO, 0.0),
        };
        EmittedRay {
            origin: self.sphere.disc_origin(dir, u_pos),
            dir,
            n: Vec3::ZERO,
            flux,
            le,
            uv: Vec2::ZERO,
            pdf_pos: 1.0 / self.sphere.disc_area(),
            pdf_dir,
        }
    }

    fn pdf_le(&self, _: Vec3, dir: Vec3) -> (f32, f32) {
        (1.0 / self.sphere.disc_area(), self.map.pdf(-dir))
    }
}

pub const FACTORY: Factory<EnvmapLight> = Factory {
    name: "envmap",
    description: "radiance at infinity from a latitude-longitude image",
    create: |l, _, resources| {
        l.string_required("filename")?;
        let scale = l.f32("scale", 1.0)?;
        if scale < 0.0 {
            return Err(l.error("scale", format!("must be non-negative, found {scale}")));
        }
        let to_world = resources.transform(l, "to_world")?;
        let bitmap = resources.bitmap(l, "filename", false)?;
        let to_world = glam::Mat3::from_mat4(to_world);
        let map = match l.choice("mapping", &["latlong", "equal_area"], "latlong")? {
            "equal_area" => EnvironmentMap::equal_area(&bitmap, scale, to_world),
            _ => EnvironmentMap::new(&bitmap, scale, to_world),
        }
        .map_err(|e| l.error("to_world", e))?;
        Ok(Box::new(EnvmapLight {
            map: Arc::new(map),
            sphere: SceneSphere::default(),
        }))
    },
};
