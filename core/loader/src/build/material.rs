//! `[materials]`: each material's `type` looked up in `foton_core::material::MATERIALS`, whose
//! factory reads the rest (textures through the loader's `Resources`).

use super::common::{Index, Loader, type_of};
use foton_core::Rgb;
use foton_core::error::Result;
use foton_core::material::{MATERIALS, Material};
use foton_core::props::Properties;
use foton_core::registry;
use foton_core::registry::Resources;
use foton_core::scene::Named;
use foton_core::texture::Texture;
use std::collections::HashMap;

/// Per material, its `normal_map` (read here, for every type: the shapes that use the
/// material carry it).
pub(super) type NormalMaps = Vec<Option<Texture>>;

/// The materials, their names' index, and their normal maps.
pub(super) fn read_materials(
    root: &Properties<'_>,
    ld: &mut Loader,
) -> Result<(Vec<Named<Material>>, Index, NormalMaps)> {
    let mut out = Vec::new();
    let mut index = HashMap::new();
    let mut normal_maps = Vec::new();
    let Some(all) = root.table("materials")? else {
        return Ok((out, index, normal_maps));
    };
    let types: Vec<&str> = registry::names(MATERIALS).collect();
    let names: Vec<&str> = all.keys().collect();
    for name in names {
        let m = all.table(name)?.unwrap();
        let ty = type_of(&m, &types)?;
        let factory = registry::find(MATERIALS, ty)
            .ok_or_else(|| m.error("type", registry::unknown("material type", ty, MATERIALS)))?;
        let normal_map = if m.has("normal_map") {
            if ty == "null" {
                return Err(m.error(
                    "normal_map",
                    "the null material does not scatter: a normal map has nothing to shade",
                ));
            }
            Some(ld.texture(&m, "normal_map", Rgb::new(0.5, 0.5, 1.0))?)
        } else {
            None
        };
        normal_maps.push(normal_map);
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
    Ok((out, index, normal_maps))
}
