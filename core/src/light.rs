//! Lights: point lights, spot lights and area lights (any emissive shape), and lights at
//! infinity (directional, constant and environment-mapped). An area light emits radiance
//! `radiance` on the side its geometric normal points to, and nothing on the other side.

use crate::Rgb;
use crate::envmap::EnvironmentMap;
use crate::geometry::Shape;
use crate::sampling::{Distribution1D, to_world, uniform_cone};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub enum Light {
    Point {
        position: Vec3,
        /// W/sr.
        intensity: Rgb,
    },
    /// A point light emitting in a cone (Mitsuba's `spot`): intensity `intensity` within
    /// `beam_width` of the axis, falling linearly in angle to zero at `cutoff`.
    Spot {
        position: Vec3,
        /// Unit direction of the cone's axis.
        axis: Vec3,
        /// W/sr at the centre.
        intensity: Rgb,
        /// Angles (radians) from the axis: full intensity within `beam_width`, none past
        /// `cutoff`.
        beam_width: f32,
        cutoff: f32,
    },
    /// Parallel light from infinitely far (Mitsuba's `directional`, a sun), travelling along
    /// `direction` and giving `irradiance` (W/m^2) to a surface facing it. Its photons leave a
    /// disc of the scene's bounding sphere (`centre`, `radius`, set once the scene is loaded),
    /// as pbrt's distant light's do.
    Directional {
        direction: Vec3,
        irradiance: Rgb,
        centre: Vec3,
        radius: f32,
    },
    /// Constant radiance from every direction at infinity (Mitsuba's `constant`, a uniform
    /// sky). Rays leaving the scene see it; its photons leave the disc of the scene's bounding
    /// sphere facing their direction (`centre`, `radius`, set once the scene is loaded).
    Constant {
        radiance: Rgb,
        centre: Vec3,
        radius: f32,
    },
    /// Radiance from every direction at infinity read from a latitude-longitude image
    /// (Mitsuba's `envmap`), sampled by its luminance; like `Constant` otherwise.
    Envmap {
        map: Arc<EnvironmentMap>,
        centre: Vec3,
        radius: f32,
    },
    Area {
        /// The emitting primitives (one for a sphere or quad, the triangles of a mesh).
        shapes: Vec<Shape>,
        /// Chooses a shape proportionally to its area.
        by_area: Distribution1D,
        area: f32,
        /// W/(sr m^2).
        radiance: Rgb,
        /// The scene object that emits.
        object: u32,
    },
}

/// A light sample seen from a receiving point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the receiver towards the light.
    pub wi: Vec3,
    pub dist: f32,
    /// Incident radiance (area light) or intensity / dist^2 (point light), unoccluded.
    pub li: Rgb,
    /// Solid-angle pdf of this sample given the light was chosen; 1 for a point light.
    pub pdf: f32,
    pub delta: bool,
    /// The point on the light and its normal (for offsetting the shadow ray's end).
    pub p: Vec3,
    pub n: Vec3,
}

