//! Statistical tests of the media's sampling: phase functions and free-flight distances, with
//! the machinery of sampling.rs.

use crate::sampling::{
    FREE_FLIGHT_CASES, PHASES, alpha_each, assert_gof, check_directions, d, phase_grid, simpson,
};
use foton_core::medium::{Homogeneous, Medium, Phase, channel};
use foton_core::sampling::Rng;
use foton_tests::stats::{assert_close, assert_rel, chi2_gof};
use glam::{DVec3, Vec3};
use std::f64::consts::TAU;

// ---------------------------------------------------------------------------------------------
// Phase functions
// ---------------------------------------------------------------------------------------------

#[test]
fn phase_functions_sample_their_eval_and_are_normalised() {
    let dir = Vec3::new(0.2, 0.7, -0.4).normalize();
    for (k, phase) in PHASES.iter().enumerate() {
        let g = match *phase {
            Phase::Isotropic => 0.0,
            Phase::HenyeyGreenstein { g } => g as f64,
        };
        // eval integrates to one over the sphere and its mean cosine is g.
        let p = |mu: f64| phase.eval(mu as f32) as f64;
        let norm = TAU * simpson(p, -1.0, 1.0, 200_000);
        let mean = TAU * simpson(|mu| mu * p(mu), -1.0, 1.0, 200_000);
        assert_close(&format!("{phase:?}: integral of eval"), norm, 1.0, 1e-4);
        assert_close(&format!("{phase:?}: mean cosine"), mean, g, 1e-4);

        // Peaks at the pole of the grid.
        let axis = if g < 0.0 { -d(dir) } else { d(dir) };
        let grid = phase_grid(axis);
        let mut rng = Rng::new(&[50, k as u64]);
        let pdf = |w: DVec3| phase.eval(d(dir).dot(w) as f32) as f64;
        let integral = check_directions(
            &format!("{phase:?} sampling"),
            &grid,
            1_000_000,
            0.0,
            &pdf,
            &mut || {
                let (wi, pdf) = phase.sample(dir, rng.next_2d());
                assert_close("|wi|", wi.length() as f64, 1.0, 1e-5);
                let want = phase.eval(dir.dot(wi)) as f64;
                assert_rel(
                    &format!("{phase:?}: sample pdf vs eval"),
                    pdf as f64,
                    want,
                    1e-3,
                );
                Some(d(wi))
            },
        );
        assert_close(
            &format!("{phase:?}: integral over the grid"),
            integral,
            1.0,
            1e-3,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Free-flight distances in media
// ---------------------------------------------------------------------------------------------

/// Probability that a free-flight distance with the spectral-MIS density (channel chosen
/// uniformly) falls in [a, b): the mean over channels of exp(-s a) - exp(-s b).
fn free_flight_mass(sigma_t: [f64; 3], a: f64, b: f64) -> f64 {
    sigma_t
        .iter()
        .map(|&s| {
            let tr = |t: f64| if s == 0.0 { 1.0 } else { (-s * t).exp() };
            tr(a) - tr(b)
        })
        .sum::<f64>()
        / 3.0
}

#[test]
fn free_flight_sampling_follows_the_spectral_mis_density_and_is_unbiased() {
    const N: usize = 400_000;
    const BINS: usize = 60;
    for (k, &(sigma_a, sigma_s, tmax)) in FREE_FLIGHT_CASES.iter().enumerate() {
        let medium = Homogeneous {
            sigma_a: Vec3::from(sigma_a),
            sigma_s: Vec3::from(sigma_s),
            phase: Phase::Isotropic,
            emission: Vec3::ZERO,
        };
        let sigma_t = medium.sigma_t().as_dvec3().to_array();
        let name = format!("free flight {sigma_t:?}, tmax {tmax}");
        // Cells: BINS equal widths over [0, end), then [end, tmax) (if tmax is infinite), then
        // "passed" (t = tmax).
        let end = if tmax.is_finite() { tmax as f64 } else { 8.0 };
        let mut edges: Vec<f64> = (0..=BINS).map(|i| end * i as f64 / BINS as f64).collect();
        edges.push(tmax as f64);
        let cells = edges.len(); // BINS + 1 intervals (the last maybe empty) + passed
        let mut expected: Vec<f64> = edges
            .windows(2)
            .map(|w| free_flight_mass(sigma_t, w[0], w[1]))
            .collect();
        expected.push(1.0 - free_flight_mass(sigma_t, 0.0, tmax as f64));

        let mut observed = vec![0u64; cells];
        let mut rng = Rng::new(&[60, k as u64]);
        // Through the Medium interface, as the integrators sample it.
        let ray = foton_core::geometry::Ray::new(Vec3::ZERO, Vec3::Z);
        // Per channel: sum of weights of scattering events, and of passing samples.
        let (mut scattered, mut passed) = (DVec3::ZERO, DVec3::ZERO);
        for _ in 0..N {
            let c = channel(rng.next_f32());
            let f = medium.sample_free_flight(&ray, tmax, c, rng.next_f32());
            let w = f.weight().as_dvec3();
            if f.scattered {
                assert!(f.t >= 0.0 && f.t < tmax, "{name}: t = {}", f.t);
                let cell = edges.partition_point(|&e| e <= f.t as f64) - 1;
                observed[cell.min(cells - 2)] += 1;
                // The reported pdfs are the per-channel densities at t.
                let t = f.t as f64;
                for (c, &st) in sigma_t.iter().enumerate() {
                    let want = st * (-st * t).exp();
                    // f32 underflows after ~87 mean free paths.
                    assert_close(
                        &format!("{name}: pdf[{c}]"),
                        f.pdf[c] as f64,
                        want,
                        1e-4 * want + 1e-30,
                    );
                }
                scattered += w;
            } else {
                assert_eq!(f.t, tmax);
                observed[cells - 1] += 1;
                passed += w;
            }
        }
        assert_gof(
            &name,
            &observed,
            &expected.iter().map(|p| p * N as f64).collect::<Vec<_>>(),
        );

        // The expectation of the weights, per channel: sigma_s / sigma_t (1 - Tr(tmax)) for
        // scattering events, Tr(tmax) for passing.
        for c in 0..3 {
            let (st, ss) = (sigma_t[c], sigma_s[c] as f64);
            let tr = if st == 0.0 {
                1.0
            } else {
                (-st * tmax as f64).exp()
            };
            let want_s = if st == 0.0 { 0.0 } else { ss / st * (1.0 - tr) };
            assert_close(
                &format!("{name}: E[weight, scattered][{c}]"),
                scattered[c] / N as f64,
                want_s,
                0.01,
            );
            assert_close(
                &format!("{name}: E[weight, passed][{c}]"),
                passed[c] / N as f64,
                tr,
                0.01,
            );
        }

        // The test can fail: the same samples against the density of a grey medium of the
        // mean sigma_t (what sampling one channel and forgetting the others would assume).
        let mean = (sigma_t[0] + sigma_t[1] + sigma_t[2]) / 3.0;
        let mut wrong: Vec<f64> = edges
            .windows(2)
            .map(|w| free_flight_mass([mean; 3], w[0], w[1]) * N as f64)
            .collect();
        wrong.push((1.0 - free_flight_mass([mean; 3], 0.0, tmax as f64)) * N as f64);
        if sigma_t[0] != sigma_t[1] {
            let g = chi2_gof(&observed, &wrong).map(|g| g.p).unwrap_or(0.0);
            assert!(g < alpha_each(), "{name}: a wrong density passed (p = {g})");
        }
    }
}
