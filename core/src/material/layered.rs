//! What `coateddiffuse` and `coatedconductor` share: pbrt-v4's `LayeredBxDF` (Pharr, Jakob
//! and Humphreys, *Physically Based Rendering*, 4th edition, section 14.3), a dielectric
//! interface on top of a base (a diffuse one, or a conductor), with a slab of homogeneous
//! medium of unit extinction, `albedo` and Henyey-Greenstein `g` between them, `thickness`
//! deep. Light that enters through the top wanders between the two, scattering in the slab, and
//! leaves through the top again: the BSDF is what a random walk through the layers brings out.
//!
//! Nothing is tabulated: [`Layered::eval`] and [`Layered::pdf`] are Monte Carlo estimates
//! (`nsamples` walks of at most `maxdepth` events, with next-event estimation towards the exit
//! direction) from a generator seeded by a hash of the two directions, so that the same pair
//! always gets the same value (bidirectional estimators compare a path's pdfs computed from
//! both ends); [`Layered::sample`] walks the layers from the sample values given. As in pbrt
//! the pdf is not the exact density of `sample` but an estimate of its main terms (reflection
//! at the top, and transmission, one reflection at the base, transmission), mixed with a
//! tenth of the uniform density: it serves multiple importance sampling only, which needs a
//! positive, deterministic function of the directions and not the exact density. A sample's
//! weight is the walk's own f cos / pdf, an unbiased estimate of f cos / p for its direction.
//!
//! Both kinds are pbrt's two-sided ones (seen from below, both directions are mirrored) whose
//! base does not transmit: nothing leaves on the other side, so `eval` and `pdf` are zero
//! there, where pbrt evaluates a walk that finds nothing and returns the uniform part of the
//! pdf. Otherwise the walk, its Russian roulette and its multiple-importance weights are
//! pbrt's, but for the weight of an exit the walk finds through a rough coat, which in pbrt
//! biases f (`exit_pdf`). The quantity carried (radiance or importance) only scales the
//! walk inside the slab by eta^2, which the exit undoes: `eval` and `pdf` take radiance, and
//! `sample` walks with the quantity it is given.
//!
//! pbrt's `maxdepth` counts the walk's events; `eval`'s next-event estimates reach one event
//! further than `sample`'s walk, so at a small depth the two differ by what the last event
//! brings (2% in a thick scattering slab at depth 10; nothing measurable without a slab).
//!
//! The interfaces are pbrt's `DielectricBxDF` and `ConductorBxDF` with the Trowbridge-Reitz
//! (GGX) distribution of [`Microfacet`] and pbrt's height-correlated masking-shadowing, smooth
//! (a delta) when both roughnesses are below 1e-3; the base of `coateddiffuse` is Lambertian.
//! They are written here in pbrt's convention, f without the cosine, with its sampling flags,
//! which the lobes of `glossy` (Mitsuba's, cosine included, no flags) do not take.

use crate::Rgb;
use crate::error::Result;
use crate::medium::Phase;
use crate::microfacet::{Microfacet, MicrofacetKind};
use crate::props::Properties;
use crate::registry::Resources;
use crate::sampling::{Rng, cosine_hemisphere};
use crate::scattering::{Bxdf, LocalSample, TransportMode, fresnel_conductor, reflect};
use crate::texture::Texture;
use crate::texture::TextureEvalContext;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Below this alpha (both directions) an interface is smooth: a delta (pbrt's
/// `EffectivelySmooth`).
const SMOOTH_ALPHA: f32 = 1e-3;

/// pbrt's seed of the directions' hash (its `GetOptions().seed`, 0 by default, mixed in).
const SEED: u64 = 0x6c61_7965_7265_6421;

/// Which scattering an interface may sample (pbrt's `BxDFReflTransFlags`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flags {
    All,
    Reflection,
    Transmission,
}

impl Flags {
    fn reflection(self) -> bool {
        self != Flags::Transmission
    }
    fn transmission(self) -> bool {
        self != Flags::Reflection
    }
}

/// A direction sampled at one interface: f without the cosine, as pbrt's `BSDFSample`.
#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    pub wi: Vec3,
    pub f: Rgb,
    pub pdf: f32,
    pub specular: bool,
    pub reflection: bool,
}

