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
//! | `texture`      | texture    | multiplies the intensity by an image across the cone (Mitsuba 3's spot `texture`) | none |
//! | `up`           | vector     | with `texture`: the image's up (v grows towards it), as a look-at's `up` | `[0, 1, 0]` |
//!
//! A texture is looked up at uv = 1/2 + (x, y) / (2 z tan(cutoff)) for a direction (x, y, z)
//! in the light's frame (+z the axis, +x = up x axis, +y = axis x x, Mitsuba's look-at
//! frame): the image spans the square of half-width tan(cutoff) at unit distance.

use super::{EmittedRay, LightSample, LightSource, LightType, read_axis, towards};
use crate::Rgb;
use crate::registry::Factory;
use crate::sampling::{to_world, uniform_cone};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

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
    /// An image across the cone; None: the same intensity at every angle about the axis.
    pub texture: Option<Arc<SpotTexture>>,
}

/// A spot light's image and the frame that places it.
#[derive(Clone, Debug)]
pub struct SpotTexture {
    pub texture: Texture,
    /// The light's +x and +y (+z is its axis).
    pub x: Vec3,
    pub y: Vec3,
    /// 1 / tan(cutoff).
    inv_tan_cutoff: f32,
    /// The falloff-weighted mean of the image over the cone (the power's factor).
    mean: Rgb,
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
    /// The light with the image `texture` across its cone, `up` giving its orientation.
    pub fn with_texture(self, texture: Texture, up: Vec3) -> Result<SpotLight, String> {
        let x = up.cross(self.axis);
        if x.length_squared() < 1e-12 {
            return Err("`up` is parallel to the axis".into());
        }
        let x = x.normalize();
        let y = self.axis.cross(x);
        let mut t = SpotTexture {
            texture,
            x,
            y,
            inv_tan_cutoff: 1.0 / self.cutoff.tan().max(1e-6),
            mean: Rgb::ONE,
        };
        // The mean weighted by the falloff: a grid uniform in the cone's solid angle.
        let cos_max = self.cutoff.cos();
        let n = 64;
        let (mut sum, mut weight) = (glam::DVec3::ZERO, 0.0f64);
        for a in 0..n {
            for b in 0..n {
                let u = Vec2::new((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
                let local = uniform_cone(u, cos_max);
                let f = self.falloff(local.z) as f64;
                let d = t.x * local.x + t.y * local.y + self.axis * local.z;
                sum += t.at(self.axis, d).as_dvec3() * f;
                weight += f;
            }
        }
        t.mean = if weight > 0.0 {
            (sum / weight).as_vec3()
        } else {
            Rgb::ZERO
        };
        Ok(SpotLight {
            texture: Some(Arc::new(t)),
            ..self
        })
    }

    /// The image's factor towards the unit direction `d` (1 without an image, 0 outside
    /// the cone).
    #[inline]
    fn image(&self, d: Vec3) -> Rgb {
        match &self.texture {
            None => Rgb::ONE,
            Some(t) if self.axis.dot(d) > 0.0 => t.at(self.axis, d),
            Some(_) => Rgb::ZERO,
        }
    }

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

    /// I times the falloff's solid angle (and the image's mean over it).
    fn power(&self) -> Rgb {
        let mean = self.texture.as_ref().map_or(Rgb::ONE, |t| t.mean);
        self.intensity * self.solid_angle() * mean
    }

    fn position(&self) -> Option<Vec3> {
        Some(self.position)
    }

    #[inline(never)]
    fn sample_li(&self, x: Vec3, _: Vec2, _: f32) -> Option<LightSample> {
        let (wi, dist, dist2) = towards(x, self.position)?;
        Some(LightSample {
            wi,
            dist,
            li: self.intensity * self.image(-wi) * (self.falloff(self.axis.dot(-wi)) / dist2),
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
        let intensity = self.intensity * self.image(dir);
        EmittedRay {
            origin: self.position,
            dir,
            n: Vec3::ZERO,
            flux: intensity * (falloff * 2.0 * PI * (1.0 - cos_max)),
            le: intensity * falloff,
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

impl SpotTexture {
    /// The image towards the unit direction `d` (in the cone: d . axis > 0).
    #[inline]
    fn at(&self, axis: Vec3, d: Vec3) -> Rgb {
        let z = d.dot(axis);
        let k = 0.5 * self.inv_tan_cutoff / z;
        self.texture
            .eval(Vec2::new(0.5 + d.dot(self.x) * k, 0.5 + d.dot(self.y) * k).into())
    }
}

pub const FACTORY: Factory<SpotLight> = Factory {
    name: "spot",
    description: "a point light emitting in a cone (Mitsuba's spot)",
    create: |l, _, resources| {
        let position = l.vec3_required("position")?;
        let intensity = l.rgb("intensity", Rgb::ONE)?;
        let axis = read_axis(l, position, "a spot light")?;
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
        let spot = SpotLight {
            position,
            axis,
            intensity,
            beam_width: beam_width.to_radians(),
            cutoff: cutoff.to_radians(),
            falloff,
            texture: None,
        };
        if !l.has("texture") {
            return Ok(Box::new(spot));
        }
        let texture = resources.texture(l, "texture", Rgb::ONE)?;
        let up = l.vec3("up", Vec3::Y)?;
        let spot = spot
            .with_texture(texture, up)
            .map_err(|e| l.error("up", e))?;
        Ok(Box::new(spot))
    },
};
