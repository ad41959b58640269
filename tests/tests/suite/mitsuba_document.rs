//! The Mitsuba XML document as Mitsuba reads it (issue 32): `<path>` folders and the file
//! resolver, `<include>` from the including file's folder with errors at the included file's
//! lines, named nested objects, top-level samplers taken by `<ref>`, `<lookAt>` in any case,
//! the default sensor, film parameters and crop windows, reconstruction filters foton lacks,
//! 2.x files, bitmap filter and wrap modes, XML syntax errors with their column.

use foton_core::value::{Document, Node, Table, Value};
use foton_loader::mitsuba::read_xml;
use foton_loader::reader::Report;
use foton_tests::{temp_dir, write};
use glam::{Vec2, Vec3};
use std::path::Path;

const OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// A scene of `body` (elements inside `<scene>`), with a light and a sphere when `body`
/// names none.
fn scene(version: &str, body: &str) -> String {
    let light = if body.contains("<emitter") {
        ""
    } else {
        "<emitter type=\"constant\"/>"
    };
    let shape = if body.contains("<shape") {
        ""
    } else {
        "<shape type=\"sphere\"/>"
    };
    format!("<scene version=\"{version}\">\n{body}\n{light}{shape}\n</scene>\n")
}

const SENSOR: &str = r#"<sensor type="perspective">
    <transform name="to_world"><lookat origin="0, 0, -5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="16"/></film>
</sensor>"#;

fn read(path: &Path, lenient: bool) -> Result<(Document, Report), String> {
    read_xml(path, &[], lenient).map_err(|e| e.to_string())
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

fn text(t: &Table, path: &str) -> String {
    match &node(t, path).value {
        Value::Str(s) => s.clone(),
        other => panic!("{path}: {other:?}"),
    }
}

fn number(t: &Table, path: &str) -> f64 {
    node(t, path)
        .value
        .as_f64()
        .unwrap_or_else(|| panic!("{path}"))
}

fn vector(t: &Table, path: &str) -> Vec3 {
    let Value::Array(a) = &node(t, path).value else {
        panic!("{path}")
    };
    let x: Vec<f32> = a.iter().map(|n| n.value.as_f64().unwrap() as f32).collect();
    Vec3::new(x[0], x[1], x[2])
}

/// `<path>` adds a folder in which every later file name is looked for after the file's own
/// folder: meshes and textures by their bare names. Without it the file is not found, and
/// the error names the element's file and line and the folders searched.
#[test]
fn path_folders_are_searched_for_files() {
    let dir = temp_dir("mitsuba-path");
    std::fs::create_dir_all(dir.join("assets/meshes")).unwrap();
    write(&dir.join("assets/meshes"), "tri.obj", OBJ);
    image::RgbImage::from_pixel(2, 2, image::Rgb([200, 100, 50]))
        .save(dir.join("assets/meshes/wood.png"))
        .unwrap();
    let body = format!(
        r#"{SENSOR}
<path value="assets/meshes"/>
<shape type="obj">
    <string name="filename" value="tri.obj"/>
    <bsdf type="diffuse">
        <texture type="bitmap" name="reflectance"><string name="filename" value="wood.png"/></texture>
    </bsdf>
</shape>"#
    );
    let xml = write(&dir, "scene.xml", &scene("3.0.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(text(&doc.root, "shapes.0.file"), "assets/meshes/tri.obj");
    let material = text(&doc.root, "shapes.0.material");
    assert_eq!(
        text(
            &doc.root,
            &format!("materials.{material}.reflectance.filename")
        ),
        "assets/meshes/wood.png"
    );
    // The scene loads: the builder finds the files where the reader says they are.
    let loaded = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    assert_eq!(loaded.film().width, 32);

    let without = scene("3.0.0", &body).replace("<path value=\"assets/meshes\"/>", "");
    let xml = write(&dir, "scene.xml", &without);
    let e = read(&xml, false).unwrap_err();
    for needle in ["scene.xml:10:", "wood.png", "no such file"] {
        assert!(e.contains(needle), "{needle}: {e}");
    }

    // A folder that does not exist is an error at its line; --lenient reads on without it.
    let missing = scene("3.0.0", &body).replace("assets/meshes\"/>", "nowhere\"/>");
    let xml = write(&dir, "scene.xml", &missing);
    let e = read(&xml, false).unwrap_err();
    for needle in ["scene.xml:6:", "nowhere", "no such folder"] {
        assert!(e.contains(needle), "{needle}: {e}");
    }
    let e = read(&xml, true).unwrap_err();
    assert!(e.contains("wood.png"), "{e}");
}

/// A file named from a repository's root, as Mitsuba 0.6's test scenes name theirs (for a
/// renderer run from that root), is found in a folder above the scene's, with a warning.
#[test]
fn files_named_from_a_folder_above_are_found_with_a_warning() {
    let dir = temp_dir("mitsuba-above");
    let tests = dir.join("data/tests");
    std::fs::create_dir_all(&tests).unwrap();
    write(&tests, "tri.obj", OBJ);
    let body = format!(
        r#"{SENSOR}
<shape type="obj"><string name="filename" value="data/tests/tri.obj"/></shape>"#
    );
    let xml = write(&tests, "scene.xml", &scene("0.5.0", &body));
    let (doc, report) = read(&xml, false).unwrap();
    // The document's paths are relative to the scene's folder.
    let found = tests
        .join(text(&doc.root, "shapes.0.file"))
        .canonicalize()
        .unwrap();
    assert_eq!(found, tests.join("tri.obj").canonicalize().unwrap());
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("data/tests/tri.obj") && w.contains("above the scene's")),
        "{:?}",
        report.warnings
    );
    // A name found nowhere stays an error.
    let xml = write(
        &tests,
        "scene.xml",
        &scene("0.5.0", &body.replace("tri.obj", "no.obj")),
    );
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("no such file"), "{e}");
}

/// An include is found from the folder of the file that includes it, a nested one from
/// its own includer's; what fails in an included file is reported at that file's line; and
/// the document keeps no line of an included file (its lines are the scene file's).
#[test]
fn includes_resolve_from_the_including_file_and_report_their_lines() {
    let dir = temp_dir("mitsuba-include");
    std::fs::create_dir_all(dir.join("parts/deeper")).unwrap();
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    write(&dir.join("meshes"), "tri.obj", OBJ);
    let main = scene(
        "3.0.0",
        &format!("{SENSOR}\n<include filename=\"parts/a.xml\"/>"),
    );
    let xml = write(&dir, "scene.xml", &main);
    write(
        &dir.join("parts"),
        "a.xml",
        "<scene version=\"2.1.0\">\n\n    <include filename=\"deeper/b.xml\"/>\n</scene>\n",
    );
    let b = "<scene version=\"3.0.0\">\n    <shape type=\"obj\">\n        <string name=\"filename\" value=\"../../meshes/tri.obj\"/>\n    </shape>\n</scene>\n";
    write(&dir.join("parts/deeper"), "b.xml", b);
    let (doc, report) = read(&xml, false).unwrap();
    assert_eq!(report.included.len(), 2, "{:?}", report.included);
    let shape = node(&doc.root, "shapes.0");
    assert_eq!(shape.line, 0);
    assert_eq!(node(&doc.root, "shapes.0.file").line, 0);
    assert!(text(&doc.root, "shapes.0.file").ends_with("tri.obj"));
    // The scene file's own values keep their lines.
    assert_eq!(node(&doc.root, "film.width").line, 4);

    // Mitsuba 3 includes a file of one object as that object.
    write(
        &dir.join("parts"),
        "red.xml",
        "<bsdf version=\"3.0.0\" type=\"diffuse\" id=\"red\">\n    <rgb name=\"reflectance\" value=\"0.8, 0.1, 0.1\"/>\n</bsdf>\n",
    );
    let with_red = main.replace(
        "<include filename=\"parts/a.xml\"/>",
        "<include filename=\"parts/red.xml\"/>\n<shape type=\"sphere\"><ref id=\"red\"/></shape>",
    );
    let red = write(&dir, "red.xml", &with_red);
    let (doc, _) = read(&red, false).unwrap();
    assert_eq!(text(&doc.root, "shapes.0.material"), "red");
    assert_eq!(
        vector(&doc.root, "materials.red.reflectance"),
        Vec3::new(0.8, 0.1, 0.1)
    );

    // A missing mesh in the nested file: that file and the element's line.
    write(
        &dir.join("parts/deeper"),
        "b.xml",
        &b.replace("tri.obj", "gone.obj"),
    );
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("b.xml:2:"), "{e}");
    assert!(e.contains("gone.obj"), "{e}");

    // A missing nested include: the including file and its line.
    write(&dir.join("parts/deeper"), "b.xml", b);
    write(
        &dir.join("parts"),
        "a.xml",
        "<scene version=\"3.0.0\">\n\n    <include filename=\"deeper/c.xml\"/>\n</scene>\n",
    );
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("a.xml:3:5"), "{e}");
    assert!(e.contains("deeper/c.xml"), "{e}");

    // An error inside an included file names its line there, not line 0.
    write(
        &dir.join("parts"),
        "a.xml",
        "<scene version=\"3.0.0\">\n\n    <bsdf type=\"dielectric\">\n        <string name=\"int_ior\" value=\"unobtainium\"/>\n    </bsdf>\n</scene>\n",
    );
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("a.xml:3:"), "{e}");
}

