//! # `vcm`: vertex connection and merging (Georgiev, Křivánek, Davidovič and Slusallek 2012)
//!
//! This table is the one list of the parameters (`[integrators.vcm]`); the README and the
//! scene-format page point here.
//!
//! | parameter    | type    | meaning                                                          | default |
//! |--------------|---------|------------------------------------------------------------------|---------|
//! | `iterations` | integer | light + camera passes to run, >= 1                               | 64 (unlimited with `time`) |
//! | `time`       | float   | run until this many seconds have passed, > 0                     | none    |
//! | `radius`     | float   | the first iteration's merge radius r_1 (world units), > 0        | 0.003 x the radius of the scene's bounding sphere (SmallVCM's) |
//! | `alpha`      | float   | the radius schedule's exponent, r_i = r_1 i^((alpha - 1) / 2), in (0, 1] | 0.75 |
//! | `mode`       | string  | `vcm` (connections and merges), `bpt` (connections only: `bdpt`'s estimator), `ppm` (merges only, SmallVCM's progressive photon mapping), `lt` (light tracing alone) | `vcm` |
//! | `rr_depth`   | integer | scattering events of a subpath before Russian roulette may end it | 5      |
//!
//! `[render] max_depth` bounds the scattering events of a whole path, as `bdpt`'s and the path
//! tracer's do; `[render] spp` is not used (each iteration takes one camera sample per pixel).
//! With `time`, `iterations` (if given) is an upper bound. For `foton compare --time` the work
//! is counted in iterations (`integrators.vcm.iterations`).
//!
//! **An iteration** (SmallVCM's `VertexCM::RunIteration`): one light subpath per pixel (N = W x H
//! of them) is traced and its connectable vertices (not on delta surfaces) are kept in a hashed
//! grid (module `grid`); then every pixel traces a camera subpath which, at each vertex,
//!
//! * connects as `bdpt` does with the pixel's own light subpath (foton-bidir: s = 0 emitters
//!   reached, s = 1 next-event estimation, s, t >= 2 vertex connections, and t = 1, the light
//!   subpath's vertices connected to the camera and splatted onto the film);
//! * merges with every light vertex of the iteration within the radius r_i: the density
//!   estimate L = beta_camera sum_v K(|x - x_v|) f(w_o, w_v) beta_v / N, with the
//!   Epanechnikov kernel K(d) = 2 / (pi r^2) (1 - d^2 / r^2) (integrates to one over the disc);
//!   a light vertex counts if its surface is the camera vertex's (geometric normals within
//!   about 25 degrees, no farther from the tangent plane than r / 4, as `sppm`'s gather disc).
//!
//! Connections and merges are weighted together by the power heuristic (tech. rep. eqs. 37-39)
//! with the running quantities d_vcm, d_vc, d_vm (foton-bidir's `mis`): a merge counts as a
//! strategy whose density is a connection's times the acceptance probability pi r^2 p, with N
//! light paths merged against one connected. So each kind of path is rendered by what samples
//! it best: diffuse interreflection by connections (as `bdpt`), caustics seen directly or
//! through glass (S D S paths, which no connection samples) by merges (as photon mapping).
//! The radius shrinks as r_i = r_1 i^((alpha - 1)/2): the merges' bias vanishes while their
//! variance stays bounded; the image converges to the path tracer's.
//!
//! **Modes** (SmallVCM's): `bpt` keeps only connections (the estimator of `bdpt`, with one
//! light path per camera sample); `ppm` keeps only merges: the camera subpath passes through
//! delta vertices to its first connectable one and merges there, unweighted, and emitters count
//! only when seen directly or through delta vertices (direct light comes from merging too).
//! As SmallVCM's, it cannot split a material with both a delta and a non-delta part (the
//! smooth coat of `plastic`): the camera path stops at such a surface and merges with its
//! non-delta part alone, leaving out what the coat reflects; `vcm` mode renders it all;
//! `lt` splats the light subpaths' vertices alone (`bdpt`'s `strategy = "light"`).
//!
//! **Determinism and parts.** Iteration i's light subpath of pixel p and its camera sample
//! draw from random streams keyed by (seed, p, i) alone, the grid is filled in pixel order and
//! each pixel sums its merges in a fixed order, and pixel and splat sums are exact fixed-point
//! sums: the image is bit-identical for any thread count. The radius depends on the iteration's
//! number alone, so iterations are independent: `--part I/N` renders a share of them (a number
//! of iterations, no `time`) and `foton merge` adds the parts exactly. Ctrl-C drops the
//! iteration under way: the image holds whole iterations. The loop around the iterations
//! (`iterations` or `time`, the part's share, Ctrl-C, checkpoints, progress) is
//! foton-photonmap's `progressive::run_passes`, as `sppm`'s and `ppb`'s; the summary line
//! counts each iteration's W x H light subpaths as its photons.
//!
//! `hide_emitters` as `bdpt` (camera rays pass through emitters until they first scatter, and
//! so do light vertices' connections to the camera). **Not supported**, refused with an error:
//! participating media (`bdpt` and `vpm` render them).
//!
//! `foton render --techniques` keeps the estimator's four techniques apart as layers of the
//! film (docs/tools.md), summing to the image: `connection` (s >= 1, t >= 2), `merging`,
//! `emission` (s = 0) and `light_tracing` (t = 1, the splats), each MIS-weighted.

