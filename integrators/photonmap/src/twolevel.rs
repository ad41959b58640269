//! A BVH of boxes built in parallel with the same tree for any number of threads: the beam
//! maps' (`beams`, `screen`), rebuilt every pass.
//!
//! obvhs builds its BVH on one thread (its `parallel` feature builds other trees, whose shape
//! depends on the threads' timing, so images would too), and a progressive pass builds a BVH
//! over tens of thousands of beam pieces: on one thread that was a third of `ppb`'s time at two
//! threads. Here the boxes are first split at the median of their centres along the widest
//! axis, [`levels`] times (core's `median_split`: a complete binary tree whose shape depends
//! only on the boxes),
//! and obvhs builds each of the leaves' BVHs, all at once on the pool's threads. A query
//! tests the top tree's boxes, then walks the leaves' BVHs it reaches, left to right, so
//! the order in which it offers primitives is fixed too.
//!
//! The median split is worse than obvhs' own top levels only where the boxes are very
//! unevenly spread; with at least [`LEAF`] boxes a leaf, a few tens of top boxes are tested
//! against obvhs' thousands of node boxes per query.

use foton_core::api::{BoxBvh, Ray, Vec3, median_parts, median_split};
use rayon::prelude::*;

/// The fewest boxes a leaf BVH is split down to (a leaf holds between this and twice this).
pub const LEAF: usize = 2048;

/// The top tree's depth for `n` boxes: leaves of [`LEAF`] to 2 [`LEAF`] boxes, at most 256.
pub fn levels(n: usize) -> u32 {
    let mut levels = 0;
    while levels < 8 && n >> (levels + 1) >= LEAF {
        levels += 1;
    }
    levels
}

/// Boxes, each known by a number, in a top tree of median splits over obvhs BVHs (core's
/// [`BoxBvh`]).
pub struct TwoLevelBvh {
    /// The top tree's boxes in heap order (node k's children are 2k + 1 and 2k + 2); the last
    /// `leaves.len()` are the leaves'. Empty boxes (lo > hi) where a leaf has no box.
    boxes: Vec<(Vec3, Vec3)>,
    leaves: Vec<BoxBvh>,
}

fn union(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> (Vec3, Vec3) {
    (a.0.min(b.0), a.1.max(b.1))
}

const EMPTY: (Vec3, Vec3) = (Vec3::INFINITY, Vec3::NEG_INFINITY);

impl TwoLevelBvh {
    /// The tree over `boxes` (lower corner, upper corner, the box's number), built on the
    /// current rayon pool's threads.
    pub fn build(boxes: Vec<(Vec3, Vec3, u32)>) -> TwoLevelBvh {
        let levels = levels(boxes.len());
        let mut items: Vec<([f32; 3], u32)> = boxes
            .par_iter()
            .enumerate()
            .map(|(index, &(lo, hi, _))| (((lo + hi) * 0.5).to_array(), index as u32))
            .collect();
        median_split(&mut items, levels);
        let ranges = median_parts(items.len(), levels);
        let built: Vec<((Vec3, Vec3), BoxBvh)> = ranges
            .par_iter()
            .map(|&(lo, hi)| {
                let leaf = &items[lo..hi];
                let corners: Vec<(Vec3, Vec3)> = leaf
                    .iter()
                    .map(|&(_, i)| {
                        let (lo, hi, _) = boxes[i as usize];
                        (lo, hi)
                    })
                    .collect();
                let ids: Vec<u32> = leaf.iter().map(|&(_, i)| boxes[i as usize].2).collect();
                let bounds = corners.iter().fold(EMPTY, |acc, &b| union(acc, b));
                (bounds, BoxBvh::build(&corners, &ids))
            })
            .collect();
        let inner = (1 << levels) - 1;
        let mut tops = vec![EMPTY; inner];
        let mut leaves = Vec::with_capacity(built.len());
        for (bounds, bvh) in built {
            tops.push(bounds);
            leaves.push(bvh);
        }
        for k in (0..inner).rev() {
            tops[k] = union(tops[2 * k + 1], tops[2 * k + 2]);
        }
        TwoLevelBvh {
            boxes: tops,
            leaves,
        }
    }

    /// The bytes the tree holds on the heap: its top boxes and its leaves' BVHs.
    pub fn heap_bytes(&self) -> usize {
        self.boxes.capacity() * std::mem::size_of::<(Vec3, Vec3)>()
            + self.leaves.capacity() * std::mem::size_of::<BoxBvh>()
            + self.leaves.iter().map(BoxBvh::heap_bytes).sum::<usize>()
    }

    /// Calls `visit(id)` for the boxes the segment from `ray.origin` to `ray.at(t_end)` may
    /// cross (obvhs' culling in the leaves: a superset of those it crosses), leaf by leaf from
    /// left to right.
    pub fn visit(&self, ray: &Ray, t_end: f32, mut visit: impl FnMut(u32)) {
        let inner = self.boxes.len() - self.leaves.len();
        let inv = Vec3::ONE / ray.dir;
        let mut stack = [0usize; 16];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let k = stack[top];
            if !slab(self.boxes[k], ray, inv, t_end) {
                continue;
            }
            if k < inner {
                stack[top] = 2 * k + 2;
                stack[top + 1] = 2 * k + 1;
                top += 2;
            } else {
                self.leaves[k - inner].visit(ray, t_end, &mut visit);
            }
        }
    }
}

