//! Spectra reduced to linear sRGB (ITU-R BT.709 primaries) as Mitsuba's RGB variants reduce
//! them: a spectrum given at some wavelengths, linear between them, is integrated against the
//! CIE 1931 colour-matching functions x̄, ȳ, z̄ and the XYZ tristimulus values are turned into
//! sRGB with the BT.709 matrix.
//!
//! Mitsuba 3 (`spectrum_list_to_srgb`) sums N = 1000 evenly spaced wavelengths λᵢ over
//! [360, 830] nm, skipping those outside the spectrum's range, with the CMFs tabulated every
//! 5 nm, linear between:
//!
//! ```text
//!     XYZ = (830 - 360) / N · Σᵢ s(λᵢ) · w(λᵢ) · (x̄, ȳ, z̄)(λᵢ) / ∫ȳ
//! ```
//!
//! where ∫ȳ = 106.7502593994140625 and w is the D65 illuminant (normalised so that its ȳ
//! integral is 1) for what reflects, and 1 for what emits. A reflectance is then clamped to
//! [0, 1]; every other quantity only to ≥ 0.
//!
//! Mitsuba 0.6 (`Spectrum::fromContinuousSpectrum` in RGB builds) integrates over
//! [360, 830] nm with the CMFs every 1 nm, never weights by D65, and normalises by the ȳ
//! integral of that table: XYZ = ∫ s · (x̄, ȳ, z̄) / ∫ ȳ. Here the integral is exact for
//! piecewise-linear spectra (two-point Gauss-Legendre between consecutive knots of s and of
//! the table), which Mitsuba 0.6's adaptive quadrature approximates to its tolerance (1e-4).
//!
//! The tables (`data/spectra/`) are the CIE's; the named conductors' indices of refraction
//! are the measured spectra Mitsuba ships. `data/spectra/README.md` gives their sources.

use glam::{DMat3, DVec3};
use std::sync::LazyLock;

/// A spectrum given at increasing wavelengths (nm), linear between them.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    pub wavelengths: Vec<f64>,
    pub values: Vec<f64>,
}

/// How Mitsuba 3 reduces a spectrum, by the quantity it stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// A reflectance (or any colour a BSDF, texture or medium reads): seen under D65, so that
    /// a spectrum of 1 is white, and clamped to [0, 1].
    Reflectance,
    /// A spectral parameter with no upper bound (a conductor's `eta` and `k` given as a
    /// spectrum, a roughness): seen under D65, clamped only to ≥ 0.
    Unbounded,
    /// What an emitter emits, and the named conductors' indices (Mitsuba's `ior_from_file`):
    /// not weighted by an illuminant, clamped only to ≥ 0.
    Emission,
}

impl Spectrum {
    /// At least two entries, at strictly increasing wavelengths.
    pub fn new(wavelengths: Vec<f64>, values: Vec<f64>) -> Result<Spectrum, String> {
        if wavelengths.len() != values.len() {
            return Err(format!(
                "{} wavelengths but {} values",
                wavelengths.len(),
                values.len()
            ));
        }
        if wavelengths.len() < 2 {
            return Err("a spectrum needs at least two wavelengths".into());
        }
        if let Some(w) = wavelengths.windows(2).find(|w| w[1] <= w[0]) {
            return Err(format!(
                "wavelengths must increase, but {} comes after {}",
                w[1], w[0]
            ));
        }
        if let Some(x) = wavelengths.iter().chain(&values).find(|x| !x.is_finite()) {
            return Err(format!("{x} is not a finite number"));
        }
        Ok(Spectrum {
            wavelengths,
            values,
        })
    }

    /// `"400:0.1, 500:0.5 600:0.8"`: wavelength:value pairs separated by commas and/or
    /// whitespace (Mitsuba's `<spectrum value>`).
    pub fn parse_pairs(text: &str) -> Result<Spectrum, String> {
        let (mut wavelengths, mut values) = (Vec::new(), Vec::new());
        for token in text
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
        {
            let pair = token.split_once(':').and_then(|(w, v)| {
                Some((w.trim().parse::<f64>().ok()?, v.trim().parse::<f64>().ok()?))
            });
            let Some((w, v)) = pair else {
                return Err(format!("`{token}` is not a wavelength:value pair"));
            };
            wavelengths.push(w);
            values.push(v);
        }
        Spectrum::new(wavelengths, values)
    }

