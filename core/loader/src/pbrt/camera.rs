//! The scene-wide statements: `Camera` into `[camera]`, `Film` into `[film]`, `Sampler`
//! and `Integrator` into `[render]` (and `[integrators.NAME]`), `PixelFilter` into the film's
//! `filter`, each with pbrt-v4's defaults when the file has none (cameras.cpp, film.cpp,
//! samplers.cpp, integrators.cpp, filters.cpp).

use super::params::Bag;
use super::parse::{Arg, Directive, Type};
use super::{Loc, Reader, table_mut};
use foton_core::error::Result;
use foton_core::value::{Node, Value};
use glam::{DMat4, DVec3};

impl Reader {
    pub(super) fn scene_wide(&mut self) -> Result<()> {
        let (camera, camera_from_world) = self.camera.clone().expect("set at WorldBegin");
        // The film first: the camera's window on the image plane depends on its resolution
        // and crop window.
        let film = self
            .film
            .clone()
            .unwrap_or_else(|| default("Film", "rgb", &camera.loc));
        let window = self.film(&film)?;
        self.camera(&camera, camera_from_world, window)?;
        let filter = self
            .filter
            .clone()
            .unwrap_or_else(|| default("PixelFilter", "gaussian", &camera.loc));
        self.filter(&filter, self.filter.is_some())?;
        let sampler = self
            .sampler
            .clone()
            .unwrap_or_else(|| default("Sampler", "zsobol", &camera.loc));
        self.sampler(&sampler, self.sampler.is_some())?;
        let integrator = self
            .integrator
            .clone()
            .unwrap_or_else(|| default("Integrator", "volpath", &camera.loc));
        self.integrator(&integrator)
    }

