//! `[materials]`: each material's `type` looked up in `foton_core::material::MATERIALS`, whose
//! factory reads the rest (textures through the loader's `Resources`).

use super::common::{Index, Loader, type_of};
use foton_core::error::Result;
use foton_core::material::{MATERIALS, Material};
use foton_core::props::Properties;
use foton_core::registry;
use foton_core::scene::Named;
use std::collections::HashMap;

pub(super) fn read_materials(
    root: &Properties<'_>,
    ld: &mut Loader,
) -> Result<(Vec<Named<Material>>, Index)> {
    let mut out = Vec::new();
    let mut index = HashMap::new();
    let Some(all) = root.table("materials")? else {
        return Ok((out, index));
    };
    let types: Vec<&str> = registry::names(MATERIALS).collect();
    let names: Vec<&str> = all.keys().collect();
    for name in names {
        let m = all.table(name)?.unwrap();
        let ty = type_of(&m, &types)?;
        let factory = registry::find(MATERIALS, ty)
            .ok_or_else(|| m.error("type", registry::unknown("material type", ty, MATERIALS)))?;
        let mut nested = Vec::new();
        let material = *(factory.create)(&m, &mut nested, ld)?;
        for bag in &nested {
            ld.done(bag);
        }
        index.insert(name.to_string(), out.len() as u32);
        out.push(Named {
            name: name.to_string(),
            value: material,
        });
        ld.done(&m);
    }
    ld.done(&all);
    Ok((out, index))
}
