//! One BVH over every primitive in the scene: obvhs builds it (a compressed wide BVH8), foton
//! traverses it.
//!
//! **Float nodes.** obvhs stores each node's eight child boxes quantised to bytes and, in its
//! traversal (`traverse!`, made for GPUs), converts them back to floats, keeps its state in
//! bit-packed groups and zeroes a 32-entry stack for every ray: for the few nodes a ray of a
//! small scene visits, that machinery was most of the traversal's cost. The scene's BVH
//! ([`Accel::build`]) is therefore decoded once into [`Node`]s of the same tree with each
//! child's box in floats (the exact union of the primitive boxes below it, tighter than the
//! quantised one), and closest-hit and shadow rays walk them with a plain stack: one slab test
//! of all eight children (AVX2 in the x86-64-v3 build, two SSE passes in the baseline's),
//! children visited nearest entry first, subtrees past the closest hit skipped. Entry
//! distances start at 0, where obvhs' start at 1e-4: a ray spawned within 1e-4 of another
//! surface (the crease of two walls, a sphere resting on the floor) now hits it instead of
//! passing through.
//!
//! **A BVH of boxes** ([`Accel::build_boxes`], photon beams' pieces) keeps obvhs' traversal
//! and its culling. Where the processor has AVX2 (checked once, at run time: the program still
//! runs on any x86-64), its node test converts and tests all eight children at once
//! ([`simd`]), with obvhs' own arithmetic (the same products and sums, no fused multiply-add),
//! so it culls exactly the same children as obvhs' SSE2 test, four at a time.
//!
//! Files: this one holds [`Accel`], its build and its queries; `float_nodes.rs` the float nodes
//! and their traversals; `simd.rs` the eight-wide node test of a BVH of boxes; `boxes.rs`
//! [`BoxBvh`], the same BVH of boxes holding only each box's number.

mod boxes;
mod float_nodes;
mod parallel;
mod simd;

pub use boxes::BoxBvh;
pub use parallel::{median_parts, median_split};

use crate::geometry::{Hit, Primitive, Ray};
use float_nodes::Node;
use glam::Vec3;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::{Ray as BvhRay, RayHit};

pub struct Accel {
    /// obvhs' compressed BVH8: traversed as it is by a BVH of boxes, by the narrow traversal
    /// and by [`Accel::for_each_hit`] and [`Accel::visit`].
    bvh: Option<CwBvh>,
    /// The same tree with its child boxes in floats (module comment); empty for a BVH of
    /// boxes ([`Accel::build_boxes`]).
    nodes: Vec<Node>,
    /// Primitives in BVH leaf order, so a traversal id indexes them directly.
    prims: Vec<Primitive>,
    /// Traverse closest-hit and shadow rays with the float nodes (or, for a BVH of boxes,
    /// with the eight-wide node test where the processor has AVX2), not obvhs' own traversal.
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

/// obvhs' BVH over `aabbs`, built on one thread.
fn cwbvh_serial(aabbs: &[Aabb]) -> CwBvh {
    let mut bvh = build_cwbvh(
        aabbs,
        BvhBuildParams::medium_build(),
        &mut std::time::Duration::default(),
    );
    // obvhs reserves a node a primitive (80 bytes each); about a tenth of that is used.
    bvh.nodes.shrink_to_fit();
    bvh
}

/// The BVH over `prims` (in eight parts built at once from [`parallel::PARALLEL`]
/// primitives) and the primitives in its leaf order.
fn cwbvh(prims: &[Primitive]) -> (CwBvh, Vec<Primitive>) {
    let aabbs: Vec<Aabb> = prims.iter().map(|p| p.shape.aabb()).collect();
    let bvh = if prims.len() >= parallel::PARALLEL {
        parallel::build(&aabbs, cwbvh_serial)
    } else {
        cwbvh_serial(&aabbs)
    };
    let ordered = bvh
        .primitive_indices
        .iter()
        .map(|&i| prims[i as usize])
        .collect();
    (bvh, ordered)
}

impl Accel {
    /// The scene's BVH: obvhs' tree, traversed through its float nodes.
    pub fn build(prims: Vec<Primitive>) -> Accel {
        let mut accel = Accel::build_boxes(prims);
        if let Some(bvh) = &accel.bvh {
            accel.nodes = Node::decode(bvh, &accel.prims);
        }
        accel.wide = true;
        accel
    }

