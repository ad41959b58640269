//! Null-collision tracking through a [`Grid`]: delta tracking (Woodcock et al. 1965) samples
//! free-flight distances and ratio tracking (Novák et al. 2014) estimates transmittance, both
//! against a majorant, here piecewise constant over a coarse grid of blocks of lattice cells
//! crossed with a 3-D DDA, or a single global one (Novák et al. 2018, "Monte Carlo methods for
//! physically based volume rendering", §3.2 and §5).
//!
//! The renderer does not use these: the `heterogeneous` medium tracks analytically
//! ([`Grid::integral`], [`Grid::invert`]), which is exact, has no variance of its own and gives
//! the exact pdfs that bidirectional estimators need. They are the alternatives it was measured
//! against (`cargo bench -p foton-tests --bench tracking`), kept correct by the tests below.
//!
//! Along a ray, the majorant of a segment is a block's largest sample: a trilinear lookup is a
//! convex combination of the samples at the corners of its cell (with the lookup point clamped
//! to the lattice, or zero beyond it), so it never exceeds the largest sample of the cells it
//! can fall in. Beyond the lattice a clamped grid takes the value on its boundary: the blocks
//! are framed by a skirt of blocks one sample thick, reaching to infinity, whose majorant is
//! the largest sample on that part of the boundary. Where lookups are zero (beyond the lattice
//! with [`Outside::Zero`](super::grid::Outside::Zero), beyond the support box with
//! [`Outside::ClampInBox`](super::grid::Outside::ClampInBox)) the majorant is zero, and along an
//! infinite segment of a clamped grid, once the ray has left the lattice along every axis it
//! moves on, the density is constant and is its own majorant.

use super::grid::Grid;
use crate::geometry::Ray;
use glam::{DVec3, Vec3};

/// A small deterministic generator (PCG32, O'Neill 2014: XSH RR output of a 64-bit LCG).
#[derive(Clone, Debug)]
pub struct Pcg32(u64);

impl Pcg32 {
    pub fn new(seed: u64) -> Pcg32 {
        let mut p = Pcg32(seed.wrapping_add(0x853c_49e6_748f_ea9b));
        p.next_u32();
        p
    }

    pub fn next_u32(&mut self) -> u32 {
        let old = self.0;
        self.0 = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// Uniform in [0, 1), 53 bits.
    pub fn uniform(&mut self) -> f64 {
        let hi = (self.next_u32() as u64) << 21;
        let lo = (self.next_u32() >> 11) as u64;
        (hi | lo) as f64 / (1u64 << 53) as f64
    }
}

/// Piecewise-constant majorants of a grid's lookups: per block of `cells`^3 lattice cells, per
/// channel, the largest sample any lookup inside the block interpolates; or one value for all
/// of space ([`Majorants::global`]).
#[derive(Clone, Debug)]
pub struct Majorants {
    /// Lattice cells per block and axis; 0 for a single global majorant.
    cells: usize,
    /// Per axis, the blocks inside the lattice (the last may be partial); the array also
    /// holds a skirt block on either side, indices -1 and `inner`, which reach to infinity.
    inner: [usize; 3],
    channels: usize,
    /// Per block (x fastest, skirts included), per channel.
    max: Vec<f32>,
}

/// Keeps a majorant above the lookups that rounding in f32 interpolation may push a few ulps
/// beyond the largest sample.
const MARGIN: f32 = 1.0 + 8.0 * f32::EPSILON;

impl Majorants {
    /// The majorant grid of `grid` with `cells` lattice cells per block and axis (at least 1).
    pub fn new(grid: &Grid, cells: usize) -> Majorants {
        let cells = cells.max(1);
        let res = grid.res();
        let channels = grid.channels();
        let inner = res.map(|n| (n - 1).div_ceil(cells));
        let dims = inner.map(|n| n + 2);
        let mut max = vec![0.0f32; dims[0] * dims[1] * dims[2] * channels];
        // The samples a block's lookups interpolate, per axis: the skirts only the boundary's.
        let range = |a: usize, b: i64| -> (usize, usize) {
            let last = res[a] - 1;
            if b < 0 {
                (0, 0)
            } else if b as usize >= inner[a] {
                (last, last)
            } else {
                let lo = b as usize * cells;
                (lo, (lo + cells).min(last))
            }
        };
        for bk in -1..=inner[2] as i64 {
            let (k0, k1) = range(2, bk);
            for bj in -1..=inner[1] as i64 {
                let (j0, j1) = range(1, bj);
                for bi in -1..=inner[0] as i64 {
                    let (i0, i1) = range(0, bi);
                    let at = (((bk + 1) as usize * dims[1] + (bj + 1) as usize) * dims[0]
                        + (bi + 1) as usize)
                        * channels;
                    for k in k0..=k1 {
                        for j in j0..=j1 {
                            for i in i0..=i1 {
                                for c in 0..channels {
                                    let m = &mut max[at + c];
                                    *m = m.max(grid.sample(i, j, k, c));
                                }
                            }
                        }
                    }
                }
            }
        }
        for m in &mut max {
            *m *= MARGIN;
        }
        Majorants {
            cells,
            inner,
            channels,
            max,
        }
    }

