//! Rays and the five kinds of primitive: analytic spheres, parallelograms ("quads") and
//! (elliptic) discs, triangles from meshes, and pieces of round curves ([`curve`]). Each
//! primitive knows its orientation: the geometric normal is the outward normal for spheres
//! and curves, normalize(u x v) for quads and discs and normalize(e1 x e2) for triangles. [`SurfacePoint`] adds what shading needs: the shading
//! normal, texture coordinates and the tangent dp/du, with Mitsuba 3's parameterisations.

use crate::Rgb;
use crate::texture::TextureEvalContext;
use glam::{Mat3, Vec2, Vec3};
use obvhs::aabb::Aabb;

pub mod curve;
use curve::Piece;

#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    /// Unit length.
    pub dir: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Ray { origin, dir }
    }
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Pushes a point off a surface along its normal, to the side `dir` leaves towards, so that a
/// ray spawned there does not hit the surface it starts on. Scaled with the point's magnitude
/// because f32 spacing grows with it.
#[inline]
pub fn offset_origin(p: Vec3, n: Vec3, dir: Vec3) -> Vec3 {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    if n.dot(dir) >= 0.0 {
        p + n * eps
    } else {
        p - n * eps
    }
}

#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// The normal points outward, or inward if `inward` (Mitsuba's `flip_normals`).
    /// `to_local` turns world directions into the sphere's own axes, about whose z its
    /// texture coordinates run (the identity: the world's axes).
    Sphere {
        center: Vec3,
        radius: f32,
        inward: bool,
        to_local: Mat3,
    },
    /// origin + s u + t v, s, t in [0, 1]. `w` = n / (n . n) with n = u x v (for the
    /// barycentric-style coordinates of a hit), `normal` = normalize(n).
    Quad {
        origin: Vec3,
        u: Vec3,
        v: Vec3,
        w: Vec3,
        normal: Vec3,
    },
    Triangle {
        p0: Vec3,
        e1: Vec3,
        e2: Vec3,
    },
    /// center + a u + b v with a^2 + b^2 <= 1 (a circle when u and v are orthogonal and of
    /// equal length: Mitsuba's `disk` under any affine `to_world`). `w` and `normal` as for
    /// a quad.
    Disk {
        center: Vec3,
        u: Vec3,
        v: Vec3,
        w: Vec3,
        normal: Vec3,
    },
    /// A piece of a round curve ([`curve`]): the convex hull of the spheres (p0, r0) and
    /// (p1, r1), closed by the spheres `caps` names ([`curve::START_CAP`],
    /// [`curve::END_CAP`]) and open at the others, met only by rays from outside. `v0` and
    /// `v1`: the curve's texture coordinate v at p0 and p1. `next`: the unit axis of the
    /// piece after this one (zero at a curve's end), into which the sphere at p1 does not
    /// reach.
    Curve {
        p0: Vec3,
        r0: f32,
        p1: Vec3,
        r1: f32,
        v0: f32,
        v1: f32,
        next: Vec3,
        caps: u8,
    },
}

/// What a mesh file gives a triangle besides its corners: vertex normals and texture
/// coordinates, in the order of the triangle's corners (p0, p0 + e1, p0 + e2).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TriangleAttrs {
    pub normals: Option<[Vec3; 3]>,
    pub uvs: Option<[Vec2; 3]>,
}

/// No [`TriangleAttrs`] for a primitive.
pub const NO_ATTRS: u32 = u32::MAX;

/// A point on a surface with what shading needs there.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3,
    /// Unit geometric normal, the primitive's own orientation.
    pub ng: Vec3,
    /// Unit shading normal (the interpolated vertex normal of a smooth mesh; else `ng`), on
    /// the side of `ng`.
    pub ns: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Tangent dp/du (zero where the parameterisation gives none): orients anisotropic BSDFs.
    pub dpdu: Vec3,
    /// Tangent dp/dv (zero where dp/du is): with dp/du, the frame a bump map tilts.
    pub dpdv: Vec3,
    /// The value of the mesh attribute the surface carries (zero where none).
    pub attribute: Rgb,
}

