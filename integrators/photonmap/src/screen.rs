//! Photon beams binned in screen space for the camera's primary rays (Jarosz, Nowrouzezahrai,
//! Thomas, Sloan and Zwicker 2011 splat the beams of their progressive passes onto the
//! image on the GPU; here the bins only choose the candidates of the same beam x beam test).
//!
//! **Why.** Through the beams' BVH a camera segment crosses about sixteen pieces' boxes for
//! each beam it accepts (a box around a thin diagonal piece is mostly empty), and the
//! traversal is two thirds of the gather. Every pixel's first camera segments lie on rays
//! from one point, the pinhole: seen from it, a piece is a thin quadrilateral on the image,
//! and only the pixels under it can accept it.
//!
//! **What a pass builds.** A camera ray from the pinhole accepts a piece only if some point
//! of the ray lies within r of the piece's segment: within the capsule of radius r around it,
//! hence within the hull of two cubes of half-size rho >= r around its ends (cubes with
//! faces parallel to the image plane). Projection maps that hull (in front of the camera) to
//! the hull of the cubes' projected corners, within the hull of the two rectangles R_0, R_1
//! bounding the projected corners of each cube: the union over s in [0, 1] of the
//! rectangles interpolated between them. For each band of image rows (one row; several in
//! tall images, [`ROWS`]) the rectangles of the s whose y-range meets the band form an
//! interval of s, and the band's x-range is read at its ends (the rectangles' sides are
//! linear in s). Each piece goes into the bins (a band and a chunk of [`CHUNK`] bands' width)
//! its x-ranges touch, with its range, in piece order.
//!
//! **The query.** A camera segment through the film point (x, y) takes the bin of (x, y) and
//! runs the map's own test (`BeamMap::cross`) on the pieces whose range holds x: the same
//! test on a superset of what it accepts, so the accepted crossings are the BVH's and the
//! estimate differs only in the order of its sum (piece order here: the same for any number
//! of threads). The bins hold the pixels a sample with a filter reaching past its pixel can
//! land in too: rows and chunks at the image's edges take every range beyond it.
//!
//! **What keeps the BVH.** Segments after a scattering event (the caller decides) and those
//! whose line is farther than [`ScreenBeams::reach`] from the pinhole (the walk offsets a
//! ray's origin at each null boundary it crosses: the cubes are grown by that much), and
//! samples outside the image's margin, are traversed through the BVH as before. Pieces whose
//! cubes reach the plane of the pinhole (or too near it to project safely) are in a second,
//! small BVH that the screen's query traverses too; pieces wholly behind the camera are left
//! out (no point of a camera ray is near them).

use crate::beams::{BeamMap, Crossing, Gather, Kernel1d};
use crate::twolevel::TwoLevelBvh;
use foton_core::api::{Camera, Ray, Rgb, Scene, Vec2, Vec3};
use rayon::prelude::*;

/// Bins are this many rows' bands wide (a band is one row up to 511 rows, [`ROWS`] more
/// rows a band above). Narrower bins mean fewer pieces scanned and more entries built: 4, 8
/// and 16 pixels took 3.196, 3.178 and 3.190 G instructions for one pass of the volumetric
/// caustic at 256 x 256, the same CPU time within the noise.
pub const CHUNK: u32 = 8;

/// Images this many rows or more tall bin a band of several rows together (and chunks as
/// many times wider): the bins then hold about as many entries as at this height, whatever
/// the image's size (a piece is in every band its footprint crosses: at 1024 rows, one row a
/// band held 130 MB of entries a pass), and a bin as many pieces.
pub const ROWS: u32 = 256;

/// Pieces binned together on one thread before the bins take them (a fixed number, so the
/// bins' order does not depend on the threads).
const PIECES_A_RUN: usize = 4096;

/// Film-space margin (pixels) added to each range against the rounding of the projection
/// and of the camera's rays (whose film positions round-trip to about 1e-4 pixel).
const FILM_EPS: f32 = 0.02;