/// One of the two surfaces of the layers, in pbrt's convention: `f` without the cosine,
/// directions on either side.
pub trait Interface {
    fn f(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb;
    fn sample(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        flags: Flags,
    ) -> Option<Scatter>;
    fn pdf(&self, wo: Vec3, wi: Vec3, flags: Flags) -> f32;
    /// Whether it scatters in deltas only.
    fn specular(&self) -> bool;
    /// The roughness of its non-delta part (see [`Bxdf::roughness`]); 0 when smooth.
    fn roughness(&self) -> f32;
}

fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// `v` turned to the upper side.
fn upper(v: Vec3) -> Vec3 {
    if v.z < 0.0 { -v } else { v }
}

fn power_heuristic(f: f32, g: f32) -> f32 {
    let (f2, g2) = (f * f, g * g);
    if f2.is_infinite() {
        return 1.0;
    }
    if f2 + g2 == 0.0 { 0.0 } else { f2 / (f2 + g2) }
}

/// The Trowbridge-Reitz (GGX) distribution with pbrt's height-correlated Smith terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    pub distribution: Microfacet,
}

impl Ggx {
    /// alpha_u, alpha_v: pbrt's `roughness`, remapped by its `RoughnessToAlpha` (sqrt) when
    /// `remap`.
    pub fn new(u_roughness: f32, v_roughness: f32, remap: bool) -> Ggx {
        let alpha = |r: f32| if remap { r.max(0.0).sqrt() } else { r };
        let (au, av) = (alpha(u_roughness), alpha(v_roughness));
        Ggx {
            distribution: Microfacet {
                kind: MicrofacetKind::Ggx,
                alpha_u: au,
                alpha_v: av,
            },
        }
    }

    pub fn smooth(&self) -> bool {
        self.distribution.alpha_u.max(self.distribution.alpha_v) < SMOOTH_ALPHA
    }

    fn d(&self, wm: Vec3) -> f32 {
        self.distribution.d(wm)
    }

    /// Smith's Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2.
    fn lambda(&self, w: Vec3) -> f32 {
        let (au, av) = (self.distribution.alpha_u, self.distribution.alpha_v);
        let alpha2_tan2 = ((au * w.x).powi(2) + (av * w.y).powi(2)) / (w.z * w.z);
        if !alpha2_tan2.is_finite() {
            return f32::INFINITY;
        }
        ((1.0 + alpha2_tan2).sqrt() - 1.0) / 2.0
    }

    fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing G(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi)).
    fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density of visible normals D_w(wm) = G1(w) max(0, w.wm) D(wm) / |cos theta_w|.
    fn pdf(&self, w: Vec3, wm: Vec3) -> f32 {
        if w.z == 0.0 {
            return 0.0;
        }
        self.g1(w) * self.d(wm) * w.dot(wm).abs() / w.z.abs()
    }

    /// A visible normal seen from `w` (from either side; the normal is on the upper one).
    fn sample_wm(&self, w: Vec3, u: Vec2) -> Option<Vec3> {
        let (wm, pdf) = self.distribution.sample(upper(w), u);
        (pdf > 0.0).then_some(wm)
    }
}

/// Dielectric Fresnel reflectance for a signed cosine (pbrt's `FrDielectric`): from below,
/// the relative index is inverted.
fn fr_dielectric(cos_i: f32, eta: f32) -> f32 {
    if cos_i < 0.0 {
        crate::scattering::fresnel_dielectric(-cos_i, 1.0 / eta)
    } else {
        crate::scattering::fresnel_dielectric(cos_i, eta)
    }
}

/// Refraction of `wi` through the interface of normal `n` (pbrt's `Refract`): the
/// transmitted direction and the relative index eta' along the way; None on total internal
/// reflection.
fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (n, eta) = if wi.dot(n) < 0.0 {
        (-n, 1.0 / eta)
    } else {
        (n, eta)
    };
    crate::scattering::refract(wi, n, eta).map(|wt| (wt, eta))
}

/// The radiance scaling of a transmission with relative index eta'.
fn transmission_scale(mode: TransportMode, etap: f32) -> f32 {
    match mode {
        TransportMode::Radiance => 1.0 / (etap * etap),
        TransportMode::Importance => 1.0,
    }
}

/// The dielectric coat (pbrt's `DielectricBxDF`): `eta` is the coat's index relative to the
/// outside, above.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    pub ggx: Ggx,
    pub eta: f32,
}

impl Dielectric {
    /// The probabilities of sampling reflection and transmission given Fresnel's R, within
    /// `flags`.
    fn choice(r: f32, flags: Flags) -> (f32, f32) {
        let pr = if flags.reflection() { r } else { 0.0 };
        let pt = if flags.transmission() { 1.0 - r } else { 0.0 };
        (pr, pt)
    }

    /// The generalized half vector of (wo, wi), on the upper side, with eta' (1 for a
    /// reflection); None where it is undefined or a microfacet would be seen from its back.
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        let reflect = cos_o * cos_i > 0.0;
        let etap = match (reflect, cos_o > 0.0) {
            (true, _) => 1.0,
            (false, true) => self.eta,
            (false, false) => 1.0 / self.eta,
        };
        let wm = wi * etap + wo;
        if cos_i == 0.0 || cos_o == 0.0 || wm.length_squared() == 0.0 {
            return None;
        }
        let wm = upper(wm.normalize());
        if wm.dot(wi) * cos_i < 0.0 || wm.dot(wo) * cos_o < 0.0 {
            return None;
        }
        Some((wm, etap))
    }
}

