//! `[media]`, and a medium named by a shape, the camera or a light (`vacuum`: none). A
//! medium's `type` is looked up in `foton_core::medium::MEDIA`, whose factory reads the rest.

use super::common::{Index, Loader, type_of, undefined};
use foton_core::error::Result;
use foton_core::medium::MEDIA;
use foton_core::props::Properties;
use foton_core::registry;
use foton_core::scene::{BoxedMedium, Named};
use std::collections::HashMap;

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
        let types: Vec<&str> = registry::names(MEDIA).collect();
        let ty = type_of(&m, &types)?;
        let factory = registry::find(MEDIA, ty)
            .ok_or_else(|| m.error("type", registry::unknown("medium type", ty, MEDIA)))?;
        let mut nested = Vec::new();
        let medium = (factory.create)(&m, &mut nested, ld)?;
        for bag in &nested {
            ld.done(bag);
        }
        index.insert(name.to_string(), out.len() as u32);
        out.push(Named {
            name: name.to_string(),
            value: medium,
        });
        ld.done(&m);
    }
    ld.done(&all);
    Ok((out, index))
}
