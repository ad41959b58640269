//! Ctrl-C while `foton render` measures what a sample costs for `render.time`: the command
//! stops there, says so and writes no image. In a test binary of its own, because it raises
//! the process-wide interrupt flag that every in-process render watches.

use foton_cli::INTERRUPTED;
use foton_tests::{foton_with_plugins, repo_root, temp_dir};
use std::sync::atomic::Ordering;
use std::time::Duration;

#[test]
fn ctrl_c_during_the_calibration_renders_nothing() {
    let dir = temp_dir("time-limit-interrupt");
    let out = dir.join("never.exr");
    let scene = repo_root().join("scenes/cornell-box.toml");
    // A limit of 60 s calibrates for 6 s; Ctrl-C comes after half a second (the command
    // clears the flag when it starts, well before that).
    let stopper = std::thread::spawn(|| {
        std::thread::sleep(Duration::from_millis(500));
        INTERRUPTED.store(true, Ordering::SeqCst);
    });
    let run = foton_with_plugins(&[
        "render",
        scene.to_str().unwrap(),
        "--set",
        "render.time=60",
        "--set",
        "render.spp=1000000",
        "--set",
        "film.width=16",
        "--set",
        "film.height=16",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    stopper.join().unwrap();
    INTERRUPTED.store(false, Ordering::SeqCst);
    assert_eq!(
        run.code, 130,
        "stdout:\n{}\nstderr:\n{}",
        run.stdout, run.stderr
    );
    assert!(
        run.stderr.contains("interrupted while measuring"),
        "{}",
        run.stderr
    );
    assert!(!out.exists(), "an image was written");
    let _ = std::fs::remove_dir_all(&dir);
}
