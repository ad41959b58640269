//! The property bag: how the scene loader and every plugin read parameters by name, with the
//! default written once at the call and every error worded in one place (Mitsuba 3's
//! `Properties`, pbrt-v4's `ParameterDictionary`). It remembers which keys were read, so that
//! unknown (misspelt) parameters can be reported afterwards.

use crate::error::{Error, Location, Result, did_you_mean, edit_distance};
use crate::kernel::{KERNELS, KernelPlugin, NormalizedKernel};
use crate::value::{Node, Table, Value};
use glam::Vec3;
use std::cell::RefCell;
use std::path::Path;

/// A key written in a table that nothing read.
#[derive(Clone, Debug, PartialEq)]
pub struct Unused {
    /// Its TOML key path (`integrators.path.rr_dept`).
    pub key: String,
    pub location: Location,
    /// The key path it most likely meant (`integrators.path.rr_depth`), if one is close.
    pub suggestion: Option<String>,
}

impl Unused {
    /// "unknown field" and what it may have meant, for messages.
    pub fn message(&self) -> String {
        match &self.suggestion {
            Some(s) => format!("unknown field (did you mean `{s}`?)"),
            None => "unknown field".into(),
        }
    }
}

pub struct Properties<'a> {
    file: &'a Path,
    path: String,
    table: &'a Table,
    line: u32,
    column: u32,
    used: RefCell<Vec<String>>,
    /// Every name asked for, present or not: what an unknown key may have meant.
    asked: RefCell<Vec<String>>,
    /// Kernel plugins that `kernel()` may return (handed over by the host).
    plugins: &'a [KernelPlugin],
}

static EMPTY: Table = Table(Vec::new());

impl<'a> Properties<'a> {
    /// A bag over `node`, which must be a table; `path` is its TOML key path ("materials.red").
    pub fn new(file: &'a Path, path: &str, node: &'a Node) -> Result<Self> {
        match &node.value {
            Value::Table(table) => Ok(Properties {
                file,
                path: path.to_string(),
                table,
                line: node.line,
                column: node.column,
                used: RefCell::new(Vec::new()),
                asked: RefCell::new(Vec::new()),
                plugins: &[],
            }),
            other => Err(Error::Scene {
                location: Location {
                    file: file.to_path_buf(),
                    line: node.line,
                    column: node.column,
                },
                key: path.to_string(),
                message: format!("expected a table, found {}", other.type_name()),
            }),
        }
    }

    /// A bag over the root table of a document.
    pub fn root(file: &'a Path, table: &'a Table) -> Self {
        Properties {
            file,
            path: String::new(),
            table,
            line: 0,
            column: 0,
            used: RefCell::new(Vec::new()),
            asked: RefCell::new(Vec::new()),
            plugins: &[],
        }
    }

    /// An empty bag (a plugin whose `[integrators.NAME]` table is absent).
    pub fn empty(file: &'a Path, path: &str) -> Self {
        Properties {
            file,
            path: path.to_string(),
            table: &EMPTY,
            line: 0,
            column: 0,
            used: RefCell::new(Vec::new()),
            asked: RefCell::new(Vec::new()),
            plugins: &[],
        }
    }

    /// Makes the host's kernel plugins (its registry's `kernels`) available to
    /// [`Properties::kernel`].
    pub fn with_kernels(mut self, kernels: &'a [KernelPlugin]) -> Self {
        self.plugins = kernels;
        self
    }

    /// The density-estimation kernel named by parameter `name` (default `default`): a built-in
    /// (`box`, `cone` with parameter `cone_c` >= 1, `gaussian`) or a kernel plugin, normalised
    /// in 2-D and 3-D. The error for an unknown name lists the kernels found.
    pub fn kernel(&self, name: &str, default: &'a str) -> Result<NormalizedKernel> {
        let kind = self.string(name, default)?;
        // A built-in reads its own parameters (`cone_c`) from this bag.
        let kernel: Box<dyn crate::kernel::Kernel> =
            if let Some(factory) = crate::registry::find(KERNELS, kind) {
                (factory.create)(self, &mut Vec::new(), &mut crate::registry::NoResources)?
            } else if let Some(k) = self.plugins.iter().find(|k| k.name == kind) {
                Box::new(k.clone())
            } else {
                let mut known: Vec<String> =
                    crate::registry::names(KERNELS).map(String::from).collect();
                known.extend(self.plugins.iter().map(|k| format!("{} (plugin)", k.name)));
                return Err(self.error(
                    name,
                    format!("unknown kernel {kind:?}; available: {}", known.join(", ")),
                ));
            };
        NormalizedKernel::new(kernel).map_err(|e| self.error(name, e.to_string()))
    }

