//! # `photon`: photon mapping (Jensen)
//!
//! This table is the one list of the parameters (`[integrators.photon]`); the README, the
//! scene-format page and docs/photon-mapping.md point here.
//!
//! | parameter         | type    | meaning                                                        | default  |
//! |-------------------|---------|----------------------------------------------------------------|----------|
//! | `global_photons`  | integer | photons emitted for the direct and indirect ("global") maps, >= 1 | 200000 |
//! | `caustic_photons` | integer | photons emitted for the caustic map; 0: no caustic map, the global map keeps the L S+ D photons (below) | 100000 |
//! | `k`               | integer | photons per radiance estimate (k nearest, >= 2: the k-th only sets the radius) | 50 |
//! | `max_radius`      | float   | largest estimate radius (world units), > 0                     | 1/20 of the scene's bounding-box diagonal |
//! | `kernel`          | string  | `box`, `cone`, `gaussian` or a kernel plugin's name            | `box`    |
//! | `cone_c`          | float   | the cone kernel's c >= 1 (read only with `kernel = "cone"`)    | 1        |
//! | `direct`          | string  | `nee` (shadow rays) or `photons` (first-hit photons)           | `nee`    |
//! | `final_gather`    | bool    | indirect light by gather rays that look the maps up            | false    |
//! | `gather_rays`     | integer | gather rays per camera sample, >= 1 (used with `final_gather`) | 32       |
//! | `glossy_roughness`| float   | glossy lobes smoother than this (microfacet alpha) are followed by sampling, not estimated (docs/photon-mapping.md, "Glossy surfaces") | 0.5 |
//!
//! `[render] max_depth` bounds the scattering events of a whole light path, as in the path
//! tracer: a photon's surface hits plus the camera path's delta bounces (each photon records
//! its count, and an estimate takes only the photons that fit). `[render] spp` camera samples.
//! A `k` larger than a map's photon budget is an error (a map that stores fewer than k is not:
//! its estimates take `max_radius`); a scene with participating media is refused (`vpm`
//! renders those).
//!
//! Two passes. **Photons** leave the lights in proportion to power (the photon pass of
//! foton-photonmap, `foton_photonmap::trace`), bounce by BSDF sampling with Russian roulette,
//! and are stored at diffuse surfaces only, by path: L D (first hit) in the direct map (only
//! when `direct = "photons"` or with final gathering), L S+ D in the caustic map (from the
//! caustic budget), and every other path in the indirect map. **Camera rays** follow mirrors
//! and glass to the first diffuse point x (core's camera walk, `foton_core::walk`), where
//! radiance = emission + direct + caustic + indirect:
//!
//! * direct: core's direct-light estimator (`foton_core::api::estimate_direct`: one shadow
//!   ray to a light chosen by power), or the direct map's estimate;
//! * caustic: the caustic map's estimate;
//! * indirect: the indirect map's estimate, or with `final_gather` the mean over cosine-
//!   distributed gather rays of the radiance leaving the diffuse point they reach (through
//!   mirrors and glass), estimated from all three maps there.
//!
//! Each light path is counted once (docs/photon-mapping.md). An estimate
//! (`PhotonMap::reflected`) is L = sum_p f(x, w_p, w) Phi_p K(d_p, r) over the k nearest
//! photons of a disc around x, r the distance to the k-th (which, on the boundary, is not
//! summed). At the camera's visible point the disc is clipped at the walls around x
//! (`PhotonMap::reflected` on a `Disc` clipped by foton-photonmap's `DiscClip`: eight probe rays in the
//! tangent plane; beside a crease the disc would reach behind the wall, where no photon of
//! this surface lands, and darken a band as wide as r); the gather rays' estimates are not.
//!
//! How the maps are used:
//!
//! * With `caustic_photons = 0` the global pass keeps its L S+ D photons in the indirect map,
//!   so caustics come from the global budget (fewer photons, more blur). With a caustic
//!   budget the global pass drops them (the caustic pass counts those paths). With
//!   `final_gather`, which reads the caustic map at x but not the indirect one, they go to
//!   the caustic map.
//! * The BSDF is evaluated per photon with the photon's own incoming direction w_p (not a
//!   reflectance times the density), so the estimate is right for any BSDF.
//! * Photons are taken from a disc, not a ball: on the same side of a surface facing the same
//!   way (stored normals within about 25 degrees) and no farther from the tangent plane than
//!   `DISC_THICKNESS` = 1/4 of the radius, so that photons on a parallel surface within the
//!   radius (the top of a low box beside the floor) stay out of the estimate.
//! * The camera walk (null boundaries crossed by core's one crossing loop, with its limit of
//!   `MAX_NULL_CROSSINGS` crossings in a row, past which a ray is ended and carries nothing),
//!   the gather rays' walk (`first_surface`) and the direct light (`estimate_direct`) are
//!   core's, the same code as `path`, `sppm` and `vpm` use.
//!
//! The method is consistent, not unbiased: estimates blur light over the radius r, which
//! shrinks as photons grow. Caustics from point lights, which a path tracer cannot render,
//! come out well.
//!
//! `foton render --techniques` keeps the terms apart as layers of the film (docs/tools.md),
//! summing to the image: `emission` (the camera walk's), `direct`, `caustic`, and `global` or,
//! with `final_gather`, `final_gather`.