pub mod grid;

use foton_bidir::mis::{Factors, weight_merge};
use foton_bidir::{At, Bidir, Origin, SplatSink, Strategy, Vertex};
use foton_core::api::{
    Budget, Error, Film, Integrator, Parameter, PixelSample, Properties, RadianceSum,
    RenderContext, Result, Rgb, Sampler, Scene, usable, with_pool,
};
use foton_photonmap::progressive::{PassBudget, Passes, Tally, read_passes, run_passes};
use grid::HashGrid;
use rayon::prelude::*;

/// Which estimators an iteration uses (`mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Connections and merges, weighted together.
    Vcm,
    /// Connections only: bidirectional path tracing.
    Bpt,
    /// Merges only, at the camera path's first connectable vertex: progressive photon mapping.
    Ppm,
    /// Light vertices connected to the camera only: light tracing.
    Lt,
}

impl Mode {
    pub const NAMES: [&'static str; 4] = ["vcm", "bpt", "ppm", "lt"];

    pub fn name(self) -> &'static str {
        match self {
            Mode::Vcm => "vcm",
            Mode::Bpt => "bpt",
            Mode::Ppm => "ppm",
            Mode::Lt => "lt",
        }
    }

    fn connects(self) -> bool {
        matches!(self, Mode::Vcm | Mode::Bpt | Mode::Lt)
    }

    fn merges(self) -> bool {
        matches!(self, Mode::Vcm | Mode::Ppm)
    }
}

pub struct Vcm {
    /// `iterations` and `time`; a pass traces one light subpath per pixel (the summary counts
    /// them as its photons).
    pub passes: PassBudget,
    /// r_1, world units.
    pub radius: f32,
    /// Whether `radius` was given (else it is the automatic one, reported as such).
    pub radius_given: bool,
    pub alpha: f32,
    pub mode: Mode,
    pub max_depth: u32,
    pub rr_depth: u32,
}

/// Random streams of the two passes (keys beside the seed, pixel and iteration).
const STREAM_LIGHT: u64 = 0x7663_6d6c;
const STREAM_CAMERA: u64 = 0x7663_6d63;

/// How far from the camera vertex's tangent plane a light vertex may lie and still be merged,
/// in units of the radius (`sppm`'s disc, foton-photonmap's `DISC_THICKNESS`).
const DISC_THICKNESS: f32 = 0.25;

/// The Epanechnikov kernel on the disc of radius r (squared: `r2`), normalised to integrate
/// to one over it: K(d) = 2 / (pi r^2) (1 - d^2 / r^2).
#[inline]
pub fn epanechnikov(d2: f32, r2: f32) -> f32 {
    if d2 >= r2 {
        return 0.0;
    }
    2.0 * std::f32::consts::FRAC_1_PI / r2 * (1.0 - d2 / r2)
}

/// The merge radius of iteration `iteration` (1-based): r_1 i^((alpha - 1) / 2) (SmallVCM's
/// schedule, tech. rep. section 5.3).
pub fn radius_of(r1: f32, alpha: f32, iteration: u64) -> f32 {
    let r = r1 as f64 * (iteration as f64).powf((alpha as f64 - 1.0) / 2.0);
    (r as f32).max(1e-7)
}

