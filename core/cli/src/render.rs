//! `foton render`: one scene to one image, or with `--part I/N` to a part file for
//! `foton merge`; a summary line of the work done, and what an interrupted render kept.

use crate::common::{INTERRUPTED, RunArgs, SceneArgs, render_with, warn};
use crate::montage::{Image, Tile, grid};
use crate::{TermProgress, part, time_limit};
use clap::Args;
use foton_core::Rgb;
use foton_core::error::{Error, Result};
use foton_core::film::{DisplayTransform, Film, ImageFormat, check_output, format_of};
use foton_core::integrator::{Part, RenderContext};
use foton_core::scene::Scene;
use foton_loader::FilmFile;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Duration;

#[derive(Args)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image (.exr or .png); default: film.output, relative to the scene file.
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[command(flatten)]
    run: RunArgs,
    /// Progressive integrators (sppm): write the image to the output file every N
    /// iterations (atomically), so that it can be watched as it converges.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    checkpoint: Option<u64>,
    /// Render the I-th (from 0) of N disjoint shares of the work and write a part file (.exr)
    /// for `foton merge`: camera samples are split (path, photon, vpm: every part builds the
    /// same photon maps), or iterations (sppm, radius_schedule = "global" only). Default
    /// output: <scene stem>-part-I-of-N.exr beside the scene.
    #[arg(long, value_name = "I/N", value_parser = part::parse_part)]
    part: Option<Part>,
    /// Also write each sampling technique's share of the image into the EXR, one layer per
    /// technique (channels <technique>.R, .G, .B), the layers summing to the image: bdpt's
    /// (s, t) strategies (s<s>t<t>, rest), the terms of the other estimators that combine
    /// techniques (docs/tools.md names them). EXR output only, not with --part; integrators
    /// without techniques refuse it.
    #[arg(long)]
    techniques: bool,
    /// With --techniques: the path length (edges, s + t - 1 in bdpt) up to which each
    /// strategy has a layer of its own; longer paths share one layer, `rest`.
    #[arg(long, value_name = "N", default_value_t = 5, requires = "techniques")]
    techniques_depth: u32,
    /// With --techniques: also write the layers as a labelled grid (.png through the scene's
    /// display transform, or .exr), the image last; bdpt's strategies as Veach's pyramid (row
    /// k = s + t - 1, column s).
    #[arg(long, value_name = "FILE", requires = "techniques")]
    techniques_grid: Option<PathBuf>,
}

