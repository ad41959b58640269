//! `LightSource` into `[[lights]]` (lights.cpp): `point` (`I`, `from`, `scale`, `power`),
//! `distant` (`L`, `from`, `to`, `scale`, `illuminance`) and `infinite` with a constant `L`
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
        let mut p = Bag::new(d);
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
                if let Some((f, l)) = p.string_opt("filename")? {
                    return self.unsupported(&l, &what, &format!("\"filename\" {f:?}: environment maps (pbrt-v4's equal-area octahedral images) are not read yet"));
                }
                if let Some(q) = p.take("portal") {
                    self.unsupported(&q.loc, &what, "portals are not read yet")?;
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
            other @ ("spot" | "goniometric" | "projection") => {
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
        let light = self.table(entries, &loc);
        self.lights.push(light);
        Ok(())
    }
}
