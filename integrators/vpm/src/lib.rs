//! # `vpm`: volumetric photon mapping (Jensen and Christensen 1998)
//!
//! This table is the one list of the parameters (`[integrators.vpm]`); the README, the
//! scene-format page and docs/photon-mapping.md point here. "diagonal" is the scene's
//! bounding-box diagonal.
//!
//! | parameter           | type    | meaning                                                    | default |
//! |---------------------|---------|------------------------------------------------------------|---------|
//! | `global_photons`    | integer | photons emitted for the surface direct and indirect maps, >= 1 | 48 per pixel of the film, at most 4000000 (3145728 at 256x256) |
//! | `caustic_photons`   | integer | photons emitted for the surface caustic map; 0: no caustic map, the global map keeps the L S+ D surface photons | 100000 |
//! | `volume_photons`    | integer | photons emitted for the volume map (traced only when the scene has media); 0: no volume map | `march`: 24 per pixel of the film, at most 4000000 (1572864 at 256x256); `beam`, `beams`: 200000 |
//! | `k`                 | integer | photons per surface estimate (>= 2)                        | 8       |
//! | `max_radius`        | float   | largest surface estimate radius, > 0                       | 1/20 of the diagonal |
//! | `k_volume`          | integer | photons per volume estimate (>= 2); with `estimate = "beam"`, the neighbour that sets each photon's radius | 8 |
//! | `max_radius_volume` | float   | largest volume estimate radius, > 0                        | 1/20 of the diagonal |
//! | `step`              | float   | ray-marching step (jittered per camera sample), > 0        | 1/5 of the diagonal |
//! | `kernel`            | string  | `box`, `cone`, `gaussian` or a kernel plugin's name (normalised in 2-D on surfaces and for the beam estimate, in 3-D for the marched volume estimate) | `box` |
//! | `cone_c`            | float   | the cone kernel's c >= 1 (read only with `kernel = "cone"`) | 1      |
//! | `direct`            | string  | `nee` (shadow rays) or `photons`                           | `nee`   |
//! | `estimate`          | string  | `march` (ray marching), `beam` (beam radiance estimate: photon points, camera beams) or `beams` (photon beams, beam x beam estimate) | `march` |
//! | `beam_type`         | string  | with `estimate = "beams"`: `short` (a beam ends at the photon's next scattering event) or `long` (at the next surface, with the transmittance along it) | `short` |
//! | `beam_radius`       | float   | with `estimate = "beams"`: the photon beams' width r (the 1-D kernel's radius), > 0 | 0.0287 x diagonal x volume_photons^(-1/5) (1/400 of the diagonal for 200000) |
//! | `glossy_roughness`  | float   | glossy lobes smoother than this (microfacet alpha) are followed by the camera walk, not estimated (docs/photon-mapping.md, "Glossy surfaces") | 0.5 |
//!
//! **Why these defaults** (measured at 256x256 on the fog scenes against converged
//! references; README, "Defaults"): the error a 16x16 block shows comes from two things, the
//! photons that fall in it (their count, not k, sets its noise: the camera samples' jitter
//! averages neighbouring estimates) and the bias of the estimates' disc and ball where they
//! reach past a wall's edge or out of the fog (a band as wide as the radius). So k is small
//! (8: a small radius, so a thin band) and the global photons grow with the pixels (48 a
//! pixel: the radius keeps its size in pixels), the volume photons too for the march (24 a
//! pixel: the ball's layer along the walls, which a grazing camera ray crosses for a long
//! way, was the worst block on Bitterli's volumetric caustic at 200000), and the surface
//! estimate's disc is clipped at the walls its probes find (foton-photonmap's `DiscClip`:
//! it no longer reaches behind a crease). The march `step` is long (a fifth of the
//! diagonal, a few points per camera ray): the jitter makes the march unbiased at any step,
//! and the scene's camera samples average its noise, while each point costs a k-nearest query
//! and a shadow ray. The marched estimate is the default: at these settings it was faster
//! than the beam radiance estimate, whose walk along the ray meets the largest photon radius.
//!
//! `[render] max_depth` bounds the scattering events of whole light paths (surface hits and
//! medium scattering events alike), as in the path tracer. `[render] spp` camera samples. A
//! `k` (or `k_volume`) larger than a map's photon budget is an error (a map that stores
//! fewer than k is not: its estimates take `max_radius`).
//!
//! **Photons** (foton-photonmap's photon pass through media, `foton_photonmap::trace`): three
//! budgets. The global pass stores surface photons in the direct (only if `direct =
//! "photons"`) and indirect maps; the caustic pass stores L S+ D surface photons; the volume
//! budget stores photons at scattering events in media, the volume map (with `direct = "nee"`
//! the first scattering events, L M, are not stored: shadow rays count them). The volume
//! budget is the global pass's first `volume_photons` photons when it is no larger (their
//! volume photons' flux scaled by global / volume): the media are walked once for both maps,
//! which took a third of the photon tracing on `fog_box.toml`; a larger volume budget is a
//! pass of its own, with its own random stream. `foton photons` draws the maps `global`,
//! `caustic` and `volume`.
//!
//! **Camera rays** are followed by core's camera walk (`foton_core::api::walk_to_diffuse`)
//! through null boundaries and delta surfaces (murky glass included), tracking the medium.
//! Along each segment through a medium of length s (measured from the boundary the ray last
//! crossed, so the gap between a boundary and the ray's offset origin is not skipped):
//!
//! ```text
//! L(x, w) = Tr(x, x_s) L_s(x_s, w) + integral_0^s Tr(x, x_t) sigma_s L_i(x_t, w) dt
//! ```
//!
//! The integral is computed by ray marching with `step`, one jittered point per step (the
//! same offset for every step of a camera sample, so each point stands for its whole step):
//! at each point the in-scattered radiance sigma_s L_i is the volume estimate
//! sum_p p(w_p, w) Phi_p K3(d_p, r) over the `k_volume` nearest volume photons, plus, with
//! `direct = "nee"`, single scattering by core's direct-light estimator in the medium (one
//! shadow ray to a light, with its transmittance). Transmittance comes from the medium
//! (`Medium::transmittance`: exp(-sigma_t d) per channel, exact, for the homogeneous medium).
//! At the first diffuse surface, L_s is the photon mapper's: emission + direct
//! (`estimate_direct`, or photons) + caustic + indirect estimates, attenuated by the
//! transmittance in front of it.
//!
//! **Beam radiance estimate** (`estimate = "beam"`, Jarosz, Zwicker and Jensen 2008): instead
//! of a k-nearest query at every step, each volume photon gets its own radius at build time
//! (the distance to its `k_volume`-th neighbour, at most `max_radius_volume`), and a camera
//! segment gathers every photon whose disc, perpendicular to the ray, it crosses:
//! sum_p Tr(x, x_p) p(w_p, w) Phi_p K2(d_p, r_p), with d_p the photon's distance from the ray
//! and K2 the kernel normalised over the disc. One tree walk per segment replaces the steps'
//! queries; single scattering by shadow rays (`direct = "nee"`) is still marched.
//!
//! **Photon beams** (`estimate = "beams"`, Jarosz, Nowrouzezahrai, Sadeghi and Jensen 2011):
//! the volume pass records each photon's flights through media as beams (foton-photonmap's
//! `beams`: short or long, `beam_type`) instead of storing points, and each camera segment
//! gathers every beam whose width it passes within, with the beam x beam estimate (a 1-D
//! kernel across the two lines; `kernel` normalised in 1-D):
//!
//! ```text
//! sum_b Phi_b W_b(t_b) sigma_s(x_c) p(w_b . -w) Tr(x, x_c) K1(u_b, r) / sin(theta_b)
//! ```
//!
//! u_b the distance between the camera ray and the beam, theta_b their angle, t_b and x_c
//! the closest points on the beam and on the camera ray, W_b = Tr_b(t_b) for long beams and
//! Tr_b(t_b) / mean_c(r_c Tr_b,c(t_b)) for short ones (1 in a grey medium; r_c the photon
//! path's spectral-MIS pdf ratios). The derivation is in foton-photonmap's `beams` module.
//! With `direct = "nee"` the beams of first flights (L M) are not kept: single scattering is
//! marched with shadow rays as for the other estimates. The default width follows the 1-D
//! estimate's error: variance ~ 1 / (photons r), bias ~ r^2, least squared error at r ~
//! photons^(-1/5). Beams are found through a BVH over their pieces: each camera segment is a
//! BVH traversal, whose cost grows with photons x r.
//!
//! Each light path is counted once: through a march point x_t, L M (x_t) by shadow rays (or
//! the volume map's first-event photons), everything else by the volume map; at surfaces as in
//! `photon` (docs/photon-mapping.md).
//!
//! At surfaces and in the walk:
//!
//! * `caustic_photons = 0` keeps the L S+ D surface photons of the global pass in the indirect
//!   map (caustics come from the global budget).
//! * Surface estimates (`PhotonMap::reflected`) evaluate the BSDF per photon with its own
//!   incoming direction, and take photons from a disc: same side of the same surface (normals
//!   within about 25 degrees), no farther from the tangent plane than `DISC_THICKNESS` = 1/4 of
//!   the radius.
//! * The camera walk, the null-boundary crossing (one loop in core, with its limit of
//!   `MAX_NULL_CROSSINGS` crossings in a row, past which a ray is ended and carries nothing),
//!   the direct light and every medium query (`dyn Medium`) are core's, shared with `path`,
//!   `photon` and `sppm`; the gap after a crossing is sampled, as `path` samples it.
//!
//! `foton render --techniques` keeps the terms apart as layers of the film (docs/tools.md),
//! summing to the image: `emission`, `direct`, `caustic`, `global` (as `photon`'s), and the
//! media's in-scattered radiance, `volume_point` (photon points) or `beam` (photon beams).

