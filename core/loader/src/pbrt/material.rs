//! `Material` and `MakeNamedMaterial` into `[materials.NAME]` (materials.cpp): `diffuse`,
//! `dielectric` (smooth or rough), `conductor` (named metal spectra, or `eta` and `k`; smooth
//! or rough) and `interface` (foton's `null`). pbrt-v4's rough materials use the
//! Trowbridge-Reitz (GGX) distribution with alpha = sqrt(roughness) when `remaproughness` is
//! true (its default); an alpha below 1e-3 is smooth (`EffectivelySmooth`).

use super::params::Bag;
use super::parse::{Directive, Param, Type, Values};
use super::spectra::{ETA_WAVELENGTH, Kind, eta_at_550, metal_rgb_ior, rgb};
use super::texture::Tex;
use super::{Loc, Reader, table_mut};
use foton_core::error::Result;
use foton_core::value::{Node, Value};

/// pbrt-v4's named metals (`metal-X-eta`, `metal-X-k`) that Mitsuba's measured data, which
/// foton carries, also has.
const METALS: &[&str] = &["Ag", "Al", "Au", "Cu", "CuZn", "MgO", "TiO2"];

/// The numeric parameters of pbrt-v4's materials that take a float texture (besides `eta`
/// where it is a dielectric's, and a mix's `amount`, which takes any).
const FLOAT_TEXTURE_PARAMS: &[&str] = &[
    "roughness",
    "uroughness",
    "vroughness",
    "thickness",
    "g",
    "interface.roughness",
    "interface.uroughness",
    "interface.vroughness",
    "interface.eta",
    "conductor.roughness",
    "conductor.uroughness",
    "conductor.vroughness",
];

impl Reader {
    /// Replaces the material's numeric parameters given as float textures by the textures'
    /// values where they are constant; a varying one is refused (`lenient`: left out, the
    /// parameter's default).
    fn constant_float_textures(
        &mut self,
        p: &mut Bag,
        ty: &str,
        what: &str,
    ) -> Result<Vec<(&'static str, Node)>> {
        let eta = matches!(ty, "dielectric" | "thindielectric" | "coateddiffuse");
        // foton's rough conductor and dielectric take a roughness texture.
        let varying_roughness = matches!(
            ty,
            "dielectric" | "conductor" | "coateddiffuse" | "coatedconductor"
        );
        let mut varying = Vec::new();
        for &name in FLOAT_TEXTURE_PARAMS.iter().chain(eta.then_some(&"eta")) {
            let Some(q) = p.take(name) else { continue };
            if q.ty != Type::Texture {
                p.put(q);
                continue;
            }
            match self.named_texture(&q, true, what)? {
                Some(Tex::Constant(c)) => p.put(Param {
                    ty: Type::Float,
                    values: Values::Nums(vec![c.x]),
                    ..q
                }),
                Some(Tex::Table(t))
                    if varying_roughness && name.ends_with("roughness") =>
                {
                    varying.push((name, t));
                }
                Some(Tex::Table(_)) => self.unsupported(
                    &q.loc,
                    what,
                    &format!(
                        "{}: a {name} that varies over the surface is not read yet (--lenient: its default)",
                        q.decl()
                    ),
                )?,
                None => {}
            }
        }
        Ok(varying)
    }

