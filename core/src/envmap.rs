//! The environment map (Mitsuba 3's `envmap`): radiance from infinitely far away, read from a
//! latitude-longitude image, importance-sampled by the image's luminance.
//!
//! Mitsuba's mapping (src/emitters/envmap.cpp), checked against Mitsuba 3.9.1: a direction d
//! in the map's frame (d = to_world^-1 of the world direction towards the environment) has
//!   u = atan2(d.x, -d.z) / (2 pi),   v = acos(d.y) / pi,
//! and conversely, with phi = 2 pi u and theta = pi v,
//!   d = (sin phi sin theta, cos theta, -cos phi sin theta):
//! +y is up (the top row, v = 0), the image's centre (u, v) = (1/2, 1/2) is +z, u = 1/4 is +x
//! and u = 0 (the left and right edges) is -z. The radiance is interpolated bilinearly
//! between texel centres, texel-centred and periodic in u (column i's centre at u =
//! (i + 1/2) / width) but corner-aligned in v (row j's centre at v = j / (height - 1): the top
//! row is the pole +y, the bottom row the pole -y).
//!
//! Sampling: the bilinear radiance is a patchwork of cells between four texel centres
//! (width x (height - 1) of them, the last column of cells joining the right edge to the
//! left). A cell is drawn with probability proportional to the mean luminance of its corners
//! times its solid angle (a piecewise-constant 2D distribution), then a direction uniform in
//! solid angle within it (u uniform, cos theta uniform): the density is the cell's probability
//! over its solid angle, which stays bounded at the poles (a density uniform in v would grow
//! as 1 / sin theta there) and makes a constant map's samples exactly uniform. Every direction
//! of non-zero radiance lies in a cell of non-zero weight, so light sampling alone (photons)
//! is unbiased. Mitsuba samples the same cells with a piecewise-bilinear density in (u, v)
//! instead; the images agree, the noise differs a little.
//!
//! pbrt-v4's layout ([`EnvironmentMap::equal_area`], its `ImageInfiniteLight`): the image
//! is Clarberg's equal-area octahedral map of the sphere, a direction d in the map's frame
//! at ([`sphere_to_square`]) (u, v) in [0, 1]^2 with row 0 the image's top row, the radiance
//! that of the texel the point falls in (no interpolation: pbrt-v4's `LookupNearest`). Every
//! texel covers the same solid angle, 4 pi / (width height), so a texel drawn by luminance
//! and a point uniform in it give the density p(texel) width height / (4 pi).

use crate::Rgb;
use crate::sampling::Distribution2D;
use crate::texture::{Bitmap, WrapMode, luminance};
use glam::{Mat3, Vec2, Vec3};
use std::f32::consts::PI;
use std::f64::consts::PI as PI64;

#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    /// Linear RGB radiance before `scale`, at least 2 x 3 texels.
    bitmap: Bitmap,
    scale: f32,
    /// World from the map's frame (orthonormal) and back.
    to_world: Mat3,
    from_world: Mat3,
    /// Over the (u - 1/(2 width), v) square, cell (i, j) between texel centres (i, j) and
    /// (i + 1, j + 1).
    distribution: Distribution2D,
    /// cos theta of the rows of texel centres, top to bottom (latitude-longitude); empty
    /// for the equal-area layout, whose distribution is over its texels.
    cos_rows: Vec<f32>,
    equal_area: bool,
    /// The integral of the radiance over the sphere of directions (W/m^2).
    integral: Rgb,
}