/// Nested objects with a `name` (as Mitsuba names every child) are taken by kind; a
/// top-level sampler, film and filter with an `id` are taken where a `<ref>` names them.
#[test]
fn named_nested_objects_and_referenced_samplers() {
    let dir = temp_dir("mitsuba-named");
    let body = r#"<sampler type="independent" id="spp7"><integer name="sample_count" value="7"/></sampler>
<rfilter type="tent" id="wide"><float name="radius" value="2"/></rfilter>
<sensor type="perspective" name="sensor">
    <ref name="sampler" id="spp7"/>
    <film type="hdrfilm" name="film">
        <integer name="width" value="8"/><integer name="height" value="8"/>
        <ref id="wide"/>
    </film>
</sensor>
<medium type="homogeneous" id="fog">
    <phase type="hg" name="phase_function"><float name="g" value="0.3"/></phase>
</medium>"#;
    let xml = write(&dir, "scene.xml", &scene("3.0.0", body));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(number(&doc.root, "render.spp"), 7.0);
    assert_eq!(text(&doc.root, "film.filter.type"), "tent");
    assert_eq!(number(&doc.root, "film.filter.radius"), 2.0);
    assert_eq!(number(&doc.root, "media.fog.phase.g"), 0.3);

    let named = body
        .replace("<ref id=\"wide\"/>", "<rfilter name=\"rfilter\" type=\"box\"/>")
        .replace(
            "<ref name=\"sampler\" id=\"spp7\"/>",
            "<sampler name=\"sampler\" type=\"independent\"><integer name=\"sample_count\" value=\"3\"/></sampler>",
        );
    let xml = write(&dir, "scene.xml", &scene("3.0.0", &named));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(number(&doc.root, "render.spp"), 3.0);
    assert_eq!(text(&doc.root, "film.filter.type"), "box");
}

/// `<lookAt>` in any case is `<lookat>`; without `up`, Mitsuba's (0.6 and 3) is the first
/// vector of the orthonormal basis it builds around the viewing direction: +x for +z.
#[test]
fn lookat_in_any_case_and_without_up() {
    let dir = temp_dir("mitsuba-lookat");
    let mut cameras = Vec::new();
    for tag in ["lookat", "lookAt", "LookAt", "LOOKAT"] {
        let body = SENSOR.replace("lookat", tag);
        let xml = write(&dir, "scene.xml", &scene("3.0.0", &body));
        let (doc, _) = read(&xml, false).unwrap();
        cameras.push((
            vector(&doc.root, "camera.position"),
            vector(&doc.root, "camera.look_at"),
            vector(&doc.root, "camera.up"),
        ));
    }
    assert!(cameras.iter().all(|c| *c == cameras[0]), "{cameras:?}");
    assert_eq!(cameras[0].0, Vec3::new(0.0, 0.0, -5.0));
    assert!((cameras[0].2 - Vec3::Y).length() < 1e-6);

    let body = SENSOR.replace(" up=\"0, 1, 0\"", "");
    let xml = write(&dir, "scene.xml", &scene("3.0.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    let up = vector(&doc.root, "camera.up");
    assert!((up - Vec3::X).length() < 1e-6, "{up}");
}

/// Without a `<sensor>`, Mitsuba 0.6's: fov 45 across the width, looking down +z from in
/// front of the scene's bounds at the distance where the fov spans their larger extent in x
/// and y; a 768 x 576 film, 4 samples per pixel. A sensor without a film or a sampler takes
/// Mitsuba's film and sample count.
#[test]
fn no_sensor_is_mitsubas_default_camera() {
    let dir = temp_dir("mitsuba-nosensor");
    let body = r#"<shape type="sphere"><point name="center" x="2" y="3" z="5"/><float name="radius" value="1"/></shape>"#;
    let xml = write(&dir, "scene.xml", &scene("0.6.0", body));
    let loaded = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    let (lo, hi) = loaded.bounds();
    let distance = (hi - lo).x.max((hi - lo).y) / (2.0 * 22.5f32.to_radians().tan());
    let expected = Vec3::new(2.0, 3.0, lo.z - distance);
    let camera = loaded.camera();
    assert!(
        (camera.position - expected).length() < 1e-4,
        "{:?}",
        camera.position
    );
    assert!((camera.forward() - Vec3::Z).length() < 1e-6);
    assert_eq!(camera.resolution(), (768, 576));
    assert_eq!(loaded.render().spp, 4);
    // The fov spans the width: the ray through the middle of the left edge is 22.5 degrees
    // off the axis.
    let edge = camera.generate_ray(Vec2::new(0.0, 288.0)).dir;
    assert!((edge.angle_between(Vec3::Z).to_degrees() - 22.5).abs() < 1e-3);

    // A sensor foton does not read: refused, or with --lenient Mitsuba's default camera.
    let spherical = r#"<sensor type="spherical"/>"#;
    let xml = write(&dir, "scene.xml", &scene("0.6.0", spherical));
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("spherical"), "{e}");
    let loaded = foton_loader::load_with(&xml, &[], &[], true).unwrap();
    assert_eq!(loaded.camera().resolution(), (768, 576));
    assert!((loaded.camera().forward() - Vec3::Z).length() < 1e-6);

    let bare = r#"<sensor type="perspective"><float name="fov" value="30"/></sensor>"#;
    let xml = write(&dir, "scene.xml", &scene("3.0.0", bare));
    let loaded = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    assert_eq!(loaded.camera().resolution(), (768, 576));
    assert_eq!(loaded.render().spp, 4);
}

/// A crop window in the middle of the film renders the same pixels as the whole film
/// would there: each crop pixel's ray is the whole film's ray through the same pixel, for a
/// window off the middle too (a shifted camera), and for a mirrored sensor. Film parameters
/// that do not change the linear image are read.
#[test]
fn crop_windows_and_film_parameters() {
    let dir = temp_dir("mitsuba-crop");
    let film = |extra: &str| {
        format!(
            r#"<sensor type="perspective">
    <float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="1, 2, -5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm">
        <integer name="width" value="40"/><integer name="height" value="30"/>
        <string name="pixel_format" value="rgba"/>
        <string name="component_format" value="float16"/>
        <boolean name="banner" value="false"/>
        <boolean name="highQualityEdges" value="true"/>
        <float name="gamma" value="2.2"/>
        {extra}
    </film>
</sensor>"#
        )
    };
    let xml = write(&dir, "full.xml", &scene("3.0.0", &film("")));
    let full = foton_loader::load_with(&xml, &[], &[], true).unwrap();
    let crop = r#"<integer name="crop_offset_x" value="10"/><integer name="crop_offset_y" value="9"/>
        <integer name="crop_width" value="20"/><integer name="crop_height" value="12"/>"#;
    let xml = write(&dir, "crop.xml", &scene("3.0.0", &film(crop)));
    let (_, report) = read(&xml, false).unwrap();
    assert!(report.left_out.is_empty(), "{:?}", report.left_out);
    let cropped = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    assert_eq!(cropped.camera().resolution(), (20, 12));
    for (x, y) in [(0.5, 0.5), (19.5, 0.5), (7.25, 11.0), (20.0, 12.0)] {
        let a = cropped.camera().generate_ray(Vec2::new(x, y)).dir;
        let b = full.camera().generate_ray(Vec2::new(x + 10.0, y + 9.0)).dir;
        assert!((a - b).length() < 1e-5, "({x}, {y}): {a} against {b}");
    }

    // Off the middle, and with the sensor mirrored (`<scale x="-1"/>`): the crop's pixels
    // of the whole (mirrored) image.
    let off = crop
        .replace("value=\"9\"", "value=\"2\"")
        .replace("value=\"10\"", "value=\"17\"");
    let mirrored = |f: String| {
        f.replace(
            "<transform name=\"to_world\">",
            "<transform name=\"to_world\"><scale x=\"-1\"/>",
        )
    };
    let xml = write(&dir, "full.xml", &scene("3.0.0", &mirrored(film(""))));
    let full = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    let xml = write(&dir, "crop.xml", &scene("3.0.0", &mirrored(film(&off))));
    let cropped = foton_loader::load_with(&xml, &[], &[], false).unwrap();
    assert_eq!(cropped.camera().resolution(), (20, 12));
    for (x, y) in [(0.5, 0.5), (19.5, 0.5), (7.25, 11.0), (20.0, 12.0)] {
        let a = cropped.camera().generate_ray(Vec2::new(x, y)).dir;
        let b = full.camera().generate_ray(Vec2::new(x + 17.0, y + 2.0)).dir;
        assert!((a - b).length() < 1e-5, "({x}, {y}): {a} against {b}");
    }
    // Mirrored: the image's right is the scene's left seen from the camera.
    let plain = foton_loader::load_with(
        &write(&dir, "plain.xml", &scene("3.0.0", &film(""))),
        &[],
        &[],
        false,
    )
    .unwrap();
    let a = full.camera().generate_ray(Vec2::new(3.0, 4.0)).dir;
    let b = plain.camera().generate_ray(Vec2::new(37.0, 4.0)).dir;
    assert!((a - b).length() < 1e-5, "{a} against {b}");
}

/// Mitsuba's mitchell (`B`, `C`), catmullrom and lanczos (`lobes`) filters, in 3.x and 0.6
/// files, read with their parameters and loaded as foton's filters of the same profile; a
/// parameter they do not have is refused as any other.
#[test]
fn mitchell_catmullrom_and_lanczos_are_read() {
    use foton_core::filter::Filter;
    let dir = temp_dir("mitsuba-filters");
    for version in ["3.0.0", "0.6.0"] {
        for (rf, ty, want) in [
            (
                "<rfilter type=\"mitchell\"><float name=\"B\" value=\"0.25\"/><float name=\"C\" value=\"0.375\"/></rfilter>",
                "mitchell",
                Filter::mitchell(0.25, 0.375),
            ),
            (
                "<rfilter type=\"mitchell\"/>",
                "mitchell",
                Filter::mitchell(1.0 / 3.0, 1.0 / 3.0),
            ),
            (
                "<rfilter type=\"catmullrom\"/>",
                "catmullrom",
                Filter::catmull_rom(),
            ),
            (
                "<rfilter type=\"lanczos\"><integer name=\"lobes\" value=\"2\"/></rfilter>",
                "lanczos",
                Filter::lanczos(2),
            ),
            ("<rfilter type=\"lanczos\"/>", "lanczos", Filter::lanczos(3)),
        ] {
            let body = SENSOR.replace("</film>", &format!("{rf}</film>"));
            let xml = write(&dir, "scene.xml", &scene(version, &body));
            let (doc, report) = read(&xml, false).unwrap_or_else(|e| panic!("{version} {rf}: {e}"));
            assert_eq!(text(&doc.root, "film.filter.type"), ty);
            assert!(report.left_out.is_empty(), "{:?}", report.left_out);
            let loaded = foton_loader::load(&xml, &[]).unwrap_or_else(|e| panic!("{rf}: {e}"));
            let got = loaded.film().filter.filter().clone();
            let same = match (&got, &want) {
                (
                    Filter::Mitchell { b, c, radius },
                    Filter::Mitchell {
                        b: b2,
                        c: c2,
                        radius: r2,
                    },
                ) => (b - b2).abs() < 1e-6 && (c - c2).abs() < 1e-6 && radius == r2,
                _ => got == want,
            };
            assert!(same, "{version} {rf}: {got:?} against {want:?}");
        }
    }
    let body = SENSOR.replace(
        "</film>",
        "<rfilter type=\"catmullrom\"><float name=\"B\" value=\"0.3\"/></rfilter></film>",
    );
    let xml = write(&dir, "scene.xml", &scene("3.0.0", &body));
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("B"), "{e}");
}

