//! The `foton` program: `render`, `check`, `plugins`, `bench`, `merge` (of the parts of a
//! render split with `render --part`, in `part`), and the tools for seeing and comparing,
//! `photons`, `compare` and `sweep` (one file each, their labelled images in `montage`, the
//! terminal progress in `progress`).
//!
//! A thin layer over foton-core: parse arguments (clap), load the scene, find the plugin, run
//! it, write the image. Errors are turned into messages here, once. Everything host-only lives
//! here and not in core (clap, indicatif, the Ctrl-C handler and its flag, the label font), so
//! that editing a tool never changes what plugins are checked against.

pub mod compare;
pub mod montage;
pub mod part;
pub mod photons;
mod progress;
pub mod sweep;

use clap::{Args, Parser, Subcommand};
use foton_core::error::{Error, Result};
use foton_core::film::{Film, ImageFormat, check_output, format_of};
use foton_core::integrator::{Integrator, Part, RenderContext};
use foton_core::plugin::{IntegratorPlugin, Registry, search_path};
use foton_core::props::Unused;
use foton_core::scene::Scene;
use foton_core::value::{Document, Value};
use foton_loader::{FilmFile, TomlDocument};
pub use progress::TermProgress;
use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Set by Ctrl-C; a running render stops and writes what it has.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Makes Ctrl-C stop the render instead of the process (a second Ctrl-C still ends it).
pub fn install_interrupt_handler() {
    let _ = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
}

#[derive(Parser)]
#[command(
    name = "foton",
    version,
    about = "foton: a physically based renderer whose integrators are plugins",
    long_about = "foton renders a scene described in one TOML file or Mitsuba XML file (0.5, 0.6 or \
                  3; see docs/scene-format.md) with the integrator plugin the file, or \
                  --integrator, names."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image (.exr linear float32, or .png: 8-bit sRGB after the scene's
    /// [film] exposure and tonemap).
    Render(RenderArgs),
    /// Parse and validate a scene; list what it uses and any unused field.
    Check(CheckArgs),
    /// Merge the parts of a render made with `foton render --part I/N` into its image.
    ///
    /// Checks first that the parts belong together (same scene content, integrator and
    /// parameters, seed, number of parts and foton build; no part twice; none missing or
    /// interrupted unless --partial), then adds their exact per-pixel sums one part at a time.
    /// The merged image equals the render done in one process with the same seed, bit for
    /// bit. Nothing is written if a check fails.
    Merge(part::MergeArgs),
    /// Write a Mitsuba 3 XML scene as the equivalent TOML scene (the same image for the same
    /// seed); lists what --lenient left out.
    Convert(ConvertArgs),
    /// List the plugins found on the plugin search path.
    Plugins(PluginArgs),
    /// Render a scene several times and report samples per second (a benchmark, not a test).
    Bench(BenchArgs),
    /// Draw a photon map as seen from the scene camera, one dot per photon.
    ///
    /// The photons are those the integrator (the scene's, or --integrator) would store: the
    /// tool asks the plugin for its photon maps and draws the one --map names. A photon is
    /// drawn where it projects if the camera sees the side of the surface it lies on (one
    /// visibility ray per photon); a pixel shows the mean colour of the dots covering it.
    ///
    /// Exposure: a dot's colour is the photon's flux divided by the 99th percentile of the
    /// drawn photons' largest channel, so that 99% of the dots are unclipped and photons of
    /// equal flux on a white surface come out white; a PNG then applies the scene's [film]
    /// exposure and tonemap, as to a render. Prints the photons stored and drawn.
    Photons(photons::PhotonsArgs),
    /// Render a scene with several integrators and lay the renders side by side, labelled.
    ///
    /// Each render is labelled with the integrator's name, samples per pixel, render time and
    /// parameters, and written beside the output as <output stem>-<integrator>.exr; the numbers
    /// go to <output stem>.json (name, description, spp, seconds, rel_mse, bias, image).
    ///
    /// --time S: each integrator gets about S seconds, found by short calibration renders that
    /// measure a fixed cost (a photon pass) and a per-step cost: path-like integrators get the
    /// spp that fills S; progressive ones (sppm) the number of iterations (their spp is
    /// reported as null); photon mappers (photon, vpm) their photon budgets scaled with S and
    /// the spp that fills the rest. The chosen values are printed and written to the JSON as
    /// --set overrides, so `foton render` with them gives the same image. --curve N also
    /// renders at S/2^(N-1), ..., S/2 and plots the error against the time (docs/tools.md).
    ///
    /// --reference IMAGE: a second row shows each render's relative difference from the
    /// reference, per pixel (x - r) / sqrt(r^2 + 0.01) of the channel means, in a diverging
    /// false colour: blue where the render is darker, light grey where equal, red where
    /// brighter, saturated at 100%. The labels and the JSON give rel_mse (the mean over pixels
    /// and channels of (x - r)^2 / (r^2 + 0.01)) and bias ((mean x - mean r) / mean r).
    Compare(compare::CompareArgs),
    /// Render a scene over the product of lists of --set values, in a labelled grid.
    ///
    /// --set KEY.PATH=V1,V2,... sweeps a scene value; the first --set with several values runs
    /// along the columns, the second down the rows, any further ones down the rows as well
    /// (row-major, earlier sets varying faster). A --set with one value applies to every cell.
    /// Each cell is labelled with its values and its render time, and in a PNG shown through
    /// its scene's [film] exposure and tonemap (so film.exposure can be swept).
    Sweep(sweep::SweepArgs),
}

