//! `foton merge`: the parts of a render made with `foton render --part I/N` added into its
//! image. The merge reads every header first (small) and refuses a set of parts that do not
//! belong together before it reads any pixels; then it adds the parts one at a time into one
//! film, so its memory is one film and one part whatever the number of parts. Its output is
//! written atomically, so a failed merge leaves nothing behind.

use crate::part::{PartInfo, read_part_film, read_part_info};
use clap::Args;
use foton_core::film::Film;
use foton_core::{Error, Result as FotonResult};
use foton_loader::FilmFile;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args)]
pub(crate) struct MergeArgs {
    /// The part files (`foton render --part I/N -o part_I.exr`), in any order.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The merged image (.exr linear float32, or .png through the scene's exposure and
    /// tonemap).
    #[arg(short, long)]
    output: PathBuf,
    /// Merge the parts that are there when some are missing or interrupted (the image then
    /// has fewer samples; it says which parts it lacks).
    #[arg(long)]
    partial: bool,
}

/// `foton merge`: checks that the parts belong together, then adds them one at a time.
pub(crate) fn run(
    a: MergeArgs,
    out: &mut dyn std::io::Write,
    err: &mut dyn std::io::Write,
) -> FotonResult<u8> {
    foton_core::film::check_output(&a.output)?;
    let start = Instant::now();
    let mut parts: BTreeMap<u32, (PathBuf, PartInfo)> = BTreeMap::new();
    let mut first: Option<(PathBuf, PartInfo)> = None;
    for path in &a.parts {
        let info = read_part_info(path)?;
        if let Some((first_path, f)) = &first {
            belongs_with(path, &info, first_path, f)?;
        } else {
            first = Some((path.clone(), info.clone()));
        }
        if let Some((other, _)) = parts.get(&info.part.index) {
            return Err(Error::Usage(format!(
                "part {} is given twice: {} and {}",
                info.part,
                other.display(),
                path.display()
            )));
        }
        parts.insert(info.part.index, (path.clone(), info));
    }
    let (_, f) = first.expect("clap requires one part");
    let count = f.part.count;
    let missing: Vec<String> = (0..count)
        .filter(|i| !parts.contains_key(i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    let interrupted: Vec<String> = parts
        .values()
        .filter(|(_, p)| p.done < p.planned)
        .map(|(path, p)| {
            format!(
                "{} (part {}: {} of {} {})",
                path.display(),
                p.part,
                p.done,
                p.planned,
                p.work
            )
        })
        .collect();
    if !a.partial {
        if !missing.is_empty() {
            return Err(Error::Usage(format!(
                "missing part(s) {} of the {count} (given {}); render them, or merge what is there with --partial",
                missing.join(", "),
                parts.len()
            )));
        }
        if !interrupted.is_empty() {
            return Err(Error::Usage(format!(
                "interrupted part(s): {}; render them again, or merge what is there with --partial",
                interrupted.join(", ")
            )));
        }
    }
    let mut film = Film::new(f.width, f.height);
    for (path, info) in parts.values() {
        let part = read_part_film(path, info)?;
        film.merge(&part);
    }
    film.color_matrix = f.color_matrix;
    film.write(&a.output, &f.display())?;
    if !missing.is_empty() {
        let _ = writeln!(
            err,
            "warning: --partial: merged without part(s) {}",
            missing.join(", ")
        );
    }
    if !interrupted.is_empty() {
        let _ = writeln!(
            err,
            "warning: --partial: merged interrupted part(s): {}",
            interrupted.join(", ")
        );
    }
    let _ = writeln!(
        out,
        "{}: {} of {count} parts, {}x{}, {} with {} -> {} ({:.2} s)",
        f.scene,
        parts.len(),
        f.width,
        f.height,
        parts.values().map(|(_, p)| p.done).sum::<u64>().to_string() + " " + &f.work,
        f.integrator,
        a.output.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(0)
}

/// Whether the part at `path` comes from the same render as the first part given.
fn belongs_with(path: &Path, p: &PartInfo, first_path: &Path, f: &PartInfo) -> FotonResult<()> {
    let differs = |what: &str, this: String, that: String| {
        Err(Error::Usage(format!(
            "{} is not a part of the same render as {}: {what} {this} (the other: {that})",
            path.display(),
            first_path.display()
        )))
    };
    if p.integrator != f.integrator {
        return differs("integrator", p.integrator.clone(), f.integrator.clone());
    }
    if p.seed != f.seed {
        return differs("seed", p.seed.to_string(), f.seed.to_string());
    }
    if p.part.count != f.part.count {
        return differs(
            "number of parts",
            p.part.count.to_string(),
            f.part.count.to_string(),
        );
    }
    if p.build != f.build {
        return differs("foton build", p.build.clone(), f.build.clone());
    }
    if (p.width, p.height) != (f.width, f.height) {
        return differs(
            "size",
            format!("{}x{}", p.width, p.height),
            format!("{}x{}", f.width, f.height),
        );
    }
    // Last: overrides of the seed or integrator change the hash too, and are named above.
    if p.scene_hash != f.scene_hash {
        return differs(
            "another scene or other overrides: scene hash",
            format!("{} of {}", p.scene_hash, p.scene),
            format!("{} of {}", f.scene_hash, f.scene),
        );
    }
    Ok(())
}