    /// A `.spd` file's text: one `wavelength value` pair per line, `#` starting a comment.
    pub fn parse_spd(text: &str) -> Result<Spectrum, String> {
        let (mut wavelengths, mut values) = (Vec::new(), Vec::new());
        for (i, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("");
            let numbers: Vec<&str> = line.split_whitespace().collect();
            if numbers.is_empty() {
                continue;
            }
            let pair = match numbers[..] {
                [w, v] => w.parse::<f64>().ok().zip(v.parse::<f64>().ok()),
                _ => None,
            };
            let Some((w, v)) = pair else {
                return Err(format!(
                    "line {}: expected a wavelength and a value, found `{}`",
                    i + 1,
                    line.trim()
                ));
            };
            wavelengths.push(w);
            values.push(v);
        }
        Spectrum::new(wavelengths, values).map_err(|e| format!("{e} (in the whole file)"))
    }

    /// The value at `lambda` (nm), linear between the given wavelengths; None outside them.
    pub fn eval(&self, lambda: f64) -> Option<f64> {
        let (w, v) = (&self.wavelengths, &self.values);
        if lambda < w[0] || lambda > w[w.len() - 1] {
            return None;
        }
        let i = w.partition_point(|&x| x <= lambda).clamp(1, w.len() - 1) - 1;
        let t = (lambda - w[i]) / (w[i + 1] - w[i]);
        Some(v[i] + t * (v[i + 1] - v[i]))
    }

    /// Linear sRGB as Mitsuba 3's RGB variants reduce the spectrum for `quantity`.
    pub fn to_srgb(&self, quantity: Quantity) -> DVec3 {
        to_srgb(|lambda| self.eval(lambda), quantity)
    }

    /// Linear sRGB as Mitsuba 0.6's RGB builds reduce the spectrum (zero outside its range),
    /// negative components kept.
    pub fn to_srgb_v06(&self) -> DVec3 {
        to_srgb_v06(|lambda| self.eval(lambda).unwrap_or(0.0), &self.wavelengths)
    }

    /// Mitsuba 0.6's `zeroExtend`: a zero one average spacing before the first value and after
    /// the last, where those are not zero already (how its scene parser takes spectra).
    pub fn zero_extended(&self) -> Spectrum {
        let (mut w, mut v) = (self.wavelengths.clone(), self.values.clone());
        let spacing = (w[w.len() - 1] - w[0]) / (w.len() - 1) as f64;
        if v[0] != 0.0 {
            w.insert(0, w[0] - spacing);
            v.insert(0, 0.0);
        }
        if v[v.len() - 1] != 0.0 {
            w.push(w[w.len() - 1] + spacing);
            v.push(0.0);
        }
        Spectrum {
            wavelengths: w,
            values: v,
        }
    }
}

/// The CMFs' range in nm.
const CIE_MIN: f64 = 360.0;
const CIE_MAX: f64 = 830.0;
/// Mitsuba 3's ∫ȳ over its table, and the ȳ integral of its D65 table.
const CIE_Y_INTEGRAL: f64 = 106.75025939941406;
const D65_Y_INTEGRAL: f64 = 98.99741751876255;

/// The CIE tables every 1 nm from 360 nm: x̄, ȳ, z̄ and D65.
struct Cie {
    xyz: Vec<DVec3>,
    d65: Vec<f64>,
}

static CIE: LazyLock<Cie> = LazyLock::new(|| {
    let mut cie = Cie {
        xyz: Vec::new(),
        d65: Vec::new(),
    };
    let text = include_str!("../data/spectra/cie1931_d65.txt");
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let x: Vec<f64> = line
            .split_whitespace()
            .map(|x| {
                x.parse()
                    .expect("core/data/spectra/cie1931_d65.txt is numbers")
            })
            .collect();
        cie.xyz.push(DVec3::new(x[1], x[2], x[3]));
        cie.d65.push(x[4]);
    }
    assert_eq!(
        cie.xyz.len(),
        471,
        "cie1931_d65.txt: 360 to 830 nm every 1 nm"
    );
    cie
});

/// A table of samples every `step` nm from 360 nm, linear between them (as Mitsuba 3 reads
/// its tables: the last interval extends the line past 830 nm, where nothing reads it).
fn lerp_table<T>(table: &[T], step: usize, lambda: f64) -> T
where
    T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
{
    let n = (table.len() - 1) / step;
    let t = (lambda - CIE_MIN) / step as f64;
    let i = (t.max(0.0) as usize).min(n - 1);
    let w = t - i as f64;
    table[i * step] * (1.0 - w) + table[(i + 1) * step] * w
}

