//! `foton compare`: one scene rendered by several integrators, side by side in one labelled
//! image; against a reference, with a false-colour difference image and error numbers per
//! render (`metrics`). Each render is also written as EXR, and the numbers as JSON (`json`).
//! With `--time S` each integrator gets about S seconds (`budget`). With `--consistency N`
//! each renders N times and the pairs are tested block by block (`consistency`).

pub(crate) mod budget;
mod consistency;
mod flip;
pub(crate) mod json;
mod metrics;
pub mod report;

pub use budget::{CALIBRATION_SECONDS, CostModel, Plan, curve_budgets, spp_for_budget};
pub use flip::{default_ppd, flip};
pub use metrics::{Errors, REL_EPSILON, difference_image, errors};

use crate::TermProgress;
use crate::common::{
    INTERRUPTED, PluginArgs, Prepared, RunArgs, SceneFile, WarnOnce, parse_spp, render_with,
    write_atomic,
};
use crate::montage::{Series, Tile, grid, log_log_plot, render_image};
use budget::{budget_text, calibrate};
use clap::Args;
use consistency::{Estimate, MIN_RENDERS, Pair, Renders, block_means, block_variances};
use foton_core::Rgb;
use foton_core::error::{Error, Result};
use foton_core::film::{DisplayTransform, Film, check_output, check_writable, srgb_encode};
use foton_core::integrator::{RenderContext, Work, peak_rss_bytes};
use foton_core::props::unknown_value;
use foton_core::sampling::{SamplerKind, splitmix64};
use foton_loader::FilmFile;
use foton_loader::image::read_image;
use metrics::errors_text;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Duration;

#[derive(Args)]
pub(crate) struct CompareArgs {
    #[command(flatten)]
    file: SceneFile,
    /// The integrator plugins to compare, comma-separated (e.g. path,photon), left to right;
    /// NAME:SAMPLER renders with that sampler (path:sobol,path:independent).
    #[arg(
        long,
        value_delimiter = ',',
        required = true,
        value_name = "NAME,NAME..."
    )]
    integrators: Vec<String>,
    /// Samples per pixel for every integrator (overrides render.spp).
    #[arg(long, conflicts_with = "time", allow_negative_numbers = true, value_parser = parse_spp)]
    spp: Option<u32>,
    /// About S seconds of rendering per integrator: samples per pixel (a progressive
    /// integrator's iterations; a photon mapper's photon budgets and spp, half the time each)
    /// are chosen from short calibration renders and printed (docs/tools.md).
    #[arg(long, value_name = "S")]
    time: Option<f64>,
    /// A reference image (.exr linear, or .png sRGB) of the scene's size: adds a row of
    /// relative-difference images and the error numbers.
    #[arg(long, value_name = "IMAGE")]
    reference: Option<PathBuf>,
    /// With --time S and --reference: also render each integrator at N budgets S/2^(N-1),
    /// ..., S/2, S and plot the relative MSE against the seconds taken, log-log, as <output
    /// stem>-curve.png (the points go to the JSON).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=12))]
    curve: Option<u32>,
    /// Test whether the integrators converge to the same image: render each N times (N >= 4)
    /// with independent seeds and test, per 8x8 block of pixels, whether their means differ by
    /// more than their standard errors allow (Welch's t-test; false discovery rate 1% over the
    /// blocks, Benjamini-Hochberg); with --reference, each against it too. Prints a verdict per
    /// pair, writes the blocks that differ to <output stem>-consistency.png and the counts to
    /// the JSON; the EXRs and the image show the mean of the N renders. Exit status 3 when a
    /// pair differs.
    #[arg(long, value_name = "N")]
    consistency: Option<u32>,
    /// Keep each sampling technique's share of the image (as `foton render --techniques`) for
    /// the integrators that combine techniques: layers in their EXRs and, with --report, a
    /// grid of them per tab (bdpt's (s, t) strategies as Veach's pyramid). The others render
    /// their image alone.
    #[arg(long)]
    techniques: bool,
    /// With --techniques: the path length up to which each of bdpt's strategies has a layer
    /// of its own; longer paths share one layer, `rest`.
    #[arg(long, value_name = "N", default_value_t = 5, requires = "techniques")]
    techniques_depth: u32,
    /// With --consistency and --reference: the reference's per-pixel standard errors (an image
    /// of its size, .exr); without, the reference is taken as exact.
    #[arg(long, value_name = "IMAGE")]
    reference_se: Option<PathBuf>,
    /// Output image (.png or .exr); default: <scene stem>-compare.png beside the scene. The
    /// renders go beside it as <output stem>-<integrator>.exr, the numbers as <output
    /// stem>.json.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also write an interactive report: one self-contained HTML page with every image
    /// (tabs, zoom to the pixel, exposure, error images against the reference, the error
    /// curves, each run's numbers and this command line; docs/tools.md).
    #[arg(long, value_name = "FILE.html")]
    report: Option<PathBuf>,
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
    #[command(flatten)]
    run: RunArgs,
    #[command(flatten)]
    plugins: PluginArgs,
}

