//! Mitsuba 3 XML scenes (issue 10): the reader's conventions against hand-written TOML
//! equivalents, `foton convert` round trips, errors with file:line, `--lenient`, and the two
//! scenes of Mitsuba's tutorials from `../shared/scenes/mitsuba` rendered by every integrator
//! that can.

use foton_loader::image::read_image;
use foton_tests::{Run, foton, foton_with_plugins, repo_root, temp_dir, write};
use std::path::{Path, PathBuf};

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

pub(crate) fn ok(run: &Run) {
    assert_eq!(
        run.code, 0,
        "stdout:\n{}\nstderr:\n{}",
        run.stdout, run.stderr
    );
}

pub(crate) fn render(scene: &Path, out: &Path, extra: &[&str]) -> Run {
    let mut args = vec!["render", s(scene), "-q", "-o", s(out)];
    args.extend(extra);
    foton_with_plugins(&args)
}

/// A scene exercising the reader: defaults and `$` substitution, `ref`/`id`, `include`, each
/// transform operation, named iors, twosided, the default BSDF, rectangle, sphere, cube and an
/// OBJ placed by a matrix, area, point, spot, directional and constant emitters.
const XML: &str = r#"<scene version="3.0.0">
    <default name="spp" value="4"/>
    <default name="res" value="32"/>
    <integrator type="path">
        <integer name="max_depth" value="4"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <string name="fov_axis" value="x"/>
        <transform name="to_world">
            <lookat origin="0, 1, 4" target="0, 1, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="24"/>
            <rfilter type="gaussian"/>
        </film>
    </sensor>
    <include filename="materials.xml"/>
    <bsdf type="twosided" id="white">
        <bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.7, 0.7"/></bsdf>
    </bsdf>
    <shape type="rectangle">
        <transform name="to_world">
            <rotate x="1" angle="-90"/>
            <scale value="2"/>
        </transform>
        <ref id="white"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <rotate x="1" angle="90"/>
            <scale x="0.3" y="1" z="0.3"/>
            <translate y="1.95"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="10, 9, 8"/></emitter>
    </shape>
    <shape type="sphere">
        <transform name="to_world">
            <scale value="0.3"/>
            <translate x="-0.6" y="0.3" z="0"/>
        </transform>
        <ref id="glass"/>
    </shape>
    <shape type="cube">
        <transform name="to_world">
            <scale value="0.2"/>
            <translate x="0.6" y="0.2"/>
        </transform>
        <ref id="mirror"/>
    </shape>
    <shape type="obj">
        <string name="filename" value="cube.obj"/>
        <boolean name="face_normals" value="true"/>
        <transform name="to_world">
            <matrix value="0.1 0 0 0  0 0.1 0 0.8  0 0 0.1 0.5  0 0 0 1"/>
        </transform>
    </shape>
    <emitter type="point">
        <point name="position" x="0.5" y="1.5" z="1"/>
        <rgb name="intensity" value="0.5"/>
    </emitter>
    <emitter type="spot">
        <transform name="to_world">
            <lookat origin="-1, 1.5, 1" target="-0.6, 0, 0" up="0, 1, 0"/>
        </transform>
        <rgb name="intensity" value="3"/>
        <float name="cutoff_angle" value="25"/>
    </emitter>
    <emitter type="directional">
        <vector name="direction" x="0.2" y="-1" z="-0.3"/>
        <rgb name="irradiance" value="0.4"/>
    </emitter>
    <emitter type="constant">
        <rgb name="radiance" value="0.05"/>
    </emitter>
</scene>
"#;

const MATERIALS: &str = r#"<scene version="3.0.0">
    <bsdf type="dielectric" id="glass">
        <string name="int_ior" value="water"/>
        <float name="ext_ior" value="1.0"/>
    </bsdf>
    <bsdf type="conductor" id="mirror"/>
</scene>
"#;

/// The TOML the XML above means under Mitsuba's conventions, written by hand.
const TOML: &str = r#"
[render]
integrator = "path"
spp = 4
seed = 0
max_depth = 3

[integrators.path]
rr_depth = 4

[film]
width = 32
height = 24
output = "scene.exr"
filter = { type = "gaussian", stddev = 0.5 }

[camera]
position = [0, 1, 4]
look_at = [0, 1, 0]
up = [0, 1, 0]
fov = 40
fov_axis = "x"

