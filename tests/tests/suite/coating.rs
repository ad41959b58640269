//! `coating` (Mitsuba 0.6's smooth dielectric layer over another material): its sampling
//! against its pdf, its albedo against the model's formula integrated here, every integrator
//! agreeing with `path` on it, and the Mitsuba reader's mapping.

use crate::lobes::{check_lobe_sampling, quad_bsdf};
use foton_core::api::{Rgb, TransportMode, Vec3};
use foton_core::sampling::Rng;
use foton_tests::render_toml;
use foton_tests::stats::{Tolerance, assert_blocks_agree};

const DIFFUSE: &str = r#"type = "coating"
ior = 1.7
sigma_a = [0.1, 0.2, 0.5]
thickness = 2.0
base = { type = "diffuse", reflectance = [0.8, 0.6, 0.4] }"#;

const COPPER: &str = r#"type = "coating"
ior = 1.5
base = { type = "roughconductor", material = "Cu", distribution = "ggx", alpha = 0.2 }"#;

/// Samples follow the pdf (the mirror reflection and the samples that cannot leave the layer
/// are the "no direction" class, expected with 1 - the pdf's integral); each weight is
/// f cos / pdf, or F / p for the mirror.
#[test]
fn coating_samples_its_pdf() {
    for (k, (name, m)) in [("diffuse", DIFFUSE), ("copper", COPPER)]
        .into_iter()
        .enumerate()
    {
        let bsdf = quad_bsdf(&format!("coating-sampling-{name}"), m);
        for (j, wo) in [
            Vec3::new(0.3, 0.1, 0.95).normalize(),
            Vec3::new(-0.8, 0.3, 0.25).normalize(),
        ]
        .into_iter()
        .enumerate()
        {
            let label = format!("coating over {name}, wo = {wo}");
            let got = check_lobe_sampling(&label, &bsdf, wo, Vec3::Z, &[31, k as u64, j as u64]);
            let p_delta = bsdf.delta_probability(wo) as f64;
            assert!(
                (got - p_delta).abs() < 5.0 * (p_delta * (1.0 - p_delta) / 400_000.0).sqrt() + 1e-4,
                "{label}: mirror picked {got}, delta_probability {p_delta}"
            );
        }
    }
}

/// Fresnel reflectance of a smooth dielectric interface, eta inside over outside, from
/// outside at cos_i (written out here, independent of the renderer's).
pub(crate) fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The albedo of a coated diffuse surface seen from `cos_o`, by quadrature of Mitsuba 0.6's
/// model: F(cos_o) + int (rho / pi) (1 - F(cos_o)) (1 - F(cos_i)) A / eta^2 cos_i d omega_i,
/// A = exp(-depth (1 / cos_o' + 1 / cos_i')), the primed cosines refracted into the layer.
fn coated_diffuse_albedo(cos_o: f64, rho: f64, eta: f64, depth: f64) -> f64 {
    let refracted = |c: f64| (1.0 - (1.0 - c * c) / (eta * eta)).sqrt();
    let n = 20_000;
    let mut sum = 0.0;
    for i in 0..n {
        let c = (i as f64 + 0.5) / n as f64;
        let a = (-depth * (1.0 / refracted(cos_o) + 1.0 / refracted(c))).exp();
        // d omega = 2 pi sin d theta = 2 pi d cos.
        sum +=
            rho / std::f64::consts::PI * (1.0 - fresnel(cos_o, eta)) * (1.0 - fresnel(c, eta)) * a
                / (eta * eta)
                * c
                * 2.0
                * std::f64::consts::PI
                / n as f64;
    }
    fresnel(cos_o, eta) + sum
}

/// The mean sample weight is the albedo the formula gives (each channel its own absorption).
#[test]
fn coated_diffuse_albedo_matches_the_model() {
    let bsdf = quad_bsdf("coating-albedo", DIFFUSE);
    let rho = [0.8, 0.6, 0.4];
    let sigma = [0.1, 0.2, 0.5];
    for cos_o in [0.95f32, 0.5, 0.15] {
        let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
        let mut rng = Rng::new(&[5, (cos_o * 100.0) as u64]);
        let n = 400_000;
        let mut sum = glam::DVec3::ZERO;
        for _ in 0..n {
            if let Some(s) = bsdf.sample(wo, rng.next_2d(), rng.next_f32(), TransportMode::Radiance)
            {
                sum += s.weight.as_dvec3();
            }
        }
        let got = sum / n as f64;
        for c in 0..3 {
            let want = coated_diffuse_albedo(cos_o as f64, rho[c], 1.7, sigma[c] * 2.0);
            assert!(
                (got[c] / want - 1.0).abs() < 0.01,
                "cos_o {cos_o}, channel {c}: mean weight {}, the model's albedo {want}",
                got[c]
            );
        }
    }
}

