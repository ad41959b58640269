//! Pixel reconstruction filters (Mitsuba's `rfilter`: box, tent, gaussian), applied by
//! filter importance sampling (Ernst et al. 2006): each camera sample of a pixel is placed at
//! an offset from the pixel's centre drawn with the density of the filter, and counts with
//! weight one. The pixel's expected value is then the filter-weighted average of the image
//! around it, what a splatting reconstruction converges to, while every pixel keeps its own
//! samples (images stay independent of the thread count, and a pixel's samples are its own).
//!
//! The filters are separable, w(x, y) = w(x) w(y), and positive, so sampling the two axes
//! apart is exact up to the tabulation of w (1024 pieces over the filter's support).

use glam::Vec2;

/// A pixel filter; radii and deviations in pixels.
#[derive(Clone, Debug, PartialEq)]
pub enum Filter {
    /// Uniform over the pixel (radius 0.5): each sample is a uniform jitter inside it.
    Box,
    /// w(x) = max(0, 1 - |x| / radius).
    Tent { radius: f32 },
    /// w(x) = max(0, exp(-x^2 / 2 stddev^2) - exp(-radius^2 / 2 stddev^2)), radius = 4
    /// stddev (Mitsuba's gaussian).
    Gaussian { stddev: f32 },
}

impl Filter {
    /// Half-width of the support, in pixels.
    pub fn radius(&self) -> f32 {
        match *self {
            Filter::Box => 0.5,
            Filter::Tent { radius } => radius,
            Filter::Gaussian { stddev } => 4.0 * stddev,
        }
    }

    /// The 1-D profile w(x) (not normalised).
    pub fn profile(&self, x: f32) -> f64 {
        let x = x as f64;
        match *self {
            Filter::Box => (x.abs() <= 0.5) as u8 as f64,
            Filter::Tent { radius } => (1.0 - x.abs() / radius as f64).max(0.0),
            Filter::Gaussian { stddev } => {
                let s2 = 2.0 * (stddev as f64).powi(2);
                let r = 4.0 * stddev as f64;
                ((-x * x / s2).exp() - (-r * r / s2).exp()).max(0.0)
            }
        }
    }

    /// The name and parameters as a scene file writes them.
    pub fn describe(&self) -> String {
        match self {
            Filter::Box => "box".into(),
            Filter::Tent { radius } => format!("tent(radius = {radius})"),
            Filter::Gaussian { stddev } => format!("gaussian(stddev = {stddev})"),
        }
    }
}

/// Places camera samples in a pixel with a filter's density.
#[derive(Clone, Debug)]
pub struct FilterSampler {
    filter: Filter,
    radius: f32,
    /// The CDF of the tabulated 1-D profile at the ends of its pieces (cdf[0] = 0,
    /// cdf[PIECES] = 1).
    cdf: Vec<f64>,
}

const PIECES: usize = 1024;

impl FilterSampler {
    pub fn new(filter: Filter) -> FilterSampler {
        let radius = filter.radius();
        let mut cdf = vec![0.0; PIECES + 1];
        if filter != Filter::Box {
            let width = 2.0 * radius / PIECES as f32;
            for i in 0..PIECES {
                let x = -radius + (i as f32 + 0.5) * width;
                cdf[i + 1] = cdf[i] + filter.profile(x);
            }
            let total = cdf[PIECES];
            cdf.iter_mut().for_each(|c| *c /= total);
        }
        FilterSampler {
            filter,
            radius,
            cdf,
        }
    }

    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// An offset from the pixel's centre along one axis, from a uniform number in [0, 1).
    fn sample_1d(&self, u: f32) -> f32 {
        let u = u as f64;
        let i = self.cdf.partition_point(|&c| c <= u).clamp(1, PIECES) - 1;
        let (lo, hi) = (self.cdf[i], self.cdf[i + 1]);
        let t = if hi > lo { (u - lo) / (hi - lo) } else { 0.5 };
        -self.radius + (i as f32 + t as f32) * (2.0 * self.radius / PIECES as f32)
    }

    /// How far (pixels) outside the image the camera samples of its edge pixels reach: the
    /// filter's radius past the pixel's half width. Light paths connected to the camera count
    /// in that margin too ([`crate::camera::Camera::sample_wi`]), so that the edge pixels'
    /// splats cover what their camera samples see.
    pub fn margin(&self) -> f32 {
        (self.radius - 0.5).max(0.0)
    }

    /// The density of `sample_1d`'s offset `x` (piecewise constant, as tabulated).
    fn pdf_1d(&self, x: f32) -> f32 {
        if x.abs() >= self.radius {
            return 0.0;
        }
        if self.filter == Filter::Box {
            return 1.0;
        }
        let width = 2.0 * self.radius / PIECES as f32;
        let i = (((x + self.radius) / width) as usize).min(PIECES - 1);
        ((self.cdf[i + 1] - self.cdf[i]) / width as f64) as f32
    }