use foton_core::api::{
    Bsdf, Budget, CameraWalk, Direct, Error, Film, Hit, Integrator, NormalizedKernel, Parameter,
    PhotonMapView, Properties, Ray, RenderContext, Result, Rgb, Sampler, Scene, TransportMode,
    Vec3, Work, first_surface, offset_origin, trace_to_diffuse, with_pool,
};
use foton_photonmap::surface::{
    SurfaceMaps, SurfaceParams, render_with_maps, render_with_maps_techniques, surface_views,
    trace_surface_photons,
};

pub struct PhotonMapper {
    /// `global_photons`, `caustic_photons`, `k`, `max_radius`.
    pub surface: SurfaceParams,
    pub kernel: NormalizedKernel,
    pub direct: Direct,
    pub final_gather: bool,
    pub gather_rays: u32,
    pub max_depth: u32,
    /// How camera paths (and gather rays) treat glossy surfaces.
    pub camera: CameraWalk,
}

/// A diffuse point reached by a camera ray: where it is, what it is, where the ray came from.
#[derive(Clone, Copy)]
struct Vertex<'a> {
    hit: &'a Hit,
    bsdf: &'a Bsdf,
    wo: Vec3,
    /// Delta bounces of the camera path before this vertex.
    bounces: u32,
}

/// Specular (delta) bounces a gather ray may follow before giving up.
const MAX_SPECULAR: u32 = 64;

