//! Statistical tests of the materials' sampling against their pdfs (diffuse, dielectric,
//! mirror), with the machinery of sampling.rs.

use crate::sampling::{
    DIELECTRIC_CASES, Frame, P_HORIZON, SphereGrid, assert_gof, check_directions, d, rgb_close,
};
use foton_core::Rgb;
use foton_core::bsdf::Bsdf;
use foton_core::geometry::SurfacePoint;
use foton_core::material::{
    DielectricMaterial, DiffuseMaterial, Material, MirrorMaterial, TransportMode,
    fresnel_dielectric, refract,
};
use foton_core::sampling::{self, Rng};
use foton_core::texture::Texture;
use foton_tests::stats::assert_close;
use glam::{DVec3, Vec3};

// ---------------------------------------------------------------------------------------------
// Materials
// ---------------------------------------------------------------------------------------------

/// The BSDF of `mat` on a flat surface with normal `ng` (no shading normal, no texture).
fn flat(mat: &Material, ng: Vec3) -> Bsdf {
    let sp = SurfacePoint {
        p: Vec3::ZERO,
        ng,
        ns: ng,
        uv: glam::Vec2::ZERO,
        dpdu: Vec3::ZERO,
        dpdv: Vec3::ZERO,
        attribute: Vec3::ZERO,
    };
    mat.bsdf(&sp).expect("a material that scatters")
}

#[test]
fn diffuse_sampling_matches_its_pdf_on_both_sides() {
    let reflectance = Rgb::new(0.8, 0.5, 0.2);
    let mat = Material::from(DiffuseMaterial {
        reflectance: Texture::Constant(reflectance),
        twosided: true,
    });
    let ng = Vec3::new(0.3, -0.4, 0.866).normalize();
    let front = Vec3::new(0.5, 0.2, 0.8).normalize();
    let back = Vec3::new(-0.1, 0.7, -0.6).normalize();
    assert!(front.dot(ng) > 0.0 && back.dot(ng) < 0.0);
    for (k, (side, wo)) in [("front", front), ("back", back)].into_iter().enumerate() {
        // The whole sphere around ng: samples on the wrong side land in empty cells.
        let grid = SphereGrid::full_sphere(d(ng), 20, 20);
        let mut rng = Rng::new(&[10, k as u64]);
        let pdf = |w: DVec3| flat(&mat, ng).pdf(wo, w.as_vec3()) as f64;
        let integral = check_directions(
            &format!("diffuse, wo on the {side}"),
            &grid,
            1_000_000,
            P_HORIZON,
            &pdf,
            &mut || {
                let mode = if rng.next_u32() & 1 == 0 {
                    TransportMode::Radiance
                } else {
                    TransportMode::Importance
                };
                let s = flat(&mat, ng).sample(wo, rng.next_2d(), rng.next_f32(), mode)?;
                assert!(!s.delta);
                assert_close("|wi|", s.wi.length() as f64, 1.0, 1e-5);
                assert!(
                    s.wi.dot(ng) * wo.dot(ng) >= 0.0,
                    "wi = {} is on the other side from wo = {wo}",
                    s.wi
                );
                let pdf = flat(&mat, ng).pdf(wo, s.wi);
                assert_close("sample pdf vs pdf()", s.pdf as f64, pdf as f64, 1e-6);
                assert!(
                    rgb_close(s.weight, reflectance, 1e-6),
                    "weight {}",
                    s.weight
                );
                if pdf > 1e-3 {
                    let fcos = flat(&mat, ng).eval(wo, s.wi);
                    assert!(
                        rgb_close(fcos / pdf, s.weight, 1e-4),
                        "f cos / pdf = {} but weight = {}",
                        fcos / pdf,
                        s.weight
                    );
                }
                Some(d(s.wi))
            },
        );
        assert_close("integral of the diffuse pdf", integral, 1.0, 1e-3);
    }
}

