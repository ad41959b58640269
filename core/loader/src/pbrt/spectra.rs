//! pbrt-v4's spectral parameters (`rgb`, `blackbody`, `spectrum`) reduced to the linear sRGB
//! colour its RGB film reports for them.
//!
//! pbrt-v4 reads an `rgb` colour as a spectrum whose film RGB is that colour (an
//! `RGBAlbedoSpectrum` for reflectances, an `RGBIlluminantSpectrum`, the colour times the
//! colour space's illuminant, for emitters), so it is kept as written. A light divides its
//! spectrum by the spectrum's luminance (`SpectrumToPhotometric`; for an `rgb` colour, by its
//! illuminant's only), so that a `blackbody` or a measured spectrum emits luminance 1 times
//! `scale`: its colour here is the spectrum's sRGB colour divided by its luminance Y. A
//! reflectance given as a spectrum is its colour under D65 ([`Quantity::Reflectance`]).

use super::Loc;
use super::parse::{Param, Type, Values};
use foton_core::error::Result;
use foton_core::spectrum::{Quantity, Spectrum, blackbody, to_srgb};
use glam::DVec3;
use std::path::Path;

/// What a spectrum stands for (pbrt-v4's `SpectrumType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A reflectance: within [0, 1].
    Albedo,
    /// An index of refraction, an absorption coefficient: not bounded above.
    Unbounded,
    /// What a light emits, normalised to luminance 1.
    Illuminant,
}

/// The luminance Y of a linear sRGB colour.
pub fn luminance(c: DVec3) -> f64 {
    c.dot(DVec3::new(0.212671, 0.715160, 0.072169))
}

/// The colour of the spectral parameter `p` (`rgb`, `blackbody`, `spectrum`, or a `float`
/// grey). A named spectrum other than an illuminant's is an error (the caller reads the named
/// metals itself); `scene_dir` is where a spectrum file is looked for.
pub fn rgb(p: &Param, kind: Kind, what: &str, scene_dir: &Path) -> Result<DVec3> {
    let err = |loc: &Loc, m: String| loc.error(what, format!("{}: {m}", p.decl()));
    match (&p.ty, &p.values) {
        (Type::Rgb, Values::Nums(v)) if v.len() == 3 => {
            let c = DVec3::new(v[0], v[1], v[2]);
            if c.min_element() < 0.0 {
                return Err(err(&p.loc, "a negative component".into()));
            }
            if kind == Kind::Albedo && c.max_element() > 1.0 {
                return Err(err(
                    &p.loc,
                    "a component above 1 (pbrt-v4 refuses a reflectance above 1)".into(),
                ));
            }
            Ok(c)
        }
        (Type::Float, Values::Nums(v)) if v.len() == 1 => Ok(DVec3::splat(v[0])),
        (Type::Blackbody, Values::Nums(v)) if v.len() == 1 => {
            if kind != Kind::Illuminant {
                return Err(err(&p.loc, "a blackbody is an emission spectrum".into()));
            }
            let t = v[0];
            if t <= 0.0 {
                return Err(err(&p.loc, format!("temperature {t} K: must be positive")));
            }
            Ok(reduce(&|l| Some(blackbody(l, t)), kind))
        }
        (Type::Spectrum, Values::Nums(v)) => {
            let (w, x): (Vec<f64>, Vec<f64>) = v.chunks(2).map(|c| (c[0], c[1])).unzip();
            let s = Spectrum::new(w, x).map_err(|m| err(&p.loc, m))?;
            Ok(reduce(&|l| s.eval(l), kind))
        }
        (Type::Spectrum, Values::Strs(names)) => {
            let name = &names[0];
            if kind == Kind::Illuminant && name == "stdillum-D65" {
                // The colour space's own illuminant: white.
                return Ok(DVec3::ONE);
            }
            let path = super::parse::resolve(scene_dir, &p.loc.file, name);
            if !path.is_file() {
                return Err(err(
                    &p.loc,
                    format!(
                        "{name:?}: not a named spectrum foton has (it knows the metal-X-eta and metal-X-k pairs of conductors, and stdillum-D65), nor a spectrum file"
                    ),
                ));
            }
            let text = std::fs::read_to_string(&path)
                .map_err(|e| err(&p.loc, format!("{}: {e}", path.display())))?;
            let s = Spectrum::parse_spd(&text)
                .map_err(|m| err(&p.loc, format!("{}: {m}", path.display())))?;
            Ok(reduce(&|l| s.eval(l), kind))
        }
        _ => Err(err(
            &p.loc,
            "expected an rgb colour, a blackbody temperature or a spectrum".into(),
        )),
    }
}