impl Interface for Dielectric {
    fn f(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        if self.eta == 1.0 || self.ggx.smooth() {
            return Rgb::ZERO;
        }
        let Some((wm, etap)) = self.half_vector(wo, wi) else {
            return Rgb::ZERO;
        };
        let (cos_o, cos_i) = (wo.z, wi.z);
        let f = fr_dielectric(wo.dot(wm), self.eta);
        let (d, g) = (self.ggx.d(wm), self.ggx.g(wo, wi));
        let value = if etap == 1.0 && same_hemisphere(wo, wi) {
            d * g * f / (4.0 * cos_i * cos_o).abs()
        } else {
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2) * cos_i * cos_o;
            d * (1.0 - f)
                * g
                * (wi.dot(wm) * wo.dot(wm) / denom).abs()
                * transmission_scale(mode, etap)
        };
        Rgb::splat(if value.is_finite() { value } else { 0.0 })
    }

    fn sample(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        flags: Flags,
    ) -> Option<Scatter> {
        if self.eta == 1.0 || self.ggx.smooth() {
            // A specular interface: reflection with probability R, else refraction.
            let r = fr_dielectric(wo.z, self.eta);
            let (pr, pt) = Self::choice(r, flags);
            if pr == 0.0 && pt == 0.0 {
                return None;
            }
            if uc < pr / (pr + pt) {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                return Some(Scatter {
                    wi,
                    f: Rgb::splat(r / wi.z.abs()),
                    pdf: pr / (pr + pt),
                    specular: true,
                    reflection: true,
                });
            }
            let (wi, etap) = refract(wo, Vec3::Z, self.eta)?;
            if wi.z == 0.0 {
                return None;
            }
            let ft = (1.0 - r) / wi.z.abs() * transmission_scale(mode, etap);
            return Some(Scatter {
                wi,
                f: Rgb::splat(ft),
                pdf: pt / (pr + pt),
                specular: true,
                reflection: false,
            });
        }
        // A rough interface: a visible microfacet, then reflection or refraction about it.
        if wo.z == 0.0 {
            return None;
        }
        let wm = self.ggx.sample_wm(wo, u)?;
        let r = fr_dielectric(wo.dot(wm), self.eta);
        let (pr, pt) = Self::choice(r, flags);
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        let (wi, f, pdf, reflection) = if uc < pr / (pr + pt) {
            let wi = reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return None;
            }
            let pdf = self.ggx.pdf(wo, wm) / (4.0 * wo.dot(wm).abs()) * pr / (pr + pt);
            let f = self.ggx.d(wm) * self.ggx.g(wo, wi) * r / (4.0 * wi.z * wo.z).abs();
            (wi, f, pdf, true)
        } else {
            let (wi, etap) = refract(wo, wm, self.eta)?;
            if same_hemisphere(wo, wi) || wi.z == 0.0 {
                return None;
            }
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2);
            let dwm_dwi = wi.dot(wm).abs() / denom;
            let pdf = self.ggx.pdf(wo, wm) * dwm_dwi * pt / (pr + pt);
            let f = (1.0 - r)
                * self.ggx.d(wm)
                * self.ggx.g(wo, wi)
                * (wi.dot(wm) * wo.dot(wm) / (wi.z * wo.z * denom)).abs()
                * transmission_scale(mode, etap);
            (wi, f, pdf, false)
        };
        (pdf > 0.0 && pdf.is_finite() && f.is_finite()).then_some(Scatter {
            wi,
            f: Rgb::splat(f),
            pdf,
            specular: false,
            reflection,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, flags: Flags) -> f32 {
        if self.eta == 1.0 || self.ggx.smooth() {
            return 0.0;
        }
        let Some((wm, etap)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let r = fr_dielectric(wo.dot(wm), self.eta);
        let (pr, pt) = Self::choice(r, flags);
        if pr == 0.0 && pt == 0.0 {
            return 0.0;
        }
        let pdf = if etap == 1.0 && same_hemisphere(wo, wi) {
            self.ggx.pdf(wo, wm) / (4.0 * wo.dot(wm).abs()) * pr / (pr + pt)
        } else {
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2);
            self.ggx.pdf(wo, wm) * wi.dot(wm).abs() / denom * pt / (pr + pt)
        };
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    fn specular(&self) -> bool {
        self.eta == 1.0 || self.ggx.smooth()
    }

    fn roughness(&self) -> f32 {
        if self.specular() {
            0.0
        } else {
            self.ggx.distribution.roughness()
        }
    }
}

/// The Lambertian base of `coateddiffuse` (pbrt's `DiffuseBxDF`): reflection on either side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    pub reflectance: Rgb,
}

