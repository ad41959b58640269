//! `coating`: a smooth dielectric layer over another material (Mitsuba 0.6's `coating`; the
//! lobe is [`CoatingBxdf`]).
//!
//! | Parameter              | Type           | Meaning                                            | Default |
//! |------------------------|----------------|----------------------------------------------------|---------|
//! | `base`                 | material table | the material under the layer: `diffuse`, `conductor`, `roughconductor`, `roughplastic`, `roughdiffuse` or `dielectric` | (required) |
//! | `ior`                  | number         | the layer's index relative to the outside          | `1.5046` (BK7 in air) |
//! | `sigma_a`              | RGB            | absorption inside the layer, per unit of `thickness` | `0`   |
//! | `thickness`            | number         | the layer's thickness, in the inverse units of `sigma_a` | `1` |
//! | `specular_reflectance` | RGB / texture  | scales the layer's reflection                      | `1`     |
//! | `twosided`             | bool           | the same seen from behind                          | `false` |
//!
//! The model is Mitsuba 0.6's (Weidlich and Wilkie 2007, one bounce in the layer): the layer
//! reflects F(cos_o) in the mirror direction; the rest enters, refracted to wo' and wi', is
//! scattered once by the base, attenuated by exp(-sigma_a thickness (1 / cos_o' + 1 / cos_i'))
//! and leaves: f = f_base(wo', wi') (1 - F(cos_o)) (1 - F(cos_i)) A / eta^2. Light that the
//! layer's underside reflects back onto the base is lost, as in Mitsuba 0.6. Over a smooth
//! metal every part is a mirror reflection: F(cos) + (1 - F(cos))^2 F_metal(cos') A.
//!
//! Over a smooth dielectric (a coated glass interface) every part is a delta and the layer
//! lies on both sides, as in Mitsuba 0.6: from either side the layer reflects F(cos_o); the
//! rest enters, is reflected or refracted by the dielectric, crosses the layer on the side it
//! leaves (absorbed over both legs) and refracts out: weight (1 - F(cos_o)) (1 - F(cos_i))
//! A w_base. The material then bounds a volume, as the dielectric does.

use crate::texture::TextureEvalContext;
use super::mirror::delta_sample;
use super::{Material, SurfaceMaterial, nested_material, read_ior};
use crate::Rgb;
use crate::glossy::{RoughConductor, RoughPlastic};
use crate::material::conductor::ConductorBxdf;
use crate::material::dielectric::DielectricBxdf;
use crate::material::diffuse::DiffuseBxdf;
use crate::material::roughdiffuse::RoughDiffuseBxdf;
use crate::material::Lobe;
use crate::props::Properties;
use crate::registry::Factory;
use crate::scattering::{Bxdf, LocalSample, TransportMode, fresnel_dielectric, sampled_direction};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

/// The lobes a coating can lie on: the non-delta ones Mitsuba's files put under it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoatBase {
    Diffuse(DiffuseBxdf),
    /// A smooth metal: the coating is then a mirror reflection.
    Conductor(ConductorBxdf),
    RoughConductor(RoughConductor),
    RoughPlastic(RoughPlastic),
    RoughDiffuse(RoughDiffuseBxdf),
    /// A smooth dielectric: the coating is then all deltas, on both sides.
    Dielectric(DielectricBxdf),
}

