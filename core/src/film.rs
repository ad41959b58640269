//! The film: per-pixel sums of radiance samples (exact, in fixed point: [`RadianceSum`]) and
//! their counts (a sample lands in its own pixel: the reconstruction filter is importance
//! sampled), and what an image file of it holds: linear EXR or sRGB PNG (the files themselves
//! are written and read by foton-loader's `image`, so that core links no image codec).
//!
//! **Splats.** Contributions that light paths bring to the camera land on any pixel: they are
//! summed apart, in a second exact buffer, and a pixel's value is its mean sample plus its
//! splat sum over the camera samples per pixel of the whole film (pbrt-v4's `AddSplat` and
//! `splatScale`; one light path per camera sample). Kept apart, the two sums merge exactly
//! across parts ([`Film::merge`]), and an interrupted render scales its splats by the samples
//! it actually took.
//!
//! An EXR holds the radiance as it is. A PNG holds display values: each linear value is
//! scaled by the exposure and tone mapped into [0, 1] ([`DisplayTransform`]), then encoded with
//! the sRGB curve. Every PNG foton writes goes through foton-loader's `write_image` so that the tools show
//! a scene the same way.

use crate::Rgb;
use crate::error::{Error, Result};
use crate::part::Part;
use std::path::Path;

/// Fractional bits of the film's fixed-point sums.
const FRACTION_BITS: i32 = 64;

/// An exact sum of radiance samples, one per channel: fixed point with 64 fractional bits in
/// an i128 (a resolution of 5e-20, sums up to 9e18). Integer addition is associative, so a
/// pixel's sum does not depend on the order its samples are added in: the image is the same
/// bit for bit whatever the thread count, the batches of samples and the parts a render is
/// split into and merged from (`foton render --part`, `foton merge`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RadianceSum(pub [i128; 3]);

/// `a.saturating_add(b)` where the sum overflows (out of line: sums of radiance never get there).
#[cold]
#[inline(never)]
fn saturated(a: i128, b: i128) -> i128 {
    a.saturating_add(b)
}

impl RadianceSum {
    pub const ZERO: RadianceSum = RadianceSum([0; 3]);

    /// A value in fixed point, rounded towards zero below the resolution; saturates beyond
    /// the range (non-finite samples are zeroed before they get here).
    #[inline]
    fn fixed(x: f64) -> i128 {
        const ONE: f64 = (1u128 << FRACTION_BITS) as f64;
        if (0.0..9.0e18).contains(&x) {
            // The same value as the general conversion below, without its library call (a
            // few percent of a cheap camera sample): the integer part by one truncating
            // instruction, the fraction (exact: x minus its integer part) scaled by 2^64.
            let whole = x as i64;
            let fraction = ((x - whole as f64) * ONE) as u64;
            ((whole as i128) << FRACTION_BITS) | fraction as i128
        } else {
            (x * ONE) as i128
        }
    }

    /// [`RadianceSum::fixed`] of an f32, from its bits: below 2^63 (non-negative) the value is
    /// m 2^(e - 150) with m its 24-bit significand and e its biased exponent (1 for a
    /// subnormal), so its fixed-point value, floor(x 2^64), is m shifted by e - 86 places
    /// (left up to 103 places, or right, where the bits shifted out are the truncation). The
    /// same value as the conversion through f64 (unit test `fixed_f32_matches_fixed`) in about
    /// a third of its instructions (its saturating conversions and the unsigned 64-bit one,
    /// which x86 lacks): three per camera sample. Negative values and from 2^63 on: `fixed`.
    #[inline]
    fn fixed_f32(x: f32) -> i128 {
        let bits = x.to_bits();
        // Sign bit clear, biased exponent below 127 + 63.
        if bits >= 190 << 23 {
            return Self::fixed(x as f64);
        }
        let exponent = bits >> 23;
        let significand = (bits & 0x7F_FFFF) | ((exponent > 0) as u32) << 23;
        let shift = exponent.max(1) as i32 - 86;
        if shift >= 0 {
            (significand as i128) << shift
        } else {
            // Right by 24 places or more leaves nothing.
            (significand as u64 >> (-shift).min(63)) as i128
        }
    }

