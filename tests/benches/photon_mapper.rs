//! Photon-mapper benchmark (not a test): photons traced per second, map build time and k = 50
//! queries per second on a real 1M-photon map, and the render time of course scene 1.
//!
//!   cargo bench -p foton-tests --bench photon_mapper

use foton_cli::{TermProgress, prepare, render_prepared};
use foton_core::integrator::{NoProgress, RenderContext};
use foton_core::kernel::{BoxKernel, NormalizedKernel};
use foton_photonmap::map::{Disc, Estimate, PhotonMap};
use foton_photonmap::trace::{PathClass, STREAM_GLOBAL, TraceOptions, trace_photons};
use foton_tests::{plugin_dir, repo_root};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

fn main() {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cancel = AtomicBool::new(false);
    let ctx = RenderContext::new(threads, &cancel, &NoProgress);
    let scene = foton_loader::load(&repo_root().join("scenes/cornell-box.toml"), &[]).unwrap();
    let n = 1_000_000;
    let opts = TraceOptions {
        photons: n,
        max_depth: 16,
        seed: 0,
        stream: STREAM_GLOBAL,
        stop_at_diffuse: false,
        sobol_emission: false,
    };
    let t = Instant::now();
    let photons = trace_photons(&scene, &opts, &ctx, 1, |_, c| {
        (c != PathClass::Caustic).then_some(0)
    })
    .unwrap()
    .pop()
    .unwrap();
    let secs = t.elapsed().as_secs_f64();
    println!(
        "cornell-box: {n} photons traced in {secs:.3} s = {:.2} M photons/s ({threads} threads), {} stored",
        n as f64 / secs / 1e6,
        photons.len()
    );

    let million: Vec<_> = photons.iter().cycle().take(1_000_000).copied().collect();
    let t = Instant::now();
    let map = PhotonMap::build(million);
    println!(
        "map build, 1M photons: {:.3} s ({threads} threads)",
        t.elapsed().as_secs_f64()
    );

    // Queries at the photons' own positions (where a render asks), one thread.
    let kernel = NormalizedKernel::new(Box::new(BoxKernel)).unwrap();
    let estimate = Estimate {
        k: 50,
        max_radius: 0.2,
        kernel: &kernel,
    };
    let mut scratch = Vec::new();
    let queries = 200_000;
    let t = Instant::now();
    let mut sum = 0.0f32;
    for p in photons.iter().step_by(photons.len() / queries + 1) {
        sum += map
            .irradiance(
                &Disc::new(p.position, p.normal(), 16),
                &estimate,
                &mut scratch,
            )
            .x;
    }
    let done = photons.len().div_ceil(photons.len() / queries + 1);
    let secs = t.elapsed().as_secs_f64();
    println!(
        "k = 50 irradiance estimates (with the normal test), 1 thread: {:.0} per second (checksum {sum:.3})",
        done as f64 / secs
    );

    let prepared = prepare(
        &repo_root().join("scenes/caustics.toml"),
        &[
            "integrators.photon.global_photons=1000000".into(),
            "integrators.photon.caustic_photons=1000000".into(),
            "integrators.photon.k=50".into(),
        ],
        &[plugin_dir()],
        false,
    )
    .unwrap();
    let progress = TermProgress::new(true);
    let (film, secs) = render_prepared(&prepared, threads, &progress).unwrap();
    println!(
        "caustics.toml, 1M global + 1M caustic photons, k = 50, {}x{} x {} spp: {:.2} s ({threads} threads)",
        film.width,
        film.height,
        prepared.scene.render().spp,
        secs.as_secs_f64()
    );
}
