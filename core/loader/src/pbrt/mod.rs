//! pbrt-v4 scenes (`.pbrt`), read into the document a TOML scene makes: `foton render
//! scene.pbrt` renders what the same scene written in TOML would, and every value keeps the
//! line it came from (values from an `Include`d file have none: a line of the document is
//! one of the scene file's), so the loader's errors name the file and line.
//!
//! pbrt-v4's conventions, as its source states them (parser.cpp, scene.cpp, cameras.cpp,
//! shapes.cpp, lights.cpp, materials.cpp): transforms post-multiply the current transform
//! (`Translate` in a file applies before what was written above it); the camera transform is
//! the current transform at `Camera` (camera from world) and camera space is left-handed (+x
//! to the image's right, +y up, +z forward), so a `LookAt` alone gives the image mirrored
//! against foton's right-handed camera (foton's `mirror`), and the usual `Scale -1 1 1` in
//! front of it undoes that; `fov` spans the shorter image axis; `maxdepth` counts bounces as
//! foton's `max_depth` does; an area light emits on its surface normal's side (a triangle's
//! winding, or its vertex normals' side when it has them; a sphere's or disk's outside,
//! turned by `ReverseOrientation`, and for a sphere also by a mirroring transform); lights
//! divide their spectrum by its luminance (`spectra`). What foton cannot render is an error
//! naming the directive, its type and file:line:column, or with `lenient` is left out and
//! listed.
//!
//! The reader is laid out as pbrt-v4's parser and scene builder are: `lexer` (tokens) and
//! `parse` (statements into [`parse::Directive`]s, `Include`/`Import` read in place), then
//! this module's graphics state (transforms, attributes, named coordinate systems) and one
//! file per kind of statement turning a directive into the tables of the TOML document:
//! `camera` (camera, film, sampler, integrator, filter), `shape`, `material`, `light`;
//! `params` reads a parameter list and `spectra` reduces spectra to RGB.

mod camera;
mod lexer;
mod light;
mod material;
mod medium;
mod params;
mod parse;
mod shape;
mod spectra;
#[cfg(test)]
mod tests;
mod texture;

use crate::reader::{Options, Report};
use foton_core::error::{Error, Location, Result};
use foton_core::value::{Document, Node, Table, Value};
use glam::{DMat4, DVec3};
use params::Bag;
use parse::Directive;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Where a token or a statement was written.
#[derive(Clone, Debug, PartialEq)]
pub struct Loc {
    pub file: Rc<Path>,
    pub line: u32,
    pub column: u32,
}

impl Loc {
    /// An error at this place about `key` (a directive, or `syntax`).
    pub fn error(&self, key: &str, message: impl Into<String>) -> Error {
        Error::Scene {
            location: Location {
                file: self.file.to_path_buf(),
                line: self.line,
                column: self.column,
            },
            key: key.into(),
            message: message.into(),
        }
    }
}

impl std::fmt::Display for Loc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}:{}", self.file.display(), self.line, self.column)
    }
}

/// The pbrt-v4 format's reader ([`crate::reader`]).
pub fn read(path: &Path, options: &Options<'_>) -> Result<(Document, Report)> {
    if path.is_dir() {
        return Err(Error::io(path, "is a directory, not a scene file"));
    }
    if !options.defines.is_empty() {
        return Err(Error::Usage(
            "-D: a pbrt-v4 scene has no defaults to override (use --set on the scene it reads as)"
                .into(),
        ));
    }
    let mut report = Report::default();
    let directives = parse::parse_file(path, &mut report.included)?;
    let mut r = Reader::new(path, options.lenient, report);
    for d in &directives {
        r.directive(d)?;
    }
    r.finish_scene()
}

/// The graphics state pbrt-v4 saves at `AttributeBegin` and restores at `AttributeEnd`.
#[derive(Clone, Debug)]
struct State {
    /// World from object (before `WorldBegin`: camera from world).
    ctm: DMat4,
    reverse_orientation: bool,
    /// The current material's name in `[materials]` (None: pbrt-v4's default, diffuse 0.5).
    material: Option<String>,
    /// The current `AreaLightSource`, given to the shapes that follow.
    area_light: Option<Directive>,
    /// The current `MediumInterface`: the media inside and outside the shapes that follow
    /// (`""`: vacuum); the outside one is where the camera and the lights sit.
    inside: String,
    outside: String,
    /// Where that `MediumInterface` was written.
    interface: Option<Loc>,
    /// `Attribute` defaults per target, in the order written.
    attributes: Attributes,
    /// `ActiveTransform EndTime`: the transform statements that follow change only the end
    /// transform, which foton does not render (it renders the start transform).
    end_only: bool,
}

