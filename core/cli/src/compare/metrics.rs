//! How far a render is from a reference: the relative mean squared error and the bias over
//! the whole image, and the per-pixel relative difference in false colour.

use crate::montage::{Image, diverging};
use foton_core::Rgb;

/// Added to the squared reference value in the relative error, so that black pixels of the
/// reference do not dominate it.
pub const REL_EPSILON: f64 = 1e-2;

/// Errors of a render against the reference, over all pixels and channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// mean of (x - ref)^2 / (ref^2 + REL_EPSILON).
    pub rel_mse: f64,
    /// (mean(x) - mean(ref)) / mean(ref); NaN when the reference is black.
    pub bias: f64,
}

pub fn errors(x: &[Rgb], reference: &[Rgb]) -> Errors {
    let (mut se, mut sx, mut sr) = (0.0f64, 0.0f64, 0.0f64);
    for (p, r) in x.iter().zip(reference) {
        for c in 0..3 {
            let (p, r) = (p[c] as f64, r[c] as f64);
            se += (p - r) * (p - r) / (r * r + REL_EPSILON);
            sx += p;
            sr += r;
        }
    }
    let n = (3 * x.len().max(1)) as f64;
    Errors {
        rel_mse: se / n,
        bias: if sr > 0.0 { (sx - sr) / sr } else { f64::NAN },
    }
}

/// "rel. MSE 1.2345e-3, bias +0.123%": the errors on a render's summary line.
pub(super) fn errors_text(e: Errors) -> String {
    format!("rel. MSE {:.4e}, bias {:+.3}%", e.rel_mse, e.bias * 100.0)
}

/// The signed relative difference of each pixel's channel mean, (x - ref) / sqrt(ref^2 +
/// REL_EPSILON) (the square root of a pixel's term of the relative MSE, with its sign), in
/// false colour.
pub fn difference_image(width: u32, height: u32, x: &[Rgb], reference: &[Rgb]) -> Image {
    let pixels = x
        .iter()
        .zip(reference)
        .map(|(p, r)| {
            let (p, r) = (
                foton_core::average(*p) as f64,
                foton_core::average(*r) as f64,
            );
            diverging(((p - r) / (r * r + REL_EPSILON).sqrt()) as f32)
        })
        .collect();
    Image {
        width,
        height,
        pixels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_of_an_identical_image_are_zero() {
        let x = [Rgb::new(0.1, 0.5, 2.0), Rgb::ZERO];
        assert_eq!(
            errors(&x, &x),
            Errors {
                rel_mse: 0.0,
                bias: 0.0
            }
        );
        let brighter: Vec<Rgb> = x.iter().map(|p| *p * 1.1).collect();
        let e = errors(&brighter, &x);
        assert!(e.rel_mse > 0.0);
        assert!((e.bias - 0.1).abs() < 1e-6, "{e:?}");
        assert!(errors(&x, &[Rgb::ZERO, Rgb::ZERO]).bias.is_nan());
    }
}
