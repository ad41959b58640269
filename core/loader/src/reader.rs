//! The seam between scene formats and the scene builder. A format's reader turns a file into
//! core's [`Document`], the tree of values a TOML scene parses to, each value with the file and
//! line it came from, and a [`Report`] of what it noticed besides; the builder
//! ([`crate::from_document`]) turns any document into a `Scene` without knowing the format,
//! so its errors name the line of whatever file the value came from. A file's format is
//! chosen by its extension ([`crate::formats`]).
//!
//! The formats: TOML ([`crate::document::read`], docs/scene-format.md), Mitsuba XML
//! ([`crate::mitsuba::read`]) and pbrt-v4 ([`crate::pbrt::read`], docs/pbrt.md), each read as
//! the TOML document it stands for. A new format is a
//! module with a [`ReadFn`] that reads a file into the document a TOML scene of the same
//! content would parse to, and one entry in [`crate::formats::FORMATS`]; nothing after the
//! document changes. This module names only what they share, so that the formats and the
//! list of them import it, and it none of them.

use foton_core::error::Result;
use foton_core::value::Document;
use std::path::{Path, PathBuf};

/// What a format's reader is given besides the file.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options<'a> {
    /// `NAME=VALUE` overrides of the file's own defaults (Mitsuba's `-D`); a format without
    /// defaults refuses them.
    pub defines: &'a [String],
    /// Leave out what foton cannot render, listed in [`Report::left_out`], instead of failing.
    pub lenient: bool,
}

/// What reading a scene file produced besides the document (empty for a TOML file).
#[derive(Debug, Default)]
pub struct Report {
    /// Elements and parameters left out (`lenient`), each with its file:line.
    pub left_out: Vec<String>,
    /// Things rendered differently from the format's own renderer, each with its file:line.
    pub notes: Vec<String>,
    /// The files it included (`<include>`), which make the scene as much as its own file.
    pub included: Vec<PathBuf>,
    /// Parameters foton understands but ignores (or renders otherwise), each with its
    /// file:line: warnings, errors with `--strict`.
    pub warnings: Vec<String>,
    /// A photon lookup radius the file gives relative to the scene's bounding sphere (Mitsuba):
    /// the integrator, the factor and its line; the loader sets `max_radius` once it knows the
    /// scene's bounds ([`crate::set_relative_radius`]).
    pub relative_radius: Option<(String, f64, u32)>,
    /// The file has no camera and takes its format's default (Mitsuba's, with this field of
    /// view in degrees across the image's width), which stands in front of the whole scene:
    /// the loader places it once it knows the scene's bounds ([`crate::load_with`]).
    pub default_camera: Option<f64>,
}

/// A format's reader: a scene file into the document and the report.
pub type ReadFn = fn(&Path, &Options<'_>) -> Result<(Document, Report)>;
