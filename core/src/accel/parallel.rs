//! The scene's BVH built on every thread, the same tree for any number of them.
//!
//! obvhs builds a BVH on one thread (its `parallel` feature builds trees that depend on the
//! threads' timing, so images would too): a million triangles took 0.9 s, most of a large
//! mesh's load. Here the primitives are split at the median of their boxes' centres along the
//! widest axis, three times (a function of the boxes alone, ties broken by index; large boxes
//! apart, see [`build`]), obvhs builds the parts' BVHs at once, and one root node whose
//! children are the parts' roots joins them into one compressed BVH8. Everything after (the float nodes, every traversal) is
//! as for a BVH built in one piece.

use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::node::CwBvhNode;
use rayon::prelude::*;

/// Primitives from which the BVH is built in eight parts.
pub(super) const PARALLEL: usize = 65_536;

/// Splits `items` (a box's centre and its index) at the median along the widest axis of their
/// centres, `levels` times: 2^levels parts of equal size (to one), each part's items
/// contiguous, left to right. The same split for any number of threads.
pub fn median_split(items: &mut [([f32; 3], u32)], levels: u32) {
    if levels == 0 || items.len() < 2 {
        return;
    }
    let (lo, hi) = items.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(lo, hi), (c, _)| {
            (
                std::array::from_fn(|i| lo[i].min(c[i])),
                std::array::from_fn(|i| hi[i].max(c[i])),
            )
        },
    );
    let e = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let a = if e[0] >= e[1] && e[0] >= e[2] {
        0
    } else if e[1] >= e[2] {
        1
    } else {
        2
    };
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |p, q| p.0[a].total_cmp(&q.0[a]).then(p.1.cmp(&q.1)));
    let (left, right) = items.split_at_mut(mid);
    if left.len() > 8192 {
        rayon::join(
            || median_split(left, levels - 1),
            || median_split(right, levels - 1),
        );
    } else {
        median_split(left, levels - 1);
        median_split(right, levels - 1);
    }
}

/// The index ranges of the 2^levels parts [`median_split`] leaves in `n` items.
pub fn median_parts(n: usize, levels: u32) -> Vec<(usize, usize)> {
    fn go(lo: usize, hi: usize, levels: u32, out: &mut Vec<(usize, usize)>) {
        if levels == 0 {
            out.push((lo, hi));
            return;
        }
        let mid = lo + (hi - lo) / 2;
        go(lo, mid, levels - 1, out);
        go(mid, hi, levels - 1, out);
    }
    let mut out = Vec::with_capacity(1 << levels);
    go(0, n, levels, &mut out);
    out
}

/// The BVH over `aabbs` built in parts at once (module comment); `build` builds one part's BVH
/// over the boxes it is given. Boxes larger than a quarter of the scene's box on some axis (a
/// floor under a detailed mesh) are kept apart: in a median part its box would cover the
/// others', and every ray would enter it. Up to three are a leaf of the root, more a part of
/// their own. The rest is split into eight parts, or four beside the large boxes (a root
/// holds eight children).
pub(super) fn build(aabbs: &[Aabb], build: impl Fn(&[Aabb]) -> CwBvh + Sync) -> CwBvh {
    let scene = aabbs.iter().fold(Aabb::empty(), |b, a| b.union(a));
    let quarter = (scene.max - scene.min) * 0.25;
    let large = |b: &Aabb| (b.max - b.min).cmpgt(quarter).any();
    let (mut items, big): (Vec<([f32; 3], u32)>, Vec<u32>) = {
        let mut items = Vec::with_capacity(aabbs.len());
        let mut big = Vec::new();
        for (i, b) in aabbs.iter().enumerate() {
            if large(b) {
                big.push(i as u32);
            } else {
                items.push((((b.min + b.max) * 0.5).to_array(), i as u32));
            }
        }
        (items, big)
    };
    let levels = if big.is_empty() { 3 } else { 2 };
    median_split(&mut items, levels);
    let mut members: Vec<Vec<u32>> = median_parts(items.len(), levels)
        .into_iter()
        .map(|(lo, hi)| items[lo..hi].iter().map(|&(_, i)| i).collect())
        .collect();
    // Up to three large boxes are a leaf of the root itself (a ray that meets them goes down no
    // part's tree); more, a part of their own.
    let leaf = if big.len() <= 3 {
        big
    } else {
        members.push(big);
        Vec::new()
    };
    let parts: Vec<(CwBvh, Vec<u32>)> = members
        .into_par_iter()
        .filter(|m| !m.is_empty())
        .map(|m| {
            let boxes: Vec<Aabb> = m.iter().map(|&i| aabbs[i as usize]).collect();
            (build(&boxes), m)
        })
        .collect();
    let leaf: Vec<(u32, Aabb)> = leaf.into_iter().map(|i| (i, aabbs[i as usize])).collect();
    join(parts, &leaf)
}

