//! The float nodes of the scene's BVH (the module comment of [`super`]) and the closest-hit
//! and shadow-ray traversals that walk them.

use super::Accel;
use crate::geometry::{Primitive, Ray};
use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use std::mem::MaybeUninit;

impl Accel {
    /// Closest hit through the float nodes: (t, primitive index). Children are visited
    /// nearest entry first, and a subtree whose entry lies past the closest hit so far is
    /// skipped.
    #[inline]
    pub(super) fn closest(&self, ray: &Ray, tmax: f32) -> Option<(f32, u32)> {
        let slab = Slab::new(ray);
        let mut tmax = tmax;
        let mut best = None;
        let mut stack = [MaybeUninit::<Entry>::uninit(); STACK];
        let mut sp = 0usize;
        let mut cur = Entry {
            item: 0,
            count: 0,
            t: 0.0,
        };
        loop {
            if cur.count == 0 {
                let node = &self.nodes[cur.item as usize];
                let (mut mask, tn) = node.enter(&slab, tmax);
                if mask != 0 && mask & (mask - 1) == 0 {
                    let i = mask.trailing_zeros() as usize;
                    cur = node.entry(i, tn[i]);
                    continue;
                }
                // Pushed in slot order, then sorted so that the nearest is on top.
                let base = sp;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let e = node.entry(i, tn[i]);
                    // Insertion into the entries pushed from this node, farthest at `base`.
                    let mut j = sp;
                    // SAFETY: stack[base..sp] were written above.
                    while j > base && unsafe { stack[j - 1].assume_init().t } < e.t {
                        stack[j] = stack[j - 1];
                        j -= 1;
                    }
                    stack[j] = MaybeUninit::new(e);
                    sp += 1;
                }
            } else {
                let first = cur.item as usize;
                for (k, prim) in self.prims[first..first + cur.count as usize]
                    .iter()
                    .enumerate()
                {
                    if let Some(t) = prim.shape.intersect(ray, tmax) {
                        tmax = t;
                        best = Some((t, (first + k) as u32));
                    }
                }
            }
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                // SAFETY: every entry below `sp` was written.
                cur = unsafe { stack[sp].assume_init() };
                if cur.t < tmax {
                    break;
                }
            }
        }
    }

    /// [`Accel::occluded`] through the float nodes.
    #[inline]
    pub(super) fn any_hit(
        &self,
        ray: &Ray,
        tmax: f32,
        blocks: &impl Fn(&Primitive) -> bool,
    ) -> bool {
        let slab = Slab::new(ray);
        let mut stack = [MaybeUninit::<u32>::uninit(); STACK];
        let mut sp = 0usize;
        let mut cur = 0u32;
        loop {
            let node = &self.nodes[cur as usize];
            let (mut mask, _) = node.enter(&slab, tmax);
            while mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let count = node.count[i] as usize;
                if count == 0 {
                    stack[sp] = MaybeUninit::new(node.child[i]);
                    sp += 1;
                    continue;
                }
                let first = node.child[i] as usize;
                for prim in &self.prims[first..first + count] {
                    if blocks(prim) && prim.shape.intersect(ray, tmax).is_some() {
                        return true;
                    }
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: every entry below `sp` was written.
            cur = unsafe { stack[sp].assume_init() };
        }
    }
}

