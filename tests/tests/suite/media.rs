//! Participating media: where media are (boundaries, nesting, touching volumes, the camera's
//! medium), transmittance along shadow rays, and the `path` integrator's volumetric estimates
//! against closed forms: single scattering from a point light against a quadrature of its
//! integral, an albedo-1 medium in a white furnace, empty media that must change nothing, and
//! determinism. The samplers (free flight, phase functions) are chi-square tested in
//! sampling_media.rs.

use foton_core::Rgb;
use foton_core::scene::Scene;
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{header, region_mean, render_file, render_toml, repo_root, temp_dir, write};
use glam::{DVec3, Vec3};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// A closed box [lo, hi] as OBJ text, normals outward (counter-clockwise seen from outside).
fn box_obj(lo: Vec3, hi: Vec3) -> String {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let mut s: String = (0..8)
        .map(|i| {
            let p = corner(i);
            format!("v {} {} {}\n", p.x, p.y, p.z)
        })
        .collect();
    let centre = 0.5 * (lo + hi);
    for axis in 0..3 {
        for side in 0..2 {
            // The face's corners in cyclic order: the two other axes' bits as 00, 01, 11, 10.
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut f: Vec<usize> = [(0, 0), (1, 0), (1, 1), (0, 1)]
                .iter()
                .map(|&(i, j)| (side << axis) | (i << a) | (j << b))
                .collect();
            let (p0, p1, p2) = (corner(f[0]), corner(f[1]), corner(f[2]));
            if (p1 - p0).cross(p2 - p0).dot(p0 - centre) < 0.0 {
                f.reverse();
            }
            s += &format!("f {} {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1, f[3] + 1);
        }
    }
    s
}

/// A scene file in a fresh folder with the given box meshes (file name, lo, hi) beside it.
fn scene_dir(name: &str, toml: &str, boxes: &[(&str, Vec3, Vec3)]) -> (PathBuf, PathBuf) {
    let dir = temp_dir(name);
    for (file, lo, hi) in boxes {
        write(&dir, file, &box_obj(*lo, *hi));
    }
    let path = write(&dir, "scene.toml", toml);
    (dir, path)
}

fn load(path: &Path) -> Scene {
    foton_loader::load(path, &[]).unwrap_or_else(|e| panic!("{e}"))
}

fn medium_index(scene: &Scene, name: &str) -> Option<u32> {
    Some(scene.media().iter().position(|m| m.name == name).unwrap() as u32)
}

fn exp_rgb(v: Vec3) -> Rgb {
    Rgb::new(v.x.exp(), v.y.exp(), v.z.exp())
}

fn assert_rgb_close(what: &str, got: Rgb, want: Rgb, rel: f32) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= rel * want[c].abs() + 1e-7,
            "{what}: got {got}, expected {want}"
        );
    }
}

const CAMERA: &str = r#"
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov = 30.0
"#;

/// Box `box_a` = [-1, 1]^2 x [-0.5, 0.5] with medium A, `box_b` touching it at z = 0.5 up to
/// z = 1.5 with medium B, a glass sphere (vacuum inside) in free space at x = 4, all in a
/// scene medium S; `extra` appended.
fn nested_scene(extra: &str) -> String {
    format!(
        r#"{}{CAMERA}
[materials.boundary]
type = "null"

[materials.glass]
type = "dielectric"
ior = 1.5

[materials.wall]
type = "diffuse"

[media.S]
type = "homogeneous"
sigma_a = [0.01, 0.02, 0.03]

[media.A]
type = "homogeneous"
sigma_a = [0.5, 1.0, 2.0]
sigma_s = [0.25, 0.0, 0.5]

[media.B]
type = "homogeneous"
sigma_a = [0.1, 0.0, 0.0]
sigma_s = [0.0, 0.3, 0.0]

[media.C]
type = "homogeneous"
sigma_s = [3.0, 3.0, 3.0]

[scene]
medium = "S"

[[shapes]]
type = "mesh"
file = "a.obj"
material = "boundary"
interior = "A"

[[shapes]]
type = "mesh"
file = "b.obj"
material = "boundary"
interior = "B"

[[shapes]]
type = "sphere"
center = [4.0, 0.0, 0.0]
radius = 0.5
material = "glass"
{extra}"#,
        header("path", 1, 4, 4, 4)
    )
}

