//! Normal maps (a material's `normal_map`, Mitsuba's `normalmap`, pbrt-v4's `normalmap`): the
//! texture's colour c gives the shading normal 2c - 1 in the surface's shading frame. A
//! Lambertian surface then reflects rho / pi E cos(shading normal, light): every integrator
//! (the path tracer's next-event estimate, light tracing's adjoint BSDF with its shading
//! normal correction, photons) must give that. Bump maps (`bump_map`, Mitsuba's `bumpmap`)
//! tilt the normal by the height's slope: the same test with a height ramp.

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
    let xml = ortho_rectangle_xml(
        2.0,
        a,
        r#"  <bsdf type="normalmap">
    <texture name="normalmap" type="bitmap"><boolean name="raw" value="true"/><string name="filename" value="n.png"/></texture>
    <ref id="grey"/>
  </bsdf>
"#,
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
    // Mitsuba 3's shadowing term on the tilted half (none on the flat one, alpha = 0).
    let tan2 = |x: f32| x.tan().powi(2);
    let g = 2.0 / (1.0 + (1.0 + tan2(b) / 8.0 * tan2(a)).sqrt());
    assert!(
        (ratio / (want * g) - 1.0).abs() < 0.03,
        "Mitsuba: tilted / flat {ratio}, expected {}",
        want * g
    );

    // Mitsuba 2's specular manifold sampling fork names the image itself (`filename`),
    // repeated `tiles` times: the image of Mitsuba's normalmap of it with that to_uv.
    for tiles in [1, 2] {
        let fork = ortho_rectangle_xml(
            2.0,
            a,
            &format!(
                "  <bsdf type=\"normalmap\"><string name=\"filename\" value=\"n.png\"/><float name=\"tiles\" value=\"{tiles}\"/><ref id=\"grey\"/></bsdf>\n"
            ),
        );
        let mitsuba = ortho_rectangle_xml(
            2.0,
            a,
            &format!(
                "  <bsdf type=\"normalmap\"><texture name=\"normalmap\" type=\"bitmap\"><boolean name=\"raw\" value=\"true\"/><string name=\"filename\" value=\"n.png\"/><transform name=\"to_uv\"><scale value=\"{tiles}\"/></transform></texture><ref id=\"grey\"/></bsdf>\n"
            ),
        );
        let fork = foton_tests::render_file(&foton_tests::write(&dir, "fork.xml", &fork), &[], 2);
        let mitsuba =
            foton_tests::render_file(&foton_tests::write(&dir, "m.xml", &mitsuba), &[], 2);
        assert!(
            fork.pixels() == mitsuba.pixels(),
            "tiles {tiles}: the fork's normal map renders otherwise"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A bump map whose height falls along u at a constant rate tilts a quad's normal by a
/// constant angle: (dp/du + h_u n) x (dp/dv) with dp/du = 4 x, dp/dv = 4 y tilts it towards
/// +x by atan(-h_u / 4). The height is an 8-bit ramp, texel i of 256 at 255 - i, read
/// bilinear: h_u = -256 / 255 per unit of u times `bump_scale`, except in the outer half
/// texels, which the camera does not see. Every integrator must shade it by the tilted
/// cosine, in the TOML form, through pbrt-v4's `displacement` and through Mitsuba's
/// `bumpmap` (a `scale` texture around the height, as Mitsuba 0.6 files write it).
#[test]
fn a_height_ramp_tilts_a_lambertian_surface_by_its_slope() {
    let dir = foton_tests::temp_dir("bump-map");
    let ramp: Vec<u8> = (0..256).map(|i| 255 - i as u8).collect();
    image::GrayImage::from_raw(256, 1, ramp)
        .unwrap()
        .save(dir.join("ramp.png"))
        .unwrap();
    let ramp = dir.join("ramp.png");
    let rho_over_pi = 0.5 / std::f32::consts::PI;
    let a = 60f32.to_radians();
    // A tilt of t degrees towards +x: h_u = -4 tan t.
    let scale_for = |t: f32| 4.0 * t.to_radians().tan() * 255.0 / 256.0;
    let scale = scale_for(30.0);
    for (integrator, spp) in [
        ("path", 16),
        ("bdpt", 16),
        ("vcm", 16),
        ("photon", 16),
        ("sppm", 16),
    ] {
        for (bump_scale, cosine) in [
            (0.0, a.cos()),
            (scale, (a - 30f32.to_radians()).cos()),
            (scale_for(-20.0), (a + 20f32.to_radians()).cos()),
        ] {
            let toml = scene(integrator, spp, None).replace(
                "reflectance = [0.5, 0.5, 0.5]\n",
                &format!(
                    "reflectance = [0.5, 0.5, 0.5]\nbump_map = {{ type = \"bitmap\", filename = {ramp:?}, raw = true }}\nbump_scale = {bump_scale}\n"
                ),
            );
            let film = render_toml("bump-map", &toml, &[], 2);
            let want = rho_over_pi * cosine;
            let mean = film.mean().x;
            assert!(
                (mean / want - 1.0).abs() < 0.03,
                "{integrator}, bump scale {bump_scale}: mean {mean}, rho / pi E cos = {want}"
            );
        }
    }

    // pbrt-v4's `displacement`: the ramp as a float image texture (read at (u, 1 - v); its
    // one row is the same at every v) scaled by its `scale`, on a quad of uv (0, 0) to (1, 1)
    // 4 wide; against the same scene without it (pbrt's distant light is normalised to the
    // scene).
    let pbrt = |displacement: &str| {
        format!(
            r#"LookAt 0 0 3  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-0.5 0.5 -0.5 0.5]
Film "rgb" "integer xresolution" 8 "integer yresolution" 8 "string filename" "o.exr"
Sampler "independent" "integer pixelsamples" 16
Integrator "path" "integer maxdepth" 1
WorldBegin
LightSource "distant" "point3 from" [{lx} 0 {lz}] "point3 to" [0 0 0] "rgb L" [1 1 1]
Texture "h" "float" "imagemap" "string filename" "ramp.png" "string encoding" "linear" "float scale" {scale}
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5] {displacement}
Shape "trianglemesh" "point3 P" [-2 -2 0  2 -2 0  2 2 0  -2 2 0]
  "point2 uv" [0 0  1 0  1 1  0 1] "integer indices" [0 1 2  0 2 3]
"#,
            lx = a.sin(),
            lz = a.cos()
        )
    };
    let mean = |text: String, name: &str| {
        let file = foton_tests::write(&dir, name, &text);
        foton_tests::render_file(&file, &[], 2).mean().x
    };
    let ratio =
        mean(pbrt("\"texture displacement\" \"h\""), "b.pbrt") / mean(pbrt(""), "flat.pbrt");
    let want = (a - 30f32.to_radians()).cos() / a.cos();
    assert!(
        (ratio / want - 1.0).abs() < 0.03,
        "pbrt displacement: bumped / flat {ratio}, expected {want}"
    );

    // Mitsuba: a rectangle scaled to 4 x 4 (dp/du = 4 x as above), the height in a 0.6-style
    // `scale` texture, the BSDF referenced.
    let xml = ortho_rectangle_xml(
        1.0,
        a,
        &format!(
            r#"  <bsdf type="bumpmap">
    <texture type="scale"><float name="scale" value="{}"/>
      <texture type="bitmap"><boolean name="raw" value="true"/><string name="filename" value="ramp.png"/></texture>
    </texture>
    <float name="scale" value="2"/>
    <ref id="grey"/>
  </bsdf>
"#,
            scale / 2.0
        ),
    );
    let file = foton_tests::write(&dir, "b.xml", &xml);
    let scene = foton_loader::load(&file, &[]).unwrap();
    let bumps: Vec<Option<f32>> = scene
        .objects()
        .iter()
        .map(|o| o.bump_map.as_ref().map(|b| b.scale))
        .collect();
    assert_eq!(bumps.len(), 2);
    assert!((bumps[0].unwrap() / scale - 1.0).abs() < 1e-6, "{bumps:?}");
    assert_eq!(
        bumps[1], None,
        "the referenced BSDF's other user is not bumped"
    );
    let film = foton_tests::render_file(&file, &[], 2);
    // Mitsuba's directional light has irradiance 1, its diffuse reflectance 0.5; Mitsuba 3
    // multiplies by its shadowing term (alpha^2 = tan^2 30 / 8, the light 60 degrees off).
    let tan2 = |deg: f32| deg.to_radians().tan().powi(2);
    let g = 2.0 / (1.0 + (1.0 + tan2(30.0) / 8.0 * tan2(60.0)).sqrt());
    let want = rho_over_pi * (a - 30f32.to_radians()).cos() * g;
    let mean = film.mean().x;
    assert!(
        (mean / want - 1.0).abs() < 0.03,
        "Mitsuba bumpmap: mean {mean}, rho / pi E cos = {want}"
    );
}

/// The BSDF a bump map gives (its shading normal tilted 30 degrees off the geometric one) is
/// sampled by its own pdf: chi-square over the sphere of directions, for a diffuse and a
/// rough conductor, with the camera direction in the plane of the tilt and across it; each
/// sample's weight is f cos / pdf.
#[test]
fn a_bump_mapped_bsdf_samples_its_pdf() {
    use crate::lobes::{check_lobe_sampling, quad_bsdf_in};
    use foton_core::api::Vec3;
    let dir = foton_tests::temp_dir("bump-map-sampling");
    let ramp: Vec<u8> = (0..256).map(|i| 255 - i as u8).collect();
    image::GrayImage::from_raw(256, 1, ramp)
        .unwrap()
        .save(dir.join("ramp.png"))
        .unwrap();
    let scale = 4.0 * 30f32.to_radians().tan() * 255.0 / 256.0;
    for (k, material) in [
        "type = \"diffuse\"\nreflectance = [0.8, 0.5, 0.2]",
        "type = \"roughconductor\"\ndistribution = \"ggx\"\nmaterial = \"Au\"\nalpha = 0.3",
    ]
    .into_iter()
    .enumerate()
    {
        let bsdf = quad_bsdf_in(
            &dir,
            &format!(
                "{material}\nbump_map = {{ type = \"bitmap\", filename = \"ramp.png\", raw = true }}\nbump_scale = {scale}"
            ),
        );
        let tilt = bsdf.frame.n.dot(Vec3::Z).acos().to_degrees();
        assert!(
            (tilt - 30.0).abs() < 0.5 && bsdf.frame.n.x > 0.0,
            "tilt {tilt}"
        );
        for (j, wo) in [
            Vec3::new(-0.4, 0.0, 0.9).normalize(),
            Vec3::new(0.2, 0.6, 0.7).normalize(),
        ]
        .into_iter()
        .enumerate()
        {
            let label = format!("{material}, wo = {wo}");
            let deltas =
                check_lobe_sampling(&label, &bsdf, wo, bsdf.frame.n, &[21, k as u64, j as u64]);
            assert_eq!(deltas, 0.0, "{label}: a delta sample");
        }
    }
}

/// Mitsuba's light-side terms on a mapped surface (`map_cut_off`, `map_shadowing`): under a
/// directional light 60 degrees off the quad's normal and a 30 degree tilt towards it, the
/// Lambertian quad reflects rho / pi E cos 30 times Estevez et al.'s term
/// 2 / (1 + sqrt(1 + alpha^2 tan^2 60)), alpha^2 = tan^2 30 / 8; with the light 100 degrees
/// off the normal (below the quad, above the tilted normal) nothing with the cut-off and
/// rho / pi E cos 70 without. Every integrator: the term is on the light's side of the BSDF
/// whichever way the integrator traces.
#[test]
fn mitsuba_light_terms_on_a_tilted_normal_map() {
    let rho_over_pi = 0.5 / std::f32::consts::PI;
    let tan2 = |deg: f32| deg.to_radians().tan().powi(2);
    let g = 2.0 / (1.0 + (1.0 + tan2(30.0) / 8.0 * tan2(60.0)).sqrt());
    for (integrator, spp) in [
        ("path", 16),
        ("bdpt", 16),
        ("vcm", 16),
        ("photon", 16),
        ("sppm", 16),
    ] {
        for (light, terms, want) in [
            (
                60f32,
                "map_shadowing = true\n",
                rho_over_pi * 30f32.to_radians().cos() * g,
            ),
            (
                60.0,
                "map_cut_off = true\n",
                rho_over_pi * 30f32.to_radians().cos(),
            ),
            (100.0, "map_cut_off = true\n", 0.0),
            (100.0, "", rho_over_pi * 70f32.to_radians().cos()),
        ] {
            let a = light.to_radians();
            let toml = scene(integrator, spp, Some(30.0))
                .replace("normal_map = {", &format!("{terms}normal_map = {{"))
                .replace(
                    &format!(
                        "direction = [{}, 0.0, {}]",
                        -60f64.to_radians().sin(),
                        -60f64.to_radians().cos()
                    ),
                    &format!("direction = [{}, 0.0, {}]", -a.sin(), -a.cos()),
                );
            assert!(toml.contains(terms) && toml.contains(&format!("{}", -a.cos())));
            let mean = render_toml("normal-map-terms", &toml, &[], 2).mean().x;
            assert!(
                (mean - want).abs() <= 0.03 * want.max(rho_over_pi * 0.1),
                "{integrator}, light {light} degrees, {terms:?}: mean {mean}, expected {want}"
            );
        }
    }
}

/// A Mitsuba 3 scene: an orthographic view `view` wide (in half-widths) of a 4 x 4 rectangle
/// with `bsdf` (which may refer to the diffuse `grey`), lit by a directional light at angle
/// `a` from its normal in the xz plane, and a sphere behind it that uses `grey` too.
fn ortho_rectangle_xml(view: f32, a: f32, bsdf: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
<integrator type="path"><integer name="max_depth" value="2"/></integrator>
<sensor type="orthographic">
  <transform name="to_world"><scale x="{view}" y="{view}"/><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
  <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
  <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
</sensor>
<emitter type="directional"><vector name="direction" x="{dx}" y="0" z="{dz}"/></emitter>
<bsdf type="diffuse" id="grey"/>
<shape type="rectangle">
  <transform name="to_world"><scale value="2"/></transform>
{bsdf}</shape>
<shape type="sphere"><point name="center" x="0" y="0" z="-10"/><ref id="grey"/></shape>
</scene>"#,
        dx = -a.sin(),
        dz = -a.cos()
    )
}
