//! Mitsuba 3 XML read with Mitsuba's meanings: the glossy BSDFs, disks, flip_normals,
//! hide_emitters, the sensor's field of view, a shape's media and an emitter without a BSDF;
//! and the project's showroom scene rendered alike by every integrator.

use crate::mitsuba::{mean, ok, render, s, scene_folder};
use foton_loader::image::read_image;
use foton_tests::{foton, repo_root, temp_dir, write};

/// The glossy BSDFs, disks, flip_normals, hide_emitters and the sensor's default field of view
/// read from XML with Mitsuba's meanings: eta = int_ior / ext_ior (air 1.000277 by default,
/// named indices), Beckmann and alpha 0.1 by default, one-sided unless `twosided`; a disk's
/// axes from its to_world; the field of view of a 50 mm lens on 35 mm film along the
/// diagonal.
#[test]
fn glossy_materials_and_shapes_read_as_mitsuba_means_them() {
    use foton_core::material::{
        Material, PlasticMaterial, RoughConductorMaterial, RoughDielectricMaterial,
        RoughPlasticMaterial,
    };
    use foton_core::microfacet::MicrofacetKind;
    let dir = scene_folder("mitsuba-glossy");
    let text = r#"<scene version="3.0.0">
    <integrator type="path"><boolean name="hide_emitters" value="true"/></integrator>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="30"/><integer name="height" value="20"/></film>
    </sensor>
    <bsdf type="roughconductor" id="a">
        <string name="material" value="Au"/><string name="distribution" value="ggx"/>
        <float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.3"/>
    </bsdf>
    <bsdf type="twosided" id="b"><bsdf type="roughplastic"><float name="int_ior" value="1.6"/></bsdf></bsdf>
    <bsdf type="roughdielectric" id="c"><string name="int_ior" value="water"/><float name="ext_ior" value="1.2"/></bsdf>
    <bsdf type="plastic" id="d"><rgb name="diffuse_reflectance" value="0.1, 0.2, 0.3"/><boolean name="nonlinear" value="true"/></bsdf>
    <shape type="sphere"><ref id="a"/></shape>
    <shape type="sphere"><point name="center" x="3" y="0" z="0"/><ref id="b"/></shape>
    <shape type="sphere"><point name="center" x="6" y="0" z="0"/><ref id="c"/></shape>
    <shape type="disk">
        <transform name="to_world"><scale x="2" y="0.5" z="1"/><translate y="-3"/></transform>
        <boolean name="flip_normals" value="true"/><ref id="d"/>
    </shape>
    <emitter type="constant"/>
</scene>
"#;
    let xml = write(&dir, "glossy.xml", text);
    let scene = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    assert!(scene.render().hide_emitters);
    // 50 mm on 35 mm film: a diagonal field of view of 2 atan(43.27 / 100) = 46.8 degrees.
    let toml = dir.join("glossy.toml");
    ok(&foton(&["convert", s(&xml), "-o", s(&toml)]));
    let converted = std::fs::read_to_string(&toml).unwrap();
    assert!(converted.contains("fov_axis = \"diagonal\""), "{converted}");
    assert!(converted.contains("fov = 46.79"), "{converted}");
    let material = |i: usize| &scene.materials()[scene.objects()[i].material as usize].value;
    let Material::RoughConductor(RoughConductorMaterial { lobe, twosided, .. }) = material(0)
    else {
        panic!("{:?}", material(0))
    };
    assert!(!*twosided);
    assert_eq!(lobe.distribution.kind, MicrofacetKind::Ggx);
    assert_eq!(
        (lobe.distribution.alpha_u, lobe.distribution.alpha_v),
        (0.05, 0.3)
    );
    assert_eq!(
        (lobe.eta, lobe.k),
        foton_core::material::conductor_ior("Au").unwrap()
    );
    let Material::RoughPlastic(RoughPlasticMaterial { lobe, twosided, .. }) = material(1) else {
        panic!("{:?}", material(1))
    };
    assert!(*twosided);
    assert_eq!(lobe.distribution.kind, MicrofacetKind::Beckmann);
    assert_eq!(lobe.distribution.alpha_u, 0.1);
    assert!((lobe.eta - 1.6 / 1.000277).abs() < 1e-6);
    let Material::RoughDielectric(RoughDielectricMaterial { lobe, .. }) = material(2) else {
        panic!("{:?}", material(2))
    };
    assert!((lobe.eta - 1.333 / 1.2).abs() < 1e-6, "{}", lobe.eta);
    let Material::Plastic(PlasticMaterial {
        lobe,
        twosided,
        diffuse_reflectance,
        ..
    }) = material(3)
    else {
        panic!("{:?}", material(3))
    };
    assert!(!*twosided && lobe.nonlinear);
    assert_eq!(
        diffuse_reflectance.eval(glam::Vec2::ZERO.into()),
        foton_core::Rgb::new(0.1, 0.2, 0.3)
    );
    assert!((lobe.eta - 1.49 / 1.000277).abs() < 1e-6);
    // The disk: an ellipse of semi-axes 2 and 0.5 at y = -3, turned to face -z.
    let disk = scene
        .accel()
        .primitives()
        .iter()
        .find(|p| p.object == 3)
        .unwrap()
        .shape;
    let foton_core::geometry::Shape::Disk {
        center,
        u,
        v,
        normal,
        ..
    } = disk
    else {
        panic!("{disk:?}")
    };
    assert_eq!(
        (center, u, v),
        (
            glam::Vec3::new(0.0, -3.0, 0.0),
            glam::Vec3::X * 2.0,
            glam::Vec3::Y * 0.5
        )
    );
    assert_eq!(normal, glam::Vec3::NEG_Z);
    // The converted TOML renders the same image.
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    ok(&render(&xml, &a, &["--spp", "2"]));
    ok(&render(&toml, &b, &["--spp", "2"]));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

/// The project's own XML scene of the glossy materials, textures, an environment map and a
/// disk light (scenes/showroom.xml; checked against Mitsuba 3 when it was written: path and
/// sppm image means within 0.1% of Mitsuba's, see docs/scene-format.md) renders alike with
/// path, photon and sppm: photon and sppm agree with path by blocks within their bias.
#[test]
fn the_showroom_renders_alike_with_every_integrator() {
    let xml = repo_root().join("scenes/showroom.xml");
    let dir = scene_folder("showroom");
    let render_with = |name: &str, extra: &[&str]| {
        let out = dir.join(format!("{name}.exr"));
        let mut args = vec!["-D", "res=32"];
        args.extend_from_slice(extra);
        ok(&render(&xml, &out, &args));
        let (w, h, pixels) = read_image(&out).unwrap();
        foton_tests::stats::film_of(w, h, &pixels)
    };
    let path = render_with("path", &["--spp", "256"]);
    let photon = render_with(
        "photon",
        &[
            "--integrator",
            "photon",
            "--spp",
            "16",
            "--set",
            "integrators.photon.global_photons=300000",
        ],
    );
    let sppm = render_with(
        "sppm",
        &[
            "-D",
            "integrator=sppm",
            "--set",
            "integrators.sppm.iterations=64",
            "--set",
            "integrators.sppm.photons_per_iteration=30000",
        ],
    );
    let mean = path.mean();
    assert!(mean.min_element() > 0.1, "{mean}");
    let tolerance = foton_tests::stats::Tolerance {
        rel: 0.12,
        z: 4.0,
        floor: 0.03 * mean.max_element() as f64,
    };
    for (name, film) in [("photon", &photon), ("sppm", &sppm)] {
        foton_tests::stats::assert_blocks_agree(
            &format!("showroom: {name} against path"),
            film,
            &path,
            4,
            tolerance,
        );
        let rel = ((film.mean() - mean) / mean).abs().max_element();
        assert!(rel < 0.03, "{name}: mean {} against {mean}", film.mean());
    }
}

/// A shape's media as Mitsuba crosses them: its `exterior` on the side its normal points to,
/// its interior (none: vacuum) behind; the camera in the sensor's medium, vacuum without one.
#[test]
fn a_shapes_exterior_medium_is_the_medium_in_front_of_it() {
    let dir = scene_folder("mitsuba-exterior");
    let scene = |sensor_medium: &str, exterior: &str| {
        format!(
            r#"<scene version="3.0.0">
    <medium type="homogeneous" id="fog"><rgb name="sigma_t" value="0.1"/></medium>
    <medium type="homogeneous" id="smoke"><rgb name="sigma_t" value="0.5"/></medium>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
        {sensor_medium}
    </sensor>
    <shape type="sphere"><bsdf type="dielectric"/><ref name="exterior" id="{exterior}"/></shape>
    <emitter type="point"><point name="position" x="0" y="3" z="3"/></emitter>
</scene>
"#
        )
    };
    let load = |text: &str| {
        let xml = write(&dir, "scene.xml", text);
        foton_loader::load_with(&xml, &[], &[], false)
    };
    let name = |s: &foton_core::scene::Scene, m: Option<u32>| {
        m.map(|m| s.media()[m as usize].name.clone())
    };
    let s = load(&scene("", "fog")).unwrap();
    assert_eq!(s.ambient_medium(), None);
    assert_eq!(s.camera_medium(), None, "no sensor medium: vacuum");
    let sphere = s.interfaces()[0].unwrap();
    assert_eq!(name(&s, sphere.outside).as_deref(), Some("fog"));
    assert_eq!(sphere.inside, None);
    let s = load(&scene("<ref name=\"medium\" id=\"fog\"/>", "fog")).unwrap();
    assert_eq!(name(&s, s.camera_medium()).as_deref(), Some("fog"));
    assert_eq!(
        s.ambient_medium(),
        None,
        "the shapes say where the media are"
    );
    // Mitsuba renders a camera in fog that sees a sphere in smoke: accepted as written.
    let s = load(&scene("<ref name=\"medium\" id=\"fog\"/>", "smoke")).unwrap();
    assert_eq!(
        name(&s, s.interfaces()[0].unwrap().outside).as_deref(),
        Some("smoke")
    );
}

/// Mitsuba (3.0 to 3.9, as 0.x) gives a shape with an area emitter and no BSDF a black
/// diffuse BSDF, not the diffuse 0.5 of other shapes: the light reflects nothing. A square
/// light of radiance 1 filling the view under a constant environment of radiance 1 is
/// exactly 1 (diffuse 0.5 would add 0.5, the cosine-weighted environment times the albedo).
/// Foton had given such lights the 0.5, which made scenes/glossy-caustic.xml's box 0.5 %
/// brighter than Mitsuba 3 (its light, below the ceiling, sent the light of the floor back).
#[test]
fn an_emitter_without_a_bsdf_reflects_nothing() {
    let dir = temp_dir("mitsuba-emitter-bsdf");
    let xml = write(
        &dir,
        "scene.xml",
        r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="20"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
    <shape type="rectangle">
        <emitter type="area"><rgb name="radiance" value="1, 1, 1"/></emitter>
    </shape>
    <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
</scene>
"#,
    );
    let out = dir.join("light.exr");
    ok(&render(&xml, &out, &[]));
    let m = mean(&out);
    for c in m {
        assert!((c - 1.0).abs() < 1e-4, "the light reflects: {m:?}");
    }
}

/// Mitsuba's `specular_reflectance` and `specular_transmittance` of the smooth dielectrics
/// (a colour or a texture) reach the material, and `difftrans` (Mitsuba 0.6's, with its
/// default 0.5 and its older name `diffuseTransmittance`) is read.
#[test]
fn dielectric_factors_and_difftrans_read_as_mitsuba_means_them() {
    use foton_core::Rgb;
    use foton_core::material::{Material, SurfaceMaterial};
    let dir = scene_folder("mitsuba-dielectric-factors");
    let shapes = |bsdfs: &str, n: usize| {
        let mut s = bsdfs.to_string();
        for i in 0..n {
            s += &format!(
                "<shape type=\"sphere\"><point name=\"center\" x=\"{}\" y=\"0\" z=\"0\"/><ref id=\"b{i}\"/></shape>\n",
                3 * i
            );
        }
        s
    };
    let text = format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
    {}
    <emitter type="constant"/>
</scene>
"#,
        shapes(
            r#"<bsdf type="dielectric" id="b0"><rgb name="specular_reflectance" value="0.5"/></bsdf>
    <bsdf type="thindielectric" id="b1">
        <texture type="checkerboard" name="specular_transmittance"><rgb name="color0" value="0.2"/><rgb name="color1" value="0.6"/></texture>
    </bsdf>
    <bsdf type="difftrans" id="b2"><rgb name="transmittance" value="0.1, 0.2, 0.3"/></bsdf>
    <bsdf type="difftrans" id="b3"/>
"#,
            4
        )
    );
    let xml = write(&dir, "factors.xml", &text);
    let scene = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    let material = |i: usize| &scene.materials()[scene.objects()[i].material as usize].value;
    let Material::Dielectric(m) = material(0) else {
        panic!("{:?}", material(0))
    };
    let b = m.bxdf(glam::Vec2::ZERO.into());
    assert_eq!(
        (b.specular_reflectance, b.specular_transmittance),
        (Rgb::splat(0.5), Rgb::ONE)
    );
    assert!((b.ior - 1.5046 / 1.000277).abs() < 1e-6);
    let Material::ThinDielectric(m) = material(1) else {
        panic!("{:?}", material(1))
    };
    assert!(m.needs_coordinates());
    assert_eq!(
        m.bxdf(glam::Vec2::ZERO.into()).specular_reflectance,
        Rgb::ONE
    );
    let ts: Vec<Rgb> = [(0.25, 0.25), (0.75, 0.25)]
        .map(|(u, v)| m.bxdf(glam::Vec2::new(u, v).into()).specular_transmittance)
        .into();
    assert!(
        ts.contains(&Rgb::splat(0.2)) && ts.contains(&Rgb::splat(0.6)),
        "{ts:?}"
    );
    let transmittance = |i: usize| match material(i) {
        Material::DiffTrans(m) => m.bxdf(glam::Vec2::ZERO.into()).transmittance,
        m => panic!("{m:?}"),
    };
    assert_eq!(transmittance(2), Rgb::new(0.1, 0.2, 0.3));
    assert_eq!(transmittance(3), Rgb::splat(0.5));
    // Mitsuba 0.6's name of the parameter.
    let old = format!(
        r#"<scene version="0.6.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
    {}
    <emitter type="constant"/>
</scene>
"#,
        shapes(
            r#"<bsdf type="difftrans" id="b0"><spectrum name="diffuseTransmittance" value="0.25"/></bsdf>
"#,
            1
        )
    );
    let xml = write(&dir, "old.xml", &old);
    let scene = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    let Material::DiffTrans(m) = &scene.materials()[scene.objects()[0].material as usize].value
    else {
        panic!()
    };
    assert_eq!(
        m.bxdf(glam::Vec2::ZERO.into()).transmittance,
        Rgb::splat(0.25)
    );
}

