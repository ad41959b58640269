//! `principled` and `principledthin`, Mitsuba 3's Disney BSDFs: their values against Mitsuba
//! 3's own (eval in both transport modes and pdf, for parameter sets that turn every lobe on
//! and direction pairs on both sides), their sampling against their pdfs (chi-square, with
//! the machinery of sampling.rs), the sampled weight against eval / pdf, reciprocity, and
//! the Mitsuba reader: files with both open, their textures and `twosided` read, the
//! converted TOML renders the same image, and out-of-range parameters are refused.

use crate::mitsuba::{ok, render, s};
use crate::sampling::{SphereGrid, d, rgb_close};
use foton_core::Rgb;
use foton_core::geometry::SurfacePoint;
use foton_core::material::{Lobe, Material, TransportMode};
use foton_core::sampling::Rng;
use foton_tests::stats::assert_gof;
use foton_tests::{foton, temp_dir, write};
use glam::{DVec3, Vec2, Vec3};

/// The materials of `[materials.NAME]` bodies, read by the scene loader.
fn materials(bodies: &[(&str, &str)]) -> Vec<Material> {
    let mut toml = foton_tests::header("path", 1, 1, 4, 4)
        + "\n[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 30\n\n\
           [[lights]]\ntype = \"constant\"\nradiance = [1, 1, 1]\n";
    for (name, body) in bodies {
        toml += &format!("\n[materials.{name}]\n{body}\n");
    }
    for (name, _) in bodies {
        toml += &format!(
            "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"{name}\"\n"
        );
    }
    let dir = temp_dir("principled-materials");
    let path = write(&dir, "scene.toml", &toml);
    let scene = foton_loader::load(&path, &[]).unwrap_or_else(|e| panic!("{e}\n{toml}"));
    let _ = std::fs::remove_dir_all(&dir);
    bodies
        .iter()
        .map(|(name, _)| {
            let m = scene.materials().iter().find(|m| m.name == *name);
            m.unwrap_or_else(|| panic!("no material {name}"))
                .value
                .clone()
        })
        .collect()
}

/// The lobe of `material` in the frame x = tangent, z = normal (local = world).
fn lobe(material: &Material) -> Lobe {
    let sp = SurfacePoint {
        p: Vec3::ZERO,
        ng: Vec3::Z,
        ns: Vec3::Z,
        uv: Vec2::new(0.3, 0.6),
        dpdu: Vec3::X,
        dpdv: Vec3::Y,
        attribute: Vec3::ZERO,
    };
    material.bsdf(&sp).expect("a material that scatters").lobe
}

/// f(wo, wi) |cos theta_i| carrying `mode`.
fn eval(lobe: &Lobe, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
    match lobe {
        Lobe::Principled(l) => l.eval_mode(wo, wi, mode),
        // The thin sheet scales nothing: the same index on both sides.
        Lobe::PrincipledThin(l) => l.eval(wo, wi),
        other => panic!("not a principled lobe: {other:?}"),
    }
}

/// The parameter sets of tests/fixtures/principled_reference.py, as TOML.
const SETS: &[(&str, &str)] = &[
    ("defaults", "type = \"principled\""),
    (
        "everything",
        "type = \"principled\"\nbase_color = [0.8, 0.4, 0.2]\nroughness = 0.4\nanisotropic = 0.5\n\
         metallic = 0.3\nspec_tint = 0.5\nsheen = 0.6\nsheen_tint = 0.4\nflatness = 0.3\n\
         clearcoat = 0.7\nclearcoat_gloss = 0.4",
    ),
    (
        "glass",
        "type = \"principled\"\nbase_color = [0.9, 0.95, 1.0]\nspec_trans = 1.0\neta = 1.5\nroughness = 0.3",
    ),
    (
        "half_glass",
        "type = \"principled\"\nbase_color = [0.5, 0.7, 0.3]\nspec_trans = 0.6\nmetallic = 0.2\n\
         specular = 0.7\nroughness = 0.5\nclearcoat = 0.3\nsheen = 0.2",
    ),
    (
        "inverted_eta",
        "type = \"principled\"\nbase_color = [0.3, 0.6, 0.9]\nspec_trans = 0.5\neta = 0.8\n\
         metallic = 0.4\nspec_tint = 0.3\nroughness = 0.6",
    ),
    (
        "thin_doc",
        "type = \"principledthin\"\nbase_color = [0.7, 0.1, 0.1]\nroughness = 0.15\nspec_tint = 0.1\n\
         anisotropic = 0.5\nspec_trans = 0.8\ndiff_trans = 0.3\neta = 1.33",
    ),
    (
        "thin_diffuse",
        "type = \"principledthin\"\nbase_color = [0.2, 0.6, 0.3]\nroughness = 0.6\nspec_trans = 0.3\n\
         diff_trans = 1.2\nsheen = 0.5\nsheen_tint = 0.5\nflatness = 0.6\neta = 1.5",
    ),
];