/// One integrator's render and its numbers.
struct Entry {
    name: String,
    description: String,
    /// None when the integrator does not take its samples from render.spp.
    spp: Option<u32>,
    /// "16 spp", "23 iterations", "own budget".
    budget: String,
    seconds: f64,
    /// The scene values --time chose (`--set` overrides), empty without --time.
    settings: Vec<String>,
    film: Film,
    /// The scene's exposure and tone map, for the render's tile in a PNG.
    display: DisplayTransform,
    image: PathBuf,
    errors: Option<Errors>,
    /// The mean LDR-FLIP error against the reference, both through `display` (`srgb`).
    flip: Option<f64>,
    /// The per-pixel LDR-FLIP error against the reference.
    flip_map: Option<Vec<f32>>,
    /// The photon (or beam) budgets in force, "key value" each.
    photons: Vec<String>,
    /// The process's peak resident memory when the render had ended.
    peak_rss_bytes: u64,
    /// With --curve: the renders at the smaller budgets, then this one.
    curve: Vec<Point>,
    /// What shrinks the bias of a biased-but-consistent integrator (`Integrator::bias`).
    bias: Option<String>,
    /// With --consistency N: the number of renders averaged in `film`.
    renders: u32,
}

impl Entry {
    /// The render's summary line.
    fn print(&self, out: &mut dyn Write) {
        let _ = write!(out, "{}: {}", self.description, self.budget);
        if self.renders > 1 {
            let _ = write!(
                out,
                ", mean of {} renders, {:.2} s each",
                self.renders, self.seconds
            );
        } else {
            let _ = write!(out, " in {:.2} s", self.seconds);
        }
        let _ = write!(out, " -> {}", self.image.display());
        if !self.settings.is_empty() {
            let _ = write!(out, " (--time chose {})", self.settings.join(" "));
        }
        if let Some(e) = self.errors {
            let _ = write!(out, "; {}", errors_text(e));
        }
        if let Some(f) = self.flip {
            let _ = write!(out, ", FLIP {f:.4}");
        }
        let _ = writeln!(out);
    }
}

/// One point of the error curve: a render at a budget of `budget` seconds.
struct Point {
    budget: f64,
    seconds: f64,
    /// Samples per pixel or iterations, where the integrator counts its work so.
    work: Option<f64>,
    errors: Errors,
    settings: Vec<String>,
}

/// The files a comparison writes.
struct Outputs {
    /// The labelled image.
    image: PathBuf,
    stem: String,
    json: PathBuf,
    /// The error curve's plot (--curve).
    curve: PathBuf,
    /// The map of the blocks that differ (--consistency).
    consistency: PathBuf,
}

impl Outputs {
    fn of(image: PathBuf) -> Outputs {
        let stem = image
            .file_stem()
            .map_or_else(|| "compare".into(), |s| s.to_string_lossy().into_owned());
        Outputs {
            json: image.with_file_name(format!("{stem}.json")),
            curve: image.with_file_name(format!("{stem}-curve.png")),
            consistency: image.with_file_name(format!("{stem}-consistency.png")),
            image,
            stem,
        }
    }

    /// The render of integrator `name` (NAME or NAME:SAMPLER).
    fn exr_of(&self, name: &str) -> PathBuf {
        let stem = &self.stem;
        self.image
            .with_file_name(format!("{stem}-{}.exr", name.replace(':', "-")))
    }
}

/// What the renders of one comparison share: its arguments, outputs, worker threads and the
/// reference's pixels.
struct Session<'a> {
    a: &'a CompareArgs,
    outputs: Outputs,
    threads: usize,
    reference: Option<Vec<Rgb>>,
}

