//! A regular lattice of values in a box, looked up with trilinear interpolation: the density
//! and albedo grids of the `heterogeneous` medium (Mitsuba's `gridvolume`, pbrt-v4's
//! `uniformgrid`). Along a ray, the interpolated value is a cubic polynomial in the distance
//! within each lattice cell, so the optical depth of a segment is a sum of exact integrals and a
//! free-flight distance is found by inverting one of them: transmittance and free-flight
//! sampling are exact, with no random numbers of their own (regular tracking, Novák et al.
//! 2018, §4.1, in its analytic form), and so are their pdfs, which bidirectional estimators
//! and their MIS weights need.
//!
//! Mitsuba's binary `.vol` format (version 3, float32 cells, x fastest) is read by
//! [`VolFile::parse`].

use crate::Rgb;
use crate::geometry::Ray;
use crate::texture::WrapMode;
use glam::{DVec3, Mat4, Vec3};

/// Where the lattice's samples lie in its unit cube.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Samples {
    /// At the centres of res^3 cells: sample i at (i + 1/2) / res (Mitsuba 3, pbrt-v4).
    Centres,
    /// At the corners, the first and last on the faces: sample i at i / (res - 1) (Mitsuba
    /// 0.6).
    Corners,
}

/// What a lookup between the outermost samples and beyond returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outside {
    /// The nearest sample's value (Mitsuba 3's clamp).
    Clamp,
    /// Zero outside the box the samples span (Mitsuba 0.6).
    Zero,
    /// The nearest sample's value within the axis-aligned box around the grid's unit cube
    /// in the scene, zero beyond it (Mitsuba 3's heterogeneous medium, which exists only in
    /// its extinction volume's bounding box).
    ClampInBox,
    /// The grid tiles space, interpolating across the seam between the last and the first
    /// sample (Mitsuba 3's `repeat` wrap mode). Lookups only: a density that repeats has no
    /// majorant grid (a medium's density refuses it).
    Repeat,
}

/// A lattice of `channels` (1 or 3) values per sample, x fastest, then y, then z.
#[derive(Clone, Debug)]
pub struct Grid {
    res: [usize; 3],
    channels: usize,
    values: Vec<f32>,
    /// World position to continuous lattice coordinates (sample (i, j, k) at (i, j, k)).
    to_lattice: Mat4,
    outside: Outside,
    /// Where the grid is not zero (world space), with [`Outside::ClampInBox`].
    support: Option<(Vec3, Vec3)>,
    max: f32,
    /// Blocks of BLOCK^3 cells per axis, and per block whether all its samples are zero
    /// (empty space, which traversal crosses in one step).
    blocks: [usize; 3],
    empty: Vec<bool>,
}

/// The cells per axis of a block of empty space.
const BLOCK: usize = 8;

/// The contents of a Mitsuba `.vol` file.
#[derive(Clone, Debug, PartialEq)]
pub struct VolFile {
    pub res: [usize; 3],
    pub channels: usize,
    /// The box the file says the samples span (Mitsuba 0.6 places the grid there; Mitsuba 3
    /// ignores it).
    pub bbox: (Vec3, Vec3),
    pub values: Vec<f32>,
}

impl VolFile {
    /// Reads Mitsuba's binary grid: `VOL`, version 3, encoding 1 (float32), x, y, z
    /// resolution, channels, bounding box (six float32), then the cells.
    pub fn parse(bytes: &[u8]) -> Result<VolFile, String> {
        let int = |at: usize| -> Option<i32> {
            Some(i32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
        };
        let float = |at: usize| -> Option<f32> {
            Some(f32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
        };
        if bytes.get(..3) != Some(b"VOL") {
            return Err("not a Mitsuba grid volume: it does not start with `VOL`".into());
        }
        if bytes.get(3) != Some(&3) {
            return Err(format!(
                "Mitsuba grid volume version {}: only version 3 is read",
                bytes.get(3).copied().unwrap_or(0)
            ));
        }
        let truncated = || "the file ends inside its header".to_string();
        let encoding = int(4).ok_or_else(truncated)?;
        if encoding != 1 {
            return Err(format!(
                "encoding {encoding}: only 1 (float32 cells) is read; \
                 Mitsuba's others (2: float16, 3: uint8, 4: quantized directions) are not"
            ));
        }
        let (nx, ny, nz) = (
            int(8).ok_or_else(truncated)?,
            int(12).ok_or_else(truncated)?,
            int(16).ok_or_else(truncated)?,
        );
        let channels = int(20).ok_or_else(truncated)?;
        if nx <= 0 || ny <= 0 || nz <= 0 {
            return Err(format!(
                "resolution {nx} x {ny} x {nz}: each must be at least 1"
            ));
        }
        if channels != 1 && channels != 3 {
            return Err(format!("{channels} channels: expected 1 or 3"));
        }
        let b: Vec<f32> = (0..6)
            .map(|i| float(24 + 4 * i).ok_or_else(truncated))
            .collect::<Result<_, _>>()?;
        let res = [nx as usize, ny as usize, nz as usize];
        let count = res
            .iter()
            .try_fold(channels as usize, |n, &r| n.checked_mul(r))
            .filter(|n| *n <= (isize::MAX as usize) / 4)
            .ok_or_else(|| format!("resolution {nx} x {ny} x {nz} is too large"))?;
        let data = bytes.get(48..).unwrap_or(&[]);
        if data.len() < count * 4 {
            return Err(format!(
                "{nx} x {ny} x {nz} x {channels} cells need {} bytes after the header; the file has {}",
                count * 4,
                data.len()
            ));
        }
        let values = data[..count * 4]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        Ok(VolFile {
            res,
            channels: channels as usize,
            bbox: (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5])),
            values,
        })
    }
}

