//! Microfacet normal distributions as Mitsuba 3 defines them (its `MicrofacetDistribution`):
//! Beckmann and GGX (Trowbridge-Reitz), anisotropic with roughnesses alpha_u along x and
//! alpha_v along y, and the sampling of visible normals (Heitz and d'Eon 2014) with Jakob's
//! numerical inversion for Beckmann and Heitz's 2018 routine for GGX; and Mitsuba 0.6's
//! third, Phong's (anisotropic: Ashikhmin and Shirley's), whose normals are sampled from
//! D(m) cos(theta_m) as 0.6 samples them (it has no visible-normal routine).
//!
//! Everything is in the local shading frame: z is the shading normal. Directions point away
//! from the surface. As in Mitsuba, Smith's G1 of the Beckmann distribution is its rational
//! approximation (< 0.35% relative error), so for Beckmann the visible-normal pdf integrates
//! to one only within that error while the sampling routine is exact.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MicrofacetKind {
    /// Gaussian random slopes (Beckmann 1963).
    Beckmann,
    /// GGX / Trowbridge-Reitz: long tails (Walter et al. 2007).
    Ggx,
    /// Phong's cos^e (Walter et al. 2007), e = 2 / alpha^2 - 2; anisotropic, Ashikhmin and
    /// Shirley's (2000) with e interpolated in phi (Mitsuba 0.6's `phong` and `as`). Its G1 is
    /// Beckmann's of the same alpha, as in Mitsuba 0.6.
    Phong,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    pub kind: MicrofacetKind,
    /// Roughness along the tangent (x) direction.
    pub alpha_u: f32,
    /// Roughness along the bitangent (y) direction.
    pub alpha_v: f32,
}

impl Microfacet {
    /// Mitsuba clamps roughness to this: below it D no longer fits a float.
    pub const MIN_ALPHA: f32 = 1e-4;

    pub fn new(kind: MicrofacetKind, alpha_u: f32, alpha_v: f32) -> Self {
        // max() also maps NaN to the minimum.
        Microfacet {
            kind,
            alpha_u: alpha_u.max(Self::MIN_ALPHA),
            alpha_v: alpha_v.max(Self::MIN_ALPHA),
        }
    }

    pub fn isotropic(kind: MicrofacetKind, alpha: f32) -> Self {
        Self::new(kind, alpha, alpha)
    }

    pub fn is_isotropic(&self) -> bool {
        self.alpha_u == self.alpha_v
    }

    /// The smaller roughness: how sharp the lobe is in its sharpest direction, which is what
    /// decides whether a density estimate would blur it.
    pub fn roughness(&self) -> f32 {
        self.alpha_u.min(self.alpha_v)
    }

