//! PLY meshes: the three encodings load to exactly the triangles of the same mesh in OBJ (so
//! they render the same image, bit for bit), with the properties and elements foton does not
//! use read past; and every malformed file is a clear error naming the PLY file and the scene
//! key, never a panic.

use foton_core::geometry::Shape;
use foton_core::scene::Scene;
use foton_tests::{Run, foton_with_plugins, header, render_toml, temp_dir, write};
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------------------------------------
// Writing PLY files
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Copy, PartialEq)]
enum Enc {
    Ascii,
    Little,
    Big,
}

const ENCODINGS: [Enc; 3] = [Enc::Ascii, Enc::Little, Enc::Big];

impl Enc {
    fn name(self) -> &'static str {
        match self {
            Enc::Ascii => "ascii",
            Enc::Little => "binary_little_endian",
            Enc::Big => "binary_big_endian",
        }
    }
}

/// One value of a record, of the type its header line declares.
#[derive(Clone, Debug)]
enum Val {
    F32(f32),
    F64(f64),
    U8(u8),
    I32(i32),
    U32(u32),
    /// A list: its count (as the header's count type) and items.
    List(Box<Val>, Vec<Val>),
}

impl Val {
    fn put(&self, enc: Enc, out: &mut Vec<u8>) {
        macro_rules! bytes {
            ($v:expr) => {
                match enc {
                    Enc::Little => out.extend_from_slice(&$v.to_le_bytes()),
                    Enc::Big => out.extend_from_slice(&$v.to_be_bytes()),
                    Enc::Ascii => out.extend_from_slice(format!("{} ", $v).as_bytes()),
                }
            };
        }
        match self {
            Val::F32(v) => bytes!(v),
            Val::F64(v) => bytes!(v),
            Val::U8(v) => bytes!(v),
            Val::I32(v) => bytes!(v),
            Val::U32(v) => bytes!(v),
            Val::List(count, items) => {
                count.put(enc, out);
                for item in items {
                    item.put(enc, out);
                }
            }
        }
    }
}

/// An element: its name, its `property ...` header lines, its records.
struct Element {
    name: &'static str,
    properties: Vec<&'static str>,
    records: Vec<Vec<Val>>,
}

/// A PLY file's bytes. `count` overrides the header's element counts (to declare more records
/// than there are).
fn ply(enc: Enc, elements: &[Element], count: &dyn Fn(&str, usize) -> usize) -> Vec<u8> {
    let mut text = format!(
        "ply\nformat {} 1.0\ncomment written by the ply test\n",
        enc.name()
    );
    for e in elements {
        text += &format!("element {} {}\n", e.name, count(e.name, e.records.len()));
        for p in &e.properties {
            text += &format!("property {p}\n");
        }
    }
    text += "end_header\n";
    let mut out = text.into_bytes();
    for e in elements {
        for record in &e.records {
            for v in record {
                v.put(enc, &mut out);
            }
            if enc == Enc::Ascii {
                out.push(b'\n');
            }
        }
    }
    out
}

fn real_counts(_: &str, n: usize) -> usize {
    n
}

/// The unit cube's corners.
const CORNERS: [[f32; 3]; 8] = [
    [0., 0., 0.],
    [1., 0., 0.],
    [1., 1., 0.],
    [0., 1., 0.],
    [0., 0., 1.],
    [1., 0., 1.],
    [1., 1., 1.],
    [0., 1., 1.],
];

