//! Mitsuba 3 XML scenes, read into the document a TOML scene makes: `foton render scene.xml`
//! renders what the same scene written in TOML would (`foton convert` writes that TOML), and
//! every value keeps the XML line it came from, so the loader's errors name the XML file and
//! line.
//!
//! Mitsuba's conventions, as its documentation states them: `<default>` and `$name`
//! substitution (`-D name=value` overrides a default), `ref`/`id`, `include`; transforms
//! composed in document order; `max_depth` counts path segments (-1: unbounded), so foton's
//! count of scattering events is one less; area emitters emit on their normal's side; the
//! sensor looks down its local +z with +y up. What foton cannot render yet is an error naming
//! the element, its type and file:line, or with `lenient` is left out and listed.

use crate::error::{Error, Location, Result};
use crate::value::{Document, Node, Table, Value};
use glam::{DMat4, DVec3};
use std::collections::HashMap;
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
}

/// Reads a Mitsuba 3 XML scene. `defines` are `NAME=VALUE` overrides of its `<default>`s.
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
    };
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    r.read_file(path, &text, true)?;
    r.place_sensor_medium();
    let mut root = std::mem::take(&mut r.root);
    if !r.shapes.is_empty() {
        root.insert("shapes", at(Value::Array(std::mem::take(&mut r.shapes)), 0));
    }
    if !r.lights.is_empty() {
        root.insert("lights", at(Value::Array(std::mem::take(&mut r.lights)), 0));
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

    fn note(&mut self, obj: &Obj, what: &str) {
        self.report
            .notes
            .push(format!("{}: {}: {what}", obj.place(), obj.what()));
    }

    fn read_file(&mut self, path: &Path, text: &str, top: bool) -> Result<()> {
        let doc = roxmltree::Document::parse(text).map_err(|e| {
            let pos = e.pos();
            Error::Syntax {
                location: Location {
                    file: path.to_path_buf(),
                    line: pos.row,
                    column: pos.col,
                },
                message: format!("XML: {e}"),
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
        if top {
            let version = scene.attribute("version").unwrap_or("");
            if !version.starts_with("3.") && !version.starts_with("2.") {
                return Err(syntax(
                    path,
                    line_of(scene),
                    &format!(
                        "<scene version=\"{version}\">: foton reads Mitsuba 3 scenes (version 3.x)"
                    ),
                ));
            }
        }
        for child in scene.children().filter(|n| n.is_element()) {
            let line = line_of(child);
            match child.tag_name().name() {
                "default" => {
                    let name = attr(child, "name", path, line)?;
                    let value = attr(child, "value", path, line)?;
                    if !self.defined.contains(&name) {
                        self.defaults.entry(name).or_insert(value);
                    }
                }
                "include" => {
                    let file = self.subst(&attr(child, "filename", path, line)?, path, line)?;
                    let inc = path.parent().unwrap_or(Path::new("")).join(file);
                    let text = std::fs::read_to_string(&inc).map_err(|e| Error::io(&inc, e))?;
                    self.report.included.push(inc.clone());
                    self.read_file(&inc, &text, false)?;
                }
                _ => {
                    let obj = self.object(child, path, &line_of)?;
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
                "bsdf" | "emitter" | "medium" | "phase" | "texture" | "rfilter" | "sampler"
                | "film" | "shape" | "sensor" | "integrator" => {
                    Prop::Object(self.object(c, file, line_of)?)
                }
                other => {
                    return Err(syntax(
                        file,
                        cl,
                        &format!("unknown element <{other}> in <{}>", obj.tag),
                    ));
                }
            };
            obj.props.push((name, prop, cl));
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
                    let (origin, target, up) = (vec("origin")?, vec("target")?, vec("up")?);
                    let dir = (target - origin).normalize();
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
                    return Err(syntax(
                        file,
                        l,
                        &format!("unknown transform operation <{other}>"),
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
            "integrator" => self.integrator(obj),
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

    fn integrator(&mut self, mut o: Obj) -> Result<()> {
        let render = table_mut(&mut self.root, "render");
        let (name, depth_default) = match o.ty.as_str() {
            "path" | "volpath" | "volpathmis" => ("path", -1),
            "direct" => ("path", 2),
            "sppm" => ("sppm", -1),
            "photonmapper" => ("photon", -1),
            _ => {
                o.props.clear();
                return self.unsupported(
                    &o,
                    "unknown integrator; foton reads path, volpath, volpathmis, direct, sppm and photonmapper",
                );
            }
        };
        render.insert("integrator", at(Value::Str(name.into()), o.line));
        let line = o.line;
        let max_depth = if o.ty == "direct" {
            2
        } else {
            let md = o.float("max_depth", depth_default as f64)?;
            let md = o.float("maxDepth", md)?;
            md as i64
        };
        // Mitsuba counts path segments (the camera ray is one); foton counts scattering
        // events. Unbounded: a cap no path reaches (Russian roulette ends them long before).
        let bounces = match max_depth {
            -1 => 65_536,
            d if d >= 1 => d - 1,
            d => {
                return Err(o.error(format!(
                    "max_depth = {d}: renders nothing (1 is emitters seen directly, -1 unbounded)"
                )));
            }
        };
        let render = table_mut(&mut self.root, "render");
        render.insert("max_depth", at(Value::Int(bounces), line));
        let params = table_mut(table_mut(&mut self.root, "integrators"), name);
        let mut set = |key: &str, v: Value| params.insert(key, at(v, line));
        match o.ty.as_str() {
            "path" | "volpath" | "volpathmis" => {
                let rr = o.int("rr_depth", 5)?;
                set("rr_depth", Value::Int(rr.max(1) - 1));
            }
            "sppm" => {
                for (mitsuba, foton) in [
                    ("photon_count", "photons_per_iteration"),
                    ("photonCount", "photons_per_iteration"),
                    ("passes", "iterations"),
                    ("maxPasses", "iterations"),
                ] {
                    if let Some((Prop::Int(v), _)) = o.take(mitsuba) {
                        set(foton, Value::Int(v));
                    }
                }
                for (mitsuba, foton) in [
                    ("initial_radius", "initial_radius"),
                    ("initialRadius", "initial_radius"),
                    ("alpha", "alpha"),
                ] {
                    if let Some((Prop::Float(v), _)) = o.take(mitsuba) {
                        set(foton, Value::Float(v));
                    }
                }
            }
            "photonmapper" => {
                for (mitsuba, foton) in [
                    ("globalPhotons", "global_photons"),
                    ("causticPhotons", "caustic_photons"),
                    ("globalLookupSize", "k"),
                ] {
                    if let Some((Prop::Int(v), _)) = o.take(mitsuba) {
                        set(foton, Value::Int(v));
                    }
                }
            }
            _ => {}
        }
        for ignored in [
            "rrDepth",
            "samples_per_pass",
            "emitter_samples",
            "bsdf_samples",
        ] {
            o.take(ignored);
        }
        if o.boolean("hide_emitters", false)? {
            table_mut(&mut self.root, "render")
                .insert("hide_emitters", at(Value::Bool(true), line));
        }
        self.leftovers(&o)
    }

    fn sensor(&mut self, mut o: Obj) -> Result<()> {
        if o.ty != "perspective" {
            o.props.clear();
            return self.unsupported(&o, "only the perspective sensor is supported");
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
        if o.ty != "hdrfilm" {
            self.note(&o, "read as hdrfilm");
        }
        let line = o.line;
        let width = o.int("width", 768)?;
        let height = o.int("height", 576)?;
        for ignored in [
            "pixel_format",
            "component_format",
            "file_format",
            "sample_border",
        ] {
            o.take(ignored);
        }
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
                        self.unsupported(&rf, "foton's filters are box, tent and gaussian")?;
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
        let spp = o.int("sample_count", 4)?;
        let render = table_mut(&mut self.root, "render");
        render.insert("spp", at(Value::Int(spp), line));
        let seed = o.int("seed", 0)?;
        table_mut(&mut self.root, "render").insert("seed", at(Value::Int(seed), line));
        // The sample pattern (stratified, multijitter...) changes noise, not the image.
        for ignored in ["jitter", "scramble"] {
            o.take(ignored);
        }
        self.leftovers(&o)
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
                        if name != "none" && crate::material::conductor(&name).is_none() {
                            return Err(o.error(format!("`material`: unknown conductor `{name}`")));
                        }
                        t.insert("material", at(Value::Str(name), line));
                    }
                    (Some((eta, l1)), Some((k, l2))) => {
                        o.props.push(("eta".into(), eta, l1));
                        o.props.push(("k".into(), k, l2));
                        let (eta, k) = (o.color("eta", DVec3::ONE)?, o.color("k", DVec3::ZERO)?);
                        t.insert("eta", vec3(eta, line));
                        t.insert("k", vec3(k, line));
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
                self.unsupported(&o, "this BSDF is not supported yet")?;
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
                self.unsupported(&o, "this texture is not supported yet")?;
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
            return Err(o.error("only homogeneous media are supported"));
        }
        let line = o.line;
        let sigma_t = o.color("sigma_t", DVec3::ONE)?;
        let albedo = o.color("albedo", DVec3::splat(0.75))?;
        let scale = o.float("scale", 1.0)?;
        // Whether a medium samples emitters changes noise, not the image.
        o.take("sample_emitters");
        let mut t = Table::default();
        t.insert("type", at(Value::Str("homogeneous".into()), line));
        t.insert("sigma_s", vec3(sigma_t * albedo * scale, line));
        t.insert(
            "sigma_a",
            vec3(sigma_t * (DVec3::ONE - albedo) * scale, line),
        );
        if let Some((Prop::Object(mut phase), l)) = o.take("") {
            match phase.ty.as_str() {
                "isotropic" => t.insert("phase", at(Value::Str("isotropic".into()), l)),
                "hg" => {
                    let g = phase.float("g", 0.8)?;
                    let mut p = Table::default();
                    p.insert("type", at(Value::Str("hg".into()), l));
                    p.insert("g", at(Value::Float(g), l));
                    t.insert("phase", at(Value::Table(p), l));
                }
                _ => return Err(phase.error("foton's phase functions are isotropic and hg")),
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
            None => {
                let name = format!("default_diffuse_{line}");
                let mut t = Table::default();
                t.insert("type", at(Value::Str("diffuse".into()), line));
                t.insert("twosided", at(Value::Bool(false), line));
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
                return self.unsupported(&o, "this shape is not supported yet");
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
                return self.unsupported(&o, "this emitter is not supported yet");
            }
        }
        self.leftovers(&o)?;
        self.lights.push(at(Value::Table(t), line));
        Ok(())
    }
}

fn syntax(file: &Path, line: u32, message: &str) -> Error {
    Error::Syntax {
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
