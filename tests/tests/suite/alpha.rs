//! Cut-outs (a shape's `alpha`, pbrt-v4's `alpha`, Mitsuba's `mask`): a surface present with
//! probability alpha. Every ray query passes it with probability 1 - alpha, camera rays,
//! shadow rays and light paths alike, so every integrator sees the same partly transparent
//! surface; a binary texture cuts the shape exactly along its pattern.

use foton_core::film::Film;
use foton_tests::{header, render_toml, temp_dir, write};

/// A white floor lit by a point light above it, seen from above, with (`screen`) a black
/// quad of the given alpha between the floor and both the light and the camera.
fn screened_floor(integrator: &str, spp: u32, screen: Option<&str>) -> String {
    let mut s = header(integrator, spp, 3, 24, 24)
        + r#"
[camera]
position = [0.0, 3.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = 30.0

[materials.white]
type = "diffuse"
reflectance = [0.8, 0.8, 0.8]

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[lights]]
type = "point"
position = [0.0, 2.0, 0.0]
intensity = [2.0, 2.0, 2.0]

[[shapes]]
type = "quad"
origin = [-2.0, 0.0, 2.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 0.0, -4.0]
material = "white"
"#;
    if let Some(alpha) = screen {
        s += &format!(
            r#"
[[shapes]]
type = "quad"
origin = [-3.0, 1.0, 3.0]
u = [6.0, 0.0, 0.0]
v = [0.0, 0.0, -6.0]
material = "black"
alpha = {alpha}
"#
        );
    }
    s
}

/// A screen of alpha 1/4 between a lit floor and both the light and the camera passes 3/4
/// of the light on the way down and 3/4 of the floor's radiance on the way up: the image is
/// (3/4)^2 of the unscreened one. For every integrator: camera rays (path, the photon
/// mappers' gather rays), shadow rays (next-event estimation, bdpt's and vcm's connections)
/// and light paths (photons, light subpaths) all pass it.
#[test]
fn a_quarter_opaque_screen_passes_three_quarters_each_way_for_every_integrator() {
    assert_screen_passes_nine_sixteenths(
        &[
            ("path", 256),
            ("bdpt", 64),
            ("vcm", 64),
            ("photon", 64),
            ("sppm", 64),
            ("vpm", 64),
            ("ppb", 64),
        ],
        "",
    );
}

/// The same in an absorbing medium filling the scene (shadow rays then carry transmittance,
/// walked past the cut-outs): the absorption is common to both images, so the ratio is
/// still (3/4)^2.
#[test]
fn a_quarter_opaque_screen_in_an_absorbing_medium() {
    let ink = "\n[media.ink]\ntype = \"homogeneous\"\nsigma_a = [0.3, 0.3, 0.3]\n\n[scene]\nmedium = \"ink\"\n";
    assert_screen_passes_nine_sixteenths(
        &[("path", 256), ("bdpt", 64), ("vpm", 64), ("ppb", 64)],
        ink,
    );
}

/// For each integrator, the screened floor (`extra` added to the scene) renders (3/4)^2 of
/// the open one.
fn assert_screen_passes_nine_sixteenths(integrators: &[(&str, u32)], extra: &str) {
    for &(integrator, spp) in integrators {
        let render = |screen| {
            render_toml(
                "alpha-screen",
                &(screened_floor(integrator, spp, screen) + extra),
                &[],
                2,
            )
        };
        let open = render(None).mean().x;
        let screened = render(Some("0.25")).mean().x;
        let ratio = screened / open;
        assert!(
            (ratio / 0.5625 - 1.0).abs() < 0.03,
            "{integrator}{extra}: screened {screened}, open {open}: ratio {ratio}, expected 0.5625"
        );
    }
}

/// A quad cut out by a checkerboard alpha (0 and 1) in front of a glowing one: each pixel
/// shows the glow where the check is cut out and the black quad where it is not, so the
/// image is the checkerboard itself, exactly (no noise: the test is binary).
#[test]
fn a_binary_alpha_texture_cuts_its_pattern_exactly() {
    let scene = header("path", 4, 1, 32, 32)
        + r#"
[camera]
type = "orthographic"
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
view_height = 2.0

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-2.0, -2.0, -1.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 4.0, 0.0]
material = "black"
emission = [1.0, 1.0, 1.0]

[[shapes]]
type = "quad"
origin = [-1.0, -1.0, 0.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "black"
alpha = { type = "checkerboard", color0 = [0.0, 0.0, 0.0], color1 = [1.0, 1.0, 1.0], to_uv = { scale = 2.0 } }
"#;
    let film: Film = render_toml("alpha-checker", &scene, &[], 2);
    // 4 x 4 checks of 8 x 8 pixels; away from the checks' edges each pixel is 0 or 1.
    let mut lit = 0;
    for y in 0..32u32 {
        for x in 0..32u32 {
            let (cx, cy) = (x % 8, y % 8);
            if cx == 0 || cx == 7 || cy == 0 || cy == 7 {
                continue;
            }
            let v = film.pixel(x, y).x;
            let glow = v > 0.5;
            assert!(v == 0.0 || v == 1.0, "pixel ({x}, {y}): {v}");
            if glow {
                lit += 1;
            }
            let (x0, y0) = (x - cx + 3, y - cy + 3);
            let first = film.pixel(x0, y0).x > 0.5;
            assert_eq!(glow, first, "pixel ({x}, {y}) differs from its check");
        }
    }
    assert_eq!(lit, 16 * 36 / 2, "half of the checks' pixels glow");
    // And the pattern alternates: the first two checks differ.
    assert_ne!(film.pixel(3, 3).x > 0.5, film.pixel(11, 3).x > 0.5);
    assert_ne!(film.pixel(3, 3).x > 0.5, film.pixel(3, 11).x > 0.5);
}

