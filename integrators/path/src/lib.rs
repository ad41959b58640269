//! # `path`: unidirectional path tracer
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
//! phase-function-sampled continuation. A medium with sigma_t = 0 is skipped, so it renders
//! exactly as vacuum; a scene without media renders exactly as before media existed.
//!
//! It is unbiased and converges to the right image for any scene, but caustics seen through
//! or cast by delta surfaces from point lights (L S+ D E paths from a point light, L S+ M E
//! volumetric caustics too) cannot be sampled: they are missing. Volumetric caustics from
//! area lights are found, slowly. That is what photon mapping is for.

use foton_core::Vec3;
use foton_core::geometry::{Ray, offset_origin};
use foton_core::integrator::{Integrator, Parameter, RenderContext};
use foton_core::material::TransportMode;
use foton_core::medium::HeroChannel;
use foton_core::props::Properties;
use foton_core::render::render_pixels;
use foton_core::sampling::{Sampler, power_heuristic};
use foton_core::scene::Scene;
use foton_core::{Result, Rgb, film::Film};

pub struct PathTracer {
    max_depth: u32,
    rr_depth: u32,
}

/// Null boundaries crossed by one ray segment before the path is abandoned (guards against a
/// ray stuck on coincident boundaries).
const MAX_NULL_CROSSINGS: u32 = 256;

impl PathTracer {
    pub fn new(max_depth: u32, rr_depth: u32) -> Self {
        PathTracer {
            max_depth,
            rr_depth,
        }
    }