impl Interface for Diffuse {
    fn f(&self, wo: Vec3, wi: Vec3, _: TransportMode) -> Rgb {
        if same_hemisphere(wo, wi) {
            self.reflectance * FRAC_1_PI
        } else {
            Rgb::ZERO
        }
    }

    fn sample(&self, wo: Vec3, _: f32, u: Vec2, _: TransportMode, flags: Flags) -> Option<Scatter> {
        if !flags.reflection() {
            return None;
        }
        let mut wi = cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        Some(Scatter {
            wi,
            f: self.reflectance * FRAC_1_PI,
            pdf: wi.z.abs() * FRAC_1_PI,
            specular: false,
            reflection: true,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, flags: Flags) -> f32 {
        if flags.reflection() && same_hemisphere(wo, wi) {
            wi.z.abs() * FRAC_1_PI
        } else {
            0.0
        }
    }

    fn specular(&self) -> bool {
        false
    }

    fn roughness(&self) -> f32 {
        f32::INFINITY
    }
}

/// The metal base of `coatedconductor` (pbrt's `ConductorBxDF`): microfacet reflection with
/// the Fresnel reflectance of the complex index `eta` + i `k`, relative to the coat.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    pub ggx: Ggx,
    pub eta: Rgb,
    pub k: Rgb,
}

impl Conductor {
    fn fresnel(&self, cos: f32) -> Rgb {
        Rgb::new(
            fresnel_conductor(cos, self.eta.x, self.k.x),
            fresnel_conductor(cos, self.eta.y, self.k.y),
            fresnel_conductor(cos, self.eta.z, self.k.z),
        )
    }
}

impl Interface for Conductor {
    fn f(&self, wo: Vec3, wi: Vec3, _: TransportMode) -> Rgb {
        if !same_hemisphere(wo, wi) || self.ggx.smooth() {
            return Rgb::ZERO;
        }
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        let wm = wi + wo;
        if cos_i == 0.0 || cos_o == 0.0 || wm.length_squared() == 0.0 {
            return Rgb::ZERO;
        }
        let wm = wm.normalize();
        let f = self.fresnel(wo.dot(wm).abs());
        f * (self.ggx.d(upper(wm)) * self.ggx.g(wo, wi) / (4.0 * cos_i * cos_o))
    }

    fn sample(&self, wo: Vec3, _: f32, u: Vec2, _: TransportMode, flags: Flags) -> Option<Scatter> {
        if !flags.reflection() {
            return None;
        }
        if self.ggx.smooth() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let cos = wi.z.abs();
            if cos == 0.0 {
                return None;
            }
            return Some(Scatter {
                wi,
                f: self.fresnel(cos) / cos,
                pdf: 1.0,
                specular: true,
                reflection: true,
            });
        }
        if wo.z == 0.0 {
            return None;
        }
        let wm = self.ggx.sample_wm(wo, u)?;
        let wi = reflect(wo, wm);
        if !same_hemisphere(wo, wi) {
            return None;
        }
        let pdf = self.ggx.pdf(wo, wm) / (4.0 * wo.dot(wm).abs());
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        if cos_i == 0.0 || !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let f = self.fresnel(wo.dot(wm).abs())
            * (self.ggx.d(wm) * self.ggx.g(wo, wi) / (4.0 * cos_i * cos_o));
        Some(Scatter {
            wi,
            f,
            pdf,
            specular: false,
            reflection: true,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, flags: Flags) -> f32 {
        if !flags.reflection() || !same_hemisphere(wo, wi) || self.ggx.smooth() {
            return 0.0;
        }
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return 0.0;
        }
        let wm = upper(wm.normalize());
        self.ggx.pdf(wo, wm) / (4.0 * wo.dot(wm).abs())
    }

    fn specular(&self) -> bool {
        self.ggx.smooth()
    }

    fn roughness(&self) -> f32 {
        if self.specular() {
            0.0
        } else {
            self.ggx.distribution.roughness()
        }
    }
}

/// pbrt-v4's `LayeredBxDF<DielectricBxDF, Base, true>`: the coat `top` at height
/// `thickness`, the `base` at 0, the slab between them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layered<B> {
    pub top: Dielectric,
    pub base: B,
    pub thickness: f32,
    pub albedo: Rgb,
    pub g: f32,
    pub max_depth: u32,
    pub n_samples: u32,
}

