//! Pixel reconstruction filters (Mitsuba's `rfilter`: box, tent, gaussian, mitchell,
//! catmullrom, lanczos; pbrt-v4's box, triangle, gaussian, mitchell, sinc), applied by filter
//! importance sampling (Ernst et al. 2006): each camera sample of a pixel is placed at an
//! offset from the pixel's centre drawn with the density of the filter. The pixel's expected
//! value is then the filter-weighted average of the image around it, what a splatting
//! reconstruction converges to, while every pixel keeps its own samples (images stay
//! independent of the thread count, and a pixel's samples are its own).
//!
//! The filters are separable, w(x, y) = w(x) w(y), and each axis is tabulated (1024 pieces
//! over the filter's support, each with w at its centre). A positive filter's offsets are
//! drawn with density w / ∫w and count with weight one. A filter with negative lobes
//! (Mitchell-Netravali, Catmull-Rom, windowed sinc) is sampled by |w|, as pbrt-v4's
//! `FilterSampler` does: an offset drawn with density |w| / ∫|w| carries the weight
//! sign(w) ∫|w| / ∫w (per axis, multiplied), so that the weighted sample still averages to
//! the filter-weighted image. Such weights are exactly 1.0 for a positive filter.

use glam::Vec2;

/// A pixel filter; radii and deviations in pixels, radii per axis (x, y).
#[derive(Clone, Debug, PartialEq)]
pub enum Filter {
    /// Uniform over the pixel (radius 0.5): each sample is a uniform jitter inside it.
    Box,
    /// w(x) = max(0, 1 - |x| / radius) (Mitsuba's tent, pbrt-v4's triangle).
    Tent { radius: Vec2 },
    /// w(x) = max(0, exp(-x^2 / 2 stddev^2) - exp(-radius^2 / 2 stddev^2)); Mitsuba's has
    /// radius = 4 stddev ([`Filter::gaussian`]), pbrt-v4's its own radius (1.5 by default).
    Gaussian { stddev: f32, radius: Vec2 },
    /// Mitchell and Netravali's cubic m(2 x / radius) with parameters B and C (1988); Mitsuba's
    /// `mitchell` has radius 2, its `catmullrom` is B = 0, C = 1/2.
    Mitchell { b: f32, c: f32, radius: Vec2 },
    /// The windowed sinc w(x) = sinc(x) sinc(x / tau) for |x| <= radius, sinc(x) =
    /// sin(pi x) / (pi x) (pbrt-v4's `sinc`); Mitsuba's `lanczos` is radius = tau = lobes.
    Sinc { radius: Vec2, tau: f32 },
}

/// Mitchell and Netravali's piecewise cubic at t (support |t| < 2).
pub fn mitchell_netravali(b: f64, c: f64, t: f64) -> f64 {
    let t = t.abs();
    let (t2, t3) = (t * t, t * t * t);
    if t < 1.0 {
        ((12.0 - 9.0 * b - 6.0 * c) * t3 + (-18.0 + 12.0 * b + 6.0 * c) * t2 + (6.0 - 2.0 * b))
            / 6.0
    } else if t < 2.0 {
        ((-b - 6.0 * c) * t3
            + (6.0 * b + 30.0 * c) * t2
            + (-12.0 * b - 48.0 * c) * t
            + (8.0 * b + 24.0 * c))
            / 6.0
    } else {
        0.0
    }
}

/// sin(pi x) / (pi x), 1 at 0.
pub fn sinc(x: f64) -> f64 {
    let x = x.abs();
    if x < 1e-5 {
        return 1.0;
    }
    let px = std::f64::consts::PI * x;
    px.sin() / px
}

impl Filter {
    /// The tent of one radius on both axes.
    pub fn tent(radius: f32) -> Filter {
        Filter::Tent {
            radius: Vec2::splat(radius),
        }
    }

    /// Mitsuba's gaussian: radius 4 stddev.
    pub fn gaussian(stddev: f32) -> Filter {
        Filter::Gaussian {
            stddev,
            radius: Vec2::splat(4.0 * stddev),
        }
    }

    /// Mitsuba's mitchell: radius 2.
    pub fn mitchell(b: f32, c: f32) -> Filter {
        Filter::Mitchell {
            b,
            c,
            radius: Vec2::splat(2.0),
        }
    }

