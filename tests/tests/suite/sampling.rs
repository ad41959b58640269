//! Statistical tests of every sampling routine against its pdf, in the manner of pbrt's and
//! Mitsuba's chi-square tests: the domain (usually the sphere of directions, parameterised by
//! (cos theta, phi) or (theta, phi) around some axis) is cut into cells, N samples are drawn and
//! binned, the expected count of each cell is the pdf integrated numerically over the cell,
//! cells expecting fewer than 5 samples are pooled, and the chi-square statistic is compared
//! with its distribution at significance 0.01, Sidak-corrected for the number of tests in this
//! file and the sampling_*.rs files (materials, lights, media), which share its machinery.
//! Besides: every pdf integrates to one, the pdf a sample reports equals the pdf function at
//! the sampled direction, and the deterministic parts (Fresnel, Snell, mirror, flux, kernel
//! normalisation) are checked against independent formulas evaluated in f64.
//!
//! All random numbers come from `Rng::new(&[seed])`, so every run draws the same samples.

use foton_core::Rgb;
use foton_core::kernel::{BUILTIN_KERNELS, NormalizedKernel, builtin};
use foton_core::medium::Phase;
use foton_core::sampling::{self, Distribution1D, Rng};
use foton_tests::stats::{self, Gof, assert_close, assert_rel, chi2_gof, chi2_sf, ln_gamma};
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::{PI, TAU};

// ---------------------------------------------------------------------------------------------
// Statistics
// ---------------------------------------------------------------------------------------------

/// Family-wise significance of all the goodness-of-fit tests of this file and sampling_*.rs.
const ALPHA: f64 = 0.01;

/// Goodness-of-fit tests in this file and sampling_*.rs, for the Sidak correction. Keep in
/// step with the tests.
const NUM_GOF_TESTS: usize = 7 // uniform_sphere, cosine_hemisphere, 3 x uniform_cone, disc, triangle
    + 2 // Distribution1D
    + 2 // diffuse, both sides
    + DIELECTRIC_CASES.len() // binomial reflect/refract frequencies
    + 3 // sample_li: quad, sphere from outside, triangles
    + 7 // sample_emission: positions and directions of 3 area lights, point light directions
    + 2 // environment map: sample_li, sample_emission directions
    + PHASES.len()
    + FREE_FLIGHT_CASES.len();

// The case lists of sampling_materials.rs and sampling_media.rs that NUM_GOF_TESTS counts
// (here, so that the count is written in one place).

/// (ior, wo inside, cos theta_o) of dielectric cases without total internal reflection.
pub(crate) const DIELECTRIC_CASES: [(f32, bool, f64); 14] = [
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

pub(crate) const PHASES: [Phase; 5] = [
    Phase::Isotropic,
    Phase::HenyeyGreenstein { g: -0.7 },
    Phase::HenyeyGreenstein { g: 0.0 },
    Phase::HenyeyGreenstein { g: 0.3 },
    Phase::HenyeyGreenstein { g: 0.9 },
];

/// (sigma_a, sigma_s, tmax): a channel that does not interact, a chromatic medium over an
/// infinite ray, a grey one.
pub(crate) const FREE_FLIGHT_CASES: [([f32; 3], [f32; 3], f32); 3] = [
    ([0.0, 0.5, 1.0], [0.0, 0.5, 3.0], 1.5),
    ([0.1, 0.0, 4.0], [0.1, 1.0, 1.0], f32::INFINITY),
    ([0.5, 0.5, 0.5], [1.5, 1.5, 1.5], 0.7),
];

/// Significance of each single test: 1 - (1 - ALPHA)^(1 / NUM_GOF_TESTS).
pub(crate) fn alpha_each() -> f64 {
    1.0 - (1.0 - ALPHA).powf(1.0 / NUM_GOF_TESTS as f64)
}

/// Panics unless the observed counts fit the expected ones at significance `alpha_each()`.
pub(crate) fn assert_gof(name: &str, observed: &[u64], expected: &[f64]) {
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
pub(crate) fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    assert!(n.is_multiple_of(2));
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        s += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

pub(crate) fn uniform_edges(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|i| lo + (hi - lo) * i as f64 / n as f64)
        .collect()
}

/// Edges in cos theta of `n` equal rows over [lo, 1] such that the cone cos theta >= c ends in
/// the middle of the second row: the first row is outside the cone, the edge of the cone is
/// well inside a cell (so rounding at the edge cannot throw a sample into an empty cell).
pub(crate) fn cone_edges(c: f64, n: usize) -> Vec<f64> {
    let k = 1.5 / n as f64;
    let lo = (c - k) / (1.0 - k);
    assert!(lo >= -1.0, "cone too wide for cone_edges");
    uniform_edges(lo, 1.0, n)
}

/// An orthonormal frame (built here, independently of `sampling::basis`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub(crate) s: DVec3,
    pub(crate) t: DVec3,
    pub(crate) n: DVec3,
}