/// One iteration's light subpaths: their vertices in pixel order, where each pixel's end, and
/// each pixel's origin on an area light.
#[derive(Default)]
struct LightPaths {
    vertices: Vec<Vertex>,
    ends: Vec<u32>,
    origins: Vec<Option<Origin>>,
}

impl LightPaths {
    fn clear(&mut self) {
        self.vertices.clear();
        self.ends.clear();
        self.origins.clear();
    }

    fn of(&self, pixel: usize) -> &[Vertex] {
        let start = if pixel == 0 { 0 } else { self.ends[pixel - 1] };
        &self.vertices[start as usize..self.ends[pixel] as usize]
    }
}

/// Splats of one row of pixels, as exact sums per pixel index, listed by the band of
/// `band_rows` image rows they land in (so that each band of the film takes its own lists).
struct RowSplats {
    bands: Vec<Vec<(u32, RadianceSum)>>,
    band_rows: u32,
    width: u32,
    /// Splats dropped: not finite, or negative.
    bad: u64,
}

impl RowSplats {
    /// Empty, for a film of `height` rows in bands of `band_rows`.
    fn reset(&mut self, height: u32, band_rows: u32) {
        self.band_rows = band_rows;
        self.bands
            .resize_with(height.div_ceil(band_rows) as usize, Vec::new);
        self.bands.iter_mut().for_each(Vec::clear);
        self.bad = 0;
    }
}

impl SplatSink for RowSplats {
    #[inline]
    fn add(&mut self, x: u32, y: u32, value: Rgb, weight: f32) {
        if !usable(value) {
            self.bad += 1;
            return;
        }
        if value == Rgb::ZERO {
            return;
        }
        let mut s = RadianceSum::ZERO;
        s.add(value * weight);
        self.bands[(y / self.band_rows) as usize].push((y * self.width + x, s));
    }
}

/// The layers of `foton render --techniques`, in the order of [`Integrator::techniques`]:
/// the first three are a camera sample's shares, the last the splats.
const TECHNIQUES: [&str; 4] = ["connection", "merging", "emission", "light_tracing"];
const CONNECTION: usize = 0;
const MERGING: usize = 1;
const EMISSION: usize = 2;
const LIGHT_TRACING: usize = 3;

/// What one row of the camera pass gives back.
struct Row {
    sums: Vec<RadianceSum>,
    /// With `--techniques`: per pixel, the sums of its connections, merges and emission
    /// (`CONNECTION`, `MERGING`, `EMISSION`); empty otherwise.
    layer_sums: Vec<[RadianceSum; 3]>,
    splats: RowSplats,
    rays: u64,
    bad: u64,
    /// The camera subpath's vertices (scratch, kept for the next pixel and iteration).
    camera: Vec<Vertex>,
}

impl Vcm {
    /// The estimator of iteration `iteration` (1-based): its radius and weights.
    fn estimator(&self, scene: &Scene, iteration: u64) -> (Bidir, f32) {
        let radius = radius_of(self.radius, self.alpha, iteration);
        let light_paths = (scene.film().width as f32) * (scene.film().height as f32);
        let mut bidir = Bidir::new(self.max_depth, self.rr_depth, Strategy::All, true);
        bidir.factors = Factors::vcm(
            radius,
            light_paths,
            self.mode.connects(),
            self.mode.merges(),
        );
        if self.mode == Mode::Bpt || self.mode == Mode::Lt {
            bidir.factors = Factors::CONNECT;
        }
        if self.mode == Mode::Lt {
            bidir.strategy = Strategy::Light;
        }
        bidir.connect = self.mode.connects();
        bidir.first_vertex_only = self.mode == Mode::Ppm;
        (bidir, radius)
    }

    fn sampler(&self, scene: &Scene, stream: u64, pixel: u64, iteration: u64) -> Sampler {
        let seed = scene.render().seed;
        // The structured samplers' patterns are keyed by the seed: the two passes get their own.
        Sampler::with_keys(
            scene.render().sampler,
            &[seed, stream, pixel, iteration],
            seed ^ stream,
            pixel,
            iteration as u32,
            self.passes.iterations.unwrap_or(1) as u32,
        )
    }