/// Mitsuba 0.6's bitmap `gamma` (1 linear, -1 sRGB, another a power law) and its `scale`
/// texture (a factor on the texture it holds, a number or a colour; around a bitmap or a
/// checkerboard) read as 0.6 reads them: the diffuse reflectance at a texel is the stored
/// value so decoded, times the factor.
#[test]
fn mitsuba_06_bitmap_gamma_and_scale_textures() {
    use foton_core::material::Material;
    let dir = temp_dir("mitsuba06-gamma-scale");
    image::GrayImage::from_raw(2, 2, vec![128; 4])
        .unwrap()
        .save(dir.join("g.png"))
        .unwrap();
    let v = 128.0f32 / 255.0;
    let srgb = ((v + 0.055) / 1.055).powf(2.4);
    for (texture, want) in [
        (
            r#"<texture type="bitmap" name="reflectance"><string name="filename" value="g.png"/><float name="gamma" value="1"/></texture>"#,
            [v; 3],
        ),
        (
            r#"<texture type="bitmap" name="reflectance"><string name="filename" value="g.png"/><float name="gamma" value="-1"/></texture>"#,
            [srgb; 3],
        ),
        (
            r#"<texture type="bitmap" name="reflectance"><string name="filename" value="g.png"/><float name="gamma" value="2.2"/></texture>"#,
            [v.powf(2.2); 3],
        ),
        (
            r#"<texture type="scale" name="reflectance"><float name="scale" value="0.5"/><texture type="bitmap"><string name="filename" value="g.png"/><float name="gamma" value="1"/></texture></texture>"#,
            [v * 0.5; 3],
        ),
        (
            r#"<texture type="scale" name="reflectance"><rgb name="scale" value="0.5, 1, 0.25"/><texture type="checkerboard"><rgb name="color0" value="0.8"/><rgb name="color1" value="0.8"/></texture></texture>"#,
            [0.4, 0.8, 0.2],
        ),
    ] {
        let xml = format!(
            r#"<scene version="0.6.0">
<sensor type="perspective"><transform name="toWorld"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
<emitter type="point"><point name="position" x="0" y="0" z="2"/></emitter>
<shape type="rectangle"><bsdf type="diffuse">{texture}</bsdf></shape>
</scene>"#
        );
        let file = write(&dir, "s.xml", &xml);
        let scene = foton_loader::load(&file, &[]).unwrap();
        let got = scene
            .materials()
            .iter()
            .find_map(|m| match &m.value {
                Material::Diffuse(d) => Some(d.reflectance.eval(glam::Vec2::new(0.3, 0.3).into())),
                _ => None,
            })
            .unwrap();
        assert!(
            (got - glam::Vec3::from(want)).abs().max_element() < 1e-4,
            "{texture}: reflectance {got}, expected {want:?}"
        );
    }
}
