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
