//! `projector`: a point light that projects an image through a pinhole, the reciprocal of a
//! perspective camera (Mitsuba 3's `projector`): it lights the rectangle of directions a
//! camera with the same field of view would see, each direction with the image's value where
//! that camera would see it.
//!
//! | Parameter    | Type          | Meaning                                                  | Default              |
//! |--------------|---------------|----------------------------------------------------------|----------------------|
//! | `position`   | point         | the pinhole                                              | required             |
//! | `look_at`    | point         | a point on its axis                                      | this or `direction`  |
//! | `direction`  | vector        | its axis                                                 | this or `look_at`    |
//! | `up`         | vector        | the image's up, as a look-at's `up`                      | `[0, 1, 0]`          |
//! | `fov`        | degrees       | the field of view along `fov_axis`, in (0, 180)          | required             |
//! | `fov_axis`   | string        | `"x"`, `"y"`, `"diagonal"`, `"smaller"`, `"larger"`     | `"x"`                |
//! | `irradiance` | RGB / texture | the image (Mitsuba's `irradiance`)                       | `[1, 1, 1]`          |
//! | `scale`      | number        | a factor on the image                                    | `1`                  |
//! | `mirror`     | boolean       | the image mirrored left to right                         | `false`              |
//!
//! The image spans the rectangle of half-widths (tan_x, tan_y) on the plane at distance 1
//! along the axis, its aspect ratio the texture's (1 for a constant); a direction (x, y, z)
//! in the light's frame (+z the axis, +x = up x axis, +y = axis x x, Mitsuba's look-at frame)
//! reads it at uv = (1/2 - x / (2 z tan_x), 1/2 - y / (2 z tan_y)), uv (0, 0) the image's
//! top-left corner, as the camera would see it. The intensity is
//! I = pi scale E(uv) / cos^3 theta (theta the angle from the axis): the irradiance on any
//! plane across the axis at distance d is pi scale E(uv) / d^2, constant for a constant image
//! (Mitsuba 3's normalisation). The power is pi scale A mean(E), A = 4 tan_x tan_y.

use super::{EmittedRay, LightSample, LightSource, LightType, read_axis, towards};
use crate::Rgb;
use crate::registry::Factory;
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct ProjectorLight {
    pub position: Vec3,
    /// The light's frame: `x` and `y` span the image (x to its left, y to its top, as
    /// Mitsuba's camera frame), `z` is the axis.
    pub x: Vec3,
    pub y: Vec3,
    pub z: Vec3,
    /// Half-widths of the image on the plane at distance 1.
    pub tan_x: f32,
    pub tan_y: f32,
    /// The image, times the light's scale.
    pub image: Texture,
    pub scale: f32,
}

impl ProjectorLight {
    /// The area of the image on the plane at distance 1.
    fn area(&self) -> f32 {
        4.0 * self.tan_x * self.tan_y
    }

    /// The image's uv towards the unit direction `d`, and cos theta; None outside the image.
    #[inline]
    fn uv(&self, d: Vec3) -> Option<(Vec2, f32)> {
        let z = d.dot(self.z);
        if z <= 0.0 {
            return None;
        }
        let u = 0.5 - d.dot(self.x) / (2.0 * z * self.tan_x);
        let v = 0.5 - d.dot(self.y) / (2.0 * z * self.tan_y);
        ((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)).then_some((Vec2::new(u, v), z))
    }

    /// The intensity (W/sr) towards the unit direction `d`: pi scale E(uv) / cos^3 theta.
    #[inline]
    fn intensity(&self, d: Vec3) -> Rgb {
        match self.uv(d) {
            Some((uv, cos)) => self.image.eval(uv.into()) * (PI * self.scale / (cos * cos * cos)),
            None => Rgb::ZERO,
        }
    }

    /// The density per solid angle of a direction of uniform points of the image's rectangle
    /// at distance 1: 1 / (A cos^3 theta) (dw = cos^3 theta dA there).
    #[inline]
    fn pdf_dir(&self, cos: f32) -> f32 {
        1.0 / (self.area() * cos * cos * cos)
    }
}

impl LightSource for ProjectorLight {
    fn light_type(&self) -> LightType {
        LightType::DeltaPosition
    }

