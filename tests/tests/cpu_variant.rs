//! The x86-64-v3 build of the path plugin (build.rs) is accepted by the `foton` built beside it and
//! renders the same images bit for bit as the baseline build. Runs where a release build has
//! made the variant and the `foton` program and the processor has x86-64-v3 (as
//! `cargo test --release --workspace` on such a machine); says so and passes otherwise.

use std::path::{Path, PathBuf};
use std::process::Command;

/// `<target>/<profile>/`: the test executable is in its `deps/`.
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().unwrap().parent().unwrap().to_path_buf()
}

fn render(foton: &Path, plugin: &Path, dir: &Path, sampler: &str) -> Vec<u8> {
    let plugins = dir.join("plugins");
    std::fs::create_dir_all(&plugins).unwrap();
    std::fs::copy(plugin, plugins.join("libfoton_path.so")).unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell_point.toml");
    let out = dir.join("image.exr");
    let run = Command::new(foton)
        .arg("render")
        .arg(&scene)
        .args(["-q", "--threads", "2", "--spp", "4", "--plugin-dir"])
        .arg(&plugins)
        .args(["--set", "film.width=32", "--set", "film.height=32"])
        .args(["--set", &format!("render.sampler={sampler}")])
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // The plugin that rendered is the one given (not one beside foton).
    let listed = Command::new(foton)
        .args(["plugins", "--plugin-dir"])
        .arg(&plugins)
        .output()
        .unwrap();
    let listed = String::from_utf8_lossy(&listed.stdout).into_owned();
    let line = listed.lines().find(|l| l.starts_with("path ")).unwrap();
    assert!(line.contains(plugins.to_str().unwrap()), "{listed}");
    std::fs::read(out).unwrap()
}

#[test]
fn x86_64_v3_build_renders_the_same_images() {
    let dir = profile_dir();
    let (foton, variant) = (dir.join("foton"), dir.join("x86-64-v3/libfoton_path.so"));
    let baseline = dir.join("deps/libfoton_path.so");
    let has_v3 = foton_core::plugin::cpu_has("x86-64-v3");
    if !(has_v3 && foton.is_file() && variant.is_file() && baseline.is_file()) {
        eprintln!(
            "skipped: x86-64-v3 {has_v3}, {} {}, {} {}",
            foton.display(),
            foton.is_file(),
            variant.display(),
            variant.is_file()
        );
        return;
    }
    let tmp = std::env::temp_dir().join(format!("foton-cpu-variant-{}", std::process::id()));
    for sampler in ["independent", "sobol"] {
        let a = render(
            &foton,
            &baseline,
            &tmp.join(format!("base-{sampler}")),
            sampler,
        );
        let b = render(
            &foton,
            &variant,
            &tmp.join(format!("v3-{sampler}")),
            sampler,
        );
        assert!(a == b, "{sampler}: the x86-64-v3 build's image differs");
    }
    let _ = std::fs::remove_dir_all(&tmp);
}
