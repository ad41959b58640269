//! The interface every integrator plugin implements, and what the host hands a render.
//!
//! Besides rendering, an integrator answers the tools' questions through typed methods, never
//! through its description text: its parameters ([`Integrator::parameters`], from which
//! [`Integrator::describe`] is built), how a time budget scales its work
//! ([`Integrator::budget`]) and the photon maps it would build ([`Integrator::photon_maps`]).
//! Any change to this file is a change of the plugin API (docs/plugins.md, "Versions").

use crate::Rgb;
use crate::error::Result;
use crate::film::Film;
use crate::props::Properties;
use crate::scene::Scene;
use glam::Vec3;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

// Parts of the interface in modules of their own, below it, so that `film` and `kernel`
// need not import it; their paths here are kept.
pub use crate::param::{ParamValue, Parameter};
pub use crate::part::Part;

/// Progress and messages from a render, implemented by the host (a terminal progress bar, or
/// nothing). Shared with plugins by reference: a plugin has its own copy of every static, so
/// anything that must be shared is handed over through this interface.
pub trait Progress: Send + Sync {
    /// A new phase ("photons", "pixels") with `total` units of work.
    fn begin(&self, phase: &str, total: u64);
    /// `units` more units of the current phase are done.
    fn advance(&self, units: u64);
    fn finish(&self);
    /// A non-fatal message for the user.
    fn warn(&self, message: &str);
    /// `n` more rays were traced (for a rays/s display).
    fn rays(&self, _n: u64) {}
    /// A short status for the current phase (a progressive integrator's iteration, photons
    /// so far and radius), shown beside the bar.
    fn status(&self, _text: &str) {}
    /// A progressive integrator finished iteration `iteration` (1-based); `image` makes the
    /// current estimate. The host writes it when the user asked for checkpoints.
    fn checkpoint(&self, _iteration: u64, _image: &dyn Fn() -> Film) {}
    /// Phase `name` of the render ran once more, for `wall` of wall-clock time and `cpu` of
    /// the process's CPU time (all threads): see [`RenderContext::timed`]. A progressive
    /// integrator reports its phases once per iteration; `foton bench --json` sums them.
    fn phase(&self, _name: &str, _wall: Duration, _cpu: Duration) {}
}

/// Progress that reports nothing.
pub struct NoProgress;
impl Progress for NoProgress {
    fn begin(&self, _: &str, _: u64) {}
    fn advance(&self, _: u64) {}
    fn finish(&self) {}
    fn warn(&self, _: &str) {}
}

/// What the host gives a render besides the scene.
pub struct RenderContext<'a> {
    /// Worker threads (a plugin builds its own pool of this size: its rayon is its own copy).
    pub threads: usize,
    /// Set by the host (on Ctrl-C, or when a tool has seen enough): stop soon and return what
    /// has been done.
    pub cancel: &'a AtomicBool,
    pub progress: &'a dyn Progress,
    /// The share of the work to do (`foton render --part I/N`); [`Part::WHOLE`] for all of it.
    pub part: Part,
    /// `Some(depth)`: keep each sampling technique's share of the image as a layer of the
    /// film (`foton render --techniques`), the layers [`Integrator::techniques`] names for
    /// `depth`; None: the image alone.
    pub techniques: Option<u32>,
}

impl<'a> RenderContext<'a> {
    /// A context for the whole render.
    pub fn new(threads: usize, cancel: &'a AtomicBool, progress: &'a dyn Progress) -> Self {
        RenderContext {
            threads,
            cancel,
            progress,
            part: Part::WHOLE,
            techniques: None,
        }
    }

    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// Runs `f` as phase `name` of the render (photon tracing, the map's build, the camera
    /// pass...), reporting its wall-clock and CPU time to [`Progress::phase`].
    pub fn timed<R>(&self, name: &str, f: impl FnOnce() -> R) -> R {
        let _phase = self.phase(name);
        f()
    }

    /// Phase `name` of the render from now until the returned guard is dropped (see
    /// [`RenderContext::timed`]).
    pub fn phase<'n>(&self, name: &'n str) -> PhaseTimer<'_, 'n> {
        PhaseTimer {
            progress: self.progress,
            name,
            wall: Instant::now(),
            cpu: process_cpu_time(),
        }
    }
}

/// A phase of a render being timed: reports itself to [`Progress::phase`] when dropped.
pub struct PhaseTimer<'a, 'n> {
    progress: &'a dyn Progress,
    name: &'n str,
    wall: Instant,
    cpu: Duration,
}

impl Drop for PhaseTimer<'_, '_> {
    fn drop(&mut self) {
        let cpu = process_cpu_time().saturating_sub(self.cpu);
        self.progress.phase(self.name, self.wall.elapsed(), cpu);
    }
}

/// The CPU time the process has used so far, all its threads together (zero where the
/// platform has no such clock).
pub fn process_cpu_time() -> Duration {
    #[cfg(unix)]
    {
        let mut t = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: clock_gettime writes the timespec it is given and nothing else.
        if unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) } == 0 {
            return Duration::new(t.tv_sec as u64, t.tv_nsec as u32);
        }
    }
    Duration::ZERO
}