    fn camera(&mut self, d: &Directive, camera_from_world: DMat4, film: FilmWindow) -> Result<()> {
        let mut p = Bag::new(d);
        let loc = &d.loc;
        let orthographic = match d.string(0) {
            "perspective" => false,
            "orthographic" => true,
            "realistic" | "spherical" => {
                self.unsupported(
                    loc,
                    &d.what(),
                    "only the perspective and orthographic cameras are read (--lenient: a perspective camera of pbrt-v4's default fov, 90 degrees, in its place)",
                )?;
                let stand_in = Directive {
                    name: d.name.clone(),
                    loc: loc.clone(),
                    args: vec![Arg::Str("perspective".into())],
                    params: Vec::new(),
                };
                return self.camera(&stand_in, camera_from_world, film);
            }
            other => {
                return Err(loc.error(
                    &d.what(),
                    format!("unknown camera {other:?}; pbrt-v4 has perspective, orthographic, realistic and spherical"),
                ));
            }
        };
        let world_from_camera = camera_from_world.inverse();
        if !world_from_camera.is_finite() {
            return Err(loc.error(&d.what(), "the camera transform is singular"));
        }
        let position = world_from_camera.transform_point3(DVec3::ZERO);
        let forward = world_from_camera.transform_vector3(DVec3::Z);
        let up = world_from_camera.transform_vector3(DVec3::Y);
        let right = world_from_camera.transform_vector3(DVec3::X);
        if forward.length_squared() == 0.0 || up.length_squared() == 0.0 {
            return Err(loc.error(&d.what(), "the camera transform is singular"));
        }
        // pbrt's image right is camera +x; foton's is forward x up.
        let mirror = forward.cross(up).dot(right) < 0.0;
        // An orthographic camera's screen window is in camera-space units: its `t` is 1.
        let fov = if orthographic {
            90.0
        } else {
            p.float("fov", 90.0)?
        };
        if !(fov > 0.0 && fov < 180.0) {
            return Err(loc.error(
                &d.what(),
                format!("\"float fov\" {fov}: must be in (0, 180) degrees"),
            ));
        }
        let lens_radius = p.float("lensradius", 0.0)?;
        let focal_distance = p.float("focaldistance", 1e6)?;
        if !(lens_radius >= 0.0 && lens_radius.is_finite()) {
            return Err(loc.error(
                &d.what(),
                format!("\"float lensradius\" {lens_radius}: must be zero or positive"),
            ));
        }
        if !(focal_distance > 0.0 && focal_distance.is_finite()) {
            return Err(loc.error(
                &d.what(),
                format!("\"float focaldistance\" {focal_distance}: must be positive"),
            ));
        }
        if orthographic && lens_radius > 0.0 {
            self.unsupported(
                loc,
                &d.what(),
                "an orthographic camera with a lens (\"float lensradius\" > 0): rendered without the lens",
            )?;
        }
        let lens_radius = if orthographic { 0.0 } else { lens_radius };
        // pbrt-v4's screen window (cameras.cpp): [-frame, frame] x [-1, 1] for a frame wider
        // than tall, else [-1, 1] x [-1/frame, 1/frame], in units of tan(fov / 2) on the
        // plane at distance 1; the image spans it, row 0 at its top.
        let (xres, yres) = (film.full.0 as f64, film.full.1 as f64);
        let frame_given = p.float_opt("frameaspectratio")?;
        let frame = frame_given.as_ref().map_or(xres / yres, |(f, _)| *f);
        if !(frame > 0.0 && frame.is_finite()) {
            return Err(loc.error(
                &d.what(),
                format!("\"frameaspectratio\" {frame}: must be positive"),
            ));
        }
        let mut screen = if frame > 1.0 {
            [-frame, frame, -1.0, 1.0]
        } else {
            [-1.0, 1.0, -1.0 / frame, 1.0 / frame]
        };
        let custom = match p.numbers("screenwindow", &[Type::Float])? {
            Some((v, l)) if v.len() == 4 => {
                if v[1] <= v[0] || v[3] <= v[2] {
                    return Err(l.error(
                        &d.what(),
                        "\"screenwindow\" [x0 x1 y0 y1] must have x0 < x1 and y0 < y1",
                    ));
                }
                screen = [v[0], v[1], v[2], v[3]];
                true
            }
            Some((v, l)) => {
                return Err(l.error(
                    &d.what(),
                    format!("\"screenwindow\": expected 4 values, found {}", v.len()),
                ));
            }
            None => false,
        };
        let custom = custom || frame_given.is_some() || film.crop.is_some() || orthographic;
        // Times only matter with motion.
        p.float_opt("shutteropen")?;
        p.float_opt("shutterclose")?;
        self.finish(&mut p)?;
        let mut entries = vec![
            ("position", self.vec3(position, loc)),
            ("look_at", self.vec3(position + forward.normalize(), loc)),
            ("up", self.vec3(up.normalize(), loc)),
        ];
        if custom {
            // The part of the image plane the (cropped) film sees: foton's vertical field of
            // view and the window's centre (`shift`), both in units of the plane at
            // distance 1. Pixels must stay square.
            // Units of the plane at distance 1 (perspective), or world units (orthographic:
            // camera-space lengths, scaled as the camera transform scales them).
            let t = if orthographic {
                forward.length()
            } else {
                (fov.to_radians() / 2.0).tan()
            };
            let [x0, x1, y0, y1] = screen;
            if ((x1 - x0) / xres - (y1 - y0) / yres).abs() > 1e-6 * (x1 - x0) / xres {
                self.unsupported(loc, &d.what(), "a screen window whose pixels are not square is not supported (foton's pixels are square)")?;
            }
            let (px0, px1, py0, py1) = film.crop.unwrap_or((0, film.full.0, 0, film.full.1));
            let sx = |px: i64| x0 + px as f64 / xres * (x1 - x0);
            let sy = |py: i64| y1 - py as f64 / yres * (y1 - y0);
            let half = (sy(py0) - sy(py1)) / 2.0 * t;
            let centre = [(sx(px0) + sx(px1)) / 2.0 * t, (sy(py0) + sy(py1)) / 2.0 * t];
            if orthographic {
                entries.push(("type", self.string("orthographic", loc)));
                entries.push(("view_height", self.num(2.0 * half, loc)));
            } else {
                entries.push(("fov", self.num(2.0 * half.atan().to_degrees(), loc)));
                entries.push(("fov_axis", self.string("y", loc)));
            }
            if centre != [0.0, 0.0] {
                let items = centre.iter().map(|c| self.num(*c, loc)).collect();
                entries.push(("shift", self.node(Value::Array(items), loc)));
            }
        } else {
            entries.push(("fov", self.num(fov, loc)));
            entries.push(("fov_axis", self.string("smaller", loc)));
        }
        if mirror {
            entries.push(("mirror", self.node(Value::Bool(true), loc)));
        }
        if lens_radius > 0.0 {
            // Camera-space lengths, in the world's units (a uniform scale of the camera
            // transform scales them).
            let scale = forward.length();
            entries.push(("lens_radius", self.num(lens_radius * scale, loc)));
            entries.push(("focus_distance", self.num(focal_distance * scale, loc)));
        }
        let camera = self.table(entries, loc);
        self.root.insert("camera", camera);
        Ok(())
    }