#[derive(Args, Clone, Default)]
pub(crate) struct PluginArgs {
    /// Look for plugins in DIR first (repeatable); then FOTON_PLUGIN_PATH, then the folder of
    /// the foton executable and its plugins/ subfolder.
    #[arg(long = "plugin-dir", value_name = "DIR")]
    plugin_dirs: Vec<PathBuf>,
}

#[derive(Args, Clone, Default)]
pub(crate) struct SceneArgs {
    /// The scene file (TOML, or a Mitsuba scene: .xml, version 3 or 0.4 to 0.6).
    scene: PathBuf,
    /// NAME=VALUE: set a Mitsuba XML scene's <default name="NAME"> (Mitsuba's -D;
    /// repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    defines: Vec<String>,
    /// Mitsuba XML scenes: leave out what foton cannot render yet (listed as warnings)
    /// instead of refusing the scene.
    #[arg(long)]
    lenient: bool,
    /// Use this integrator plugin instead of the scene's render.integrator.
    #[arg(long)]
    integrator: Option<String>,
    /// Samples per pixel (overrides render.spp).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::parse_spp)]
    spp: Option<u32>,
    /// Random seed (overrides render.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Override any scene value by its dotted TOML key path, e.g. --set render.spp=16
    /// --set integrators.photon.k=100 (repeatable).
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    sets: Vec<String>,
    /// Treat unknown (unused) scene fields and integrator parameters, and Mitsuba parameters
    /// foton understands but ignores (warnings otherwise), as errors.
    #[arg(long)]
    strict: bool,
    #[command(flatten)]
    plugins: PluginArgs,
}

#[derive(Args)]
struct ConvertArgs {
    /// The Mitsuba scene (.xml, version 3 or 0.4 to 0.6).
    scene: PathBuf,
    /// The TOML scene to write; default: <scene stem>.toml beside the scene.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// NAME=VALUE: set a <default name="NAME"> (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    defines: Vec<String>,
    /// Leave out what foton cannot render yet (listed) instead of refusing the scene.
    #[arg(long)]
    lenient: bool,
    /// A parameter foton understands but ignores is an error, not a warning.
    #[arg(long)]
    strict: bool,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image (.exr or .png); default: film.output, relative to the scene file.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
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
}

#[derive(Args)]
struct CheckArgs {
    #[command(flatten)]
    scene: SceneArgs,
}

