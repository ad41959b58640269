//! Bad input, values: a value of the wrong type or length, numbers that make no sense, OBJ
//! meshes that cannot be read, media and cameras in no well-defined medium. The helpers and
//! the base scene are bad_input.rs's.

use crate::bad_input::{
    BASE, FOG, QUAD, SPHERE, SceneFile, assert_bad_value, assert_error, edit, foton, scene_with,
    show,
};
use foton_tests::write;

// ---------------------------------------------------------------------------------------------
// Wrong type or length of a value
// ---------------------------------------------------------------------------------------------

#[test]
fn number_instead_of_an_rgb_array() {
    assert_bad_value(
        "reflectance-number",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = 2",
        "materials.white.reflectance",
        &["expected an array of 3 numbers", "found an integer `2`"],
    );
}

#[test]
fn rgb_array_of_the_wrong_length() {
    assert_bad_value(
        "reflectance-length",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [1, 2]",
        "materials.white.reflectance",
        &["expected an array of 3 numbers", "found 2 element(s)"],
    );
}

#[test]
fn array_with_a_non_number() {
    assert_bad_value(
        "center-string",
        "center = [0, 1, 0]",
        "center = [0, \"a\", 0]",
        "shapes[0].center",
        &["expected an array of 3 numbers"],
    );
}

#[test]
fn string_instead_of_a_number() {
    assert_bad_value(
        "radius-string",
        "radius = 0.5",
        "radius = \"big\"",
        "shapes[0].radius",
        &["expected a number", "found a string"],
    );
}

#[test]
fn float_instead_of_an_integer() {
    assert_bad_value(
        "spp-float",
        "spp = 1",
        "spp = 1.5",
        "render.spp",
        &["expected an integer", "found a float `1.5`"],
    );
}

#[test]
fn negative_integer() {
    assert_bad_value(
        "seed-negative",
        "seed = 3",
        "seed = -1",
        "render.seed",
        &["expected a non-negative integer", "-1"],
    );
}

#[test]
fn table_instead_of_a_string() {
    assert_bad_value(
        "material-table",
        "material = \"white\"",
        "material = { name = \"white\" }",
        "shapes[0].material",
        &["expected a string", "found a table"],
    );
}

#[test]
fn section_that_is_not_a_table() {
    // A root key, so before the first table header; the `[film]` table goes.
    let text = edit(BASE, "# A valid 8x8 test scene.\n", "film = 3\n");
    let text = edit(
        &text,
        "[film]\nwidth = 8\nheight = 8\noutput = \"out.png\"\n",
        "",
    );
    let scene = SceneFile::new("film-not-table", &text);
    scene.check_fails(
        "film = 3",
        "film",
        &["expected a table", "found an integer"],
    );
}

// ---------------------------------------------------------------------------------------------
// Numbers that make no sense
// ---------------------------------------------------------------------------------------------

#[test]
fn negative_radius() {
    assert_bad_value(
        "radius-negative",
        "radius = 0.5",
        "radius = -1",
        "shapes[0].radius",
        &["must be positive", "-1"],
    );
    assert_bad_value(
        "radius-zero",
        "radius = 0.5",
        "radius = 0",
        "shapes[0].radius",
        &["must be positive", "0"],
    );
}

#[test]
fn nan_and_infinite_numbers() {
    assert_bad_value(
        "radius-nan",
        "radius = 0.5",
        "radius = nan",
        "shapes[0].radius",
        &["expected a finite number", "NaN"],
    );
    assert_bad_value(
        "center-inf",
        "center = [0, 1, 0]",
        "center = [0, inf, 0]",
        "shapes[0].center",
        &["expected a finite number", "inf"],
    );
    assert_bad_value(
        "intensity-inf",
        "intensity = [1, 1, 1]",
        "intensity = [1, -inf, 1]",
        "lights[0].intensity",
        &["expected a finite number", "inf"],
    );
}

/// Core bug: `Properties::finite` checks the f64 before narrowing it to f32, so 1e40 passes
/// and becomes an infinite radius, on which the BVH builder (obvhs) panics.
#[test]
fn number_too_large_for_f32_radius() {
    assert_bad_value(
        "radius-huge",
        "radius = 0.5",
        "radius = 1e40",
        "shapes[0].radius",
        &["finite"],
    );
}

/// Core bug (same cause): a camera position of 1e39 becomes infinite and is accepted.
#[test]
fn number_too_large_for_f32_camera_position() {
    assert_bad_value(
        "position-huge",
        "position = [0, 1, 3.9]",
        "position = [0, 1e39, 3.9]",
        "camera.position",
        &["finite"],
    );
}

