//! `disney_sheen`: the sheen lobe of Disney's BSDF on its own (Burley 2012; lajolla's
//! `disneysheen`): a grazing highlight f cos_i = C_sheen (1 - |h . wi|)^5 cos_i, C_sheen white
//! blended by `sheen_tint` towards the base colour's hue. One-sided; sampled by the cosine.
//!
//! | Parameter    | Type             | Meaning                                 | Default |
//! |--------------|------------------|-----------------------------------------|---------|
//! | `base_color` | RGB / texture    | the colour whose hue the tint takes     | `0.5`   |
//! | `sheen_tint` | number / texture | 0: a white sheen, 1: the base colour's hue | `0.5` |

use super::principled_common::{Scalar, read_scalar, schlick_weight, sheen_color};
use super::{SurfaceMaterial, reflectance};
use crate::Rgb;
use crate::registry::Factory;
use crate::sampling::cosine_hemisphere;
use crate::scattering::{Bxdf, LocalSample, TransportMode};
use crate::texture::{Texture, TextureEvalContext};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

#[derive(Clone, Debug)]
pub struct DisneySheenMaterial {
    pub base_color: Texture,
    pub sheen_tint: Scalar,
}

/// The sheen lobe of colour `color` (see the module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisneySheenBxdf {
    pub color: Rgb,
}

impl SurfaceMaterial for DisneySheenMaterial {
    type Bxdf = DisneySheenBxdf;

    #[inline]
    fn bxdf(&self, ctx: TextureEvalContext) -> DisneySheenBxdf {
        DisneySheenBxdf {
            color: sheen_color(self.base_color.at(ctx), self.sheen_tint.at(ctx)),
        }
    }

    fn needs_coordinates(&self) -> bool {
        !self.base_color.is_constant() || !self.sheen_tint.is_constant()
    }
}

impl Bxdf for DisneySheenBxdf {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let h = (wo + wi).normalize();
        self.color * (schlick_weight(h.dot(wi)) * wi.z)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        wi.z * FRAC_1_PI
    }

    fn sample(&self, wo: Vec3, u: Vec2, _: f32, _: TransportMode) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        let h = (wo + wi).normalize();
        Some(LocalSample {
            wi,
            weight: self.color * (schlick_weight(h.dot(wi)) * PI),
            pdf: wi.z * FRAC_1_PI,
            delta: false,
        })
    }

    fn roughness(&self) -> f32 {
        f32::INFINITY
    }
}

pub const FACTORY: Factory<DisneySheenMaterial> = Factory {
    name: "disney_sheen",
    description: "the sheen lobe of Disney's BSDF on its own (lajolla's disneysheen)",
    create: |m, _, resources| {
        Ok(Box::new(DisneySheenMaterial {
            base_color: reflectance(m, "base_color", Rgb::splat(0.5), resources)?,
            sheen_tint: read_scalar(m, "sheen_tint", 0.5, (0.0, 1.0), resources)?,
        }))
    },
};