#[derive(Args)]
struct BenchArgs {
    /// The scene to render (default: the Cornell box of scenes/cornell-box.toml, built into
    /// the program so that the benchmark runs from any folder).
    scene: Option<PathBuf>,
    #[arg(long)]
    integrator: Option<String>,
    #[arg(long, allow_negative_numbers = true, value_parser = crate::parse_spp)]
    spp: Option<u32>,
    #[arg(long)]
    threads: Option<usize>,
    /// Number of timed renders (the best is reported).
    #[arg(long, default_value_t = 3)]
    repeat: u32,
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    sets: Vec<String>,
    /// Traverse the scene's BVH with obvhs' own traversal instead of foton's float nodes: to
    /// measure what those give (the image differs only where a ray starts within 1e-4 of
    /// another surface, which obvhs' traversal does not see)
    #[arg(long)]
    narrow_bvh: bool,
    #[command(flatten)]
    plugins: PluginArgs,
}

/// Runs the command line `args` (args[0] is the program name); returns the exit code.
pub fn run(args: Vec<OsString>, out: &mut dyn Write, err: &mut dyn Write) -> u8 {
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let text = e.render().to_string();
            if e.use_stderr() {
                let _ = write!(err, "{text}");
            } else {
                let _ = write!(out, "{text}");
            }
            return e.exit_code().clamp(0, 255) as u8;
        }
    };
    let result = match cli.command {
        Command::Render(a) => cmd_render(a, out, err),
        Command::Check(a) => cmd_check(a, out, err),
        Command::Merge(a) => part::run(a, out, err),
        Command::Convert(a) => cmd_convert(a, out, err),
        Command::Plugins(a) => cmd_plugins(a, out),
        Command::Bench(a) => cmd_bench(a, out, err),
        Command::Photons(a) => photons::run(a, out, err),
        Command::Compare(a) => compare::run(a, out, err),
        Command::Sweep(a) => sweep::run(a, out, err),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            let _ = writeln!(err, "error: {e}");
            1
        }
    }
}

/// `--spp N`: one message for every value that is not a number of samples (`0`, `-4`, `x`),
/// rather than clap's advice to pass `-4` after `--`.
pub(crate) fn parse_spp(text: &str) -> std::result::Result<u32, String> {
    match text.trim().parse::<i64>() {
        Ok(n) if n >= 1 => {
            u32::try_from(n).map_err(|_| format!("at most {} samples per pixel", u32::MAX))
        }
        Ok(n) => Err(format!("samples per pixel must be at least 1, not {n}")),
        Err(_) => Err(format!(
            "expected a whole number of samples per pixel (at least 1), not `{text}`"
        )),
    }
}

/// A scene ready to render: loaded, its integrator found and created.
pub struct Prepared {
    pub scene: Scene,
    pub integrator: Box<dyn Integrator>,
    /// The plugin the integrator comes from (for messages).
    pub plugin: IntegratorPlugin,
    pub warnings: Vec<String>,
}

pub(crate) fn scene_overrides(a: &SceneArgs) -> Vec<String> {
    let mut sets = a.sets.clone();
    if let Some(name) = &a.integrator {
        sets.push(format!("render.integrator={name:?}"));
    }
    if let Some(spp) = a.spp {
        sets.push(format!("render.spp={spp}"));
    }
    if let Some(seed) = a.seed {
        sets.push(format!("render.seed={seed}"));
    }
    sets
}

/// Errors from inside a plugin name the plugin and its file; errors in its parameters stay
/// scene errors (they name the scene file, key and line).
pub(crate) fn blame_plugin(plugin: &IntegratorPlugin, e: Error) -> Error {
    match e {
        Error::Scene { .. } | Error::Syntax { .. } | Error::XmlSyntax { .. } | Error::Io { .. } => {
            e
        }
        other => Error::Plugin {
            file: plugin.file.clone(),
            message: format!("integrator `{}`: {other}", plugin.name),
        },
    }
}

/// Loads a scene and creates its integrator from the plugin search path.
pub fn prepare(
    scene_path: &Path,
    overrides: &[String],
    plugin_dirs: &[PathBuf],
    strict: bool,
) -> Result<Prepared> {
    prepare_xml(scene_path, overrides, &[], false, plugin_dirs, strict)
}

