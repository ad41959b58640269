//! Mitsuba's plugins of each kind, so that a type foton does not read is reported as Mitsuba
//! would know it: "not supported" for one of Mitsuba's, "unknown" (with the close name) for a
//! typo.

/// The plugins of each kind in Mitsuba 3 and 0.6 (for "not supported" against "unknown").
const MITSUBA_PLUGINS: &[(&str, &[&str])] = &[
    (
        "bsdf",
        &[
            "diffuse",
            "dielectric",
            "thindielectric",
            "roughdielectric",
            "conductor",
            "roughconductor",
            "plastic",
            "roughplastic",
            "twosided",
            "null",
            "principled",
            "principledthin",
            "bumpmap",
            "normalmap",
            "blendbsdf",
            "mask",
            "hair",
            "measured",
            "pplastic",
            "polarizer",
            "retarder",
            "circular",
            "coating",
            "roughcoating",
            "phong",
            "ward",
            "mixturebsdf",
            "difftrans",
            "hk",
            "irawan",
            "roughdiffuse",
            "bump",
        ],
    ),
    (
        "shape",
        &[
            "obj",
            "ply",
            "serialized",
            "sphere",
            "rectangle",
            "cube",
            "disk",
            "cylinder",
            "bsplinecurve",
            "linearcurve",
            "sdfgrid",
            "shapegroup",
            "instance",
            "ellipsoids",
            "ellipsoidsmesh",
            "merge",
            "hair",
            "heightfield",
        ],
    ),
    (
        "emitter",
        &[
            "area",
            "point",
            "spot",
            "directional",
            "constant",
            "envmap",
            "projector",
            "directionalarea",
            "sunsky",
            "sky",
            "sun",
            "collimated",
        ],
    ),
    (
        "texture",
        &[
            "bitmap",
            "checkerboard",
            "mesh_attribute",
            "volume",
            "gridtexture",
            "scale",
            "vertexcolors",
            "wireframe",
            "curvature",
        ],
    ),
    (
        "sensor",
        &[
            "perspective",
            "thinlens",
            "orthographic",
            "radiancemeter",
            "irradiancemeter",
            "distant",
            "batch",
            "telecentric",
            "spherical",
            "fluencemeter",
            "perspective_rdist",
        ],
    ),
    ("medium", &["homogeneous", "heterogeneous"]),
    (
        "phase",
        &[
            "isotropic",
            "hg",
            "rayleigh",
            "sggx",
            "tabphase",
            "blendphase",
            "kkay",
            "microflake",
            "mixturephase",
        ],
    ),
    (
        "film",
        &["hdrfilm", "ldrfilm", "specfilm", "tiledhdrfilm", "mfilm"],
    ),
    (
        "rfilter",
        &[
            "box",
            "tent",
            "gaussian",
            "mitchell",
            "catmullrom",
            "lanczos",
        ],
    ),
];

/// The message for a plugin type foton does not read: `supported` (with `not supported`
/// wording) when Mitsuba has it, "unknown" with the close name otherwise.
/// The plugin of Mitsuba's `kind` that `ty` names in another case (`Rectangle`), if `ty` is
/// none of them as written.
pub(super) fn in_another_case(kind: &str, ty: &str) -> Option<&'static str> {
    let names = MITSUBA_PLUGINS
        .iter()
        .filter(|(k, _)| *k == kind)
        .flat_map(|(_, names)| names.iter().copied());
    if names.clone().any(|n| n == ty) {
        return None;
    }
    names.into_iter().find(|n| n.eq_ignore_ascii_case(ty))
}

pub(super) fn not_read(kind: &str, ty: &str, supported: &str) -> String {
    let known = MITSUBA_PLUGINS
        .iter()
        .find(|(k, _)| *k == kind)
        .map_or(&[][..], |(_, names)| names);
    if known.contains(&ty) {
        supported.to_string()
    } else {
        format!(
            "unknown {kind} type `{ty}`{}",
            foton_core::error::suggestion(ty, known.iter().copied())
        )
    }
}

