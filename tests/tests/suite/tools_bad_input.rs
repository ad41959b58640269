//! Bad input to the seeing-and-comparing commands (`foton photons`, `compare`, `sweep`):
//! every one ends in a message naming the problem and a non-zero exit, and writes nothing
//! but beside its output.

use crate::tools::{fails_with, ok, s, setup};
use foton_tests::{foton_with_plugins, temp_dir, write};
use std::path::Path;

#[test]
fn unknown_integrator_in_compare_lists_the_known_ones() {
    let (dir, scene) = setup("bad-integrator");
    let out = dir.join("c.png");
    let run = foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path,nope",
        "-o",
        s(&out),
    ]);
    fails_with(
        &run,
        &["no integrator plugin named `nope`", "available:", "path"],
    );
    assert!(!out.exists());
    let run = foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path,",
        "-o",
        s(&out),
    ]);
    fails_with(&run, &["empty integrator name"]);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn spp_and_time_together_are_refused() {
    let (dir, scene) = setup("bad-spp-time");
    let run = foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path",
        "--spp",
        "2",
        "--time",
        "1",
    ]);
    fails_with(&run, &["--spp", "--time", "cannot be used with"]);
    let run = foton_with_plugins(&["compare", s(&scene), "--integrators", "path", "--time", "0"]);
    fails_with(&run, &["--time 0", "positive"]);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn set_without_a_value_is_refused() {
    let (dir, scene) = setup("bad-set");
    let out = dir.join("x.png");
    for args in [
        &["sweep", s(&scene), "--set", "render.spp", "-o", s(&out)][..],
        &[
            "compare",
            s(&scene),
            "--integrators",
            "path",
            "--set",
            "render.spp",
            "-o",
            s(&out),
        ],
        &["photons", s(&scene), "--set", "render.seed", "-o", s(&out)],
    ] {
        fails_with(
            &foton_with_plugins(args),
            &["render.", "expected KEY.PATH=VALUE"],
        );
    }
    let run = foton_with_plugins(&["sweep", s(&scene), "--set", "render.spp=", "-o", s(&out)]);
    fails_with(&run, &["render.spp", "empty value list"]);
    let run = foton_with_plugins(&[
        "sweep",
        s(&scene),
        "--set",
        "render.spp=1,,2",
        "-o",
        s(&out),
    ]);
    fails_with(&run, &["render.spp", "empty value"]);
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn unknown_map_is_refused() {
    let (dir, scene) = setup("bad-map");
    let run = foton_with_plugins(&[
        "photons",
        s(&scene),
        "--integrator",
        "photon",
        "--map",
        "direct",
    ]);
    fails_with(&run, &["--map direct", "`photon`", "global, caustic"]);
    // An integrator without photon maps says so.
    let run = foton_with_plugins(&["photons", s(&scene)]);
    fails_with(&run, &["`path` builds no photon maps", "--integrator"]);
    let _ = std::fs::remove_dir_all(dir);
}

/// Every file `compare` and `sweep` write goes beside -o: nothing is left in the scene's
/// folder. A --set for one of the compared integrators is checked by that one.
#[test]
fn compare_and_sweep_write_only_beside_the_output() {
    let (dir, scene) = setup("outputs");
    let elsewhere = temp_dir("outputs-elsewhere");
    let before: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    ok(&foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path,photon",
        "--spp",
        "1",
        "--set",
        "integrators.photon.k=5",
        "-o",
        s(&elsewhere.join("c.png")),
        "-q",
    ]));
    ok(&foton_with_plugins(&[
        "sweep",
        s(&scene),
        "--set",
        "render.seed=1,2",
        "--spp",
        "1",
        "-o",
        s(&elsewhere.join("s.png")),
    ]));
    let after: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(before, after, "files were written beside the scene");
    for f in ["c.png", "c.json", "c-path.exr", "c-photon.exr", "s.png"] {
        assert!(elsewhere.join(f).is_file(), "{f} not beside -o");
    }
    let run = foton_with_plugins(&[
        "compare",
        s(&scene),
        "--integrators",
        "path,photon",
        "--set",
        "integrators.sppm.alpah=0.5",
        "-o",
        s(&elsewhere.join("d.png")),
    ]);
    fails_with(
        &run,
        &[
            "integrators.sppm.alpah",
            "did you mean `integrators.sppm.alpha`",
        ],
    );
    let _ = std::fs::remove_dir_all(dir);
    let _ = std::fs::remove_dir_all(elsewhere);
}

/// A folder given as the output is named as such, not as an image of unknown format.
#[test]
fn a_folder_as_output_is_refused_as_a_folder() {
    let (dir, scene) = setup("folder-output");
    for args in [
        &["render", s(&scene), "-o", s(&dir)][..],
        &["compare", s(&scene), "--integrators", "path", "-o", s(&dir)],
        &[
            "sweep",
            s(&scene),
            "--set",
            "render.seed=1,2",
            "-o",
            s(&dir),
        ],
    ] {
        let run = foton_with_plugins(args);
        fails_with(&run, &["is a directory, not a file"]);
        assert!(!run.stderr.contains("format"), "{}", run.stderr);
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn missing_output_folder_is_found_before_rendering() {
    let (dir, scene) = setup("bad-output");
    let out = dir.join("no-such-folder").join("x.png");
    for args in [
        &[
            "photons",
            s(&scene),
            "--integrator",
            "photon",
            "-o",
            s(&out),
        ][..],
        &["compare", s(&scene), "--integrators", "path", "-o", s(&out)],
        &[
            "sweep",
            s(&scene),
            "--set",
            "render.seed=1,2",
            "-o",
            s(&out),
        ],
    ] {
        let run = foton_with_plugins(args);
        fails_with(&run, &["no-such-folder", "does not exist"]);
        assert!(run.stdout.is_empty(), "nothing rendered: {}", run.stdout);
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn bad_reference_is_refused() {
    let (dir, scene) = setup("bad-reference");
    let out = dir.join("c.png");
    let small = dir.join("small.exr");
    let run = foton_with_plugins(&[
        "render",
        s(&scene),
        "--set",
        "film.width=16",
        "--set",
        "film.height=16",
        "--spp",
        "1",
        "-o",
        s(&small),
        "-q",
    ]);
    ok(&run);
    let compare = |reference: &Path| {
        foton_with_plugins(&[
            "compare",
            s(&scene),
            "--integrators",
            "path",
            "--reference",
            s(reference),
            "-o",
            s(&out),
        ])
    };
    let run = compare(&small);
    fails_with(&run, &["small.exr", "16x16", "32x32"]);
    assert!(run.stdout.is_empty(), "nothing rendered: {}", run.stdout);
    let garbage = write(&dir, "garbage.exr", "not an image");
    fails_with(
        &compare(&garbage),
        &["garbage.exr", "cannot read the reference image"],
    );
    fails_with(
        &compare(&dir.join("missing.png")),
        &["missing.png", "cannot read the reference image"],
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(dir);
}