/// CIE XYZ to linear sRGB (BT.709 primaries, D65 white), with Mitsuba's coefficients (in
/// single precision, as Mitsuba writes them).
pub fn xyz_to_srgb(xyz: DVec3) -> DVec3 {
    let m = |a: f32, b: f32, c: f32| DVec3::new(a.into(), b.into(), c.into());
    DVec3::new(
        m(3.240479, -1.53715, -0.498535).dot(xyz),
        m(-0.969256, 1.875991, 0.041556).dot(xyz),
        m(0.055648, -0.204043, 1.057311).dot(xyz),
    )
}

/// Mitsuba 3's `spectrum_list_to_srgb` of the spectrum `s` (None: outside its range).
pub fn to_srgb(s: impl Fn(f64) -> Option<f64>, quantity: Quantity) -> DVec3 {
    let rgb = xyz_to_srgb(to_xyz(s, quantity)).max(DVec3::ZERO);
    match quantity {
        Quantity::Reflectance => rgb.min(DVec3::ONE),
        _ => rgb,
    }
}

fn to_xyz(s: impl Fn(f64) -> Option<f64>, quantity: Quantity) -> DVec3 {
    const STEPS: usize = 1000;
    let cie = &*CIE;
    let mut xyz = DVec3::ZERO;
    for i in 0..STEPS {
        let lambda = CIE_MIN + (i as f64 / (STEPS - 1) as f64) * (CIE_MAX - CIE_MIN);
        let Some(value) = s(lambda) else { continue };
        let illuminant = match quantity {
            Quantity::Emission => 1.0,
            _ => lerp_table(&cie.d65, 5, lambda) / D65_Y_INTEGRAL,
        };
        xyz += lerp_table(&cie.xyz, 5, lambda) * value * illuminant;
    }
    xyz * (CIE_MAX - CIE_MIN) / (CIE_Y_INTEGRAL * STEPS as f64)
}

/// Mitsuba 3's reduction of a spectrum of constant `value` in an emitter: not white, since
/// sRGB's white is D65's colour, not the flat spectrum's.
pub fn uniform_emission(value: f64) -> DVec3 {
    xyz_to_srgb(DVec3::ONE) * value
}

/// Mitsuba 0.6's `fromContinuousSpectrum` (RGB builds) of a spectrum `s`, zero outside its
/// range, whose derivative may jump only at `knots` (nm) and at whole nanometres.
pub fn to_srgb_v06(s: impl Fn(f64) -> f64, knots: &[f64]) -> DVec3 {
    xyz_to_srgb(to_xyz_v06(s, knots))
}

fn to_xyz_v06(s: impl Fn(f64) -> f64, knots: &[f64]) -> DVec3 {
    let cie = &*CIE;
    let mut points: Vec<f64> = (0..cie.xyz.len())
        .map(|i| CIE_MIN + i as f64)
        .chain(knots.iter().copied())
        .filter(|l| (CIE_MIN..=CIE_MAX).contains(l))
        .collect();
    points.sort_by(f64::total_cmp);
    points.dedup();
    // Two-point Gauss-Legendre is exact for the product of two linear pieces.
    let offset = 0.5 / 3f64.sqrt();
    let mut xyz = DVec3::ZERO;
    for w in points.windows(2) {
        let (a, h) = (w[0], w[1] - w[0]);
        for lambda in [a + h * (0.5 - offset), a + h * (0.5 + offset)] {
            xyz += lerp_table(&cie.xyz, 1, lambda) * s(lambda) * (h / 2.0);
        }
    }
    let y_integral: f64 = cie.xyz.windows(2).map(|p| (p[0].y + p[1].y) / 2.0).sum();
    xyz / y_integral
}

/// The chromaticity (x, y) of a spectrum `s`, sampled every 1 nm over the CIE tables.
fn chromaticity(s: impl Fn(f64) -> f64) -> (f64, f64) {
    let cie = &*CIE;
    let xyz: DVec3 = cie
        .xyz
        .iter()
        .enumerate()
        .map(|(i, c)| *c * s(CIE_MIN + i as f64))
        .sum();
    let sum = xyz.x + xyz.y + xyz.z;
    (xyz.x / sum, xyz.y / sum)
}

