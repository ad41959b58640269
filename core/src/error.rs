//! Errors as types; the `foton` command turns them into messages once, at the edge.

use std::path::PathBuf;

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Where in a scene description a value came from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    pub file: PathBuf,
    /// 1-based; 0 when the value did not come from the file (a default or `--set`).
    pub line: u32,
    pub column: u32,
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.file.display())
        } else {
            write!(f, "{}:{}:{}", self.file.display(), self.line, self.column)
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A problem in a scene file: names file, line, the TOML key path and what was expected.
    #[error("{location}: `{key}`: {message}")]
    Scene {
        location: Location,
        key: String,
        message: String,
    },
    /// TOML that does not parse.
    #[error("{location}: TOML syntax error: {message}")]
    Syntax { location: Location, message: String },
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("plugin {file}: {message}")]
    Plugin { file: PathBuf, message: String },
    #[error("{0}")]
    Usage(String),
    #[error("render failed: {0}")]
    Render(String),
    #[error("interrupted")]
    Interrupted,
    /// A panic caught at a plugin boundary ("panicked in render: ...").
    #[error("{0}")]
    Panic(String),
}

impl Error {
    pub fn io(path: impl Into<PathBuf>, err: impl std::fmt::Display) -> Self {
        Error::Io {
            path: path.into(),
            message: err.to_string(),
        }
    }
}
