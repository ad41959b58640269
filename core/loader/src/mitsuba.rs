//! Mitsuba XML scenes (Mitsuba 3, and 0.4 to 0.6 upgraded as Mitsuba 3 upgrades them), read
//! into the document a TOML scene makes: `foton render scene.xml` renders what the same scene
//! written in TOML would (`foton convert` writes that TOML), and every value keeps the XML
//! line it came from, so the loader's errors name the XML file and line. Parameters foton
//! understands but ignores are warnings with their file:line (`XmlReport::warnings`), errors
//! with `--strict`.
//!
//! Mitsuba's conventions, as its documentation states them: `<default>` and `$name`
//! substitution (`-D name=value` overrides a default), `ref`/`id`, `include`; transforms
//! composed in document order; `max_depth` counts path segments (-1: unbounded), so foton's
//! count of scattering events is one less; area emitters emit on their normal's side; the
//! sensor looks down its local +z with +y up. What foton cannot render yet is an error naming
//! the element, its type and file:line, or with `lenient` is left out and listed.

use foton_core::error::{Error, Location, Result};
use foton_core::value::{Document, Node, Table, Value};
use glam::{DMat4, DVec3};
use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// What reading an XML scene produced besides the document.
#[derive(Debug, Default)]
pub struct XmlReport {
    /// Elements and parameters left out (`lenient`), each with its file:line.
    pub left_out: Vec<String>,
    /// Things rendered differently from Mitsuba, each with its file:line.
    pub notes: Vec<String>,
    /// The files it included (`<include>`), which make the scene as much as its own file.
    pub included: Vec<PathBuf>,
    /// Parameters foton understands but ignores (or renders otherwise), each with its
    /// file:line: warnings, errors with `--strict`.
    pub warnings: Vec<String>,
    /// A photon lookup radius Mitsuba gives relative to the scene's bounding sphere: the
    /// integrator, the factor and its line; the loader sets `max_radius` once it knows the
    /// scene's bounds.
    pub relative_radius: Option<(String, f64, u32)>,
}

/// Reads a Mitsuba XML scene (3.x, 2.x, or 0.x and 1.x upgraded). `defines` are `NAME=VALUE` overrides of its `<default>`s.
pub fn read_xml(path: &Path, defines: &[String], lenient: bool) -> Result<(Document, XmlReport)> {
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
        report: XmlReport::default(),
        root: Table::default(),
        shapes: Vec::new(),
        lights: Vec::new(),
        bsdfs: HashMap::new(),
        textures: HashMap::new(),
        media: HashMap::new(),
        sensor_medium: None,
        shape_media: false,
        anonymous: 0,
        v1: false,
        used: RefCell::default(),
        declared: HashSet::new(),
        integrator: None,
    };
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    r.read_file(path, &text)?;
    r.check_defines(path)?;
    r.place_sensor_medium();
    if let Some(o) = r.integrator.take() {
        r.integrator(o)?;
    }
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

/// A property of an XML object.
#[derive(Clone, Debug)]
enum Prop {
    Float(f64),
    Int(i64),
    Bool(bool),
    Str(String),
    Color(DVec3),
    Point(DVec3),
    Transform(DMat4),
    Ref(String),
    Object(Obj),
}

/// An XML object element (`<bsdf type="...">`): its properties by name, in order.
#[derive(Clone, Debug)]
struct Obj {
    tag: String,
    ty: String,
    id: Option<String>,
    line: u32,
    /// The file it was written in (an `include`d one is not the scene's).
    file: PathBuf,
    props: Vec<(String, Prop, u32)>,
}

impl Obj {
    fn place(&self) -> String {
        format!("{}:{}", self.file.display(), self.line)
    }

    fn what(&self) -> String {
        format!("<{} type=\"{}\">", self.tag, self.ty)
    }

    fn take(&mut self, name: &str) -> Option<(Prop, u32)> {
        let i = self.props.iter().position(|(n, _, _)| n == name)?;
        let (_, p, line) = self.props.remove(i);
        Some((p, line))
    }

    fn error(&self, message: impl std::fmt::Display) -> Error {
        Error::Scene {
            location: Location {
                file: self.file.clone(),
                line: self.line,
                column: 1,
            },
            key: self.what(),
            message: message.to_string(),
        }
    }

    fn float(&mut self, name: &str, default: f64) -> Result<f64> {
        match self.take(name) {
            None => Ok(default),
            Some((Prop::Float(x), _)) => Ok(x),
            Some((Prop::Int(i), _)) => Ok(i as f64),
            Some((p, _)) => Err(self.error(format!("`{name}`: expected a number, found {p:?}"))),
        }
    }

    fn int(&mut self, name: &str, default: i64) -> Result<i64> {
        match self.take(name) {
            None => Ok(default),
            Some((Prop::Int(i), _)) => Ok(i),
            Some((p, _)) => Err(self.error(format!("`{name}`: expected an integer, found {p:?}"))),
        }
    }

    fn boolean(&mut self, name: &str, default: bool) -> Result<bool> {
        match self.take(name) {
            None => Ok(default),
            Some((Prop::Bool(b), _)) => Ok(b),
            Some((p, _)) => Err(self.error(format!("`{name}`: expected a boolean, found {p:?}"))),
        }
    }

    fn string(&mut self, name: &str) -> Result<Option<String>> {
        match self.take(name) {
            None => Ok(None),
            Some((Prop::Str(s), _)) => Ok(Some(s)),
            Some((p, _)) => Err(self.error(format!("`{name}`: expected a string, found {p:?}"))),
        }
    }

    /// A colour: `<rgb>`, a uniform `<spectrum>` or `<float>`.
    fn color(&mut self, name: &str, default: DVec3) -> Result<DVec3> {
        match self.take(name) {
            None => Ok(default),
            Some((Prop::Color(c), _)) => Ok(c),
            Some((Prop::Float(x), _)) => Ok(DVec3::splat(x)),
            Some((Prop::Int(i), _)) => Ok(DVec3::splat(i as f64)),
            Some((Prop::Object(o), _)) if o.tag == "texture" => Err(self.error(format!(
                "`{name}`: textures ({}) are not supported yet",
                o.what()
            ))),
            Some((p, _)) => Err(self.error(format!("`{name}`: expected a colour, found {p:?}"))),
        }
    }

    fn point(&mut self, name: &str) -> Result<Option<DVec3>> {
        match self.take(name) {
            None => Ok(None),
            Some((Prop::Point(p), _)) => Ok(Some(p)),
            Some((p, _)) => Err(self.error(format!("`{name}`: expected a point, found {p:?}"))),
        }
    }

    fn transform(&mut self, name: &str) -> Result<DMat4> {
        match self.take(name) {
            None => Ok(DMat4::IDENTITY),
            Some((Prop::Transform(m), _)) => Ok(m),
            Some((p, _)) => Err(self.error(format!("`{name}`: expected a transform, found {p:?}"))),
        }
    }
}

struct Reader {
    file: PathBuf,
    dir: PathBuf,
    defaults: HashMap<String, String>,
    /// Names set by -D (a `<default>` does not override them).
    defined: Vec<String>,
    lenient: bool,
    report: XmlReport,
    root: Table,
    shapes: Vec<Node>,
    lights: Vec<Node>,
    /// BSDF ids to their material names in `[materials]`.
    bsdfs: HashMap<String, String>,
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
    /// The `<default>`s declared.
    declared: HashSet<String>,
    /// The `<integrator>`, read last: which plugin renders a photon mapper depends on whether
    /// the scene has media.
    integrator: Option<Obj>,
}

