//! Media as Mitsuba files write them: a shape's `interior` (behind its normal) and `exterior`
//! (in front of it) on open and closed shapes, the camera's and lights' `medium`, and the
//! leak check. Physics against closed forms (transmittance through a slab of fog between two
//! open quads), against the inferred formulation of the same scene (an open-walled fog box
//! against a closed fog volume, the camera's medium against the scene medium), and the
//! volumetric caustic of Bitterli's Mitsuba 3 scene.

use foton_core::Rgb;
use foton_core::scene::Scene;
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, region_mean, render_file, render_toml, repo_root, temp_dir, write};
use glam::Vec3;

const FOG: &str = r#"
[media.fog]
type = "homogeneous"
sigma_a = [0.4, 0.8, 1.6]
"#;

/// A camera at z = 5 looking at an emitter (radiance 1, 2, 3) at z = -1 through a slab of
/// fog from z = -0.5 to 0.5 bounded by two open null quads that name both their sides.
fn slab_scene(spp: u32) -> String {
    format!(
        r#"{}
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov = 0.5
{FOG}
[materials.boundary]
type = "null"

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[[shapes]]
type = "quad"
origin = [-10.0, -10.0, -1.0]
u = [20.0, 0.0, 0.0]
v = [0.0, 20.0, 0.0]
material = "black"
emission = [1.0, 2.0, 3.0]

# Normal +z: the fog is behind it (below z = 0.5), vacuum in front.
[[shapes]]
type = "quad"
origin = [-5.0, -5.0, 0.5]
u = [10.0, 0.0, 0.0]
v = [0.0, 10.0, 0.0]
material = "boundary"
interior = "fog"
exterior = "vacuum"

# Normal +z: vacuum behind it, the fog in front (above z = -0.5).
[[shapes]]
type = "quad"
origin = [-5.0, -5.0, -0.5]
u = [10.0, 0.0, 0.0]
v = [0.0, 10.0, 0.0]
material = "boundary"
exterior = "fog"
interior = "vacuum"
"#,
        header("path", spp, 0, 4, 4)
    )
}