/// Over a smooth metal the coating is one mirror reflection: its weight is the layer's
/// F(cos) plus (1 - F(cos))^2 A times the metal's reflectance (a perfect mirror here), A the
/// layer's absorption along the refracted cosine both ways.
#[test]
fn coating_over_a_smooth_metal_is_one_mirror_reflection() {
    let bsdf = quad_bsdf(
        "coating-metal",
        r#"type = "coating"
ior = 1.5
sigma_a = [0.1, 0.3, 0.6]
base = { type = "conductor" }"#,
    );
    assert!(bsdf.is_delta());
    let mut rng = Rng::new(&[8]);
    for cos in [0.9f32, 0.5, 0.1] {
        let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
        assert_eq!(bsdf.delta_probability(wo), 1.0);
        assert_eq!(bsdf.eval(wo, Vec3::new(-wo.x, 0.0, wo.z)), Rgb::ZERO);
        let s = bsdf
            .sample(wo, rng.next_2d(), rng.next_f32(), TransportMode::Radiance)
            .unwrap();
        assert!(s.delta && (s.wi - Vec3::new(-wo.x, 0.0, wo.z)).length() < 1e-5);
        let f = fresnel(cos as f64, 1.5);
        let cos_in = (1.0 - (1.0 - (cos * cos) as f64) / 2.25).sqrt();
        for (c, sigma) in [0.1, 0.3, 0.6].into_iter().enumerate() {
            let want = f + (1.0 - f).powi(2) * (-2.0 * sigma / cos_in).exp();
            assert!(
                (s.weight[c] as f64 - want).abs() < 1e-4,
                "cos {cos}, channel {c}: weight {}, expected {want}",
                s.weight[c]
            );
        }
    }
}

/// Over a smooth dielectric (Mitsuba 0.6's coated glass) the coating is all deltas and lies
/// on both sides. From either side, the mean weight sent back to the mirror direction is the
/// layer's F(cos) plus (1 - F(cos))^2 A F_glass(cos') (the glass's reflection at the cosine
/// refracted into the layer); the one sent through is (1 - F(cos)) (1 - F_glass(cos'))
/// (1 - F_layer(cos_t)) A, out at the angle the glass alone would refract to (the parallel
/// layer changes no direction), A the layer's absorption along both legs.
#[test]
fn coating_over_glass_reflects_and_transmits_as_the_model_says() {
    let (eta_c, ior, sigma) = (1.5f64, 1.33f64, [0.1, 0.3, 0.6]);
    let bsdf = quad_bsdf(
        "coating-glass",
        r#"type = "coating"
ior = 1.5
sigma_a = [0.1, 0.3, 0.6]
base = { type = "dielectric", ior = 1.33 }"#,
    );
    assert!(bsdf.is_delta());
    let mut rng = Rng::new(&[9]);
    for cos in [0.8f64, -0.8, 0.3, -0.3] {
        let sin = (1.0 - cos * cos).sqrt();
        let wo = Vec3::new(sin as f32, 0.0, cos as f32);
        assert_eq!(bsdf.delta_probability(wo), 1.0);
        // The glass's index relative to the side the light comes from.
        let eta_g = if cos > 0.0 { ior } else { 1.0 / ior };
        let cos_in = (1.0 - sin * sin / (eta_c * eta_c)).sqrt();
        let sin_t = sin / eta_c / eta_g;
        let cos_t = (1.0 - sin_t * sin_t).sqrt();
        let f = fresnel(cos.abs(), eta_c);
        let f_glass = fresnel(cos_in, eta_g);
        let f_out = fresnel(cos_t, 1.0 / eta_c);
        let n = 200_000;
        let (mut back, mut through) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
        for _ in 0..n {
            let Some(s) = bsdf.sample(wo, rng.next_2d(), rng.next_f32(), TransportMode::Importance)
            else {
                continue;
            };
            assert!(s.delta);
            let (tangent, z) = (s.wi.truncate().length() as f64, s.wi.z as f64);
            if z * cos > 0.0 {
                assert!((tangent - sin).abs() < 1e-4, "reflected to {}", s.wi);
                back += s.weight.as_dvec3();
            } else {
                assert!(
                    (tangent - sin / eta_g).abs() < 1e-4,
                    "refracted to {}, the glass alone to sin {}",
                    s.wi,
                    sin / eta_g
                );
                through += s.weight.as_dvec3();
            }
        }
        for (c, sigma) in sigma.into_iter().enumerate() {
            let absorbed = |a: f64, b: f64| (-sigma * (1.0 / a + 1.0 / b)).exp();
            let want_back = f + (1.0 - f).powi(2) * f_glass * absorbed(cos_in, cos_in);
            let want_through =
                (1.0 - f) * (1.0 - f_glass) * (1.0 - f_out) * absorbed(cos_in, cos_t);
            let (got_back, got_through) = (back[c] / n as f64, through[c] / n as f64);
            assert!(
                (got_back - want_back).abs() <= 0.02 * want_back,
                "cos {cos}, channel {c}: reflected {got_back}, expected {want_back}"
            );
            assert!(
                // Zero where the light cannot leave the far side (total internal reflection).
                (got_through - want_through).abs() <= 0.02 * want_through,
                "cos {cos}, channel {c}: transmitted {got_through}, expected {want_through}"
            );
        }
    }
}

