//! `foton convert`: a Mitsuba XML or pbrt-v4 scene written as the equivalent TOML scene (the
//! same image for the same seed), checked to load from where it is written before it is
//! written.

use crate::common::{warn, write_atomic};
use clap::Args;
use foton_core::error::{Error, Result};
use foton_loader::TomlDocument;
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct ConvertArgs {
    /// The Mitsuba scene (.xml, version 3 or 0.4 to 0.6) or pbrt-v4 scene (.pbrt).
    scene: PathBuf,
    /// The TOML scene to write; default: <scene stem>.toml beside the scene.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// NAME=VALUE: set a <default name="NAME"> (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    defines: Vec<String>,
    /// Leave out what foton cannot render yet (listed) instead of refusing the scene.
    #[arg(long)]
    lenient: bool,
    /// A parameter foton understands but ignores is an error, not a warning.
    #[arg(long)]
    strict: bool,
}

pub(crate) fn run(a: ConvertArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| a.scene.with_extension("toml"));
    if output.extension().and_then(|e| e.to_str()) != Some("toml") {
        return Err(Error::Usage(format!(
            "convert writes a TOML scene: name the output .toml, not {}",
            output.display()
        )));
    }
    let is_pbrt = a
        .scene
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pbrt"));
    let (mut doc, report) = if is_pbrt {
        let options = foton_loader::reader::Options {
            defines: &a.defines,
            lenient: a.lenient,
        };
        foton_loader::pbrt::read(&a.scene, &options)?
    } else {
        foton_loader::mitsuba::read_xml(&a.scene, &a.defines, a.lenient)?
    };
    if a.strict
        && let Some(w) = report.warnings.first()
    {
        return Err(Error::Usage(format!(
            "{w} (--strict: a parameter foton ignores is an error)"
        )));
    }
    // Files are named relative to the scene; written into another folder, relative to it.
    let folder = |p: &Path| match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => std::fs::canonicalize(d).ok(),
        _ => std::fs::canonicalize(".").ok(),
    };
    let base = folder(&a.scene).ok_or_else(|| Error::io(&a.scene, "cannot resolve its folder"))?;
    let target = folder(&output).ok_or_else(|| {
        Error::io(
            &output,
            "the folder to write the TOML scene into does not exist",
        )
    })?;
    if target != base {
        doc.rebase_files(&base, &target);
    }
    // The TOML must load from where it is written: check it before writing.
    let mut written = doc.clone();
    written.file = output.clone();
    let mut scene = foton_loader::from_document(written)?;
    if let Some((integrator, factor, line)) = &report.relative_radius {
        foton_loader::set_relative_radius(&mut scene, integrator, *factor, *line);
        doc.root = scene.document().root.clone();
    }
    let header = format!(
        "# Converted by `foton convert` from {}\n",
        a.scene.display()
    );
    write_atomic(&output, (header + &doc.to_toml()).as_bytes())?;
    for l in &report.left_out {
        let _ = writeln!(err, "left out: {l}");
    }
    warn(err, &report.warnings);
    for n in &report.notes {
        let _ = writeln!(err, "note: {n}");
    }
    let _ = writeln!(out, "{} -> {}", a.scene.display(), output.display());
    Ok(0)
}