impl SurfacePoint {
    /// Where the surface's textures are looked up.
    #[inline]
    pub fn texture_ctx(&self) -> TextureEvalContext {
        TextureEvalContext {
            uv: self.uv,
            p: self.p,
            attribute: self.attribute,
        }
    }
}

/// A shape instance in the scene: geometry plus the index of the scene object it belongs to
/// (material, emission, interior medium).
#[derive(Clone, Copy, Debug)]
pub struct Primitive {
    pub shape: Shape,
    pub object: u32,
    /// Index of the triangle's [`TriangleAttrs`] in the scene, or [`NO_ATTRS`].
    pub attrs: u32,
}

/// A ray-surface intersection.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    pub p: Vec3,
    /// Unit geometric normal with the primitive's own orientation (not flipped towards the ray).
    pub ng: Vec3,
    pub prim: u32,
}

/// The distances along `ray` at which it meets the sphere of `center` and `radius`, both roots,
/// unordered; None if it misses. The numerically careful form of Ray Tracing Gems ch. 7,
/// which avoids cancellation for distant or small spheres. `Shape::intersect` takes the
/// nearest in range, a shadow ray's crossings both.
// Forced inline: the body of the sphere's primitive test, like `Shape::intersect`.
#[inline(always)]
pub(crate) fn sphere_roots(ray: &Ray, center: Vec3, radius: f32) -> Option<(f32, f32)> {
    let f = ray.origin - center;
    let b = -f.dot(ray.dir);
    let l = f + b * ray.dir;
    let disc = radius * radius - l.dot(l);
    if disc < 0.0 {
        return None;
    }
    let c = f.dot(f) - radius * radius;
    let q = b + b.signum() * disc.sqrt();
    if q == 0.0 {
        return None;
    }
    Some((c / q, q))
}

impl Shape {
    /// A curve's piece. Only the `Curve` arms of this type's matches call it.
    #[inline(always)]
    fn piece(&self) -> Piece {
        let Shape::Curve {
            p0,
            r0,
            p1,
            r1,
            next,
            caps,
            ..
        } = *self
        else {
            unreachable!("a curve's piece of another shape")
        };
        Piece {
            p0,
            r0,
            p1,
            r1,
            next,
            caps,
        }
    }

    /// Whether the surface is flat: the same normal everywhere on it.
    #[inline]
    pub fn is_flat(&self) -> bool {
        matches!(
            self,
            Shape::Quad { .. } | Shape::Triangle { .. } | Shape::Disk { .. }
        )
    }

    pub fn quad(origin: Vec3, u: Vec3, v: Vec3) -> Shape {
        let n = u.cross(v);
        Shape::Quad {
            origin,
            u,
            v,
            w: n / n.dot(n),
            normal: n.normalize(),
        }
    }

    pub fn disk(center: Vec3, u: Vec3, v: Vec3) -> Shape {
        let n = u.cross(v);
        Shape::Disk {
            center,
            u,
            v,
            w: n / n.dot(n),
            normal: n.normalize(),
        }
    }

    /// A sphere with its normal outward.
    pub fn sphere(center: Vec3, radius: f32) -> Shape {
        Shape::Sphere {
            center,
            radius,
            inward: false,
            to_local: Mat3::IDENTITY,
        }
    }

    /// A sphere whose texture coordinates run about its own axes: `to_local`'s rows are
    /// the directions in the world of its x, y and z (orthonormal).
    pub fn sphere_with_axes(center: Vec3, radius: f32, to_local: Mat3) -> Shape {
        Shape::Sphere {
            center,
            radius,
            inward: false,
            to_local,
        }
    }

    /// Turns the surface's normal the other way (Mitsuba's `flip_normals`), keeping its
    /// texture coordinates.
    pub fn flip(&mut self) {
        match self {
            Shape::Quad { normal, .. } | Shape::Disk { normal, .. } => *normal = -*normal,
            Shape::Triangle { e1, e2, .. } => std::mem::swap(e1, e2),
            Shape::Sphere { inward, .. } => *inward = !*inward,
            // Mitsuba's curves have no `flip_normals`; the reader refuses it.
            Shape::Curve { .. } => {}
        }
    }

