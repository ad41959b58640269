//! `sunsky`: daylight at infinity, Mitsuba 0.6's `sunsky` (and, with one scale 0, its `sky`
//! or `sun`): the Hosek-Wilkie sky and Preetham's sun ([`crate::sky`]) rasterised into a
//! latitude-longitude map, rendered as an `envmap`.
//!
//! | Parameter          | Type      | Meaning                                                   | Default   |
//! |--------------------|-----------|-----------------------------------------------------------|-----------|
//! | `sun_direction`    | vector    | towards the sun, in world space                            | from the date |
//! | `year`, `month`, `day` | integer | the date (with no `sun_direction`)                      | 2010, 7, 10 |
//! | `hour`, `minute`, `second` | number | local time                                          | 15, 0, 0  |
//! | `latitude`, `longitude` | number | degrees north and east                                 | 35.6894, 139.6917 |
//! | `timezone`         | number    | hours ahead of UTC                                         | 9         |
//! | `turbidity`        | number    | haze, in [1, 10]                                           | 3         |
//! | `albedo`           | RGB       | the ground's albedo (lights the sky from below), in [0, 1] | 0.2       |
//! | `stretch`          | number    | stretches the sky over the horizon, in [1, 2]              | 1         |
//! | `scale`            | number    | scales the sky and the sun                                 | 1         |
//! | `sky_scale`        | number    | scales the sky; 0 leaves it out                            | `scale`   |
//! | `sun_scale`        | number    | scales the sun; 0 leaves it out                            | `scale`   |
//! | `sun_radius_scale` | number    | the sun's radius in true suns; > 0 (same power, dimmer)   | 1         |
//! | `extend`           | boolean   | continue the sky below the horizon                          | false     |
//! | `resolution`       | integer   | the map's width (height: half)                             | 512       |
//! | `to_world`         | transform | the frame whose +y is the zenith (only its rotation counts) | identity |
//!
//! A sun of radius 0 is a `directional` light of irradiance L_sun Ω_sun: give it as one, with
//! `sun_scale = 0` here.

use super::envmap::EnvmapLight;
use super::{EmittedRay, LightSample, LightSource, LightType, SceneSphere};
use crate::Rgb;
use crate::envmap::EnvironmentMap;
use crate::registry::Factory;
use crate::sky::{DATE_KEYS, DateTime, Place, Spherical, SunSky, sun_position};
use glam::{Mat3, Vec2, Vec3};
use std::sync::Arc;

/// The rasterised map, rendered as an [`EnvmapLight`].
#[derive(Clone, Debug)]
pub struct SunSkyLight {
    pub map: EnvmapLight,
}

impl LightSource for SunSkyLight {
    fn light_type(&self) -> LightType {
        self.map.light_type()
    }
    fn power(&self) -> Rgb {
        self.map.power()
    }
    fn fit_to_scene(&mut self, sphere: SceneSphere) {
        self.map.fit_to_scene(sphere)
    }
    #[inline]
    fn sample_li(&self, x: Vec3, u: Vec2, uc: f32) -> Option<LightSample> {
        self.map.sample_li(x, u, uc)
    }
    fn pdf_li(&self, x: Vec3, p: Vec3, n: Vec3) -> f32 {
        self.map.pdf_li(x, p, n)
    }
    #[inline]
    fn environment(&self, dir: Vec3) -> Rgb {
        self.map.environment(dir)
    }
    fn sample_emission(&self, u_pos: Vec2, u_dir: Vec2, uc: f32) -> EmittedRay {
        self.map.sample_emission(u_pos, u_dir, uc)
    }
    fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        self.map.pdf_le(n, dir)
    }
}

pub const FACTORY: Factory<SunSkyLight> = Factory {
    name: "sunsky",
    description: "daylight: the Hosek-Wilkie sky and Preetham's sun (Mitsuba 0.6's sunsky)",
    create: |l, _, resources| {
        let to_world = Mat3::from_mat4(resources.transform(l, "to_world")?);
        let sun = match l.vec3_opt("sun_direction")? {
            Some(d) => {
                if let Some(k) = DATE_KEYS.iter().find(|k| l.has(k)) {
                    return Err(l.error(
                        k,
                        "give the sun's position either as `sun_direction` or by date, time \
                         and place, not both",
                    ));
                }
                let local = to_world.inverse() * d;
                if local.length_squared() <= 0.0 || !local.is_finite() {
                    return Err(l.error("sun_direction", "gives no direction (zero length)"));
                }
                Spherical::of(local.as_dvec3().normalize())
            }
            None => {
                let (d, p) = (DateTime::default(), Place::default());
                let int = |k: &str, default: i32| -> crate::error::Result<i32> {
                    let v = l.f32(k, default as f32)?;
                    if v.fract() != 0.0 {
                        return Err(l.error(k, format!("expected a whole number, found {v}")));
                    }
                    Ok(v as i32)
                };
                let when = DateTime {
                    year: int("year", d.year)?,
                    month: int("month", d.month)?,
                    day: int("day", d.day)?,
                    hour: l.f32("hour", d.hour as f32)? as f64,
                    minute: l.f32("minute", d.minute as f32)? as f64,
                    second: l.f32("second", d.second as f32)? as f64,
                };
                let place = Place {
                    latitude: l.f32("latitude", p.latitude as f32)? as f64,
                    longitude: l.f32("longitude", p.longitude as f32)? as f64,
                    timezone: l.f32("timezone", p.timezone as f32)? as f64,
                };
                sun_position(&when, &place)
            }
        };
        let scale = l.f32("scale", 1.0)?;
        let albedo = l.rgb("albedo", Vec3::splat(0.2))?;
        let sky = SunSky {
            sun,
            turbidity: l.f32("turbidity", 3.0)? as f64,
            albedo: albedo.as_dvec3(),
            stretch: l.f32("stretch", 1.0)? as f64,
            sky_scale: l.f32("sky_scale", scale)? as f64,
            sun_scale: l.f32("sun_scale", scale)? as f64,
            sun_radius_scale: l.f32("sun_radius_scale", 1.0)? as f64,
            extend: l.bool("extend", false)?,
        };
        for k in ["scale", "sky_scale", "sun_scale"] {
            if l.f32(k, 0.0)? < 0.0 {
                return Err(l.error(k, "must be non-negative"));
            }
        }
        if sky.sun_scale > 0.0 && sky.sun_radius_scale == 0.0 {
            return Err(l.error(
                "sun_radius_scale",
                "a sun of radius 0 is a `directional` light: give it as one, with \
                 `sun_scale = 0` here",
            ));
        }
        sky.validate().map_err(|(key, e)| {
            // The sun's position may come from the date, time and place.
            let key = if l.has(key) {
                key
            } else if key == "sun_direction" {
                DATE_KEYS.iter().copied().find(|k| l.has(k)).unwrap_or("type")
            } else {
                "type"
            };
            l.error(key, e)
        })?;
        let resolution = l.u32("resolution", 512)? as usize;
        if !(4..=1 << 14).contains(&resolution) {
            return Err(l.error(
                "resolution",
                format!("expected a width in [4, 16384], found {resolution}"),
            ));
        }
        let map = EnvironmentMap::new(&sky.rasterize(resolution), 1.0, to_world)
            .map_err(|e| l.error("to_world", e))?;
        Ok(Box::new(SunSkyLight {
            map: EnvmapLight {
                map: Arc::new(map),
                sphere: SceneSphere::default(),
            },
        }))
    },
};