/// The parameters `Attribute` gives the shapes, lights, materials, media and textures that
/// follow in its attribute block.
#[derive(Clone, Debug, Default)]
struct Attributes {
    shape: Vec<parse::Param>,
    light: Vec<parse::Param>,
    material: Vec<parse::Param>,
    medium: Vec<parse::Param>,
    texture: Vec<parse::Param>,
}

/// A shape statement of an `ObjectBegin` block, with the state it was read in.
#[derive(Clone)]
struct Recorded {
    d: Directive,
    state: State,
}

struct Reader {
    file: PathBuf,
    dir: PathBuf,
    lenient: bool,
    report: Report,
    root: Table,
    shapes: Vec<Node>,
    lights: Vec<Node>,
    state: State,
    stack: Vec<(State, Loc)>,
    /// `TransformBegin`'s saved transforms (pbrt-v3's, still read by pbrt-v4).
    transforms: Vec<DMat4>,
    named_coordinates: HashMap<String, DMat4>,
    /// `MakeNamedMaterial` names to their names in `[materials]`.
    named_materials: HashMap<String, String>,
    anonymous: usize,
    world: bool,
    /// `Camera`, with the camera-from-world transform at it.
    camera: Option<(Directive, DMat4)>,
    film: Option<Directive>,
    sampler: Option<Directive>,
    integrator: Option<Directive>,
    filter: Option<Directive>,
    /// `ObjectBegin` blocks: their names and shapes; the one being read.
    objects: HashMap<String, Vec<Recorded>>,
    object: Option<(String, Vec<Recorded>)>,
    /// Whether the note on plymesh orientation was given (once a scene).
    ply_noted: bool,
    /// `Texture` names (spectrum and float textures are named apart, as in pbrt-v4).
    textures: HashMap<String, texture::Tex>,
    float_textures: HashMap<String, texture::Tex>,
    /// `MakeNamedMedium` names to their keys in `[media]`; those left out (`lenient`); the
    /// names used, checked at the end (a medium may be made after its use).
    named_media: HashMap<String, String>,
    left_out_media: std::collections::HashSet<String>,
    medium_refs: Vec<(String, Loc)>,
    /// The outside medium at `Camera`.
    camera_medium: Option<(String, Loc)>,
    /// The film's imaging ratio (exposure time x ISO / 100): the factor of every light.
    imaging_ratio: f64,
}

impl Reader {
    fn new(path: &Path, lenient: bool, report: Report) -> Reader {
        Reader {
            file: path.to_path_buf(),
            dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            lenient,
            report,
            root: Table::default(),
            shapes: Vec::new(),
            lights: Vec::new(),
            state: State {
                ctm: DMat4::IDENTITY,
                reverse_orientation: false,
                material: None,
                area_light: None,
                inside: String::new(),
                outside: String::new(),
                interface: None,
                attributes: Attributes::default(),
                end_only: false,
            },
            stack: Vec::new(),
            transforms: Vec::new(),
            named_coordinates: HashMap::new(),
            named_materials: HashMap::new(),
            anonymous: 0,
            world: false,
            camera: None,
            film: None,
            sampler: None,
            integrator: None,
            filter: None,
            objects: HashMap::new(),
            object: None,
            ply_noted: false,
            textures: HashMap::new(),
            float_textures: HashMap::new(),
            named_media: HashMap::new(),
            left_out_media: Default::default(),
            medium_refs: Vec::new(),
            camera_medium: None,
            imaging_ratio: 1.0,
        }
    }

    /// A value written at `loc`: with its line when `loc` is in the scene file itself.
    fn node(&self, value: Value, loc: &Loc) -> Node {
        let own = *loc.file == *self.file;
        Node {
            value,
            line: if own { loc.line } else { 0 },
            column: if own { loc.column } else { 0 },
        }
    }

    fn num(&self, x: f64, loc: &Loc) -> Node {
        self.node(Value::Float(x), loc)
    }

    fn string(&self, s: &str, loc: &Loc) -> Node {
        self.node(Value::Str(s.to_string()), loc)
    }

    fn vec3(&self, v: DVec3, loc: &Loc) -> Node {
        let items = v.to_array().iter().map(|x| self.num(*x, loc)).collect();
        self.node(Value::Array(items), loc)
    }