    /// Radiance arriving at the camera along `ray`; adds the rays traced to `rays`.
    pub fn li(&self, scene: &Scene, mut ray: Ray, sampler: &mut Sampler, rays: &mut u64) -> Rgb {
        let mut radiance = Rgb::ZERO;
        let mut beta = Rgb::ONE;
        let mut depth = 0u32;
        // The camera ray counts as specular: emitters seen directly get full weight.
        let mut specular = true;
        let mut prev_pdf = 0.0f32;
        let mut prev_p = ray.origin;
        let mut crossings = 0u32;
        // The medium the ray travels in (None: vacuum).
        let mut medium = scene.camera_medium;
        // Spectral MIS over the whole path, chosen at the first medium the path meets.
        let mut hero: Option<HeroChannel> = None;
        // How far the ray's origin lies past the null boundary it just crossed, along the ray:
        // that piece of the medium is sampled too (as if the ray started on the boundary).
        let mut next_gap = 0.0f32;

        loop {
            *rays += 1;
            let hit = scene.intersect(&ray, f32::INFINITY);
            let gap = std::mem::take(&mut next_gap);

            // ---- Medium: free flight to a scattering event or to the surface ----
            if let Some(m) = medium.map(|m| &scene.media[m as usize].value)
                && !m.is_vacuum()
            {
                let tmax = hit.map_or(f32::INFINITY, |h| h.t + gap);
                let hero = hero.get_or_insert_with(|| HeroChannel::new(sampler.next_f32()));
                let flight = m.sample_free_flight(tmax, hero.channel, sampler.next_f32());
                beta *= hero.update(&flight);
                if beta == Rgb::ZERO {
                    break;
                }
                if flight.scattered {
                    crossings = 0;
                    if depth >= self.max_depth {
                        break;
                    }
                    let x = ray.at(flight.t - gap);
                    let phase = m.phase;

                    // ---- Emitter sampling from the medium ----
                    // The phase function takes the cosine between the directions light
                    // travels in: from the light (-wi) and on towards the camera (-ray.dir).
                    if let Some((light_id, pmf)) = scene.sample_light(sampler.next_f32()) {
                        let light = &scene.lights[light_id];
                        let (u, uc) = (sampler.next_2d(), sampler.next_f32());
                        if let Some(ls) = light.sample_li(x, u, uc)
                            && ls.li != Rgb::ZERO
                        {
                            *rays += 1;
                            let tr = scene.transmittance(x, Vec3::ZERO, ls.p, ls.n, medium);
                            if tr != Rgb::ZERO {
                                let p = phase.eval(ray.dir.dot(ls.wi));
                                if ls.delta {
                                    radiance += beta * tr * p * ls.li / pmf;
                                } else {
                                    let pdf_light = pmf * ls.pdf;
                                    let w = power_heuristic(pdf_light, p);
                                    radiance += beta * tr * p * ls.li * w / pdf_light;
                                }
                            }
                        }
                    }

                    // ---- Phase-function sampling: p / pdf = 1, beta is unchanged ----
                    let (wi, pdf) = phase.sample(ray.dir, sampler.next_2d());
                    specular = false;
                    prev_pdf = pdf;
                    prev_p = x;
                    depth += 1;
                    if depth >= self.rr_depth {
                        let survive = beta.max_element().min(0.95);
                        if survive <= 0.0 || sampler.next_f32() >= survive {
                            break;
                        }
                        beta /= survive;
                    }
                    ray = Ray::new(x, wi);
                    continue;
                }
            }

            let Some(hit) = hit else {
                break;
            };
            let material = *scene.material(&hit);
            if material.is_null() {
                crossings += 1;
                if crossings > MAX_NULL_CROSSINGS {
                    break;
                }
                medium = scene.medium_after(&hit, ray.dir, medium);
                let origin = offset_origin(hit.p, hit.ng, ray.dir);
                // The origin is offset along the normal; back along the ray to the boundary's
                // plane is offset / |cos| (bounded, for grazing rays, by 10 offsets).
                let offset = (origin - hit.p).length();
                next_gap = offset / hit.ng.dot(ray.dir).abs().max(0.1);
                ray = Ray::new(origin, ray.dir);
                continue;
            }
            crossings = 0;
            let wo = -ray.dir;

            // ---- Emission (weighted against light sampling at the previous vertex) ----
            if let Some((light_id, light)) = scene.area_light(&hit) {
                let le = light.emitted(hit.ng, wo);
                if le != Rgb::ZERO {
                    if specular {
                        radiance += beta * le;
                    } else {
                        let pdf_light = scene.light_pmf(light_id as usize)
                            * light.pdf_li(prev_p, hit.p, hit.ng);
                        radiance += beta * le * power_heuristic(prev_pdf, pdf_light);
                    }
                }
            }
            if depth >= self.max_depth {
                break;
            }

            // ---- Emitter sampling ----
            if !material.is_delta()
                && let Some((light_id, pmf)) = scene.sample_light(sampler.next_f32())
            {
                let light = &scene.lights[light_id];
                let (u, uc) = (sampler.next_2d(), sampler.next_f32());
                if let Some(ls) = light.sample_li(hit.p, u, uc)
                    && ls.li != Rgb::ZERO
                {
                    let f = material.eval(wo, ls.wi, hit.ng);
                    *rays += (f != Rgb::ZERO) as u64;
                    let tr = if f != Rgb::ZERO {
                        let side = scene.medium_after(&hit, ls.wi, medium);
                        scene.transmittance(hit.p, hit.ng, ls.p, ls.n, side)
                    } else {
                        Rgb::ZERO
                    };
                    if tr != Rgb::ZERO {
                        // Without media tr is exactly one: the image is bit for bit the one
                        // rendered before media existed.
                        let cos = ls.wi.dot(hit.ng).abs();
                        if ls.delta {
                            radiance += beta * f * cos * ls.li * tr / pmf;
                        } else {
                            let pdf_light = pmf * ls.pdf;
                            let pdf_bsdf = material.pdf(wo, ls.wi, hit.ng);
                            let w = power_heuristic(pdf_light, pdf_bsdf);
                            radiance += beta * f * cos * ls.li * tr * w / pdf_light;
                        }
                    }
                }
            }

            // ---- BSDF sampling ----
            let (u, uc) = (sampler.next_2d(), sampler.next_f32());
            let Some(bs) = material.sample(wo, hit.ng, u, uc, TransportMode::Radiance) else {
                break;
            };
            beta *= bs.weight;
            specular = bs.delta;
            prev_pdf = bs.pdf;
            prev_p = hit.p;
            depth += 1;
            // Refraction into or out of a volume changes the medium; reflection keeps it.
            medium = scene.medium_after(&hit, bs.wi, medium);

            // ---- Russian roulette: keep the throughput's expectation, end dim paths ----
            if depth >= self.rr_depth {
                let survive = beta.max_element().min(0.95);
                if survive <= 0.0 || sampler.next_f32() >= survive {
                    break;
                }
                beta /= survive;
            }
            ray = Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi);
        }
        radiance
    }
}

impl Integrator for PathTracer {
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
    Ok(Box::new(PathTracer::new(scene.render.max_depth, rr_depth)))
}

foton_core::declare_integrator!("path", "unidirectional path tracer (NEE + MIS)", create);
