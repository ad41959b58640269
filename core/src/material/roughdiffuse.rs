//! `roughdiffuse`: a rough diffuse surface of V-grooves with Lambertian facets (Oren and Nayar
//! 1994), as Mitsuba 0.6's `roughdiffuse`. The roughness is given as `alpha`, the RMS slope
//! of the microfacet models, and read as the standard deviation sigma = alpha / sqrt(2) of the
//! facets' slopes (the factor Mitsuba fitted). The full model is the paper's: single
//! scattering with its C1, C2 and C3 terms plus the facets' interreflection (rho^2 C4); the
//! fast approximation is the qualitative model A + B max(0, cos(phi_i - phi_o)) sin(alpha)
//! tan(beta). alpha = 0 is Lambertian. Sampled by the cosine.
//!
//! | Parameter         | Type                   | Meaning                                        | Default |
//! |-------------------|------------------------|------------------------------------------------|---------|
//! | `reflectance`     | RGB / texture          | the facets' albedo (also read as `diffuse_reflectance`, as Mitsuba does) | `0.5` |
//! | `alpha`           | number / RGB / texture | the RMS slope of the facets (>= 0; the mean of a colour's channels) | `0.2` |
//! | `use_fast_approx` | bool                   | the qualitative model, without the interreflection and C3 terms | `false` |
//! | `ensure_energy_conservation` | bool        | as Mitsuba 0.6: a reflectance above 1 is scaled by 0.99 / its maximum (with a warning) | `true` |
//! | `twosided`        | bool                   | the same seen from behind (false: black, a Mitsuba BSDF not wrapped in `twosided`) | `true` |
//!
//! Mitsuba 3 has no `roughdiffuse`; the values are tested against 0.6's formulas.

use crate::texture::TextureEvalContext;
use super::SurfaceMaterial;
use super::phong::{channel_mean, energy_conserving_scale, scalar_texture};
use crate::Rgb;
use crate::registry::Factory;
use crate::sampling::cosine_hemisphere;
use crate::scattering::{Bxdf, LocalSample, TransportMode, sampled_direction};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_1_SQRT_2};

#[derive(Clone, Debug)]
pub struct RoughDiffuseMaterial {
    pub reflectance: Texture,
    /// The RMS slope, as the mean of the texture's channels.
    pub alpha: Texture,
    /// Scales the reflectance (Mitsuba 0.6's energy conservation; 1 when it is at most 1).
    pub scale: f32,
    pub fast_approx: bool,
    pub twosided: bool,
}

/// The Oren-Nayar lobe, one-sided (black unless both directions are above).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDiffuseBxdf {
    pub reflectance: Rgb,
    pub alpha: f32,
    pub fast_approx: bool,
}

