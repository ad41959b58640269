//! `phong`: the modified Phong model (Phong 1975; Lafortune and Willems 1994), a Lambertian
//! part plus a lobe around the mirror direction, as Mitsuba 0.6's `phong`:
//! f = diffuse_reflectance / pi + specular_reflectance (n + 2) / (2 pi) cos^n(alpha), alpha
//! the angle between `wi` and `wo`'s mirror direction. One part or the other is sampled, with
//! the probability of the specular one the share of its mean luminance over the surface in the
//! two colours' (Mitsuba's `m_specularSamplingWeight`); the specular part samples
//! cos^n(alpha) (n + 1) / (2 pi) around the mirror direction.
//!
//! | Parameter              | Type                   | Meaning                                   | Default |
//! |------------------------|------------------------|-------------------------------------------|---------|
//! | `exponent`             | number / RGB / texture | the lobe's exponent n (>= 0; the mean of a colour's channels) | `30` |
//! | `specular_reflectance` | RGB / texture          | the specular part's weight                | `0.2`   |
//! | `diffuse_reflectance`  | RGB / texture          | the diffuse part's albedo                 | `0.5`   |
//! | `ensure_energy_conservation` | bool             | as Mitsuba 0.6: where the two colours sum above 1 in a channel, scale both by 0.99 / that sum (with a warning) | `true` |
//! | `twosided`             | bool                   | the same seen from behind (false: black, a Mitsuba BSDF not wrapped in `twosided`) | `true` |
//!
//! Mitsuba 3 has no `phong`; the values are tested against 0.6's formulas.

use crate::texture::TextureEvalContext;
use super::SurfaceMaterial;
use crate::Rgb;
use crate::error::Result;
use crate::props::Properties;
use crate::registry::{Factory, Resources};
use crate::sampling::{cosine_hemisphere, to_world};
use crate::scattering::{Bxdf, LocalSample, TransportMode};
use crate::texture::{Texture, luminance};
use crate::value::Value;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

#[derive(Clone, Debug)]
pub struct PhongMaterial {
    pub diffuse_reflectance: Texture,
    pub specular_reflectance: Texture,
    /// n, as the mean of the texture's channels.
    pub exponent: Texture,
    /// Scales both colours (Mitsuba 0.6's energy conservation; 1 when they sum to at most 1).
    pub scale: f32,
    /// The probability of sampling the specular part.
    pub specular_sampling_weight: f32,
    pub twosided: bool,
}

/// The modified Phong lobe, one-sided (black unless both directions are above).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhongBxdf {
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    pub exponent: f32,
    pub specular_sampling_weight: f32,
}

impl SurfaceMaterial for PhongMaterial {
    type Bxdf = PhongBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> PhongBxdf {
        PhongBxdf {
            diffuse_reflectance: self.diffuse_reflectance.at(ctx) * self.scale,
            specular_reflectance: self.specular_reflectance.at(ctx) * self.scale,
            exponent: channel_mean(self.exponent.at(ctx)),
            specular_sampling_weight: self.specular_sampling_weight,
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.diffuse_reflectance.is_constant()
            || !self.specular_reflectance.is_constant()
            || !self.exponent.is_constant()
    }

    fn twosided(&self) -> bool {
        self.twosided
    }
}

impl PhongBxdf {
    /// cos alpha: `wi` against `wo` mirrored about the normal.
    #[inline]
    fn cos_alpha(wo: Vec3, wi: Vec3) -> f32 {
        wi.z * wo.z - wi.x * wo.x - wi.y * wo.y
    }
}

impl Bxdf for PhongBxdf {
    #[inline(never)]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let n = self.exponent;
        let cos_alpha = Self::cos_alpha(wo, wi);
        let mut f = self.diffuse_reflectance * FRAC_1_PI;
        if cos_alpha > 0.0 {
            f += self.specular_reflectance * ((n + 2.0) / (2.0 * PI) * cos_alpha.powf(n));
        }
        f * wi.z
    }

