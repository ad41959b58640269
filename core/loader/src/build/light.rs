//! `[[lights]]`: point, spot, directional, constant and envmap lights (a point or spot light
//! with the medium it sits in).

use super::common::{Geometry, Index, Loader, array_of_tables, read_transform_at, type_of};
use super::medium::medium_ref;
use crate::texture::load_bitmap;
use foton_core::Rgb;
use foton_core::error::Result;
use foton_core::light::Light;
use foton_core::props::Properties;
use glam::Vec3;

const LIGHT_TYPES: &[&str] = &["point", "spot", "directional", "constant", "envmap"];

/// The lights of `[[lights]]`, each with the medium the file puts it in (`medium`, for point
/// and spot lights; None: found from where it lies).
pub(super) fn read_lights(
    root: &Properties<'_>,
    ld: &mut Loader,
    media: &Index,
    g: &mut Geometry,
) -> Result<()> {
    for l in array_of_tables(root, "lights")? {
        let ty = type_of(&l, LIGHT_TYPES)?;
        if !LIGHT_TYPES.contains(&ty) {
            return Err(l.error(
                "type",
                format!(
                    "unknown light type {ty:?}; expected one of: {}",
                    LIGHT_TYPES.join(", ")
                ),
            ));
        }
        if ty == "constant" || ty == "envmap" {
            if g.lights.iter().any(Light::is_environment) {
                return Err(l.error(
                    "type",
                    "a scene has at most one environment light (constant or envmap)",
                ));
            }
            let light = if ty == "envmap" {
                read_envmap(&l, ld)?
            } else {
                Light::Constant {
                    radiance: l.rgb("radiance", Rgb::ONE)?,
                    centre: Vec3::ZERO,
                    radius: 0.0,
                }
            };
            g.lights.push(light);
            g.light_media.push(None);
            ld.done(&l);
            continue;
        }
        if ty == "directional" {
            g.lights.push(read_directional(&l)?);
            g.light_media.push(None);
            ld.done(&l);
            continue;
        }
        let position = l.vec3_required("position")?;
        g.light_media.push(medium_ref(&l, "medium", media)?);
        if ty == "spot" {
            g.lights.push(read_spot(&l, position)?);
            ld.done(&l);
            continue;
        }
        let intensity = match (l.rgb_opt("intensity")?, l.rgb_opt("power")?) {
            (Some(i), None) => i,
            (None, Some(p)) => p / (4.0 * std::f32::consts::PI),
            (Some(_), Some(_)) => {
                return Err(l.error(
                    "power",
                    "give either intensity (W/sr) or power (W), not both",
                ));
            }
            (None, None) => {
                return Err(l.error(
                    "intensity",
                    "missing; expected intensity = [r, g, b] (W/sr) or power = [r, g, b] (W)",
                ));
            }
        };
        g.lights.push(Light::Point {
            position,
            intensity,
        });
        ld.done(&l);
    }
    Ok(())
}

/// A `type = "directional"` light (Mitsuba's `directional`): `direction` it travels in, and
/// the `irradiance` (W/m^2) it gives a surface facing it.
fn read_directional(l: &Properties<'_>) -> Result<Light> {
    let direction = l.vec3_required("direction")?;
    if direction.length_squared() == 0.0 {
        return Err(l.error("direction", "gives no direction (zero length)"));
    }
    let irradiance = l.rgb("irradiance", Rgb::ONE)?;
    Ok(Light::Directional {
        direction: direction.normalize(),
        irradiance,
        centre: Vec3::ZERO,
        radius: 0.0,
    })
}

/// A `type = "envmap"` light (Mitsuba's `envmap`): the latitude-longitude image `filename`
/// (OpenEXR or Radiance HDR, linear; PNG or JPEG, sRGB-decoded), its radiance times `scale`
/// (default 1), turned by `to_world` (a transform table; only its rotation counts).
fn read_envmap(l: &Properties<'_>, ld: &mut Loader) -> Result<Light> {
    let file = l.string_required("filename")?;
    let scale = l.f32("scale", 1.0)?;
    if scale < 0.0 {
        return Err(l.error("scale", format!("must be non-negative, found {scale}")));
    }
    let to_world = read_transform_at(l, "to_world", ld)?;
    let path = ld.dir.join(file);
    let bitmap = load_bitmap(&path, false).map_err(|e| l.error("filename", e.to_string()))?;
    ld.sources.push(path);
    let map =
        foton_core::envmap::EnvironmentMap::new(&bitmap, scale, glam::Mat3::from_mat4(to_world))
            .map_err(|e| l.error("to_world", e))?;
    Ok(Light::Envmap {
        map: std::sync::Arc::new(map),
        centre: Vec3::ZERO,
        radius: 0.0,
    })
}

/// A `type = "spot"` light (Mitsuba's `spot`): `intensity` (W/sr at the centre, default 1),
/// the axis by `look_at` (a point) or `direction`, `cutoff_angle` (degrees from the axis,
/// default 20) and `beam_width` (default 3/4 of the cutoff).
fn read_spot(l: &Properties<'_>, position: Vec3) -> Result<Light> {
    let intensity = l.rgb("intensity", Rgb::ONE)?;
    let axis = match (l.vec3_opt("look_at")?, l.vec3_opt("direction")?) {
        (Some(target), None) => target - position,
        (None, Some(d)) => d,
        (Some(_), Some(_)) => {
            return Err(l.error("direction", "give either look_at or direction, not both"));
        }
        (None, None) => {
            return Err(l.error(
                "look_at",
                "missing; a spot light needs look_at = [x, y, z] or direction = [x, y, z]",
            ));
        }
    };
    if axis.length_squared() == 0.0 {
        let key = if l.has("look_at") {
            "look_at"
        } else {
            "direction"
        };
        return Err(l.error(key, "gives no direction (zero length)"));
    }
    let cutoff = l.f32("cutoff_angle", 20.0)?;
    if !(cutoff > 0.0 && cutoff <= 90.0) {
        return Err(l.error(
            "cutoff_angle",
            format!("must be in (0, 90] degrees, found {cutoff}"),
        ));
    }
    let beam_width = l.f32("beam_width", 0.75 * cutoff)?;
    if !(beam_width >= 0.0 && beam_width <= cutoff) {
        return Err(l.error(
            "beam_width",
            format!("must be in [0, cutoff_angle = {cutoff}] degrees, found {beam_width}"),
        ));
    }
    Ok(Light::Spot {
        position,
        axis: axis.normalize(),
        intensity,
        beam_width: beam_width.to_radians(),
        cutoff: cutoff.to_radians(),
    })
}
