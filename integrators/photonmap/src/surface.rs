//! Jensen's surface photon maps, shared by `photon` and `vpm`: the passes that fill them, and
//! the radiance estimate at a camera path's visible point.
//!
//! Two budgets, each with its own random stream. The **global** pass stores every surface
//! photon by its path: L D (first hit) in the direct map, kept only when something reads it
//! (direct light from photons, a final gather), every path with a diffuse bounce before the
//! last in the indirect map, and L S+ D when there is no caustic budget (otherwise the caustic
//! budget counts those paths and the global pass drops them) in the indirect map too, or,
//! when a final gather replaces the indirect map's estimate at the visible point, in the
//! caustic map, which is read there (`caustics_apart`).
//! The **caustic** pass stores the L S+ D photons, traced to their first diffuse hit only.
//! Each light path is thus counted once (docs/photon-mapping.md).

use crate::map::{Estimate, Photon, PhotonMap};
use crate::trace::{PathClass, STREAM_CAUSTIC, STREAM_GLOBAL, Site, TraceOptions, trace_photons};
use foton_core::bsdf::Bsdf;
use foton_core::direct::{Direct, Mis, Scatter, estimate_direct};
use foton_core::error::Result;
use foton_core::geometry::Hit;
use foton_core::integrator::RenderContext;
use foton_core::props::Properties;
use foton_core::sampling::Sampler;
use foton_core::scene::Scene;
use foton_core::walk::VisiblePoint;
use foton_core::{Rgb, Vec3};

/// The photon budgets of the surface maps.
#[derive(Clone, Copy, Debug)]
pub struct Budgets {
    /// Photons emitted for the direct and indirect maps.
    pub global: u64,
    /// Photons emitted for the caustic map (0: no caustic map).
    pub caustic: u64,
    /// Scattering events a photon path may have.
    pub max_depth: u32,
}

/// The stored photons of the two passes: [direct, caustic, indirect] (the direct list empty
/// unless `keep_direct`). Without a caustic budget, the global pass's L S+ D photons go to
/// the caustic list if `caustics_apart` (a final gather reads the caustic map at the visible
/// point and not the indirect one), else to the indirect list (one denser map: its estimate
/// has a smaller radius than a sparse caustic map's).
pub fn trace_surface_photons(
    scene: &Scene,
    ctx: &RenderContext<'_>,
    budgets: &Budgets,
    keep_direct: bool,
    caustics_apart: bool,
) -> Result<[Vec<Photon>; 3]> {
    let pass = |photons, stream, stop_at_diffuse| TraceOptions {
        photons,
        max_depth: budgets.max_depth,
        seed: scene.render.seed,
        stream,
        stop_at_diffuse,
        sobol_emission: TraceOptions::emission_for(scene.render.sampler),
    };
    let caustic_map = budgets.caustic > 0;
    let global = pass(budgets.global, STREAM_GLOBAL, false);
    let mut lists = trace_photons(scene, &global, ctx, 3, |site, class| {
        if site != Site::Surface {
            return None;
        }
        match class {
            PathClass::Direct => keep_direct.then_some(0),
            PathClass::Caustic if caustic_map => None,
            PathClass::Caustic if caustics_apart => Some(1),
            PathClass::Caustic | PathClass::Indirect => Some(2),
        }
    })?;
    let indirect = lists.pop().unwrap();
    let global_caustic = lists.pop().unwrap();
    let direct = lists.pop().unwrap();
    let caustic = if caustic_map {
        let opts = pass(budgets.caustic, STREAM_CAUSTIC, true);
        trace_photons(scene, &opts, ctx, 1, |site, class| {
            (site == Site::Surface && class == PathClass::Caustic).then_some(0)
        })?
        .pop()
        .unwrap()
    } else {
        global_caustic
    };
    Ok([direct, caustic, indirect])
}

/// An error if an estimate's `k` (parameter `key`) exceeds a photon budget it is drawn from:
/// no estimate could ever find k photons, a mistake in the parameters. A map that merely
/// stores fewer than k (a sparse caustic map) is no error: see [`SurfaceMaps::build`].
/// `budgets`: each map's name, its budget's parameter and the photons emitted for it (0: no
/// such map).
pub fn check_k(
    props: &Properties<'_>,
    key: &str,
    k: usize,
    budgets: &[(&str, &str, u64)],
) -> Result<()> {
    for &(map, budget_key, emitted) in budgets {
        if emitted > 0 && k as u64 > emitted {
            return Err(props.error(
                key,
                format!(
                    "k = {k} is larger than the {emitted} photons emitted for the {map} map ({budget_key}): no estimate could find k; lower it or emit more photons"
                ),
            ));
        }
    }
    Ok(())
}

/// The surface maps. `direct` exists when something reads it.
pub struct SurfaceMaps {
    pub direct: Option<PhotonMap>,
    pub caustic: PhotonMap,
    pub indirect: PhotonMap,
}

impl SurfaceMaps {
    /// Builds the maps from the passes' lists (see [`trace_surface_photons`]). A map may hold
    /// fewer photons than an estimate's k (a scene with a few caustic paths, off a plastic's
    /// coat): every query then finds fewer than k and takes `max_radius`, as in any sparse
    /// region, so that is no error.
    pub fn build([direct, caustic, indirect]: [Vec<Photon>; 3], keep_direct: bool) -> SurfaceMaps {
        SurfaceMaps {
            direct: keep_direct.then(|| PhotonMap::build(direct)),
            caustic: PhotonMap::build(caustic),
            indirect: PhotonMap::build(indirect),
        }
    }

    /// Radiance reflected towards the camera at a visible point by light of at most `depth`
    /// scattering events after it: direct (shadow rays, or the direct map), caustic, and
    /// indirect unless `indirect` is false (a final gather computes it instead). Not weighted
    /// by the path's throughput; emission is the camera walk's.
    #[allow(clippy::too_many_arguments)]
    pub fn reflected_at(
        &self,
        scene: &Scene,
        vp: &VisiblePoint,
        estimate: &Estimate<'_>,
        direct: Direct,
        depth: u32,
        indirect: bool,
        sampler: &mut Sampler,
        rays: &mut u64,
    ) -> Rgb {
        let (hit, bsdf, wo, n) = (&vp.hit, &vp.bsdf, vp.wo, vp.n);
        let mut l = match (direct, &self.direct) {
            (Direct::Photons, Some(map)) => map.reflected(estimate, bsdf, hit, wo, n, depth),
            _ => {
                let at = Scatter::Surface { hit, bsdf };
                estimate_direct(scene, at, wo, vp.medium, Mis::LightOnly, sampler, rays)
            }
        };
        l += self.caustic.reflected(estimate, bsdf, hit, wo, n, depth);
        if indirect {
            l += self.indirect.reflected(estimate, bsdf, hit, wo, n, depth);
        }
        l
    }

    /// Radiance reflected towards `wo` at `hit` by the photons of every map (direct, caustic
    /// and indirect), as seen at the end of a gather ray.
    pub fn reflected_by_all(
        &self,
        estimate: &Estimate<'_>,
        bsdf: &Bsdf,
        hit: &Hit,
        wo: Vec3,
        depth: u32,
    ) -> Rgb {
        let n = if hit.ng.dot(wo) > 0.0 {
            hit.ng
        } else {
            -hit.ng
        };
        let mut l = self.caustic.reflected(estimate, bsdf, hit, wo, n, depth)
            + self.indirect.reflected(estimate, bsdf, hit, wo, n, depth);
        if let Some(direct) = &self.direct {
            l += direct.reflected(estimate, bsdf, hit, wo, n, depth);
        }
        l
    }
}