impl Accel {
    /// Whether a primitive accepted by `accept` has its box within distance `r` of `p`: the
    /// float nodes walked with a ball in place of a ray.
    pub(super) fn any_box_near(
        &self,
        p: Vec3,
        r: f32,
        accept: &impl Fn(&Primitive) -> bool,
    ) -> bool {
        let r2 = r * r;
        let mut stack = [MaybeUninit::<u32>::uninit(); STACK];
        let mut sp = 0usize;
        let mut cur = 0u32;
        loop {
            let node = &self.nodes[cur as usize];
            for i in 0..8 {
                let mut d2 = 0.0f32;
                for axis in 0..3 {
                    let (lo, hi) = (node.bounds[axis][i], node.bounds[3 + axis][i]);
                    let d = (lo - p[axis]).max(p[axis] - hi).max(0.0);
                    d2 += d * d;
                }
                // An empty slot's box (min +inf, max -inf) is infinitely far.
                if d2 > r2 {
                    continue;
                }
                let count = node.count[i] as usize;
                if count == 0 {
                    stack[sp] = MaybeUninit::new(node.child[i]);
                    sp += 1;
                    continue;
                }
                let first = node.child[i] as usize;
                for prim in &self.prims[first..first + count] {
                    let b = prim.shape.aabb();
                    let d = (Vec3::from(b.min) - p)
                        .max(p - Vec3::from(b.max))
                        .max(Vec3::ZERO);
                    if d.length_squared() <= r2 && accept(prim) {
                        return true;
                    }
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: every entry below `sp` was written.
            cur = unsafe { stack[sp].assume_init() };
        }
    }
}

/// Entries of the traversal stacks: a node's visit pops one entry and pushes at most eight,
/// so a tree of depth d needs at most 7 d + 1. Room for depth 64 (obvhs' own stack holds 32
/// groups); uninitialised, it costs nothing until used.
const STACK: usize = 7 * 64 + 1;

/// A subtree to visit: a node (`count` 0) or a leaf of `count` primitives from `item`, entered
/// at distance `t`.
#[derive(Clone, Copy, Debug)]
struct Entry {
    item: u32,
    count: u32,
    t: f32,
}

/// A ray as the slab test takes it: origin, inverse direction (obvhs' `safe_inverse`: finite,
/// so that a zero distance never makes a NaN), and the rows of each axis' near and far planes
/// (near x, y, z, far x, y, z).
struct Slab {
    origin: [f32; 3],
    inv: [f32; 3],
    rows: [u8; 6],
}

/// [`Slab::rows`] by the ray's octant (bit i: the ray runs towards -axis i, whose near plane
/// is then the max row, 3 + i).
const ROWS: [[u8; 6]; 8] = {
    let mut rows = [[0u8; 6]; 8];
    let mut octant = 0;
    while octant < 8 {
        let mut axis = 0;
        while axis < 3 {
            let negative = (octant >> axis) & 1 == 1;
            rows[octant][axis] = if negative { 3 + axis as u8 } else { axis as u8 };
            rows[octant][3 + axis] = if negative { axis as u8 } else { 3 + axis as u8 };
            axis += 1;
        }
        octant += 1;
    }
    rows
};

impl Slab {
    // Branch-free, in SSE lanes: a scalar branch and division per axis cost 57 instructions
    // a ray, about as much as the node test.
    #[inline(always)]
    fn new(ray: &Ray) -> Slab {
        let d = Vec3A::from(ray.dir + Vec3::ZERO);
        // safe_inverse: 1 / x, or sign(x) / EPSILON where |x| <= EPSILON, which is
        // 1 / copysign(EPSILON, x) exactly (EPSILON is a power of two).
        let inv = Vec3A::ONE / d.abs().max(Vec3A::splat(f32::EPSILON)).copysign(d);
        Slab {
            origin: ray.origin.to_array(),
            inv: inv.to_array(),
            rows: ROWS[d.is_negative_bitmask() as usize],
        }
    }
}

/// An eight-wide node whose children's boxes are floats: the exact union of the primitive
/// boxes below each child (tighter than obvhs' quantised ones, which are rounded outwards to
/// 8 bits), in rows of eight for one slab test of all children.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct Node {
    /// Min x, y, z, then max x, y, z; an empty slot is the empty box (min +inf, max -inf):
    /// its near plane is at +inf and its far one at -inf whichever way a ray runs.
    bounds: [[f32; 8]; 6],
    /// A node's index, or a leaf's first primitive.
    child: [u32; 8],
    /// A leaf's primitives; 0 for a node.
    count: [u8; 8],
}

impl Node {
    /// obvhs' nodes with their children's boxes computed from `prims` (in leaf order); the
    /// same indices.
    pub(super) fn decode(bvh: &CwBvh, prims: &[Primitive]) -> Vec<Node> {
        let empty = Node {
            bounds: [
                [f32::INFINITY; 8],
                [f32::INFINITY; 8],
                [f32::INFINITY; 8],
                [f32::NEG_INFINITY; 8],
                [f32::NEG_INFINITY; 8],
                [f32::NEG_INFINITY; 8],
            ],
            child: [0; 8],
            count: [0; 8],
        };
        let mut nodes = vec![empty; bvh.nodes.len()];
        fn fill(i: usize, bvh: &CwBvh, prims: &[Primitive], nodes: &mut [Node]) -> Aabb {
            let node = &bvh.nodes[i];
            let mut all = Aabb::empty();
            for ch in 0..8 {
                if node.is_child_empty(ch) {
                    continue;
                }
                let b = if node.is_leaf(ch) {
                    let (first, count) = node.child_primitives(ch);
                    nodes[i].child[ch] = first;
                    nodes[i].count[ch] = count as u8;
                    prims[first as usize..(first + count) as usize]
                        .iter()
                        .fold(Aabb::empty(), |b, p| b.union(&p.shape.aabb()))
                } else {
                    let j = node.child_node_index(ch);
                    nodes[i].child[ch] = j;
                    fill(j as usize, bvh, prims, nodes)
                };
                for axis in 0..3 {
                    nodes[i].bounds[axis][ch] = b.min[axis];
                    nodes[i].bounds[3 + axis][ch] = b.max[axis];
                }
                all = all.union(&b);
            }
            all
        }
        if !nodes.is_empty() {
            fill(0, bvh, prims, &mut nodes);
        }
        nodes
    }

