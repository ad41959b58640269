//! `foton._foton`: the extension module under the `foton` Python package (python/foton/).
//!
//! A thin layer over the program's own code paths, so that an image rendered from Python is
//! the image `foton render` writes, bit for bit: scenes are loaded by foton-core
//! (`foton_loader::load_with`, TOML or Mitsuba XML; `Document::parse` for TOML text) with `--set`
//! style overrides, their
//! integrator is created by `foton_cli::prepare_scene` from the plugins on the search path,
//! and rendered by `foton_cli::render_with`; images are written and read by foton-core's film
//! functions, and compared by `foton compare`'s error function. The Python side (argument
//! handling, numpy, tqdm, the exception classes) is in python/foton/__init__.py.
//!
//! A render runs on a thread of its own with the GIL released; the calling thread waits for
//! it in short slices without the GIL, and between slices takes the GIL to check for signals
//! (Ctrl-C) and to report progress. On KeyboardInterrupt it sets the render's cancel flag,
//! waits for the integrator to return what it has, and raises the KeyboardInterrupt with the
//! partial image attached (`.image`, `.render_info`).

use foton_cli::{Prepared, prepare_scene, render_with};
use foton_core::Rgb;
use foton_core::error::Error;
use foton_core::film::{DisplayTransform, Film, ToneMap};
use foton_core::integrator::{ParamValue, Progress, RenderContext};
use foton_core::plugin::{Registry, search_path};
use foton_core::scene::Scene;
use foton_core::value::Document;
use foton_loader::TomlDocument;
use foton_loader::image::{read_image, write_image};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyDict, PyList};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

/// How long the calling thread waits without the GIL between two checks for signals and
/// progress: the delay before Ctrl-C reaches a render's cancel flag.
const POLL: Duration = Duration::from_millis(25);

/// The Python exception for a foton error: the classes of `foton._errors`, whose message is
/// the program's (`error: ...` without the prefix) and whose attributes are the error's parts.
fn py_error(py: Python<'_>, e: Error) -> PyErr {
    let module = match py.import("foton._errors") {
        Ok(m) => m,
        Err(err) => return err,
    };
    let message = e.to_string();
    let kwargs = PyDict::new(py);
    let path = |p: &std::path::Path| p.to_string_lossy().into_owned();
    let class = (|| -> PyResult<&str> {
        Ok(match &e {
            Error::Scene {
                location,
                key,
                message,
            } => {
                kwargs.set_item("file", path(&location.file))?;
                kwargs.set_item("line", (location.line > 0).then_some(location.line))?;
                kwargs.set_item("column", (location.line > 0).then_some(location.column))?;
                kwargs.set_item("key", key)?;
                kwargs.set_item("reason", message)?;
                "SceneError"
            }
            Error::Syntax { location, message } | Error::XmlSyntax { location, message } => {
                kwargs.set_item("file", path(&location.file))?;
                kwargs.set_item("line", (location.line > 0).then_some(location.line))?;
                kwargs.set_item("column", (location.line > 0).then_some(location.column))?;
                kwargs.set_item("reason", message)?;
                "SceneError"
            }
            Error::Io { path: p, message } => {
                kwargs.set_item("path", path(p))?;
                kwargs.set_item("reason", message)?;
                "FileError"
            }
            Error::Plugin { file, message } => {
                kwargs.set_item("file", path(file))?;
                kwargs.set_item("reason", message)?;
                "PluginError"
            }
            // The plugin named by an argument (not by the scene file) is not on the path.
            Error::Usage(message) if message.starts_with("no integrator plugin named") => {
                kwargs.set_item("reason", message)?;
                "PluginError"
            }
            Error::Usage(_) => "UsageError",
            Error::Render(_) | Error::Interrupted | Error::Panic(_) => "RenderError",
        })
    })();
    let class = match class {
        Ok(c) => c,
        Err(err) => return err,
    };
    match module
        .getattr(class)
        .and_then(|c| c.call((message,), Some(&kwargs)))
    {
        Ok(value) => PyErr::from_value(value),
        Err(err) => err,
    }
}