/// The white of a colour temperature as pbrt-v4's `Spectra::D` makes it: CIE daylight of
/// correlated colour temperature `kelvin` x 1.4388 / 1.4380 (the second radiation constant's
/// revision), from the CIE's polynomial in 1/T for x and the daylight locus for y; below
/// 4000 K, where daylight is not defined, a black body's.
pub fn daylight_chromaticity(kelvin: f64) -> (f64, f64) {
    let t = kelvin * 1.4388 / 1.4380;
    if t < 4000.0 {
        return chromaticity(|lambda| blackbody(lambda, t));
    }
    let x = if t <= 7000.0 {
        -4.607e9 / t.powi(3) + 2.9678e6 / t.powi(2) + 0.09911e3 / t + 0.244063
    } else {
        -2.0064e9 / t.powi(3) + 1.9018e6 / t.powi(2) + 0.24748e3 / t + 0.23704
    };
    (x, -3.0 * x * x + 2.870 * x - 0.275)
}

/// The colour temperatures (K) [`white_balance`] takes: those of lights and skies (pbrt-v4
/// adapts from CIE daylight, or a black body below 4000 K; 0 K has no colour).
pub const WHITE_BALANCE_KELVIN: std::ops::RangeInclusive<f64> = 1000.0..=100_000.0;

/// pbrt-v4's white balance (`Film "rgb" "float whitebalance"` with its default `cie1931`
/// sensor; `WhiteBalance` in `util/color.cpp`) as a matrix on linear sRGB: von Kries
/// adaptation in Bradford's cone space (LMS) from the white of `kelvin`
/// ([`daylight_chromaticity`]) to sRGB's, D65's, so that a surface lit by that white is
/// rendered white.
pub fn white_balance(kelvin: f64) -> DMat3 {
    // Bradford's XYZ to LMS, rows as written (glam's matrices are built from columns).
    let lms_from_xyz = DMat3::from_cols_array(&[
        0.8951, -0.7502, 0.0389, 0.2664, 1.7135, -0.0685, -0.1614, 0.0367, 1.0296,
    ]);
    let xyz = |(x, y): (f64, f64)| DVec3::new(x / y, 1.0, (1.0 - x - y) / y);
    let d65 = chromaticity(|lambda| lerp_table(&CIE.d65, 1, lambda));
    let source = lms_from_xyz * xyz(daylight_chromaticity(kelvin));
    let target = lms_from_xyz * xyz(d65);
    let adapt = lms_from_xyz.inverse() * DMat3::from_diagonal(target / source) * lms_from_xyz;
    let srgb_from_xyz = DMat3::from_cols(
        xyz_to_srgb(DVec3::X),
        xyz_to_srgb(DVec3::Y),
        xyz_to_srgb(DVec3::Z),
    );
    srgb_from_xyz * adapt * srgb_from_xyz.inverse()
}

/// Planck's law with Mitsuba 3's constants: the spectral radiance of a black body at
/// `kelvin`, in W m⁻² sr⁻¹ nm⁻¹, at `lambda` nm.
pub fn blackbody(lambda: f64, kelvin: f64) -> f64 {
    planck(lambda, kelvin, 6.62607004e-34, 2.99792458e8, 1.38064852e-23)
}

/// Planck's law with Mitsuba 0.6's constants (its `BlackBodySpectrum`).
pub fn blackbody_v06(lambda: f64, kelvin: f64) -> f64 {
    planck(lambda, kelvin, 6.62606957e-34, 299792458.0, 1.3806488e-23)
}

fn planck(lambda: f64, kelvin: f64, h: f64, c: f64, k: f64) -> f64 {
    let l = lambda * 1e-9;
    2.0 * h * c * c / (l.powi(5) * ((h * c / (k * l * kelvin)).exp() - 1.0)) * 1e-9
}

/// Mitsuba's named conductors: those it ships spectra for (`data/ior/<name>.eta.spd` and
/// `.k.spd`), with their files.
macro_rules! conductors {
    ($($name:literal),* $(,)?) => {
        const CONDUCTOR_DATA: &[(&str, &str, &str)] = &[$((
            $name,
            include_str!(concat!("../data/spectra/ior/", $name, ".eta.spd")),
            include_str!(concat!("../data/spectra/ior/", $name, ".k.spd")),
        )),*];
    };
}