use foton_core::api::{
    Budget, CameraWalk, Direct, Film, Integrator, Medium, Mis, NormalizedKernel, Parameter,
    PhotonMapView, Properties, Ray, RenderContext, Result, Rgb, Sampler, Scatter, Scene, Segment,
    Vec3, Work, estimate_direct, walk_to_diffuse, with_pool,
};
use foton_photonmap::beams::{
    BeamKind, BeamMap, Kernel1d, default_beam_radius, exit_distance, read_beam_type,
};
use foton_photonmap::map::{Estimate, PhotonMap, with_scratch};
use foton_photonmap::surface::{
    PassLists, SurfaceDefaults, SurfaceMaps, SurfaceParams, VolumeShare, check_k, diagonal, read_k,
    read_positive, render_with_maps, render_with_maps_techniques, surface_views,
    trace_surface_and_volume_photons, trace_surface_photons,
};
use foton_photonmap::trace::{
    PathClass, STREAM_VOLUME, Site, TraceOptions, trace_photons_and_beams,
};
use rayon::prelude::*;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeEstimate {
    /// A k-nearest volume estimate at every marching step.
    March,
    /// The beam radiance estimate along each camera segment.
    Beam,
    /// Photon beams: the beam x beam estimate along each camera segment.
    Beams,
}

