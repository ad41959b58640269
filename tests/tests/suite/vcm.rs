//! Vertex connection and merging, `vcm` (issue 19):
//!
//! * in `bpt` mode (connections only) it is `bdpt`'s estimator: the two agree;
//! * in `ppm` mode (merges only) it agrees with `sppm` rendering the same paths (photons for
//!   direct light too);
//! * the full estimator agrees with `bdpt` on a diffuse box and with `path` on a caustic one (a
//!   glass sphere over a diffuse floor, lit by an area light the path tracer can hit) and on
//!   glossy materials with a caustic (scenes/glossy-caustic.xml);
//! * with `hide_emitters` it agrees with `path` rendering the same;
//! * the image is the same bit for bit for any thread count, parts merge to the whole render
//!   exactly, and a cancelled render keeps whole iterations;
//! * a scene with participating media is refused with the integrators that render it.
//!
//! Block means are compared within z standard errors of the pixel-wise difference
//! (`foton_tests::stats::compare_blocks`), as in tests/tests/suite/bdpt.rs; where merges are used the
//! radius bias is allowed for as a relative term derived in the test's comment.

use crate::parts::assert_three_parts_merge;
use foton_core::film::Film;
use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{render_file, render_toml, temp_dir, write};

const SIZE: u32 = 32;
const Z: Tolerance = Tolerance {
    rel: 0.0,
    z: 4.5,
    floor: 1e-4,
};

/// The Cornell box of bdpt.rs (its spheres of materials `a` and `b`, a 1 x 1 quad light of
/// radiance 5 below the ceiling, at SIZE x SIZE, the `independent` sampler its standard errors
/// assume) with a glass material.
fn cornell(a: &str, b: &str) -> String {
    super::bdpt::cornell(a, b, GLASS, super::bdpt::CEILING_LIGHT)
}

const GLASS: &str = r#"
[materials.glass]
type = "dielectric"
ior = 1.5
"#;

fn render(scene: &str, integrator: &str, sets: &[String]) -> Film {
    let mut all = vec![format!("render.integrator=\"{integrator}\"")];
    all.extend(sets.iter().cloned());
    let refs: Vec<&str> = all.iter().map(String::as_str).collect();
    render_toml(integrator, scene, &refs, 2)
}

/// `vcm` with `mode`, `iterations`, first radius `radius` and `max_depth`.
fn vcm(scene: &str, mode: &str, iterations: u32, radius: f32, max_depth: u32) -> Film {
    render(
        scene,
        "vcm",
        &[
            format!("integrators.vcm.mode=\"{mode}\""),
            format!("integrators.vcm.iterations={iterations}"),
            format!("integrators.vcm.radius={radius}"),
            format!("render.max_depth={max_depth}"),
        ],
    )
}

fn spp(integrator: &str, scene: &str, spp: u32, max_depth: u32) -> Film {
    render(
        scene,
        integrator,
        &[
            format!("render.spp={spp}"),
            format!("render.max_depth={max_depth}"),
        ],
    )
}

/// The relative allowance for the merges' bias on a block of `block` world units: within r of
/// an edge of a surface (a corner of the box, a sphere's contact) a merge's disc loses up to
/// half its support, so a block along such an edge may read up to half its radiance low over
/// a band of width r: a fraction r / block of it. (Inside a surface the bias of a smooth
/// illumination is O((r / L)^2) for L its scale, ~1e-4 here: below the noise.)
fn merge_bias(radius: f32, block: f32) -> f64 {
    0.5 * (radius / block) as f64
}

/// A block of the 4 x 4 grid spans 8 pixels; at the back wall (4.9 from the camera, 39.3
/// degrees of field for 32 pixels) that is 4.9 x 2 tan(19.65 deg) / 4 = 0.44 world units, at
/// the front of the floor about half: 0.2, the smaller for the allowance.
const BLOCK: f32 = 0.2;

/// Connections only: the estimator of `bdpt` (one light path per camera sample), with its
/// random numbers drawn in another order: the two agree within their noise.
#[test]
fn vcm_in_bpt_mode_agrees_with_bdpt() {
    let scene = cornell("white", "glass");
    let bdpt = spp("bdpt", &scene, 128, 8);
    let film = vcm(&scene, "bpt", 128, 0.01, 8);
    assert_blocks_agree("vcm (bpt) against bdpt", &film, &bdpt, 4, Z);
}