    #[inline]
    pub fn add(&mut self, radiance: Rgb) {
        for (s, x) in self.0.iter_mut().zip([radiance.x, radiance.y, radiance.z]) {
            let v = Self::fixed_f32(x);
            // `saturating_add`, its saturation out of line: an add with carry and a branch on
            // overflow per channel, where the saturating form selects on every add.
            *s = match s.checked_add(v) {
                Some(sum) => sum,
                None => saturated(*s, v),
            };
        }
    }

    #[inline]
    pub fn add_f64(&mut self, radiance: [f64; 3]) {
        for (s, x) in self.0.iter_mut().zip(radiance) {
            *s = s.saturating_add(Self::fixed(x));
        }
    }

    #[inline]
    pub fn merge(&mut self, other: &RadianceSum) {
        for (s, x) in self.0.iter_mut().zip(other.0) {
            *s = s.saturating_add(x);
        }
    }

    /// The sum as floating point.
    pub fn to_f64(&self) -> [f64; 3] {
        self.0.map(|s| s as f64 * 2f64.powi(-FRACTION_BITS))
    }
}

/// One sampling technique's share of the image (`foton render --techniques`): exact sums of
/// the contributions that technique made, to the camera samples and to the splats, kept as the
/// film's own. Its pixels are made with the film's sample counts and splat scale
/// ([`Film::layer_pixels`]), so that a film's layers sum to its image (to float rounding)
/// when the integrator gives every contribution to exactly one technique.
#[derive(Clone, Debug)]
pub struct Layer {
    /// The technique's name, as the EXR's channels `<name>.R`, `<name>.G`, `<name>.B` carry it.
    pub name: String,
    sum: Vec<RadianceSum>,
    /// Empty until the technique's first splat.
    splat: Vec<RadianceSum>,
}

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    sum: Vec<RadianceSum>,
    count: Vec<u32>,
    /// Splatted contributions (light paths connected to the camera, which land on any pixel):
    /// exact sums as `sum`, empty for an integrator that does not splat. See [`Film::pixel`].
    splat: Vec<RadianceSum>,
    /// The share of the render this film holds (set by the render loop from
    /// `RenderContext::part`; [`Part::WHOLE`] unless the render was asked for a part).
    pub part: Part,
    /// Rays traced to make the image (statistics; 0 if the integrator does not count).
    pub rays: u64,
    /// Iterations a progressive integrator (sppm) completed; 0 for the others, whose work is
    /// counted in samples ([`Film::total_samples`]).
    pub iterations: u64,
    /// The iterations the progressive integrator was asked for; 0 when it has no fixed number
    /// (a time budget), or is not progressive. Fewer `iterations` mean it was interrupted.
    pub iterations_planned: u64,
    /// Photons emitted over all the iterations of a progressive integrator; 0 for the others.
    pub photons: u64,
    /// Each technique's share of the image, when the render was asked for them
    /// (`RenderContext::techniques`); empty otherwise.
    layers: Vec<Layer>,
    /// The camera's response, a matrix on each pixel's linear sRGB value (`[film]
    /// white_balance`); None: the radiance as rendered. The sums stay unchanged: parts and
    /// merges add them before the matrix applies.
    pub color_matrix: Option<glam::DMat3>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            sum: vec![RadianceSum::ZERO; n],
            count: vec![0; n],
            splat: Vec::new(),
            part: Part::WHOLE,
            rays: 0,
            iterations: 0,
            iterations_planned: 0,
            photons: 0,
            layers: Vec::new(),
            color_matrix: None,
        }
    }

    /// A film from its per-pixel sums and sample counts (row-major), as a partial result
    /// stores them, and its splat sums (empty: none). None if the lengths do not match the
    /// size.
    pub fn from_sums(
        width: u32,
        height: u32,
        sum: Vec<RadianceSum>,
        count: Vec<u32>,
        splat: Vec<RadianceSum>,
    ) -> Option<Film> {
        let n = width as usize * height as usize;
        if sum.len() != n || count.len() != n || !(splat.is_empty() || splat.len() == n) {
            return None;
        }
        Some(Film {
            width,
            height,
            sum,
            count,
            splat,
            ..Film::new(0, 0)
        })
    }

    /// Adds a splat sum to pixel `i` (pbrt-v4's `AddSplat`; the film keeps a splat buffer from
    /// the first one on). Integer sums: the order splats arrive in does not matter.
    pub fn add_splat(&mut self, i: usize, sum: &RadianceSum) {
        if self.splat.is_empty() {
            self.splat = vec![RadianceSum::ZERO; self.sum.len()];
        }
        self.splat[i].merge(sum);
    }

    /// The per-pixel splat sums, row-major; empty if nothing was splatted.
    pub fn splats(&self) -> &[RadianceSum] {
        &self.splat
    }

    /// What a splat sum is multiplied by in a pixel's value: one over the camera samples per
    /// pixel taken over the whole image (pbrt-v4's `splatScale`), as their total over the
    /// pixel count, so that an interrupted render, whose pixels hold different counts, scales
    /// its splats by the samples actually taken (each camera sample traced one light path).
    fn splat_scale(&self) -> f64 {
        let total = self.total_samples();
        if total == 0 {
            0.0
        } else {
            self.sum.len() as f64 / total as f64
        }
    }

    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    #[inline]
    pub fn add_sample(&mut self, x: u32, y: u32, radiance: Rgb) {
        let i = self.index(x, y);
        self.sum[i].add(radiance);
        self.count[i] += 1;
    }

    /// Adds another film's sums, counts and splats (merging parts).
    pub fn merge(&mut self, other: &Film) {
        for (i, (sum, n)) in other.sums().iter().zip(other.counts()).enumerate() {
            self.add_pixel(i, sum, *n);
        }
        for (i, s) in other.splats().iter().enumerate() {
            self.add_splat(i, s);
        }
        for layer in &other.layers {
            let k = self.add_layer(&layer.name);
            for (i, s) in layer.sum.iter().enumerate() {
                self.add_layer_pixel(k, i, s);
            }
            for (i, s) in layer.splat.iter().enumerate() {
                self.add_layer_splat(k, i, s);
            }
        }
    }

    /// The index of the technique layer `name`, added (black) if the film has none of that
    /// name yet.
    pub fn add_layer(&mut self, name: &str) -> usize {
        if let Some(k) = self.layers.iter().position(|l| l.name == name) {
            return k;
        }
        self.layers.push(Layer {
            name: name.to_string(),
            sum: vec![RadianceSum::ZERO; self.sum.len()],
            splat: Vec::new(),
        });
        self.layers.len() - 1
    }

    /// The technique layers, in the order they were added.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// Adds to pixel `i` of layer `k` the sum of its technique's shares of camera samples the
    /// film counts (with [`Film::add_pixel`]) in the pixel.
    pub fn add_layer_pixel(&mut self, k: usize, i: usize, sum: &RadianceSum) {
        self.layers[k].sum[i].merge(sum);
    }

    /// Adds to pixel `i` of layer `k` a splat sum of its technique (one also given to
    /// [`Film::add_splat`]).
    pub fn add_layer_splat(&mut self, k: usize, i: usize, sum: &RadianceSum) {
        let layer = &mut self.layers[k];
        if layer.splat.is_empty() {
            layer.splat = vec![RadianceSum::ZERO; self.sum.len()];
        }
        layer.splat[i].merge(sum);
    }

    /// The pixels of layer `k`, row-major: its sums over the film's sample counts, plus its
    /// splats times the film's splat scale, as [`Film::pixels`] makes the image.
    pub fn layer_pixels(&self, k: usize) -> Vec<Rgb> {
        let scale = self.splat_scale();
        let layer = &self.layers[k];
        (0..self.sum.len())
            .map(|i| {
                let v = value(&layer.sum[i], self.count[i], layer.splat.get(i), scale);
                self.respond(v)
            })
            .collect()
    }

    /// Adds a pixel's accumulated sum and count (used when merging tiles and parts).
    pub fn add_pixel(&mut self, i: usize, sum: &RadianceSum, count: u32) {
        self.sum[i].merge(sum);
        self.count[i] += count;
    }

    /// Sets a pixel's value directly as if from one sample (for integrators that produce
    /// whole estimates, e.g. progressive photon mapping).
    pub fn set_pixel(&mut self, x: u32, y: u32, value: Rgb) {
        let i = self.index(x, y);
        self.sum[i] = RadianceSum::ZERO;
        self.sum[i].add(value);
        self.count[i] = 1;
    }

    /// The per-pixel sums, row-major.
    pub fn sums(&self) -> &[RadianceSum] {
        &self.sum
    }

    /// The per-pixel sample counts, row-major.
    pub fn counts(&self) -> &[u32] {
        &self.count
    }

    pub fn sample_count(&self, x: u32, y: u32) -> u32 {
        self.count[self.index(x, y)]
    }

    pub fn total_samples(&self) -> u64 {
        self.count.iter().map(|&c| c as u64).sum()
    }

    /// Pixel value: the mean of its samples, each pixel divided by its own count (an
    /// interrupted render has pixels with different counts; black without samples), plus its
    /// splat sum times [`Film::splat_scale`].
    pub fn pixel(&self, x: u32, y: u32) -> Rgb {
        self.pixel_at(self.index(x, y), self.splat_scale())
    }

    fn pixel_at(&self, i: usize, splat_scale: f64) -> Rgb {
        self.respond(value(
            &self.sum[i],
            self.count[i],
            self.splat.get(i),
            splat_scale,
        ))
    }

    /// A pixel's value through the camera's response ([`Film::color_matrix`]).
    #[inline]
    fn respond(&self, v: glam::DVec3) -> Rgb {
        match self.color_matrix {
            Some(m) => (m * v).as_vec3(),
            None => v.as_vec3(),
        }
    }

    /// All pixels, row-major from the top-left.
    pub fn pixels(&self) -> Vec<Rgb> {
        let scale = self.splat_scale();
        (0..self.sum.len())
            .map(|i| self.pixel_at(i, scale))
            .collect()
    }

    /// Mean of all pixel values.
    pub fn mean(&self) -> Rgb {
        let px = self.pixels();
        let sum: glam::DVec3 = px.iter().map(|p| p.as_dvec3()).sum();
        (sum / px.len().max(1) as f64).as_vec3()
    }
}

