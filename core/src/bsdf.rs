//! The BSDF at a surface point (pbrt-v4's `BSDF`): a material's lobe with its textures looked
//! up there, in the local shading frame (z the shading normal, x along dp/du), with the
//! geometric normal kept for the corrections shading normals need.
//!
//! Conventions (Mitsuba 3's): both directions point away from the surface, `wo` towards the
//! viewer (or where a photon came from), `wi` the other one; `eval` is f(wo, wi) |cos theta_i|
//! with theta_i measured from the shading normal; one-sided lobes are black when either
//! direction lies below the shading frame.
//!
//! **Shading normals and photons.** Radiance and flux obey different scattering equations
//! once the shading normal differs from the geometric one (Veach 1997, section 5.3): a photon
//! (importance mode) scattered from `wo` to `wi` is weighted by f |wo.ns| |wi.ng| / |wo.ng|
//! instead of f |wi.ns|, and a photon arriving along `wi` with flux Phi gives a density
//! estimate f |wi.ns| / |wi.ng| Phi / A ([`Bsdf::eval_density`]). Both reduce to the usual
//! forms where ns = ng.

use crate::Rgb;
use crate::geometry::SurfacePoint;
use crate::material::diffuse::DiffuseBxdf;
use crate::material::{Lobe, Material};
use crate::sampling::basis;
use crate::scattering::TransportMode;
use crate::texture::TextureEvalContext;
use glam::{Vec2, Vec3};

pub use crate::scattering::LocalSample;

/// An orthonormal frame: `n` the normal, `s` and `t` the tangents.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// Any frame around `n` (unit).
    #[inline]
    pub fn from_normal(n: Vec3) -> Frame {
        let (s, t) = basis(n);
        Frame { s, t, n }
    }

    /// The frame around `n` whose `s` is `dpdu` made orthogonal to `n` (Gram-Schmidt, as
    /// Mitsuba orients its shading frame); any frame if `dpdu` is (nearly) along `n`.
    #[inline]
    pub fn from_normal_tangent(n: Vec3, dpdu: Vec3) -> Frame {
        let s = dpdu - n * n.dot(dpdu);
        let len2 = s.length_squared();
        // A tangent within about 0.06 degrees of the normal orients nothing reliably.
        if len2 <= 1e-6 * dpdu.length_squared() || len2.is_nan() {
            return Frame::from_normal(n);
        }
        let s = s / len2.sqrt();
        // Once more: the first subtraction loses digits when dpdu is nearly along n.
        let s = (s - n * n.dot(s)).normalize();
        Frame {
            s,
            t: n.cross(s),
            n,
        }
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// A sampled direction of a BSDF (world space).
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    /// f |cos theta_i| / pdf (importance mode: with the shading-normal correction): what the
    /// path throughput is multiplied by.
    pub weight: Rgb,
    /// Solid-angle pdf; for a delta lobe the probability of having chosen it.
    pub pdf: f32,
    pub delta: bool,
}

/// What Mitsuba puts on the light's side of a normal- or bump-mapped BSDF, the map having
/// tilted the shading normal away from the surface's own `base_n`: light arriving from the
/// other side of `base_n` than of the tilted normal is cut off (Mitsuba 0.6 and 3), and the
/// rest multiplied by Estevez et al.'s shadowing term (Ray Tracing Gems, 2019; Mitsuba 3's
/// `use_shadowing_function`) 2 / (1 + sqrt(1 + alpha^2 tan^2 theta)), theta the light's
/// angle to `base_n`, alpha^2 = min(tan^2 of the tilt / 8, 1). Not reciprocal: the light's
/// side is `wi` of [`Bsdf::eval`] and of radiance sampling, `wo` of importance sampling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightTerms {
    /// The surface's shading normal before the map; zero: no terms.
    pub base_n: Vec3,
    /// alpha^2 of the shadowing term; negative: no shadowing term (the cut-off alone).
    pub alpha2: f32,
}

impl LightTerms {
    /// No terms (every BSDF but a mapped one of a Mitsuba file).
    pub const NONE: LightTerms = LightTerms {
        base_n: Vec3::ZERO,
        alpha2: -1.0,
    };

    /// The terms for a map that tilted `base_n` to `n`, with the shadowing term if `shadowing`.
    pub fn new(base_n: Vec3, n: Vec3, shadowing: bool) -> LightTerms {
        let alpha2 = if shadowing {
            let c = n.dot(base_n).clamp(-1.0, 1.0);
            let tan2 = if c * c > 0.0 {
                (1.0 - c * c) / (c * c)
            } else {
                f32::INFINITY
            };
            (0.125 * tan2).min(1.0)
        } else {
            -1.0
        };
        LightTerms { base_n, alpha2 }
    }

