//! `Texture` (textures.cpp) into foton's texture tables, which a material parameter that names
//! the texture (`"texture reflectance" "name"`) takes in place of a colour.
//!
//! Spectrum textures: `imagemap` as foton's `bitmap`, `checkerboard` (2-D) as foton's
//! `checkerboard`, `constant`, and `scale` and `mix` where they reduce to one of those (a
//! constant scale of an image, constants mixed by a constant amount). Float textures the
//! same, as grey tables: a shape's `alpha` and a mix's `amount` take any of them, the
//! materials' numeric parameters (roughness, eta...) constants only. pbrt-v4's `uv` mapping, st = (su u + du, sv v + dv), becomes the
//! texture's `to_uv`: an image texture reads its image at (s, 1 - t) (pbrt-v4 puts st = (0, 0)
//! at the image's lower left, foton, as Mitsuba, at its upper left); pbrt-v4's checkerboard
//! changes colour at every integer of s and t, foton's at every half, so its st is halved.
//! pbrt-v4's image textures default to sRGB decoding for PNG files only (every other file
//! is read as linear, JPEG included).

use super::params::Bag;
use super::parse::{Directive, Param, Type, Values};
use super::spectra::{Kind, rgb};
use super::{Loc, Reader};
use crate::texture::scale_texture_table;
use foton_core::error::Result;
use foton_core::value::{Node, Value};
use glam::DVec3;

/// A texture as a material parameter takes it.
#[derive(Clone, Debug)]
pub(super) enum Tex {
    /// The same colour everywhere (a grey for a float texture).
    Constant(DVec3),
    /// A foton texture table (`bitmap`, `checkerboard`).
    Table(Node),
}

/// The texture classes pbrt-v4 has.
const CLASSES: &[&str] = &[
    "bilerp",
    "checkerboard",
    "constant",
    "directionmix",
    "dots",
    "fbm",
    "imagemap",
    "marble",
    "mix",
    "ptex",
    "scale",
    "windy",
    "wrinkled",
];

impl Reader {
    /// Reads `Texture "name" "spectrum" | "float" "class" ...`.
    pub(super) fn texture(&mut self, d: &Directive) -> Result<()> {
        let (name, ty, class) = (d.string(0), d.string(1), d.string(2));
        let what = format!("Texture {name:?} {ty:?} {class:?}");
        let float = match ty {
            "float" => true,
            // pbrt-v3 wrote "color".
            "spectrum" | "color" | "rgb" => false,
            other => {
                return Err(d.loc.error(
                    &what,
                    format!("unknown texture type {other:?}; expected \"spectrum\" or \"float\""),
                ));
            }
        };
        let mut p = Bag::new(d).with_defaults(&self.state.attributes.texture);
        p.what = what.clone();
        let loc = d.loc.clone();
        let tex = match class {
            "constant" => {
                if float {
                    Some(Tex::Constant(DVec3::splat(p.float("value", 1.0)?)))
                } else {
                    let c = match p.take("value") {
                        Some(q) => self.constant_colour(&q, &what)?,
                        None => DVec3::ONE,
                    };
                    Some(Tex::Constant(c))
                }
            }
            "imagemap" => self.imagemap(&mut p, &what, &loc)?,
            "checkerboard" => self.checkerboard(&mut p, float, &what, &loc)?,
            "scale" => {
                let t = self.texture_param(&mut p, "tex", DVec3::ONE, float, &what)?;
                let s = self.texture_param(&mut p, "scale", DVec3::ONE, true, &what)?;
                match (t, s) {
                    (Some(Tex::Constant(a)), Some(Tex::Constant(b))) => Some(Tex::Constant(a * b)),
                    (Some(Tex::Table(mut t)), Some(Tex::Constant(b))) => {
                        scale_table(self, &mut t, b, &loc);
                        Some(Tex::Table(t))
                    }
                    (Some(_), Some(_)) => {
                        self.unsupported(
                            &loc,
                            &what,
                            "a texture scaled by a varying texture is not read yet",
                        )?;
                        None
                    }
                    _ => None,
                }
            }
            "mix" => {
                let a = self.texture_param(&mut p, "tex1", DVec3::ZERO, float, &what)?;
                let b = self.texture_param(&mut p, "tex2", DVec3::ONE, float, &what)?;
                let amount =
                    self.texture_param(&mut p, "amount", DVec3::splat(0.5), true, &what)?;
                match (a, b, amount) {
                    (Some(Tex::Constant(a)), Some(Tex::Constant(b)), Some(Tex::Constant(t))) => {
                        Some(Tex::Constant(a * (DVec3::ONE - t) + b * t))
                    }
                    (Some(_), Some(_), Some(_)) => {
                        self.unsupported(
                            &loc,
                            &what,
                            "a mix of textures that vary is not read yet (constants mixed by a constant amount are)",
                        )?;
                        None
                    }
                    _ => None,
                }
            }
            other if CLASSES.contains(&other) => {
                self.unsupported(&loc, &what, &format!("the {other} texture is not read yet"))?;
                None
            }
            other => {
                return Err(loc.error(
                    &what,
                    format!(
                        "unknown texture class {other:?}; pbrt-v4 has {}",
                        CLASSES.join(", ")
                    ),
                ));
            }
        };
        let Some(tex) = tex else {
            // Left out (lenient): its name stays unknown, and a parameter naming it is left
            // out in turn.
            p.rest();
            return Ok(());
        };
        self.finish(&mut p)?;
        let textures = if float {
            &mut self.float_textures
        } else {
            &mut self.textures
        };
        textures.insert(name.to_string(), tex);
        Ok(())
    }

