//! One BVH over every primitive in the scene (obvhs' compressed wide BVH8).

use crate::geometry::{Hit, Primitive, Ray};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::{Ray as BvhRay, RayHit};

pub struct Accel {
    bvh: Option<CwBvh>,
    /// Primitives in BVH leaf order, so a traversal id indexes them directly.
    prims: Vec<Primitive>,
}

impl Accel {
    pub fn build(prims: Vec<Primitive>) -> Accel {
        if prims.is_empty() {
            return Accel { bvh: None, prims };
        }
        let aabbs: Vec<Aabb> = prims.iter().map(|p| p.shape.aabb()).collect();
        let bvh = build_cwbvh(
            &aabbs,
            BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        let ordered = bvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        Accel {
            bvh: Some(bvh),
            prims: ordered,
        }
    }

    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// Closest intersection with t in (0, tmax).
    #[inline]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let bray = BvhRay::new(ray.origin.into(), ray.dir.into(), 0.0, tmax);
        let mut hit = RayHit::none();
        let found = bvh.ray_traverse(bray, &mut hit, |r, id| {
            self.prims[id]
                .shape
                .intersect(ray, r.tmax)
                .unwrap_or(f32::INFINITY)
        });
        if !found {
            return None;
        }
        let prim = &self.prims[hit.primitive_id as usize];
        let p = ray.at(hit.t);
        Some(Hit {
            t: hit.t,
            p,
            ng: prim.shape.normal(p),
            prim: hit.primitive_id,
        })
    }

    /// Whether any primitive accepted by `blocks` lies on the ray within (0, tmax). Stops at the
    /// first such hit (shadow rays need no closest hit).
    #[inline]
    pub fn occluded(&self, ray: &Ray, tmax: f32, blocks: impl Fn(&Primitive) -> bool) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let bray = BvhRay::new(ray.origin.into(), ray.dir.into(), 0.0, tmax);
        !bvh.ray_traverse_miss(bray, |r, id| {
            let prim = &self.prims[id];
            if !blocks(prim) {
                return f32::INFINITY;
            }
            prim.shape.intersect(ray, r.tmax).unwrap_or(f32::INFINITY)
        })
    }

    /// Calls `f(primitive index, t)` for every primitive the ray meets within (0, tmax), in no
    /// particular order (medium boundaries need every crossing, not only the closest).
    pub fn for_each_hit(&self, ray: &Ray, tmax: f32, mut f: impl FnMut(u32, f32)) {
        let Some(bvh) = self.bvh.as_ref() else {
            return;
        };
        let bray = BvhRay::new(ray.origin.into(), ray.dir.into(), 0.0, tmax);
        bvh.ray_traverse_anyhit(bray, |_, id| {
            if let Some(t) = self.prims[id].shape.intersect(ray, tmax) {
                f(id as u32, t);
            }
        });
    }

    /// Offers `visit` every primitive whose box the ray crosses within (0, tmax), in no
    /// particular order, until it returns true; returns whether it did. (A shadow ray that
    /// must both find blockers and collect what it passes.)
    pub fn visit(
        &self,
        ray: &Ray,
        tmax: f32,
        mut visit: impl FnMut(u32, &Primitive) -> bool,
    ) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let bray = BvhRay::new(ray.origin.into(), ray.dir.into(), 0.0, tmax);
        !bvh.ray_traverse_miss(bray, |_, id| {
            if visit(id as u32, &self.prims[id]) {
                0.0
            } else {
                f32::INFINITY
            }
        })
    }
}
