//! Shapes and their shading (issue 10): disks (an area light's irradiance against the formula),
//! `flip_normals`, `hide_emitters`, smooth shading normals of meshes (computed as Mitsuba does
//! when a file has none, or read from the file) and texture coordinates from files.

use foton_core::Rgb;
use foton_tests::{foton_with_plugins, header, region_mean, render_toml, temp_dir, write};

/// A camera for the scenes that are only loaded, not rendered.
const CAMERA: &str = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 30\n\n";

/// A disk light of radiance L and radius R, facing down from height h over a white-ish floor,
/// seen by a narrow camera beside it. On the disk's axis the irradiance is
/// E = pi L R^2 / (h^2 + R^2), so the floor's radiance there is rho E / pi (direct light only).
fn disk_scene(integrator: &str, spp: u32, flip: bool) -> String {
    let (normal, flip_normals) = if flip {
        ("[0, 1, 0]", "flip_normals = true")
    } else {
        ("[0, -1, 0]", "")
    };
    header(integrator, spp, 1, 4, 4)
        + &format!(
            r#"
[camera]
position = [0, 0.4, 3]
look_at = [0, 0, 0]
fov = 0.5

[materials.floor]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[materials.black]
type = "diffuse"
reflectance = [0, 0, 0]

[[shapes]]
type = "quad"
origin = [-2, 0, 2]
u = [4, 0, 0]
v = [0, 0, -4]
material = "floor"

[[shapes]]
type = "disk"
center = [0, 1, 0]
normal = {normal}
radius = 0.5
material = "black"
emission = [4, 4, 4]
{flip_normals}

[integrators.photon]
global_photons = 2000000
caustic_photons = 0
direct = "photons"
k = 4000

[integrators.sppm]
iterations = 64
photons_per_iteration = 20000
"#
        )
}

#[test]
fn a_disk_light_gives_the_irradiance_of_its_formula() {
    let (l, r, h, rho) = (4.0f32, 0.5f32, 1.0f32, 0.5f32);
    let e = std::f32::consts::PI * l * r * r / (h * h + r * r);
    let want = rho * e / std::f32::consts::PI;
    // path: light samples on the disk (its area sampling); photon: photons leaving it
    // (direct light from the photons); sppm: both.
    // Tolerances: the path tracer's noise; the photon estimate's noise (4000 photons: 1.6%) and
    // its blur (a disc of radius 0.08, over which E falls by about 1.2%); sppm's noise.
    for (integrator, spp, tol) in [("path", 256, 0.01), ("photon", 4, 0.05), ("sppm", 1, 0.03)] {
        let film = render_toml("disk-light", &disk_scene(integrator, spp, false), &[], 2);
        let (m, _) = region_mean(&film, 0, 0, 4, 4);
        let err = (m.x - want).abs() / want;
        assert!(err < tol, "{integrator}: {m} against {want}");
    }
    // The same disk facing up, turned over by flip_normals, lights the floor the same; facing
    // up without the flip, it lights nothing (an area light emits on its normal's side).
    let flipped = render_toml("disk-flipped", &disk_scene("path", 256, true), &[], 2);
    let (m, _) = region_mean(&flipped, 0, 0, 4, 4);
    assert!(
        (m.x - want).abs() / want < 0.01,
        "flipped: {m} against {want}"
    );
    let up = disk_scene("path", 16, true).replace("flip_normals = true", "");
    let dark = render_toml("disk-up", &up, &[], 2);
    assert_eq!(dark.mean(), Rgb::ZERO);
}