/// The parameters Mitsuba 0.6 reads, by element and plugin type (`""`: every plugin of that
/// element, its base class's), in the snake case a 0.x file is upgraded to. Mitsuba 0.6 warns
/// about any other parameter of a file and renders on ("Unqueried attribute"), where Mitsuba 2
/// and 3 refuse the file; a 0.x file is read as 0.6 reads it, so a parameter not listed here
/// and not read by foton is a warning, and one listed here that foton does not read is not
/// supported (0.6 would honour it).
const MITSUBA06_PARAMETERS: &[(&str, &str, &[&str])] = &[
    ("bsdf", "", &["ensure_energy_conservation"]),
    ("bsdf", "blendbsdf", &["weight"]),
    ("bsdf", "bumpmap", &["gamma"]),
    ("bsdf", "normalmap", &["gamma"]),
    (
        "bsdf",
        "coating",
        &[
            "int_ior",
            "ext_ior",
            "sigma_a",
            "specular_reflectance",
            "thickness",
        ],
    ),
    (
        "bsdf",
        "roughcoating",
        &[
            "int_ior",
            "ext_ior",
            "sigma_a",
            "specular_reflectance",
            "thickness",
            "alpha",
            "distribution",
        ],
    ),
    (
        "bsdf",
        "conductor",
        &["eta", "k", "ext_eta", "material", "specular_reflectance"],
    ),
    (
        "bsdf",
        "roughconductor",
        &[
            "eta",
            "k",
            "ext_eta",
            "material",
            "specular_reflectance",
            "alpha",
            "alpha_u",
            "alpha_v",
            "distribution",
            "sample_visible",
        ],
    ),
    (
        "bsdf",
        "dielectric",
        &[
            "int_ior",
            "ext_ior",
            "specular_reflectance",
            "specular_transmittance",
        ],
    ),
    (
        "bsdf",
        "thindielectric",
        &[
            "int_ior",
            "ext_ior",
            "specular_reflectance",
            "specular_transmittance",
        ],
    ),
    (
        "bsdf",
        "roughdielectric",
        &[
            "int_ior",
            "ext_ior",
            "specular_reflectance",
            "specular_transmittance",
            "alpha",
            "alpha_u",
            "alpha_v",
            "distribution",
            "sample_visible",
        ],
    ),
    (
        "bsdf",
        "difftrans",
        &["transmittance", "diffuse_transmittance"],
    ),
    ("bsdf", "diffuse", &["reflectance"]),
    ("bsdf", "mask", &["opacity"]),
    ("bsdf", "mixturebsdf", &["weights"]),
    (
        "bsdf",
        "phong",
        &["diffuse_reflectance", "exponent", "specular_reflectance"],
    ),
    (
        "bsdf",
        "plastic",
        &[
            "int_ior",
            "ext_ior",
            "diffuse_reflectance",
            "nonlinear",
            "specular_reflectance",
        ],
    ),
    (
        "bsdf",
        "roughplastic",
        &[
            "int_ior",
            "ext_ior",
            "diffuse_reflectance",
            "nonlinear",
            "specular_reflectance",
            "alpha",
            "distribution",
            "sample_visible",
        ],
    ),
    (
        "bsdf",
        "roughdiffuse",
        &["alpha", "reflectance", "use_fast_approx"],
    ),
    (
        "bsdf",
        "ward",
        &[
            "alpha",
            "alpha_u",
            "alpha_v",
            "diffuse_reflectance",
            "specular_reflectance",
            "variant",
        ],
    ),
    ("emitter", "", &["sampling_weight", "to_world", "medium"]),
    ("emitter", "area", &["radiance"]),
    ("emitter", "collimated", &["power"]),
    ("emitter", "constant", &["radiance"]),
    ("emitter", "directional", &["direction", "irradiance"]),
    (
        "emitter",
        "envmap",
        &["filename", "gamma", "scale", "cache"],
    ),
    ("emitter", "point", &["intensity", "position"]),
    (
        "emitter",
        "spot",
        &["beam_width", "cutoff_angle", "intensity", "texture"],
    ),
    (
        "emitter",
        "sky",
        &[
            "albedo",
            "extend",
            "resolution",
            "scale",
            "stretch",
            "turbidity",
        ],
    ),
    (
        "emitter",
        "sun",
        &[
            "resolution",
            "scale",
            "stretch",
            "sun_radius_scale",
            "turbidity",
        ],
    ),
    (
        "emitter",
        "sunsky",
        &[
            "albedo",
            "resolution",
            "scale",
            "sky_scale",
            "stretch",
            "sun_direction",
            "sun_radius_scale",
            "sun_scale",
            "turbidity",
        ],
    ),
    (
        "film",
        "",
        &[
            "width",
            "height",
            "crop_offset_x",
            "crop_offset_y",
            "crop_width",
            "crop_height",
            "high_quality_edges",
        ],
    ),
    (
        "film",
        "hdrfilm",
        &[
            "attach_log",
            "banner",
            "channel_names",
            "component_format",
            "file_format",
            "pixel_format",
        ],
    ),
    (
        "film",
        "ldrfilm",
        &[
            "banner",
            "burn",
            "exposure",
            "file_format",
            "gamma",
            "key",
            "pixel_format",
            "tonemap_method",
        ],
    ),
    (
        "integrator",
        "",
        &["max_depth", "rr_depth", "strict_normals", "hide_emitters"],
    ),
    (
        "integrator",
        "bdpt",
        &["light_image", "sample_direct", "show_weighted"],
    ),
    (
        "integrator",
        "direct",
        &["bsdf_samples", "emitter_samples", "shading_samples"],
    ),
    (
        "integrator",
        "photonmapper",
        &[
            "auto_cancel_gathering",
            "caustic_lookup_radius",
            "caustic_lookup_size",
            "caustic_photons",
            "direct_samples",
            "gather_locally",
            "global_lookup_radius",
            "global_lookup_size",
            "global_photons",
            "glossy_samples",
            "granularity",
            "lookup_size",
            "max_specular_depth",
            "volume_lookup_size",
            "volume_photons",
        ],
    ),
    (
        "integrator",
        "ppm",
        &[
            "alpha",
            "auto_cancel_gathering",
            "granularity",
            "initial_radius",
            "max_passes",
            "photon_count",
        ],
    ),
    (
        "integrator",
        "sppm",
        &[
            "alpha",
            "auto_cancel_gathering",
            "granularity",
            "initial_radius",
            "max_passes",
            "photon_count",
        ],
    ),
    ("integrator", "ptracer", &["brute_force", "granularity"]),
    (
        "medium",
        "",
        &[
            "sigma_a",
            "sigma_s",
            "sigma_t",
            "albedo",
            "material",
            "scale",
            "density_multiplier",
        ],
    ),
    (
        "medium",
        "homogeneous",
        &[
            "channel",
            "medium_sampling_weight",
            "monochromatic",
            "sampling_density",
            "strategy",
        ],
    ),
    ("medium", "heterogeneous", &["method", "step_size"]),
    ("phase", "hg", &["g"]),
    ("rfilter", "box", &["radius"]),
    ("rfilter", "gaussian", &["stddev"]),
    ("rfilter", "lanczos", &["lobes"]),
    ("rfilter", "mitchell", &["B", "C"]),
    ("sampler", "", &["sample_count"]),
    ("sampler", "halton", &["scramble"]),
    ("sampler", "hammersley", &["scramble"]),
    ("sampler", "sobol", &["scramble"]),
    ("sampler", "ldsampler", &["dimension"]),
    ("sampler", "stratified", &["dimension"]),
    (
        "sensor",
        "",
        &[
            "to_world",
            "shutter_open",
            "shutter_open_time",
            "near_clip",
            "far_clip",
            "focus_distance",
            "fov",
            "fov_axis",
            "focal_length",
        ],
    ),
    ("sensor", "thinlens", &["aperture_radius"]),
    ("sensor", "telecentric", &["aperture_radius"]),
    ("shape", "", &["to_world", "flip_normals"]),
    ("shape", "cylinder", &["p0", "p1", "radius"]),
    ("shape", "sphere", &["center", "radius"]),
    (
        "shape",
        "obj",
        &[
            "collapse",
            "face_normals",
            "filename",
            "flip_tex_coords",
            "load_materials",
            "max_smooth_angle",
            "shape_index",
        ],
    ),
    (
        "shape",
        "ply",
        &["filename", "max_smooth_angle", "srgb", "face_normals"],
    ),
    (
        "shape",
        "serialized",
        &[
            "face_normals",
            "filename",
            "max_smooth_angle",
            "shape_index",
        ],
    ),
    ("texture", "", &["to_uv"]),
    (
        "texture",
        "bitmap",
        &[
            "cache",
            "channel",
            "filename",
            "filter_type",
            "gamma",
            "max_anisotropy",
            "wrap_mode",
            "wrap_mode_u",
            "wrap_mode_v",
        ],
    ),
    ("texture", "checkerboard", &["color0", "color1"]),
    (
        "texture",
        "gridtexture",
        &["color0", "color1", "line_width"],
    ),
    ("texture", "scale", &["scale", "value"]),
];

/// Whether Mitsuba 0.6 reads parameter `name` (snake case) of a `<kind type="ty">`: a
/// parameter of a 0.x file that foton leaves unread is a warning when 0.6 does not read it
/// either (see [`MITSUBA06_PARAMETERS`]).
pub(super) fn mitsuba06_reads(kind: &str, ty: &str, name: &str) -> bool {
    MITSUBA06_PARAMETERS
        .iter()
        .any(|(k, t, names)| *k == kind && (t.is_empty() || *t == ty) && names.contains(&name))
}