    fn table(&self, entries: Vec<(&str, Node)>, loc: &Loc) -> Node {
        let mut t = Table::default();
        for (k, v) in entries {
            t.insert(k, v);
        }
        self.node(Value::Table(t), loc)
    }

    /// Something foton cannot render: an error, or with `lenient` a line in the report.
    fn unsupported(&mut self, loc: &Loc, what: &str, why: &str) -> Result<()> {
        if self.lenient {
            self.report.left_out.push(format!("{loc}: {what}: {why}"));
            Ok(())
        } else {
            Err(loc.error(what, format!("{why} (--lenient renders without it)")))
        }
    }

    fn note(&mut self, loc: &Loc, what: &str, message: &str) {
        self.report.notes.push(format!("{loc}: {what}: {message}"));
    }

    fn warn(&mut self, loc: &Loc, what: &str, message: &str) {
        self.report
            .warnings
            .push(format!("{loc}: {what}: {message}"));
    }

    /// The parameters of `bag` nobody read: pbrt-v4 parameters foton does not render.
    fn finish(&mut self, bag: &mut Bag) -> Result<()> {
        let what = bag.what.clone();
        for p in bag.rest() {
            self.unsupported(
                &p.loc,
                &what,
                &format!("parameter {} is not supported", p.decl()),
            )?;
        }
        Ok(())
    }

    fn new_name(&mut self, prefix: &str) -> String {
        self.anonymous += 1;
        format!("{prefix}_{}", self.anonymous)
    }

