//! Progressive photon beams (`ppb`): the error against a converged path-traced image falls with
//! passes, agreement with the path tracer on single scattering from a point light in fog,
//! determinism across thread counts and parts, bad parameters.

use foton_core::film::Film;
use foton_tests::cornell_fog_16 as cornell_fog;
use foton_tests::stats::{Tolerance, assert_blocks_agree, rel_err, rel_rmse};
use foton_tests::{foton, foton_with_plugins, render_toml, repo_root, temp_dir};

fn ppb_passes(passes: u64, seed: u64) -> Film {
    let n = format!("integrators.ppb.iterations={passes}");
    let seed = format!("render.seed={seed}");
    cornell_fog(
        &[
            "render.integrator=ppb",
            "integrators.ppb.photons_per_iteration=5000",
            // Surface photons of their own (the defaults' kind), few: 16 x 16 pixels.
            "integrators.ppb.surface_photons=20000",
            &n,
            &seed,
        ],
        2,
    )
}

/// The foggy Cornell box (fog, spheres, walls: beams in the fog, sppm's gather on the
/// surfaces): the relative RMS error against the path tracer (4096 spp, whose own error is
/// about 1 % per pixel) falls from 4 to 32 passes and the image converges to the path
/// tracer's: mean within 2 %, blocks within 6 %.
#[test]
fn error_falls_with_passes_on_the_fog_box() {
    let path = cornell_fog(&["render.integrator=path", "render.spp=4096"], 2);
    let mut errors = Vec::new();
    let mut films = Vec::new();
    for passes in [4, 32] {
        // Two seeds each: one render's error is itself noisy.
        films = [1, 2]
            .iter()
            .map(|&seed| ppb_passes(passes, seed))
            .collect();
        let e = films.iter().map(|f| rel_rmse(f, &path)).sum::<f64>() / 2.0;
        errors.push(e);
    }
    eprintln!("relative RMS error after 4 and 32 passes: {errors:?}");
    // Variance falls as n^-alpha and the bias with the radii: 8 times the passes must at least
    // take off a third of the error (measured: see the README).
    assert!(errors[1] < 0.67 * errors[0], "{errors:?}");
    // The mean over both seeds: one 32-pass render's mean still moves by a few percent from
    // seed to seed (its low-frequency blotches): a 2 % bound on one seed would test the seed.
    let a = (films[0].mean() + films[1].mean()) / 2.0;
    let b = path.mean();
    assert!(rel_err(a, b) < 0.02, "{a} against {b}");
    let film = &films[0];
    assert_blocks_agree(
        "ppb, 32 passes",
        film,
        &path,
        2,
        Tolerance {
            rel: 0.06,
            z: 4.0,
            floor: 0.0,
        },
    );
}

/// The point-light fog box of tests/tests/suite/beams.rs (the light just above the view, shared in
/// foton_tests): at max_depth 1 the image is single scattering only, all of it from beams.
fn point_light_fog(integrator: &str, max_depth: u32) -> String {
    let ppb = "[integrators.ppb]\niterations = 16\nphotons_per_iteration = 10000\nsurface_photons = 10000";
    let hg = "{ type = \"hg\", g = 0.5 }";
    foton_tests::point_light_fog(integrator, 4096, max_depth, hg, ppb)
}

/// Tolerances as in tests/tests/suite/beams.rs (there with 200k photons in one pass; here 16
/// passes of 10k, with shrinking beams): image mean within 3 %, 3 x 3 blocks within 8 % or
/// 4 se.
#[test]
fn single_scattering_from_a_point_light_agrees_with_path() {
    for max_depth in [1, 8] {
        let path = render_toml("ppb-path", &point_light_fog("path", max_depth), &[], 2);
        for kind in ["short", "long"] {
            let set = format!("integrators.ppb.beam_type=\"{kind}\"");
            let ppb = render_toml("ppb", &point_light_fog("ppb", max_depth), &[&set], 2);
            let (a, b) = (ppb.mean(), path.mean());
            eprintln!(
                "max_depth {max_depth}, {kind} beams: ppb {a}, path {b}: {}",
                rel_err(a, b)
            );
            assert!(rel_err(a, b) < 0.03, "{kind}: {a} against {b}");
            assert_blocks_agree(
                &format!("ppb, max_depth {max_depth}, {kind} beams"),
                &ppb,
                &path,
                3,
                Tolerance {
                    rel: 0.08,
                    z: 4.0,
                    floor: 0.0,
                },
            );
        }
    }
}