    /// Mitsuba's catmullrom: Mitchell-Netravali with B = 0, C = 1/2, radius 2.
    pub fn catmull_rom() -> Filter {
        Filter::mitchell(0.0, 0.5)
    }

    /// Mitsuba's lanczos: the sinc windowed by sinc(x / lobes), radius `lobes`.
    pub fn lanczos(lobes: u32) -> Filter {
        Filter::Sinc {
            radius: Vec2::splat(lobes as f32),
            tau: lobes as f32,
        }
    }

    /// Half-widths of the support along x and y, in pixels.
    pub fn radius(&self) -> Vec2 {
        match *self {
            Filter::Box => Vec2::splat(0.5),
            Filter::Tent { radius }
            | Filter::Gaussian { radius, .. }
            | Filter::Mitchell { radius, .. }
            | Filter::Sinc { radius, .. } => radius,
        }
    }

    /// The 1-D profile w(x) along `axis` (0: x, 1: y), not normalised; negative in the
    /// negative lobes of mitchell and sinc.
    pub fn profile(&self, axis: usize, x: f32) -> f64 {
        let r = self.radius()[axis] as f64;
        let x = x as f64;
        match *self {
            Filter::Box => (x.abs() <= 0.5) as u8 as f64,
            Filter::Tent { .. } => (1.0 - x.abs() / r).max(0.0),
            Filter::Gaussian { stddev, .. } => {
                let s2 = 2.0 * (stddev as f64).powi(2);
                ((-x * x / s2).exp() - (-r * r / s2).exp()).max(0.0)
            }
            Filter::Mitchell { b, c, .. } => {
                if x.abs() > r {
                    return 0.0;
                }
                mitchell_netravali(b as f64, c as f64, 2.0 * x / r)
            }
            Filter::Sinc { tau, .. } => {
                if x.abs() > r {
                    return 0.0;
                }
                sinc(x) * sinc(x / tau as f64)
            }
        }
    }

    /// The name and parameters as a scene file writes them.
    pub fn describe(&self) -> String {
        let radius = |r: Vec2| {
            if r.x == r.y {
                format!("{}", r.x)
            } else {
                format!("[{}, {}]", r.x, r.y)
            }
        };
        match self {
            Filter::Box => "box".into(),
            Filter::Tent { radius: r } => format!("tent(radius = {})", radius(*r)),
            Filter::Gaussian { stddev, radius: r } if *r == Vec2::splat(4.0 * stddev) => {
                format!("gaussian(stddev = {stddev})")
            }
            Filter::Gaussian { stddev, radius: r } => {
                format!("gaussian(stddev = {stddev}, radius = {})", radius(*r))
            }
            Filter::Mitchell { b, c, radius: r } => {
                format!("mitchell(b = {b}, c = {c}, radius = {})", radius(*r))
            }
            Filter::Sinc { radius: r, tau } => {
                format!("sinc(radius = {}, tau = {tau})", radius(*r))
            }
        }
    }

    /// Why this filter cannot filter an image (a radius out of (0, 256], a parameter not
    /// finite, or a profile that integrates to zero or less), or None.
    pub fn problem(&self) -> Option<String> {
        let r = self.radius();
        if !(r.x > 0.0 && r.x <= 256.0 && r.y > 0.0 && r.y <= 256.0) {
            return Some(format!("radius {r}: each must be in (0, 256] pixels"));
        }
        let finite = match *self {
            Filter::Box | Filter::Tent { .. } => true,
            Filter::Gaussian { stddev, .. } => stddev > 0.0 && stddev.is_finite(),
            Filter::Mitchell { b, c, .. } => b.is_finite() && c.is_finite(),
            Filter::Sinc { tau, .. } => tau > 0.0 && tau.is_finite(),
        };
        if !finite {
            return Some(format!("{}: a parameter out of range", self.describe()));
        }
        for axis in 0..2 {
            let t = Axis::new(self, axis);
            if !(t.signed_total > 0.0 && t.ratio.is_finite() && t.ratio >= 1.0) {
                return Some(format!(
                    "{}: its profile integrates to {} along {}, which cannot weight an average",
                    self.describe(),
                    t.signed_total,
                    ["x", "y"][axis]
                ));
            }
        }
        None
    }
}

