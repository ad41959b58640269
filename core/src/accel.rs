//! One BVH over every primitive in the scene (obvhs' compressed wide BVH8).
//!
//! **Wide node tests.** obvhs tests a node's eight children four at a time with SSE2 (the
//! baseline of x86-64), converting its quantised bounds to floats one byte at a time. Where
//! the processor has AVX2 (checked once, at run time: the program still runs on any x86-64),
//! closest-hit and shadow rays are traversed by the same loop (obvhs' `traverse!`) with a node
//! test that converts and tests all eight children at once ([`simd`]); the traversal, and the
//! primitive tests inlined into it, are then compiled for x86-64-v3. Its arithmetic is
//! obvhs' own (the same products and sums, no fused multiply-add), so it culls exactly the
//! same children and renders the same images.

use crate::geometry::{Hit, Primitive, Ray};
use glam::Vec3;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::{Ray as BvhRay, RayHit};

pub struct Accel {
    bvh: Option<CwBvh>,
    /// Primitives in BVH leaf order, so a traversal id indexes them directly.
    prims: Vec<Primitive>,
    /// Traverse with the eight-wide node test (the processor has AVX2; see the module comment).
    wide: bool,
}

/// obvhs' ray for `ray` up to `tmax`. obvhs 0.4 takes a ray's octant from `d < 0.0` (false
/// for -0.0) but its inverse direction from the sign (-inf for -0.0): for a component -0.0
/// (`-Vec3::Y`, a negated or reflected axis direction) the two disagree and the traversal
/// misses every box. Adding +0.0 turns -0.0 into +0.0 and leaves every other value as it is.
#[inline]
fn bvh_ray(ray: &Ray, tmax: f32) -> BvhRay {
    BvhRay::new(ray.origin.into(), (ray.dir + Vec3::ZERO).into(), 0.0, tmax)
}

impl Accel {
    pub fn build(prims: Vec<Primitive>) -> Accel {
        let wide = simd::available();
        if prims.is_empty() {
            return Accel {
                bvh: None,
                prims,
                wide,
            };
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
            wide,
        }
    }

    /// The same BVH traversed with obvhs' own node test only (`wide` false), or with the
    /// wide one where the processor has it (true): for tests and benchmarks.
    pub fn set_wide(&mut self, wide: bool) {
        self.wide = wide && simd::available();
    }

    /// Whether traversals use the eight-wide node test.
    pub fn wide(&self) -> bool {
        self.wide
    }

    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// Closest intersection with t in (0, tmax).
    #[inline]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let bray = bvh_ray(ray, tmax);
        let mut hit = RayHit::none();
        let test = |r: &BvhRay, id: usize| {
            self.prims[id]
                .shape
                .intersect(ray, r.tmax)
                .unwrap_or(f32::INFINITY)
        };
        let found = if self.wide {
            simd::closest(bvh, bray, &mut hit, test)
        } else {
            bvh.ray_traverse(bray, &mut hit, test)
        };
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
        let bray = bvh_ray(ray, tmax);
        let test = |r: &BvhRay, id: usize| blocker_distance(&self.prims[id], &blocks, ray, r);
        if self.wide {
            !simd::miss(bvh, bray, test)
        } else {
            !bvh.ray_traverse_miss(bray, test)
        }
    }

    /// Calls `f(primitive index, t)` for every primitive the ray meets within (0, tmax), in no
    /// particular order (medium boundaries need every crossing, not only the closest).
    pub fn for_each_hit(&self, ray: &Ray, tmax: f32, mut f: impl FnMut(u32, f32)) {
        let Some(bvh) = self.bvh.as_ref() else {
            return;
        };
        let bray = bvh_ray(ray, tmax);
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
        let bray = bvh_ray(ray, tmax);
        !bvh.ray_traverse_miss(bray, |_, id| {
            if visit(id as u32, &self.prims[id]) {
                0.0
            } else {
                f32::INFINITY
            }
        })
    }
}