impl Grid {
    /// A grid of `values` (`channels` per sample, x fastest) whose unit cube `to_world` maps
    /// into the scene. Values must be finite; negative ones are read as zero.
    pub fn new(
        res: [usize; 3],
        channels: usize,
        values: Vec<f32>,
        to_world: Mat4,
        samples: Samples,
        outside: Outside,
    ) -> Result<Grid, String> {
        if res.contains(&0) {
            return Err(format!(
                "resolution {} x {} x {}: each must be at least 1",
                res[0], res[1], res[2]
            ));
        }
        if channels != 1 && channels != 3 {
            return Err(format!("{channels} channels: expected 1 or 3"));
        }
        let count = res[0] * res[1] * res[2] * channels;
        if values.len() != count {
            return Err(format!(
                "{} values for {} x {} x {} samples of {channels} channel(s): expected {count}",
                values.len(),
                res[0],
                res[1],
                res[2]
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(format!("value {i} is {}: values must be finite", values[i]));
        }
        // Exact tracking needs a density that is nowhere negative; simulations write tiny
        // negative values (rounding), which are zero.
        let values: Vec<f32> = values.into_iter().map(|v| v.max(0.0)).collect();
        if to_world.determinant() == 0.0 || !to_world.is_finite() {
            return Err("the transform is singular".into());
        }
        let n = Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        let unit_to_lattice = match samples {
            Samples::Centres => Mat4::from_translation(Vec3::splat(-0.5)) * Mat4::from_scale(n),
            Samples::Corners => Mat4::from_scale((n - 1.0).max(Vec3::ZERO)),
        };
        let max = values.iter().copied().fold(0.0, f32::max);
        let support = (outside == Outside::ClampInBox).then(|| {
            let corners = (0..8).map(|i| {
                let c = Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32);
                to_world.transform_point3(c)
            });
            corners.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            })
        });
        let outside = match outside {
            Outside::ClampInBox => Outside::Clamp,
            o => o,
        };
        let blocks = res.map(|n| (n - 1).div_ceil(BLOCK));
        let mut empty = vec![true; blocks[0] * blocks[1] * blocks[2]];
        for k in 0..res[2] {
            for j in 0..res[1] {
                for i in 0..res[0] {
                    let at = ((k * res[1] + j) * res[0] + i) * channels;
                    if values[at..at + channels].iter().all(|v| *v == 0.0) {
                        continue;
                    }
                    // A sample is a corner of the cells on either side of it (cells x - 1
                    // and x, of 0..=res - 2).
                    let span = |x: usize, r: usize| {
                        (x.saturating_sub(1) / BLOCK)..=(x.min(r.saturating_sub(2)) / BLOCK)
                    };
                    for bk in span(k, res[2]).filter(|b| *b < blocks[2]) {
                        for bj in span(j, res[1]).filter(|b| *b < blocks[1]) {
                            for bi in span(i, res[0]).filter(|b| *b < blocks[0]) {
                                empty[(bk * blocks[1] + bj) * blocks[0] + bi] = false;
                            }
                        }
                    }
                }
            }
        }
        Ok(Grid {
            res,
            channels,
            values,
            to_lattice: unit_to_lattice * to_world.inverse(),
            outside,
            support,
            max,
            blocks,
            empty,
        })
    }

    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The largest value of any sample and channel.
    pub fn max(&self) -> f32 {
        self.max
    }

    /// The mean over samples, per channel (grey grids: the same in each).
    pub fn mean(&self) -> Rgb {
        let mut sum = DVec3::ZERO;
        for v in self.values.chunks_exact(self.channels) {
            sum += if self.channels == 1 {
                DVec3::splat(v[0] as f64)
            } else {
                DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
            };
        }
        (sum / (self.values.len() / self.channels) as f64).as_vec3()
    }

    /// Samples per axis.
    pub(crate) fn res(&self) -> [usize; 3] {
        self.res
    }

    /// World position to continuous lattice coordinates (sample (i, j, k) at (i, j, k)).
    pub(crate) fn to_lattice(&self) -> Mat4 {
        self.to_lattice
    }

    /// Whether a lookup beyond the outermost samples takes the nearest one's value
    /// ([`Outside::Clamp`] and [`Outside::ClampInBox`]) rather than zero.
    pub(crate) fn clamps(&self) -> bool {
        self.outside == Outside::Clamp
    }

    /// The world-space box beyond which lookups are zero ([`Outside::ClampInBox`]).
    pub(crate) fn support(&self) -> Option<(Vec3, Vec3)> {
        self.support
    }

    #[inline]
    pub(crate) fn sample(&self, i: usize, j: usize, k: usize, c: usize) -> f32 {
        self.values[((k * self.res[1] + j) * self.res[0] + i) * self.channels + c]
    }

    /// Per axis, the two samples to interpolate between and the weight of the second; None
    /// where a lookup is zero (outside, with [`Outside::Zero`]).
    #[inline]
    fn corners(&self, q: Vec3) -> Option<[(usize, usize, f32); 3]> {
        let mut out = [(0, 0, 0.0); 3];
        for (a, o) in out.iter_mut().enumerate() {
            let last = (self.res[a] - 1) as f32;
            let mut x = q[a];
            if self.outside == Outside::Repeat {
                // Both neighbours wrapped as a repeating bitmap's texels are.
                let f = x.floor();
                let i = if f.is_finite() { f as i64 } else { 0 };
                let wrap = |i| WrapMode::Repeat.wrap(i, self.res[a]);
                *o = (wrap(i), wrap(i + 1), (x - f).clamp(0.0, 1.0));
                continue;
            }
            if !(0.0..=last).contains(&x) {
                match self.outside {
                    Outside::Zero => return None,
                    Outside::Clamp | Outside::ClampInBox | Outside::Repeat => {
                        x = x.clamp(0.0, last)
                    }
                }
            }
            // x is in [0, last]; NaN (a degenerate ray) lands on sample 0.
            let i = (x as usize).min(self.res[a].saturating_sub(2));
            let j = (i + 1).min(self.res[a] - 1);
            *o = (i, j, (x - i as f32).clamp(0.0, 1.0));
        }
        Some(out)
    }

    /// Trilinear interpolation at `p` (world space), per channel; a grey grid's value in each.
    pub fn lookup(&self, p: Vec3) -> Rgb {
        if let Some((lo, hi)) = self.support
            && !(p.cmpge(lo).all() && p.cmple(hi).all())
        {
            return Rgb::ZERO;
        }
        let Some([x, y, z]) = self.corners(self.to_lattice.transform_point3(p)) else {
            return Rgb::ZERO;
        };
        let mut v = [0.0; 3];
        for (c, v) in v.iter_mut().enumerate().take(self.channels) {
            let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
            let e = |j, k| lerp(self.sample(x.0, j, k, c), self.sample(x.1, j, k, c), x.2);
            let g = |k| lerp(e(y.0, k), e(y.1, k), y.2);
            *v = lerp(g(z.0), g(z.1), z.2);
        }
        if self.channels == 1 {
            Rgb::splat(v[0])
        } else {
            Rgb::from(v)
        }
    }

    /// Walks the grid along `ray` over (0, `tmax`) in pieces, each within one lattice cell:
    /// calls `piece(start, length, cell)` for each, in order, until it returns false. The last
    /// piece may be infinitely long when `tmax` is (the grid is then constant along it).
    pub fn pieces(&self, ray: &Ray, tmax: f32, mut piece: impl FnMut(f64, f64, &Cell) -> bool) {
        let (mut t, mut tmax) = (0.0f64, tmax as f64);
        let mut after = None;
        if let Some((lo, hi)) = self.support {
            // The slabs of the support box: zero before and after it.
            let (mut t0, mut t1) = (0.0f64, tmax);
            for a in 0..3 {
                let (o, d) = (ray.origin[a] as f64, ray.dir[a] as f64);
                let (lo, hi) = (lo[a] as f64, hi[a] as f64);
                if d == 0.0 {
                    if o < lo || o > hi {
                        t1 = -1.0;
                    }
                    continue;
                }
                let (a, b) = ((lo - o) / d, (hi - o) / d);
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
            if t1 <= t0 {
                piece(0.0, tmax, &Cell::ZERO);
                return;
            }
            if t0 > 0.0 && !piece(0.0, t0, &Cell::ZERO) {
                return;
            }
            if t1 < tmax {
                after = Some((t1, tmax));
            }
            (t, tmax) = (t0, t1);
        }
        let o = self.to_lattice.transform_point3(ray.origin).as_dvec3();
        let d = self.to_lattice.transform_vector3(ray.dir).as_dvec3();
        let start = o + d * t;
        // Per axis, the lattice cell: -1 below the first sample, k between samples k and
        // k + 1, res - 1 beyond the last; the distance to the next cell and its step.
        let (mut cell, mut next, mut delta) = self.dda(o, d, start);
        while t < tmax {
            // Empty space: the whole block of cells at once.
            if let Some(exit) = self.empty_block_exit(o, d, &cell)
                && exit > t
            {
                let end = exit.min(tmax);
                if !piece(t, end - t, &Cell::ZERO) {
                    return;
                }
                t = end;
                if end >= tmax {
                    break;
                }
                (cell, next, delta) = self.dda(o, d, o + d * t);
                continue;
            }
            let a = if next[0] <= next[1] && next[0] <= next[2] {
                0
            } else if next[1] <= next[2] {
                1
            } else {
                2
            };
            let end = next[a].min(tmax).max(t);
            if !piece(t, end - t, &self.cell(o, d, t, &cell)) {
                return;
            }
            t = end;
            if next[a] >= tmax {
                break;
            }
            // Step into the next cell along axis a.
            let last = self.res[a] as i64 - 1;
            if d[a] > 0.0 {
                cell[a] += 1;
                next[a] = if cell[a] < last {
                    next[a] + delta[a]
                } else {
                    f64::INFINITY
                };
            } else {
                cell[a] -= 1;
                next[a] = if cell[a] >= 0 {
                    next[a] + delta[a]
                } else {
                    f64::INFINITY
                };
            }
        }
        if let Some((t1, tmax)) = after {
            piece(t1, tmax - t1, &Cell::ZERO);
        }
    }

    /// The 3-D DDA's state at lattice point `q` of the ray o + t d: per axis, the cell (-1
    /// below the first sample, k between samples k and k + 1, res - 1 beyond the last), the
    /// distance at which the ray enters the next one, and the distance between crossings.
    #[allow(clippy::type_complexity)]
    fn dda(&self, o: DVec3, d: DVec3, q: DVec3) -> ([i64; 3], [f64; 3], [f64; 3]) {
        let mut cell = [0i64; 3];
        let mut next = [f64::INFINITY; 3];
        let mut delta = [f64::INFINITY; 3];
        for a in 0..3 {
            let last = self.res[a] as i64 - 1;
            cell[a] = (q[a].floor() as i64).clamp(-1, last);
            if d[a] > 0.0 && cell[a] < last {
                next[a] = (cell[a] as f64 + 1.0 - o[a]) / d[a];
                delta[a] = 1.0 / d[a];
            } else if d[a] < 0.0 && cell[a] >= 0 {
                next[a] = (cell[a] as f64 - o[a]) / d[a];
                delta[a] = -1.0 / d[a];
            }
        }
        (cell, next, delta)
    }

    /// If `cell` lies in a block of cells whose samples are all zero, the distance at which
    /// the ray o + t d leaves the block.
    #[inline]
    fn empty_block_exit(&self, o: DVec3, d: DVec3, cell: &[i64; 3]) -> Option<f64> {
        let mut b = [0usize; 3];
        for a in 0..3 {
            if cell[a] < 0 || cell[a] >= self.res[a] as i64 - 1 {
                return None;
            }
            b[a] = cell[a] as usize / BLOCK;
        }
        if !self.empty[(b[2] * self.blocks[1] + b[1]) * self.blocks[0] + b[0]] {
            return None;
        }
        let mut exit = f64::INFINITY;
        for a in 0..3 {
            let lo = (b[a] * BLOCK) as f64;
            let hi = ((b[a] + 1) * BLOCK).min(self.res[a] - 1) as f64;
            if d[a] > 0.0 {
                exit = exit.min((hi - o[a]) / d[a]);
            } else if d[a] < 0.0 {
                exit = exit.min((lo - o[a]) / d[a]);
            }
        }
        Some(exit)
    }

    /// The piece of the ray o + t d from distance `t` on within the lattice cell `cell`.
    fn cell(&self, o: DVec3, d: DVec3, t: f64, cell: &[i64; 3]) -> Cell {
        // Per axis: the samples on either side and the weight of the second, linear in s.
        let mut at = [(0usize, 0usize); 3];
        let mut piece = Cell {
            channels: self.channels,
            zero: false,
            v: [[0.0; 8]; 3],
            w0: [0.0; 3],
            dw: [0.0; 3],
        };
        for a in 0..3 {
            let last = self.res[a] as i64 - 1;
            let c = cell[a];
            if c < 0 || c >= last {
                // Zero beyond the samples, except on the plane of the last one of an axis
                // the ray does not move along (a grid one sample thick).
                let on_last = c == last && d[a] == 0.0 && o[a] == last as f64;
                if self.outside == Outside::Zero && !on_last {
                    return Cell::ZERO;
                }
                let i = c.clamp(0, last) as usize;
                at[a] = (i, i);
            } else {
                let i = c as usize;
                at[a] = (i, i + 1);
                piece.w0[a] = (o[a] + d[a] * t - c as f64).clamp(0.0, 1.0);
                piece.dw[a] = d[a];
            }
        }
        let [x, y, z] = at;
        for ch in 0..self.channels {
            for (n, v) in piece.v[ch].iter_mut().enumerate() {
                let i = if n & 1 == 0 { x.0 } else { x.1 };
                let j = if n & 2 == 0 { y.0 } else { y.1 };
                let k = if n & 4 == 0 { z.0 } else { z.1 };
                *v = self.sample(i, j, k, ch);
            }
        }
        piece
    }

    /// The integral of each channel along `ray` over (0, `d`) (a grey grid's in each): the
    /// optical depth per unit scale.
    pub fn integral(&self, ray: &Ray, d: f32) -> DVec3 {
        let mut sum = DVec3::ZERO;
        self.pieces(ray, d, |_, len, c| {
            sum += c.integrals(len);
            sum.is_finite()
        });
        sum
    }

    /// The distance t in (0, `tmax`) at which the integral of `channel` along `ray` reaches
    /// `target`, with the integral of each channel there; or None, with the integrals over
    /// the whole segment, when it stays below.
    pub fn invert(
        &self,
        ray: &Ray,
        tmax: f32,
        channel: usize,
        target: f64,
    ) -> (Option<f64>, DVec3) {
        let mut sum = DVec3::ZERO;
        let mut found = None;
        self.pieces(ray, tmax, |start, len, c| {
            let whole = c.integrals(len);
            if sum[channel] + whole[channel] >= target && whole[channel] > 0.0 {
                let s = c.cubic(channel).solve(target - sum[channel], len);
                found = Some(start + s);
                sum += c.integrals(s);
                sum[channel] = target;
                return false;
            }
            sum += whole;
            true
        });
        (found, sum)
    }
}