impl EnvironmentMap {
    /// The map of `bitmap` (linear radiance, scaled by `scale`) turned by the linear part of
    /// `to_world`, which must be a rotation or a mirror, possibly uniformly scaled (the
    /// translation is irrelevant to directions). Negative texels are taken as zero.
    pub fn new(bitmap: &Bitmap, scale: f32, to_world: Mat3) -> Result<EnvironmentMap, String> {
        if scale < 0.0 || !scale.is_finite() {
            return Err(format!(
                "the scale must be finite and non-negative, found {scale}"
            ));
        }
        let gram = to_world.transpose() * to_world;
        let s2 = gram.x_axis.x;
        let orthogonal = s2 > 0.0
            && (gram - Mat3::from_diagonal(Vec3::splat(s2)))
                .to_cols_array()
                .iter()
                .all(|e| e.abs() <= 1e-4 * s2);
        if !orthogonal {
            return Err(
                "an environment map's transform must be a rotation (or a mirror), \
                 possibly uniformly scaled"
                    .into(),
            );
        }
        let to_world = to_world * (1.0 / s2.sqrt());
        // As Mitsuba: the interpolation needs two columns and, corner-aligned in v, three
        // rows; smaller images repeat their last column and row.
        let padded = bitmap.pad_to(2, 3);
        let texels = padded.texels().iter().map(|c| c.max(Rgb::ZERO)).collect();
        let bitmap = Bitmap::new(padded.width(), padded.height(), texels).expect("same size");
        let (w, h) = (bitmap.width(), bitmap.height());

        let cos_row = |j: usize| (PI64 * j as f64 / (h - 1) as f64).cos();
        let mut weights = Vec::with_capacity(w * (h - 1));
        let mut integral = glam::DVec3::ZERO;
        for j in 0..h - 1 {
            // Integrals over the row of cells of sin(theta) dv times the weights of its top
            // and bottom texels in the interpolation (1 - t and t, t its position in v).
            let (a, b) = (
                PI64 * j as f64 / (h - 1) as f64,
                PI64 * (j + 1) as f64 / (h - 1) as f64,
            );
            let dt = b - a;
            let top = (dt * a.cos() - (b.sin() - a.sin())) / (PI64 * dt);
            let bottom = (b.sin() - a.sin() - dt * b.cos()) / (PI64 * dt);
            let solid_angle = (cos_row(j) - cos_row(j + 1)) as f32;
            for i in 0..w {
                let i1 = (i + 1) % w;
                let corners = [
                    bitmap.texel(i, j),
                    bitmap.texel(i1, j),
                    bitmap.texel(i, j + 1),
                    bitmap.texel(i1, j + 1),
                ];
                let lum: f32 = corners.iter().map(|&c| luminance(c)).sum::<f32>() / 4.0;
                weights.push(lum * solid_angle);
                // Each corner's weight integrates to 1 / (2 w) over the cell's width in u.
                integral += ((corners[0] + corners[1]).as_dvec3() * top
                    + (corners[2] + corners[3]).as_dvec3() * bottom)
                    / (2.0 * w as f64);
            }
        }
        // d(omega) = sin(theta) d(theta) d(phi) = 2 pi^2 sin(theta) du dv.
        let integral = (integral * (2.0 * PI64 * PI64) * scale as f64).as_vec3();
        Ok(EnvironmentMap {
            distribution: Distribution2D::new(&weights, w, h - 1),
            cos_rows: (0..h).map(|j| cos_row(j) as f32).collect(),
            equal_area: false,
            bitmap,
            scale,
            to_world,
            from_world: to_world.transpose(),
            integral,
        })
    }

    /// The map of an image in pbrt-v4's equal-area octahedral layout, as [`Self::new`]
    /// otherwise.
    pub fn equal_area(
        bitmap: &Bitmap,
        scale: f32,
        to_world: Mat3,
    ) -> Result<EnvironmentMap, String> {
        let mut map = EnvironmentMap::new(
            &Bitmap::new(1, 1, vec![Rgb::ONE]).expect("1 x 1"),
            scale,
            to_world,
        )?;
        let texels: Vec<Rgb> = bitmap.texels().iter().map(|c| c.max(Rgb::ZERO)).collect();
        let (w, h) = (bitmap.width(), bitmap.height());
        let weights: Vec<f32> = texels.iter().map(|&c| luminance(c)).collect();
        let sum: glam::DVec3 = texels.iter().map(|c| c.as_dvec3()).sum();
        map.integral = (sum * (4.0 * PI64 / (w * h) as f64) * scale as f64).as_vec3();
        map.distribution = Distribution2D::new(&weights, w, h);
        map.bitmap = Bitmap::new(w, h, texels).expect("same size");
        map.cos_rows = Vec::new();
        map.equal_area = true;
        Ok(map)
    }

