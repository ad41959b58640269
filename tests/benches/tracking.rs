//! Tracking through the smoke scene's density grid (a benchmark, not a test): free-flight
//! samples and transmittance evaluations per second with the analytic tracking the renderer
//! uses (`Grid::invert`, `Grid::integral`) beside delta and ratio tracking
//! (`foton_core::medium::tracking`) over majorant grids of 2^3, 4^3 and 8^3 cells per block and
//! a single global majorant; and ratio tracking's variance, whence its efficiency 1 / (variance
//! x time) (analytic transmittance has no variance).
//!
//!   cargo bench -p foton-tests --bench tracking

use foton_core::geometry::Ray;
use foton_core::medium::grid::{Grid, Outside, Samples, VolFile};
use foton_core::medium::tracking::{Majorants, Pcg32, delta_tracking, ratio_tracking};
use foton_tests::repo_root;
use glam::{Mat4, Vec3};
use std::hint::black_box;
use std::time::Instant;

/// scenes/smoke.toml's extinction and box.
const SIGMA_T: f64 = 40.0;
const LO: Vec3 = Vec3::new(-0.6, 0.001, -0.6);
const SIZE: Vec3 = Vec3::new(1.2, 1.6, 1.2);

/// The distances over which `ray` is inside the smoke's box.
fn box_span(ray: &Ray) -> (f32, f32) {
    let (lo, hi) = (LO, LO + SIZE);
    let (mut t0, mut t1) = (f32::NEG_INFINITY, f32::INFINITY);
    for a in 0..3 {
        let (x, y) = (
            (lo[a] - ray.origin[a]) / ray.dir[a],
            (hi[a] - ray.origin[a]) / ray.dir[a],
        );
        t0 = t0.max(x.min(y));
        t1 = t1.min(x.max(y));
    }
    (t0, t1)
}

/// The medium segments of the benchmark: from points in the box in uniform directions to the
/// box's wall (paths scattered inside), and from the camera through the box (its entry to its
/// exit).
fn rays(n: usize) -> Vec<(Ray, f32)> {
    let mut rng = Pcg32::new(2024);
    let mut u = || rng.uniform() as f32;
    let mut out = Vec::with_capacity(2 * n);
    for _ in 0..n {
        let o = LO + SIZE * Vec3::new(u(), u(), u());
        let z = 2.0 * u() - 1.0;
        let phi = std::f32::consts::TAU * u();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let ray = Ray::new(o, Vec3::new(r * phi.cos(), r * phi.sin(), z));
        let (_, t1) = box_span(&ray);
        out.push((ray, t1));
    }
    let camera = Vec3::new(0.0, 1.0, 3.9);
    while out.len() < 2 * n {
        let target = LO + SIZE * Vec3::new(u(), u(), u());
        let ray = Ray::new(camera, (target - camera).normalize());
        let (t0, t1) = box_span(&ray);
        if t1 > t0 && t0 > 0.0 {
            out.push((Ray::new(ray.at(t0), ray.dir), t1 - t0));
        }
    }
    out
}

/// The fastest of `rounds` runs of `f` over all rays, in nanoseconds per ray.
fn time(rounds: usize, rays: usize, mut f: impl FnMut() -> f64) -> f64 {
    (0..rounds)
        .map(|_| {
            let t = Instant::now();
            black_box(f());
            t.elapsed().as_secs_f64() * 1e9 / rays as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let bytes = std::fs::read(repo_root().join("scenes/volumes/smoke.vol")).expect("smoke.vol");
    let f = VolFile::parse(&bytes).unwrap();
    let to_world = Mat4::from_translation(LO) * Mat4::from_scale(SIZE);
    let grid = Grid::new(
        f.res,
        f.channels,
        f.values,
        to_world,
        Samples::Centres,
        Outside::Clamp,
    )
    .unwrap();
    let rays = rays(100_000);
    let n = rays.len();
    let exact: Vec<f64> = rays
        .iter()
        .map(|(r, t)| (-SIGMA_T * grid.integral(r, *t).x).exp())
        .collect();
    println!(
        "smoke.vol {:?}, sigma_t {SIGMA_T} x density (max {}), {n} segments \
         (half from inside the box, half from the camera), mean transmittance {:.4}",
        f.res,
        grid.max(),
        exact.iter().sum::<f64>() / n as f64
    );
    let rounds = 3;
    let mut rng = Pcg32::new(7);

    // Analytic: one uniform number per free flight, none per transmittance.
    let ff = time(rounds, n, || {
        let mut s = 0.0;
        for (r, tmax) in &rays {
            let target = -(1.0 - rng.uniform()).ln() / SIGMA_T;
            s += grid.invert(r, *tmax, 0, target).0.unwrap_or(-1.0);
        }
        s
    });
    let tr = time(rounds, n, || {
        rays.iter()
            .map(|(r, t)| (-SIGMA_T * grid.integral(r, *t).x).exp())
            .sum()
    });
    println!();
    println!(
        "| tracking | free flight ns/sample | Msamples/s | uniforms/sample | transmittance ns/eval | Mevals/s | uniforms/eval | variance | efficiency 1/(var x s) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    println!(
        "| analytic (invert, integral) | {ff:.0} | {:.2} | - | {tr:.0} | {:.2} | - | 0 | inf |",
        1e3 / ff,
        1e3 / tr
    );
    let kinds = [
        ("global majorant", Majorants::global(&grid)),
        ("majorant grid 8^3 cells/block", Majorants::new(&grid, 8)),
        ("majorant grid 4^3 cells/block", Majorants::new(&grid, 4)),
        ("majorant grid 2^3 cells/block", Majorants::new(&grid, 2)),
    ];
    for (name, maj) in &kinds {
        // Uniform numbers drawn: delta tracking, two per tentative collision (distance,
        // acceptance) and one per segment it leaves; ratio tracking, one per tentative
        // collision and one per segment it leaves.
        let mut draws = 0u64;
        let ff = time(rounds, n, || {
            draws = 0;
            let mut u = || {
                draws += 1;
                rng.uniform()
            };
            let mut s = 0.0;
            for (r, tmax) in &rays {
                s += delta_tracking(&grid, maj, r, *tmax, SIGMA_T, 0, &mut u).unwrap_or(-1.0);
            }
            s
        });
        let ff_draws = draws as f64 / n as f64;
        let mut err2 = 0.0;
        let tr = time(rounds, n, || {
            draws = 0;
            err2 = 0.0;
            let mut u = || {
                draws += 1;
                rng.uniform()
            };
            let mut s = 0.0;
            for ((r, tmax), exact) in rays.iter().zip(&exact) {
                let e = ratio_tracking(&grid, maj, r, *tmax, SIGMA_T, 0, &mut u);
                err2 += (e - exact) * (e - exact);
                s += e;
            }
            s
        });
        let variance = err2 / n as f64;
        println!(
            "| {name} ({} majorants) | {ff:.0} | {:.2} | {:.1} | {tr:.0} | {:.2} | {:.1} | {variance:.5} | {:.3e} |",
            maj.len(),
            1e3 / ff,
            ff_draws,
            1e3 / tr,
            draws as f64 / n as f64,
            1.0 / (variance * tr * 1e-9)
        );
    }
}