/// Independent Fresnel equations for unpolarised light from index n_i into index n_t at
/// incidence cosine cos_i: (R, T, cos_t), T from the transmission amplitudes (so that R + T = 1
/// is a check, not a definition); None on total internal reflection.
fn fresnel_reference(cos_i: f64, n_i: f64, n_t: f64) -> Option<(f64, f64, f64)> {
    let sin_t = n_i / n_t * (1.0 - cos_i * cos_i).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let rp = (n_t * cos_i - n_i * cos_t) / (n_t * cos_i + n_i * cos_t);
    let ts = 2.0 * n_i * cos_i / (n_i * cos_i + n_t * cos_t);
    let tp = 2.0 * n_i * cos_i / (n_t * cos_i + n_i * cos_t);
    let r = 0.5 * (rs * rs + rp * rp);
    let t = n_t * cos_t / (n_i * cos_i) * 0.5 * (ts * ts + tp * tp);
    Some((r, t, cos_t))
}

/// Cases with total internal reflection (the critical cosines are 0.745 and 0.661).
const TIR_CASES: [(f32, bool, f64); 5] = [
    (1.5, true, 0.74),
    (1.5, true, 0.3),
    (1.5, true, 0.02),
    (0.75, false, 0.65),
    (0.75, false, 0.2),
];

fn dielectric_wo(ng: Vec3, inside: bool, cos: f64) -> (Vec3, Vec3) {
    let n = if inside { -ng } else { ng };
    let s = Frame::new(d(n)).s;
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    ((d(n) * cos + s * sin).as_vec3().normalize(), n)
}

#[test]
fn dielectric_reflects_with_fresnel_probability_and_refracts_by_snell() {
    const N: usize = 100_000;
    let ng = Vec3::new(-0.2, 0.5, 0.84).normalize();
    for (k, &(ior, inside, cos)) in DIELECTRIC_CASES.iter().enumerate() {
        let mat = Material::from(DielectricMaterial::new(ior));
        let (wo, n) = dielectric_wo(ng, inside, cos);
        let (n_o, n_t) = if inside {
            (ior as f64, 1.0)
        } else {
            (1.0, ior as f64)
        };
        let cos_o = d(wo).dot(d(n));
        let name = format!(
            "dielectric ior {ior}, wo {}, cos {cos}",
            if inside { "inside" } else { "outside" }
        );
        let (r, t, cos_t) = fresnel_reference(cos_o, n_o, n_t)
            .unwrap_or_else(|| panic!("{name}: unexpected total internal reflection"));
        assert_close(&format!("{name}: R + T"), r + t, 1.0, 1e-12);
        let f = fresnel_dielectric(cos_o as f32, (n_t / n_o) as f32) as f64;
        assert_close(&format!("{name}: Fresnel F"), f, r, 2e-6);
        // Energy: the core's reflectance and the independent transmittance add up to one.
        assert_close(&format!("{name}: F + T"), f + t, 1.0, 2e-6);

        let mut rng = Rng::new(&[20, k as u64]);
        let mut counts = [0u64; 2];
        for _ in 0..N {
            let mode = if rng.next_u32() & 1 == 0 {
                TransportMode::Radiance
            } else {
                TransportMode::Importance
            };
            let s = flat(&mat, ng)
                .sample(wo, rng.next_2d(), rng.next_f32(), mode)
                .unwrap_or_else(|| panic!("{name}: no sample"));
            assert!(s.delta, "{name}: not a delta lobe");
            let wi = d(s.wi);
            assert_close(&format!("{name}: |wi|"), wi.length(), 1.0, 1e-5);
            if wi.dot(d(n)) > 0.0 {
                counts[0] += 1;
                let mirror = 2.0 * d(wo).dot(d(n)) * d(n) - d(wo);
                assert!(
                    (wi - mirror).length() < 1e-5,
                    "{name}: reflection {wi} is not {mirror}"
                );
                assert_close(&format!("{name}: reflection pdf"), s.pdf as f64, r, 2e-6);
                assert!(
                    rgb_close(s.weight, Rgb::ONE, 1e-6),
                    "{name}: reflection weight {}",
                    s.weight
                );
            } else {
                counts[1] += 1;
                // Snell: n_o sin_o = n_t sin_t, in the plane of wo and n, on the far side.
                let sin_o = d(wo).cross(d(n)).length();
                let sin_t = wi.cross(d(n)).length();
                assert_close(&format!("{name}: Snell"), n_t * sin_t, n_o * sin_o, 1e-5);
                assert_close(&format!("{name}: cos theta_t"), -wi.dot(d(n)), cos_t, 1e-5);
                assert_close(
                    &format!("{name}: coplanar"),
                    wi.dot(d(n).cross(d(wo))),
                    0.0,
                    1e-5,
                );
                let tangent_o = d(wo) - d(wo).dot(d(n)) * d(n);
                let tangent_i = wi - wi.dot(d(n)) * d(n);
                assert!(
                    tangent_o.dot(tangent_i) <= 1e-6,
                    "{name}: refraction bends the wrong way"
                );
                assert_close(
                    &format!("{name}: refraction pdf"),
                    s.pdf as f64,
                    1.0 - r,
                    2e-6,
                );
                // Radiance is scaled by (n_o / n_t)^2 = 1 / eta^2 with eta = n_t / n_o; flux
                // (importance) is not.
                let scale = match mode {
                    TransportMode::Radiance => (n_o / n_t).powi(2),
                    TransportMode::Importance => 1.0,
                };
                assert!(
                    rgb_close(s.weight, Rgb::splat(scale as f32), 1e-6),
                    "{name}: refraction weight {} in {mode:?}, expected {scale}",
                    s.weight
                );
            }
        }
        assert_gof(
            &format!("{name}: reflect/refract frequencies"),
            &counts,
            &[N as f64 * r, N as f64 * (1.0 - r)],
        );
    }
}

