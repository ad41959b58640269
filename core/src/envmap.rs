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
    /// cos theta of the rows of texel centres, top to bottom.
    cos_rows: Vec<f32>,
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
            bitmap,
            scale,
            to_world,
            from_world: to_world.transpose(),
            integral,
        })
    }

    /// Radiance arriving from direction `dir` (towards the environment, world space).
    #[inline]
    pub fn eval(&self, dir: Vec3) -> Rgb {
        let d = (self.from_world * dir).normalize_or_zero();
        let uv = Vec2::new(
            d.x.atan2(-d.z) * (0.5 / PI),
            d.y.clamp(-1.0, 1.0).acos() * (1.0 / PI),
        );
        self.eval_uv(uv)
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
}
