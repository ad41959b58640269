//! `MakeNamedMedium` into `[media.NAME]` and `MediumInterface` into the media on either side
//! of the shapes that follow, the camera's and the lights' media (media.cpp, scene.cpp).
//!
//! `homogeneous` (`sigma_a`, `sigma_s`, default 1 each, or a measured `preset`, times
//! `scale`; `g`) is foton's
//! `homogeneous` medium with a Henyey-Greenstein phase function. `uniformgrid` (`density`,
//! `nx`, `ny`, `nz`, `p0`, `p1`, `sigma_a`, `sigma_s`, `scale`, `g`) is foton's
//! `heterogeneous` medium: sigma_t = (sigma_a + sigma_s) scale, albedo = sigma_s /
//! (sigma_a + sigma_s), and the density grid placed by the medium's transform (the current transform
//! at `MakeNamedMedium`) over the box [p0, p1]. pbrt-v4's `SampledGrid` has its samples at
//! the cells' centres and reads zero beyond them (a lookup between the outermost samples and
//! the box's faces falls towards zero), so the grid is written with a border of zero samples
//! one cell wide: inside the box it reads as pbrt-v4's does. (pbrt-v4 also clips the medium
//! to the box; here the half cell outside it keeps what the border interpolates to, which
//! matters only where the medium's boundary shape is larger than its box.)
//!
//! A shape whose `MediumInterface` names two different media (inside, outside; `""` is
//! vacuum) is a medium transition: its `interior` and `exterior`. pbrt-v4 ignores an
//! interface that is no transition (a ray keeps the medium it is in), and so does foton: such
//! a shape has no media of its own. The camera and the point and spot lights sit in the
//! outside medium current at their statement.

use super::params::Bag;
use super::parse::{Directive, Type, Values};
use super::spectra::{Kind, rgb};
use super::{Loc, Reader, table_mut, vec};
use foton_core::error::Result;
use foton_core::value::{Node, Value};
use glam::{DMat4, DVec3};

