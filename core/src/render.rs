//! The parallel image loop shared by integrators that estimate radiance per camera sample.
//!
//! Samples are taken in passes (1, 1, 2, 4, ... samples per pixel) over 16x16 tiles run in
//! parallel; each sample's random numbers depend on its pixel and index alone and pixels sum
//! their samples exactly ([`RadianceSum`]), so the image is bit-identical for a given seed
//! whatever the thread count, and a render split into parts (`RenderContext::part`: part i of
//! n takes the samples [spp i / n, spp (i + 1) / n) of every pixel) sums to the whole render.
//! Ctrl-C stops between pixels: every pixel keeps the samples it has and is divided by its own
//! count.
//!
//! **Splats.** An integrator that also traces paths from the lights ([`render_pixels_splatting`])
//! adds what they bring to the camera to any pixel ([`Splats::add`]). Each tile keeps its splats
//! as exact fixed-point sums ([`RadianceSum`]) in a short list and adds them to one image-sized
//! splat buffer when the list fills and when the tile ends, grouped by band of rows: each band
//! has its own lock, and a band another thread holds is left for
//! later rather than waited for (with one lock for the image, the tiles of a light-tracing
//! render queued on it). Integer addition is
//! associative and commutative, so the buffer holds the same bits whatever order the tiles and
//! threads add in: the image stays bit-identical for any thread count (a per-thread buffer
//! would too, at one image of memory per thread; floating-point atomics would not). A tile's
//! splats come from the camera samples of the pixels it finished, so after Ctrl-C the splat
//! buffer holds the light paths of exactly the samples the film counts, and the film scales it
//! by those ([`Film::pixel`]).

use crate::Rgb;
use crate::error::{Error, Result};
use crate::film::{Film, RadianceSum};
use crate::geometry::Ray;
use crate::integrator::RenderContext;
use crate::sampling::{PixelSamplers, Sampler};
use crate::scene::{RenderSettings, Scene};
use glam::Vec2;
use rayon::prelude::*;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

pub const TILE: u32 = 16;

/// Runs `f` on a pool of `threads` workers. Each plugin links its own rayon, so the pool is
/// built here, in the caller's copy, from the host's thread count. Pools are kept (one per
/// thread count) and reused: a progressive integrator runs several phases per iteration, and
/// starting the threads anew for each cost about a millisecond per phase at 16 threads.
pub fn with_pool<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> Result<R> {
    static POOLS: Mutex<Vec<(usize, std::sync::Arc<rayon::ThreadPool>)>> = Mutex::new(Vec::new());
    let threads = threads.max(1);
    let pool = {
        let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
        match pools.iter().find(|(n, _)| *n == threads) {
            Some((_, pool)) => pool.clone(),
            None => {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .map_err(|e| Error::Render(format!("cannot start {threads} threads: {e}")))?;
                let pool = std::sync::Arc::new(pool);
                pools.push((threads, pool.clone()));
                pool
            }
        }
    };
    Ok(pool.install(f))
}

/// The sampler of camera sample `sample` of pixel (x, y): the scene's kind, with the strata
/// of all `[render] spp` samples (not of a part's share, so that parts sum to the whole).
#[inline]
pub fn pixel_sampler(
    settings: &RenderSettings,
    width: u32,
    x: u32,
    y: u32,
    sample: u32,
) -> Sampler {
    pixel_samplers(settings, width, x, y).sample(sample)
}

/// The samplers of pixel (x, y)'s camera samples ([`pixel_sampler`] of each), the hashes of
/// the seed and the pixel made once.
#[inline]
pub fn pixel_samplers(settings: &RenderSettings, width: u32, x: u32, y: u32) -> PixelSamplers {
    let pixel = (y as u64) * width as u64 + x as u64;
    PixelSamplers::new(settings.sampler, settings.seed, pixel, settings.spp)
}

/// One camera sample as the pixel loop draws it.
#[derive(Clone, Copy, Debug)]
pub struct PixelSample {
    pub ray: Ray,
    /// The pixel it estimates.
    pub x: u32,
    pub y: u32,
    /// Where on the film the ray starts (pixel units), drawn from the reconstruction filter.
    pub film: Vec2,
    /// The filter's density at `film` for this pixel ([`crate::filter::FilterSampler::pdf`]).
    pub filter_pdf: f32,
    /// The weight the sample's estimate counts with ([`crate::filter::FilmSample::weight`]):
    /// exactly 1.0 with a positive filter, sign(w) ∫|w| / ∫w with one that has negative
    /// lobes. The pixel loop multiplies what the integrator's `radiance` returns (and its
    /// techniques' shares) by it; an integrator with its own camera loop does the same.
    pub filter_weight: f32,
}

