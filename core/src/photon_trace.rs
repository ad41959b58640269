//! The photon pass shared by the photon-mapping integrators: photons leave the lights in
//! proportion to power, walk the scene by BSDF sampling with Russian roulette, and are
//! offered for storage at every diffuse (non-delta) surface they reach, classified by the
//! path that brought them there (Jensen's L D, L S+ D and the rest).
//!
//! A photon leaving light l carries (power of l) / (pmf(l) x photons emitted); lights are
//! chosen with pmf proportional to power, so that is (total power) / (photons emitted),
//! counting the photons that hit nothing. Photon i draws from its own random stream, so the
//! maps are identical whatever the number of threads.

use crate::Rgb;
use crate::error::Result;
use crate::geometry::{Ray, offset_origin};
use crate::integrator::RenderContext;
use crate::material::TransportMode;
use crate::photon::Photon;
use crate::render::with_pool;
use crate::sampling::Rng;
use crate::scene::Scene;
use rayon::prelude::*;

/// The path a photon took to reach a diffuse surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathClass {
    /// L D: straight from a light (direct illumination).
    Direct,
    /// L S+ D: through one or more specular (delta) bounces only (caustics).
    Caustic,
    /// Every other path: at least one diffuse bounce before this one (indirect illumination).
    Indirect,
}

#[derive(Clone, Copy, Debug)]
pub struct TraceOptions {
    /// Photons to emit.
    pub photons: u64,
    /// Surface hits a photon may make (scattering events, like the path tracer's max_depth).
    pub max_depth: u32,
    pub seed: u64,
    /// Separates the random streams of different photon passes (global, caustic, ...).
    pub stream: u64,
    /// End each photon at its first diffuse hit (a caustic pass has nothing to store after).
    pub stop_at_diffuse: bool,
}

/// Stream identifiers, so that passes draw independent random numbers.
pub const STREAM_GLOBAL: u64 = 0x676c_6f62;
pub const STREAM_CAUSTIC: u64 = 0x6361_7573;

/// Photons per parallel work unit (also the granularity of progress reports).
const CHUNK: u64 = 4096;

/// Null boundaries crossed in a row before a photon is abandoned.
const MAX_NULL_CROSSINGS: u32 = 256;

/// Traces one photon, calling `store(photon, class)` at every diffuse hit.
pub fn trace_one(
    scene: &Scene,
    opts: &TraceOptions,
    index: u64,
    mut store: impl FnMut(Photon, PathClass),
) {
    let mut rng = Rng::new(&[opts.seed, opts.stream, index]);
    let Some((light_id, pmf)) = scene.sample_light(rng.next_f32()) else {
        return;
    };
    let light = &scene.lights[light_id];
    let (u_pos, u_dir, uc) = (rng.next_2d(), rng.next_2d(), rng.next_f32());
    let emitted = light.sample_emission(u_pos, u_dir, uc);
    let mut flux: Rgb = emitted.flux / (pmf * opts.photons as f32);
    let origin = if emitted.n == glam::Vec3::ZERO {
        emitted.origin
    } else {
        offset_origin(emitted.origin, emitted.n, emitted.dir)
    };
    let mut ray = Ray::new(origin, emitted.dir);
    let mut hits = 0u32;
    let mut specular_only = true;
    let mut crossings = 0;
    while let Some(hit) = scene.intersect(&ray, f32::INFINITY) {
        let material = *scene.material(&hit);
        if material.is_null() {
            crossings += 1;
            if crossings > MAX_NULL_CROSSINGS {
                return;
            }
            ray = Ray::new(offset_origin(hit.p, hit.ng, ray.dir), ray.dir);
            continue;
        }
        crossings = 0;
        hits += 1;
        let wi = -ray.dir;
        if !material.is_delta() {
            let class = if hits == 1 {
                PathClass::Direct
            } else if specular_only {
                PathClass::Caustic
            } else {
                PathClass::Indirect
            };
            let n = if hit.ng.dot(wi) > 0.0 {
                hit.ng
            } else {
                -hit.ng
            };
            store(Photon::new(hit.p, flux, wi, n).with_depth(hits), class);
            if opts.stop_at_diffuse {
                return;
            }
            specular_only = false;
        }
        if hits >= opts.max_depth {
            return;
        }
        let (u, uc) = (rng.next_2d(), rng.next_f32());
        let Some(bs) = material.sample(wi, hit.ng, u, uc, TransportMode::Importance) else {
            return;
        };
        // Russian roulette on the scattering weight (the reflectance for a Lambertian
        // surface): a survivor's flux is divided by its survival probability, so the flux is
        // kept in expectation and a grey surface keeps every photon's power unchanged.
        let survive = bs.weight.max_element().min(1.0);
        if survive <= 0.0 || rng.next_f32() >= survive {
            return;
        }
        flux *= bs.weight / survive;
        ray = Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi);
    }
}

/// Traces `opts.photons` photons in parallel and sorts the stored photons into `lists`
/// lists: `sort(class)` names the list a photon goes to, or None to drop it. Photons keep
/// the order they were emitted in (deterministic).
pub fn trace_photons(
    scene: &Scene,
    opts: &TraceOptions,
    ctx: &RenderContext<'_>,
    lists: usize,
    sort: impl Fn(PathClass) -> Option<usize> + Sync,
) -> Result<Vec<Vec<Photon>>> {
    ctx.progress.begin("photons", opts.photons);
    let chunks = opts.photons.div_ceil(CHUNK);
    let parts: Vec<Vec<Vec<Photon>>> = with_pool(ctx.threads, || {
        (0..chunks)
            .into_par_iter()
            .map(|c| {
                let mut out = vec![Vec::new(); lists];
                if ctx.cancelled() {
                    return out;
                }
                let end = ((c + 1) * CHUNK).min(opts.photons);
                for i in c * CHUNK..end {
                    trace_one(scene, opts, i, |p, class| {
                        if let Some(list) = sort(class) {
                            out[list].push(p);
                        }
                    });
                }
                ctx.progress.advance(end - c * CHUNK);
                out
            })
            .collect()
    })?;
    ctx.progress.finish();
    let mut result = vec![Vec::new(); lists];
    for part in parts {
        for (list, photons) in result.iter_mut().zip(part) {
            list.extend(photons);
        }
    }
    Ok(result)
}
