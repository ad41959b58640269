//! The `foton` program: `render`, `check`, `convert`, `plugins`, `bench`, `merge` (of the parts
//! of a render split with `render --part`, whose file format is in `part`), and the tools for
//! seeing and comparing, `photons`, `compare` and `sweep`: one module per command, each with
//! its arguments and its `run`. What they share (the scene and plugin arguments, loading a
//! scene and creating its integrator, rendering it, default outputs, warnings) is in `common`;
//! the tools' labelled images in `montage`, the terminal progress in `progress`. This file
//! parses the command line (clap) and hands it to its command.
//!
//! A thin layer over foton-core: parse arguments, load the scene, find the plugin, run it,
//! write the image. Errors are turned into messages here, once. Everything host-only lives
//! here and not in core (clap, indicatif, the Ctrl-C handler and its flag, the label font), so
//! that editing a tool never changes what plugins are checked against.

mod bench;
mod check;
mod common;
pub mod compare;
mod convert;
mod merge;
pub mod montage;
pub mod part;
pub mod photons;
mod plugins;
mod progress;
mod render;
pub mod sweep;
pub mod time_limit;

pub use common::{
    INTERRUPTED, Prepared, install_interrupt_handler, prepare, prepare_scene, render_part,
    render_prepared, render_with,
};
pub use progress::TermProgress;

use clap::{Parser, Subcommand};
use std::ffi::OsString;
use std::io::Write;

#[derive(Parser)]
#[command(
    name = "foton",
    version,
    about = "foton: a physically based renderer whose integrators are plugins",
    long_about = "foton renders a scene described in one TOML file, Mitsuba XML file (0.4 to 3.x) \
                  or pbrt-v4 file (see docs/scene-format.md, docs/pbrt.md) with the integrator \
                  plugin the file, or --integrator, names."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image (.exr linear float32, or .png: 8-bit sRGB after the scene's
    /// [film] exposure and tonemap).
    Render(render::RenderArgs),
    /// Parse and validate a scene; list what it uses and any unused field.
    Check(check::CheckArgs),
    /// Merge the parts of a render made with `foton render --part I/N` into its image.
    ///
    /// Checks first that the parts belong together (same scene content, integrator and
    /// parameters, seed, number of parts and foton build; no part twice; none missing or
    /// interrupted unless --partial), then adds their exact per-pixel sums one part at a time.
    /// The merged image equals the render done in one process with the same seed, bit for
    /// bit. Nothing is written if a check fails.
    Merge(merge::MergeArgs),
    /// Write a Mitsuba XML or pbrt-v4 scene as the equivalent TOML scene (the same image for
    /// the same seed); lists what --lenient left out.
    Convert(convert::ConvertArgs),
    /// List the plugins found on the plugin search path.
    Plugins(common::PluginArgs),
    /// Render a scene several times and report samples per second (a benchmark, not a test).
    Bench(bench::BenchArgs),
    /// Draw a photon map as seen from the scene camera, one dot per photon.
    ///
    /// The photons are those the integrator (the scene's, or --integrator) would store: the
    /// tool asks the plugin for its photon maps and draws the one --map names. A photon is
    /// drawn where it projects if the camera sees the side of the surface it lies on (one
    /// visibility ray per photon); a pixel shows the mean colour of the dots covering it.
    ///
    /// Exposure: a dot's colour is the photon's flux divided by the 99th percentile of the
    /// drawn photons' largest channel, so that 99% of the dots are unclipped and photons of
    /// equal flux on a white surface come out white; a PNG then applies the scene's [film]
    /// exposure and tonemap, as to a render. Prints the photons stored and drawn.
    Photons(photons::PhotonsArgs),
    /// Render a scene with several integrators and lay the renders side by side, labelled.
    ///
    /// Each render is labelled with the integrator's name, samples per pixel, render time and
    /// parameters, and written beside the output as <output stem>-<integrator>.exr; the numbers
    /// go to <output stem>.json (name, description, spp, seconds, rel_mse, bias, flip, image).
    ///
    /// --time S: each integrator gets about S seconds, found by short calibration renders that
    /// measure a fixed cost (a photon pass) and a per-step cost: path-like integrators get the
    /// spp that fills S; progressive ones (sppm) the number of iterations (their spp is
    /// reported as null); photon mappers (photon, vpm) their photon budgets scaled with S and
    /// the spp that fills the rest. The chosen values are printed and written to the JSON as
    /// --set overrides, so `foton render` with them gives the same image. --curve N also
    /// renders at S/2^(N-1), ..., S/2 and plots the error against the time (docs/tools.md).
    ///
    /// --reference IMAGE: a second row shows each render's relative difference from the
    /// reference, per pixel (x - r) / sqrt(r^2 + 0.01) of the channel means, in a diverging
    /// false colour: blue where the render is darker, light grey where equal, red where
    /// brighter, saturated at 100%. The labels and the JSON give rel_mse (the mean over pixels
    /// and channels of (x - r)^2 / (r^2 + 0.01)) and bias ((mean x - mean r) / mean r).
    ///
    /// --consistency N: each integrator renders N times (N >= 4) with independent seeds, and
    /// each pair (and each integrator against --reference) is tested per 8x8 block: Welch's
    /// t-test per channel, Simes' combination of the channels, Benjamini-Hochberg at a 1%
    /// false discovery rate over the blocks. A verdict per pair is printed (biased-but-
    /// consistent integrators say what shrinks their bias), the blocks that differ are drawn
    /// in <output stem>-consistency.png, the counts go to the JSON; the EXRs and the image are
    /// the means of the N renders. Exit status 3 when a pair differs.
    Compare(compare::CompareArgs),
    /// Render a scene over the product of lists of --set values, in a labelled grid.
    ///
    /// --set KEY.PATH=V1,V2,... sweeps a scene value; the first --set with several values runs
    /// along the columns, the second down the rows, any further ones down the rows as well
    /// (row-major, earlier sets varying faster). A --set with one value applies to every cell.
    /// Each cell is labelled with its values and its render time, and in a PNG shown through
    /// its scene's [film] exposure and tonemap (so film.exposure can be swept).
    Sweep(sweep::SweepArgs),
}

/// Runs the command line `args` (args[0] is the program name); returns the exit code.
pub fn run(args: Vec<OsString>, out: &mut dyn Write, err: &mut dyn Write) -> u8 {
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let text = e.render().to_string();
            if e.use_stderr() {
                let _ = write!(err, "{text}");
            } else {
                let _ = write!(out, "{text}");
            }
            return e.exit_code().clamp(0, 255) as u8;
        }
    };
    let result = match cli.command {
        Command::Render(a) => render::run(a, out, err),
        Command::Check(a) => check::run(a, out, err),
        Command::Merge(a) => merge::run(a, out, err),
        Command::Convert(a) => convert::run(a, out, err),
        Command::Plugins(a) => plugins::run(a, out),
        Command::Bench(a) => bench::run(a, out, err),
        Command::Photons(a) => photons::run(a, out, err),
        Command::Compare(a) => compare::run(a, out, err),
        Command::Sweep(a) => sweep::run(a, out, err),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            let _ = writeln!(err, "error: {e}");
            1
        }
    }
}