impl VolumeEstimate {
    pub fn name(self) -> &'static str {
        match self {
            VolumeEstimate::March => "march",
            VolumeEstimate::Beam => "beam",
            VolumeEstimate::Beams => "beams",
        }
    }
}

pub struct Vpm {
    /// `global_photons`, `caustic_photons`, `k`, `max_radius`.
    pub surface: SurfaceParams,
    pub volume_photons: u64,
    pub k_volume: usize,
    pub max_radius_volume: f32,
    pub step: f32,
    pub kernel: NormalizedKernel,
    pub direct: Direct,
    pub estimate: VolumeEstimate,
    /// With `estimate = "beams"`: short or long beams, their width.
    pub beam_type: BeamKind,
    pub beam_radius: f32,
    /// The kernel's 1-D normalisation (`Kernel1d::norm`).
    pub kernel_1d: f32,
    pub max_depth: u32,
    /// How camera paths treat glossy surfaces.
    pub camera: CameraWalk,
}

pub struct Maps {
    /// The direct (with `direct = "photons"`), caustic and indirect surface maps.
    pub surface: SurfaceMaps,
    pub volume: PhotonMap,
    /// For the beam estimate: each volume photon's radius (in the map's order) and the
    /// largest.
    pub volume_radius: Vec<f32>,
    pub volume_radius_max: f32,
    /// With `estimate = "beams"`: the volume pass's photon beams.
    pub beams: Option<BeamMap>,
    /// Where camera rays that leave the scene stop marching: the box around the geometry,
    /// the lights and the volume photons, grown by the volume radius.
    pub bounds: (Vec3, Vec3),
}

