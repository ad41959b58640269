//! The interface every integrator plugin implements.

use crate::error::Result;
use crate::film::Film;
use crate::props::Properties;
use crate::scene::Scene;
use std::sync::atomic::{AtomicBool, Ordering};

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
    /// Set by the host on Ctrl-C: stop soon and return what has been done.
    pub cancel: &'a AtomicBool,
    pub progress: &'a dyn Progress,
}

impl RenderContext<'_> {
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// An integrator: computes an image of a scene.
pub trait Integrator: Send + Sync {
    /// Renders the scene's camera view. On cancellation, returns the film as it is (each pixel
    /// holds its own sample count), not an error.
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film>;

    /// The configured integrator, for logs and labels (Mitsuba's `to_string`).
    fn describe(&self) -> String;
}

/// Creates an integrator from its `[integrators.NAME]` parameters.
pub type CreateIntegrator = fn(&Properties<'_>, &Scene) -> Result<Box<dyn Integrator>>;