impl CoatBase {
    fn of(lobe: Lobe) -> Option<CoatBase> {
        match lobe {
            Lobe::Diffuse(l) => Some(CoatBase::Diffuse(l)),
            Lobe::Conductor(l) => Some(CoatBase::Conductor(l)),
            Lobe::RoughConductor(l) => Some(CoatBase::RoughConductor(l)),
            Lobe::RoughPlastic(l) => Some(CoatBase::RoughPlastic(l)),
            Lobe::RoughDiffuse(l) => Some(CoatBase::RoughDiffuse(l)),
            Lobe::Dielectric(l) => Some(CoatBase::Dielectric(l)),
            _ => None,
        }
    }

    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        match self {
            CoatBase::Diffuse(l) => Bxdf::eval(l, wo, wi),
            CoatBase::Conductor(l) => Bxdf::eval(l, wo, wi),
            CoatBase::RoughConductor(l) => Bxdf::eval(l, wo, wi),
            CoatBase::RoughPlastic(l) => Bxdf::eval(l, wo, wi),
            CoatBase::RoughDiffuse(l) => Bxdf::eval(l, wo, wi),
            CoatBase::Dielectric(l) => Bxdf::eval(l, wo, wi),
        }
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            CoatBase::Diffuse(l) => Bxdf::pdf(l, wo, wi),
            CoatBase::Conductor(l) => Bxdf::pdf(l, wo, wi),
            CoatBase::RoughConductor(l) => Bxdf::pdf(l, wo, wi),
            CoatBase::RoughPlastic(l) => Bxdf::pdf(l, wo, wi),
            CoatBase::RoughDiffuse(l) => Bxdf::pdf(l, wo, wi),
            CoatBase::Dielectric(l) => Bxdf::pdf(l, wo, wi),
        }
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        match self {
            CoatBase::Diffuse(l) => Bxdf::sample(l, wo, u, uc, mode),
            CoatBase::Conductor(l) => Bxdf::sample(l, wo, u, uc, mode),
            CoatBase::RoughConductor(l) => Bxdf::sample(l, wo, u, uc, mode),
            CoatBase::RoughPlastic(l) => Bxdf::sample(l, wo, u, uc, mode),
            CoatBase::RoughDiffuse(l) => Bxdf::sample(l, wo, u, uc, mode),
            CoatBase::Dielectric(l) => Bxdf::sample(l, wo, u, uc, mode),
        }
    }

    fn roughness(&self) -> f32 {
        match self {
            CoatBase::Diffuse(l) => Bxdf::roughness(l),
            CoatBase::Conductor(l) => Bxdf::roughness(l),
            CoatBase::RoughConductor(l) => Bxdf::roughness(l),
            CoatBase::RoughPlastic(l) => Bxdf::roughness(l),
            CoatBase::RoughDiffuse(l) => Bxdf::roughness(l),
            CoatBase::Dielectric(l) => Bxdf::roughness(l),
        }
    }
}

/// A smooth dielectric layer over a [`CoatBase`] (see the module). One-sided: both directions
/// above the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoatingBxdf {
    pub base: CoatBase,
    /// The layer's index relative to the outside.
    pub eta: f32,
    /// sigma_a times the thickness: the optical depth of the layer along its normal.
    pub depth: Rgb,
    pub specular_reflectance: Rgb,
    /// The weight that steers samples to the mirror reflection (Mitsuba 0.6's: 1 / (1 +
    /// the channels' mean of exp(-2 depth))).
    pub specular_weight: f32,
}

/// `w` with its z given the sign of `side`'s.
#[inline]
fn on_side_of(w: Vec3, side: f32) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs().copysign(side))
}