/// Transmittance through the slab of unit extinction across a height `dz` along `w`.
fn tr(dz: f32, w: Vec3) -> f32 {
    if dz.abs() <= f32::MIN_POSITIVE {
        return 1.0;
    }
    (-(dz / w.z).abs()).exp()
}

/// The generator of one estimate, keyed by the bits of two directions (pbrt's
/// `RNG(Hash(seed, a), Hash(b))`); -0 and 0 hash alike.
fn rng_of(a: Vec3, b: [f32; 3]) -> Rng {
    let bits = |x: f32| u64::from((x + 0.0).to_bits());
    let pair = |x: f32, y: f32| bits(x) | (bits(y) << 32);
    Rng::new(&[
        SEED,
        pair(a.x, a.y),
        bits(a.z),
        pair(b[0], b[1]),
        bits(b[2]),
    ])
}

/// The density with which the exit's sample from `wi` (`wis` of [`Layered::f`]) produces
/// the walk's direction `w` under the coat: the other technique's pdf, in the same measure
/// (solid angle inside), for the multiple-importance weight of an exit found by the walk.
///
/// pbrt-v4 weighs these with the coat's pdf the other way round, `top.PDF(-w, wi)`, a
/// density over the outside direction wi: the two techniques' weights then do not sum to
/// one and a rough coat's f is biased (by about 8% on a white base under roughness 0.1: pbrt-v4's
/// own renders of a rough coat by BSDF sampling alone and by light sampling alone disagree,
/// docs/pbrt.md). This is the one place the
/// walk departs from pbrt's.
fn exit_pdf(top: &Dielectric, wi: Vec3, w: Vec3) -> f32 {
    top.pdf(wi, -w, Flags::Transmission)
}

/// A usable interface sample (pbrt's `!bs || !bs->f || bs->pdf == 0 || bs->wi.z == 0`
/// rejected).
fn usable(s: Option<Scatter>) -> Option<Scatter> {
    s.filter(|s| s.f != Rgb::ZERO && s.pdf > 0.0 && s.wi.z != 0.0)
}

impl<B: Interface> Layered<B> {
    fn phase(&self) -> Phase {
        Phase::HenyeyGreenstein { g: self.g }
    }

    fn scatters(&self) -> bool {
        self.albedo != Rgb::ZERO
    }

    /// Whether every path through the layers is a chain of deltas.
    fn all_specular(&self) -> bool {
        self.top.specular() && self.base.specular() && !self.scatters()
    }