    /// Radiance arriving from direction `dir` (towards the environment, world space).
    #[inline]
    pub fn eval(&self, dir: Vec3) -> Rgb {
        let d = (self.from_world * dir).normalize_or_zero();
        if self.equal_area {
            return self.eval_texel(sphere_to_square(d));
        }
        let uv = Vec2::new(
            d.x.atan2(-d.z) * (0.5 / PI),
            d.y.clamp(-1.0, 1.0).acos() * (1.0 / PI),
        );
        self.eval_uv(uv)
    }

    /// The texel the point `uv` of the equal-area square falls in.
    #[inline]
    fn eval_texel(&self, uv: Vec2) -> Rgb {
        let (w, h) = (self.bitmap.width(), self.bitmap.height());
        let x = ((uv.x * w as f32) as usize).min(w - 1);
        let y = ((uv.y * h as f32) as usize).min(h - 1);
        self.scale * self.bitmap.texel(x, y)
    }

    #[inline]
    fn eval_uv(&self, uv: Vec2) -> Rgb {
        let (w, h) = (self.bitmap.width() as f32, self.bitmap.height() as f32);
        self.scale
            * self.bitmap.bilinear(
                uv.x * w - 0.5,
                uv.y.clamp(0.0, 1.0) * (h - 1.0),
                [WrapMode::Repeat, WrapMode::Clamp],
            )
    }

    /// A direction towards the environment (world space) drawn by luminance, its radiance
    /// and its solid-angle density; None for a black map.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Rgb, f32)> {
        let (p, _) = self.distribution.sample(u)?;
        if self.equal_area {
            let dir = self.to_world * square_to_sphere(p);
            let pdf = self.pdf(dir);
            return (pdf > 0.0).then(|| (dir, self.eval_texel(p), pdf));
        }
        let (row, t) = self.row(p.y);
        // Uniform in cos theta across the row of cells: uniform in solid angle.
        let (c0, c1) = (self.cos_rows[row], self.cos_rows[row + 1]);
        let cos_t = (c0 + t * (c1 - c0)).clamp(-1.0, 1.0);
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let u_map = p.x + 0.5 / self.bitmap.width() as f32;
        let (sin_p, cos_p) = (2.0 * PI * u_map).sin_cos();
        let d = Vec3::new(sin_p * sin_t, cos_t, -cos_p * sin_t);
        let uv = Vec2::new(u_map, cos_t.acos() * (1.0 / PI));
        let dir = self.to_world * d;
        // The density of the cell the direction is found in again, as `pdf` finds it: a
        // sample within rounding of a cell's edge may land in the neighbour, whose density
        // MIS must then see in both places.
        let pdf = self.pdf(dir);
        (pdf > 0.0).then(|| (dir, self.eval_uv(uv), pdf))
    }

    /// The row of cells that `v` in [0, 1] falls in and where in it (0 at the top, 1 at the
    /// bottom).
    #[inline]
    fn row(&self, v: f32) -> (usize, f32) {
        let rows = self.cos_rows.len() - 1;
        let y = v.clamp(0.0, 1.0) * rows as f32;
        let row = (y as usize).min(rows - 1);
        (row, (y - row as f32).clamp(0.0, 1.0))
    }

    /// The solid-angle density within a cell of `row` whose density on the (u, v) square is
    /// `pdf_square`: the cell's probability over its solid angle.
    #[inline]
    fn cell_pdf(&self, pdf_square: f32, row: usize) -> f32 {
        let (nu, nv) = (self.bitmap.width(), self.cos_rows.len() - 1);
        let probability = pdf_square / (nu * nv) as f32;
        let solid_angle = 2.0 * PI / nu as f32 * (self.cos_rows[row] - self.cos_rows[row + 1]);
        probability / solid_angle
    }

    /// The solid-angle density with which `sample` draws direction `dir` (world space).
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let d = (self.from_world * dir).normalize_or_zero();
        if d == Vec3::ZERO {
            return 0.0;
        }
        if self.equal_area {
            let p = sphere_to_square(d).clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON));
            return self.distribution.pdf(p) / (4.0 * PI);
        }
        let u = d.x.atan2(-d.z) * (0.5 / PI) - 0.5 / self.bitmap.width() as f32;
        let v = d.y.clamp(-1.0, 1.0).acos() * (1.0 / PI);
        let (row, _) = self.row(v);
        let pdf_square = self.distribution.pdf(Vec2::new(u - u.floor(), v));
        self.cell_pdf(pdf_square, row)
    }

    /// The integral of the radiance over the sphere of directions, exact for the bilinear
    /// interpolation (W/m^2; the irradiance of a plane is not this but its cosine-weighted
    /// half).
    pub fn integral(&self) -> Rgb {
        self.integral
    }

    pub fn scale(&self) -> f32 {
        self.scale
    }

    pub fn bitmap(&self) -> &Bitmap {
        &self.bitmap
    }
}