    pub fn aabb(&self) -> Aabb {
        let (lo, hi) = match *self {
            Shape::Sphere { center, radius, .. } => {
                (center - Vec3::splat(radius), center + Vec3::splat(radius))
            }
            Shape::Quad { origin, u, v, .. } => {
                let pts = [origin, origin + u, origin + v, origin + u + v];
                bounds(&pts)
            }
            Shape::Triangle { p0, e1, e2 } => bounds(&[p0, p0 + e1, p0 + e2]),
            Shape::Disk { center, u, v, .. } => {
                // The ellipse's extent along each axis: sqrt(u_i^2 + v_i^2).
                let half = (u * u + v * v).map(f32::sqrt);
                (center - half, center + half)
            }
            Shape::Curve { .. } => self.piece().bounds(),
        };
        // Pad flat boxes: an axis-aligned quad has zero thickness.
        let pad = Vec3::splat(1e-5 * (1.0 + lo.abs().max(hi.abs()).max_element()));
        Aabb::new((lo - pad).into(), (hi + pad).into())
    }

    pub fn area(&self) -> f32 {
        match *self {
            Shape::Sphere { radius, .. } => 4.0 * std::f32::consts::PI * radius * radius,
            Shape::Quad { u, v, .. } => u.cross(v).length(),
            Shape::Triangle { e1, e2, .. } => 0.5 * e1.cross(e2).length(),
            Shape::Disk { u, v, .. } => std::f32::consts::PI * u.cross(v).length(),
            Shape::Curve { .. } => self.piece().area(),
        }
    }

    /// Distance along the ray to the nearest intersection in (0, tmax), or None.
    // Forced inline: it is the body of every traversal's primitive test, where a call per
    // primitive showed (2.7% of the path tracer's instructions, with the shadow-ray closure).
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<f32> {
        match *self {
            Shape::Sphere { center, radius, .. } => {
                let (mut t0, mut t1) = sphere_roots(ray, center, radius)?;
                if t0 > t1 {
                    std::mem::swap(&mut t0, &mut t1);
                }
                if t0 > 0.0 && t0 < tmax {
                    Some(t0)
                } else if t1 > 0.0 && t1 < tmax {
                    Some(t1)
                } else {
                    None
                }
            }
            Shape::Quad {
                origin,
                u,
                v,
                w,
                normal,
            } => {
                let denom = normal.dot(ray.dir);
                if denom.abs() < 1e-12 {
                    return None;
                }
                let t = normal.dot(origin - ray.origin) / denom;
                if !(t > 0.0 && t < tmax) {
                    return None;
                }
                let q = ray.at(t) - origin;
                let a = w.dot(q.cross(v));
                let b = w.dot(u.cross(q));
                ((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)).then_some(t)
            }
            Shape::Triangle { p0, e1, e2 } => {
                // Moeller-Trumbore.
                let pvec = ray.dir.cross(e2);
                let det = e1.dot(pvec);
                if det.abs() < 1e-12 {
                    return None;
                }
                let inv = 1.0 / det;
                let tvec = ray.origin - p0;
                let b1 = tvec.dot(pvec) * inv;
                if !(0.0..=1.0).contains(&b1) {
                    return None;
                }
                let qvec = tvec.cross(e1);
                let b2 = ray.dir.dot(qvec) * inv;
                if b2 < 0.0 || b1 + b2 > 1.0 {
                    return None;
                }
                let t = e2.dot(qvec) * inv;
                (t > 0.0 && t < tmax).then_some(t)
            }
            Shape::Disk {
                center,
                u,
                v,
                w,
                normal,
            } => {
                let denom = normal.dot(ray.dir);
                if denom.abs() < 1e-12 {
                    return None;
                }
                let t = normal.dot(center - ray.origin) / denom;
                if !(t > 0.0 && t < tmax) {
                    return None;
                }
                let q = ray.at(t) - center;
                let a = w.dot(q.cross(v));
                let b = w.dot(u.cross(q));
                (a * a + b * b <= 1.0).then_some(t)
            }
            Shape::Curve { .. } => self.piece().intersect(ray, tmax),
        }
    }

