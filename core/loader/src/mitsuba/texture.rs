//! `<texture>`: Mitsuba's `bitmap` and `checkerboard` as the inline texture tables foton's
//! materials take, and a colour parameter that may be a texture (nested or a `<ref>`).

use super::object::{Obj, Prop, show};
use super::plugins::not_read;
use super::upgrade::camel_to_snake;
use super::{Reader, at, matrix_table, vec3};
use crate::texture::{scale_texture_table, table_colour};
use foton_core::error::Result;
use foton_core::value::{Node, Table, Value};
use glam::{DMat4, DVec3};

impl Reader {
    /// A colour parameter that may be a texture (`<texture name="...">` inside, or a `<ref>` to
    /// a top-level one): an RGB array or the texture's inline table for the TOML material.
    /// None: a texture left out (lenient).
    pub(super) fn texture(
        &mut self,
        o: &mut Obj,
        name: &str,
        default: DVec3,
    ) -> Result<Option<Node>> {
        let line = o.line;
        match o.take(name) {
            Some((Prop::Object(t), _)) if t.tag == "texture" => {
                Ok(self.texture_table(t)?.map(|t| at(Value::Table(t), line)))
            }
            Some((Prop::Ref(id), l)) => match self.textures.get(&id) {
                Some(t) => Ok(Some(at(Value::Table(t.clone()), line))),
                None if self.left_out_ids.contains(&id) => {
                    o.props.clear();
                    self.unsupported(o, &format!("`{name}`: texture `{id}` was left out"))?;
                    Ok(None)
                }
                None => Err(o.error(format!("`{name}`: line {l}: no texture with id `{id}`"))),
            },
            Some((p, l)) => {
                o.props.push((name.to_string(), p, l));
                Ok(Some(vec3(o.color(name, default)?, line)))
            }
            None => Ok(Some(vec3(default, line))),
        }
    }

    /// A parameter foton takes as a constant where Mitsuba also takes a texture (an area
    /// emitter's radiance, a roughness): its colour, or for a texture (given inline or by
    /// `<ref>`) its mean over the texture, with `lenient` and a line in the report.
    pub(super) fn constant(&mut self, o: &mut Obj, name: &str, default: DVec3) -> Result<DVec3> {
        let table = match o.take(name) {
            Some((Prop::Object(t), _)) if t.tag == "texture" => {
                let what = t.what();
                self.unsupported(o, &format!("`{name}`: a texture ({what}) where foton takes a constant: rendered with the texture's mean"))?;
                self.texture_table(t)?
            }
            Some((Prop::Ref(id), _)) if self.textures.contains_key(&id) => {
                self.unsupported(o, &format!("`{name}`: the texture `{id}` where foton takes a constant: rendered with the texture's mean"))?;
                self.textures.get(&id).cloned()
            }
            Some((p, l)) => {
                o.props.push((name.to_string(), p, l));
                return o.color(name, default);
            }
            None => return Ok(default),
        };
        let Some(t) = table else {
            return Ok(default);
        };
        let colour = |key: &str| table_colour(&t, key, 0.0);
        match t.get("type").map(|n| &n.value) {
            Some(Value::Str(ty)) if ty == "checkerboard" => {
                Ok((colour("color0") + colour("color1")) * 0.5)
            }
            Some(Value::Str(ty)) if ty == "constant" => Ok(colour("value")),
            Some(Value::Str(ty)) if ty == "bitmap" => {
                let Some(Value::Str(file)) = t.get("filename").map(|n| &n.value) else {
                    return Ok(default);
                };
                use crate::texture::Decode;
                let raw = matches!(t.get("raw").map(|n| &n.value), Some(Value::Bool(true)));
                let decode = match t.get("gamma").and_then(|n| n.value.as_f64()) {
                    Some(g) => Decode::Gamma(g as f32),
                    None if raw => Decode::Linear,
                    None => Decode::Srgb,
                };
                let bitmap = crate::texture::load_bitmap_decoded(&self.dir.join(file), decode)?;
                let m = bitmap.mean();
                let scale = table_colour(&t, "scale", 1.0);
                Ok(DVec3::new(m.x as f64, m.y as f64, m.z as f64) * scale)
            }
            _ => Ok(default),
        }
    }

