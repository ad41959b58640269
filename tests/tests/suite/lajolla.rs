//! lajolla's single-lobe Disney BSDFs (a course renderer's Mitsuba-format scenes): the BSDF
//! foton reads each as evaluates to the homework's formula for that lobe (UCSD CSE 272,
//! homework 1, written out here independently), on a rectangle facing +z; the two lobes foton
//! has as materials of their own (`disney_sheen`, `disney_clearcoat`) sample their pdf.

use crate::coating::fresnel;
use crate::lobes::check_lobe_sampling;
use foton_core::api::{Ray, Rgb, Vec3};
use foton_core::bsdf::Bsdf;
use std::f32::consts::PI;

/// The BSDF of a Mitsuba 0.5 rectangle (normal +z) made of `bsdf`, at its centre.
fn rectangle_bsdf(name: &str, bsdf: &str) -> Bsdf {
    let dir = foton_tests::temp_dir(name);
    let xml = format!(
        r#"<scene version="0.5.0">
<sensor type="perspective"><transform name="toWorld"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
<emitter type="constant"/>
<shape type="rectangle">{bsdf}</shape>
</scene>"#
    );
    let file = foton_tests::write(&dir, "scene.xml", &xml);
    let scene = foton_loader::load_with(&file, &[], &[], false).unwrap();
    let hit = scene
        .intersect(&Ray::new(Vec3::new(0.1, 0.2, 1.0), -Vec3::Z), f32::INFINITY)
        .unwrap();
    scene.bsdf(&hit).unwrap()
}

fn schlick(cos: f32) -> f32 {
    (1.0 - cos.abs()).clamp(0.0, 1.0).powi(5)
}

/// Smith's G1 of an isotropic GGX of `alpha` (the homework's Lambda form).
fn g1(w: Vec3, alpha: f32) -> f32 {
    let lambda = ((1.0 + alpha * alpha * (w.x * w.x + w.y * w.y) / (w.z * w.z)).sqrt() - 1.0) / 2.0;
    1.0 / (1.0 + lambda)
}

fn ggx(h: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    1.0 / (PI * a2 * ((h.x * h.x + h.y * h.y) / a2 + h.z * h.z).powi(2))
}

/// Pairs of directions above the surface (wo towards the viewer, wi towards the light).
fn pairs() -> Vec<(Vec3, Vec3)> {
    let d = |x: f32, y: f32, z: f32| Vec3::new(x, y, z).normalize();
    vec![
        (d(0.3, 0.1, 0.9), d(-0.4, 0.2, 0.8)),
        (d(0.8, -0.2, 0.3), d(-0.7, 0.1, 0.4)),
        (d(0.1, 0.5, 0.6), d(0.2, 0.4, 0.7)),
        (d(-0.9, 0.0, 0.2), d(0.5, -0.5, 0.6)),
    ]
}

fn assert_close(what: &str, got: Rgb, want: Rgb) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= 2e-3 * want[c].abs() + 1e-6,
            "{what}: foton {got}, the homework's formula {want}"
        );
    }
}

#[test]
fn disney_diffuse_is_the_base_diffuse_blended_with_the_fake_subsurface() {
    let (bc, r, ss) = (Rgb::new(0.82, 0.67, 0.16), 0.5f32, 0.5f32);
    let bsdf = rectangle_bsdf(
        "lajolla-diffuse",
        r#"<bsdf type="disneydiffuse"><rgb name="baseColor" value="0.82 0.67 0.16"/><float name="roughness" value="0.5"/><float name="subsurface" value="0.5"/></bsdf>"#,
    );
    for (wo, wi) in pairs() {
        let h = (wo + wi).normalize();
        let hw = h.dot(wi).abs();
        let fd90 = 0.5 + 2.0 * r * hw * hw;
        let fd = |w: Vec3| 1.0 + (fd90 - 1.0) * schlick(w.z);
        let fss90 = r * hw * hw;
        let fss = |w: Vec3| 1.0 + (fss90 - 1.0) * schlick(w.z);
        let base = fd(wo) * fd(wi);
        let sub = 1.25 * (fss(wo) * fss(wi) * (1.0 / (wo.z + wi.z) - 0.5) + 0.5);
        let want = bc * ((1.0 - ss) * base + ss * sub) / PI * wi.z;
        assert_close(&format!("diffuse at {wo}, {wi}"), bsdf.eval(wo, wi), want);
    }
}

#[test]
fn disney_metal_is_ggx_with_schlicks_fresnel_of_the_base_colour() {
    let (bc, r) = (Rgb::new(0.82, 0.67, 0.16), 0.3f32);
    let bsdf = rectangle_bsdf(
        "lajolla-metal",
        r#"<bsdf type="disneymetal"><rgb name="baseColor" value="0.82 0.67 0.16"/><float name="roughness" value="0.3"/></bsdf>"#,
    );
    let alpha = r * r;
    for (wo, wi) in pairs() {
        let h = (wo + wi).normalize();
        let f = bc + (Rgb::ONE - bc) * schlick(h.dot(wi));
        let want = f * (ggx(h, alpha) * g1(wo, alpha) * g1(wi, alpha) / (4.0 * wo.z));
        assert_close(&format!("metal at {wo}, {wi}"), bsdf.eval(wo, wi), want);
    }
}

