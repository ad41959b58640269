//! `foton compare`: one scene rendered by several integrators, side by side in one labelled
//! image; against a reference, with a false-colour difference image and error numbers per
//! render. Each render is also written as EXR, and the numbers as JSON.

use super::montage::{Image, Tile, diverging, grid};
use super::{INTERRUPTED, PluginArgs, Prepared, TermProgress, beside_scene, prepare, threads};
use super::{render_prepared, write_atomic};
use crate::Rgb;
use crate::error::{Error, Result};
use crate::film::{Film, check_output, read_image};
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Duration;

/// Added to the squared reference value in the relative error, so that black pixels of the
/// reference do not dominate it.
pub const REL_EPSILON: f64 = 1e-2;

#[derive(Args)]
pub(super) struct CompareArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// The integrator plugins to compare, comma-separated (e.g. path,photon), left to right.
    #[arg(
        long,
        value_delimiter = ',',
        required = true,
        value_name = "NAME,NAME..."
    )]
    integrators: Vec<String>,
    /// Samples per pixel for every integrator (overrides render.spp).
    #[arg(long, conflicts_with = "time")]
    spp: Option<u32>,
    /// About S seconds of rendering per integrator: samples per pixel are chosen from two
    /// short calibration renders (1 and 2 spp) and printed.
    #[arg(long, value_name = "S")]
    time: Option<f64>,
    /// A reference image (.exr linear, or .png sRGB) of the scene's size: adds a row of
    /// relative-difference images and the error numbers.
    #[arg(long, value_name = "IMAGE")]
    reference: Option<PathBuf>,
    /// Output image (.png or .exr); default: <scene stem>-compare.png beside the scene. The
    /// renders go beside it as <output stem>-<integrator>.exr, the numbers as <output
    /// stem>.json.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Random seed (overrides render.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Override any scene value by its dotted TOML key path (repeatable); applies to every
    /// integrator.
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    sets: Vec<String>,
    /// Treat unknown (unused) scene fields and integrator parameters as errors.
    #[arg(long)]
    strict: bool,
    /// Worker threads (default: all cores). The images do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    plugins: PluginArgs,
}

/// Errors of a render against the reference, over all pixels and channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// mean of (x - ref)^2 / (ref^2 + REL_EPSILON).
    pub rel_mse: f64,
    /// (mean(x) - mean(ref)) / mean(ref); NaN when the reference is black.
    pub bias: f64,
}

pub fn errors(x: &[Rgb], reference: &[Rgb]) -> Errors {
    let (mut se, mut sx, mut sr) = (0.0f64, 0.0f64, 0.0f64);
    for (p, r) in x.iter().zip(reference) {
        for c in 0..3 {
            let (p, r) = (p[c] as f64, r[c] as f64);
            se += (p - r) * (p - r) / (r * r + REL_EPSILON);
            sx += p;
            sr += r;
        }
    }
    let n = (3 * x.len().max(1)) as f64;
    Errors {
        rel_mse: se / n,
        bias: if sr > 0.0 { (sx - sr) / sr } else { f64::NAN },
    }
}

/// The signed relative difference of each pixel's channel mean, (x - ref) / sqrt(ref^2 +
/// REL_EPSILON) (the square root of a pixel's term of the relative MSE, with its sign), in
/// false colour.
pub fn difference_image(width: u32, height: u32, x: &[Rgb], reference: &[Rgb]) -> Image {
    let pixels = x
        .iter()
        .zip(reference)
        .map(|(p, r)| {
            let (p, r) = (crate::average(*p) as f64, crate::average(*r) as f64);
            diverging(((p - r) / (r * r + REL_EPSILON).sqrt()) as f32)
        })
        .collect();
    Image {
        width,
        height,
        pixels,
    }
}

/// Samples per pixel that fill `budget` seconds, from the times of renders at 1 and 2 spp:
/// t(spp) = fixed + spp x per_sample. The per-sample cost is bounded to [t2/20, t2/2], so that
/// timer noise on a fast render cannot ask for an enormous number of samples.
pub fn spp_for_budget(budget: f64, t1: f64, t2: f64) -> u32 {
    let t2 = t2.max(1e-6);
    let per_sample = (t2 - t1).clamp(t2 / 20.0, t2 / 2.0);
    let fixed = (t2 - 2.0 * per_sample).max(0.0);
    ((budget - fixed) / per_sample)
        .floor()
        .clamp(1.0, u32::MAX as f64) as u32
}

/// Whether a film has the `spp` samples in every pixel that render.spp asked for. An
/// integrator with a budget of its own (sppm: iterations or time) writes one estimate per
/// pixel whatever render.spp says; with `spp` = 1 the two cannot be told apart.
fn takes_spp(film: &Film, spp: u32) -> bool {
    film.total_samples() == film.width as u64 * film.height as u64 * spp as u64
}

fn spp_text(spp: Option<u32>) -> String {
    spp.map_or_else(|| "own budget".into(), |n| format!("{n} spp"))
}

