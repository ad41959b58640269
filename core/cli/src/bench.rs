//! `foton bench`: a scene rendered several times, the best time reported as samples (or
//! photons and iterations) and rays per second; the Cornell box when no scene is given.

use crate::TermProgress;
use crate::common::{
    INTERRUPTED, Overrides, PluginArgs, prepare, prepare_scene, render_prepared, threads, warn,
};
use clap::Args;
use foton_core::error::Result;
use foton_core::plugin::search_path;
use foton_core::value::Document;
use foton_loader::TomlDocument;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

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
    let mut p = match &a.scene {
        Some(path) => prepare(path, &overrides, &a.plugins.plugin_dirs, false)?,
        None => {
            let mut doc = Document::parse(DEFAULT_SCENE, Path::new(DEFAULT_SCENE_NAME))?;
            for o in &overrides {
                doc.set(o)?;
            }
            let scene = foton_loader::from_document(doc)?;
            prepare_scene(scene, &search_path(&a.plugins.plugin_dirs), false)?
        }
    };
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