/// Where a render's light paths add what they bring to the camera (see the module comment).
pub struct Splats<'a> {
    width: u32,
    pending: Vec<(u32, RadianceSum)>,
    /// Scratch for grouping `pending` by band.
    order: Vec<u32>,
    buffer: Option<&'a SplatBuffer>,
    bad: u64,
}

/// Splats a tile keeps before it adds them to the shared buffer.
const SPLAT_BATCH: usize = 4096;

/// Bands of rows the splat buffer is locked by, at most.
const SPLAT_BANDS: u32 = 64;

/// The film's splat sums, in bands of rows with a lock each (module comment).
struct SplatBuffer {
    /// Pixels a band.
    band: usize,
    bands: Vec<Mutex<Vec<RadianceSum>>>,
}

impl SplatBuffer {
    fn new(width: u32, height: u32) -> SplatBuffer {
        let rows = height.div_ceil(SPLAT_BANDS).max(1);
        let band = (rows * width).max(1) as usize;
        let pixels = width as usize * height as usize;
        SplatBuffer {
            band,
            bands: (0..pixels.div_ceil(band))
                .map(|b| Mutex::new(vec![RadianceSum::ZERO; band.min(pixels - b * band)]))
                .collect(),
        }
    }

    /// Adds `splats` to the sums: grouped by band (a counting pass, not a sort: `order` is
    /// scratch), each band's group under its lock, the bands another thread holds after the
    /// others.
    fn add(&self, splats: &[(u32, RadianceSum)], order: &mut Vec<u32>) {
        const N: usize = SPLAT_BANDS as usize + 1;
        let mut start = [0u32; N];
        for &(i, _) in splats {
            start[i as usize / self.band + 1] += 1;
        }
        for b in 1..N {
            start[b] += start[b - 1];
        }
        let mut next = start;
        order.resize(splats.len(), 0);
        for (k, &(i, _)) in splats.iter().enumerate() {
            let b = i as usize / self.band;
            order[next[b] as usize] = k as u32;
            next[b] += 1;
        }
        let group = |b: usize| &order[start[b] as usize..start[b + 1] as usize];
        let mut busy = [false; N];
        for (b, band) in self.bands.iter().enumerate() {
            if group(b).is_empty() {
                continue;
            }
            match band.try_lock() {
                Ok(mut sums) => self.merge(b, &mut sums, splats, group(b)),
                Err(std::sync::TryLockError::WouldBlock) => busy[b] = true,
                Err(std::sync::TryLockError::Poisoned(e)) => {
                    self.merge(b, &mut e.into_inner(), splats, group(b))
                }
            }
        }
        for (b, band) in self.bands.iter().enumerate() {
            if busy[b] {
                let mut sums = band.lock().unwrap_or_else(|e| e.into_inner());
                self.merge(b, &mut sums, splats, group(b));
            }
        }
    }

    fn merge(
        &self,
        b: usize,
        sums: &mut [RadianceSum],
        splats: &[(u32, RadianceSum)],
        group: &[u32],
    ) {
        for &k in group {
            let (i, sum) = &splats[k as usize];
            sums[*i as usize - b * self.band].merge(sum);
        }
    }

    /// The sums, pixel by pixel.
    fn into_sums(self) -> impl Iterator<Item = RadianceSum> {
        self.bands
            .into_iter()
            .flat_map(|m| m.into_inner().unwrap_or_else(|e| e.into_inner()))
    }
}

