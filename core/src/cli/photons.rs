//! `foton photons`: a photon map seen from the scene camera, one dot per photon coloured by the
//! flux it carries, like the photon-map pictures of Jensen's book.
//!
//! The photons come from core's photon pass with the budgets and the classification of the
//! `photon` integrator (its `[integrators.photon]` table is read; the plugin is not loaded):
//! the global map holds the direct (L D) and indirect photons of `global_photons`, the caustic
//! map the L S+ D photons of `caustic_photons`, traced to their first diffuse hit only.

use super::{INTERRUPTED, PluginArgs, TermProgress, beside_scene, threads};
use crate::error::Result;
use crate::film::check_output;
use crate::integrator::RenderContext;
use crate::photon::Photon;
use crate::photon_trace::{
    PathClass, STREAM_CAUSTIC, STREAM_GLOBAL, STREAM_VOLUME, Site, TraceOptions, trace_photons,
};
use crate::props::Properties;
use crate::render::with_pool;
use crate::scene::Scene;
use crate::{Rgb, Vec3};
use clap::{Args, ValueEnum};
use glam::Vec2;
use rayon::prelude::*;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::Ordering;

/// The photon integrator's default budgets (integrators/photon: keep them equal).
const GLOBAL_PHOTONS: u64 = 200_000;
const CAUSTIC_PHOTONS: u64 = 100_000;
/// `vpm`'s default volume budget.
const VOLUME_PHOTONS: u64 = 200_000;

/// The fraction of drawn photons whose colour is not clipped: the exposure maps this
/// quantile of the photons' largest channel to 1.
pub const EXPOSURE_QUANTILE: f64 = 0.99;

/// A photon map that `foton photons` can draw. A new map (the volume photons of a volumetric
/// photon mapper) is one more variant and one more arm in [`MapKind::pass`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MapKind {
    /// Direct and indirect photons of the global budget (L D, and paths with a diffuse bounce
    /// before the last).
    Global,
    /// Caustic photons (L S+ D) of the caustic budget.
    Caustic,
    /// Photons at scattering events in participating media, of the volumetric photon
    /// mapper's volume budget (`[integrators.vpm]`).
    Volume,
}

/// How a map is filled: the photon pass to trace and which of its photons to keep.
struct Pass {
    opts: TraceOptions,
    site: Site,
    /// Which path classes (direct, caustic, indirect) are kept.
    classes: [bool; 3],
}

impl Pass {
    fn keeps(&self, site: Site, class: PathClass) -> bool {
        site == self.site
            && self.classes[match class {
                PathClass::Direct => 0,
                PathClass::Caustic => 1,
                PathClass::Indirect => 2,
            }]
    }
}

impl MapKind {
    pub fn name(self) -> &'static str {
        match self {
            MapKind::Global => "global",
            MapKind::Caustic => "caustic",
            MapKind::Volume => "volume",
        }
    }

    /// The integrator whose `[integrators.NAME]` table holds this map's budget.
    fn integrator(self) -> &'static str {
        match self {
            MapKind::Global | MapKind::Caustic => "photon",
            MapKind::Volume => "vpm",
        }
    }

    /// The pass of the photon integrators' `build_maps` that fills this map, with its budget
    /// read from `props` (the scene's `[integrators.photon]` or `[integrators.vpm]` table).
    fn pass(self, props: &Properties<'_>, scene: &Scene) -> Result<Pass> {
        let opts = |photons, stream, stop_at_diffuse| TraceOptions {
            photons,
            max_depth: scene.render.max_depth,
            seed: scene.render.seed,
            stream,
            stop_at_diffuse,
        };
        Ok(match self {
            MapKind::Global => {
                let photons = props.u64("global_photons", GLOBAL_PHOTONS)?;
                if photons == 0 {
                    return Err(props.error("global_photons", "must be at least 1"));
                }
                // L S+ D photons of the global budget are dropped: the caustic budget counts
                // them.
                Pass {
                    opts: opts(photons, STREAM_GLOBAL, false),
                    site: Site::Surface,
                    classes: [true, false, true],
                }
            }
            MapKind::Caustic => Pass {
                opts: opts(
                    props.u64("caustic_photons", CAUSTIC_PHOTONS)?,
                    STREAM_CAUSTIC,
                    true,
                ),
                site: Site::Surface,
                classes: [false, true, false],
            },
            // As vpm stores them: the first scattering events only when direct light is by
            // photons (with shadow rays, single scattering is not in the map).
            MapKind::Volume => Pass {
                opts: opts(
                    props.u64("volume_photons", VOLUME_PHOTONS)?,
                    STREAM_VOLUME,
                    false,
                ),
                site: Site::Volume,
                classes: [
                    props.choice("direct", &["nee", "photons"], "nee")? == "photons",
                    true,
                    true,
                ],
            },
        })
    }
}

#[derive(Args)]
pub(super) struct PhotonsArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// The photon map to draw.
    #[arg(long, value_enum, default_value_t = MapKind::Global)]
    map: MapKind,
    /// Output image (.png or .exr); default: <scene stem>-<map>-photons.png beside the scene.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Random seed (overrides render.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Override any scene value by its dotted TOML key path, e.g. --set
    /// integrators.photon.global_photons=50000 (repeatable).
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    sets: Vec<String>,
    /// Side of the square dot drawn for each photon, in pixels.
    #[arg(long, default_value_t = 1, value_name = "PIXELS",
          value_parser = clap::value_parser!(u32).range(1..=64))]
    dot: u32,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    /// Accepted so that command lines can be shared with `render`; `photons` loads no plugin
    /// (the photon pass is in core).
    #[command(flatten)]
    plugins: PluginArgs,
}

