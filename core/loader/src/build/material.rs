//! `[materials]`: each material's `type` looked up in `foton_core::material::MATERIALS`, whose
//! factory reads the rest (textures through the loader's `Resources`).

use super::common::{Index, Loader, type_of};
use foton_core::Rgb;
use foton_core::error::Result;
use foton_core::material::{MATERIALS, Material};
use foton_core::props::Properties;
use foton_core::registry;
use foton_core::registry::Resources;
use foton_core::scene::{BumpMap, MapLight, Named};
use foton_core::texture::Texture;
use std::collections::HashMap;

/// A material's `normal_map` or `bump_map` (read here, for every type: the shapes that use
/// the material carry it).
#[derive(Clone, Default)]
pub(super) struct ShadingMaps {
    pub normal_map: Option<Texture>,
    pub bump_map: Option<BumpMap>,
    pub map_light: MapLight,
}

/// Per material, its shading maps.
pub(super) type NormalMaps = Vec<ShadingMaps>;

/// The materials, their names' index, and their normal and bump maps.
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
        let mut maps = ShadingMaps::default();
        for key in ["normal_map", "bump_map"] {
            if m.has(key) && ty == "null" {
                return Err(m.error(
                    key,
                    "the null material does not scatter: a normal or bump map has nothing to shade",
                ));
            }
        }
        if m.has("normal_map") {
            if m.has("bump_map") {
                return Err(m.error(
                    "bump_map",
                    "a material has a normal_map or a bump_map, not both",
                ));
            }
            maps.normal_map = Some(ld.texture(&m, "normal_map", Rgb::new(0.5, 0.5, 1.0))?);
        }
        if m.has("bump_map") {
            let scale = m.f32("bump_scale", 1.0)?;
            if !scale.is_finite() {
                return Err(m.error("bump_scale", "expected a finite number"));
            }
            maps.bump_map = Some(BumpMap {
                height: ld.texture(&m, "bump_map", Rgb::ZERO)?,
                scale,
            });
        } else if m.has("bump_scale") {
            return Err(m.error("bump_scale", "a bump_scale without a bump_map"));
        }
        for key in ["map_cut_off", "map_shadowing"] {
            if m.has(key) && maps.normal_map.is_none() && maps.bump_map.is_none() {
                return Err(m.error(
                    key,
                    "applies to a normal_map or a bump_map, and there is none",
                ));
            }
        }
        maps.map_light = MapLight {
            cut_off: m.bool("map_cut_off", false)?,
            shadowing: m.bool("map_shadowing", false)?,
        };
        normal_maps.push(maps);
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