/// A camera sample's place in its pixel: where on the film (pixel units), and the weight
/// its estimate counts with (exactly 1.0 with a positive filter; sign(w) ∫|w| / ∫w with one
/// that has negative lobes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmSample {
    pub film: Vec2,
    pub weight: f32,
}

/// One axis of a filter, tabulated.
#[derive(Clone, Debug)]
struct Axis {
    radius: f32,
    /// The CDF of |w| at the ends of its pieces (cdf[0] = 0, cdf[PIECES] = 1).
    cdf: Vec<f64>,
    /// Per piece, the weight of an offset drawn in it: sign(w) ∫|w| / ∫w (all 1.0 without
    /// negative pieces).
    weight: Vec<f32>,
    /// ∫|w| / ∫w over the tabulated profile (1 for a positive filter).
    ratio: f64,
    /// ∫w (unnormalised), for messages.
    signed_total: f64,
}

const PIECES: usize = 1024;

impl Axis {
    fn new(filter: &Filter, axis: usize) -> Axis {
        let radius = filter.radius()[axis];
        // The box's is uniform (its sampler jitters in the pixel without the table).
        let mut cdf: Vec<f64> = (0..=PIECES).map(|i| i as f64 / PIECES as f64).collect();
        let mut weight = vec![1.0f32; PIECES];
        let (mut ratio, mut signed_total) = (1.0, 1.0);
        if *filter != Filter::Box {
            cdf[0] = 0.0;
            let width = 2.0 * radius / PIECES as f32;
            let mut negative = vec![false; PIECES];
            signed_total = 0.0;
            for i in 0..PIECES {
                let x = -radius + (i as f32 + 0.5) * width;
                let w = filter.profile(axis, x);
                negative[i] = w < 0.0;
                signed_total += w;
                cdf[i + 1] = cdf[i] + w.abs();
            }
            let total = cdf[PIECES];
            cdf.iter_mut().for_each(|c| *c /= total);
            if negative.iter().any(|&n| n) {
                ratio = total / signed_total;
                for (w, &n) in weight.iter_mut().zip(&negative) {
                    *w = if n { -ratio as f32 } else { ratio as f32 };
                }
            }
        }
        Axis {
            radius,
            cdf,
            weight,
            ratio,
            signed_total,
        }
    }

    /// An offset from the pixel's centre along this axis, and its piece, from a uniform
    /// number in [0, 1).
    fn sample(&self, u: f32) -> (f32, usize) {
        let u = u as f64;
        let i = self.cdf.partition_point(|&c| c <= u).clamp(1, PIECES) - 1;
        let (lo, hi) = (self.cdf[i], self.cdf[i + 1]);
        let t = if hi > lo { (u - lo) / (hi - lo) } else { 0.5 };
        let x = -self.radius + (i as f32 + t as f32) * (2.0 * self.radius / PIECES as f32);
        (x, i)
    }

    /// The piece offset `x` lies in (None outside the support).
    fn piece(&self, x: f32) -> Option<usize> {
        if x.abs() >= self.radius {
            return None;
        }
        let width = 2.0 * self.radius / PIECES as f32;
        Some((((x + self.radius) / width) as usize).min(PIECES - 1))
    }

    /// The density of `sample`'s offset `x` (piecewise constant, as tabulated).
    fn pdf(&self, x: f32) -> f32 {
        let Some(i) = self.piece(x) else {
            return 0.0;
        };
        let width = 2.0 * self.radius / PIECES as f32;
        ((self.cdf[i + 1] - self.cdf[i]) / width as f64) as f32
    }
}

/// Places camera samples in a pixel with a filter's density (|w| for a filter with negative
/// lobes), each with its weight.
#[derive(Clone, Debug)]
pub struct FilterSampler {
    filter: Filter,
    axes: [Axis; 2],
    /// Whether the filter has negative lobes (weights other than 1.0).
    signed: bool,
}