#[test]
fn reflectance_above_one_is_a_warning() {
    let scene = scene_with(
        "reflectance-above-one",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [1.5, 0.5, 0.5]",
    );
    let run = scene.check(&[]);
    assert_eq!(run.code, 0, "a warning, not an error:\n{}", show(&run));
    let warning = run
        .stderr
        .lines()
        .find(|l| l.starts_with("warning: "))
        .unwrap_or_else(|| panic!("no warning:\n{}", show(&run)));
    for needle in [
        scene.at("reflectance = [1.5"),
        "`materials.white.reflectance`".into(),
        "above 1".into(),
    ] {
        assert!(
            warning.contains(&needle),
            "the warning lacks {needle:?}:\n{}",
            show(&run)
        );
    }
    // It renders, with the warning.
    let run = scene.render(&[]);
    assert_eq!(run.code, 0, "{}", show(&run));
    assert!(run.stderr.contains("above 1"), "{}", show(&run));
}

#[test]
fn negative_reflectance_is_an_error() {
    assert_bad_value(
        "reflectance-negative",
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [0.5, -0.1, 0.5]",
        "materials.white.reflectance",
        &["expected non-negative values"],
    );
}

#[test]
fn non_positive_index_of_refraction() {
    let text = edit(BASE, "type = \"diffuse\"", "type = \"dielectric\"");
    let text = edit(&text, "reflectance = [0.5, 0.5, 0.5]", "ior = 0");
    let scene = SceneFile::new("ior-zero", &text);
    scene.check_fails("ior = 0", "materials.white.ior", &["must be positive"]);
}

#[test]
fn zero_area_quad() {
    // Parallel edges.
    let quad = edit(QUAD, "v = [0, 2, 0]", "v = [4, 0, 0]");
    let scene = scene_with("quad-parallel", SPHERE, &quad);
    scene.check_fails("v = [4, 0, 0]", "shapes[0].v", &["zero area"]);
    // A zero edge.
    let quad = edit(QUAD, "u = [2, 0, 0]", "u = [0, 0, 0]");
    let scene = scene_with("quad-zero", SPHERE, &quad);
    scene.check_fails("v = [0, 2, 0]", "shapes[0].v", &["zero area"]);
}

#[test]
fn field_of_view_outside_0_180() {
    for (i, fov) in ["0", "180", "-10", "200"].iter().enumerate() {
        assert_bad_value(
            &format!("fov-{i}"),
            "fov = 40",
            &format!("fov = {fov}"),
            "camera.fov",
            &["must be in (0, 180) degrees", &format!("found {fov}")],
        );
    }
    assert_bad_value(
        "fov-nan",
        "fov = 40",
        "fov = nan",
        "camera.fov",
        &["expected a finite number"],
    );
}

#[test]
fn film_width_or_height_zero() {
    assert_bad_value(
        "width-zero",
        "width = 8",
        "width = 0",
        "film.width",
        &["must be between 1 and 32768", "found 0"],
    );
    assert_bad_value(
        "height-zero",
        "height = 8",
        "height = 0",
        "film.height",
        &["must be between 1 and 32768", "found 0"],
    );
}

#[test]
fn samples_per_pixel_zero() {
    assert_bad_value(
        "spp-zero",
        "spp = 1",
        "spp = 0",
        "render.spp",
        &["must be at least 1"],
    );
    // From the command line: one message about the option, whatever the bad value (clap
    // would otherwise take `-4` for an unknown flag and advise `-- -4`).
    let scene = SceneFile::new("spp-zero-flag", BASE);
    for (value, words) in [
        ("0", "at least 1, not 0"),
        ("-4", "at least 1, not -4"),
        ("four", "expected a whole number"),
    ] {
        let run = scene.render(&["--spp", value]);
        assert_ne!(run.code, 0, "--spp {value} rendered:\n{}", show(&run));
        let errors: Vec<&str> = run
            .stderr
            .lines()
            .filter(|l| l.starts_with("error"))
            .collect();
        assert_eq!(
            errors.len(),
            1,
            "--spp {value}: one message:\n{}",
            show(&run)
        );
        assert!(
            errors[0].contains("--spp") && errors[0].contains(words),
            "--spp {value}:\n{}",
            show(&run)
        );
        assert!(!run.stderr.contains("tip:"), "{}", show(&run));
    }
}

