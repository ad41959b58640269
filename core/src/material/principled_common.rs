//! What `principled` and `principledthin` share (Mitsuba 3's `principledhelpers.h`): their
//! numeric parameters that may be textures, the Schlick Fresnel terms, the GGX roughness of
//! Disney's `roughness` and `anisotropic`, the test that a microfacet is seen from the side a
//! direction lies on, and the diffuse, retro-reflection, fake-subsurface and sheen terms of
//! Burley's 2012 and 2015 notes, all as Mitsuba 3 computes them.

use crate::Rgb;
use crate::error::Result;
use crate::microfacet::{Microfacet, MicrofacetKind};
use crate::props::Properties;
use crate::registry::Resources;
use crate::texture::TextureEvalContext;
use crate::texture::{Texture, luminance};
use crate::value::Value;
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// A number that may vary over the surface: a constant, or a texture read as its luminance
/// (Mitsuba's `eval_1` of an RGB bitmap).
#[derive(Clone, Debug)]
pub enum Scalar {
    Constant(f32),
    Texture(Texture),
}

impl Scalar {
    /// The value at surface coordinates `uv`.
    #[inline(always)]
    pub fn at(&self, ctx: TextureEvalContext) -> f32 {
        match self {
            Scalar::Constant(x) => *x,
            Scalar::Texture(t) => luminance(t.eval(ctx)),
        }
    }

    pub fn is_constant(&self) -> bool {
        matches!(self, Scalar::Constant(_))
    }

    /// Mitsuba's `get_flag`: whether the parameter was given other than as the number 0 (a
    /// texture counts as given). `principled` adjusts its index of refraction by it.
    pub fn given(&self) -> bool {
        !matches!(self, Scalar::Constant(x) if *x == 0.0)
    }
}

/// The numeric parameter `key` (`default` when absent): a number within `[lo, hi]`, or a
/// texture table whose values' luminance stays below `hi`.
pub fn read_scalar(
    m: &Properties<'_>,
    key: &str,
    default: f32,
    (lo, hi): (f32, f32),
    resources: &mut dyn Resources,
) -> Result<Scalar> {
    let range = || {
        if hi.is_finite() {
            format!("[{lo}, {hi}]")
        } else {
            format!("at least {lo}")
        }
    };
    if m.node(key)
        .is_some_and(|n| matches!(n.value, Value::Table(_)))
    {
        let t = resources.texture(m, key, Rgb::splat(default))?;
        // Each channel's bound bounds the luminance (its weights are positive).
        let max = luminance(t.max());
        if max > hi * (1.0 + 1e-6) {
            return Err(m.error(
                key,
                format!(
                    "the texture reaches {max} (luminance); expected values in {}",
                    range()
                ),
            ));
        }
        return Ok(Scalar::Texture(t));
    }
    let x = m.f32(key, default)?;
    if !(lo..=hi).contains(&x) {
        return Err(m.error(key, format!("expected a number in {}, found {x}", range())));
    }
    Ok(Scalar::Constant(x))
}

/// A sampling rate (`principled`'s `*_sampling_rate`): a non-negative number, 1 by default.
pub fn read_rate(m: &Properties<'_>, key: &str) -> Result<f32> {
    let x = m.f32(key, 1.0)?;
    if x < 0.0 {
        return Err(m.error(key, format!("expected a non-negative number, found {x}")));
    }
    Ok(x)
}

/// Schlick's weight (1 - cos)^5, cos clamped to [0, 1].
#[inline]
pub fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// The reflectance at normal incidence of a dielectric interface of relative index `eta`.
#[inline]
pub fn schlick_r0(eta: f32) -> f32 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

