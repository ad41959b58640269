//! `foton compare --consistency N`: do two estimators converge to the same image? Each
//! integrator renders the scene N times with independent seeds; per block of BLOCK x BLOCK
//! pixels, the N block means of one integrator are tested against the N of another (Welch's
//! t-test: unequal variances, Welch-Satterthwaite degrees of freedom), or against a reference
//! image's block mean (with the reference's own standard error, if given). The three colour
//! channels are tested apart and their p-values combined by Simes' test (the smallest of
//! m p_(k) / k), so that a bias in one channel is not diluted by the other two, while three
//! channels that move together (a grey scene) count about as one test, not three as
//! Bonferroni's correction would have them; over the blocks,
//! Benjamini and Hochberg's adjusted p-values hold the false discovery rate at FDR.
//!
//! The Student-t distribution is written here (the regularized incomplete beta function by
//! its continued fraction, Numerical Recipes' `betacf` with the modified Lentz method): a few
//! dozen lines, against a statistics crate for one function.

use crate::montage::{Image, Tile, grid};
use foton_core::Rgb;

/// The blocks are BLOCK x BLOCK pixels (partial at the right and bottom edges).
pub const BLOCK: u32 = 8;
/// The false discovery rate over the blocks of one pair.
pub const FDR: f64 = 0.01;
/// The fewest renders per integrator: with fewer, a sample variance has too few degrees of
/// freedom to say much.
pub const MIN_RENDERS: u32 = 4;
/// Differences below this fraction of the block's mean are float rounding, not bias: a
/// variance floor, so that two exact, equal estimates (a light seen directly, the same in
/// every render) are not told apart by their last bits.
const PRECISION: f64 = 1e-5;

/// Blocks across and down an image of `width` x `height`.
pub fn block_grid(width: u32, height: u32) -> (u32, u32) {
    (width.div_ceil(BLOCK), height.div_ceil(BLOCK))
}

/// The mean of each channel over each block, blocks row-major; `f` maps a pixel to the
/// value averaged (the pixel itself, or its squared standard error).
fn block_sums(
    pixels: &[Rgb],
    width: u32,
    height: u32,
    f: impl Fn(Rgb) -> [f64; 3],
) -> (Vec<[f64; 3]>, Vec<f64>) {
    let (bw, bh) = block_grid(width, height);
    let mut sums = vec![[0.0f64; 3]; (bw * bh) as usize];
    let mut counts = vec![0.0f64; (bw * bh) as usize];
    for y in 0..height {
        for x in 0..width {
            let b = ((y / BLOCK) * bw + x / BLOCK) as usize;
            let v = f(pixels[(y * width + x) as usize]);
            for c in 0..3 {
                sums[b][c] += v[c];
            }
            counts[b] += 1.0;
        }
    }
    (sums, counts)
}

/// The mean of each channel over each block of `pixels` (`width` x `height`, row-major).
pub fn block_means(pixels: &[Rgb], width: u32, height: u32) -> Vec<[f64; 3]> {
    let (sums, counts) = block_sums(pixels, width, height, |p| p.as_dvec3().to_array());
    sums.iter()
        .zip(&counts)
        .map(|(s, &n)| s.map(|s| s / n))
        .collect()
}

/// The variance of each block mean of an image whose pixels have independent errors with
/// these standard errors: sum(se^2) / n^2.
pub fn block_variances(se: &[Rgb], width: u32, height: u32) -> Vec<[f64; 3]> {
    let (sums, counts) = block_sums(se, width, height, |p| {
        p.as_dvec3().to_array().map(|s| s * s)
    });
    sums.iter()
        .zip(&counts)
        .map(|(s, &n)| s.map(|s| s / (n * n)))
        .collect()
}

/// An estimate of every block's mean: the estimate, the variance of the estimate, and the
/// degrees of freedom of that variance (infinite when it is known, not estimated).
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    pub mean: Vec<[f64; 3]>,
    pub var: Vec<[f64; 3]>,
    pub df: f64,
}