impl PhotonMapper {
    /// The photon pass: traces both budgets and builds the maps (foton-photonmap's surface
    /// maps; the direct map only when direct light or final gathering reads it).
    pub fn build_maps(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<SurfaceMaps> {
        let need_direct = self.direct == Direct::Photons || self.final_gather;
        let lists = trace_surface_photons(
            scene,
            ctx,
            &self.surface.budgets(self.max_depth),
            need_direct,
            self.final_gather,
        )?;
        if lists[2].is_empty() && !scene.lights().is_empty() {
            ctx.progress
                .warn("no photon reached a second diffuse surface: the indirect map is empty");
        }
        let _build = ctx.phase("photon map build");
        with_pool(ctx.threads, || SurfaceMaps::build(lists, need_direct))
    }

    /// Indirect light at a diffuse point by final gathering: rays by the BSDF's non-delta part,
    /// followed through mirrors and glass to a diffuse point whose reflected radiance the maps
    /// give.
    /// Emission found along them is not counted: it is direct light (L D) or a caustic
    /// (L S+ D), both counted elsewhere.
    fn final_gather(
        &self,
        scene: &Scene,
        maps: &SurfaceMaps,
        v: &Vertex<'_>,
        sampler: &mut Sampler,
        rays: &mut u64,
    ) -> Rgb {
        let Vertex {
            hit,
            bsdf,
            wo,
            bounces,
        } = *v;
        // Scattering events left for the light paths after x: the delta bounces of a gather
        // ray and the photon's own events (the one at y included).
        let budget = self.max_depth.saturating_sub(bounces + 1);
        let mut sum = Rgb::ZERO;
        for _ in 0..self.gather_rays {
            let (u, uc) = (sampler.next_2d(), sampler.next_f32());
            let Some(bs) = bsdf.sample(wo, u, uc, TransportMode::Radiance) else {
                continue;
            };
            // The camera walk followed the delta part (a smooth plastic's coat) with its
            // probability and estimates the rest here, so a gather ray that picks the delta
            // part would count its reflection twice: it gathers nothing. The other rays'
            // weight f cos / pdf, with the pdf of the whole BSDF, already holds one over
            // the rest's probability, so the gather's mean is the non-delta part's integral.
            if bs.delta {
                continue;
            }
            let mut beta = bs.weight;
            let mut ray = Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi);
            for b in 0..MAX_SPECULAR.min(budget) {
                let Some((y, arrived)) = first_surface(scene, ray, None, rays) else {
                    break;
                };
                let Some(m) = scene.bsdf(&y) else {
                    break;
                };
                let wo_y = -arrived.ray.dir;
                // A delta part (all of a mirror, the coat of a smooth plastic) is followed;
                // the rest is the maps' estimate, each weighted by one over its probability.
                let p_delta = if m.is_delta() {
                    1.0
                } else {
                    m.delta_probability(wo_y)
                };
                let (u, uc) = (sampler.next_2d(), sampler.next_f32());
                let sampled = if p_delta > 0.0 {
                    m.sample(wo_y, u, uc, TransportMode::Radiance)
                } else {
                    None
                };
                match sampled {
                    Some(bs) if bs.delta => {
                        beta *= bs.weight;
                        ray = Ray::new(offset_origin(y.p, y.ng, bs.wi), bs.wi);
                    }
                    _ if m.is_delta() => break,
                    _ => {
                        let depth = budget - b;
                        let l = maps.reflected_by_all(
                            &self.surface.estimate(&self.kernel),
                            &m,
                            &y,
                            wo_y,
                            depth,
                        );
                        sum += beta * l / (1.0 - p_delta);
                        break;
                    }
                }
            }
        }
        sum / self.gather_rays as f32
    }

    /// Radiance arriving at the camera along `ray`: follow mirrors and glass to the first
    /// diffuse point, then emission + direct + caustic + indirect there.
    pub fn li(
        &self,
        scene: &Scene,
        maps: &SurfaceMaps,
        ray: Ray,
        sampler: &mut Sampler,
        rays: &mut u64,
    ) -> Rgb {
        self.li_with(scene, maps, ray, sampler, rays, |_, _| {})
    }

    /// [`PhotonMapper::li`] that also hands `share` each term with its technique
    /// (`EMISSION`, `DIRECT`, `CAUSTIC`, `GLOBAL` or `FINAL_GATHER`), weighted by the camera
    /// path's throughput: their sum is the radiance returned, to float rounding.
    pub fn li_with(
        &self,
        scene: &Scene,
        maps: &SurfaceMaps,
        ray: Ray,
        sampler: &mut Sampler,
        rays: &mut u64,
        mut share: impl FnMut(usize, Rgb),
    ) -> Rgb {
        let path = trace_to_diffuse(scene, ray, self.camera, sampler, rays);
        share(EMISSION, path.emitted);
        let Some(vp) = path.visible else {
            return path.emitted;
        };
        // Photons here may have taken the scattering events the camera path has left.
        let depth = self.max_depth - vp.bounces;
        let estimate = self.surface.estimate(&self.kernel);
        let [direct, caustic, global] = maps.reflected_parts(
            scene,
            &vp,
            &estimate,
            self.direct,
            depth,
            !self.final_gather,
            sampler,
            rays,
        );
        let mut l = direct;
        l += caustic;
        share(DIRECT, vp.beta * direct);
        share(CAUSTIC, vp.beta * caustic);
        if self.final_gather {
            let vertex = Vertex {
                hit: &vp.hit,
                bsdf: &vp.bsdf,
                wo: vp.wo,
                bounces: vp.bounces,
            };
            let gathered = self.final_gather(scene, maps, &vertex, sampler, rays);
            l += gathered;
            share(FINAL_GATHER, vp.beta * gathered);
        } else {
            l += global;
            share(GLOBAL, vp.beta * global);
        }
        path.emitted + vp.beta * l
    }
}

