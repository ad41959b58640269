//! Statistics for the tests: means of pixel blocks with their standard errors, block-by-block
//! comparison of two images (with the worst block's numbers for the failure message),
//! relative errors, and Pearson's chi-square goodness-of-fit test.

use foton_core::film::Film;
use glam::{DVec3, Vec3};
use std::f64::consts::{PI, TAU};
use std::fmt;

// -----------------------------------------------------------------------------------------
// Relative errors
// -----------------------------------------------------------------------------------------

/// The largest relative error over the channels, |a - b| / |b| (b the reference).
pub fn rel_err(a: Vec3, b: Vec3) -> f32 {
    ((a - b) / b).abs().max_element()
}

/// Relative RMS error of `film` against `reference` over all pixels (channel mean),
/// relative to the reference's mean.
pub fn rel_rmse(film: &Film, reference: &Film) -> f64 {
    let (a, b) = (film.pixels(), reference.pixels());
    assert_eq!(a.len(), b.len(), "images of different sizes");
    let mean_ref: f64 = b
        .iter()
        .map(|p| p.as_dvec3().element_sum() / 3.0)
        .sum::<f64>()
        / b.len() as f64;
    let se: f64 = a
        .iter()
        .zip(&b)
        .map(|(x, y)| {
            let d = (x.as_dvec3() - y.as_dvec3()).element_sum() / 3.0;
            d * d
        })
        .sum::<f64>()
        / a.len() as f64;
    se.sqrt() / mean_ref
}

/// Panics unless |got - want| <= tol.
pub fn assert_close(what: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got}, expected {want} (tolerance {tol})"
    );
}

/// Panics unless |got - want| <= rel max(|got|, |want|).
pub fn assert_rel(what: &str, got: f64, want: f64, rel: f64) {
    assert!(
        (got - want).abs() <= rel * want.abs().max(got.abs()),
        "{what}: got {got}, expected {want} (relative tolerance {rel})"
    );
}

// -----------------------------------------------------------------------------------------
// Blocks of pixels
// -----------------------------------------------------------------------------------------

/// The pixels [x0, x1) x [y0, y1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Rect {
    pub fn new(x0: u32, y0: u32, x1: u32, y1: u32) -> Rect {
        assert!(
            x0 < x1 && y0 < y1,
            "empty rectangle ({x0},{y0})-({x1},{y1})"
        );
        Rect { x0, y0, x1, y1 }
    }

    /// The whole film.
    pub fn all(film: &Film) -> Rect {
        Rect::new(0, 0, film.width, film.height)
    }

    pub fn pixels(&self) -> usize {
        ((self.x1 - self.x0) * (self.y1 - self.y0)) as usize
    }

    /// Whether the rectangle reaches the edge of a `width` x `height` image.
    pub fn on_border(&self, width: u32, height: u32) -> bool {
        self.x0 == 0 || self.y0 == 0 || self.x1 == width || self.y1 == height
    }

    fn iter(self) -> impl Iterator<Item = (u32, u32)> {
        (self.y0..self.y1).flat_map(move |y| (self.x0..self.x1).map(move |x| (x, y)))
    }
}

impl fmt::Display for Rect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "pixels ({},{})-({},{})",
            self.x0, self.y0, self.x1, self.y1
        )
    }
}

/// `width` x `height` pixels cut into `n` x `n` blocks of (nearly) equal size, row by row
/// from the top left.
pub fn grid(width: u32, height: u32, n: u32) -> Vec<Rect> {
    assert!(
        n >= 1 && n <= width && n <= height,
        "{n} blocks of {width}x{height}"
    );
    let edge = |size: u32, i: u32| size * i / n;
    let mut out = Vec::new();
    for j in 0..n {
        for i in 0..n {
            out.push(Rect::new(
                edge(width, i),
                edge(height, j),
                edge(width, i + 1),
                edge(height, j + 1),
            ));
        }
    }
    out
}

/// Mean of the per-pixel values over a block, and the standard error of that mean
/// (standard deviation of the pixels / sqrt(n), per channel: the pixels taken as
/// independent samples, so that the picture's own variation inside the block counts as
/// noise).
#[derive(Clone, Copy, Debug)]
pub struct BlockStats {
    pub mean: DVec3,
    pub se: DVec3,
    pub pixels: usize,
}

