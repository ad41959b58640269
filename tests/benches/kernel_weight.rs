//! A kernel plugin's weight with and without the check on use (a benchmark, not a test): what
//! the estimates pay per photon for a plugin kernel, checked (every plugin kernel now) and
//! called as it comes (as before). Compiles plugins/epanechnikov with the system C compiler.
//!
//!   cargo bench -p foton-tests --bench kernel_weight

use foton_core::kernel::{Kernel, NormalizedKernel};
use foton_core::plugin::{KernelPlugin, Registry};
use foton_tests::{repo_root, temp_dir};
use std::hint::black_box;
use std::process::Command;
use std::time::Instant;

/// A plugin's profile taken as it comes (a trusted kernel, like the built-ins).
struct Unchecked(KernelPlugin);
impl Kernel for Unchecked {
    fn name(&self) -> &str {
        self.0.name()
    }
    fn profile(&self, t: f64) -> f64 {
        self.0.profile(t)
    }
}

/// Nanoseconds per `weight_2d` over distances spread over the disc, in no order.
fn time(kernel: &NormalizedKernel, n: u32) -> f64 {
    let r = 0.37f32;
    let t = Instant::now();
    let mut s = 0.0f32;
    for i in 0..n {
        let d = (i.wrapping_mul(2_654_435_761) >> 8) as f32 / (1 << 24) as f32 * r;
        s += kernel.weight_2d(black_box(d), r);
    }
    black_box(s);
    t.elapsed().as_secs_f64() * 1e9 / n as f64
}

fn main() {
    let dir = temp_dir("kernel-bench");
    let status = Command::new(std::env::var("CC").unwrap_or_else(|_| "cc".into()))
        .args(["-shared", "-fPIC", "-O2", "-I"])
        .arg(repo_root().join("plugins"))
        .arg("-o")
        .arg(dir.join("libfoton_epanechnikov.so"))
        .arg(repo_root().join("plugins/epanechnikov/epanechnikov.c"))
        .status()
        .expect("cc");
    assert!(status.success());
    let plugin = Registry::discover(std::slice::from_ref(&dir))
        .kernel("epanechnikov")
        .expect("found")
        .clone();
    let checked = NormalizedKernel::new(Box::new(plugin.clone())).unwrap();
    let unchecked = NormalizedKernel::new(Box::new(Unchecked(plugin))).unwrap();
    let n = 20_000_000;
    time(&checked, n); // warm-up
    for _ in 0..3 {
        let (a, b) = (time(&unchecked, n), time(&checked, n));
        let (c, d) = (time(&checked, n), time(&unchecked, n));
        println!(
            "weight_2d: checked {:.2} ns, unchecked {:.2} ns",
            (b + c) / 2.0,
            (a + d) / 2.0
        );
    }
    checked
        .check_weights()
        .expect("Epanechnikov's weights are all good");
    let _ = std::fs::remove_dir_all(dir);
}