/// One piece's x-range in a bin.
#[derive(Clone, Copy, Debug)]
struct Span {
    piece: u32,
    x0: f32,
    x1: f32,
}

/// The pieces of one pass's beams binned by the pixels whose primary rays may accept them.
pub struct ScreenBeams {
    position: Vec3,
    width: u32,
    height: u32,
    /// Rows a band, and the bins' width in pixels.
    band: u32,
    chunk: f32,
    bands: u32,
    chunks: u32,
    /// Band-major: band k, chunk c at k * chunks + c.
    bins: Vec<Vec<Span>>,
    /// Pieces too near the pinhole's plane to project, in a BVH of their own.
    near: Option<TwoLevelBvh>,
    /// The farthest a segment's line may pass from the pinhole and still use the bins.
    reach: f32,
    /// Whether the camera is a pinhole: the bins hold rays from a point only (a lens's or an
    /// orthographic camera's rays go through the BVH).
    pinhole: bool,
    /// How far past the image film positions may lie and still use the bins (pixels).
    margin: f32,
}

impl ScreenBeams {
    /// Bins the pieces of `map` for the primary rays of `camera`, whose film positions lie
    /// within `margin` pixels of the image (the filter's reach: `FilterSampler::margin`).
    pub fn build(map: &BeamMap, camera: &Camera, margin: f32) -> ScreenBeams {
        let (width, height) = camera.resolution();
        let band = (height / ROWS).max(1);
        let bands = height.div_ceil(band).max(1);
        let chunks = width.div_ceil(CHUNK * band).max(1);
        let r = map.radius();
        // Segments offset from the pinhole's line by up to this much use the bins (a fiftieth
        // of the width: a null boundary's offset, seen along a camera ray, is far less).
        let reach = 0.02 * r;
        let margin = margin.max(0.0) + 1.0;
        let mut screen = ScreenBeams {
            position: camera.position,
            width,
            height,
            band,
            chunk: (CHUNK * band) as f32,
            bands,
            chunks,
            bins: vec![Vec::new(); (bands * chunks) as usize],
            near: None,
            reach,
            margin,
            pinhole: camera.lens().0 == 0.0 && !camera.is_orthographic(),
        };
        let pinhole = Pinhole::of(camera);
        // Pieces in fixed runs (the same for any number of threads), each binned on its own;
        // the bins then take each run's entries in run order: piece order, as one loop.
        // Per run: its (bin, span) entries sorted by bin, and its pieces near the pinhole.
        type Run = (Vec<(u32, Span)>, Vec<(Vec3, Vec3, u32)>);
        let runs: Vec<Run> = map
            .pieces
            .par_chunks(PIECES_A_RUN)
            .enumerate()
            .map(|(run, pieces)| {
                let (mut entries, mut near) = (Vec::new(), Vec::new());
                for (i, piece) in pieces.iter().enumerate() {
                    let id = (run * PIECES_A_RUN + i) as u32;
                    let (p0, p1) = (piece.start(), piece.end());
                    let scale =
                        p0.abs().max(p1.abs()).max_element() + camera.position.abs().max_element();
                    // The cubes' half-size: the width, what the segments' lines may be
                    // offset, and margins against rounding (as the BVH's boxes have).
                    let rho = r * 1.001 + reach + 16.0 * f32::EPSILON * scale;
                    let (c0, c1) = (pinhole.to_camera(p0), pinhole.to_camera(p1));
                    if c0.z.max(c1.z) + rho < 0.0 {
                        continue; // behind the camera: no camera ray comes near it
                    }
                    if c0.z.min(c1.z) - rho <= 1e-3 * r.max(1e-6 * scale) {
                        near.push(piece.bounds(r, id));
                        continue;
                    }
                    screen.spans(
                        id,
                        pinhole.cube(c0, rho),
                        pinhole.cube(c1, rho),
                        |bin, span| entries.push((bin as u32, span)),
                    );
                }
                // Stable: within a bin, piece order.
                entries.sort_by_key(|&(bin, _)| bin);
                (entries, near)
            })
            .collect();
        let starts: Vec<Vec<usize>> = runs
            .par_iter()
            .map(|(entries, _)| {
                (0..=screen.bins.len())
                    .map(|bin| entries.partition_point(|&(b, _)| (b as usize) < bin))
                    .collect()
            })
            .collect();
        screen
            .bins
            .par_iter_mut()
            .enumerate()
            .for_each(|(bin, spans)| {
                for ((entries, _), start) in runs.iter().zip(&starts) {
                    spans.extend(entries[start[bin]..start[bin + 1]].iter().map(|&(_, s)| s));
                }
            });
        let near: Vec<(Vec3, Vec3, u32)> = runs.into_iter().flat_map(|(_, near)| near).collect();
        if !near.is_empty() {
            screen.near = Some(TwoLevelBvh::build(near));
        }
        screen
    }