impl Reader {
    /// `MakeNamedMedium "name" "string type" ...`.
    pub(super) fn medium(&mut self, d: &Directive) -> Result<()> {
        let name = d.string(0).to_string();
        let mut p = Bag::new(d).with_defaults(&self.state.attributes.medium);
        let loc = d.loc.clone();
        let (ty, tloc) = p
            .string_opt("type")?
            .ok_or_else(|| loc.error(&d.what(), "missing \"string type\""))?;
        let what = format!("MakeNamedMedium {name:?} (type {ty:?})");
        p.what = what.clone();
        let key = medium_key(&name);
        if let Some(other) = self
            .named_media
            .iter()
            .find(|(n, k)| **k == key && **n != name)
        {
            return Err(loc.error(
                &what,
                format!(
                    "its name and {:?} are the same TOML key {key:?}: rename one",
                    other.0
                ),
            ));
        }
        // sigma_a and sigma_s (default 1, or a preset's), times `scale`; g.
        let coefficients = |r: &Reader,
                            p: &mut Bag,
                            preset: Option<(DVec3, DVec3)>|
         -> Result<(DVec3, DVec3, f64)> {
            let mut sigma = |n: &str| -> Result<DVec3> {
                match p.take(n) {
                    Some(q) => rgb(&q, Kind::Unbounded, &what, &r.dir),
                    None => Ok(DVec3::ONE),
                }
            };
            let (sa, ss) = match preset {
                Some((s_s, s_a)) => (s_a, s_s),
                None => (sigma("sigma_a")?, sigma("sigma_s")?),
            };
            let scale = p.float("scale", 1.0)?;
            if scale < 0.0 {
                return Err(loc.error(&what, format!("\"scale\" {scale}: must not be negative")));
            }
            let g = p.float("g", 0.0)?;
            if g.abs() >= 1.0 {
                return Err(loc.error(&what, format!("\"g\" {g}: must be within (-1, 1)")));
            }
            Ok((sa * scale, ss * scale, g))
        };
        let mut entries: Vec<(&str, Node)> = Vec::new();
        match ty.as_str() {
            "homogeneous" => {
                let preset = match p.string_opt("preset")? {
                    Some((name, l)) => match measured(&name) {
                        Some(c) => Some(c),
                        None => {
                            // pbrt-v4 warns and goes on with the coefficients given.
                            self.warn(&l, &what, &format!("no measured medium named {name:?}: sigma_a and sigma_s as given (see core/data/media/measured.csv)"));
                            None
                        }
                    },
                    None => None,
                };
                // Le (an illuminant, luminance 1) times `Lescale`.
                let le = match p.take("Le") {
                    Some(q) => rgb(&q, Kind::Illuminant, &what, &self.dir)?,
                    None => DVec3::ZERO,
                } * p.float("Lescale", 1.0)?;
                let (sa, ss, g) = coefficients(self, &mut p, preset)?;
                entries.push(("type", self.string("homogeneous", &loc)));
                entries.push(("sigma_a", self.vec3(sa, &loc)));
                entries.push(("sigma_s", self.vec3(ss, &loc)));
                if le.min_element() < 0.0 {
                    return Err(loc.error(&what, "\"Lescale\": must not be negative"));
                }
                if le != DVec3::ZERO {
                    entries.push(("emission", self.vec3(le, &loc)));
                }
                if g != 0.0 {
                    entries.push(("phase", self.phase(g, &loc)));
                }
            }
            "uniformgrid" | "rgbgrid" => {
                let rgb_grid = ty == "rgbgrid";
                let n = [p.int("nx", 1)?, p.int("ny", 1)?, p.int("nz", 1)?];
                if n.iter().any(|x| *x < 1) {
                    return Err(loc.error(
                        &what,
                        format!("\"nx\", \"ny\", \"nz\" {n:?}: must be positive"),
                    ));
                }
                let n = n.map(|x| x as usize);
                let count = n[0].checked_mul(n[1]).and_then(|c| c.checked_mul(n[2]));
                // Per sample: the extinction (1 or 3 channels) and, for an RGB grid, the albedo.
                let grid = |p: &mut Bag,
                            name: &str,
                            ty: Type,
                            width: usize|
                 -> Result<Option<(Vec<f64>, Loc)>> {
                    match p.numbers(name, &[ty])? {
                        Some((v, l)) if count.and_then(|c| c.checked_mul(width)) != Some(v.len()) => Err(l.error(
                            &what,
                            format!("\"{name}\" has {} values; expected nx ny nz = {} x {} x {} of {width}", v.len(), n[0], n[1], n[2]),
                        )),
                        v => Ok(v),
                    }
                };
                let has_sigma_a = p.has("sigma_a");
                let (extinction, albedo_grid, dloc) = if rgb_grid {
                    let sa = grid(&mut p, "sigma_a", Type::Rgb, 3)?;
                    let ss = grid(&mut p, "sigma_s", Type::Rgb, 3)?;
                    let dloc = match (&sa, &ss) {
                        (Some((_, l)), _) | (None, Some((_, l))) => l.clone(),
                        (None, None) => return Err(loc.error(&what, "an RGB grid needs \"rgb sigma_a\" or \"rgb sigma_s\" (nx ny nz colours)")),
                    };
                    let len = 3 * count.unwrap_or(0);
                    let sa = sa.map_or(vec![0.0; len], |(v, _)| v);
                    let ss = ss.map_or(vec![0.0; len], |(v, _)| v);
                    let st: Vec<f64> = sa.iter().zip(&ss).map(|(a, s)| a + s).collect();
                    let albedo: Vec<f64> = st
                        .iter()
                        .zip(&ss)
                        .map(|(t, s)| if *t > 0.0 { s / t } else { 0.0 })
                        .collect();
                    (st, Some(albedo), dloc)
                } else {
                    let (d, l) = grid(&mut p, "density", Type::Float, 1)?.ok_or_else(|| {
                        loc.error(&what, "missing \"float density\" (nx ny nz values)")
                    })?;
                    (d, None, l)
                };
                let channels = if rgb_grid { 3 } else { 1 };
                // The emitted radiance per sample (RGB), on a grid of `n` or (a constant Le
                // without `Lescale`) of one sample, which pbrt-v4 also reads as a grid.
                let emission = if rgb_grid {
                    let le = grid(&mut p, "Le", Type::Rgb, 3)?;
                    let scale = p.float("Lescale", 1.0)?;
                    match le {
                        Some(_) if !has_sigma_a => {
                            return Err(loc.error(&what, "an RGB grid with \"Le\" needs \"sigma_a\" (pbrt-v4 refuses it too)"));
                        }
                        Some((v, l)) => {
                            Some((n, v.iter().map(|x| x * scale).collect::<Vec<f64>>(), l))
                        }
                        None => None,
                    }
                } else {
                    self.temperature(&mut p, &what)?;
                    let le = match p.take("Le") {
                        Some(q) => Some((rgb(&q, Kind::Illuminant, &what, &self.dir)?, q.loc)),
                        None => None,
                    };
                    let scales = grid(&mut p, "Lescale", Type::Float, 1)?;
                    match (le, scales) {
                        (Some((c, l)), Some((v, _))) => {
                            Some((n, v.iter().flat_map(|x| (c * *x).to_array()).collect(), l))
                        }
                        (Some((c, l)), None) => Some(([1, 1, 1], c.to_array().to_vec(), l)),
                        // pbrt-v4 reads a scale without Le as no emission.
                        (None, _) => None,
                    }
                };
                let corner = |p: &mut Bag, k: &str, default: DVec3| -> Result<DVec3> {
                    Ok(p.numbers(k, &[Type::Point3])?
                        .map_or(default, |(v, _)| vec(&v)))
                };
                let p0 = corner(&mut p, "p0", DVec3::ZERO)?;
                let p1 = corner(&mut p, "p1", DVec3::ONE)?;
                let size = p1 - p0;
                if size.min_element() <= 0.0 {
                    return Err(loc.error(&what, "\"p1\" must exceed \"p0\" on every axis"));
                }
                // An RGB grid's coefficients are its grids, times `scale`; a density grid's
                // multiply sigma_a and sigma_s.
                let (sigma_t, albedo) = if rgb_grid {
                    let scale = p.float("scale", 1.0)?;
                    if scale < 0.0 {
                        return Err(
                            loc.error(&what, format!("\"scale\" {scale}: must not be negative"))
                        );
                    }
                    (DVec3::splat(scale), DVec3::ONE)
                } else {
                    let (sa, ss, _) = coefficients(self, &mut p, None)?;
                    let st = sa + ss;
                    (
                        st,
                        DVec3::select(st.cmpgt(DVec3::ZERO), ss / st, DVec3::ZERO),
                    )
                };
                let g = p.float("g", 0.0)?;
                if g.abs() >= 1.0 {
                    return Err(loc.error(&what, format!("\"g\" {g}: must be within (-1, 1)")));
                }
                // A grid of n samples over [p0, p1] as pbrt-v4's `SampledGrid` reads it.
                let sampled =
                    |r: &Reader, n: [usize; 3], values: &[f64], channels: usize, l: &Loc| {
                        let (padded, values) = bordered(n, values, channels);
                        let cell = size / DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64);
                        let padded_box = r.state.ctm
                            * DMat4::from_translation(p0 - cell)
                            * DMat4::from_scale(size + 2.0 * cell);
                        r.grid_table(padded, &values, padded_box, "zero", l)
                    };
                entries.push(("type", self.string("heterogeneous", &loc)));
                entries.push(("sigma_t", self.vec3(sigma_t, &loc)));
                match albedo_grid {
                    // Per sample, clamped beyond the outermost ones: sigma_s = albedo x
                    // sigma_t then follows pbrt-v4's interpolated sigma_s where the albedo
                    // varies slowly, also at the faces.
                    Some(a) => {
                        let unpadded =
                            self.state.ctm * DMat4::from_translation(p0) * DMat4::from_scale(size);
                        let t = self.grid_table(n, &a, unpadded, "clamp", &dloc);
                        entries.push(("albedo", t));
                    }
                    None => entries.push(("albedo", self.vec3(albedo, &loc))),
                }
                let density = sampled(self, n, &extinction, channels, &dloc);
                entries.push(("density", density));
                if let Some((res, values, l)) = emission
                    && values.iter().any(|x| *x > 0.0)
                {
                    entries.push(("emission", sampled(self, res, &values, 3, &l)));
                }
                if g != 0.0 {
                    entries.push(("phase", self.phase(g, &loc)));
                }
            }
            other @ ("cloud" | "nanovdb") => {
                self.unsupported(
                    &tloc,
                    &what,
                    &format!(
                        "the {other} medium is not read yet (--lenient: vacuum where it is named)"
                    ),
                )?;
                self.left_out_media.insert(name);
                p.rest();
                return Ok(());
            }
            other => {
                return Err(tloc.error(&what, format!("unknown medium type {other:?}; pbrt-v4 has homogeneous, uniformgrid, rgbgrid, cloud and nanovdb")));
            }
        }
        self.finish(&mut p)?;
        let t = self.table(entries, &loc);
        table_mut(&mut self.root, "media").insert(&key, t);
        self.named_media.insert(name, key);
        Ok(())
    }

    /// A grid's `temperature` (blackbody emission): refused unless all zero (pbrt-v4
    /// interpolates the temperature and then takes its blackbody, which a colour grid cannot
    /// reproduce).
    fn temperature(&mut self, p: &mut Bag, what: &str) -> Result<()> {
        for n in [
            "temperature",
            "temperatureoffset",
            "temperaturecutoff",
            "temperaturescale",
        ] {
            if let Some(q) = p.take(n)
                && n == "temperature"
                && !matches!(&q.values, Values::Nums(v) if v.iter().all(|x| *x == 0.0))
            {
                self.unsupported(
                    &q.loc,
                    what,
                    &format!(
                        "{}: media emitting by temperature are not read yet",
                        q.decl()
                    ),
                )?;
            }
        }
        Ok(())
    }

    /// A volume table of `values` on `res` samples at the cells' centres of the unit cube
    /// placed by `unit_to_world`, read as `outside` beyond them.
    fn grid_table(
        &self,
        res: [usize; 3],
        values: &[f64],
        unit_to_world: DMat4,
        outside: &str,
        loc: &Loc,
    ) -> Node {
        let resolution = res.iter().map(|x| self.num(*x as f64, loc)).collect();
        let values = values.iter().map(|x| self.num(*x, loc)).collect();
        self.table(
            vec![
                ("resolution", self.node(Value::Array(resolution), loc)),
                ("values", self.node(Value::Array(values), loc)),
                ("transform", self.matrix(unit_to_world, loc)),
                ("samples", self.string("centres", loc)),
                ("outside", self.string(outside, loc)),
            ],
            loc,
        )
    }

    fn phase(&self, g: f64, loc: &Loc) -> Node {
        self.table(
            vec![("type", self.string("hg", loc)), ("g", self.num(g, loc))],
            loc,
        )
    }

    /// The `[media]` key of a medium named in a `MediumInterface` (`""`: vacuum), the
    /// reference kept to be checked once the whole scene is read.
    pub(super) fn medium_ref(&mut self, name: &str, loc: &Loc) -> String {
        if name.is_empty() || self.left_out_media.contains(name) {
            return "vacuum".into();
        }
        self.medium_refs.push((name.to_string(), loc.clone()));
        medium_key(name)
    }

    /// Every medium named was made (pbrt-v4 allows a `MakeNamedMedium` after its use).
    pub(super) fn check_medium_refs(&mut self) -> Result<()> {
        for (name, loc) in std::mem::take(&mut self.medium_refs) {
            if !self.named_media.contains_key(&name) {
                let mut made: Vec<&str> = self.named_media.keys().map(String::as_str).collect();
                made.sort_unstable();
                return Err(loc.error(
                    "MediumInterface",
                    format!(
                        "no medium named {name:?} (MakeNamedMedium makes one); made: {}",
                        if made.is_empty() {
                            "none".into()
                        } else {
                            made.join(", ")
                        }
                    ),
                ));
            }
        }
        Ok(())
    }

    /// A shape's `interior` and `exterior` when its medium interface is a transition.
    pub(super) fn medium_sides(
        &mut self,
        state: &super::State,
        loc: &Loc,
    ) -> Vec<(&'static str, Node)> {
        if state.inside == state.outside {
            return Vec::new();
        }
        let (inside, outside) = (state.inside.clone(), state.outside.clone());
        let at = state.interface.as_ref().unwrap_or(loc);
        let i = self.medium_ref(&inside, at);
        let o = self.medium_ref(&outside, at);
        vec![
            ("interior", self.string(&i, loc)),
            ("exterior", self.string(&o, loc)),
        ]
    }
}