#[test]
fn dielectric_totally_reflects_beyond_the_critical_angle() {
    let ng = Vec3::new(-0.2, 0.5, 0.84).normalize();
    for (k, &(ior, inside, cos)) in TIR_CASES.iter().enumerate() {
        let mat = Material::from(DielectricMaterial::new(ior));
        let (wo, n) = dielectric_wo(ng, inside, cos);
        let (n_o, n_t) = if inside {
            (ior as f64, 1.0)
        } else {
            (1.0, ior as f64)
        };
        let cos_o = d(wo).dot(d(n));
        assert!(fresnel_reference(cos_o, n_o, n_t).is_none());
        assert_eq!(fresnel_dielectric(cos_o as f32, (n_t / n_o) as f32), 1.0);
        assert!(refract(wo, n, (n_t / n_o) as f32).is_none());
        let mut rng = Rng::new(&[21, k as u64]);
        for _ in 0..10_000 {
            let s = flat(&mat, ng)
                .sample(wo, rng.next_2d(), rng.next_f32(), TransportMode::Radiance)
                .unwrap();
            let mirror = 2.0 * d(wo).dot(d(n)) * d(n) - d(wo);
            assert!(
                (d(s.wi) - mirror).length() < 1e-5,
                "TIR gave {} not {mirror}",
                s.wi
            );
            assert_eq!(s.pdf, 1.0);
            assert_eq!(s.weight, Rgb::ONE);
        }
    }
}

#[test]
fn mirror_reflects_exactly() {
    let reflectance = Rgb::new(0.9, 0.6, 0.3);
    let mat = Material::from(MirrorMaterial {
        reflectance: Texture::Constant(reflectance),
    });
    let mut rng = Rng::new(&[22]);
    for _ in 0..100_000 {
        let ng = sampling::uniform_sphere(rng.next_2d());
        let wo = sampling::uniform_sphere(rng.next_2d());
        if wo.dot(ng).abs() < 1e-3 {
            continue;
        }
        let mode = if rng.next_u32() & 1 == 0 {
            TransportMode::Radiance
        } else {
            TransportMode::Importance
        };
        let s = flat(&mat, ng)
            .sample(wo, rng.next_2d(), rng.next_f32(), mode)
            .unwrap();
        let (wo64, n64) = (d(wo), d(ng));
        let mirror = 2.0 * wo64.dot(n64) * n64 - wo64;
        assert!(
            (d(s.wi) - mirror).length() < 1e-5,
            "mirror of {wo} about {ng}: {} not {mirror}",
            s.wi
        );
        assert_close("cos in = cos out", d(s.wi).dot(n64), wo64.dot(n64), 1e-5);
        assert!(s.delta && s.pdf == 1.0 && s.weight == reflectance);
        assert_eq!(flat(&mat, ng).eval(wo, s.wi), Rgb::ZERO);
        assert_eq!(flat(&mat, ng).pdf(wo, s.wi), 0.0);
    }
}