    /// The children the ray enters within [0, tmax], as a bit mask, and their entry
    /// distances: the slab test of all eight at once. Written out in AVX2 where the code is
    /// compiled for it (the x86-64-v3 build of the path plugin), where LLVM vectorised the
    /// loop below only in part; elsewhere that loop (two SSE passes). Both compute the same
    /// values: maxps and minps are the `if` below.
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    #[inline(always)]
    fn enter(&self, r: &Slab, tmax: f32) -> (u32, [f32; 8]) {
        use std::arch::x86_64::*;
        // SAFETY: the build has AVX2 (the cfg above); the rows are 32-byte aligned
        // (`repr(align(32))`, rows of 32 bytes).
        unsafe {
            // SAFETY (the index): a slab's rows are below 6.
            let row = |i: u8| _mm256_load_ps(self.bounds.get_unchecked(i as usize).as_ptr());
            let mut tn = _mm256_setzero_ps();
            let mut tf = _mm256_set1_ps(tmax);
            for axis in 0..3 {
                let (o, inv) = (_mm256_set1_ps(r.origin[axis]), _mm256_set1_ps(r.inv[axis]));
                let a = _mm256_mul_ps(_mm256_sub_ps(row(r.rows[axis]), o), inv);
                let b = _mm256_mul_ps(_mm256_sub_ps(row(r.rows[3 + axis]), o), inv);
                tn = _mm256_max_ps(a, tn);
                tf = _mm256_min_ps(b, tf);
            }
            let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tn, tf)) as u32;
            let mut t = [0.0f32; 8];
            _mm256_storeu_ps(t.as_mut_ptr(), tn);
            (mask, t)
        }
    }

    /// See the AVX2 version above.
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    #[inline(always)]
    fn enter(&self, r: &Slab, tmax: f32) -> (u32, [f32; 8]) {
        let mut tn = [0.0f32; 8];
        let mut tf = [tmax; 8];
        for axis in 0..3 {
            // SAFETY: a slab's rows are below 6.
            let (near, far) = unsafe {
                (
                    self.bounds.get_unchecked(r.rows[axis] as usize),
                    self.bounds.get_unchecked(r.rows[3 + axis] as usize),
                )
            };
            let (o, inv) = (r.origin[axis], r.inv[axis]);
            for i in 0..8 {
                let a = (near[i] - o) * inv;
                let b = (far[i] - o) * inv;
                tn[i] = if a > tn[i] { a } else { tn[i] };
                tf[i] = if b < tf[i] { b } else { tf[i] };
            }
        }
        let mut mask = 0;
        for i in 0..8 {
            mask |= ((tn[i] <= tf[i]) as u32) << i;
        }
        (mask, tn)
    }

    #[inline(always)]
    fn entry(&self, i: usize, t: f32) -> Entry {
        Entry {
            item: self.child[i],
            count: self.count[i] as u32,
            t,
        }
    }
}
