//! `foton photons`: a photon map seen from the scene camera, one dot per photon coloured by the
//! flux it carries, like the photon-map pictures of Jensen's book.
//!
//! The photons are the ones the integrator would store: the tool asks the integrator plugin
//! for its maps (`Integrator::photon_maps`) and draws the one named by `--map`, so it works
//! for any integrator that exposes maps, a third party's included, and knows nothing of their
//! budgets or classifications.

use crate::TermProgress;
use crate::common::{INTERRUPTED, RunArgs, SceneArgs, blame_plugin, warn};
use clap::Args;
use foton_core::error::{Error, Result};
use foton_core::film::check_output;
use foton_core::integrator::{MapPhoton, RenderContext};
use foton_core::render::with_pool;
use foton_core::scene::Scene;
use foton_core::{Rgb, Vec3};
use glam::Vec2;
use rayon::prelude::*;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::Ordering;

/// The fraction of drawn photons whose colour is not clipped: the exposure maps this
/// quantile of the photons' largest channel to 1.
pub const EXPOSURE_QUANTILE: f64 = 0.99;

#[derive(Args)]
pub(crate) struct PhotonsArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// The photon map to draw, by the name the integrator gives it (`photon` and `vpm`:
    /// global, caustic; `vpm`: volume; `sppm`: the first iteration's photons, iteration);
    /// default: the integrator's first map.
    #[arg(long)]
    map: Option<String>,
    /// Output image (.png or .exr); default: <scene stem>-<map>-photons.png beside the scene.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Side of the square dot drawn for each photon, in pixels.
    #[arg(long, default_value_t = 1, value_name = "PIXELS",
          value_parser = clap::value_parser!(u32).range(1..=64))]
    dot: u32,
    #[command(flatten)]
    run: RunArgs,
}

/// Where a photon shows on the film, if the camera sees it: in front of the camera, inside
/// the image, on the side of its surface that faces the camera (a volume photon has no
/// surface: its normal is zero), and not hidden.
fn visible_at(scene: &Scene, photon: &MapPhoton) -> Option<Vec2> {
    let camera = &scene.camera();
    let film = camera.project(photon.position)?;
    let n = photon.normal;
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

pub(crate) fn run(a: PhotonsArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let p = a.scene.prepare(&a.scene.overrides())?;
    let scene = &p.scene;
    warn(err, &p.warnings);

    let progress = TermProgress::new(a.run.quiet);
    INTERRUPTED.store(false, Ordering::SeqCst);
    let threads = a.run.threads();
    let ctx = RenderContext::new(threads, &INTERRUPTED, &progress);
    let name = p.integrator.name().to_string();
    let mut maps = p
        .integrator
        .photon_maps(scene, &ctx)
        .map_err(|e| blame_plugin(&p.plugin, e))?;
    warn(err, progress.take_warnings());
    if maps.is_empty() {
        return Err(Error::Usage(format!(
            "integrator `{name}` builds no photon maps; name one that does with --integrator (e.g. photon, vpm, sppm)"
        )));
    }
    let index = match &a.map {
        None => 0,
        Some(wanted) => maps.iter().position(|m| &m.name == wanted).ok_or_else(|| {
            let names: Vec<&str> = maps.iter().map(|m| m.name.as_str()).collect();
            Error::Usage(format!(
                "--map {wanted}: integrator `{name}` has no such photon map; its maps: {}",
                names.join(", ")
            ))
        })?,
    };
    let map = maps.swap_remove(index);
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| a.scene.file.beside(&format!("{}-photons.png", map.name)));
    check_output(&output)?;
    let photons = &map.photons;

    let at: Vec<Option<Vec2>> = with_pool(threads, || {
        photons.par_iter().map(|p| visible_at(scene, p)).collect()
    })?;
    let drawn: Vec<(Vec2, Rgb)> = photons
        .iter()
        .zip(&at)
        .filter_map(|(p, at)| at.map(|film| (film, p.power)))
        .collect();
    let scale = exposure(&drawn.iter().map(|d| d.1).collect::<Vec<_>>());

    // Each pixel shows the mean colour of the dots covering it: density shows as coverage,
    // flux as colour.
    let (width, height) = (scene.film().width, scene.film().height);
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
    foton_loader::image::write_image(&output, width, height, &pixels, &scene.film().display())?;

    let _ = writeln!(
        out,
        "{}: {name} {} map ({}): {} stored of {} photons emitted, {} drawn (visible from the camera), exposure x{:.4e} -> {}",
        scene.file().display(),
        map.name,
        map.description,
        photons.len(),
        map.emitted,
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
    if photons.is_empty() {
        let _ = writeln!(
            err,
            "note: the {} map is empty: no photon was stored there",
            map.name
        );
    }
    Ok(0)
}