pub(crate) fn run(a: RenderArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let mut overrides = a.scene.overrides();
    let mut p = a.scene.prepare(&overrides)?;
    let output = match (&a.output, a.part) {
        (Some(o), _) => o.clone(),
        (None, Some(part)) => a
            .scene
            .file
            .beside(&format!("part-{}-of-{}.exr", part.index, part.count)),
        (None, None) => p.scene.film().output.clone(),
    };
    check_output(&output)?;
    if a.part.is_some() {
        if format_of(&output)? != ImageFormat::Exr {
            return Err(Error::Usage(format!(
                "--part writes exact per-pixel sums, which only EXR can hold: name the output .exr, not {}",
                output.display()
            )));
        }
        if a.checkpoint.is_some() {
            return Err(Error::Usage(
                "--checkpoint and --part: a part's image is not the render's, merge the parts to see it".into(),
            ));
        }
    }
    let techniques = a.techniques.then_some(a.techniques_depth);
    if let Some(depth) = techniques {
        if a.part.is_some() {
            return Err(Error::Usage(
                "--techniques and --part: a part file holds the image's exact sums only, not the technique layers; render the techniques in one process".into(),
            ));
        }
        if format_of(&output)? != ImageFormat::Exr {
            return Err(Error::Usage(format!(
                "--techniques writes the technique layers into an EXR: name the output .exr, not {}",
                output.display()
            )));
        }
        if let Some(grid) = &a.techniques_grid {
            check_output(grid)?;
        }
        if p.integrator.techniques(depth).is_empty() {
            return Err(Error::Usage(format!(
                "--techniques: {} has no techniques to show (it is one estimator; docs/tools.md lists the integrators that have them)",
                p.integrator.name()
            )));
        }
    }
    warn(err, &p.warnings);
    if let Some(seconds) = p.scene.render().time {
        if a.part.is_some() {
            return Err(Error::Usage(
                "--part and render.time: each part would fit its own samples to the time limit, and the parts would not merge; set render.spp instead".into(),
            ));
        }
        INTERRUPTED.store(false, Ordering::SeqCst);
        let fitted = time_limit::fit(&mut p, seconds.into(), a.run.threads(), &|extra| {
            let mut o = overrides.clone();
            o.extend_from_slice(extra);
            a.scene.prepare(&o)
        })?;
        if INTERRUPTED.load(Ordering::SeqCst) {
            let _ = writeln!(
                err,
                "interrupted while measuring the cost of a sample for render.time: nothing rendered"
            );
            return Ok(130);
        }
        if let time_limit::Fitted::Iterations { set, .. } = &fitted {
            overrides.push(set.clone());
            p = a.scene.prepare(&overrides)?;
        }
        let _ = match fitted.set() {
            Some(set) => writeln!(
                err,
                "note: render.time = {seconds} s: {} fill it (`--set {set}` renders the same image)",
                fitted.text()
            ),
            None => writeln!(
                err,
                "warning: render.time = {seconds} s: {} sets its own budget; the time limit does not apply",
                p.integrator.describe()
            ),
        };
    }
    let mut progress = TermProgress::new(a.run.quiet);
    if let Some(every) = a.checkpoint {
        progress = progress.with_checkpoint(
            every,
            output.clone(),
            p.scene.film().display(),
            p.scene.film().color_matrix(),
        );
    }
    INTERRUPTED.store(false, Ordering::SeqCst);
    let threads = a.run.threads();
    let ctx = RenderContext {
        part: a.part.unwrap_or(Part::WHOLE),
        techniques,
        ..RenderContext::new(threads, &INTERRUPTED, &progress)
    };
    let (film, elapsed) = render_with(&p, &ctx)?;
    if let Some(depth) = techniques {
        let names: Vec<&str> = film.layers().iter().map(|l| l.name.as_str()).collect();
        if names != p.integrator.techniques(depth) {
            return Err(Error::Render(format!(
                "--techniques: {} returned the layers [{}], not the ones it names",
                p.integrator.name(),
                names.join(", ")
            )));
        }
    }
    if a.checkpoint.is_some() && progress.checkpoints.load(Ordering::Relaxed) == 0 {
        let _ = writeln!(
            err,
            "warning: --checkpoint: {} is not progressive and wrote no intermediate image",
            p.integrator.describe()
        );
    }
    warn(err, progress.take_warnings());
    let of_part = match a.part {
        Some(part) => {
            // The defines change an XML scene as overrides do.
            let mut hashed = overrides.clone();
            hashed.extend(a.scene.file.defines.iter().map(|d| format!("-D {d}")));
            let info = part::PartInfo::of(&p.scene, &hashed, &p.integrator.describe(), &film)?;
            part::write_part(&output, &film, &info, &[])?;
            format!(", part {part}")
        }
        None => {
            film.write(&output, &p.scene.film().display())?;
            if let Some(grid) = &a.techniques_grid {
                technique_grid(&film, &p.scene.film().display(), grid).write(grid)?;
            }
            String::new()
        }
    };
    let _ = writeln!(
        out,
        "{}: {}x{}{of_part}, {} with {} -> {}",
        p.scene.file().display(),
        film.width,
        film.height,
        work_done(&film, elapsed, threads),
        p.integrator.describe(),
        output.display()
    );
    if INTERRUPTED.load(Ordering::SeqCst) {
        let _ = writeln!(
            err,
            "interrupted: {}",
            kept_after_interrupt(&film, &p.scene)
        );
        return Ok(130);
    }
    Ok(0)
}

