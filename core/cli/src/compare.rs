//! `foton compare`: one scene rendered by several integrators, side by side in one labelled
//! image; against a reference, with a false-colour difference image and error numbers per
//! render. Each render is also written as EXR, and the numbers as JSON.

use crate::montage::{Image, Series, Tile, diverging, grid, log_log_plot, render_image};
use crate::{INTERRUPTED, PluginArgs, Prepared, TermProgress, beside_scene, prepare_xml, threads};
use crate::{render_prepared, write_atomic};
use clap::Args;
use foton_core::Rgb;
use foton_core::error::{Error, Result};
use foton_core::film::{DisplayTransform, Film, check_output};
use foton_core::integrator::{Budget, Work};
use foton_core::props::unknown_value;
use foton_core::sampling::SamplerKind;
use foton_loader::FilmFile;
use foton_loader::image::read_image;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Duration;

/// Added to the squared reference value in the relative error, so that black pixels of the
/// reference do not dominate it.
pub const REL_EPSILON: f64 = 1e-2;

#[derive(Args)]
pub(super) struct CompareArgs {
    /// The scene file (TOML, or a Mitsuba 3 scene: .xml).
    scene: PathBuf,
    /// NAME=VALUE: set a Mitsuba XML scene's <default name="NAME"> (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    defines: Vec<String>,
    /// Mitsuba XML scenes: leave out what foton cannot render yet (listed) instead of refusing.
    #[arg(long)]
    lenient: bool,
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
    #[arg(long, conflicts_with = "time", allow_negative_numbers = true, value_parser = crate::parse_spp)]
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
            let (p, r) = (
                foton_core::average(*p) as f64,
                foton_core::average(*r) as f64,
            );
            diverging(((p - r) / (r * r + REL_EPSILON).sqrt()) as f32)
        })
        .collect();
    Image {
        width,
        height,
        pixels,
    }
}

/// The cost of a render as a function of its budget n (samples per pixel, or iterations of a
/// progressive integrator), t(n) = fixed + n x per_unit, from the times t1 and t2 of renders
/// at n and 2n.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostModel {
    /// Seconds that do not grow with n (a photon mapper's photon pass).
    pub fixed: f64,
    pub per_unit: f64,
    /// The time of the longer calibration render (t2).
    pub longest: f64,
}

impl CostModel {
    /// per_unit = (t2 - t1) / n, bounded to [t2/20, t2/2] / n so that timer noise on a fast
    /// render cannot ask for an enormous budget; fixed = t2 - 2n per_unit.
    pub fn from_times(n: u32, t1: f64, t2: f64) -> CostModel {
        let n = n.max(1) as f64;
        let t2 = t2.max(1e-6);
        let per_unit = ((t2 - t1) / n).clamp(t2 / 20.0 / n, t2 / 2.0 / n);
        CostModel {
            fixed: (t2 - 2.0 * n * per_unit).max(0.0),
            per_unit,
            longest: t2,
        }
    }

    /// The budget n that fills `seconds`, at least 1.
    pub fn units_for(&self, seconds: f64) -> u32 {
        ((seconds - self.fixed) / self.per_unit)
            .floor()
            .clamp(1.0, u32::MAX as f64) as u32
    }
}

/// Calibration renders take at least this long (or a tenth of the budget, if that is less),
/// so that their times are not timer and scheduler noise.
pub const CALIBRATION_SECONDS: f64 = 0.05;

/// The cost model from renders at n and 2n units, n = 1 and then larger until the render at
/// 2n takes `min_seconds` (n at most 2^16). `seconds_of(n)` renders at n and returns its time.
fn calibrate_cost(
    min_seconds: f64,
    mut seconds_of: impl FnMut(u32) -> Result<f64>,
) -> Result<CostModel> {
    const MAX_UNITS: u32 = 1 << 16;
    let mut n = 1u32;
    loop {
        let t1 = seconds_of(n)?;
        let t2 = seconds_of(2 * n)?;
        if t2 >= min_seconds || n >= MAX_UNITS || INTERRUPTED.load(Ordering::SeqCst) {
            return Ok(CostModel::from_times(n, t1, t2));
        }
        let factor = (min_seconds / t2.max(1e-6)).ceil().clamp(2.0, 1024.0) as u32;
        n = n.saturating_mul(factor).min(MAX_UNITS);
    }
}

/// Samples per pixel that fill `budget` seconds, from the times of renders at 1 and 2 spp
/// (see `CostModel`).
pub fn spp_for_budget(budget: f64, t1: f64, t2: f64) -> u32 {
    CostModel::from_times(1, t1, t2).units_for(budget)
}