    /// Calls `add(bin, span)` for each bin piece `id`'s rows' x-ranges touch: `a` and `b`
    /// are the rectangles (x_lo, y_lo, x_hi, y_hi) around its two ends' cubes.
    fn spans(&self, id: u32, a: [f32; 4], b: [f32; 4], mut add: impl FnMut(usize, Span)) {
        let (w, h, m) = (self.width as f32, self.height as f32, self.margin);
        let (y_lo, y_hi) = (a[1].min(b[1]) - FILM_EPS, a[3].max(b[3]) + FILM_EPS);
        if y_hi < -m || y_lo > h + m || a[2].max(b[2]) < -m || a[0].min(b[0]) > w + m {
            return;
        }
        let last = self.bands as i64 - 1;
        for k in self.band_of(y_lo)..=self.band_of(y_hi) {
            // The band's rows; the edge bands take what lies beyond the image.
            let band_lo = if k == 0 {
                f32::NEG_INFINITY
            } else {
                (k as u32 * self.band) as f32
            } - FILM_EPS;
            let band_hi = if k as i64 == last {
                f32::INFINITY
            } else {
                ((k as u32 + 1) * self.band) as f32
            } + FILM_EPS;
            // The s for which the interpolated rectangle's y-range meets the band: y_lo(s) <=
            // band_hi and y_hi(s) >= band_lo, each an interval of s.
            let (s0, s1) = at_most(a[1], b[1], band_hi);
            let (t0, t1) = at_most(-a[3], -b[3], -band_lo);
            // Widened a little against the rounding of the division (a wider interval only
            // widens the x-range).
            let (s0, s1) = ((s0.max(t0) - 1e-4).max(0.0), (s1.min(t1) + 1e-4).min(1.0));
            if s0 > s1 {
                continue;
            }
            let lerp = |u: f32, v: f32, s: f32| u + (v - u) * s;
            let x0 = lerp(a[0], b[0], s0).min(lerp(a[0], b[0], s1)) - FILM_EPS;
            let x1 = lerp(a[2], b[2], s0).max(lerp(a[2], b[2], s1)) + FILM_EPS;
            if x1 < -m || x0 > w + m {
                continue;
            }
            let (c0, c1) = (self.chunk_of(x0), self.chunk_of(x1));
            let bins = k * self.chunks as usize;
            for chunk in c0..=c1 {
                add(bins + chunk, Span { piece: id, x0, x1 });
            }
        }
    }

    #[inline]
    fn chunk_of(&self, x: f32) -> usize {
        ((x / self.chunk).floor() as i64).clamp(0, self.chunks as i64 - 1) as usize
    }

    #[inline]
    fn band_of(&self, y: f32) -> usize {
        ((y / self.band as f32).floor() as i64).clamp(0, self.bands as i64 - 1) as usize
    }

    /// The farthest a camera segment's line may pass from the pinhole and still use the bins.
    pub fn reach(&self) -> f32 {
        self.reach
    }

