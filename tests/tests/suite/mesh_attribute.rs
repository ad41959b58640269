//! Mesh attributes (Mitsuba 3's `mesh_attribute` texture): a PLY file's extra vertex and face
//! properties, grouped and named as Mitsuba 3 names them (`color_0 color_1 color_2` of the
//! vertices is `vertex_color`, `r g b` of the faces `face_color`, `weight_0` `face_weight`),
//! carried to the surface and read by the material's textures. Two diffuse quads exactly fill
//! a 16 x 16 view under a constant environment of radiance 1, so that each pixel's radiance
//! is the reflectance there (L_o = rho E / pi with E = pi): a face attribute is constant over
//! its quad, a vertex attribute that is an affine function of position is that function at
//! every point whatever the triangulation, and a face weight of 0 or 1 picks one side of a
//! blend. The environment's light is sampled with multiple importance sampling, so pixels are
//! noisy: 4096 samples each put one standard deviation near 0.6 %, and the tolerance is 3 %.

use foton_core::film::Film;
use foton_tests::{foton_with_plugins, header, temp_dir, write};
use glam::Vec3;

/// The vertex colour at (x, y): affine, so that barycentric interpolation reproduces it.
fn vertex_colour(x: f32, y: f32) -> Vec3 {
    Vec3::new(0.5 + 0.3 * x, 0.4 - 0.2 * y, 0.3 + 0.1 * x + 0.1 * y)
}

/// The face colours of the left and right quads.
const FACE: [[f32; 3]; 2] = [[0.2, 0.6, 0.9], [0.8, 0.3, 0.1]];