impl Vpm {
    /// The three photon passes: the surface maps' two (foton-photonmap's surface passes:
    /// [direct, caustic, indirect], the direct list only if `keep_direct`) and the volume
    /// pass, which stores photons at scattering events in media: L M photons (first
    /// scattering events) only with `direct = "photons"`, otherwise shadow rays count them.
    fn trace_lists(
        &self,
        scene: &Scene,
        ctx: &RenderContext<'_>,
        keep_direct: bool,
    ) -> Result<PassLists> {
        let budgets = self.surface.budgets(self.max_depth);
        let photons_direct = self.direct == Direct::Photons;
        let wants_volume = self.volume_photons > 0 && scene.has_media();
        let beams = (self.estimate == VolumeEstimate::Beams).then_some(self.beam_type);
        if wants_volume && self.volume_photons <= budgets.global {
            // The global pass's first photons are the volume pass: their walks through the
            // media are traced once for both maps.
            let share = VolumeShare {
                photons: self.volume_photons,
                points: self.estimate != VolumeEstimate::Beams,
                beams,
                keep_direct: photons_direct,
            };
            return trace_surface_and_volume_photons(
                scene,
                ctx,
                &budgets,
                keep_direct,
                false,
                Some(share),
            );
        }
        let surface = trace_surface_photons(scene, ctx, &budgets, keep_direct, false)?;
        let (volume, beams) = if wants_volume {
            let opts = TraceOptions {
                photons: self.volume_photons,
                max_depth: self.max_depth,
                seed: scene.render().seed,
                stream: STREAM_VOLUME,
                stop_at_diffuse: false,
                sobol_emission: TraceOptions::emission_for(scene.render().sampler),
            };
            // Each light path once: L M by shadow rays unless direct = "photons".
            let keep = |class| class != PathClass::Direct || photons_direct;
            let (mut lists, beams) = trace_photons_and_beams(
                scene,
                &opts,
                ctx,
                1,
                |site, class| {
                    let points = self.estimate != VolumeEstimate::Beams;
                    (points && site == Site::Volume && keep(class)).then_some(0)
                },
                beams,
                keep,
            )?;
            (lists.pop().unwrap(), beams)
        } else {
            (Vec::new(), Vec::new())
        };
        Ok((surface, volume, beams))
    }