    /// The factor on light arriving along `w` at a BSDF of shading normal `n`.
    #[inline]
    fn factor(&self, n: Vec3, w: Vec3) -> f32 {
        let c0 = w.dot(self.base_n);
        if c0 * w.dot(n) <= 0.0 {
            return 0.0;
        }
        if self.alpha2 < 0.0 {
            return 1.0;
        }
        let c2 = c0 * c0;
        let tan2 = ((1.0 - c2) / c2).max(0.0);
        2.0 / (1.0 + (1.0 + self.alpha2 * tan2).sqrt())
    }
}

/// The BSDF at a surface point.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    pub lobe: Lobe,
    /// The shading frame (its `n` is the shading normal).
    pub frame: Frame,
    /// The unit geometric normal (the primitive's orientation).
    pub ng: Vec3,
    /// A one-sided lobe seen from below acts as seen from above (Mitsuba's `twosided`): both
    /// directions are mirrored to the upper side.
    pub twosided: bool,
    /// [`LightTerms::NONE`] but on the normal- and bump-mapped surfaces of Mitsuba files.
    pub light_terms: LightTerms,
}

impl Bsdf {
    /// True when every part is a delta (mirror, smooth glass): photons are never stored there.
    #[inline]
    pub fn is_delta(&self) -> bool {
        self.lobe.is_delta()
    }

    /// The cosines of `wo` and `wi` with the shading normal, for a lobe that needs nothing
    /// else of the frame (the diffuse lobe is isotropic and flat: eval and pdf depend on the
    /// directions' z alone). Two dot products instead of the six of [`Bsdf::local`]: most
    /// surfaces of most scenes are diffuse, and each path vertex evaluates them once per
    /// light sample. `twosided` mirroring is left to the lobe (its own flag).
    #[inline]
    fn cosines(&self, wo: Vec3, wi: Vec3) -> (f32, f32) {
        (wo.dot(self.frame.n), wi.dot(self.frame.n))
    }

    /// `wo` and `wi` in the local frame, both mirrored to the upper side for a two-sided
    /// BSDF seen from below.
    #[inline]
    fn local(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
        let (mut wo, mut wi) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if self.twosided && wo.z < 0.0 {
            wo.z = -wo.z;
            wi.z = -wi.z;
        }
        (wo, wi)
    }