/// The script's direction pairs (wo towards the viewer, wi), before normalisation.
const PAIRS: [([f32; 3], [f32; 3]); 6] = [
    ([0.3, 0.2, 0.9], [-0.4, 0.1, 0.8]),
    ([0.6, -0.1, 0.5], [-0.55, 0.15, 0.55]),
    ([0.3, 0.2, 0.9], [-0.2, -0.1, -0.95]),
    ([0.2, -0.3, -0.85], [-0.3, 0.2, -0.7]),
    ([0.2, -0.3, -0.85], [-0.25, 0.35, 0.8]),
    ([0.95, 0.0, 0.12], [-0.9, 0.1, 0.2]),
];

// Made by tests/fixtures/principled_reference.py (Mitsuba 3.9.1, scalar_rgb).
/// (set, pair): eval (radiance), eval (importance), pdf.
type Reference = (&'static str, usize, [f32; 3], [f32; 3], f32);
#[rustfmt::skip]
const MITSUBA: &[Reference] = &[
    ("defaults", 0, [0.16526215, 0.16526215, 0.16526215], [0.16526215, 0.16526215, 0.16526215], 0.4369293),
    ("defaults", 1, [0.20216511, 0.20216511, 0.20216511], [0.20216511, 0.20216511, 0.20216511], 0.96432024),
    ("defaults", 2, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0),
    ("defaults", 3, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 1.0512574),
    ("defaults", 4, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0),
    ("defaults", 5, [0.34807608, 0.34807608, 0.34807608], [0.34807608, 0.34807608, 0.34807608], 0.5764823),
    ("everything", 0, [0.24488223, 0.12934676, 0.07157901], [0.24488223, 0.12934676, 0.07157901], 0.31954262),
    ("everything", 1, [1.0881063, 0.5973557, 0.35198033], [1.0881063, 0.5973557, 0.35198033], 2.0825686),
    ("everything", 2, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0),
    ("everything", 3, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 2.078425),
    ("everything", 4, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0),
    ("everything", 5, [0.22088063, 0.17000338, 0.14456478], [0.22088063, 0.17000338, 0.14456478], 0.25885347),
    ("glass", 0, [0.015459295, 0.015459295, 0.015459295], [0.015459295, 0.015459295, 0.015459295], 0.015467616),
    ("glass", 1, [0.33486238, 0.33486238, 0.33486238], [0.33486238, 0.33486238, 0.33486238], 0.33558932),
    ("glass", 2, [24.348412, 25.015615, 25.66548], [54.783928, 56.285137, 57.747334], 57.753807),
    ("glass", 3, [0.10000394, 0.10000394, 0.10000394], [0.10000394, 0.10000394, 0.10000394], 0.10005765),
    ("glass", 4, [6.4218173, 6.59779, 6.76919], [2.8541408, 2.9323509, 3.0085287], 3.0102892),
    ("glass", 5, [0.16224445, 0.16224445, 0.16224445], [0.16224445, 0.16224445, 0.16224445], 0.16872127),
    ("half_glass", 0, [0.13479367, 0.17644139, 0.09314595], [0.13479367, 0.17644139, 0.09314595], 0.31865206),
    ("half_glass", 1, [0.3115104, 0.39256495, 0.23045588], [0.3115104, 0.39256495, 0.23045588], 0.8230907),
    ("half_glass", 2, [3.213085, 3.8017733, 2.488845], [8.43249, 9.977457, 6.5317793], 8.556026),
    ("half_glass", 3, [0.032396246, 0.032396246, 0.032396246], [0.032396246, 0.032396246, 0.032396246], 0.06777082),
    ("half_glass", 4, [2.8847451, 3.4132764, 2.2345142], [1.0991926, 1.3005823, 0.851431], 3.253089),
    ("half_glass", 5, [0.41272974, 0.4372833, 0.3881761], [0.41272974, 0.4372833, 0.3881761], 0.6140825),
    ("inverted_eta", 0, [0.0797694, 0.15720204, 0.23463464], [0.0797694, 0.15720204, 0.23463464], 0.29945043),
    ("inverted_eta", 1, [0.19619972, 0.3071184, 0.41803703], [0.19619972, 0.3071184, 0.41803703], 0.53762174),
    ("inverted_eta", 2, [0.18024512, 0.2549051, 0.3121937], [0.11535686, 0.16313924, 0.19980395], 0.16229942),
    ("inverted_eta", 3, [0.0022014217, 0.0022014217, 0.0022014217], [0.0022014217, 0.0022014217, 0.0022014217], 0.0074006165),
    ("inverted_eta", 4, [0.21970822, 0.31071436, 0.3805458], [0.34329408, 0.4854912, 0.5946028], 2.1086082),
    ("inverted_eta", 5, [0.6319144, 0.63598657, 0.6400588], [0.6319144, 0.63598657, 0.6400588], 0.71909267),
    ("thin_doc", 0, [0.03393194, 0.0050153974, 0.0050153974], [0.03393194, 0.0050153974, 0.0050153974], 0.053450674),
    ("thin_doc", 1, [0.07615824, 0.04603021, 0.04603021], [0.07615824, 0.04603021, 0.04603021], 0.7651249),
    ("thin_doc", 2, [0.03986052, 0.00569436, 0.00569436], [0.03986052, 0.00569436, 0.00569436], 0.033609696),
    ("thin_doc", 3, [0.047979362, 0.016042927, 0.016042927], [0.047979362, 0.016042927, 0.016042927], 0.33867216),
    ("thin_doc", 4, [0.24399626, 0.03485661, 0.03485661], [0.24399626, 0.03485661, 0.03485661], 0.18206294),
    ("thin_doc", 5, [0.008329552, 0.0038187113, 0.0038187113], [0.008329552, 0.0038187113, 0.0038187113], 0.016207606),
    ("thin_diffuse", 0, [0.018078245, 0.043833505, 0.024517061], [0.018078245, 0.043833505, 0.024517061], 0.14409323),
    ("thin_diffuse", 1, [0.025957031, 0.049958453, 0.031957388], [0.025957031, 0.049958453, 0.031957388], 0.19209106),
    ("thin_diffuse", 2, [0.1745878, 0.5237634, 0.2618817], [0.1745878, 0.5237634, 0.2618817], 0.517179),
    ("thin_diffuse", 3, [0.01997381, 0.04578719, 0.026427155], [0.01997381, 0.04578719, 0.026427155], 0.16691642),
    ("thin_diffuse", 4, [0.2279872, 0.68396163, 0.34198081], [0.2279872, 0.68396163, 0.34198081], 0.65132266),
    ("thin_diffuse", 5, [0.08383024, 0.098253965, 0.08743618], [0.08383024, 0.098253965, 0.08743618], 0.15635547),
];

/// Values within 1e-4 relative (of the larger; both in single precision, computed in a
/// different order), zero where Mitsuba's are zero.
fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-4 * a.abs().max(b.abs())
}

