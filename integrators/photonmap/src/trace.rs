//! The photon pass shared by the photon-mapping integrators: photons leave the lights (and
//! emitting media, `sources`) in proportion to power, walk the scene by BSDF sampling with Russian roulette, and are
//! offered for storage at every diffuse (non-delta) surface they reach, classified by the
//! path that brought them there (Jensen's L D, L S+ D and the rest).
//!
//! A photon leaving light l carries (power of l) / (pmf(l) x photons emitted); lights are
//! chosen with pmf proportional to power, so that is (total power) / (photons emitted),
//! counting the photons that hit nothing (`sources` says the same of media). Photon i draws from its own random stream, so the
//! maps are identical whatever the number of threads.

use crate::beams::{Beam, BeamKind, exit_distance};
use crate::map::Photon;
use crate::sources::Sources;
use foton_core::api::{
    HeroChannel, Ray, RayWalk, Reached, RenderContext, Result, Rgb, Rng, SOBOL_DIMENSIONS,
    SamplerKind, Scene, SobolPoint, TransportMode, offset_origin, splitmix64, with_pool,
};
use glam::Vec2;
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
    /// End each photon at its first non-delta bounce (a caustic pass has nothing to store
    /// after): at a diffuse surface after storing it, at a smooth plastic when it takes the
    /// base rather than the delta coat.
    pub stop_at_diffuse: bool,
    /// Emission (position, direction, light choice) from Owen-scrambled Sobol points indexed
    /// by photon number, scrambled per (seed, stream) so that passes differ (quasi-Monte Carlo
    /// photon mapping, Keller 1997); false: the photon's independent stream.
    pub sobol_emission: bool,
}

impl TraceOptions {
    /// Sobol emission when the scene's sampler is other than `independent`.
    pub fn emission_for(kind: SamplerKind) -> bool {
        kind.name() != "independent"
    }
}

/// Stream identifiers, so that passes draw independent random numbers.
pub const STREAM_GLOBAL: u64 = 0x676c_6f62;
pub const STREAM_CAUSTIC: u64 = 0x6361_7573;
pub const STREAM_VOLUME: u64 = 0x766f_6c75;

/// Photons per parallel work unit (also the granularity of progress reports): a 256th of the
/// pass, from 64 to 4096 (a progressive pass of a few thousand photons was one unit, traced on
/// one thread). The results do not depend on it: photon i's random numbers depend on i alone,
/// and the units' photons are joined in order.
fn chunk(photons: u64) -> u64 {
    photons.div_ceil(256).clamp(64, 4096)
}

/// Where a photon is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Site {
    /// On a diffuse (non-delta) surface.
    Surface,
    /// At a scattering event in a participating medium (its normal is zero).
    Volume,
}

/// Traces one photon, calling `store(photon, site, class)` at every diffuse surface hit and
/// every scattering event in a medium, from one of `sources` (the lights, emitting media).
/// A photon from an emitting medium is never in class `Direct` or `Caustic`: next-event
/// estimation and the caustic pass's light paths start at lights.
///
/// In a medium the photon samples a free-flight distance (spectral MIS over the colour
/// channels along its whole path, as the path tracer); at a scattering event it is stored
/// with its flux times the event's weight (sigma_s / sigma_t in a grey medium: stored
/// photons then have the density of scattered light, which the volume estimate needs), then
/// survives by Russian roulette on that weight (the albedo) and goes on in a phase-function-
/// sampled direction. Scattering events count toward `max_depth` like surface hits.
pub fn trace_one(
    scene: &Scene,
    opts: &TraceOptions,
    sources: &Sources,
    index: u64,
    store: impl FnMut(Photon, Site, PathClass),
) {
    trace_one_with_beams(scene, opts, sources, index, None, store, |_, _| {});
}