    fn film(&mut self, d: &Directive) -> Result<FilmWindow> {
        let mut p = Bag::new(d);
        let loc = &d.loc;
        match d.string(0) {
            "rgb" => {}
            "gbuffer" | "spectral" => {
                self.note(loc, &d.what(), "rendered as an RGB film (foton writes RGB)");
            }
            other => {
                return Err(loc.error(
                    &d.what(),
                    format!("unknown film {other:?}; pbrt-v4 has rgb, gbuffer and spectral"),
                ));
            }
        }
        let width = p.int("xresolution", 1280)?;
        let height = p.int("yresolution", 720)?;
        if !(1..=32768).contains(&width) || !(1..=32768).contains(&height) {
            return Err(loc.error(
                &d.what(),
                format!("resolution {width} x {height}: each must be 1 to 32768"),
            ));
        }
        let filename = p.string_opt("filename")?;
        let (name, name_loc) = filename.unwrap_or(("pbrt.exr".into(), loc.clone()));
        let lower = name.to_ascii_lowercase();
        let output = if lower.ends_with(".exr") || lower.ends_with(".png") {
            name
        } else {
            let stem = std::path::Path::new(&name).with_extension("exr");
            let out = stem.to_string_lossy().into_owned();
            self.note(
                &name_loc,
                &d.what(),
                &format!("\"filename\" {name:?}: written as {out:?} (foton writes EXR or PNG)"),
            );
            out
        };
        // The sensor's imaging ratio (film.cpp's PixelSensor): the camera's exposure time
        // (shutterclose - shutteropen, scene.cpp) x ISO / 100, 1 by default; the image
        // scales with it, as with every light's emission (`Reader::imaging_ratio`).
        let iso = p.float("iso", 100.0)?;
        let shutter = |name: &str, default: f64| {
            self.camera
                .as_ref()
                .and_then(|(c, _)| {
                    c.params
                        .iter()
                        .find(|q| q.name == name)
                        .and_then(|q| match &q.values {
                            super::parse::Values::Nums(v) if v.len() == 1 => Some(v[0]),
                            _ => None,
                        })
                })
                .unwrap_or(default)
        };
        let exposure = shutter("shutterclose", 1.0) - shutter("shutteropen", 0.0);
        let ratio = exposure * iso / 100.0;
        if !(ratio > 0.0 && ratio.is_finite()) {
            return Err(loc.error(&d.what(), format!("the imaging ratio (exposure time {exposure} x iso {iso} / 100) must be positive")));
        }
        self.imaging_ratio = ratio;
        if let Some((s, l)) = p.string_opt("sensor")?
            && s != "cie1931"
        {
            self.unsupported(
                &l,
                &d.what(),
                &format!("\"string sensor\" {s:?}: only cie1931 (pbrt-v4's default) is read"),
            )?;
        }
        // 0, the default of the cie1931 sensor, is no white balance.
        if let Some((w, l)) = p.float_opt("whitebalance")?
            && w != 0.0
        {
            if !foton_core::spectrum::WHITE_BALANCE_KELVIN.contains(&w) {
                return Err(l.error(
                    &d.what(),
                    format!("\"whitebalance\" {w}: expected 0 (none) or a colour temperature between 1000 and 100000 K"),
                ));
            }
            let n = self.num(w, &l);
            table_mut(&mut self.root, "film").insert("white_balance", n);
        }
        // The pixels rendered (film.cpp): `pixelbounds` [x0 x1 y0 y1], or `cropwindow` in
        // [0, 1] (which wins), x0 = ceil(xres min(c0, c1)) and so on; the image written is
        // that window alone.
        let mut crop = None;
        if let Some((v, l)) = p.numbers("pixelbounds", &[Type::Integer])? {
            if v.len() != 4 {
                return Err(l.error(
                    &d.what(),
                    format!("\"pixelbounds\": expected 4 values, found {}", v.len()),
                ));
            }
            let b = (
                (v[0] as i64).clamp(0, width),
                (v[1] as i64).clamp(0, width),
                (v[2] as i64).clamp(0, height),
                (v[3] as i64).clamp(0, height),
            );
            crop = Some((b, l));
        }
        if let Some((v, l)) = p.numbers("cropwindow", &[Type::Float])? {
            if v.len() != 4 {
                return Err(l.error(
                    &d.what(),
                    format!("\"cropwindow\": expected 4 values, found {}", v.len()),
                ));
            }
            let c = |a: f64, b: f64| (a.min(b).clamp(0.0, 1.0), a.max(b).clamp(0.0, 1.0));
            let ((cx0, cx1), (cy0, cy1)) = (c(v[0], v[1]), c(v[2], v[3]));
            let px = |f: f64, n: i64| (n as f64 * f).ceil() as i64;
            crop = Some((
                (
                    px(cx0, width),
                    px(cx1, width),
                    px(cy0, height),
                    px(cy1, height),
                ),
                l,
            ));
        }
        let crop = match crop {
            Some(((x0, x1, y0, y1), l)) if x1 <= x0 || y1 <= y0 => {
                return Err(l.error(&d.what(), "the crop window holds no pixel"));
            }
            Some((b, _)) if b != (0, width, 0, height) => Some(b),
            _ => None,
        };
        if let Some((m, l)) = p.float_opt("maxcomponentvalue")?
            && m.is_finite()
        {
            self.warn(
                &l,
                &d.what(),
                &format!("\"maxcomponentvalue\" {m} ignored: foton does not clamp samples"),
            );
        }
        // What changes the file written, not the image.
        p.bool("savefp16", true)?;
        p.float_opt("diagonal")?;
        p.bool("writefp16", true)?;
        self.finish(&mut p)?;
        let film = table_mut(&mut self.root, "film");
        let (w, h, o) = (
            Node {
                value: Value::Int(width),
                line: 0,
                column: 0,
            },
            Node {
                value: Value::Int(height),
                line: 0,
                column: 0,
            },
            Node {
                value: Value::Str(output),
                line: 0,
                column: 0,
            },
        );
        film.insert("width", w);
        film.insert("height", h);
        film.insert("output", o);
        if let Some((x0, x1, y0, y1)) = crop {
            film.insert(
                "width",
                Node {
                    value: Value::Int(x1 - x0),
                    line: 0,
                    column: 0,
                },
            );
            film.insert(
                "height",
                Node {
                    value: Value::Int(y1 - y0),
                    line: 0,
                    column: 0,
                },
            );
        }
        Ok(FilmWindow {
            full: (width, height),
            crop,
        })
    }

