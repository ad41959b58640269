//! Photons and the photon map: a balanced kd-tree over compact photons with k-nearest and
//! fixed-radius queries (Jensen, "Realistic Image Synthesis Using Photon Mapping", ch. 6).
//!
//! The tree is implicit and bucketed: photons are reordered so that each range [lo, hi) is
//! split at its median index mid = (lo + hi) / 2 into [lo, mid) and [mid, hi) along the axis
//! of largest extent; the node stores that axis and the median's coordinate at index mid
//! (unique per node). Ranges of at most `LEAF` photons are buckets, searched linearly over a
//! separate position array. Queries track the squared distance from the query to each cell
//! incrementally (Arya and Mount), which prunes more than the distance to the last plane.
//! Built in parallel with rayon; the result does not depend on the number of threads.

use foton_core::api::{
    Bsdf, Lobe, NormalizedKernel, Phase, Primitive, Ray, Rgb, Scene, offset_origin,
};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::cmp::Ordering;
use std::mem::MaybeUninit;

/// A photon: 32 bytes. The incoming direction is octahedron-encoded in 2 x 16 bits; the
/// surface normal, only ever compared against a threshold, in 3 x 8 bits (cheap to decode in
/// the estimate's inner loop); the number of scattering events of its path in one byte.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Photon {
    pub position: Vec3,
    /// Flux carried (W).
    pub power: [f32; 3],
    /// Direction the photon came from (unit, pointing away from the surface).
    wi: [u16; 2],
    /// Surface normal on the side the photon arrived at, times 127 (zero for volume photons).
    normal: [i8; 3],
    /// Scattering events of the photon's path, this one included (saturates at 255).
    depth: u8,
}

fn oct_encode(v: Vec3) -> [u16; 2] {
    let l1 = v.x.abs() + v.y.abs() + v.z.abs();
    let (mut x, mut y) = (v.x / l1, v.y / l1);
    if v.z < 0.0 {
        let (ox, oy) = (x, y);
        x = (1.0 - oy.abs()) * ox.signum();
        y = (1.0 - ox.abs()) * oy.signum();
    }
    let q = |c: f32| ((c.clamp(-1.0, 1.0) * 0.5 + 0.5) * 65535.0).round() as u16;
    [q(x), q(y)]
}

fn oct_decode(e: [u16; 2]) -> Vec3 {
    let x = e[0] as f32 / 65535.0 * 2.0 - 1.0;
    let y = e[1] as f32 / 65535.0 * 2.0 - 1.0;
    let z = 1.0 - x.abs() - y.abs();
    let t = (-z).max(0.0);
    let x = x + if x >= 0.0 { -t } else { t };
    let y = y + if y >= 0.0 { -t } else { t };
    Vec3::new(x, y, z).normalize()
}

impl Photon {
    pub fn new(position: Vec3, power: Rgb, wi: Vec3, normal: Vec3) -> Photon {
        Photon {
            position,
            power: power.to_array(),
            wi: oct_encode(wi),
            normal: {
                let q = |c: f32| (c.clamp(-1.0, 1.0) * 127.0).round() as i8;
                [q(normal.x), q(normal.y), q(normal.z)]
            },
            depth: 0,
        }
    }

    /// The photon with the number of scattering events of its path (this one included).
    pub fn with_depth(mut self, depth: u32) -> Photon {
        self.depth = depth.min(255) as u8;
        self
    }

    /// Scattering events of the photon's path, the one where it is stored included. An
    /// estimate for a camera path that already has `a` events takes only photons with depth
    /// <= max_depth - a, so that no light path is longer than `max_depth`, as in the path
    /// tracer.
    #[inline]
    pub fn depth(&self) -> u32 {
        self.depth as u32
    }

    #[inline]
    pub fn power(&self) -> Rgb {
        Rgb::from_array(self.power)
    }
    /// The direction the photon came from, pointing away from where it was stored.
    #[inline]
    pub fn wi(&self) -> Vec3 {
        oct_decode(self.wi)
    }
    /// The stored surface normal, on the side the photon arrived at (unit length to within
    /// 1%).
    #[inline]
    pub fn normal(&self) -> Vec3 {
        Vec3::new(
            self.normal[0] as f32,
            self.normal[1] as f32,
            self.normal[2] as f32,
        ) * (1.0 / 127.0)
    }
}

const LEAF: usize = 8;

/// Photons farther from a surface estimate's tangent plane than this fraction of its radius
/// are not counted: the estimate gathers from a disc, not a ball, so that photons on a
/// parallel surface within reach (the top of a low box beside the floor, a step, a rug) do not
/// leak into it. A quarter keeps curved surfaces whole: a sphere of radius R bends away from
/// its tangent plane by about r^2 / 2R at distance r, under r / 4 while R >= 2r.
pub const DISC_THICKNESS: f32 = 0.25;

/// Rays a [`DiscClip`] casts in the tangent plane to find the walls around a point.
pub const CLIP_PROBES: usize = 8;

