//! The eight-wide node test and the traversals that use it (x86-64 with AVX2; elsewhere
//! `available` is false and the traversals are obvhs' own).

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
        let slab = |lo: &[u8; 8], hi: &[u8; 8], axis: usize| {
            let (lo, hi) = (q(lo), q(hi));
            let (near, far) = if ray.direction[axis] < 0.0 {
                (hi, lo)
            } else {
                (lo, hi)
            };
            let (d, o) = (_mm256_set1_ps(dir_inv[axis]), _mm256_set1_ps(origin[axis]));
            (
                _mm256_add_ps(_mm256_mul_ps(near, d), o),
                _mm256_add_ps(_mm256_mul_ps(far, d), o),
            )
        };
        let (tmin_x, tmax_x) = slab(&node.child_min_x, &node.child_max_x, 0);
        let (tmin_y, tmax_y) = slab(&node.child_min_y, &node.child_max_y, 1);
        let (tmin_z, tmax_z) = slab(&node.child_min_z, &node.child_max_z, 2);
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
