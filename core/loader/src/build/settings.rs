//! `[render]`, `[film]` (with its reconstruction filter) and `[camera]`.

use super::common::{Index, Loader};
use super::medium::medium_ref;
use foton_core::camera::Camera;
use foton_core::error::Result;
use foton_core::filter::{Filter, FilterSampler};
use foton_core::props::Properties;
use foton_core::registry::{self, NoResources};
use foton_core::sampling::{SAMPLERS, SamplerKind};
use foton_core::scene::{FilmSettings, RenderSettings};
use foton_core::value::{Node, Value};
use glam::{Vec2, Vec3};
use std::path::PathBuf;

pub(super) fn read_render(root: &Properties<'_>, ld: &mut Loader) -> Result<RenderSettings> {
    let t = root
        .table("render")?
        .unwrap_or_else(|| Properties::empty(root.file(), "render"));
    let integrator = t.string("integrator", "path")?.to_string();
    let spp = t.u32("spp", 16)?;
    if spp == 0 {
        return Err(t.error("spp", "must be at least 1"));
    }
    let time = t.f32_opt("time")?;
    if let Some(time) = time
        && (time.is_nan() || time <= 0.0)
    {
        return Err(t.error("time", format!("must be above 0 seconds, not {time}")));
    }
    let settings = RenderSettings {
        integrator,
        spp,
        seed: t.u64("seed", 0)?,
        max_depth: t.u32("max_depth", 16)?,
        hide_emitters: t.bool("hide_emitters", false)?,
        sampler: read_sampler(&t, root.node("render"), ld)?,
        time,
    };
    ld.done(&t);
    Ok(settings)
}

/// `[render] sampler`, looked up in `SAMPLERS`, whose factory reads the sampler's parameters
/// (`stratified`'s `jitter`) from `[render]`. A parameter that the sampler does not read but
/// others do is an error that names them, rather than an unknown field.
fn read_sampler(t: &Properties<'_>, node: Option<&Node>, ld: &mut Loader) -> Result<SamplerKind> {
    let name = t.string("sampler", "sobol")?;
    let factory = registry::find(SAMPLERS, name)
        .ok_or_else(|| t.error("sampler", registry::unknown("sampler", name, SAMPLERS)))?;
    let kind = *(factory.create)(t, &mut Vec::new(), ld)?;
    let Some(node) = node else {
        return Ok(kind);
    };
    let unused: Vec<String> = t.unused().into_iter().map(|u| u.key).collect();
    for key in t.keys().filter(|k| unused.contains(&t.key_path(k))) {
        let mut readers = Vec::new();
        for other in SAMPLERS.iter().filter(|f| f.name != name) {
            // Which keys the other sampler reads: its errors are not this scene's.
            let probe = Properties::new(t.file(), t.path(), node)?;
            let _ = (other.create)(&probe, &mut Vec::new(), &mut NoResources);
            if !probe.unused().iter().any(|u| u.key == t.key_path(key)) {
                readers.push(format!("{:?}", other.name));
            }
        }
        if !readers.is_empty() {
            return Err(t.error(
                key,
                format!(
                    "applies to sampler = {} only, not {name:?}",
                    readers.join(" or ")
                ),
            ));
        }
    }
    Ok(kind)
}

pub(super) fn read_film(root: &Properties<'_>, ld: &mut Loader) -> Result<FilmSettings> {
    let t = root
        .table("film")?
        .unwrap_or_else(|| Properties::empty(root.file(), "film"));
    let width = t.u32("width", 256)?;
    let height = t.u32("height", 256)?;
    for (k, v) in [("width", width), ("height", height)] {
        if v == 0 || v > 1 << 15 {
            return Err(t.error(k, format!("must be between 1 and 32768, found {v}")));
        }
    }
    let output = t.string("output", "out.exr")?;
    let out = PathBuf::from(output);
    foton_core::film::format_of(&out).map_err(|_| {
        t.error(
            "output",
            format!("{output:?}: unsupported format; expected a .exr or .png file name"),
        )
    })?;
    use foton_core::film::ToneMap;
    // 2^64 still fits a float with room to spare; beyond, an image is all black or all
    // white whatever the scene, which is surely a typo.
    const MAX_EXPOSURE: f32 = 64.0;
    let exposure = t.f32("exposure", 0.0)?;
    if exposure.abs() > MAX_EXPOSURE {
        return Err(t.error(
            "exposure",
            format!("must be between -{MAX_EXPOSURE} and {MAX_EXPOSURE} stops, found {exposure}"),
        ));
    }
    let tonemap =
        ToneMap::from_name(t.choice("tonemap", &ToneMap::NAMES, "clamp")?).unwrap_or_default();
    let filter = read_filter(&t, ld)?;
    let white_balance = t.f32_opt("white_balance")?;
    if let Some(k) = white_balance
        && !foton_core::spectrum::WHITE_BALANCE_KELVIN.contains(&(k as f64))
    {
        return Err(t.error(
            "white_balance",
            format!("expected a colour temperature between 1000 and 100000 K, found {k}"),
        ));
    }
    let film = FilmSettings {
        width,
        height,
        output: ld.dir.join(out),
        exposure,
        tonemap,
        filter: FilterSampler::new(filter),
        white_balance,
    };
    ld.done(&t);
    Ok(film)
}