    /// Reads the material `d` into `[materials.name]`. false: left out (`lenient`).
    pub(super) fn material(&mut self, d: &Directive, name: &str) -> Result<bool> {
        let mut p = Bag::new(d).with_defaults(&self.state.attributes.material);
        let loc = d.loc.clone();
        // MakeNamedMaterial gives the type as a parameter.
        let (ty, what) = if d.name == "MakeNamedMaterial" {
            let (ty, _) = p
                .string_opt("type")?
                .ok_or_else(|| loc.error(&d.what(), "missing \"string type\""))?;
            (
                ty.clone(),
                format!("MakeNamedMaterial {:?} (type {ty:?})", d.string(0)),
            )
        } else {
            (d.string(0).to_string(), d.what())
        };
        // pbrt-v4's bump map: a float texture of heights (a constant one tilts nothing).
        let displacement = match p.take("displacement") {
            Some(q) if q.ty == Type::Texture => match self.named_texture(&q, true, &what)? {
                Some(Tex::Table(t)) => Some((t, q.loc.clone())),
                _ => None,
            },
            Some(q) if q.ty == Type::Float => None,
            Some(q) => {
                return Err(q.loc.error(
                    &what,
                    format!("{}: expected a float or a float texture", q.decl()),
                ));
            }
            None => None,
        };
        // pbrt-v4 reads the map as linear values at (u, 1 - v), repeated, bilinearly.
        let normal_map = p.string_opt("normalmap")?.map(|(file, l)| {
            self.table(
                vec![
                    ("type", self.string("bitmap", &l)),
                    ("filename", self.string(&file, &l)),
                    ("raw", self.node(Value::Bool(true), &l)),
                    ("to_uv", self.to_uv([1.0, -1.0], [0.0, 1.0], &l)),
                ],
                &l,
            )
        });
        let varying = self.constant_float_textures(&mut p, &ty, &what)?;
        let mut entries: Vec<(&str, Node)> = Vec::new();
        match ty.as_str() {
            "diffuse" => {
                let c = self.colour(&mut p, "reflectance", Kind::Albedo, &what)?;
                entries.push(("type", self.string("diffuse", &loc)));
                if let Some(c) = c {
                    entries.push(("reflectance", c));
                } else {
                    entries.push(("reflectance", self.vec3(glam::DVec3::splat(0.5), &loc)));
                }
            }
            "dielectric" | "conductor" => {
                let textured = if varying.is_empty() {
                    None
                } else {
                    Some(self.roughness_textures(&mut p, varying, &what, &loc)?)
                };
                let alpha = match textured {
                    Some(_) => None,
                    None => self.roughness(&mut p, &what)?,
                };
                let rough = alpha.is_some() || textured.is_some();
                if ty == "dielectric" {
                    let eta = self.eta(&mut p, &what)?;
                    if eta <= 0.0 {
                        return Err(loc.error(&what, format!("\"eta\" {eta}: must be positive")));
                    }
                    entries.push((
                        "type",
                        self.string(
                            if rough {
                                "roughdielectric"
                            } else {
                                "dielectric"
                            },
                            &loc,
                        ),
                    ));
                    entries.push(("ior", self.num(eta, &loc)));
                } else {
                    entries.push((
                        "type",
                        self.string(if rough { "roughconductor" } else { "conductor" }, &loc),
                    ));
                    if let Some(q) = p.take("reflectance") {
                        self.unsupported(&q.loc, &what, "a conductor given by its \"reflectance\" is not read yet (eta and k are)")?;
                        return Ok(false);
                    }
                    let Some((e, kk)) = self.metal_index(&mut p, ["eta", "k"], 1.0, &what, &loc)?
                    else {
                        return Ok(false);
                    };
                    entries.push(("eta", self.vec3(e, &loc)));
                    entries.push(("k", self.vec3(kk, &loc)));
                }
                if let Some(t) = textured {
                    entries.push(("distribution", self.string("ggx", &loc)));
                    entries.extend(t);
                }
                if let Some((au, av)) = alpha {
                    entries.push(("distribution", self.string("ggx", &loc)));
                    if au == av {
                        entries.push(("alpha", self.num(au, &loc)));
                    } else {
                        entries.push(("alpha_u", self.num(au, &loc)));
                        entries.push(("alpha_v", self.num(av, &loc)));
                    }
                }
            }
            "interface" => entries.push(("type", self.string("null", &loc))),
            // pbrt-v4 still takes these for `interface`, with a warning (materials.cpp).
            "" | "none" => {
                self.warn(
                    &loc,
                    &what,
                    &format!(
                        "material {ty:?} is pbrt-v3's name of \"interface\": read as interface"
                    ),
                );
                entries.push(("type", self.string("null", &loc)));
            }
            "thindielectric" => {
                let eta = self.eta(&mut p, &what)?;
                if eta <= 0.0 {
                    return Err(loc.error(&what, format!("\"eta\" {eta}: must be positive")));
                }
                entries.push(("type", self.string("thindielectric", &loc)));
                entries.push(("ior", self.num(eta, &loc)));
            }
            "diffusetransmission" => {
                // f = R / pi on the side light comes from, T / pi through: foton's blend of a
                // diffuse reflector R / w_R and a diffuse transmitter T / w_T, taken with
                // probabilities w_R and w_T (the largest channels; the rest is absorbed).
                let constant =
                    |r: &mut Reader, p: &mut Bag, name: &str| -> Result<Option<glam::DVec3>> {
                        match r.colour(p, name, Kind::Albedo, &what)? {
                            None => Ok(Some(glam::DVec3::splat(0.25))),
                            Some(Node {
                                value: Value::Array(a),
                                ..
                            }) => Ok(Some(glam::DVec3::new(
                                a[0].value.as_f64().unwrap_or(0.0),
                                a[1].value.as_f64().unwrap_or(0.0),
                                a[2].value.as_f64().unwrap_or(0.0),
                            ))),
                            Some(_) => {
                                r.unsupported(
                                    &loc,
                                    &what,
                                    &format!("a textured \"{name}\" is not read yet"),
                                )?;
                                Ok(None)
                            }
                        }
                    };
                let (Some(rr), Some(tt)) = (
                    constant(self, &mut p, "reflectance")?,
                    constant(self, &mut p, "transmittance")?,
                ) else {
                    return Ok(false);
                };
                let scale = p.float("scale", 1.0)?;
                let (rr, tt) = (rr * scale, tt * scale);
                let (wr, wt) = (rr.max_element(), tt.max_element());
                if wr + wt > 1.0 + 1e-9 {
                    self.unsupported(&loc, &what, &format!("reflectance and transmittance whose largest channels sum to {} > 1 are not read yet", wr + wt))?;
                    return Ok(false);
                }
                let mut parts = Vec::new();
                let mut weights = Vec::new();
                for (w, ty, key, c) in [
                    (wr, "diffuse", "reflectance", rr),
                    (wt, "difftrans", "transmittance", tt),
                ] {
                    if w > 0.0 {
                        let part = vec![
                            ("type", self.string(ty, &loc)),
                            (key, self.vec3(c / w, &loc)),
                        ];
                        parts.push(self.table(part, &loc));
                        weights.push(self.num(w, &loc));
                    }
                }
                if parts.is_empty() {
                    entries.push(("type", self.string("diffuse", &loc)));
                    entries.push(("reflectance", self.vec3(glam::DVec3::ZERO, &loc)));
                } else {
                    entries.push(("type", self.string("blend", &loc)));
                    entries.push(("materials", self.node(Value::Array(parts), &loc)));
                    entries.push(("weights", self.node(Value::Array(weights), &loc)));
                }
            }
            "mix" => {
                let names = match p.take("materials") {
                    Some(q) => match &q.values {
                        Values::Strs(s) if q.ty == Type::String && s.len() == 2 => s.clone(),
                        _ => {
                            return Err(q.loc.error(
                                &what,
                                format!("{}: expected two material names", q.decl()),
                            ));
                        }
                    },
                    None => {
                        return Err(
                            loc.error(&what, "missing \"string materials\" (two named materials)")
                        );
                    }
                };
                let mut parts = Vec::new();
                for n in &names {
                    let table = self.named_materials.get(n).and_then(|key| {
                        match self.root.get("materials") {
                            Some(Node {
                                value: Value::Table(t),
                                ..
                            }) => t.get(key).cloned(),
                            _ => None,
                        }
                    });
                    match table {
                        Some(t) if !matches!(&t.value, Value::Table(tt) if matches!(tt.get("type"), Some(Node { value: Value::Str(k), .. }) if k == "null")) => {
                            parts.push(t)
                        }
                        Some(_) => {
                            return Err(loc.error(
                                &what,
                                format!("{n:?}: an \"interface\" material cannot be part of a mix"),
                            ));
                        }
                        None => {
                            self.unsupported(&loc, &what, &format!("no named material {n:?} (made by MakeNamedMaterial before the mix; one left out leaves the mix out)"))?;
                            return Ok(false);
                        }
                    }
                }
                let amount = match p.take("amount") {
                    None => Some(self.num(0.5, &loc)),
                    Some(q) if q.ty == Type::Texture => {
                        match self.named_texture(&q, true, &what)? {
                            Some(Tex::Constant(c)) => Some(self.num(c.x, &q.loc)),
                            Some(Tex::Table(t)) => Some(t),
                            None => None,
                        }
                    }
                    Some(q) => match (&q.ty, &q.values) {
                        (Type::Float, Values::Nums(v)) if v.len() == 1 => {
                            Some(self.num(v[0].clamp(0.0, 1.0), &q.loc))
                        }
                        _ => {
                            return Err(q.loc.error(
                                &what,
                                format!(
                                    "{}: expected \"float amount\" or a float texture",
                                    q.decl()
                                ),
                            ));
                        }
                    },
                };
                entries.push(("type", self.string("blend", &loc)));
                entries.push(("materials", self.node(Value::Array(parts), &loc)));
                if let Some(a) = amount {
                    entries.push(("weight", a));
                }
            }
            "coateddiffuse" | "coatedconductor" => {
                entries.push(("type", self.string(&ty, &loc)));
                let diffuse = ty == "coateddiffuse";
                // pbrt-v4's names, a dot made an underscore (foton's TOML keys).
                let floats: &[(&str, &str)] = if diffuse {
                    &[
                        ("roughness", "roughness"),
                        ("uroughness", "uroughness"),
                        ("vroughness", "vroughness"),
                        ("eta", "eta"),
                        ("thickness", "thickness"),
                        ("g", "g"),
                    ]
                } else {
                    &[
                        ("interface.roughness", "interface_roughness"),
                        ("interface.uroughness", "interface_uroughness"),
                        ("interface.vroughness", "interface_vroughness"),
                        ("interface.eta", "interface_eta"),
                        ("conductor.roughness", "conductor_roughness"),
                        ("conductor.uroughness", "conductor_uroughness"),
                        ("conductor.vroughness", "conductor_vroughness"),
                        ("thickness", "thickness"),
                        ("g", "g"),
                    ]
                };
                for (name, table) in varying.iter().cloned() {
                    if let Some(&(_, key)) = floats.iter().find(|(n, _)| *n == name) {
                        entries.push((key, table));
                    }
                }
                for &(name, key) in floats {
                    let Some(q) = p.take(name) else { continue };
                    let x = match (&q.ty, &q.values) {
                        (Type::Float, Values::Nums(v)) if v.len() == 1 => Some(v[0]),
                        (Type::Texture, _) => match self.named_texture(&q, true, &what)? {
                            Some(Tex::Constant(c)) => Some(c.x),
                            _ => None,
                        },
                        (Type::Spectrum, _) if name.ends_with("eta") => {
                            let eta = eta_at_550(&q, &what, &self.dir)?;
                            if let Some(eta) = eta {
                                self.warn(&q.loc, &what, &format!("{}: dispersion ignored, the index at {ETA_WAVELENGTH} nm ({eta}) everywhere", q.decl()));
                            }
                            eta
                        }
                        _ => {
                            return Err(q.loc.error(
                                &what,
                                format!("{}: expected one \"float {name}\"", q.decl()),
                            ));
                        }
                    };
                    if let Some(x) = x {
                        entries.push((key, self.num(x, &q.loc)));
                    }
                }
                for name in ["maxdepth", "nsamples"] {
                    if let Some((n, l)) = p.int_opt(name)? {
                        entries.push((name, self.num(n as f64, &l)));
                    }
                }
                let remap = p.bool("remaproughness", true)?;
                entries.push(("remaproughness", self.node(Value::Bool(remap), &loc)));
                if let Some(c) = self.colour(&mut p, "albedo", Kind::Albedo, &what)? {
                    entries.push(("albedo", c));
                }
                if let Some(c) = self.colour(&mut p, "reflectance", Kind::Albedo, &what)? {
                    entries.push(("reflectance", c));
                } else if !diffuse {
                    // Under the coat the metal's index is relative to the coat's.
                    let outside = entries
                        .iter()
                        .find(|(k, _)| *k == "interface_eta")
                        .and_then(|(_, n)| n.value.as_f64())
                        .filter(|x| *x > 0.0)
                        .unwrap_or(1.5);
                    let names = ["conductor.eta", "conductor.k"];
                    let Some((e, kk)) = self.metal_index(&mut p, names, outside, &what, &loc)?
                    else {
                        return Ok(false);
                    };
                    entries.push(("conductor_eta", self.vec3(e, &loc)));
                    entries.push(("conductor_k", self.vec3(kk, &loc)));
                }
            }
            other @ ("measured" | "subsurface" | "hair") => {
                self.unsupported(
                    &loc,
                    &what,
                    &format!("the {other} material is not read yet"),
                )?;
                return Ok(false);
            }
            other => {
                return Err(loc.error(&what, format!("unknown material {other:?}; pbrt-v4 has diffuse, coateddiffuse, coatedconductor, conductor, dielectric, thindielectric, diffusetransmission, mix, measured, subsurface, hair and interface")));
            }
        }
        self.finish(&mut p)?;
        if ty != "interface" {
            // pbrt-v4 applies the normal map where a material has both.
            match (normal_map, displacement) {
                (Some(map), displacement) => {
                    if let Some((_, l)) = displacement {
                        self.note(&l, &what, "\"displacement\" beside a \"normalmap\": the normal map is used, as pbrt-v4 uses it");
                    }
                    entries.push(("normal_map", map));
                }
                (None, Some((height, l))) => {
                    entries.push(("bump_map", height));
                    entries.push(("bump_scale", self.num(1.0, &l)));
                }
                (None, None) => {}
            }
        }
        let t = self.table(entries, &loc);
        table_mut(&mut self.root, "materials").insert(name, t);
        Ok(true)
    }

