//! The parallel image loop shared by integrators that estimate radiance per camera sample.
//!
//! Samples are taken in passes (1, 1, 2, 4, ... samples per pixel) over 16x16 tiles run in
//! parallel; each sample's random numbers depend on its pixel and index alone and pixels sum
//! their samples exactly ([`RadianceSum`]), so the image is bit-identical for a given seed
//! whatever the thread count, and a render split into parts (`RenderContext::part`: part i of
//! n takes the samples [spp i / n, spp (i + 1) / n) of every pixel) sums to the whole render.
//! Ctrl-C stops between pixels: every pixel keeps the samples it has and is divided by its own
//! count.

use crate::Rgb;
use crate::error::{Error, Result};
use crate::film::{Film, RadianceSum};
use crate::geometry::Ray;
use crate::integrator::RenderContext;
use crate::sampling::Sampler;
use crate::scene::{RenderSettings, Scene};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

pub const TILE: u32 = 16;

/// Runs `f` on a pool of `threads` workers. Each plugin links its own rayon, so the pool is
/// built here, in the caller's copy, from the host's thread count.
pub fn with_pool<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> Result<R> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| Error::Render(format!("cannot start {threads} threads: {e}")))?;
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
    let pixel = (y as u64) * width as u64 + x as u64;
    Sampler::new(settings.sampler, settings.seed, pixel, sample, settings.spp)
}

/// Renders `scene.render.spp` samples per pixel, or the share of them `ctx.part` names;
/// `radiance` estimates the radiance arriving along a camera ray and adds the rays it traced to
/// its last argument (for statistics). The film position is drawn from the scene's
/// reconstruction filter.
pub fn render_pixels<F>(scene: &Scene, ctx: &RenderContext<'_>, radiance: F) -> Result<Film>
where
    F: Fn(&Ray, &mut Sampler, &mut u64) -> Rgb + Sync,
{
    let (width, height) = (scene.film.width, scene.film.height);
    let share = ctx.part.share(scene.render.spp as u64);
    let (first, spp) = (share.start as u32, share.end as u32);
    let mut film = Film::new(width, height);
    film.part = ctx.part;
    let tiles: Vec<(u32, u32)> = (0..height.div_ceil(TILE))
        .flat_map(|ty| (0..width.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let bad_samples = AtomicU64::new(0);
    let rays = AtomicU64::new(0);
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
    let mut done = first;
    while done < spp && !ctx.cancelled() {
        let batch = (done - first).max(1).min(spp - done);
        let (s0, s1) = (done, done + batch);
        let results: Vec<Vec<(usize, RadianceSum, u32)>> = with_pool(ctx.threads, || {
            tiles
                .par_iter()
                .map(|&(x0, y0)| {
                    let mut out = Vec::with_capacity((TILE * TILE) as usize);
                    let mut tile_rays = 0u64;
                    for y in y0..(y0 + TILE).min(height) {
                        if ctx.cancelled() {
                            break;
                        }
                        for x in x0..(x0 + TILE).min(width) {
                            let mut sum = RadianceSum::ZERO;
                            for s in s0..s1 {
                                let mut sampler = pixel_sampler(&scene.render, width, x, y, s);
                                let at = scene.film.filter.film_position(x, y, sampler.next_2d());
                                let ray = scene.camera.generate_ray(at);
                                let mut l = radiance(&ray, &mut sampler, &mut tile_rays);
                                if !usable(l) {
                                    bad_samples.fetch_add(1, Ordering::Relaxed);
                                    l = Rgb::ZERO;
                                }
                                sum.add(l);
                            }
                            out.push((film.index(x, y), sum, s1 - s0));
                        }
                    }
                    rays.fetch_add(tile_rays, Ordering::Relaxed);
                    ctx.progress.rays(tile_rays);
                    ctx.progress.advance(out.len() as u64 * (s1 - s0) as u64);
                    out
                })
                .collect()
        })?;
        for (i, sum, n) in results.into_iter().flatten() {
            film.add_pixel(i, &sum, n);
        }
        done = s1;
    }
    ctx.progress.finish();
    film.rays = rays.load(Ordering::Relaxed);
    warn_unusable(
        ctx,
        bad_samples.load(Ordering::Relaxed),
        "sample(s)",
        "replaced by zero",
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