/// The techniques of `foton render --techniques`, as layers: emission seen from the camera
/// (directly or through mirrors and glass), direct light, the caustic map's estimate, and the
/// global (indirect) map's estimate or, with `final_gather`, the gather's (the last layer).
const EMISSION: usize = 0;
const DIRECT: usize = 1;
const CAUSTIC: usize = 2;
const GLOBAL: usize = 3;
const FINAL_GATHER: usize = 3;

impl Integrator for PhotonMapper {
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        let Some(depth) = ctx.techniques else {
            return render_with_maps(
                scene,
                ctx,
                &self.kernel,
                || self.build_maps(scene, ctx),
                |maps, ray, sampler, rays| self.li(scene, maps, ray, sampler, rays),
            );
        };
        render_with_maps_techniques(
            scene,
            ctx,
            &self.kernel,
            &self.techniques(depth),
            || self.build_maps(scene, ctx),
            |maps, ray, sampler, techniques, rays| {
                self.li_with(scene, maps, ray, sampler, rays, |k, v| techniques.add(k, v))
            },
        )
    }

    /// `emission`, `direct`, `caustic`, then `global` or (with `final_gather`)
    /// `final_gather`.
    fn techniques(&self, _depth: u32) -> Vec<String> {
        let last = if self.final_gather {
            "final_gather"
        } else {
            "global"
        };
        ["emission", "direct", "caustic", last]
            .map(String::from)
            .to_vec()
    }

    fn name(&self) -> &str {
        "photon"
    }

    fn parameters(&self) -> Vec<Parameter> {
        let mut p = self.surface.parameters();
        p.extend(self.kernel.parameters());
        p.extend([
            Parameter::str("direct", self.direct.name()),
            Parameter::bool("final_gather", self.final_gather),
            Parameter::int("gather_rays", self.gather_rays),
            Parameter::float("glossy_roughness", self.camera.glossy_roughness),
        ]);
        p
    }

    fn budget(&self) -> Budget {
        Budget {
            work: Work::Samples,
            scaled: self.surface.scaled("photon"),
        }
    }

    /// Each estimate averages over a disc as wide as its k-th photon (at most `max_radius`).
    fn bias(&self) -> Option<String> {
        Some("more photons (integrators.photon.global_photons, integrators.photon.caustic_photons) or a smaller integrators.photon.k or integrators.photon.max_radius shrink it".into())
    }

    /// `global`: the direct and indirect photons of the global budget (Jensen's global map;
    /// a render keeps the direct ones only for `direct = "photons"` or final gathering), and
    /// `caustic`: the L S+ D photons of the caustic budget.
    fn photon_maps(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Vec<PhotonMapView>> {
        let lists = trace_surface_photons(
            scene,
            ctx,
            &self.surface.budgets(self.max_depth),
            true,
            false,
        )?;
        Ok(surface_views(&self.surface, lists).to_vec())
    }
}

/// Reads the parameters (see the table above).
pub fn create(props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
    let surface = SurfaceParams::read(props, scene)?;
    let kernel = props.kernel("kernel", "box")?;
    let direct = Direct::read(props)?;
    let final_gather = props.bool("final_gather", false)?;
    let gather_rays = props.u32("gather_rays", 32)?;
    if gather_rays == 0 {
        return Err(props.error("gather_rays", "must be at least 1"));
    }
    if scene.has_media() {
        return Err(Error::Usage(format!(
            "{}: the scene has participating media, which `photon` does not render (use `vpm`)",
            scene.file().display()
        )));
    }
    Ok(Box::new(PhotonMapper {
        surface,
        kernel,
        direct,
        final_gather,
        gather_rays,
        max_depth: scene.render().max_depth,
        camera: CameraWalk::read(props, scene)?,
    }))
}

foton_core::api::declare_integrator!("photon", "photon mapping (Jensen)", create);
