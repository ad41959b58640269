//! Computes the build identifier that plugins are checked against (see build_id.rs for what
//! it covers and why), and the rustc version.

#[path = "api_surface.rs"]
mod api_surface;
#[path = "build_id.rs"]
mod build_id;

use std::path::Path;
use std::process::Command;

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").unwrap();
    let manifest = Path::new(&manifest);
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let rustc_version = Command::new(&rustc)
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown rustc".into());
    // A plugin built a second time for a newer CPU (integrators/path/build.rs sets these) is
    // identified as the baseline build it copies, from the baseline's target features, and
    // tagged with its level: the host accepts the tag only on a processor that has it.
    let variant = std::env::var("FOTON_PLUGIN_VARIANT").ok();
    let settings: Vec<String> = [
        "TARGET",
        "CARGO_CFG_DEBUG_ASSERTIONS",
        "CARGO_CFG_PANIC",
        "CARGO_CFG_TARGET_FEATURE",
    ]
    .iter()
    // Set but empty (debug assertions on) is not the same as unset: compare the OsStrings.
    .map(|&var| match (var, &variant) {
        ("CARGO_CFG_TARGET_FEATURE", Some(_)) => format!(
            "{var}={:?}",
            std::env::var_os("FOTON_VARIANT_BASE_FEATURES")
        ),
        _ => format!("{var}={:?}", std::env::var_os(var)),
    })
    .collect();
    // The workspace's lock file (core is a member of the workspace at its parent).
    let lock_path = manifest.join("../Cargo.lock");
    let lock = std::fs::read_to_string(&lock_path).ok();
    let id = build_id::build_id(&build_id::Inputs {
        core_dir: manifest,
        lock: lock.as_deref(),
        rustc: &rustc_version,
        settings: &settings,
    });
    let assertions = if std::env::var_os("CARGO_CFG_DEBUG_ASSERTIONS").is_some() {
        "debug-assertions"
    } else {
        "release"
    };
    let tag = variant.map_or(String::new(), |v| format!("+{v}"));
    println!("cargo:rustc-env=FOTON_BUILD_ID={id:016x}-{assertions}{tag}");
    println!("cargo:rustc-env=FOTON_RUSTC_VERSION={rustc_version}");
    let surface = api_surface::surface(&manifest.join("src")).unwrap_or_else(|e| panic!("{e}"));
    println!(
        "cargo:rustc-env=FOTON_PLUGIN_API_VERSION={}",
        api_surface::version(&surface)
    );
    // For the tests, which recompute the identifier.
    println!(
        "cargo:rustc-env=FOTON_BUILD_SETTINGS={}",
        settings.join(";")
    );
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.toml");
    println!("cargo:rerun-if-changed=build_id.rs");
    println!("cargo:rerun-if-changed=api_surface.rs");
    println!("cargo:rerun-if-env-changed=FOTON_PLUGIN_VARIANT");
    println!("cargo:rerun-if-env-changed=FOTON_VARIANT_BASE_FEATURES");
    println!("cargo:rerun-if-changed={}", lock_path.display());
}