#[test]
fn flip_normals_turns_meshes_quads_and_spheres_over() {
    let dir = temp_dir("flip-normals");
    // One triangle, wound to face +y: flipped, it faces -y.
    let obj = write(&dir, "tri.obj", "v -1 0 -1\nv 0 0 1\nv 1 0 -1\nf 1 2 3\n");
    for (shape, facing) in [
        (
            format!("type = \"mesh\"\nfile = \"{}\"", obj.display()),
            1.0f32,
        ),
        (
            "type = \"quad\"\norigin = [-1, 0, -1]\nu = [0, 0, 2]\nv = [2, 0, 0]".to_string(),
            1.0,
        ),
    ] {
        for flip in [false, true] {
            let text = format!(
                "{CAMERA}[materials.m]\ntype = \"diffuse\"\n\n[[shapes]]\n{shape}\nmaterial = \"m\"\nflip_normals = {flip}\n"
            );
            let path = write(&dir, "s.toml", &text);
            let scene = foton_loader::load(&path, &[]).unwrap();
            let hit = scene
                .intersect(
                    &foton_core::geometry::Ray::new(
                        glam::Vec3::new(0.1, 1.0, -0.2),
                        glam::Vec3::NEG_Y,
                    ),
                    f32::INFINITY,
                )
                .expect("the ray meets the shape");
            let sp = scene.surface(&hit);
            let want = if flip { -facing } else { facing };
            assert!(
                (sp.ng.y - want).abs() < 1e-6 && (sp.ns.y - want).abs() < 1e-6,
                "{shape} flip {flip}: ng {} ns {}",
                sp.ng,
                sp.ns
            );
        }
    }
    // A sphere turned inside out: its normal points to the centre; it cannot hold a medium.
    let sphere = |extra: &str| {
        format!(
            "{CAMERA}[materials.m]\ntype = \"diffuse\"\n\n[media.fog]\ntype = \"homogeneous\"\nsigma_a = [0.1, 0.1, 0.1]\nsigma_s = [0.1, 0.1, 0.1]\n\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\nflip_normals = true\n{extra}"
        )
    };
    let scene = foton_loader::load(&write(&dir, "sphere.toml", &sphere("")), &[]).unwrap();
    let ray = foton_core::geometry::Ray::new(glam::Vec3::new(0.0, 0.0, 3.0), glam::Vec3::NEG_Z);
    let hit = scene.intersect(&ray, f32::INFINITY).unwrap();
    assert!((hit.ng - glam::Vec3::NEG_Z).length() < 1e-6, "{}", hit.ng);
    let path = write(&dir, "sphere.toml", &sphere("interior = \"fog\""));
    let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
    assert_eq!(run.code, 1);
    assert!(
        run.stderr.contains("shapes[0].flip_normals") && run.stderr.contains("inside out"),
        "{}",
        run.stderr
    );
}

/// An emissive sphere turned inside out lights what is inside it and nothing outside: a
/// two-sided diffuse square at the centre of a dome of radiance L (a furnace from inside)
/// shows rho L, and the same dome seen from outside is black.
#[test]
fn an_inside_out_sphere_emits_inwards() {
    let scene = |integrator: &str, camera_z: f32| {
        header(integrator, 64, 4, 8, 8)
            + &format!(
                r#"
[camera]
position = [0, 0, {camera_z}]
look_at = [0, 0, 0]
fov = 10

[materials.grey]
type = "diffuse"
reflectance = [0.6, 0.6, 0.6]

[materials.black]
type = "diffuse"
reflectance = [0, 0, 0]

[[shapes]]
type = "quad"
origin = [-0.5, -0.5, 0]
u = [1, 0, 0]
v = [0, 1, 0]
material = "grey"

[[shapes]]
type = "sphere"
center = [0, 0, 0]
radius = 5
material = "black"
emission = [2, 2, 2]
flip_normals = true

[integrators.photon]
global_photons = 200000
caustic_photons = 0
direct = "photons"
k = 200
"#
            )
    };
    // path: light samples on the dome from inside; photon: photons it emits inwards.
    for (integrator, tol) in [("path", 0.01), ("photon", 0.05)] {
        let inside = render_toml("dome-inside", &scene(integrator, 3.0), &[], 2);
        let (m, se) = region_mean(&inside, 2, 2, 6, 6);
        assert!(
            (m.x - 1.2).abs() < 4.0 * se.x + tol * 1.2,
            "{integrator}: rho L = 1.2 inside the dome: {m}"
        );
    }
    let outside = render_toml("dome-outside", &scene("path", 8.0), &[], 2);
    assert_eq!(outside.mean(), Rgb::ZERO, "the dome is dark from outside");
}

