//! `[[lights]]`: each entry's `type` looked up in `foton_core::light::LIGHTS`, whose factory
//! reads the rest; a point or spot light with the medium it sits in.

use super::common::{Geometry, Index, Loader, array_of_tables, type_of};
use super::medium::medium_ref;
use foton_core::error::Result;
use foton_core::light::{LIGHTS, Light};
use foton_core::props::Properties;
use foton_core::registry;

/// The lights of `[[lights]]`, each with the medium the file puts it in (`medium`, for lights
/// with a position; None: found from where it lies).
pub(super) fn read_lights(
    root: &Properties<'_>,
    ld: &mut Loader,
    media: &Index,
    g: &mut Geometry,
) -> Result<()> {
    let types: Vec<&str> = registry::names(LIGHTS).collect();
    for l in array_of_tables(root, "lights")? {
        let ty = type_of(&l, &types)?;
        let factory = registry::find(LIGHTS, ty)
            .ok_or_else(|| l.error("type", registry::unknown("light type", ty, LIGHTS)))?;
        let mut nested = Vec::new();
        let light = *(factory.create)(&l, &mut nested, ld)?;
        for bag in &nested {
            ld.done(bag);
        }
        if light.is_environment() && g.lights.iter().any(Light::is_environment) {
            return Err(l.error(
                "type",
                "a scene has at most one environment light (constant or envmap)",
            ));
        }
        let medium = match light.position() {
            Some(_) => medium_ref(&l, "medium", media)?,
            None => None,
        };
        g.lights.push(light);
        g.light_media.push(medium);
        ld.done(&l);
    }
    Ok(())
}
