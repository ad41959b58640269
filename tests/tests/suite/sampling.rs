//! Statistical tests of every sampling routine against its pdf, in the manner of pbrt's and
//! Mitsuba's chi-square tests: the domain (usually the sphere of directions, parameterised by
//! (cos theta, phi) or (theta, phi) around some axis) is cut into cells, N samples are drawn and
//! binned, the expected count of each cell is the pdf integrated numerically over the cell,
//! cells expecting fewer than 5 samples are pooled, and the chi-square statistic is compared
//! with its distribution at significance 0.01, Sidak-corrected for the number of tests in this
//! file. Besides: every pdf integrates to one, the pdf a sample reports equals the pdf
//! function at the sampled direction, and the deterministic parts (Fresnel, Snell, mirror,
//! flux, kernel normalisation) are checked against independent formulas evaluated in f64.
//!
//! All random numbers come from `Rng::new(&[seed])`, so every run draws the same samples.

use foton_core::Rgb;
use foton_core::bsdf::Bsdf;
use foton_core::envmap::EnvironmentMap;
use foton_core::geometry::{Shape, SurfacePoint};
use foton_core::kernel::{BUILTIN_KERNELS, NormalizedKernel, builtin};
use foton_core::light::{Light, area_light};
use foton_core::material::{Material, TransportMode, fresnel_dielectric, refract};
use foton_core::medium::{Homogeneous, Medium, Phase, channel};
use foton_core::sampling::{self, Distribution1D, Rng};
use foton_core::texture::Bitmap;
use foton_core::texture::Texture;
use foton_tests::stats::{self, Gof, assert_close, assert_rel, chi2_gof, chi2_sf, ln_gamma};
use glam::{DVec3, Mat3, Vec2, Vec3};
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

// ---------------------------------------------------------------------------------------------
// Statistics
// ---------------------------------------------------------------------------------------------

/// Family-wise significance of all the goodness-of-fit tests of this file.
const ALPHA: f64 = 0.01;

/// Goodness-of-fit tests in this file, for the Sidak correction. Keep in step with the tests.
const NUM_GOF_TESTS: usize = 7 // uniform_sphere, cosine_hemisphere, 3 x uniform_cone, disc, triangle
    + 2 // Distribution1D
    + 2 // diffuse, both sides
    + DIELECTRIC_CASES.len() // binomial reflect/refract frequencies
    + 3 // sample_li: quad, sphere from outside, triangles
    + 7 // sample_emission: positions and directions of 3 area lights, point light directions
    + 2 // environment map: sample_li, sample_emission directions
    + PHASES.len()
    + FREE_FLIGHT_CASES.len();

/// Significance of each single test: 1 - (1 - ALPHA)^(1 / NUM_GOF_TESTS).
fn alpha_each() -> f64 {
    1.0 - (1.0 - ALPHA).powf(1.0 / NUM_GOF_TESTS as f64)
}

/// Panics unless the observed counts fit the expected ones at significance `alpha_each()`.
fn assert_gof(name: &str, observed: &[u64], expected: &[f64]) {
    stats::assert_gof(name, observed, expected, alpha_each());
}

// ---------------------------------------------------------------------------------------------
// Numerical integration and binning
// ---------------------------------------------------------------------------------------------

/// Sub-cells per side of a cell in `integrate_rect`.
const SUB: usize = 24;
/// Further midpoints per side in a sub-cell across which the integrand jumps.
const REFINE: usize = 16;

/// Integral of f(x, y) jac(x) over [x0, x1] x [y0, y1]: the midpoint rule on a SUB x SUB grid,
/// refined REFINE x REFINE times in every sub-cell whose corners and centre disagree on whether
/// f vanishes or vary by more than half (edges of a light, of a cone, of a disc).
fn integrate_rect(
    f: &dyn Fn(f64, f64) -> f64,
    jac: &dyn Fn(f64) -> f64,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> f64 {
    let hx = (x1 - x0) / SUB as f64;
    let hy = (y1 - y0) / SUB as f64;
    let mut corner = vec![0.0; (SUB + 1) * (SUB + 1)];
    for i in 0..=SUB {
        for j in 0..=SUB {
            corner[i * (SUB + 1) + j] = f(x0 + i as f64 * hx, y0 + j as f64 * hy);
        }
    }
    let mut total = 0.0;
    for i in 0..SUB {
        for j in 0..SUB {
            let xm = x0 + (i as f64 + 0.5) * hx;
            let ym = y0 + (j as f64 + 0.5) * hy;
            let m = f(xm, ym);
            let c = [
                corner[i * (SUB + 1) + j],
                corner[(i + 1) * (SUB + 1) + j],
                corner[i * (SUB + 1) + j + 1],
                corner[(i + 1) * (SUB + 1) + j + 1],
            ];
            let lo = c.iter().fold(m, |a, &b| a.min(b));
            let hi = c.iter().fold(m, |a, &b| a.max(b));
            if hi > 0.0 && (lo <= 0.0 || hi > 1.5 * lo) {
                let gx = hx / REFINE as f64;
                let gy = hy / REFINE as f64;
                let mut s = 0.0;
                for a in 0..REFINE {
                    let x = x0 + i as f64 * hx + (a as f64 + 0.5) * gx;
                    let jx = jac(x);
                    for b in 0..REFINE {
                        s += f(x, y0 + j as f64 * hy + (b as f64 + 0.5) * gy) * jx;
                    }
                }
                total += s * gx * gy;
            } else {
                total += m * jac(xm) * hx * hy;
            }
        }
    }
    total
}

/// Composite Simpson's rule of f on [a, b] with n (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    assert!(n.is_multiple_of(2));
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        s += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

fn uniform_edges(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|i| lo + (hi - lo) * i as f64 / n as f64)
        .collect()
}

/// Edges in cos theta of `n` equal rows over [lo, 1] such that the cone cos theta >= c ends in
/// the middle of the second row: the first row is outside the cone, the edge of the cone is
/// well inside a cell (so rounding at the edge cannot throw a sample into an empty cell).
fn cone_edges(c: f64, n: usize) -> Vec<f64> {
    let k = 1.5 / n as f64;
    let lo = (c - k) / (1.0 - k);
    assert!(lo >= -1.0, "cone too wide for cone_edges");
    uniform_edges(lo, 1.0, n)
}

/// An orthonormal frame (built here, independently of `sampling::basis`).
#[derive(Clone, Copy, Debug)]
struct Frame {
    s: DVec3,
    t: DVec3,
    n: DVec3,
}

impl Frame {
    fn new(n: DVec3) -> Self {
        let n = n.normalize();
        let a = if n.x.abs() > 0.8 { DVec3::Y } else { DVec3::X };
        let s = a.cross(n).normalize();
        Frame {
            s,
            t: n.cross(s),
            n,
        }
    }
    fn to_world(self, l: DVec3) -> DVec3 {
        self.s * l.x + self.t * l.y + self.n * l.z
    }
    fn to_local(self, w: DVec3) -> DVec3 {
        DVec3::new(w.dot(self.s), w.dot(self.t), w.dot(self.n))
    }
}

/// How the polar angle is binned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Polar {
    /// Cells of equal width in cos theta (equal solid angle for equal widths).
    Cos,
    /// Cells in theta (resolves peaks at the pole).
    Theta,
}

/// A partition of (part of) the sphere of directions into cells (polar rows x phi columns)
/// around `frame.n`.
struct SphereGrid {
    frame: Frame,
    polar: Polar,
    /// Ascending edges of the rows in cos theta or theta.
    edges: Vec<f64>,
    n_phi: usize,
}

impl SphereGrid {
    fn new(axis: DVec3, polar: Polar, edges: Vec<f64>, n_phi: usize) -> Self {
        assert!(edges.windows(2).all(|w| w[0] < w[1]));
        SphereGrid {
            frame: Frame::new(axis),
            polar,
            edges,
            n_phi,
        }
    }

    fn full_sphere(axis: DVec3, n_cos: usize, n_phi: usize) -> Self {
        Self::new(axis, Polar::Cos, uniform_edges(-1.0, 1.0, n_cos), n_phi)
    }

    fn len(&self) -> usize {
        (self.edges.len() - 1) * self.n_phi
    }