/// Mean and standard error of a list of values.
fn mean_se(values: impl Iterator<Item = DVec3>) -> BlockStats {
    let (mut sum, mut sum2, mut n) = (DVec3::ZERO, DVec3::ZERO, 0usize);
    for v in values {
        sum += v;
        sum2 += v * v;
        n += 1;
    }
    assert!(n > 0, "no pixels");
    let nf = n as f64;
    let mean = sum / nf;
    // The variance of the pixels about their mean (divided by n, not n - 1: for the
    // blocks of 16 pixels and more of the tests that is at most 3 % low, on the strict
    // side), then of the mean of n.
    let var = (sum2 / nf - mean * mean).max(DVec3::ZERO);
    let se = (var / nf).sqrt();
    BlockStats {
        mean,
        se,
        pixels: n,
    }
}

/// A film holding `pixels` (row-major from the top left, as `Film::pixels` and
/// `read_image` give them), one sample each: for comparing images read from files.
pub fn film_of(width: u32, height: u32, pixels: &[Vec3]) -> Film {
    assert_eq!(pixels.len(), (width * height) as usize, "{width}x{height}");
    let mut film = Film::new(width, height);
    for (i, p) in pixels.iter().enumerate() {
        film.set_pixel(i as u32 % width, i as u32 / width, *p);
    }
    film
}

pub fn block_stats(film: &Film, r: Rect) -> BlockStats {
    mean_se(r.iter().map(|(x, y)| film.pixel(x, y).as_dvec3()))
}

/// How far apart two block means may be: |a - b| <= max(rel |b|, z se, floor), with se the
/// standard error of the block mean of the pixel-wise difference a - b (see
/// `compare_blocks`), b the reference.
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    /// Bias and noise the pixel statistics do not see (a photon map's low-frequency noise,
    /// its blur), relative to the reference block.
    pub rel: f64,
    /// Standard errors allowed for the pixel noise of both images.
    pub z: f64,
    /// Absolute floor, for blocks that are (nearly) black in the reference.
    pub floor: f64,
}

/// One block and channel of a comparison.
#[derive(Clone, Copy, Debug)]
pub struct BlockDiff {
    pub rect: Rect,
    pub channel: usize,
    pub tolerance: Tolerance,
    /// Block means of the image under test and of the reference.
    pub a: f64,
    pub b: f64,
    /// Standard errors of the two block means and of their difference.
    pub se_a: f64,
    pub se_b: f64,
    pub se_diff: f64,
    /// max(rel |b|, z se_diff, floor).
    pub allowed: f64,
}

impl BlockDiff {
    /// |a - b| / allowed: above 1 fails (equal means never do, even when nothing is
    /// allowed).
    pub fn excess(&self) -> f64 {
        if self.a == self.b {
            0.0
        } else {
            (self.a - self.b).abs() / self.allowed
        }
    }
    /// (a - b) / b.
    pub fn rel(&self) -> f64 {
        (self.a - self.b) / self.b
    }
    /// (a - b) / se_diff.
    pub fn z(&self) -> f64 {
        (self.a - self.b) / self.se_diff
    }
}

impl fmt::Display for BlockDiff {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}, channel {}: {:.5} +- {:.5} vs reference {:.5} +- {:.5} ({:+.2} %, {:+.1} se of the difference {:.5}; allowed {:.5} by {:?}, used {:.0} %)",
            self.rect,
            self.channel,
            self.a,
            self.se_a,
            self.b,
            self.se_b,
            100.0 * self.rel(),
            self.z(),
            self.se_diff,
            self.allowed,
            self.tolerance,
            100.0 * self.excess()
        )
    }
}

/// All blocks and channels of a comparison.
#[derive(Clone, Debug)]
pub struct BlockComparison {
    pub diffs: Vec<BlockDiff>,
}

impl BlockComparison {
    /// The block and channel that use the largest part of their allowance.
    pub fn worst(&self) -> &BlockDiff {
        self.diffs
            .iter()
            .max_by(|a, b| a.excess().total_cmp(&b.excess()))
            .expect("no blocks")
    }

    /// The blocks and channels that fail.
    pub fn failures(&self) -> Vec<&BlockDiff> {
        self.diffs.iter().filter(|d| d.excess() > 1.0).collect()
    }

