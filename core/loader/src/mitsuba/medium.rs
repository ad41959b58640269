//! `<medium>`: a homogeneous medium into `[media]` (sigma_s and sigma_a, sigma_t and albedo,
//! or in files older than 2.0 a measured `material`; scale), with its `<phase>` function.

use super::object::{Obj, Prop};
use super::plugins::not_read;
use super::{Reader, at, table_mut, vec3};
use foton_core::error::{Error, Result};
use foton_core::value::{Table, Value};
use glam::DVec3;

impl Reader {
    /// A medium into `[media]`; returns its name there.
    pub(super) fn medium(&mut self, mut o: Obj) -> Result<String> {
        // Henyey-Greenstein's g defaults to 0.8 in Mitsuba 3 and to 0 in Mitsuba 0.6. Mitsuba
        // 3 opens a file older than 2.0 (and takes its own default) only if each medium
        // parameter is one of its own: a homogeneous medium of sigma_t and albedo. Any other
        // (0.6's sigma_s and sigma_a, densityMultiplier, a measured material) it refuses, so
        // that file is 0.6's alone.
        let mitsuba3_reads = !self.v1
            || (o.ty == "homogeneous"
                && o.props.iter().all(|(n, _, _)| {
                    matches!(
                        n.as_str(),
                        "sigma_t"
                            | "albedo"
                            | "scale"
                            | "sample_emitters"
                            | "has_spectral_extinction"
                            | ""
                    )
                }));
        let g_default = if mitsuba3_reads { 0.8 } else { 0.0 };
        if o.ty == "heterogeneous" {
            match self.grid_unsupported(&o) {
                None => return self.heterogeneous(o, true),
                Some(why) => self.unsupported(
                    &o,
                    &format!(
                        "{why}; rendered as a homogeneous medium of the grids' mean density and albedo"
                    ),
                )?,
            }
            self.mean_volumes(&mut o)?;
            o.ty = "homogeneous".into();
            o.take("method");
            o.take("step_size");
        }
        let textured = o
            .props
            .iter()
            .any(|(_, p, _)| matches!(p, Prop::Object(v) if v.tag == "volume"));
        // Mitsuba 3's homogeneous medium takes its albedo from a volume, looked up where light
        // scatters; its extinction is constant: foton's heterogeneous medium of density 1
        // everywhere.
        let albedo_only = o
            .props
            .iter()
            .all(|(n, p, _)| n == "albedo" || !matches!(p, Prop::Object(v) if v.tag == "volume"));
        if o.ty == "homogeneous"
            && textured
            && !self.v1
            && albedo_only
            && self.grid_unsupported(&o).is_none()
        {
            return self.heterogeneous(o, false);
        }
        if o.ty == "homogeneous" && textured {
            self.unsupported(
                &o,
                "a <volume> in a homogeneous medium is not supported yet; rendered with its mean",
            )?;
            self.mean_volumes(&mut o)?;
        }
        if o.ty != "homogeneous" {
            return Err(o.error(not_read(
                "medium",
                &o.ty,
                "only homogeneous media are supported",
            )));
        }
        let line = o.line;
        let has = |o: &Obj, k: &str| o.props.iter().any(|(n, _, _)| n == k);
        let coefficients = ["sigma_s", "sigma_a", "sigma_t", "albedo"];
        // Mitsuba 0.6 writes a medium as a named measured `material`, as sigma_s and sigma_a or
        // as sigma_t and albedo (Mitsuba 3 only the last, and its upgrade drops sigma_s and
        // sigma_a: foton keeps them).
        let (sigma_s, sigma_a) = if has(&o, "material") {
            if !self.v1 {
                return Err(o.error(
                    "`material` (Mitsuba 0.6's measured media) is not Mitsuba 3's: give sigma_t and albedo",
                ));
            }
            if coefficients.iter().any(|k| has(&o, k)) {
                return Err(
                    o.error("give either a named `material` or scattering coefficients, not both")
                );
            }
            let name = o.string("material")?.unwrap_or_default();
            let found = MEASURED_MEDIA
                .iter()
                .find(|(n, ..)| n.eq_ignore_ascii_case(&name));
            let Some((_, s, a, g)) = found else {
                let names: Vec<&str> = MEASURED_MEDIA.iter().map(|(n, ..)| *n).collect();
                return Err(o.error(format!(
                    "`material`: no measured medium `{name}`; Mitsuba 0.6's are: {}",
                    names.join(", ")
                )));
            };
            // Mitsuba 0.6 scales the table by 100 and, ignoring the preset's anisotropy,
            // scatters with the reduced coefficient sigma_s (1 - g).
            let (s, a, g) = (DVec3::from(*s), DVec3::from(*a), DVec3::from(*g));
            (s * 100.0 * (DVec3::ONE - g), a * 100.0)
        } else if has(&o, "sigma_s") || has(&o, "sigma_a") {
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
        // Mitsuba 3's hint that sigma_t is the same in every channel: its volpath then
        // samples and weighs distances as if it were, which is exact when it is.
        if let Some((p, l)) = o.take("has_spectral_extinction") {
            let sigma_t = (sigma_s + sigma_a) * scale;
            let grey =
                sigma_t.max_element() - sigma_t.min_element() <= 1e-6 * sigma_t.max_element();
            if matches!(p, Prop::Bool(false)) && !grey {
                self.warn(
                    &o,
                    l,
                    "`has_spectral_extinction` = false with a sigma_t that differs between channels: foton renders the extinction of each channel (Mitsuba 3's volpath takes it as one, and its image differs)",
                );
            }
        }
        let mut t = Table::default();
        t.insert("type", at(Value::Str("homogeneous".into()), line));
        t.insert("sigma_s", vec3(sigma_s * scale, line));
        t.insert("sigma_a", vec3(sigma_a * scale, line));
        self.finish_medium(o, t, g_default)
    }

    /// A medium's table `t` completed with its `<phase>`, checked for parameters nobody read
    /// and added to `[media]`; returns its name there.
    fn finish_medium(&mut self, mut o: Obj, mut t: Table, g_default: f64) -> Result<String> {
        self.phase(&mut o, &mut t, g_default)?;
        self.leftovers(&o)?;
        let name = self.new_name("medium", &o.id);
        if let Some(id) = &o.id {
            self.media.insert(id.clone(), name.clone());
        }
        table_mut(&mut self.root, "media").insert(&name, at(Value::Table(t), o.line));
        Ok(name)
    }

    /// The `<phase>` nested in a medium, into its table `t` (`g_default`: Henyey-Greenstein's
    /// g where the file gives none).
    fn phase(&mut self, o: &mut Obj, t: &mut Table, g_default: f64) -> Result<()> {
        if let Some((Prop::Object(mut phase), l)) = o.take("") {
            match phase.ty.as_str() {
                "isotropic" => t.insert("phase", at(Value::Str("isotropic".into()), l)),
                "hg" => {
                    let g = phase.float("g", g_default)?;
                    let mut p = Table::default();
                    p.insert("type", at(Value::Str("hg".into()), l));
                    p.insert("g", at(Value::Float(g), l));
                    t.insert("phase", at(Value::Table(p), l));
                }
                _ => {
                    let m = not_read(
                        "phase",
                        &phase.ty,
                        "foton's phase functions are isotropic and hg; rendered with the isotropic one",
                    );
                    phase.props.clear();
                    self.unsupported(&phase, &m)?;
                    t.insert("phase", at(Value::Str("isotropic".into()), l));
                }
            }
            self.leftovers(&phase)?;
        }
        Ok(())
    }

    /// Why a heterogeneous medium cannot be read as foton's `heterogeneous` (None: it can):
    /// its volumes must be `gridvolume`s or `constvolume`s, interpolated trilinearly and
    /// clamped (Mitsuba 3) or zero (0.6) outside.
    pub(super) fn grid_unsupported(&self, o: &Obj) -> Option<String> {
        for (name, p, _) in &o.props {
            let Prop::Object(v) = p else { continue };
            if v.tag != "volume" {
                continue;
            }
            match v.ty.as_str() {
                "constvolume" => continue,
                "gridvolume" => {}
                other => {
                    return Some(format!(
                        "`{name}`: volume type `{other}` is not supported yet"
                    ));
                }
            }
            let value = |k: &str| {
                v.props.iter().find_map(|(n, p, _)| match p {
                    Prop::Str(s) if n == k => Some(s.clone()),
                    _ => None,
                })
            };
            if value("filter_type").is_some_and(|f| f != "bilinear" && f != "trilinear") {
                return Some(format!(
                    "`{name}`: only trilinear grid lookups are supported"
                ));
            }
            // Inside the extinction volume's box (all of the medium that exists in Mitsuba
            // 3) `mirror` reads what `clamp` reads: the sample beyond the first one,
            // mirrored, is the first. An albedo volume may be looked up beyond its box.
            let extinction = !self.v1 && (name == "sigma_t" || name == "density");
            let read = |w: &str| {
                w == "clamp" || (w == "mirror" && extinction) || (w == "repeat" && !extinction)
            };
            if value("wrap_mode").is_some_and(|w| !read(&w)) {
                return Some(format!(
                    "`{name}`: only the `clamp` wrap mode is supported{}",
                    if extinction {
                        " (and `mirror`)"
                    } else {
                        " (and `repeat`)"
                    }
                ));
            }
        }
        None
    }

    /// A heterogeneous medium into `[media]` as foton's `heterogeneous`: the extinction
    /// (`sigma_t`, 0.6's `density`) and `albedo` volumes or constants, `scale`, the phase.
    /// Unless `bounded` (Mitsuba 3's homogeneous medium with an albedo volume), a constant
    /// extinction fills all of the medium, not its volume's box.
    fn heterogeneous(&mut self, mut o: Obj, bounded: bool) -> Result<String> {
        let line = o.line;
        let mut t = Table::default();
        t.insert("type", at(Value::Str("heterogeneous".into()), line));
        let scale = o.float("scale", 1.0)?;
        let key = if o.props.iter().any(|(n, _, _)| n == "density") {
            "density"
        } else {
            "sigma_t"
        };
        let mut sigma_t = DVec3::splat(scale);
        // Mitsuba's default extinction is a constant 1.
        let extinction = self
            .volume(&mut o, key)?
            .unwrap_or(Volume::Constant(DVec3::ONE, glam::DMat4::IDENTITY));
        match extinction {
            Volume::Grid(mut g) => {
                // Mitsuba 3's medium exists only in its extinction volume's bounding box.
                if let Value::Table(g) = &mut g.value
                    && !self.v1
                {
                    g.insert("outside", at(Value::Str("box".into()), line));
                }
                t.insert("density", g)
            }
            Volume::Constant(c, to_world) => {
                sigma_t *= c;
                if self.v1 || !bounded {
                    t.insert("density", at(Value::Float(1.0), line));
                } else {
                    // A constant volume too has a box: its unit cube under its to_world.
                    let mut g = Table::default();
                    let one = |x: f64| at(Value::Float(x), line);
                    g.insert(
                        "resolution",
                        at(Value::Array(vec![one(1.0), one(1.0), one(1.0)]), line),
                    );
                    g.insert("values", at(Value::Array(vec![one(1.0)]), line));
                    g.insert("transform", super::matrix_table(to_world, line));
                    g.insert("outside", at(Value::Str("box".into()), line));
                    t.insert("density", at(Value::Table(g), line));
                }
            }
        }
        t.insert("sigma_t", vec3(sigma_t, line));
        match self.volume(&mut o, "albedo")? {
            Some(Volume::Grid(g)) => t.insert("albedo", g),
            Some(Volume::Constant(c, _)) => t.insert("albedo", vec3(c, line)),
            None => t.insert("albedo", vec3(DVec3::splat(0.75), line)),
        }
        // How Mitsuba samples distances and estimates transmittance changes noise (0.6's
        // Simpson quadrature also bias), not the medium: foton's tracking is exact.
        for k in [
            "method",
            "step_size",
            "sample_emitters",
            "has_spectral_extinction",
        ] {
            o.take(k);
        }
        self.finish_medium(o, t, if self.v1 { 0.0 } else { 0.8 })
    }

    /// A medium's volume `key`: a grid as foton's volume table, or a constant (a
    /// `constvolume`, a `<float>`, an `<rgb>`).
    pub(super) fn volume(&mut self, o: &mut Obj, key: &str) -> Result<Option<Volume>> {
        let v = match o.take(key) {
            None => return Ok(None),
            Some((Prop::Object(v), _)) if v.tag == "volume" => v,
            Some((p, l)) => {
                o.props.push((key.to_string(), p, l));
                return Ok(Some(Volume::Constant(
                    o.color(key, DVec3::ONE)?,
                    glam::DMat4::IDENTITY,
                )));
            }
        };
        let mut v = v;
        if v.ty == "constvolume" {
            let c = v.color("value", DVec3::ONE)?;
            let to_world = v.transform("to_world")?;
            self.leftovers(&v)?;
            return Ok(Some(Volume::Constant(c, to_world)));
        }
        let line = v.line;
        let file = self.filename(&mut v)?;
        let Value::Str(rel) = &file.value else {
            unreachable!("filename is a string")
        };
        let mut to_world = v.transform("to_world")?;
        v.take("filter_type");
        let repeat = matches!(v.take("wrap_mode"), Some((Prop::Str(w), _)) if w == "repeat");
        v.take("raw");
        v.take("send_data");
        let use_bbox = v.boolean("use_grid_bbox", false)?;
        let mut g = Table::default();
        if self.v1 || use_bbox {
            // Mitsuba 0.6 places the grid in the box its file gives (or `min` and `max`),
            // samples on its corners, zero beyond; Mitsuba 3 only with `use_grid_bbox`.
            let path = self.dir.join(rel);
            let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
            let f = foton_core::medium::grid::VolFile::parse(&bytes)
                .map_err(|e| v.error(format!("{}: {e}", path.display())))?;
            let (fmin, fmax) = (f.bbox.0.as_dvec3(), f.bbox.1.as_dvec3());
            let min = v.point("min")?.unwrap_or(fmin);
            let max = v.point("max")?.unwrap_or(fmax);
            to_world =
                to_world * glam::DMat4::from_translation(min) * glam::DMat4::from_scale(max - min);
            if self.v1 {
                g.insert("samples", at(Value::Str("corners".into()), line));
                g.insert("outside", at(Value::Str("zero".into()), line));
            }
        }
        if repeat {
            g.insert("outside", at(Value::Str("repeat".into()), line));
        }
        g.insert("file", file.clone());
        g.insert("transform", super::matrix_table(to_world, line));
        self.leftovers(&v)?;
        Ok(Some(Volume::Grid(at(Value::Table(g), line))))
    }

    /// A heterogeneous medium's `<volume>`s (`density` or `sigma_t`, `albedo`) replaced by
    /// their means (lenient: see [`Reader::medium`]): a `constvolume`'s value, a `gridvolume`'s
    /// mean over its cells (Mitsuba's binary `.vol` file), 1 for any other.
    fn mean_volumes(&mut self, o: &mut Obj) -> Result<()> {
        for (name, p, _) in &mut o.props {
            let Prop::Object(v) = p else { continue };
            if v.tag != "volume" {
                continue;
            }
            let mean = match v.ty.as_str() {
                "constvolume" => v.color("value", DVec3::ONE)?,
                "gridvolume" => {
                    let file = v
                        .string("filename")?
                        .ok_or_else(|| v.error("missing `filename`"))?;
                    let path = self.resolve(&v.file, &file).map_err(|looked| {
                        v.error(format!(
                            "`filename` = {file:?}: no such file in {}",
                            super::shown(&looked)
                        ))
                    })?;
                    let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
                    grid_mean(&bytes).ok_or_else(|| {
                        v.error(format!(
                            "{}: not a Mitsuba grid volume (`VOL`, version 3, float32 cells)",
                            path.display()
                        ))
                    })?
                }
                _ => DVec3::ONE,
            };
            // Mitsuba 0.6 names the extinction volume `density`, Mitsuba 3 `sigma_t`.
            if name == "density" {
                *name = "sigma_t".into();
            }
            *p = Prop::Color(mean);
        }
        Ok(())
    }
}

/// The mean of a Mitsuba `.vol` grid's cells (version 3, float32; one channel is grey, three
/// are RGB); None for anything else.
fn grid_mean(bytes: &[u8]) -> Option<DVec3> {
    let int = |at: usize| -> Option<i32> {
        Some(i32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
    };
    if bytes.get(..4)? != b"VOL\x03" || int(4)? != 1 {
        return None;
    }
    let (x, y, z, channels) = (int(8)?, int(12)?, int(16)?, int(20)?);
    if x <= 0 || y <= 0 || z <= 0 || !(channels == 1 || channels == 3) {
        return None;
    }
    let cells = (x as usize)
        .checked_mul(y as usize)?
        .checked_mul(z as usize)?;
    let data = bytes.get(48..48 + cells.checked_mul(channels as usize * 4)?)?;
    let mut sum = DVec3::ZERO;
    for cell in data.chunks_exact(channels as usize * 4) {
        let c = |i: usize| f32::from_le_bytes(cell[4 * i..4 * i + 4].try_into().unwrap_or([0; 4]));
        sum += if channels == 1 {
            DVec3::splat(c(0) as f64)
        } else {
            DVec3::new(c(0) as f64, c(1) as f64, c(2) as f64)
        };
    }
    Some(sum / cells as f64)
}

/// Mitsuba 0.6's measured media (its `materialData`): name, sigma_s, sigma_a and the
/// anisotropy g per channel (r, g, b). The first twelve are the fits of Jensen, Marschner,
/// Levoy and Hanrahan, "A Practical Model for Subsurface Light Transport" (SIGGRAPH 2001),
/// without anisotropy data; the others are from Narasimhan, Gupta, Donner, Ramamoorthi, Nayar
/// and Jensen, "Acquiring Scattering Properties of Participating Media by Dilution"
/// (SIGGRAPH 2006).
#[allow(clippy::type_complexity)]
const MEASURED_MEDIA: &[(&str, [f64; 3], [f64; 3], [f64; 3])] = &[
    (
        "Apple",
        [2.29, 2.39, 1.97],
        [0.0030, 0.0034, 0.046],
        [0.0, 0.0, 0.0],
    ),
    (
        "Chicken1",
        [0.15, 0.21, 0.38],
        [0.0015, 0.077, 0.19],
        [0.0, 0.0, 0.0],
    ),
    (
        "Chicken2",
        [0.19, 0.25, 0.32],
        [0.0018, 0.088, 0.20],
        [0.0, 0.0, 0.0],
    ),
    (
        "Cream",
        [7.38, 5.47, 3.15],
        [0.0002, 0.0028, 0.0163],
        [0.0, 0.0, 0.0],
    ),
    (
        "Ketchup",
        [0.18, 0.07, 0.03],
        [0.061, 0.97, 1.45],
        [0.0, 0.0, 0.0],
    ),
    (
        "Marble",
        [2.19, 2.62, 3.00],
        [0.0021, 0.0041, 0.0071],
        [0.0, 0.0, 0.0],
    ),
    (
        "Potato",
        [0.68, 0.70, 0.55],
        [0.0024, 0.0090, 0.12],
        [0.0, 0.0, 0.0],
    ),
    (
        "Skimmilk",
        [0.70, 1.22, 1.90],
        [0.0014, 0.0025, 0.0142],
        [0.0, 0.0, 0.0],
    ),
    (
        "Skin1",
        [0.74, 0.88, 1.01],
        [0.032, 0.17, 0.48],
        [0.0, 0.0, 0.0],
    ),
    (
        "Skin2",
        [1.09, 1.59, 1.79],
        [0.013, 0.070, 0.145],
        [0.0, 0.0, 0.0],
    ),
    (
        "Spectralon",
        [11.6, 20.4, 14.9],
        [0.00, 0.00, 0.00],
        [0.0, 0.0, 0.0],
    ),
    (
        "Wholemilk",
        [2.55, 3.21, 3.77],
        [0.0011, 0.0024, 0.014],
        [0.0, 0.0, 0.0],
    ),
    (
        "Lowfat Milk",
        [13.1157, 15.4445, 17.9572],
        [0.00287, 0.00575, 0.01150],
        [0.93200, 0.90200, 0.85900],
    ),
    (
        "Reduced Milk",
        [13.7335, 15.6003, 17.8007],
        [0.00256, 0.00511, 0.01278],
        [0.81900, 0.79700, 0.74600],
    ),
    (
        "Regular Milk",
        [18.2052, 20.3826, 22.3698],
        [0.00153, 0.00460, 0.01993],
        [0.75000, 0.71400, 0.68100],
    ),
    (
        "Espresso",
        [7.78262, 8.13050, 8.53875],
        [4.79838, 6.57512, 8.84925],
        [0.90700, 0.89600, 0.88000],
    ),
    (
        "Mint Mocha Coffee",
        [3.51133, 4.14383, 5.59667],
        [3.77200, 5.82283, 7.82000],
        [0.91000, 0.90700, 0.91400],
    ),
    (
        "Lowfat Soy Milk",
        [2.03838, 2.32875, 3.90281],
        [0.00144, 0.00719, 0.03594],
        [0.85000, 0.85300, 0.84200],
    ),
    (
        "Regular Soy Milk",
        [4.66325, 5.20183, 8.74575],
        [0.00192, 0.00958, 0.06517],
        [0.87300, 0.85800, 0.83200],
    ),
    (
        "Lowfat Chocolate Milk",
        [9.83710, 11.4954, 13.1629],
        [0.01150, 0.03680, 0.15640],
        [0.93400, 0.92700, 0.91600],
    ),
    (
        "Regular Chocolate Milk",
        [10.5685, 13.1416, 15.2202],
        [0.01006, 0.04313, 0.14375],
        [0.86200, 0.83800, 0.80600],
    ),
    (
        "Coke",
        [0.00254, 0.00299, 0.00000],
        [0.10014, 0.16503, 0.24680],
        [0.96500, 0.97200, 0.00000],
    ),
    (
        "Pepsi",
        [0.00083, 0.00203, 0.00000],
        [0.09164, 0.14158, 0.20729],
        [0.92600, 0.97900, 0.00000],
    ),
    (
        "Sprite",
        [0.00011, 0.00014, 0.00014],
        [0.00189, 0.00183, 0.00200],
        [0.94300, 0.95300, 0.95200],
    ),
    (
        "Gatorade",
        [0.03668, 0.04488, 0.05742],
        [0.02479, 0.01929, 0.00888],
        [0.93300, 0.93300, 0.93500],
    ),
    (
        "Chardonnay",
        [0.00021, 0.00033, 0.00048],
        [0.01078, 0.01186, 0.02400],
        [0.91400, 0.95800, 0.97500],
    ),
    (
        "White Zinfandel",
        [0.00022, 0.00033, 0.00046],
        [0.01207, 0.01618, 0.01984],
        [0.91900, 0.94300, 0.97200],
    ),
    (
        "Merlot",
        [0.00081, 0.00000, 0.00000],
        [0.11632, 0.25191, 0.29434],
        [0.97400, 0.00000, 0.00000],
    ),
    (
        "Budweiser Beder",
        [0.00029, 0.00055, 0.00059],
        [0.01149, 0.02491, 0.05779],
        [0.91700, 0.95600, 0.98200],
    ),
    (
        "Coors Light Beer",
        [0.00062, 0.00127, 0.00000],
        [0.00616, 0.01398, 0.03498],
        [0.91800, 0.96600, 0.00000],
    ),
    (
        "Clorox",
        [0.02731, 0.03302, 0.03695],
        [0.00335, 0.01489, 0.02630],
        [0.91200, 0.90500, 0.89200],
    ),
    (
        "Apple Juice",
        [0.00257, 0.00311, 0.00413],
        [0.01296, 0.02374, 0.05218],
        [0.94700, 0.94900, 0.94500],
    ),
    (
        "Cranberry Juice",
        [0.00196, 0.00238, 0.00301],
        [0.03944, 0.09422, 0.12426],
        [0.94700, 0.95100, 0.97400],
    ),
    (
        "Grape Juice",
        [0.00138, 0.00000, 0.00000],
        [0.10404, 0.23958, 0.29325],
        [0.96100, 0.00000, 0.00000],
    ),
    (
        "Ruby Grapefruit Juice",
        [0.15496, 0.15391, 0.15995],
        [0.08587, 0.18314, 0.25262],
        [0.92900, 0.92900, 0.93100],
    ),
    (
        "White Grapefruit Juice",
        [0.50499, 0.52742, 0.75282],
        [0.01380, 0.01883, 0.05678],
        [0.54800, 0.54500, 0.56500],
    ),
    (
        "Shampoo",
        [0.00797, 0.00874, 0.01127],
        [0.01411, 0.04569, 0.06172],
        [0.91000, 0.90500, 0.92000],
    ),
    (
        "Strawberry Shampoo",
        [0.00215, 0.00245, 0.00253],
        [0.01449, 0.05796, 0.07582],
        [0.92700, 0.93500, 0.99400],
    ),
    (
        "Head & Shoulders Shampoo",
        [0.26747, 0.27696, 0.29574],
        [0.08462, 0.15688, 0.20365],
        [0.91100, 0.89600, 0.88400],
    ),
    (
        "Lemon Tea Powder",
        [0.74489, 0.83823, 1.00158],
        [2.42881, 4.57573, 7.21270],
        [0.94600, 0.94600, 0.94900],
    ),
    (
        "Orange Juice Powder",
        [0.00193, 0.00213, 0.00226],
        [0.00145, 0.00344, 0.00786],
        [0.91900, 0.91800, 0.92200],
    ),
    (
        "Pink Lemonade Powder",
        [0.00123, 0.00133, 0.00131],
        [0.00116, 0.00237, 0.00320],
        [0.90200, 0.90200, 0.90400],
    ),
    (
        "Cappuccino Powder",
        [12.2094, 16.4659, 29.2727],
        [35.8441, 49.5470, 61.0844],
        [0.84900, 0.84300, 0.92600],
    ),
    (
        "Salt Powder",
        [0.13805, 0.15677, 0.17865],
        [0.28415, 0.32570, 0.34148],
        [0.80200, 0.79300, 0.82100],
    ),
    (
        "Sugar Powder",
        [0.00282, 0.00315, 0.00393],
        [0.01264, 0.03105, 0.05012],
        [0.92100, 0.91900, 0.93100],
    ),
    (
        "Suisse Mocha Powder",
        [30.0848, 33.4452, 38.7191],
        [17.5020, 27.0044, 35.4334],
        [0.90700, 0.89400, 0.88800],
    ),
    (
        "Pacific Ocean Surface Water",
        [0.00180, 0.00183, 0.00228],
        [0.03184, 0.03132, 0.03015],
        [0.90200, 0.82500, 0.91400],
    ),
];

/// A heterogeneous medium's volume parameter as the reader writes it.
pub(super) enum Volume {
    /// A volume table (`file`, `transform`, and where they are not the defaults `samples`
    /// and `outside`).
    Grid(foton_core::value::Node),
    /// A value and the volume's `to_world` (Mitsuba 3's medium exists only in its box).
    Constant(DVec3, glam::DMat4),
}
