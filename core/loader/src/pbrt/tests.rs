//! Directive by directive: a small pbrt-v4 text and the document values it reads as.

use crate::reader::{Options, Report};
use foton_core::value::{Document, Node, Table, Value};

fn read(text: &str, lenient: bool) -> Result<(Document, Report), String> {
    static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("foton-pbrt-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("scene.pbrt");
    std::fs::write(&path, text).unwrap();
    let out = super::read(
        &path,
        &Options {
            defines: &[],
            lenient,
        },
    )
    .map_err(|e| e.to_string());
    std::fs::remove_dir_all(&dir).ok();
    out
}

fn doc(text: &str) -> Table {
    read(text, false).unwrap_or_else(|e| panic!("{e}")).0.root
}

fn node<'d>(t: &'d Table, path: &str) -> &'d Node {
    let mut keys = path.split('.');
    let mut n = t
        .get(keys.next().unwrap())
        .unwrap_or_else(|| panic!("{path}"));
    for k in keys {
        n = match &n.value {
            Value::Table(t) => t.get(k).unwrap_or_else(|| panic!("{path}: {k}")),
            Value::Array(a) => &a[k.parse::<usize>().unwrap()],
            other => panic!("{path}: {k} in {other:?}"),
        };
    }
    n
}

fn has(t: &Table, path: &str) -> bool {
    let (head, last) = path.rsplit_once('.').unwrap();
    match &node(t, head).value {
        Value::Table(t) => t.get(last).is_some(),
        _ => false,
    }
}

fn num(t: &Table, path: &str) -> f64 {
    node(t, path)
        .value
        .as_f64()
        .unwrap_or_else(|| panic!("{path}"))
}

fn text(t: &Table, path: &str) -> String {
    match &node(t, path).value {
        Value::Str(s) => s.clone(),
        other => panic!("{path}: {other:?}"),
    }
}

fn nums(t: &Table, path: &str) -> Vec<f64> {
    let Value::Array(a) = &node(t, path).value else {
        panic!("{path}")
    };
    a.iter().map(|n| n.value.as_f64().unwrap()).collect()
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
}

const WORLD: &str = "WorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1]\n";

#[test]
fn lookat_camera_is_mirrored_unless_scaled_by_minus_one_in_x() {
    let t = doc(&format!(
        "LookAt 0 1 5  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\n{WORLD}"
    ));
    assert!(close(&nums(&t, "camera.position"), &[0.0, 1.0, 5.0]));
    assert!(close(&nums(&t, "camera.look_at"), &[0.0, 1.0, 4.0]));
    assert!(close(&nums(&t, "camera.up"), &[0.0, 1.0, 0.0]));
    assert_eq!(num(&t, "camera.fov"), 45.0);
    assert_eq!(text(&t, "camera.fov_axis"), "smaller");
    // pbrt's camera space is left-handed: a LookAt alone puts world -x on the image's right.
    assert_eq!(node(&t, "camera.mirror").value, Value::Bool(true));
    let t = doc(&format!(
        "Scale -1 1 1\nLookAt 0 1 5  0 1 0  0 1 0\nCamera \"perspective\"\n{WORLD}"
    ));
    assert!(!has(&t, "camera.mirror"));
    assert!(close(&nums(&t, "camera.position"), &[0.0, 1.0, 5.0]));
    assert_eq!(num(&t, "camera.fov"), 90.0);
    // The line of the statement is kept.
    assert_eq!(node(&t, "camera.fov").line, 3);
}

#[test]
fn camera_without_lookat_looks_down_z_and_coordinate_systems_are_named() {
    let t = doc(&format!("Camera \"perspective\"\n{WORLD}"));
    assert!(close(&nums(&t, "camera.position"), &[0.0, 0.0, 0.0]));
    assert!(close(&nums(&t, "camera.look_at"), &[0.0, 0.0, 1.0]));
    // CoordSysTransform "camera": world from camera, so a light there sits at the eye.
    let t = doc(
        "LookAt 3 4 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
         AttributeBegin\nCoordSysTransform \"camera\"\nLightSource \"point\" \"point3 from\" [0 0 0]\nAttributeEnd\n",
    );
    assert!(close(&nums(&t, "lights.0.position"), &[3.0, 4.0, 5.0]));
}

#[test]
fn film_sampler_integrator_and_their_defaults() {
    let t = doc(&format!("Camera \"perspective\"\n{WORLD}"));
    assert_eq!(node(&t, "film.width").value, Value::Int(1280));
    assert_eq!(node(&t, "film.height").value, Value::Int(720));
    assert_eq!(text(&t, "film.output"), "pbrt.exr");
    assert_eq!(node(&t, "render.spp").value, Value::Int(16));
    assert_eq!(node(&t, "render.max_depth").value, Value::Int(5));
    assert_eq!(text(&t, "render.integrator"), "path");
    assert_eq!(text(&t, "render.sampler"), "sobol");
    assert_eq!(text(&t, "film.filter.type"), "gaussian");
    let t = doc(&format!(
        "Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 32 \"string filename\" \"x.png\"\n\
         Sampler \"independent\" \"integer pixelsamples\" 4\nIntegrator \"bdpt\" \"integer maxdepth\" 7\n\
         PixelFilter \"box\"\nCamera \"perspective\"\n{WORLD}"
    ));
    assert_eq!(node(&t, "film.width").value, Value::Int(64));
    assert_eq!(text(&t, "film.output"), "x.png");
    assert_eq!(text(&t, "film.filter"), "box");
    assert_eq!(node(&t, "render.spp").value, Value::Int(4));
    assert_eq!(text(&t, "render.sampler"), "independent");
    assert_eq!(text(&t, "render.integrator"), "bdpt");
    assert_eq!(node(&t, "render.max_depth").value, Value::Int(7));
    // pbrt-v4's SPPM runs as many iterations as the sampler has samples per pixel (it has no
    // "iterations" parameter: an error there).
    let t = doc(&format!(
        "Sampler \"halton\" \"integer pixelsamples\" 10\nIntegrator \"sppm\" \"integer photonsperiteration\" 1000 \"float radius\" 0.1\n{WORLD}"
    ));
    assert_eq!(
        node(&t, "integrators.sppm.iterations").value,
        Value::Int(10)
    );
    let e = read(
        &format!("Integrator \"sppm\" \"integer iterations\" 10\n{WORLD}"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("\"integer iterations\""), "{e}");
    assert_eq!(num(&t, "integrators.sppm.initial_radius"), 0.1);
    assert_eq!(
        node(&t, "integrators.sppm.photons_per_iteration").value,
        Value::Int(1000)
    );
}

/// `Identity` resets the transform; `Option` takes pbrt-v4's bare name and value as well as a
/// typed parameter; `ActiveTransform` renders the start transform with a warning, the
/// transforms written for the end time alone left unused.
#[test]
fn identity_option_and_active_transform() {
    let (d, report) = read(
        &format!(
            "Option \"seed\" 3\nOption \"bool disablepixeljitter\" true\nOption \"msereferenceout\" \"x.txt\"\n{WORLD}\
             Translate 5 0 0\nIdentity\nTranslate 1 0 0\n\
             ActiveTransform EndTime\nTranslate 0 7 0\nIdentity\nActiveTransform All\n\
             LightSource \"point\" \"point3 from\" [0 0 0]\n"
        ),
        false,
    )
    .unwrap();
    let p = nums(&d.root, "lights.1.position");
    assert!(close(&p, &[1.0, 0.0, 0.0]), "{p:?}");
    assert!(
        report.warnings.iter().any(|w| w.contains("motion blur")),
        "{:?}",
        report.warnings
    );
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("\"seed\"") && w.contains("ignored")),
        "{:?}",
        report.warnings
    );
    let e = read(&format!("{WORLD}Option \"seed\""), false).unwrap_err();
    assert!(e.contains("the option's value"), "{e}");
}

/// A spherical or realistic camera is refused; `--lenient` renders a perspective camera of
/// pbrt-v4's default fov in its place.
#[test]
fn other_cameras_are_refused_or_a_perspective_stand_in() {
    let text = format!(
        "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"spherical\" \"string mapping\" \"equalarea\"\n{WORLD}"
    );
    let e = read(&text, false).unwrap_err();
    assert!(e.contains("spherical") && e.contains(":2:"), "{e}");
    let (d, report) = read(&text, true).unwrap();
    assert_eq!(num(&d.root, "camera.fov"), 90.0);
    assert!(close(&nums(&d.root, "camera.position"), &[0.0, 0.0, 5.0]));
    assert!(
        report
            .left_out
            .iter()
            .any(|l| l.contains("perspective camera")),
        "{:?}",
        report.left_out
    );
}

