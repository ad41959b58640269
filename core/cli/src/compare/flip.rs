//! LDR-FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"):
//! the perceived difference between two sRGB images in [0, 1] viewed at a given number of
//! pixels per degree, per pixel in [0, 1], as NVIDIA's reference implementation
//! (github.com/NVlabs/flip, BSD-3-Clause; written here from the paper and its published
//! constants, not copied) computes it:
//!
//! 1. each image, sRGB decoded to linear RGB, goes to the opponent space YCxCz (CIE XYZ
//!    relative to D65, then Y = 116 y - 16, Cx = 500 (x - y), Cz = 200 (y - z));
//! 2. each channel is blurred by the contrast sensitivity function of its channel, a (sum of)
//!    Gaussian(s) a sqrt(pi / b) exp(-pi^2 r^2 / b) in degrees (separable; edges clamped);
//! 3. the blurred colours go back to linear RGB, clamped to [0, 1], to CIELab, whose a and b
//!    are scaled by 0.01 L (Hunt effect); the colour error is the HyAB distance |dL| +
//!    |(da, db)| raised to qc = 0.7, and compressed to [0, 1]: [0, pc cmax) linearly onto [0,
//!    pt), the rest onto [pt, 1] (pc = 0.4, pt = 0.95, cmax the distance of green to blue);
//! 4. edges and points: the normalised achromatic channel (Y + 16) / 116 of the unblurred
//!    images is convolved with the first and second derivatives of a Gaussian of standard
//!    deviation 0.5 w ppd pixels (w = 0.082 degrees); the feature error is (max(|edge diff|,
//!    |point diff|) / sqrt 2)^qf, qf = 0.5;
//! 5. the error is colour error^(1 - feature error).
//!
//! The arithmetic is in f32, as in the reference code, so the two agree to rounding.

use std::f32::consts::PI;

/// The reference code's default pixels per degree: a 0.7 m wide 3840-pixel monitor seen from
/// 0.7 m (67.02).
pub fn default_ppd() -> f32 {
    0.7 * (3840.0 / 0.7) * (PI / 180.0)
}

/// The colour error's exponent qc, its compression's pc and pt.
const QC: f32 = 0.7;
const PC: f32 = 0.4;
const PT: f32 = 0.95;
/// The feature detectors' width in degrees, and the feature error's exponent.
const FEATURE_WIDTH: f32 = 0.082;
const QF: f32 = 0.5;

/// The contrast sensitivity functions as sums of two Gaussians (a1, b1), (a2, b2) per
/// channel of YCxCz (the paper's Table; b in degrees^2).
const CSF_A1: [f32; 3] = [1.0, 1.0, 34.1];
const CSF_B1: [f32; 3] = [0.0047, 0.0053, 0.04];
const CSF_A2: [f32; 3] = [0.0, 0.0, 13.5];
const CSF_B2: [f32; 3] = [1.0e-5, 1.0e-5, 0.025];

/// D65 white in XYZ, and its inverse.
const WHITE: [f32; 3] = [0.950_428_55, 1.0, 1.088_900_4];
const INV_WHITE: [f32; 3] = [1.052_156_9, 1.0, 0.918_357_7];

type Px = [f32; 3];

