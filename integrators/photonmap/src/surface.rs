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
//! Each light path is thus counted once (docs/photon-mapping.md). The global pass may also
//! keep what its first photons do in media ([`VolumeShare`], `vpm`'s volume map): a volume
//! pass that traces no photon of its own.

use crate::beams::{Beam, BeamKind};
use crate::map::{CLIP_PROBES, Disc, DiscClip, Estimate, Photon, PhotonMap};
use crate::trace::{
    PathClass, STREAM_CAUSTIC, STREAM_GLOBAL, Site, TraceOptions, trace_photons,
    trace_photons_and_beams_indexed,
};
use foton_core::api::{
    Bsdf, Direct, Film, Hit, Mis, NormalizedKernel, Parameter, PhotonMapView, Properties, Ray,
    RenderContext, Result, Rgb, Sampler, Scatter, Scene, Techniques, Vec3, VisiblePoint,
    estimate_direct, render_pixels, render_pixels_techniques,
};

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
    Ok(trace_surface_and_volume_photons(scene, ctx, budgets, keep_direct, caustics_apart, None)?.0)
}

/// What the photon passes store: the surface lists [direct, caustic, indirect], the volume
/// photons and the photon beams.
pub type PassLists = ([Vec<Photon>; 3], Vec<Photon>, Vec<Beam>);

/// What the global pass also keeps in media: the volume photons (scattering events) and the
/// beams (flights) of its first `photons` photons (at most the global budget), their flux
/// scaled by global / `photons` so that they stand for a volume pass of that many photons.
#[derive(Clone, Copy, Debug)]
pub struct VolumeShare {
    pub photons: u64,
    /// Whether the scattering events are kept (the volume map's points).
    pub points: bool,
    /// The beams' kind (None: none).
    pub beams: Option<BeamKind>,
    /// Whether L M (first scattering events, a light's first flight) is kept.
    pub keep_direct: bool,
}

/// [`trace_surface_photons`] and, with `volume`, the volume photons and beams the global
/// pass's first photons leave in media.
pub fn trace_surface_and_volume_photons(
    scene: &Scene,
    ctx: &RenderContext<'_>,
    budgets: &Budgets,
    keep_direct: bool,
    caustics_apart: bool,
    volume: Option<VolumeShare>,
) -> Result<PassLists> {
    let pass = |photons, stream, stop_at_diffuse| TraceOptions {
        photons,
        max_depth: budgets.max_depth,
        seed: scene.render().seed,
        stream,
        stop_at_diffuse,
        sobol_emission: TraceOptions::emission_for(scene.render().sampler),
    };
    let caustic_map = budgets.caustic > 0;
    let global = pass(budgets.global, STREAM_GLOBAL, false);
    let share = volume.map(|v| VolumeShare {
        photons: v.photons.min(budgets.global),
        ..v
    });
    let in_share = |class: PathClass, i: u64| {
        share.is_some_and(|v| i < v.photons && (class != PathClass::Direct || v.keep_direct))
    };
    let (mut lists, mut beams) = trace_photons_and_beams_indexed(
        scene,
        &global,
        ctx,
        4,
        |site, class, i| {
            if site == Site::Volume {
                return (share.is_some_and(|v| v.points) && in_share(class, i)).then_some(3);
            }
            match class {
                PathClass::Direct => keep_direct.then_some(0),
                PathClass::Caustic if caustic_map => None,
                PathClass::Caustic if caustics_apart => Some(1),
                PathClass::Caustic | PathClass::Indirect => Some(2),
            }
        },
        share.and_then(|v| v.beams),
        in_share,
    )?;
    let mut volume_photons = lists.pop().unwrap();
    if let Some(v) = share
        && v.photons > 0
        && v.photons < budgets.global
    {
        let scale = budgets.global as f32 / v.photons as f32;
        for p in &mut volume_photons {
            p.power = p.power.map(|c| c * scale);
        }
        for b in &mut beams {
            b.flux *= scale;
        }
    }
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
    Ok(([direct, caustic, indirect], volume_photons, beams))
}

/// The parameters of the surface maps and their estimate, which `photon` and `vpm` read
/// alike (their tables list them): `global_photons`, `caustic_photons`, `k`, `max_radius`;
/// each plugin has its own defaults ([`SurfaceDefaults`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceParams {
    pub global_photons: u64,
    pub caustic_photons: u64,
    /// Photons per estimate (the k-th sets the radius).
    pub k: usize,
    /// The largest estimate radius.
    pub max_radius: f32,
}

/// What a plugin's `global_photons`, `caustic_photons` and `k` default to (`max_radius`
/// defaults to 1/20 of the scene's bounding-box diagonal for both).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceDefaults {
    pub global_photons: u64,
    pub caustic_photons: u64,
    pub k: u32,
}

