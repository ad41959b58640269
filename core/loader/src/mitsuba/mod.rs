//! Mitsuba XML scenes (Mitsuba 3, and 0.4 to 0.6 upgraded as Mitsuba 3 upgrades them), read
//! into the document a TOML scene makes: `foton render scene.xml` renders what the same scene
//! written in TOML would (`foton convert` writes that TOML), and every value keeps the XML
//! line it came from, so the loader's errors name the XML file and line. Parameters foton
//! understands but ignores are warnings with their file:line (`Report::warnings`), errors
//! with `--strict`.
//!
//! Mitsuba's conventions, as its documentation states them: `<default>` and `$name`
//! substitution (`-D name=value` overrides a default), `ref`/`id`, `include`, file names
//! looked for as Mitsuba's file resolver does (the file's folder, `<path>` folders, the
//! including files' folders, the scene's), no `<sensor>` as Mitsuba's default one; transforms
//! composed in document order; `max_depth` counts path segments (-1: unbounded), so foton's
//! count of scattering events is one less; area emitters emit on their normal's side; the
//! sensor looks down its local +z with +y up. What foton cannot render yet is an error naming
//! the element, its type and file:line, or with `lenient` is left out and listed.
//!
//! The reader is laid out as Mitsuba 3's parser and plugin folders are. `document` reads the
//! XML: `<include>`, `<path>`, `<default>` and `$name`, `<alias>`, each element into an `Obj` (its
//! property list, `object`), `<transform>` composed; `upgrade` holds the version upgrade
//! rules for files older than 2.0. Then one file per element family turns an element into the
//! tables of the TOML document: `shape`, `bsdf`, `emitter`, `medium`, `texture`, `sensor`
//! (with its film, reconstruction filter and sampler) and `integrator`, each an
//! `impl Reader` block. `plugins` lists Mitsuba's plugins, so that a type foton does not read
//! is "not supported" or "unknown" as Mitsuba would know it.

mod bsdf;
mod document;
mod emitter;
mod integrator;
mod medium;
mod object;
mod plugins;
mod sensor;
mod shape;
#[cfg(test)]
mod tests;
mod texture;
mod upgrade;

use crate::reader::{Options, Report};
use foton_core::error::{Error, Result};
use foton_core::value::{Document, Node, Table, Value};
use glam::{DMat4, DVec3};
use object::{Obj, Prop, show};
use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// The Mitsuba format's reader ([`crate::reader`]): [`read_xml`] of a file.
pub fn read(path: &Path, options: &Options<'_>) -> Result<(Document, Report)> {
    if path.is_dir() {
        return Err(Error::io(path, "is a directory, not a scene file"));
    }
    read_xml(path, options.defines, options.lenient)
}