/// Directions over which a [`DiscClip`] integrates the disc's covered part.
const CLIP_ANGLES: usize = 64;

/// Where the surface stops around a point: the walls that a surface estimate's disc reaches
/// across (a concave crease: the floor's disc beside a wall reaches behind it, where no floor
/// photon can land), as lines of the tangent plane. A k-nearest estimate divides the photons
/// it finds by the disc's area; beside a wall they cover only part of it, and the estimate
/// darkens a band as wide as its radius along every crease, up to a factor 2 on the crease
/// and 4 in a corner (Jensen's book, the "edge" problem; Hey and Purgathofer 2002 correct it
/// by the area the photons cover). Photons cannot tell a wall from a dark area with k = 8;
/// the geometry can: `CLIP_PROBES` rays from the point in its tangent plane find the walls
/// within reach, each probe hit gives its wall's plane, and that plane meets the tangent
/// plane in a line. The estimate then keeps only photons on the point's side of every line
/// and divides by the kernel's mass over the disc on that side ([`DiscClip::coverage`]):
/// the photons of a region divided by the region's measure, unbiased for a uniform density
/// whatever the region. A crease whose line stays between the probes (all eight miss it)
/// cuts off under 1.3 % of the disc. Walls are taken as planes beyond where the probe hit
/// them (a wall narrower than the disc, its end within the radius, is rare).
#[derive(Clone, Copy, Debug, Default)]
pub struct DiscClip {
    /// Lines g . x = s of the tangent plane (frame `frame`, origin the point): unit g, s > 0;
    /// the surface is on the side g . x < s.
    lines: [(Vec2, f32); CLIP_PROBES],
    count: usize,
    /// The tangent frame (u, v) of the probes.
    frame: (Vec3, Vec3),
    p: Vec3,
}

/// Where a surface estimate gathers: the disc around `p` in the tangent plane of `n` (the
/// normal on the side looked at), from photons of at most `max_depth` scattering events,
/// clipped at the walls of `clip`.
#[derive(Clone, Copy, Debug)]
pub struct Disc<'a> {
    pub p: Vec3,
    pub n: Vec3,
    pub max_depth: u32,
    pub clip: &'a DiscClip,
}

impl Disc<'static> {
    /// A whole disc (no wall clips it).
    pub fn new(p: Vec3, n: Vec3, max_depth: u32) -> Disc<'static> {
        Disc {
            p,
            n,
            max_depth,
            clip: &DiscClip::NONE,
        }
    }
}

impl<'a> Disc<'a> {
    /// The disc clipped at the walls of `clip`.
    pub fn clipped(self, clip: &'a DiscClip) -> Disc<'a> {
        Disc { clip, ..self }
    }
}

impl DiscClip {
    /// No wall: every disc is whole.
    pub const NONE: DiscClip = DiscClip {
        lines: [(Vec2::ZERO, 0.0); CLIP_PROBES],
        count: 0,
        frame: (Vec3::ZERO, Vec3::ZERO),
        p: Vec3::ZERO,
    };

    /// Probes the tangent plane at p (normal `n`, on the side looked at) up to `reach` (the
    /// largest radius an estimate there may take). A probe hit counts as a wall if its surface
    /// is not a null boundary and turns away from the tangent plane by more than the
    /// estimate's own normal test (normals within about 25 degrees are the same surface, a
    /// gently curved one included).
    pub fn probe(scene: &Scene, p: Vec3, n: Vec3, reach: f32) -> DiscClip {
        let (u, v) = n.any_orthonormal_pair();
        let mut clip = DiscClip {
            frame: (u, v),
            p,
            ..DiscClip::NONE
        };
        let origin = offset_origin(p, n, n);
        // No probe can find a wall where no surface that could be one comes within reach
        // (most points, away from creases): skip the rays. A hit lies in its primitive's
        // box, rounding aside (the margin).
        let margin = 1e-3 * reach + 1e-5 * origin.abs().max_element();
        let wall = |prim: &Primitive| {
            // A plane's normal is the same everywhere on it: the one a probe hit would have.
            let coplanar = prim.shape.is_flat() && prim.shape.normal(Vec3::ZERO).dot(n).abs() > 0.9;
            !coplanar && !scene.material_of(prim).is_null()
        };
        if !scene.accel().any_near(origin, reach + margin, wall) {
            return clip;
        }
        for j in 0..CLIP_PROBES {
            let theta = (j as f32 + 0.5) * std::f32::consts::TAU / CLIP_PROBES as f32;
            let (sin, cos) = theta.sin_cos();
            let Some(hit) = scene.intersect(&Ray::new(origin, u * cos + v * sin), reach) else {
                continue;
            };
            if hit.ng.dot(n).abs() > 0.9 || scene.material(&hit).is_null() {
                continue;
            }
            // The wall's plane ng . (x - hit) = 0 in the tangent plane's coordinates.
            let g = Vec2::new(hit.ng.dot(u), hit.ng.dot(v));
            let len = g.length();
            let (mut g, mut s) = (g / len, hit.ng.dot(hit.p - p) / len);
            if s < 0.0 {
                (g, s) = (-g, -s);
            }
            let seen = clip.lines[..clip.count]
                .iter()
                .any(|&(h, t)| h.dot(g) > 0.999 && (t - s).abs() <= 1e-3 * reach);
            if !seen {
                clip.lines[clip.count] = (g, s);
                clip.count += 1;
            }
        }
        clip
    }