impl CoatingBxdf {
    /// A coated dielectric, sampled (see the module): the layer's reflection, or the light
    /// through the layer that the dielectric reflects or refracts, out on the side it leaves.
    fn sample_coated_dielectric(
        &self,
        glass: &DielectricBxdf,
        wo: Vec3,
        u: Vec2,
        uc: f32,
        mode: TransportMode,
    ) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let (up, f_o) = self.inside(Vec3::new(wo.x, wo.y, wo.z.abs()));
        let wo_in = on_side_of(up, wo.z);
        let (uc, p_spec) = match self.layer_or_through(wo, f_o, uc) {
            Ok(through) => through,
            Err(layer) => return layer,
        };
        let s = glass.sample(wo_in, u, uc, mode)?;
        let out = self.outside(Vec3::new(s.wi.x, s.wi.y, s.wi.z.abs()))?;
        let f_i = fresnel_dielectric(out.z, self.eta);
        let weight = s.weight
            * self.attenuation(wo_in.z.abs(), s.wi.z.abs())
            * ((1.0 - f_o) * (1.0 - f_i) / (1.0 - p_spec));
        delta_sample(on_side_of(out, s.wi.z), weight, s.pdf * (1.0 - p_spec))
    }

    /// `w` (above the surface) refracted into the layer, and the layer's Fresnel
    /// reflectance for it.
    #[inline]
    fn inside(&self, w: Vec3) -> (Vec3, f32) {
        let e = 1.0 / self.eta;
        let sin2 = (e * e * (1.0 - w.z * w.z)).min(1.0);
        let cos_t = (1.0 - sin2).sqrt();
        (
            Vec3::new(e * w.x, e * w.y, cos_t),
            fresnel_dielectric(w.z, self.eta),
        )
    }

    /// `w` (inside the layer, above the base) refracted out of it.
    #[inline]
    fn outside(&self, w: Vec3) -> Option<Vec3> {
        let sin2 = self.eta * self.eta * (1.0 - w.z * w.z);
        (sin2 < 1.0).then(|| Vec3::new(self.eta * w.x, self.eta * w.y, (1.0 - sin2).sqrt()))
    }

    #[inline]
    fn attenuation(&self, cos_o: f32, cos_i: f32) -> Rgb {
        if self.depth == Rgb::ZERO {
            return Rgb::ONE;
        }
        let d = -(1.0 / cos_o + 1.0 / cos_i);
        Rgb::new(
            (self.depth.x * d).exp(),
            (self.depth.y * d).exp(),
            (self.depth.z * d).exp(),
        )
    }

    /// The layer's mirror reflection of `wo` (Fresnel reflectance `f_o`), chosen with its
    /// probability when `uc` falls below it (`Err`); else the light goes through the layer:
    /// `uc` rescaled for the base, and the probability the reflection had.
    #[inline]
    fn layer_or_through(
        &self,
        wo: Vec3,
        f_o: f32,
        uc: f32,
    ) -> Result<(f32, f32), Option<LocalSample>> {
        let p_spec = self.prob_specular(f_o);
        if uc < p_spec {
            return Err(delta_sample(
                Vec3::new(-wo.x, -wo.y, wo.z),
                self.specular_reflectance * (f_o / p_spec),
                p_spec,
            ));
        }
        Ok((((uc - p_spec) / (1.0 - p_spec)).min(1.0 - f32::EPSILON), p_spec))
    }

    /// The probability of sampling the mirror reflection for `wo` (above the surface), whose
    /// Fresnel reflectance is `f_o`.
    #[inline]
    fn prob_specular(&self, f_o: f32) -> f32 {
        let w = self.specular_weight;
        let s = f_o * w;
        let rest = (1.0 - f_o) * (1.0 - w);
        if s + rest > 0.0 { s / (s + rest) } else { 0.0 }
    }
}

impl Bxdf for CoatingBxdf {
    fn is_delta(&self) -> bool {
        matches!(self.base, CoatBase::Conductor(_) | CoatBase::Dielectric(_))
    }

    /// The light through the layer (the mirror reflection is a delta).
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let (wo_in, f_o) = self.inside(wo);
        let (wi_in, f_i) = self.inside(wi);
        // The base's f cos_i' times the change of solid angle at the exit: the base's cosine
        // becomes the outside one over eta^2.
        let f = self.base.eval(wo_in, wi_in);
        f * self.attenuation(wo_in.z, wi_in.z)
            * ((1.0 - f_o) * (1.0 - f_i) * wi.z / (self.eta * self.eta * wi_in.z))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let (wo_in, f_o) = self.inside(wo);
        let (wi_in, _) = self.inside(wi);
        // d omega' / d omega = cos_i / (eta^2 cos_i').
        (1.0 - self.prob_specular(f_o))
            * self.base.pdf(wo_in, wi_in)
            * (wi.z / (self.eta * self.eta * wi_in.z))
    }

    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        if let CoatBase::Dielectric(glass) = &self.base {
            return self.sample_coated_dielectric(glass, wo, u, uc, mode);
        }
        if wo.z <= 0.0 {
            return None;
        }
        let (wo_in, f_o) = self.inside(wo);
        if let CoatBase::Conductor(metal) = &self.base {
            // Both parts leave in the mirror direction: one delta of their sum.
            let inner = metal.sample(wo_in, u, uc, mode)?;
            let through = inner.weight
                * self.attenuation(wo_in.z, wo_in.z)
                * ((1.0 - f_o) * (1.0 - f_o));
            return delta_sample(
                Vec3::new(-wo.x, -wo.y, wo.z),
                self.specular_reflectance * f_o + through,
                1.0,
            );
        }
        let (uc, _) = match self.layer_or_through(wo, f_o, uc) {
            Ok(through) => through,
            Err(layer) => return layer,
        };
        let s = self.base.sample(wo_in, u, uc, mode)?;
        if s.delta || s.wi.z <= 0.0 {
            return None;
        }
        let wi = self.outside(s.wi)?;
        sampled_direction(self, wo, wi)
    }

    fn roughness(&self) -> f32 {
        self.base.roughness()
    }

    fn delta_probability(&self, wo: Vec3) -> f32 {
        if let CoatBase::Dielectric(_) = self.base {
            return if wo.z == 0.0 { 0.0 } else { 1.0 };
        }
        if wo.z <= 0.0 {
            return 0.0;
        }
        if self.is_delta() {
            return 1.0;
        }
        self.prob_specular(fresnel_dielectric(wo.z, self.eta))
    }
}