    pub fn build_maps(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Maps> {
        let photons_direct = self.direct == Direct::Photons;
        let (surface, volume, beams) = self.trace_lists(scene, ctx, photons_direct)?;
        let _build = ctx.phase("photon map build");
        let (beams, surface, volume) = with_pool(ctx.threads, || {
            (
                (self.estimate == VolumeEstimate::Beams)
                    .then(|| BeamMap::build(beams, self.beam_radius)),
                SurfaceMaps::build(surface, photons_direct),
                PhotonMap::build(volume),
            )
        })?;
        let volume_radius: Vec<f32> = if self.estimate == VolumeEstimate::Beam {
            with_pool(ctx.threads, || {
                volume
                    .photons()
                    .par_iter()
                    .map_init(Vec::new, |scratch, p| {
                        volume
                            .knn(
                                p.position,
                                self.k_volume,
                                self.max_radius_volume,
                                |_, _| true,
                                scratch,
                            )
                            .sqrt()
                    })
                    .collect()
            })?
        } else {
            Vec::new()
        };
        let volume_radius_max = volume_radius.iter().copied().fold(0.0, f32::max);
        let (mut lo, mut hi) = scene.bounds();
        if !volume.is_empty() {
            let (vlo, vhi) = volume.bounds();
            lo = lo.min(vlo);
            hi = hi.max(vhi);
        }
        let grow = Vec3::splat(self.max_radius_volume);
        Ok(Maps {
            surface,
            volume,
            volume_radius,
            volume_radius_max,
            beams,
            bounds: (lo - grow, hi + grow),
        })
    }

    /// The in-scattering integral along the segment `seg` through medium `m` (the radiance
    /// the medium scatters towards the camera, not yet weighted by the throughput before it),
    /// by ray marching or the beam estimate; `bounces` delta bounces precede it.
    #[allow(clippy::too_many_arguments)]
    fn in_medium(
        &self,
        scene: &Scene,
        maps: &Maps,
        seg: &Segment,
        m: &dyn Medium,
        bounces: u32,
        sampler: &mut Sampler,
        rays: &mut u64,
    ) -> Rgb {
        // A march point is a scattering event: the light paths through it have one event
        // more than the camera path before it.
        if bounces >= self.max_depth {
            return Rgb::ZERO;
        }
        let start = seg.start();
        let t_end = if seg.hit.is_some() {
            seg.length()
        } else {
            exit_distance(&start, maps.bounds)
        };
        if t_end.is_nan() || t_end <= 0.0 {
            return Rgb::ZERO;
        }
        let mut inscattered = Rgb::ZERO;
        match (self.estimate, &maps.beams, seg.medium) {
            (VolumeEstimate::Beam, _, _) => {
                inscattered += self.beam(maps, m, &start, t_end, bounces);
            }
            (VolumeEstimate::Beams, Some(beams), Some(medium)) => {
                let kernel = Kernel1d::with_norm(&self.kernel, self.kernel_1d);
                let depth = self.max_depth - bounces;
                inscattered += beams.in_scattered(scene, &kernel, &start, t_end, medium, depth);
            }
            _ => {}
        }
        if self.estimate == VolumeEstimate::March || self.direct == Direct::ShadowRays {
            inscattered += self.march(
                scene, maps, m, seg.medium, &start, t_end, bounces, sampler, rays,
            );
        }
        inscattered
    }

    /// The in-scattering integral along `ray` from 0 to `t_end` in medium `m`, by ray
    /// marching; `bounces` delta bounces precede it on the camera path.
    #[allow(clippy::too_many_arguments)]
    fn march(
        &self,
        scene: &Scene,
        maps: &Maps,
        m: &dyn Medium,
        medium: Option<u32>,
        ray: &Ray,
        t_end: f32,
        bounces: u32,
        sampler: &mut Sampler,
        rays: &mut u64,
    ) -> Rgb {
        let depth = self.max_depth - bounces;
        let estimate = Estimate {
            k: self.k_volume,
            max_radius: self.max_radius_volume,
            kernel: &self.kernel,
        };
        let phase = m.phase();
        let u = sampler.next_f32();
        let mut sum = Rgb::ZERO;
        let mut t0 = 0.0f32;
        while t0 < t_end {
            let dt = self.step.min(t_end - t0);
            let t = t0 + u * dt;
            let tr = m.transmittance(ray, t);
            // Past this, what is left of the integral is below a millionth of what the
            // surface behind would get: not worth a photon query.
            if tr.max_element() < 1e-6 {
                break;
            }
            let x = ray.at(t);
            let mut inscattered =
                if maps.volume.is_empty() || self.estimate != VolumeEstimate::March {
                    Rgb::ZERO
                } else {
                    with_scratch(|s| {
                        maps.volume
                            .in_scattered(x, ray.dir, &phase, depth, &estimate, s)
                    })
                };
            if self.direct == Direct::ShadowRays {
                // Single scattering: sigma_s times the phase-weighted direct light.
                let at = Scatter::Medium { p: x, phase };
                inscattered += m.sigma_s(x)
                    * estimate_direct(scene, at, -ray.dir, medium, Mis::LightOnly, sampler, rays);
            }
            sum += tr * inscattered * dt;
            t0 += dt;
        }
        sum
    }

    /// The beam radiance estimate of the in-scattering integral along `ray` from 0 to
    /// `t_end` in medium `m`.
    fn beam(&self, maps: &Maps, m: &dyn Medium, ray: &Ray, t_end: f32, bounces: u32) -> Rgb {
        if maps.volume.is_empty() {
            return Rgb::ZERO;
        }
        let depth = self.max_depth - bounces;
        let phase = m.phase();
        let mut sum = Rgb::ZERO;
        maps.volume.along_ray(
            ray.origin,
            ray.dir,
            t_end,
            maps.volume_radius_max,
            |i, photon, t, d2| {
                let r = maps.volume_radius[i as usize];
                if d2 >= r * r || photon.depth() > depth {
                    return;
                }
                let w = self.kernel.weight_2d(d2.sqrt(), r) * phase.eval(photon.wi().dot(ray.dir));
                sum += m.transmittance(ray, t) * photon.power() * w;
            },
        );
        sum
    }

    /// Radiance arriving at the camera along `ray`: the camera walk (core's) through null
    /// boundaries, media and delta surfaces, with the in-scattered radiance of each medium
    /// segment, then at the first diffuse surface emission + direct + caustic + indirect.
    pub fn li(
        &self,
        scene: &Scene,
        maps: &Maps,
        ray: Ray,
        sampler: &mut Sampler,
        rays: &mut u64,
    ) -> Rgb {
        self.li_with(scene, maps, ray, sampler, rays, |_, _| {})
    }

    /// [`Vpm::li`] that also hands `share` each term with its technique (`EMISSION`,
    /// `DIRECT`, `CAUSTIC`, `GLOBAL`, `VOLUME`), weighted by the camera path's throughput:
    /// their sum is the radiance returned, to float rounding.
    pub fn li_with(
        &self,
        scene: &Scene,
        maps: &Maps,
        ray: Ray,
        sampler: &mut Sampler,
        rays: &mut u64,
        mut share: impl FnMut(usize, Rgb),
    ) -> Rgb {
        let path = walk_to_diffuse(
            scene,
            ray,
            self.camera,
            sampler,
            rays,
            |seg: &Segment, m: &dyn Medium, bounces: u32, sampler: &mut Sampler, rays: &mut u64| {
                self.in_medium(scene, maps, seg, m, bounces, sampler, rays)
            },
        );
        share(EMISSION, path.emission);
        share(VOLUME, path.in_scattered);
        let Some(vp) = path.visible else {
            return path.emitted;
        };
        let depth = self.max_depth - vp.bounces;
        let estimate = self.surface.estimate(&self.kernel);
        let [direct, caustic, global] = maps.surface.reflected_parts(
            scene,
            &vp,
            &estimate,
            self.direct,
            depth,
            true,
            sampler,
            rays,
        );
        share(DIRECT, vp.beta * direct);
        share(CAUSTIC, vp.beta * caustic);
        share(GLOBAL, vp.beta * global);
        let mut l = direct;
        l += caustic;
        l += global;
        path.emitted + vp.beta * l
    }
}

impl Integrator for Vpm {
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

