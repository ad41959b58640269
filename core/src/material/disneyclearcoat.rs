//! `disney_clearcoat`: the clearcoat lobe of Disney's BSDF on its own (Burley 2012; lajolla's
//! `disneyclearcoat`), a microfacet reflection f cos_i = F D G / (4 cos_o): Schlick's Fresnel
//! of index 1.5 (R0 = 0.04), Berry's GTR1 distribution of alpha 0.1 (`clearcoat_gloss` 0) to
//! 0.001 (1), Smith's GGX masking of roughness 0.25 for both directions. Mitsuba 3's
//! principled clearcoat leaves out the 1 / (4 cos_i cos_o); this lobe has it, as the
//! microfacet model and lajolla do. One-sided; normals sampled from D cos theta_m.
//!
//! | Parameter         | Type             | Meaning                                      | Default |
//! |-------------------|------------------|----------------------------------------------|---------|
//! | `clearcoat_gloss` | number / texture | 0: a rough (alpha 0.1), 1: a glossy (0.001) coat | `1` |

use super::SurfaceMaterial;
use super::principled_common::{Gtr1, Scalar, clearcoat_g1, lerp, read_scalar, schlick_weight};
use crate::Rgb;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode, reflect};
use crate::texture::TextureEvalContext;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct DisneyClearcoatMaterial {
    pub clearcoat_gloss: Scalar,
}

/// The clearcoat lobe of GTR1 roughness `alpha` (see the module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisneyClearcoatBxdf {
    pub alpha: f32,
}

impl SurfaceMaterial for DisneyClearcoatMaterial {
    type Bxdf = DisneyClearcoatBxdf;

    #[inline]
    fn bxdf(&self, ctx: TextureEvalContext) -> DisneyClearcoatBxdf {
        DisneyClearcoatBxdf {
            alpha: lerp(0.1, 0.001, self.clearcoat_gloss.at(ctx)),
        }
    }

    fn needs_coordinates(&self) -> bool {
        !self.clearcoat_gloss.is_constant()
    }
}

impl DisneyClearcoatBxdf {
    /// f cos_i for directions above the surface and their half vector.
    fn value(&self, wo: Vec3, wi: Vec3, h: Vec3) -> f32 {
        let f = 0.04 + 0.96 * schlick_weight(h.dot(wi).abs());
        let d = Gtr1 { alpha: self.alpha }.d(h);
        f * d * clearcoat_g1(wo, h) * clearcoat_g1(wi, h) / (4.0 * wo.z)
    }
}

impl Bxdf for DisneyClearcoatBxdf {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        Rgb::splat(self.value(wo, wi, (wo + wi).normalize()))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        // The reflection's Jacobian d omega_h / d omega_i = 1 / (4 |h . wi|).
        Gtr1 { alpha: self.alpha }.pdf(h) / (4.0 * h.dot(wi).abs())
    }

    fn sample(&self, wo: Vec3, u: Vec2, _: f32, _: TransportMode) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let h = Gtr1 { alpha: self.alpha }.sample(u);
        let wi = reflect(wo, h);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf(wo, wi);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(LocalSample {
            wi,
            weight: Rgb::splat(self.value(wo, wi, h) / pdf),
            pdf,
            delta: false,
        })
    }

    fn roughness(&self) -> f32 {
        self.alpha
    }
}

pub const FACTORY: Factory<DisneyClearcoatMaterial> = Factory {
    name: "disney_clearcoat",
    description: "the clearcoat lobe of Disney's BSDF on its own (lajolla's disneyclearcoat)",
    create: |m, _, resources| {
        Ok(Box::new(DisneyClearcoatMaterial {
            clearcoat_gloss: read_scalar(m, "clearcoat_gloss", 1.0, (0.0, 1.0), resources)?,
        }))
    },
};