impl SurfaceDefaults {
    /// `photon`'s: 200 000 global and 100 000 caustic photons, k = 50.
    pub const PHOTON: SurfaceDefaults = SurfaceDefaults {
        global_photons: 200_000,
        caustic_photons: 100_000,
        k: 50,
    };
}

impl SurfaceParams {
    /// Reads and checks them with `photon`'s defaults ([`SurfaceDefaults::PHOTON`]).
    pub fn read(props: &Properties<'_>, scene: &Scene) -> Result<SurfaceParams> {
        SurfaceParams::read_with(props, scene, SurfaceDefaults::PHOTON)
    }

    /// Reads and checks them with the plugin's own defaults.
    pub fn read_with(
        props: &Properties<'_>,
        scene: &Scene,
        defaults: SurfaceDefaults,
    ) -> Result<SurfaceParams> {
        let global_photons = props.u64("global_photons", defaults.global_photons)?;
        if global_photons == 0 {
            return Err(props.error("global_photons", "must be at least 1"));
        }
        let caustic_photons = props.u64("caustic_photons", defaults.caustic_photons)?;
        let k = read_k(props, "k", defaults.k)?;
        check_k(
            props,
            "k",
            k,
            &[
                ("global", "global_photons", global_photons),
                ("caustic", "caustic_photons", caustic_photons),
            ],
        )?;
        let max_radius = read_positive(props, "max_radius", diagonal(scene) / 20.0)?;
        Ok(SurfaceParams {
            global_photons,
            caustic_photons,
            k,
            max_radius,
        })
    }

    pub fn budgets(&self, max_depth: u32) -> Budgets {
        Budgets {
            global: self.global_photons,
            caustic: self.caustic_photons,
            max_depth,
        }
    }

    pub fn estimate<'a>(&self, kernel: &'a NormalizedKernel) -> Estimate<'a> {
        Estimate {
            k: self.k,
            max_radius: self.max_radius,
            kernel,
        }
    }

    /// The parameters as `Integrator::parameters` lists them.
    pub fn parameters(&self) -> Vec<Parameter> {
        vec![
            Parameter::int("global_photons", self.global_photons),
            Parameter::int("caustic_photons", self.caustic_photons),
            Parameter::int("k", self.k),
            Parameter::float("max_radius", self.max_radius),
        ]
    }

    /// The photon budgets `foton compare --time` scales with the time (`Budget::scaled`).
    pub fn scaled(&self, plugin: &str) -> Vec<(String, u64)> {
        vec![
            (
                format!("integrators.{plugin}.global_photons"),
                self.global_photons,
            ),
            (
                format!("integrators.{plugin}.caustic_photons"),
                self.caustic_photons,
            ),
        ]
    }
}

/// The scene's bounding-box diagonal, the unit of the default radii and steps (1 for an
/// empty scene).
pub fn diagonal(scene: &Scene) -> f32 {
    let d = (scene.bounds().1 - scene.bounds().0).length();
    if d > 0.0 { d } else { 1.0 }
}

/// Reads an estimate's photon count `key`: at least 2, since the k-th nearest photon lies on
/// the boundary of the estimate's disc and is not summed (docs/photon-mapping.md): k = 1
/// would leave nothing to sum.
pub fn read_k(props: &Properties<'_>, key: &str, default: u32) -> Result<usize> {
    let k = props.u32(key, default)? as usize;
    if k < 2 {
        return Err(props.error(
            key,
            format!("must be at least 2, found {k} (the k-th nearest photon only sets the radius: the estimate sums the k - 1 inside it)"),
        ));
    }
    Ok(k)
}

/// Reads a length or step `key` that must be positive and finite.
pub fn read_positive(props: &Properties<'_>, key: &str, default: f32) -> Result<f32> {
    let x = props.f32(key, default)?;
    if !(x > 0.0 && x.is_finite()) {
        return Err(props.error(key, format!("must be positive, found {x}")));
    }
    Ok(x)
}

/// The surface maps as `foton photons` draws them, from the lists of
/// [`trace_surface_photons`] (with the direct list kept): `global`, the direct and indirect
/// photons of the global budget (Jensen's global map; a render keeps the direct ones only
/// when something reads them), and `caustic`, the L S+ D photons of the caustic budget.
pub fn surface_views(
    params: &SurfaceParams,
    [mut global, caustic, indirect]: [Vec<Photon>; 3],
) -> [PhotonMapView; 2] {
    global.extend(indirect);
    [
        crate::view(
            "global",
            if params.caustic_photons > 0 {
                "L D and paths with a diffuse bounce, of the global budget"
            } else {
                "every surface path of the global budget (no caustic map)"
            },
            params.global_photons,
            &global,
        ),
        crate::view(
            "caustic",
            "L S+ D photons of the caustic budget",
            params.caustic_photons,
            &caustic,
        ),
    ]
}