impl Estimate {
    /// From the block means of N independent renders: their mean, its variance s^2 / N (s^2
    /// the sample variance), N - 1 degrees of freedom.
    pub fn of_renders(renders: &[Vec<[f64; 3]>]) -> Estimate {
        let n = renders.len() as f64;
        assert!(renders.len() >= 2, "a variance needs two renders");
        let blocks = renders[0].len();
        let mut mean = vec![[0.0f64; 3]; blocks];
        let mut var = vec![[0.0f64; 3]; blocks];
        for b in 0..blocks {
            for c in 0..3 {
                let m = renders.iter().map(|r| r[b][c]).sum::<f64>() / n;
                let ss = renders.iter().map(|r| (r[b][c] - m).powi(2)).sum::<f64>();
                mean[b][c] = m;
                var[b][c] = ss / (n - 1.0) / n;
            }
        }
        Estimate {
            mean,
            var,
            df: n - 1.0,
        }
    }

    /// A reference's block means, with the variances of its standard-error image
    /// (`block_variances`) or as exact (zero).
    pub fn reference(mean: Vec<[f64; 3]>, var: Option<Vec<[f64; 3]>>) -> Estimate {
        let var = var.unwrap_or_else(|| vec![[0.0; 3]; mean.len()]);
        Estimate {
            mean,
            var,
            df: f64::INFINITY,
        }
    }
}

/// The renders of one integrator as --consistency accumulates them: per render its block
/// means; per pixel the running mean and sum of squared deviations of its values (Welford's
/// update: exactly zero for a pixel that is the same in every render).
#[derive(Clone, Debug)]
pub struct Renders {
    width: u32,
    height: u32,
    blocks: Vec<Vec<[f64; 3]>>,
    mean: Vec<[f64; 3]>,
    m2: Vec<[f64; 3]>,
}

impl Renders {
    pub fn new(width: u32, height: u32) -> Renders {
        let n = (width * height) as usize;
        Renders {
            width,
            height,
            blocks: Vec::new(),
            mean: vec![[0.0; 3]; n],
            m2: vec![[0.0; 3]; n],
        }
    }

    /// Adds a render's pixels (row-major, `width` x `height`).
    pub fn add(&mut self, pixels: &[Rgb]) {
        self.blocks
            .push(block_means(pixels, self.width, self.height));
        let n = self.blocks.len() as f64;
        for ((p, mean), m2) in pixels.iter().zip(&mut self.mean).zip(&mut self.m2) {
            for c in 0..3 {
                let x = p[c] as f64;
                let d = x - mean[c];
                mean[c] += d / n;
                m2[c] += d * (x - mean[c]);
            }
        }
    }

    /// The mean of the renders, per pixel.
    pub fn mean_pixels(&self) -> Vec<Rgb> {
        self.mean
            .iter()
            .map(|m| Rgb::new(m[0] as f32, m[1] as f32, m[2] as f32))
            .collect()
    }

    /// The estimate of every block's mean from the N renders (at least 2): the mean of their
    /// block means, with N - 1 degrees of freedom, and as its variance the larger of two
    /// estimates of it. One is the spread of the N block means (`Estimate::of_renders`), right
    /// also when the pixels' errors are correlated (a photon map's are: one photon lights many
    /// pixels). The other pools the pixels' own spreads over the block, sum s_i^2 / (n^2 N),
    /// right when they are independent, and then with n times the degrees of freedom: a
    /// heavy-tailed estimator (rare bright paths) whose N block means happened to miss its
    /// outliers gets a block spread far below its variance more often than the t
    /// distribution allows; its pixels' spreads are less often all caught low. Taking the
    /// larger, at N - 1 degrees of freedom, errs on the side of "consistent".
    pub fn estimate(&self) -> Estimate {
        let mut e = Estimate::of_renders(&self.blocks);
        let n = self.blocks.len() as f64;
        let (bw, _) = block_grid(self.width, self.height);
        let mut pooled = vec![[0.0f64; 3]; e.var.len()];
        let mut pixels = vec![0.0f64; e.var.len()];
        for (i, m2) in self.m2.iter().enumerate() {
            let (x, y) = (i as u32 % self.width, i as u32 / self.width);
            let b = ((y / BLOCK) * bw + x / BLOCK) as usize;
            pixels[b] += 1.0;
            for c in 0..3 {
                pooled[b][c] += m2[c] / (n - 1.0) / n;
            }
        }
        for ((v, pooled), n) in e.var.iter_mut().zip(&pooled).zip(&pixels) {
            for c in 0..3 {
                v[c] = v[c].max(pooled[c] / (n * n));
            }
        }
        e
    }
}