/// A value set on the command line that nothing reads is an error (the user asked for it),
/// naming what it probably meant; the same key written in the file stays a warning (the test
/// above). Values for another integrator than the rendering one are checked by that one.
#[test]
fn set_keys_that_nothing_reads_are_errors() {
    let scene = SceneFile::new("set-typo", BASE);
    for (set, words) in [
        (
            "integrators.path.rr_dept=3",
            &[
                "--set integrators.path.rr_dept",
                "did you mean `integrators.path.rr_depth`",
            ][..],
        ),
        (
            "render.sppp=2",
            &["--set render.sppp", "did you mean `render.spp`"][..],
        ),
        (
            "film.colour=1",
            &[
                "--set film.colour",
                "neither the scene nor the integrator `path`",
            ][..],
        ),
        (
            "integrators.photon.kk=10",
            &[
                "--set integrators.photon.kk",
                "the integrator `photon`",
                "did you mean `integrators.photon.k`",
            ][..],
        ),
        (
            "integrators.pth.rr_depth=3",
            &[
                "--set integrators.pth.rr_depth",
                "no integrator plugin named `pth`",
            ][..],
        ),
    ] {
        let run = scene.render(&["--set", set]);
        assert_error(&run, words);
    }
    // Keys that are read are fine, also those of another integrator than the rendering one
    // (settings for several, switched with --integrator, as a file holds them).
    let run = scene.render(&[
        "--set",
        "integrators.photon.k=10",
        "--set",
        "integrators.path.rr_depth=3",
        "--set",
        "render.spp=1",
    ]);
    assert_eq!(run.code, 0, "{}", show(&run));
    // A sweep over a misspelt key renders nothing (it used to render identical cells).
    let out = scene.dir.join("sweep.png");
    let run = foton(&[
        "sweep",
        scene.path_str(),
        "--set",
        "integrators.path.rr_dept=3,4",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_error(&run, &["integrators.path.rr_dept", "did you mean"]);
    assert!(!out.exists());
}

#[test]
fn camera_looking_at_itself() {
    assert_bad_value(
        "look-at-self",
        "look_at = [0, 1, 0]",
        "look_at = [0, 1, 3.9]",
        "camera.look_at",
        &["same point as position"],
    );
}

// ---------------------------------------------------------------------------------------------
// OBJ meshes
// ---------------------------------------------------------------------------------------------

/// A scene whose shape is the mesh `file`, with `obj` (if any) written next to it.
fn mesh_scene(name: &str, file: &str, obj: Option<&str>, extra: &str) -> SceneFile {
    let shape = format!("type = \"mesh\"\nfile = \"{file}\"{extra}");
    let scene = scene_with(name, SPHERE, &shape);
    if let Some(obj) = obj {
        write(&scene.dir, file, obj);
    }
    scene
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

#[test]
fn obj_missing() {
    let scene = mesh_scene("obj-missing", "missing.obj", None, "");
    scene.check_fails(
        "file = \"missing.obj\"",
        "shapes[0].file",
        &["cannot open mesh", "missing.obj", "No such file"],
    );
}

#[test]
fn obj_malformed() {
    for (i, obj) in [
        "v 0 zz 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
    ]
    .iter()
    .enumerate()
    {
        let scene = mesh_scene(&format!("obj-malformed-{i}"), "bad.obj", Some(obj), "");
        scene.check_fails(
            "file = \"bad.obj\"",
            "shapes[0].file",
            &["bad.obj", "malformed OBJ"],
        );
    }
}

#[test]
fn obj_index_out_of_range() {
    for (i, face) in ["f 1 2 7", "f 0 1 2", "f -10 1 2", "f 1 2 4294967299"]
        .iter()
        .enumerate()
    {
        let obj = format!("{TRIANGLE}{face}\n");
        let scene = mesh_scene(&format!("obj-range-{i}"), "range.obj", Some(&obj), "");
        scene.check_fails(
            "file = \"range.obj\"",
            "shapes[0].file",
            &["range.obj", "index out of bounds"],
        );
    }
}

#[test]
fn obj_without_triangles() {
    // (A mesh whose faces are all of zero area loads, invisible, as in Mitsuba: see
    // mitsuba_shapes.)
    for (i, obj) in ["", "# only a comment\n"].iter().enumerate() {
        let scene = mesh_scene(&format!("obj-empty-{i}"), "empty.obj", Some(obj), "");
        scene.check_fails(
            "file = \"empty.obj\"",
            "shapes[0].file",
            &["empty.obj", "no triangles"],
        );
    }
}

#[test]
fn obj_non_finite_vertex() {
    let obj = "v 0 nan 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let scene = mesh_scene("obj-nan", "nan.obj", Some(obj), "");
    scene.check_fails(
        "file = \"nan.obj\"",
        "shapes[0].file",
        &["nan.obj", "non-finite vertex"],
    );
}

#[test]
fn mesh_transform_with_zero_scale() {
    let obj = format!("{TRIANGLE}f 1 2 3\n");
    let scene = mesh_scene(
        "obj-scale-zero",
        "tri.obj",
        Some(&obj),
        "\ntransform = { scale = [1, 0, 1] }",
    );
    scene.check_fails(
        "transform = { scale",
        "shapes[0].transform.scale",
        &["must not be zero"],
    );
}

// ---------------------------------------------------------------------------------------------
// Media
// ---------------------------------------------------------------------------------------------

#[test]
fn medium_negative_sigma() {
    let text = edit(
        &format!("{BASE}{FOG}"),
        "sigma_a = [0.1, 0.1, 0.1]",
        "sigma_a = [0.1, -0.1, 0.1]",
    );
    let scene = SceneFile::new("medium-sigma", &text);
    scene.check_fails(
        "sigma_a = [0.1, -0.1, 0.1]",
        "media.fog.sigma_a",
        &["expected non-negative values"],
    );
}

#[test]
fn medium_phase_g_out_of_range() {
    for (i, g) in ["1", "-1.5"].iter().enumerate() {
        let text = format!("{BASE}{FOG}phase = {{ type = \"hg\", g = {g} }}\n");
        let scene = SceneFile::new(&format!("medium-g-{i}"), &text);
        scene.check_fails(
            "phase = {",
            "media.fog.phase.g",
            &["|g| < 1", &format!("found {g}")],
        );
    }
}

#[test]
fn interior_medium_on_a_quad() {
    let text = edit(
        &format!("{BASE}{FOG}"),
        SPHERE,
        &format!("{QUAD}\ninterior = \"fog\""),
    );
    let scene = SceneFile::new("interior-quad", &text);
    scene.check_fails(
        "interior = \"fog\"",
        "shapes[0].interior",
        &["quad", "not closed", "interior medium"],
    );
}

#[test]
fn interior_medium_on_an_open_mesh() {
    let obj = format!("{TRIANGLE}f 1 2 3\n");
    let shape = "type = \"mesh\"\nfile = \"open.obj\"\ninterior = \"fog\"";
    let text = edit(&format!("{BASE}{FOG}"), SPHERE, shape);
    let scene = SceneFile::new("interior-open-mesh", &text);
    write(&scene.dir, "open.obj", &obj);
    scene.check_fails(
        "interior = \"fog\"",
        "shapes[0].interior",
        &["mesh", "not closed", "interior medium"],
    );
}

// ---------------------------------------------------------------------------------------------
// Media: values that are not numbers, and cameras in no well-defined medium
// ---------------------------------------------------------------------------------------------

#[test]
fn medium_non_finite_sigma() {
    for (i, bad) in ["[nan, 0.5, 0.5]", "[0.5, inf, 0.5]"].iter().enumerate() {
        let text = edit(
            &format!("{BASE}{FOG}"),
            "sigma_s = [0.5, 0.5, 0.5]",
            &format!("sigma_s = {bad}"),
        );
        let scene = SceneFile::new(&format!("medium-sigma-nan-{i}"), &text);
        scene.check_fails(
            &format!("sigma_s = {bad}"),
            "media.fog.sigma_s",
            &["expected a finite number"],
        );
    }
}

#[test]
fn camera_on_a_medium_boundary() {
    // The sphere of BASE (centre [0, 1, 0], radius 0.5) filled with fog, the camera on it.
    let text = edit(
        &edit(
            &format!("{BASE}{FOG}"),
            SPHERE,
            &format!("{SPHERE}\ninterior = \"fog\""),
        ),
        "position = [0, 1, 3.9]",
        "position = [0, 1, 0.5]",
    );
    let scene = SceneFile::new("camera-on-boundary", &text);
    scene.check_fails(
        "position = [0, 1, 0.5]",
        "camera.position",
        &[
            "medium around the camera is undefined",
            "shapes[0]",
            "boundary",
        ],
    );
    // The render fails the same way, before rendering.
    let run = scene.render(&[]);
    assert_error(&run, &["medium around the camera is undefined"]);
}

#[test]
fn camera_inside_overlapping_media() {
    let second = "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.6, 1, 0]\nradius = 0.5\nmaterial = \"white\"\ninterior = \"fog\"\n";
    let text = edit(
        &edit(
            &format!("{BASE}{FOG}{second}"),
            SPHERE,
            &format!("{SPHERE}\ninterior = \"fog\""),
        ),
        "position = [0, 1, 3.9]",
        "position = [0.3, 1, 0]",
    );
    let scene = SceneFile::new("camera-in-overlap", &text);
    scene.check_fails(
        "position = [0.3, 1, 0]",
        "camera.position",
        &[
            "medium around the camera is undefined",
            "shapes[0] and shapes[1]",
            "overlap",
        ],
    );
}
