//! The volumetric photon mapper (`vpm`) against the volumetric path tracer, its convergence,
//! determinism and parameters.

use foton_tests::{assert_refused, foton_with_plugins, render_file, repo_root};

const VIEW: [&str; 2] = ["film.width=32", "film.height=32"];

/// The path tracer's image mean (2048 spp).
fn path_mean(scene: &str) -> glam::Vec3 {
    render_file(
        &repo_root().join(scene),
        &[&VIEW[..], &["render.integrator=path", "render.spp=2048"]].concat(),
        2,
    )
    .mean()
}

/// Relative error of vpm's image mean against the path tracer's at two settings: a coarse one
/// (50k photons per map, volume radius 0.2) and a fine one (800k, radius 0.05).
fn vpm_errors(scene: &str, path: glam::Vec3, extra: &[&str]) -> [f32; 2] {
    let scene = repo_root().join(scene);
    let view = [&VIEW[..], extra].concat();
    let mut errors = [0.0; 2];
    for (i, (photons, radius)) in [("50000", "0.2"), ("800000", "0.05")].iter().enumerate() {
        let set = [
            format!("integrators.vpm.global_photons={photons}"),
            format!("integrators.vpm.volume_photons={photons}"),
            format!("integrators.vpm.max_radius_volume={radius}"),
        ];
        let set: Vec<&str> = set.iter().map(|s| s.as_str()).collect();
        let vpm = render_file(
            &scene,
            &[
                &view[..],
                &["render.integrator=vpm", "render.spp=16"],
                &set[..],
            ]
            .concat(),
            2,
        )
        .mean();
        errors[i] = ((vpm - path) / path).abs().max_element();
        eprintln!(
            "{}: path {path}, vpm ({photons}, r {radius}) {vpm}",
            scene.display()
        );
    }
    errors
}

// The bound: the volume estimate blurs over its radius, which darkens it within a radius of
// surfaces (the ball reaches where no photon can be); measured 1.8 % and 0.6 % (fog cube),
// 1.6 % and 0.5 % (thin fog) for the two settings. The path tracer's mean at 2048 spp is
// good to about 0.3 %. The fine setting must be within 1.5 % and better than the coarse one.
const BOUND: f32 = 0.015;

#[test]
fn agrees_with_path_on_the_fog_cube_and_converges() {
    let path = path_mean("scenes/fog_box.toml");
    let [coarse, fine] = vpm_errors("scenes/fog_box.toml", path, &[]);
    assert!(fine < BOUND && fine < coarse, "{coarse} then {fine}");
    // direct = "photons": the first scattering events come from the volume map instead of
    // shadow rays.
    let photons = ["integrators.vpm.direct=\"photons\""];
    let [coarse, fine] = vpm_errors("scenes/fog_box.toml", path, &photons);
    assert!(fine < BOUND && fine < coarse, "{coarse} then {fine}");
    // The beam radiance estimate instead of marching, all scattering by photons.
    let beam = [
        "integrators.vpm.estimate=\"beam\"",
        "integrators.vpm.direct=\"photons\"",
    ];
    let [coarse, fine] = vpm_errors("scenes/fog_box.toml", path, &beam);
    assert!(fine < BOUND && fine < coarse, "{coarse} then {fine}");
}

#[test]
fn agrees_with_path_on_the_fog_filled_cornell_box_and_converges() {
    let path = path_mean("scenes/cornell-fog.toml");
    let [coarse, fine] = vpm_errors("scenes/cornell-fog.toml", path, &[]);
    assert!(fine < BOUND && fine < coarse, "{coarse} then {fine}");
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
    let (w, h, _) = foton_core::film::read_image(&out).unwrap();
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
    // and camera rays enter it by refraction. Image means: measured 0.86 % and 0.27 %. (Over
    // the sphere's pixels alone, one render's photon-map noise is +-4 to 12 % from seed to
    // seed, all pixels seeing the same few magnified blotches through the sphere; the mean of
    // four seeds agreed with the path tracer within 0.7 %.)
    let path = path_mean("scenes/murky-glass.toml");
    let [coarse, fine] = vpm_errors("scenes/murky-glass.toml", path, &[]);
    assert!(fine < BOUND && fine < coarse, "{coarse} then {fine}");
}
