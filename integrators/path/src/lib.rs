//! # `path`: unidirectional path tracer
//!
//! This table is the one list of the parameters (`[integrators.path]`); the README and the
//! scene-format page point here.
//!
//! | parameter  | type    | meaning                                                  | default |
//! |------------|---------|----------------------------------------------------------|---------|
//! | `rr_depth` | integer | scattering events before Russian roulette may end a path | 5       |
//!
//! `[render] max_depth` bounds the number of scattering events, surface bounces and scattering
//! in media alike (0: only emitters seen directly, 1: direct lighting and single scattering).
//! `[render] spp` camera samples per pixel.
//!
//! Next-event estimation at every non-delta vertex: point lights by shadow rays; area lights
//! (any emissive shape) by shadow rays combined with BSDF sampling by multiple importance
//! sampling (power heuristic). Lights are chosen with probability proportional to power.
//! Delta materials (mirror, glass) are followed by BSDF sampling only; radiance is scaled by
//! 1/eta^2 on refraction. Null boundaries are crossed without counting as a bounce.
//!
//! Participating media (volumetric path tracing): the ray's medium is tracked from the camera
//! through every boundary it crosses (`Scene::medium_after`). In a medium a free-flight
//! distance is sampled up to the next surface, with spectral MIS over the channels along the
//! whole path (a hero channel per path, pbrt-v4's scheme), so coloured media are unbiased; a
//! scattering event is a path vertex (it counts toward `max_depth`) with next-event
//! estimation (shadow rays carry the transmittance of the media and null boundaries they
//! cross; area lights are combined with phase-function sampling by MIS) and a
//! phase-function-sampled continuation. An emitting medium adds its emission at each
//! scattering event sampled in it (Tr sigma_a Le over the event's pdf: the collision
//! estimator); no shadow ray aims at it. A medium with sigma_t = 0 is skipped, so it renders
//! exactly as vacuum; a scene without media renders exactly as before media existed.
//!
//! It is unbiased and converges to the right image for any scene, but caustics seen through
//! or cast by delta surfaces from point lights (L S+ D E paths from a point light, L S+ M E
//! volumetric caustics too) cannot be sampled: they are missing. Volumetric caustics from
//! area lights are found, slowly. That is what photon mapping is for.
//!
//! **Shared code.** The ray's walk through null boundaries and media is core's
//! (`foton_core::api::RayWalk`, the one crossing loop every integrator and the photon pass
//! use): a segment is measured from the boundary the ray last crossed, so the gap between the
//! boundary and the ray's offset origin is sampled too, and past `MAX_NULL_CROSSINGS` (256)
//! crossings in a row the path is ended and carries nothing further. Light sampling is core's
//! direct-light estimator (`foton_core::api::estimate_direct` with
//! `Mis::WithScatterSampling`: the power heuristic against the BSDF's or phase function's
//! pdf), the same one `photon`, `sppm` and `vpm` use (without MIS); media are queried through
//! core's `Medium` interface.
//!
//! **Built twice.** Release builds for x86-64 also build this crate with `-C
//! target-cpu=x86-64-v3` (`build.rs`), loaded instead where the processor has it: the same
//! images, 6 to 8 % less time on the Cornell box (docs/PERFORMANCE.md).

use foton_core::api::{
    Film, HeroChannel, Integrator, Mis, Parameter, Properties, Ray, RayWalk, Reached,
    RenderContext, Result, Rgb, Sampler, Scatter, Scene, TransportMode, Vec3, estimate_direct,
    power_heuristic, render_pixels, russian_roulette,
};

pub struct PathTracer {
    max_depth: u32,
    rr_depth: u32,
}

impl PathTracer {
    pub fn new(max_depth: u32, rr_depth: u32) -> Self {
        PathTracer {
            max_depth,
            rr_depth,
        }
    }