/// One side of a test: an estimate of a mean, the variance of the estimate, its degrees of
/// freedom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Side {
    pub mean: f64,
    pub var: f64,
    pub df: f64,
}

/// The two-sided p-value of Welch's t-test that `a` and `b` estimate the same mean: t = (a -
/// b) / sqrt(var_a + var_b), with the Welch-Satterthwaite degrees of freedom (var_a +
/// var_b)^2 / (var_a^2 / df_a + var_b^2 / df_b) (a variance known exactly, df infinite, adds
/// nothing below). None when there is nothing to test: both exact and equal (to PRECISION).
/// Both exact and different: 0.
pub fn welch_p(a: Side, b: Side) -> Option<f64> {
    let diff = a.mean - b.mean;
    if !diff.is_finite() {
        // A NaN or an infinity: the same on both sides, or a difference.
        return (a.mean != b.mean).then_some(0.0);
    }
    let scale = PRECISION * a.mean.abs().max(b.mean.abs());
    if a.var + b.var == 0.0 {
        return (diff.abs() > scale).then_some(0.0);
    }
    let var = a.var + b.var + scale * scale;
    if !var.is_finite() {
        return None;
    }
    let spread = |s: Side| {
        if s.df.is_finite() {
            s.var * s.var / s.df
        } else {
            0.0
        }
    };
    // Infinite when both variances are known exactly: the normal distribution.
    let df = var * var / (spread(a) + spread(b));
    Some(student_t_two_sided(diff / var.sqrt(), df))
}

/// The p-value of a block: each channel's Welch test, combined by Simes' test (m channels
/// tested, p_(k) the k-th smallest: min_k m p_(k) / k; valid when the channels' errors are
/// positively correlated, as a render's are, and an exact test when they are independent). None
/// when no channel is tested.
pub fn block_p(a: &Estimate, b: &Estimate, block: usize) -> Option<f64> {
    let side = |e: &Estimate, c: usize| Side {
        mean: e.mean[block][c],
        var: e.var[block][c],
        df: e.df,
    };
    let mut ps: Vec<f64> = (0..3)
        .filter_map(|c| welch_p(side(a, c), side(b, c)))
        .collect();
    ps.sort_by(f64::total_cmp);
    let m = ps.len() as f64;
    ps.iter()
        .enumerate()
        .map(|(k, p)| m * p / (k + 1) as f64)
        .reduce(f64::min)
        .map(|p| p.min(1.0))
}

/// Benjamini and Hochberg's adjusted p-values, in the order of `p`: p_(i) m / i for the i-th
/// smallest of m, made non-decreasing from the largest down, at most 1. A hypothesis is
/// rejected at false discovery rate q when its adjusted p-value is at most q.
pub fn bh_adjust(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&i, &j| p[i].total_cmp(&p[j]));
    let mut adjusted = vec![1.0; m];
    let mut running = 1.0f64;
    for (rank, &i) in order.iter().enumerate().rev() {
        running = running.min(p[i] * m as f64 / (rank + 1) as f64);
        adjusted[i] = running.min(1.0);
    }
    adjusted
}

/// The test of one pair over the blocks.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// Per block, row-major: its adjusted p-value, None when not tested.
    pub adjusted: Vec<Option<f64>>,
}

impl Outcome {
    pub fn tested(&self) -> usize {
        self.adjusted.iter().flatten().count()
    }

    /// Whether block `b` differs (its adjusted p-value at most FDR).
    pub fn differs(&self, b: usize) -> bool {
        self.adjusted[b].is_some_and(|p| p <= FDR)
    }