    /// pbrt-v4's filters (filters.cpp) as foton's: `box` (radius 0.5: the pixel) and
    /// `gaussian` as they are, `triangle` as `tent`; the default gaussian of sigma 0.5 and
    /// radius 1.5 as foton's gaussian of that standard deviation (support 2).
    /// `PixelFilter`: each of pbrt-v4's filters with its `xradius` and `yradius` (filters.cpp's
    /// defaults), as foton's filter of the same profile.
    fn filter(&mut self, d: &Directive, given: bool) -> Result<()> {
        let mut p = Bag::new(d);
        let loc = &d.loc;
        let radius = |p: &mut Bag, default: f64| -> Result<(f64, f64)> {
            Ok((p.float("xradius", default)?, p.float("yradius", default)?))
        };
        let (ty, mut entries) = match d.string(0) {
            "box" => {
                let (rx, ry) = radius(&mut p, 0.5)?;
                if (rx - 0.5).abs() > 1e-9 || (ry - 0.5).abs() > 1e-9 {
                    self.unsupported(
                        loc,
                        &d.what(),
                        "a box of another radius than 0.5 (the pixel) is not read yet",
                    )?;
                }
                self.finish(&mut p)?;
                let filter = self.string("box", loc);
                table_mut(&mut self.root, "film").insert("filter", filter);
                return Ok(());
            }
            "gaussian" => {
                let (rx, ry) = radius(&mut p, 1.5)?;
                let sigma = p.float("sigma", 0.5)?;
                if given {
                    self.note(loc, &d.what(), "rendered by foton's gaussian filter of the same sigma and radius (pbrt-v4's profile, sampled with the filter's density)");
                }
                (
                    "gaussian",
                    vec![("stddev", sigma), ("radius", rx), ("radius", ry)],
                )
            }
            // pbrt-v4's triangle, max(0, r - |x|) per axis, is foton's tent of the same radii.
            "triangle" => {
                let (rx, ry) = radius(&mut p, 2.0)?;
                ("tent", vec![("radius", rx), ("radius", ry)])
            }
            "mitchell" => {
                let (rx, ry) = radius(&mut p, 2.0)?;
                let b = p.float("B", 1.0 / 3.0)?;
                let c = p.float("C", 1.0 / 3.0)?;
                (
                    "mitchell",
                    vec![("b", b), ("c", c), ("radius", rx), ("radius", ry)],
                )
            }
            "sinc" => {
                let (rx, ry) = radius(&mut p, 4.0)?;
                let tau = p.float("tau", 3.0)?;
                ("sinc", vec![("tau", tau), ("radius", rx), ("radius", ry)])
            }
            other => {
                return Err(loc.error(&d.what(), format!("unknown filter {other:?}; pbrt-v4 has box, gaussian, mitchell, sinc and triangle")));
            }
        };
        self.finish(&mut p)?;
        // The two radii become one `radius = [x, y]`.
        let ry = entries.pop().expect("radius y").1;
        let rx = entries.pop().expect("radius x").1;
        let mut table = vec![("type", self.string(ty, loc))];
        for (k, v) in entries {
            table.push((k, self.num(v, loc)));
        }
        let radius = if rx == ry {
            self.num(rx, loc)
        } else {
            let items = vec![self.num(rx, loc), self.num(ry, loc)];
            self.node(Value::Array(items), loc)
        };
        table.push(("radius", radius));
        let filter = self.table(table, loc);
        table_mut(&mut self.root, "film").insert("filter", filter);
        Ok(())
    }