[materials.white]
type = "diffuse"
reflectance = [0.7, 0.7, 0.7]
[materials.black]
type = "diffuse"
reflectance = [0, 0, 0]
twosided = false
[materials.glass]
type = "dielectric"
ior = 1.333
[materials.mirror]
type = "mirror"
[materials.default]
type = "diffuse"
twosided = false

# The floor: [-2, 2]^2 at y = 0, normal up.
[[shapes]]
type = "quad"
origin = [-2, 0, 2]
u = [4, 0, 0]
v = [0, 0, -4]
material = "white"

# The light: 0.6 x 0.6 at y = 1.95, emitting down.
[[shapes]]
type = "quad"
origin = [-0.3, 1.95, -0.3]
u = [0.6, 0, 0]
v = [0, 0, 0.6]
material = "black"
emission = [10, 9, 8]

[[shapes]]
type = "sphere"
center = [-0.6, 0.3, 0]
radius = 0.3
material = "glass"

[[shapes]]
type = "mesh"
file = "box.obj"
material = "mirror"

[[shapes]]
type = "mesh"
file = "cube.obj"
transform = { translate = [0, 0.8, 0.5], scale = 0.1 }
material = "default"

[[lights]]
type = "point"
position = [0.5, 1.5, 1]
intensity = [0.5, 0.5, 0.5]

[[lights]]
type = "spot"
position = [-1, 1.5, 1]
look_at = [-0.6, 0, 0]
intensity = [3, 3, 3]
cutoff_angle = 25

[[lights]]
type = "directional"
direction = [0.2, -1, -0.3]
irradiance = [0.4, 0.4, 0.4]

[[lights]]
type = "constant"
radiance = [0.05, 0.05, 0.05]
"#;

/// The cube of the XML's `cube` shape ([-1, 1]^3 scaled by 0.2, moved to (0.6, 0.2, 0)).
const BOX_OBJ: &str = "v 0.4 0 -0.2\nv 0.8 0 -0.2\nv 0.8 0.4 -0.2\nv 0.4 0.4 -0.2\n\
v 0.4 0 0.2\nv 0.8 0 0.2\nv 0.8 0.4 0.2\nv 0.4 0.4 0.2\n\
f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";

pub(crate) fn scene_folder(name: &str) -> PathBuf {
    let dir = temp_dir(name);
    write(&dir, "scene.xml", XML);
    write(&dir, "materials.xml", MATERIALS);
    write(&dir, "box.obj", BOX_OBJ);
    std::fs::copy(
        repo_root().join("scenes/meshes/cube.obj"),
        dir.join("cube.obj"),
    )
    .unwrap();
    dir
}

pub(crate) fn mean(path: &Path) -> [f64; 3] {
    let (_, _, px) = read_image(path).unwrap();
    let mut m = [0.0; 3];
    for p in &px {
        for c in 0..3 {
            m[c] += p[c] as f64 / px.len() as f64;
        }
    }
    m
}

/// The XML renders as the TOML written by hand from Mitsuba's documented conventions (camera
/// from lookat, rectangle and cube from their transforms and normals, max_depth 4 segments =
/// 3 bounces, named iors, twosided, emitters): equal in the mean within 2% (the cube is six
/// quads in one and a mesh in the other, and float rounding of transformed points differs, so
/// samples do not match bit for bit). And the XML converted to TOML renders bit for bit as the
/// XML.
#[test]
fn xml_renders_as_its_toml_meaning_and_convert_round_trips() {
    let dir = scene_folder("mitsuba-conventions");
    let (xml, toml) = (dir.join("scene.xml"), write(&dir, "hand.toml", TOML));
    let (a, b) = (dir.join("xml.exr"), dir.join("toml.exr"));
    let spp = ["--spp", "256"];
    ok(&render(&xml, &a, &spp));
    ok(&render(&toml, &b, &spp));
    let (ma, mb) = (mean(&a), mean(&b));
    for c in 0..3 {
        assert!(
            (ma[c] - mb[c]).abs() <= 0.02 * mb[c],
            "channel {c}: xml {} vs toml {}",
            ma[c],
            mb[c]
        );
    }
    assert!(mb[0] > 0.01, "a black image proves nothing: {mb:?}");

    let converted = dir.join("converted.toml");
    let run = foton(&["convert", s(&xml), "-o", s(&converted), "-D", "res=20"]);
    ok(&run);
    let (c1, c2) = (dir.join("c1.exr"), dir.join("c2.exr"));
    ok(&render(&xml, &c1, &["-D", "res=20"]));
    ok(&render(&converted, &c2, &[]));
    assert!(std::fs::read(&c1).unwrap() == std::fs::read(&c2).unwrap());
    // Into another folder: the meshes are named relative to the new file (a folder of
    // scenes moves as a whole), and the image is written beside it.
    let elsewhere = temp_dir("mitsuba-convert-elsewhere").join("scene.toml");
    ok(&foton(&["convert", s(&xml), "-o", s(&elsewhere)]));
    let text = std::fs::read_to_string(&elsewhere).unwrap();
    let full = std::fs::canonicalize(&dir).unwrap();
    let files = text.lines().filter(|l| l.starts_with("file"));
    assert!(files.clone().count() > 0, "{text}");
    assert!(
        files.clone().all(|l| !l.contains(full.to_str().unwrap())),
        "{text}"
    );
    assert!(text.contains("file = \"../"), "{text}");
    let c3 = dir.join("c3.exr");
    ok(&render(&elsewhere, &c3, &["--set", "film.width=20"]));
    assert!(std::fs::read(&c1).unwrap() == std::fs::read(&c3).unwrap());
}

