//! Textured materials (issue 10): a texture lookup against its pixels in a render, textures
//! in every material field that takes a colour, and the errors.

use foton_core::Rgb;
use foton_tests::{foton_with_plugins, header, region_mean, render_toml, temp_dir, write};

/// The sRGB decoding curve, written here from its definition (IEC 61966-2-1).
fn linear(c: u8) -> f32 {
    let x = c as f32 / 255.0;
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// A 4 x 4 PNG of distinct colours; texel (i, j) is (40 + 50 i, 30 + 60 j, 200 - 40 i).
fn texels(i: u32, j: u32) -> [u8; 3] {
    [
        (40 + 50 * i) as u8,
        (30 + 60 * j) as u8,
        (200 - 40 * i) as u8,
    ]
}

/// A two-sided diffuse quad exactly filling a 16 x 16 view, its texture looked up with
/// `nearest`, under a constant environment of radiance 1: with nothing else in the scene the
/// quad's radiance is its reflectance (E = pi L on either side, L_o = rho E / pi), so each
/// 4 x 4 block of pixels is one texel, sRGB-decoded (or not, `raw`). Row 0 of the image is
/// v = 0, at the quad's `origin + v`... as Mitsuba's rectangle: uv (0, 0) at the corner
/// `origin`, and the image's first row at v = 0.
fn textured_quad(integrator: &str, material: &str) -> String {
    header(integrator, 64, 8, 16, 16)
        + &format!(
            r#"
[camera]
position = [0, 0, 10]
look_at = [0, 0, 0]
fov = {fov}

[materials.m]
{material}

# u along +x, v along -y: texel row 0 (v = 0) is at the top of the view.
[[shapes]]
type = "quad"
origin = [-1, 1, 0]
u = [2, 0, 0]
v = [0, -2, 0]
material = "m"

[[lights]]
type = "constant"
radiance = [1, 1, 1]

[integrators.photon]
global_photons = 200000
caustic_photons = 0
k = 100

[integrators.sppm]
iterations = 64
photons_per_iteration = 20000
"#,
            fov = 2.0 * (0.1f64).atan().to_degrees()
        )
}

#[test]
fn a_texture_lookup_renders_its_pixels() {
    let dir = temp_dir("texture-pixels");
    let mut img = image::RgbImage::new(4, 4);
    for (i, j, p) in img.enumerate_pixels_mut() {
        *p = image::Rgb(texels(i, j));
    }
    img.save(dir.join("tex.png")).unwrap();
    let png = dir.join("tex.png");
    for (raw, integrator) in [(false, "path"), (true, "path"), (false, "sppm")] {
        let material = format!(
            "type = \"diffuse\"\nreflectance = {{ type = \"bitmap\", filename = \"{}\", filter_type = \"nearest\", raw = {raw} }}",
            png.display()
        );
        let film = render_toml(
            "texture-pixels",
            &textured_quad(integrator, &material),
            &[],
            2,
        );
        for j in 0..4 {
            for i in 0..4 {
                let (m, se) = region_mean(&film, 4 * i, 4 * j, 4 * i + 4, 4 * j + 4);
                let t = texels(i, j);
                let want = if raw {
                    Rgb::new(t[0] as f32, t[1] as f32, t[2] as f32) / 255.0
                } else {
                    Rgb::new(linear(t[0]), linear(t[1]), linear(t[2]))
                };
                let err = (m - want).abs();
                assert!(
                    err.max_element() < 4.0 * se.max_element() + 0.01 * want.max_element(),
                    "{integrator}, raw {raw}: texel ({i}, {j}) renders {m}, its value is {want} (se {se})"
                );
            }
        }
    }
}

/// A checkerboard with `to_uv` scaled by 2: 4 x 4 squares over the quad, `color0` in the
/// corner at uv (0, 0) (both frac(u), frac(v) <= 1/2).
#[test]
fn a_checkerboard_alternates_its_colours() {
    let material = "type = \"diffuse\"\nreflectance = { type = \"checkerboard\", color0 = [0.8, 0.6, 0.4], color1 = [0.1, 0.2, 0.3], to_uv = { scale = 2 } }";
    let film = render_toml("checkerboard", &textured_quad("path", material), &[], 2);
    for j in 0..4 {
        for i in 0..4 {
            let (m, se) = region_mean(&film, 4 * i, 4 * j, 4 * i + 4, 4 * j + 4);
            let want = if (i + j) % 2 == 0 {
                Rgb::new(0.8, 0.6, 0.4)
            } else {
                Rgb::new(0.1, 0.2, 0.3)
            };
            assert!(
                (m - want).abs().max_element() < 4.0 * se.max_element() + 0.01,
                "square ({i}, {j}): {m} against {want}"
            );
        }
    }
}

/// Every colour field of every material takes a texture: a constant-colour checkerboard
/// (both colours equal) and a `constant` texture render exactly as the plain colour, bit for
/// bit.
#[test]
fn every_colour_field_takes_a_texture() {
    let colour = "[0.7, 0.5, 0.3]";
    let tex = "{ type = \"checkerboard\", color0 = [0.7, 0.5, 0.3], color1 = [0.7, 0.5, 0.3] }";
    let constant = "{ type = \"constant\", value = [0.7, 0.5, 0.3] }";
    for (ty, fields) in [
        ("diffuse", vec!["reflectance"]),
        ("mirror", vec!["reflectance"]),
        ("conductor\"\nmaterial = \"Cu", vec!["specular_reflectance"]),
        (
            "roughconductor\"\nalpha = 0.2\nmaterial = \"Cu",
            vec!["specular_reflectance"],
        ),
        (
            "roughdielectric\"\nalpha = 0.2\nior = 1.3\ndistribution = \"ggx",
            vec!["specular_reflectance", "specular_transmittance"],
        ),
        (
            "dielectric",
            vec!["specular_reflectance", "specular_transmittance"],
        ),
        (
            "thindielectric",
            vec!["specular_reflectance", "specular_transmittance"],
        ),
        ("difftrans", vec!["transmittance"]),
        (
            "plastic",
            vec!["diffuse_reflectance", "specular_reflectance"],
        ),
        (
            "roughplastic\"\nalpha = 0.2\ndistribution = \"ggx",
            vec!["diffuse_reflectance", "specular_reflectance"],
        ),
    ] {
        let body = |value: &str| {
            let mut m = format!("type = \"{ty}\"\n");
            for f in &fields {
                m += &format!("{f} = {value}\n");
            }
            m
        };
        let plain = render_toml(
            "texture-fields",
            &textured_quad("path", &body(colour)),
            &[],
            2,
        );
        let textured = render_toml("texture-fields", &textured_quad("path", &body(tex)), &[], 2);
        assert!(plain.mean().max_element() > 0.0, "{ty}");
        assert!(
            plain.pixels() == textured.pixels(),
            "{ty}: the texture renders differently from its colour"
        );
        let constant = render_toml(
            "texture-fields",
            &textured_quad("path", &body(constant)),
            &[],
            2,
        );
        assert!(
            plain.pixels() == constant.pixels(),
            "{ty}: the constant texture renders differently from its colour"
        );
    }
}

#[test]
fn bad_textures_are_clear_errors() {
    let dir = temp_dir("texture-errors");
    for (material, needles) in [
        (
            "type = \"diffuse\"\nreflectance = { type = \"bitmap\", filename = \"missing.png\" }",
            vec!["materials.m.reflectance.filename", "missing.png"],
        ),
        (
            "type = \"diffuse\"\nreflectance = { type = \"marble\" }",
            vec!["materials.m.reflectance.type", "bitmap, checkerboard"],
        ),
        (
            "type = \"diffuse\"\nreflectance = { type = \"checkerboard\", colour0 = [1, 0, 0] }",
            vec!["colour0"],
        ),
    ] {
        let path = write(&dir, "s.toml", &textured_quad("path", material));
        let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
        for n in needles {
            assert!(
                run.stderr.contains(n),
                "{material}: {n} not in: {}",
                run.stderr
            );
        }
    }
}

/// A volume texture (Mitsuba 3's `volume`) is its grid looked up at the surface's point in
/// the scene: two samples along x over the quad's [-1, 1], at x = -1/2 and 1/2, clamped
/// beyond them and linear between, so each column of 4 x 4 blocks has the grid's value at
/// its centre (the block means a linear function at its middle).
#[test]
fn a_volume_texture_reads_its_grid_where_the_surface_is() {
    let material = "type = \"diffuse\"\nreflectance = { type = \"volume\", volume = { resolution = [2, 1, 1], values = [0.2, 0.5, 0.9, 0.8, 0.1, 0.3], transform = { matrix = [2, 0, 0, -1, 0, 2, 0, -1, 0, 0, 2, -1, 0, 0, 0, 1] } } }";
    let film = render_toml("volume-texture", &textured_quad("path", material), &[], 2);
    let (a, b) = (Rgb::new(0.2, 0.5, 0.9), Rgb::new(0.8, 0.1, 0.3));
    // x at the centres of the four columns of blocks, and where that lies between the samples.
    for (i, t) in [0.0f32, 0.25, 0.75, 1.0].into_iter().enumerate() {
        let want = a + (b - a) * t;
        for j in 0..4 {
            let (m, se) = region_mean(&film, 4 * i as u32, 4 * j, 4 * i as u32 + 4, 4 * j + 4);
            assert!(
                (m - want).abs().max_element() < 4.0 * se.max_element() + 0.01,
                "block ({i}, {j}): {m} against {want}"
            );
        }
    }
}
