//! The volumetric photon mapper (`vpm`) against the volumetric path tracer, its convergence,
//! determinism and parameters.

use foton_core::film::Film;
use foton_tests::stats::{Tolerance, assert_blocks_agree_by, rel_err};
use foton_tests::{assert_refused, foton_with_plugins, render_file, repo_root};

const VIEW: [&str; 2] = ["film.width=32", "film.height=32"];

/// The path tracer's image (2048 spp).
fn path_film(scene: &str) -> Film {
    render_file(
        &repo_root().join(scene),
        &[&VIEW[..], &["render.integrator=path", "render.spp=2048"]].concat(),
        2,
    )
}

/// vpm's image at a coarse setting (50k photons per map, volume radius 0.2, one seed, 16 spp)
/// and a fine one (800k, radius 0.05), the fine one the sum of four renders of 16 spp with
/// seeds 0 to 3 (four photon maps: see BOUND), with the standard error of its mean (relative
/// to it) from the spread of the four renders' means (at 4 spp each the camera samples'
/// noise alone spread them by 4 %).
fn vpm_films(scene: &str, extra: &[&str]) -> ([Film; 2], f32) {
    let scene = repo_root().join(scene);
    let view = [&VIEW[..], extra].concat();
    let render = |photons: &str, radius: &str, spp: &str, seed: u32| {
        let set = [
            format!("integrators.vpm.global_photons={photons}"),
            format!("integrators.vpm.volume_photons={photons}"),
            format!("integrators.vpm.max_radius_volume={radius}"),
            format!("render.spp={spp}"),
            format!("render.seed={seed}"),
        ];
        let set: Vec<&str> = set.iter().map(|s| s.as_str()).collect();
        render_file(
            &scene,
            &[&view[..], &["render.integrator=vpm"], &set[..]].concat(),
            2,
        )
    };
    let coarse = render("50000", "0.2", "16", 0);
    let mut fine = render("800000", "0.05", "16", 0);
    let mut means = vec![fine.mean().element_sum()];
    for seed in 1..4 {
        let other = render("800000", "0.05", "16", seed);
        means.push(other.mean().element_sum());
        for (i, (sum, &count)) in other.sums().iter().zip(other.counts()).enumerate() {
            fine.add_pixel(i, sum, count);
        }
    }
    let n = means.len() as f32;
    let mean = means.iter().sum::<f32>() / n;
    let variance = means.iter().map(|m| (m - mean).powi(2)).sum::<f32>() / (n - 1.0);
    ([coarse, fine], (variance / n).sqrt() / mean)
}

/// vpm against the path tracer: the relative error of the image mean must be below BOUND at
/// the fine setting and below the coarse setting's, or within two of the fine setting's
/// standard errors of it (it converges; the murky glass's coarse setting is within 1 %); the
/// fine setting's image must agree block by block.
fn assert_agrees_and_converges(what: &str, scene: &str, path: &Film, extra: &[&str]) {
    let ([coarse, fine], se) = vpm_films(scene, extra);
    let p = path.mean();
    let errors = [rel_err(coarse.mean(), p), rel_err(fine.mean(), p)];
    eprintln!(
        "{what}: path {p}, vpm (50k, r 0.2) {}, (800k, r 0.05) {} (standard error {se}): {errors:?}",
        coarse.mean(),
        fine.mean()
    );
    assert!(
        errors[1] < BOUND && errors[1] < errors[0].max(2.0 * se),
        "{what}: {} then {} (standard error {se})",
        errors[0],
        errors[1]
    );
    assert_blocks_agree_by(what, &fine, path, 4, |block| Tolerance {
        rel: if block.on_border(32, 32) { 0.07 } else { 0.04 },
        z: 4.0,
        floor: 0.0,
    });
}