    fn sampler(&mut self, d: &Directive, given: bool) -> Result<()> {
        let mut p = Bag::new(d);
        let loc = &d.loc;
        let (sampler, spp) = match d.string(0) {
            "independent" => ("independent", p.int("pixelsamples", 16)?),
            "stratified" => {
                let x = p.int("xsamples", 4)?;
                let y = p.int("ysamples", 4)?;
                if !p.bool("jitter", true)? {
                    let no = self.node(Value::Bool(false), loc);
                    table_mut(&mut self.root, "render").insert("jitter", no);
                }
                ("stratified", x * y)
            }
            kind @ ("sobol" | "zsobol" | "paddedsobol" | "halton" | "pmj02bn") => {
                let spp = p.int("pixelsamples", 16)?;
                p.string_opt("randomization")?;
                p.int_opt("seed")?;
                if given {
                    self.note(loc, &d.what(), &format!("sampled by foton's sobol sampler (Owen-scrambled Sobol points), not pbrt-v4's {kind}: the same image, other noise"));
                }
                ("sobol", spp)
            }
            other => {
                return Err(loc.error(&d.what(), format!("unknown sampler {other:?}; pbrt-v4 has independent, stratified, sobol, zsobol, paddedsobol, halton and pmj02bn")));
            }
        };
        p.int_opt("seed")?;
        if spp < 1 {
            return Err(loc.error(
                &d.what(),
                format!("{spp} samples per pixel: must be at least 1"),
            ));
        }
        self.finish(&mut p)?;
        let render = table_mut(&mut self.root, "render");
        render.insert(
            "sampler",
            Node {
                value: Value::Str(sampler.into()),
                line: 0,
                column: 0,
            },
        );
        render.insert(
            "spp",
            Node {
                value: Value::Int(spp),
                line: 0,
                column: 0,
            },
        );
        Ok(())
    }