    /// `emission`, `direct`, `caustic`, `global` (the surface estimates at the visible
    /// point), then the media's in-scattered radiance: `volume_point` (photon points:
    /// `estimate = "march"` or `"beam"`) or `beam` (photon beams, `estimate = "beams"`).
    fn techniques(&self, _depth: u32) -> Vec<String> {
        let volume = match self.estimate {
            VolumeEstimate::Beams => "beam",
            VolumeEstimate::March | VolumeEstimate::Beam => "volume_point",
        };
        ["emission", "direct", "caustic", "global", volume]
            .map(String::from)
            .to_vec()
    }

    fn name(&self) -> &str {
        "vpm"
    }

    fn parameters(&self) -> Vec<Parameter> {
        let mut p = self.surface.parameters();
        p.extend([
            Parameter::int("volume_photons", self.volume_photons),
            Parameter::int("k_volume", self.k_volume),
            Parameter::float("max_radius_volume", self.max_radius_volume),
            Parameter::float("step", self.step),
        ]);
        p.extend(self.kernel.parameters());
        p.extend([
            Parameter::str("direct", self.direct.name()),
            Parameter::str("estimate", self.estimate.name()),
            Parameter::float("glossy_roughness", self.camera.glossy_roughness),
        ]);
        if self.estimate == VolumeEstimate::Beams {
            p.extend([
                Parameter::str("beam_type", self.beam_type.name()),
                Parameter::float("beam_radius", self.beam_radius),
            ]);
        }
        p
    }

    fn budget(&self) -> Budget {
        Budget {
            work: Work::Samples,
            scaled: {
                let mut scaled = self.surface.scaled("vpm");
                scaled.push(("integrators.vpm.volume_photons".into(), self.volume_photons));
                scaled
            },
        }
    }

    /// Surface estimates average over a disc, volume estimates over a ball or a beam's width.
    fn bias(&self) -> Option<String> {
        Some("more photons (integrators.vpm.global_photons, integrators.vpm.caustic_photons, integrators.vpm.volume_photons) or a smaller integrators.vpm.k, integrators.vpm.k_volume, integrators.vpm.max_radius or integrators.vpm.max_radius_volume shrink it".into())
    }