/// A piece of a ray within one lattice cell: each channel's corner samples and, per axis, the
/// weight of the second sample, linear in the distance s from the piece's start. The
/// interpolated value is a cubic in s.
#[derive(Clone, Copy, Debug)]
pub struct Cell {
    channels: usize,
    zero: bool,
    /// Per channel, the corners, index x + 2 y + 4 z (0: the first sample, 1: the second).
    v: [[f32; 8]; 3],
    w0: [f64; 3],
    dw: [f64; 3],
}

impl Cell {
    const ZERO: Cell = Cell {
        channels: 1,
        zero: true,
        v: [[0.0; 8]; 3],
        w0: [0.0; 3],
        dw: [0.0; 3],
    };

    /// Channel `ch`'s value at distance s into the piece.
    #[inline]
    fn value(&self, ch: usize, s: f64) -> f64 {
        let w = |a: usize| self.w0[a] + self.dw[a] * s;
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let v = self.v[ch].map(f64::from);
        let wx = w(0);
        let e = |n: usize| lerp(v[n], v[n + 1], wx);
        let wy = w(1);
        lerp(lerp(e(0), e(2), wy), lerp(e(4), e(6), wy), w(2))
    }

    /// Each channel's integral over (0, `len`) (one channel: the same in each). Simpson's
    /// rule, exact for the cubic; an infinite piece, along which the value is constant,
    /// integrates to infinity unless it is zero.
    #[inline]
    pub fn integrals(&self, len: f64) -> DVec3 {
        if self.zero {
            return DVec3::ZERO;
        }
        let one = |ch: usize| {
            if len.is_infinite() {
                if self.value(ch, 0.0) > 0.0 {
                    f64::INFINITY
                } else {
                    0.0
                }
            } else {
                len / 6.0
                    * (self.value(ch, 0.0) + 4.0 * self.value(ch, 0.5 * len) + self.value(ch, len))
            }
        };
        if self.channels == 1 {
            DVec3::splat(one(0))
        } else {
            DVec3::new(one(0), one(1), one(2))
        }
    }