/// The per-pixel LDR-FLIP error of `test` against `reference` (row-major, `width` x `height`
/// sRGB values, clamped to [0, 1] here), viewed at `ppd` pixels per degree, and its mean.
pub fn flip(
    reference: &[Px],
    test: &[Px],
    width: usize,
    height: usize,
    ppd: f32,
) -> (Vec<f32>, f64) {
    assert_eq!(reference.len(), width * height);
    assert_eq!(test.len(), width * height);
    if width == 0 || height == 0 {
        return (Vec::new(), 0.0);
    }
    let to_ycxcz = |img: &[Px]| -> Vec<Px> {
        img.iter()
            .map(|p| xyz_to_ycxcz(rgb_to_xyz(p.map(|c| srgb_to_linear(c.clamp(0.0, 1.0))))))
            .collect()
    };
    let (r, t) = (to_ycxcz(reference), to_ycxcz(test));
    let colour = colour_error(&r, &t, width, height, ppd);
    let feature = feature_error(&r, &t, width, height, ppd);
    let map: Vec<f32> = colour
        .iter()
        .zip(&feature)
        .map(|(&c, &f)| c.powf(1.0 - f))
        .collect();
    let mean = map.iter().map(|&e| e as f64).sum::<f64>() / map.len() as f64;
    (map, mean)
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn rgb_to_xyz(c: Px) -> Px {
    // Linear sRGB (D65) to XYZ, in exact rational form.
    let m = [
        [
            10_135_552.0 / 24_577_794.0,
            8_788_810.0 / 24_577_794.0,
            4_435_075.0 / 24_577_794.0,
        ],
        [
            2_613_072.0 / 12_288_897.0,
            8_788_810.0 / 12_288_897.0,
            887_015.0 / 12_288_897.0,
        ],
        [
            1_425_312.0 / 73_733_382.0,
            8_788_810.0 / 73_733_382.0,
            70_074_185.0 / 73_733_382.0,
        ],
    ];
    mul(&m, c)
}

fn xyz_to_rgb(c: Px) -> Px {
    let m = [
        [3.241_003_3, -1.537_398_9, -0.498_615_86],
        [-0.969_224_3, 1.875_930_1, 0.041_554_224],
        [0.055_639_423, -0.204_011_2, 1.057_148_9],
    ];
    mul(&m, c)
}

fn mul(m: &[[f32; 3]; 3], c: Px) -> Px {
    m.map(|row| row[0] * c[0] + row[1] * c[1] + row[2] * c[2])
}

fn xyz_to_ycxcz(c: Px) -> Px {
    let [x, y, z] = [
        c[0] * INV_WHITE[0],
        c[1] * INV_WHITE[1],
        c[2] * INV_WHITE[2],
    ];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

fn ycxcz_to_xyz(c: Px) -> Px {
    let y = (c[0] + 16.0) / 116.0;
    [
        (y + c[1] / 500.0) * WHITE[0],
        y * WHITE[1],
        (y - c[2] / 200.0) * WHITE[2],
    ]
}

fn xyz_to_lab(c: Px) -> Px {
    let delta = 6.0f32 / 29.0;
    let f = |v: f32| {
        if v > delta * delta * delta {
            v.powf(1.0 / 3.0)
        } else {
            v / (3.0 * delta * delta) + 4.0 / 29.0
        }
    };
    let [x, y, z] = [
        f(c[0] * INV_WHITE[0]),
        f(c[1] * INV_WHITE[1]),
        f(c[2] * INV_WHITE[2]),
    ];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// CIELab with a and b scaled by 0.01 L (the Hunt effect: colour differences shrink in the
/// dark).
fn hunt(lab: Px) -> Px {
    [lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]]
}

fn hyab(a: Px, b: Px) -> f32 {
    (a[0] - b[0]).abs() + ((a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The largest colour error before compression: Hunt-adjusted HyAB of green to blue, ^qc.
fn cmax() -> f32 {
    let lab = |c: Px| hunt(xyz_to_lab(rgb_to_xyz(c)));
    hyab(lab([0.0, 1.0, 0.0]), lab([0.0, 0.0, 1.0])).powf(QC)
}

/// The CSF Gaussian a sqrt(pi / b) exp(-pi^2 d2 / b) at squared distance `d2` (degrees^2).
fn csf(d2: f32, a: f32, b: f32) -> f32 {
    a * (PI / b).sqrt() * (-PI * PI * d2 / b).exp()
}

/// Convolves each row (`horizontal`) or column of the `width` x `height` planes `src` with
/// the 1D `kernel` (odd length, centred), the image's edge pixels repeated beyond it.
fn convolve(
    src: &[f32],
    width: usize,
    height: usize,
    kernel: &[f32],
    horizontal: bool,
) -> Vec<f32> {
    let r = (kernel.len() / 2) as isize;
    let mut out = vec![0.0f32; src.len()];
    for y in 0..height {
        for x in 0..width {
            let mut sum = 0.0f32;
            for (k, &w) in kernel.iter().enumerate() {
                let o = k as isize - r;
                let i = if horizontal {
                    let xx = (x as isize + o).clamp(0, width as isize - 1) as usize;
                    y * width + xx
                } else {
                    let yy = (y as isize + o).clamp(0, height as isize - 1) as usize;
                    yy * width + x
                };
                sum += w * src[i];
            }
            out[y * width + x] = sum;
        }
    }
    out
}

/// Separable 2D convolution of a plane: `kx` along rows, then `ky` along columns.
fn convolve2(src: &[f32], width: usize, height: usize, kx: &[f32], ky: &[f32]) -> Vec<f32> {
    let rows = convolve(src, width, height, kx, true);
    convolve(&rows, width, height, ky, false)
}

/// The colour error (step 3) of each pixel, compressed to [0, 1].
fn colour_error(r: &[Px], t: &[Px], width: usize, height: usize, ppd: f32) -> Vec<f32> {
    // The kernels reach 3 standard deviations of the widest Gaussian.
    let b_max = CSF_B1.iter().chain(&CSF_B2).fold(0.0f32, |m, &b| m.max(b));
    let radius = (3.0 * (b_max / (2.0 * PI * PI)).sqrt() * ppd).ceil() as isize;
    let taps = |f: &dyn Fn(f32) -> f32| -> Vec<f32> {
        (-radius..=radius)
            .map(|i| {
                let d = i as f32 / ppd;
                f(d * d)
            })
            .collect()
    };
    let normalised = |mut k: Vec<f32>, norm: f32| {
        k.iter_mut().for_each(|w| *w /= norm);
        k
    };
    // Y and Cx: one Gaussian each, normalised to sum 1.
    let ky = taps(&|d2| csf(d2, CSF_A1[0], CSF_B1[0]));
    let ky_sum: f32 = ky.iter().sum();
    let ky = normalised(ky, ky_sum);
    let kx = taps(&|d2| csf(d2, CSF_A1[1], CSF_B1[1]));
    let kx_sum: f32 = kx.iter().sum();
    let kx = normalised(kx, kx_sum);
    // Cz: a sum of two Gaussians, each separated into the product of two 1D factors with
    // the square root of its weight; the 2D sum is normalised to 1.
    let sqrt_csf =
        |d2: f32, a: f32, b: f32| (a * (PI / b).sqrt()).sqrt() * (-PI * PI * d2 / b).exp();
    let kz1 = taps(&|d2| sqrt_csf(d2, CSF_A1[2], CSF_B1[2]));
    let kz2 = taps(&|d2| sqrt_csf(d2, CSF_A2[2], CSF_B2[2]));
    let (s1, s2): (f32, f32) = (kz1.iter().sum(), kz2.iter().sum());
    let norm = (s1 * s1 + s2 * s2).sqrt();
    let (kz1, kz2) = (normalised(kz1, norm), normalised(kz2, norm));

    let filter = |img: &[Px]| -> Vec<Px> {
        let plane = |c: usize| img.iter().map(|p| p[c]).collect::<Vec<f32>>();
        let y = convolve2(&plane(0), width, height, &ky, &ky);
        let cx = convolve2(&plane(1), width, height, &kx, &kx);
        let z = plane(2);
        let cz1 = convolve2(&z, width, height, &kz1, &kz1);
        let cz2 = convolve2(&z, width, height, &kz2, &kz2);
        (0..img.len())
            .map(|i| {
                let rgb = xyz_to_rgb(ycxcz_to_xyz([y[i], cx[i], cz1[i] + cz2[i]]))
                    .map(|c| c.clamp(0.0, 1.0));
                hunt(xyz_to_lab(rgb_to_xyz(rgb)))
            })
            .collect()
    };
    let (fr, ft) = (filter(r), filter(t));
    let cmax = cmax();
    let knee = PC * cmax;
    fr.iter()
        .zip(&ft)
        .map(|(&a, &b)| {
            let e = hyab(a, b).powf(QC);
            if e < knee {
                e * (PT / knee)
            } else {
                PT + (e - knee) / (cmax - knee) * (1.0 - PT)
            }
        })
        .collect()
}

/// The feature error (step 4) of each pixel.
fn feature_error(r: &[Px], t: &[Px], width: usize, height: usize, ppd: f32) -> Vec<f32> {
    let sd = 0.5 * FEATURE_WIDTH * ppd;
    let radius = (3.0 * sd).ceil() as i32;
    let xs: Vec<f32> = (-radius..=radius).map(|i| i as f32).collect();
    let g: Vec<f32> = xs
        .iter()
        .map(|&x| (-(x * x) / (2.0 * sd * sd)).exp())
        .collect();
    let dg: Vec<f32> = xs.iter().zip(&g).map(|(&x, &g)| -x * g).collect();
    let ddg: Vec<f32> = xs
        .iter()
        .zip(&g)
        .map(|(&x, &g)| (x * x / (sd * sd) - 1.0) * g)
        .collect();
    // The Gaussian sums to 1; the positive and the negative lobes of each derivative to 1 and
    // -1.
    let g_sum: f32 = g.iter().sum();
    let g: Vec<f32> = g.iter().map(|w| w / g_sum).collect();
    let lobes = |k: Vec<f32>| {
        let pos: f32 = k.iter().filter(|&&w| w > 0.0).sum();
        let neg: f32 = -k.iter().filter(|&&w| w <= 0.0).sum::<f32>();
        k.iter()
            .map(|&w| if w > 0.0 { w / pos } else { w / neg })
            .collect::<Vec<f32>>()
    };
    let (dg, ddg) = (lobes(dg), lobes(ddg));

    // Edge and point strengths of the normalised achromatic channel.
    let features = |img: &[Px]| -> (Vec<f32>, Vec<f32>) {
        let a: Vec<f32> = img.iter().map(|p| (p[0] + 16.0) / 116.0).collect();
        let dx = convolve2(&a, width, height, &dg, &g);
        let dy = convolve2(&a, width, height, &g, &dg);
        let ddx = convolve2(&a, width, height, &ddg, &g);
        let ddy = convolve2(&a, width, height, &g, &ddg);
        let edge = dx.iter().zip(&dy).map(|(x, y)| x.hypot(*y)).collect();
        let point = ddx.iter().zip(&ddy).map(|(x, y)| x.hypot(*y)).collect();
        (edge, point)
    };
    let ((er, pr), (et, pt)) = (features(r), features(t));
    (0..r.len())
        .map(|i| {
            let d = (er[i] - et[i]).abs().max((pr[i] - pt[i]).abs());
            (d / std::f32::consts::SQRT_2).powf(QF)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// How close our means must be to NVIDIA's flip-evaluator's (the tolerance).
    const TOLERANCE: f64 = 0.002;

    fn uniform(c: f32, n: usize) -> Vec<Px> {
        vec![[c; 3]; n]
    }

    #[test]
    fn identical_images_have_no_error() {
        let img: Vec<Px> = (0..20 * 15)
            .map(|i| {
                [
                    (i % 7) as f32 / 6.0,
                    (i % 5) as f32 / 4.0,
                    (i % 3) as f32 / 2.0,
                ]
            })
            .collect();
        let (map, mean) = flip(&img, &img, 20, 15, default_ppd());
        assert_eq!(mean, 0.0);
        assert!(map.iter().all(|&e| e == 0.0));
    }

    #[test]
    fn default_ppd_is_nvidias() {
        // flip_evaluator.evaluate(...)[2]["ppd"] = 67.02064514160156.
        assert!(
            (default_ppd() - 67.020_645).abs() < 1e-4,
            "{}",
            default_ppd()
        );
    }

    #[test]
    fn black_against_white_matches_flip_evaluator() {
        // flip_evaluator 1.x (pip install flip-evaluator), `evaluate(black, white, "LDR")` on
        // 16x16 images: mean 0.9673909544944763. Tolerance 0.002.
        let (map, mean) = flip(
            &uniform(0.0, 256),
            &uniform(1.0, 256),
            16,
            16,
            default_ppd(),
        );
        assert!(
            (mean - 0.967_390_954_494_476_3).abs() <= TOLERANCE,
            "{mean}"
        );
        assert!(map.iter().all(|&e| (0.0..=1.0).contains(&e)));
    }

    #[test]
    fn small_patch_matches_flip_evaluator() {
        // An 8x8 grey (0.5) reference; the test has an orange (1, 0.2, 0) 2x2 patch at rows
        // and columns 3..5. flip_evaluator's `evaluate(ref, test, "LDR")`: mean
        // 0.13052266836166382, row 4 of the map below. Tolerance 0.002.
        let reference = uniform(0.5, 64);
        let mut test = reference.clone();
        for y in 3..5 {
            for x in 3..5 {
                test[y * 8 + x] = [1.0, 0.2, 0.0];
            }
        }
        let (map, mean) = flip(&reference, &test, 8, 8, default_ppd());
        assert!(
            (mean - 0.130_522_668_361_663_82).abs() <= TOLERANCE,
            "{mean}"
        );
        let row4 = [
            0.057_380_19,
            0.128_686_16,
            0.301_851_7,
            0.457_181_2,
            0.457_181_2,
            0.301_851_7,
            0.128_686_67,
            0.057_380_22,
        ];
        for (x, want) in row4.iter().enumerate() {
            assert!(
                (map[4 * 8 + x] - want).abs() <= 0.002,
                "x {x}: {} vs {want}",
                map[4 * 8 + x]
            );
        }
    }

    #[test]
    fn errors_are_in_the_unit_interval() {
        let (w, h) = (23, 17);
        let a: Vec<Px> = (0..w * h)
            .map(|i| {
                [
                    ((i * 37) % 101) as f32 / 100.0,
                    ((i * 53) % 97) as f32 / 96.0,
                    ((i * 11) % 13) as f32 / 12.0,
                ]
            })
            .collect();
        let b: Vec<Px> = (0..w * h)
            .map(|i| {
                [
                    ((i * 29) % 89) as f32 / 88.0,
                    1.0 - ((i * 7) % 5) as f32 / 4.0,
                    ((i * 3) % 17) as f32 / 16.0 * 2.0 - 0.5,
                ]
            })
            .collect();
        let (map, mean) = flip(&a, &b, w, h, default_ppd());
        assert!(map.iter().all(|&e| (0.0..=1.0).contains(&e)), "{map:?}");
        // flip_evaluator's `evaluate(a, clip(b, 0, 1), "LDR")` on the same images (H x W x 3,
        // row-major): 0.42317643761634827. Tolerance 0.002.
        assert!(
            (mean - 0.423_176_437_616_348_27).abs() <= TOLERANCE,
            "{mean}"
        );
    }
}
