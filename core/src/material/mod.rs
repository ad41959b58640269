//! Materials: what a scene says a surface is made of, one file per kind, each listed on one
//! line of the `materials!` invocation below (Mitsuba 3's BSDF plugins, pbrt-v4's
//! `Material`s).
//!
//! A kind implements [`SurfaceMaterial`]: at a surface point it gives its lobe, a [`Bxdf`]
//! with the kind's textures looked up there. [`Material`] is the tagged union of the kinds
//! and [`Lobe`] that of their lobes, which the integrators call without a virtual call (BSDF
//! evaluation and sampling are in their innermost loops); [`Material::bsdf`] puts the lobe in
//! the point's shading frame ([`crate::bsdf::Bsdf`]). [`MATERIALS`] is the table of their
//! factories, which the scene reader looks a `[materials]` entry's `type` up in.
//!
//! Mirror surfaces are two-sided, diffuse ones unless made one-sided (Mitsuba's BSDFs are
//! one-sided: black seen from behind).

pub mod blend;
pub mod layered;
mod principled_common;

use crate::Rgb;
use crate::error::Result;
use crate::glossy;
use crate::microfacet::{Microfacet, MicrofacetKind};
use crate::props::Properties;
use crate::registry::{self, Factory, Resources};
use crate::scattering::Bxdf;
use crate::texture::TextureEvalContext;
use crate::texture::{Texture, scalar};
use glam::{Vec2, Vec3};

pub use crate::scattering::{
    LocalSample, TransportMode, fresnel_conductor, fresnel_dielectric, reflect, refract,
};
pub use blend::BlendMaterial;
pub use conductor::{CONDUCTORS, conductor_ior};

materials! {
    /// A material of any kind: one variant per file of this folder, each line naming the
    /// kind and its lobe, and two the macro adds: `Null`, the invisible boundary of a medium
    /// (rays cross it without scattering), and `Blend`, a weighted sum of materials of which
    /// each hit takes one (so that it has no lobe of its own).
    #[derive(Clone, Debug)]
    pub enum Material {
        Diffuse(diffuse::DiffuseMaterial, diffuse::DiffuseBxdf),
        Mirror(mirror::MirrorMaterial, mirror::MirrorBxdf),
        Conductor(conductor::ConductorMaterial, conductor::ConductorBxdf),
        Dielectric(dielectric::DielectricMaterial, dielectric::DielectricBxdf),
        ThinDielectric(thindielectric::ThinDielectricMaterial, thindielectric::ThinDielectricBxdf),
        RoughConductor(roughconductor::RoughConductorMaterial, glossy::RoughConductor),
        RoughDielectric(roughdielectric::RoughDielectricMaterial, glossy::RoughDielectric),
        Plastic(plastic::PlasticMaterial, glossy::Plastic),
        RoughPlastic(roughplastic::RoughPlasticMaterial, glossy::RoughPlastic),
        Phong(phong::PhongMaterial, phong::PhongBxdf),
        Ward(ward::WardMaterial, ward::WardBxdf),
        RoughDiffuse(roughdiffuse::RoughDiffuseMaterial, roughdiffuse::RoughDiffuseBxdf),
        Principled(principled::PrincipledMaterial, principled::PrincipledBxdf),
        PrincipledThin(principledthin::PrincipledThinMaterial, principledthin::PrincipledThinBxdf),
        DiffTrans(difftrans::DiffTransMaterial, difftrans::DiffTransBxdf),
        CoatedDiffuse(coateddiffuse::CoatedDiffuseMaterial, coateddiffuse::CoatedDiffuseBxdf),
        CoatedConductor(coatedconductor::CoatedConductorMaterial, coatedconductor::CoatedConductorBxdf),
        Coating(coating::CoatingMaterial, coating::CoatingBxdf),
        PPlastic(pplastic::PPlasticMaterial, pplastic::PPlasticBxdf),
        DisneySheen(disneysheen::DisneySheenMaterial, disneysheen::DisneySheenBxdf),
        DisneyClearcoat(disneyclearcoat::DisneyClearcoatMaterial, disneyclearcoat::DisneyClearcoatBxdf),
    }

    /// A material's scattering at one point, its textures looked up: one variant per kind of
    /// [`Material`] but `Null`, holding the kind's [`Bxdf`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub enum Lobe {}
}

/// One kind of material: what [`Material`] dispatches to.
pub trait SurfaceMaterial {
    /// Its scattering at a point.
    type Bxdf: Bxdf;

    /// The lobe at `ctx` (the surface's coordinates and mesh attribute), its textures looked
    /// up there ([`Texture::at`]).
    fn bxdf(&self, ctx: TextureEvalContext) -> Self::Bxdf;

