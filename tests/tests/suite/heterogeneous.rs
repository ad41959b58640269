//! The `heterogeneous` medium: density and albedo on grids, exact transmittance and
//! free-flight sampling (core/src/medium/grid.rs), rendered by every integrator that renders
//! media.

use foton_core::Rgb;
use foton_core::geometry::Ray;
use foton_core::medium::grid::{Grid, Outside, Samples};
use foton_core::medium::heterogeneous::Albedo;
use foton_core::medium::{Heterogeneous, Medium, Phase};
use foton_tests::render_toml;
use foton_tests::stats::{Tolerance, assert_blocks_agree, assert_gof};
use glam::{Mat4, Vec3};

/// A grey medium of `res` samples on the unit cube (Mitsuba 3's placement).
fn medium(res: [usize; 3], values: Vec<f32>, sigma_t: Rgb, samples: Samples) -> Heterogeneous {
    Heterogeneous {
        density: Grid::new(res, 1, values, Mat4::IDENTITY, samples, Outside::Zero).unwrap(),
        sigma_t,
        albedo: Albedo::Constant(Rgb::splat(0.5)),
        phase: Phase::Isotropic,
        emission: None,
    }
}

/// A density rising linearly from a to b across the cube, along x: along any ray that crosses
/// it, the optical depth is sigma_t (a + b) / 2 times the length inside, whatever the path.
#[test]
fn transmittance_is_exp_of_minus_the_optical_depth_of_a_linear_ramp() {
    let (a, b) = (0.5f32, 3.5f32);
    let sigma_t = Rgb::new(1.0, 0.5, 2.0);
    let m = medium([2, 1, 1], vec![a, b], sigma_t, Samples::Corners);
    // Through the cube along x from outside: length 1 inside.
    let ray = Ray::new(Vec3::new(-0.5, 0.0, 0.0), Vec3::X);
    let want = (-sigma_t * (a + b) / 2.0).exp();
    let got = m.transmittance(&ray, 2.0);
    assert!((got - want).abs().max_element() < 1e-5, "{got} vs {want}");
    // Half way: the integral of a + (b - a) x over (0, 1/2).
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    let want = (-sigma_t * (a / 2.0 + (b - a) / 8.0)).exp();
    let got = m.transmittance(&ray, 0.5);
    assert!((got - want).abs().max_element() < 1e-5, "{got} vs {want}");
    // Diagonally in the plane y = 0: the density depends on x alone, so the depth is the
    // mean density over the chord times its length.
    let dir = Vec3::new(1.0, 0.0, 1.0).normalize();
    let ray = Ray::new(Vec3::ZERO, dir);
    let len = 2f32.sqrt();
    let want = (-sigma_t * (a + b) / 2.0 * len).exp();
    let got = m.transmittance(&ray, 10.0);
    assert!((got - want).abs().max_element() < 1e-5, "{got} vs {want}");
}

/// Free-flight distances follow sigma_t,c(t) Tr_c(t) for the channel sampled: a chi-square
/// test of 200 000 distances in 24 bins of a ray through a random 4 x 4 x 4 grid, plus the
/// probability of passing the segment; and each sample's pdf is that density.
#[test]
fn free_flight_distances_follow_the_exact_density() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let values: Vec<f32> = (0..64).map(|_| 3.0 * next()).collect();
    let sigma_t = Rgb::new(1.0, 2.0, 0.5);
    let m = medium([4, 4, 4], values, sigma_t, Samples::Centres);
    let ray = Ray::new(
        Vec3::new(-0.2, 0.1, 0.3),
        Vec3::new(1.0, 0.7, 0.4).normalize(),
    );
    let tmax = 1.4;
    let bins = 24;
    let edge = |i: usize| tmax * i as f32 / bins as f32;
    for channel in 0..3 {
        let tr = |t: f32| m.transmittance(&ray, t)[channel] as f64;
        let mut expected: Vec<f64> = (0..bins).map(|i| tr(edge(i)) - tr(edge(i + 1))).collect();
        expected.push(tr(tmax));
        let n = 200_000;
        let mut observed = vec![0u64; bins + 1];
        for _ in 0..n {
            let f = m.sample_free_flight(&ray, tmax, channel, next());
            if f.scattered {
                observed[((f.t / tmax * bins as f32) as usize).min(bins - 1)] += 1;
                let p = ray.at(f.t);
                let want = m.sigma_t(p)[channel] * m.transmittance(&ray, f.t)[channel];
                assert!((f.pdf[channel] - want).abs() <= 1e-4 * want.max(1e-3));
            } else {
                assert_eq!(f.t, tmax);
                observed[bins] += 1;
            }
        }
        let expected: Vec<f64> = expected.iter().map(|p| p * n as f64).collect();
        assert_gof(&format!("channel {channel}"), &observed, &expected, 1e-4);
    }
}