/// `whitebalance` (a colour temperature; 0, the default, none) is the film's white balance.
#[test]
fn white_balance_is_the_films() {
    let film = |wb: &str| format!("Film \"rgb\" \"float whitebalance\" {wb}\n{WORLD}");
    assert_eq!(num(&doc(&film("5000")), "film.white_balance"), 5000.0);
    assert!(!has(&doc(&film("0")), "film.white_balance"));
    let e = read(&film("20"), false).unwrap_err();
    assert!(
        e.contains("\"whitebalance\" 20") && e.contains(":1:"),
        "{e}"
    );
}

/// pbrt-v4's other integrators: the simpler estimators of path's image as path, lightpath as
/// bdpt (a note says so), ambientocclusion as foton's `ao` with its two parameters; mlt refused.
#[test]
fn every_pbrt_integrator_maps_or_is_refused() {
    for (pbrt, foton) in [
        ("simplepath", "path"),
        ("simplevolpath", "path"),
        ("randomwalk", "path"),
        ("lightpath", "bdpt"),
        ("ambientocclusion", "ao"),
    ] {
        let extra = if pbrt == "simplepath" {
            "\"bool samplelights\" false \"bool samplebsdf\" true"
        } else {
            ""
        };
        let (d, report) = read(
            &format!("Integrator \"{pbrt}\" \"integer maxdepth\" 3 {extra}\n{WORLD}"),
            false,
        )
        .unwrap_or_else(|e| panic!("{pbrt}: {e}"));
        assert_eq!(text(&d.root, "render.integrator"), foton, "{pbrt}");
        assert_eq!(node(&d.root, "render.max_depth").value, Value::Int(3));
        if foton != "ao" {
            assert!(
                report.notes.iter().any(|n| n.contains(foton)),
                "{pbrt}: {:?}",
                report.notes
            );
        }
    }
    let t = doc(&format!("Integrator \"ambientocclusion\"\n{WORLD}"));
    assert_eq!(node(&t, "integrators.ao.cosine").value, Value::Bool(true));
    assert!(!has(&t, "integrators.ao.max_distance"));
    let t = doc(&format!(
        "Integrator \"ambientocclusion\" \"bool cossample\" false \"float maxdistance\" 2.5\n{WORLD}"
    ));
    assert_eq!(node(&t, "integrators.ao.cosine").value, Value::Bool(false));
    assert_eq!(num(&t, "integrators.ao.max_distance"), 2.5);
    let e = read(
        &format!("Integrator \"ambientocclusion\" \"float maxdistance\" 0\n{WORLD}"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("\"maxdistance\" 0: must be positive"), "{e}");
    let e = read(&format!("Integrator \"mlt\"\n{WORLD}"), false).unwrap_err();
    assert!(e.contains("Metropolis"), "{e}");
    let (d, _) = read(&format!("Integrator \"mlt\"\n{WORLD}"), true).unwrap();
    assert_eq!(text(&d.root, "render.integrator"), "path");
}

#[test]
fn transforms_compose_as_pbrt_does() {
    // Translate then Scale: the scale applies first to the object.
    let t = doc(&format!(
        "{WORLD}AttributeBegin\nTranslate 1 2 3\nScale 2 2 2\nShape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n\
         Shape \"sphere\"\n\
         AttributeBegin\nRotate 90 0 0 1\nTranslate 1 0 0\nShape \"sphere\"\nAttributeEnd\n\
         AttributeBegin\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  4 5 6 1]\nShape \"sphere\"\nAttributeEnd\n\
         AttributeBegin\nTranslate 1 0 0\nConcatTransform [1 0 0 0  0 1 0 0  0 0 1 0  0 1 0 1]\nShape \"sphere\"\nAttributeEnd\n"
    ));
    assert!(close(&nums(&t, "shapes.0.center"), &[1.0, 2.0, 3.0]));
    assert!((num(&t, "shapes.0.radius") - 1.0).abs() < 1e-12);
    // AttributeEnd restored the identity.
    assert!(close(&nums(&t, "shapes.1.center"), &[0.0, 0.0, 0.0]));
    // Rotate 90 about z of (1, 0, 0): (0, 1, 0), counter-clockwise as pbrt's matrix is.
    let c = nums(&t, "shapes.2.center");
    assert!(
        close(
            &c.iter().map(|x| x.round()).collect::<Vec<_>>(),
            &[0.0, 1.0, 0.0]
        ),
        "{c:?}"
    );
    // The 16 numbers are the matrix column by column: the translation last.
    assert!(close(&nums(&t, "shapes.3.center"), &[4.0, 5.0, 6.0]));
    assert!(close(&nums(&t, "shapes.4.center"), &[1.0, 1.0, 0.0]));
    let e = read(&format!("{WORLD}Scale 1 2 1\nShape \"sphere\"\n"), false).unwrap_err();
    assert!(
        e.contains("scene.pbrt:4:1") && e.contains("ellipsoid"),
        "{e}"
    );
}

#[test]
fn orientation_reverse_and_mirrors() {
    let t = doc(&format!(
        "{WORLD}ReverseOrientation\nShape \"sphere\"\nShape \"disk\"\nReverseOrientation\n\
         Scale -1 1 1\nShape \"sphere\"\nShape \"disk\"\n"
    ));
    assert_eq!(node(&t, "shapes.0.flip_normals").value, Value::Bool(true));
    assert_eq!(node(&t, "shapes.1.flip_normals").value, Value::Bool(true));
    // pbrt-v4 flips a sphere's normal under a mirroring transform (it faces inward); a disk's
    // u x v carries the mirror already.
    assert_eq!(node(&t, "shapes.2.flip_normals").value, Value::Bool(true));
    assert!(!has(&t, "shapes.3.flip_normals"));
    assert!(close(&nums(&t, "shapes.3.u"), &[-1.0, 0.0, 0.0]));
}

#[test]
fn triangle_meshes_inline_and_turned_towards_their_normals() {
    let t = doc(&format!(
        "{WORLD}Translate 0 0 1\nShape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\n\
         \"integer indices\" [0 1 2  2 1 3] \"normal N\" [0 0 -1  0 0 -1  0 0 -1  0 0 -1]\n\
         \"point2 uv\" [0 0 1 0 0 1 1 1]\n"
    ));
    assert_eq!(text(&t, "shapes.0.type"), "mesh");
    assert_eq!(nums(&t, "shapes.0.positions").len(), 12);
    assert_eq!(nums(&t, "shapes.0.uvs").len(), 8);
    // Both triangles wind towards +z but their normals point to -z: reversed.
    assert!(close(
        &nums(&t, "shapes.0.indices"),
        &[0.0, 2.0, 1.0, 2.0, 3.0, 1.0]
    ));
    let m = nums(&t, "shapes.0.transform.matrix");
    assert!(close(&m[8..12], &[0.0, 0.0, 1.0, 1.0]), "{m:?}");
    let e = read(
        &format!("{WORLD}Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 1] \"integer indices\" [0 1 4]\n"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("4 is out of range"), "{e}");
}

#[test]
fn area_lights_attach_to_the_shapes_that_follow_in_their_attribute_block() {
    let t = doc(&format!(
        "{WORLD}AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 2 3] \"float scale\" 2\n\
         Shape \"sphere\"\nAttributeEnd\nShape \"sphere\"\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"float power\" 10\n\
         Shape \"trianglemesh\" \"point3 P\" [0 0 0 2 0 0 0 2 0]\nAttributeEnd\n"
    ));
    assert!(close(&nums(&t, "shapes.0.emission"), &[2.0, 4.0, 6.0]));
    assert!(!has(&t, "shapes.1.emission"));
    // power / (pi area): the triangle's area is 2.
    let e = nums(&t, "shapes.2.emission");
    let want = 10.0 / (std::f64::consts::PI * 2.0);
    assert!(close(&e, &[want, want, want]), "{e:?}");
    // Two-sided: `emission_twosided`, and `power` shared by the two sides; on a mesh, per
    // triangle (pbrt-v4 makes each triangle a light of its own).
    let t = doc(&format!(
        "{WORLD}AreaLightSource \"diffuse\" \"bool twosided\" true \"float power\" 10\n\
         Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  1 1 0  0 1 0] \"integer indices\" [0 1 2  0 2 3]\n"
    ));
    assert!(matches!(
        node(&t, "shapes.0.emission_twosided").value,
        Value::Bool(true)
    ));
    let e = nums(&t, "shapes.0.emission");
    let want = 10.0 / (2.0 * std::f64::consts::PI * 0.5);
    assert!(close(&e, &[want, want, want]), "{e:?}");
    // A mesh without "N" is shaded flat, as pbrt-v4 shades it.
    assert!(matches!(
        node(&t, "shapes.0.compute_normals").value,
        Value::Bool(false)
    ));
}

#[test]
fn materials_named_and_anonymous() {
    let t = doc(&format!(
        "{WORLD}MakeNamedMaterial \"red wall\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.6 0.1 0.1]\n\
         Material \"dielectric\" \"float eta\" 1.33\nShape \"sphere\"\n\
         NamedMaterial \"red wall\"\nShape \"sphere\"\n\
         Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.04\nShape \"sphere\"\n\
         Material \"conductor\" \"rgb eta\" [0.2 0.9 1.1] \"rgb k\" [3.9 2.4 2.2]\nShape \"sphere\"\n\
         Material \"interface\"\nShape \"sphere\"\n"
    ));
    let m = |i: usize| text(&t, &format!("shapes.{i}.material"));
    assert_eq!(text(&t, &format!("materials.{}.type", m(0))), "dielectric");
    assert_eq!(num(&t, &format!("materials.{}.ior", m(0))), 1.33);
    assert_eq!(text(&t, &format!("materials.{}.type", m(1))), "diffuse");
    assert!(close(
        &nums(&t, &format!("materials.{}.reflectance", m(1))),
        &[0.6, 0.1, 0.1]
    ));
    assert_eq!(
        text(&t, &format!("materials.{}.type", m(2))),
        "roughconductor"
    );
    // Gold's RGB index fitted to pbrt-v4's spectral Fresnel reflectance (spectra.rs).
    let (eta, k) = super::spectra::metal_rgb_ior("Au", 1.0).unwrap();
    assert!(close(
        &nums(&t, &format!("materials.{}.eta", m(2))),
        &eta.to_array()
    ));
    assert!(close(
        &nums(&t, &format!("materials.{}.k", m(2))),
        &k.to_array()
    ));
    assert_eq!(text(&t, &format!("materials.{}.distribution", m(2))), "ggx");
    assert!((num(&t, &format!("materials.{}.alpha", m(2))) - 0.2).abs() < 1e-12);
    assert_eq!(text(&t, &format!("materials.{}.type", m(3))), "conductor");
    assert!(close(
        &nums(&t, &format!("materials.{}.k", m(3))),
        &[3.9, 2.4, 2.2]
    ));
    assert_eq!(text(&t, &format!("materials.{}.type", m(4))), "null");
    // Before any Material: pbrt-v4's default, diffuse 0.5.
    let t = doc(&format!("{WORLD}Shape \"sphere\"\n"));
    assert_eq!(text(&t, "shapes.0.material"), "default");
    assert_eq!(text(&t, "materials.default.type"), "diffuse");
    let e = read(&format!("{WORLD}NamedMaterial \"nope\"\n"), false).unwrap_err();
    assert!(e.contains("no material named \"nope\""), "{e}");
}

#[test]
fn lights_point_distant_infinite() {
    let t = doc(
        "WorldBegin\nTranslate 0 1 0\nLightSource \"point\" \"rgb I\" [1 2 3] \"point3 from\" [1 0 0] \"float scale\" 2\n\
         LightSource \"point\" \"float power\" 100\n\
         LightSource \"distant\" \"point3 from\" [0 10 0] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n\
         LightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n",
    );
    assert!(close(&nums(&t, "lights.0.position"), &[1.0, 1.0, 0.0]));
    assert!(close(&nums(&t, "lights.0.intensity"), &[2.0, 4.0, 6.0]));
    let i = 100.0 / (4.0 * std::f64::consts::PI);
    assert!(close(&nums(&t, "lights.1.intensity"), &[i, i, i]));
    assert_eq!(text(&t, "lights.2.type"), "directional");
    assert!(close(&nums(&t, "lights.2.direction"), &[0.0, -1.0, 0.0]));
    assert!(close(&nums(&t, "lights.2.irradiance"), &[3.0, 3.0, 3.0]));
    assert_eq!(text(&t, "lights.3.type"), "constant");
}

#[test]
fn spot_lights_keep_pbrts_cone_and_smoothstep_and_power() {
    let t = doc(
        "WorldBegin\nTranslate 0 1 0\nLightSource \"spot\" \"rgb I\" [1 2 3] \"point3 from\" [0 2 0] \"point3 to\" [1 2 0] \"float coneangle\" 40 \"float conedeltaangle\" 10\n\
         LightSource \"spot\" \"float power\" 50\n",
    );
    assert_eq!(text(&t, "lights.0.type"), "spot");
    assert_eq!(text(&t, "lights.0.falloff"), "smoothstep");
    assert!(close(&nums(&t, "lights.0.position"), &[0.0, 3.0, 0.0]));
    assert!(close(&nums(&t, "lights.0.direction"), &[1.0, 0.0, 0.0]));
    assert!(close(&nums(&t, "lights.0.intensity"), &[1.0, 2.0, 3.0]));
    assert_eq!(num(&t, "lights.0.cutoff_angle"), 40.0);
    assert_eq!(num(&t, "lights.0.beam_width"), 30.0);
    // pbrt-v4's defaults (cone 30, delta 5, along +z) and `power` over the smoothstep cone.
    assert!(close(&nums(&t, "lights.1.direction"), &[0.0, 0.0, 1.0]));
    let (e, s) = (30f64.to_radians().cos(), 25f64.to_radians().cos());
    let i = 50.0 / (2.0 * std::f64::consts::PI * ((1.0 - s) + (s - e) / 2.0));
    assert!(close(&nums(&t, "lights.1.intensity"), &[i, i, i]));
    let e = read(
        "WorldBegin\nLightSource \"spot\" \"float coneangle\" 120\n",
        false,
    )
    .unwrap_err();
    assert!(
        e.contains("scene.pbrt:2:1") && e.contains("coneangle"),
        "{e}"
    );
}

#[test]
fn unsupported_is_an_error_or_left_out_with_lenient() {
    let text = format!(
        "{WORLD}Shape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\nShape \"sphere\" \"float radius\" 1 \"float bogus\" 2\n"
    );
    let e = read(&text, false).unwrap_err();
    assert!(
        e.contains("scene.pbrt:3:1") && e.contains("Shape \"curve\""),
        "{e}"
    );
    let (d, report) = read(&text, true).unwrap();
    assert_eq!(report.left_out.len(), 2, "{:?}", report.left_out);
    assert!(report.left_out[0].contains("curve"));
    assert!(
        report.left_out[1].contains("\"float bogus\""),
        "{:?}",
        report.left_out
    );
    assert_eq!(nums(&d.root, "shapes.0.center").len(), 3);
    let e = read("Shape \"sphere\"\n", false).unwrap_err();
    assert!(e.contains("no WorldBegin"), "{e}");
    let e = read(&format!("{WORLD}AttributeBegin\n"), false).unwrap_err();
    assert!(
        e.contains("scene.pbrt:3:1") && e.contains("never ended"),
        "{e}"
    );
}

#[test]
fn object_instances_are_copies_under_the_instance_transform() {
    let t = doc(&format!(
        "{WORLD}ObjectBegin \"ball\"\nTranslate 1 0 0\nShape \"sphere\"\nObjectEnd\n\
         Translate 0 5 0\nObjectInstance \"ball\"\n"
    ));
    let Value::Array(shapes) = &node(&t, "shapes").value else {
        panic!()
    };
    assert_eq!(shapes.len(), 1);
    assert!(close(&nums(&t, "shapes.0.center"), &[1.0, 5.0, 0.0]));
}

#[test]
fn plymesh_reads_ply_and_ply_gz_and_inline_meshes_build() {
    use std::io::Write;
    let dir = std::env::temp_dir().join(format!("foton-pbrt-ply-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
               element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    std::fs::write(dir.join("tri.ply"), ply).unwrap();
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(ply.as_bytes()).unwrap();
    std::fs::write(dir.join("tri.ply.gz"), gz.finish().unwrap()).unwrap();
    let scene = dir.join("scene.pbrt");
    std::fs::write(
        &scene,
        "WorldBegin\nLightSource \"point\" \"point3 from\" [0 0 3]\n\
         Translate 0 0 2\nShape \"plymesh\" \"string filename\" \"tri.ply\"\n\
         Translate 0 0 2\nShape \"plymesh\" \"string filename\" \"tri.ply.gz\"\n\
         Shape \"trianglemesh\" \"point3 P\" [0 0 0 3 0 0 0 3 0] \"integer indices\" [0 1 2]\n",
    )
    .unwrap();
    let built = crate::load_with(&scene, &[], &[], false).unwrap_or_else(|e| panic!("{e}"));
    let (lo, hi) = built.bounds();
    std::fs::remove_dir_all(&dir).ok();
    // The bounds are padded a little; the .ply at z = 2, the .ply.gz and the inline mesh
    // (its 3 x 3 triangle) at z = 4.
    let near = |a: f32, b: f32| (a - b).abs() < 1e-3;
    assert!(near(lo.z, 2.0) && near(hi.z, 4.0), "{lo} {hi}");
    assert!(near(hi.x, 3.0) && near(hi.y, 3.0), "{lo} {hi}");
}

#[test]
fn textures_map_to_foton_textures_with_pbrts_uv_conventions() {
    let t = doc(&format!(
        "{WORLD}Texture \"wood\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\" \"float uscale\" 2 \"float vscale\" 3 \"float udelta\" 0.5 \"float vdelta\" 0.25 \"string filter\" \"point\" \"string wrap\" \"clamp\"\n\
         Texture \"bright\" \"spectrum\" \"scale\" \"texture tex\" \"wood\" \"float scale\" 2\n\
         Texture \"lin\" \"spectrum\" \"imagemap\" \"string filename\" \"a.exr\"\n\
         Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" 4 \"float vscale\" 8 \"rgb tex1\" [1 0 0] \"rgb tex2\" [0 0 1]\n\
         Texture \"k\" \"spectrum\" \"constant\" \"rgb value\" [0.1 0.2 0.3]\n\
         Texture \"half\" \"float\" \"constant\" \"float value\" 0.25\n\
         Texture \"m\" \"spectrum\" \"mix\" \"texture tex1\" \"k\" \"rgb tex2\" [1 1 1] \"texture amount\" \"half\"\n\
         Material \"diffuse\" \"texture reflectance\" \"wood\"\nShape \"sphere\"\n\
         Material \"diffuse\" \"texture reflectance\" \"bright\"\nShape \"sphere\"\n\
         Material \"diffuse\" \"texture reflectance\" \"lin\"\nShape \"sphere\"\n\
         Material \"diffuse\" \"texture reflectance\" \"checks\"\nShape \"sphere\"\n\
         Material \"diffuse\" \"texture reflectance\" \"k\"\nShape \"sphere\"\n\
         Material \"diffuse\" \"texture reflectance\" \"m\"\nShape \"sphere\"\n"
    ));
    let r = |i: usize| format!("materials.material_{i}.reflectance");
    assert_eq!(text(&t, &format!("{}.type", r(1))), "bitmap");
    assert_eq!(text(&t, &format!("{}.filename", r(1))), "wood.png");
    assert_eq!(text(&t, &format!("{}.filter_type", r(1))), "nearest");
    assert_eq!(text(&t, &format!("{}.wrap_mode", r(1))), "clamp");
    assert!(!has(&t, &format!("{}.raw", r(1))), "PNG: sRGB-decoded");
    // st = (2u + 0.5, 3v + 0.25), read at (s, 1 - t).
    assert!(close(
        &nums(&t, &format!("{}.to_uv.matrix", r(1))),
        &[2.0, 0.0, 0.5, 0.0, -3.0, 0.75, 0.0, 0.0, 1.0]
    ));
    assert!(close(
        &nums(&t, &format!("{}.scale", r(2))),
        &[2.0, 2.0, 2.0]
    ));
    assert!(
        matches!(node(&t, &format!("{}.raw", r(3))).value, Value::Bool(true)),
        "EXR: linear"
    );
    assert_eq!(text(&t, &format!("{}.type", r(4))), "checkerboard");
    assert!(close(
        &nums(&t, &format!("{}.color0", r(4))),
        &[1.0, 0.0, 0.0]
    ));
    assert!(close(
        &nums(&t, &format!("{}.to_uv.matrix", r(4))),
        &[2.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 1.0]
    ));
    assert!(close(&nums(&t, &r(5)), &[0.1, 0.2, 0.3]));
    assert!(close(&nums(&t, &r(6)), &[0.325, 0.4, 0.475]));
}

#[test]
fn textures_foton_cannot_render_are_errors_or_left_out() {
    let text = format!(
        "{WORLD}Texture \"r\" \"float\" \"wrinkled\"\n\
         Texture \"n\" \"spectrum\" \"fbm\"\n\
         Material \"diffuse\" \"texture reflectance\" \"n\"\nShape \"sphere\"\n"
    );
    let e = read(&text, false).unwrap_err();
    assert!(
        e.contains("scene.pbrt:3:1") && e.contains("wrinkled texture is not read yet"),
        "{e}"
    );
    let (d, report) = read(&text, true).unwrap();
    assert_eq!(report.left_out.len(), 3, "{:?}", report.left_out);
    assert!(
        report.left_out[2].contains("no spectrum texture named \"n\""),
        "{:?}",
        report.left_out
    );
    // The material stands, with its default reflectance.
    assert!(close(
        &nums(&d.root, "materials.material_1.reflectance"),
        &[0.5, 0.5, 0.5]
    ));
    let e = read(
        &format!("{WORLD}Texture \"x\" \"spectrum\" \"plaid\"\n"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("unknown texture class \"plaid\""), "{e}");
    let e = read(
        &format!("{WORLD}Material \"diffuse\" \"texture reflectance\" \"nope\"\n"),
        false,
    )
    .unwrap_err();
    assert!(
        e.contains("scene.pbrt:3") && e.contains("no spectrum texture named \"nope\""),
        "{e}"
    );
}

/// A shape's `alpha`: a float below 1, or a float texture (an image, a checkerboard, a
/// constant), becomes the shape's `alpha`; 1 leaves it out. A material's numeric parameter
/// may name a constant float texture; one that varies is refused (`lenient`: its default).
#[test]
fn alpha_and_float_textures() {
    let t = doc(&format!(
        "{WORLD}Texture \"leaf\" \"float\" \"imagemap\" \"string filename\" \"leaf.png\"\n\
         Texture \"half\" \"float\" \"constant\" \"float value\" 0.3\n\
         Texture \"checks\" \"float\" \"checkerboard\" \"float tex1\" 1 \"float tex2\" 0\n\
         Shape \"sphere\" \"float alpha\" 0.5\n\
         Shape \"sphere\" \"float alpha\" 1\n\
         Shape \"sphere\" \"texture alpha\" \"leaf\"\n\
         Shape \"sphere\" \"texture alpha\" \"checks\"\n\
         Shape \"sphere\" \"texture alpha\" \"half\"\n\
         Material \"conductor\" \"texture roughness\" \"half\"\nShape \"sphere\"\n"
    ));
    assert_eq!(num(&t, "shapes.0.alpha"), 0.5);
    assert!(!has(&t, "shapes.1.alpha"));
    assert_eq!(text(&t, "shapes.2.alpha.type"), "bitmap");
    assert_eq!(text(&t, "shapes.2.alpha.filename"), "leaf.png");
    assert_eq!(text(&t, "shapes.3.alpha.type"), "checkerboard");
    assert!(close(&nums(&t, "shapes.3.alpha.color0"), &[1.0, 1.0, 1.0]));
    assert!((num(&t, "shapes.4.alpha") - 0.3).abs() < 1e-12);
    let m = text(&t, "shapes.5.material");
    assert_eq!(text(&t, &format!("materials.{m}.type")), "roughconductor");
    // A varying roughness of a conductor or a dielectric: foton's textured alpha, remapped.
    let t = doc(&format!(
        "{WORLD}Texture \"leaf\" \"float\" \"imagemap\" \"string filename\" \"leaf.png\"\n\
         Material \"dielectric\" \"texture roughness\" \"leaf\" \"float vroughness\" 0.2\nShape \"sphere\"\n"
    ));
    let m = text(&t, "shapes.0.material");
    assert_eq!(text(&t, &format!("materials.{m}.type")), "roughdielectric");
    assert_eq!(text(&t, &format!("materials.{m}.alpha_u.type")), "bitmap");
    assert_eq!(num(&t, &format!("materials.{m}.alpha_v")), 0.2);
    assert!(matches!(
        node(&t, &format!("materials.{m}.remaproughness")).value,
        Value::Bool(true)
    ));
    let t = doc(&format!(
        "{WORLD}Texture \"leaf\" \"float\" \"imagemap\" \"string filename\" \"leaf.png\"\n\
         Material \"coatedconductor\" \"texture conductor.roughness\" \"leaf\"\nShape \"sphere\"\n"
    ));
    let m = text(&t, "shapes.0.material");
    assert_eq!(
        text(&t, &format!("materials.{m}.conductor_roughness.type")),
        "bitmap"
    );

    // A cut-out area light: the shape emits and is cut out.
    let t = doc(&format!(
        "{WORLD}AttributeBegin\nAreaLightSource \"diffuse\"\nShape \"sphere\" \"float alpha\" 0.5\nAttributeEnd\n"
    ));
    assert!(has(&t, "shapes.0.alpha") && has(&t, "shapes.0.emission"));
    // A thickness that varies: refused, or (lenient) left out, said in the report.
    let words = "a thickness that varies over the surface";
    let text = format!(
        "{WORLD}Texture \"leaf\" \"float\" \"imagemap\" \"string filename\" \"leaf.png\"\n\
         Material \"coateddiffuse\" \"texture thickness\" \"leaf\"\nShape \"sphere\"\n"
    );
    let e = read(&text, false).unwrap_err();
    assert!(e.contains(words), "{e}");
    let (d, report) = read(&text, true).unwrap();
    assert_eq!(report.left_out.len(), 1, "{:?}", report.left_out);
    assert!(report.left_out[0].contains(words));
    assert!(!has(&d.root, "shapes.0.alpha"));
}

#[test]
fn media_and_medium_interfaces() {
    let t = doc(
        "MakeNamedMedium \"air\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 0.2 0.3] \"float scale\" 2 \"float g\" 0.5\n\
         MediumInterface \"\" \"air\"\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
         LightSource \"point\" \"rgb I\" [1 1 1]\n\
         MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"integer ny\" 1 \"integer nz\" 1 \"float density\" [1 3] \"point3 p0\" [0 0 0] \"point3 p1\" [2 1 1] \"rgb sigma_a\" [1 1 1] \"rgb sigma_s\" [3 3 3]\n\
         AttributeBegin\nMediumInterface \"smoke\" \"air\"\nMaterial \"interface\"\nShape \"sphere\"\nAttributeEnd\n\
         Shape \"sphere\"\nMediumInterface \"air\"\nShape \"sphere\"\n",
    );
    assert_eq!(text(&t, "camera.medium"), "air");
    assert_eq!(text(&t, "lights.0.medium"), "air");
    assert_eq!(text(&t, "media.air.type"), "homogeneous");
    assert!(close(&nums(&t, "media.air.sigma_a"), &[0.2, 0.4, 0.6]));
    assert!(close(&nums(&t, "media.air.sigma_s"), &[2.0, 2.0, 2.0]));
    assert_eq!(num(&t, "media.air.phase.g"), 0.5);
    assert_eq!(text(&t, "shapes.0.interior"), "smoke");
    assert_eq!(text(&t, "shapes.0.exterior"), "air");
    // The interface in effect at the camera (vacuum inside, air outside) is a transition
    // too; a single name is none.
    assert_eq!(text(&t, "shapes.1.interior"), "vacuum");
    assert!(!has(&t, "shapes.2.interior"));
    assert_eq!(text(&t, "media.smoke.type"), "heterogeneous");
    assert!(close(&nums(&t, "media.smoke.sigma_t"), &[4.0, 4.0, 4.0]));
    assert!(close(&nums(&t, "media.smoke.albedo"), &[0.75, 0.75, 0.75]));
    // A border of zeros, one cell wide: 4 x 3 x 3 samples, the two given in the middle.
    assert!(close(
        &nums(&t, "media.smoke.density.resolution"),
        &[4.0, 3.0, 3.0]
    ));
    let v = nums(&t, "media.smoke.density.values");
    assert_eq!(v.len(), 36);
    assert_eq!((v[12 + 4 + 1], v[12 + 4 + 2]), (1.0, 3.0));
    assert_eq!(v.iter().sum::<f64>(), 4.0);
    // The unit cube onto [-1, 3] x [-1, 2] x [-1, 2]: the box grown by one cell per side.
    assert!(close(
        &nums(&t, "media.smoke.density.transform.matrix"),
        &[
            4.0, 0.0, 0.0, -1.0, 0.0, 3.0, 0.0, -1.0, 0.0, 0.0, 3.0, -1.0, 0.0, 0.0, 0.0, 1.0
        ]
    ));
    let e = read(
        &format!("{WORLD}MediumInterface \"fog\" \"\"\nShape \"sphere\"\n"),
        false,
    )
    .unwrap_err();
    assert!(
        e.contains("scene.pbrt:3:1") && e.contains("no medium named \"fog\""),
        "{e}"
    );
    let cloud = format!(
        "{WORLD}MakeNamedMedium \"c\" \"string type\" \"cloud\"\nMediumInterface \"c\" \"\"\nShape \"sphere\"\n"
    );
    assert!(
        read(&cloud, false)
            .unwrap_err()
            .contains("the cloud medium")
    );
    let (d, report) = read(&cloud, true).unwrap();
    assert_eq!(report.left_out.len(), 1, "{:?}", report.left_out);
    assert_eq!(text(&d.root, "shapes.0.interior"), "vacuum");
}

#[test]
fn pixel_filters_with_their_radii_and_parameters() {
    let filter = |line: &str| doc(&format!("{line}\nCamera \"perspective\"\n{WORLD}"));
    // The default: pbrt-v4's gaussian, sigma 0.5, radius 1.5.
    let t = doc(&format!("Camera \"perspective\"\n{WORLD}"));
    assert_eq!(text(&t, "film.filter.type"), "gaussian");
    assert_eq!(num(&t, "film.filter.stddev"), 0.5);
    assert_eq!(num(&t, "film.filter.radius"), 1.5);
    let t = filter(
        "PixelFilter \"gaussian\" \"float sigma\" 0.7 \"float xradius\" 2 \"float yradius\" 1",
    );
    assert_eq!(num(&t, "film.filter.stddev"), 0.7);
    assert!(close(&nums(&t, "film.filter.radius"), &[2.0, 1.0]));
    let t = filter("PixelFilter \"triangle\" \"float yradius\" 1");
    assert_eq!(text(&t, "film.filter.type"), "tent");
    assert!(close(&nums(&t, "film.filter.radius"), &[2.0, 1.0]));
    let t = filter("PixelFilter \"mitchell\"");
    assert_eq!(text(&t, "film.filter.type"), "mitchell");
    assert!((num(&t, "film.filter.b") - 1.0 / 3.0).abs() < 1e-12);
    assert!((num(&t, "film.filter.c") - 1.0 / 3.0).abs() < 1e-12);
    assert_eq!(num(&t, "film.filter.radius"), 2.0);
    let t = filter("PixelFilter \"mitchell\" \"float B\" 0 \"float C\" 0.5 \"float xradius\" 3");
    assert_eq!(num(&t, "film.filter.b"), 0.0);
    assert_eq!(num(&t, "film.filter.c"), 0.5);
    assert!(close(&nums(&t, "film.filter.radius"), &[3.0, 2.0]));
    let t = filter("PixelFilter \"sinc\"");
    assert_eq!(text(&t, "film.filter.type"), "sinc");
    assert_eq!(num(&t, "film.filter.tau"), 3.0);
    assert_eq!(num(&t, "film.filter.radius"), 4.0);
    let t = filter("PixelFilter \"sinc\" \"float tau\" 2 \"float xradius\" 2 \"float yradius\" 2");
    assert_eq!(num(&t, "film.filter.tau"), 2.0);
    assert_eq!(num(&t, "film.filter.radius"), 2.0);
    let t = filter("PixelFilter \"box\"");
    assert_eq!(text(&t, "film.filter"), "box");
    let e = read(
        &format!("PixelFilter \"box\" \"float xradius\" 1\nCamera \"perspective\"\n{WORLD}"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("another radius"), "{e}");
    let e = read(
        &format!("PixelFilter \"mitchell\" \"float bogus\" 1\nCamera \"perspective\"\n{WORLD}"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("bogus"), "{e}");
}

#[test]
fn thin_dielectric_diffuse_transmission_and_mix() {
    let t = doc(&format!(
        "{WORLD}Material \"thindielectric\" \"float eta\" 1.33\nShape \"sphere\"\n\
         Material \"diffusetransmission\" \"rgb reflectance\" [0.2 0.4 0.1] \"rgb transmittance\" [0.3 0.1 0.5]\nShape \"sphere\"\n\
         MakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n\
         MakeNamedMaterial \"b\" \"string type\" \"dielectric\"\n\
         MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"a\" \"b\"] \"float amount\" 0.3\n\
         NamedMaterial \"m\"\nShape \"sphere\"\n"
    ));
    assert_eq!(text(&t, "materials.material_1.type"), "thindielectric");
    assert_eq!(num(&t, "materials.material_1.ior"), 1.33);
    // R / pi + T / pi as a blend of R / 0.4 and T / 0.5 taken with probabilities 0.4 and 0.5.
    assert_eq!(text(&t, "materials.material_2.type"), "blend");
    assert!(close(
        &nums(&t, "materials.material_2.weights"),
        &[0.4, 0.5]
    ));
    assert_eq!(text(&t, "materials.material_2.materials.0.type"), "diffuse");
    assert!(close(
        &nums(&t, "materials.material_2.materials.0.reflectance"),
        &[0.5, 1.0, 0.25]
    ));
    assert_eq!(
        text(&t, "materials.material_2.materials.1.type"),
        "difftrans"
    );
    assert!(close(
        &nums(&t, "materials.material_2.materials.1.transmittance"),
        &[0.6, 0.2, 1.0]
    ));
    assert_eq!(text(&t, "materials.m.type"), "blend");
    assert_eq!(text(&t, "materials.m.materials.0.type"), "diffuse");
    assert_eq!(text(&t, "materials.m.materials.1.type"), "dielectric");
    assert_eq!(num(&t, "materials.m.weight"), 0.3);
    let e = read(
        &format!("{WORLD}Material \"mix\" \"string materials\" [\"x\" \"y\"]\n"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("no named material \"x\""), "{e}");
}

#[test]
fn coated_materials_keep_pbrts_names() {
    let t = doc(&format!(
        "{WORLD}Material \"coateddiffuse\" \"rgb reflectance\" [0.7 0.3 0.1] \"float roughness\" 0.1 \"float thickness\" 0.05 \"rgb albedo\" [0.5 0.5 0.5] \"integer maxdepth\" 20\nShape \"sphere\"\n\
         Material \"coatedconductor\" \"spectrum conductor.eta\" \"metal-Au-eta\" \"spectrum conductor.k\" \"metal-Au-k\" \"float interface.roughness\" 0.05 \"float conductor.roughness\" 0.2 \"float interface.eta\" 1.4\nShape \"sphere\"\n\
         Material \"coatedconductor\" \"rgb conductor.eta\" [0.2 0.3 0.4] \"rgb conductor.k\" [3 3 3] \"bool remaproughness\" false\nShape \"sphere\"\n"
    ));
    assert_eq!(text(&t, "materials.material_1.type"), "coateddiffuse");
    assert!(close(
        &nums(&t, "materials.material_1.reflectance"),
        &[0.7, 0.3, 0.1]
    ));
    assert_eq!(num(&t, "materials.material_1.roughness"), 0.1);
    assert_eq!(num(&t, "materials.material_1.thickness"), 0.05);
    assert_eq!(num(&t, "materials.material_1.maxdepth"), 20.0);
    assert!(close(
        &nums(&t, "materials.material_1.albedo"),
        &[0.5, 0.5, 0.5]
    ));
    // Relative to the coat's index 1.4, then given back in the outside's units.
    let (eta, _) = super::spectra::metal_rgb_ior("Au", 1.4).unwrap();
    assert!(close(
        &nums(&t, "materials.material_2.conductor_eta"),
        &eta.to_array()
    ));
    assert_eq!(num(&t, "materials.material_2.interface_roughness"), 0.05);
    assert_eq!(num(&t, "materials.material_2.conductor_roughness"), 0.2);
    assert_eq!(num(&t, "materials.material_2.interface_eta"), 1.4);
    assert!(close(
        &nums(&t, "materials.material_3.conductor_eta"),
        &[0.2, 0.3, 0.4]
    ));
    assert!(matches!(
        node(&t, "materials.material_3.remaproughness").value,
        Value::Bool(false)
    ));
}

#[test]
fn crop_windows_and_screen_windows_are_a_narrower_shifted_camera() {
    let t = doc(&format!(
        "Camera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 48 \"float cropwindow\" [0.75 0.25 0.1 0.6]\n{WORLD}"
    ));
    // Pixels ceil(64 x 0.25) = 16 to 48 and ceil(48 x 0.1) = 5 to ceil(48 x 0.6) = 29.
    assert_eq!(num(&t, "film.width"), 32.0);
    assert_eq!(num(&t, "film.height"), 24.0);
    let tan = 15f64.to_radians().tan();
    // Screen y from 1 - 2 x 5/48 down to 1 - 2 x 29/48: half of 1, centred at 7/24.
    assert!((num(&t, "camera.fov") - 2.0 * (0.5 * tan).atan().to_degrees()).abs() < 1e-9);
    assert_eq!(text(&t, "camera.fov_axis"), "y");
    assert!(close(&nums(&t, "camera.shift"), &[0.0, 7.0 / 24.0 * tan]));
    let t = doc(&format!(
        "Camera \"perspective\" \"float fov\" 30 \"float screenwindow\" [-0.5 1.5 -0.5 1]\nFilm \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 48\n{WORLD}"
    ));
    assert!((num(&t, "camera.fov") - 2.0 * (0.75 * tan).atan().to_degrees()).abs() < 1e-9);
    assert!(close(&nums(&t, "camera.shift"), &[0.5 * tan, 0.25 * tan]));
    let e = read(&format!("Camera \"perspective\" \"float screenwindow\" [-1 1 -1 1]\nFilm \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 48\n{WORLD}"), false).unwrap_err();
    assert!(e.contains("not square"), "{e}");
}

#[test]
fn attribute_gives_defaults_within_its_attribute_block() {
    let t = doc(&format!(
        "{WORLD}AttributeBegin\nAttribute \"shape\" \"float radius\" 0.25 \"float bogus\" 1\nAttribute \"shape\" \"float radius\" 0.5\n\
         Attribute \"material\" \"rgb reflectance\" [0.1 0.2 0.3]\nMaterial \"diffuse\"\nShape \"sphere\"\nShape \"sphere\" \"float radius\" 2\nAttributeEnd\nShape \"sphere\"\n"
    ));
    // The latest Attribute wins, the shape's own parameter over both, none after the block;
    // an attribute nobody reads is no error.
    assert_eq!(num(&t, "shapes.0.radius"), 0.5);
    assert_eq!(num(&t, "shapes.1.radius"), 2.0);
    assert_eq!(num(&t, "shapes.2.radius"), 1.0);
    assert!(close(
        &nums(&t, "materials.material_1.reflectance"),
        &[0.1, 0.2, 0.3]
    ));
    let e = read(
        &format!("{WORLD}Attribute \"camera\" \"float fov\" 3\n"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("unknown target \"camera\""), "{e}");
}

#[test]
fn bilinear_patches_and_cylinders_become_meshes() {
    let t = doc(&format!(
        "{WORLD}Shape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\n\
         Shape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 1]\n\
         Shape \"cylinder\" \"float radius\" 2 \"float phimax\" 180\n"
    ));
    // Planar: two triangles wound as dp/du x dp/dv = +z; uv the patch's.
    let idx = nums(&t, "shapes.0.indices");
    assert_eq!(idx.len(), 6);
    let p = nums(&t, "shapes.0.positions");
    let v = |i: f64| {
        glam::DVec3::new(
            p[3 * i as usize],
            p[3 * i as usize + 1],
            p[3 * i as usize + 2],
        )
    };
    assert!((v(idx[1]) - v(idx[0])).cross(v(idx[2]) - v(idx[0])).z > 0.0);
    assert_eq!(nums(&t, "shapes.0.uvs").len(), 8);
    // Curved: 8 x 8 quads, vertices on the patch.
    assert_eq!(nums(&t, "shapes.1.indices").len(), 8 * 8 * 6);
    // Half a cylinder: 32 facets, vertices at radius 2 with outward normals.
    assert_eq!(nums(&t, "shapes.2.indices").len(), 32 * 6);
    let (p, n) = (nums(&t, "shapes.2.positions"), nums(&t, "shapes.2.normals"));
    for (q, m) in p.chunks(3).zip(n.chunks(3)) {
        assert!(((q[0] * q[0] + q[1] * q[1]).sqrt() - 2.0).abs() < 1e-9 && q[1] >= -1e-9);
        assert!((q[0] * m[0] + q[1] * m[1]) > 0.0);
    }
}

/// A scene using most of what the reader maps, for the mutation test.
const RICH: &str = r#"Scale -1 1 1
LookAt 0 1 4  0 0.5 0  0 1 0
Camera "perspective" "float fov" 40 "float screenwindow" [-1 1 -0.75 0.75]
Film "rgb" "integer xresolution" 16 "integer yresolution" 12 "float cropwindow" [0.1 0.9 0 1] "string filename" "x.exr"
PixelFilter "mitchell" "float xradius" 2
Sampler "stratified" "integer xsamples" 2 "integer ysamples" 2
Integrator "volpath" "integer maxdepth" 5
MakeNamedMedium "air" "string type" "homogeneous" "rgb sigma_a" [0.01 0.01 0.01] "rgb sigma_s" [0.1 0.1 0.1] "float g" 0.3
MediumInterface "" "air"
WorldBegin
Attribute "shape" "float radius" 0.5
Texture "img" "spectrum" "imagemap" "string filename" "t.png" "float uscale" 2 "string filter" "point"
Texture "chk" "spectrum" "checkerboard" "rgb tex1" [1 0 0] "rgb tex2" [0 0 1] "float uscale" 4
Texture "k" "float" "constant" "float value" 0.3
Texture "s" "spectrum" "scale" "texture tex" "img" "float scale" 0.5
LightSource "point" "rgb I" [1 1 1] "point3 from" [0 2 0]
LightSource "spot" "rgb I" [2 2 2] "point3 from" [1 2 1] "point3 to" [0 0 0] "float coneangle" 40
LightSource "distant" "point3 from" [0 1 1] "point3 to" [0 0 0] "rgb L" [1 1 1]
LightSource "infinite" "string filename" "t.png" "float scale" 0.5
MakeNamedMaterial "a" "string type" "diffuse" "texture reflectance" "chk"
MakeNamedMaterial "b" "string type" "conductor" "spectrum eta" "metal-Au-eta" "spectrum k" "metal-Au-k" "float roughness" 0.1
MakeNamedMaterial "m" "string type" "mix" "string materials" ["a" "b"] "texture amount" "k"
MakeNamedMedium "smoke" "string type" "uniformgrid" "integer nx" 2 "integer ny" 2 "integer nz" 1 "float density" [1 2 3 4] "point3 p0" [-1 0 -1] "point3 p1" [1 1 1]
AttributeBegin
  NamedMaterial "m"
  Shape "sphere"
  Translate 1 0 0
  Material "coateddiffuse" "texture reflectance" "s" "float roughness" 0.05
  Shape "disk" "float radius" 0.3
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [3 3 3] "float power" 10
  Shape "bilinearmesh" "point3 P" [-0.5 2 -0.5  0.5 2 -0.5  -0.5 2 0.5  0.5 2 0.5] "integer indices" [0 2 1 3]
AttributeEnd
AttributeBegin
  MediumInterface "smoke" "air"
  Material "interface"
  Shape "trianglemesh" "point3 P" [-1 0 -1  1 0 -1  1 1 -1  -1 1 -1] "integer indices" [0 1 2  0 2 3] "point2 uv" [0 0 1 0 1 1 0 1]
AttributeEnd
ObjectBegin "o"
  Material "diffusetransmission"
  Shape "cylinder" "float radius" 0.2 "float zmin" 0 "float zmax" 0.5
ObjectEnd
ObjectInstance "o"
Material "thindielectric" "float eta" 1.4
Shape "trianglemesh" "point3 P" [0 0 0  1 0 0  0 1 0]
"#;

/// The mutation test (`crate::mutations`) on that scene. `FOTON_FUZZ_PBRT=N` runs N cases
/// instead of 1,500.
#[test]
fn mutated_pbrt_scenes_are_errors_or_scenes_never_panics() {
    let n = crate::mutations::count("FOTON_FUZZ_PBRT", 1_500);
    let dir = std::env::temp_dir().join(format!("foton-pbrt-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A 2 x 2 PNG for the image texture and the environment map.
    let mut img = image::RgbImage::new(2, 2);
    img.put_pixel(1, 0, image::Rgb([200, 100, 50]));
    img.save(dir.join("t.png")).unwrap();
    crate::mutations::check(
        &dir.join("scene.pbrt"),
        RICH,
        b" []\"#\n01-.ex",
        n,
        0x9e37_79b9_7f4a_7c15,
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Geometry beyond what f32 holds (found by the mutation test: obvhs' build overflowed on a
/// cylinder 1e30 long) is an error naming the shape, for every format.
#[test]
fn geometry_beyond_1e15_is_an_error_not_a_panic() {
    let dir = std::env::temp_dir().join(format!("foton-pbrt-huge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pbrt = dir.join("huge.pbrt");
    std::fs::write(
        &pbrt,
        format!("{WORLD}Shape \"cylinder\" \"float zmax\" 1e30\n"),
    )
    .unwrap();
    let e = crate::load::load_with(&pbrt, &[], &[], false)
        .err()
        .expect("an error")
        .to_string();
    assert!(e.contains("within 1e15") && e.contains("shapes[0]"), "{e}");
    let toml = dir.join("huge.toml");
    std::fs::write(
        &toml,
        "[camera]\nposition = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\n[materials.m]\ntype = \"diffuse\"\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1e30\nmaterial = \"m\"\n",
    )
    .unwrap();
    let e = crate::load::load_with(&toml, &[], &[], false)
        .err()
        .expect("an error")
        .to_string();
    assert!(e.contains("huge.toml:") && e.contains("within 1e15"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn loop_subdivision_refines_at_load() {
    let t = doc(&format!(
        "{WORLD}Shape \"loopsubdiv\" \"integer levels\" 2 \"point3 P\" [0 0 0  1 0 0  1 1 0  0 1 0] \"integer indices\" [0 1 2  0 2 3]\n\
         Shape \"loopsubdiv\" \"point3 P\" [1 1 1  -1 -1 1  -1 1 -1  1 -1 -1] \"integer indices\" [0 1 2  0 3 1  0 2 3  1 3 2]\n"
    ));
    // A flat quad stays flat: 2 x 4^2 triangles, normals +z as wound.
    assert_eq!(nums(&t, "shapes.0.indices").len(), 32 * 3);
    assert!(
        nums(&t, "shapes.0.positions")
            .chunks(3)
            .all(|v| v[2].abs() < 1e-12)
    );
    assert!(
        nums(&t, "shapes.0.normals")
            .chunks(3)
            .all(|n| (n[2] - 1.0).abs() < 1e-9)
    );
    // A tetrahedron, 3 levels by default: 4 x 64 triangles, its limit surface strictly inside
    // the tetrahedron's circumsphere and around its centre.
    assert_eq!(nums(&t, "shapes.1.indices").len(), 256 * 3);
    for v in nums(&t, "shapes.1.positions").chunks(3) {
        let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!(r > 0.2 && r < 3f64.sqrt(), "{v:?}");
    }
    let e = read(
        &format!(
            "{WORLD}Shape \"loopsubdiv\" \"integer levels\" 12 \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
        ),
        false,
    )
    .unwrap_err();
    assert!(e.contains("\"levels\" 12"), "{e}");
}

#[test]
fn spectral_indices_are_read_at_550_nm() {
    let (d, report) = read(
        &format!(
            "{WORLD}Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\nShape \"sphere\"\n\
             Material \"thindielectric\" \"spectrum eta\" [400 1.6 700 1.3]\nShape \"sphere\"\n\
             Material \"coateddiffuse\" \"spectrum eta\" \"glass-F11\"\nShape \"sphere\"\n"
        ),
        false,
    )
    .unwrap();
    let t = d.root;
    assert_eq!(num(&t, "materials.material_1.ior"), 1.51854);
    // Linear between 400 and 700 nm: 1.6 - 0.3 x 150 / 300.
    assert!((num(&t, "materials.material_2.ior") - 1.45).abs() < 1e-9);
    assert_eq!(num(&t, "materials.material_3.eta"), 1.79112);
    assert_eq!(
        report
            .warnings
            .iter()
            .filter(|w| w.contains("dispersion ignored"))
            .count(),
        3,
        "{:?}",
        report.warnings
    );
    let e = read(
        &format!("{WORLD}Material \"dielectric\" \"spectrum eta\" \"glass-XYZ\"\n"),
        false,
    )
    .unwrap_err();
    assert!(e.contains("glass-XYZ") && e.contains("glass-BK7"), "{e}");
}

#[test]
fn media_are_dropped_for_integrators_that_ignore_them_and_material_none_is_interface() {
    let scene = |integrator: &str| {
        format!(
            "Integrator \"{integrator}\"\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nMediumInterface \"\" \"fog\"\nCamera \"perspective\"\n{WORLD}\
             MediumInterface \"fog\" \"\"\nMaterial \"none\"\nShape \"sphere\"\n"
        )
    };
    let (d, report) = read(&scene("path"), false).unwrap();
    assert!(!has(&d.root, "camera.medium") && d.root.get("media").is_none());
    assert!(!has(&d.root, "shapes.0.interior"));
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("ignores participating media")),
        "{:?}",
        report.warnings
    );
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("\"none\" is pbrt-v3's name")),
        "{:?}",
        report.warnings
    );
    assert_eq!(text(&d.root, "materials.material_1.type"), "null");
    let t = doc(&scene("volpath"));
    assert_eq!(text(&t, "camera.medium"), "fog");
    assert_eq!(text(&t, "shapes.0.interior"), "fog");
}

#[test]
fn iso_and_shutter_scale_every_light() {
    let t = doc(
        "Camera \"perspective\" \"float shutteropen\" 0 \"float shutterclose\" 0.5\nFilm \"rgb\" \"float iso\" 400\nWorldBegin\n\
         LightSource \"point\" \"rgb I\" [1 2 3]\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [4 4 4]\nShape \"sphere\"\nAttributeEnd\n",
    );
    // 0.5 s x ISO 400 / 100 = 2.
    assert!(close(&nums(&t, "lights.0.intensity"), &[2.0, 4.0, 6.0]));
    assert!(close(&nums(&t, "lights.1.radiance"), &[1.0, 1.0, 1.0]));
    assert!(close(&nums(&t, "shapes.0.emission"), &[8.0, 8.0, 8.0]));
}

#[test]
fn measured_media_presets() {
    let (d, report) = read(
        &format!(
            "{WORLD}MakeNamedMedium \"milk\" \"string type\" \"homogeneous\" \"string preset\" \"Wholemilk\" \"float scale\" 10\n\
             MakeNamedMedium \"x\" \"string type\" \"homogeneous\" \"string preset\" \"Unobtainium\" \"rgb sigma_a\" [1 2 3]\n"
        ),
        false,
    )
    .unwrap();
    // Jensen et al. 2001: whole milk, sigma_s' = (2.55, 3.21, 3.77), sigma_a = (0.0011,
    // 0.0024, 0.014) per mm; times scale.
    assert!(close(
        &nums(&d.root, "media.milk.sigma_s"),
        &[25.5, 32.1, 37.7]
    ));
    assert!(close(
        &nums(&d.root, "media.milk.sigma_a"),
        &[0.011, 0.024, 0.14]
    ));
    // An unknown preset: a warning, the coefficients as given (pbrt-v4 does the same).
    assert!(close(&nums(&d.root, "media.x.sigma_a"), &[1.0, 2.0, 3.0]));
    assert!(
        report.warnings.iter().any(|w| w.contains("Unobtainium")),
        "{:?}",
        report.warnings
    );
}

#[test]
fn rgb_grid_media_are_an_rgb_extinction_and_albedo() {
    let t = doc(&format!(
        "{WORLD}MakeNamedMedium \"m\" \"string type\" \"rgbgrid\" \"integer nx\" 2 \"rgb sigma_a\" [1 0 0  0 0 0] \"rgb sigma_s\" [1 2 3  0 4 0] \"float scale\" 2\n"
    ));
    assert!(close(&nums(&t, "media.m.sigma_t"), &[2.0, 2.0, 2.0]));
    // Extinction sigma_a + sigma_s per sample (3 channels) with a border of zeros.
    assert!(close(
        &nums(&t, "media.m.density.resolution"),
        &[4.0, 3.0, 3.0]
    ));
    let v = nums(&t, "media.m.density.values");
    assert_eq!(v.len(), 36 * 3);
    assert_eq!(
        &v[(12 + 4 + 1) * 3..(12 + 4 + 3) * 3],
        &[2.0, 2.0, 3.0, 0.0, 4.0, 0.0]
    );
    // The albedo per sample, unpadded, clamped beyond (0 where nothing is there).
    assert_eq!(
        nums(&t, "media.m.albedo.values"),
        vec![0.5, 1.0, 1.0, 0.0, 1.0, 0.0]
    );
    assert_eq!(text(&t, "media.m.albedo.outside"), "clamp");
}

#[test]
fn emitting_media_read_le_times_its_scale() {
    let t = doc(&format!(
        "{WORLD}MakeNamedMedium \"h\" \"string type\" \"homogeneous\" \"rgb Le\" [1 2 3] \"float Lescale\" 2\n\
         MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [1 1] \"rgb Le\" [1 0.5 0] \"float Lescale\" [2 4]\n\
         MakeNamedMedium \"c\" \"string type\" \"uniformgrid\" \"float density\" [1] \"rgb Le\" [3 3 3]\n\
         MakeNamedMedium \"r\" \"string type\" \"rgbgrid\" \"integer nx\" 2 \"rgb sigma_a\" [1 1 1  1 1 1] \"rgb Le\" [1 0 0  0 1 0] \"float Lescale\" 3\n\
         MakeNamedMedium \"n\" \"string type\" \"uniformgrid\" \"float density\" [1] \"float Lescale\" [5]\n"
    ));
    assert!(close(&nums(&t, "media.h.emission"), &[2.0, 4.0, 6.0]));
    // Le x Lescale per sample (3 channels), bordered by zeros as the density.
    assert!(close(
        &nums(&t, "media.g.emission.resolution"),
        &[4.0, 3.0, 3.0]
    ));
    let v = nums(&t, "media.g.emission.values");
    assert_eq!(
        &v[(12 + 4 + 1) * 3..(12 + 4 + 3) * 3],
        &[2.0, 1.0, 0.0, 4.0, 2.0, 0.0]
    );
    assert_eq!(text(&t, "media.g.emission.outside"), "zero");
    // Without Lescale, Le on one sample at the box's centre (pbrt-v4's 1 x 1 x 1 grid).
    assert!(close(
        &nums(&t, "media.c.emission.resolution"),
        &[3.0, 3.0, 3.0]
    ));
    assert_eq!(
        nums(&t, "media.c.emission.values")[13 * 3..14 * 3],
        [3.0, 3.0, 3.0]
    );
    let v = nums(&t, "media.r.emission.values");
    assert_eq!(
        &v[(12 + 4 + 1) * 3..(12 + 4 + 3) * 3],
        &[3.0, 0.0, 0.0, 0.0, 3.0, 0.0]
    );
    // A scale without Le emits nothing.
    assert!(!has(&t, "media.n.emission"));
    // A grid of scales must have one per sample; an RGB grid's Le needs sigma_a; a
    // temperature grid is not read.
    for (params, words) in [
        (
            "\"uniformgrid\" \"integer nx\" 2 \"float density\" [1 1] \"rgb Le\" [1 1 1] \"float Lescale\" [2]",
            "\"Lescale\" has 1 values",
        ),
        (
            "\"rgbgrid\" \"rgb sigma_s\" [1 1 1] \"rgb Le\" [1 1 1]",
            "needs \"sigma_a\"",
        ),
        (
            "\"uniformgrid\" \"float density\" [1] \"float temperature\" [1500]",
            "emitting by temperature are not read yet",
        ),
    ] {
        let e = read(
            &format!("{WORLD}MakeNamedMedium \"m\" \"string type\" {params}\n"),
            false,
        )
        .unwrap_err();
        assert!(e.contains(words), "{params}: {e}");
    }
}