    /// Pieces binned, counted once per bin (for measurements).
    pub fn entries(&self) -> usize {
        self.bins.iter().map(Vec::len).sum()
    }

    /// Whether the bins answer for a camera segment on `ray`, the primary ray through the
    /// film point `film`: false if its line is too far from the pinhole, or `film` outside
    /// the image's margin.
    fn answers(&self, film: Vec2, ray: &Ray) -> bool {
        let off = (ray.origin - self.position).cross(ray.dir);
        let (w, h, m) = (self.width as f32, self.height as f32, self.margin);
        self.pinhole
            && off.length_squared() <= self.reach * self.reach
            && film.x >= -m
            && film.y >= -m
            && film.x <= w + m
            && film.y <= h + m
    }

    /// Calls `visit(piece, crossing)` for every piece of `map` (the map the bins were built
    /// from) that `BeamMap::cross` accepts on the camera segment `ray` (0 to `t_end`, medium
    /// `medium`), a segment on the primary ray through the film point `film` that the bins
    /// answer for ([`ScreenBeams::answers`]).
    fn along(
        &self,
        map: &BeamMap,
        film: Vec2,
        ray: &Ray,
        t_end: f32,
        medium: u32,
        visit: &mut impl FnMut(u32, &Crossing),
    ) {
        let bin = &self.bins[self.band_of(film.y) * self.chunks as usize + self.chunk_of(film.x)];
        for span in bin {
            if span.x0 <= film.x
                && film.x <= span.x1
                && let Some(c) = map.cross(span.piece, ray, t_end, medium)
            {
                visit(span.piece, &c);
            }
        }
        if let Some(near) = &self.near {
            map.traverse(near, ray, t_end, medium, visit);
        }
    }
}

// The estimate with the screen's candidates is the map's, but lives here, beside the bins:
// the map (beams.rs) knows nothing of the screen built from it.
impl BeamMap {
    /// [`BeamMap::in_scattered`] along a camera segment on the primary ray through the film
    /// point `film` (a segment of the camera path before any scattering: from the pinhole, or
    /// past null boundaries on the same line), with the candidate pieces from the pass's
    /// screen bins `screen` where they apply ([`ScreenBeams::answers`]); the same
    /// estimate, summed in piece order.
    #[allow(clippy::too_many_arguments)]
    pub fn in_scattered_primary(
        &self,
        scene: &Scene,
        kernel: &Kernel1d<'_>,
        screen: &ScreenBeams,
        film: Vec2,
        ray: &Ray,
        t_end: f32,
        medium: u32,
        depth: u32,
    ) -> Rgb {
        if !screen.answers(film, ray) {
            return self.in_scattered(scene, kernel, ray, t_end, medium, depth);
        }
        let gather = Gather::new(self, scene, kernel, ray, medium, depth);
        let mut sum = Rgb::ZERO;
        let mut add = |id, c: &Crossing| gather.add(&mut sum, id, c);
        screen.along(self, film, ray, t_end, medium, &mut add);
        sum
    }
}

/// The s in [0, 1] for which u + (v - u) s <= bound, as an interval (empty: s0 > s1).
#[inline]
fn at_most(u: f32, v: f32, bound: f32) -> (f32, f32) {
    let d = v - u;
    if d == 0.0 {
        return if u <= bound { (0.0, 1.0) } else { (1.0, 0.0) };
    }
    let s = (bound - u) / d;
    if d > 0.0 { (0.0, s) } else { (s, 1.0) }
}

/// The camera's projection, as the bins use it: film = centre + f (X / Z, -Y / Z) in the
/// camera's frame (X along the image's x axis, Y up, Z the optical axis), read off the
/// camera's own rays (to about 1e-7 relative: the bins' margins cover it).
struct Pinhole {
    position: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    centre: Vec2,
    /// The focal length in pixels.
    focal: f32,
}