/// Reads a Mitsuba XML scene (3.x, 2.x, or 0.x and 1.x upgraded). `defines` are `NAME=VALUE` overrides of its `<default>`s.
pub fn read_xml(path: &Path, defines: &[String], lenient: bool) -> Result<(Document, Report)> {
    let mut defaults = HashMap::new();
    for d in defines {
        let (name, value) = d
            .split_once('=')
            .ok_or_else(|| Error::Usage(format!("-D {d}: expected NAME=VALUE, e.g. -D spp=16")))?;
        defaults.insert(name.trim().to_string(), value.trim().to_string());
    }
    let mut r = Reader {
        file: path.to_path_buf(),
        dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        defined: defaults.keys().cloned().collect(),
        defaults,
        lenient,
        report: Report::default(),
        root: Table::default(),
        shapes: Vec::new(),
        lights: Vec::new(),
        bsdfs: HashMap::new(),
        masks: HashMap::new(),
        textures: HashMap::new(),
        media: HashMap::new(),
        sensor_medium: None,
        shape_media: false,
        anonymous: 0,
        v1: false,
        used: RefCell::default(),
        unresolved: RefCell::default(),
        late_warnings: RefCell::default(),
        declared: HashSet::new(),
        integrator: None,
        search: vec![path.parent().map(Path::to_path_buf).unwrap_or_default()],
        objects: HashMap::new(),
        sensor: false,
        meter: None,
        crop: None,
        pending: Vec::new(),
        left_out_ids: HashSet::new(),
    };
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    r.read_file(path, &text)?;
    r.make_objects()?;
    r.report.left_out.append(&mut r.unresolved.borrow_mut());
    r.report.warnings.append(&mut r.late_warnings.borrow_mut());
    r.check_defines(path)?;
    // No sensor, or (lenient) none foton reads.
    if r.root.get("camera").is_none() {
        r.default_sensor(path, r.sensor);
    }
    r.place_sensor_medium();
    if let Some(o) = r.integrator.take() {
        let included = o.file != r.file;
        let before = r.root.clone();
        r.integrator(o)?;
        if included {
            forget_lines(&before, &mut r.root);
            if let Some((_, _, line)) = &mut r.report.relative_radius {
                *line = 0;
            }
        }
    }
    r.samples_past_u32();
    let mut root = std::mem::take(&mut r.root);
    if !r.shapes.is_empty() {
        root.insert("shapes", at(Value::Array(std::mem::take(&mut r.shapes)), 0));
    }
    if !r.lights.is_empty() {
        root.insert("lights", at(Value::Array(std::mem::take(&mut r.lights)), 0));
    }
    // Mitsuba samples independently when a file names no sampler; foton's TOML default
    // (sobol) would render such a file with other noise than Mitsuba's.
    let render = table_mut(&mut root, "render");
    if render.get("sampler").is_none() {
        render.insert("sampler", at(Value::Str("independent".into()), 0));
    }
    let film = table_mut(&mut root, "film");
    if film.get("output").is_none() {
        let stem = path
            .file_stem()
            .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
        film.insert("output", at(Value::Str(format!("{stem}.exr")), 0));
    }
    Ok((
        Document {
            file: path.to_path_buf(),
            root,
        },
        r.report,
    ))
}

/// The values `after` holds that `before` did not (or held otherwise) lose their line: they
/// were written in an included file, and a line of the document is one of the scene file's.
/// (Errors while reading the included file name it and its lines; the builder's cannot.)
fn forget_lines(before: &Table, after: &mut Table) {
    for (key, node) in &mut after.0 {
        let old = before.get(key);
        if old == Some(&*node) {
            continue;
        }
        match (old, &mut node.value) {
            (
                Some(Node {
                    value: Value::Table(old),
                    ..
                }),
                Value::Table(new),
            ) => forget_lines(old, new),
            _ => forget_line(node),
        }
    }
}

/// A value, and all it holds, without a line of the scene file (see [`forget_lines`]).
fn forget_line(node: &mut Node) {
    node.line = 0;
    node.column = 0;
    match &mut node.value {
        Value::Array(items) => items.iter_mut().for_each(forget_line),
        Value::Table(t) => t.0.iter_mut().for_each(|(_, n)| forget_line(n)),
        _ => {}
    }
}

