//! Mitsuba's shapes as Mitsuba reads them (issue 32): `serialized` meshes (`shape_index`,
//! `to_world`, `flip_normals`, the file's normals and texture coordinates), every parameter
//! of `sphere` and `cylinder`, `shapegroup` with `instance`, `merge`, meshes with zero-area triangles,
//! and what a `<ref>` or a nested object inside a shape names. Checked on the loaded scene by
//! tracing rays at it.

use foton_core::geometry::Ray;
use foton_core::scene::Scene;
use foton_tests::{temp_dir, write};
use glam::{Mat3, Vec2, Vec3};
use std::path::Path;

/// A zlib stream of `data` in stored (uncompressed) deflate blocks: an encoder independent of
/// the reader's inflater (RFC 1950 and 1951).
fn zlib_stored(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0x78, 0x01];
    let chunks: Vec<&[u8]> = if data.is_empty() {
        vec![&[]]
    } else {
        data.chunks(65535).collect()
    };
    for (i, c) in chunks.iter().enumerate() {
        out.push(u8::from(i + 1 == chunks.len()));
        let len = c.len() as u16;
        out.extend(len.to_le_bytes());
        out.extend((!len).to_le_bytes());
        out.extend(*c);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &x in data {
        a = (a + x as u32) % 65521;
        b = (b + a) % 65521;
    }
    out.extend((b << 16 | a).to_be_bytes());
    out
}

/// One mesh of a serialized file: positions, optional normals and texture coordinates.
struct Mesh {
    positions: Vec<[f64; 3]>,
    normals: Option<Vec<[f64; 3]>>,
    uvs: Option<Vec<[f64; 2]>>,
    triangles: Vec<[u32; 3]>,
}

/// A Mitsuba serialized file (version 3 or 4, f32 or f64) holding `meshes`.
fn serialized(meshes: &[Mesh], version: u16, double: bool) -> Vec<u8> {
    let mut file = Vec::new();
    let mut offsets = Vec::new();
    for m in meshes {
        offsets.push(file.len() as u64);
        file.extend(0x041Cu16.to_le_bytes());
        file.extend(version.to_le_bytes());
        let mut s = Vec::new();
        let precision = if double { 0x2000u32 } else { 0x1000 };
        let flags = precision | u32::from(m.normals.is_some()) | (u32::from(m.uvs.is_some()) << 1);
        s.extend(flags.to_le_bytes());
        if version == 4 {
            s.extend(b"name\0");
        }
        s.extend((m.positions.len() as u64).to_le_bytes());
        s.extend((m.triangles.len() as u64).to_le_bytes());
        let mut put = |xs: &[f64]| {
            for &x in xs {
                if double {
                    s.extend(x.to_le_bytes());
                } else {
                    s.extend((x as f32).to_le_bytes());
                }
            }
        };
        put(m.positions.as_flattened());
        if let Some(n) = &m.normals {
            put(n.as_flattened());
        }
        if let Some(t) = &m.uvs {
            put(t.as_flattened());
        }
        for i in m.triangles.as_flattened() {
            s.extend(i.to_le_bytes());
        }
        file.extend(zlib_stored(&s));
    }
    for o in offsets {
        if version == 4 {
            file.extend(o.to_le_bytes());
        } else {
            file.extend((o as u32).to_le_bytes());
        }
    }
    file.extend((meshes.len() as u32).to_le_bytes());
    file
}