/// A pixel's value from its sum of `n` samples and its splat sum (if any): the mean sample
/// plus the splats times `splat_scale`.
#[inline]
fn value(sum: &RadianceSum, n: u32, splat: Option<&RadianceSum>, splat_scale: f64) -> glam::DVec3 {
    let mut v = [0.0f64; 3];
    if n > 0 {
        let s = sum.to_f64();
        v = s.map(|s| s / n as f64);
    }
    if let Some(splat) = splat {
        let s = splat.to_f64();
        for c in 0..3 {
            v[c] += s[c] * splat_scale;
        }
    }
    glam::DVec3::from(v)
}

/// How exposed radiance is squeezed into the [0, 1] an 8-bit image can hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ToneMap {
    /// Values above 1 are cut to 1 (white): exact below 1, so that tests can compare pixels
    /// with radiance.
    #[default]
    Clamp,
    /// [`filmic`]: a smooth shoulder that keeps detail in highlights up to about 7 and
    /// desaturates them towards white.
    Filmic,
}

impl ToneMap {
    /// The names `[film] tonemap` takes, in the order of the documentation.
    pub const NAMES: [&'static str; 2] = ["clamp", "filmic"];

    pub fn from_name(name: &str) -> Option<ToneMap> {
        match name {
            "clamp" => Some(ToneMap::Clamp),
            "filmic" => Some(ToneMap::Filmic),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ToneMap::Clamp => "clamp",
            ToneMap::Filmic => "filmic",
        }
    }

    /// The display value in [0, 1] of an exposed linear value; negative and NaN give 0 (a NaN
    /// pixel is a bug to see as black, not a reason to fail writing the image).
    #[inline]
    pub fn apply(self, x: f32) -> f32 {
        // `max` returns the other operand for NaN, so NaN becomes 0 here.
        let x = x.max(0.0);
        match self {
            ToneMap::Clamp => x.min(1.0),
            ToneMap::Filmic => filmic(x),
        }
    }
}

/// The ACES filmic curve as fitted by Krzysztof Narkowicz ("ACES Filmic Tone Mapping Curve",
/// 2016), applied to each channel:
///
/// ```text
/// f(x) = min(1, x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14))     for x >= 0
/// ```
///
/// It maps 0 to 0, rises monotonically (its derivative's numerator is 1.408 x^2 + 0.7028 x +
/// 0.0042 > 0), gives 0.80 at x = 1 and reaches 1 at x = 7.24, above which it stays at 1. The
/// fit is to ACES's RRT + ODT with its input pre-exposed so that an image keeps roughly its
/// untone-mapped brightness; the unexposed ACES curve is f(0.6 x), i.e. `exposure = -0.737`.
#[inline]
pub fn filmic(x: f32) -> f32 {
    let x = x.max(0.0);
    if x.is_infinite() {
        return 1.0;
    }
    let (a, b, c, d, e) = (2.51f32, 0.03f32, 2.43f32, 0.59f32, 0.14f32);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).min(1.0)
}

