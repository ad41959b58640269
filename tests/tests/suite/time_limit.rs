//! `render.time`, a time limit (Mitsuba's `timeout`): `foton render` takes the camera samples
//! that fill it, never more than the scene's `spp`, and says which `render.spp` renders the
//! same image. The 32x32 box of the tools' tests, rendered by `path`.

use crate::tools::{fails_with, ok, s, setup};
use foton_tests::foton_with_plugins;

/// The samples per pixel the note names ("`--set render.spp=N` renders the same image").
fn chosen_spp(stderr: &str) -> u32 {
    let at = stderr.find("render.spp=").expect("the note names the spp") + "render.spp=".len();
    let digits: String = stderr[at..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().unwrap()
}

/// The camera samples the summary line reports ("65536 samples in 0.12 s").
fn samples(stdout: &str) -> u64 {
    let end = stdout.find(" samples in").expect("the summary line");
    let start = stdout[..end].rfind(' ').map_or(0, |i| i + 1);
    stdout[start..end].parse().unwrap()
}

#[test]
fn a_time_limit_chooses_the_samples_and_names_the_count_that_renders_the_same_image() {
    let (dir, scene) = setup("time-limit");
    let timed = dir.join("timed.exr");
    // A million samples per pixel take minutes; 0.3 s take far fewer.
    let run = foton_with_plugins(&[
        "render",
        s(&scene),
        "--set",
        "render.spp=1000000",
        "--set",
        "render.time=0.3",
        "-o",
        s(&timed),
        "-q",
    ]);
    ok(&run);
    let spp = chosen_spp(&run.stderr);
    assert!(spp < 1_000_000, "{}", run.stderr);
    assert_eq!(
        samples(&run.stdout),
        u64::from(spp) * 32 * 32,
        "{}",
        run.stdout
    );
    let plain = dir.join("plain.exr");
    let set = format!("render.spp={spp}");
    ok(&foton_with_plugins(&[
        "render",
        s(&scene),
        "--set",
        &set,
        "-o",
        s(&plain),
        "-q",
    ]));
    assert!(
        std::fs::read(&timed).unwrap() == std::fs::read(&plain).unwrap(),
        "the time-limited render differs from the render at {spp} spp"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_time_limit_never_adds_samples() {
    let (dir, scene) = setup("time-limit-bound");
    // The scene asks for 2 spp; a minute fits far more, and 2 are rendered.
    let run = foton_with_plugins(&[
        "render",
        s(&scene),
        "--set",
        "render.time=60",
        "-o",
        s(&dir.join("out.exr")),
        "-q",
    ]);
    ok(&run);
    assert_eq!(chosen_spp(&run.stderr), 2, "{}", run.stderr);
    assert_eq!(samples(&run.stdout), 2 * 32 * 32, "{}", run.stdout);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_time_limit_is_refused_for_a_part_and_must_be_positive() {
    let (dir, scene) = setup("time-limit-bad");
    let part = foton_with_plugins(&[
        "render",
        s(&scene),
        "--set",
        "render.time=1",
        "--part",
        "0/2",
        "-o",
        s(&dir.join("p.exr")),
    ]);
    fails_with(&part, &["--part", "render.time", "render.spp"]);
    let zero = foton_with_plugins(&["check", s(&scene), "--set", "render.time=0"]);
    fails_with(&zero, &["render.time", "above 0"]);
    let _ = std::fs::remove_dir_all(dir);
}