    /// `imagemap`: foton's `bitmap`.
    fn imagemap(&mut self, p: &mut Bag, what: &str, loc: &Loc) -> Result<Option<Tex>> {
        let Some((filename, floc)) = p.string_opt("filename")? else {
            return Err(loc.error(what, "missing \"string filename\""));
        };
        let Some((su, sv, du, dv)) = self.uv_mapping(p, what, loc)? else {
            return Ok(None);
        };
        let mut entries = vec![
            ("type", self.string("bitmap", loc)),
            ("filename", self.string(&filename, &floc)),
        ];
        let png = filename.to_ascii_lowercase().ends_with(".png");
        let encoding = p.string_opt("encoding")?;
        let linear = match encoding.as_ref().map(|(e, l)| (e.as_str(), l)) {
            None => !png,
            Some(("sRGB", _)) => false,
            Some(("linear", _)) => true,
            Some((other, l)) => {
                self.unsupported(
                    l,
                    what,
                    &format!(
                        "\"encoding\" {other:?}: foton decodes images as sRGB or reads them as linear (a gamma is not read yet)"
                    ),
                )?;
                !png
            }
        };
        if linear {
            entries.push(("raw", self.node(Value::Bool(true), loc)));
        }
        if let Some((filter, l)) = p.string_opt("filter")? {
            let f = match filter.as_str() {
                "point" => "nearest",
                "bilinear" => "bilinear",
                "trilinear" | "ewa" | "EWA" => {
                    self.note(&l, what, &format!("\"filter\" {filter:?}: foton looks the full-resolution image up bilinearly (no MIP map): the same image where a texel covers a pixel or more, more aliasing where the texture is minified"));
                    "bilinear"
                }
                other => {
                    return Err(l.error(
                        what,
                        format!(
                            "\"filter\" {other:?}: pbrt-v4 has point, bilinear, trilinear and ewa"
                        ),
                    ));
                }
            };
            entries.push(("filter_type", self.string(f, &l)));
        }
        p.take("maxanisotropy");
        if let Some((wrap, l)) = p.string_opt("wrap")? {
            match wrap.as_str() {
                "repeat" | "clamp" => entries.push(("wrap_mode", self.string(&wrap, &l))),
                "black" | "octahedralsphere" => {
                    self.unsupported(
                        &l,
                        what,
                        &format!("\"wrap\" {wrap:?} is not read yet (--lenient: repeat)"),
                    )?;
                }
                other => {
                    return Err(l.error(
                        what,
                        format!("\"wrap\" {other:?}: pbrt-v4 has repeat, black, clamp and octahedralsphere"),
                    ));
                }
            }
        }
        if p.bool("invert", false)? {
            self.unsupported(loc, what, "\"invert\" is not read yet")?;
        }
        let scale = p.float("scale", 1.0)?;
        if scale < 0.0 {
            return Err(loc.error(what, format!("\"scale\" {scale}: must not be negative")));
        }
        if scale != 1.0 {
            entries.push(("scale", self.num(scale, loc)));
        }
        // pbrt-v4 reads the image at (s, 1 - t).
        entries.push(("to_uv", self.to_uv([su, -sv], [du, 1.0 - dv], loc)));
        Ok(Some(Tex::Table(self.table(entries, loc))))
    }

    /// `checkerboard` (`dimension` 2): foton's `checkerboard` of half pbrt-v4's st.
    fn checkerboard(
        &mut self,
        p: &mut Bag,
        float: bool,
        what: &str,
        loc: &Loc,
    ) -> Result<Option<Tex>> {
        let dimension = p.int("dimension", 2)?;
        if dimension != 2 {
            self.unsupported(loc, what, "a solid (3-D) checkerboard is not read yet")?;
            return Ok(None);
        }
        let Some((su, sv, du, dv)) = self.uv_mapping(p, what, loc)? else {
            return Ok(None);
        };
        let tex1 = self.texture_param(p, "tex1", DVec3::ONE, float, what)?;
        let tex2 = self.texture_param(p, "tex2", DVec3::ZERO, float, what)?;
        let (Some(Tex::Constant(a)), Some(Tex::Constant(b))) = (tex1, tex2) else {
            self.unsupported(
                loc,
                what,
                "a checkerboard of textures that vary is not read yet (of colours it is)",
            )?;
            return Ok(None);
        };
        let entries = vec![
            ("type", self.string("checkerboard", loc)),
            ("color0", self.vec3(a, loc)),
            ("color1", self.vec3(b, loc)),
            (
                "to_uv",
                self.to_uv([su / 2.0, sv / 2.0], [du / 2.0, dv / 2.0], loc),
            ),
        ];
        Ok(Some(Tex::Table(self.table(entries, loc))))
    }