/// What a cut-out cannot be is a clear error naming the shape's `alpha`.
#[test]
fn bad_alphas_are_clear_errors() {
    let base = screened_floor("path", 1, None);
    for (extra, words) in [
        ("alpha = 1.5\n", "expected a number in [0, 1]"),
        ("alpha = \"half\"\n", "alpha"),
    ] {
        let dir = temp_dir("alpha-bad");
        let file = write(&dir, "s.toml", &format!("{base}{extra}"));
        let err = foton_loader::load(&file, &[])
            .err()
            .expect("refused")
            .to_string();
        assert!(
            err.contains(words) && err.contains("shapes[0].alpha"),
            "{extra}: {err}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Mitsuba's `mask` BSDF (its `opacity` around a BSDF, nested or referenced, inside
/// `twosided` or around it) is the cut-out of the shapes that use it: a black screen of
/// opacity 0.3 before a glowing wall shows 0.7 of the glow.
#[test]
fn mitsubas_mask_is_a_cut_out() {
    let xml = |bsdf: &str, screen_bsdf: &str| {
        format!(
            r#"<scene version="3.0.0">
<sensor type="perspective">
  <float name="fov" value="30"/>
  <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
  <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
  <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
</sensor>
{bsdf}
<shape type="rectangle">
  <transform name="to_world"><scale value="10"/><translate z="-1"/></transform>
  <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
  <emitter type="area"><rgb name="radiance" value="1"/></emitter>
</shape>
<shape type="rectangle">
  <transform name="to_world"><scale value="10"/></transform>
  {screen_bsdf}
</shape>
</scene>"#
        )
    };
    let black = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>"#;
    let dir = temp_dir("alpha-mask");
    for (i, (defs, screen)) in [
        (
            String::new(),
            format!(r#"<bsdf type="mask"><float name="opacity" value="0.3"/>{black}</bsdf>"#),
        ),
        (
            format!(
                r#"<bsdf type="twosided" id="screen"><bsdf type="mask"><rgb name="opacity" value="0.3"/>{black}</bsdf></bsdf>"#
            ),
            r#"<ref id="screen"/>"#.to_string(),
        ),
        (
            r#"<bsdf type="diffuse" id="black"><rgb name="reflectance" value="0"/></bsdf>
<bsdf type="mask" id="screen"><float name="opacity" value="0.3"/><ref id="black"/></bsdf>"#
                .to_string(),
            r#"<ref id="screen"/>"#.to_string(),
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let file = write(&dir, &format!("mask{i}.xml"), &xml(&defs, &screen));
        let film = foton_tests::render_file(&file, &[], 2);
        let mean = film.mean().x;
        assert!(
            (mean / 0.7 - 1.0).abs() < 0.03,
            "{}: mean {mean}, expected 0.7",
            file.display()
        );
    }
    // A checkerboard opacity: Mitsuba 3 reads a texture as a number with its checkerboard's
    // colours swapped (its `eval_1`; rendered by Mitsuba 3.9.1's volpath, the mask scene
    // agrees with foton only so); Mitsuba 0.6 does not.
    for (version, opaque_first) in [("3.0.0", false), ("0.6.0", true)] {
        let checks = format!(
            r#"<bsdf type="mask"><texture type="checkerboard" name="opacity"><rgb name="color0" value="1"/><rgb name="color1" value="0"/></texture>{black}</bsdf>"#
        );
        let file = write(
            &dir,
            &format!("checks-{version}.xml"),
            &xml("", &checks).replace("3.0.0", version),
        );
        let scene = foton_loader::load(&file, &[]).unwrap();
        let alpha = scene.objects()[1].alpha.as_ref().expect("a cut-out");
        // uv (0.25, 0.25) lies in the check of color0.
        let a = alpha.eval(glam::Vec2::splat(0.25).into()).x;
        assert_eq!(a == 1.0, opaque_first, "{version}: alpha {a}");
    }
    // On an emitter: refused, or (lenient) the mask left out.
    let emitter = xml(
        "",
        &format!(
            r#"<bsdf type="mask"><float name="opacity" value="0.3"/>{black}</bsdf><emitter type="area"><rgb name="radiance" value="1"/></emitter>"#
        ),
    );
    let file = write(&dir, "emitter.xml", &emitter);
    let err = foton_loader::load(&file, &[])
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("cut-out emitter"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Mitsuba 3 comparison scenes (docs/scene-format.md) open as written: the mask's
/// shapes carry their cut-outs, the rough materials their roughness textures.
#[test]
fn the_mitsuba3_comparison_scenes_open_as_written() {
    let root = foton_tests::repo_root().join("scenes/mitsuba3");
    let mask = foton_loader::load(&root.join("mask.xml"), &[]).unwrap();
    let cut: Vec<bool> = mask.objects().iter().map(|o| o.alpha.is_some()).collect();
    assert_eq!(cut, [false, true, true]);
    let rough = foton_loader::load(&root.join("rough-texture.xml"), &[]).unwrap();
    assert!(rough.unused().is_empty(), "{:?}", rough.unused());
    for m in rough.materials() {
        let textured = match &m.value {
            foton_core::material::Material::RoughConductor(r) => r.roughness.is_some(),
            foton_core::material::Material::RoughDielectric(r) => r.roughness.is_some(),
            _ => continue,
        };
        assert!(textured, "{}", m.name);
    }
}
