//! `foton bench`: a scene rendered several times, the best time reported as samples (or
//! photons and iterations) and rays per second; the Cornell box when no scene is given.

use crate::TermProgress;
use crate::common::{
    INTERRUPTED, Overrides, PluginArgs, Prepared, prepare, prepare_scene, render_prepared,
    render_with, threads, warn,
};
use crate::compare::json::json_string;
use clap::Args;
use foton_core::error::{Error, Result};
use foton_core::film::Film;
use foton_core::integrator::{Progress, RenderContext, peak_rss_bytes, process_cpu_time};
use foton_core::plugin::search_path;
use foton_core::value::Document;
use foton_loader::TomlDocument;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// The scene `foton bench` renders when given none: the README's default scene.
const DEFAULT_SCENE: &str = include_str!("../../../scenes/cornell-box.toml");
const DEFAULT_SCENE_NAME: &str = "scenes/cornell-box.toml";

#[derive(Args)]
pub(crate) struct BenchArgs {
    /// The scene to render (default: the Cornell box of scenes/cornell-box.toml, built into
    /// the program so that the benchmark runs from any folder).
    scene: Option<PathBuf>,
    #[command(flatten)]
    overrides: Overrides,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Number of timed renders (the best is reported).
    #[arg(long, default_value_t = 3)]
    repeat: u32,
    /// Override any scene value by its dotted TOML key path (repeatable).
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    sets: Vec<String>,
    /// Write a phase profile to this JSON file: the scene loaded and rendered once on one
    /// thread and once on all (`--threads`), each phase's wall and CPU seconds, the serial
    /// fraction and the speed-ups Amdahl's law predicts at 16 and 64 threads, peak memory.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Traverse the scene's BVH with obvhs' own traversal of its compressed wide BVH instead
    /// of foton's float nodes: to measure what those give (the image differs only where a
    /// ray starts within 1e-4 of another surface, which obvhs' traversal does not see).
    #[arg(long, alias = "narrow-bvh")]
    obvhs_traversal: bool,
    #[command(flatten)]
    plugins: PluginArgs,
}

pub(crate) fn run(a: BenchArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let mut overrides = a.sets.clone();
    a.overrides.push_onto(&mut overrides);
    let load = || -> Result<Prepared> {
        match &a.scene {
            Some(path) => prepare(path, &overrides, &a.plugins.plugin_dirs, false),
            None => {
                let mut doc = Document::parse(DEFAULT_SCENE, Path::new(DEFAULT_SCENE_NAME))?;
                for o in &overrides {
                    doc.set(o)?;
                }
                let scene = foton_loader::from_document(doc)?;
                prepare_scene(scene, &search_path(&a.plugins.plugin_dirs), false)
            }
        }
    };
    if let Some(json) = &a.json {
        return profile(&a, &load, json, out, err);
    }
    let mut p = load()?;
    warn(err, &p.warnings);
    if a.obvhs_traversal {
        p.scene.accel_mut().set_wide(false);
    }
    let threads = threads(a.threads);
    let progress = TermProgress::new(true);
    INTERRUPTED.store(false, Ordering::SeqCst);
    let mut best = f64::INFINITY;
    let mut last = None;
    for i in 0..a.repeat.max(1) {
        let (film, t) = render_prepared(&p, threads, &progress)?;
        let _ = writeln!(out, "run {}: {:.3} s", i + 1, t.as_secs_f64());
        best = best.min(t.as_secs_f64());
        last = Some(film);
    }
    let film = last.expect("at least one run");
    let rate = |n: u64| n as f64 / best / 1e6;
    let work = if film.iterations > 0 {
        format!(
            "{} iterations of {} photons, {threads} threads: best {best:.3} s, {:.3} M photons/s, {:.2} iterations/s",
            film.iterations,
            film.photons / film.iterations,
            rate(film.photons),
            film.iterations as f64 / best
        )
    } else {
        format!(
            "{} spp, {threads} threads: best {best:.3} s, {:.3} M samples/s",
            p.scene.render().spp,
            rate(film.total_samples())
        )
    };
    let _ = writeln!(
        out,
        "{} with {}: {}x{} x {work}, {:.3} M rays/s, BVH traversed {}",
        p.scene.file().display(),
        p.integrator.describe(),
        p.scene.film().width,
        p.scene.film().height,
        rate(film.rays),
        if p.scene.accel().wide() {
            "through float nodes"
        } else {
            "by obvhs"
        }
    );
    Ok(0)
}

