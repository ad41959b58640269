//! `blend` (Mitsuba's `blendbsdf` and 0.6's `mixturebsdf`): each hit takes one component,
//! chosen with probability its weight by a hash of the hit, so that the surface renders as
//! the weighted sum of its components. Checked against that sum (a diffuse sphere in a
//! constant environment shows rho L, so a blend of two diffuses shows the diffuse of their
//! weighted albedo), the choice's frequency against the weights (binomial bounds), and
//! Mitsuba files read with Mitsuba's meanings.

use crate::mitsuba::scene_folder;
use foton_core::geometry::SurfacePoint;
use foton_core::material::blend::BlendWeights;
use foton_core::material::{Lobe, Material};
use foton_core::sampling::Rng;
use foton_tests::{header, region_mean, render_toml, temp_dir, write};
use glam::{Vec2, Vec3};

/// The scene file of a sphere of material `m`, given as the `[materials.m]` table's text,
/// in a constant environment L = 1 seen by `integrator` at `spp` samples per pixel.
fn sphere_scene(integrator: &str, material: &str, spp: u32) -> String {
    header(integrator, spp, 4, 32, 32)
        + r#"
[camera]
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40.0

[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "m"

[[lights]]
type = "constant"
radiance = [1.0, 1.0, 1.0]
"# + "\n[materials.m]\n"
        + material
}

/// The material of a `[materials.m]` table's text, read by the scene reader; Err: its
/// error.
fn try_material(name: &str, toml: &str) -> Result<Material, String> {
    let dir = temp_dir(name);
    let path = write(&dir, "scene.toml", &sphere_scene("path", toml, 1));
    let scene = foton_loader::load_with(&path, &[], &[], false).map_err(|e| e.to_string());
    let _ = std::fs::remove_dir_all(dir);
    let scene = scene?;
    Ok(scene.materials()[scene.objects()[0].material as usize]
        .value
        .clone())
}

fn material(toml: &str) -> Material {
    try_material("blend-material", toml).unwrap()
}

fn diffuse(rho: f32) -> String {
    format!("{{ type = \"diffuse\", reflectance = [{rho}, {rho}, {rho}] }}")
}

/// The albedo of the diffuse lobe a hit at `p` takes.
fn albedo_at(m: &Material, p: Vec3, uv: Vec2) -> f32 {
    let sp = SurfacePoint {
        p,
        ng: Vec3::Z,
        ns: Vec3::Z,
        uv,
        dpdu: Vec3::ZERO,
        dpdv: Vec3::ZERO,
        attribute: Vec3::ZERO,
    };
    match m.bsdf(&sp).expect("a blend scatters").lobe {
        Lobe::Diffuse(d) => d.reflectance.x,
        other => panic!("{other:?}"),
    }
}

/// Counts, over `n` random points, how often each albedo of `albedos` is chosen, and checks
/// each count against n times its probability within 4.5 binomial standard deviations.
fn check_frequencies(m: &Material, n: usize, albedos: &[(f32, f64)]) {
    let mut rng = Rng::new(&[11]);
    let mut counts = vec![0usize; albedos.len()];
    for _ in 0..n {
        let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0 - 5.0;
        let uv = rng.next_2d();
        let a = albedo_at(m, p, uv);
        // The same point takes the same component.
        assert_eq!(a, albedo_at(m, p, uv));
        let i = albedos
            .iter()
            .position(|(rho, _)| *rho == a)
            .unwrap_or_else(|| panic!("albedo {a} is none of the components'"));
        counts[i] += 1;
    }
    for (&(rho, prob), &count) in albedos.iter().zip(&counts) {
        let mean = n as f64 * prob;
        let sd = (n as f64 * prob * (1.0 - prob)).sqrt();
        assert!(
            (count as f64 - mean).abs() <= 4.5 * sd,
            "albedo {rho}: chosen {count} times of {n}, expected {mean} +- {sd}"
        );
    }
}

/// A blend of weight w chooses its second component at a fraction w of the points; a
/// mixture each at its weight, the rest (1 - the weights' sum) black; nested blends choose
/// independently of their outer blend (a blend of weight 1/2 inside one of weight 1/2: 1/4,
/// 1/4, 1/2).
#[test]
fn each_component_is_chosen_with_probability_its_weight() {
    let n = 40_000;
    for w in [0.0, 0.3, 0.75, 1.0] {
        let m = material(&format!(
            "type = \"blend\"\nweight = {w}\nmaterials = [{}, {}]",
            diffuse(0.2),
            diffuse(0.8)
        ));
        check_frequencies(&m, n, &[(0.2, 1.0 - w), (0.8, w)]);
    }
    let m = material(&format!(
        "type = \"blend\"\nweights = [0.2, 0.5]\nmaterials = [{}, {}]",
        diffuse(0.2),
        diffuse(0.8)
    ));
    check_frequencies(&m, n, &[(0.2, 0.2), (0.8, 0.5), (0.0, 0.3)]);
    let m = material(&format!(
        "type = \"blend\"\nweight = 0.5\nmaterials = [{{ type = \"blend\", weight = 0.5, materials = [{}, {}] }}, {}]",
        diffuse(0.1),
        diffuse(0.2),
        diffuse(0.8)
    ));
    check_frequencies(&m, n, &[(0.1, 0.25), (0.2, 0.25), (0.8, 0.5)]);
}

/// Weights summing above 1 are scaled to sum to 1 (Mitsuba 0.6's `ensureEnergyConservation`,
/// on by default); bad weights and a null component are refused with the key named.
#[test]
fn mixture_weights_are_checked_as_mitsuba_checks_them() {
    let m = material(&format!(
        "type = \"blend\"\nweights = [0.6, 1.2]\nmaterials = [{}, {}]",
        diffuse(0.2),
        diffuse(0.8)
    ));
    let Material::Blend(b) = &m else { panic!() };
    let BlendWeights::Mixture(w) = &b.weights else {
        panic!()
    };
    assert!((w[0] - 1.0 / 3.0).abs() < 1e-6 && (w[1] - 2.0 / 3.0).abs() < 1e-6);
    for (toml, key) in [
        (
            "weights = [0.6, 1.2]\nensure_energy_conservation = false",
            "ensure_energy_conservation",
        ),
        ("weights = [0.5]", "weights"),
        ("weights = [-0.5, 0.5]", "weights"),
        ("weights = [0.0, 0.0]", "weights"),
    ] {
        let text = format!(
            "type = \"blend\"\n{toml}\nmaterials = [{}, {}]",
            diffuse(0.2),
            diffuse(0.8)
        );
        let err = try_material("blend-bad", &text)
            .err()
            .unwrap_or_else(|| panic!("{toml}: accepted"));
        assert!(err.contains(&format!("materials.m.{key}")), "{toml}: {err}");
    }
    let text = format!(
        "type = \"blend\"\nmaterials = [{}, {{ type = \"null\" }}]",
        diffuse(0.2)
    );
    let err = try_material("blend-null", &text).err().unwrap();
    assert!(
        err.contains("materials.m.materials[1].type") && err.contains("null"),
        "{err}"
    );
}

/// A diffuse sphere in a constant environment L = 1 shows its albedo: a blend of diffuses
/// 0.2 and 0.8 at weight w shows 0.2 (1 - w) + 0.8 w, a mixture the weighted sum of its
/// albedos (path tracer and bdpt, whose connections see the same component at a point as its
/// own hit did; 64 spp; within 4 standard errors of the centre's mean, which include the
/// noise of the per-hit choice).
#[test]
fn a_blend_of_diffuses_renders_as_the_diffuse_of_their_weighted_albedo() {
    for (text, rho) in [
        (
            format!(
                "type = \"blend\"\nweight = 0.3\nmaterials = [{}, {}]",
                diffuse(0.2),
                diffuse(0.8)
            ),
            0.2 * 0.7 + 0.8 * 0.3,
        ),
        (
            format!(
                "type = \"blend\"\nweights = [0.2, 0.5]\nmaterials = [{}, {}]",
                diffuse(0.2),
                diffuse(0.8)
            ),
            0.2 * 0.2 + 0.8 * 0.5,
        ),
    ] {
        for integrator in ["path", "bdpt"] {
            let scene = sphere_scene(integrator, &text, 64);
            let film = render_toml("blend-sphere", &scene, &[], 2);
            let (centre, se) = region_mean(&film, 11, 11, 21, 21);
            let off = ((centre - Vec3::splat(rho)).abs() - 4.0 * se).max_element();
            assert!(
                off <= 0.0,
                "{integrator}, {text}: {centre} against {rho} (standard error {se})"
            );
        }
    }
}

/// A Mitsuba 3 `blendbsdf` (its weight of the second BSDF, a nested one and a referenced
/// `twosided` one) and a Mitsuba 0.6 `mixturebsdf` (its `weights` string, scaled when they
/// sum above 1) read as blends of the BSDFs they name.
#[test]
fn mitsuba_blendbsdf_and_mixturebsdf_are_read_as_blends() {
    let dir = scene_folder("mitsuba-blend");
    let v3 = r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
    <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf></bsdf>
    <bsdf type="blendbsdf" id="mix">
        <float name="weight" value="0.3"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf>
        <ref id="white"/>
    </bsdf>
    <shape type="sphere"><ref id="mix"/></shape>
    <emitter type="constant"/>
</scene>
"#;
    let xml = write(&dir, "blend3.xml", v3);
    let scene = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    let m = &scene.materials()[scene.objects()[0].material as usize].value;
    let Material::Blend(b) = m else {
        panic!("{m:?}")
    };
    let BlendWeights::Blend(w) = &b.weights else {
        panic!("{:?}", b.weights)
    };
    assert_eq!(w.at(Vec2::ZERO.into()), Vec3::splat(0.3));
    let rho = |m: &Material| match m {
        Material::Diffuse(d) => (d.reflectance.at(Vec2::ZERO.into()).x, d.twosided),
        other => panic!("{other:?}"),
    };
    assert_eq!(rho(&b.components[0]), (0.2, false));
    assert_eq!(rho(&b.components[1]), (0.8, true));

    let v06 = r#"<scene version="0.6.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
    <bsdf type="twosided" id="mix">
        <bsdf type="mixturebsdf">
            <string name="weights" value="0.6, 0.3;0.3"/>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf>
        </bsdf>
    </bsdf>
    <shape type="sphere"><ref id="mix"/></shape>
    <emitter type="constant"/>
</scene>
"#;
    let xml = write(&dir, "mixture06.xml", v06);
    let scene = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    let m = &scene.materials()[scene.objects()[0].material as usize].value;
    let Material::Blend(b) = m else {
        panic!("{m:?}")
    };
    let BlendWeights::Mixture(w) = &b.weights else {
        panic!("{:?}", b.weights)
    };
    for (got, want) in w.iter().zip([0.5, 0.25, 0.25]) {
        assert!((got - want).abs() < 1e-6, "{w:?}");
    }
    // Wrapped in `twosided`, every component is two-sided.
    for (c, want) in b.components.iter().zip([0.2, 0.5, 0.8]) {
        assert_eq!(rho(c), (want, true));
    }

    // A null BSDF in a blend is refused, as is a blendbsdf of one BSDF.
    for (name, body) in [
        (
            "null.xml",
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/><bsdf type="null"/></bsdf>"#,
        ),
        (
            "one.xml",
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/></bsdf>"#,
        ),
    ] {
        let text = v3.replace(
            r#"<shape type="sphere"><ref id="mix"/></shape>"#,
            &format!(r#"<shape type="sphere">{body}</shape>"#),
        );
        let xml = write(&dir, name, &text);
        let err = foton_loader::load_with(&xml, &[], &[], false)
            .err()
            .unwrap_or_else(|| panic!("{name}: accepted"))
            .to_string();
        assert!(err.contains("blend"), "{name}: {err}");
    }
}
