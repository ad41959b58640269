//! TOML text into a [`Document`] (foton-core's tree of values with their positions), the
//! `--set KEY.PATH=VALUE` overrides, and a document back to TOML text: core keeps the tree,
//! which plugins read, and no TOML parser. The methods are a trait on core's type, so that
//! `Document::parse`, `Document::load`, `doc.set(...)` and `doc.to_toml()` read as before
//! wherever this trait is in scope. [`read`] is the TOML format's reader ([`crate::reader`]).

use crate::reader::{Options, Report};
use foton_core::error::{Error, Location, Result};
use foton_core::value::{Document, Node, Table, Value};
use std::path::Path;
use toml::de::{DeTable, DeValue};

/// The TOML format's reader ([`crate::reader`]): the file parsed. A TOML scene has no defaults
/// for `-D` to override (`--set` changes any value) and nothing it leaves out.
pub fn read(path: &Path, options: &Options<'_>) -> Result<(Document, Report)> {
    if let Some(d) = options.defines.first() {
        return Err(Error::Usage(format!(
            "-D {d}: defaults are for Mitsuba XML scenes; use --set KEY.PATH=VALUE for a TOML scene"
        )));
    }
    Ok((Document::load(path)?, Report::default()))
}

/// Reading and writing a [`Document`] as TOML text.
pub trait TomlDocument: Sized {
    /// The document as TOML text (what `foton convert` writes): tables in key order, arrays of
    /// tables as `[[...]]`.
    fn to_toml(&self) -> String;
    /// Parses TOML text; `file` is only used in messages and to resolve relative paths.
    fn parse(text: &str, file: &Path) -> Result<Self>;
    /// Reads and parses a TOML file.
    fn load(file: &Path) -> Result<Self>;
    /// Applies `--set a.b.c=value` (like Mitsuba's -D): the value is parsed as TOML, and taken
    /// as a string if it does not parse (so `--set film.output=x.png` works unquoted).
    fn set(&mut self, assignment: &str) -> Result<()>;
}

impl TomlDocument for Document {
    fn to_toml(&self) -> String {
        fn convert(v: &Value) -> toml::Value {
            match v {
                Value::Bool(b) => toml::Value::Boolean(*b),
                Value::Int(i) => toml::Value::Integer(*i),
                Value::Float(f) => toml::Value::Float(*f),
                Value::Str(s) | Value::Datetime(s) => toml::Value::String(s.clone()),
                Value::Array(items) => {
                    toml::Value::Array(items.iter().map(|n| convert(&n.value)).collect())
                }
                Value::Table(t) => toml::Value::Table(
                    t.0.iter()
                        .map(|(k, n)| (k.clone(), convert(&n.value)))
                        .collect(),
                ),
            }
        }
        let table: toml::Table = self
            .root
            .0
            .iter()
            .map(|(k, n)| (k.clone(), convert(&n.value)))
            .collect();
        toml::to_string(&table).unwrap_or_default()
    }

    fn parse(text: &str, file: &Path) -> Result<Document> {
        let parsed = DeTable::parse(text).map_err(|e| {
            let (line, column) = e.span().map_or((0, 0), |s| line_col(text, s.start));
            let mut message = e.message().trim().to_string();
            if let Some(span) = e.span().filter(|_| message == DUPLICATE_KEY) {
                message = duplicate_key_message(text, span);
            }
            Error::Syntax {
                location: Location {
                    file: file.to_path_buf(),
                    line,
                    column,
                },
                message,
            }
        })?;
        Ok(Document {
            file: file.to_path_buf(),
            root: convert_table(text, parsed.get_ref(), file)?,
        })
    }

    fn load(file: &Path) -> Result<Document> {
        if file.is_dir() {
            return Err(Error::io(file, "is a directory, not a scene file"));
        }
        let text = std::fs::read_to_string(file).map_err(|e| Error::io(file, e))?;
        <Document as TomlDocument>::parse(&text, file)
    }