/// The unit square at height z (two triangles), facing +z by its winding.
fn square(z: f64, normal: Option<[f64; 3]>, uvs: bool) -> Mesh {
    Mesh {
        positions: vec![[0., 0., z], [1., 0., z], [1., 1., z], [0., 1., z]],
        normals: normal.map(|n| vec![n; 4]),
        uvs: uvs.then(|| vec![[0., 0.], [1., 0.], [1., 1.], [0., 1.]]),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

const SENSOR: &str = r#"<sensor type="perspective"><transform name="to_world"><lookat origin="0, 0, 20" target="0, 0, 0" up="0, 1, 0"/></transform></sensor>"#;

/// The XML scene made of `body` (and a sensor) in `dir`.
fn xml(dir: &Path, body: &str) -> std::path::PathBuf {
    write(
        dir,
        "scene.xml",
        &format!("<scene version=\"3.0.0\">\n{SENSOR}\n{body}\n</scene>\n"),
    )
}

fn load(path: &Path) -> Scene {
    foton_loader::load(path, &[]).unwrap_or_else(|e| panic!("{e}"))
}

fn load_err(path: &Path, lenient: bool) -> String {
    match foton_loader::load_with(path, &[], &[], lenient) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e) => e.to_string(),
    }
}

/// Where a ray from `origin` along `dir` first hits, with the geometric and shading normals
/// and texture coordinates there.
fn trace(scene: &Scene, origin: Vec3, dir: Vec3) -> Option<(f32, Vec3, Vec3, Vec2)> {
    let hit = scene.intersect(&Ray::new(origin, dir.normalize()), f32::INFINITY)?;
    let s = scene.surface(&hit);
    Some((hit.t, s.ng, s.ns, s.uv))
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).length() <= tol
}

#[test]
fn serialized_meshes_are_placed_by_shape_index_and_to_world_with_their_normals() {
    let tilted = [0.0, 0.6, 0.8];
    let meshes = [
        square(0.0, None, false),
        square(0.0, Some(tilted), true),
        square(5.0, None, true),
    ];
    for (version, double) in [(3, false), (4, true), (4, false)] {
        let dir = temp_dir("serialized");
        std::fs::write(
            dir.join("m.serialized"),
            serialized(&meshes, version, double),
        )
        .unwrap();
        // Mitsuba reads the file whatever its name.
        std::fs::write(dir.join("m.bin"), serialized(&meshes, version, double)).unwrap();
        let path = xml(
            &dir,
            r#"<shape type="serialized"><string name="filename" value="m.serialized"/>
    <transform name="to_world"><translate x="10"/></transform></shape>
<shape type="serialized"><string name="filename" value="m.serialized"/><integer name="shape_index" value="1"/>
    <transform name="to_world"><translate z="1"/></transform></shape>
<shape type="serialized"><string name="filename" value="m.bin"/><integer name="shape_index" value="1"/>
    <boolean name="flip_normals" value="true"/>
    <transform name="to_world"><translate x="-10"/></transform></shape>
<shape type="serialized"><string name="filename" value="m.serialized"/><integer name="shape_index" value="2"/>
    <boolean name="face_normals" value="true"/>
    <transform name="to_world"><translate x="20" z="-5"/></transform></shape>"#,
        );
        let scene = load(&path);
        let down = -Vec3::Z;
        // Mesh 0, moved to x = 10: no normals in the file, flat.
        let (t, ng, ns, _) = trace(&scene, Vec3::new(10.5, 0.5, 3.0), down).unwrap();
        assert!((t - 3.0).abs() < 1e-4 && close(ng, Vec3::Z, 1e-5) && close(ns, Vec3::Z, 1e-5));
        // Mesh 1 at z = 1: its own normals and texture coordinates (v not flipped).
        let (t, ng, ns, uv) = trace(&scene, Vec3::new(0.25, 0.75, 3.0), down).unwrap();
        assert!((t - 2.0).abs() < 1e-4, "t = {t}");
        assert!(close(ng, Vec3::Z, 1e-5), "{ng}");
        assert!(close(ns, Vec3::new(0.0, 0.6, 0.8), 1e-5), "{ns}");
        assert!((uv - Vec2::new(0.25, 0.75)).length() < 1e-5, "{uv}");
        // Mesh 1 again, turned inside out.
        let (_, ng, ns, _) = trace(&scene, Vec3::new(-9.75, 0.75, 3.0), down).unwrap();
        assert!(close(ng, -Vec3::Z, 1e-5) && close(ns, Vec3::new(0.0, -0.6, -0.8), 1e-5));
        // Mesh 2 (at z = 5 in the file), moved down to z = 0.
        let (t, _, _, _) = trace(&scene, Vec3::new(20.5, 0.5, 3.0), down).unwrap();
        assert!((t - 3.0).abs() < 1e-4);
        assert!(trace(&scene, Vec3::new(30.0, 0.5, 3.0), down).is_none());
    }
}