/// Where a scene comes from.
enum Source {
    /// A TOML or Mitsuba XML scene file, with the XML's `-D` defines and `--lenient`.
    File {
        path: PathBuf,
        defines: Vec<String>,
        lenient: bool,
    },
    /// TOML text; `file` names it in messages and relative paths are resolved from its folder.
    Text { text: String, file: PathBuf },
}

impl Source {
    /// As `foton render` loads a scene file (`foton_loader::load_with`), or the same from text.
    fn load(&self, overrides: &[String]) -> foton_core::Result<Scene> {
        match self {
            Source::File {
                path,
                defines,
                lenient,
            } => foton_loader::load_with(path, overrides, defines, *lenient),
            Source::Text { text, file } => {
                let mut doc = Document::parse(text, file)?;
                for o in overrides {
                    doc.set(o)?;
                }
                foton_loader::from_document(doc)
            }
        }
    }
}

/// A loaded scene with its integrator created: what `foton.load` returns (wrapped by
/// `foton.Scene`). Each render with other settings (integrator, spp, seed, parameters) loads
/// the scene again with them as overrides, as the program would; the last such preparation is
/// kept for the next render with the same settings.
#[pyclass(module = "foton._foton", frozen)]
struct NativeScene {
    source: Source,
    overrides: Vec<String>,
    search: Vec<PathBuf>,
    strict: bool,
    base: Arc<Prepared>,
    last: Mutex<Option<(Vec<String>, Arc<Prepared>)>>,
}

impl NativeScene {
    /// The scene with `extra` overrides after its own, loaded again and its integrator
    /// created (without the GIL: call inside `detach`).
    fn load(&self, extra: &[String]) -> foton_core::error::Result<Prepared> {
        let mut overrides = self.overrides.clone();
        overrides.extend_from_slice(extra);
        prepare_scene(self.source.load(&overrides)?, &self.search, self.strict)
    }

    fn prepare(&self, py: Python<'_>, extra: &[String]) -> PyResult<Arc<Prepared>> {
        if extra.is_empty() {
            return Ok(self.base.clone());
        }
        if let Some((sets, p)) = &*self.last.lock().unwrap()
            && sets == extra
        {
            return Ok(p.clone());
        }
        let prepared = py
            .detach(|| self.load(extra))
            .map_err(|e| py_error(py, e))?;
        let prepared = Arc::new(prepared);
        *self.last.lock().unwrap() = Some((extra.to_vec(), prepared.clone()));
        Ok(prepared)
    }
}

/// The render's progress, kept for the calling thread to report (the render thread must not
/// touch Python).
#[derive(Default)]
struct Report {
    /// (phase number, phase, units in the phase)
    phase: Mutex<(u64, String, u64)>,
    done: AtomicU64,
    /// The phases that ended since the last report, as they ended (a phase shorter than the
    /// interval between reports is reported all the same).
    ended: Mutex<Vec<(u64, String, u64, u64)>>,
    warnings: Mutex<Vec<String>>,
}

impl Progress for Report {
    fn begin(&self, phase: &str, total: u64) {
        let mut p = self.phase.lock().unwrap();
        if p.0 > 0 {
            let done = self.done.load(Ordering::Relaxed);
            self.ended
                .lock()
                .unwrap()
                .push((p.0, std::mem::take(&mut p.1), done, p.2));
        }
        *p = (p.0 + 1, phase.to_string(), total);
        self.done.store(0, Ordering::Relaxed);
    }
    fn advance(&self, units: u64) {
        self.done.fetch_add(units, Ordering::Relaxed);
    }
    fn finish(&self) {}
    fn warn(&self, message: &str) {
        self.warnings.lock().unwrap().push(message.to_string());
    }
}

impl Report {
    /// (phase number, phase, done, total); phase number 0: no phase has begun.
    fn snapshot(&self) -> (u64, String, u64, u64) {
        let p = self.phase.lock().unwrap();
        (p.0, p.1.clone(), self.done.load(Ordering::Relaxed), p.2)
    }
}

