//! Loading a scene file (TOML, see docs/scene-format.md) into a [`Scene`].
//!
//! Every table is read through a [`Properties`] bag, so every error names file, line, key path
//! and what was expected, and every key that was never read is reported as unused.

use crate::document::TomlDocument;
use crate::mesh::{MeshOptions, load_mesh};
use crate::texture::{load_bitmap, read_texture_param};
use foton_core::Rgb;
use foton_core::camera::Camera;
use foton_core::error::{Error, Result};
use foton_core::filter::{Filter, FilterSampler};
use foton_core::geometry::{NO_ATTRS, Primitive, Shape, TriangleAttrs};
use foton_core::glossy::{Plastic, RoughConductor, RoughDielectric, RoughPlastic};
use foton_core::light::{Light, area_light};
use foton_core::material::Material;
use foton_core::medium::{Homogeneous, Phase};
use foton_core::microfacet::{Microfacet, MicrofacetKind};
use foton_core::props::{Properties, Unused};
use foton_core::sampling::SamplerKind;
use foton_core::scene::{
    BoxedMedium, FilmSettings, Named, Object, RenderSettings, Scene, SceneParts,
};
use foton_core::texture::Texture;
use foton_core::value::{Document, Value};
use glam::{Mat4, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

const SECTIONS: &[&str] = &[
    "render",
    "film",
    "camera",
    "integrators",
    "materials",
    "media",
    "shapes",
    "lights",
    "scene",
];
const MATERIAL_TYPES: &[&str] = &[
    "diffuse",
    "mirror",
    "conductor",
    "roughconductor",
    "dielectric",
    "thindielectric",
    "roughdielectric",
    "plastic",
    "roughplastic",
    "null",
];
const SHAPE_TYPES: &[&str] = &["sphere", "quad", "disk", "mesh"];
const LIGHT_TYPES: &[&str] = &["point", "spot", "directional", "constant", "envmap"];
const MEDIUM_TYPES: &[&str] = &["homogeneous"];

/// Collects the bags of a load so that unused keys can be listed at the end.
struct Loader {
    dir: PathBuf,
    sources: Vec<PathBuf>,
    bags: Vec<Vec<Unused>>,
    warnings: Vec<String>,
}

impl Loader {
    fn done(&mut self, bag: &Properties<'_>) {
        self.bags.push(bag.unused());
    }

    fn warn(&mut self, bag: &Properties<'_>, key: &str, message: String) {
        self.warnings.push(format!(
            "{}: `{}`: {message}",
            bag.location(key),
            bag.key_path(key)
        ));
    }
}

/// Loads a scene file, applying `--set` style overrides first.
pub fn load(path: &Path, overrides: &[String]) -> Result<Scene> {
    load_with(path, overrides, &[], false)
}

/// Loads a scene file: TOML, or a Mitsuba XML scene (`.xml`) whose `<default>`s `defines`
/// (`NAME=VALUE`, Mitsuba's `-D`) override and whose unsupported elements are left out and
/// listed among the warnings if `lenient`. `--set` style `overrides` apply to the document in
/// both cases (for XML: to the TOML it reads as).
pub fn load_with(
    path: &Path,
    overrides: &[String],
    defines: &[String],
    lenient: bool,
) -> Result<Scene> {
    let is_xml = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
    let (mut doc, report) = if is_xml {
        if path.is_dir() {
            return Err(foton_core::Error::io(
                path,
                "is a directory, not a scene file",
            ));
        }
        let (doc, report) = crate::mitsuba::read_xml(path, defines, lenient)?;
        (doc, Some(report))
    } else {
        if let Some(d) = defines.first() {
            return Err(foton_core::Error::Usage(format!(
                "-D {d}: defaults are for Mitsuba XML scenes; use --set KEY.PATH=VALUE for a TOML scene"
            )));
        }
        (Document::load(path)?, None)
    };
    for o in overrides {
        doc.set(o)?;
    }
    let mut scene = from_document(doc)?;
    if let Some(report) = report {
        if let Some((integrator, factor, line)) = &report.relative_radius {
            set_relative_radius(&mut scene, integrator, *factor, *line);
        }
        let left_out = report.left_out.iter().map(|l| format!("left out: {l}"));
        scene.add_report(
            report.included,
            left_out.chain(report.notes).collect::<Vec<_>>(),
            report.warnings,
        );
    }
    Ok(scene)
}

/// The scene a parsed document describes.
pub fn from_document(doc: Document) -> Result<Scene> {
    let file = doc.file.clone();
    let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut ld = Loader {
        dir,
        sources: Vec::new(),
        bags: Vec::new(),
        warnings: Vec::new(),
    };
    let root = Properties::root(&file, &doc.root);
    for key in root.keys() {
        if !SECTIONS.contains(&key) {
            return Err(root.error(
                key,
                format!("unknown section; expected one of: {}", SECTIONS.join(", ")),
            ));
        }
    }
    root.node("integrators");

    let render = read_render(&root, &mut ld)?;
    let film = read_film(&root, &mut ld)?;
    let (materials, material_index) = read_materials(&root, &mut ld)?;
    let (media, medium_index) = read_media(&root, &mut ld)?;
    let (camera, camera_placed) = read_camera(&root, &film, &medium_index, &mut ld)?;

    let mut objects = Vec::new();
    let mut prims = Vec::new();
    let mut triangle_attrs = Vec::new();
    let mut lights = Vec::new();
    read_shapes(
        &root,
        &mut ld,
        &materials,
        &material_index,
        &medium_index,
        &mut objects,
        (&mut prims, &mut triangle_attrs),
        &mut lights,
    )?;
    // Per light: the medium the file puts it in (None: found from where it lies).
    let mut light_media: Vec<Option<Option<u32>>> = lights
        .iter()
        .map(|l| match *l {
            Light::Area { object, .. } => {
                let o: &Object = &objects[object as usize];
                // Mitsuba's area emitter emits into its shape's exterior.
                o.explicit_media.then_some(o.exterior)
            }
            _ => None,
        })
        .collect();
    read_point_lights(&root, &mut ld, &medium_index, &mut lights, &mut light_media)?;

    let mut medium = None;
    if let Some(scene) = root.table("scene")? {
        if let Some(name) = scene.string_opt("medium")? {
            medium =
                Some(*medium_index.get(name).ok_or_else(|| {
                    scene.error("medium", undefined("medium", name, &medium_index))
                })?);
        }
        ld.done(&scene);
    }

    if lights.is_empty() {
        ld.warnings.push(format!(
            "{}: the scene has no lights: the image will be black",
            file.display()
        ));
    }
    ld.done(&root);
    let mut unused: Vec<Unused> = ld.bags.into_iter().flatten().collect();
    unused.sort_by(|a, b| (a.location.line, &a.key).cmp(&(b.location.line, &b.key)));
    let warnings = ld.warnings;
    let sources = ld.sources;
    // Where the error is if the medium around the camera turns out undefined (the scene
    // takes the document, which the bags borrow).
    let camera_error = match root.table("camera").ok().flatten() {
        Some(t) => t.error("position", ""),
        None => root.error("camera", ""),
    };
    Scene::new(SceneParts {
        file,
        render,
        film,
        camera,
        camera_medium: camera_placed,
        materials,
        media,
        objects,
        primitives: prims,
        triangle_attrs,
        lights,
        light_media,
        medium,
        document: doc,
        sources,
        unused,
        warnings,
    })
    .map_err(|why| match camera_error {
        Error::Scene { location, key, .. } => Error::Scene {
            location,
            key,
            message: format!("the medium around the camera is undefined: {why}; move the camera"),
        },
        other => other,
    })
}

/// A Mitsuba photon mapper's lookup radius, a fraction of the radius of the scene's bounding
/// sphere (Mitsuba's `getBSphere`: around the bounding box, half its diagonal), as the
/// plugin's `max_radius` in world units, unless the document already gives one (`--set`).
pub fn set_relative_radius(scene: &mut Scene, integrator: &str, factor: f64, line: u32) {
    use foton_core::value::{Node, Value};
    let (lo, hi) = scene.bounds();
    let radius = 0.5 * f64::from((hi - lo).length());
    if !radius.is_finite() || radius <= 0.0 {
        return;
    }
    let node = |value| Node {
        value,
        line,
        column: u32::from(line > 0),
    };
    let root = &mut scene.document_mut().root;
    if root.get("integrators").is_none() {
        root.insert("integrators", node(Value::Table(Default::default())));
    }
    let Some(Value::Table(integrators)) = root.get_mut("integrators").map(|n| &mut n.value) else {
        return;
    };
    if integrators.get(integrator).is_none() {
        integrators.insert(integrator, node(Value::Table(Default::default())));
    }
    if let Some(Value::Table(t)) = integrators.get_mut(integrator).map(|n| &mut n.value)
        && t.get("max_radius").is_none()
    {
        t.insert("max_radius", node(Value::Float(factor * radius)));
    }
}

fn undefined(kind: &str, name: &str, known: &HashMap<String, u32>) -> String {
    let mut names: Vec<&str> = known.keys().map(String::as_str).collect();
    names.sort();
    if names.is_empty() {
        {
            let plural = if kind == "medium" {
                "media"
            } else {
                "materials"
            };
            format!("{kind} {name:?} is not defined (no {plural} are defined)")
        }
    } else {
        format!(
            "{kind} {name:?} is not defined; defined: {}",
            names.join(", ")
        )
    }
}

fn read_render(root: &Properties<'_>, ld: &mut Loader) -> Result<RenderSettings> {
    let t = root
        .table("render")?
        .unwrap_or_else(|| Properties::empty(root.file(), "render"));
    let integrator = t.string("integrator", "path")?.to_string();
    let spp = t.u32("spp", 16)?;
    if spp == 0 {
        return Err(t.error("spp", "must be at least 1"));
    }
    let settings = RenderSettings {
        integrator,
        spp,
        seed: t.u64("seed", 0)?,
        max_depth: t.u32("max_depth", 16)?,
        hide_emitters: t.bool("hide_emitters", false)?,
        sampler: read_sampler(&t)?,
    };
    ld.done(&t);
    Ok(settings)
}

/// `[render] sampler` and, for `stratified`, `jitter`.
fn read_sampler(t: &Properties<'_>) -> Result<SamplerKind> {
    let name = t.choice("sampler", &SamplerKind::NAMES, "sobol")?;
    let jitter = t.bool("jitter", true)?;
    let kind = SamplerKind::from_name(name, jitter).expect("a name of SamplerKind::NAMES");
    if t.has("jitter") && !matches!(kind, SamplerKind::Stratified { .. }) {
        return Err(t.error(
            "jitter",
            format!(
                "applies to sampler = \"stratified\" only, not {:?}",
                kind.name()
            ),
        ));
    }
    Ok(kind)
}

fn read_film(root: &Properties<'_>, ld: &mut Loader) -> Result<FilmSettings> {
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
    let film = FilmSettings {
        width,
        height,
        output: ld.dir.join(out),
        exposure,
        tonemap,
        filter: FilterSampler::new(filter),
    };
    ld.done(&t);
    Ok(film)
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

/// `[film] filter`: "box" (the default), "tent", "gaussian", or a table with `type` and the
/// filter's parameter (`radius` of the tent, default 1; `stddev` of the gaussian, default
/// 0.5), in pixels.
fn read_filter(t: &Properties<'_>, ld: &mut Loader) -> Result<Filter> {
    const TYPES: [&str; 3] = ["box", "tent", "gaussian"];
    let expected = "expected \"box\", \"tent\", \"gaussian\" or a table such as { type = \"tent\", radius = 1.0 }";
    let ty = match t.node("filter").map(|n| &n.value) {
        None => return Ok(Filter::Box),
        Some(Value::Str(s)) if TYPES.contains(&s.as_str()) => s.as_str(),
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
            let filter = match ty {
                "tent" => Filter::Tent {
                    radius: positive("radius", 1.0)?,
                },
                "gaussian" => Filter::Gaussian {
                    stddev: positive("stddev", 0.5)?,
                },
                _ => Filter::Box,
            };
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
    Ok(match ty {
        "tent" => Filter::Tent { radius: 1.0 },
        "gaussian" => Filter::Gaussian { stddev: 0.5 },
        _ => Filter::Box,
    })
}

/// The camera, and the medium the file puts it in (None: found from where it stands).
fn read_camera(
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
    let position = t.vec3_required("position")?;
    let look_at = t.vec3_required("look_at")?;
    let up = t.vec3("up", Vec3::Y)?;
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
    let medium = medium_ref(&t, "medium", media)?;
    ld.done(&t);
    let camera = Camera::new(position, look_at, up, fov, film.width, film.height);
    Ok((camera, medium))
}

/// A medium named at `key` (`interior`, `exterior`, a camera's or a light's `medium`):
/// None if the key is absent, Some(None) for `"vacuum"`, which names no medium (Mitsuba's
/// side without a medium).
fn medium_ref(t: &Properties<'_>, key: &str, media: &Index) -> Result<Option<Option<u32>>> {
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

type Index = HashMap<String, u32>;

fn read_materials(root: &Properties<'_>, ld: &mut Loader) -> Result<(Vec<Named<Material>>, Index)> {
    let mut out = Vec::new();
    let mut index = HashMap::new();
    let Some(all) = root.table("materials")? else {
        return Ok((out, index));
    };
    let names: Vec<&str> = all.keys().collect();
    for name in names {
        let m = all.table(name)?.unwrap();
        let ty = m.string_opt("type")?.ok_or_else(|| {
            m.error(
                "type",
                format!("missing; expected one of: {}", MATERIAL_TYPES.join(", ")),
            )
        })?;
        // A colour that may be a texture; a reflectance above 1 is warned about.
        let mut texture = |key: &str, default: Rgb, reflectance: bool| -> Result<Texture> {
            let (t, bag) = read_texture_param(&m, key, default, &ld.dir)?;
            if let Some(bag) = bag {
                ld.done(&bag);
            }
            if reflectance && t.max().max_element() > 1.0 {
                ld.warn(&m, key, "is above 1: the material creates energy".into());
            }
            Ok(t)
        };
        let material = match ty {
            "diffuse" => Material::Diffuse {
                reflectance: texture("reflectance", Rgb::splat(0.5), true)?,
                twosided: m.bool("twosided", true)?,
            },
            "mirror" => Material::Mirror {
                reflectance: texture("reflectance", Rgb::ONE, true)?,
            },
            "conductor" => {
                let specular_reflectance = texture("specular_reflectance", Rgb::ONE, false)?;
                match read_conductor_ior(&m)? {
                    Some((eta, k)) => Material::Conductor {
                        eta,
                        k,
                        specular_reflectance,
                    },
                    // Mitsuba's default: a perfect mirror.
                    None => Material::Mirror {
                        reflectance: specular_reflectance,
                    },
                }
            }
            "roughconductor" => {
                let specular_reflectance = texture("specular_reflectance", Rgb::ONE, false)?;
                // No named material and no eta, k: a perfect (rough) mirror, F = 1.
                let (eta, k) = read_conductor_ior(&m)?.unwrap_or((Rgb::ZERO, Rgb::ZERO));
                Material::RoughConductor {
                    lobe: RoughConductor {
                        distribution: read_microfacet(&m, true)?,
                        eta,
                        k,
                        specular_reflectance: Rgb::ONE,
                    },
                    specular_reflectance,
                    twosided: m.bool("twosided", true)?,
                }
            }
            "roughdielectric" => Material::RoughDielectric {
                lobe: RoughDielectric {
                    distribution: read_microfacet(&m, true)?,
                    eta: read_ior(&m, 1.5)?,
                    specular_reflectance: Rgb::ONE,
                    specular_transmittance: Rgb::ONE,
                },
                specular_reflectance: texture("specular_reflectance", Rgb::ONE, false)?,
                specular_transmittance: texture("specular_transmittance", Rgb::ONE, false)?,
            },
            "plastic" | "roughplastic" => {
                // Mitsuba's default: polypropylene in air.
                let eta = read_ior(&m, 1.49 / 1.000277)?;
                let diffuse_reflectance = texture("diffuse_reflectance", Rgb::splat(0.5), true)?;
                let specular_reflectance = texture("specular_reflectance", Rgb::ONE, false)?;
                let nonlinear = m.bool("nonlinear", false)?;
                let twosided = m.bool("twosided", true)?;
                // The lobes' colours are set at each point from the textures.
                let (diffuse, specular) = (Rgb::splat(0.5), Rgb::ONE);
                if ty == "plastic" {
                    Material::Plastic {
                        lobe: Plastic {
                            eta,
                            diffuse_reflectance: diffuse,
                            specular_reflectance: specular,
                            nonlinear,
                        },
                        diffuse_reflectance,
                        specular_reflectance,
                        twosided,
                    }
                } else {
                    let d = read_microfacet(&m, false)?;
                    Material::RoughPlastic {
                        lobe: RoughPlastic::new(
                            d.kind, d.alpha_u, eta, diffuse, specular, nonlinear,
                        ),
                        diffuse_reflectance,
                        specular_reflectance,
                        twosided,
                    }
                }
            }
            "dielectric" | "thindielectric" => {
                let ior = read_ior(&m, 1.5)?;
                if ty == "dielectric" {
                    Material::Dielectric { ior }
                } else {
                    Material::ThinDielectric { ior }
                }
            }
            "null" => Material::Null,
            other => {
                return Err(m.error(
                    "type",
                    format!(
                        "unknown material type {other:?}; expected one of: {}",
                        MATERIAL_TYPES.join(", ")
                    ),
                ));
            }
        };
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

/// A conductor's complex index of refraction: a named `material` (Mitsuba's names; `none`: a
/// perfect mirror) or `eta` and `k`. None: a perfect mirror.
fn read_conductor_ior(m: &Properties<'_>) -> Result<Option<(Rgb, Rgb)>> {
    let named = m.string_opt("material")?;
    let (eta, k) = (m.rgb_opt("eta")?, m.rgb_opt("k")?);
    match (named, eta, k) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => Err(m.error(
            "material",
            "give either a named `material` or `eta` and `k`, not both",
        )),
        (None, Some(eta), Some(k)) => Ok(Some((eta, k))),
        (None, Some(_), None) | (None, None, Some(_)) => {
            let missing = if m.has("eta") { "k" } else { "eta" };
            Err(m.error(
                missing,
                "missing: a conductor's index of refraction needs both eta and k",
            ))
        }
        (None, None, None) | (Some("none"), None, None) => Ok(None),
        (Some(name), None, None) => {
            let found = foton_core::material::conductor(name).ok_or_else(|| {
                let names: Vec<&str> = foton_core::material::CONDUCTORS
                    .iter()
                    .map(|(n, _, _)| *n)
                    .collect();
                m.error(
                    "material",
                    format!(
                        "unknown conductor `{name}`; expected none or one of: {}",
                        names.join(", ")
                    ),
                )
            })?;
            Ok(Some(found))
        }
    }
}

/// A relative index of refraction `ior` (inside over outside), positive.
fn read_ior(m: &Properties<'_>, default: f32) -> Result<f32> {
    let ior = m.f32("ior", default)?;
    if ior <= 0.0 || !ior.is_finite() {
        return Err(m.error("ior", format!("must be positive, found {ior}")));
    }
    Ok(ior)
}

/// A microfacet distribution: `distribution` (`beckmann`, Mitsuba's default, or `ggx`) and
/// `alpha` (default 0.1), or `alpha_u` and `alpha_v` where `anisotropic` lobes are allowed.
fn read_microfacet(m: &Properties<'_>, anisotropic: bool) -> Result<Microfacet> {
    let kind = match m.string("distribution", "beckmann")? {
        "beckmann" => MicrofacetKind::Beckmann,
        "ggx" => MicrofacetKind::Ggx,
        other => {
            return Err(m.error(
                "distribution",
                format!("unknown distribution {other:?}; expected beckmann or ggx"),
            ));
        }
    };
    let positive = |key: &str, x: f32| {
        if x > 0.0 && x.is_finite() {
            Ok(x)
        } else {
            Err(m.error(key, format!("must be positive, found {x}")))
        }
    };
    if m.has("alpha_u") || m.has("alpha_v") {
        if !anisotropic {
            return Err(m.error(
                if m.has("alpha_u") {
                    "alpha_u"
                } else {
                    "alpha_v"
                },
                "this material's roughness is isotropic: give `alpha`",
            ));
        }
        if m.has("alpha") {
            return Err(m.error("alpha", "give either `alpha` or `alpha_u` and `alpha_v`"));
        }
        let u = positive("alpha_u", m.f32_required("alpha_u")?)?;
        let v = positive("alpha_v", m.f32_required("alpha_v")?)?;
        return Ok(Microfacet::new(kind, u, v));
    }
    let alpha = positive("alpha", m.f32("alpha", 0.1)?)?;
    Ok(Microfacet::isotropic(kind, alpha))
}

fn read_media(root: &Properties<'_>, ld: &mut Loader) -> Result<(Vec<Named<BoxedMedium>>, Index)> {
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
        let ty = m.string_opt("type")?.ok_or_else(|| {
            m.error(
                "type",
                format!("missing; expected one of: {}", MEDIUM_TYPES.join(", ")),
            )
        })?;
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

/// The `[[shapes]]` or `[[lights]]` array: (key path, bag) per element.
fn array_of_tables<'a>(root: &Properties<'a>, key: &str) -> Result<Vec<Properties<'a>>> {
    let Some(node) = root.node(key) else {
        return Ok(Vec::new());
    };
    let Value::Array(items) = &node.value else {
        return Err(root.error(
            key,
            format!(
                "expected an array of tables ([[{key}]]), found {}",
                node.value.type_name()
            ),
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(i, item)| Properties::new(root.file(), &format!("{key}[{i}]"), item))
        .collect()
}

fn read_transform(s: &Properties<'_>, ld: &mut Loader) -> Result<Mat4> {
    read_transform_at(s, "transform", ld)
}

/// The transform table `key` of `s` (`matrix`, or translate, rotate and scale).
fn read_transform_at(s: &Properties<'_>, key: &str, ld: &mut Loader) -> Result<Mat4> {
    let Some(t) = s.table(key)? else {
        return Ok(Mat4::IDENTITY);
    };
    if let Some(m) = t.floats_opt("matrix", 16)? {
        if let Some(other) = ["translate", "rotate", "scale"].iter().find(|k| t.has(k)) {
            return Err(t.error(
                other,
                "a transform is either `matrix` or translate, rotate and scale, not both",
            ));
        }
        // Row-major, as written (and as Mitsuba's <matrix value="..."/>).
        let m = Mat4::from_cols_slice(&m).transpose();
        if m.row(3) != glam::Vec4::W {
            return Err(t.error(
                "matrix",
                "the last row must be [0, 0, 0, 1] (an affine transform)",
            ));
        }
        if m.determinant() == 0.0 {
            return Err(t.error("matrix", "is singular (it flattens the mesh)"));
        }
        ld.done(&t);
        return Ok(m);
    }
    let translate = t.vec3("translate", Vec3::ZERO)?;
    let scale = match t.node("scale").map(|n| &n.value) {
        None => Vec3::ONE,
        Some(Value::Array(_)) => t.vec3_required("scale")?,
        Some(_) => Vec3::splat(t.f32_required("scale")?),
    };
    if scale.x * scale.y * scale.z == 0.0 {
        return Err(t.error("scale", "must not be zero"));
    }
    let rotate = match t.table("rotate")? {
        None => Mat4::IDENTITY,
        Some(r) => {
            let axis = r.vec3_required("axis")?;
            if axis.length_squared() == 0.0 {
                return Err(r.error("axis", "must not be the zero vector"));
            }
            let degrees = r.f32_required("degrees")?;
            ld.done(&r);
            Mat4::from_axis_angle(axis.normalize(), degrees.to_radians())
        }
    };
    ld.done(&t);
    Ok(Mat4::from_translation(translate) * rotate * Mat4::from_scale(scale))
}

#[allow(clippy::too_many_arguments)]
fn read_shapes(
    root: &Properties<'_>,
    ld: &mut Loader,
    material_defs: &[Named<Material>],
    materials: &Index,
    media: &Index,
    objects: &mut Vec<Object>,
    (prims, triangle_attrs): (&mut Vec<Primitive>, &mut Vec<TriangleAttrs>),
    lights: &mut Vec<Light>,
) -> Result<()> {
    for s in array_of_tables(root, "shapes")? {
        let ty = s.string_opt("type")?.ok_or_else(|| {
            s.error(
                "type",
                format!("missing; expected one of: {}", SHAPE_TYPES.join(", ")),
            )
        })?;
        let mut closed = ty == "sphere";
        let flip = s.bool("flip_normals", false)?;
        let mut attrs = Vec::new();
        let mut shapes = match ty {
            "sphere" => {
                let center = s.vec3_required("center")?;
                let radius = s.f32_required("radius")?;
                if radius <= 0.0 {
                    return Err(s.error("radius", format!("must be positive, found {radius}")));
                }
                vec![Shape::sphere(center, radius)]
            }
            "quad" => {
                let origin = s.vec3_required("origin")?;
                let u = s.vec3_required("u")?;
                let v = s.vec3_required("v")?;
                if u.cross(v).length_squared() == 0.0 {
                    return Err(
                        s.error("v", "u and v are parallel or zero: the quad has zero area")
                    );
                }
                vec![Shape::quad(origin, u, v)]
            }
            "disk" => {
                let center = s.vec3_required("center")?;
                // Either the two semi-axes (an ellipse; Mitsuba's disk under its to_world, which
                // also fixes where the angle of its texture coordinates starts) or a circle.
                let (u, v) = if s.has("u") || s.has("v") {
                    (s.vec3_required("u")?, s.vec3_required("v")?)
                } else {
                    let normal = s.vec3_required("normal")?;
                    let radius = s.f32_required("radius")?;
                    if radius <= 0.0 {
                        return Err(s.error("radius", format!("must be positive, found {radius}")));
                    }
                    if normal.length_squared() == 0.0 {
                        return Err(s.error("normal", "must not be the zero vector"));
                    }
                    let f = foton_core::bsdf::Frame::from_normal(normal.normalize());
                    (f.s * radius, f.t * radius)
                };
                if u.cross(v).length_squared() == 0.0 {
                    return Err(
                        s.error("v", "u and v are parallel or zero: the disk has zero area")
                    );
                }
                vec![Shape::disk(center, u, v)]
            }
            "mesh" => {
                let file = s.string_required("file")?;
                let transform = read_transform(&s, ld)?;
                let options = MeshOptions {
                    face_normals: s.bool("face_normals", false)?,
                    flip_tex_coords: s.bool("flip_tex_coords", true)?,
                    flip_normals: flip,
                };
                let path = ld.dir.join(file);
                let mesh = load_mesh(&s, &path, transform, options)?;
                ld.sources.push(path);
                closed = mesh.closed;
                attrs = mesh.attrs;
                mesh.triangles
            }
            other => {
                return Err(s.error(
                    "type",
                    format!(
                        "unknown shape type {other:?}; expected one of: {}",
                        SHAPE_TYPES.join(", ")
                    ),
                ));
            }
        };
        if flip {
            if ty == "sphere" && s.has("interior") && !s.has("exterior") {
                return Err(s.error(
                    "flip_normals",
                    "a sphere turned inside out cannot hold an interior medium (its inside would be all of space outside it)",
                ));
            }
            if ty != "mesh" {
                // The mesh reader reversed its triangles itself.
                shapes.iter_mut().for_each(Shape::flip);
            }
        }
        let material_name = s.string_required("material")?;
        let material = *materials
            .get(material_name)
            .ok_or_else(|| s.error("material", undefined("material", material_name, materials)))?;
        // With `exterior` the file names both sides (Mitsuba's media: interior behind the
        // normal, exterior in front, whatever the shape); with `interior` alone the shape
        // must close its medium in, and its outside is found from where it lies.
        let exterior = medium_ref(&s, "exterior", media)?;
        let interior = medium_ref(&s, "interior", media)?;
        if let (Some(inside), None) = (interior, exterior) {
            if inside.is_none() {
                return Err(s.error(
                    "interior",
                    "`vacuum` as the only medium of a shape says nothing; give `exterior` too",
                ));
            }
            if !closed {
                return Err(s.error(
                    "interior",
                    format!("a {ty} that is not closed cannot hold an interior medium by itself: light would leak out of the medium through its edges (a mesh needs every edge shared by exactly two consistently oriented triangles); close it, or give `exterior` too (the medium on the side its normal points to) if other shapes close the medium"),
                ));
            }
        }
        let explicit_media = exterior.is_some();
        let (interior, exterior) = (interior.flatten(), exterior.flatten());
        let object = objects.len() as u32;
        let mut light = None;
        if let Some(emission) = s.rgb_opt("emission")?
            && emission.max_element() > 0.0
        {
            if material_defs[material as usize].value.is_null() {
                return Err(s.error(
                    "emission",
                    "a shape with the null material is invisible and cannot emit; give it a real material (e.g. a black diffuse one)",
                ));
            }
            light = Some(lights.len() as u32);
            lights.push(area_light(shapes.clone(), emission, object));
        }
        objects.push(Object {
            name: s.path().to_string(),
            material,
            light,
            interior,
            exterior,
            explicit_media,
            closed,
        });
        let first_attrs = triangle_attrs.len() as u32;
        let with_attrs = !attrs.is_empty();
        triangle_attrs.extend(attrs);
        prims.extend(shapes.into_iter().enumerate().map(|(i, shape)| Primitive {
            shape,
            object,
            attrs: if with_attrs {
                first_attrs + i as u32
            } else {
                NO_ATTRS
            },
        }));
        ld.done(&s);
    }
    Ok(())
}

/// The lights of `[[lights]]`, each with the medium the file puts it in (`medium`, for point
/// and spot lights; None: found from where it lies).
fn read_point_lights(
    root: &Properties<'_>,
    ld: &mut Loader,
    media: &Index,
    lights: &mut Vec<Light>,
    light_media: &mut Vec<Option<Option<u32>>>,
) -> Result<()> {
    for l in array_of_tables(root, "lights")? {
        let ty = l.string_opt("type")?.ok_or_else(|| {
            l.error(
                "type",
                format!("missing; expected one of: {}", LIGHT_TYPES.join(", ")),
            )
        })?;
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
            if lights.iter().any(Light::is_environment) {
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
            lights.push(light);
            light_media.push(None);
            ld.done(&l);
            continue;
        }
        if ty == "directional" {
            lights.push(read_directional(&l)?);
            light_media.push(None);
            ld.done(&l);
            continue;
        }
        let position = l.vec3_required("position")?;
        light_media.push(medium_ref(&l, "medium", media)?);
        if ty == "spot" {
            lights.push(read_spot(&l, position)?);
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
        lights.push(Light::Point {
            position,
            intensity,
        });
        ld.done(&l);
    }
    Ok(())
}