    /// pbrt-v4's `uv` mapping (`uscale`, `vscale`, `udelta`, `vdelta`); None: another mapping,
    /// left out (`lenient`).
    fn uv_mapping(
        &mut self,
        p: &mut Bag,
        what: &str,
        loc: &Loc,
    ) -> Result<Option<(f64, f64, f64, f64)>> {
        if let Some((m, l)) = p.string_opt("mapping")?
            && m != "uv"
        {
            if !["spherical", "cylindrical", "planar"].contains(&m.as_str()) {
                return Err(l.error(
                    what,
                    format!("\"mapping\" {m:?}: pbrt-v4 has uv, spherical, cylindrical and planar"),
                ));
            }
            self.unsupported(
                &l,
                what,
                &format!("the {m} texture mapping is not read yet (uv is)"),
            )?;
            for k in ["v1", "v2", "uscale", "vscale", "udelta", "vdelta"] {
                p.take(k);
            }
            return Ok(None);
        }
        let su = p.float("uscale", 1.0)?;
        let sv = p.float("vscale", 1.0)?;
        let du = p.float("udelta", 0.0)?;
        let dv = p.float("vdelta", 0.0)?;
        if su == 0.0 || sv == 0.0 {
            return Err(loc.error(what, "\"uscale\" and \"vscale\" must not be zero"));
        }
        Ok(Some((su, sv, du, dv)))
    }

    /// A `to_uv` table: uv' = scale uv + offset, as a row-major 3 x 3 matrix.
    pub(super) fn to_uv(&self, scale: [f64; 2], offset: [f64; 2], loc: &Loc) -> Node {
        let m = [
            scale[0], 0.0, offset[0], 0.0, scale[1], offset[1], 0.0, 0.0, 1.0,
        ];
        let items = m.iter().map(|x| self.num(*x, loc)).collect();
        let matrix = self.node(Value::Array(items), loc);
        self.table(vec![("matrix", matrix)], loc)
    }

    /// A texture-valued parameter of a texture (`tex1`, `amount`...): a value written in
    /// place, or a texture named; `default` when absent. None: a texture left out
    /// (`lenient`).
    fn texture_param(
        &mut self,
        p: &mut Bag,
        name: &str,
        default: DVec3,
        float: bool,
        what: &str,
    ) -> Result<Option<Tex>> {
        let Some(q) = p.take(name) else {
            return Ok(Some(Tex::Constant(default)));
        };
        if q.ty == Type::Texture {
            return self.named_texture(&q, float, what);
        }
        if float {
            return match (&q.ty, &q.values) {
                (Type::Float, Values::Nums(v)) if v.len() == 1 => {
                    Ok(Some(Tex::Constant(DVec3::splat(v[0]))))
                }
                _ => Err(q
                    .loc
                    .error(what, format!("{}: expected one \"float {name}\"", q.decl()))),
            };
        }
        Ok(Some(Tex::Constant(self.constant_colour(&q, what)?)))
    }

    /// The texture a `"texture NAME" "texname"` parameter names. None: left out (`lenient`).
    pub(super) fn named_texture(
        &mut self,
        q: &Param,
        float: bool,
        what: &str,
    ) -> Result<Option<Tex>> {
        let Values::Strs(s) = &q.values else {
            return Err(q
                .loc
                .error(what, format!("{}: expected a texture's name", q.decl())));
        };
        let textures = if float {
            &self.float_textures
        } else {
            &self.textures
        };
        match textures.get(&s[0]) {
            Some(t) => Ok(Some(t.clone())),
            None => {
                let kind = if float { "float" } else { "spectrum" };
                self.unsupported(
                    &q.loc,
                    what,
                    &format!(
                        "{}: no {kind} texture named {:?} (a Texture statement before it makes one; one left out leaves this out too)",
                        q.decl(),
                        s[0]
                    ),
                )?;
                Ok(None)
            }
        }
    }

    /// A colour written in place (`rgb`, `spectrum`, `blackbody` or a float grey); not bounded
    /// by 1 here, as a texture may be scaled (the material bounds its reflectances).
    fn constant_colour(&mut self, q: &Param, what: &str) -> Result<DVec3> {
        rgb(q, Kind::Unbounded, what, &self.dir)
    }
}

/// Multiplies a texture table's colours by `s`: a bitmap's `scale`, a checkerboard's colours.
fn scale_table(r: &Reader, t: &mut Node, s: DVec3, loc: &Loc) {
    if let Value::Table(table) = &mut t.value {
        scale_texture_table(table, s, |v| r.vec3(v, loc));
    }
}