/// Mitsuba 2.0 to 2.2 files are read as 3.x files are (the same names), and their sample
/// scheduling parameters are not refused.
#[test]
fn mitsuba_2_files_are_read() {
    let dir = temp_dir("mitsuba-2");
    for version in ["2.0", "2.0.0", "2.1.0", "2.2.1"] {
        let body = format!(
            "<integrator type=\"path\"><integer name=\"max_depth\" value=\"3\"/><integer name=\"samples_per_pass\" value=\"4\"/></integrator>\n{SENSOR}"
        );
        let xml = write(&dir, "scene.xml", &scene(version, &body));
        let (doc, _) = read(&xml, false).unwrap_or_else(|e| panic!("{version}: {e}"));
        assert_eq!(number(&doc.root, "render.max_depth"), 2.0);
    }
}

/// Mitsuba 2 and 3 stop at an integrator's `timeout` (seconds; negative: none): foton's
/// render.time. Their sample counts are 64-bit: 99999999999 with a timeout is a bound, which
/// foton's largest count stands for; without one, `--lenient` clamps it with a warning and the
/// file as written is refused.
#[test]
fn a_timeout_is_a_time_limit_and_bounds_a_64_bit_sample_count() {
    let dir = temp_dir("mitsuba-timeout");
    let body = |timeout: &str| {
        format!(
            r#"<integrator type="path"><float name="timeout" value="{timeout}"/></integrator>
<sensor type="perspective">
    <transform name="to_world"><lookat origin="0, 0, -5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="99999999999"/></sampler>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="16"/></film>
</sensor>"#
        )
    };
    let xml = write(&dir, "timed.xml", &scene("2.0.0", &body("12")));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(number(&doc.root, "render.time"), 12.0);
    assert_eq!(number(&doc.root, "render.spp"), f64::from(u32::MAX));
    let scene_of = |xml: &Path| foton_loader::load_with(xml, &[], &[], false);
    assert_eq!(scene_of(&xml).unwrap().render().time, Some(12.0));
    // No time limit: refused as written (at the count's line), clamped with --lenient.
    let xml = write(&dir, "untimed.xml", &scene("2.0.0", &body("-1")));
    let (doc, _) = read(&xml, false).unwrap();
    assert!(matches!(&node(&doc.root, "render").value, Value::Table(t) if t.get("time").is_none()));
    let Err(e) = scene_of(&xml) else {
        panic!("a 64-bit sample count without a timeout opened as written")
    };
    let e = e.to_string();
    assert!(
        e.contains("untimed.xml:5") && e.contains("99999999999"),
        "{e}"
    );
    let (doc, report) = read(&xml, true).unwrap();
    assert_eq!(number(&doc.root, "render.spp"), f64::from(u32::MAX));
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("99999999999") && w.contains("timeout")),
        "{:?}",
        report.warnings
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// Bitmap filter and wrap modes as foton's textures have them: Mitsuba 3's names kept,
/// 0.6's camelCase and its mipmapped filters read (bilinear, a warning), a constant border
/// clamped with `--lenient` (an error without).
#[test]
fn bitmap_filter_and_wrap_modes() {
    let dir = temp_dir("mitsuba-bitmap");
    image::RgbImage::from_pixel(2, 2, image::Rgb([10, 20, 30]))
        .save(dir.join("t.png"))
        .unwrap();
    let body = |params: &str| {
        format!(
            r#"{SENSOR}
<shape type="sphere"><bsdf type="diffuse">
    <texture type="bitmap" name="reflectance"><string name="filename" value="t.png"/>{params}</texture>
</bsdf></shape>"#
        )
    };
    let cases = [
        (
            r#"<string name="filter_type" value="nearest"/><string name="wrap_mode" value="mirror"/>"#,
            "nearest",
            "mirror",
            false,
        ),
        (
            r#"<string name="filterType" value="trilinear"/><string name="wrapMode" value="clamp"/>"#,
            "bilinear",
            "clamp",
            true,
        ),
        (
            r#"<string name="filter_type" value="ewa"/><string name="wrap_mode_u" value="repeat"/><string name="wrap_mode_v" value="repeat"/>"#,
            "bilinear",
            "repeat",
            true,
        ),
    ];
    for (params, filter, wrap, warned) in cases {
        let xml = write(&dir, "scene.xml", &scene("3.0.0", &body(params)));
        let (doc, report) = read(&xml, false).unwrap_or_else(|e| panic!("{params}: {e}"));
        let m = text(&doc.root, "shapes.0.material");
        assert_eq!(
            text(&doc.root, &format!("materials.{m}.reflectance.filter_type")),
            filter
        );
        assert_eq!(
            text(&doc.root, &format!("materials.{m}.reflectance.wrap_mode")),
            wrap
        );
        assert_eq!(!report.warnings.is_empty(), warned, "{:?}", report.warnings);
        foton_loader::load_with(&xml, &[], &[], false).unwrap();
    }
    // A texture left out (--lenient) leaves out what takes it by reference, which says so.
    let dropped = format!(
        r#"{SENSOR}
<texture type="volume" id="tex"><volume type="openvdb" name="volume"/></texture>
<shape type="sphere"><bsdf type="diffuse"><ref name="reflectance" id="tex"/></bsdf></shape>"#
    );
    let xml = write(&dir, "scene.xml", &scene("3.0.0", &dropped));
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("volume"), "{e}");
    let (doc, report) = read(&xml, true).unwrap();
    assert!(doc.root.get("shapes").is_none());
    assert!(
        report
            .left_out
            .iter()
            .any(|l| l.contains("texture `tex` was left out")),
        "{:?}",
        report.left_out
    );

    for border in ["zero", "one"] {
        let params = format!("<string name=\"wrap_mode\" value=\"{border}\"/>");
        let xml = write(&dir, "scene.xml", &scene("3.0.0", &body(&params)));
        let e = read(&xml, false).unwrap_err();
        assert!(e.contains(border) && e.contains("--lenient"), "{e}");
        let (doc, report) = read(&xml, true).unwrap();
        let m = text(&doc.root, "shapes.0.material");
        assert_eq!(
            text(&doc.root, &format!("materials.{m}.reflectance.wrap_mode")),
            "clamp"
        );
        assert_eq!(report.left_out.len(), 1, "{:?}", report.left_out);
    }
}