    /// Channel `ch` as a cubic in the distance into the piece.
    pub fn cubic(&self, ch: usize) -> Cubic {
        if self.zero {
            return Cubic::ZERO;
        }
        let ch = ch.min(self.channels - 1);
        let lerp =
            |a: Cubic, b: Cubic, a_: usize| a.add(&b.sub(&a).mul_linear(self.w0[a_], self.dw[a_]));
        let v = |n: usize| Cubic::constant(self.v[ch][n] as f64);
        let e = |n: usize| lerp(v(n), v(n + 1), 0);
        lerp(lerp(e(0), e(2), 1), lerp(e(4), e(6), 1), 2)
    }
}

/// A cubic polynomial c0 + c1 s + c2 s^2 + c3 s^3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cubic(pub [f64; 4]);

impl Cubic {
    pub const ZERO: Cubic = Cubic([0.0; 4]);

    fn constant(c: f64) -> Cubic {
        Cubic([c, 0.0, 0.0, 0.0])
    }
    fn add(&self, o: &Cubic) -> Cubic {
        Cubic(std::array::from_fn(|i| self.0[i] + o.0[i]))
    }
    fn sub(&self, o: &Cubic) -> Cubic {
        Cubic(std::array::from_fn(|i| self.0[i] - o.0[i]))
    }
    /// The product with w0 + dw s (the degree never exceeds 3 here: one factor per axis).
    fn mul_linear(&self, w0: f64, dw: f64) -> Cubic {
        let c = &self.0;
        Cubic([
            c[0] * w0,
            c[1] * w0 + c[0] * dw,
            c[2] * w0 + c[1] * dw,
            c[3] * w0 + c[2] * dw,
        ])
    }