    /// The normal distribution D(m), normalised so that the projected microfacet area is one:
    /// the integral of D(m) cos(theta_m) over the hemisphere is 1. Zero below the surface.
    pub fn d(&self, m: Vec3) -> f32 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let cos2 = m.z * m.z;
        let slope2 = (m.x / au).powi(2) + (m.y / av).powi(2);
        let d = match self.kind {
            MicrofacetKind::Beckmann => (-slope2 / cos2).exp() / (PI * au * av * cos2 * cos2),
            MicrofacetKind::Ggx => 1.0 / (PI * au * av * (slope2 + cos2).powi(2)),
            MicrofacetKind::Phong => {
                if m.z <= 0.0 {
                    return 0.0;
                }
                let (eu, ev) = self.phong_exponents();
                (eu + 2.0).sqrt() * (ev + 2.0).sqrt() / (2.0 * PI)
                    * m.z.powf(self.phong_exponent(m))
            }
        };
        // Mitsuba's cut-off: tiny values only make trouble further on (and NaN fails it too).
        if d * m.z > 1e-20 { d } else { 0.0 }
    }

    /// Smith's masking function G1(v, m): the fraction of microfacets with normal m visible
    /// from v. Zero when v sees the back of the microfacet (v.m and v.z of opposite signs).
    pub fn smith_g1(&self, v: Vec3, m: Vec3) -> f32 {
        let facing = v.dot(m) * v.z;
        if facing <= 0.0 || facing.is_nan() {
            return 0.0;
        }
        let xy_alpha2 = (self.alpha_u * v.x).powi(2) + (self.alpha_v * v.y).powi(2);
        if xy_alpha2 == 0.0 {
            return 1.0; // normal incidence: nothing shadows
        }
        // tan^2 of v's angle to the normal, in the stretched (alpha = 1) configuration.
        let tan2 = xy_alpha2 / (v.z * v.z);
        match self.kind {
            MicrofacetKind::Beckmann | MicrofacetKind::Phong => {
                // Mitsuba's rational fit of 2 / (1 + Lambda(a)), a = 1 / tan (Walter et al.
                // 2007, eq. 27), rather than the erf form.
                let a = 1.0 / tan2.sqrt();
                if a >= 1.6 {
                    1.0
                } else {
                    (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
                }
            }
            MicrofacetKind::Ggx => 2.0 / (1.0 + (1.0 + tan2).sqrt()),
        }
    }

    /// Separable shadowing-masking G(wi, wo, m) = G1(wi, m) G1(wo, m).
    pub fn g(&self, wi: Vec3, wo: Vec3, m: Vec3) -> f32 {
        self.smith_g1(wi, m) * self.smith_g1(wo, m)
    }

    /// Density of visible normals seen from `wi` (wi.z > 0), D_wi(m) = G1(wi, m) max(0, wi.m)
    /// D(m) / cos(theta_i): the solid-angle pdf of [`Microfacet::sample`]. Phong's: D(m)
    /// cos(theta_m), whatever `wi` sees.
    pub fn pdf(&self, wi: Vec3, m: Vec3) -> f32 {
        if wi.z <= 0.0 || !wi.is_finite() || !m.is_finite() {
            return 0.0;
        }
        if !self.samples_visible_normals() {
            return self.d(m) * m.z;
        }
        self.d(m) * self.smith_g1(wi, m) * wi.dot(m).abs() / wi.z
    }

    /// Whether [`Microfacet::sample`] draws the normals visible from wi (all but Phong's):
    /// then the lobes' densities are D G1(wo) / (4 cos_o) and their sample weights reduce to
    /// G1(wi) times the rest; Phong's normals come from D cos theta_m, and nothing cancels.
    #[inline]
    pub fn samples_visible_normals(&self) -> bool {
        self.kind != MicrofacetKind::Phong
    }

    /// Phong's exponents along x and y: 2 / alpha^2 - 2 (Mitsuba 0.6), at least 0.
    #[inline]
    fn phong_exponents(&self) -> (f32, f32) {
        let e = |a: f32| (2.0 / (a * a) - 2.0).max(0.0);
        (e(self.alpha_u), e(self.alpha_v))
    }

    /// Ashikhmin and Shirley's exponent towards `m`: e_u cos^2 phi + e_v sin^2 phi.
    #[inline]
    fn phong_exponent(&self, m: Vec3) -> f32 {
        let (eu, ev) = self.phong_exponents();
        let sin2 = m.x * m.x + m.y * m.y;
        if self.is_isotropic() || sin2 <= f32::MIN_POSITIVE {
            return eu;
        }
        (eu * m.x * m.x + ev * m.y * m.y) / sin2
    }

    /// A Phong normal with density D(m) cos(theta_m) (Mitsuba 0.6's `sampleAll`): phi by
    /// quadrant from tan phi = sqrt((e_u + 2) / (e_v + 2)) tan(pi u / 2), then cos theta =
    /// u^(1 / (e + 2)) with e that phi's exponent.
    fn sample_phong(&self, u: Vec2) -> Vec3 {
        let (eu, ev) = self.phong_exponents();
        let (phi, e) = if self.is_isotropic() {
            (2.0 * PI * u.y, eu)
        } else {
            let first = |u1: f32| {
                let phi = (((eu + 2.0) / (ev + 2.0)).sqrt() * (PI * u1 * 0.5).tan()).atan();
                let (s, c) = phi.sin_cos();
                (phi, eu * c * c + ev * s * s)
            };
            let v = u.y;
            if v < 0.25 {
                first(4.0 * v)
            } else if v < 0.5 {
                let (p, e) = first(4.0 * (0.5 - v));
                (PI - p, e)
            } else if v < 0.75 {
                let (p, e) = first(4.0 * (v - 0.5));
                (PI + p, e)
            } else {
                let (p, e) = first(4.0 * (1.0 - v));
                (2.0 * PI - p, e)
            }
        };
        let cos_theta = u.x.powf(1.0 / (e + 2.0));
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (s, c) = phi.sin_cos();
        Vec3::new(sin_theta * c, sin_theta * s, cos_theta)
    }

    /// Samples a microfacet normal visible from `wi` (wi.z > 0) with density D_wi(m): stretch
    /// wi to the alpha = 1 configuration, sample the slopes of the normals it sees there,
    /// rotate and unstretch them. Returns (m, pdf); pdf is zero when nothing can be sampled
    /// (wi at or below the horizon, degenerate input).
    pub fn sample(&self, wi: Vec3, u: Vec2) -> (Vec3, f32) {
        match self.sample_normal(wi, u) {
            Some(m) => (m, self.pdf(wi, m)),
            None => (Vec3::Z, 0.0),
        }
    }

    /// [`Microfacet::sample`] without the pdf.
    fn sample_normal(&self, wi: Vec3, u: Vec2) -> Option<Vec3> {
        let frame = self.stretched_frame(wi)?;
        let slope = match self.kind {
            MicrofacetKind::Beckmann => Vec2::new(
                beckmann_visible_slope_x(frame.0, u.x),
                beckmann_slope_y(u.y),
            ),
            MicrofacetKind::Ggx => ggx_visible_slope(frame.0, u),
            MicrofacetKind::Phong => {
                let m = self.sample_phong(u);
                return m.is_finite().then_some(m);
            }
        };
        self.unstretch(frame, slope)
    }

    /// The normals [`Microfacet::sample`] gives from `wi` at every point (nodes[i], nodes[j])
    /// of a grid of sample coordinates, passed to `f(i, j, m, w)` with the weight w that makes
    /// the grid's rule an expectation over the visible normals (for integrals over the sample
    /// space): 1 where the normals sampled are the visible ones, D_wi(m) / (D(m) cos theta_m)
    /// for Phong's. For Beckmann the x slope depends on u.x only and the y slope on u.y only,
    /// so each is computed once per row or column: the inversion is what costs.
    pub(crate) fn for_each_normal_on_grid(
        &self,
        wi: Vec3,
        nodes: &[f32],
        mut f: impl FnMut(usize, usize, Vec3, f32),
    ) {
        let Some(frame) = self.stretched_frame(wi) else {
            return;
        };
        let (xs, ys): (Vec<f32>, Vec<f32>) = match self.kind {
            MicrofacetKind::Beckmann => nodes
                .iter()
                .map(|&u| (beckmann_visible_slope_x(frame.0, u), beckmann_slope_y(u)))
                .unzip(),
            MicrofacetKind::Ggx | MicrofacetKind::Phong => (Vec::new(), Vec::new()),
        };
        for (i, &ux) in nodes.iter().enumerate() {
            for (j, &uy) in nodes.iter().enumerate() {
                let slope = match self.kind {
                    MicrofacetKind::Beckmann => Vec2::new(xs[i], ys[j]),
                    MicrofacetKind::Ggx => ggx_visible_slope(frame.0, Vec2::new(ux, uy)),
                    MicrofacetKind::Phong => {
                        let m = self.sample_phong(Vec2::new(ux, uy));
                        if m.is_finite() && m.z > 0.0 {
                            let w = self.smith_g1(wi, m) * wi.dot(m).max(0.0) / (wi.z * m.z);
                            f(i, j, m, w);
                        }
                        continue;
                    }
                };
                if let Some(m) = self.unstretch(frame, slope) {
                    f(i, j, m, 1.0);
                }
            }
        }
    }

    /// wi stretched to the alpha = 1 configuration: (cos theta, sin phi, cos phi). None when
    /// wi is at or below the horizon.
    fn stretched_frame(&self, wi: Vec3) -> Option<(f32, f32, f32)> {
        if wi.z <= 0.0 || !wi.is_finite() {
            return None;
        }
        let wi_s = Vec3::new(self.alpha_u * wi.x, self.alpha_v * wi.y, wi.z).normalize();
        let sin_theta = (1.0 - wi_s.z * wi_s.z).max(0.0).sqrt();
        Some(if sin_theta > 1e-6 {
            (
                wi_s.z,
                (wi_s.y / sin_theta).clamp(-1.0, 1.0),
                (wi_s.x / sin_theta).clamp(-1.0, 1.0),
            )
        } else {
            (wi_s.z, 0.0, 1.0)
        })
    }

    /// The normal of the slope sampled in the stretched frame, rotated back to wi's azimuth
    /// and unstretched.
    fn unstretch(&self, (_, sin_phi, cos_phi): (f32, f32, f32), s: Vec2) -> Option<Vec3> {
        let slope = Vec2::new(
            (cos_phi * s.x - sin_phi * s.y) * self.alpha_u,
            (sin_phi * s.x + cos_phi * s.y) * self.alpha_v,
        );
        let m = Vec3::new(-slope.x, -slope.y, 1.0).normalize();
        m.is_finite().then_some(m)
    }
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Mitsuba's `quad::gauss_legendre`): the nodes
/// by Newton's method on P_n in f64, for integrals over the sample space of the visible
/// normals ([`Microfacet::for_each_normal_on_grid`]: the rough coat's tables) and the tests'
/// integrals of pdfs.
pub(crate) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let legendre = |x: f64| {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
            p0 = p1;
            p1 = p2;
        }
        // P_n and its derivative.
        (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
    };
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            let (_, dp) = legendre(x);
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Slopes of the visible normals of the GGX surface with alpha = 1 seen at cos(theta_i), in a
/// frame where wi lies in the xz plane (Heitz 2018: a uniform point on the disc, squeezed onto
/// the visible half of the projected hemisphere, lifted back onto it; Mitsuba's variant).
fn ggx_visible_slope(cos_theta_i: f32, u: Vec2) -> Vec2 {
    let p = crate::sampling::concentric_disc(u);
    let s = 0.5 * (1.0 + cos_theta_i);
    let x = p.x;
    let y = (1.0 - s) * (1.0 - x * x).max(0.0).sqrt() + s * p.y;
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    let sin_theta_i = (1.0 - cos_theta_i * cos_theta_i).max(0.0).sqrt();
    let norm = 1.0 / (sin_theta_i * y + cos_theta_i * z);
    Vec2::new((cos_theta_i * y - sin_theta_i * z) * norm, x * norm)
}

/// The x slope (in the plane of wi) of the visible normals of the Beckmann surface with
/// alpha = 1 (Jakob 2014, "An improved visible normal sampling routine for the Beckmann
/// distribution"): Newton's method on its CDF, parameterised by erf(slope) so that it is
/// nearly linear. In f64, since the CDF is flat in its tails.
fn beckmann_visible_slope_x(cos_theta_i: f32, u: f32) -> f32 {
    let cos = cos_theta_i as f64;
    let tan = (1.0 - cos * cos).max(0.0).sqrt() / cos;
    let cot = 1.0 / tan;
    let inv_sqrt_pi = 1.0 / std::f64::consts::PI.sqrt();
    let u = (u as f64).clamp(1e-6, 1.0 - 1e-6);
    // x = erf(slope) lies in (-1, erf(cot)); the unnormalised CDF is 1 + x + tan e^(-s^2) /
    // sqrt(pi). The initial guess is exact for grazing incidence.
    let x_max = erf(cot);
    let mut x = x_max - (x_max + 1.0) * erf((-u.ln()).sqrt());
    let target = u * (1.0 + x_max + inv_sqrt_pi * tan * (-cot * cot).exp());
    for _ in 0..3 {
        let slope = erfinv(x);
        let value = 1.0 + x + inv_sqrt_pi * tan * (-slope * slope).exp() - target;
        let derivative = 1.0 - slope * tan;
        x -= value / derivative;
        x = x.clamp(-1.0 + 1e-12, 1.0 - 1e-12);
    }
    erfinv(x) as f32
}

/// The y slope of the Beckmann surface with alpha = 1: Gaussian, whatever wi.
fn beckmann_slope_y(u: f32) -> f32 {
    erfinv(2.0 * (u as f64).clamp(1e-6, 1.0 - 1e-6) - 1.0) as f32
}

/// The error function, from the Chebyshev fit of erfc in Numerical Recipes (relative error of
/// erfc below 1.2e-7 everywhere).
fn erf(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398
                                + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277))))))));
    let erfc = t * (-z * z + poly).exp();
    if x >= 0.0 { 1.0 - erfc } else { erfc - 1.0 }
}