/// How `--time` gives an integrator a budget of S seconds, from its calibration renders.
#[derive(Clone, Debug, PartialEq)]
pub enum Plan {
    /// Samples per pixel (render.spp) fill the time.
    Samples(CostModel),
    /// A progressive integrator (its `Integrator::budget` counts iterations, sppm): the scene
    /// value at `key` fills the time; render.spp is not used.
    Iterations { cost: CostModel, key: String },
    /// An integrator with budgets that scale beside its samples (`Integrator::budget`'s
    /// `scaled`: a photon mapper's photon budgets): about half of the time goes to their fixed
    /// cost, half to camera samples. The scene's budgets are taken to belong to the time 2 x
    /// `photon_pass` (the measured fixed cost) and are scaled in proportion to the budget;
    /// spp = (S / 2) / `per_sample`.
    PhotonsAndSamples {
        per_sample: f64,
        photon_pass: f64,
        photons: Vec<(String, u64)>,
    },
    /// A budget that --time cannot set: the calibration render is the render.
    Fixed,
}

impl Plan {
    /// The scene values (`--set` overrides) that make the integrator take about `seconds`.
    pub fn settings(&self, seconds: f64) -> Vec<String> {
        match self {
            Plan::Samples(cost) => vec![format!("render.spp={}", cost.units_for(seconds))],
            Plan::Iterations { cost, key } => vec![format!("{key}={}", cost.units_for(seconds))],
            Plan::PhotonsAndSamples {
                per_sample,
                photon_pass,
                photons,
            } => {
                let half = seconds / 2.0;
                let spp = (half / per_sample).floor().clamp(1.0, u32::MAX as f64) as u32;
                let scale = half / photon_pass;
                let mut sets = vec![format!("render.spp={spp}")];
                for (key, n) in photons {
                    let scaled = if *n == 0 {
                        0
                    } else {
                        (*n as f64 * scale).round().clamp(1.0, 1e15) as u64
                    };
                    sets.push(format!("{key}={scaled}"));
                }
                sets
            }
            Plan::Fixed => Vec::new(),
        }
    }
}

/// "16 spp", "23 iterations" (a progressive integrator's iterations, as --time set them or
/// as its parameters say), or "own budget".
fn budget_text(p: &Prepared, settings: &[String]) -> String {
    match p.integrator.budget().work {
        Work::Samples => format!("{} spp", p.scene.render().spp),
        Work::Iterations { key } => {
            let set = settings
                .iter()
                .find_map(|s| s.strip_prefix(&format!("{key}=")).map(str::to_string));
            let name = key.rsplit('.').next().unwrap_or(&key);
            let given = || {
                p.integrator
                    .parameters()
                    .into_iter()
                    .find(|q| q.name == name)
                    .map(|q| q.value.to_string())
            };
            match set.or_else(given) {
                Some(n) => format!("{n} iterations"),
                None => "own budget".into(),
            }
        }
        Work::Own => "own budget".into(),
    }
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
    /// With --curve: the renders at the smaller budgets, then this one.
    curve: Vec<Point>,
}

