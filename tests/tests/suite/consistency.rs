//! `foton compare --consistency N`: two consistent estimators pass, a photon map biased on
//! purpose (few photons, a huge k, no radius cap) is caught, against another integrator and
//! against a reference; its exit status, JSON, map and verdicts; the refusals. On the box of
//! tools.rs at 48x48 (36 blocks of 8x8) with a few samples: each test takes about a second.

use crate::tools::{fails_with, ok, s, setup};
use foton_core::Rgb;
use foton_core::film::DisplayTransform;
use foton_loader::image::{read_image, write_image};
use foton_tests::{Run, foton_with_plugins};
use std::path::Path;

/// The box at 48x48.
const SIZE: [&str; 4] = ["--set", "film.width=48", "--set", "film.height=48"];

/// A photon map whose estimate is blurred over the whole box: 300 photons, each estimate
/// taking 250 of them with no bound on its radius.
const BIASED_PHOTONS: [&str; 8] = [
    "--set",
    "integrators.photon.global_photons=300",
    "--set",
    "integrators.photon.caustic_photons=0",
    "--set",
    "integrators.photon.k=250",
    "--set",
    "integrators.photon.max_radius=100",
];

fn compare(scene: &Path, out: &Path, args: &[&str]) -> Run {
    let mut all = vec!["compare", s(scene), "-o", s(out), "-q"];
    all.extend_from_slice(&SIZE);
    all.extend_from_slice(args);
    foton_with_plugins(&all)
}

/// The consistency entry of pair `a` vs `b` in compare's JSON: its line.
fn pair_json<'a>(json: &'a str, a: &str, b: &str) -> &'a str {
    let key = format!("{{\"a\": \"{a}\", \"b\": \"{b}\"");
    let at = json
        .find(&key)
        .unwrap_or_else(|| panic!("no pair {a} vs {b} in {json}"));
    json[at..].lines().next().unwrap()
}

/// A numeric field of a pair's JSON line.
fn field(pair: &str, name: &str) -> f64 {
    let key = format!("\"{name}\": ");
    let i = pair
        .find(&key)
        .unwrap_or_else(|| panic!("no {name} in {pair}"))
        + key.len();
    pair[i..]
        .split([',', '}'])
        .next()
        .unwrap()
        .trim()
        .parse()
        .unwrap()
}