    /// One line per block: its rectangle and, per channel, the relative difference and the
    /// part of the allowance used (for the record in the test output).
    pub fn table(&self) -> String {
        let mut s = String::new();
        for chunk in self.diffs.chunks(3) {
            s += &format!("  {}:", chunk[0].rect);
            for d in chunk {
                if d.a == d.b {
                    s += &format!("  {:>30}", "equal");
                    continue;
                }
                s += &format!(
                    "  {:+6.2} % ({:+5.1} se, {:3.0} % used)",
                    100.0 * d.rel(),
                    d.z(),
                    100.0 * d.excess()
                );
            }
            s += "\n";
        }
        s
    }

    /// Panics with the worst block's numbers (and the whole table) if a block fails.
    pub fn assert_ok(&self, what: &str) {
        let failures = self.failures();
        assert!(
            failures.is_empty(),
            "{what}: {} of {} block channels disagree; worst: {}\n{}",
            failures.len(),
            self.diffs.len(),
            self.worst(),
            self.table()
        );
    }
}

/// Compares `film` with `reference` block by block, per channel: each block mean of the
/// image under test must lie within max(rel |b|, z se_diff, floor) of the reference's.
///
/// se_diff is the standard error of the block mean of the pixel-wise difference a - b,
/// the pixels taken as independent: for independent renders it estimates
/// sqrt(se_a^2 + se_b^2) of their pixel noise, for renders that share their random
/// numbers (the same seed) it is smaller, as their noise is; the picture's structure
/// inside a block (edges, shading), which both images share, cancels in the difference
/// instead of counting as noise as it does in se_a and se_b. Noise that is correlated
/// over many pixels (a photon map's blotches) is not seen by it: `rel` must cover that.
///
/// `tolerance` gives each block its own: blocks where a known bias lives (a photon map's
/// darkening along the edges of a box) may be given more than the others.
pub fn compare_blocks(
    film: &Film,
    reference: &Film,
    blocks: &[Rect],
    tolerance: impl Fn(Rect) -> Tolerance,
) -> BlockComparison {
    assert_eq!(
        (film.width, film.height),
        (reference.width, reference.height),
        "images of different sizes"
    );
    let mut diffs = Vec::new();
    for &rect in blocks {
        let a = block_stats(film, rect);
        let b = block_stats(reference, rect);
        let d = mean_se(
            rect.iter()
                .map(|(x, y)| (film.pixel(x, y) - reference.pixel(x, y)).as_dvec3()),
        );
        let tolerance = tolerance(rect);
        for c in 0..3 {
            let allowed = (tolerance.rel * b.mean[c].abs())
                .max(tolerance.z * d.se[c])
                .max(tolerance.floor);
            diffs.push(BlockDiff {
                rect,
                channel: c,
                tolerance,
                a: a.mean[c],
                b: b.mean[c],
                se_a: a.se[c],
                se_b: b.se[c],
                se_diff: d.se[c],
                allowed,
            });
        }
    }
    BlockComparison { diffs }
}

/// `compare_blocks` on an `n` x `n` grid with the same tolerance for every block,
/// asserting that every block agrees (the table goes to stderr, for the record).
pub fn assert_blocks_agree(
    what: &str,
    film: &Film,
    reference: &Film,
    n: u32,
    tolerance: Tolerance,
) -> BlockComparison {
    assert_blocks_agree_by(what, film, reference, n, |_| tolerance)
}

/// `assert_blocks_agree` with a tolerance for each block.
pub fn assert_blocks_agree_by(
    what: &str,
    film: &Film,
    reference: &Film,
    n: u32,
    tolerance: impl Fn(Rect) -> Tolerance,
) -> BlockComparison {
    let cmp = compare_blocks(
        film,
        reference,
        &grid(reference.width, reference.height, n),
        tolerance,
    );
    eprintln!("{what}: worst block {}\n{}", cmp.worst(), cmp.table());
    cmp.assert_ok(what);
    cmp
}

// -----------------------------------------------------------------------------------------
// Chi-square goodness of fit
// -----------------------------------------------------------------------------------------

/// Cells expecting fewer samples than this are pooled into one cell.
pub const MIN_EXPECTED: f64 = 5.0;