/// Mitsuba's `max_depth` counts segments: 1 shows emitters only, 2 direct light (as
/// `direct`), -1 is unbounded.
#[test]
fn max_depth_counts_segments() {
    let dir = scene_folder("mitsuba-depth");
    let xml = dir.join("scene.xml");
    let check = |depth: &str, expected: &str| {
        let text = XML.replace(
            "<integer name=\"max_depth\" value=\"4\"/>",
            &format!("<integer name=\"max_depth\" value=\"{depth}\"/>"),
        );
        write(&dir, "scene.xml", &text);
        let run = foton_with_plugins(&["check", s(&xml)]);
        ok(&run);
        assert!(run.stdout.contains(expected), "{depth}: {}", run.stdout);
    };
    check("1", "max_depth 0 ");
    check("2", "max_depth 1 ");
    check("-1", "max_depth 65536 ");
    let text = XML.replace(
        "<integrator type=\"path\">\n        <integer name=\"max_depth\" value=\"4\"/>\n    </integrator>",
        "<integrator type=\"direct\"/>",
    );
    write(&dir, "scene.xml", &text);
    let run = foton_with_plugins(&["check", s(&xml)]);
    ok(&run);
    assert!(run.stdout.contains("max_depth 1 "), "{}", run.stdout);
    // Mitsuba 3's differentiable integrators render their primal image, the path tracer's
    // (their max_depth defaults to 6), direct_projective's direct lighting's.
    for (integrator, expected) in [
        ("<integrator type=\"prb\"/>", "max_depth 5 "),
        (
            "<integrator type=\"prb_projective\"><integer name=\"max_depth\" value=\"3\"/><integer name=\"sppi\" value=\"0\"/></integrator>",
            "max_depth 2 ",
        ),
        ("<integrator type=\"prbvolpath\"/>", "max_depth 5 "),
        ("<integrator type=\"direct_projective\"/>", "max_depth 1 "),
    ] {
        let text = XML.replace(
            "<integrator type=\"path\">\n        <integer name=\"max_depth\" value=\"4\"/>\n    </integrator>",
            integrator,
        );
        write(&dir, "scene.xml", &text);
        let run = foton_with_plugins(&["check", s(&xml)]);
        ok(&run);
        assert!(
            run.stdout.contains(expected) && run.stdout.contains("path"),
            "{integrator}: {}",
            run.stdout
        );
    }
}