#[test]
fn disney_glass_reflects_with_the_base_colour_and_refracts_with_its_square_root() {
    let (bc, r, eta) = (Rgb::new(0.82, 0.67, 0.16), 0.4f32, 1.5f32);
    let glass = |name: &str, colour: &str| {
        rectangle_bsdf(
            name,
            &format!(
                r#"<bsdf type="disneyglass"><rgb name="baseColor" value="{colour}"/><float name="roughness" value="0.4"/><float name="eta" value="1.5"/></bsdf>"#
            ),
        )
    };
    let tinted = glass("lajolla-glass", "0.82 0.67 0.16");
    let clear = glass("lajolla-glass-clear", "1 1 1");
    let alpha = r * r;
    for (wo, wi) in pairs() {
        let h = (wo + wi).normalize();
        let f = fresnel(h.dot(wo) as f64, eta as f64) as f32;
        let want = bc * (f * ggx(h, alpha) * g1(wo, alpha) * g1(wi, alpha) / (4.0 * wo.z));
        assert_close(
            &format!("glass reflection at {wo}, {wi}"),
            tinted.eval(wo, wi),
            want,
        );
        // Through the surface near the refracted direction: the clear glass's value times
        // sqrt(base colour).
        let below = Vec3::new(-0.6 * wo.x, -0.6 * wo.y, -wo.z).normalize();
        let through = clear.eval(wo, below);
        assert!(through.max_element() > 0.0, "no refraction to {below}");
        assert_close(
            &format!("glass refraction at {wo}, {below}"),
            tinted.eval(wo, below),
            through * bc.map(f32::sqrt),
        );
    }
}

#[test]
fn disney_clearcoat_is_gtr1_with_schlicks_fresnel_of_index_1_5() {
    let gloss = 0.5f32;
    let bsdf = rectangle_bsdf(
        "lajolla-clearcoat",
        r#"<bsdf type="disneyclearcoat"><float name="clearcoatGloss" value="0.5"/></bsdf>"#,
    );
    let ag = (1.0 - gloss) * 0.1 + gloss * 0.001;
    let a2 = ag * ag;
    for (wo, wi) in pairs() {
        let h = (wo + wi).normalize();
        let f = 0.04 + 0.96 * schlick(h.dot(wi));
        let d = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * h.z * h.z));
        let want = f * d * g1(wo, 0.25) * g1(wi, 0.25) / (4.0 * wo.z);
        assert_close(
            &format!("clearcoat at {wo}, {wi}"),
            bsdf.eval(wo, wi),
            Rgb::splat(want),
        );
    }
    for (j, wo) in [Vec3::new(0.3, 0.1, 0.9), Vec3::new(-0.8, 0.2, 0.3)]
        .into_iter()
        .enumerate()
    {
        let wo = wo.normalize();
        // A rough coat: its lobe spreads over many cells of the chi-square grid.
        let rough = rectangle_bsdf(
            "lajolla-clearcoat-rough",
            r#"<bsdf type="disneyclearcoat"><float name="clearcoatGloss" value="0"/></bsdf>"#,
        );
        check_lobe_sampling(
            &format!("clearcoat, wo = {wo}"),
            &rough,
            wo,
            Vec3::Z,
            &[41, j as u64],
        );
    }
}

#[test]
fn disney_sheen_is_a_tinted_schlick_weight_at_grazing_angles() {
    let (bc, tint) = (Rgb::new(0.82, 0.67, 0.16), 0.5f32);
    let bsdf = rectangle_bsdf(
        "lajolla-sheen",
        r#"<bsdf type="disneysheen"><rgb name="baseColor" value="0.82 0.67 0.16"/><float name="sheenTint" value="0.5"/></bsdf>"#,
    );
    let luminance = 0.2126 * bc[0] + 0.7152 * bc[1] + 0.0722 * bc[2];
    let c_sheen = Rgb::splat(1.0 - tint) + bc / luminance * tint;
    for (wo, wi) in pairs() {
        let h = (wo + wi).normalize();
        let want = c_sheen * (schlick(h.dot(wi)) * wi.z);
        assert_close(&format!("sheen at {wo}, {wi}"), bsdf.eval(wo, wi), want);
    }
    for (j, wo) in [Vec3::new(0.3, 0.1, 0.9), Vec3::new(-0.8, 0.2, 0.3)]
        .into_iter()
        .enumerate()
    {
        let wo = wo.normalize();
        check_lobe_sampling(
            &format!("sheen, wo = {wo}"),
            &bsdf,
            wo,
            Vec3::Z,
            &[43, j as u64],
        );
    }
}
