//! foton-core: what an integrator plugin links, and what the host hands it.
//!
//! One module per concept, named as in the literature: [`scene`] (the scene and its queries,
//! volumes, visibility), [`geometry`] and [`accel`] (the BVH), [`material`] and [`bsdf`] (over
//! [`scattering`], the Fresnel terms and transport mode they share), [`light`], [`camera`],
//! [`film`], [`sampling`], [`medium`], [`kernel`] (density-estimation kernels), [`integrator`]
//! (the plugin interface), [`render`] (the shared parallel image loop) and [`plugin`]
//! (declaring and loading plugins). Nothing host-only lives here: the `foton` program and its
//! tools are the crate in `cli/`, the scene files (TOML, Mitsuba XML, meshes, images) are read
//! by the crate in `loader/`, the photon machinery of the photon-mapping plugins is
//! `integrators/photonmap`.

pub mod accel;
pub mod api;
pub mod bsdf;
pub mod camera;
pub mod direct;
pub mod envmap;
pub mod error;
pub mod film;
pub mod filter;
pub mod geometry;
pub mod glossy;
pub mod integrator;
pub mod kernel;
pub mod light;
pub mod material;
pub mod medium;
pub mod microfacet;
pub mod param;
pub mod part;
pub mod plugin;
pub mod props;
pub mod registry;
pub mod render;
pub mod sampling;
pub mod scattering;
pub mod scene;
pub mod sky;
pub mod spectrum;
pub mod texture;
pub mod value;
pub mod walk;

pub use error::{Error, Result};
pub use glam::{Vec2, Vec3};

/// Linear RGB radiometric quantity (radiance, flux, reflectance...).
pub type Rgb = glam::Vec3;

/// Average of the three channels: the scalar used for power-proportional choices and
/// Russian roulette, so that no channel is favoured.
#[inline]
pub fn average(c: Rgb) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// Version of this crate, compared with the one a plugin was built against.
pub const CORE_VERSION: &str = env!("CARGO_PKG_VERSION");
/// rustc that compiled this crate (from build.rs).
pub const RUSTC_VERSION: &str = env!("FOTON_RUSTC_VERSION");
/// Hash of what defines the plugin ABI: core's sources, the versions of its dependencies,
/// rustc, the target and the settings that change layouts (build.rs, build_id.rs).
pub const BUILD_ID: &str = env!("FOTON_BUILD_ID");
/// The settings hashed into [`BUILD_ID`] (`;`-separated), for the tests that recompute it.
pub const BUILD_SETTINGS: &str = env!("FOTON_BUILD_SETTINGS");

/// The plugin and extension guides of docs/, compiled here as doc-tests so that their examples
/// cannot drift from the API they describe.
#[doc(hidden)]
pub mod guides {
    #[doc = include_str!("../../docs/plugins.md")]
    pub mod plugins {}
    #[doc = include_str!("../../docs/extending.md")]
    pub mod extending {}
}
