//! `<sensor>` and what it holds: the camera (a perspective or thinlens sensor's to_world, fov
//! or focal length, aperture and focus distance, medium; a radiance meter's ray; an
//! irradiance meter nested in a shape), `<film>` (size, format, `ldrfilm`'s tone curve, a crop
//! window; a meter's one pixel) with its `<rfilter>`, and `<sampler>` (which foton sampler
//! renders Mitsuba's, sample count, seed); Mitsuba's defaults for a sensor without a film or
//! a sampler, and for a file without a sensor.

use super::object::{Obj, Prop, show};
use super::plugins::not_read;
use super::upgrade::camel_to_snake;
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
        match o.ty.as_str() {
            "radiancemeter" => return self.radiance_meter(o),
            "irradiancemeter" => {
                return Err(o.error(
                    "an irradiancemeter measures over the shape it is nested in (<shape ...><sensor type=\"irradiancemeter\"/></shape>), as Mitsuba reads it; alone it has no surface",
                ));
            }
            _ => {}
        }
        if !["perspective", "thinlens", "orthographic"].contains(&o.ty.as_str()) {
            o.props.clear();
            let m = not_read(
                "sensor",
                &o.ty,
                "foton reads the perspective, thinlens, orthographic, radiancemeter and irradiancemeter sensors",
            );
            return self.unsupported(&o, &m);
        }
        let line = o.line;
        let m = o.transform("to_world")?;
        let position = m.transform_point3(DVec3::ZERO);
        let dir = m.transform_vector3(DVec3::Z).normalize();
        let up = m.transform_vector3(DVec3::Y).normalize();
        let left = m.transform_vector3(DVec3::X);
        // A transform with a negative determinant (`<scale x="-1"/>`) mirrors the image.
        let handedness = left.dot(up.cross(dir));
        if !(handedness != 0.0 && handedness.is_finite()) {
            return Err(
                o.error("`to_world`: a degenerate sensor transform (its axes do not span space)")
            );
        }
        let mirror = handedness < 0.0;
        if o.ty == "orthographic" {
            // Camera space's [-1, 1] spans the image's width (and [-1/aspect, 1/aspect] its
            // height): the transform's scale sizes the view. Pixels stay square only if it
            // scales x and y alike.
            let (sx, sy) = (left.length(), m.transform_vector3(DVec3::Y).length());
            if (sx - sy).abs() > 1e-6 * sx.max(sy) {
                return Err(o.error(format!(
                    "`to_world` scales the orthographic view by {sx} across and {sy} up: foton's pixels are square (give the same scale to x and y)"
                )));
            }
            o.take("near_clip");
            o.take("far_clip");
            let camera = table_mut(&mut self.root, "camera");
            camera.insert("type", at(Value::Str("orthographic".into()), line));
            camera.insert("view_width", at(Value::Float(2.0 * sx), line));
            if mirror {
                camera.insert("mirror", at(Value::Bool(true), line));
            }
            camera.insert("position", vec3(position, line));
            camera.insert("look_at", vec3(position + dir, line));
            camera.insert("up", vec3(up, line));
            return self.sensor_contents(o);
        }
        let (fov, fov_axis) = field_of_view(&mut o)?;
        // A thin lens focuses at `focus_distance` along the view, by default at the far clip
        // plane (Mitsuba's ProjectiveCamera); the clip planes change nothing else foton
        // renders, and a pinhole's focus distance nothing at all.
        o.take("near_clip");
        let far_clip = o.float("far_clip", 1e4)?;
        let focus_distance = o.float("focus_distance", far_clip)?;
        let lens = if o.ty == "thinlens" {
            if !o.props.iter().any(|(n, _, _)| n == "aperture_radius") {
                return Err(o.error("a thinlens sensor needs `aperture_radius` (as Mitsuba does)"));
            }
            let radius = o.float("aperture_radius", 0.0)?;
            if !(radius >= 0.0 && radius.is_finite()) {
                return Err(o.error(format!(
                    "`aperture_radius` = {radius}: expected zero or a positive radius"
                )));
            }
            if !(focus_distance > 0.0 && focus_distance.is_finite()) {
                return Err(o.error(format!(
                    "`focus_distance` = {focus_distance}: expected a positive distance"
                )));
            }
            (radius > 0.0).then_some((radius, focus_distance))
        } else {
            None
        };
        let camera = table_mut(&mut self.root, "camera");
        if mirror {
            camera.insert("mirror", at(Value::Bool(true), line));
        }
        camera.insert("position", vec3(position, line));
        camera.insert("look_at", vec3(position + dir, line));
        camera.insert("up", vec3(up, line));
        camera.insert("fov", at(Value::Float(fov), line));
        camera.insert("fov_axis", at(Value::Str(fov_axis), line));
        if let Some((radius, focus)) = lens {
            camera.insert("lens_radius", at(Value::Float(radius), line));
            camera.insert("focus_distance", at(Value::Float(focus), line));
        }
        self.sensor_contents(o)
    }

    /// Mitsuba's `radiancemeter`: the radiance arriving at a point from one direction, its
    /// `origin` and `direction` (Mitsuba 3) or its `to_world`'s origin and +z.
    fn radiance_meter(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        let has = |o: &Obj, name: &str| o.props.iter().any(|(n, _, _)| n == name);
        let (origin, direction) = if has(&o, "to_world") {
            if has(&o, "origin") || has(&o, "direction") {
                return Err(o.error(
                    "give either `to_world` or `origin` and `direction`, not both (as Mitsuba 3 says)",
                ));
            }
            let m = o.transform("to_world")?;
            (
                m.transform_point3(DVec3::ZERO),
                m.transform_vector3(DVec3::Z),
            )
        } else {
            match (o.point("origin")?, o.point("direction")?) {
                (Some(p), Some(d)) => (p, d),
                (None, None) => (DVec3::ZERO, DVec3::Z),
                _ => {
                    return Err(o.error(
                        "give both `origin` and `direction` (or neither), as Mitsuba 3 says",
                    ));
                }
            }
        };
        let direction = direction.try_normalize().ok_or_else(|| {
            o.error("the meter's direction has no length (a zero `direction` or a degenerate `to_world`)")
        })?;
        let camera = table_mut(&mut self.root, "camera");
        camera.insert("type", at(Value::Str("radiancemeter".into()), line));
        camera.insert("position", vec3(origin, line));
        camera.insert("look_at", vec3(origin + direction, line));
        camera.insert("up", vec3(direction.any_orthonormal_vector(), line));
        self.meter = Some("radiancemeter");
        self.sensor_contents(o)
    }

    /// Mitsuba's `irradiancemeter`, nested in the shape `shape_line` reads: the mean
    /// irradiance over that shape's surface (its `[[shapes]]` entries are marked `sensor`).
    /// False: the file has a sensor already, which is the one rendered.
    pub(super) fn irradiance_meter(&mut self, mut o: Obj) -> Result<bool> {
        if self.sensor {
            self.warn(
                &o,
                o.line,
                "a second sensor: not rendered (foton renders the file's first sensor, as Mitsuba's render does)",
            );
            return Ok(false);
        }
        if o.props.iter().any(|(n, _, _)| n == "to_world") {
            return Err(o.error(
                "`to_world`: an irradiancemeter is where its shape is (Mitsuba refuses its own transform too)",
            ));
        }
        for t in ["shutter_open", "shutter_close"] {
            o.take(t);
        }
        self.sensor = true;
        self.meter = Some("irradiancemeter");
        table_mut(&mut self.root, "camera")
            .insert("type", at(Value::Str("irradiancemeter".into()), o.line));
        self.sensor_contents(o)?;
        Ok(true)
    }

    /// A sensor's medium, film, reconstruction filter and sampler.
    fn sensor_contents(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        if let Some((Prop::Ref(id), l)) = o.take("medium") {
            let name = self
                .media
                .get(&id)
                .cloned()
                .ok_or_else(|| o.error(format!("line {l}: no medium with id `{id}`")))?;
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
        // A reconstruction filter beside the film instead of in it (as exporters write):
        // Mitsuba 2 and 3 refuse the file, its intent is plain; the film takes it.
        let mut loose_filter = None;
        for child in &nested {
            if child.tag == "rfilter" {
                if loose_filter.is_some() {
                    return Err(child.error("a second reconstruction filter in the sensor"));
                }
                self.warn(
                    child,
                    child.line,
                    "a filter directly in the sensor (Mitsuba 2 and 3 take it only in the <film>): the film's filter",
                );
                loose_filter = Some(child.clone());
            }
        }
        let give_filter = |film: &mut Obj, filter: &mut Option<Obj>| -> Result<()> {
            if let Some(f) = filter.take() {
                if film
                    .props
                    .iter()
                    .any(|(_, p, _)| matches!(p, Prop::Object(c) if c.tag == "rfilter"))
                {
                    return Err(f.error("a reconstruction filter in both the sensor and its film"));
                }
                let line = f.line;
                film.props.push((String::new(), Prop::Object(f), line));
            }
            Ok(())
        };
        let (mut film, mut sampler) = (false, false);
        for child in nested {
            match child.tag.as_str() {
                "rfilter" => {}
                "film" => {
                    film = true;
                    let mut child = child;
                    give_filter(&mut child, &mut loose_filter)?;
                    self.film(child)?;
                }
                "sampler" => {
                    sampler = true;
                    self.sampler(child)?;
                }
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
        // Mitsuba's sensor without them: an hdrfilm of its defaults, 4 independent samples.
        if !film {
            let mut default = Obj {
                tag: "film".into(),
                ty: "hdrfilm".into(),
                id: None,
                props: Vec::new(),
                ..o.clone()
            };
            give_filter(&mut default, &mut loose_filter)?;
            self.film(default)?;
        }
        if !sampler {
            table_mut(&mut self.root, "render").insert("spp", at(Value::Int(4), line));
        }
        if let Some(crop) = self.crop.take() {
            self.crop_camera(&o, crop)?;
        }
        // A line of an included file is not one of the document's.
        if o.file != self.file
            && let Some((_, l)) = &mut self.sensor_medium
        {
            *l = 0;
        }
        self.leftovers(&o)
    }

    /// Mitsuba's sensor when a file has none (Mitsuba 0.6's `Scene::configure`; Mitsuba 3
    /// renders nothing without one): a perspective camera with a 45-degree field of view
    /// across the image's width, looking down +z at the scene's bounds from in front of them,
    /// on a 768 x 576 hdrfilm with 4 independent samples per pixel. Where it stands depends
    /// on the scene's bounds: the loader places it ([`Report::default_camera`]).
    pub(super) fn default_sensor(&mut self, path: &std::path::Path, left_out: bool) {
        let camera = table_mut(&mut self.root, "camera");
        camera.insert("position", vec3(DVec3::new(0.0, 0.0, -1.0), 0));
        camera.insert("look_at", vec3(DVec3::ZERO, 0));
        camera.insert("up", vec3(DVec3::Y, 0));
        camera.insert("fov", at(Value::Float(DEFAULT_FOV), 0));
        camera.insert("fov_axis", at(Value::Str("x".into()), 0));
        let film = table_mut(&mut self.root, "film");
        film.insert("width", at(Value::Int(768), 0));
        film.insert("height", at(Value::Int(576), 0));
        let mut filter = Table::default();
        filter.insert("type", at(Value::Str("gaussian".into()), 0));
        filter.insert("stddev", at(Value::Float(0.5), 0));
        film.insert("filter", at(Value::Table(filter), 0));
        table_mut(&mut self.root, "render").insert("spp", at(Value::Int(4), 0));
        self.report.default_camera = Some(DEFAULT_FOV);
        let why = if left_out {
            "no <sensor> foton reads"
        } else {
            "no <sensor>"
        };
        self.report.notes.push(format!(
            "{}: {why}: rendered by Mitsuba's default, a perspective camera (fov 45 across the width) looking down +z at the whole scene, 768 x 576 pixels, 4 samples per pixel",
            path.display()
        ));
    }

    /// A crop window (`crop_offset_x`, `crop_offset_y`, `crop_width`, `crop_height`, with
    /// the film's full size): the camera of the window alone, a narrower field of view (an
    /// orthographic camera: a narrower view) on a smaller film, shifted to the window's
    /// centre; the same pixels.
    fn crop_camera(&mut self, sensor: &Obj, crop: Crop) -> Result<()> {
        let Crop {
            x,
            y,
            width,
            height,
            full,
            line,
        } = crop;
        if (width, height) == full {
            return Ok(());
        }
        let camera = table_mut(&mut self.root, "camera");
        if let Some(view_width) = camera.get("view_width").and_then(|n| n.value.as_f64()) {
            // Orthographic: the window's part of the view, its centre in world units.
            let (full_w, full_h) = (full.0 as f64, full.1 as f64);
            let half = view_width / 2.0;
            camera.insert(
                "view_width",
                at(Value::Float(view_width * width as f64 / full_w), line),
            );
            let shift = [
                ((2 * x + width) as f64 / full_w - 1.0) * half,
                (1.0 - (2 * y + height) as f64 / full_h) * half * full_h / full_w,
            ];
            if shift != [0.0, 0.0] {
                let s = shift.map(|c| at(Value::Float(c), line)).to_vec();
                camera.insert("shift", at(Value::Array(s), line));
            }
            let film = table_mut(&mut self.root, "film");
            film.insert("width", at(Value::Int(width), line));
            film.insert("height", at(Value::Int(height), line));
            return Ok(());
        }
        let fov = camera
            .get("fov")
            .and_then(|n| n.value.as_f64())
            .unwrap_or(DEFAULT_FOV);
        let axis = match camera.get("fov_axis").map(|n| &n.value) {
            Some(Value::Str(a)) => a.clone(),
            _ => "x".into(),
        };
        let tan_v = vertical_tan(fov, &axis, full.0, full.1).ok_or_else(|| {
            sensor.error(format!(
                "`fov_axis` = {axis:?}: expected x, y, diagonal, smaller or larger"
            ))
        })?;
        let tan_crop = tan_v * height as f64 / full.1 as f64;
        let fov = 2.0 * tan_crop.atan().to_degrees();
        camera.insert("fov", at(Value::Float(fov), line));
        camera.insert("fov_axis", at(Value::Str("y".into()), line));
        // The crop's centre on the image plane at distance 1 (a window off the middle is a
        // camera shifted there; a centred one needs no shift).
        let (full_w, full_h) = (full.0 as f64, full.1 as f64);
        let shift = [
            ((2 * x + width) as f64 / full_w - 1.0) * tan_v * full_w / full_h,
            (1.0 - (2 * y + height) as f64 / full_h) * tan_v,
        ];
        if shift != [0.0, 0.0] {
            let s = shift.map(|c| at(Value::Float(c), line)).to_vec();
            camera.insert("shift", at(Value::Array(s), line));
        }
        let film = table_mut(&mut self.root, "film");
        film.insert("width", at(Value::Int(width), line));
        film.insert("height", at(Value::Int(height), line));
        Ok(())
    }

    fn film(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        let ldr = match o.ty.as_str() {
            "hdrfilm" | "tiledhdrfilm" => false,
            "ldrfilm" => true,
            // Mitsuba 0.6's film for measurements: a text file of the values (one pixel by
            // default).
            "mfilm" => {
                for name in ["file_format", "fileFormat", "digits", "variable"] {
                    o.take(name);
                }
                self.warn(
                    &o,
                    line,
                    "an mfilm writes the values as text: foton writes them as an OpenEXR image",
                );
                false
            }
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
        // Exporters write Mitsuba 0.6's names into newer files too.
        for (name, _, _) in &mut o.props {
            *name = camel_to_snake(name);
        }
        let (w, h) = if o.ty == "mfilm" { (1, 1) } else { (768, 576) };
        let mut width = o.int("width", w)?;
        let mut height = o.int("height", h)?;
        if let Some(meter) = self.meter.map(a_meter)
            && (width, height) != (1, 1)
        {
            // Mitsuba 3 refuses any other film; 0.6's radiance meter measures the same
            // ray in every pixel, its irradiance meter a part of the shape's uv square.
            if !o.v1 {
                return Err(o.error(format!(
                    "{meter} measures one value: its film is 1 x 1 pixels (Mitsuba 3 takes no other), found {width} x {height}"
                )));
            }
            let why = if self.meter == Some("irradiancemeter") {
                "Mitsuba 0.6 measures a part of the shape's uv square in each: foton measures the whole surface, their mean, on one pixel"
            } else {
                "each the same ray: foton measures it on one pixel"
            };
            self.warn(
                &o,
                line,
                &format!("a film of {width} x {height} pixels for {meter} ({why})"),
            );
            (width, height) = (1, 1);
        }
        self.crop_window(&mut o, width, height)?;
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
                "ignored (foton writes 32-bit floats: the same linear values)",
            );
            // An hdrfilm stores linear values: a gamma would only change an 8-bit copy.
            if let Some((p, l)) = o.take("gamma") {
                self.note(
                    &Obj {
                        line: l,
                        ..o.clone()
                    },
                    &format!(
                        "`gamma` = {}: ignored (an hdrfilm stores linear values)",
                        show(&p)
                    ),
                );
            }
        }
        // Luminance, alpha and the other channels Mitsuba can add are outside the RGB foton
        // writes; the RGB is the same.
        let rgb = |p: &Prop| matches!(p, Prop::Str(s) if s == "rgb");
        self.ignored(
            &mut o,
            "pixel_format",
            &rgb,
            "ignored (foton writes the RGB channels only)",
        );
        if ldr {
            self.ignored(
                &mut o,
                "component_format",
                &|_| false,
                "ignored (foton writes an 8-bit PNG)",
            );
        }
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
                    // Filters with negative lobes: Mitsuba's `B` and `C` (0.6 writes them so
                    // too; radius 2) and `lobes` (radius = lobes).
                    "mitchell" => {
                        let b = rf.float("B", 1.0 / 3.0)?;
                        let c = rf.float("C", 1.0 / 3.0)?;
                        filter.insert("b", at(Value::Float(b), l));
                        filter.insert("c", at(Value::Float(c), l));
                    }
                    "catmullrom" => {}
                    "lanczos" => {
                        let lobes = rf.int("lobes", 3)?;
                        if !(1..=64).contains(&lobes) {
                            return Err(rf.error(format!("`lobes` {lobes}: must be 1 to 64")));
                        }
                        filter.insert("lobes", at(Value::Int(lobes), l));
                    }
                    _ => {
                        rf.props.clear();
                        let m = not_read(
                            "rfilter",
                            &rf.ty,
                            "foton's filters are box, tent, gaussian, mitchell, catmullrom and lanczos",
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
        // A meter weighs its samples alike: the mean over its surface (or its ray), which
        // another filter over one pixel only weighs otherwise.
        if self.meter.is_some() {
            filter = Table::default();
            filter.insert("type", at(Value::Str("box".into()), rf_line));
        }
        if filter.get("type").is_some() {
            table_mut(&mut self.root, "film").insert("filter", at(Value::Table(filter), rf_line));
        }
        self.leftovers(&o)
    }

    /// A film's crop window, kept for the sensor ([`Reader::crop_camera`]) once it is whole.
    fn crop_window(&mut self, o: &mut Obj, width: i64, height: i64) -> Result<()> {
        let keys = [
            "crop_offset_x",
            "crop_offset_y",
            "crop_width",
            "crop_height",
        ];
        let line = keys
            .iter()
            .find_map(|k| o.props.iter().find(|(n, _, _)| n == k).map(|(_, _, l)| *l));
        let Some(line) = line else {
            return Ok(());
        };
        let x = o.int("crop_offset_x", 0)?;
        let y = o.int("crop_offset_y", 0)?;
        let w = o.int("crop_width", width)?;
        let h = o.int("crop_height", height)?;
        if x < 0 || y < 0 || w < 1 || h < 1 || x + w > width || y + h > height {
            return Err(o.error(format!(
                "the crop window {w} x {h} at {x}, {y} is not inside the {width} x {height} film"
            )));
        }
        self.crop = Some(Crop {
            x,
            y,
            width: w,
            height: h,
            full: (width, height),
            line,
        });
        Ok(())
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

/// A perspective sensor's or projector's field of view and the axis it spans (Mitsuba's
/// `fov` and `fov_axis`, or `focal_length` on 35 mm film, along the diagonal).
pub(super) fn field_of_view(o: &mut Obj) -> Result<(f64, String)> {
    let has_fov = o.props.iter().any(|(n, _, _)| n == "fov");
    Ok(if has_fov {
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
    })
}

/// Mitsuba's field of view when a file gives none.
const DEFAULT_FOV: f64 = 45.0;

/// A film's crop window and the film's full size (pixels), with the line that gives it.
pub(super) struct Crop {
    x: i64,
    y: i64,
    width: i64,
    height: i64,
    full: (i64, i64),
    line: u32,
}

/// tan of half the vertical field of view of a film `width` x `height` whose `fov` (degrees)
/// spans `axis` (Mitsuba's `fov_axis`, as foton's camera reads it). None: an unknown axis.
fn vertical_tan(fov: f64, axis: &str, width: i64, height: i64) -> Option<f64> {
    let aspect = width as f64 / height as f64;
    let t = (fov.to_radians() * 0.5).tan();
    let wide = width >= height;
    Some(match axis {
        "x" => t / aspect,
        "y" => t,
        "diagonal" => t / (1.0 + aspect * aspect).sqrt(),
        "smaller" if wide => t,
        "smaller" => t / aspect,
        "larger" if wide => t / aspect,
        "larger" => t,
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

/// A meter's plugin name with its article, for messages.
pub(super) fn a_meter(meter: &str) -> String {
    if meter.starts_with('i') {
        format!("an {meter}")
    } else {
        format!("a {meter}")
    }
}