/// The inverse error function: Giles' single-precision approximation ("Approximating the
/// erfinv function", GPU Computing Gems, 2011; relative error about 1e-7, as Mitsuba's).
fn erfinv(y: f64) -> f64 {
    let y = y.clamp(-1.0 + 1e-15, 1.0 - 1e-15);
    let w = -((1.0 - y) * (1.0 + y)).ln();
    if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.81022636e-08;
        for c in [
            3.43273939e-07,
            -3.5233877e-06,
            -4.39150654e-06,
            0.00021858087,
            -0.00125372503,
            -0.00417768164,
            0.246640727,
            1.50140941,
        ] {
            p = c + p * w;
        }
        p * y
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -0.000200214257;
        for c in [
            0.000100950558,
            0.00134934322,
            -0.00367342844,
            0.00573950773,
            -0.0076224613,
            0.00943887047,
            1.00167406,
            2.83297682,
        ] {
            p = c + p * w;
        }
        p * y
    }
}

/// Pearson's chi-square goodness-of-fit test of a direction sampler against its pdf over the
/// sphere, in the manner of pbrt's and Mitsuba's tests (shared with `glossy`'s tests).
#[cfg(test)]
pub(crate) mod chi2 {
    use super::gauss_legendre;
    use crate::sampling::Rng;
    use glam::Vec3;
    use std::f64::consts::{PI, TAU};