/// The weight of Schlick's approximation F = R0 + (1 - R0) w at the microfacet cosine
/// `cos_i` (negative: from inside) of an interface of relative index `eta`: w of the
/// incident cosine when the light goes into the denser side, of the transmitted one when it
/// leaves it (1 on total internal reflection).
#[inline]
pub fn schlick_fresnel_weight(cos_i: f32, eta: f32) -> f32 {
    let (eta_it, eta_ti) = if cos_i >= 0.0 {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    if eta_it > 1.0 {
        schlick_weight(cos_i.abs())
    } else {
        let cos_t2 = 1.0 - (1.0 - cos_i * cos_i) * eta_ti * eta_ti;
        schlick_weight(cos_t2.max(0.0).sqrt())
    }
}

/// Schlick's Fresnel term for the reflectance `r0` at normal incidence (per channel).
#[inline]
pub fn schlick_fresnel(r0: Rgb, cos_i: f32, eta: f32) -> Rgb {
    let w = schlick_fresnel_weight(cos_i, eta);
    w * (Rgb::ONE - r0) + r0
}

/// `base_color` over its luminance (white where the luminance is zero): the hue that the
/// `*_tint` parameters blend towards.
#[inline]
pub fn tint(base_color: Rgb) -> Rgb {
    let lum = luminance(base_color);
    if lum > 0.0 {
        base_color / lum
    } else {
        Rgb::ONE
    }
}

pub(crate) use crate::glossy::{fresnel, refract};

/// The GGX distribution of Disney's `roughness` and `anisotropic` (Burley 2012):
/// alpha = roughness^2, stretched by sqrt(1 - 0.9 anisotropic) along x and shrunk along y,
/// at least 0.001.
#[inline]
pub fn distribution(roughness: f32, anisotropic: f32) -> Microfacet {
    let r2 = roughness * roughness;
    let aspect = (1.0 - 0.9 * anisotropic).sqrt();
    Microfacet::new(
        MicrofacetKind::Ggx,
        (r2 / aspect).max(0.001),
        (r2 * aspect).max(0.001),
    )
}

/// Whether microfacet `m` is seen from the side of the macrosurface that `v` (the viewer,
/// whose cosine is `cos_v`) lies on, and from the side `w` lies on: the same side for a
/// reflection, the other for a transmission (Mitsuba's `mac_mic_compatibility`).
#[inline]
pub fn compatible(m: Vec3, v: Vec3, w: Vec3, cos_v: f32, reflection: bool) -> bool {
    let m = if cos_v < 0.0 { -m } else { m };
    v.dot(m) > 0.0
        && if reflection {
            w.dot(m) > 0.0
        } else {
            w.dot(m) < 0.0
        }
}

/// Burley's diffuse term with retro-reflection, blended by `flatness` with the
/// Hanrahan-Krueger fake subsurface, for the absolute cosines of the two directions and
/// cos theta_d, the cosine between the half vector and either direction. Times
/// base_color / pi, this is the diffuse BRDF.
#[inline]
pub fn diffuse(cos_o: f32, cos_i: f32, cos_d: f32, roughness: f32, flatness: f32) -> f32 {
    let (fo, fi) = (schlick_weight(cos_o), schlick_weight(cos_i));
    let f_diff = (1.0 - 0.5 * fi) * (1.0 - 0.5 * fo);
    let rr = 2.0 * roughness * cos_d * cos_d;
    let f_retro = rr * (fo + fi + fo * fi * (rr - 1.0));
    if flatness > 0.0 {
        // Fss90 "flattens" the retro-reflection by the roughness.
        let fss90 = rr / 2.0;
        let fss = (1.0 + (fss90 - 1.0) * fo) * (1.0 + (fss90 - 1.0) * fi);
        let f_ss = 1.25 * (fss * (1.0 / (cos_o + cos_i) - 0.5) + 0.5);
        lerp(f_diff + f_retro, f_ss, flatness)
    } else {
        f_diff + f_retro
    }
}

/// The sheen's colour: white blended towards the base colour's hue by `sheen_tint`.
#[inline]
pub fn sheen_color(base_color: Rgb, sheen_tint: f32) -> Rgb {
    if sheen_tint > 0.0 {
        Rgb::ONE + (tint(base_color) - Rgb::ONE) * sheen_tint
    } else {
        Rgb::ONE
    }
}

/// a + (b - a) t.
#[inline]
pub fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// The clearcoat's microfacet distribution, Burley's GTR1 (Berry's), isotropic.
#[derive(Clone, Copy)]
pub struct Gtr1 {
    pub alpha: f32,
}

impl Gtr1 {
    pub fn d(&self, m: Vec3) -> f32 {
        let a2 = self.alpha * self.alpha;
        let d = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * m.z * m.z));
        if d * m.z > 1e-20 { d } else { 0.0 }
    }

    /// D(m) cos theta_m, the density of [`Gtr1::sample`].
    pub fn pdf(&self, m: Vec3) -> f32 {
        if m.z < 0.0 { 0.0 } else { m.z * self.d(m) }
    }

    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (sin_phi, cos_phi) = (TAU * u.x).sin_cos();
        let a2 = self.alpha * self.alpha;
        let cos2 = (1.0 - a2.powf(1.0 - u.y)) / (1.0 - a2);
        let sin = (1.0 - cos2).max(0.0).sqrt();
        Vec3::new(cos_phi * sin, sin_phi * sin, cos2.max(0.0).sqrt())
    }
}

/// Smith's GGX masking of the clearcoat (roughness 0.25, isotropic), as Mitsuba writes it.
pub fn clearcoat_g1(v: Vec3, m: Vec3) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    if v.z == 1.0 {
        return 1.0;
    }
    let cos2 = v.z * v.z;
    let tan2 = (1.0 - cos2) / cos2;
    2.0 / (1.0 + (1.0 + 0.0625 * tan2).sqrt())
}
