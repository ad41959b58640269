//! `spot`: a point light emitting in a cone (Mitsuba's `spot`), at full intensity within
//! `beam_width` of its axis, falling to zero at `cutoff_angle`: linearly in the angle
//! (Mitsuba's falloff), or as a smoothstep in the cosine (pbrt-v4's `spot`, `falloff =
//! "smoothstep"`).
//!
//! | Parameter      | Type       | Meaning                                      | Default              |
//! |----------------|------------|----------------------------------------------|----------------------|
//! | `position`     | point      | where it is                                  | required             |
//! | `look_at`      | point      | a point on its axis                          | this or `direction`  |
//! | `direction`    | vector     | its axis                                     | this or `look_at`    |
//! | `intensity`    | RGB (W/sr) | intensity at the centre of the cone          | `[1, 1, 1]`          |
//! | `cutoff_angle` | degrees    | no light past it, in (0, 90]                 | `20`                 |
//! | `beam_width`   | degrees    | full intensity within it, in [0, cutoff]     | 3/4 of the cutoff    |
//! | `falloff`      | string     | `"linear"` (in the angle) or `"smoothstep"` (in the cosine) | `"linear"` |

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
    pub falloff: Falloff,
}

/// How the intensity falls from the beam width to the cutoff.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Falloff {
    /// Linear in the angle (Mitsuba's `falloff_curve`).
    Linear,
    /// pbrt-v4's `SmoothStep(cos cutoff, cos beam width, cos theta)`.
    Smoothstep,
}

impl SpotLight {
    /// The falloff at angle theta from the axis.
    #[inline]
    fn falloff(&self, cos_theta: f32) -> f32 {
        match self.falloff {
            Falloff::Linear => spot_falloff(cos_theta, self.beam_width, self.cutoff),
            Falloff::Smoothstep => {
                smoothstep(self.cutoff.cos(), self.beam_width.cos(), cos_theta)
            }
        }
    }

    /// The integral of the falloff over the sphere of directions.
    fn solid_angle(&self) -> f32 {
        match self.falloff {
            Falloff::Linear => spot_solid_angle(self.beam_width, self.cutoff),
            // The smoothstep's mean over its ramp is 1/2: 2 pi [(1 - cos b) + (cos b - cos
            // c) / 2] (pbrt-v4's `SpotLight::Phi`).
            Falloff::Smoothstep => {
                let (cb, cc) = (self.beam_width.cos() as f64, self.cutoff.cos() as f64);
                (2.0 * std::f64::consts::PI * ((1.0 - cb) + (cb - cc) / 2.0)) as f32
            }
        }
    }
}

/// 0 at and below `a`, 1 at and above `b`, the cubic 3t^2 - 2t^3 between (pbrt-v4's
/// `SmoothStep`; a step at `a` when a = b).
#[inline]
pub fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
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
        self.intensity * self.solid_angle()
    }

    fn position(&self) -> Option<Vec3> {
        Some(self.position)
    }

    #[inline(never)]
    fn sample_li(&self, x: Vec3, _: Vec2, _: f32) -> Option<LightSample> {
        let (wi, dist, dist2) = towards(x, self.position)?;
        let falloff = self.falloff(self.axis.dot(-wi));
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
        let falloff = self.falloff(self.axis.dot(dir));
        EmittedRay {
            origin: self.position,
            dir,
            n: Vec3::ZERO,
            flux: self.intensity * (falloff * 2.0 * PI * (1.0 - cos_max)),
            le: self.intensity * falloff,
            uv: Vec2::ZERO,
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
        let falloff = match l.choice("falloff", &["linear", "smoothstep"], "linear")? {
            "smoothstep" => Falloff::Smoothstep,
            _ => Falloff::Linear,
        };
        Ok(Box::new(SpotLight {
            position,
            axis: axis.normalize(),
            intensity,
            beam_width: beam_width.to_radians(),
            cutoff: cutoff.to_radians(),
            falloff,
        }))
    },
};
