//! A BVH of bare boxes, each known by a number: what a structure of many small boxes that are
//! not scene geometry needs (photon beams' pieces), at 17 bytes or so a box.
//!
//! The same tree as [`Accel::build_boxes`](super::Accel::build_boxes) builds over primitives
//! with those boxes, traversed the same way (the eight-wide node test where the processor has
//! AVX2), but holding only each box's number in leaf order: no primitive (60 bytes) and no
//! obvhs index list (4 bytes) per box.

use super::{bvh_ray, simd};
use crate::geometry::Ray;
use glam::Vec3;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;

pub struct BoxBvh {
    bvh: Option<CwBvh>,
    /// The boxes' numbers in the BVH's leaf order.
    ids: Vec<u32>,
    /// Traverse with the eight-wide node test (the processor has AVX2).
    wide: bool,
}

impl BoxBvh {
    /// The BVH over `boxes` (lower and upper corners), box i known as `ids[i]`.
    pub fn build(boxes: &[(Vec3, Vec3)], ids: &[u32]) -> BoxBvh {
        assert_eq!(boxes.len(), ids.len(), "one number a box");
        let wide = simd::available();
        if boxes.is_empty() {
            return BoxBvh {
                bvh: None,
                ids: Vec::new(),
                wide,
            };
        }
        let aabbs: Vec<Aabb> = boxes
            .iter()
            .map(|&(lo, hi)| Aabb::new(lo.into(), hi.into()))
            .collect();
        let mut bvh = build_cwbvh(
            &aabbs,
            BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        let ids = bvh
            .primitive_indices
            .iter()
            .map(|&i| ids[i as usize])
            .collect();
        // The traversal hands over leaf positions, which `ids` now maps.
        bvh.primitive_indices = Vec::new();
        // obvhs reserves a node a box; a tenth of that is used.
        bvh.nodes.shrink_to_fit();
        BoxBvh {
            bvh: Some(bvh),
            ids,
            wide,
        }
    }

    /// Calls `visit(id)` for every box the segment from `ray.origin` to `ray.at(tmax)` may
    /// enter (obvhs' culling: its quantised node boxes, entry distances from 1e-4).
    #[inline]
    pub fn visit(&self, ray: &Ray, tmax: f32, mut visit: impl FnMut(u32)) {
        let Some(bvh) = self.bvh.as_ref() else {
            return;
        };
        let bray = bvh_ray(ray, tmax);
        let each = |_: &obvhs::ray::Ray, k: usize| {
            visit(self.ids[k]);
            f32::INFINITY
        };
        if self.wide {
            simd::miss(bvh, bray, each);
        } else {
            bvh.ray_traverse_miss(bray, each);
        }
    }

    /// The bytes the BVH holds on the heap: its nodes and the boxes' numbers.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.bvh.as_ref().map_or(0, |b| {
            b.nodes.capacity() * size_of::<obvhs::cwbvh::node::CwBvhNode>()
        }) + self.ids.capacity() * size_of::<u32>()
    }

    /// Whether traversals use the eight-wide node test.
    pub fn wide(&self) -> bool {
        self.wide
    }

    /// The same BVH traversed with obvhs' own traversal (`wide` false), or with the
    /// eight-wide node test where the processor has it: for tests and benchmarks.
    pub fn set_wide(&mut self, wide: bool) {
        self.wide = wide && simd::available();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Accel;
    use crate::geometry::{NO_ATTRS, Primitive, Shape};
    use crate::sampling::Rng;

    /// The same boxes offered in the same order as an `Accel` of flat triangles spanning them
    /// offers its primitives, with either traversal.
    #[test]
    fn offers_what_a_bvh_of_the_same_boxes_offers() {
        let mut rng = Rng::new(&[3]);
        let mut v = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let prims: Vec<Primitive> = (0..3000)
            .map(|i| Primitive {
                shape: Shape::Triangle {
                    p0: v() * 10.0,
                    e1: v() * 0.5,
                    e2: Vec3::ZERO,
                },
                object: 7 * i,
                attrs: NO_ATTRS,
            })
            .collect();
        let boxes: Vec<(Vec3, Vec3)> = prims
            .iter()
            .map(|p| {
                let b = p.shape.aabb();
                (b.min.into(), b.max.into())
            })
            .collect();
        let ids: Vec<u32> = prims.iter().map(|p| p.object).collect();
        let mut accel = Accel::build_boxes(prims);
        let mut bvh = BoxBvh::build(&boxes, &ids);
        let mut offered = 0;
        for wide in [true, false] {
            accel.set_wide(wide);
            bvh.set_wide(wide);
            for _ in 0..300 {
                let ray = Ray::new(v() * 10.0, (v() - 0.5).normalize());
                let tmax = v().x * 8.0;
                let want = std::cell::RefCell::new(Vec::new());
                accel.occluded(&ray, tmax, |p| {
                    want.borrow_mut().push(p.object);
                    false
                });
                let mut got = Vec::new();
                bvh.visit(&ray, tmax, |id| got.push(id));
                assert_eq!(got, want.into_inner());
                offered += got.len();
            }
        }
        assert!(offered > 500, "{offered}");
    }
}