    fn set(&mut self, assignment: &str) -> Result<()> {
        let (path, raw) = assignment.split_once('=').ok_or_else(|| {
            Error::Usage(format!(
                "--set {assignment}: expected KEY.PATH=VALUE, e.g. render.spp=16"
            ))
        })?;
        let path = path.trim();
        let keys: Vec<&str> = path.split('.').collect();
        if keys.iter().any(|k| k.is_empty()) {
            return Err(Error::Usage(format!(
                "--set {assignment}: empty key in `{path}`"
            )));
        }
        if keys.iter().any(|k| k.contains('[')) {
            return Err(Error::Usage(format!(
                "--set {assignment}: elements of arrays ([[shapes]], [[lights]]) cannot be set from the command line; edit the scene file"
            )));
        }
        let text = format!("v = {}", raw.trim());
        let mut value = match DeTable::parse(&text) {
            Ok(t) => {
                let node = convert_table(&text, t.get_ref(), &self.file).map_err(|e| {
                    let why = match e {
                        Error::Syntax { message, .. } => message,
                        other => other.to_string(),
                    };
                    Error::Usage(format!("--set {assignment}: {why}"))
                })?;
                node.get("v").map(|n| n.value.clone()).unwrap()
            }
            Err(_) => Value::Str(raw.trim().to_string()),
        };
        // Positions inside the `v = ...` text mean nothing to the user: mark the whole value
        // as coming from the command line.
        clear_positions(&mut value);
        let mut table = &mut self.root;
        for key in &keys[..keys.len() - 1] {
            if table.get(key).is_none() {
                table.insert(
                    key,
                    Node {
                        value: Value::Table(Table::default()),
                        line: 0,
                        column: 0,
                    },
                );
            }
            table = match &mut table.get_mut(key).unwrap().value {
                Value::Table(t) => t,
                other => {
                    return Err(Error::Usage(format!(
                        "--set {assignment}: `{key}` is {}, not a table",
                        other.type_name()
                    )));
                }
            };
        }
        table.insert(
            keys[keys.len() - 1],
            Node {
                value,
                line: 0,
                column: 0,
            },
        );
        Ok(())
    }
}

fn clear_positions(value: &mut Value) {
    let nodes: Vec<&mut Node> = match value {
        Value::Array(items) => items.iter_mut().collect(),
        Value::Table(t) => t.0.iter_mut().map(|(_, n)| n).collect(),
        _ => return,
    };
    for n in nodes {
        n.line = 0;
        n.column = 0;
        clear_positions(&mut n.value);
    }
}

fn line_col(src: &str, offset: usize) -> (u32, u32) {
    let before = &src[..offset.min(src.len())];
    let line = before.matches('\n').count() as u32 + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) as u32 + 1;
    (line, col)
}

fn convert(src: &str, value: &DeValue<'_>, start: usize, file: &Path) -> Result<Node> {
    let (line, column) = line_col(src, start);
    let value = match value {
        DeValue::String(s) => Value::Str(s.to_string()),
        DeValue::Integer(i) => {
            let digits = i.as_str().replace('_', "");
            let digits = digits
                .trim_start_matches("0x")
                .trim_start_matches("0o")
                .trim_start_matches("0b");
            let parsed = i64::from_str_radix(digits, i.radix()).map_err(|e| Error::Syntax {
                location: Location {
                    file: file.to_path_buf(),
                    line,
                    column,
                },
                message: format!("integer {}: {e}", i.as_str()),
            })?;
            Value::Int(parsed)
        }
        DeValue::Float(f) => {
            let text = f.as_str().replace('_', "");
            let parsed = match text.as_str() {
                "inf" | "+inf" => f64::INFINITY,
                "-inf" => f64::NEG_INFINITY,
                "nan" | "+nan" | "-nan" => f64::NAN,
                t => t.parse::<f64>().map_err(|e| Error::Syntax {
                    location: Location {
                        file: file.to_path_buf(),
                        line,
                        column,
                    },
                    message: format!("float {t}: {e}"),
                })?,
            };
            Value::Float(parsed)
        }
        DeValue::Boolean(b) => Value::Bool(*b),
        DeValue::Datetime(d) => Value::Datetime(d.to_string()),
        DeValue::Array(items) => Value::Array(
            items
                .iter()
                .map(|item| convert(src, item.get_ref(), item.span().start, file))
                .collect::<Result<_>>()?,
        ),
        DeValue::Table(t) => Value::Table(convert_table(src, t, file)?),
    };
    Ok(Node {
        value,
        line,
        column,
    })
}

fn convert_table(src: &str, table: &DeTable<'_>, file: &Path) -> Result<Table> {
    let mut out = Table::default();
    for (key, value) in table.iter() {
        // A table's position is that of its key (its header), which is where a user looks.
        let start = key.span().start;
        let mut node = convert(src, value.get_ref(), value.span().start, file)?;
        if matches!(node.value, Value::Table(_)) {
            let (line, column) = line_col(src, start);
            node.line = line;
            node.column = column;
        }
        out.0.push((key.get_ref().to_string(), node));
    }
    Ok(out)
}

/// toml's message for a key written twice; it points at the second one and names neither the
/// key's table nor where the first one is.
const DUPLICATE_KEY: &str = "duplicate key";

/// Stands for a duplicate key while the text is parsed again; `{}` is a counter. A bare key
/// no scene uses.
const PLACEHOLDER: &str = "foton-duplicate-key-placeholder-";