/// The render of the one-pass photon mappers (`photon`, `vpm`): build the maps (`build`: the
/// photon passes), then every pixel's samples through the shared pixel loop (`li`: the
/// radiance along a camera ray), and check the kernel's weights. Cancelled during the photon
/// passes, the image is black.
pub fn render_with_maps<M: Sync>(
    scene: &Scene,
    ctx: &RenderContext<'_>,
    kernel: &NormalizedKernel,
    build: impl FnOnce() -> Result<M>,
    li: impl Fn(&M, Ray, &mut Sampler, &mut u64) -> Rgb + Sync,
) -> Result<Film> {
    let maps = build()?;
    if ctx.cancelled() {
        return Ok(Film::new(scene.film().width, scene.film().height));
    }
    let film = render_pixels(scene, ctx, |ray, sampler, rays| {
        li(&maps, *ray, sampler, rays)
    })?;
    kernel.check_weights()?;
    Ok(film)
}

/// [`render_with_maps`] that also keeps each technique's share of the image (`foton render
/// --techniques`): `li` reports technique `k` (of `techniques`, the layers' names) to its
/// [`Techniques`].
pub fn render_with_maps_techniques<M: Sync>(
    scene: &Scene,
    ctx: &RenderContext<'_>,
    kernel: &NormalizedKernel,
    techniques: &[String],
    build: impl FnOnce() -> Result<M>,
    li: impl Fn(&M, Ray, &mut Sampler, &mut Techniques<'_>, &mut u64) -> Rgb + Sync,
) -> Result<Film> {
    let maps = build()?;
    if ctx.cancelled() {
        let mut film = Film::new(scene.film().width, scene.film().height);
        for name in techniques {
            film.add_layer(name);
        }
        return Ok(film);
    }
    let film = render_pixels_techniques(scene, ctx, techniques, |ps, sampler, _, t, rays| {
        li(&maps, ps.ray, sampler, t, rays)
    })?;
    kernel.check_weights()?;
    Ok(film)
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
    /// indirect unless `indirect` is false (a final gather computes it instead). The estimates'
    /// discs are clipped at the walls around the point ([`DiscClip`]: eight probe rays). Not
    /// weighted by the path's throughput; emission is the camera walk's.
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
        let [d, c, i] =
            self.reflected_parts(scene, vp, estimate, direct, depth, indirect, sampler, rays);
        let mut l = d;
        l += c;
        if indirect {
            l += i;
        }
        l
    }

    /// The three terms of [`SurfaceMaps::reflected_at`] apart: direct, caustic and indirect
    /// (zero when `indirect` is false), each a technique of `foton render --techniques`.
    #[allow(clippy::too_many_arguments)]
    pub fn reflected_parts(
        &self,
        scene: &Scene,
        vp: &VisiblePoint,
        estimate: &Estimate<'_>,
        direct: Direct,
        depth: u32,
        indirect: bool,
        sampler: &mut Sampler,
        rays: &mut u64,
    ) -> [Rgb; 3] {
        let (hit, bsdf, wo, n) = (&vp.hit, &vp.bsdf, vp.wo, vp.n);
        // The walls the estimates' discs may reach across, found once for the three maps.
        let clip = if depth > 0 {
            *rays += CLIP_PROBES as u64;
            DiscClip::probe(scene, hit.p, n, estimate.max_radius)
        } else {
            DiscClip::NONE
        };
        let disc = Disc::new(hit.p, n, depth).clipped(&clip);
        let d = match (direct, &self.direct) {
            (Direct::Photons, Some(map)) => map.reflected(estimate, &disc, bsdf, wo),
            _ => {
                let at = Scatter::Surface { hit, bsdf };
                estimate_direct(scene, at, wo, vp.medium, Mis::LightOnly, sampler, rays)
            }
        };
        let c = self.caustic.reflected(estimate, &disc, bsdf, wo);
        let i = if indirect {
            self.indirect.reflected(estimate, &disc, bsdf, wo)
        } else {
            Rgb::ZERO
        };
        [d, c, i]
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
        let disc = Disc::new(hit.p, n, depth);
        let mut l = self.caustic.reflected(estimate, &disc, bsdf, wo)
            + self.indirect.reflected(estimate, &disc, bsdf, wo);
        if let Some(direct) = &self.direct {
            l += direct.reflected(estimate, &disc, bsdf, wo);
        }
        l
    }
}