/// Merges only, at the camera path's first non-delta vertex (through the glass sphere), with
/// emitters seen directly or through glass: `sppm` with photons for direct light, the same
/// global radius schedule (Knaus and Zwicker's, whose r_i^2 falls as i^(alpha - 1), as vcm's)
/// and the box kernel. Both are consistent; each has the radius bias of `merge_bias`.
#[test]
fn vcm_in_ppm_mode_agrees_with_sppm() {
    let scene = cornell("white", "glass");
    let radius = 0.02;
    let sppm = render(
        &scene,
        "sppm",
        &[
            "integrators.sppm.iterations=512".into(),
            "integrators.sppm.photons_per_iteration=4096".into(),
            "integrators.sppm.direct=\"photons\"".into(),
            "integrators.sppm.radius_schedule=\"global\"".into(),
            format!("integrators.sppm.initial_radius={radius}"),
            "integrators.sppm.alpha=0.75".into(),
            "render.max_depth=8".into(),
        ],
    );
    let film = vcm(&scene, "ppm", 1024, radius, 8);
    let tolerance = Tolerance {
        rel: 2.0 * merge_bias(radius, BLOCK),
        ..Z
    };
    assert_blocks_agree("vcm (ppm) against sppm", &film, &sppm, 4, tolerance);
}

/// The full estimator on a diffuse box: connections carry almost all of the weight there
/// (eta = pi r^2 N is small), and it agrees with bdpt.
#[test]
fn vcm_agrees_with_bdpt_on_a_diffuse_box() {
    let scene = cornell("white", "white");
    let radius = 0.02;
    let bdpt = spp("bdpt", &scene, 256, 8);
    let film = vcm(&scene, "vcm", 128, radius, 8);
    let tolerance = Tolerance {
        rel: merge_bias(radius, BLOCK),
        ..Z
    };
    assert_blocks_agree("vcm against bdpt, diffuse box", &film, &bdpt, 4, tolerance);
}

/// A glass sphere over the floor (and a diffuse one), lit by an area light: the caustic under
/// the glass and the box seen through it are S D S or L S D paths that merges render; the
/// path tracer renders them by reaching the light through the glass. They agree.
#[test]
fn vcm_agrees_with_path_on_a_caustic() {
    let scene = cornell("glass", "white");
    let radius = 0.02;
    let path = spp("path", &scene, 8192, 8);
    let film = vcm(&scene, "vcm", 512, radius, 8);
    let tolerance = Tolerance {
        rel: merge_bias(radius, BLOCK),
        ..Z
    };
    assert_blocks_agree("vcm against path, caustic", &film, &path, 4, tolerance);
}

/// Glossy light and a caustic at once (scenes/glossy-caustic.xml, a Mitsuba 3 file: a GGX gold
/// sphere, a rough-plastic back wall, a smooth glass sphere and its caustic, a small light):
/// merges and connections through rough conductors and rough plastic, weighted together,
/// agree with the path tracer. A block of the 4 x 4 grid spans 8 of 32 pixels, about 0.5 world
/// units at the floor's front and more behind: the radius allowance uses 0.5.
#[test]
fn vcm_agrees_with_path_on_glossy_materials_and_a_caustic() {
    let file = foton_tests::repo_root().join("scenes/glossy-caustic.xml");
    let radius = 0.02;
    let size = [format!("film.width={SIZE}"), format!("film.height={SIZE}")];
    let sets = |extra: &[String]| -> Vec<String> { size.iter().chain(extra).cloned().collect() };
    let film = |sets: Vec<String>| {
        let refs: Vec<&str> = sets.iter().map(String::as_str).collect();
        render_file(&file, &refs, 2)
    };
    let path = film(sets(&["render.spp=4096".into()]));
    let vcm = film(sets(&[
        "render.integrator=\"vcm\"".into(),
        "integrators.vcm.iterations=256".into(),
        format!("integrators.vcm.radius={radius}"),
    ]));
    let tolerance = Tolerance {
        rel: merge_bias(radius, 0.5),
        ..Z
    };
    assert_blocks_agree(
        "vcm against path, glossy-caustic.xml",
        &vcm,
        &path,
        4,
        tolerance,
    );
}

/// `hide_emitters` as `path` renders it (camera rays pass through emitters until they first
/// scatter): the ceiling light and a white emitting sphere in the middle of the view hidden,
/// the wall behind the sphere seen through it.
#[test]
fn vcm_hides_emitters_as_path_does() {
    let scene = cornell("white", "glass").replace(
        "emission = [5.0, 5.0, 5.0]",
        "emission = [5.0, 5.0, 5.0]\n\n[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 1.0, 0.2]\nradius = 0.2\nmaterial = \"white\"\nemission = [4.0, 4.0, 4.0]",
    );
    let radius = 0.02;
    let hide = "render.hide_emitters=true".to_string();
    let path = render(&scene, "path", &["render.spp=4096".into(), hide.clone()]);
    let film = render(
        &scene,
        "vcm",
        &[
            "integrators.vcm.iterations=256".into(),
            format!("integrators.vcm.radius={radius}"),
            hide,
        ],
    );
    let tolerance = Tolerance {
        rel: merge_bias(radius, BLOCK),
        ..Z
    };
    assert_blocks_agree(
        "vcm against path, hide_emitters",
        &film,
        &path,
        4,
        tolerance,
    );
}

