//! `LightSource` into `[[lights]]` (lights.cpp): `point` (`I`, `from`, `scale`, `power`),
//! `spot` (`I`, `from`, `to`, `coneangle`, `conedeltaangle`, `scale`, `power`; foton's spot
//! with pbrt-v4's smoothstep falloff), `distant` (`L`, `from`, `to`, `scale`, `illuminance`)
//! and `infinite` with a constant `L`
//! (`scale`, `illuminance`). Each light's spectrum is normalised to luminance 1 (`spectra`),
//! so an `rgb` is its own colour and `scale` the rest; `power` is the power of the light as
//! if its colour were white, as pbrt-v4 computes it.

use super::params::Bag;
use super::parse::{Directive, Type};
use super::spectra::{Kind, rgb};
use super::{Reader, vec};
use foton_core::error::Result;
use glam::DVec3;
use std::f64::consts::PI;

impl Reader {
    pub(super) fn light(&mut self, d: &Directive) -> Result<()> {
        let mut p = Bag::new(d).with_defaults(&self.state.attributes.light);
        let loc = d.loc.clone();
        let what = d.what();
        let m = self.state.ctm;
        let spectrum = |r: &Reader, p: &mut Bag, name: &str| -> Result<DVec3> {
            match p.take(name) {
                Some(q) => rgb(&q, Kind::Illuminant, &what, &r.dir),
                None => Ok(DVec3::ONE),
            }
        };
        let point = |p: &mut Bag, name: &str, default: DVec3| -> Result<DVec3> {
            Ok(p.numbers(name, &[Type::Point3])?
                .map_or(default, |(v, _)| vec(&v[0..3])))
        };
        let mut entries = Vec::new();
        match d.string(0) {
            "point" => {
                let i = spectrum(self, &mut p, "I")?;
                let mut scale = p.float("scale", 1.0)?;
                if let Some((phi, _)) = p.float_opt("power")?
                    && phi > 0.0
                {
                    scale *= phi / (4.0 * PI);
                }
                let from = point(&mut p, "from", DVec3::ZERO)?;
                entries.push(("type", self.string("point", &loc)));
                entries.push(("position", self.vec3(m.transform_point3(from), &loc)));
                entries.push(("intensity", self.vec3(i * scale, &loc)));
            }
            "distant" => {
                let l = spectrum(self, &mut p, "L")?;
                let mut scale = p.float("scale", 1.0)?;
                if let Some((e, _)) = p.float_opt("illuminance")?
                    && e > 0.0
                {
                    scale *= e;
                }
                let from = point(&mut p, "from", DVec3::ZERO)?;
                let to = point(&mut p, "to", DVec3::Z)?;
                let direction = m.transform_vector3(to - from);
                if direction.length_squared() == 0.0 {
                    return Err(loc.error(&what, "\"from\" and \"to\" coincide: no direction"));
                }
                entries.push(("type", self.string("directional", &loc)));
                entries.push(("direction", self.vec3(direction.normalize(), &loc)));
                entries.push(("irradiance", self.vec3(l * scale, &loc)));
            }
            "infinite" => {
                if let Some(q) = p.take("portal") {
                    self.unsupported(&q.loc, &what, "portals are not read yet")?;
                }
                if let Some((f, l)) = p.string_opt("filename")? {
                    if p.has("L") {
                        return Err(loc.error(&what, "both \"L\" and \"filename\": give one"));
                    }
                    if let Some(q) = p.take("illuminance") {
                        self.unsupported(&q.loc, &what, "\"illuminance\" with an image is not read yet (--lenient: \"scale\" alone)")?;
                    }
                    let scale = p.float("scale", 1.0)?;
                    let path = super::parse::resolve(&self.dir, &l.file, &f);
                    let rel = path
                        .strip_prefix(&self.dir)
                        .map_or(path.clone(), std::path::Path::to_path_buf);
                    entries.push(("type", self.string("envmap", &loc)));
                    entries.push(("filename", self.string(&rel.to_string_lossy(), &l)));
                    entries.push(("mapping", self.string("equal_area", &loc)));
                    entries.push(("scale", self.num(scale, &loc)));
                    entries.push(("to_world", self.matrix(m, &loc)));
                    self.finish(&mut p)?;
                    let light = self.table(entries, &loc);
                    self.lights.push(light);
                    return Ok(());
                }
                let l = spectrum(self, &mut p, "L")?;
                let mut scale = p.float("scale", 1.0)?;
                if let Some((e, _)) = p.float_opt("illuminance")?
                    && e > 0.0
                {
                    scale *= e / PI;
                }
                entries.push(("type", self.string("constant", &loc)));
                entries.push(("radiance", self.vec3(l * scale, &loc)));
            }
            "spot" => {
                let i = spectrum(self, &mut p, "I")?;
                let mut scale = p.float("scale", 1.0)?;
                let cone = p.float("coneangle", 30.0)?;
                let delta = p.float("conedeltaangle", 5.0)?;
                if !(cone > 0.0 && cone <= 90.0) {
                    return Err(loc.error(
                        &what,
                        format!("\"coneangle\" {cone}: foton's spot lights take (0, 90] degrees"),
                    ));
                }
                if !(0.0..=cone).contains(&delta) {
                    return Err(loc.error(
                        &what,
                        format!(
                            "\"conedeltaangle\" {delta}: expected within [0, coneangle = {cone}]"
                        ),
                    ));
                }
                let (cos_end, cos_start) =
                    (cone.to_radians().cos(), (cone - delta).to_radians().cos());
                if let Some((phi, _)) = p.float_opt("power")?
                    && phi > 0.0
                {
                    scale *= phi / (2.0 * PI * ((1.0 - cos_start) + (cos_start - cos_end) / 2.0));
                }
                let from = point(&mut p, "from", DVec3::ZERO)?;
                let to = point(&mut p, "to", DVec3::Z)?;
                let axis = m.transform_vector3(to - from);
                if axis.length_squared() == 0.0 {
                    return Err(loc.error(&what, "\"from\" and \"to\" coincide: no direction"));
                }
                entries.push(("type", self.string("spot", &loc)));
                entries.push(("position", self.vec3(m.transform_point3(from), &loc)));
                entries.push(("direction", self.vec3(axis.normalize(), &loc)));
                entries.push(("intensity", self.vec3(i * scale, &loc)));
                entries.push(("cutoff_angle", self.num(cone, &loc)));
                entries.push(("beam_width", self.num(cone - delta, &loc)));
                entries.push(("falloff", self.string("smoothstep", &loc)));
            }
            other @ ("goniometric" | "projection") => {
                return self.unsupported(
                    &loc,
                    &what,
                    &format!("the {other} light is not read yet"),
                );
            }
            other => {
                return Err(loc.error(&what, format!("unknown light {other:?}; pbrt-v4 has point, spot, goniometric, projection, distant and infinite")));
            }
        }
        self.finish(&mut p)?;
        let positional = matches!(d.string(0), "point" | "spot");
        if positional && !self.state.outside.is_empty() {
            let outside = self.state.outside.clone();
            let at = self.state.interface.clone().unwrap_or(loc.clone());
            let key = self.medium_ref(&outside, &at);
            entries.push(("medium", self.string(&key, &loc)));
        }
        let light = self.table(entries, &loc);
        self.lights.push(light);
        Ok(())
    }
}