/// An area emitter defined at the top level and given to a shape by `<ref>` (before or after
/// it) is the shape's emitter, a medium given by an unnamed `<ref>` the sensor's or the light's; XML that does
/// not parse is reported at its line and column.
#[test]
fn referenced_area_emitters_and_syntax_error_columns() {
    let dir = temp_dir("mitsuba-refs");
    let body = format!(
        r#"{SENSOR}
<emitter type="area" id="glow"><rgb name="radiance" value="3, 2, 1"/></emitter>
<shape type="sphere"><ref id="glow"/></shape>"#
    );
    let xml = write(&dir, "scene.xml", &scene("3.0.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(
        vector(&doc.root, "shapes.0.emission"),
        Vec3::new(3.0, 2.0, 1.0)
    );

    // Mitsuba resolves references once the file is read: the official Cornell box gives its
    // light by a <ref> before the emitter, in an included file.
    let body = format!(
        r#"{SENSOR}
<include filename="shapes.xml"/>
<bsdf type="diffuse" id="white"/>
<emitter type="area" id="glow"><rgb name="radiance" value="5, 5, 5"/></emitter>"#
    );
    write(
        &dir,
        "shapes.xml",
        "<scene version=\"3.0.0\">\n    <shape type=\"sphere\">\n        <ref id=\"white\"/>\n        <ref id=\"glow\"/>\n    </shape>\n</scene>\n",
    );
    let xml = write(&dir, "scene.xml", &scene("3.0.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(
        vector(&doc.root, "shapes.0.emission"),
        Vec3::new(5.0, 5.0, 5.0)
    );
    assert_eq!(text(&doc.root, "shapes.0.material"), "white");
    assert_eq!(node(&doc.root, "shapes.0").line, 0);

    // An unnamed reference to a medium is a sensor's or a light's medium, not a BSDF.
    let body = r#"<medium type="homogeneous" id="fog"><rgb name="sigma_t" value="0.1"/></medium>
<sensor type="perspective"><ref id="fog"/></sensor>
<emitter type="point"><ref id="fog"/></emitter>"#;
    let xml = write(&dir, "scene.xml", &scene("3.0.0", body));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(text(&doc.root, "camera.medium"), "fog");
    assert_eq!(text(&doc.root, "lights.0.medium"), "fog");

    // A property of the wrong kind is named as the file writes it, not as a debug dump.
    let body = r#"<sensor type="perspective"><texture type="checkerboard" name="fov"/></sensor>"#;
    let xml = write(&dir, "scene.xml", &scene("3.0.0", body));
    let e = read(&xml, false).unwrap_err();
    assert!(
        e.contains("`fov`: expected a number, found <texture type=\"checkerboard\">"),
        "{e}"
    );
    assert!(!e.contains("Obj {"), "{e}");

    let broken = "<scene version=\"3.0.0\">\n    <shape type=\"sphere\">\n        <float name=\"radius\" value=\"1\"/ >\n    </shape>\n</scene>\n";
    let xml = write(&dir, "scene.xml", broken);
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("scene.xml:3:40"), "{e}");
    let bad_value = "<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n      <float name=\"radius\"/>\n  </shape>\n</scene>\n";
    let xml = write(&dir, "scene.xml", bad_value);
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("scene.xml:3:7"), "{e}");
}

/// A parameter no Mitsuba plugin reads: Mitsuba 0.6 warns of an unqueried attribute and
/// renders, so a 0.x file opens with a warning naming it; Mitsuba 2 and 3 refuse the file, and
/// so does foton for theirs. A parameter 0.6 reads and foton does not honour is still refused.
/// Booleans in any case (Mitsuba 2 and 3), comments with `--` (their pugixml).
#[test]
fn unread_parameters_of_0x_files_warn_as_mitsuba_0_6_does() {
    let dir = temp_dir("mitsuba-unqueried");
    let body = |version: &str| {
        scene(
            version,
            &format!(
                "<!-- made by a tool -- version 2 -->\n<integrator type=\"path\"><integer name=\"stepSnapshot\" value=\"3\"/><boolean name=\"hideEmitters\" value=\"True\"/></integrator>\n{SENSOR}"
            ),
        )
    };
    let xml = write(&dir, "old.xml", &body("0.6.0"));
    let (doc, report) = read(&xml, false).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("old.xml:3") && w.contains("`step_snapshot` ignored")),
        "{:?}",
        report.warnings
    );
    assert_eq!(
        node(&doc.root, "render.hide_emitters").value,
        Value::Bool(true)
    );
    for version in ["2.1.0", "3.0.0"] {
        let xml = write(&dir, "new.xml", &body(version));
        let e = read(&xml, false).unwrap_err();
        assert!(
            e.contains("new.xml:3") && e.contains("step_snapshot"),
            "{version}: {e}"
        );
    }
    // Mitsuba 0.6's sensors read `shutterOpenTime` (motion blur), which foton does not
    // render: refused, not ignored.
    let xml = write(
        &dir,
        "honoured.xml",
        &scene(
            "0.5.0",
            &SENSOR.replace(
                "<film",
                "<float name=\"shutterOpenTime\" value=\"1\"/><film",
            ),
        ),
    );
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("shutter_open_time"), "{e}");
}