/// The technique layers of `film` as one labelled grid for `output`, each tile shown as
/// `foton render` would write it (a PNG through `display`), the image (their sum) last. Layers
/// named `s<s>t<t>` (bdpt's strategies) make Veach's pyramid: row k = s + t - 1 (the path
/// length), column s, blank cells to the right; the other layers (`rest`) follow in one row.
fn technique_grid(film: &Film, display: &DisplayTransform, output: &Path) -> Image {
    let png = matches!(format_of(output), Ok(ImageFormat::Png));
    let tile = |mut pixels: Vec<Rgb>, label: &str| {
        if png {
            pixels.iter_mut().for_each(|p| *p = display.map(*p));
        }
        Tile {
            image: Image {
                width: film.width,
                height: film.height,
                pixels,
            },
            label: vec![label.to_string()],
        }
    };
    let blank = || Tile {
        image: Image::new(film.width, film.height, Rgb::ZERO),
        label: Vec::new(),
    };
    let strategy = |name: &str| -> Option<(u32, u32)> {
        let (s, t) = name.strip_prefix('s')?.split_once('t')?;
        Some((s.parse().ok()?, t.parse().ok()?))
    };
    let layers = film.layers();
    let longest = (layers.iter())
        .filter_map(|l| strategy(&l.name))
        .map(|(s, t)| s + t - 1)
        .max();
    let mut tiles = Vec::new();
    let columns = match longest {
        Some(longest) => {
            for k in 1..=longest {
                for s in 0..=longest {
                    let name = format!("s{s}t{}", (k + 1).saturating_sub(s));
                    match layers.iter().position(|l| s <= k && l.name == name) {
                        Some(i) => tiles.push(tile(film.layer_pixels(i), &name)),
                        None => tiles.push(blank()),
                    }
                }
            }
            longest as usize + 1
        }
        None => layers.len() + 1,
    };
    for (i, layer) in layers.iter().enumerate() {
        if strategy(&layer.name).is_none() {
            tiles.push(tile(film.layer_pixels(i), &layer.name));
        }
    }
    tiles.push(tile(film.pixels(), "image (the sum)"));
    grid(&tiles, columns)
}

/// A rate with a unit prefix that keeps its digits: "1.27 M", "4.8 k" (a progressive render of
/// a few thousand photons a pass read "0.00 M photons/s").
fn rate(per_second: f64) -> String {
    if per_second >= 1e6 {
        format!("{:.2} M", per_second / 1e6)
    } else if per_second >= 1e3 {
        format!("{:.1} k", per_second / 1e3)
    } else {
        format!("{per_second:.0}")
    }
}

/// What a render did, for its summary line: the iterations and photons of a progressive
/// integrator (its camera samples are one per pixel per iteration, a meaningless rate), or the
/// samples of the others.
fn work_done(film: &Film, elapsed: Duration, threads: usize) -> String {
    let secs = elapsed.as_secs_f64();
    let per_second = |n: u64| n as f64 / secs.max(1e-9);
    if film.iterations > 0 {
        format!(
            "{} iterations, {} photons in {secs:.2} s ({} photons/s, {:.2} iterations/s, {threads} threads)",
            film.iterations,
            film.photons,
            rate(per_second(film.photons)),
            per_second(film.iterations),
        )
    } else {
        let samples = film.total_samples();
        format!(
            "{samples} samples in {secs:.2} s ({} samples/s, {threads} threads)",
            rate(per_second(samples))
        )
    }
}

/// What an interrupted render wrote: the estimate of the iterations done (an iteration is
/// kept whole or dropped), or the samples done.
fn kept_after_interrupt(film: &Film, scene: &Scene) -> String {
    if film.iterations > 0 || film.iterations_planned > 0 {
        let of = match film.iterations_planned {
            0 => String::new(),
            n => format!(" of {n}"),
        };
        format!(
            "wrote the estimate of the {}{of} iterations done",
            film.iterations
        )
    } else {
        let share = film.part.share(scene.render().spp as u64);
        let full = film.width as u64 * film.height as u64 * (share.end - share.start);
        format!(
            "wrote the image of the {} of {full} samples done so far",
            film.total_samples()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::rate;

    #[test]
    fn rates_keep_their_digits() {
        assert_eq!(rate(1_270_000.0), "1.27 M");
        assert_eq!(rate(4_796.0), "4.8 k");
        assert_eq!(rate(12.4), "12");
    }
}
