//! `<emitter>` outside a shape: point, spot, projector, collimated, directional, constant, envmap and
//! sun-and-sky lights as `[[lights]]` entries (a point, spot or projector light with the
//! medium it sits in).

use super::object::{Obj, Prop, show};
use super::plugins::not_read;
use super::{Reader, at, matrix_table, vec3};
use foton_core::error::Result;
use foton_core::sky::{DATE_KEYS, DateTime, Place, Spherical, SunSky, sun_position};
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
            if !matches!(o.ty.as_str(), "point" | "spot" | "projector" | "collimated") {
                return Err(
                    o.error("only point, spot, projector and collimated emitters sit in a medium")
                );
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
                // Mitsuba 3's image across the cone, in the frame of the spot's to_world.
                // (A texture left out, lenient, is reported: the spot without it.)
                if o.props.iter().any(|(n, _, _)| n == "texture")
                    && let Some(tex) = self.texture(&mut o, "texture", DVec3::ONE)?
                {
                    t.insert("texture", tex);
                    t.insert("up", vec3(m.transform_vector3(DVec3::Y), line));
                }
            }
            // Mitsuba 0.6's beam along the to_world's +z from its origin.
            "collimated" => {
                t.insert("position", vec3(m.transform_point3(DVec3::ZERO), line));
                t.insert("direction", vec3(m.transform_vector3(DVec3::Z), line));
                let p = o.color("power", DVec3::ONE)?;
                t.insert("power", vec3(p, line));
            }
            // The reverse of a perspective camera of the same to_world and field of view.
            "projector" => {
                t.insert("position", vec3(m.transform_point3(DVec3::ZERO), line));
                t.insert("direction", vec3(m.transform_vector3(DVec3::Z), line));
                t.insert("up", vec3(m.transform_vector3(DVec3::Y), line));
                if m.determinant() < 0.0 {
                    t.insert("mirror", at(Value::Bool(true), line));
                }
                let (fov, axis) = super::sensor::field_of_view(&mut o)?;
                t.insert("fov", at(Value::Float(fov), line));
                t.insert("fov_axis", at(Value::Str(axis), line));
                if let Some(tex) = self.texture(&mut o, "irradiance", DVec3::ONE)? {
                    t.insert("irradiance", tex);
                }
                t.insert("scale", at(Value::Float(o.float("scale", 1.0)?), line));
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
            "sunsky" | "sky" | "sun" => {
                let lights = self.sunsky(&mut o, m, t)?;
                o.take("sampling_weight");
                self.leftovers(&o)?;
                self.lights
                    .extend(lights.into_iter().map(|l| at(Value::Table(l), line)));
                return Ok(());
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
        self.manifold_hints(&mut o);
        self.leftovers(&o)?;
        self.lights.push(at(Value::Table(t), line));
        Ok(())
    }
}