fn load_toml(name: &str, toml: &str) -> Scene {
    let dir = temp_dir(name);
    let path = write(&dir, "scene.toml", toml);
    let scene = foton_loader::load(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(dir);
    scene
}

#[test]
fn fog_between_two_open_quads_transmits_exp_minus_sigma_t_d() {
    let scene = load_toml("sides-slab-load", &slab_scene(4));
    assert!(scene.has_media());
    assert_eq!(scene.camera_medium(), None, "the camera stands in vacuum");
    let sigma = Vec3::new(0.4, 0.8, 1.6);
    let want = |d: f32| {
        Rgb::new(
            (-sigma.x * d).exp(),
            (-sigma.y * d).exp(),
            (-sigma.z * d).exp(),
        )
    };
    // Shadow rays: from the camera's side through the slab, and from inside it out.
    let tr = scene.transmittance(
        Vec3::new(0.1, 0.0, 3.0),
        Vec3::ZERO,
        Vec3::new(0.1, 0.0, -0.9),
        Vec3::ZERO,
        None,
    );
    let fog = Some(0);
    let inside = scene.transmittance(
        Vec3::new(0.0, 0.2, 0.0),
        Vec3::ZERO,
        Vec3::new(0.0, 0.2, 2.0),
        Vec3::ZERO,
        fog,
    );
    for c in 0..3 {
        assert!(
            (tr[c] - want(1.0)[c]).abs() < 1e-4 * want(1.0)[c] + 1e-7,
            "through: {tr}"
        );
        assert!(
            (inside[c] - want(0.5)[c]).abs() < 1e-4 * want(0.5)[c] + 1e-7,
            "out: {inside}"
        );
    }
    // Rendered: a sample passes with probability p (spectral MIS) and carries Le Tr / p.
    let spp = 256;
    let film = render_toml("sides-slab", &slab_scene(spp), &[], 2);
    let le = Rgb::new(1.0, 2.0, 3.0);
    let expect = le * want(1.0);
    let p = foton_core::medium::free_flight_pass_probability(sigma, 1.0);
    let n = 16.0 * spp as f32;
    let err = expect / p * (p * (1.0 - p) / n).sqrt();
    let mean = film.mean();
    for c in 0..3 {
        assert!(
            (mean[c] - expect[c]).abs() < 4.0 * err[c] + 1e-6,
            "channel {c}: {mean} +- {err}, expected {expect}"
        );
    }
}

/// A diffuse room [-1, 1] x [0, 2] x [-1, 1] open towards the camera (at z = 6), a light
/// quad under its ceiling, filled with scattering fog: `sides` true, the walls and the light
/// stand in the fog (interior = exterior = fog) and a null quad with the fog behind it closes
/// the opening, as Bitterli's volumetric-caustic file; false, the walls name no medium and a
/// closed null box inset by 1 mm holds the fog (foton's inferred volume).
fn room(integrator: &str, spp: u32, sides: bool) -> String {
    let both = if sides {
        "interior = \"fog\"\nexterior = \"fog\"\n"
    } else {
        ""
    };
    let quad = |o: [f32; 3], u: [f32; 3], v: [f32; 3], extra: &str| {
        format!("[[shapes]]\ntype = \"quad\"\norigin = {o:?}\nu = {u:?}\nv = {v:?}\n{extra}")
    };
    let mut s = format!(
        r#"{}
[camera]
position = [0.0, 1.0, 6.0]
look_at = [0.0, 1.0, 0.0]
fov = 22.0

[media.fog]
type = "homogeneous"
sigma_s = [0.6, 0.6, 0.6]
sigma_a = [0.1, 0.1, 0.1]

[materials.wall]
type = "diffuse"
reflectance = [0.7, 0.6, 0.5]

[materials.black]
type = "diffuse"
reflectance = [0.0, 0.0, 0.0]

[materials.boundary]
type = "null"

[integrators.vpm]
global_photons = 20000
volume_photons = 20000
caustic_photons = 0
"#,
        header(integrator, spp, 6, 8, 8)
    );
    let wall = format!("material = \"wall\"\n{both}");
    // Floor, ceiling, back, left, right, normals inward.
    s += &quad([-1.0, 0.0, -1.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0], &wall);
    s += &quad([-1.0, 2.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0], &wall);
    s += &quad([-1.0, 0.0, -1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], &wall);
    s += &quad([-1.0, 0.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0], &wall);
    s += &quad([1.0, 0.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0], &wall);
    let light = format!("material = \"black\"\nemission = [8.0, 8.0, 8.0]\n{both}");
    s += &quad([-0.3, 1.95, -0.3], [0.6, 0.0, 0.0], [0.0, 0.0, 0.6], &light);
    if sides {
        // The opening, its normal towards the camera: fog behind, vacuum in front.
        let front = "material = \"boundary\"\ninterior = \"fog\"\nexterior = \"vacuum\"\n";
        s += &quad([-1.0, 0.0, 1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], front);
    } else {
        s += "[[shapes]]\ntype = \"mesh\"\nfile = \"fog.obj\"\nmaterial = \"boundary\"\ninterior = \"fog\"\n";
    }
    s
}

/// The fog box [-0.999, 0.999] x [0.001, 1.999] x [-0.999, 1] as OBJ, normals outward.
const FOG_BOX: &str = "v -0.999 0.001 -0.999\nv 0.999 0.001 -0.999\nv -0.999 1.999 -0.999\nv 0.999 1.999 -0.999\n\
v -0.999 0.001 1\nv 0.999 0.001 1\nv -0.999 1.999 1\nv 0.999 1.999 1\n\
f 1 3 4 2\nf 5 6 8 7\nf 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\n";

fn render_room(name: &str, integrator: &str, spp: u32, sides: bool) -> foton_core::film::Film {
    let dir = temp_dir(name);
    write(&dir, "fog.obj", FOG_BOX);
    let path = write(&dir, "scene.toml", &room(integrator, spp, sides));
    let film = render_file(&path, &[], 2);
    let _ = std::fs::remove_dir_all(dir);
    film
}

#[test]
fn open_walled_fog_box_renders_as_the_closed_volume() {
    let tolerance = Tolerance {
        rel: 0.03,
        z: 4.0,
        floor: 1e-3,
    };
    let open = render_room("sides-room-open", "path", 256, true);
    let closed = render_room("sides-room-closed", "path", 256, false);
    assert!(open.mean().min_element() > 0.0);
    assert_blocks_agree(
        "path: open walls in fog against a fog volume",
        &open,
        &closed,
        2,
        tolerance,
    );
    // vpm: the same estimator (and bias) on both formulations.
    let open = render_room("sides-room-open-vpm", "vpm", 16, true);
    let closed = render_room("sides-room-closed-vpm", "vpm", 16, false);
    let tolerance = Tolerance {
        rel: 0.06,
        ..tolerance
    };
    assert_blocks_agree(
        "vpm: open walls in fog against a fog volume",
        &open,
        &closed,
        2,
        tolerance,
    );
}

/// The room in fog everywhere: the scene medium, or the camera's `medium` with every shape
/// in the fog on both sides. The same walk, so the same image, bit for bit.
#[test]
fn camera_in_fog_by_its_medium_renders_as_by_the_scene_medium() {
    let base = room("path", 16, false).replace(
        "[[shapes]]\ntype = \"mesh\"\nfile = \"fog.obj\"\nmaterial = \"boundary\"\ninterior = \"fog\"\n",
        "",
    );
    let by_scene = format!("{base}\n[scene]\nmedium = \"fog\"\n");
    let sides = room("path", 16, true);
    let front = sides.rfind("[[shapes]]").unwrap();
    let by_camera = sides[..front].replace("fov = 22.0\n", "fov = 22.0\nmedium = \"fog\"\n");
    let a = render_toml("sides-camera-scene", &by_scene, &[], 2);
    let b = render_toml("sides-camera-medium", &by_camera, &[], 2);
    assert!(a.mean().min_element() > 0.0);
    assert_eq!(
        a.mean(),
        b.mean(),
        "the camera's medium against the scene medium"
    );
}

#[test]
fn a_medium_whose_boundary_leaks_is_an_error_naming_the_shape() {
    let text = slab_scene(1).replace("exterior = \"vacuum\"\n", "");
    let dir = temp_dir("sides-leak");
    let path = write(&dir, "scene.toml", &text);
    let err = foton_loader::load(&path, &[])
        .err()
        .expect("an open quad holding fog alone")
        .to_string();
    let _ = std::fs::remove_dir_all(dir);
    for part in [
        "shapes[1].interior",
        "quad that is not closed",
        "leak",
        "exterior",
    ] {
        assert!(err.contains(part), "{part:?} not in: {err}");
    }
    // An undefined medium at the camera.
    let text = slab_scene(1).replace("fov = 0.5\n", "fov = 0.5\nmedium = \"smoke\"\n");
    let dir = temp_dir("sides-undefined");
    let path = write(&dir, "scene.toml", &text);
    let err = foton_loader::load(&path, &[])
        .err()
        .expect("an undefined medium")
        .to_string();
    let _ = std::fs::remove_dir_all(dir);
    assert!(
        err.contains("camera.medium") && err.contains("\"smoke\""),
        "{err}"
    );
}

/// A fog box standing on the floor (its bottom face in the floor's plane) is a warning naming
/// both shapes; 1 mm above it, none.
#[test]
fn a_medium_boundary_on_a_floor_is_a_warning() {
    let scene = |bottom: f32| {
        let half = 0.5 * (1.0 - bottom);
        format!(
            r#"{}
[camera]
position = [0.0, 0.5, 4.0]
look_at = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov = 30.0
[materials.white]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]
[materials.boundary]
type = "null"
[media.fog]
type = "homogeneous"
sigma_a = [0.1, 0.1, 0.1]
sigma_s = [0.5, 0.5, 0.5]
[[shapes]]
type = "quad"
origin = [-2.0, 0.0, 2.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 0.0, -4.0]
material = "white"
[[shapes]]
type = "mesh"
file = "{}"
material = "boundary"
interior = "fog"
transform = {{ translate = [0.0, {}, 0.0], scale = [0.5, {half}, 0.5] }}
[[lights]]
type = "point"
position = [0.0, 3.0, 1.0]
intensity = [1.0, 1.0, 1.0]
"#,
            header("path", 1, 4, 4, 4),
            repo_root().join("scenes/meshes/cube.obj").display(),
            bottom + half,
        )
    };
    let on = load_toml("sides-on-floor", &scene(0.0));
    let warned: Vec<&String> = on
        .warnings()
        .iter()
        .filter(|w| w.contains("a medium boundary"))
        .collect();
    assert_eq!(warned.len(), 1, "{:?}", on.warnings());
    assert!(
        warned[0].contains("shapes[1]") && warned[0].contains("shapes[0]"),
        "{}",
        warned[0]
    );
    let above = load_toml("sides-above-floor", &scene(0.001));
    assert!(
        !above
            .warnings()
            .iter()
            .any(|w| w.contains("a medium boundary")),
        "{:?}",
        above.warnings()
    );
}