/// ln Gamma(x) for x > 0 (Lanczos, g = 7, 9 terms; relative error ~1e-15).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection formula.
        PI.ln() - (PI * x).sin().ln() - ln_gamma(1.0 - x)
    } else {
        let x = x - 1.0;
        let t = x + G + 0.5;
        let mut a = C[0];
        for (i, &c) in C.iter().enumerate().skip(1) {
            a += c / (x + i as f64);
        }
        0.5 * TAU.ln() + (x + 0.5) * t.ln() - t + a.ln()
    }
}

/// Regularised upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a): by its
/// series below x = a + 1, by its continued fraction (modified Lentz) above (Numerical
/// Recipes' gser and gcf).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0, "gamma_q({a}, {x})");
    if x == 0.0 {
        return 1.0;
    }
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut ap, mut del) = (a, 1.0 / a);
        let mut sum = del;
        for _ in 0..100_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * prefactor).max(0.0)
    } else {
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..100_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        prefactor * h
    }
}

/// P(X > x) for X chi-square distributed with `dof` degrees of freedom.
pub fn chi2_sf(x: f64, dof: f64) -> f64 {
    gamma_q(0.5 * dof, 0.5 * x)
}

/// The result of a chi-square test: the statistic, its degrees of freedom, its p-value.
#[derive(Debug)]
pub struct Gof {
    pub stat: f64,
    pub dof: usize,
    pub p: f64,
}

/// Pearson's chi-square test of observed counts against expected counts (Mitsuba's
/// variant: cells are sorted by expected count and the smallest pooled until the pool
/// expects at least MIN_EXPECTED). A sample in a cell that expects exactly nothing is an
/// error.
pub fn chi2_gof(observed: &[u64], expected: &[f64]) -> Result<Gof, String> {
    assert_eq!(observed.len(), expected.len());
    let mut order: Vec<usize> = (0..observed.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    let mut stat = 0.0;
    let mut cells = 0usize;
    for &i in &order {
        let (o, e) = (observed[i] as f64, expected[i]);
        assert!(e >= 0.0 && e.is_finite(), "expected count {e} in cell {i}");
        if e == 0.0 {
            if o > 0.0 {
                return Err(format!(
                    "{o} samples in cell {i}, where the pdf integrates to exactly zero"
                ));
            }
            continue;
        }
        if e < MIN_EXPECTED || (pool_e > 0.0 && pool_e < MIN_EXPECTED) {
            pool_o += o;
            pool_e += e;
        } else {
            stat += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pool_e > 0.0 {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        cells += 1;
    }
    if cells < 2 {
        return Err(format!(
            "only {cells} cell(s) after pooling: the test is void"
        ));
    }
    let dof = cells - 1;
    Ok(Gof {
        stat,
        dof,
        p: chi2_sf(stat, dof as f64),
    })
}

/// The cells that contribute most to the statistic, for failure messages.
pub fn worst_cells(observed: &[u64], expected: &[f64]) -> String {
    let mut v: Vec<(usize, f64)> = (0..observed.len())
        .filter(|&i| expected[i] > 0.0)
        .map(|i| {
            let d = observed[i] as f64 - expected[i];
            (i, d * d / expected[i])
        })
        .collect();
    v.sort_by(|a, b| b.1.total_cmp(&a.1));
    v.iter()
        .take(8)
        .map(|&(i, c)| {
            format!(
                "cell {i}: observed {} expected {:.1} (contributes {c:.1})",
                observed[i], expected[i]
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// Panics unless the observed counts fit the expected ones at significance `alpha`.
pub fn assert_gof(name: &str, observed: &[u64], expected: &[f64], alpha: f64) {
    match chi2_gof(observed, expected) {
        Err(e) => panic!("{name}: {e}"),
        Ok(g) => {
            println!(
                "{name}: chi2 = {:.1}, dof = {}, p = {:.3e} (reject below {alpha:.2e})",
                g.stat, g.dof, g.p,
            );
            assert!(
                g.p >= alpha,
                "{name}: the samples do not follow the pdf: chi2 = {:.1} with {} dof, p = {:.3e} < {alpha:.2e}. Worst cells: {}",
                g.stat,
                g.dof,
                g.p,
                worst_cells(observed, expected)
            );
        }
    }
}