impl Reader {
    /// Mitsuba 0.6's `sunsky`, `sky` (no sun) or `sun` (no sky) as a `sunsky` light (`t`);
    /// a sun of radius 0 (`sun_radius_scale` 0) becomes the
    /// `directional` light Mitsuba makes of it, beside the sky's map (if there is a sky).
    /// Mitsuba 3's `sunsky` (3.6, its own sun and sky data) is refused; `--lenient` renders
    /// 0.6's in its place.
    fn sunsky(&mut self, o: &mut Obj, m: DMat4, mut t: Table) -> Result<Vec<Table>> {
        let line = o.line;
        let f = |x: f64| at(Value::Float(x), line);
        if !o.v1 {
            self.unsupported(
                o,
                &format!(
                    "Mitsuba 3's `{}` (its own sun and sky data) is not supported yet; rendered with Mitsuba 0.6's sun and sky",
                    o.ty
                ),
            )?;
            // Mitsuba 3's aperture is the sun's full angle in degrees.
            let aperture = o.float("sun_aperture", 0.5358)?;
            o.props.push((
                "sun_radius_scale".into(),
                Prop::Float(aperture / 0.5358),
                line,
            ));
            o.take("complex_sun");
        }
        t.insert("type", at(Value::Str("sunsky".into()), line));
        let scale = o.float("scale", 1.0)?;
        let (sky_scale, sun_scale) = match o.ty.as_str() {
            "sky" => (scale, 0.0),
            "sun" => (0.0, scale),
            _ => (o.float("sky_scale", scale)?, o.float("sun_scale", scale)?),
        };
        let radius_scale = match o.ty.as_str() {
            "sky" => 1.0,
            _ => o.float("sun_radius_scale", 1.0)?,
        };
        let turbidity = o.float("turbidity", 3.0)?;
        let stretch = o.float("stretch", 1.0)?;
        for (k, x) in [
            ("turbidity", turbidity),
            ("stretch", stretch),
            ("sky_scale", sky_scale),
        ] {
            t.insert(k, f(x));
        }
        if o.ty != "sun" {
            let albedo = o.color("albedo", DVec3::splat(0.2))?;
            t.insert("albedo", vec3(albedo, line));
            let extend = o.boolean("extend", false)?;
            t.insert("extend", at(Value::Bool(extend), line));
        }
        let resolution = o.int("resolution", 512)?;
        t.insert("resolution", at(Value::Int(resolution), line));
        if m != DMat4::IDENTITY {
            t.insert("to_world", matrix_table(m, line));
        }
        // Where the sun is: a direction in world space, or a date, a time and a place.
        let sun = match o.take("sun_direction") {
            Some((Prop::Point(d), _)) => {
                if let Some(k) = DATE_KEYS
                    .iter()
                    .find(|k| o.props.iter().any(|(n, _, _)| n == *k))
                {
                    return Err(o.error(format!(
                        "`{k}`: both `sunDirection` and a time or place are given; Mitsuba takes only one of them"
                    )));
                }
                t.insert("sun_direction", vec3(d, line));
                let local = m.inverse().transform_vector3(d);
                Spherical::of(local.normalize_or_zero())
            }
            Some((p, _)) => {
                return Err(o.error(format!(
                    "`sun_direction`: expected a vector, found {}",
                    show(&p)
                )));
            }
            None => {
                let (d, p) = (DateTime::default(), Place::default());
                let when = DateTime {
                    year: o.int("year", d.year as i64)? as i32,
                    month: o.int("month", d.month as i64)? as i32,
                    day: o.int("day", d.day as i64)? as i32,
                    hour: o.float("hour", d.hour)?,
                    minute: o.float("minute", d.minute)?,
                    second: o.float("second", d.second)?,
                };
                let place = Place {
                    latitude: o.float("latitude", p.latitude)?,
                    longitude: o.float("longitude", p.longitude)?,
                    timezone: o.float("timezone", p.timezone)?,
                };
                for (k, x) in [
                    ("year", when.year),
                    ("month", when.month),
                    ("day", when.day),
                ] {
                    t.insert(k, at(Value::Int(x as i64), line));
                }
                for (k, x) in [
                    ("hour", when.hour),
                    ("minute", when.minute),
                    ("second", when.second),
                    ("latitude", place.latitude),
                    ("longitude", place.longitude),
                    ("timezone", place.timezone),
                ] {
                    t.insert(k, f(x));
                }
                sun_position(&when, &place)
            }
        };
        if radius_scale != 0.0 || sun_scale == 0.0 {
            t.insert("sun_scale", f(sun_scale));
            t.insert("sun_radius_scale", f(radius_scale));
            return Ok(vec![t]);
        }
        // A sun of radius 0: the map holds the sky only, the sun is a directional light of
        // the true sun's irradiance (Mitsuba's own substitution).
        t.insert("sun_scale", f(0.0));
        let model = SunSky {
            sun,
            turbidity,
            albedo: DVec3::splat(0.2),
            stretch,
            sky_scale: 0.0,
            sun_scale,
            sun_radius_scale: 0.0,
            extend: false,
        };
        let mut d = Table::default();
        d.insert("type", at(Value::Str("directional".into()), line));
        let towards = m.transform_vector3(model.sun_direction());
        d.insert("direction", vec3(-towards, line));
        let e = model.sun_radiance() * SunSky::sun_solid_angle();
        d.insert("irradiance", vec3(e, line));
        Ok(if sky_scale > 0.0 { vec![t, d] } else { vec![d] })
    }
}