    /// A `<texture>` as the inline table foton's materials take (docs/scene-format.md):
    /// Mitsuba's `bitmap` (filename, raw, filter_type, wrap_mode, to_uv) and `checkerboard`
    /// (color0, color1, to_uv). None: left out (lenient).
    pub(super) fn texture_table(&mut self, mut o: Obj) -> Result<Option<Table>> {
        let line = o.line;
        let mut t = Table::default();
        t.insert("type", at(Value::Str(o.ty.clone()), line));
        // Exporters write Mitsuba 0.6's names (`filterType`, `wrapMode`) into newer files.
        for (name, _, _) in &mut o.props {
            *name = camel_to_snake(name);
        }
        match o.ty.as_str() {
            "bitmap" => {
                t.insert("filename", self.filename(&mut o)?);
                let mut raw = o.boolean("raw", false)?;
                // Mitsuba 0.6's `gamma`: 1 linear, -1 sRGB, another a power law.
                match o.take("gamma") {
                    None => {}
                    Some((Prop::Float(1.0), _)) => raw = true,
                    Some((Prop::Float(-1.0), _)) => raw = false,
                    Some((Prop::Float(g), l)) if g > 0.0 => {
                        t.insert("gamma", at(Value::Float(g), l));
                    }
                    Some((p, _)) => {
                        return Err(o.error(format!(
                            "`gamma`: expected 1 (linear), -1 (sRGB) or another positive exponent, found {}",
                            show(&p)
                        )));
                    }
                }
                if raw {
                    t.insert("raw", at(Value::Bool(true), line));
                }
                self.bitmap_lookup(&mut o, &mut t)?;
                // Storage format and value clamping change nothing foton renders.
                o.take("format");
                o.take("accel");
            }
            "scale" => {
                // Mitsuba 0.6's `scale`: the texture it holds times a number or colour,
                // folded into that texture's values.
                let factor = o.color("scale", DVec3::ONE)?;
                let Some(j) = o
                    .props
                    .iter()
                    .position(|(_, p, _)| matches!(p, Prop::Object(n) if n.tag == "texture"))
                else {
                    return Err(o.error("a scale texture without the texture it scales"));
                };
                let (_, Prop::Object(inner), _) = o.props.remove(j) else {
                    unreachable!()
                };
                self.leftovers(&o)?;
                let Some(mut inner) = self.texture_table(inner)? else {
                    return Ok(None);
                };
                scale_texture_table(&mut inner, factor, |v| vec3(v, line));
                return Ok(Some(inner));
            }
            // Mitsuba 3's value without colour conversion: foton's colours have none.
            "rawconstant" => {
                t.insert("type", at(Value::Str("constant".into()), line));
                let value = match o.take("value") {
                    Some((Prop::Float(x), _)) => DVec3::splat(x),
                    Some((Prop::Int(i), _)) => DVec3::splat(i as f64),
                    Some((Prop::Point(v) | Prop::Color(v), _)) => v,
                    Some((p, _)) => {
                        return Err(o.error(format!(
                            "`value`: expected a float or a vector, found {}",
                            show(&p)
                        )));
                    }
                    None => return Err(o.error("a rawconstant texture needs its `value`")),
                };
                t.insert("value", vec3(value, line));
            }
            "volume" => {
                // Mitsuba 3's volume texture: its `volume` looked up at the surface's point.
                let kind = o.props.iter().find_map(|(n, p, _)| match p {
                    Prop::Object(v) if n == "volume" && v.tag == "volume" => Some(v.ty.clone()),
                    _ => None,
                });
                // A grid's lookup as a medium's grids have it (trilinear; clamp or repeat).
                let why = if kind
                    .as_deref()
                    .is_some_and(|k| k != "gridvolume" && k != "constvolume")
                {
                    Some(format!(
                        "`volume`: volume type `{}` is not supported yet",
                        kind.unwrap_or_default()
                    ))
                } else {
                    self.grid_unsupported(&o)
                };
                if let Some(m) = why {
                    o.props.clear();
                    self.unsupported(&o, &m)?;
                    return Ok(None);
                }
                match self.volume(&mut o, "volume")? {
                    Some(super::medium::Volume::Grid(g)) => t.insert("volume", g),
                    Some(super::medium::Volume::Constant(c, _)) => {
                        t.insert("type", at(Value::Str("constant".into()), line));
                        t.insert("value", vec3(c, line));
                    }
                    None => {
                        return Err(o.error("a volume texture needs its `volume`"));
                    }
                }
            }
            "mesh_attribute" => {
                let Some(name) = o.string("name")? else {
                    return Err(
                        o.error("a mesh_attribute texture needs the `name` of the attribute")
                    );
                };
                t.insert("name", at(Value::Str(name), line));
                let scale = o.float("scale", 1.0)?;
                t.insert("scale", at(Value::Float(scale), line));
            }
            "checkerboard" => {
                for (key, default) in [("color0", 0.4), ("color1", 0.2)] {
                    let c = o.color(key, DVec3::splat(default))?;
                    t.insert(key, vec3(c, line));
                }
            }
            _ => {
                o.props.clear();
                let m = not_read("texture", &o.ty, "this texture is not supported yet");
                self.unsupported(&o, &m)?;
                return Ok(None);
            }
        }
        let m = o.transform("to_uv")?;
        if m != DMat4::IDENTITY {
            t.insert("to_uv", matrix_table(m, line));
        }
        self.leftovers(&o)?;
        Ok(Some(t))
    }