    /// Cells in cos(theta) (over [-1, 1]) and phi.
    pub const N_COS: usize = 16;
    pub const N_PHI: usize = 32;
    /// Cells expecting fewer samples are pooled.
    const MIN_EXPECTED: f64 = 5.0;

    /// What a sampler produced: a direction with a density, or something the pdf does not
    /// cover (a delta lobe, or no sample), counted in a cell of its own.
    pub enum Outcome {
        Dir(Vec3),
        Other,
    }

    fn cell(v: Vec3) -> Option<usize> {
        if !v.is_finite() {
            return None;
        }
        let c = ((v.z as f64 + 1.0) * 0.5 * N_COS as f64).floor() as isize;
        let mut phi = (v.y as f64).atan2(v.x as f64);
        if phi < 0.0 {
            phi += TAU;
        }
        let p = (phi / TAU * N_PHI as f64).floor() as isize;
        Some(
            c.clamp(0, N_COS as isize - 1) as usize * N_PHI
                + p.clamp(0, N_PHI as isize - 1) as usize,
        )
    }

    /// The integral of `pdf` over each cell (in (cos theta, phi), whose Jacobian is one), by
    /// adaptive 3 x 3 Gauss-Legendre: a rectangle is split in four (at least MIN_DEPTH times) until the quarters agree
    /// with the whole to an absolute 1e-7 (narrow lobes, the pole, kinks at the horizon).
    pub fn integrate_cells(pdf: &dyn Fn(Vec3) -> f64) -> Vec<f64> {
        const MIN_DEPTH: u32 = 3;
        const MAX_DEPTH: u32 = 9;
        let gl = gauss_legendre(3);
        let rule = |c0: f64, c1: f64, p0: f64, p1: f64| {
            let mut s = 0.0;
            for &(xa, wa) in &gl {
                let cos = c0 + 0.5 * (c1 - c0) * (xa + 1.0);
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                for &(xb, wb) in &gl {
                    let phi = p0 + 0.5 * (p1 - p0) * (xb + 1.0);
                    let v = Vec3::new(
                        (sin * phi.cos()) as f32,
                        (sin * phi.sin()) as f32,
                        cos as f32,
                    );
                    s += wa * wb * pdf(v);
                }
            }
            s * 0.25 * (c1 - c0) * (p1 - p0)
        };
        fn adapt(
            rule: &dyn Fn(f64, f64, f64, f64) -> f64,
            (c0, c1, p0, p1): (f64, f64, f64, f64),
            whole: f64,
            tol: f64,
            depth: u32,
        ) -> f64 {
            let (cm, pm) = (0.5 * (c0 + c1), 0.5 * (p0 + p1));
            let quads = [
                (c0, cm, p0, pm),
                (cm, c1, p0, pm),
                (c0, cm, pm, p1),
                (cm, c1, pm, p1),
            ];
            let parts = quads.map(|q| rule(q.0, q.1, q.2, q.3));
            let sum: f64 = parts.iter().sum();
            // The first levels always split: a lobe narrower than the nodes' spacing (a sliver
            // at the pole) would make both rules agree on zero.
            if depth == 0 || (depth <= MAX_DEPTH - MIN_DEPTH && (sum - whole).abs() < tol) {
                return sum;
            }
            quads
                .iter()
                .zip(parts)
                .map(|(&q, part)| adapt(rule, q, part, 0.5 * tol, depth - 1))
                .sum()
        }
        let mut out = vec![0.0; N_COS * N_PHI];
        for ci in 0..N_COS {
            for pi in 0..N_PHI {
                let r = (
                    -1.0 + 2.0 * ci as f64 / N_COS as f64,
                    -1.0 + 2.0 * (ci + 1) as f64 / N_COS as f64,
                    TAU * pi as f64 / N_PHI as f64,
                    TAU * (pi + 1) as f64 / N_PHI as f64,
                );
                let whole = rule(r.0, r.1, r.2, r.3);
                out[ci * N_PHI + pi] = adapt(&rule, r, whole, 1e-7, MAX_DEPTH);
            }
        }
        out
    }

