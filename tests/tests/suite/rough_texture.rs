//! A microfacet roughness given as a texture (`alpha` a texture table of `roughconductor`
//! and `roughdielectric`; pbrt-v4's `"texture roughness"`, Mitsuba's textured `alpha`): each
//! point is the material of the roughness there.

use foton_core::film::Film;
use foton_tests::{header, region_mean, render_toml};

/// A copper quad seen from above, lit by a point light above each half; `alpha` as given.
fn scene(material: &str, alpha: &str) -> String {
    header("path", 64, 3, 32, 16)
        + &format!(
            r#"
[camera]
type = "orthographic"
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
view_height = 1.0

[materials.metal]
type = "{material}"
distribution = "ggx"
alpha = {alpha}
{extra}

[[lights]]
type = "point"
position = [-0.5, 0.0, 0.6]
intensity = [1.0, 1.0, 1.0]

[[lights]]
type = "point"
position = [0.5, 0.0, 0.6]
intensity = [1.0, 1.0, 1.0]

[[shapes]]
type = "quad"
origin = [-1.0, -0.5, 0.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
material = "metal"
"#,
            extra = if material == "roughconductor" {
                "material = \"Cu\""
            } else {
                "ior = 1.5"
            }
        )
}

/// A checkerboard along u alone (v' = 0.25): `a` on the quad's left half, `b` on its right.
fn checks(a: f32, b: f32) -> String {
    format!(
        "{{ type = \"checkerboard\", color0 = [{a}, {a}, {a}], color1 = [{b}, {b}, {b}], to_uv = {{ matrix = [1, 0, 0, 0, 0, 0.25, 0, 0, 1] }} }}"
    )
}

/// The halves of `textured` against the same halves of `left` and `right`, within `tol`;
/// and the two constants unlike each other there (so that the test can fail).
fn assert_halves(what: &str, textured: &Film, left: &Film, right: &Film, tol: f32) {
    for (half, x0, x1, want) in [("left", 2, 14, left), ("right", 18, 30, right)] {
        let (got, _) = region_mean(textured, x0, 2, x1, 14);
        let (expected, _) = region_mean(want, x0, 2, x1, 14);
        assert!(
            (got.x / expected.x - 1.0).abs() < tol,
            "{what}, {half} half: {} against {}",
            got.x,
            expected.x
        );
    }
    let (a, _) = region_mean(left, 2, 2, 14, 14);
    let (b, _) = region_mean(right, 2, 2, 14, 14);
    assert!((a.x / b.x - 1.0).abs() > 0.1, "{what}: {} and {}", a.x, b.x);
}

#[test]
fn each_point_of_a_textured_roughness_is_the_material_of_its_roughness() {
    // alpha 0.05 on the left half, 0.4 on the right half; 0.05 and 0.4 as the square roots
    // of 0.0025 and 0.16 with remaproughness.
    for material in ["roughconductor", "roughdielectric"] {
        let smooth = render_toml("rough-tex", &scene(material, "0.05"), &[], 2);
        let rough = render_toml("rough-tex", &scene(material, "0.4"), &[], 2);
        for (alpha, sets) in [
            (checks(0.05, 0.4), vec![]),
            (
                checks(0.0025, 0.16),
                vec!["materials.metal.remaproughness=true"],
            ),
        ] {
            let textured = render_toml("rough-tex", &scene(material, &alpha), &sets, 2);
            assert_halves(
                &format!("{material} {sets:?}"),
                &textured,
                &smooth,
                &rough,
                0.02,
            );
        }
    }
}

/// The same for the coat of `coateddiffuse` and the metal of `coatedconductor` (pbrt-v4's
/// `roughness` and `conductor.roughness`, remapped by default).
#[test]
fn a_coats_textured_roughness_is_the_coat_of_each_points_roughness() {
    for (material, key) in [
        ("coateddiffuse", "roughness"),
        ("coatedconductor", "conductor_roughness"),
    ] {
        let scene = |value: &str| {
            scene("roughconductor", "0.1").replace(
                "type = \"roughconductor\"\ndistribution = \"ggx\"\nalpha = 0.1\nmaterial = \"Cu\"",
                &format!("type = \"{material}\"\n{key} = {value}"),
            )
        };
        let smooth = render_toml("rough-coat", &scene("0.01"), &[], 2);
        let rough = render_toml("rough-coat", &scene("0.3"), &[], 2);
        let textured = render_toml("rough-coat", &scene(&checks(0.01, 0.3)), &[], 2);
        assert_halves(material, &textured, &smooth, &rough, 0.03);
    }
}
