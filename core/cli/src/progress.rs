//! Terminal progress: a bar with elapsed time, ETA and throughput on a terminal, nothing
//! otherwise. Warnings from the render are collected and printed after it.

use foton_core::film::{DisplayTransform, Film};
use foton_core::integrator::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

pub struct TermProgress {
    bar: Mutex<Option<ProgressBar>>,
    visible: bool,
    pub warnings: Mutex<Vec<String>>,
    rays: AtomicU64,
    start: Mutex<Instant>,
    /// Write the image every N iterations of a progressive integrator to this file, a PNG
    /// through this display transform (the scene's, as the final image).
    checkpoint: Option<(u64, PathBuf, DisplayTransform)>,
    /// Checkpoint calls received (0 after a render: the integrator is not progressive).
    pub checkpoints: AtomicU64,
}

impl TermProgress {
    pub fn new(quiet: bool) -> Self {
        TermProgress {
            bar: Mutex::new(None),
            visible: !quiet && std::io::stderr().is_terminal(),
            warnings: Mutex::new(Vec::new()),
            rays: AtomicU64::new(0),
            start: Mutex::new(Instant::now()),
            checkpoint: None,
            checkpoints: AtomicU64::new(0),
        }
    }

    /// Writes the current image to `path` (atomically; a PNG through `display`) every `every`
    /// iterations of a progressive integrator.
    pub fn with_checkpoint(mut self, every: u64, path: PathBuf, display: DisplayTransform) -> Self {
        self.checkpoint = Some((every.max(1), path, display));
        self
    }

    pub fn take_warnings(&self) -> Vec<String> {
        std::mem::take(&mut *self.warnings.lock().unwrap())
    }
}

impl Progress for TermProgress {
    fn begin(&self, phase: &str, total: u64) {
        let target = if self.visible {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(Some(total), target);
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>8} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta} {msg}",
            )
            .expect("valid template"),
        );
        bar.set_prefix(phase.to_string());
        self.rays.store(0, Ordering::Relaxed);
        *self.start.lock().unwrap() = Instant::now();
        if let Some(old) = self.bar.lock().unwrap().replace(bar) {
            old.finish_and_clear();
        }
    }
    fn advance(&self, units: u64) {
        if let Some(bar) = &*self.bar.lock().unwrap() {
            bar.inc(units);
        }
    }
    fn finish(&self) {
        if let Some(bar) = self.bar.lock().unwrap().take() {
            bar.finish_and_clear();
        }
    }
    fn rays(&self, n: u64) {
        let total = self.rays.fetch_add(n, Ordering::Relaxed) + n;
        if let Some(bar) = &*self.bar.lock().unwrap() {
            let secs = self.start.lock().unwrap().elapsed().as_secs_f64().max(1e-3);
            bar.set_message(format!("{:.2} M rays/s", total as f64 / secs / 1e6));
        }
    }
    fn status(&self, text: &str) {
        if let Some(bar) = &*self.bar.lock().unwrap() {
            bar.set_message(text.to_string());
        }
    }
    fn checkpoint(&self, iteration: u64, image: &dyn Fn() -> Film) {
        self.checkpoints.fetch_add(1, Ordering::Relaxed);
        if let Some((every, path, display)) = &self.checkpoint
            && iteration.is_multiple_of(*every)
            && let Err(e) = image().write(path, display)
        {
            self.warn(&format!("checkpoint at iteration {iteration}: {e}"));
        }
    }
    fn warn(&self, message: &str) {
        self.warnings.lock().unwrap().push(message.to_string());
    }
}