    /// Regularised upper incomplete gamma Q(a, x) (series / continued fraction, as in
    /// Numerical Recipes), for the chi-square survival function.
    fn gamma_q(a: f64, x: f64) -> f64 {
        if x <= 0.0 {
            return 1.0;
        }
        let ln_gamma = |z: f64| {
            // Lanczos, g = 7, n = 9.
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
            let z = z - 1.0;
            let t = z + 7.5;
            let mut s = C[0];
            for (i, &c) in C.iter().enumerate().skip(1) {
                s += c / (z + i as f64);
            }
            0.5 * TAU.ln() + (z + 0.5) * t.ln() - t + s.ln()
        };
        let front = (-x + a * x.ln() - ln_gamma(a)).exp();
        if x < a + 1.0 {
            let (mut ap, mut del) = (a, 1.0 / a);
            let mut sum = del;
            for _ in 0..10_000 {
                ap += 1.0;
                del *= x / ap;
                sum += del;
                if del.abs() < sum.abs() * 1e-15 {
                    break;
                }
            }
            (1.0 - sum * front).max(0.0)
        } else {
            let tiny = 1e-300;
            let mut b = x + 1.0 - a;
            let mut c = 1.0 / tiny;
            let mut d = 1.0 / b;
            let mut h = d;
            for i in 1..10_000 {
                let an = -(i as f64) * (i as f64 - a);
                b += 2.0;
                d = an * d + b;
                if d.abs() < tiny {
                    d = tiny;
                }
                c = b + an / c;
                if c.abs() < tiny {
                    c = tiny;
                }
                d = 1.0 / d;
                let del = d * c;
                h *= del;
                if (del - 1.0).abs() < 1e-15 {
                    break;
                }
            }
            front * h
        }
    }