    /// A single majorant for all of space: the grid's largest sample per channel.
    pub fn global(grid: &Grid) -> Majorants {
        let channels = grid.channels();
        let res = grid.res();
        let mut max = vec![0.0f32; channels];
        for k in 0..res[2] {
            for j in 0..res[1] {
                for i in 0..res[0] {
                    for (c, m) in max.iter_mut().enumerate() {
                        *m = m.max(grid.sample(i, j, k, c));
                    }
                }
            }
        }
        Majorants {
            cells: 0,
            inner: [0; 3],
            channels,
            max: max.into_iter().map(|m| m * MARGIN).collect(),
        }
    }

    /// The number of majorant values per channel (blocks, skirts included; 1 if global).
    pub fn len(&self) -> usize {
        self.max.len() / self.channels
    }

    pub fn is_empty(&self) -> bool {
        self.max.is_empty()
    }

    #[inline]
    fn at(&self, b: [i64; 3], channel: usize) -> f32 {
        let dims = self.inner.map(|n| n + 2);
        let i =
            ((b[2] + 1) as usize * dims[1] + (b[1] + 1) as usize) * dims[0] + (b[0] + 1) as usize;
        self.max[i * self.channels + channel.min(self.channels - 1)]
    }

    /// Walks `ray` over (0, `tmax`) in consecutive segments of constant majorant:
    /// `segment(start, end, majorant)` for each, in order, until it returns false. The majorant
    /// bounds `grid.lookup(ray.at(t))[channel]` for t in the segment; the last segment may end
    /// at infinity, along which the lookup is then constant and equal to it.
    pub fn segments(
        &self,
        grid: &Grid,
        ray: &Ray,
        tmax: f32,
        channel: usize,
        mut segment: impl FnMut(f64, f64, f32) -> bool,
    ) {
        let tmax = tmax as f64;
        if tmax.is_nan() || tmax <= 0.0 {
            return;
        }
        let o = grid.to_lattice().transform_point3(ray.origin).as_dvec3();
        let d = grid.to_lattice().transform_vector3(ray.dir).as_dvec3();
        let last = grid.res().map(|n| (n - 1) as f64);
        // Where lookups may be non-zero: the support box, and the lattice unless clamped.
        let (mut t0, mut t1) = (0.0f64, tmax);
        if let Some((lo, hi)) = grid.support() {
            let (a, b) = slabs(
                ray.origin.as_dvec3(),
                ray.dir.as_dvec3(),
                lo.as_dvec3(),
                hi.as_dvec3(),
            );
            (t0, t1) = (t0.max(a), t1.min(b));
        }
        if !grid.clamps() {
            let (a, b) = slabs(o, d, DVec3::ZERO, DVec3::from(last));
            (t0, t1) = (t0.max(a), t1.min(b));
        }
        if t1 <= t0 {
            segment(0.0, tmax, 0.0);
            return;
        }
        if t0 > 0.0 && !segment(0.0, t0, 0.0) {
            return;
        }
        // An infinite segment through a clamped grid: past the distance at which the ray has
        // left the lattice along every axis it moves on, the lookup is constant.
        let mut tail = None;
        if t1.is_infinite() {
            let mut tc = t0;
            for a in 0..3 {
                if d[a] > 0.0 {
                    tc = tc.max((last[a] - o[a]) / d[a]);
                } else if d[a] < 0.0 {
                    tc = tc.max(-o[a] / d[a]);
                }
            }
            let value = grid.lookup(ray.at((tc + 1.0) as f32))[channel];
            tail = Some((tc, value));
            t1 = tc;
        }
        let go_on = if self.cells == 0 {
            t1 <= t0 || segment(t0, t1, self.max[channel.min(self.channels - 1)])
        } else {
            self.dda(o, d, last, t0, t1, channel, &mut segment)
        };
        if !go_on {
            return;
        }
        if let Some((tc, value)) = tail {
            segment(tc, f64::INFINITY, value);
        } else if t1 < tmax {
            segment(t1, tmax, 0.0);
        }
    }