/// [`prepare`] for the scene arguments of a command.
pub(crate) fn prepare_args(a: &SceneArgs, overrides: &[String]) -> Result<Prepared> {
    prepare_xml(
        &a.scene,
        overrides,
        &a.defines,
        a.lenient,
        &a.plugins.plugin_dirs,
        a.strict,
    )
}

/// [`prepare`], with a Mitsuba XML scene's `-D` defines and `--lenient`.
pub fn prepare_xml(
    scene_path: &Path,
    overrides: &[String],
    defines: &[String],
    lenient: bool,
    plugin_dirs: &[PathBuf],
    strict: bool,
) -> Result<Prepared> {
    let scene = foton_loader::load_with(scene_path, overrides, defines, lenient)?;
    prepare_scene(scene, &search_path(plugin_dirs), strict)
}

/// Creates a loaded scene's integrator from the plugins found in `search` (the whole search
/// path, in order: [`search_path`]'s folders and any the caller adds after them, as the Python
/// package does with its own plugin folder); as [`prepare`] does after loading.
pub fn prepare_scene(scene: Scene, search: &[PathBuf], strict: bool) -> Result<Prepared> {
    let registry = Registry::discover(search);
    let plugin = match registry.integrator(&scene.render().integrator) {
        Ok(p) => p.clone(),
        Err(e) => {
            // Written in the file: say where; given on the command line: say so.
            let location = scene.location_of(&["render", "integrator"]);
            return Err(match location {
                Some(location) if location.line > 0 => Error::Scene {
                    location,
                    key: "render.integrator".into(),
                    message: e.to_string(),
                },
                _ => e,
            });
        }
    };
    let props = scene
        .integrator_properties(&scene.render().integrator)?
        .with_kernels(&registry.kernels);
    let integrator = plugin
        .create(&props, &scene)
        .map_err(|e| blame_plugin(&plugin, e))?;
    let mut unused = scene.unused().to_vec();
    unused.extend(props.unused());
    drop(props);
    // A value the command line set (--set, --spp, Python's overrides: no line in the file)
    // that nothing reads was asked for explicitly: rendering without it would answer another
    // question than the one asked, so it is an error even without --strict.
    unread_set(&unused, &scene.render().integrator)?;
    // Values set for other integrators (settings for several, as a file holds, switched with
    // --integrator) are checked by those integrators' plugins, so that a typo there is caught
    // too. One that cannot be created for this scene (`photon` refuses media) is not checked.
    for (name, key) in other_integrators_set(&scene) {
        let other = registry
            .integrator(&name)
            .map_err(|e| Error::Usage(format!("--set {key}: {e}")))?;
        let props = scene
            .integrator_properties(&name)?
            .with_kernels(&registry.kernels);
        if other.create(&props, &scene).is_ok() {
            unread_set(&props.unused(), &name)?;
        }
    }
    if strict && let Some(w) = scene.ignored().first() {
        return Err(Error::Usage(format!(
            "{w} (--strict: a parameter foton ignores is an error)"
        )));
    }
    if strict && let Some(u) = unused.first() {
        return Err(Error::Scene {
            location: u.location.clone(),
            key: u.key.clone(),
            message: format!(
                "{} (not used by the scene loader or the integrator)",
                u.message()
            ),
        });
    }
    let mut warnings = scene.warnings().to_vec();
    warnings.extend(scene.ignored().iter().cloned());
    warnings.extend(
        unused
            .iter()
            .map(|u| format!("{}: `{}`: {}, ignored", u.location, u.key, u.message())),
    );
    Ok(Prepared {
        scene,
        integrator,
        plugin,
        warnings,
    })
}