    pub fn differing(&self) -> usize {
        (0..self.adjusted.len())
            .filter(|&b| self.differs(b))
            .count()
    }

    /// The smallest adjusted p-value; None when no block was tested.
    pub fn min_adjusted_p(&self) -> Option<f64> {
        self.adjusted.iter().flatten().copied().reduce(f64::min)
    }
}

/// Tests `a` against `b`, block by block (`block_p`), with Benjamini-Hochberg over the blocks
/// tested.
pub fn test(a: &Estimate, b: &Estimate) -> Outcome {
    let p: Vec<Option<f64>> = (0..a.mean.len()).map(|i| block_p(a, b, i)).collect();
    let tested: Vec<f64> = p.iter().flatten().copied().collect();
    let mut adjusted = bh_adjust(&tested).into_iter();
    Outcome {
        adjusted: p.iter().map(|p| p.and_then(|_| adjusted.next())).collect(),
    }
}

/// One pair tested: two integrators, or an integrator and the reference (`b` = "reference").
#[derive(Clone, Debug)]
pub struct Pair {
    pub a: String,
    pub b: String,
    pub outcome: Outcome,
    /// The pair's biased-but-consistent integrators, by name, with what shrinks their bias
    /// (`Integrator::bias`).
    pub biased: Vec<(String, String)>,
}

impl Pair {
    pub fn differs(&self) -> bool {
        self.outcome.differing() > 0
    }

    /// "consistency path vs bdpt: 0 of 16 blocks differ (smallest adjusted p 0.41): consistent".
    pub fn verdict(&self) -> String {
        let o = &self.outcome;
        let mut s = format!(
            "consistency {} vs {}: {} of {} blocks differ",
            self.a,
            self.b,
            o.differing(),
            o.tested()
        );
        match o.min_adjusted_p() {
            Some(p) => s += &format!(" (smallest adjusted p {})", p_text(p)),
            None => s += " (no block to test: both exact and equal everywhere)",
        }
        if !self.differs() {
            return s + ": consistent";
        }
        s += ": DIFFER";
        for (name, note) in &self.biased {
            s += &format!(
                "; {name} is biased but consistent: a difference may be its bias at this budget; {note}"
            );
        }
        s
    }
}

/// A p-value for the verdict: 0.41, 0.013, 2.3e-9.
pub fn p_text(p: f64) -> String {
    if p >= 0.01 {
        format!("{p:.2}")
    } else if p > 0.0 {
        format!("{p:.1e}")
    } else {
        "0".into()
    }
}

/// Panels of the map are magnified (by a whole factor, at most 8) to be at least this wide, so
/// that the blocks of a small image, and its label, can be read.
const MAP_WIDTH: u32 = 256;

/// The map of the blocks that differ, one panel per pair: `base` (the first integrator's
/// image as displayed) in dimmed grey, each block that differs in red.
pub fn map(base: &Image, pairs: &[Pair]) -> Image {
    let (bw, _) = block_grid(base.width, base.height);
    let zoom = MAP_WIDTH.div_ceil(base.width.max(1)).clamp(1, 8);
    let grey: Vec<Rgb> = base
        .pixels
        .iter()
        .map(|p| Rgb::splat(0.05 + 0.45 * foton_core::average(p.clamp(Rgb::ZERO, Rgb::ONE))))
        .collect();
    let red = Rgb::new(0.9, 0.02, 0.02);
    let tiles: Vec<Tile> = pairs
        .iter()
        .map(|pair| {
            let mut image = Image::new(base.width * zoom, base.height * zoom, Rgb::ZERO);
            for y in 0..image.height {
                for x in 0..image.width {
                    let (px, py) = (x / zoom, y / zoom);
                    let g = grey[(py * base.width + px) as usize];
                    let b = ((py / BLOCK) * bw + px / BLOCK) as usize;
                    let c = if pair.outcome.differs(b) {
                        red * 0.7 + g * 0.6
                    } else {
                        g
                    };
                    image.put(x as i64, y as i64, c);
                }
            }
            let o = &pair.outcome;
            Tile {
                image,
                label: vec![
                    format!("{} vs {}", pair.a, pair.b),
                    format!("{} of {} blocks differ", o.differing(), o.tested()),
                    o.min_adjusted_p().map_or_else(
                        || "no block to test".into(),
                        |p| format!("smallest adj. p {}", p_text(p)),
                    ),
                ],
            }
        })
        .collect();
    grid(&tiles, tiles.len().min(3))
}

