//! Cut-outs: shapes made partly absent by an `alpha` texture (pbrt-v4's `alpha` on shapes,
//! Mitsuba's `mask` BSDF). A ray passes where alpha is 0, stops where it is 1, and between
//! stops with probability alpha: a stochastic test, so that the expected image is alpha
//! times the shape's over 1 - alpha times what lies behind, as a blend would be, with every
//! estimator's ray queries unchanged. The test hashes the ray that meets the surface, as
//! pbrt-v4's does (its origin and direction), so that a query asked again answers the same;
//! a ray spawned past a cut-out has another origin, so each layer decides independently.

use super::Scene;
use crate::geometry::{Hit, Ray, offset_origin};
use crate::sampling::splitmix64;
use crate::texture::{Texture, scalar};
use glam::Vec3;

/// Cut-out hits one ray passes before the next is taken as opaque: a bound on the work of a
/// ray through dense foliage, far beyond what any image shows.
const MAX_CUT_OUT_CROSSINGS: usize = 4096;

impl Scene {
    /// The closest hit of `ray` that is not cut out, `hit` being its closest hit of all.
    #[inline(never)]
    pub(super) fn intersect_past_cut_outs(&self, ray: &Ray, tmax: f32, hit: Hit) -> Option<Hit> {
        let mut hit = hit;
        let mut origin = ray.origin;
        for _ in 0..MAX_CUT_OUT_CROSSINGS {
            if !self.cut_out(&hit, origin, ray.dir) {
                return Some(hit);
            }
            origin = offset_origin(hit.p, hit.ng, ray.dir);
            // Distances stay those of the original ray.
            let t0 = (origin - ray.origin).dot(ray.dir);
            if t0 >= tmax {
                return None;
            }
            let next = self
                .accel
                .intersect(&Ray::new(origin, ray.dir), tmax - t0)?;
            hit = Hit {
                t: t0 + next.t,
                ..next
            };
        }
        Some(hit)
    }

    /// Whether the ray from `origin` along `dir` passes the surface at `hit`.
    #[inline]
    fn cut_out(&self, hit: &Hit, origin: Vec3, dir: Vec3) -> bool {
        let Some(alpha) = &self.object(hit).alpha else {
            return false;
        };
        let a = match alpha {
            Texture::Constant(c) => scalar(*c),
            t => scalar(t.eval(self.surface(hit).texture_ctx())),
        };
        if a >= 1.0 {
            false
        } else if a <= 0.0 {
            true
        } else {
            ray_hash(origin, dir) >= a
        }
    }

    /// [`Scene::occluded`] in a scene with cut-outs: closest hits past them, one after
    /// another through null boundaries, from `from` to `to`.
    #[inline(never)]
    pub(super) fn occluded_past_cut_outs(&self, from: Vec3, to: Vec3) -> bool {
        let mut origin = from;
        for _ in 0..=crate::walk::MAX_NULL_CROSSINGS {
            let seg = to - origin;
            let dist = seg.length();
            if dist <= 0.0 || seg.dot(to - from) <= 0.0 {
                return false;
            }
            let ray = Ray::new(origin, seg / dist);
            let Some(hit) = self.intersect(&ray, dist) else {
                return false;
            };
            if !self.material(&hit).is_null() {
                return true;
            }
            origin = offset_origin(hit.p, hit.ng, ray.dir);
        }
        // Past the crossing limit the shadow ray is ended like any other ray (crate::walk).
        true
    }
}

/// A number in [0, 1) determined by a ray (its origin's and direction's bits).
#[inline]
fn ray_hash(origin: Vec3, dir: Vec3) -> f32 {
    let bits = |v: Vec3| {
        (
            u64::from(v.x.to_bits()) << 32 | u64::from(v.y.to_bits()),
            u64::from(v.z.to_bits()),
        )
    };
    let (a, b) = bits(origin);
    let (c, d) = bits(dir);
    let h = splitmix64(splitmix64(splitmix64(splitmix64(a) ^ b) ^ c) ^ d);
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}