impl FilterSampler {
    /// The sampler of `filter`, which should have no [`Filter::problem`] (the scene readers
    /// refuse those).
    pub fn new(filter: Filter) -> FilterSampler {
        let axes = [Axis::new(&filter, 0), Axis::new(&filter, 1)];
        let signed = axes
            .iter()
            .any(|a| a.ratio != 1.0 || a.weight.iter().any(|&w| w != 1.0));
        FilterSampler {
            filter,
            axes,
            signed,
        }
    }

    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// Whether the filter has negative lobes, so that camera samples carry weights other
    /// than one.
    pub fn is_signed(&self) -> bool {
        self.signed
    }

    /// How far (pixels) outside the image the camera samples of its edge pixels reach: the
    /// filter's radius past the pixel's half width. Light paths connected to the camera count
    /// in that margin too ([`crate::camera::Camera::sample_wi`]), so that the edge pixels'
    /// splats cover what their camera samples see.
    pub fn margin(&self) -> f32 {
        (self.axes[0].radius.max(self.axes[1].radius) - 0.5).max(0.0)
    }

    /// The density (per unit film area, pixels^-2) with which [`FilterSampler::sample`]
    /// places a camera sample of pixel (x, y) at `film`: |h_xy(film)| / ∫|h|, for the filter
    /// h_xy around the pixel. It is the density MIS with the camera needs. The box filter's
    /// is 1 inside the pixel.
    pub fn pdf(&self, x: u32, y: u32, film: Vec2) -> f32 {
        match self.filter {
            Filter::Box => (film.x.floor() == x as f32 && film.y.floor() == y as f32) as u8 as f32,
            _ => {
                let d = film - Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                self.axes[0].pdf(d.x) * self.axes[1].pdf(d.y)
            }
        }
    }

    /// The weight [`FilterSampler::sample`] gives a camera sample of pixel (x, y) at `film`:
    /// sign(h_xy(film)) ∫|h| / ∫h, 1.0 with a positive filter (and 0 outside the support).
    pub fn weight(&self, x: u32, y: u32, film: Vec2) -> f32 {
        if !self.signed {
            return (self.pdf(x, y, film) > 0.0) as u8 as f32;
        }
        let d = film - Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        match (self.axes[0].piece(d.x), self.axes[1].piece(d.y)) {
            (Some(i), Some(j)) => self.axes[0].weight[i] * self.axes[1].weight[j],
            _ => 0.0,
        }
    }

    /// Calls `f(x, y, pdf, weight)` for every pixel of a `width` x `height` image whose
    /// filter covers the film point `film`, with pdf = [`FilterSampler::pdf`] > 0 and weight
    /// = [`FilterSampler::weight`]: where a contribution found at `film` by a path from the
    /// lights (a splat) lands. A pixel's value is the integral of the image weighted by the
    /// normalised filter h = pdf * weight; its camera samples estimate it by drawing positions
    /// with density pdf (each with its weight), a splat by weighting with h = pdf * weight:
    /// the same pixel value, so the two kinds of estimate add up (and MIS weighs them against
    /// each other with pdf, the camera's density). With the box filter a splat lands in the
    /// one pixel `film` lies in, with pdf 1 and weight 1.
    pub fn footprint(
        &self,
        film: Vec2,
        width: u32,
        height: u32,
        mut f: impl FnMut(u32, u32, f32, f32),
    ) {
        let r = self.filter.radius();
        let range = |c: f32, r: f32, n: u32| {
            let lo = ((c - 0.5 - r).ceil() as i64).max(0);
            let hi = ((c + r - 0.5).floor() as i64).min(n as i64 - 1);
            lo..=hi
        };
        for y in range(film.y, r.y, height) {
            for x in range(film.x, r.x, width) {
                let pdf = self.pdf(x as u32, y as u32, film);
                if pdf > 0.0 {
                    // A positive filter's weight is 1 wherever its pdf is not 0.
                    let weight = if self.signed {
                        self.weight(x as u32, y as u32, film)
                    } else {
                        1.0
                    };
                    f(x as u32, y as u32, pdf, weight);
                }
            }
        }
    }