    /// pbrt's `LayeredBxDF::f` (without the cosine) for `wo` above the surface and `wi` on
    /// the same side: the coat's reflection, plus `n_samples` random walks entering through
    /// the coat, each adding next-event estimates towards `wi` at the base and in the slab.
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let mode = TransportMode::Radiance;
        let n = self.n_samples.max(1);
        let (top, base, thickness) = (&self.top, &self.base, self.thickness);
        // Entering and leaving through the coat, at height `thickness`.
        let exit_z = thickness;
        let mut f = n as f32 * top.f(wo, wi, mode);
        let mut rng = rng_of(wo, wi.to_array());
        let mut r = move || rng.next_f32();
        let phase = self.phase();
        for _ in 0..n {
            let Some(wos) =
                usable(top.sample(wo, r(), Vec2::new(r(), r()), mode, Flags::Transmission))
            else {
                continue;
            };
            // The exit, sampled from wi as light would come (the adjoint quantity).
            let Some(wis) = usable(top.sample(
                wi,
                r(),
                Vec2::new(r(), r()),
                TransportMode::Importance,
                Flags::Transmission,
            )) else {
                continue;
            };
            let mut beta = wos.f * wos.wi.z.abs() / wos.pdf;
            let mut z = thickness;
            let mut w = wos.wi;
            for depth in 0..self.max_depth {
                // Russian roulette.
                if depth > 3 && beta.max_element() < 0.25 {
                    let q = (1.0 - beta.max_element()).max(0.0);
                    if r() < q {
                        break;
                    }
                    beta /= 1.0 - q;
                }
                if !self.scatters() {
                    // Straight to the other interface.
                    z = if z == thickness { 0.0 } else { thickness };
                    beta *= tr(thickness, w);
                } else {
                    // A free flight in the slab (unit extinction).
                    let dz = -(1.0 - r()).ln() * w.z.abs();
                    let zp = if w.z > 0.0 { z + dz } else { z - dz };
                    if zp == z {
                        continue;
                    }
                    if 0.0 < zp && zp < thickness {
                        // Scattering in the slab: next-event estimate through the exit along
                        // wis, MIS-weighted against the phase function's own sampling.
                        let exit_dir = -wis.wi;
                        let p = phase.eval(w.dot(exit_dir));
                        let wt = if top.specular() {
                            1.0
                        } else {
                            power_heuristic(wis.pdf, p)
                        };
                        f += beta
                            * self.albedo
                            * (p * wt * tr(zp - exit_z, wis.wi) / wis.pdf)
                            * wis.f;
                        // Then the phase function's direction.
                        let (w_new, ps_pdf) = phase.sample(w, Vec2::new(r(), r()));
                        if ps_pdf == 0.0 || w_new.z == 0.0 {
                            continue;
                        }
                        // p / pdf = 1 for Henyey-Greenstein, sampled exactly.
                        beta *= self.albedo;
                        w = w_new;
                        z = zp;
                        // Its own estimate through a rough exit, MIS-weighted likewise.
                        if ((z < exit_z && w.z > 0.0) || (z > exit_z && w.z < 0.0))
                            && !top.specular()
                        {
                            let f_exit = top.f(-w, wi, mode);
                            if f_exit != Rgb::ZERO {
                                // The density with which wis would have been this
                                // direction (see `exit_pdf`).
                                let exit_pdf = exit_pdf(top, wi, w);
                                let wt = power_heuristic(ps_pdf, exit_pdf);
                                f += beta * tr(zp - exit_z, w) * f_exit * wt;
                            }
                        }
                        continue;
                    }
                    z = zp.clamp(0.0, thickness);
                }
                if z == exit_z {
                    // Back from below the coat: its internal reflection.
                    let Some(bs) =
                        usable(top.sample(-w, r(), Vec2::new(r(), r()), mode, Flags::Reflection))
                    else {
                        break;
                    };
                    beta *= bs.f * bs.wi.z.abs() / bs.pdf;
                    w = bs.wi;
                } else {
                    // At the base: next-event estimate through the exit along wis...
                    if !base.specular() {
                        let wt = if top.specular() {
                            1.0
                        } else {
                            power_heuristic(wis.pdf, base.pdf(-w, -wis.wi, Flags::All))
                        };
                        f += beta
                            * base.f(-w, -wis.wi, mode)
                            * (wis.wi.z.abs() * wt * tr(thickness, wis.wi) / wis.pdf)
                            * wis.f;
                    }
                    // ...then the base's own direction...
                    let Some(bs) =
                        usable(base.sample(-w, r(), Vec2::new(r(), r()), mode, Flags::Reflection))
                    else {
                        break;
                    };
                    beta *= bs.f * bs.wi.z.abs() / bs.pdf;
                    w = bs.wi;
                    // ...and its estimate through a rough exit.
                    if !top.specular() {
                        let f_exit = top.f(-w, wi, mode);
                        if f_exit != Rgb::ZERO {
                            let wt = if base.specular() {
                                1.0
                            } else {
                                power_heuristic(bs.pdf, exit_pdf(top, wi, w))
                            };
                            f += beta * tr(thickness, bs.wi) * f_exit * wt;
                        }
                    }
                }
            }
        }
        f / n as f32
    }

    /// pbrt's `LayeredBxDF::PDF` for `wo` above the surface and `wi` on the same side: the
    /// coat's reflection plus an estimate of transmission, base reflection, transmission,
    /// mixed with a tenth of the uniform density.
    fn pdf_estimate(&self, wo: Vec3, wi: Vec3) -> f32 {
        let mode = TransportMode::Radiance;
        let n = self.n_samples.max(1);
        let (top, base) = (&self.top, &self.base);
        let mut rng = rng_of(wi, wo.to_array());
        let mut r = move || rng.next_f32();
        let mut pdf_sum = n as f32 * top.pdf(wo, wi, Flags::Reflection);
        let valid = |s: Option<Scatter>| s.filter(|s| s.f != Rgb::ZERO && s.pdf > 0.0);
        for _ in 0..n {
            let wos = valid(top.sample(wo, r(), Vec2::new(r(), r()), mode, Flags::Transmission));
            let wis = valid(top.sample(
                wi,
                r(),
                Vec2::new(r(), r()),
                TransportMode::Importance,
                Flags::Transmission,
            ));
            let (Some(wos), Some(wis)) = (wos, wis) else {
                continue;
            };
            if top.specular() {
                pdf_sum += base.pdf(-wos.wi, -wis.wi, Flags::All);
                continue;
            }
            // Both transmissions are rough: MIS between the base's pdf at the pair of
            // sampled directions and the coat's at the base's sampled direction.
            let Some(rs) = valid(base.sample(-wos.wi, r(), Vec2::new(r(), r()), mode, Flags::All))
            else {
                continue;
            };
            if base.specular() {
                pdf_sum += top.pdf(-rs.wi, wi, Flags::All);
            } else {
                let r_pdf = base.pdf(-wos.wi, -wis.wi, Flags::All);
                pdf_sum += power_heuristic(wis.pdf, r_pdf) * r_pdf;
                let t_pdf = top.pdf(-rs.wi, wi, Flags::All);
                pdf_sum += power_heuristic(rs.pdf, t_pdf) * t_pdf;
            }
        }
        0.1 / (4.0 * PI) + 0.9 * pdf_sum / n as f32
    }

    /// pbrt's `LayeredBxDF::Sample_f` for `wo` above the surface: the coat's sample; if it
    /// refracts, a walk through the layers until it leaves through the coat. Returns the
    /// direction, the path's f (without the final cosine) and pdf, and whether every event
    /// was a delta.
    fn walk(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode) -> Option<Scatter> {
        let bs = usable(self.top.sample(wo, uc, u, mode, Flags::All))?;
        if bs.reflection {
            return Some(bs);
        }
        let mut w = bs.wi;
        let mut specular_path = bs.specular;
        let mut rng = rng_of(wo, [uc, u.x, u.y]);
        let mut r = move || rng.next_f32();
        let mut f = bs.f * bs.wi.z.abs();
        let mut pdf = bs.pdf;
        let mut z = self.thickness;
        let phase = self.phase();
        for depth in 0..self.max_depth {
            // Russian roulette on f / pdf.
            let rr_beta = f.max_element() / pdf;
            if depth > 3 && rr_beta < 0.25 {
                let q = (1.0 - rr_beta).max(0.0);
                if r() < q {
                    return None;
                }
                pdf *= 1.0 - q;
            }
            if w.z == 0.0 {
                return None;
            }
            if self.scatters() {
                let dz = -(1.0 - r()).ln() * w.z.abs();
                let zp = if w.z > 0.0 { z + dz } else { z - dz };
                if zp == z {
                    return None;
                }
                if 0.0 < zp && zp < self.thickness {
                    let (w_new, ps_pdf) = phase.sample(w, Vec2::new(r(), r()));
                    if ps_pdf == 0.0 || w_new.z == 0.0 {
                        return None;
                    }
                    f *= self.albedo * ps_pdf;
                    pdf *= ps_pdf;
                    specular_path = false;
                    w = w_new;
                    z = zp;
                    continue;
                }
                z = zp.clamp(0.0, self.thickness);
            } else {
                z = if z == self.thickness {
                    0.0
                } else {
                    self.thickness
                };
                f *= tr(self.thickness, w);
            }
            let (uc, u) = (r(), Vec2::new(r(), r()));
            let bs = if z == 0.0 {
                self.base.sample(-w, uc, u, mode, Flags::All)
            } else {
                self.top.sample(-w, uc, u, mode, Flags::All)
            };
            let bs = usable(bs)?;
            f *= bs.f;
            pdf *= bs.pdf;
            specular_path &= bs.specular;
            w = bs.wi;
            if !bs.reflection {
                // Out through the coat.
                return Some(Scatter {
                    wi: w,
                    f,
                    pdf,
                    specular: specular_path,
                    reflection: true,
                });
            }
            f *= bs.wi.z.abs();
        }
        None
    }
}