/// Mitsuba 3's eval (radiance and importance) and pdf, reproduced. One difference on
/// purpose: seen from behind, a principled material without transmission samples nothing,
/// and its pdf is zero here where Mitsuba's is that of the specular reflection (its eval is
/// black there either way).
#[test]
fn eval_and_pdf_equal_mitsuba_3s() {
    let mats = materials(SETS);
    let mut checked = 0;
    for &(set, pair, radiance, importance, pdf) in MITSUBA {
        let k = SETS.iter().position(|(n, _)| *n == set).unwrap();
        let l = lobe(&mats[k]);
        let (wo, wi) = PAIRS[pair];
        let (wo, wi) = (Vec3::from(wo).normalize(), Vec3::from(wi).normalize());
        let what = format!("{set}, pair {pair} (wo {wo}, wi {wi})");
        for (mode, want) in [
            (TransportMode::Radiance, radiance),
            (TransportMode::Importance, importance),
        ] {
            let got = eval(&l, wo, wi, mode);
            assert!(
                (0..3).all(|c| close(got[c], want[c])),
                "{what}: eval {mode:?} {got}, Mitsuba {want:?}"
            );
        }
        let got = l.pdf(wo, wi);
        let opaque_from_behind = wo.z < 0.0 && matches!(l, Lobe::Principled(_)) && !l.transmits();
        if opaque_from_behind {
            assert!(got == 0.0, "{what}: pdf {got}, Mitsuba {pdf}");
        } else {
            assert!(close(got, pdf), "{what}: pdf {got}, Mitsuba {pdf}");
        }
        checked += 1;
    }
    assert_eq!(checked, SETS.len() * PAIRS.len());
}

