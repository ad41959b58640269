//! `<texture>`: Mitsuba's `bitmap` and `checkerboard` as the inline texture tables foton's
//! materials take, and a colour parameter that may be a texture (nested or a `<ref>`).

use super::object::{Obj, Prop};
use super::plugins::not_read;
use super::{Reader, at, matrix_table, vec3};
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
                None => Err(o.error(format!(
                    "`{name}`: line {l}: no texture with id `{id}` before it"
                ))),
            },
            Some((p, l)) => {
                o.props.push((name.to_string(), p, l));
                Ok(Some(vec3(o.color(name, default)?, line)))
            }
            None => Ok(Some(vec3(default, line))),
        }
    }

    /// A `<texture>` as the inline table foton's materials take (docs/scene-format.md):
    /// Mitsuba's `bitmap` (filename, raw, filter_type, wrap_mode, to_uv) and `checkerboard`
    /// (color0, color1, to_uv). None: left out (lenient).
    pub(super) fn texture_table(&mut self, mut o: Obj) -> Result<Option<Table>> {
        let line = o.line;
        let mut t = Table::default();
        t.insert("type", at(Value::Str(o.ty.clone()), line));
        match o.ty.as_str() {
            "bitmap" => {
                t.insert("filename", self.filename(&mut o)?);
                if o.boolean("raw", false)? {
                    t.insert("raw", at(Value::Bool(true), line));
                }
                for key in ["filter_type", "wrap_mode"] {
                    if let Some(v) = o.string(key)? {
                        t.insert(key, at(Value::Str(v), line));
                    }
                }
                // Storage format and value clamping change nothing foton renders.
                o.take("format");
                o.take("accel");
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
}