/// The folders a file was looked for in, for a message ("." for the working folder).
fn shown(folders: &[PathBuf]) -> String {
    if folders.is_empty() {
        return "no folder (the path is absolute)".into();
    }
    folders
        .iter()
        .map(|d| match d.to_string_lossy() {
            s if s.is_empty() => "\".\"".to_string(),
            s => format!("{s:?}"),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn at(value: Value, line: u32) -> Node {
    Node {
        value,
        line,
        column: if line > 0 { 1 } else { 0 },
    }
}

fn table_mut<'t>(t: &'t mut Table, key: &str) -> &'t mut Table {
    if t.get(key).is_none() {
        t.insert(key, at(Value::Table(Table::default()), 0));
    }
    match &mut t.get_mut(key).expect("inserted").value {
        Value::Table(inner) => inner,
        _ => unreachable!("only tables are inserted under section keys"),
    }
}

/// A transform as the TOML `{ matrix = [16 numbers, row-major] }` table.
fn matrix_table(m: DMat4, line: u32) -> Node {
    let rows: Vec<Node> = (0..4)
        .flat_map(|r| m.row(r).to_array())
        .map(|x| at(Value::Float(x), line))
        .collect();
    let mut t = Table::default();
    t.insert("matrix", at(Value::Array(rows), line));
    at(Value::Table(t), line)
}

fn vec3(v: DVec3, line: u32) -> Node {
    at(
        Value::Array(
            v.to_array()
                .iter()
                .map(|x| at(Value::Float(*x), line))
                .collect(),
        ),
        line,
    )
}

struct Reader {
    file: PathBuf,
    dir: PathBuf,
    defaults: HashMap<String, String>,
    /// Names set by -D (a `<default>` does not override them).
    defined: Vec<String>,
    lenient: bool,
    report: Report,
    root: Table,
    shapes: Vec<Node>,
    lights: Vec<Node>,
    /// BSDF ids to their material names in `[materials]`.
    bsdfs: HashMap<String, String>,
    /// Materials that a `mask` wraps, to their opacity: a shape with one takes it as its
    /// `alpha`.
    masks: HashMap<String, Node>,
    /// The sensor's medium (its name in `[media]`, line).
    sensor_medium: Option<(String, u32)>,
    /// Whether any shape names an interior or exterior medium.
    shape_media: bool,
    /// Top-level `<texture id="...">`s, as the inline tables a material field takes.
    textures: HashMap<String, Table>,
    /// Medium ids to their names in `[media]`.
    media: HashMap<String, String>,
    anonymous: usize,
    /// The file being read is Mitsuba 0.x or 1.x: its properties are upgraded as Mitsuba 3
    /// upgrades them (camelCase to snake_case...).
    v1: bool,
    /// The `$name`s substituted so far (a `-D` nobody uses is a typo).
    used: RefCell<HashSet<String>>,
    /// With `lenient`, the properties left out for a `$name` with no value (what the report
    /// says of each), gathered while reading elements and added to the report at the end.
    unresolved: RefCell<Vec<String>>,
    /// Warnings of what is read where the reader holds itself unchanged (a file found only in
    /// a folder above the scene's, a plugin name in another case), added to the report at the
    /// end.
    late_warnings: RefCell<Vec<String>>,
    /// The `<default>`s declared.
    declared: HashSet<String>,
    /// The `<integrator>`, read last: which plugin renders a photon mapper depends on whether
    /// the scene has media.
    integrator: Option<Obj>,
    /// Mitsuba's file resolver: the folders a relative file name is looked for in, the last
    /// first (the scene's folder, then each `<path>` and each including file's folder, in
    /// the order read; an `<include>`d file's own are forgotten at its end).
    search: Vec<PathBuf>,
    /// Top-level objects with an `id` that others take by `<ref>` and that are not made
    /// where they stand: samplers, films, reconstruction filters, area emitters.
    objects: HashMap<String, Obj>,
    /// Whether the file has a `<sensor>` (without one, Mitsuba places its own; with one
    /// foton does not read, `lenient` places Mitsuba's default).
    sensor: bool,
    /// The sensor when it is a meter: `radiancemeter` or `irradiancemeter`.
    meter: Option<&'static str>,
    /// The film's crop window, read with the film, applied to the sensor's camera.
    crop: Option<sensor::Crop>,
    /// The top-level objects (and aliases) read, made once the whole file is read.
    pending: Vec<Obj>,
    /// Ids of top-level objects left out (lenient).
    left_out_ids: HashSet<String>,
}

impl Reader {
    /// Something foton cannot render: an error, or with `lenient` a line in the report.
    fn unsupported(&mut self, obj: &Obj, what: &str) -> Result<()> {
        if self.lenient {
            self.report
                .left_out
                .push(format!("{}: {}: {what}", obj.place(), obj.what()));
            Ok(())
        } else {
            Err(obj.error(format!("{what} (--lenient renders without it)")))
        }
    }

    /// Properties nobody read: Mitsuba parameters foton does not know. In a 0.x file, one
    /// that Mitsuba 0.6 does not read either is a warning, as 0.6 makes it.
    fn leftovers(&mut self, obj: &Obj) -> Result<()> {
        for (name, _, line) in obj.props.clone() {
            let o = Obj {
                line,
                ..obj.clone()
            };
            if obj.v1 && !plugins::mitsuba06_reads(&obj.tag, &obj.ty, &name) {
                self.warn(
                    obj,
                    line,
                    &format!(
                        "parameter `{name}` ignored: Mitsuba 0.6 does not read it either (it warns of an unqueried attribute and renders on)"
                    ),
                );
                continue;
            }
            self.unsupported(&o, &format!("parameter `{name}` is not supported"))?;
        }
        Ok(())
    }

    /// A parameter foton understands but ignores or renders otherwise (at `line`).
    fn warn(&mut self, obj: &Obj, line: u32, what: &str) {
        self.report.warnings.push(format!(
            "{}:{line}: {}: {what}",
            obj.file.display(),
            obj.what()
        ));
    }

    /// Takes a parameter foton does not honour: a warning unless `same` says its value asks
    /// for what foton does anyway (`why` empty: it changes nothing foton renders).
    fn ignored(&mut self, o: &mut Obj, name: &str, same: &dyn Fn(&Prop) -> bool, why: &str) {
        if let Some((p, line)) = o.take(name)
            && !same(&p)
        {
            let why = if why.is_empty() {
                "ignored (it changes how Mitsuba runs, not the image)"
            } else {
                why
            };
            self.warn(o, line, &format!("`{name}` = {}: {why}", show(&p)));
        }
    }

    /// Takes the hints of the specular manifold sampling fork of Mitsuba 2 (Zeltner et al.
    /// 2020: which emitters, casters and receivers its caustic integrators connect), which
    /// its other integrators ignore: noted, as they change no image foton renders.
    fn manifold_hints(&mut self, o: &mut Obj) {
        const HINTS: [&str; 7] = [
            "caustic_emitter_single",
            "caustic_emitter_multi",
            "caustic_caster_single",
            "caustic_caster_multi",
            "caustic_receiver",
            "caustic_bouncer",
            "glinty",
        ];
        let mut taken = Vec::new();
        for h in HINTS {
            if o.take(h).is_some() {
                taken.push(format!("`{h}`"));
            }
        }
        if !taken.is_empty() {
            let what = format!(
                "{} read as the hints of Mitsuba 2's specular manifold sampling fork: they choose what its caustic integrators connect and change nothing else",
                taken.join(", ")
            );
            self.note(o, &what);
        }
    }

    fn note(&mut self, obj: &Obj, what: &str) {
        self.report
            .notes
            .push(format!("{}: {}: {what}", obj.place(), obj.what()));
    }

    fn new_name(&mut self, prefix: &str, id: &Option<String>) -> String {
        id.clone().unwrap_or_else(|| {
            self.anonymous += 1;
            format!("{prefix}_{}", self.anonymous)
        })
    }

    /// The element's required `filename`, found as Mitsuba's file resolver finds it
    /// ([`Reader::resolve`]), as the TOML document's path (relative to the main scene's
    /// folder, or absolute). A file found nowhere is an error at the element.
    fn filename(&self, o: &mut Obj) -> Result<Node> {
        let file = o
            .string("filename")?
            .ok_or_else(|| o.error("missing `filename`"))?;
        let path = self.resolve(&o.file, &file).map_err(|looked| {
            o.error(format!(
                "`filename` = {file:?}: no such file in {}",
                shown(&looked)
            ))
        })?;
        let rel = path
            .strip_prefix(&self.dir)
            .map_or(path.clone(), Path::to_path_buf);
        Ok(at(Value::Str(rel.to_string_lossy().into_owned()), o.line))
    }

    /// A relative file name written in `from`, looked for in `from`'s folder, then in the
    /// resolver's folders, the last added first (Mitsuba's `<path>` and `<include>` prepend
    /// theirs; the scene's folder is the last resort), then in the working folder, which
    /// Mitsuba's resolver holds from the start. Mitsuba 3 resolves the files of an included
    /// scene from the main scene's folder and Mitsuba 0.6 from the included file's: both are
    /// searched. Files written relative to a repository's root (as Mitsuba 0.6's test scenes
    /// are, for a renderer run from there) are found in the scene folder's ancestors, with a
    /// warning. Err: the folders looked in.
    fn resolve(&self, from: &Path, name: &str) -> std::result::Result<PathBuf, Vec<PathBuf>> {
        let name = Path::new(name);
        if name.is_absolute() {
            return if name.exists() {
                Ok(name.to_path_buf())
            } else {
                Err(Vec::new())
            };
        }
        let own = from.parent().unwrap_or(Path::new("")).to_path_buf();
        let cwd = std::env::current_dir().ok();
        let mut looked: Vec<PathBuf> = Vec::new();
        for dir in std::iter::once(&own)
            .chain(self.search.iter().rev())
            .chain(cwd.as_ref())
        {
            if looked.contains(dir) {
                continue;
            }
            let candidate = dir.join(name);
            if candidate.exists() {
                return Ok(candidate);
            }
            looked.push(dir.clone());
        }
        let main = std::path::absolute(&self.dir).unwrap_or_else(|_| self.dir.clone());
        if let Some(candidate) = main
            .ancestors()
            .skip(1)
            .map(|dir| dir.join(name))
            .find(|c| c.exists())
        {
            self.late_warnings.borrow_mut().push(format!(
                "{}: {:?} found as {}, in a folder above the scene's: Mitsuba finds it there \
                 only when run from that folder",
                from.display(),
                name,
                candidate.display()
            ));
            return Ok(candidate);
        }
        Err(looked)
    }

    /// A top-level object others take by `<ref>`. Without an `id` nothing can: Mitsuba makes
    /// it and uses it nowhere.
    fn keep(&mut self, obj: Obj) -> Result<()> {
        match obj.id.clone() {
            Some(id) => {
                self.objects.insert(id, obj);
                Ok(())
            }
            None => {
                self.warn(
                    &obj,
                    obj.line,
                    "ignored: at the top level without an `id`, nothing uses it",
                );
                Ok(())
            }
        }
    }

    fn top_level(&mut self, obj: Obj) -> Result<()> {
        match obj.tag.as_str() {
            "integrator" => {
                if self.integrator.is_some() {
                    return Err(obj.error("a second <integrator>: a scene has one"));
                }
                self.integrator = Some(obj);
                Ok(())
            }
            // Mitsuba's render takes the first sensor of the file.
            "sensor" if self.sensor => {
                self.warn(
                    &obj,
                    obj.line,
                    "a second sensor: not rendered (foton renders the file's first sensor, as Mitsuba's render does)",
                );
                Ok(())
            }
            "sensor" => {
                self.sensor = true;
                self.sensor(obj)
            }
            // Made where a sensor, a film, a shape or a medium takes them by `<ref>`.
            "sampler" | "film" | "rfilter" | "phase" => self.keep(obj),
            "emitter" if obj.ty == "area" => self.keep(obj),
            "bsdf" => self.bsdf(obj).map(|_| ()),
            "medium" => self.medium(obj).map(|_| ()),
            "shape" => self.shape(obj),
            "emitter" => self.emitter(obj),
            "texture" => {
                let id = obj.id.clone();
                let Some(t) = self.texture_table(obj)? else {
                    // Left out (lenient): what takes it by reference is left out with it.
                    self.left_out_ids.extend(id);
                    return Ok(());
                };
                if let Some(id) = id {
                    self.textures.insert(id, t);
                }
                Ok(())
            }
            other => Err(obj.error(format!("<{other}> is not a top-level element of a scene"))),
        }
    }
}
