//! The XML document: the file parsed, `<include>`d files read in place (each upgraded by its
//! own version, found from the folder of the file that includes it), `<path>` folders added
//! to the file resolver, `<default>`s and `$name` substituted (`-D` overrides a default),
//! `<alias>` ids, each element into an `Obj` with its properties (a `<ref>` to a top-level
//! sampler, film, filter or area emitter as that object), and `<transform>` operations
//! composed in document order. Errors name the file, line and column of the element. What
//! the document's elements mean is the element-family files' work.

use super::object::{Obj, Prop};
use super::upgrade::upgrade_v1;
use super::{Reader, forget_line, forget_lines, plugins, shown};
use foton_core::error::{Error, Location, Result};
use foton_core::spectrum::{self, Quantity, Spectrum};
use foton_core::value::{Node, Table, Value};
use glam::{DMat4, DVec3};
use std::path::Path;

impl Reader {
    /// A `-D NAME=...` that no `<default>` declares and no `$NAME` uses is a typo.
    pub(super) fn check_defines(&self, path: &Path) -> Result<()> {
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

    pub(super) fn read_file(&mut self, path: &Path, text: &str) -> Result<()> {
        let text = comments_as_pugixml_reads_them(text);
        let doc = roxmltree::Document::parse(&text).map_err(|e| {
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
        let line_of = |n: roxmltree::Node<'_, '_>| {
            let p = doc.text_pos_at(n.range().start);
            Pos {
                line: p.row,
                column: p.col,
            }
        };
        // Mitsuba 3 includes a file of one object (a `<bsdf>`, a `<shape>`...) as that object.
        let root = scene.tag_name().name();
        let fragment = path != self.file && OBJECT_TAGS.contains(&root);
        if root != "scene" && !fragment {
            let what = if path == self.file {
                "the root element must be <scene>"
            } else {
                "the root element of an included file must be <scene> or an object (<bsdf>, <shape>...)"
            };
            return Err(syntax(path, line_of(scene), what));
        }
        // Each file is upgraded by its own version, as Mitsuba 3 does with included files.
        let version = scene.attribute("version").ok_or_else(|| {
            syntax(
                path,
                line_of(scene),
                &format!(
                    "<{root}> without `version` (Mitsuba requires it, e.g. version=\"3.0.0\")"
                ),
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
        let read = if fragment {
            self.object(scene, path, &line_of)
                .map(|o| self.pending.push(o))
        } else {
            self.read_scene_children(path, scene, &line_of)
        };
        self.v1 = outer_v1;
        read
    }

    /// A `<default name value>`: the name's value unless `-D` or an earlier default gave one.
    fn declare_default(&mut self, n: roxmltree::Node<'_, '_>, path: &Path, pos: Pos) -> Result<()> {
        let name = attr(n, "name", path, pos)?;
        let value = attr(n, "value", path, pos)?;
        self.declared.insert(name.clone());
        if !self.defined.contains(&name) {
            self.defaults.entry(name).or_insert(value);
        }
        Ok(())
    }

    fn read_scene_children(
        &mut self,
        path: &Path,
        scene: roxmltree::Node<'_, '_>,
        line_of: &dyn Fn(roxmltree::Node<'_, '_>) -> Pos,
    ) -> Result<()> {
        // Mitsuba (0.6 and 3) takes a <default> inside an object too, defining the name from
        // there on: every default of the file is declared first, in document order (a use
        // before its declaration, which Mitsuba refuses, is read).
        for d in scene
            .descendants()
            .filter(|n| n.is_element() && n.tag_name().name() == "default")
        {
            self.declare_default(d, path, line_of(d))?;
        }
        for child in scene.children().filter(|n| n.is_element()) {
            let pos = line_of(child);
            match child.tag_name().name() {
                "default" => self.declare_default(child, path, pos)?,
                "include" => {
                    let file = self.subst(&attr(child, "filename", path, pos)?, path, pos)?;
                    let inc = self.resolve(path, &file).map_err(|looked| {
                        syntax(
                            path,
                            pos,
                            &format!(
                                "<include filename=\"{file}\">: no such file in {}",
                                shown(&looked)
                            ),
                        )
                    })?;
                    let text = std::fs::read_to_string(&inc).map_err(|e| Error::io(&inc, e))?;
                    self.report.included.push(inc.clone());
                    // Mitsuba resolves the included file's own includes from the folder of
                    // the file that includes it, and forgets the included file's <path>s.
                    let mark = self.search.len();
                    self.search
                        .push(path.parent().unwrap_or(Path::new("")).to_path_buf());
                    let read = self.read_file(&inc, &text);
                    self.search.truncate(mark);
                    read?;
                }
                // Resolved with the references, once every id is known.
                "alias" => {
                    let id = self.subst(&attr(child, "id", path, pos)?, path, pos)?;
                    let alias = self.subst(&attr(child, "as", path, pos)?, path, pos)?;
                    self.pending.push(Obj {
                        tag: "alias".into(),
                        ty: alias,
                        id: Some(id),
                        line: pos.line,
                        file: path.to_path_buf(),
                        props: Vec::new(),
                        v1: self.v1,
                    });
                }
                "path" => self.path(child, path, pos)?,
                _ => {
                    let obj = self.object(child, path, line_of)?;
                    self.pending.push(obj);
                }
            }
        }
        Ok(())
    }

    /// The top-level objects read, made once every id is known (Mitsuba resolves references
    /// after reading the whole file, so a `<ref>` may come before its object): the objects
    /// taken by reference first, then textures and media, then BSDFs, aliases, and the rest,
    /// each kind in document order. What an included file's objects add to the document
    /// keeps no line: the document's lines are the scene file's.
    pub(super) fn make_objects(&mut self) -> Result<()> {
        let mut pending = std::mem::take(&mut self.pending);
        let rank = |o: &Obj| match o.tag.as_str() {
            // Kept to be made where they are taken (a medium takes a phase function).
            "sampler" | "film" | "rfilter" | "phase" => 0,
            "emitter" if o.ty == "area" => 0,
            "texture" | "medium" => 1,
            "bsdf" => 2,
            "alias" => 3,
            _ => 4,
        };
        pending.sort_by_key(rank);
        for mut obj in pending {
            self.expand_refs(&mut obj, 0);
            self.v1 = obj.v1;
            if obj.tag == "alias" {
                self.alias(&obj)?;
                continue;
            }
            if obj.file == self.file {
                self.top_level(obj)?;
                continue;
            }
            let before = Snapshot::of(&self.root);
            let (shapes, lights) = (self.shapes.len(), self.lights.len());
            let textures = self.textures.clone();
            self.top_level(obj)?;
            before.forget_since(&mut self.root);
            for node in self.shapes[shapes..]
                .iter_mut()
                .chain(&mut self.lights[lights..])
            {
                forget_line(node);
            }
            for (id, t) in &mut self.textures {
                if textures.get(id) != Some(&*t) {
                    forget_lines(&Table::default(), t);
                }
            }
        }
        Ok(())
    }

    /// A `<ref>` to a sampler, film, filter or area emitter is that object, made where it is
    /// taken; an unnamed one to a medium is its parent's `medium` (a sensor's, an emitter's;
    /// a shape's says interior or exterior), not a BSDF.
    fn expand_refs(&self, o: &mut Obj, depth: u32) {
        for (name, p, _) in &mut o.props {
            match p {
                Prop::Ref(id) if depth < 16 => {
                    if let Some(obj) = self.objects.get(id.as_str()) {
                        let mut obj = obj.clone();
                        self.expand_refs(&mut obj, depth + 1);
                        if ONE_OF_A_KIND.contains(&obj.tag.as_str()) {
                            name.clear();
                        }
                        *p = Prop::Object(obj);
                    } else if name.is_empty() && self.media.contains_key(id.as_str()) {
                        *name = "medium".into();
                    }
                }
                Prop::Object(child) if depth < 16 => self.expand_refs(child, depth + 1),
                _ => {}
            }
        }
    }

    /// `<alias id="a" as="b">`: `b` names what `a` does.
    fn alias(&mut self, o: &Obj) -> Result<()> {
        let (id, alias) = (o.id.clone().unwrap_or_default(), o.ty.clone());
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
                &o.file,
                Pos {
                    line: o.line,
                    column: 1,
                },
                &format!("<alias id=\"{id}\">: no BSDF, medium or texture with that id"),
            ));
        }
        Ok(())
    }

    /// `<path value="...">`: a folder the files named after it are looked for in (Mitsuba 3's
    /// file resolver), relative to the file's own folder or found by the resolver.
    fn path(&mut self, n: roxmltree::Node<'_, '_>, file: &Path, pos: Pos) -> Result<()> {
        let value = self.subst(&attr(n, "value", file, pos)?, file, pos)?;
        let own = file.parent().unwrap_or(Path::new("")).join(&value);
        let folder = if own.is_dir() {
            Some(own)
        } else {
            self.resolve(file, &value).ok().filter(|p| p.is_dir())
        };
        match folder {
            Some(folder) => self.search.push(folder),
            None if self.lenient => self.report.left_out.push(format!(
                "{}:{}: <path value=\"{value}\">: no such folder",
                file.display(),
                pos.line
            )),
            None => {
                return Err(syntax(
                    file,
                    pos,
                    &format!(
                        "<path value=\"{value}\">: no such folder (--lenient reads on without it)"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// `$name` replaced by the default's value.
    fn subst(&self, s: &str, file: &Path, pos: Pos) -> Result<String> {
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
                    pos,
                    &format!("`${name}`: no <default name=\"{name}\"> and no -D {name}=..."),
                )
            })?;
            out.push_str(value);
            rest = &after[end..];
        }
        out.push_str(rest);
        Ok(out)
    }

    /// The first `$name` in `s` that has no value (no `<default>`, no `-D`).
    fn unresolved(&self, s: &str) -> Option<String> {
        s.split('$').skip(1).find_map(|after| {
            let end = after
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..end];
            (!self.defaults.contains_key(name)).then(|| name.to_string())
        })
    }

    /// A property whose value is a `$name` without a value (no `<default>`, no `-D`) is left
    /// out, its plugin's default standing, with a warning: Mitsuba refuses such a file, but
    /// its documentation's scenes are written so, for a script to give the values. With
    /// `lenient`, any element whose attributes name one is left out, and the report says so.
    /// True if `n` is left out.
    fn leave_out_unresolved(&self, n: roxmltree::Node<'_, '_>, file: &Path, pos: Pos) -> bool {
        let Some(name) = n.attributes().find_map(|a| self.unresolved(a.value())) else {
            return false;
        };
        let tag = n.tag_name().name();
        let value_only = VALUE_TAGS.contains(&tag)
            && n.attributes()
                .all(|a| a.name() == "value" || self.unresolved(a.value()).is_none());
        if !self.lenient && !value_only {
            return false;
        }
        self.used.borrow_mut().insert(name.clone());
        let what = match n.attribute("name") {
            Some(p) => format!("<{tag} name=\"{p}\">"),
            None => format!("<{tag}>"),
        };
        let line = format!(
            "{}:{}: {what}: `${name}` has no <default> and no -D {name}=... (its plugin's default stands)",
            file.display(),
            pos.line
        );
        if self.lenient {
            self.unresolved.borrow_mut().push(line);
        } else {
            self.late_warnings.borrow_mut().push(line);
        }
        true
    }

    fn object(
        &self,
        n: roxmltree::Node<'_, '_>,
        file: &Path,
        line_of: &dyn Fn(roxmltree::Node<'_, '_>) -> Pos,
    ) -> Result<Obj> {
        let pos = line_of(n);
        let line = pos.line;
        let get = |name: &str| -> Result<Option<String>> {
            n.attribute(name)
                .map(|v| self.subst(v, file, pos))
                .transpose()
        };
        // A type without a value (lenient): an unknown plugin, left out where it is read.
        let ty = match n.attribute("type") {
            Some(t) if self.lenient && self.unresolved(t).is_some() => t.to_string(),
            _ => get("type")?.unwrap_or_default(),
        };
        // Mitsuba finds a plugin by its file's name: `Rectangle` loads `rectangle` where the
        // file system ignores case (Windows, macOS), as the files' authors saw it do.
        let ty = match plugins::in_another_case(n.tag_name().name(), &ty) {
            Some(name) => {
                self.late_warnings.borrow_mut().push(format!(
                    "{}:{line}: <{} type=\"{ty}\">: read as `{name}` (Mitsuba's plugin names are lower case; a file system that ignores case finds `{ty}` as `{name}`)",
                    file.display(),
                    n.tag_name().name()
                ));
                name.to_string()
            }
            None => ty,
        };
        let mut obj = Obj {
            tag: n.tag_name().name().to_string(),
            ty,
            id: get("id")?,
            line,
            file: file.to_path_buf(),
            props: Vec::new(),
            v1: self.v1,
        };
        for c in n.children().filter(|c| c.is_element()) {
            let cpos = line_of(c);
            let cl = cpos.line;
            // Declared before the file's objects were read (`read_scene_children`).
            if c.tag_name().name() == "default" {
                continue;
            }
            if !OBJECT_TAGS.contains(&c.tag_name().name())
                && self.leave_out_unresolved(c, file, cpos)
            {
                continue;
            }
            let cget = |name: &str| -> Result<Option<String>> {
                c.attribute(name)
                    .map(|v| self.subst(v, file, cpos))
                    .transpose()
            };
            let name = cget("name")?.unwrap_or_default();
            let value =
                || cget("value")?.ok_or_else(|| syntax(file, cpos, "missing attribute `value`"));
            let bad = |what: &str, v: &str| syntax(file, cpos, &format!("`{name}`: {what} `{v}`"));
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
                    // Mitsuba 2 and 3 compare without case (`True`, as Python writes it).
                    let v = v.trim();
                    Prop::Bool(if v.eq_ignore_ascii_case("true") {
                        true
                    } else if v.eq_ignore_ascii_case("false") {
                        false
                    } else {
                        return Err(bad("not true or false", v));
                    })
                }
                "string" => Prop::Str(value()?),
                "rgb" => {
                    let v = value()?;
                    // Mitsuba 0.6 also reads "#rrggbb", as linear values (its <srgb> decodes
                    // them); Mitsuba 3 does not.
                    match v.trim().strip_prefix('#').filter(|_| self.v1) {
                        Some(hex) => {
                            Prop::Color(hex_color(hex).ok_or_else(|| bad("expected #rrggbb", &v))?)
                        }
                        None => {
                            let xs = numbers(&v).ok_or_else(|| bad("not a list of numbers", &v))?;
                            match xs[..] {
                                [x] => Prop::Color(DVec3::splat(x)),
                                [r, g, b] => Prop::Color(DVec3::new(r, g, b)),
                                _ => return Err(bad("expected one value or three (r, g, b)", &v)),
                            }
                        }
                    }
                }
                // Mitsuba 3 reads a <spectrum type="..."> as a texture of that plugin.
                "spectrum" if c.has_attribute("type") => {
                    let spectrum = self.object(c, file, line_of)?;
                    self.spectrum_object(spectrum, quantity(&obj, &name))?
                }
                "spectrum" => {
                    let (value, filename) = (cget("value")?, cget("filename")?);
                    let at = Place {
                        file,
                        pos: cpos,
                        name: &name,
                    };
                    Prop::Color(self.spectrum(value, filename, quantity(&obj, &name), at)?)
                }
                "blackbody" => {
                    let (temperature, scale) = (cget("temperature")?, cget("scale")?);
                    let at = Place {
                        file,
                        pos: cpos,
                        name: &name,
                    };
                    Prop::Color(self.blackbody(temperature, scale, at)?)
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
                    let id = cget("id")?.ok_or_else(|| syntax(file, cpos, "<ref> without id"))?;
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
                | "film" | "shape" | "sensor" | "integrator" | "volume" => {
                    Prop::Object(self.object(c, file, line_of)?)
                }
                other if KNOWN_UNREAD.contains(&other) => {
                    return Err(syntax(
                        file,
                        cpos,
                        &format!("<{other}> in <{}> is not supported", obj.tag),
                    ));
                }
                other => {
                    let known = PROPERTY_TAGS.iter().chain(OBJECT_TAGS).copied();
                    return Err(syntax(
                        file,
                        cpos,
                        &format!(
                            "unknown element <{other}> in <{}>{}",
                            obj.tag,
                            foton_core::error::suggestion(other, known)
                        ),
                    ));
                }
            };
            // These are one of a kind in their parent, which takes them whatever their name
            // (Mitsuba names every nested object; files write `name="rfilter"`...).
            let name = match &prop {
                Prop::Object(o) if ONE_OF_A_KIND.contains(&o.tag.as_str()) => String::new(),
                _ => name,
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
        line_of: &dyn Fn(roxmltree::Node<'_, '_>) -> Pos,
    ) -> Result<DMat4> {
        let mut m = DMat4::IDENTITY;
        for op in n.children().filter(|c| c.is_element()) {
            let lpos = line_of(op);
            let get = |name: &str| -> Result<Option<String>> {
                op.attribute(name)
                    .map(|v| self.subst(v, file, lpos))
                    .transpose()
            };
            let bad = |v: &str| {
                syntax(
                    file,
                    lpos,
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
                    .ok_or_else(|| syntax(file, lpos, &format!("<lookat> without `{name}`")))?;
                let xs = numbers(&v)
                    .filter(|x| x.len() == 3)
                    .ok_or_else(|| bad(&v))?;
                Ok(DVec3::new(xs[0], xs[1], xs[2]))
            };
            // Mitsuba 0.6 and the upgrade of older files accept `lookAt`; exporters write
            // other cases too.
            let tag = op.tag_name().name();
            let tag = if tag.eq_ignore_ascii_case("lookat") {
                "lookat"
            } else {
                tag
            };
            let step = match tag {
                "translate" => DMat4::from_translation(xyz(0.0)?),
                "scale" => DMat4::from_scale(xyz(1.0)?),
                "rotate" => {
                    let axis = xyz(0.0)?;
                    if axis.length_squared() == 0.0 {
                        return Err(syntax(file, lpos, "<rotate> about the zero vector"));
                    }
                    let angle = num("angle", 0.0)?.to_radians();
                    if self.v1 || axis.length_squared() == 1.0 {
                        DMat4::from_axis_angle(axis.normalize(), angle)
                    } else {
                        // Mitsuba 2 and 3 do not normalise the axis: c I + (1 - c) a a^T +
                        // s [a]x, which also scales and shears unless |a| = 1.
                        if (axis.length() - 1.0).abs() > 1e-6 {
                            self.late_warnings.borrow_mut().push(format!(
                                "{}:{}: <rotate> about an axis of length {:.4}: Mitsuba 3 does not normalise it, so the rotation also scales; read as Mitsuba 3 reads it (write a unit axis for a rotation alone)",
                                file.display(),
                                lpos.line,
                                axis.length()
                            ));
                        }
                        let (s, c) = angle.sin_cos();
                        let outer = |i: usize| axis * axis[i] * (1.0 - c);
                        let cross = glam::DMat3::from_cols(
                            DVec3::new(0.0, axis.z, -axis.y),
                            DVec3::new(-axis.z, 0.0, axis.x),
                            DVec3::new(axis.y, -axis.x, 0.0),
                        );
                        let m3 = glam::DMat3::from_diagonal(DVec3::splat(c))
                            + glam::DMat3::from_cols(outer(0), outer(1), outer(2))
                            + cross * s;
                        DMat4::from_mat3(m3)
                    }
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
                            lpos,
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
                        lpos,
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
}

/// Where a spectrum is written, for its messages: the file, the element and its `name`.
#[derive(Clone, Copy)]
struct Place<'a> {
    file: &'a Path,
    pos: Pos,
    name: &'a str,
}

impl Place<'_> {
    fn error(&self, tag: &str, message: &str) -> Error {
        syntax(
            self.file,
            self.pos,
            &format!("<{tag} name=\"{}\">: {message}", self.name),
        )
    }
}

/// Spectra, reduced to linear sRGB as Mitsuba 3's RGB variants reduce them, in files of every
/// version Mitsuba 3 reads; the forms only Mitsuba 0.6 reads (three values, `#rrggbb`,
/// `<blackbody>`, `<srgb>`) as 0.6 reads them (see `foton_core::spectrum`).
impl Reader {
    /// `<spectrum value="..."/>` (one value, wavelength:value pairs, or in a file older than
    /// 2.0 three values: Mitsuba 0.6's RGB builds have three spectral samples, r, g and b)
    /// or `<spectrum filename="x.spd"/>`.
    fn spectrum(
        &self,
        value: Option<String>,
        filename: Option<String>,
        quantity: Quantity,
        at: Place<'_>,
    ) -> Result<DVec3> {
        let bad = |message: &str| at.error("spectrum", message);
        let spectrum = match (value, filename) {
            (Some(v), None) if !v.contains(':') => {
                let xs = numbers(&v).ok_or_else(|| bad(&format!("`{v}` is not a number")))?;
                return match (&xs[..], self.v1) {
                    // Mitsuba 3 gives a flat emission the colour of a flat spectrum in
                    // sRGB, as its spectral variants render it, in files of every version
                    // (Mitsuba 0.6 a grey).
                    ([x], _) if quantity == Quantity::Emission => {
                        Ok(spectrum::uniform_emission(*x))
                    }
                    ([x], _) => Ok(DVec3::splat(*x)),
                    ([r, g, b], true) => Ok(DVec3::new(*r, *g, *b)),
                    (_, true) => Err(bad(&format!(
                        "`{v}`: expected one value, three (r, g, b) or wavelength:value pairs"
                    ))),
                    (_, false) => Err(bad(&format!(
                        "`{v}`: expected one value or wavelength:value pairs (Mitsuba 3 reads \
                         three values as r, g, b only in files older than version 2.0; \
                         write <rgb> for a colour)"
                    ))),
                };
            }
            (Some(v), None) => Spectrum::parse_pairs(&v).map_err(|e: String| bad(&e))?,
            (None, Some(name)) => {
                let path = self.resolve(at.file, &name).map_err(|looked| {
                    bad(&format!(
                        "filename=\"{name}\": no such file in {}",
                        shown(&looked)
                    ))
                })?;
                let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
                Spectrum::parse_spd(&text).map_err(|e| bad(&format!("{}: {e}", path.display())))?
            }
            _ => return Err(bad("expected either `value` or `filename`")),
        };
        // Mitsuba 3 reduces the spectra of older files as its own (Mitsuba 0.6 ramped them
        // to zero past their ends and weighted reflectances by no illuminant).
        Ok(spectrum.to_srgb(quantity))
    }

    /// Mitsuba 0.6's `<blackbody temperature="5000K" scale="1"/>`: Planck's law in
    /// W m⁻² sr⁻¹ nm⁻¹, reduced to RGB, times `scale`.
    fn blackbody(
        &self,
        temperature: Option<String>,
        scale: Option<String>,
        at: Place<'_>,
    ) -> Result<DVec3> {
        let bad = |message: &str| at.error("blackbody", message);
        if !self.v1 {
            return Err(bad(
                "<blackbody> is Mitsuba 0.6's; Mitsuba 3 writes <spectrum type=\"blackbody\"> \
                 with a <float name=\"temperature\">",
            ));
        }
        let t = temperature.ok_or_else(|| bad("missing attribute `temperature`"))?;
        let kelvin = t
            .trim()
            .trim_end_matches(['K', 'k'])
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|k| *k > 0.0)
            .ok_or_else(|| bad(&format!("temperature `{t}`: expected kelvins, e.g. 5000K")))?;
        let scale = match scale {
            None => 1.0,
            Some(s) => s
                .trim()
                .parse::<f64>()
                .map_err(|_| bad(&format!("scale `{s}`: not a number")))?,
        };
        let rgb = spectrum::to_srgb_v06(|l| spectrum::blackbody_v06(l, kelvin), &[]);
        Ok(rgb.max(DVec3::ZERO) * scale)
    }

    /// Mitsuba 3's spectrum plugins written as `<spectrum type="...">` with their parameters:
    /// reduced to a colour as the RGB variants reduce `<spectrum value>`s (its RGB variants
    /// cannot render `blackbody`, `regular` and `irregular`; this is what its spectral
    /// variants render). Other types (`bitmap`...) are textures.
    fn spectrum_object(&self, mut o: Obj, quantity: Quantity) -> Result<Prop> {
        let text = |o: &mut Obj, key: &str| -> Result<Vec<f64>> {
            let s = o
                .string(key)?
                .ok_or_else(|| o.error(format!("missing `{key}`")))?;
            numbers(&s).ok_or_else(|| o.error(format!("`{key}`: `{s}` is not a list of numbers")))
        };
        let bad = |o: &Obj, e: String| o.error(e);
        let color = match o.ty.as_str() {
            "blackbody" => {
                let kelvin = o.float("temperature", f64::NAN)?;
                if kelvin.is_nan() || kelvin <= 0.0 {
                    return Err(o.error("`temperature`: a positive number of kelvins is needed"));
                }
                let (lo, hi) = (
                    o.float("wavelength_min", 360.0)?,
                    o.float("wavelength_max", 830.0)?,
                );
                spectrum::to_srgb(
                    |l| {
                        (lo..=hi)
                            .contains(&l)
                            .then(|| spectrum::blackbody(l, kelvin))
                    },
                    quantity,
                )
            }
            "regular" => {
                let (lo, hi) = (
                    o.float("wavelength_min", f64::NAN)?,
                    o.float("wavelength_max", f64::NAN)?,
                );
                let values = text(&mut o, "values")?;
                let n = values.len().max(2) - 1;
                let wavelengths = (0..values.len())
                    .map(|i| lo + (hi - lo) * i as f64 / n as f64)
                    .collect();
                Spectrum::new(wavelengths, values)
                    .map_err(|e| bad(&o, e))?
                    .to_srgb(quantity)
            }
            "irregular" => {
                let wavelengths = text(&mut o, "wavelengths")?;
                let values = text(&mut o, "values")?;
                Spectrum::new(wavelengths, values)
                    .map_err(|e| bad(&o, e))?
                    .to_srgb(quantity)
            }
            "uniform" => DVec3::splat(o.float("value", f64::NAN)?),
            // In RGB variants `d65` is its colour times its scale.
            "d65" => o.color("color", DVec3::ONE)? * o.float("scale", 1.0)?,
            "srgb" => o.color("color", DVec3::splat(f64::NAN))?,
            _ => {
                o.tag = "texture".into();
                return Ok(Prop::Object(o));
            }
        };
        if let Some((key, _, _)) = o.props.first() {
            return Err(o.error(format!("unknown parameter `{key}`")));
        }
        if !color.is_finite() {
            return Err(o.error("missing parameters (`value`, `color`, `wavelength_min`...)"));
        }
        Ok(Prop::Color(color))
    }
}

/// `rrggbb` in hexadecimal, each channel over 255.
fn hex_color(hex: &str) -> Option<DVec3> {
    if hex.len() != 6 || !hex.is_ascii() {
        return None;
    }
    let channel = |i: usize| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).ok();
    Some(
        DVec3::new(
            f64::from(channel(0)?),
            f64::from(channel(1)?),
            f64::from(channel(2)?),
        ) / 255.0,
    )
}

/// What a Mitsuba 3 plugin reads its property `name` as: an emitter's radiance, irradiance
/// and intensity emit; a BSDF's indices of refraction and roughnesses have no upper bound;
/// everything else is a reflectance.
fn quantity(parent: &Obj, name: &str) -> Quantity {
    match (parent.tag.as_str(), name) {
        ("emitter", "radiance" | "irradiance" | "intensity") => Quantity::Emission,
        ("bsdf", "eta" | "k" | "alpha" | "alpha_u" | "alpha_v" | "sigma_a") => Quantity::Unbounded,
        _ => Quantity::Reflectance,
    }
}

/// The document's sections as they were, to tell what one object added: the tables of
/// named entries (materials, media) by their length, the others whole.
struct Snapshot(Vec<(String, Result<usize, Node>)>);

impl Snapshot {
    fn of(root: &Table) -> Snapshot {
        Snapshot(
            root.0
                .iter()
                .map(|(k, n)| match (&n.value, k.as_str()) {
                    (Value::Table(t), "materials" | "media") => (k.clone(), Ok(t.0.len())),
                    _ => (k.clone(), Err(n.clone())),
                })
                .collect(),
        )
    }

    /// What changed since the snapshot loses its line ([`forget_lines`]).
    fn forget_since(&self, root: &mut Table) {
        for (key, node) in &mut root.0 {
            match (
                self.0.iter().find(|(k, _)| k == key).map(|(_, s)| s),
                &mut node.value,
            ) {
                (Some(Ok(len)), Value::Table(t)) => {
                    t.0.iter_mut().skip(*len).for_each(|(_, n)| forget_line(n));
                }
                (Some(Err(old)), _) => {
                    let mut before = Table::default();
                    before.0.push((key.clone(), old.clone()));
                    let mut after = Table(vec![(key.clone(), node.clone())]);
                    forget_lines(&before, &mut after);
                    *node = after.0.remove(0).1;
                }
                _ => forget_line(node),
            }
        }
    }
}

/// Where an element starts in its file.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pos {
    line: u32,
    column: u32,
}

fn syntax(file: &Path, pos: Pos, message: &str) -> Error {
    Error::XmlSyntax {
        location: Location {
            file: file.to_path_buf(),
            line: pos.line,
            column: pos.column,
        },
        message: message.to_string(),
    }
}

fn attr(n: roxmltree::Node<'_, '_>, name: &str, file: &Path, pos: Pos) -> Result<String> {
    n.attribute(name).map(str::to_string).ok_or_else(|| {
        syntax(
            file,
            pos,
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
    "blackbody",
    "point",
    "vector",
    "transform",
    "ref",
];

/// Nested objects a parent has at most one of and finds by kind, not by name.
const ONE_OF_A_KIND: &[&str] = &["rfilter", "sampler", "film", "phase"];

/// The properties that hold one value, in `value`.
const VALUE_TAGS: &[&str] = &[
    "float", "integer", "boolean", "string", "rgb", "spectrum", "srgb",
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
    "animation",
    "alias",
    "path",
    "include",
    "default",
    "subsurface",
    "luminaire",
    "null",
];

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

/// The text with `--` inside comments made ` -` (and a `-` that ends a comment made a space):
/// XML forbids them there, but Mitsuba 2 and 3 read files with pugixml, which takes a comment
/// as everything up to the first `-->`, so that published files have them. Same length, so
/// that lines and columns stay those of the file.
fn comments_as_pugixml_reads_them(text: &str) -> std::borrow::Cow<'_, str> {
    let mut out: Option<Vec<u8>> = None;
    let bytes = text.as_bytes();
    let mut at = 0;
    while let Some(start) = text[at..].find("<!--").map(|i| at + i + 4) {
        let Some(end) = text[start..].find("-->").map(|i| start + i) else {
            break;
        };
        let body = &bytes[start..end];
        if body.windows(2).any(|w| w == b"--") || body.last() == Some(&b'-') {
            let o = out.get_or_insert_with(|| bytes.to_vec());
            for i in start..end {
                if o[i] == b'-' && (i + 1 == end || o[i + 1] == b'-') {
                    o[i] = b' ';
                }
            }
        }
        at = end + 3;
    }
    match out {
        // Only ASCII '-' became ASCII ' ': still UTF-8, so the lossy path never replaces.
        Some(o) => std::borrow::Cow::Owned(String::from_utf8_lossy(&o).into_owned()),
        None => std::borrow::Cow::Borrowed(text),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn double_hyphens_in_comments_are_blanked_keeping_positions() {
        let text = "<scene>\n<!-- a -- b --->\n<!-- fine -->\n<!-- c--d -->\n</scene>";
        let read = comments_as_pugixml_reads_them(text);
        assert_eq!(read.len(), text.len());
        assert_eq!(
            read,
            "<scene>\n<!-- a  - b  -->\n<!-- fine -->\n<!-- c -d -->\n</scene>"
        );
        assert!(roxmltree::Document::parse(&read).is_ok());
        assert!(
            roxmltree::Document::parse(text).is_err(),
            "the case the function exists for"
        );
        let clean = "<scene><!-- fine --></scene>";
        assert!(matches!(
            comments_as_pugixml_reads_them(clean),
            std::borrow::Cow::Borrowed(_)
        ));
    }
}