// ---------------------------------------------------------------------------------------------
// The Student-t distribution
// ---------------------------------------------------------------------------------------------

/// P(|T| >= |t|) for T Student-t distributed with `df` degrees of freedom (> 0; infinite: the
/// normal distribution): the regularized incomplete beta function I_x(df/2, 1/2) at x = df /
/// (df + t^2).
pub fn student_t_two_sided(t: f64, df: f64) -> f64 {
    if t.is_nan() || df.is_nan() {
        return f64::NAN;
    }
    if df > 1e7 {
        return erfc(t.abs() / std::f64::consts::SQRT_2);
    }
    if t.is_infinite() {
        return 0.0;
    }
    beta_regularized(df / 2.0, 0.5, df / (df + t * t))
}

/// ln Gamma(x) for x > 0 (Lanczos' approximation as in Numerical Recipes' `gammln`, relative
/// error below 2e-10).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 6] = [
        76.180_091_729_471_46,
        -86.505_320_329_416_77,
        24.014_098_240_830_91,
        -1.231_739_572_450_155,
        0.120_865_097_386_617_9e-2,
        -0.539_523_938_495_3e-5,
    ];
    let tmp = x + 5.5;
    let tmp = tmp - (x + 0.5) * tmp.ln();
    let mut y = x;
    let mut series = 1.000_000_000_190_015;
    for c in C {
        y += 1.0;
        series += c / y;
    }
    -tmp + (2.506_628_274_631_000_5 * series / x).ln()
}

/// The regularized incomplete beta function I_x(a, b): its continued fraction where it
/// converges fast (x < (a + 1) / (a + b + 2)), otherwise through I_x(a, b) = 1 - I_{1-x}(b,
/// a).
fn beta_regularized(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_fraction(a, b, x) / a
    } else {
        1.0 - front * beta_fraction(b, a, 1.0 - x) / b
    }
}

/// The continued fraction of the incomplete beta function, evaluated by the modified Lentz
/// method (Numerical Recipes' `betacf`).
fn beta_fraction(a: f64, b: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    const EPS: f64 = 1e-15;
    let guard = |v: f64| if v.abs() < TINY { TINY } else { v };
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 / guard(1.0 - qab * x / qap);
    let mut h = d;
    for m in 1..10_000 {
        let m = m as f64;
        let m2 = 2.0 * m;
        // The even step.
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 / guard(1.0 + aa * d);
        c = guard(1.0 + aa / c);
        h *= d * c;
        // The odd step.
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 / guard(1.0 + aa * d);
        c = guard(1.0 + aa / c);
        let step = d * c;
        h *= step;
        if (step - 1.0).abs() < EPS {
            break;
        }
    }
    h
}

/// The complementary error function (Numerical Recipes' `erfcc`, a Chebyshev fit, relative
/// error below 1.2e-7 everywhere).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * (-z * z + poly).exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

#[cfg(test)]
mod tests {
    use super::*;
    use foton_core::sampling::Rng;

    fn close(got: f64, want: f64, rel: f64) {
        assert!(
            (got - want).abs() <= rel * want.abs(),
            "got {got}, expected {want}"
        );
    }