    /// The blocks the ray o + t d crosses over (t0, t1), in lattice space: false if
    /// `segment` stopped the walk.
    #[allow(clippy::too_many_arguments)]
    fn dda(
        &self,
        o: DVec3,
        d: DVec3,
        last: [f64; 3],
        t0: f64,
        t1: f64,
        channel: usize,
        segment: &mut impl FnMut(f64, f64, f32) -> bool,
    ) -> bool {
        let cells = self.cells as f64;
        let inner = self.inner.map(|n| n as i64);
        // The lower plane of block b of axis a (b in 0..=inner; the upper skirt's is `last`).
        let lower = |a: usize, b: i64| {
            if b >= inner[a] {
                last[a]
            } else {
                b as f64 * cells
            }
        };
        let q = o + d * t0;
        let mut b = [0i64; 3];
        let mut next = [f64::INFINITY; 3];
        for a in 0..3 {
            b[a] = if q[a] < 0.0 {
                -1
            } else if q[a] >= last[a] {
                inner[a]
            } else {
                ((q[a] / cells) as i64).min(inner[a] - 1)
            };
        }
        let crossing = |a: usize, b: i64| {
            if d[a] > 0.0 && b < inner[a] {
                (lower(a, b + 1) - o[a]) / d[a]
            } else if d[a] < 0.0 && b >= 0 {
                (lower(a, b) - o[a]) / d[a]
            } else {
                f64::INFINITY
            }
        };
        for a in 0..3 {
            next[a] = crossing(a, b[a]);
        }
        let mut t = t0;
        while t < t1 {
            let a = if next[0] <= next[1] && next[0] <= next[2] {
                0
            } else if next[1] <= next[2] {
                1
            } else {
                2
            };
            let end = next[a].min(t1).max(t);
            if end > t && !segment(t, end, self.at(b, channel)) {
                return false;
            }
            t = end;
            if end >= t1 {
                break;
            }
            b[a] += if d[a] > 0.0 { 1 } else { -1 };
            next[a] = crossing(a, b[a]);
        }
        true
    }
}

/// The distances (t0, t1) over which the ray o + t d is inside the box (lo, hi); t1 <= t0 if
/// it misses it.
fn slabs(o: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> (f64, f64) {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < lo[a] || o[a] > hi[a] {
                return (0.0, -1.0);
            }
            continue;
        }
        let (x, y) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
        t0 = t0.max(x.min(y));
        t1 = t1.min(x.max(y));
    }
    (t0, t1)
}

/// The extinction `sigma_scale` times `grid`'s `channel` at distance t along `ray`.
#[inline]
fn density(grid: &Grid, ray: &Ray, t: f64, sigma_scale: f64, channel: usize) -> f64 {
    let p: Vec3 = ray.at(t as f32);
    sigma_scale * grid.lookup(p)[channel] as f64
}