    fn directive(&mut self, d: &Directive) -> Result<()> {
        let n = d.numbers();
        let ctm = self.state.ctm;
        if self.state.end_only
            && matches!(
                d.name.as_str(),
                "Translate"
                    | "Scale"
                    | "Rotate"
                    | "LookAt"
                    | "Transform"
                    | "ConcatTransform"
                    | "CoordSysTransform"
                    | "Identity"
            )
        {
            return Ok(());
        }
        match d.name.as_str() {
            "Identity" => self.state.ctm = DMat4::IDENTITY,
            "Translate" => self.state.ctm = ctm * DMat4::from_translation(vec(&n[0..3])),
            "Scale" => self.state.ctm = ctm * DMat4::from_scale(vec(&n[0..3])),
            "Rotate" => {
                let axis = vec(&n[1..4]);
                if axis.length_squared() == 0.0 {
                    return Err(d.loc.error("Rotate", "the axis is zero"));
                }
                self.state.ctm = ctm * DMat4::from_axis_angle(axis.normalize(), n[0].to_radians());
            }
            "LookAt" => {
                let m = look_at(vec(&n[0..3]), vec(&n[3..6]), vec(&n[6..9]))
                    .ok_or_else(|| {
                        d.loc.error(
                            "LookAt",
                            "the eye and the target coincide, or `up` is parallel to the view direction",
                        )
                    })?;
                self.state.ctm = ctm * m;
            }
            // pbrt-v4 reads the 16 numbers column by column (it transposes the matrix).
            "Transform" => self.state.ctm = DMat4::from_cols_slice(&n),
            "ConcatTransform" => self.state.ctm = ctm * DMat4::from_cols_slice(&n),
            "CoordinateSystem" => {
                self.named_coordinates.insert(d.string(0).to_string(), ctm);
            }
            "CoordSysTransform" => match self.named_coordinates.get(d.string(0)) {
                Some(m) => self.state.ctm = *m,
                None => {
                    // pbrt-v4 warns and goes on.
                    self.warn(
                        &d.loc,
                        "CoordSysTransform",
                        &format!("no coordinate system named {:?}: ignored", d.string(0)),
                    );
                }
            },
            "TransformBegin" => self.transforms.push(ctm),
            "TransformEnd" => match self.transforms.pop() {
                Some(m) => self.state.ctm = m,
                None => return Err(d.loc.error("TransformEnd", "no TransformBegin to end")),
            },
            "ReverseOrientation" => {
                self.state.reverse_orientation = !self.state.reverse_orientation
            }
            "AttributeBegin" => self.stack.push((self.state.clone(), d.loc.clone())),
            "AttributeEnd" => match self.stack.pop() {
                Some((s, _)) => self.state = s,
                None => {
                    return Err(d
                        .loc
                        .error("AttributeEnd", "unmatched: no AttributeBegin to end"));
                }
            },
            "ActiveTransform" => {
                // pbrt-v4 blurs between a start and an end transform over the shutter;
                // foton renders the start transform.
                self.state.end_only = d.string(0) == "EndTime";
                if d.string(0) != "All" {
                    self.warn(
                        &d.loc,
                        &format!("ActiveTransform {}", d.string(0)),
                        "motion blur is not rendered: foton renders the start transform (the transforms written under ActiveTransform EndTime are not used)",
                    );
                }
            }
            "TransformTimes" => {}
            "WorldBegin" => {
                if self.world {
                    return Err(d.loc.error("WorldBegin", "a second WorldBegin"));
                }
                self.world = true;
                if self.camera.is_none() {
                    // pbrt-v4's default camera: perspective, camera space = world space.
                    let default = Directive {
                        name: "Camera".into(),
                        loc: d.loc.clone(),
                        args: vec![parse::Arg::Str("perspective".into())],
                        params: Vec::new(),
                    };
                    self.camera = Some((default, ctm));
                }
                self.state.ctm = DMat4::IDENTITY;
                self.named_coordinates
                    .insert("world".into(), DMat4::IDENTITY);
            }
            "WorldEnd" => {
                self.note(&d.loc, "WorldEnd", "a pbrt-v3 statement: read and ignored");
            }
            "Camera" => {
                if self.world {
                    return Err(d
                        .loc
                        .error("Camera", "after WorldBegin: the camera comes before it"));
                }
                self.named_coordinates
                    .insert("camera".into(), ctm.inverse());
                self.camera = Some((d.clone(), ctm));
                self.camera_medium = (!self.state.outside.is_empty()).then(|| {
                    let at = self.state.interface.clone().unwrap_or(d.loc.clone());
                    (self.state.outside.clone(), at)
                });
            }
            "Film" => self.film = Some(d.clone()),
            "Sampler" => self.sampler = Some(d.clone()),
            "Integrator" => self.integrator = Some(d.clone()),
            "PixelFilter" => self.filter = Some(d.clone()),
            "Accelerator" => self.note(
                &d.loc,
                &d.what(),
                "read and ignored: foton builds its own BVH",
            ),
            "ColorSpace" => {
                if d.string(0) != "srgb" {
                    self.unsupported(&d.loc, &d.what(), "foton renders in linear sRGB only")?;
                }
            }
            "Option" => {
                let mut names: Vec<String> = d.params.iter().map(|p| p.decl()).collect();
                if let Some(parse::Arg::Str(name)) = d.args.first() {
                    names.push(format!("{name:?}"));
                }
                self.warn(
                    &d.loc,
                    "Option",
                    &format!("{} ignored (it changes how pbrt-v4 runs)", names.join(", ")),
                );
            }
            "Material" => {
                let name = self.new_name("material");
                // Left out (lenient): pbrt-v4's default material stands in.
                self.state.material = self.material(d, &name)?.then_some(name);
            }
            "MakeNamedMaterial" => {
                let pbrt_name = d.string(0).to_string();
                let name = self.material_key(&pbrt_name);
                if self.material(d, &name)? {
                    self.named_materials.insert(pbrt_name, name);
                }
            }
            "NamedMaterial" => {
                let name = d.string(0);
                match self.named_materials.get(name) {
                    Some(key) => self.state.material = Some(key.clone()),
                    None if self.lenient => {
                        self.report.left_out.push(format!(
                            "{}: NamedMaterial {name:?}: no such material (left out or never made): the default material stands",
                            d.loc
                        ));
                        self.state.material = None;
                    }
                    None => {
                        let mut known: Vec<&str> =
                            self.named_materials.keys().map(String::as_str).collect();
                        known.sort_unstable();
                        return Err(d.loc.error(
                            "NamedMaterial",
                            format!(
                                "no material named {name:?} (MakeNamedMaterial makes one); made: {}",
                                if known.is_empty() { "none".to_string() } else { known.join(", ") }
                            ),
                        ));
                    }
                }
            }
            "AreaLightSource" => self.state.area_light = Some(d.clone()),
            "LightSource" => self.light(d)?,
            "Shape" => {
                if let Some((_, recorded)) = &mut self.object {
                    recorded.push(Recorded {
                        d: d.clone(),
                        state: self.state.clone(),
                    });
                } else {
                    let state = self.state.clone();
                    self.shape(d, &state)?;
                }
            }
            "ObjectBegin" => {
                if self.object.is_some() {
                    return Err(d.loc.error("ObjectBegin", "inside another ObjectBegin"));
                }
                self.stack.push((self.state.clone(), d.loc.clone()));
                self.object = Some((d.string(0).to_string(), Vec::new()));
            }
            "ObjectEnd" => {
                let Some((name, shapes)) = self.object.take() else {
                    return Err(d.loc.error("ObjectEnd", "no ObjectBegin to end"));
                };
                self.objects.insert(name, shapes);
                if let Some((s, _)) = self.stack.pop() {
                    self.state = s;
                }
            }
            "ObjectInstance" => {
                let name = d.string(0);
                let Some(shapes) = self.objects.get(name).cloned() else {
                    return Err(d.loc.error(
                        "ObjectInstance",
                        format!("no object named {name:?} (ObjectBegin defines one)"),
                    ));
                };
                for Recorded {
                    d: shape,
                    mut state,
                } in shapes
                {
                    // pbrt-v4: the instance's transform applied to the object's own.
                    state.ctm = ctm * state.ctm;
                    self.shape(&shape, &state)?;
                }
            }
            "Texture" => self.texture(d)?,
            "MakeNamedMedium" => self.medium(d)?,
            "MediumInterface" => {
                // One name: the same medium on both sides.
                self.state.inside = d.string(0).to_string();
                self.state.outside = if d.args.len() > 1 {
                    d.string(1).to_string()
                } else {
                    d.string(0).to_string()
                };
                self.state.interface = Some(d.loc.clone());
            }
            "Attribute" => {
                let a = &mut self.state.attributes;
                let target = match d.string(0) {
                    "shape" => &mut a.shape,
                    "light" => &mut a.light,
                    "material" => &mut a.material,
                    "medium" => &mut a.medium,
                    "texture" => &mut a.texture,
                    other => {
                        return Err(d.loc.error(
                            "Attribute",
                            format!("unknown target {other:?}; expected shape, light, material, medium or texture"),
                        ));
                    }
                };
                target.extend(d.params.iter().cloned());
            }
            other => unreachable!("the parser knows no directive `{other}`"),
        }
        Ok(())
    }

