//! Warps: the maps from uniform numbers in the unit square to directions and points with a
//! known density (pbrt-v4's `util/sampling.h`), and the frame around a normal they are built in.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Orthonormal basis around `n` (Duff et al. 2017, branchless).
#[inline]
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// `local` (z up) expressed in the frame whose z axis is `n`.
#[inline]
pub fn to_world(local: Vec3, n: Vec3) -> Vec3 {
    let (s, t) = basis(n);
    s * local.x + t * local.y + n * local.z
}

/// Uniform direction on the unit sphere; pdf 1/(4 pi).
#[inline]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform direction on the hemisphere around +z; pdf 1/(2 pi).
#[inline]
pub fn uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Concentric map of the square onto the unit disc (Shirley-Chiu).
#[inline]
pub fn concentric_disc(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, PI / 4.0 * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction on the hemisphere around +z; pdf cos(theta)/pi.
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disc(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Uniform direction in the cone of half-angle acos(cos_max) around +z; pdf 1/(2 pi (1 - cos_max)).
#[inline]
pub fn uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_t = 1.0 - u.x * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// Uniform barycentrics (b0, b1) on a triangle (the square-root warp).
#[inline]
pub fn uniform_triangle(u: Vec2) -> (f32, f32) {
    let su = u.x.sqrt();
    (1.0 - su, u.y * su)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn basis_is_orthonormal() {
        let mut rng = Rng::new(&[1]);
        for _ in 0..1000 {
            let n = uniform_sphere(rng.next_2d());
            let (s, t) = basis(n);
            assert!((s.length() - 1.0).abs() < 1e-4 && (t.length() - 1.0).abs() < 1e-4);
            assert!(s.dot(t).abs() < 1e-4 && s.dot(n).abs() < 1e-4 && t.dot(n).abs() < 1e-4);
        }
    }

    /// Chi-square of the hemisphere warps against their densities, over 8 x 8 cells of
    /// (cos theta, phi): a cell's probability is the density's integral over it (uniform: its
    /// share of cos theta; cosine: its share of cos^2 theta), the threshold the statistic's
    /// quantile at 5 standard deviations (Wilson-Hilferty).
    #[test]
    fn hemisphere_warps_follow_their_densities() {
        const N: usize = 8;
        let samples = 200_000;
        type Warp = fn(Vec2) -> Vec3;
        type Cdf = fn(f64) -> f64;
        let warps: [(&str, Warp, Cdf); 2] = [
            ("uniform", uniform_hemisphere, |c| c),
            ("cosine", cosine_hemisphere, |c| c * c),
        ];
        for (name, warp, cdf) in warps {
            let mut rng = Rng::new(&[7]);
            let mut counts = [[0u32; N]; N];
            for _ in 0..samples {
                let w = warp(rng.next_2d());
                assert!((w.length() - 1.0).abs() < 1e-4 && w.z >= 0.0, "{name}: {w}");
                let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI) / (2.0 * PI);
                let i = ((w.z * N as f32) as usize).min(N - 1);
                let j = ((phi * N as f32) as usize).min(N - 1);
                counts[i][j] += 1;
            }
            let mut chi2 = 0.0;
            for (i, row) in counts.iter().enumerate() {
                let p = (cdf((i + 1) as f64 / N as f64) - cdf(i as f64 / N as f64)) / N as f64;
                let expected = p * samples as f64;
                for &c in row {
                    chi2 += (c as f64 - expected).powi(2) / expected;
                }
            }
            let k = (N * N - 1) as f64;
            let v = 2.0 / (9.0 * k);
            let limit = k * (1.0 - v + 5.0 * v.sqrt()).powi(3);
            assert!(chi2 < limit, "{name}: chi2 {chi2} over {limit}");
        }
    }
}
