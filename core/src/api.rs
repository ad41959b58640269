//! The plugin API: everything an integrator or kernel plugin may use of foton-core, and the
//! only module through which the crates under `integrators/` reach it (a test holds them to
//! it). What is not re-exported here is not promised: the rest of foton-core is the host's,
//! free to change between versions.
//!
//! [`PLUGIN_API_VERSION`] is computed when foton-core is built, over what this module exposes
//! (core/api_surface.rs): the signatures of the items below, their public fields and methods,
//! the traits they implement, and the declaration macros' text. A change that could break a
//! plugin built against this module changes it; a change anywhere else (a function's body, a
//! comment, an item not exposed here) does not.
//!
//! The items, by concept:
//! - the plugin itself: [`Integrator`], [`declare_integrator!`], its parameters
//!   ([`Properties`]) and what it reports ([`Parameter`], [`Budget`], [`PhotonMapView`]);
//! - the render: [`RenderContext`], [`Film`] (with its technique [`Layer`]s), the shared
//!   image loops ([`render_pixels`], [`render_pixels_splatting`], [`render_pixels_techniques`]
//!   with its [`Techniques`]) and thread pool ([`with_pool`]);
//! - the scene and its queries: [`Scene`], [`Ray`], [`Hit`], [`Bsdf`], [`Light`], [`Medium`],
//!   the walks that cross null boundaries and media ([`RayWalk`], [`CameraWalk`]) and
//!   next-event estimation ([`estimate_direct`]);
//! - sampling: [`Sampler`], [`Rng`], warps and MIS heuristics;
//! - density estimation: [`Kernel`], [`NormalizedKernel`] and the built-in kernels.

// The plugin and its declaration.
pub use crate::declare_integrator;
pub use crate::error::{Error, Result};
#[doc(hidden)]
pub use crate::integrator::CreateIntegrator;
pub use crate::integrator::{
    Budget, Integrator, MapPhoton, NoProgress, ParamValue, Parameter, Part, PhaseTimer,
    PhotonMapView, Progress, RenderContext, Work, describe,
};
pub use crate::plugin::PLUGIN_API_VERSION;
#[doc(hidden)]
pub use crate::plugin::{
    BUILD_ID_C, CORE_VERSION_C, IntegratorDeclaration, KERNEL_API_VERSION, KernelDeclaration,
    LAYOUT_FINGERPRINT, RUSTC_VERSION_C, guarded_create,
};
pub use crate::props::Properties;

// Values and colours.
pub use crate::{Rgb, average};
pub use glam::{DVec3, Vec2, Vec3};

// The scene and its queries.
pub use crate::accel::{Accel, BoxBvh, median_parts, median_split};
pub use crate::bsdf::Bsdf;
pub use crate::camera::{Camera, Meter};
pub use crate::geometry::{Hit, NO_ATTRS, Primitive, Ray, Shape, offset_origin};
pub use crate::light::{Light, LightType};
pub use crate::material::{Lobe, TransportMode};
pub use crate::medium::{HeroChannel, Medium, Phase, channel, transmittance_homogeneous};
pub use crate::scene::Scene;

// Walks through the scene and next-event estimation.
pub use crate::direct::{Direct, Mis, Scatter, estimate_direct};
pub use crate::walk::{
    CameraWalk, RayWalk, Reached, Segment, VisiblePoint, first_surface, trace_to_diffuse,
    walk_to_diffuse,
};

// Sampling.
pub use crate::sampling::{
    Distribution1D, Rng, SOBOL_DIMENSIONS, Sampler, SamplerKind, SobolPoint, cosine_hemisphere,
    power_heuristic, russian_roulette, splitmix64, to_world, uniform_hemisphere, uniform_sphere,
};

// The image.
pub use crate::film::{Film, Layer, RadianceSum};
pub use crate::render::{
    PixelSample, Splats, Techniques, render_pixels, render_pixels_splatting,
    render_pixels_techniques, usable, warn_unusable, with_pool,
};

// Density estimation.
pub use crate::kernel::{BoxKernel, ConeKernel, GaussianKernel, Kernel, NormalizedKernel};