impl Session<'_> {
    /// The scene as the command line sets it for integrator `name` (NAME or NAME:SAMPLER), plus
    /// `extra` overrides.
    fn overrides(&self, name: &str, extra: &[String]) -> Vec<String> {
        let a = self.a;
        let mut overrides = a.sets.clone();
        let (integrator, sampler) = name
            .split_once(':')
            .map_or((name, None), |(i, s)| (i, Some(s)));
        overrides.push(format!("render.integrator={integrator:?}"));
        if let Some(sampler) = sampler {
            overrides.push(format!("render.sampler={sampler:?}"));
        }
        if let Some(spp) = a.spp {
            overrides.push(format!("render.spp={spp}"));
        }
        if let Some(seed) = a.seed {
            overrides.push(format!("render.seed={seed}"));
        }
        overrides.extend_from_slice(extra);
        overrides
    }

    /// The scene and integrator `name` with `extra` overrides (--time's choices).
    fn prepare(&self, name: &str, extra: &[String]) -> Result<Prepared> {
        let a = self.a;
        a.file
            .prepare(&self.overrides(name, extra), &a.plugins, a.strict)
    }

    /// Renders `p` and returns the film and the time it took; the progress's warnings are
    /// printed with the integrator's name.
    fn render(&self, p: &Prepared, quiet: bool, err: &mut dyn Write) -> Result<(Film, Duration)> {
        let progress = TermProgress::new(quiet);
        let depth = self.a.techniques.then_some(self.a.techniques_depth);
        let ctx = RenderContext {
            techniques: depth.filter(|&d| !p.integrator.techniques(d).is_empty()),
            ..RenderContext::new(self.threads, &INTERRUPTED, &progress)
        };
        let result = render_with(p, &ctx);
        for w in progress.take_warnings() {
            let _ = writeln!(err, "warning: {}: {w}", p.plugin.name);
        }
        result
    }

    /// Renders integrator `name` (created as `p`): once, or with --time after calibrating its
    /// budget, and with --curve at every budget of the curve; with the integrator as it
    /// rendered (--time's choices set). None when interrupted.
    fn render_entry(
        &self,
        name: &str,
        mut p: Prepared,
        out: &mut dyn Write,
        err: &mut dyn Write,
    ) -> Result<Option<(Entry, Prepared)>> {
        let a = self.a;
        let mut curve = Vec::new();
        let (p, film, elapsed, settings) = match a.time {
            None => {
                // The scene's own time limit (render.time), where --time does not set one.
                if let Some(seconds) = p.scene.render().time {
                    let fitted =
                        crate::time_limit::fit(&mut p, seconds.into(), self.threads, &|extra| {
                            self.prepare(name, extra)
                        })?;
                    if let crate::time_limit::Fitted::Iterations { set, .. } = &fitted {
                        p = self.prepare(name, std::slice::from_ref(set))?;
                    }
                    let _ = writeln!(
                        err,
                        "note: `{name}`: render.time = {seconds} s: {}",
                        fitted.text()
                    );
                }
                let (film, elapsed) = self.render(&p, a.run.quiet, err)?;
                (p, film, elapsed, Vec::new())
            }
            Some(budget) => {
                let (plan, shown) = calibrate(self, name, &mut p, budget, err)?;
                if interrupted(err) {
                    return Ok(None);
                }
                let budgets = match (a.curve, &shown) {
                    (Some(points), None) => curve_budgets(budget, points),
                    (Some(_), Some(_)) => {
                        let _ = writeln!(
                            err,
                            "warning: `{name}`: no error curve, --time cannot set its budget"
                        );
                        vec![budget]
                    }
                    (None, _) => vec![budget],
                };
                let mut last = None;
                for (j, &b) in budgets.iter().enumerate() {
                    let settings = plan.settings(b);
                    let is_last = j + 1 == budgets.len();
                    let (q, film, elapsed) = match shown {
                        Some((ref film, t)) if is_last => {
                            (self.prepare(name, &[])?, film.clone(), t)
                        }
                        _ => {
                            let q = self.prepare(name, &settings)?;
                            let (film, t) = self.render(&q, a.run.quiet || !is_last, err)?;
                            (q, film, t)
                        }
                    };
                    if interrupted(err) {
                        return Ok(None);
                    }
                    if let (Some(r), Some(_)) = (&self.reference, a.curve)
                        && shown.is_none()
                    {
                        let point = Point {
                            budget: b,
                            seconds: elapsed.as_secs_f64(),
                            work: work_done(&q, &settings),
                            errors: errors(&film.pixels(), r),
                            settings: settings.clone(),
                        };
                        let _ = writeln!(
                            out,
                            "{name}, curve point {} of {} ({b:.3} s budget; {}): {:.2} s, {}",
                            j + 1,
                            budgets.len(),
                            settings.join(" "),
                            point.seconds,
                            errors_text(point.errors)
                        );
                        curve.push(point);
                    }
                    if is_last {
                        last = Some((q, film, elapsed, settings));
                    }
                }
                last.expect("at least one budget")
            }
        };
        if interrupted(err) {
            return Ok(None);
        }
        let spp = (p.integrator.budget().work == Work::Samples).then_some(p.scene.render().spp);
        let display = p.scene.film().display();
        let (errors, flip_mean, flip_map) = self.score(&film, &display);
        let photons = p
            .integrator
            .budget()
            .scaled
            .iter()
            .filter(|(key, _)| key.contains("photon") || key.contains("beam"))
            .map(|(key, n)| format!("{} {n}", key.rsplit('.').next().unwrap_or(key)))
            .collect();
        let entry = Entry {
            name: name.to_string(),
            description: p.integrator.describe(),
            spp,
            budget: budget_text(&p, &settings),
            seconds: elapsed.as_secs_f64(),
            settings,
            film,
            display,
            image: self.outputs.exr_of(name),
            errors,
            flip: flip_mean,
            flip_map,
            photons,
            peak_rss_bytes: peak_rss_bytes(),
            curve,
            bias: p.integrator.bias(),
            renders: 1,
        };
        Ok(Some((entry, p)))
    }

    /// The errors, the mean LDR-FLIP error and its per-pixel map of `film` against the
    /// reference, if there is one.
    fn score(
        &self,
        film: &Film,
        display: &DisplayTransform,
    ) -> (Option<Errors>, Option<f64>, Option<Vec<f32>>) {
        let Some(r) = &self.reference else {
            return (None, None, None);
        };
        let pixels = film.pixels();
        let (w, h) = (film.width as usize, film.height as usize);
        let (flip_map, flip_mean) = flip(
            &srgb(r, display),
            &srgb(&pixels, display),
            w,
            h,
            default_ppd(),
        );
        (Some(errors(&pixels, r)), Some(flip_mean), Some(flip_map))
    }

    /// --consistency N: renders the entry's integrator (`p`, as it rendered the entry) N - 1
    /// more times, each with its own seed (`repetition_seed`), and makes the entry the mean of
    /// the N renders (its film, errors and seconds per render). Returns the N renders, the
    /// entry's own first; None when interrupted.
    fn repeat(
        &self,
        entry: &mut Entry,
        p: &mut Prepared,
        n: u32,
        err: &mut dyn Write,
    ) -> Result<Option<Renders>> {
        let (w, h) = (entry.film.width, entry.film.height);
        let mut renders = Renders::new(w, h);
        renders.add(&entry.film.pixels());
        let mut seconds = entry.seconds;
        let base = p.scene.render().seed;
        for i in 1..n {
            p.scene.render_mut().seed = repetition_seed(base, i);
            let (film, elapsed) = self.render(p, self.a.run.quiet, err)?;
            if interrupted(err) {
                return Ok(None);
            }
            renders.add(&film.pixels());
            seconds += elapsed.as_secs_f64();
        }
        p.scene.render_mut().seed = base;
        let mut mean = Film::new(w, h);
        for (i, c) in renders.mean_pixels().into_iter().enumerate() {
            mean.set_pixel(i as u32 % w, i as u32 / w, c);
        }
        (entry.errors, entry.flip, entry.flip_map) = self.score(&mean, &entry.display);
        entry.film = mean;
        entry.seconds = seconds / n as f64;
        entry.renders = n;
        Ok(Some(renders))
    }
}