    #[test]
    fn student_t_p_values_match_the_tables() {
        // Two-sided critical values of Student's t (any statistics table).
        close(student_t_two_sided(12.706_204_736_174_7, 1.0), 0.05, 1e-8);
        close(student_t_two_sided(2.228_138_851_986_27, 10.0), 0.05, 1e-8);
        close(student_t_two_sided(3.169_272_667_175_84, 10.0), 0.01, 1e-8);
        close(student_t_two_sided(2.085_963_447_265_84, 20.0), 0.05, 1e-8);
        close(student_t_two_sided(-2.776_445_105_197_8, 4.0), 0.05, 1e-8);
        // Closed forms: df = 1 is Cauchy, P(|T| > 1) = 1/2; df = 2, 1 - t / sqrt(2 + t^2).
        close(student_t_two_sided(1.0, 1.0), 0.5, 1e-10);
        close(
            student_t_two_sided(2.0, 2.0),
            1.0 - 2.0 / 6f64.sqrt(),
            1e-10,
        );
        close(student_t_two_sided(0.0, 3.0), 1.0, 1e-12);
        // Far in the tail: df = 2, t = 1000.
        let t: f64 = 1000.0;
        close(
            student_t_two_sided(t, 2.0),
            1.0 - t / (2.0 + t * t).sqrt(),
            1e-6,
        );
        // The normal limit, and a large df close to it.
        close(
            student_t_two_sided(1.959_963_984_540_054, f64::INFINITY),
            0.05,
            1e-6,
        );
        close(student_t_two_sided(2.575_829_303_548_901, 1e9), 0.01, 1e-6);
        close(student_t_two_sided(1.959_963_984_540_054, 1e6), 0.05, 1e-4);
        // Non-integer df (Welch's), between its neighbours.
        let p = student_t_two_sided(2.5, 4.5);
        assert!(
            student_t_two_sided(2.5, 5.0) < p && p < student_t_two_sided(2.5, 4.0),
            "{p}"
        );
    }

    #[test]
    fn welch_test_of_a_worked_example() {
        // a = 1, 2, 3, 4; b = 2, 4, 6, 8: t = -sqrt(3), df = 4.41176... (by hand: var of the
        // means 5/12 and 5/3).
        let a = Estimate::of_renders(&[1.0, 2.0, 3.0, 4.0].map(|x| vec![[x; 3]]));
        let b = Estimate::of_renders(&[2.0, 4.0, 6.0, 8.0].map(|x| vec![[x; 3]]));
        close(a.var[0][0], 5.0 / 12.0, 1e-12);
        close(b.var[0][0], 5.0 / 3.0, 1e-12);
        let side = |e: &Estimate| Side {
            mean: e.mean[0][0],
            var: e.var[0][0],
            df: e.df,
        };
        let var: f64 = 5.0 / 12.0 + 5.0 / 3.0;
        let df = var * var / ((5.0f64 / 12.0).powi(2) / 3.0 + (5.0f64 / 3.0).powi(2) / 3.0);
        close(df, 4.411_764_705_882_353, 1e-9);
        let p = welch_p(side(&a), side(&b)).unwrap();
        close(p, student_t_two_sided(3f64.sqrt(), df), 1e-9);
        assert!(p > 0.1 && p < 0.2, "{p}");
        // Three channels alike count as one.
        close(block_p(&a, &b, 0).unwrap(), p, 1e-12);
        // One channel apart: Simes' combination of its p-value with two of 1.
        let mut c = b.clone();
        c.mean[0][1] = a.mean[0][1];
        c.mean[0][2] = a.mean[0][2];
        close(block_p(&a, &c, 0).unwrap(), 3.0 * p, 1e-12);
    }

    #[test]
    fn exact_estimates_are_not_tested_or_differ() {
        let exact = |m: f64| Side {
            mean: m,
            var: 0.0,
            df: 3.0,
        };
        assert_eq!(welch_p(exact(0.0), exact(0.0)), None);
        assert_eq!(welch_p(exact(1.0), exact(1.0 + 1e-7)), None);
        assert_eq!(welch_p(exact(1.0), exact(1.1)), Some(0.0));
        assert_eq!(welch_p(exact(0.0), exact(1e-30)), Some(0.0));
        // Against an exact reference, a noisy estimate is tested with its own df.
        let noisy = Side {
            mean: 1.0,
            var: 0.01,
            df: 3.0,
        };
        let reference = Side {
            mean: 1.3,
            var: 0.0,
            df: f64::INFINITY,
        };
        close(
            welch_p(noisy, reference).unwrap(),
            student_t_two_sided(3.0, 3.0),
            1e-6,
        );
    }