    /// Traces one light subpath per pixel into `paths`, each row first into its own of
    /// `rows` (both kept from one iteration to the next: no allocation once they are large
    /// enough); returns the rays cast.
    fn light_pass(
        &self,
        scene: &Scene,
        bidir: &Bidir,
        media: &[Option<u32>],
        iteration: u64,
        rows: &mut Vec<LightPaths>,
        paths: &mut LightPaths,
    ) -> u64 {
        let (width, height) = (scene.film().width, scene.film().height);
        rows.resize_with(height as usize, LightPaths::default);
        // Each row's paths (its ends counted from the row's first vertex), then joined in row
        // order: the same vertices in the same order whatever the thread count.
        let rays = rows
            .par_iter_mut()
            .enumerate()
            .map(|(y, row)| {
                row.clear();
                let mut rays = 0u64;
                for x in 0..width {
                    let pixel = y as u64 * width as u64 + x as u64;
                    let mut sampler = self.sampler(scene, STREAM_LIGHT, pixel, iteration);
                    let origin = bidir.light_subpath(
                        scene,
                        media,
                        &mut sampler,
                        &mut row.vertices,
                        &mut rays,
                    );
                    row.origins.push(origin);
                    row.ends.push(row.vertices.len() as u32);
                }
                rays
            })
            .sum();
        paths.clear();
        let mut base = 0u32;
        for row in rows.iter() {
            paths.ends.extend(row.ends.iter().map(|e| e + base));
            paths.origins.extend_from_slice(&row.origins);
            base += row.vertices.len() as u32;
        }
        // The vertices, the bulk of it, copied in parallel, each row to its place.
        let total = base as usize;
        paths.vertices.reserve(total);
        let mut places = Vec::with_capacity(rows.len());
        let mut rest = &mut paths.vertices.spare_capacity_mut()[..total];
        for row in rows.iter() {
            let (place, tail) = rest.split_at_mut(row.vertices.len());
            places.push(place);
            rest = tail;
        }
        places
            .into_par_iter()
            .zip(rows.par_iter())
            .for_each(|(place, row)| {
                for (slot, v) in place.iter_mut().zip(&row.vertices) {
                    slot.write(*v);
                }
            });
        // SAFETY: the places cover the first `total` slots, and each row wrote all of its own.
        unsafe { paths.vertices.set_len(total) };
        rays
    }