    /// The density (per unit film area, pixels^-2) with which [`FilterSampler::film_position`]
    /// places a camera sample of pixel (x, y) at `film`: the filter h_xy(film) each camera
    /// sample of the pixel estimates the image with. The box filter's is 1 inside the pixel.
    pub fn pdf(&self, x: u32, y: u32, film: Vec2) -> f32 {
        match self.filter {
            Filter::Box => (film.x.floor() == x as f32 && film.y.floor() == y as f32) as u8 as f32,
            _ => {
                let d = film - Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                self.pdf_1d(d.x) * self.pdf_1d(d.y)
            }
        }
    }

    /// Calls `f(x, y, h)` for every pixel of a `width` x `height` image whose filter covers the
    /// film point `film`, with h = [`FilterSampler::pdf`] > 0: where a contribution found at
    /// `film` by a path from the lights (a splat) lands. A pixel's value is the integral of
    /// the image weighted by h; its camera samples estimate it by drawing positions with
    /// density h (weight one each), a splat by weighting with h: the same pixel value, so the
    /// two kinds of estimate add up (and MIS may weigh them against each other). With the box
    /// filter a splat lands in the one pixel `film` lies in.
    pub fn footprint(&self, film: Vec2, width: u32, height: u32, mut f: impl FnMut(u32, u32, f32)) {
        let r = self.radius;
        let range = |c: f32, n: u32| {
            let lo = ((c - 0.5 - r).ceil() as i64).max(0);
            let hi = ((c + r - 0.5).floor() as i64).min(n as i64 - 1);
            lo..=hi
        };
        for y in range(film.y, height) {
            for x in range(film.x, width) {
                let h = self.pdf(x as u32, y as u32, film);
                if h > 0.0 {
                    f(x as u32, y as u32, h);
                }
            }
        }
    }

    /// Where in pixel (x, y) a camera sample goes, in film coordinates, from two uniform
    /// numbers. The box filter is the uniform jitter (x + u.x, y + u.y), exactly.
    #[inline]
    pub fn film_position(&self, x: u32, y: u32, u: Vec2) -> Vec2 {
        let corner = Vec2::new(x as f32, y as f32);
        match self.filter {
            Filter::Box => corner + u,
            _ => corner + Vec2::splat(0.5) + Vec2::new(self.sample_1d(u.x), self.sample_1d(u.y)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The density integrates to one over the pixel's support, matches a histogram of the
    /// positions `film_position` draws, and `footprint` finds every pixel with h > 0.
    #[test]
    fn filter_density_matches_its_samples() {
        for filter in [
            Filter::Box,
            Filter::Tent { radius: 1.5 },
            Filter::Gaussian { stddev: 0.5 },
        ] {
            let fs = FilterSampler::new(filter.clone());
            let (x, y) = (5u32, 7u32);
            let r = fs.radius;
            // Riemann sum over the support.
            let steps = 400;
            let cell = 2.0 * r / steps as f32;
            let mut total = 0.0f64;
            for i in 0..steps {
                for j in 0..steps {
                    let p = Vec2::new(
                        x as f32 + 0.5 - r + (i as f32 + 0.5) * cell,
                        y as f32 + 0.5 - r + (j as f32 + 0.5) * cell,
                    );
                    total += (fs.pdf(x, y, p) * cell * cell) as f64;
                }
            }
            assert!((total - 1.0).abs() < 1e-3, "{filter:?}: {total}");
            // Histogram of offsets along x against the 1-D density.
            let mut rng = crate::sampling::Rng::new(&[11]);
            let bins = 10;
            let mut hist = vec![0u32; bins];
            let n = 200_000;
            for _ in 0..n {
                let p = fs.film_position(x, y, rng.next_2d());
                let d = p.x - (x as f32 + 0.5);
                let b = (((d + r) / (2.0 * r)) * bins as f32) as usize;
                hist[b.min(bins - 1)] += 1;
            }
            for (b, &h) in hist.iter().enumerate() {
                let w = 2.0 * r / bins as f32;
                let mut want = 0.0;
                for k in 0..100 {
                    let d = -r + (b as f32 + (k as f32 + 0.5) / 100.0) * w;
                    want += fs.pdf_1d(d) * w / 100.0;
                }
                let got = h as f32 / n as f32;
                let sigma = (want * (1.0 - want) / n as f32).sqrt();
                assert!(
                    (got - want).abs() < 5.0 * sigma + 1e-4,
                    "{filter:?} bin {b}: {got} vs {want}"
                );
            }
            // Every pixel around a point, by brute force, against the footprint.
            let film = Vec2::new(3.3, 2.9);
            let mut found = Vec::new();
            fs.footprint(film, 8, 6, |px, py, h| found.push((px, py, h)));
            let mut want = Vec::new();
            for py in 0..6 {
                for px in 0..8 {
                    let h = fs.pdf(px, py, film);
                    if h > 0.0 {
                        want.push((px, py, h));
                    }
                }
            }
            assert_eq!(found, want, "{filter:?}");
        }
    }
}
