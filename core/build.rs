//! Computes the build identifier that plugins are checked against.
//!
//! Rust has no stable ABI: a plugin is only safe to call when it was compiled from the very
//! same core sources, by the same rustc, for the same target and with the same code-generation
//! settings as the host. The identifier hashes all of those, so a stale plugin is refused at
//! load time instead of crashing. (Dependency versions are checked separately, by the layout
//! fingerprint in plugin.rs.)

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::Path;
use std::process::Command;

fn hash_dir(dir: &Path, hasher: &mut DefaultHasher) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("core/src is readable")
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            hash_dir(&path, hasher);
        } else {
            path.file_name().hash(hasher);
            std::fs::read(&path)
                .expect("source file is readable")
                .hash(hasher);
        }
    }
}

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

    let mut hasher = DefaultHasher::new();
    hash_dir(&manifest.join("src"), &mut hasher);
    std::fs::read(manifest.join("Cargo.toml"))
        .unwrap()
        .hash(&mut hasher);
    rustc_version.hash(&mut hasher);
    // What can change the layout or calling convention of types that cross the boundary:
    // not the optimisation level or debug info, but debug assertions (dependencies may add
    // fields under them), panic strategy and target features.
    for var in [
        "TARGET",
        "CARGO_CFG_DEBUG_ASSERTIONS",
        "CARGO_CFG_PANIC",
        "CARGO_CFG_TARGET_FEATURE",
    ] {
        std::env::var(var).unwrap_or_default().hash(&mut hasher);
    }
    let assertions = if std::env::var_os("CARGO_CFG_DEBUG_ASSERTIONS").is_some() {
        "debug-assertions"
    } else {
        "release"
    };
    println!(
        "cargo:rustc-env=FOTON_BUILD_ID={:016x}-{assertions}",
        hasher.finish()
    );
    println!("cargo:rustc-env=FOTON_RUSTC_VERSION={rustc_version}");
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.toml");
}