/// Parameter sets of the sampling tests, with a viewing direction each: a metal, glass seen
/// from both sides, a clearcoat, sheen with fake subsurface, every lobe seen from behind,
/// sampling rates other than 1, and the thin sheet with diffuse transmission from both
/// sides. Roughnesses stay above 0.4 (alpha 0.16), which the grid's cells resolve.
const SAMPLING_CASES: &[(&str, &str, [f32; 3])] = &[
    (
        "metal",
        "type = \"principled\"\nbase_color = [0.9, 0.6, 0.3]\nmetallic = 1\nroughness = 0.5\nanisotropic = 0.6",
        [0.5, 0.2, 0.84],
    ),
    (
        "glass_front",
        "type = \"principled\"\nspec_trans = 1\neta = 1.5\nroughness = 0.5",
        [0.4, -0.3, 0.866],
    ),
    (
        "glass_behind",
        "type = \"principled\"\nspec_trans = 1\neta = 1.5\nroughness = 0.5",
        [0.3, 0.1, -0.95],
    ),
    (
        "clearcoat",
        "type = \"principled\"\nbase_color = [0.4, 0.5, 0.6]\nroughness = 0.6\nclearcoat = 1\nclearcoat_gloss = 0.2",
        [0.3, 0.4, 0.866],
    ),
    (
        "sheen",
        "type = \"principled\"\nroughness = 0.8\nsheen = 1\nsheen_tint = 0.7\nflatness = 0.5\nspec_tint = 0.4",
        [0.7, 0.0, 0.71],
    ),
    (
        "everything_behind",
        "type = \"principled\"\nbase_color = [0.5, 0.7, 0.3]\nspec_trans = 0.6\nmetallic = 0.2\n\
         specular = 0.7\nroughness = 0.5\nclearcoat = 0.3\nsheen = 0.2",
        [-0.2, 0.3, -0.93],
    ),
    (
        "rates",
        "type = \"principled\"\nbase_color = [0.5, 0.7, 0.3]\nspec_trans = 0.6\nmetallic = 0.2\n\
         roughness = 0.5\nclearcoat = 0.3\ndiffuse_reflectance_sampling_rate = 0.3\n\
         main_specular_sampling_rate = 0.5\nclearcoat_sampling_rate = 2",
        [0.6, 0.3, 0.74],
    ),
    (
        "thin_front",
        "type = \"principledthin\"\nbase_color = [0.7, 0.3, 0.1]\nroughness = 0.45\nanisotropic = 0.3\n\
         spec_trans = 0.6\ndiff_trans = 0.8\neta = 1.33\nsheen = 0.4",
        [0.3, 0.3, 0.9],
    ),
    (
        "thin_behind",
        "type = \"principledthin\"\nbase_color = [0.7, 0.3, 0.1]\nroughness = 0.45\nanisotropic = 0.3\n\
         spec_trans = 0.6\ndiff_trans = 0.8\neta = 1.33\nsheen = 0.4",
        [0.2, -0.5, -0.84],
    ),
];