    pub fn eval(&self, s: f64) -> f64 {
        let c = &self.0;
        c[0] + s * (c[1] + s * (c[2] + s * c[3]))
    }

    /// The integral over (0, `s`); an infinite `s` gives infinity unless the cubic is zero.
    pub fn integral(&self, s: f64) -> f64 {
        let c = &self.0;
        if s.is_infinite() {
            return if c.iter().all(|c| *c == 0.0) {
                0.0
            } else {
                f64::INFINITY
            };
        }
        s * (c[0] + s * (c[1] / 2.0 + s * (c[2] / 3.0 + s * c[3] / 4.0)))
    }

    /// The s in [0, `len`] at which the integral from 0 reaches `target` (at most the
    /// integral over the whole piece): Newton's method kept inside a shrinking bracket, which
    /// converges because the cubic is not negative on the piece, so the integral increases.
    pub fn solve(&self, target: f64, len: f64) -> f64 {
        if len.is_infinite() {
            // The cubic of an infinite piece is a positive constant.
            return target / self.0[0];
        }
        let (mut lo, mut hi) = (0.0, len);
        let mut s = if self.integral(len) > 0.0 {
            len * target / self.integral(len)
        } else {
            0.0
        };
        for _ in 0..64 {
            let f = self.integral(s) - target;
            if f.abs() <= 1e-12 * target.max(1e-30) {
                break;
            }
            if f < 0.0 {
                lo = s;
            } else {
                hi = s;
            }
            let slope = self.eval(s);
            let newton = s - f / slope;
            s = if slope > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if hi - lo <= 1e-15 * len {
                break;
            }
        }
        s.clamp(0.0, len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator for the tests' grids and rays.
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 40) as f32) / (1u64 << 24) as f32
        }
    }

    fn random_grid(rng: &mut Lcg, samples: Samples, outside: Outside, channels: usize) -> Grid {
        let res = [3, 4, 2];
        let values = (0..24 * channels).map(|_| rng.next() * 2.0).collect();
        let to_world = Mat4::from_translation(Vec3::new(-1.0, 0.5, 0.0))
            * Mat4::from_scale(Vec3::new(2.0, 1.5, 3.0));
        Grid::new(res, channels, values, to_world, samples, outside).unwrap()
    }

    /// `repeat` tiles space with the grid: a lookup one period (the transformed unit cube's
    /// edge) away reads the same, inside the grid it reads what `clamp` reads, and across the
    /// seam it interpolates between the last sample and the first, as drjit's repeat wrap.
    #[test]
    fn a_repeating_grid_tiles_space() {
        let mut rng = Lcg(11);
        let repeat = random_grid(&mut rng, Samples::Centres, Outside::Repeat, 3);
        let mut rng = Lcg(11);
        let clamp = random_grid(&mut rng, Samples::Centres, Outside::Clamp, 3);
        // The unit cube maps to [-1, 1] x [0.5, 2] x [0, 3]: periods 2, 1.5 and 3.
        let period = Vec3::new(2.0, 1.5, 3.0);
        for _ in 0..200 {
            let p =
                Vec3::new(-1.0, 0.5, 0.0) + period * Vec3::new(rng.next(), rng.next(), rng.next());
            let inside = repeat.lookup(p);
            for k in [-2.0, -1.0, 1.0, 3.0] {
                let q = p + Vec3::new(k * period.x, -k * period.y, 2.0 * k * period.z);
                assert!(
                    (repeat.lookup(q) - inside).abs().max_element() < 1e-4,
                    "{p} {q}"
                );
            }
            // Between the first and last sample centres of every axis, clamp reads the same.
            let u = (p - Vec3::new(-1.0, 0.5, 0.0)) / period;
            let n = Vec3::new(3.0, 4.0, 2.0);
            if (u * n).cmpge(Vec3::splat(0.5)).all() && (u * n).cmple(n - 0.5).all() {
                assert!((clamp.lookup(p) - inside).abs().max_element() < 1e-5);
            }
        }
        // On the cube's face x = -1 (lattice x = -1/2), halfway between sample 2 and sample 0.
        let (j, k) = (1usize, 1usize);
        let p = Vec3::new(
            -1.0,
            0.5 + (j as f32 + 0.5) / 4.0 * 1.5,
            (k as f32 + 0.5) / 2.0 * 3.0,
        );
        for c in 0..3 {
            let expected = 0.5 * (repeat.sample(2, j, k, c) + repeat.sample(0, j, k, c));
            assert!((repeat.lookup(p)[c] - expected).abs() < 1e-5);
        }
    }

    /// The integral by the midpoint rule over lookups, against which the exact one is checked.
    fn quadrature(g: &Grid, ray: &Ray, d: f32) -> DVec3 {
        let n = 200_000;
        let h = d as f64 / n as f64;
        (0..n)
            .map(|i| g.lookup(ray.at(((i as f64 + 0.5) * h) as f32)).as_dvec3() * h)
            .sum()
    }

    #[test]
    fn samples_lie_where_mitsuba_puts_them() {
        // Mitsuba 3: sample i at (i + 1/2) / n, clamped beyond; 0.6: at i / (n - 1), zero
        // beyond.
        let v = vec![0.0, 1.0, 2.0, 3.0];
        let g = |s, o| Grid::new([4, 1, 1], 1, v.clone(), Mat4::IDENTITY, s, o).unwrap();
        let centres = g(Samples::Centres, Outside::Clamp);
        for (x, want) in [
            (0.0, 0.0),
            (0.25, 0.5),
            (0.375, 1.0),
            (0.5, 1.5),
            (0.875, 3.0),
            (1.0, 3.0),
        ] {
            assert_eq!(centres.lookup(Vec3::new(x, 0.3, 0.9)).x, want, "x = {x}");
        }
        let corners = g(Samples::Corners, Outside::Zero);
        for (x, want) in [
            (0.0, 0.0),
            (1.0 / 3.0, 1.0),
            (0.5, 1.5),
            (-0.01, 0.0),
            (1.01, 0.0),
        ] {
            assert!(
                (corners.lookup(Vec3::new(x, 0.0, 0.0)).x - want).abs() < 1e-6,
                "x = {x}"
            );
        }
    }

    #[test]
    fn integrals_along_rays_equal_quadrature_of_lookups() {
        let mut rng = Lcg(7);
        for (samples, outside, channels) in [
            (Samples::Centres, Outside::Clamp, 1),
            (Samples::Corners, Outside::Zero, 1),
            (Samples::Centres, Outside::Zero, 1),
            (Samples::Centres, Outside::Clamp, 3),
            (Samples::Centres, Outside::ClampInBox, 1),
            (Samples::Corners, Outside::ClampInBox, 3),
        ] {
            let g = random_grid(&mut rng, samples, outside, channels);
            for _ in 0..20 {
                let o = Vec3::new(
                    rng.next() * 4.0 - 2.0,
                    rng.next() * 3.0,
                    rng.next() * 4.0 - 0.5,
                );
                let dir =
                    Vec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize();
                let ray = Ray::new(o, dir);
                let d = 0.5 + rng.next() * 5.0;
                let exact = g.integral(&ray, d);
                let q = quadrature(&g, &ray, d);
                let tolerance = 1e-4 * q.max_element().max(1.0);
                assert!(
                    (exact - q).abs().max_element() <= tolerance,
                    "{samples:?} {outside:?}: {exact} vs {q}"
                );
            }
        }
    }

    /// A sparse grid, mostly empty blocks that traversal crosses in one step: the integrals
    /// are still those of the lookups, and inversion still lands on its target.
    #[test]
    fn empty_blocks_are_crossed_without_changing_the_integral() {
        let mut rng = Lcg(5);
        let res = [19, 21, 17];
        let mut values = vec![0.0f32; 19 * 21 * 17];
        for _ in 0..12 {
            let (i, j, k) = (
                (rng.next() * 19.0) as usize,
                (rng.next() * 21.0) as usize,
                (rng.next() * 17.0) as usize,
            );
            values[(k * 21 + j) * 19 + i] = 1.0 + 4.0 * rng.next();
        }
        // The first and last samples of an axis too (the edges of the blocks' range).
        values[0] = 2.0;
        values[19 * 21 * 17 - 1] = 3.0;
        // Samples on the faces between blocks, seen from the cells on their lower side.
        let faces = [(8, 10, 8), (16, 8, 3), (3, 16, 16)];
        for (i, j, k) in faces {
            values[(k * 21 + j) * 19 + i] = 1.0;
        }
        let g = Grid::new(
            res,
            1,
            values,
            Mat4::IDENTITY,
            Samples::Corners,
            Outside::Zero,
        )
        .unwrap();
        assert!(g.empty.iter().any(|e| *e) && g.empty.iter().any(|e| !*e));
        let lattice = |x: f32, n: usize| x / (n - 1) as f32;
        for (i, j, k) in faces {
            for dir in [Vec3::X, Vec3::Y, Vec3::Z] {
                let mut o = Vec3::new(
                    lattice(i as f32 - 0.5, 19),
                    lattice(j as f32 - 0.5, 21),
                    lattice(k as f32 - 0.5, 17),
                );
                o -= dir * o.dot(dir) + dir * 0.1;
                let ray = Ray::new(o, dir);
                let (exact, q) = (g.integral(&ray, 1.2).x, quadrature(&g, &ray, 1.2).x);
                assert!(q > 0.0 && (exact - q).abs() <= 2e-3 * q, "{exact} vs {q}");
            }
        }
        for _ in 0..40 {
            let o = Vec3::new(
                rng.next() * 1.4 - 0.2,
                rng.next() * 1.4 - 0.2,
                rng.next() * 1.4 - 0.2,
            );
            let dir = Vec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize();
            let ray = Ray::new(o, dir);
            let exact = g.integral(&ray, 2.0).x;
            let q = quadrature(&g, &ray, 2.0).x;
            assert!((exact - q).abs() <= 2e-3 * q.max(0.05), "{exact} vs {q}");
            if exact > 0.0 {
                let target = exact * rng.next() as f64;
                let (t, _) = g.invert(&ray, 2.0, 0, target);
                let at = g.integral(&ray, t.unwrap() as f32).x;
                assert!(
                    (at - target).abs() <= 1e-4 * target.max(1e-3),
                    "{at} vs {target}"
                );
            }
        }
    }

    #[test]
    fn inverting_the_integral_finds_the_distance_that_reaches_the_target() {
        let mut rng = Lcg(11);
        let g = random_grid(&mut rng, Samples::Centres, Outside::ClampInBox, 3);
        for i in 0..300 {
            let channel = i % 3;
            let o = Vec3::new(
                rng.next() * 2.0 - 1.0,
                rng.next() * 1.5 + 0.5,
                rng.next() * 3.0,
            );
            let dir = Vec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize();
            let ray = Ray::new(o, dir);
            let whole = g.integral(&ray, 3.0);
            let target = rng.next() as f64 * whole[channel] * 1.2;
            let (t, depth) = g.invert(&ray, 3.0, channel, target);
            match t {
                Some(t) => {
                    assert!(target <= whole[channel] + 1e-9);
                    // Every channel's integral up to t, not only the one inverted.
                    let at = g.integral(&ray, t as f32);
                    assert!(
                        (at[channel] - target).abs() <= 1e-4 * target.max(1e-3),
                        "{at} vs {target}"
                    );
                    assert!(
                        (at - depth).abs().max_element() <= 1e-4 * at.max_element().max(1e-3),
                        "{at} vs {depth}"
                    );
                }
                None => assert!(
                    target > whole[channel] * (1.0 - 1e-9)
                        && (depth - whole).abs().max_element() < 1e-9
                ),
            }
        }
    }

    #[test]
    fn an_infinite_segment_through_a_clamped_grid_is_opaque_and_through_a_zero_one_is_not() {
        let v = vec![1.0; 8];
        let ray = Ray::new(Vec3::splat(0.5), Vec3::X);
        let clamp = Grid::new(
            [2; 3],
            1,
            v.clone(),
            Mat4::IDENTITY,
            Samples::Centres,
            Outside::Clamp,
        );
        assert_eq!(
            clamp.unwrap().integral(&ray, f32::INFINITY).x,
            f64::INFINITY
        );
        let zero = Grid::new(
            [2; 3],
            1,
            v,
            Mat4::IDENTITY,
            Samples::Corners,
            Outside::Zero,
        )
        .unwrap();
        assert!((zero.integral(&ray, f32::INFINITY).x - 0.5).abs() < 1e-9);
    }

    #[test]
    fn vol_files_are_read_as_mitsuba_writes_them() {
        let mut bytes = b"VOL\x03".to_vec();
        for i in [1i32, 2, 1, 1, 3] {
            bytes.extend(i.to_le_bytes());
        }
        for f in [
            0.0f32, 0.0, 0.0, 1.0, 2.0, 3.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6,
        ] {
            bytes.extend(f.to_le_bytes());
        }
        let f = VolFile::parse(&bytes).unwrap();
        assert_eq!((f.res, f.channels), ([2, 1, 1], 3));
        assert_eq!(f.bbox, (Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)));
        assert_eq!(f.values, [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
        let short = VolFile::parse(&bytes[..bytes.len() - 1]).unwrap_err();
        assert!(short.contains("need 24 bytes"), "{short}");
        bytes[3] = 2;
        assert!(VolFile::parse(&bytes).unwrap_err().contains("version 2"));
        assert!(VolFile::parse(b"PLY").unwrap_err().contains("VOL"));
    }
}