    /// The camera pass: every pixel's camera subpath, its connections with its own light
    /// subpath (whose t = 1 splats it also makes) and its merges. `LAYERS`: each row also
    /// keeps its pixels' techniques apart (`--techniques`).
    fn camera_pass<const LAYERS: bool>(
        &self,
        scene: &Scene,
        bidir: &Bidir,
        lights: &LightPaths,
        grid: Option<&HashGrid>,
        iteration: u64,
        rows: &mut Vec<Row>,
    ) {
        let (width, height) = (scene.film().width, scene.film().height);
        // The film's splats are added in bands of rows, one per thread of the pool this runs
        // in (the accumulation reads the bands from the rows).
        let band_rows = height.div_ceil(rayon::current_num_threads() as u32).max(1);
        let filter = &scene.film().filter;
        let light_paths = width as f32 * height as f32;
        rows.resize_with(height as usize, || Row {
            sums: Vec::with_capacity(width as usize),
            layer_sums: Vec::new(),
            splats: RowSplats {
                bands: Vec::new(),
                band_rows,
                width,
                bad: 0,
            },
            rays: 0,
            bad: 0,
            camera: Vec::new(),
        });
        rows.par_iter_mut().enumerate().for_each(|(y, row)| {
            let y = y as u32;
            row.sums.clear();
            row.layer_sums.clear();
            row.splats.reset(height, band_rows);
            row.rays = 0;
            row.bad = 0;
            let mut camera = std::mem::take(&mut row.camera);
            for x in 0..width {
                let pixel = y as usize * width as usize + x as usize;
                let mut sampler = self.sampler(scene, STREAM_CAMERA, pixel as u64, iteration);
                let rays = &mut row.rays;
                // ---- t = 1: this pixel's light subpath connected to the camera ----
                if self.mode.connects() {
                    if let Some(o) = &lights.origins[pixel] {
                        bidir.splat_origin(scene, o, &mut sampler, &mut row.splats, rays);
                    }
                    for v in lights.of(pixel) {
                        bidir.splat_vertex(scene, v, &mut sampler, &mut row.splats, rays);
                    }
                }
                let mut l = Rgb::ZERO;
                // The techniques' shares of l (LAYERS only).
                let mut shares = [Rgb::ZERO; 3];
                let mut weight = 1.0f32;
                if self.mode != Mode::Lt {
                    let at = filter.sample(x, y, sampler.next_2d());
                    let ps = PixelSample {
                        ray: scene
                            .camera()
                            .generate_ray_lens(at.film, || sampler.next_2d()),
                        x,
                        y,
                        film: at.film,
                        filter_pdf: filter.pdf(x, y, at.film),
                        filter_weight: at.weight,
                    };
                    camera.clear();
                    l = bidir.camera_subpath(scene, &ps, &mut sampler, &mut camera, rays);
                    if LAYERS {
                        shares[EMISSION] = l;
                    }
                    for c in &camera {
                        if self.mode.connects() {
                            // ---- s >= 1, t >= 2: connections ----
                            let direct = bidir.direct(scene, c, &mut sampler, rays);
                            l += direct;
                            if LAYERS {
                                shares[CONNECTION] += direct;
                            }
                            for v in lights.of(pixel) {
                                let connected = bidir.connect(scene, c, v, rays);
                                l += connected;
                                if LAYERS {
                                    shares[CONNECTION] += connected;
                                }
                            }
                        }
                        if let Some(grid) = grid {
                            // ---- merges ----
                            let merged = self.merge(bidir, c, &lights.vertices, grid) / light_paths;
                            l += merged;
                            if LAYERS {
                                shares[MERGING] += merged;
                            }
                        }
                    }
                    weight = at.weight;
                }
                if !usable(l) {
                    row.bad += 1;
                    l = Rgb::ZERO;
                    shares = [Rgb::ZERO; 3];
                }
                // The camera sample's filter weight, after the check (it may be negative):
                // exactly 1.0 for a positive filter.
                l *= weight;
                if LAYERS {
                    shares.iter_mut().for_each(|v| *v *= weight);
                }
                let mut sum = RadianceSum::ZERO;
                sum.add(l);
                row.sums.push(sum);
                if LAYERS {
                    row.layer_sums.push(shares.map(|v| {
                        let mut sum = RadianceSum::ZERO;
                        sum.add(v);
                        sum
                    }));
                }
            }
            row.camera = camera;
        });
    }

    /// The merges of camera vertex `c` with the light vertices within the grid's radius: sum_v
    /// K f beta_c beta_v w_v (divided by the light path count by the caller).
    fn merge(&self, bidir: &Bidir, c: &Vertex, vertices: &[Vertex], grid: &HashGrid) -> Rgb {
        let At::Surface { hit, bsdf } = &c.at else {
            return Rgb::ZERO;
        };
        let radius = grid.radius();
        let r2 = radius * radius;
        let thickness = DISC_THICKNESS * radius;
        let mut sum = Rgb::ZERO;
        grid.within(c.p, |i, d2| {
            let v = &vertices[i];
            // A merged path has l + m - 1 scattering events (l, m the two subpaths' segments).
            if v.length + c.length > self.max_depth.saturating_add(1) {
                return;
            }
            let At::Surface { hit: vh, .. } = &v.at else {
                return;
            };
            // The same surface: normals within about 25 degrees (either side: the BSDF tells
            // reflection from transmission), close to the tangent plane.
            if vh.ng.dot(hit.ng).abs() <= 0.9 || (v.p - c.p).dot(hit.ng).abs() > thickness {
                return;
            }
            let f = bsdf.eval_density(c.wo, v.wo);
            if f == Rgb::ZERO {
                return;
            }
            let w = if self.mode == Mode::Ppm {
                1.0
            } else {
                weight_merge(
                    &bidir.factors,
                    &c.running,
                    &v.running,
                    bsdf.pdf(c.wo, v.wo),
                    bsdf.pdf(v.wo, c.wo),
                )
            };
            sum += f * v.beta * (epanechnikov(d2, r2) * w);
        });
        c.beta * sum
    }
}