    /// A `[materials]` key for a pbrt-v4 material name: the name itself when it is a plain
    /// TOML key, else made one (and unique).
    fn material_key(&mut self, name: &str) -> String {
        let plain = plain_key(name, "material");
        let taken = |k: &str| matches!(self.root.get("materials"), Some(Node { value: Value::Table(t), .. }) if t.get(k).is_some());
        if !taken(&plain) && plain == name {
            return plain;
        }
        let mut i = 1;
        while taken(&format!("{plain}_{i}")) {
            i += 1;
        }
        format!("{plain}_{i}")
    }

    /// The material of a shape: the current one, or pbrt-v4's default (diffuse 0.5).
    fn current_material(&mut self, state: &State) -> String {
        if let Some(m) = &state.material {
            return m.clone();
        }
        let materials = table_mut(&mut self.root, "materials");
        if materials.get("default").is_none() {
            let mut t = Table::default();
            t.insert(
                "type",
                Node {
                    value: Value::Str("diffuse".into()),
                    line: 0,
                    column: 0,
                },
            );
            materials.insert(
                "default",
                Node {
                    value: Value::Table(t),
                    line: 0,
                    column: 0,
                },
            );
        }
        "default".into()
    }

    fn finish_scene(mut self) -> Result<(Document, Report)> {
        if let Some((_, loc)) = self.stack.last() {
            return Err(loc.error("AttributeBegin", "never ended: no matching AttributeEnd"));
        }
        if !self.world {
            return Err(Error::io(
                &self.file,
                "no WorldBegin: a pbrt-v4 scene describes its world after WorldBegin",
            ));
        }
        self.scene_wide()?;
        if let Some((name, loc)) = self.camera_medium.take() {
            let key = self.medium_ref(&name, &loc);
            let node = self.string(&key, &loc);
            table_mut(&mut self.root, "camera").insert("medium", node);
        }
        self.check_medium_refs()?;
        self.without_media_unless_volumetric();
        self.scale_emission(self.imaging_ratio);
        let mut root = std::mem::take(&mut self.root);
        if !self.shapes.is_empty() {
            root.insert(
                "shapes",
                Node {
                    value: Value::Array(std::mem::take(&mut self.shapes)),
                    line: 0,
                    column: 0,
                },
            );
        }
        if !self.lights.is_empty() {
            root.insert(
                "lights",
                Node {
                    value: Value::Array(std::mem::take(&mut self.lights)),
                    line: 0,
                    column: 0,
                },
            );
        }
        Ok((
            Document {
                file: self.file.clone(),
                root,
            },
            self.report,
        ))
    }
}