/// Every integrator that renders surfaces agrees with `path` on coated spheres and walls:
/// the photon mappers estimate the base's part at the visible point and follow the mirror
/// reflection with its probability.
#[test]
fn integrators_agree_on_coatings() {
    let materials = format!(
        "[materials.coat_diffuse]\n{DIFFUSE}\n\n[materials.coat_copper]\n{COPPER}\n\n[materials.coat_gold]\ntype = \"coating\"\nsigma_a = [0.05, 0.1, 0.3]\nbase = {{ type = \"conductor\", material = \"Au\" }}\n"
    );
    for (a, b) in [
        ("coat_diffuse", "coat_copper"),
        ("coat_gold", "coat_diffuse"),
    ] {
        let scene = crate::bdpt::cornell(a, b, &materials, crate::bdpt::CEILING_LIGHT);
        let render = |integrator: &str, spp: u32| {
            render_toml(
                &format!("coating-{integrator}"),
                &scene,
                &[
                    &format!("render.integrator=\"{integrator}\""),
                    &format!("render.spp={spp}"),
                ],
                2,
            )
        };
        let reference = render("path", 512);
        let tolerance = Tolerance {
            rel: 0.04,
            z: 4.5,
            floor: 1e-3,
        };
        for (integrator, spp) in [("bdpt", 64), ("vcm", 64), ("photon", 64), ("sppm", 64)] {
            let film = render(integrator, spp);
            let (a, b) = (film.mean(), reference.mean());
            assert!(
                (a / b - Rgb::ONE).abs().max_element() < 0.03,
                "{integrator}: image mean {a} against path's {b}"
            );
            assert_blocks_agree(
                &format!("{integrator} against path on coatings {a} and {b}"),
                &film,
                &reference,
                4,
                tolerance,
            );
        }
    }
}

/// Mitsuba 0.6's `coating`: its layer's parameters and the BSDF it covers (nested or
/// referenced) become a `coating` table; a BSDF foton cannot coat is refused, and left
/// uncoated with `--lenient`.
#[test]
fn the_mitsuba_reader_maps_coating() {
    let dir = foton_tests::temp_dir("coating-mitsuba");
    let scene = |bsdf: &str| {
        format!(
            r#"<scene version="0.6.0">
<sensor type="perspective"><transform name="toWorld"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
<emitter type="point"><point name="position" x="0" y="0" z="2"/></emitter>
<bsdf type="roughconductor" id="cu"><string name="material" value="Cu"/></bsdf>
<shape type="rectangle">{bsdf}</shape>
</scene>"#
        )
    };
    let load = |name: &str, bsdf: &str, lenient: bool| {
        let file = foton_tests::write(&dir, name, &scene(bsdf));
        foton_loader::load_with(&file, &[], &[], lenient)
    };
    let s = load(
        "a.xml",
        r#"<bsdf type="coating"><float name="intIOR" value="1.7"/><float name="thickness" value="2"/><rgb name="sigmaA" value="0.1, 0.2, 0.3"/><ref id="cu"/></bsdf>"#,
        false,
    )
    .unwrap();
    let coating = s
        .materials()
        .iter()
        .find_map(|m| match &m.value {
            foton_core::material::Material::Coating(c) => Some(c.clone()),
            _ => None,
        })
        .expect("a coating material");
    assert!(
        (coating.eta - 1.7 / 1.000277).abs() < 1e-5,
        "{}",
        coating.eta
    );
    assert!(
        (coating.depth - Rgb::new(0.2, 0.4, 0.6))
            .abs()
            .max_element()
            < 1e-6
    );
    assert!(matches!(
        *coating.base,
        foton_core::material::Material::RoughConductor(_)
    ));
    let over_plastic = r#"<bsdf type="coating"><bsdf type="plastic"/></bsdf>"#;
    let Err(err) = load("b.xml", over_plastic, false) else {
        panic!("a coating over smooth plastic was read")
    };
    let err = err.to_string();
    assert!(
        err.contains("coating") && err.contains("--lenient"),
        "{err}"
    );
    let s = load("c.xml", over_plastic, true).unwrap();
    assert!(
        s.materials()
            .iter()
            .all(|m| !matches!(m.value, foton_core::material::Material::Coating(_))),
        "left uncoated"
    );
}