    /// Whether the lobe depends on the surface's texture coordinates or tangent: a texture
    /// that varies, or an anisotropic lobe. Without them the BSDF is built in any frame
    /// around the geometric normal, without the surface's parametrisation.
    fn needs_coordinates(&self) -> bool;

    /// Whether its lobes are all Dirac deltas (see [`Bxdf::is_delta`]).
    fn is_delta(&self) -> bool {
        <Self::Bxdf as Bxdf>::DELTA
    }

    /// Whether the BSDF mirrors both directions to the upper side when seen from below
    /// (Mitsuba's `twosided` around a one-sided lobe). A lobe that handles both sides itself
    /// (the diffuse one, a dielectric) says false.
    fn twosided(&self) -> bool {
        false
    }

    /// Whether a closed shape of this material bounds a volume of its own (an interface
    /// into a medium, as glass is) when the scene does not say which media it separates.
    fn encloses_volume(&self) -> bool {
        false
    }
}

/// Declares the material kinds' files and the [`Material`] and [`Lobe`] unions over them, one
/// line per kind: `Variant(file::Kind, Lobe)` declares `pub mod file;` (which defines `Kind`,
/// implementing [`SurfaceMaterial`] with `type Bxdf = Lobe`, and
/// `pub const FACTORY: Factory<Kind>`), re-exports `Kind`, adds the factory to [`MATERIALS`],
/// `Variant(Kind)` to `Material` and `Variant(Lobe)` to `Lobe`, and the variant to the
/// unions' methods, which dispatch to the kind's [`SurfaceMaterial`] and its lobe's [`Bxdf`].
macro_rules! materials {
    (
        $(#[$attr:meta])*
        pub enum Material { $($variant:ident($module:ident::$kind:ident, $bxdf:ty)),* $(,)? }

        $(#[$lobe_attr:meta])*
        pub enum Lobe {}
    ) => {
        $(pub mod $module;)*
        $(pub use $module::$kind;)*

        $(#[$attr])*
        pub enum Material {
            $($variant($kind),)*
            Null,
            Blend(Box<blend::BlendMaterial>),
        }

        $(#[$lobe_attr])*
        pub enum Lobe {
            $($variant($bxdf),)*
        }

        /// The built-in materials: a `[materials]` entry's `type` is looked up here.
        pub const MATERIALS: &[Factory<Material>] = &[$(Factory {
            name: $module::FACTORY.name,
            description: $module::FACTORY.description,
            create: |bag, nested, resources| {
                let material = ($module::FACTORY.create)(bag, nested, resources)?;
                Ok(Box::new(Material::$variant(*material)))
            },
        },)* NULL, blend::FACTORY];

        $(impl From<$kind> for Material {
            fn from(material: $kind) -> Material {
                Material::$variant(material)
            }
        })*

        impl Material {
            /// True when the material scatters only in Dirac deltas (mirror, smooth glass).
            #[inline]
            pub fn is_delta(&self) -> bool {
                match self {
                    $(Material::$variant(m) => m.is_delta(),)*
                    Material::Null => false,
                    Material::Blend(b) => b.is_delta(),
                }
            }

            /// See [`SurfaceMaterial::needs_coordinates`].
            #[inline]
            pub fn needs_coordinates(&self) -> bool {
                match self {
                    $(Material::$variant(m) => m.needs_coordinates(),)*
                    Material::Null => false,
                    // The choice of a component hashes the hit's position and coordinates.
                    Material::Blend(_) => true,
                }
            }

            /// See [`SurfaceMaterial::encloses_volume`].
            pub fn encloses_volume(&self) -> bool {
                match self {
                    $(Material::$variant(m) => m.encloses_volume(),)*
                    Material::Null => false,
                    Material::Blend(b) => b.encloses_volume(),
                }
            }

            /// The lobe at point `p` with coordinates `uv` and whether the BSDF mirrors
            /// directions from below (see [`SurfaceMaterial`]); None for the null material,
            /// which does not scatter. Only a blend reads `p` (to choose its component).
            #[inline(always)]
            pub(crate) fn lobe_at(&self, p: Vec3, ctx: TextureEvalContext) -> Option<(Lobe, bool)> {
                match self {
                    $(Material::$variant(m) => Some((Lobe::$variant(m.bxdf(ctx)), m.twosided())),)*
                    Material::Null => None,
                    Material::Blend(b) => b.lobe_at(p, ctx),
                }
            }
        }

        impl Lobe {
            /// True when the lobe is a sum of Dirac deltas (see [`Bxdf::DELTA`]).
            #[inline]
            pub fn is_delta(&self) -> bool {
                match self {
                    $(Lobe::$variant(l) => Bxdf::is_delta(l),)*
                }
            }

            /// See [`Bxdf::eval`].
            #[inline]
            pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
                match self {
                    $(Lobe::$variant(l) => Bxdf::eval(l, wo, wi),)*
                }
            }

            /// See [`Bxdf::pdf`].
            #[inline]
            pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
                match self {
                    $(Lobe::$variant(l) => Bxdf::pdf(l, wo, wi),)*
                }
            }

            /// See [`Bxdf::sample`]; None for `wo` in the surface's plane.
            #[inline]
            pub fn sample(
                &self,
                wo: Vec3,
                u: Vec2,
                uc: f32,
                mode: TransportMode,
            ) -> Option<LocalSample> {
                if wo.z == 0.0 {
                    return None;
                }
                match self {
                    $(Lobe::$variant(l) => Bxdf::sample(l, wo, u, uc, mode),)*
                }
            }

            /// See [`Bxdf::roughness`].
            #[inline]
            pub fn roughness(&self) -> f32 {
                match self {
                    $(Lobe::$variant(l) => Bxdf::roughness(l),)*
                }
            }

            /// See [`Bxdf::transmits`].
            #[inline]
            pub fn transmits(&self) -> bool {
                match self {
                    $(Lobe::$variant(l) => Bxdf::transmits(l),)*
                }
            }

            /// See [`Bxdf::delta_probability`].
            #[inline]
            pub fn delta_probability(&self, wo: Vec3) -> f32 {
                match self {
                    $(Lobe::$variant(l) => Bxdf::delta_probability(l, wo),)*
                }
            }
        }
    };
}
use materials;

impl Material {
    pub fn is_null(&self) -> bool {
        matches!(self, Material::Null)
    }
}

/// `null`: an invisible boundary (of a medium).
const NULL: Factory<Material> = Factory {
    name: "null",
    description: "an invisible boundary of a medium: rays cross it without scattering",
    create: |_, _, _| Ok(Box::new(Material::Null)),
};

/// A material given as a table inside another's bag (a blend's component, a coating's
/// base), read by the factory its `type` names; `bag` is then owed to `nested`.
pub(crate) fn nested_material<'a>(
    bag: &Properties<'a>,
    nested: &mut Vec<Properties<'a>>,
    resources: &mut dyn Resources,
) -> Result<Material> {
    let ty = bag.string_opt("type")?.ok_or_else(|| {
        let types: Vec<&str> = registry::names(MATERIALS).collect();
        bag.error(
            "type",
            format!("missing; expected one of: {}", types.join(", ")),
        )
    })?;
    let factory = registry::find(MATERIALS, ty)
        .ok_or_else(|| bag.error("type", registry::unknown("material type", ty, MATERIALS)))?;
    Ok(*(factory.create)(bag, nested, resources)?)
}

/// A reflectance that may vary over the surface (`key`, `default` when absent); one above 1
/// is warned about, since the material then creates energy.
pub fn reflectance(
    m: &Properties<'_>,
    key: &str,
    default: Rgb,
    resources: &mut dyn Resources,
) -> Result<Texture> {
    let t = resources.texture(m, key, default)?;
    if t.max().max_element() > 1.0 {
        resources.warn(m, key, "is above 1: the material creates energy".into());
    }
    Ok(t)
}

/// A relative index of refraction `ior` (inside over outside), positive.
pub fn read_ior(m: &Properties<'_>, default: f32) -> Result<f32> {
    let ior = m.f32("ior", default)?;
    if ior <= 0.0 || !ior.is_finite() {
        return Err(m.error("ior", format!("must be positive, found {ior}")));
    }
    Ok(ior)
}

/// A microfacet distribution: `distribution` (`beckmann`, Mitsuba's default, or `ggx`) and
/// `alpha` (default 0.1), or `alpha_u` and `alpha_v` where `anisotropic` lobes are allowed.
/// A microfacet roughness that varies over the surface: its values along u and v from
/// textures (read as numbers: [`crate::texture::scalar`]), alpha either the value or, with
/// `remap`, its square root (pbrt-v4's `remaproughness`).
#[derive(Clone, Debug)]
pub struct RoughnessTextures {
    pub u: Texture,
    pub v: Texture,
    pub remap: bool,
}

impl RoughnessTextures {
    /// The values along u and v at surface coordinates `uv`, before any remapping.
    #[inline]
    pub fn values(&self, ctx: TextureEvalContext) -> (f32, f32) {
        (scalar(self.u.at(ctx)), scalar(self.v.at(ctx)))
    }

    /// The textures' mean values, for what asks of the material as a whole.
    pub fn means(&self) -> (f32, f32) {
        (scalar(self.u.mean()), scalar(self.v.mean()))
    }

    /// The distribution at surface coordinates `uv`, of the kind of `d`.
    #[inline]
    pub fn at(&self, d: Microfacet, ctx: TextureEvalContext) -> Microfacet {
        let (u, v) = self.values(ctx);
        Microfacet::new(d.kind, self.alpha(u), self.alpha(v))
    }

    #[inline]
    fn alpha(&self, x: f32) -> f32 {
        if self.remap { x.max(0.0).sqrt() } else { x }
    }
}

/// Whether any of `keys` is given as a texture table.
pub(crate) fn any_texture_table(m: &Properties<'_>, keys: &[&str]) -> bool {
    keys.iter().any(|k| {
        m.node(k)
            .is_some_and(|n| matches!(n.value, crate::value::Value::Table(_)))
    })
}

/// A roughness parameter `key` that may vary: a texture table, or a number (>= 0) as a
/// constant texture; absent, `default` (None: required).
pub(crate) fn read_roughness_texture(
    m: &Properties<'_>,
    key: &str,
    default: Option<f32>,
    resources: &mut dyn Resources,
) -> Result<Texture> {
    if any_texture_table(m, &[key]) {
        return resources.texture(m, key, Rgb::ZERO);
    }
    let x = match default {
        Some(d) => m.f32(key, d)?,
        None => m.f32_required(key)?,
    };
    if !(x >= 0.0 && x.is_finite()) {
        return Err(m.error(key, format!("must not be negative, found {x}")));
    }
    Ok(Texture::Constant(Rgb::splat(x)))
}

/// The roughness of a microfacet material: [`read_microfacet`]'s distribution, and, where
/// `alpha` (or `alpha_u`, `alpha_v`) is a texture table, the textures that replace its
/// roughness at each point. `remaproughness` (default false) takes alpha as the square root
/// of the values given, numbers and textures alike (pbrt-v4's `RoughnessToAlpha`).
pub fn read_roughness(
    m: &Properties<'_>,
    anisotropic: bool,
    resources: &mut dyn Resources,
) -> Result<(Microfacet, Option<RoughnessTextures>)> {
    let remap = m.bool("remaproughness", false)?;
    if !any_texture_table(m, &["alpha", "alpha_u", "alpha_v"]) {
        let mut d = read_microfacet(m, anisotropic)?;
        if remap {
            d = Microfacet::new(d.kind, d.alpha_u.sqrt(), d.alpha_v.sqrt());
        }
        return Ok((d, None));
    }
    let kind = read_microfacet_kind(m)?;
    let (u, v) = if m.has("alpha_u") || m.has("alpha_v") {
        if !anisotropic {
            return Err(m.error(
                "alpha_u",
                "this material's roughness is isotropic: give `alpha`",
            ));
        }
        (
            read_roughness_texture(m, "alpha_u", None, resources)?,
            read_roughness_texture(m, "alpha_v", None, resources)?,
        )
    } else {
        let t = read_roughness_texture(m, "alpha", None, resources)?;
        (t.clone(), t)
    };
    let textures = RoughnessTextures { u, v, remap };
    let (mu, mv) = textures.means();
    let d = Microfacet::new(kind, textures.alpha(mu), textures.alpha(mv));
    Ok((d, Some(textures)))
}

fn read_microfacet_kind(m: &Properties<'_>) -> Result<MicrofacetKind> {
    match m.string("distribution", "beckmann")? {
        "beckmann" => Ok(MicrofacetKind::Beckmann),
        "ggx" => Ok(MicrofacetKind::Ggx),
        "phong" => Ok(MicrofacetKind::Phong),
        other => Err(m.error(
            "distribution",
            format!("unknown distribution {other:?}; expected beckmann, ggx or phong"),
        )),
    }
}

pub fn read_microfacet(m: &Properties<'_>, anisotropic: bool) -> Result<Microfacet> {
    let kind = read_microfacet_kind(m)?;
    let positive = |key: &str, x: f32| {
        if x > 0.0 && x.is_finite() {
            Ok(x)
        } else {
            Err(m.error(key, format!("must be positive, found {x}")))
        }
    };
    if m.has("alpha_u") || m.has("alpha_v") {
        if !anisotropic {
            return Err(m.error(
                if m.has("alpha_u") {
                    "alpha_u"
                } else {
                    "alpha_v"
                },
                "this material's roughness is isotropic: give `alpha`",
            ));
        }
        if m.has("alpha") {
            return Err(m.error("alpha", "give either `alpha` or `alpha_u` and `alpha_v`"));
        }
        let u = positive("alpha_u", m.f32_required("alpha_u")?)?;
        let v = positive("alpha_v", m.f32_required("alpha_v")?)?;
        return Ok(Microfacet::new(kind, u, v));
    }
    let alpha = positive("alpha", m.f32("alpha", 0.1)?)?;
    Ok(Microfacet::isotropic(kind, alpha))
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
        let (au_eta, au_k) = conductor_ior("Au").unwrap();
        assert!((au_eta.x - 0.143).abs() < 1e-3 && (au_k.x - 3.983).abs() < 1e-3);
        assert_eq!(conductor_ior("gold"), None);
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
