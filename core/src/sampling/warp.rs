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
}