// The bound on the image mean: the volume estimate blurs over its radius, which darkens it
// within a radius of surfaces (the ball reaches where no photon can be); measured 1.8 % and
// 0.6 % (fog cube), 1.6 % and 0.5 % (thin fog) for the two settings. The path tracer's mean
// at 2048 spp is good to about 0.3 %. The fine setting must be within 1.5 % and better than
// the coarse one. One render's photon maps and camera samples move the fine image's mean from
// seed to seed by a standard deviation of 0.85 to 1.4 % (fog cube, seeds 0 to 9 with
// `sampler = "sobol"`: seed 0 fell at -1.7 %; every scene here, seeds 0 to 3), so the fine
// setting is the mean of four seeds (a standard error of 0.6 to 0.7 %, printed): 1.5 % is
// the bias and two and a half of those.
//
// Block by block (4x4 blocks of 8x8 pixels, the fine setting): each within max(rel, 4 se) of
// the path tracer's, se the standard error of the block mean of the pixel-wise difference
// (the camera samples' noise of both renders; largest on the ceiling's light and, in the
// murky glass, on the sphere, where each pixel sees a few photons' blotches magnified).
// rel is for what the pixel statistics do not see, a bias and the photon maps' own noise.
// The four inner blocks (the fog in front of the back wall, the murky sphere) hold the fog
// cube's edges, where the volume estimate's ball reaches out of the fog and darkens it (the
// bound above): with direct = "photons" up to 2.6 % low (seed 0; 1.2 to 1.6 % over three
// other seeds), else within 1.5 %, with spreads up to 0.6 % (but for the murky sphere's
// block, which se covers): 4 %. The twelve outer blocks hold the box's edges, where the
// surface estimate's disc reaches past a wall's edge into area without its photons, which
// darkens it: 7 % (measured up to 4.7 % low, mean of three seeds, spreads up to 1.2 %;
// single renders up to 6.9 %; with 3.2M surface photons the worst block is 2.7 % low, with
// k = 200 instead of 50 it is 4.4 % low: it is that bias). No block is black: no floor.
const BOUND: f32 = 0.015;

#[test]
fn agrees_with_path_on_the_fog_cube_and_converges() {
    let scene = "scenes/fog_box.toml";
    let path = path_film(scene);
    assert_agrees_and_converges("fog cube", scene, &path, &[]);
    // direct = "photons": the first scattering events come from the volume map instead of
    // shadow rays.
    let photons = ["integrators.vpm.direct=\"photons\""];
    assert_agrees_and_converges("fog cube, direct photons", scene, &path, &photons);
    // The beam radiance estimate instead of marching, all scattering by photons.
    let beam = [
        "integrators.vpm.estimate=\"beam\"",
        "integrators.vpm.direct=\"photons\"",
    ];
    assert_agrees_and_converges("fog cube, beam estimate", scene, &path, &beam);
}

#[test]
fn agrees_with_path_on_the_fog_filled_cornell_box_and_converges() {
    let scene = "scenes/cornell-fog.toml";
    assert_agrees_and_converges("fog-filled cornell box", scene, &path_film(scene), &[]);
}

/// Issue 20, item 3: a user who writes nothing gets an image within 10 % per block of the
/// converged one. `vpm` with no parameter of its own on the fog box (at 32x32 the defaults
/// scale the global photons to the pixels, 48 a pixel; the scene's 64 spp) against the path
/// tracer at 2048 spp, 4x4 blocks of 8x8 pixels, each within max(10 %, 4 se) per channel.
/// Measured: worst block channel -8.0 % (the top-left corner, the box edges' bias), mean -1.1 %.
#[test]
fn defaults_agree_with_path_on_the_fog_box() {
    let scene = "scenes/fog_box.toml";
    let path = path_film(scene);
    let vpm = render_file(
        &repo_root().join(scene),
        &[&VIEW[..], &["render.integrator=vpm"]].concat(),
        2,
    );
    eprintln!(
        "defaults: vpm {}, path {}: {}",
        vpm.mean(),
        path.mean(),
        rel_err(vpm.mean(), path.mean())
    );
    assert_blocks_agree_by("vpm defaults, fog box", &vpm, &path, 4, |_| Tolerance {
        rel: 0.10,
        z: 4.0,
        floor: 0.0,
    });
}