/// Two unit quads side by side over [-1, 1] x [-1, 1] at z = 0, each one four-sided face
/// (fan-triangulated by the reader), with vertex colours, face colours and face weights.
fn ply() -> String {
    let mut v = String::new();
    for (x, y) in [
        (-1.0, -1.0),
        (0.0, -1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (1.0, -1.0),
        (1.0, 1.0),
    ] {
        let c = vertex_colour(x, y);
        v += &format!("{x} {y} 0 {} {} {}\n", c.x, c.y, c.z);
    }
    let f = FACE.map(|c| format!("{} {} {}", c[0], c[1], c[2]));
    format!(
        "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n\
         property float color_0\nproperty float color_1\nproperty float color_2\n\
         element face 2\nproperty list uchar int vertex_indices\nproperty float r\nproperty float g\n\
         property float b\nproperty float weight_0\nend_header\n{v}4 0 1 2 3 {} 0\n4 1 4 5 2 {} 1\n",
        f[0], f[1]
    )
}

fn scene(material: &str) -> String {
    header("path", 4096, 2, 16, 16)
        + &format!(
            r#"
[camera]
position = [0, 0, 10]
look_at = [0, 0, 0]
fov = {fov}

[materials.m]
{material}

[[shapes]]
type = "mesh"
file = "quads.ply"
material = "m"

[[lights]]
type = "constant"
radiance = [1, 1, 1]
"#,
            fov = 2.0 * (0.1f64).atan().to_degrees()
        )
}

fn render(name: &str, material: &str) -> Film {
    let dir = temp_dir(name);
    write(&dir, "quads.ply", &ply());
    let path = write(&dir, "scene.toml", &scene(material));
    foton_tests::render_file(&path, &[], 1)
}

/// The world point at the centre of pixel (i, j): the view spans [-1, 1] with +y up.
fn pixel_centre(i: u32, j: u32) -> (f32, f32) {
    (-1.0 + (i as f32 + 0.5) / 8.0, 1.0 - (j as f32 + 0.5) / 8.0)
}

/// Pixels away from the seam between the quads and from the view's edge, where the pixel
/// filter reaches past one quad.
fn interior() -> impl Iterator<Item = (u32, u32)> {
    (2..14u32)
        .flat_map(|j| (2..14u32).map(move |i| (i, j)))
        .filter(|&(i, _)| !(6..10).contains(&i))
}

/// Within 3 % of the expected colour, channel by channel.
fn close(got: Vec3, expected: Vec3) -> bool {
    (got - expected)
        .abs()
        .cmple(0.03 * expected + Vec3::splat(1e-6))
        .all()
}

#[test]
fn a_face_attribute_is_constant_over_its_face() {
    let film = render(
        "mesh_attribute_face",
        r#"type = "diffuse"
reflectance = { type = "mesh_attribute", name = "face_color" }"#,
    );
    for (i, j) in interior() {
        let expected = Vec3::from(FACE[usize::from(i >= 8)]);
        let got = film.pixel(i, j);
        assert!(
            close(got, expected),
            "pixel ({i}, {j}): {got} where the face colour is {expected}"
        );
    }
}

#[test]
fn a_vertex_attribute_is_interpolated_across_the_triangles() {
    let film = render(
        "mesh_attribute_vertex",
        r#"type = "diffuse"
reflectance = { type = "mesh_attribute", name = "vertex_color", scale = 0.5 }"#,
    );
    for (i, j) in interior() {
        let (x, y) = pixel_centre(i, j);
        let expected = 0.5 * vertex_colour(x, y);
        let got = film.pixel(i, j);
        assert!(
            close(got, expected),
            "pixel ({i}, {j}) at ({x}, {y}): {got}, expected {expected}"
        );
    }
}

#[test]
fn a_face_weight_chooses_a_blends_component() {
    let film = render(
        "mesh_attribute_weight",
        r#"type = "blend"
weight = { type = "mesh_attribute", name = "face_weight" }
materials = [
    { type = "diffuse", reflectance = [0.0, 0.5, 0.5] },
    { type = "diffuse", reflectance = [1.0, 1.0, 0.0] },
]"#,
    );
    for (i, j) in interior() {
        let expected = if i < 8 {
            Vec3::new(0.0, 0.5, 0.5)
        } else {
            Vec3::new(1.0, 1.0, 0.0)
        };
        let got = film.pixel(i, j);
        assert!(
            close(got, expected),
            "pixel ({i}, {j}): {got}, expected {expected}"
        );
    }
}

#[test]
fn an_attribute_the_mesh_lacks_is_an_error_naming_those_it_has() {
    let dir = temp_dir("mesh_attribute_missing");
    write(&dir, "quads.ply", &ply());
    let cases = [
        (
            r#"type = "diffuse"
reflectance = { type = "mesh_attribute", name = "vertex_weight" }"#,
            "vertex_weight",
            "it has vertex_color, face_color, face_weight",
        ),
        (
            r#"type = "diffuse"
reflectance = { type = "mesh_attribute", name = "colour" }"#,
            "reflectance",
            "starts with `vertex_` or `face_`",
        ),
    ];
    for (material, key, message) in cases {
        let path = write(&dir, "scene.toml", &scene(material));
        let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
        assert_ne!(run.code, 0, "{material}: accepted");
        assert!(
            run.stderr.contains(key) && run.stderr.contains(message),
            "{material}: {}",
            run.stderr
        );
        assert!(run.stderr.contains("scene.toml:"), "{}", run.stderr);
    }
    // As emitted radiance, which the area light does not look up.
    let emitting = scene(r#"type = "diffuse""#).replace(
        "material = \"m\"\n",
        "material = \"m\"\nemission = { type = \"mesh_attribute\", name = \"face_color\" }\n",
    );
    let path = write(&dir, "scene.toml", &emitting);
    let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
    assert_ne!(run.code, 0);
    assert!(
        run.stderr.contains("emission") && run.stderr.contains("not supported yet"),
        "{}",
        run.stderr
    );
    // Nor a volume texture, or either as the cut-out of an emitting shape.
    for (key, table) in [
        (
            "emission",
            "{ type = \"volume\", volume = { resolution = [1, 1, 1], values = [1] } }",
        ),
        (
            "alpha",
            "{ type = \"mesh_attribute\", name = \"face_weight\" }",
        ),
    ] {
        let extra = if key == "alpha" {
            format!("emission = [1, 1, 1]\nalpha = {table}\n")
        } else {
            format!("emission = {table}\n")
        };
        let text = scene(r#"type = "diffuse""#)
            .replace("material = \"m\"\n", &format!("material = \"m\"\n{extra}"));
        let path = write(&dir, "scene.toml", &text);
        let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
        assert_ne!(run.code, 0, "{key}: accepted");
        assert!(
            run.stderr.contains(key) && run.stderr.contains("not supported yet"),
            "{key}: {}",
            run.stderr
        );
    }
    // On a shape that is not a mesh.
    let sphere = scene(
        r#"type = "diffuse"
reflectance = { type = "mesh_attribute", name = "vertex_color" }"#,
    )
    .replace(
        "type = \"mesh\"\nfile = \"quads.ply\"",
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1",
    );
    let path = write(&dir, "scene.toml", &sphere);
    let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
    assert_ne!(run.code, 0);
    assert!(run.stderr.contains("only a mesh carries"), "{}", run.stderr);
}
