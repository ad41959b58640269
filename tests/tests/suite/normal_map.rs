//! Normal maps (a material's `normal_map`, Mitsuba's `normalmap`, pbrt-v4's `normalmap`): the
//! texture's colour c gives the shading normal 2c - 1 in the surface's shading frame. A
//! Lambertian surface then reflects rho / pi E cos(shading normal, light): every integrator
//! (the path tracer's next-event estimate, light tracing's adjoint BSDF with its shading
//! normal correction, photons) must give that.

use foton_tests::{header, render_toml};

/// A white quad facing +z under a directional light 60 degrees off its normal (towards +x),
/// seen straight on by an orthographic camera; its normals tilted by `tilt` degrees towards
/// +x by a constant normal map.
fn scene(integrator: &str, spp: u32, tilt: Option<f64>) -> String {
    let map = match tilt {
        Some(b) => {
            let b = b.to_radians();
            let c = |x: f64| (x + 1.0) / 2.0;
            format!(
                "normal_map = {{ type = \"checkerboard\", color0 = [{0}, 0.5, {1}], color1 = [{0}, 0.5, {1}] }}\n",
                c(b.sin()),
                c(b.cos())
            )
        }
        None => String::new(),
    };
    let a = 60f64.to_radians();
    header(integrator, spp, 1, 16, 16)
        + &format!(
            r#"
[camera]
type = "orthographic"
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
view_height = 1.0

[materials.white]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]
{map}
[[lights]]
type = "directional"
direction = [{dx}, 0.0, {dz}]
irradiance = [1.0, 1.0, 1.0]

[[shapes]]
type = "quad"
origin = [-2.0, -2.0, 0.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 4.0, 0.0]
material = "white"
"#,
            dx = -a.sin(),
            dz = -a.cos(),
        )
}

#[test]
fn a_tilted_normal_map_shades_a_lambertian_surface_by_the_tilted_cosine() {
    let rho_over_pi = 0.5 / std::f32::consts::PI;
    for (integrator, spp) in [
        ("path", 16),
        ("bdpt", 16),
        ("vcm", 16),
        ("photon", 16),
        ("sppm", 16),
    ] {
        for (tilt, cosine) in [
            (None, 60f32.to_radians().cos()),
            (Some(30.0), 30f32.to_radians().cos()),
            (Some(-20.0), 80f32.to_radians().cos()),
        ] {
            let film = render_toml("normal-map", &scene(integrator, spp, tilt), &[], 2);
            let want = rho_over_pi * cosine;
            let mean = film.mean().x;
            assert!(
                (mean / want - 1.0).abs() < 0.03,
                "{integrator}, tilt {tilt:?}: mean {mean}, rho / pi E cos = {want}"
            );
        }
    }
}

/// The readers: pbrt-v4's `normalmap` (an image read linear at (u, 1 - v)) and Mitsuba's
/// `normalmap` BSDF (nested, or around a referenced BSDF, whose other users keep their own
/// normals) give the same tilt as the TOML scene above.
#[test]
fn readers_map_normal_maps_as_their_renderers_do() {
    let dir = foton_tests::temp_dir("normal-map-readers");
    // An 8 x 8 8-bit map: its top four rows (pbrt's v > 1/2, Mitsuba's v < 1/2) tilted 30
    // degrees towards +u, the bottom four untilted.
    let b = 30f32.to_radians();
    let byte = |x: f32| ((x + 1.0) / 2.0 * 255.0).round() as u8;
    let tilted = [byte(b.sin()), 128, byte(b.cos())];
    let flat = [128, 128, 255];
    let pixels: Vec<u8> = (0..64)
        .flat_map(|i| if i < 32 { tilted } else { flat })
        .collect();
    image::RgbImage::from_raw(8, 8, pixels)
        .unwrap()
        .save(dir.join("n.png"))
        .unwrap();
    let a = 60f32.to_radians();
    // pbrt: the quad's uv (0, 0) to (1, 1) fills the view.
    let pbrt = format!(
        r#"LookAt 0 0 3  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-2 2 -2 2]
Film "rgb" "integer xresolution" 16 "integer yresolution" 16 "string filename" "o.exr"
Sampler "independent" "integer pixelsamples" 16
Integrator "path" "integer maxdepth" 1
WorldBegin
LightSource "distant" "point3 from" [{lx} 0 {lz}] "point3 to" [0 0 0] "rgb L" [1 1 1]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5] "string normalmap" "n.png"
Shape "trianglemesh" "point3 P" [-2 -2 0  2 -2 0  2 2 0  -2 2 0]
  "point2 uv" [0 0  1 0  1 1  0 1] "integer indices" [0 1 2  0 2 3]
"#,
        lx = a.sin(),
        lz = a.cos()
    );
    let file = foton_tests::write(&dir, "n.pbrt", &pbrt);
    let film = foton_tests::render_file(&file, &[], 2);
    // The image's rows 2 to 6 see v in (0.59, 0.88), tilted; rows 10 to 14 v in (0.12, 0.34),
    // flat (away from the rows the bilinear lookup blends). pbrt's distant light is
    // normalised to the scene: compare the two.
    let (top, _) = foton_tests::region_mean(&film, 0, 2, 16, 7);
    let (bottom, _) = foton_tests::region_mean(&film, 0, 10, 16, 15);
    let ratio = top.x / bottom.x;
    let want = (a - b).cos() / a.cos();
    assert!(
        (ratio / want - 1.0).abs() < 0.03,
        "pbrt: tilted / flat {ratio}, expected {want}"
    );

    // Mitsuba reads the image at (u, v), v = 0 its top row: the tilted rows are at the
    // rectangle's v < 1/2, its lower half.
    let xml = format!(
        r#"<scene version="3.0.0">
<integrator type="path"><integer name="max_depth" value="2"/></integrator>
<sensor type="orthographic">
  <transform name="to_world"><scale x="2" y="2"/><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
  <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
  <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
</sensor>
<emitter type="directional"><vector name="direction" x="{dx}" y="0" z="{dz}"/></emitter>
<bsdf type="diffuse" id="grey"/>
<shape type="rectangle">
  <transform name="to_world"><scale value="2"/></transform>
  <bsdf type="normalmap">
    <texture name="normalmap" type="bitmap"><boolean name="raw" value="true"/><string name="filename" value="n.png"/></texture>
    <ref id="grey"/>
  </bsdf>
</shape>
<shape type="sphere"><point name="center" x="0" y="0" z="-10"/><ref id="grey"/></shape>
</scene>"#,
        dx = -a.sin(),
        dz = -a.cos()
    );
    let file = foton_tests::write(&dir, "n.xml", &xml);
    let scene = foton_loader::load(&file, &[]).unwrap();
    let maps: Vec<bool> = scene
        .objects()
        .iter()
        .map(|o| o.normal_map.is_some())
        .collect();
    assert_eq!(
        maps,
        [true, false],
        "the referenced BSDF's other user keeps its normals"
    );
    let film = foton_tests::render_file(&file, &[], 2);
    let (top, _) = foton_tests::region_mean(&film, 0, 2, 16, 7);
    let (bottom, _) = foton_tests::region_mean(&film, 0, 10, 16, 15);
    let ratio = bottom.x / top.x;
    assert!(
        (ratio / want - 1.0).abs() < 0.03,
        "Mitsuba: tilted / flat {ratio}, expected {want}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
