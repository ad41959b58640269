//! `coatedconductor`: a metal under a dielectric coat, with an optional scattering slab
//! between them (pbrt-v4's `coatedconductor`, its `CoatedConductorBxDF`; the lobe is a
//! [`Layered`] random walk, see `layered.rs`). pbrt's dotted names are written with an
//! underscore: `interface.roughness` is `interface_roughness`.
//!
//! | Parameter                  | Type          | Meaning                                  | Default |
//! |----------------------------|---------------|------------------------------------------|---------|
//! | `interface_roughness`      | number / texture | the coat's roughness (or `interface_uroughness`, `interface_vroughness`) | `0` |
//! | `interface_eta`            | number        | the coat's index relative to the outside | `1.5`   |
//! | `conductor_eta`, `conductor_k` | RGB       | the metal's complex index relative to the outside (divided by `interface_eta` under the coat, as pbrt does) | copper |
//! | `conductor_material`       | string        | instead: a named conductor (`Cu`, `Au`, ...: `conductor`'s names) | |
//! | `reflectance`              | RGB / texture | instead: the metal's normal reflectance r (eta 1, k = 2 sqrt(r) / sqrt(1 - r)) | |
//! | `conductor_roughness`      | number / texture | the metal's roughness (or `conductor_uroughness`, `conductor_vroughness`) | `0` |
//! | `remaproughness`, `thickness`, `albedo`, `g`, `maxdepth`, `nsamples` | | as for `coateddiffuse` | |

use crate::texture::TextureEvalContext;
use super::SurfaceMaterial;
use super::conductor::conductor_ior;
use super::layered::{self, Conductor, Dielectric, Layered};
use crate::Rgb;
use crate::registry::Factory;
use crate::texture::Texture;

/// The lobe: pbrt's `LayeredBxDF<DielectricBxDF, ConductorBxDF, true>`.
pub type CoatedConductorBxdf = Layered<Conductor>;

#[derive(Clone, Debug)]
pub struct CoatedConductorMaterial {
    /// The lobe, its albedo (and its metal's index, when given by `reflectance`) set at
    /// each point from the textures.
    pub lobe: CoatedConductorBxdf,
    /// The metal's normal reflectance, when it is given that way.
    pub reflectance: Option<Texture>,
    pub albedo: Texture,
    /// The coat's and the metal's roughness where they vary over the surface.
    pub roughness: [Option<super::RoughnessTextures>; 2],
}

/// pbrt's index of a metal of normal reflectance `r`: eta 1 and k = 2 sqrt(r) / sqrt(1 - r)
/// (r clamped below 1), both relative to the coat of index `interface_eta`.
fn index_of_reflectance(r: Rgb, interface_eta: f32) -> (Rgb, Rgb) {
    let r = r.clamp(Rgb::ZERO, Rgb::splat(0.9999));
    let k = 2.0 * r.powf(0.5) / (Rgb::ONE - r).max(Rgb::ZERO).powf(0.5);
    (Rgb::ONE / interface_eta, k / interface_eta)
}

impl SurfaceMaterial for CoatedConductorMaterial {
    type Bxdf = CoatedConductorBxdf;

    #[inline(always)]
    fn bxdf(&self, ctx: TextureEvalContext) -> CoatedConductorBxdf {
        let mut lobe = self.lobe;
        lobe.albedo = self.albedo.at(ctx).clamp(Rgb::ZERO, Rgb::ONE);
        if let Some(r) = &self.reflectance {
            (lobe.base.eta, lobe.base.k) = index_of_reflectance(r.at(ctx), lobe.top.eta);
        }
        if let Some(r) = &self.roughness[0] {
            lobe.top.ggx = r.ggx_at(ctx);
        }
        if let Some(r) = &self.roughness[1] {
            lobe.base.ggx = r.ggx_at(ctx);
        }
        lobe
    }

    #[inline]
    fn needs_coordinates(&self) -> bool {
        !self.lobe.top.ggx.distribution.is_isotropic()
            || !self.lobe.base.ggx.distribution.is_isotropic()
            || self.reflectance.as_ref().is_some_and(|r| !r.is_constant())
            || !self.albedo.is_constant()
            || self.roughness.iter().any(Option::is_some)
    }
}

pub const FACTORY: Factory<CoatedConductorMaterial> = Factory {
    name: "coatedconductor",
    description: "a metal under a dielectric coat, by a random walk between them (pbrt-v4's)",
    create: |m, _, resources| {
        let interface_eta = layered::read_eta(m, "interface_eta")?;
        let named = m.string_opt("conductor_material")?;
        let (eta, k) = (m.rgb_opt("conductor_eta")?, m.rgb_opt("conductor_k")?);
        let given_index = named.is_some() || eta.is_some() || k.is_some();
        if m.has("reflectance") && given_index {
            return Err(m.error(
                "reflectance",
                "give either `reflectance` or the conductor's index (`conductor_eta` and `conductor_k`, or `conductor_material`), not both",
            ));
        }
        if named.is_some() && (eta.is_some() || k.is_some()) {
            return Err(m.error(
                "conductor_material",
                "give either `conductor_material` or `conductor_eta` and `conductor_k`, not both",
            ));
        }
        let unknown = |name: &str| {
            let names: Vec<&str> = super::CONDUCTORS.iter().map(|(n, _, _)| *n).collect();
            m.error(
                "conductor_material",
                format!("unknown conductor `{name}`; expected one of: {}", names.join(", ")),
            )
        };
        let copper = conductor_ior("Cu").expect("copper is a named conductor");
        // pbrt's defaults: copper's eta and k, each where the other is given alone.
        let (eta, k) = match named {
            Some(name) => conductor_ior(name).ok_or_else(|| unknown(name))?,
            None => (eta.unwrap_or(copper.0), k.unwrap_or(copper.1)),
        };
        let reflectance = if m.has("reflectance") {
            Some(super::reflectance(m, "reflectance", Rgb::ONE, resources)?)
        } else {
            None
        };
        let slab = layered::read_slab(m, resources)?;
        let (top_ggx, top_roughness) = layered::read_ggx_textured(m, "interface_", resources)?;
        let (base_ggx, base_roughness) = layered::read_ggx_textured(m, "conductor_", resources)?;
        let lobe = Layered {
            top: Dielectric {
                ggx: top_ggx,
                eta: interface_eta,
            },
            base: Conductor {
                ggx: base_ggx,
                // Relative to the coat above it.
                eta: eta / interface_eta,
                k: k / interface_eta,
            },
            thickness: slab.thickness,
            albedo: Rgb::ZERO,
            g: slab.g,
            max_depth: slab.max_depth,
            n_samples: slab.n_samples,
        };
        Ok(Box::new(CoatedConductorMaterial {
            lobe,
            reflectance,
            albedo: slab.albedo,
            roughness: [top_roughness, base_roughness],
        }))
    },
};