impl Reader {
    /// Every light's emission times `k` (the film's imaging ratio, by which pbrt-v4 scales
    /// the image: light transport is linear in the emission).
    fn scale_emission(&mut self, k: f64) {
        if k == 1.0 {
            return;
        }
        let scale = |node: &mut Node| match &mut node.value {
            Value::Float(x) => *x *= k,
            Value::Int(i) => node.value = Value::Float(*i as f64 * k),
            Value::Array(a) => a.iter_mut().for_each(|n| {
                if let Some(x) = n.value.as_f64() {
                    n.value = Value::Float(x * k);
                }
            }),
            _ => {}
        };
        for l in &mut self.lights {
            if let Value::Table(t) = &mut l.value {
                for key in ["intensity", "irradiance", "radiance", "scale"] {
                    if let Some(n) = t.get_mut(key) {
                        scale(n);
                    }
                }
            }
        }
        for s in &mut self.shapes {
            if let Value::Table(t) = &mut s.value
                && let Some(n) = t.get_mut("emission")
            {
                match &mut n.value {
                    Value::Table(texture) => {
                        let (line, column) = (n.line, n.column);
                        let num = |x: f64| Node {
                            value: Value::Float(x),
                            line,
                            column,
                        };
                        crate::texture::scale_texture_table(texture, DVec3::splat(k), |c| Node {
                            value: Value::Array(c.to_array().map(num).to_vec()),
                            line,
                            column,
                        })
                    }
                    _ => scale(n),
                }
            }
        }
    }

    /// pbrt-v4's integrators other than `volpath`, `simplevolpath`, `bdpt` and `mlt` ignore
    /// participating media (render.cpp warns): the scene renders as without them, so the
    /// media are dropped, with a warning.
    fn without_media_unless_volumetric(&mut self) {
        let integrator = self
            .integrator
            .as_ref()
            .map_or("volpath", |d| d.string(0))
            .to_string();
        if matches!(
            integrator.as_str(),
            "volpath" | "simplevolpath" | "bdpt" | "mlt"
        ) || self.root.get("media").is_none()
        {
            return;
        }
        let loc = self
            .integrator
            .as_ref()
            .map(|d| d.loc.clone())
            .expect("not volpath");
        self.warn(&loc, &format!("Integrator {integrator:?}"), "pbrt-v4's integrator ignores participating media (use volpath to render them): the scene is read without them");
        self.root.0.retain(|(k, _)| k != "media");
        let strip = |t: &mut Node, keys: &[&str]| {
            if let Value::Table(t) = &mut t.value {
                t.0.retain(|(k, _)| !keys.contains(&k.as_str()));
            }
        };
        if let Some(c) = self.root.get_mut("camera") {
            strip(c, &["medium"]);
        }
        for s in &mut self.shapes {
            strip(s, &["interior", "exterior"]);
        }
        for l in &mut self.lights {
            strip(l, &["medium"]);
        }
    }
}

/// `name` made a plain TOML key (other characters than letters, digits, `_` and `-` made
/// `_`; `empty` for an empty name).
fn plain_key(name: &str, empty: &str) -> String {
    let key: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if key.is_empty() { empty.into() } else { key }
}

fn vec(n: &[f64]) -> DVec3 {
    DVec3::new(n[0], n[1], n[2])
}

/// pbrt-v4's `LookAt`: camera from world, with camera space's +x = up x forward (its
/// left-handed convention), +y the up made perpendicular, +z forward.
fn look_at(eye: DVec3, target: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (target - eye).try_normalize()?;
    let right = up.try_normalize()?.cross(dir).try_normalize()?;
    let new_up = dir.cross(right);
    let world_from_camera = DMat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        eye.extend(1.0),
    );
    Some(world_from_camera.inverse())
}

fn table_mut<'t>(t: &'t mut Table, key: &str) -> &'t mut Table {
    if t.get(key).is_none() {
        t.insert(
            key,
            Node {
                value: Value::Table(Table::default()),
                line: 0,
                column: 0,
            },
        );
    }
    match &mut t.get_mut(key).expect("inserted").value {
        Value::Table(inner) => inner,
        _ => unreachable!("only tables are inserted under section keys"),
    }
}