/// A numpy float32 array (height, width, 3) over a bytearray filled by `fill` (no other copy:
/// numpy's array is a view of the bytearray).
fn array<'py>(
    py: Python<'py>,
    width: u32,
    height: u32,
    fill: impl FnOnce(&mut [u8]),
) -> PyResult<Bound<'py, PyAny>> {
    let n = width as usize * height as usize * 3 * 4;
    let bytes = PyByteArray::new_with(py, n, |b| {
        fill(b);
        Ok(())
    })?;
    let np = py.import("numpy")?;
    np.call_method1("frombuffer", (bytes, np.getattr("float32")?))?
        .call_method1("reshape", ((height as usize, width as usize, 3usize),))
}

fn put(bytes: &mut [u8], i: usize, c: Rgb) {
    for (k, v) in c.to_array().into_iter().enumerate() {
        bytes[(3 * i + k) * 4..(3 * i + k + 1) * 4].copy_from_slice(&v.to_ne_bytes());
    }
}

/// The film's pixels (`Film::pixel`, what `foton render` writes to an EXR), row-major from
/// the top-left, as a numpy array.
fn film_array<'py>(py: Python<'py>, film: &Film) -> PyResult<Bound<'py, PyAny>> {
    array(py, film.width, film.height, |b| {
        for y in 0..film.height {
            for x in 0..film.width {
                put(
                    b,
                    y as usize * film.width as usize + x as usize,
                    film.pixel(x, y),
                );
            }
        }
    })
}

/// Native-endian float32 RGB triples (numpy's `tobytes()` of a float32 array) as pixels.
fn pixels_of(data: &[u8], width: u32, height: u32) -> PyResult<Vec<Rgb>> {
    let n = width as usize * height as usize;
    if data.len() != n * 12 {
        return Err(PyValueError::new_err(format!(
            "{} bytes of pixel data for a {width}x{height} RGB float32 image ({} expected)",
            data.len(),
            n * 12
        )));
    }
    let f = |i: usize| f32::from_ne_bytes(data[4 * i..4 * i + 4].try_into().unwrap());
    Ok((0..n)
        .map(|i| Rgb::new(f(3 * i), f(3 * i + 1), f(3 * i + 2)))
        .collect())
}

fn param_value(py: Python<'_>, v: &ParamValue) -> PyResult<Py<PyAny>> {
    Ok(match v {
        ParamValue::Int(n) => n.into_pyobject(py)?.into_any().unbind(),
        ParamValue::Float(x) => x.into_pyobject(py)?.into_any().unbind(),
        ParamValue::Bool(b) => b.into_pyobject(py)?.to_owned().into_any().unbind(),
        ParamValue::Str(s) => s.into_pyobject(py)?.into_any().unbind(),
    })
}

