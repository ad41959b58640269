//! Materials: what a scene says a surface is made of. At a surface point a material gives
//! its BSDF ([`Material::bsdf`], see [`crate::bsdf`]); mirror surfaces are two-sided, diffuse
//! ones unless made one-sided (Mitsuba's BSDFs are one-sided: black seen from behind).

use crate::Rgb;
use crate::bsdf::{Bsdf, Frame, Lobe};
use crate::geometry::SurfacePoint;
use crate::glossy::{Plastic, RoughConductor, RoughDielectric, RoughPlastic};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

pub use crate::scattering::{
    TransportMode, fresnel_conductor, fresnel_dielectric, reflect, refract,
};

/// A material. Colours marked "texture" are [`Texture`]s (a constant, an image or a
/// checkerboard over the surface's uv); the lobe structs hold the rest, their textured fields
/// being set at each surface point.
#[derive(Clone, Debug)]
pub enum Material {
    /// Lambertian: f = reflectance / pi (texture); if not `twosided`, only on the side the
    /// normal points to (black from behind, as a Mitsuba BSDF not wrapped in `twosided`).
    Diffuse {
        reflectance: Texture,
        twosided: bool,
    },
    /// Perfect specular reflection scaled by `reflectance` (texture).
    Mirror { reflectance: Texture },
    /// A smooth conductor (Mitsuba's `conductor`): specular reflection with the Fresnel
    /// reflectance of the complex index of refraction eta + i k (per channel, relative to the
    /// outside), scaled by `specular_reflectance` (texture).
    Conductor {
        eta: Rgb,
        k: Rgb,
        specular_reflectance: Texture,
    },
    /// Smooth dielectric interface with Fresnel reflection and refraction; `ior` is the index
    /// of the side the normal points away from (inside), relative to the outside.
    Dielectric { ior: f32 },
    /// A thin sheet of glass (Mitsuba's `thindielectric`): light is reflected or passes
    /// straight through, with the Fresnel reflectance of the sheet's two faces and their
    /// interreflections, R' = 2R / (1 + R). It bounds no volume.
    ThinDielectric { ior: f32 },
    /// Microfacet reflection off a conductor (Mitsuba's `roughconductor`).
    RoughConductor {
        lobe: RoughConductor,
        specular_reflectance: Texture,
        twosided: bool,
    },
    /// Microfacet reflection and refraction at a dielectric interface (Mitsuba's
    /// `roughdielectric`; two-sided by nature).
    RoughDielectric {
        lobe: RoughDielectric,
        specular_reflectance: Texture,
        specular_transmittance: Texture,
    },
    /// A diffuse base under a smooth dielectric coat (Mitsuba's `plastic`).
    Plastic {
        lobe: Plastic,
        diffuse_reflectance: Texture,
        specular_reflectance: Texture,
        twosided: bool,
    },
    /// A diffuse base under a rough dielectric coat (Mitsuba's `roughplastic`).
    RoughPlastic {
        lobe: RoughPlastic,
        diffuse_reflectance: Texture,
        specular_reflectance: Texture,
        twosided: bool,
    },
    /// An invisible boundary (of a medium): rays cross it without scattering.
    Null,
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
pub fn conductor(name: &str) -> Option<(Rgb, Rgb)> {
    CONDUCTORS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, eta, k)| (*eta, *k))
}