/// `moment` renders the integrator it wraps, with a warning that the moment layer is not
/// written (as are `stokes`'s and `aov`'s layers); an emitter's `sampling_weight` (noise, not
/// the image) is read without a word.
#[test]
fn moment_renders_the_wrapped_integrator() {
    let dir = temp_dir("mitsuba-moment");
    let body = format!(
        "<integrator type=\"moment\"><integrator type=\"bdpt\"><integer name=\"max_depth\" value=\"4\"/></integrator></integrator>\n{SENSOR}\n<shape type=\"sphere\"><emitter type=\"area\"><float name=\"sampling_weight\" value=\"2\"/></emitter></shape>"
    );
    let xml = write(&dir, "moment.xml", &scene("3.0.0", &body));
    let (doc, report) = read(&xml, false).unwrap();
    assert_eq!(text(&doc.root, "render.integrator"), "bdpt");
    assert_eq!(number(&doc.root, "render.max_depth"), 3.0);
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("moment.xml:2") && w.contains("second-moment layer")),
        "{:?}",
        report.warnings
    );
    assert!(
        !report
            .warnings
            .iter()
            .any(|w| w.contains("sampling_weight"))
    );
    let xml = write(
        &dir,
        "empty.xml",
        &scene("3.0.0", &format!("<integrator type=\"moment\"/>\n{SENSOR}")),
    );
    let e = read(&xml, false).unwrap_err();
    assert!(
        e.contains("empty.xml:2") && e.contains("without the integrator it wraps"),
        "{e}"
    );
    // `stokes` wraps one too: its Stokes layers are not written.
    let stokes = body.replace("\"moment\"", "\"stokes\"");
    let xml = write(&dir, "stokes.xml", &scene("3.0.0", &stokes));
    let (doc, report) = read(&xml, false).unwrap();
    assert_eq!(text(&doc.root, "render.integrator"), "bdpt");
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("stokes.xml:2") && w.contains("Stokes layers")),
        "{:?}",
        report.warnings
    );
    // So does `aov` (its AOVs not written); without one it writes only AOVs: refused, and
    // --lenient renders with foton's default.
    let aov = body.replace(
        "<integrator type=\"moment\">",
        "<integrator type=\"aov\"><string name=\"aovs\" value=\"dd.y:depth\"/>",
    );
    let xml = write(&dir, "aov.xml", &scene("3.0.0", &aov));
    let (doc, report) = read(&xml, false).unwrap();
    assert_eq!(text(&doc.root, "render.integrator"), "bdpt");
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("aov.xml:2") && w.contains("AOV layers (dd.y:depth)")),
        "{:?}",
        report.warnings
    );
    let alone = format!(
        "<integrator type=\"aov\"><string name=\"aovs\" value=\"dd.y:depth\"/></integrator>\n{SENSOR}"
    );
    let xml = write(&dir, "aov_alone.xml", &scene("3.0.0", &alone));
    let e = read(&xml, false).unwrap_err();
    assert!(
        e.contains("aov_alone.xml:2") && e.contains("only its AOVs"),
        "{e}"
    );
    assert!(read(&xml, true).is_ok());
}

/// A plugin named in another case (`Rectangle`, which Mitsuba finds where the file system
/// ignores case) is read as Mitsuba's, with a warning; a name no plugin has in any case is
/// still unknown.
#[test]
fn plugin_names_in_another_case() {
    let dir = temp_dir("mitsuba-case");
    let body = format!("{SENSOR}\n<shape type=\"Sphere\"><bsdf type=\"Diffuse\"/></shape>");
    let xml = write(&dir, "case.xml", &scene("3.0.0", &body));
    let (doc, report) = read(&xml, false).unwrap();
    assert_eq!(text(&doc.root, "shapes.0.type"), "sphere");
    for needle in [
        "case.xml:6: <shape type=\"Sphere\">",
        "case.xml:6: <bsdf type=\"Diffuse\">",
    ] {
        assert!(
            report.warnings.iter().any(|w| w.contains(needle)),
            "{needle}: {:?}",
            report.warnings
        );
    }
    let xml = write(
        &dir,
        "case.xml",
        &scene("3.0.0", &body.replace("Sphere", "Spheroid")),
    );
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("unknown shape type `Spheroid`"), "{e}");
}

/// Mitsuba 3's RGB variants render a linear polarizer as a null surface passing half its
/// transmittance straight through: seen through one, a uniform sky of radiance 1 is 0.5,
/// through two 0.25 (whatever their angles: no polarisation is tracked), through one of
/// transmittance 0.5 0.25.
#[test]
fn polarizers_pass_half_their_transmittance() {
    let dir = temp_dir("mitsuba-polarizer");
    let sensor = r#"<sensor type="orthographic">
    <transform name="to_world"><lookat origin="0, 0, -5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
</sensor>"#;
    let sheet = |z: f32, extra: &str| {
        format!(
            "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"5\"/><translate z=\"{z}\"/></transform><bsdf type=\"polarizer\">{extra}</bsdf></shape>"
        )
    };
    let cases = [
        (sheet(0.0, ""), 0.5),
        (
            format!(
                "{}{}",
                sheet(0.0, ""),
                sheet(1.0, "<float name=\"theta\" value=\"90\"/>")
            ),
            0.25,
        ),
        (
            sheet(0.0, "<float name=\"transmittance\" value=\"0.5\"/>"),
            0.25,
        ),
    ];
    for (i, (sheets, expected)) in cases.iter().enumerate() {
        let body = format!(
            "<integrator type=\"path\"/>{sensor}\n{sheets}\n<emitter type=\"constant\"><rgb name=\"radiance\" value=\"1\"/></emitter>"
        );
        let xml = write(&dir, "polarizer.xml", &scene("3.0.0", &body));
        let (_, report) = read(&xml, false).unwrap();
        assert!(
            report.notes.iter().any(|w| w.contains("no polarisation")),
            "{:?}",
            report.notes
        );
        let film = foton_tests::render_file(&xml, &[], 2);
        let (mean, se) = foton_tests::region_mean(&film, 0, 0, 8, 8);
        for c in 0..3 {
            assert!(
                (mean[c] - expected).abs() < 4.0 * se[c] + 1e-4,
                "case {i}: {mean} +- {se}, expected {expected}"
            );
        }
        // Noise, not an exact value: the cut-out is stochastic.
        assert!(se[0] > 0.0, "case {i}");
    }
}

/// What `--lenient` gets past that Mitsuba refuses or foton lacks, each said in the report:
/// a `$name` with no value (the property left out, its default standing; without
/// `--lenient` a warning). Mitsuba 0.6's
/// `phong` microfacet distribution and its other name `as` are foton's `phong`. Read as
/// written: a top-level `<phase>` taken by `<ref>` from a medium, a filter beside the film in
/// the sensor.
#[test]
fn lenient_gets_past_unresolved_names_and_0_6_distributions() {
    let dir = temp_dir("mitsuba-lenient-more");
    let body = format!(
        "<sampler type=\"independent\" id=\"s\"><integer name=\"sample_count\" value=\"$spp\"/></sampler>\n<bsdf type=\"roughconductor\" id=\"b\"><string name=\"distribution\" value=\"phong\"/></bsdf>\n{SENSOR}"
    );
    let xml = write(&dir, "lenient.xml", &scene("0.6.0", &body));
    let (_, report) = read(&xml, false).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("lenient.xml:2") && w.contains("$spp")),
        "{:?}",
        report.warnings
    );
    let (doc, report) = read(&xml, true).unwrap();
    let said = |needle: &str| report.left_out.iter().any(|w| w.contains(needle));
    assert!(
        said("lenient.xml:2") && said("`$spp`"),
        "{:?}",
        report.left_out
    );
    assert!(!said("lenient.xml:3"), "{:?}", report.left_out);
    assert_eq!(text(&doc.root, "materials.b.distribution"), "phong");
    let (doc, _) = read(
        &write(
            &dir,
            "as.xml",
            &scene("0.6.0", &body.replace("$spp", "4").replace("phong", "as")),
        ),
        false,
    )
    .unwrap();
    assert_eq!(text(&doc.root, "materials.b.distribution"), "phong");
    let e = read(
        &write(&dir, "typo.xml", &body.replace("phong", "phnog")),
        true,
    );
    assert!(
        e.is_err(),
        "a misspelt distribution is not Mitsuba's: refused"
    );

    let body = "<phase type=\"hg\" id=\"fwd\"><float name=\"g\" value=\"0.7\"/></phase>\n<medium type=\"homogeneous\" id=\"fog\"><ref id=\"fwd\"/></medium>\n<sensor type=\"perspective\"><rfilter type=\"tent\"/><ref id=\"fog\"/></sensor>";
    let xml = write(&dir, "phase.xml", &scene("3.0.0", body));
    let (doc, report) = read(&xml, false).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(number(&doc.root, "media.fog.phase.g"), 0.7);
    assert_eq!(text(&doc.root, "film.filter.type"), "tent");
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("phase.xml:4") && w.contains("the film's filter")),
        "{:?}",
        report.warnings
    );
}