    pub fn file(&self) -> &'a Path {
        self.file
    }
    /// The TOML key path of this table ("" for the root).
    pub fn path(&self) -> &str {
        &self.path
    }

    pub fn key_path(&self, name: &str) -> String {
        if self.path.is_empty() {
            name.to_string()
        } else {
            format!("{}.{}", self.path, name)
        }
    }

    /// Where `name` was written, or the table itself when it was not.
    pub fn location(&self, name: &str) -> Location {
        let (line, column) = self
            .table
            .get(name)
            .map_or((self.line, self.column), |n| (n.line, n.column));
        Location {
            file: self.file.to_path_buf(),
            line,
            column,
        }
    }

    /// The error every check uses: file, line, key path, message.
    pub fn error(&self, name: &str, message: impl Into<String>) -> Error {
        Error::Scene {
            location: self.location(name),
            key: self.key_path(name),
            message: message.into(),
        }
    }

    pub fn has(&self, name: &str) -> bool {
        self.ask(name);
        self.table.get(name).is_some()
    }

    fn ask(&self, name: &str) {
        let mut asked = self.asked.borrow_mut();
        if !asked.iter().any(|k| k == name) {
            asked.push(name.to_string());
        }
    }

    pub fn keys(&self) -> impl Iterator<Item = &'a str> {
        self.table.keys()
    }

    /// The raw node, marked as used.
    pub fn node(&self, name: &str) -> Option<&'a Node> {
        self.ask(name);
        let node = self.table.get(name)?;
        let mut used = self.used.borrow_mut();
        if !used.iter().any(|k| k == name) {
            used.push(name.to_string());
        }
        Some(node)
    }

    fn expected(&self, name: &str, what: &str, found: &Value) -> Error {
        self.error(
            name,
            format!(
                "expected {what}, found {} `{}`",
                found.type_name(),
                found.show()
            ),
        )
    }

    fn number(&self, name: &str, node: &Node) -> Result<f64> {
        node.value
            .as_f64()
            .ok_or_else(|| self.expected(name, "a number", &node.value))
    }

    fn finite(&self, name: &str, x: f64) -> Result<f32> {
        // Checked after the conversion: 1e40 is a finite f64 but an infinite f32.
        let v = x as f32;
        if v.is_finite() {
            Ok(v)
        } else if x.is_finite() {
            Err(self.error(
                name,
                format!("expected a finite number; {x} is too large for single precision"),
            ))
        } else {
            Err(self.error(name, format!("expected a finite number, found {x}")))
        }
    }

    pub fn f32_opt(&self, name: &str) -> Result<Option<f32>> {
        match self.node(name) {
            None => Ok(None),
            Some(node) => {
                let x = self.number(name, node)?;
                self.finite(name, x).map(Some)
            }
        }
    }

    /// A finite number, `default` when absent.
    pub fn f32(&self, name: &str, default: f32) -> Result<f32> {
        Ok(self.f32_opt(name)?.unwrap_or(default))
    }

    pub fn f32_required(&self, name: &str) -> Result<f32> {
        self.f32_opt(name)?
            .ok_or_else(|| self.error(name, "missing; expected a number"))
    }

    /// A number that may also be `inf` (e.g. an unbounded radius).
    pub fn f32_or_inf(&self, name: &str, default: f32) -> Result<f32> {
        match self.node(name) {
            None => Ok(default),
            Some(node) => {
                let x = self.number(name, node)?;
                if x.is_nan() {
                    Err(self.error(name, "expected a number, found nan"))
                } else {
                    Ok(x as f32)
                }
            }
        }
    }

    /// A non-negative integer, `default` when absent.
    pub fn u64(&self, name: &str, default: u64) -> Result<u64> {
        match self.node(name) {
            None => Ok(default),
            Some(node) => match node.value {
                Value::Int(i) if i >= 0 => Ok(i as u64),
                Value::Int(i) => {
                    Err(self.error(name, format!("expected a non-negative integer, found {i}")))
                }
                ref other => Err(self.expected(name, "an integer", other)),
            },
        }
    }

    pub fn u32(&self, name: &str, default: u32) -> Result<u32> {
        let v = self.u64(name, default as u64)?;
        u32::try_from(v)
            .map_err(|_| self.error(name, format!("{v} is too large (at most {})", u32::MAX)))
    }

    pub fn bool(&self, name: &str, default: bool) -> Result<bool> {
        match self.node(name) {
            None => Ok(default),
            Some(node) => match node.value {
                Value::Bool(b) => Ok(b),
                ref other => Err(self.expected(name, "true or false", other)),
            },
        }
    }

    pub fn string_opt(&self, name: &str) -> Result<Option<&'a str>> {
        match self.node(name) {
            None => Ok(None),
            Some(node) => match &node.value {
                Value::Str(s) => Ok(Some(s.as_str())),
                other => Err(self.expected(name, "a string", other)),
            },
        }
    }

    pub fn string(&self, name: &str, default: &'a str) -> Result<&'a str> {
        Ok(self.string_opt(name)?.unwrap_or(default))
    }

    pub fn string_required(&self, name: &str) -> Result<&'a str> {
        self.string_opt(name)?
            .ok_or_else(|| self.error(name, "missing; expected a string"))
    }

    /// One of `options`, `default` when absent; the error lists the options.
    pub fn choice(&self, name: &str, options: &[&str], default: &'a str) -> Result<&'a str> {
        let s = self.string(name, default)?;
        if options.contains(&s) {
            Ok(s)
        } else {
            Err(self.error(name, unknown_value(s, options)))
        }
    }

    /// An array of exactly `n` finite numbers.
    pub fn floats_opt(&self, name: &str, n: usize) -> Result<Option<Vec<f32>>> {
        let Some(node) = self.node(name) else {
            return Ok(None);
        };
        let expected = format!("an array of {n} numbers");
        let Value::Array(items) = &node.value else {
            return Err(self.expected(name, &expected, &node.value));
        };
        if items.len() != n {
            return Err(self.error(
                name,
                format!(
                    "expected {expected}, found {} element(s) `{}`",
                    items.len(),
                    node.value.show()
                ),
            ));
        }
        let mut v = Vec::with_capacity(n);
        for item in items {
            let x = item
                .value
                .as_f64()
                .ok_or_else(|| self.expected(name, &expected, &node.value))?;
            v.push(self.finite(name, x)?);
        }
        Ok(Some(v))
    }

    pub fn vec3_opt(&self, name: &str) -> Result<Option<Vec3>> {
        Ok(self.floats_opt(name, 3)?.map(|v| Vec3::from_slice(&v)))
    }

    pub fn vec3(&self, name: &str, default: Vec3) -> Result<Vec3> {
        Ok(self.vec3_opt(name)?.unwrap_or(default))
    }

    pub fn vec3_required(&self, name: &str) -> Result<Vec3> {
        self.vec3_opt(name)?
            .ok_or_else(|| self.error(name, "missing; expected an array of 3 numbers [x, y, z]"))
    }

    /// An RGB triple whose channels are all >= 0.
    pub fn rgb_opt(&self, name: &str) -> Result<Option<Vec3>> {
        let v = self.vec3_opt(name)?;
        if let Some(c) = v
            && c.min_element() < 0.0
        {
            return Err(self.error(
                name,
                format!(
                    "expected non-negative values, found [{}, {}, {}]",
                    c.x, c.y, c.z
                ),
            ));
        }
        Ok(v)
    }

    pub fn rgb(&self, name: &str, default: Vec3) -> Result<Vec3> {
        Ok(self.rgb_opt(name)?.unwrap_or(default))
    }

    /// A nested table, if present.
    pub fn table(&self, name: &str) -> Result<Option<Properties<'a>>> {
        match self.node(name) {
            None => Ok(None),
            Some(node) => Properties::new(self.file, &self.key_path(name), node).map(Some),
        }
    }

    /// Keys present in the table but never read: misspelt or unsupported parameters, each
    /// with the name it most likely meant among those that were asked for.
    pub fn unused(&self) -> Vec<Unused> {
        let used = self.used.borrow();
        let asked = self.asked.borrow();
        self.table
            .keys()
            .filter(|k| !used.iter().any(|u| u == k))
            .map(|k| Unused {
                key: self.key_path(k),
                location: self.location(k),
                suggestion: did_you_mean(k, asked.iter().map(String::as_str))
                    .map(|s| self.key_path(s)),
            })
            .collect()
    }
}

/// "unknown value "sobl" (did you mean "sobol"?); expected one of: ...": the suggestion is
/// the option nearest in edit distance ([`edit_distance`], which counts a swap of neighbouring
/// characters as one edit), when it is near enough to be a typing slip.
pub fn unknown_value(value: &str, options: &[&str]) -> String {
    let nearest = options
        .iter()
        .map(|o| (edit_distance(&value.to_lowercase(), o), *o))
        .min();
    let hint = match nearest {
        Some((d, o)) if d <= (o.len() / 3).max(1) => format!(" (did you mean {o:?}?)"),
        _ => String::new(),
    };
    format!(
        "unknown value {value:?}{hint}; expected one of: {}",
        options.join(", ")
    )
}