/// The passes of one render (foton-photonmap's `run_passes` runs them): the film the
/// iterations add their pixel samples and splats to.
struct VcmPasses<'a> {
    vcm: &'a Vcm,
    scene: &'a Scene,
    media: Vec<Option<u32>>,
    /// The film's exact sums: per pixel its samples' and its splats' (empty until the
    /// first splat), and the passes added.
    sums: Vec<RadianceSum>,
    splats: Vec<RadianceSum>,
    /// With `--techniques`: per pixel, the sums of its connections, merges and emission
    /// (`CONNECTION`, `MERGING`, `EMISSION`); empty otherwise. Light tracing is the splats.
    layer_sums: Vec<[RadianceSum; 3]>,
    passes: u32,
    tally: Tally,
    /// Memory kept from one iteration to the next.
    buffers: Buffers,
}

/// An iteration's light paths, their grid and the camera pass's rows, kept for the next
/// iteration: refilled, not allocated anew (their pages faulted in again each iteration were
/// a tenth of the time).
struct Buffers {
    light_rows: Vec<LightPaths>,
    lights: LightPaths,
    grid: HashGrid,
    rows: Vec<Row>,
}

impl Passes for VcmPasses<'_> {
    /// Iteration `iteration` (0-based): the light pass, the grid of its vertices, the camera
    /// pass; its pixel sums and splats go to the film.
    fn pass(&mut self, iteration: u64, quiet: &RenderContext<'_>) -> Result<Option<String>> {
        let (vcm, scene) = (self.vcm, self.scene);
        let (bidir, radius) = vcm.estimator(scene, iteration + 1);
        let media = &self.media;
        let layers = !self.layer_sums.is_empty();
        let b = &mut self.buffers;
        let mut rays = with_pool(quiet.threads, || {
            let light_rays = quiet.timed("light tracing", || {
                vcm.light_pass(
                    scene,
                    &bidir,
                    media,
                    iteration,
                    &mut b.light_rows,
                    &mut b.lights,
                )
            });
            let merges = vcm.mode.merges();
            if merges {
                quiet.timed("hash grid build", || {
                    b.grid
                        .rebuild(b.lights.vertices.par_iter().map(|v| v.p), radius)
                });
            }
            let grid = merges.then_some(&b.grid);
            quiet.timed("camera pass", || {
                if layers {
                    vcm.camera_pass::<true>(scene, &bidir, &b.lights, grid, iteration, &mut b.rows)
                } else {
                    vcm.camera_pass::<false>(scene, &bidir, &b.lights, grid, iteration, &mut b.rows)
                }
            });
            light_rays
        })?;
        if quiet.cancelled() {
            // An iteration cut short would leave pixels without their sample: drop it.
            return Ok(None);
        }
        let width = scene.film().width as usize;
        let _accumulate = quiet.phase("film accumulation");
        let rows = &self.buffers.rows;
        let splatted = |r: &Row| r.splats.bands.iter().any(|b| !b.is_empty());
        if self.splats.is_empty() && rows.iter().any(splatted) {
            self.splats = vec![RadianceSum::ZERO; self.sums.len()];
        }
        // Integer sums: added in any order, the same film. The splats by bands of rows, each
        // band's task taking its own list from every row.
        let band = width * rows.first().map_or(1, |r| r.splats.band_rows) as usize;
        let (sums, splats) = (&mut self.sums, &mut self.splats);
        with_pool(quiet.threads, || {
            rayon::join(
                || {
                    sums.par_chunks_mut(width)
                        .zip(rows.par_iter())
                        .for_each(|(dst, row)| {
                            for (d, s) in dst.iter_mut().zip(&row.sums) {
                                d.merge(s);
                            }
                        })
                },
                || {
                    splats
                        .par_chunks_mut(band)
                        .enumerate()
                        .for_each(|(b, chunk)| {
                            let start = b * band;
                            for row in rows {
                                for (i, s) in &row.splats.bands[b] {
                                    chunk[*i as usize - start].merge(s);
                                }
                            }
                        })
                },
            )
        })?;
        if layers {
            for (dst, row) in self.layer_sums.chunks_mut(width).zip(rows) {
                for (d, s) in dst.iter_mut().zip(&row.layer_sums) {
                    for (d, s) in d.iter_mut().zip(s) {
                        d.merge(s);
                    }
                }
            }
        }
        self.passes += 1;
        for row in rows {
            rays += row.rays;
            Tally::add(&self.tally.bad_samples, row.bad);
            Tally::add(&self.tally.bad_splats, row.splats.bad);
        }
        Tally::add(&self.tally.rays, rays);
        let done = iteration + 1;
        Ok(Some(format!(
            "iteration {done}, {} light paths, radius {radius:.5}",
            done * vcm.passes.photons_per_iteration
        )))
    }

    /// The film holds the exact sums: each pixel's mean over its samples, the splats scaled
    /// by the samples taken.
    fn film(&self, _passes: u64) -> Film {
        let (width, height) = (self.scene.film().width, self.scene.film().height);
        let mut film = Film::from_sums(
            width,
            height,
            self.sums.clone(),
            vec![self.passes; self.sums.len()],
            self.splats.clone(),
        )
        .expect("sums of the film's size");
        if !self.layer_sums.is_empty() {
            for name in TECHNIQUES {
                film.add_layer(name);
            }
            for (i, sums) in self.layer_sums.iter().enumerate() {
                for (k, s) in sums.iter().enumerate() {
                    film.add_layer_pixel(k, i, s);
                }
            }
            // Every splat is a light vertex connected to the camera (t = 1).
            for (i, s) in self.splats.iter().enumerate() {
                film.add_layer_splat(LIGHT_TRACING, i, s);
            }
        }
        film
    }

    fn tally(&self) -> &Tally {
        &self.tally
    }
}