/// Delta (Woodcock) tracking: a free-flight distance in (0, `tmax`) along `ray` drawn with
/// density sigma(t) exp(-integral of sigma over (0, t)), sigma = `sigma_scale` times the grid's
/// `channel`; None (probability exp of minus the whole optical depth) if it passes `tmax`.
/// Within each majorant segment, tentative collisions are drawn from the majorant mu's
/// exponential, and accepted as real with probability sigma / mu (Novák et al. 2018, §5.1).
/// `rng` returns uniform numbers in [0, 1).
pub fn delta_tracking(
    grid: &Grid,
    majorants: &Majorants,
    ray: &Ray,
    tmax: f32,
    sigma_scale: f64,
    channel: usize,
    rng: &mut impl FnMut() -> f64,
) -> Option<f64> {
    let mut found = None;
    majorants.segments(grid, ray, tmax, channel, |start, end, m| {
        let mu = sigma_scale * m as f64;
        if mu <= 0.0 {
            return true;
        }
        // The exponential's memorylessness lets each segment start afresh at its start.
        let mut t = start;
        loop {
            t -= (1.0 - rng()).ln() / mu;
            if t >= end {
                return true;
            }
            if rng() * mu < density(grid, ray, t, sigma_scale, channel) {
                found = Some(t);
                return false;
            }
        }
    });
    found
}