    /// The cell of direction `w`, None outside the grid's polar range.
    fn cell(&self, w: DVec3) -> Option<usize> {
        let l = self.frame.to_local(w);
        let len = l.length();
        if len.is_nan() || len == 0.0 {
            return None;
        }
        let z = (l.z / len).clamp(-1.0, 1.0);
        let x = match self.polar {
            Polar::Cos => z,
            Polar::Theta => z.acos(),
        };
        let (lo, hi) = (self.edges[0], self.edges[self.edges.len() - 1]);
        if !(lo..=hi).contains(&x) {
            return None;
        }
        let i = (self.edges.partition_point(|&e| e <= x) - 1).min(self.edges.len() - 2);
        let phi = l.y.atan2(l.x).rem_euclid(TAU);
        let j = ((phi / TAU * self.n_phi as f64) as usize).min(self.n_phi - 1);
        Some(i * self.n_phi + j)
    }

    fn dir(&self, x: f64, phi: f64) -> DVec3 {
        let z = match self.polar {
            Polar::Cos => x,
            Polar::Theta => x.cos(),
        };
        let r = (1.0 - z * z).max(0.0).sqrt();
        self.frame
            .to_world(DVec3::new(r * phi.cos(), r * phi.sin(), z))
    }

    /// Probability of each cell under the solid-angle density `pdf`.
    fn probabilities(&self, pdf: &dyn Fn(DVec3) -> f64) -> Vec<f64> {
        let f = |x: f64, phi: f64| pdf(self.dir(x, phi));
        let jac = |x: f64| match self.polar {
            Polar::Cos => 1.0,
            Polar::Theta => x.sin(),
        };
        let mut out = Vec::with_capacity(self.len());
        for row in self.edges.windows(2) {
            for j in 0..self.n_phi {
                let phi = (
                    TAU * j as f64 / self.n_phi as f64,
                    TAU * (j + 1) as f64 / self.n_phi as f64,
                );
                out.push(integrate_rect(&f, &jac, (row[0], row[1]), phi));
            }
        }
        out
    }
}

/// Draws `n` directions, bins them on `grid` plus two extra cells (the sampler returned
/// nothing, expected with probability `p_none`; the direction is outside the grid, expected
/// never) and tests them against the solid-angle density `pdf`. Returns the integral of `pdf`
/// over the grid.
fn gof_directions(
    grid: &SphereGrid,
    n: usize,
    p_none: f64,
    pdf: &dyn Fn(DVec3) -> f64,
    sample: &mut dyn FnMut() -> Option<DVec3>,
) -> (Result<Gof, String>, f64, Vec<u64>, Vec<f64>) {
    let probs = grid.probabilities(pdf);
    let mut obs = vec![0u64; grid.len() + 2];
    for _ in 0..n {
        match sample() {
            None => obs[grid.len()] += 1,
            Some(w) => match grid.cell(w) {
                Some(c) => obs[c] += 1,
                None => obs[grid.len() + 1] += 1,
            },
        }
    }
    let integral: f64 = probs.iter().sum();
    let mut exp: Vec<f64> = probs.iter().map(|p| p * n as f64).collect();
    exp.push(p_none * n as f64);
    exp.push(0.0);
    (chi2_gof(&obs, &exp), integral, obs, exp)
}

/// `gof_directions`, asserting the fit. Returns the integral of `pdf` over the grid.
fn check_directions(
    name: &str,
    grid: &SphereGrid,
    n: usize,
    p_none: f64,
    pdf: &dyn Fn(DVec3) -> f64,
    sample: &mut dyn FnMut() -> Option<DVec3>,
) -> f64 {
    let (_, integral, obs, exp) = gof_directions(grid, n, p_none, pdf, sample);
    let outside = obs[grid.len() + 1];
    assert!(
        outside == 0,
        "{name}: {outside} of {n} sampled directions fall outside the support of the pdf"
    );
    if p_none == 0.0 {
        let none = obs[grid.len()];
        assert!(none == 0, "{name}: the sampler failed {none} times");
    }
    assert_gof(name, &obs, &exp);
    integral
}