impl Splats<'_> {
    /// Adds `value` to pixel (x, y)'s splat sum. The film multiplies the sum by one over the
    /// camera samples per pixel ([`Film::pixel`]): a splat is one light path's estimate of
    /// the pixel, scaled as a camera sample's radiance is. A value that is not [`usable`] is
    /// dropped (and counted in the render's warning).
    #[inline]
    pub fn add(&mut self, x: u32, y: u32, value: Rgb) {
        self.add_weighted(x, y, value, 1.0)
    }

    /// [`Splats::add`] of `value` times `weight`, the filter's weight of the pixel at the
    /// splat's film point ([`crate::filter::FilterSampler::footprint`]: negative in a
    /// filter's negative lobes, exactly 1.0 for a positive filter): `value` itself must be
    /// [`usable`].
    #[inline]
    pub fn add_weighted(&mut self, x: u32, y: u32, value: Rgb, weight: f32) {
        if !usable(value) {
            self.bad += 1;
            return;
        }
        if value == Rgb::ZERO {
            return;
        }
        let mut sum = RadianceSum::ZERO;
        sum.add(value * weight);
        self.pending.push((y * self.width + x, sum));
        if self.pending.len() >= SPLAT_BATCH {
            self.flush();
        }
    }

    fn flush(&mut self) {
        if let Some(buffer) = self.buffer {
            buffer.add(&self.pending, &mut self.order);
        }
        self.pending.clear();
    }
}

/// Where a camera sample reports each sampling technique's share of its estimate, when the
/// render keeps them (`foton render --techniques`, [`render_pixels_techniques`]): technique
/// `k`'s share of the radiance the sample returns ([`Techniques::add`]) and of what it splats
/// ([`Techniques::splat`]). Each technique's shares go to a layer of the film, summed exactly as
/// the image is (a sample whose radiance is not [`usable`] is dropped from every layer as it is
/// replaced by zero in the image), so that the layers sum to the image when every contribution
/// is given to exactly one technique.
pub struct Techniques<'a> {
    width: u32,
    pixels: usize,
    /// The current camera sample's shares, per technique.
    sample: Vec<Rgb>,
    /// Splats not yet added to `buffer`: (technique, pixel, sum).
    pending: Vec<(u32, u32, RadianceSum)>,
    /// Every technique's splat sums, technique after technique.
    buffer: &'a Mutex<Vec<RadianceSum>>,
}

impl Techniques<'_> {
    /// Adds `value` to technique `technique`'s share of the camera sample's radiance (the
    /// value the sample returns must be the sum of its shares).
    #[inline]
    pub fn add(&mut self, technique: usize, value: Rgb) {
        self.sample[technique] += value;
    }

    /// Adds `value` to technique `technique`'s splats at pixel (x, y): the same value given to
    /// [`Splats::add`] (dropped, as there, when not [`usable`] or zero).
    #[inline]
    pub fn splat(&mut self, technique: usize, x: u32, y: u32, value: Rgb) {
        self.splat_weighted(technique, x, y, value, 1.0)
    }

    /// [`Techniques::splat`] of `value` times the filter's `weight`, as
    /// [`Splats::add_weighted`].
    #[inline]
    pub fn splat_weighted(&mut self, technique: usize, x: u32, y: u32, value: Rgb, weight: f32) {
        if !usable(value) || value == Rgb::ZERO {
            return;
        }
        let mut sum = RadianceSum::ZERO;
        sum.add(value * weight);
        self.pending
            .push((technique as u32, y * self.width + x, sum));
        if self.pending.len() >= SPLAT_BATCH {
            self.flush();
        }
    }

    fn flush(&mut self) {
        let mut buffer = self.buffer.lock().unwrap_or_else(|e| e.into_inner());
        for (k, i, sum) in self.pending.drain(..) {
            buffer[k as usize * self.pixels + i as usize].merge(&sum);
        }
    }
}