/// Clarberg's equal-area map of the unit square onto the sphere (pbrt-v4's
/// `EqualAreaSquareToSphere`): the square's centre is +z, its corners -z; the square folded
/// as an octahedron, each of its four quadrants one of the hemisphere's quarters, the
/// triangles nearer the corners the southern hemisphere's.
pub fn square_to_sphere(p: Vec2) -> Vec3 {
    let (u, v) = (2.0 * p.x - 1.0, 2.0 * p.y - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    // Signed distance from the diagonal |u| + |v| = 1 (the equator).
    let signed = 1.0 - (up + vp);
    let r = 1.0 - signed.abs();
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * (PI / 4.0);
    let z = (1.0 - r * r).copysign(signed);
    let (sin_phi, cos_phi) = phi.sin_cos();
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(cos_phi.copysign(u) * s, sin_phi.copysign(v) * s, z)
}

/// The inverse of [`square_to_sphere`] for a unit direction (pbrt-v4's
/// `EqualAreaSphereToSquare`, with the arctangent its polynomial approximates).
pub fn sphere_to_square(d: Vec3) -> Vec2 {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let t = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = t.atan() * (2.0 / PI);
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        // The southern hemisphere: the triangles towards the corners.
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    Vec2::new(0.5 * (u.copysign(d.x) + 1.0), 0.5 * (v.copysign(d.y) + 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// 8 x 5 texels: dim blue-grey, one bright texel and a red column.
    fn image() -> Bitmap {
        let (w, h) = (8, 5);
        let mut texels = vec![Rgb::new(0.2, 0.3, 0.5); w * h];
        texels[2 * w + 5] = Rgb::new(40.0, 30.0, 20.0);
        for j in 0..h {
            texels[j * w + 1] = Rgb::new(2.0, 0.0, 0.0);
        }
        Bitmap::new(w, h, texels).unwrap()
    }

    #[test]
    fn texel_centres_map_to_mitsubas_directions() {
        let img = image();
        let map = EnvironmentMap::new(&img, 2.0, Mat3::IDENTITY).unwrap();
        let dir = |u: f32, v: f32| {
            let (st, ct) = (PI * v).sin_cos();
            let (sp, cp) = (2.0 * PI * u).sin_cos();
            Vec3::new(sp * st, ct, -cp * st)
        };
        for j in 0..5 {
            for i in 0..8 {
                let got = map.eval(dir((i as f32 + 0.5) / 8.0, j as f32 / 4.0));
                let want = 2.0 * img.texel(i, j);
                if j == 0 || j == 4 {
                    continue; // the poles: every column meets there
                }
                assert!(
                    (got - want).abs().max_element() < 1e-4 * want.max_element(),
                    "({i}, {j}): {got} {want}"
                );
            }
        }
        // +z is the image centre: between columns 3 and 4 of the middle row.
        let c = map.eval(Vec3::Z);
        assert!(
            (c - (img.texel(3, 2) + img.texel(4, 2)))
                .abs()
                .max_element()
                < 1e-5
        );
        // +y is the top row (uniform there but for the red column 1, far from where the
        // pole's u = atan2(0, -0) / (2 pi) = 1/2 reads it).
        let up = map.eval(Vec3::Y);
        assert!(
            (up - 2.0 * img.texel(3, 0)).abs().max_element() < 1e-5,
            "{up}"
        );
        // A rotation of 90 degrees about y turns +z of the map onto +x of the world.
        let turned = EnvironmentMap::new(&img, 2.0, Mat3::from_rotation_y(PI / 2.0)).unwrap();
        assert!((turned.eval(Vec3::X) - c).abs().max_element() < 1e-4);
    }

    #[test]
    fn the_pdf_integrates_to_one_and_matches_the_samples() {
        let map = EnvironmentMap::new(&image(), 1.0, Mat3::from_rotation_x(0.3)).unwrap();
        // Midpoint rule over (cos theta, phi) about the world's z axis.
        let (n_cos, n_phi) = (400, 800);
        let mut total = 0.0f64;
        let mut radiance = glam::DVec3::ZERO;
        for a in 0..n_cos {
            let z = -1.0 + 2.0 * (a as f32 + 0.5) / n_cos as f32;
            let r = (1.0 - z * z).sqrt();
            for b in 0..n_phi {
                let phi = 2.0 * PI * (b as f32 + 0.5) / n_phi as f32;
                let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                total += map.pdf(d) as f64;
                radiance += map.eval(d).as_dvec3();
            }
        }
        let cell = 4.0 * PI64 / (n_cos * n_phi) as f64;
        assert!((total * cell - 1.0).abs() < 2e-3, "{}", total * cell);
        let integral = radiance * cell;
        let rel = ((integral - map.integral().as_dvec3()) / integral)
            .abs()
            .max_element();
        assert!(rel < 2e-3, "{integral} against {}", map.integral());
        let mut rng = Rng::new(&[5]);
        for _ in 0..10_000 {
            let (d, l, pdf) = map.sample(rng.next_2d()).unwrap();
            assert!((d.length() - 1.0).abs() < 1e-4);
            assert!(
                ((map.pdf(d) - pdf) / pdf).abs() < 2e-3,
                "{} against {pdf}",
                map.pdf(d)
            );
            assert!((map.eval(d) - l).abs().max_element() <= 1e-3 * l.max_element());
        }
    }

    #[test]
    fn a_constant_map_integrates_to_4_pi_l_and_samples_uniformly() {
        let l = Rgb::new(1.0, 0.5, 0.25);
        let map =
            EnvironmentMap::new(&Bitmap::new(1, 1, vec![l]).unwrap(), 1.0, Mat3::IDENTITY).unwrap();
        assert!((map.integral() - 4.0 * PI * l).abs().max_element() < 1e-5);
        assert_eq!(map.eval(Vec3::new(0.3, -0.2, 0.9)), l);
        // Uniform over the sphere: every sample has density 1 / (4 pi).
        let mut rng = Rng::new(&[6]);
        for _ in 0..1000 {
            let (d, _, pdf) = map.sample(rng.next_2d()).unwrap();
            assert!((pdf * 4.0 * PI - 1.0).abs() < 1e-4, "{pdf}");
            assert!((map.pdf(d) * 4.0 * PI - 1.0).abs() < 1e-4);
        }
        let black = EnvironmentMap::new(
            &Bitmap::new(2, 2, vec![Rgb::ZERO; 4]).unwrap(),
            1.0,
            Mat3::IDENTITY,
        )
        .unwrap();
        assert!(black.sample(Vec2::splat(0.5)).is_none());
        assert_eq!(black.pdf(Vec3::X), 0.0);
        assert!(
            EnvironmentMap::new(&image(), 1.0, Mat3::from_diagonal(Vec3::new(1.0, 2.0, 1.0)))
                .is_err()
        );
        assert!(EnvironmentMap::new(&image(), -1.0, Mat3::IDENTITY).is_err());
    }

    /// Clarberg's map: the square's centre is +z, its corners -z, its edges' midpoints the
    /// equator's +-x and +-y; the inverse inverts it; and it preserves area: uniform points
    /// of the square give directions uniform on the sphere (chi-square over 8 bands of z of
    /// equal solid angle times 8 sectors of phi, 63 degrees of freedom).
    #[test]
    fn equal_area_map_is_inverse_and_preserves_area() {
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-5;
        assert!(close(square_to_sphere(Vec2::splat(0.5)), Vec3::Z));
        assert!(close(square_to_sphere(Vec2::ZERO), -Vec3::Z));
        assert!(close(square_to_sphere(Vec2::new(1.0, 0.5)), Vec3::X));
        assert!(close(square_to_sphere(Vec2::new(0.5, 1.0)), Vec3::Y));
        assert!(close(square_to_sphere(Vec2::new(0.0, 0.5)), -Vec3::X));
        let mut rng = Rng::new(&[9]);
        let (bands, sectors, n) = (8usize, 8usize, 200_000usize);
        let mut counts = vec![0u32; bands * sectors];
        for _ in 0..n {
            let p = rng.next_2d();
            let d = square_to_sphere(p);
            assert!((d.length() - 1.0).abs() < 1e-5, "{p} -> {d}");
            let back = sphere_to_square(d);
            assert!(
                (back - p).abs().max_element() < 1e-4,
                "{p} -> {d} -> {back}"
            );
            let band = (((d.z + 1.0) / 2.0 * bands as f32) as usize).min(bands - 1);
            let phi = d.y.atan2(d.x) + PI;
            let sector = ((phi / (2.0 * PI) * sectors as f32) as usize).min(sectors - 1);
            counts[band * sectors + sector] += 1;
        }
        let expected = n as f64 / (bands * sectors) as f64;
        let chi2: f64 = counts
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        // 63 degrees of freedom: the 99.9th percentile is about 103.4.
        assert!(chi2 < 103.4, "chi-square {chi2}");
    }

    /// An equal-area map reads the texel a direction falls in, integrates to 4 pi times its
    /// mean, and its samples' density is its pdf, which integrates to one.
    #[test]
    fn equal_area_map_lookup_integral_and_pdf() {
        let (w, h) = (8, 8);
        let mut texels = vec![Rgb::new(0.2, 0.3, 0.5); w * h];
        texels[3 * w + 5] = Rgb::new(40.0, 30.0, 20.0);
        let img = Bitmap::new(w, h, texels.clone()).unwrap();
        let map = EnvironmentMap::equal_area(&img, 2.0, Mat3::from_rotation_x(0.3)).unwrap();
        let centre = |i: usize, j: usize| {
            Mat3::from_rotation_x(0.3)
                * square_to_sphere(Vec2::new(
                    (i as f32 + 0.5) / w as f32,
                    (j as f32 + 0.5) / h as f32,
                ))
        };
        assert_eq!(map.eval(centre(5, 3)), 2.0 * texels[3 * w + 5]);
        assert_eq!(map.eval(centre(1, 6)), 2.0 * texels[6 * w + 1]);
        let mean: Rgb = texels.iter().copied().sum::<Rgb>() / (w * h) as f32;
        assert!(
            (map.integral() - 2.0 * 4.0 * PI * mean).abs().max_element()
                < 1e-3 * map.integral().max_element()
        );
        let (n_cos, n_phi) = (400, 800);
        let mut total = 0.0f64;
        for a in 0..n_cos {
            let z = -1.0 + 2.0 * (a as f32 + 0.5) / n_cos as f32;
            let r = (1.0 - z * z).sqrt();
            for b in 0..n_phi {
                let phi = 2.0 * PI * (b as f32 + 0.5) / n_phi as f32;
                total += map.pdf(Vec3::new(r * phi.cos(), r * phi.sin(), z)) as f64;
            }
        }
        let cell = 4.0 * PI64 / (n_cos * n_phi) as f64;
        assert!((total * cell - 1.0).abs() < 2e-3, "{}", total * cell);
        let mut rng = Rng::new(&[8]);
        let mut bright = 0;
        for _ in 0..10_000 {
            let (d, l, pdf) = map.sample(rng.next_2d()).unwrap();
            assert!(((map.pdf(d) - pdf) / pdf).abs() < 1e-3);
            assert_eq!(map.eval(d), l);
            bright += (l.x > 10.0) as u32;
        }
        // The bright texel's share of the luminance.
        let lum = |c: Rgb| luminance(c) as f64;
        let share = lum(texels[3 * w + 5]) / texels.iter().map(|&c| lum(c)).sum::<f64>();
        let sd = (share * (1.0 - share) / 10_000.0).sqrt();
        assert!(
            (bright as f64 / 10_000.0 - share).abs() < 4.0 * sd,
            "{bright} against {share}"
        );
    }
}
