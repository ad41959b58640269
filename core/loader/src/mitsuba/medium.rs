//! `<medium>`: a homogeneous medium into `[media]` (sigma_s and sigma_a, or sigma_t and
//! albedo; scale), with its `<phase>` function.

use super::object::{Obj, Prop};
use super::plugins::not_read;
use super::{Reader, at, table_mut, vec3};
use foton_core::error::{Error, Result};
use foton_core::value::{Table, Value};
use glam::DVec3;

impl Reader {
    /// A medium into `[media]`; returns its name there.
    pub(super) fn medium(&mut self, mut o: Obj) -> Result<String> {
        if o.ty == "heterogeneous" {
            self.unsupported(
                &o,
                "heterogeneous media are not supported yet; rendered as a homogeneous medium of the grids' mean density and albedo",
            )?;
            self.mean_volumes(&mut o)?;
            o.ty = "homogeneous".into();
            o.take("method");
            o.take("step_size");
        }
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
                        "foton's phase functions are isotropic and hg; rendered with the isotropic one",
                    );
                    phase.props.clear();
                    self.unsupported(&phase, &m)?;
                    t.insert("phase", at(Value::Str("isotropic".into()), l));
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

    /// A heterogeneous medium's `<volume>`s (`density` or `sigma_t`, `albedo`) replaced by
    /// their means (lenient: see [`Reader::medium`]): a `constvolume`'s value, a `gridvolume`'s
    /// mean over its cells (Mitsuba's binary `.vol` file), 1 for any other.
    fn mean_volumes(&mut self, o: &mut Obj) -> Result<()> {
        for (name, p, _) in &mut o.props {
            let Prop::Object(v) = p else { continue };
            if v.tag != "volume" {
                continue;
            }
            let mean = match v.ty.as_str() {
                "constvolume" => v.color("value", DVec3::ONE)?,
                "gridvolume" => {
                    let file = v
                        .string("filename")?
                        .ok_or_else(|| v.error("missing `filename`"))?;
                    let path = self.resolve(&v.file, &file).map_err(|looked| {
                        v.error(format!(
                            "`filename` = {file:?}: no such file in {}",
                            super::shown(&looked)
                        ))
                    })?;
                    let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
                    grid_mean(&bytes).ok_or_else(|| {
                        v.error(format!(
                            "{}: not a Mitsuba grid volume (`VOL`, version 3, float32 cells)",
                            path.display()
                        ))
                    })?
                }
                _ => DVec3::ONE,
            };
            // Mitsuba 0.6 names the extinction volume `density`, Mitsuba 3 `sigma_t`.
            if name == "density" {
                *name = "sigma_t".into();
            }
            *p = Prop::Color(mean);
        }
        Ok(())
    }
}

/// The mean of a Mitsuba `.vol` grid's cells (version 3, float32; one channel is grey, three
/// are RGB); None for anything else.
fn grid_mean(bytes: &[u8]) -> Option<DVec3> {
    let int = |at: usize| -> Option<i32> {
        Some(i32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
    };
    if bytes.get(..4)? != b"VOL\x03" || int(4)? != 1 {
        return None;
    }
    let (x, y, z, channels) = (int(8)?, int(12)?, int(16)?, int(20)?);
    if x <= 0 || y <= 0 || z <= 0 || !(channels == 1 || channels == 3) {
        return None;
    }
    let cells = (x as usize)
        .checked_mul(y as usize)?
        .checked_mul(z as usize)?;
    let data = bytes.get(48..48 + cells.checked_mul(channels as usize * 4)?)?;
    let mut sum = DVec3::ZERO;
    for cell in data.chunks_exact(channels as usize * 4) {
        let c = |i: usize| f32::from_le_bytes(cell[4 * i..4 * i + 4].try_into().unwrap_or([0; 4]));
        sum += if channels == 1 {
            DVec3::splat(c(0) as f64)
        } else {
            DVec3::new(c(0) as f64, c(1) as f64, c(2) as f64)
        };
    }
    Some(sum / cells as f64)
}