    #[test]
    fn benjamini_hochberg_of_their_example() {
        // Benjamini and Hochberg (1995), section 4: 15 p-values; at q = 0.05 the four smallest
        // are rejected. Adjusted values as R's p.adjust(p, "BH") gives them.
        let p = [
            0.0001, 0.0004, 0.0019, 0.0095, 0.0201, 0.0278, 0.0298, 0.0344, 0.0459, 0.3240, 0.4262,
            0.5719, 0.6528, 0.7590, 1.0000,
        ];
        let adjusted = bh_adjust(&p);
        let want = [
            0.0015,
            0.003,
            0.0095,
            0.035625,
            0.0603,
            0.063857142857,
            0.063857142857,
            0.0645,
            0.0765,
            0.486,
            0.58118181818,
            0.714875,
            0.75323076923,
            0.81321428571,
            1.0,
        ];
        for (g, w) in adjusted.iter().zip(want) {
            close(*g, w, 1e-9);
        }
        assert_eq!(adjusted.iter().filter(|&&a| a <= 0.05).count(), 4);
        // The order of the input does not matter.
        let mut reversed = p;
        reversed.reverse();
        let mut back = bh_adjust(&reversed);
        back.reverse();
        assert_eq!(back, adjusted);
    }

    /// N renders of 256 blocks each: every block's mean is `mean(block)` plus noise; the
    /// noise is a sum of exponentials (skewed, like a render's), its variance varying by
    /// block.
    fn renders(rng: &mut Rng, n: usize, mean: impl Fn(usize) -> f64) -> Vec<Vec<[f64; 3]>> {
        (0..n)
            .map(|_| {
                (0..256)
                    .map(|b| {
                        let scale = 0.05 + (b % 7) as f64 * 0.1;
                        [0, 1, 2].map(|_| {
                            let e: f64 = (0..8).map(|_| -(1.0 - rng.next_f32() as f64).ln()).sum();
                            mean(b) + scale * (e / 8.0 - 1.0)
                        })
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn one_estimator_against_itself_is_consistent_and_a_shift_is_caught() {
        let mut rng = Rng::new(&[7, 1]);
        let mut rejections = 0;
        let mut small = 0;
        let mut all = 0;
        for _ in 0..20 {
            let a = Estimate::of_renders(&renders(&mut rng, 4, |_| 1.0));
            let b = Estimate::of_renders(&renders(&mut rng, 6, |_| 1.0));
            let outcome = test(&a, &b);
            assert_eq!(outcome.tested(), 256);
            rejections += outcome.differing();
            // The raw p-values are about uniform: about 10% of them below 0.1.
            for i in 0..256 {
                let p = block_p(&a, &b, i).unwrap();
                all += 1;
                small += (p < 0.1) as usize;
            }
        }
        assert!(rejections <= 1, "{rejections} false rejections");
        let fraction = small as f64 / all as f64;
        // Simes' combination of three independent channels is exact: 0.1.
        assert!((0.08..=0.12).contains(&fraction), "{fraction}");

        // Twenty blocks one standard deviation of a render's noise brighter, in one channel.
        let a = Estimate::of_renders(&renders(&mut rng, 8, |_| 1.0));
        let mut shifted = renders(&mut rng, 8, |_| 1.0);
        for r in &mut shifted {
            for b in 0..20 {
                r[b * 12][1] += 0.6;
            }
        }
        let outcome = test(&a, &Estimate::of_renders(&shifted));
        let caught = (0..20).filter(|&b| outcome.differs(b * 12)).count();
        assert!(caught >= 15, "{caught} of 20 shifted blocks caught");
        assert!(outcome.differing() <= caught + 1);
        assert!(outcome.min_adjusted_p().unwrap() < 1e-3);
    }

    #[test]
    fn renders_pool_their_pixels_spreads_and_keep_correlated_ones() {
        let (w, h) = (64, 64);
        let n = (w * h) as usize;
        let mut rng = Rng::new(&[3]);
        // Independent noise per pixel: the spread of 4 block means alone is often far below
        // the variance (chi-square with 3 degrees of freedom); the pixels' pooled spread is
        // not.
        let mut independent = Renders::new(w, h);
        // The same noise over the whole image (one photon lighting every pixel): the spread
        // of the block means is the variance; the pixels' own spreads are as large, no larger.
        let mut correlated = Renders::new(w, h);
        // Constant: nothing to test.
        let mut exact = Renders::new(w, h);
        let mut shared = [0.0f64; 4];
        for s in &mut shared {
            *s = rng.next_f32() as f64;
            independent.add(
                &(0..n)
                    .map(|_| Rgb::splat(rng.next_f32()))
                    .collect::<Vec<_>>(),
            );
            correlated.add(&vec![Rgb::splat(*s as f32); n]);
            exact.add(&vec![Rgb::splat(0.25); n]);
        }
        let e = independent.estimate();
        // Uniform noise: variance 1/12 per pixel; of the mean of 64 pixels and 4 renders.
        let want = 1.0 / 12.0 / 64.0 / 4.0;
        for v in &e.var {
            assert!(v[0] > 0.75 * want, "{} {want}", v[0]);
        }
        assert_eq!(e.df, 3.0);

        let e = correlated.estimate();
        let mean = shared.iter().sum::<f64>() / 4.0;
        let var = shared.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / 3.0 / 4.0;
        for b in 0..64 {
            assert!(
                (e.var[b][0] / var - 1.0).abs() < 1e-4,
                "{} {var}",
                e.var[b][0]
            );
            assert!((e.mean[b][0] - mean).abs() < 1e-6);
        }

        let e = exact.estimate();
        assert!(e.var.iter().all(|v| *v == [0.0; 3]));
        assert_eq!(test(&e, &e.clone()).tested(), 0);
        assert_eq!(exact.mean_pixels()[5], Rgb::splat(0.25));
    }

    #[test]
    fn verdicts_say_what_differs_and_what_may_explain_it() {
        let pair = |adjusted: Vec<Option<f64>>, biased: Vec<(String, String)>| Pair {
            a: "path".into(),
            b: "photon".into(),
            outcome: Outcome { adjusted },
            biased,
        };
        let note = || vec![("photon".to_string(), "more photons shrink it".to_string())];
        let same = pair(vec![Some(0.41), None, Some(1.0)], note());
        assert!(!same.differs());
        assert_eq!(
            same.verdict(),
            "consistency path vs photon: 0 of 2 blocks differ (smallest adjusted p 0.41): consistent"
        );
        let differ = pair(vec![Some(2.34e-9), Some(0.01), Some(0.5)], note());
        assert!(differ.differs());
        assert_eq!(
            differ.verdict(),
            "consistency path vs photon: 2 of 3 blocks differ (smallest adjusted p 2.3e-9): DIFFER; photon is biased but consistent: a difference may be its bias at this budget; more photons shrink it"
        );
        let untested = pair(vec![None; 4], Vec::new());
        assert!(
            untested
                .verdict()
                .ends_with("(no block to test: both exact and equal everywhere): consistent")
        );
        assert_eq!(p_text(0.0), "0");
        assert_eq!(p_text(0.013), "0.01");
    }

    #[test]
    fn block_means_and_variances_of_a_small_image() {
        // 10 x 9 pixels: blocks 8x8, 2x8, 8x1, 2x1.
        let (w, h) = (10, 9);
        let pixels: Vec<Rgb> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                Rgb::new(x as f32, y as f32, 1.0)
            })
            .collect();
        assert_eq!(block_grid(w, h), (2, 2));
        let m = block_means(&pixels, w, h);
        assert_eq!(
            m,
            [
                [3.5, 3.5, 1.0],
                [8.5, 3.5, 1.0],
                [3.5, 8.0, 1.0],
                [8.5, 8.0, 1.0]
            ]
        );
        let se = vec![Rgb::splat(2.0); (w * h) as usize];
        let v = block_variances(&se, w, h);
        assert_eq!(v[0], [4.0 / 64.0; 3]);
        assert_eq!(v[3], [4.0 / 2.0; 3]);
    }
}