/// Whether the segment [0, t_end] of `ray` may cross the box `(lo, hi)`: a slab test
/// with a margin of a thousandth of the box's size (it only culls: the leaves' BVHs test
/// the boxes themselves).
#[inline]
fn slab((lo, hi): (Vec3, Vec3), ray: &Ray, inv: Vec3, t_end: f32) -> bool {
    if lo.x > hi.x {
        return false;
    }
    let pad = (hi - lo).max_element() * 1e-3 + 1e-6 * lo.abs().max(hi.abs()).max_element();
    let (lo, hi) = (lo - Vec3::splat(pad), hi + Vec3::splat(pad));
    let (mut near, mut far) = (0.0f32, t_end);
    for i in 0..3 {
        if ray.dir[i] == 0.0 {
            if ray.origin[i] < lo[i] || ray.origin[i] > hi[i] {
                return false;
            }
            continue;
        }
        let (t0, t1) = (
            (lo[i] - ray.origin[i]) * inv[i],
            (hi[i] - ray.origin[i]) * inv[i],
        );
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    near <= far
}

#[cfg(test)]
mod tests {
    use super::*;
    use foton_core::api::Rng;

    fn boxes(rng: &mut Rng, n: usize) -> Vec<(Vec3, Vec3, u32)> {
        (0..n)
            .map(|i| {
                let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32() * 0.1) * 10.0;
                let e = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 0.3;
                (p, p + e, 3 * i as u32)
            })
            .collect()
    }

    /// Whether the segment passes well inside the box (clear of what rounding decides).
    fn crosses((lo, hi, _): (Vec3, Vec3, u32), ray: &Ray, t_end: f32) -> bool {
        let (lo, hi) = (lo + 0.01, hi - 0.01);
        let (mut near, mut far) = (0.01f32, t_end - 0.01);
        for i in 0..3 {
            if ray.dir[i] == 0.0 {
                if ray.origin[i] <= lo[i] || ray.origin[i] >= hi[i] {
                    return false;
                }
                continue;
            }
            let t0 = (lo[i] - ray.origin[i]) / ray.dir[i];
            let t1 = (hi[i] - ray.origin[i]) / ray.dir[i];
            near = near.max(t0.min(t1));
            far = far.min(t0.max(t1));
        }
        near < far
    }

    #[test]
    fn levels_keep_leaves_between_one_and_two_leaf_sizes() {
        assert_eq!(levels(0), 0);
        assert_eq!(levels(2 * LEAF - 1), 0);
        assert_eq!(levels(2 * LEAF), 1);
        for n in [5000, 52_000, 300_000] {
            let leaf = n >> levels(n);
            assert!((LEAF..2 * LEAF).contains(&leaf), "{n}: {leaf}");
        }
        assert_eq!(levels(usize::MAX / 2), 8);
    }

    /// Every box a segment crosses is offered, once, whatever the pool, in the same order.
    #[test]
    fn offers_every_crossed_box_once_in_the_same_order_on_any_pool() {
        let mut rng = Rng::new(&[7]);
        let all = boxes(&mut rng, 9000);
        let build = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| TwoLevelBvh::build(all.clone()))
        };
        let (one, three) = (build(1), build(3));
        assert_eq!(one.leaves.len(), 4);
        let mut offered_total = 0;
        for i in 0..400 {
            let o = Vec3::new(
                rng.next_f32() * 12.0 - 1.0,
                rng.next_f32() * 12.0 - 1.0,
                rng.next_f32(),
            );
            let mut d = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
            if i % 7 == 0 {
                d.z = 0.0; // parallel to a slab
            }
            let ray = Ray::new(o, d.normalize());
            let t_end = rng.next_f32() * 15.0;
            let mut a = Vec::new();
            one.visit(&ray, t_end, |id| a.push(id));
            let mut b = Vec::new();
            three.visit(&ray, t_end, |id| b.push(id));
            assert_eq!(a, b);
            let mut sorted = a.clone();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), a.len(), "a box offered twice");
            for &bx in &all {
                if crosses(bx, &ray, t_end) {
                    assert!(sorted.binary_search(&bx.2).is_ok(), "missed {}", bx.2);
                }
            }
            offered_total += a.len();
        }
        assert!(offered_total > 1000, "{offered_total}");
    }
}