#[derive(Clone, Debug)]
pub struct CoatingMaterial {
    /// The material under the layer (one whose lobe is a [`CoatBase`]).
    pub base: Box<Material>,
    pub eta: f32,
    pub depth: Rgb,
    pub specular_reflectance: Texture,
    pub specular_weight: f32,
    pub twosided: bool,
}

impl SurfaceMaterial for CoatingMaterial {
    type Bxdf = CoatingBxdf;

    #[inline]
    fn bxdf(&self, ctx: TextureEvalContext) -> CoatingBxdf {
        let base = self
            .base
            .lobe_at(Vec3::ZERO, ctx)
            .and_then(|(lobe, _)| CoatBase::of(lobe))
            .expect("a coating's base is checked when it is read");
        CoatingBxdf {
            base,
            eta: self.eta,
            depth: self.depth,
            specular_reflectance: self.specular_reflectance.at(ctx),
            specular_weight: self.specular_weight,
        }
    }

    fn needs_coordinates(&self) -> bool {
        self.base.needs_coordinates() || !self.specular_reflectance.is_constant()
    }

    fn twosided(&self) -> bool {
        self.twosided
    }

    fn is_delta(&self) -> bool {
        matches!(*self.base, Material::Conductor(_) | Material::Dielectric(_))
    }

    fn encloses_volume(&self) -> bool {
        self.base.encloses_volume()
    }
}

pub const FACTORY: Factory<CoatingMaterial> = Factory {
    name: "coating",
    description: "a smooth dielectric layer over another material (Mitsuba 0.6's coating)",
    create: |m, nested, resources| {
        let Some(node) = m.node("base") else {
            return Err(m.error("base", "missing: the material under the layer, a table"));
        };
        let bag = Properties::new(m.file(), &m.key_path("base"), node)?;
        let base = nested_material(&bag, nested, resources)?;
        let ty = bag.string_opt("type")?.unwrap_or_default();
        let supported = base
            .lobe_at(Vec3::ZERO, TextureEvalContext::default())
            .and_then(|(lobe, _)| CoatBase::of(lobe))
            .is_some();
        if !supported || matches!(base, Material::Blend(_)) {
            return Err(bag.error(
                "type",
                format!("a coating lies on a diffuse, conductor, roughconductor, roughplastic, roughdiffuse or dielectric material, not on `{ty}`"),
            ));
        }
        let base_twosided = base.lobe_at(Vec3::ZERO, TextureEvalContext::default()).is_some_and(|(l, t)| {
            t || matches!(l, Lobe::Diffuse(DiffuseBxdf { twosided: true, .. }))
        });
        let twosided = m.bool("twosided", false)? || base_twosided;
        if twosided && matches!(base, Material::Dielectric(_)) {
            return Err(m.error(
                "twosided",
                "a coating over a dielectric lies on both sides of it already",
            ));
        }
        nested.push(bag);
        // Mitsuba 0.6's default: BK7 in air.
        let eta = read_ior(m, 1.5046 / 1.000277)?;
        let sigma_a = m.rgb("sigma_a", Rgb::ZERO)?;
        let thickness = m.f32("thickness", 1.0)?;
        if sigma_a.min_element() < 0.0 || thickness < 0.0 {
            return Err(m.error(
                "sigma_a",
                "the layer's absorption and thickness must not be negative",
            ));
        }
        let depth = sigma_a * thickness;
        let mean_transmittance = (0..3).map(|c| (-2.0 * depth[c]).exp()).sum::<f32>() / 3.0;
        Ok(Box::new(CoatingMaterial {
            base: Box::new(base),
            eta,
            depth,
            specular_reflectance: resources.texture(m, "specular_reflectance", Rgb::ONE)?,
            specular_weight: 1.0 / (mean_transmittance + 1.0),
            twosided,
        }))
    },
};
