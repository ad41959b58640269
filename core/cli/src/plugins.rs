//! `foton plugins`: the integrator and kernel plugins found on the search path, the versions
//! they are checked against, and the files skipped (with why).

use crate::common::PluginArgs;
use foton_core::error::Result;
use foton_core::plugin::{Registry, search_path};
use std::fmt::Display;
use std::io::Write;

pub(crate) fn run(a: PluginArgs, out: &mut dyn Write) -> Result<u8> {
    let dirs = search_path(&a.plugin_dirs);
    let reg = Registry::discover(&dirs);
    let mut row = |name: &str, kind: &str, description: &str, file: &dyn Display| {
        let _ = writeln!(out, "{name:<12} {kind:<11} {description:<40} {file}");
    };
    row("name", "kind", "description", &"file");
    for p in &reg.integrators {
        row(&p.name, "integrator", &p.description, &p.file.display());
    }
    for k in &reg.kernels {
        row(&k.name, "kernel", "", &k.file.display());
    }
    let _ = writeln!(
        out,
        "\nfoton-core {}, plugin API {}, {}, build {}",
        foton_core::CORE_VERSION,
        foton_core::plugin::PLUGIN_API_VERSION,
        foton_core::RUSTC_VERSION,
        foton_core::BUILD_ID
    );
    let shown: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
    let _ = writeln!(out, "search path: {}", shown.join(":"));
    for p in &reg.problems {
        let _ = writeln!(out, "skipped {}: {}", p.file.display(), p.message);
    }
    Ok(0)
}