/// Wall and CPU time summed per phase name, in the order the phases first ran.
#[derive(Default)]
struct Phases(Vec<(String, Duration, Duration)>);

impl Phases {
    fn add(&mut self, name: &str, wall: Duration, cpu: Duration) {
        match self.0.iter_mut().find(|(n, _, _)| n == name) {
            Some((_, w, c)) => {
                *w += wall;
                *c += cpu;
            }
            None => self.0.push((name.to_string(), wall, cpu)),
        }
    }

    fn get(&self, name: &str) -> (f64, f64) {
        self.0
            .iter()
            .find(|(n, _, _)| n == name)
            .map_or((0.0, 0.0), |(_, w, c)| (w.as_secs_f64(), c.as_secs_f64()))
    }
}

/// The terminal's progress, with the phases a render reports recorded.
struct PhaseLog<'a> {
    inner: &'a dyn Progress,
    phases: Mutex<Phases>,
}

impl Progress for PhaseLog<'_> {
    fn begin(&self, phase: &str, total: u64) {
        self.inner.begin(phase, total);
    }
    fn advance(&self, units: u64) {
        self.inner.advance(units);
    }
    fn finish(&self) {
        self.inner.finish();
    }
    fn warn(&self, message: &str) {
        self.inner.warn(message);
    }
    fn rays(&self, n: u64) {
        self.inner.rays(n);
    }
    fn status(&self, text: &str) {
        self.inner.status(text);
    }
    fn checkpoint(&self, iteration: u64, image: &dyn Fn() -> Film) {
        self.inner.checkpoint(iteration, image);
    }
    fn phase(&self, name: &str, wall: Duration, cpu: Duration) {
        self.phases
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .add(name, wall, cpu);
    }
}

const LOAD: &str = "scene load and BVH build";
const OTHER: &str = "other (integrator set-up)";

/// Loads and renders the scene on `threads` threads (the load in a pool of that size too):
/// its phases, with the load and the rest of the render as phases of their own, and the
/// render's description.
fn profile_run(
    load: &(dyn Fn() -> Result<Prepared> + Sync),
    threads: usize,
    err: &mut dyn Write,
) -> Result<(Phases, String)> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Usage(format!("cannot start {threads} threads: {e}")))?;
    let (wall, cpu) = (Instant::now(), process_cpu_time());
    let p = pool.install(load)?;
    let mut phases = Phases::default();
    phases.add(LOAD, wall.elapsed(), process_cpu_time().saturating_sub(cpu));
    warn(err, &p.warnings);
    let progress = crate::TermProgress::new(true);
    let log = PhaseLog {
        inner: &progress,
        phases: Mutex::new(Phases::default()),
    };
    let ctx = RenderContext::new(threads, &INTERRUPTED, &log);
    let (wall, cpu) = (Instant::now(), process_cpu_time());
    render_with(&p, &ctx)?;
    let (wall, cpu) = (wall.elapsed(), process_cpu_time().saturating_sub(cpu));
    let rendered = log.phases.into_inner().unwrap_or_else(|e| e.into_inner());
    let (mut w, mut c) = (wall, cpu);
    for (name, pw, pc) in rendered.0 {
        w = w.saturating_sub(pw);
        c = c.saturating_sub(pc);
        phases.add(&name, pw, pc);
    }
    phases.add(OTHER, w, c);
    let what = format!(
        "{} with {}",
        p.scene.file().display(),
        p.integrator.describe()
    );
    Ok((phases, what))
}