#[pymethods]
impl NativeScene {
    #[getter]
    fn file(&self) -> PathBuf {
        self.base.scene.file().to_path_buf()
    }
    #[getter]
    fn width(&self) -> u32 {
        self.base.scene.film().width
    }
    #[getter]
    fn height(&self) -> u32 {
        self.base.scene.film().height
    }
    #[getter]
    fn spp(&self) -> u32 {
        self.base.scene.render().spp
    }
    #[getter]
    fn seed(&self) -> u64 {
        self.base.scene.render().seed
    }
    #[getter]
    fn sampler(&self) -> &'static str {
        self.base.scene.render().sampler.name()
    }
    #[getter]
    fn max_depth(&self) -> u32 {
        self.base.scene.render().max_depth
    }
    #[getter]
    fn integrator(&self) -> String {
        self.base.scene.render().integrator.clone()
    }
    /// The integrator with its parameters in force, as `foton render` prints it.
    #[getter]
    fn description(&self) -> String {
        self.base.integrator.describe()
    }
    /// The film output the scene names (resolved against its folder).
    #[getter]
    fn output(&self) -> PathBuf {
        self.base.scene.film().output.clone()
    }
    /// (exposure, tone map name): the scene's display transform for PNG outputs.
    #[getter]
    fn display(&self) -> (f32, &'static str) {
        let d = self.base.scene.film().display();
        (d.exposure, d.tonemap.name())
    }
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.base.warnings.clone()
    }
    /// The integrator's parameters in force: [(name, value)].
    #[getter]
    fn parameters(&self, py: Python<'_>) -> PyResult<Vec<(String, Py<PyAny>)>> {
        self.base
            .integrator
            .parameters()
            .iter()
            .map(|p| Ok((p.name.clone(), param_value(py, &p.value)?)))
            .collect()
    }

    /// Renders with `overrides` added to the scene's; returns (image, info). See the module
    /// comment for Ctrl-C. `progress(phase, done, total)` is called from the calling thread
    /// while the render runs; an exception from it cancels the render and is raised.
    #[pyo3(signature = (overrides, threads=None, progress=None))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        overrides: Vec<String>,
        threads: Option<usize>,
        progress: Option<Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        let mut overrides = overrides;
        let threads = threads
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
            .max(1);
        // A time limit (render.time, Mitsuba's timeout): the samples or iterations that fill
        // it, as `foton render` chooses them, set as an override.
        if let Some(seconds) = self.prepare(py, &overrides)?.scene.render().time {
            let fitted = py
                .detach(|| {
                    let owned = |extra: &[String]| {
                        let mut o = overrides.clone();
                        o.extend_from_slice(extra);
                        self.load(&o)
                    };
                    let mut q = owned(&[])?;
                    foton_cli::time_limit::fit(&mut q, seconds.into(), threads, &owned)
                })
                .map_err(|e| py_error(py, e))?;
            overrides.extend(fitted.set());
        }
        let p = self.prepare(py, &overrides)?;
        let report = Report::default();
        let cancel = AtomicBool::new(false);
        let finished = (Mutex::new(false), Condvar::new());
        // The exception that stopped the render: KeyboardInterrupt (or what a signal handler
        // raised), or the progress callback's.
        let mut stop: Option<PyErr> = None;
        // Each phase is reported with done = 0 first, then as it advances, and with its last
        // count when it has ended.
        let mut reported = (0u64, u64::MAX);
        let mut report_progress = |stop: &mut Option<PyErr>| {
            let Some(cb) = &progress else { return };
            let ended = std::mem::take(&mut *report.ended.lock().unwrap());
            for (n, phase, done, total) in ended.into_iter().chain([report.snapshot()]) {
                if n == 0 || (n, done) == reported {
                    continue;
                }
                let mut calls = vec![done];
                if n != reported.0 && done > 0 {
                    calls.insert(0, 0);
                }
                reported = (n, done);
                for done in calls {
                    if stop.is_some() {
                        return;
                    }
                    if let Err(e) = cb.call1((&phase, done, total)) {
                        cancel.store(true, Ordering::SeqCst);
                        *stop = Some(e);
                    }
                }
            }
        };
        let result = std::thread::scope(|s| {
            let worker = s.spawn(|| {
                let ctx = RenderContext::new(threads, &cancel, &report);
                let result = render_with(&p, &ctx);
                *finished.0.lock().unwrap() = true;
                finished.1.notify_all();
                result
            });
            loop {
                let done = py.detach(|| {
                    let guard = finished.0.lock().unwrap();
                    *finished
                        .1
                        .wait_timeout_while(guard, POLL, |done| !*done)
                        .unwrap()
                        .0
                });
                if stop.is_none()
                    && let Err(e) = py.check_signals()
                {
                    cancel.store(true, Ordering::SeqCst);
                    stop = Some(e);
                }
                report_progress(&mut stop);
                if done {
                    break;
                }
            }
            worker.join()
        });
        let result = result
            .map_err(|_| PyRuntimeError::new_err("foton: the render thread panicked"))?
            .map_err(|e| py_error(py, e));
        let (film, elapsed) = match result {
            Ok(r) => r,
            // Stopped, then failed: the stop is what the caller asked for.
            Err(e) => return Err(stop.unwrap_or(e)),
        };
        let info = PyDict::new(py);
        info.set_item("integrator", p.integrator.describe())?;
        info.set_item("seconds", elapsed.as_secs_f64())?;
        info.set_item("spp", p.scene.render().spp)?;
        info.set_item("sampler", p.scene.render().sampler.name())?;
        info.set_item("samples", film.total_samples())?;
        info.set_item("iterations", film.iterations)?;
        info.set_item("iterations_planned", film.iterations_planned)?;
        info.set_item("photons", film.photons)?;
        info.set_item("rays", film.rays)?;
        info.set_item("threads", threads)?;
        info.set_item("interrupted", cancel.load(Ordering::SeqCst))?;
        info.set_item("warnings", report.warnings.lock().unwrap().clone())?;
        let image = film_array(py, &film)?;
        drop(film);
        // What was left of the render's progress after a stop is not reported.
        if let Some(stop) = stop {
            let value = stop.value(py);
            // Best effort: an exception type without a __dict__ cannot carry them.
            let _ = value.setattr("image", &image);
            let _ = value.setattr("render_info", &info);
            return Err(stop);
        }
        Ok((image, info))
    }
}