    #[inline(never)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let n = self.exponent;
        let cos_alpha = Self::cos_alpha(wo, wi);
        let specular = if cos_alpha > 0.0 {
            cos_alpha.powf(n) * (n + 1.0) / (2.0 * PI)
        } else {
            0.0
        };
        let w = self.specular_sampling_weight;
        w * specular + (1.0 - w) * wi.z * FRAC_1_PI
    }

    #[inline(never)]
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, _: TransportMode) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if uc < self.specular_sampling_weight {
            // cos^n around the mirror direction: cos alpha = u^(1 / (n + 1)).
            let n = self.exponent;
            let sin_alpha = (1.0 - u.y.powf(2.0 / (n + 1.0))).max(0.0).sqrt();
            let cos_alpha = u.y.powf(1.0 / (n + 1.0));
            let (sin_phi, cos_phi) = (2.0 * PI * u.x).sin_cos();
            let local = Vec3::new(sin_alpha * cos_phi, sin_alpha * sin_phi, cos_alpha);
            to_world(local, Vec3::new(-wo.x, -wo.y, wo.z))
        } else {
            cosine_hemisphere(u)
        };
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(LocalSample {
            wi,
            weight: self.eval(wo, wi) / pdf,
            pdf,
            delta: false,
        })
    }

    /// Mitsuba's Beckmann-equivalent roughness of the lobe, sqrt(2 / (n + 2)).
    #[inline]
    fn roughness(&self) -> f32 {
        (2.0 / (self.exponent + 2.0)).sqrt()
    }
}

/// A scalar that may vary over the surface (Mitsuba's float textures): a number, `[r, g, b]`
/// or a texture table (read as the mean of its channels where it is used); `default` when
/// absent. Negative numbers are refused.
pub(super) fn scalar_texture(
    m: &Properties<'_>,
    key: &str,
    default: f32,
    resources: &mut dyn Resources,
) -> Result<Texture> {
    if let Some(node) = m.node(key)
        && matches!(node.value, Value::Float(_) | Value::Int(_))
    {
        let x = m.f32(key, default)?;
        if x < 0.0 {
            return Err(m.error(key, format!("must be >= 0, found {x}")));
        }
        return Ok(Texture::Constant(Rgb::splat(x)));
    }
    resources.texture(m, key, Rgb::splat(default))
}

/// The mean of a colour's channels (Mitsuba's `Spectrum::average`), a grey exactly its value.
#[inline(always)]
pub(super) fn channel_mean(c: Rgb) -> f32 {
    if c.x == c.y && c.y == c.z {
        c.x
    } else {
        (c.x + c.y + c.z) / 3.0
    }
}

/// Mitsuba 0.6's `ensureEnergyConservation` of colours that add up (`keys`, their
/// `textures`): when their per-channel maxima sum above 1 in a channel, the factor
/// 0.99 / that sum that scales them all (with a warning); otherwise, or when the bag's
/// `ensure_energy_conservation` is false, 1.
pub(super) fn energy_conserving_scale(
    m: &Properties<'_>,
    keys: &[&str],
    textures: &[&Texture],
    resources: &mut dyn Resources,
) -> Result<f32> {
    if !m.bool("ensure_energy_conservation", true)? {
        return Ok(1.0);
    }
    let sum: Rgb = textures.iter().map(|t| t.max()).sum();
    let max = sum.max_element();
    if max <= 1.0 {
        return Ok(1.0);
    }
    let scale = 0.99 / max;
    let names = keys
        .iter()
        .map(|k| format!("`{k}`"))
        .collect::<Vec<_>>()
        .join(" and ");
    resources.warn(
        m,
        keys[0],
        format!(
            "{names} reach {max} in a channel, above 1: scaled by {scale} as Mitsuba does \
             (`ensure_energy_conservation = false` keeps them)"
        ),
    );
    Ok(scale)
}

/// The probability of sampling a specular part: its mean luminance's share (Mitsuba's
/// `m_specularSamplingWeight`); 0 when both are black.
pub(super) fn specular_sampling_weight(specular: &Texture, diffuse: &Texture) -> f32 {
    let (s, d) = (luminance(specular.mean()), luminance(diffuse.mean()));
    if s + d > 0.0 { s / (s + d) } else { 0.0 }
}

pub const FACTORY: Factory<PhongMaterial> = Factory {
    name: "phong",
    description: "the modified Phong model: a Lambertian part and a cos^n lobe around the mirror direction",
    create: |m, _, resources| {
        let exponent = scalar_texture(m, "exponent", 30.0, resources)?;
        let specular_reflectance =
            resources.texture(m, "specular_reflectance", Rgb::splat(0.2))?;
        let diffuse_reflectance = resources.texture(m, "diffuse_reflectance", Rgb::splat(0.5))?;
        let scale = energy_conserving_scale(
            m,
            &["specular_reflectance", "diffuse_reflectance"],
            &[&specular_reflectance, &diffuse_reflectance],
            resources,
        )?;
        Ok(Box::new(PhongMaterial {
            specular_sampling_weight: specular_sampling_weight(
                &specular_reflectance,
                &diffuse_reflectance,
            ),
            diffuse_reflectance,
            specular_reflectance,
            exponent,
            scale,
            twosided: m.bool("twosided", true)?,
        }))
    },
};
