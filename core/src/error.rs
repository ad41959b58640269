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

/// The candidate closest to `word` (Levenshtein distance), if it is close enough to be what
/// was meant: at most one edit per three characters, and never the whole word.
pub fn did_you_mean<'c>(
    word: &str,
    candidates: impl IntoIterator<Item = &'c str>,
) -> Option<&'c str> {
    let limit = (word.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .filter(|c| *c != word)
        .map(|c| (edit_distance(word, c), c))
        .filter(|&(d, c)| d <= limit && d < c.chars().count().max(word.chars().count()))
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

/// Levenshtein distance, with a transposition of neighbours counted as one edit (`rr_dpeth`).
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    // d[i][j]: distance between a[..i] and b[..j], three rows kept.
    let mut prev2 = vec![0usize; b.len() + 1];
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut row = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            row[j] = (prev[j] + 1).min(row[j - 1] + 1).min(prev[j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                row[j] = row[j].min(prev2[j - 2] + 1);
            }
        }
        prev2 = std::mem::replace(&mut prev, row);
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_names_are_suggested_and_far_ones_not() {
        let keys = ["rr_depth", "max_depth", "spp", "seed"];
        assert_eq!(did_you_mean("rr_dept", keys), Some("rr_depth"));
        assert_eq!(did_you_mean("rr_dpeth", keys), Some("rr_depth"));
        assert_eq!(did_you_mean("sppp", keys), Some("spp"));
        assert_eq!(did_you_mean("colour", keys), None);
        assert_eq!(
            did_you_mean("spp", keys),
            None,
            "an exact name is not a typo"
        );
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
    }
}
