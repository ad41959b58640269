//! Renders split into parts and merged (`foton render --part I/N`, `foton merge`): the merged
//! image equals the render done in one process bit for bit, for every integrator that can
//! split its work, and parts that do not belong together are refused with nothing written.

use foton_core::Rgb;
use foton_core::film::RadianceSum;
use foton_core::integrator::Part;
use foton_core::sampling::Rng;
use foton_loader::image::read_image;
use foton_tests::{Run, foton, foton_with_plugins, repo_root, temp_dir};
use std::path::{Path, PathBuf};

/// A small render of a scene of the repository with `sets` as extra arguments.
struct Case {
    scene: PathBuf,
    args: Vec<String>,
}

impl Case {
    fn new(scene: &str, args: &[&str]) -> Case {
        let mut all: Vec<String> = ["--set", "film.width=48", "--set", "film.height=64", "-q"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        all.extend(args.iter().map(|s| s.to_string()));
        Case {
            scene: repo_root().join("scenes").join(scene),
            args: all,
        }
    }

    fn render(&self, extra: &[&str]) -> Run {
        let mut args = vec!["render", self.scene.to_str().unwrap()];
        args.extend(self.args.iter().map(String::as_str));
        args.extend(extra);
        foton_with_plugins(&args)
    }

    /// Renders part `i` of `n` into `dir`.
    fn part(&self, dir: &Path, i: u32, n: u32, extra: &[&str]) -> PathBuf {
        let out = dir.join(format!("part-{i}-{n}.exr"));
        let part = format!("{i}/{n}");
        let mut args = vec!["--part", &part, "-o", out.to_str().unwrap()];
        args.extend(extra);
        let run = self.render(&args);
        assert_eq!(run.code, 0, "part {part}: {}", run.stderr);
        assert!(
            run.stdout.contains(&format!("part {part}")),
            "{}",
            run.stdout
        );
        out
    }
}

fn merge(parts: &[PathBuf], out: &Path, extra: &[&str]) -> Run {
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|p| p.to_str().unwrap()));
    args.extend(["-o", out.to_str().unwrap()]);
    args.extend(extra);
    foton(&args)
}