#[test]
fn consistent_integrators_pass_the_consistency_test() {
    let (dir, scene) = setup("consistency-pass");
    let out = dir.join("c.png");
    let run = compare(
        &scene,
        &out,
        &[
            "--integrators",
            "path,path:independent,bdpt",
            "--spp",
            "4",
            "--consistency",
            "5",
        ],
    );
    ok(&run);
    let json = std::fs::read_to_string(dir.join("c.json")).unwrap();
    for (a, b) in [
        ("path", "path:independent"),
        ("path", "bdpt"),
        ("path:independent", "bdpt"),
    ] {
        let pair = pair_json(&json, a, b);
        assert_eq!(field(pair, "blocks_differ"), 0.0, "{pair}");
        // The corners see past the box (black in every render): not tested.
        let tested = field(pair, "blocks_tested");
        assert!((10.0..36.0).contains(&tested), "{pair}");
        assert!(field(pair, "min_adjusted_p") > 0.01, "{pair}");
        assert!(pair.contains("\"differ\": false"), "{pair}");
        assert!(
            run.stdout.contains(&format!(
                "consistency {a} vs {b}: 0 of {tested} blocks differ"
            )),
            "{}",
            run.stdout
        );
    }
    assert_eq!(run.stdout.matches(": consistent\n").count(), 3);
    assert!(json.contains("\"renders\": 5"), "{json}");
    // The map: one panel per pair, three across.
    let (w, _, _) = read_image(&dir.join("c-consistency.png")).unwrap();
    assert!(w > 3 * 48, "{w}");
    // The EXR is the mean of the five renders: not the first alone.
    let first = dir.join("first.png");
    let one = compare(&scene, &first, &["--integrators", "path", "--spp", "4"]);
    ok(&one);
    let (_, _, mean) = read_image(&dir.join("c-path.exr")).unwrap();
    let (_, _, single) = read_image(&dir.join("first-path.exr")).unwrap();
    assert_ne!(mean, single);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_biased_photon_map_is_caught() {
    let (dir, scene) = setup("consistency-biased");
    let out = dir.join("c.png");
    let mut args = vec![
        "--integrators",
        "path,photon",
        "--spp",
        "4",
        "--consistency",
        "4",
    ];
    args.extend_from_slice(&BIASED_PHOTONS);
    let run = compare(&scene, &out, &args);
    assert_eq!(run.code, 3, "{}\n{}", run.stdout, run.stderr);
    let json = std::fs::read_to_string(dir.join("c.json")).unwrap();
    let pair = pair_json(&json, "path", "photon");
    assert!(field(pair, "blocks_differ") >= 10.0, "{pair}");
    assert!(field(pair, "min_adjusted_p") <= 0.01, "{pair}");
    assert!(pair.contains("\"differ\": true"), "{pair}");
    assert!(pair.contains("\"biased\": [\"photon\"]"), "{pair}");
    for words in [
        "consistency path vs photon: ",
        ": DIFFER; photon is biased but consistent: a difference may be its bias at this budget",
        "more photons (integrators.photon.global_photons",
    ] {
        assert!(run.stdout.contains(words), "{words}: {}", run.stdout);
    }
    // Everything is written all the same.
    for file in ["c.png", "c-path.exr", "c-photon.exr", "c-consistency.png"] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn consistency_against_a_reference_and_its_standard_error() {
    let (dir, scene) = setup("consistency-reference");
    let reference = dir.join("ref.exr");
    let mut render = vec![
        "render",
        s(&scene),
        "--spp",
        "256",
        "--seed",
        "99",
        "-o",
        s(&reference),
        "-q",
    ];
    render.extend_from_slice(&SIZE);
    ok(&foton_with_plugins(&render));

    let with_reference = |integrator: &str, extra: &[&str]| {
        let out = dir.join(format!("{integrator}.png"));
        let mut args = vec![
            "--integrators",
            integrator,
            "--spp",
            "4",
            "--consistency",
            "4",
            "--reference",
            s(&reference),
        ];
        args.extend_from_slice(extra);
        let run = compare(&scene, &out, &args);
        let json = std::fs::read_to_string(out.with_extension("json")).unwrap_or_default();
        (run, json)
    };
    let (run, json) = with_reference("path", &[]);
    ok(&run);
    assert_eq!(
        field(pair_json(&json, "path", "reference"), "blocks_differ"),
        0.0
    );
    let (run, json) = with_reference("photon", &BIASED_PHOTONS);
    assert_eq!(run.code, 3, "{}\n{}", run.stdout, run.stderr);
    assert!(field(pair_json(&json, "photon", "reference"), "blocks_differ") >= 10.0);

    // A reference said to be this uncertain cannot tell the photon map from it.
    let se = dir.join("se.exr");
    write_image(
        &se,
        48,
        48,
        &vec![Rgb::splat(50.0); 48 * 48],
        &DisplayTransform::default(),
    )
    .unwrap();
    let mut extra = BIASED_PHOTONS.to_vec();
    extra.extend(["--reference-se", s(&se)]);
    let (run, json) = with_reference("photon", &extra);
    ok(&run);
    assert_eq!(
        field(pair_json(&json, "photon", "reference"), "blocks_differ"),
        0.0
    );

    // A standard-error image of another size is refused before anything renders.
    let small = dir.join("small.exr");
    write_image(&small, 8, 8, &[Rgb::ONE; 64], &DisplayTransform::default()).unwrap();
    let (run, _) = with_reference("path", &["--reference-se", s(&small)]);
    fails_with(&run, &["standard errors are 8x8", "48x48"]);
    assert!(run.stdout.is_empty(), "{}", run.stdout);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn consistency_refuses_too_few_renders_and_nothing_to_test() {
    let (dir, scene) = setup("consistency-refusals");
    let out = dir.join("c.png");
    let run = compare(
        &scene,
        &out,
        &["--integrators", "path,bdpt", "--consistency", "3"],
    );
    fails_with(&run, &["--consistency 3", "at least 4 renders"]);
    let run = compare(
        &scene,
        &out,
        &["--integrators", "path", "--consistency", "4"],
    );
    fails_with(
        &run,
        &["--consistency 4 needs two integrators or a --reference"],
    );
    let run = compare(
        &scene,
        &out,
        &["--integrators", "path,bdpt", "--reference-se", "se.exr"],
    );
    fails_with(
        &run,
        &["--reference-se IMAGE needs --consistency N and --reference"],
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(dir);
}
