//! Visibility between two points: shadow rays, which pass null boundaries and carry the
//! transmittance of the media they cross.

use super::Scene;
use crate::Rgb;
use crate::geometry::{Hit, Ray, Shape, offset_origin, sphere_roots};
use crate::walk::MAX_NULL_CROSSINGS;
use glam::Vec3;

impl Scene {
    /// Transmittance along the segment between two points, starting in `medium`: zero if
    /// anything but null boundaries blocks it, otherwise the product of exp(-sigma_t d) over
    /// the pieces between the null boundaries it crosses, each in its own medium. The ends
    /// are offset along their normals as in [`Scene::occluded`] (a zero normal, e.g. a point
    /// in a medium or a point light: no offset). Without media it is exactly 0 or 1.
    pub fn transmittance(
        &self,
        p0: Vec3,
        n0: Vec3,
        p1: Vec3,
        n1: Vec3,
        medium: Option<u32>,
    ) -> Rgb {
        if !self.has_media() {
            return if self.occluded(p0, n0, p1, n1) {
                Rgb::ZERO
            } else {
                Rgb::ONE
            };
        }
        let d = p1 - p0;
        let (from, to) = shadow_ends(p0, n0, p1, n1);
        let seg = to - from;
        let dist = seg.length();
        if dist <= 0.0 || seg.dot(d) <= 0.0 {
            return self.transmittance_between(medium, p0, p1);
        }
        if self.has_alpha {
            return self.transmittance_walk(p0, p1, from, to, medium);
        }
        // One traversal of the segment: it stops at the first blocker, and collects the null
        // boundaries crossed (a sphere may be crossed twice); they are then walked in order.
        let ray = Ray::new(from, seg / dist);
        let mut crossings = [(0.0f32, 0u32); MAX_COLLECTED_CROSSINGS];
        let mut n = 0;
        let mut overflow = false;
        let blocked = self.accel.visit(&ray, dist, |i, prim| {
            let material = &self.materials[self.objects[prim.object as usize].material as usize];
            if !material.value.is_null() {
                return prim.shape.intersect(&ray, dist).is_some();
            }
            for t in segment_crossings(&prim.shape, &ray, dist)
                .into_iter()
                .flatten()
            {
                if n < crossings.len() {
                    crossings[n] = (t, i);
                    n += 1;
                } else {
                    overflow = true;
                }
            }
            false
        });
        if blocked {
            return Rgb::ZERO;
        }
        if overflow {
            return self.transmittance_walk(p0, p1, from, to, medium);
        }
        let crossings = &mut crossings[..n];
        crossings.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let prims = self.accel.primitives();
        let mut tr = Rgb::ONE;
        let mut medium = medium;
        // Distances are measured from the end points themselves, not the offset origins.
        let mut last = p0;
        for &(t, i) in crossings.iter() {
            let p = ray.at(t);
            tr *= self.transmittance_between(medium, last, p);
            last = p;
            let hit = Hit {
                t,
                p,
                ng: prims[i as usize].shape.normal(p),
                prim: i,
            };
            medium = self.medium_after(&hit, ray.dir, medium);
        }
        tr * self.transmittance_between(medium, last, p1)
    }

    /// The transmittance of `medium` (one in vacuum) along the straight segment from `a` to
    /// `b`.
    fn transmittance_between(&self, medium: Option<u32>, a: Vec3, b: Vec3) -> Rgb {
        let Some(m) = medium else {
            return Rgb::ONE;
        };
        let d = a.distance(b);
        if d > 0.0 {
            self.medium(m).transmittance(&Ray::new(a, (b - a) / d), d)
        } else {
            Rgb::ONE
        }
    }

    /// [`Scene::transmittance`] by closest hits, one boundary after another: for segments
    /// that cross more boundaries than one traversal collects, and past cut-outs.
    fn transmittance_walk(
        &self,
        p0: Vec3,
        p1: Vec3,
        from: Vec3,
        to: Vec3,
        medium: Option<u32>,
    ) -> Rgb {
        let d = p1 - p0;
        let mut tr = Rgb::ONE;
        let mut medium = medium;
        let mut origin = from;
        let mut last = p0;
        for _ in 0..=MAX_NULL_CROSSINGS {
            let seg = to - origin;
            let dist = seg.length();
            if dist <= 0.0 || seg.dot(d) <= 0.0 {
                return tr * self.transmittance_between(medium, last, p1);
            }
            let ray = Ray::new(origin, seg / dist);
            let Some(hit) = self.intersect(&ray, dist) else {
                return tr * self.transmittance_between(medium, last, p1);
            };
            if !self.material(&hit).is_null() {
                return Rgb::ZERO;
            }
            tr *= self.transmittance_between(medium, last, hit.p);
            if tr == Rgb::ZERO {
                return tr;
            }
            last = hit.p;
            medium = self.medium_after(&hit, ray.dir, medium);
            origin = offset_origin(hit.p, hit.ng, ray.dir);
        }
        // Past the crossing limit the shadow ray is ended like any other ray (crate::walk).
        Rgb::ZERO
    }

    /// Whether the segment between two surface points is blocked by anything but null
    /// boundaries and cut-outs. The ends are offset along their normals (a zero normal: no offset).
    // Inlined: the shadow ray's set-up is a few vector operations on values the caller has in
    // registers, and a call per shadow ray cost 6 % of the path tracer's instructions.
    #[inline]
    pub fn occluded(&self, p0: Vec3, n0: Vec3, p1: Vec3, n1: Vec3) -> bool {
        let (from, to) = shadow_ends(p0, n0, p1, n1);
        let seg = to - from;
        let dist = seg.length();
        if dist <= 0.0 {
            return false;
        }
        if self.has_alpha {
            return self.occluded_past_cut_outs(from, to);
        }
        let ray = Ray::new(from, seg / dist);
        let prims_objects = &self.objects;
        let materials = &self.materials;
        self.accel.occluded(&ray, dist, |prim| {
            !materials[prims_objects[prim.object as usize].material as usize]
                .value
                .is_null()
        })
    }
}

/// The ends of a shadow ray between two points, each pushed off its surface along its normal
/// towards the other (a zero normal, a point in a medium or a point light: not moved).
#[inline]
fn shadow_ends(p0: Vec3, n0: Vec3, p1: Vec3, n1: Vec3) -> (Vec3, Vec3) {
    let d = p1 - p0;
    let from = if n0 == Vec3::ZERO {
        p0
    } else {
        offset_origin(p0, n0, d)
    };
    let to = if n1 == Vec3::ZERO {
        p1
    } else {
        offset_origin(p1, n1, -d)
    };
    (from, to)
}

/// Null-boundary crossings one traversal of a shadow ray collects; more, and it walks them
/// one closest hit at a time.
const MAX_COLLECTED_CROSSINGS: usize = 16;

/// Where a ray crosses a shape within (0, tmax): both roots of a sphere, the one point of a
/// quad or triangle.
fn segment_crossings(shape: &Shape, ray: &Ray, tmax: f32) -> [Option<f32>; 2] {
    match *shape {
        Shape::Sphere { center, radius, .. } => {
            let Some((t0, t1)) = sphere_roots(ray, center, radius) else {
                return [None, None];
            };
            let inside = |t: f32| (t > 0.0 && t < tmax).then_some(t);
            [inside(t0), inside(t1)]
        }
        _ => [shape.intersect(ray, tmax), None],
    }
}