/// `values` (`channels` per sample) on `n` samples with a border of zeros: (n + 2) samples
/// per axis at the centres of cells of the same size, the first one a cell before the grid's.
fn bordered(n: [usize; 3], values: &[f64], channels: usize) -> ([usize; 3], Vec<f64>) {
    let padded = n.map(|x| x + 2);
    let mut out = vec![0.0; padded[0] * padded[1] * padded[2] * channels];
    for z in 0..n[2] {
        for y in 0..n[1] {
            for x in 0..n[0] {
                let to = ((z + 1) * padded[1] + y + 1) * padded[0] + x + 1;
                let from = (z * n[1] + y) * n[0] + x;
                out[to * channels..(to + 1) * channels]
                    .copy_from_slice(&values[from * channels..(from + 1) * channels]);
            }
        }
    }
    (padded, out)
}

/// A measured medium (`core/data/media/measured.csv`, pbrt-v4's presets): sigma_s and
/// sigma_a in 1/mm.
fn measured(name: &str) -> Option<(DVec3, DVec3)> {
    include_str!("../../../data/media/measured.csv")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("name,"))
        .find_map(|l| {
            let (n, rest) = l.split_once(',')?;
            if n != name {
                return None;
            }
            let v: Vec<f64> = rest
                .split(',')
                .filter_map(|x| x.trim().parse().ok())
                .collect();
            (v.len() == 6).then(|| (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5])))
        })
}

/// A medium's key in `[media]`: its name made a plain TOML key (`vacuum` is foton's name for
/// no medium).
fn medium_key(name: &str) -> String {
    match super::plain_key(name, "medium") {
        key if key == "vacuum" => "vacuum_".into(),
        key => key,
    }
}