/// Sampled directions follow the pdf (chi-square over the sphere; a sample that fails counts
/// in a cell of its own, expected with the mass the pdf leaves out), the pdf a sample
/// reports is pdf(), and its weight is f |cos theta_i| / pdf in the mode it was drawn for.
#[test]
fn sampling_follows_the_pdf_and_weights_are_eval_over_pdf() {
    const N: usize = 400_000;
    let alpha = 1.0 - 0.99f64.powf(1.0 / SAMPLING_CASES.len() as f64);
    let bodies: Vec<(&str, &str)> = SAMPLING_CASES.iter().map(|(n, b, _)| (*n, *b)).collect();
    let mats = materials(&bodies);
    for (k, (name, _, wo)) in SAMPLING_CASES.iter().enumerate() {
        let l = lobe(&mats[k]);
        let wo = Vec3::from(*wo).normalize();
        let grid = SphereGrid::full_sphere(DVec3::Z, 24, 48);
        let probs = grid.probabilities(&|w| l.pdf(wo, w.as_vec3()) as f64);
        let integral: f64 = probs.iter().sum();
        assert!(
            integral < 1.0 + 2e-3,
            "{name}: the pdf integrates to {integral}"
        );
        assert!(integral > 0.5, "{name}: the pdf integrates to {integral}");
        let mut observed = vec![0u64; grid.len() + 1];
        let mut rng = Rng::new(&[41, k as u64]);
        for i in 0..N {
            let mode = if i % 2 == 0 {
                TransportMode::Radiance
            } else {
                TransportMode::Importance
            };
            let Some(s) = l.sample(wo, rng.next_2d(), rng.next_f32(), mode) else {
                observed[grid.len()] += 1;
                continue;
            };
            assert!(
                !s.delta && (s.wi.length() - 1.0).abs() < 1e-4,
                "{name}: {s:?}"
            );
            let pdf = l.pdf(wo, s.wi);
            assert!(
                (s.pdf - pdf).abs() <= 1e-5 * pdf,
                "{name}: sample pdf {} vs pdf() {pdf}",
                s.pdf
            );
            let f = eval(&l, wo, s.wi, mode);
            assert!(
                rgb_close(s.weight * pdf, f, 1e-4),
                "{name}: weight {} x pdf {pdf} is not f cos {f} ({mode:?})",
                s.weight
            );
            match grid.cell(d(s.wi)) {
                Some(c) => observed[c] += 1,
                None => panic!("{name}: {} outside the sphere", s.wi),
            }
        }
        let mut expected: Vec<f64> = probs.iter().map(|p| p * N as f64).collect();
        expected.push((1.0 - integral).max(0.0) * N as f64);
        assert_gof(name, &observed, &expected, alpha);
    }
}