impl SurfaceMaterial for RoughDiffuseMaterial {
    type Bxdf = RoughDiffuseBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> RoughDiffuseBxdf {
        RoughDiffuseBxdf {
            reflectance: self.reflectance.at(ctx) * self.scale,
            alpha: channel_mean(self.alpha.at(ctx)),
            fast_approx: self.fast_approx,
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.reflectance.is_constant() || !self.alpha.is_constant()
    }

    fn twosided(&self) -> bool {
        self.twosided
    }
}

/// sin theta and the clamped cos phi and sin phi of a direction (Mitsuba's `Frame`).
#[inline]
fn angles(w: Vec3) -> (f32, f32, f32) {
    let sin2 = 1.0 - w.z * w.z;
    let sin = if sin2 <= 0.0 { 0.0 } else { sin2.sqrt() };
    if sin == 0.0 {
        return (0.0, 1.0, 1.0);
    }
    (
        sin,
        (w.x / sin).clamp(-1.0, 1.0),
        (w.y / sin).clamp(-1.0, 1.0),
    )
}

impl Bxdf for RoughDiffuseBxdf {
    #[inline(never)]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let sigma = self.alpha * FRAC_1_SQRT_2;
        let sigma2 = sigma * sigma;
        let (sin_o, cos_phi_o, sin_phi_o) = angles(wo);
        let (sin_i, cos_phi_i, sin_phi_i) = angles(wi);
        // cos(phi_o - phi_i); 0 where either azimuth is undefined.
        let cos_phi_diff = if sin_o > 1e-4 && sin_i > 1e-4 {
            cos_phi_o * cos_phi_i + sin_phi_o * sin_phi_i
        } else {
            0.0
        };
        // alpha the larger polar angle of the two, beta the smaller.
        let (sin_alpha, sin_beta, tan_beta) = if wo.z > wi.z {
            (sin_i, sin_o, sin_o / wo.z)
        } else {
            (sin_o, sin_i, sin_i / wi.z)
        };
        let rho = self.reflectance;
        if self.fast_approx {
            let a = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
            let b = 0.45 * sigma2 / (sigma2 + 0.09);
            return rho
                * (FRAC_1_PI * wi.z * (a + b * cos_phi_diff.max(0.0) * sin_alpha * tan_beta));
        }
        let (theta_o, theta_i) = (wo.z.min(1.0).acos(), wi.z.min(1.0).acos());
        let (alpha, beta) = (theta_o.max(theta_i), theta_o.min(theta_i));
        let tmp = sigma2 / (sigma2 + 0.09);
        let tmp2 = 4.0 * FRAC_1_PI * FRAC_1_PI * alpha * beta;
        let tmp3 = 2.0 * beta * FRAC_1_PI;
        let c1 = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
        let c2 = 0.45
            * tmp
            * if cos_phi_diff > 0.0 {
                sin_alpha
            } else {
                sin_alpha - tmp3 * tmp3 * tmp3
            };
        let c3 = 0.125 * tmp * tmp2 * tmp2;
        let c4 = 0.17 * sigma2 / (sigma2 + 0.13);
        // tan((alpha + beta) / 2) by the half-angle formula.
        let tan_half = (sin_alpha + sin_beta)
            / ((1.0 - sin_alpha * sin_alpha).max(0.0).sqrt()
                + (1.0 - sin_beta * sin_beta).max(0.0).sqrt());
        let single = rho
            * (c1 + cos_phi_diff * c2 * tan_beta + (1.0 - cos_phi_diff.abs()) * c3 * tan_half);
        let double = rho * rho * (c4 * (1.0 - cos_phi_diff * tmp3 * tmp3));
        (single + double) * (FRAC_1_PI * wi.z)
    }

    #[inline(never)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            0.0
        } else {
            wi.z * FRAC_1_PI
        }
    }

    #[inline(never)]
    fn sample(&self, wo: Vec3, u: Vec2, _: f32, _: TransportMode) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = cosine_hemisphere(u);
        sampled_direction(self, wo, wi)
    }

    /// Diffuse, whatever alpha (Mitsuba's).
    #[inline]
    fn roughness(&self) -> f32 {
        f32::INFINITY
    }
}

pub const FACTORY: Factory<RoughDiffuseMaterial> = Factory {
    name: "roughdiffuse",
    description: "a rough diffuse surface (Oren-Nayar, with interreflections)",
    create: |m, _, resources| {
        // Mitsuba reads either name, `reflectance` first.
        let key = if !m.has("reflectance") && m.has("diffuse_reflectance") {
            "diffuse_reflectance"
        } else {
            "reflectance"
        };
        let reflectance = resources.texture(m, key, Rgb::splat(0.5))?;
        let scale = energy_conserving_scale(m, &[key], &[&reflectance], resources)?;
        Ok(Box::new(RoughDiffuseMaterial {
            reflectance,
            alpha: scalar_texture(m, "alpha", 0.2, resources)?,
            scale,
            fast_approx: m.bool("use_fast_approx", false)?,
            twosided: m.bool("twosided", true)?,
        }))
    },
};
