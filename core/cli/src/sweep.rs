//! `foton sweep`: one scene rendered over the product of lists of `--set` values, in a
//! labelled grid. The first `--set` with several values runs along the columns, the second
//! down the rows, further ones down the rows too (row-major, the earlier varying faster); a
//! `--set` with one value applies to every cell.
//!
//! On a cluster the cells are an array job: `--cells` prints their number, `--cell I
//! --cells-dir DIR` renders one into DIR/cell-I.exr (a part file of a whole render, with the
//! sweep's signature and the cell's time), and `--assemble --cells-dir DIR` lays out the grid
//! from those files, the same grid as one process makes but for the times.

use crate::TermProgress;
use crate::common::{
    INTERRUPTED, Overrides, PluginArgs, Prepared, RunArgs, SceneFile, WarnOnce, render_prepared,
    warn,
};
use crate::montage::{Tile, grid, render_image};
use crate::part::{PartInfo, fnv_hex, read_part_film, read_part_header, write_part};
use clap::Args;
use foton_core::error::{Error, Result};
use foton_core::film::check_output;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

/// More cells than this is almost certainly a typo in a value list.
pub const MAX_CELLS: usize = 256;

#[derive(Args)]
pub(crate) struct SweepArgs {
    #[command(flatten)]
    file: SceneFile,
    /// KEY.PATH=VALUE[,VALUE...]: the values to sweep a scene value over (repeatable). Commas
    /// inside brackets, braces or quotes do not split: camera.position=[0,1,3],[0,1,4] is two
    /// values.
    #[arg(long = "set", value_name = "KEY.PATH=VALUES")]
    sets: Vec<String>,
    #[command(flatten)]
    overrides: Overrides,
    /// Output image (.png or .exr); default: <scene stem>-sweep.png beside the scene.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Treat unknown (unused) scene fields and integrator parameters as errors.
    #[arg(long)]
    strict: bool,
    #[command(flatten)]
    run: RunArgs,
    /// Print the number of cells and do nothing else (to size an array job).
    #[arg(long, conflicts_with_all = ["cell", "assemble"])]
    cells: bool,
    /// Render only cell I (from 0, in the grid's row-major order) into DIR/cell-I.exr
    /// (--cells-dir): one task of an array job.
    #[arg(
        long,
        value_name = "I",
        requires = "cells_dir",
        conflicts_with = "assemble"
    )]
    cell: Option<usize>,
    /// Lay out the grid from the cells that --cell rendered into --cells-dir, rendering
    /// nothing (the same --set arguments as the cells'; a cell from another sweep is refused).
    #[arg(long, requires = "cells_dir")]
    assemble: bool,
    /// The folder of the cell files of --cell and --assemble (shared by the tasks).
    #[arg(long, value_name = "DIR")]
    cells_dir: Option<PathBuf>,
    #[command(flatten)]
    plugins: PluginArgs,
}

/// A `--set` of `foton sweep`: a key path and the values it takes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SweepSet {
    pub key: String,
    pub values: Vec<String>,
}