    /// Draws `n` samples, bins them, and panics unless they fit `pdf` at significance
    /// `alpha`. The mass the pdf does not cover (1 minus its integral) is the expected count
    /// of the `Other` cell.
    pub fn assert_fits(
        name: &str,
        n: usize,
        seed: u64,
        mut sample: impl FnMut(&mut Rng) -> Outcome,
        pdf: &dyn Fn(Vec3) -> f64,
        alpha: f64,
    ) {
        let mut observed = vec![0u64; N_COS * N_PHI + 1];
        let mut rng = Rng::new(&[seed]);
        for _ in 0..n {
            match sample(&mut rng) {
                Outcome::Dir(v) => match cell(v) {
                    Some(i) => observed[i] += 1,
                    None => panic!("{name}: sampled a non-finite direction {v}"),
                },
                Outcome::Other => observed[N_COS * N_PHI] += 1,
            }
        }
        let mut expected: Vec<f64> = integrate_cells(pdf).iter().map(|p| p * n as f64).collect();
        let covered: f64 = expected.iter().sum::<f64>() / n as f64;
        assert!(
            covered < 1.0 + 2e-3,
            "{name}: the pdf integrates to {covered} > 1"
        );
        expected.push((1.0 - covered).max(0.0) * n as f64);

        let mut order: Vec<usize> = (0..expected.len()).collect();
        order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
        let (mut pool_o, mut pool_e, mut stat, mut cells) = (0.0, 0.0, 0.0, 0usize);
        let mut worst = (0usize, 0.0f64);
        for &i in &order {
            let (o, e) = (observed[i] as f64, expected[i]);
            if e < MIN_EXPECTED || (pool_e > 0.0 && pool_e < MIN_EXPECTED) {
                pool_o += o;
                pool_e += e;
            } else {
                let c = (o - e) * (o - e) / e;
                if c > worst.1 {
                    worst = (i, c);
                }
                stat += c;
                cells += 1;
            }
        }
        if pool_e > 0.0 {
            stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
            cells += 1;
        } else {
            assert!(
                pool_o == 0.0,
                "{name}: {pool_o} samples where the pdf is zero"
            );
        }
        assert!(cells >= 2, "{name}: too few cells");
        let dof = (cells - 1) as f64;
        let p = gamma_q(0.5 * dof, 0.5 * stat);
        assert!(
            p >= alpha,
            "{name}: samples do not follow the pdf: chi2 = {stat:.1}, dof = {dof}, p = {p:.2e} < {alpha:.2e}; \
             worst cell {} observed {} expected {:.1}; other: observed {} expected {:.1}",
            worst.0,
            observed[worst.0],
            expected[worst.0],
            observed[N_COS * N_PHI],
            expected[N_COS * N_PHI]
        );
    }