fn d(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

fn rgb_close(a: Rgb, b: Rgb, rel: f32) -> bool {
    (a - b).abs().max_element() <= rel * a.abs().max(b.abs()).max_element().max(1e-30)
}

/// Probability that a sampler built on `cosine_hemisphere` meets the measure-zero event of a
/// direction exactly on the horizon, which `next_f32`'s 24-bit grid makes possible: u.x or
/// u.y exactly 0 (then rounding may or may not give z = 0). An upper bound, used as the
/// expected frequency of "no sample" (it is pooled away, so it cannot mask a real failure).
const P_HORIZON: f64 = 2.0 / (1u64 << 24) as f64;

// ---------------------------------------------------------------------------------------------
// The test machinery itself
// ---------------------------------------------------------------------------------------------

#[test]
fn chi_square_survival_function_matches_tables() {
    // (dof, quantile, upper-tail probability) from standard tables.
    for (dof, x, q) in [
        (1.0, 3.841_459, 0.05),
        (1.0, 6.634_897, 0.01),
        (3.0, 7.814_728, 0.05),
        (10.0, 23.209_251, 0.01),
        (100.0, 135.806_723, 0.01),
        (1000.0, 1_106.969, 0.01),
    ] {
        assert_rel(&format!("chi2_sf({x}, {dof})"), chi2_sf(x, dof), q, 2e-5);
    }
    // Two degrees of freedom: exp(-x / 2), on both branches of gamma_q.
    for x in [0.01, 0.5, 1.9, 2.1, 7.0, 40.0, 300.0] {
        assert_rel("chi2_sf(x, 2)", chi2_sf(x, 2.0), (-0.5 * x).exp(), 1e-12);
    }
    // The median of chi-square(dof) is close to dof (1 - 2 / (9 dof))^3.
    for dof in [50.0f64, 400.0, 2000.0] {
        let m = dof * (1.0 - 2.0 / (9.0 * dof)).powi(3);
        assert_close("median", chi2_sf(m, dof), 0.5, 2e-3);
    }
    assert_rel("ln Gamma(10)", ln_gamma(10.0), 362_880f64.ln(), 1e-13);
    assert_rel("ln Gamma(1/2)", ln_gamma(0.5), 0.5 * PI.ln(), 1e-13);
    assert_rel(
        "ln Gamma(0.1)",
        ln_gamma(0.1),
        9.513_507_698_668_732f64.ln(),
        1e-12,
    );
    assert!(alpha_each() > 0.0 && alpha_each() < ALPHA / NUM_GOF_TESTS as f64 * 1.01);
}

/// The tests have power: slightly wrong pdfs are rejected at the corrected significance.
#[test]
fn chi_square_test_rejects_slightly_wrong_pdfs() {
    // Uniform directions against a density 5% higher at one pole than at the other.
    let grid = SphereGrid::full_sphere(DVec3::Z, 10, 20);
    let mut rng = Rng::new(&[9001]);
    let wrong = |w: DVec3| (1.0 + 0.05 * w.z) / (4.0 * PI);
    let (r, integral, ..) = gof_directions(&grid, 1_000_000, 0.0, &wrong, &mut || {
        Some(d(sampling::uniform_sphere(rng.next_2d())))
    });
    assert_close("integral of the wrong pdf", integral, 1.0, 1e-6);
    let g = r.unwrap();
    assert!(g.p < alpha_each(), "a 5% tilt went unnoticed: {g:?}");

    // Henyey-Greenstein g = 0.3 samples against g = 0.32.
    let dir = Vec3::new(0.2, 0.7, -0.4).normalize();
    let grid = phase_grid(d(dir));
    let mut rng = Rng::new(&[9002]);
    let other = Phase::HenyeyGreenstein { g: 0.32 };
    let sampled = Phase::HenyeyGreenstein { g: 0.3 };
    let pdf = |w: DVec3| other.eval(d(dir).dot(w) as f32) as f64;
    let (r, ..) = gof_directions(&grid, 1_000_000, 0.0, &pdf, &mut || {
        Some(d(sampled.sample(dir, rng.next_2d()).0))
    });
    let g = r.unwrap();
    assert!(g.p < alpha_each(), "g = 0.3 passed for g = 0.32: {g:?}");

    // Counts in a cell the pdf says is empty are an error whatever the statistic.
    assert!(chi2_gof(&[10, 10, 1], &[10.5, 10.5, 0.0]).is_err());
}

// ---------------------------------------------------------------------------------------------
// sampling.rs warps
// ---------------------------------------------------------------------------------------------

#[test]
fn uniform_sphere_is_uniform() {
    let grid = SphereGrid::full_sphere(DVec3::new(0.3, -0.5, 0.8), 10, 20);
    let mut rng = Rng::new(&[1]);
    let pdf = |_: DVec3| 1.0 / (4.0 * PI);
    let integral = check_directions("uniform_sphere", &grid, 1_000_000, 0.0, &pdf, &mut || {
        let w = sampling::uniform_sphere(rng.next_2d());
        assert_close("|uniform_sphere|", w.length() as f64, 1.0, 1e-5);
        Some(d(w))
    });
    assert_close("integral of 1/(4 pi)", integral, 1.0, 1e-6);
    assert_close(
        "UNIFORM_SPHERE_PDF",
        sampling::UNIFORM_SPHERE_PDF as f64,
        1.0 / (4.0 * PI),
        1e-8,
    );
}

#[test]
fn cosine_hemisphere_is_cosine_distributed() {
    // The whole sphere, so that a sample below the horizon lands in an empty cell.
    let grid = SphereGrid::full_sphere(DVec3::Z, 20, 20);
    let mut rng = Rng::new(&[2]);
    let pdf = |w: DVec3| w.z.max(0.0) / PI;
    let integral = check_directions(
        "cosine_hemisphere",
        &grid,
        1_000_000,
        0.0,
        &pdf,
        &mut || {
            let w = sampling::cosine_hemisphere(rng.next_2d());
            assert_close("|cosine_hemisphere|", w.length() as f64, 1.0, 1e-5);
            assert!(w.z >= 0.0);
            Some(d(w))
        },
    );
    assert_close("integral of cos/pi", integral, 1.0, 1e-3);
}

#[test]
fn uniform_cone_is_uniform_in_its_cone() {
    for (k, cos_max) in [0.95f32, 0.3, -0.6].into_iter().enumerate() {
        let c = cos_max as f64;
        let grid = SphereGrid::new(DVec3::Z, Polar::Cos, cone_edges(c, 10), 20);
        let mut rng = Rng::new(&[3, k as u64]);
        let pdf = |w: DVec3| {
            if w.z >= c {
                1.0 / (TAU * (1.0 - c))
            } else {
                0.0
            }
        };
        let integral = check_directions(
            &format!("uniform_cone(cos_max = {cos_max})"),
            &grid,
            1_000_000,
            0.0,
            &pdf,
            &mut || {
                let w = sampling::uniform_cone(rng.next_2d(), cos_max);
                assert_close("|uniform_cone|", w.length() as f64, 1.0, 1e-5);
                Some(d(w))
            },
        );
        assert_close("integral of the cone pdf", integral, 1.0, 1e-3);
    }
}

#[test]
fn concentric_disc_is_uniform_on_the_disc() {
    // Cartesian cells over [-1, 1]^2; the expected counts integrate the indicator of the disc.
    const N_CELLS: usize = 20;
    const N: usize = 1_000_000;
    let h = 2.0 / N_CELLS as f64;
    let inside = |x: f64, y: f64| {
        if x * x + y * y <= 1.0 { 1.0 / PI } else { 0.0 }
    };
    let mut exp = Vec::new();
    for i in 0..N_CELLS {
        for j in 0..N_CELLS {
            let x0 = -1.0 + i as f64 * h;
            let y0 = -1.0 + j as f64 * h;
            exp.push(N as f64 * integrate_rect(&inside, &|_| 1.0, (x0, x0 + h), (y0, y0 + h)));
        }
    }
    assert_close(
        "area of the disc / pi",
        exp.iter().sum::<f64>() / N as f64,
        1.0,
        1e-4,
    );
    let mut obs = vec![0u64; N_CELLS * N_CELLS];
    let mut rng = Rng::new(&[4]);
    for _ in 0..N {
        let p = sampling::concentric_disc(rng.next_2d());
        assert!(p.length() <= 1.0 + 1e-6, "{p} is off the disc");
        let cell = |v: f32| (((v as f64 + 1.0) / h) as usize).min(N_CELLS - 1);
        obs[cell(p.x) * N_CELLS + cell(p.y)] += 1;
    }
    assert_gof("concentric_disc", &obs, &exp);
    assert_eq!(sampling::concentric_disc(Vec2::splat(0.5)), Vec2::ZERO);
}

#[test]
fn uniform_triangle_is_uniform_in_barycentric_space() {
    // Cells of the unit square in (b1, b2); the triangle b1 + b2 <= 1 covers those with
    // i + j < n - 1 fully and those with i + j = n - 1 by half (the diagonal passes through
    // their corners), so the expected counts are exact.
    const N_CELLS: usize = 20;
    const N: usize = 1_000_000;
    let mut exp = vec![0.0; N_CELLS * N_CELLS];
    for i in 0..N_CELLS {
        for j in 0..N_CELLS {
            let area = match (i + j).cmp(&(N_CELLS - 1)) {
                std::cmp::Ordering::Less => 1.0,
                std::cmp::Ordering::Equal => 0.5,
                std::cmp::Ordering::Greater => 0.0,
            } / (N_CELLS * N_CELLS) as f64;
            exp[i * N_CELLS + j] = N as f64 * 2.0 * area;
        }
    }
    let mut obs = vec![0u64; N_CELLS * N_CELLS];
    let mut rng = Rng::new(&[5]);
    for _ in 0..N {
        let (b1, b2) = sampling::uniform_triangle(rng.next_2d());
        assert!(
            b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 + 1e-6,
            "({b1}, {b2}) is off the triangle"
        );
        let cell = |v: f32| ((v as f64 * N_CELLS as f64) as usize).min(N_CELLS - 1);
        obs[cell(b1) * N_CELLS + cell(b2)] += 1;
    }
    assert_gof("uniform_triangle", &obs, &exp);
}

#[test]
fn distribution1d_follows_its_pmf_and_never_draws_zero_weights() {
    let weights = [0.0f32, 1.0, 3.5, 0.0, 0.2, 2.0, 0.0, 7.0, 0.01, 0.0, 0.0];
    let total: f64 = weights.iter().map(|&w| w as f64).sum();
    let dist = Distribution1D::new(&weights);
    assert_eq!(dist.len(), weights.len());
    assert_rel("total", dist.total() as f64, total, 1e-6);
    for (i, &w) in weights.iter().enumerate() {
        assert_close(
            &format!("pmf({i})"),
            dist.pmf(i) as f64,
            w as f64 / total,
            1e-7,
        );
    }

    // Chi-square of the drawn indices.
    const N: usize = 1_000_000;
    let mut obs = vec![0u64; weights.len()];
    let mut rng = Rng::new(&[6]);
    for _ in 0..N {
        let (i, p) = dist.sample(rng.next_f32());
        assert!(weights[i] > 0.0, "drew index {i} of zero weight");
        assert_eq!(p, dist.pmf(i));
        obs[i] += 1;
    }
    let exp: Vec<f64> = weights
        .iter()
        .map(|&w| N as f64 * w as f64 / total)
        .collect();
    assert_gof("Distribution1D (11 weights)", &obs, &exp);

    // Exhaustively over every value next_f32 can return: never a zero weight, and the
    // frequencies are the pmf up to the 2^-24 grid and the f32 rounding of the CDF.
    let mut count = vec![0u64; weights.len()];
    for k in 0..1u32 << 24 {
        let u = k as f32 * (1.0 / (1u32 << 24) as f32);
        let (i, _) = dist.sample(u);
        assert!(weights[i] > 0.0, "u = {u} drew index {i} of zero weight");
        count[i] += 1;
    }
    for (i, &w) in weights.iter().enumerate() {
        let freq = count[i] as f64 / (1u64 << 24) as f64;
        assert_close(
            &format!("frequency of {i} over all u"),
            freq,
            w as f64 / total,
            3e-7,
        );
    }

    // A long distribution with many zeros and weights over four decades.
    let mut rng = Rng::new(&[7]);
    let mut weights: Vec<f32> = (0..1000)
        .map(|_| {
            if rng.next_f32() < 0.3 {
                0.0
            } else {
                10f32.powf(-3.0 + 4.0 * rng.next_f32())
            }
        })
        .collect();
    weights[0] = 0.0;
    weights[999] = 0.0;
    let total: f64 = weights.iter().map(|&w| w as f64).sum();
    let dist = Distribution1D::new(&weights);
    const N2: usize = 2_000_000;
    let mut obs = vec![0u64; weights.len()];
    for _ in 0..N2 {
        let (i, p) = dist.sample(rng.next_f32());
        assert!(weights[i] > 0.0, "drew index {i} of zero weight");
        assert_eq!(p, dist.pmf(i));
        obs[i] += 1;
    }
    let exp: Vec<f64> = weights
        .iter()
        .map(|&w| N2 as f64 * w as f64 / total)
        .collect();
    assert_gof("Distribution1D (1000 weights)", &obs, &exp);
}

// ---------------------------------------------------------------------------------------------
// Materials
// ---------------------------------------------------------------------------------------------

/// The BSDF of `mat` on a flat surface with normal `ng` (no shading normal, no texture).
fn flat(mat: &Material, ng: Vec3) -> Bsdf {
    let sp = SurfacePoint {
        p: Vec3::ZERO,
        ng,
        ns: ng,
        uv: glam::Vec2::ZERO,
        dpdu: Vec3::ZERO,
    };
    mat.bsdf(&sp).expect("a material that scatters")
}

#[test]
fn diffuse_sampling_matches_its_pdf_on_both_sides() {
    let reflectance = Rgb::new(0.8, 0.5, 0.2);
    let mat = Material::Diffuse {
        reflectance: Texture::Constant(reflectance),
        twosided: true,
    };
    let ng = Vec3::new(0.3, -0.4, 0.866).normalize();
    let front = Vec3::new(0.5, 0.2, 0.8).normalize();
    let back = Vec3::new(-0.1, 0.7, -0.6).normalize();
    assert!(front.dot(ng) > 0.0 && back.dot(ng) < 0.0);
    for (k, (side, wo)) in [("front", front), ("back", back)].into_iter().enumerate() {
        // The whole sphere around ng: samples on the wrong side land in empty cells.
        let grid = SphereGrid::full_sphere(d(ng), 20, 20);
        let mut rng = Rng::new(&[10, k as u64]);
        let pdf = |w: DVec3| flat(&mat, ng).pdf(wo, w.as_vec3()) as f64;
        let integral = check_directions(
            &format!("diffuse, wo on the {side}"),
            &grid,
            1_000_000,
            P_HORIZON,
            &pdf,
            &mut || {
                let mode = if rng.next_u32() & 1 == 0 {
                    TransportMode::Radiance
                } else {
                    TransportMode::Importance
                };
                let s = flat(&mat, ng).sample(wo, rng.next_2d(), rng.next_f32(), mode)?;
                assert!(!s.delta);
                assert_close("|wi|", s.wi.length() as f64, 1.0, 1e-5);
                assert!(
                    s.wi.dot(ng) * wo.dot(ng) >= 0.0,
                    "wi = {} is on the other side from wo = {wo}",
                    s.wi
                );
                let pdf = flat(&mat, ng).pdf(wo, s.wi);
                assert_close("sample pdf vs pdf()", s.pdf as f64, pdf as f64, 1e-6);
                assert!(
                    rgb_close(s.weight, reflectance, 1e-6),
                    "weight {}",
                    s.weight
                );
                if pdf > 1e-3 {
                    let fcos = flat(&mat, ng).eval(wo, s.wi);
                    assert!(
                        rgb_close(fcos / pdf, s.weight, 1e-4),
                        "f cos / pdf = {} but weight = {}",
                        fcos / pdf,
                        s.weight
                    );
                }
                Some(d(s.wi))
            },
        );
        assert_close("integral of the diffuse pdf", integral, 1.0, 1e-3);
    }
}

/// Independent Fresnel equations for unpolarised light from index n_i into index n_t at
/// incidence cosine cos_i: (R, T, cos_t), T from the transmission amplitudes (so that R + T = 1
/// is a check, not a definition); None on total internal reflection.
fn fresnel_reference(cos_i: f64, n_i: f64, n_t: f64) -> Option<(f64, f64, f64)> {
    let sin_t = n_i / n_t * (1.0 - cos_i * cos_i).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let rp = (n_t * cos_i - n_i * cos_t) / (n_t * cos_i + n_i * cos_t);
    let ts = 2.0 * n_i * cos_i / (n_i * cos_i + n_t * cos_t);
    let tp = 2.0 * n_i * cos_i / (n_t * cos_i + n_i * cos_t);
    let r = 0.5 * (rs * rs + rp * rp);
    let t = n_t * cos_t / (n_i * cos_i) * 0.5 * (ts * ts + tp * tp);
    Some((r, t, cos_t))
}

/// (ior, wo inside, cos theta_o) of dielectric cases without total internal reflection.
const DIELECTRIC_CASES: [(f32, bool, f64); 14] = [
    (1.5, false, 1.0),
    (1.5, false, 0.7),
    (1.5, false, 0.4),
    (1.5, false, 0.1),
    (1.5, true, 1.0),
    (1.5, true, 0.9),
    (1.5, true, 0.76),
    (0.75, false, 1.0),
    (0.75, false, 0.8),
    (0.75, false, 0.67),
    (0.75, true, 1.0),
    (0.75, true, 0.7),
    (0.75, true, 0.4),
    (0.75, true, 0.1),
];

/// Cases with total internal reflection (the critical cosines are 0.745 and 0.661).
const TIR_CASES: [(f32, bool, f64); 5] = [
    (1.5, true, 0.74),
    (1.5, true, 0.3),
    (1.5, true, 0.02),
    (0.75, false, 0.65),
    (0.75, false, 0.2),
];

fn dielectric_wo(ng: Vec3, inside: bool, cos: f64) -> (Vec3, Vec3) {
    let n = if inside { -ng } else { ng };
    let s = Frame::new(d(n)).s;
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    ((d(n) * cos + s * sin).as_vec3().normalize(), n)
}

#[test]
fn dielectric_reflects_with_fresnel_probability_and_refracts_by_snell() {
    const N: usize = 100_000;
    let ng = Vec3::new(-0.2, 0.5, 0.84).normalize();
    for (k, &(ior, inside, cos)) in DIELECTRIC_CASES.iter().enumerate() {
        let mat = Material::Dielectric { ior };
        let (wo, n) = dielectric_wo(ng, inside, cos);
        let (n_o, n_t) = if inside {
            (ior as f64, 1.0)
        } else {
            (1.0, ior as f64)
        };
        let cos_o = d(wo).dot(d(n));
        let name = format!(
            "dielectric ior {ior}, wo {}, cos {cos}",
            if inside { "inside" } else { "outside" }
        );
        let (r, t, cos_t) = fresnel_reference(cos_o, n_o, n_t)
            .unwrap_or_else(|| panic!("{name}: unexpected total internal reflection"));
        assert_close(&format!("{name}: R + T"), r + t, 1.0, 1e-12);
        let f = fresnel_dielectric(cos_o as f32, (n_t / n_o) as f32) as f64;
        assert_close(&format!("{name}: Fresnel F"), f, r, 2e-6);
        // Energy: the core's reflectance and the independent transmittance add up to one.
        assert_close(&format!("{name}: F + T"), f + t, 1.0, 2e-6);

        let mut rng = Rng::new(&[20, k as u64]);
        let mut counts = [0u64; 2];
        for _ in 0..N {
            let mode = if rng.next_u32() & 1 == 0 {
                TransportMode::Radiance
            } else {
                TransportMode::Importance
            };
            let s = flat(&mat, ng)
                .sample(wo, rng.next_2d(), rng.next_f32(), mode)
                .unwrap_or_else(|| panic!("{name}: no sample"));
            assert!(s.delta, "{name}: not a delta lobe");
            let wi = d(s.wi);
            assert_close(&format!("{name}: |wi|"), wi.length(), 1.0, 1e-5);
            if wi.dot(d(n)) > 0.0 {
                counts[0] += 1;
                let mirror = 2.0 * d(wo).dot(d(n)) * d(n) - d(wo);
                assert!(
                    (wi - mirror).length() < 1e-5,
                    "{name}: reflection {wi} is not {mirror}"
                );
                assert_close(&format!("{name}: reflection pdf"), s.pdf as f64, r, 2e-6);
                assert!(
                    rgb_close(s.weight, Rgb::ONE, 1e-6),
                    "{name}: reflection weight {}",
                    s.weight
                );
            } else {
                counts[1] += 1;
                // Snell: n_o sin_o = n_t sin_t, in the plane of wo and n, on the far side.
                let sin_o = d(wo).cross(d(n)).length();
                let sin_t = wi.cross(d(n)).length();
                assert_close(&format!("{name}: Snell"), n_t * sin_t, n_o * sin_o, 1e-5);
                assert_close(&format!("{name}: cos theta_t"), -wi.dot(d(n)), cos_t, 1e-5);
                assert_close(
                    &format!("{name}: coplanar"),
                    wi.dot(d(n).cross(d(wo))),
                    0.0,
                    1e-5,
                );
                let tangent_o = d(wo) - d(wo).dot(d(n)) * d(n);
                let tangent_i = wi - wi.dot(d(n)) * d(n);
                assert!(
                    tangent_o.dot(tangent_i) <= 1e-6,
                    "{name}: refraction bends the wrong way"
                );
                assert_close(
                    &format!("{name}: refraction pdf"),
                    s.pdf as f64,
                    1.0 - r,
                    2e-6,
                );
                // Radiance is scaled by (n_o / n_t)^2 = 1 / eta^2 with eta = n_t / n_o; flux
                // (importance) is not.
                let scale = match mode {
                    TransportMode::Radiance => (n_o / n_t).powi(2),
                    TransportMode::Importance => 1.0,
                };
                assert!(
                    rgb_close(s.weight, Rgb::splat(scale as f32), 1e-6),
                    "{name}: refraction weight {} in {mode:?}, expected {scale}",
                    s.weight
                );
            }
        }
        assert_gof(
            &format!("{name}: reflect/refract frequencies"),
            &counts,
            &[N as f64 * r, N as f64 * (1.0 - r)],
        );
    }
}

#[test]
fn dielectric_totally_reflects_beyond_the_critical_angle() {
    let ng = Vec3::new(-0.2, 0.5, 0.84).normalize();
    for (k, &(ior, inside, cos)) in TIR_CASES.iter().enumerate() {
        let mat = Material::Dielectric { ior };
        let (wo, n) = dielectric_wo(ng, inside, cos);
        let (n_o, n_t) = if inside {
            (ior as f64, 1.0)
        } else {
            (1.0, ior as f64)
        };
        let cos_o = d(wo).dot(d(n));
        assert!(fresnel_reference(cos_o, n_o, n_t).is_none());
        assert_eq!(fresnel_dielectric(cos_o as f32, (n_t / n_o) as f32), 1.0);
        assert!(refract(wo, n, (n_t / n_o) as f32).is_none());
        let mut rng = Rng::new(&[21, k as u64]);
        for _ in 0..10_000 {
            let s = flat(&mat, ng)
                .sample(wo, rng.next_2d(), rng.next_f32(), TransportMode::Radiance)
                .unwrap();
            let mirror = 2.0 * d(wo).dot(d(n)) * d(n) - d(wo);
            assert!(
                (d(s.wi) - mirror).length() < 1e-5,
                "TIR gave {} not {mirror}",
                s.wi
            );
            assert_eq!(s.pdf, 1.0);
            assert_eq!(s.weight, Rgb::ONE);
        }
    }
}

#[test]
fn mirror_reflects_exactly() {
    let reflectance = Rgb::new(0.9, 0.6, 0.3);
    let mat = Material::Mirror {
        reflectance: Texture::Constant(reflectance),
    };
    let mut rng = Rng::new(&[22]);
    for _ in 0..100_000 {
        let ng = sampling::uniform_sphere(rng.next_2d());
        let wo = sampling::uniform_sphere(rng.next_2d());
        if wo.dot(ng).abs() < 1e-3 {
            continue;
        }
        let mode = if rng.next_u32() & 1 == 0 {
            TransportMode::Radiance
        } else {
            TransportMode::Importance
        };
        let s = flat(&mat, ng)
            .sample(wo, rng.next_2d(), rng.next_f32(), mode)
            .unwrap();
        let (wo64, n64) = (d(wo), d(ng));
        let mirror = 2.0 * wo64.dot(n64) * n64 - wo64;
        assert!(
            (d(s.wi) - mirror).length() < 1e-5,
            "mirror of {wo} about {ng}: {} not {mirror}",
            s.wi
        );
        assert_close("cos in = cos out", d(s.wi).dot(n64), wo64.dot(n64), 1e-5);
        assert!(s.delta && s.pdf == 1.0 && s.weight == reflectance);
        assert_eq!(flat(&mat, ng).eval(wo, s.wi), Rgb::ZERO);
        assert_eq!(flat(&mat, ng).pdf(wo, s.wi), 0.0);
    }
}

// ---------------------------------------------------------------------------------------------
// Lights
// ---------------------------------------------------------------------------------------------

/// Nearest intersection of the ray x + t w (t > 0) with `shape`: (t, point, unit normal with the
/// shape's own orientation), computed here in f64.
fn hit(shape: &Shape, x: DVec3, w: DVec3) -> Option<(f64, DVec3, DVec3)> {
    let plane = |o: DVec3, a: DVec3, b: DVec3| {
        let n = a.cross(b);
        let denom = n.dot(w);
        if denom == 0.0 {
            return None;
        }
        let t = n.dot(o - x) / denom;
        if t <= 0.0 {
            return None;
        }
        let q = x + w * t - o;
        let nn = n.dot(n);
        Some((
            t,
            q.cross(b).dot(n) / nn,
            a.cross(q).dot(n) / nn,
            n.normalize(),
        ))
    };
    match *shape {
        Shape::Sphere { center, radius, .. } => {
            let (c, r) = (d(center), radius as f64);
            let f = x - c;
            let b = f.dot(w);
            let disc = b * b - (f.dot(f) - r * r);
            if disc < 0.0 {
                return None;
            }
            let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
            let t = if t0 > 0.0 {
                t0
            } else if t1 > 0.0 {
                t1
            } else {
                return None;
            };
            let p = x + w * t;
            Some((t, p, (p - c) / r))
        }
        Shape::Quad { origin, u, v, .. } => {
            let (t, a, b, n) = plane(d(origin), d(u), d(v))?;
            ((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)).then(|| (t, x + w * t, n))
        }
        Shape::Triangle { p0, e1, e2 } => {
            let (t, a, b, n) = plane(d(p0), d(e1), d(e2))?;
            (a >= 0.0 && b >= 0.0 && a + b <= 1.0).then(|| (t, x + w * t, n))
        }
        Shape::Disk {
            center,
            u,
            v,
            normal,
            ..
        } => {
            let (t, a, b, _) = plane(d(center), d(u), d(v))?;
            (a * a + b * b <= 1.0).then(|| (t, x + w * t, d(normal)))
        }
    }
}

/// Area of a shape, computed here.
fn shape_area(shape: &Shape) -> f64 {
    match *shape {
        Shape::Sphere { radius, .. } => 4.0 * PI * (radius as f64).powi(2),
        Shape::Quad { u, v, .. } => d(u).cross(d(v)).length(),
        Shape::Triangle { e1, e2, .. } => 0.5 * d(e1).cross(d(e2)).length(),
        Shape::Disk { u, v, .. } => PI * d(u).cross(d(v)).length(),
    }
}

/// The shape's own normal at `p` if `p` lies on it (within `tol`), else None.
fn on_shape(shape: &Shape, p: DVec3, tol: f64) -> Option<DVec3> {
    let plane = |o: DVec3, a: DVec3, b: DVec3| {
        let n = a.cross(b);
        let q = p - o;
        let nn = n.dot(n);
        let dist = q.dot(n) / nn.sqrt();
        (dist.abs() <= tol).then(|| {
            (
                q.cross(b).dot(n) / nn,
                a.cross(q).dot(n) / nn,
                n.normalize(),
            )
        })
    };
    match *shape {
        Shape::Sphere { center, radius, .. } => {
            let r = p - d(center);
            ((r.length() - radius as f64).abs() <= tol).then(|| r.normalize())
        }
        Shape::Quad { origin, u, v, .. } => {
            let (a, b, n) = plane(d(origin), d(u), d(v))?;
            (a >= -tol && a <= 1.0 + tol && b >= -tol && b <= 1.0 + tol).then_some(n)
        }
        Shape::Triangle { p0, e1, e2 } => {
            let (a, b, n) = plane(d(p0), d(e1), d(e2))?;
            (a >= -tol && b >= -tol && a + b <= 1.0 + tol).then_some(n)
        }
        Shape::Disk {
            center,
            u,
            v,
            normal,
            ..
        } => {
            let (a, b, _) = plane(d(center), d(u), d(v))?;
            (a * a + b * b <= 1.0 + tol).then_some(d(normal))
        }
    }
}

/// Solid-angle density of `light.sample_li(x, ..)` returning a sample in direction w: the sum
/// of `pdf_li` at the points of the shapes along w (sample_li does not test occlusion), only
/// those facing x unless `back_too` (sample_li returns None for the others).
fn li_density(light: &Light, shapes: &[Shape], x: DVec3, w: DVec3, back_too: bool) -> f64 {
    shapes
        .iter()
        .filter_map(|s| hit(s, x, w))
        .filter(|&(_, _, n)| back_too || n.dot(-w) > 0.0)
        .map(|(_, p, n)| light.pdf_li(x.as_vec3(), p.as_vec3(), n.as_vec3()) as f64)
        .sum()
}

/// A grid around the direction from x to the mean of `points`, wide enough for all of them.
fn grid_towards(x: DVec3, points: &[DVec3]) -> SphereGrid {
    let axis = (points.iter().copied().sum::<DVec3>() / points.len() as f64 - x).normalize();
    let cos_min = points
        .iter()
        .map(|&p| (p - x).normalize().dot(axis))
        .fold(1.0f64, f64::min);
    let lo = cos_min - 0.1 * (1.0 - cos_min);
    SphereGrid::new(axis, Polar::Cos, uniform_edges(lo, 1.0, 10), 20)
}

fn vertices(shape: &Shape) -> Vec<DVec3> {
    match *shape {
        Shape::Quad { origin, u, v, .. } => {
            let (o, u, v) = (d(origin), d(u), d(v));
            vec![o, o + u, o + v, o + u + v]
        }
        Shape::Triangle { p0, e1, e2 } => vec![d(p0), d(p0 + e1), d(p0 + e2)],
        Shape::Disk { center, u, v, .. } => {
            let (c, u, v) = (d(center), d(u), d(v));
            vec![c + u, c - u, c + v, c - v]
        }
        Shape::Sphere { .. } => unreachable!(),
    }
}

/// Draws `n` light samples from x, checks each against the geometry (the point lies on the
/// light, along wi, at dist, facing x, with the radiance, pdf = pdf_li = `point_pdf`, the
/// density computed here) and tests their directions against pdf_li by chi-square.
/// Returns the integral of the sampled density over the grid.
#[allow(clippy::too_many_arguments)]
fn check_sample_li(
    name: &str,
    light: &Light,
    shapes: &[Shape],
    radiance: Rgb,
    x: Vec3,
    grid: &SphereGrid,
    p_none: f64,
    seed: u64,
    point_pdf: &dyn Fn(DVec3, DVec3) -> f64,
) -> f64 {
    let x64 = d(x);
    let mut rng = Rng::new(&[seed]);
    let mut grazing = 0usize;
    const N: usize = 1_000_000;
    let pdf = |w: DVec3| li_density(light, shapes, x64, w, false);
    let integral = check_directions(name, grid, N, p_none, &pdf, &mut || {
        let ls = light.sample_li(x, rng.next_2d(), rng.next_f32())?;
        let (wi, p) = (d(ls.wi), d(ls.p));
        assert!(!ls.delta);
        assert_close("|wi|", wi.length(), 1.0, 1e-5);
        let dist = (p - x64).length();
        assert_rel("dist", ls.dist as f64, dist, 1e-4);
        assert!(
            (x64 + wi * dist - p).length() < 1e-4 * (1.0 + dist),
            "{name}: p is not along wi"
        );
        let n = shapes
            .iter()
            .find_map(|s| on_shape(s, p, 1e-4))
            .unwrap_or_else(|| panic!("{name}: sampled point {p} is not on the light"));
        assert!(
            (d(ls.n) - n).length() < 1e-4,
            "{name}: normal {} is not {n}",
            ls.n
        );
        let cos_l = n.dot(-wi);
        if cos_l < 1e-3 {
            // Rounding may turn a silhouette point of a sphere away from x.
            grazing += 1;
            assert!(
                cos_l > -1e-3,
                "{name}: sampled a point facing away, cos = {cos_l}"
            );
        } else {
            assert_eq!(ls.li, radiance, "{name}: li");
        }
        let pdf_li = light.pdf_li(x, ls.p, ls.n) as f64;
        assert_rel(
            &format!("{name}: sample pdf vs pdf_li"),
            ls.pdf as f64,
            pdf_li,
            1e-4,
        );
        assert_rel(
            &format!("{name}: pdf_li vs independent pdf"),
            pdf_li,
            point_pdf(p, n),
            1e-3,
        );
        Some(wi)
    });
    assert!(grazing < N / 10_000, "{name}: {grazing} grazing samples");
    integral
}

fn quad_light() -> (Light, Vec<Shape>, Rgb) {
    let quad = Shape::quad(
        Vec3::new(-0.5, 2.0, -0.3),
        Vec3::new(1.2, 0.1, 0.0),
        Vec3::new(0.0, 0.2, 0.8),
    );
    let radiance = Rgb::new(3.0, 2.0, 1.0);
    (area_light(vec![quad], radiance, 0), vec![quad], radiance)
}

fn sphere_light() -> (Light, Vec<Shape>, Rgb) {
    let sphere = Shape::sphere(Vec3::new(0.3, -0.2, 2.5), 0.6);
    let radiance = Rgb::new(1.0, 4.0, 2.0);
    (
        area_light(vec![sphere], radiance, 1),
        vec![sphere],
        radiance,
    )
}

/// Three triangles of different areas: two facing the origin (overlapping as seen from it),
/// one facing away.
fn triangle_light() -> (Light, Vec<Shape>, Rgb) {
    let tris = vec![
        Shape::Triangle {
            p0: Vec3::new(-0.5, -0.4, 2.0),
            e1: Vec3::new(0.0, 1.0, 0.1),
            e2: Vec3::new(0.9, 0.0, 0.2),
        },
        Shape::Triangle {
            p0: Vec3::new(0.0, 0.0, 2.6),
            e1: Vec3::new(0.0, 0.7, -0.3),
            e2: Vec3::new(1.0, 0.2, 0.0),
        },
        Shape::Triangle {
            p0: Vec3::new(-0.8, 0.3, 2.2),
            e1: Vec3::new(0.6, 0.0, 0.0),
            e2: Vec3::new(0.0, 0.5, 0.1),
        },
    ];
    let radiance = Rgb::new(0.5, 1.5, 2.5);
    (area_light(tris.clone(), radiance, 2), tris, radiance)
}

/// d^2 / (|cos| A): the solid-angle density of a point chosen uniformly by area.
fn area_to_solid_angle(x: DVec3, p: DVec3, n: DVec3, area: f64) -> f64 {
    let v = p - x;
    v.length_squared() / (n.dot(v.normalize()).abs() * area)
}

#[test]
fn quad_light_sample_li_matches_pdf_li() {
    let (light, shapes, radiance) = quad_light();
    let x = Vec3::new(0.1, 0.3, 0.2);
    let area = shape_area(&shapes[0]);
    let grid = grid_towards(d(x), &vertices(&shapes[0]));
    let integral = check_sample_li(
        "quad light sample_li",
        &light,
        &shapes,
        radiance,
        x,
        &grid,
        0.0,
        30,
        &|p, n| area_to_solid_angle(d(x), p, n, area),
    );
    assert_close("integral of pdf_li over the quad", integral, 1.0, 1e-3);
}

#[test]
fn sphere_light_seen_from_outside_samples_its_cone() {
    let (light, shapes, radiance) = sphere_light();
    let Shape::Sphere { center, radius, .. } = shapes[0] else {
        unreachable!()
    };
    let x = Vec3::new(0.0, 0.1, 0.0);
    let (c, r) = (d(center), radius as f64);
    let dist2 = (c - d(x)).length_squared();
    let cos_max = (1.0 - r * r / dist2).sqrt();
    let cone_pdf = 1.0 / (TAU * (1.0 - cos_max));
    let grid = SphereGrid::new(c - d(x), Polar::Cos, cone_edges(cos_max, 10), 20);
    let integral = check_sample_li(
        "sphere light (outside) sample_li",
        &light,
        &shapes,
        radiance,
        x,
        &grid,
        0.0,
        31,
        &|_, _| cone_pdf,
    );
    assert_close("integral of pdf_li over the cone", integral, 1.0, 1e-3);
}

#[test]
fn sphere_light_seen_from_inside_is_dark_and_its_pdf_li_normalised() {
    // Emission is one-sided (outward), so from inside the light sends nothing: sample_li must
    // return no sample or one of zero radiance, consistently with `emitted`.
    let (light, shapes, _) = sphere_light();
    let Shape::Sphere { center, .. } = shapes[0] else {
        unreachable!()
    };
    let x = center + Vec3::new(0.1, 0.2, -0.15);
    let mut rng = Rng::new(&[32]);
    for _ in 0..100_000 {
        if let Some(ls) = light.sample_li(x, rng.next_2d(), rng.next_f32()) {
            assert_eq!(ls.li, Rgb::ZERO, "light from inside a one-sided sphere");
            assert_eq!(light.emitted(ls.n, -ls.wi), Rgb::ZERO);
        }
    }
    // pdf_li (the area density converted to solid angle) still integrates to one over the
    // sphere of directions.
    let grid = SphereGrid::full_sphere(DVec3::new(0.2, 0.9, -0.3), 10, 20);
    let integral: f64 = grid
        .probabilities(&|w| li_density(&light, &shapes, d(x), w, true))
        .iter()
        .sum();
    assert_close("integral of pdf_li from inside", integral, 1.0, 1e-3);
}

#[test]
fn triangle_light_sample_li_matches_pdf_li() {
    let (light, shapes, radiance) = triangle_light();
    let x = Vec3::ZERO;
    let areas: Vec<f64> = shapes.iter().map(shape_area).collect();
    let total: f64 = areas.iter().sum();
    let facing: Vec<bool> = shapes
        .iter()
        .map(|s| {
            let v = vertices(s);
            let n = on_shape(s, v[0], 1e-9).unwrap();
            n.dot(d(x) - v[0]) > 0.0
        })
        .collect();
    assert_eq!(facing, [true, true, false], "test geometry");
    let front: Vec<DVec3> = shapes
        .iter()
        .zip(&facing)
        .filter(|&(_, &f)| f)
        .flat_map(|(s, _)| vertices(s))
        .collect();
    let p_none = areas[2] / total;
    let grid = grid_towards(d(x), &front);
    let integral = check_sample_li(
        "triangle light sample_li",
        &light,
        &shapes,
        radiance,
        x,
        &grid,
        p_none,
        33,
        &|p, n| area_to_solid_angle(d(x), p, n, total),
    );
    assert_close(
        "integral over the facing triangles",
        integral,
        1.0 - p_none,
        1e-3,
    );
    // Over all three triangles, pdf_li integrates to one.
    let all: Vec<DVec3> = shapes.iter().flat_map(vertices).collect();
    let grid = grid_towards(d(x), &all);
    let integral: f64 = grid
        .probabilities(&|w| li_density(&light, &shapes, d(x), w, true))
        .iter()
        .sum();
    assert_close("integral of pdf_li over all triangles", integral, 1.0, 1e-3);
}

/// Tests `sample_emission` of an area light: flux = power = pi A L, the normal is the shape's,
/// the direction is cosine-distributed about it (whole sphere, so backward emission would land
/// in empty cells). `position_cell` bins the origin (None: not on the light); `position_exp`
/// gives the expected counts of those cells.
fn check_area_emission(
    name: &str,
    light: &Light,
    shapes: &[Shape],
    radiance: Rgb,
    seed: u64,
    position_cell: &dyn Fn(DVec3, DVec3) -> Option<usize>,
    position_exp: &[f64],
) {
    const N: usize = 1_000_000;
    let area: f64 = shapes.iter().map(shape_area).sum();
    let power = light.power();
    assert!(
        rgb_close(power, (PI * area) as f32 * radiance, 1e-5),
        "{name}: power {power} is not pi A L = {}",
        (PI * area) as f32 * radiance
    );
    let mut rng = Rng::new(&[seed]);
    let mut pos_obs = vec![0u64; position_exp.len()];
    let grid = SphereGrid::full_sphere(DVec3::Z, 10, 20);
    let pdf = |w: DVec3| w.z.max(0.0) / PI;
    check_directions(
        &format!("{name}: emitted directions"),
        &grid,
        N,
        0.0,
        &pdf,
        &mut || {
            let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
            assert_eq!(e.flux, power, "{name}: flux");
            let o = d(e.origin);
            let n = shapes
                .iter()
                .filter_map(|s| on_shape(s, o, 1e-4))
                .find(|&n| (n - d(e.n)).length() < 1e-4)
                .unwrap_or_else(|| {
                    panic!("{name}: origin {o} with normal {} is not on the light", e.n)
                });
            let cell =
                position_cell(o, n).unwrap_or_else(|| panic!("{name}: origin {o} not binned"));
            pos_obs[cell] += 1;
            assert_close("|dir|", e.dir.length() as f64, 1.0, 1e-5);
            Some(Frame::new(n).to_local(d(e.dir)))
        },
    );
    let exp: Vec<f64> = position_exp.iter().map(|p| p * N as f64).collect();
    assert_gof(&format!("{name}: emission positions"), &pos_obs, &exp);
}

#[test]
fn quad_light_emission() {
    let (light, shapes, radiance) = quad_light();
    let Shape::Quad { origin, u, v, .. } = shapes[0] else {
        unreachable!()
    };
    const G: usize = 10;
    let (o, u, v) = (d(origin), d(u), d(v));
    let nrm = u.cross(v);
    let cell = |p: DVec3, _: DVec3| {
        let q = p - o;
        let s = q.cross(v).dot(nrm) / nrm.dot(nrm);
        let t = u.cross(q).dot(nrm) / nrm.dot(nrm);
        let idx = |a: f64| ((a * G as f64).max(0.0) as usize).min(G - 1);
        Some(idx(s) * G + idx(t))
    };
    check_area_emission(
        "quad light",
        &light,
        &shapes,
        radiance,
        40,
        &cell,
        &[1.0 / (G * G) as f64; G * G],
    );
}

#[test]
fn sphere_light_emission() {
    let (light, shapes, radiance) = sphere_light();
    let grid = SphereGrid::full_sphere(DVec3::new(0.5, 0.5, -0.7), 10, 20);
    let exp = vec![1.0 / grid.len() as f64; grid.len()];
    check_area_emission(
        "sphere light",
        &light,
        &shapes,
        radiance,
        41,
        &|_, n| grid.cell(n),
        &exp,
    );
}

#[test]
fn triangle_light_emission() {
    let (light, shapes, radiance) = triangle_light();
    // Per triangle, (b1, b2) binned as in uniform_triangle (exact expected counts).
    const G: usize = 5;
    let areas: Vec<f64> = shapes.iter().map(shape_area).collect();
    let total: f64 = areas.iter().sum();
    let mut exp = Vec::new();
    for a in &areas {
        for i in 0..G {
            for j in 0..G {
                let frac = match (i + j).cmp(&(G - 1)) {
                    std::cmp::Ordering::Less => 2.0,
                    std::cmp::Ordering::Equal => 1.0,
                    std::cmp::Ordering::Greater => 0.0,
                } / (G * G) as f64;
                exp.push(a / total * frac);
            }
        }
    }
    let cell = |p: DVec3, n: DVec3| {
        shapes.iter().enumerate().find_map(|(k, s)| {
            let Shape::Triangle { p0, e1, e2 } = *s else {
                unreachable!()
            };
            let (e1, e2) = (d(e1), d(e2));
            let m = e1.cross(e2);
            if (m.normalize() - n).length() > 1e-6 {
                return None;
            }
            let q = p - d(p0);
            let b1 = q.cross(e2).dot(m) / m.dot(m);
            let b2 = e1.cross(q).dot(m) / m.dot(m);
            let idx = |a: f64| ((a * G as f64).max(0.0) as usize).min(G - 1);
            Some(k * G * G + idx(b1) * G + idx(b2))
        })
    };
    check_area_emission("triangle light", &light, &shapes, radiance, 42, &cell, &exp);
}

#[test]
fn point_light_emission_is_uniform_with_its_power() {
    let position = Vec3::new(0.4, -1.0, 2.0);
    let intensity = Rgb::new(2.0, 1.0, 0.5);
    let light = Light::Point {
        position,
        intensity,
    };
    let power = light.power();
    assert!(rgb_close(power, (4.0 * PI) as f32 * intensity, 1e-6));
    let grid = SphereGrid::full_sphere(DVec3::new(-0.3, 0.2, 0.9), 10, 20);
    let mut rng = Rng::new(&[43]);
    let pdf = |_: DVec3| 1.0 / (4.0 * PI);
    check_directions(
        "point light emission",
        &grid,
        1_000_000,
        0.0,
        &pdf,
        &mut || {
            let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
            assert_eq!(e.origin, position);
            assert_eq!(e.n, Vec3::ZERO);
            assert_eq!(e.flux, power);
            assert_close("|dir|", e.dir.length() as f64, 1.0, 1e-5);
            Some(d(e.dir))
        },
    );
}

// ---------------------------------------------------------------------------------------------
// The environment map
// ---------------------------------------------------------------------------------------------

/// A 16 x 8 map, turned away from the axes: a dim sky, a brighter ground with a red column
/// and a small bright sun (a texel and its neighbour).
fn envmap_light() -> (Light, Mat3) {
    let (w, h) = (16, 8);
    let mut texels = Vec::with_capacity(w * h);
    for j in 0..h {
        for i in 0..w {
            texels.push(if i == 3 {
                Rgb::new(1.5, 0.0, 0.0)
            } else if j < h / 2 {
                Rgb::new(0.2, 0.3, 0.6)
            } else {
                Rgb::new(0.5, 0.4, 0.3)
            });
        }
    }
    texels[2 * w + 9] = Rgb::new(300.0, 250.0, 200.0);
    texels[2 * w + 10] = Rgb::new(100.0, 80.0, 60.0);
    let to_world = Mat3::from_axis_angle(Vec3::new(1.0, 0.5, -0.3).normalize(), 0.7);
    let bitmap = Bitmap::new(w, h, texels).unwrap();
    let map = EnvironmentMap::new(&bitmap, 1.5, to_world).unwrap();
    let light = Light::Envmap {
        map: Arc::new(map),
        centre: Vec3::new(0.1, 0.2, 0.3),
        radius: 2.0,
    };
    (light, to_world)
}

/// A grid in theta about the map's pole, whose sin(theta) cancels the 1/sin(theta) of the
/// map's density.
fn envmap_grid(to_world: Mat3) -> SphereGrid {
    SphereGrid::new(
        d(to_world * Vec3::Y),
        Polar::Theta,
        uniform_edges(0.0, PI, 16),
        32,
    )
}

#[test]
fn envmap_sample_li_matches_pdf_li() {
    let (light, to_world) = envmap_light();
    let x = Vec3::new(0.3, -0.2, 0.5);
    let pdf = |w: DVec3| light.pdf_li(x, x + w.as_vec3(), Vec3::ZERO) as f64;
    let mut rng = Rng::new(&[51]);
    let n = 1_000_000;
    // The density is piecewise constant: a direction within rounding of a cell's edge (x + wi
    // - x is not quite wi) may find the neighbour's.
    let mut mismatches = 0;
    let integral = check_directions(
        "envmap sample_li",
        &envmap_grid(to_world),
        n,
        0.0,
        &pdf,
        &mut || {
            let ls = light.sample_li(x, rng.next_2d(), rng.next_f32())?;
            assert!(!ls.delta);
            if ((ls.pdf as f64 - pdf(d(ls.wi))) / pdf(d(ls.wi))).abs() > 1e-3 {
                mismatches += 1;
            }
            let le = light.environment(ls.wi);
            assert!(rgb_close(ls.li, le, 1e-3), "{} against {le}", ls.li);
            assert!(ls.dist > 0.0 && (ls.p - (x + ls.wi * ls.dist)).length() < 1e-3);
            Some(d(ls.wi))
        },
    );
    assert_close("integral of the envmap's pdf_li", integral, 1.0, 2e-3);
    assert!(
        mismatches <= n / 10_000,
        "{mismatches} samples whose pdf is not pdf_li's"
    );
}

#[test]
fn envmap_emission_follows_its_pdf_with_its_power() {
    let (light, to_world) = envmap_light();
    let Light::Envmap { centre, radius, .. } = light else {
        unreachable!()
    };
    let pdf = |w: DVec3| light.pdf_li(Vec3::ZERO, -w.as_vec3(), Vec3::ZERO) as f64;
    let mut rng = Rng::new(&[52]);
    let n = 1_000_000;
    let mut flux = DVec3::ZERO;
    let mut flux2 = DVec3::ZERO;
    check_directions(
        "envmap emission directions",
        &envmap_grid(to_world),
        n,
        0.0,
        &pdf,
        &mut || {
            let e = light.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_f32());
            // From the disc of the bounding sphere facing the photon's direction, outside it.
            let o = e.origin - centre;
            assert_close(
                "origin behind the centre",
                o.dot(e.dir) as f64,
                -radius as f64,
                1e-4,
            );
            assert!((o - o.dot(e.dir) * e.dir).length() <= radius * 1.0001);
            flux += e.flux.as_dvec3();
            flux2 += (e.flux * e.flux).as_dvec3();
            Some(d(e.dir))
        },
    );
    // The mean flux is the power, within 4 standard errors.
    let mean = flux / n as f64;
    let se = ((flux2 / n as f64 - mean * mean) / n as f64)
        .max(DVec3::ZERO)
        .sqrt();
    let power = light.power().as_dvec3();
    for c in 0..3 {
        assert!(
            (mean[c] - power[c]).abs() < 4.0 * se[c] + 1e-6 * power[c],
            "mean flux {mean} against power {power} (se {se})"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Phase functions
// ---------------------------------------------------------------------------------------------

const PHASES: [Phase; 5] = [
    Phase::Isotropic,
    Phase::HenyeyGreenstein { g: -0.7 },
    Phase::HenyeyGreenstein { g: 0.0 },
    Phase::HenyeyGreenstein { g: 0.3 },
    Phase::HenyeyGreenstein { g: 0.9 },
];

/// Rows in theta, finer towards the axis (theta_k = pi (k / 30)^2), to resolve forward peaks.
fn phase_grid(axis: DVec3) -> SphereGrid {
    let edges = (0..=30).map(|k| PI * (k as f64 / 30.0).powi(2)).collect();
    SphereGrid::new(axis, Polar::Theta, edges, 16)
}

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
// Density-estimation kernels
// ---------------------------------------------------------------------------------------------

#[test]
fn normalized_kernels_integrate_to_one_over_disc_and_ball() {
    const M: usize = 200_000;
    for &name in BUILTIN_KERNELS {
        let cs: &[f64] = if name == "cone" { &[1.0, 2.0] } else { &[1.0] };
        for &c in cs {
            let kernel = NormalizedKernel::new(builtin(name, c).unwrap()).unwrap();
            for r in [1.0f32, 0.37, 2.5] {
                // Midpoint rule in the radius: dA = 2 pi rho d rho, dV = 4 pi rho^2 d rho.
                let h = r as f64 / M as f64;
                let (mut disc, mut ball) = (0.0, 0.0);
                for i in 0..M {
                    let rho = (i as f64 + 0.5) * h;
                    let w2 = kernel.weight_2d(rho as f32, r) as f64;
                    let w3 = kernel.weight_3d(rho as f32, r) as f64;
                    assert!(w2.is_finite() && w2 >= 0.0 && w3.is_finite() && w3 >= 0.0);
                    disc += w2 * TAU * rho * h;
                    ball += w3 * 2.0 * TAU * rho * rho * h;
                }
                let what = format!("kernel {name} (c = {c}), r = {r}");
                assert_close(&format!("{what}: integral over the disc"), disc, 1.0, 1e-3);
                assert_close(&format!("{what}: integral over the ball"), ball, 1.0, 1e-3);
                assert_eq!(
                    kernel.weight_2d(1.001 * r, r),
                    0.0,
                    "{what}: weight beyond r"
                );
                assert_eq!(
                    kernel.weight_3d(1.001 * r, r),
                    0.0,
                    "{what}: weight beyond r"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Free-flight distances in media
// ---------------------------------------------------------------------------------------------

/// (sigma_a, sigma_s, tmax): a channel that does not interact, a chromatic medium over an
/// infinite ray, a grey one.
const FREE_FLIGHT_CASES: [([f32; 3], [f32; 3], f32); 3] = [
    ([0.0, 0.5, 1.0], [0.0, 0.5, 3.0], 1.5),
    ([0.1, 0.0, 4.0], [0.1, 1.0, 1.0], f32::INFINITY),
    ([0.5, 0.5, 0.5], [1.5, 1.5, 1.5], 0.7),
];

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