/// Fog filling all space (the scene's medium, the camera in it) around one small sphere lit
/// by a point light above the view: most camera rays leave the scene's box and go on through
/// fog, meeting beams as far as photons went. Single scattering (max_depth 1): the fog's
/// light is all beams'; image mean within 3 %, 3 x 3 blocks within 8 % or 4 se of `path`.
#[test]
fn camera_rays_leaving_the_scene_in_fog_gather_the_beams_beyond_it() {
    let scene = |integrator: &str| {
        let mut s = foton_tests::header(integrator, 4096, 1, 24, 24);
        s += r#"
[camera]
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 36.0
[scene]
medium = "fog"
[media.fog]
type = "homogeneous"
sigma_a = [0.05, 0.05, 0.05]
sigma_s = [0.3, 0.3, 0.3]
[materials.white]
type = "diffuse"
reflectance = [0.8, 0.8, 0.8]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 0.3
material = "white"
[[lights]]
type = "point"
position = [0.0, 1.9, 1.0]
intensity = [2.0, 2.0, 2.0]
[integrators.ppb]
iterations = 32
photons_per_iteration = 10000
surface_photons = 10000
initial_beam_radius = 0.1
"#;
        s
    };
    let path = render_toml("ppb-open-path", &scene("path"), &[], 2);
    let ppb = render_toml("ppb-open", &scene("ppb"), &[], 2);
    let (a, b) = (ppb.mean(), path.mean());
    assert!(rel_err(a, b) < 0.03, "ppb {a} against path {b}");
    assert_blocks_agree(
        "ppb against path, unbounded fog",
        &ppb,
        &path,
        3,
        Tolerance {
            rel: 0.08,
            z: 4.0,
            floor: 0.0,
        },
    );
}

#[test]
fn identical_for_one_and_many_threads() {
    let set = [
        "render.integrator=ppb",
        "integrators.ppb.iterations=3",
        "integrators.ppb.photons_per_iteration=3000",
        "integrators.ppb.surface_photons=6000",
    ];
    let one = cornell_fog(&set, 1);
    let many = cornell_fog(&set, 3);
    assert_eq!(one.pixels(), many.pixels());
    assert!(one.mean().x > 0.0);
}

/// Passes are independent (radii from the pass number, streams keyed by the pass): three
/// parts merge into the whole render's EXR byte for byte; a time budget cannot be split.
#[test]
fn parts_merge_to_the_whole_render() {
    let dir = temp_dir("ppb-parts");
    let scene = repo_root().join("scenes/cornell-fog.toml");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--integrator",
            "ppb",
            "-q",
            "--set",
            "film.width=12",
            "--set",
            "film.height=10",
            "--set",
            "integrators.ppb.iterations=5",
            "--set",
            "integrators.ppb.photons_per_iteration=2000",
            "--set",
            "integrators.ppb.surface_photons=4000",
        ];
        args.extend(extra);
        foton_with_plugins(&args)
    };
    let whole = dir.join("whole.exr");
    let run = render(&["--threads", "1", "-o", whole.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let parts: Vec<String> = (0..3)
        .map(|i| {
            let out = dir.join(format!("part-{i}.exr"));
            let part = format!("{i}/3");
            let run = render(&[
                "--threads",
                "2",
                "--part",
                &part,
                "-o",
                out.to_str().unwrap(),
            ]);
            assert_eq!(run.code, 0, "{}", run.stderr);
            out.to_str().unwrap().to_string()
        })
        .collect();
    let merged = dir.join("merged.exr");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(String::as_str));
    args.extend(["-o", merged.to_str().unwrap()]);
    let run = foton(&args);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        std::fs::read(&whole).unwrap() == std::fs::read(&merged).unwrap(),
        "the merged parts differ from the whole render"
    );
    let timed = render(&[
        "--set",
        "integrators.ppb.time=1",
        "--part",
        "0/2",
        "-o",
        dir.join("timed.exr").to_str().unwrap(),
    ]);
    assert_ne!(timed.code, 0);
    assert!(
        timed.stderr.contains("ppb splits into parts"),
        "{}",
        timed.stderr
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn bad_parameters_are_clear_errors() {
    foton_tests::assert_refused(
        "scenes/fog_box.toml",
        "ppb",
        &["film.width=8", "film.height=8"],
        &[
            ("integrators.ppb.iterations=0", "iterations"),
            (
                "integrators.ppb.photons_per_iteration=0",
                "photons_per_iteration",
            ),
            ("integrators.ppb.surface_photons=10", "surface_photons"),
            (
                "integrators.ppb.initial_beam_radius=0",
                "initial_beam_radius",
            ),
            ("integrators.ppb.initial_radius=-1", "initial_radius"),
            ("integrators.ppb.alpha=1.5", "alpha"),
            ("integrators.ppb.beam_type=\"wide\"", "beam_type"),
            ("integrators.ppb.time=0", "time"),
            ("integrators.ppb.kernel=\"nope\"", "kernel"),
        ],
    );
}