impl Integrator for Vcm {
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        let mut passes = VcmPasses {
            vcm: self,
            scene,
            media: scene.emission_media()?,
            sums: vec![
                RadianceSum::ZERO;
                scene.film().width as usize * scene.film().height as usize
            ],
            splats: Vec::new(),
            layer_sums: match ctx.techniques {
                Some(_) => {
                    let pixels = scene.film().width as usize * scene.film().height as usize;
                    vec![[RadianceSum::ZERO; 3]; pixels]
                }
                None => Vec::new(),
            },
            passes: 0,
            tally: Tally::default(),
            buffers: Buffers {
                light_rows: Vec::new(),
                lights: LightPaths::default(),
                grid: HashGrid::empty(),
                rows: Vec::new(),
            },
        };
        // Iteration i's radius and random streams depend on i alone: any share of them can
        // be rendered apart.
        run_passes(
            "vcm",
            &self.passes,
            ctx,
            Ok(()),
            "camera sample(s)",
            &mut passes,
        )
    }

    fn name(&self) -> &str {
        "vcm"
    }

    /// `connection` (s >= 1, t >= 2: next-event estimation and connections), `merging`
    /// (vertex merging), `emission` (camera paths reaching emitters, s = 0) and
    /// `light_tracing` (light vertices connected to the camera, t = 1: the splats).
    fn techniques(&self, _depth: u32) -> Vec<String> {
        TECHNIQUES.map(String::from).to_vec()
    }

    fn parameters(&self) -> Vec<Parameter> {
        let mut p = Vec::new();
        if let Some(n) = self.passes.iterations {
            p.push(Parameter::int("iterations", n));
        }
        if let Some(t) = self.passes.time {
            p.push(Parameter::float("time", t));
        }
        p.push(if self.radius_given {
            Parameter::float("radius", self.radius)
        } else {
            Parameter::str("radius", "auto")
        });
        p.push(Parameter::float("alpha", self.alpha));
        p.push(Parameter::str("mode", self.mode.name()));
        p.push(Parameter::int("rr_depth", self.rr_depth));
        p
    }

    fn budget(&self) -> Budget {
        PassBudget::budget("vcm")
    }

    /// Merging is density estimation over the radius, which shrinks with the iterations;
    /// connections alone (`bpt`, `lt`) are unbiased.
    fn bias(&self) -> Option<String> {
        match self.mode {
            Mode::Bpt | Mode::Lt => None,
            Mode::Vcm | Mode::Ppm => Some(
                "more iterations (integrators.vcm.iterations) or a smaller integrators.vcm.radius shrink it".into(),
            ),
        }
    }
}