/// Its faces, counter-clockwise seen from outside.
const QUADS: [[u32; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [3, 7, 6, 2],
    [0, 4, 7, 3],
    [1, 2, 6, 5],
];

fn cube_obj(quads: &[[u32; 4]]) -> String {
    let mut obj = String::new();
    for c in CORNERS {
        obj += &format!("v {} {} {}\n", c[0], c[1], c[2]);
    }
    for q in quads {
        obj += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    obj
}

/// The vertex element of the cube with `positions`, among normals, uv and colour properties
/// (and x stored as a double, the others as floats).
fn vertex_element(positions: &[[f32; 3]]) -> Element {
    Element {
        name: "vertex",
        properties: vec![
            "float nx",
            "double x",
            "float y",
            "float ny",
            "float z",
            "float nz",
            "float u",
            "float v",
            "uchar red",
            "uchar green",
            "uchar blue",
        ],
        records: positions
            .iter()
            .map(|p| {
                vec![
                    Val::F32(0.5),
                    Val::F64(p[0] as f64),
                    Val::F32(p[1]),
                    Val::F32(-0.5),
                    Val::F32(p[2]),
                    Val::F32(0.25),
                    Val::F32(p[0]),
                    Val::F32(p[1]),
                    Val::U8(200),
                    Val::U8(10),
                    Val::U8(255),
                ]
            })
            .collect(),
    }
}

/// A face element with `faces` as `list uchar int vertex_indices`, between a flags byte and a
/// texture-coordinate list.
fn face_element(faces: &[Vec<i32>]) -> Element {
    Element {
        name: "face",
        properties: vec![
            "uchar flags",
            "list uchar int vertex_indices",
            "list uchar float texcoord",
        ],
        records: faces
            .iter()
            .map(|f| {
                vec![
                    Val::U8(7),
                    Val::List(
                        Box::new(Val::U8(f.len() as u8)),
                        f.iter().map(|&i| Val::I32(i)).collect(),
                    ),
                    Val::List(Box::new(Val::U8(2)), vec![Val::F32(0.125), Val::F32(0.75)]),
                ]
            })
            .collect(),
    }
}

/// Elements foton skips: materials (with a list) before the faces, edges after them.
fn materials() -> Element {
    Element {
        name: "material",
        properties: vec!["uchar ambient_red", "list uint uint ids", "float power"],
        records: vec![
            vec![
                Val::U8(1),
                Val::List(Box::new(Val::U32(3)), vec![Val::U32(9); 3]),
                Val::F32(2.0),
            ],
            vec![
                Val::U8(2),
                Val::List(Box::new(Val::U32(0)), vec![]),
                Val::F32(1.0),
            ],
        ],
    }
}

fn edges() -> Element {
    Element {
        name: "edge",
        properties: vec!["int vertex1", "int vertex2"],
        records: (0..4).map(|i| vec![Val::I32(i), Val::I32(i + 1)]).collect(),
    }
}

fn cube_faces(quads: &[[u32; 4]]) -> Vec<Vec<i32>> {
    quads
        .iter()
        .map(|q| q.iter().map(|&i| i as i32).collect())
        .collect()
}

/// The cube as a PLY file, with the extra properties and elements.
fn cube_ply(enc: Enc, quads: &[[u32; 4]]) -> Vec<u8> {
    let elements = [
        vertex_element(&CORNERS),
        materials(),
        face_element(&cube_faces(quads)),
        edges(),
    ];
    ply(enc, &elements, &real_counts)
}

// ---------------------------------------------------------------------------------------------
// Scenes
// ---------------------------------------------------------------------------------------------

/// A 16x12 scene looking at the mesh `file` (transformed, so that the shared transform code
/// runs), lit by a point light; `extra` goes into the shape.
fn scene_text(file: &Path, extra: &str) -> String {
    header("path", 4, 3, 16, 12)
        + &format!(
            r#"
[camera]
position = [2.5, 2, 4]
look_at = [0, 0.3, 0]
up = [0, 1, 0]
fov = 40

[materials.white]
type = "diffuse"
reflectance = [0.7, 0.6, 0.5]

[media.fog]
type = "homogeneous"
sigma_a = [0.1, 0.1, 0.1]
sigma_s = [0.5, 0.5, 0.5]

[[shapes]]
type = "quad"
origin = [-5, -0.5, -5]
u = [0, 0, 10]
v = [10, 0, 0]
material = "white"

[[shapes]]
type = "mesh"
file = "{}"
transform = {{ translate = [-0.4, -0.5, 0.1], scale = [1.2, 0.9, 1.1], rotate = {{ axis = [0, 1, 0], degrees = 30 }} }}
material = "white"{extra}

[[lights]]
type = "point"
position = [1, 3, 2]
intensity = [5, 5, 5]
"#,
            file.display()
        )
}

fn load(dir: &Path, file: &Path, extra: &str) -> Scene {
    let scene = write(dir, "scene.toml", &scene_text(file, extra));
    foton_loader::load(&scene, &[]).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
}

/// The mesh's triangles, as bits, in BVH order (the same for the same input).
fn mesh_triangles(scene: &Scene) -> Vec<[u32; 9]> {
    scene
        .accel()
        .primitives()
        .iter()
        .filter(|p| p.object == 1)
        .map(|p| match p.shape {
            Shape::Triangle { p0, e1, e2 } => {
                let f = [p0, e1, e2].map(|v| v.to_array()).concat();
                std::array::from_fn(|i| f[i].to_bits())
            }
            other => panic!("a mesh gave {other:?}"),
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Loading
// ---------------------------------------------------------------------------------------------

#[test]
fn ply_cube_loads_like_the_obj_cube() {
    let dir = temp_dir("ply-cube");
    let obj = write(&dir, "cube.obj", &cube_obj(&QUADS));
    // Filled with fog: closedness is asked only of shapes that may bound a medium.
    let fog = "\ninterior = \"fog\"";
    let reference = load(&dir, &obj, fog);
    let want = mesh_triangles(&reference);
    assert_eq!(want.len(), 12, "the OBJ cube has 12 triangles");
    assert!(reference.objects()[1].closed);
    for enc in ENCODINGS {
        let ply = dir.join(format!("cube-{}.ply", enc.name()));
        std::fs::write(&ply, cube_ply(enc, &QUADS)).unwrap();
        let scene = load(&dir, &ply, fog);
        assert_eq!(
            mesh_triangles(&scene),
            want,
            "{}: not the OBJ's triangles",
            enc.name()
        );
        assert!(scene.objects()[1].closed, "{}: not closed", enc.name());
    }
}

#[test]
fn crlf_header_and_uppercase_extension() {
    let dir = temp_dir("ply-crlf");
    let obj = write(&dir, "cube.obj", &cube_obj(&QUADS));
    let want = mesh_triangles(&load(&dir, &obj, ""));
    let bytes = cube_ply(Enc::Little, &QUADS);
    let end = b"end_header\n";
    let at = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
    let header = String::from_utf8(bytes[..at].to_vec()).unwrap();
    let mut crlf = header.replace('\n', "\r\n").into_bytes();
    crlf.extend_from_slice(&bytes[at..]);
    let ply = dir.join("CUBE.PLY");
    std::fs::write(&ply, crlf).unwrap();
    assert_eq!(mesh_triangles(&load(&dir, &ply, "")), want);
}

#[test]
fn polygons_are_fan_triangulated() {
    let dir = temp_dir("ply-fan");
    // A pentagon in the plane z = 0: fans (0 1 2) (0 2 3) (0 3 4).
    let pentagon = [
        [0., 0., 0.],
        [2., 0., 0.],
        [3., 1., 0.],
        [1., 2., 0.],
        [-1., 1., 0.],
    ];
    for enc in ENCODINGS {
        let elements = [
            vertex_element(&pentagon),
            face_element(&[vec![0, 1, 2, 3, 4]]),
        ];
        let ply = dir.join(format!("pentagon-{}.ply", enc.name()));
        std::fs::write(&ply, ply_bytes(enc, &elements)).unwrap();
        // With a medium named, so that its closedness is found out.
        let scene = write(
            &dir,
            "scene.toml",
            &scene_text(&ply, "\nexterior = \"fog\""),
        );
        let scene = foton_loader::load(&scene, &[]).unwrap();
        let mut corners: Vec<[[f32; 3]; 3]> = Vec::new();
        for p in scene.accel().primitives().iter().filter(|p| p.object == 1) {
            let Shape::Triangle { p0, e1, e2 } = p.shape else {
                panic!("not a triangle")
            };
            corners.push([p0, p0 + e1, p0 + e2].map(|v| v.to_array()));
        }
        assert_eq!(corners.len(), 3, "{}", enc.name());
        assert!(!scene.objects()[1].closed);
        // Through the transform the corners are not exact: compare the fans' first corners
        // and the areas, which identify the triangles.
        let transform = |p: [f32; 3]| {
            let m = glam::Mat4::from_translation(glam::Vec3::new(-0.4, -0.5, 0.1))
                * glam::Mat4::from_axis_angle(glam::Vec3::Y, 30f32.to_radians())
                * glam::Mat4::from_scale(glam::Vec3::new(1.2, 0.9, 1.1));
            m.transform_point3(glam::Vec3::from(p))
        };
        let mut want: Vec<[glam::Vec3; 3]> = [[0, 1, 2], [0, 2, 3], [0, 3, 4]]
            .iter()
            .map(|t| t.map(|i| transform(pentagon[i])))
            .collect();
        let mut got: Vec<[glam::Vec3; 3]> =
            corners.iter().map(|c| c.map(glam::Vec3::from)).collect();
        let key = |t: &[glam::Vec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]).length();
        want.sort_by(|a, b| key(a).total_cmp(&key(b)));
        got.sort_by(|a, b| key(a).total_cmp(&key(b)));
        for (g, w) in got.iter().zip(&want) {
            for (a, b) in g.iter().zip(w) {
                assert!(
                    a.distance(*b) < 1e-5,
                    "{}: got {got:?}, want {want:?}",
                    enc.name()
                );
            }
        }
    }
}

fn ply_bytes(enc: Enc, elements: &[Element]) -> Vec<u8> {
    ply(enc, elements, &real_counts)
}

#[test]
fn interior_medium_needs_a_closed_ply_mesh() {
    let dir = temp_dir("ply-interior");
    let cube = dir.join("cube.ply");
    std::fs::write(&cube, cube_ply(Enc::Little, &QUADS)).unwrap();
    let scene = load(&dir, &cube, "\ninterior = \"fog\"");
    assert_eq!(scene.objects()[1].interior, Some(0));

    // Without its top the box is open: refused.
    let open = dir.join("open.ply");
    std::fs::write(&open, cube_ply(Enc::Little, &QUADS[..5])).unwrap();
    let path = write(
        &dir,
        "open.toml",
        &scene_text(&open, "\ninterior = \"fog\""),
    );
    let run = foton_with_plugins(&["check", path.to_str().unwrap()]);
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert!(run.stderr.contains("not closed"), "{}", run.stderr);
}

#[test]
fn ply_cube_renders_like_the_obj_cube() {
    let dir = temp_dir("ply-render");
    let obj = write(&dir, "cube.obj", &cube_obj(&QUADS));
    // Face normals: the two readers' triangles must be the same bit for bit (smooth normals
    // sum the faces around a vertex in the order the file lists them).
    let flat = "\nface_normals = true";
    let reference = render_toml("ply-render-obj", &scene_text(&obj, flat), &[], 2);
    let bits = |film: &foton_core::film::Film| -> Vec<[u32; 3]> {
        film.pixels()
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect()
    };
    let want = bits(&reference);
    assert!(
        reference.pixels().iter().any(|p| p.max_element() > 0.0),
        "the reference is black: the test would prove nothing"
    );
    for enc in ENCODINGS {
        let ply = dir.join(format!("cube-{}.ply", enc.name()));
        std::fs::write(&ply, cube_ply(enc, &QUADS)).unwrap();
        let film = render_toml("ply-render-ply", &scene_text(&ply, flat), &[], 2);
        assert!(bits(&film) == want, "{}: the image differs", enc.name());
    }
}

// ---------------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------------

/// `foton check` on a scene whose mesh is `name` holding `bytes`: exit code 1, and an error
/// naming the scene file, the key `shapes[1].file`, the mesh file and each of `words`.
fn assert_mesh_error(case: &str, name: &str, bytes: &[u8], words: &[&str]) {
    let dir = temp_dir(&format!("ply-error-{case}"));
    let mesh: PathBuf = dir.join(name);
    std::fs::write(&mesh, bytes).unwrap();
    let scene = write(&dir, "scene.toml", &scene_text(&mesh, ""));
    let run: Run = foton_with_plugins(&["check", scene.to_str().unwrap()]);
    let show = format!(
        "{case}: exit code {}\n--- stderr ---\n{}",
        run.code, run.stderr
    );
    assert_eq!(run.code, 1, "{show}");
    assert!(run.stderr.starts_with("error: "), "{show}");
    assert!(!run.stderr.contains("panicked"), "{show}");
    let scene_at = format!("{}:", scene.display());
    let mesh_name = mesh.display().to_string();
    for needle in [scene_at.as_str(), "`shapes[1].file`", mesh_name.as_str()]
        .iter()
        .chain(words)
    {
        assert!(run.stderr.contains(needle), "{show}\nmissing {needle:?}");
    }
}

/// The cube's PLY header and ascii data, text-edited.
fn ascii_cube_with(from: &str, to: &str) -> Vec<u8> {
    let text = String::from_utf8(cube_ply(Enc::Ascii, &QUADS)).unwrap();
    assert_eq!(text.matches(from).count(), 1, "test bug: {from:?}");
    text.replace(from, to).into_bytes()
}

#[test]
fn bad_headers() {
    let cases: [(&str, Vec<u8>, &[&str]); 8] = [
        ("not-ply", b"solid cube\n".to_vec(), &["not a PLY file"]),
        (
            "no-end",
            b"ply\nformat ascii 1.0\nelement vertex 3\n".to_vec(),
            &["no `end_header`"],
        ),
        (
            "no-format",
            b"ply\nelement vertex 0\nend_header\n".to_vec(),
            &["no `format` line"],
        ),
        (
            "format",
            ascii_cube_with("format ascii 1.0", "format binary_middle_endian 1.0"),
            &["unknown format", "binary_middle_endian"],
        ),
        (
            "version",
            ascii_cube_with("format ascii 1.0", "format ascii 2.0"),
            &["unsupported version"],
        ),
        (
            "type",
            ascii_cube_with("property float y", "property float128 y"),
            &["unknown type \"float128\""],
        ),
        (
            "count",
            ascii_cube_with("element edge 4", "element edge many"),
            &["element count"],
        ),
        (
            "keyword",
            ascii_cube_with("comment written", "commment written"),
            &["line 3", "expected format, element, property"],
        ),
    ];
    for (case, bytes, words) in cases {
        assert_mesh_error(case, "mesh.ply", &bytes, words);
    }
}

#[test]
fn missing_coordinates_and_faces() {
    assert_mesh_error(
        "no-z",
        "mesh.ply",
        &ascii_cube_with("property float z\n", "property float w\n"),
        &["no `z` property"],
    );
    assert_mesh_error(
        "list-x",
        "mesh.ply",
        &ascii_cube_with("property double x\n", "property list uchar double x\n"),
        &["`x` is a list"],
    );
    assert_mesh_error(
        "no-vertex",
        "mesh.ply",
        &ascii_cube_with("element vertex 8", "element vertices 8"),
        &["no `vertex` element"],
    );
    assert_mesh_error(
        "no-indices",
        "mesh.ply",
        &ascii_cube_with("vertex_indices", "corners"),
        &["no `vertex_indices`"],
    );
    // The other name some writers use.
    let dir = temp_dir("ply-vertex-index");
    let ply = dir.join("cube.ply");
    std::fs::write(&ply, ascii_cube_with("vertex_indices", "vertex_index")).unwrap();
    assert_eq!(mesh_triangles(&load(&dir, &ply, "")).len(), 12);
}

#[test]
fn unknown_extension() {
    assert_mesh_error(
        "extension",
        "cube.stl",
        &cube_ply(Enc::Ascii, &QUADS),
        &["unknown mesh format", ".obj or .ply"],
    );
}

#[test]
fn index_out_of_range() {
    for enc in ENCODINGS {
        let mut faces = cube_faces(&QUADS);
        faces[2][1] = 8;
        let elements = [vertex_element(&CORNERS), face_element(&faces)];
        assert_mesh_error(
            "range",
            "range.ply",
            &ply_bytes(enc, &elements),
            &["face index 8 out of range (8 vertices)"],
        );
        faces[2][1] = -1;
        let elements = [vertex_element(&CORNERS), face_element(&faces)];
        assert_mesh_error(
            "negative",
            "negative.ply",
            &ply_bytes(enc, &elements),
            &["face 2 has the vertex index -1", "out of range"],
        );
    }
}

#[test]
fn face_with_two_indices() {
    for enc in ENCODINGS {
        let mut faces = cube_faces(&QUADS);
        faces[4] = vec![0, 1];
        let elements = [vertex_element(&CORNERS), face_element(&faces)];
        assert_mesh_error(
            "two",
            "two.ply",
            &ply_bytes(enc, &elements),
            &["face 4 has 2 vertex indices", "at least 3"],
        );
    }
}

#[test]
fn non_finite_vertex() {
    for enc in ENCODINGS {
        let mut corners = CORNERS;
        corners[6][1] = f32::NAN;
        let elements = [vertex_element(&corners), face_element(&cube_faces(&QUADS))];
        assert_mesh_error(
            "nan",
            "nan.ply",
            &ply_bytes(enc, &elements),
            &["non-finite vertex"],
        );
    }
}

#[test]
fn truncated_files() {
    for enc in ENCODINGS {
        let elements = [
            vertex_element(&CORNERS),
            materials(),
            face_element(&cube_faces(&QUADS)),
            edges(),
        ];
        // More vertices declared than written, then no faces: the data ends in the vertices.
        let more = |name: &str, n: usize| if name == "vertex" { n + 40 } else { n };
        let bytes = ply(enc, &[vertex_element(&CORNERS), face_element(&[])], &more);
        assert_mesh_error(
            "vertices",
            "short.ply",
            &bytes,
            &["truncated", "expected 48 vertices, read 8"],
        );
        let bytes = ply(enc, &elements[..3], &|name, n| {
            if name == "face" { n + 3 } else { n }
        });
        assert_mesh_error(
            "faces",
            "short.ply",
            &bytes,
            &["truncated", "expected 9 faces, read 6"],
        );
        // A file cut in the middle of the skipped edge element.
        let full = ply(enc, &elements, &real_counts);
        let cut = &full[..full.len() - 6];
        assert_mesh_error(
            "edges",
            "short.ply",
            cut,
            &["truncated", "expected 4 `edge` elements, read 3"],
        );
    }
}