    /// Whether a photon at `x` lies on the point's side of every wall.
    #[inline]
    pub fn keeps(&self, x: Vec3) -> bool {
        if self.count == 0 {
            return true;
        }
        let d = x - self.p;
        let q = Vec2::new(d.dot(self.frame.0), d.dot(self.frame.1));
        self.lines[..self.count].iter().all(|&(g, s)| g.dot(q) < s)
    }

    /// The fraction of the kernel's mass over the disc of radius r that lies on the point's
    /// side of every wall (1 with no wall within r): the integral over directions of the
    /// kernel's mass out to the nearest wall, in `CLIP_ANGLES` directions, with the radial
    /// mass tabulated from the kernel's profile (x^2 for the box).
    pub fn coverage(&self, r: f32, kernel: &NormalizedKernel) -> f32 {
        if self.lines[..self.count].iter().all(|&(_, s)| s >= r) {
            return 1.0;
        }
        // Mass within x r, at x = i / RADIAL, normalised to 1 at x = 1 (midpoint rule).
        const RADIAL: usize = 16;
        let mut mass = [0.0f32; RADIAL + 1];
        for i in 1..=RADIAL {
            let x = (i as f32 - 0.5) / RADIAL as f32;
            mass[i] = mass[i - 1] + kernel.weight_2d(x, 1.0) * x;
        }
        let total = mass[RADIAL];
        let within = |x: f32| {
            let f = x.clamp(0.0, 1.0) * RADIAL as f32;
            let i = (f as usize).min(RADIAL - 1);
            (mass[i] + (mass[i + 1] - mass[i]) * (f - i as f32)) / total
        };
        let mut sum = 0.0;
        for k in 0..CLIP_ANGLES {
            let theta = (k as f32 + 0.5) * std::f32::consts::TAU / CLIP_ANGLES as f32;
            let (sin, cos) = theta.sin_cos();
            let w = Vec2::new(cos, sin);
            let mut t = r;
            for &(g, s) in &self.lines[..self.count] {
                let c = g.dot(w);
                if c > 0.0 {
                    t = t.min(s / c);
                }
            }
            sum += within(t / r);
        }
        // A point on a crease keeps half the disc, in a corner a quarter; the floor keeps a
        // wall met at a grazing probe from dividing by next to nothing.
        (sum / CLIP_ANGLES as f32).max(0.1)
    }
}

thread_local! {
    /// Per-thread buffer for the k nearest photons of an estimate.
    static SCRATCH: std::cell::RefCell<Vec<Neighbour>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Runs `f` with this thread's buffer for the neighbours of an estimate (no allocation per
/// estimate).
pub fn with_scratch<R>(f: impl FnOnce(&mut Vec<Neighbour>) -> R) -> R {
    SCRATCH.with_borrow_mut(f)
}

/// How a k-nearest-neighbour radiance estimate is made.
#[derive(Clone, Copy)]
pub struct Estimate<'a> {
    /// Photons per estimate.
    pub k: usize,
    /// Largest radius searched.
    pub max_radius: f32,
    pub kernel: &'a NormalizedKernel,
}

pub struct PhotonMap {
    photons: Vec<Photon>,
    positions: Vec<[f32; 3]>,
    /// Split axis and coordinate of the node whose range has its median at this index
    /// (unused for buckets).
    axis: Vec<u8>,
    split: Vec<f32>,
    /// Bounds of the photons' positions (an empty box at the origin for no photon).
    bounds: (Vec3, Vec3),
}

/// A neighbour found by a query: squared distance and photon index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbour {
    pub d2: f32,
    pub index: u32,
}

/// Nodes of more photons than this find their bounds over pieces in parallel.
const PARALLEL_BOUNDS: usize = 1 << 16;

/// Photons per piece of a parallel bounds computation.
const PIECE: usize = 1 << 12;

/// The kd-tree's order of photons along axis `a`: ties broken by the full position, so that
/// the order (and every query's result) is the same whatever the thread count.
fn order(a: usize) -> impl Fn(&Photon, &Photon) -> Ordering + Copy + Sync {
    move |p: &Photon, q: &Photon| {
        p.position[a].total_cmp(&q.position[a]).then_with(|| {
            p.position
                .to_array()
                .map(f32::to_bits)
                .cmp(&q.position.to_array().map(f32::to_bits))
        })
    }
}