/// Ratio tracking: an unbiased estimate of the transmittance exp(-integral of sigma over (0,
/// `tmax`)) along `ray`, sigma = `sigma_scale` times the grid's `channel`: the product over
/// the tentative collisions of the majorant mu's exponential of 1 - sigma / mu (Novák et al.
/// 2014; 2018, §5.2). `rng` returns uniform numbers in [0, 1).
pub fn ratio_tracking(
    grid: &Grid,
    majorants: &Majorants,
    ray: &Ray,
    tmax: f32,
    sigma_scale: f64,
    channel: usize,
    rng: &mut impl FnMut() -> f64,
) -> f64 {
    let mut tr = 1.0f64;
    majorants.segments(grid, ray, tmax, channel, |start, end, m| {
        let mu = sigma_scale * m as f64;
        if mu <= 0.0 {
            return true;
        }
        if end.is_infinite() {
            // The constant tail, whose transmittance is zero.
            tr = 0.0;
            return false;
        }
        let mut t = start;
        loop {
            t -= (1.0 - rng()).ln() / mu;
            if t >= end {
                return true;
            }
            tr *= 1.0 - density(grid, ray, t, sigma_scale, channel) / mu;
            if tr <= 0.0 {
                tr = 0.0;
                return false;
            }
        }
    });
    tr
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::medium::grid::{Outside, Samples};
    use glam::Mat4;

    /// Grids of every kind: (samples, outside, channels), with a few zero samples and zero
    /// blocks, in a box of the scene that is not the unit cube.
    fn grids(rng: &mut Pcg32) -> Vec<(String, Grid)> {
        let mut out = Vec::new();
        for (samples, outside, channels) in [
            (Samples::Centres, Outside::Clamp, 1),
            (Samples::Corners, Outside::Clamp, 1),
            (Samples::Centres, Outside::Zero, 1),
            (Samples::Corners, Outside::Zero, 3),
            (Samples::Centres, Outside::ClampInBox, 3),
            (Samples::Corners, Outside::ClampInBox, 1),
        ] {
            let res = [11, 7, 9];
            let n = res[0] * res[1] * res[2];
            let values = (0..n * channels)
                .map(|i| {
                    let s = i / channels;
                    let (x, y) = (s % res[0], (s / res[0]) % res[1]);
                    // A sparse corner, so blocks' majorants differ.
                    if x < 4 && y < 3 {
                        0.0
                    } else {
                        (rng.uniform() * 2.0) as f32 * if x > 7 { 3.0 } else { 1.0 }
                    }
                })
                .collect();
            let to_world = Mat4::from_translation(Vec3::new(-1.0, 0.5, 0.0))
                * Mat4::from_scale(Vec3::new(2.0, 1.5, 3.0));
            let g = Grid::new(res, channels, values, to_world, samples, outside).unwrap();
            out.push((format!("{samples:?} {outside:?} {channels}"), g));
        }
        out
    }

    fn random_ray(rng: &mut Pcg32) -> Ray {
        // Origins around the grid's box [-1, 1] x [0.5, 2] x [0, 3], many outside it.
        let o = Vec3::new(
            (rng.uniform() * 4.0 - 2.0) as f32,
            (rng.uniform() * 3.0) as f32,
            (rng.uniform() * 5.0 - 1.0) as f32,
        );
        let z = rng.uniform() * 2.0 - 1.0;
        let phi = rng.uniform() * std::f64::consts::TAU;
        let r = (1.0 - z * z).max(0.0).sqrt();
        Ray::new(
            o,
            Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32),
        )
    }

    /// The majorant of every segment bounds the lookups along it, inside the lattice and
    /// beyond, for every kind of grid, block size and the global majorant; the segments are
    /// consecutive and cover (0, tmax).
    #[test]
    fn majorants_bound_the_lookups_along_rays() {
        let mut rng = Pcg32::new(1);
        for (name, g) in grids(&mut rng) {
            for maj in [
                Majorants::global(&g),
                Majorants::new(&g, 1),
                Majorants::new(&g, 3),
                Majorants::new(&g, 4),
            ] {
                for r in 0..300 {
                    let ray = random_ray(&mut rng);
                    let tmax = if r % 5 == 0 {
                        f32::INFINITY
                    } else {
                        (rng.uniform() * 8.0) as f32
                    };
                    let channel = r % g.channels();
                    let mut at = 0.0;
                    let mut points = 0;
                    maj.segments(&g, &ray, tmax, channel, |start, end, m| {
                        assert!(
                            (start - at).abs() <= 1e-9 * at.abs().max(1.0),
                            "{name}: segment from {start} after {at}"
                        );
                        at = end;
                        for _ in 0..8 {
                            let t = start + rng.uniform() * (end.min(start + 20.0) - start);
                            let v = g.lookup(ray.at(t as f32))[channel];
                            assert!(
                                v <= m + 1e-5 * g.max(),
                                "{name}, {} cells: lookup {v} above majorant {m} at t = {t}",
                                maj.cells
                            );
                            points += 1;
                        }
                        true
                    });
                    assert_eq!(at, tmax as f64, "{name}: segments end at {at}");
                    assert!(points > 0);
                }
            }
        }
        // The majorant grid is tighter than the global one where it can be.
        let (_, g) = &grids(&mut rng)[0];
        let (fine, global) = (Majorants::new(g, 2), Majorants::global(g));
        assert!(fine.max.iter().any(|m| *m < 0.5 * global.max[0]));
        assert!(fine.max.contains(&0.0));
    }

    /// The upper quantile of chi-square with k degrees of freedom at z standard deviations
    /// (Wilson and Hilferty 1931).
    fn chi2_quantile(k: f64, z: f64) -> f64 {
        let v = 2.0 / (9.0 * k);
        k * (1.0 - v + z * v.sqrt()).powi(3)
    }

    /// The rays and extinctions of the statistical tests: a few kinds of grid, rays from
    /// inside and outside the lattice, segments that end inside it, beyond it and at infinity.
    fn cases() -> Vec<(String, Grid, Ray, f32, f64, usize)> {
        let mut rng = Pcg32::new(3);
        let gs = grids(&mut rng);
        let ray = |o: [f32; 3], d: [f32; 3]| Ray::new(Vec3::from(o), Vec3::from(d).normalize());
        let mut out = Vec::new();
        for (i, (name, g)) in gs.into_iter().enumerate() {
            let (r, tmax) = match i {
                0 => (ray([-1.5, 1.0, 0.2], [1.0, 0.3, 0.8]), 4.0),
                1 => (ray([0.9, 1.9, 2.5], [-1.0, -0.4, -0.6]), f32::INFINITY),
                2 => (ray([-2.0, 1.2, 1.5], [1.0, 0.1, 0.05]), 6.0),
                3 => (ray([0.0, 1.0, -0.5], [0.2, 0.1, 1.0]), 3.0),
                4 => (ray([-0.5, 0.8, 0.5], [0.5, 0.5, 1.0]), 10.0),
                _ => (ray([1.5, 1.5, 1.5], [-1.0, -0.2, 0.1]), f32::INFINITY),
            };
            let channel = i % g.channels();
            // An optical depth of about 2 over the segment (or up to its infinite tail).
            let depth = g.integral(&r, tmax.min(12.0))[channel];
            assert!(depth > 0.0, "{name}");
            out.push((name, g, r, tmax, 2.0 / depth, channel));
        }
        out
    }

    /// Delta-tracking distances, with the global majorant and with majorant grids, are
    /// distributed as the exact free flight: binned by the exact cdf 1 - exp(-sigma tau(t))
    /// into bins of equal probability, and one for passing tmax, they pass a chi-square test
    /// at p = 1e-4.
    #[test]
    fn delta_tracking_samples_the_exact_free_flight_distribution() {
        let (n, bins) = (100_000usize, 20usize);
        let mut rng = Pcg32::new(9);
        let mut u = || rng.uniform();
        for (name, g, ray, tmax, sigma, channel) in cases() {
            let whole = sigma * g.integral(&ray, tmax)[channel];
            let pass = (-whole).exp();
            for maj in [Majorants::global(&g), Majorants::new(&g, 4)] {
                let mut count = vec![0usize; bins + 1];
                for _ in 0..n {
                    match delta_tracking(&g, &maj, &ray, tmax, sigma, channel, &mut u) {
                        Some(t) => {
                            assert!(t > 0.0 && t < tmax as f64, "{name}: t = {t}");
                            let cdf = 1.0 - (-sigma * g.integral(&ray, t as f32)[channel]).exp();
                            let b = (cdf / (1.0 - pass) * bins as f64) as usize;
                            count[b.min(bins - 1)] += 1;
                        }
                        None => count[bins] += 1,
                    }
                }
                let expected = |b: usize| {
                    n as f64
                        * if b == bins {
                            pass
                        } else {
                            (1.0 - pass) / bins as f64
                        }
                };
                let chi2: f64 = (0..=bins)
                    .map(|b| (count[b] as f64 - expected(b)).powi(2) / expected(b).max(1e-300))
                    .sum();
                let limit = chi2_quantile(bins as f64, 3.72);
                assert!(
                    chi2 < limit,
                    "{name}, {} cells per block: chi-square {chi2} > {limit}; {count:?}",
                    maj.cells
                );
            }
        }
    }

    /// The mean of ratio-tracking estimates is the exact transmittance within 4 standard
    /// errors, with the global majorant and majorant grids; each estimate is in [0, 1].
    #[test]
    fn ratio_tracking_is_unbiased() {
        let n = 20_000;
        let mut rng = Pcg32::new(17);
        let mut u = || rng.uniform();
        for (name, g, ray, tmax, sigma, channel) in cases() {
            let exact = (-sigma * g.integral(&ray, tmax)[channel]).exp();
            for maj in [
                Majorants::global(&g),
                Majorants::new(&g, 2),
                Majorants::new(&g, 4),
            ] {
                let (mut sum, mut sum2) = (0.0, 0.0);
                for _ in 0..n {
                    let e = ratio_tracking(&g, &maj, &ray, tmax, sigma, channel, &mut u);
                    assert!((0.0..=1.0).contains(&e), "{name}: {e}");
                    sum += e;
                    sum2 += e * e;
                }
                let mean = sum / n as f64;
                let se = ((sum2 / n as f64 - mean * mean).max(0.0) / (n - 1) as f64).sqrt();
                assert!(
                    (mean - exact).abs() <= 4.0 * se + 1e-12,
                    "{name}, {} cells per block: mean {mean} vs exact {exact} (se {se})",
                    maj.cells
                );
            }
        }
    }
}