#[test]
fn identical_for_one_and_many_threads() {
    let scene = repo_root().join("scenes/fog-beam.toml");
    let set = [
        "render.integrator=vpm",
        "film.width=16",
        "film.height=16",
        "render.spp=2",
        "integrators.vpm.global_photons=20000",
        "integrators.vpm.volume_photons=20000",
        "integrators.vpm.caustic_photons=20000",
    ];
    let one = render_file(&scene, &set, 1);
    let many = render_file(&scene, &set, 3);
    assert_eq!(one.pixels(), many.pixels());
    assert!(one.mean().x > 0.0);
}

#[test]
fn bad_parameters_are_clear_errors() {
    let small = [
        "film.width=8",
        "film.height=8",
        "integrators.vpm.volume_photons=2000",
    ];
    assert_refused(
        "scenes/fog_box.toml",
        "vpm",
        &small,
        &[
            ("integrators.vpm.global_photons=0", "global_photons"),
            ("integrators.vpm.k=1", "k"),
            ("integrators.vpm.k_volume=0", "k_volume"),
            ("integrators.vpm.max_radius_volume=0", "max_radius_volume"),
            ("integrators.vpm.step=-0.1", "step"),
            ("integrators.vpm.direct=\"sometimes\"", "direct"),
            ("integrators.vpm.estimate=\"guess\"", "estimate"),
            ("integrators.vpm.kernel=\"nope\"", "kernel"),
            ("integrators.vpm.k_volume=100000000", "larger than"),
        ],
    );
}

/// `foton photons --map volume`: the numbers it reports (stored, emitted, drawn).
fn volume_map_counts(scene: &str) -> (u64, u64) {
    let scene = repo_root().join(scene);
    let dir = foton_tests::temp_dir("volume-map");
    let out = dir.join("volume.png");
    let run = foton_with_plugins(&[
        "photons",
        scene.to_str().unwrap(),
        "--integrator",
        "vpm",
        "--map",
        "volume",
        "--set",
        "integrators.vpm.volume_photons=20000",
        "--set",
        "film.width=32",
        "--set",
        "film.height=32",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let (w, h, _) = foton_loader::image::read_image(&out).unwrap();
    assert_eq!((w, h), (32, 32));
    let _ = std::fs::remove_dir_all(dir);
    let number_before = |word: &str| -> u64 {
        let i = run.stdout.find(word).unwrap();
        run.stdout[..i]
            .split_whitespace()
            .last()
            .unwrap()
            .parse()
            .unwrap()
    };
    (number_before(" stored"), number_before(" drawn"))
}

#[test]
fn photons_command_shows_the_volume_map() {
    let (stored, drawn) = volume_map_counts("scenes/fog_box.toml");
    assert!(
        stored > 1000 && drawn > 0 && drawn <= stored,
        "{stored} {drawn}"
    );
    // No medium, no volume photon.
    assert_eq!(volume_map_counts("scenes/cornell-box.toml"), (0, 0));
}

#[test]
fn agrees_with_path_on_murky_glass_and_converges() {
    // A dielectric sphere holding a coloured, forward-scattering (HG g = 0.7) medium: photons
    // and camera rays enter it by refraction. Image means: measured 0.86 % and 0.27 % (one
    // seed), 0.36 % (the fine setting's four seeds). (Over
    // the sphere's pixels alone, one render's photon-map noise is +-4 to 12 % from seed to
    // seed, all pixels seeing the same few magnified blotches through the sphere; the mean of
    // four seeds agreed with the path tracer within 0.7 %.) Block by block, the sphere's
    // blocks are the known exception: the blotches make their pixels differ, so the
    // standard error of the difference is large there (measured up to 11 % of the block, so
    // about 45 % is allowed; one of three seeds put a sphere block 28 % off, at 2.4 se):
    // those blocks are only loosely checked, the image mean and the other blocks are not.
    let scene = "scenes/murky-glass.toml";
    assert_agrees_and_converges("murky glass", scene, &path_film(scene), &[]);
}