fn bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `foton render SCENE -q ARGS` rendered whole (on 1 thread) and in 3 parts (on 2 threads,
/// given out of order), merged: the whole render's EXR byte for byte. `what` names the render
/// in the failure message. (The splatting integrators' check: their splat sums are stored and
/// added apart, and scaled by the samples of all parts.)
pub(crate) fn assert_three_parts_merge(what: &str, scene: &Path, args: &[&str]) {
    let dir = scene.parent().unwrap();
    let render = |extra: &[&str]| {
        let mut all = vec!["render", scene.to_str().unwrap(), "-q"];
        all.extend(args);
        all.extend(extra);
        let run = foton_with_plugins(&all);
        assert_eq!(run.code, 0, "{}", run.stderr);
    };
    let whole = dir.join("whole.exr");
    render(&["--threads", "1", "-o", whole.to_str().unwrap()]);
    let mut parts = Vec::new();
    for i in (0..3).rev() {
        let out = dir.join(format!("part-{i}.exr"));
        render(&[
            "--threads",
            "2",
            "--part",
            &format!("{i}/3"),
            "-o",
            out.to_str().unwrap(),
        ]);
        parts.push(out);
    }
    let merged = dir.join("merged.exr");
    let run = merge(&parts, &merged, &[]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        bytes(&merged) == bytes(&whole),
        "the merge of 3 {what} parts differs from the whole render"
    );
}

/// The case rendered whole (on 1 thread) and in 4 parts (on 2 threads, parts given out of
/// order) and in 3 parts: both merges give the whole render's EXR byte for byte.
fn assert_merge_is_exact(name: &str, case: &Case) {
    let dir = temp_dir(name);
    let whole = dir.join("whole.exr");
    let run = case.render(&["--threads", "1", "-o", whole.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    for n in [4, 3] {
        let mut parts: Vec<PathBuf> = (0..n)
            .map(|i| case.part(&dir, i, n, &["--threads", "2"]))
            .collect();
        parts.reverse();
        let merged = dir.join(format!("merged-{n}.exr"));
        let run = merge(&parts, &merged, &[]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        assert!(
            run.stdout.contains(&format!("{n} of {n} parts")),
            "{}",
            run.stdout
        );
        assert!(
            bytes(&merged) == bytes(&whole),
            "{name}: the merge of {n} parts differs from the whole render"
        );
    }
    // And the parts are not all the same image: each holds its own share.
    let (_, _, a) = read_image(&dir.join("part-0-4.exr")).unwrap();
    let (_, _, b) = read_image(&dir.join("part-1-4.exr")).unwrap();
    assert_ne!(a, b, "{name}: parts 0 and 1 hold the same samples");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn path_parts_merge_to_the_whole_render() {
    assert_merge_is_exact(
        "parts-path",
        &Case::new("cornell-box.toml", &["--integrator", "path", "--spp", "6"]),
    );
}

/// The structured samplers too: strata and Sobol points are of the whole render's spp and
/// depend on (seed, pixel, sample) alone, so parts and thread counts change nothing; `photon`
/// with `sobol` also emits its photons from Sobol points.
#[test]
fn stratified_and_sobol_parts_merge_to_the_whole_render() {
    for sampler in ["stratified", "sobol"] {
        let set = format!("render.sampler={sampler:?}");
        assert_merge_is_exact(
            &format!("parts-path-{sampler}"),
            &Case::new(
                "cornell-box.toml",
                &["--integrator", "path", "--spp", "6", "--set", &set],
            ),
        );
    }
    assert_merge_is_exact(
        "parts-photon-sobol",
        &Case::new(
            "caustics.toml",
            &[
                "--integrator",
                "photon",
                "--spp",
                "4",
                "--set",
                "render.sampler=\"sobol\"",
                "--set",
                "integrators.photon.global_photons=20000",
                "--set",
                "integrators.photon.caustic_photons=20000",
            ],
        ),
    );
}

#[test]
fn photon_parts_merge_to_the_whole_render() {
    assert_merge_is_exact(
        "parts-photon",
        &Case::new(
            "caustics.toml",
            &[
                "--integrator",
                "photon",
                "--spp",
                "4",
                "--set",
                "integrators.photon.global_photons=20000",
                "--set",
                "integrators.photon.caustic_photons=20000",
            ],
        ),
    );
}

#[test]
fn vpm_parts_merge_to_the_whole_render() {
    assert_merge_is_exact(
        "parts-vpm",
        &Case::new(
            "cornell-fog.toml",
            &[
                "--integrator",
                "vpm",
                "--spp",
                "4",
                "--set",
                "integrators.vpm.global_photons=10000",
                "--set",
                "integrators.vpm.volume_photons=10000",
            ],
        ),
    );
}

/// sppm's iterations are split; under the global radius schedule every iteration's estimate
/// is a function of its number, and the film sums them exactly, so the merge is bit for bit
/// too (the bound the issue allows, summation order, is not needed).
#[test]
fn sppm_global_parts_merge_to_the_whole_render() {
    assert_merge_is_exact(
        "parts-sppm",
        &Case::new(
            "caustics.toml",
            &[
                "--integrator",
                "sppm",
                "--set",
                "integrators.sppm.radius_schedule=\"global\"",
                "--set",
                "integrators.sppm.iterations=5",
                "--set",
                "integrators.sppm.photons_per_iteration=5000",
            ],
        ),
    );
}

#[test]
fn sppm_pixel_schedule_refuses_parts_with_the_reason() {
    let dir = temp_dir("parts-sppm-pixel");
    let out = dir.join("p.exr");
    let case = Case::new(
        "caustics.toml",
        &[
            "--integrator",
            "sppm",
            "--set",
            "integrators.sppm.iterations=2",
        ],
    );
    let run = case.render(&["--part", "0/2", "-o", out.to_str().unwrap()]);
    assert_eq!(run.code, 1);
    for needle in ["radius_schedule = \"global\"", "pixel schedule", "0/2"] {
        assert!(run.stderr.contains(needle), "{needle}: {}", run.stderr);
    }
    assert!(!out.exists());
    // A time budget has no fixed number of iterations to split either.
    let case = Case::new(
        "caustics.toml",
        &[
            "--integrator",
            "sppm",
            "--set",
            "integrators.sppm.radius_schedule=\"global\"",
            "--set",
            "integrators.sppm.time=1",
        ],
    );
    let run = case.render(&["--part", "1/2", "-o", out.to_str().unwrap()]);
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert!(
        run.stderr.contains("number of iterations"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
}

/// A plugin that ignores `RenderContext::part` returns the film of the whole render: the host
/// refuses it instead of letting a merge count the work N times.
#[test]
fn an_integrator_that_ignores_the_part_is_refused() {
    let dir = temp_dir("parts-ignored");
    let out = dir.join("p.exr");
    let case = Case::new(
        "cornell-box.toml",
        &[
            "--integrator",
            "panicky",
            "--set",
            "integrators.panicky.panic_in=\"never\"",
        ],
    );
    let run = case.render(&["--part", "1/3", "-o", out.to_str().unwrap()]);
    assert_eq!(run.code, 1);
    assert!(
        run.stderr.contains("cannot render in parts") && run.stderr.contains("panicky"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
}

#[test]
fn bad_part_arguments_are_refused() {
    let dir = temp_dir("parts-args");
    let case = Case::new("cornell-box.toml", &["--spp", "2"]);
    for bad in ["4/4", "1", "a/2", "1/-2", "0/0"] {
        let run = case.render(&["--part", bad, "-o", dir.join("p.exr").to_str().unwrap()]);
        assert_eq!(run.code, 2, "{bad}: {}", run.stderr);
        assert!(run.stderr.contains("I/N"), "{bad}: {}", run.stderr);
    }
    // More parts than samples: a part without any says so.
    let empty = dir.join("empty.exr");
    let run = case.render(&["--part", "2/4", "-o", empty.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stderr.contains("holds none"), "{}", run.stderr);
    let png = dir.join("p.png");
    let run = case.render(&["--part", "0/2", "-o", png.to_str().unwrap()]);
    assert_eq!(run.code, 1);
    assert!(run.stderr.contains("only EXR"), "{}", run.stderr);
    assert!(!png.exists());
}

/// Parts that are missing, given twice, from another scene, seed or number of parts,
/// truncated, or not parts at all: each is a clear error and no output is written.
#[test]
fn bad_sets_of_parts_are_refused_and_nothing_is_written() {
    let dir = temp_dir("parts-bad");
    let case = Case::new("cornell-box.toml", &["--spp", "4"]);
    let parts: Vec<PathBuf> = (0..4).map(|i| case.part(&dir, i, 4, &[])).collect();
    let other_dir = temp_dir("parts-bad-other");
    let other_scene = Case::new(
        "cornell-box.toml",
        &["--spp", "4", "--set", "film.exposure=1"],
    )
    .part(&other_dir, 2, 4, &[]);
    let other_seed =
        Case::new("cornell-box.toml", &["--spp", "4", "--seed", "99"]).part(&other_dir, 3, 4, &[]);
    let other_n = case.part(&other_dir, 1, 3, &[]);
    let truncated = dir.join("truncated.exr");
    let b = bytes(&parts[2]);
    std::fs::write(&truncated, &b[..b.len() * 2 / 3]).unwrap();
    let plain = dir.join("plain.exr");
    let run = case.render(&["-o", plain.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);

    let out = dir.join("merged.exr");
    let p = |i: usize| parts[i].clone();
    let cases: Vec<(&str, Vec<PathBuf>, Vec<&str>)> = vec![
        (
            "missing",
            vec![p(0), p(1), p(3)],
            vec!["missing", "2/4", "--partial"],
        ),
        (
            "twice",
            vec![p(0), p(1), p(1), p(2), p(3)],
            vec!["part 1/4 is given twice"],
        ),
        (
            "other scene",
            vec![p(0), p(1), other_scene, p(3)],
            vec!["another scene", "scene hash"],
        ),
        (
            "other seed",
            vec![p(0), p(1), p(2), other_seed],
            vec!["seed 99 (the other: 0)"],
        ),
        (
            "other count",
            vec![p(0), other_n, p(2), p(3)],
            vec!["number of parts 3"],
        ),
        (
            "truncated",
            vec![p(0), p(1), truncated.clone(), p(3)],
            vec!["truncated.exr", "cannot read the part"],
        ),
        (
            "not a part",
            vec![p(0), plain.clone()],
            vec!["plain.exr", "not a foton part"],
        ),
    ];
    for (what, files, needles) in cases {
        let run = merge(&files, &out, &[]);
        assert_eq!(run.code, 1, "{what}: {}", run.stderr);
        for needle in needles {
            assert!(
                run.stderr.contains(needle),
                "{what}: {needle}: {}",
                run.stderr
            );
        }
        assert!(!out.exists(), "{what}: an output was written");
    }
    // A truncated part is refused even when every header is fine and --partial is given.
    let run = merge(&[p(0), p(1), truncated, p(3)], &out, &["--partial"]);
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert!(!out.exists());
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");

    // --partial merges what is there and says what is missing: 3 of 4 parts of 4 spp hold
    // 3 samples per pixel, so the image is the mean of those three.
    let run = merge(&[p(0), p(1), p(3)], &out, &["--partial"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stderr.contains("without part(s) 2/4"), "{}", run.stderr);
    assert!(run.stdout.contains("3 of 4 parts"), "{}", run.stdout);
    let (_, _, partial) = read_image(&out).unwrap();
    let three = dir.join("three.exr");
    let run = merge(&[p(0), p(1)], &three, &["--partial"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let (_, _, two) = read_image(&three).unwrap();
    let (_, _, last) = read_image(&p(3)).unwrap();
    for ((m, a), b) in partial.iter().zip(&two).zip(&last) {
        let expected = (*a * 2.0 + *b) / 3.0;
        assert!(
            (*m - expected).abs().max_element() <= 1e-5 * expected.max_element().max(1.0),
            "{m} vs {expected}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&other_dir);
}

/// The shares of the parts cover the work exactly once, in order, and differ by one unit at
/// most.
#[test]
fn shares_cover_the_work_once() {
    for total in [0u64, 1, 2, 7, 64, 1000, u32::MAX as u64 * 3] {
        for n in [1u32, 2, 3, 4, 7, 64, 1000] {
            let mut next = 0;
            let (mut lo, mut hi) = (u64::MAX, 0);
            for i in 0..n {
                let s = Part::new(i, n).unwrap().share(total);
                assert_eq!(s.start, next, "total {total}, part {i}/{n}");
                next = s.end;
                lo = lo.min(s.end - s.start);
                hi = hi.max(s.end - s.start);
            }
            assert_eq!(next, total, "total {total}, {n} parts");
            assert!(hi - lo <= 1, "total {total}, {n} parts: {lo}..{hi}");
        }
    }
    assert!(Part::new(3, 3).is_none());
    assert_eq!(Part::WHOLE.share(5), 0..5);
}

/// The film's fixed-point sums: the same bits in any order of addition, and the mean within a
/// relative 1e-12 of the f64 sum for radiance over 24 orders of magnitude.
#[test]
fn radiance_sums_are_exact_in_any_order() {
    let mut rng = Rng::new(&[11]);
    let samples: Vec<Rgb> = (0..10_000)
        .map(|_| {
            let e = |u: f32| 10f32.powf(u * 24.0 - 12.0);
            Rgb::new(e(rng.next_f32()), e(rng.next_f32()), e(rng.next_f32()))
        })
        .collect();
    let mut forward = RadianceSum::ZERO;
    samples.iter().for_each(|s| forward.add(*s));
    let mut backward = RadianceSum::ZERO;
    samples.iter().rev().for_each(|s| backward.add(*s));
    // In blocks, merged, as parts and tiles are.
    let mut blocks = RadianceSum::ZERO;
    for chunk in samples.chunks(7) {
        let mut b = RadianceSum::ZERO;
        chunk.iter().for_each(|s| b.add(*s));
        blocks.merge(&b);
    }
    assert_eq!(forward, backward);
    assert_eq!(forward, blocks);
    // Values on either side of the fast conversion's range convert as the general one does.
    for x in [
        0.0f32, 1e-30, 0.75, 1.0, 3.0e9, 8.9e18, 9.1e18, 1e30, -0.5, -3.0,
    ] {
        let mut a = RadianceSum::ZERO;
        a.add(Rgb::splat(x));
        let expected = (x as f64 * 2f64.powi(64)) as i128;
        assert_eq!(a.0, [expected; 3], "{x}");
    }
    let exact: [f64; 3] = [0, 1, 2].map(|c| samples.iter().map(|s| s[c] as f64).sum());
    for (c, (got, exact)) in forward.to_f64().into_iter().zip(exact).enumerate() {
        assert!(
            ((got - exact) / exact).abs() < 1e-12,
            "channel {c}: {got} vs {exact}"
        );
    }
}