/// A photon leaving a light.
#[derive(Clone, Copy, Debug)]
pub struct EmittedRay {
    pub origin: Vec3,
    pub dir: Vec3,
    /// Normal at the origin (zero for a point light).
    pub n: Vec3,
    /// Le cos / (pdf_pos pdf_dir): the flux carried by one emitted sample (before dividing by
    /// the number of samples and the light-selection probability).
    pub flux: Rgb,
    /// What leaves along `dir`: radiance (area lights, lights at infinity: per unit area of
    /// the disc they are emitted from; for a directional light, its irradiance) or intensity
    /// (point and spot lights).
    pub le: Rgb,
    /// The densities of the sample, as [`Light::pdf_le`] gives them: of the origin (per unit
    /// area; 1 for a point or spot light) and of the direction (per solid angle; 1 for a
    /// directional light, whose direction is fixed).
    pub pdf_pos: f32,
    pub pdf_dir: f32,
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

/// The spot light's falloff at angle theta from its axis (Mitsuba's `falloff_curve`): 1 within
/// the beam width, linear in the angle down to 0 at the cutoff, 0 beyond.
#[inline]
pub fn spot_falloff(cos_theta: f32, beam_width: f32, cutoff: f32) -> f32 {
    if cos_theta <= cutoff.cos() {
        return 0.0;
    }
    if cos_theta >= beam_width.cos() {
        return 1.0;
    }
    ((cutoff - cos_theta.clamp(-1.0, 1.0).acos()) / (cutoff - beam_width)).clamp(0.0, 1.0)
}

/// The integral of the spot falloff over the sphere of directions (its power per unit
/// intensity): 2 pi [1 - cos b + ((c - b) cos b + sin b - sin c) / (c - b)], b the beam width
/// and c the cutoff (2 pi (1 - cos c) when they are equal).
pub fn spot_solid_angle(beam_width: f32, cutoff: f32) -> f32 {
    let (b, c) = (beam_width as f64, cutoff as f64);
    let ramp = if c - b > 1e-9 {
        ((c - b) * b.cos() + b.sin() - c.sin()) / (c - b)
    } else {
        0.0
    };
    (2.0 * std::f64::consts::PI * (1.0 - b.cos() + ramp)) as f32
}

/// A light sample from infinitely far along `wi` (a delta direction with unit pdf, to be
/// adjusted by the caller): the shadow ray ends past the scene's bounding sphere.
fn sample_at_infinity(x: Vec3, wi: Vec3, centre: Vec3, radius: f32) -> LightSample {
    let dist = 2.0 * radius + x.distance(centre);
    LightSample {
        wi,
        dist,
        li: Rgb::ZERO,
        pdf: 1.0,
        delta: true,
        p: x + wi * dist,
        n: Vec3::ZERO,
    }
}

/// Where a photon from infinitely far, travelling along `dir`, starts: a uniform point of the
/// bounding sphere's disc facing it, just outside the sphere (pbrt's distant light).
fn disc_origin(dir: Vec3, centre: Vec3, radius: f32, u: Vec2) -> Vec3 {
    let d = crate::sampling::concentric_disc(u) * radius;
    let (s, t) = crate::sampling::basis(dir);
    centre - dir * radius + s * d.x + t * d.y
}

impl Light {
    /// Total emitted power in W: 4 pi I for a point light, I times the falloff's solid angle
    /// for a spot light, pi A L for a one-sided area light.
    pub fn power(&self) -> Rgb {
        match self {
            Light::Point { intensity, .. } => 4.0 * PI * *intensity,
            Light::Spot {
                intensity,
                beam_width,
                cutoff,
                ..
            } => *intensity * spot_solid_angle(*beam_width, *cutoff),
            Light::Directional {
                irradiance, radius, ..
            } => *irradiance * (PI * radius * radius),
            // The flux through the bounding sphere's disc from every direction: 4 pi L pi R^2.
            Light::Constant {
                radiance, radius, ..
            } => *radiance * (4.0 * PI * PI * radius * radius),
            // pi R^2 times the integral of L over the sphere (pbrt's ImageInfiniteLight).
            Light::Envmap { map, radius, .. } => map.integral() * (PI * radius * radius),
            Light::Area { area, radiance, .. } => PI * *area * *radiance,
        }
    }

    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. }
        )
    }

    /// Whether rays that leave the scene see this light (a constant or an environment map:
    /// a scene has at most one).
    pub fn is_environment(&self) -> bool {
        matches!(self, Light::Constant { .. } | Light::Envmap { .. })
    }

    /// For a light at infinity: the scene's bounding sphere, which its power (the flux
    /// through the sphere's disc) and its photons' origins need. Other lights ignore it.
    pub fn fit_to_scene(&mut self, scene_centre: Vec3, scene_radius: f32) {
        if let Light::Directional { centre, radius, .. }
        | Light::Constant { centre, radius, .. }
        | Light::Envmap { centre, radius, .. } = self
        {
            *centre = scene_centre;
            *radius = scene_radius;
        }
    }

    /// Where a delta light is (a point or spot light), for the scene's bounds.
    pub fn position(&self) -> Option<Vec3> {
        match self {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(*position),
            Light::Directional { .. }
            | Light::Constant { .. }
            | Light::Envmap { .. }
            | Light::Area { .. } => None,
        }
    }

    /// Samples a direction from `x` towards the light.
    // A point light's sample is a few operations, inlined into the integrators' loops; a call
    // per path vertex, with the sample copied out through memory, was 3 % of the path
    // tracer's instructions on the Cornell box. The other lights are a call
    // ([`Light::sample_li_extended`]), which their sampling outweighs.
    #[inline(always)]
    pub fn sample_li(&self, x: Vec3, u: Vec2, uc: f32) -> Option<LightSample> {
        match self {
            Light::Point {
                position,
                intensity,
            } => point_sample(x, *position, *intensity),
            _ => self.sample_li_extended(x, u, uc),
        }
    }

    /// [`Light::sample_li`] for every light (point lights too, so that it is whole).
    #[inline(never)]
    fn sample_li_extended(&self, x: Vec3, u: Vec2, uc: f32) -> Option<LightSample> {
        match self {
            Light::Point {
                position,
                intensity,
            } => point_sample(x, *position, *intensity),
            Light::Spot {
                position,
                axis,
                intensity,
                beam_width,
                cutoff,
            } => {
                let (wi, dist, dist2) = towards(x, *position)?;
                let falloff = spot_falloff(axis.dot(-wi), *beam_width, *cutoff);
                Some(LightSample {
                    wi,
                    dist,
                    li: *intensity * (falloff / dist2),
                    pdf: 1.0,
                    delta: true,
                    p: *position,
                    n: Vec3::ZERO,
                })
            }
            Light::Directional {
                direction,
                irradiance,
                centre,
                radius,
            } => {
                let mut ls = sample_at_infinity(x, -*direction, *centre, *radius);
                ls.li = *irradiance;
                Some(ls)
            }
            Light::Constant {
                radiance,
                centre,
                radius,
            } => {
                // Uniform over the sphere of directions.
                let wi = crate::sampling::uniform_sphere(u);
                let mut ls = sample_at_infinity(x, wi, *centre, *radius);
                ls.li = *radiance;
                ls.pdf = crate::sampling::UNIFORM_SPHERE_PDF;
                ls.delta = false;
                Some(ls)
            }
            Light::Envmap {
                map,
                centre,
                radius,
            } => {
                let (wi, li, pdf) = map.sample(u)?;
                let mut ls = sample_at_infinity(x, wi, *centre, *radius);
                ls.li = li;
                ls.pdf = pdf;
                ls.delta = false;
                Some(ls)
            }
            Light::Area {
                shapes,
                by_area,
                area,
                radiance,
                ..
            } => {
                let (i, _) = by_area.sample(uc);
                let shape = &shapes[i];
                if let Shape::Sphere {
                    center,
                    radius,
                    inward,
                } = *shape
                    && shapes.len() == 1
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
                        li: if inward { Rgb::ZERO } else { *radiance },
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
                let cos_l = n.dot(-wi);
                if cos_l <= 0.0 {
                    return None;
                }
                Some(LightSample {
                    wi,
                    dist,
                    li: *radiance,
                    pdf: dist2 / (cos_l * *area),
                    delta: false,
                    p,
                    n,
                })
            }
        }
    }

    /// Solid-angle pdf with which `sample_li` from `x` produces the point `p` (normal `n`) on
    /// this light. Needed for MIS when a BSDF-sampled ray hits the light.
    pub fn pdf_li(&self, x: Vec3, p: Vec3, n: Vec3) -> f32 {
        match self {
            Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. } => 0.0,
            Light::Constant { .. } => crate::sampling::UNIFORM_SPHERE_PDF,
            // The direction is all that counts: `p` is any point along it from `x`.
            Light::Envmap { map, .. } => map.pdf((p - x).normalize_or_zero()),
            Light::Area { shapes, area, .. } => {
                if let Shape::Sphere { center, radius, .. } = shapes[0]
                    && shapes.len() == 1
                    && let Some(cone) = SphereCone::from(center, radius, x)
                {
                    return cone.pdf();
                }
                let d = p - x;
                let cos_l = n.dot(-d.normalize()).abs();
                if cos_l == 0.0 {
                    return 0.0;
                }
                d.length_squared() / (cos_l * *area)
            }
        }
    }

    /// Radiance arriving from infinitely far along -`dir` (a ray travelling along `dir` that
    /// leaves the scene): an environment light's, zero for the others.
    #[inline]
    pub fn environment(&self, dir: Vec3) -> Rgb {
        match self {
            Light::Constant { radiance, .. } => *radiance,
            Light::Envmap { map, .. } => map.eval(dir),
            _ => Rgb::ZERO,
        }
    }

    /// Radiance leaving the light at a point with normal `n` in direction `w`.
    #[inline]
    pub fn emitted(&self, n: Vec3, w: Vec3) -> Rgb {
        match self {
            Light::Area { radiance, .. } if n.dot(w) > 0.0 => *radiance,
            _ => Rgb::ZERO,
        }
    }

    /// Samples a photon leaving the light: a point light emits uniformly over the sphere, an
    /// area light from a uniform point with a cosine-distributed direction on its normal side.
    pub fn sample_emission(&self, u_pos: Vec2, u_dir: Vec2, uc: f32) -> EmittedRay {
        match self {
            Light::Point {
                position,
                intensity,
            } => EmittedRay {
                origin: *position,
                dir: crate::sampling::uniform_sphere(u_dir),
                n: Vec3::ZERO,
                flux: 4.0 * PI * *intensity,
                le: *intensity,
                pdf_pos: 1.0,
                pdf_dir: crate::sampling::UNIFORM_SPHERE_PDF,
            },
            Light::Spot {
                position,
                axis,
                intensity,
                beam_width,
                cutoff,
            } => {
                // Uniform in the cone of the cutoff, weighted by the falloff: I f / pdf.
                let cos_max = cutoff.cos();
                let dir = to_world(uniform_cone(u_dir, cos_max), *axis);
                let falloff = spot_falloff(axis.dot(dir), *beam_width, *cutoff);
                EmittedRay {
                    origin: *position,
                    dir,
                    n: Vec3::ZERO,
                    flux: *intensity * (falloff * 2.0 * PI * (1.0 - cos_max)),
                    le: *intensity * falloff,
                    pdf_pos: 1.0,
                    pdf_dir: 1.0 / (2.0 * PI * (1.0 - cos_max)),
                }
            }
            Light::Directional {
                direction,
                irradiance,
                centre,
                radius,
            } => EmittedRay {
                origin: disc_origin(*direction, *centre, *radius, u_pos),
                dir: *direction,
                n: Vec3::ZERO,
                flux: *irradiance * (PI * radius * radius),
                le: *irradiance,
                pdf_pos: 1.0 / (PI * radius * radius),
                pdf_dir: 1.0,
            },
            Light::Constant {
                radiance,
                centre,
                radius,
            } => {
                // A uniform direction, then a uniform point of the disc facing it: L cos /
                // (1/(pi R^2) x 1/(4 pi)) with cos = 1 on the disc.
                let dir = -crate::sampling::uniform_sphere(u_dir);
                EmittedRay {
                    origin: disc_origin(dir, *centre, *radius, u_pos),
                    dir,
                    n: Vec3::ZERO,
                    flux: *radiance * (4.0 * PI * PI * radius * radius),
                    le: *radiance,
                    pdf_pos: 1.0 / (PI * radius * radius),
                    pdf_dir: crate::sampling::UNIFORM_SPHERE_PDF,
                }
            }
            Light::Envmap {
                map,
                centre,
                radius,
            } => {
                // A direction by the map's density, then a uniform point of the disc facing
                // it: L / (pdf_dir / (pi R^2)) (pbrt's ImageInfiniteLight::SampleLe).
                let (dir, flux, le, pdf_dir) = match map.sample(u_dir) {
                    Some((wi, li, pdf)) => (-wi, li * (PI * radius * radius / pdf), li, pdf),
                    None => (-Vec3::Z, Rgb::ZERO, Rgb::ZERO, 0.0),
                };
                EmittedRay {
                    origin: disc_origin(dir, *centre, *radius, u_pos),
                    dir,
                    n: Vec3::ZERO,
                    flux,
                    le,
                    pdf_pos: 1.0 / (PI * radius * radius),
                    pdf_dir,
                }
            }
            Light::Area {
                shapes,
                by_area,
                area,
                radiance,
                ..
            } => {
                let (i, _) = by_area.sample(uc);
                let (p, n) = shapes[i].sample_area(u_pos);
                let local = crate::sampling::cosine_hemisphere(u_dir);
                EmittedRay {
                    origin: p,
                    dir: to_world(local, n),
                    n,
                    // L cos / (1/A * cos/pi) = pi A L
                    flux: PI * *area * *radiance,
                    le: *radiance,
                    pdf_pos: 1.0 / *area,
                    pdf_dir: local.z * std::f32::consts::FRAC_1_PI,
                }
            }
        }
    }

    /// The densities with which [`Light::sample_emission`] emits a ray along `dir` (unit) from
    /// a point with normal `n` on the light (pbrt-v4's `PDF_Le`): (per unit area of where it
    /// starts, per solid angle of its direction). A point or spot light's position is a delta
    /// (1); a directional light's direction is (1). A light at infinity starts its rays on the
    /// disc of the scene's bounding sphere facing `dir`, whatever the origin. Zero for what
    /// the light never emits (behind an area light, outside a spot's cone).
    pub fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        match self {
            Light::Point { .. } => (1.0, crate::sampling::UNIFORM_SPHERE_PDF),
            Light::Spot { axis, cutoff, .. } => {
                let cos_max = cutoff.cos();
                let pdf = if axis.dot(dir) > cos_max {
                    1.0 / (2.0 * PI * (1.0 - cos_max))
                } else {
                    0.0
                };
                (1.0, pdf)
            }
            Light::Directional { radius, .. } => (1.0 / (PI * radius * radius), 1.0),
            Light::Constant { radius, .. } => (
                1.0 / (PI * radius * radius),
                crate::sampling::UNIFORM_SPHERE_PDF,
            ),
            Light::Envmap { map, radius, .. } => (1.0 / (PI * radius * radius), map.pdf(-dir)),
            Light::Area { area, .. } => (
                1.0 / *area,
                n.dot(dir).max(0.0) * std::f32::consts::FRAC_1_PI,
            ),
        }
    }

    /// Whether the light is infinitely far (directional, constant, environment map): its
    /// rays start on the scene's bounding disc, and a distance to it means nothing.
    pub fn is_infinite(&self) -> bool {
        matches!(
            self,
            Light::Directional { .. } | Light::Constant { .. } | Light::Envmap { .. }
        )
    }
}