#[test]
fn a_bad_serialized_file_is_an_error_with_its_name_and_the_shapes_line() {
    let dir = temp_dir("serialized-bad");
    let file = serialized(&[square(0.0, None, false)], 4, false);
    std::fs::write(dir.join("m.serialized"), &file).unwrap();
    std::fs::write(dir.join("cut.serialized"), &file[..file.len() / 2]).unwrap();
    let shape = |name: &str, index: i64| {
        format!(
            r#"<shape type="serialized"><string name="filename" value="{name}"/><integer name="shape_index" value="{index}"/></shape>"#
        )
    };
    let cases = [
        (
            shape("m.serialized", 3),
            "shape_index 3 is out of range: the file holds 1 mesh",
        ),
        (shape("cut.serialized", 0), "cut.serialized: mesh 0: "),
        (shape("m.serialized", -1), "`shape_index` = -1"),
        (shape("none.serialized", 0), "none.serialized"),
    ];
    for (body, expected) in cases {
        let e = load_err(&xml(&dir, &body), false);
        assert!(e.contains(expected), "{e}");
        // The shape is on the file's third line.
        assert!(e.contains("scene.xml:3"), "{e}");
    }
}

#[test]
fn sphere_center_radius_and_to_world_compose_as_in_mitsuba_3() {
    let dir = temp_dir("sphere");
    let path = xml(
        &dir,
        r#"<shape type="sphere"><point name="center" value="4, 0, 0"/><float name="radius" value="2"/>
    <transform name="to_world"><scale value="0.5"/><translate y="1"/></transform></shape>
<shape type="sphere"><transform name="to_world"><scale x="-1"/><translate x="-5"/></transform></shape>
<shape type="sphere"><transform name="to_world"><scale x="1" y="3" z="1"/><translate x="5" y="-5"/></transform></shape>"#,
    );
    let scene = load(&path);
    let down = -Vec3::Z;
    // Center (2, 1, 0), radius 1: hit at z = 1 from above.
    let (t, ng, _, _) = trace(&scene, Vec3::new(2.0, 1.0, 5.0), down).unwrap();
    assert!(
        (t - 4.0).abs() < 1e-4 && close(ng, Vec3::Z, 1e-4),
        "{t} {ng}"
    );
    assert!(trace(&scene, Vec3::new(3.1, 1.0, 5.0), down).is_none());
    // A mirroring to_world turns the sphere inside out (Mitsuba 3: a negative scale factor;
    // checked with Mitsuba 3.9.1).
    let (t, ng, _, _) = trace(&scene, Vec3::new(-5.0, 0.0, 5.0), down).unwrap();
    assert!(
        (t - 4.0).abs() < 1e-4 && close(ng, -Vec3::Z, 1e-4),
        "{t} {ng}"
    );
    // A non-uniform scale: the sphere of radius |to_world x| = 1, with a warning.
    assert!(trace(&scene, Vec3::new(5.0, -3.0, 5.0), down).is_none());
    let (t, _, _, _) = trace(&scene, Vec3::new(5.0, -5.0, 5.0), down).unwrap();
    assert!((t - 4.0).abs() < 1e-4);
    assert!(
        scene
            .ignored()
            .iter()
            .any(|w| w.contains("scene.xml:6") && w.contains("non-uniformly")),
        "{:?}",
        scene.ignored()
    );
}