impl<B: Interface> Bxdf for Layered<B> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if !same_hemisphere(wo, wi) || !wo.is_finite() || !wi.is_finite() {
            return Rgb::ZERO;
        }
        // Two-sided: seen from below, both directions mirrored.
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        let f = self.f(wo, wi) * wi.z;
        if f.is_finite() { f } else { Rgb::ZERO }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) || !wo.is_finite() || !wi.is_finite() {
            return 0.0;
        }
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        let pdf = self.pdf_estimate(wo, wi);
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<LocalSample> {
        if !wo.is_finite() {
            return None;
        }
        let below = wo.z < 0.0;
        let wo = if below { -wo } else { wo };
        let s = self.walk(wo, uc, u, mode)?;
        if !same_hemisphere(wo, s.wi) {
            return None;
        }
        let weight = s.f * (s.wi.z.abs() / s.pdf);
        // A delta's pdf is its probability, as for the other lobes; otherwise the walk's pdf
        // is only that of its path: multiple importance sampling takes the estimate `pdf`
        // gives for the pair (pbrt's `pdfIsProportional`).
        let pdf = if s.specular {
            s.pdf
        } else {
            self.pdf_estimate(wo, s.wi)
        };
        if !(weight.is_finite() && pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(LocalSample {
            wi: if below { -s.wi } else { s.wi },
            weight,
            pdf,
            delta: s.specular,
        })
    }

    fn roughness(&self) -> f32 {
        if self.all_specular() {
            return 0.0;
        }
        // The sharpest rough interface; a diffuse base or a scattering slab alone: infinite.
        let rough = |x: f32| if x > 0.0 { x } else { f32::INFINITY };
        rough(self.top.roughness()).min(rough(self.base.roughness()))
    }

    fn delta_probability(&self, wo: Vec3) -> f32 {
        if !self.top.specular() {
            return 0.0;
        }
        if self.all_specular() {
            return 1.0;
        }
        // The coat's delta reflection, picked with its Fresnel reflectance.
        fr_dielectric(wo.z.abs(), self.top.eta)
    }
}

