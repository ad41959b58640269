//! Progress: a bar with elapsed time, ETA and throughput on a terminal; elsewhere (Slurm,
//! Kubernetes, `nohup`, a notebook's subprocess: stderr is a file or a pipe) a plain line every
//! few seconds, which a log keeps and a person can read. Warnings from the render are
//! collected and printed after it.

use foton_core::film::{DisplayTransform, Film};
use foton_core::integrator::Progress;
use foton_loader::FilmFile;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// How often a plain progress line is printed: `FOTON_PROGRESS_INTERVAL` seconds, else 5.
fn plain_interval() -> Duration {
    std::env::var("FOTON_PROGRESS_INTERVAL")
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .map_or(Duration::from_secs(5), Duration::from_secs_f64)
}

/// `render: 42% (5/12), 0:07 elapsed, about 0:10 left`: what a log line says of a phase.
pub fn plain_line(phase: &str, done: u64, total: u64, elapsed: Duration) -> String {
    let clock = |d: Duration| {
        let s = d.as_secs();
        if s >= 3600 {
            format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
        } else {
            format!("{}:{:02}", s / 60, s % 60)
        }
    };
    let done = done.min(total);
    let fraction = if total == 0 {
        1.0
    } else {
        done as f64 / total as f64
    };
    let left = if done == total {
        "done".to_string()
    } else if done == 0 {
        "time left unknown".to_string()
    } else {
        let rest = elapsed.as_secs_f64() * (1.0 - fraction) / fraction;
        format!("about {} left", clock(Duration::from_secs_f64(rest)))
    };
    format!(
        "{phase}: {:.0}% ({done}/{total}), {} elapsed, {left}",
        100.0 * fraction,
        clock(elapsed)
    )
}

pub struct TermProgress {
    bar: Mutex<Option<ProgressBar>>,
    visible: bool,
    /// Plain lines instead of the bar (stderr is not a terminal), this often.
    plain: Option<Duration>,
    /// The current phase for the plain lines: its name and total, the units done, and when
    /// the last line was printed (after the phase began).
    phase: Mutex<(String, u64)>,
    done: AtomicU64,
    printed: Mutex<Duration>,
    pub warnings: Mutex<Vec<String>>,
    rays: AtomicU64,
    start: Mutex<Instant>,
    /// Write the image every N iterations of a progressive integrator to this file, a PNG
    /// through this display transform (the scene's, as the final image).
    checkpoint: Option<(u64, PathBuf, DisplayTransform, Option<glam::DMat3>)>,
    /// Checkpoint calls received (0 after a render: the integrator is not progressive).
    pub checkpoints: AtomicU64,
}

impl TermProgress {
    pub fn new(quiet: bool) -> Self {
        let terminal = std::io::stderr().is_terminal();
        TermProgress {
            bar: Mutex::new(None),
            visible: !quiet && terminal,
            plain: (!quiet && !terminal).then(plain_interval),
            phase: Mutex::new((String::new(), 0)),
            done: AtomicU64::new(0),
            printed: Mutex::new(Duration::ZERO),
            warnings: Mutex::new(Vec::new()),
            rays: AtomicU64::new(0),
            start: Mutex::new(Instant::now()),
            checkpoint: None,
            checkpoints: AtomicU64::new(0),
        }
    }

    /// Writes the current image to `path` (atomically, through the film's `color_matrix`; a
    /// PNG through `display`) every `every` iterations of a progressive integrator.
    pub fn with_checkpoint(
        mut self,
        every: u64,
        path: PathBuf,
        display: DisplayTransform,
        color_matrix: Option<glam::DMat3>,
    ) -> Self {
        self.checkpoint = Some((every.max(1), path, display, color_matrix));
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
        *self.phase.lock().unwrap() = (phase.to_string(), total);
        self.done.store(0, Ordering::Relaxed);
        *self.printed.lock().unwrap() = Duration::ZERO;
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
        self.done.fetch_add(units, Ordering::Relaxed);
        if let Some(every) = self.plain
            // Workers never wait for the printer; whoever holds the lock prints, so lines
            // come out in order.
            && let Ok(mut printed) = self.printed.try_lock()
        {
            let elapsed = self.start.lock().unwrap().elapsed();
            if elapsed >= *printed + every {
                *printed = elapsed;
                let (phase, total) = self.phase.lock().unwrap().clone();
                let done = self.done.load(Ordering::Relaxed);
                eprintln!("{}", plain_line(&phase, done, total, elapsed));
            }
        }
    }
    fn finish(&self) {
        if self.plain.is_some() && *self.printed.lock().unwrap() > Duration::ZERO {
            let (phase, total) = self.phase.lock().unwrap().clone();
            let elapsed = self.start.lock().unwrap().elapsed();
            eprintln!("{}", plain_line(&phase, total, total, elapsed));
        }
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
        if let Some((every, path, display, color_matrix)) = &self.checkpoint
            && iteration.is_multiple_of(*every)
            && let Err(e) = {
                let mut film = image();
                film.color_matrix = *color_matrix;
                film.write(path, display)
            }
        {
            self.warn(&format!("checkpoint at iteration {iteration}: {e}"));
        }
    }
    fn warn(&self, message: &str) {
        self.warnings.lock().unwrap().push(message.to_string());
    }
}