    /// Unit geometric normal at a point on the surface.
    #[inline]
    pub fn normal(&self, p: Vec3) -> Vec3 {
        match *self {
            Shape::Sphere { center, inward, .. } => {
                let n = (p - center).normalize();
                if inward { -n } else { n }
            }
            Shape::Quad { normal, .. } => normal,
            Shape::Triangle { e1, e2, .. } => e1.cross(e2).normalize(),
            Shape::Disk { normal, .. } => normal,
            Shape::Curve { .. } => self.piece().normal(p),
        }
    }

    /// The surface at `p` (a point on it): Mitsuba 3's texture coordinates and tangents
    /// (sphere: u = phi / 2 pi, v = theta / pi; rectangle: the corner coordinates in [0, 1]^2;
    /// disk: u = r, v = phi / 2 pi; triangle: interpolated, else the barycentrics (b1, b2)),
    /// and the shading normal from a triangle's vertex normals.
    pub fn surface(&self, p: Vec3, attrs: Option<&TriangleAttrs>) -> SurfacePoint {
        self.surface_at(p, self.normal(p), attrs, None, true)
    }

    /// [`Shape::surface`] at a point whose geometric normal `ng` is known (a hit's: not
    /// computed again), with the texture coordinates and the tangent (zero) left out unless
    /// `coordinates`: most materials need neither, and a sphere's cost an atan2 and an acos
    /// per hit.
    #[inline]
    pub fn surface_at(
        &self,
        p: Vec3,
        ng: Vec3,
        attrs: Option<&TriangleAttrs>,
        attribute: Option<&[Rgb; 3]>,
        coordinates: bool,
    ) -> SurfacePoint {
        if !coordinates
            && !matches!(
                attrs,
                Some(TriangleAttrs {
                    normals: Some(_),
                    ..
                })
            )
        {
            return SurfacePoint {
                p,
                ng,
                ns: ng,
                uv: Vec2::ZERO,
                dpdu: Vec3::ZERO,
                dpdv: Vec3::ZERO,
                attribute: Rgb::ZERO,
            };
        }
        let mut value = Rgb::ZERO;
        let (uv, dpdu, dpdv, ns) = match *self {
            Shape::Sphere {
                center,
                radius,
                to_local,
                ..
            } => {
                let d = to_local * ((p - center) / radius);
                let mut phi = d.y.atan2(d.x);
                if phi < 0.0 {
                    phi += 2.0 * std::f32::consts::PI;
                }
                let theta = d.z.clamp(-1.0, 1.0).acos();
                let uv = Vec2::new(
                    phi * (0.5 * std::f32::consts::FRAC_1_PI),
                    theta * std::f32::consts::FRAC_1_PI,
                );
                let to_world = to_local.transpose();
                let dpdu =
                    to_world * (Vec3::new(-d.y, d.x, 0.0) * (2.0 * std::f32::consts::PI * radius));
                // d p / d theta times d theta / d v = pi: (cos theta cos phi, cos theta sin
                // phi, -sin theta) pi r.
                let sin_theta = (d.x * d.x + d.y * d.y).sqrt();
                let dpdv = if sin_theta > 0.0 {
                    to_world
                        * (Vec3::new(d.z * d.x / sin_theta, d.z * d.y / sin_theta, -sin_theta)
                            * (std::f32::consts::PI * radius))
                } else {
                    Vec3::ZERO
                };
                (uv, dpdu, dpdv, ng)
            }
            Shape::Quad {
                origin, u, v, w, ..
            } => {
                let q = p - origin;
                (Vec2::new(w.dot(q.cross(v)), w.dot(u.cross(q))), u, v, ng)
            }
            Shape::Disk {
                center, u, v, w, ..
            } => {
                let q = p - center;
                let (a, b) = (w.dot(q.cross(v)), w.dot(u.cross(q)));
                let mut phi = b.atan2(a);
                if phi < 0.0 {
                    phi += 2.0 * std::f32::consts::PI;
                }
                let r = (a * a + b * b).sqrt();
                // d p / d r along the radius, as Mitsuba's disk (u = r).
                let dpdu = if r > 0.0 { (a * u + b * v) / r } else { u };
                // d p / d phi times d phi / d v = 2 pi.
                let dpdv = (a * v - b * u) * (2.0 * std::f32::consts::PI);
                (
                    Vec2::new(r, phi * (0.5 * std::f32::consts::FRAC_1_PI)),
                    dpdu,
                    dpdv,
                    ng,
                )
            }
            Shape::Triangle { p0, e1, e2 } => {
                let n = e1.cross(e2);
                let q = p - p0;
                let inv = 1.0 / n.dot(n);
                let b1 = q.cross(e2).dot(n) * inv;
                let b2 = e1.cross(q).dot(n) * inv;
                let b0 = 1.0 - b1 - b2;
                if let Some(c) = attribute {
                    value = b0 * c[0] + b1 * c[1] + b2 * c[2];
                }
                let mut uv = Vec2::new(b1, b2);
                let (mut dpdu, mut dpdv) = (Vec3::ZERO, Vec3::ZERO);
                let mut ns = ng;
                if let Some(a) = attrs {
                    if let Some(t) = a.uvs {
                        uv = b0 * t[0] + b1 * t[1] + b2 * t[2];
                        // Solve e1 = du1 dpdu + dv1 dpdv, e2 = du2 dpdu + dv2 dpdv.
                        let (d1, d2) = (t[1] - t[0], t[2] - t[0]);
                        let det = d1.x * d2.y - d1.y * d2.x;
                        if det.abs() > 1e-20 {
                            dpdu = (d2.y * e1 - d1.y * e2) / det;
                            dpdv = (d1.x * e2 - d2.x * e1) / det;
                        }
                    }
                    if let Some(nv) = a.normals {
                        let n = b0 * nv[0] + b1 * nv[1] + b2 * nv[2];
                        if n.length_squared() > 0.0 {
                            ns = n.normalize();
                        }
                    }
                }
                (uv, dpdu, dpdv, ns)
            }
            Shape::Curve { v0, v1, .. } => {
                let (uv, dpdu, dpdv) = self.piece().surface(p, ng, v0, v1);
                (uv, dpdu, dpdv, ng)
            }
        };
        SurfacePoint {
            p,
            ng,
            ns,
            uv,
            dpdu,
            dpdv,
            attribute: value,
        }
    }

