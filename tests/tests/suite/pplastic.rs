//! `pplastic` (Mitsuba 3's polarised plastic, unpolarised): its sampling against its pdf, its
//! diffuse part against the formula, and the Mitsuba reader's mapping. Its image against
//! Mitsuba 3's: docs/scene-format.md.

use crate::coating::fresnel;
use crate::lobes::{check_lobe_sampling, quad_bsdf};
use foton_core::api::{Rgb, Vec3};

#[test]
fn pplastic_samples_its_pdf() {
    for (k, m) in [
        // Sharp lobes at grazing angles defeat the grid's quadrature of the pdf (the
        // integral that gives the expected count of samples below the horizon): alpha 0.25.
        "type = \"pplastic\"\nalpha = 0.25",
        "type = \"pplastic\"\ndistribution = \"ggx\"\nalpha_u = 0.05\nalpha_v = 0.4\ndiffuse_reflectance = [0.1, 0.2, 0.6]",
    ]
    .into_iter()
    .enumerate()
    {
        let bsdf = quad_bsdf(&format!("pplastic-sampling-{k}"), m);
        for (j, wo) in [
            Vec3::new(0.3, 0.1, 0.95).normalize(),
            Vec3::new(-0.8, 0.3, 0.25).normalize(),
        ]
        .into_iter()
        .enumerate()
        {
            let label = format!("{m:?}, wo = {wo}");
            let deltas = check_lobe_sampling(&label, &bsdf, wo, Vec3::Z, &[41, k as u64, j as u64]);
            assert_eq!(deltas, 0.0, "{label}: a delta sample");
        }
    }
}

/// Without its microfacet reflection (specular_reflectance 0) the lobe is the Lambertian
/// base seen through two smooth interfaces: rho / pi (1 - F(cos_o)) (1 - F(cos_i)) cos_i.
#[test]
fn pplastic_base_is_lambertian_through_two_interfaces() {
    let bsdf = quad_bsdf(
        "pplastic-base",
        "type = \"pplastic\"\nior = 1.6\nspecular_reflectance = [0.0, 0.0, 0.0]\ndiffuse_reflectance = [0.8, 0.5, 0.2]",
    );
    let dir = |deg: f32, phi: f32| {
        let (t, p) = (deg.to_radians(), phi.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    };
    for (a, b) in [(10.0, 40.0), (60.0, 75.0), (85.0, 5.0)] {
        let (wo, wi) = (dir(a, 0.0), dir(b, 130.0));
        let got = bsdf.eval(wo, wi);
        let k = (1.0 - fresnel(wo.z as f64, 1.6)) * (1.0 - fresnel(wi.z as f64, 1.6))
            / std::f64::consts::PI
            * wi.z as f64;
        let want = Rgb::new(0.8, 0.5, 0.2) * k as f32;
        assert!(
            (got - want).abs().max_element() < 1e-5,
            "wo {a}, wi {b}: {got} against {want}"
        );
    }
}