    /// A bitmap's lookup: `filter_type` (Mitsuba 3: bilinear, nearest; 0.6: ewa, trilinear,
    /// nearest) and `wrap_mode` (repeat, mirror, clamp; 0.6 also zero and one, and a mode per
    /// axis, `wrap_mode_u` and `wrap_mode_v`), as foton's bitmap textures have them: bilinear
    /// or nearest, repeat, mirror or clamp. Mipmapped filters are bilinear without the
    /// mipmap (the same where a texel covers at least a pixel: a warning); a constant border
    /// is clamped (the same inside the texture: a warning, an error without `lenient`).
    fn bitmap_lookup(&mut self, o: &mut Obj, t: &mut Table) -> Result<()> {
        if let Some((p, l)) = o.take("filter_type") {
            let Prop::Str(f) = &p else {
                return Err(o.error(format!(
                    "`filter_type`: expected a string, found {}",
                    show(&p)
                )));
            };
            let foton = match f.to_lowercase().as_str() {
                "bilinear" => "bilinear",
                "nearest" => "nearest",
                "trilinear" | "ewa" => {
                    self.warn(
                        o,
                        l,
                        &format!("`filter_type` = {f:?}: foton filters bilinearly without a mipmap (the same where a texel covers at least a pixel; aliasing where the texture is minified)"),
                    );
                    "bilinear"
                }
                other => {
                    return Err(o.error(format!(
                        "`filter_type` = {other:?}: expected bilinear, nearest, trilinear or ewa"
                    )));
                }
            };
            t.insert("filter_type", at(Value::Str(foton.into()), l));
        }
        let mode = |o: &mut Obj, key: &str| -> Result<Option<(String, u32)>> {
            match o.take(key) {
                None => Ok(None),
                Some((Prop::Str(m), l)) => Ok(Some((m.to_lowercase(), l))),
                Some((p, _)) => {
                    Err(o.error(format!("`{key}`: expected a string, found {}", show(&p))))
                }
            }
        };
        let both = mode(o, "wrap_mode")?;
        let u = mode(o, "wrap_mode_u")?;
        let v = mode(o, "wrap_mode_v")?;
        let (wrap, l) = match (both, u, v) {
            (Some(w), None, None) => w,
            (None, None, None) => return Ok(()),
            (_, u, v) => {
                let (u, v) = (
                    u.unwrap_or(("repeat".into(), o.line)),
                    v.unwrap_or(("repeat".into(), o.line)),
                );
                if u.0 != v.0 {
                    let w = Obj {
                        line: v.1,
                        ..o.clone()
                    };
                    self.unsupported(
                        &w,
                        &format!("`wrap_mode_v` = {:?} other than `wrap_mode_u` = {:?} is not supported; both wrap as {:?}", v.0, u.0, u.0),
                    )?;
                }
                u
            }
        };
        let foton = match wrap.as_str() {
            "repeat" | "mirror" | "clamp" => wrap.clone(),
            "zero" | "one" => {
                let w = Obj {
                    line: l,
                    ..o.clone()
                };
                self.unsupported(
                    &w,
                    &format!("`wrap_mode` = {wrap:?} (a constant outside the texture) is not supported; it is clamped"),
                )?;
                "clamp".into()
            }
            other => {
                return Err(o.error(format!(
                    "`wrap_mode` = {other:?}: expected repeat, mirror, clamp, zero or one"
                )));
            }
        };
        t.insert("wrap_mode", at(Value::Str(foton), l));
        Ok(())
    }
}
