//! `conductor`: a smooth metal, specular reflection with the Fresnel reflectance of its
//! complex index of refraction (Mitsuba's `conductor`), and the named conductors' indices.
//!
//! | Parameter              | Type          | Meaning                                  | Default        |
//! |------------------------|---------------|------------------------------------------|----------------|
//! | `material`             | string        | a named conductor (`Au`, `Ag`, ...; `none`: a perfect mirror) | a perfect mirror |
//! | `eta`, `k`             | RGB           | the complex index eta + i k, relative to the outside (both, or `material`) | |
//! | `specular_reflectance` | RGB / texture | scales the reflection                    | `1`            |

use crate::texture::TextureEvalContext;
use super::SurfaceMaterial;
use super::mirror::{delta_sample, reflect_local};
use crate::Rgb;
use crate::error::Result;
use crate::props::Properties;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode, fresnel_conductor};
use crate::spectrum::{self, Quantity, Spectrum};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::sync::LazyLock;

#[derive(Clone, Debug)]
pub struct ConductorMaterial {
    /// The complex index of refraction eta + i k (per channel, relative to the outside);
    /// both zero: a perfect mirror (F = 1).
    pub eta: Rgb,
    pub k: Rgb,
    pub specular_reflectance: Texture,
}

/// A delta reflection weighted by the conductor's Fresnel reflectance, from either side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConductorBxdf {
    pub eta: Rgb,
    pub k: Rgb,
    pub specular_reflectance: Rgb,
}

impl SurfaceMaterial for ConductorMaterial {
    type Bxdf = ConductorBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> ConductorBxdf {
        ConductorBxdf {
            eta: self.eta,
            k: self.k,
            specular_reflectance: self.specular_reflectance.at(ctx),
        }
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.specular_reflectance.is_constant()
    }
}

impl Bxdf for ConductorBxdf {
    const DELTA: bool = true;

    fn eval(&self, _: Vec3, _: Vec3) -> Rgb {
        Rgb::ZERO
    }

    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        0.0
    }

    #[inline]
    fn sample(&self, wo: Vec3, _: Vec2, _: f32, _: TransportMode) -> Option<LocalSample> {
        let c = wo.z.abs();
        let f = Rgb::new(
            fresnel_conductor(c, self.eta.x, self.k.x),
            fresnel_conductor(c, self.eta.y, self.k.y),
            fresnel_conductor(c, self.eta.z, self.k.z),
        );
        delta_sample(reflect_local(wo), self.specular_reflectance * f, 1.0)
    }

    fn roughness(&self) -> f32 {
        0.0
    }
}

pub const FACTORY: Factory<ConductorMaterial> = Factory {
    name: "conductor",
    description: "a smooth metal: Fresnel-weighted specular reflection",
    create: |m, _, resources| {
        let specular_reflectance = resources.texture(m, "specular_reflectance", Rgb::ONE)?;
        // No named material and no eta, k: Mitsuba's default, a perfect mirror.
        let (eta, k) = read_conductor_ior(m)?.unwrap_or((Rgb::ZERO, Rgb::ZERO));
        Ok(Box::new(ConductorMaterial {
            eta,
            k,
            specular_reflectance,
        }))
    },
};

/// A conductor's complex index of refraction: a named `material` (Mitsuba's names; `none`: a
/// perfect mirror) or `eta` and `k`. None: a perfect mirror.
pub fn read_conductor_ior(m: &Properties<'_>) -> Result<Option<(Rgb, Rgb)>> {
    let named = m.string_opt("material")?;
    let (eta, k) = (m.rgb_opt("eta")?, m.rgb_opt("k")?);
    match (named, eta, k) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => Err(m.error(
            "material",
            "give either a named `material` or `eta` and `k`, not both",
        )),
        (None, Some(eta), Some(k)) => Ok(Some((eta, k))),
        (None, Some(_), None) | (None, None, Some(_)) => {
            let missing = if m.has("eta") { "k" } else { "eta" };
            Err(m.error(
                missing,
                "missing: a conductor's index of refraction needs both eta and k",
            ))
        }
        (None, None, None) | (Some("none"), None, None) => Ok(None),
        (Some(name), None, None) => {
            let found = conductor_ior(name).ok_or_else(|| {
                let names: Vec<&str> = CONDUCTORS.iter().map(|(n, _, _)| *n).collect();
                m.error(
                    "material",
                    format!(
                        "unknown conductor `{name}`; expected none or one of: {}",
                        names.join(", ")
                    ),
                )
            })?;
            Ok(Some(found))
        }
    }
}

/// Mitsuba's named conductors with the RGB complex indices of refraction (eta, k) Mitsuba 3's
/// RGB variants give them: its measured spectra (`core/data/spectra/ior/`) reduced as its
/// `ior_from_file` reduces them ([`Quantity::Emission`]: not weighted by an illuminant,
/// negative components clamped to 0). Iterates as a slice of `(name, eta, k)`.
pub const CONDUCTORS: Conductors = Conductors;

/// The table of [`CONDUCTORS`], computed from the spectra when first used.
#[derive(Clone, Copy, Debug)]
pub struct Conductors;

static CONDUCTOR_TABLE: LazyLock<Vec<(&'static str, Rgb, Rgb)>> = LazyLock::new(|| {
    spectrum::conductor_names()
        .map(|name| {
            let (eta, k) = spectrum::conductor(name).expect("a conductor of the list");
            let rgb = |s: Spectrum| s.to_srgb(Quantity::Emission).as_vec3();
            (name, rgb(eta), rgb(k))
        })
        .collect()
});

impl Conductors {
    pub fn iter(self) -> std::slice::Iter<'static, (&'static str, Rgb, Rgb)> {
        CONDUCTOR_TABLE.iter()
    }
}

impl IntoIterator for Conductors {
    type Item = &'static (&'static str, Rgb, Rgb);
    type IntoIter = std::slice::Iter<'static, (&'static str, Rgb, Rgb)>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

/// The complex index of refraction of a named conductor (Mitsuba's names: `Au`, `Ag`...).
pub fn conductor_ior(name: &str) -> Option<(Rgb, Rgb)> {
    CONDUCTORS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, eta, k)| (*eta, *k))
}