/// One integrator's render and its numbers.
struct Entry {
    name: String,
    description: String,
    /// None when the integrator does not take its samples from render.spp.
    spp: Option<u32>,
    seconds: f64,
    film: Film,
    image: PathBuf,
    errors: Option<Errors>,
}

fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn json_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".into()
    }
}

fn json(scene: &Path, reference: Option<&Path>, entries: &[Entry]) -> String {
    let file_name = |p: &Path| {
        p.file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    };
    let mut s = String::from("{\n");
    s += &format!(
        "  \"scene\": {},\n",
        json_string(&scene.display().to_string())
    );
    s += &format!(
        "  \"reference\": {},\n",
        reference.map_or("null".into(), |r| json_string(&r.display().to_string()))
    );
    s += "  \"integrators\": [\n";
    for (i, e) in entries.iter().enumerate() {
        let (rel_mse, bias) = e
            .errors
            .map_or((f64::NAN, f64::NAN), |er| (er.rel_mse, er.bias));
        s += "    {\n";
        s += &format!("      \"name\": {},\n", json_string(&e.name));
        s += &format!("      \"description\": {},\n", json_string(&e.description));
        s += &format!(
            "      \"spp\": {},\n",
            e.spp.map_or("null".into(), |n| n.to_string())
        );
        s += &format!("      \"seconds\": {},\n", json_number(e.seconds));
        s += &format!("      \"rel_mse\": {},\n", json_number(rel_mse));
        s += &format!("      \"bias\": {},\n", json_number(bias));
        s += &format!("      \"image\": {}\n", json_string(&file_name(&e.image)));
        s += if i + 1 < entries.len() {
            "    },\n"
        } else {
            "    }\n"
        };
    }
    s += "  ]\n}\n";
    s
}

fn render_timed(
    p: &Prepared,
    threads: usize,
    quiet: bool,
    err: &mut dyn Write,
) -> Result<(Film, Duration)> {
    let progress = TermProgress::new(quiet);
    let result = render_prepared(p, threads, &progress);
    for w in progress.take_warnings() {
        let _ = writeln!(err, "warning: {}: {w}", p.plugin.name);
    }
    result
}