/// The integrators other than `scene`'s whose tables hold a value the command line set (no
/// line in the file), with the key path of the first such value.
fn other_integrators_set(scene: &Scene) -> Vec<(String, String)> {
    fn first_set(table: &foton_core::value::Table, path: &str) -> Option<String> {
        table.0.iter().find_map(|(k, node)| match &node.value {
            Value::Table(t) => first_set(t, &format!("{path}.{k}")),
            _ if node.line == 0 => Some(format!("{path}.{k}")),
            _ => None,
        })
    }
    let Some(Value::Table(integrators)) =
        scene.document().root.get("integrators").map(|n| &n.value)
    else {
        return Vec::new();
    };
    integrators
        .0
        .iter()
        .filter_map(|(name, node)| match &node.value {
            Value::Table(t) if *name != scene.render().integrator => {
                first_set(t, &format!("integrators.{name}")).map(|key| (name.clone(), key))
            }
            _ => None,
        })
        .collect()
}

/// The error for a value set from the command line that `integrator` does not read.
fn unread_set(unused: &[Unused], integrator: &str) -> Result<()> {
    match unused.iter().find(|u| u.location.line == 0) {
        Some(u) => {
            let hint = u
                .suggestion
                .as_ref()
                .map_or(String::new(), |s| format!(" (did you mean `{s}`?)"));
            Err(Error::Usage(format!(
                "--set {}: neither the scene nor the integrator `{integrator}` reads it{hint}",
                u.key
            )))
        }
        None => Ok(()),
    }
}

/// `<scene stem>-<suffix>` in the scene's folder: the default output of the tools.
fn beside_scene(scene: &Path, suffix: &str) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
    scene.with_file_name(format!("{stem}-{suffix}"))
}

/// Writes a file atomically: to a temporary name in the same folder, then renamed over `path`.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |tmp| std::fs::write(tmp, bytes))
}

/// Writes a file atomically with `write`, which writes to the temporary path it is given.
fn write_atomic_with(path: &Path, write: impl FnOnce(&Path) -> std::io::Result<()>) -> Result<()> {
    let name = path
        .file_name()
        .ok_or_else(|| Error::io(path, "not a file name"))?
        .to_string_lossy();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    write(&tmp)
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            Error::io(path, e)
        })
}