/// `[film] filter`: a name ("box", the default, "tent", "gaussian", "mitchell",
/// "catmullrom", "lanczos", "sinc": each with its defaults) or a table with `type` and the
/// filter's parameters, in pixels: `radius` (a number, or `[x, y]` for two radii) of the tent
/// (default 1), the gaussian (default 4 `stddev`; `stddev` default 0.5), mitchell and
/// catmullrom (default 2) and sinc (default 4); mitchell's `b` and `c` (default 1/3 each);
/// lanczos's `lobes` (default 3: the sinc windowed by sinc(x / lobes), radius `lobes`); sinc's
/// `tau` (default 3).
fn read_filter(t: &Properties<'_>, ld: &mut Loader) -> Result<Filter> {
    const TYPES: [&str; 7] = [
        "box",
        "tent",
        "gaussian",
        "mitchell",
        "catmullrom",
        "lanczos",
        "sinc",
    ];
    let expected = "expected \"box\", \"tent\", \"gaussian\", \"mitchell\", \"catmullrom\", \"lanczos\", \"sinc\" or a table such as { type = \"tent\", radius = 1.0 }";
    let filter = match t.node("filter").map(|n| &n.value) {
        None => return Ok(Filter::Box),
        Some(Value::Str(s)) if TYPES.contains(&s.as_str()) => default_filter(s),
        Some(Value::Str(s)) => {
            return Err(t.error("filter", format!("unknown filter {s:?}; {expected}")));
        }
        Some(Value::Table(_)) => {
            let f = t.table("filter")?.unwrap();
            let ty = f.choice("type", &TYPES, "box")?;
            let positive = |key: &str, default: f32| -> Result<f32> {
                let x = f.f32(key, default)?;
                if !(x > 0.0 && x <= 64.0) {
                    return Err(f.error(key, format!("must be in (0, 64] pixels, found {x}")));
                }
                Ok(x)
            };
            // A radius: one number for both axes or [x, y].
            let radius = |default: f32| -> Result<Vec2> {
                let r = match f.node("radius").map(|n| &n.value) {
                    Some(Value::Array(_)) => {
                        let r = f.floats_opt("radius", 2)?.unwrap();
                        Vec2::new(r[0], r[1])
                    }
                    _ => Vec2::splat(f.f32("radius", default)?),
                };
                if !(r.x > 0.0 && r.x <= 256.0 && r.y > 0.0 && r.y <= 256.0) {
                    return Err(f.error(
                        "radius",
                        format!("each radius must be in (0, 256] pixels, found {r}"),
                    ));
                }
                Ok(r)
            };
            let filter = match ty {
                "tent" => Filter::Tent {
                    radius: radius(1.0)?,
                },
                "gaussian" => {
                    let stddev = positive("stddev", 0.5)?;
                    Filter::Gaussian {
                        stddev,
                        radius: radius(4.0 * stddev)?,
                    }
                }
                "mitchell" => Filter::Mitchell {
                    b: f.f32("b", 1.0 / 3.0)?,
                    c: f.f32("c", 1.0 / 3.0)?,
                    radius: radius(2.0)?,
                },
                "catmullrom" => Filter::Mitchell {
                    b: 0.0,
                    c: 0.5,
                    radius: radius(2.0)?,
                },
                "lanczos" => {
                    let lobes = f.u32("lobes", 3)?;
                    if !(1..=64).contains(&lobes) {
                        return Err(f.error("lobes", format!("must be 1 to 64, found {lobes}")));
                    }
                    Filter::lanczos(lobes)
                }
                "sinc" => Filter::Sinc {
                    radius: radius(4.0)?,
                    tau: positive("tau", 3.0)?,
                },
                _ => Filter::Box,
            };
            if let Some(problem) = filter.problem() {
                return Err(f.error("type", problem));
            }
            ld.done(&f);
            return Ok(filter);
        }
        Some(other) => {
            return Err(t.error(
                "filter",
                format!("{expected}, found {} `{}`", other.type_name(), other.show()),
            ));
        }
    };
    Ok(filter)
}