/// The process's peak resident memory in bytes (zero where the platform does not say).
pub fn peak_rss_bytes() -> u64 {
    #[cfg(unix)]
    {
        // SAFETY: getrusage fills the struct it is given; zeroed is a valid rusage.
        let mut u: libc::rusage = unsafe { std::mem::zeroed() };
        if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } == 0 {
            // Linux reports kilobytes, macOS bytes.
            let scale = if cfg!(target_os = "macos") { 1 } else { 1024 };
            return u.ru_maxrss.max(0) as u64 * scale;
        }
    }
    0
}

/// "name(a = 1, b = box)": the form of [`Integrator::describe`].
pub fn describe(name: &str, parameters: &[Parameter]) -> String {
    let items: Vec<String> = parameters
        .iter()
        .map(|p| format!("{} = {}", p.name, p.value))
        .collect();
    format!("{name}({})", items.join(", "))
}

/// What the work of a render is counted in.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Work {
    /// Camera samples per pixel, `render.spp`.
    Samples,
    /// Iterations of a progressive integrator, set by the scene value at this dotted key
    /// (`integrators.sppm.iterations`); `render.spp` is not used.
    Iterations { key: String },
    /// A budget the tools cannot set (the integrator decides how much work it does).
    Own,
}

/// How a time budget scales an integrator: the render's time grows with its [`Work`] (from a
/// fixed cost, such as a photon pass), and each of `scaled` (photon budgets) is a cost that a
/// longer budget grows in proportion.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Budget {
    pub work: Work,
    /// Dotted scene keys and their values in force, e.g.
    /// ("integrators.photon.global_photons", 200000).
    pub scaled: Vec<(String, u64)>,
}

impl Budget {
    /// A budget counted in camera samples and nothing else.
    pub fn samples() -> Budget {
        Budget {
            work: Work::Samples,
            scaled: Vec::new(),
        }
    }
}

/// A stored photon as the tools see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapPhoton {
    pub position: Vec3,
    /// Flux carried (W).
    pub power: Rgb,
    /// Surface normal on the side the photon arrived at; zero for a photon in a medium.
    pub normal: Vec3,
}

/// One photon map an integrator builds, for `foton photons`.
#[derive(Clone, Debug, PartialEq)]
pub struct PhotonMapView {
    /// The map's name (`global`, `caustic`, `volume`...), as `foton photons --map` takes it.
    pub name: String,
    /// What the map holds, in a few words ("L S+ D photons of the caustic budget").
    pub description: String,
    /// Photons emitted by the pass that filled it (stored ones are in `photons`).
    pub emitted: u64,
    pub photons: Vec<MapPhoton>,
}

/// An integrator: computes an image of a scene.
pub trait Integrator: Send + Sync {
    /// The name it is registered under (`photon`).
    fn name(&self) -> &str;

    /// Every parameter in force, with the key of `[integrators.NAME]` it is read from.
    fn parameters(&self) -> Vec<Parameter>;

    /// Renders the scene's camera view, or the share of it that `ctx.part` names (an
    /// integrator that cannot split its work returns an error for a part). On cancellation,
    /// returns the film as it is (each pixel holds its own sample count), not an error.
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film>;

    /// How a time budget scales the work (`foton compare --time`).
    fn budget(&self) -> Budget {
        Budget::samples()
    }

    /// The photon maps the integrator builds for `scene`, in the order it names them; empty
    /// for an integrator without photon maps. The same photons a render would store.
    fn photon_maps(&self, _scene: &Scene, _ctx: &RenderContext<'_>) -> Result<Vec<PhotonMapView>> {
        Ok(Vec::new())
    }

    /// Whether the estimator is biased but consistent (density estimation: photon mapping,
    /// merging), its bias vanishing as its budget grows: None for an unbiased one (the
    /// default); otherwise what shrinks the bias, in a few words that name the scene keys
    /// ("more photons (integrators.photon.global_photons) or a smaller
    /// integrators.photon.k"). `foton compare --consistency` says it when the integrator's
    /// image differs from another's.
    fn bias(&self) -> Option<String> {
        None
    }

    /// The sampling techniques whose shares of the image [`Integrator::render`] keeps as layers
    /// of the film when `RenderContext::techniques` is `Some(depth)` (`foton render
    /// --techniques`), by name, in the order of the film's layers; they sum to the image.
    /// `depth` is the path length past which an estimator with a technique per length
    /// (`bdpt`) pools them. Empty (the default): the integrator has no techniques to show, and
    /// the host refuses the option.
    fn techniques(&self, _depth: u32) -> Vec<String> {
        Vec::new()
    }

    /// Whether it renders a meter ([`crate::camera::Meter`]: Mitsuba's radiance and irradiance
    /// meters), which only paths traced from the camera reach. False (the default): the host
    /// refuses a scene whose sensor is one.
    fn renders_meters(&self) -> bool {
        false
    }

    /// The configured integrator, for logs and labels (Mitsuba's `to_string`).
    fn describe(&self) -> String {
        describe(self.name(), &self.parameters())
    }
}

/// Creates an integrator from its `[integrators.NAME]` parameters.
pub type CreateIntegrator = fn(&Properties<'_>, &Scene) -> Result<Box<dyn Integrator>>;