/// pbrt-v4's named glasses (`glass-BK7`...) as their index at 550 nm, interpolated in the
/// measured tables pbrt-v4 carries (src/pbrt/util/spectrum.cpp, from refractiveindex.info):
/// foton's dielectrics are not dispersive.
pub const GLASSES: &[(&str, f64)] = &[
    ("glass-BK7", 1.51854),
    ("glass-BAF10", 1.67305),
    ("glass-FK51A", 1.4878),
    ("glass-LASF9", 1.85581),
    ("glass-F5", 1.67709),
    ("glass-F10", 1.73357),
    ("glass-F11", 1.79112),
];

/// The wavelength at which a spectral index of refraction is read.
pub const ETA_WAVELENGTH: f64 = 550.0;

/// An index of refraction given as a spectrum (a named glass, wavelength-value pairs or a
/// file): its value at [`ETA_WAVELENGTH`]. None: a float or not a spectrum.
pub fn eta_at_550(p: &Param, what: &str, scene_dir: &Path) -> Result<Option<f64>> {
    let err = |m: String| p.loc.error(what, format!("{}: {m}", p.decl()));
    let spectrum = match (&p.ty, &p.values) {
        (Type::Spectrum, Values::Nums(v)) => {
            let (w, x): (Vec<f64>, Vec<f64>) = v.chunks(2).map(|c| (c[0], c[1])).unzip();
            Spectrum::new(w, x).map_err(err)?
        }
        (Type::Spectrum, Values::Strs(names)) => {
            if let Some((_, eta)) = GLASSES.iter().find(|(n, _)| *n == names[0]) {
                return Ok(Some(*eta));
            }
            let path = super::parse::resolve(scene_dir, &p.loc.file, &names[0]);
            if !path.is_file() {
                return Err(err(format!(
                    "{:?}: not a glass foton knows ({}) nor a spectrum file",
                    names[0],
                    GLASSES
                        .iter()
                        .map(|(n, _)| *n)
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
            let text = std::fs::read_to_string(&path)
                .map_err(|e| err(format!("{}: {e}", path.display())))?;
            Spectrum::parse_spd(&text).map_err(|m| err(format!("{}: {m}", path.display())))?
        }
        _ => return Ok(None),
    };
    match spectrum.eval(ETA_WAVELENGTH) {
        Some(eta) if eta > 0.0 => Ok(Some(eta)),
        _ => Err(err(format!("no positive value at {ETA_WAVELENGTH} nm"))),
    }
}

/// Fresnel reflectance of a conductor of complex index eta + i k (relative to the outside)
/// at incidence cos theta: the mean of the s and p polarisations.
fn fresnel_conductor(cos: f64, eta: f64, k: f64) -> f64 {
    let c2 = cos * cos;
    let s2 = 1.0 - c2;
    let (e2, k2) = (eta * eta, k * k);
    let t0 = e2 - k2 - s2;
    let a2b2 = (t0 * t0 + 4.0 * e2 * k2).sqrt();
    let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
    let t1 = a2b2 + c2;
    let t2 = 2.0 * cos * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rs + rp)
}

/// The incidence (cos theta) at which the fit below matches the edge of the reflectance.
const EDGE_COS: f64 = 0.25;

/// RGB eta and k for a named metal (foton's measured spectra) relative to a medium of index
/// `outside`, chosen so that the RGB Fresnel reflectance foton renders matches the colour of
/// the spectral one pbrt-v4 renders (its reflectance per wavelength, reduced to sRGB under
/// D65) at normal incidence exactly, and at cos theta = 1/4: per channel, Gulbrandsen's
/// parametrisation (2014) of the indices with reflectance r at normal incidence, n between
/// (1 - r) / (1 + r) and (1 + sqrt r) / (1 - sqrt r) and k from r and n, searched for the
/// n that matches the edge. Reducing eta and k to RGB first (Mitsuba 3's RGB variants) makes
/// gold a few per cent off pbrt-v4's.
pub fn metal_rgb_ior(name: &str, outside: f64) -> Option<(DVec3, DVec3)> {
    let (eta, k) = foton_core::spectrum::conductor(name)?;
    let spectral = |cos: f64| {
        to_srgb(
            |l| {
                Some(fresnel_conductor(
                    cos,
                    eta.eval(l)? / outside,
                    k.eval(l)? / outside,
                ))
            },
            Quantity::Reflectance,
        )
    };
    let (r0, edge) = (spectral(1.0), spectral(EDGE_COS));
    let mut n_out = DVec3::ZERO;
    let mut k_out = DVec3::ZERO;
    for c in 0..3 {
        let r = r0[c].clamp(1e-4, 0.9999);
        let k_of = |n: f64| {
            ((r * (n + 1.0).powi(2) - (n - 1.0).powi(2)) / (1.0 - r))
                .max(0.0)
                .sqrt()
        };
        let (lo, hi) = ((1.0 - r) / (1.0 + r), (1.0 + r.sqrt()) / (1.0 - r.sqrt()));
        let miss = |n: f64| (fresnel_conductor(EDGE_COS, n, k_of(n)) - edge[c]).abs();
        // A scan then a local refinement: the edge reflectance is smooth in n.
        let steps = 400;
        let mut best = lo;
        for i in 0..=steps {
            let n = lo + (hi - lo) * i as f64 / steps as f64;
            if miss(n) < miss(best) {
                best = n;
            }
        }
        let mut step = (hi - lo) / steps as f64;
        for _ in 0..40 {
            for n in [best - step, best + step] {
                if n > lo && n < hi && miss(n) < miss(best) {
                    best = n;
                }
            }
            step *= 0.5;
        }
        n_out[c] = best * outside;
        k_out[c] = k_of(best) * outside;
    }
    Some((n_out, k_out))
}

fn reduce(s: &dyn Fn(f64) -> Option<f64>, kind: Kind) -> DVec3 {
    match kind {
        Kind::Albedo => to_srgb(s, Quantity::Reflectance),
        Kind::Unbounded => to_srgb(s, Quantity::Unbounded),
        Kind::Illuminant => {
            let c = to_srgb(s, Quantity::Emission);
            let y = luminance(c);
            if y > 0.0 { c / y } else { DVec3::ZERO }
        }
    }
}

#[cfg(test)]
mod tests {

    /// The fitted RGB index reflects, per channel, what the spectral index reflects reduced
    /// to sRGB: exactly at normal incidence, closely at the fit's edge angle, and within a
    /// few per cent between (where reducing eta and k to RGB first is off by more for gold).
    #[test]
    fn metal_rgb_ior_matches_the_spectral_fresnel_colour() {
        for (metal, outside) in [("Au", 1.0), ("Cu", 1.0), ("Ag", 1.5), ("Al", 1.0)] {
            let (n, k) = metal_rgb_ior(metal, outside).unwrap();
            let (se, sk) = foton_core::spectrum::conductor(metal).unwrap();
            let normal = to_srgb(
                |l| {
                    Some(fresnel_conductor(
                        1.0,
                        se.eval(l)? / outside,
                        sk.eval(l)? / outside,
                    ))
                },
                Quantity::Unbounded,
            );
            for cos in [1.0, EDGE_COS, 0.6] {
                let want = to_srgb(
                    |l| {
                        Some(fresnel_conductor(
                            cos,
                            se.eval(l)? / outside,
                            sk.eval(l)? / outside,
                        ))
                    },
                    Quantity::Reflectance,
                );
                for c in 0..3 {
                    if cos != 1.0 && normal[c] >= 0.9999 {
                        // Out of gamut (gold's red): only its normal reflectance is fitted.
                        continue;
                    }
                    let got = fresnel_conductor(cos, n[c] / outside, k[c] / outside);
                    // A conductor reflects less than all: a colour beyond sRGB's gamut, above
                    // 1, is fitted at 0.9999.
                    let want = want.min(DVec3::splat(0.9999));
                    let tol = if cos == 1.0 {
                        1e-6
                    } else if cos == EDGE_COS {
                        2e-3
                    } else {
                        0.03
                    };
                    assert!(
                        (got - want[c]).abs() <= tol * want[c].max(0.05),
                        "{metal} at cos {cos}, channel {c}: {got} against {}",
                        want[c]
                    );
                }
            }
        }
        // Fresnel at normal incidence: ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2).
        let f = fresnel_conductor(1.0, 0.2, 3.0);
        assert!((f - (0.64 + 9.0) / (1.44 + 9.0)).abs() < 1e-12);
    }

    use super::*;
    use std::rc::Rc;

    fn param(ty: Type, values: Values) -> Param {
        Param {
            ty,
            name: "L".into(),
            values,
            loc: Loc {
                file: Rc::from(Path::new("t.pbrt")),
                line: 1,
                column: 1,
            },
        }
    }

    #[test]
    fn lights_emit_luminance_one_per_unit_scale() {
        let p = param(Type::Blackbody, Values::Nums(vec![6500.0]));
        let c = rgb(&p, Kind::Illuminant, "x", Path::new("")).unwrap();
        assert!((luminance(c) - 1.0).abs() < 1e-9, "{c}");
        // 6500 K is close to D65's white.
        assert!((c - DVec3::ONE).abs().max_element() < 0.1, "{c}");
        let p = param(Type::Rgb, Values::Nums(vec![2.0, 3.0, 4.0]));
        assert_eq!(
            rgb(&p, Kind::Illuminant, "x", Path::new("")).unwrap(),
            DVec3::new(2.0, 3.0, 4.0)
        );
        let p = param(Type::Rgb, Values::Nums(vec![0.5, 1.5, 0.0]));
        assert!(rgb(&p, Kind::Albedo, "x", Path::new("")).is_err());
        let p = param(Type::Spectrum, Values::Nums(vec![300.0, 0.5, 900.0, 0.5]));
        let c = rgb(&p, Kind::Albedo, "x", Path::new("")).unwrap();
        assert!((c - DVec3::splat(0.5)).abs().max_element() < 0.01, "{c}");
    }
}