pub(super) fn run(a: CompareArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let mut names: Vec<String> = Vec::new();
    for name in a.integrators.iter().map(|n| n.trim()) {
        if name.is_empty() {
            return Err(Error::Usage(format!(
                "--integrators {}: empty integrator name",
                a.integrators.join(",")
            )));
        }
        if names.iter().any(|n| n == name) {
            return Err(Error::Usage(format!(
                "--integrators: `{name}` is listed twice"
            )));
        }
        names.push(name.to_string());
    }
    if let Some(t) = a.time
        && !(t > 0.0 && t.is_finite())
    {
        return Err(Error::Usage(format!(
            "--time {t}: expected a positive number of seconds"
        )));
    }
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| beside_scene(&a.scene, "compare.png"));
    check_output(&output)?;
    let stem = output
        .file_stem()
        .map_or_else(|| "compare".into(), |s| s.to_string_lossy().into_owned());
    let exr_of = |name: &str| output.with_file_name(format!("{stem}-{name}.exr"));
    let json_path = output.with_file_name(format!("{stem}.json"));
    for name in &names {
        check_output(&exr_of(name))?;
    }
    let reference = match &a.reference {
        Some(path) => Some(read_image(path).map_err(|e| match e {
            Error::Io { path, message } => Error::Io {
                path,
                message: format!("cannot read the reference image: {message}"),
            },
            other => other,
        })?),
        None => None,
    };

    // Every integrator is created before anything renders: a misspelt name or a bad
    // parameter is reported at once, not after the first render.
    let mut prepared = Vec::new();
    let mut warned: Vec<String> = Vec::new();
    for name in &names {
        let mut overrides = a.sets.clone();
        overrides.push(format!("render.integrator={name:?}"));
        if let Some(spp) = a.spp {
            overrides.push(format!("render.spp={spp}"));
        }
        if let Some(seed) = a.seed {
            overrides.push(format!("render.seed={seed}"));
        }
        let p = prepare(&a.scene, &overrides, &a.plugins.plugin_dirs, a.strict)?;
        for w in &p.warnings {
            if !warned.contains(w) {
                let _ = writeln!(err, "warning: {w}");
                warned.push(w.clone());
            }
        }
        prepared.push(p);
    }
    let (width, height) = (prepared[0].scene.film.width, prepared[0].scene.film.height);
    if let (Some((w, h, _)), Some(path)) = (&reference, &a.reference)
        && (*w, *h) != (width, height)
    {
        return Err(Error::io(
            path,
            format!("the reference is {w}x{h} but the scene renders {width}x{height}"),
        ));
    }

    let threads = threads(a.threads);
    INTERRUPTED.store(false, Ordering::SeqCst);
    let mut entries = Vec::new();
    for (name, mut p) in names.iter().zip(prepared) {
        let mut rendered = None;
        if let Some(budget) = a.time {
            p.scene.render.spp = 1;
            let (_, t1) = render_timed(&p, threads, true, err)?;
            p.scene.render.spp = 2;
            let (film, t2) = render_timed(&p, threads, true, err)?;
            if takes_spp(&film, 2) {
                p.scene.render.spp = spp_for_budget(budget, t1.as_secs_f64(), t2.as_secs_f64());
            } else {
                // Its budget is its own (sppm's iterations or time): more samples per pixel
                // would not change the image, so the calibration render is the render.
                let _ = writeln!(
                    err,
                    "warning: `{name}` does not take its samples from render.spp, so --time cannot set its budget; give it its own (e.g. --set integrators.{name}.time={budget})"
                );
                rendered = Some((film, t2));
            }
        }
        let (film, elapsed) = match rendered {
            Some(r) => r,
            None => render_timed(&p, threads, a.quiet, err)?,
        };
        if INTERRUPTED.load(Ordering::SeqCst) {
            let _ = writeln!(err, "interrupted: nothing written");
            return Ok(130);
        }
        let spp = p.scene.render.spp;
        let spp = takes_spp(&film, spp).then_some(spp);
        let image = exr_of(name);
        film.write(&image)?;
        let errors = reference
            .as_ref()
            .map(|(_, _, r)| errors(&film.pixels(), r));
        let entry = Entry {
            name: name.clone(),
            description: p.integrator.describe(),
            spp,
            seconds: elapsed.as_secs_f64(),
            film,
            image,
            errors,
        };
        let _ = write!(
            out,
            "{}: {} in {:.2} s -> {}",
            entry.description,
            spp_text(entry.spp),
            entry.seconds,
            entry.image.display()
        );
        if let Some(e) = entry.errors {
            let _ = write!(
                out,
                "; rel. MSE {:.4e}, bias {:+.3}%",
                e.rel_mse,
                e.bias * 100.0
            );
        }
        let _ = writeln!(out);
        entries.push(entry);
    }

    let mut tiles: Vec<Tile> = entries
        .iter()
        .map(|e| Tile {
            image: Image::from_film(&e.film),
            label: vec![
                format!("{}: {}, {:.2} s", e.name, spp_text(e.spp), e.seconds),
                // Narrow tiles: `k=50` wraps better than `k = 50`.
                e.description.replace(" = ", "="),
            ],
        })
        .collect();
    if let Some((_, _, r)) = &reference {
        for e in &entries {
            let er = e.errors.expect("errors are computed with a reference");
            let bias = if er.bias.is_finite() {
                format!("{:+.2}%", er.bias * 100.0)
            } else {
                "n/a (black reference)".into()
            };
            tiles.push(Tile {
                image: difference_image(width, height, &e.film.pixels(), r),
                label: vec![
                    format!("{} vs reference", e.name),
                    format!("rel. MSE {:.3e}", er.rel_mse),
                    format!("bias {bias}"),
                ],
            });
        }
    }
    grid(&tiles, entries.len()).write(&output)?;
    write_atomic(
        &json_path,
        json(&a.scene, a.reference.as_deref(), &entries).as_bytes(),
    )?;
    let _ = writeln!(out, "-> {} and {}", output.display(), json_path.display());
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_of_an_identical_image_are_zero() {
        let x = [Rgb::new(0.1, 0.5, 2.0), Rgb::ZERO];
        assert_eq!(
            errors(&x, &x),
            Errors {
                rel_mse: 0.0,
                bias: 0.0
            }
        );
        let brighter: Vec<Rgb> = x.iter().map(|p| *p * 1.1).collect();
        let e = errors(&brighter, &x);
        assert!(e.rel_mse > 0.0);
        assert!((e.bias - 0.1).abs() < 1e-6, "{e:?}");
        assert!(errors(&x, &[Rgb::ZERO, Rgb::ZERO]).bias.is_nan());
    }

    #[test]
    fn budget_is_filled_and_fixed_costs_are_not_counted_per_sample() {
        // 1 s of photon pass, 1/8 s per sample: 10 s fit 72 samples.
        assert_eq!(spp_for_budget(10.0, 1.125, 1.25), 72);
        // Pure per-sample cost.
        assert_eq!(spp_for_budget(8.0, 0.5, 1.0), 16);
        // A noisy, faster second render does not ask for millions of samples.
        let spp = spp_for_budget(1.0, 0.02, 0.01);
        assert!((1000..=2000).contains(&spp), "{spp}");
        assert_eq!(spp_for_budget(0.001, 1.0, 2.0), 1);
    }

    #[test]
    fn json_escapes_strings_and_writes_null_for_missing_numbers() {
        assert_eq!(json_string("a\"b\\c\n"), "\"a\\\"b\\\\c\\n\"");
        assert_eq!(json_number(f64::NAN), "null");
        assert_eq!(json_number(0.0), "0");
        assert_eq!(json_number(0.25), "0.25");
    }
}
