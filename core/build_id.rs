//! The build identifier: a hash of exactly what defines the plugin ABI, shared by build.rs
//! (which computes it) and the tests (which check what changes it and what does not).
//!
//! Rust has no stable ABI and every plugin links its own copy of foton-core, so a plugin is
//! only safe to call when its copy was built from the same core as the host's: the same core
//! sources (every type that crosses the boundary, and the code both sides run over them), the
//! same versions of core's dependencies (glam, obvhs... whose types are inside core's), the
//! same rustc, target and code-generation settings that can change layouts. Nothing else: the
//! `foton` program's sources (cli/), the scene loader's (loader/: the TOML, XML, mesh and image
//! readers) and the dependencies only they link (clap, indicatif, roxmltree, image...) are not
//! inputs, so a plugin built before a change to the tools or a reader still loads after it.

use std::collections::hash_map::DefaultHasher;
use std::collections::{BTreeSet, HashMap};
use std::hash::{Hash, Hasher};
use std::path::Path;

/// What the identifier is computed from.
pub struct Inputs<'a> {
    /// core's folder: `src/`, `Cargo.toml`, `build.rs` and this file are hashed.
    pub core_dir: &'a Path,
    /// The workspace's Cargo.lock, if there is one: the resolved versions of core's
    /// dependencies (their whole closure) are hashed.
    pub lock: Option<&'a str>,
    /// `rustc --version`.
    pub rustc: &'a str,
    /// Settings that can change layouts: target, debug assertions (dependencies may add fields
    /// under them), panic strategy, target features.
    pub settings: &'a [String],
}

fn hash_dir(dir: &Path, hasher: &mut DefaultHasher) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("core's sources are readable")
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

/// The packages foton-core depends on, directly or not, as "name version source" lines from
/// a Cargo.lock (sorted). The lock file names the optional dependencies of dependencies too,
/// so this can hold more than is built (obvhs's rdst lists criterion): more, never less.
pub fn dependency_closure(lock: &str, root: &str) -> BTreeSet<String> {
    struct Package {
        version: String,
        source: String,
        dependencies: Vec<String>,
    }
    let mut packages: HashMap<String, Vec<Package>> = HashMap::new();
    for block in lock.split("[[package]]").skip(1) {
        let field = |key: &str| {
            block.lines().find_map(|l| {
                let rest = l.trim().strip_prefix(key)?.trim_start().strip_prefix('=')?;
                Some(rest.trim().trim_matches('"').to_string())
            })
        };
        let (Some(name), Some(version)) = (field("name"), field("version")) else {
            continue;
        };
        let dependencies = block
            .split_once("dependencies = [")
            .map(|(_, rest)| rest.split(']').next().unwrap_or(""))
            .unwrap_or("")
            .split(',')
            .map(|d| d.trim().trim_matches('"').to_string())
            .filter(|d| !d.is_empty())
            .collect();
        packages.entry(name).or_default().push(Package {
            version,
            source: field("source").unwrap_or_default(),
            dependencies,
        });
    }
    let mut seen = BTreeSet::new();
    let mut todo = vec![root.to_string()];
    while let Some(spec) = todo.pop() {
        // "name", or "name version" when several versions are locked.
        let mut words = spec.split_whitespace();
        let name = words.next().unwrap_or_default();
        let version = words.next();
        let Some(candidates) = packages.get(name) else {
            continue;
        };
        for p in candidates
            .iter()
            .filter(|p| version.is_none_or(|v| v == p.version))
        {
            if seen.insert(format!("{name} {} {}", p.version, p.source)) {
                todo.extend(p.dependencies.iter().cloned());
            }
        }
    }
    seen
}

/// The identifier (see the module comment).
pub fn build_id(inputs: &Inputs<'_>) -> u64 {
    let mut hasher = DefaultHasher::new();
    hash_dir(&inputs.core_dir.join("src"), &mut hasher);
    for file in ["Cargo.toml", "build.rs", "build_id.rs", "api_surface.rs"] {
        std::fs::read(inputs.core_dir.join(file))
            .unwrap_or_default()
            .hash(&mut hasher);
    }
    match inputs.lock {
        Some(lock) => dependency_closure(lock, "foton-core").hash(&mut hasher),
        None => "no Cargo.lock".hash(&mut hasher),
    }
    inputs.rustc.hash(&mut hasher);
    inputs.settings.hash(&mut hasher);
    hasher.finish()
}
