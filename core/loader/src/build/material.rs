//! `[materials]`: each material's type and parameters (textures through [`crate::texture`]),
//! its index of refraction and microfacet distribution.

use super::common::{Index, Loader, type_of};
use crate::texture::read_texture_param;
use foton_core::Rgb;
use foton_core::error::Result;
use foton_core::glossy::{Plastic, RoughConductor, RoughDielectric, RoughPlastic};
use foton_core::material::Material;
use foton_core::microfacet::{Microfacet, MicrofacetKind};
use foton_core::props::Properties;
use foton_core::registry::Resources;
use foton_core::scene::Named;
use foton_core::texture::Texture;
use std::collections::HashMap;

const MATERIAL_TYPES: &[&str] = &[
    "diffuse",
    "mirror",
    "conductor",
    "roughconductor",
    "dielectric",
    "thindielectric",
    "roughdielectric",
    "plastic",
    "roughplastic",
    "null",
];

pub(super) fn read_materials(
    root: &Properties<'_>,
    ld: &mut Loader,
) -> Result<(Vec<Named<Material>>, Index)> {
    let mut out = Vec::new();
    let mut index = HashMap::new();
    let Some(all) = root.table("materials")? else {
        return Ok((out, index));
    };
    let names: Vec<&str> = all.keys().collect();
    for name in names {
        let m = all.table(name)?.unwrap();
        let ty = type_of(&m, MATERIAL_TYPES)?;
        // A colour that may be a texture; a reflectance above 1 is warned about.
        let mut texture = |key: &str, default: Rgb, reflectance: bool| -> Result<Texture> {
            let (t, bag) = read_texture_param(&m, key, default, &ld.dir)?;
            if let Some(bag) = bag {
                ld.done(&bag);
            }
            if reflectance && t.max().max_element() > 1.0 {
                ld.warn(&m, key, "is above 1: the material creates energy".into());
            }
            Ok(t)
        };
        let material = match ty {
            "diffuse" => Material::Diffuse {
                reflectance: texture("reflectance", Rgb::splat(0.5), true)?,
                twosided: m.bool("twosided", true)?,
            },
            "mirror" => Material::Mirror {
                reflectance: texture("reflectance", Rgb::ONE, true)?,
            },
            "conductor" => {
                let specular_reflectance = texture("specular_reflectance", Rgb::ONE, false)?;
                match read_conductor_ior(&m)? {
                    Some((eta, k)) => Material::Conductor {
                        eta,
                        k,
                        specular_reflectance,
                    },
                    // Mitsuba's default: a perfect mirror.
                    None => Material::Mirror {
                        reflectance: specular_reflectance,
                    },
                }
            }
            "roughconductor" => {
                let specular_reflectance = texture("specular_reflectance", Rgb::ONE, false)?;
                // No named material and no eta, k: a perfect (rough) mirror, F = 1.
                let (eta, k) = read_conductor_ior(&m)?.unwrap_or((Rgb::ZERO, Rgb::ZERO));
                Material::RoughConductor {
                    lobe: RoughConductor {
                        distribution: read_microfacet(&m, true)?,
                        eta,
                        k,
                        specular_reflectance: Rgb::ONE,
                    },
                    specular_reflectance,
                    twosided: m.bool("twosided", true)?,
                }
            }
            "roughdielectric" => Material::RoughDielectric {
                lobe: RoughDielectric {
                    distribution: read_microfacet(&m, true)?,
                    eta: read_ior(&m, 1.5)?,
                    specular_reflectance: Rgb::ONE,
                    specular_transmittance: Rgb::ONE,
                },
                specular_reflectance: texture("specular_reflectance", Rgb::ONE, false)?,
                specular_transmittance: texture("specular_transmittance", Rgb::ONE, false)?,
            },
            "plastic" | "roughplastic" => {
                // Mitsuba's default: polypropylene in air.
                let eta = read_ior(&m, 1.49 / 1.000277)?;
                let diffuse_reflectance = texture("diffuse_reflectance", Rgb::splat(0.5), true)?;
                let specular_reflectance = texture("specular_reflectance", Rgb::ONE, false)?;
                let nonlinear = m.bool("nonlinear", false)?;
                let twosided = m.bool("twosided", true)?;
                // The lobes' colours are set at each point from the textures.
                let (diffuse, specular) = (Rgb::splat(0.5), Rgb::ONE);
                if ty == "plastic" {
                    Material::Plastic {
                        lobe: Plastic {
                            eta,
                            diffuse_reflectance: diffuse,
                            specular_reflectance: specular,
                            nonlinear,
                        },
                        diffuse_reflectance,
                        specular_reflectance,
                        twosided,
                    }
                } else {
                    let d = read_microfacet(&m, false)?;
                    Material::RoughPlastic {
                        lobe: RoughPlastic::new(
                            d.kind, d.alpha_u, eta, diffuse, specular, nonlinear,
                        ),
                        diffuse_reflectance,
                        specular_reflectance,
                        twosided,
                    }
                }
            }
            "dielectric" | "thindielectric" => {
                let ior = read_ior(&m, 1.5)?;
                if ty == "dielectric" {
                    Material::Dielectric { ior }
                } else {
                    Material::ThinDielectric { ior }
                }
            }
            "null" => Material::Null,
            other => {
                return Err(m.error(
                    "type",
                    format!(
                        "unknown material type {other:?}; expected one of: {}",
                        MATERIAL_TYPES.join(", ")
                    ),
                ));
            }
        };
        index.insert(name.to_string(), out.len() as u32);
        out.push(Named {
            name: name.to_string(),
            value: material,
        });
        ld.done(&m);
    }
    ld.done(&all);
    Ok((out, index))
}

/// A conductor's complex index of refraction: a named `material` (Mitsuba's names; `none`: a
/// perfect mirror) or `eta` and `k`. None: a perfect mirror.
fn read_conductor_ior(m: &Properties<'_>) -> Result<Option<(Rgb, Rgb)>> {
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
            let found = foton_core::material::conductor(name).ok_or_else(|| {
                let names: Vec<&str> = foton_core::material::CONDUCTORS
                    .iter()
                    .map(|(n, _, _)| *n)
                    .collect();
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

/// A relative index of refraction `ior` (inside over outside), positive.
fn read_ior(m: &Properties<'_>, default: f32) -> Result<f32> {
    let ior = m.f32("ior", default)?;
    if ior <= 0.0 || !ior.is_finite() {
        return Err(m.error("ior", format!("must be positive, found {ior}")));
    }
    Ok(ior)
}

/// A microfacet distribution: `distribution` (`beckmann`, Mitsuba's default, or `ggx`) and
/// `alpha` (default 0.1), or `alpha_u` and `alpha_v` where `anisotropic` lobes are allowed.
fn read_microfacet(m: &Properties<'_>, anisotropic: bool) -> Result<Microfacet> {
    let kind = match m.string("distribution", "beckmann")? {
        "beckmann" => MicrofacetKind::Beckmann,
        "ggx" => MicrofacetKind::Ggx,
        other => {
            return Err(m.error(
                "distribution",
                format!("unknown distribution {other:?}; expected beckmann or ggx"),
            ));
        }
    };
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
