//! Direct light: the one estimator every integrator uses (Mitsuba's
//! `sample_emitter_direction` followed by `BSDF::eval`), and the one `direct` option of the
//! photon-mapping integrators.
//!
//! A light is chosen in proportion to power, a point on it is sampled, and one shadow ray
//! carries the transmittance of the media and null boundaries it crosses:
//!
//! ```text
//! L_d = f(wo, wi) |cos theta_i| L_i(wi) Tr w / (pmf(light) pdf(wi))     at a surface
//! L_d = p(wo, wi) L_i(wi) Tr w / (pmf(light) pdf(wi))                   in a medium
//! ```
//!
//! (in a medium without sigma_s, which the caller's throughput or estimate carries). The MIS
//! weight w is 1 when the light sample is the only estimate of direct light at the point (the
//! photon integrators' visible points and march points), and the power heuristic against the
//! BSDF's or phase function's pdf when the caller also finds the lights by sampling those (the
//! path tracer, which counts what its next ray hits with the matching weight).

use crate::Rgb;
use crate::bsdf::Bsdf;
use crate::error::Result;
use crate::geometry::Hit;
use crate::medium::Phase;
use crate::props::Properties;
use crate::sampling::{Sampler, power_heuristic};
use crate::scene::Scene;
use glam::Vec3;

/// How the photon-mapping integrators get direct light (their `direct` parameter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direct {
    /// Shadow rays to the lights (`"nee"`, the default).
    ShadowRays,
    /// The first-hit photons' density estimate (`"photons"`).
    Photons,
}

impl Direct {
    /// Reads the `direct` parameter: `"nee"` (default) or `"photons"`.
    pub fn read(props: &Properties<'_>) -> Result<Direct> {
        Ok(match props.choice("direct", &["nee", "photons"], "nee")? {
            "photons" => Direct::Photons,
            _ => Direct::ShadowRays,
        })
    }

    /// The value as written in a scene file.
    pub fn name(self) -> &'static str {
        match self {
            Direct::ShadowRays => "nee",
            Direct::Photons => "photons",
        }
    }
}

/// Where light is scattered towards the viewer.
#[derive(Clone, Copy, Debug)]
pub enum Scatter<'a> {
    /// A surface point and its BSDF.
    Surface { hit: &'a Hit, bsdf: &'a Bsdf },
    /// A point in a medium and its phase function.
    Medium { p: Vec3, phase: Phase },
}

/// How the light sample is weighted against other estimates of the same light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mis {
    /// The light sample is the only estimate of direct light at the point.
    LightOnly,
    /// The caller also samples the BSDF or phase function and counts the lights its ray hits:
    /// both are weighted by the power heuristic.
    WithScatterSampling,
}

/// Direct light scattered towards `wo` at `at` by one light sample (see the module comment).
/// `medium` is the medium the path arrived in (None: vacuum); a shadow ray leaving a surface
/// starts in the medium on the side it leaves towards. Adds the shadow rays traced to `rays`.
// Inlined into each integrator's loop, as the path tracer's own next-event estimation was: a
// call per vertex measurably slowed `path` (about 5% on the Cornell box).
#[inline(always)]
pub fn estimate_direct(
    scene: &Scene,
    at: Scatter<'_>,
    wo: Vec3,
    medium: Option<u32>,
    mis: Mis,
    sampler: &mut Sampler,
    rays: &mut u64,
) -> Rgb {
    let Some((light_id, pmf)) = scene.sample_light(sampler.next_f32()) else {
        return Rgb::ZERO;
    };
    let (u, uc) = (sampler.next_2d(), sampler.next_f32());
    let p = match at {
        Scatter::Surface { hit, .. } => hit.p,
        Scatter::Medium { p, .. } => p,
    };
    let Some(ls) = scene.lights[light_id].sample_li(p, u, uc) else {
        return Rgb::ZERO;
    };
    if ls.li == Rgb::ZERO {
        return Rgb::ZERO;
    }
    // The scattering function times the cosine, its sampling pdf, and the visibility.
    let (f, scatter_pdf, tr) = match at {
        Scatter::Surface { hit, bsdf } => {
            let (f, pdf) = bsdf.eval_pdf(wo, ls.wi);
            if f == Rgb::ZERO {
                return Rgb::ZERO;
            }
            *rays += 1;
            let tr = if scene.has_media() {
                let side = scene.medium_after(hit, ls.wi, medium);
                scene.transmittance(hit.p, hit.ng, ls.p, ls.n, side)
            } else if scene.occluded(hit.p, hit.ng, ls.p, ls.n) {
                Rgb::ZERO
            } else {
                Rgb::ONE
            };
            let pdf = if mis == Mis::WithScatterSampling && !ls.delta {
                pdf
            } else {
                0.0
            };
            (f, pdf, tr)
        }
        Scatter::Medium { p, phase } => {
            *rays += 1;
            let tr = scene.transmittance(p, Vec3::ZERO, ls.p, ls.n, medium);
            // The phase function takes the cosine between the directions light travels in:
            // from the light (-wi) and on towards the viewer (-wo).
            let f = phase.eval(-wo.dot(ls.wi));
            (Rgb::splat(f), f, tr)
        }
    };
    if tr == Rgb::ZERO {
        return Rgb::ZERO;
    }
    let pdf_light = pmf * ls.pdf;
    let w = match mis {
        Mis::WithScatterSampling if !ls.delta => power_heuristic(pdf_light, scatter_pdf),
        _ => 1.0,
    };
    f * ls.li * tr * (w / pdf_light)
}