/// One point of the error curve: a render at a budget of `budget` seconds.
struct Point {
    budget: f64,
    seconds: f64,
    errors: Errors,
    settings: Vec<String>,
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

fn json_settings(settings: &[String]) -> String {
    let items: Vec<String> = settings.iter().map(|x| json_string(x)).collect();
    format!("[{}]", items.join(", "))
}

fn json(scene: &Path, reference: Option<&Path>, time: Option<f64>, entries: &[Entry]) -> String {
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
    s += &format!("  \"time\": {},\n", time.map_or("null".into(), json_number));
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
        s += &format!("      \"set\": {},\n", json_settings(&e.settings));
        if !e.curve.is_empty() {
            s += "      \"curve\": [\n";
            for (j, p) in e.curve.iter().enumerate() {
                s += &format!(
                    "        {{\"budget\": {}, \"seconds\": {}, \"rel_mse\": {}, \"bias\": {}, \"set\": {}}}{}\n",
                    json_number(p.budget),
                    json_number(p.seconds),
                    json_number(p.errors.rel_mse),
                    json_number(p.errors.bias),
                    json_settings(&p.settings),
                    if j + 1 < e.curve.len() { "," } else { "" }
                );
            }
            s += "      ],\n";
        }
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

/// Calibrates how `--time` sets integrator `name`'s budget (see `Plan`), from what the
/// integrator says of its work (`Integrator::budget`): renders at n and 2n samples per pixel,
/// or iterations of a progressive integrator (`calibrate_cost`). With `Plan::Fixed` (a budget
/// of its own), also returns the one render made, which is then the render shown.
fn calibrate(
    name: &str,
    p: &mut Prepared,
    prep: &dyn Fn(&[String]) -> Result<Prepared>,
    budget: f64,
    threads: usize,
    err: &mut dyn Write,
) -> Result<(Plan, Option<(Film, Duration)>)> {
    let min_seconds = CALIBRATION_SECONDS.min(budget / 10.0);
    let Budget { work, scaled } = p.integrator.budget();
    match work {
        Work::Iterations { key } => {
            let cost = calibrate_cost(min_seconds, |n| {
                let q = prep(&[format!("{key}={n}")])?;
                Ok(render_timed(&q, threads, true, err)?.1.as_secs_f64())
            })?;
            let _ = writeln!(
                err,
                "note: `{name}` does not take its samples from render.spp: --time sets its iterations instead ({key})"
            );
            Ok((Plan::Iterations { cost, key }, None))
        }
        Work::Own => {
            let _ = writeln!(
                err,
                "warning: `{name}` sets its own budget, so --time cannot set it; it renders as the scene says"
            );
            let shown = render_timed(p, threads, true, err)?;
            Ok((Plan::Fixed, Some(shown)))
        }
        Work::Samples => {
            let cost = calibrate_cost(min_seconds, |n| {
                p.scene.render_mut().spp = n;
                Ok(render_timed(p, threads, true, err)?.1.as_secs_f64())
            })?;
            let plan = if scaled.is_empty() {
                Plan::Samples(cost)
            } else {
                Plan::PhotonsAndSamples {
                    per_sample: cost.per_unit,
                    // Not below the bound of the per-sample cost: noise on a fast photon pass
                    // would otherwise ask for an enormous number of photons.
                    photon_pass: cost.fixed.max(cost.longest / 20.0),
                    photons: scaled,
                }
            };
            Ok((plan, None))
        }
    }
}

/// The budgets of the error curve: `points` times from `budget` / 2^(points - 1) to `budget`,
/// each twice the one before.
pub fn curve_budgets(budget: f64, points: u32) -> Vec<f64> {
    (0..points)
        .map(|j| budget / 2f64.powi((points - 1 - j) as i32))
        .collect()
}

fn errors_text(e: Errors) -> String {
    format!("rel. MSE {:.4e}, bias {:+.3}%", e.rel_mse, e.bias * 100.0)
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
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| beside_scene(&a.scene, "compare.png"));
    check_output(&output)?;
    let stem = output
        .file_stem()
        .map_or_else(|| "compare".into(), |s| s.to_string_lossy().into_owned());
    let exr_of =
        |name: &str| output.with_file_name(format!("{stem}-{}.exr", name.replace(':', "-")));
    let json_path = output.with_file_name(format!("{stem}.json"));
    let curve_path = output.with_file_name(format!("{stem}-curve.png"));
    for name in &names {
        check_output(&exr_of(name))?;
    }
    if a.curve.is_some() {
        check_output(&curve_path)?;
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

    // The scene as the command line sets it for integrator `name`, plus `extra` overrides.
    let overrides = |name: &str, extra: &[String]| {
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
    };

    // Every integrator is created before anything renders: a misspelt name or a bad
    // parameter is reported at once, not after the first render.
    let mut prepared = Vec::new();
    let mut warned: Vec<String> = Vec::new();
    for name in &names {
        let p = prepare_xml(
            &a.scene,
            &overrides(name, &[]),
            &a.defines,
            a.lenient,
            &a.plugins.plugin_dirs,
            a.strict,
        )?;
        for w in &p.warnings {
            if !warned.contains(w) {
                let _ = writeln!(err, "warning: {w}");
                warned.push(w.clone());
            }
        }
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

    let threads = threads(a.threads);
    INTERRUPTED.store(false, Ordering::SeqCst);
    let interrupted = |err: &mut dyn Write| {
        let stop = INTERRUPTED.load(Ordering::SeqCst);
        if stop {
            let _ = writeln!(err, "interrupted: nothing written");
        }
        stop
    };
    let mut entries = Vec::new();
    for (name, mut p) in names.iter().zip(prepared) {
        // The scene with --time's choices for this integrator (warnings were printed above).
        let prep = |extra: &[String]| {
            prepare_xml(
                &a.scene,
                &overrides(name, extra),
                &a.defines,
                a.lenient,
                &a.plugins.plugin_dirs,
                a.strict,
            )
        };
        let mut curve = Vec::new();
        let (p, film, elapsed, settings) = match a.time {
            None => {
                let (film, elapsed) = render_timed(&p, threads, a.quiet, err)?;
                (p, film, elapsed, Vec::new())
            }
            Some(budget) => {
                let (plan, shown) = calibrate(name, &mut p, &prep, budget, threads, err)?;
                if interrupted(err) {
                    return Ok(130);
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
                        Some((ref film, t)) if is_last => (prep(&[])?, film.clone(), t),
                        _ => {
                            let q = prep(&settings)?;
                            let (film, t) = render_timed(&q, threads, a.quiet || !is_last, err)?;
                            (q, film, t)
                        }
                    };
                    if interrupted(err) {
                        return Ok(130);
                    }
                    if let (Some((_, _, r)), Some(_)) = (&reference, a.curve)
                        && shown.is_none()
                    {
                        let point = Point {
                            budget: b,
                            seconds: elapsed.as_secs_f64(),
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
            return Ok(130);
        }
        let spp = (p.integrator.budget().work == Work::Samples).then_some(p.scene.render().spp);
        let budget = budget_text(&p, &settings);
        let image = exr_of(name);
        film.write(&image, &p.scene.film().display())?;
        let errors = reference
            .as_ref()
            .map(|(_, _, r)| errors(&film.pixels(), r));
        let entry = Entry {
            name: name.clone(),
            description: p.integrator.describe(),
            spp,
            budget,
            seconds: elapsed.as_secs_f64(),
            settings,
            film,
            display: p.scene.film().display(),
            image,
            errors,
            curve,
        };
        let _ = write!(
            out,
            "{}: {} in {:.2} s -> {}",
            entry.description,
            entry.budget,
            entry.seconds,
            entry.image.display()
        );
        if !entry.settings.is_empty() {
            let _ = write!(out, " (--time chose {})", entry.settings.join(" "));
        }
        if let Some(e) = entry.errors {
            let _ = write!(out, "; {}", errors_text(e));
        }
        let _ = writeln!(out);
        entries.push(entry);
    }

    let mut tiles: Vec<Tile> = entries
        .iter()
        .map(|e| Tile {
            image: render_image(&e.film, &e.display, &output),
            label: vec![
                format!("{}: {}, {:.2} s", e.name, e.budget, e.seconds),
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
        json(&a.scene, a.reference.as_deref(), a.time, &entries).as_bytes(),
    )?;
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
            .scene
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let title = format!("{scene_name} {width}x{height}: error against render time");
        log_log_plot(&title, "render time (seconds)", "relative MSE", &series)
            .write(&curve_path)?;
        let _ = writeln!(
            out,
            "-> {}, {} and {}",
            output.display(),
            curve_path.display(),
            json_path.display()
        );
    } else {
        let _ = writeln!(out, "-> {} and {}", output.display(), json_path.display());
    }
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

    #[test]
    fn photon_budgets_and_samples_grow_with_the_time() {
        // A photon pass of 0.5 s at the scene's budgets, 0.05 s per sample per pixel: the
        // scene's budgets belong to 1 s; 10 s gets ten times the photons and 100 spp.
        let plan = Plan::PhotonsAndSamples {
            per_sample: 0.05,
            photon_pass: 0.5,
            photons: vec![
                ("integrators.photon.global_photons".into(), 200_000),
                ("integrators.photon.caustic_photons".into(), 0),
            ],
        };
        assert_eq!(
            plan.settings(10.0),
            [
                "render.spp=100",
                "integrators.photon.global_photons=2000000",
                "integrators.photon.caustic_photons=0"
            ]
        );
        assert_eq!(
            plan.settings(0.01)[..2],
            ["render.spp=1", "integrators.photon.global_photons=2000"]
        );
        let cost = CostModel::from_times(1, 1.125, 1.25);
        assert_eq!(
            Plan::Iterations {
                cost,
                key: "integrators.sppm.iterations".into()
            }
            .settings(10.0),
            ["integrators.sppm.iterations=72"]
        );
        assert_eq!(Plan::Samples(cost).settings(10.0), ["render.spp=72"]);
    }

    #[test]
    fn curve_budgets_double_up_to_the_time() {
        assert_eq!(curve_budgets(20.0, 5), [1.25, 2.5, 5.0, 10.0, 20.0]);
        assert_eq!(curve_budgets(1.0, 2), [0.5, 1.0]);
    }
}