    /// A point distributed uniformly by area, and the normal there.
    #[inline]
    pub fn sample_area(&self, u: Vec2) -> (Vec3, Vec3) {
        match *self {
            Shape::Sphere {
                center,
                radius,
                inward,
                ..
            } => {
                let d = crate::sampling::uniform_sphere(u);
                (center + radius * d, if inward { -d } else { d })
            }
            Shape::Quad {
                origin,
                u: eu,
                v: ev,
                normal,
                ..
            } => (origin + u.x * eu + u.y * ev, normal),
            Shape::Triangle { p0, e1, e2 } => {
                let (b1, b2) = crate::sampling::uniform_triangle(u);
                (p0 + b1 * e1 + b2 * e2, e1.cross(e2).normalize())
            }
            Shape::Disk {
                center,
                u: eu,
                v: ev,
                normal,
                ..
            } => {
                let d = crate::sampling::concentric_disc(u);
                (center + d.x * eu + d.y * ev, normal)
            }
            Shape::Curve { .. } => self.piece().sample_area(u),
        }
    }
}

fn bounds(pts: &[Vec3]) -> (Vec3, Vec3) {
    pts.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

#[cfg(test)]
mod tests {

    /// A sphere's axes fit in the room a quad takes: the shape (and the BVH's primitives)
    /// stay the size they were.
    #[test]
    fn a_sphere_is_no_larger_than_a_quad() {
        assert_eq!(std::mem::size_of::<Shape>(), 64);
    }
    use super::*;

    #[test]
    fn quad_hit_and_miss() {
        let q = Shape::quad(
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
        );
        let down = Ray::new(Vec3::new(0.2, 1.0, 0.3), Vec3::NEG_Y);
        assert!((q.intersect(&down, f32::INFINITY).unwrap() - 1.0).abs() < 1e-6);
        let outside = Ray::new(Vec3::new(1.5, 1.0, 0.0), Vec3::NEG_Y);
        assert!(q.intersect(&outside, f32::INFINITY).is_none());
        assert!(q.intersect(&down, 0.5).is_none());
        // u x v = (2,0,0) x (0,0,2) = (0,-4,0): the normal points down.
        assert!((q.normal(Vec3::ZERO) - Vec3::NEG_Y).length() < 1e-6);
    }

    #[test]
    fn sphere_hits_from_outside_and_inside() {
        let s = Shape::sphere(Vec3::ZERO, 1.0);
        let r = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z);
        assert!((s.intersect(&r, f32::INFINITY).unwrap() - 4.0).abs() < 1e-5);
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert!((s.intersect(&inside, f32::INFINITY).unwrap() - 1.0).abs() < 1e-5);
    }

    /// dp/du and dp/dv are the derivatives of the parameterisation: a small step along
    /// either, put back on the surface, moves the texture coordinates by that step in u or v
    /// alone (sphere under a rotation, quad, ellipse-shaped disk, triangle with uvs).
    #[test]
    fn tangents_are_the_derivatives_of_the_texture_coordinates() {
        let sphere = Shape::Sphere {
            center: Vec3::new(0.5, 0.0, 1.0),
            radius: 2.0,
            inward: false,
            to_local: Mat3::from_rotation_x(0.7) * Mat3::from_rotation_z(0.3),
        };
        let quad = Shape::quad(
            Vec3::ZERO,
            Vec3::new(2.0, 0.5, 0.0),
            Vec3::new(0.0, 1.0, 3.0),
        );
        let disk = Shape::disk(
            Vec3::ONE,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.5),
        );
        let triangle = Shape::Triangle {
            p0: Vec3::ZERO,
            e1: Vec3::new(2.0, 0.0, 0.0),
            e2: Vec3::new(0.5, 1.0, 1.0),
        };
        let attrs = TriangleAttrs {
            normals: None,
            uvs: Some([
                Vec2::new(0.1, 0.2),
                Vec2::new(0.9, 0.4),
                Vec2::new(0.3, 1.5),
            ]),
        };
        let onto = |shape: &Shape, p: Vec3| match *shape {
            Shape::Sphere { center, radius, .. } => center + (p - center).normalize() * radius,
            _ => p,
        };
        for (shape, attrs) in [
            (sphere, None),
            (quad, None),
            (disk, None),
            (triangle, Some(&attrs)),
        ] {
            for u in [
                Vec2::new(0.3, 0.4),
                Vec2::new(0.6, 0.2),
                Vec2::new(0.45, 0.7),
            ] {
                let (p, _) = shape.sample_area(u);
                let sp = shape.surface(p, attrs);
                let h = 1e-3;
                for (tangent, step) in [(sp.dpdu, Vec2::X), (sp.dpdv, Vec2::Y)] {
                    let moved = shape.surface(onto(&shape, p + h * tangent), attrs).uv;
                    let duv = (moved - sp.uv) / h;
                    assert!(
                        (duv - step).length() < 2e-2,
                        "{shape:?} at {p}: a step along the tangent of {step} moved uv by {duv}"
                    );
                }
            }
        }
    }

    #[test]
    fn surface_coordinates_follow_mitsuba() {
        // Sphere: u = phi / 2 pi from +x towards +y, v = theta / pi from +z.
        let s = Shape::sphere(Vec3::new(1.0, 2.0, 3.0), 2.0);
        let at = |d: Vec3| s.surface(Vec3::new(1.0, 2.0, 3.0) + 2.0 * d, None);
        let sp = at(Vec3::Y);
        assert!((sp.uv - Vec2::new(0.25, 0.5)).length() < 1e-6, "{}", sp.uv);
        assert!(sp.dpdu.normalize().dot(Vec3::NEG_X) > 0.999);
        assert!((at(Vec3::Z).uv.y).abs() < 1e-6 && (at(-Vec3::Z).uv.y - 1.0).abs() < 1e-6);
        assert!((at(Vec3::NEG_Y).uv.x - 0.75).abs() < 1e-6);
        // Quad: the corner coordinates (Mitsuba's rectangle: (x + 1) / 2, (y + 1) / 2).
        let q = Shape::quad(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        );
        let sp = q.surface(Vec3::new(0.5, 3.0, 0.0), None);
        assert!((sp.uv - Vec2::new(0.25, 0.75)).length() < 1e-6);
        assert_eq!(sp.ns, sp.ng);
        // Disk: u = r, v = phi / 2 pi from its u axis towards v; area pi |u x v|.
        let d = Shape::disk(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        let sp = d.surface(Vec3::new(0.0, 0.5, 0.0), None);
        assert!((sp.uv - Vec2::new(0.5, 0.25)).length() < 1e-6, "{}", sp.uv);
        assert!((d.area() - 2.0 * std::f32::consts::PI).abs() < 1e-5);
        let ray = Ray::new(Vec3::new(1.9, 0.0, 1.0), Vec3::NEG_Z);
        assert!(d.intersect(&ray, f32::INFINITY).is_some());
        let ray = Ray::new(Vec3::new(1.5, 0.8, 1.0), Vec3::NEG_Z);
        assert!(
            d.intersect(&ray, f32::INFINITY).is_none(),
            "outside the ellipse"
        );
        // Triangle: barycentrics without attributes; interpolated uvs, normals and dp/du
        // with them.
        let t = Shape::Triangle {
            p0: Vec3::ZERO,
            e1: Vec3::X,
            e2: Vec3::Y,
        };
        let p = Vec3::new(0.25, 0.5, 0.0);
        assert!((t.surface(p, None).uv - Vec2::new(0.25, 0.5)).length() < 1e-6);
        let attrs = TriangleAttrs {
            normals: Some([Vec3::Z, Vec3::Z, Vec3::new(1.0, 0.0, 1.0).normalize()]),
            uvs: Some([Vec2::ZERO, Vec2::new(0.0, 2.0), Vec2::new(2.0, 0.0)]),
        };
        let sp = t.surface(p, Some(&attrs));
        assert!((sp.uv - Vec2::new(1.0, 0.5)).length() < 1e-6, "{}", sp.uv);
        // u grows along e2 (uv (2, 0) at p0 + e2): dp/du = e2 / 2.
        assert!(
            (sp.dpdu - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6,
            "{}",
            sp.dpdu
        );
        let n = (0.25 * Vec3::Z + 0.25 * Vec3::Z + 0.5 * Vec3::new(1.0, 0.0, 1.0).normalize())
            .normalize();
        assert!((sp.ns - n).length() < 1e-6);
        assert_eq!(sp.ng, Vec3::Z);
    }

    #[test]
    fn triangle_hit() {
        let t = Shape::Triangle {
            p0: Vec3::ZERO,
            e1: Vec3::X,
            e2: Vec3::Y,
        };
        let r = Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z);
        assert!((t.intersect(&r, f32::INFINITY).unwrap() - 1.0).abs() < 1e-6);
        let miss = Ray::new(Vec3::new(0.75, 0.75, 1.0), Vec3::NEG_Z);
        assert!(t.intersect(&miss, f32::INFINITY).is_none());
        assert!((t.area() - 0.5).abs() < 1e-6);
    }
}
