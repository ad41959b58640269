//! What every command shares: the arguments that name a scene and the plugins, loading a
//! scene with the command line's overrides and creating its integrator ([`prepare`]),
//! rendering it ([`render_prepared`]) under the program's interrupt flag, the default output
//! paths and atomic writes, and the `warning:` lines.

use clap::Args;
use foton_core::error::{Error, Result};
use foton_core::film::Film;
use foton_core::integrator::{Integrator, Part, RenderContext};
use foton_core::plugin::{IntegratorPlugin, Registry, search_path};
use foton_core::props::Unused;
use foton_core::scene::Scene;
use foton_core::value::{Table, Value};
use std::fmt::Display;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::TermProgress;

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

#[derive(Args, Clone, Default)]
pub(crate) struct PluginArgs {
    /// Look for plugins in DIR first (repeatable); then FOTON_PLUGIN_PATH, then the folder of
    /// the foton executable and its plugins/ subfolder.
    #[arg(long = "plugin-dir", value_name = "DIR")]
    pub plugin_dirs: Vec<PathBuf>,
}

/// The scene file and how to read a Mitsuba one.
#[derive(Args, Clone, Default)]
pub(crate) struct SceneFile {
    /// The scene file (TOML, a Mitsuba scene: .xml, version 3 or 0.4 to 0.6, or a pbrt-v4 scene: .pbrt).
    pub scene: PathBuf,
    /// NAME=VALUE: set a Mitsuba XML scene's <default name="NAME"> (Mitsuba's -D;
    /// repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    pub defines: Vec<String>,
    /// Mitsuba XML scenes: leave out what foton cannot render yet (listed as warnings)
    /// instead of refusing the scene.
    #[arg(long)]
    pub lenient: bool,
}

impl SceneFile {
    /// Loads the scene with `overrides` (`KEY.PATH=VALUE`) and creates its integrator from the
    /// plugins on the search path (`plugins` first).
    pub fn prepare(
        &self,
        overrides: &[String],
        plugins: &PluginArgs,
        strict: bool,
    ) -> Result<Prepared> {
        let scene = foton_loader::load_with(&self.scene, overrides, &self.defines, self.lenient)?;
        prepare_scene(scene, &search_path(&plugins.plugin_dirs), strict)
    }

    /// `<scene stem>-<suffix>` beside the scene: a tool's default output.
    pub fn beside(&self, suffix: &str) -> PathBuf {
        beside_scene(&self.scene, suffix)
    }
}

/// The scene values that have options of their own: the integrator, spp and seed.
#[derive(Args, Clone, Default)]
pub(crate) struct Overrides {
    /// Use this integrator plugin instead of the scene's render.integrator.
    #[arg(long)]
    pub integrator: Option<String>,
    /// Samples per pixel (overrides render.spp).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_spp)]
    pub spp: Option<u32>,
    /// Random seed (overrides render.seed).
    #[arg(long)]
    pub seed: Option<u64>,
}

impl Overrides {
    /// Appends the options given as `--set` overrides, after `sets` (which they override).
    pub fn push_onto(&self, sets: &mut Vec<String>) {
        if let Some(name) = &self.integrator {
            sets.push(format!("render.integrator={name:?}"));
        }
        if let Some(spp) = self.spp {
            sets.push(format!("render.spp={spp}"));
        }
        if let Some(seed) = self.seed {
            sets.push(format!("render.seed={seed}"));
        }
    }
}

/// The scene arguments of `render`, `check` and `photons`.
#[derive(Args, Clone, Default)]
pub(crate) struct SceneArgs {
    #[command(flatten)]
    pub file: SceneFile,
    #[command(flatten)]
    pub overrides: Overrides,
    /// Override any scene value by its dotted TOML key path, e.g. --set render.spp=16
    /// --set integrators.photon.k=100 (repeatable).
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    pub sets: Vec<String>,
    /// Treat unknown (unused) scene fields and integrator parameters, and Mitsuba parameters
    /// foton understands but ignores (warnings otherwise), as errors.
    #[arg(long)]
    pub strict: bool,
    #[command(flatten)]
    pub plugins: PluginArgs,
}

impl SceneArgs {
    /// Every scene value the command line sets: the `--set`s, then the options.
    pub fn overrides(&self) -> Vec<String> {
        let mut sets = self.sets.clone();
        self.overrides.push_onto(&mut sets);
        sets
    }

    /// [`SceneFile::prepare`] with these arguments' plugins and `--strict`.
    pub fn prepare(&self, overrides: &[String]) -> Result<Prepared> {
        self.file.prepare(overrides, &self.plugins, self.strict)
    }
}

/// How the renders run: threads and progress (the images depend on neither).
#[derive(Args, Clone, Default)]
pub(crate) struct RunArgs {
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

impl RunArgs {
    pub fn threads(&self) -> usize {
        threads(self.threads)
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

/// `requested` worker threads, or all cores.
pub(crate) fn threads(requested: Option<usize>) -> usize {
    requested.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// A scene ready to render: loaded, its integrator found and created.
pub struct Prepared {
    pub scene: Scene,
    pub integrator: Box<dyn Integrator>,
    /// The plugin the integrator comes from (for messages).
    pub plugin: IntegratorPlugin,
    pub warnings: Vec<String>,
}

/// Loads a scene and creates its integrator from the plugin search path.
pub fn prepare(
    scene_path: &Path,
    overrides: &[String],
    plugin_dirs: &[PathBuf],
    strict: bool,
) -> Result<Prepared> {
    let scene = foton_loader::load_with(scene_path, overrides, &[], false)?;
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
    fn first_set(table: &Table, path: &str) -> Option<String> {
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
    let mut film = p
        .integrator
        .render(&p.scene, ctx)
        .map_err(|e| blame_plugin(&p.plugin, e))?;
    film.color_matrix = p.scene.film().color_matrix();
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

/// `<scene stem>-<suffix>` in the scene's folder: the default output of the tools.
pub(crate) fn beside_scene(scene: &Path, suffix: &str) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
    scene.with_file_name(format!("{stem}-{suffix}"))
}

/// Writes a file atomically: to a temporary name in the same folder, then renamed over `path`.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |tmp| std::fs::write(tmp, bytes))
}

/// Writes a file atomically with `write`, which writes to the temporary path it is given.
pub(crate) fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&Path) -> std::io::Result<()>,
) -> Result<()> {
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

/// Prints each of `warnings` as a `warning:` line.
pub(crate) fn warn(err: &mut dyn Write, warnings: impl IntoIterator<Item = impl Display>) {
    for w in warnings {
        let _ = writeln!(err, "warning: {w}");
    }
}

/// The `warning:` lines of several renders of one scene, each printed once.
#[derive(Default)]
pub(crate) struct WarnOnce(Vec<String>);

impl WarnOnce {
    pub fn warn(&mut self, err: &mut dyn Write, warnings: &[String]) {
        for w in warnings {
            if !self.0.contains(w) {
                let _ = writeln!(err, "warning: {w}");
                self.0.push(w.clone());
            }
        }
    }
}
