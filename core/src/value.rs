//! A scene document as an owned tree whose every value remembers its line and column, so that
//! scene errors can name the place they come from. The tree is what plugins read their
//! parameters from ([`crate::props::Properties`]); parsing TOML text into it (and `--set`) is
//! the loader's (foton-loader's `document`), so that core needs no TOML parser.

use std::path::{Path, PathBuf};

#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Bool(bool),
    Int(i64),
    Float(f64),
    Str(String),
    Datetime(String),
    Array(Vec<Node>),
    Table(Table),
}

/// A value and where it was written (line 0: not from the file, e.g. `--set`).
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub value: Value,
    pub line: u32,
    pub column: u32,
}

/// Keys in file order is not what toml gives; sorted order is stable and good enough.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table(pub Vec<(String, Node)>);

impl Table {
    pub fn get(&self, key: &str) -> Option<&Node> {
        self.0.iter().find(|(k, _)| k == key).map(|(_, n)| n)
    }
    pub fn get_mut(&mut self, key: &str) -> Option<&mut Node> {
        self.0.iter_mut().find(|(k, _)| k == key).map(|(_, n)| n)
    }
    pub fn keys(&self) -> impl Iterator<Item = &str> {
        self.0.iter().map(|(k, _)| k.as_str())
    }
    pub fn insert(&mut self, key: &str, node: Node) {
        match self.get_mut(key) {
            Some(slot) => *slot = node,
            None => self.0.push((key.to_string(), node)),
        }
    }
}

impl Value {
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::Bool(_) => "a boolean",
            Value::Int(_) => "an integer",
            Value::Float(_) => "a float",
            Value::Str(_) => "a string",
            Value::Datetime(_) => "a datetime",
            Value::Array(_) => "an array",
            Value::Table(_) => "a table",
        }
    }
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Value::Int(i) => Some(i as f64),
            Value::Float(f) => Some(f),
            _ => None,
        }
    }
    /// Short rendering for error messages.
    pub fn show(&self) -> String {
        match self {
            Value::Bool(b) => b.to_string(),
            Value::Int(i) => i.to_string(),
            Value::Float(f) => f.to_string(),
            Value::Str(s) => format!("{s:?}"),
            Value::Datetime(s) => s.clone(),
            Value::Array(a) => {
                let items: Vec<String> = a.iter().map(|n| n.value.show()).collect();
                format!("[{}]", items.join(", "))
            }
            Value::Table(_) => "{...}".into(),
        }
    }
}

/// A parsed scene document: its tree and the file it came from.
#[derive(Clone, Debug)]
pub struct Document {
    pub file: PathBuf,
    pub root: Table,
}

/// `path` relative to the folder `base` (both absolute): `../meshes/a.obj`. Lexical: `..`
/// in `path` is resolved against the components before it, which is right for the canonical
/// folders `foton convert` passes.
pub fn relative_path(path: &Path, base: &Path) -> PathBuf {
    use std::path::Component;
    let normal = |p: &Path| {
        let mut out: Vec<Component<'_>> = Vec::new();
        for c in p.components() {
            match c {
                Component::CurDir => {}
                Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                    out.pop();
                }
                c => out.push(c),
            }
        }
        out.into_iter()
            .map(|c| c.as_os_str().to_owned())
            .collect::<Vec<_>>()
    };
    let (p, b) = (normal(path), normal(base));
    let common = p.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &p[common..] {
        out.push(c);
    }
    out
}

impl Document {
    /// Rewrites the relative `file` of every shape and the `filename` of every light (an
    /// envmap's image) and of every material's texture, written relative to the folder `from`,
    /// relative to the folder `to` (both absolute): for a document written into another folder
    /// than the one it was read from, whose inputs must still be found. The film's `output`
    /// is left as it is, so the image is written beside the new file.
    pub fn rebase_files(&mut self, from: &Path, to: &Path) {
        let fix = |node: &mut Node| {
            if let Value::Str(s) = &mut node.value
                && Path::new(s.as_str()).is_relative()
            {
                *s = relative_path(&from.join(&*s), to)
                    .to_string_lossy()
                    .into_owned();
            }
        };
        for (array, key) in [("shapes", "file"), ("lights", "filename")] {
            if let Some(Node {
                value: Value::Array(items),
                ..
            }) = self.root.get_mut(array)
            {
                for item in items {
                    if let Value::Table(t) = &mut item.value
                        && let Some(file) = t.get_mut(key)
                    {
                        fix(file);
                    }
                }
            }
        }
        // A texture is an inline table with a `filename`, as a material's field.
        if let Some(Node {
            value: Value::Table(materials),
            ..
        }) = self.root.get_mut("materials")
        {
            for (_, material) in materials.0.iter_mut() {
                if let Value::Table(fields) = &mut material.value {
                    for (_, field) in fields.0.iter_mut() {
                        if let Value::Table(texture) = &mut field.value
                            && let Some(file) = texture.get_mut("filename")
                        {
                            fix(file);
                        }
                    }
                }
            }
        }
    }
}