/// Amdahl's law: the speed-up on `n` threads of work whose fraction `f` is serial.
fn amdahl(f: f64, n: f64) -> f64 {
    1.0 / (f + (1.0 - f) / n)
}

/// `foton bench --json`: the phase profile (see [`BenchArgs::json`]).
fn profile(
    a: &BenchArgs,
    load: &(dyn Fn() -> Result<Prepared> + Sync),
    json: &Path,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<u8> {
    let n = threads(a.threads);
    INTERRUPTED.store(false, Ordering::SeqCst);
    let (one, what) = profile_run(load, 1, err)?;
    let (all, _) = profile_run(load, n, err)?;
    let total = |p: &Phases| {
        p.0.iter().fold((0.0, 0.0), |(w, c), (_, pw, pc)| {
            (w + pw.as_secs_f64(), c + pc.as_secs_f64())
        })
    };
    let (t1, tn) = (total(&one).0, total(&all).0);
    // The Karp-Flatt metric: the serial fraction that explains the measured speed-up.
    let serial = if n > 1 && tn > 0.0 {
        let speedup = t1 / tn;
        Some(((1.0 / speedup - 1.0 / n as f64) / (1.0 - 1.0 / n as f64)).clamp(0.0, 1.0))
    } else {
        None
    };
    let num = |x: f64| format!("{x:.6}");
    let mut s = String::from("{\n");
    s += &format!("  \"scene\": {},\n", json_string(&what));
    s += &format!("  \"threads\": {n},\n");
    s += "  \"phases\": [\n";
    let names: Vec<&String> = one.0.iter().map(|(name, _, _)| name).collect();
    let mut rows = Vec::new();
    for name in names.iter().copied().chain(
        all.0
            .iter()
            .map(|(name, _, _)| name)
            .filter(|name| !names.contains(name)),
    ) {
        let ((w1, c1), (wn, cn)) = (one.get(name), all.get(name));
        rows.push(format!(
            "    {{\"name\": {}, \"wall_1\": {}, \"cpu_1\": {}, \"wall_all\": {}, \"cpu_all\": {}}}",
            json_string(name),
            num(w1),
            num(c1),
            num(wn),
            num(cn)
        ));
    }
    s += &rows.join(",\n");
    s += "\n  ],\n";
    s += &format!(
        "  \"total\": {{\"wall_1\": {}, \"cpu_1\": {}, \"wall_all\": {}, \"cpu_all\": {}}},\n",
        num(t1),
        num(total(&one).1),
        num(tn),
        num(total(&all).1)
    );
    let opt = |x: Option<f64>| x.map_or("null".to_string(), num);
    s += &format!("  \"serial_fraction\": {},\n", opt(serial));
    s += &format!(
        "  \"predicted_speedup_16\": {},\n",
        opt(serial.map(|f| amdahl(f, 16.0)))
    );
    s += &format!(
        "  \"predicted_speedup_64\": {},\n",
        opt(serial.map(|f| amdahl(f, 64.0)))
    );
    s += &format!("  \"peak_rss_bytes\": {}\n", peak_rss_bytes());
    s += "}\n";
    crate::common::write_atomic(json, s.as_bytes())?;
    let _ = writeln!(out, "{what}: {t1:.3} s on 1 thread, {tn:.3} s on {n}");
    for (name, _, _) in &all.0 {
        let ((w1, _), (wn, cn)) = (one.get(name), all.get(name));
        let _ = writeln!(
            out,
            "  {name}: {w1:.3} s -> {wn:.3} s (CPU {cn:.3} s on {n} threads)"
        );
    }
    if let Some(f) = serial {
        let _ = writeln!(
            out,
            "serial fraction {f:.3}: Amdahl predicts {:.1}x on 16 threads, {:.1}x on 64",
            amdahl(f, 16.0),
            amdahl(f, 64.0)
        );
    }
    let _ = writeln!(out, "-> {}", json.display());
    Ok(0)
}
