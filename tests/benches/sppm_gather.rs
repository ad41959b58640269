//! Progressive photon mapping's gather step, two ways (a benchmark, not a test):
//!
//! * kd-tree over the iteration's photons (core's `PhotonMap`), one fixed-radius query per
//!   visible point: what `sppm` does;
//! * pbrt-v4's hash grid over the visible points, each photon adding itself to the visible
//!   points whose disc holds it (atomic adds: faster to write, but the order of the
//!   floating-point additions, and so the image, then depends on the thread count).
//!
//! On the Cornell box at 256x256 (65k visible points) with 100k photons per iteration, the
//! time of one iteration's build + gather for each, and the photons per second of an iteration.
//!
//!   cargo bench -p foton-tests --bench sppm_gather

use foton_core::integrator::{NoProgress, RenderContext};
use foton_core::sampling::independent::Independent;
use foton_core::sampling::{Sampler, SamplerKind};
use foton_core::walk::{CameraWalk, GLOSSY_ROUGHNESS, trace_to_diffuse};
use foton_photonmap::map::PhotonMap;
use foton_photonmap::trace::{PathClass, STREAM_GLOBAL, TraceOptions, trace_photons};
use foton_tests::repo_root;
use glam::{IVec3, Vec2, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Instant;

struct Vp {
    p: Vec3,
    n: Vec3,
}

fn atomic_add(a: &AtomicU32, v: f32) {
    let mut old = a.load(Ordering::Relaxed);
    loop {
        let new = (f32::from_bits(old) + v).to_bits();
        match a.compare_exchange_weak(old, new, Ordering::Relaxed, Ordering::Relaxed) {
            Ok(_) => return,
            Err(x) => old = x,
        }
    }
}

fn main() {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let scene = foton_loader::load(&repo_root().join("scenes/cornell-box.toml"), &[]).unwrap();
    let (w, h) = (scene.film().width, scene.film().height);
    let mut rays = 0;
    let vps: Vec<Vp> = (0..w * h)
        .filter_map(|i| {
            let mut s = Sampler::with_keys(
                SamplerKind::from(Independent),
                &[1, i as u64],
                1,
                i as u64,
                0,
                1,
            );
            let film = Vec2::new((i % w) as f32, (i / w) as f32) + s.next_2d();
            let path = trace_to_diffuse(
                &scene,
                scene.camera().generate_ray(film),
                CameraWalk {
                    max_depth: 16,
                    glossy_roughness: GLOSSY_ROUGHNESS,
                },
                &mut s,
                &mut rays,
            );
            path.visible.map(|v| Vp { p: v.hit.p, n: v.n })
        })
        .collect();
    let radius = 0.02f32;
    let cancel = Default::default();
    let ctx = RenderContext::new(threads, &cancel, &NoProgress);
    let n_photons = 100_000;
    let opts = TraceOptions {
        photons: n_photons,
        max_depth: 16,
        seed: 3,
        stream: STREAM_GLOBAL,
        stop_at_diffuse: false,
        sobol_emission: false,
    };
    let t = Instant::now();
    let photons = trace_photons(&scene, &opts, &ctx, 1, |_, c| {
        (c != PathClass::Direct).then_some(0)
    })
    .unwrap()
    .pop()
    .unwrap();
    let trace = t.elapsed().as_secs_f64();
    println!(
        "{} visible points, {n_photons} photons traced in {trace:.3} s ({:.2} M photons/s, {threads} threads), {} stored, radius {radius}",
        vps.len(),
        n_photons as f64 / trace / 1e6,
        photons.len()
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();

    for round in 0..3 {
        // kd-tree over photons, a query per visible point.
        let t = Instant::now();
        let (map, counts) = pool.install(|| {
            let map = PhotonMap::build(photons.clone());
            let counts: Vec<f32> = vps
                .par_iter()
                .map(|vp| {
                    let mut m = 0.0;
                    map.within(vp.p, radius, |ph, _| {
                        if ph.normal().dot(vp.n) > 0.9 {
                            m += ph.power().x;
                        }
                    });
                    m
                })
                .collect();
            (map, counts)
        });
        let kd = t.elapsed().as_secs_f64();
        drop(map);

        // Hash grid over visible points (cells of the diameter), photons scattered into it.
        let t = Instant::now();
        let grid_counts = pool.install(|| {
            let cell = 2.0 * radius;
            let key = |p: Vec3| (p / cell).floor().as_ivec3();
            let mut grid: HashMap<IVec3, Vec<u32>> = HashMap::new();
            for (i, vp) in vps.iter().enumerate() {
                let (lo, hi) = (key(vp.p - radius), key(vp.p + radius));
                for z in lo.z..=hi.z {
                    for y in lo.y..=hi.y {
                        for x in lo.x..=hi.x {
                            grid.entry(IVec3::new(x, y, z)).or_default().push(i as u32);
                        }
                    }
                }
            }
            let built = t.elapsed().as_secs_f64();
            let sums: Vec<AtomicU32> = (0..vps.len()).map(|_| AtomicU32::new(0)).collect();
            photons.par_iter().for_each(|ph| {
                if let Some(list) = grid.get(&key(ph.position)) {
                    for &i in list {
                        let vp = &vps[i as usize];
                        if vp.p.distance_squared(ph.position) < radius * radius
                            && ph.normal().dot(vp.n) > 0.9
                        {
                            atomic_add(&sums[i as usize], ph.power().x);
                        }
                    }
                }
            });
            let sums = sums
                .into_iter()
                .map(|a| f32::from_bits(a.into_inner()))
                .collect::<Vec<f32>>();
            (sums, built)
        });
        let (grid_counts, grid_build) = grid_counts;
        let hash = t.elapsed().as_secs_f64();
        let (a, b): (f64, f64) = (
            counts.iter().map(|&x| x as f64).sum(),
            grid_counts.iter().map(|&x| x as f64).sum(),
        );
        assert!(
            (a - b).abs() <= 1e-3 * a.max(1e-9),
            "the two gathers disagree: {a} vs {b}"
        );
        println!(
            "round {round}: kd-tree over photons {:.1} ms, hash grid over visible points {:.1} ms (of which a serial build {:.1} ms) (build + gather, {threads} threads)",
            kd * 1e3,
            hash * 1e3,
            grid_build * 1e3
        );
    }
    let photon_bytes = photons.len() * std::mem::size_of::<foton_photonmap::map::Photon>();
    println!(
        "memory per iteration: photons {:.1} MB (+ positions and splits {:.1} MB in the tree)",
        photon_bytes as f64 / 1e6,
        photons.len() as f64 * 17.0 / 1e6
    );
}