/// Loads a scene (from `path`, or from TOML `text` named `path`) and creates its integrator.
#[pyfunction]
#[pyo3(signature = (path, text, overrides, defines, lenient, plugin_dirs, extra_dirs, strict))]
#[allow(clippy::too_many_arguments)]
fn load(
    py: Python<'_>,
    path: PathBuf,
    text: Option<String>,
    overrides: Vec<String>,
    defines: Vec<String>,
    lenient: bool,
    plugin_dirs: Vec<PathBuf>,
    extra_dirs: Vec<PathBuf>,
    strict: bool,
) -> PyResult<NativeScene> {
    let source = match text {
        Some(text) => Source::Text { text, file: path },
        None => Source::File {
            path,
            defines,
            lenient,
        },
    };
    let search = search(&plugin_dirs, &extra_dirs);
    let base = py
        .detach(|| {
            let scene = source.load(&overrides)?;
            prepare_scene(scene, &search, strict)
        })
        .map_err(|e| py_error(py, e))?;
    Ok(NativeScene {
        source,
        overrides,
        search,
        strict,
        base: Arc::new(base),
        last: Mutex::new(None),
    })
}

/// The program's search path (`--plugin-dir`s, FOTON_PLUGIN_PATH, the executable's folder and
/// its plugins/), then `extra` (the package's own plugin folder).
fn search(plugin_dirs: &[PathBuf], extra: &[PathBuf]) -> Vec<PathBuf> {
    let mut dirs = search_path(plugin_dirs);
    dirs.extend(extra.iter().cloned());
    dirs
}

/// The plugins found, as `foton plugins` lists them.
#[pyfunction]
fn plugins<'py>(
    py: Python<'py>,
    plugin_dirs: Vec<PathBuf>,
    extra_dirs: Vec<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let dirs = search(&plugin_dirs, &extra_dirs);
    let registry = py.detach(|| Registry::discover(&dirs));
    let found = PyList::empty(py);
    for p in &registry.integrators {
        found.append((&p.name, "integrator", &p.description, &p.file))?;
    }
    for k in &registry.kernels {
        found.append((&k.name, "kernel", "", &k.file))?;
    }
    let skipped = PyList::empty(py);
    for p in &registry.problems {
        skipped.append((&p.file, &p.message))?;
    }
    let out = PyDict::new(py);
    out.set_item("plugins", found)?;
    out.set_item("skipped", skipped)?;
    out.set_item("search_path", dirs)?;
    Ok(out)
}

/// What plugins are checked against: foton-core's version, the plugin API, rustc and the build
/// identifier (as the last line of `foton plugins`).
#[pyfunction]
fn build_info<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("core_version", foton_core::CORE_VERSION)?;
    out.set_item("plugin_api", foton_core::plugin::PLUGIN_API_VERSION)?;
    out.set_item("rustc", foton_core::RUSTC_VERSION)?;
    out.set_item("build_id", foton_core::BUILD_ID)?;
    Ok(out)
}

