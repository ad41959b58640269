//! `<bsdf>`: a Mitsuba BSDF as a material of `[materials]` (diffuse, dielectrics, conductors,
//! plastics, their rough variants, twosided, null), with Mitsuba's defaults written out and
//! its named indices of refraction.

use super::object::{Obj, Prop};
use super::plugins::not_read;
use super::{Reader, at, table_mut, vec3};
use foton_core::error::Result;
use foton_core::value::{Table, Value};
use glam::DVec3;

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
                        if name != "none" && foton_core::material::conductor_ior(&name).is_none() {
                            return Err(o.error(format!("`material`: unknown conductor `{name}`")));
                        }
                        t.insert("material", at(Value::Str(name), line));
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
            "principled" | "principledthin" => {
                put("type", Value::Str(o.ty.clone()));
                if !self.principled(&mut o, &mut t)? {
                    return Ok(None);
                }
            }
            "null" => put("type", Value::Str("null".into())),
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
            match self.scalar_texture(o, k)? {
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
    fn scalar_texture(&mut self, o: &mut Obj, name: &str) -> Result<Scalar> {
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
                    Some(node) => Scalar::Given(node),
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

/// What [`Reader::scalar_texture`] found.
enum Scalar {
    Absent,
    /// A texture left out (lenient).
    LeftOut,
    Given(foton_core::value::Node),
}