/// Mitsuba's named indices of refraction (its documentation's table).
const IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

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

    /// Properties nobody read: Mitsuba parameters foton does not know.
    fn leftovers(&mut self, obj: &Obj) -> Result<()> {
        for (name, _, line) in obj.props.clone() {
            let o = Obj {
                line,
                ..obj.clone()
            };
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

    /// A `-D NAME=...` that no `<default>` declares and no `$NAME` uses is a typo.
    fn check_defines(&self, path: &Path) -> Result<()> {
        let used = self.used.borrow();
        for name in &self.defined {
            if !self.declared.contains(name) && !used.contains(name) {
                let known: Vec<&str> = self
                    .declared
                    .iter()
                    .chain(used.iter())
                    .map(String::as_str)
                    .collect();
                let mut sorted = known.clone();
                sorted.sort_unstable();
                sorted.dedup();
                return Err(Error::Usage(format!(
                    "-D {name}: {} never uses `${name}`{}; its parameters: {}",
                    path.display(),
                    foton_core::error::suggestion(name, known),
                    if sorted.is_empty() {
                        "none".to_string()
                    } else {
                        sorted.join(", ")
                    }
                )));
            }
        }
        Ok(())
    }

    fn note(&mut self, obj: &Obj, what: &str) {
        self.report
            .notes
            .push(format!("{}: {}: {what}", obj.place(), obj.what()));
    }

    fn read_file(&mut self, path: &Path, text: &str) -> Result<()> {
        let doc = roxmltree::Document::parse(text).map_err(|e| {
            let pos = e.pos();
            Error::XmlSyntax {
                location: Location {
                    file: path.to_path_buf(),
                    line: pos.row,
                    column: pos.col,
                },
                message: e.to_string(),
            }
        })?;
        let scene = doc.root_element();
        let is_main = path == self.file;
        let line_of = |n: roxmltree::Node<'_, '_>| {
            // Lines of an included file do not belong to the scene file's document.
            if is_main {
                doc.text_pos_at(n.range().start).row
            } else {
                0
            }
        };
        if scene.tag_name().name() != "scene" {
            return Err(syntax(
                path,
                line_of(scene),
                "the root element must be <scene>",
            ));
        }
        // Each file is upgraded by its own version, as Mitsuba 3 does with included files.
        let version = scene.attribute("version").ok_or_else(|| {
            syntax(
                path,
                line_of(scene),
                "<scene> without `version` (Mitsuba requires it, e.g. version=\"3.0.0\")",
            )
        })?;
        let major = version
            .split('.')
            .next()
            .and_then(|m| m.trim().parse::<u32>().ok())
            .filter(|m| *m <= 3)
            .ok_or_else(|| {
                syntax(
                    path,
                    line_of(scene),
                    &format!(
                        "<scene version=\"{version}\">: expected a Mitsuba version, 0.4.0 to 3.x"
                    ),
                )
            })?;
        let outer_v1 = std::mem::replace(&mut self.v1, major < 2);
        self.read_scene_children(path, scene, &line_of)?;
        self.v1 = outer_v1;
        Ok(())
    }

    fn read_scene_children(
        &mut self,
        path: &Path,
        scene: roxmltree::Node<'_, '_>,
        line_of: &dyn Fn(roxmltree::Node<'_, '_>) -> u32,
    ) -> Result<()> {
        for child in scene.children().filter(|n| n.is_element()) {
            let line = line_of(child);
            match child.tag_name().name() {
                "default" => {
                    let name = attr(child, "name", path, line)?;
                    let value = attr(child, "value", path, line)?;
                    self.declared.insert(name.clone());
                    if !self.defined.contains(&name) {
                        self.defaults.entry(name).or_insert(value);
                    }
                }
                "include" => {
                    let file = self.subst(&attr(child, "filename", path, line)?, path, line)?;
                    let inc = path.parent().unwrap_or(Path::new("")).join(file);
                    let text = std::fs::read_to_string(&inc).map_err(|e| Error::io(&inc, e))?;
                    self.report.included.push(inc.clone());
                    self.read_file(&inc, &text)?;
                }
                "alias" => {
                    let id = self.subst(&attr(child, "id", path, line)?, path, line)?;
                    let alias = self.subst(&attr(child, "as", path, line)?, path, line)?;
                    let mut found = false;
                    for map in [&mut self.bsdfs, &mut self.media] {
                        if let Some(name) = map.get(&id).cloned() {
                            map.insert(alias.clone(), name);
                            found = true;
                        }
                    }
                    if let Some(t) = self.textures.get(&id).cloned() {
                        self.textures.insert(alias.clone(), t);
                        found = true;
                    }
                    if !found {
                        return Err(syntax(
                            path,
                            line,
                            &format!(
                                "<alias id=\"{id}\">: no BSDF, medium or texture with that id before it"
                            ),
                        ));
                    }
                }
                "path" => {
                    return Err(syntax(
                        path,
                        line,
                        "<path> (a folder searched for files) is not supported: give file names relative to the scene",
                    ));
                }
                _ => {
                    let obj = self.object(child, path, line_of)?;
                    self.top_level(obj)?;
                }
            }
        }
        Ok(())
    }

    /// `$name` replaced by the default's value.
    fn subst(&self, s: &str, file: &Path, line: u32) -> Result<String> {
        let mut out = String::new();
        let mut rest = s;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let end = after
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..end];
            self.used.borrow_mut().insert(name.to_string());
            let value = self.defaults.get(name).ok_or_else(|| {
                syntax(
                    file,
                    line,
                    &format!("`${name}`: no <default name=\"{name}\"> and no -D {name}=..."),
                )
            })?;
            out.push_str(value);
            rest = &after[end..];
        }
        out.push_str(rest);
        Ok(out)
    }

    fn object(
        &self,
        n: roxmltree::Node<'_, '_>,
        file: &Path,
        line_of: &dyn Fn(roxmltree::Node<'_, '_>) -> u32,
    ) -> Result<Obj> {
        let line = line_of(n);
        let get = |name: &str| -> Result<Option<String>> {
            n.attribute(name)
                .map(|v| self.subst(v, file, line))
                .transpose()
        };
        let mut obj = Obj {
            tag: n.tag_name().name().to_string(),
            ty: get("type")?.unwrap_or_default(),
            id: get("id")?,
            line,
            file: file.to_path_buf(),
            props: Vec::new(),
        };
        for c in n.children().filter(|c| c.is_element()) {
            let cl = line_of(c);
            let cget = |name: &str| -> Result<Option<String>> {
                c.attribute(name)
                    .map(|v| self.subst(v, file, cl))
                    .transpose()
            };
            let name = cget("name")?.unwrap_or_default();
            let value =
                || cget("value")?.ok_or_else(|| syntax(file, cl, "missing attribute `value`"));
            let bad = |what: &str, v: &str| syntax(file, cl, &format!("`{name}`: {what} `{v}`"));
            let tag = c.tag_name().name();
            let prop = match tag {
                "float" => {
                    let v = value()?;
                    Prop::Float(v.trim().parse().map_err(|_| bad("not a number", &v))?)
                }
                "integer" => {
                    let v = value()?;
                    Prop::Int(v.trim().parse().map_err(|_| bad("not an integer", &v))?)
                }
                "boolean" => {
                    let v = value()?;
                    Prop::Bool(match v.trim() {
                        "true" => true,
                        "false" => false,
                        _ => return Err(bad("not true or false", &v)),
                    })
                }
                "string" => Prop::Str(value()?),
                "rgb" | "spectrum" => {
                    let v = value()?;
                    let xs = numbers(&v).ok_or_else(|| bad("not a list of numbers", &v))?;
                    match (tag, xs.len()) {
                        (_, 1) => Prop::Color(DVec3::splat(xs[0])),
                        ("rgb", 3) => Prop::Color(DVec3::new(xs[0], xs[1], xs[2])),
                        _ => {
                            return Err(bad(
                                "expected one value or three (r, g, b); wavelength:value spectra are not supported",
                                &v,
                            ));
                        }
                    }
                }
                "point" | "vector" => {
                    let p = match cget("value")? {
                        Some(v) => {
                            let xs = numbers(&v).ok_or_else(|| bad("not three numbers", &v))?;
                            if xs.len() != 3 {
                                return Err(bad("not three numbers", &v));
                            }
                            DVec3::new(xs[0], xs[1], xs[2])
                        }
                        None => {
                            let coord = |k: &str| -> Result<f64> {
                                cget(k)?.map_or(Ok(0.0), |v| {
                                    v.trim().parse().map_err(|_| bad("not a number", &v))
                                })
                            };
                            DVec3::new(coord("x")?, coord("y")?, coord("z")?)
                        }
                    };
                    Prop::Point(p)
                }
                "transform" => Prop::Transform(self.transform(c, file, line_of)?),
                "ref" => {
                    let id = cget("id")?.ok_or_else(|| syntax(file, cl, "<ref> without id"))?;
                    Prop::Ref(id)
                }
                // Mitsuba 0.6's sRGB colour: "#rrggbb" or numbers, both sRGB-encoded.
                "srgb" => {
                    let v = value()?;
                    let xs = match v.trim().strip_prefix('#') {
                        Some(hex) if hex.len() == 6 => (0..3)
                            .map(|i| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).ok())
                            .map(|x| x.map(|x| f64::from(x) / 255.0))
                            .collect::<Option<Vec<f64>>>(),
                        Some(_) => None,
                        None => numbers(&v),
                    }
                    .filter(|xs| xs.len() == 1 || xs.len() == 3)
                    .ok_or_else(|| bad("expected #rrggbb or one or three numbers", &v))?;
                    let c = if xs.len() == 1 {
                        DVec3::splat(xs[0])
                    } else {
                        DVec3::new(xs[0], xs[1], xs[2])
                    };
                    Prop::Color(DVec3::from_array(c.to_array().map(srgb_to_linear)))
                }
                "bsdf" | "emitter" | "medium" | "phase" | "texture" | "rfilter" | "sampler"
                | "film" | "shape" | "sensor" | "integrator" => {
                    Prop::Object(self.object(c, file, line_of)?)
                }
                other if KNOWN_UNREAD.contains(&other) => {
                    return Err(syntax(
                        file,
                        cl,
                        &format!("<{other}> in <{}> is not supported", obj.tag),
                    ));
                }
                other => {
                    let known = PROPERTY_TAGS.iter().chain(OBJECT_TAGS).copied();
                    return Err(syntax(
                        file,
                        cl,
                        &format!(
                            "unknown element <{other}> in <{}>{}",
                            obj.tag,
                            foton_core::error::suggestion(other, known)
                        ),
                    ));
                }
            };
            obj.props.push((name, prop, cl));
        }
        if self.v1 {
            upgrade_v1(&mut obj);
        }
        Ok(obj)
    }

    /// A `<transform>`'s operations, each applied after the ones before it.
    fn transform(
        &self,
        n: roxmltree::Node<'_, '_>,
        file: &Path,
        line_of: &dyn Fn(roxmltree::Node<'_, '_>) -> u32,
    ) -> Result<DMat4> {
        let mut m = DMat4::IDENTITY;
        for op in n.children().filter(|c| c.is_element()) {
            let l = line_of(op);
            let get = |name: &str| -> Result<Option<String>> {
                op.attribute(name)
                    .map(|v| self.subst(v, file, l))
                    .transpose()
            };
            let bad = |v: &str| {
                syntax(
                    file,
                    l,
                    &format!("<{}>: bad value `{v}`", op.tag_name().name()),
                )
            };
            let num = |name: &str, default: f64| -> Result<f64> {
                get(name)?.map_or(Ok(default), |v| v.trim().parse().map_err(|_| bad(&v)))
            };
            let xyz = |default: f64| -> Result<DVec3> {
                match get("value")? {
                    Some(v) => {
                        let xs = numbers(&v).ok_or_else(|| bad(&v))?;
                        match xs.len() {
                            1 => Ok(DVec3::splat(xs[0])),
                            3 => Ok(DVec3::new(xs[0], xs[1], xs[2])),
                            _ => Err(bad(&v)),
                        }
                    }
                    None => Ok(DVec3::new(
                        num("x", default)?,
                        num("y", default)?,
                        num("z", default)?,
                    )),
                }
            };
            let vec = |name: &str| -> Result<DVec3> {
                let v = get(name)?
                    .ok_or_else(|| syntax(file, l, &format!("<lookat> without `{name}`")))?;
                let xs = numbers(&v)
                    .filter(|x| x.len() == 3)
                    .ok_or_else(|| bad(&v))?;
                Ok(DVec3::new(xs[0], xs[1], xs[2]))
            };
            let step = match op.tag_name().name() {
                "translate" => DMat4::from_translation(xyz(0.0)?),
                "scale" => DMat4::from_scale(xyz(1.0)?),
                "rotate" => {
                    let axis = xyz(0.0)?;
                    if axis.length_squared() == 0.0 {
                        return Err(syntax(file, l, "<rotate> about the zero vector"));
                    }
                    DMat4::from_axis_angle(axis.normalize(), num("angle", 0.0)?.to_radians())
                }
                "matrix" => {
                    let v = get("value")?.ok_or_else(|| bad(""))?;
                    let xs = numbers(&v).ok_or_else(|| bad(&v))?;
                    match xs.len() {
                        16 => DMat4::from_cols_slice(&xs).transpose(),
                        9 => DMat4::from_mat3(glam::DMat3::from_cols_slice(&xs).transpose()),
                        _ => return Err(bad(&v)),
                    }
                }
                "lookat" => {
                    let (origin, target) = (vec("origin")?, vec("target")?);
                    let dir = (target - origin).normalize();
                    // Without `up` (or with a zero one), Mitsuba completes the direction to
                    // an orthonormal basis (its coordinate_system) and takes the first vector.
                    let up = match get("up")? {
                        Some(_) => vec("up")?,
                        None => DVec3::ZERO,
                    };
                    let up = if up == DVec3::ZERO && dir.is_finite() {
                        coordinate_system(dir).0
                    } else {
                        up
                    };
                    let left = up.cross(dir).normalize();
                    if !dir.is_finite() || !left.is_finite() {
                        return Err(syntax(
                            file,
                            l,
                            "<lookat>: degenerate origin, target and up",
                        ));
                    }
                    let new_up = dir.cross(left);
                    DMat4::from_cols(
                        left.extend(0.0),
                        new_up.extend(0.0),
                        dir.extend(0.0),
                        origin.extend(1.0),
                    )
                }
                other => {
                    let ops = ["translate", "scale", "rotate", "matrix", "lookat"];
                    return Err(syntax(
                        file,
                        l,
                        &format!(
                            "unknown transform operation <{other}>{}",
                            foton_core::error::suggestion(other, ops)
                        ),
                    ));
                }
            };
            m = step * m;
        }
        Ok(m)
    }

    /// The sensor's medium is the camera's. When no shape names a medium, Mitsuba's scene is
    /// that medium everywhere (every ray stays in the camera's medium), which is foton's
    /// scene medium; otherwise the shapes say where each medium is.
    fn place_sensor_medium(&mut self) {
        let Some((name, line)) = self.sensor_medium.take() else {
            return;
        };
        table_mut(&mut self.root, "camera").insert("medium", at(Value::Str(name.clone()), line));
        if !self.shape_media {
            table_mut(&mut self.root, "scene").insert("medium", at(Value::Str(name), line));
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
            "sensor" => self.sensor(obj),
            "bsdf" => self.bsdf(obj).map(|_| ()),
            "medium" => self.medium(obj).map(|_| ()),
            "shape" => self.shape(obj),
            "emitter" => self.emitter(obj),
            "texture" => {
                let id = obj.id.clone();
                let Some(t) = self.texture_table(obj)? else {
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

    /// Mitsuba's integrator: the foton plugin that renders it, its parameters translated
    /// (each one foton has no equivalent for is a warning). Read after the rest of the scene.
    fn integrator(&mut self, mut o: Obj) -> Result<()> {
        // Mitsuba 3 reads integrators' names as written; 0.6 files are upgraded. Accept the
        // 0.6 spelling in either (older exporters mix them).
        for (name, _, _) in &mut o.props {
            *name = camel_to_snake(name);
        }
        let has_media = !self.media.is_empty();
        let Some(name) = foton_integrator(&o.ty, has_media) else {
            o.props.clear();
            let message = if MITSUBA_INTEGRATORS.contains(&o.ty.as_str()) {
                format!(
                    "integrator `{}` is not supported; foton renders path, volpath, volpath_simple, volpathmis, direct, photonmapper, sppm, ppm and bdpt",
                    o.ty
                )
            } else {
                format!(
                    "unknown integrator `{}`{}",
                    o.ty,
                    foton_core::error::suggestion(&o.ty, MITSUBA_INTEGRATORS.iter().copied())
                )
            };
            return self.unsupported(&o, &message);
        };
        let line = o.line;
        table_mut(&mut self.root, "render").insert("integrator", at(Value::Str(name.into()), line));
        if o.ty == "ppm" {
            self.note(
                &o,
                "rendered by sppm (the stochastic variant of progressive photon mapping converges to the same image)",
            );
        }
        // Mitsuba's max_depth counts path segments (1: emitters seen directly, 2: direct
        // light); foton's counts scattering events, one less. -1 is unbounded in both
        // Mitsubas: a cap no path reaches (Russian roulette ends them long before).
        let max_depth = if o.ty == "direct" {
            2
        } else {
            o.int("max_depth", -1)?
        };
        let bounces = match max_depth {
            -1 => 65_536,
            d if d >= 1 => d - 1,
            d => {
                return Err(o.error(format!(
                    "max_depth = {d}: renders nothing (1 is emitters seen directly, -1 unbounded)"
                )));
            }
        };
        table_mut(&mut self.root, "render").insert("max_depth", at(Value::Int(bounces), line));
        if o.boolean("hide_emitters", false)? {
            table_mut(&mut self.root, "render")
                .insert("hide_emitters", at(Value::Bool(true), line));
        }
        let mut params: Vec<(&str, Value)> = Vec::new();
        let rr = o.take("rr_depth");
        match name {
            "path" | "bdpt" => {
                // Mitsuba starts Russian roulette at path depth rr_depth (segments, 5 unless
                // the file says): foton counts scattering events.
                if let Some((p, l)) = rr {
                    o.props.push(("rr_depth".into(), p, l));
                }
                let rr = o.int("rr_depth", 5)?;
                params.push(("rr_depth", Value::Int(rr.max(1) - 1)));
            }
            _ => {
                if let Some((p, l)) = rr {
                    self.warn(
                        &o,
                        l,
                        &format!(
                            "`rr_depth` = {}: ignored ({name} traces photons with its own Russian roulette)",
                            show(&p)
                        ),
                    );
                }
            }
        }
        let same = |_: &Prop| false;
        self.ignored(
            &mut o,
            "strict_normals",
            &|p| matches!(p, Prop::Bool(false)),
            "ignored (foton does not end paths whose shading and geometric normals disagree)",
        );
        let noise = "ignored (it changes the noise, not the image: foton takes one sample per camera sample; raise spp)";
        match o.ty.as_str() {
            "direct" => {
                for k in ["emitter_samples", "bsdf_samples", "shading_samples"] {
                    self.ignored(&mut o, k, &same, noise);
                }
            }
            "photonmapper" => {
                // Mitsuba 0.6's defaults, written out: the budgets and k are its meaning.
                let photons = |o: &mut Obj, k: &str| o.int(k, 250_000);
                params.push((
                    "global_photons",
                    Value::Int(photons(&mut o, "global_photons")?),
                ));
                params.push((
                    "caustic_photons",
                    Value::Int(photons(&mut o, "caustic_photons")?),
                ));
                let volume = photons(&mut o, "volume_photons")?;
                let lookup = o.int("lookup_size", 120)?;
                let k = o.int("global_lookup_size", lookup)?;
                params.push(("k", Value::Int(k)));
                let kc = o.int("caustic_lookup_size", lookup)?;
                if kc != k {
                    let why = format!(
                        "`caustic_lookup_size` = {kc}: foton's photon maps share one k ({k}, the global lookup size)"
                    );
                    self.warn(&o, line, &why);
                }
                let kv = o.int("volume_lookup_size", lookup)?;
                if name == "vpm" {
                    params.push(("volume_photons", Value::Int(volume)));
                    params.push(("k_volume", Value::Int(kv)));
                }
                // Mitsuba's lookup radii are fractions of the bounding sphere's radius.
                let rg = o.float("global_lookup_radius", 0.05)?;
                self.report.relative_radius = Some((name.to_string(), rg, line));
                if let Some((p, l)) = o.take("caustic_lookup_radius") {
                    let why = format!(
                        "`caustic_lookup_radius` = {}: foton's photon maps share one largest radius (the global lookup radius)",
                        show(&p)
                    );
                    self.warn(&o, l, &why);
                }
                for k in ["direct_samples", "glossy_samples"] {
                    self.ignored(&mut o, k, &same, noise);
                }
                self.ignored(
                    &mut o,
                    "max_specular_depth",
                    &same,
                    "ignored (foton follows specular bounces up to max_depth)",
                );
                for k in ["granularity", "gather_locally", "auto_cancel_gathering"] {
                    self.ignored(&mut o, k, &|_| true, "");
                }
            }
            "sppm" | "ppm" => {
                if let Some(n) = o
                    .take("photon_count")
                    .or_else(|| o.take("photons_per_iteration"))
                {
                    o.props.push(("photon_count".into(), n.0, n.1));
                    params.push((
                        "photons_per_iteration",
                        Value::Int(o.int("photon_count", 250_000)?),
                    ));
                }
                // 0 (Mitsuba's default): a radius guessed from the scene, as foton's is.
                let r = o.float("initial_radius", 0.0)?;
                if r > 0.0 {
                    params.push(("initial_radius", Value::Float(r)));
                }
                if let Some((p, l)) = o.take("alpha") {
                    o.props.push(("alpha".into(), p, l));
                    params.push(("alpha", Value::Float(o.float("alpha", 0.7)?)));
                }
                let passes = match o.take("passes").or_else(|| o.take("max_passes")) {
                    Some((p, l)) => {
                        o.props.push(("passes".into(), p, l));
                        Some((o.int("passes", -1)?, l))
                    }
                    None => None,
                };
                match passes {
                    Some((n, _)) if n >= 1 => params.push(("iterations", Value::Int(n))),
                    Some((n, l)) => {
                        let why = format!(
                            "passes = {n} (until stopped): foton runs its default number of iterations; give integrators.sppm.iterations or time"
                        );
                        self.warn(&o, l, &why);
                    }
                    None => {}
                }
                for k in ["granularity", "auto_cancel_gathering", "samples_per_pass"] {
                    self.ignored(&mut o, k, &|_| true, "");
                }
            }
            "bdpt" => {
                // lightImage = false: no strategy connects light paths to the camera.
                if !o.boolean("light_image", true)? {
                    params.push(("light_image", Value::Bool(false)));
                }
                // sampleDirect changes how often next-event strategies are taken, not the
                // image: foton's bdpt takes every strategy once per camera sample.
                self.ignored(
                    &mut o,
                    "sample_direct",
                    &|p| matches!(p, Prop::Bool(true)),
                    "ignored",
                );
            }
            _ => {}
        }
        let t = table_mut(table_mut(&mut self.root, "integrators"), name);
        for (k, v) in params {
            t.insert(k, at(v, line));
        }
        self.leftovers(&o)
    }

    fn sensor(&mut self, mut o: Obj) -> Result<()> {
        if o.ty != "perspective" {
            o.props.clear();
            let m = not_read("sensor", &o.ty, "only the perspective sensor is supported");
            return self.unsupported(&o, &m);
        }
        let line = o.line;
        let m = o.transform("to_world")?;
        let position = m.transform_point3(DVec3::ZERO);
        let dir = m.transform_vector3(DVec3::Z).normalize();
        let up = m.transform_vector3(DVec3::Y).normalize();
        let left = m.transform_vector3(DVec3::X);
        if left.dot(up.cross(dir)) <= 0.0 {
            self.unsupported(
                &o,
                "a sensor to_world that mirrors the image is not supported",
            )?;
        }
        let has_fov = o.props.iter().any(|(n, _, _)| n == "fov");
        let (fov, fov_axis) = if has_fov {
            if o.props.iter().any(|(n, _, _)| n == "focal_length") {
                return Err(o.error("give either `fov` or `focal_length`, not both"));
            }
            let fov = o.float("fov", 45.0)?;
            (fov, o.string("fov_axis")?.unwrap_or_else(|| "x".into()))
        } else {
            // Mitsuba's default: a focal length on 35 mm film (36 x 24 mm), whose diagonal
            // field of view is 2 atan(43.27 / 2f).
            let f = o.string("focal_length")?.unwrap_or_else(|| "50mm".into());
            let mm: f64 = f
                .strip_suffix("mm")
                .unwrap_or(&f)
                .trim()
                .parse()
                .ok()
                .filter(|x: &f64| *x > 0.0)
                .ok_or_else(|| {
                    o.error(format!(
                        "`focal_length` = {f:?}: expected a positive length in millimetres, such as \"50mm\""
                    ))
                })?;
            let diagonal = (36.0f64 * 36.0 + 24.0 * 24.0).sqrt();
            let fov = 2.0 * (diagonal / (2.0 * mm)).atan().to_degrees();
            o.take("fov_axis");
            (fov, "diagonal".to_string())
        };
        // A pinhole: the clip planes and focus distance change nothing foton renders.
        for ignored in ["near_clip", "far_clip", "focus_distance"] {
            o.take(ignored);
        }
        let camera = table_mut(&mut self.root, "camera");
        camera.insert("position", vec3(position, line));
        camera.insert("look_at", vec3(position + dir, line));
        camera.insert("up", vec3(up, line));
        camera.insert("fov", at(Value::Float(fov), line));
        camera.insert("fov_axis", at(Value::Str(fov_axis), line));
        if let Some((Prop::Ref(id), l)) = o.take("medium") {
            let name = self.media.get(&id).cloned().ok_or_else(|| {
                o.error(format!("medium `{id}` is not defined (before line {l})"))
            })?;
            self.sensor_medium = Some((name, l));
        }
        let nested: Vec<Obj> = o
            .props
            .iter()
            .filter_map(|(_, p, _)| match p {
                Prop::Object(c) => Some(c.clone()),
                _ => None,
            })
            .collect();
        o.props.retain(|(_, p, _)| !matches!(p, Prop::Object(_)));
        for child in nested {
            match child.tag.as_str() {
                "film" => self.film(child)?,
                "sampler" => self.sampler(child)?,
                "medium" => {
                    let l = child.line;
                    let name = self.medium(child)?;
                    self.sensor_medium = Some((name, l));
                }
                _ => {
                    let mut c = child;
                    c.props.clear();
                    self.unsupported(&c, "not supported inside a sensor")?;
                }
            }
        }
        self.leftovers(&o)
    }

    fn film(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        let ldr = match o.ty.as_str() {
            "hdrfilm" | "tiledhdrfilm" => false,
            "ldrfilm" => true,
            _ => {
                o.props.clear();
                return self.unsupported(
                    &o,
                    &not_read(
                        "film",
                        &o.ty,
                        "this film is not supported; foton reads hdrfilm and ldrfilm",
                    ),
                );
            }
        };
        let width = o.int("width", 768)?;
        let height = o.int("height", 576)?;
        if ldr {
            self.ldr_film(&mut o)?;
        } else {
            let exr = |p: &Prop| matches!(p, Prop::Str(s) if s == "openexr" || s == "exr");
            self.ignored(&mut o, "file_format", &exr, "foton writes OpenEXR");
            let f32 = |p: &Prop| matches!(p, Prop::Str(s) if s == "float32");
            self.ignored(
                &mut o,
                "component_format",
                &f32,
                "foton writes 32-bit floats",
            );
        }
        let rgb = |p: &Prop| matches!(p, Prop::Str(s) if s == "rgb");
        self.ignored(&mut o, "pixel_format", &rgb, "foton writes RGB");
        let no = |p: &Prop| matches!(p, Prop::Bool(false));
        self.ignored(&mut o, "banner", &no, "foton draws no banner");
        self.ignored(
            &mut o,
            "high_quality_edges",
            &no,
            "ignored (pixels at the border are filtered as inside)",
        );
        self.ignored(&mut o, "attach_log", &|_| true, "");
        o.take("sample_border");
        let film = table_mut(&mut self.root, "film");
        film.insert("width", at(Value::Int(width), line));
        film.insert("height", at(Value::Int(height), line));
        // Mitsuba's default reconstruction filter is Gaussian (stddev 0.5).
        let mut filter = Table::default();
        let mut rf_line = line;
        match o.take("") {
            Some((Prop::Object(mut rf), l)) if rf.tag == "rfilter" => {
                rf_line = l;
                filter.insert("type", at(Value::Str(rf.ty.clone()), l));
                match rf.ty.as_str() {
                    "box" => {}
                    "tent" => {
                        let r = rf.float("radius", 1.0)?;
                        filter.insert("radius", at(Value::Float(r), l));
                    }
                    "gaussian" => {
                        let s = rf.float("stddev", 0.5)?;
                        filter.insert("stddev", at(Value::Float(s), l));
                    }
                    _ => {
                        rf.props.clear();
                        let m = not_read(
                            "rfilter",
                            &rf.ty,
                            "foton's filters are box, tent and gaussian",
                        );
                        self.unsupported(&rf, &m)?;
                        filter = Table::default();
                    }
                }
                self.leftovers(&rf)?;
            }
            Some((other, l)) => {
                o.props.push((String::new(), other, l));
            }
            None => {
                filter.insert("type", at(Value::Str("gaussian".into()), line));
                filter.insert("stddev", at(Value::Float(0.5), line));
            }
        }
        if filter.get("type").is_some() {
            table_mut(&mut self.root, "film").insert("filter", at(Value::Table(filter), rf_line));
        }
        self.leftovers(&o)
    }

    fn sampler(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        let Some((sampler, exact)) = foton_sampler(&o.ty) else {
            let known = [
                "independent",
                "stratified",
                "multijitter",
                "orthogonal",
                "ldsampler",
                "sobol",
                "halton",
                "hammersley",
            ];
            return Err(o.error(format!(
                "unknown sampler `{}`{}",
                o.ty,
                foton_core::error::suggestion(&o.ty, known)
            )));
        };
        if !exact {
            self.warn(
                &o,
                line,
                &format!(
                    "foton samples with `{sampler}` (the same image, other noise) instead of `{}`",
                    o.ty
                ),
            );
        }
        let spp = o.int("sample_count", 4)?;
        let render = table_mut(&mut self.root, "render");
        render.insert("spp", at(Value::Int(spp), line));
        render.insert("sampler", at(Value::Str(sampler.into()), line));
        let seed = o.int("seed", 0)?;
        table_mut(&mut self.root, "render").insert("seed", at(Value::Int(seed), line));
        if sampler == "stratified" {
            let jitter = o.boolean("jitter", true)?;
            table_mut(&mut self.root, "render").insert("jitter", at(Value::Bool(jitter), line));
        }
        // The other patterns' options go with the pattern (warned about above); Sobol's
        // scrambling is always Owen's.
        for ignored in ["jitter", "scramble", "dimension", "resolution"] {
            o.take(ignored);
        }
        self.leftovers(&o)
    }

    /// Mitsuba 0.6's `ldrfilm`: a PNG through foton's exposure and tone curve (the sRGB
    /// curve; `gamma` = 2.2 is close to it, a note; another gamma a warning).
    fn ldr_film(&mut self, o: &mut Obj) -> Result<()> {
        let line = o.line;
        let png = |p: &Prop| matches!(p, Prop::Str(s) if s == "png");
        self.ignored(o, "file_format", &png, "foton writes a PNG");
        let stem = self
            .file
            .file_stem()
            .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
        let film = table_mut(&mut self.root, "film");
        film.insert("output", at(Value::Str(format!("{stem}.png")), line));
        let exposure = o.float("exposure", 0.0)?;
        if exposure != 0.0 {
            table_mut(&mut self.root, "film").insert("exposure", at(Value::Float(exposure), line));
        }
        if let Some((p, l)) = o.take("gamma") {
            match p {
                Prop::Float(-1.0) => {}
                Prop::Float(g) if (g - 2.2).abs() < 1e-6 => self.note(
                    o,
                    "gamma 2.2 is written with the sRGB curve, which differs from it by at most 3.4% of white (in the darkest tones)",
                ),
                other => self.warn(
                    o,
                    l,
                    &format!("`gamma` = {}: foton writes the sRGB curve", show(&other)),
                ),
            }
        }
        let method = o
            .string("tonemap_method")?
            .unwrap_or_else(|| "gamma".into());
        match method.as_str() {
            "gamma" => {}
            "reinhard" => self.warn(
                o,
                line,
                "`tonemap_method` = \"reinhard\": foton's tone curves are clamp (used) and filmic",
            ),
            other => {
                return Err(o.error(format!(
                    "`tonemap_method` = {other:?}: expected gamma or reinhard"
                )));
            }
        }
        for k in ["key", "burn"] {
            self.ignored(
                o,
                k,
                &|_| false,
                "ignored (a parameter of Reinhard's tone mapping)",
            );
        }
        Ok(())
    }

    fn new_name(&mut self, prefix: &str, id: &Option<String>) -> String {
        id.clone().unwrap_or_else(|| {
            self.anonymous += 1;
            format!("{prefix}_{}", self.anonymous)
        })
    }

    /// A BSDF into `[materials]`; returns its name there (None if left out).
    fn bsdf(&mut self, mut o: Obj) -> Result<Option<String>> {
        let line = o.line;
        let mut t = Table::default();
        let mut put = |k: &str, v: Value| t.insert(k, at(v, line));
        match o.ty.as_str() {
            "twosided" => {
                let inner = o
                    .props
                    .iter()
                    .position(|(_, p, _)| matches!(p, Prop::Object(_)));
                let Some(i) = inner else {
                    return Err(o.error("a twosided BSDF without the BSDF it wraps"));
                };
                let (_, Prop::Object(mut inner), _) = o.props.remove(i) else {
                    unreachable!()
                };
                if inner.id.is_none() {
                    inner.id = o.id.clone();
                }
                self.leftovers(&o)?;
                let name = self.bsdf(inner)?;
                // The same BSDF on both sides: diffuse's own switch (the others are two-sided
                // or have no sides).
                if let Some(Value::Table(t)) = name
                    .as_deref()
                    .and_then(|n| table_mut(&mut self.root, "materials").get_mut(n))
                    .map(|n| &mut n.value)
                    && t.get("twosided").is_some()
                {
                    t.insert("twosided", at(Value::Bool(true), line));
                }
                return Ok(name);
            }
            "diffuse" => {
                put("type", Value::Str("diffuse".into()));
                let Some(c) = self.texture(&mut o, "reflectance", DVec3::splat(0.5))? else {
                    return Ok(None);
                };
                t.insert("reflectance", c);
                // Mitsuba's BSDFs are one-sided unless wrapped in `twosided`.
                t.insert("twosided", at(Value::Bool(false), line));
            }
            "dielectric" | "thindielectric" => {
                put("type", Value::Str(o.ty.clone()));
                let int = self.ior(&mut o, "int_ior", 1.5046)?;
                let ext = self.ior(&mut o, "ext_ior", 1.000277)?;
                t.insert("ior", at(Value::Float(int / ext), line));
                for k in ["specular_reflectance", "specular_transmittance"] {
                    if o.color(k, DVec3::ONE)? != DVec3::ONE {
                        self.unsupported(&o, &format!("`{k}` other than 1 is not supported yet"))?;
                    }
                }
            }
            "conductor" | "roughconductor" => {
                put("type", Value::Str(o.ty.clone()));
                if o.ty == "roughconductor" {
                    self.microfacet(&mut o, &mut t, true)?;
                    // Mitsuba's BSDFs are one-sided unless wrapped in `twosided`.
                    t.insert("twosided", at(Value::Bool(false), line));
                }
                let material = o.string("material")?;
                let (eta, k) = (o.take("eta"), o.take("k"));
                match (eta, k) {
                    (None, None) => {
                        let name = material.unwrap_or_else(|| "none".into());
                        if name != "none" && foton_core::material::conductor(&name).is_none() {
                            return Err(o.error(format!("`material`: unknown conductor `{name}`")));
                        }
                        t.insert("material", at(Value::Str(name), line));
                    }
                    (Some((eta, l1)), Some((k, l2))) => {
                        o.props.push(("eta".into(), eta, l1));
                        o.props.push(("k".into(), k, l2));
                        let (eta, k) = (o.color("eta", DVec3::ONE)?, o.color("k", DVec3::ZERO)?);
                        // Mitsuba 0.6's index of the outside: the Fresnel terms take eta / ext.
                        let ext = self.ior(&mut o, "ext_eta", 1.0)?;
                        t.insert("eta", vec3(eta / ext, line));
                        t.insert("k", vec3(k / ext, line));
                    }
                    _ => {
                        return Err(
                            o.error("a conductor needs both `eta` and `k`, or a `material`")
                        );
                    }
                }
                let Some(c) = self.texture(&mut o, "specular_reflectance", DVec3::ONE)? else {
                    return Ok(None);
                };
                t.insert("specular_reflectance", c);
            }
            "roughdielectric" => {
                put("type", Value::Str("roughdielectric".into()));
                self.microfacet(&mut o, &mut t, true)?;
                let int = self.ior(&mut o, "int_ior", 1.5046)?;
                let ext = self.ior(&mut o, "ext_ior", 1.000277)?;
                t.insert("ior", at(Value::Float(int / ext), line));
                for k in ["specular_reflectance", "specular_transmittance"] {
                    let Some(c) = self.texture(&mut o, k, DVec3::ONE)? else {
                        return Ok(None);
                    };
                    t.insert(k, c);
                }
            }
            "plastic" | "roughplastic" => {
                put("type", Value::Str(o.ty.clone()));
                if o.ty == "roughplastic" {
                    self.microfacet(&mut o, &mut t, false)?;
                }
                let int = self.ior(&mut o, "int_ior", 1.49)?;
                let ext = self.ior(&mut o, "ext_ior", 1.000277)?;
                t.insert("ior", at(Value::Float(int / ext), line));
                for (k, default) in [("diffuse_reflectance", 0.5), ("specular_reflectance", 1.0)] {
                    let Some(c) = self.texture(&mut o, k, DVec3::splat(default))? else {
                        return Ok(None);
                    };
                    t.insert(k, c);
                }
                let nonlinear = o.boolean("nonlinear", false)?;
                t.insert("nonlinear", at(Value::Bool(nonlinear), line));
                t.insert("twosided", at(Value::Bool(false), line));
            }
            "null" => put("type", Value::Str("null".into())),
            _ => {
                o.props.clear();
                let m = not_read("bsdf", &o.ty, "this BSDF is not supported yet");
                self.unsupported(&o, &m)?;
                return Ok(None);
            }
        }
        self.leftovers(&o)?;
        let name = self.new_name("bsdf", &o.id);
        if let Some(id) = &o.id {
            self.bsdfs.insert(id.clone(), name.clone());
        }
        table_mut(&mut self.root, "materials").insert(&name, at(Value::Table(t), line));
        Ok(Some(name))
    }

    /// A colour parameter that may be a texture (`<texture name="...">` inside, or a `<ref>` to
    /// a top-level one): an RGB array or the texture's inline table for the TOML material.
    /// None: a texture left out (lenient).
    fn texture(&mut self, o: &mut Obj, name: &str, default: DVec3) -> Result<Option<Node>> {
        let line = o.line;
        match o.take(name) {
            Some((Prop::Object(t), _)) if t.tag == "texture" => {
                Ok(self.texture_table(t)?.map(|t| at(Value::Table(t), line)))
            }
            Some((Prop::Ref(id), l)) => match self.textures.get(&id) {
                Some(t) => Ok(Some(at(Value::Table(t.clone()), line))),
                None => Err(o.error(format!(
                    "`{name}`: line {l}: no texture with id `{id}` before it"
                ))),
            },
            Some((p, l)) => {
                o.props.push((name.to_string(), p, l));
                Ok(Some(vec3(o.color(name, default)?, line)))
            }
            None => Ok(Some(vec3(default, line))),
        }
    }

    /// The element's required `filename`, relative to the XML file, as the TOML document's
    /// path (relative to the main scene's folder, or absolute).
    fn filename(&self, o: &mut Obj) -> Result<Node> {
        let file = o
            .string("filename")?
            .ok_or_else(|| o.error("missing `filename`"))?;
        let path = o.file.parent().unwrap_or(Path::new("")).join(&file);
        let rel = path
            .strip_prefix(&self.dir)
            .map_or(path.clone(), Path::to_path_buf);
        Ok(at(Value::Str(rel.to_string_lossy().into_owned()), o.line))
    }

    /// A `<texture>` as the inline table foton's materials take (docs/scene-format.md):
    /// Mitsuba's `bitmap` (filename, raw, filter_type, wrap_mode, to_uv) and `checkerboard`
    /// (color0, color1, to_uv). None: left out (lenient).
    fn texture_table(&mut self, mut o: Obj) -> Result<Option<Table>> {
        let line = o.line;
        let mut t = Table::default();
        t.insert("type", at(Value::Str(o.ty.clone()), line));
        match o.ty.as_str() {
            "bitmap" => {
                t.insert("filename", self.filename(&mut o)?);
                if o.boolean("raw", false)? {
                    t.insert("raw", at(Value::Bool(true), line));
                }
                for key in ["filter_type", "wrap_mode"] {
                    if let Some(v) = o.string(key)? {
                        t.insert(key, at(Value::Str(v), line));
                    }
                }
                // Storage format and value clamping change nothing foton renders.
                o.take("format");
                o.take("accel");
            }
            "checkerboard" => {
                for (key, default) in [("color0", 0.4), ("color1", 0.2)] {
                    let c = o.color(key, DVec3::splat(default))?;
                    t.insert(key, vec3(c, line));
                }
            }
            _ => {
                o.props.clear();
                let m = not_read("texture", &o.ty, "this texture is not supported yet");
                self.unsupported(&o, &m)?;
                return Ok(None);
            }
        }
        let m = o.transform("to_uv")?;
        if m != DMat4::IDENTITY {
            t.insert("to_uv", matrix_table(m, line));
        }
        self.leftovers(&o)?;
        Ok(Some(t))
    }

    /// A microfacet BSDF's `distribution` and `alpha` (or, if `anisotropic`, `alpha_u` and
    /// `alpha_v`), Mitsuba's defaults written out. Visible-normal sampling is foton's only
    /// sampling: `sample_visible` changes noise, not the image.
    fn microfacet(&mut self, o: &mut Obj, t: &mut Table, anisotropic: bool) -> Result<()> {
        let line = o.line;
        let distribution = o
            .string("distribution")?
            .unwrap_or_else(|| "beckmann".into());
        if distribution != "beckmann" && distribution != "ggx" {
            return Err(o.error(format!(
                "`distribution`: unknown {distribution:?}; expected beckmann or ggx"
            )));
        }
        t.insert("distribution", at(Value::Str(distribution), line));
        o.take("sample_visible");
        let has = |o: &Obj, k: &str| o.props.iter().any(|(n, _, _)| n == k);
        if anisotropic && (has(o, "alpha_u") || has(o, "alpha_v")) {
            let u = o.float("alpha_u", 0.1)?;
            let v = o.float("alpha_v", 0.1)?;
            t.insert("alpha_u", at(Value::Float(u), line));
            t.insert("alpha_v", at(Value::Float(v), line));
        } else {
            let a = o.float("alpha", 0.1)?;
            t.insert("alpha", at(Value::Float(a), line));
        }
        Ok(())
    }

    fn ior(&mut self, o: &mut Obj, name: &str, default: f64) -> Result<f64> {
        match o.take(name) {
            None => Ok(default),
            Some((Prop::Float(x), _)) => Ok(x),
            Some((Prop::Str(s), _)) => IORS
                .iter()
                .find(|(n, _)| *n == s.to_lowercase())
                .map(|(_, v)| *v)
                .ok_or_else(|| {
                    o.error(format!(
                        "`{name}`: unknown material `{s}`; known: {}",
                        IORS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
                    ))
                }),
            Some((p, _)) => Err(o.error(format!(
                "`{name}`: expected a number or a name, found {p:?}"
            ))),
        }
    }

    /// A medium into `[media]`; returns its name there.
    fn medium(&mut self, mut o: Obj) -> Result<String> {
        if o.ty != "homogeneous" {
            return Err(o.error(not_read(
                "medium",
                &o.ty,
                "only homogeneous media are supported",
            )));
        }
        let line = o.line;
        let has = |o: &Obj, k: &str| o.props.iter().any(|(n, _, _)| n == k);
        if has(&o, "material") {
            return Err(o.error("`material` (Mitsuba 0.6's measured media) is not supported: give sigma_s and sigma_a"));
        }
        // Mitsuba 0.6 writes a medium as sigma_s and sigma_a or as sigma_t and albedo (Mitsuba
        // 3 only the latter, and its upgrade drops the former: foton keeps them).
        let (sigma_s, sigma_a) = if has(&o, "sigma_s") || has(&o, "sigma_a") {
            if has(&o, "sigma_t") || has(&o, "albedo") {
                return Err(o.error("give sigma_s and sigma_a, or sigma_t and albedo, not both"));
            }
            (
                o.color("sigma_s", DVec3::ONE)?,
                o.color("sigma_a", DVec3::ONE)?,
            )
        } else {
            let sigma_t = o.color("sigma_t", DVec3::ONE)?;
            let albedo = o.color("albedo", DVec3::splat(0.75))?;
            (sigma_t * albedo, sigma_t * (DVec3::ONE - albedo))
        };
        // Mitsuba 0.6 calls the scale density_multiplier.
        let scale = o.float("density_multiplier", 1.0)?;
        let scale = o.float("scale", scale)?;
        // Whether a medium samples emitters changes noise, not the image.
        o.take("sample_emitters");
        let mut t = Table::default();
        t.insert("type", at(Value::Str("homogeneous".into()), line));
        t.insert("sigma_s", vec3(sigma_s * scale, line));
        t.insert("sigma_a", vec3(sigma_a * scale, line));
        if let Some((Prop::Object(mut phase), l)) = o.take("") {
            match phase.ty.as_str() {
                "isotropic" => t.insert("phase", at(Value::Str("isotropic".into()), l)),
                "hg" => {
                    // Mitsuba 0.6's default g is 0, Mitsuba 3's 0.8.
                    let g = phase.float("g", if self.v1 { 0.0 } else { 0.8 })?;
                    let mut p = Table::default();
                    p.insert("type", at(Value::Str("hg".into()), l));
                    p.insert("g", at(Value::Float(g), l));
                    t.insert("phase", at(Value::Table(p), l));
                }
                _ => {
                    let m = not_read(
                        "phase",
                        &phase.ty,
                        "foton's phase functions are isotropic and hg",
                    );
                    return Err(phase.error(m));
                }
            }
            self.leftovers(&phase)?;
        }
        self.leftovers(&o)?;
        let name = self.new_name("medium", &o.id);
        if let Some(id) = &o.id {
            self.media.insert(id.clone(), name.clone());
        }
        table_mut(&mut self.root, "media").insert(&name, at(Value::Table(t), line));
        Ok(name)
    }

    fn shape(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        let m = o.transform("to_world")?;
        // The material: a nested BSDF, a reference, or Mitsuba's default (diffuse 0.5).
        let mut material = None;
        let mut emission = None;
        // Mitsuba's interior (behind the normal) and exterior (in front of it).
        let mut interior = None;
        let mut exterior = None;
        let props = std::mem::take(&mut o.props);
        for (name, p, l) in props {
            match p {
                Prop::Object(b) if b.tag == "bsdf" => material = Some(self.bsdf(b)?),
                Prop::Ref(id) if name.is_empty() || name == "bsdf" => {
                    let found = self.bsdfs.get(&id).cloned();
                    if found.is_none() && !self.lenient {
                        return Err(o.error(format!("line {l}: no BSDF with id `{id}` before it")));
                    }
                    material = Some(found);
                }
                Prop::Object(mut e) if e.tag == "emitter" => {
                    if e.ty != "area" {
                        return Err(e.error("a shape's emitter must be `area`"));
                    }
                    emission = Some(e.color("radiance", DVec3::ONE)?);
                    self.leftovers(&e)?;
                }
                Prop::Object(med) if med.tag == "medium" && name == "interior" => {
                    interior = Some(self.medium(med)?)
                }
                Prop::Ref(id) if name == "interior" => {
                    interior = Some(self.media.get(&id).cloned().ok_or_else(|| {
                        o.error(format!("line {l}: no medium with id `{id}` before it"))
                    })?)
                }
                Prop::Object(med) if med.tag == "medium" && name == "exterior" => {
                    exterior = Some(self.medium(med)?)
                }
                Prop::Ref(id) if name == "exterior" => {
                    exterior = Some(self.media.get(&id).cloned().ok_or_else(|| {
                        o.error(format!("line {l}: no medium with id `{id}` before it"))
                    })?)
                }
                other => o.props.push((name, other, l)),
            }
        }
        let material = match material {
            Some(Some(name)) => name,
            Some(None) => return Ok(()), // left out with its BSDF (lenient)
            // Mitsuba 0.x gives a medium transition without a BSDF the null BSDF (its
            // Shape::configure): an index-matched boundary of the fog (Bitterli's
            // volumetric caustic); Mitsuba 3 gives every shape its diffuse default.
            None if self.v1 && emission.is_none() && (interior.is_some() || exterior.is_some()) => {
                let name = "null_boundary".to_string();
                let mut t = Table::default();
                t.insert("type", at(Value::Str("null".into()), line));
                table_mut(&mut self.root, "materials").insert(&name, at(Value::Table(t), line));
                name
            }
            None => {
                let name = format!("default_diffuse_{line}");
                let mut t = Table::default();
                t.insert("type", at(Value::Str("diffuse".into()), line));
                t.insert("twosided", at(Value::Bool(false), line));
                // ... and an emitter without one an all-absorbing diffuse BSDF: a pure
                // emitter, in Mitsuba 3 (Shape's constructor, 3.0 to 3.9) as in 0.x.
                if emission.is_some() {
                    t.insert("reflectance", vec3(DVec3::ZERO, line));
                }
                table_mut(&mut self.root, "materials").insert(&name, at(Value::Table(t), line));
                name
            }
        };
        let flip_normals = o.boolean("flip_normals", false)?;
        let mut shapes: Vec<Table> = Vec::new();
        let quad = |origin: DVec3, u: DVec3, v: DVec3| {
            let mut t = Table::default();
            t.insert("type", at(Value::Str("quad".into()), line));
            t.insert("origin", vec3(origin, line));
            t.insert("u", vec3(u, line));
            t.insert("v", vec3(v, line));
            t
        };
        // A shape's normal is its transformed normal, M^-T n; u x v = det(M) M^-T (x x y)
        // points the other way under a mirroring to_world: flipped back (which keeps the
        // texture coordinates, as swapping the edges would not).
        let mirrored = m.determinant() < 0.0;
        let flip = mirrored != flip_normals;
        let rectangle = |corner: DVec3, a: DVec3, b: DVec3| {
            let origin = m.transform_point3(corner);
            let (u, v) = (m.transform_vector3(a), m.transform_vector3(b));
            let mut t = quad(origin, u, v);
            if flip {
                t.insert("flip_normals", at(Value::Bool(true), line));
            }
            t
        };
        match o.ty.as_str() {
            "obj" | "ply" => {
                let file = self.filename(&mut o)?;
                let mut t = Table::default();
                t.insert("type", at(Value::Str("mesh".into()), line));
                if o.boolean("face_normals", false)? {
                    t.insert("face_normals", at(Value::Bool(true), line));
                }
                if o.ty == "obj" && !o.boolean("flip_tex_coords", true)? {
                    t.insert("flip_tex_coords", at(Value::Bool(false), line));
                }
                if flip_normals {
                    t.insert("flip_normals", at(Value::Bool(true), line));
                }
                t.insert("file", file);
                if m != DMat4::IDENTITY {
                    t.insert("transform", matrix_table(m, line));
                }
                shapes.push(t);
            }
            "disk" => {
                let mut t = Table::default();
                t.insert("type", at(Value::Str("disk".into()), line));
                t.insert("center", vec3(m.transform_point3(DVec3::ZERO), line));
                t.insert("u", vec3(m.transform_vector3(DVec3::X), line));
                t.insert("v", vec3(m.transform_vector3(DVec3::Y), line));
                if flip {
                    t.insert("flip_normals", at(Value::Bool(true), line));
                }
                shapes.push(t);
            }
            "sphere" => {
                let center = o.point("center")?.unwrap_or(DVec3::ZERO);
                let radius = o.float("radius", 1.0)?;
                let (x, y, z) = (
                    m.transform_vector3(DVec3::X),
                    m.transform_vector3(DVec3::Y),
                    m.transform_vector3(DVec3::Z),
                );
                let s = x.length();
                let tol = 1e-6 * s.max(1e-30);
                if (y.length() - s).abs() > tol
                    || (z.length() - s).abs() > tol
                    || x.dot(y).abs() > tol * s
                    || y.dot(z).abs() > tol * s
                {
                    self.unsupported(
                        &o,
                        "a sphere with a non-uniform scale (an ellipsoid) is not supported",
                    )?;
                    return Ok(());
                }
                let mut t = Table::default();
                t.insert("type", at(Value::Str("sphere".into()), line));
                t.insert("center", vec3(m.transform_point3(center), line));
                t.insert("radius", at(Value::Float(radius * s), line));
                if flip_normals {
                    t.insert("flip_normals", at(Value::Bool(true), line));
                }
                shapes.push(t);
            }
            "rectangle" => shapes.push(rectangle(
                DVec3::new(-1.0, -1.0, 0.0),
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
            )),
            "cube" => {
                // Six outward-facing faces of [-1, 1]^3.
                for axis in 0..3 {
                    for side in [-1.0, 1.0] {
                        let n = DVec3::AXES[axis] * side;
                        let a = DVec3::AXES[(axis + 1) % 3] * 2.0;
                        let b = DVec3::AXES[(axis + 2) % 3] * 2.0;
                        let (a, b) = if side > 0.0 { (a, b) } else { (b, a) };
                        shapes.push(rectangle(n - a / 2.0 - b / 2.0, a, b));
                    }
                }
            }
            _ => {
                o.props.clear();
                let m = not_read("shape", &o.ty, "this shape is not supported yet");
                return self.unsupported(&o, &m);
            }
        }
        self.leftovers(&o)?;
        for mut t in shapes {
            t.insert("material", at(Value::Str(material.clone()), line));
            if let Some(e) = emission {
                t.insert("emission", vec3(e, line));
            }
            // Both sides, as Mitsuba crosses them: a side without a medium is vacuum.
            if interior.is_some() || exterior.is_some() {
                self.shape_media = true;
                for (key, side) in [("interior", &interior), ("exterior", &exterior)] {
                    let name = side.clone().unwrap_or_else(|| "vacuum".into());
                    t.insert(key, at(Value::Str(name), line));
                }
            }
            self.shapes.push(at(Value::Table(t), line));
        }
        Ok(())
    }

    fn emitter(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        let mut t = Table::default();
        t.insert("type", at(Value::Str(o.ty.clone()), line));
        let m = o.transform("to_world")?;
        // The medium a point or spot light sits in (Mitsuba's emitter `medium`).
        if let Some((p, l)) = o.take("medium") {
            let name = match p {
                Prop::Ref(id) => self.media.get(&id).cloned().ok_or_else(|| {
                    o.error(format!("line {l}: no medium with id `{id}` before it"))
                })?,
                Prop::Object(med) if med.tag == "medium" => self.medium(med)?,
                other => {
                    return Err(o.error(format!("`medium`: expected a medium, found {other:?}")));
                }
            };
            if !matches!(o.ty.as_str(), "point" | "spot") {
                return Err(o.error("only point and spot emitters sit in a medium"));
            }
            t.insert("medium", at(Value::Str(name), l));
        }
        match o.ty.as_str() {
            "point" => {
                let p = o.point("position")?.unwrap_or(DVec3::ZERO);
                t.insert("position", vec3(m.transform_point3(p), line));
                let i = o.color("intensity", DVec3::ONE)?;
                t.insert("intensity", vec3(i, line));
            }
            "spot" => {
                t.insert("position", vec3(m.transform_point3(DVec3::ZERO), line));
                let d = m.transform_vector3(DVec3::Z);
                t.insert("direction", vec3(d, line));
                let i = o.color("intensity", DVec3::ONE)?;
                t.insert("intensity", vec3(i, line));
                let cutoff = o.float("cutoff_angle", 20.0)?;
                let beam = o.float("beam_width", cutoff * 0.75)?;
                t.insert("cutoff_angle", at(Value::Float(cutoff), line));
                t.insert("beam_width", at(Value::Float(beam), line));
            }
            "directional" => {
                let d = match o.take("direction") {
                    Some((Prop::Point(d), _)) => d,
                    Some((p, _)) => {
                        return Err(o.error(format!("`direction`: expected a vector, found {p:?}")));
                    }
                    None => m.transform_vector3(DVec3::Z),
                };
                t.insert("direction", vec3(d, line));
                let e = o.color("irradiance", DVec3::ONE)?;
                t.insert("irradiance", vec3(e, line));
            }
            "constant" => {
                let l = o.color("radiance", DVec3::ONE)?;
                t.insert("radiance", vec3(l, line));
            }
            "envmap" => {
                t.insert("filename", self.filename(&mut o)?);
                t.insert("scale", at(Value::Float(o.float("scale", 1.0)?), line));
                if m != DMat4::IDENTITY {
                    t.insert("to_world", matrix_table(m, line));
                }
                // Compensation changes only the noise.
                o.take("mis_compensation");
            }
            _ => {
                o.props.clear();
                let m = not_read("emitter", &o.ty, "this emitter is not supported yet");
                return self.unsupported(&o, &m);
            }
        }
        self.leftovers(&o)?;
        self.lights.push(at(Value::Table(t), line));
        Ok(())
    }
}

fn syntax(file: &Path, line: u32, message: &str) -> Error {
    Error::XmlSyntax {
        location: Location {
            file: file.to_path_buf(),
            line,
            column: if line > 0 { 1 } else { 0 },
        },
        message: message.to_string(),
    }
}

fn attr(n: roxmltree::Node<'_, '_>, name: &str, file: &Path, line: u32) -> Result<String> {
    n.attribute(name).map(str::to_string).ok_or_else(|| {
        syntax(
            file,
            line,
            &format!("<{}> without `{name}`", n.tag_name().name()),
        )
    })
}

/// Numbers separated by commas and/or spaces.
fn numbers(s: &str) -> Option<Vec<f64>> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|x| !x.is_empty())
        .map(|x| x.parse().ok())
        .collect()
}

/// The property elements of Mitsuba 3's parser (and 0.6's `srgb`) that foton reads.
const PROPERTY_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "rgb",
    "srgb",
    "spectrum",
    "point",
    "vector",
    "transform",
    "ref",
];

