//! Area lights: an emissive shape (any shape given an `emission`; in Mitsuba files, an
//! `area` emitter inside a shape) emits `radiance` on the side its geometric normal points
//! to, and nothing on the other side, unless it is two-sided (pbrt-v4's `twosided`: the
//! same radiance on both sides, twice the power). They are made with their shapes, never
//! from a `[[lights]]` entry: the factory's error says where they go.

use super::{EmittedRay, Light, LightSample, LightSource, LightType};
use crate::Rgb;
use crate::geometry::{Shape, TriangleAttrs};
use crate::registry::Factory;
use crate::sampling::{Distribution1D, cosine_hemisphere, to_world};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The emitting primitives (one for a sphere or quad, the triangles of a mesh).
    pub shapes: Vec<Shape>,
    /// Chooses a shape proportionally to its area.
    pub by_area: Distribution1D,
    pub area: f32,
    /// W/(sr m^2): the radiance, or its scale where a texture gives it.
    pub radiance: Rgb,
    /// What varies over the surface (a radiance texture, a cut-out), looked up at the
    /// surface's texture coordinates; None: `radiance` everywhere.
    pub texture: Option<Arc<EmissionTexture>>,
    /// The scene object that emits.
    pub object: u32,
    /// Whether it emits on both sides.
    pub twosided: bool,
}

/// What varies over an area light's surface, with what finds the texture coordinates at a
/// point the light samples: each shape's mesh attributes (as the scene holds them for its
/// hits).
#[derive(Clone, Debug)]
pub struct EmissionTexture {
    /// The radiance's factor (Mitsuba's textured `radiance`, pbrt-v4's image); None: 1.
    pub texture: Option<Texture>,
    /// The shape's cut-out (its `alpha`, a grey texture): a ray meets the surface with
    /// probability alpha ([`crate::scene::Scene`]'s cut-out test), so a point the light
    /// samples emits alpha times the radiance, a point a ray finds the radiance (pbrt-v4's
    /// `DiffuseAreaLight` with `alpha`, in expectation). None: opaque.
    pub alpha: Option<Texture>,
    /// Per shape, in the order of [`AreaLight::shapes`] (empty: no shape has attributes).
    pub attrs: Vec<TriangleAttrs>,
    /// The mean over the light's area of alpha times the texture (its power's factor).
    mean: Rgb,
}

impl AreaLight {
    /// The area light over the given shapes, the scene object `object`.
    pub fn new(shapes: Vec<Shape>, radiance: Rgb, object: u32) -> AreaLight {
        let areas: Vec<f32> = shapes.iter().map(|s| s.area()).collect();
        let area = areas.iter().sum();
        AreaLight {
            by_area: Distribution1D::new(&areas),
            shapes,
            area,
            radiance,
            texture: None,
            object,
            twosided: false,
        }
    }

    /// The light emitting on both sides of its shapes when `twosided`.
    pub fn with_twosided(self, twosided: bool) -> AreaLight {
        AreaLight { twosided, ..self }
    }

    /// The light whose radiance is `radiance` times `texture` (if any) at the surface's
    /// texture coordinates, cut out by `alpha` (if any); `attrs` gives each shape's mesh
    /// attributes (empty if none has any).
    pub fn with_texture(
        self,
        texture: Option<Texture>,
        alpha: Option<Texture>,
        attrs: Vec<TriangleAttrs>,
    ) -> AreaLight {
        if texture.is_none() && alpha.is_none() {
            return self;
        }
        let mut t = EmissionTexture {
            texture,
            alpha,
            attrs,
            mean: Rgb::ONE,
        };
        // The mean by area: a grid of points on each shape, finer where there are few.
        let per_side = ((4096 / self.shapes.len().max(1)) as f32).sqrt().max(4.0) as usize;
        let mut sum = glam::DVec3::ZERO;
        for (i, shape) in self.shapes.iter().enumerate() {
            let mut shape_sum = glam::DVec3::ZERO;
            for a in 0..per_side {
                for b in 0..per_side {
                    let u = Vec2::new(
                        (a as f32 + 0.5) / per_side as f32,
                        (b as f32 + 0.5) / per_side as f32,
                    );
                    let (p, n) = shape.sample_area(u);
                    shape_sum += t.sampled(t.uv(shape, i, p, n)).as_dvec3();
                }
            }
            sum += shape_sum * (shape.area() as f64 / (per_side * per_side) as f64);
        }
        t.mean = (sum / self.area.max(f32::MIN_POSITIVE) as f64).as_vec3();
        AreaLight {
            texture: Some(Arc::new(t)),
            ..self
        }
    }

    /// How many sides emit.
    #[inline]
    fn sides(&self) -> f32 {
        if self.twosided { 2.0 } else { 1.0 }
    }

