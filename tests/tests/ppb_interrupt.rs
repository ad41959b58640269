//! Progressive photon beams from the host's side, as tests/tests/sppm_interrupt.rs does for
//! `sppm`: Ctrl-C after some passes returns exactly the average of the passes done (the image
//! is bit for bit the render of that many passes), `--checkpoint` writes the image of the
//! passes so far atomically, and the interrupted command says how many passes its image holds.
//! `--part I/N` + `foton merge` (bit for bit the whole render) is in tests/tests/suite/ppb.rs. In a
//! test binary of its own, because it raises the process-wide interrupt flag that every
//! in-process render watches.

use foton_cli::{INTERRUPTED, TermProgress, prepare, render_prepared};
use foton_core::film::Film;
use foton_loader::image::read_image;
use foton_tests::{foton_with_plugins, plugin_dir, repo_root, temp_dir};
use std::sync::atomic::Ordering;
use std::time::Duration;

/// The foggy Cornell box at 16 x 16 with `ppb`, small passes.
const SET: [&str; 6] = [
    "render.integrator=\"ppb\"",
    "film.width=16",
    "film.height=16",
    "integrators.ppb.photons_per_iteration=2000",
    "integrators.ppb.surface_photons=4000",
    "render.seed=3",
];

fn scene() -> std::path::PathBuf {
    repo_root().join("scenes/cornell-fog.toml")
}

/// The render of exactly `passes` passes, uninterrupted.
fn render_passes(passes: u64) -> Film {
    let n = format!("integrators.ppb.iterations={passes}");
    foton_tests::render_file(&scene(), &[&SET[..], &[n.as_str()]].concat(), 2)
}

#[test]
fn ctrl_c_and_checkpoints_hold_the_average_of_the_passes_done() {
    let dir = temp_dir("ppb-interrupt");
    let out = dir.join("progress.exr");
    let overrides: Vec<String> = SET
        .iter()
        .chain(&["integrators.ppb.iterations=100000000"])
        .map(|s| s.to_string())
        .collect();
    let prepared = prepare(&scene(), &overrides, &[plugin_dir()], true).unwrap();
    let every = 2;
    let progress =
        TermProgress::new(true).with_checkpoint(every, out.clone(), Default::default(), None);
    // Far too many passes to finish: only the interrupt ends it.
    let stopper = std::thread::spawn(|| {
        std::thread::sleep(Duration::from_millis(1500));
        INTERRUPTED.store(true, Ordering::SeqCst);
    });
    let (film, _) = render_prepared(&prepared, 2, &progress).unwrap();
    stopper.join().unwrap();
    INTERRUPTED.store(false, Ordering::SeqCst);

    // The image says how many passes it holds, each of them whole (a pass cut short by the
    // interrupt is dropped: part of its photons would bias it) ...
    let done = film.iterations;
    assert_eq!(done, progress.checkpoints.load(Ordering::Relaxed));
    assert!(done >= 2, "only {done} passes in 1.5 s");
    assert_eq!(film.photons, done * 2000);
    // ... and is their average: bit for bit the render of `done` passes (the passes' random
    // streams depend on their number alone, not on how many are planned).
    assert!(
        film.pixels() == render_passes(done).pixels(),
        "the interrupted image is not the render of its {done} passes"
    );
    // The last checkpoint holds the passes up to the last multiple of `every`, bit for bit,
    // and was written atomically: no temporary file is left beside it.
    let last = done / every * every;
    let (w, h, pixels) = read_image(&out).unwrap();
    assert_eq!((w, h), (16, 16));
    assert!(
        pixels == render_passes(last).pixels(),
        "the checkpoint is not the render of its {last} passes"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "temporary files left: {leftovers:?}");
    let _ = std::fs::remove_dir_all(&dir);

    interrupted_command_writes_the_passes_done();
}

/// `foton render` stopped by Ctrl-C writes the image of its whole passes, says how many, and
/// its summary counts passes and photons. Run after the test above, not beside it: both
/// raise the process-wide interrupt flag.
fn interrupted_command_writes_the_passes_done() {
    let dir = temp_dir("ppb-interrupt-command");
    let out = dir.join("interrupted.exr");
    // The checkpoint of the first pass shows that the render is under way (the command
    // clears the interrupt flag when it starts): only then is Ctrl-C simulated.
    let watched = out.clone();
    let stopper = std::thread::spawn(move || {
        let start = std::time::Instant::now();
        while !watched.exists() && start.elapsed() < Duration::from_secs(120) {
            std::thread::sleep(Duration::from_millis(20));
        }
        INTERRUPTED.store(true, Ordering::SeqCst);
    });
    let scene = scene();
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
        "--checkpoint",
        "1",
    ];
    for s in SET.iter().chain(&["integrators.ppb.iterations=100000000"]) {
        args.extend(["--set", s]);
    }
    let run = foton_with_plugins(&args);
    stopper.join().unwrap();
    INTERRUPTED.store(false, Ordering::SeqCst);
    let shown = format!("stdout:\n{}stderr:\n{}", run.stdout, run.stderr);
    assert_eq!(run.code, 130, "{shown}");
    let prefix = "interrupted: wrote the estimate of the ";
    let rest = run
        .stderr
        .lines()
        .find_map(|l| l.strip_prefix(prefix))
        .unwrap_or_else(|| panic!("no `{prefix}...` line:\n{shown}"));
    let (done, rest) = rest.split_once(' ').unwrap();
    let done: u64 = done.parse().unwrap();
    assert!(done >= 1, "{shown}");
    assert_eq!(rest, "of 100000000 iterations done", "{shown}");
    assert!(
        run.stdout
            .contains(&format!("{done} iterations, {} photons in", done * 2000)),
        "{shown}"
    );
    let (_, _, pixels) = read_image(&out).unwrap();
    assert!(
        pixels == render_passes(done).pixels(),
        "the interrupted command's image is not the render of its {done} passes"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
