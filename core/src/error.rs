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
    /// XML that does not parse or breaks Mitsuba's scene structure (a Mitsuba scene file).
    #[error("{location}: XML error: {message}")]
    XmlSyntax { location: Location, message: String },
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

/// The candidate closest to `name` when it is close enough to be a typo (Levenshtein distance
/// at most a third of the name's length, and at least 1 allowed): the "did you mean" of
/// unknown names, shared by the TOML and the XML readers.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .filter(|c| *c != name)
        .map(|c| (edit_distance(&name.to_lowercase(), &c.to_lowercase()), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// " (did you mean `x`?)" or nothing: the suffix an "unknown ..." message takes.
pub fn suggestion<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    did_you_mean(name, candidates).map_or_else(String::new, |c| format!(" (did you mean `{c}`?)"))
}

/// The edit distance with adjacent transpositions (optimal string alignment): insertions,
/// deletions, substitutions and swaps of neighbouring characters each count one, so that
/// `flaot` is one edit from `float`.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            d[i][j] = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d[i][j] = d[i][j].min(d[i - 2][j - 2] + 1);
            }
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_counts_single_character_edits() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("path", "path"), 0);
        assert_eq!(edit_distance("flaot", "float"), 1);
        assert_eq!(
            did_you_mean("phtonmapper", ["path", "photonmapper", "sppm"]),
            Some("photonmapper")
        );
        assert_eq!(did_you_mean("xyz", ["path", "sppm"]), None);
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
    }
}
