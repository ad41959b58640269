//! The camera side shared by the photon-mapping integrators: a camera ray is followed through
//! mirrors and glass (delta surfaces) to its first diffuse point, the *visible point* where
//! photon density estimates are made; there, direct light may be estimated by a shadow ray.

use crate::Rgb;
use crate::geometry::{Hit, Ray, offset_origin};
use crate::material::{Material, TransportMode};
use crate::sampling::Sampler;
use crate::scene::Scene;
use glam::Vec3;

/// Null boundaries crossed in a row before a ray is abandoned (a ray stuck on coincident
/// boundaries).
pub const MAX_NULL_CROSSINGS: u32 = 256;

/// The next surface along a ray that is not a null boundary, and the ray that reached it.
pub fn next_surface(scene: &Scene, mut ray: Ray, rays: &mut u64) -> Option<(Hit, Ray)> {
    for _ in 0..MAX_NULL_CROSSINGS {
        *rays += 1;
        let hit = scene.intersect(&ray, f32::INFINITY)?;
        if !scene.material(&hit).is_null() {
            return Some((hit, ray));
        }
        ray = Ray::new(offset_origin(hit.p, hit.ng, ray.dir), ray.dir);
    }
    None
}

/// The first diffuse point of a camera path.
#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint {
    pub hit: Hit,
    pub material: Material,
    /// Direction towards the camera (along the path).
    pub wo: Vec3,
    /// Surface normal on the side `wo` is on.
    pub n: Vec3,
    /// Throughput of the delta bounces before it.
    pub beta: Rgb,
    /// Delta bounces before it: photons gathered here may have at most max_depth - bounces
    /// scattering events.
    pub bounces: u32,
    /// Length of the path from the camera (for the pixel's footprint).
    pub distance: f32,
}

/// A camera path followed through delta surfaces.
#[derive(Clone, Copy, Debug)]
pub struct CameraPath {
    /// Emission met along the way, the visible point's own included (E S* L paths), weighted
    /// by the throughput.
    pub emitted: Rgb,
    /// None if the path left the scene, ended on a delta surface or at `max_depth` bounces.
    pub visible: Option<VisiblePoint>,
}

/// Follows `ray` through at most `max_depth` delta bounces (sampling reflection or refraction
/// in radiance mode) to the first non-delta surface.
pub fn trace_to_diffuse(
    scene: &Scene,
    mut ray: Ray,
    max_depth: u32,
    sampler: &mut Sampler,
    rays: &mut u64,
) -> CameraPath {
    let mut emitted = Rgb::ZERO;
    let mut beta = Rgb::ONE;
    let mut bounces = 0u32;
    let mut distance = 0.0;
    while let Some((hit, arrived)) = next_surface(scene, ray, rays) {
        let material = *scene.material(&hit);
        let wo = -arrived.dir;
        distance += hit.p.distance(arrived.origin);
        if let Some((_, light)) = scene.area_light(&hit) {
            emitted += beta * light.emitted(hit.ng, wo);
        }
        if bounces >= max_depth {
            break;
        }
        if material.is_delta() {
            let (u, uc) = (sampler.next_2d(), sampler.next_f32());
            let Some(bs) = material.sample(wo, hit.ng, u, uc, TransportMode::Radiance) else {
                break;
            };
            beta *= bs.weight;
            bounces += 1;
            ray = Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi);
            continue;
        }
        let n = if hit.ng.dot(wo) > 0.0 {
            hit.ng
        } else {
            -hit.ng
        };
        return CameraPath {
            emitted,
            visible: Some(VisiblePoint {
                hit,
                material,
                wo,
                n,
                beta,
                bounces,
                distance,
            }),
        };
    }
    CameraPath {
        emitted,
        visible: None,
    }
}

/// Direct light reflected towards `wo` at a non-delta point, by one shadow ray to a light
/// chosen in proportion to power (no MIS: the photon integrators never hit lights by BSDF
/// sampling at this vertex, so light sampling alone counts the L D paths).
pub fn direct_light(
    scene: &Scene,
    hit: &Hit,
    material: &Material,
    wo: Vec3,
    sampler: &mut Sampler,
    rays: &mut u64,
) -> Rgb {
    direct_light_in(scene, hit, material, wo, None, sampler, rays)
}

/// [`direct_light`] in a scene with media: `medium` is the one the camera ray arrived in, and
/// the shadow ray carries the transmittance of the media and null boundaries it crosses.
pub fn direct_light_in(
    scene: &Scene,
    hit: &Hit,
    material: &Material,
    wo: Vec3,
    medium: Option<u32>,
    sampler: &mut Sampler,
    rays: &mut u64,
) -> Rgb {
    let Some((light_id, pmf)) = scene.sample_light(sampler.next_f32()) else {
        return Rgb::ZERO;
    };
    let (u, uc) = (sampler.next_2d(), sampler.next_f32());
    let Some(ls) = scene.lights[light_id].sample_li(hit.p, u, uc) else {
        return Rgb::ZERO;
    };
    let f = material.eval(wo, ls.wi, hit.ng);
    if f == Rgb::ZERO || ls.li == Rgb::ZERO {
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
    f * ls.wi.dot(hit.ng).abs() * ls.li * tr / (pmf * ls.pdf)
}
