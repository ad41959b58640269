//! `<bsdf>`: a Mitsuba BSDF as a material of `[materials]` (diffuse, dielectrics, conductors,
//! plastics, their rough variants, difftrans, phong, ward, roughdiffuse, principled,
//! principledthin, twosided, null, blendbsdf and mixturebsdf as `blend`, mask as its shapes'
//! `alpha`, normalmap as the wrapped material's `normal_map`), with Mitsuba's
//! defaults written out and
//! its named indices of refraction.

use super::object::{Obj, Prop, show};
use super::plugins::not_read;
use super::{Reader, at, table_mut, vec3};
use foton_core::error::Result;
use foton_core::value::{Node, Table, Value};
use glam::DVec3;

/// Mitsuba's named indices of refraction (Mitsuba 3's and 0.6's `ior_data`, the same table).
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
    /// A BSDF into `[materials]`; returns its name there (None if left out).
    pub(super) fn bsdf(&mut self, mut o: Obj) -> Result<Option<String>> {
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
                // or have no sides), a blend's components' switches.
                if let Some(Value::Table(t)) = name
                    .as_deref()
                    .and_then(|n| table_mut(&mut self.root, "materials").get_mut(n))
                    .map(|n| &mut n.value)
                {
                    make_twosided(t, line);
                }
                return Ok(name);
            }
            "mask" => {
                // Mitsuba's mask blends the BSDF it wraps with a null one by `opacity`: as
                // foton reads it, a cut-out of the shapes that use it (their `alpha`).
                let Some(opacity) = self.texture(&mut o, "opacity", DVec3::splat(0.5))? else {
                    return Ok(None);
                };
                let opacity = self.as_eval_1(&o, "opacity", opacity);
                let (inner, l) = take_wrapped(&mut o, "mask")?;
                self.leftovers(&o)?;
                let name = match inner {
                    Prop::Object(mut inner) if inner.tag == "bsdf" => {
                        if inner.id.is_none() {
                            inner.id = o.id.clone();
                        }
                        self.bsdf(inner)?
                    }
                    Prop::Ref(id) => match self.bsdfs.get(&id) {
                        Some(name) => Some(name.clone()),
                        None => {
                            return Err(o.error(format!(
                                "line {l}: no BSDF with id `{id}` for the mask to wrap"
                            )));
                        }
                    },
                    _ => return Err(o.error("a mask BSDF wraps a BSDF")),
                };
                if let Some(name) = &name {
                    if let Some(id) = &o.id {
                        self.bsdfs.insert(id.clone(), name.clone());
                    }
                    self.masks.insert(name.clone(), opacity);
                }
                return Ok(name);
            }
            "polarizer" => {
                // foton does not track polarisation. Mitsuba 3's RGB variants render a linear
                // polarizer as a null surface passing half its `transmittance` straight
                // through (its `theta` is unused there): as foton reads it, a black surface
                // cut out by alpha = 1 - transmittance / 2, whose expectation is the same.
                let tr = self.constant(&mut o, "transmittance", DVec3::ONE)?;
                o.take("theta");
                o.take("polarizing");
                self.leftovers(&o)?;
                let mean = (tr.x + tr.y + tr.z) / 3.0;
                if (tr - DVec3::splat(mean)).abs().max_element() > 1e-6 {
                    self.unsupported(
                        &o,
                        "`transmittance`: a coloured transmittance where foton's cut-out takes one number: rendered with its mean",
                    )?;
                }
                self.note(
                    &o,
                    "rendered as Mitsuba 3's RGB variants render it (no polarisation): half the transmittance passes straight through",
                );
                put("type", Value::Str("diffuse".into()));
                put(
                    "reflectance",
                    Value::Array(vec![at(Value::Float(0.0), line); 3]),
                );
                put("twosided", Value::Bool(true));
                let name = self.new_name("bsdf", &o.id);
                if let Some(id) = &o.id {
                    self.bsdfs.insert(id.clone(), name.clone());
                }
                table_mut(&mut self.root, "materials").insert(&name, at(Value::Table(t), line));
                let alpha = (1.0 - 0.5 * mean).clamp(0.0, 1.0);
                self.masks
                    .insert(name.clone(), at(Value::Float(alpha), line));
                return Ok(Some(name));
            }
            "normalmap" => {
                // The BSDF it wraps, with the map as its `normal_map`: nested, it is read
                // with the map; referenced, a copy of it gets the map (the original may be
                // used without it elsewhere).
                let fork = o.props.iter().any(|(n, _, _)| n == "filename")
                    && !o.props.iter().any(|(n, _, _)| n == "normalmap");
                let map = if fork {
                    self.fork_normal_map(&mut o)?
                } else {
                    self.texture(&mut o, "normalmap", DVec3::new(0.5, 0.5, 1.0))?
                };
                let Some(map) = map else {
                    return Ok(None);
                };
                let mut entries = self.map_light(&mut o, "normal map")?;
                entries.push(("normal_map", map));
                let (inner, l) = take_wrapped(&mut o, "normalmap")?;
                self.leftovers(&o)?;
                return self.wrapped_with(&o, inner, l, "normal map", entries);
            }
            "bumpmap" => {
                // Mitsuba takes the first texture among the children, whatever its name.
                let Some(i) = o.props.iter().position(|(_, p, _)| match p {
                    Prop::Object(t) => t.tag == "texture",
                    Prop::Ref(id) => {
                        self.textures.contains_key(id) || self.left_out_ids.contains(id)
                    }
                    _ => false,
                }) else {
                    return Err(o.error("a bumpmap BSDF without its height texture"));
                };
                let (_, height, hl) = o.props.remove(i);
                let mut scale = o.float("scale", 1.0)?;
                let height = match height {
                    Prop::Object(mut t) => {
                        // Mitsuba 0.6's bump maps are written as a `scale` texture around
                        // the height: its factor is the bump map's scale.
                        while t.ty == "scale" {
                            scale *= t.float("scale", 1.0)?;
                            let Some(j) = t.props.iter().position(
                                |(_, p, _)| matches!(p, Prop::Object(n) if n.tag == "texture"),
                            ) else {
                                return Err(
                                    t.error("a scale texture without the texture it scales")
                                );
                            };
                            let (_, inner, _) = t.props.remove(j);
                            self.leftovers(&t)?;
                            let Prop::Object(inner) = inner else {
                                unreachable!()
                            };
                            t = inner;
                        }
                        self.texture_table(t)?
                    }
                    Prop::Ref(id) => self.textures.get(&id).cloned(),
                    _ => unreachable!(),
                };
                let mut entries = self.map_light(&mut o, "bump map")?;
                let (inner, l) = take_wrapped(&mut o, "bumpmap")?;
                self.leftovers(&o)?;
                // A height texture left out (--lenient, reported): the BSDF without bumps.
                match height {
                    Some(h) => {
                        entries.push(("bump_map", at(Value::Table(h), hl)));
                        entries.push(("bump_scale", at(Value::Float(scale), hl)));
                    }
                    None => entries.clear(),
                }
                return self.wrapped_with(&o, inner, l, "bump map", entries);
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
                    let Some(c) = self.texture(&mut o, k, DVec3::ONE)? else {
                        return Ok(None);
                    };
                    t.insert(k, c);
                }
            }
            "difftrans" => {
                put("type", Value::Str("difftrans".into()));
                // Mitsuba 0.6 also reads `diffuseTransmittance` when `transmittance` is absent
                // (Mitsuba 3 has no `difftrans`; a newer file is read the same way).
                let has = |k: &str| o.props.iter().any(|(n, _, _)| n == k);
                let key = if o.v1 && !has("transmittance") && has("diffuse_transmittance") {
                    "diffuse_transmittance"
                } else {
                    "transmittance"
                };
                let Some(c) = self.texture(&mut o, key, DVec3::splat(0.5))? else {
                    return Ok(None);
                };
                t.insert("transmittance", c);
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
                        // Mitsuba 3's conductor is a perfect mirror unless told otherwise, in
                        // files of every version (Mitsuba 0.6's was copper).
                        let default = "none";
                        let name = material.unwrap_or_else(|| default.into());
                        let spectra = foton_core::spectrum::conductor(&name);
                        // Mitsuba 0.6's index of the outside: the Fresnel terms take eta / ext
                        // and k / ext (all of them 1 for `none`, whose eta is 0).
                        let ext = if o.v1 {
                            self.ior(&mut o, "ext_eta", 1.0)?
                        } else {
                            1.0
                        };
                        if name.eq_ignore_ascii_case("none") {
                            t.insert("material", at(Value::Str("none".into()), line));
                        } else if spectra.is_none() {
                            return Err(o.error(format!("`material`: unknown conductor `{name}`")));
                        } else if ext != 1.0 {
                            // Mitsuba 0.6's `extEta` (Mitsuba 3 has none) divides the
                            // indices Mitsuba 3 would reduce.
                            let (eta, k) = spectra.expect("checked above");
                            let rgb = |s: foton_core::spectrum::Spectrum| {
                                s.to_srgb(foton_core::spectrum::Quantity::Emission) / ext
                            };
                            t.insert("eta", vec3(rgb(eta), line));
                            t.insert("k", vec3(rgb(k), line));
                        } else {
                            t.insert("material", at(Value::Str(name), line));
                        }
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
                if !self.plastic_params(&mut o, &mut t)? {
                    return Ok(None);
                }
                let nonlinear = o.boolean("nonlinear", false)?;
                t.insert("nonlinear", at(Value::Bool(nonlinear), line));
                t.insert("twosided", at(Value::Bool(false), line));
            }
            "pplastic" => {
                put("type", Value::Str("pplastic".into()));
                self.microfacet(&mut o, &mut t, true)?;
                if !self.plastic_params(&mut o, &mut t)? {
                    return Ok(None);
                }
                // Mitsuba 3 samples visible normals or not; the image is the same.
                o.take("sample_visible");
                self.note(
                    &o,
                    "pplastic's polarisation is not tracked: rendered as Mitsuba 3's RGB variants render it",
                );
            }
            "coating" => {
                put("type", Value::Str("coating".into()));
                let int = self.ior(&mut o, "int_ior", 1.5046)?;
                let ext = self.ior(&mut o, "ext_ior", 1.000277)?;
                t.insert("ior", at(Value::Float(int / ext), line));
                let sigma_a = o.color("sigma_a", DVec3::ZERO)?;
                t.insert("sigma_a", vec3(sigma_a, line));
                let thickness = o.float("thickness", 1.0)?;
                t.insert("thickness", at(Value::Float(thickness), line));
                let Some(c) = self.texture(&mut o, "specular_reflectance", DVec3::ONE)? else {
                    return Ok(None);
                };
                t.insert("specular_reflectance", c);
                let (inner, l) = take_wrapped(&mut o, "coating")?;
                let base = match inner {
                    Prop::Object(inner) if inner.tag == "bsdf" => self.bsdf(inner)?,
                    Prop::Ref(id) => match self.bsdfs.get(&id) {
                        Some(name) => Some(name.clone()),
                        None => {
                            return Err(o.error(format!(
                                "line {l}: no BSDF with id `{id}` for the coating to cover"
                            )));
                        }
                    },
                    _ => return Err(o.error("a coating BSDF covers a BSDF")),
                };
                let Some(base) = base else {
                    return Ok(None);
                };
                let table = table_mut(&mut self.root, "materials").get(&base).cloned();
                let kind = match table.as_ref().map(|n| &n.value) {
                    Some(Value::Table(b)) => match b.get("type").map(|n| &n.value) {
                        Some(Value::Str(ty)) => ty.clone(),
                        _ => String::new(),
                    },
                    _ => String::new(),
                };
                let covered = [
                    "diffuse",
                    "conductor",
                    "roughconductor",
                    "roughplastic",
                    "roughdiffuse",
                    "dielectric",
                ];
                if !covered.contains(&kind.as_str())
                    || self.masks.contains_key(&base)
                    || table.as_ref().is_some_and(|n| {
                        matches!(&n.value, Value::Table(b) if b.get("normal_map").is_some() || b.get("bump_map").is_some())
                    })
                {
                    self.unsupported(
                        &o,
                        &format!("a coating over this BSDF (`{kind}`, or one with a mask or a normal or bump map): foton coats diffuse, conductor, roughconductor, roughplastic, roughdiffuse and dielectric BSDFs (--lenient: the BSDF without the coating)"),
                    )?;
                    if let Some(id) = &o.id {
                        self.bsdfs.insert(id.clone(), base.clone());
                    }
                    return Ok(Some(base));
                }
                if let Some(table) = table {
                    t.insert("base", table);
                }
            }
            "phong" | "ward" => {
                put("type", Value::Str(o.ty.clone()));
                if o.ty == "phong" {
                    let Some(n) = self.scalar_texture(&mut o, "exponent", 30.0)? else {
                        return Ok(None);
                    };
                    t.insert("exponent", n);
                } else {
                    // Mitsuba 0.6 reads the variant in any case.
                    let variant = o
                        .string("variant")?
                        .unwrap_or_else(|| "balanced".into())
                        .to_lowercase();
                    t.insert("variant", at(Value::Str(variant), line));
                    let alpha = o.float("alpha", 0.1)?;
                    for k in ["alpha_u", "alpha_v"] {
                        let Some(a) = self.scalar_texture(&mut o, k, alpha)? else {
                            return Ok(None);
                        };
                        t.insert(k, a);
                    }
                }
                for (k, default) in [("specular_reflectance", 0.2), ("diffuse_reflectance", 0.5)] {
                    let Some(c) = self.texture(&mut o, k, DVec3::splat(default))? else {
                        return Ok(None);
                    };
                    t.insert(k, c);
                }
                energy_conservation(&mut o, &mut t)?;
                // Mitsuba's BSDFs are one-sided unless wrapped in `twosided`.
                t.insert("twosided", at(Value::Bool(false), line));
            }
            "roughdiffuse" => {
                put("type", Value::Str("roughdiffuse".into()));
                // Mitsuba 0.6 reads `reflectance`, or else `diffuseReflectance`.
                let key = if o.props.iter().any(|(n, _, _)| n == "reflectance") {
                    "reflectance"
                } else {
                    "diffuse_reflectance"
                };
                let Some(c) = self.texture(&mut o, key, DVec3::splat(0.5))? else {
                    return Ok(None);
                };
                t.insert("reflectance", c);
                let Some(a) = self.scalar_texture(&mut o, "alpha", 0.2)? else {
                    return Ok(None);
                };
                t.insert("alpha", a);
                let fast = o.boolean("use_fast_approx", false)?;
                t.insert("use_fast_approx", at(Value::Bool(fast), line));
                self.ignored(
                    &mut o,
                    "distribution",
                    &|_| false,
                    "ignored, as by Mitsuba 0.6's roughdiffuse (its roughness is Oren-Nayar's)",
                );
                energy_conservation(&mut o, &mut t)?;
                t.insert("twosided", at(Value::Bool(false), line));
            }
            "principled" | "principledthin" => {
                put("type", Value::Str(o.ty.clone()));
                if !self.principled(&mut o, &mut t)? {
                    return Ok(None);
                }
            }
            "disneybsdf" => {
                put("type", Value::Str("principled".into()));
                if !self.disney(&mut o, &mut t)? {
                    return Ok(None);
                }
            }
            "disneydiffuse" | "disneymetal" => {
                put("type", Value::Str("principled".into()));
                if !self.disney_lobe(&mut o, &mut t)? {
                    return Ok(None);
                }
            }
            "disneysheen" => {
                put("type", Value::Str("disney_sheen".into()));
                self.lajolla_reads_only(&mut o, &["base_color", "sheen_tint"]);
                let Some(c) = self.texture(&mut o, "base_color", DVec3::splat(0.5))? else {
                    return Ok(None);
                };
                t.insert("base_color", c);
                match self.principled_scalar(&mut o, "sheen_tint")? {
                    Scalar::Absent => {}
                    Scalar::LeftOut => return Ok(None),
                    Scalar::Given(v) => t.insert("sheen_tint", v),
                }
            }
            "disneyclearcoat" => {
                put("type", Value::Str("disney_clearcoat".into()));
                self.lajolla_reads_only(&mut o, &["clearcoat_gloss"]);
                match self.principled_scalar(&mut o, "clearcoat_gloss")? {
                    Scalar::Absent => {}
                    Scalar::LeftOut => return Ok(None),
                    Scalar::Given(v) => t.insert("clearcoat_gloss", v),
                }
            }
            "disneyglass" => {
                put("type", Value::Str("roughdielectric".into()));
                if !self.disney_glass(&mut o, &mut t)? {
                    return Ok(None);
                }
            }
            "null" => put("type", Value::Str("null".into())),
            "blendbsdf" | "mixturebsdf" => {
                put("type", Value::Str("blend".into()));
                let Some(components) = self.blend_components(&mut o)? else {
                    return Ok(None);
                };
                if o.ty == "blendbsdf" {
                    if components.len() != 2 {
                        return Err(o.error(format!(
                            "a blendbsdf blends two BSDFs; found {}",
                            components.len()
                        )));
                    }
                    // Mitsuba 3 requires the weight; 0.6 takes 0.5.
                    if !o.v1 && !o.props.iter().any(|(n, _, _)| n == "weight") {
                        return Err(o.error("a blendbsdf needs its `weight` (Mitsuba 3)"));
                    }
                    let Some(w) = self.scalar_texture(&mut o, "weight", 0.5)? else {
                        return Ok(None);
                    };
                    t.insert("weight", w);
                    // Read by 0.6's base class, unused by its blendbsdf.
                    o.take("ensure_energy_conservation");
                } else {
                    let weights = o.string("weights")?.unwrap_or_default();
                    let mut ws = Vec::new();
                    for token in weights.split([' ', ',', ';']).filter(|s| !s.is_empty()) {
                        let w: f64 = token.parse().map_err(|_| {
                            o.error(format!("`weights`: could not read {token:?} as a number"))
                        })?;
                        ws.push(at(Value::Float(w), line));
                    }
                    if ws.is_empty() {
                        return Err(o.error("a mixturebsdf needs its `weights`"));
                    }
                    if ws.len() != components.len() {
                        return Err(o.error(format!(
                            "{} weights for {} BSDFs: a mixturebsdf takes one per BSDF",
                            ws.len(),
                            components.len()
                        )));
                    }
                    put("weights", Value::Array(ws));
                    energy_conservation(&mut o, &mut t)?;
                }
                t.insert("materials", at(Value::Array(components), line));
            }
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

    /// A microfacet BSDF's `distribution` and `alpha` (or, if `anisotropic`, `alpha_u` and
    /// `alpha_v`), Mitsuba's defaults written out. Visible-normal sampling is foton's only
    /// sampling: `sample_visible` changes noise, not the image.
    fn microfacet(&mut self, o: &mut Obj, t: &mut Table, anisotropic: bool) -> Result<()> {
        let line = o.line;
        let distribution = o
            .string("distribution")?
            .unwrap_or_else(|| "beckmann".into());
        let distribution = match distribution.as_str() {
            "beckmann" | "ggx" => distribution,
            // Mitsuba 0.6's third, Phong's, which it calls `as` too (Ashikhmin and Shirley's
            // where anisotropic): one distribution.
            "phong" | "as" => "phong".to_string(),
            _ => {
                return Err(o.error(format!(
                    "`distribution`: unknown {distribution:?}; expected beckmann or ggx (or, in Mitsuba 0.6, phong or as)"
                )));
            }
        };
        t.insert("distribution", at(Value::Str(distribution), line));
        o.take("sample_visible");
        let has = |o: &Obj, k: &str| o.props.iter().any(|(n, _, _)| n == k);
        // A textured roughness: as a texture for the conductor and the dielectric (those that
        // may be anisotropic), its mean (lenient) for roughplastic, whose roughness is a
        // constant.
        let mut textures = Vec::new();
        for k in ["alpha", "alpha_u", "alpha_v"] {
            let textured = o.props.iter().any(|(n, p, _)| {
                n == k
                    && match p {
                        Prop::Object(t) => t.tag == "texture",
                        Prop::Ref(id) => self.textures.contains_key(id),
                        _ => false,
                    }
            });
            if textured && anisotropic {
                if let Some(node) = self.texture(o, k, DVec3::splat(0.1))? {
                    let node = self.as_eval_1(o, k, node);
                    textures.push((k, node));
                }
            } else if textured {
                let mean = self.constant(o, k, DVec3::splat(0.1))?;
                let l = o.line;
                o.props.push((k.to_string(), Prop::Float(mean.x), l));
            }
        }
        let textured = |k: &str| textures.iter().any(|(n, _)| *n == k);
        if anisotropic
            && (has(o, "alpha_u")
                || has(o, "alpha_v")
                || textured("alpha_u")
                || textured("alpha_v"))
        {
            for k in ["alpha_u", "alpha_v"] {
                if !textured(k) {
                    let a = o.float(k, 0.1)?;
                    t.insert(k, at(Value::Float(a), line));
                }
            }
        } else if !textured("alpha") {
            let a = o.float("alpha", 0.1)?;
            t.insert("alpha", at(Value::Float(a), line));
        }
        for (k, node) in textures {
            t.insert(k, node);
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
}

impl Reader {
    /// A float parameter that may be a texture (Mitsuba's float textures, as `phong`'s
    /// `exponent`): a number, or what [`Reader::texture`] makes of a colour or a texture.
    /// None: a texture left out (lenient).
    fn scalar_texture(&mut self, o: &mut Obj, name: &str, default: f64) -> Result<Option<Node>> {
        let line = o.line;
        match o.take(name) {
            None => Ok(Some(at(Value::Float(default), line))),
            Some((Prop::Float(x), _)) => Ok(Some(at(Value::Float(x), line))),
            Some((Prop::Int(i), _)) => Ok(Some(at(Value::Float(i as f64), line))),
            Some((p, l)) => {
                o.props.push((name.to_string(), p, l));
                let t = self.texture(o, name, DVec3::splat(default))?;
                Ok(t.map(|t| self.as_eval_1(o, name, t)))
            }
        }
    }

    /// A texture Mitsuba 3 reads as a number (its `eval_1`: roughness, opacity, weights): a
    /// checkerboard's colours swapped, since Mitsuba 3's checkerboard gives `color0` where
    /// its `eval` gives `color1` (3.0 to 3.9; checked against 3.9.1).
    fn as_eval_1(&mut self, o: &Obj, name: &str, mut node: Node) -> Node {
        if o.v1 {
            return node;
        }
        if let Value::Table(t) = &mut node.value
            && matches!(t.get("type").map(|n| &n.value), Some(Value::Str(k)) if k == "checkerboard")
        {
            let line = node.line;
            let c0 = t
                .get("color0")
                .cloned()
                .unwrap_or_else(|| at(Value::Float(0.4), line));
            let c1 = t
                .get("color1")
                .cloned()
                .unwrap_or_else(|| at(Value::Float(0.2), line));
            t.insert("color0", c1);
            t.insert("color1", c0);
            self.note(
                o,
                &format!("`{name}`: a checkerboard read as a number takes `color1` where its colour takes `color0`, as Mitsuba 3 reads it"),
            );
        }
        node
    }
}

impl Reader {
    /// What the plastics share: `int_ior` and `ext_ior` (polypropylene in air) as `ior`, and
    /// the two reflectances. false: a texture was left out (lenient).
    fn plastic_params(&mut self, o: &mut Obj, t: &mut Table) -> Result<bool> {
        let line = o.line;
        let int = self.ior(o, "int_ior", 1.49)?;
        let ext = self.ior(o, "ext_ior", 1.000277)?;
        t.insert("ior", at(Value::Float(int / ext), line));
        for (k, default) in [("diffuse_reflectance", 0.5), ("specular_reflectance", 1.0)] {
            let Some(c) = self.texture(o, k, DVec3::splat(default))? else {
                return Ok(false);
            };
            t.insert(k, c);
        }
        Ok(true)
    }

    /// What a `normalmap` or `bumpmap` does to the light's side of the BSDF it wraps: Mitsuba
    /// 0.6 and 3 cut off light from below the surface's own normal, Mitsuba 3 (3.7 and
    /// later) also applies its shadowing term unless `use_shadowing_function` is false. Its
    /// `flip_invalid_normals` is noted: foton does not flip normals.
    fn map_light(&mut self, o: &mut Obj, what: &str) -> Result<Vec<(&'static str, Node)>> {
        let line = o.line;
        let shadowing = o.boolean("use_shadowing_function", true)? && !o.v1;
        let flip = o.boolean("flip_invalid_normals", true)?;
        if !o.v1 && flip {
            self.note(
                o,
                &format!("the {what}'s normals are not flipped where they face away from the viewer (Mitsuba 3's `flip_invalid_normals`): the same wherever the viewer sees the surface from above its tilted normal"),
            );
        }
        Ok(vec![
            ("map_cut_off", at(Value::Bool(true), line)),
            ("map_shadowing", at(Value::Bool(shadowing), line)),
        ])
    }
}

impl Reader {
    /// The material of a BSDF that a wrapper (`normalmap`, `bumpmap`) wraps, with the
    /// wrapper's `entries` added: nested, it is read with them; referenced, a copy of it gets
    /// them (the original may be used without them elsewhere). Registers the wrapper's id.
    fn wrapped_with(
        &mut self,
        o: &Obj,
        inner: Prop,
        l: u32,
        what: &str,
        entries: Vec<(&str, Node)>,
    ) -> Result<Option<String>> {
        let name = match inner {
            Prop::Object(inner) if inner.tag == "bsdf" => self.bsdf(inner)?,
            Prop::Ref(id) => {
                let Some(original) = self.bsdfs.get(&id).cloned() else {
                    return Err(o.error(format!(
                        "line {l}: no BSDF with id `{id}` for the {what} to wrap"
                    )));
                };
                let materials = table_mut(&mut self.root, "materials");
                let copy = materials.get(&original).cloned();
                let name = self.new_name("bsdf", &None);
                if let Some(copy) = copy {
                    table_mut(&mut self.root, "materials").insert(&name, copy);
                }
                if let Some(mask) = self.masks.get(&original).cloned() {
                    self.masks.insert(name.clone(), mask);
                }
                Some(name)
            }
            _ => return Err(o.error(format!("a {what} BSDF wraps a BSDF"))),
        };
        let Some(name) = name else {
            return Ok(None);
        };
        if let Some(Value::Table(t)) = table_mut(&mut self.root, "materials")
            .get_mut(&name)
            .map(|n| &mut n.value)
        {
            if t.get("normal_map").is_none() && t.get("bump_map").is_none() {
                for (key, value) in entries {
                    t.insert(key, value);
                }
            } else {
                self.unsupported(
                    o,
                    &format!("a {what} around a BSDF that already has a normal or bump map: foton applies one map per material, the inner one"),
                )?;
            }
        }
        if let Some(id) = &o.id {
            self.bsdfs.insert(id.clone(), name.clone());
        }
        Ok(Some(name))
    }
}

/// Makes a material table two-sided (Mitsuba's `twosided` around it): its own switch, or
/// those of a blend's components.
/// Takes from a wrapping BSDF (`mask`, `normalmap`) the BSDF it wraps, nested or referenced,
/// with its line; an error if it has none.
fn take_wrapped(o: &mut Obj, what: &str) -> Result<(Prop, u32)> {
    let Some(i) = o
        .props
        .iter()
        .position(|(_, p, _)| matches!(p, Prop::Object(_) | Prop::Ref(_)))
    else {
        return Err(o.error(format!("a {what} BSDF without the BSDF it wraps")));
    };
    let (_, inner, line) = o.props.remove(i);
    Ok((inner, line))
}

fn make_twosided(t: &mut Table, line: u32) {
    if t.get("twosided").is_some() {
        t.insert("twosided", at(Value::Bool(true), line));
    }
    if let Some(Node {
        value: Value::Array(components),
        ..
    }) = t.get_mut("materials")
    {
        for c in components {
            if let Value::Table(inner) = &mut c.value {
                make_twosided(inner, line);
            }
        }
    }
}

impl Reader {
    /// The BSDFs nested in (or referenced by) a blendbsdf or mixturebsdf, in the file's
    /// order, as material tables (copies of those written to `[materials]`). None: one was
    /// left out (lenient). A null BSDF among them is refused.
    fn blend_components(&mut self, o: &mut Obj) -> Result<Option<Vec<Node>>> {
        let mut names = Vec::new();
        let mut i = 0;
        while i < o.props.len() {
            let take = match &o.props[i].1 {
                Prop::Object(b) => b.tag == "bsdf",
                Prop::Ref(id) => self.bsdfs.contains_key(id),
                _ => false,
            };
            if !take {
                i += 1;
                continue;
            }
            let (_, p, l) = o.props.remove(i);
            let name = match p {
                Prop::Object(b) => self.bsdf(b)?,
                Prop::Ref(id) => self.bsdfs.get(&id).cloned(),
                _ => unreachable!(),
            };
            let Some(name) = name else {
                return Ok(None);
            };
            if self.masks.contains_key(&name) {
                o.props.clear();
                self.unsupported(
                    o,
                    "a mask BSDF inside a blend: a cut-out part of a blend is not rendered yet",
                )?;
                return Ok(None);
            }
            names.push((name, l));
        }
        let mut out = Vec::new();
        for (name, l) in names {
            let node = table_mut(&mut self.root, "materials")
                .get(&name)
                .cloned()
                .expect("a BSDF read is in [materials]");
            if let Value::Table(t) = &node.value
                && matches!(t.get("type").map(|n| &n.value), Some(Value::Str(s)) if s == "null")
            {
                let here = Obj {
                    line: l,
                    props: Vec::new(),
                    ..o.clone()
                };
                return Err(here.error(
                    "a null BSDF inside a blend is not supported (foton's null surfaces are holes everywhere, not at some points)",
                ));
            }
            out.push(node);
        }
        Ok(Some(out))
    }
}

/// Mitsuba 0.6's `ensureEnergyConservation` (default true), written only when off.
fn energy_conservation(o: &mut Obj, t: &mut Table) -> Result<()> {
    if !o.boolean("ensure_energy_conservation", true)? {
        t.insert("ensure_energy_conservation", at(Value::Bool(false), o.line));
    }
    Ok(())
}

/// The numeric parameters of `principled` and `principledthin` that may be textures (the
/// thin sheet's `eta` among them), and their sampling rates.
const PRINCIPLED_SCALARS: &[&str] = &[
    "roughness",
    "anisotropic",
    "metallic",
    "spec_trans",
    "spec_tint",
    "sheen",
    "sheen_tint",
    "flatness",
    "clearcoat",
    "clearcoat_gloss",
];
const PRINCIPLED_THIN_SCALARS: &[&str] = &[
    "roughness",
    "anisotropic",
    "spec_trans",
    "eta",
    "spec_tint",
    "sheen",
    "sheen_tint",
    "flatness",
    "diff_trans",
];
const PRINCIPLED_RATES: &[&str] = &[
    "diffuse_reflectance_sampling_rate",
    "main_specular_sampling_rate",
    "clearcoat_sampling_rate",
];
const PRINCIPLED_THIN_RATES: &[&str] = &[
    "specular_reflectance_sampling_rate",
    "specular_transmittance_sampling_rate",
    "diffuse_reflectance_sampling_rate",
    "diffuse_transmittance_sampling_rate",
];

impl Reader {
    /// `principled` and `principledthin`: foton's parameters have Mitsuba's names and
    /// defaults, so only those given are written. False: a texture was left out (lenient).
    /// The Disney BSDF of lajolla (a course renderer's Mitsuba 0.6 dialect), the model
    /// Mitsuba 3's principled BSDF implements (Burley 2015): its parameters under principled's
    /// names. Its `subsurface` blend has no principled counterpart (a warning); `specular`
    /// beside `eta` is dropped, since principled derives each from the other.
    fn disney(&mut self, o: &mut Obj, t: &mut Table) -> Result<bool> {
        self.note(
            o,
            "lajolla's Disney BSDF, read as Mitsuba 3's principled BSDF, the same model (Burley 2015) in other details: Mitsuba's clearcoat leaves out the microfacet 1 / (4 cos_i cos_o), its dielectric reflection takes the Fresnel equations of eta where lajolla's takes Schlick's of `specular` R0(eta), and its glass reflection is not tinted by the base colour",
        );
        for (from, to) in [
            ("specular_transmission", "spec_trans"),
            ("specular_tint", "spec_tint"),
        ] {
            if let Some((p, l)) = o.take(from) {
                o.props.push((to.to_string(), p, l));
            }
        }
        self.ignored(
            o,
            "subsurface",
            &|p| matches!(p, Prop::Float(x) if *x == 0.0),
            "ignored (the principled BSDF has no subsurface lobe: its diffuse lobe renders in its place)",
        );
        if o.props.iter().any(|(n, _, _)| n == "eta") {
            let eta = o.float("eta", 1.5)?;
            o.props.push(("eta".into(), Prop::Float(eta), o.line));
            // Principled's specular is the reflectance at normal incidence of eta, scaled:
            // specular = ((eta - 1) / (eta + 1))^2 / 0.08.
            let implied = ((eta - 1.0) / (eta + 1.0)).powi(2) / 0.08;
            self.ignored(
                o,
                "specular",
                &|p| matches!(p, Prop::Float(x) if (x - implied).abs() < 1e-3),
                &format!("ignored (eta = {eta} gives the specular reflectance, {implied:.3})"),
            );
        }
        self.principled(o, t)
    }

    /// Takes the parameters lajolla's single-lobe BSDF `o` does not read (lajolla ignores
    /// them): a warning each. `read` are the names it reads, snake_cased.
    fn lajolla_reads_only(&mut self, o: &mut Obj, read: &[&str]) {
        let other: Vec<String> = (o.props.iter())
            .map(|(n, _, _)| n.clone())
            .filter(|n| !read.contains(&n.as_str()))
            .collect();
        let why = format!("ignored (lajolla's `{}` does not read it)", o.ty);
        for name in other {
            self.ignored(o, &name, &|_| false, &why);
        }
    }

    /// lajolla's `disneydiffuse` and `disneymetal`, lobes of its Disney BSDF on their own (the
    /// course's homework formulas, Burley 2012 and 2015): Mitsuba 3's principled BSDF with
    /// the others switched off. Its diffuse lobe (no specular: eta 1) is Burley's base
    /// diffuse blended by `flatness` with the fake subsurface as lajolla's by `subsurface`;
    /// at metallic 1 its only lobe is the GGX metal with Schlick's Fresnel of the base colour.
    /// lajolla's defaults written out.
    fn disney_lobe(&mut self, o: &mut Obj, t: &mut Table) -> Result<bool> {
        let line = o.line;
        let float = |x: f64| at(Value::Float(x), line);
        match o.ty.as_str() {
            "disneydiffuse" => {
                self.lajolla_reads_only(o, &["base_color", "roughness", "subsurface"]);
                if let Some((p, l)) = o.take("subsurface") {
                    o.props.push(("flatness".into(), p, l));
                }
                if !self.principled(o, t)? {
                    return Ok(false);
                }
                t.insert("specular", float(0.0));
            }
            "disneymetal" => {
                self.lajolla_reads_only(o, &["base_color", "roughness", "anisotropic"]);
                if !self.principled(o, t)? {
                    return Ok(false);
                }
                t.insert("metallic", float(1.0));
            }
            _ => unreachable!("only lajolla's diffuse and metal lobes are read as principled"),
        }
        for k in ["roughness", "anisotropic"] {
            if t.get(k).is_none() {
                t.insert(k, float(if k == "roughness" { 0.5 } else { 0.0 }));
            }
        }
        let alpha = if o.ty == "disneymetal" {
            " (GGX alpha at least 0.001 where lajolla's is 0.0001: the same above roughness 0.032)"
        } else {
            ""
        };
        self.note(
            o,
            &format!(
                "lajolla's single {} lobe of its Disney BSDF (a course renderer's), read as Mitsuba 3's principled BSDF with only that lobe on{alpha}",
                o.ty.trim_start_matches("disney")
            ),
        );
        Ok(true)
    }

    /// lajolla's `disneyglass`: Walter et al.'s rough dielectric with the anisotropic GGX of
    /// Disney's roughness (alpha = roughness^2 over and times sqrt(1 - 0.9 anisotropic), at
    /// least 0.0001), the reflection tinted by the base colour and the refraction by its
    /// square root: a roughdielectric with those reflectance and transmittance.
    fn disney_glass(&mut self, o: &mut Obj, t: &mut Table) -> Result<bool> {
        let line = o.line;
        self.lajolla_reads_only(o, &["base_color", "roughness", "anisotropic", "eta"]);
        let number = |o: &mut Obj, k: &str, default: f64| match o.take(k) {
            None => Ok(default),
            Some((Prop::Float(x), _)) => Ok(x),
            Some((Prop::Int(i), _)) => Ok(i as f64),
            Some((p, l)) => Err(o.error(format!(
                "line {l}: `{k}`: foton reads lajolla's glass with a constant {k}, not {}",
                show(&p)
            ))),
        };
        let roughness = number(o, "roughness", 0.5)?;
        let anisotropic = number(o, "anisotropic", 0.0)?;
        let eta = number(o, "eta", 1.5)?;
        let base = match o.take("base_color") {
            None => DVec3::splat(0.5),
            Some((Prop::Color(c), _)) => c,
            Some((Prop::Float(x), _)) => DVec3::splat(x),
            Some((p, l)) => {
                return Err(o.error(format!(
                    "line {l}: `base_color`: foton reads lajolla's glass with a constant colour (its refraction takes the square root), not {}",
                    show(&p)
                )));
            }
        };
        let aspect = (1.0 - 0.9 * anisotropic).sqrt();
        let r2 = roughness * roughness;
        let float = |x: f64| at(Value::Float(x), line);
        t.insert("distribution", at(Value::Str("ggx".into()), line));
        t.insert("alpha_u", float((r2 / aspect).max(1e-4)));
        t.insert("alpha_v", float((r2 * aspect).max(1e-4)));
        t.insert("ior", float(eta));
        t.insert("specular_reflectance", vec3(base, line));
        t.insert("specular_transmittance", vec3(base.map(f64::sqrt), line));
        self.note(
            o,
            "lajolla's single glass lobe of its Disney BSDF (a course renderer's), read as a rough dielectric: anisotropic GGX, the reflection times the base colour, the refraction times its square root",
        );
        Ok(true)
    }

    fn principled(&mut self, o: &mut Obj, t: &mut Table) -> Result<bool> {
        let line = o.line;
        let thin = o.ty == "principledthin";
        let Some(c) = self.texture(o, "base_color", DVec3::splat(0.5))? else {
            return Ok(false);
        };
        t.insert("base_color", c);
        let (scalars, rates) = if thin {
            (PRINCIPLED_THIN_SCALARS, PRINCIPLED_THIN_RATES)
        } else {
            (PRINCIPLED_SCALARS, PRINCIPLED_RATES)
        };
        for &k in scalars {
            match self.principled_scalar(o, k)? {
                Scalar::Absent => {}
                Scalar::LeftOut => return Ok(false),
                Scalar::Given(v) => t.insert(k, v),
            }
        }
        let has = |o: &Obj, k: &str| o.props.iter().any(|(n, _, _)| n == k);
        if !thin && has(o, "eta") && has(o, "specular") {
            return Err(o.error("give either `eta` or `specular`, not both"));
        }
        let floats: &[&str] = if thin { &[] } else { &["eta", "specular"] };
        for &k in floats.iter().chain(rates) {
            if o.props.iter().any(|(n, _, _)| n == k) {
                let x = o.float(k, 0.0)?;
                t.insert(k, at(Value::Float(x), line));
            }
        }
        if !thin {
            // Mitsuba's BSDFs are one-sided unless wrapped in `twosided`.
            t.insert("twosided", at(Value::Bool(false), line));
        }
        Ok(true)
    }

    /// A numeric parameter that may be a texture: a number (an RGB colour gives its mean, as
    /// Mitsuba's `eval_1` of a colour), or the texture's table (whose luminance foton reads,
    /// as Mitsuba's of a bitmap).
    fn principled_scalar(&mut self, o: &mut Obj, name: &str) -> Result<Scalar> {
        let line = o.line;
        match o.take(name) {
            None => Ok(Scalar::Absent),
            Some((Prop::Float(x), _)) => Ok(Scalar::Given(at(Value::Float(x), line))),
            Some((Prop::Int(i), _)) => Ok(Scalar::Given(at(Value::Float(i as f64), line))),
            Some((Prop::Color(c), _)) => Ok(Scalar::Given(at(
                Value::Float((c.x + c.y + c.z) / 3.0),
                line,
            ))),
            Some((p @ (Prop::Object(_) | Prop::Ref(_)), l)) => {
                o.props.push((name.to_string(), p, l));
                Ok(match self.texture(o, name, DVec3::ZERO)? {
                    Some(node) => Scalar::Given(self.as_eval_1(o, name, node)),
                    None => Scalar::LeftOut,
                })
            }
            Some((p, _)) => Err(o.error(format!(
                "`{name}`: expected a number or a texture, found {}",
                super::object::show(&p)
            ))),
        }
    }
}

/// What [`Reader::principled_scalar`] found.
enum Scalar {
    Absent,
    /// A texture left out (lenient).
    LeftOut,
    Given(foton_core::value::Node),
}

impl Reader {
    /// The normal map of Mitsuba 2's specular manifold sampling fork (`filename`, `tiles`):
    /// its image's normals, normalize(2 rgb - 1), repeated `tiles` times over the uv square,
    /// as Mitsuba's `normalmap` of that image reads them (interpolated between texel centres
    /// as normals, where the fork interpolates their slopes: the same normals at the
    /// centres). Its LEAN fallback serves only its glint integrators.
    fn fork_normal_map(&mut self, o: &mut Obj) -> Result<Option<Node>> {
        let line = o.line;
        let file = self.filename(o)?;
        let tiles = o.float("tiles", 1.0)?;
        for k in [
            "use_slopes",
            "lean_fallback",
            "lean_fallback_alpha",
            "lean_fallback_material",
            "eta",
            "k",
        ] {
            o.take(k);
        }
        self.note(
            o,
            "the normal map of Mitsuba 2's specular manifold sampling fork (`filename`, `tiles`): read as Mitsuba's normalmap of that image, repeated `tiles` times (its LEAN fallback, for its glint integrators, is not read)",
        );
        let mut t = Table::default();
        t.insert("type", at(Value::Str("bitmap".into()), line));
        t.insert("filename", file);
        t.insert("raw", at(Value::Bool(true), line));
        if tiles != 1.0 {
            let mut to_uv = Table::default();
            to_uv.insert("scale", at(Value::Float(tiles), line));
            t.insert("to_uv", at(Value::Table(to_uv), line));
        }
        Ok(Some(at(Value::Table(t), line)))
    }
}