/// The parameters both coated kinds read the same way.
#[derive(Clone, Debug)]
pub struct SlabParams {
    pub thickness: f32,
    pub albedo: Texture,
    pub g: f32,
    pub max_depth: u32,
    pub n_samples: u32,
}

/// `thickness` (0.01), `albedo` (0, a texture), `g` (0, clamped to [-1, 1]), `maxdepth` (10)
/// and `nsamples` (1), as pbrt reads them.
pub fn read_slab(m: &Properties<'_>, resources: &mut dyn Resources) -> Result<SlabParams> {
    let thickness = m.f32("thickness", 0.01)?;
    if !(thickness >= 0.0 && thickness.is_finite()) {
        return Err(m.error("thickness", format!("must be >= 0, found {thickness}")));
    }
    let n_samples = m.u32("nsamples", 1)?;
    if n_samples == 0 {
        return Err(m.error("nsamples", "must be at least 1"));
    }
    Ok(SlabParams {
        // pbrt: at least the smallest normal float.
        thickness: thickness.max(f32::MIN_POSITIVE),
        albedo: super::reflectance(m, "albedo", Rgb::ZERO, resources)?,
        g: m.f32("g", 0.0)?.clamp(-1.0, 1.0),
        max_depth: m.u32("maxdepth", 10)?,
        n_samples,
    })
}

/// A GGX distribution from pbrt's `{prefix}roughness` (default 0) or `{prefix}uroughness`
/// and `{prefix}vroughness`, remapped when `remaproughness` (default true) says so.
pub fn read_ggx(m: &Properties<'_>, prefix: &str) -> Result<Ggx> {
    let key = |name: &str| format!("{prefix}{name}");
    let roughness = m.f32(&key("roughness"), 0.0)?;
    let u = m.f32(&key("uroughness"), roughness)?;
    let v = m.f32(&key("vroughness"), roughness)?;
    for (name, x) in [
        ("roughness", roughness),
        ("uroughness", u),
        ("vroughness", v),
    ] {
        if !(x >= 0.0 && x.is_finite()) {
            return Err(m.error(&key(name), format!("must be >= 0, found {x}")));
        }
    }
    Ok(Ggx::new(u, v, m.bool("remaproughness", true)?))
}

impl super::RoughnessTextures {
    /// A coat's or a base's distribution at surface coordinates `uv`.
    #[inline]
    pub fn ggx_at(&self, ctx: TextureEvalContext) -> Ggx {
        let (u, v) = self.values(ctx);
        Ggx::new(u, v, self.remap)
    }
}

/// [`read_ggx`], and where `roughness` (`uroughness`, `vroughness`) is a texture table, the
/// textures that give each point its own (the distribution then has their means).
pub fn read_ggx_textured(
    m: &Properties<'_>,
    prefix: &str,
    resources: &mut dyn Resources,
) -> Result<(Ggx, Option<super::RoughnessTextures>)> {
    let [r, u, v] = ["roughness", "uroughness", "vroughness"].map(|n| format!("{prefix}{n}"));
    if !super::any_texture_table(m, &[&r, &u, &v]) {
        return Ok((read_ggx(m, prefix)?, None));
    }
    let r = super::read_roughness_texture(m, &r, Some(0.0), resources)?;
    let mut read = |key: &str| -> Result<Texture> {
        if m.has(key) {
            super::read_roughness_texture(m, key, None, resources)
        } else {
            Ok(r.clone())
        }
    };
    let textures = super::RoughnessTextures {
        u: read(&u)?,
        v: read(&v)?,
        remap: m.bool("remaproughness", true)?,
    };
    let (mu, mv) = textures.means();
    Ok((Ggx::new(mu, mv, textures.remap), Some(textures)))
}

/// A relative index of refraction `key` (default 1.5), positive; pbrt takes 0 as 1.
pub fn read_eta(m: &Properties<'_>, key: &str) -> Result<f32> {
    let eta = m.f32(key, 1.5)?;
    if eta < 0.0 || !eta.is_finite() {
        return Err(m.error(key, format!("must be positive, found {eta}")));
    }
    Ok(if eta == 0.0 { 1.0 } else { eta })
}

#[cfg(test)]
mod tests;
