//! `<sensor>` and what it holds: the camera (a perspective sensor's to_world, fov or focal
//! length, medium), `<film>` (size, format, `ldrfilm`'s tone curve) with its `<rfilter>`, and
//! `<sampler>` (which foton sampler renders Mitsuba's, sample count, seed).

use super::object::{Obj, Prop, show};
use super::plugins::not_read;
use super::{Reader, at, table_mut, vec3};
use foton_core::error::Result;
use foton_core::value::{Table, Value};
use glam::DVec3;

impl Reader {
    /// The sensor's medium is the camera's. When no shape names a medium, Mitsuba's scene is
    /// that medium everywhere (every ray stays in the camera's medium), which is foton's
    /// scene medium; otherwise the shapes say where each medium is.
    pub(super) fn place_sensor_medium(&mut self) {
        let Some((name, line)) = self.sensor_medium.take() else {
            return;
        };
        table_mut(&mut self.root, "camera").insert("medium", at(Value::Str(name.clone()), line));
        if !self.shape_media {
            table_mut(&mut self.root, "scene").insert("medium", at(Value::Str(name), line));
        }
    }

    pub(super) fn sensor(&mut self, mut o: Obj) -> Result<()> {
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