    /// Radiance arriving at the camera along `ray`; adds the rays traced to `rays`.
    pub fn li(&self, scene: &Scene, ray: Ray, sampler: &mut Sampler, rays: &mut u64) -> Rgb {
        let mut radiance = Rgb::ZERO;
        let mut beta = Rgb::ONE;
        let mut depth = 0u32;
        // The camera ray counts as specular: emitters seen directly get full weight.
        let mut specular = true;
        let mut prev_pdf = 0.0f32;
        let mut prev_p = ray.origin;
        // The ray, the medium it travels in and the null boundaries it crosses.
        let mut walk = RayWalk::camera(scene, ray);
        // Spectral MIS over the whole path, chosen at the first medium the path meets.
        let mut hero: Option<HeroChannel> = None;

        loop {
            let seg = walk.segment(scene, rays);

            // ---- Medium: free flight to a scattering event or to the surface ----
            if let Some(m) = seg.interacting_medium(scene) {
                let hero = hero.get_or_insert_with(|| HeroChannel::new(sampler.next_f32()));
                let flight = m.sample_free_flight(
                    &seg.start(),
                    seg.length(),
                    hero.channel,
                    sampler.next_f32(),
                );
                // ---- The medium's emission at the event (no other strategy samples it) ----
                if flight.emitted != Rgb::ZERO {
                    radiance += beta * hero.emission(&flight);
                }
                beta *= hero.update(&flight);
                if beta == Rgb::ZERO {
                    break;
                }
                if flight.scattered {
                    if depth >= self.max_depth {
                        break;
                    }
                    let x = seg.at(flight.t);
                    let phase = m.phase();
                    let wo = -seg.ray.dir;

                    // ---- Emitter sampling from the medium ----
                    let at = Scatter::Medium { p: x, phase };
                    let mis = Mis::WithScatterSampling;
                    radiance +=
                        beta * estimate_direct(scene, at, wo, walk.medium, mis, sampler, rays);

                    // ---- Phase-function sampling: p / pdf = 1, beta is unchanged ----
                    let (wi, pdf) = phase.sample(seg.ray.dir, sampler.next_2d());
                    specular = false;
                    prev_pdf = pdf;
                    prev_p = x;
                    depth += 1;
                    if !russian_roulette(depth, self.rr_depth, &mut beta, sampler) {
                        break;
                    }
                    walk.scatter_in_medium(x, wi);
                    continue;
                }
            }

            let Some(hit) = seg.hit else {
                // ---- The environment, weighted against light sampling as an emitter ----
                if let Some((light_id, le)) = scene.escaped(seg.ray.dir)
                    && !(depth == 0 && scene.render().hide_emitters)
                {
                    if specular {
                        radiance += beta * le;
                    } else {
                        let light = &scene.lights()[light_id as usize];
                        let pdf_light = scene.light_pmf(light_id as usize)
                            * light.pdf_li(prev_p, prev_p + seg.ray.dir, Vec3::ZERO);
                        radiance += beta * le * power_heuristic(prev_pdf, pdf_light);
                    }
                }
                break;
            };
            let bsdf = match walk.reach(scene, &hit) {
                Reached::Surface(bsdf) => bsdf,
                Reached::Crossed => continue,
                Reached::Ended => break,
            };
            let wo = -seg.ray.dir;

            // ---- Emission (weighted against light sampling at the previous vertex) ----
            if let Some((light_id, light, le)) = seg.emitted(scene) {
                if specular {
                    radiance += beta * le;
                } else {
                    let pdf_light =
                        scene.light_pmf(light_id as usize) * light.pdf_li(prev_p, hit.p, hit.ng);
                    radiance += beta * le * power_heuristic(prev_pdf, pdf_light);
                }
            }
            if depth >= self.max_depth {
                break;
            }

            // ---- Emitter sampling ----
            if !bsdf.is_delta() {
                let at = Scatter::Surface {
                    hit: &hit,
                    bsdf: &bsdf,
                };
                let mis = Mis::WithScatterSampling;
                radiance += beta * estimate_direct(scene, at, wo, walk.medium, mis, sampler, rays);
            }

            // ---- BSDF sampling ----
            let (u, uc) = (sampler.next_2d(), sampler.next_f32());
            let Some(bs) = bsdf.sample(wo, u, uc, TransportMode::Radiance) else {
                break;
            };
            beta *= bs.weight;
            specular = bs.delta;
            prev_pdf = bs.pdf;
            prev_p = hit.p;
            depth += 1;
            if !russian_roulette(depth, self.rr_depth, &mut beta, sampler) {
                break;
            }
            walk.scatter_at_surface(scene, &hit, bs.wi);
        }
        radiance
    }
}

impl Integrator for PathTracer {
    fn renders_meters(&self) -> bool {
        true
    }

    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        render_pixels(scene, ctx, |ray, sampler, rays| {
            self.li(scene, *ray, sampler, rays)
        })
    }

    fn name(&self) -> &str {
        "path"
    }

    fn parameters(&self) -> Vec<Parameter> {
        vec![Parameter::int("rr_depth", self.rr_depth)]
    }
}

/// Reads the parameters (see the table above).
pub fn create(props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
    let rr_depth = props.u32("rr_depth", 5)?;
    Ok(Box::new(PathTracer::new(
        scene.render().max_depth,
        rr_depth,
    )))
}

foton_core::api::declare_integrator!("path", "unidirectional path tracer (NEE + MIS)", create);
