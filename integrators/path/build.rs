//! Builds this plugin a second time for x86-64-v3 (AVX2, FMA, BMI2...) beside the baseline
//! one: `<profile>/x86-64-v3/libfoton_path.so`, which foton loads instead where the processor
//! has those features (core's `plugin::search_path`). A `#[target_feature]` copy of the path
//! loop does not get the gain, because core's walk, scene and BSDF functions are then no
//! longer inlined into it; the whole crate and core compiled with `-C target-cpu=x86-64-v3`
//! do (docs/PERFORMANCE.md). Cargo has no per-package target CPU, so this script
//! runs cargo again, on this package alone, in its own target folder (sharing the outer
//! build's job slots). Release builds on x86-64 only; `FOTON_NO_CPU_VARIANTS=1` skips it. A
//! failure is a warning: the baseline plugin is built regardless and works everywhere.
//!
//! The variant's core is identified as the baseline's build with a `+x86-64-v3` tag
//! (core/build.rs), so the host's checks (core build identifier, layout fingerprint) hold.

use std::path::{Path, PathBuf};
use std::process::Command;

const LEVEL: &str = "x86-64-v3";

fn main() {
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.toml");
    // The variant links core: rebuild it when core or the dependencies' versions change.
    for input in ["src", "Cargo.toml", "build.rs", "build_id.rs"] {
        println!("cargo:rerun-if-changed=../../core/{input}");
    }
    println!("cargo:rerun-if-changed=../../Cargo.lock");
    println!("cargo:rerun-if-env-changed=FOTON_PLUGIN_VARIANT");
    println!("cargo:rerun-if-env-changed=FOTON_NO_CPU_VARIANTS");

    let var = |name: &str| std::env::var(name).unwrap_or_default();
    // The variant's own build (this script run by the cargo it starts) builds nothing more.
    if std::env::var_os("FOTON_PLUGIN_VARIANT").is_some()
        || std::env::var_os("FOTON_NO_CPU_VARIANTS").is_some()
        || var("CARGO_CFG_TARGET_ARCH") != "x86_64"
        || var("CARGO_CFG_TARGET_OS") != "linux"
        || var("PROFILE") != "release"
    {
        return;
    }
    // Already built for v3 or beyond (RUSTFLAGS): the baseline plugin is the variant.
    if var("CARGO_CFG_TARGET_FEATURE")
        .split(',')
        .any(|f| f == "avx2")
    {
        return;
    }
    let out_dir = PathBuf::from(var("OUT_DIR"));
    // OUT_DIR is <target>/[<triple>/]<profile>/build/<package>-<hash>/out.
    let Some(profile_dir) = out_dir.ancestors().nth(3).map(Path::to_path_buf) else {
        return;
    };
    if let Err(e) = build_variant(&profile_dir) {
        println!("cargo:warning=the {LEVEL} build of the path plugin was skipped: {e}");
    }
}

fn build_variant(profile_dir: &Path) -> Result<(), String> {
    let target_dir = profile_dir.join(format!("{LEVEL}-build"));
    let mut flags = std::env::var("CARGO_ENCODED_RUSTFLAGS").unwrap_or_default();
    if !flags.is_empty() {
        flags.push('\u{1f}');
    }
    flags.push_str(&format!("-Ctarget-cpu={LEVEL}"));
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap()).join("Cargo.toml");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.args([
        "build",
        "--release",
        "--lib",
        "--offline",
        "--manifest-path",
    ])
    .arg(&manifest)
    .env("CARGO_TARGET_DIR", &target_dir)
    .env("CARGO_ENCODED_RUSTFLAGS", flags)
    .env("FOTON_PLUGIN_VARIANT", LEVEL)
    .env_remove("RUSTFLAGS")
    .env_remove("CARGO_BUILD_RUSTFLAGS")
    .env_remove("RUSTC_WORKSPACE_WRAPPER");
    // The baseline's target features, from which core identifies the variant's build.
    match std::env::var_os("CARGO_CFG_TARGET_FEATURE") {
        Some(f) => cmd.env("FOTON_VARIANT_BASE_FEATURES", f),
        None => cmd.env_remove("FOTON_VARIANT_BASE_FEATURES"),
    };
    let out = cmd.output().map_err(|e| format!("cannot run cargo: {e}"))?;
    if !out.status.success() {
        let log = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = log.lines().rev().take(5).collect();
        return Err(format!(
            "cargo failed: {}",
            tail.into_iter().rev().collect::<Vec<_>>().join(" / ")
        ));
    }
    let name = "libfoton_path.so";
    let built = target_dir.join("release").join(name);
    let dest_dir = profile_dir.join(LEVEL);
    std::fs::create_dir_all(&dest_dir).map_err(|e| format!("{}: {e}", dest_dir.display()))?;
    // Copied to a temporary name and renamed, so that a foton running meanwhile never loads
    // a half-written library.
    let tmp = dest_dir.join(format!(".{name}.tmp"));
    std::fs::copy(&built, &tmp).map_err(|e| format!("{}: {e}", built.display()))?;
    std::fs::rename(&tmp, dest_dir.join(name)).map_err(|e| format!("{}: {e}", tmp.display()))?;
    Ok(())
}
