//! Phase functions, and how a medium's `phase` parameter names one.

use crate::error::Result;
use crate::props::Properties;
use crate::sampling::{to_world, uniform_sphere};
use crate::value::Value;
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

impl Phase {
    /// The phase function a medium's bag names at `phase`: absent or `"isotropic"`, or a table
    /// `{ type = "hg", g = ... }` (|g| < 1), which is pushed onto `nested` (see
    /// [`crate::registry::Create`]).
    pub fn read<'a>(m: &Properties<'a>, nested: &mut Vec<Properties<'a>>) -> Result<Phase> {
        match m.node("phase").map(|n| &n.value) {
            None => Ok(Phase::Isotropic),
            Some(Value::Str(s)) if s == "isotropic" => Ok(Phase::Isotropic),
            Some(Value::Str(s)) => Err(m.error(
                "phase",
                format!("unknown phase function {s:?}; expected \"isotropic\" or {{ type = \"hg\", g = ... }}"),
            )),
            Some(Value::Table(_)) => {
                let p = m.table("phase")?.unwrap();
                let ty = p.choice("type", &["hg", "isotropic"], "hg")?;
                let phase = if ty == "isotropic" {
                    Phase::Isotropic
                } else {
                    let g = p.f32("g", 0.0)?;
                    if g.abs() >= 1.0 {
                        return Err(p.error("g", format!("must satisfy |g| < 1, found {g}")));
                    }
                    Phase::HenyeyGreenstein { g }
                };
                nested.push(p);
                Ok(phase)
            }
            Some(other) => Err(m.error(
                "phase",
                format!(
                    "expected \"isotropic\" or {{ type = \"hg\", g = ... }}, found {} `{}`",
                    other.type_name(),
                    other.show()
                ),
            )),
        }
    }
}