/// SmallVCM's default first radius: 0.003 x the radius of the scene's bounding sphere.
pub fn auto_radius(scene: &Scene) -> f32 {
    let diagonal = (scene.bounds().1 - scene.bounds().0).length();
    (0.003 * 0.5 * diagonal).max(1e-6)
}

/// Reads the parameters (see the table above).
pub fn create(props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
    let (iterations, time) = read_passes(props, 64)?;
    let radius = props.f32_opt("radius")?;
    if let Some(r) = radius
        && !(r > 0.0 && r.is_finite())
    {
        return Err(props.error("radius", format!("must be positive, found {r}")));
    }
    let alpha = props.f32("alpha", 0.75)?;
    if !(alpha > 0.0 && alpha <= 1.0) {
        return Err(props.error("alpha", format!("must be in (0, 1], found {alpha}")));
    }
    let mode = match props.choice("mode", &Mode::NAMES, "vcm")? {
        "bpt" => Mode::Bpt,
        "ppm" => Mode::Ppm,
        "lt" => Mode::Lt,
        _ => Mode::Vcm,
    };
    let rr_depth = props.u32("rr_depth", 5)?;
    if scene.has_media() {
        return Err(Error::Usage(format!(
            "{}: the scene has participating media, which `vcm` does not render (merging is on \
             surfaces only): use `bdpt` or `vpm`",
            scene.file().display()
        )));
    }
    let light_paths = scene.film().width as u64 * scene.film().height as u64;
    Ok(Box::new(Vcm {
        passes: PassBudget {
            iterations,
            time,
            photons_per_iteration: light_paths,
        },
        radius: radius.unwrap_or_else(|| auto_radius(scene)),
        radius_given: radius.is_some(),
        alpha,
        mode,
        max_depth: scene.render().max_depth,
        rr_depth,
    }))
}

foton_core::api::declare_integrator!(
    "vcm",
    "vertex connection and merging (Georgiev et al., MIS of bdpt and photon mapping)",
    create
);

#[cfg(test)]
mod tests {
    use super::*;

    /// The Epanechnikov kernel integrates to one over its disc, for any radius (midpoint rule
    /// in the radius: 2 pi int_0^r K(d) d dd), and is zero outside.
    #[test]
    fn the_epanechnikov_kernel_integrates_to_one_over_the_disc() {
        for r in [1e-3f32, 0.05, 1.0, 30.0] {
            let n = 20_000;
            let h = r as f64 / n as f64;
            let integral: f64 = (0..n)
                .map(|i| {
                    let d = (i as f64 + 0.5) * h;
                    2.0 * std::f64::consts::PI * d * epanechnikov((d * d) as f32, r * r) as f64 * h
                })
                .sum();
            assert!((integral - 1.0).abs() < 1e-4, "r = {r}: {integral}");
            assert_eq!(epanechnikov(r * r * 1.0001, r * r), 0.0);
        }
    }

    /// Issue 35: an iteration's light vertices and their hash grid within twice the size of
    /// the vertex records (with each pixel's path end, 4 bytes per pixel, beside them).
    #[test]
    fn light_vertices_and_their_grid_hold_at_most_twice_the_records() {
        let n = 50_000;
        let mut rng = foton_core::api::Rng::new(&[8]);
        let positions: Vec<foton_core::api::Vec3> = (0..n)
            .map(|_| foton_core::api::Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()))
            .collect();
        let grid = grid::HashGrid::build(positions, 0.01);
        let record = std::mem::size_of::<Vertex>();
        let per_vertex = (n * record + grid.heap_bytes()) as f64 / n as f64;
        println!("vcm: {per_vertex:.1} bytes per light vertex, records of {record} bytes");
        assert!(
            per_vertex <= 2.0 * record as f64,
            "{per_vertex} per {record}"
        );
    }

    /// The schedule: r_1 at the first iteration, r_1 i^((alpha - 1) / 2) after.
    #[test]
    fn the_radius_shrinks_as_the_schedule_says() {
        assert_eq!(radius_of(0.1, 0.75, 1), 0.1);
        let r = radius_of(0.1, 0.75, 16);
        assert!((r - 0.1 * 16f32.powf(-0.125)).abs() < 1e-7, "{r}");
        assert_eq!(radius_of(0.1, 1.0, 1000), 0.1);
    }
}