/// Bitterli's volumetric caustic (Mitsuba 3 port: the fog in a `cube` with a `null` BSDF,
/// walls and light in the fog, a glass sphere with the fog outside): `path` and `vpm` render
/// the fog; `vpm` shows the light the sphere focuses below it, brighter than the fog beside.
#[test]
fn bitterli_volumetric_caustic_v3_renders_its_caustic_with_vpm() {
    let file = repo_root().join("scenes/bitterli/volumetric-caustic/scene_v3.xml");
    let scene = foton_loader::load(&file, &[]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        scene.camera_medium(),
        None,
        "the camera stands outside the fog"
    );
    let size = ["film.width=16", "film.height=16", "render.max_depth=8"];
    let mut vpm = size.to_vec();
    vpm.extend([
        "render.integrator=\"vpm\"",
        "render.spp=4",
        "integrators.vpm.global_photons=20000",
        "integrators.vpm.volume_photons=100000",
        "integrators.vpm.caustic_photons=20000",
    ]);
    let film = render_file(&file, &vpm, 2);
    // The sphere (x = -0.23, y = 1.2, r = 0.3) covers about columns 4 to 8 and rows 5 to 8
    // of 16; the beam it focuses runs down column 5 below it (rows 7 to 10). Beside it: the
    // fog at the same height, columns 2 and 3.
    let (caustic, _) = region_mean(&film, 5, 7, 6, 11);
    let (beside, _) = region_mean(&film, 2, 7, 4, 11);
    assert!(beside.min_element() > 0.0, "the fog is lit: {beside}");
    assert!(
        caustic.x > 1.25 * beside.x,
        "vpm: the focused light {caustic} against the fog beside it {beside}"
    );
    let mut path = size.to_vec();
    path.extend(["render.integrator=\"path\"", "render.spp=16"]);
    let film = render_file(&file, &path, 2);
    let (beside_path, se) = region_mean(&film, 10, 8, 13, 11);
    assert!(
        beside_path.x > 4.0 * se.x && beside_path.z > 0.0,
        "path: the fog is lit: {beside_path}"
    );
}