    /// A colour parameter that may vary: a spectrum, an rgb or a float grey as an RGB
    /// array, or a texture (`"texture NAME" "tex"`) as its constant or its foton texture
    /// table. None: absent, or a texture left out (`lenient`).
    fn colour(&mut self, p: &mut Bag, name: &str, kind: Kind, what: &str) -> Result<Option<Node>> {
        let Some(q) = p.take(name) else {
            return Ok(None);
        };
        if q.ty == Type::Texture {
            return Ok(match self.named_texture(&q, false, what)? {
                Some(Tex::Constant(c)) => Some(self.vec3(c, &q.loc)),
                Some(Tex::Table(t)) => Some(t),
                None => None,
            });
        }
        let c = rgb(&q, kind, what, &self.dir)?;
        Ok(Some(self.vec3(c, &q.loc)))
    }

    /// A metal's complex index from the parameters `names` (eta, k; neither: copper, pbrt-v4's
    /// default): a named metal (`metal-X-eta` with `metal-X-k`) as RGB fitted to its spectral
    /// reflectance relative to a medium of index `outside` ([`metal_rgb_ior`]), or two
    /// spectra reduced to RGB. None: left out (`lenient`).
    fn metal_index(
        &mut self,
        p: &mut Bag,
        names: [&str; 2],
        outside: f64,
        what: &str,
        loc: &Loc,
    ) -> Result<Option<(glam::DVec3, glam::DVec3)>> {
        let (eta, k) = (p.take(names[0]), p.take(names[1]));
        let named = |q: &Option<super::parse::Param>, suffix: &str| match q {
            None => Some("Cu".to_string()),
            Some(q) => match (&q.ty, &q.values) {
                (Type::Spectrum, Values::Strs(s)) => s[0]
                    .strip_prefix("metal-")
                    .and_then(|m| m.strip_suffix(suffix))
                    .map(str::to_string),
                _ => None,
            },
        };
        match (named(&eta, "-eta"), named(&k, "-k"), eta, k) {
            (Some(a), Some(b), _, _) if a == b => {
                let fitted = METALS
                    .contains(&a.as_str())
                    .then(|| metal_rgb_ior(&a, outside))
                    .flatten();
                if fitted.is_none() {
                    self.unsupported(
                        loc,
                        what,
                        &format!("the metal {a:?}: foton has no data for it"),
                    )?;
                }
                Ok(fitted)
            }
            (_, _, Some(eta), Some(k)) => Ok(Some((
                rgb(&eta, Kind::Unbounded, what, &self.dir)?,
                rgb(&k, Kind::Unbounded, what, &self.dir)?,
            ))),
            _ => Err(loc.error(
                what,
                format!(
                    "give both \"{}\" and \"{}\" (or neither: copper)",
                    names[0], names[1]
                ),
            )),
        }
    }