fn threads(requested: Option<usize>) -> usize {
    requested.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Renders a prepared scene on `threads` threads.
pub fn render_prepared(
    p: &Prepared,
    threads: usize,
    progress: &TermProgress,
) -> Result<(Film, Duration)> {
    render_part(p, threads, progress, Part::WHOLE)
}

/// Renders `part` of a prepared scene's work on `threads` threads.
pub fn render_part(
    p: &Prepared,
    threads: usize,
    progress: &TermProgress,
    part: Part,
) -> Result<(Film, Duration)> {
    let ctx = RenderContext {
        part,
        ..RenderContext::new(threads, &INTERRUPTED, progress)
    };
    render_with(p, &ctx)
}

/// Renders a prepared scene with the caller's context (its own cancel flag and progress, as
/// the Python package's), as [`render_prepared`] does with the program's; returns the film and
/// the time the render took.
pub fn render_with(p: &Prepared, ctx: &RenderContext<'_>) -> Result<(Film, Duration)> {
    let start = Instant::now();
    let film = p
        .integrator
        .render(&p.scene, ctx)
        .map_err(|e| blame_plugin(&p.plugin, e))?;
    if film.part != ctx.part {
        // A plugin that ignored the part rendered all of the work: merging such films would
        // count it N times.
        return Err(blame_plugin(
            &p.plugin,
            Error::Render(format!(
                "asked for part {}, it returned a film of part {}: this integrator cannot render in parts",
                ctx.part, film.part
            )),
        ));
    }
    Ok((film, start.elapsed()))
}

fn cmd_render(a: RenderArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let overrides = scene_overrides(&a.scene);
    let p = prepare_args(&a.scene, &overrides)?;
    let output = match (&a.output, a.part) {
        (Some(o), _) => o.clone(),
        (None, Some(part)) => beside_scene(
            &a.scene.scene,
            &format!("part-{}-of-{}.exr", part.index, part.count),
        ),
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
    for w in &p.warnings {
        let _ = writeln!(err, "warning: {w}");
    }
    let mut progress = TermProgress::new(a.quiet);
    if let Some(every) = a.checkpoint {
        progress = progress.with_checkpoint(every, output.clone(), p.scene.film().display());
    }
    INTERRUPTED.store(false, Ordering::SeqCst);
    let threads = threads(a.threads);
    let (film, elapsed) = render_part(&p, threads, &progress, a.part.unwrap_or(Part::WHOLE))?;
    if a.checkpoint.is_some() && progress.checkpoints.load(Ordering::Relaxed) == 0 {
        let _ = writeln!(
            err,
            "warning: --checkpoint: {} is not progressive and wrote no intermediate image",
            p.integrator.describe()
        );
    }
    for w in progress.take_warnings() {
        let _ = writeln!(err, "warning: {w}");
    }
    let of_part = match a.part {
        Some(part) => {
            // The defines change an XML scene as overrides do.
            let mut hashed = overrides.clone();
            hashed.extend(a.scene.defines.iter().map(|d| format!("-D {d}")));
            let info = part::PartInfo::of(&p.scene, &hashed, &p.integrator.describe(), &film)?;
            part::write_part(&output, &film, &info, &[])?;
            format!(", part {part}")
        }
        None => {
            film.write(&output, &p.scene.film().display())?;
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

fn cmd_convert(a: ConvertArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| a.scene.with_extension("toml"));
    if output.extension().and_then(|e| e.to_str()) != Some("toml") {
        return Err(Error::Usage(format!(
            "convert writes a TOML scene: name the output .toml, not {}",
            output.display()
        )));
    }
    let (mut doc, report) = foton_loader::mitsuba::read_xml(&a.scene, &a.defines, a.lenient)?;
    if a.strict
        && let Some(w) = report.warnings.first()
    {
        return Err(Error::Usage(format!(
            "{w} (--strict: a parameter foton ignores is an error)"
        )));
    }
    // Files are named relative to the scene; written into another folder, relative to it.
    let folder = |p: &Path| match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => std::fs::canonicalize(d).ok(),
        _ => std::fs::canonicalize(".").ok(),
    };
    let base = folder(&a.scene).ok_or_else(|| Error::io(&a.scene, "cannot resolve its folder"))?;
    let target = folder(&output).ok_or_else(|| {
        Error::io(
            &output,
            "the folder to write the TOML scene into does not exist",
        )
    })?;
    if target != base {
        doc.rebase_files(&base, &target);
    }
    // The TOML must load from where it is written: check it before writing.
    let mut written = doc.clone();
    written.file = output.clone();
    let mut scene = foton_loader::from_document(written)?;
    if let Some((integrator, factor, line)) = &report.relative_radius {
        foton_loader::set_relative_radius(&mut scene, integrator, *factor, *line);
        doc.root = scene.document().root.clone();
    }
    let header = format!(
        "# Converted by `foton convert` from {}\n",
        a.scene.display()
    );
    write_atomic(&output, (header + &doc.to_toml()).as_bytes())?;
    for l in &report.left_out {
        let _ = writeln!(err, "left out: {l}");
    }
    for w in &report.warnings {
        let _ = writeln!(err, "warning: {w}");
    }
    for n in &report.notes {
        let _ = writeln!(err, "note: {n}");
    }
    let _ = writeln!(out, "{} -> {}", a.scene.display(), output.display());
    Ok(0)
}

fn cmd_check(a: CheckArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let overrides = scene_overrides(&a.scene);
    let p = prepare_args(&a.scene, &overrides)?;
    let s = &p.scene;
    let _ = writeln!(out, "scene      {}", s.file().display());
    let _ = writeln!(out, "integrator {}", p.integrator.describe());
    let _ = writeln!(
        out,
        "render     {}x{}, {} spp ({}), seed {}, max_depth {} -> {}",
        s.film().width,
        s.film().height,
        s.render().spp,
        s.render().sampler.name(),
        s.render().seed,
        s.render().max_depth,
        s.film().output.display()
    );
    let names = |v: Vec<&str>| {
        if v.is_empty() {
            "-".to_string()
        } else {
            v.join(", ")
        }
    };
    let _ = writeln!(
        out,
        "materials  {}",
        names(s.materials().iter().map(|m| m.name.as_str()).collect())
    );
    let _ = writeln!(
        out,
        "media      {}",
        names(s.media().iter().map(|m| m.name.as_str()).collect())
    );
    let _ = writeln!(
        out,
        "shapes     {} ({} primitives)",
        s.objects().len(),
        s.accel().primitives().len()
    );
    use foton_core::light::Light;
    let count = |f: fn(&Light) -> bool| s.lights().iter().filter(|l| f(l)).count();
    let kinds = [
        ("point", count(|l| matches!(l, Light::Point { .. }))),
        ("spot", count(|l| matches!(l, Light::Spot { .. }))),
        (
            "directional",
            count(|l| matches!(l, Light::Directional { .. })),
        ),
        ("environment", count(Light::is_environment)),
        ("area", count(|l| matches!(l, Light::Area { .. }))),
    ];
    let listed: Vec<String> = kinds
        .iter()
        .filter(|(kind, n)| *n > 0 || matches!(*kind, "point" | "area"))
        .map(|(kind, n)| format!("{n} {kind}"))
        .collect();
    let power = s.total_power();
    let _ = writeln!(
        out,
        "lights     {}; total power [{:.4}, {:.4}, {:.4}] W",
        listed.join(", "),
        power.x,
        power.y,
        power.z
    );
    for w in &p.warnings {
        let _ = writeln!(err, "warning: {w}");
    }
    let _ = writeln!(out, "ok");
    Ok(0)
}

fn cmd_plugins(a: PluginArgs, out: &mut dyn Write) -> Result<u8> {
    let dirs = search_path(&a.plugin_dirs);
    let reg = Registry::discover(&dirs);
    let _ = writeln!(
        out,
        "{:<12} {:<11} {:<40} file",
        "name", "kind", "description"
    );
    for p in &reg.integrators {
        let _ = writeln!(
            out,
            "{:<12} {:<11} {:<40} {}",
            p.name,
            "integrator",
            p.description,
            p.file.display()
        );
    }
    for k in &reg.kernels {
        let _ = writeln!(
            out,
            "{:<12} {:<11} {:<40} {}",
            k.name,
            "kernel",
            "",
            k.file.display()
        );
    }
    let _ = writeln!(
        out,
        "\nfoton-core {}, plugin API {}, {}, build {}",
        foton_core::CORE_VERSION,
        foton_core::plugin::PLUGIN_API_VERSION,
        foton_core::RUSTC_VERSION,
        foton_core::BUILD_ID
    );
    let shown: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
    let _ = writeln!(out, "search path: {}", shown.join(":"));
    for p in &reg.problems {
        let _ = writeln!(out, "skipped {}: {}", p.file.display(), p.message);
    }
    Ok(0)
}

/// The scene `foton bench` renders when given none: the README's default scene.
const DEFAULT_SCENE: &str = include_str!("../../../scenes/cornell-box.toml");
const DEFAULT_SCENE_NAME: &str = "scenes/cornell-box.toml";

fn cmd_bench(a: BenchArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let args = SceneArgs {
        scene: a.scene.clone().unwrap_or_default(),
        integrator: a.integrator.clone(),
        spp: a.spp,
        sets: a.sets.clone(),
        plugins: a.plugins.clone(),
        ..Default::default()
    };
    let overrides = scene_overrides(&args);
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
    for w in &p.warnings {
        let _ = writeln!(err, "warning: {w}");
    }
    if a.narrow_bvh {
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
        "{} with {}: {}x{} x {work}, {:.3} M rays/s, {} BVH node test",
        p.scene.file().display(),
        p.integrator.describe(),
        p.scene.film().width,
        p.scene.film().height,
        rate(film.rays),
        if p.scene.accel().wide() {
            "8-wide (AVX2)"
        } else {
            "4-wide (SSE2)"
        }
    );
    Ok(0)
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