/// Writes float32 RGB pixels as `foton render` writes a film: EXR linear, PNG 8-bit sRGB
/// through the display transform.
#[pyfunction]
fn write(
    py: Python<'_>,
    path: PathBuf,
    data: &[u8],
    width: u32,
    height: u32,
    exposure: f32,
    tonemap: &str,
) -> PyResult<()> {
    let display = DisplayTransform::new(exposure, tone_map(tonemap)?);
    let pixels = pixels_of(data, width, height)?;
    py.detach(|| write_image(&path, width, height, &pixels, &display))
        .map_err(|e| py_error(py, e))
}

/// The 8-bit sRGB values a PNG of the pixels holds (`write`'s PNG), as a uint8 numpy array.
#[pyfunction]
fn to_display<'py>(
    py: Python<'py>,
    data: &[u8],
    width: u32,
    height: u32,
    exposure: f32,
    tonemap: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let display = DisplayTransform::new(exposure, tone_map(tonemap)?);
    let pixels = pixels_of(data, width, height)?;
    let n = pixels.len() * 3;
    let bytes = PyByteArray::new_with(py, n, |b| {
        for (i, p) in pixels.iter().enumerate() {
            b[3 * i..3 * i + 3].copy_from_slice(&display.encode(*p));
        }
        Ok(())
    })?;
    let np = py.import("numpy")?;
    np.call_method1("frombuffer", (bytes, np.getattr("uint8")?))?
        .call_method1("reshape", ((height as usize, width as usize, 3usize),))
}

fn tone_map(name: &str) -> PyResult<ToneMap> {
    ToneMap::from_name(name).ok_or_else(|| {
        PyValueError::new_err(format!(
            "unknown tone map `{name}`; expected one of: {}",
            ToneMap::NAMES.join(", ")
        ))
    })
}

/// Reads an image as linear RGB (EXR as stored, PNG decoded from sRGB).
#[pyfunction]
fn read(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let (width, height, pixels) = py
        .detach(|| read_image(&path))
        .map_err(|e| py_error(py, e))?;
    array(py, width, height, |b| {
        for (i, p) in pixels.iter().enumerate() {
            put(b, i, *p);
        }
    })
}

/// `foton compare`'s error figures of an image against a reference of the same size:
/// (rel_mse, bias).
#[pyfunction]
fn errors(data: &[u8], reference: &[u8], width: u32, height: u32) -> PyResult<(f64, f64)> {
    let x = pixels_of(data, width, height)?;
    let r = pixels_of(reference, width, height)?;
    let e = foton_cli::compare::errors(&x, &r);
    Ok((e.rel_mse, e.bias))
}

/// `foton compare --report`'s page of named images against a reference, written to `path`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn report(
    path: &str,
    names: Vec<String>,
    images: Vec<Vec<u8>>,
    reference: &[u8],
    width: u32,
    height: u32,
    exposure: f32,
    tonemap: &str,
    title: &str,
    command: &str,
) -> PyResult<()> {
    let display = DisplayTransform::new(exposure, tone_map(tonemap)?);
    let reference = pixels_of(reference, width, height)?;
    let images = names
        .into_iter()
        .zip(&images)
        .map(|(name, data)| Ok((name, pixels_of(data, width, height)?)))
        .collect::<PyResult<Vec<_>>>()?;
    let report = foton_cli::compare::report::of_images(
        title, command, width, height, display, images, reference,
    );
    foton_cli::compare::report::write(std::path::Path::new(path), &report)
        .map_err(|e| PyOSError::new_err(e.to_string()))
}

#[pymodule]
fn _foton(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NativeScene>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(plugins, m)?)?;
    m.add_function(wrap_pyfunction!(build_info, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(to_display, m)?)?;
    m.add_function(wrap_pyfunction!(errors, m)?)?;
    m.add_function(wrap_pyfunction!(report, m)?)?;
    Ok(())
}