    /// A BVH for primitives that stand for boxes, traversed through obvhs' compressed nodes
    /// (photon beams' pieces: their callbacks rely on obvhs' culling, whose entry distance
    /// starts at 1e-4).
    pub fn build_boxes(prims: Vec<Primitive>) -> Accel {
        let wide = simd::available();
        if prims.is_empty() {
            return Accel {
                bvh: None,
                nodes: Vec::new(),
                prims,
                wide,
            };
        }
        let (bvh, prims) = cwbvh(&prims);
        Accel {
            bvh: Some(bvh),
            nodes: Vec::new(),
            prims,
            wide,
        }
    }

    /// The same BVH traversed with obvhs' own traversal (`wide` false), or with the faster
    /// one (true, where there is one): for tests and benchmarks.
    pub fn set_wide(&mut self, wide: bool) {
        self.wide = wide && (!self.nodes.is_empty() || simd::available());
    }

    /// Whether traversals use the float nodes or the eight-wide node test.
    pub fn wide(&self) -> bool {
        self.wide
    }

    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// The bytes the BVH holds on the heap: its nodes (both forms) and its primitives.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        let bvh = self.bvh.as_ref().map_or(0, |b| {
            b.nodes.capacity() * size_of::<obvhs::cwbvh::node::CwBvhNode>()
                + b.primitive_indices.capacity() * size_of::<u32>()
        });
        bvh + self.nodes.capacity() * size_of::<Node>()
            + self.prims.capacity() * size_of::<Primitive>()
    }

    /// Closest intersection with t in (0, tmax).
    #[inline]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<Hit> {
        let (t, prim) = if self.wide && !self.nodes.is_empty() {
            self.closest(ray, tmax)?
        } else {
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
            (hit.t, hit.primitive_id)
        };
        let p = ray.at(t);
        Some(Hit {
            t,
            p,
            ng: self.prims[prim as usize].shape.normal(p),
            prim,
        })
    }

    /// Whether any primitive accepted by `blocks` lies on the ray within (0, tmax). Stops at the
    /// first such hit (shadow rays need no closest hit). `blocks` is asked about every
    /// primitive of each leaf whose box the ray enters, before the primitive is tested.
    #[inline]
    pub fn occluded(&self, ray: &Ray, tmax: f32, blocks: impl Fn(&Primitive) -> bool) -> bool {
        if self.wide && !self.nodes.is_empty() {
            return self.any_hit(ray, tmax, &blocks);
        }
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

    /// Whether any primitive accepted by `accept` may lie within distance `r` of `p`: its
    /// box does (false only when none can; a BVH of boxes answers true). A cheap test before
    /// rays that look for surfaces near a point.
    pub fn any_near(&self, p: Vec3, r: f32, accept: impl Fn(&Primitive) -> bool) -> bool {
        if self.nodes.is_empty() {
            return !self.prims.is_empty();
        }
        self.any_box_near(p, r, &accept)
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

    /// The wide node test of a BVH of boxes culls exactly what obvhs' own does (every node,
    /// random rays, random tmax), and the traversals built on it find the same closest hits
    /// and the same blocked shadow rays.
    #[test]
    fn wide_traversal_matches_obvhs() {
        if !simd::available() {
            eprintln!("no AVX2 here: the wide traversal is not used, nothing to compare");
            return;
        }
        let mut rng = Rng::new(&[3]);
        let prims = scene(&mut rng, 300);
        let mut accel = Accel::build_boxes(prims);
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

    /// The nearest hit of `ray` among all of `prims`, by testing every one.
    fn brute_force(prims: &[Primitive], ray: &Ray, tmax: f32) -> Option<f32> {
        prims
            .iter()
            .filter_map(|p| p.shape.intersect(ray, tmax))
            .min_by(|a, b| a.total_cmp(b))
    }

    /// Random rays, half of them starting just off a random primitive's surface (what
    /// bounces and shadow rays do), a tenth of them along an axis.
    fn rays_through(rng: &mut Rng, prims: &[Primitive], n: usize) -> Vec<(Ray, f32)> {
        (0..n)
            .map(|k| {
                let mut d = uniform_sphere(rng.next_2d());
                if k % 10 == 0 {
                    d = [Vec3::X, -Vec3::Y, Vec3::Z][k % 3];
                }
                let o = if k % 2 == 0 {
                    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0
                } else {
                    let prim = &prims[(rng.next_f32() * prims.len() as f32) as usize % prims.len()];
                    let (p, n) = prim.shape.sample_area(rng.next_2d());
                    p + n * if rng.next_f32() < 0.5 { 2e-5 } else { -2e-5 }
                };
                let tmax = if rng.next_f32() < 0.5 {
                    f32::INFINITY
                } else {
                    rng.next_f32() * 8.0
                };
                (Ray::new(o, d), tmax)
            })
            .collect()
    }

    /// The float nodes' traversals find what testing every primitive finds: the same
    /// nearest distance, bit for bit, and the same blocked shadow rays, on trees of one node
    /// and of several levels.
    #[test]
    fn float_traversal_matches_testing_every_primitive() {
        let mut rng = Rng::new(&[5]);
        for n in [1, 7, 40, 3000] {
            let prims = scene(&mut rng, n);
            let accel = Accel::build(prims.clone());
            assert!(accel.wide() && !accel.nodes.is_empty());
            let (mut hits, mut blocked) = (0, 0);
            for (ray, tmax) in rays_through(&mut rng, &prims, 4000) {
                let want = brute_force(&prims, &ray, tmax);
                let got = accel.intersect(&ray, tmax);
                assert_eq!(
                    got.map(|h| h.t.to_bits()),
                    want.map(f32::to_bits),
                    "{n} primitives, {ray:?} up to {tmax}"
                );
                if let Some(h) = got {
                    let shape = &accel.primitives()[h.prim as usize].shape;
                    assert_eq!(
                        shape.intersect(&ray, tmax),
                        Some(h.t),
                        "the hit's primitive"
                    );
                    hits += 1;
                }
                let occluded = accel.occluded(&ray, tmax, |_| true);
                assert_eq!(
                    occluded,
                    want.is_some(),
                    "{n} primitives, shadow ray {ray:?}"
                );
                blocked += occluded as u32;
                // A shadow ray that only the even primitives block.
                let even = |p: &Primitive| p.object.is_multiple_of(2);
                let want_even = prims
                    .iter()
                    .any(|p| even(p) && p.shape.intersect(&ray, tmax).is_some());
                assert_eq!(accel.occluded(&ray, tmax, even), want_even);
            }
            assert!(
                hits > 100 && blocked > 100,
                "{n}: {hits} hits, {blocked} blocked"
            );
        }
    }

    /// A BVH built in parts ([`parallel`]: eight median parts; with quads as large as the
    /// scene, four and those apart) answers every query as testing every primitive does (closest hits bit for bit, shadow
    /// rays, every crossing, what `visit` is offered), and is the same tree on one thread and
    /// on three.
    #[test]
    fn a_bvh_built_in_parts_answers_as_every_primitive_does() {
        // Quads as large as the scene (a floor and walls): none (eight median parts), three
        // (four parts and a leaf of the root), five (four parts and a part of theirs).
        for (large, imask) in [(0, 0xff), (3, 0b1111), (5, 0b1_1111)] {
            let mut rng = Rng::new(&[8, large]);
            let mut prims = scene(&mut rng, parallel::PARALLEL + 4321);
            for k in 0..large {
                let o = Vec3::splat(k as f32 * 0.1);
                prims.push(Primitive {
                    shape: Shape::quad(o, Vec3::X * 10.0, Vec3::Y * 10.0 + Vec3::Z * k as f32),
                    object: 0,
                    attrs: crate::geometry::NO_ATTRS,
                });
            }
            for (i, p) in prims.iter_mut().enumerate() {
                p.object = i as u32;
            }
            built_in_parts_answers_as_every_primitive_does(&mut rng, &prims, imask);
        }
    }

    fn built_in_parts_answers_as_every_primitive_does(
        rng: &mut Rng,
        prims: &[Primitive],
        parts: u8,
    ) {
        let build = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Accel::build(prims.to_vec()))
        };
        let (accel, other) = (build(1), build(3));
        let bvh = accel.bvh.as_ref().unwrap();
        assert_eq!(bvh.nodes, other.bvh.as_ref().unwrap().nodes);
        let objects = |a: &Accel| a.prims.iter().map(|p| p.object).collect::<Vec<_>>();
        assert_eq!(objects(&accel), objects(&other));
        assert_eq!(bvh.nodes[0].imask, parts, "the root's children: one a part");
        let (mut hits, mut crossings) = (0, 0);
        for (ray, tmax) in rays_through(rng, prims, 400) {
            let want = brute_force(prims, &ray, tmax);
            let got = accel.intersect(&ray, tmax);
            assert_eq!(got.map(|h| h.t.to_bits()), want.map(f32::to_bits));
            hits += got.is_some() as u32;
            assert_eq!(accel.occluded(&ray, tmax, |_| true), want.is_some());
            let mut every: Vec<(u32, u32)> = prims
                .iter()
                .filter_map(|p| Some((p.object, p.shape.intersect(&ray, tmax)?.to_bits())))
                .collect();
            every.sort();
            let mut found = Vec::new();
            accel.for_each_hit(&ray, tmax, |i, t| {
                found.push((accel.prims[i as usize].object, t.to_bits()))
            });
            found.sort();
            assert_eq!(found, every, "for_each_hit");
            let mut offered = Vec::new();
            accel.visit(&ray, tmax, |_, p| {
                if let Some(t) = p.shape.intersect(&ray, tmax) {
                    offered.push((p.object, t.to_bits()));
                }
                false
            });
            offered.sort();
            assert_eq!(offered, every, "visit");
            crossings += every.len();
        }
        assert!(
            hits > 50 && crossings > 100,
            "{hits} hits, {crossings} crossings"
        );
    }

    /// The ball query finds what testing every primitive's box finds: some accepted box
    /// within r of the point, or none, for points near and far from the primitives.
    #[test]
    fn any_near_matches_testing_every_box() {
        let mut rng = Rng::new(&[6]);
        for n in [1, 7, 40, 3000] {
            let mut prims = scene(&mut rng, n);
            for (i, p) in prims.iter_mut().enumerate() {
                p.object = i as u32;
            }
            let accel = Accel::build(prims.clone());
            let (mut near, mut far) = (0, 0);
            for _ in 0..4000 {
                let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0;
                let r = 1.5 * rng.next_f32() * rng.next_f32();
                let odd = |q: &Primitive| q.object % 2 == 1;
                for accept in [&(|_: &Primitive| true) as &dyn Fn(&Primitive) -> bool, &odd] {
                    let want = prims.iter().any(|q| {
                        let b = q.shape.aabb();
                        let d = (Vec3::from(b.min) - p)
                            .max(p - Vec3::from(b.max))
                            .max(Vec3::ZERO);
                        d.length_squared() <= r * r && accept(q)
                    });
                    assert_eq!(accel.any_near(p, r, accept), want, "{n}: {p} within {r}");
                    if want { near += 1 } else { far += 1 }
                }
            }
            assert!(
                n < 40 || (near > 100 && far > 100),
                "{n}: {near} near, {far} far"
            );
        }
    }

    /// A ray leaving a surface 2e-5 from another one (the crease of a floor and a wall, a
    /// sphere resting on the floor) hits it: obvhs' traversal starts its entry distances at
    /// 1e-4 and let such rays through, light leaking along every crease.
    #[test]
    fn rays_spawned_beside_a_surface_hit_it() {
        let floor = Shape::quad(Vec3::new(-1.0, 0.0, 1.0), Vec3::X * 2.0, -Vec3::Z * 2.0);
        let wall = Shape::quad(Vec3::new(-1.0, 0.0, -1.0), Vec3::Y * 2.0, Vec3::Z * 2.0);
        let ball = Shape::sphere(Vec3::new(0.3, 0.3, 0.0), 0.3);
        let prims: Vec<Primitive> = [floor, wall, ball]
            .into_iter()
            .enumerate()
            .map(|(i, shape)| Primitive {
                shape,
                object: i as u32,
                attrs: crate::geometry::NO_ATTRS,
            })
            .collect();
        let accel = Accel::build(prims);
        for (o, d) in [
            (Vec3::new(-0.9998, 2e-5, 0.1), Vec3::new(0.4, -0.9, -0.1)),
            (Vec3::new(0.3, 2e-5, 0.01), Vec3::new(-0.3, -0.9, 0.2)),
            (Vec3::new(-1.0 + 2e-5, 0.5, 0.2), Vec3::new(-0.8, 0.5, 0.3)),
        ] {
            let ray = Ray::new(o, d.normalize());
            let hit = accel.intersect(&ray, f32::INFINITY);
            assert!(
                hit.is_some_and(|h| h.t < 1e-4),
                "{ray:?} passes through the surface beside it: {hit:?}"
            );
            assert!(accel.occluded(&ray, 1.0, |_| true));
        }
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
