//! `homogeneous`: a medium with the same coefficients everywhere.
//!
//! | Parameter | Type        | Meaning                                             | Default       |
//! |-----------|-------------|-----------------------------------------------------|---------------|
//! | `sigma_a` | RGB (1/m)   | absorption coefficient                              | `[0, 0, 0]`   |
//! | `sigma_s` | RGB (1/m)   | scattering coefficient                              | `[0, 0, 0]`   |
//! | `phase`   | string/table| `"isotropic"` or `{ type = "hg", g = ... }`         | `"isotropic"` |
//! | `emission`| RGB (W m^-2 sr^-1) | emitted radiance Le: sigma_a Le per metre along a ray | `[0, 0, 0]` |

use super::{FreeFlight, Medium, Phase, transmittance_homogeneous};
use crate::Rgb;
use crate::geometry::Ray;
use crate::registry::Factory;
use glam::Vec3;

/// A medium with the same coefficients everywhere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homogeneous {
    pub sigma_a: Rgb,
    pub sigma_s: Rgb,
    pub phase: Phase,
    /// Emitted radiance Le.
    pub emission: Rgb,
}

impl Homogeneous {
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }

    /// Transmittance over a distance `d` (which may be infinite).
    #[inline]
    pub fn transmittance_over(&self, d: f32) -> Rgb {
        transmittance_homogeneous(self.sigma_t(), d)
    }
}

impl Medium for Homogeneous {
    fn is_vacuum(&self) -> bool {
        self.sigma_t().max_element() == 0.0
    }
    fn sigma_a(&self, _: Vec3) -> Rgb {
        self.sigma_a
    }
    fn sigma_s(&self, _: Vec3) -> Rgb {
        self.sigma_s
    }
    fn phase(&self) -> Phase {
        self.phase
    }
    fn emission(&self, _: Vec3) -> Rgb {
        self.emission
    }
    fn is_emissive(&self) -> bool {
        self.emission != Rgb::ZERO && self.sigma_a != Rgb::ZERO
    }
    /// Beer-Lambert: exp(-sigma_t d) per channel.
    fn transmittance(&self, _ray: &Ray, d: f32) -> Rgb {
        self.transmittance_over(d)
    }
    /// t is drawn from sigma_t,c exp(-sigma_t,c t) for the given channel c.
    fn sample_free_flight(&self, _ray: &Ray, tmax: f32, channel: usize, u: f32) -> FreeFlight {
        let sigma_t = self.sigma_t();
        let s = sigma_t[channel];
        // 1 - u is in (0, 1]: the logarithm is finite.
        let t = if s > 0.0 {
            -(1.0 - u).ln() / s
        } else {
            f32::INFINITY
        };
        if t < tmax {
            let tr = transmittance_homogeneous(sigma_t, t);
            FreeFlight {
                t,
                scattered: true,
                f: self.sigma_s * tr,
                pdf: sigma_t * tr,
                emitted: self.sigma_a * self.emission * tr,
            }
        } else {
            let tr = transmittance_homogeneous(sigma_t, tmax);
            FreeFlight {
                t: tmax,
                scattered: false,
                f: tr,
                pdf: tr,
                emitted: Rgb::ZERO,
            }
        }
    }
    fn homogeneous(&self) -> Option<Homogeneous> {
        Some(*self)
    }
}

pub const FACTORY: Factory<dyn Medium> = Factory {
    name: "homogeneous",
    description: "constant absorption and scattering, isotropic or Henyey-Greenstein phase",
    create: |m, nested, _| {
        let sigma_a = m.rgb("sigma_a", Rgb::ZERO)?;
        let sigma_s = m.rgb("sigma_s", Rgb::ZERO)?;
        let phase = Phase::read(m, nested)?;
        let emission = m.rgb("emission", Rgb::ZERO)?;
        if emission.min_element() < 0.0 {
            return Err(m.error("emission", "must not be negative"));
        }
        Ok(Box::new(Homogeneous {
            sigma_a,
            sigma_s,
            phase,
            emission,
        }))
    },
};