/// The display transform of 8-bit outputs: linear radiance is multiplied by 2^`exposure`,
/// then tone mapped into [0, 1] (then a PNG encodes it with the sRGB curve). From the scene's
/// `[film] exposure` and `tonemap`; the default (0 stops, clamp) is the plain clip.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DisplayTransform {
    /// In stops (powers of two).
    pub exposure: f32,
    pub tonemap: ToneMap,
}

impl DisplayTransform {
    pub fn new(exposure: f32, tonemap: ToneMap) -> DisplayTransform {
        DisplayTransform { exposure, tonemap }
    }

    /// The display value in [0, 1] (linear, before the sRGB curve) of linear radiance `c`.
    #[inline]
    pub fn map(&self, c: Rgb) -> Rgb {
        let scale = self.exposure.exp2();
        let f = |x: f32| self.tonemap.apply(x * scale);
        Rgb::new(f(c.x), f(c.y), f(c.z))
    }

    /// The 8-bit sRGB value a PNG stores for linear radiance `c`.
    #[inline]
    pub fn encode(&self, c: Rgb) -> [u8; 3] {
        self.map(c)
            .to_array()
            .map(|v| (srgb_encode(v) * 255.0 + 0.5) as u8)
    }
}

/// sRGB transfer curve (IEC 61966-2-1) of a linear value in [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    let c = linear.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`srgb_encode`]: the linear value of an sRGB-encoded one in [0, 1].
pub fn srgb_decode(encoded: f32) -> f32 {
    let c = encoded.clamp(0.0, 1.0);
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The format an output path asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Exr,
    Png,
}