/// Renders `scene.render.spp` samples per pixel, or the share of them `ctx.part` names;
/// `radiance` estimates the radiance arriving along a camera ray and adds the rays it traced to
/// its last argument (for statistics). The film position is drawn from the scene's
/// reconstruction filter.
pub fn render_pixels<F>(scene: &Scene, ctx: &RenderContext<'_>, radiance: F) -> Result<Film>
where
    F: Fn(&Ray, &mut Sampler, &mut u64) -> Rgb + Sync,
{
    render_loop::<false, _>(scene, ctx, false, &[], |sample, sampler, _, _, rays| {
        radiance(&sample.ray, sampler, rays)
    })
}

/// [`render_pixels`] for an integrator that also splats (light tracing, bidirectional path
/// tracing): `radiance` gets the whole camera sample and a [`Splats`] to add contributions to
/// any pixel, and returns the camera sample's own estimate. The film then has a splat buffer.
pub fn render_pixels_splatting<F>(
    scene: &Scene,
    ctx: &RenderContext<'_>,
    radiance: F,
) -> Result<Film>
where
    F: Fn(&PixelSample, &mut Sampler, &mut Splats<'_>, &mut u64) -> Rgb + Sync,
{
    render_loop::<false, _>(scene, ctx, true, &[], |sample, sampler, splats, _, rays| {
        radiance(sample, sampler, splats, rays)
    })
}

/// [`render_pixels_splatting`] that also keeps each sampling technique's share of the image
/// (`foton render --techniques`): `radiance` reports the shares of technique `k` (the k-th of
/// `techniques`, the layers' names) to its [`Techniques`], and the film gets one layer per
/// technique ([`Film::layers`]).
pub fn render_pixels_techniques<F>(
    scene: &Scene,
    ctx: &RenderContext<'_>,
    techniques: &[String],
    radiance: F,
) -> Result<Film>
where
    F: Fn(&PixelSample, &mut Sampler, &mut Splats<'_>, &mut Techniques<'_>, &mut u64) -> Rgb + Sync,
{
    render_loop::<true, _>(scene, ctx, true, techniques, radiance)
}

/// The pixel loop; `LAYERS`: the render keeps the techniques' shares (a constant, so that a
/// render without them pays nothing per sample).
fn render_loop<const LAYERS: bool, F>(
    scene: &Scene,
    ctx: &RenderContext<'_>,
    splatting: bool,
    techniques: &[String],
    radiance: F,
) -> Result<Film>
where
    F: Fn(&PixelSample, &mut Sampler, &mut Splats<'_>, &mut Techniques<'_>, &mut u64) -> Rgb + Sync,
{
    let (width, height) = (scene.film.width, scene.film.height);
    let share = ctx.part.share(scene.render.spp as u64);
    let (first, spp) = (share.start as u32, share.end as u32);
    let mut film = Film::new(width, height);
    film.part = ctx.part;
    let pixels = width as usize * height as usize;
    let layers = if LAYERS { techniques.len() } else { 0 };
    for name in &techniques[..layers] {
        film.add_layer(name);
    }
    let layer_splats = Mutex::new(vec![RadianceSum::ZERO; layers * pixels]);
    let tiles: Vec<(u32, u32)> = (0..height.div_ceil(TILE))
        .flat_map(|ty| (0..width.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let bad_samples = AtomicU64::new(0);
    let bad_splats = AtomicU64::new(0);
    let rays = AtomicU64::new(0);
    let splat_buffer = SplatBuffer::new(width, if splatting { height } else { 0 });
    ctx.progress.begin(
        "pixels",
        width as u64 * height as u64 * (spp - first) as u64,
    );

    if first == spp && !ctx.part.is_whole() {
        ctx.progress.warn(&format!(
            "part {} of {} samples per pixel holds none: split into at most {} parts",
            ctx.part, scene.render.spp, scene.render.spp
        ));
    }
    let filter = &scene.film.filter;
    let ray_weight = scene.camera.ray_weight();
    let mut done = first;
    while done < spp && !ctx.cancelled() {
        let batch = (done - first).max(1).min(spp - done);
        let (s0, s1) = (done, done + batch);
        type TileOut = (Vec<(usize, RadianceSum, u32)>, Vec<RadianceSum>);
        let results: Vec<TileOut> = ctx.timed("camera pass", || {
            with_pool(ctx.threads, || {
                tiles
                    .par_iter()
                    .map(|&(x0, y0)| {
                        let mut out = Vec::with_capacity((TILE * TILE) as usize);
                        let mut tile_rays = 0u64;
                        let mut splats = Splats {
                            width,
                            pending: Vec::new(),
                            order: Vec::new(),
                            buffer: splatting.then_some(&splat_buffer),
                            bad: 0,
                        };
                        // Per pixel of `out`, each technique's sum (LAYERS only).
                        let mut layer_out = Vec::new();
                        let mut techniques = Techniques {
                            width,
                            pixels,
                            sample: vec![Rgb::ZERO; layers],
                            pending: Vec::new(),
                            buffer: &layer_splats,
                        };
                        for y in y0..(y0 + TILE).min(height) {
                            if ctx.cancelled() {
                                break;
                            }
                            for x in x0..(x0 + TILE).min(width) {
                                let mut sum = RadianceSum::ZERO;
                                let first_layer = layer_out.len();
                                if LAYERS {
                                    layer_out.resize(first_layer + layers, RadianceSum::ZERO);
                                }
                                let samplers = pixel_samplers(&scene.render, width, x, y);
                                for s in s0..s1 {
                                    let mut sampler = samplers.sample(s);
                                    let at = filter.sample(x, y, sampler.next_2d());
                                    let sample = PixelSample {
                                        ray: scene
                                            .camera
                                            .generate_ray_lens(at.film, || sampler.next_2d()),
                                        x,
                                        y,
                                        film: at.film,
                                        filter_pdf: filter.pdf(x, y, at.film),
                                        filter_weight: at.weight,
                                    };
                                    let mut l = radiance(
                                        &sample,
                                        &mut sampler,
                                        &mut splats,
                                        &mut techniques,
                                        &mut tile_rays,
                                    );
                                    if !usable(l) {
                                        bad_samples.fetch_add(1, Ordering::Relaxed);
                                        l = Rgb::ZERO;
                                        if LAYERS {
                                            techniques.sample.fill(Rgb::ZERO);
                                        }
                                    }
                                    // The filter's weight, after the check (it may be
                                    // negative); exactly 1.0 for a positive filter and a
                                    // camera (a meter's rays may weigh more).
                                    let weight = at.weight * ray_weight;
                                    l *= weight;
                                    if LAYERS {
                                        techniques.sample.iter_mut().for_each(|v| *v *= weight);
                                    }
                                    sum.add(l);
                                    if LAYERS {
                                        let sums = &mut layer_out[first_layer..];
                                        for (s, v) in sums.iter_mut().zip(&mut techniques.sample) {
                                            s.add(*v);
                                            *v = Rgb::ZERO;
                                        }
                                    }
                                }
                                out.push((film.index(x, y), sum, s1 - s0));
                            }
                        }
                        splats.flush();
                        if LAYERS {
                            techniques.flush();
                        }
                        bad_splats.fetch_add(splats.bad, Ordering::Relaxed);
                        rays.fetch_add(tile_rays, Ordering::Relaxed);
                        ctx.progress.rays(tile_rays);
                        ctx.progress.advance(out.len() as u64 * (s1 - s0) as u64);
                        (out, layer_out)
                    })
                    .collect()
            })
        })?;
        ctx.timed("film accumulation", || {
            for (out, layer_out) in results {
                for (j, (i, sum, n)) in out.into_iter().enumerate() {
                    film.add_pixel(i, &sum, n);
                    if LAYERS {
                        for (k, s) in layer_out[j * layers..(j + 1) * layers].iter().enumerate() {
                            film.add_layer_pixel(k, i, s);
                        }
                    }
                }
            }
        });
        done = s1;
    }
    ctx.progress.finish();
    if splatting {
        for (i, sum) in splat_buffer.into_sums().enumerate() {
            film.add_splat(i, &sum);
        }
        let buffer = layer_splats.into_inner().unwrap_or_else(|e| e.into_inner());
        for (j, sum) in buffer.iter().enumerate() {
            if *sum != RadianceSum::ZERO {
                film.add_layer_splat(j / pixels, j % pixels, sum);
            }
        }
    }
    film.rays = rays.load(Ordering::Relaxed);
    warn_unusable(
        ctx,
        bad_samples.load(Ordering::Relaxed),
        "sample(s)",
        "replaced by zero",
    );
    warn_unusable(
        ctx,
        bad_splats.load(Ordering::Relaxed),
        "splat(s)",
        "dropped",
    );
    Ok(film)
}

/// Whether radiance (or flux) can be added to a pixel's sums: finite and non-negative. One
/// value that is not (a NaN from 0 x inf in a corner case of some BSDF) would stay in the
/// pixel for the rest of the render, so integrators replace such values by zero (the
/// guard of [`render_pixels`], which `sppm` applies to its camera samples and photons).
#[inline]
pub fn usable(l: Rgb) -> bool {
    l.is_finite() && l.min_element() >= 0.0
}

/// The warning after a render that met `bad` values that were not [`usable`]: `what` they
/// were, `done` what was done with them.
pub fn warn_unusable(ctx: &RenderContext<'_>, bad: u64, what: &str, done: &str) {
    if bad > 0 {
        ctx.progress.warn(&format!(
            "{bad} {what} were NaN, infinite or negative and were {done}"
        ));
    }
}