    fn power(&self) -> Rgb {
        self.image.mean() * (PI * self.scale * self.area())
    }

    fn position(&self) -> Option<Vec3> {
        Some(self.position)
    }

    fn sample_li(&self, x: Vec3, _: Vec2, _: f32) -> Option<LightSample> {
        let (wi, dist, dist2) = towards(x, self.position)?;
        Some(LightSample {
            wi,
            dist,
            li: self.intensity(-wi) / dist2,
            pdf: 1.0,
            delta: true,
            p: self.position,
            n: Vec3::ZERO,
        })
    }

    fn pdf_li(&self, _: Vec3, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    /// Through a uniform point of the image's rectangle at distance 1: each photon carries
    /// pi scale A E(uv).
    fn sample_emission(&self, _: Vec2, u_dir: Vec2, _: f32) -> EmittedRay {
        let local = Vec3::new(
            (1.0 - 2.0 * u_dir.x) * self.tan_x,
            (1.0 - 2.0 * u_dir.y) * self.tan_y,
            1.0,
        );
        let dir = (self.x * local.x + self.y * local.y + self.z).normalize();
        let cos = 1.0 / local.length();
        let e = self.image.eval(u_dir.into()) * (PI * self.scale);
        EmittedRay {
            origin: self.position,
            dir,
            n: Vec3::ZERO,
            flux: e * self.area(),
            le: e / (cos * cos * cos),
            uv: Vec2::ZERO,
            pdf_pos: 1.0,
            pdf_dir: self.pdf_dir(cos),
        }
    }

    fn pdf_le(&self, _: Vec3, dir: Vec3) -> (f32, f32) {
        match self.uv(dir) {
            Some((_, cos)) => (1.0, self.pdf_dir(cos)),
            None => (1.0, 0.0),
        }
    }
}

/// tan of half the field of view across the image's width, for `fov` (degrees) along `axis`
/// of an image of aspect ratio `aspect` (width / height): Mitsuba 3's `parse_fov`. None: an
/// unknown axis.
pub fn tan_half_width(fov: f32, axis: &str, aspect: f32) -> Option<f32> {
    let t = (fov.to_radians() * 0.5).tan();
    let axis = match axis {
        "smaller" if aspect > 1.0 => "y",
        "smaller" => "x",
        "larger" if aspect > 1.0 => "x",
        "larger" => "y",
        other => other,
    };
    Some(match axis {
        "x" => t,
        "y" => t * aspect,
        "diagonal" => t * aspect / (aspect * aspect + 1.0).sqrt(),
        _ => return None,
    })
}

pub const FACTORY: Factory<ProjectorLight> = Factory {
    name: "projector",
    description: "a point light projecting an image (Mitsuba 3's projector)",
    create: |l, _, resources| {
        let position = l.vec3_required("position")?;
        let z = read_axis(l, position, "a projector")?;
        let up = l.vec3("up", Vec3::Y)?;
        let left = up.cross(z);
        if left.length_squared() < 1e-12 {
            return Err(l.error("up", "is parallel to the projector's axis"));
        }
        let left = left.normalize();
        let y = z.cross(left);
        let x = if l.bool("mirror", false)? { -left } else { left };
        let fov = l.f32_required("fov")?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(l.error("fov", format!("must be in (0, 180) degrees, found {fov}")));
        }
        let axis_name = l.choice(
            "fov_axis",
            &["x", "y", "diagonal", "smaller", "larger"],
            "x",
        )?;
        let image = resources.texture(l, "irradiance", Rgb::ONE)?;
        let aspect = match &image {
            Texture::Bitmap { bitmap, .. } => bitmap.width() as f32 / bitmap.height() as f32,
            _ => 1.0,
        };
        let tan_x = tan_half_width(fov, axis_name, aspect)
            .ok_or_else(|| l.error("fov_axis", "unknown axis"))?;
        let scale = l.f32("scale", 1.0)?;
        if !(scale >= 0.0 && scale.is_finite()) {
            return Err(l.error("scale", format!("must be >= 0 and finite, found {scale}")));
        }
        Ok(Box::new(ProjectorLight {
            position,
            x,
            y,
            z,
            tan_x,
            tan_y: tan_x / aspect,
            image,
            scale,
        }))
    },
};