/// A heterogeneous medium (Mitsuba 0.6's `density` grid and `albedo` constant) is foton's
/// `heterogeneous`: the grid in the box its file gives, samples on the corners, zero beyond,
/// `scale` into sigma_t; a phase function foton lacks is refused as written and the
/// isotropic one with `--lenient`.
#[test]
fn heterogeneous_media_read_their_grids() {
    let dir = temp_dir("mitsuba-heterogeneous");
    // A 2 x 1 x 1 grid of one channel in the box (0, 0, 0)-(1, 1, 1): samples 1 and 3.
    let mut vol = b"VOL\x03".to_vec();
    for i in [1i32, 2, 1, 1, 1] {
        vol.extend(i.to_le_bytes());
    }
    for f in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 3.0] {
        vol.extend(f.to_le_bytes());
    }
    std::fs::write(dir.join("smoke.vol"), &vol).unwrap();
    let body = format!(
        "<medium type=\"heterogeneous\" id=\"smoke\">\n<volume name=\"density\" type=\"gridvolume\"><string name=\"filename\" value=\"smoke.vol\"/></volume>\n<volume name=\"albedo\" type=\"constvolume\"><spectrum name=\"value\" value=\"0.9\"/></volume>\n<float name=\"scale\" value=\"10\"/><string name=\"method\" value=\"woodcock\"/>\n<phase type=\"rayleigh\"/>\n</medium>\n{SENSOR}"
    );
    let xml = write(&dir, "smoke.xml", &scene("0.6.0", &body));
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("smoke.xml:6") && e.contains("rayleigh"), "{e}");
    let (doc, report) = read(&xml, true).unwrap();
    assert_eq!(text(&doc.root, "media.smoke.type"), "heterogeneous");
    assert!((vector(&doc.root, "media.smoke.sigma_t") - Vec3::splat(10.0)).length() < 1e-4);
    assert!((vector(&doc.root, "media.smoke.albedo") - Vec3::splat(0.9)).length() < 1e-4);
    assert_eq!(text(&doc.root, "media.smoke.density.samples"), "corners");
    assert_eq!(text(&doc.root, "media.smoke.density.outside"), "zero");
    assert!(text(&doc.root, "media.smoke.density.file").ends_with("smoke.vol"));
    assert_eq!(text(&doc.root, "media.smoke.phase"), "isotropic");
    assert!(
        report
            .left_out
            .iter()
            .any(|w| w.contains("smoke.xml:6") && w.contains("rayleigh")),
        "{:?}",
        report.left_out
    );
    // Mitsuba 3: the grid on its unit cube under `to_world`, and the medium only in that
    // box (a constant extinction too: a one-sample grid in its box).
    let body = format!(
        "<medium type=\"heterogeneous\" id=\"smoke\">\n<volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"smoke.vol\"/><transform name=\"to_world\"><scale value=\"2\"/></transform></volume>\n<rgb name=\"albedo\" value=\"0.5, 0.6, 0.7\"/><float name=\"scale\" value=\"4\"/></medium>\n<medium type=\"heterogeneous\" id=\"fog\"><volume name=\"sigma_t\" type=\"constvolume\"><rgb name=\"value\" value=\"1, 2, 3\"/></volume></medium>\n{SENSOR}"
    );
    let xml = write(&dir, "smoke3.xml", &scene("3.0.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(text(&doc.root, "media.smoke.density.outside"), "box");
    assert!((number(&doc.root, "media.smoke.density.transform.matrix.0") - 2.0).abs() < 1e-9);
    assert!((vector(&doc.root, "media.smoke.sigma_t") - Vec3::splat(4.0)).length() < 1e-4);
    assert!((vector(&doc.root, "media.fog.sigma_t") - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-4);
    assert_eq!(text(&doc.root, "media.fog.density.outside"), "box");
    assert!((vector(&doc.root, "media.fog.albedo") - Vec3::splat(0.75)).length() < 1e-4);
    // `mirror` reads as `clamp` in the extinction volume (the medium is only in its box),
    // not in an albedo volume, which may be looked up beyond its own.
    let wrap = "<string name=\"wrap_mode\" value=\"mirror\"/>";
    let grid = |name: &str| {
        format!(
            "<volume name=\"{name}\" type=\"gridvolume\"><string name=\"filename\" value=\"smoke.vol\"/>{wrap}</volume>"
        )
    };
    let body = format!(
        "<medium type=\"heterogeneous\" id=\"smoke\">{}</medium>\n{SENSOR}",
        grid("sigma_t")
    );
    let xml = write(&dir, "mirror.xml", &scene("3.0.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    assert!(text(&doc.root, "media.smoke.density.file").ends_with("smoke.vol"));
    let body = format!(
        "<medium type=\"heterogeneous\" id=\"smoke\">{}{}</medium>\n{SENSOR}",
        grid("sigma_t"),
        grid("albedo")
    );
    let xml = write(&dir, "mirror-albedo.xml", &scene("3.0.0", &body));
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("albedo") && e.contains("wrap mode"), "{e}");
    // A grid in a homogeneous medium (Mitsuba 3's textured albedo): a heterogeneous medium of
    // density 1 wherever the medium is (not only in the grid's box), the albedo looked up on
    // the grid, its `repeat` kept.
    let milk = |wrap: &str| {
        format!(
            "<medium type=\"homogeneous\" id=\"milk\"><volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"smoke.vol\"/><string name=\"wrap_mode\" value=\"{wrap}\"/></volume><rgb name=\"sigma_t\" value=\"1\"/><float name=\"scale\" value=\"2\"/></medium>\n{SENSOR}"
        )
    };
    let xml = write(&dir, "milk.xml", &scene("3.0.0", &milk("repeat")));
    let (doc, report) = read(&xml, false).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert_eq!(text(&doc.root, "media.milk.type"), "heterogeneous");
    assert_eq!(number(&doc.root, "media.milk.density"), 1.0);
    assert!((vector(&doc.root, "media.milk.sigma_t") - Vec3::splat(2.0)).length() < 1e-6);
    assert!(text(&doc.root, "media.milk.albedo.file").ends_with("smoke.vol"));
    assert_eq!(text(&doc.root, "media.milk.albedo.outside"), "repeat");
    foton_loader::load_with(&xml, &[], &[], false).unwrap();
    // Mitsuba 3's volume texture: its grid, looked up where the surface is.
    let body = format!(
        "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"volume\" name=\"reflectance\"><volume type=\"gridvolume\" name=\"volume\"><string name=\"filename\" value=\"smoke.vol\"/></volume></texture></bsdf></shape>\n{SENSOR}"
    );
    let xml = write(&dir, "volume-texture.xml", &scene("3.0.0", &body));
    let (doc, report) = read(&xml, false).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let m = text(&doc.root, "shapes.0.material");
    assert_eq!(
        text(&doc.root, &format!("materials.{m}.reflectance.type")),
        "volume"
    );
    assert!(
        text(&doc.root, &format!("materials.{m}.reflectance.volume.file")).ends_with("smoke.vol")
    );
    foton_loader::load_with(&xml, &[], &[], false).unwrap();
    // Its grid's lookup is a medium's: a nearest lookup is refused (--lenient: left out).
    let nearest = body.replace(
        "value=\"smoke.vol\"/></volume>",
        "value=\"smoke.vol\"/><string name=\"filter_type\" value=\"nearest\"/></volume>",
    );
    let xml = write(&dir, "volume-texture.xml", &scene("3.0.0", &nearest));
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("trilinear"), "{e}");
    // A wrap mode foton does not look an albedo up with: the grid's mean, said.
    let xml = write(&dir, "milk.xml", &scene("3.0.0", &milk("mirror")));
    assert!(read(&xml, false).is_err());
    let (doc, report) = read(&xml, true).unwrap();
    assert!((vector(&doc.root, "media.milk.sigma_s").x - 4.0).abs() < 1e-4);
    assert!(
        report.left_out.iter().any(|w| w.contains("milk.xml:2")),
        "{:?}",
        report.left_out
    );
    let xml = write(
        &dir,
        "smoke.xml",
        &scene(
            "0.6.0",
            &format!(
                "<medium type=\"heterogeneous\" id=\"smoke\">\n<volume name=\"density\" type=\"gridvolume\"><string name=\"filename\" value=\"smoke.vol\"/></volume>\n</medium>\n{SENSOR}"
            ),
        ),
    );
    std::fs::write(dir.join("smoke.vol"), &vol[..30]).unwrap();
    let e = read(&xml, true).unwrap_err();
    assert!(
        e.contains("smoke.vol") && e.contains("ends inside its header"),
        "{e}"
    );
}

/// A texture where foton takes a constant (a rough plastic's roughness) is refused as
/// written and, with `--lenient`, rendered with its mean, said in the report; an area
/// emitter's radiance takes the texture itself.
#[test]
fn lenient_textures_where_foton_takes_constants_are_their_means() {
    let dir = temp_dir("mitsuba-textured-constants");
    let checker = |name: &str, a: f64, b: f64| {
        format!(
            "<texture type=\"checkerboard\" name=\"{name}\"><rgb name=\"color0\" value=\"{a}\"/><rgb name=\"color1\" value=\"{b}\"/></texture>"
        )
    };
    let body = format!(
        "<shape type=\"sphere\">\n<emitter type=\"area\">{}</emitter>\n<bsdf type=\"roughplastic\" id=\"metal\">{}</bsdf>\n</shape>\n{SENSOR}",
        checker("radiance", 2.0, 4.0),
        checker("alpha", 0.1, 0.3)
    );
    let xml = write(&dir, "textured.xml", &scene("3.0.0", &body));
    let e = read(&xml, false).unwrap_err();
    assert!(e.contains("textured.xml:4") && e.contains("`alpha`"), "{e}");
    let (doc, report) = read(&xml, true).unwrap();
    let Value::Array(shapes) = &node(&doc.root, "shapes").value else {
        panic!("shapes")
    };
    let Value::Table(sphere) = &shapes[0].value else {
        panic!("a shape")
    };
    let Value::Table(emission) = &sphere.get("emission").unwrap().value else {
        panic!("a texture table")
    };
    assert!(matches!(&emission.get("type").unwrap().value, Value::Str(t) if t == "checkerboard"));
    assert!((number(&doc.root, "materials.metal.alpha") - 0.2).abs() < 1e-12);
    assert_eq!(report.left_out.len(), 1, "{:?}", report.left_out);
    // roughconductor and roughdielectric take the texture itself.
    let body = format!(
        "<shape type=\"sphere\">\n<bsdf type=\"roughconductor\" id=\"metal\">{}</bsdf>\n</shape>\n{SENSOR}",
        checker("alpha", 0.1, 0.3)
    );
    let xml = write(&dir, "textured-metal.xml", &scene("3.0.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    let Value::Table(alpha) = &node(&doc.root, "materials.metal.alpha").value else {
        panic!("a texture table")
    };
    assert!(matches!(&alpha.get("type").unwrap().value, Value::Str(t) if t == "checkerboard"));
}

/// A `<default>` inside an object (Mitsuba 0.6 and 3 read it there too) defines its name as
/// one at the top does; `-D` still wins.
#[test]
fn a_default_inside_an_object_defines_its_name() {
    let dir = temp_dir("mitsuba-nested-default");
    let body = format!(
        "<bsdf type=\"roughplastic\" id=\"plate\">\n<default name=\"a\" value=\"0.25\"/>\n<float name=\"alpha\" value=\"$a\"/>\n</bsdf>\n<shape type=\"sphere\"><ref id=\"plate\"/></shape>\n{SENSOR}"
    );
    let xml = write(&dir, "nested.xml", &scene("0.6.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    assert_eq!(number(&doc.root, "materials.plate.alpha"), 0.25);
    let (doc, _) = read_xml(&xml, &["a=0.5".to_string()], false).unwrap();
    assert_eq!(number(&doc.root, "materials.plate.alpha"), 0.5);
}

/// The specular manifold sampling fork's hints (on shapes and emitters) choose what its
/// caustic integrators connect: read, with a note, in a file that opens as written.
#[test]
fn manifold_sampling_hints_are_noted() {
    let dir = temp_dir("mitsuba-sms-hints");
    let body = format!(
        "<shape type=\"sphere\"><boolean name=\"caustic_caster_single\" value=\"true\"/>\n<emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/><boolean name=\"caustic_emitter_single\" value=\"true\"/></emitter></shape>\n{SENSOR}"
    );
    let xml = write(&dir, "hints.xml", &scene("2.0.0", &body));
    let (_, report) = read(&xml, false).unwrap();
    let noted = |h: &str| {
        report
            .notes
            .iter()
            .any(|n| n.contains(h) && n.contains("manifold"))
    };
    assert!(
        noted("caustic_caster_single") && noted("caustic_emitter_single"),
        "{:?}",
        report.notes
    );
}

/// Mitsuba 3's `has_spectral_extinction` = false: a hint its volpath takes to treat sigma_t as
/// one value, exact where sigma_t is grey (read silently), not otherwise (a warning).
#[test]
fn the_spectral_extinction_hint_warns_only_where_it_changes_mitsubas_image() {
    let dir = temp_dir("mitsuba-spectral-extinction");
    let medium = |sigma_t: &str| {
        format!(
            "<medium type=\"homogeneous\" id=\"fog\"><rgb name=\"sigma_t\" value=\"{sigma_t}\"/>\n<boolean name=\"has_spectral_extinction\" value=\"false\"/></medium>\n{SENSOR}\n<shape type=\"sphere\"><ref name=\"interior\" id=\"fog\"/><bsdf type=\"null\"/></shape>"
        )
    };
    let xml = write(&dir, "grey.xml", &scene("3.0.0", &medium("0.5")));
    let (_, report) = read(&xml, false).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let xml = write(&dir, "coloured.xml", &scene("3.0.0", &medium("0.5, 1, 2")));
    let (_, report) = read(&xml, false).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("coloured.xml:3") && w.contains("has_spectral_extinction")),
        "{:?}",
        report.warnings
    );
}

/// Mitsuba 3's `rawconstant` texture (a float or a vector, no colour conversion) is foton's
/// `constant` texture of that value.
#[test]
fn rawconstant_textures_are_constants() {
    let dir = temp_dir("mitsuba-rawconstant");
    for (value, want) in [
        ("<float name=\"value\" value=\"0.25\"/>", [0.25, 0.25, 0.25]),
        (
            "<vector name=\"value\" value=\"0.5, 0.5, 1.0\"/>",
            [0.5, 0.5, 1.0],
        ),
    ] {
        let body = format!(
            "{SENSOR}\n<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"rawconstant\" name=\"reflectance\">{value}</texture></bsdf></shape>"
        );
        let xml = write(&dir, "raw.xml", &scene("3.0.0", &body));
        let (doc, _) = read(&xml, false).unwrap();
        let material = text(&doc.root, "shapes.0.material");
        let reflectance = format!("materials.{material}.reflectance");
        assert_eq!(text(&doc.root, &format!("{reflectance}.type")), "constant");
        let Value::Array(v) = &node(&doc.root, &format!("{reflectance}.value")).value else {
            panic!("value")
        };
        let got: Vec<f64> = v.iter().map(|n| n.value.as_f64().unwrap()).collect();
        assert_eq!(got, want);
    }
}

/// A property whose value is a `$name` no `<default>` or `-D` gives (Mitsuba's documentation
/// scenes leave `$spp` to a script) is left out with a warning: its plugin's default stands.
/// A plugin type without a value stays an error.
#[test]
fn a_value_without_a_default_leaves_its_default() {
    let dir = temp_dir("mitsuba-unresolved-value");
    let sensor = r#"<sensor type="perspective">
<transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
<sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
</sensor>"#;
    let xml = write(&dir, "spp.xml", &scene("3.0.0", sensor));
    let (doc, report) = read(&xml, false).unwrap();
    // Mitsuba's independent sampler takes 4 samples unless told.
    assert_eq!(number(&doc.root, "render.spp"), 4.0);
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("spp.xml:") && w.contains("`$spp` has no <default>")),
        "{:?}",
        report.warnings
    );
    assert!(report.left_out.is_empty(), "{:?}", report.left_out);
    let (doc, _) = read_xml(&xml, &["spp=3".to_string()], false).unwrap();
    assert_eq!(number(&doc.root, "render.spp"), 3.0);
    let xml = write(
        &dir,
        "type.xml",
        &scene(
            "3.0.0",
            &format!("<bsdf type=\"$kind\" id=\"a\"/>\n{SENSOR}"),
        ),
    );
    let err = read(&xml, false).unwrap_err();
    assert!(err.contains("`$kind`: no <default"), "{err}");
}

/// The integrators of Mitsuba's forks that estimate the image of one of Mitsuba's own (path
/// guiding, EARS, specular manifold sampling; a fork's VCM) open as written, rendered by the
/// foton plugin that converges to the same image, with a note; their own parameters are
/// warnings, the common ones read as Mitsuba's path tracer reads them.
#[test]
fn fork_integrators_render_by_the_estimator_they_share() {
    let dir = temp_dir("mitsuba-fork-integrators");
    let cases = [
        (
            r#"<integrator type="guided_path"><integer name="maxDepth" value="8"/><string name="budgetType" value="spp"/></integrator>"#,
            "path",
            Some(7.0),
            "budget_type",
        ),
        (
            r#"<integrator type="recursive_path"><float name="budget" value="60"/></integrator>"#,
            "path",
            None,
            "budget",
        ),
        (
            r#"<integrator type="vcm"><integer name="maxDepth" value="6"/><boolean name="enableVM" value="true"/></integrator>"#,
            "vcm",
            Some(5.0),
            "",
        ),
        (
            r#"<integrator type="vcm"><boolean name="enableVM" value="false"/></integrator>"#,
            "bdpt",
            None,
            "",
        ),
    ];
    for (i, (integrator, plugin, depth, own)) in cases.into_iter().enumerate() {
        let xml = write(
            &dir,
            &format!("fork{i}.xml"),
            &scene("0.6.0", &format!("{integrator}\n{SENSOR}")),
        );
        let (doc, report) = read(&xml, false).unwrap_or_else(|e| panic!("{integrator}: {e}"));
        assert!(
            matches!(&node(&doc.root, "render.integrator").value, Value::Str(p) if p == plugin),
            "{integrator}"
        );
        if let Some(depth) = depth {
            assert_eq!(number(&doc.root, "render.max_depth"), depth, "{integrator}");
        }
        assert!(
            report
                .notes
                .iter()
                .any(|n| n.contains("fork of Mitsuba") && n.contains(plugin)),
            "{:?}",
            report.notes
        );
        if !own.is_empty() {
            assert!(
                report
                    .warnings
                    .iter()
                    .any(|w| w.contains(&format!("`{own}`")) && w.contains("fork's integrator")),
                "{:?}",
                report.warnings
            );
        }
    }
    // A fork's integrator that renders something else stays unknown.
    let xml = write(
        &dir,
        "field.xml",
        &scene(
            "0.6.0",
            &format!("<integrator type=\"meanCurvature\"/>\n{SENSOR}"),
        ),
    );
    let err = read(&xml, false).unwrap_err();
    assert!(err.contains("unknown integrator"), "{err}");
}

/// lajolla's `disneybsdf` (a course renderer's Mitsuba 0.6 dialect) is Mitsuba 3's principled
/// BSDF under other names: specularTransmission and specularTint are spec_trans and
/// spec_tint; a specular that eta implies is dropped silently, another is a warning, and so is
/// a subsurface blend (principled has none).
#[test]
fn lajolla_disney_bsdf_is_the_principled_bsdf() {
    let dir = temp_dir("mitsuba-disney");
    let bsdf = |specular: f64| {
        format!(
            "<bsdf type=\"disneybsdf\" id=\"d\"><rgb name=\"baseColor\" value=\"0.8 0.6 0.2\"/><float name=\"specularTransmission\" value=\"0.25\"/><float name=\"specularTint\" value=\"0.75\"/><float name=\"subsurface\" value=\"0.5\"/><float name=\"metallic\" value=\"0.5\"/><float name=\"eta\" value=\"1.5\"/><float name=\"specular\" value=\"{specular}\"/></bsdf>\n<shape type=\"sphere\"><ref id=\"d\"/></shape>\n{SENSOR}"
        )
    };
    let xml = write(&dir, "disney.xml", &scene("0.5.0", &bsdf(0.5)));
    let (doc, report) = read(&xml, false).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(text(&doc.root, "materials.d.type"), "principled");
    assert_eq!(number(&doc.root, "materials.d.spec_trans"), 0.25);
    assert_eq!(number(&doc.root, "materials.d.spec_tint"), 0.75);
    assert_eq!(number(&doc.root, "materials.d.metallic"), 0.5);
    assert_eq!(number(&doc.root, "materials.d.eta"), 1.5);
    let warned = |r: &Report, needle: &str| r.warnings.iter().any(|w| w.contains(needle));
    assert!(
        warned(&report, "`subsurface` = 0.5"),
        "{:?}",
        report.warnings
    );
    assert!(!warned(&report, "`specular`"), "{:?}", report.warnings);
    assert!(
        report.notes.iter().any(|n| n.contains("principled")),
        "{:?}",
        report.notes
    );
    let xml = write(&dir, "disney-specular.xml", &scene("0.5.0", &bsdf(0.3)));
    let (_, report) = read(&xml, false).unwrap_or_else(|e| panic!("{e}"));
    assert!(warned(&report, "`specular` = 0.3"), "{:?}", report.warnings);
}

/// Mitsuba 3 does not normalise a `<rotate>` axis: about (1, 2, 0.5) by 45 degrees its matrix
/// is c I + (1 - c) a a^T + s [a]x, which also scales (columns as Mitsuba 3.9.1 prints them:
/// the first is (1, 0.93934, -1.26777)); a warning says so. Mitsuba 0.6 normalises it.
#[test]
fn a_rotation_about_a_long_axis_scales_in_mitsuba_3_only() {
    let dir = temp_dir("mitsuba-rotate-axis");
    let body = format!(
        "<shape type=\"rectangle\"><transform name=\"to_world\"><rotate x=\"1\" y=\"2\" z=\"0.5\" angle=\"45\"/></transform></shape>\n{SENSOR}"
    );
    let xml = write(&dir, "three.xml", &scene("3.0.0", &body));
    let (doc, report) = read(&xml, false).unwrap();
    let u = vector(&doc.root, "shapes.0.u");
    assert!(
        (u - 2.0 * Vec3::new(1.0, 0.93934, -1.26777)).length() < 1e-4,
        "{u}"
    );
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("three.xml:2") && w.contains("does not normalise")),
        "{:?}",
        report.warnings
    );
    let xml = write(&dir, "old.xml", &scene("0.5.0", &body));
    let (doc, _) = read(&xml, false).unwrap();
    assert!((vector(&doc.root, "shapes.0.u").length() - 2.0).abs() < 1e-5);
}