/// The distance to `prim` along a shadow ray if it blocks it (`blocks`), else infinity.
// Forced inline: the wide traversal did not take the closure in by itself (a call per
// primitive tested, 1% of the path tracer's instructions).
#[inline(always)]
fn blocker_distance(
    prim: &Primitive,
    blocks: &impl Fn(&Primitive) -> bool,
    ray: &Ray,
    r: &BvhRay,
) -> f32 {
    if !blocks(prim) {
        return f32::INFINITY;
    }
    prim.shape.intersect(ray, r.tmax).unwrap_or(f32::INFINITY)
}

/// The eight-wide node test and the traversals that use it (x86-64 with AVX2; elsewhere
/// `available` is false and the traversals are obvhs' own).
mod simd {
    use obvhs::cwbvh::CwBvh;
    use obvhs::ray::{Ray as BvhRay, RayHit};

    /// Whether the processor has what the wide traversal is compiled for.
    pub fn available() -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("bmi1")
                && std::arch::is_x86_feature_detected!("lzcnt")
                && std::arch::is_x86_feature_detected!("popcnt")
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    }

    /// obvhs' `ray_traverse` (closest hit) with the wide node test. Only where [`available`].
    #[inline(always)]
    pub fn closest<F: FnMut(&BvhRay, usize) -> f32>(
        bvh: &CwBvh,
        ray: BvhRay,
        hit: &mut RayHit,
        f: F,
    ) -> bool {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the caller checked `available()` (Accel::wide).
        unsafe {
            x86::closest(bvh, ray, hit, f)
        }
        #[cfg(not(target_arch = "x86_64"))]
        bvh.ray_traverse(ray, hit, f)
    }

    /// obvhs' `ray_traverse_miss` (true if nothing is hit) with the wide node test. Only where
    /// [`available`].
    #[inline(always)]
    pub fn miss<F: FnMut(&BvhRay, usize) -> f32>(bvh: &CwBvh, ray: BvhRay, f: F) -> bool {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the caller checked `available()` (Accel::wide).
        unsafe {
            x86::miss(bvh, ray, f)
        }
        #[cfg(not(target_arch = "x86_64"))]
        bvh.ray_traverse_miss(ray, f)
    }

    #[cfg(target_arch = "x86_64")]
    pub(super) mod x86 {
        use glam::{UVec2, Vec3A};
        use obvhs::cwbvh::CwBvh;
        use obvhs::cwbvh::node::{CwBvhNode, extract_byte64};
        use obvhs::ray::{Ray as BvhRay, RayHit};
        use std::arch::x86_64::*;

        /// obvhs' lower bound on a child's entry distance (its `node::EPSILON`, not public).
        const EPSILON: f32 = 0.0001;

        /// The children of `node` that `ray` enters, as obvhs' `CwBvhNode::intersect_ray`
        /// gives them (the traversal's hit mask), all eight tested at once: each byte row of
        /// quantised bounds widened to eight floats in two instructions, where obvhs builds
        /// two vectors of four from single bytes. The same operations in the same order as
        /// obvhs' SSE test, so the same children are culled, bit for bit.
        #[target_feature(enable = "avx2,bmi1,lzcnt,popcnt")]
        #[inline]
        pub unsafe fn intersect_node(node: &CwBvhNode, ray: &BvhRay, oct_inv4: u32) -> u32 {
            let dir_inv = node.compute_extent() * ray.inv_direction;
            let origin = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
            // Eight bytes to eight floats.
            let q = |v: &[u8; 8]| {
                // SAFETY: reads the eight bytes of `v`.
                let bytes = unsafe { _mm_loadl_epi64(v.as_ptr() as *const __m128i) };
                _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(bytes))
            };
            // The slab of one axis: entry and exit distances, near plane first.
            let slab = |lo: &[u8; 8], hi: &[u8; 8], negative: bool, d: f32, o: f32| {
                let (lo, hi) = (q(lo), q(hi));
                let (near, far) = if negative { (hi, lo) } else { (lo, hi) };
                let (d, o) = (_mm256_set1_ps(d), _mm256_set1_ps(o));
                (
                    _mm256_add_ps(_mm256_mul_ps(near, d), o),
                    _mm256_add_ps(_mm256_mul_ps(far, d), o),
                )
            };
            let (tmin_x, tmax_x) = slab(
                &node.child_min_x,
                &node.child_max_x,
                ray.direction.x < 0.0,
                dir_inv.x,
                origin.x,
            );
            let (tmin_y, tmax_y) = slab(
                &node.child_min_y,
                &node.child_max_y,
                ray.direction.y < 0.0,
                dir_inv.y,
                origin.y,
            );
            let (tmin_z, tmax_z) = slab(
                &node.child_min_z,
                &node.child_max_z,
                ray.direction.z < 0.0,
                dir_inv.z,
                origin.z,
            );
            let tmin = _mm256_max_ps(tmin_x, _mm256_max_ps(tmin_y, tmin_z));
            let tmax = _mm256_min_ps(tmax_x, _mm256_min_ps(tmax_y, tmax_z));
            let tmin = _mm256_max_ps(tmin, _mm256_set1_ps(EPSILON));
            let tmax = _mm256_min_ps(tmax, _mm256_set1_ps(ray.tmax));
            // _mm_cmple_ps's predicate: false when either is NaN.
            let mut entered = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OS>(tmin, tmax)) as u32;
            let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
            let mut hit_mask = 0u32;
            while entered != 0 {
                let child = entered.trailing_zeros() as usize;
                entered &= entered - 1;
                hit_mask |= extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
            }
            hit_mask
        }

        /// See [`super::closest`].
        #[target_feature(enable = "avx2,bmi1,lzcnt,popcnt")]
        pub unsafe fn closest<F: FnMut(&BvhRay, usize) -> f32>(
            bvh: &CwBvh,
            ray: BvhRay,
            hit: &mut RayHit,
            mut f: F,
        ) -> bool {
            let mut traverse_ray = ray;
            let mut state = bvh.new_traversal(ray.direction);
            let mut node;
            obvhs::traverse!(
                bvh,
                node,
                state,
                // SAFETY: this function's features are the node test's.
                unsafe { intersect_node(node, &traverse_ray, state.oct_inv4) },
                {
                    let t = f(&traverse_ray, state.primitive_id as usize);
                    if t < traverse_ray.tmax {
                        hit.primitive_id = state.primitive_id;
                        hit.t = t;
                        traverse_ray.tmax = t;
                    }
                }
            );
            hit.t < ray.tmax
        }

        /// See [`super::miss`].
        #[target_feature(enable = "avx2,bmi1,lzcnt,popcnt")]
        pub unsafe fn miss<F: FnMut(&BvhRay, usize) -> f32>(
            bvh: &CwBvh,
            ray: BvhRay,
            mut f: F,
        ) -> bool {
            let mut state = bvh.new_traversal(ray.direction);
            let mut node;
            let mut miss = true;
            'outer: {
                obvhs::traverse!(
                    bvh,
                    node,
                    state,
                    // SAFETY: this function's features are the node test's.
                    unsafe { intersect_node(node, &ray, state.oct_inv4) },
                    {
                        let t = f(&ray, state.primitive_id as usize);
                        if t < ray.tmax {
                            miss = false;
                            break 'outer;
                        }
                    }
                );
            }
            miss
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Shape;
    use crate::sampling::{Rng, uniform_sphere};
    use glam::Vec3;

    /// Spheres and quads scattered in a box: a BVH of several levels.
    fn scene(rng: &mut Rng, n: usize) -> Vec<Primitive> {
        let mut point = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
        (0..n)
            .map(|i| {
                let shape = if i % 2 == 0 {
                    Shape::sphere(point(), 0.05 + 0.3 * (i % 7) as f32 / 7.0)
                } else {
                    let o = point();
                    Shape::quad(o, (point() - o) * 0.1, (point() - o) * 0.1)
                };
                Primitive {
                    shape,
                    object: 0,
                    attrs: crate::geometry::NO_ATTRS,
                }
            })
            .collect()
    }

    /// The wide node test culls exactly what obvhs' own does (every node, random rays,
    /// random tmax), and the traversals built on it find the same closest hits and the same
    /// blocked shadow rays.
    #[test]
    fn wide_traversal_matches_obvhs() {
        if !simd::available() {
            eprintln!("no AVX2 here: the wide traversal is not used, nothing to compare");
            return;
        }
        let mut rng = Rng::new(&[3]);
        let prims = scene(&mut rng, 300);
        let mut accel = Accel::build(prims);
        let bvh = accel.bvh.as_ref().unwrap();
        let mut masks = 0;
        for _ in 0..2000 {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0;
            let d = uniform_sphere(rng.next_2d());
            let tmax = if rng.next_f32() < 0.5 {
                f32::INFINITY
            } else {
                rng.next_f32() * 8.0
            };
            let bray = BvhRay::new(o.into(), d.into(), 0.0, tmax);
            let oct_inv4 = bvh.new_traversal(bray.direction).oct_inv4;
            for node in &bvh.nodes {
                let want = node.intersect_ray(&bray, oct_inv4);
                #[cfg(target_arch = "x86_64")]
                // SAFETY: AVX2 is available (checked above).
                let got = unsafe { simd::x86::intersect_node(node, &bray, oct_inv4) };
                #[cfg(not(target_arch = "x86_64"))]
                let got = want;
                assert_eq!(got, want);
                masks += (want != 0) as u32;
            }
        }
        assert!(masks > 1000, "too few nodes entered to compare: {masks}");
        let mut rays = Vec::new();
        for _ in 0..5000 {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0;
            rays.push((
                Ray::new(o, uniform_sphere(rng.next_2d())),
                rng.next_f32() * 12.0,
            ));
        }
        let trace = |accel: &Accel| -> Vec<(Option<(u32, u32)>, bool)> {
            rays.iter()
                .map(|(ray, tmax)| {
                    let hit = accel
                        .intersect(ray, f32::INFINITY)
                        .map(|h| (h.prim, h.t.to_bits()));
                    (hit, accel.occluded(ray, *tmax, |_| true))
                })
                .collect()
        };
        let wide = trace(&accel);
        accel.set_wide(false);
        let narrow = trace(&accel);
        assert_eq!(wide, narrow);
        let hits = wide.iter().filter(|(h, _)| h.is_some()).count();
        let blocked = wide.iter().filter(|(_, b)| *b).count();
        assert!(
            hits > 500 && blocked > 200 && blocked < 4900,
            "{hits} {blocked}"
        );
    }

    /// A direction with a -0.0 component (the axis directions written as `-Vec3::Y`, what
    /// negating or reflecting a vector gives) finds what the same direction with +0.0 finds:
    /// obvhs 0.4 takes a ray's octant from `d < 0.0` and its inverse direction from the sign,
    /// which disagree for -0.0, and its traversal then missed every box.
    #[test]
    fn negative_zero_directions_hit_what_positive_zero_ones_hit() {
        let mut prims: Vec<Primitive> = (0..16)
            .map(|i| Primitive {
                shape: Shape::sphere(Vec3::new(i as f32 * 3.0, 5.0, 0.0), 0.5),
                object: 0,
                attrs: crate::geometry::NO_ATTRS,
            })
            .collect();
        prims.push(Primitive {
            shape: Shape::quad(Vec3::new(-1.0, 0.0, -1.0), Vec3::X * 50.0, Vec3::Z * 2.0),
            object: 0,
            attrs: crate::geometry::NO_ATTRS,
        });
        for narrow in [false, true] {
            let mut accel = Accel::build(prims.clone());
            if narrow {
                accel.wide = false;
            }
            for (origin, dir) in [
                (Vec3::new(0.0, 10.0, 0.0), -Vec3::Y),
                (Vec3::new(6.0, 2.0, 0.0), -Vec3::Y),
                (Vec3::new(6.0, 10.0, 0.0), Vec3::new(-0.0, -1.0, 0.0)),
                (Vec3::new(-5.0, 5.0, -0.0), Vec3::new(1.0, -0.0, -0.0)),
            ] {
                let positive = dir + Vec3::ZERO;
                let ray = Ray::new(origin, dir);
                let expected = accel.intersect(&Ray::new(origin, positive), 100.0);
                assert!(
                    expected.is_some(),
                    "the scene is hit from {origin} along {positive}"
                );
                let hit = accel.intersect(&ray, 100.0);
                assert_eq!(
                    hit.map(|h| h.t),
                    expected.map(|h| h.t),
                    "from {origin} along {dir:?} (narrow {narrow})"
                );
                assert!(
                    accel.occluded(&ray, 100.0, |_| true),
                    "shadow ray along {dir:?}"
                );
            }
        }
    }
}