/// A filter by its name alone, with its defaults.
fn default_filter(name: &str) -> Filter {
    match name {
        "tent" => Filter::tent(1.0),
        "gaussian" => Filter::gaussian(0.5),
        "mitchell" => Filter::mitchell(1.0 / 3.0, 1.0 / 3.0),
        "catmullrom" => Filter::catmull_rom(),
        "lanczos" => Filter::lanczos(3),
        "sinc" => Filter::Sinc {
            radius: Vec2::splat(4.0),
            tau: 3.0,
        },
        _ => Filter::Box,
    }
}

/// The camera, and the medium the file puts it in (None: found from where it stands).
pub(super) fn read_camera(
    root: &Properties<'_>,
    film: &FilmSettings,
    media: &Index,
    ld: &mut Loader,
) -> Result<(Camera, Option<Option<u32>>)> {
    let Some(t) = root.table("camera")? else {
        return Err(root.error(
            "camera",
            "missing section [camera]; expected position, look_at, up, fov",
        ));
    };
    let ty = t.choice(
        "type",
        &[
            "perspective",
            "orthographic",
            "radiancemeter",
            "irradiancemeter",
        ],
        "perspective",
    )?;
    if ty.ends_with("meter") {
        return read_meter(&t, ty, film, media, ld);
    }
    let position = t.vec3_required("position")?;
    let look_at = t.vec3_required("look_at")?;
    let up = t.vec3("up", Vec3::Y)?;
    let orthographic = ty == "orthographic";
    if orthographic {
        for key in ["fov", "fov_axis", "lens_radius", "focus_distance"] {
            if t.has(key) {
                return Err(t.error(
                    key,
                    "has no meaning for an orthographic camera (its view is `view_height` tall)",
                ));
            }
        }
    } else {
        for key in ["view_height", "view_width"] {
            if t.has(key) {
                return Err(t.error(
                    key,
                    "is an orthographic camera's (type = \"orthographic\"); a perspective camera takes `fov`",
                ));
            }
        }
    }
    // An orthographic camera's view: its height, or its width (the height following from
    // the image's aspect ratio), in world units.
    let view_height = if orthographic {
        let (key, size) = match (t.f32_opt("view_height")?, t.f32_opt("view_width")?) {
            (Some(_), Some(_)) => {
                return Err(t.error("view_width", "give `view_height` or `view_width`, not both"));
            }
            (Some(h), None) => ("view_height", h),
            (None, Some(w)) => ("view_width", w),
            (None, None) => {
                return Err(t.error(
                    "view_height",
                    "an orthographic camera needs `view_height` (or `view_width`): the size of what it sees, in world units",
                ));
            }
        };
        if !(size > 0.0 && size.is_finite()) {
            return Err(t.error(key, format!("must be positive, found {size}")));
        }
        if key == "view_width" {
            size * film.height as f32 / film.width as f32
        } else {
            size
        }
    } else {
        0.0
    };
    let fov = t.f32("fov", 39.3)?;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(t.error("fov", format!("must be in (0, 180) degrees, found {fov}")));
    }
    // Which extent of the image `fov` spans (Mitsuba's fov_axis); the camera takes the
    // vertical one. tan of the half angles: horizontal = aspect x vertical.
    let axis = t.choice(
        "fov_axis",
        &["y", "x", "diagonal", "smaller", "larger"],
        "y",
    )?;
    let aspect = film.width as f32 / film.height as f32;
    let tan_half = (fov.to_radians() * 0.5).tan();
    let wide = film.width >= film.height;
    let tan_vertical = match axis {
        "x" => tan_half / aspect,
        "diagonal" => tan_half / (1.0 + aspect * aspect).sqrt(),
        "smaller" if wide => tan_half,
        "smaller" => tan_half / aspect,
        "larger" if wide => tan_half / aspect,
        _ => tan_half,
    };
    let fov = 2.0 * tan_vertical.atan().to_degrees();
    let forward = look_at - position;
    if forward.length_squared() == 0.0 {
        return Err(t.error("look_at", "is the same point as position"));
    }
    if forward.normalize().cross(up).length_squared() < 1e-12 {
        return Err(t.error("up", "is zero or parallel to the viewing direction"));
    }
    let mirror = t.bool("mirror", false)?;
    let shift = match t.floats_opt("shift", 2)? {
        Some(s) if s.iter().all(|x| x.is_finite()) => Vec2::new(s[0], s[1]),
        Some(s) => return Err(t.error("shift", format!("must be finite, found {s:?}"))),
        None => Vec2::ZERO,
    };
    // A thin lens: focused by default on the look_at point (its distance along the view).
    let lens_radius = t.f32("lens_radius", 0.0)?;
    if !(lens_radius >= 0.0 && lens_radius.is_finite()) {
        return Err(t.error(
            "lens_radius",
            format!("must be zero (a pinhole) or positive, found {lens_radius}"),
        ));
    }
    let focus_distance = t.f32("focus_distance", forward.length())?;
    if !(focus_distance > 0.0 && focus_distance.is_finite()) {
        return Err(t.error(
            "focus_distance",
            format!("must be positive, found {focus_distance}"),
        ));
    }
    let medium = medium_ref(&t, "medium", media)?;
    ld.done(&t);
    let mut camera = if orthographic {
        Camera::orthographic(position, look_at, up, view_height, film.width, film.height)
            .with_shift(shift)
    } else {
        Camera::new(position, look_at, up, fov, film.width, film.height)
            .with_shift(shift)
            .with_lens(lens_radius, focus_distance)
    };
    if mirror {
        camera = camera.mirrored();
    }
    Ok((camera, medium))
}