    /// Exact G1(v) over the G1 the code uses: 1 for GGX; for Beckmann, whose G1 is Mitsuba's
    /// rational fit, the erf form 1 / (1 + Lambda) over the fit. A visible-normal pdf times
    /// this is the exact density of the (exact) sampling routine: the fit only rescales it.
    pub fn g1_correction(md: &super::Microfacet, v: Vec3) -> f64 {
        if md.kind != super::MicrofacetKind::Beckmann || v.z <= 0.0 {
            return 1.0;
        }
        let xy =
            (md.alpha_u as f64 * v.x as f64).powi(2) + (md.alpha_v as f64 * v.y as f64).powi(2);
        if xy == 0.0 {
            return 1.0;
        }
        let a = v.z as f64 / xy.sqrt();
        let lambda = 0.5 * (super::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * PI.sqrt());
        1.0 / (1.0 + lambda) / md.smith_g1(v, glam::Vec3::Z) as f64
    }

    /// Sidak: the significance of each of `tests` tests for a family-wise significance of 1%.
    pub fn sidak(tests: usize) -> f64 {
        1.0 - 0.99f64.powf(1.0 / tests as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::chi2::{self, Outcome};
    use super::*;
    use crate::sampling::Rng;

    const DISTRIBUTIONS: [(MicrofacetKind, f32, f32); 9] = [
        (MicrofacetKind::Beckmann, 0.1, 0.1),
        (MicrofacetKind::Beckmann, 0.5, 0.5),
        (MicrofacetKind::Beckmann, 0.15, 0.6),
        (MicrofacetKind::Ggx, 0.1, 0.1),
        (MicrofacetKind::Ggx, 0.5, 0.5),
        (MicrofacetKind::Ggx, 0.6, 0.15),
        (MicrofacetKind::Phong, 0.1, 0.1),
        (MicrofacetKind::Phong, 0.5, 0.5),
        (MicrofacetKind::Phong, 0.15, 0.6),
    ];
    /// Viewing directions: normal, oblique, grazing, off-axis in phi.
    fn views() -> [Vec3; 3] {
        [
            Vec3::Z,
            Vec3::new(0.6, 0.3, 0.7).normalize(),
            Vec3::new(-0.3, 0.95, 0.05).normalize(),
        ]
    }

    #[test]
    fn erf_and_erfinv_agree_with_known_values() {
        // erf(0.5), erf(1), erf(2) to 10 digits.
        for (x, e) in [
            (0.5, 0.5204998778),
            (1.0, 0.8427007929),
            (2.0, 0.9953222650),
        ] {
            assert!((erf(x) - e).abs() < 2e-7, "erf({x}) = {}", erf(x));
            assert!((erf(-x) + e).abs() < 2e-7);
        }
        for y in [-0.999999, -0.9, -0.3, 0.0, 0.2, 0.7, 0.99, 0.999999] {
            assert!((erf(erfinv(y)) - y).abs() < 1e-6, "{y}");
        }
    }

    /// Integral over the hemisphere of f(m), in (cos theta, phi) with Gauss-Legendre cells.
    fn hemisphere_integral(f: &dyn Fn(Vec3) -> f64) -> f64 {
        chi2::integrate_cells(&|m| if m.z > 0.0 { f(m) } else { 0.0 })
            .iter()
            .sum()
    }

    #[test]
    fn projected_area_is_one() {
        for (kind, au, av) in DISTRIBUTIONS {
            let md = Microfacet::new(kind, au, av);
            let i = hemisphere_integral(&|m| md.d(m) as f64 * m.z as f64);
            assert!((i - 1.0).abs() < 2e-3, "{md:?}: {i}");
        }
    }

    #[test]
    fn visible_normal_pdf_integrates_to_one() {
        for (kind, au, av) in DISTRIBUTIONS {
            let md = Microfacet::new(kind, au, av);
            for wi in views() {
                let i = hemisphere_integral(&|m| md.pdf(wi, m) as f64);
                // Beckmann's G1 is Mitsuba's rational fit, within 0.35% of the exact one.
                let tol = match kind {
                    MicrofacetKind::Beckmann => 6e-3,
                    MicrofacetKind::Ggx | MicrofacetKind::Phong => 2e-3,
                };
                assert!((i - 1.0).abs() < tol, "{md:?} wi {wi}: {i}");
            }
        }
    }

    #[test]
    fn ggx_g1_is_exact_and_beckmann_g1_close_to_exact() {
        // Exact Lambda for Beckmann: (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)).
        let md = Microfacet::isotropic(MicrofacetKind::Beckmann, 0.4);
        for cos in [0.05f32, 0.2, 0.5, 0.9] {
            let v = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let a = (cos / (1.0 - cos * cos).sqrt() / 0.4) as f64;
            let lambda =
                0.5 * (erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt());
            let exact = 1.0 / (1.0 + lambda);
            let g1 = md.smith_g1(v, Vec3::Z) as f64;
            assert!((g1 - exact).abs() < 4e-3 * exact, "{cos}: {g1} vs {exact}");
        }
        // GGX: 2 / (1 + sqrt(1 + alpha^2 tan^2)).
        let md = Microfacet::new(MicrofacetKind::Ggx, 0.3, 0.7);
        let v = Vec3::new(0.4, 0.5, 0.3).normalize();
        let tan2 = (0.3f32 * v.x).powi(2) / (v.z * v.z) + (0.7f32 * v.y).powi(2) / (v.z * v.z);
        let exact = 2.0 / (1.0 + (1.0 + tan2).sqrt());
        assert!((md.smith_g1(v, Vec3::Z) - exact).abs() < 1e-6);
        // Back-facing microfacets are invisible.
        assert_eq!(md.smith_g1(v, -Vec3::X), 0.0);
    }

    #[test]
    fn sampled_normals_follow_the_visible_normal_pdf() {
        let alpha = chi2::sidak(DISTRIBUTIONS.len() * views().len());
        for (k, (kind, au, av)) in DISTRIBUTIONS.into_iter().enumerate() {
            let md = Microfacet::new(kind, au, av);
            for (j, wi) in views().into_iter().enumerate() {
                let mut pdf_mismatch = 0.0f32;
                chi2::assert_fits(
                    &format!("{md:?} wi {wi}"),
                    200_000,
                    (k * 10 + j) as u64,
                    |rng: &mut Rng| {
                        let (m, pdf) = md.sample(wi, rng.next_2d());
                        if pdf <= 0.0 {
                            return Outcome::Other;
                        }
                        let p = md.pdf(wi, m);
                        pdf_mismatch = pdf_mismatch.max((pdf - p).abs() / p);
                        Outcome::Dir(m)
                    },
                    &|m| md.pdf(wi, m) as f64 * chi2::g1_correction(&md, wi),
                    alpha,
                );
                assert!(pdf_mismatch < 1e-4, "{md:?}: sample's pdf {pdf_mismatch}");
            }
        }
    }

    #[test]
    fn degenerate_input_gives_no_nan() {
        let md = Microfacet::isotropic(MicrofacetKind::Ggx, 0.0);
        assert_eq!(md.alpha_u, Microfacet::MIN_ALPHA);
        for kind in [
            MicrofacetKind::Beckmann,
            MicrofacetKind::Ggx,
            MicrofacetKind::Phong,
        ] {
            let md = Microfacet::new(kind, f32::NAN, 0.3);
            for wi in [Vec3::ZERO, -Vec3::Z, Vec3::X, Vec3::splat(f32::NAN)] {
                let (m, pdf) = md.sample(wi, Vec2::new(0.3, 0.7));
                assert!(m.is_finite() && pdf == 0.0, "{wi}: {m} {pdf}");
            }
            for u in [Vec2::ZERO, Vec2::ONE, Vec2::new(0.0, 1.0)] {
                let (m, pdf) = md.sample(Vec3::Z, u);
                assert!(m.is_finite() && pdf.is_finite(), "{u}: {m} {pdf}");
                let (m, pdf) = md.sample(Vec3::new(1.0, 0.0, 1e-7).normalize(), u);
                assert!(m.is_finite() && pdf.is_finite(), "{u}: {m} {pdf}");
            }
            assert_eq!(md.d(Vec3::X), 0.0);
            assert_eq!(md.d(Vec3::ZERO), 0.0);
        }
    }
}
