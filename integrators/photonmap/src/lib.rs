//! foton-photonmap: the photon machinery that the photon-mapping integrators (`photon`,
//! `sppm`, `vpm`) share, linked into each of them.
//!
//! - [`trace`]: the photon pass: photons leave the lights in proportion to power, walk the
//!   scene (surfaces and media) by BSDF and phase-function sampling with Russian roulette, and
//!   are offered for storage at every non-delta surface and scattering event, classified by
//!   their path (L D, L S+ D, the rest);
//! - [`map`]: the compact photon and the photon map (a kd-tree) with its k-nearest and
//!   fixed-radius queries and the density estimates made from them.
//!
//! Nothing here crosses the plugin boundary: the host never sees a `PhotonMap`. What the
//! `foton photons` tool draws comes back through `Integrator::photon_maps` as core's plain
//! `integrator::PhotonMapView`.

pub mod map;
pub mod surface;
pub mod trace;

pub use map::{Estimate, Neighbour, Photon, PhotonMap};

use foton_core::integrator::{MapPhoton, PhotonMapView};

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
