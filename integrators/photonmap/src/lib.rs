//! foton-photonmap: the photon machinery that the photon-mapping integrators (`photon`,
//! `sppm`, `vpm`, `ppb`) share, linked into each of them. An ordinary library crate, not a plugin.
//!
//! - [`trace`]: the photon pass: photons leave the lights and emitting media in proportion to
//!   power, walk the scene (surfaces and media, through core's `walk::RayWalk`, the one
//!   null-boundary crossing loop) by BSDF and phase-function sampling with Russian roulette,
//!   and are offered for storage at every non-delta surface and scattering event, classified
//!   by their path (L D, L S+ D, the rest); the caller sorts them into its maps;
//! - [`sources`]: where photons start: the lights, and media that emit (a point drawn over
//!   a lattice of the medium's region, a direction over the sphere);
//! - [`map`]: the compact photon (32 bytes) and the photon map (a balanced kd-tree) with its
//!   k-nearest (`knn`), fixed-radius (`within`) and beam (`along_ray`) queries, and the
//!   density estimates made from them: `radiance` (reflected radiance, the BSDF evaluated per
//!   photon with the photon's own incoming direction), `reflected` (the same for a material at
//!   a hit), `irradiance` and `in_scattered` (the volume estimate). Surface estimates gather
//!   from a disc, not a ball: photons farther from the tangent plane than
//!   [`map::DISC_THICKNESS`] (1/4) of the radius are not counted.
//! - [`beams`]: photon beams (each photon flight through a medium, short or long), their BVH
//!   and the beam x beam estimate with a 1-D kernel (Jarosz et al. 2011), for `vpm` and `ppb`;
//! - [`twolevel`]: the beams' BVH of boxes, a top tree of median splits over obvhs BVHs built
//!   in parallel (the same tree for any number of threads);
//! - [`screen`]: a pass's beams binned in screen space, the candidates of the camera's primary
//!   rays (`ppb`), in place of the BVH's;
//! - [`progressive`]: what `sppm` and `ppb` share: the pass loop (`run_passes`: iterations or
//!   a time budget, parts, Ctrl-C, checkpoints; each plugin gives only its per-pass estimator,
//!   a `Passes`) and its parameters (`PassBudget`), Knaus and Zwicker's radius schedule, the
//!   automatic first radius, the disc gather at a visible point;
//! - [`surface`]: Jensen's surface maps and what `photon` and `vpm` share: their passes, the
//!   estimate at a visible point, the parameters of the surface maps (`SurfaceParams`) and the
//!   one-pass render (`render_with_maps`).
//!
//! Nothing here crosses the plugin boundary: the host never sees a `PhotonMap`. What the
//! `foton photons` tool draws comes back through `Integrator::photon_maps` as core's plain
//! `integrator::PhotonMapView` ([`view`] makes one), so an integrator can expose maps without
//! linking this crate. It is not part of the build identifier either: each plugin that links
//! it carries its own copy (docs/crates.md).

pub mod beams;
pub mod map;
pub mod progressive;
pub mod screen;
pub mod sources;
pub mod surface;
pub mod trace;
pub mod twolevel;

pub use map::{Estimate, Neighbour, Photon, PhotonMap};

use foton_core::api::{MapPhoton, PhotonMapView};

/// A map as the tools see it (`Integrator::photon_maps`).
pub fn view(name: &str, description: &str, emitted: u64, photons: &[Photon]) -> PhotonMapView {
    PhotonMapView {
        name: name.into(),
        description: description.into(),
        emitted,
        photons: photons
            .iter()
            .map(|p| MapPhoton {
                position: p.position,
                power: p.power(),
                normal: p.normal(),
            })
            .collect(),
    }
}