/// The point-light fog box of the beam tests with its fog on a grid: `values` (3 x 3 x 3,
/// x fastest) of density, sigma_t 0.7 and albedo 6/7 (the homogeneous fog's sigma_a 0.1,
/// sigma_s 0.6 at density 1).
fn grid_fog(integrator: &str, spp: u32, tables: &str, values: &[f32]) -> String {
    let fog = foton_tests::point_light_fog(integrator, spp, 8, "\"isotropic\"", tables);
    let values: Vec<String> = values.iter().map(|v| format!("{v:.3}")).collect();
    let grid = format!(
        r#"[media.fog]
type = "heterogeneous"
sigma_t = 0.7
albedo = {albedo}
density = {{ resolution = [3, 3, 3], values = [{values}], transform = {{ translate = [-1.0, -1.6, -1.0], scale = [2.0, 3.2, 2.0] }} }}
"#,
        albedo = 0.6 / 0.7,
        values = values.join(", ")
    );
    let homogeneous = "[media.fog]\ntype = \"homogeneous\"\nsigma_a = [0.1, 0.1, 0.1]\nsigma_s = [0.6, 0.6, 0.6]\n";
    assert!(fog.contains(homogeneous));
    fog.replace(homogeneous, &grid)
}

/// A density that varies by a factor of ten over the box.
fn varying() -> Vec<f32> {
    (0..27)
        .map(|i| 0.2 + 1.8 * (((i * 7) % 27) as f32 / 26.0))
        .collect()
}

/// A grid of ones is the homogeneous fog: the same image for the same seed (the same random
/// numbers give the same distances, to rounding).
#[test]
fn a_grid_of_ones_renders_as_the_homogeneous_medium() {
    let homogeneous = foton_tests::point_light_fog("path", 64, 8, "\"isotropic\"", "");
    let grid = grid_fog("path", 64, "", &[1.0; 27]);
    let a = render_toml("grid-ones", &grid, &[], 2);
    let b = render_toml("grid-ones-homogeneous", &homogeneous, &[], 2);
    let tolerance = Tolerance {
        rel: 0.002,
        z: 0.0,
        floor: 1e-6,
    };
    assert_blocks_agree("grid of ones against homogeneous", &a, &b, 4, tolerance);
}

/// bdpt (vertices in the medium, MIS with its pdfs), vpm and ppb against path in a medium
/// whose density varies tenfold.
#[test]
fn integrators_agree_with_path_in_a_varying_medium() {
    let path = render_toml("grid-path", &grid_fog("path", 2048, "", &varying()), &[], 2);
    let bdpt = render_toml("grid-bdpt", &grid_fog("bdpt", 512, "", &varying()), &[], 2);
    let exact = Tolerance {
        rel: 0.02,
        z: 4.0,
        floor: 0.0,
    };
    assert_blocks_agree("bdpt against path, grid fog", &bdpt, &path, 4, exact);
    // The default photon count (24 a pixel) leaves the thin corners of this small image
    // with few photons, whose k-nearest radii reach out of the box (a bias at its faces that
    // falls with the photons: -26 %, -8 %, -4.5 % and -1.6 % in the worst block at 14k,
    // 400k, 2M and 8M photons).
    let vpm = "[integrators.vpm]\nvolume_photons = 2000000";
    let vpm = render_toml("grid-vpm", &grid_fog("vpm", 32, vpm, &varying()), &[], 2);
    let biased = Tolerance {
        rel: 0.06,
        z: 4.0,
        floor: 0.0,
    };
    assert_blocks_agree("vpm against path, grid fog", &vpm, &path, 4, biased);
    let ppb = "[integrators.ppb]\niterations = 16\nphotons_per_iteration = 10000\nsurface_photons = 10000";
    let ppb = render_toml("grid-ppb", &grid_fog("ppb", 16, ppb, &varying()), &[], 2);
    let biased = Tolerance {
        rel: 0.08,
        z: 4.0,
        floor: 0.0,
    };
    assert_blocks_agree("ppb against path, grid fog", &ppb, &path, 4, biased);
}