/// A meter ([`foton_core::camera::Meter`]) as the camera: a radiance meter's ray (`position`,
/// `look_at`), or an irradiance meter, whose surface is the shapes marked `sensor = true`
/// (attached once the shapes are read: here a placeholder). Either measures on a film of one
/// pixel with the box filter.
fn read_meter(
    t: &Properties<'_>,
    ty: &str,
    film: &FilmSettings,
    media: &Index,
    ld: &mut Loader,
) -> Result<(Camera, Option<Option<u32>>)> {
    for key in [
        "fov",
        "fov_axis",
        "lens_radius",
        "focus_distance",
        "view_height",
        "view_width",
        "shift",
        "mirror",
    ] {
        if t.has(key) {
            return Err(t.error(key, format!("has no meaning for a {ty}")));
        }
    }
    if (film.width, film.height) != (1, 1) {
        return Err(t.error(
            "type",
            format!(
                "a {ty} measures one value: its film must be 1x1 pixels, found {}x{}",
                film.width, film.height
            ),
        ));
    }
    if *film.filter.filter() != Filter::Box {
        return Err(t.error(
            "type",
            format!("a {ty}'s film of one pixel takes the box filter (`[film] filter = \"box\"`)"),
        ));
    }
    let camera = if ty == "radiancemeter" {
        let position = t.vec3_required("position")?;
        let look_at = t.vec3_required("look_at")?;
        let up = t.vec3("up", Vec3::Y)?;
        let forward = look_at - position;
        if forward.length_squared() == 0.0 {
            return Err(t.error("look_at", "is the same point as position"));
        }
        let up = if forward.normalize().cross(up).length_squared() < 1e-12 {
            // The meter has no image to orient: any other axis does.
            if forward.x.abs() < 0.9 {
                Vec3::X
            } else {
                Vec3::Y
            }
        } else {
            up
        };
        Camera::radiance_meter(position, look_at, up)
    } else {
        for key in ["position", "look_at", "up"] {
            if t.has(key) {
                return Err(t.error(
                    key,
                    "has no meaning for an irradiancemeter: it measures over the shapes marked `sensor = true`",
                ));
            }
        }
        Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, 1.0, 1, 1)
    };
    let medium = medium_ref(t, "medium", media)?;
    ld.done(t);
    Ok((camera, medium))
}
