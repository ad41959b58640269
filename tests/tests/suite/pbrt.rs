//! pbrt-v4 scenes (issue 33): a scene written in pbrt-v4's format renders as the same scene
//! written in foton's TOML. The strongest check of the reader's conventions: pbrt's
//! left-handed camera space (`Scale -1 1 1` before `LookAt`), `fov` across the shorter image
//! axis (the images are wider than tall), the side an area light's triangles emit on, and
//! the walls' colours on their sides of the image.

use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{render_file, render_toml, repo_root, temp_dir, write};

const Z: Tolerance = Tolerance {
    rel: 0.0,
    z: 4.5,
    floor: 2e-3,
};

/// A Cornell box lit by a small square area light under its ceiling, seen through an image
/// of 48 x 32 pixels.
const PBRT_BOX: &str = r#"
Scale -1 1 1
LookAt 0 1 3.9  0 1 0  0 1 0
Camera "perspective" "float fov" 39.3
Film "rgb" "integer xresolution" 48 "integer yresolution" 32 "string filename" "box.exr"
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 256
Integrator "path" "integer maxdepth" 5
WorldBegin
MakeNamedMaterial "white" "string type" "diffuse" "rgb reflectance" [0.73 0.73 0.73]
MakeNamedMaterial "red" "string type" "diffuse" "rgb reflectance" [0.63 0.065 0.05]
MakeNamedMaterial "green" "string type" "diffuse" "rgb reflectance" [0.14 0.45 0.091]
NamedMaterial "white"
Shape "trianglemesh" "point3 P" [-1 0 1  1 0 1  1 0 -1  -1 0 -1] "integer indices" [0 1 2  0 2 3]
Shape "trianglemesh" "point3 P" [-1 2 -1  1 2 -1  1 2 1  -1 2 1] "integer indices" [0 1 2  0 2 3]
Shape "trianglemesh" "point3 P" [-1 0 -1  1 0 -1  1 2 -1  -1 2 -1] "integer indices" [0 1 2  0 2 3]
NamedMaterial "red"
Shape "trianglemesh" "point3 P" [-1 0 -1  -1 2 -1  -1 2 1  -1 0 1] "integer indices" [0 1 2  0 2 3]
NamedMaterial "green"
Shape "trianglemesh" "point3 P" [1 0 -1  1 0 1  1 2 1  1 2 -1] "integer indices" [0 1 2  0 2 3]
NamedMaterial "white"
AttributeBegin
  Translate -0.45 0.35 -0.35
  Shape "sphere" "float radius" 0.35
AttributeEnd
AttributeBegin
  Material "diffuse" "rgb reflectance" [0 0 0]
  # Wound so that its normal points down, into the box.
  AreaLightSource "diffuse" "rgb L" [4 4 4] "float scale" 2
  Shape "trianglemesh" "point3 P" [-0.25 1.99 -0.25  0.25 1.99 -0.25  0.25 1.99 0.25  -0.25 1.99 0.25]
    "integer indices" [0 1 2  0 2 3]
AttributeEnd
"#;

const TOML_BOX: &str = r#"
[render]
integrator = "path"
spp = 256
seed = 7
max_depth = 5
sampler = "independent"

[film]
width = 48
height = 32
output = "box.exr"

[camera]
position = [0.0, 1.0, 3.9]
look_at = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 39.3
fov_axis = "y"

[materials.white]
type = "diffuse"
reflectance = [0.73, 0.73, 0.73]

[materials.red]
type = "diffuse"
reflectance = [0.63, 0.065, 0.05]

[materials.green]
type = "diffuse"
reflectance = [0.14, 0.45, 0.091]

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-1.0, 0.0, 1.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 0.0, -2.0]
material = "white"

[[shapes]]
type = "quad"
origin = [-1.0, 2.0, -1.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 0.0, 2.0]
material = "white"

