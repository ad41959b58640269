//! Distributions proportional to tabulated weights, sampled by inverting their CDFs: 1-D
//! (lights by power, shapes by area) and 2-D (environment maps).

use super::rng::ONE_MINUS_EPSILON;
use glam::Vec2;

/// A discrete distribution proportional to non-negative weights, sampled by inverting its CDF.
#[derive(Clone, Debug, Default)]
pub struct Distribution1D {
    cdf: Vec<f32>,
    pmf: Vec<f32>,
    total: f32,
}

impl Distribution1D {
    pub fn new(weights: &[f32]) -> Self {
        let total: f64 = weights.iter().map(|&w| w.max(0.0) as f64).sum();
        let mut cdf = Vec::with_capacity(weights.len());
        let mut acc = 0.0f64;
        for &w in weights {
            acc += w.max(0.0) as f64;
            cdf.push(if total > 0.0 {
                (acc / total) as f32
            } else {
                0.0
            });
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let pmf = weights
            .iter()
            .map(|&w| {
                if total > 0.0 {
                    (w.max(0.0) as f64 / total) as f32
                } else {
                    0.0
                }
            })
            .collect();
        Distribution1D {
            cdf,
            pmf,
            total: total as f32,
        }
    }

    pub fn len(&self) -> usize {
        self.pmf.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }
    /// Sum of the weights.
    pub fn total(&self) -> f32 {
        self.total
    }
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// Index i with probability pmf(i); never returns an index of zero weight.
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let mut i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        while self.pmf[i] == 0.0 && i + 1 < self.pmf.len() {
            i += 1;
        }
        while self.pmf[i] == 0.0 && i > 0 {
            i -= 1;
        }
        (i, self.pmf[i])
    }

    /// A point of [0, 1) with density proportional to the weights, each weight spread evenly
    /// over its cell of width 1/len: (the point, its density, the cell).
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, pmf) = self.sample(u);
        let below = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        // Where u falls within the cell's share of the cdf (0 if u landed in a skipped one).
        let offset = if pmf > 0.0 {
            ((u - below) / pmf).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        let n = self.len() as f32;
        (((i as f32 + offset) / n).min(ONE_MINUS_EPSILON), pmf * n, i)
    }
}

/// cells of each row (pbrt's `PiecewiseConstant2D`).
#[derive(Clone, Debug, Default)]
pub struct Distribution2D {
    conditional: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `weights` row by row: `weights[v * nu + u]`, `nv` rows of `nu` cells.
    pub fn new(weights: &[f32], nu: usize, nv: usize) -> Self {
        assert_eq!(weights.len(), nu * nv, "a grid of {nu} x {nv} weights");
        let conditional: Vec<Distribution1D> =
            weights.chunks(nu).map(Distribution1D::new).collect();
        let row_totals: Vec<f32> = conditional.iter().map(Distribution1D::total).collect();
        Distribution2D {
            marginal: Distribution1D::new(&row_totals),
            conditional,
        }
    }

    /// Sum of the weights.
    pub fn total(&self) -> f32 {
        self.marginal.total()
    }

    /// A point of [0, 1)^2 and its density (with respect to area on the square); None when
    /// every weight is zero.
    pub fn sample(&self, u: Vec2) -> Option<(Vec2, f32)> {
        if self.total() <= 0.0 {
            return None;
        }
        let (y, pdf_y, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_x, _) = self.conditional[row].sample_continuous(u.x);
        Some((Vec2::new(x, y), pdf_x * pdf_y))
    }

    /// The density at `p` of [0, 1]^2 (0 outside).
    pub fn pdf(&self, p: Vec2) -> f32 {
        let inside = (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y);
        if self.total() <= 0.0 || !inside {
            return 0.0;
        }
        let (nu, nv) = (self.conditional[0].len(), self.conditional.len());
        let row = ((p.y * nv as f32) as usize).min(nv - 1);
        let col = ((p.x * nu as f32) as usize).min(nu - 1);
        self.marginal.pmf(row) * self.conditional[row].pmf(col) * (nu * nv) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn distribution_never_picks_zero_weight() {
        let d = Distribution1D::new(&[0.0, 1.0, 0.0, 3.0, 0.0]);
        for k in 0..1000 {
            let (i, p) = d.sample(k as f32 / 1000.0);
            assert!(i == 1 || i == 3, "picked {i}");
            assert!(p > 0.0);
        }
        assert_eq!(d.sample(0.9999).0, 3);
    }

    #[test]
    fn distribution2d_density_is_the_normalised_weights() {
        let w = [0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 3.0, 0.5, 4.0];
        let d = Distribution2D::new(&w, 3, 3);
        let total: f32 = w.iter().sum();
        let mut rng = Rng::new(&[3]);
        let mut counts = [0u32; 9];
        let n = 90_000;
        for _ in 0..n {
            let (p, pdf) = d.sample(rng.next_2d()).unwrap();
            let cell = (p.y * 3.0) as usize * 3 + (p.x * 3.0) as usize;
            assert!(w[cell] > 0.0, "sampled a cell of zero weight");
            assert!((pdf - w[cell] / total * 9.0).abs() < 1e-5);
            assert!((d.pdf(p) - pdf).abs() < 1e-5);
            counts[cell] += 1;
        }
        for (c, w) in counts.iter().zip(w) {
            let want = w / total * n as f32;
            assert!(
                (*c as f32 - want).abs() < 5.0 * want.sqrt().max(1.0),
                "{c} vs {want}"
            );
        }
        assert!(
            Distribution2D::new(&[0.0; 4], 2, 2)
                .sample(Vec2::splat(0.5))
                .is_none()
        );
    }
}