/// The seed of render `i` (0, 1, ...) of --consistency: the scene's seed for the first (the
/// render --consistency does not change), then seeds hashed from it and i.
fn repetition_seed(base: u64, i: u32) -> u64 {
    if i == 0 {
        base
    } else {
        splitmix64(base ^ splitmix64(0x636f_6e73_6973_7400 ^ i as u64))
    }
}

/// The display's sRGB values in [0, 1] of linear `pixels`: the scene's exposure and tone map
/// (`display`), then the sRGB curve, as a PNG of them (the montage's tiles) stores them before
/// quantisation to 8 bits. FLIP's input.
fn srgb(pixels: &[Rgb], display: &DisplayTransform) -> Vec<[f32; 3]> {
    pixels
        .iter()
        .map(|&p| display.map(p).to_array().map(srgb_encode))
        .collect()
}

/// Whether Ctrl-C stopped the comparison (then nothing is written, and it says so).
fn interrupted(err: &mut dyn Write) -> bool {
    let stop = INTERRUPTED.load(Ordering::SeqCst);
    if stop {
        let _ = writeln!(err, "interrupted: nothing written");
    }
    stop
}

/// The integrator names of `--integrators`, checked: none empty or twice, samplers known.
fn integrator_names(a: &CompareArgs) -> Result<Vec<String>> {
    let mut names: Vec<String> = Vec::new();
    for name in a.integrators.iter().map(|n| n.trim()) {
        if name.is_empty() {
            return Err(Error::Usage(format!(
                "--integrators {}: empty integrator name",
                a.integrators.join(",")
            )));
        }
        if let Some((_, sampler)) = name.split_once(':')
            && !SamplerKind::NAMES.contains(&sampler)
        {
            return Err(Error::Usage(format!(
                "--integrators {name}: sampler {}",
                unknown_value(sampler, &SamplerKind::NAMES)
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
    if let Some(n) = a.consistency {
        if n < MIN_RENDERS {
            return Err(Error::Usage(format!(
                "--consistency {n}: at least {MIN_RENDERS} renders per integrator are needed (the standard error of fewer has too few degrees of freedom to test with)"
            )));
        }
        if names.len() < 2 && a.reference.is_none() {
            return Err(Error::Usage(format!(
                "--consistency {n} needs two integrators or a --reference to test against"
            )));
        }
    }
    if a.reference_se.is_some() && (a.consistency.is_none() || a.reference.is_none()) {
        return Err(Error::Usage(
            "--reference-se IMAGE needs --consistency N and --reference REF: it is the reference's standard error, for the consistency test".into(),
        ));
    }
    if let Some(n) = a.curve {
        if a.time.is_none() {
            return Err(Error::Usage(format!(
                "--curve {n} needs --time S: the curve's budgets are S/2^{}, ..., S/2, S",
                n - 1
            )));
        }
        if a.reference.is_none() {
            return Err(Error::Usage(format!(
                "--curve {n} needs --reference REF: the curve is the error against a reference image (e.g. a long path-traced render of the scene)"
            )));
        }
    }
    Ok(names)
}

/// The reference image: its width, height and pixels.
fn read_reference(path: &Path) -> Result<(u32, u32, Vec<Rgb>)> {
    read_image(path).map_err(|e| match e {
        Error::Io { path, message } => Error::Io {
            path,
            message: format!("cannot read the reference image: {message}"),
        },
        other => other,
    })
}

pub(crate) fn run(a: CompareArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let names = integrator_names(&a)?;
    let outputs = Outputs::of(
        a.output
            .clone()
            .unwrap_or_else(|| a.file.beside("compare.png")),
    );
    check_output(&outputs.image)?;
    for name in &names {
        check_output(&outputs.exr_of(name))?;
    }
    if a.curve.is_some() {
        check_output(&outputs.curve)?;
    }
    if let Some(report) = &a.report {
        if !report
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"))
        {
            return Err(Error::io(
                report,
                "--report writes an HTML page: name it FILE.html",
            ));
        }
        check_writable(report)?;
    }
    if a.consistency.is_some() {
        check_output(&outputs.consistency)?;
    }
    let reference = a.reference.as_deref().map(read_reference).transpose()?;
    let reference_se = a.reference_se.as_deref().map(read_reference).transpose()?;
    let mut session = Session {
        a: &a,
        outputs,
        threads: a.run.threads(),
        reference: None,
    };

    // Every integrator is created before anything renders: a misspelt name or a bad
    // parameter is reported at once, not after the first render.
    let mut prepared = Vec::new();
    let mut warned = WarnOnce::default();
    for name in &names {
        let p = session.prepare(name, &[])?;
        warned.warn(err, &p.warnings);
        prepared.push(p);
    }
    let (width, height) = (
        prepared[0].scene.film().width,
        prepared[0].scene.film().height,
    );
    if let (Some((w, h, _)), Some(path)) = (&reference, &a.reference)
        && (*w, *h) != (width, height)
    {
        return Err(Error::io(
            path,
            format!("the reference is {w}x{h} but the scene renders {width}x{height}"),
        ));
    }
    if let (Some((w, h, _)), Some(path)) = (&reference_se, &a.reference_se)
        && (*w, *h) != (width, height)
    {
        return Err(Error::io(
            path,
            format!(
                "the reference's standard errors are {w}x{h} but the scene renders {width}x{height}"
            ),
        ));
    }
    session.reference = reference.map(|(_, _, pixels)| pixels);

    INTERRUPTED.store(false, Ordering::SeqCst);
    let mut entries = Vec::new();
    let mut repetitions = Vec::new();
    for (name, p) in names.iter().zip(prepared) {
        let Some((mut entry, mut p)) = session.render_entry(name, p, out, err)? else {
            return Ok(130);
        };
        if let Some(n) = a.consistency {
            let Some(renders) = session.repeat(&mut entry, &mut p, n, err)? else {
                return Ok(130);
            };
            repetitions.push(renders);
        }
        entry.film.write(&entry.image, &entry.display)?;
        entry.print(out);
        entries.push(entry);
    }

    let outputs = &session.outputs;
    let tiles = tiles(&entries, session.reference.as_deref(), &outputs.image);
    grid(&tiles, entries.len()).write(&outputs.image)?;
    let pairs = a.consistency.map(|_| {
        let reference = session.reference.as_deref().map(|r| {
            let var = reference_se
                .as_ref()
                .map(|(_, _, se)| block_variances(se, width, height));
            Estimate::reference(block_means(r, width, height), var)
        });
        consistency_pairs(&entries, &repetitions, reference.as_ref())
    });
    write_atomic(
        &outputs.json,
        json::json(
            &a.file.scene,
            a.reference.as_deref(),
            a.time,
            &entries,
            pairs.as_deref(),
        )
        .as_bytes(),
    )?;
    if let Some(pairs) = &pairs {
        let base = render_image(&entries[0].film, &entries[0].display, &outputs.consistency);
        consistency::map(&base, pairs).write(&outputs.consistency)?;
        for pair in pairs {
            let _ = writeln!(out, "{}", pair.verdict());
        }
        let _ = writeln!(out, "-> {}", outputs.consistency.display());
    }
    if a.curve.is_some() {
        let series: Vec<Series> = entries
            .iter()
            .map(|e| Series {
                name: e.name.clone(),
                points: e
                    .curve
                    .iter()
                    .map(|p| (p.seconds, p.errors.rel_mse))
                    .collect(),
            })
            .collect();
        let scene_name = a
            .file
            .scene
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let title = format!("{scene_name} {width}x{height}: error against render time");
        log_log_plot(&title, "render time (seconds)", "relative MSE", &series)
            .write(&outputs.curve)?;
        let _ = writeln!(
            out,
            "-> {}, {} and {}",
            outputs.image.display(),
            outputs.curve.display(),
            outputs.json.display()
        );
    } else {
        let _ = writeln!(
            out,
            "-> {} and {}",
            outputs.image.display(),
            outputs.json.display()
        );
    }
    if let Some(path) = &a.report {
        report::write(
            path,
            &report_of(&a, width, height, &entries, session.reference),
        )?;
        let _ = writeln!(out, "-> {}", path.display());
    }
    let differ = pairs.iter().flatten().any(Pair::differs);
    Ok(if differ { 3 } else { 0 })
}

/// --consistency: every pair of integrators tested (in the order given), then each against the
/// reference if there is one. `repetitions[i]`: entry i's renders.
fn consistency_pairs(
    entries: &[Entry],
    repetitions: &[Renders],
    reference: Option<&Estimate>,
) -> Vec<Pair> {
    let estimates: Vec<Estimate> = repetitions.iter().map(Renders::estimate).collect();
    let notes = |es: &[&Entry]| {
        es.iter()
            .filter_map(|e| e.bias.clone().map(|note| (e.name.clone(), note)))
            .collect()
    };
    let mut pairs = Vec::new();
    for i in 0..entries.len() {
        for j in i + 1..entries.len() {
            pairs.push(Pair {
                a: entries[i].name.clone(),
                b: entries[j].name.clone(),
                outcome: consistency::test(&estimates[i], &estimates[j]),
                biased: notes(&[&entries[i], &entries[j]]),
            });
        }
    }
    if let Some(r) = reference {
        for (e, estimate) in entries.iter().zip(&estimates) {
            pairs.push(Pair {
                a: e.name.clone(),
                b: "reference".into(),
                outcome: consistency::test(estimate, r),
                biased: notes(&[e]),
            });
        }
    }
    pairs
}

/// The samples per pixel or iterations of a render of `p` with `settings` (the number that
/// `budget_text` shows), where the integrator counts its work so.
fn work_done(p: &Prepared, settings: &[String]) -> Option<f64> {
    budget_text(p, settings).split(' ').next()?.parse().ok()
}

/// The interactive report's content: a tab per render, then the reference's.
fn report_of(
    a: &CompareArgs,
    width: u32,
    height: u32,
    entries: &[Entry],
    reference: Option<Vec<Rgb>>,
) -> report::Report {
    let scene_name = a
        .file
        .scene
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let mut tabs: Vec<report::Tab> = entries
        .iter()
        .map(|e| report::Tab {
            name: e.name.clone(),
            reference: false,
            pixels: e.film.pixels(),
            flip: e.flip_map.clone(),
            layers: (e.film.layers().iter().enumerate())
                .map(|(k, l)| (l.name.clone(), e.film.layer_pixels(k)))
                .collect(),
        })
        .collect();
    if let Some(pixels) = reference {
        tabs.push(report::Tab {
            name: "reference".into(),
            reference: true,
            pixels,
            flip: None,
            layers: Vec::new(),
        });
    }
    report::Report {
        title: format!("foton compare: {scene_name}"),
        command: report::command_line(std::env::args()),
        width,
        height,
        display: entries
            .first()
            .map_or_else(DisplayTransform::default, |e| e.display),
        tabs,
        runs: entries
            .iter()
            .map(|e| report::Run {
                name: e.name.clone(),
                description: e.description.clone(),
                budget: e.budget.clone(),
                photons: e.photons.join(", "),
                seconds: Some(e.seconds),
                peak_rss_bytes: Some(e.peak_rss_bytes),
                errors: e.errors,
                flip: e.flip,
            })
            .collect(),
        curves: entries
            .iter()
            .map(|e| {
                let points = e
                    .curve
                    .iter()
                    .map(|p| report::CurvePoint {
                        seconds: p.seconds,
                        work: p.work,
                        rel_mse: p.errors.rel_mse,
                    })
                    .collect();
                (e.name.clone(), points)
            })
            .collect(),
    }
}

/// The labelled tiles: the renders in a row, and with a reference their differences from it
/// in a second row.
fn tiles(entries: &[Entry], reference: Option<&[Rgb]>, output: &Path) -> Vec<Tile> {
    let mut tiles: Vec<Tile> = entries
        .iter()
        .map(|e| Tile {
            image: render_image(&e.film, &e.display, output),
            label: vec![
                if e.renders > 1 {
                    format!(
                        "{}: {}, mean of {}, {:.2} s each",
                        e.name, e.budget, e.renders, e.seconds
                    )
                } else {
                    format!("{}: {}, {:.2} s", e.name, e.budget, e.seconds)
                },
                // Narrow tiles: `k=50` wraps better than `k = 50`.
                e.description.replace(" = ", "="),
            ],
        })
        .collect();
    if let Some(r) = reference {
        for e in entries {
            let er = e.errors.expect("errors are computed with a reference");
            let bias = if er.bias.is_finite() {
                format!("{:+.2}%", er.bias * 100.0)
            } else {
                "n/a (black reference)".into()
            };
            tiles.push(Tile {
                image: difference_image(e.film.width, e.film.height, &e.film.pixels(), r),
                label: vec![
                    format!("{} vs reference", e.name),
                    format!("rel. MSE {:.3e}", er.rel_mse),
                    format!("bias {bias}"),
                ],
            });
        }
    }
    tiles
}
