//! End-to-end tests of the `foton` executable as a user runs it: plugin discovery beside the
//! executable and through FOTON_PLUGIN_PATH, deleting a plugin, help texts, `bench`'s BVH
//! traversal flag, Ctrl-C.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn deps_dir() -> PathBuf {
    std::env::current_exe()
        .unwrap()
        .parent()
        .unwrap()
        .to_path_buf()
}

fn path_plugin() -> PathBuf {
    let so = deps_dir().join(format!(
        "{}foton_path{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    assert!(so.is_file(), "cargo should have built {}", so.display());
    so
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("foton-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A fresh "installation": a copy of the foton executable, optionally with the path plugin
/// beside it.
fn install(name: &str, with_plugin: bool) -> (PathBuf, PathBuf) {
    let dir = temp_dir(name);
    let exe = dir.join("foton");
    std::fs::copy(env!("CARGO_BIN_EXE_foton"), &exe).unwrap();
    if with_plugin {
        std::fs::copy(path_plugin(), dir.join(path_plugin().file_name().unwrap())).unwrap();
    }
    (dir, exe)
}

fn foton(exe: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(exe)
        .args(args)
        .env_remove("FOTON_PLUGIN_PATH")
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn scene(dir: &Path, spp: u32, size: u32) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let text = std::fs::read_to_string(src)
        .unwrap()
        .replace("spp = 64", &format!("spp = {spp}"))
        .replace("width = 256", &format!("width = {size}"))
        .replace("height = 256", &format!("height = {size}"));
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn plugin_beside_the_executable_is_found_and_deleting_it_removes_it() {
    let (dir, exe) = install("beside", true);
    let (code, out, _) = foton(&exe, &["plugins"]);
    assert_eq!(code, 0);
    assert!(
        out.lines()
            .any(|l| l.starts_with("path ") && l.contains("integrator")),
        "{out}"
    );

    let scene = scene(&dir, 1, 8);
    let (code, _, err) = foton(&exe, &["render", scene.to_str().unwrap(), "-q"]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("cornell-box.png").is_file());

    std::fs::remove_file(dir.join(path_plugin().file_name().unwrap())).unwrap();
    let (code, out, _) = foton(&exe, &["plugins"]);
    assert_eq!(code, 0);
    assert!(!out.lines().any(|l| l.starts_with("path ")), "{out}");
    let (code, _, err) = foton(&exe, &["render", scene.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("no integrator plugin named `path`"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn plugin_is_found_through_flag_and_environment() {
    let (dir, exe) = install("env", false);
    let plugins = dir.join("elsewhere");
    std::fs::create_dir_all(&plugins).unwrap();
    std::fs::copy(
        path_plugin(),
        plugins.join(path_plugin().file_name().unwrap()),
    )
    .unwrap();

    let (_, out, _) = foton(&exe, &["plugins"]);
    assert!(!out.lines().any(|l| l.starts_with("path ")), "{out}");

    let (_, out, _) = foton(
        &exe,
        &["plugins", "--plugin-dir", plugins.to_str().unwrap()],
    );
    assert!(out.lines().any(|l| l.starts_with("path ")), "{out}");

    let out = Command::new(&exe)
        .arg("plugins")
        .env(
            "FOTON_PLUGIN_PATH",
            format!("/nonexistent:{}", plugins.display()),
        )
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&out.stdout);
    assert!(out.lines().any(|l| l.starts_with("path ")), "{out}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_scene_cannot_name_a_plugin_file() {
    // The integrator field is a name looked up on the search path, never a path to load.
    let (dir, exe) = install("no-path", true);
    let scene = scene(&dir, 1, 8);
    let evil = dir.join("libfoton_evil.so");
    std::fs::copy(path_plugin(), &evil).unwrap();
    let name = evil.to_str().unwrap();
    let (code, _, err) = foton(
        &exe,
        &["render", scene.to_str().unwrap(), "--integrator", name],
    );
    assert_eq!(code, 1);
    assert!(err.contains("no integrator plugin named"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn every_subcommand_has_help() {
    let exe = Path::new(env!("CARGO_BIN_EXE_foton"));
    for sub in [
        "render", "check", "merge", "convert", "plugins", "bench", "photons", "compare", "sweep",
    ] {
        let (code, out, _) = foton(exe, &[sub, "--help"]);
        assert_eq!(code, 0, "{sub} --help");
        assert!(out.contains("Usage: foton"), "{sub}: {out}");
    }
    let (code, _, err) = foton(exe, &["render"]);
    assert_eq!(code, 2, "a missing argument is a usage error");
    assert!(err.contains("SCENE"), "{err}");
}

#[test]
fn ctrl_c_writes_the_samples_done_so_far() {
    let (dir, exe) = install("ctrl-c", true);
    // Far too many samples to finish: only an interrupt ends it.
    let scene = scene(&dir, 100_000, 32);
    let output = dir.join("partial.exr");
    let child = Command::new(&exe)
        .args([
            "render",
            scene.to_str().unwrap(),
            "-q",
            "-o",
            output.to_str().unwrap(),
        ])
        .env_remove("FOTON_PLUGIN_PATH")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    // A path tracer counts its work in samples: the message says how many of all.
    let samples = err
        .lines()
        .find_map(|l| l.strip_prefix("interrupted: wrote the image of the "))
        .and_then(|rest| rest.strip_suffix(" samples done so far"))
        .unwrap_or_else(|| panic!("no `interrupted: ...` line: {err}"));
    let full = (32 * 32 * 100_000u64).to_string();
    let (done, of) = samples.split_once(" of ").unwrap();
    assert_eq!(of, full, "{err}");
    let done: u64 = done.parse().unwrap();
    assert!(done > 0 && done < 32 * 32 * 100_000, "{err}");
    let (w, h, px) = foton_loader::image::read_image(&output).unwrap();
    assert_eq!((w, h), (32, 32));
    // Every pixel has samples from the passes completed: none is black in a lit box.
    assert!(px.iter().all(|p| p.max_element() > 0.0));
    let _ = std::fs::remove_dir_all(dir);
}

/// Under a batch system or `nohup` stderr is a file or a pipe: the bar is replaced by a plain
/// line every FOTON_PROGRESS_INTERVAL seconds (percentage, elapsed, time left), ending with
/// the phase done; `-q` prints none.
#[test]
fn progress_without_a_terminal_is_a_plain_line_now_and_then() {
    let (dir, exe) = install("progress", true);
    let scene = scene(&dir, 64, 48);
    let run = |quiet: bool| {
        let mut cmd = Command::new(&exe);
        cmd.args(["render", scene.to_str().unwrap(), "-o"])
            .arg(dir.join("out.png"))
            .env_remove("FOTON_PLUGIN_PATH")
            .env("FOTON_PROGRESS_INTERVAL", "0.001")
            .stderr(Stdio::piped());
        if quiet {
            cmd.arg("-q");
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let text = run(false);
    let lines: Vec<&str> = text.lines().filter(|l| l.starts_with("pixels: ")).collect();
    assert!(lines.len() >= 2, "no progress lines:\n{text}");
    let percent = |l: &str| -> u32 {
        l["pixels: ".len()..]
            .split('%')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let all: Vec<u32> = lines.iter().map(|l| percent(l)).collect();
    assert!(all.windows(2).all(|w| w[0] <= w[1]), "{text}");
    assert!(lines.iter().all(|l| l.contains("elapsed")), "{text}");
    let last = lines.last().unwrap();
    assert!(percent(last) == 100 && last.ends_with("done"), "{text}");
    assert!(
        lines[..lines.len() - 1].iter().any(|l| l.contains("left")),
        "{text}"
    );
    assert!(
        !text.contains('\r'),
        "no terminal escapes in a log: {text:?}"
    );
    assert!(!run(true).contains("pixels: "));
    let _ = std::fs::remove_dir_all(dir);
}

/// `foton bench` with no scene renders the default scene built into the program, from any
/// folder.
#[test]
fn bench_without_a_scene_works_from_any_folder() {
    let (dir, exe) = install("bench", true);
    let out = Command::new(&exe)
        .args([
            "bench",
            "--spp",
            "1",
            "--repeat",
            "1",
            "--set",
            "film.width=16",
        ])
        .current_dir(&dir)
        .env_remove("FOTON_PLUGIN_PATH")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("cornell-box.toml with path") && stdout.contains("16x256"),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// `bench --obvhs-traversal` switches the scene's BVH to obvhs' own traversal, and says so;
/// its former name `--narrow-bvh` still works for the scripts that use it, unlisted.
#[test]
fn bench_names_the_bvh_traversal_and_keeps_the_old_flag() {
    // The built-in Cornell box, small.
    let small = ["--repeat", "1", "--spp", "1", "--set", "film.width=8"];
    let (dir, exe) = install("bench-traversal", true);
    for (flag, traversal) in [
        ("--seed=1", "BVH traversed through float nodes"),
        ("--obvhs-traversal", "BVH traversed by obvhs"),
        ("--narrow-bvh", "BVH traversed by obvhs"),
    ] {
        let (code, out, err) = foton(&exe, &[&["bench", flag][..], &small].concat());
        assert_eq!(code, 0, "{flag}: {err}");
        assert!(out.contains(traversal), "{flag}: {out}");
    }
    let (_, help, _) = foton(&exe, &["bench", "--help"]);
    assert!(help.contains("--obvhs-traversal"), "{help}");
    assert!(!help.contains("narrow"), "{help}");
    let _ = std::fs::remove_dir_all(dir);
}