impl Frame {
    pub(crate) fn new(n: DVec3) -> Self {
        let n = n.normalize();
        let a = if n.x.abs() > 0.8 { DVec3::Y } else { DVec3::X };
        let s = a.cross(n).normalize();
        Frame {
            s,
            t: n.cross(s),
            n,
        }
    }
    pub(crate) fn to_world(self, l: DVec3) -> DVec3 {
        self.s * l.x + self.t * l.y + self.n * l.z
    }
    pub(crate) fn to_local(self, w: DVec3) -> DVec3 {
        DVec3::new(w.dot(self.s), w.dot(self.t), w.dot(self.n))
    }
}

/// How the polar angle is binned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Polar {
    /// Cells of equal width in cos theta (equal solid angle for equal widths).
    Cos,
    /// Cells in theta (resolves peaks at the pole).
    Theta,
}

/// A partition of (part of) the sphere of directions into cells (polar rows x phi columns)
/// around `frame.n`.
pub(crate) struct SphereGrid {
    frame: Frame,
    polar: Polar,
    /// Ascending edges of the rows in cos theta or theta.
    edges: Vec<f64>,
    n_phi: usize,
}

impl SphereGrid {
    pub(crate) fn new(axis: DVec3, polar: Polar, edges: Vec<f64>, n_phi: usize) -> Self {
        assert!(edges.windows(2).all(|w| w[0] < w[1]));
        SphereGrid {
            frame: Frame::new(axis),
            polar,
            edges,
            n_phi,
        }
    }

    pub(crate) fn full_sphere(axis: DVec3, n_cos: usize, n_phi: usize) -> Self {
        Self::new(axis, Polar::Cos, uniform_edges(-1.0, 1.0, n_cos), n_phi)
    }

    pub(crate) fn len(&self) -> usize {
        (self.edges.len() - 1) * self.n_phi
    }

    /// The cell of direction `w`, None outside the grid's polar range.
    pub(crate) fn cell(&self, w: DVec3) -> Option<usize> {
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

    pub(crate) fn dir(&self, x: f64, phi: f64) -> DVec3 {
        let z = match self.polar {
            Polar::Cos => x,
            Polar::Theta => x.cos(),
        };
        let r = (1.0 - z * z).max(0.0).sqrt();
        self.frame
            .to_world(DVec3::new(r * phi.cos(), r * phi.sin(), z))
    }

    /// Probability of each cell under the solid-angle density `pdf`.
    pub(crate) fn probabilities(&self, pdf: &dyn Fn(DVec3) -> f64) -> Vec<f64> {
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

/// Rows in theta, finer towards the axis (theta_k = pi (k / 30)^2), to resolve forward peaks.
pub(crate) fn phase_grid(axis: DVec3) -> SphereGrid {
    let edges = (0..=30).map(|k| PI * (k as f64 / 30.0).powi(2)).collect();
    SphereGrid::new(axis, Polar::Theta, edges, 16)
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
pub(crate) fn check_directions(
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

pub(crate) fn d(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

pub(crate) fn rgb_close(a: Rgb, b: Rgb, rel: f32) -> bool {
    (a - b).abs().max_element() <= rel * a.abs().max(b.abs()).max_element().max(1e-30)
}

/// Probability that a sampler built on `cosine_hemisphere` meets the measure-zero event of a
/// direction exactly on the horizon, which `next_f32`'s 24-bit grid makes possible: u.x or
/// u.y exactly 0 (then rounding may or may not give z = 0). An upper bound, used as the
/// expected frequency of "no sample" (it is pooled away, so it cannot mask a real failure).
pub(crate) const P_HORIZON: f64 = 2.0 / (1u64 << 24) as f64;

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
// foton_core::sampling: warps and distributions
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