    /// f(wo, wi) |cos theta_i| (radiance: the cosine from the shading normal).
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let f = if let Lobe::Diffuse(d) = &self.lobe {
            let (cos_o, cos_i) = self.cosines(wo, wi);
            d.eval_cos(d.twosided || self.twosided, cos_o, cos_i)
        } else {
            let (wo, wi) = self.local(wo, wi);
            self.lobe.eval(wo, wi)
        };
        f * self.light_factor(wi)
    }

    /// The [`LightTerms`] factor on light arriving along `w`.
    #[inline]
    fn light_factor(&self, w: Vec3) -> f32 {
        if self.light_terms.base_n == Vec3::ZERO {
            1.0
        } else {
            self.light_terms.factor(self.frame.n, w)
        }
    }

    /// What a photon arriving along `wi` with unit flux gives the radiance towards `wo`, per
    /// unit area: f(wo, wi) |wi.ns| / |wi.ng| (f alone without shading normals).
    #[inline]
    pub fn eval_density(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let cos_g = wi.dot(self.ng).abs();
        if cos_g == 0.0 {
            return Rgb::ZERO;
        }
        self.eval(wo, wi) / cos_g
    }

    /// [`Bsdf::eval`] and [`Bsdf::pdf`] together (next-event estimation wants both), the
    /// directions taken to the local frame once.
    #[inline]
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let light = self.light_factor(wi);
        if let Lobe::Diffuse(d) = &self.lobe {
            let (cos_o, cos_i) = self.cosines(wo, wi);
            let twosided = d.twosided || self.twosided;
            return (
                d.eval_cos(twosided, cos_o, cos_i) * light,
                DiffuseBxdf::pdf_cos(twosided, cos_o, cos_i),
            );
        }
        let (wo, wi) = self.local(wo, wi);
        (self.lobe.eval(wo, wi) * light, self.lobe.pdf(wo, wi))
    }

    /// Solid-angle pdf with which `sample` produces `wi` (its non-delta part).
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if let Lobe::Diffuse(d) = &self.lobe {
            let (cos_o, cos_i) = self.cosines(wo, wi);
            return DiffuseBxdf::pdf_cos(d.twosided || self.twosided, cos_o, cos_i);
        }
        let (wo, wi) = self.local(wo, wi);
        self.lobe.pdf(wo, wi)
    }

    /// Samples `wi` for `wo` (see [`Lobe::sample`]); in importance mode the weight carries the
    /// shading-normal correction (module comment).
    #[inline]
    pub fn sample(&self, wo: Vec3, u: Vec2, uc: f32, mode: TransportMode) -> Option<BsdfSample> {
        let s = if let Lobe::Diffuse(d) = &self.lobe {
            // The diffuse lobe reads only wo's cosine (see `Bsdf::cosines`): its `sample`
            // with the two-sided mirroring folded in. Black from below a one-sided lobe; the
            // cosine-weighted direction is taken to wo's side.
            let cos_o = wo.dot(self.frame.n);
            if cos_o == 0.0 || (cos_o < 0.0 && !(d.twosided || self.twosided)) {
                return None;
            }
            d.sample_cos(cos_o, u)?
        } else {
            let mut local_wo = self.frame.to_local(wo);
            let below = self.twosided && local_wo.z < 0.0;
            if below {
                local_wo.z = -local_wo.z;
            }
            let mut s = self.lobe.sample(local_wo, u, uc, mode)?;
            if below {
                s.wi.z = -s.wi.z;
            }
            s
        };
        let wi = self.frame.to_world(s.wi);
        let mut weight = s.weight;
        if mode == TransportMode::Importance && self.frame.n != self.ng {
            let (cos_o_g, cos_i_s) = (wo.dot(self.ng).abs(), s.wi.z.abs());
            if cos_o_g == 0.0 || cos_i_s == 0.0 {
                return None;
            }
            weight *= (wo.dot(self.frame.n).abs() * wi.dot(self.ng).abs()) / (cos_o_g * cos_i_s);
        }
        if self.light_terms.base_n != Vec3::ZERO {
            // The light arrives along the sampled direction in radiance transport, along wo in
            // importance transport.
            weight *= self.light_factor(match mode {
                TransportMode::Radiance => wi,
                TransportMode::Importance => wo,
            });
        }
        Some(BsdfSample {
            wi,
            weight,
            pdf: s.pdf,
            delta: s.delta,
        })
    }

    /// See [`Lobe::roughness`].
    #[inline]
    pub fn roughness(&self) -> f32 {
        self.lobe.roughness()
    }

    /// See [`Lobe::delta_probability`].
    #[inline]
    pub fn delta_probability(&self, wo: Vec3) -> f32 {
        let (wo, _) = self.local(wo, wo);
        self.lobe.delta_probability(wo)
    }
}