#[test]
fn a_cylinder_is_a_prism_of_mitsubas_area_from_p0_to_p1() {
    let dir = temp_dir("cylinder");
    let path = xml(
        &dir,
        r#"<shape type="cylinder"><point name="p0" value="0, 0, -1"/><point name="p1" value="0, 0, 3"/>
    <float name="radius" value="0.5"/>
    <transform name="to_world"><translate x="1"/></transform>
    <emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>"#,
    );
    let scene = load(&path);
    // One-sided emitter: power = pi L A with A = 2 pi r l = 2 pi 0.5 4.
    let expected = std::f32::consts::PI * 2.0 * (2.0 * std::f32::consts::PI * 0.5 * 4.0);
    let power = scene.total_power();
    assert!(
        (power.x / expected - 1.0).abs() < 1e-3,
        "{power} against {expected}"
    );
    // From the side, along y, the surface is within the facets' sagitta of radius 0.5, with
    // its normal outward; the axis runs along z between -1 and 3 only.
    let (t, ng, _, _) = trace(&scene, Vec3::new(1.0, -5.0, 1.0), Vec3::Y).unwrap();
    assert!((t - 4.5).abs() < 0.01, "t = {t}");
    assert!(ng.dot(-Vec3::Y) > 0.99, "{ng}");
    assert!(trace(&scene, Vec3::new(1.0, -5.0, 3.5), Vec3::Y).is_none());
    assert!(trace(&scene, Vec3::new(1.0, -5.0, -0.5), Vec3::Y).is_some());
    assert!(scene.warnings().iter().any(|w| w.contains("flat facets")));
}

#[test]
fn instances_are_transformed_copies_of_their_shapegroup() {
    let dir = temp_dir("instances");
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    write(&dir, "tri.ply", ply);
    let path = xml(
        &dir,
        r#"<bsdf type="diffuse" id="white"/>
<shape type="shapegroup" id="group">
    <shape type="rectangle"><ref id="white"/><transform name="to_world"><translate y="3"/></transform></shape>
    <shape type="sphere"><float name="radius" value="0.5"/></shape>
    <shape type="ply"><string name="filename" value="tri.ply"/>
        <transform name="to_world"><translate y="-3"/></transform></shape>
</shape>
<shape type="merge">
    <shape type="instance"><ref id="group"/><transform name="to_world"><translate x="10"/></transform></shape>
</shape>
<shape type="instance"><ref id="group"/><transform name="to_world"><scale x="-2" y="2" z="2"/><translate x="-10"/></transform></shape>"#,
    );
    let scene = load(&path);
    let down = -Vec3::Z;
    // The group alone renders nothing.
    assert!(trace(&scene, Vec3::new(0.0, 0.0, 5.0), down).is_none());
    // First instance: the rectangle [-1, 1]^2 around (10, 3), the sphere at (10, 0), the
    // triangle's corner at (10, -3).
    let (t, ng, _, _) = trace(&scene, Vec3::new(10.9, 3.9, 5.0), down).unwrap();
    assert!((t - 5.0).abs() < 1e-4 && close(ng, Vec3::Z, 1e-5));
    let (t, _, _, _) = trace(&scene, Vec3::new(10.0, 0.0, 5.0), down).unwrap();
    assert!((t - 4.5).abs() < 1e-4);
    let (t, ng, _, _) = trace(&scene, Vec3::new(10.2, -2.8, 5.0), down).unwrap();
    assert!((t - 5.0).abs() < 1e-4 && close(ng, Vec3::Z, 1e-5), "{ng}");
    assert!(trace(&scene, Vec3::new(9.8, -2.8, 5.0), down).is_none());
    // Second: twice as large and mirrored in x about x = -10. Every shape keeps its normals,
    // transformed as normals (Mitsuba 3's instance; checked with Mitsuba 3.9.1).
    let (t, ng, _, _) = trace(&scene, Vec3::new(-11.9, 7.9, 5.0), down).unwrap();
    assert!((t - 5.0).abs() < 1e-4 && close(ng, Vec3::Z, 1e-5), "{ng}");
    let (t, ng, _, _) = trace(&scene, Vec3::new(-10.0, 0.0, 5.0), down).unwrap();
    assert!(
        (t - 4.0).abs() < 1e-4 && close(ng, Vec3::Z, 1e-4),
        "{t} {ng}"
    );
    let (t, ng, _, _) = trace(&scene, Vec3::new(-10.4, -5.6, 5.0), down).unwrap();
    assert!((t - 5.0).abs() < 1e-4 && close(ng, Vec3::Z, 1e-5), "{ng}");
    assert!(trace(&scene, Vec3::new(-9.6, -5.6, 5.0), down).is_none());
}

