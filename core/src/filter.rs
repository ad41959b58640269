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