impl Material {
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
        self.bsdf_in(sp.p, sp.texture_ctx(), sp.ng, frame)
    }

    /// The BSDF at a point of a flat surface whose material needs no texture coordinates and
    /// no tangent ([`Material::needs_coordinates`] false): the shading normal is the
    /// geometric one `ng`, and the frame any frame around it, as [`Material::bsdf`] makes it
    /// for such a point. (The scene's hit queries call this where they can: the frame is then
    /// built without testing a tangent that is known to be zero.)
    #[inline]
    pub fn flat_bsdf(&self, ng: Vec3) -> Option<Bsdf> {
        self.bsdf_in(Vec3::ZERO, TextureEvalContext::default(), ng, || {
            Frame::from_normal(ng)
        })
    }

    /// The BSDF at point `p` (which only a blend reads) with its textures looked up at `ctx`,
    /// the geometric normal `ng`, and the shading frame `frame` makes (not made for the null
    /// material).
    #[inline(always)]
    fn bsdf_in(
        &self,
        p: Vec3,
        ctx: TextureEvalContext,
        ng: Vec3,
        frame: impl FnOnce() -> Frame,
    ) -> Option<Bsdf> {
        let (lobe, twosided) = self.lobe_at(p, ctx)?;
        Some(Bsdf {
            lobe,
            frame: frame(),
            ng,
            twosided,
            light_terms: LightTerms::NONE,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::FRAC_1_PI;

    #[test]
    fn frames_are_orthonormal_and_invert() {
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        for f in [
            Frame::from_normal(n),
            Frame::from_normal_tangent(n, Vec3::new(1.0, 2.0, 0.5)),
            Frame::from_normal_tangent(n, n * 3.0),
        ] {
            assert!((f.s.dot(f.t)).abs() < 1e-6 && (f.s.dot(f.n)).abs() < 1e-6);
            assert!((f.s.length() - 1.0).abs() < 1e-6 && (f.t.length() - 1.0).abs() < 1e-6);
            // Right-handed: s x t = n.
            assert!((f.s.cross(f.t) - f.n).length() < 1e-5);
            let v = Vec3::new(0.2, 0.7, -0.4);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-6);
        }
        let f = Frame::from_normal_tangent(Vec3::Z, Vec3::new(2.0, 0.0, 1.0));
        assert!((f.s - Vec3::X).length() < 1e-6);
    }

    /// The diffuse lobe's shortcut (cosines with the normal, no local frame) gives exactly
    /// what the lobe gives in the local frame, from both sides, one- and two-sided.
    #[test]
    fn diffuse_shortcut_matches_the_local_frame() {
        let mut rng = crate::sampling::Rng::new(&[7]);
        let mut dir = || crate::sampling::uniform_sphere(rng.next_2d());
        for twosided_lobe in [false, true] {
            for twosided in [false, true] {
                let n = dir();
                let bsdf = Bsdf {
                    lobe: Lobe::Diffuse(DiffuseBxdf {
                        reflectance: Rgb::new(0.7, 0.4, 0.2),
                        twosided: twosided_lobe,
                    }),
                    frame: Frame::from_normal_tangent(n, dir()),
                    ng: n,
                    twosided,
                    light_terms: LightTerms::NONE,
                };
                for _ in 0..200 {
                    let (wo, wi) = (dir(), dir());
                    let (lo, li) = bsdf.local(wo, wi);
                    let (f, pdf) = bsdf.eval_pdf(wo, wi);
                    assert_eq!(f, bsdf.lobe.eval(lo, li));
                    assert_eq!(pdf, bsdf.lobe.pdf(lo, li));
                    assert_eq!(bsdf.eval(wo, wi), f);
                    assert_eq!(bsdf.pdf(wo, wi), pdf);
                    // A sampled direction's weight and pdf are those eval and pdf give it.
                    let u = Vec2::new(0.37, 0.81);
                    if let Some(s) = bsdf.sample(wo, u, 0.5, TransportMode::Radiance) {
                        let (f, pdf) = bsdf.eval_pdf(wo, s.wi);
                        assert!((s.pdf - pdf).abs() < 1e-5, "{} {pdf}", s.pdf);
                        assert!((s.weight * s.pdf - f).abs().max_element() < 1e-5);
                    } else {
                        assert_eq!(bsdf.pdf(wo, wo), 0.0);
                    }
                }
            }
        }
    }

    #[test]
    fn shading_correction_only_where_normals_differ() {
        let lobe = Lobe::Diffuse(DiffuseBxdf {
            reflectance: Rgb::splat(0.5),
            twosided: true,
        });
        let ng = Vec3::Z;
        let flat = Bsdf {
            lobe,
            frame: Frame::from_normal(ng),
            ng,
            twosided: false,
            light_terms: LightTerms::NONE,
        };
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let (u, uc) = (Vec2::new(0.3, 0.7), 0.5);
        let a = flat.sample(wo, u, uc, TransportMode::Radiance).unwrap();
        let b = flat.sample(wo, u, uc, TransportMode::Importance).unwrap();
        assert_eq!(a.weight, b.weight);
        // A tilted shading normal: radiance weight f |wi.ns| / pdf = rho; importance weight
        // rho |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|).
        let ns = Vec3::new(0.2, 0.0, 1.0).normalize();
        let tilted = Bsdf {
            lobe,
            frame: Frame::from_normal(ns),
            ng,
            twosided: false,
            light_terms: LightTerms::NONE,
        };
        let r = tilted.sample(wo, u, uc, TransportMode::Radiance).unwrap();
        let i = tilted.sample(wo, u, uc, TransportMode::Importance).unwrap();
        assert!((r.weight - Rgb::splat(0.5)).length() < 1e-6);
        let expected =
            0.5 * wo.dot(ns).abs() * i.wi.dot(ng).abs() / (wo.dot(ng).abs() * i.wi.dot(ns).abs());
        assert!(
            (i.weight.x - expected).abs() < 1e-5,
            "{} {expected}",
            i.weight.x
        );
        // The density estimate's factor.
        let wi = Vec3::new(-0.3, 0.1, 0.9).normalize();
        let d = tilted.eval_density(wo, wi);
        let want = 0.5 * FRAC_1_PI * wi.dot(ns) / wi.dot(ng);
        assert!((d.x - want).abs() < 1e-6);
    }
}