    /// Where in pixel (x, y) a camera sample goes, in film coordinates, and its weight, from
    /// two uniform numbers. The box filter is the uniform jitter (x + u.x, y + u.y), exactly;
    /// every positive filter's weight is exactly 1.0. Whoever draws the sample multiplies its
    /// estimate by the weight.
    #[inline]
    pub fn sample(&self, x: u32, y: u32, u: Vec2) -> FilmSample {
        let corner = Vec2::new(x as f32, y as f32);
        match self.filter {
            Filter::Box => FilmSample {
                film: corner + u,
                weight: 1.0,
            },
            _ => {
                let (dx, i) = self.axes[0].sample(u.x);
                let (dy, j) = self.axes[1].sample(u.y);
                FilmSample {
                    film: corner + Vec2::splat(0.5) + Vec2::new(dx, dy),
                    weight: self.axes[0].weight[i] * self.axes[1].weight[j],
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The density integrates to one over the pixel's support, matches a histogram of the
    /// positions `sample` draws, the weights are one for positive filters and signed where
    /// the filter is negative, and `footprint` finds every pixel with pdf > 0.
    #[test]
    fn filter_density_matches_its_samples() {
        for filter in [
            Filter::Box,
            Filter::tent(1.5),
            Filter::gaussian(0.5),
            Filter::mitchell(1.0 / 3.0, 1.0 / 3.0),
            Filter::Sinc {
                radius: Vec2::new(2.0, 1.5),
                tau: 2.0,
            },
        ] {
            let fs = FilterSampler::new(filter.clone());
            let signed = matches!(filter, Filter::Mitchell { .. } | Filter::Sinc { .. });
            assert_eq!(fs.is_signed(), signed, "{filter:?}");
            let (x, y) = (5u32, 7u32);
            let r = filter.radius();
            // Riemann sum over the support.
            let steps = 400;
            let cell = 2.0 * r / steps as f32;
            let mut total = 0.0f64;
            for i in 0..steps {
                for j in 0..steps {
                    let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - r
                        + (Vec2::new(i as f32, j as f32) + 0.5) * cell;
                    total += (fs.pdf(x, y, p) * cell.x * cell.y) as f64;
                }
            }
            assert!((total - 1.0).abs() < 1e-3, "{filter:?}: {total}");
            // Histogram of offsets along each axis against the 1-D density.
            for axis in 0..2 {
                let r = r[axis];
                let mut rng = crate::sampling::Rng::new(&[11]);
                let bins = 10;
                let mut hist = vec![0u32; bins];
                let n = 200_000;
                for _ in 0..n {
                    let s = fs.sample(x, y, rng.next_2d());
                    let d = (s.film - Vec2::new(x as f32 + 0.5, y as f32 + 0.5))[axis];
                    assert_eq!(s.weight, fs.weight(x, y, s.film), "{filter:?}");
                    if !signed {
                        assert_eq!(s.weight, 1.0);
                    }
                    let b = (((d + r) / (2.0 * r)) * bins as f32) as usize;
                    hist[b.min(bins - 1)] += 1;
                }
                for (b, &h) in hist.iter().enumerate() {
                    let w = 2.0 * r / bins as f32;
                    let mut want = 0.0;
                    for k in 0..100 {
                        let d = -r + (b as f32 + (k as f32 + 0.5) / 100.0) * w;
                        want += fs.axes[axis].pdf(d) * w / 100.0;
                    }
                    let got = h as f32 / n as f32;
                    let sigma = (want * (1.0 - want) / n as f32).sqrt();
                    assert!(
                        (got - want).abs() < 5.0 * sigma + 1e-4,
                        "{filter:?} axis {axis} bin {b}: {got} vs {want}"
                    );
                }
            }
            // Every pixel around a point, by brute force, against the footprint.
            let film = Vec2::new(3.3, 2.9);
            let mut found = Vec::new();
            fs.footprint(film, 8, 6, |px, py, h, w| found.push((px, py, h, w)));
            let mut want = Vec::new();
            for py in 0..6 {
                for px in 0..8 {
                    let h = fs.pdf(px, py, film);
                    if h > 0.0 {
                        want.push((px, py, h, fs.weight(px, py, film)));
                    }
                }
            }
            assert_eq!(found, want, "{filter:?}");
            if signed {
                assert!(
                    found.iter().any(|f| f.3 < 0.0),
                    "{filter:?}: no negative weight"
                );
            }
        }
    }
}
