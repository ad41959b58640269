//! `spot`: a point light emitting in a cone (Mitsuba's `spot`), at full intensity within
//! `beam_width` of its axis, falling linearly in angle to zero at `cutoff_angle`.
//!
//! | Parameter      | Type       | Meaning                                      | Default              |
//! |----------------|------------|----------------------------------------------|----------------------|
//! | `position`     | point      | where it is                                  | required             |
//! | `look_at`      | point      | a point on its axis                          | this or `direction`  |
//! | `direction`    | vector     | its axis                                     | this or `look_at`    |
//! | `intensity`    | RGB (W/sr) | intensity at the centre of the cone          | `[1, 1, 1]`          |
//! | `cutoff_angle` | degrees    | no light past it, in (0, 90]                 | `20`                 |
//! | `beam_width`   | degrees    | full intensity within it, in [0, cutoff]     | 3/4 of the cutoff    |

use super::{EmittedRay, LightSample, LightSource, LightType, towards};
use crate::Rgb;
use crate::registry::Factory;
use crate::sampling::{to_world, uniform_cone};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct SpotLight {
    pub position: Vec3,
    /// Unit direction of the cone's axis.
    pub axis: Vec3,
    /// W/sr at the centre.
    pub intensity: Rgb,
    /// Angles (radians) from the axis: full intensity within `beam_width`, none past
    /// `cutoff`.
    pub beam_width: f32,
    pub cutoff: f32,
}

/// The spot light's falloff at angle theta from its axis (Mitsuba's `falloff_curve`): 1 within
/// the beam width, linear in the angle down to 0 at the cutoff, 0 beyond.
#[inline]
pub fn spot_falloff(cos_theta: f32, beam_width: f32, cutoff: f32) -> f32 {
    if cos_theta <= cutoff.cos() {
        return 0.0;
    }
    if cos_theta >= beam_width.cos() {
        return 1.0;
    }
    ((cutoff - cos_theta.clamp(-1.0, 1.0).acos()) / (cutoff - beam_width)).clamp(0.0, 1.0)
}

/// The integral of the spot falloff over the sphere of directions (its power per unit
/// intensity): 2 pi [1 - cos b + ((c - b) cos b + sin b - sin c) / (c - b)], b the beam width
/// and c the cutoff (2 pi (1 - cos c) when they are equal).
pub fn spot_solid_angle(beam_width: f32, cutoff: f32) -> f32 {
    let (b, c) = (beam_width as f64, cutoff as f64);
    let ramp = if c - b > 1e-9 {
        ((c - b) * b.cos() + b.sin() - c.sin()) / (c - b)
    } else {
        0.0
    };
    (2.0 * std::f64::consts::PI * (1.0 - b.cos() + ramp)) as f32
}

impl LightSource for SpotLight {
    fn light_type(&self) -> LightType {
        LightType::DeltaPosition
    }

    /// I times the falloff's solid angle.
    fn power(&self) -> Rgb {
        self.intensity * spot_solid_angle(self.beam_width, self.cutoff)
    }

    fn position(&self) -> Option<Vec3> {
        Some(self.position)
    }

    #[inline(never)]
    fn sample_li(&self, x: Vec3, _: Vec2, _: f32) -> Option<LightSample> {
        let (wi, dist, dist2) = towards(x, self.position)?;
        let falloff = spot_falloff(self.axis.dot(-wi), self.beam_width, self.cutoff);
        Some(LightSample {
            wi,
            dist,
            li: self.intensity * (falloff / dist2),
            pdf: 1.0,
            delta: true,
            p: self.position,
            n: Vec3::ZERO,
        })
    }

    fn pdf_li(&self, _: Vec3, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    /// Uniform in the cone of the cutoff, weighted by the falloff: I f / pdf.
    fn sample_emission(&self, _: Vec2, u_dir: Vec2, _: f32) -> EmittedRay {
        let cos_max = self.cutoff.cos();
        let dir = to_world(uniform_cone(u_dir, cos_max), self.axis);
        let falloff = spot_falloff(self.axis.dot(dir), self.beam_width, self.cutoff);
        EmittedRay {
            origin: self.position,
            dir,
            n: Vec3::ZERO,
            flux: self.intensity * (falloff * 2.0 * PI * (1.0 - cos_max)),
            le: self.intensity * falloff,
            pdf_pos: 1.0,
            pdf_dir: 1.0 / (2.0 * PI * (1.0 - cos_max)),
        }
    }

    fn pdf_le(&self, _: Vec3, dir: Vec3) -> (f32, f32) {
        let cos_max = self.cutoff.cos();
        let pdf = if self.axis.dot(dir) > cos_max {
            1.0 / (2.0 * PI * (1.0 - cos_max))
        } else {
            0.0
        };
        (1.0, pdf)
    }
}

pub const FACTORY: Factory<SpotLight> = Factory {
    name: "spot",
    description: "a point light emitting in a cone (Mitsuba's spot)",
    create: |l, _, _| {
        let position = l.vec3_required("position")?;
        let intensity = l.rgb("intensity", Rgb::ONE)?;
        let axis = match (l.vec3_opt("look_at")?, l.vec3_opt("direction")?) {
            (Some(target), None) => target - position,
            (None, Some(d)) => d,
            (Some(_), Some(_)) => {
                return Err(l.error("direction", "give either look_at or direction, not both"));
            }
            (None, None) => {
                return Err(l.error(
                    "look_at",
                    "missing; a spot light needs look_at = [x, y, z] or direction = [x, y, z]",
                ));
            }
        };
        if axis.length_squared() == 0.0 {
            let key = if l.has("look_at") {
                "look_at"
            } else {
                "direction"
            };
            return Err(l.error(key, "gives no direction (zero length)"));
        }
        let cutoff = l.f32("cutoff_angle", 20.0)?;
        if !(cutoff > 0.0 && cutoff <= 90.0) {
            return Err(l.error(
                "cutoff_angle",
                format!("must be in (0, 90] degrees, found {cutoff}"),
            ));
        }
        let beam_width = l.f32("beam_width", 0.75 * cutoff)?;
        if !(beam_width >= 0.0 && beam_width <= cutoff) {
            return Err(l.error(
                "beam_width",
                format!("must be in [0, cutoff_angle = {cutoff}] degrees, found {beam_width}"),
            ));
        }
        Ok(Box::new(SpotLight {
            position,
            axis: axis.normalize(),
            intensity,
            beam_width: beam_width.to_radians(),
            cutoff: cutoff.to_radians(),
        }))
    },
};