/// `hide_emitters`: the camera does not see emitters directly (an area light in front of it is
/// passed through, the environment is black behind everything), but their light still lights
/// the scene.
#[test]
fn hidden_emitters_light_the_scene_but_are_not_seen() {
    let scene = |integrator: &str, hide: bool| {
        header(integrator, 16, 8, 8, 8).replace(
            "max_depth = 8",
            &format!("max_depth = 8\nhide_emitters = {hide}"),
        ) + r#"
[camera]
position = [0, 0, 6]
look_at = [0, 0, 0]
fov = 30

[materials.grey]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]

[materials.black]
type = "diffuse"
reflectance = [0, 0, 0]

# An emitter facing the camera, covering the left half of the view.
[[shapes]]
type = "quad"
origin = [-3, -3, 2]
u = [3, 0, 0]
v = [0, 6, 0]
material = "black"
emission = [5, 5, 5]

# A grey sphere on the right.
[[shapes]]
type = "sphere"
center = [1.0, 0, 0]
radius = 0.6
material = "grey"

[[lights]]
type = "constant"
radiance = [1, 1, 1]

# Few photons bounce twice (off the sphere onto itself): a small k.
[integrators.photon]
global_photons = 20000
caustic_photons = 0
k = 2

[integrators.sppm]
iterations = 64
photons_per_iteration = 2000
"#
    };
    for integrator in ["path", "photon", "sppm"] {
        let shown = render_toml("hide-emitters", &scene(integrator, false), &[], 2);
        let hidden = render_toml("hide-emitters", &scene(integrator, true), &[], 2);
        // The emitter's half: its radiance, or (hidden) the black environment behind it.
        let (left, _) = region_mean(&shown, 0, 0, 3, 8);
        assert!(
            (left - Rgb::splat(5.0)).abs().max_element() < 1e-4,
            "{integrator}: {left}"
        );
        let (left, _) = region_mean(&hidden, 0, 0, 3, 8);
        assert_eq!(left, Rgb::ZERO, "{integrator}: the hidden emitter");
        // The background corner on the right: the environment, or black.
        assert!((shown.pixel(7, 0) - Rgb::ONE).abs().max_element() < 1e-4);
        assert_eq!(
            hidden.pixel(7, 0),
            Rgb::ZERO,
            "{integrator}: the environment"
        );
        // The sphere is lit either way: the same image there (pixels wholly on it).
        let (a, _) = region_mean(&shown, 6, 3, 7, 5);
        let (b, _) = region_mean(&hidden, 6, 3, 7, 5);
        assert!(a.x > 0.2, "{integrator}: the sphere is lit: {a}");
        assert_eq!(a, b, "{integrator}: hiding emitters changed the sphere");
    }
}

/// A sphere tessellated as a latitude-longitude OBJ (shared vertices, no normals, no texture
/// coordinates), `rows` x `2 rows` quads.
fn uv_sphere_obj(rows: usize, with_vt: bool) -> String {
    let cols = 2 * rows;
    let mut s = String::new();
    let vertex = |i: usize, j: usize| {
        let theta = std::f64::consts::PI * i as f64 / rows as f64;
        let phi = 2.0 * std::f64::consts::PI * j as f64 / cols as f64;
        (
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    };
    for i in 0..=rows {
        for j in 0..cols {
            let (x, y, z) = vertex(i, j);
            s += &format!("v {x} {y} {z}\n");
            if with_vt {
                s += &format!("vt {} {}\n", j as f64 / cols as f64, i as f64 / rows as f64);
            }
        }
    }
    let id = |i: usize, j: usize| i * cols + j % cols + 1;
    for i in 0..rows {
        for j in 0..cols {
            let (a, b, c, d) = (id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j));
            if with_vt {
                s += &format!("f {a}/{a} {b}/{b} {c}/{c} {d}/{d}\n");
            } else {
                s += &format!("f {a} {b} {c} {d}\n");
            }
        }
    }
    s
}

