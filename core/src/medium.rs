//! Participating media. Declared here and parsed from scenes; rendering them is the job of the
//! integrators that support media.

use crate::Rgb;
use crate::sampling::{to_world, uniform_sphere};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Phase functions, in terms of the angle between the direction light travels before and
/// after scattering (cos = 1: straight on). g > 0 scatters forward.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    Isotropic,
    HenyeyGreenstein { g: f32 },
}

impl Phase {
    /// p(cos theta), normalised over the sphere of directions.
    pub fn eval(&self, cos_theta: f32) -> f32 {
        match *self {
            Phase::Isotropic => 1.0 / (4.0 * PI),
            Phase::HenyeyGreenstein { g } => {
                let denom = 1.0 + g * g - 2.0 * g * cos_theta;
                (1.0 - g * g) / (4.0 * PI * denom * denom.max(1e-12).sqrt())
            }
        }
    }

    /// Samples a new travel direction for light travelling along `dir`; the pdf equals `eval`.
    pub fn sample(&self, dir: Vec3, u: Vec2) -> (Vec3, f32) {
        match *self {
            Phase::Isotropic => (uniform_sphere(u), 1.0 / (4.0 * PI)),
            Phase::HenyeyGreenstein { g } => {
                let cos_theta = if g.abs() < 1e-3 {
                    1.0 - 2.0 * u.x
                } else {
                    let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u.x);
                    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
                };
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                let local = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
                (to_world(local, dir), self.eval(cos_theta))
            }
        }
    }
}

/// A participating medium.
pub trait Medium: Send + Sync + std::fmt::Debug {
    /// Absorption coefficient (1/m) at `p`.
    fn sigma_a(&self, p: Vec3) -> Rgb;
    /// Scattering coefficient (1/m) at `p`.
    fn sigma_s(&self, p: Vec3) -> Rgb;
    fn phase(&self) -> Phase;
    /// Transmittance along the segment from `a` to `b`.
    fn transmittance(&self, a: Vec3, b: Vec3) -> Rgb;
}

/// A medium with the same coefficients everywhere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homogeneous {
    pub sigma_a: Rgb,
    pub sigma_s: Rgb,
    pub phase: Phase,
}

impl Homogeneous {
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }
}

impl Medium for Homogeneous {
    fn sigma_a(&self, _: Vec3) -> Rgb {
        self.sigma_a
    }
    fn sigma_s(&self, _: Vec3) -> Rgb {
        self.sigma_s
    }
    fn phase(&self) -> Phase {
        self.phase
    }
    /// Beer-Lambert: exp(-sigma_t d) per channel.
    fn transmittance(&self, a: Vec3, b: Vec3) -> Rgb {
        let d = a.distance(b);
        (-self.sigma_t() * d).exp()
    }
}