/// The same image bit for bit (pixel sums, counts and splat sums) on 1, 2 and 3 threads; the
/// work the summary reports is the same too: the iterations, and one light subpath per pixel
/// and iteration as its photons.
#[test]
fn vcm_is_the_same_for_any_thread_count() {
    let scene = cornell("glass", "white");
    let dir = temp_dir("vcm-threads");
    let file = write(&dir, "scene.toml", &scene);
    let sets = [
        "render.integrator=\"vcm\"",
        "integrators.vcm.iterations=4",
        "integrators.vcm.radius=0.05",
        "render.sampler=\"sobol\"",
    ];
    let films: Vec<Film> = [1, 2, 3]
        .iter()
        .map(|&threads| render_file(&file, &sets, threads))
        .collect();
    assert!(films[0].splats().iter().any(|s| s.0[0] > 0), "vcm splats");
    let light_paths = 4 * SIZE as u64 * SIZE as u64;
    for f in &films {
        assert_eq!((f.iterations, f.photons), (4, light_paths));
        assert!(f.rays > light_paths, "rays: {}", f.rays);
    }
    for f in &films[1..] {
        assert_eq!(f.rays, films[0].rays);
        assert_eq!(f.sums(), films[0].sums());
        assert_eq!(f.counts(), films[0].counts());
        assert_eq!(f.splats(), films[0].splats());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `foton render --part I/N` splits the iterations; the merged parts are the whole render's
/// EXR byte for byte.
#[test]
fn vcm_parts_merge_to_the_whole_render() {
    let dir = temp_dir("vcm-parts");
    let scene = write(&dir, "scene.toml", &cornell("glass", "white"));
    assert_three_parts_merge(
        "vcm",
        &scene,
        &[
            "--integrator",
            "vcm",
            "--set",
            "integrators.vcm.iterations=5",
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Media (merging is on surfaces only) and bad parameters are refused with the reason; for media, the integrators that render them are named.
#[test]
fn vcm_refuses_what_it_does_not_render() {
    foton_tests::assert_refused(
        "scenes/cornell-fog.toml",
        "vcm",
        &[],
        &[("render.spp=1", "use `bdpt` or `vpm`")],
    );
    foton_tests::assert_refused(
        "scenes/cornell-box.toml",
        "vcm",
        &[],
        &[
            ("integrators.vcm.mode=\"bdpt\"", "mode"),
            ("integrators.vcm.radius=0", "radius"),
            ("integrators.vcm.alpha=1.5", "alpha"),
            ("integrators.vcm.iterations=0", "iterations"),
        ],
    );
}

/// Cancelling a render (what Ctrl-C does) keeps whole iterations: the film it returns is, bit
/// for bit, the render of that many iterations (every pixel counts them all, and the splats
/// are those of the same light paths), never one with part of an iteration.
#[test]
fn a_cancelled_vcm_render_is_a_whole_number_of_iterations() {
    use foton_core::integrator::{NoProgress, RenderContext};
    use std::sync::atomic::{AtomicBool, Ordering};
    let dir = temp_dir("vcm-cancel");
    let file = write(&dir, "scene.toml", &cornell("glass", "white"));
    let prepare = |iterations: u64| {
        let sets = [
            "render.integrator=\"vcm\"".to_string(),
            format!("integrators.vcm.iterations={iterations}"),
        ];
        foton_cli::prepare(&file, &sets, &[foton_tests::plugin_dir()], true).unwrap()
    };
    let long = prepare(1_000_000);
    let cancel = AtomicBool::new(false);
    let film = std::thread::scope(|s| {
        s.spawn(|| {
            std::thread::sleep(std::time::Duration::from_millis(700));
            cancel.store(true, Ordering::SeqCst);
        });
        let ctx = RenderContext::new(2, &cancel, &NoProgress);
        long.integrator.render(&long.scene, &ctx).unwrap()
    });
    let n = film.iterations;
    assert!(n >= 1, "no iteration in 0.7 s");
    assert!(film.counts().iter().all(|&c| c as u64 == n));
    let whole = prepare(n);
    let never = AtomicBool::new(false);
    let ctx = RenderContext::new(1, &never, &NoProgress);
    let reference = whole.integrator.render(&whole.scene, &ctx).unwrap();
    assert_eq!(film.sums(), reference.sums(), "{n} iterations");
    assert_eq!(film.splats(), reference.splats(), "{n} iterations");
    let _ = std::fs::remove_dir_all(&dir);
}