/// [`trace_one`], also calling `beam(beam, class)` for each flight through a medium that
/// interacts, as a beam of kind `beams` (None: no beams), before the flight is sampled; the
/// class is that of a light path scattering once on the beam. The photon walks exactly as in
/// [`trace_one`] (the same random numbers): beams are a record of its flights.
pub fn trace_one_with_beams(
    scene: &Scene,
    opts: &TraceOptions,
    sources: &Sources,
    index: u64,
    beams: Option<BeamKind>,
    mut store: impl FnMut(Photon, Site, PathClass),
    mut beam: impl FnMut(Beam, PathClass),
) {
    let mut rng = Rng::new(&[opts.seed, opts.stream, index]);
    // In the independent stream's order: light choice, position, direction, component.
    let mut u = [0.0f32; SOBOL_DIMENSIONS];
    if opts.sobol_emission {
        // Sobol's first dimensions are its best stratified together: position and direction
        // there, the light choice and the emission component after.
        let mut point = SobolPoint::new(index, splitmix64(opts.seed ^ opts.stream));
        for k in [1, 2, 3, 4, 0, 5] {
            u[k] = point.next_f32().expect("six Sobol dimensions");
        }
    } else {
        u.iter_mut().for_each(|u| *u = rng.next_f32());
    }
    let (u_pos, u_dir, uc) = (Vec2::new(u[1], u[2]), Vec2::new(u[3], u[4]), u[5]);
    let Some(emitted) = sources.sample(scene, u[0], u_pos, u_dir, uc) else {
        return;
    };
    let mut flux: Rgb = emitted.power / (emitted.pdf * opts.photons as f32);
    if emitted.from_medium && flux == Rgb::ZERO {
        return; // a point of the region's box where another medium is
    }
    let origin = if emitted.n == glam::Vec3::ZERO {
        emitted.origin
    } else {
        offset_origin(emitted.origin, emitted.n, emitted.dir)
    };
    let mut walk = RayWalk::new(Ray::new(origin, emitted.dir), emitted.medium);
    let mut hero: Option<HeroChannel> = None;
    let mut hits = 0u32;
    let mut specular_only = !emitted.from_medium;
    let class_of = |hits: u32, specular_only: bool| {
        if hits == 1 && emitted.nee {
            PathClass::Direct
        } else if specular_only {
            PathClass::Caustic
        } else {
            PathClass::Indirect
        }
    };
    loop {
        let seg = walk.segment(scene, &mut 0);
        if let Some(m) = seg.interacting_medium(scene) {
            let hero = hero.get_or_insert_with(|| HeroChannel::new(rng.next_f32()));
            let start = seg.start();
            let flight = m.sample_free_flight(&start, seg.length(), hero.channel, rng.next_f32());
            if let Some(kind) = beams {
                let end = match kind {
                    BeamKind::Short => flight.t,
                    BeamKind::Long => seg.length(),
                };
                // A beam without end (a long beam, or a short one whose hero channel does
                // not attenuate, leaving the scene in a medium) is cut at the scene's box.
                let length = if end.is_finite() {
                    end
                } else {
                    exit_distance(&start, scene.bounds())
                };
                if length > 0.0 {
                    beam(
                        Beam {
                            origin: start.origin,
                            dir: start.dir,
                            length,
                            flux,
                            hero_r: hero.r,
                            medium: seg.medium.expect("an interacting medium"),
                            depth: hits + 1,
                            kind,
                        },
                        class_of(hits + 1, specular_only),
                    );
                }
            }
            let weight = hero.update(&flight);
            if flight.scattered {
                hits += 1;
                let x = seg.at(flight.t);
                let scattered = flux * weight;
                if scattered == Rgb::ZERO {
                    return; // absorbed: a medium that does not scatter stores nothing
                }
                store(
                    Photon::new(x, scattered, -seg.ray.dir, glam::Vec3::ZERO).with_depth(hits),
                    Site::Volume,
                    class_of(hits, specular_only),
                );
                if opts.stop_at_diffuse {
                    return;
                }
                specular_only = false;
                if hits >= opts.max_depth {
                    return;
                }
                // Russian roulette on the albedo, as on a surface's reflectance.
                let survive = (scattered.max_element() / flux.max_element().max(1e-30)).min(1.0);
                if survive <= 0.0 || rng.next_f32() >= survive {
                    return;
                }
                flux = scattered / survive;
                let (wi, _) = m.phase().sample(seg.ray.dir, rng.next_2d());
                walk.scatter_in_medium(x, wi);
                continue;
            }
            flux *= weight;
            if flux == Rgb::ZERO {
                return;
            }
        }
        let Some(hit) = seg.hit else {
            return;
        };
        let bsdf = match walk.reach(scene, &hit) {
            Reached::Surface(bsdf) => bsdf,
            Reached::Crossed => continue,
            Reached::Ended => return,
        };
        hits += 1;
        let wi = -seg.ray.dir;
        if !bsdf.is_delta() {
            let n = if hit.ng.dot(wi) > 0.0 {
                hit.ng
            } else {
                -hit.ng
            };
            store(
                Photon::new(hit.p, flux, wi, n).with_depth(hits),
                Site::Surface,
                class_of(hits, specular_only),
            );
            if opts.stop_at_diffuse && bsdf.delta_probability(wi) == 0.0 {
                return;
            }
        }
        if hits >= opts.max_depth {
            return;
        }
        let (u, uc) = (rng.next_2d(), rng.next_f32());
        let Some(bs) = bsdf.sample(wi, u, uc, TransportMode::Importance) else {
            return;
        };
        // A bounce is specular by the lobe it took, not by the surface: a photon reflected by
        // a smooth plastic's delta coat is still on an L S+ path, as the camera walk and the
        // gather rays, which follow that coat by sampling, count it (the coat's light reaches
        // a diffuse point through the caustic map). Only a non-delta bounce makes the path
        // indirect, and ends a caustic pass's photon.
        if !bs.delta {
            if opts.stop_at_diffuse {
                return;
            }
            specular_only = false;
        }
        // Russian roulette on the scattering weight (the reflectance for a Lambertian
        // surface): a survivor's flux is divided by its survival probability, so the flux is
        // kept in expectation and a grey surface keeps every photon's power unchanged.
        let survive = bs.weight.max_element().min(1.0);
        if survive <= 0.0 || rng.next_f32() >= survive {
            return;
        }
        flux *= bs.weight / survive;
        walk.scatter_at_surface(scene, &hit, bs.wi);
    }
}