/// What foton cannot render is an error naming the element, its type and file:line;
/// `--lenient` renders without it and lists it. Other bad input names its place too.
#[test]
fn unsupported_and_bad_xml_is_a_clear_error() {
    let dir = scene_folder("mitsuba-errors");
    let xml = dir.join("scene.xml");
    let out = dir.join("out.exr");
    let rough = XML
        .replace("<bsdf type=\"conductor\" id=\"mirror\"/>", "")
        .replace(
            "<ref id=\"mirror\"/>",
            "<bsdf type=\"hk\"><float name=\"thickness\" value=\"0.1\"/></bsdf>",
        );
    write(&dir, "scene.xml", &rough);
    let run = render(&xml, &out, &[]);
    assert_eq!(run.code, 1);
    for needle in [
        "scene.xml:",
        "<bsdf type=\"hk\">",
        "not supported yet",
        "--lenient",
    ] {
        assert!(run.stderr.contains(needle), "{needle}: {}", run.stderr);
    }
    assert!(!out.exists());
    let run = render(&xml, &out, &["--lenient"]);
    ok(&run);
    assert!(run.stderr.contains("left out: "), "{}", run.stderr);
    assert!(run.stderr.contains("hk"), "{}", run.stderr);
    std::fs::remove_file(&out).unwrap();

    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            // A reference's id without a value (a property's value is left out instead).
            XML.replace("<ref id=\"white\"/>", "<ref id=\"$nothing\"/>"),
            vec!["$nothing", "-D nothing"],
        ),
        (
            XML.replace("version=\"3.0.0\"", "version=\"4.0.0\""),
            vec!["scene.xml:1:", "XML error", "expected a Mitsuba version"],
        ),
        (
            XML.replace("</sensor>", "</sensr>"),
            vec!["scene.xml:", "XML"],
        ),
        (
            XML.replace(
                "<float name=\"fov\" value=\"40\"/>",
                "<float name=\"fov\" value=\"wide\"/>",
            ),
            vec!["scene.xml:8:", "`fov`", "wide"],
        ),
        (
            XML.replace("<ref id=\"white\"/>", "<ref id=\"whit\"/>"),
            vec!["whit"],
        ),
    ];
    for (text, needles) in cases {
        write(&dir, "scene.xml", &text);
        let run = render(&xml, &out, &[]);
        assert_eq!(run.code, 1, "{needles:?}: {}", run.stderr);
        for needle in needles {
            assert!(run.stderr.contains(needle), "{needle}: {}", run.stderr);
        }
        assert!(!out.exists());
    }
    // An unknown named ior, in the included file: the error names that file.
    write(&dir, "scene.xml", XML);
    write(
        &dir,
        "materials.xml",
        &MATERIALS.replace("water", "unobtainium"),
    );
    let run = render(&xml, &out, &[]);
    assert_eq!(run.code, 1);
    for needle in ["materials.xml:", "unobtainium", "bk7"] {
        assert!(run.stderr.contains(needle), "{needle}: {}", run.stderr);
    }
    // -D is for XML scenes.
    let toml = write(&dir, "hand.toml", TOML);
    let run = render(&toml, &out, &["-D", "spp=3"]);
    assert_eq!(run.code, 1);
    assert!(run.stderr.contains("--set"), "{}", run.stderr);
}

/// The tutorials' two scenes, unchanged, from `../shared/scenes/mitsuba`: the Cornell box
/// renders with path, photon and sppm, which agree in the mean over the image within their
/// noise and bias (5%); the teapot (direct light only) with path and sppm, which agree within
/// 5% too. The folder is beside the repository in CI, which sets FOTON_REQUIRE_SHARED so that
/// its absence fails there; a clone elsewhere says that it skips.
#[test]
fn the_shared_mitsuba_scenes_render_with_every_integrator() {
    let shared = repo_root().join("../shared/scenes/mitsuba");
    if !shared.join("cbox.xml").exists() {
        assert!(
            std::env::var_os("FOTON_REQUIRE_SHARED").is_none(),
            "{} is missing",
            shared.display()
        );
        eprintln!("skipped: {} is not beside this clone", shared.display());
        return;
    }
    let dir = temp_dir("mitsuba-shared");
    let cbox = shared.join("cbox.xml");
    let small = ["-D", "res=32", "-D", "spp=64"];
    let path = dir.join("path.exr");
    ok(&render(&cbox, &path, &small));
    let reference = mean(&path);
    for (integrator, extra) in [
        (
            "photon",
            vec![
                "--set",
                "integrators.photon.global_photons=100000",
                "--set",
                "integrators.photon.caustic_photons=50000",
            ],
        ),
        (
            "sppm",
            vec![
                "--set",
                "integrators.sppm.iterations=24",
                "--set",
                "integrators.sppm.photons_per_iteration=20000",
            ],
        ),
    ] {
        let out = dir.join(format!("{integrator}.exr"));
        let mut args: Vec<&str> = small.to_vec();
        args.extend(["--integrator", integrator]);
        args.extend(extra.iter().copied());
        ok(&render(&cbox, &out, &args));
        let m = mean(&out);
        for c in 0..3 {
            assert!(
                (m[c] - reference[c]).abs() <= 0.05 * reference[c],
                "{integrator} channel {c}: {} vs path {}",
                m[c],
                reference[c]
            );
        }
    }
    let teapot = shared.join("teapot.xml");
    let (a, b) = (dir.join("teapot-path.exr"), dir.join("teapot-sppm.exr"));
    let small = ["-D", "res=32", "-D", "spp=16"];
    ok(&render(&teapot, &a, &small));
    let mut args = small.to_vec();
    args.extend([
        "--integrator",
        "sppm",
        "--set",
        "integrators.sppm.iterations=16",
    ]);
    ok(&render(&teapot, &b, &args));
    let (ma, mb) = (mean(&a), mean(&b));
    assert!(ma[0] > 0.01, "the teapot is black: {ma:?}");
    for c in 0..3 {
        assert!(
            (mb[c] - ma[c]).abs() <= 0.05 * ma[c].max(1e-3),
            "teapot channel {c}: sppm {} vs path {}",
            mb[c],
            ma[c]
        );
    }
}