impl Pinhole {
    fn of(camera: &Camera) -> Pinhole {
        let (width, height) = camera.resolution();
        let forward = camera.forward();
        let centre = Vec2::new(width as f32 * 0.5, height as f32 * 0.5);
        let towards_x = camera.generate_ray(centre + Vec2::new(1.0, 0.0)).dir;
        let right = (towards_x - forward * towards_x.dot(forward)).normalize();
        let up = right.cross(forward).normalize();
        // The ray through the top edge's middle leaves at tan(fov / 2) above the axis.
        let top = camera.generate_ray(Vec2::new(centre.x, 0.0)).dir;
        let tan_half = top.dot(up) / top.dot(forward);
        Pinhole {
            position: camera.position,
            right,
            up,
            forward,
            centre,
            focal: height as f32 * 0.5 / tan_half,
        }
    }

    #[inline]
    fn to_camera(&self, p: Vec3) -> Vec3 {
        let d = p - self.position;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    /// The film-space rectangle (x_lo, y_lo, x_hi, y_hi) around the projection of the cube
    /// of half-size `rho` centred at `c` (camera frame, c.z - rho > 0) with faces along the
    /// camera's axes: each extreme at a corner, the nearer or the farther face's as the sign
    /// of the coordinate says. Widened by the margin against rounding (FILM_EPS, and 1e-5 of
    /// the coordinates' size for the far-off ones).
    #[inline]
    fn cube(&self, c: Vec3, rho: f32) -> [f32; 4] {
        let (near, far) = (c.z - rho, c.z + rho);
        let lo = |v: f32| v / if v < 0.0 { near } else { far };
        let hi = |v: f32| v / if v > 0.0 { near } else { far };
        let f = self.focal;
        let rect = [
            self.centre.x + f * lo(c.x - rho),
            self.centre.y - f * hi(c.y + rho),
            self.centre.x + f * hi(c.x + rho),
            self.centre.y - f * lo(c.y - rho),
        ];
        let size = rect.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        let eps = FILM_EPS + 1e-5 * size;
        [rect[0] - eps, rect[1] - eps, rect[2] + eps, rect[3] + eps]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::beams::Beam;
    use foton_core::api::Rng;

    /// Random beams in front of a camera, some through the pinhole's plane and behind it, two
    /// media.
    pub(crate) fn random_beams(rng: &mut Rng, camera: &Camera, n: usize) -> Vec<Beam> {
        let point = |rng: &mut Rng, c: Vec3, s: f32| {
            c + (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * s
        };
        (0..n)
            .map(|i| {
                let (a, b) = if i % 10 == 9 {
                    // Around the camera: crossing its plane, near it, or behind it.
                    (
                        point(rng, camera.position, 1.5),
                        point(rng, camera.position, 1.5),
                    )
                } else if i % 10 == 8 {
                    // Along the image's x or y axis, where a footprint's x-range is tightest.
                    let a = point(rng, Vec3::ZERO, 2.0);
                    let f = camera.forward();
                    let towards_x = camera.generate_ray(Vec2::new(1.0, 0.0)).dir;
                    let right = (towards_x - f * towards_x.dot(f)).normalize();
                    let axis = if i % 20 == 8 { right } else { f.cross(right) };
                    (a, a + axis * (0.5 + 2.0 * rng.next_f32()))
                } else {
                    (point(rng, Vec3::ZERO, 2.0), point(rng, Vec3::ZERO, 2.0))
                };
                Beam::unit_test(a, b, (i % 7 == 6) as u32)
            })
            .collect()
    }

    /// The screen's bins accept exactly the crossings the BVH accepts on camera segments from
    /// the pinhole or past null boundaries on the same line (offset from it by up to the
    /// reach), through film points inside the image and in its margin, for two widths; and
    /// they decline segments they cannot answer for (farther off the line, or outside the
    /// margin) without visiting anything.
    #[test]
    fn the_bins_accept_what_the_bvh_accepts() {
        let mut rng = Rng::new(&[17]);
        let (mut accepted, mut declined, mut near) = (0, 0, 0);
        // One row a band, and four (a tall image: ROWS).
        for (r, (w, h)) in [
            (0.05f32, (640, 480)),
            (0.012, (640, 480)),
            (0.03, (320, 1100)),
        ] {
            let camera = Camera::new(
                Vec3::new(0.4, 0.3, 6.0),
                Vec3::new(0.0, -0.2, 0.0),
                Vec3::Y,
                45.0,
                w,
                h,
            );
            let (w, h) = (w as f32, h as f32);
            let beams = random_beams(&mut rng, &camera, 700);
            let map = BeamMap::build(beams, r);
            let screen = ScreenBeams::build(&map, &camera, 0.5);
            let bvh = map_bvh(&map);
            near += screen.near.is_some() as u32;
            for i in 0..3000 {
                let mut film = Vec2::new(
                    rng.next_f32() * (w + 4.0) - 2.0,
                    rng.next_f32() * (h + 4.0) - 2.0,
                );
                if i % 2 == 1 {
                    // Through a point 0.999 r from a random piece, across the piece as the
                    // image sees it (the edge of its footprint), near its ends too.
                    let piece = &map.pieces[(rng.next_f32() * map.pieces.len() as f32) as usize];
                    let u = [0.0, 1.0, rng.next_f32()][i % 3];
                    let x_b = piece.origin + piece.dir * (piece.t0 + (piece.t1 - piece.t0) * u);
                    let across = piece.dir.cross(x_b - camera.position).normalize_or_zero();
                    let sign = if rng.next_f32() < 0.5 { -1.0 } else { 1.0 };
                    if let Some(f) = camera.project_within(x_b + across * (sign * 0.999 * r), 1.5) {
                        film = f;
                    }
                }
                let primary = camera.generate_ray(film);
                // A start on the line (or off it by up to the reach, as past a null
                // boundary; a tenth of the segments by more, which the bins decline).
                let along = if i % 3 == 0 {
                    0.0
                } else {
                    rng.next_f32() * 7.0
                };
                let side = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
                let side = (side - primary.dir * side.dot(primary.dir)).normalize_or_zero();
                let off = if i % 10 == 0 {
                    3.0
                } else {
                    0.99 * rng.next_f32()
                };
                let ray = Ray::new(
                    primary.at(along) + side * (off * screen.reach()),
                    primary.dir,
                );
                let t_end = 0.5 + rng.next_f32() * 12.0;
                let medium = (i % 5 == 4) as u32;
                let mut want = Vec::new();
                map.traverse(&bvh, &ray, t_end, medium, &mut |id, c| {
                    want.push((id, c.t_c.to_bits()))
                });
                let mut got = Vec::new();
                let answered = screen.answers(film, &ray);
                if answered {
                    screen.along(&map, film, &ray, t_end, medium, &mut |id, c| {
                        got.push((id, c.t_c.to_bits()))
                    });
                }
                let inside =
                    film.x >= -1.5 && film.y >= -1.5 && film.x <= w + 1.5 && film.y <= h + 1.5;
                if off <= 1.0 && inside {
                    assert!(answered, "film {film}, offset {off}");
                }
                if !answered {
                    assert!(got.is_empty());
                    declined += 1;
                    continue;
                }
                want.sort();
                got.sort();
                assert_eq!(got, want, "film {film}, r {r}, start {along}, offset {off}");
                accepted += got.len();
            }
        }
        eprintln!("{accepted} crossings, {declined} segments declined");
        assert!(accepted > 2000, "too few crossings to compare: {accepted}");
        assert!(declined > 300, "{declined}");
        assert!(near > 0, "no piece near the camera's plane");
    }

    /// The map's own BVH (private to the map: rebuilt here from its pieces).
    fn map_bvh(map: &BeamMap) -> TwoLevelBvh {
        TwoLevelBvh::build(
            map.pieces
                .iter()
                .enumerate()
                .map(|(id, p)| p.bounds(map.radius(), id as u32))
                .collect(),
        )
    }
}
