//! `<emitter>` outside a shape: point, spot, directional, constant and envmap lights as
//! `[[lights]]` entries (a point or spot light with the medium it sits in).

use super::object::{Obj, Prop, show};
use super::plugins::not_read;
use super::{Reader, at, matrix_table, vec3};
use foton_core::error::Result;
use foton_core::value::{Table, Value};
use glam::{DMat4, DVec3};

impl Reader {
    pub(super) fn emitter(&mut self, mut o: Obj) -> Result<()> {
        let line = o.line;
        let mut t = Table::default();
        t.insert("type", at(Value::Str(o.ty.clone()), line));
        let m = o.transform("to_world")?;
        // The medium a point or spot light sits in (Mitsuba's emitter `medium`).
        if let Some((p, l)) = o.take("medium") {
            let name = match p {
                Prop::Ref(id) => self
                    .media
                    .get(&id)
                    .cloned()
                    .ok_or_else(|| o.error(format!("line {l}: no medium with id `{id}`")))?,
                Prop::Object(med) if med.tag == "medium" => self.medium(med)?,
                other => {
                    return Err(o.error(format!(
                        "`medium`: expected a medium, found {}",
                        show(&other)
                    )));
                }
            };
            if !matches!(o.ty.as_str(), "point" | "spot") {
                return Err(o.error("only point and spot emitters sit in a medium"));
            }
            t.insert("medium", at(Value::Str(name), l));
        }
        match o.ty.as_str() {
            "point" => {
                let p = o.point("position")?.unwrap_or(DVec3::ZERO);
                t.insert("position", vec3(m.transform_point3(p), line));
                let i = o.color("intensity", DVec3::ONE)?;
                t.insert("intensity", vec3(i, line));
            }
            "spot" => {
                t.insert("position", vec3(m.transform_point3(DVec3::ZERO), line));
                let d = m.transform_vector3(DVec3::Z);
                t.insert("direction", vec3(d, line));
                let i = o.color("intensity", DVec3::ONE)?;
                t.insert("intensity", vec3(i, line));
                let cutoff = o.float("cutoff_angle", 20.0)?;
                let beam = o.float("beam_width", cutoff * 0.75)?;
                t.insert("cutoff_angle", at(Value::Float(cutoff), line));
                t.insert("beam_width", at(Value::Float(beam), line));
            }
            "directional" => {
                let d = match o.take("direction") {
                    Some((Prop::Point(d), _)) => d,
                    Some((p, _)) => {
                        return Err(o.error(format!(
                            "`direction`: expected a vector, found {}",
                            show(&p)
                        )));
                    }
                    None => m.transform_vector3(DVec3::Z),
                };
                t.insert("direction", vec3(d, line));
                let e = o.color("irradiance", DVec3::ONE)?;
                t.insert("irradiance", vec3(e, line));
            }
            "constant" => {
                let l = self.constant(&mut o, "radiance", DVec3::ONE)?;
                t.insert("radiance", vec3(l, line));
            }
            "envmap" => {
                t.insert("filename", self.filename(&mut o)?);
                t.insert("scale", at(Value::Float(o.float("scale", 1.0)?), line));
                if m != DMat4::IDENTITY {
                    t.insert("to_world", matrix_table(m, line));
                }
                // Compensation changes only the noise.
                o.take("mis_compensation");
            }
            _ => {
                o.props.clear();
                let m = not_read("emitter", &o.ty, "this emitter is not supported yet");
                return self.unsupported(&o, &m);
            }
        }
        // How often next-event estimation picks this emitter: noise, not the image (foton
        // picks by power).
        o.take("sampling_weight");
        self.leftovers(&o)?;
        self.lights.push(at(Value::Table(t), line));
        Ok(())
    }
}