/// Splits a value list on the commas that are outside brackets, braces and quotes, so that
/// an array or inline table stays one value. Values are trimmed.
pub fn split_values(list: &str) -> Vec<String> {
    let mut values = Vec::new();
    let mut depth = 0i32;
    let mut quote: Option<char> = None;
    let mut escaped = false;
    let mut current = String::new();
    for c in list.chars() {
        if let Some(q) = quote {
            if escaped {
                escaped = false;
            } else if c == '\\' && q == '"' {
                escaped = true;
            } else if c == q {
                quote = None;
            }
            current.push(c);
            continue;
        }
        match c {
            '"' | '\'' => quote = Some(c),
            '[' | '{' => depth += 1,
            ']' | '}' => depth -= 1,
            ',' if depth <= 0 => {
                values.push(current.trim().to_string());
                current.clear();
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    values.push(current.trim().to_string());
    values
}

/// Parses `KEY.PATH=VALUE[,VALUE...]`.
pub fn parse_set(arg: &str) -> Result<SweepSet> {
    let (key, list) = arg.split_once('=').ok_or_else(|| {
        Error::Usage(format!(
            "--set {arg}: expected KEY.PATH=VALUE[,VALUE...], e.g. integrators.photon.k=10,50"
        ))
    })?;
    let key = key.trim();
    if key.is_empty() {
        return Err(Error::Usage(format!("--set {arg}: empty key")));
    }
    if list.trim().is_empty() {
        return Err(Error::Usage(format!(
            "--set {arg}: empty value list for `{key}`"
        )));
    }
    let values = split_values(list);
    if values.iter().any(String::is_empty) {
        return Err(Error::Usage(format!(
            "--set {arg}: empty value in the list for `{key}`"
        )));
    }
    Ok(SweepSet {
        key: key.to_string(),
        values,
    })
}

/// One cell of the grid: the index of the value each set takes.
fn cell_choices(sets: &[SweepSet], cell: usize) -> Vec<usize> {
    let mut rest = cell;
    sets.iter()
        .map(|s| {
            let i = rest % s.values.len();
            rest /= s.values.len();
            i
        })
        .collect()
}

/// The names the labels give the swept keys: the last part of the key path, or the whole
/// path when two swept keys end alike.
fn short_names(sets: &[&SweepSet]) -> Vec<String> {
    let last = |k: &str| k.rsplit('.').next().unwrap_or(k).to_string();
    sets.iter()
        .map(|s| {
            let short = last(&s.key);
            if sets.iter().filter(|o| last(&o.key) == short).count() > 1 {
                s.key.clone()
            } else {
                short
            }
        })
        .collect()
}

pub(crate) fn run(a: SweepArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<u8> {
    let sets = a
        .sets
        .iter()
        .map(|s| parse_set(s))
        .collect::<Result<Vec<_>>>()?;
    let cells: usize = sets.iter().map(|s| s.values.len()).product();
    if cells > MAX_CELLS {
        return Err(Error::Usage(format!(
            "the sweep has {cells} cells; at most {MAX_CELLS}"
        )));
    }
    if a.cells {
        let _ = writeln!(out, "{cells}");
        return Ok(0);
    }
    if let Some(cell) = a.cell
        && cell >= cells
    {
        return Err(Error::Usage(format!(
            "--cell {cell}: the sweep has {cells} cells, numbered from 0"
        )));
    }
    let swept: Vec<&SweepSet> = sets.iter().filter(|s| s.values.len() > 1).collect();
    let names = short_names(&swept);
    let columns = swept.first().map_or(1, |s| s.values.len());

    let overrides_of = |cell: usize| {
        let choice = cell_choices(&sets, cell);
        let mut overrides: Vec<String> = sets
            .iter()
            .zip(&choice)
            .map(|(s, &i)| format!("{}={}", s.key, s.values[i]))
            .collect();
        a.overrides.push_onto(&mut overrides);
        let label: Vec<String> = sets
            .iter()
            .zip(&choice)
            .filter(|(s, _)| s.values.len() > 1)
            .zip(&names)
            .map(|((s, &i), name)| format!("{name}={}", s.values[i]))
            .collect();
        (overrides, label)
    };
    let signature = sweep_signature(&a)?;
    if let Some(cell) = a.cell {
        let (overrides, label) = overrides_of(cell);
        let task = CellTask {
            cell,
            overrides,
            label,
            signature: &signature,
            dir: a.cells_dir.as_deref().expect("clap requires --cells-dir"),
        };
        return render_cell(&a, &task, out, err);
    }
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| a.file.beside("sweep.png"));
    check_output(&output)?;

    if a.assemble {
        let dir = a.cells_dir.as_deref().expect("clap requires --cells-dir");
        let mut tiles = Vec::new();
        let mut missing = Vec::new();
        for cell in 0..cells {
            let path = cell_path(dir, cell);
            if !path.exists() {
                missing.push(cell.to_string());
                continue;
            }
            let (info, attributes) = read_part_header(&path)?;
            let get = |key: &str| attributes.get(key).cloned().unwrap_or_default();
            if get("foton.sweep") != signature || get("foton.cell") != cell.to_string() {
                return Err(Error::Usage(format!(
                    "{}: a cell of another sweep (other scene, --set values or flags) or of another cell",
                    path.display()
                )));
            }
            let film = read_part_film(&path, &info)?;
            let (_, mut label) = overrides_of(cell);
            let _ = writeln!(
                out,
                "[{}] {}: {}",
                label.join(", "),
                info.integrator,
                get("foton.cellWork")
            );
            label.push(format!("{} s", get("foton.seconds")));
            tiles.push(Tile {
                image: render_image(&film, &info.display(), &output),
                label,
            });
        }
        if !missing.is_empty() {
            return Err(Error::Usage(format!(
                "missing cell(s) {} of {cells} in {}: render them with --cell I",
                missing.join(", "),
                dir.display()
            )));
        }
        grid(&tiles, columns).write(&output)?;
        let _ = writeln!(
            out,
            "{cells} cells ({columns} x {}) -> {}",
            cells / columns,
            output.display()
        );
        return Ok(0);
    }

    // Every cell's scene and integrator are created first, so that a bad value fails before
    // any render; they are loaded again one at a time to render (a sweep over a large scene
    // would not fit in memory many times over).
    let mut warned = WarnOnce::default();
    for cell in 0..cells {
        let p = prepare_cell(&a, &overrides_of(cell).0)?;
        warned.warn(err, &p.warnings);
    }

    let threads = a.run.threads();
    INTERRUPTED.store(false, Ordering::SeqCst);
    let mut tiles = Vec::new();
    for cell in 0..cells {
        let (overrides, mut label) = overrides_of(cell);
        let p = prepare_cell(&a, &overrides)?;
        let progress = TermProgress::new(a.run.quiet);
        let (film, elapsed) = render_prepared(&p, threads, &progress)?;
        warn(err, progress.take_warnings());
        if INTERRUPTED.load(Ordering::SeqCst) {
            let _ = writeln!(err, "interrupted: nothing written");
            return Ok(130);
        }
        let secs = elapsed.as_secs_f64();
        let work = cell_work(&film, &p);
        let _ = writeln!(
            out,
            "[{}] {}: {work} in {secs:.2} s",
            label.join(", "),
            p.integrator.describe(),
        );
        label.push(format!("{:.2} s", secs));
        // Each cell through its own scene's display transform: a sweep may vary the exposure.
        tiles.push(Tile {
            image: render_image(&film, &p.scene.film().display(), &output),
            label,
        });
    }
    let img = grid(&tiles, columns);
    img.write(&output)?;
    let _ = writeln!(
        out,
        "{} cells ({} x {}) -> {}",
        cells,
        columns,
        cells / columns,
        output.display()
    );
    Ok(0)
}

fn prepare_cell(a: &SweepArgs, overrides: &[String]) -> Result<Prepared> {
    a.file.prepare(overrides, &a.plugins, a.strict)
}

fn cell_work(film: &foton_core::film::Film, p: &Prepared) -> String {
    if film.iterations > 0 {
        format!("{} iterations", film.iterations)
    } else {
        format!("{} spp", p.scene.render().spp)
    }
}

fn cell_path(dir: &Path, cell: usize) -> PathBuf {
    dir.join(format!("cell-{cell}.exr"))
}

/// What makes two sweeps the same: the scene file's bytes and every argument that changes the
/// cells (the lists of values, the integrator, spp and seed).
fn sweep_signature(a: &SweepArgs) -> Result<String> {
    let path = &a.file.scene;
    let scene = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let mut fields: Vec<Vec<u8>> = vec![scene];
    fields.extend(a.sets.iter().map(|s| s.as_bytes().to_vec()));
    fields.extend(
        a.file
            .defines
            .iter()
            .map(|d| format!("-D {d}").into_bytes()),
    );
    let o = &a.overrides;
    fields.push(format!("{:?} {:?} {:?}", o.integrator, o.spp, o.seed).into_bytes());
    Ok(fnv_hex(&fields))
}

/// One task of an array job (`--cell I`): the cell, its scene values and label, the sweep's
/// signature and the folder of the cell files.
struct CellTask<'a> {
    cell: usize,
    overrides: Vec<String>,
    label: Vec<String>,
    signature: &'a str,
    dir: &'a Path,
}

/// `--cell I`: renders one cell into its file in the cells' folder.
fn render_cell(
    a: &SweepArgs,
    task: &CellTask,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<u8> {
    let CellTask {
        cell,
        overrides,
        label,
        signature,
        dir,
    } = task;
    let path = cell_path(dir, *cell);
    check_output(&path)?;
    let p = prepare_cell(a, overrides)?;
    warn(err, &p.warnings);
    INTERRUPTED.store(false, Ordering::SeqCst);
    let progress = TermProgress::new(a.run.quiet);
    let (film, elapsed) = render_prepared(&p, a.run.threads(), &progress)?;
    warn(err, progress.take_warnings());
    if INTERRUPTED.load(Ordering::SeqCst) {
        let _ = writeln!(err, "interrupted: nothing written");
        return Ok(130);
    }
    let work = cell_work(&film, &p);
    let info = PartInfo::of(&p.scene, overrides, &p.integrator.describe(), &film)?;
    let secs = format!("{:.2}", elapsed.as_secs_f64());
    write_part(
        &path,
        &film,
        &info,
        &[
            ("foton.sweep", signature.to_string()),
            ("foton.cell", cell.to_string()),
            ("foton.cellWork", work.clone()),
            ("foton.seconds", secs.clone()),
        ],
    )?;
    let _ = writeln!(
        out,
        "[{}] {}: {work} in {secs} s -> {}",
        label.join(", "),
        p.integrator.describe(),
        path.display()
    );
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_split_on_commas_outside_brackets_and_quotes() {
        assert_eq!(split_values("[1,2],x"), ["[1,2]", "x"]);
        assert_eq!(split_values("1, 10 ,100"), ["1", "10", "100"]);
        assert_eq!(split_values("[[0,1],[2,3]]"), ["[[0,1],[2,3]]"]);
        assert_eq!(split_values("{a=1,b=2},3"), ["{a=1,b=2}", "3"]);
        assert_eq!(
            split_values(r#""a,b",'c,d',"e\",f""#),
            [r#""a,b""#, "'c,d'", r#""e\",f""#]
        );
    }

    #[test]
    fn sets_parse_and_bad_ones_are_named() {
        assert_eq!(
            parse_set("a=[1,2],x").unwrap(),
            SweepSet {
                key: "a".into(),
                values: vec!["[1,2]".into(), "x".into()]
            }
        );
        let message = |s: &str| parse_set(s).unwrap_err().to_string();
        assert!(message("render.spp").contains("expected KEY.PATH=VALUE"));
        assert!(message("render.spp=").contains("empty value list"));
        assert!(message("render.spp=1,,2").contains("empty value"));
        assert!(message("=1").contains("empty key"));
    }

    #[test]
    fn first_set_varies_fastest() {
        let set = |k: &str, n: usize| SweepSet {
            key: k.into(),
            values: (0..n).map(|i| i.to_string()).collect(),
        };
        let sets = [set("a", 2), set("b", 1), set("c", 3)];
        assert_eq!(cell_choices(&sets, 0), [0, 0, 0]);
        assert_eq!(cell_choices(&sets, 1), [1, 0, 0]);
        assert_eq!(cell_choices(&sets, 2), [0, 0, 1]);
        assert_eq!(cell_choices(&sets, 5), [1, 0, 2]);
        let (x, y) = (
            set("integrators.photon.k", 2),
            set("integrators.other.k", 2),
        );
        assert_eq!(short_names(&[&x, &sets[0]]), ["k", "a"]);
        assert_eq!(
            short_names(&[&x, &y]),
            ["integrators.photon.k", "integrators.other.k"]
        );
    }
}
