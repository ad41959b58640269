//! `conductor`: a smooth metal, specular reflection with the Fresnel reflectance of its
//! complex index of refraction (Mitsuba's `conductor`), and the named conductors' indices.
//!
//! | Parameter              | Type          | Meaning                                  | Default        |
//! |------------------------|---------------|------------------------------------------|----------------|
//! | `material`             | string        | a named conductor (`Au`, `Ag`, ...; `none`: a perfect mirror) | a perfect mirror |
//! | `eta`, `k`             | RGB           | the complex index eta + i k, relative to the outside (both, or `material`) | |
//! | `specular_reflectance` | RGB / texture | scales the reflection                    | `1`            |

use super::SurfaceMaterial;
use super::mirror::{delta_sample, reflect_local};
use crate::Rgb;
use crate::error::Result;
use crate::props::Properties;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode, fresnel_conductor};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

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
    fn bxdf(&self, uv: Vec2) -> ConductorBxdf {
        ConductorBxdf {
            eta: self.eta,
            k: self.k,
            specular_reflectance: self.specular_reflectance.at(uv),
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

/// Mitsuba 3's named conductors: the RGB complex indices of refraction (eta, k) its
/// `scalar_rgb` variant uses for them (its spectral data reduced to RGB, read from mitsuba
/// 3.9.1 with `mi.traverse`; negative values, from out-of-gamut spectra, clamped to 0).
pub const CONDUCTORS: &[(&str, Rgb, Rgb)] = &[
    (
        "a-C",
        Rgb::new(2.94405, 2.22714, 1.96816),
        Rgb::new(0.887465, 0.799299, 0.81529),
    ),
    (
        "Ag",
        Rgb::new(0.155276, 0.116728, 0.138388),
        Rgb::new(4.82835, 3.12222, 2.1469),
    ),
    (
        "Al",
        Rgb::new(1.6575, 0.880405, 0.521244),
        Rgb::new(9.22381, 6.2695, 4.837),
    ),
    (
        "AlAs",
        Rgb::new(3.6053, 3.23294, 2.21632),
        Rgb::new(0.000679437, 0.0, 0.00751271),
    ),
    (
        "AlSb",
        Rgb::new(0.0, 4.13937, 4.66925),
        Rgb::new(0.0, 0.0940091, 1.30057),
    ),
    (
        "Au",
        Rgb::new(0.143036, 0.375307, 1.44205),
        Rgb::new(3.983, 2.38556, 1.60336),
    ),
    (
        "Be",
        Rgb::new(4.18501, 3.18503, 2.78406),
        Rgb::new(3.83547, 3.01012, 2.86899),
    ),
    (
        "Cr",
        Rgb::new(4.36967, 2.91651, 1.6549),
        Rgb::new(5.20655, 4.23131, 3.7547),
    ),
    (
        "CsI",
        Rgb::new(2.1449, 1.70232, 1.66243),
        Rgb::new(0.0, 0.0, 0.0),
    ),
    (
        "Cu",
        Rgb::new(0.201005, 0.92375, 1.10222),
        Rgb::new(3.91326, 2.45305, 2.14209),
    ),
    (
        "Cu2O",
        Rgb::new(3.55177, 2.94987, 2.75188),
        Rgb::new(0.114207, 0.193897, 0.606134),
    ),
    (
        "CuO",
        Rgb::new(3.24754, 2.44781, 2.21022),
        Rgb::new(0.52109, 0.570031, 0.722179),
    ),
    (
        "d-C",
        Rgb::new(2.70872, 2.31883, 2.2289),
        Rgb::new(0.0, 0.0, 0.0),
    ),
    (
        "Hg",
        Rgb::new(2.39894, 1.44003, 0.90957),
        Rgb::new(6.32759, 4.37192, 3.42176),
    ),
    (
        "HgTe",
        Rgb::new(4.77904, 3.2312, 2.6599),
        Rgb::new(1.63161, 1.58081, 1.72929),
    ),
    (
        "Ir",
        Rgb::new(3.0863, 2.08219, 1.61791),
        Rgb::new(5.59215, 4.06709, 3.26731),
    ),
    (
        "K",
        Rgb::new(0.0640432, 0.0464098, 0.0381849),
        Rgb::new(2.1042, 1.34894, 0.913126),
    ),
    (
        "Li",
        Rgb::new(0.265791, 0.195618, 0.220949),
        Rgb::new(3.54015, 2.31112, 1.66861),
    ),
    (
        "MgO",
        Rgb::new(2.08958, 1.65072, 1.59488),
        Rgb::new(4.3327e-12, 0.0, 2.49865e-11),
    ),
    (
        "Mo",
        Rgb::new(4.48397, 3.52513, 2.77631),
        Rgb::new(4.11144, 3.42083, 3.15061),
    ),
    (
        "Na_palik",
        Rgb::new(0.0602694, 0.0561409, 0.0619884),
        Rgb::new(3.17927, 2.11249, 1.57904),
    ),
    (
        "Nb",
        Rgb::new(3.42007, 2.79009, 2.39563),
        Rgb::new(3.44139, 2.73767, 2.57975),
    ),
    (
        "Ni_palik",
        Rgb::new(2.3673, 1.66337, 1.46708),
        Rgb::new(4.49881, 3.05015, 2.34544),
    ),
    (
        "Rh",
        Rgb::new(2.58579, 1.86022, 1.55426),
        Rgb::new(6.78226, 4.70299, 3.97607),
    ),
    (
        "Se",
        Rgb::new(4.05831, 2.84294, 2.82085),
        Rgb::new(0.75405, 0.638444, 0.521808),
    ),
    (
        "SiC",
        Rgb::new(3.17234, 2.52597, 2.47937),
        Rgb::new(7.53766e-07, 0.0, 1.01925e-05),
    ),
    (
        "SnTe",
        Rgb::new(4.52425, 1.98164, 1.28159),
        Rgb::new(0.0, 0.0, 0.0),
    ),
    (
        "Ta",
        Rgb::new(2.06272, 2.39294, 2.62793),
        Rgb::new(2.40836, 1.74149, 1.94703),
    ),
    (
        "Te",
        Rgb::new(7.39023, 4.4821, 2.63711),
        Rgb::new(3.25602, 3.52706, 3.29205),
    ),
    (
        "ThF4",
        Rgb::new(1.83071, 1.44223, 1.38765),
        Rgb::new(0.0, 0.0, 0.0),
    ),
    (
        "TiC",
        Rgb::new(3.70053, 2.83742, 2.58229),
        Rgb::new(3.26564, 2.35159, 2.17279),
    ),
    (
        "TiN",
        Rgb::new(1.64845, 1.15052, 1.37982),
        Rgb::new(3.36833, 1.9435, 1.10207),
    ),
    (
        "TiO2",
        Rgb::new(3.45661, 2.80174, 2.90517),
        Rgb::new(0.000105265, 0.0, 0.000652887),
    ),
    (
        "VC",
        Rgb::new(3.65757, 2.75274, 2.53267),
        Rgb::new(3.0683, 2.19869, 1.96319),
    ),
    (
        "V_palik",
        Rgb::new(4.27758, 3.51295, 2.76107),
        Rgb::new(3.4913, 2.88945, 3.11152),
    ),
    (
        "VN",
        Rgb::new(2.8656, 2.11919, 1.94009),
        Rgb::new(3.03224, 2.05612, 1.61631),
    ),
    (
        "W",
        Rgb::new(4.37082, 3.30025, 2.99841),
        Rgb::new(3.50064, 2.60487, 2.27323),
    ),
];

/// The complex index of refraction of a named conductor (Mitsuba's names: `Au`, `Ag`...).
pub fn conductor_ior(name: &str) -> Option<(Rgb, Rgb)> {
    CONDUCTORS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, eta, k)| (*eta, *k))
}