/// One BVH of the parts' BVHs (each with the input indices of its boxes) and of up to three
/// boxes `leaf` (input index, box): a root whose children are copies of the parts' roots and
/// one leaf of those boxes, then each part's nodes, moved.
fn join(parts: Vec<(CwBvh, Vec<u32>)>, leaf: &[(u32, Aabb)]) -> CwBvh {
    let k = parts.len();
    assert!(leaf.len() <= 3, "a leaf holds up to three boxes");
    assert!(
        (1..=8).contains(&(k + !leaf.is_empty() as usize)),
        "a root holds up to eight children"
    );
    let leaf_box = leaf.iter().fold(Aabb::empty(), |b, (_, a)| b.union(a));
    let total = parts
        .iter()
        .fold(leaf_box, |b, (p, _)| b.union(&p.total_aabb));
    let mut nodes = vec![CwBvhNode::default(); 1 + k];
    // The root's leaf first: its boxes at primitive 0.
    let mut primitive_indices: Vec<u32> = leaf.iter().map(|&(i, _)| i).collect();
    for (g, (part, members)) in parts.iter().enumerate() {
        let (node_base, prim_base) = (nodes.len() as u32, primitive_indices.len() as u32);
        for node in &part.nodes {
            let mut node = *node;
            node.child_base_idx += node_base;
            node.primitive_base_idx += prim_base;
            nodes.push(node);
        }
        nodes[1 + g] = nodes[node_base as usize];
        primitive_indices.extend(part.primitive_indices.iter().map(|&i| members[i as usize]));
    }
    // The root, encoded as obvhs encodes a node: its box's corner, a power-of-two scale per
    // axis, each child's box quantised outwards to bytes.
    let p = total.min;
    let scale = ((total.max - total.min).max(Vec3A::splat(1e-20)) * (1.0 / 255.0))
        .log2()
        .ceil()
        .exp2();
    let rcp = 1.0 / scale;
    let mut root = CwBvhNode {
        p: Vec3::from(p),
        e: scale.to_array().map(|c| (c.to_bits() >> 23) as u8),
        imask: 0,
        child_base_idx: 1,
        primitive_base_idx: 0,
        ..CwBvhNode::default()
    };
    let mut child = |i: usize, b: &Aabb| {
        let lo = ((b.min - p) * rcp)
            .floor()
            .clamp(Vec3A::ZERO, Vec3A::splat(255.0));
        let hi = ((b.max - p) * rcp)
            .ceil()
            .clamp(Vec3A::ZERO, Vec3A::splat(255.0));
        root.child_min_x[i] = lo.x as u8;
        root.child_min_y[i] = lo.y as u8;
        root.child_min_z[i] = lo.z as u8;
        root.child_max_x[i] = hi.x as u8;
        root.child_max_y[i] = hi.y as u8;
        root.child_max_z[i] = hi.z as u8;
    };
    for (i, (part, _)) in parts.iter().enumerate() {
        child(i, &part.total_aabb);
    }
    if !leaf.is_empty() {
        child(k, &leaf_box);
    }
    for i in 0..k {
        root.imask |= 1 << i;
        root.child_meta[i] = (24 + i as u8) | 0b0010_0000;
    }
    if !leaf.is_empty() {
        // Primitives 0.. of the root's: the count in unary in the high three bits.
        root.child_meta[k] = [0, 0b0010_0000, 0b0110_0000, 0b1110_0000][leaf.len()];
    }
    nodes[0] = root;
    CwBvh {
        nodes,
        primitive_indices,
        total_aabb: total,
        exact_node_aabbs: None,
        uses_spatial_splits: false,
    }
}