/// The bounds of the photons' positions; over pieces in parallel for a large slice.
fn bounds_of(photons: &[Photon]) -> (Vec3, Vec3) {
    let empty = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let fold = |s: &[Photon]| {
        s.iter().fold(empty, |(lo, hi), p| {
            (lo.min(p.position), hi.max(p.position))
        })
    };
    if photons.len() > PARALLEL_BOUNDS {
        photons
            .par_chunks(PIECE)
            .map(fold)
            .reduce(|| empty, |(a, b), (c, d)| (a.min(c), b.max(d)))
    } else {
        fold(photons)
    }
}

fn build_range(photons: &mut [Photon], axis: &mut [u8], split: &mut [f32]) {
    let n = photons.len();
    if n <= LEAF {
        return;
    }
    let (lo, hi) = bounds_of(photons);
    let extent = hi - lo;
    let a = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = n / 2;
    photons.select_nth_unstable_by(mid, order(a));
    axis[mid] = a as u8;
    split[mid] = photons[mid].position[a];
    let (left, right) = photons.split_at_mut(mid);
    let (left_axis, right_axis) = axis.split_at_mut(mid);
    let (left_split, right_split) = split.split_at_mut(mid);
    if n > 8192 {
        rayon::join(
            || build_range(left, left_axis, left_split),
            || build_range(right, right_axis, right_split),
        );
    } else {
        build_range(left, left_axis, left_split);
        build_range(right, right_axis, right_split);
    }
}

/// The k best neighbours so far: a max-heap kept as an array (`offer`), or for a small k an
/// unsorted array (`offer_small`).
struct Candidates<'a> {
    items: &'a mut Vec<Neighbour>,
    k: usize,
    /// Current search radius squared.
    r2: f32,
    /// For a small k, once k are held: the index of the farthest (whose distance is `r2`).
    worst: usize,
}

impl Candidates<'_> {
    #[inline]
    fn offer(&mut self, n: Neighbour) {
        if self.items.len() < self.k {
            self.items.push(n);
            sift_up(self.items);
            if self.items.len() == self.k {
                self.r2 = self.r2.min(self.items[0].d2);
            }
        } else if n.d2 < self.items[0].d2 {
            self.items[0] = n;
            sift_down(self.items);
            self.r2 = self.items[0].d2;
        }
    }
}

/// Up to this k the candidates are an unsorted array whose largest is found by a scan when
/// it is replaced: cheaper than a heap's sifts for the small k of the defaults (vpm's 8).
const SMALL_K: usize = 16;

impl Candidates<'_> {
    #[inline]
    fn offer_small(&mut self, n: Neighbour) {
        let items = &mut *self.items;
        if items.len() < self.k {
            items.push(n);
            if items.len() == self.k {
                let (i, d2) = largest(items);
                self.worst = i;
                self.r2 = self.r2.min(d2);
            }
        } else if n.d2 < items[self.worst].d2 {
            items[self.worst] = n;
            (self.worst, self.r2) = largest(items);
        }
    }
}

/// The index and squared distance of the farthest candidate (the first of equals).
#[inline]
fn largest(items: &[Neighbour]) -> (usize, f32) {
    let mut best = (0, items[0].d2);
    for (i, n) in items.iter().enumerate().skip(1) {
        if n.d2 > best.1 {
            best = (i, n.d2);
        }
    }
    best
}

fn sift_up(h: &mut [Neighbour]) {
    let mut i = h.len() - 1;
    while i > 0 {
        let parent = (i - 1) / 2;
        if h[parent].d2 >= h[i].d2 {
            break;
        }
        h.swap(parent, i);
        i = parent;
    }
}

fn sift_down(h: &mut [Neighbour]) {
    let mut i = 0;
    loop {
        let (l, r) = (2 * i + 1, 2 * i + 2);
        let mut largest = i;
        if l < h.len() && h[l].d2 > h[largest].d2 {
            largest = l;
        }
        if r < h.len() && h[r].d2 > h[largest].d2 {
            largest = r;
        }
        if largest == i {
            break;
        }
        h.swap(i, largest);
        i = largest;
    }
}

impl PhotonMap {
    pub fn build(mut photons: Vec<Photon>) -> PhotonMap {
        let mut axis = vec![0u8; photons.len()];
        let mut split = vec![0f32; photons.len()];
        build_range(&mut photons, &mut axis, &mut split);
        let positions = photons.iter().map(|p| p.position.to_array()).collect();
        let bounds = if photons.is_empty() {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            bounds_of(&photons)
        };
        PhotonMap {
            photons,
            positions,
            axis,
            split,
            bounds,
        }
    }