/// Traces `opts.photons` photons in parallel and sorts the stored photons into `lists`
/// lists: `sort(site, class)` names the list a photon goes to, or None to drop it. Photons
/// keep the order they were emitted in (deterministic).
pub fn trace_photons(
    scene: &Scene,
    opts: &TraceOptions,
    ctx: &RenderContext<'_>,
    lists: usize,
    sort: impl Fn(Site, PathClass) -> Option<usize> + Sync,
) -> Result<Vec<Vec<Photon>>> {
    Ok(trace_photons_and_beams(scene, opts, ctx, lists, sort, None, |_| false)?.0)
}

/// [`trace_photons`], also recording the photons' flights through media as beams of kind
/// `beams` (None: none), those whose class `keep_beam` accepts, in emission order.
pub fn trace_photons_and_beams(
    scene: &Scene,
    opts: &TraceOptions,
    ctx: &RenderContext<'_>,
    lists: usize,
    sort: impl Fn(Site, PathClass) -> Option<usize> + Sync,
    beams: Option<BeamKind>,
    keep_beam: impl Fn(PathClass) -> bool + Sync,
) -> Result<(Vec<Vec<Photon>>, Vec<Beam>)> {
    trace_photons_and_beams_indexed(
        scene,
        opts,
        ctx,
        lists,
        |site, class, _| sort(site, class),
        beams,
        |class, _| keep_beam(class),
    )
}

/// [`trace_photons_and_beams`] whose `sort` and `keep_beam` are also told the photon's index
/// (its place in emission order, 0 to `opts.photons` - 1).
pub fn trace_photons_and_beams_indexed(
    scene: &Scene,
    opts: &TraceOptions,
    ctx: &RenderContext<'_>,
    lists: usize,
    sort: impl Fn(Site, PathClass, u64) -> Option<usize> + Sync,
    beams: Option<BeamKind>,
    keep_beam: impl Fn(PathClass, u64) -> bool + Sync,
) -> Result<(Vec<Vec<Photon>>, Vec<Beam>)> {
    let sources = Sources::new(scene)?;
    ctx.progress.begin("photons", opts.photons);
    let chunk = chunk(opts.photons);
    let chunks = opts.photons.div_ceil(chunk);
    let _tracing = ctx.phase("photon tracing");
    let parts: Vec<(Vec<Vec<Photon>>, Vec<Beam>)> = with_pool(ctx.threads, || {
        (0..chunks)
            .into_par_iter()
            .map(|c| {
                let mut out = vec![Vec::new(); lists];
                let mut out_beams = Vec::new();
                if ctx.cancelled() {
                    return (out, out_beams);
                }
                let end = ((c + 1) * chunk).min(opts.photons);
                for i in c * chunk..end {
                    trace_one_with_beams(
                        scene,
                        opts,
                        &sources,
                        i,
                        beams,
                        |p, site, class| {
                            if let Some(list) = sort(site, class, i) {
                                out[list].push(p);
                            }
                        },
                        |b, class| {
                            if keep_beam(class, i) {
                                out_beams.push(b);
                            }
                        },
                    );
                }
                ctx.progress.advance(end - c * chunk);
                (out, out_beams)
            })
            .collect()
    })?;
    ctx.progress.finish();
    let mut result = vec![Vec::new(); lists];
    let mut all_beams = Vec::new();
    for (part, part_beams) in parts {
        for (list, photons) in result.iter_mut().zip(part) {
            list.extend(photons);
        }
        all_beams.extend(part_beams);
    }
    Ok((result, all_beams))
}