fn nested_boxes() -> [(&'static str, Vec3, Vec3); 2] {
    [
        (
            "a.obj",
            Vec3::new(-1.0, -1.0, -0.5),
            Vec3::new(1.0, 1.0, 0.5),
        ),
        (
            "b.obj",
            Vec3::new(-1.0, -1.0, 0.5),
            Vec3::new(1.0, 1.0, 1.5),
        ),
    ]
}

#[test]
fn transmittance_through_slabs_is_exp_minus_sigma_t_d_per_channel() {
    // A sphere of medium C (radius 0.25) nested in box A; box B touches A.
    let sphere_c = "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.5, 0.0]\nradius = 0.25\nmaterial = \"boundary\"\ninterior = \"C\"\n";
    let (dir, path) = scene_dir("media-slabs", &nested_scene(sphere_c), &nested_boxes());
    let scene = load(&path);
    // Homogeneous media: sigma_t is the same at every point.
    let sigma_t = |name: &str| {
        scene
            .medium(medium_index(&scene, name).unwrap())
            .sigma_t(Vec3::ZERO)
    };
    let (s, a, b, c) = (sigma_t("S"), sigma_t("A"), sigma_t("B"), sigma_t("C"));
    let tr = |p0: Vec3, p1: Vec3| {
        let m = scene.medium_at(p0).unwrap();
        scene.transmittance(p0, Vec3::ZERO, p1, Vec3::ZERO, m)
    };

    // Through A alone, along x: 2 in A, 1 + 1 in S.
    let got = tr(Vec3::new(-2.0, -0.5, 0.0), Vec3::new(2.0, -0.5, 0.0));
    assert_rgb_close("S | A | S", got, exp_rgb(-(2.0 * a + 2.0 * s)), 1e-5);

    // Along z through both touching boxes: S 1.5, A 1, B 1, S 0.5.
    let got = tr(Vec3::new(0.3, -0.5, -2.0), Vec3::new(0.3, -0.5, 2.0));
    let want = exp_rgb(-(2.0 * s + a + b));
    assert_rgb_close("S | A | B | S", got, want, 1e-5);
    // And back: the medium after each crossing does not depend on the direction.
    let back = tr(Vec3::new(0.3, -0.5, 2.0), Vec3::new(0.3, -0.5, -2.0));
    assert_rgb_close("S | B | A | S", back, want, 1e-5);

    // Through the sphere of C nested in A: 2 in S, 1.5 in A, 0.5 in C.
    let got = tr(Vec3::new(-2.0, 0.5, 0.0), Vec3::new(2.0, 0.5, 0.0));
    assert_rgb_close(
        "S | A | C | A | S",
        got,
        exp_rgb(-(2.0 * s + 1.5 * a + 0.5 * c)),
        1e-5,
    );

    // Starting inside the nested sphere, and inside B.
    let got = tr(Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.0, 0.5, 3.0));
    let want = exp_rgb(-(0.25 * c + 0.25 * a + b + 1.5 * s));
    assert_rgb_close("C | A | B | S", got, want, 1e-5);

    // The clear glass sphere is vacuum inside, but glass blocks shadow rays.
    assert_eq!(
        tr(Vec3::new(2.0, 0.0, 0.0), Vec3::new(6.0, 0.0, 0.0)),
        Rgb::ZERO
    );
    // A segment inside the glass: vacuum.
    assert_eq!(
        tr(Vec3::new(3.8, 0.0, 0.0), Vec3::new(4.2, 0.0, 0.0)),
        Rgb::ONE
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn medium_at_finds_the_innermost_volume_and_the_interfaces_their_outsides() {
    let sphere_c = "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.5, 0.0]\nradius = 0.25\nmaterial = \"boundary\"\ninterior = \"C\"\n";
    let (dir, path) = scene_dir("media-at", &nested_scene(sphere_c), &nested_boxes());
    let scene = load(&path);
    let m = |n: &str| medium_index(&scene, n);
    assert_eq!(scene.camera_medium(), m("S"));
    assert_eq!(scene.medium_at(Vec3::new(0.0, 0.0, 0.0)), Ok(m("A")));
    assert_eq!(scene.medium_at(Vec3::new(0.0, 0.5, 0.1)), Ok(m("C")));
    assert_eq!(scene.medium_at(Vec3::new(0.0, 0.0, 1.0)), Ok(m("B")));
    assert_eq!(scene.medium_at(Vec3::new(4.0, 0.1, 0.0)), Ok(None));
    assert_eq!(scene.medium_at(Vec3::new(0.0, 3.0, 0.0)), Ok(m("S")));
    // On a boundary: undefined, and said so.
    let err = scene.medium_at(Vec3::new(0.0, 0.0, 0.5)).unwrap_err();
    assert!(err.contains("boundary"), "{err}");
    // The sphere's outside is A, A's and B's outside is S, the glass's outside is S.
    let sphere = scene.interfaces()[3].unwrap();
    assert_eq!(
        (sphere.inside, sphere.outside, sphere.depth),
        (m("C"), m("A"), 1)
    );
    let a = scene.interfaces()[0].unwrap();
    assert_eq!((a.inside, a.outside, a.depth), (m("A"), m("S"), 0));
    let glass = scene.interfaces()[2].unwrap();
    assert_eq!((glass.inside, glass.outside), (None, m("S")));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn camera_inside_a_nested_medium_starts_there() {
    let (dir, path) = scene_dir("media-camera", &nested_scene(""), &nested_boxes());
    let scene = foton_loader::load(&path, &["camera.position=[0.2, 0.1, 1.0]".into()]).unwrap();
    assert_eq!(scene.camera_medium(), medium_index(&scene, "B"));
    let scene = foton_loader::load(&path, &["camera.position=[4.0, 0.1, 0.0]".into()]).unwrap();
    assert_eq!(scene.camera_medium(), None, "inside the clear glass");
    let _ = std::fs::remove_dir_all(dir);
}

/// A 4x4 image, `max_depth` 0 (emission only), of an emitter of radiance [1, 2, 3] at z = -1
/// seen from z = 5 through slabs of absorbing media ((sigma_a, z0, z1), each a closed box
/// behind a null boundary); asserts that the image is Le exp(-sum sigma_a d) per channel.
fn assert_rendered_transmittance(name: &str, slabs: &[(Vec3, f32, f32)]) {
    let mut toml = format!(
        r#"{}
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov = 0.5

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
"#,
        header("path", 256, 0, 4, 4)
    );
    let mut boxes = Vec::new();
    let mut files = Vec::new();
    let mut optical_depth = Vec3::ZERO;
    for (k, &(sigma_a, z0, z1)) in slabs.iter().enumerate() {
        toml += &format!(
            "[media.m{k}]\ntype = \"homogeneous\"\nsigma_a = [{}, {}, {}]\n[[shapes]]\ntype = \"mesh\"\nfile = \"slab{k}.obj\"\nmaterial = \"boundary\"\ninterior = \"m{k}\"\n",
            sigma_a.x, sigma_a.y, sigma_a.z
        );
        files.push(format!("slab{k}.obj"));
        boxes.push((Vec3::new(-5.0, -5.0, z0), Vec3::new(5.0, 5.0, z1)));
        optical_depth += sigma_a * (z1 - z0);
    }
    let boxes: Vec<(&str, Vec3, Vec3)> = files
        .iter()
        .zip(&boxes)
        .map(|(f, &(lo, hi))| (f.as_str(), lo, hi))
        .collect();
    let (dir, path) = scene_dir(name, &toml, &boxes);
    let film = render_file(&path, &[], 2);
    let want = Rgb::new(1.0, 2.0, 3.0) * exp_rgb(-optical_depth);
    // A sample passes with probability P (the mean over the hero channels of their
    // transmittance) and then carries Le Tr / P, else nothing (the media do not scatter): the
    // standard error of the mean of n samples is Le Tr / P sqrt(P (1 - P) / n).
    let mean = film.mean();
    let p = foton_core::medium::free_flight_pass_probability(optical_depth, 1.0);
    let n = 16.0 * 256.0;
    let err = want / p * (p * (1.0 - p) / n).sqrt();
    for c in 0..3 {
        assert!(
            (mean[c] - want[c]).abs() < 4.0 * err[c] + 1e-6,
            "{name}: channel {c}: {mean} +- {err}, expected {want}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn rendered_transmittance_through_an_absorbing_slab() {
    assert_rendered_transmittance(
        "media-slab-render",
        &[(Vec3::new(0.5, 2.0, 4.0), -0.25, 0.25)],
    );
}

#[test]
fn rendered_transmittance_through_touching_volumes() {
    // Three slabs touching at z = 0 and z = 0.3: the camera ray crosses their shared faces,
    // where whichever of the two coincident boundaries it hits first, it must enter the next
    // slab, not vacuum.
    assert_rendered_transmittance(
        "media-touching-render",
        &[
            (Vec3::new(0.5, 2.0, 4.0), -0.25, 0.0),
            (Vec3::new(3.0, 0.2, 0.0), 0.0, 0.3),
            (Vec3::new(1.0, 1.0, 1.0), 0.3, 0.5),
        ],
    );
}

/// The HG phase function (or isotropic for g = 0) in f64, independently of the core's.
fn hg(g: f64, cos: f64) -> f64 {
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
}

#[test]
fn single_scattering_from_a_point_light_matches_quadrature() {
    // An infinite chromatic medium, a point light off the axis of a very narrow camera, one
    // scattering event (max_depth = 1): L = int_0^inf Tr(t) sigma_s p(cos) I Tr(d) / d^2 dt.
    let sigma_a = DVec3::new(0.05, 0.2, 0.4);
    let sigma_s = DVec3::new(0.5, 0.3, 0.1);
    let g = 0.5;
    let intensity = DVec3::new(2.0, 3.0, 4.0);
    let light = DVec3::new(0.4, 0.0, -1.5);
    let toml = format!(
        r#"{}
[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
fov = 0.01

[media.fog]
type = "homogeneous"
sigma_a = [{}, {}, {}]
sigma_s = [{}, {}, {}]
phase = {{ type = "hg", g = {g} }}

[scene]
medium = "fog"

[[lights]]
type = "point"
position = [{}, {}, {}]
intensity = [{}, {}, {}]
"#,
        header("path", 65536, 1, 4, 4),
        sigma_a.x,
        sigma_a.y,
        sigma_a.z,
        sigma_s.x,
        sigma_s.y,
        sigma_s.z,
        light.x,
        light.y,
        light.z,
        intensity.x,
        intensity.y,
        intensity.z
    );
    let film = render_toml("media-single", &toml, &[], 2);

    // The camera ray is -z; light travels from the light to x = (0, 0, -t), then to the
    // camera (+z).
    let sigma_t = sigma_a + sigma_s;
    let integrand = |t: f64| {
        let x = DVec3::new(0.0, 0.0, -t);
        let to_x = x - light;
        let d = to_x.length();
        let cos = to_x.z / d;
        let tr =
            |s: DVec3, l: f64| DVec3::new((-s.x * l).exp(), (-s.y * l).exp(), (-s.z * l).exp());
        tr(sigma_t, t) * sigma_s * hg(g, cos) * intensity * tr(sigma_t, d) / (d * d)
    };
    // Simpson on [0, 200] (Tr < e^-110 beyond), fine near the light's closest approach.
    let n = 400_000;
    let (a, b) = (0.0, 200.0);
    let h = (b - a) / n as f64;
    let mut want = integrand(a) + integrand(b);
    for i in 1..n {
        want += integrand(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    want *= h / 3.0;

    let (mean, err) = region_mean(&film, 0, 0, 4, 4);
    for c in 0..3 {
        let (m, e, w) = (mean[c] as f64, err[c] as f64, want[c]);
        println!("channel {c}: rendered {m} +- {e}, quadrature {w}");
        assert!(
            (m - w).abs() < 4.0 * e + 1e-3 * w,
            "channel {c}: rendered {m} +- {e}, quadrature {w}"
        );
        assert!(e < 0.02 * w, "too noisy to prove anything: {e} vs {w}");
    }
}

/// Six inward-facing diffuse quads (albedo `rho`) emitting `le` forming the box [-1, 1]^3,
/// camera inside, filled with the scene medium given by `medium` (TOML of `[media.m]`).
fn furnace_with_medium(rho: f32, le: f32, medium: &str, spp: u32) -> String {
    let c = |x: f32, y: f32, z: f32| format!("[{x}, {y}, {z}]");
    let faces = [
        (c(-1., -1., -1.), c(0., 0., 2.), c(2., 0., 0.)),
        (c(-1., 1., -1.), c(2., 0., 0.), c(0., 0., 2.)),
        (c(-1., -1., -1.), c(2., 0., 0.), c(0., 2., 0.)),
        (c(-1., -1., 1.), c(0., 2., 0.), c(2., 0., 0.)),
        (c(-1., -1., -1.), c(0., 2., 0.), c(0., 0., 2.)),
        (c(1., -1., -1.), c(0., 0., 2.), c(0., 2., 0.)),
    ];
    let mut s = header("path", spp, 1000, 16, 16);
    s += "[camera]\nposition = [0.0, 0.0, 0.9]\nlook_at = [0.0, 0.0, 0.0]\nfov = 90.0\n";
    s += &format!("[materials.wall]\ntype = \"diffuse\"\nreflectance = [{rho}, {rho}, {rho}]\n");
    s += medium;
    s += "[scene]\nmedium = \"m\"\n";
    for (o, u, v) in faces {
        s += &format!(
            "[[shapes]]\ntype = \"quad\"\norigin = {o}\nu = {u}\nv = {v}\nmaterial = \"wall\"\nemission = [{le}, {le}, {le}]\n"
        );
    }
    s
}

#[test]
fn albedo_one_medium_leaves_a_white_furnace_uniform() {
    // In a uniform radiance field, a medium that only scatters takes out as much as it puts
    // in: the image stays le / (1 - rho) whatever sigma_s (chromatic) and the phase function.
    let medium = "[media.m]\ntype = \"homogeneous\"\nsigma_s = [0.5, 1.5, 3.0]\nphase = { type = \"hg\", g = 0.6 }\n";
    let film = render_toml(
        "media-furnace",
        &furnace_with_medium(0.5, 1.0, medium, 64),
        &[],
        2,
    );
    let (mean, err) = region_mean(&film, 0, 0, 16, 16);
    println!("albedo-1 medium in the furnace: {mean} +- {err}, expected 2");
    for c in 0..3 {
        assert!(
            (mean[c] - 2.0).abs() < (4.0 * err[c]).max(1e-3) && (mean[c] - 2.0).abs() < 0.03,
            "channel {c}: {mean} +- {err}, expected 2"
        );
    }
    // An absorbing medium must darken it (the test can fail).
    let medium =
        "[media.m]\ntype = \"homogeneous\"\nsigma_a = [0.3, 0.3, 0.3]\nsigma_s = [0.5, 1.5, 3.0]\n";
    let film = render_toml(
        "media-furnace-a",
        &furnace_with_medium(0.5, 1.0, medium, 16),
        &[],
        2,
    );
    assert!(film.mean().max_element() < 1.8, "{}", film.mean());
}

#[test]
fn murky_glass_with_an_albedo_one_medium_is_invisible_in_a_furnace() {
    // A lossless dielectric sphere filled with a medium that only scatters, in the furnace:
    // the field stays uniform only if paths enter the medium on refraction into the sphere,
    // leave it on refraction out, and the 1/eta^2 scaling is undone on the way out.
    let inner = "[media.inner]\ntype = \"homogeneous\"\nsigma_s = [4.0, 2.0, 1.0]\nphase = { type = \"hg\", g = -0.3 }\n";
    let sphere = "[materials.glass]\ntype = \"dielectric\"\nior = 1.5\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, -0.2]\nradius = 0.5\nmaterial = \"glass\"\ninterior = \"inner\"\n";
    let medium = format!("[media.m]\ntype = \"homogeneous\"\n{inner}");
    let toml = furnace_with_medium(0.5, 1.0, &medium, 64) + sphere;
    let film = render_toml("media-furnace-murky", &toml, &[], 2);
    // The pixels that see the sphere (it covers the middle of the image).
    let (mean, err) = region_mean(&film, 5, 5, 11, 11);
    println!("murky glass in the furnace: {mean} +- {err}, expected 2");
    for c in 0..3 {
        assert!(
            (mean[c] - 2.0).abs() < (4.0 * err[c]).max(0.02),
            "channel {c}: {mean} +- {err}, expected 2"
        );
    }
    // With absorption inside, the sphere is darker (the test can fail).
    let toml = toml.replace(
        "sigma_s = [4.0, 2.0, 1.0]",
        "sigma_a = [1.0, 1.0, 1.0]\nsigma_s = [4.0, 2.0, 1.0]",
    );
    let film = render_toml("media-furnace-murky-a", &toml, &[], 2);
    let (dark, _) = region_mean(&film, 5, 5, 11, 11);
    assert!(dark.max_element() < 1.8, "{dark}");
}

#[test]
fn empty_media_change_nothing() {
    let cornell = repo_root().join("scenes/cornell-box.toml");
    let text = std::fs::read_to_string(&cornell).unwrap();
    let empty = "\n[media.empty]\ntype = \"homogeneous\"\n";
    let small = ["film.width=24", "film.height=24", "render.spp=8"];
    let reference = render_file(&cornell, &small, 2);

    // An empty medium filling free space: the same paths, bit for bit.
    let with_scene_medium = format!("{text}{empty}\n[scene]\nmedium = \"empty\"\n");
    let film = render_toml("media-empty-scene", &with_scene_medium, &small, 2);
    assert_eq!(film.pixels(), reference.pixels());

    // An empty medium behind a null boundary: rays are restarted at the boundary, so hit
    // points differ in the last bits, and a few of the 8 paths of a pixel that bounce many
    // times end up on another surface: most pixels agree to rounding, all agree in the mean.
    let with_cube = format!(
        "{text}{empty}\n[materials.boundary]\ntype = \"null\"\n\n[[shapes]]\ntype = \"mesh\"\nfile = \"cube.obj\"\nmaterial = \"boundary\"\ninterior = \"empty\"\n"
    );
    let (dir, path) = scene_dir(
        "media-empty-cube",
        &with_cube,
        &[(
            "cube.obj",
            Vec3::new(-0.6, 0.1, -0.6),
            Vec3::new(0.6, 1.3, 0.6),
        )],
    );
    let film = render_file(&path, &small, 2);
    let mut differ = 0;
    for (a, b) in film.pixels().iter().zip(reference.pixels().iter()) {
        if (*a - *b).abs().max_element() > 1e-4 * (1.0 + b.max_element()) {
            differ += 1;
        }
    }
    let n = reference.pixels().len();
    assert!(differ * 5 < n, "{differ} of {n} pixels differ");
    let (a, b) = (film.mean(), reference.mean());
    assert!(
        (a - b).abs().max_element() < 3e-3 * b.max_element(),
        "{a} vs {b}"
    );
    // And region by region (4x4 blocks of 6x6 pixels), each to the same 0.3 % plus what the
    // few diverging paths add: the pixel-wise differences are zero but for them, so the
    // standard error of the difference measures exactly that noise (z = 4 of it allowed).
    assert_blocks_agree(
        "empty medium behind a null boundary",
        &film,
        &reference,
        4,
        Tolerance {
            rel: 3e-3,
            z: 4.0,
            floor: 3e-3 * b.max_element() as f64,
        },
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn fog_scenes_are_identical_for_one_and_many_threads() {
    let path = repo_root().join("scenes/fog_box.toml");
    let small = ["film.width=16", "film.height=16", "render.spp=4"];
    let one = render_file(&path, &small, 1);
    let many = render_file(&path, &small, 3);
    assert_eq!(one.pixels(), many.pixels());
    assert!(one.mean().min_element() > 0.0);
}