/// "`materials.white.reflectance`: duplicate key (first written on line 12)" for the duplicate
/// key whose second occurrence is at `span` of `text`.
///
/// The key's path is found by parsing the text again with that occurrence renamed to a
/// placeholder, then looking the placeholder up in the tree: so dotted keys, table headers,
/// inline tables and arrays of tables all get their full path, without a second TOML parser.
/// Further duplicates (the same key a third time, or other keys) make the renamed text fail
/// again: each is renamed in turn to a placeholder of its own. Should that fail anyway, the
/// message names the key as written.
fn duplicate_key_message(text: &str, span: std::ops::Range<usize>) -> String {
    let written = text.get(span.clone()).unwrap_or_default().trim();
    let name = written.trim_matches(|c| c == '"' || c == '\'');
    let mut renamed = text.to_string();
    let mut span = span;
    for i in 0..16 {
        if renamed.get(span.clone()).is_none() {
            break;
        }
        renamed.replace_range(span, &format!("{PLACEHOLDER}{i}"));
        match DeTable::parse(&renamed) {
            Ok(tree) => {
                let placeholder = format!("{PLACEHOLDER}0");
                if let Some((path, first)) =
                    find_renamed(tree.get_ref(), &placeholder, name, String::new())
                {
                    let first = first
                        .map(|at| format!(" (first written on line {})", line_col(&renamed, at).0))
                        .unwrap_or_default();
                    return format!("`{path}`: {DUPLICATE_KEY}{first}");
                }
                break;
            }
            Err(e) if e.message().trim() == DUPLICATE_KEY && e.span().is_some() => {
                span = e.span().unwrap_or_default();
            }
            Err(_) => break,
        }
    }
    format!("`{name}`: {DUPLICATE_KEY}")
}

/// The key path of `placeholder` in `table` (whose own path is `path`), and the offset of its
/// sibling `name`, the first occurrence of the duplicate key.
fn find_renamed(
    table: &DeTable<'_>,
    placeholder: &str,
    name: &str,
    path: String,
) -> Option<(String, Option<usize>)> {
    let join = |key: &str| {
        if path.is_empty() {
            key.to_string()
        } else {
            format!("{path}.{key}")
        }
    };
    for (key, value) in table.iter() {
        if key.get_ref() == placeholder {
            let first = table
                .iter()
                .find(|(k, _)| k.get_ref() == name)
                .map(|(k, _)| k.span().start);
            return Some((join(name), first));
        }
        let found = match value.get_ref() {
            DeValue::Table(t) => find_renamed(t, placeholder, name, join(key.get_ref())),
            DeValue::Array(items) => items.iter().enumerate().find_map(|(i, item)| {
                let DeValue::Table(t) = item.get_ref() else {
                    return None;
                };
                find_renamed(
                    t,
                    placeholder,
                    name,
                    format!("{}[{i}]", join(key.get_ref())),
                )
            }),
            _ => None,
        };
        if found.is_some() {
            return found;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The message of parsing `text`, which must fail.
    fn error(text: &str) -> String {
        Document::parse(text, Path::new("scene.toml"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn duplicate_keys_are_named_by_their_path_and_first_line() {
        let cases = [
            (
                "[materials.white]\nreflectance = 1\nreflectance = 2\n",
                "scene.toml:3:1: TOML syntax error: `materials.white.reflectance`: duplicate key (first written on line 2)",
            ),
            (
                "a = 1\nb = 2\na = 3\n",
                "scene.toml:3:1: TOML syntax error: `a`: duplicate key (first written on line 1)",
            ),
            (
                "[film]\nwidth = 1\n\n[film]\nheight = 2\n",
                "`film`: duplicate key (first written on line 1)",
            ),
            (
                "[media.fog]\nphase = { type = \"hg\", g = 0.1, g = 0.2 }\n",
                "`media.fog.phase.g`: duplicate key (first written on line 2)",
            ),
            (
                "[a]\nb.c = 1\nb.c = 2\n",
                "`a.b.c`: duplicate key (first written on line 2)",
            ),
            (
                "[[shapes]]\ntype = 'sphere'\n\n[[shapes]]\ntype = 'quad'\n\"type\" = 'mesh'\n",
                "scene.toml:6:1: TOML syntax error: `shapes[1].type`: duplicate key (first written on line 5)",
            ),
            // Another duplicate further on does not hide the first one's path.
            (
                "[film]\nwidth = 1\n\n[film]\nheight = 2\n[camera]\nfov = 1\nfov = 2\n",
                "scene.toml:4:2: TOML syntax error: `film`: duplicate key (first written on line 1)",
            ),
            // Three times: the second is reported.
            (
                "x = 1\nx = 2\nx = 3\n",
                "scene.toml:2:1: TOML syntax error: `x`: duplicate key (first written on line 1)",
            ),
        ];
        for (text, expected) in cases {
            let message = error(text);
            assert!(message.contains(expected), "{text:?}:\n{message}");
        }
    }

    #[test]
    fn other_syntax_errors_keep_their_message() {
        let message = error("[film\nwidth = 1\n");
        assert!(message.starts_with("scene.toml:1:"), "{message}");
        assert!(!message.contains(DUPLICATE_KEY), "{message}");
    }
}