/// Reflection is reciprocal, f(wo, wi) = f(wi, wo); transmission is as the adjoint BSDF says,
/// the importance transported from wo to wi equal to the radiance from wi to wo (the 1 / eta^2
/// of radiance in one direction only). Random pairs over the sphere, every set of the
/// reference test. Pairs whose microfacet is seen at grazing angles (|cos| < 0.1) are left
/// out: there the Fresnel term's cos theta_t, sqrt(1 - sin^2 theta_i / eta^2), loses most of
/// its single-precision digits (Mitsuba computes it the same way), and the two directions'
/// terms differ by up to 0.2 %.
#[test]
fn reciprocity() {
    let mats = materials(SETS);
    let mut rng = Rng::new(&[43]);
    let dir = |rng: &mut Rng| {
        let u = rng.next_2d();
        let z = 1.0 - 2.0 * u.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u.y;
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    for ((set, _), m) in SETS.iter().zip(&mats) {
        let l = lobe(m);
        let mut nonzero = [0; 2];
        for _ in 0..20_000 {
            let (wo, wi) = (dir(&mut rng), dir(&mut rng));
            if wo.z.abs() < 0.05 || wi.z.abs() < 0.05 {
                continue;
            }
            let transmission = wo.z * wi.z < 0.0;
            let h = match l {
                Lobe::Principled(p) if transmission => {
                    let eta = if wo.z > 0.0 { p.eta } else { 1.0 / p.eta };
                    (wo + eta * wi).normalize()
                }
                // The thin sheet's: of wo and wi mirrored to wo's side.
                _ => (wo + Vec3::new(wi.x, wi.y, wi.z * wo.z.signum() * wi.z.signum())).normalize(),
            };
            let cos_d = wo.dot(h).abs();
            if cos_d < 0.1 {
                continue;
            }
            // Mitsuba's thin specular transmission masks the transmitted direction itself, not
            // its mirror image, against the half vector of the mirror image: it is on where
            // cos theta_d < 2 |cos theta| h.z for the transmitted direction's cosine, which
            // is not reciprocal. Pairs where it is on in one direction only are left out.
            if matches!(l, Lobe::PrincipledThin(_)) && transmission {
                let on = |cos: f32| cos_d < 2.0 * cos.abs() * h.z.abs();
                if on(wi.z) != on(wo.z) {
                    continue;
                }
            }
            let forward = eval(&l, wo, wi, TransportMode::Importance) / wi.z.abs();
            let backward = eval(&l, wi, wo, TransportMode::Radiance) / wo.z.abs();
            assert!(
                rgb_close(forward, backward, 1e-3)
                    || (forward - backward).abs().max_element() < 1e-6,
                "{set}: wo {wo}, wi {wi}: f(wo, wi) {forward}, f*(wi, wo) {backward}"
            );
            if forward.max_element() > 1e-3 {
                nonzero[transmission as usize] += 1;
            }
        }
        assert!(nonzero[0] > 500, "{set}: {nonzero:?}");
        if l.transmits() {
            assert!(nonzero[1] > 500, "{set}: {nonzero:?}");
        }
    }
}

/// Mitsuba 3 files with both BSDFs open and read as Mitsuba means them: numbers, a bitmap
/// roughness, a checkerboard index, the sampling rates, `twosided`; the converted TOML
/// renders the same image.
#[test]
fn mitsuba_files_with_principled_materials_open() {
    let dir = temp_dir("principled-xml");
    let mut img = image::RgbImage::new(2, 2);
    for (x, y, p) in img.enumerate_pixels_mut() {
        *p = image::Rgb([if (x + y) % 2 == 0 { 255 } else { 0 }; 3]);
    }
    img.save(dir.join("rough.png")).unwrap();
    let text = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 8" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/></film>
    </sensor>
    <bsdf type="principled" id="a">
        <rgb name="base_color" value="0.8, 0.3, 0.2"/>
        <texture name="roughness" type="bitmap">
            <string name="filename" value="rough.png"/><boolean name="raw" value="true"/>
        </texture>
        <float name="metallic" value="0.3"/>
        <float name="specular" value="0.6"/>
        <float name="anisotropic" value="0.5"/>
        <float name="clearcoat" value="0.6"/>
        <float name="clearcoat_gloss" value="0.3"/>
        <float name="sheen" value="0.3"/>
        <float name="main_specular_sampling_rate" value="2"/>
    </bsdf>
    <bsdf type="twosided" id="b">
        <bsdf type="principled"><float name="eta" value="1.4"/></bsdf>
    </bsdf>
    <bsdf type="principledthin" id="c">
        <texture name="eta" type="checkerboard">
            <float name="color0" value="1.2"/><float name="color1" value="1.6"/>
        </texture>
        <float name="spec_trans" value="0.4"/>
        <float name="diff_trans" value="1.5"/>
        <float name="diffuse_transmittance_sampling_rate" value="0.5"/>
    </bsdf>
    <shape type="sphere"><point name="center" x="-2.5" y="0" z="0"/><ref id="a"/></shape>
    <shape type="sphere"><ref id="b"/></shape>
    <shape type="sphere"><point name="center" x="2.5" y="0" z="0"/><ref id="c"/></shape>
    <emitter type="constant"/>
</scene>
"#;
    let xml = write(&dir, "scene.xml", text);
    let scene = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    let material = |i: usize| &scene.materials()[scene.objects()[i].material as usize].value;
    use foton_core::material::{PrincipledMaterial, PrincipledThinMaterial};
    let Material::Principled(a) = material(0) else {
        panic!("{:?}", material(0))
    };
    let at = |u: f32, v: f32| Vec2::new(u, v);
    assert_eq!(
        a.base_color.eval(at(0.0, 0.0).into()),
        Rgb::new(0.8, 0.3, 0.2)
    );
    // The raw bitmap's texels (nearest to the texel centres): 1 and 0.
    assert!((a.roughness.at(at(0.25, 0.25).into()) - 1.0).abs() < 1e-6);
    assert!(a.roughness.at(at(0.75, 0.25).into()).abs() < 1e-6);
    assert_eq!(
        (
            a.metallic.at(at(0.0, 0.0).into()),
            a.anisotropic.at(at(0.0, 0.0).into())
        ),
        (0.3, 0.5)
    );
    assert_eq!(a.clearcoat_gloss.at(at(0.0, 0.0).into()), 0.3);
    // specular 0.6: eta = 2 / (1 - sqrt(0.08 x 0.6)) - 1.
    let eta = 2.0 / (1.0 - (0.08f32 * 0.6).sqrt()) - 1.0;
    assert!((a.eta - eta).abs() < 1e-6, "{}", a.eta);
    assert_eq!(
        (
            a.diffuse_rate,
            a.specular_rate,
            a.clearcoat_rate,
            a.twosided
        ),
        (1.0, 2.0, 1.0, false)
    );
    let Material::Principled(PrincipledMaterial { eta, twosided, .. }) = material(1) else {
        panic!("{:?}", material(1))
    };
    assert_eq!((*eta, *twosided), (1.4, true));
    let Material::PrincipledThin(PrincipledThinMaterial {
        eta,
        diff_trans,
        rates,
        ..
    }) = material(2)
    else {
        panic!("{:?}", material(2))
    };
    let (e0, e1) = (eta.at(at(0.25, 0.25).into()), eta.at(at(0.75, 0.25).into()));
    assert!(
        [(e0, e1), (e1, e0)]
            .iter()
            .any(|&(x, y)| (x - 1.2).abs() < 1e-6 && (y - 1.6).abs() < 1e-6),
        "{e0} {e1}"
    );
    assert_eq!(diff_trans.at(at(0.0, 0.0).into()), 1.5);
    assert_eq!(*rates, [1.0, 1.0, 1.0, 0.5]);
    // The converted TOML renders the same image.
    let toml = dir.join("scene.toml");
    ok(&foton(&["convert", s(&xml), "-o", s(&toml)]));
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    ok(&render(&xml, &a, &["--spp", "2"]));
    ok(&render(&toml, &b, &["--spp", "2"]));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Out-of-range and contradictory parameters are refused with the parameter's name, from
/// TOML and from Mitsuba files.
#[test]
fn bad_parameters_are_refused() {
    for (body, key, what) in [
        (
            "type = \"principled\"\nmetallic = 1.5",
            "metallic",
            "[0, 1]",
        ),
        (
            "type = \"principled\"\neta = 1.3\nspecular = 0.5",
            "specular",
            "either",
        ),
        (
            "type = \"principled\"\nroughness = -0.1",
            "roughness",
            "at least 0",
        ),
        (
            "type = \"principled\"\nspec_trans = 0.5\ntwosided = true",
            "twosided",
            "transmit",
        ),
        (
            "type = \"principled\"\nclearcoat_sampling_rate = -1",
            "clearcoat_sampling_rate",
            "non-negative",
        ),
        (
            "type = \"principledthin\"\ndiff_trans = 2.5",
            "diff_trans",
            "[0, 2]",
        ),
        ("type = \"principledthin\"\neta = 0", "eta", "positive"),
        (
            "type = \"principledthin\"\nroughness = [0.1, 0.2, 0.3]",
            "roughness",
            "number",
        ),
    ] {
        let toml = foton_tests::header("path", 1, 1, 4, 4) + "\n[materials.m]\n" + body;
        let dir = temp_dir("principled-bad");
        let path = write(&dir, "scene.toml", &toml);
        let e = foton_loader::load(&path, &[])
            .err()
            .unwrap_or_else(|| panic!("{body}: loads"));
        let e = e.to_string();
        assert!(e.contains(key) && e.contains(what), "{body}: {e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
    let dir = temp_dir("principled-bad-xml");
    for (bsdf, what) in [
        (
            r#"<bsdf type="principled"><float name="eta" value="1.5"/><float name="specular" value="0.5"/></bsdf>"#,
            "either `eta` or `specular`",
        ),
        (
            r#"<bsdf type="principled"><string name="roughness" value="rough"/></bsdf>"#,
            "`roughness`: expected a number or a texture",
        ),
        (
            r#"<bsdf type="principledthin"><float name="spec_trans" value="1.2"/></bsdf>"#,
            "spec_trans",
        ),
    ] {
        let text = format!(
            "<scene version=\"3.0.0\">\n<shape type=\"sphere\">\n{bsdf}\n</shape>\n</scene>\n"
        );
        let xml = write(&dir, "scene.xml", &text);
        let e = foton_loader::load_with(&xml, &[], &[], false)
            .err()
            .unwrap_or_else(|| panic!("{bsdf}: loads"))
            .to_string();
        assert!(e.contains(what) && e.contains("scene.xml"), "{bsdf}: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