impl Material {
    /// True when the material scatters only in Dirac deltas (mirror, smooth glass).
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Material::Mirror { .. }
                | Material::Conductor { .. }
                | Material::Dielectric { .. }
                | Material::ThinDielectric { .. }
        )
    }

    pub fn is_null(&self) -> bool {
        matches!(self, Material::Null)
    }

    /// Whether the BSDF depends on the surface's texture coordinates or tangent: a texture
    /// that varies, or an anisotropic lobe.
    #[inline]
    pub fn needs_coordinates(&self) -> bool {
        let varies = |t: &Texture| !t.is_constant();
        match self {
            Material::Diffuse { reflectance, .. } | Material::Mirror { reflectance } => {
                varies(reflectance)
            }
            Material::Conductor {
                specular_reflectance,
                ..
            } => varies(specular_reflectance),
            Material::RoughConductor {
                lobe,
                specular_reflectance,
                ..
            } => !lobe.distribution.is_isotropic() || varies(specular_reflectance),
            Material::RoughDielectric {
                lobe,
                specular_reflectance,
                specular_transmittance,
            } => {
                !lobe.distribution.is_isotropic()
                    || varies(specular_reflectance)
                    || varies(specular_transmittance)
            }
            Material::Plastic {
                diffuse_reflectance,
                specular_reflectance,
                ..
            }
            | Material::RoughPlastic {
                diffuse_reflectance,
                specular_reflectance,
                ..
            } => varies(diffuse_reflectance) || varies(specular_reflectance),
            Material::Dielectric { .. } | Material::ThinDielectric { .. } | Material::Null => false,
        }
    }

    /// The BSDF at surface point `sp` (None for the null material, which does not scatter).
    #[inline]
    pub fn bsdf(&self, sp: &SurfacePoint) -> Option<Bsdf> {
        // Without a tangent (not needed, or none), any frame: isotropic lobes do not care.
        let frame = || {
            if sp.dpdu == Vec3::ZERO {
                Frame::from_normal(sp.ns)
            } else {
                Frame::from_normal_tangent(sp.ns, sp.dpdu)
            }
        };
        self.bsdf_in(sp.uv, sp.ng, frame)
    }

    /// The BSDF at a point of a flat surface whose material needs no texture coordinates and
    /// no tangent ([`Material::needs_coordinates`] false): the shading normal is the
    /// geometric one `ng`, and the frame any frame around it, as [`Material::bsdf`] makes it
    /// for such a point. (The scene's hit queries call this where they can: the frame is then
    /// built without testing a tangent that is known to be zero.)
    #[inline]
    pub fn flat_bsdf(&self, ng: Vec3) -> Option<Bsdf> {
        self.bsdf_in(Vec2::ZERO, ng, || Frame::from_normal(ng))
    }

    /// The BSDF with its textures looked up at `uv`, the geometric normal `ng`, and the
    /// shading frame `frame` makes (not made for the null material).
    #[inline(always)]
    fn bsdf_in(&self, uv: Vec2, ng: Vec3, frame: impl FnOnce() -> Frame) -> Option<Bsdf> {
        // Constant colours without the call: `Texture::eval` is too large to be inlined, and
        // most colours of most scenes are constants (a call per colour per hit cost about 1%
        // of the path tracer's instructions on the Cornell box).
        let at = |t: &Texture| match t {
            Texture::Constant(c) => *c,
            _ => t.eval(uv),
        };
        let lobe = match self {
            Material::Diffuse {
                reflectance,
                twosided,
            } => Lobe::Diffuse {
                reflectance: at(reflectance),
                twosided: *twosided,
            },
            Material::Mirror { reflectance } => Lobe::Mirror {
                reflectance: at(reflectance),
            },
            Material::Conductor {
                eta,
                k,
                specular_reflectance,
            } => Lobe::Conductor {
                eta: *eta,
                k: *k,
                specular_reflectance: at(specular_reflectance),
            },
            Material::Dielectric { ior } => Lobe::Dielectric { ior: *ior },
            Material::ThinDielectric { ior } => Lobe::ThinDielectric { ior: *ior },
            Material::RoughConductor {
                lobe,
                specular_reflectance,
                ..
            } => Lobe::RoughConductor(RoughConductor {
                specular_reflectance: at(specular_reflectance),
                ..*lobe
            }),
            Material::RoughDielectric {
                lobe,
                specular_reflectance,
                specular_transmittance,
            } => Lobe::RoughDielectric(RoughDielectric {
                specular_reflectance: at(specular_reflectance),
                specular_transmittance: at(specular_transmittance),
                ..*lobe
            }),
            Material::Plastic {
                lobe,
                diffuse_reflectance,
                specular_reflectance,
                ..
            } => Lobe::Plastic(Plastic {
                diffuse_reflectance: at(diffuse_reflectance),
                specular_reflectance: at(specular_reflectance),
                ..*lobe
            }),
            Material::RoughPlastic {
                lobe,
                diffuse_reflectance,
                specular_reflectance,
                ..
            } => {
                let mut l = *lobe;
                l.diffuse_reflectance = at(diffuse_reflectance);
                l.specular_reflectance = at(specular_reflectance);
                Lobe::RoughPlastic(l)
            }
            Material::Null => return None,
        };
        let twosided = match *self {
            Material::RoughConductor { twosided, .. }
            | Material::Plastic { twosided, .. }
            | Material::RoughPlastic { twosided, .. } => twosided,
            _ => false,
        };
        Some(Bsdf {
            lobe,
            frame: frame(),
            ng,
            twosided,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_normal_incidence() {
        let f = fresnel_dielectric(1.0, 1.5);
        assert!((f - 0.04).abs() < 1e-6);
        assert_eq!(fresnel_dielectric(0.1, 1.0 / 1.5), 1.0);
    }

    #[test]
    fn fresnel_conductor_against_its_limits() {
        // Normal incidence: ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2).
        for (n, k) in [(0.143f32, 3.983f32), (1.5, 0.0), (2.5, 1.0), (0.2, 0.0)] {
            let expected = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
            assert!(
                (fresnel_conductor(1.0, n, k) - expected).abs() < 1e-6,
                "{n} {k}"
            );
        }
        // No absorption: the dielectric's reflectance (below the critical angle, eta > 1).
        for cos in [1.0f32, 0.8, 0.5, 0.2, 0.05] {
            let (c, d) = (
                fresnel_conductor(cos, 1.5, 0.0),
                fresnel_dielectric(cos, 1.5),
            );
            assert!((c - d).abs() < 1e-6, "{cos}: {c} vs {d}");
        }
        // Grazing incidence reflects everything; reflectance stays in [0, 1].
        assert!((fresnel_conductor(0.0, 0.2, 3.9) - 1.0).abs() < 1e-6);
        for (_, eta, k) in CONDUCTORS {
            for i in 0..=20 {
                let f = fresnel_conductor(i as f32 / 20.0, eta.x, k.x);
                assert!((0.0..=1.0).contains(&f), "{f}");
            }
        }
        let (au_eta, au_k) = conductor("Au").unwrap();
        assert!((au_eta.x - 0.143).abs() < 1e-3 && (au_k.x - 3.983).abs() < 1e-3);
        assert_eq!(conductor("gold"), None);
    }

    #[test]
    fn refraction_obeys_snell() {
        let n = Vec3::Z;
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wi = refract(wo, n, 1.5).unwrap();
        let sin_i = 0.6;
        let sin_t = (1.0 - wi.z * wi.z).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
        assert!(wi.z < 0.0 && wi.x < 0.0);
    }
}