/// The object elements of Mitsuba's parser.
const OBJECT_TAGS: &[&str] = &[
    "bsdf",
    "emitter",
    "medium",
    "phase",
    "texture",
    "rfilter",
    "sampler",
    "film",
    "shape",
    "sensor",
    "integrator",
];

/// Elements Mitsuba (3 or 0.6) reads that foton does not: "not supported", not "unknown".
const KNOWN_UNREAD: &[&str] = &[
    "volume",
    "blackbody",
    "animation",
    "alias",
    "path",
    "include",
    "default",
    "subsurface",
    "luminaire",
    "null",
];

/// Mitsuba 3's upgrade of a property list from a file older than 2.0 (its `upgrade_from_v1`):
/// camelCase names to snake_case, a diffuse BSDF's `diffuse_reflectance` to `reflectance`,
/// and `uoffset`, `voffset`, `uscale`, `vscale` to a `to_uv` transform. Unlike Mitsuba 3,
/// nothing is dropped: a medium's `sigma_s` and `sigma_a` stay (Mitsuba 0.6 honours them).
fn upgrade_v1(o: &mut Obj) {
    for (name, _, _) in &mut o.props {
        *name = camel_to_snake(name);
    }
    if o.ty == "diffuse" {
        for (name, _, _) in &mut o.props {
            if name == "diffuse_reflectance" {
                *name = "reflectance".into();
            }
        }
    }
    let mut offset = DVec3::ZERO;
    let mut scale = DVec3::ONE;
    let mut any = None;
    o.props.retain(|(name, p, line)| {
        let x = match p {
            Prop::Float(x) => *x,
            Prop::Int(i) => *i as f64,
            _ => return true,
        };
        match name.as_str() {
            "uoffset" => offset.x = x,
            "voffset" => offset.y = x,
            "uscale" => scale.x = x,
            "vscale" => scale.y = x,
            _ => return true,
        }
        any = Some(*line);
        false
    });
    if let Some(line) = any {
        let m = DMat4::from_scale(scale) * DMat4::from_translation(offset);
        o.props.push(("to_uv".into(), Prop::Transform(m), line));
    }
}