/// Where a photon shows on the film, if the camera sees it: in front of the camera, inside
/// the image, on the side of its surface that faces the camera (a volume photon has no
/// surface: its normal is zero), and not hidden.
fn visible_at(scene: &Scene, photon: &Photon) -> Option<Vec2> {
    let camera = &scene.camera;
    let film = camera.project(photon.position)?;
    let n = photon.normal();
    if n != Vec3::ZERO && n.dot(camera.position - photon.position) <= 0.0 {
        return None;
    }
    (!scene.occluded(camera.position, Vec3::ZERO, photon.position, n)).then_some(film)
}

/// The exposure: 1 over the `EXPOSURE_QUANTILE` quantile of the photons' largest channel.
/// Photons of one pass mostly carry the same flux (Russian roulette keeps it), so the bulk of
/// the dots come out at full brightness in their surface's colour.
fn exposure(powers: &[Rgb]) -> f32 {
    let mut peaks: Vec<f32> = powers.iter().map(|p| p.max_element()).collect();
    if peaks.is_empty() {
        return 1.0;
    }
    let i = ((peaks.len() - 1) as f64 * EXPOSURE_QUANTILE).round() as usize;
    let (_, q, _) = peaks.select_nth_unstable_by(i, f32::total_cmp);
    if *q > 0.0 && q.is_finite() {
        1.0 / *q
    } else {
        1.0
    }
}

pub(super) fn run(a: PhotonsArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let mut overrides = a.sets.clone();
    if let Some(seed) = a.seed {
        overrides.push(format!("render.seed={seed}"));
    }
    let scene = Scene::load(&a.scene, &overrides)?;
    let props = scene.integrator_properties(a.map.integrator())?;
    let pass = a.map.pass(&props, &scene)?;
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| beside_scene(&a.scene, &format!("{}-photons.png", a.map.name())));
    check_output(&output)?;
    for w in &scene.warnings {
        let _ = writeln!(err, "warning: {w}");
    }
    for (key, loc) in &scene.unused {
        let _ = writeln!(err, "warning: {loc}: `{key}`: unknown field, ignored");
    }

    let progress = TermProgress::new(a.quiet);
    INTERRUPTED.store(false, Ordering::SeqCst);
    let threads = threads(a.threads);
    let ctx = RenderContext {
        threads,
        cancel: &INTERRUPTED,
        progress: &progress,
    };
    let photons = trace_photons(&scene, &pass.opts, &ctx, 1, |site, c| {
        pass.keeps(site, c).then_some(0)
    })?
    .pop()
    .unwrap_or_default();
    for w in progress.take_warnings() {
        let _ = writeln!(err, "warning: {w}");
    }

    let at: Vec<Option<Vec2>> = with_pool(threads, || {
        photons.par_iter().map(|p| visible_at(&scene, p)).collect()
    })?;
    let drawn: Vec<(Vec2, Rgb)> = photons
        .iter()
        .zip(&at)
        .filter_map(|(p, at)| at.map(|film| (film, p.power())))
        .collect();
    let scale = exposure(&drawn.iter().map(|d| d.1).collect::<Vec<_>>());

    // Each pixel shows the mean colour of the dots covering it: density shows as coverage,
    // flux as colour.
    let (width, height) = (scene.film.width, scene.film.height);
    let mut sum = vec![Rgb::ZERO; width as usize * height as usize];
    let mut count = vec![0u32; sum.len()];
    let half = (a.dot as i64 - 1) / 2;
    for (film, power) in &drawn {
        let (cx, cy) = (film.x.floor() as i64 - half, film.y.floor() as i64 - half);
        for y in cy..cy + a.dot as i64 {
            for x in cx..cx + a.dot as i64 {
                if x >= 0 && y >= 0 && x < width as i64 && y < height as i64 {
                    let i = y as usize * width as usize + x as usize;
                    sum[i] += *power * scale;
                    count[i] += 1;
                }
            }
        }
    }
    let pixels: Vec<Rgb> = sum
        .iter()
        .zip(&count)
        .map(|(s, &n)| if n == 0 { Rgb::ZERO } else { *s / n as f32 })
        .collect();
    crate::film::write_image(&output, width, height, &pixels)?;

    let _ = writeln!(
        out,
        "{}: {} map: {} stored of {} photons emitted, {} drawn (visible from the camera), exposure x{:.4e} -> {}",
        scene.file.display(),
        a.map.name(),
        photons.len(),
        pass.opts.photons,
        drawn.len(),
        scale,
        output.display()
    );
    if INTERRUPTED.load(Ordering::SeqCst) {
        let _ = writeln!(
            err,
            "interrupted: drew the photons traced so far ({} stored)",
            photons.len()
        );
        return Ok(130);
    }
    if photons.is_empty() && a.map == MapKind::Caustic {
        let _ = writeln!(
            err,
            "note: no caustic photons: no photon reached a diffuse surface through specular surfaces only"
        );
    }
    Ok(0)
}