    fn integrator(&mut self, d: &Directive) -> Result<()> {
        let mut p = Bag::new(d);
        let loc = &d.loc;
        let kind = d.string(0).to_string();
        let depth = p.int("maxdepth", 5)?;
        if depth < 0 {
            return Err(loc.error(
                &d.what(),
                format!("\"maxdepth\" {depth}: must not be negative"),
            ));
        }
        let name = match kind.as_str() {
            "path" | "volpath" => {
                if p.bool("regularize", false)? {
                    self.warn(
                        loc,
                        &d.what(),
                        "\"regularize\" ignored: foton does not regularize BSDFs",
                    );
                }
                p.string_opt("lightsampler")?;
                "path"
            }
            "bdpt" => {
                p.string_opt("lightsampler")?;
                for name in ["visualizestrategies", "visualizeweights", "regularize"] {
                    if p.bool(name, false)? {
                        self.warn(loc, &d.what(), &format!("\"{name}\" ignored"));
                    }
                }
                "bdpt"
            }
            "sppm" => {
                // pbrt-v4 runs as many iterations as the sampler has samples per pixel.
                let photons = p.int("photonsperiteration", -1)?;
                let radius = p.float("radius", 1.0)?;
                p.int_opt("seed")?;
                let iterations = match table_mut(&mut self.root, "render").get("spp") {
                    Some(n) => n.value.as_f64().unwrap_or(16.0) as i64,
                    None => 16,
                };
                let mut entries = vec![
                    ("initial_radius", self.num(radius, loc)),
                    ("iterations", self.node(Value::Int(iterations.max(1)), loc)),
                ];
                if photons > 0 {
                    entries.push(("photons_per_iteration", self.node(Value::Int(photons), loc)));
                } else {
                    let film = table_mut(&mut self.root, "film");
                    let pixels = [film.get("width"), film.get("height")]
                        .iter()
                        .map(|n| n.and_then(|n| n.value.as_f64()).unwrap_or(1.0))
                        .product::<f64>();
                    entries.push((
                        "photons_per_iteration",
                        self.node(Value::Int(pixels as i64), loc),
                    ));
                }
                let t = self.table(entries, loc);
                table_mut(&mut self.root, "integrators").insert("sppm", t);
                "sppm"
            }
            "simplepath" | "simplevolpath" | "randomwalk" => {
                // Estimators of the same image as path's by simpler means (simplepath's
                // light and BSDF sampling may each be switched off, randomwalk samples
                // directions uniformly, simplevolpath follows media with delta tracking).
                p.bool("samplelights", true)?;
                p.bool("samplebsdf", true)?;
                self.note(
                    loc,
                    &d.what(),
                    "rendered by foton's path tracer (the same image, with less noise)",
                );
                "path"
            }
            "lightpath" => {
                self.note(
                    loc,
                    &d.what(),
                    "rendered by foton's bdpt, whose light-tracing strategy is pbrt-v4's \
                     lightpath; bdpt also renders what light tracing cannot reach (specular \
                     surfaces seen directly, and what is seen in them)",
                );
                "bdpt"
            }
            "ambientocclusion" => {
                let cosine = p.bool("cossample", true)?;
                let max_distance = p.float_opt("maxdistance")?;
                let mut entries = vec![("cosine", self.node(Value::Bool(cosine), loc))];
                if let Some((r, l)) = max_distance {
                    if r.is_nan() || r <= 0.0 {
                        return Err(
                            l.error(&d.what(), format!("\"maxdistance\" {r}: must be positive"))
                        );
                    }
                    if r.is_finite() {
                        entries.push(("max_distance", self.num(r, &l)));
                    }
                }
                let t = self.table(entries, loc);
                table_mut(&mut self.root, "integrators").insert("ao", t);
                "ao"
            }
            "mlt" => {
                self.unsupported(loc, &d.what(), "not rendered (foton has no Metropolis light transport); --lenient renders it with foton's path tracer")?;
                "path"
            }
            other => {
                return Err(loc.error(&d.what(), format!("unknown integrator {other:?}; pbrt-v4 has volpath, path, bdpt, sppm, mlt, lightpath, simplepath, simplevolpath, randomwalk and ambientocclusion")));
            }
        };
        self.finish(&mut p)?;
        let render = table_mut(&mut self.root, "render");
        render.insert(
            "integrator",
            Node {
                value: Value::Str(name.into()),
                line: 0,
                column: 0,
            },
        );
        // pbrt-v4's maxdepth counts the bounces after the camera ray's first hit as foton's
        // max_depth counts scattering events: 1 is direct lighting.
        render.insert(
            "max_depth",
            Node {
                value: Value::Int(depth),
                line: 0,
                column: 0,
            },
        );
        Ok(())
    }
}

/// A statement the file does not have, with pbrt-v4's default type.
/// The film's full resolution and the pixels it renders of it (x0, x1, y0, y1; None: all).
#[derive(Clone, Copy, Debug)]
pub(super) struct FilmWindow {
    full: (i64, i64),
    crop: Option<(i64, i64, i64, i64)>,
}

fn default(name: &str, ty: &str, loc: &Loc) -> Directive {
    Directive {
        name: name.into(),
        loc: loc.clone(),
        args: vec![Arg::Str(ty.into())],
        params: Vec::new(),
    }
}