    pub fn len(&self) -> usize {
        self.photons.len()
    }
    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    /// The bytes the map holds on the heap: the photon records and the kd-tree's positions,
    /// split axes and split coordinates beside them.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.photons.capacity() * size_of::<Photon>()
            + self.positions.capacity() * size_of::<[f32; 3]>()
            + self.axis.capacity()
            + self.split.capacity() * size_of::<f32>()
    }
    pub fn photons(&self) -> &[Photon] {
        &self.photons
    }
    #[inline]
    pub fn photon(&self, index: u32) -> &Photon {
        &self.photons[index as usize]
    }

    /// Calls `visit(index, d2)` for every photon within squared radius `*r2` of `p`, in tree
    /// order; `visit` may shrink `*r2` to prune the rest of the search.
    #[inline]
    fn search(&self, p: Vec3, r2: &mut f32, mut visit: impl FnMut(u32, f32, &mut f32)) {
        let q = p.to_array();
        // Ranges [lo, hi) still to visit, each with the squared distance from the query to its
        // cell (a lower bound on any of its photons' distances) and the per-axis offsets
        // that distance is made of (Arya and Mount's incremental distance).
        #[derive(Clone, Copy)]
        struct Pending {
            lo: u32,
            hi: u32,
            dist2: f32,
            off: [f32; 3],
        }
        // Written only when pushed: filling all 64 (1.5 kB) on every query cost 2 % of vpm.
        let mut stack = [const { MaybeUninit::<Pending>::uninit() }; 64];
        let mut top = 0;
        let (mut lo, mut hi) = (0usize, self.photons.len());
        let mut off = [0.0f32; 3];
        let mut dist2 = 0.0f32;
        loop {
            if hi - lo <= LEAF {
                for i in lo..hi {
                    let s = self.positions[i];
                    let d = [s[0] - q[0], s[1] - q[1], s[2] - q[2]];
                    let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    if d2 < *r2 {
                        visit(i as u32, d2, r2);
                    }
                }
            } else {
                let mid = (lo + hi) / 2;
                let a = self.axis[mid] as usize;
                let delta = q[a] - self.split[mid];
                // Near side first; the far cell is farther by the change of this axis' offset.
                let (near, far) = if delta < 0.0 {
                    ((lo, mid), (mid, hi))
                } else {
                    ((mid, hi), (lo, mid))
                };
                let far_dist2 = dist2 - off[a] * off[a] + delta * delta;
                if far_dist2 < *r2 {
                    let mut far_off = off;
                    far_off[a] = delta;
                    stack[top] = MaybeUninit::new(Pending {
                        lo: far.0 as u32,
                        hi: far.1 as u32,
                        dist2: far_dist2,
                        off: far_off,
                    });
                    top += 1;
                }
                (lo, hi) = near;
                continue;
            }
            // Pop the next range whose cell is still within the (possibly shrunk) radius.
            loop {
                if top == 0 {
                    return;
                }
                top -= 1;
                // SAFETY: stack[..top] were written by the pushes above.
                let next = unsafe { stack[top].assume_init() };
                if next.dist2 < *r2 {
                    (lo, hi, dist2, off) =
                        (next.lo as usize, next.hi as usize, next.dist2, next.off);
                    break;
                }
            }
        }
    }

    /// The (up to) k nearest photons within `max_radius` of `p` that `accept` takes, into
    /// `out` (unordered). `accept(photon, r2)` is asked with the current squared search
    /// radius, which only shrinks. Returns the squared search radius: the distance to the
    /// k-th photon if k were found, else `max_radius`^2.
    pub fn knn(
        &self,
        p: Vec3,
        k: usize,
        max_radius: f32,
        accept: impl Fn(&Photon, f32) -> bool,
        out: &mut Vec<Neighbour>,
    ) -> f32 {
        out.clear();
        if self.photons.is_empty() || k == 0 {
            return max_radius * max_radius;
        }
        let mut cand = Candidates {
            items: out,
            k,
            r2: max_radius * max_radius,
            worst: 0,
        };
        let mut r2 = cand.r2;
        // One search loop per kind of candidate list, chosen once per query.
        if k <= SMALL_K {
            self.search(p, &mut r2, |i, d2, r2| {
                if accept(&self.photons[i as usize], *r2) {
                    cand.offer_small(Neighbour { d2, index: i });
                    *r2 = cand.r2;
                }
            });
        } else {
            self.search(p, &mut r2, |i, d2, r2| {
                if accept(&self.photons[i as usize], *r2) {
                    cand.offer(Neighbour { d2, index: i });
                    *r2 = cand.r2;
                }
            });
        }
        cand.r2
    }

    /// Calls `f` for every photon within `radius` of `p`.
    pub fn within(&self, p: Vec3, radius: f32, mut f: impl FnMut(&Photon, f32)) {
        if self.photons.is_empty() {
            return;
        }
        let mut r2 = radius * radius;
        self.search(p, &mut r2, |i, d2, _| f(&self.photons[i as usize], d2));
    }

    /// Calls `visit(index, photon, t, d2)` for every photon whose distance from the segment
    /// `origin + t dir`, t in [0, `t_max`], is below `radius`, measured perpendicular to it
    /// (d2 its square, t the photon's projection on the line, inside [0, t_max]). `dir` is
    /// unit. The beam radiance estimate's query (Jarosz, Zwicker and Jensen 2008): the tree
    /// is walked with each node's box, grown by `radius`, clipped against the segment.
    pub fn along_ray(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        radius: f32,
        mut visit: impl FnMut(u32, &Photon, f32, f32),
    ) {
        if self.photons.is_empty() {
            return;
        }
        let inv = dir.recip();
        let r2 = radius * radius;
        let hits_box = |lo: Vec3, hi: Vec3| {
            let t0 = (lo - Vec3::splat(radius) - origin) * inv;
            let t1 = (hi + Vec3::splat(radius) - origin) * inv;
            // NaN from 0 * inf (a ray in a box face's plane) is ignored by min/max.
            let near = t0.min(t1).max_element().max(0.0);
            let far = t0.max(t1).min_element().min(t_max);
            near <= far
        };
        let (lo, hi) = self.bounds();
        // Depth-first: at most one pending range per level of the tree (under 64 levels for
        // any photon count), so no allocation per ray.
        let mut stack = [(0usize, 0usize, Vec3::ZERO, Vec3::ZERO); 64];
        stack[0] = (0, self.photons.len(), lo, hi);
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (lo_i, hi_i, lo, hi) = stack[top];
            if !hits_box(lo, hi) {
                continue;
            }
            if hi_i - lo_i <= LEAF {
                for i in lo_i..hi_i {
                    let v = Vec3::from_array(self.positions[i]) - origin;
                    let t = v.dot(dir);
                    if !(0.0..=t_max).contains(&t) {
                        continue;
                    }
                    let d2 = (v - dir * t).length_squared();
                    if d2 < r2 {
                        visit(i as u32, &self.photons[i], t, d2);
                    }
                }
                continue;
            }
            let mid = (lo_i + hi_i) / 2;
            let a = self.axis[mid] as usize;
            let split = self.split[mid];
            let (mut left_hi, mut right_lo) = (hi, lo);
            left_hi[a] = split;
            right_lo[a] = split;
            stack[top] = (mid, hi_i, right_lo, hi);
            stack[top + 1] = (lo_i, mid, lo, left_hi);
            top += 2;
        }
    }

    /// The k-nearest density estimate shared by surfaces and volumes: the sum of
    /// `contribution(photon, d, r)` over the k nearest photons (within `max_radius`) that
    /// `accept` takes (see [`PhotonMap::knn`]), r the distance to the k-th, and of those the
    /// ones `keep(photon, r)` keeps.
    ///
    /// That photon lies on the boundary of the disc (ball) of radius r, so only the k - 1
    /// inside are summed (for a uniform density the expected count inside the k-th
    /// neighbour's radius is k - 1). When fewer than k photons lie within `max_radius`,
    /// r = `max_radius` and all of them are summed.
    fn knn_estimate(
        &self,
        p: Vec3,
        estimate: &Estimate<'_>,
        accept: impl Fn(&Photon, f32) -> bool,
        keep: impl Fn(&Photon, f32) -> bool,
        scratch: &mut Vec<Neighbour>,
        mut contribution: impl FnMut(&Photon, f32, f32) -> Rgb,
    ) -> Rgb {
        let k = estimate.k;
        let r2 = self.knn(p, k, estimate.max_radius, accept, scratch);
        if scratch.is_empty() {
            return Rgb::ZERO;
        }
        let r = r2.sqrt();
        let full = scratch.len() == k;
        let mut sum = Rgb::ZERO;
        for nb in scratch.iter() {
            if full && nb.d2 >= r2 {
                continue; // the k-th photon, on the boundary
            }
            let photon = &self.photons[nb.index as usize];
            if keep(photon, r) {
                sum += contribution(photon, nb.d2.sqrt(), r);
            }
        }
        sum
    }

    /// Radiance reflected at the disc's point p (normal n on the side looked at) from the
    /// photons of the disc around it: sum over the k nearest photons (see `knn_estimate`) of
    /// f(wi_p) Phi_p K2(d_p, r), with `f` the BSDF towards the viewer evaluated with each
    /// photon's own incoming direction, so that any BSDF, glossy ones included, is right.
    ///
    /// Photons are taken from a disc, not a ball: stored on the same side of a surface facing
    /// the same way (normals within about 25 degrees), with paths of at most the disc's
    /// `max_depth` scattering events, and no farther from the tangent plane than
    /// [`DISC_THICKNESS`] times the radius. With the disc clipped at the walls around p
    /// ([`DiscClip`]): only photons on p's side of every wall, divided by the kernel's mass on
    /// that side.
    pub fn radiance(
        &self,
        disc: &Disc<'_>,
        estimate: &Estimate<'_>,
        scratch: &mut Vec<Neighbour>,
        f: impl Fn(Vec3) -> Rgb,
    ) -> Rgb {
        let &Disc {
            p,
            n,
            max_depth,
            clip,
        } = disc;
        let thickness2 = DISC_THICKNESS * DISC_THICKNESS;
        let height2 = |ph: &Photon| {
            let h = (ph.position - p).dot(n);
            h * h
        };
        let mut radius = 0.0f32;
        let sum = self.knn_estimate(
            p,
            estimate,
            // Rejected early against the current radius, which only shrinks: a photon too far
            // from the plane for it is too far for the final one.
            |ph, r2| {
                ph.depth() <= max_depth
                    && ph.normal().dot(n) > 0.9
                    && height2(ph) <= thickness2 * r2
                    && clip.keeps(ph.position)
            },
            |ph, r| height2(ph) <= thickness2 * r * r,
            scratch,
            |ph, d, r| {
                radius = r;
                f(ph.wi()) * ph.power() * estimate.kernel.weight_2d(d, r)
            },
        );
        if radius > 0.0 {
            sum / clip.coverage(radius, estimate.kernel)
        } else {
            sum
        }
    }

    /// Radiance reflected towards `wo` by `bsdf` at the disc's point from the photons of the
    /// disc: the surface estimate every photon integrator makes, with the BSDF evaluated per
    /// photon (`Bsdf::eval_density`). Uses this thread's scratch buffer.
    pub fn reflected(
        &self,
        estimate: &Estimate<'_>,
        disc: &Disc<'_>,
        bsdf: &Bsdf,
        wo: Vec3,
    ) -> Rgb {
        if self.is_empty() || disc.max_depth == 0 {
            return Rgb::ZERO;
        }
        with_scratch(|scratch| {
            if let Lobe::Diffuse(_) = bsdf.lobe
                && bsdf.frame.n == bsdf.ng
            {
                // A Lambertian BSDF without a shading normal is the same for every photon of
                // the disc (each arrived on the side looked at): f once, outside the sum, and
                // no direction to decode.
                let f = bsdf.eval_density(wo, disc.n);
                let e = self.radiance(disc, estimate, scratch, |_| Rgb::ONE);
                return f * e;
            }
            self.radiance(disc, estimate, scratch, |wi| bsdf.eval_density(wo, wi))
        })
    }

    /// Irradiance at a surface point: [`PhotonMap::radiance`] with f = 1, the sum of photon
    /// power times the surface kernel K2 over the photons of the disc.
    pub fn irradiance(
        &self,
        disc: &Disc<'_>,
        estimate: &Estimate<'_>,
        scratch: &mut Vec<Neighbour>,
    ) -> Rgb {
        self.radiance(disc, estimate, scratch, |_| Rgb::ONE)
    }

    /// In-scattered radiance at a point in a medium towards the camera, sigma_s times the
    /// integral of phase times incident radiance (Jensen and Christensen 1998): the sum over
    /// the k nearest volume photons (see `knn_estimate`; of at most `max_depth` scattering
    /// events) of p(theta) Phi_p K3(d_p, r), K3 normalised over the ball. `dir` is the camera
    /// ray's direction (light leaves towards -dir). Stored flux already carries
    /// sigma_s / sigma_t, so no coefficient appears here.
    pub fn in_scattered(
        &self,
        p: Vec3,
        dir: Vec3,
        phase: &Phase,
        max_depth: u32,
        estimate: &Estimate<'_>,
        scratch: &mut Vec<Neighbour>,
    ) -> Rgb {
        self.knn_estimate(
            p,
            estimate,
            |ph, _| ph.depth() <= max_depth,
            |_, _| true,
            scratch,
            // Light travelled along -wi_p and leaves along -dir.
            |ph, d, r| {
                ph.power() * (phase.eval(ph.wi().dot(dir)) * estimate.kernel.weight_3d(d, r))
            },
        )
    }

    /// Bounds of the stored photons (empty map: an empty box at the origin).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use foton_core::api::Rng;

    fn random_map(n: usize, seed: u64) -> (Vec<Photon>, PhotonMap) {
        let mut rng = Rng::new(&[seed]);
        let photons: Vec<Photon> = (0..n)
            .map(|_| {
                let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32() * 0.1);
                Photon::new(p, Rgb::ONE, Vec3::Z, Vec3::Z)
            })
            .collect();
        (photons.clone(), PhotonMap::build(photons))
    }

    /// A map large enough to be partitioned in parallel (with photons at equal positions, on
    /// planes and at one point, as a collimated beam leaves them) is a kd-tree: at every node
    /// the photons before the median are not above its split and those after not below; and
    /// it is the same, photon for photon, built on one thread or on four.
    #[test]
    fn a_large_map_is_a_kd_tree_whatever_the_threads() {
        let mut rng = Rng::new(&[3]);
        let photons: Vec<Photon> = (0..300_000)
            .map(|i| {
                let p = match i % 3 {
                    0 => Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()),
                    1 => Vec3::new(rng.next_f32(), 0.5, rng.next_f32()),
                    _ => Vec3::splat(0.25),
                };
                Photon::new(p, Rgb::splat(i as f32), Vec3::Z, Vec3::Z)
            })
            .collect();
        let build = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| PhotonMap::build(photons.clone()))
        };
        let (one, four) = (build(1), build(4));
        assert!(one.photons == four.photons);
        assert_eq!(one.split, four.split);
        fn check(map: &PhotonMap, lo: usize, hi: usize) {
            if hi - lo <= LEAF {
                return;
            }
            let mid = lo + (hi - lo) / 2;
            let (a, s) = (map.axis[mid] as usize, map.split[mid]);
            assert!(map.photons[lo..mid].iter().all(|p| p.position[a] <= s));
            assert!(map.photons[mid..hi].iter().all(|p| p.position[a] >= s));
            check(map, lo, mid);
            check(map, mid, hi);
        }
        check(&one, 0, one.photons.len());
        let mut powers: Vec<u32> = one.photons.iter().map(|p| p.power[0] as u32).collect();
        powers.sort_unstable();
        assert!(powers.iter().enumerate().all(|(i, &p)| p == i as u32));
    }

    /// Issue 35: a photon map within twice the size of its photon records.
    #[test]
    fn a_photon_map_holds_at_most_twice_its_records() {
        let n = 100_000;
        let (_, map) = random_map(n, 9);
        let per_photon = map.heap_bytes() as f64 / n as f64;
        let record = std::mem::size_of::<Photon>() as f64;
        println!("photon map: {per_photon:.1} bytes per photon, records of {record} bytes");
        assert!(per_photon >= record, "{per_photon}");
        assert!(
            per_photon <= 2.0 * record,
            "{per_photon} bytes per {record}-byte photon"
        );
    }

    #[test]
    fn along_ray_matches_brute_force() {
        let (all, map) = random_map(20_000, 3);
        let mut rng = Rng::new(&[4]);
        for _ in 0..100 {
            let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 1.4 - 0.2;
            let dir = foton_core::api::uniform_sphere(rng.next_2d());
            let (t_max, radius) = (0.2 + rng.next_f32(), 0.01 + 0.05 * rng.next_f32());
            let mut got = Vec::new();
            map.along_ray(origin, dir, t_max, radius, |_, p, t, d2| {
                got.push((
                    p.position.to_array().map(f32::to_bits),
                    t.to_bits(),
                    d2.to_bits(),
                ))
            });
            let mut want: Vec<_> = all
                .iter()
                .filter_map(|p| {
                    let v = p.position - origin;
                    let t = v.dot(dir);
                    let d2 = (v - dir * t).length_squared();
                    ((0.0..=t_max).contains(&t) && d2 < radius * radius).then_some((
                        p.position.to_array().map(f32::to_bits),
                        t.to_bits(),
                        d2.to_bits(),
                    ))
                })
                .collect();
            got.sort();
            want.sort();
            assert_eq!(got, want);
        }
    }

    #[test]
    fn knn_matches_brute_force() {
        let (all, map) = random_map(20_000, 1);
        let mut rng = Rng::new(&[2]);
        let mut out = Vec::new();
        for _ in 0..200 {
            let q = Vec3::new(rng.next_f32(), rng.next_f32(), 0.05);
            let k = 1 + (rng.next_u32() % 60) as usize;
            let r2 = map.knn(q, k, 0.2, |_, _| true, &mut out);
            let mut d: Vec<f32> = all
                .iter()
                .map(|p| p.position.distance_squared(q))
                .filter(|&d2| d2 < 0.04)
                .collect();
            d.sort_by(f32::total_cmp);
            d.truncate(k);
            let mut got: Vec<f32> = out.iter().map(|n| n.d2).collect();
            got.sort_by(f32::total_cmp);
            assert_eq!(got, d);
            if d.len() == k {
                assert_eq!(r2, d[k - 1]);
            }
        }
    }

    #[test]
    fn within_matches_brute_force() {
        let (all, map) = random_map(5_000, 3);
        let q = Vec3::new(0.4, 0.6, 0.0);
        let mut count = 0;
        map.within(q, 0.1, |_, _| count += 1);
        let want = all
            .iter()
            .filter(|p| p.position.distance_squared(q) < 0.01)
            .count();
        assert_eq!(count, want);
    }

    #[test]
    fn directions_survive_encoding() {
        let mut rng = Rng::new(&[4]);
        for _ in 0..1000 {
            let d = foton_core::api::uniform_sphere(rng.next_2d());
            let p = Photon::new(Vec3::ZERO, Rgb::ONE, d, -d);
            assert!(p.wi().dot(d) > 0.99999);
            assert!(p.normal().dot(-d) > 0.99 && p.normal().length() < 1.01);
        }
        assert_eq!(std::mem::size_of::<Photon>(), 32);
    }
}