/// Builds an area light over the given shapes.
pub fn area_light(shapes: Vec<Shape>, radiance: Rgb, object: u32) -> Light {
    let areas: Vec<f32> = shapes.iter().map(|s| s.area()).collect();
    let area = areas.iter().sum();
    Light::Area {
        by_area: Distribution1D::new(&areas),
        shapes,
        area,
        radiance,
        object,
    }
}

/// A point light's sample from `x`: intensity over distance squared, pdf 1 (delta).
#[inline(always)]
fn point_sample(x: Vec3, position: Vec3, intensity: Rgb) -> Option<LightSample> {
    let (wi, dist, dist2) = towards(x, position)?;
    Some(LightSample {
        wi,
        dist,
        li: intensity / dist2,
        pdf: 1.0,
        delta: true,
        p: position,
        n: Vec3::ZERO,
    })
}

/// The direction from `x` to `p`, the distance and its square (a point light's 1/r^2); None
/// when they coincide.
#[inline(always)]
fn towards(x: Vec3, p: Vec3) -> Option<(Vec3, f32, f32)> {
    let d = p - x;
    let dist2 = d.length_squared();
    if dist2 == 0.0 {
        return None;
    }
    let dist = dist2.sqrt();
    Some((d / dist, dist, dist2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Rng, uniform_sphere};

    fn lights() -> Vec<(&'static str, Light)> {
        let mut out = vec![
            (
                "point",
                Light::Point {
                    position: Vec3::new(0.1, 0.2, 0.3),
                    intensity: Rgb::new(1.0, 2.0, 3.0),
                },
            ),
            (
                "spot",
                Light::Spot {
                    position: Vec3::ZERO,
                    axis: Vec3::new(0.3, -1.0, 0.2).normalize(),
                    intensity: Rgb::splat(2.0),
                    beam_width: 0.3,
                    cutoff: 0.6,
                },
            ),
            (
                "directional",
                Light::Directional {
                    direction: Vec3::new(0.2, -1.0, 0.1).normalize(),
                    irradiance: Rgb::splat(3.0),
                    centre: Vec3::ONE,
                    radius: 2.0,
                },
            ),
            (
                "constant",
                Light::Constant {
                    radiance: Rgb::splat(0.5),
                    centre: Vec3::ZERO,
                    radius: 3.0,
                },
            ),
        ];
        let quad = Shape::quad(
            Vec3::new(-0.5, 1.0, -0.5),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        );
        let tri = Shape::Triangle {
            p0: Vec3::ZERO,
            e1: Vec3::X,
            e2: Vec3::new(0.3, 0.0, 2.0),
        };
        let mut inward = Shape::sphere(Vec3::new(0.0, 2.0, 0.0), 0.5);
        inward.flip();
        for (name, shapes) in [
            ("area quad", vec![quad]),
            ("area quad + triangle", vec![quad, tri]),
            ("area sphere", vec![Shape::sphere(Vec3::ZERO, 0.7)]),
            ("area inward sphere", vec![inward]),
            (
                "area disk",
                vec![Shape::disk(Vec3::ZERO, Vec3::X * 0.4, Vec3::Z * 0.4)],
            ),
        ] {
            out.push((name, area_light(shapes, Rgb::new(2.0, 1.0, 0.5), 0)));
        }
        out
    }

    /// `sample_emission` reports the densities `pdf_le` gives for its ray, and its flux is
    /// Le cos / (pdf_pos pdf_dir).
    #[test]
    fn emission_pdfs_match_the_samples() {
        let mut rng = Rng::new(&[3]);
        for (name, light) in lights() {
            for _ in 0..2000 {
                let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
                let (pos, dir) = light.pdf_le(e.n, e.dir);
                assert!(
                    (pos - e.pdf_pos).abs() <= 1e-5 * pos,
                    "{name}: {pos} {}",
                    e.pdf_pos
                );
                assert!(
                    (dir - e.pdf_dir).abs() <= 2e-4 * dir,
                    "{name}: {dir} {}",
                    e.pdf_dir
                );
                let cos = if e.n == Vec3::ZERO {
                    1.0
                } else {
                    e.n.dot(e.dir)
                };
                if e.pdf_dir > 0.0 {
                    let flux = e.le * (cos / (e.pdf_pos * e.pdf_dir));
                    assert!(
                        (flux - e.flux).abs().max_element() <= 1e-3 * e.flux.max_element(),
                        "{name}: {flux} {}",
                        e.flux
                    );
                }
            }
        }
    }

    /// The direction density integrates to one over the sphere (Monte Carlo with uniform
    /// directions), from any point of an area light; and the emitted power it implies,
    /// the integral of Le cos over directions and area, is `power()`.
    #[test]
    fn emission_direction_pdfs_integrate_to_one() {
        let mut rng = Rng::new(&[5]);
        let n = 200_000;
        for (name, light) in lights() {
            if matches!(light, Light::Directional { .. }) {
                continue; // a delta direction
            }
            let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
            let mut sum = 0.0f64;
            for _ in 0..n {
                let w = uniform_sphere(rng.next_2d());
                sum += light.pdf_le(e.n, w).1 as f64;
            }
            let integral = sum * 4.0 * std::f64::consts::PI / n as f64;
            assert!((integral - 1.0).abs() < 0.02, "{name}: {integral}");
        }
    }
}