/// The TOML mesh transform's `matrix` (what an XML `to_world` becomes): refused when it is
/// not affine, is singular, or comes with translate, rotate or scale.
#[test]
fn a_mesh_matrix_must_be_an_affine_placement() {
    let dir = scene_folder("mitsuba-matrix");
    let base = TOML.replace(
        "transform = { translate = [0, 0.8, 0.5], scale = 0.1 }",
        "TRANSFORM",
    );
    for (transform, needle) in [
        (
            "transform = { matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1] }",
            "last row",
        ),
        (
            "transform = { matrix = [1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] }",
            "singular",
        ),
        (
            "transform = { matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], scale = 2 }",
            "either `matrix`",
        ),
        ("transform = { matrix = [1, 0, 0] }", "16 numbers"),
    ] {
        let scene = write(&dir, "m.toml", &base.replace("TRANSFORM", transform));
        let run = foton_with_plugins(&["check", s(&scene)]);
        assert_eq!(run.code, 1, "{transform}");
        assert!(
            run.stderr.contains(needle) && run.stderr.contains("m.toml:"),
            "{needle}: {}",
            run.stderr
        );
    }
    let scene = write(
        &dir,
        "m.toml",
        &base.replace(
            "TRANSFORM",
            "transform = { matrix = [0.1, 0, 0, 0, 0, 0.1, 0, 0.8, 0, 0, 0.1, 0.5, 0, 0, 0, 1] }",
        ),
    );
    ok(&foton_with_plugins(&["check", s(&scene)]));
}

/// The tools take XML scenes and their defines: a sweep over an XML scene with -D.
#[test]
fn sweep_takes_an_xml_scene_and_its_defines() {
    let dir = scene_folder("mitsuba-sweep");
    let out = dir.join("grid.png");
    let run = foton_with_plugins(&[
        "sweep",
        s(&dir.join("scene.xml")),
        "-D",
        "res=16",
        "--set",
        "render.spp=1,2",
        "-q",
        "-o",
        s(&out),
    ]);
    ok(&run);
    assert!(run.stdout.contains("2 cells (2 x 1)"), "{}", run.stdout);
    // Without the define the film is 32 wide: the grid is wider.
    let (w16, _, _) = read_image(&out).unwrap();
    ok(&foton_with_plugins(&[
        "sweep",
        s(&dir.join("scene.xml")),
        "--set",
        "render.spp=1,2",
        "-q",
        "-o",
        s(&out),
    ]));
    let (w32, _, _) = read_image(&out).unwrap();
    assert!(w32 > w16, "{w32} vs {w16}");
}

/// `foton compare` on an XML scene with -D: both integrators render the defined size.
#[test]
fn compare_takes_an_xml_scene_and_its_defines() {
    let dir = scene_folder("mitsuba-compare");
    let out = dir.join("cmp.png");
    let run = foton_with_plugins(&[
        "compare",
        s(&dir.join("scene.xml")),
        "--integrators",
        "path,sppm",
        "-D",
        "res=16",
        "--spp",
        "2",
        "--set",
        "integrators.sppm.iterations=2",
        "--set",
        "integrators.sppm.photons_per_iteration=1000",
        "-q",
        "-o",
        s(&out),
    ]);
    ok(&run);
    let (w, _, _) = read_image(&dir.join("cmp-path.exr")).unwrap();
    assert_eq!(w, 16);
}