pub fn format_of(path: &Path) -> Result<ImageFormat> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .as_deref()
    {
        Some("exr") => Ok(ImageFormat::Exr),
        Some("png") => Ok(ImageFormat::Png),
        _ => Err(Error::io(
            path,
            "unsupported output format: use .exr (linear float32) or .png (sRGB 8-bit)",
        )),
    }
}

/// Checks before rendering that an output can be written: known extension, existing and
/// writable folder. Finding out after a long render would lose it.
pub fn check_output(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::io(
            path,
            "is a directory, not a file: name the image in it (e.g. render.exr or render.png)",
        ));
    }
    format_of(path)?;
    check_writable(path)
}

/// Checks that `path` can be written, as [`check_output`] does, whatever its format.
pub fn check_writable(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::io(path, "is a directory, not a file"));
    }
    if path.exists() && !path.is_file() {
        return Err(Error::io(
            path,
            "the output exists and is not a regular file",
        ));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if dir.exists() && !dir.is_dir() {
        return Err(Error::io(
            path,
            format!("{} is not a folder", dir.display()),
        ));
    }
    if !dir.is_dir() {
        return Err(Error::io(
            path,
            format!("output folder {} does not exist", dir.display()),
        ));
    }
    let probe = dir.join(format!(".foton-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| {
        Error::io(
            path,
            format!("output folder {} is not writable: {e}", dir.display()),
        )
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sums saturate at the ends of the range, as `saturating_add` made them.
    #[test]
    fn radiance_sums_saturate() {
        let mut sum = RadianceSum([i128::MAX - 5, i128::MIN + 5, 7]);
        sum.add(Rgb::new(1.0, -1.0, 2.0));
        assert_eq!(sum.0[0], i128::MAX);
        assert_eq!(sum.0[1], i128::MIN);
        assert_eq!(sum.0[2], 7 + (2i128 << 64));
        sum.add(Rgb::new(f32::MAX, 0.0, 0.0));
        assert_eq!(sum.0[0], i128::MAX);
    }

    /// The f32 conversion from the bits gives the f64 conversion's value for every kind of
    /// f32: zeros, subnormals, the whole exponent range around both ends of the fast path,
    /// negative values, infinities and NaN (what `add` took before).
    #[test]
    fn fixed_f32_matches_fixed() {
        let mut rng = crate::sampling::Rng::new(&[11]);
        let mut values = vec![
            0.0f32,
            -0.0,
            f32::MIN_POSITIVE,
            f32::from_bits(1),
            f32::from_bits(0x7F_FFFF),
            1.0,
            0.5,
            9.0e18,
            9.3e18,
            2f32.powi(63),
            f32::from_bits(2f32.powi(63).to_bits() - 1),
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -1.0,
            -1e-30,
            2f32.powi(-64),
            2f32.powi(-65),
            1.5 * 2f32.powi(-64),
        ];
        for _ in 0..200_000 {
            values.push(f32::from_bits(rng.next_u32()));
            // Mostly the range radiance lives in.
            values.push(rng.next_f32() * 2f32.powi((rng.next_u32() % 80) as i32 - 40));
        }
        for x in values {
            assert_eq!(
                RadianceSum::fixed_f32(x),
                RadianceSum::fixed(x as f64),
                "{x:e} ({:#x})",
                x.to_bits()
            );
        }
    }

    #[test]
    fn filmic_is_its_formula_monotonic_and_bounded() {
        assert_eq!(filmic(0.0), 0.0);
        // Values of x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14) worked out by hand.
        for (x, f) in [
            (0.18, 0.086_724 / 0.324_932),
            (1.0, 2.54 / 3.16),
            (4.0, 40.28 / 41.38),
        ] {
            assert!(
                (filmic(x) - f).abs() < 1e-5,
                "f({x}) = {} vs {f}",
                filmic(x)
            );
        }
        let mut last = 0.0;
        for i in 1..=100_000 {
            let x = i as f32 * 1e-3;
            let f = filmic(x);
            assert!(f >= last, "f decreases at {x}: {f} < {last}");
            // Strictly increasing up to where it reaches 1 (x = 7.24).
            assert!(x > 7.2 || f > last, "f is flat at {x}");
            assert!(f <= 1.0, "f({x}) = {f}");
            last = f;
        }
        for x in [1e3, 1e10, f32::MAX, f32::INFINITY] {
            assert_eq!(filmic(x), 1.0, "{x}");
        }
        assert!(filmic(7.0) < 1.0);
        // No negative or undefined display values.
        assert_eq!(ToneMap::Filmic.apply(-1.0), 0.0);
        assert_eq!(ToneMap::Filmic.apply(f32::NAN), 0.0);
    }

    #[test]
    fn display_transform_exposes_then_tone_maps() {
        let clamp = |e| DisplayTransform::new(e, ToneMap::Clamp);
        assert_eq!(
            clamp(-1.0).map(Rgb::new(1.5, 0.5, 4.0)),
            Rgb::new(0.75, 0.25, 1.0)
        );
        assert_eq!(
            clamp(2.0).map(Rgb::new(0.1, -1.0, f32::NAN)),
            Rgb::new(0.4, 0.0, 0.0)
        );
        let filmic_one = DisplayTransform::new(1.0, ToneMap::Filmic).map(Rgb::splat(0.5));
        assert!((filmic_one.x - filmic(1.0)).abs() < 1e-7);
        // The default is the plain clip.
        assert_eq!(DisplayTransform::default(), clamp(0.0));
        assert_eq!(
            DisplayTransform::default().encode(Rgb::new(0.0, 1.0, 7.0)),
            [0, 255, 255]
        );
        for name in ToneMap::NAMES {
            assert_eq!(ToneMap::from_name(name).unwrap().name(), name);
        }
        assert_eq!(ToneMap::from_name("aces"), None);
    }

    /// A pixel is its mean sample plus its splat sum over the camera samples per pixel of the
    /// whole film, taken as they were: an interrupted render (pixels with different counts)
    /// scales its splats by the samples it took, and merged films add exactly.
    #[test]
    fn splats_are_scaled_by_the_samples_taken() {
        let mut film = Film::new(2, 1);
        let sum = |v: f32| {
            let mut s = RadianceSum::ZERO;
            s.add(Rgb::splat(v));
            s
        };
        // Pixel 0 took 4 samples, pixel 1 only 2 (interrupted): 3 per pixel on average.
        film.add_pixel(0, &sum(2.0), 4);
        film.add_pixel(1, &sum(1.0), 2);
        assert_eq!(film.pixel(1, 0), Rgb::splat(0.5));
        film.add_splat(0, &sum(0.75));
        film.add_splat(1, &sum(1.5));
        assert_eq!(film.pixel(0, 0), Rgb::splat(0.5 + 0.25));
        assert_eq!(film.pixel(1, 0), Rgb::splat(0.5 + 0.5));
        // Two such films merged: sums, counts and splats add; the image is the same.
        let mut merged = Film::new(2, 1);
        merged.merge(&film);
        merged.merge(&film);
        assert_eq!(merged.pixels(), film.pixels());
        assert_eq!(merged.splats()[1], {
            let mut s = sum(1.5);
            s.merge(&sum(1.5));
            s
        });
        // A film without splats has no splat buffer.
        assert!(Film::new(2, 1).splats().is_empty());
    }

    /// Technique layers: their pixels use the film's counts and splat scale, so that they
    /// sum to the image (an interrupted render's uneven counts and the splats included), and
    /// merging films adds their layers by name.
    #[test]
    fn layers_sum_to_the_image() {
        let sum = |v: f32| {
            let mut s = RadianceSum::ZERO;
            s.add(Rgb::splat(v));
            s
        };
        let mut film = Film::new(2, 1);
        let (a, b) = (film.add_layer("a"), film.add_layer("b"));
        assert_eq!((a, b, film.add_layer("a")), (0, 1, 0));
        // Pixel 0: 4 samples of 0.5 = 0.25 (a) + 0.25 (b); pixel 1: 2 samples of 0.5, all a.
        film.add_pixel(0, &sum(2.0), 4);
        film.add_layer_pixel(a, 0, &sum(1.0));
        film.add_layer_pixel(b, 0, &sum(1.0));
        film.add_pixel(1, &sum(1.0), 2);
        film.add_layer_pixel(a, 1, &sum(1.0));
        // Splats on pixel 1, all b's.
        film.add_splat(1, &sum(0.75));
        film.add_layer_splat(b, 1, &sum(0.75));
        let total = |f: &Film| -> Vec<Rgb> {
            let (la, lb) = (f.layer_pixels(0), f.layer_pixels(1));
            la.iter().zip(&lb).map(|(x, y)| *x + *y).collect()
        };
        assert_eq!(total(&film), film.pixels());
        assert_eq!(film.layer_pixels(b)[1], Rgb::splat(0.25));
        let mut merged = Film::new(2, 1);
        merged.merge(&film);
        merged.merge(&film);
        assert_eq!(merged.layers().len(), 2);
        assert_eq!(total(&merged), merged.pixels());
        assert_eq!(merged.pixels(), film.pixels());
    }

    #[test]
    fn srgb_decode_inverts_encode() {
        for i in 0..=1000 {
            let x = i as f32 / 1000.0;
            assert!((srgb_decode(srgb_encode(x)) - x).abs() < 1e-5, "{x}");
        }
        assert_eq!(srgb_decode(0.0), 0.0);
        assert!((srgb_decode(1.0) - 1.0).abs() < 1e-6);
    }
}
