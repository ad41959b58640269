//! The scene formats foton reads, each by the extensions of its files: the one list a new
//! format is added to (its reader implements [`crate::reader::ReadFn`]).

use crate::reader::{Options, ReadFn, Report};
use foton_core::error::Result;
use foton_core::value::Document;
use std::path::Path;

/// A scene format: the extensions of its files and its reader.
pub struct Format {
    /// Lower case, without the dot; matched ignoring case.
    pub extensions: &'static [&'static str],
    pub read: ReadFn,
}

/// The scene formats foton reads. The first, TOML, also reads a file whose extension no
/// format claims.
pub static FORMATS: &[Format] = &[
    Format {
        extensions: &["toml"],
        read: crate::document::read,
    },
    Format {
        extensions: &["xml"],
        read: crate::mitsuba::read,
    },
    Format {
        extensions: &["pbrt"],
        read: crate::pbrt::read,
    },
];

/// The format of the scene file `path`, by its extension.
pub fn format_of(path: &Path) -> &'static Format {
    let claims = |f: &&Format| {
        path.extension()
            .is_some_and(|e| f.extensions.iter().any(|x| e.eq_ignore_ascii_case(x)))
    };
    FORMATS.iter().find(claims).unwrap_or(&FORMATS[0])
}

/// Reads the scene file `path` with its format's reader.
pub fn read(path: &Path, options: &Options<'_>) -> Result<(Document, Report)> {
    (format_of(path).read)(path, options)
}
