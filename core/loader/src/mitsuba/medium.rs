//! `<medium>`: a homogeneous medium into `[media]` (sigma_s and sigma_a, or sigma_t and
//! albedo; scale), with its `<phase>` function.

use super::object::{Obj, Prop};
use super::plugins::not_read;
use super::{Reader, at, table_mut, vec3};
use foton_core::error::Result;
use foton_core::value::{Table, Value};
use glam::DVec3;

impl Reader {
    /// A medium into `[media]`; returns its name there.
    pub(super) fn medium(&mut self, mut o: Obj) -> Result<String> {
        if o.ty != "homogeneous" {
            return Err(o.error(not_read(
                "medium",
                &o.ty,
                "only homogeneous media are supported",
            )));
        }
        let line = o.line;
        let has = |o: &Obj, k: &str| o.props.iter().any(|(n, _, _)| n == k);
        if has(&o, "material") {
            return Err(o.error("`material` (Mitsuba 0.6's measured media) is not supported: give sigma_s and sigma_a"));
        }
        // Mitsuba 0.6 writes a medium as sigma_s and sigma_a or as sigma_t and albedo (Mitsuba
        // 3 only the latter, and its upgrade drops the former: foton keeps them).
        let (sigma_s, sigma_a) = if has(&o, "sigma_s") || has(&o, "sigma_a") {
            if has(&o, "sigma_t") || has(&o, "albedo") {
                return Err(o.error("give sigma_s and sigma_a, or sigma_t and albedo, not both"));
            }
            (
                o.color("sigma_s", DVec3::ONE)?,
                o.color("sigma_a", DVec3::ONE)?,
            )
        } else {
            let sigma_t = o.color("sigma_t", DVec3::ONE)?;
            let albedo = o.color("albedo", DVec3::splat(0.75))?;
            (sigma_t * albedo, sigma_t * (DVec3::ONE - albedo))
        };
        // Mitsuba 0.6 calls the scale density_multiplier.
        let scale = o.float("density_multiplier", 1.0)?;
        let scale = o.float("scale", scale)?;
        // Whether a medium samples emitters changes noise, not the image.
        o.take("sample_emitters");
        let mut t = Table::default();
        t.insert("type", at(Value::Str("homogeneous".into()), line));
        t.insert("sigma_s", vec3(sigma_s * scale, line));
        t.insert("sigma_a", vec3(sigma_a * scale, line));
        if let Some((Prop::Object(mut phase), l)) = o.take("") {
            match phase.ty.as_str() {
                "isotropic" => t.insert("phase", at(Value::Str("isotropic".into()), l)),
                "hg" => {
                    // Mitsuba 0.6's default g is 0, Mitsuba 3's 0.8.
                    let g = phase.float("g", if self.v1 { 0.0 } else { 0.8 })?;
                    let mut p = Table::default();
                    p.insert("type", at(Value::Str("hg".into()), l));
                    p.insert("g", at(Value::Float(g), l));
                    t.insert("phase", at(Value::Table(p), l));
                }
                _ => {
                    let m = not_read(
                        "phase",
                        &phase.ty,
                        "foton's phase functions are isotropic and hg",
                    );
                    return Err(phase.error(m));
                }
            }
            self.leftovers(&phase)?;
        }
        self.leftovers(&o)?;
        let name = self.new_name("medium", &o.id);
        if let Some(id) = &o.id {
            self.media.insert(id.clone(), name.clone());
        }
        table_mut(&mut self.root, "media").insert(&name, at(Value::Table(t), line));
        Ok(name)
    }
}