conductors!(
    "a-C",
    "Ag",
    "Al",
    "AlAs",
    "AlAs_palik",
    "AlSb",
    "AlSb_palik",
    "Au",
    "Be",
    "Be_palik",
    "Cr",
    "CsI",
    "CsI_palik",
    "Cu",
    "Cu2O",
    "Cu2O_palik",
    "CuO",
    "CuO_palik",
    "Cu_palik",
    "d-C",
    "d-C_palik",
    "Hg",
    "HgTe",
    "HgTe_palik",
    "Hg_palik",
    "Ir",
    "Ir_palik",
    "K",
    "K_palik",
    "Li",
    "Li_palik",
    "MgO",
    "MgO_palik",
    "Mo",
    "Mo_palik",
    "Na_palik",
    "Nb",
    "Nb_palik",
    "Ni_palik",
    "Rh",
    "Rh_palik",
    "Se",
    "Se-e",
    "Se-e_palik",
    "Se_palik",
    "SiC",
    "SiC_palik",
    "SnTe",
    "SnTe_palik",
    "Ta",
    "Ta_palik",
    "Te",
    "Te-e",
    "Te-e_palik",
    "Te_palik",
    "ThF4",
    "ThF4_palik",
    "TiC",
    "TiC_palik",
    "TiN",
    "TiN_palik",
    "TiO2",
    "TiO2-e",
    "TiO2-e_palik",
    "TiO2_palik",
    "VC",
    "VC_palik",
    "VN",
    "VN_palik",
    "V_palik",
    "W",
);

/// The names of Mitsuba's conductors, as its `material` parameter takes them.
pub fn conductor_names() -> impl Iterator<Item = &'static str> {
    CONDUCTOR_DATA.iter().map(|(name, _, _)| *name)
}

/// A named conductor's measured complex index of refraction: the spectra of eta and k.
pub fn conductor(name: &str) -> Option<(Spectrum, Spectrum)> {
    let (_, eta, k) = CONDUCTOR_DATA.iter().find(|(n, _, _)| *n == name)?;
    let read = |text: &str| {
        Spectrum::parse_spd(text).unwrap_or_else(|e| panic!("core/data/spectra/ior/{name}: {e}"))
    };
    Some((read(eta), read(k)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_conductor_file_reads() {
        // Each spans the blue and green at least (AlSb, the shortest, ends at 590 nm).
        for name in conductor_names() {
            let (eta, k) = conductor(name).unwrap();
            for s in [eta, k] {
                let w = &s.wavelengths;
                assert!(w[0] < 400.0 && w[w.len() - 1] > 580.0, "{name}: {w:?}");
            }
        }
    }

    /// pbrt-v4's white balance: the identity at D65's temperature, each temperature's white
    /// made grey, and CIE daylight on its locus.
    #[test]
    fn white_balance_maps_the_temperatures_white_to_srgbs() {
        // D65 is daylight of 6504 K: 6500 K (6503.6 K after the constant's revision) is
        // within 1e-3 of the identity.
        let m = white_balance(6500.0);
        for (c, axis) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
            let d = m * axis - axis;
            assert!(d.abs().max_element() < 2e-3, "column {c}: {d}");
        }
        // The white of each temperature, as linear sRGB, becomes grey; warm whites are
        // red in sRGB, cool ones blue.
        let xyz = |(x, y): (f64, f64)| DVec3::new(x / y, 1.0, (1.0 - x - y) / y);
        for kelvin in [2700.0, 3500.0, 4000.0, 5000.0, 8000.0, 12000.0] {
            let white = xyz_to_srgb(xyz(daylight_chromaticity(kelvin)));
            let balanced = white_balance(kelvin) * white;
            let spread = balanced.max_element() / balanced.min_element() - 1.0;
            assert!(spread < 1e-3, "{kelvin} K: {white} -> {balanced}");
            let warm = kelvin < 6500.0;
            assert_eq!(white.x > white.z, warm, "{kelvin} K: {white}");
        }
        // The daylight locus: CIE 15's D50 and D75 chromaticities (4 decimals).
        for (kelvin, x, y) in [(5000.0, 0.3457, 0.3585), (7500.0, 0.2990, 0.3149)] {
            let (dx, dy) = daylight_chromaticity(kelvin);
            assert!(
                (dx - x).abs() < 2e-4 && (dy - y).abs() < 2e-4,
                "{kelvin} K: {dx} {dy}"
            );
        }
    }

    /// Mitsuba's normalisations make a flat spectrum of 1 emit a luminance Y of 1: Mitsuba
    /// 3's constant is its 1000-wavelength sum of ȳ, 0.6's the integral of its table.
    #[test]
    fn a_flat_spectrum_has_unit_luminance() {
        let y = to_xyz(|_| Some(1.0), Quantity::Emission).y;
        assert!((y - 1.0).abs() < 1e-6, "{y}");
        let y = to_xyz_v06(|_| 1.0, &[]).y;
        assert!((y - 1.0).abs() < 1e-12, "{y}");
        // Under D65 Mitsuba 3's white falls short of 1 by its D65 constant's rounding.
        let y = to_xyz(|_| Some(1.0), Quantity::Reflectance).y;
        assert!((y - 0.99889).abs() < 1e-5, "{y}");
    }
}