#[test]
fn instancing_errors_say_what_is_wrong() {
    let dir = temp_dir("instances-bad");
    let cases = [
        (
            r#"<shape type="instance"><ref id="nothing"/></shape>"#,
            "no shapegroup with id `nothing` before it",
        ),
        (
            r#"<bsdf type="diffuse" id="white"/>
<shape type="instance"><ref id="white"/></shape>"#,
            "(`white` is a BSDF)",
        ),
        (
            r#"<shape type="shapegroup" id="g"><shape type="sphere"><emitter type="area"/></shape></shape>"#,
            "Mitsuba does not instance emitters",
        ),
        (
            r#"<shape type="shapegroup"><shape type="sphere"/></shape>"#,
            "a shapegroup needs an id",
        ),
    ];
    for (body, expected) in cases {
        let e = load_err(&xml(&dir, body), false);
        assert!(e.contains(expected), "{e}");
    }
}

#[test]
fn zero_area_triangles_are_left_out_and_an_all_degenerate_mesh_is_invisible() {
    let dir = temp_dir("degenerate");
    let header = |faces: usize| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n"
        )
    };
    // One real triangle, one with collinear corners, one with a repeated corner.
    write(
        &dir,
        "some.ply",
        &(header(3) + "3 0 1 2\n3 0 1 3\n3 0 0 2\n"),
    );
    write(&dir, "none.ply", &(header(2) + "3 0 1 3\n3 0 0 2\n"));
    let mesh = |file: &str, extra: &str| {
        format!(r#"<shape type="ply"><string name="filename" value="{file}"/>{extra}</shape>"#)
    };
    let scene = load(&xml(&dir, &(mesh("some.ply", "") + &mesh("none.ply", ""))));
    assert!(trace(&scene, Vec3::new(0.2, 0.2, 5.0), -Vec3::Z).is_some());
    assert!(trace(&scene, Vec3::new(1.5, 0.0, 5.0), -Vec3::Z).is_none());
    // As an emitter, a mesh without area cannot be: said with its file.
    let e = load_err(
        &xml(&dir, &mesh("none.ply", r#"<emitter type="area"/>"#)),
        false,
    );
    assert!(
        e.contains("none.ply") && e.contains("no triangle of non-zero area"),
        "{e}"
    );
}

#[test]
fn a_ref_or_object_in_a_shape_is_taken_for_what_it_names() {
    let dir = temp_dir("refs");
    let defs = r#"<bsdf type="diffuse" id="white"/>
<medium type="homogeneous" id="fog"/>
<texture type="checkerboard" id="checks"/>"#;
    // A medium referenced without a side: ignored with a warning, as Mitsuba 3 ignores it.
    let path = xml(
        &dir,
        &format!("{defs}\n<shape type=\"sphere\">\n<ref id=\"white\"/>\n<ref id=\"fog\"/></shape>"),
    );
    let scene = load(&path);
    assert!(
        scene
            .ignored()
            .iter()
            .any(|w| w.contains("scene.xml:8") && w.contains("names a medium")),
        "{:?}",
        scene.ignored()
    );
    // Each error at the line of the <ref>, saying what the id is.
    let cases = [
        (
            "<shape type=\"sphere\">\n<ref name=\"interior\" id=\"white\"/></shape>",
            "scene.xml:7",
            "no medium with id `white` before it (`white` is a BSDF)",
        ),
        (
            "<shape type=\"sphere\">\n<ref id=\"checks\"/></shape>",
            "scene.xml:7",
            "`checks` is a texture; a shape takes a BSDF, an area emitter or a medium",
        ),
        (
            "<shape type=\"sphere\">\n\n<ref id=\"nothing\"/></shape>",
            "scene.xml:8",
            "no BSDF, area emitter or medium with id `nothing` before it",
        ),
        (
            "<shape type=\"sphere\">\n<bsdf type=\"diffuse\"/>\n<ref id=\"white\"/></shape>",
            "scene.xml:8",
            "a second BSDF",
        ),
        (
            "<shape type=\"sphere\">\n<sensor type=\"perspective\"/></shape>",
            "scene.xml:7",
            "a sensor other than an irradiancemeter attached to a shape is not supported",
        ),
    ];
    for (shape, line, expected) in cases {
        let path = xml(&dir, &format!("{defs}\n{shape}"));
        let e = load_err(&path, false);
        assert!(e.contains(expected) && e.contains(line), "{e}");
    }
    // --lenient renders the sphere without its sensor.
    let path = xml(
        &dir,
        &format!("{defs}\n<shape type=\"sphere\">\n<sensor type=\"perspective\"/></shape>"),
    );
    let scene = foton_loader::load_with(&path, &[], &[], true).unwrap();
    assert!(trace(&scene, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).is_some());
    // ... and the sphere without the <ref> it cannot resolve, saying so.
    let path = xml(
        &dir,
        &format!("{defs}\n<shape type=\"sphere\">\n<ref id=\"nothing\"/></shape>"),
    );
    let scene = foton_loader::load_with(&path, &[], &[], true).unwrap();
    assert!(trace(&scene, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).is_some());
    let said = scene.warnings().join("\n");
    assert!(
        said.contains("left out: ") && said.contains("scene.xml:7") && said.contains("`nothing`"),
        "{said}"
    );
}

#[test]
fn mitsuba_06_mesh_parameters_are_read() {
    let dir = temp_dir("mesh-06");
    write(
        &dir,
        "tri.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nmtllib tri.mtl\nusemtl red\nf 1 2 3\n",
    );
    // A floor square (normal +z) and a wall square (normal -y) meeting at a right angle
    // along y = 1.
    let fold = Mesh {
        positions: vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [1., 1., 1.],
            [0., 1., 1.],
        ],
        normals: None,
        uvs: None,
        triangles: vec![[0, 1, 2], [0, 2, 3], [3, 2, 4], [3, 4, 5]],
    };
    std::fs::write(
        dir.join("m.serialized"),
        serialized(&[square(0.0, None, false), fold], 3, false),
    )
    .unwrap();
    let scene_with = |angle: &str| {
        format!(
            r#"<scene version="0.6.0">
<sensor type="perspective"><transform name="toWorld"><lookat origin="0, 0, 20" target="0, 0, 0" up="0, 1, 0"/></transform></sensor>
<shape type="obj"><string name="filename" value="tri.obj"/>
    <boolean name="collapse" value="true"/><boolean name="loadMaterials" value="true"/>
    <boolean name="faceNormals" value="true"/><boolean name="flipNormals" value="true"/>
    <transform name="toWorld"><translate x="5"/></transform></shape>
<shape type="serialized"><string name="filename" value="m.serialized"/>
    <integer name="shapeIndex" value="1"/>{angle}</shape>
</scene>
"#
        )
    };
    let path = write(
        &dir,
        "scene.xml",
        &scene_with(r#"<float name="maxSmoothAngle" value="30"/>"#),
    );
    let scene = load(&path);
    let (t, ng, ns, _) = trace(&scene, Vec3::new(5.2, 0.2, 5.0), -Vec3::Z).unwrap();
    assert!((t - 5.0).abs() < 1e-4 && close(ng, -Vec3::Z, 1e-5) && close(ns, -Vec3::Z, 1e-5));
    // Next to the fold the floor is shaded flat: 90 degrees is beyond 30.
    let near_fold = Vec3::new(0.5, 0.95, 5.0);
    let (_, _, ns, _) = trace(&scene, near_fold, -Vec3::Z).unwrap();
    assert!(close(ns, Vec3::Z, 1e-5), "{ns}");
    let ignored = scene.ignored().join("\n");
    assert!(
        ignored.contains("scene.xml:4") && ignored.contains("MTL materials"),
        "{ignored}"
    );
    assert!(!ignored.contains("collapse"), "{ignored}");
    // Without it, the normals are smoothed across the fold (Mitsuba's computed normals),
    // towards the wall's, -y.
    let path = write(&dir, "scene.xml", &scene_with(""));
    let (_, _, ns, _) = trace(&load(&path), near_fold, -Vec3::Z).unwrap();
    assert!(ns.y < -0.3, "{ns}");
    // With face normals, Mitsuba 0.6 refuses it.
    let path = write(
        &dir,
        "scene.xml",
        &scene_with(
            r#"<float name="maxSmoothAngle" value="30"/><boolean name="faceNormals" value="true"/>"#,
        ),
    );
    let e = load_err(&path, false);
    assert!(e.contains("`max_smooth_angle` and `face_normals`"), "{e}");
}

#[test]
fn ply_texture_coordinates_are_flipped_only_when_asked() {
    let dir = temp_dir("ply-uv");
    write(
        &dir,
        "tri.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n",
    );
    for (flip, v) in [
        ("", 0.25),
        (r#"<boolean name="flip_tex_coords" value="true"/>"#, 0.75),
    ] {
        let path = xml(
            &dir,
            &format!(
                r#"<shape type="ply"><string name="filename" value="tri.ply"/>{flip}</shape>"#
            ),
        );
        let (_, _, _, uv) = trace(&load(&path), Vec3::new(0.25, 0.25, 5.0), -Vec3::Z).unwrap();
        assert!((uv - Vec2::new(0.25, v)).length() < 1e-5, "{flip}: {uv}");
    }
}

#[test]
fn an_area_emitter_given_by_ref_makes_its_shape_emit() {
    let dir = temp_dir("area-ref");
    let path = xml(
        &dir,
        r#"<emitter type="area" id="light"><rgb name="radiance" value="3"/></emitter>
<shape type="rectangle"><ref id="light"/></shape>"#,
    );
    let scene = load(&path);
    // One-sided: pi L A, A = 4.
    let expected = std::f32::consts::PI * 3.0 * 4.0;
    assert!((scene.total_power().x / expected - 1.0).abs() < 1e-4);
}

#[test]
fn another_emitter_inside_a_shape_is_a_light_of_its_own() {
    let dir = temp_dir("spot-in-shape");
    // Mitsuba 3 reads the spot as a scene light at its own to_world, not the rectangle's
    // (checked with Mitsuba 3.9.1).
    let path = xml(
        &dir,
        r#"<shape type="rectangle"><transform name="to_world"><translate z="5"/></transform>
    <emitter type="spot"><rgb name="intensity" value="2"/></emitter></shape>"#,
    );
    let scene = load(&path);
    assert_eq!(scene.lights().len(), 1);
    assert!(trace(&scene, Vec3::new(0.0, 0.0, 10.0), -Vec3::Z).is_some());
    let said = scene.warnings().join("\n");
    assert!(
        said.contains("scene.xml:4") && said.contains("light of its own"),
        "{said}"
    );
}

/// A `cube` has Mitsuba 3's texture coordinates on every face, with its normals outward,
/// under a rotation and non-uniform scale and under a mirroring to_world. Expected: Mitsuba
/// 3's mesh itself (src/shapes/cube.cpp: `side_normals`, `side_uv`, `position_index`, corner c
/// at (+-1, +-1, +-1) by the bits of c, triangles {4s, 4s+1, 4s+2} and {4s+3, 4s, 4s+2}),
/// evaluated at points inside each triangle (checked with Mitsuba 3.9.1).
#[test]
fn cube_faces_have_mitsuba_3s_texture_coordinates_and_outward_normals() {
    let side_normals = [
        [0., -1., 0.],
        [0., 1., 0.],
        [1., 0., 0.],
        [0., 0., 1.],
        [-1., 0., 0.],
        [0., 0., -1.],
    ];
    let side_uv = [[0., 1.], [1., 1.], [1., 0.], [0., 0.]];
    let position_index = [
        1, 5, 4, 0, 3, 2, 6, 7, 1, 3, 7, 5, 5, 7, 6, 4, 4, 6, 2, 0, 3, 1, 0, 2,
    ];
    let corner = |c: u32| {
        let sign = |bit: u32| if c & bit != 0 { 1.0 } else { -1.0 };
        Vec3::new(sign(1), sign(2), sign(4))
    };
    let dir = temp_dir("cube-uv");
    let path = xml(
        &dir,
        r#"<shape type="cube"><transform name="to_world"><scale x="1.5" y="0.5" z="0.8"/>
    <rotate x="1" angle="30"/><rotate y="1" angle="50"/></transform></shape>
<shape type="cube"><transform name="to_world"><scale x="-1" y="0.7" z="1.2"/>
    <rotate z="1" angle="40"/><translate x="20"/></transform></shape>"#,
    );
    let scene = load(&path);
    let (x, y) = (30f32.to_radians(), 50f32.to_radians());
    let turned = Mat3::from_rotation_y(y) * Mat3::from_rotation_x(x);
    let cubes = [
        (
            turned * Mat3::from_diagonal(Vec3::new(1.5, 0.5, 0.8)),
            Vec3::ZERO,
        ),
        (
            Mat3::from_rotation_z(40f32.to_radians())
                * Mat3::from_diagonal(Vec3::new(-1.0, 0.7, 1.2)),
            Vec3::new(20.0, 0.0, 0.0),
        ),
    ];
    for (m, offset) in cubes {
        for s in 0..6 {
            let normal = (m.inverse().transpose() * Vec3::from_array(side_normals[s])).normalize();
            let vertex = |k: usize| {
                (
                    corner(position_index[4 * s + k]),
                    Vec2::from_array(side_uv[k]),
                )
            };
            // A point inside each of the face's two triangles, by its barycentric weights.
            for (tri, w) in [([0, 1, 2], [0.2, 0.3, 0.5]), ([3, 0, 2], [0.6, 0.3, 0.1])] {
                let (mut p, mut uv) = (Vec3::ZERO, Vec2::ZERO);
                for (k, w) in tri.into_iter().zip(w) {
                    let (q, t) = vertex(k);
                    p += w * q;
                    uv += w * t;
                }
                let at = m * p + offset;
                let (t, ng, ns, got) = trace(&scene, at + 3.0 * normal, -normal)
                    .unwrap_or_else(|| panic!("face {s} of {m}: missed {at}"));
                let what = format!("face {s} of {m} at {p}: t {t} ng {ng} ns {ns} uv {got}");
                assert!((t - 3.0).abs() < 1e-3, "{what}");
                assert!((got - uv).length() < 1e-4, "{what}: uv {uv} expected");
                assert!(
                    close(ng, normal, 1e-4) && close(ns, normal, 1e-4),
                    "{what}: {normal} expected"
                );
            }
        }
    }
}