/// Smooth normals: a coarse tessellated sphere without normals is shaded with vertex normals
/// computed from its faces (Mitsuba's default), so its normals are close to the true sphere's
/// everywhere; with `face_normals` they are the facets' (off by up to half a facet's angle),
/// and with `compute_normals = false` too (the file has none).
#[test]
fn meshes_without_normals_are_shaded_smooth() {
    let dir = temp_dir("smooth-normals");
    let obj = write(&dir, "sphere.obj", &uv_sphere_obj(12, false));
    let load = |extra: &str| {
        let text = format!(
            "{CAMERA}[materials.m]\ntype = \"diffuse\"\n\n[[shapes]]\ntype = \"mesh\"\nfile = \"{}\"\nmaterial = \"m\"\n{extra}\n",
            obj.display()
        );
        foton_loader::load(&write(&dir, "s.toml", &text), &[]).unwrap()
    };
    let (smooth, faceted) = (load(""), load("face_normals = true"));
    // pbrt-v4's way: no normals computed where the file has none.
    let uncomputed = load("compute_normals = false");
    let mut rng = foton_core::sampling::Rng::new(&[5]);
    let (mut worst_smooth, mut worst_faceted) = (0.0f32, 0.0f32);
    for _ in 0..2000 {
        // A ray from outside towards a random point of the unit sphere.
        let target = foton_core::sampling::uniform_sphere(rng.next_2d()) * 0.9;
        if target.y.abs() > 0.75 {
            // Each pole is a ring of distinct vertices at one position (as a latitude-longitude
            // file has it): their normals are smoothed over their own faces only.
            continue;
        }
        let origin = target.normalize() * 3.0;
        let ray = foton_core::geometry::Ray::new(origin, (target - origin).normalize());
        let hit = uncomputed.intersect(&ray, f32::INFINITY).unwrap();
        assert_eq!(
            uncomputed.surface(&hit).ns,
            hit.ng,
            "compute_normals = false: flat"
        );
        for (scene, worst) in [(&smooth, &mut worst_smooth), (&faceted, &mut worst_faceted)] {
            let hit = scene.intersect(&ray, f32::INFINITY).unwrap();
            let sp = scene.surface(&hit);
            let truth = hit.p.normalize();
            *worst = worst.max(sp.ns.dot(truth).clamp(-1.0, 1.0).acos().to_degrees());
            assert!(sp.ns.dot(sp.ng) > 0.9, "ns on the geometric normal's side");
        }
    }
    // A facet spans 15 degrees: face normals are off by up to about 10 degrees (at a facet's
    // corner); the interpolated normals by a fraction of that.
    assert!(worst_faceted > 5.0, "faceted: {worst_faceted}");
    assert!(
        worst_smooth < 2.5,
        "smooth: {worst_smooth} (faceted {worst_faceted})"
    );
}

/// Normals and texture coordinates written in the file are used: OBJ `vn` (a quad whose
/// vertex normals all lean the same way shades with that normal) and `vt` (flipped in v, as
/// Mitsuba reads OBJ files); PLY `nx ny nz` and `u v` (not flipped).
#[test]
fn normals_and_texture_coordinates_come_from_the_file() {
    let dir = temp_dir("file-normals");
    let lean = glam::Vec3::new(0.3, 1.0, 0.0).normalize();
    let obj = write(
        &dir,
        "quad.obj",
        &format!(
            "v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn {} {} {}\nf 1/1/1 2/2/1 3/3/1 4/4/1\n",
            lean.x, lean.y, lean.z
        ),
    );
    let ply = write(
        &dir,
        "quad.ply",
        &format!(
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n-1 0 1 {x} {y} {z} 0 0\n1 0 1 {x} {y} {z} 1 0\n1 0 -1 {x} {y} {z} 1 1\n-1 0 -1 {x} {y} {z} 0 1\n4 0 1 2 3\n",
            x = lean.x,
            y = lean.y,
            z = lean.z
        ),
    );
    for (file, v_at_far_edge) in [(obj, 0.0f32), (ply, 1.0)] {
        let text = format!(
            "{CAMERA}[materials.m]\ntype = \"diffuse\"\n\n[[shapes]]\ntype = \"mesh\"\nfile = \"{}\"\nmaterial = \"m\"\n",
            file.display()
        );
        let scene = foton_loader::load(&write(&dir, "s.toml", &text), &[]).unwrap();
        // Near the corner (1, 0, -1): u = 1 and v = 1 as written (0 once flipped).
        let ray =
            foton_core::geometry::Ray::new(glam::Vec3::new(0.98, 1.0, -0.98), glam::Vec3::NEG_Y);
        let hit = scene.intersect(&ray, f32::INFINITY).unwrap();
        let sp = scene.surface(&hit);
        assert!(
            (sp.ns - lean).length() < 1e-5,
            "{}: ns {}",
            file.display(),
            sp.ns
        );
        assert!((sp.ng - glam::Vec3::Y).length() < 1e-6);
        assert!(
            (sp.uv.x - 0.99).abs() < 1e-4,
            "{}: uv {}",
            file.display(),
            sp.uv
        );
        assert!(
            (sp.uv.y - (v_at_far_edge * 0.99 + (1.0 - v_at_far_edge) * 0.01)).abs() < 1e-4,
            "{}: uv {}",
            file.display(),
            sp.uv
        );
    }
}