    /// A dielectric's `eta` (default 1.5): a float, or a spectrum read at 550 nm (foton's
    /// dielectrics are not dispersive: a warning).
    fn eta(&mut self, p: &mut Bag, what: &str) -> Result<f64> {
        let Some(q) = p.take("eta") else {
            return Ok(1.5);
        };
        if let (Type::Float, Values::Nums(v)) = (&q.ty, &q.values)
            && v.len() == 1
        {
            return Ok(v[0]);
        }
        match eta_at_550(&q, what, &self.dir)? {
            Some(eta) => {
                self.warn(&q.loc, what, &format!("{}: dispersion ignored, the index at {ETA_WAVELENGTH} nm ({eta}) everywhere", q.decl()));
                Ok(eta)
            }
            None => Err(q.loc.error(
                what,
                format!("{}: expected \"float eta\" or \"spectrum eta\"", q.decl()),
            )),
        }
    }

    /// pbrt-v4's roughness parameters as GGX alphas (None: smooth).
    /// A roughness given as textures (`varying`: the parameters that named a varying float
    /// texture) as foton's `alpha_u`, `alpha_v` (tables, or numbers where given as such) and
    /// `remaproughness` (pbrt-v4's default true: alpha = sqrt(roughness)).
    fn roughness_textures(
        &mut self,
        p: &mut Bag,
        varying: Vec<(&'static str, Node)>,
        what: &str,
        loc: &Loc,
    ) -> Result<Vec<(&'static str, Node)>> {
        let given = |name: &str, p: &mut Bag, r: &mut Reader| -> Result<Option<Node>> {
            if let Some((_, t)) = varying.iter().find(|(n, _)| *n == name) {
                return Ok(Some(t.clone()));
            }
            Ok(match p.float_opt(name)? {
                Some((x, l)) if x >= 0.0 => Some(r.num(x, &l)),
                Some((x, _)) => {
                    return Err(loc.error(what, format!("{name} {x}: must not be negative")));
                }
                None => None,
            })
        };
        let r = given("roughness", p, self)?;
        let u = given("uroughness", p, self)?.or(r.clone());
        let v = given("vroughness", p, self)?.or(r);
        let remap = p.bool("remaproughness", true)?;
        let zero = || self.num(0.0, loc);
        Ok(vec![
            ("alpha_u", u.unwrap_or_else(zero)),
            ("alpha_v", v.unwrap_or_else(zero)),
            ("remaproughness", self.node(Value::Bool(remap), loc)),
        ])
    }

    fn roughness(&mut self, p: &mut Bag, what: &str) -> Result<Option<(f64, f64)>> {
        let r = p.float_opt("roughness")?;
        let u = p.float_opt("uroughness")?.or(r.clone());
        let v = p.float_opt("vroughness")?.or(r);
        let remap = p.bool("remaproughness", true)?;
        let alpha = |x: Option<(f64, Loc)>| -> Result<f64> {
            let x = x.map_or(0.0, |(x, _)| x);
            if x < 0.0 {
                return Err(p
                    .loc
                    .error(what, format!("roughness {x}: must not be negative")));
            }
            Ok(if remap { x.sqrt() } else { x })
        };
        let (au, av) = (alpha(u)?, alpha(v)?);
        // TrowbridgeReitzDistribution::EffectivelySmooth.
        if au.max(av) < 1e-3 {
            return Ok(None);
        }
        if au.min(av) <= 0.0 {
            return Err(p.loc.error(what, "one roughness zero and the other not: foton's rough materials need both above zero"));
        }
        Ok(Some((au, av)))
    }
}
