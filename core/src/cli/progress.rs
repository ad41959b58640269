//! Terminal progress: a bar with elapsed time, ETA and throughput on a terminal, nothing
//! otherwise. Warnings from the render are collected and printed after it.

use crate::integrator::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;

pub struct TermProgress {
    bar: Mutex<Option<ProgressBar>>,
    visible: bool,
    pub warnings: Mutex<Vec<String>>,
}

impl TermProgress {
    pub fn new(quiet: bool) -> Self {
        TermProgress {
            bar: Mutex::new(None),
            visible: !quiet && std::io::stderr().is_terminal(),
            warnings: Mutex::new(Vec::new()),
        }
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
                "{prefix:>8} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta} {per_sec}",
            )
            .expect("valid template"),
        );
        bar.set_prefix(phase.to_string());
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
    fn warn(&self, message: &str) {
        self.warnings.lock().unwrap().push(message.to_string());
    }
}
