//! Progressive rendering from the host's side: checkpoints written while `sppm` runs, and
//! Ctrl-C returning the estimate so far. In a test binary of its own, because it raises the
//! process-wide interrupt flag that every in-process render watches.

use foton_cli::{INTERRUPTED, TermProgress, prepare, render_prepared};
use foton_loader::image::read_image;
use foton_tests::{foton_with_plugins, plugin_dir, repo_root, temp_dir};
use std::sync::atomic::Ordering;
use std::time::Duration;

#[test]
fn checkpoints_are_written_and_ctrl_c_keeps_the_estimate() {
    let dir = temp_dir("sppm-interrupt");
    let out = dir.join("progress.exr");
    let overrides: Vec<String> = [
        "render.integrator=\"sppm\"",
        "film.width=16",
        "film.height=16",
        "integrators.sppm.iterations=100000000",
        "integrators.sppm.photons_per_iteration=2000",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let prepared = prepare(
        &repo_root().join("scenes/cornell-box.toml"),
        &overrides,
        &[plugin_dir()],
        true,
    )
    .unwrap();
    let progress =
        TermProgress::new(true).with_checkpoint(3, out.clone(), Default::default(), None);
    // Far too many iterations to finish: only the interrupt ends it.
    let stopper = std::thread::spawn(|| {
        std::thread::sleep(Duration::from_millis(1500));
        INTERRUPTED.store(true, Ordering::SeqCst);
    });
    let (film, _) = render_prepared(&prepared, 2, &progress).unwrap();
    stopper.join().unwrap();
    INTERRUPTED.store(false, Ordering::SeqCst);

    let iterations = progress.checkpoints.load(Ordering::Relaxed);
    assert!(iterations >= 3, "only {iterations} iterations in 1.5 s");
    // The estimate so far: every pixel sees the lit box.
    for p in film.pixels() {
        assert!(p.is_finite() && p.min_element() > 0.0, "{p}");
    }
    // A checkpoint was written (render_prepared itself writes nothing), and it is an image
    // of the same scene at an earlier iteration: close to the final estimate on average.
    let (w, h, pixels) = read_image(&out).unwrap();
    assert_eq!((w, h), (16, 16));
    let mean =
        |px: &[glam::Vec3]| px.iter().map(|p| p.element_sum()).sum::<f32>() / px.len() as f32;
    let (a, b) = (mean(&pixels), mean(&film.pixels()));
    assert!((a - b).abs() < 0.2 * b, "checkpoint mean {a} vs final {b}");
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "temporary files left: {leftovers:?}");
    let _ = std::fs::remove_dir_all(&dir);

    interrupted_render_reports_iterations();
}

/// `foton render` stopped by Ctrl-C says how many whole iterations the image holds, and its
/// summary counts iterations and photons (not the one camera sample per pixel per iteration).
/// Run after the test above, not beside it: both raise the process-wide interrupt flag.
fn interrupted_render_reports_iterations() {
    let dir = temp_dir("sppm-interrupt-message");
    let out = dir.join("interrupted.png");
    let scene = repo_root().join("scenes/cornell-box.toml");
    // The checkpoint of the first iteration shows that the render is under way (the command
    // clears the interrupt flag when it starts): only then is Ctrl-C simulated.
    let watched = out.clone();
    let stopper = std::thread::spawn(move || {
        let start = std::time::Instant::now();
        while !watched.exists() && start.elapsed() < Duration::from_secs(120) {
            std::thread::sleep(Duration::from_millis(20));
        }
        INTERRUPTED.store(true, Ordering::SeqCst);
    });
    let run = foton_with_plugins(&[
        "render",
        scene.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
        "--checkpoint",
        "1",
        "--set",
        "render.integrator=\"sppm\"",
        "--set",
        "film.width=16",
        "--set",
        "film.height=16",
        "--set",
        "integrators.sppm.iterations=100000000",
        "--set",
        "integrators.sppm.photons_per_iteration=2000",
    ]);
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
    // The summary agrees with it: every iteration emitted its 2000 photons.
    assert!(
        run.stdout
            .contains(&format!("{done} iterations, {} photons in", done * 2000)),
        "{shown}"
    );
    assert!(!run.stdout.contains("samples"), "{shown}");
    let _ = std::fs::remove_dir_all(&dir);
}
