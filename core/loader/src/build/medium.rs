//! `[media]`, and a medium named by a shape, the camera or a light (`vacuum`: none).

use super::common::{Index, Loader, type_of, undefined};
use foton_core::Rgb;
use foton_core::error::Result;
use foton_core::medium::{Homogeneous, Phase};
use foton_core::props::Properties;
use foton_core::scene::{BoxedMedium, Named};
use foton_core::value::Value;
use std::collections::HashMap;

const MEDIUM_TYPES: &[&str] = &["homogeneous"];

/// A medium named at `key` (`interior`, `exterior`, a camera's or a light's `medium`):
/// None if the key is absent, Some(None) for `"vacuum"`, which names no medium (Mitsuba's
/// side without a medium).
pub(super) fn medium_ref(
    t: &Properties<'_>,
    key: &str,
    media: &Index,
) -> Result<Option<Option<u32>>> {
    match t.string_opt(key)? {
        None => Ok(None),
        Some(VACUUM) => Ok(Some(None)),
        Some(name) => match media.get(name) {
            Some(&id) => Ok(Some(Some(id))),
            None => Err(t.error(key, undefined("medium", name, media))),
        },
    }
}

/// The medium name that means no medium.
const VACUUM: &str = "vacuum";

pub(super) fn read_media(
    root: &Properties<'_>,
    ld: &mut Loader,
) -> Result<(Vec<Named<BoxedMedium>>, Index)> {
    let mut out = Vec::new();
    let mut index = HashMap::new();
    let Some(all) = root.table("media")? else {
        return Ok((out, index));
    };
    let names: Vec<&str> = all.keys().collect();
    for name in names {
        let m = all.table(name)?.unwrap();
        if name == VACUUM {
            return Err(all.error(
                name,
                "`vacuum` is reserved: it names no medium (in `interior`, `exterior` and `medium`); call this medium something else",
            ));
        }
        let ty = type_of(&m, MEDIUM_TYPES)?;
        if ty != "homogeneous" {
            return Err(m.error(
                "type",
                format!(
                    "unknown medium type {ty:?}; expected one of: {}",
                    MEDIUM_TYPES.join(", ")
                ),
            ));
        }
        let sigma_a = m.rgb("sigma_a", Rgb::ZERO)?;
        let sigma_s = m.rgb("sigma_s", Rgb::ZERO)?;
        let phase = match m.node("phase").map(|n| &n.value) {
            None => Phase::Isotropic,
            Some(Value::Str(s)) if s == "isotropic" => Phase::Isotropic,
            Some(Value::Str(s)) => {
                return Err(m.error(
                    "phase",
                    format!("unknown phase function {s:?}; expected \"isotropic\" or {{ type = \"hg\", g = ... }}"),
                ));
            }
            Some(Value::Table(_)) => {
                let p = m.table("phase")?.unwrap();
                let ty = p.choice("type", &["hg", "isotropic"], "hg")?;
                let phase = if ty == "isotropic" {
                    Phase::Isotropic
                } else {
                    let g = p.f32("g", 0.0)?;
                    if g.abs() >= 1.0 {
                        return Err(p.error("g", format!("must satisfy |g| < 1, found {g}")));
                    }
                    Phase::HenyeyGreenstein { g }
                };
                ld.done(&p);
                phase
            }
            Some(other) => {
                return Err(m.error(
                    "phase",
                    format!(
                        "expected \"isotropic\" or {{ type = \"hg\", g = ... }}, found {} `{}`",
                        other.type_name(),
                        other.show()
                    ),
                ));
            }
        };
        index.insert(name.to_string(), out.len() as u32);
        out.push(Named {
            name: name.to_string(),
            value: Box::new(Homogeneous {
                sigma_a,
                sigma_s,
                phase,
            }),
        });
        ld.done(&m);
    }
    ld.done(&all);
    Ok((out, index))
}