[[shapes]]
type = "quad"
origin = [-1.0, 0.0, -1.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "white"

[[shapes]]
type = "quad"
origin = [-1.0, 0.0, -1.0]
u = [0.0, 2.0, 0.0]
v = [0.0, 0.0, 2.0]
material = "red"

[[shapes]]
type = "quad"
origin = [1.0, 0.0, -1.0]
u = [0.0, 0.0, 2.0]
v = [0.0, 2.0, 0.0]
material = "green"

[[shapes]]
type = "sphere"
center = [-0.45, 0.35, -0.35]
radius = 0.35
material = "white"

[[shapes]]
type = "quad"
origin = [-0.25, 1.99, -0.25]
u = [0.5, 0.0, 0.0]
v = [0.0, 0.0, 0.5]
material = "black"
emission = [8.0, 8.0, 8.0]
"#;

#[test]
fn a_pbrt_cornell_box_renders_as_the_same_scene_written_in_toml() {
    let dir = temp_dir("pbrt-box");
    let scene = write(&dir, "box.pbrt", PBRT_BOX);
    let pbrt = render_file(&scene, &[], 2);
    let toml = render_toml("pbrt-box-toml", TOML_BOX, &[], 2);
    assert_eq!((pbrt.width, pbrt.height), (48, 32));
    assert_blocks_agree("pbrt box against its TOML", &pbrt, &toml, 4, Z);
    // The side walls lie within x in [8, 15] and [33, 40] (the image's sides see past the box).
    let walls = |f: &foton_core::film::Film| {
        (
            foton_tests::region_mean(f, 9, 8, 14, 24).0,
            foton_tests::region_mean(f, 34, 8, 39, 24).0,
        )
    };
    let (left, right) = walls(&pbrt);
    assert!(
        left.x > left.y && right.y > right.x,
        "left {left}, right {right}"
    );
    // Without `Scale -1 1 1` pbrt-v4's image is mirrored: red on the right.
    let mirrored = write(
        &dir,
        "mirrored.pbrt",
        &PBRT_BOX.replacen("Scale -1 1 1", "", 1),
    );
    let (left, right) = walls(&render_file(&mirrored, &[], 2));
    assert!(
        left.y > left.x && right.x > right.y,
        "left {left}, right {right}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_cornell_box_pbrt_scene_renders_as_the_toml_one() {
    let scenes = repo_root().join("scenes");
    let set = [
        "film.width=32",
        "film.height=32",
        "render.spp=64",
        "render.sampler=\"independent\"",
    ];
    let pbrt = render_file(&scenes.join("cornell-box.pbrt"), &set, 2);
    let mut toml_set = set.to_vec();
    toml_set.push("render.seed=3");
    let toml = render_file(&scenes.join("cornell-box.toml"), &toml_set, 2);
    assert_blocks_agree(
        "cornell-box.pbrt against cornell-box.toml",
        &pbrt,
        &toml,
        4,
        Z,
    );
}

/// `foton convert` writes a pbrt-v4 scene as the TOML document it reads to: the converted
/// file renders bit for bit as the pbrt file (inline meshes, the mirrored camera, the area
/// light and the sampler carried over).
#[test]
fn convert_writes_the_toml_that_renders_as_the_pbrt_file() {
    let dir = temp_dir("pbrt-convert");
    let pbrt = write(&dir, "box.pbrt", PBRT_BOX);
    let toml = dir.join("box.toml");
    let run = foton_tests::foton(&[
        "convert",
        pbrt.to_str().unwrap(),
        "-o",
        toml.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let text = std::fs::read_to_string(&toml).unwrap();
    assert!(text.contains("positions"), "no inline mesh in:\n{text}");
    let set = ["render.spp=4"];
    let a = render_file(&pbrt, &set, 2);
    let b = render_file(&toml, &set, 2);
    assert!(
        a.pixels().iter().any(|p| p.x > 0.0),
        "a black image proves nothing"
    );
    assert_eq!(
        a.pixels(),
        b.pixels(),
        "the converted TOML renders otherwise"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// pbrt-v4 puts texture coordinates (0, 0) at an image's lower-left corner
/// (`SpectrumImageTexture::Evaluate` reads the image at (s, 1 - t)): an image whose top half
/// is red and bottom half blue, on a quad whose uv (0, 0) is its lower-left corner, appears
/// upright, red above blue, and its `scale` brightens it. PNG texels are sRGB-decoded.
#[test]
fn image_textures_read_the_image_at_s_and_one_minus_t() {
    let dir = temp_dir("pbrt-imagemap");
    let mut img = image::RgbImage::new(1, 2);
    img.put_pixel(0, 0, image::Rgb([255, 0, 0]));
    img.put_pixel(0, 1, image::Rgb([0, 0, 255]));
    img.save(dir.join("rb.png")).unwrap();
    let scene = |scale: f64| {
        format!(
            r#"
Scale -1 1 1
LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8 "string filename" "t.exr"
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 64
Integrator "path" "integer maxdepth" 1
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Texture "rb" "spectrum" "imagemap" "string filename" "rb.png" "string filter" "point" "float scale" {scale}
Material "diffuse" "texture reflectance" "rb"
Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] "integer indices" [0 1 2  0 2 3]
  "point2 uv" [0 0  1 0  1 1  0 1]
"#
        )
    };
    let plain = write(&dir, "plain.pbrt", &scene(1.0));
    let film = render_file(&plain, &[], 2);
    let (top, _) = foton_tests::region_mean(&film, 0, 0, 8, 4);
    let (bottom, _) = foton_tests::region_mean(&film, 0, 4, 8, 8);
    assert!(
        top.x > 0.5 && top.z < 0.01 && bottom.z > 0.5 && bottom.x < 0.01,
        "red above blue: top {top}, bottom {bottom}"
    );
    // The constant environment of radiance 1 reflected by a diffuse white is 1 (it sees
    // only the environment): the texel's linear value times `scale`.
    let (top, se) = foton_tests::region_mean(&film, 0, 0, 8, 4);
    assert!((top.x - 1.0).abs() < 4.0 * se.x + 1e-3, "{top} +- {se}");
    let bright = write(&dir, "bright.pbrt", &scene(0.5));
    let (top, se) = foton_tests::region_mean(&render_file(&bright, &[], 2), 0, 0, 8, 4);
    assert!((top.x - 0.5).abs() < 4.0 * se.x + 1e-3, "{top} +- {se}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// exp(-tau) through pbrt-v4's media, seen against a white environment through a cube of
/// side 1 that holds them: a `homogeneous` absorber of sigma_a = 2 gives exp(-2); a
/// `uniformgrid` of constant density 1 on 4 cells per axis with the same sigma_a reads zero
/// beyond its samples (pbrt-v4's `SampledGrid`), so the density falls linearly to 1/2 over
/// the half cell at each face it crosses, and tau = 2 (1 - cell / 4) = 1.875.
#[test]
fn transmittance_through_pbrt_media_is_exp_minus_tau() {
    let dir = temp_dir("pbrt-media");
    let scene = |medium: &str| {
        format!(
            r#"
Scale -1 1 1
LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 4
Film "rgb" "integer xresolution" 6 "integer yresolution" 6 "string filename" "m.exr"
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 64
Integrator "volpath" "integer maxdepth" 4
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
MakeNamedMedium "m" "rgb sigma_a" [2 2 2] "rgb sigma_s" [0 0 0] {medium}
AttributeBegin
MediumInterface "m" ""
Material "interface"
Shape "trianglemesh" "point3 P" [-0.5 -0.5 -0.5  0.5 -0.5 -0.5  0.5 0.5 -0.5  -0.5 0.5 -0.5
                                -0.5 -0.5 0.5  0.5 -0.5 0.5  0.5 0.5 0.5  -0.5 0.5 0.5]
  "integer indices" [0 3 2  0 2 1  4 5 6  4 6 7  0 1 5  0 5 4  3 7 6  3 6 2  0 4 7  0 7 3  1 2 6  1 6 5]
AttributeEnd
"#
        )
    };
    let homogeneous = write(&dir, "h.pbrt", &scene("\"string type\" \"homogeneous\""));
    let grid = write(
        &dir,
        "g.pbrt",
        &scene(&format!(
            "\"string type\" \"uniformgrid\" \"integer nx\" 4 \"integer ny\" 4 \"integer nz\" 4 \"float density\" [{}] \"point3 p0\" [-0.5 -0.5 -0.5] \"point3 p1\" [0.5 0.5 0.5]",
            vec!["1"; 64].join(" ")
        )),
    );
    for (file, tau) in [(&homogeneous, 2.0f32), (&grid, 1.875)] {
        let film = render_file(file, &[], 2);
        let (mean, se) = foton_tests::region_mean(&film, 0, 0, 6, 6);
        let want = (-tau).exp();
        assert!(
            (mean.x - want).abs() < 4.0 * se.x + 2e-3 * want,
            "{}: {mean} +- {se}, exp(-{tau}) = {want}",
            file.display()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// pbrt-v4's image `infinite` light is an equal-area octahedral map (`EqualAreaSphereToSquare`):
/// the image's top half is the light's -y hemisphere, its bottom half +y. An image white on
/// top and black below lights the underside of a white diffuse plane (reflectance 0.8) to
/// 0.8 x `scale` and leaves its top black; `Rotate 180 1 0 0` on the light swaps them.
#[test]
fn image_infinite_lights_are_equal_area_octahedral_maps() {
    let dir = temp_dir("pbrt-envmap");
    let mut img = image::RgbImage::new(8, 8);
    for y in 0..4 {
        for x in 0..8 {
            img.put_pixel(x, y, image::Rgb([255, 255, 255]));
        }
    }
    img.save(dir.join("sky.png")).unwrap();
    let scene = |eye_y: f64, rotate: &str| {
        format!(
            r#"
LookAt 0 {eye_y} 0  0 0 0  0 0 1
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8 "string filename" "e.exr"
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 64
Integrator "path" "integer maxdepth" 1
WorldBegin
AttributeBegin
{rotate}
LightSource "infinite" "string filename" "sky.png" "float scale" 0.5
AttributeEnd
Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
Shape "trianglemesh" "point3 P" [-5 0 -5  5 0 -5  5 0 5  -5 0 5] "integer indices" [0 1 2  0 2 3]
"#
        )
    };
    for (eye_y, rotate, want) in [
        (-3.0, "", 0.4),
        (3.0, "", 0.0),
        (-3.0, "Rotate 180 1 0 0", 0.0),
        (3.0, "Rotate 180 1 0 0", 0.4),
    ] {
        let file = write(&dir, "e.pbrt", &scene(eye_y, rotate));
        let film = render_file(&file, &[], 2);
        let (mean, se) = foton_tests::region_mean(&film, 0, 0, 8, 8);
        assert!(
            (mean.x - want).abs() < 4.0 * se.x + 2e-3,
            "eye at y = {eye_y}, {rotate:?}: {mean} +- {se}, expected {want}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The scenes checked against pbrt-v4 (scenes/pbrt-v4, docs/pbrt.md) load as they are; the
/// two that only pbrt-v4 renders (its simplepath) load leniently.
#[test]
fn the_scenes_compared_with_pbrt_v4_load() {
    let dir = repo_root().join("scenes/pbrt-v4");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "pbrt") {
            continue;
        }
        let lenient = path.to_string_lossy().ends_with("-sampling.pbrt");
        foton_loader::load_with(&path, &[], &[], lenient)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        n += 1;
    }
    assert!(n >= 8, "{n} scenes");
}