    /// `global` (direct and indirect surface photons of the global budget), `caustic` (L S+ D
    /// surface photons of the caustic budget) and `volume` (the volume map as rendered).
    fn photon_maps(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Vec<PhotonMapView>> {
        let (surface, mut volume, beams) = self.trace_lists(scene, ctx, true)?;
        if self.estimate == VolumeEstimate::Beams {
            // A beam is drawn at its start.
            volume = beams.iter().map(|b| b.as_photon()).collect();
        }
        let [global, caustic] = surface_views(&self.surface, surface);
        Ok(vec![
            global,
            caustic,
            foton_photonmap::view(
                "volume",
                "photons at scattering events in media, of the volume budget",
                self.volume_photons,
                &volume,
            ),
        ])
    }
}

/// Global photons per pixel of the film by default: with k fixed, the surface estimate's
/// radius, and with it the band along a wall's edge that its disc darkens, then keeps its
/// size in pixels whatever the resolution (README, "Defaults").
pub const GLOBAL_PHOTONS_PER_PIXEL: u64 = 48;
/// ... and at most this many (3M took 175 MB of memory in all on the foggy Cornell box).
pub const MAX_DEFAULT_GLOBAL_PHOTONS: u64 = 4_000_000;
/// Volume photons per pixel of the film by default for the marched estimate (at most
/// [`MAX_DEFAULT_GLOBAL_PHOTONS`]): the ball of the volume estimate beside a wall, or at the
/// fog's boundary, reaches out of the fog where no photon is stored and darkens a layer as
/// thick as its radius, which a camera ray grazing a wall crosses for a long way (the box's
/// sides on Bitterli's volumetric caustic); more photons shrink the ball. The march's cost
/// hardly grows with them (a k-nearest query per point), so they are counted per pixel like
/// the global photons (README, "Defaults").
pub const VOLUME_PHOTONS_PER_PIXEL: u64 = 24;
/// The volume photons of the beam radiance estimate and of photon beams by default: their
/// cost grows with the photons (every photon radius, or beam, a camera ray passes).
pub const BEAM_VOLUME_PHOTONS: u64 = 200_000;
/// The default k of the surface and volume estimates: small, since the camera samples'
/// jitter averages neighbouring estimates (a 16x16 block's error is set by the photons in
/// it, not by k) and a small k keeps the radius, and its bias at edges, small.
pub const DEFAULT_K: u32 = 8;

/// The layers of `foton render --techniques`, in the order of `techniques`.
const EMISSION: usize = 0;
const DIRECT: usize = 1;
const CAUSTIC: usize = 2;
const GLOBAL: usize = 3;
const VOLUME: usize = 4;

/// Reads the parameters (see the table above).
pub fn create(props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
    let diagonal = diagonal(scene);
    let pixels = scene.film().width as u64 * scene.film().height as u64;
    let defaults = SurfaceDefaults {
        global_photons: (GLOBAL_PHOTONS_PER_PIXEL * pixels).clamp(1, MAX_DEFAULT_GLOBAL_PHOTONS),
        caustic_photons: 100_000,
        k: DEFAULT_K,
    };
    let surface = SurfaceParams::read_with(props, scene, defaults)?;
    let estimate = match props.choice("estimate", &["march", "beam", "beams"], "march")? {
        "beam" => VolumeEstimate::Beam,
        "beams" => VolumeEstimate::Beams,
        _ => VolumeEstimate::March,
    };
    let volume_photons = props.u64(
        "volume_photons",
        match estimate {
            VolumeEstimate::March => {
                (VOLUME_PHOTONS_PER_PIXEL * pixels).clamp(1, MAX_DEFAULT_GLOBAL_PHOTONS)
            }
            _ => BEAM_VOLUME_PHOTONS,
        },
    )?;
    let k_volume = read_k(props, "k_volume", DEFAULT_K)?;
    check_k(
        props,
        "k_volume",
        k_volume,
        &[("volume", "volume_photons", volume_photons)],
    )?;
    let positive = |key: &str, default: f32| read_positive(props, key, default);
    let max_radius_volume = positive("max_radius_volume", diagonal / 20.0)?;
    let step = positive("step", diagonal / 5.0)?;
    let kernel = props.kernel("kernel", "box")?;
    let direct = Direct::read(props)?;
    let beams = estimate == VolumeEstimate::Beams;
    let beam_type = if beams {
        read_beam_type(props)?
    } else {
        BeamKind::Short
    };
    let beam_radius = if beams {
        positive(
            "beam_radius",
            default_beam_radius(diagonal, volume_photons.max(1)),
        )?
    } else {
        0.0
    };
    let kernel_1d = Kernel1d::norm(&kernel);
    Ok(Box::new(Vpm {
        surface,
        volume_photons,
        k_volume,
        max_radius_volume,
        step,
        kernel,
        direct,
        estimate,
        beam_type,
        beam_radius,
        kernel_1d,
        max_depth: scene.render().max_depth,
        camera: CameraWalk::read(props, scene)?,
    }))
}

foton_core::api::declare_integrator!(
    "vpm",
    "volumetric photon mapping (Jensen and Christensen)",
    create
);