    /// The radiance at point `p` (normal `n`) of shape `i`, a point the light sampled, and
    /// its texture coordinates (zero if nothing varies).
    #[inline]
    fn sampled_at(&self, i: usize, p: Vec3, n: Vec3) -> (Rgb, Vec2) {
        match &self.texture {
            None => (self.radiance, Vec2::ZERO),
            Some(t) => {
                let uv = t.uv(&self.shapes[i], i, p, n);
                (self.radiance * t.sampled(uv), uv)
            }
        }
    }

    /// The cut-out's opacity at `uv` (1 without one): what a point the light samples, not a
    /// ray, finds of its emission.
    #[inline]
    pub fn opacity(&self, uv: Vec2) -> f32 {
        self.texture.as_ref().map_or(1.0, |t| t.opacity(uv))
    }
}

impl EmissionTexture {
    /// The texture coordinates at point `p` (normal `n`) of `shape`, the light's `i`-th.
    fn uv(&self, shape: &Shape, i: usize, p: Vec3, n: Vec3) -> Vec2 {
        shape.surface_at(p, n, self.attrs.get(i), None, true).uv
    }

    /// The radiance's factor where a ray meets the surface at `uv`.
    #[inline]
    fn seen(&self, uv: Vec2) -> Rgb {
        self.texture.as_ref().map_or(Rgb::ONE, |t| t.eval(uv.into()))
    }

    /// The cut-out's opacity at `uv` (1 without one).
    fn opacity(&self, uv: Vec2) -> f32 {
        self.alpha
            .as_ref()
            .map_or(1.0, |a| crate::texture::scalar(a.eval(uv.into())).clamp(0.0, 1.0))
    }

    /// The radiance's factor at a sampled point: times the opacity there.
    fn sampled(&self, uv: Vec2) -> Rgb {
        self.seen(uv) * self.opacity(uv)
    }
}

/// [`AreaLight::new`] as a [`Light`].
pub fn area_light(shapes: Vec<Shape>, radiance: Rgb, object: u32) -> Light {
    Light::Area(AreaLight::new(shapes, radiance, object))
}

/// The cone of directions a sphere subtends from a point outside it: sin^2 and 1 - cos of its
/// half-angle theta_max. 1 - cos is taken as sin^2 / (1 + cos), which has no cancellation:
/// sqrt(1 - r^2/d^2) rounds to 1 in 32-bit floats once r/d falls below about 2e-4 (the pdf
/// 1 / (2 pi (1 - cos)) is then infinite), and is visibly off well before. pbrt-v4 switches
/// to a Taylor series below 1.5 degrees for the same reason; the identity is exact at every
/// angle.
#[derive(Clone, Copy, Debug)]
struct SphereCone {
    sin2_max: f32,
    one_minus_cos_max: f32,
}

impl SphereCone {
    /// None at points inside the sphere or on it (those sample its area instead).
    fn from(center: Vec3, radius: f32, x: Vec3) -> Option<SphereCone> {
        let d2 = (center - x).length_squared();
        let r2 = radius * radius;
        // Written so that a NaN distance gives None too.
        if d2.partial_cmp(&(r2 * 1.0001)) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let sin2_max = r2 / d2;
        let cos_max = (1.0 - sin2_max).sqrt();
        Some(SphereCone {
            sin2_max,
            one_minus_cos_max: sin2_max / (1.0 + cos_max),
        })
    }

    /// Solid-angle pdf of a direction sampled uniformly in the cone.
    fn pdf(&self) -> f32 {
        1.0 / (2.0 * PI * self.one_minus_cos_max)
    }

    /// A direction uniform in the cone (in the frame whose z axis points at the centre) and
    /// the unit normal of the sphere where it first meets it, from the angle alpha at the
    /// centre between the receiver and that point (pbrt-v4's Sphere::Sample): no ray is
    /// intersected, so no sample misses the sphere however small it looks.
    fn sample(&self, u: Vec2) -> (Vec3, Vec3) {
        // 1 - cos theta uniform on [0, 1 - cos theta_max], sin^2 from it without cancellation.
        let one_minus_cos = u.x * self.one_minus_cos_max;
        let sin2 = (one_minus_cos * (2.0 - one_minus_cos)).min(self.sin2_max);
        let cos = 1.0 - one_minus_cos;
        let sin = sin2.sqrt();
        let ratio = sin2 / self.sin2_max;
        let cos_alpha = sin2 / self.sin2_max.sqrt() + cos * (1.0 - ratio).max(0.0).sqrt();
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * u.y).sin_cos();
        let wi = Vec3::new(sin * cos_phi, sin * sin_phi, cos);
        // The point lies on the side of the centre the direction leans to, facing back.
        let n = Vec3::new(sin_alpha * cos_phi, sin_alpha * sin_phi, -cos_alpha);
        (wi, n)
    }
}