/// Mitsuba 3's `camel_to_underscore_case`: an upper-case letter after a lower-case one starts
/// a new word (`toWorld` to `to_world`), and the upper-case letters right after it stay in
/// that word (`intIOR` to `int_ior`).
fn camel_to_snake(name: &str) -> String {
    let c: Vec<char> = name.chars().collect();
    let mut out = String::with_capacity(name.len() + 4);
    let mut i = 0;
    while i < c.len() {
        if i > 0 && c[i - 1].is_ascii_lowercase() && c[i].is_ascii_uppercase() {
            out.push('_');
            out.push(c[i].to_ascii_lowercase());
            while i + 1 < c.len() && c[i + 1].is_ascii_uppercase() {
                i += 1;
                out.push(c[i].to_ascii_lowercase());
            }
        } else {
            out.push(c[i]);
        }
        i += 1;
    }
    out
}

/// Completes the unit vector `n` to an orthonormal basis (Duff et al. 2017, "Building an
/// orthonormal basis, revisited"), as Mitsuba 3's `coordinate_system` does: `<lookat>`
/// without `up` takes the first vector, so foton's camera is Mitsuba's.
fn coordinate_system(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(n.x * n.x * a * sign + 1.0, b * sign, -n.x * sign),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// The sRGB transfer curve inverted (IEC 61966-2-1): Mitsuba 0.6's `<srgb>` colours.
fn srgb_to_linear(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// A property's value as the file wrote it, for messages.
fn show(p: &Prop) -> String {
    match p {
        Prop::Float(x) => x.to_string(),
        Prop::Int(i) => i.to_string(),
        Prop::Bool(b) => b.to_string(),
        Prop::Str(s) => format!("{s:?}"),
        Prop::Color(c) | Prop::Point(c) => format!("[{}, {}, {}]", c.x, c.y, c.z),
        Prop::Ref(id) => format!("<ref id={id:?}>"),
        Prop::Object(o) => o.what(),
        Prop::Transform(_) => "a transform".into(),
    }
}

/// The plugins of each kind in Mitsuba 3 and 0.6 (for "not supported" against "unknown").
const MITSUBA_PLUGINS: &[(&str, &[&str])] = &[
    (
        "bsdf",
        &[
            "diffuse",
            "dielectric",
            "thindielectric",
            "roughdielectric",
            "conductor",
            "roughconductor",
            "plastic",
            "roughplastic",
            "twosided",
            "null",
            "principled",
            "principledthin",
            "bumpmap",
            "normalmap",
            "blendbsdf",
            "mask",
            "hair",
            "measured",
            "pplastic",
            "polarizer",
            "retarder",
            "circular",
            "coating",
            "roughcoating",
            "phong",
            "ward",
            "mixturebsdf",
            "difftrans",
            "hk",
            "irawan",
            "roughdiffuse",
            "bump",
        ],
    ),
    (
        "shape",
        &[
            "obj",
            "ply",
            "serialized",
            "sphere",
            "rectangle",
            "cube",
            "disk",
            "cylinder",
            "bsplinecurve",
            "linearcurve",
            "sdfgrid",
            "shapegroup",
            "instance",
            "ellipsoids",
            "ellipsoidsmesh",
            "merge",
            "hair",
            "heightfield",
        ],
    ),
    (
        "emitter",
        &[
            "area",
            "point",
            "spot",
            "directional",
            "constant",
            "envmap",
            "projector",
            "directionalarea",
            "sunsky",
            "sky",
            "sun",
            "collimated",
        ],
    ),
    (
        "texture",
        &[
            "bitmap",
            "checkerboard",
            "mesh_attribute",
            "volume",
            "gridtexture",
            "scale",
            "vertexcolors",
            "wireframe",
            "curvature",
        ],
    ),
    (
        "sensor",
        &[
            "perspective",
            "thinlens",
            "orthographic",
            "radiancemeter",
            "irradiancemeter",
            "distant",
            "batch",
            "telecentric",
            "spherical",
            "fluencemeter",
            "perspective_rdist",
        ],
    ),
    ("medium", &["homogeneous", "heterogeneous"]),
    (
        "phase",
        &[
            "isotropic",
            "hg",
            "rayleigh",
            "sggx",
            "tabphase",
            "blendphase",
            "kkay",
            "microflake",
            "mixturephase",
        ],
    ),
    (
        "film",
        &["hdrfilm", "ldrfilm", "specfilm", "tiledhdrfilm", "mfilm"],
    ),
    (
        "rfilter",
        &[
            "box",
            "tent",
            "gaussian",
            "mitchell",
            "catmullrom",
            "lanczos",
        ],
    ),
];

/// The message for a plugin type foton does not read: `supported` (with `not supported`
/// wording) when Mitsuba has it, "unknown" with the close name otherwise.
fn not_read(kind: &str, ty: &str, supported: &str) -> String {
    let known = MITSUBA_PLUGINS
        .iter()
        .find(|(k, _)| *k == kind)
        .map_or(&[][..], |(_, names)| names);
    if known.contains(&ty) {
        supported.to_string()
    } else {
        format!(
            "unknown {kind} type `{ty}`{}",
            foton_core::error::suggestion(ty, known.iter().copied())
        )
    }
}

/// The integrators of Mitsuba 3 and 0.6 (for "not supported" against "unknown").
const MITSUBA_INTEGRATORS: &[&str] = &[
    "path",
    "volpath",
    "volpath_simple",
    "volpathmis",
    "direct",
    "photonmapper",
    "sppm",
    "ppm",
    "bdpt",
    "ao",
    "aov",
    "depth",
    "moment",
    "stokes",
    "prb",
    "prbvolpath",
    "direct_projective",
    "prb_projective",
    "ptracer",
    "vpl",
    "irrcache",
    "adaptive",
    "field",
    "multichannel",
    "mlt",
    "pssmlt",
    "erpt",
];

/// The foton plugin that renders a Mitsuba integrator, or None (not supported). A photon
/// mapper in a scene with media is foton's volumetric one.
fn foton_integrator(mitsuba: &str, has_media: bool) -> Option<&'static str> {
    Some(match mitsuba {
        "path" | "volpath" | "volpath_simple" | "volpathmis" | "direct" => "path",
        "photonmapper" if has_media => "vpm",
        "photonmapper" => "photon",
        "sppm" | "ppm" => "sppm",
        "bdpt" => "bdpt",
        _ => return None,
    })
}

/// Mitsuba's samplers and what foton samples with: the one place that decides it. Every
/// sampler gives the same image in expectation; one foton lacks is rendered by the nearest
/// foton has (`multijitter` is jittered strata, the low-discrepancy ones Owen-scrambled
/// Sobol points: other noise), with a warning. None: not a Mitsuba sampler. The flag says
/// whether foton's sampler is Mitsuba's.
fn foton_sampler(mitsuba: &str) -> Option<(&'static str, bool)> {
    Some(match mitsuba {
        "independent" => ("independent", true),
        "stratified" => ("stratified", true),
        "sobol" => ("sobol", true),
        "multijitter" => ("stratified", false),
        "orthogonal" | "ldsampler" | "halton" | "hammersley" => ("sobol", false),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_becomes_snake_case_as_in_mitsuba_3() {
        for (old, new) in [
            ("toWorld", "to_world"),
            ("intIOR", "int_ior"),
            ("sampleCount", "sample_count"),
            ("sigmaS", "sigma_s"),
            ("specularReflectance", "specular_reflectance"),
            ("globalLookupRadius", "global_lookup_radius"),
            ("max_depth", "max_depth"),
            ("fov", "fov"),
        ] {
            assert_eq!(camel_to_snake(old), new);
        }
    }

    #[test]
    fn coordinate_system_is_orthonormal() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.3, -0.5, 0.2).normalize(),
            DVec3::X,
        ] {
            let (s, t) = coordinate_system(n);
            assert!((s.length() - 1.0).abs() < 1e-12 && (t.length() - 1.0).abs() < 1e-12);
            assert!(s.dot(n).abs() < 1e-12 && t.dot(n).abs() < 1e-12 && s.dot(t).abs() < 1e-12);
            assert!((s.cross(t) - n).length() < 1e-12, "right-handed for {n}");
        }
    }
}