impl LightSource for AreaLight {
    fn light_type(&self) -> LightType {
        LightType::Area
    }

    /// pi A L per emitting side (L the mean over the area of a textured radiance).
    fn power(&self) -> Rgb {
        let mean = self.texture.as_ref().map_or(Rgb::ONE, |t| t.mean);
        self.sides() * PI * self.area * self.radiance * mean
    }

    #[inline(never)]
    fn sample_li(&self, x: Vec3, u: Vec2, uc: f32) -> Option<LightSample> {
        let (i, _) = self.by_area.sample(uc);
        let shape = &self.shapes[i];
        if let Shape::Sphere {
            center,
            radius,
            inward,
            ..
        } = *shape
            && self.shapes.len() == 1
            && let Some(cone) = SphereCone::from(center, radius, x)
        {
            // Sample the cone of directions the sphere subtends (pbrt-v4's
            // Sphere::Sample(ctx)): every sample sees the near side.
            let axis = (center - x).normalize();
            let (wi, outward) = cone.sample(u);
            let (wi, outward) = (to_world(wi, axis), to_world(outward, axis));
            let p = center + outward * radius;
            // A sphere turned inside out is dark from outside.
            let n = if inward { -outward } else { outward };
            return Some(LightSample {
                wi,
                dist: x.distance(p),
                li: if inward && !self.twosided {
                    Rgb::ZERO
                } else {
                    self.sampled_at(0, p, n).0
                },
                pdf: cone.pdf(),
                delta: false,
                p,
                n,
            });
        }
        let (p, n) = shape.sample_area(u);
        let d = p - x;
        let dist2 = d.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = d / dist;
        let mut cos_l = n.dot(-wi);
        if self.twosided {
            cos_l = cos_l.abs();
        }
        if cos_l <= 0.0 {
            return None;
        }
        Some(LightSample {
            wi,
            dist,
            li: self.sampled_at(i, p, n).0,
            pdf: dist2 / (cos_l * self.area),
            delta: false,
            p,
            n,
        })
    }

    fn pdf_li(&self, x: Vec3, p: Vec3, n: Vec3) -> f32 {
        if let Shape::Sphere { center, radius, .. } = self.shapes[0]
            && self.shapes.len() == 1
            && let Some(cone) = SphereCone::from(center, radius, x)
        {
            return cone.pdf();
        }
        let d = p - x;
        let cos_l = n.dot(-d.normalize()).abs();
        if cos_l == 0.0 {
            return 0.0;
        }
        d.length_squared() / (cos_l * self.area)
    }

    #[inline]
    fn emitted(&self, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        let cos = n.dot(w);
        if cos > 0.0 || (self.twosided && cos < 0.0) {
            match &self.texture {
                None => self.radiance,
                Some(t) => self.radiance * t.seen(uv),
            }
        } else {
            Rgb::ZERO
        }
    }

    /// A uniform point, a cosine-distributed direction on its normal side (two-sided: on
    /// either side with probability 1/2, the first direction number choosing it).
    fn sample_emission(&self, u_pos: Vec2, u_dir: Vec2, uc: f32) -> EmittedRay {
        let (i, _) = self.by_area.sample(uc);
        let (p, mut n) = self.shapes[i].sample_area(u_pos);
        let (le, uv) = self.sampled_at(i, p, n);
        let mut u_dir = u_dir;
        if self.twosided {
            if u_dir.x < 0.5 {
                u_dir.x *= 2.0;
            } else {
                u_dir.x = (2.0 * u_dir.x - 1.0).min(crate::sampling::ONE_MINUS_EPSILON);
                n = -n;
            }
        }
        let local = cosine_hemisphere(u_dir);
        EmittedRay {
            origin: p,
            dir: to_world(local, n),
            n,
            // L cos / (1/A * cos/(sides pi)) = sides pi A L
            flux: self.sides() * PI * self.area * le,
            le,
            uv,
            pdf_pos: 1.0 / self.area,
            pdf_dir: local.z * std::f32::consts::FRAC_1_PI / self.sides(),
        }
    }

    fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        let cos = if self.twosided {
            n.dot(dir).abs() / 2.0
        } else {
            n.dot(dir).max(0.0)
        };
        (1.0 / self.area, cos * std::f32::consts::FRAC_1_PI)
    }
}

pub const FACTORY: Factory<AreaLight> = Factory {
    name: "area",
    description: "an emissive shape (a shape's `emission`)",
    create: |l, _, _| {
        Err(l.error(
            "type",
            "an area light is a shape that emits: give the shape `emission = [r, g, b]` \
             (W/(sr m^2)) instead of a [[lights]] entry",
        ))
    },
};
